!> The per-point and per-node kernels of the mortar-type methods (`voiga_contact_mortar`
!> and the methods that extend it): one slave point's residual and geometric tangent at
!> fixed interpolated tractions, and the share of a node's weighted slip that counts in
!> the step it touched.
module voiga_contact_mortar_kernels
    use voiga_kinds, only: dp
    use voiga_contact_surface, only: surface_point_t
    use voiga_contact_master, only: master_point_t
    use voiga_contact_kinematics, only: point_operators
    implicit none
    private

    public :: mortar_point, node_touch_factors

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
        n = mp%n(1:2)
        la = norm2(mp%a(1:2))
        that = mp%a(1:2)/la
        g = dot_product(sp%x(1:2) - mp%x(1:2), n)
        ! linearization of the projection: dxi = c . du; master tangent A = Dm + a2 (x) c
        den = dot_product(mp%a(1:2), mp%a(1:2)) - g*dot_product(n, mp%a2(1:2))
        c = (matmul(mp%a(1:2), gm) + g*matmul(n, dm))/den
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

    !> The share f_A of each node's weighted slip that counts, and d f_A / d(g_A / D_A):
    !> all of it (1, 0) for a node in contact at the last converged state (`active`);
    !> for one open there with mean gap g0 = `gap0` > 0 and now g = g_A / D_A < 0, the part
    !> after the linearly interpolated touch, f = -g / (g0 - g), f' = -g0 / (g0 - g)^2; 0
    !> when it is not closed now or had no projection then (huge: it touches here).
    !> Without it a node that closes in a step sticks where it was at the step's start,
    !> and the motion of the open surface before it touched (an elastic body's surface
    !> sliding along a rigid one under the growing load) becomes a spurious stick traction.
    !> `g_a` weighted gaps (huge where nothing projects), `d_a` weights [nodes].
    pure subroutine node_touch_factors(active, gap0, g_a, d_a, f, df)
        logical, intent(in) :: active(:)
        real(dp), intent(in) :: gap0(:), g_a(:), d_a(:)
        real(dp), intent(out) :: f(:), df(:)
        real(dp) :: g
        integer :: a
        f = 1.0_dp
        df = 0.0_dp
        do a = 1, size(f)
            if (active(a) .or. .not. gap0(a) > 0.0_dp) cycle
            f(a) = 0.0_dp
            if (gap0(a) >= huge(1.0_dp) .or. g_a(a) >= huge(1.0_dp) .or. d_a(a) <= 0.0_dp) cycle
            g = g_a(a)/d_a(a)
            if (g >= 0.0_dp) cycle
            f(a) = -g/(gap0(a) - g)
            df(a) = -gap0(a)/(gap0(a) - g)**2
        end do
    end subroutine node_touch_factors

end module voiga_contact_mortar_kernels
