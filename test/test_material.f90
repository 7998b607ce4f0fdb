!> The material laws on three-dimensional gradients (`stress3`): the Neo-Hookean
!> kernel matches its closed forms in uniaxial stretch and simple shear, reduces to
!> the plane-strain kernel when F33 = 1, and its spatial tangent matches finite
!> differences of tau (dtau = c : d + l tau + tau l^T, l = dF F^-1); Hooke's law is
!> exactly linear with its tensor.
module test_material
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_testdrive, only: unittest_t, new_unittest, check
    use voiga_material_neohookean, only: neo_hookean_t
    use voiga_material_linear, only: linear_elastic_t
    use voiga_material, only: lame_from_young
    use voiga_test_fixtures, only: lcg_t
    implicit none
    private

    public :: collect_material

    real(dp), parameter :: youngs = 210.0_dp, poisson = 0.3_dp

contains

    subroutine collect_material(testsuite)
        type(unittest_t), allocatable, intent(out) :: testsuite(:)
        testsuite = [ &
                    new_unittest('neo_hookean_3d_uniaxial_stretch', test_uniaxial), &
                    new_unittest('neo_hookean_3d_simple_shear', test_shear), &
                    new_unittest('neo_hookean_3d_is_plane_strain_at_f33_1', test_plane_strain), &
                    new_unittest('neo_hookean_3d_tangent_fd', test_tangent), &
                    new_unittest('linear_3d_exact', test_linear), &
                    new_unittest('fields3_rotated_stretch', test_fields3) &
                    ]
    end subroutine collect_material

    function neo() result(m)
        type(neo_hookean_t) :: m
        call lame_from_young(m, youngs, poisson)
    end function neo

    !> F = diag(l, 1, 1): J = l, bbar = l^(-2/3) diag(l^2, 1, 1), so
    !> tau11 = 2/3 mu l^(-2/3) (l^2 - 1) + K/2 (l^2 - 1),
    !> tau22 = tau33 = -1/3 mu l^(-2/3) (l^2 - 1) + K/2 (l^2 - 1), no shear.
    subroutine test_uniaxial(error)
        type(error_t), allocatable, intent(out) :: error
        type(neo_hookean_t) :: m
        real(dp), parameter :: l = 2.5_dp
        real(dp) :: g(3, 3), s(3, 3), c(3, 3, 3, 3), t11, t22
        logical :: ok
        m = neo()
        g = 0.0_dp
        g(1, 1) = l - 1.0_dp
        call m%stress3(g, s, c, ok)
        t11 = 2.0_dp/3.0_dp*m%mu*l**(-2.0_dp/3.0_dp)*(l**2 - 1.0_dp) + 0.5_dp*m%kappa*(l**2 - 1.0_dp)
        t22 = -1.0_dp/3.0_dp*m%mu*l**(-2.0_dp/3.0_dp)*(l**2 - 1.0_dp) + 0.5_dp*m%kappa*(l**2 - 1.0_dp)
        call check(error, ok .and. abs(s(1, 1) - t11) < 1.0e-10_dp*abs(t11) .and. &
                   abs(s(2, 2) - t22) < 1.0e-10_dp*abs(t11) .and. abs(s(3, 3) - t22) < 1.0e-10_dp*abs(t11) .and. &
                   abs(s(1, 2)) + abs(s(1, 3)) + abs(s(2, 3)) < 1.0e-10_dp*abs(t11), 'uniaxial stretch')
    end subroutine test_uniaxial

    !> F = I + g e1 (x) e2: J = 1, bbar = b, tr = 3 + g^2, so tau12 = mu g,
    !> tau11 = 2/3 mu g^2, tau22 = tau33 = -1/3 mu g^2 (no volumetric part).
    subroutine test_shear(error)
        type(error_t), allocatable, intent(out) :: error
        type(neo_hookean_t) :: m
        real(dp), parameter :: gam = 1.5_dp
        real(dp) :: g(3, 3), s(3, 3), c(3, 3, 3, 3), expected(3, 3)
        logical :: ok
        m = neo()
        g = 0.0_dp
        g(1, 2) = gam
        call m%stress3(g, s, c, ok)
        expected = 0.0_dp
        expected(1, 1) = 2.0_dp/3.0_dp*m%mu*gam**2
        expected(2, 2) = -m%mu*gam**2/3.0_dp
        expected(3, 3) = -m%mu*gam**2/3.0_dp
        expected(1, 2) = m%mu*gam
        expected(2, 1) = m%mu*gam
        call check(error, ok .and. maxval(abs(s - expected)) < 1.0e-10_dp*m%mu*gam, 'simple shear')
    end subroutine test_shear

    !> A plane gradient (third row and column zero): the in-plane stress and tangent
    !> are the plane-strain kernel's (which the 2D element tests verify).
    subroutine test_plane_strain(error)
        type(error_t), allocatable, intent(out) :: error
        type(neo_hookean_t) :: m
        real(dp) :: g2(2, 2), s2(2, 2), c2(2, 2, 2, 2), g(3, 3), s(3, 3), c(3, 3, 3, 3)
        logical :: ok2, ok
        m = neo()
        g2 = reshape([0.3_dp, -0.2_dp, 0.45_dp, -0.25_dp], [2, 2])
        call m%stress(g2, s2, c2, ok2)
        g = 0.0_dp
        g(1:2, 1:2) = g2
        call m%stress3(g, s, c, ok)
        call check(error, ok .and. ok2 .and. maxval(abs(s(1:2, 1:2) - s2)) < 1.0e-12_dp*maxval(abs(s2)) .and. &
                   maxval(abs(c(1:2, 1:2, 1:2, 1:2) - c2)) < 1.0e-12_dp*maxval(abs(c2)), &
                   'the 3D kernel at F33 = 1 differs from the plane-strain kernel')
    end subroutine test_plane_strain

    !> dtau/de along dF at a random large deformation against c : d + l tau + tau l^T.
    subroutine test_tangent(error)
        type(error_t), allocatable, intent(out) :: error
        type(neo_hookean_t) :: m
        type(lcg_t) :: rng
        real(dp), parameter :: h = 1.0e-6_dp
        real(dp) :: g(3, 3), df(3, 3), f(3, 3), finv(3, 3), l(3, 3), d(3, 3), s(3, 3), c(3, 3, 3, 3)
        real(dp) :: sp(3, 3), sm(3, 3), cc(3, 3, 3, 3), predicted(3, 3)
        logical :: ok, okp, okm
        integer :: i, j
        m = neo()
        do j = 1, 3
            do i = 1, 3
                g(i, j) = 0.4_dp*(rng%uniform() - 0.5_dp)
                df(i, j) = rng%uniform() - 0.5_dp
            end do
        end do
        call m%stress3(g, s, c, ok)
        call m%stress3(g + h*df, sp, cc, okp)
        call m%stress3(g - h*df, sm, cc, okm)
        f = g
        do i = 1, 3
            f(i, i) = f(i, i) + 1.0_dp
        end do
        finv = inverse3(f)
        l = matmul(df, finv)
        d = 0.5_dp*(l + transpose(l))
        do j = 1, 3
            do i = 1, 3
                predicted(i, j) = sum(c(i, j, :, :)*d)
            end do
        end do
        predicted = predicted + matmul(l, s) + matmul(s, transpose(l))
        call check(error, ok .and. okp .and. okm .and. &
                   maxval(abs((sp - sm)/(2*h) - predicted)) < 1.0e-6_dp*maxval(abs(predicted)), &
                   'the spatial tangent differs from finite differences')
    end subroutine test_tangent

    pure function inverse3(a) result(b)
        real(dp), intent(in) :: a(3, 3)
        real(dp) :: b(3, 3), det
        b(1, 1) = a(2, 2)*a(3, 3) - a(2, 3)*a(3, 2)
        b(1, 2) = a(1, 3)*a(3, 2) - a(1, 2)*a(3, 3)
        b(1, 3) = a(1, 2)*a(2, 3) - a(1, 3)*a(2, 2)
        b(2, 1) = a(2, 3)*a(3, 1) - a(2, 1)*a(3, 3)
        b(2, 2) = a(1, 1)*a(3, 3) - a(1, 3)*a(3, 1)
        b(2, 3) = a(1, 3)*a(2, 1) - a(1, 1)*a(2, 3)
        b(3, 1) = a(2, 1)*a(3, 2) - a(2, 2)*a(3, 1)
        b(3, 2) = a(1, 2)*a(3, 1) - a(1, 1)*a(3, 2)
        b(3, 3) = a(1, 1)*a(2, 2) - a(1, 2)*a(2, 1)
        det = a(1, 1)*b(1, 1) + a(1, 2)*b(2, 1) + a(1, 3)*b(3, 1)
        b = b/det
    end function inverse3

    !> Hooke's law: s(g + dg) - s(g) = c : dg exactly (to round-off), c with both minor
    !> symmetries and the major one.
    subroutine test_linear(error)
        type(error_t), allocatable, intent(out) :: error
        type(linear_elastic_t) :: m
        type(lcg_t) :: rng
        real(dp) :: g(3, 3), dg(3, 3), s0(3, 3), s1(3, 3), c(3, 3, 3, 3), predicted(3, 3)
        logical :: ok
        integer :: i, j
        call lame_from_young(m, youngs, poisson)
        do j = 1, 3
            do i = 1, 3
                g(i, j) = rng%uniform() - 0.5_dp
                dg(i, j) = rng%uniform() - 0.5_dp
            end do
        end do
        call m%stress3(g, s0, c, ok)
        call m%stress3(g + dg, s1, c, ok)
        do j = 1, 3
            do i = 1, 3
                predicted(i, j) = sum(c(i, j, :, :)*dg)
            end do
        end do
        call check(error, maxval(abs(s1 - s0 - predicted)) < 1.0e-12_dp*youngs, 'Hooke is not linear in c')
        if (allocated(error)) return
        call check(error, all(abs(c - reshape(c, shape(c), order=[2, 1, 3, 4])) < 1.0e-14_dp*youngs) .and. &
                   all(abs(c - reshape(c, shape(c), order=[3, 4, 1, 2])) < 1.0e-14_dp*youngs), &
                   'the tensor is not symmetric')
    end subroutine test_linear

    !> F = Q diag(l) (any rotation Q after the stretch): the result file's strain is
    !> ln V = Q diag(ln l) Q^T, the stress tau/J rotated likewise; Hooke's fields are
    !> sym(grad u) and its stress.
    subroutine test_fields3(error)
        type(error_t), allocatable, intent(out) :: error
        type(neo_hookean_t) :: m
        type(linear_elastic_t) :: lin
        real(dp) :: q(3, 3), l(3), f(3, 3), stress(6), strain(6), expect(3, 3), s(3, 3), c(3, 3, 3, 3), jac
        real(dp) :: s0(3, 3), g(3, 3)
        integer :: i
        logical :: ok
        m = neo()
        ! (as the factory sets it: the law's kinematics are finite)
        m%finite_strain = .true.
        ! a rotation by 0.7 about the axis (1, 2, 2)/3 (Rodrigues)
        q = rotation([1.0_dp, 2.0_dp, 2.0_dp]/3.0_dp, 0.7_dp)
        l = [1.3_dp, 0.8_dp, 1.1_dp]
        f = 0.0_dp
        do i = 1, 3
            f(:, i) = q(:, i)*l(i)
        end do
        ! F = Q diag(l) R^T with R = Q: V = Q diag(l) Q^T
        f = matmul(f, transpose(q))
        g = f
        do i = 1, 3
            g(i, i) = g(i, i) - 1.0_dp
        end do
        call m%fields3(g, stress, strain, ok)
        expect = matmul(q, matmul(diag(log(l)), transpose(q)))
        call check(error, ok .and. maxval(abs(strain - voigt6(expect))) < 1.0e-13_dp, 'ln V of a rotated stretch')
        if (allocated(error)) return
        call m%stress3(g, s, c, ok)
        jac = product(l)
        call check(error, maxval(abs(stress - voigt6(s/jac))) < 1.0e-12_dp*maxval(abs(s)), 'sigma = tau/J')
        if (allocated(error)) return
        call lame_from_young(lin, youngs, poisson)
        g = 1.0e-3_dp*reshape([1.0_dp, 2.0_dp, -1.0_dp, 0.5_dp, -2.0_dp, 1.5_dp, 0.3_dp, 0.7_dp, 1.1_dp], [3, 3])
        call lin%fields3(g, stress, strain, ok)
        call lin%stress3(g, s0, c, ok)
        call check(error, maxval(abs(strain - voigt6(0.5_dp*(g + transpose(g))))) == 0.0_dp .and. &
                   maxval(abs(stress - voigt6(s0))) == 0.0_dp, 'Hooke: sym(grad u) and its stress')
    contains
        pure function diag(v) result(d)
            real(dp), intent(in) :: v(3)
            real(dp) :: d(3, 3)
            integer :: k
            d = 0.0_dp
            do k = 1, 3
                d(k, k) = v(k)
            end do
        end function diag
        pure function voigt6(a) result(v)
            real(dp), intent(in) :: a(3, 3)
            real(dp) :: v(6)
            v = [a(1, 1), a(2, 2), a(3, 3), a(1, 2), a(2, 3), a(1, 3)]
        end function voigt6
        pure function rotation(axis, angle) result(r)
            real(dp), intent(in) :: axis(3), angle
            real(dp) :: r(3, 3), k(3, 3)
            k = reshape([0.0_dp, axis(3), -axis(2), -axis(3), 0.0_dp, axis(1), axis(2), -axis(1), 0.0_dp], [3, 3])
            r = diag([1.0_dp, 1.0_dp, 1.0_dp]) + sin(angle)*k + (1.0_dp - cos(angle))*matmul(k, k)
        end function rotation
    end subroutine test_fields3

end module test_material
