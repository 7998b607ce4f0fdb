"""Exact 3D bodies (trivariate NURBS volumes): shapes, splipy volumes and ``.g2``
files as :class:`pre.volume.Volume` objects with named faces, checked and written as
a geometry file of volumes (``docs/formats.md``, "Geometry HDF5"; ``docs/pre.md``).

Every builder returns a right-handed volume (det J > 0: ``(d/dxi, d/deta, d/dzeta)``
a right-handed frame) whose contact face, by convention, is ``zeta = 1``; each names
its six faces with the labels of its ``*_FACES`` table, which ``faces`` renames
(``{label: new name}``). Circular arcs are the exact rational quadratic arcs (one
span of at most 90 degrees, middle weight ``cos(sweep / 2)``); the builders compute
the control points themselves (the tests compare each with the same body built by
``splipy.volume_factory``).

- :func:`box`: trilinear, xi along x, eta along y, zeta along z (``top`` z = z1).
- :func:`cylinder_sector`: a thick sector of a cylinder about a line parallel to z:
  xi along the angle, eta along z, zeta from the inner to the outer radius.
- :func:`shell_octant`: the octant x, y, z >= 0 of a thick spherical shell: xi along
  the longitude, eta from the equator to the pole (the face ``eta = 1`` collapses onto
  the z axis), zeta from the inner to the outer sphere.
- :func:`ball_octant`, :func:`polar_ball_octant`: a quarter of the lower hemisphere of a
  ball, in spherical coordinates about a horizontal axis (its lowest point a regular
  corner) or about the vertical one (knot lines circles about its lowest point);
  :func:`half_ball_shell`: a half of it, hollow, sheared along x.
- :func:`extrude`, :func:`revolve`: a 2D body (:class:`pre.nurbs.Patch`, z = 0) swept
  along z or about an axis in its plane: xi along the sweep (backwards for a clockwise
  patch, so that the volume is right-handed), ``(eta, zeta)`` the
  patch's ``(xi, eta)``, so its edges name the four side faces and its contact edge
  ``eta = 1`` becomes the contact face ``zeta = 1``.
- :func:`solid` turns a splipy volume (``splipy.volume_factory``, :func:`read_g2_volumes`)
  into a volume; :func:`write_volumes` checks and writes the file.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import splipy

from .geometry import check_patch, jacobian_signs, read_g2
from .h5io import write_geometry
from .nurbs import Patch
from .volume import FACE_KEYS, Volume, check_volume, volume_from_splipy

BOX_FACES = {"left": "xi0", "right": "xi1", "front": "eta0", "back": "eta1",
             "bottom": "zeta0", "top": "zeta1"}
"""Face labels of a box: ``left``/``right`` x = x0/x1, ``front``/``back`` y = y0/y1,
``bottom``/``top`` z = z0/z1 (the contact face)."""

CYLINDER_FACES = {"start": "xi0", "end": "xi1", "bottom": "eta0", "top": "eta1",
                  "inner": "zeta0", "outer": "zeta1"}
"""Face labels of a cylinder sector: ``start``/``end`` the planes at the first/second
angle, ``bottom``/``top`` z = z0/z1, ``inner``/``outer`` the cylinders (``outer``: the
contact face)."""

SHELL_FACES = {"start": "xi0", "end": "xi1", "equator": "eta0", "pole": "eta1",
               "inner": "zeta0", "outer": "zeta1"}
"""Face labels of a shell octant: ``start`` the plane y = y_c (longitude 0), ``end``
the plane x = x_c (longitude 90 degrees), ``equator`` the plane z = z_c, ``pole`` the
face collapsed onto the axis x = x_c, y = y_c, ``inner``/``outer`` the spheres
(``outer``: the contact face)."""

BALL_FACES = {"symmetry_y": "xi0", "top": "xi1", "symmetry_x": "eta0", "axis": "eta1",
              "centre": "zeta0", "outer": "zeta1"}
"""Face labels of a ball octant (:func:`ball_octant`): ``symmetry_y`` the plane
y = y_c, ``top`` the plane z = z_c, ``symmetry_x`` the plane x = x_c, ``axis`` the face
collapsed onto the axis y = y_c, z = z_c, ``centre`` the face collapsed onto the
centre, ``outer`` the sphere (the contact face)."""

SWEEP_ENDS = {"extrude": ("back", "front"), "revolve": ("plane", "turned")}
"""Default labels of the end faces of a swept 2D body: where the sweep starts (z = z0,
or the patch itself in the plane z = 0) and where it ends (z = z1, or the patch turned
by the angle); names other than the edges of the shapes of :mod:`pre.geometry`."""

Point = Sequence[float]
ONE = np.array([0.0, 0.0, 1.0, 1.0])
"""Knots of one linear span."""
ARC = np.array([0.0, 0.0, 0.0, 1.0, 1.0, 1.0])
"""Knots of one rational quadratic arc."""


def _named(labels: dict[str, str], faces: dict[str, str] | None) -> dict[str, str]:
    """Face key -> name, from label -> key and the renames ``faces`` (label -> name)."""
    faces = dict(faces or {})
    unknown = set(faces) - set(labels)
    if unknown:
        raise ValueError(f"unknown face(s) {sorted(unknown)}; the faces are {list(labels)}")
    return {key: faces.get(label, label) for label, key in labels.items()}


def _pair(values: Sequence[float], what: str) -> tuple[float, float]:
    a, b = (float(v) for v in values)
    if not b > a:
        raise ValueError(f"{what}: need {what}[0] < {what}[1], got {[a, b]}")
    return a, b


def cos_sin(degrees: float) -> tuple[float, float]:
    """``(cos, sin)`` of an angle in degrees, exact (0, 1, -1) at multiples of 90."""
    if degrees % 90 == 0:
        k = int(degrees // 90) % 4
        return ((1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0))[k]
    r = math.radians(degrees)
    return math.cos(r), math.sin(r)


def _half(sweep: float) -> tuple[float, float]:
    """``(cos, tan)`` of half a sweep of at most 90 degrees: the middle weight of an
    exact arc and the height of its middle control point over the chord's start."""
    if sweep == 90:
        return math.sqrt(0.5), 1.0
    h = math.radians(sweep / 2)
    return math.cos(h), math.tan(h)


def _sweep(angle: float, what: str) -> float:
    angle = float(angle)
    if not 0 < angle <= 90:
        raise ValueError(f"{what}: the angle must be more than 0 and at most 90 degrees per patch, "
                         f"got {angle:g} (a larger one: several bodies)")
    return angle


def box(x: Sequence[float], y: Sequence[float], z: Sequence[float],
        faces: dict[str, str] | None = None) -> Volume:
    """The box ``[x0, x1] x [y0, y1] x [z0, z1]``: degree 1 in each direction, 2 x 2 x 2
    control points; faces :data:`BOX_FACES`."""
    xs, ys, zs = _pair(x, "x"), _pair(y, "y"), _pair(z, "z")
    zz, yy, xx = np.meshgrid(zs, ys, xs, indexing="ij")
    return Volume((1, 1, 1), ONE, ONE, ONE, np.stack([xx, yy, zz], axis=-1), np.ones((2, 2, 2)),
                  _named(BOX_FACES, faces))


def cylinder_sector(r_in: float, r_out: float, angles: Sequence[float] = (0.0, 90.0),
                    z: Sequence[float] = (0.0, 1.0), centre: Point = (0.0, 0.0),
                    faces: dict[str, str] | None = None) -> Volume:
    """The thick cylinder sector ``r_in <= r <= r_out`` about the line ``(x, y) = centre``
    parallel to z, from ``angles[0]`` to ``angles[1]`` (degrees, counter-clockwise seen
    from +z, at most 90 apart), ``z[0] <= z <= z[1]``. Degrees (2, 1, 1): xi along the
    angle (an exact rational quadratic arc), eta along z, zeta radial; 3 x 2 x 2 control
    points; faces :data:`CYLINDER_FACES`."""
    r_in, r_out = float(r_in), float(r_out)
    if not 0 < r_in < r_out:
        raise ValueError(f"cylinder sector: need 0 < r_in < r_out, got {r_in}, {r_out}")
    a0, a1 = (float(a) for a in angles)
    sweep = _sweep(a1 - a0, "cylinder sector")
    z0, z1 = _pair(z, "z")
    cw, _ = _half(sweep)
    c0, s0 = cos_sin(a0)
    c1, s1 = cos_sin(a1)
    cm, sm = cos_sin(a0 + sweep / 2)
    # the arc's control points on the unit circle: start, the tangents' meeting point, end
    unit = np.array([[c0, s0], [cm / cw, sm / cw], [c1, s1]])
    cp = np.zeros((2, 2, 3, 3))
    for k, r in enumerate((r_in, r_out)):
        for j, zj in enumerate((z0, z1)):
            cp[k, j, :, :2] = np.asarray(centre, dtype=float) + r * unit
            cp[k, j, :, 2] = zj
    w = np.broadcast_to(np.array([1.0, cw, 1.0]), (2, 2, 3)).copy()
    return Volume((2, 1, 1), ARC, ONE, ONE, cp, w, _named(CYLINDER_FACES, faces))


def shell_octant(r_in: float, r_out: float, centre: Point = (0.0, 0.0, 0.0),
                 faces: dict[str, str] | None = None) -> Volume:
    """The octant ``x, y, z >= centre`` of the thick spherical shell ``r_in <= |x - centre|
    <= r_out``: the exact rational NURBS octant, the tensor product of two quarter arcs
    (longitude and latitude; weights ``w_i w_j`` with ``w = (1, sqrt(1/2), 1)``) and a
    line. Degrees (2, 2, 1), 3 x 3 x 2 control points; xi along the longitude from the
    plane y = y_c to x = x_c, eta from the equator to the pole (the three control points
    of each pole row coincide: the face ``eta = 1`` collapses onto the axis, allowed as
    it lies on the boundary), zeta radial; faces :data:`SHELL_FACES`."""
    r_in, r_out = float(r_in), float(r_out)
    if not 0 < r_in < r_out:
        raise ValueError(f"shell octant: need 0 < r_in < r_out, got {r_in}, {r_out}")
    w45 = math.sqrt(0.5)
    lon = np.array([[1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])  # (x, y) of the longitude arc
    lat = np.array([[1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])  # (rho, z) of the latitude arc
    w = np.array([1.0, w45, 1.0])
    cp = np.zeros((2, 3, 3, 3))
    for k, r in enumerate((r_in, r_out)):
        for j in range(3):
            cp[k, j, :, :2] = r * lat[j, 0] * lon
            cp[k, j, :, 2] = r * lat[j, 1]
    cp += np.asarray(centre, dtype=float)
    weights = np.broadcast_to(np.outer(w, w), (2, 3, 3)).copy()
    return Volume((2, 2, 1), ARC, ARC, ONE, cp, weights, _named(SHELL_FACES, faces))


def ball_octant(radius: float, centre: Point = (0.0, 0.0, 0.0),
                faces: dict[str, str] | None = None) -> Volume:
    """The octant ``x >= x_c, y >= y_c, z <= z_c`` of the ball ``|x - centre| <= radius``
    (a quarter of the lower hemisphere) in spherical coordinates about the x axis,
    ``x = rho cos(theta)``, ``(y, z) = rho sin(theta) (cos(phi), sin(phi))``: xi along phi
    from -90 degrees (the plane y = y_c) to 0 (the plane z = z_c), eta along theta from
    90 degrees (the plane x = x_c) to 0 (the x axis), zeta along rho from the centre to
    the sphere. The exact rational NURBS: the tensor product of two quarter arcs (weights
    ``w_i w_j``, ``w = (1, sqrt(1/2), 1)``) and a line; degrees (2, 2, 1), 3 x 3 x 2
    control points, right-handed. The lowest point ``centre - (0, 0, radius)`` is the
    corner ``(xi, eta, zeta) = (0, 0, 1)`` of the sphere, where nothing degenerates; the
    faces ``eta = 1`` (onto the x axis) and ``zeta = 0`` (onto the centre) collapse, as
    the shell octant's pole (allowed: boundary faces). Faces :data:`BALL_FACES`."""
    radius = float(radius)
    if not radius > 0:
        raise ValueError(f"ball octant: need radius > 0, got {radius}")
    w45 = math.sqrt(0.5)
    phi = np.array([[0.0, -1.0], [1.0, -1.0], [1.0, 0.0]])  # (cos, sin) polygon, -90 .. 0 degrees
    theta = np.array([[0.0, 1.0], [1.0, 1.0], [1.0, 0.0]])  # (cos, sin) polygon, 90 .. 0 degrees
    cp = np.zeros((2, 3, 3, 3))
    for j in range(3):
        cp[1, j, :, 0] = radius * theta[j, 0]
        cp[1, j, :, 1:] = radius * theta[j, 1] * phi
    cp += np.asarray(centre, dtype=float)
    w = np.array([1.0, w45, 1.0])
    weights = np.broadcast_to(np.outer(w, w), (2, 3, 3)).copy()
    return Volume((2, 2, 1), ARC, ARC, ONE, cp, weights, _named(BALL_FACES, faces))


POLAR_BALL_FACES = {"symmetry_y": "xi0", "symmetry_x": "xi1", "axis": "eta0", "top": "eta1",
                    "centre": "zeta0", "outer": "zeta1"}
"""Face labels of a polar ball octant (:func:`polar_ball_octant`): ``symmetry_y`` the
plane y = y_c, ``symmetry_x`` the plane x = x_c, ``axis`` the face collapsed onto the
axis x = x_c, y = y_c below the centre, ``top`` the plane z = z_c, ``centre`` the face
collapsed onto the centre, ``outer`` the sphere (the contact face)."""


def polar_ball_octant(radius: float, centre: Point = (0.0, 0.0, 0.0),
                      faces: dict[str, str] | None = None) -> Volume:
    """The octant ``x >= x_c, y >= y_c, z <= z_c`` of the ball ``|x - centre| <= radius``,
    as :func:`ball_octant` but in spherical coordinates about the vertical axis through
    its lowest point, ``(x, y) = rho sin(theta) (cos(phi), sin(phi))``, ``z = -rho
    cos(theta)``: xi along phi from 0 (the plane y = y_c) to 90 degrees (x = x_c), eta
    along theta from 0 (the axis) to 90 degrees (the plane z = z_c), zeta along rho. Its
    knot lines of eta are circles about the lowest point ``centre - (0, 0, radius)``, so
    a contact zone about that point has its edge along a knot line, where a Cartesian
    grid cuts the edge at every angle (the 3D Hertz scene's ``--grid polar``). The face
    ``eta = 0`` collapses onto the axis (so the lowest point is a collapsed edge of the
    sphere face: the coincident control points there are separate unknowns, held
    together by the stiffness only) and ``zeta = 0`` onto the centre. Degrees (2, 2, 1),
    3 x 3 x 2 control points, right-handed; faces :data:`POLAR_BALL_FACES`."""
    w45 = math.sqrt(0.5)
    cp, weights = _polar_net(radius, centre, np.array([[1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]),
                             np.array([1.0, w45, 1.0]), "polar ball octant")
    return Volume((2, 2, 1), ARC, ARC, ONE, cp, weights, _named(POLAR_BALL_FACES, faces))


def _polar_net(radius: float, centre: Point, phi: np.ndarray, w_phi: np.ndarray,
               what: str) -> tuple[np.ndarray, np.ndarray]:
    """Control points (2, 3, n, 3) and weights of a ball in spherical coordinates about
    the vertical axis through its lowest point: the azimuth's (cos, sin) polygon ``phi``
    (n, 2) with its weights ``w_phi``, times the polar angle's quarter arc from the axis
    (theta 0 .. 90 degrees) and a line from the centre to the sphere."""
    radius = float(radius)
    if not radius > 0:
        raise ValueError(f"{what}: need radius > 0, got {radius}")
    theta = np.array([[0.0, 1.0], [1.0, 1.0], [1.0, 0.0]])  # (sin, cos) polygon, 0 .. 90 degrees
    cp = np.zeros((2, 3, len(phi), 3))
    for j in range(3):
        cp[1, j, :, :2] = radius * theta[j, 0] * phi
        cp[1, j, :, 2] = -radius * theta[j, 1]
    cp += np.asarray(centre, dtype=float)
    w_theta = np.array([1.0, math.sqrt(0.5), 1.0])
    return cp, np.broadcast_to(np.outer(w_theta, w_phi), (2, 3, len(phi))).copy()


POLAR_HALF_FACES = {"symmetry_y": "xi0", "symmetry_y_back": "xi1", "axis": "eta0", "top": "eta1",
                    "centre": "zeta0", "outer": "zeta1"}
"""Face labels of a polar half ball (:func:`polar_half_ball`): ``symmetry_y`` and
``symmetry_y_back`` the halves x >= x_c and x <= x_c of the plane y = y_c, ``axis``,
``top``, ``centre`` and ``outer`` as the polar ball octant's."""
HALF_TURN = np.array([0.0, 0.0, 0.0, 0.5, 0.5, 1.0, 1.0, 1.0])
"""Knots of two rational quadratic quarter arcs (a C0 knot between them)."""


def polar_half_ball(radius: float, centre: Point = (0.0, 0.0, 0.0),
                    faces: dict[str, str] | None = None) -> Volume:
    """The half ``y >= y_c, z <= z_c`` of the lower hemisphere of the ball ``|x - centre|
    <= radius``, in the polar ball octant's coordinates (:func:`polar_ball_octant`) with
    phi from 0 to 180 degrees (two exact quarter arcs, the knot between them on the
    plane x = x_c): the knot lines of eta are half circles about the lowest point, for a
    contact sheared along x (the 3D Cattaneo-Mindlin scene's ``--grid polar``). Degrees
    (2, 2, 1), 5 x 3 x 2 control points, right-handed; the faces ``eta = 0`` (the axis)
    and ``zeta = 0`` (the centre) collapse; faces :data:`POLAR_HALF_FACES`."""
    w45 = math.sqrt(0.5)
    phi = np.array([[1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [-1.0, 1.0], [-1.0, 0.0]])  # 0 .. 180 degrees
    cp, weights = _polar_net(radius, centre, phi, np.array([1.0, w45, 1.0, w45, 1.0]), "polar half ball")
    return Volume((2, 2, 1), HALF_TURN, ARC, ONE, cp, weights, _named(POLAR_HALF_FACES, faces))


DISC_FACES = {"axis": "xi0", "rim": "xi1", "symmetry_y": "eta0", "symmetry_x": "eta1",
              "bottom": "zeta0", "top": "zeta1"}
"""Face labels of a polar quarter cylinder (:func:`polar_quarter_cylinder`): ``axis`` the
face collapsed onto the axis, ``rim`` the cylinder, ``symmetry_y``/``symmetry_x`` the
planes y = y_c / x = x_c, ``bottom``/``top`` z = z0 / z1 (``top``: the contact face)."""


def polar_quarter_cylinder(radius: float, z: Sequence[float], centre: Sequence[float] = (0.0, 0.0),
                           faces: dict[str, str] | None = None) -> Volume:
    """The quarter ``x >= x_c, y >= y_c`` of the solid cylinder ``|(x, y) - centre| <=
    radius``, ``z0 <= z <= z1``, in cylindrical coordinates: xi along the distance r from
    the axis (degree 1: the face ``xi = 0`` collapses onto the axis), eta along the angle
    from 0 (the plane y = y_c) to 90 degrees (one exact rational arc), zeta along z. Its
    knot lines of xi on the top face are circles about the axis, as a polar ball's
    (:func:`polar_ball_octant`): the elastic half-space under it in the 3D Hertz scene's
    polar grid. Right-handed; faces :data:`DISC_FACES`."""
    radius = float(radius)
    z0, z1 = _pair(z, "z")
    if not radius > 0:
        raise ValueError(f"polar quarter cylinder: need radius > 0, got {radius}")
    phi = np.array([[1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])  # (cos, sin) polygon, 0 .. 90 degrees
    cp = np.zeros((2, 3, 2, 3))
    for k, zk in enumerate((z0, z1)):
        cp[k, :, 1, :2] = radius * phi
        cp[k, :, :, :2] += np.asarray(centre, dtype=float)
        cp[k, :, :, 2] = zk
    weights = np.broadcast_to(np.array([1.0, math.sqrt(0.5), 1.0])[None, :, None], (2, 3, 2)).copy()
    return Volume((1, 2, 1), ONE, ARC, ONE, cp, weights, _named(DISC_FACES, faces))


HALF_SHELL_FACES = {"symmetry_y": "xi0", "top": "xi1", "end_xneg": "eta0", "end_xpos": "eta1",
                    "inner": "zeta0", "outer": "zeta1"}
"""Face labels of a half ball shell (:func:`half_ball_shell`): ``symmetry_y`` the plane
y = y_c, ``top`` the plane z = z_c, ``end_xneg`` and ``end_xpos`` the cones about the x
axis at x < x_c and x > x_c, ``inner`` the inner sphere, ``outer`` the sphere (the
contact face)."""


def half_ball_shell(radius: float, inner: float, cone: float, centre: Point = (0.0, 0.0, 0.0),
                    faces: dict[str, str] | None = None) -> Volume:
    """The half ``y >= y_c, z <= z_c`` of the lower hemisphere of the shell ``inner <=
    |x - centre| <= radius`` within ``cone`` degrees (< 90) of the plane x = x_c, in
    spherical coordinates about the x axis as :func:`ball_octant`: xi along phi from -90
    degrees (the plane y = y_c) to 0 (the plane z = z_c), eta along theta from 90 + cone
    to 90 - cone degrees (x from negative to positive), zeta along rho from ``inner`` to
    ``radius``. Exact: the tensor product of a quarter arc, one rational quadratic arc of
    2 cone degrees (weights ``(1, cos(cone), 1)``) and a line; degrees (2, 2, 1), right-handed,
    nothing collapses. The lowest point ``centre - (0, 0, radius)`` is the middle of the
    edge ``xi = 0, zeta = 1`` (eta = 1/2) of the sphere face: a half model of a ball pressed
    and sheared along x keeps its contact away from every edge but the symmetry plane's.
    Faces :data:`HALF_SHELL_FACES`."""
    radius, inner, cone = float(radius), float(inner), float(cone)
    if not (0.0 < inner < radius and 0.0 < cone < 90.0):
        raise ValueError(f"half ball shell: need 0 < inner < radius and 0 < cone < 90 degrees, got "
                         f"inner {inner}, radius {radius}, cone {cone}")
    t = math.radians(cone)
    phi = np.array([[0.0, -1.0], [1.0, -1.0], [1.0, 0.0]])  # (cos, sin) polygon, -90 .. 0 degrees
    theta = np.array([[-math.sin(t), math.cos(t)], [0.0, 1.0 / math.cos(t)], [math.sin(t), math.cos(t)]])
    cp = np.zeros((2, 3, 3, 3))
    for k, rho in enumerate((inner, radius)):
        for j in range(3):
            cp[k, j, :, 0] = rho * theta[j, 0]
            cp[k, j, :, 1:] = rho * theta[j, 1] * phi
    cp += np.asarray(centre, dtype=float)
    w_phi, w_theta = np.array([1.0, math.sqrt(0.5), 1.0]), np.array([1.0, math.cos(t), 1.0])
    weights = np.broadcast_to(np.outer(w_theta, w_phi), (2, 3, 3)).copy()
    return Volume((2, 2, 1), ARC, ARC, ONE, cp, weights, _named(HALF_SHELL_FACES, faces))


def _clockwise(patch: Patch, name: str) -> bool:
    """``patch`` checked (:func:`pre.geometry.check_patch`); whether it runs clockwise
    (det J < 0, as the annular sectors, xi along the arcs and eta outwards)."""
    check_patch(name, patch)
    return float(np.median(jacobian_signs(patch, 8))) < 0


def _right_handed(vol: Volume, clockwise: bool) -> Volume:
    """A volume swept from a patch, right-handed: for a clockwise patch its sweep
    direction xi is reversed (the ends' names swapped along; the patch's own
    parametrization, along eta and zeta, is kept)."""
    if not clockwise:
        return vol
    faces = {**vol.faces, "xi0": vol.faces["xi1"], "xi1": vol.faces["xi0"]}
    return Volume(vol.degree, 1.0 - vol.knots_xi[::-1], vol.knots_eta, vol.knots_zeta,
                  vol.control_points[:, :, ::-1].copy(), vol.weights[:, :, ::-1].copy(), faces)


def _sweep_faces(patch: Patch, ends: Sequence[str], what: str) -> dict[str, str]:
    names = {"xi0": ends[0], "xi1": ends[1], "eta0": patch.edges["xi0"], "eta1": patch.edges["xi1"],
             "zeta0": patch.edges["eta0"], "zeta1": patch.edges["eta1"]}
    if len(set(names.values())) != 6:
        raise ValueError(f"{what}: the end faces {list(ends)} need names other than the patch's edges "
                         f"{[patch.edges[k] for k in ('xi0', 'xi1', 'eta0', 'eta1')]} (pass ends=...)")
    return names


def extrude(patch: Patch, z: Sequence[float] = (0.0, 1.0),
            ends: Sequence[str] = SWEEP_ENDS["extrude"]) -> Volume:
    """The 2D body ``patch`` (in the plane z = 0, edges named) swept along z from
    ``z[0]`` to ``z[1]``. Degrees ``(1, p_xi, p_eta)``, ``2 x n_xi x n_eta`` control
    points: xi along z, ``(eta, zeta)`` the patch's ``(xi, eta)``. Faces: ``ends``
    (default ``back``, z = z0, and ``front``, z = z1) at xi = 0 and 1, the patch's edges
    ``xi0``, ``xi1``, ``eta0``, ``eta1`` at eta = 0, eta = 1, zeta = 0, zeta = 1 (its
    contact edge becomes the contact face). A clockwise patch (det J < 0, as an
    :func:`pre.geometry.annular_sector`) is swept the other way, xi from z1 to z0
    (``front`` at xi = 0), so that the volume is right-handed."""
    clockwise = _clockwise(patch, "extruded patch")
    z0, z1 = _pair(z, "z")
    n_eta2, n_xi2 = patch.shape
    cp = np.zeros((n_eta2, n_xi2, 2, 3))
    cp[..., :2] = patch.control_points[:, :, None, :]
    cp[..., 2] = [z0, z1]
    w = np.repeat(patch.weights[:, :, None], 2, axis=2)
    return _right_handed(Volume((1, *patch.degree), ONE, patch.knots_xi, patch.knots_eta, cp, w,
                                _sweep_faces(patch, ends, "extrude")), clockwise)


def revolve(patch: Patch, angle: float = 90.0, axis_point: Point = (0.0, 0.0),
            axis_direction: Point = (0.0, 1.0), ends: Sequence[str] = SWEEP_ENDS["revolve"]) -> Volume:
    """The 2D body ``patch`` (in the plane z = 0, edges named, on one side of the axis)
    revolved by ``angle`` degrees (more than 0, at most 90) about the axis through
    ``axis_point`` along ``axis_direction`` (both in the plane z = 0), turning out of
    the plane towards +z. Degrees ``(2, p_xi, p_eta)``, ``3 x n_xi x n_eta`` control
    points: xi along the angle (exact rational quadratic arcs), ``(eta, zeta)`` the
    patch's ``(xi, eta)``. Faces: ``ends`` (default ``plane``, the patch itself, and
    ``turned``, the patch turned) at xi = 0 and 1 (swapped for a clockwise patch, whose xi
    runs from the end back to the start, as in :func:`extrude`), the patch's edges at
    eta = 0, 1 and zeta = 0, 1 as in :func:`extrude`. An edge on the axis makes a face
    collapsed onto it (allowed); a patch across the axis is refused."""
    clockwise = _clockwise(patch, "revolved patch")
    sweep = _sweep(angle, "revolve")
    a = np.asarray(axis_direction, dtype=float)
    if a.shape != (2,) or not np.linalg.norm(a) > 0:
        raise ValueError(f"revolve: axis_direction must be a non-zero [x, y], got {list(axis_direction)}")
    a = a / np.linalg.norm(a)
    c = np.asarray(axis_point, dtype=float)
    v = patch.control_points - c  # (n_eta, n_xi, 2)
    side = a[0] * v[..., 1] - a[1] * v[..., 0]  # > 0: left of the axis
    size = float(np.abs(v).max())
    if side.max() > 1e-12 * size and side.min() < -1e-12 * size:
        raise ValueError("revolve: the patch's control points lie on both sides of the axis")
    if side.max() <= 1e-12 * size:  # on the right: turn about -a, so that it rises towards +z
        a, side = -a, -side
    along = (v @ a)[..., None] * a  # the axial part of each control point
    radial = v - along  # in the plane, perpendicular to the axis; its length is `side`
    cw, tw = _half(sweep)
    cos_t, sin_t = cos_sin(sweep)
    n_eta2, n_xi2 = patch.shape
    cp = np.zeros((n_eta2, n_xi2, 3, 3))
    rows = [(radial, 0.0 * side), (radial, side * tw), (radial * cos_t, side * sin_t)]
    for i, (in_plane, height) in enumerate(rows):
        cp[:, :, i, :2] = c + along + in_plane
        cp[:, :, i, 2] = height
    w = patch.weights[:, :, None] * np.array([1.0, cw, 1.0])
    return _right_handed(Volume((2, *patch.degree), ARC, patch.knots_xi, patch.knots_eta, cp, w,
                                _sweep_faces(patch, ends, "revolve")), clockwise)


def solid(spline: splipy.Volume, faces: dict[str, str]) -> Volume:
    """A splipy volume as a body: 3D control points, parameters rescaled to [0, 1]^3,
    ``faces`` naming ``xi0``, ``xi1``, ``eta0``, ``eta1``, ``zeta0``, ``zeta1``."""
    if spline.pardim != 3:
        raise ValueError(f"a volume has 3 parametric directions, the splipy object has {spline.pardim}")
    missing = set(FACE_KEYS) - set(faces)
    if missing:
        raise ValueError(f"name every face: missing {sorted(missing)}")
    s = spline.clone()
    if s.dimension != 3:
        s.set_dimension(3)
    s.reparam()
    return volume_from_splipy(s, {k: faces[k] for k in FACE_KEYS})


def read_g2_volumes(path: str | Path) -> list[splipy.Volume]:
    """The volumes of a GoTools ``.g2`` file (splipy's reader), in the file's order."""
    return [o for o in read_g2(path) if o.pardim == 3]


def write_volumes(path: str | Path, bodies: dict[str, Volume | splipy.Volume], scene: str = "",
                  units: str = "mm, N", faces: dict[str, dict[str, str]] | None = None) -> Path:
    """Check every volume (:func:`pre.volume.check_volume`) and write the geometry file
    of volumes (root ``dimension = 3``); splipy volumes are converted with :func:`solid`
    (their face names from ``faces[name]``). Returns the path."""
    if not bodies:
        raise ValueError("no bodies to write")
    volumes = {}
    for name, b in bodies.items():
        vol = b if isinstance(b, Volume) else solid(b, (faces or {}).get(name, {}))
        check_volume(name, vol)
        volumes[name] = vol
    path = Path(path)
    write_geometry(path, scene or path.stem, volumes, units=units,
                   generator="voiga pre (python -m pre geometry3d)")
    return path
