!> The `&solver` group: load steps, Newton's tolerances, adaptive stepping, the
!> linear solver and the step damping (docs/formats.md).
module voiga_io_input_case_solver
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use, intrinsic :: iso_fortran_env, only: int64
    use voiga_io_input_namelist, only: group_error
    use voiga_io_input_case_values, only: check_length, max_phases, either
    use voiga_solver_settings, only: solver_settings_t
    use voiga_solver_linear_factory, only: linear_solver_names
    use voiga_solver_step_length, only: damping_names
    implicit none
    private

    public :: read_solver

    !> Most load steps of a run (all phases).
    integer(int64), parameter :: max_steps = 1000000
    !> Most Newton iterations per attempt, and most cuts per step.
    integer, parameter :: max_count = 10000

contains

    !> Read the `&solver` group from its text and validate it; every value the group
    !> does not set keeps its default.
    subroutine read_solver(text, path, entry, error)
        !> The group's text (`nml_group_t%text`).
        character(len=*), intent(in) :: text(:)
        character(len=*), intent(in) :: path
        type(solver_settings_t), intent(out) :: entry
        type(error_t), allocatable, intent(out) :: error
        integer :: n_steps(max_phases), max_iterations, n_gauss, ios, nph, max_cuts, grow_iterations
        integer :: max_stalled_iterations
        integer :: first_read(max_phases)
        logical :: given(max_phases)
        real(dp) :: tol_residual, tol_energy, min_step_fraction
        logical :: predictor, stick_predictor
        ! one character more than kept: a longer value is refused, not cut
        character(len=17) :: linear_solver, damping
        character(len=512) :: msg
        namelist /solver/ n_steps, max_iterations, tol_residual, tol_energy, n_gauss, &
            min_step_fraction, max_cuts, grow_iterations, predictor, stick_predictor, linear_solver, damping, &
            max_stalled_iterations

        max_iterations = entry%max_iterations
        tol_residual = entry%tol_residual
        tol_energy = entry%tol_energy
        n_gauss = entry%n_gauss
        min_step_fraction = entry%min_step_fraction
        max_cuts = entry%max_cuts
        grow_iterations = entry%grow_iterations
        max_stalled_iterations = entry%max_stalled_iterations
        predictor = entry%predictor
        stick_predictor = entry%stick_predictor
        linear_solver = entry%linear_solver
        damping = entry%damping
        ! the entries of n_steps the group sets are those two reads with different
        ! fillers agree on (no integer is a marker a user could not write)
        n_steps = 0
        read (text, nml=solver, iostat=ios, iomsg=msg)
        if (ios /= 0) then
            call group_error(path, 'solver', text, ios, msg, try_solver, error)
            return
        end if
        first_read = n_steps
        n_steps = 1
        read (text, nml=solver, iostat=ios, iomsg=msg)
        given = n_steps == first_read
        nph = count(given)
        if (nph == 0) then
            n_steps(1) = 1
            nph = 1
        else if (.not. all(given(1:nph))) then
            call fatal_error(error, path//': &solver: n_steps must be one list starting at entry 1', &
                             error_code%input)
            return
        end if
        call check_length(linear_solver, 16, 'linear_solver', path//': &solver: ', error)
        call check_length(damping, 16, 'damping', path//': &solver: ', error)
        if (allocated(error)) return
        entry%linear_solver = linear_solver
        entry%damping = damping
        entry%n_steps = n_steps(1:nph)
        entry%min_step_fraction = min_step_fraction
        entry%max_cuts = max_cuts
        entry%grow_iterations = grow_iterations
        entry%max_stalled_iterations = max_stalled_iterations
        entry%predictor = predictor
        entry%stick_predictor = stick_predictor
        entry%max_iterations = max_iterations
        entry%tol_residual = tol_residual
        entry%tol_energy = tol_energy
        entry%n_gauss = n_gauss
        call check_solver(entry, n_steps(1:nph), path//': &solver: ', error)
    contains
        subroutine try_solver(text, ios, msg)
            character(len=*), intent(in) :: text
            integer, intent(out) :: ios
            character(len=*), intent(inout) :: msg
            ! allow(C181): ios goes back to the caller, which reports it
            read (text, nml=solver, iostat=ios, iomsg=msg)
        end subroutine try_solver
    end subroutine read_solver

    !> Every value in its range; `raw_steps`: the n_steps entries as given.
    subroutine check_solver(s, raw_steps, where, error)
        type(solver_settings_t), intent(in) :: s
        integer, intent(in) :: raw_steps(:)
        character(len=*), intent(in) :: where
        type(error_t), allocatable, intent(out) :: error
        character(len=24) :: total
        write (total, '(i0)') sum(int(raw_steps, int64))
        if (any(raw_steps < 1)) then
            call fatal_error(error, where//'n_steps must be >= 1 in every phase', error_code%input)
        else if (sum(int(raw_steps, int64)) > max_steps) then
            call fatal_error(error, where//'n_steps: at most 1000000 load steps in all (the sum is '// &
                             trim(total)//')', error_code%input)
        else if (s%max_iterations < 1 .or. s%max_iterations > max_count) then
            call fatal_error(error, where//'max_iterations must be between 1 and 10000', error_code%input)
        else if (.not. (s%tol_residual > 0.0_dp .and. s%tol_residual < 1.0_dp)) then
            call fatal_error(error, where//'tol_residual must lie in (0, 1)', error_code%input)
        else if (.not. (s%tol_energy >= 0.0_dp .and. s%tol_energy < 1.0_dp)) then
            call fatal_error(error, where//'tol_energy must lie in [0, 1)', error_code%input)
        else if (s%n_gauss < 0 .or. s%n_gauss > 30) then
            call fatal_error(error, where//'n_gauss must be between 0 (automatic) and 30', error_code%input)
        else if (.not. (s%min_step_fraction > 0.0_dp .and. s%min_step_fraction <= 1.0_dp)) then
            call fatal_error(error, where//'min_step_fraction must lie in (0, 1]', error_code%input)
        else if (s%min_step_fraction < 1.0e-12_dp) then
            call fatal_error(error, where//'min_step_fraction must be >= 1e-12 (a smaller increment '// &
                             'would not change the load time)', error_code%input)
        else if (s%max_cuts < 0 .or. s%max_cuts > max_count) then
            call fatal_error(error, where//'max_cuts must be between 0 and 10000', error_code%input)
        else if (s%grow_iterations < 0) then
            call fatal_error(error, where//'grow_iterations must be >= 0', error_code%input)
        else if (s%max_stalled_iterations < 0) then
            call fatal_error(error, where//'max_stalled_iterations must be >= 0 (0: no budget)', &
                             error_code%input)
        else if (.not. any(linear_solver_names == s%linear_solver)) then
            call fatal_error(error, where//"linear_solver = '"//trim(s%linear_solver)// &
                             "': must be "//either(linear_solver_names), error_code%input)
        else if (.not. any(damping_names == s%damping)) then
            call fatal_error(error, where//"damping = '"//trim(s%damping)// &
                             "': must be "//either(damping_names), error_code%input)
        else if (trim(s%damping) == 'natural' .and. trim(s%linear_solver) == 'multigrid') then
            call fatal_error(error, where//"damping = 'natural' needs linear_solver = 'direct' "// &
                             '(its test solves with the last factorization)', error_code%input)
        end if
    end subroutine check_solver

end module voiga_io_input_case_solver
