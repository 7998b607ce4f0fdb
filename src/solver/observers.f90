!> Several observers of one run side by side: `observers_t` is a `progress_t` that
!> forwards every hook to each observer in the order they were added (the result
!> file and the terminal in `app/main.f90`), so that neither has to extend the
!> other. A hook that can fail (`set_up`, `step_done`) stops at the first observer
!> that fails: the ones after it do not hear of the step.
module voiga_solver_observers
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_model, only: model_t
    use voiga_solver_records, only: cut_record_t
    use voiga_solver_progress, only: progress_t, iteration_report_t, fixed_point_report_t, step_report_t
    implicit none
    private

    public :: observers_t

    !> One observer (the caller's object: it must outlive the run).
    type :: observer_ref_t
        class(progress_t), pointer :: p => null()
    end type observer_ref_t

    !> The observers, in the order their hooks are called.
    type, extends(progress_t) :: observers_t
        type(observer_ref_t), allocatable :: list(:)
    contains
        procedure :: add => observers_add
        procedure :: set_up => observers_set_up
        procedure :: substep => observers_substep
        procedure :: iteration => observers_iteration
        procedure :: factorized => observers_factorized
        procedure :: linear_solved => observers_linear_solved
        procedure :: retried => observers_retried
        procedure :: softened => observers_softened
        procedure :: cut => observers_cut
        procedure :: fixed_point => observers_fixed_point
        procedure :: fixed_point_done => observers_fixed_point_done
        procedure :: multipliers_updated => observers_multipliers_updated
        procedure :: step_done => observers_step_done
        procedure :: warning => observers_warning
    end type observers_t

contains

    !> Add `observer` after the others.
    subroutine observers_add(self, observer)
        class(observers_t), intent(inout) :: self
        class(progress_t), target, intent(inout) :: observer
        type(observer_ref_t), allocatable :: longer(:)
        integer :: i
        if (.not. allocated(self%list)) allocate (self%list(0))
        allocate (longer(size(self%list) + 1))
        do i = 1, size(self%list)
            longer(i)%p => self%list(i)%p
        end do
        ! (the observer is the caller's: its hooks change it through this pointer)
        longer(size(longer))%p => observer
        call move_alloc(longer, self%list)
    end subroutine observers_add

    subroutine observers_set_up(self, level_dofs, error)
        class(observers_t), intent(inout) :: self
        integer, intent(in) :: level_dofs(:)
        type(error_t), allocatable, intent(out) :: error
        integer :: i
        do i = 1, n(self)
            call self%list(i)%p%set_up(level_dofs, error)
            if (allocated(error)) return
        end do
    end subroutine observers_set_up

    subroutine observers_substep(self, step, n_steps, substep, cuts, run_cuts, time, fraction)
        class(observers_t), intent(inout) :: self
        integer, intent(in) :: step, n_steps, substep, cuts, run_cuts
        real(dp), intent(in) :: time, fraction
        integer :: i
        do i = 1, n(self)
            call self%list(i)%p%substep(step, n_steps, substep, cuts, run_cuts, time, fraction)
        end do
    end subroutine observers_substep

    subroutine observers_iteration(self, report)
        class(observers_t), intent(inout) :: self
        type(iteration_report_t), intent(in) :: report
        integer :: i
        do i = 1, n(self)
            call self%list(i)%p%iteration(report)
        end do
    end subroutine observers_iteration

    subroutine observers_factorized(self, sign, log10_det)
        class(observers_t), intent(inout) :: self
        integer, intent(in) :: sign
        real(dp), intent(in) :: log10_det
        integer :: i
        do i = 1, n(self)
            call self%list(i)%p%factorized(sign, log10_det)
        end do
    end subroutine observers_factorized

    subroutine observers_linear_solved(self, iterations, residual, asked)
        class(observers_t), intent(inout) :: self
        integer, intent(in) :: iterations
        real(dp), intent(in) :: residual, asked
        integer :: i
        do i = 1, n(self)
            call self%list(i)%p%linear_solved(iterations, residual, asked)
        end do
    end subroutine observers_linear_solved

    subroutine observers_retried(self, step, time, reason)
        class(observers_t), intent(inout) :: self
        integer, intent(in) :: step
        real(dp), intent(in) :: time
        character(len=*), intent(in) :: reason
        integer :: i
        do i = 1, n(self)
            call self%list(i)%p%retried(step, time, reason)
        end do
    end subroutine observers_retried

    subroutine observers_softened(self, step, time, pair, what, reason)
        class(observers_t), intent(inout) :: self
        integer, intent(in) :: step, pair
        real(dp), intent(in) :: time
        character(len=*), intent(in) :: what, reason
        integer :: i
        do i = 1, n(self)
            call self%list(i)%p%softened(step, time, pair, what, reason)
        end do
    end subroutine observers_softened

    subroutine observers_cut(self, cut, reason)
        class(observers_t), intent(inout) :: self
        type(cut_record_t), intent(in) :: cut
        character(len=*), intent(in) :: reason
        integer :: i
        do i = 1, n(self)
            call self%list(i)%p%cut(cut, reason)
        end do
    end subroutine observers_cut

    subroutine observers_fixed_point(self, report)
        class(observers_t), intent(inout) :: self
        type(fixed_point_report_t), intent(in) :: report
        integer :: i
        do i = 1, n(self)
            call self%list(i)%p%fixed_point(report)
        end do
    end subroutine observers_fixed_point

    subroutine observers_fixed_point_done(self, report)
        class(observers_t), intent(inout) :: self
        type(fixed_point_report_t), intent(in) :: report
        integer :: i
        do i = 1, n(self)
            call self%list(i)%p%fixed_point_done(report)
        end do
    end subroutine observers_fixed_point_done

    subroutine observers_multipliers_updated(self, step, update, residual)
        class(observers_t), intent(inout) :: self
        integer, intent(in) :: step, update
        real(dp), intent(in) :: residual
        integer :: i
        do i = 1, n(self)
            call self%list(i)%p%multipliers_updated(step, update, residual)
        end do
    end subroutine observers_multipliers_updated

    subroutine observers_step_done(self, report, u, model, error)
        class(observers_t), intent(inout) :: self
        type(step_report_t), intent(in) :: report
        real(dp), intent(in) :: u(:)
        type(model_t), intent(in) :: model
        type(error_t), allocatable, intent(out) :: error
        integer :: i
        do i = 1, n(self)
            call self%list(i)%p%step_done(report, u, model, error)
            if (allocated(error)) return
        end do
    end subroutine observers_step_done

    subroutine observers_warning(self, text)
        class(observers_t), intent(inout) :: self
        character(len=*), intent(in) :: text
        integer :: i
        do i = 1, n(self)
            call self%list(i)%p%warning(text)
        end do
    end subroutine observers_warning

    !> How many observers there are (none added yet: 0).
    pure integer function n(self)
        class(observers_t), intent(in) :: self
        n = 0
        if (allocated(self%list)) n = size(self%list)
    end function n

end module voiga_solver_observers
