!> The multigrid solver and its parts: the knot-insertion matrix against the
!> basis functions, CSR products against dense ones, nested coarse spaces
!> (partition of unity and exact geometry in the coarse space, with and without
!> a VO layer), and GMRES + V-cycle against UMFPACK with iteration counts that do
!> not grow with the mesh.
module test_multigrid
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_testdrive, only: unittest_t, new_unittest, check
    use voiga_nurbs_basis, only: find_span, basis_funs, n_basis
    use voiga_nurbs_refine, only: insertion_matrix
    use voiga_linalg_sparse, only: csc_matrix_t
    use voiga_linalg_csr, only: csr_t, csr_from_triplets, csr_transpose, csr_matmul, csr_to_csc, &
                                csr_from_csc, csr_matvec
    use voiga_solver_umfpack, only: umfpack_t
    use voiga_solver_multigrid, only: multigrid_t
    use voiga_solver_linear, only: solve_accuracy_t
    use voiga_discretization_layout, only: layout_t
    use voiga_discretization_patch, only: discretization_t, new_discretization
    use voiga_discretization_hierarchy, only: coarse_space_t, cp_map_t, coarsen_discretization, &
                                              coarsen_space
    use voiga_model, only: model_t
    use voiga_model_loads, only: dirichlet_settings_t
    use voiga_model_assembly, only: assemble, stiffness_pattern, assembly_stats_t
    use voiga_linalg_lapack, only: solve_spd
    use voiga_test_fixtures, only: lcg_t, annulus_sector, rectangle, paper_layout, scene_t, scene_model
    implicit none
    private

    public :: collect_multigrid

    real(dp), parameter :: pi = acos(-1.0_dp)

contains

    subroutine collect_multigrid(testsuite)
        type(unittest_t), allocatable, intent(out) :: testsuite(:)
        testsuite = [ &
                    new_unittest('insertion_matrix_basis', test_insertion), &
                    new_unittest('csr_products_dense', test_csr), &
                    new_unittest('coarse_spaces_nested', test_nested), &
                    new_unittest('gmres_multigrid_vs_umfpack', test_solve) &
                    ]
    end subroutine collect_multigrid

    !> B_coarse(k)(u) = sum_i t(i, k) B_fine(i)(u) at 97 points, for a nonuniform
    !> knot vector with a double knot, degrees 1..4.
    subroutine test_insertion(error)
        type(error_t), allocatable, intent(out) :: error
        real(dp), allocatable :: coarse(:), fine(:), t(:, :), bc(:), bf(:)
        integer :: p, j, sc, sf, n
        real(dp) :: u, err

        do p = 1, 4
            coarse = [spread(0.0_dp, 1, p + 1), 0.3_dp, 0.5_dp, 0.5_dp, spread(1.0_dp, 1, p + 1)]
            fine = [spread(0.0_dp, 1, p + 1), 0.1_dp, 0.3_dp, 0.4_dp, 0.5_dp, 0.5_dp, 0.5_dp, 0.8_dp, &
                    0.9_dp, spread(1.0_dp, 1, p + 1)]
            t = insertion_matrix(p, coarse, fine)
            call check(error, size(t, 1), n_basis(fine, p), 'rows = fine functions')
            if (allocated(error)) return
            call check(error, size(t, 2), n_basis(coarse, p), 'columns = coarse functions')
            if (allocated(error)) return
            err = 0.0_dp
            do j = 0, 96
                u = real(j, dp)/97.0_dp
                sc = find_span(coarse, p, u)
                sf = find_span(fine, p, u)
                allocate (bc(n_basis(coarse, p)), bf(n_basis(fine, p)))
                bc = 0.0_dp
                bf = 0.0_dp
                bc(sc - p:sc) = basis_funs(coarse, p, sc, u)
                bf(sf - p:sf) = basis_funs(fine, p, sf, u)
                err = max(err, maxval(abs(bc - matmul(transpose(t), bf))))
                deallocate (bc, bf)
            end do
            call check(error, err < 1.0e-14_dp, 'coarse basis = t^T fine basis')
            if (allocated(error)) return
        end do
    end subroutine test_insertion

    !> A random sparse 30 x 20 and 20 x 25: product, transpose and CSC round trip
    !> equal the dense ones.
    subroutine test_csr(error)
        type(error_t), allocatable, intent(out) :: error
        type(lcg_t) :: rng
        type(csr_t) :: a, b, c, at, back
        type(csc_matrix_t) :: sq
        real(dp) :: da(30, 20), db(20, 25)
        real(dp), allocatable :: x(:), y(:)
        integer :: j

        call random_csr(rng, 30, 20, 90, a, da)
        call random_csr(rng, 20, 25, 70, b, db)
        call csr_matmul(a, b, c, sorted=.true.)
        call check(error, maxval(abs(dense(c) - matmul(da, db))) < 1.0e-13_dp, 'a b')
        if (allocated(error)) return
        call check(error, all(c%col(2:) > c%col(:size(c%col) - 1) .or. &
                              row_starts(c, size(c%col))), 'columns sorted within rows')
        if (allocated(error)) return
        call csr_transpose(a, at)
        call check(error, maxval(abs(dense(at) - transpose(da))) == 0.0_dp, 'a^T')
        if (allocated(error)) return
        ! square: CSC and back
        call csr_matmul(at, a, c)
        call csr_to_csc(c, sq)
        call csr_from_csc(sq, back)
        call check(error, maxval(abs(dense(back) - matmul(transpose(da), da))) < 1.0e-13_dp, 'CSC round trip')
        if (allocated(error)) return
        allocate (x(20), y(20))
        x = [(real(mod(7*j, 5), dp) - 2.0_dp, j=1, 20)]
        call csr_matvec(back, x, y)
        call check(error, maxval(abs(y - matmul(matmul(transpose(da), da), x))) < 1.0e-12_dp, 'matvec')
    contains
        logical function row_starts(m, n)
            type(csr_t), intent(in) :: m
            integer, intent(in) :: n
            ! true only if every descent of col happens at a row start
            integer :: k
            row_starts = .true.
            do k = 2, n
                if (m%col(k) <= m%col(k - 1) .and. .not. any(m%ptr == k)) row_starts = .false.
            end do
        end function row_starts
    end subroutine test_csr

    subroutine random_csr(rng, m, n, nnz, a, d)
        type(lcg_t), intent(inout) :: rng
        integer, intent(in) :: m, n, nnz
        type(csr_t), intent(out) :: a
        real(dp), intent(out) :: d(m, n)
        integer :: rows(nnz), cols(nnz), k
        real(dp) :: vals(nnz)
        d = 0.0_dp
        do k = 1, nnz
            rows(k) = 1 + int(rng%uniform()*m)
            cols(k) = 1 + int(rng%uniform()*n)
            vals(k) = rng%uniform() - 0.5_dp
            d(rows(k), cols(k)) = d(rows(k), cols(k)) + vals(k)
        end do
        call csr_from_triplets(m, n, rows, cols, vals, a)
    end subroutine random_csr

    function dense(a) result(d)
        type(csr_t), intent(in) :: a
        real(dp) :: d(a%nrow, a%ncol)
        integer :: i, k
        d = 0.0_dp
        do i = 1, a%nrow
            do k = a%ptr(i), a%ptr(i + 1) - 1
                d(i, a%col(k)) = d(i, a%col(k)) + a%val(k)
            end do
        end do
    end function dense

    !> Two coarsenings of a rational quarter-annulus sector (N2, NN2.2 and NN3:
    !> a VO layer of the bulk degree, and one above it): every fine row of the
    !> prolongation sums to 1 (the coarse NURBS keep the partition of unity), and
    !> the fine control points are the prolongation of coarse ones (the exact
    !> geometry lies in each coarse space) to 1e-12.
    subroutine test_nested(error)
        type(error_t), allocatable, intent(out) :: error
        character(len=5), parameter :: names(3) = [character(len=5) :: 'N2', 'NN2.2', 'NN3']
        type(discretization_t) :: d
        type(coarse_space_t) :: s1, s2
        type(cp_map_t) :: m1, m2
        logical :: changed
        real(dp), allocatable :: x1(:, :), x2(:, :)
        integer :: k

        do k = 1, size(names)
            call new_discretization(d, annulus_sector([0.0_dp, 0.0_dp], 1.0_dp, 2.0_dp, pi/2, 2), &
                                    paper_layout(trim(names(k)), [8, 4], 'outer'), '', error)
            if (allocated(error)) return
            call coarsen_discretization(d, s1, m1, changed, error)
            if (allocated(error)) return
            call check(error, changed, trim(names(k))//': coarsened')
            if (allocated(error)) return
            ! xi: 8 elements with the sector's double knot at 1/2 -> 4 (the double knot
            ! stays), 7 functions; eta: 4 -> 2 elements, 4 functions
            call check(error, size(s1%w), 7*4, trim(names(k))//': 4 x 2 quadratic elements')
            if (allocated(error)) return
            call check_map(m1, d%x, trim(names(k))//' level 1', x1, error)
            if (allocated(error)) return
            call coarsen_space(s1, s2, m2, changed, error)
            if (allocated(error)) return
            call check_map(m2, x1, trim(names(k))//' level 2', x2, error)
            if (allocated(error)) return
        end do
    end subroutine test_nested

    !> Row sums 1; xf = map xc for the least-squares xc (returned).
    subroutine check_map(map, xf, label, xc, error)
        type(cp_map_t), intent(in) :: map
        real(dp), intent(in) :: xf(:, :)
        character(len=*), intent(in) :: label
        real(dp), allocatable, intent(out) :: xc(:, :)
        type(error_t), allocatable, intent(out) :: error
        real(dp), allocatable :: p(:, :), g(:, :), rhs(:, :)
        integer :: k, info

        allocate (p(map%n_fine, map%n_coarse))
        p = 0.0_dp
        do k = 1, size(map%val)
            p(map%fine(k), map%coarse(k)) = p(map%fine(k), map%coarse(k)) + map%val(k)
        end do
        call check(error, maxval(abs(sum(p, dim=2) - 1.0_dp)) < 1.0e-13_dp, label//': row sums 1')
        if (allocated(error)) return
        g = matmul(transpose(p), p)
        rhs = matmul(transpose(p), transpose(xf))
        call solve_spd(g, rhs, info)
        call check(error, info, 0, label//': full column rank')
        if (allocated(error)) return
        xc = transpose(rhs)
        call check(error, maxval(abs(matmul(p, rhs) - transpose(xf))) < 1.0e-12_dp, &
                   label//': geometry in the coarse space')
    end subroutine check_map

    !> A clamped linear-elastic square (N2, n x n elements, bottom clamped, left
    !> held in x): GMRES + multigrid solves K x = b to 1e-10 and agrees with
    !> UMFPACK; the iterations stay below 10 from 16 x 16 to 64 x 64 elements.
    subroutine test_solve(error)
        type(error_t), allocatable, intent(out) :: error
        integer, parameter :: sizes(3) = [16, 32, 64]
        type(model_t) :: model
        type(csc_matrix_t) :: k
        type(assembly_stats_t) :: stats
        real(dp), allocatable :: u(:), r(:), b(:), x(:), xd(:)
        integer :: i, j, its(3)
        character(len=80) :: label

        do i = 1, size(sizes)
            call square_model(sizes(i), model, error)
            if (allocated(error)) return
            call stiffness_pattern(model, k, error)
            if (allocated(error)) return
            allocate (u(model%ndof), r(model%ndof), b(model%ndof), x(model%ndof), xd(model%ndof))
            u = 0.0_dp
            call assemble(model, u, 1.0_dp, r, stats, error, k)
            if (allocated(error)) return
            call k%fix_dofs(model%fixed)
            b = [(sin(0.37_dp*real(j, dp)) + 0.1_dp, j=1, size(b))]
            b = merge(0.0_dp, b, model%fixed)
            ! (a new multigrid_t per size: no assignment of objects holding UMFPACK handles)
            call solve_one(error)
            if (allocated(error)) return
            deallocate (u, r, b, x, xd)
        end do
    contains
        subroutine solve_one(error)
            type(error_t), allocatable, intent(out) :: error
            type(multigrid_t) :: mg
            type(umfpack_t) :: lu
            mg%coarse_dofs = 100
            call mg%build(model%bodies(:)%disc, model%bodies(:)%dof0, model%ndof, model%fixed, error)
            if (allocated(error)) return
            call check(error, mg%n_levels() >= 3, 'at least 3 levels')
            if (allocated(error)) return
            call mg%factor(k, error)
            if (allocated(error)) return
            call mg%solve(k, b, x, error, solve_accuracy_t(rtol=1.0e-10_dp))
            if (allocated(error)) return
            its(i) = mg%last_iterations()
            call lu%factor(k, error)
            if (allocated(error)) return
            call lu%solve(k, b, xd, error)
            if (allocated(error)) return
            write (label, '(a,i0,a,i0,a)') 'n = ', sizes(i), ' (', its(i), ' iterations)'
            call check(error, mg%last_residual() <= 1.0e-10_dp, trim(label)//': residual reached')
            if (allocated(error)) return
            call check(error, maxval(abs(x - xd)) <= 1.0e-8_dp*maxval(abs(xd)), trim(label)//': = UMFPACK')
            if (allocated(error)) return
            call check(error, its(i) < 10, trim(label)//': fewer than 10 GMRES iterations')
        end subroutine solve_one
    end subroutine test_solve

    !> Unit linear-elastic square, n x n N2 elements, bottom clamped, left edge x held.
    subroutine square_model(n, model, error)
        integer, intent(in) :: n
        type(model_t), intent(out) :: model
        type(error_t), allocatable, intent(out) :: error
        type(scene_t) :: c
        type(discretization_t) :: discs(1)
        type(layout_t) :: layout
        allocate (c%bodies(1))
        c%bodies(1)%name = 'square'
        c%bodies(1)%material = 'linear'
        c%bodies(1)%youngs_modulus = 1.0_dp
        c%bodies(1)%poisson_ratio = 0.3_dp
        layout%nel(:2) = [n, n]
        layout%degree(:2) = [2, 2]
        c%bodies(1)%layout = layout
        c%solver%n_steps = [1]
        allocate (c%pressure(0), c%contact(0))
        c%dirichlet = [dirichlet_settings_t(body='square', edge='bottom', fix=[.true., .true., .false.], &
                                            values=reshape([0.0_dp, 0.0_dp], [2, 1])), &
                       dirichlet_settings_t(body='square', edge='left', fix=[.true., .false., .false.], &
                                            values=reshape([0.0_dp, 0.0_dp], [2, 1]))]
        call new_discretization(discs(1), rectangle(0.0_dp, 0.0_dp, 1.0_dp, 1.0_dp), layout, '', error)
        if (allocated(error)) return
        call scene_model(c, discs, model, error)
    end subroutine square_model

end module test_multigrid
