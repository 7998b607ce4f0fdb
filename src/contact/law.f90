!> The contact law: normal penalty and Coulomb friction by an elastic predictor
!> and a return map (docs/theory.md, section 7). The per-point form of GPTS, whose
!> tangent is interleaved with the kinematics of the point, is in
!> `voiga_contact_gpts`; here the law's parameters, the contact states and the law
!> at one slave control point of the mortar-type penalty.
module voiga_contact_law
    use voiga_kinds, only: dp
    implicit none
    private

    public :: contact_law_t, control_point_law, control_point_law3, state_inactive, state_stick, state_slip

    !> Contact states of a slave point or control point.
    integer, parameter :: state_inactive = 0, state_stick = 1, state_slip = 2

    !> Penalty and friction parameters of a pair.
    type :: contact_law_t
        real(dp) :: eps_n = 0.0_dp, eps_t = 0.0_dp, mu = 0.0_dp
        !> False only for the stick predictor of a substep (`voiga_solver_newton`,
        !> `stick_predictor`): the elastic predictor is kept whatever its size, so every
        !> active point sticks.
        logical :: return_map = .true.
    end type contact_law_t

contains

    !> The law at one slave control point of the mortar-type penalty: weighted gap
    !> `g_a`, weight `d_a` = int N_A dA0, weighted slip increment `ds_a` and
    !> committed tangential traction `t_old`; gives the pressure `p` (active when
    !> g_a < gap_tol d_a), the tangential traction `t` (zero without friction), its
    !> trial value and the state. Frictionless when mu = 0 (no friction code runs).
    pure subroutine control_point_law(law, g_a, d_a, ds_a, t_old, gap_tol, p, t, state, ttr)
        type(contact_law_t), intent(in) :: law
        real(dp), intent(in) :: g_a, d_a, ds_a, t_old, gap_tol
        real(dp), intent(out) :: p, t
        integer, intent(out) :: state
        !> Trial tangential traction (elastic predictor; 0 when open or frictionless).
        real(dp), intent(out) :: ttr

        p = 0.0_dp
        t = 0.0_dp
        ttr = 0.0_dp
        state = state_inactive
        if (d_a <= 0.0_dp .or. g_a >= gap_tol*d_a) return
        p = -law%eps_n*g_a/d_a
        state = state_stick
        if (law%mu > 0.0_dp) then
            ttr = t_old - law%eps_t*ds_a/d_a
            if (abs(ttr) <= law%mu*p .or. .not. law%return_map) then
                t = ttr
            else
                state = state_slip
                t = law%mu*p*sign(1.0_dp, ttr)
            end if
        end if
    end subroutine control_point_law

    !> `control_point_law` on a face: the weighted slip `ds_a`, the committed traction
    !> `t_old` and the traction `t` are vectors [3] (Cartesian components; the tangent
    !> plane's, up to the master's curvature over the node's support: the points project
    !> it onto theirs), and the return map is radial, onto the disc |t| <= mu p.
    pure subroutine control_point_law3(law, g_a, d_a, ds_a, t_old, gap_tol, p, t, state, ttr)
        type(contact_law_t), intent(in) :: law
        real(dp), intent(in) :: g_a, d_a, ds_a(3), t_old(3), gap_tol
        real(dp), intent(out) :: p, t(3)
        integer, intent(out) :: state
        !> Trial tangential traction [3] (0 when open).
        real(dp), intent(out) :: ttr(3)
        real(dp) :: size_tr
        p = 0.0_dp
        t = 0.0_dp
        ttr = 0.0_dp
        state = state_inactive
        if (d_a <= 0.0_dp .or. g_a >= gap_tol*d_a) return
        p = -law%eps_n*g_a/d_a
        state = state_stick
        ! (a phase without friction: no tangential traction, as on an edge)
        if (law%mu <= 0.0_dp) return
        ttr = t_old - law%eps_t*ds_a/d_a
        size_tr = norm2(ttr)
        ! (active at a gap just below gap_tol D_A, p is a round-off below 0: no trial
        ! traction is then no slip direction either, it sticks)
        if (size_tr <= law%mu*p .or. size_tr <= 0.0_dp .or. .not. law%return_map) then
            t = ttr
        else
            state = state_slip
            t = law%mu*p*ttr/size_tr
        end if
    end subroutine control_point_law3

end module voiga_contact_law
