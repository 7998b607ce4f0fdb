!> The per-point contact kernels on a face (3D, two convective coordinates on each
!> side): the Gauss-point-to-surface penalty (`gpts_point3`) and the mortar-type
!> point at a fixed interpolated pressure (`mortar_point3`). What differs from the
!> edge's kernels (`voiga_contact_gpts`, `voiga_contact_mortar_kernels`) is the
!> geometry of a surface (two tangents, the metric and curvature of the master, the
!> area element of the slave: `face_linearization`); the loops over points, the
!> law's parameters, the history and the output are the pairs' (docs/theory.md,
!> section 7, "Faces").
!>
!> Normal contact only: the tangential (Coulomb) part on the two-dimensional
!> tangent plane is issue 42's next step, and a frictional pair on a face is refused
!> where the case is read.
!>
!> Local DOFs of a point: the slave point's functions first (3 per function), then
!> the master's (none for a rigid master), as in `voiga_contact_kinematics`.
module voiga_contact_face_kernels
    use voiga_kinds, only: dp
    use voiga_contact_surface, only: surface_point_t
    use voiga_contact_master, only: master_point_t
    use voiga_contact_law, only: contact_law_t
    use voiga_nurbs_patch, only: cross
    implicit none
    private

    public :: gpts_point3, mortar_point3

contains

    !> Residual `r` (internal-force sign: r = -int G^T t da) and tangent `k` of an
    !> active slave point on a face, t = p_N n with p_N = -eps_n g. `w` is the Gauss
    !> weight times the parametric Jacobian of the slave cell: da = |a_1 x a_2| w.
    pure subroutine gpts_point3(law, w, sp, mp, r, k, g, pn)
        type(contact_law_t), intent(in) :: law
        real(dp), intent(in) :: w
        type(surface_point_t), intent(in) :: sp
        type(master_point_t), intent(in) :: mp
        real(dp), intent(out) :: r(:), k(:, :)
        !> Normal gap and contact pressure (>= 0 in contact).
        real(dp), intent(out) :: g, pn
        real(dp) :: gm(3, size(r)), dm(3, size(r), 2), c(size(r), 2), ng(size(r)), dn(3, size(r)), &
                    dda(size(r)), gt(size(r)), t(3), da
        integer :: a, b
        call face_linearization(sp, mp, w, g, da, gm, dm, c, ng, dn, dda)
        pn = -law%eps_n*g
        t = pn*mp%n
        do a = 1, size(r)
            gt(a) = dot_product(t, gm(:, a))
        end do
        r = -da*gt
        do a = 1, size(r)
            ! dt = -eps_n n ng^T + pn dn; the master functions move with xi; da varies
            do b = 1, size(r)
                k(b, a) = -da*dot_product(gm(:, b), -law%eps_n*mp%n*ng(a) + pn*dn(:, a)) &
                          + da*(dot_product(dm(:, b, 1), t)*c(a, 1) + dot_product(dm(:, b, 2), t)*c(a, 2)) &
                          - gt(b)*dda(a)
            end do
        end do
    end subroutine gpts_point3

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

    !> The kinematics of a slave point `sp` and its projection `mp` on a face and
    !> their linearization by the local DOFs (m_alpha the master tangents,
    !> A_ab = m_a . m_b - g n . m_ab): the gap `g`, the slave area element `da` =
    !> |a_1 x a_2| w; the operators `gm` (to x_s - x_m) and `dm(:, :, alpha)` (to m_alpha
    !> at fixed xi); the projection's change dxi_alpha = c(:, alpha) du from
    !> A dxi = m_a . G du + g n . Dm_a du; the gap's dg = `ng` du = n . G du; the
    !> normal's dn = `dn` du = -a^alpha (n . dm_alpha), dm_alpha = Dm_alpha du +
    !> m_alpha,beta c_beta du (a^alpha contravariant); the area element's d(da) =
    !> `dda` du = da a_s^alpha . Ds_alpha du.
    pure subroutine face_linearization(sp, mp, w, g, da, gm, dm, c, ng, dn, dda)
        type(surface_point_t), intent(in) :: sp
        type(master_point_t), intent(in) :: mp
        real(dp), intent(in) :: w
        real(dp), intent(out) :: g, da, gm(:, :), dm(:, :, :), c(:, :), ng(:), dn(:, :), dda(:)
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
