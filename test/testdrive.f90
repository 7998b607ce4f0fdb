!> A small test harness in the shape of test-drive: a suite is a list of
!> `unittest_t` built by a `collect_<suite>` routine; a test is a
!> `subroutine t(error)` that allocates `error` on failure via `check`.
module voiga_testdrive
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error
    implicit none
    private

    public :: unittest_t, testsuite_t, new_unittest, new_testsuite, test_interface
    public :: collect_interface, run_testsuite, check, test_failed

    abstract interface
        !> A single test: allocate `error` to fail.
        subroutine test_interface(error)
            import :: error_t
            type(error_t), allocatable, intent(out) :: error
        end subroutine test_interface
    end interface

    !> One named test.
    type :: unittest_t
        character(len=:), allocatable :: name
        procedure(test_interface), pointer, nopass :: test => null()
    end type unittest_t

    abstract interface
        !> Fill `testsuite` with the tests of a suite.
        subroutine collect_interface(testsuite)
            import :: unittest_t
            type(unittest_t), allocatable, intent(out) :: testsuite(:)
        end subroutine collect_interface
    end interface

    !> One named suite.
    type :: testsuite_t
        character(len=:), allocatable :: name
        procedure(collect_interface), pointer, nopass :: collect => null()
    end type testsuite_t

    !> Compare values; `rel`/`abs` tolerances for reals: pass when
    !> |a - b| <= max(abs, rel*|b|).
    interface check
        module procedure :: check_logical
        module procedure :: check_int
        module procedure :: check_real
        module procedure :: check_real_array
        module procedure :: check_string
    end interface check

contains

    !> Build a test entry.
    function new_unittest(name, test) result(self)
        character(len=*), intent(in) :: name
        procedure(test_interface) :: test
        type(unittest_t) :: self
        self%name = name
        self%test => test
    end function new_unittest

    !> Build a suite entry.
    function new_testsuite(name, collect) result(self)
        character(len=*), intent(in) :: name
        procedure(collect_interface) :: collect
        type(testsuite_t) :: self
        self%name = name
        self%collect => collect
    end function new_testsuite

    !> Run every test of a suite, printing one line per test; count results.
    subroutine run_testsuite(suite, filter, npass, nfail)
        type(testsuite_t), intent(in) :: suite
        !> Run only tests whose name contains this (empty: all).
        character(len=*), intent(in) :: filter
        integer, intent(inout) :: npass, nfail
        type(unittest_t), allocatable :: tests(:)
        type(error_t), allocatable :: error
        integer :: i

        call suite%collect(tests)
        do i = 1, size(tests)
            if (len_trim(filter) > 0) then
                if (index(suite%name//'/'//tests(i)%name, trim(filter)) == 0) cycle
            end if
            call tests(i)%test(error)
            if (allocated(error)) then
                nfail = nfail + 1
                write (*, '(a)') '  FAIL  '//suite%name//'/'//tests(i)%name
                write (*, '(a)') '        '//error%message
                deallocate (error)
            else
                npass = npass + 1
                write (*, '(a)') '  ok    '//suite%name//'/'//tests(i)%name
            end if
        end do
    end subroutine run_testsuite

    !> Fail unconditionally with a message.
    subroutine test_failed(error, message)
        type(error_t), allocatable, intent(out) :: error
        character(len=*), intent(in) :: message
        call fatal_error(error, message)
    end subroutine test_failed

    subroutine check_logical(error, condition, message)
        type(error_t), allocatable, intent(out) :: error
        logical, intent(in) :: condition
        character(len=*), intent(in) :: message
        if (.not. condition) call fatal_error(error, 'check failed: '//message)
    end subroutine check_logical

    subroutine check_int(error, actual, expected, message)
        type(error_t), allocatable, intent(out) :: error
        integer, intent(in) :: actual, expected
        character(len=*), intent(in) :: message
        character(len=64) :: buf
        if (actual /= expected) then
            write (buf, '(a,i0,a,i0)') 'got ', actual, ', expected ', expected
            call fatal_error(error, message//': '//trim(buf))
        end if
    end subroutine check_int

    subroutine check_string(error, actual, expected, message)
        type(error_t), allocatable, intent(out) :: error
        character(len=*), intent(in) :: actual, expected
        character(len=*), intent(in) :: message
        if (actual /= expected) then
            call fatal_error(error, message//": got '"//actual//"', expected '"//expected//"'")
        end if
    end subroutine check_string

    subroutine check_real(error, actual, expected, message, rel, abs)
        type(error_t), allocatable, intent(out) :: error
        real(dp), intent(in) :: actual, expected
        character(len=*), intent(in) :: message
        real(dp), intent(in), optional :: rel, abs
        real(dp) :: tol
        character(len=128) :: buf

        tol = tolerance(expected, rel, abs)
        if (.not. (ieee_abs(actual - expected) <= tol)) then
            write (buf, '(a,es23.15,a,es23.15,a,es9.2)') 'got ', actual, ', expected ', &
                expected, ', tol ', tol
            call fatal_error(error, message//': '//trim(buf))
        end if
    end subroutine check_real

    subroutine check_real_array(error, actual, expected, message, rel, abs)
        type(error_t), allocatable, intent(out) :: error
        real(dp), intent(in) :: actual(:), expected(:)
        character(len=*), intent(in) :: message
        real(dp), intent(in), optional :: rel, abs
        integer :: i
        character(len=160) :: buf

        if (size(actual) /= size(expected)) then
            write (buf, '(a,i0,a,i0)') 'size ', size(actual), ' /= ', size(expected)
            call fatal_error(error, message//': '//trim(buf))
            return
        end if
        do i = 1, size(actual)
            if (.not. (ieee_abs(actual(i) - expected(i)) <= tolerance(expected(i), rel, abs))) then
                write (buf, '(a,i0,a,es23.15,a,es23.15)') 'entry ', i, ': got ', actual(i), &
                    ', expected ', expected(i)
                call fatal_error(error, message//': '//trim(buf))
                return
            end if
        end do
    end subroutine check_real_array

    pure real(dp) function tolerance(expected, rel, abs) result(tol)
        real(dp), intent(in) :: expected
        real(dp), intent(in), optional :: rel, abs
        tol = 0.0_dp
        if (present(abs)) tol = abs
        if (present(rel)) tol = max(tol, rel*ieee_abs(expected))
        if (.not. present(rel) .and. .not. present(abs)) tol = 10*epsilon(1.0_dp)*ieee_abs(expected)
    end function tolerance

    pure elemental real(dp) function ieee_abs(x)
        real(dp), intent(in) :: x
        ieee_abs = merge(x, -x, x >= 0.0_dp)
    end function ieee_abs

end module voiga_testdrive
