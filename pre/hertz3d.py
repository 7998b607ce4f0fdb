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
d (a sphere on a rigid flat: ``d = a^2 / R``); the runs' a is 1.8 % larger at d = 0.01 R
(0.4 % at 0.000625 R).

Grid ``polar`` (``--grid polar``, meshes p<k> of :data:`POLAR_MESHES`): the same octant
in spherical coordinates about the vertical axis through the lowest point
(:func:`pre.solids.polar_ball_octant`), whose theta knot lines are circles about the
contact: theta graded as above with the spans at the expected edge (0.9 to 1.1 a_est)
split, :data:`PHI_ELEMENTS` along phi, rho as above. The Cartesian grid's error falls
only like the zone cells' size, the rate of a square-root edge that no knot line follows
(docs/verification-faces.md); the polar grid resolves the edge as the 2D scene's
``--edge-refine`` does. The lowest point is then on the collapsed face ``axis``. With
``--master block`` the block is then the quarter cylinder of radius L about the same
axis (:func:`pre.solids.polar_quarter_cylinder`, faces named as the box's), its r knots
the box's x knots split over the same band, :data:`PHI_ELEMENTS` along its angle.

Master ``block`` (``--master block``; issue 42's "sphere on an elastic block"): instead of
the rigid plane, a second body ``block``, the box ``[0, L] x [0, L] x [-R - H, -R]``
(:func:`pre.solids.box`; L = H = ``block_size`` R, default :data:`BLOCK_SIZE`), the
quarter of a half-space under the ball with the same symmetry faces (``symmetry_x``
x = 0 with ``fix_x``, ``symmetry_y`` y = 0 with ``fix_y``), its ``bottom`` fixed in z,
its ``top`` (z = -R) the master face of ``&contact slave = 'ball', master = 'block'``;
the ball's material unless given, the ball's layout. Its knots are graded toward the
contact point (0, 0, -R) as the ball's (:func:`block_knots`): along x and y cells
``block_cell`` (default :data:`BLOCK_CELL`) times the ball's fine ones over the ball's
fine zone ``R sin(theta_c)``, then the ball's ``rest`` count growing to L; along z the
ball's ``radial`` count growing from that size at the top to the bottom. The two
contact faces do not match (a mortar integral over the ball's cells crosses the
block's kinks)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .cases import GEOMETRY_FILE, HERTZ_STEPS, case_stem, to_namelist_text
from .h5io import write_geometry
from .hertz import EDGE_BAND, Cylinder, HertzCaseError, split_spans, write_scene3d_folder
from .meshes import arc_parameter_exact, graded_angles, hertz_eta_knots, hertz_theta_c
from .solid_case import knotted_body_group, solid_dofs
from .solids import ball_octant, box, polar_ball_octant, polar_quarter_cylinder
from .volume import Volume

SOLID_METHOD = "mortar"
"""The contact method the cases name: voiga's default on solids (GPTS's n_gauss^2
constraints per face cell lock; docs/verification-faces.md)."""

SCENE = "hertz3d"
BODY = "ball"
CONTACT_FACE = "outer"
"""The sphere face (rho = R) of :func:`pre.solids.ball_octant`."""
MATERIALS = ("linear", "neo-hookean")
MASTERS = ("rigid", "block")
"""``--master``: the rigid plane z = -R, or the elastic block under it."""
BLOCK = "block"
BLOCK_FACE = "top"
BLOCK_FACES = {"left": "symmetry_x", "front": "symmetry_y"}
"""The block's faces: :data:`pre.solids.BOX_FACES` with x = 0 and y = 0 renamed as the ball's."""
BLOCK_SIZE = 1.0
"""L = H over R: ten contact radii (a/R = 0.1), where the block's finite size changes the
pressure by less than the meshes can show (docs/verification.md, "Contact on faces")."""
BLOCK_CELL = 1.3
"""The block's top cells under the zone over the ball's fine cells: comparable, not
matching (within the ball's fine zone no block knot comes within 2 % of a cell of a
ball knot line on any mesh; 1.2, 1.33, 1.4 or 0.8 put some within 1 %)."""

MESHES: dict[str, tuple[int, int, int]] = {
    "m1": (5, 5, 5),
    "m2": (7, 7, 7),
    "m3": (10, 10, 10),
    "m4": (15, 13, 13),
}
"""Mesh -> (fine, rest, radial) elements: along each angle ``fine`` over the contact
zone and ``rest`` beyond, radially ``radial`` (NN2.2: about 5,700 to 60,000 DOFs)."""

GRIDS = ("cartesian", "polar")
"""``--grid``: the ball in spherical coordinates about a horizontal axis
(:func:`pre.solids.ball_octant`, meshes :data:`MESHES`) or about the vertical one through
the contact point (:func:`pre.solids.polar_ball_octant`, meshes :data:`POLAR_MESHES`)."""

POLAR_MESHES: dict[str, tuple[int, int, int, int]] = {
    "p1": (10, 10, 10, 2),
    "p2": (16, 10, 12, 4),
    "p3": (20, 10, 12, 4),
    "p4": (30, 10, 12, 4),
}
"""Polar mesh -> (fine, rest, radial, edge): along theta ``fine`` elements over the
contact zone, those overlapping :data:`pre.hertz.EDGE_BAND` of the expected a split into
``edge``, and ``rest`` beyond; radially ``radial``; :data:`PHI_ELEMENTS` along the
azimuth (NN2.2: about 5,000 to 13,000 DOFs)."""
PHI_ELEMENTS = 2
"""Elements along the azimuth of a polar mesh. One would do for this scene: the basis
along phi holds cos and sin exactly (the geometry's rational arc), so the axisymmetric
solution is in the space; two keep the mesh from depending on that."""

LAYOUTS: tuple[str, ...] = ("N2", "N3", "NN2.1", "NN2.2")
"""The layouts of the study (any solid layout is accepted)."""

FIELD_SAMPLES = 3
"""``&output samples``: the element's ends and centre along each direction."""


@dataclass(frozen=True)
class Ball(Cylinder):
    """A Hertz problem of a sphere: radius, material, indentation (consistent units);
    the values and their ranges are :class:`pre.hertz.Cylinder`'s, plus the material law."""

    material: str = "linear"
    master: str = "rigid"
    grid: str = "cartesian"
    """:data:`GRIDS`: the ball's parametrization, and the meshes it takes."""
    """:data:`MASTERS`: the rigid plane or the block."""
    block_size: float = BLOCK_SIZE
    """The block's L = H over R."""
    block_cell: float = BLOCK_CELL
    """The block's top cells over the ball's fine ones (:data:`BLOCK_CELL`)."""
    block_youngs_modulus: float | None = None
    """The block's E (None: the ball's)."""
    block_poisson_ratio: float | None = None
    """The block's nu (None: the ball's)."""

    def check(self) -> None:
        """HertzCaseError naming the first value out of range."""
        super().check()
        if self.material not in MATERIALS:
            raise HertzCaseError(f"material {self.material!r} must be one of {', '.join(MATERIALS)}")
        if self.master not in MASTERS:
            raise HertzCaseError(f"master {self.master!r} must be one of {', '.join(MASTERS)}")
        if self.grid not in GRIDS:
            raise HertzCaseError(f"grid {self.grid!r} must be one of {', '.join(GRIDS)}")
        if not (math.isfinite(self.block_size) and 0.25 <= self.block_size <= 100):
            raise HertzCaseError(f"block size {self.block_size!r} must be from 0.25 to 100 (L = H over R)")
        if not (math.isfinite(self.block_cell) and 0.25 <= self.block_cell <= 4):
            raise HertzCaseError(f"block cell {self.block_cell!r} must be from 0.25 to 4 (over the ball's)")
        e, nu = self.block_material
        if not (math.isfinite(e) and e > 0):
            raise HertzCaseError(f"block youngs modulus {e!r} must be > 0")
        if not (math.isfinite(nu) and -1.0 < nu < 0.5):
            raise HertzCaseError(f"block poisson ratio {nu!r} must be in (-1, 0.5)")

    @property
    def block_material(self) -> tuple[float, float]:
        """The block's ``(E, nu)``: the given ones, else the ball's."""
        e = self.youngs_modulus if self.block_youngs_modulus is None else self.block_youngs_modulus
        nu = self.poisson_ratio if self.block_poisson_ratio is None else self.block_poisson_ratio
        return float(e), float(nu)

    @property
    def half_width(self) -> float:
        """Estimated contact radius ``a = sqrt(R d)`` (Hertz, sphere on a rigid flat)."""
        return math.sqrt(self.radius * self.indentation)


def ball_geometry(ball: Ball) -> dict[str, Volume]:
    """The bodies of the scene: the ball octant of radius R (faces of
    :data:`pre.solids.BALL_FACES`) and, for the master ``block``, the block (faces
    :data:`BLOCK_FACES`)."""
    bodies = {BODY: (polar_ball_octant if ball.grid == "polar" else ball_octant)(ball.radius)}
    if ball.master == BLOCK:
        r, side = float(ball.radius), float(ball.block_size) * float(ball.radius)
        bodies[BLOCK] = (polar_quarter_cylinder(side, (-r - side, -r)) if ball.grid == "polar" else
                         box((0.0, side), (0.0, side), (-r - side, -r), faces=BLOCK_FACES))
    return bodies


def mesh_counts(ball: Ball, mesh: str) -> tuple[int, int, int]:
    """``(fine, rest, radial)`` of mesh ``mesh`` of the ball's grid (HertzCaseError
    naming the grid's meshes if it has none of that name)."""
    table: dict[str, tuple[int, ...]] = dict(POLAR_MESHES) if ball.grid == "polar" else dict(MESHES)
    if mesh not in table:
        raise HertzCaseError(f"mesh {mesh!r}: the {ball.grid} grid's meshes are {', '.join(table)}")
    fine, rest, radial = table[mesh][:3]
    return fine, rest, radial


def ball_knots(ball: Ball, mesh: str) -> dict[str, list[float]]:
    """``knots_xi``, ``knots_eta``, ``knots_zeta`` of mesh ``mesh`` (module docstring):
    on the Cartesian grid both angles graded alike from the lowest point (xi along phi,
    eta along theta, each starting there), on the polar grid theta so and split at the
    expected edge (:func:`polar_theta_knots`), phi uniform; rho graded toward the sphere."""
    fine, rest, radial = mesh_counts(ball, mesh)
    theta_c = hertz_theta_c(ball.half_width / ball.radius)
    angle = [arc_parameter_exact(a) for a in graded_angles(theta_c, fine, rest)]
    rho = [float(k) for k in hertz_eta_knots(radial, theta_c / fine, thickness=1.0)]
    if ball.grid == "polar":
        return {"knots_xi": [k / PHI_ELEMENTS for k in range(1, PHI_ELEMENTS)],
                "knots_eta": polar_theta_knots(angle, ball.half_width / ball.radius, POLAR_MESHES[mesh][3]),
                "knots_zeta": rho}
    return {"knots_xi": angle, "knots_eta": list(angle), "knots_zeta": rho}


def polar_theta_knots(knots: list[float], half_width: float, edge: int) -> list[float]:
    """The graded theta knots of a polar mesh with every span that overlaps
    :data:`pre.hertz.EDGE_BAND` times ``half_width`` (a / R) split into ``edge``: the
    zone's edge, a circle about the lowest point, runs along these knot lines, and the
    band holds the runs' a (1.8 % above sqrt(R d) at d = 0.01 R, 0.4 % at 0.000625 R)."""
    t0, t1 = (arc_parameter_exact(math.asin(f * half_width)) for f in EDGE_BAND)
    return split_spans(knots, [(t0, t1)], edge)


def block_knots(ball: Ball, mesh: str, cell: float | None = None) -> dict[str, list[float]]:
    """The block's ``knots_xi``, ``knots_eta`` (x and y over L), ``knots_zeta`` (z over H,
    1 at the top) on mesh ``mesh`` (module docstring): cells ``cell`` (default the
    ball's ``block_cell``) times the ball's
    fine arc ``R theta_c / fine`` over at least the ball's fine zone ``R sin(theta_c)``
    along x and y, then ``rest`` cells growing to L; ``radial`` cells across, growing
    from that size at the top (:func:`pre.meshes.hertz_eta_knots`)."""
    fine, rest, radial = mesh_counts(ball, mesh)
    theta_c = hertz_theta_c(ball.half_width / ball.radius)
    side = float(ball.block_size) * float(ball.radius)
    h = (ball.block_cell if cell is None else cell) * ball.radius * theta_c / fine
    n_fine = math.ceil(ball.radius * math.sin(theta_c) / h - 1e-9)
    if n_fine * h > side / 2 or radial * h >= side:
        raise HertzCaseError(f"block size {ball.block_size:g} R is too small for the contact zone on {mesh}: "
                             f"its cells span {n_fine * h:g} along the top (at most half the block, "
                             f"{side / 2:g}) and {radial * h:g} in depth (less than {side:g})")
    along = [x / side for x in graded_angles(n_fine * h, n_fine, rest, sweep=side)]
    depth = [float(k) for k in hertz_eta_knots(radial, h / side, thickness=1.0)]
    if ball.grid == "polar":  # xi along r = xi L, the same split at the expected edge as the ball's
        a = ball.half_width / side
        along = split_spans(along, [(EDGE_BAND[0] * a, EDGE_BAND[1] * a)], POLAR_MESHES[mesh][3])
        return {"knots_xi": along, "knots_eta": [k / PHI_ELEMENTS for k in range(1, PHI_ELEMENTS)],
                "knots_zeta": depth}
    return {"knots_xi": along, "knots_eta": list(along), "knots_zeta": depth}


def _solid_group(name: str, vol: Volume, knots: dict[str, list[float]], layout: str, face: str,
                 material: str, youngs_modulus: float, poisson_ratio: float) -> dict[str, Any]:
    """A ``&body`` of the scene with explicit knots (:func:`pre.solid_case.knotted_body_group`:
    the contact face is ``zeta = 1`` of both volumes)."""
    spec = {"name": name, "layout": layout, "contact_face": face, "material": material,
            "youngs_modulus": youngs_modulus, "poisson_ratio": poisson_ratio}
    try:
        return knotted_body_group(spec, vol, knots)
    except ValueError as err:
        raise HertzCaseError(str(err)) from None


def ball_case(ball: Ball, mesh: str, layout: str, n_steps: int | None = None,
              method: str = SOLID_METHOD, penalty_normal: float | None = None) -> dict[str, Any]:
    """The namelist groups of the case ``mesh``, ``layout`` (module docstring).
    ``penalty_normal``: None leaves it to voiga (automatic)."""
    ball.check()
    vols = ball_geometry(ball)
    bodies = [_solid_group(BODY, vols[BODY], ball_knots(ball, mesh), layout, CONTACT_FACE, ball.material,
                           ball.youngs_modulus, ball.poisson_ratio)]
    if n_steps is not None and n_steps < 1:
        raise HertzCaseError(f"steps {n_steps} must be >= 1")
    contact: dict[str, Any] = {"slave": BODY, "master": "rigid",
                               "rigid_point": [0.0, 0.0, -float(ball.radius)],
                               "rigid_normal": [0.0, 0.0, 1.0], "method": method}
    dirichlet = [{"body": BODY, "face": "top", "fix_z": True, "uz": -float(ball.indentation)},
                 {"body": BODY, "face": "symmetry_x", "fix_x": True},
                 {"body": BODY, "face": "symmetry_y", "fix_y": True}]
    on = ""
    if ball.master == BLOCK:
        e, nu = ball.block_material
        bodies.append(_solid_group(BLOCK, vols[BLOCK], block_knots(ball, mesh), layout, BLOCK_FACE,
                                   ball.material, e, nu))
        contact = {"slave": BODY, "master": BLOCK, "method": method}
        dirichlet += [{"body": BLOCK, "face": "bottom", "fix_z": True},
                      {"body": BLOCK, "face": "symmetry_x", "fix_x": True},
                      {"body": BLOCK, "face": "symmetry_y", "fix_y": True}]
        on = f", on a block L = H = {ball.block_size * ball.radius:g}, E = {e:g}, nu = {nu:g}"
    if penalty_normal is not None:
        if not (isinstance(penalty_normal, (int, float)) and 0 < penalty_normal < math.inf):
            raise HertzCaseError(f"penalty_normal {penalty_normal!r} must be > 0")
        contact["penalty_normal"] = float(penalty_normal)
    grid = ", polar grid" if ball.grid == "polar" else ""
    title = (f"hertz3d {mesh} {layout}: ball octant{grid} R = {ball.radius:g}, E = {ball.youngs_modulus:g}, "
             f"nu = {ball.poisson_ratio:g}, {ball.material}, indentation {ball.indentation:g}{on}")
    return {"case": {"title": title, "scene": SCENE, "mesh": mesh, "layout": layout,
                     "geometry": GEOMETRY_FILE, "output": f"{case_stem(mesh, layout)}.h5",
                     "n_bodies": len(bodies)},
            "body": bodies,
            "solver": {"n_steps": int(n_steps or HERTZ_STEPS)},
            "dirichlet": dirichlet,
            "contact": [contact],
            "output": {"fields": ["stress"], "samples": FIELD_SAMPLES, "every": 0}}


def case_dofs(ball: Ball, mesh: str, layout: str) -> dict[str, int]:
    """The ball's DOFs in a case (:func:`pre.solid_case.solid_dofs`)."""
    return solid_dofs(ball_case(ball, mesh, layout)["body"][0], ball_geometry(ball)[BODY])


def body_dofs(ball: Ball, mesh: str, layout: str) -> dict[str, int]:
    """Body name -> its total DOFs in a case (the ball, and the block for that master)."""
    vols = ball_geometry(ball)
    return {b["name"]: solid_dofs(b, vols[b["name"]])["total"] for b in ball_case(ball, mesh, layout)["body"]}


def write_hertz3d(ball: Ball, meshes: Sequence[str], layouts: Sequence[str], out: str | Path,
                  force: bool = False, **options: Any) -> tuple[Path, list[Path], bool]:
    """Write ``out/geometry.h5`` and ``out/<mesh>-<layout>.nml`` for every mesh and
    layout (``options``: :func:`ball_case`'s). Existing case files, or a geometry file of
    another ball, are refused (HertzCaseError, nothing written) unless ``force``; a
    geometry file with the same contents is kept. Returns ``(geometry, cases, geometry
    written)``."""
    texts = {case_stem(m, lay): to_namelist_text(ball_case(ball, m, lay, **options))
             for m in meshes for lay in layouts}
    bodies = ball_geometry(ball)

    def geometry_file(path: Path) -> None:
        write_geometry(path, SCENE, bodies, generator="voiga pre (python -m pre hertz3d)")

    other = "another ball" if ball.master == "rigid" else "another ball or block"
    return write_scene3d_folder(out, texts, bodies, geometry_file, force, other)
