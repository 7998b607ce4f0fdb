!> A small HDF5 file object over the raw Fortran API.
!>
!> `call h%open(path, 'r'|'w'|'rw', error)`, `h%write(path, array, error)`,
!> `h%read(path, array, error)`, attributes with `h%write_attr(path, name, value, error)`
!> and `h%read_attr_*(path, name, value, error)`, `h%flush(error)`, `h%close(error)`.
!> Paths are absolute ('/bodies/die/knots_xi'); missing parent groups are created on
!> write, and a dataset or attribute that exists is replaced (a restarted run rewrites
!> run-wide records).
!>
!> Every HDF5 call is checked: a failure comes back as an `error_t` naming the file,
!> the object and the HDF5 call that failed, and every handle opened on the way is
!> closed on every path. Writes that HDF5 only caches can fail at `flush` or `close`
!> (a full disk), so those report errors too. The queries `exists`, `has_attr` and
!> `shape` answer "no" (or an empty shape) when HDF5 fails.
!>
!> A write (`write`, `write_attr`, `create_group`) called without its `error`
!> argument keeps its failure in the object instead: the first one is kept, later
!> writes without `error` do nothing, and `check(error)` hands it over. A writer
!> of many objects (a result file's step) so checks once, where its writing ends,
!> instead of after every call; nothing is opened after the failure, and what the
!> failed call opened it closed.
!>
!> Arrays are written in Fortran order, so h5py shows them with the axes reversed
!> (docs/formats.md); reals as 64-bit floats, integers as the native (32-bit) integer,
!> a scalar as a dataset of one element and shape (1,). Strings are written as
!> fixed-length ASCII attributes; fixed and variable-length string attributes are read.
!>
!> Reading converts with HDF5's own conversions, which are exact for what we accept:
!> reals are read from any integer or floating-point dataset (an integer beyond 2^53
!> would round); integers only from integer datasets of any width, through a 64-bit
!> buffer whose values must fit a default integer. Refused with an error: strings,
!> compound, enum and other classes (HDF5 either has no conversion, so the read
!> fails, or converts lossily: floats to integers are truncated and clamped, NaN
!> becomes the most negative integer, wide integers are clamped to the narrow range),
!> a rank other than the array's, and attributes of more than one value.
module voiga_io_hdf5
    use, intrinsic :: iso_c_binding, only: c_ptr, c_loc, c_int, path_char => c_char, path_end => c_null_char
    use, intrinsic :: iso_fortran_env, only: int64
    use hdf5, only: hid_t, hsize_t, h5open_f, h5fopen_f, h5fcreate_f, h5fclose_f, h5fflush_f, &
                    H5F_ACC_RDONLY_F, H5F_ACC_RDWR_F, H5F_ACC_TRUNC_F, H5F_ACC_EXCL_F, H5F_SCOPE_GLOBAL_F, &
                    h5dopen_f, h5dcreate_f, h5dwrite_f, h5dread_f, h5dget_space_f, h5dget_type_f, &
                    h5screate_simple_f, h5sget_simple_extent_ndims_f, h5sget_simple_extent_dims_f, &
                    h5gcreate_f, h5lexists_f, h5ldelete_f, h5tget_class_f, H5T_INTEGER_F, &
                    H5T_FLOAT_F, H5T_NATIVE_DOUBLE, H5T_NATIVE_INTEGER, h5kind_to_type, &
                    H5_INTEGER_KIND, h5eset_auto_f, h5pcreate_f, h5pclose_f, h5pset_file_locking_f, &
                    H5P_FILE_ACCESS_F
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_io_hdf5_status, only: note, release, class_name, not_open, fits_integer
    use voiga_platform_os, only: file_info_t, file_status, kind_name, kind_missing, kind_regular
    implicit none
    private

    public :: h5file_t, finish_interrupted_flush

    !> An open HDF5 file.
    type :: h5file_t
        integer(hid_t) :: id = -1
        character(len=:), allocatable :: path
        !> The group `create_group` last made or found (so it and its parents exist,
        !> groups are never deleted): `exists` answers for them without asking HDF5.
        !> Every attribute and dataset of a step checked its path level by level
        !> with H5Lexists (a path traversal each): a third of the output's time.
        character(len=:), allocatable, private :: known
        !> The first failure of a write made without an `error` argument (`check`).
        type(error_t), allocatable, private :: failure
    contains
        procedure :: open => file_open
        procedure :: close => file_close
        procedure :: flush => file_flush
        procedure :: exists => file_exists
        procedure :: is_open => file_is_open
        !> Write a real (64-bit) or integer array of any rank, or a scalar.
        generic :: write => write_real, write_int
        procedure, private :: write_real, write_int
        !> Read into an allocatable real array of rank 0 to 3 or integer array of rank
        !> 0 or 1, optionally of at most `limit` values (checked before anything is read).
        generic :: read => read_real, read_int
        procedure, private :: read_real, read_int
        !> The descriptor of the open file (-1 when none): its identity.
        procedure :: descriptor => file_descriptor
        generic :: write_attr => attr_write_str, attr_write_int, attr_write_real
        procedure, private :: attr_write_str, attr_write_int, attr_write_real
        procedure :: read_attr_str => attr_read_str
        procedure :: read_attr_int => attr_read_int
        procedure :: read_attr_real => attr_read_real
        procedure :: has_attr => attr_exists
        procedure :: shape => dataset_shape
        procedure :: create_group => group_create
        !> Has a write without an `error` argument failed (since the last `check`)?
        procedure :: failed => file_failed
        procedure :: check => file_check
        !> (gfortran emits a private procedure of the module that the submodules
        !> call only when it is a binding.)
        procedure, private :: skips, hand_over
        final :: file_finalize
    end type h5file_t

    interface

        !> Write a string attribute (fixed-length ASCII; an empty string is stored as
        !> ' '). Without `error`, as every write: a failure is kept (`check`).
        module subroutine attr_write_str(self, path, name, value, error)
            class(h5file_t), intent(inout) :: self
            character(len=*), intent(in) :: path, name, value
            type(error_t), allocatable, intent(out), optional :: error
        end subroutine attr_write_str

        !> Write an integer attribute (native integer).
        module subroutine attr_write_int(self, path, name, value, error)
            class(h5file_t), intent(inout) :: self
            character(len=*), intent(in) :: path, name
            integer, target, intent(in) :: value
            type(error_t), allocatable, intent(out), optional :: error
        end subroutine attr_write_int

        !> Write a real attribute (64-bit float).
        module subroutine attr_write_real(self, path, name, value, error)
            class(h5file_t), intent(inout) :: self
            character(len=*), intent(in) :: path, name
            real(dp), target, intent(in) :: value
            type(error_t), allocatable, intent(out), optional :: error
        end subroutine attr_write_real

        !> Does object `path` have attribute `name`? (No, when HDF5 fails.)
        module logical function attr_exists(self, path, name)
            class(h5file_t), intent(inout) :: self
            character(len=*), intent(in) :: path, name
        end function attr_exists

        !> Read a scalar string attribute, fixed or variable length (trailing blanks
        !> and NULs removed).
        module subroutine attr_read_str(self, path, name, value, error)
            class(h5file_t), intent(inout) :: self
            character(len=*), intent(in) :: path, name
            character(len=:), allocatable, intent(out) :: value
            type(error_t), allocatable, intent(out) :: error
        end subroutine attr_read_str

        !> Read a scalar integer attribute (any integer width; the value must fit).
        module subroutine attr_read_int(self, path, name, value, error)
            class(h5file_t), intent(inout) :: self
            character(len=*), intent(in) :: path, name
            integer, intent(out) :: value
            type(error_t), allocatable, intent(out) :: error
        end subroutine attr_read_int

        !> Read a scalar real attribute (from any integer or floating-point type).
        module subroutine attr_read_real(self, path, name, value, error)
            class(h5file_t), intent(inout) :: self
            character(len=*), intent(in) :: path, name
            real(dp), target, intent(out) :: value
            type(error_t), allocatable, intent(out) :: error
        end subroutine attr_read_real
    end interface

    interface
        !> Read a real dataset of the array's rank (rank 0: a scalar or one-element
        !> dataset), converting integers and other floats; a dataset of more than
        !> `limit` values (default: 2^31 - 1) is refused before anything is read.
        module subroutine read_real(self, path, array, error, limit)
            class(h5file_t), intent(in) :: self
            character(len=*), intent(in) :: path
            real(dp), allocatable, target, intent(out) :: array(..)
            type(error_t), allocatable, intent(out) :: error
            integer(int64), intent(in), optional :: limit
        end subroutine read_real

        !> Read an integer dataset (any integer width) of the array's rank; its values
        !> must fit a default integer. `limit` as for `read_real`.
        module subroutine read_int(self, path, array, error, limit)
            class(h5file_t), intent(in) :: self
            character(len=*), intent(in) :: path
            integer, allocatable, intent(out) :: array(..)
            type(error_t), allocatable, intent(out) :: error
            integer(int64), intent(in), optional :: limit
        end subroutine read_int

        !> Shape of dataset `path` in Fortran order (empty if missing, unreadable or
        !> kept outside the file; a dimension beyond 2^31 - 1 as 2^31 - 1).
        module function dataset_shape(self, path) result(dims)
            class(h5file_t), intent(in) :: self
            character(len=*), intent(in) :: path
            integer, allocatable :: dims(:)
        end function dataset_shape
    end interface

    interface
        !> The descriptor of an open HDF5 file (journal_vfd.c; -1 when none).
        function c_h5_fd(file) bind(c, name='voiga_h5_fd') result(fd)
            import :: c_int, hid_t
            integer(hid_t), value :: file
            integer(c_int) :: fd
        end function c_h5_fd
        !> The journaled file driver on a file access list (journal_vfd.c); 0: done.
        function c_journal_fapl(fapl) bind(c, name='voiga_journal_fapl') result(st)
            import :: c_int, hid_t
            integer(hid_t), value :: fapl
            integer(c_int) :: st
        end function c_journal_fapl
        !> Finish a flush a killed writer left in `path` (journal_vfd.c): 1 done,
        !> 0 nothing to do, -1 failed.
        function c_journal_recover(path) bind(c, name='voiga_journal_recover') result(st)
            import :: c_int, path_char
            character(kind=path_char), intent(in) :: path(*)
            integer(c_int) :: st
        end function c_journal_recover
    end interface

contains

    !> Open `path`: mode 'r' read-only, 'rw' read-write (an existing regular file:
    !> a FIFO or a device is refused before HDF5 opens it), 'w' create (truncate), 'x'
    !> create a new file (refused when anything is at the name; never through a link).
    !> A file this object had open is closed first. HDF5's own file locking is off:
    !> a result file is guarded by the writer's lock file and its `flock` while a
    !> step is written (`voiga_io_output_results`, docs/hdf5.md), whatever
    !> HDF5_USE_FILE_LOCKING says, and HDF5's lock would exclude that `flock`.
    subroutine file_open(self, path, mode, error)
        class(h5file_t), intent(inout) :: self
        character(len=*), intent(in) :: path, mode
        type(error_t), allocatable, intent(out) :: error
        integer :: st
        integer(hid_t) :: fapl
        type(file_info_t) :: info

        call self%close(error)
        if (allocated(error)) return
        call h5open_f(st)
        ! we report errors ourselves: no HDF5 error stack on stderr
        if (st == 0) call h5eset_auto_f(0, st)
        if (st == 0) call h5pcreate_f(H5P_FILE_ACCESS_F, fapl, st)
        if (st == 0) call h5pset_file_locking_f(fapl, .false., .true., st)
        ! files voiga writes are written through the journaled driver: a kill at any
        ! instant leaves the file as it was after a flush (docs/hdf5.md, "Crash safety")
        if (st == 0 .and. mode /= 'r') st = c_journal_fapl(fapl)
        if (st /= 0) then
            call fatal_error(error, "cannot initialise the HDF5 library to open '"//path//"'")
            return
        end if
        select case (mode)
        case ('r', 'rw')
            info = file_status(path, .true.)
            if (info%kind == kind_missing) then
                call fatal_error(error, "file '"//path//"' does not exist", error_code%input)
            else if (info%kind /= kind_regular) then
                ! (HDF5 would wait for the other end of a FIFO, or read a device)
                call fatal_error(error, "'"//path//"' is "//kind_name(info%kind)//', not an HDF5 file', &
                                 error_code%input)
            else
                call h5fopen_f(path, merge(H5F_ACC_RDONLY_F, H5F_ACC_RDWR_F, mode == 'r'), self%id, st, &
                               access_prp=fapl)
                if (st /= 0) then
                    self%id = -1
                    call fatal_error(error, "file '"//path//"' is not a readable HDF5 file", &
                                     error_code%input)
                end if
            end if
        case ('w', 'x')
            call h5fcreate_f(path, merge(H5F_ACC_EXCL_F, H5F_ACC_TRUNC_F, mode == 'x'), self%id, st, &
                             access_prp=fapl)
            if (st /= 0) then
                self%id = -1
                call fatal_error(error, "cannot create HDF5 file '"//path//"'", error_code%input)
            end if
        case default
            call fatal_error(error, "unknown HDF5 open mode '"//mode//"'")
        end select
        call h5pclose_f(fapl, st)
        if (.not. allocated(error)) self%path = path
        self%known = ''
        ! (a failure belongs to the file it happened in)
        if (allocated(self%failure)) deallocate (self%failure)
    end subroutine file_open

    !> Finish the flush a killed writer of the file `path` left half done, if it
    !> did (docs/hdf5.md, "Crash safety"; journal_vfd.c): `done` tells whether there
    !> was one. Nothing while another process holds the file's `flock`, or when the
    !> file cannot be written (then it is read as it is).
    subroutine finish_interrupted_flush(path, done)
        character(len=*), intent(in) :: path
        logical, intent(out) :: done
        done = c_journal_recover(path//path_end) == 1
    end subroutine finish_interrupted_flush

    !> Close the file (nothing to do if it is not open). Data HDF5 still held in
    !> its caches is written here, so a full disk can show up only now.
    subroutine file_close(self, error)
        class(h5file_t), intent(inout) :: self
        type(error_t), allocatable, intent(out) :: error
        integer :: st
        if (self%id < 0) return
        call h5fclose_f(self%id, st)
        self%id = -1
        self%known = ''
        if (st /= 0) call fatal_error(error, self%path//': closing the file failed in H5Fclose '// &
                                      '(what was written may not be on disk)')
    end subroutine file_close

    !> Last resort for a file nobody closed: close it, ignoring the status (there
    !> is nobody left to tell).
    subroutine file_finalize(self)
        type(h5file_t), intent(inout) :: self
        integer :: st
        if (self%id >= 0) call h5fclose_f(self%id, st)
        self%id = -1
    end subroutine file_finalize

    !> The descriptor of the open file (the driver's; -1 when the file is not open).
    integer(c_int) function file_descriptor(self)
        class(h5file_t), intent(in) :: self
        file_descriptor = -1
        if (self%id >= 0) file_descriptor = c_h5_fd(self%id)
    end function file_descriptor

    !> Is the file open?
    logical function file_is_open(self)
        class(h5file_t), intent(in) :: self
        file_is_open = self%id >= 0
    end function file_is_open

    !> Write buffers to disk so that a later crash keeps what was written (nothing to
    !> do if the file is not open).
    subroutine file_flush(self, error)
        class(h5file_t), intent(in) :: self
        type(error_t), allocatable, intent(out) :: error
        integer :: st
        if (self%id < 0) return
        call h5fflush_f(self%id, H5F_SCOPE_GLOBAL_F, st)
        if (st /= 0) call fatal_error(error, self%path//': flushing the file failed in '// &
                                      'H5Fflush (is the disk full?)')
    end subroutine file_flush

    !> Does the object (group or dataset) at `path` exist? (No, when HDF5 fails.)
    logical function file_exists(self, path)
        class(h5file_t), intent(in) :: self
        character(len=*), intent(in) :: path
        integer :: st, i
        logical :: ok
        file_exists = .false.
        if (self%id < 0) return
        if (known_group(self, path)) then
            file_exists = .true.
            return
        end if
        ! check each parent first: H5Lexists fails on a path with a missing parent
        do i = 2, len(path) - 1
            if (path(i:i) /= '/') cycle
            if (known_group(self, path(1:i - 1))) cycle
            call h5lexists_f(self%id, path(1:i - 1), ok, st)
            if (st /= 0 .or. .not. ok) return
        end do
        if (path == '/') then
            file_exists = .true.
            return
        end if
        call h5lexists_f(self%id, path, ok, st)
        file_exists = st == 0 .and. ok
    end function file_exists

    !> Whether `path` is the group `create_group` last made or found, or one of its parents.
    pure logical function known_group(self, path)
        class(h5file_t), intent(in) :: self
        character(len=*), intent(in) :: path
        integer :: n
        known_group = .false.
        if (.not. allocated(self%known)) return
        n = len(path)
        if (n == 0 .or. len(self%known) < n) return
        if (self%known(1:n) /= path) return
        known_group = len(self%known) == n
        if (.not. known_group) known_group = self%known(n + 1:n + 1) == '/'
    end function known_group

    !> Create the group `path` and any missing parents.
    subroutine group_create(self, path, error)
        class(h5file_t), intent(inout) :: self
        character(len=*), intent(in) :: path
        type(error_t), allocatable, intent(out), optional :: error
        type(error_t), allocatable :: outcome
        if (self%skips(present(error))) return
        call make_groups(self, path, outcome)
        call self%hand_over(outcome, error)
    end subroutine group_create

    !> Create the group `path` and any missing parents (`group_create`).
    subroutine make_groups(self, path, error)
        class(h5file_t), intent(inout) :: self
        character(len=*), intent(in) :: path
        type(error_t), allocatable, intent(out) :: error
        integer :: i, st
        integer(hid_t) :: gid
        character(len=:), allocatable :: failed

        if (not_open(self%id, path, error)) return
        do i = 2, len(path) + 1
            if (i <= len(path)) then
                if (path(i:i) /= '/') cycle
            end if
            if (self%exists(path(1:i - 1))) cycle
            gid = -1
            call h5gcreate_f(self%id, path(1:i - 1), gid, st)
            call note(st, 'H5Gcreate', failed)
            call release(gid, failed)
            if (allocated(failed)) then
                call fatal_error(error, self%path//": creating group '"//path(1:i - 1)// &
                                 "' failed in "//failed)
                return
            end if
        end do
        self%known = path
    end subroutine make_groups

    !> Write a real array of any rank (a scalar as one element) as 64-bit floats.
    subroutine write_real(self, path, array, error)
        class(h5file_t), intent(inout) :: self
        character(len=*), intent(in) :: path
        real(dp), contiguous, target, intent(in) :: array(..)
        type(error_t), allocatable, intent(out), optional :: error
        call write_array(self, path, H5T_NATIVE_DOUBLE, written_dims(shape(array, kind=hsize_t)), &
                         c_loc(array), error)
    end subroutine write_real

    !> Write an integer array of any rank (a scalar as one element) as native integers.
    subroutine write_int(self, path, array, error)
        class(h5file_t), intent(inout) :: self
        character(len=*), intent(in) :: path
        integer, contiguous, target, intent(in) :: array(..)
        type(error_t), allocatable, intent(out), optional :: error
        call write_array(self, path, H5T_NATIVE_INTEGER, written_dims(shape(array, kind=hsize_t)), &
                         c_loc(array), error)
    end subroutine write_int

    !> `write_dataset`, its failure to `error` or, without one, kept by the file.
    subroutine write_array(self, path, dtype, dims, buf, error)
        class(h5file_t), intent(inout) :: self
        character(len=*), intent(in) :: path
        integer(hid_t), intent(in) :: dtype
        integer(hsize_t), intent(in) :: dims(:)
        type(c_ptr), intent(in) :: buf
        type(error_t), allocatable, intent(out), optional :: error
        type(error_t), allocatable :: outcome
        if (self%skips(present(error))) return
        call write_dataset(self, path, dtype, dims, buf, outcome)
        call self%hand_over(outcome, error)
    end subroutine write_array

    !> Whether a write without `error` (`has_error` false) is skipped: a write
    !> without one failed before.
    pure logical function skips(self, has_error)
        class(h5file_t), intent(in) :: self
        logical, intent(in) :: has_error
        skips = .not. has_error .and. allocated(self%failure)
    end function skips

    !> The `outcome` of a write to its caller's `error`, or, without one, kept as
    !> the file's failure (the first one only: later writes were skipped).
    subroutine hand_over(self, outcome, error)
        class(h5file_t), intent(inout) :: self
        type(error_t), allocatable, intent(inout) :: outcome
        type(error_t), allocatable, intent(out), optional :: error
        if (.not. allocated(outcome)) return
        if (present(error)) then
            call move_alloc(outcome, error)
        else
            call move_alloc(outcome, self%failure)
        end if
    end subroutine hand_over

    !> Has a write without an `error` argument failed since the last `check`?
    pure logical function file_failed(self)
        class(h5file_t), intent(in) :: self
        file_failed = allocated(self%failure)
    end function file_failed

    !> Hand over the failure of the writes made without an `error` argument (the
    !> first one; the file forgets it): `error` is set only when one failed and it
    !> holds none yet (an earlier error of the caller's stays the first).
    subroutine file_check(self, error)
        class(h5file_t), intent(inout) :: self
        type(error_t), allocatable, intent(inout) :: error
        if (.not. allocated(self%failure)) return
        if (allocated(error)) then
            deallocate (self%failure)
        else
            call move_alloc(self%failure, error)
        end if
    end subroutine file_check

    !> The dataset shape of an array of shape `array_shape`: a scalar is one element.
    pure function written_dims(array_shape) result(dims)
        integer(hsize_t), intent(in) :: array_shape(:)
        integer(hsize_t), allocatable :: dims(:)
        if (size(array_shape) == 0) then
            dims = [1_hsize_t]
        else
            ! (gfortran 12 gives an empty array constructor, e.g. `[real(dp) ::]`, passed
            ! as assumed-rank, the extent -1)
            dims = max(array_shape, 0_hsize_t)
        end if
    end function written_dims

    !> Write the contiguous data at `buf`, of HDF5 type `dtype` (also the type in the
    !> file) and shape `dims`, as dataset `path`, replacing one that exists.
    subroutine write_dataset(self, path, dtype, dims, buf, error)
        class(h5file_t), intent(inout) :: self
        character(len=*), intent(in) :: path
        integer(hid_t), intent(in) :: dtype
        integer(hsize_t), intent(in) :: dims(:)
        type(c_ptr), intent(in) :: buf
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: did, sid
        integer :: st
        character(len=:), allocatable :: failed

        if (not_open(self%id, path, error)) return
        if (len(parent_of(path)) > 0) then
            call self%create_group(parent_of(path), error)
            if (allocated(error)) return
        end if
        did = -1
        sid = -1
        steps: block
            if (self%exists(path)) then
                call h5ldelete_f(self%id, path, st)
                call note(st, 'H5Ldelete', failed)
                if (allocated(failed)) exit steps
            end if
            call h5screate_simple_f(size(dims), dims, sid, st)
            call note(st, 'H5Screate_simple', failed)
            if (allocated(failed)) exit steps
            call h5dcreate_f(self%id, path, dtype, sid, did, st)
            call note(st, 'H5Dcreate', failed)
            if (allocated(failed)) exit steps
            ! (an empty dataset has nothing to write, and HDF5 refuses a null buffer)
            if (product(dims) == 0) exit steps
            call h5dwrite_f(did, dtype, buf, st)
            call note(st, 'H5Dwrite', failed)
        end block steps
        call release(did, failed)
        call release(sid, failed)
        if (allocated(failed)) call fatal_error(error, self%path//": writing dataset '"//path// &
                                                "' failed in "//failed)
    end subroutine write_dataset

    !> Parent group of a path ('/a/b/c' -> '/a/b'); '' for top-level names.
    pure function parent_of(path) result(parent)
        character(len=*), intent(in) :: path
        character(len=:), allocatable :: parent
        integer :: i
        i = index(path, '/', back=.true.)
        parent = path(1:max(i - 1, 0))
    end function parent_of

end module voiga_io_hdf5
