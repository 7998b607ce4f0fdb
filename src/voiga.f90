!> voiga: isogeometric large-deformation contact with varying-order NURBS.
!> Umbrella module re-exporting the public API, in data-flow order:
!> case -> geometry -> discretization -> model -> solver -> output.
module voiga
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_version, only: voiga_version_string
    use voiga_io_case, only: case_t, read_case
    use voiga_io_geometry, only: read_patch
    use voiga_nurbs_surface, only: nurbs_surface_t, surface_eval
    use voiga_nurbs_curve, only: nurbs_curve_t, curve_eval
    use voiga_discretization_layout, only: layout_t
    use voiga_discretization_patch, only: discretization_t, new_discretization
    use voiga_discretization_element, only: element_basis
    use voiga_discretization_bodies, only: discretize_bodies
    use voiga_model, only: model_t, new_model
    use voiga_solver_newton, only: solve_steps, solver_stats_t
    use voiga_io_results, only: results_t
    implicit none
    public
end module voiga
