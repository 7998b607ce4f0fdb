!> The element kernel (`voiga_element_solid`) against the tangent written out
!> term by term, for a law whose tangent lacks the major symmetry: the kernel then
!> forms the fourth block of K (K^yx) instead of transposing K^xy.
module test_element_kernel
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_testdrive, only: unittest_t, new_unittest, check
    use voiga_material, only: material_t
    use voiga_element_solid, only: solid_element, element_points_t, element_work_t
    use voiga_test_fixtures, only: lcg_t
    implicit none
    private

    public :: collect_element_kernel

    !> A small-strain law sigma = c : grad_u with moduli that have the minor
    !> symmetries but not the major one (c_ijkl /= c_klij); not a physical law, a
    !> tangent the symmetric shortcut would get wrong.
    type, extends(material_t) :: skew_law_t
        real(dp) :: c(2, 2, 2, 2) = 0.0_dp
    contains
        procedure :: stress => skew_stress
        procedure :: fields => skew_fields
        procedure, nopass :: strain_name => skew_strain_name
    end type skew_law_t

contains

    subroutine collect_element_kernel(testsuite)
        type(unittest_t), allocatable, intent(out) :: testsuite(:)
        testsuite = [new_unittest('unsymmetric_tangent_blocks', test_unsymmetric)]
    end subroutine collect_element_kernel

    pure subroutine skew_stress(self, grad_u, s, c, ok)
        class(skew_law_t), intent(in) :: self
        real(dp), intent(in) :: grad_u(2, 2)
        real(dp), intent(out) :: s(2, 2), c(2, 2, 2, 2)
        logical, intent(out) :: ok
        integer :: i, j
        do j = 1, 2
            do i = 1, 2
                s(i, j) = sum(self%c(i, j, :, :)*grad_u)
            end do
        end do
        c = self%c
        ok = .true.
    end subroutine skew_stress

    pure subroutine skew_fields(self, grad_u, stress, strain, ok)
        class(skew_law_t), intent(in) :: self
        real(dp), intent(in) :: grad_u(2, 2)
        real(dp), intent(out) :: stress(4), strain(4)
        logical, intent(out) :: ok
        stress = 0.0_dp
        strain = 0.0_dp
        ok = self%finite_strain .eqv. .false.
    end subroutine skew_fields

    pure function skew_strain_name() result(name)
        character(len=:), allocatable :: name
        name = 'none'
    end function skew_strain_name

    !> Random gradients, weights and displacements on 9 functions and 9 points:
    !> K_(a,i)(b,k) = sum_q w_q sum_jl dN_a/dX_j c_ijkl dN_b/dX_l and
    !> f_(a,i) = sum_q w_q sum_j sigma_ij dN_a/dX_j, against the kernel.
    subroutine test_unsymmetric(error)
        type(error_t), allocatable, intent(out) :: error
        integer, parameter :: nen = 9, np = 9
        type(skew_law_t) :: law
        type(element_points_t) :: pts
        type(element_work_t) :: work
        type(lcg_t) :: rng
        real(dp) :: u(2, nen), fe(2*nen), ke(2*nen, 2*nen), fref(2*nen), kref(2*nen, 2*nen)
        real(dp) :: d(3, 3), grad_u(2, 2), s(2, 2), c(2, 2, 2, 2)
        integer, parameter :: vi(3) = [1, 2, 1], vj(3) = [1, 2, 2]
        integer :: i, j, k, l, a, b, q, m, n
        logical :: ok

        do n = 1, 3
            do m = 1, 3
                d(m, n) = rng%uniform() + merge(2.0_dp, 0.0_dp, m == n)
            end do
        end do
        ! c from the unsymmetric Voigt matrix d, with the minor symmetries
        do n = 1, 3
            do m = 1, 3
                law%c(vi(m), vj(m), vi(n), vj(n)) = d(m, n)
                law%c(vj(m), vi(m), vi(n), vj(n)) = d(m, n)
                law%c(vi(m), vj(m), vj(n), vi(n)) = d(m, n)
                law%c(vj(m), vi(m), vj(n), vi(n)) = d(m, n)
            end do
        end do
        allocate (pts%dndx(2, nen, np), pts%wdv(np))
        do q = 1, np
            pts%wdv(q) = 0.5_dp + rng%uniform()
            do a = 1, nen
                pts%dndx(:, a, q) = [rng%uniform(), rng%uniform()] - 0.5_dp
            end do
        end do
        do a = 1, nen
            u(:, a) = 0.01_dp*([rng%uniform(), rng%uniform()] - 0.5_dp)
        end do

        fref = 0.0_dp
        kref = 0.0_dp
        do q = 1, np
            grad_u = matmul(u, transpose(pts%dndx(:, :, q)))
            call law%stress(grad_u, s, c, ok)
            do a = 1, nen
                do i = 1, 2
                    fref(2*(a - 1) + i) = fref(2*(a - 1) + i) + pts%wdv(q)*sum(s(i, :)*pts%dndx(:, a, q))
                    do b = 1, nen
                        do k = 1, 2
                            do j = 1, 2
                                do l = 1, 2
                                    kref(2*(a - 1) + i, 2*(b - 1) + k) = kref(2*(a - 1) + i, 2*(b - 1) + k) + &
                                        pts%wdv(q)*pts%dndx(j, a, q)*law%c(i, j, k, l)*pts%dndx(l, b, q)
                                end do
                            end do
                        end do
                    end do
                end do
            end do
        end do

        call solid_element(law, pts, u, fe, ke, ok, work)
        call check(error, ok, 'the kernel accepts the state')
        if (allocated(error)) return
        call check(error, maxval(abs(kref - transpose(kref)))/maxval(abs(kref)) > 1.0e-3_dp, &
                   'the reference tangent is unsymmetric')
        if (allocated(error)) return
        call check(error, maxval(abs(ke - kref))/maxval(abs(kref)), 0.0_dp, 'K against the written-out sum', &
                   abs=1.0e-13_dp)
        if (allocated(error)) return
        call check(error, maxval(abs(fe - fref))/maxval(abs(fref)), 0.0_dp, 'f against the written-out sum', &
                   abs=1.0e-13_dp)
    end subroutine test_unsymmetric

end module test_element_kernel
