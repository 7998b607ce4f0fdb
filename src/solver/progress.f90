!> How a run's progress leaves the solver: the solver calls these hooks and never
!> prints or writes a file itself. `progress_t` does nothing; the result file
!> (`voiga_io_output_results`) and the terminal (`app/`) extend it with what they show.
!> The hooks a run calls, in order: `set_up` once (a hierarchical linear solver's
!> levels), then per attempt at a substep `substep`, per Newton iteration
!> `iteration`, `factorized`, `linear_solved`;
!> per failed attempt `retried` or `cut`; per Tresca fixed point `fixed_point`
!> and `fixed_point_done`; per converged step `step_done`; `warning` whenever the
!> run finds something the user should know (`voiga_model_checks`).
module voiga_solver_progress
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_model, only: model_t
    use voiga_solver_records, only: step_record_t, cut_record_t
    implicit none
    private

    public :: progress_t, iteration_report_t, fixed_point_report_t, step_report_t

    !> One Newton iteration: its residual, energy norm, accepted step length, the
    !> round-off floor (negative: not computed, a converged iterate evaluated
    !> without its tangent), and the contact states of every pair.
    type :: iteration_report_t
        integer :: step = 0, iteration = 0
        real(dp) :: residual = 0.0_dp, energy = 0.0_dp, step_length = 0.0_dp, floor = 0.0_dp
        !> Per pair: points sticking, slipping, and all its points.
        integer, allocatable :: stick(:), slip(:), points(:)
    end type iteration_report_t

    !> One iteration of the Tresca fixed point, or (`done`) its accepted end.
    type :: fixed_point_report_t
        integer :: step = 0, iteration = 0, newton_iterations = 0, det_sign = 0
        real(dp) :: time = 0.0_dp
        !> Coulomb residual, its reference (the substep's first), the round-off floor,
        !> the force scale; the largest bound change and the largest bound.
        real(dp) :: residual = 0.0_dp, reference = 0.0_dp, floor = 0.0_dp, scale = 0.0_dp
        real(dp) :: change = 0.0_dp, largest = 0.0_dp
    end type fixed_point_report_t

    !> A converged nominal step and what a restart after it needs.
    type :: step_report_t
        type(step_record_t) :: record
        !> Steps planned; the residual norm at the end; seconds since the run started.
        integer :: n_steps = 0
        real(dp) :: residual = 0.0_dp, wall = 0.0_dp
        !> The cuts made while solving this step, and the cuts of the run so far.
        type(cut_record_t), allocatable :: cuts(:)
        integer :: n_cuts = 0
        !> The substep fraction carried to the next step and the run's force scale.
        real(dp) :: next_fraction = 1.0_dp, r0_max = 0.0_dp
    end type step_report_t

    !> The hooks, each doing nothing here.
    type :: progress_t
    contains
        procedure :: set_up => progress_set_up
        procedure :: substep => progress_substep
        procedure :: iteration => progress_iteration
        procedure :: factorized => progress_factorized
        procedure :: linear_solved => progress_linear_solved
        procedure :: retried => progress_retried
        procedure :: softened => progress_softened
        procedure :: cut => progress_cut
        procedure :: fixed_point => progress_fixed_point
        procedure :: fixed_point_done => progress_fixed_point
        procedure :: multipliers_updated => progress_multipliers_updated
        procedure :: step_done => progress_step_done
        procedure :: warning => progress_warning
    end type progress_t

contains

    !> The run is set up; `level_dofs`: DOFs of each level of the linear solver
    !> (called only for a hierarchical one). A failure ends the run.
    subroutine progress_set_up(self, level_dofs, error)
        class(progress_t), intent(inout) :: self
        integer, intent(in) :: level_dofs(:)
        type(error_t), allocatable, intent(out) :: error
    end subroutine progress_set_up

    !> An attempt at substep `substep` of nominal step `step` (of `n_steps`) begins,
    !> towards load time `time` with increment `fraction` of the nominal step;
    !> `cuts`: the cuts of this step so far, `run_cuts` those of the run.
    subroutine progress_substep(self, step, n_steps, substep, cuts, run_cuts, time, fraction)
        class(progress_t), intent(inout) :: self
        integer, intent(in) :: step, n_steps, substep, cuts, run_cuts
        real(dp), intent(in) :: time, fraction
    end subroutine progress_substep

    subroutine progress_iteration(self, report)
        class(progress_t), intent(inout) :: self
        type(iteration_report_t), intent(in) :: report
    end subroutine progress_iteration

    !> The tangent was factorized: sign and log10 magnitude of its determinant.
    subroutine progress_factorized(self, sign, log10_det)
        class(progress_t), intent(inout) :: self
        integer, intent(in) :: sign
        real(dp), intent(in) :: log10_det
    end subroutine progress_factorized

    !> An iterative linear solve ended after `iterations` at relative residual
    !> `residual`; `asked`: the relative residual it was asked for.
    subroutine progress_linear_solved(self, iterations, residual, asked)
        class(progress_t), intent(inout) :: self
        integer, intent(in) :: iterations
        real(dp), intent(in) :: residual, asked
    end subroutine progress_linear_solved

    !> A substep whose predicted start failed (`reason`) is retried from the last
    !> converged state.
    subroutine progress_retried(self, step, time, reason)
        class(progress_t), intent(inout) :: self
        integer, intent(in) :: step
        real(dp), intent(in) :: time
        character(len=*), intent(in) :: reason
    end subroutine progress_retried

    !> A substep failed (`reason`) and pair `pair` made its penalties softer
    !> (`what`); the substep is retried at the same increment.
    subroutine progress_softened(self, step, time, pair, what, reason)
        class(progress_t), intent(inout) :: self
        integer, intent(in) :: step, pair
        real(dp), intent(in) :: time
        character(len=*), intent(in) :: what, reason
    end subroutine progress_softened

    !> The increment was cut (`reason`: the whole message, `cut%reason` keeps its start).
    subroutine progress_cut(self, cut, reason)
        class(progress_t), intent(inout) :: self
        type(cut_record_t), intent(in) :: cut
        character(len=*), intent(in) :: reason
    end subroutine progress_cut

    subroutine progress_fixed_point(self, report)
        class(progress_t), intent(inout) :: self
        type(fixed_point_report_t), intent(in) :: report
    end subroutine progress_fixed_point

    !> The `update`-th multiplier update of the augmented Lagrangian at `step`; the
    !> largest constraint residual before it (relative to the slave element size).
    subroutine progress_multipliers_updated(self, step, update, residual)
        class(progress_t), intent(inout) :: self
        integer, intent(in) :: step, update
        real(dp), intent(in) :: residual
    end subroutine progress_multipliers_updated

    !> A nominal step converged with displacement `u`; `model` holds the contact
    !> pairs' output of its last evaluation. A failure (the result file cannot be
    !> written) ends the run.
    subroutine progress_step_done(self, report, u, model, error)
        class(progress_t), intent(inout) :: self
        type(step_report_t), intent(in) :: report
        real(dp), intent(in) :: u(:)
        type(model_t), intent(in) :: model
        type(error_t), allocatable, intent(out) :: error
    end subroutine progress_step_done

    !> Something the user should know that does not stop the run (`text`: one line,
    !> naming the pair or body, the cause and the remedy).
    subroutine progress_warning(self, text)
        class(progress_t), intent(inout) :: self
        character(len=*), intent(in) :: text
    end subroutine progress_warning

end module voiga_solver_progress
