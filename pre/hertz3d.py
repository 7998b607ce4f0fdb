"""The 3D Hertz scene of issue 42 (``python -m pre hertz3d OUTDIR``): a quarter of the
lower hemisphere of a ball pressed onto a rigid plane.

Geometry: the octant ``x >= 0, y >= 0, z <= 0`` of the ball ``|X| <= R`` centred at the
origin (:func:`pre.solids.ball_octant`, one exact NURBS volume in spherical coordinates
about the x axis), its flat top at z = 0, touching the rigid plane z = -R at its lowest
point (0, 0, -R). That point is the corner ``(xi, eta, zeta) = (0, 0, 1)`` of the sphere
face ``outer``, where the map is regular; the two collapsed faces (``centre``, the ball's
centre, and ``axis``, the x axis) are on the top face's edges, far from the contact.

Loads, as the 2D hertz scene's: the top face moves down by the indentation d (``uz =
-d``) in :data:`pre.cases.HERTZ_STEPS` steps, ``ux = 0`` on the symmetry face x = 0 and
``uy = 0`` on y = 0, frictionless GPTS contact of the sphere face with the rigid plane
(penalty automatic unless given). ``&output`` asks for the stress at the last step, for
the subsurface shear of ``python -m post hertz3d``.

Mesh m<k> (:data:`MESHES`): along both angles, ``fine`` elements uniform in angle over
``theta_c = asin(1.5 a_est / R)`` from the lowest point (the 2D hertz scene's zone,
:func:`pre.meshes.hertz_theta_c`), then ``rest`` growing geometrically to 90 degrees
(:func:`pre.meshes.graded_angles`), mapped to the arc parameters exactly
(:func:`pre.meshes.arc_parameter_exact`); radially ``radial`` elements graded toward the
sphere, the surface element as long as the fine ones (:func:`pre.meshes.hertz_eta_knots`).
``a_est = sqrt(R d)`` is Hertz's half-width for a sphere whose approach to the plane is
d (a sphere on a rigid flat: ``d = a^2 / R``); the top face's d also holds the
compression of the hemisphere itself, so the run's a is somewhat smaller.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .cases import GEOMETRY_FILE, HERTZ_STEPS, case_stem, to_namelist_text
from .files import write_text
from .h5io import write_geometry
from .hertz import Cylinder, HertzCaseError, write_shared_geometry
from .meshes import arc_parameter_exact, graded_angles, hertz_eta_knots, hertz_theta_c
from .solid_case import knotted_body_group, solid_dofs
from .solids import ball_octant
from .volume import Volume, check_volume

SOLID_METHOD = "mortar"
"""The contact method the cases name: voiga's default on solids (GPTS's n_gauss^2
constraints per face cell lock; docs/verification-faces.md)."""

SCENE = "hertz3d"
BODY = "ball"
CONTACT_FACE = "outer"
"""The sphere face (rho = R) of :func:`pre.solids.ball_octant`."""
MATERIALS = ("linear", "neo-hookean")

MESHES: dict[str, tuple[int, int, int]] = {
    "m1": (5, 5, 5),
    "m2": (7, 7, 7),
    "m3": (10, 10, 10),
    "m4": (15, 13, 13),
}
"""Mesh -> (fine, rest, radial) elements: along each angle ``fine`` over the contact
zone and ``rest`` beyond, radially ``radial`` (NN2.2: about 5,700 to 60,000 DOFs)."""

LAYOUTS: tuple[str, ...] = ("N2", "N3", "NN2.1", "NN2.2")
"""The layouts of the study (any solid layout is accepted)."""

FIELD_SAMPLES = 3
"""``&output samples``: the element's ends and centre along each direction."""


@dataclass(frozen=True)
class Ball(Cylinder):
    """A Hertz problem of a sphere: radius, material, indentation (consistent units);
    the values and their ranges are :class:`pre.hertz.Cylinder`'s, plus the material law."""

    material: str = "linear"

    def check(self) -> None:
        """HertzCaseError naming the first value out of range."""
        super().check()
        if self.material not in MATERIALS:
            raise HertzCaseError(f"material {self.material!r} must be one of {', '.join(MATERIALS)}")

    @property
    def half_width(self) -> float:
        """Estimated contact radius ``a = sqrt(R d)`` (Hertz, sphere on a rigid flat)."""
        return math.sqrt(self.radius * self.indentation)


def ball_geometry(ball: Ball) -> dict[str, Volume]:
    """The body of the scene: the ball octant of radius R, faces of :data:`pre.solids.BALL_FACES`."""
    return {BODY: ball_octant(ball.radius)}


def ball_knots(ball: Ball, mesh: str) -> dict[str, list[float]]:
    """``knots_xi``, ``knots_eta``, ``knots_zeta`` of mesh ``mesh`` (module docstring):
    both angles graded alike from the lowest point (xi along phi, eta along theta, each
    starting there), rho graded toward the sphere."""
    if mesh not in MESHES:
        raise HertzCaseError(f"mesh {mesh!r}: one of {', '.join(MESHES)}")
    fine, rest, radial = MESHES[mesh]
    theta_c = hertz_theta_c(ball.half_width / ball.radius)
    angle = [arc_parameter_exact(a) for a in graded_angles(theta_c, fine, rest)]
    rho = hertz_eta_knots(radial, theta_c / fine, thickness=1.0)
    return {"knots_xi": angle, "knots_eta": list(angle), "knots_zeta": [float(k) for k in rho]}


def ball_case(ball: Ball, mesh: str, layout: str, n_steps: int | None = None,
              method: str = SOLID_METHOD, penalty_normal: float | None = None) -> dict[str, Any]:
    """The namelist groups of the case ``mesh``, ``layout`` (module docstring).
    ``penalty_normal``: None leaves it to voiga (automatic)."""
    ball.check()
    knots = ball_knots(ball, mesh)
    vol = ball_geometry(ball)[BODY]
    spec = {"name": BODY, "layout": layout, "contact_face": CONTACT_FACE, "material": ball.material,
            "youngs_modulus": ball.youngs_modulus, "poisson_ratio": ball.poisson_ratio}
    try:
        body = knotted_body_group(spec, vol, knots)
    except ValueError as err:
        raise HertzCaseError(str(err)) from None
    if n_steps is not None and n_steps < 1:
        raise HertzCaseError(f"steps {n_steps} must be >= 1")
    contact: dict[str, Any] = {"slave": BODY, "master": "rigid",
                               "rigid_point": [0.0, 0.0, -float(ball.radius)],
                               "rigid_normal": [0.0, 0.0, 1.0], "method": method}
    if penalty_normal is not None:
        if not (isinstance(penalty_normal, (int, float)) and 0 < penalty_normal < math.inf):
            raise HertzCaseError(f"penalty_normal {penalty_normal!r} must be > 0")
        contact["penalty_normal"] = float(penalty_normal)
    title = (f"hertz3d {mesh} {layout}: ball octant R = {ball.radius:g}, E = {ball.youngs_modulus:g}, "
             f"nu = {ball.poisson_ratio:g}, {ball.material}, indentation {ball.indentation:g}")
    return {"case": {"title": title, "scene": SCENE, "mesh": mesh, "layout": layout,
                     "geometry": GEOMETRY_FILE, "output": f"{case_stem(mesh, layout)}.h5", "n_bodies": 1},
            "body": [body],
            "solver": {"n_steps": int(n_steps or HERTZ_STEPS)},
            "dirichlet": [
                {"body": BODY, "face": "top", "fix_z": True, "uz": -float(ball.indentation)},
                {"body": BODY, "face": "symmetry_x", "fix_x": True},
                {"body": BODY, "face": "symmetry_y", "fix_y": True},
            ],
            "contact": [contact],
            "output": {"fields": ["stress"], "samples": FIELD_SAMPLES, "every": 0}}


def case_dofs(ball: Ball, mesh: str, layout: str) -> dict[str, int]:
    """The DOFs of a case (:func:`pre.solid_case.solid_dofs`)."""
    return solid_dofs(ball_case(ball, mesh, layout)["body"][0], ball_geometry(ball)[BODY])


def write_hertz3d(ball: Ball, meshes: Sequence[str], layouts: Sequence[str], out: str | Path,
                  force: bool = False, **options: Any) -> tuple[Path, list[Path], bool]:
    """Write ``out/geometry.h5`` and ``out/<mesh>-<layout>.nml`` for every mesh and
    layout (``options``: :func:`ball_case`'s). Existing case files, or a geometry file of
    another ball, are refused (HertzCaseError, nothing written) unless ``force``; a
    geometry file with the same contents is kept. Returns ``(geometry, cases, geometry
    written)``."""
    texts = {case_stem(m, lay): to_namelist_text(ball_case(ball, m, lay, **options))
             for m in meshes for lay in layouts}
    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    cases = [folder / f"{stem}.nml" for stem in texts]
    bodies = ball_geometry(ball)
    for name, vol in bodies.items():
        check_volume(name, vol)

    def geometry_file(path: Path) -> None:
        write_geometry(path, SCENE, bodies, generator="voiga pre (python -m pre hertz3d)")

    geometry, fresh = write_shared_geometry(folder, geometry_file, cases, force, other="another ball")
    for case, text in zip(cases, texts.values(), strict=True):
        write_text(case, text)
    return geometry, cases, fresh
