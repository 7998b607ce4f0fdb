!> SIGINT and SIGTERM as a polled flag: the handler (installed by the program
!> with `catch_signals`) only records the signal; the solver polls
!> `caught_signal()` between Newton iterations and load steps and stops there,
!> so a result file is never left in the middle of a write.
!>
!> The handler and its flag are in libc.c: a handler has no argument through which
!> it could reach the caller's state, so the flag lives beside it, a C
!> `volatile sig_atomic_t` (the one type the C standard lets a handler write), and
!> the signal numbers come from `<signal.h>`. No Fortran module variable changes.
module voiga_platform_signals
    use, intrinsic :: iso_c_binding, only: c_int
    use voiga_text, only: str
    implicit none
    private

    public :: catch_signals, caught_signal, clear_signal, signal_name

    interface
        subroutine c_catch_signals() bind(c, name='voiga_catch_signals')
        end subroutine c_catch_signals
        function c_caught_signal() bind(c, name='voiga_caught_signal') result(signum)
            import :: c_int
            integer(c_int) :: signum
        end function c_caught_signal
        subroutine c_clear_signal() bind(c, name='voiga_clear_signal')
        end subroutine c_clear_signal
        function c_sigint() bind(c, name='voiga_sigint') result(signum)
            import :: c_int
            integer(c_int) :: signum
        end function c_sigint
        function c_sigterm() bind(c, name='voiga_sigterm') result(signum)
            import :: c_int
            integer(c_int) :: signum
        end function c_sigterm
    end interface

contains

    !> Route SIGINT and SIGTERM to the flag. The handler restores the default
    !> action when it runs, so that a second Ctrl-C ends a run stuck in a long
    !> factorization at once.
    subroutine catch_signals()
        call c_catch_signals()
    end subroutine catch_signals

    !> The signal caught since the start or the last `clear_signal` (0: none).
    integer function caught_signal()
        caught_signal = int(c_caught_signal())
    end function caught_signal

    !> Forget a caught signal.
    subroutine clear_signal()
        call c_clear_signal()
    end subroutine clear_signal

    !> 'SIGINT', 'SIGTERM' or 'signal <n>'.
    function signal_name(signum) result(name)
        integer, intent(in) :: signum
        character(len=:), allocatable :: name
        if (signum == c_sigint()) then
            name = 'SIGINT'
        else if (signum == c_sigterm()) then
            name = 'SIGTERM'
        else
            name = 'signal '//str(signum)
        end if
    end function signal_name

end module voiga_platform_signals
