"""The 3D ironing scene of issue 42 (``python -m pre ironing3d OUTDIR``): a rigid sphere
pressed into a Neo-Hookean slab and slid along it with Coulomb friction, in the spirit
of Puso and Laursen's 3D ironing (values and study: docs/ironing3d.md).

Geometry (half model, ``y >= 0``): the slab ``[0, 4] x [0, 1] x [-1, 0]``
(:func:`pre.solids.box`, contact face ``top``, z = 0) and the die, the rigid surface
``die`` of the geometry file: the cap of the sphere of radius R = 0.5 centred at
(1, 0, R) within 45 degrees of its lowest point (:func:`pre.rigid_surfaces.sphere_cap`),
touching the slab at (1, 0, 0).

Loads: the slab's bottom fixed, ``uy = 0`` on its symmetry face y = 0 (``front``); the
die moves down by the indentation d = 0.1 in :data:`PRESS_STEPS` steps, then along x by
:data:`SLIDE` in :data:`SLIDE_STEPS` steps (``rigid_ux``, ``rigid_uz``, two load
phases); GPTS contact (the scene's reference; ``method='mortar'``, ``--method mortar``,
for the mortar-type one) with voiga's default ``n_gauss`` (the layer's degree + 1 points
per direction of a slave cell; or the given one) and friction mu (0.3).

Mesh m<k> (:data:`MESHES`): uniform along x (``nx`` elements over the slab's length),
across ``fine`` elements over the path's band ``0 <= y <= BAND`` and ``rest`` beyond,
``nz`` through the thickness graded toward the top (its top element as tall as the
band's). The contact's radius is about sqrt(R d) = 0.22.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .cases import GEOMETRY_FILE, case_stem, to_namelist_text
from .h5io import write_geometry
from .hertz import HertzCaseError, write_scene3d_folder
from .meshes import geometric_sizes
from .rigid_surfaces import add_surfaces, sphere_cap
from .solid_case import knotted_body_group, solid_dofs
from .solids import box
from .volume import Volume

SCENE = "ironing3d"
BODY = "slab"
DIE = "die"
CONTACT_FACE = "top"
LENGTH, WIDTH, THICKNESS = 4.0, 1.0, 1.0
"""The slab ``[0, LENGTH] x [0, WIDTH] x [-THICKNESS, 0]`` (half model: y >= 0)."""
START = 1.0
"""x of the die's lowest point at the start."""
SLIDE = 2.0
"""The die's travel along x in the sliding phase (to x = 3: a die radius and more from
the slab's end)."""
PRESS_STEPS, SLIDE_STEPS = 10, 40
CAP_HALF_ANGLE = 45.0
"""Degrees of the sphere cap around its lowest point: it spans x and y within R sin 45
= 0.35 of its centre, beyond the contact's radius (about 0.22)."""
BAND = 0.5
"""The band 0 <= y <= BAND along the path that the ``fine`` elements across cover."""

MESHES: dict[str, tuple[int, int, int, int]] = {
    "m1": (16, 2, 1, 3),
    "m2": (24, 3, 1, 4),
    "m3": (32, 4, 2, 5),
    "m4": (48, 6, 2, 6),
}
"""Mesh -> (nx, fine, rest, nz): element size along the path 0.25, 0.167, 0.125, 0.083
(about 1.1, 0.75, 0.56, 0.37 contact radii), across ``BAND / fine`` alike."""

LAYOUTS: tuple[str, ...] = ("N2", "NN2.1", "NN2.2")
DEFAULT_GAUSS: int | None = None
"""``&contact n_gauss``: None leaves voiga's default, the contact layer's degree + 1 per
direction of a slave cell (docs/ironing3d.md: 2 points, which lock less in the Hertz
scene, oscillate 3 to 8 times more here and cut steps in the VO layer)."""


@dataclass(frozen=True)
class Iron:
    """The scene's values (consistent units): die radius, indentation, friction, slab
    material."""

    radius: float = 0.5
    indentation: float = 0.1
    friction: float = 0.3
    youngs_modulus: float = 1.0
    poisson_ratio: float = 0.3

    def check(self) -> None:
        """HertzCaseError naming the first value out of range."""
        for name in ("radius", "indentation", "friction", "youngs_modulus", "poisson_ratio"):
            if not math.isfinite(getattr(self, name)):
                raise HertzCaseError(f"{name} {getattr(self, name)!r} is not a finite number")
        if not 0 < self.radius <= 1.0:
            raise HertzCaseError(f"radius {self.radius:g} must be > 0 and <= 1 (the slab's width)")
        if not 0 < self.indentation < 0.5 * self.radius:
            raise HertzCaseError(f"indentation {self.indentation:g} must be > 0 and < R/2")
        if self.friction < 0:
            raise HertzCaseError(f"friction {self.friction:g} must be >= 0")
        if self.youngs_modulus <= 0 or not -1.0 < self.poisson_ratio < 0.5:
            raise HertzCaseError("youngs modulus must be > 0 and poisson ratio in (-1, 0.5)")

    @property
    def contact_radius(self) -> float:
        """Estimated contact radius sqrt(R d)."""
        return math.sqrt(self.radius * self.indentation)


def scene_geometry() -> dict[str, Volume]:
    """The slab (:func:`pre.solids.box`; xi along x, eta along y, zeta along z)."""
    return {BODY: box((0.0, LENGTH), (0.0, WIDTH), (-THICKNESS, 0.0))}


def slab_knots(mesh: str) -> dict[str, list[float]]:
    """``knots_xi``, ``knots_eta``, ``knots_zeta`` of mesh ``mesh`` (module docstring;
    the box's parameters are its coordinates over the lengths)."""
    if mesh not in MESHES:
        raise HertzCaseError(f"mesh {mesh!r}: one of {', '.join(MESHES)}")
    nx, fine, rest, nz = MESHES[mesh]
    xi = [i / nx for i in range(1, nx)]
    h = BAND / fine
    eta = [i * h / WIDTH for i in range(1, fine + 1)]
    eta += [(BAND + i * (WIDTH - BAND) / rest) / WIDTH for i in range(1, rest)]
    sizes = geometric_sizes(nz, h, THICKNESS)
    depth = [float(sum(sizes[:k])) for k in range(1, nz)]          # from the top
    zeta = sorted(1.0 - t / THICKNESS for t in depth)
    return {"knots_xi": xi, "knots_eta": eta, "knots_zeta": zeta}


def iron_case(iron: Iron, mesh: str, layout: str, steps: Sequence[int] | None = None,
              n_gauss: int | None = DEFAULT_GAUSS, penalty_normal: float | None = None,
              method: str = "gpts") -> dict[str, Any]:
    """The namelist groups of the case ``mesh``, ``layout`` (module docstring).
    ``steps``: (press, slide) steps; ``n_gauss`` and ``penalty_normal`` None leave them
    to voiga (its n_gauss is the contact layer's degree + 1); ``method`` the
    ``&contact method``, 'gpts' or 'mortar' (both carry friction on faces)."""
    iron.check()
    press, slide = steps if steps is not None else (PRESS_STEPS, SLIDE_STEPS)
    if press < 1 or slide < 1:
        raise HertzCaseError(f"steps {press}, {slide} must be >= 1")
    if n_gauss is not None and n_gauss < 1:
        raise HertzCaseError(f"n_gauss {n_gauss} must be >= 1")
    if method not in ("gpts", "mortar"):
        raise HertzCaseError(f"method {method!r} must be 'gpts' or 'mortar'")
    knots = slab_knots(mesh)
    vol = scene_geometry()[BODY]
    spec = {"name": BODY, "layout": layout, "contact_face": CONTACT_FACE, "material": "neo-hookean",
            "youngs_modulus": iron.youngs_modulus, "poisson_ratio": iron.poisson_ratio}
    try:   # the top face is zeta = 1: the patch voiga solves on keeps the box's directions
        body = knotted_body_group(spec, vol, knots)
    except ValueError as err:
        raise HertzCaseError(str(err)) from None
    contact: dict[str, Any] = {"slave": BODY, "master": "rigid", "rigid_surface": DIE, "method": method,
                               "friction": float(iron.friction),
                               "rigid_ux": [0.0, SLIDE], "rigid_uz": [-iron.indentation] * 2}
    if n_gauss is not None:
        contact["n_gauss"] = int(n_gauss)
    if penalty_normal is not None:
        if not 0 < penalty_normal < math.inf:
            raise HertzCaseError(f"penalty_normal {penalty_normal!r} must be > 0")
        contact["penalty_normal"] = float(penalty_normal)
    title = (f"ironing3d {mesh} {layout}: sphere R = {iron.radius:g} pressed {iron.indentation:g} into a "
             f"Neo-Hookean slab (E = {iron.youngs_modulus:g}, nu = {iron.poisson_ratio:g}), slid "
             f"{SLIDE:g} with mu = {iron.friction:g}")
    return {"case": {"title": title, "scene": SCENE, "mesh": mesh, "layout": layout,
                     "geometry": GEOMETRY_FILE, "output": f"{case_stem(mesh, layout)}.h5", "n_bodies": 1},
            "body": [body],
            "solver": {"n_steps": [int(press), int(slide)]},
            "dirichlet": [
                {"body": BODY, "face": "bottom", "fix_x": True, "fix_y": True, "fix_z": True},
                {"body": BODY, "face": "front", "fix_y": True},
            ],
            "contact": [contact]}


def case_dofs(iron: Iron, mesh: str, layout: str) -> dict[str, int]:
    """The DOFs of a case (:func:`pre.solid_case.solid_dofs`)."""
    return solid_dofs(iron_case(iron, mesh, layout)["body"][0], scene_geometry()[BODY])


def write_ironing3d(iron: Iron, meshes: Sequence[str], layouts: Sequence[str], out: str | Path,
                    force: bool = False, **options: Any) -> tuple[Path, list[Path], bool]:
    """Write ``out/geometry.h5`` (the slab and the surface ``die``) and
    ``out/<mesh>-<layout>.nml`` for every mesh and layout (``options``:
    :func:`iron_case`'s). Existing case files, or a geometry file of another die, are
    refused (HertzCaseError, nothing written) unless ``force``. Returns ``(geometry,
    cases, geometry written)``."""
    texts = {case_stem(m, lay): to_namelist_text(iron_case(iron, m, lay, **options))
             for m in meshes for lay in layouts}
    bodies = scene_geometry()
    die = sphere_cap(iron.radius, (START, 0.0, iron.radius), CAP_HALF_ANGLE)

    def geometry_file(path: Path) -> None:
        write_geometry(path, SCENE, bodies, generator="voiga pre (python -m pre ironing3d)")
        add_surfaces(str(path), {DIE: die})

    return write_scene3d_folder(out, texts, bodies, geometry_file, force, "another die")
