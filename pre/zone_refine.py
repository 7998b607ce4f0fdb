"""Knots that resolve the edges of a contact zone (``python -m pre refine RESULT.h5``;
the measurements come from :mod:`post.adapt`).

Everything here works on one body's element boundaries (breaks) in one parametric
direction and a wanted element size at a few places, and only ever *adds* knots: every
existing span is split into equal-density parts, so the refined mesh nests in the old
one and the refinement is NURBS knot insertion (the geometry unchanged, exactly).

The wanted size is a function on the direction's reference length coordinate ``s``:
``size_i`` within ``reach_i`` of each request's position, growing linearly with the
distance beyond it (``GROWTH`` - 1 per unit length: neighbouring elements differ by
about that factor), never larger than the old element. A span ``[s_a, s_b]`` gets
``n = ceil(int 1/size ds)`` elements, placed where that integral reaches ``k / n`` of
its value, so the sizes follow the wanted function inside the span too.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

GROWTH = 1.5
"""Largest ratio of neighbouring element sizes in the grading back to the old mesh."""
SAMPLES = 400
"""Points per old span at which the density is integrated."""


@dataclass(frozen=True)
class SizeRequest:
    """A wanted element size around a point of a direction (reference lengths)."""

    position: float
    """Where (in the direction's reference length coordinate)."""
    size: float
    """The element size wanted there."""
    reach: float
    """Half-length of the interval with that size (beyond it the size grows)."""


def wanted_size(s: np.ndarray, requests: list[SizeRequest], growth: float = GROWTH) -> np.ndarray:
    """The wanted size at the coordinates ``s`` (inf where no request reaches)."""
    out = np.full(np.shape(s), np.inf)
    for r in requests:
        beyond = np.clip(np.abs(s - r.position) - r.reach, 0.0, None)
        out = np.minimum(out, r.size + (growth - 1.0) * beyond)
    return out


def split_breaks(breaks: np.ndarray, length: np.ndarray, requests: list[SizeRequest],
                 growth: float = GROWTH) -> np.ndarray:
    """The refined breaks of one direction: ``breaks`` (increasing parameters, ends
    included) with every span split as the module docstring says. ``length``: the
    reference length coordinate at each break (increasing). The new breaks are placed
    by linear interpolation of the parameter in the length within each span."""
    breaks = np.asarray(breaks, dtype=float)
    length = np.asarray(length, dtype=float)
    out = [float(breaks[0])]
    for k in range(len(breaks) - 1):
        s = np.linspace(length[k], length[k + 1], SAMPLES + 1)
        old = length[k + 1] - length[k]
        size = np.minimum(wanted_size(s, requests, growth), old)
        density = np.concatenate([[0.0], np.cumsum(0.5 * (1 / size[1:] + 1 / size[:-1]) * np.diff(s))])
        n = max(1, math.ceil(density[-1] - 1e-9))
        if n > 1:
            inner = np.interp(density[-1] * np.arange(1, n) / n, density, s)
            t = (inner - length[k]) / old
            out += [float(breaks[k] + (breaks[k + 1] - breaks[k]) * v) for v in t]
        out.append(float(breaks[k + 1]))
    return np.array(out)


def interior(breaks: np.ndarray) -> list[float]:
    """The interior breaks as a case file's ``knots_xi`` / ``knots_eta`` list."""
    return [float(v) for v in np.asarray(breaks)[1:-1]]
