"""Ironing measures: die reaction forces per step and their oscillation during sliding
(the paper's Table 3)."""

from __future__ import annotations

import numpy as np

from .reader import Result


def die_forces(result: Result, die: str = "die", edge: str = "inner") -> tuple[np.ndarray, np.ndarray]:
    """Step numbers and the resultant reaction (Px, Py) on the die's driven edge, (n, nsd)."""
    k = result.dirichlet_index(die, edge)
    steps = np.array([s.step for s in result.steps])
    forces = np.array([s.reactions[k] for s in result.steps]).reshape(-1, result.dimension)
    return steps, forces


def oscillation(result: Result, press_steps: int = 10, die: str = "die") -> tuple[float, float]:
    """Oscillation amplitude (max - min) of Px and Py over the second half of the sliding
    steps (the steps after ``press_steps``); our definition, the paper's window is lost."""
    steps, forces = die_forces(result, die)
    sliding = steps > press_steps
    n = int(sliding.sum())
    if n < 2:
        raise ValueError(f"{result.path}: fewer than 2 sliding steps")
    window = np.flatnonzero(sliding)[n // 2:]
    f = forces[window]
    return float(np.ptp(f[:, 0])), float(np.ptp(f[:, 1]))
