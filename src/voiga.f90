!> voiga: isogeometric large-deformation contact with varying-order NURBS.
!> Umbrella module re-exporting the public API, in data-flow order:
!> case -> geometry -> discretization -> model -> solver -> output.
module voiga
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_version, only: voiga_version_string
    use voiga_io_input_case, only: case_t, read_case, check_edges
    use voiga_io_input_geometry, only: read_patch
    use voiga_io_input_bodies, only: discretize_bodies
    use voiga_nurbs_surface, only: nurbs_surface_t, surface_eval
    use voiga_nurbs_curve, only: nurbs_curve_t, curve_eval
    use voiga_discretization_layout, only: layout_t
    use voiga_discretization_patch, only: discretization_t, new_discretization
    use voiga_discretization_element, only: element_basis
    use voiga_model_body, only: body_settings_t
    use voiga_model_loads, only: dirichlet_settings_t, pressure_settings_t
    use voiga_contact_factory, only: contact_settings_t
    use voiga_model, only: model_t, new_model
    use voiga_solver_settings, only: solver_settings_t
    use voiga_solver_progress, only: progress_t
    use voiga_solver_observers, only: observers_t
    use voiga_solver_records, only: solver_stats_t
    use voiga_solver_stepping, only: solve_steps
    use voiga_io_output_results, only: results_t
    implicit none
    public
end module voiga
