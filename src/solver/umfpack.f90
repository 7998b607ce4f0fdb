!> Direct sparse LU solves with UMFPACK (SuiteSparse), `double` values with `int` or, for large
!> matrices, `long` indices.
!>
!> `umfpack_t` owns the opaque Symbolic and Numeric objects of UMFPACK. The
!> symbolic analysis (fill-reducing ordering) depends only on the sparsity
!> pattern, which stays fixed over a simulation, so `factorize` redoes it only
!> when the pattern changes; every call redoes the numeric LU. Every UMFPACK
!> status other than `UMFPACK_OK` becomes an `error_t` naming the routine and
!> the status, and no handle is leaked on any path. The 32-bit-index version
!> (umfpack_di_*) is used until it runs out of memory (it cannot index the
!> factors of about 1.7e6 DOFs); the factorization is then redone, and every
!> later one done, with the 64-bit version (umfpack_dl_*). The raw C interfaces are
!> private to this module.
module voiga_solver_umfpack
    use, intrinsic :: iso_c_binding, only: c_int, c_long, c_double, c_ptr, c_null_ptr, c_associated
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_text, only: str
    use voiga_linalg_sparse, only: csc_matrix_t
    use voiga_solver_linear, only: linear_solver_t, solve_accuracy_t
    implicit none
    private

    public :: umfpack_t, dp_is_c_double

    !> Sizes of UMFPACK's Control and Info arrays (umfpack.h).
    integer, parameter :: umfpack_control = 20, umfpack_info = 90
    !> `sys` argument of umfpack_di_solve: solve A x = b.
    integer(c_int), parameter :: umfpack_a = 0
    !> Control(UMFPACK_IRSTEP) (0-based in C): most iterative refinement steps of a solve.
    integer, parameter :: umfpack_irstep = 7
    !> A solve refines its solution iteratively (UMFPACK's default, at most 2 steps)
    !> only when the reciprocal condition estimate of the factorization is below this.
    !> A refinement step costs a residual and a second solve (solve with refinement
    !> 8 ms, without 2 ms on ironing m4 N6); in a Newton iteration the next residual
    !> corrects a direction that is off by rounding anyway, so only a badly
    !> conditioned matrix needs it. Measured rcond: hertz 6e-3..2e-2, ironing and
    !> ironing-deep 1.4e-3..8e-2 (not refined); rings 4e-4..1.3e-3 and stiff penalties
    !> (ironing with 1e4 x E: 6e-7..8e-2, median 2e-4) keep the refinement.
    real(dp), parameter :: refine_below_rcond = 1.0e-3_dp
    !> Info(UMFPACK_RCOND) (0-based in C): reciprocal condition estimate.
    integer, parameter :: umfpack_rcond = 67

    !> Status codes (umfpack.h).
    integer(c_int), parameter :: umfpack_ok = 0
    integer(c_int), parameter :: umfpack_warning_singular_matrix = 1
    integer(c_int), parameter :: umfpack_warning_determinant_underflow = 2
    integer(c_int), parameter :: umfpack_warning_determinant_overflow = 3
    integer(c_int), parameter :: umfpack_error_out_of_memory = -1
    integer(c_int), parameter :: umfpack_error_invalid_numeric_object = -3
    integer(c_int), parameter :: umfpack_error_invalid_symbolic_object = -4
    integer(c_int), parameter :: umfpack_error_argument_missing = -5
    integer(c_int), parameter :: umfpack_error_n_nonpositive = -6
    integer(c_int), parameter :: umfpack_error_invalid_matrix = -8
    integer(c_int), parameter :: umfpack_error_different_pattern = -11
    integer(c_int), parameter :: umfpack_error_invalid_system = -13
    integer(c_int), parameter :: umfpack_error_invalid_permutation = -15
    integer(c_int), parameter :: umfpack_error_file_io = -17
    integer(c_int), parameter :: umfpack_error_ordering_failed = -18
    integer(c_int), parameter :: umfpack_error_internal_error = -911

    !> LU factorization of a `csc_matrix_t`, with the symbolic analysis reused
    !> while the pattern is unchanged. Not copyable: assigning one `umfpack_t` to
    !> another leaves the target empty (it will factorize afresh), so two objects
    !> never free the same handle.
    type, extends(linear_solver_t) :: umfpack_t
        !> Number of symbolic analyses done so far (read only).
        integer :: n_symbolic = 0
        !> Number of successful numeric factorizations so far (read only).
        integer :: n_numeric = 0
        !> UMFPACK's reciprocal condition estimate of the last numeric
        !> factorization (read only; 0 when there is none).
        real(dp) :: rcond = 0.0_dp
        !> Use UMFPACK's 64-bit-index version (umfpack_dl_*). Set by `factorize`
        !> when the 32-bit version runs out of memory (its factors are indexed by
        !> 32-bit integers: about 1.7e6 DOFs of a 2D p = 2 mesh are too many) and
        !> kept from then on; may be set before the first factorization.
        logical :: wide = .false.
        type(c_ptr), private :: symbolic = c_null_ptr
        type(c_ptr), private :: numeric = c_null_ptr
        !> Pattern the symbolic analysis was computed for; shapes: [n+1], [nnz].
        integer, private :: n = 0
        integer(c_int), allocatable, private :: colptr(:), rowind(:)
        !> The same pattern with 64-bit indices (only when `wide`).
        integer(c_long), allocatable, private :: colptr_l(:), rowind_l(:)
    contains
        !> Symbolic analysis (when needed) and numeric LU of a matrix.
        procedure :: factor => umfpack_factorize
        !> Solve A x = b with the current factorization.
        procedure :: solve => umfpack_solve
        !> Sign and log10 magnitude of det(A) of the current factorization.
        procedure :: determinant => umfpack_determinant
        procedure :: has_determinant => umfpack_has_determinant
        procedure :: factorizations => umfpack_factorizations
        !> Free the Symbolic and Numeric objects; safe to call any number of times.
        procedure :: release => umfpack_release
        procedure, private :: assign => umfpack_assign
        generic :: assignment(=) => assign
        final :: umfpack_final
    end type umfpack_t

    interface
        subroutine umfpack_di_defaults(control) bind(c, name='umfpack_di_defaults')
            import :: c_double
            real(c_double), intent(out) :: control(*)
        end subroutine umfpack_di_defaults

        function umfpack_di_symbolic(n_row, n_col, ap, ai, ax, symbolic, control, info) &
            result(status) bind(c, name='umfpack_di_symbolic')
            import :: c_int, c_double, c_ptr
            integer(c_int), value :: n_row, n_col
            integer(c_int), intent(in) :: ap(*), ai(*)
            real(c_double), intent(in) :: ax(*)
            type(c_ptr), intent(out) :: symbolic
            real(c_double), intent(in) :: control(*)
            real(c_double), intent(out) :: info(*)
            integer(c_int) :: status
        end function umfpack_di_symbolic

        function umfpack_di_numeric(ap, ai, ax, symbolic, numeric, control, info) &
            result(status) bind(c, name='umfpack_di_numeric')
            import :: c_int, c_double, c_ptr
            integer(c_int), intent(in) :: ap(*), ai(*)
            real(c_double), intent(in) :: ax(*)
            type(c_ptr), value :: symbolic
            type(c_ptr), intent(out) :: numeric
            real(c_double), intent(in) :: control(*)
            real(c_double), intent(out) :: info(*)
            integer(c_int) :: status
        end function umfpack_di_numeric

        function umfpack_di_solve(sys, ap, ai, ax, x, b, numeric, control, info) &
            result(status) bind(c, name='umfpack_di_solve')
            import :: c_int, c_double, c_ptr
            integer(c_int), value :: sys
            integer(c_int), intent(in) :: ap(*), ai(*)
            real(c_double), intent(in) :: ax(*)
            real(c_double), intent(out) :: x(*)
            real(c_double), intent(in) :: b(*)
            type(c_ptr), value :: numeric
            real(c_double), intent(in) :: control(*)
            real(c_double), intent(out) :: info(*)
            integer(c_int) :: status
        end function umfpack_di_solve

        function umfpack_di_get_determinant(mx, ex, numeric, info) result(status) &
            bind(c, name='umfpack_di_get_determinant')
            import :: c_int, c_double, c_ptr
            real(c_double), intent(out) :: mx, ex
            type(c_ptr), value :: numeric
            real(c_double), intent(out) :: info(*)
            integer(c_int) :: status
        end function umfpack_di_get_determinant

        function umfpack_dl_symbolic(n_row, n_col, ap, ai, ax, symbolic, control, info) &
            result(status) bind(c, name='umfpack_dl_symbolic')
            import :: c_long, c_double, c_ptr
            integer(c_long), value :: n_row, n_col
            integer(c_long), intent(in) :: ap(*), ai(*)
            real(c_double), intent(in) :: ax(*)
            type(c_ptr), intent(out) :: symbolic
            real(c_double), intent(in) :: control(*)
            real(c_double), intent(out) :: info(*)
            integer(c_long) :: status
        end function umfpack_dl_symbolic

        function umfpack_dl_numeric(ap, ai, ax, symbolic, numeric, control, info) &
            result(status) bind(c, name='umfpack_dl_numeric')
            import :: c_long, c_double, c_ptr
            integer(c_long), intent(in) :: ap(*), ai(*)
            real(c_double), intent(in) :: ax(*)
            type(c_ptr), value :: symbolic
            type(c_ptr), intent(out) :: numeric
            real(c_double), intent(in) :: control(*)
            real(c_double), intent(out) :: info(*)
            integer(c_long) :: status
        end function umfpack_dl_numeric

        function umfpack_dl_solve(sys, ap, ai, ax, x, b, numeric, control, info) &
            result(status) bind(c, name='umfpack_dl_solve')
            import :: c_long, c_double, c_ptr
            integer(c_long), value :: sys
            integer(c_long), intent(in) :: ap(*), ai(*)
            real(c_double), intent(in) :: ax(*)
            real(c_double), intent(out) :: x(*)
            real(c_double), intent(in) :: b(*)
            type(c_ptr), value :: numeric
            real(c_double), intent(in) :: control(*)
            real(c_double), intent(out) :: info(*)
            integer(c_long) :: status
        end function umfpack_dl_solve

        function umfpack_dl_get_determinant(mx, ex, numeric, info) result(status) &
            bind(c, name='umfpack_dl_get_determinant')
            import :: c_long, c_double, c_ptr
            real(c_double), intent(out) :: mx, ex
            type(c_ptr), value :: numeric
            real(c_double), intent(out) :: info(*)
            integer(c_long) :: status
        end function umfpack_dl_get_determinant

        subroutine umfpack_dl_free_symbolic(symbolic) bind(c, name='umfpack_dl_free_symbolic')
            import :: c_ptr
            type(c_ptr), intent(inout) :: symbolic
        end subroutine umfpack_dl_free_symbolic

        subroutine umfpack_dl_free_numeric(numeric) bind(c, name='umfpack_dl_free_numeric')
            import :: c_ptr
            type(c_ptr), intent(inout) :: numeric
        end subroutine umfpack_dl_free_numeric

        subroutine umfpack_di_free_symbolic(symbolic) bind(c, name='umfpack_di_free_symbolic')
            import :: c_ptr
            type(c_ptr), intent(inout) :: symbolic
        end subroutine umfpack_di_free_symbolic

        subroutine umfpack_di_free_numeric(numeric) bind(c, name='umfpack_di_free_numeric')
            import :: c_ptr
            type(c_ptr), intent(inout) :: numeric
        end subroutine umfpack_di_free_numeric
    end interface

contains

    !> .true. when `real(dp)` is C's double, so `real(dp)` arrays pass to UMFPACK
    !> without conversion (a test checks it once).
    pure logical function dp_is_c_double()
        dp_is_c_double = dp == c_double
    end function dp_is_c_double

    !> LU-factorize `a`: symbolic analysis when there is none yet or `a`'s
    !> pattern (n, colptr, rowind) differs from the one it was computed for, then
    !> the numeric factorization (replacing the previous one). A singular matrix
    !> is an error (code `error_code%numeric`); afterwards the object holds no
    !> numeric factorization but keeps a valid symbolic one.
    subroutine umfpack_factorize(self, a, error)
        class(umfpack_t), intent(inout) :: self
        !> Matrix with a pattern from `new_csc_pattern`.
        type(csc_matrix_t), intent(in) :: a
        type(error_t), allocatable, intent(out) :: error
        real(c_double) :: control(umfpack_control), info(umfpack_info)
        integer(c_int) :: status

        call check_matrix(a, 'factorize', error)
        if (allocated(error)) return
        call umfpack_di_defaults(control)

        call free_numeric(self)
        do
            if (.not. c_associated(self%symbolic) .or. .not. same_pattern(self, a)) then
                call free_symbolic(self)
                if (self%wide) then
                    self%colptr_l = int(a%colptr, c_long)
                    self%rowind_l = int(a%rowind, c_long)
                    status = int(umfpack_dl_symbolic(int(a%n, c_long), int(a%n, c_long), self%colptr_l, &
                                                     self%rowind_l, a%values, self%symbolic, control, info), c_int)
                else
                    status = umfpack_di_symbolic(int(a%n, c_int), int(a%n, c_int), a%colptr, &
                                                 a%rowind, a%values, self%symbolic, control, info)
                end if
                if (status /= umfpack_ok) then
                    call free_symbolic(self)
                    call status_error(error, merge('umfpack_dl_symbolic', 'umfpack_di_symbolic', self%wide), &
                                      status)
                    return
                end if
                self%n = a%n
                self%colptr = a%colptr
                self%rowind = a%rowind
                self%n_symbolic = self%n_symbolic + 1
            end if
            if (self%wide) then
                status = int(umfpack_dl_numeric(self%colptr_l, self%rowind_l, a%values, self%symbolic, &
                                                self%numeric, control, info), c_int)
            else
                status = umfpack_di_numeric(a%colptr, a%rowind, a%values, self%symbolic, &
                                            self%numeric, control, info)
            end if
            if (status == umfpack_error_out_of_memory .and. .not. self%wide) then
                ! the 32-bit version cannot index factors this large: once more, 64-bit
                call free_numeric(self)
                call free_symbolic(self)
                self%wide = .true.
                cycle
            end if
            exit
        end do
        if (status /= umfpack_ok) then
            call free_numeric(self)
            call status_error(error, merge('umfpack_dl_numeric', 'umfpack_di_numeric', self%wide), status)
            return
        end if
        self%n_numeric = self%n_numeric + 1
        self%rcond = info(umfpack_rcond + 1)
    end subroutine umfpack_factorize

    !> Solve A x = b with the current numeric factorization. `a` must be the
    !> matrix last passed to `factorize` (UMFPACK uses it for iterative
    !> refinement, done only when rcond < `refine_below_rcond`); its pattern is
    !> checked, its values are not.
    subroutine umfpack_solve(self, a, b, x, error, accuracy)
        class(umfpack_t), intent(inout) :: self
        !> The factorized matrix.
        type(csc_matrix_t), intent(in) :: a
        !> Right-hand side; shape: [n].
        real(dp), intent(in) :: b(:)
        !> Solution; shape: [n].
        real(dp), intent(out) :: x(:)
        type(error_t), allocatable, intent(out) :: error
        !> Ignored: a direct solve is as accurate as the factorization.
        type(solve_accuracy_t), intent(in), optional :: accuracy
        real(c_double) :: control(umfpack_control), info(umfpack_info)
        integer(c_int) :: status

        if (.not. c_associated(self%numeric)) then
            call fatal_error(error, 'umfpack solve: no numeric factorization '// &
                             '(factorize was not called or failed)')
            return
        end if
        call check_matrix(a, 'solve', error)
        if (allocated(error)) return
        if (.not. same_pattern(self, a)) then
            call fatal_error(error, 'umfpack solve: the matrix pattern differs from '// &
                             'the factorized one')
            return
        end if
        if (size(b) /= a%n .or. size(x) /= a%n) then
            call fatal_error(error, 'umfpack solve: size(b) = '//str(size(b))//', size(x) = '// &
                             str(size(x))//', expected n = '//str(a%n))
            return
        end if
        call umfpack_di_defaults(control)
        if (self%rcond >= refine_below_rcond) control(umfpack_irstep + 1) = 0.0_c_double
        if (self%wide) then
            status = int(umfpack_dl_solve(int(umfpack_a, c_long), self%colptr_l, self%rowind_l, a%values, &
                                          x, b, self%numeric, control, info), c_int)
        else
            status = umfpack_di_solve(umfpack_a, a%colptr, a%rowind, a%values, x, b, &
                                      self%numeric, control, info)
        end if
        if (status /= umfpack_ok) then
            call status_error(error, merge('umfpack_dl_solve', 'umfpack_di_solve', self%wide), status)
            return
        end if
    end subroutine umfpack_solve

    !> det(A) = sign x 10**log10_abs of the current numeric factorization (UMFPACK
    !> returns it as mantissa and base-10 exponent, so it neither over- nor
    !> underflows). sign = 0 for a singular factorization.
    subroutine umfpack_determinant(self, sign, log10_abs, error)
        class(umfpack_t), intent(in) :: self
        integer, intent(out) :: sign
        real(dp), intent(out) :: log10_abs
        type(error_t), allocatable, intent(out) :: error
        real(c_double) :: mx, ex, info(umfpack_info)
        integer(c_int) :: status
        sign = 0
        log10_abs = -huge(1.0_dp)
        if (.not. c_associated(self%numeric)) then
            call fatal_error(error, 'umfpack determinant: no numeric factorization')
            return
        end if
        if (self%wide) then
            status = int(umfpack_dl_get_determinant(mx, ex, self%numeric, info), c_int)
        else
            status = umfpack_di_get_determinant(mx, ex, self%numeric, info)
        end if
        if (status < umfpack_ok) then
            call status_error(error, 'umfpack_di_get_determinant', status)
            return
        end if
        if (mx > 0.0_c_double) sign = 1
        if (mx < 0.0_c_double) sign = -1
        if (mx /= 0.0_c_double) log10_abs = log10(abs(mx)) + ex
    end subroutine umfpack_determinant

    !> A direct solver knows the sign of det(A).
    pure logical function umfpack_has_determinant(self)
        class(umfpack_t), intent(in) :: self
        umfpack_has_determinant = .true.
    end function umfpack_has_determinant

    !> Symbolic analyses and numeric factorizations so far.
    pure subroutine umfpack_factorizations(self, symbolic, numeric)
        class(umfpack_t), intent(in) :: self
        integer, intent(out) :: symbolic, numeric
        symbolic = self%n_symbolic
        numeric = self%n_numeric
    end subroutine umfpack_factorizations

    !> Free both UMFPACK objects and forget the pattern; the counters are kept.
    subroutine umfpack_release(self)
        class(umfpack_t), intent(inout) :: self
        call free_numeric(self)
        call free_symbolic(self)
    end subroutine umfpack_release

    !> Finalizer: frees what a forgotten `release` left.
    subroutine umfpack_final(self)
        type(umfpack_t), intent(inout) :: self
        call umfpack_release(self)
    end subroutine umfpack_final

    !> Defined assignment: handles are never copied (two owners would free them
    !> twice); the target is released and left empty with zero counters, except
    !> that `lu = lu` changes nothing.
    subroutine umfpack_assign(lhs, rhs)
        class(umfpack_t), intent(inout) :: lhs
        type(umfpack_t), intent(in) :: rhs
        if (c_associated(lhs%symbolic, rhs%symbolic)) return
        call umfpack_release(lhs)
        lhs%n_symbolic = 0
        lhs%n_numeric = 0
        lhs%rcond = 0.0_dp
    end subroutine umfpack_assign

    subroutine free_numeric(self)
        class(umfpack_t), intent(inout) :: self
        if (c_associated(self%numeric)) then
            if (self%wide) then
                call umfpack_dl_free_numeric(self%numeric)
            else
                call umfpack_di_free_numeric(self%numeric)
            end if
        end if
        self%numeric = c_null_ptr
        self%rcond = 0.0_dp
    end subroutine free_numeric

    subroutine free_symbolic(self)
        class(umfpack_t), intent(inout) :: self
        if (c_associated(self%symbolic)) then
            if (self%wide) then
                call umfpack_dl_free_symbolic(self%symbolic)
            else
                call umfpack_di_free_symbolic(self%symbolic)
            end if
        end if
        self%symbolic = c_null_ptr
        self%n = 0
        if (allocated(self%colptr)) deallocate (self%colptr)
        if (allocated(self%rowind)) deallocate (self%rowind)
        if (allocated(self%colptr_l)) deallocate (self%colptr_l)
        if (allocated(self%rowind_l)) deallocate (self%rowind_l)
    end subroutine free_symbolic

    !> Whether `a` has the pattern the symbolic analysis was computed for.
    pure logical function same_pattern(self, a)
        class(umfpack_t), intent(in) :: self
        type(csc_matrix_t), intent(in) :: a
        same_pattern = .false.
        if (.not. allocated(self%colptr) .or. .not. allocated(self%rowind)) return
        if (self%n /= a%n) return
        if (size(self%rowind) /= size(a%rowind)) return
        if (any(self%colptr /= a%colptr)) return
        if (any(self%rowind /= a%rowind)) return
        same_pattern = .true.
    end function same_pattern

    !> Refuse a matrix UMFPACK would read out of bounds.
    subroutine check_matrix(a, routine, error)
        type(csc_matrix_t), intent(in) :: a
        character(len=*), intent(in) :: routine
        type(error_t), allocatable, intent(out) :: error
        if (a%n < 1) then
            call fatal_error(error, 'umfpack '//routine//': empty matrix (n < 1)')
        else if (.not. (allocated(a%colptr) .and. allocated(a%rowind) &
                        .and. allocated(a%values))) then
            call fatal_error(error, 'umfpack '//routine//': matrix has no pattern '// &
                             '(build it with new_csc_pattern)')
        else if (size(a%colptr) /= a%n + 1) then
            call fatal_error(error, 'umfpack '//routine//': size(colptr) /= n + 1')
        else if (size(a%rowind) < a%colptr(a%n + 1) .or. size(a%values) < a%colptr(a%n + 1)) then
            call fatal_error(error, 'umfpack '//routine//': rowind or values shorter than nnz')
        end if
    end subroutine check_matrix

    !> Error naming the routine and the meaning of a non-OK status; code `numeric`
    !> (the load step may be cut) except for running out of memory (generic: the run
    !> ends, a smaller increment needs as much memory).
    subroutine status_error(error, routine, status)
        type(error_t), allocatable, intent(out) :: error
        character(len=*), intent(in) :: routine
        integer(c_int), intent(in) :: status
        character(len=:), allocatable :: num

        num = str(int(status))
        if (status == umfpack_error_out_of_memory) then
            ! not a numerical failure: a smaller increment would not need less memory
            call fatal_error(error, routine//' failed: '//status_meaning(status)// &
                             ' (UMFPACK status '//trim(num)//'): the LU factors of the '// &
                             'stiffness matrix need more memory than the machine gave UMFPACK; '// &
                             'a coarser mesh or a lower degree needs less')
        else
            call fatal_error(error, routine//' failed: '//status_meaning(status)// &
                             ' (UMFPACK status '//trim(num)//')', error_code%numeric)
        end if
    end subroutine status_error

    !> Meaning of an UMFPACK status code (umfpack.h names).
    pure function status_meaning(status) result(text)
        integer(c_int), intent(in) :: status
        character(len=:), allocatable :: text
        select case (status)
        case (umfpack_ok)
            text = 'no error (UMFPACK_OK)'
        case (umfpack_warning_singular_matrix)
            text = 'singular stiffness matrix (UMFPACK_WARNING_singular_matrix)'
        case (umfpack_warning_determinant_underflow)
            text = 'determinant underflow (UMFPACK_WARNING_determinant_underflow)'
        case (umfpack_warning_determinant_overflow)
            text = 'determinant overflow (UMFPACK_WARNING_determinant_overflow)'
        case (umfpack_error_out_of_memory)
            text = 'out of memory (UMFPACK_ERROR_out_of_memory)'
        case (umfpack_error_invalid_numeric_object)
            text = 'invalid Numeric object (UMFPACK_ERROR_invalid_Numeric_object)'
        case (umfpack_error_invalid_symbolic_object)
            text = 'invalid Symbolic object (UMFPACK_ERROR_invalid_Symbolic_object)'
        case (umfpack_error_argument_missing)
            text = 'a required argument is missing (UMFPACK_ERROR_argument_missing)'
        case (umfpack_error_n_nonpositive)
            text = 'matrix dimension is not positive (UMFPACK_ERROR_n_nonpositive)'
        case (umfpack_error_invalid_matrix)
            text = 'invalid matrix: column pointers or row indices are not a valid, '// &
                   'sorted CSC pattern (UMFPACK_ERROR_invalid_matrix)'
        case (umfpack_error_different_pattern)
            text = 'the pattern changed since the symbolic analysis '// &
                   '(UMFPACK_ERROR_different_pattern)'
        case (umfpack_error_invalid_system)
            text = 'invalid system (UMFPACK_ERROR_invalid_system)'
        case (umfpack_error_invalid_permutation)
            text = 'invalid permutation (UMFPACK_ERROR_invalid_permutation)'
        case (umfpack_error_file_io)
            text = 'file I/O error (UMFPACK_ERROR_file_IO)'
        case (umfpack_error_ordering_failed)
            text = 'fill-reducing ordering failed (UMFPACK_ERROR_ordering_failed)'
        case (umfpack_error_internal_error)
            text = 'internal error (UMFPACK_ERROR_internal_error)'
        case default
            text = 'unknown status'
        end select
    end function status_meaning

end module voiga_solver_umfpack
