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
                    H5F_ACC_RDONLY_F, H5F_ACC_RDWR_F, H5F_ACC_TRUNC_F, H5F_SCOPE_GLOBAL_F, &
                    h5dopen_f, h5dcreate_f, h5dwrite_f, h5dread_f, h5dget_space_f, h5dget_type_f, &
                    h5screate_simple_f, h5sget_simple_extent_ndims_f, h5sget_simple_extent_dims_f, &
                    h5gcreate_f, h5lexists_f, h5ldelete_f, h5tget_class_f, H5T_INTEGER_F, &
                    H5T_FLOAT_F, H5T_NATIVE_DOUBLE, H5T_NATIVE_INTEGER, h5kind_to_type, &
                    H5_INTEGER_KIND, h5eset_auto_f, h5pcreate_f, h5pclose_f, h5pset_file_locking_f, &
                    H5P_FILE_ACCESS_F
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_io_hdf5_status, only: note, release, class_name, not_open, fits_integer
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
    contains
        procedure :: open => file_open
        procedure :: close => file_close
        procedure :: flush => file_flush
        procedure :: exists => file_exists
        procedure :: is_open => file_is_open
        !> Write a real (64-bit) or integer array of any rank, or a scalar.
        generic :: write => write_real, write_int
        procedure, private :: write_real, write_int
        !> Read into an allocatable real array of rank 0 to 3 or integer array of rank 0 or 1.
        generic :: read => read_real, read_int
        procedure, private :: read_real, read_int
        generic :: write_attr => attr_write_str, attr_write_int, attr_write_real
        procedure, private :: attr_write_str, attr_write_int, attr_write_real
        procedure :: read_attr_str => attr_read_str
        procedure :: read_attr_int => attr_read_int
        procedure :: read_attr_real => attr_read_real
        procedure :: has_attr => attr_exists
        procedure :: shape => dataset_shape
        procedure :: create_group => group_create
        final :: file_finalize
    end type h5file_t

    interface

        !> Write a string attribute (fixed-length ASCII; an empty string is stored as ' ').
        module subroutine attr_write_str(self, path, name, value, error)
            class(h5file_t), intent(inout) :: self
            character(len=*), intent(in) :: path, name, value
            type(error_t), allocatable, intent(out) :: error
        end subroutine attr_write_str

        !> Write an integer attribute (native integer).
        module subroutine attr_write_int(self, path, name, value, error)
            class(h5file_t), intent(inout) :: self
            character(len=*), intent(in) :: path, name
            integer, target, intent(in) :: value
            type(error_t), allocatable, intent(out) :: error
        end subroutine attr_write_int

        !> Write a real attribute (64-bit float).
        module subroutine attr_write_real(self, path, name, value, error)
            class(h5file_t), intent(inout) :: self
            character(len=*), intent(in) :: path, name
            real(dp), target, intent(in) :: value
            type(error_t), allocatable, intent(out) :: error
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

    !> Open `path`: mode 'r' read-only, 'rw' read-write, 'w' create (truncate).
    !> A file this object had open is closed first. HDF5's own file locking is off:
    !> a result file is guarded by the writer's lock file and its `flock` while a
    !> step is written (`voiga_io_results`, docs/hdf5.md), whatever
    !> HDF5_USE_FILE_LOCKING says, and HDF5's lock would exclude that `flock`.
    subroutine file_open(self, path, mode, error)
        class(h5file_t), intent(inout) :: self
        character(len=*), intent(in) :: path, mode
        type(error_t), allocatable, intent(out) :: error
        integer :: st
        integer(hid_t) :: fapl
        logical :: present

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
            inquire (file=path, exist=present)
            if (.not. present) then
                call fatal_error(error, "file '"//path//"' does not exist", error_code%input)
            else
                call h5fopen_f(path, merge(H5F_ACC_RDONLY_F, H5F_ACC_RDWR_F, mode == 'r'), self%id, st, &
                               access_prp=fapl)
                if (st /= 0) then
                    self%id = -1
                    call fatal_error(error, "file '"//path//"' is not a readable HDF5 file", &
                                     error_code%input)
                end if
            end if
        case ('w')
            call h5fcreate_f(path, H5F_ACC_TRUNC_F, self%id, st, access_prp=fapl)
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
        if (st /= 0) call fatal_error(error, self%path//": closing the file failed in H5Fclose "// &
                                      "(what was written may not be on disk)")
    end subroutine file_close

    !> Last resort for a file nobody closed: close it, ignoring the status (there
    !> is nobody left to tell).
    subroutine file_finalize(self)
        type(h5file_t), intent(inout) :: self
        integer :: st
        if (self%id >= 0) call h5fclose_f(self%id, st)
        self%id = -1
    end subroutine file_finalize

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
        if (st /= 0) call fatal_error(error, self%path//": flushing the file failed in "// &
                                      "H5Fflush (is the disk full?)")
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
    end subroutine group_create

    !> Write a real array of any rank (a scalar as one element) as 64-bit floats.
    subroutine write_real(self, path, array, error)
        class(h5file_t), intent(inout) :: self
        character(len=*), intent(in) :: path
        real(dp), contiguous, target, intent(in) :: array(..)
        type(error_t), allocatable, intent(out) :: error
        call write_dataset(self, path, H5T_NATIVE_DOUBLE, &
                           written_dims(shape(array, kind=hsize_t)), c_loc(array), error)
    end subroutine write_real

    !> Write an integer array of any rank (a scalar as one element) as native integers.
    subroutine write_int(self, path, array, error)
        class(h5file_t), intent(inout) :: self
        character(len=*), intent(in) :: path
        integer, contiguous, target, intent(in) :: array(..)
        type(error_t), allocatable, intent(out) :: error
        call write_dataset(self, path, H5T_NATIVE_INTEGER, &
                           written_dims(shape(array, kind=hsize_t)), c_loc(array), error)
    end subroutine write_int

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

    !> Read a real dataset of the array's rank (rank 0: a scalar or one-element dataset),
    !> converting integers and other floats.
    subroutine read_real(self, path, array, error)
        class(h5file_t), intent(in) :: self
        character(len=*), intent(in) :: path
        real(dp), allocatable, target, intent(out) :: array(..)
        type(error_t), allocatable, intent(out) :: error
        integer(hsize_t), allocatable :: dims(:)

        call dataset_layout(self, path, rank(array), .true., dims, error)
        if (allocated(error)) return
        select rank (array)
        rank (0)
            allocate (array)
        rank (1)
            allocate (array(dims(1)))
        rank (2)
            allocate (array(dims(1), dims(2)))
        rank (3)
            allocate (array(dims(1), dims(2), dims(3)))
        rank default
            call unsupported_rank(self, path, rank(array), error)
            return
        end select
        call read_dataset(self, path, H5T_NATIVE_DOUBLE, product(dims), c_loc(array), error)
    end subroutine read_real

    !> Read an integer dataset (any integer width) of the array's rank; its values
    !> must fit a default integer.
    subroutine read_int(self, path, array, error)
        class(h5file_t), intent(in) :: self
        character(len=*), intent(in) :: path
        integer, allocatable, intent(out) :: array(..)
        type(error_t), allocatable, intent(out) :: error
        integer(hsize_t), allocatable :: dims(:)
        integer(int64), allocatable, target :: wide(:)

        call dataset_layout(self, path, rank(array), .false., dims, error)
        if (allocated(error)) return
        allocate (wide(product(dims)))
        call read_dataset(self, path, h5kind_to_type(int64, H5_INTEGER_KIND), product(dims), &
                          c_loc(wide), error)
        if (allocated(error)) return
        if (.not. fits_integer(wide)) then
            call fatal_error(error, self%path//": dataset '"//path// &
                             "' holds integers too large for a default integer", error_code%input)
            return
        end if
        select rank (array)
        rank (0)
            allocate (array)
            array = int(wide(1))
        rank (1)
            allocate (array(dims(1)))
            array = int(wide)
        rank default
            call unsupported_rank(self, path, rank(array), error)
        end select
    end subroutine read_int

    !> The error for an array rank `read` has no branch for.
    subroutine unsupported_rank(self, path, array_rank, error)
        class(h5file_t), intent(in) :: self
        character(len=*), intent(in) :: path
        integer, intent(in) :: array_rank
        type(error_t), allocatable, intent(out) :: error
        character(len=12) :: buf
        write (buf, '(i0)') array_rank
        call fatal_error(error, self%path//": reading dataset '"//path// &
                         "' into an array of rank "//trim(buf)//" is not supported")
    end subroutine unsupported_rank

    !> Shape (Fortran order) of dataset `path`, checked to be readable as an array of
    !> rank `array_rank` (rank 0 takes a scalar or one-element dataset) holding
    !> reals (`as_real`: integer or float datasets) or integers (integer datasets).
    subroutine dataset_layout(self, path, array_rank, as_real, dims, error)
        class(h5file_t), intent(in) :: self
        character(len=*), intent(in) :: path
        integer, intent(in) :: array_rank
        logical, intent(in) :: as_real
        integer(hsize_t), allocatable, intent(out) :: dims(:)
        type(error_t), allocatable, intent(out) :: error
        integer :: type_class
        character(len=32) :: buf
        character(len=:), allocatable :: expected

        call dataset_info(self, path, dims, type_class, error)
        if (allocated(error)) return
        expected = merge('numbers ', 'integers', as_real)
        if (.not. (type_class == H5T_INTEGER_F .or. &
                   (as_real .and. type_class == H5T_FLOAT_F))) then
            call fatal_error(error, self%path//": dataset '"//path//"' holds "// &
                             class_name(type_class)//", not "//trim(expected), error_code%input)
            return
        end if
        if (array_rank == 0 .and. product(dims) == 1 .and. size(dims) <= 1) then
            dims = [integer(hsize_t) ::]
        else if (size(dims) /= array_rank) then
            write (buf, '(i0,a,i0)') size(dims), ', expected ', array_rank
            call fatal_error(error, self%path//": dataset '"//path//"' has rank "//trim(buf), &
                             error_code%input)
        end if
    end subroutine dataset_layout

    !> Shape (Fortran order) and HDF5 type class of dataset `path`.
    subroutine dataset_info(self, path, dims, type_class, error)
        class(h5file_t), intent(in) :: self
        character(len=*), intent(in) :: path
        integer(hsize_t), allocatable, intent(out) :: dims(:)
        integer, intent(out) :: type_class
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: did, sid, tid
        integer(hsize_t), allocatable :: maxdims(:)
        integer :: st, ndims
        character(len=:), allocatable :: failed

        type_class = -1
        allocate (dims(0))
        if (not_open(self%id, path, error)) return
        if (.not. self%exists(path)) then
            call fatal_error(error, self%path//": dataset '"//path//"' is missing", &
                             error_code%input)
            return
        end if
        sid = -1
        tid = -1
        call h5dopen_f(self%id, path, did, st)
        if (st /= 0) then
            call fatal_error(error, self%path//": '"//path//"' is not a dataset", error_code%input)
            return
        end if
        steps: block
            call h5dget_type_f(did, tid, st)
            call note(st, 'H5Dget_type', failed)
            if (allocated(failed)) exit steps
            call h5tget_class_f(tid, type_class, st)
            call note(st, 'H5Tget_class', failed)
            call h5dget_space_f(did, sid, st)
            call note(st, 'H5Dget_space', failed)
            if (allocated(failed)) exit steps
            call h5sget_simple_extent_ndims_f(sid, ndims, st)
            call note(st, 'H5Sget_simple_extent_ndims', failed)
            if (allocated(failed)) exit steps
            deallocate (dims)
            allocate (dims(ndims), maxdims(ndims))
            call h5sget_simple_extent_dims_f(sid, dims, maxdims, st)
            ! (returns the rank on success)
            call note(merge(0, -1, st == ndims), 'H5Sget_simple_extent_dims', failed)
        end block steps
        call release(tid, failed)
        call release(sid, failed)
        call release(did, failed)
        if (allocated(failed)) call fatal_error(error, self%path//": inspecting dataset '"//path// &
                                                "' failed in "//failed, error_code%input)
    end subroutine dataset_info

    !> Read all `n` values of dataset `path` as HDF5 type `mem_type` into `buf`.
    subroutine read_dataset(self, path, mem_type, n, buf, error)
        class(h5file_t), intent(in) :: self
        character(len=*), intent(in) :: path
        integer(hid_t), intent(in) :: mem_type
        integer(hsize_t), intent(in) :: n
        type(c_ptr), intent(in) :: buf
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: did
        integer :: st
        character(len=:), allocatable :: failed
        type(c_ptr) :: p

        if (n == 0) return
        p = buf
        did = -1
        call h5dopen_f(self%id, path, did, st)
        call note(st, 'H5Dopen', failed)
        if (.not. allocated(failed)) then
            call h5dread_f(did, mem_type, p, st)
            call note(st, 'H5Dread', failed)
        end if
        call release(did, failed)
        if (allocated(failed)) call fatal_error(error, self%path//": reading dataset '"//path// &
                                                "' failed in "//failed, error_code%input)
    end subroutine read_dataset

    !> Shape of dataset `path` in Fortran order (empty if missing or unreadable).
    function dataset_shape(self, path) result(dims)
        class(h5file_t), intent(in) :: self
        character(len=*), intent(in) :: path
        integer, allocatable :: dims(:)
        integer(hsize_t), allocatable :: d(:)
        integer :: type_class
        type(error_t), allocatable :: error
        call dataset_info(self, path, d, type_class, error)
        if (allocated(error)) then
            allocate (dims(0))
        else
            dims = int(d)
        end if
    end function dataset_shape

    !> Parent group of a path ('/a/b/c' -> '/a/b'); '' for top-level names.
    pure function parent_of(path) result(parent)
        character(len=*), intent(in) :: path
        character(len=:), allocatable :: parent
        integer :: i
        i = index(path, '/', back=.true.)
        parent = path(1:max(i - 1, 0))
    end function parent_of

end module voiga_io_hdf5
