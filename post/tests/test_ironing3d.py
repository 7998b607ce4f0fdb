"""The ironing measures of ``post ironing`` (post/ironing3d.py) on made-up histories:
the detrended amplitude over the second half of sliding, over the mean, ignores a smooth
trend and the press phase, and a run too short to measure is refused."""
from __future__ import annotations

import numpy as np
import pytest

from post.ironing3d import MIN_SLIDING, IroningError, _measure


def _history(n_press: int = 10, n_slide: int = 40, amp: float = 0.01) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    steps = np.arange(1, n_press + n_slide + 1)
    sliding = steps > n_press
    s = np.where(sliding, steps - n_press, 0).astype(float)
    ft = np.where(sliding, 0.3 + 1e-3 * s + amp * np.sin(2 * np.pi * s / 5), 0.01 * steps)
    fn = np.where(sliding, -1.0 - 2e-3 * s, -0.1 * steps)
    return steps, np.column_stack([ft, fn]), sliding


def test_the_trend_is_removed_and_the_oscillation_kept() -> None:
    steps, f, sliding = _history()
    m = _measure(steps, f, sliding)
    assert m["osc_n"] < 1e-12                          # a linear trend only
    w = np.flatnonzero(sliding)[20:]
    assert m["mean_t"] == pytest.approx(f[w, 0].mean())
    assert m["amp_t"] == pytest.approx(2 * 0.01 * np.sin(2 * np.pi / 5), rel=0.15)   # the samples' max - min
    assert m["osc_t"] == pytest.approx(m["amp_t"] / m["mean_t"])
    assert m["ratio"] == pytest.approx(abs(m["mean_t"] / m["mean_n"]))
    assert m["spread_n"] == pytest.approx(np.ptp(f[sliding, 1]) / abs(f[sliding, 1].mean()))


def test_too_few_sliding_steps_are_refused() -> None:
    steps, f, sliding = _history(n_slide=MIN_SLIDING - 1)
    with pytest.raises(IroningError, match="sliding steps"):
        _measure(steps, f, sliding)
