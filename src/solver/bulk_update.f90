!> Direct solves with tangents K = K0 + D whose bulk part K0 never changes: every
!> body linear-elastic, so only the contact adds to the tangent, and only on the
!> DOFs C it couples. K0 (the bodies' stiffness, Dirichlet DOFs eliminated) is
!> Cholesky-factorized once per run, with the DOFs contact can reach, R (C is in
!> R), ordered last: P K0 P^T = L L^T, and L's trailing block L_RR is theirs. Then
!> S = (K0^-1)_RR = L_RR^-T L_RR^-1 (dense, order |R|, once per run), and with
!> w = L^-1 P b, x0_C = (L_RR^-T w_R)_C,
!>
!>     (I + S_CC D_CC) y = x0_C,    x = P^T L^-T (w - [0; L_RR^-1 E D_CC y])
!>
!> solves K x = b exactly in exact arithmetic (Woodbury's identity in the form that
!> needs no inverse of D, which is singular wherever a contact point is inactive):
!> a tangent costs a dense LU of order |C|, a solve one solve with K0 and two
!> triangular solves of order |R|. No column of K0^-1 is solved for.
!>
!> D is found entry by entry as K - K0 on the tangent's pattern, so the path is
!> exact whatever the caller assembled: where it differs outside R (a body that is
!> not linear after all, another Dirichlet set) or on more DOFs than the dense work
!> pays for, K is factorized whole.
!>
!> A large reach (a solid's contact face: thousands of DOFs, where S's |R|^3 would cost
!> more than many factorizations) is updated lazily instead: K0 factorized without an
!> ordering constraint, and the columns Z of K0^-1 computed only for the DOFs contact
!> has coupled so far, when a tangent first needs them (one solve with L and L^T each,
!> kept for the run: K0 does not change); then S_CC = Z_C rows, and
!>
!>     x0 = K0^-1 b,    (I + S_CC D_CC) y = x0_C,    x = x0 - Z_C D_CC y.
module voiga_solver_bulk_update
    use, intrinsic :: iso_c_binding, only: c_int
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_text, only: str, real_str
    use voiga_linalg_lapack, only: lu_factor, lu_solve, triangular_inverse
    use voiga_linalg_blas, only: dgemm, triangular_solve
    use voiga_linalg_sparse, only: csc_matrix_t, pattern_positions
    use voiga_solver_linear, only: linear_solver_t, solve_accuracy_t, solve_one_column
    use voiga_solver_umfpack, only: umfpack_t
    use voiga_solver_cholmod, only: cholmod_t
    implicit none
    private

    public :: bulk_update_t, new_bulk_update

    !> K0 below this reciprocal condition estimate ((min / max diagonal of its
    !> Cholesky factor)^2) is taken as singular: a body that only contact holds in
    !> place has a rigid-body mode, which the factorization meets as a pivot of
    !> round-off size, not as an exact zero (measured: 4.5e-16 for the pressed blocks
    !> of test_alm, against 1.1e-3 for hertz m4 NN2.2). The update would lose every
    !> digit to that mode; the whole tangents (contact included) are regular.
    real(dp), parameter :: singular_rcond = 1.0e-10_dp

    !> `max_rank` is at least this: the dense work of an update of 64 DOFs, under a
    !> megaflop, costs less than a millisecond whatever a sparse LU would.
    integer, parameter :: min_rank = 64

    !> Largest reach by default: S, dense of order |R|, takes at most 128 MiB (a
    !> contact edge of 4096 DOFs; hertz m4 NN2.2 has 436, m6 N2 580).
    integer, parameter :: default_max_reach = 4096
    !> A reach larger than this is updated lazily (see the module): S's |R|^3 flops
    !> (1e9 here) then cost more than the columns contact couples (the 2D cases' reaches,
    !> at most 580, stay eager; a solid's face of 3072 DOFs took 6 s to form S).
    integer, parameter :: default_eager_reach = 1024
    !> The lazy columns of K0^-1 take at most this many bytes; a tangent needing more
    !> is factorized whole.
    real(dp), parameter :: max_column_bytes = 1024.0_dp**3

    !> K0 counts as symmetric when max |K0 - K0^T| <= this x max |K0| (rounding of
    !> the element integrals: each element matrix is symmetric but summed in the
    !> floating-point order of its loops); then K0^-1's rows are its columns.
    real(dp), parameter :: symmetric_tol = 1.0e-13_dp

    !> The linear solver of tangents with a constant bulk part (see the module).
    type, extends(linear_solver_t) :: bulk_update_t
        !> Largest |C| solved by the update: the dense LU and product of order m,
        !> 8/3 m^3 flops, cost at most a numeric factorization of K0 (CHOLMOD's flop
        !> count; an LU of the whole tangent costs more), and at least `min_rank`.
        integer :: max_rank = 0
        !> The bulk stiffness on its own pattern, its Cholesky factor, and the LU of a whole tangent.
        type(csc_matrix_t), private :: k0
        type(cholmod_t), private :: chol
        type(umfpack_t), private :: full
        !> The last tangent was factorized whole (`full`), not updated.
        logical, private :: whole = .false.
        !> K0's values on the pattern of the last tangent [nnz], and that pattern [n+1], [nnz].
        real(dp), allocatable, private :: base(:)
        integer(c_int), allocatable, private :: colptr(:), rowind(:)
        !> perm(k): the DOF at position k of the factor [n] (R: its last m);
        !> at(dof): the DOF's position within R, 0 outside it [n].
        integer, allocatable, private :: perm(:), at(:)
        !> L_RR and S = (K0^-1)_RR; shapes [m, m].
        real(dp), allocatable, private :: l_rr(:, :), s(:, :)
        !> The update of the last tangent: C [k], D_CC [k, k], the LU of I + S_CC D_CC [k, k] and its pivots.
        integer, allocatable, private :: c(:), piv(:)
        real(dp), allocatable, private :: d(:, :), lu(:, :)
        integer, private :: sign_m = 0
        real(dp), private :: log_m = 0.0_dp
        !> Lazy mode: the columns of K0^-1 computed so far [n, capacity] (`nz` of them),
        !> each DOF's column (0: none yet) [n], and the reach's size.
        logical, private :: lazy = .false.
        real(dp), allocatable, private :: z(:, :)
        integer, allocatable, private :: zcol(:)
        integer, private :: nz = 0, m_reach = 0
    contains
        procedure :: factor => bulk_factor
        procedure :: solve => bulk_solve
        procedure :: solve_columns => bulk_solve_columns
        procedure :: has_determinant => bulk_has_determinant
        procedure :: determinant => bulk_determinant
        procedure :: factorizations => bulk_factorizations
        !> |C| of the last tangent (-1: it was factorized whole) and |R|.
        procedure :: rank => bulk_rank
        procedure :: reach => bulk_reach
    end type bulk_update_t

contains

    !> Set up with the bulk stiffness `k0` (its values are those every tangent
    !> starts from; Dirichlet DOFs `fixed` [n] eliminated here) and the DOFs contact
    !> can couple, `reach` (distinct); factorize it with them last and form S.
    !> K0 must be symmetric (to `symmetric_tol`) and positive definite, else an
    !> error with code `numeric`: the caller then factorizes whole tangents (a body
    !> that only contact holds in place has a singular K0). A reach of more than
    !> `max_reach` DOFs (default `default_max_reach`) is an error too: S would not pay.
    subroutine new_bulk_update(self, k0, fixed, reach, error, max_reach, eager_reach)
        type(bulk_update_t), intent(out) :: self
        type(csc_matrix_t), intent(in) :: k0
        logical, intent(in) :: fixed(:)
        integer, intent(in) :: reach(:)
        type(error_t), allocatable, intent(out) :: error
        !> Largest eager reach (default `default_max_reach`), and the reach beyond
        !> which the update is lazy (default `default_eager_reach`).
        integer, intent(in), optional :: max_reach, eager_reach
        real(dp) :: rel
        integer :: m, k, limit, eager
        limit = default_max_reach
        if (present(max_reach)) limit = max_reach
        eager = default_eager_reach
        if (present(eager_reach)) eager = eager_reach
        self%lazy = size(reach) > eager
        if (size(reach) > limit .and. .not. self%lazy) then
            call fatal_error(error, 'bulk update: contact can reach '//str(size(reach))//' DOFs, more than '// &
                             str(limit)//' (the dense S of their K0^-1 would take '// &
                             real_str(8.0_dp*real(size(reach), dp)**2/2.0_dp**20, 'f0.0')//' MiB)')
            return
        end if
        self%k0 = k0
        call self%k0%fix_dofs(fixed)
        rel = asymmetry(self%k0)
        if (rel > symmetric_tol) then
            call fatal_error(error, 'the bulk stiffness is not symmetric (max |K - K^T| / max |K| = '// &
                             real_str(rel, 'es9.2')//')', error_code%numeric)
            return
        end if
        if (self%lazy) then
            call self%chol%factor(self%k0, error)
        else
            call self%chol%factor_last(self%k0, reach, error)
        end if
        if (allocated(error)) return
        if (self%chol%rcond < singular_rcond) then
            call fatal_error(error, 'the bulk stiffness is singular (CHOLMOD''s reciprocal condition estimate '// &
                             real_str(self%chol%rcond, 'es9.2')//')', error_code%numeric)
            return
        end if
        self%max_rank = max(min_rank, floor((3.0_dp*self%chol%flops/8.0_dp)**(1.0_dp/3.0_dp)))
        m = size(reach)
        self%m_reach = m
        if (self%lazy) then
            allocate (self%at(k0%n), self%zcol(k0%n), source=0)
            self%at(reach) = 1
            allocate (self%z(k0%n, 0), self%l_rr(0, 0), self%c(0), self%piv(0), self%d(0, 0), self%lu(0, 0))
            return
        end if
        self%perm = self%chol%permutation()
        allocate (self%at(k0%n), source=0)
        self%at(self%perm(k0%n - m + 1:)) = [(k, k=1, m)]
        call reach_inverse(self, m, error)
        allocate (self%c(0), self%piv(0), self%d(0, 0), self%lu(0, 0))
    end subroutine new_bulk_update

    !> L_RR from the factor, and S = L_RR^-T L_RR^-1.
    subroutine reach_inverse(self, m, error)
        type(bulk_update_t), intent(inout) :: self
        integer, intent(in) :: m
        type(error_t), allocatable, intent(out) :: error
        real(dp), allocatable :: inv(:, :)
        integer :: info
        call self%chol%trailing(m, self%l_rr, error)
        if (allocated(error)) return
        inv = self%l_rr
        call triangular_inverse(inv, info)
        if (info /= 0) then
            call fatal_error(error, 'the bulk stiffness''s factor is singular (pivot '//str(info)//')', &
                             error_code%numeric)
            return
        end if
        allocate (self%s(m, m))
        if (m > 0) call dgemm('T', 'N', m, m, m, 1.0_dp, inv, m, inv, m, 0.0_dp, self%s, m)
    end subroutine reach_inverse

    !> Prepare solves with the tangent `a`: find its update D = a - K0 and factorize
    !> I + S_CC D_CC; or, when C is too large or leaves the reach, factorize `a` whole.
    subroutine bulk_factor(self, a, error)
        class(bulk_update_t), intent(inout) :: self
        type(csc_matrix_t), intent(in) :: a
        type(error_t), allocatable, intent(out) :: error
        integer :: info

        call rebase(self, a, error)
        if (allocated(error)) return
        self%c = update_dofs(a, self%base)
        self%whole = size(self%c) > self%max_rank
        if (.not. self%whole) self%whole = any(self%at(self%c) == 0)
        if (.not. self%whole .and. self%lazy) then
            call lazy_columns(self, error)
            if (allocated(error)) return
        end if
        if (self%whole) then
            call self%full%factor(a, error)
            return
        end if
        self%sign_m = 1
        self%log_m = 0.0_dp
        if (size(self%c) == 0) return
        call update_matrix(self, a)
        if (allocated(self%piv)) deallocate (self%piv)
        allocate (self%piv(size(self%c)))
        call lu_factor(self%lu, self%piv, info)
        if (info /= 0) then
            call fatal_error(error, 'the tangent is singular (its contact update, pivot '//str(info)// &
                             ' of '//str(size(self%c))//')', error_code%numeric)
            return
        end if
        call dense_determinant(self%lu, self%piv, self%sign_m, self%log_m)
    end subroutine bulk_factor

    !> K0's values on the pattern of `a`, when it differs from the last one (every
    !> entry of K0 is in a tangent's pattern: the bodies' elements are).
    subroutine rebase(self, a, error)
        type(bulk_update_t), intent(inout) :: self
        type(csc_matrix_t), intent(in) :: a
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: pos(:)
        integer :: p
        if (allocated(self%colptr)) then
            if (size(self%colptr) == size(a%colptr) .and. size(self%rowind) == size(a%rowind)) then
                if (all(self%colptr == a%colptr) .and. all(self%rowind == a%rowind)) return
            end if
        end if
        if (a%n /= self%k0%n) then
            call fatal_error(error, 'bulk update: the tangent has '//str(a%n)//' DOFs, the bulk '// &
                             str(self%k0%n))
            return
        end if
        call pattern_positions(self%k0, a, pos)
        if (allocated(self%base)) deallocate (self%base)
        allocate (self%base(a%nnz()), source=0.0_dp)
        do p = 1, size(pos)
            if (pos(p) > 0) then
                self%base(pos(p)) = self%k0%values(p)
            else if (self%k0%values(p) /= 0.0_dp) then
                call fatal_error(error, 'bulk update: the tangent''s pattern lacks a bulk entry')
                return
            end if
        end do
        self%colptr = a%colptr
        self%rowind = a%rowind
    end subroutine rebase

    !> The DOFs (ascending) of every row and column where `a` differs from `base`.
    pure function update_dofs(a, base) result(c)
        type(csc_matrix_t), intent(in) :: a
        real(dp), intent(in) :: base(:)
        integer, allocatable :: c(:)
        logical :: mark(a%n)
        integer :: i, j, p
        mark = .false.
        do j = 1, a%n
            do p = a%colptr(j) + 1, a%colptr(j + 1)
                if (a%values(p) /= base(p)) then
                    mark(j) = .true.
                    mark(a%rowind(p) + 1) = .true.
                end if
            end do
        end do
        c = pack([(i, i=1, a%n)], mark)
    end function update_dofs

    !> D_CC from the tangent `a` and the matrix I + S_CC D_CC to factorize.
    subroutine update_matrix(self, a)
        type(bulk_update_t), intent(inout) :: self
        type(csc_matrix_t), intent(in) :: a
        integer, allocatable :: at(:), idx(:)
        real(dp) :: v
        integer :: m, q, p, i
        m = size(self%c)
        allocate (at(a%n), source=0)
        at(self%c) = [(q, q=1, m)]
        idx = self%at(self%c)
        if (allocated(self%d)) deallocate (self%d)
        if (allocated(self%lu)) deallocate (self%lu)
        allocate (self%d(m, m), self%lu(m, m), source=0.0_dp)
        ! S_CC D_CC column by column from D's nonzeros (a contact element couples a
        ! few neighbouring DOFs: some 12 per column, against |C| for a dense product)
        do q = 1, m
            do p = a%colptr(self%c(q)) + 1, a%colptr(self%c(q) + 1)
                i = at(a%rowind(p) + 1)
                if (i == 0) cycle
                v = a%values(p) - self%base(p)
                self%d(i, q) = v
                if (v == 0.0_dp) cycle
                if (self%lazy) then
                    self%lu(:, q) = self%lu(:, q) + v*self%z(self%c, self%zcol(self%c(i)))
                else
                    self%lu(:, q) = self%lu(:, q) + v*self%s(idx, idx(i))
                end if
            end do
            self%lu(q, q) = self%lu(q, q) + 1.0_dp
        end do
    end subroutine update_matrix

    !> max |a - a^T| / max |a| (0 for a zero matrix; huge when an entry's transpose
    !> is missing from the pattern and the entry is not zero). One pass: column i is
    !> asked for its rows j in ascending order (the columns j are walked in order and
    !> each column's rows are sorted), so a cursor per column finds each transpose.
    pure real(dp) function asymmetry(a) result(rel)
        type(csc_matrix_t), intent(in) :: a
        integer :: j, p, i
        integer, allocatable :: cursor(:)
        real(dp) :: big
        logical :: found
        rel = 0.0_dp
        big = maxval(abs(a%values))
        if (big == 0.0_dp) return
        cursor = a%colptr(1:a%n) + 1
        do j = 1, a%n
            do p = a%colptr(j) + 1, a%colptr(j + 1)
                i = a%rowind(p) + 1
                do while (cursor(i) <= a%colptr(i + 1))
                    if (a%rowind(cursor(i)) + 1 >= j) exit
                    cursor(i) = cursor(i) + 1
                end do
                found = .false.
                if (cursor(i) <= a%colptr(i + 1)) found = a%rowind(cursor(i)) + 1 == j
                if (found) then
                    rel = max(rel, abs(a%values(p) - a%values(cursor(i))))
                else if (a%values(p) /= 0.0_dp) then
                    rel = huge(1.0_dp)
                end if
            end do
        end do
        rel = rel/big
    end function asymmetry

    !> Sign and log10 |det| of a matrix from its LU factors and pivots.
    pure subroutine dense_determinant(lu, piv, sign, log10_abs)
        real(dp), intent(in) :: lu(:, :)
        integer, intent(in) :: piv(:)
        integer, intent(out) :: sign
        real(dp), intent(out) :: log10_abs
        integer :: i
        sign = 1
        log10_abs = 0.0_dp
        do i = 1, size(piv)
            if (piv(i) /= i) sign = -sign
            if (lu(i, i) < 0.0_dp) sign = -sign
            log10_abs = log10_abs + log10(abs(lu(i, i)))
        end do
    end subroutine dense_determinant

    !> Solve a x = b with what `factor` prepared (`a`: the tangent passed to it).
    subroutine bulk_solve(self, a, b, x, error, accuracy)
        class(bulk_update_t), intent(inout) :: self
        type(csc_matrix_t), intent(in) :: a
        real(dp), intent(in) :: b(:)
        real(dp), intent(out) :: x(:)
        type(error_t), allocatable, intent(out) :: error
        !> Ignored: a direct solve.
        type(solve_accuracy_t), intent(in), optional :: accuracy
        call solve_one_column(self, a, b, x, error)
    end subroutine bulk_solve

    !> Solve a X = B (shapes [n, nrhs]): W = L^-1 P B, (I + S D) Y = (L_RR^-T W_R)_C,
    !> X = P^T L^-T (W - [0; L_RR^-1 E D Y]), each solve with L for all columns at once.
    subroutine bulk_solve_columns(self, a, b, x, error)
        class(bulk_update_t), intent(inout) :: self
        type(csc_matrix_t), intent(in) :: a
        real(dp), intent(in) :: b(:, :)
        real(dp), intent(out) :: x(:, :)
        type(error_t), allocatable, intent(out) :: error
        real(dp), allocatable :: w(:, :), t(:, :)
        integer :: r0

        if (self%whole) then
            call self%full%solve_columns(a, b, x, error)
            return
        end if
        if (self%lazy) then
            call lazy_solve(self, a, b, x, error)
            return
        end if
        allocate (w, mold=b)
        call self%chol%forward(b(self%perm, :), w, error)
        if (allocated(error)) return
        r0 = size(w, 1) - size(self%l_rr, 1)
        if (size(self%c) > 0) then
            call reach_correction(self, w(r0 + 1:, :), error)
            if (allocated(error)) return
        end if
        allocate (t, mold=b)
        call self%chol%backward(w, t, error)
        if (allocated(error)) return
        x(self%perm, :) = t
    end subroutine bulk_solve_columns

    !> W_R := W_R - L_RR^-1 E D Y with (I + S D) Y = (L_RR^-T W_R)_C (`w_r`: [m, nrhs]).
    subroutine reach_correction(self, w_r, error)
        type(bulk_update_t), intent(in) :: self
        real(dp), intent(inout) :: w_r(:, :)
        type(error_t), allocatable, intent(out) :: error
        real(dp), allocatable :: z(:, :), y(:, :)
        integer :: info
        z = w_r
        call triangular_solve(self%l_rr, z, transposed=.true.)
        y = z(self%at(self%c), :)
        call lu_solve(self%lu, self%piv, y, info)
        if (info /= 0) then
            call fatal_error(error, 'bulk update: dense solve failed (info '//str(info)//')')
            return
        end if
        z = 0.0_dp
        z(self%at(self%c), :) = matmul(self%d, y)
        call triangular_solve(self%l_rr, z, transposed=.false.)
        w_r = w_r - z
    end subroutine reach_correction

    !> Lazy mode: the columns of K0^-1 of the DOFs of C not computed yet, solved for
    !> at once and kept; if they would take more than `max_column_bytes`, the tangent
    !> is factorized whole instead (`whole`).
    subroutine lazy_columns(self, error)
        type(bulk_update_t), intent(inout) :: self
        type(error_t), allocatable, intent(out) :: error
        real(dp), allocatable :: e(:, :), cols(:, :), grown(:, :)
        integer, allocatable :: missing(:)
        integer :: n, j
        n = size(self%zcol)
        missing = pack(self%c, self%zcol(self%c) == 0)
        if (size(missing) == 0) return
        if (8.0_dp*real(n, dp)*real(self%nz + size(missing), dp) > max_column_bytes) then
            self%whole = .true.
            return
        end if
        allocate (e(n, size(missing)), cols(n, size(missing)), source=0.0_dp)
        do j = 1, size(missing)
            e(missing(j), j) = 1.0_dp
        end do
        call self%chol%solve_columns(self%k0, e, cols, error)
        if (allocated(error)) return
        if (self%nz + size(missing) > size(self%z, 2)) then
            allocate (grown(n, max(2*size(self%z, 2), self%nz + size(missing))))
            grown(:, 1:self%nz) = self%z(:, 1:self%nz)
            call move_alloc(grown, self%z)
        end if
        self%z(:, self%nz + 1:self%nz + size(missing)) = cols
        self%zcol(missing) = [(self%nz + j, j=1, size(missing))]
        self%nz = self%nz + size(missing)
    end subroutine lazy_columns

    !> Lazy mode: X0 = K0^-1 B, (I + S_CC D_CC) Y = X0_C, X = X0 - Z_C D_CC Y.
    subroutine lazy_solve(self, a, b, x, error)
        type(bulk_update_t), intent(inout) :: self
        type(csc_matrix_t), intent(in) :: a
        real(dp), intent(in) :: b(:, :)
        real(dp), intent(out) :: x(:, :)
        type(error_t), allocatable, intent(out) :: error
        real(dp), allocatable :: y(:, :), dy(:, :)
        integer :: info, q, j
        call self%chol%solve_columns(a, b, x, error)
        if (allocated(error) .or. size(self%c) == 0) return
        y = x(self%c, :)
        call lu_solve(self%lu, self%piv, y, info)
        if (info /= 0) then
            call fatal_error(error, 'bulk update: dense solve failed (info '//str(info)//')')
            return
        end if
        ! column by column from the kept columns (no gathered copy of Z_C per solve)
        dy = matmul(self%d, y)
        do j = 1, size(x, 2)
            do q = 1, size(self%c)
                x(:, j) = x(:, j) - dy(q, j)*self%z(:, self%zcol(self%c(q)))
            end do
        end do
    end subroutine lazy_solve

    pure logical function bulk_has_determinant(self)
        class(bulk_update_t), intent(in) :: self
        bulk_has_determinant = .true.
    end function bulk_has_determinant

    !> det K = det K0 det(I + S_CC D_CC) (or that of the whole LU).
    subroutine bulk_determinant(self, sign, log10_abs, error)
        class(bulk_update_t), intent(in) :: self
        integer, intent(out) :: sign
        real(dp), intent(out) :: log10_abs
        type(error_t), allocatable, intent(out) :: error
        if (self%whole) then
            call self%full%determinant(sign, log10_abs, error)
            return
        end if
        sign = self%sign_m
        log10_abs = self%chol%log10_det + self%log_m
    end subroutine bulk_determinant

    !> Those of K0 (one of each per run) and of the whole tangents.
    pure subroutine bulk_factorizations(self, symbolic, numeric)
        class(bulk_update_t), intent(in) :: self
        integer, intent(out) :: symbolic, numeric
        symbolic = self%chol%n_factor + self%full%n_symbolic
        numeric = self%chol%n_factor + self%full%n_numeric
    end subroutine bulk_factorizations

    pure integer function bulk_rank(self) result(m)
        class(bulk_update_t), intent(in) :: self
        m = merge(-1, size(self%c), self%whole)
    end function bulk_rank

    pure integer function bulk_reach(self) result(n)
        class(bulk_update_t), intent(in) :: self
        n = self%m_reach
    end function bulk_reach

end module voiga_solver_bulk_update
