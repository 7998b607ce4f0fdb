"""The deformed-body figure of a solid (``python -m post plot-deformed`` on a result of
dimension 3): a perspective-free 3D view (matplotlib's mplot3d) of every body's
boundary in its current configuration ``X + scale * u``.

Each of a body's six faces is sampled on a parametric grid that contains every element
boundary (at least :data:`MIN_SAMPLES` samples per direction, the same number in every
element), evaluated with the exact
map of :mod:`post.field` and coloured by the quantity of :mod:`post.quantity` (``|u|``,
a component, or a sampled stress or strain, interpolated within the elements), flat
per facet. Only the facets turned towards the viewer are drawn (back-face culling;
mplot3d's depth sort of the facets does the rest: right for a convex body, close for
others), with the element boundaries on them as thin black lines in the same sort;
``reference=True`` adds the undeformed body's twelve edges (grey, in the same sort).
The view is from elevation :data:`ELEVATION` and azimuth :data:`AZIMUTH` degrees, with
equal scales on the three axes. Why a 3D view
rather than sections: it shows the whole outer surface (where a solid's stresses
are largest and its boundary conditions act) in one picture, at the cost of
the interior; ParaView (``python -m post vtk``) cuts and clips it.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.cm import ScalarMappable  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402

from .field import displacement, evaluate  # noqa: E402
from .paraview import element_samples  # noqa: E402
from .plot import CMAP, _title, auto_scale, breakpoints, colour_norms  # noqa: E402
from .quantity import DISPLACEMENT, displacement_quantity, label, sampled_quantity  # noqa: E402
from .reader import Body, Result, Step, body_displacement  # noqa: E402

MIN_SAMPLES = 40
"""At least this many samples along each parametric direction of a face (and one per
element: a fine mesh is drawn with flat facets per element, which keeps mplot3d's
polygons to about the faces' elements)."""

ELEVATION, AZIMUTH = 25.0, -55.0
"""The view direction (degrees, mplot3d's ``view_init``)."""

LIFT = 0.02
"""The element boundaries are drawn this fraction of the scene's size towards the viewer
(about a facet's size): in mplot3d's depth order (by the mean depth of each polygon)
they come after the facets around them, and before anything farther in front."""

FACES: tuple[tuple[int, float], ...] = ((0, 0.0), (0, 1.0), (1, 0.0), (1, 1.0), (2, 0.0), (2, 1.0))
"""The six faces of the parameter cube: (fixed direction, its value): xi0, xi1, eta0,
eta1, zeta0, zeta1."""


def face_parameters(body: Body, face: tuple[int, float],
                    minimum: int = MIN_SAMPLES) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(xi, eta, zeta)`` on a sampling grid of a face ``(n_v, n_u)``: its two free
    directions (in order; every element boundary included), the third fixed."""
    fixed, value = face
    breaks = breakpoints(body)
    free = [d for d in range(3) if d != fixed]
    u, v = (element_samples(breaks[d], 1, minimum) for d in free)
    uu, vv = np.meshgrid(u, v)
    params = [None, None, None]
    params[free[0]], params[free[1]] = uu, vv
    params[fixed] = np.full_like(uu, value)
    return params[0], params[1], params[2]


def face_quantity(body: Body, step: Step | None, u: np.ndarray, name: str,
                  params: tuple[np.ndarray, np.ndarray, np.ndarray]) -> np.ndarray:
    """The quantity ``name`` at the face samples ``params`` (``u``: the displacement there)."""
    if name in DISPLACEMENT:
        return displacement_quantity(name, u)
    if step is None:
        raise ValueError(f"--field {name}: the reference configuration (step 0) has no stress")
    return sampled_quantity(step, body, name, *params)


def view_direction(elevation: float = ELEVATION, azimuth: float = AZIMUTH) -> np.ndarray:
    """Unit vector from the scene towards the viewer of mplot3d's ``view_init``."""
    e, a = np.radians(elevation), np.radians(azimuth)
    return np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])


def _face_grid_lines(params: tuple[np.ndarray, np.ndarray, np.ndarray], fixed: int,
                     breaks: tuple[np.ndarray, ...]) -> tuple[np.ndarray, np.ndarray]:
    """Which columns (constant first free parameter) and rows (constant second) of a
    face's sampling grid lie on element boundaries: boolean ``(n_u,)``, ``(n_v,)``."""
    free = [d for d in range(3) if d != fixed]
    u, v = params[free[0]][0, :], params[free[1]][:, 0]
    return np.isin(u, breaks[free[0]]), np.isin(v, breaks[free[1]])


def _facets(points: np.ndarray, values: np.ndarray, inward: np.ndarray, towards: np.ndarray,
            columns: np.ndarray, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Of a face's sampling grid ``points (n_v, n_u, 3)``: the facets ``(n, 4, 3)`` turned
    towards the viewer (``towards``; ``inward`` (3,): a direction into the body from the
    face), the mean value of each, and the element boundaries on them (the grid lines
    ``columns`` and ``rows`` say are boundaries) as segments ``(m, 2, 3)`` beside at
    least one front facet."""
    quads = np.stack([points[:-1, :-1], points[:-1, 1:], points[1:, 1:], points[1:, :-1]], axis=2)
    normal = np.cross(quads[..., 1, :] - quads[..., 0, :], quads[..., 3, :] - quads[..., 0, :])
    if np.sum(normal @ inward) > 0:  # point the normals out of the body
        normal = -normal
    mean = 0.25 * (values[:-1, :-1] + values[:-1, 1:] + values[1:, 1:] + values[1:, :-1])
    front = np.sum(normal * towards, axis=-1) > 0
    # a grid line's segment is seen when a facet on either side of it is
    pad = np.pad(front, 1)
    seen_col = pad[1:-1, :-1] | pad[1:-1, 1:]  # (n_v - 1, n_u): segments along v
    seen_row = pad[:-1, 1:-1] | pad[1:, 1:-1]  # (n_v, n_u - 1): segments along u
    along_v = np.stack([points[:-1], points[1:]], axis=2)[seen_col & columns[None, :]]
    along_u = np.stack([points[:, :-1], points[:, 1:]], axis=2)[seen_row & rows[:, None]]
    return quads[front], mean[front], np.concatenate([along_v, along_u])


def _reference_edges(body: Body, n: int = 60) -> list[np.ndarray]:
    """The twelve edges of the undeformed body (lines of the parameter cube)."""
    t = np.linspace(0.0, 1.0, n)
    lines = []
    for d in range(3):
        for a in (0.0, 1.0):
            for b in (0.0, 1.0):
                params = [np.full(n, a), np.full(n, b)]
                params.insert(d, t)
                lines.append(evaluate(body, None, *params))
    return lines


def solid_figure(result: Result, step: int = -1, scale: float | str = "auto",
                 length_unit: str | None = None, reference: bool = False, field: str = "u",
                 colour_scale: str | None = None) -> tuple[plt.Figure, dict]:
    """The figure of every solid of ``result`` deformed at ``step`` (selection as in
    :meth:`post.reader.Result.select_step`), and for each body the collection of
    facets and lines (one for all: mplot3d sorts within a collection).

    ``scale`` (``'auto'``: :func:`post.plot.auto_scale`), ``length_unit``, ``field``
    and ``colour_scale`` as in :func:`post.plot.deformed_figure`; ``reference=True``
    adds the undeformed edges (grey).
    """
    if colour_scale is None:
        colour_scale = "body" if field in DISPLACEMENT else "shared"
    if colour_scale not in ("body", "shared"):
        raise ValueError(f"colour scale {colour_scale!r}: 'body' or 'shared'")
    s = result.select_step(step)
    number = 0 if s is None else s.step
    unit = length_unit or result.units.length

    faces = {}  # body -> [(face, reference points, displacement, inward, values, parameters)]
    for name, body in result.bodies.items():
        u = body_displacement(result, name, number)
        faces[name] = []
        for face in FACES:
            params = face_parameters(body, face)
            ref, uf = evaluate(body, None, *params), displacement(body, u, *params)
            inner = list(params)
            inner[face[0]] = np.full_like(params[0], 0.5)
            inward = (evaluate(body, None, *inner) - ref).reshape(-1, 3).mean(axis=0)
            faces[name].append((face, ref, uf, inward, face_quantity(body, s, uf, field, params), params))
    norms = colour_norms({n: np.concatenate([f[4].ravel() for f in fs]) for n, fs in faces.items()},
                         field, colour_scale == "body")
    allpts = np.concatenate([(f[1] + f[2]).reshape(-1, 3) for fs in faces.values() for f in fs])
    size = float(np.max(np.ptp(allpts, axis=0)))
    if scale == "auto":
        umax = max(float(np.linalg.norm(f[2], axis=-1).max()) for fs in faces.values() for f in fs)
        scale = auto_scale(size, umax)
    scale = float(scale)

    fig = plt.figure(figsize=(9.0, 7.5), layout="constrained")
    ax = fig.add_subplot(projection="3d")
    ax.view_init(ELEVATION, AZIMUTH)
    towards = view_direction()
    lift = LIFT * size * towards
    # one collection for every body's facets and the lines on them, so that mplot3d's
    # depth sort (per polygon) hides what is behind: the lines are closed two-point
    # polygons; the facets' edges in their own colour (no seams between them)
    polygons, faces_rgba, edges_rgba = [], [], []

    def add_lines(segments: np.ndarray, colour: tuple[float, ...]) -> None:
        polygons.append(segments[:, [0, 1, 1, 0]] + lift)
        faces_rgba.append(np.zeros((len(segments), 4)))
        edges_rgba.append(np.tile(colour, (len(segments), 1)))

    drawn = []
    for name, fs in faces.items():
        breaks = breakpoints(result.bodies[name])
        for face, ref, uf, inward, values, params in fs:
            columns, rows = _face_grid_lines(params, face[0], breaks)
            points = ref + scale * uf
            quads, mean, segments = _facets(points, values, inward, towards, columns, rows)
            rgba = plt.get_cmap(CMAP)(norms[name](mean))
            polygons.append(quads)
            faces_rgba.append(rgba)
            edges_rgba.append(rgba)
            add_lines(segments, matplotlib.colors.to_rgba("k", 0.75))
            drawn.append(points.reshape(-1, 3))
    if reference:
        for body in result.bodies.values():
            for edge in _reference_edges(body):
                add_lines(np.stack([edge[:-1], edge[1:]], axis=1), matplotlib.colors.to_rgba("0.35"))
                drawn.append(edge)
    poly = Poly3DCollection(np.concatenate(polygons), facecolors=np.concatenate(faces_rgba),
                            edgecolors=np.concatenate(edges_rgba), linewidths=0.4)
    ax.add_collection3d(poly)
    lo, hi = np.concatenate(drawn).min(axis=0), np.concatenate(drawn).max(axis=0)
    span = np.maximum(hi - lo, 1e-9 * max(float(np.max(hi - lo)), 1.0))
    ax.set_xlim(lo[0], lo[0] + span[0])
    ax.set_ylim(lo[1], lo[1] + span[1])
    ax.set_zlim(lo[2], lo[2] + span[2])
    ax.set_box_aspect(tuple(span))
    for axis, setter in zip("xyz", (ax.set_xlabel, ax.set_ylabel, ax.set_zlabel), strict=True):
        setter(f"{axis} [{unit}]")
    ax.set_title(_title(result, number, None if s is None else s.time, scale), fontsize=10)
    text = label(field, result.units)
    if colour_scale == "shared" or len(faces) == 1:
        first = next(iter(faces))
        cbar = fig.colorbar(ScalarMappable(norm=norms[first], cmap=CMAP), ax=ax, shrink=0.7, pad=0.08)
        cbar.set_label(text)
    else:
        for name in faces:
            cbar = fig.colorbar(ScalarMappable(norm=norms[name], cmap=CMAP), ax=ax, shrink=0.7,
                                pad=0.08, fraction=0.04)
            cbar.set_label(f"{name}: {text}", fontsize=8)
    return fig, {name: poly for name in faces}
