!> The process's side of the operating system (Linux, glibc): the memory it may
!> use (/proc/meminfo, /proc/self/status, `getrlimit`), the file-size limit, leaving
!> without exit handlers, running itself again, and SIGXFSZ.
!>
!> The raw libc interfaces are private. The calls that need the system's constants
!> (RLIMIT_AS, RLIMIT_FSIZE, RLIM_INFINITY, SIGXFSZ, SIG_IGN, STDOUT_FILENO) or its
!> `struct rlimit` are in libc.c, which includes the system headers.
module voiga_platform_process
    use, intrinsic :: iso_c_binding, only: c_int, c_char, c_ptr, c_null_ptr, c_null_char, c_loc, &
                                           c_int64_t
    use, intrinsic :: iso_fortran_env, only: int64, output_unit, error_unit
    use voiga_platform_os, only: c_str
    implicit none
    private

    public :: memory_available, address_space_limited, write_failure_cause, leave
    public :: reexec_with_environment, ignore_file_size_signal, stdout_is_terminal

    interface
        !> The soft limits (bytes; -1 when unlimited or unknown) of `ulimit -v` and
        !> `ulimit -f` (libc.c).
        function c_address_space_limit() bind(c, name='voiga_address_space_limit') result(bytes)
            import :: c_int64_t
            integer(c_int64_t) :: bytes
        end function c_address_space_limit
        function c_file_size_limit() bind(c, name='voiga_file_size_limit') result(bytes)
            import :: c_int64_t
            integer(c_int64_t) :: bytes
        end function c_file_size_limit
        subroutine c_exit_now(status) bind(c, name='_exit')
            import :: c_int
            integer(c_int), value :: status
        end subroutine c_exit_now
        function c_setenv(name, value, overwrite) bind(c, name='setenv') result(st)
            import :: c_char, c_int
            character(kind=c_char), intent(in) :: name(*), value(*)
            integer(c_int), value :: overwrite
            integer(c_int) :: st
        end function c_setenv
        subroutine c_ignore_file_size_signal() bind(c, name='voiga_ignore_file_size_signal')
        end subroutine c_ignore_file_size_signal
        function c_stdout_is_terminal() bind(c, name='voiga_stdout_is_terminal') result(yes)
            import :: c_int
            integer(c_int) :: yes
        end function c_stdout_is_terminal
        function c_execv(path, argv) bind(c, name='execv') result(st)
            import :: c_char, c_ptr, c_int
            character(kind=c_char), intent(in) :: path(*)
            type(c_ptr), intent(in) :: argv(*)
            integer(c_int) :: st
        end function c_execv
    end interface

contains

    !> The memory this process may still use (bytes): `physical`, the system's
    !> available memory (/proc/meminfo MemAvailable), and `address`, what the
    !> address-space limit (`ulimit -v`) leaves beside the address space in use
    !> (/proc/self/status VmSize); -1 when unknown or unlimited.
    subroutine memory_available(physical, address)
        integer(int64), intent(out) :: physical, address
        integer(int64) :: limit
        physical = proc_value('/proc/meminfo', 'MemAvailable:')
        address = -1
        limit = c_address_space_limit()
        if (limit > 0) &
            address = max(limit - max(proc_value('/proc/self/status', 'VmSize:'), 0_int64), 0_int64)
    end subroutine memory_available

    !> Is the address space of this process limited (`ulimit -v`)?
    logical function address_space_limited()
        address_space_limited = c_address_space_limit() >= 0
    end function address_space_limited

    !> The value in bytes of the line `key  <n> kB` of a /proc file; -1 if absent.
    function proc_value(path, key) result(bytes)
        character(len=*), intent(in) :: path, key
        integer(int64) :: bytes
        character(len=256) :: line
        integer :: u, ios
        bytes = -1
        open (newunit=u, file=path, status='old', action='read', iostat=ios)
        if (ios /= 0) return
        do
            read (u, '(a)', iostat=ios) line
            if (ios /= 0) exit
            if (index(line, key) /= 1) cycle
            read (line(len(key) + 1:), *, iostat=ios) bytes
            if (ios /= 0) bytes = -1
            if (bytes >= 0) bytes = bytes*1024_int64
            exit
        end do
        close (u)
    end function proc_value

    !> Why a write to `path` may have failed, as ' (...)' for a message: the
    !> file-size limit (`ulimit -f`) when the file has reached it, else a full disk.
    function write_failure_cause(path) result(text)
        character(len=*), intent(in) :: path
        character(len=:), allocatable :: text
        integer(int64) :: limit, size
        character(len=24) :: buf
        text = ' (is the disk full?)'
        limit = c_file_size_limit()
        if (limit < 0) return
        inquire (file=path, size=size)
        if (size + 1048576_int64 < limit) return
        write (buf, '(i0)') limit
        text = ' (the file-size limit, ulimit -f, of '//trim(buf)//' bytes is reached)'
    end function write_failure_cause

    !> End the process at once with exit code `code` after flushing standard output
    !> and error: no exit handler runs (HDF5's would write a half-written step of a
    !> result file whose writing failed over the steps already on disk).
    subroutine leave(code)
        integer, intent(in) :: code
        flush (output_unit)
        flush (error_unit)
        call c_exit_now(int(code, c_int))
    end subroutine leave

    !> A write beyond the file-size limit (`ulimit -f`, a quota of sorts) fails
    !> with EFBIG like one on a full disk, instead of killing the process with
    !> SIGXFSZ (whose default action the gfortran runtime also takes over).
    subroutine ignore_file_size_signal()
        call c_ignore_file_size_signal()
    end subroutine ignore_file_size_signal

    !> Run this program again, from the start and with the same arguments, with
    !> the environment variable `name` set to `value`; returns only if that fails.
    subroutine reexec_with_environment(name, value)
        character(len=*), intent(in) :: name, value
        character(kind=c_char, len=:), allocatable, target :: args(:)
        type(c_ptr), allocatable :: argv(:)
        integer :: i, n, length, width
        integer(c_int) :: st

        n = command_argument_count()
        width = 1
        do i = 0, n
            call get_command_argument(i, length=length)
            width = max(width, length + 1)
        end do
        allocate (character(kind=c_char, len=width) :: args(0:n))
        allocate (argv(0:n + 1))
        do i = 0, n
            call get_command_argument(i, length=length)
            call get_command_argument(i, args(i))
            args(i)(length + 1:length + 1) = c_null_char
            argv(i) = c_loc(args(i))
        end do
        argv(n + 1) = c_null_ptr
        if (c_setenv(c_str(name), c_str(value), 1_c_int) /= 0) return
        flush (output_unit)
        flush (error_unit)
        st = c_execv(c_str('/proc/self/exe'), argv)
    end subroutine reexec_with_environment

    !> Whether the standard output is a terminal (`isatty(1)`): only there does a run
    !> show a live progress line (a pipe or a file gets whole lines only).
    logical function stdout_is_terminal() result(yes)
        yes = c_stdout_is_terminal() == 1_c_int
    end function stdout_is_terminal

end module voiga_platform_process
