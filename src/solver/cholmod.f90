!> Sparse Cholesky solves with CHOLMOD (SuiteSparse) for symmetric positive
!> definite matrices, many right-hand sides at once.
!>
!> Used for the bulk stiffness of linear-elastic bodies (`voiga_solver_bulk_update`),
!> factorized once per run: with the DOFs contact can reach ordered last
!> (`factor_last`), L's trailing block gives their part of K0^-1 without any solve,
!> and a tangent's solve is a forward and a backward solve with L (`forward`,
!> `backward`) around a small dense correction. CHOLMOD is
!> reached through the C functions of `cholmod_shim.c` (its structs stay in C);
!> the raw interfaces are private here. Only the lower triangle of the matrix is
!> read. Not copyable: assigning one `cholmod_t` to another leaves the target
!> empty, so two objects never free the same factor.
module voiga_solver_cholmod
    use, intrinsic :: iso_c_binding, only: c_int, c_double, c_ptr, c_null_ptr, c_associated
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_text, only: str
    use voiga_linalg_sparse, only: csc_matrix_t
    use voiga_solver_linear, only: linear_solver_t, solve_accuracy_t, solve_one_column
    implicit none
    private

    public :: cholmod_t, cholmod_runs_serial

    !> A Cholesky factorization L L^T of a symmetric positive definite `csc_matrix_t`.
    type, extends(linear_solver_t) :: cholmod_t
        !> Factorizations so far (each an ordering and a numeric factorization; read only).
        integer :: n_factor = 0
        !> Flops of the last factorization, log10 det of its matrix and CHOLMOD's
        !> reciprocal condition estimate, (min / max diagonal of L)^2 (read only).
        real(dp) :: flops = 0.0_dp, log10_det = 0.0_dp, rcond = 0.0_dp
        integer, private :: n = 0
        type(c_ptr), private :: handle = c_null_ptr
    contains
        procedure :: factor => cholmod_factor
        !> Factorize with given DOFs ordered last (their block of L is `trailing`).
        procedure :: factor_last => cholmod_factor_last
        procedure :: solve => cholmod_solve
        !> Solve A X = B for the columns of B at once.
        procedure :: solve_columns => cholmod_solve_columns
        !> Solve L X = B or L^T X = B (the factor of the permuted matrix P A P^T = L L^T).
        procedure :: forward => cholmod_forward
        procedure :: backward => cholmod_backward
        !> The ordering (P A P^T = L L^T: position k holds DOF perm(k)) and L's trailing block.
        procedure :: permutation => cholmod_permutation
        procedure :: trailing => cholmod_trailing
        procedure :: has_determinant => cholmod_has_determinant
        procedure :: determinant => cholmod_determinant
        procedure :: factorizations => cholmod_factorizations
        !> Free the factor; safe to call any number of times.
        procedure :: release => cholmod_release
        procedure, private :: assign => cholmod_assign
        generic :: assignment(=) => assign
        final :: cholmod_final
    end type cholmod_t

    interface
        function voiga_cholmod_factor(n, colptr, rowind, values, nlast, last, handle, flops, log10_det, rcond) &
            result(status) bind(c, name='voiga_cholmod_factor')
            import :: c_int, c_double, c_ptr
            integer(c_int), value :: n, nlast
            integer(c_int), intent(in) :: colptr(*), rowind(*), last(*)
            real(c_double), intent(in) :: values(*)
            type(c_ptr), intent(out) :: handle
            real(c_double), intent(out) :: flops, log10_det, rcond
            integer(c_int) :: status
        end function voiga_cholmod_factor

        function voiga_cholmod_solve(handle, sys, nrhs, b, x) result(status) bind(c, name='voiga_cholmod_solve')
            import :: c_int, c_double, c_ptr
            type(c_ptr), value :: handle
            integer(c_int), value :: sys, nrhs
            real(c_double), intent(in) :: b(*)
            real(c_double), intent(out) :: x(*)
            integer(c_int) :: status
        end function voiga_cholmod_solve

        subroutine voiga_cholmod_perm(handle, perm) bind(c, name='voiga_cholmod_perm')
            import :: c_int, c_ptr
            type(c_ptr), value :: handle
            integer(c_int), intent(out) :: perm(*)
        end subroutine voiga_cholmod_perm

        function voiga_cholmod_trailing(handle, m, l) result(status) bind(c, name='voiga_cholmod_trailing')
            import :: c_int, c_double, c_ptr
            type(c_ptr), value :: handle
            integer(c_int), value :: m
            real(c_double), intent(out) :: l(*)
            integer(c_int) :: status
        end function voiga_cholmod_trailing

        function voiga_cholmod_serial() result(serial) bind(c, name='voiga_cholmod_serial')
            import :: c_int
            integer(c_int) :: serial
        end function voiga_cholmod_serial

        subroutine voiga_cholmod_free(handle) bind(c, name='voiga_cholmod_free')
            import :: c_ptr
            type(c_ptr), value :: handle
        end subroutine voiga_cholmod_free
    end interface

contains

    !> CHOLMOD's OpenMP loops run on the calling thread: OpenMP allows fewer threads
    !> than the fixed number CHOLMOD was compiled to ask for (voiga's default of one
    !> thread, or `OMP_NUM_THREADS` below it), or there is no OpenMP (cholmod_shim.c).
    logical function cholmod_runs_serial()
        cholmod_runs_serial = voiga_cholmod_serial() /= 0
    end function cholmod_runs_serial

    !> Factorize `a` (its lower triangle; a new ordering each time). A matrix that
    !> is not positive definite is an error with code `numeric`.
    subroutine cholmod_factor(self, a, error)
        class(cholmod_t), intent(inout) :: self
        type(csc_matrix_t), intent(in) :: a
        type(error_t), allocatable, intent(out) :: error
        call factor_with(self, a, [integer ::], error)
    end subroutine cholmod_factor

    !> Factorize `a` with the DOFs `last` (distinct, 1-based) ordered after all
    !> others (CAMD with two constraint sets, supernodal L L^T): the trailing
    !> size(last) x size(last) block of L is theirs. Errors as `factor`'s, and one
    !> when that ordering cannot be made.
    subroutine cholmod_factor_last(self, a, last, error)
        class(cholmod_t), intent(inout) :: self
        type(csc_matrix_t), intent(in) :: a
        integer, intent(in) :: last(:)
        type(error_t), allocatable, intent(out) :: error
        call factor_with(self, a, last, error)
    end subroutine cholmod_factor_last

    subroutine factor_with(self, a, last, error)
        class(cholmod_t), intent(inout) :: self
        type(csc_matrix_t), intent(in) :: a
        integer, intent(in) :: last(:)
        type(error_t), allocatable, intent(out) :: error
        integer(c_int) :: status
        call cholmod_release(self)
        status = voiga_cholmod_factor(int(a%n, c_int), a%colptr, a%rowind, a%values, int(size(last), c_int), &
                                      int(last - 1, c_int), self%handle, self%flops, self%log10_det, self%rcond)
        if (status == 1) then
            call fatal_error(error, 'cholmod: the matrix is not positive definite', error_code%numeric)
            return
        else if (status == -2) then
            call fatal_error(error, 'cholmod: no ordering with the '//str(size(last))//' given DOFs last')
            return
        else if (status /= 0) then
            call fatal_error(error, 'cholmod: the factorization failed (out of memory or invalid matrix)')
            return
        end if
        self%n = a%n
        self%n_factor = self%n_factor + 1
    end subroutine factor_with

    !> Solve a x = b with the factor of `factor` (`a` is not read).
    subroutine cholmod_solve(self, a, b, x, error, accuracy)
        class(cholmod_t), intent(inout) :: self
        type(csc_matrix_t), intent(in) :: a
        !> Right-hand side and solution; shape: [n].
        real(dp), intent(in) :: b(:)
        real(dp), intent(out) :: x(:)
        type(error_t), allocatable, intent(out) :: error
        !> Ignored: a direct solve.
        type(solve_accuracy_t), intent(in), optional :: accuracy
        call solve_one_column(self, a, b, x, error)
    end subroutine cholmod_solve

    !> Solve a X = B (`a` is not read), all columns at once; shapes: [n, nrhs].
    subroutine cholmod_solve_columns(self, a, b, x, error)
        class(cholmod_t), intent(inout) :: self
        type(csc_matrix_t), intent(in) :: a
        real(dp), intent(in) :: b(:, :)
        real(dp), intent(out) :: x(:, :)
        type(error_t), allocatable, intent(out) :: error
        call solve_system(self, 0_c_int, b, x, error)
    end subroutine cholmod_solve_columns

    !> Solve L X = B (no permutation; shapes [n, nrhs]).
    subroutine cholmod_forward(self, b, x, error)
        class(cholmod_t), intent(inout) :: self
        real(dp), intent(in) :: b(:, :)
        real(dp), intent(out) :: x(:, :)
        type(error_t), allocatable, intent(out) :: error
        call solve_system(self, 1_c_int, b, x, error)
    end subroutine cholmod_forward

    !> Solve L^T X = B (no permutation; shapes [n, nrhs]).
    subroutine cholmod_backward(self, b, x, error)
        class(cholmod_t), intent(inout) :: self
        real(dp), intent(in) :: b(:, :)
        real(dp), intent(out) :: x(:, :)
        type(error_t), allocatable, intent(out) :: error
        call solve_system(self, 2_c_int, b, x, error)
    end subroutine cholmod_backward

    !> Solve system `sys` of voiga_cholmod_solve: 0 A X = B, 1 L X = B, 2 L^T X = B.
    subroutine solve_system(self, sys, b, x, error)
        class(cholmod_t), intent(inout) :: self
        integer(c_int), intent(in) :: sys
        real(dp), intent(in) :: b(:, :)
        real(dp), intent(out) :: x(:, :)
        type(error_t), allocatable, intent(out) :: error
        if (.not. c_associated(self%handle)) then
            call fatal_error(error, 'cholmod solve: no factorization (factor was not called or failed)')
            return
        end if
        if (size(b, 1) /= self%n .or. any(shape(x) /= shape(b))) then
            call fatal_error(error, 'cholmod solve: right-hand sides of '//str(size(b, 1))//' rows, expected '// &
                             str(self%n))
            return
        end if
        if (size(b, 2) == 0) return
        if (voiga_cholmod_solve(self%handle, sys, int(size(b, 2), c_int), b, x) /= 0) &
            call fatal_error(error, 'cholmod solve: out of memory')
    end subroutine solve_system

    !> The ordering of the factor: P A P^T = L L^T with (P b)(k) = b(perm(k)); [n], 1-based.
    function cholmod_permutation(self) result(perm)
        class(cholmod_t), intent(in) :: self
        integer, allocatable :: perm(:)
        integer(c_int), allocatable :: p(:)
        allocate (p(self%n))
        if (self%n > 0) call voiga_cholmod_perm(self%handle, p)
        perm = p + 1
    end function cholmod_permutation

    !> The trailing m x m block of L (lower triangle, zeros above; m <= n), from a
    !> supernodal factor as `factor_last` makes.
    subroutine cholmod_trailing(self, m, l, error)
        class(cholmod_t), intent(in) :: self
        integer, intent(in) :: m
        real(dp), allocatable, intent(out) :: l(:, :)
        type(error_t), allocatable, intent(out) :: error
        allocate (l(m, m))
        if (m == 0) return
        if (.not. c_associated(self%handle) .or. m > self%n) then
            call fatal_error(error, 'cholmod: no factor with a trailing block of '//str(m))
            return
        end if
        if (voiga_cholmod_trailing(self%handle, int(m, c_int), l) /= 0) &
            call fatal_error(error, 'cholmod: the factor is not supernodal')
    end subroutine cholmod_trailing

    pure logical function cholmod_has_determinant(self)
        class(cholmod_t), intent(in) :: self
        cholmod_has_determinant = .true.
    end function cholmod_has_determinant

    !> det > 0 (positive definite) and its log10.
    subroutine cholmod_determinant(self, sign, log10_abs, error)
        class(cholmod_t), intent(in) :: self
        integer, intent(out) :: sign
        real(dp), intent(out) :: log10_abs
        type(error_t), allocatable, intent(out) :: error
        sign = merge(1, 0, c_associated(self%handle))
        log10_abs = self%log10_det
    end subroutine cholmod_determinant

    pure subroutine cholmod_factorizations(self, symbolic, numeric)
        class(cholmod_t), intent(in) :: self
        integer, intent(out) :: symbolic, numeric
        symbolic = self%n_factor
        numeric = self%n_factor
    end subroutine cholmod_factorizations

    subroutine cholmod_release(self)
        class(cholmod_t), intent(inout) :: self
        if (c_associated(self%handle)) call voiga_cholmod_free(self%handle)
        self%handle = c_null_ptr
    end subroutine cholmod_release

    subroutine cholmod_assign(lhs, rhs)
        class(cholmod_t), intent(inout) :: lhs
        type(cholmod_t), intent(in) :: rhs
        if (c_associated(lhs%handle, rhs%handle)) return
        call cholmod_release(lhs)
        lhs%n_factor = 0
    end subroutine cholmod_assign

    subroutine cholmod_final(self)
        type(cholmod_t), intent(inout) :: self
        call cholmod_release(self)
    end subroutine cholmod_final

end module voiga_solver_cholmod
