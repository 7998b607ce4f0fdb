"""The groups and variables of a case file (``docs/formats.md``), as voiga's readers
declare them: what a spec may hold (``pre.spec``, ``pre.spec3d``) and a study may
change (``post.study``)."""

from __future__ import annotations

NAMELISTS: dict[str, frozenset[str]] = {
    "case": frozenset({"title", "scene", "mesh", "layout", "geometry", "output", "n_bodies", "overwrite"}),
    "body": frozenset({"name", "material", "youngs_modulus", "poisson_ratio", "basis", "degree_xi",
                       "degree_eta", "degree_zeta", "nel_xi", "nel_eta", "nel_zeta", "knots_xi", "knots_eta",
                       "knots_zeta", "contact_edge", "contact_face", "layer_degree", "layer_elevations"}),
    "solver": frozenset({"n_steps", "max_iterations", "tol_residual", "tol_energy", "n_gauss",
                         "min_step_fraction", "max_cuts", "grow_iterations", "predictor",
                         "linear_solver", "damping", "max_stalled_iterations", "stick_predictor"}),
    "dirichlet": frozenset({"body", "edge", "face", "fix_x", "fix_y", "fix_z", "ux", "uy", "uz"}),
    "pressure": frozenset({"body", "edge", "face", "p"}),
    "contact": frozenset({"slave", "master", "rigid_point", "rigid_normal", "penalty_normal",
                          "penalty_tangent", "friction", "n_gauss", "method", "tolerance", "rigid_curve",
                          "rigid_surface", "rigid_ux", "rigid_uy", "rigid_uz", "allow_overlap"}),
    "output": frozenset({"fields", "samples", "every", "steps"}),
}
"""Namelist group -> its variables, as the readers in ``src/io/input/case/`` declare them (a
test compares the two: ``post/tests/test_study.py``). A study's changes are checked
against it."""

SOLID_ONLY: dict[str, frozenset[str]] = {
    "body": frozenset({"degree_zeta", "nel_zeta", "knots_zeta", "contact_face"}),
    "dirichlet": frozenset({"face", "fix_z", "uz"}),
    "pressure": frozenset({"face"}),
}
"""The variables only a solid (a volume of the geometry file) has (docs/formats.md,
"Solids")."""

PLANE_ONLY: dict[str, frozenset[str]] = {
    "body": frozenset({"contact_edge"}),
    "dirichlet": frozenset({"edge"}),
    "pressure": frozenset({"edge"}),
}
"""The variables of a plane body's groups that a solid's name otherwise (voiga takes
``edge`` for ``face``; a spec of solids names faces)."""

PLANE: dict[str, frozenset[str]] = {g: v - SOLID_ONLY.get(g, frozenset()) for g, v in NAMELISTS.items()}
"""The variables of a plane case: what the 2D spec's case tables may hold."""

SOLID: dict[str, frozenset[str]] = {g: v - PLANE_ONLY.get(g, frozenset())
                                    for g, v in NAMELISTS.items() if g != "contact"}
"""The variables of a solid case: what the 3D spec's case tables may hold (no
``&contact`` yet: issue 42)."""
