!> Geometric multigrid over nested spline spaces, as the preconditioner of
!> restarted GMRES: the `linear_solver = 'multigrid'` of `&solver`
!> (docs/performance.md, "Multigrid").
!>
!> The hierarchy (`build`) is made once per run from the bodies' discretizations
!> (`voiga_discretization_hierarchy`): each level halves the elements per
!> direction of every body that still has removable knots, the prolongation is
!> knot insertion (block diagonal over the bodies, the same for both displacement
!> components), until the coarse problem has at most `coarse_dofs` DOFs or no
!> body can be coarsened. Dirichlet DOFs: the fine ones are dropped from the
!> prolongation, and so is every coarse DOF whose function is nonzero on one
!> (the coarse space satisfies the homogeneous constraints).
!>
!> Every Newton iteration (`setup`) computes the Galerkin coarse operators
!> A_(l+1) = P_l^T A_l P_l from the assembled tangent, contact included, and
!> factorizes the coarsest with UMFPACK. A V-cycle smooths with `sweeps` forward
!> Gauss-Seidel sweeps before the coarse correction and as many backward sweeps
!> after it (symmetric for a symmetric tangent). GMRES (right preconditioned,
!> restarted every `restart` iterations) stops at a relative residual `rtol`.
!> Cost per Newton iteration: linear in the DOFs times the GMRES iterations.
module voiga_solver_multigrid
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_solver_sparse, only: csc_matrix_t
    use voiga_solver_csr, only: csr_t, csr_from_csc, csr_from_triplets, csr_transpose, csr_matmul, &
                                csr_to_csc, csr_matvec, csr_diagonal_positions, csr_matmul_numeric
    use voiga_solver_umfpack, only: umfpack_t
    use voiga_solver_linear, only: linear_solver_t, solve_accuracy_t
    use voiga_solver_smoother, only: line_set_t, new_line_set
    use voiga_solver_signals, only: caught_signal, signal_name
    use voiga_discretization_patch, only: discretization_t
    use voiga_discretization_hierarchy, only: coarse_space_t, cp_map_t, coarsen_discretization, &
                                              coarsen_space
    implicit none
    private

    public :: multigrid_t

    !> One level: its operator and the transfer from the next coarser level.
    type :: mg_level_t
        integer :: n = 0
        type(csr_t) :: a
        !> Prolongation from level + 1 [n, n_coarser] and its transpose (not on the coarsest).
        type(csr_t) :: p, r
        !> a p (kept for its pattern: later set-ups only recompute values).
        type(csr_t) :: ap
        !> Position of each row's diagonal in a%val.
        integer, allocatable :: diag(:)
        !> Smoother lines: rows of control points along xi (1) and along eta (2).
        type(line_set_t) :: lines(2)
        !> DOFs outside the multigrid space (Dirichlet and what they constrain).
        logical, allocatable :: fixed(:)
        !> Work vectors: right-hand side, solution, residual [n]; line solves.
        real(dp), allocatable :: b(:), x(:), res(:), work(:)
    end type mg_level_t

    !> Control points of a body at one level, as the smoother's lines see them:
    !> ids(i, j) of the tensor grid (0: none) and an extra xi line (the VO layer).
    type :: body_grid_t
        integer, allocatable :: ids(:, :), extra(:)
    end type body_grid_t

    !> The multigrid preconditioner and its GMRES. Holds a UMFPACK factorization:
    !> declare one per solve sequence and do not assign these objects (gfortran
    !> crashed finalizing the handle of an assigned structure-constructor temporary).
    type, extends(linear_solver_t) :: multigrid_t
        !> Largest coarse problem solved directly.
        integer :: coarse_dofs = 2000
        !> Line Gauss-Seidel sweeps (each: xi lines, then eta lines) before and
        !> after each coarse correction.
        integer :: sweeps = 1
        !> GMRES restart length and iteration cap per solve.
        integer :: restart = 50, max_iterations = 500
        !> Counters (read only): setups, solves, GMRES iterations in all and in the last solve.
        integer :: n_setups = 0, n_solves = 0, n_iterations = 0, iterations_last = 0
        !> Relative residual reached by the last solve (read only).
        real(dp) :: residual_last = 0.0_dp
        type(mg_level_t), allocatable :: levels(:)
        !> The tangent's CSC pattern the operators were built for, and the position
        !> in the tangent's values of each fine CSR entry.
        integer, allocatable, private :: colptr(:), rowind(:), perm(:)
        type(csc_matrix_t), private :: coarse
        type(umfpack_t), private :: lu
        !> GMRES work arrays, kept between solves (no page faults per solve).
        real(dp), allocatable, private :: v(:, :), w(:), r(:)
    contains
        !> Build the hierarchy of spaces and prolongations (once per run).
        procedure :: build => mg_build
        !> Galerkin operators and coarsest factorization for a new tangent.
        procedure :: factor => mg_setup
        !> Solve A x = b to a relative residual (GMRES + V-cycle).
        procedure :: solve => mg_solve
        !> Number of levels (1: no coarsening possible).
        procedure :: n_levels => mg_n_levels
        !> DOFs of every level.
        procedure :: level_dofs => mg_level_dofs
        procedure :: iterative => mg_iterative
        procedure :: last_iterations => mg_last_iterations
        procedure :: last_residual => mg_last_residual
    end type multigrid_t

contains

    !> Build the hierarchy for bodies `discs` whose DOFs start at `dof0` (2 per
    !> control point: 2(a-1)+c), `ndof` in all, with the Dirichlet DOFs `fixed`.
    subroutine mg_build(self, discs, dof0, ndof, fixed, error)
        class(multigrid_t), intent(inout) :: self
        type(discretization_t), intent(in) :: discs(:)
        integer, intent(in) :: dof0(:), ndof
        logical, intent(in) :: fixed(:)
        type(error_t), allocatable, intent(out) :: error
        type(mg_level_t), allocatable :: levels(:)
        type(coarse_space_t), allocatable :: spaces(:), next(:)
        type(cp_map_t), allocatable :: maps(:)
        integer, allocatable :: off_f(:), off_c(:), ncp(:)
        ! body is still at its discretization (no coarse space yet)
        logical, allocatable :: at_disc(:), changed(:)
        type(body_grid_t), allocatable :: grids(:)
        integer :: nb, ib, lev, nc, i, j

        nb = size(discs)
        allocate (spaces(nb), next(nb), maps(nb), off_f(nb), off_c(nb), ncp(nb), at_disc(nb), changed(nb))
        allocate (grids(nb))
        at_disc = .true.
        off_f = dof0
        do ib = 1, nb
            ncp(ib) = discs(ib)%ncp
            grids(ib)%ids = discs(ib)%bulk_id
            grids(ib)%extra = discs(ib)%layer_id
        end do
        allocate (levels(1))
        levels(1)%n = ndof
        levels(1)%fixed = fixed
        lev = 1
        do while (levels(lev)%n > self%coarse_dofs)
            do ib = 1, nb
                if (at_disc(ib)) then
                    call coarsen_discretization(discs(ib), next(ib), maps(ib), changed(ib), error)
                else
                    call coarsen_space(spaces(ib), next(ib), maps(ib), changed(ib), error)
                end if
                ! a coarse space that cannot be built (rank-deficient insertion, weights
                ! that do not fit) ends this body's coarsening, not the run
                if (allocated(error)) then
                    deallocate (error)
                    changed(ib) = .false.
                end if
                if (.not. changed(ib)) call identity_map(ncp(ib), maps(ib))
            end do
            if (.not. any(changed)) exit
            nc = 0
            do ib = 1, nb
                off_c(ib) = nc
                nc = nc + 2*maps(ib)%n_coarse
            end do
            call make_lines(levels(lev), grids, off_f)
            call append_level(levels, lev, maps, off_f, off_c, nc)
            do ib = 1, nb
                if (changed(ib)) then
                    ! the coarse control points form a plain tensor grid
                    deallocate (grids(ib)%ids)
                    allocate (grids(ib)%ids(size(next(ib)%w, 1), size(next(ib)%w, 2)))
                    do j = 1, size(grids(ib)%ids, 2)
                        do i = 1, size(grids(ib)%ids, 1)
                            grids(ib)%ids(i, j) = i + (j - 1)*size(grids(ib)%ids, 1)
                        end do
                    end do
                    grids(ib)%extra = [integer ::]
                    call move_alloc(next(ib)%knots_xi, spaces(ib)%knots_xi)
                    call move_alloc(next(ib)%knots_eta, spaces(ib)%knots_eta)
                    call move_alloc(next(ib)%w, spaces(ib)%w)
                    spaces(ib)%degree = next(ib)%degree
                    at_disc(ib) = .false.
                end if
                ncp(ib) = maps(ib)%n_coarse
            end do
            off_f = off_c
            lev = lev + 1
        end do
        call move_alloc(levels, self%levels)
        do lev = 1, size(self%levels)
            associate (l => self%levels(lev))
                allocate (l%b(l%n), l%x(l%n), l%res(l%n))
                allocate (l%work(max(1, l%lines(1)%longest(), l%lines(2)%longest())))
            end associate
        end do
    end subroutine mg_build

    !> The smoother's xi and eta lines of a level whose bodies' DOFs start at
    !> `off` (fixed DOFs are in no line).
    subroutine make_lines(level, grids, off)
        type(mg_level_t), intent(inout) :: level
        type(body_grid_t), intent(in) :: grids(:)
        integer, intent(in) :: off(:)
        integer, allocatable :: ptr(:), dofs(:)
        integer :: dir, ib, i, j, nl, nd

        do dir = 1, 2
            allocate (ptr(1), dofs(level%n))
            ptr(1) = 1
            nl = 0
            nd = 0
            do ib = 1, size(grids)
                associate (ids => grids(ib)%ids)
                    if (dir == 1) then
                        do j = 1, size(ids, 2)
                            call add_line(ids(:, j), off(ib))
                        end do
                        if (size(grids(ib)%extra) > 0) call add_line(grids(ib)%extra, off(ib))
                    else
                        do i = 1, size(ids, 1)
                            call add_line(ids(i, :), off(ib))
                        end do
                    end if
                end associate
            end do
            call new_line_set(level%lines(dir), level%n, ptr, dofs(1:nd))
            deallocate (ptr, dofs)
        end do
    contains
        subroutine add_line(cps, offset)
            integer, intent(in) :: cps(:), offset
            integer :: k, c, d, n0
            n0 = nd
            do k = 1, size(cps)
                if (cps(k) == 0) cycle
                do c = 1, 2
                    d = offset + 2*(cps(k) - 1) + c
                    if (level%fixed(d)) cycle
                    nd = nd + 1
                    dofs(nd) = d
                end do
            end do
            if (nd > n0) then
                nl = nl + 1
                ptr = [ptr, nd + 1]
            end if
        end subroutine add_line
    end subroutine make_lines

    !> The map of a body that is not coarsened further.
    pure subroutine identity_map(n, map)
        integer, intent(in) :: n
        type(cp_map_t), intent(out) :: map
        integer :: i
        map%n_fine = n
        map%n_coarse = n
        map%fine = [(i, i=1, n)]
        map%coarse = map%fine
        map%val = [(1.0_dp, i=1, n)]
    end subroutine identity_map

    !> Add level lev + 1 with nc DOFs: the DOF prolongation from the bodies'
    !> control-point maps, without the fixed fine rows and the coarse columns
    !> that touch them.
    subroutine append_level(levels, lev, maps, off_f, off_c, nc)
        type(mg_level_t), allocatable, intent(inout) :: levels(:)
        integer, intent(in) :: lev
        type(cp_map_t), intent(in) :: maps(:)
        integer, intent(in) :: off_f(:), off_c(:), nc
        type(mg_level_t), allocatable :: grown(:)
        integer, allocatable :: rows(:), cols(:)
        real(dp), allocatable :: vals(:)
        logical, allocatable :: cfixed(:), keep(:)
        integer :: ib, k, c, n, i, j

        n = 2*sum([(size(maps(ib)%val), ib=1, size(maps))])
        allocate (rows(n), cols(n), vals(n), cfixed(nc))
        cfixed = .false.
        n = 0
        do ib = 1, size(maps)
            do k = 1, size(maps(ib)%val)
                do c = 1, 2
                    n = n + 1
                    rows(n) = off_f(ib) + 2*(maps(ib)%fine(k) - 1) + c
                    cols(n) = off_c(ib) + 2*(maps(ib)%coarse(k) - 1) + c
                    vals(n) = maps(ib)%val(k)
                end do
            end do
        end do
        associate (f => levels(lev)%fixed)
            do k = 1, n
                if (f(rows(k))) cfixed(cols(k)) = .true.
            end do
            allocate (keep(n))
            do k = 1, n
                i = rows(k)
                j = cols(k)
                keep(k) = .not. (f(i) .or. cfixed(j))
            end do
        end associate
        allocate (grown(lev + 1))
        grown(1:lev) = levels(1:lev)
        call csr_from_triplets(levels(lev)%n, nc, pack(rows, keep), pack(cols, keep), pack(vals, keep), &
                               grown(lev)%p)
        call csr_transpose(grown(lev)%p, grown(lev)%r)
        grown(lev + 1)%n = nc
        grown(lev + 1)%fixed = cfixed
        call move_alloc(grown, levels)
    end subroutine append_level

    pure integer function mg_n_levels(self)
        class(multigrid_t), intent(in) :: self
        mg_n_levels = 0
        if (allocated(self%levels)) mg_n_levels = size(self%levels)
    end function mg_n_levels

    pure function mg_level_dofs(self) result(n)
        class(multigrid_t), intent(in) :: self
        integer, allocatable :: n(:)
        integer :: l
        allocate (n(self%n_levels()))
        do l = 1, size(n)
            n(l) = self%levels(l)%n
        end do
    end function mg_level_dofs

    pure logical function mg_iterative(self)
        class(multigrid_t), intent(in) :: self
        mg_iterative = .true.
    end function mg_iterative

    !> GMRES iterations of the last solve, and the relative residual it reached.
    pure integer function mg_last_iterations(self) result(n)
        class(multigrid_t), intent(in) :: self
        n = self%iterations_last
    end function mg_last_iterations

    pure real(dp) function mg_last_residual(self) result(res)
        class(multigrid_t), intent(in) :: self
        res = self%residual_last
    end function mg_last_residual

    !> Operators of every level for the tangent `a` (Dirichlet rows and columns
    !> already replaced by the identity, `csc_matrix_t%fix_dofs`).
    subroutine mg_setup(self, a, error)
        class(multigrid_t), intent(inout) :: self
        type(csc_matrix_t), intent(in) :: a
        type(error_t), allocatable, intent(out) :: error
        integer :: l, nl
        logical :: same

        if (.not. allocated(self%levels)) then
            call fatal_error(error, 'multigrid: setup before build')
            return
        end if
        nl = size(self%levels)
        same = .false.
        if (allocated(self%colptr)) then
            if (size(self%colptr) == size(a%colptr) .and. size(self%rowind) == size(a%rowind)) &
                same = all(self%colptr == a%colptr) .and. all(self%rowind == a%rowind)
        end if
        if (same) then
            ! the patterns are those of the last set-up: values only
            self%levels(1)%a%val = a%values(self%perm)
            do l = 1, nl - 1
                call csr_matmul_numeric(self%levels(l)%a, self%levels(l)%p, self%levels(l)%ap)
                call csr_matmul_numeric(self%levels(l)%r, self%levels(l)%ap, self%levels(l + 1)%a)
                associate (c => self%levels(l + 1))
                    where (c%fixed) c%a%val(c%diag) = 1.0_dp
                end associate
            end do
        else
            call fine_operator(self, a)
            do l = 1, nl - 1
                call csr_matmul(self%levels(l)%a, self%levels(l)%p, self%levels(l)%ap)
                call csr_matmul(self%levels(l)%r, self%levels(l)%ap, self%levels(l + 1)%a, sorted=.true.)
                call unit_diagonal(self%levels(l + 1)%a, self%levels(l + 1)%fixed)
            end do
            do l = 1, nl - 1
                call self%levels(l)%lines(1)%analyse(self%levels(l)%a)
                call self%levels(l)%lines(2)%analyse(self%levels(l)%a)
            end do
            do l = 1, nl
                self%levels(l)%diag = csr_diagonal_positions(self%levels(l)%a)
                if (any(self%levels(l)%diag == 0)) then
                    call fatal_error(error, 'multigrid: a level operator has no diagonal entry', &
                                     error_code%numeric)
                    return
                end if
            end do
        end if
        do l = 1, nl
            if (any(self%levels(l)%a%val(self%levels(l)%diag) == 0.0_dp)) then
                call fatal_error(error, 'multigrid: a zero on the diagonal of a level operator', &
                                 error_code%numeric)
                return
            end if
        end do
        do l = 1, nl - 1
            call self%levels(l)%lines(1)%factor(self%levels(l)%a, error)
            if (allocated(error)) return
            call self%levels(l)%lines(2)%factor(self%levels(l)%a, error)
            if (allocated(error)) return
        end do
        if (same) then
            self%coarse%values = 0.0_dp
            call coarse_values(self%levels(nl)%a, self%coarse)
        else
            call csr_to_csc(self%levels(nl)%a, self%coarse)
        end if
        call self%lu%factor(self%coarse, error)
        if (allocated(error)) then
            error%message = 'multigrid coarsest level: '//error%message
            return
        end if
        self%n_setups = self%n_setups + 1
    end subroutine mg_setup

    !> The fine operator in CSR, and the map from its entries to the tangent's
    !> values (kept for later set-ups with the same pattern).
    subroutine fine_operator(self, k)
        class(multigrid_t), intent(inout) :: self
        type(csc_matrix_t), intent(in) :: k
        type(csc_matrix_t) :: index
        type(csr_t) :: t
        integer :: q

        ! the transpose of the entry numbers gives each CSR entry's CSC position
        index%n = k%n
        index%colptr = k%colptr
        index%rowind = k%rowind
        index%values = [(real(q, dp), q=1, size(k%values))]
        call csr_from_csc(index, t)
        self%perm = nint(t%val)
        call csr_from_csc(k, self%levels(1)%a)
        self%colptr = k%colptr
        self%rowind = k%rowind
    end subroutine fine_operator

    !> Copy the values of a square CSR matrix into a CSC matrix of the same pattern.
    pure subroutine coarse_values(a, c)
        type(csr_t), intent(in) :: a
        type(csc_matrix_t), intent(inout) :: c
        integer :: i, q, j, p
        do i = 1, a%nrow
            do q = a%ptr(i), a%ptr(i + 1) - 1
                j = a%col(q)
                ! row i of column j: rows ascend within the column
                do p = c%colptr(j) + 1, c%colptr(j + 1)
                    if (c%rowind(p) + 1 == i) then
                        c%values(p) = a%val(q)
                        exit
                    end if
                end do
            end do
        end do
    end subroutine coarse_values

    !> Put 1 on the (missing) diagonal of the rows of `fixed` DOFs, which the
    !> Galerkin product leaves empty.
    pure subroutine unit_diagonal(a, fixed)
        type(csr_t), intent(inout) :: a
        logical, intent(in) :: fixed(:)
        integer, allocatable :: rows(:), cols(:)
        real(dp), allocatable :: vals(:)
        integer :: i, nf, n, k, nrow, ncol

        nf = count(fixed)
        if (nf == 0) return
        n = size(a%val)
        allocate (rows(n + nf), cols(n + nf), vals(n + nf))
        do i = 1, a%nrow
            rows(a%ptr(i):a%ptr(i + 1) - 1) = i
        end do
        cols(1:n) = a%col
        vals(1:n) = a%val
        k = n
        do i = 1, a%nrow
            if (fixed(i)) then
                k = k + 1
                rows(k) = i
                cols(k) = i
                vals(k) = 1.0_dp
            end if
        end do
        nrow = a%nrow
        ncol = a%ncol
        call csr_from_triplets(nrow, ncol, rows, cols, vals, a)
    end subroutine unit_diagonal

    !> One V-cycle from level l down: levels(l)%x ~ A_l^-1 levels(l)%b.
    recursive subroutine vcycle(self, l, error)
        class(multigrid_t), intent(inout) :: self
        integer, intent(in) :: l
        type(error_t), allocatable, intent(out) :: error
        integer :: s

        associate (lv => self%levels(l))
            if (l == size(self%levels)) then
                call self%lu%solve(self%coarse, lv%b, lv%x, error)
                return
            end if
            lv%x = 0.0_dp
            do s = 1, self%sweeps
                call lv%lines(1)%sweep(lv%a, lv%b, lv%x, .true., lv%work)
                call lv%lines(2)%sweep(lv%a, lv%b, lv%x, .true., lv%work)
            end do
            call csr_matvec(lv%a, lv%x, lv%res)
            lv%res = lv%b - lv%res
            call csr_matvec(lv%r, lv%res, self%levels(l + 1)%b)
            call vcycle(self, l + 1, error)
            if (allocated(error)) return
            call csr_matvec(lv%p, self%levels(l + 1)%x, lv%res)
            lv%x = lv%x + lv%res
            do s = 1, self%sweeps
                call lv%lines(2)%sweep(lv%a, lv%b, lv%x, .false., lv%work)
                call lv%lines(1)%sweep(lv%a, lv%b, lv%x, .false., lv%work)
            end do
        end associate
    end subroutine vcycle

    !> z = M^-1 v: one V-cycle.
    subroutine precondition(self, v, z, error)
        class(multigrid_t), intent(inout) :: self
        real(dp), intent(in) :: v(:)
        real(dp), intent(out) :: z(:)
        type(error_t), allocatable, intent(out) :: error
        self%levels(1)%b = v
        call vcycle(self, 1, error)
        z = self%levels(1)%x
    end subroutine precondition

    !> Solve A x = b (A: the fine operator of the last `factor`; `a` is not used
    !> again) by GMRES(restart), right preconditioned by a V-cycle, to
    !> ||b - A x|| <= rtol ||b||; or, after `accuracy%soft_iterations` iterations, to
    !> `accuracy%soft_rtol` (a looser target for a slowly converging solve whose
    !> accuracy matters little). Without `accuracy`: rtol = 1e-12, the attainable
    !> level in double precision. Not reaching it within `max_iterations` is a
    !> numerical error.
    subroutine mg_solve(self, a, b, x, error, accuracy)
        class(multigrid_t), intent(inout) :: self
        type(csc_matrix_t), intent(in) :: a
        real(dp), intent(in) :: b(:)
        real(dp), intent(out) :: x(:)
        type(error_t), allocatable, intent(out) :: error
        type(solve_accuracy_t), intent(in), optional :: accuracy
        real(dp), allocatable :: h(:, :), g(:), cs(:), sn(:), y(:)
        real(dp) :: bnorm, beta, target, temp, soft_target, rtol
        integer :: n, m, j, i, total, soft_it
        character(len=200) :: msg

        n = size(b)
        m = self%restart
        x = 0.0_dp
        self%n_solves = self%n_solves + 1
        self%iterations_last = 0
        bnorm = norm2(b)
        self%residual_last = 0.0_dp
        if (bnorm == 0.0_dp) return
        rtol = 1.0e-12_dp
        if (present(accuracy)) rtol = accuracy%rtol
        target = rtol*bnorm
        soft_it = huge(1)
        soft_target = target
        if (present(accuracy)) then
            if (accuracy%soft_iterations > 0) then
                soft_it = accuracy%soft_iterations
                soft_target = max(target, accuracy%soft_rtol*bnorm)
            end if
        end if
        allocate (h(m + 1, m), g(m + 1), cs(m), sn(m), y(m))
        if (.not. allocated(self%v)) allocate (self%v(n, m + 1), self%w(n), self%r(n))
        associate (v => self%v, w => self%w, r => self%r)
        r = b
        beta = bnorm
        total = 0
        do
            v(:, 1) = r/beta
            g = 0.0_dp
            g(1) = beta
            h = 0.0_dp
            j = 0
            do while (j < m)
                j = j + 1
                total = total + 1
                ! a long solve must not delay SIGINT/SIGTERM (generic error: not a
                ! numerical failure, the caller reads the signal)
                if (caught_signal() /= 0) then
                    call fatal_error(error, 'interrupted by '//signal_name(caught_signal()))
                    return
                end if
                call precondition(self, v(:, j), w, error)
                if (allocated(error)) return
                call csr_matvec(self%levels(1)%a, w, v(:, j + 1))
                ! modified Gram-Schmidt
                do i = 1, j
                    h(i, j) = dot_product(v(:, i), v(:, j + 1))
                    v(:, j + 1) = v(:, j + 1) - h(i, j)*v(:, i)
                end do
                h(j + 1, j) = norm2(v(:, j + 1))
                if (h(j + 1, j) > 0.0_dp) v(:, j + 1) = v(:, j + 1)/h(j + 1, j)
                do i = 1, j - 1
                    temp = cs(i)*h(i, j) + sn(i)*h(i + 1, j)
                    h(i + 1, j) = -sn(i)*h(i, j) + cs(i)*h(i + 1, j)
                    h(i, j) = temp
                end do
                temp = hypot(h(j, j), h(j + 1, j))
                if (temp == 0.0_dp) then
                    ! breakdown: the Krylov space holds the solution already
                    j = j - 1
                    exit
                end if
                cs(j) = h(j, j)/temp
                sn(j) = h(j + 1, j)/temp
                h(j, j) = temp
                h(j + 1, j) = 0.0_dp
                g(j + 1) = -sn(j)*g(j)
                g(j) = cs(j)*g(j)
                if (abs(g(j + 1)) <= target .or. total >= self%max_iterations) exit
                if (total >= soft_it .and. abs(g(j + 1)) <= soft_target) exit
            end do
            ! y = H^-1 g (upper triangular), x += M^-1 V y
            do i = j, 1, -1
                y(i) = (g(i) - dot_product(h(i, i + 1:j), y(i + 1:j)))/h(i, i)
            end do
            w = 0.0_dp
            do i = 1, j
                w = w + y(i)*v(:, i)
            end do
            call precondition(self, w, r, error)
            if (allocated(error)) return
            x = x + r
            call csr_matvec(self%levels(1)%a, x, r)
            r = b - r
            beta = norm2(r)
            self%residual_last = beta/bnorm
            if (beta <= target) exit
            if (total >= soft_it .and. beta <= soft_target) exit
            if (total >= self%max_iterations .or. .not. (beta == beta)) then
                write (msg, '(a,i0,a,es9.2,a,es9.2)') 'multigrid GMRES did not converge in ', total, &
                    ' iterations: relative residual ', beta/bnorm, ' > ', rtol
                call fatal_error(error, trim(msg), error_code%numeric)
                exit
            end if
        end do
        end associate
        self%iterations_last = total
        self%n_iterations = self%n_iterations + total
    end subroutine mg_solve

end module voiga_solver_multigrid
