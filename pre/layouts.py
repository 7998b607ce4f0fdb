"""Layout names (``N2``, ``NN4``, ``NN2.2``, ``L1``) -> &body settings.

See docs/benchmarks.md section 1 and the layout table of docs/formats.md. Bulk
degree 2 is the lowest degree that is exact for our scenes. A solid's layouts
(:func:`solid_layout`) have the 3D meaning of docs/formats.md, "Solids".
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


MAX_DEGREE = 20
"""Highest degree voiga takes (bulk, and layer degree plus elevations)."""


@dataclass(frozen=True)
class SolidLayout:
    """The discretization settings of a solid's layout: the bulk degree in all three
    directions, the VO layer on the contact face (degree 0: none)."""

    name: str
    basis: str  # 'nurbs' or 'linear'
    degree: int
    layer_degree: int
    layer_elevations: int


def solid_layout(name: str | None, coarse: int) -> SolidLayout:
    """Settings of a solid's layout for a volume whose highest degree is ``coarse``.
    ``Np``: degree p in all three directions (at least ``coarse``, so that the geometry
    stays exact), no layer; ``NNq``, ``NNq.k``: the default bulk degree and a layer of
    degree q (at least the bulk's) on the contact face, k more elevations; ``L1``:
    degree 1, nodes on the exact geometry. ``None``: the default, ``N<p>`` with p the
    larger of 2 and ``coarse`` (2 for a box, whose exact degree 1 locks in bending)."""
    base = max(BULK_DEGREE, coarse)
    if name is None:
        name = f"N{base}"
    if name == "L1":
        return SolidLayout(name, "linear", 1, 0, 0)
    m = _NP.match(name)
    if m:
        p = int(m.group(1))
        if not coarse <= p <= MAX_DEGREE:
            raise ValueError(f"layout {name}: the degree must be {coarse} (the geometry's) to {MAX_DEGREE}")
        return SolidLayout(name, "nurbs", p, 0, 0)
    m = _NNP.match(name)
    if m:
        q, k = int(m.group(1)), int(m.group(2) or 0)
        if q < base:
            raise ValueError(f"layout {name}: the layer degree {q} is below the bulk degree {base} "
                             f"(NN{base} or higher)")
        if q + k > MAX_DEGREE:
            raise ValueError(f"layout {name}: layer degree plus elevations above {MAX_DEGREE}")
        return SolidLayout(name, "nurbs", base, q, k)
    raise ValueError(f"unknown layout {name!r} (expected Np, NNq, NNq.k or L1)")
