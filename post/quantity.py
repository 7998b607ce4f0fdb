"""The scalar a figure of the bodies is coloured by (``python -m post plot-deformed
--field``): the displacement (``u``: its magnitude, ``ux``, ``uy``) from the exact VO
map, or a sampled solver field (``von_mises``, ``stress_xx`` ... ``strain_xy``) of the
steps where the case's ``&output`` asked for them (docs/hdf5.md, "Sampled fields").

A sampled field is known at ``samples x samples`` points per element (a uniform grid
of the element with its ends); between them it is interpolated bilinearly within the
element (one sample: constant per element). The stress of a NURBS body is smooth inside
an element, so the figure shows the solver's values at the samples and a faithful
picture between them; nothing is extrapolated across elements.
"""

from __future__ import annotations

import numpy as np

from .reader import Body, Result, Step

COMPONENTS = ("xx", "yy", "zz", "xy")
"""The components of the sampled stress and strain, in the file's order."""

DISPLACEMENT = ("u", "ux", "uy")
"""Displacement quantities: from the displacements, at every step."""

FIELDS = ("von_mises",) + tuple(f"{t}_{c}" for t in ("stress", "strain") for c in COMPONENTS)
"""Sampled quantities: from the step's fields."""

QUANTITIES = DISPLACEMENT + FIELDS
"""Every name ``--field`` takes."""


def label(name: str, units) -> str:  # noqa: ANN001 (post.units.Units)
    """The colour bar's label of ``name``, with its unit."""
    if name == "u":
        return f"displacement magnitude |u| [{units.length}]"
    if name in ("ux", "uy"):
        return f"displacement u_{name[1]} [{units.length}]"
    if name == "von_mises":
        return f"von Mises stress [{units.pressure}]"
    kind, comp = name.split("_")
    if kind == "stress":
        return f"Cauchy stress sigma_{comp} [{units.pressure}]"
    return f"strain eps_{comp} (the law's measure) [-]"


def signed(name: str) -> bool:
    """Whether the quantity takes both signs (its colour scale is then not from 0)."""
    return name not in ("u", "von_mises")


def check_name(name: str) -> None:
    """ValueError naming the known quantities when ``name`` is not one."""
    if name not in QUANTITIES:
        raise ValueError(f"--field {name!r}: not a quantity (known: {', '.join(QUANTITIES)})")


def displacement_quantity(name: str, u: np.ndarray) -> np.ndarray:
    """``u``, ``ux`` or ``uy`` of a displacement field ``(..., 2)``."""
    if name == "u":
        return np.linalg.norm(u, axis=-1)
    return u[..., 0 if name == "ux" else 1]


def _samples(step: Step, body: Body, name: str) -> tuple[np.ndarray, int]:
    """The sampled values of ``name`` of ``body`` at ``step``, ``(nel, s, s)`` (eta, xi
    within each element), and s."""
    fields = step.fields.get(body.name)
    if not fields:
        raise ValueError(f"step {step.step} has no sampled fields (stress, strain, von Mises): add "
                         "[output] to the spec, or &output to the case (docs/formats.md), and run again")
    key, comp = ("von_mises", None) if name == "von_mises" else name.split("_")
    if key not in fields:
        raise ValueError(f"step {step.step}: body {body.name!r} has no {key!r} field (&output fields "
                         f"named {sorted(k for k in fields if k in ('stress', 'strain', 'von_mises'))})")
    values = np.asarray(fields[key], dtype=float)
    if comp is not None:
        values = values.reshape(-1, 4)[:, COMPONENTS.index(comp)]
    s = int(step.field_info.get(body.name, {}).get("samples", 1))
    nel = len(body.element_ranges)
    element = np.asarray(fields["element"], dtype=int)
    if values.size != nel * s * s or not np.array_equal(element, np.repeat(np.arange(nel), s * s)):
        raise ValueError(f"step {step.step}: body {body.name!r}: the sampled fields do not match its "
                         f"{nel} elements x {s} x {s} samples")
    return values.reshape(nel, s, s), s


def element_of(body: Body, xi: np.ndarray, eta: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For parameter points, the 0-based element holding each and the local
    coordinates (a, b) in [0, 1]^2 within it (a point on an element boundary: the
    element after it, the last one at 1)."""
    r = body.element_ranges
    bx, be = np.unique(r[:, :2]), np.unique(r[:, 2:])
    ix = np.clip(np.searchsorted(bx, xi, side="right") - 1, 0, len(bx) - 2)
    iy = np.clip(np.searchsorted(be, eta, side="right") - 1, 0, len(be) - 2)
    table = np.full((len(be) - 1, len(bx) - 1), -1, dtype=int)
    table[np.searchsorted(be, r[:, 2]), np.searchsorted(bx, r[:, 0])] = np.arange(len(r))
    e = table[iy, ix]
    if np.any(e < 0):
        raise ValueError(f"body {body.name!r}: its elements do not tile the parameter square")
    a = (xi - r[e, 0]) / (r[e, 1] - r[e, 0])
    b = (eta - r[e, 2]) / (r[e, 3] - r[e, 2])
    return e, np.clip(a, 0.0, 1.0), np.clip(b, 0.0, 1.0)


def sampled_quantity(step: Step, body: Body, name: str, xi: np.ndarray, eta: np.ndarray) -> np.ndarray:
    """A sampled field ``name`` of ``body`` at ``step`` at the parameter points
    ``(xi, eta)`` (any shape, broadcast together): bilinear between the samples of
    the element holding each point."""
    values, s = _samples(step, body, name)
    xi_b, eta_b = np.broadcast_arrays(np.asarray(xi, float), np.asarray(eta, float))
    e, a, b = element_of(body, xi_b.ravel(), eta_b.ravel())
    if s == 1:
        return values[e, 0, 0].reshape(xi_b.shape)
    ga, gb = a * (s - 1), b * (s - 1)
    i0 = np.minimum(ga.astype(int), s - 2)
    j0 = np.minimum(gb.astype(int), s - 2)
    fa, fb = ga - i0, gb - j0
    v = ((1 - fa) * (1 - fb) * values[e, j0, i0] + fa * (1 - fb) * values[e, j0, i0 + 1]
         + (1 - fa) * fb * values[e, j0 + 1, i0] + fa * fb * values[e, j0 + 1, i0 + 1])
    return v.reshape(xi_b.shape)


def steps_with_fields(result: Result) -> list[int]:
    """The converged steps that have sampled fields."""
    return [s.step for s in result.steps if s.fields]
