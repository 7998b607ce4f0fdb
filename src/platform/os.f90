!> The operating-system calls of the file layer (Linux, glibc): canonical paths,
!> what a path names and its identity (device and inode, so that two names of one
!> file are told from two files), files created without following links and
!> without replacing anything, regular files opened without blocking on a FIFO,
!> renames that replace only when asked, descriptors' `flock`, and space reserved
!> for a write (`fallocate`). The locks built on them are `voiga_platform_lock`'s,
!> the process's own limits `voiga_platform_process`'s.
!>
!> The raw interfaces are private; the calls that need the system's constants or
!> macros (flags, `errno`) are in libc.c, which includes the system headers: no
!> flag value is written here. They return -errno on failure.
module voiga_platform_os
    use, intrinsic :: iso_c_binding, only: c_int, c_char, c_ptr, c_null_ptr, c_null_char, c_long, &
                                           c_size_t, c_associated, c_f_pointer, c_int64_t
    use, intrinsic :: iso_fortran_env, only: int64
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_platform_sha256, only: sha256_text
    use voiga_kinds, only: dp
    use voiga_text, only: fixed_str
    implicit none
    private

    public :: canonical_path, rename_file, remove_file, path_exists, is_directory, companion
    public :: file_info_t, file_status, fd_status, path_kind, fd_size, same_file, names_file, kind_name, what_is
    public :: create_new, open_regular, close_fd, lock_fd, write_text, read_text
    public :: reserve_space, release_space, c_str, strerror
    public :: kind_unknown, kind_missing, kind_regular, kind_folder, kind_link, kind_fifo, kind_char, &
              kind_block, kind_socket

    !> What a path names (libc.c's KIND_*); `kind_unknown` when its status
    !> could not be taken.
    integer, parameter :: kind_unknown = -1, kind_missing = 0, kind_regular = 1, kind_folder = 2, &
                          kind_link = 3, kind_fifo = 4, kind_char = 5, kind_block = 6, kind_socket = 7

    !> What a path or a descriptor names: its kind and, when it exists, the
    !> identity of the file (device and inode: one file whatever name it has), its
    !> number of names (hard links) and its size in bytes.
    type :: file_info_t
        integer :: kind = kind_missing
        integer(int64) :: device = -1, inode = -1, links = 0, size = 0
        !> The errno when `kind` is `kind_unknown`.
        integer :: errno = 0
    end type file_info_t

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
        function c_strerror(errnum) bind(c, name='voiga_strerror') result(p)
            import :: c_int, c_ptr
            integer(c_int), value :: errnum
            type(c_ptr) :: p
        end function c_strerror
        function c_errno() bind(c, name='voiga_errno') result(e)
            import :: c_int
            integer(c_int) :: e
        end function c_errno
        function c_enoent() bind(c, name='voiga_enoent') result(e)
            import :: c_int
            integer(c_int) :: e
        end function c_enoent
        function c_eexist() bind(c, name='voiga_eexist') result(e)
            import :: c_int
            integer(c_int) :: e
        end function c_eexist
        function c_name_max() bind(c, name='voiga_name_max') result(n)
            import :: c_int
            integer(c_int) :: n
        end function c_name_max
        function c_path_max() bind(c, name='voiga_path_max') result(n)
            import :: c_int
            integer(c_int) :: n
        end function c_path_max
        function c_readlink(path, buf, n) bind(c, name='readlink') result(length)
            import :: c_char, c_size_t, c_long
            character(kind=c_char), intent(in) :: path(*)
            character(kind=c_char), intent(out) :: buf(*)
            integer(c_size_t), value :: n
            integer(c_long) :: length
        end function c_readlink
        function c_file_status(path, follow, out) bind(c, name='voiga_file_status') result(kind)
            import :: c_char, c_int, c_int64_t
            character(kind=c_char), intent(in) :: path(*)
            integer(c_int), value :: follow
            integer(c_int64_t), intent(out) :: out(4)
            integer(c_int) :: kind
        end function c_file_status
        function c_fd_status(fd, out) bind(c, name='voiga_fd_status') result(kind)
            import :: c_int, c_int64_t
            integer(c_int), value :: fd
            integer(c_int64_t), intent(out) :: out(4)
            integer(c_int) :: kind
        end function c_fd_status
        function c_create_new(path) bind(c, name='voiga_create_new') result(fd)
            import :: c_char, c_int
            character(kind=c_char), intent(in) :: path(*)
            integer(c_int) :: fd
        end function c_create_new
        function c_open_regular(path, writable, follow, kind) bind(c, name='voiga_open_regular') result(fd)
            import :: c_char, c_int
            character(kind=c_char), intent(in) :: path(*)
            integer(c_int), value :: writable, follow
            integer(c_int), intent(out) :: kind
            integer(c_int) :: fd
        end function c_open_regular
        function c_lock(fd, how, wait) bind(c, name='voiga_lock') result(st)
            import :: c_int
            integer(c_int), value :: fd, how, wait
            integer(c_int) :: st
        end function c_lock
        function c_close(fd) bind(c, name='voiga_close') result(st)
            import :: c_int
            integer(c_int), value :: fd
            integer(c_int) :: st
        end function c_close
        function c_write_text(fd, text, n) bind(c, name='voiga_write_text') result(st)
            import :: c_int, c_char
            integer(c_int), value :: fd, n
            character(kind=c_char), intent(in) :: text(*)
            integer(c_int) :: st
        end function c_write_text
        function c_read_text(fd, text, n) bind(c, name='voiga_read_text') result(st)
            import :: c_int, c_char
            integer(c_int), value :: fd, n
            character(kind=c_char), intent(out) :: text(*)
            integer(c_int) :: st
        end function c_read_text
        function c_unlink(path) bind(c, name='voiga_unlink') result(st)
            import :: c_char, c_int
            character(kind=c_char), intent(in) :: path(*)
            integer(c_int) :: st
        end function c_unlink
        function c_rename(from, to, replace) bind(c, name='voiga_rename') result(st)
            import :: c_char, c_int
            character(kind=c_char), intent(in) :: from(*), to(*)
            integer(c_int), value :: replace
            integer(c_int) :: st
        end function c_rename
        function c_reserve(fd, bytes) bind(c, name='voiga_reserve') result(st)
            import :: c_int, c_int64_t
            integer(c_int), value :: fd
            integer(c_int64_t), value :: bytes
            integer(c_int) :: st
        end function c_reserve
        function c_release(fd) bind(c, name='voiga_release') result(st)
            import :: c_int
            integer(c_int), value :: fd
            integer(c_int) :: st
        end function c_release
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
        errno = int(c_errno())
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
        character(kind=c_char), allocatable :: buf(:)
        integer(c_long) :: n
        integer :: i
        allocate (buf(c_path_max()))
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
        if (e /= c_enoent()) then
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
    !> be (NAME_MAX: 255 bytes on Linux), the first 200 characters of the name, '-',
    !> 16 hex digits of the name's SHA-256 and `suffix` (the same for every writer of
    !> `path`).
    function companion(path, suffix) result(name)
        character(len=*), intent(in) :: path, suffix
        character(len=:), allocatable :: name
        character(len=64) :: hex
        integer :: i
        i = index(path, '/', back=.true.)
        if (len(path) - i + len(suffix) <= c_name_max()) then
            name = path//suffix
        else
            hex = sha256_text(path(i + 1:))
            name = path(1:i)//path(i + 1:i + 200)//'-'//hex(1:16)//suffix
        end if
    end function companion

    !> What `path` names: the file a symbolic link points to when `follow`, else
    !> the link itself.
    function file_status(path, follow) result(info)
        character(len=*), intent(in) :: path
        logical, intent(in) :: follow
        type(file_info_t) :: info
        integer(c_int64_t) :: out(4)
        call described(c_file_status(c_str(path), merge(1_c_int, 0_c_int, follow), out), out, info)
    end function file_status

    !> The kind of what `path` names (`file_status`'s).
    integer function path_kind(path, follow)
        character(len=*), intent(in) :: path
        logical, intent(in) :: follow
        type(file_info_t) :: info
        info = file_status(path, follow)
        path_kind = info%kind
    end function path_kind

    !> The size in bytes of the file open as `fd` (0 when unknown).
    integer(int64) function fd_size(fd)
        integer(c_int), intent(in) :: fd
        type(file_info_t) :: info
        info = fd_status(fd)
        fd_size = info%size
    end function fd_size

    !> What the open descriptor `fd` is.
    function fd_status(fd) result(info)
        integer(c_int), intent(in) :: fd
        type(file_info_t) :: info
        integer(c_int64_t) :: out(4)
        call described(c_fd_status(fd, out), out, info)
    end function fd_status

    pure subroutine described(kind, out, info)
        integer(c_int), intent(in) :: kind
        integer(c_int64_t), intent(in) :: out(4)
        type(file_info_t), intent(out) :: info
        if (kind < 0) then
            info%kind = kind_unknown
            info%errno = -kind
        else
            info%kind = kind
            if (kind /= kind_missing) then
                info%device = out(1)
                info%inode = out(2)
                info%links = out(3)
                info%size = out(4)
            end if
        end if
    end subroutine described

    !> Are `a` and `b` the same existing file (device and inode), whatever their names?
    pure logical function same_file(a, b)
        type(file_info_t), intent(in) :: a, b
        same_file = a%kind > kind_missing .and. b%kind > kind_missing .and. a%device == b%device .and. &
                    a%inode == b%inode
    end function same_file

    !> Does the name `path` (not followed if a link) still name the file `info`
    !> describes? (No when it was removed, or moved and something else put there.)
    logical function names_file(path, info)
        character(len=*), intent(in) :: path
        type(file_info_t), intent(in) :: info
        names_file = same_file(file_status(path, .false.), info)
    end function names_file

    !> What a kind of file is called in messages ('a FIFO (named pipe)').
    pure function kind_name(kind) result(name)
        integer, intent(in) :: kind
        character(len=:), allocatable :: name
        select case (kind)
        case (kind_missing)
            name = 'missing'
        case (kind_regular)
            name = 'a regular file'
        case (kind_folder)
            name = 'a folder'
        case (kind_link)
            name = 'a symbolic link'
        case (kind_fifo)
            name = 'a FIFO (named pipe)'
        case (kind_char)
            name = 'a character device'
        case (kind_block)
            name = 'a block device'
        case (kind_socket)
            name = 'a socket'
        case default
            name = 'of unknown kind'
        end select
    end function kind_name

    !> What `info` is called in a message refusing to touch it: its kind, or 'a
    !> second name of another file' for a regular file with more than one name.
    pure function what_is(info) result(name)
        type(file_info_t), intent(in) :: info
        character(len=:), allocatable :: name
        if (info%kind == kind_regular .and. info%links > 1) then
            name = 'a second name of another file'
        else
            name = kind_name(info%kind)
        end if
    end function what_is

    !> Does `path` exist (after following links)?
    logical function path_exists(path)
        character(len=*), intent(in) :: path
        path_exists = path_kind(path, .true.) > kind_missing
    end function path_exists

    !> Is `path` an existing folder (after following links)?
    logical function is_directory(path)
        character(len=*), intent(in) :: path
        is_directory = path_kind(path, .true.) == kind_folder
    end function is_directory

    !> Create `path` as a new file, open for reading and writing (`fd`), never
    !> through a symbolic link and never over anything there; `fd` < 0 and `e`
    !> the errno when it cannot be (`exists`: because something is there).
    subroutine create_new(path, fd, e, exists)
        character(len=*), intent(in) :: path
        integer(c_int), intent(out) :: fd
        integer, intent(out) :: e
        logical, intent(out) :: exists
        fd = c_create_new(c_str(path))
        e = int(max(-fd, 0_c_int))
        exists = e == c_eexist()
    end subroutine create_new

    !> Open the existing regular file `path` (for writing too when `writable`; a
    !> link at its last component is not followed unless `follow`): `fd`, or `fd` < 0
    !> with `e` the errno and `kind` what is there (a FIFO or a device is never
    !> opened in a way that waits).
    subroutine open_regular(path, writable, follow, fd, kind, e)
        character(len=*), intent(in) :: path
        logical, intent(in) :: writable, follow
        integer(c_int), intent(out) :: fd
        integer, intent(out) :: kind, e
        integer(c_int) :: k
        fd = c_open_regular(c_str(path), merge(1_c_int, 0_c_int, writable), merge(1_c_int, 0_c_int, follow), k)
        kind = int(k)
        e = int(max(-fd, 0_c_int))
    end subroutine open_regular

    !> Close a descriptor (nothing when < 0) and set it to -1.
    subroutine close_fd(fd)
        integer(c_int), intent(inout) :: fd
        integer(c_int) :: st
        if (fd >= 0) st = c_close(fd)
        fd = -1
    end subroutine close_fd

    !> `flock` on `fd`: `how` 'release', 'shared' or 'exclusive', waiting for it
    !> when `wait`. 0 taken, 1 another process holds it, else -errno.
    integer function lock_fd(fd, how, wait)
        integer(c_int), intent(in) :: fd
        character(len=*), intent(in) :: how
        logical, intent(in) :: wait
        integer(c_int) :: op
        op = merge(0_c_int, merge(1_c_int, 2_c_int, how == 'shared'), how == 'release')
        lock_fd = int(c_lock(fd, op, merge(1_c_int, 0_c_int, wait)))
    end function lock_fd

    !> Make `text` the whole content of the file open as `fd`; the errno, or 0.
    integer function write_text(fd, text)
        integer(c_int), intent(in) :: fd
        character(len=*), intent(in) :: text
        write_text = -int(c_write_text(fd, text, int(len(text), c_int)))
    end function write_text

    !> At most the first `n` bytes of the file open as `fd` ('' when unreadable).
    function read_text(fd, n) result(text)
        integer(c_int), intent(in) :: fd
        integer, intent(in) :: n
        character(len=:), allocatable :: text
        character(kind=c_char) :: buf(max(n, 1))
        integer(c_int) :: got
        integer :: i
        got = c_read_text(fd, buf, int(n, c_int))
        allocate (character(len=max(int(got), 0)) :: text)
        do i = 1, len(text)
            text(i:i) = buf(i)
        end do
    end function read_text

    !> Rename `from` to `to` (same file system: atomic). An existing `to` is
    !> replaced only when `replace`; otherwise the rename fails naming it.
    subroutine rename_file(from, to, replace, error)
        character(len=*), intent(in) :: from, to
        logical, intent(in) :: replace
        type(error_t), allocatable, intent(out) :: error
        integer(c_int) :: st
        st = c_rename(c_str(from), c_str(to), merge(1_c_int, 0_c_int, replace))
        if (st /= 0) call fatal_error(error, "cannot rename '"//from//"' to '"//to//"': "//strerror(-int(st)))
    end subroutine rename_file

    !> Remove the name `path` (a link itself, never its target; nothing if it does
    !> not exist).
    subroutine remove_file(path)
        character(len=*), intent(in) :: path
        integer(c_int) :: st
        st = c_unlink(c_str(path))
    end subroutine remove_file

    !> Reserve `bytes` of disk beyond the end of the file open as `fd` (`path` names
    !> it in messages), so that writes of up to that size cannot fail for want of
    !> space (`fallocate`, the file's size unchanged). A full disk or an exceeded
    !> quota is an error naming it; a file system that cannot reserve space is not
    !> (nothing is reserved).
    subroutine reserve_space(fd, path, bytes, error)
        integer(c_int), intent(in) :: fd
        character(len=*), intent(in) :: path
        integer(int64), intent(in) :: bytes
        type(error_t), allocatable, intent(out) :: error
        integer(c_int) :: st
        st = c_reserve(fd, int(bytes, c_int64_t))
        if (st /= 0) then
            call fatal_error(error, path//': no room for the next '//fixed_str(real(bytes, dp)/2.0_dp**20, 1)// &
                             ' MB: '//strerror(-int(st)))
        end if
    end subroutine reserve_space

    !> Give back the space `reserve_space` reserved beyond the end of the file open
    !> as `fd` and the writes did not use.
    subroutine release_space(fd)
        integer(c_int), intent(in) :: fd
        integer(c_int) :: st
        st = c_release(fd)
    end subroutine release_space

end module voiga_platform_os
