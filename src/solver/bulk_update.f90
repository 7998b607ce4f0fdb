!> Direct solves with tangents K = K0 + D whose bulk part K0 never changes: every
!> body linear-elastic, so only the contact adds to the tangent, and only on the
!> DOFs C it couples. K0 (the bodies' stiffness, Dirichlet DOFs eliminated) is
!> LU-factorized once per run, and each tangent is solved through its update
!> D = K - K0, a low-rank one. With x0 = K0^-1 b and S = (K0^-1)_CC,
!>
!>     (I + S D_CC) y = x0_C,    x = K0^-1 (b - E D_CC y)        (y = x_C)
!>
!> solves K x = b exactly in exact arithmetic (Woodbury's identity in the form that
!> needs no inverse of D, which is singular wherever a contact point is inactive).
!> S is kept over the run for every DOF that was ever in C: a DOF entering C costs
!> one solve with K0 and one with K0^T (its column and its row of K0^-1); a
!> tangent then costs a dense LU of order |C|, and a solve two solves with K0.
!>
!> D is found entry by entry as K - K0 on the tangent's pattern, so the path is
!> exact whatever the caller assembled: where the bulk part does change after all
!> (a body that is not linear, another Dirichlet set), C grows until the dense
!> work would cost more than a sparse LU of K, and K is then factorized whole.
module voiga_solver_bulk_update
    use, intrinsic :: iso_c_binding, only: c_int
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_text, only: str, real_str
    use voiga_linalg_lapack, only: lu_factor, lu_solve
    use voiga_linalg_blas, only: dgemm
    use voiga_solver_sparse, only: csc_matrix_t, pattern_positions
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

    !> Columns of K0^-1 learned per multi-column solve (bounds the work arrays, n x this).
    integer, parameter :: learn_block = 64

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
        !> Most values of the whole columns of K0^-1 kept (default 2^24: 128 MiB;
        !> hertz m4 NN2.2 keeps 171 columns of 7540, 1.3e6).
        real(dp) :: max_kept = 2.0_dp**24
        !> The bulk stiffness on its own pattern, its Cholesky factor, and the LU of a whole tangent.
        type(csc_matrix_t), private :: k0
        type(cholmod_t), private :: chol
        type(umfpack_t), private :: full
        !> The last tangent was factorized whole (`full`), not updated.
        logical, private :: whole = .false.
        !> K0's values on the pattern of the last tangent [nnz], and that pattern [n+1], [nnz].
        real(dp), allocatable, private :: base(:)
        integer(c_int), allocatable, private :: colptr(:), rowind(:)
        !> DOFs whose rows and columns of K0^-1 are known, the first `ns` of `known`;
        !> `slot(dof)`: position among them (0: none), shape [n].
        integer, allocatable, private :: known(:), slot(:)
        integer, private :: ns = 0
        !> s(p, q) = K0^-1(known(p), known(q)); shape: [capacity, capacity].
        real(dp), allocatable, private :: s(:, :)
        !> z(:, q) = K0^-1 e_known(q), the whole columns, kept while they fit in
        !> `max_kept` (then a solve needs one solve with K0, else two); shape: [n, capacity].
        real(dp), allocatable, private :: z(:, :)
        !> The update of the last tangent: C [m], D_CC [m, m], the LU of I + S_CC D_CC [m, m] and its pivots.
        integer, allocatable, private :: c(:), piv(:)
        real(dp), allocatable, private :: d(:, :), lu(:, :)
        integer, private :: sign_m = 0
        real(dp), private :: log_m = 0.0_dp
    contains
        procedure :: factor => bulk_factor
        procedure :: solve => bulk_solve
        procedure :: solve_columns => bulk_solve_columns
        procedure :: has_determinant => bulk_has_determinant
        procedure :: determinant => bulk_determinant
        procedure :: factorizations => bulk_factorizations
        !> |C| of the last tangent (-1: it was factorized whole) and the DOFs of K0^-1 known.
        procedure :: rank => bulk_rank
        procedure :: known_dofs => bulk_known_dofs
    end type bulk_update_t

contains

    !> Set up with the bulk stiffness `k0` (its values are those every tangent
    !> starts from; Dirichlet DOFs `fixed` [n] eliminated here) and factorize it.
    !> K0 must be symmetric (to `symmetric_tol`) and positive definite, else an
    !> error with code `numeric`: the caller then factorizes whole tangents (a body
    !> that only contact holds in place has a singular K0).
    subroutine new_bulk_update(self, k0, fixed, error)
        type(bulk_update_t), intent(out) :: self
        type(csc_matrix_t), intent(in) :: k0
        logical, intent(in) :: fixed(:)
        type(error_t), allocatable, intent(out) :: error
        real(dp) :: rel
        self%k0 = k0
        call self%k0%fix_dofs(fixed)
        rel = asymmetry(self%k0)
        if (rel > symmetric_tol) then
            call fatal_error(error, 'the bulk stiffness is not symmetric (max |K - K^T| / max |K| = '// &
                             real_str(rel, 'es9.2')//')', error_code%numeric)
            return
        end if
        call self%chol%factor(self%k0, error)
        if (allocated(error)) return
        if (self%chol%rcond < singular_rcond) then
            call fatal_error(error, 'the bulk stiffness is singular (CHOLMOD''s reciprocal condition estimate '// &
                             real_str(self%chol%rcond, 'es9.2')//')', error_code%numeric)
            return
        end if
        self%max_rank = max(min_rank, floor((3.0_dp*self%chol%flops/8.0_dp)**(1.0_dp/3.0_dp)))
        allocate (self%slot(k0%n), source=0)
        allocate (self%known(0), self%s(0, 0), self%z(k0%n, 0), self%c(0), self%piv(0), self%d(0, 0), &
                  self%lu(0, 0))
    end subroutine new_bulk_update

    !> Prepare solves with the tangent `a`: find its update D = a - K0, learn the
    !> rows and columns of K0^-1 of the DOFs new to C, factorize I + S_CC D_CC; or,
    !> when C is too large, factorize `a` whole.
    subroutine bulk_factor(self, a, error)
        class(bulk_update_t), intent(inout) :: self
        type(csc_matrix_t), intent(in) :: a
        type(error_t), allocatable, intent(out) :: error
        integer :: info

        call rebase(self, a, error)
        if (allocated(error)) return
        self%c = update_dofs(a, self%base)
        self%whole = size(self%c) > self%max_rank
        if (self%whole) then
            call self%full%factor(a, error)
            return
        end if
        self%sign_m = 1
        self%log_m = 0.0_dp
        if (size(self%c) == 0) return
        call learn(self, self%c, error)
        if (allocated(error)) return
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

    !> Learn the columns of K0^-1 of the DOFs of `c` not yet known, `learn_block`
    !> at a time (K0 is symmetric: they are its rows too). When the known set would
    !> outgrow four times `max_rank`, or its matrix S `max_kept` values, it is started
    !> again from `c`.
    subroutine learn(self, c, error)
        type(bulk_update_t), intent(inout) :: self
        integer, intent(in) :: c(:)
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: new(:)
        real(dp), allocatable :: e(:, :), x(:, :), grown(:, :)
        integer :: k, k1, nb, q0, cap, limit

        new = pack(c, self%slot(c) == 0)
        if (size(new) == 0) return
        limit = min(4*self%max_rank, floor(sqrt(self%max_kept)))
        if (self%ns + size(new) > limit) then
            self%slot(self%known(:self%ns)) = 0
            self%ns = 0
            new = c
        end if
        cap = size(self%s, 1)
        if (self%ns + size(new) > cap) then
            cap = max(min(2*cap, limit), self%ns + size(new))
            allocate (grown(cap, cap), source=0.0_dp)
            grown(:self%ns, :self%ns) = self%s(:self%ns, :self%ns)
            call move_alloc(grown, self%s)
            self%known = [self%known(:self%ns), [(0, k=self%ns + 1, cap)]]
            if (allocated(self%z)) call grow_columns(self%z, self%ns, cap, self%max_kept)
        end if
        do k1 = 1, size(new), learn_block
            nb = min(learn_block, size(new) - k1 + 1)
            allocate (e(self%k0%n, nb), x(self%k0%n, nb), source=0.0_dp)
            q0 = self%ns
            do k = 1, nb
                e(new(k1 + k - 1), k) = 1.0_dp
                self%known(q0 + k) = new(k1 + k - 1)
                self%slot(new(k1 + k - 1)) = q0 + k
            end do
            call self%chol%solve_columns(self%k0, e, x, error)
            if (allocated(error)) return
            self%ns = q0 + nb
            if (allocated(self%z)) self%z(:, q0 + 1:self%ns) = x
            self%s(:self%ns, q0 + 1:self%ns) = x(self%known(:self%ns), :)
            self%s(q0 + 1:self%ns, :q0) = transpose(self%s(:q0, q0 + 1:self%ns))
            deallocate (e, x)
        end do
    end subroutine learn

    !> Room for `cap` columns of which the first `ns` are kept; none at all (the
    !> array deallocated) beyond `max_kept` values.
    pure subroutine grow_columns(z, ns, cap, max_kept)
        real(dp), allocatable, intent(inout) :: z(:, :)
        integer, intent(in) :: ns, cap
        real(dp), intent(in) :: max_kept
        real(dp), allocatable :: grown(:, :)
        if (real(size(z, 1), dp)*real(cap, dp) > max_kept) then
            deallocate (z)
            return
        end if
        allocate (grown(size(z, 1), cap))
        grown(:, :ns) = z(:, :ns)
        call move_alloc(grown, z)
    end subroutine grow_columns

    !> D_CC from the tangent `a` and the matrix I + S_CC D_CC to factorize.
    subroutine update_matrix(self, a)
        type(bulk_update_t), intent(inout) :: self
        type(csc_matrix_t), intent(in) :: a
        integer, allocatable :: at(:), idx(:)
        integer :: m, q, p, i
        m = size(self%c)
        allocate (at(a%n), source=0)
        at(self%c) = [(q, q=1, m)]
        if (allocated(self%d)) deallocate (self%d)
        allocate (self%d(m, m), source=0.0_dp)
        do q = 1, m
            do p = a%colptr(self%c(q)) + 1, a%colptr(self%c(q) + 1)
                i = at(a%rowind(p) + 1)
                if (i > 0) self%d(i, q) = a%values(p) - self%base(p)
            end do
        end do
        idx = self%slot(self%c)
        self%lu = matmul(self%s(idx, idx), self%d)
        do q = 1, m
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

    !> Solve a X = B (shapes [n, nrhs]): X0 = K0^-1 B, (I + S D) Y = X0_C,
    !> X = X0 - K0^-1 E D Y (from the kept columns of K0^-1, else by a second
    !> solve), each solve with K0 for all columns at once.
    subroutine bulk_solve_columns(self, a, b, x, error)
        class(bulk_update_t), intent(inout) :: self
        type(csc_matrix_t), intent(in) :: a
        real(dp), intent(in) :: b(:, :)
        real(dp), intent(out) :: x(:, :)
        type(error_t), allocatable, intent(out) :: error
        real(dp), allocatable :: y(:, :), rhs(:, :), w(:, :)
        integer :: info

        if (self%whole) then
            call self%full%solve_columns(a, b, x, error)
            return
        end if
        call self%chol%solve_columns(self%k0, b, x, error)
        if (allocated(error) .or. size(self%c) == 0) return
        y = x(self%c, :)
        call lu_solve(self%lu, self%piv, y, info)
        if (info /= 0) then
            call fatal_error(error, 'bulk update: dense solve failed (info '//str(info)//')')
            return
        end if
        if (allocated(self%z)) then
            ! K0^-1 E (D y) from the kept columns: one product with all of them, D y
            ! scattered to their slots (zeros for the known DOFs outside C)
            allocate (w(self%ns, size(x, 2)), source=0.0_dp)
            w(self%slot(self%c), :) = matmul(self%d, y)
            call dgemm('N', 'N', size(x, 1), size(x, 2), self%ns, -1.0_dp, self%z, size(self%z, 1), &
                       w, self%ns, 1.0_dp, x, size(x, 1))
            return
        end if
        rhs = b
        rhs(self%c, :) = rhs(self%c, :) - matmul(self%d, y)
        call self%chol%solve_columns(self%k0, rhs, x, error)
    end subroutine bulk_solve_columns

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

    pure integer function bulk_known_dofs(self) result(n)
        class(bulk_update_t), intent(in) :: self
        n = self%ns
    end function bulk_known_dofs

end module voiga_solver_bulk_update
