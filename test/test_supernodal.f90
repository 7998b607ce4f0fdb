!> The supernodal LU (`voiga_solver_supernodal`): solutions and determinants equal
!> to UMFPACK's, pivoting inside a supernode, the analysis redone only for new
!> nonzeros, UMFPACK's fallback, iterative refinement of ill-conditioned solves.
module test_supernodal
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, error_code
    use voiga_testdrive, only: unittest_t, new_unittest, check
    use voiga_linalg_sparse, only: csc_matrix_t, new_csc_pattern
    use voiga_solver_umfpack, only: umfpack_t
    use voiga_solver_supernodal, only: supernodal_lu_t
    use voiga_test_fixtures, only: lcg_t
    implicit none
    private

    public :: collect_supernodal

contains

    subroutine collect_supernodal(testsuite)
        type(unittest_t), allocatable, intent(out) :: testsuite(:)
        testsuite = [ &
                    new_unittest('supernodal_matches_umfpack', test_matches_umfpack), &
                    new_unittest('supernodal_pivots_in_block', test_block_pivots), &
                    new_unittest('supernodal_new_nonzeros', test_new_nonzeros), &
                    new_unittest('supernodal_singular_falls_back', test_singular), &
                    new_unittest('supernodal_ill_conditioned', test_refines) &
                    ]
    end subroutine collect_supernodal

    !> An m x m grid of 4-node elements with 2 DOFs per node (the pattern of a 2D
    !> solid), element matrices random and unsymmetric plus `shift` on their diagonal.
    !> With `floating`, every element matrix maps a constant vector to zero (rows
    !> summing to zero, as a stiffness without supports): the sum is singular.
    subroutine grid_matrix(m, shift, rng, a, error, floating, corners)
        integer, intent(in) :: m
        real(dp), intent(in) :: shift
        type(lcg_t), intent(inout) :: rng
        type(csc_matrix_t), intent(out) :: a
        type(error_t), allocatable, intent(out) :: error
        logical, intent(in), optional :: floating
        !> Also couple the first and the last DOF in the pattern (values zero).
        logical, intent(in), optional :: corners
        integer, allocatable :: ptr(:), dofs(:)
        real(dp) :: ke(8, 8)
        integer :: i, j, e, n0, a1, b1
        allocate (ptr((m - 1)**2 + 2), dofs(8*(m - 1)**2 + 2))
        e = 0
        do j = 1, m - 1
            do i = 1, m - 1
                e = e + 1
                ptr(e) = 8*(e - 1) + 1
                n0 = (j - 1)*m + i
                dofs(8*e - 7:8*e) = element_dofs([n0, n0 + 1, n0 + m + 1, n0 + m])
            end do
        end do
        ptr(e + 1) = 8*e + 1
        if (present(corners)) then
            if (corners) then
                dofs(8*e + 1:8*e + 2) = [1, 2*m*m]
                ptr(e + 2) = 8*e + 3
                e = e + 1
            end if
        end if
        call new_csc_pattern(a, 2*m*m, ptr(1:e + 1), dofs, error)
        if (allocated(error)) return
        do e = 1, (m - 1)**2
            do b1 = 1, 8
                do a1 = 1, 8
                    ke(a1, b1) = rng%uniform() - 0.5_dp
                end do
                ke(b1, b1) = ke(b1, b1) + shift
            end do
            if (present(floating)) then
                if (floating) then
                    do a1 = 1, 8
                        ke(a1, :) = ke(a1, :) - sum(ke(a1, :))/8.0_dp
                    end do
                end if
            end if
            call a%add_element(dofs(8*e - 7:8*e), ke)
        end do
    contains
        pure function element_dofs(nodes) result(d)
            integer, intent(in) :: nodes(4)
            integer :: d(8), k
            do k = 1, 4
                d(2*k - 1) = 2*nodes(k) - 1
                d(2*k) = 2*nodes(k)
            end do
        end function element_dofs
    end subroutine grid_matrix

    !> Solve with both solvers; the supernodal solution against UMFPACK's and the
    !> residual, both relative, within `tol`.
    subroutine compare_solves(lu, umf, a, rng, tol, what, error)
        type(supernodal_lu_t), intent(inout) :: lu
        type(umfpack_t), intent(inout) :: umf
        type(csc_matrix_t), intent(in) :: a
        type(lcg_t), intent(inout) :: rng
        real(dp), intent(in) :: tol
        character(len=*), intent(in) :: what
        type(error_t), allocatable, intent(out) :: error
        real(dp) :: b(a%n), x(a%n), xu(a%n), r(a%n)
        integer :: i
        do i = 1, a%n
            b(i) = rng%uniform() - 0.5_dp
        end do
        call lu%factor(a, error)
        if (allocated(error)) return
        call umf%factor(a, error)
        if (allocated(error)) return
        call lu%solve(a, b, x, error)
        if (allocated(error)) return
        call umf%solve(a, b, xu, error)
        if (allocated(error)) return
        call a%matvec(x, r)
        call check(error, norm2(r - b)/norm2(b), 0.0_dp, what//': relative residual', abs=tol)
        if (allocated(error)) return
        call check(error, maxval(abs(x - xu))/maxval(abs(xu)), 0.0_dp, what//': against UMFPACK', abs=tol)
    end subroutine compare_solves

    !> A 2D-solid-like unsymmetric matrix with Dirichlet DOFs eliminated: the same
    !> solution and determinant as UMFPACK, by the supernodal factorization itself.
    subroutine test_matches_umfpack(error)
        type(error_t), allocatable, intent(out) :: error
        type(csc_matrix_t) :: a
        type(supernodal_lu_t) :: lu
        type(umfpack_t) :: umf
        type(lcg_t) :: rng
        logical, allocatable :: fixed(:)

        call grid_matrix(20, 4.0_dp, rng, a, error)
        if (allocated(error)) return
        allocate (fixed(a%n), source=.false.)
        fixed(1:40) = .true.
        call a%fix_dofs(fixed)
        call compare_solves(lu, umf, a, rng, 1.0e-12_dp, 'grid 20 x 20', error)
        if (allocated(error)) return
        call check(error, lu%n_fallback, 0, 'factorized without UMFPACK')
        if (allocated(error)) return
        call same_determinant(lu, umf, error)
        if (allocated(error)) return
        call check(error, lu%rcond > 0.0_dp .and. lu%rcond <= 1.0_dp, 'rcond in (0, 1]')
    end subroutine test_matches_umfpack

    !> The supernodal LU's determinant (sign and log10 |det|, to 1e-10) is UMFPACK's
    !> of the same matrix.
    subroutine same_determinant(lu, umf, error)
        type(supernodal_lu_t), intent(inout) :: lu
        type(umfpack_t), intent(inout) :: umf
        type(error_t), allocatable, intent(out) :: error
        integer :: sign_sn, sign_umf
        real(dp) :: log_sn, log_umf
        call lu%determinant(sign_sn, log_sn, error)
        if (allocated(error)) return
        call umf%determinant(sign_umf, log_umf, error)
        if (allocated(error)) return
        call check(error, sign_sn, sign_umf, 'sign of det')
        if (allocated(error)) return
        call check(error, log_sn, log_umf, 'log10 |det|', rel=1.0e-10_dp)
    end subroutine same_determinant

    !> Dense matrices (one supernode each) with a zero diagonal: every pivot comes
    !> from another row of the block, and the sign of det follows the row swaps; 6
    !> columns (the loops) and 30 (LAPACK's dgetrf and BLAS 3, from 24 columns).
    subroutine test_block_pivots(error)
        type(error_t), allocatable, intent(out) :: error
        integer, parameter :: sizes(2) = [6, 30]
        type(csc_matrix_t) :: a
        type(supernodal_lu_t) :: lu
        type(umfpack_t) :: umf
        type(lcg_t) :: rng
        real(dp), allocatable :: ke(:, :)
        integer :: i, j, n, t

        do t = 1, size(sizes)
            n = sizes(t)
            call new_csc_pattern(a, n, [1, n + 1], [(i, i=1, n)], error)
            if (allocated(error)) return
            allocate (ke(n, n))
            do j = 1, n
                do i = 1, n
                    ke(i, j) = 1.0_dp + rng%uniform()
                end do
                ke(j, j) = 0.0_dp
            end do
            call a%add_element([(i, i=1, n)], ke)
            deallocate (ke)
            call compare_solves(lu, umf, a, rng, 1.0e-12_dp, 'dense, zero diagonal', error)
            if (allocated(error)) return
            call check(error, lu%n_fallback, 0, 'pivoted inside the supernode')
            if (allocated(error)) return
            call same_determinant(lu, umf, error)
            if (allocated(error)) return
        end do
    end subroutine test_block_pivots

    !> Entries of the pattern that are zero are left out of the analysis. A nonzero
    !> outside the analysed fronts (the two far corners of a grid coupled) makes a
    !> new analysis; the same matrix on a new pattern (the coupling's zero entries
    !> dropped) is mapped into the fronts there are, without one.
    subroutine test_new_nonzeros(error)
        type(error_t), allocatable, intent(out) :: error
        type(csc_matrix_t) :: a, b
        type(supernodal_lu_t) :: lu
        type(umfpack_t) :: umf
        type(lcg_t) :: rng, rng2
        integer :: p, q, n

        call grid_matrix(12, 4.0_dp, rng, a, error, corners=.true.)
        if (allocated(error)) return
        n = a%n
        p = a%index_of(1, n)
        q = a%index_of(n, 1)
        call check(error, p > 0 .and. q > 0, 'the corners are coupled in the pattern')
        if (allocated(error)) return
        call compare_solves(lu, umf, a, rng, 1.0e-12_dp, 'corners zero', error)
        if (allocated(error)) return
        call check(error, lu%n_symbolic, 1, 'one analysis')
        if (allocated(error)) return
        a%values(p) = 0.5_dp
        a%values(q) = -0.5_dp
        call compare_solves(lu, umf, a, rng, 1.0e-12_dp, 'corners coupled', error)
        if (allocated(error)) return
        call check(error, lu%n_symbolic, 2, 'a nonzero outside the fronts: analysed again')
        if (allocated(error)) return
        a%values(p) = 0.0_dp
        a%values(q) = 0.0_dp
        call compare_solves(lu, umf, a, rng, 1.0e-12_dp, 'corners zero again', error)
        if (allocated(error)) return
        call check(error, lu%n_symbolic + lu%n_mapped, 2, 'fewer nonzeros: nothing to analyse or map')
        if (allocated(error)) return
        ! the same values on the pattern without the corner coupling
        call grid_matrix(12, 4.0_dp, rng2, b, error)
        if (allocated(error)) return
        call compare_solves(lu, umf, b, rng, 1.0e-12_dp, 'new pattern', error)
        if (allocated(error)) return
        call check(error, lu%n_symbolic, 2, 'new pattern, nonzeros in the fronts: no analysis')
        if (allocated(error)) return
        call check(error, lu%n_mapped, 1, 'new pattern: mapped into the fronts')
        if (allocated(error)) return
        call check(error, lu%n_numeric, 4, 'four factorizations')
    end subroutine test_new_nonzeros

    !> A singular matrix (a zero column): the supernodal factorization meets a zero
    !> pivot and hands the matrix to UMFPACK, whose error (code numeric) is returned.
    subroutine test_singular(error)
        type(error_t), allocatable, intent(out) :: error
        type(csc_matrix_t) :: a
        type(supernodal_lu_t) :: lu
        type(lcg_t) :: rng
        type(error_t), allocatable :: failure
        integer :: j, p

        call grid_matrix(8, 4.0_dp, rng, a, error)
        if (allocated(error)) return
        j = 37
        do p = a%colptr(j) + 1, a%colptr(j + 1)
            a%values(p) = 0.0_dp
        end do
        call lu%factor(a, failure)
        call check(error, allocated(failure), 'a singular matrix is an error')
        if (allocated(error)) return
        call check(error, failure%code, error_code%numeric, 'with code numeric')
        if (allocated(error)) return
        call check(error, lu%n_fallback, 1, 'UMFPACK tried it')
    end subroutine test_singular

    !> A nearly singular matrix (rcond < 1e-3, so solves take the refinement branch):
    !> as accurate as UMFPACK's refined solves (relative residuals 3.4e-9 and 1.8e-9;
    !> componentwise backward errors 3.3e-16 and 1.8e-16, which refinement does not
    !> lower further: the factorization is backward stable here).
    subroutine test_refines(error)
        type(error_t), allocatable, intent(out) :: error
        type(csc_matrix_t) :: a
        type(supernodal_lu_t) :: lu
        type(umfpack_t) :: umf
        type(lcg_t) :: rng
        integer :: j

        ! a floating body held by a spring of 1e-7 at every DOF
        call grid_matrix(10, 8.0_dp, rng, a, error, floating=.true.)
        if (allocated(error)) return
        do j = 1, a%n
            call a%add_element([j], reshape([1.0e-7_dp], [1, 1]))
        end do
        ! |x| ~ 1e7 |b|: residuals ~ eps |A| |x| ~ 1e-9 |b| (UMFPACK's: 1.8e-9)
        call compare_solves(lu, umf, a, rng, 1.0e-8_dp, 'ill-conditioned', error)
        if (allocated(error)) return
        call check(error, lu%rcond < 1.0e-3_dp, 'rcond below the refinement threshold')
    end subroutine test_refines

end module test_supernodal
