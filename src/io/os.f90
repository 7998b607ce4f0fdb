!> The operating-system calls of the file layer (Linux, glibc): canonical paths,
!> rename and remove, advisory locks (`flock`) and space reserved for a write
!> (`fallocate`). The process's own limits are `voiga_io_process`'s.
!>
!> The raw libc interfaces are private. The constants are Linux's (asm-generic,
!> x86-64 and arm64): `open` flags O_RDONLY 0, O_WRONLY 1, O_RDWR 2, O_CREAT 64,
!> O_CLOEXEC 524288, O_DIRECTORY 65536; `flock` LOCK_SH 1, LOCK_EX 2, LOCK_NB 4,
!> LOCK_UN 8; `fallocate` FALLOC_FL_KEEP_SIZE 1; errno EINTR 4, ENOENT 2,
!> EWOULDBLOCK 11, EOPNOTSUPP 95.
module voiga_io_os
    use, intrinsic :: iso_c_binding, only: c_int, c_char, c_ptr, c_null_ptr, c_null_char, c_long, &
                                           c_size_t, c_associated, c_f_pointer, c_int64_t
    use, intrinsic :: iso_fortran_env, only: int64
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_io_sha256, only: sha256_text
    use voiga_kinds, only: dp
    use voiga_text, only: fixed_str
    implicit none
    private

    public :: canonical_path, rename_file, remove_file, path_exists, is_directory, companion
    public :: lock_t, acquire_lock, release_lock, hold_exclusive, hold_shared, let_go
    public :: reserve_space, release_space, c_str

    integer(c_int), parameter :: o_rdonly = 0, o_wronly = 1, o_rdwr = 2, o_creat = 64, &
                                 o_cloexec = 524288
    integer(c_int), parameter :: lock_sh = 1, lock_ex = 2, lock_nb = 4, lock_un = 8
    integer(c_int), parameter :: falloc_fl_keep_size = 1
    integer(c_int), parameter :: eintr = 4, enoent = 2, ewouldblock = 11, eopnotsupp = 95

    !> A lock held on a file (`flock` on an open descriptor; released when the
    !> descriptor is closed, also by the kernel when the process dies).
    type :: lock_t
        integer(c_int) :: fd = -1
        !> The lock file, when the lock owns one (removed on release).
        character(len=:), allocatable :: path
    end type lock_t

    interface
        function c_realpath(path, resolved) bind(c, name='realpath') result(p)
            import :: c_char, c_ptr
            character(kind=c_char), intent(in) :: path(*)
            type(c_ptr), value :: resolved
            type(c_ptr) :: p
        end function c_realpath
        subroutine c_free(p) bind(c, name='free')
            import :: c_ptr
            type(c_ptr), value :: p
        end subroutine c_free
        function c_strlen(s) bind(c, name='strlen') result(n)
            import :: c_ptr, c_size_t
            type(c_ptr), value :: s
            integer(c_size_t) :: n
        end function c_strlen
        function c_strerror(errnum) bind(c, name='strerror') result(p)
            import :: c_int, c_ptr
            integer(c_int), value :: errnum
            type(c_ptr) :: p
        end function c_strerror
        function c_errno_location() bind(c, name='__errno_location') result(p)
            import :: c_ptr
            type(c_ptr) :: p
        end function c_errno_location
        function c_rename(from, to) bind(c, name='rename') result(st)
            import :: c_char, c_int
            character(kind=c_char), intent(in) :: from(*), to(*)
            integer(c_int) :: st
        end function c_rename
        function c_unlink(path) bind(c, name='unlink') result(st)
            import :: c_char, c_int
            character(kind=c_char), intent(in) :: path(*)
            integer(c_int) :: st
        end function c_unlink
        function c_open(path, flags, mode) bind(c, name='open') result(fd)
            import :: c_char, c_int
            character(kind=c_char), intent(in) :: path(*)
            integer(c_int), value :: flags, mode
            integer(c_int) :: fd
        end function c_open
        function c_close(fd) bind(c, name='close') result(st)
            import :: c_int
            integer(c_int), value :: fd
            integer(c_int) :: st
        end function c_close
        function c_flock(fd, op) bind(c, name='flock') result(st)
            import :: c_int
            integer(c_int), value :: fd, op
            integer(c_int) :: st
        end function c_flock
        function c_lseek(fd, offset, whence) bind(c, name='lseek') result(pos)
            import :: c_int, c_int64_t
            integer(c_int), value :: fd, whence
            integer(c_int64_t), value :: offset
            integer(c_int64_t) :: pos
        end function c_lseek
        function c_fallocate(fd, mode, offset, length) bind(c, name='fallocate') result(st)
            import :: c_int, c_int64_t
            integer(c_int), value :: fd, mode
            integer(c_int64_t), value :: offset, length
            integer(c_int) :: st
        end function c_fallocate
        function c_ftruncate(fd, length) bind(c, name='ftruncate') result(st)
            import :: c_int, c_int64_t
            integer(c_int), value :: fd
            integer(c_int64_t), value :: length
            integer(c_int) :: st
        end function c_ftruncate
        function c_write(fd, buf, n) bind(c, name='write') result(written)
            import :: c_int, c_char, c_size_t, c_long
            integer(c_int), value :: fd
            character(kind=c_char), intent(in) :: buf(*)
            integer(c_size_t), value :: n
            integer(c_long) :: written
        end function c_write
        function c_readlink(path, buf, n) bind(c, name='readlink') result(length)
            import :: c_char, c_size_t, c_long
            character(kind=c_char), intent(in) :: path(*)
            character(kind=c_char), intent(out) :: buf(*)
            integer(c_size_t), value :: n
            integer(c_long) :: length
        end function c_readlink
        function c_getpid() bind(c, name='getpid') result(pid)
            import :: c_int
            integer(c_int) :: pid
        end function c_getpid
        function c_usleep(usec) bind(c, name='usleep') result(st)
            import :: c_int
            integer(c_int), value :: usec
            integer(c_int) :: st
        end function c_usleep
    end interface

contains

    !> A Fortran string as a NUL-terminated C string.
    pure function c_str(text) result(s)
        character(len=*), intent(in) :: text
        character(kind=c_char, len=:), allocatable :: s
        s = text//c_null_char
    end function c_str

    !> The C string at `p` as a Fortran string.
    function f_str(p) result(text)
        type(c_ptr), intent(in) :: p
        character(len=:), allocatable :: text
        character(kind=c_char), pointer :: chars(:)
        integer :: n, i
        n = int(c_strlen(p))
        call c_f_pointer(p, chars, [n])
        allocate (character(len=n) :: text)
        do i = 1, n
            text(i:i) = chars(i)
        end do
    end function f_str

    !> The current `errno`.
    integer function errno()
        integer(c_int), pointer :: e
        call c_f_pointer(c_errno_location(), e)
        errno = int(e)
    end function errno

    !> The system's text for error number `e` ("No space left on device").
    function strerror(e) result(text)
        integer, intent(in) :: e
        character(len=:), allocatable :: text
        text = f_str(c_strerror(int(e, c_int)))
    end function strerror

    !> Folder part of `path` ('' for a bare name, '/' for the root).
    pure function folder_of(path) result(dir)
        character(len=*), intent(in) :: path
        character(len=:), allocatable :: dir
        integer :: i
        i = index(path, '/', back=.true.)
        if (i == 0) then
            dir = ''
        else if (i == 1) then
            dir = '/'
        else
            dir = path(1:i - 1)
        end if
    end function folder_of

    !> `realpath`: the absolute path of an existing file or folder with every
    !> symbolic link, '.' and '..' resolved; `ok` false (and `e` the errno) otherwise.
    subroutine real_path(path, resolved, ok, e)
        character(len=*), intent(in) :: path
        character(len=:), allocatable, intent(out) :: resolved
        logical, intent(out) :: ok
        integer, intent(out) :: e
        type(c_ptr) :: p
        p = c_realpath(c_str(path), c_null_ptr)
        ok = c_associated(p)
        e = 0
        if (.not. ok) then
            e = errno()
            resolved = path
            return
        end if
        resolved = f_str(p)
        call c_free(p)
    end subroutine real_path

    !> The target of the symbolic link `path` (`ok` false when it is not one).
    subroutine link_target(path, target, ok)
        character(len=*), intent(in) :: path
        character(len=:), allocatable, intent(out) :: target
        logical, intent(out) :: ok
        character(kind=c_char) :: buf(4096)
        integer(c_long) :: n
        integer :: i
        n = c_readlink(c_str(path), buf, int(size(buf), c_size_t))
        ok = n >= 0 .and. n < size(buf)
        if (.not. ok) return
        allocate (character(len=n) :: target)
        do i = 1, int(n)
            target(i:i) = buf(i)
        end do
    end subroutine link_target

    !> The absolute path `path` names, with every symbolic link, '.' and '..'
    !> resolved, whether or not the file exists (its folder must): two paths name
    !> the same file when their canonical paths are equal. A symbolic link to a
    !> missing file is followed to where the file would be created.
    recursive subroutine canonical_path(path, resolved, error, depth)
        character(len=*), intent(in) :: path
        character(len=:), allocatable, intent(out) :: resolved
        type(error_t), allocatable, intent(out) :: error
        !> Links followed so far (at most 40, as the kernel allows).
        integer, intent(in), optional :: depth
        character(len=:), allocatable :: dir, base, target, real_dir
        logical :: ok
        integer :: e, level

        level = 0
        if (present(depth)) level = depth
        if (len(path) == 0) then
            call fatal_error(error, 'an empty file name', error_code%input)
            return
        end if
        call real_path(path, resolved, ok, e)
        if (ok) return
        if (e /= enoent) then
            call fatal_error(error, "'"//path//"': "//strerror(e), error_code%input)
            return
        end if
        dir = folder_of(path)
        base = path(index(path, '/', back=.true.) + 1:)
        call link_target(path, target, ok)
        if (ok) then
            if (level >= 40) then
                call fatal_error(error, "'"//path//"': too many levels of symbolic links", &
                                 error_code%input)
                return
            end if
            if (target(1:1) /= '/' .and. len(dir) > 0) target = dir//'/'//target
            call canonical_path(target, resolved, error, level + 1)
            return
        end if
        if (base == '.' .or. base == '..' .or. len(base) == 0) then
            call fatal_error(error, "'"//path//"' names a folder, not a file", error_code%input)
            return
        end if
        if (len(dir) == 0) dir = '.'
        call real_path(dir, real_dir, ok, e)
        if (.not. ok) then
            call fatal_error(error, "folder '"//dir//"' of '"//path//"': "//strerror(e), &
                             error_code%input)
            return
        end if
        if (real_dir == '/') real_dir = ''
        resolved = real_dir//'/'//base
    end subroutine canonical_path

    !> The file beside `path` that a writer keeps with it: `path` with `suffix`
    !> ('.part', '.lock'), or, when that name would be longer than a file name may
    !> be (255 bytes), the first 200 characters of the name, '-', 16 hex digits of
    !> the name's SHA-256 and `suffix` (the same for every writer of `path`).
    function companion(path, suffix) result(name)
        character(len=*), intent(in) :: path, suffix
        character(len=:), allocatable :: name
        character(len=64) :: hex
        integer :: i
        i = index(path, '/', back=.true.)
        if (len(path) - i + len(suffix) <= 255) then
            name = path//suffix
        else
            hex = sha256_text(path(i + 1:))
            name = path(1:i)//path(i + 1:i + 200)//'-'//hex(1:16)//suffix
        end if
    end function companion

    !> Does `path` exist (after following links)?
    logical function path_exists(path)
        character(len=*), intent(in) :: path
        character(len=:), allocatable :: resolved
        integer :: e
        call real_path(path, resolved, path_exists, e)
    end function path_exists

    !> Is `path` an existing folder?
    logical function is_directory(path)
        character(len=*), intent(in) :: path
        integer(c_int) :: fd
        ! O_DIRECTORY (65536) opens only a folder
        fd = c_open(c_str(path), ior(o_rdonly, ior(o_cloexec, 65536_c_int)), 0_c_int)
        is_directory = fd >= 0
        if (fd >= 0) fd = c_close(fd)
    end function is_directory

    !> Rename `from` to `to` (same file system: atomic; `to` is replaced).
    subroutine rename_file(from, to, error)
        character(len=*), intent(in) :: from, to
        type(error_t), allocatable, intent(out) :: error
        if (c_rename(c_str(from), c_str(to)) /= 0) &
            call fatal_error(error, "cannot rename '"//from//"' to '"//to//"': "//strerror(errno()))
    end subroutine rename_file

    !> Remove the file `path` (nothing if it does not exist).
    subroutine remove_file(path)
        character(len=*), intent(in) :: path
        integer(c_int) :: st
        st = c_unlink(c_str(path))
    end subroutine remove_file

    !> Take the lock file `path` (created if missing) for this process, without
    !> waiting: a lock another process holds is an error naming its process id.
    !> The lock file holds our process id; `release_lock` removes it.
    subroutine acquire_lock(lock, path, what, error)
        type(lock_t), intent(inout) :: lock
        character(len=*), intent(in) :: path
        !> What the lock guards, for messages ("result file 'out.h5'").
        character(len=*), intent(in) :: what
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: holder, link
        character(len=24) :: buf
        integer(c_int) :: fd, st
        integer :: attempt
        logical :: ok

        do attempt = 1, 3
            fd = c_open(c_str(path), ior(o_rdwr, ior(o_creat, o_cloexec)), int(o'644', c_int))
            if (fd < 0) then
                call fatal_error(error, "cannot create the lock file '"//path//"' for "//what//': '// &
                                 strerror(errno()), error_code%input)
                return
            end if
            if (c_flock(fd, ior(lock_ex, lock_nb)) /= 0) then
                holder = first_line(path)
                st = c_close(fd)
                if (len(holder) > 0) holder = ' (process '//holder//')'
                call fatal_error(error, what//' is being written by another voiga run'//holder// &
                                 '; lock file '//path, error_code%input)
                return
            end if
            ! a lock file removed by its last holder between our open and our flock
            ! is no lock: open it again
            write (buf, '(i0)') fd
            call link_target('/proc/self/fd/'//trim(buf), link, ok)
            if (.not. ok) exit
            if (index(link, ' (deleted)') == 0) exit
            st = c_close(fd)
            fd = -1
        end do
        if (fd < 0) then
            call fatal_error(error, "cannot take the lock file '"//path//"' for "//what, error_code%input)
            return
        end if
        write (buf, '(i0)') c_getpid()
        st = c_ftruncate(fd, 0_c_int64_t)
        if (c_write(fd, c_str(trim(buf)//new_line('a')), int(len_trim(buf) + 1, c_size_t)) < 0) continue
        lock%fd = fd
        lock%path = path
    end subroutine acquire_lock

    !> The first line of a small text file ('' if unreadable).
    function first_line(path) result(line)
        character(len=*), intent(in) :: path
        character(len=:), allocatable :: line
        character(len=64) :: buf
        integer :: u, ios
        line = ''
        open (newunit=u, file=path, status='old', action='read', iostat=ios)
        if (ios /= 0) return
        read (u, '(a)', iostat=ios) buf
        close (u)
        if (ios == 0) line = trim(adjustl(buf))
    end function first_line

    !> Let go of a lock; a lock file the lock owns is removed first (while held).
    subroutine release_lock(lock)
        type(lock_t), intent(inout) :: lock
        integer(c_int) :: st
        if (lock%fd < 0) return
        if (allocated(lock%path)) call remove_file(lock%path)
        st = c_close(lock%fd)
        lock%fd = -1
    end subroutine release_lock

    !> Hold an exclusive `flock` on the existing file `path` (readers that take a
    !> shared one wait), waiting at most `seconds`; `held` tells whether it was
    !> taken (not when a reader kept its lock that long, or the file system has no
    !> locks). Released by `let_go`.
    subroutine hold_exclusive(lock, path, seconds, held)
        type(lock_t), intent(inout) :: lock
        character(len=*), intent(in) :: path
        real, intent(in) :: seconds
        logical, intent(out) :: held
        call hold(lock, path, lock_ex, seconds, held)
    end subroutine hold_exclusive

    !> Hold a shared `flock` on `path` (waits while a writer holds an exclusive one,
    !> at most `seconds`).
    subroutine hold_shared(lock, path, seconds, held)
        type(lock_t), intent(inout) :: lock
        character(len=*), intent(in) :: path
        real, intent(in) :: seconds
        logical, intent(out) :: held
        call hold(lock, path, lock_sh, seconds, held)
    end subroutine hold_shared

    subroutine hold(lock, path, op, seconds, held)
        type(lock_t), intent(inout) :: lock
        character(len=*), intent(in) :: path
        integer(c_int), intent(in) :: op
        real, intent(in) :: seconds
        logical, intent(out) :: held
        integer :: waited_ms
        integer(c_int) :: st
        held = .false.
        call let_go(lock)
        lock%fd = c_open(c_str(path), ior(o_rdonly, o_cloexec), 0_c_int)
        if (lock%fd < 0) return
        waited_ms = 0
        do
            if (c_flock(lock%fd, ior(op, lock_nb)) == 0) then
                held = .true.
                return
            end if
            if (errno() /= ewouldblock .and. errno() /= eintr) exit
            if (waited_ms >= int(1000*seconds)) exit
            st = c_usleep(10000_c_int)
            waited_ms = waited_ms + 10
        end do
        st = c_close(lock%fd)
        lock%fd = -1
    end subroutine hold

    !> Release a lock taken by `hold_exclusive` or `hold_shared`.
    subroutine let_go(lock)
        type(lock_t), intent(inout) :: lock
        integer(c_int) :: st
        if (lock%fd < 0) return
        st = c_close(lock%fd)
        lock%fd = -1
    end subroutine let_go

    !> Reserve `bytes` of disk beyond the end of the existing file `path`, so that
    !> writes of up to that size cannot fail for want of space (`fallocate`, the
    !> file's size unchanged). A full disk or an exceeded quota is an error naming
    !> it; a file system that cannot reserve space is not (nothing is reserved).
    subroutine reserve_space(path, bytes, error)
        character(len=*), intent(in) :: path
        integer(int64), intent(in) :: bytes
        type(error_t), allocatable, intent(out) :: error
        integer(c_int) :: fd, st
        integer(c_int64_t) :: size
        integer :: e
        fd = c_open(c_str(path), ior(o_wronly, o_cloexec), 0_c_int)
        if (fd < 0) then
            call fatal_error(error, "cannot open '"//path//"' to reserve space: "//strerror(errno()))
            return
        end if
        size = c_lseek(fd, 0_c_int64_t, 2_c_int)
        st = c_fallocate(fd, falloc_fl_keep_size, max(size, 0_c_int64_t), int(bytes, c_int64_t))
        e = errno()
        if (st /= 0 .and. e /= eopnotsupp) then
            call fatal_error(error, path//': no room for the next '//fixed_str(real(bytes, dp)/2.0_dp**20, 1)// &
                             ' MB: '//strerror(e))
        end if
        st = c_close(fd)
    end subroutine reserve_space

    !> Give back the space `reserve_space` reserved beyond the end of `path` and
    !> the writes did not use (truncating the file to its own size does it).
    subroutine release_space(path)
        character(len=*), intent(in) :: path
        integer(c_int) :: fd, st
        integer(c_int64_t) :: size
        fd = c_open(c_str(path), ior(o_wronly, o_cloexec), 0_c_int)
        if (fd < 0) return
        size = c_lseek(fd, 0_c_int64_t, 2_c_int)
        if (size >= 0) st = c_ftruncate(fd, size)
        st = c_close(fd)
    end subroutine release_space

end module voiga_io_os
