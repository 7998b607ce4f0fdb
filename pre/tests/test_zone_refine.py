"""pre/zone_refine.py: knots added around wanted sizes, the old ones kept."""

from __future__ import annotations

import numpy as np

from pre.zone_refine import GROWTH, SizeRequest, interior, split_breaks, wanted_size


def test_wanted_size_grows_beyond_reach() -> None:
    r = SizeRequest(position=1.0, size=0.01, reach=0.05)
    s = np.array([1.0, 1.05, 1.15, 0.85])
    got = wanted_size(s, [r])
    assert np.allclose(got, [0.01, 0.01, 0.01 + (GROWTH - 1) * 0.1, 0.01 + (GROWTH - 1) * 0.1], rtol=1e-14)
    assert np.all(np.isinf(wanted_size(s, [])))


def test_split_without_requests_keeps_breaks() -> None:
    breaks = np.array([0.0, 0.2, 0.7, 1.0])
    assert np.array_equal(split_breaks(breaks, 3 * breaks, []), breaks)


def test_split_nests_and_meets_the_size() -> None:
    breaks = np.array([0.0, 0.25, 0.5, 0.75, 1.0])
    length = 2.0 * breaks  # two length units per parameter unit
    req = SizeRequest(position=0.9, size=0.02, reach=0.04)
    new = split_breaks(breaks, length, [req])
    assert all(np.isclose(new, b, atol=1e-15).any() for b in breaks)  # the old knots are kept
    s = 2.0 * new
    sizes = np.diff(s)
    mid = 0.5 * (s[1:] + s[:-1])
    near = np.abs(mid - req.position) <= req.reach
    assert near.any() and sizes[near].max() <= req.size * 1.05
    # sizes follow the wanted function: never above it by more than the rounding up
    assert np.all(sizes <= np.minimum(wanted_size(mid, [req]) * 1.5, 0.5 + 1e-12))
    ratios = sizes[1:] / sizes[:-1]
    assert np.all(np.maximum(ratios, 1 / ratios) <= GROWTH * 1.6)
    assert interior(new) == [float(v) for v in new[1:-1]]
