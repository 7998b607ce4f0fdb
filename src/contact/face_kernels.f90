!> The per-point contact kernels on a face (3D, two convective coordinates on each
!> side): the Gauss-point-to-surface penalty (`gpts_point3`) and the mortar-type
!> point at a fixed interpolated pressure (`mortar_point3`). What differs from the
!> edge's kernels (`voiga_contact_gpts`, `voiga_contact_mortar_kernels`) is the
!> geometry of a surface (two tangents, the metric and curvature of the master, the
!> area element of the slave: `face_linearization`); the loops over points, the
!> law's parameters, the history and the output are the pairs' (docs/theory.md,
!> section 7, "Faces").
!>
!> Friction: Coulomb on the tangent plane, per point for GPTS (`coulomb3`), per
!> control point for the mortar-type pair (`mortar_friction_point3` gives a point's
!> share; the law is `control_point_law3`).
!>
!> Local DOFs of a point: the slave point's functions first (3 per function), then
!> the master's (none for a rigid master), as in `voiga_contact_kinematics`.
module voiga_contact_face_kernels
    use voiga_kinds, only: dp
    use voiga_contact_surface, only: surface_point_t
    use voiga_contact_master, only: master_point_t
    use voiga_contact_law, only: contact_law_t, state_stick, state_slip
    use voiga_nurbs_patch, only: cross
    implicit none
    private

    public :: gpts_point3, mortar_point3, mortar_friction_point3

contains

    !> Residual `r` (internal-force sign: r = -int G^T t da) and tangent `k` of an
    !> active slave point on a face, t = p_N n + t_T with p_N = -eps_n g. `w` is the
    !> Gauss weight times the parametric Jacobian of the slave cell: da = |a_1 x a_2| w.
    !> Frictionless when mu = 0 (no friction code runs). With friction, Coulomb's law on
    !> the tangent plane by an elastic predictor on the convected slip since the stick
    !> anchor and a radial return (section 7, "Faces"): the slip s = xi - anchor (for a
    !> point that touched in this step, the part after the touch, as on an edge), its
    !> vector g_T = s^alpha m_alpha, the trial t_T = -eps_T g_T; beyond mu p_N (or the
    !> prescribed `bound`, Tresca mode) t_T = mu p_N nu, nu = t_tr / |t_tr|, and the anchor
    !> follows to where |t_tr| = mu p_N.
    pure subroutine gpts_point3(law, w, sp, mp, anchor, touch, gap0, r, k, state, g, pn, tt, new_anchor, bound)
        type(contact_law_t), intent(in) :: law
        real(dp), intent(in) :: w
        type(surface_point_t), intent(in) :: sp
        type(master_point_t), intent(in) :: mp
        !> The committed stick anchor (master coordinates), whether the point was open at
        !> the last converged state and its gap there (`voiga_contact_gpts`, `gpts_point`).
        real(dp), intent(in) :: anchor(2), gap0
        logical, intent(in) :: touch
        real(dp), intent(out) :: r(:), k(:, :)
        integer, intent(out) :: state
        !> Normal gap, contact pressure (>= 0 in contact), tangential traction [3].
        real(dp), intent(out) :: g, pn, tt(3)
        real(dp), intent(out) :: new_anchor(2)
        real(dp), intent(in), optional :: bound
        real(dp) :: gm(3, size(r)), dm(3, size(r), 2), dmt(3, size(r), 2), c(size(r), 2), ng(size(r)), &
                    dn(3, size(r)), dda(size(r)), gt(size(r)), dt(3, size(r)), t(3), da
        integer :: a, b
        call face_linearization(sp, mp, w, g, da, gm, dm, c, ng, dn, dda, dmt)
        pn = -law%eps_n*g
        do a = 1, size(r)
            dt(:, a) = -law%eps_n*mp%n*ng(a) + pn*dn(:, a)
        end do
        tt = 0.0_dp
        state = state_stick
        new_anchor = [mp%xi, mp%eta]
        if (law%mu > 0.0_dp) call coulomb3(law, mp, anchor, touch, gap0, g, pn, c, ng, dmt, tt, dt, state, &
                                           new_anchor, bound)
        t = pn*mp%n + tt
        do a = 1, size(r)
            gt(a) = dot_product(t, gm(:, a))
        end do
        r = -da*gt
        do a = 1, size(r)
            ! the master functions move with xi; da varies
            do b = 1, size(r)
                k(b, a) = -da*dot_product(gm(:, b), dt(:, a)) &
                          + da*(dot_product(dm(:, b, 1), t)*c(a, 1) + dot_product(dm(:, b, 2), t)*c(a, 2)) &
                          - gt(b)*dda(a)
            end do
        end do
    end subroutine gpts_point3

    !> The tangential traction `tt` of Coulomb's law on a face (see `gpts_point3`), added
    !> with its derivative to `dt` [3, nd]; `c` the projection's derivative [nd, 2],
    !> `ng` the gap's, `dmt` the master tangents' total derivatives [3, nd, 2].
    pure subroutine coulomb3(law, mp, anchor, touch, gap0, g, pn, c, ng, dmt, tt, dt, state, new_anchor, bound)
        type(contact_law_t), intent(in) :: law
        type(master_point_t), intent(in) :: mp
        real(dp), intent(in) :: anchor(2), gap0, g, pn, c(:, :), ng(:), dmt(:, :, :)
        logical, intent(in) :: touch
        real(dp), intent(out) :: tt(3)
        real(dp), intent(inout) :: dt(:, :), new_anchor(2)
        integer, intent(inout) :: state
        real(dp), intent(in), optional :: bound
        real(dp) :: s(2), ds(size(ng), 2), gtv(3), dg(3, size(ng)), nu(3), limit, f, tr
        integer :: a
        s = [mp%xi, mp%eta] - anchor
        ds = c
        if (touch) then
            ! only the slip after the interpolated touch counts (none without a projection then)
            if (gap0 < huge(1.0_dp) .and. gap0 > g) then
                f = -g/(gap0 - g)
                ds(:, 1) = f*c(:, 1) - s(1)*gap0/(gap0 - g)**2*ng
                ds(:, 2) = f*c(:, 2) - s(2)*gap0/(gap0 - g)**2*ng
                s = f*s
            else
                s = 0.0_dp
                ds = 0.0_dp
            end if
        end if
        gtv = s(1)*mp%a + s(2)*mp%b
        do a = 1, size(ng)
            dg(:, a) = mp%a*ds(a, 1) + mp%b*ds(a, 2) + s(1)*dmt(:, a, 1) + s(2)*dmt(:, a, 2)
        end do
        tt = -law%eps_t*gtv
        tr = norm2(tt)
        limit = law%mu*pn
        if (present(bound)) limit = bound
        new_anchor = [mp%xi, mp%eta] - s
        if (tr <= limit .or. .not. law%return_map) then
            dt = dt - law%eps_t*dg
            return
        end if
        ! radial return: t_T = limit nu; d nu = (I - nu nu^T) d t_tr / |t_tr|
        state = state_slip
        nu = tt/tr
        tt = limit*nu
        do a = 1, size(ng)
            dg(:, a) = -law%eps_t*dg(:, a)
            dt(:, a) = dt(:, a) + limit/tr*(dg(:, a) - nu*dot_product(nu, dg(:, a)))
            ! Coulomb: the bound moves with p_N (Tresca: it is fixed)
            if (.not. present(bound)) dt(:, a) = dt(:, a) - law%mu*law%eps_n*ng(a)*nu
        end do
        new_anchor = [mp%xi, mp%eta] - (limit/tr)*s
    end subroutine coulomb3

    !> The mortar-type point on a face (frictionless): residual `r` = -w0 G^T (pbar n)
    !> at the fixed interpolated pressure `pbar` (per reference area, `w0` the point's
    !> reference area), its geometric tangent `k` at fixed pbar (the normal turning,
    !> the master functions moving with xi), and `gn` = d g / du = G^T n, from which
    !> the pair forms the coupling through the control points' pressures.
    pure subroutine mortar_point3(w0, sp, mp, pbar, r, k, gn)
        real(dp), intent(in) :: w0, pbar
        type(surface_point_t), intent(in) :: sp
        type(master_point_t), intent(in) :: mp
        real(dp), intent(out) :: r(:), k(:, :), gn(:)
        real(dp) :: gm(3, size(r)), dm(3, size(r), 2), c(size(r), 2), dn(3, size(r)), dda(size(r)), t(3), g, da
        integer :: a, b
        ! (w = 1: da and dda are not used, the integral is over the reference area)
        call face_linearization(sp, mp, 1.0_dp, g, da, gm, dm, c, gn, dn, dda)
        t = pbar*mp%n
        do a = 1, size(r)
            r(a) = -w0*dot_product(t, gm(:, a))
        end do
        do a = 1, size(r)
            do b = 1, size(r)
                k(b, a) = -w0*pbar*dot_product(gm(:, b), dn(:, a)) &
                          + w0*(dot_product(dm(:, b, 1), t)*c(a, 1) + dot_product(dm(:, b, 2), t)*c(a, 2))
            end do
        end do
    end subroutine mortar_point3

    !> The mortar-type point on a face with friction: as `mortar_point3`, with the
    !> interpolated tangential traction `tbar` [3] projected onto the master's tangent
    !> plane at the point, t = pbar n + (I - n n^T) tbar, both held fixed in `k` (the
    !> normal and the projector turning); and the vectors from which the pair forms the
    !> coupling through the control points: `gn` = G^T n [nd], `gp` = G^T (I - n n^T)
    !> [nd, 3], and (`slip`: the point had a projection at the last converged state) its
    !> slip vector `s` = dxi^alpha m_alpha [3] (`dxi` [2] = xi_m - xi_m,last in both
    !> master coordinates) and `ms` = d s / du [3, nd]; `tt` the projected traction [3].
    pure subroutine mortar_friction_point3(w0, sp, mp, pbar, tbar, dxi, slip, r, k, gn, gp, s, ms, tt)
        real(dp), intent(in) :: w0, pbar, tbar(3), dxi(2)
        type(surface_point_t), intent(in) :: sp
        type(master_point_t), intent(in) :: mp
        logical, intent(in) :: slip
        real(dp), intent(out) :: r(:), k(:, :), gn(:), gp(:, :), s(3), ms(:, :), tt(3)
        real(dp) :: gm(3, size(r)), dm(3, size(r), 2), dmt(3, size(r), 2), c(size(r), 2), dn(3, size(r)), &
                    dda(size(r)), dt(3, size(r)), t(3), n(3), g, da, tn
        integer :: a, b
        call face_linearization(sp, mp, 1.0_dp, g, da, gm, dm, c, gn, dn, dda, dmt)
        n = mp%n
        tn = dot_product(n, tbar)
        tt = tbar - tn*n
        t = pbar*n + tt
        do a = 1, size(r)
            r(a) = -w0*dot_product(t, gm(:, a))
            gp(a, :) = gm(:, a) - n*dot_product(n, gm(:, a))
            ! d t at fixed pbar, tbar: pbar dn - (n . tbar) dn - n (dn . tbar)
            dt(:, a) = (pbar - tn)*dn(:, a) - n*dot_product(dn(:, a), tbar)
        end do
        do a = 1, size(r)
            do b = 1, size(r)
                k(b, a) = -w0*dot_product(gm(:, b), dt(:, a)) &
                          + w0*(dot_product(dm(:, b, 1), t)*c(a, 1) + dot_product(dm(:, b, 2), t)*c(a, 2))
            end do
        end do
        s = 0.0_dp
        ms = 0.0_dp
        if (.not. slip) return
        s = dxi(1)*mp%a + dxi(2)*mp%b
        do a = 1, size(r)
            ms(:, a) = mp%a*c(a, 1) + mp%b*c(a, 2) + dxi(1)*dmt(:, a, 1) + dxi(2)*dmt(:, a, 2)
        end do
    end subroutine mortar_friction_point3

    !> The kinematics of a slave point `sp` and its projection `mp` on a face and
    !> their linearization by the local DOFs (m_alpha the master tangents,
    !> A_ab = m_a . m_b - g n . m_ab): the gap `g`, the slave area element `da` =
    !> |a_1 x a_2| w; the operators `gm` (to x_s - x_m) and `dm(:, :, alpha)` (to m_alpha
    !> at fixed xi); the projection's change dxi_alpha = c(:, alpha) du from
    !> A dxi = m_a . G du + g n . Dm_a du; the gap's dg = `ng` du = n . G du; the
    !> normal's dn = `dn` du = -a^alpha (n . dm_alpha), dm_alpha = Dm_alpha du +
    !> m_alpha,beta c_beta du (a^alpha contravariant); the area element's d(da) =
    !> `dda` du = da a_s^alpha . Ds_alpha du.
    pure subroutine face_linearization(sp, mp, w, g, da, gm, dm, c, ng, dn, dda, dmt)
        type(surface_point_t), intent(in) :: sp
        type(master_point_t), intent(in) :: mp
        real(dp), intent(in) :: w
        real(dp), intent(out) :: g, da, gm(:, :), dm(:, :, :), c(:, :), ng(:), dn(:, :), dda(:)
        !> The master tangents' total derivatives dm_alpha [3, nd, 2] (optional).
        real(dp), intent(out), optional :: dmt(:, :, :)
        real(dp) :: ds(3, size(ng), 2), n(3), mt(3, 2), mc(3, 2), sc(3, 2), amat(2, 2), ainv(2, 2), &
                    h(3, 2, 2), q(2), na(2), det
        integer :: a, b, al
        call face_operators(sp, mp, gm, dm, ds)
        n = mp%n
        mt(:, 1) = mp%a
        mt(:, 2) = mp%b
        h(:, 1, 1) = mp%a2
        h(:, 2, 2) = mp%b2
        h(:, 1, 2) = mp%ab
        h(:, 2, 1) = mp%ab
        g = dot_product(sp%x - mp%x, n)
        da = norm2(cross(sp%a, sp%b))*w
        call contravariant(mt, mc)
        call contravariant(reshape([sp%a, sp%b], [3, 2]), sc)
        do a = 1, 2
            do b = 1, 2
                amat(a, b) = dot_product(mt(:, a), mt(:, b)) - g*dot_product(n, h(:, a, b))
            end do
        end do
        det = amat(1, 1)*amat(2, 2) - amat(1, 2)*amat(2, 1)
        ainv = reshape([amat(2, 2), -amat(2, 1), -amat(1, 2), amat(1, 1)], [2, 2])/det
        do a = 1, size(ng)
            do al = 1, 2
                q(al) = dot_product(mt(:, al), gm(:, a)) + g*dot_product(n, dm(:, a, al))
            end do
            c(a, :) = matmul(ainv, q)
            ng(a) = dot_product(n, gm(:, a))
            do al = 1, 2
                na(al) = dot_product(n, dm(:, a, al)) + dot_product(n, h(:, al, 1))*c(a, 1) + &
                         dot_product(n, h(:, al, 2))*c(a, 2)
                if (present(dmt)) dmt(:, a, al) = dm(:, a, al) + h(:, al, 1)*c(a, 1) + h(:, al, 2)*c(a, 2)
            end do
            dn(:, a) = -(mc(:, 1)*na(1) + mc(:, 2)*na(2))
            dda(a) = da*(dot_product(sc(:, 1), ds(:, a, 1)) + dot_product(sc(:, 2), ds(:, a, 2)))
        end do
    end subroutine face_linearization

    !> `gm` maps the local DOFs to x_s - x_m(xi), `dm(:, :, alpha)` to the master
    !> tangent m_alpha at fixed xi, `ds(:, :, alpha)` to the slave tangent a_alpha.
    pure subroutine face_operators(sp, mp, gm, dm, ds)
        type(surface_point_t), intent(in) :: sp
        type(master_point_t), intent(in) :: mp
        real(dp), intent(out) :: gm(:, :), dm(:, :, :), ds(:, :, :)
        integer :: ns, a, c, j
        ns = size(sp%r)
        gm = 0.0_dp
        dm = 0.0_dp
        ds = 0.0_dp
        do a = 1, ns
            do c = 1, 3
                j = 3*(a - 1) + c
                gm(c, j) = sp%r(a)
                ds(c, j, 1) = sp%dr(a)
                ds(c, j, 2) = sp%drb(a)
            end do
        end do
        do a = 1, size(mp%r)
            do c = 1, 3
                j = 3*(ns + a - 1) + c
                gm(c, j) = -mp%r(a)
                dm(c, j, 1) = mp%dr(a)
                dm(c, j, 2) = mp%drb(a)
            end do
        end do
    end subroutine face_operators

    !> The contravariant vectors a^alpha of the tangents `cov` [3, 2]:
    !> a^alpha = m^alpha beta a_beta, m the metric.
    pure subroutine contravariant(cov, con)
        real(dp), intent(in) :: cov(3, 2)
        real(dp), intent(out) :: con(3, 2)
        real(dp) :: m11, m12, m22, det
        m11 = dot_product(cov(:, 1), cov(:, 1))
        m12 = dot_product(cov(:, 1), cov(:, 2))
        m22 = dot_product(cov(:, 2), cov(:, 2))
        det = m11*m22 - m12**2
        con(:, 1) = (m22*cov(:, 1) - m12*cov(:, 2))/det
        con(:, 2) = (m11*cov(:, 2) - m12*cov(:, 1))/det
    end subroutine contravariant

end module voiga_contact_face_kernels
