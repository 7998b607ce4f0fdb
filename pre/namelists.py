"""The groups and variables of a case file (``docs/formats.md``), as voiga's readers
declare them: what a spec may hold (``pre.spec``) and a study may change
(``post.study``)."""

from __future__ import annotations

NAMELISTS: dict[str, frozenset[str]] = {
    "case": frozenset({"title", "scene", "mesh", "layout", "geometry", "output", "n_bodies", "overwrite"}),
    "body": frozenset({"name", "material", "youngs_modulus", "poisson_ratio", "basis", "degree_xi",
                       "degree_eta", "degree_zeta", "nel_xi", "nel_eta", "nel_zeta", "knots_xi",
                       "knots_eta", "knots_zeta", "contact_edge", "contact_face", "layer_degree",
                       "layer_elevations"}),
    "solver": frozenset({"n_steps", "max_iterations", "tol_residual", "tol_energy", "n_gauss",
                         "min_step_fraction", "max_cuts", "grow_iterations", "predictor",
                         "linear_solver", "damping", "max_stalled_iterations", "stick_predictor"}),
    "dirichlet": frozenset({"body", "edge", "face", "fix_x", "fix_y", "fix_z", "ux", "uy", "uz"}),
    "pressure": frozenset({"body", "edge", "face", "p"}),
    "contact": frozenset({"slave", "master", "rigid_point", "rigid_normal", "penalty_normal",
                          "penalty_tangent", "friction", "n_gauss", "method", "tolerance", "rigid_curve",
                          "rigid_ux", "rigid_uy", "allow_overlap"}),
    "output": frozenset({"fields", "samples", "every", "steps"}),
}
"""Namelist group -> its variables, as the readers in ``src/io/input/case/`` declare them (a
test compares the two: ``post/tests/test_study.py``). A spec's case tables and a
study's changes are checked against it."""
