!> Geometric multigrid over nested spline spaces, as the preconditioner of
!> restarted GMRES: the `linear_solver = 'multigrid'` of `&solver`
!> (docs/performance.md, "Multigrid").
!>
!> The hierarchy (`build`) is made once per run (`voiga_solver_multigrid_levels`).
!> Every Newton iteration (`factor`) computes the Galerkin coarse operators
!> A_(l+1) = P_l^T A_l P_l from the assembled tangent, contact included, and
!> factorizes the coarsest with UMFPACK; unless the tangent equals the last one
!> entry by entry (a linear body without contact), then all of it stands. A V-cycle smooths with `sweeps` forward
!> Gauss-Seidel sweeps before the coarse correction and as many backward sweeps
!> after it (symmetric for a symmetric tangent). GMRES (right preconditioned,
!> restarted every `restart` iterations) stops at a relative residual `rtol`.
!> Cost per Newton iteration: linear in the DOFs times the GMRES iterations.
module voiga_solver_multigrid
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_linalg_sparse, only: csc_matrix_t
    use voiga_linalg_csr, only: csr_t, csr_from_csc, csr_from_triplets, csr_matmul, &
                                csr_to_csc, csr_matvec, csr_diagonal_positions, csr_matmul_numeric
    use voiga_solver_umfpack, only: umfpack_t
    use voiga_solver_linear, only: linear_solver_t, solve_accuracy_t
    use voiga_platform_signals, only: caught_signal, signal_name
    use voiga_text, only: str, real_str
    use voiga_discretization_patch, only: discretization_t
    use voiga_solver_multigrid_levels, only: mg_level_t, build_levels
    implicit none
    private

    public :: multigrid_t

    !> The multigrid preconditioner and its GMRES. Holds a UMFPACK factorization:
    !> declare one per solve sequence and do not assign these objects (gfortran
    !> crashed finalizing the handle of an assigned structure-constructor temporary).
    type, extends(linear_solver_t) :: multigrid_t
        !> Largest coarse problem solved directly.
        integer :: coarse_dofs = 2000
        !> Line Gauss-Seidel sweeps (each: xi lines, then eta lines, then zeta lines)
        !> before and after each coarse correction (in reverse order after).
        integer :: sweeps = 1
        !> GMRES restart length and iteration cap per solve.
        integer :: restart = 50, max_iterations = 500
        !> Counters (read only): setups, setups skipped (the tangent of the last one
        !> again), solves, GMRES iterations in all and in the last solve.
        integer :: n_setups = 0, n_reused = 0, n_solves = 0, n_iterations = 0, iterations_last = 0
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

    !> Build the hierarchy for bodies `discs` whose DOFs start at `dof0` (nsd per
    !> control point: nsd(a-1)+c), `ndof` in all, with the Dirichlet DOFs `fixed`.
    subroutine mg_build(self, discs, dof0, ndof, fixed, error)
        class(multigrid_t), intent(inout) :: self
        type(discretization_t), intent(in) :: discs(:)
        integer, intent(in) :: dof0(:), ndof
        logical, intent(in) :: fixed(:)
        type(error_t), allocatable, intent(out) :: error
        call build_levels(self%coarse_dofs, discs, dof0, ndof, fixed, self%levels, error)
    end subroutine mg_build

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
        integer :: l, nl, d
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
            ! the tangent of the last set-up (a linear body without contact, whose
            ! tangent does not change): its operators and factors stand
            if (same_values(self%levels(1)%a%val, a%values, self%perm)) then
                self%n_reused = self%n_reused + 1
                return
            end if
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
                do d = 1, size(self%levels(l)%lines)
                    call self%levels(l)%lines(d)%analyse(self%levels(l)%a)
                end do
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
            do d = 1, size(self%levels(l)%lines)
                call self%levels(l)%lines(d)%factor(self%levels(l)%a, error)
                if (allocated(error)) return
            end do
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

    !> Is val(q) = values(perm(q)) for every q? (A loop that stops at the first
    !> difference: no temporary of the tangent's size.)
    pure logical function same_values(val, values, perm) result(same)
        real(dp), intent(in) :: val(:), values(:)
        integer, intent(in) :: perm(:)
        integer :: q
        same = .false.
        do q = 1, size(perm)
            if (val(q) /= values(perm(q))) return
        end do
        same = .true.
    end function same_values

    !> The fine operator in CSR, and the map from its entries to the tangent's
    !> values (kept for later set-ups with the same pattern).
    subroutine fine_operator(self, k)
        class(multigrid_t), intent(inout) :: self
        type(csc_matrix_t), intent(in) :: k

        call csr_from_csc(k, self%levels(1)%a, self%perm)
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
        integer :: s, d

        associate (lv => self%levels(l))
            if (l == size(self%levels)) then
                call self%lu%solve(self%coarse, lv%b, lv%x, error)
                return
            end if
            lv%x = 0.0_dp
            do s = 1, self%sweeps
                do d = 1, size(lv%lines)
                    call lv%lines(d)%sweep(lv%a, lv%b, lv%x, .true., lv%work)
                end do
            end do
            call csr_matvec(lv%a, lv%x, lv%res)
            lv%res = lv%b - lv%res
            call csr_matvec(lv%r, lv%res, self%levels(l + 1)%b)
            call vcycle(self, l + 1, error)
            if (allocated(error)) return
            call csr_matvec(lv%p, self%levels(l + 1)%x, lv%res)
            lv%x = lv%x + lv%res
            do s = 1, self%sweeps
                do d = size(lv%lines), 1, -1
                    call lv%lines(d)%sweep(lv%a, lv%b, lv%x, .false., lv%work)
                end do
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
                call fatal_error(error, 'multigrid GMRES did not converge in '//str(total)// &
                                 ' iterations: relative residual '//real_str(beta/bnorm, 'es9.2')//' > '// &
                                 real_str(rtol, 'es9.2'), error_code%numeric)
                exit
            end if
        end do
        end associate
        self%iterations_last = total
        self%n_iterations = self%n_iterations + total
    end subroutine mg_solve

end module voiga_solver_multigrid
