!> Gauss-point-to-surface (GPTS) penalty contact at one slave quadrature point:
!> normal penalty, Coulomb friction by an elastic predictor and return map on the
!> convected master coordinate, residual and consistent tangent (docs/theory.md,
!> section 7).
!>
!> Tresca mode (optional argument `bound`): the slip limit is a given bound instead
!> of mu p_N; its tangent has no normal-tangential coupling (the successive
!> approximations of `voiga_solver_newton`, docs/robustness.md, "Tresca fixed point").
!>
!> Local DOFs: the slave point's functions first (2 per function), then the
!> master's (none for a rigid master). G maps them to x_s - x_m(xi), Dm to the
!> master tangent a = dx_m/dxi at fixed xi, Ds to the slave tangent.
module voiga_contact_gpts
    use voiga_kinds, only: dp
    use voiga_contact_surface, only: surface_point_t
    use voiga_contact_master, only: master_point_t
    implicit none
    private

    public :: contact_law_t, gpts_point, point_operators, state_inactive, state_stick, state_slip

    integer, parameter :: state_inactive = 0, state_stick = 1, state_slip = 2

    !> Penalty and friction parameters of a pair.
    type :: contact_law_t
        real(dp) :: eps_n = 0.0_dp, eps_t = 0.0_dp, mu = 0.0_dp
    end type contact_law_t

contains

    !> Residual `r` (internal-force sign: r = -int G^T t da) and tangent `k` of an
    !> active point, with the traction t on the slave. Frictionless when mu = 0
    !> (no friction code runs). `anchor` is the committed stick point (convected
    !> master coordinate); `new_anchor` the one to commit if the step converges.
    !> With `bound` (and mu > 0) the slip limit |t_T| <= bound is prescribed (Tresca
    !> friction) instead of mu pn; without it the Coulomb code below runs unchanged.
    pure subroutine gpts_point(law, w, sp, mp, anchor, r, k, state, g, pn, pt, new_anchor, bound)
        type(contact_law_t), intent(in) :: law
        !> Quadrature weight times d(xi_s)/d(reference parameter): da = |a_s| w.
        real(dp), intent(in) :: w
        type(surface_point_t), intent(in) :: sp
        type(master_point_t), intent(in) :: mp
        real(dp), intent(in) :: anchor
        real(dp), intent(out) :: r(:), k(:, :)
        integer, intent(out) :: state
        !> Normal gap, contact pressure (>= 0) and tangential traction t . t_hat.
        real(dp), intent(out) :: g, pn, pt
        real(dp), intent(out) :: new_anchor
        !> Prescribed slip bound (traction, >= 0): Tresca mode.
        real(dp), intent(in), optional :: bound
        real(dp) :: gm(2, size(r)), dm(2, size(r)), ds(2, size(r)), amat(2, size(r)), tmat(2, size(r))
        real(dp) :: c(size(r)), ng(size(r)), na(size(r)), gt(size(r)), dmt(size(r)), dst(size(r))
        real(dp) :: n(2), that(2), ts(2), t(2), la, las, den, da, slip, ttr, s
        integer :: a

        call point_operators(sp, mp, gm, dm, ds)
        n = mp%n
        la = norm2(mp%a)
        that = mp%a/la
        las = norm2(sp%a)
        ts = sp%a/las
        da = las*w
        g = dot_product(sp%x - mp%x, n)
        pn = -law%eps_n*g
        ! linearization of the projection: dxi = c . du
        den = dot_product(mp%a, mp%a) - g*dot_product(n, mp%a2)
        c = (matmul(mp%a, gm) + g*matmul(n, dm))/den
        ! total change of the master tangent: A = Dm + a2 (x) c
        amat(1, :) = dm(1, :) + mp%a2(1)*c
        amat(2, :) = dm(2, :) + mp%a2(2)*c
        ng = matmul(n, gm)          ! d g
        na = matmul(n, amat)/la     ! n . dA / |a|: dn = -t_hat na, dt_hat = n na

        ! normal traction and its derivative
        t = pn*n
        tmat(1, :) = -law%eps_n*(n(1)*ng - g*that(1)*na)
        tmat(2, :) = -law%eps_n*(n(2)*ng - g*that(2)*na)
        state = state_stick
        pt = 0.0_dp
        new_anchor = anchor
        if (law%mu > 0.0_dp .and. present(bound)) then
            ! Tresca: the same predictor and return map with the slip limit fixed
            slip = mp%xi - anchor
            ttr = law%eps_t*abs(slip)*la
            if (ttr <= bound) then
                t = t - law%eps_t*slip*mp%a
                tmat(1, :) = tmat(1, :) - law%eps_t*(mp%a(1)*c + slip*amat(1, :))
                tmat(2, :) = tmat(2, :) - law%eps_t*(mp%a(2)*c + slip*amat(2, :))
                pt = -law%eps_t*slip*la
            else
                ! t_T = -bound s t_hat; only t_hat moves (dt_hat = n na)
                state = state_slip
                s = sign(1.0_dp, slip)
                t = t - bound*s*that
                tmat(1, :) = tmat(1, :) - bound*s*n(1)*na
                tmat(2, :) = tmat(2, :) - bound*s*n(2)*na
                pt = -bound*s
                new_anchor = mp%xi - s*bound/(law%eps_t*la)
            end if
        else if (law%mu > 0.0_dp) then
            ! elastic predictor on the convected coordinate
            slip = mp%xi - anchor
            ttr = law%eps_t*abs(slip)*la
            if (ttr <= law%mu*pn) then
                t = t - law%eps_t*slip*mp%a
                tmat(1, :) = tmat(1, :) - law%eps_t*(mp%a(1)*c + slip*amat(1, :))
                tmat(2, :) = tmat(2, :) - law%eps_t*(mp%a(2)*c + slip*amat(2, :))
                pt = -law%eps_t*slip*la
            else
                ! return map: |t_T| = mu pn, the anchor follows the slave point
                state = state_slip
                s = sign(1.0_dp, slip)
                t = t - law%mu*pn*s*that
                tmat(1, :) = tmat(1, :) + law%mu*law%eps_n*s*(that(1)*ng + g*n(1)*na)
                tmat(2, :) = tmat(2, :) + law%mu*law%eps_n*s*(that(2)*ng + g*n(2)*na)
                pt = -law%mu*pn*s
                new_anchor = mp%xi - s*law%mu*pn/(law%eps_t*la)
            end if
        end if

        gt = matmul(t, gm)          ! G^T t
        dmt = matmul(t, dm)         ! Dm^T t
        dst = matmul(ts, ds)        ! t_s . Ds
        r = -da*gt
        do a = 1, size(r)
            ! K = -da G^T T + da (Dm^T t) c^T - w (G^T t)(t_s^T Ds)
            k(:, a) = -da*matmul(transpose(gm), tmat(:, a)) + da*dmt*c(a) - w*gt*dst(a)
        end do
    end subroutine gpts_point

    !> The linear maps of a slave point and its projection on the local DOFs (the
    !> slave point's functions first, 2 per function, then the master's): `gm` to
    !> x_s - x_m(xi), `dm` to the master tangent dx_m/dxi at fixed xi, `ds` to the
    !> slave tangent. Shapes [2, 2 (ns + nm)].
    pure subroutine point_operators(sp, mp, gm, dm, ds)
        type(surface_point_t), intent(in) :: sp
        type(master_point_t), intent(in) :: mp
        real(dp), intent(out) :: gm(:, :), dm(:, :), ds(:, :)
        integer :: ns, a
        ns = size(sp%r)
        gm = 0.0_dp
        dm = 0.0_dp
        ds = 0.0_dp
        do a = 1, ns
            gm(1, 2*a - 1) = sp%r(a)
            gm(2, 2*a) = sp%r(a)
            ds(1, 2*a - 1) = sp%dr(a)
            ds(2, 2*a) = sp%dr(a)
        end do
        do a = 1, size(mp%r)
            gm(1, 2*(ns + a) - 1) = -mp%r(a)
            gm(2, 2*(ns + a)) = -mp%r(a)
            dm(1, 2*(ns + a) - 1) = mp%dr(a)
            dm(2, 2*(ns + a)) = mp%dr(a)
        end do
    end subroutine point_operators

end module voiga_contact_gpts
