"""Layout names (``N2``, ``NN4``, ``NN2.2``, ``L1``) -> &body settings.

See docs/benchmarks.md section 1 and the layout table of docs/formats.md. Bulk
degree 2 is the lowest degree that is exact for our scenes.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

BULK_DEGREE = 2
"""Lowest degree that represents every scene exactly."""


@dataclass(frozen=True)
class Layout:
    """The discretization settings a layout name stands for."""

    name: str
    basis: str  # 'nurbs' or 'linear'
    degree_xi: int
    degree_eta: int
    layer_degree: int  # 0 = no layer
    layer_elevations: int


_NP = re.compile(r"^N(\d+)$")
_NNP = re.compile(r"^NN(\d+)(?:\.(\d+))?$")


def parse_layout(name: str) -> Layout:
    """Settings of a layout: ``Np``, ``NNp``, ``NNp.k`` or ``L1``."""
    if name == "L1":
        return Layout(name, "linear", 1, 1, 0, 0)
    m = _NP.match(name)
    if m:
        p = int(m.group(1))
        if p < BULK_DEGREE:
            raise ValueError(f"{name}: degree below {BULK_DEGREE} is not exact for the scenes")
        return Layout(name, "nurbs", p, BULK_DEGREE, 0, 0)
    m = _NNP.match(name)
    if m:
        q = int(m.group(1))
        k = int(m.group(2) or 0)
        if q < BULK_DEGREE:
            raise ValueError(f"{name}: layer degree below {BULK_DEGREE}")
        return Layout(name, "nurbs", BULK_DEGREE, BULK_DEGREE, q, k)
    raise ValueError(f"unknown layout {name!r} (expected Np, NNp, NNp.k or L1)")
