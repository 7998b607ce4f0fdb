!> How long a Newton step is taken (docs/robustness.md): each rule looks at the
!> trial point u_prev + alpha du and either accepts it or shortens alpha.
!>
!> - the crossing limit of the contact pairs (`step_limit`, mortar pairs): a step
!>   that crosses a contact-state boundary the tangent did not describe stops just
!>   beyond the first crossing;
!> - natural damping (`&solver damping = 'natural'`, affine invariant): the
!>   simplified Newton correction at the trial point must be shorter than
!>   (1 - alpha/4) times the Newton correction; the step follows a Kantorovich
!>   estimate of the curvature;
!> - residual backtracking (`damping = 'residual'`, and wherever the contact
!>   states changed): a step that increases the residual norm is halved.
module voiga_solver_step_length
    use voiga_kinds, only: dp
    use voiga_model, only: model_t
    implicit none
    private

    public :: damping_names, crossing_limit, backtracks, natural_reduction, natural_first_step
    public :: max_line_search, creep_step, max_natural_damping, min_natural_step

    !> The valid values of `&solver damping` (the case reader checks against them).
    character(len=*), parameter :: damping_names(2) = [character(len=8) :: 'residual', 'natural']

    !> Most halvings of one Newton step.
    integer, parameter :: max_line_search = 8

    !> Mortar pairs: a Newton step that closes an open control point is shortened to
    !> this multiple of the fraction at which the first one closes (a little beyond,
    !> so that it is active and its stiffness in the next tangent).
    real(dp), parameter :: closing_overshoot = 1.01_dp

    !> A Newton iteration whose accepted step is at most this long creeps; an attempt
    !> that fails with half its iterations creeping (residual damping) names natural
    !> damping in its message.
    real(dp), parameter :: creep_step = 0.0625_dp

    !> Natural damping: most step reductions of one Newton iteration, and the
    !> smallest step length.
    integer, parameter :: max_natural_damping = 10
    real(dp), parameter :: min_natural_step = 1.0e-4_dp

contains

    !> The fraction of the last step the contact pairs allow (1: all of it).
    pure real(dp) function crossing_limit(model) result(frac)
        type(model_t), intent(in) :: model
        integer :: ip
        frac = 1.0_dp
        do ip = 1, size(model%pairs)
            frac = min(frac, model%pairs(ip)%pair%step_limit(closing_overshoot))
        end do
    end function crossing_limit

    !> Residual backtracking: the trial point's residual `rn` exceeds the last
    !> accepted one's, the step has been halved fewer than `max_line_search` times
    !> (`nls`), and the residual is not at its round-off level (`roundoff`).
    pure logical function backtracks(rn, rn_prev, nls, roundoff)
        real(dp), intent(in) :: rn, rn_prev
        integer, intent(in) :: nls
        logical, intent(in) :: roundoff
        backtracks = rn > rn_prev .and. nls < max_line_search .and. .not. roundoff
    end function backtracks

    !> Natural monotonicity test at step length `alpha` with the simplified
    !> correction `du_bar` at the trial point and the Newton correction `du`
    !> (norm `du_norm`); `reduce` when it fails (and fewer than `max_natural_damping`
    !> reductions were made, `nls`), with the new step length `new_alpha`.
    pure subroutine natural_reduction(du_bar, du, du_norm, alpha, nls, reduce, new_alpha)
        real(dp), intent(in) :: du_bar(:), du(:), du_norm, alpha
        integer, intent(in) :: nls
        logical, intent(out) :: reduce
        real(dp), intent(out) :: new_alpha
        real(dp) :: theta, h_est
        theta = norm2(du_bar)/du_norm
        reduce = theta > 1.0_dp - 0.25_dp*alpha .and. nls < max_natural_damping
        new_alpha = alpha
        if (.not. reduce) return
        ! Kantorovich estimate of the step the curvature allows
        h_est = 2.0_dp*norm2(du_bar - (1.0_dp - alpha)*du)/(alpha**2*du_norm)
        new_alpha = max(min(0.5_dp*alpha, 1.0_dp/max(h_est, tiny(1.0_dp))), min_natural_step)
    end subroutine natural_reduction

    !> Natural damping's a-priori step length for a new correction `du` (norm
    !> `du_norm`) from the last accepted step's contraction: its simplified
    !> correction `du_bar_acc`, the previous correction's norm and step length.
    pure real(dp) function natural_first_step(du_bar_acc, du, du_norm, du_norm_prev, alpha_prev) result(alpha)
        real(dp), intent(in) :: du_bar_acc(:), du(:), du_norm, du_norm_prev, alpha_prev
        real(dp) :: h_est
        h_est = norm2(du_bar_acc - du)*du_norm/max(du_norm_prev*norm2(du_bar_acc), tiny(1.0_dp))
        alpha = max(min(1.0_dp, alpha_prev/max(h_est, tiny(1.0_dp))), min_natural_step)
    end function natural_first_step

end module voiga_solver_step_length
