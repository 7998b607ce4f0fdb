!> The solver's settings (`&solver`; read and validated by `voiga_io_input_case_solver`,
!> reference in docs/formats.md): the load steps of each phase, Newton's tolerances,
!> the adaptive load stepping, the linear solver and the step damping. The load
!> "time" runs from 0 to the number of phases; phase k ends at time k.
module voiga_solver_settings
    use voiga_kinds, only: dp
    implicit none
    private

    public :: solver_settings_t

    !> Every `&solver` value.
    type :: solver_settings_t
        !> Load steps of each phase; the number of entries is the number of phases.
        integer, allocatable :: n_steps(:)
        !> Newton iteration cap per step.
        integer :: max_iterations = 25
        !> Converged when ||r|| <= tol_residual ||r_0|| (r_0: the step's first residual) ...
        real(dp) :: tol_residual = 1.0e-10_dp
        !> ... or |du . r| <= tol_energy |du_1 . r_0|.
        real(dp) :: tol_energy = 1.0e-20_dp
        !> Gauss points per direction in the bodies (0: degree + 1 in each direction).
        integer :: n_gauss = 0
        !> Adaptive load stepping (docs/stepping.md): a failed load increment is
        !> halved down to min_step_fraction of the nominal step ...
        real(dp) :: min_step_fraction = 1.0e-4_dp
        !> ... at most max_cuts times per nominal step (0: no cutting, a failed step fails the run) ...
        integer :: max_cuts = 30
        !> ... and doubled (never beyond the nominal step) after a substep that
        !> converged in at most grow_iterations Newton iterations.
        integer :: grow_iterations = 5
        !> A nominal step is given up as hopeless when its failed attempts since the
        !> last converged substep have taken this many Newton iterations (all
        !> attempts, Tresca retries included; 0: no such budget): the run then ends
        !> suggesting more load steps instead of cutting on (docs/stepping.md).
        integer :: max_stalled_iterations = 1000
        !> Start each substep from the last step's increment, extrapolated (within a
        !> load phase; docs/stepping.md).
        logical :: predictor = .true.
        !> Start a frictional substep that has no increment to extrapolate (the first
        !> of a load phase, a retry) from a stick predictor: one linear step with every
        !> point in contact at the last converged state sticking (docs/robustness.md).
        logical :: stick_predictor = .true.
        !> Linear solver of each Newton iteration (`linear_solver_names`): 'direct'
        !> (UMFPACK LU) or 'multigrid' (GMRES preconditioned by geometric multigrid).
        character(len=16) :: linear_solver = 'direct'
        !> Newton step damping (`damping_names`): 'residual' (halve a step that
        !> increases the residual norm) or 'natural' (affine-invariant; direct solver only).
        character(len=16) :: damping = 'residual'
        !> Solve every substep of a frictional model by the Tresca fixed point (from the
        !> last converged state), not only those whose Newton attempt folds: for tests
        !> and comparisons (Fortran API only, not a case-file setting).
        logical :: tresca_always = .false.
        !> Integrate each linear-elastic body's stiffness once per stiffness pattern
        !> (its internal force is then K u) and, with the direct solver and only
        !> linear-elastic bodies, factorize the bodies' stiffness once per run and
        !> solve each tangent as an update of it (`voiga_solver_bulk_update`). False:
        !> integrate every body and factorize every tangent whole at every iteration.
        !> The results agree to round-off (Fortran API only: for tests and comparisons).
        logical :: reuse_linear_bulk = .true.
    contains
        !> Total number of load steps over all phases.
        procedure :: total_steps => settings_total_steps
        !> Load time at the end of global step `step` (0 = start).
        procedure :: step_time => settings_step_time
        !> Load phase (1-based) a step belongs to.
        procedure :: phase_of_step => settings_phase_of_step
    end type solver_settings_t

contains

    pure integer function settings_total_steps(self) result(n)
        class(solver_settings_t), intent(in) :: self
        n = 1
        if (allocated(self%n_steps)) n = sum(self%n_steps)
    end function settings_total_steps

    pure real(dp) function settings_step_time(self, step) result(t)
        class(solver_settings_t), intent(in) :: self
        integer, intent(in) :: step
        integer :: k, left
        left = step
        t = 0.0_dp
        do k = 1, size(self%n_steps)
            if (left <= self%n_steps(k)) then
                t = real(k - 1, dp) + real(left, dp)/real(self%n_steps(k), dp)
                return
            end if
            left = left - self%n_steps(k)
        end do
        t = real(size(self%n_steps), dp)
    end function settings_step_time

    pure integer function settings_phase_of_step(self, step) result(ph)
        class(solver_settings_t), intent(in) :: self
        integer, intent(in) :: step
        integer :: total
        total = 0
        do ph = 1, size(self%n_steps)
            total = total + self%n_steps(ph)
            if (step <= total) return
        end do
        ph = size(self%n_steps)
    end function settings_phase_of_step

end module voiga_solver_settings
