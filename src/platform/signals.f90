!> SIGINT and SIGTERM as a polled flag: the handler (installed by the program
!> with `catch_signals`) only records the signal; the solver polls
!> `caught_signal()` between Newton iterations and load steps and stops there,
!> so a result file is never left in the middle of a write.
!>
!> The flag is the one mutable module variable of the library: a signal handler
!> has no argument through which it could reach the caller's state. It is
!> `volatile` (set asynchronously) and `protected` (only the handler and
!> `clear_signal` change it).
module voiga_platform_signals
    use, intrinsic :: iso_c_binding, only: c_int, c_funptr, c_funloc, c_null_funptr
    use voiga_text, only: str
    implicit none
    private

    public :: catch_signals, caught_signal, clear_signal, signal_name, sigint, sigterm

    !> Linux signal numbers.
    integer(c_int), parameter :: sigint = 2_c_int, sigterm = 15_c_int

    !> The last signal caught (0: none).
    integer(c_int), volatile, protected :: caught = 0_c_int

    interface
        !> libc `sighandler_t signal(int signum, sighandler_t handler)`.
        function c_signal(signum, handler) bind(c, name='signal') result(previous)
            import :: c_int, c_funptr
            integer(c_int), value :: signum
            type(c_funptr), value :: handler
            type(c_funptr) :: previous
        end function c_signal
    end interface

contains

    !> Route SIGINT and SIGTERM to the flag.
    subroutine catch_signals()
        type(c_funptr) :: previous
        previous = c_signal(sigint, c_funloc(on_signal))
        previous = c_signal(sigterm, c_funloc(on_signal))
    end subroutine catch_signals

    !> The handler: record the signal and restore the default action (SIG_DFL is
    !> the null pointer), so that a second Ctrl-C ends a run stuck in a long
    !> factorization at once. Both are async-signal safe.
    subroutine on_signal(signum) bind(c)
        integer(c_int), value :: signum
        type(c_funptr) :: previous
        caught = signum
        previous = c_signal(signum, c_null_funptr)
    end subroutine on_signal

    !> The signal caught since the start or the last `clear_signal` (0: none).
    integer function caught_signal()
        caught_signal = int(caught)
    end function caught_signal

    !> Forget a caught signal.
    subroutine clear_signal()
        caught = 0_c_int
    end subroutine clear_signal

    !> 'SIGINT', 'SIGTERM' or 'signal <n>'.
    pure function signal_name(signum) result(name)
        integer, intent(in) :: signum
        character(len=:), allocatable :: name
        select case (signum)
        case (sigint)
            name = 'SIGINT'
        case (sigterm)
            name = 'SIGTERM'
        case default
            name = 'signal '//str(signum)
        end select
    end function signal_name

end module voiga_platform_signals
