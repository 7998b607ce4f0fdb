!> The CSC stiffness matrix (pattern, assembly, matvec, Dirichlet elimination)
!> and the UMFPACK wrapper (solve, reuse of the symbolic analysis, errors).
module test_sparse
    use, intrinsic :: iso_c_binding, only: c_int, c_double
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, error_code
    use voiga_testdrive, only: unittest_t, new_unittest, check
    use voiga_linalg_sparse, only: csc_matrix_t, new_csc_pattern, pattern_positions, &
                                   consecutive_runs
    use voiga_solver_umfpack, only: umfpack_t, dp_is_c_double
    use voiga_test_fixtures, only: lcg_t
    use voiga_platform_libraries, only: kernels_for
    implicit none
    private

    public :: collect_sparse

contains

    subroutine collect_sparse(testsuite)
        type(unittest_t), allocatable, intent(out) :: testsuite(:)
        testsuite = [ &
                    new_unittest('kinds_match_c', test_kinds), &
                    new_unittest('chain_pattern', test_chain_pattern), &
                    new_unittest('bad_pattern_input', test_bad_pattern), &
                    new_unittest('pattern_positions', test_pattern_positions), &
                    new_unittest('consecutive_runs', test_consecutive_runs), &
                    new_unittest('assembly_matvec_dense', test_assembly), &
                    new_unittest('missed_entries_counted', test_missed), &
                    new_unittest('fix_dofs', test_fix_dofs), &
                    new_unittest('pattern_large_fast', test_large_pattern), &
                    new_unittest('umfpack_laplacian', test_laplacian), &
                    new_unittest('umfpack_symbolic_reuse', test_reuse), &
                    new_unittest('umfpack_pattern_change', test_pattern_change), &
                    new_unittest('umfpack_singular', test_singular), &
                    new_unittest('umfpack_determinant', test_determinant), &
                    new_unittest('umfpack_64bit_indices', test_wide), &
                    new_unittest('umfpack_misuse', test_misuse), &
                    new_unittest('blas_kernels_choice', test_kernels_choice) &
                    ]
    end subroutine collect_sparse

    !> OpenBLAS's generic kernels (its fallback on a CPU it does not know) are
    !> replaced by those of the CPU's widest vector features; kernels OpenBLAS chose
    !> for a CPU it knows are kept.
    subroutine test_kernels_choice(error)
        type(error_t), allocatable, intent(out) :: error
        call check(error, kernels_for('Prescott', .true., .true., .true.) == 'SkylakeX', 'AVX-512: SkylakeX')
        if (allocated(error)) return
        call check(error, kernels_for('PRESCOTT', .false., .true., .true.) == 'Haswell', 'AVX2: Haswell')
        if (allocated(error)) return
        call check(error, kernels_for('Prescott', .false., .false., .true.) == 'Sandybridge', 'AVX: Sandybridge')
        if (allocated(error)) return
        call check(error, kernels_for('Prescott', .false., .false., .false.) == '', 'SSE3 only: kept')
        if (allocated(error)) return
        call check(error, kernels_for('Haswell', .true., .true., .true.) == '', 'a known CPU: kept')
        if (allocated(error)) return
        call check(error, kernels_for('Zen', .true., .true., .true.) == '', 'Zen kept')
    end subroutine test_kernels_choice

    !> Runs of consecutive integers: a control-point row of an element, a break
    !> between rows, single entries, a descent (not a run), an empty list.
    subroutine test_consecutive_runs(error)
        type(error_t), allocatable, intent(out) :: error
        integer :: runs(10), nr
        call consecutive_runs([4, 5, 6, 10, 11, 12, 20, 7, 8], runs, nr)
        call check(error, nr == 4, 'four runs')
        if (allocated(error)) return
        call check(error, all(runs(1:5) == [1, 4, 7, 8, 10]), 'run starts 1 4 7 8, end 10')
        if (allocated(error)) return
        call consecutive_runs([3, 2, 1], runs, nr)
        call check(error, nr == 3 .and. all(runs(1:4) == [1, 2, 3, 4]), 'a descent is three runs')
        if (allocated(error)) return
        call consecutive_runs([integer ::], runs, nr)
        call check(error, nr == 0 .and. runs(1) == 1, 'no entries: no runs')
    end subroutine test_consecutive_runs

    subroutine test_kinds(error)
        type(error_t), allocatable, intent(out) :: error
        call check(error, dp_is_c_double(), 'real(dp) is C double')
        if (allocated(error)) return
        ! the CSC index arrays are integer(c_int); callers fill them from default
        ! integers, so the default integer must not be wider than C's int
        call check(error, c_int == kind(0), 'default integer is C int')
        if (allocated(error)) return
        call check(error, c_double == dp, 'c_double == dp')
    end subroutine test_kinds

    !> Chain of 2-DOF elements (1,2), (2,3), (3,4), (4,5) in shuffled order, a
    !> skipped DOF 0 in one element, and DOF 6 touched by no element.
    subroutine test_chain_pattern(error)
        type(error_t), allocatable, intent(out) :: error
        type(csc_matrix_t) :: a
        integer, parameter :: colptr(7) = [0, 2, 5, 8, 11, 13, 14]
        integer, parameter :: rowind(14) = [0, 1, 0, 1, 2, 1, 2, 3, 2, 3, 4, 3, 4, 5]
        integer :: k

        call new_csc_pattern(a, 6, [1, 3, 5, 7, 9, 11], [3, 4, 2, 1, 5, 4, 0, 5, 2, 3], error)
        if (allocated(error)) return
        call check(error, a%n, 6, 'n')
        if (allocated(error)) return
        call check(error, a%nnz(), 14, 'nnz')
        if (allocated(error)) return
        call check(error, size(a%colptr), 7, 'size(colptr)')
        if (allocated(error)) return
        do k = 1, 7
            call check(error, int(a%colptr(k)), colptr(k), 'colptr entry')
            if (allocated(error)) return
        end do
        do k = 1, 14
            call check(error, int(a%rowind(k)), rowind(k), 'rowind entry')
            if (allocated(error)) return
        end do
        call check(error, size(a%values), 14, 'size(values)')
        if (allocated(error)) return
        call check(error, maxval(abs(a%values)), 0.0_dp, 'values start at zero', abs=0.0_dp)
        if (allocated(error)) return
        call check(error, a%index_of(5, 4), 11, 'index_of(5, 4)')
        if (allocated(error)) return
        call check(error, a%index_of(5, 3), 0, 'index_of(5, 3) not stored')
        if (allocated(error)) return
        call check(error, a%index_of(6, 6), 14, 'isolated DOF keeps its diagonal')
    end subroutine test_chain_pattern

    !> Entries of one pattern found in another (a contact coupling added and one
    !> removed, as when the contact pattern is rebuilt): every entry of the old
    !> pattern maps to the same (row, column) of the new one, or to 0 when the new
    !> one lacks it.
    subroutine test_pattern_positions(error)
        type(error_t), allocatable, intent(out) :: error
        type(csc_matrix_t) :: old, new
        integer, allocatable :: old2new(:)
        integer :: j, p, i

        ! chain (1,2), (2,3), (3,4) plus a coupling (1,4); then the chain plus (2,5)
        call new_csc_pattern(old, 5, [1, 3, 5, 7, 9], [1, 2, 2, 3, 3, 4, 1, 4], error)
        if (allocated(error)) return
        call new_csc_pattern(new, 5, [1, 3, 5, 7, 9], [1, 2, 2, 3, 3, 4, 2, 5], error)
        if (allocated(error)) return
        call pattern_positions(old, new, old2new)
        call check(error, size(old2new), old%nnz(), 'one position per old entry')
        if (allocated(error)) return
        do j = 1, old%n
            do p = old%colptr(j) + 1, old%colptr(j + 1)
                i = old%rowind(p) + 1
                call check(error, old2new(p), new%index_of(i, j), 'position of an old entry')
                if (allocated(error)) return
            end do
        end do
        call check(error, count(old2new == 0), 2, 'the removed coupling (1,4), (4,1) has no position')
    end subroutine test_pattern_positions

    subroutine test_bad_pattern(error)
        type(error_t), allocatable, intent(out) :: error
        logical :: failed
        type(csc_matrix_t) :: a

        call new_csc_pattern(a, 3, [1, 3], [1, 4], error)
        failed = allocated(error)
        call check(error, failed, 'DOF > n refused')
        if (allocated(error)) return
        call new_csc_pattern(a, 3, [1, 3, 2], [1, 2, 3], error)
        failed = allocated(error)
        call check(error, failed, 'decreasing elem_ptr refused')
        if (allocated(error)) return
        call new_csc_pattern(a, 3, [1, 5], [1, 2, 3], error)
        failed = allocated(error)
        call check(error, failed, 'elem_ptr past elem_dofs refused')
        if (allocated(error)) return
        call new_csc_pattern(a, 3, [1], [integer ::], error)
        if (allocated(error)) return
        call check(error, a%nnz(), 3, 'no elements: diagonal only')
    end subroutine test_bad_pattern

    !> Random SPD element matrix: B^T B + m I with B uniform in [-1, 1).
    function random_spd(rng, m) result(ke)
        type(lcg_t), intent(inout) :: rng
        integer, intent(in) :: m
        real(dp) :: ke(m, m), b(m, m)
        integer :: i, j
        do j = 1, m
            do i = 1, m
                b(i, j) = 2.0_dp*rng%uniform() - 1.0_dp
            end do
        end do
        ke = matmul(transpose(b), b)
        do i = 1, m
            ke(i, i) = ke(i, i) + real(m, dp)
        end do
    end function random_spd

    !> Overlapping 4-DOF elements of a 2-DOF-per-node bar, DOF order inside each
    !> element reversed for odd elements, DOFs of node 1 constrained (0).
    subroutine bar_elements(nel, elem_ptr, elem_dofs, n)
        integer, intent(in) :: nel
        integer, allocatable, intent(out) :: elem_ptr(:), elem_dofs(:)
        integer, intent(out) :: n
        integer :: e, d(4)
        n = 2*nel
        allocate (elem_ptr(nel + 1), elem_dofs(4*nel))
        do e = 1, nel
            elem_ptr(e) = 4*(e - 1) + 1
            ! node e has DOFs 2e-3, 2e-2 (node 1 fixed: 0), node e+1 has 2e-1, 2e
            d = [2*e - 3, 2*e - 2, 2*e - 1, 2*e]
            where (d < 1) d = 0
            if (mod(e, 2) == 1) d = d(4:1:-1)
            elem_dofs(4*(e - 1) + 1:4*e) = d
        end do
        elem_ptr(nel + 1) = 4*nel + 1
    end subroutine bar_elements

    function to_dense(a) result(d)
        type(csc_matrix_t), intent(in) :: a
        real(dp) :: d(a%n, a%n)
        integer :: j, k
        d = 0.0_dp
        do j = 1, a%n
            do k = a%colptr(j) + 1, a%colptr(j + 1)
                d(a%rowind(k) + 1, j) = a%values(k)
            end do
        end do
    end function to_dense

    subroutine test_assembly(error)
        type(error_t), allocatable, intent(out) :: error
        integer, parameter :: nel = 12
        type(csc_matrix_t) :: a, b
        type(lcg_t) :: rng
        integer, allocatable :: elem_ptr(:), elem_dofs(:), pos(:, :, :)
        real(dp), allocatable :: dense(:, :), x(:), y(:), ke(:, :, :)
        integer :: n, e, i, j, k
        integer, allocatable :: dofs(:)

        call bar_elements(nel, elem_ptr, elem_dofs, n)
        call new_csc_pattern(a, n, elem_ptr, elem_dofs, error)
        if (allocated(error)) return
        call new_csc_pattern(b, n, elem_ptr, elem_dofs, error)
        if (allocated(error)) return
        allocate (dense(n, n), source=0.0_dp)
        allocate (ke(4, 4, nel), pos(4, 4, nel))
        do e = 1, nel
            dofs = elem_dofs(elem_ptr(e):elem_ptr(e + 1) - 1)
            ke(:, :, e) = random_spd(rng, 4)
            call a%add_element(dofs, ke(:, :, e))
            call b%element_positions(dofs, pos(:, :, e))
            do j = 1, 4
                do i = 1, 4
                    if (dofs(i) > 0 .and. dofs(j) > 0) then
                        dense(dofs(i), dofs(j)) = dense(dofs(i), dofs(j)) + ke(i, j, e)
                    end if
                end do
            end do
        end do
        ! cached positions: same values, twice over after a zero
        do k = 1, 2
            call b%zero()
            do e = 1, nel
                call b%add_at(pos(:, :, e), ke(:, :, e))
            end do
        end do
        call check(error, a%missed, 0, 'add_element missed entries')
        if (allocated(error)) return
        call check(error, b%missed, 0, 'element_positions missed entries')
        if (allocated(error)) return
        ! the same sums in the same order: bitwise equal
        call check(error, reshape(to_dense(a), [n*n]), reshape(dense, [n*n]), &
                   'add_element vs dense', abs=0.0_dp)
        if (allocated(error)) return
        call check(error, b%values, a%values, 'add_at vs add_element', abs=0.0_dp)
        if (allocated(error)) return
        ! tridiagonal block bandwidth: nodes couple only with neighbours
        call check(error, a%nnz(), 4*(3*n/2 - 2), 'nnz of a 2-DOF-per-node chain')
        if (allocated(error)) return

        allocate (x(n), y(n))
        do i = 1, n
            x(i) = rng%uniform() - 0.5_dp
        end do
        call a%matvec(x, y)
        ! entries O(10), n = 24 terms: round-off well below 1e-13
        call check(error, y, matmul(dense, x), 'matvec vs dense', abs=1.0e-13_dp)
    end subroutine test_assembly

    subroutine test_missed(error)
        type(error_t), allocatable, intent(out) :: error
        type(csc_matrix_t) :: a
        integer :: pos(2, 2)

        call new_csc_pattern(a, 4, [1, 3, 5], [1, 2, 3, 4], error)
        if (allocated(error)) return
        call a%add_element([2, 3], reshape([1.0_dp, 2.0_dp, 3.0_dp, 4.0_dp], [2, 2]))
        call check(error, a%missed, 2, 'pairs (2,3), (3,2) are not in the pattern')
        if (allocated(error)) return
        call check(error, a%values(a%index_of(2, 2)), 1.0_dp, 'stored part added', abs=0.0_dp)
        if (allocated(error)) return
        call a%element_positions([1, 5], pos)
        call check(error, a%missed, 5, 'DOF 5 > n counts three times')
        if (allocated(error)) return
        call check(error, pos(1, 1), a%index_of(1, 1), 'pos of (1,1)')
        if (allocated(error)) return
        call check(error, count(pos == 0), 3, 'out-of-range positions are 0')
    end subroutine test_missed

    subroutine test_fix_dofs(error)
        type(error_t), allocatable, intent(out) :: error
        integer, parameter :: nel = 6
        type(csc_matrix_t) :: a
        type(lcg_t) :: rng
        integer, allocatable :: elem_ptr(:), elem_dofs(:)
        real(dp), allocatable :: dense(:, :), got(:, :)
        logical, allocatable :: fixed(:)
        integer :: n, e, i

        call bar_elements(nel, elem_ptr, elem_dofs, n)
        call new_csc_pattern(a, n, elem_ptr, elem_dofs, error)
        if (allocated(error)) return
        do e = 1, nel
            call a%add_element(elem_dofs(elem_ptr(e):elem_ptr(e + 1) - 1), random_spd(rng, 4))
        end do
        allocate (dense(n, n), got(n, n))
        dense = to_dense(a)
        allocate (fixed(n), source=.false.)
        fixed([1, 6, n]) = .true.
        call a%fix_dofs(fixed)
        do i = 1, n
            if (fixed(i)) then
                dense(i, :) = 0.0_dp
                dense(:, i) = 0.0_dp
                dense(i, i) = 1.0_dp
            end if
        end do
        got = to_dense(a)
        call check(error, reshape(got, [n*n]), reshape(dense, [n*n]), 'fix_dofs', abs=0.0_dp)
        if (allocated(error)) return
        call check(error, a%nnz(), size(a%rowind), 'pattern kept')
    end subroutine test_fix_dofs

    !> Pattern of a quadratic 2D patch (9-node elements, 2 DOFs per node):
    !> 200 x 200 elements, 80802 DOFs, 1.3e6 entries. Checks the entry count
    !> against the closed form and the sorted, symmetric layout; cheap (~0.1 s).
    subroutine test_large_pattern(error)
        type(error_t), allocatable, intent(out) :: error
        type(csc_matrix_t) :: a
        integer, parameter :: ne = 200, nn = ne + 2
        integer, allocatable :: elem_ptr(:), elem_dofs(:)
        integer :: ex, ey, e, p, i, j, k, node, n, expected, m1

        n = 2*nn*nn
        allocate (elem_ptr(ne*ne + 1), elem_dofs(18*ne*ne))
        e = 0
        p = 0
        do ey = 1, ne
            do ex = 1, ne
                e = e + 1
                elem_ptr(e) = p + 1
                do j = 0, 2
                    do i = 0, 2
                        node = (ey - 1 + j)*nn + (ex - 1 + i)
                        elem_dofs(p + 1:p + 2) = [2*node + 1, 2*node + 2]
                        p = p + 2
                    end do
                end do
            end do
        end do
        elem_ptr(ne*ne + 1) = p + 1
        call new_csc_pattern(a, n, elem_ptr, elem_dofs, error)
        if (allocated(error)) return
        ! node couplings per direction: a node at index i couples with
        ! min(i,2)+min(nn-1-i,2)+1 nodes along that axis
        m1 = 0
        do i = 0, nn - 1
            m1 = m1 + min(i, 2) + min(nn - 1 - i, 2) + 1
        end do
        expected = 4*m1*m1
        call check(error, a%nnz(), expected, 'nnz of a C1 quadratic patch')
        if (allocated(error)) return
        do j = 1, a%n
            do k = a%colptr(j) + 1, a%colptr(j + 1) - 1
                if (a%rowind(k + 1) <= a%rowind(k)) then
                    call check(error, .false., 'rows strictly ascending in every column')
                    return
                end if
            end do
        end do
        call check(error, a%index_of(1, 2*nn*2 + 6) > 0 .and. a%index_of(2*nn*2 + 6, 1) > 0, &
                   'symmetric coupling at distance 2')
        if (allocated(error)) return
        call check(error, a%index_of(1, 2*nn*3 + 1), 0, 'no coupling at distance 3')
    end subroutine test_large_pattern

    !> Dirichlet 5-point Laplacian on an m x m grid: edge elements [1 -1; -1 1]
    !> plus one 1-DOF element per node topping its diagonal up to 4.
    subroutine laplacian(m, a, ke_edge, error)
        integer, intent(in) :: m
        type(csc_matrix_t), intent(out) :: a
        real(dp), intent(in) :: ke_edge(2, 2)
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: elem_ptr(:), elem_dofs(:)
        integer :: i, j, e, p, node, nedge, nbr

        nedge = 2*m*(m - 1)
        allocate (elem_ptr(nedge + m*m + 1), elem_dofs(2*nedge + m*m))
        e = 0
        p = 0
        do j = 1, m
            do i = 1, m
                node = (j - 1)*m + i
                if (i < m) call push([node, node + 1])
                if (j < m) call push([node, node + m])
                call push([node])
            end do
        end do
        elem_ptr(e + 1) = p + 1
        call new_csc_pattern(a, m*m, elem_ptr, elem_dofs, error)
        if (allocated(error)) return
        do e = 1, size(elem_ptr) - 1
            if (elem_ptr(e + 1) - elem_ptr(e) == 2) then
                call a%add_element(elem_dofs(elem_ptr(e):elem_ptr(e) + 1), ke_edge)
            else
                node = elem_dofs(elem_ptr(e))
                i = mod(node - 1, m) + 1
                j = (node - 1)/m + 1
                nbr = merge(1, 0, i > 1) + merge(1, 0, i < m) + merge(1, 0, j > 1) &
                      + merge(1, 0, j < m)
                call a%add_element([node], reshape([real(4 - nbr, dp)*ke_edge(1, 1)], [1, 1]))
            end if
        end do
    contains
        subroutine push(d)
            integer, intent(in) :: d(:)
            e = e + 1
            elem_ptr(e) = p + 1
            elem_dofs(p + 1:p + size(d)) = d
            p = p + size(d)
        end subroutine push
    end subroutine laplacian

    !> Solve with `lu` and check the relative residual and the error against `xe`.
    !> The Laplacian's condition number is ~ 4 m^2 / pi^2 ~ 1e3 for m = 50, so a
    !> backward-stable LU gives residuals ~ 1e-16 and errors ~ 1e-13: 1e-12 holds
    !> with margin.
    subroutine solve_and_check(lu, a, xe, what, error)
        type(umfpack_t), intent(inout) :: lu
        type(csc_matrix_t), intent(in) :: a
        real(dp), intent(in) :: xe(:)
        character(len=*), intent(in) :: what
        type(error_t), allocatable, intent(out) :: error
        real(dp), allocatable :: b(:), x(:), r(:)

        allocate (b(a%n), x(a%n), r(a%n))
        call a%matvec(xe, b)
        call lu%solve(a, b, x, error)
        if (allocated(error)) return
        call a%matvec(x, r)
        call check(error, norm2(r - b)/norm2(b), 0.0_dp, what//': relative residual', &
                   abs=1.0e-12_dp)
        if (allocated(error)) return
        call check(error, maxval(abs(x - xe))/maxval(abs(xe)), 0.0_dp, what//': error', &
                   abs=1.0e-12_dp)
    end subroutine solve_and_check

    function random_vector(rng, n) result(x)
        type(lcg_t), intent(inout) :: rng
        integer, intent(in) :: n
        real(dp) :: x(n)
        integer :: i
        do i = 1, n
            x(i) = rng%uniform() - 0.5_dp
        end do
    end function random_vector

    subroutine test_laplacian(error)
        type(error_t), allocatable, intent(out) :: error
        integer, parameter :: m = 50
        type(csc_matrix_t) :: a
        type(umfpack_t) :: lu
        type(lcg_t) :: rng

        call laplacian(m, a, reshape([1.0_dp, -1.0_dp, -1.0_dp, 1.0_dp], [2, 2]), error)
        if (allocated(error)) return
        call check(error, a%nnz(), 5*m*m - 4*m, 'nnz of the 5-point stencil')
        if (allocated(error)) return
        call check(error, a%missed, 0, 'missed')
        if (allocated(error)) return
        call lu%factor(a, error)
        if (allocated(error)) return
        call check(error, lu%rcond > 0.0_dp, 'rcond estimate available')
        if (allocated(error)) return
        call solve_and_check(lu, a, random_vector(rng, m*m), 'laplacian', error)
    end subroutine test_laplacian

    subroutine test_reuse(error)
        type(error_t), allocatable, intent(out) :: error
        integer, parameter :: m = 30
        type(csc_matrix_t) :: a
        type(umfpack_t) :: lu
        type(lcg_t) :: rng
        real(dp), allocatable :: xe(:)

        call laplacian(m, a, reshape([1.0_dp, -1.0_dp, -1.0_dp, 1.0_dp], [2, 2]), error)
        if (allocated(error)) return
        call lu%factor(a, error)
        if (allocated(error)) return
        allocate (xe(m*m))
        xe = random_vector(rng, m*m)
        call solve_and_check(lu, a, xe, 'first', error)
        if (allocated(error)) return

        ! new values, same pattern: an unsymmetric "convective" edge matrix
        call laplacian(m, a, reshape([3.0_dp, -1.0_dp, -2.0_dp, 3.0_dp], [2, 2]), error)
        if (allocated(error)) return
        call lu%factor(a, error)
        if (allocated(error)) return
        call check(error, lu%n_symbolic, 1, 'symbolic analysis reused')
        if (allocated(error)) return
        call check(error, lu%n_numeric, 2, 'numeric factorizations')
        if (allocated(error)) return
        call solve_and_check(lu, a, xe, 'refactorized', error)
        if (allocated(error)) return
        call lu%release()
        call lu%release()
        call check(error, lu%n_symbolic, 1, 'counters survive release')
    end subroutine test_reuse

    !> det of 200 2x2 diagonal blocks [2 1; 1 3] (det 5), one of them replaced by
    !> [1 2; 2 1] (det -3): sign and log10 |det| = 199 log10 5 + log10 3 (5^199 would
    !> overflow as a double: UMFPACK's mantissa/exponent form must not).
    subroutine test_determinant(error)
        type(error_t), allocatable, intent(out) :: error
        type(csc_matrix_t) :: a
        type(umfpack_t) :: lu
        type(error_t), allocatable :: misuse
        integer :: e, sgn
        real(dp) :: log_det

        call lu%determinant(sgn, log_det, misuse)
        call check(error, allocated(misuse), 'determinant without a factorization is an error')
        if (allocated(error)) return
        call new_csc_pattern(a, 400, [(2*e - 1, e=1, 200), 401], [(e, e=1, 400)], error)
        if (allocated(error)) return
        do e = 1, 200
            call a%add_element([2*e - 1, 2*e], reshape([2.0_dp, 1.0_dp, 1.0_dp, 3.0_dp], [2, 2]))
        end do
        call lu%factor(a, error)
        if (allocated(error)) return
        call lu%determinant(sgn, log_det, error)
        if (allocated(error)) return
        call check(error, sgn, 1, 'sign of det, all blocks positive')
        if (allocated(error)) return
        call check(error, log_det, 200*log10(5.0_dp), 'log10 det', rel=1.0e-12_dp)
        if (allocated(error)) return
        a%values = 0.0_dp
        do e = 1, 200
            if (e == 77) then
                call a%add_element([2*e - 1, 2*e], reshape([1.0_dp, 2.0_dp, 2.0_dp, 1.0_dp], [2, 2]))
            else
                call a%add_element([2*e - 1, 2*e], reshape([2.0_dp, 1.0_dp, 1.0_dp, 3.0_dp], [2, 2]))
            end if
        end do
        call lu%factor(a, error)
        if (allocated(error)) return
        call lu%determinant(sgn, log_det, error)
        if (allocated(error)) return
        call check(error, sgn, -1, 'sign of det, one indefinite block')
        if (allocated(error)) return
        call check(error, log_det, 199*log10(5.0_dp) + log10(3.0_dp), 'log10 |det|', rel=1.0e-12_dp)
    end subroutine test_determinant

    !> The 64-bit-index version (used after the 32-bit one ran out of memory):
    !> same solution, determinant sign, refactorization with the symbolic reused.
    subroutine test_wide(error)
        type(error_t), allocatable, intent(out) :: error
        integer, parameter :: m = 30
        type(csc_matrix_t) :: a
        type(umfpack_t) :: lu
        type(lcg_t) :: rng
        integer :: sgn
        real(dp) :: log_det

        call laplacian(m, a, reshape([1.0_dp, -1.0_dp, -1.0_dp, 1.0_dp], [2, 2]), error)
        if (allocated(error)) return
        lu%wide = .true.
        call lu%factor(a, error)
        if (allocated(error)) return
        call solve_and_check(lu, a, random_vector(rng, m*m), 'laplacian, 64-bit', error)
        if (allocated(error)) return
        call lu%determinant(sgn, log_det, error)
        if (allocated(error)) return
        call check(error, sgn, 1, 'det of an SPD matrix, 64-bit')
        if (allocated(error)) return
        call lu%factor(a, error)
        if (allocated(error)) return
        call check(error, lu%n_symbolic, 1, 'symbolic analysis reused, 64-bit')
        if (allocated(error)) return
        call check(error, lu%wide, 'still 64-bit')
    end subroutine test_wide

    subroutine test_pattern_change(error)
        type(error_t), allocatable, intent(out) :: error
        type(csc_matrix_t) :: a, b
        type(umfpack_t) :: lu
        type(lcg_t) :: rng
        integer :: e

        call laplacian(20, a, reshape([1.0_dp, -1.0_dp, -1.0_dp, 1.0_dp], [2, 2]), error)
        if (allocated(error)) return
        call lu%factor(a, error)
        if (allocated(error)) return
        ! same n, different pattern: an SPD 2-DOF-per-node bar
        call new_csc_pattern(b, 400, [(2*e - 1, e=1, 200), 401], [(e, e=1, 400)], error)
        if (allocated(error)) return
        do e = 1, 200
            call b%add_element([2*e - 1, 2*e], random_spd(rng, 2))
        end do
        call lu%factor(b, error)
        if (allocated(error)) return
        call check(error, lu%n_symbolic, 2, 'new pattern, new symbolic analysis')
        if (allocated(error)) return
        call solve_and_check(lu, b, random_vector(rng, 400), 'new pattern', error)
        if (allocated(error)) return
        ! and back to a smaller matrix
        call laplacian(7, a, reshape([1.0_dp, -1.0_dp, -1.0_dp, 1.0_dp], [2, 2]), error)
        if (allocated(error)) return
        call lu%factor(a, error)
        if (allocated(error)) return
        call check(error, lu%n_symbolic, 3, 'new n, new symbolic analysis')
        if (allocated(error)) return
        call check(error, lu%n_numeric, 3, 'numeric factorizations')
        if (allocated(error)) return
        call solve_and_check(lu, a, random_vector(rng, 49), 'smaller', error)
    end subroutine test_pattern_change

    subroutine test_singular(error)
        type(error_t), allocatable, intent(out) :: error
        logical :: failed
        integer, parameter :: nel = 10
        type(csc_matrix_t) :: a
        type(umfpack_t) :: lu
        type(lcg_t) :: rng
        real(dp) :: x(nel + 1), b(nel + 1)
        logical :: fixed(nel + 1)
        character(len=:), allocatable :: message
        integer :: e, code

        ! free spring chain: rigid-body mode, exactly singular in floating point
        ! (integer entries, exact elimination)
        call new_csc_pattern(a, nel + 1, [(2*e - 1, e=1, nel + 1)], &
                             [([e, e + 1], e=1, nel)], error)
        if (allocated(error)) return
        do e = 1, nel
            call a%add_element([e, e + 1], reshape([1.0_dp, -1.0_dp, -1.0_dp, 1.0_dp], [2, 2]))
        end do
        call lu%factor(a, error)
        if (.not. allocated(error)) then
            call check(error, .false., 'singular matrix refused')
            return
        end if
        message = error%message
        code = error%code
        deallocate (error)
        call check(error, index(message, 'singular stiffness matrix') > 0, &
                   'message names the singularity: '//message)
        if (allocated(error)) return
        call check(error, index(message, 'umfpack_di_numeric') > 0, &
                   'message names the routine: '//message)
        if (allocated(error)) return
        call check(error, code, error_code%numeric, 'numeric error code')
        if (allocated(error)) return
        call check(error, lu%n_numeric, 0, 'no numeric factorization counted')
        if (allocated(error)) return
        b = 1.0_dp
        call lu%solve(a, b, x, error)
        failed = allocated(error)
        call check(error, failed, 'solve after a failed factorization refused')
        if (allocated(error)) return

        ! clamp one end: the same object and symbolic analysis work again
        fixed = .false.
        fixed(1) = .true.
        call a%fix_dofs(fixed)
        call lu%factor(a, error)
        if (allocated(error)) return
        call check(error, lu%n_symbolic, 1, 'symbolic kept after the failure')
        if (allocated(error)) return
        x = random_vector(rng, nel + 1)
        x(1) = 0.0_dp
        call solve_and_check(lu, a, x, 'clamped chain', error)
        if (allocated(error)) return

        ! all-zero values on a stored diagonal
        call a%zero()
        call lu%factor(a, error)
        failed = allocated(error)
        call check(error, failed, 'zero matrix refused')
    end subroutine test_singular

    subroutine test_misuse(error)
        type(error_t), allocatable, intent(out) :: error
        logical :: failed
        type(csc_matrix_t) :: a, empty
        type(umfpack_t) :: lu, other
        real(dp) :: b(3), x(3), x4(4)

        call lu%factor(empty, error)
        failed = allocated(error)
        call check(error, failed, 'matrix without pattern refused')
        if (allocated(error)) return
        call new_csc_pattern(a, 3, [1, 3, 5], [1, 2, 2, 3], error)
        if (allocated(error)) return
        b = 1.0_dp
        call lu%solve(a, b, x, error)
        failed = allocated(error)
        call check(error, failed, 'solve before factorize refused')
        if (allocated(error)) return
        call a%add_element([1, 2], reshape([2.0_dp, -1.0_dp, -1.0_dp, 2.0_dp], [2, 2]))
        call a%add_element([2, 3], reshape([2.0_dp, -1.0_dp, -1.0_dp, 2.0_dp], [2, 2]))
        call lu%factor(a, error)
        if (allocated(error)) return
        call lu%solve(a, b, x4, error)
        failed = allocated(error)
        call check(error, failed, 'wrong size of x refused')
        if (allocated(error)) return
        call lu%solve(empty, b, x, error)
        failed = allocated(error)
        call check(error, failed, 'solve with another matrix refused')
        if (allocated(error)) return
        ! copying never shares handles: the copy is empty, the original still works
        other = lu
        call other%solve(a, b, x, error)
        failed = allocated(error)
        call check(error, failed, 'a copy holds no factorization')
        if (allocated(error)) return
        call lu%solve(a, b, x, error)
        if (allocated(error)) return
        ! A = [2 -1 0; -1 4 -1; 0 -1 2], b = 1: x = [5/6, 2/3, 5/6]
        call check(error, x, [5.0_dp/6.0_dp, 2.0_dp/3.0_dp, 5.0_dp/6.0_dp], 'small solve', &
                   rel=1.0e-14_dp)
    end subroutine test_misuse

end module test_sparse
