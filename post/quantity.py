"""The scalar a figure of the bodies is coloured by (``python -m post plot-deformed
--field``): the displacement (``u``: its magnitude, ``ux``, ``uy``, of a solid ``uz``)
from the exact VO map, or a sampled solver field (``von_mises``, ``stress_xx`` ...
``strain_xy``, of a solid also the ``yz`` and ``xz`` components) of the steps where the
case's ``&output`` asked for them (docs/hdf5.md, "Sampled fields").

A sampled field is known at ``samples`` points per direction of each element (a uniform
grid of the element with its ends: ``samples^2`` points in a plane element,
``samples^3`` in a solid's); between them it is interpolated bilinearly (trilinearly)
within the element (one sample: constant per element). The stress of a NURBS body is
smooth inside an element, so the figure shows the solver's values at the samples and a
faithful picture between them; nothing is extrapolated across elements.
"""

from __future__ import annotations

import numpy as np

from .reader import Body, Result, Step

COMPONENTS = ("xx", "yy", "zz", "xy")
"""The components of the sampled stress and strain of a plane body, in the file's order."""

COMPONENTS_3D = ("xx", "yy", "zz", "xy", "yz", "xz")
"""The components of a solid's sampled stress and strain, in the file's order."""

DISPLACEMENT = ("u", "ux", "uy", "uz")
"""Displacement quantities: from the displacements, at every step (``uz``: solids)."""

FIELDS = ("von_mises",) + tuple(f"{t}_{c}" for t in ("stress", "strain") for c in COMPONENTS_3D)
"""Sampled quantities: from the step's fields (``yz``, ``xz``: solids)."""

QUANTITIES = DISPLACEMENT + FIELDS
"""Every name ``--field`` takes."""


def components(dimension: int) -> tuple[str, ...]:
    """The stress and strain components of a result file of spatial ``dimension``."""
    return COMPONENTS if dimension == 2 else COMPONENTS_3D


def quantities(dimension: int) -> tuple[str, ...]:
    """The quantities of a result file of spatial ``dimension``."""
    if dimension == 3:
        return QUANTITIES
    return tuple(q for q in QUANTITIES if q != "uz" and not q.endswith(("_yz", "_xz")))


def label(name: str, units) -> str:  # noqa: ANN001 (post.units.Units)
    """The colour bar's label of ``name``, with its unit."""
    if name == "u":
        return f"displacement magnitude |u| [{units.length}]"
    if name in ("ux", "uy", "uz"):
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


def check_name(name: str, dimension: int = 2) -> None:
    """ValueError naming the known quantities when ``name`` is not one of a result file
    of spatial ``dimension``."""
    known = quantities(dimension)
    if name not in known:
        what = "not a quantity of a plane (2D) result" if name in QUANTITIES else "not a quantity"
        raise ValueError(f"--field {name!r}: {what} (known: {', '.join(known)})")


def displacement_quantity(name: str, u: np.ndarray) -> np.ndarray:
    """``u``, ``ux``, ``uy`` or ``uz`` of a displacement field ``(..., nsd)``."""
    if name == "u":
        return np.linalg.norm(u, axis=-1)
    return u[..., "xyz".index(name[1])]


def _samples(step: Step, body: Body, name: str) -> tuple[np.ndarray, int]:
    """The sampled values of ``name`` of ``body`` at ``step``, ``(nel, s, s)`` (eta, xi
    within each element) or of a solid ``(nel, s, s, s)`` (zeta, eta, xi), and s."""
    fields = step.fields.get(body.name)
    if not fields:
        raise ValueError(f"step {step.step} has no sampled fields (stress, strain, von Mises): add "
                         "[output] to the spec, or &output to the case (docs/formats.md), and run again")
    key, comp = ("von_mises", None) if name == "von_mises" else name.split("_")
    if key not in fields:
        raise ValueError(f"step {step.step}: body {body.name!r} has no {key!r} field (&output fields "
                         f"named {sorted(k for k in fields if k in ('stress', 'strain', 'von_mises'))})")
    values = np.asarray(fields[key], dtype=float)
    nsd = body.nsd
    if comp is not None:
        names = components(nsd)
        if comp not in names:
            raise ValueError(f"{name!r}: a {nsd}D body's stress and strain have the components "
                             f"{', '.join(names)}")
        values = values.reshape(-1, len(names))[:, names.index(comp)]
    s = int(step.field_info.get(body.name, {}).get("samples", 1))
    nel = len(body.element_ranges)
    per = s**nsd
    element = np.asarray(fields["element"], dtype=int)
    if values.size != nel * per or not np.array_equal(element, np.repeat(np.arange(nel), per)):
        raise ValueError(f"step {step.step}: body {body.name!r}: the sampled fields do not match its "
                         f"{nel} elements x {' x '.join([str(s)] * nsd)} samples")
    return values.reshape(nel, *([s] * nsd)), s


def element_of(body: Body, xi: np.ndarray, eta: np.ndarray,
               zeta: np.ndarray | None = None) -> tuple[np.ndarray, ...]:
    """For parameter points, the 0-based element holding each and the local
    coordinates (a, b) in [0, 1]^2 within it, of a solid's (a, b, c) in [0, 1]^3 (a
    point on an element boundary: the element after it, the last one at 1)."""
    r = body.element_ranges
    t = [xi, eta] if zeta is None else [xi, eta, zeta]
    if r.shape[1] != 2 * len(t):
        raise ValueError(f"body {body.name!r}: {r.shape[1] // 2} parameters, {len(t)} given")
    breaks = [np.unique(r[:, 2 * d:2 * d + 2]) for d in range(len(t))]
    spans = [np.clip(np.searchsorted(b, v, side="right") - 1, 0, len(b) - 2) for b, v in zip(breaks, t, strict=True)]
    # table[..., j, i] (the last direction first): the element of each span box
    table = np.full([len(b) - 1 for b in breaks][::-1], -1, dtype=int)
    table[tuple(np.searchsorted(breaks[d], r[:, 2 * d]) for d in reversed(range(len(t))))] = np.arange(len(r))
    e = table[tuple(spans[::-1])]
    if np.any(e < 0):
        raise ValueError(f"body {body.name!r}: its elements do not tile the parameter box")
    local = [np.clip((v - r[e, 2 * d]) / (r[e, 2 * d + 1] - r[e, 2 * d]), 0.0, 1.0) for d, v in enumerate(t)]
    return (e, *local)


def sampled_quantity(step: Step, body: Body, name: str, xi: np.ndarray, eta: np.ndarray,
                     zeta: np.ndarray | None = None) -> np.ndarray:
    """A sampled field ``name`` of ``body`` at ``step`` at the parameter points
    ``(xi, eta)``, of a solid ``(xi, eta, zeta)`` (any shape, broadcast together):
    multilinear between the samples of the element holding each point."""
    values, s = _samples(step, body, name)
    given = [xi, eta] if zeta is None else [xi, eta, zeta]
    if len(given) != body.nsd:
        raise ValueError(f"body {body.name!r}: {body.nsd} parameters, {len(given)} given")
    arrays = np.broadcast_arrays(*(np.asarray(v, float) for v in given))
    e, *local = element_of(body, *(a.ravel() for a in arrays))
    if s == 1:
        return values.reshape(len(values))[e].reshape(arrays[0].shape)
    lower, frac = [], []
    for a in local:  # per direction: the sample below and the fraction to the next
        g = a * (s - 1)
        i0 = np.minimum(g.astype(int), s - 2)
        lower.append(i0)
        frac.append(g - i0)
    v = np.zeros(len(e))
    for corner in np.ndindex(*([2] * len(local))):  # (0/1 per direction, xi first)
        weight = np.prod([f if c else 1 - f for c, f in zip(corner, frac, strict=True)], axis=0)
        index = tuple(i0 + c for i0, c in zip(lower, corner, strict=True))
        v += weight * values[(e, *index[::-1])]
    return v.reshape(arrays[0].shape)


def steps_with_fields(result: Result) -> list[int]:
    """The converged steps that have sampled fields."""
    return [s.step for s in result.steps if s.fields]
