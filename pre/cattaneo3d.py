"""The 3D Cattaneo-Mindlin scene of issue 42 (``python -m pre cattaneo3d OUTDIR``): half
of a ball pressed onto a rigid plane without friction, then sheared along x with Coulomb
friction (docs/cattaneo3d.md).

Geometry: the half ``y >= 0, z <= 0`` of the lower hemisphere of a ball of radius R,
centred at the origin, cut to a shell (inner radius :data:`INNER` R) and to within
:data:`CONE` degrees of the plane x = 0 (:func:`pre.solids.half_ball_shell`: one exact
NURBS volume, nothing collapsed). The lowest point (0, 0, -R), where the ball first
touches the rigid plane z = -R, lies on the symmetry face y = 0, in the middle of the
sphere face's edge there.

Loads, in two phases: the press (``press_steps``) moves the top face z = 0 down by the
indentation d with u_x = u_y = 0 there, frictionless (``friction = 0.0, mu``: a rigid
flat pressed with friction leaves a stick traction Cattaneo-Mindlin does not have,
docs/verification.md); the shear (``shear_steps``) keeps the top and moves the rigid
plane by ``shear`` along x, with friction mu. ``u_y = 0`` on the symmetry face. The
contact method is voiga's default on solids unless ``method`` is given.

Mesh m<k> (:data:`pre.hertz3d.MESHES`: fine, rest, radial): along phi (xi) ``fine``
elements uniform in angle over ``theta_c`` from the lowest point
(:func:`pre.meshes.hertz_theta_c`), then ``rest`` growing to 90 degrees; along theta (eta)
the same on each side of 90 degrees (twice as many elements, a knot line through the
lowest point); radially ``radial`` elements graded toward the sphere, the surface element
as long as the fine ones.

The shear: Mindlin's tangential compliance of the contact for Q = ``target`` mu P plus
the ball's own (:data:`BODY_COMPLIANCE`), so that the run ends near
Q/(mu P) = ``target``; ``post cattaneo3d`` measures the Q/(mu P) reached."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .cases import GEOMETRY_FILE, case_stem, to_namelist_text
from .h5io import write_geometry
from .hertz import EDGE_BAND, HertzCaseError, split_spans, write_scene3d_folder
from .hertz3d import GRIDS, MESHES, POLAR_MESHES, _solid_group
from .meshes import arc_parameter_exact, graded_angles, hertz_eta_knots, hertz_theta_c
from .solid_case import solid_dofs
from .solids import half_ball_shell, polar_half_ball
from .volume import Volume

SCENE = "cattaneo3d"
BODY = "ball"
CONTACT_FACE = "outer"
INNER = 0.05
"""Inner radius of the shell over R (the 2D scenes' hole)."""
CONE = 60.0
"""The body spans theta = 90 +- CONE degrees about the x axis (|x| <= R sin(CONE))."""
PHI_ELEMENTS = 4
"""Elements along each quarter of phi on the polar grid: the shear's field varies as cos 2
phi, which the geometry's rational arc does not hold exactly (the press's does)."""
BODY_COMPLIANCE = 1.0
"""The ball's own tangential compliance beyond the contact's, times G R (see
:meth:`HalfBall.shear_for`): the half shell's top held, measured from the plane's move and
Q/(mu P) of an m1 N2 run (1.0; an estimate, the run measures what it reaches)."""


@dataclass(frozen=True)
class HalfBall:
    """A Cattaneo-Mindlin problem of a sphere on a rigid flat (consistent units)."""

    radius: float = 1.0
    youngs_modulus: float = 1.0
    poisson_ratio: float = 0.3
    indentation: float = 0.01
    friction: float = 0.3
    target: float = 0.5
    """Q / (mu P) the shear aims at (:meth:`shear_for`)."""
    shear: float | None = None
    """The rigid plane's move along x in the shear phase (None: :meth:`shear_for` target)."""
    press_steps: int = 10
    shear_steps: int = 10
    method: str | None = None
    """``&contact method`` (None: voiga's default on solids)."""
    grid: str = "cartesian"
    """:data:`pre.hertz3d.GRIDS`: the half shell, or the polar half ball (module docstring)."""

    def check(self) -> None:
        """HertzCaseError naming the first value out of range."""
        for name in ("radius", "youngs_modulus", "poisson_ratio", "indentation", "friction", "target"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v)):
                raise HertzCaseError(f"{name.replace('_', ' ')} {v!r} is not a finite number")
        if self.radius <= 0 or self.youngs_modulus <= 0:
            raise HertzCaseError("radius and youngs modulus must be > 0")
        if not -1.0 < self.poisson_ratio < 0.5:
            raise HertzCaseError(f"poisson ratio {self.poisson_ratio:g} must be in (-1, 0.5)")
        if not 0.0 < self.indentation < 0.1 * self.radius:
            raise HertzCaseError(f"indentation {self.indentation:g} must be > 0 and < radius/10")
        if not self.friction > 0:
            raise HertzCaseError(f"friction {self.friction:g} must be > 0 (Cattaneo-Mindlin needs mu)")
        if not 0.0 < self.target < 1.0:
            raise HertzCaseError(f"target Q/(mu P) {self.target:g} must be in (0, 1) (1: gross slip)")
        if self.shear is not None and not (math.isfinite(self.shear) and self.shear > 0):
            raise HertzCaseError(f"shear {self.shear!r} must be > 0")
        if self.grid not in GRIDS:
            raise HertzCaseError(f"grid {self.grid!r} must be one of {', '.join(GRIDS)}")
        if self.press_steps < 1 or self.shear_steps < 1:
            raise HertzCaseError("press and shear steps must be >= 1")

    @property
    def half_width(self) -> float:
        """Estimated contact radius ``a = sqrt(R d)`` (Hertz, sphere on a rigid flat)."""
        return math.sqrt(self.radius * self.indentation)

    def shear_for(self, target: float) -> float:
        """The plane's move for Q/(mu P) = ``target``: Mindlin's (Johnson, Contact
        Mechanics, eq. 7.42 with a rigid flat) ``3 mu P (2 - nu) / (16 G a) (1 - (1 -
        target)^(2/3))`` plus the ball's own ``BODY_COMPLIANCE target mu P / (G R)``, with
        Hertz's P and a of the approach d (estimates: the run measures what it reached)."""
        nu, g = self.poisson_ratio, self.youngs_modulus / (2.0 * (1.0 + self.poisson_ratio))
        a = self.half_width
        force = 4.0 / 3.0 * self.youngs_modulus / (1.0 - nu**2) * math.sqrt(self.radius) * self.indentation**1.5
        contact = 3.0 * self.friction * force * (2.0 - nu) / (16.0 * g * a) * (1.0 - (1.0 - target) ** (2.0 / 3.0))
        return contact + BODY_COMPLIANCE * target * self.friction * force / (g * self.radius)

    @property
    def plane_shear(self) -> float:
        """The rigid plane's move in the shear phase."""
        return float(self.shear) if self.shear is not None else self.shear_for(self.target)


def ball_knots(ball: HalfBall, mesh: str) -> dict[str, list[float]]:
    """``knots_xi`` (phi), ``knots_eta`` (theta, symmetric about the lowest point),
    ``knots_zeta`` (rho) of mesh ``mesh`` (module docstring)."""
    if ball.grid == "polar":
        return polar_knots(ball, mesh)
    if mesh not in MESHES:
        raise HertzCaseError(f"mesh {mesh!r}: the cartesian grid's meshes are {', '.join(MESHES)}")
    fine, rest, radial = MESHES[mesh]
    theta_c = hertz_theta_c(ball.half_width / ball.radius)
    phi = [arc_parameter_exact(a) for a in graded_angles(theta_c, fine, rest)]
    cone = math.radians(CONE)
    side = graded_angles(theta_c, fine, rest, sweep=cone)
    angles = [cone - g for g in reversed(side)] + [cone] + [cone + g for g in side]
    theta = [arc_parameter_exact(a, sweep=2.0 * cone) for a in angles]
    thickness = 1.0 - INNER
    rho = hertz_eta_knots(radial, theta_c / fine / thickness, thickness=1.0)
    return {"knots_xi": phi, "knots_eta": theta, "knots_zeta": [float(k) for k in rho]}


def polar_knots(ball: HalfBall, mesh: str) -> dict[str, list[float]]:
    """The knots of a polar mesh (:data:`pre.hertz3d.POLAR_MESHES`): :data:`PHI_ELEMENTS`
    uniform along each quarter of phi (the C0 knot at 90 degrees kept once); theta graded
    as the 3D Hertz scene's with the spans over :data:`pre.hertz.EDGE_BAND` of both
    expected edges, the contact's a = sqrt(R d) and the stick zone's c = a (1 -
    target)^(1/3), split into ``edge``; rho graded toward the sphere."""
    if mesh not in POLAR_MESHES:
        raise HertzCaseError(f"mesh {mesh!r}: the polar grid's meshes are {', '.join(POLAR_MESHES)}")
    fine, rest, radial, edge = POLAR_MESHES[mesh]
    a = ball.half_width / ball.radius
    theta_c = hertz_theta_c(a)
    theta = [arc_parameter_exact(t) for t in graded_angles(theta_c, fine, rest)]
    bands = [tuple(arc_parameter_exact(math.asin(f * r)) for f in EDGE_BAND)
             for r in (a, a * (1.0 - ball.target) ** (1.0 / 3.0))]
    n = 2 * PHI_ELEMENTS
    return {"knots_xi": [k / n for k in range(1, n) if 2 * k != n],
            "knots_eta": split_spans(theta, bands, edge),
            "knots_zeta": [float(k) for k in hertz_eta_knots(radial, theta_c / fine, thickness=1.0)]}


def ball_geometry(ball: HalfBall) -> dict[str, Volume]:
    """The scene's one body (:func:`pre.solids.half_ball_shell`, or
    :func:`pre.solids.polar_half_ball` on the polar grid)."""
    if ball.grid == "polar":
        return {BODY: polar_half_ball(ball.radius)}
    return {BODY: half_ball_shell(ball.radius, INNER * ball.radius, CONE)}


def ball_case(ball: HalfBall, mesh: str, layout: str) -> dict[str, Any]:
    """The namelist groups of the case ``mesh``, ``layout`` (module docstring)."""
    ball.check()
    vol = ball_geometry(ball)[BODY]
    body = _solid_group(BODY, vol, ball_knots(ball, mesh), layout, CONTACT_FACE, "linear",
                        ball.youngs_modulus, ball.poisson_ratio)
    d, s, r = float(ball.indentation), ball.plane_shear, float(ball.radius)
    symmetry = ["symmetry_y", "symmetry_y_back"] if ball.grid == "polar" else ["symmetry_y"]
    contact: dict[str, Any] = {"slave": BODY, "master": "rigid", "rigid_point": [0.0, 0.0, -r],
                               "rigid_normal": [0.0, 0.0, 1.0], "friction": [0.0, float(ball.friction)],
                               "rigid_ux": [0.0, s]}
    if ball.method is not None:
        contact["method"] = ball.method
    grid = " (polar grid)" if ball.grid == "polar" else ""
    title = (f"cattaneo3d {mesh} {layout}: half ball{grid} R = {r:g}, E = {ball.youngs_modulus:g}, "
             f"nu = {ball.poisson_ratio:g}, pressed {d:g} without friction, sheared {s:.4g} with mu = "
             f"{ball.friction:g}")
    return {"case": {"title": title, "scene": SCENE, "mesh": mesh, "layout": layout,
                     "geometry": GEOMETRY_FILE, "output": f"{case_stem(mesh, layout)}.h5", "n_bodies": 1},
            "body": [body],
            "solver": {"n_steps": [int(ball.press_steps), int(ball.shear_steps)]},
            "dirichlet": [{"body": BODY, "face": "top", "fix_x": True, "fix_y": True, "fix_z": True,
                           "ux": [0.0, 0.0], "uy": [0.0, 0.0], "uz": [-d, -d]},
                          *({"body": BODY, "face": f, "fix_y": True} for f in symmetry)],
            "contact": [contact]}


def case_dofs(ball: HalfBall, mesh: str, layout: str) -> dict[str, int]:
    """Body name -> its DOFs in a case."""
    return {BODY: solid_dofs(ball_case(ball, mesh, layout)["body"][0], ball_geometry(ball)[BODY])["total"]}


def write_cattaneo3d(ball: HalfBall, meshes: Sequence[str], layouts: Sequence[str], out: str | Path,
                     force: bool = False) -> tuple[Path, list[Path], bool]:
    """Write ``out/geometry.h5`` and ``out/<mesh>-<layout>.nml`` for every mesh and layout.
    Existing case files, or a geometry file of another ball, are refused (HertzCaseError,
    nothing written) unless ``force``. Returns ``(geometry, cases, geometry written)``."""
    texts = {case_stem(m, lay): to_namelist_text(ball_case(ball, m, lay)) for m in meshes for lay in layouts}
    bodies = ball_geometry(ball)

    def geometry_file(path: Path) -> None:
        write_geometry(path, SCENE, bodies, generator="voiga pre (python -m pre cattaneo3d)")

    return write_scene3d_folder(out, texts, bodies, geometry_file, force, "another half ball")
