!> The stick predictor of a frictional substep (docs/theory.md, section 6, "Stick
!> predictor"): a start for Newton where the points that stuck at the last converged
!> state still stick, taken by one linear step on the Newton attempt's matrices.
module voiga_solver_stick_predictor
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_model, only: model_t
    use voiga_model_assembly, only: assemble
    use voiga_solver_newton, only: newton_t
    use voiga_solver_records, only: wall_seconds
    use voiga_solver_context, only: context_t
    implicit none
    private

    public :: stick_predictor

contains

    !> The stick predictor of a frictional substep (`ctx`) that starts from
    !> the last converged state `u` (prescribed values set): one linear step with
    !> every active contact point sticking (the elastic predictor of its traction kept
    !> whatever its size, `contact_law_t%return_map`). When a rigid obstacle or a
    !> body starts to slide the points that stuck at the last state are all beyond
    !> their slip bound at `u` (the obstacle moved under them): the Coulomb tangent
    !> there has no tangential stiffness, Newton's first step overshoots and the
    !> stick/slip states cycle (hertz rigid flat, NN2.2, 16 cuts and 5589 iterations
    !> for the first sliding step; docs/robustness.md). The predicted start is where
    !> the points held, which most of them do. Newton then starts there with the true
    !> law, its tolerances relative to the residual there; the step counts as one
    !> iteration.
    subroutine stick_predictor(self, model, ctx, u, error)
        type(newton_t), intent(inout) :: self
        type(model_t), intent(inout) :: model
        type(context_t), intent(inout) :: ctx
        real(dp), intent(inout) :: u(:)
        type(error_t), allocatable, intent(out) :: error
        real(dp), allocatable :: du(:), rhs(:)
        real(dp) :: bulk0, contact0, tic
        integer :: ip

        do ip = 1, size(model%pairs)
            call model%pairs(ip)%pair%stick_trial(.true.)
        end do
        bulk0 = ctx%stats%assembly%seconds_bulk
        contact0 = ctx%stats%assembly%seconds_contact
        call assemble(model, u, ctx%time, self%r, ctx%stats%assembly, error, self%k, self%map, refit=.true.)
        ctx%record%seconds(1) = ctx%record%seconds(1) + ctx%stats%assembly%seconds_bulk - bulk0
        ctx%record%seconds(2) = ctx%record%seconds(2) + ctx%stats%assembly%seconds_contact - contact0
        do ip = 1, size(model%pairs)
            call model%pairs(ip)%pair%stick_trial(.false.)
            call model%pairs(ip)%pair%reset_trial()
        end do
        if (allocated(error)) return
        tic = wall_seconds()
        call self%k%fix_dofs(model%fixed)
        call self%linear%renew_analysis()
        call self%linear%factor(self%k, error)
        ctx%record%seconds(3) = ctx%record%seconds(3) + wall_seconds() - tic
        if (allocated(error)) return
        tic = wall_seconds()
        rhs = -merge(0.0_dp, self%r, model%fixed)
        allocate (du(size(u)))
        call self%linear%solve(self%k, rhs, du, error)
        ctx%record%seconds(4) = ctx%record%seconds(4) + wall_seconds() - tic
        if (allocated(error)) return
        if (.not. all(ieee_is_finite(du))) then
            call fatal_error(error, 'the stick predictor is not finite', error_code%numeric)
            return
        end if
        u = u + du
        ctx%stats%iterations = ctx%stats%iterations + 1
        ctx%record%iterations_total = ctx%record%iterations_total + 1
        ctx%stats%stick_predictions = ctx%stats%stick_predictions + 1
    end subroutine stick_predictor

end module voiga_solver_stick_predictor
