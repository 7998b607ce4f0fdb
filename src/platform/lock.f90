!> Locks on files: the writer's lock file of a result or a dump, and the `flock` a
!> writer holds on the file itself while it writes (readers that take a shared one
!> wait).
!>
!> A lock file is a file this process created (exclusively, never through a link)
!> and holds by its descriptor (`flock`, released by the kernel when the process
!> dies), holding our process id. A lock file that nobody holds is one a killed
!> run left: it is removed and created anew, but only when it is one (a regular
!> file with one name holding a process id); anything else at its name (a link, a
!> FIFO, a device, a second name of another file, other content) is never opened
!> for writing, never truncated and never removed: the run is refused naming it.
module voiga_platform_lock
    use, intrinsic :: iso_c_binding, only: c_int
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_platform_os, only: file_info_t, fd_status, names_file, kind_name, what_is, &
                                 create_new, open_regular, close_fd, lock_fd, write_text, &
                                 read_text, remove_file, strerror, kind_missing, kind_regular
    implicit none
    private

    public :: lock_t, acquire_lock, release_lock, lock_intact, hold_file, let_go_file

    !> A lock file held by this process.
    type :: lock_t
        integer(c_int) :: fd = -1
        !> The lock file, and the file it was when taken (its name must keep naming
        !> it: `lock_intact`).
        character(len=:), allocatable :: path
        type(file_info_t) :: id
    end type lock_t

    !> Tries before giving up when other processes keep creating and removing the
    !> lock file between our steps.
    integer, parameter :: attempts = 8

    interface
        function c_getpid() bind(c, name='getpid') result(pid)
            import :: c_int
            integer(c_int) :: pid
        end function c_getpid
    end interface

contains

    !> Take the lock file `path` for this process, without waiting: a lock another
    !> process holds is an error naming its process id; a lock file a killed run
    !> left is replaced; anything else at the name is refused, untouched.
    subroutine acquire_lock(lock, path, what, error)
        type(lock_t), intent(inout) :: lock
        character(len=*), intent(in) :: path
        !> What the lock guards, for messages ("result file 'out.h5'").
        character(len=*), intent(in) :: what
        type(error_t), allocatable, intent(out) :: error
        integer(c_int) :: fd
        integer :: attempt, e
        character(len=24) :: pid
        logical :: exists

        do attempt = 1, attempts
            call create_new(path, fd, e, exists)
            if (fd >= 0) then
                ! another process may have opened our new file and taken its flock
                ! (as a lock left by a killed run): it wins, we look again
                if (lock_fd(fd, 'exclusive', .false.) == 0 .and. names_file(path, fd_status(fd))) then
                    write (pid, '(i0)') c_getpid()
                    e = write_text(fd, trim(pid)//new_line('a'))
                    lock%fd = fd
                    lock%path = path
                    lock%id = fd_status(fd)
                    return
                end if
                call close_fd(fd)
                cycle
            end if
            if (.not. exists) then
                call fatal_error(error, "cannot create the lock file '"//path//"' for "//what//': '// &
                                 strerror(e), error_code%input)
                return
            end if
            call take_over(path, what, error)
            if (allocated(error)) return
        end do
        call fatal_error(error, "cannot take the lock file '"//path//"' for "//what// &
                         ' (other processes keep creating and removing it)', error_code%input)
    end subroutine acquire_lock

    !> An existing lock file `path`: refused (`error`) when another process holds
    !> it or it is not a lock file of ours; removed when a killed run left it (the
    !> caller creates it again), left alone when it went away meanwhile.
    subroutine take_over(path, what, error)
        character(len=*), intent(in) :: path, what
        type(error_t), allocatable, intent(out) :: error
        type(file_info_t) :: info
        integer(c_int) :: fd
        integer :: kind, e, st
        character(len=:), allocatable :: holder

        call open_regular(path, .false., .false., fd, kind, e)
        if (fd < 0) then
            if (kind == kind_missing) return
            if (kind /= kind_regular) then
                call fatal_error(error, "the lock file '"//path//"' for "//what//' is '//kind_name(kind)// &
                                 ', not a lock file of voiga: nothing was written; remove it', error_code%input)
            else
                call fatal_error(error, "cannot open the lock file '"//path//"' for "//what//': '// &
                                 strerror(e), error_code%input)
            end if
            return
        end if
        info = fd_status(fd)
        st = lock_fd(fd, 'exclusive', .false.)
        if (st /= 0) then
            holder = trim(adjustl(first_line(read_text(fd, 64))))
            call close_fd(fd)
            if (st == 1) then
                if (len(holder) > 0) holder = ' (process '//holder//')'
                call fatal_error(error, what//' is being written by another voiga run'//holder// &
                                 '; lock file '//path, error_code%input)
            else
                call fatal_error(error, "cannot lock '"//path//"' for "//what//': '//strerror(-st), &
                                 error_code%input)
            end if
            return
        end if
        ! nobody holds it: its run was killed, if it is a lock file of ours
        if (.not. names_file(path, info)) then
            call close_fd(fd)
            return
        end if
        if (info%links /= 1 .or. info%size > 32 .or. .not. holds_a_pid(read_text(fd, 32))) then
            call close_fd(fd)
            if (info%links /= 1) then
                call fatal_error(error, "the lock file '"//path//"' for "//what//' is '//what_is(info)// &
                                 ', not a lock file of voiga: nothing was written; remove it', error_code%input)
            else
                call fatal_error(error, "the lock file '"//path//"' for "//what//' holds something else than '// &
                                 'a process id: not a lock file of voiga; nothing was written; remove it', &
                                 error_code%input)
            end if
            return
        end if
        call remove_file(path)
        call close_fd(fd)
    end subroutine take_over

    !> The text up to the first new line.
    pure function first_line(text) result(line)
        character(len=*), intent(in) :: text
        character(len=:), allocatable :: line
        integer :: i
        i = index(text, new_line('a'))
        if (i == 0) i = len(text) + 1
        line = text(1:i - 1)
    end function first_line

    !> Is `text` what a lock file of ours holds: a process id and a new line, or
    !> nothing (a run killed before it wrote its id)?
    pure logical function holds_a_pid(text)
        character(len=*), intent(in) :: text
        character(len=:), allocatable :: digits
        digits = trim(adjustl(first_line(text)))
        holds_a_pid = verify(digits, '0123456789') == 0 .and. len(text) <= len(first_line(text)) + 1
    end function holds_a_pid

    !> Does the lock file's name still name the file we hold? (Not when it was
    !> removed or replaced: another run may have taken the lock since.)
    logical function lock_intact(lock)
        type(lock_t), intent(in) :: lock
        lock_intact = .false.
        if (lock%fd < 0 .or. .not. allocated(lock%path)) return
        lock_intact = names_file(lock%path, lock%id)
    end function lock_intact

    !> Let go of a lock; its lock file is removed first (while held), when its name
    !> still names it (another run's lock file is left alone).
    subroutine release_lock(lock)
        type(lock_t), intent(inout) :: lock
        if (lock%fd < 0) return
        if (lock_intact(lock)) call remove_file(lock%path)
        call close_fd(lock%fd)
    end subroutine release_lock

    !> Hold an exclusive `flock` on the open file `fd` (readers that take a shared
    !> one wait), waiting at most `seconds`; `held` tells whether it was taken (not
    !> when a reader kept its lock that long, or the file system has no locks).
    !> Released by `let_go_file`.
    subroutine hold_file(fd, seconds, held)
        integer(c_int), intent(in) :: fd
        real, intent(in) :: seconds
        logical, intent(out) :: held
        integer :: waited_ms, st
        waited_ms = 0
        do
            st = lock_fd(fd, 'exclusive', .false.)
            held = st == 0
            if (st /= 1 .or. waited_ms >= int(1000*seconds)) return
            call sleep_ms(10)
            waited_ms = waited_ms + 10
        end do
    end subroutine hold_file

    !> Release the `flock` `hold_file` took (the file stays open).
    subroutine let_go_file(fd)
        integer(c_int), intent(in) :: fd
        integer :: st
        if (fd >= 0) st = lock_fd(fd, 'release', .false.)
    end subroutine let_go_file

    subroutine sleep_ms(ms)
        integer, intent(in) :: ms
        interface
            function c_usleep(usec) bind(c, name='usleep') result(st)
                import :: c_int
                integer(c_int), value :: usec
                integer(c_int) :: st
            end function c_usleep
        end interface
        integer(c_int) :: st
        st = c_usleep(int(1000*ms, c_int))
    end subroutine sleep_ms

end module voiga_platform_lock
