!> Mortar-type penalty contact (`&contact method = 'mortar'`): the gap and the
!> tangential slip are weighted with the slave edge's functions and integrated over
!> the slave's Gauss points, so the penalty acts once per slave control point A
!> instead of once per Gauss point (docs/theory.md, section 7.4):
!>
!>     g_A = int N_A g dA0,   D_A = int N_A dA0,   p_A = -eps_N g_A / D_A   (g_A < 0)
!>
!> and the traction at a slave point is interpolated from the control points,
!> p(xi) = sum_A N_A(xi) p_A. Friction: per control point, the tangential traction
!> t_A is the state variable, with an elastic predictor on the weighted increment
!> of slip ds_A = int N_A (xi_m - xi_m,last) |a_m| dA0 and a return map onto
!> |t_A| <= mu p_A. The integrals use the reference length dA0 of the slave edge
!> (nominal tractions); the residual at a point is r = -w0 G^T (p n + t t_hat), as
!> in `voiga_contact_gpts`.
!>
!> This module holds the per-point and per-control-point kernels; the sums over
!> points are in `voiga_contact_pair`. Local DOFs as in `voiga_contact_gpts`.
module voiga_contact_mortar
    use voiga_kinds, only: dp
    use voiga_contact_surface, only: surface_point_t
    use voiga_contact_master, only: master_point_t
    use voiga_contact_gpts, only: contact_law_t, point_operators, state_inactive, state_stick, state_slip
    implicit none
    private

    public :: mortar_point, mortar_law

contains

    !> Residual `r` and geometric tangent `k` of one slave point whose interpolated
    !> pressure `pbar` and tangential traction `tbar` are held fixed; and the point's
    !> derivative vectors (local DOFs), from which `voiga_contact_pair` forms the
    !> coupling through the control-point tractions: `gn` = d g / du = G^T n,
    !> `gt` = G^T t_hat, `m` = d ds / du with ds = dxi |a_m| the point's slip since
    !> the last converged state (`dxi` = xi_m - xi_m,last; zero vector without
    !> `slip`, a point that had no projection then).
    pure subroutine mortar_point(w0, sp, mp, pbar, tbar, dxi, slip, friction, r, k, gn, gt, m)
        !> Reference length weight: Gauss weight x |dX/dxi|.
        real(dp), intent(in) :: w0
        type(surface_point_t), intent(in) :: sp
        type(master_point_t), intent(in) :: mp
        real(dp), intent(in) :: pbar, tbar, dxi
        logical, intent(in) :: slip
        !> False: frictionless, `gt` and `m` are zero (no friction code runs).
        logical, intent(in) :: friction
        real(dp), intent(out) :: r(:), k(:, :), gn(:), gt(:), m(:)
        real(dp) :: gm(2, size(r)), dm(2, size(r)), ds(2, size(r)), amat(2, size(r))
        real(dp) :: c(size(r)), na(size(r)), dmt(size(r)), n(2), that(2), t(2), dt(2), la, g, den
        integer :: a

        call point_operators(sp, mp, gm, dm, ds)
        n = mp%n
        la = norm2(mp%a)
        that = mp%a/la
        g = dot_product(sp%x - mp%x, n)
        ! linearization of the projection: dxi = c . du; master tangent A = Dm + a2 (x) c
        den = dot_product(mp%a, mp%a) - g*dot_product(n, mp%a2)
        c = (matmul(mp%a, gm) + g*matmul(n, dm))/den
        amat(1, :) = dm(1, :) + mp%a2(1)*c
        amat(2, :) = dm(2, :) + mp%a2(2)*c
        na = matmul(n, amat)/la     ! dn = -t_hat na, dt_hat = n na
        gn = matmul(n, gm)
        gt = 0.0_dp
        m = 0.0_dp
        if (friction) then
            gt = matmul(that, gm)
            if (slip) m = la*c + dxi*matmul(that, amat)
        end if
        t = pbar*n + tbar*that
        ! d t at fixed pbar, tbar: pbar dn + tbar dt_hat = (tbar n - pbar t_hat) na
        dt = tbar*n - pbar*that
        r = -w0*matmul(t, gm)
        dmt = matmul(t, dm)
        do a = 1, size(r)
            ! K = -w0 G^T dt na^T + w0 (Dm^T t) c^T (the master functions move with xi)
            k(:, a) = -w0*matmul(dt, gm)*na(a) + w0*dmt*c(a)
        end do
    end subroutine mortar_point

    !> The law at one slave control point: weighted gap `g_a`, weight `d_a` =
    !> int N_A dA0, weighted slip increment `ds_a` and committed tangential traction
    !> `t_old`; gives the pressure `p` (active when g_a < gap_tol d_a), the
    !> tangential traction `t` (zero without friction), its trial value and the state. Frictionless
    !> when mu = 0 (no friction code runs).
    pure subroutine mortar_law(law, g_a, d_a, ds_a, t_old, gap_tol, p, t, state, ttr)
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
            if (abs(ttr) <= law%mu*p) then
                t = ttr
            else
                state = state_slip
                t = law%mu*p*sign(1.0_dp, ttr)
            end if
        end if
    end subroutine mortar_law

end module voiga_contact_mortar
