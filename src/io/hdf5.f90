!> A small HDF5 file object over the raw Fortran API.
!>
!> `call h%open(path, 'r'|'w'|'rw', error)`, `h%write(path, array)`, `h%read(path, array, error)`,
!> attributes with `h%write_attr(path, name, value)`, `h%close()`. Paths are absolute
!> ('/bodies/die/knots_xi'); missing parent groups are created on write. Every handle
!> is closed on every path, and a finalizer closes a forgotten file. Arrays are
!> written in Fortran order, so h5py shows them with the axes reversed (docs/formats.md).
!> Strings are written as fixed-length ASCII; both fixed and variable-length
!> string attributes are read.
module voiga_io_hdf5
    use, intrinsic :: iso_c_binding, only: c_ptr, c_loc, c_f_pointer, c_char, c_size_t, c_null_char
    use hdf5, only: hid_t, hsize_t, size_t, h5open_f, h5fopen_f, h5fcreate_f, h5fclose_f, h5fflush_f, &
                    H5F_ACC_RDONLY_F, H5F_ACC_RDWR_F, H5F_ACC_TRUNC_F, H5F_SCOPE_GLOBAL_F, &
                    h5dopen_f, h5dclose_f, h5dcreate_f, h5dwrite_f, h5dread_f, h5dget_space_f, &
                    h5dvlen_reclaim_f, H5P_DEFAULT_F, &
                    h5screate_simple_f, h5screate_f, h5sclose_f, h5sget_simple_extent_ndims_f, &
                    h5sget_simple_extent_dims_f, H5S_SCALAR_F, &
                    h5gcreate_f, h5gclose_f, h5lexists_f, h5ldelete_f, &
                    h5acreate_f, h5aopen_f, h5aclose_f, h5awrite_f, h5aread_f, h5aexists_f, &
                    h5aget_type_f, h5aget_space_f, h5adelete_f, &
                    h5tcopy_f, h5tclose_f, h5tset_size_f, h5tget_size_f, h5tis_variable_str_f, &
                    H5T_NATIVE_DOUBLE, H5T_NATIVE_INTEGER, H5T_FORTRAN_S1, H5T_STRING, &
                    h5eset_auto_f, h5oopen_f, h5oclose_f
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    implicit none
    private

    public :: h5file_t

    !> An open HDF5 file.
    type :: h5file_t
        integer(hid_t) :: id = -1
        character(len=:), allocatable :: path
    contains
        procedure :: open => file_open
        procedure :: close => file_close
        procedure :: flush => file_flush
        procedure :: exists => file_exists
        procedure :: is_open => file_is_open
        generic :: write => write_r1, write_r2, write_r3, write_i1, write_i0, write_r0
        procedure, private :: write_r1, write_r2, write_r3, write_i1, write_i0, write_r0
        generic :: read => read_r1, read_r2, read_r3, read_i1
        procedure, private :: read_r1, read_r2, read_r3, read_i1
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

contains

    !> Open `path`: mode 'r' read-only, 'rw' read-write, 'w' create (truncate).
    subroutine file_open(self, path, mode, error)
        class(h5file_t), intent(inout) :: self
        character(len=*), intent(in) :: path, mode
        type(error_t), allocatable, intent(out) :: error
        integer :: st
        logical :: present

        if (self%id >= 0) call self%close()
        call h5open_f(st)
        ! we report errors ourselves
        call h5eset_auto_f(0, st)
        select case (mode)
        case ('r', 'rw')
            inquire (file=path, exist=present)
            if (.not. present) then
                call fatal_error(error, "file '"//path//"' does not exist", error_code%input)
                return
            end if
            call h5fopen_f(path, merge(H5F_ACC_RDONLY_F, H5F_ACC_RDWR_F, mode == 'r'), self%id, st)
            if (st /= 0) then
                self%id = -1
                call fatal_error(error, "file '"//path//"' is not a readable HDF5 file", error_code%input)
                return
            end if
        case ('w')
            call h5fcreate_f(path, H5F_ACC_TRUNC_F, self%id, st)
            if (st /= 0) then
                self%id = -1
                call fatal_error(error, "cannot create HDF5 file '"//path//"'", error_code%input)
                return
            end if
        case default
            call fatal_error(error, "unknown HDF5 open mode '"//mode//"'")
            return
        end select
        self%path = path
    end subroutine file_open

    !> Close the file (no-op if it is not open).
    subroutine file_close(self)
        class(h5file_t), intent(inout) :: self
        integer :: st
        if (self%id >= 0) call h5fclose_f(self%id, st)
        self%id = -1
    end subroutine file_close

    subroutine file_finalize(self)
        type(h5file_t), intent(inout) :: self
        call file_close(self)
    end subroutine file_finalize

    !> Is the file open?
    logical function file_is_open(self)
        class(h5file_t), intent(in) :: self
        file_is_open = self%id >= 0
    end function file_is_open

    !> Write buffers to disk so that a later crash keeps what was written.
    subroutine file_flush(self)
        class(h5file_t), intent(in) :: self
        integer :: st
        if (self%id >= 0) call h5fflush_f(self%id, H5F_SCOPE_GLOBAL_F, st)
    end subroutine file_flush

    !> Does the object (group or dataset) at `path` exist?
    logical function file_exists(self, path)
        class(h5file_t), intent(in) :: self
        character(len=*), intent(in) :: path
        integer :: st, i
        logical :: ok
        file_exists = .false.
        if (self%id < 0) return
        ! check each parent first: H5Lexists fails on a path with a missing parent
        do i = 2, len(path) - 1
            if (path(i:i) /= '/') cycle
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

    !> Create the group `path` and any missing parents.
    subroutine group_create(self, path)
        class(h5file_t), intent(inout) :: self
        character(len=*), intent(in) :: path
        integer :: i, st
        integer(hid_t) :: gid
        do i = 2, len(path) + 1
            if (i <= len(path)) then
                if (path(i:i) /= '/') cycle
            end if
            if (.not. self%exists(path(1:i - 1))) then
                call h5gcreate_f(self%id, path(1:i - 1), gid, st)
                if (st == 0) call h5gclose_f(gid, st)
            end if
        end do
    end subroutine group_create

    !> Parent group of a path ('/a/b/c' -> '/a/b'); '' for top-level names.
    pure function parent_of(path) result(parent)
        character(len=*), intent(in) :: path
        character(len=:), allocatable :: parent
        integer :: i
        i = index(path, '/', back=.true.)
        parent = path(1:max(i - 1, 0))
    end function parent_of

    !> Create a dataset of the given type and shape (replacing nothing: the path must be new).
    subroutine create_dataset(self, path, dtype, dims, did, sid)
        class(h5file_t), intent(inout) :: self
        character(len=*), intent(in) :: path
        integer(hid_t), intent(in) :: dtype
        integer(hsize_t), intent(in) :: dims(:)
        integer(hid_t), intent(out) :: did, sid
        integer :: st
        if (len(parent_of(path)) > 0) call self%create_group(parent_of(path))
        ! a dataset that exists is replaced (a restarted run rewrites run-wide records)
        if (self%exists(path)) call h5ldelete_f(self%id, path, st)
        if (size(dims) == 0) then
            call h5screate_f(H5S_SCALAR_F, sid, st)
        else
            call h5screate_simple_f(size(dims), dims, sid, st)
        end if
        call h5dcreate_f(self%id, path, dtype, sid, did, st)
    end subroutine create_dataset

    subroutine write_r0(self, path, value)
        class(h5file_t), intent(inout) :: self
        character(len=*), intent(in) :: path
        real(dp), intent(in) :: value
        call self%write(path, [value])
    end subroutine write_r0

    subroutine write_r1(self, path, array)
        class(h5file_t), intent(inout) :: self
        character(len=*), intent(in) :: path
        real(dp), intent(in) :: array(:)
        integer(hid_t) :: did, sid
        integer(hsize_t) :: dims(1)
        integer :: st
        dims = shape(array, kind=hsize_t)
        call create_dataset(self, path, H5T_NATIVE_DOUBLE, dims, did, sid)
        call h5dwrite_f(did, H5T_NATIVE_DOUBLE, array, dims, st)
        call h5dclose_f(did, st)
        call h5sclose_f(sid, st)
    end subroutine write_r1

    subroutine write_r2(self, path, array)
        class(h5file_t), intent(inout) :: self
        character(len=*), intent(in) :: path
        real(dp), intent(in) :: array(:, :)
        integer(hid_t) :: did, sid
        integer(hsize_t) :: dims(2)
        integer :: st
        dims = shape(array, kind=hsize_t)
        call create_dataset(self, path, H5T_NATIVE_DOUBLE, dims, did, sid)
        call h5dwrite_f(did, H5T_NATIVE_DOUBLE, array, dims, st)
        call h5dclose_f(did, st)
        call h5sclose_f(sid, st)
    end subroutine write_r2

    subroutine write_r3(self, path, array)
        class(h5file_t), intent(inout) :: self
        character(len=*), intent(in) :: path
        real(dp), intent(in) :: array(:, :, :)
        integer(hid_t) :: did, sid
        integer(hsize_t) :: dims(3)
        integer :: st
        dims = shape(array, kind=hsize_t)
        call create_dataset(self, path, H5T_NATIVE_DOUBLE, dims, did, sid)
        call h5dwrite_f(did, H5T_NATIVE_DOUBLE, array, dims, st)
        call h5dclose_f(did, st)
        call h5sclose_f(sid, st)
    end subroutine write_r3

    subroutine write_i1(self, path, array)
        class(h5file_t), intent(inout) :: self
        character(len=*), intent(in) :: path
        integer, intent(in) :: array(:)
        integer(hid_t) :: did, sid
        integer(hsize_t) :: dims(1)
        integer :: st
        dims = shape(array, kind=hsize_t)
        call create_dataset(self, path, H5T_NATIVE_INTEGER, dims, did, sid)
        call h5dwrite_f(did, H5T_NATIVE_INTEGER, array, dims, st)
        call h5dclose_f(did, st)
        call h5sclose_f(sid, st)
    end subroutine write_i1

    subroutine write_i0(self, path, value)
        class(h5file_t), intent(inout) :: self
        character(len=*), intent(in) :: path
        integer, intent(in) :: value
        call self%write(path, [value])
    end subroutine write_i0

    !> Open dataset `path` and return its dims (Fortran order); error if missing
    !> or of another rank.
    subroutine open_dataset(self, path, rank, did, dims, error)
        class(h5file_t), intent(in) :: self
        character(len=*), intent(in) :: path
        integer, intent(in) :: rank
        integer(hid_t), intent(out) :: did
        integer(hsize_t), intent(out) :: dims(rank)
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: sid
        integer(hsize_t) :: maxdims(rank)
        integer :: st, ndims
        character(len=16) :: buf

        did = -1
        if (.not. self%exists(path)) then
            call fatal_error(error, self%path//": dataset '"//path//"' is missing", error_code%input)
            return
        end if
        call h5dopen_f(self%id, path, did, st)
        if (st /= 0) then
            did = -1
            call fatal_error(error, self%path//": '"//path//"' is not a dataset", error_code%input)
            return
        end if
        call h5dget_space_f(did, sid, st)
        call h5sget_simple_extent_ndims_f(sid, ndims, st)
        if (ndims /= rank) then
            call h5sclose_f(sid, st)
            call h5dclose_f(did, st)
            did = -1
            write (buf, '(i0,a,i0)') ndims, ' not ', rank
            call fatal_error(error, self%path//": dataset '"//path//"' has rank "//trim(buf), &
                             error_code%input)
            return
        end if
        call h5sget_simple_extent_dims_f(sid, dims, maxdims, st)
        call h5sclose_f(sid, st)
    end subroutine open_dataset

    !> Shape of dataset `path` in Fortran order (empty if missing).
    function dataset_shape(self, path) result(dims)
        class(h5file_t), intent(in) :: self
        character(len=*), intent(in) :: path
        integer, allocatable :: dims(:)
        integer(hid_t) :: did, sid
        integer(hsize_t) :: d(8), maxd(8)
        integer :: st, ndims
        allocate (dims(0))
        if (.not. self%exists(path)) return
        call h5dopen_f(self%id, path, did, st)
        if (st /= 0) return
        call h5dget_space_f(did, sid, st)
        call h5sget_simple_extent_ndims_f(sid, ndims, st)
        call h5sget_simple_extent_dims_f(sid, d(1:ndims), maxd(1:ndims), st)
        dims = int(d(1:ndims))
        call h5sclose_f(sid, st)
        call h5dclose_f(did, st)
    end function dataset_shape

    subroutine read_r1(self, path, array, error)
        class(h5file_t), intent(in) :: self
        character(len=*), intent(in) :: path
        real(dp), allocatable, intent(out) :: array(:)
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: did
        integer(hsize_t) :: dims(1)
        integer :: st
        call open_dataset(self, path, 1, did, dims, error)
        if (allocated(error)) return
        allocate (array(dims(1)))
        call h5dread_f(did, H5T_NATIVE_DOUBLE, array, dims, st)
        if (st /= 0) call read_failed(self, path, error)
        call h5dclose_f(did, st)
    end subroutine read_r1

    subroutine read_r2(self, path, array, error)
        class(h5file_t), intent(in) :: self
        character(len=*), intent(in) :: path
        real(dp), allocatable, intent(out) :: array(:, :)
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: did
        integer(hsize_t) :: dims(2)
        integer :: st
        call open_dataset(self, path, 2, did, dims, error)
        if (allocated(error)) return
        allocate (array(dims(1), dims(2)))
        call h5dread_f(did, H5T_NATIVE_DOUBLE, array, dims, st)
        if (st /= 0) call read_failed(self, path, error)
        call h5dclose_f(did, st)
    end subroutine read_r2

    subroutine read_r3(self, path, array, error)
        class(h5file_t), intent(in) :: self
        character(len=*), intent(in) :: path
        real(dp), allocatable, intent(out) :: array(:, :, :)
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: did
        integer(hsize_t) :: dims(3)
        integer :: st
        call open_dataset(self, path, 3, did, dims, error)
        if (allocated(error)) return
        allocate (array(dims(1), dims(2), dims(3)))
        call h5dread_f(did, H5T_NATIVE_DOUBLE, array, dims, st)
        if (st /= 0) call read_failed(self, path, error)
        call h5dclose_f(did, st)
    end subroutine read_r3

    subroutine read_i1(self, path, array, error)
        class(h5file_t), intent(in) :: self
        character(len=*), intent(in) :: path
        integer, allocatable, intent(out) :: array(:)
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: did
        integer(hsize_t) :: dims(1)
        integer :: st
        call open_dataset(self, path, 1, did, dims, error)
        if (allocated(error)) return
        allocate (array(dims(1)))
        call h5dread_f(did, H5T_NATIVE_INTEGER, array, dims, st)
        if (st /= 0) call read_failed(self, path, error)
        call h5dclose_f(did, st)
    end subroutine read_i1

    subroutine read_failed(self, path, error)
        class(h5file_t), intent(in) :: self
        character(len=*), intent(in) :: path
        type(error_t), allocatable, intent(out) :: error
        call fatal_error(error, self%path//": cannot read dataset '"//path// &
                         "' as numbers", error_code%input)
    end subroutine read_failed

    !> Open the object `path` ('/' for the root) for attribute work.
    subroutine open_object(self, path, oid, st)
        class(h5file_t), intent(inout) :: self
        character(len=*), intent(in) :: path
        integer(hid_t), intent(out) :: oid
        integer, intent(out) :: st
        if (path /= '/') then
            if (.not. self%exists(path)) call self%create_group(path)
        end if
        call h5oopen_f(self%id, path, oid, st)
    end subroutine open_object

    !> Write a string attribute (replacing an existing one).
    subroutine attr_write_str(self, path, name, value)
        class(h5file_t), intent(inout) :: self
        character(len=*), intent(in) :: path, name, value
        integer(hid_t) :: oid, aid, sid, tid
        integer(hsize_t) :: dims(1) = [1]
        integer :: st
        call open_object(self, path, oid, st)
        if (st /= 0) return
        call delete_attr(oid, name)
        call h5screate_f(H5S_SCALAR_F, sid, st)
        call h5tcopy_f(H5T_FORTRAN_S1, tid, st)
        call h5tset_size_f(tid, int(max(len(value), 1), size_t), st)
        call h5acreate_f(oid, name, tid, sid, aid, st)
        if (len(value) > 0) then
            call h5awrite_f(aid, tid, value, dims, st)
        else
            call h5awrite_f(aid, tid, ' ', dims, st)
        end if
        call h5aclose_f(aid, st)
        call h5tclose_f(tid, st)
        call h5sclose_f(sid, st)
        call h5oclose_f(oid, st)
    end subroutine attr_write_str

    subroutine attr_write_int(self, path, name, value)
        class(h5file_t), intent(inout) :: self
        character(len=*), intent(in) :: path, name
        integer, intent(in) :: value
        integer(hid_t) :: oid, aid, sid
        integer(hsize_t) :: dims(1) = [1]
        integer :: st
        call open_object(self, path, oid, st)
        if (st /= 0) return
        call delete_attr(oid, name)
        call h5screate_f(H5S_SCALAR_F, sid, st)
        call h5acreate_f(oid, name, H5T_NATIVE_INTEGER, sid, aid, st)
        call h5awrite_f(aid, H5T_NATIVE_INTEGER, value, dims, st)
        call h5aclose_f(aid, st)
        call h5sclose_f(sid, st)
        call h5oclose_f(oid, st)
    end subroutine attr_write_int

    subroutine attr_write_real(self, path, name, value)
        class(h5file_t), intent(inout) :: self
        character(len=*), intent(in) :: path, name
        real(dp), intent(in) :: value
        integer(hid_t) :: oid, aid, sid
        integer(hsize_t) :: dims(1) = [1]
        integer :: st
        call open_object(self, path, oid, st)
        if (st /= 0) return
        call delete_attr(oid, name)
        call h5screate_f(H5S_SCALAR_F, sid, st)
        call h5acreate_f(oid, name, H5T_NATIVE_DOUBLE, sid, aid, st)
        call h5awrite_f(aid, H5T_NATIVE_DOUBLE, value, dims, st)
        call h5aclose_f(aid, st)
        call h5sclose_f(sid, st)
        call h5oclose_f(oid, st)
    end subroutine attr_write_real

    !> Remove attribute `name` of object `oid` if it exists (attributes are overwritten).
    subroutine delete_attr(oid, name)
        integer(hid_t), intent(in) :: oid
        character(len=*), intent(in) :: name
        logical :: exists
        integer :: st
        call h5aexists_f(oid, name, exists, st)
        if (st == 0 .and. exists) call h5adelete_f(oid, name, st)
    end subroutine delete_attr

    !> Does object `path` have attribute `name`?
    logical function attr_exists(self, path, name)
        class(h5file_t), intent(inout) :: self
        character(len=*), intent(in) :: path, name
        integer(hid_t) :: oid
        integer :: st
        attr_exists = .false.
        if (path /= '/' .and. .not. self%exists(path)) return
        call h5oopen_f(self%id, path, oid, st)
        if (st /= 0) return
        call h5aexists_f(oid, name, attr_exists, st)
        if (st /= 0) attr_exists = .false.
        call h5oclose_f(oid, st)
    end function attr_exists

    !> Read a scalar string attribute, fixed or variable length (trailing blanks
    !> and NULs removed).
    subroutine attr_read_str(self, path, name, value, error)
        class(h5file_t), intent(inout) :: self
        character(len=*), intent(in) :: path, name
        character(len=:), allocatable, intent(out) :: value
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: oid, aid, ftid, mtid, sid
        integer(size_t) :: n
        integer :: st, i
        logical :: is_vlen
        character(len=:), allocatable, target :: buf
        type(c_ptr), target :: vptr(1)
        type(c_ptr) :: f_ptr
        character(kind=c_char), pointer :: cstr(:)

        if (.not. self%has_attr(path, name)) then
            call fatal_error(error, self%path//": attribute '"//name//"' of '"//path// &
                             "' is missing", error_code%input)
            return
        end if
        call h5oopen_f(self%id, path, oid, st)
        call h5aopen_f(oid, name, aid, st)
        call h5aget_type_f(aid, ftid, st)
        call h5tis_variable_str_f(ftid, is_vlen, st)
        if (st /= 0) then
            call h5tclose_f(ftid, st)
            call h5aclose_f(aid, st)
            call h5oclose_f(oid, st)
            call fatal_error(error, self%path//": attribute '"//name//"' of '"//path// &
                             "' is not a string", error_code%input)
            return
        end if
        if (is_vlen) then
            ! read with the file's own (variable-length string) type
            call h5tcopy_f(ftid, mtid, st)
            f_ptr = c_loc(vptr(1))
            call h5aread_f(aid, mtid, f_ptr, st)
            value = ''
            if (st == 0) then
                call c_f_pointer(vptr(1), cstr, [4096])
                do i = 1, 4096
                    if (cstr(i) == c_null_char) exit
                    value = value//cstr(i)
                end do
                call h5aget_space_f(aid, sid, st)
                call h5dvlen_reclaim_f(mtid, sid, H5P_DEFAULT_F, f_ptr, st)
                call h5sclose_f(sid, st)
            end if
            call h5tclose_f(mtid, st)
        else
            call h5tget_size_f(ftid, n, st)
            allocate (character(len=n) :: buf)
            call h5tcopy_f(H5T_FORTRAN_S1, mtid, st)
            call h5tset_size_f(mtid, n, st)
            f_ptr = c_loc(buf)
            call h5aread_f(aid, mtid, f_ptr, st)
            call h5tclose_f(mtid, st)
            do i = 1, len(buf)
                if (buf(i:i) == c_null_char) buf(i:i) = ' '
            end do
            value = trim(buf)
        end if
        call h5tclose_f(ftid, st)
        call h5aclose_f(aid, st)
        call h5oclose_f(oid, st)
    end subroutine attr_read_str

    !> Read a scalar integer attribute.
    subroutine attr_read_int(self, path, name, value, error)
        class(h5file_t), intent(inout) :: self
        character(len=*), intent(in) :: path, name
        integer, intent(out) :: value
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: oid, aid
        integer(hsize_t) :: dims(1) = [1]
        integer :: st
        value = 0
        if (.not. self%has_attr(path, name)) then
            call fatal_error(error, self%path//": attribute '"//name//"' of '"//path// &
                             "' is missing", error_code%input)
            return
        end if
        call h5oopen_f(self%id, path, oid, st)
        call h5aopen_f(oid, name, aid, st)
        call h5aread_f(aid, H5T_NATIVE_INTEGER, value, dims, st)
        call h5aclose_f(aid, st)
        call h5oclose_f(oid, st)
        if (st /= 0) call fatal_error(error, self%path//": attribute '"//name//"' of '"//path// &
                                      "' is not an integer", error_code%input)
    end subroutine attr_read_int

    !> Read a scalar real attribute.
    subroutine attr_read_real(self, path, name, value, error)
        class(h5file_t), intent(inout) :: self
        character(len=*), intent(in) :: path, name
        real(dp), intent(out) :: value
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: oid, aid
        integer(hsize_t) :: dims(1) = [1]
        integer :: st
        value = 0.0_dp
        if (.not. self%has_attr(path, name)) then
            call fatal_error(error, self%path//": attribute '"//name//"' of '"//path// &
                             "' is missing", error_code%input)
            return
        end if
        call h5oopen_f(self%id, path, oid, st)
        call h5aopen_f(oid, name, aid, st)
        call h5aread_f(aid, H5T_NATIVE_DOUBLE, value, dims, st)
        call h5aclose_f(aid, st)
        call h5oclose_f(oid, st)
        if (st /= 0) call fatal_error(error, self%path//": attribute '"//name//"' of '"//path// &
                                      "' is not an integer", error_code%input)
    end subroutine attr_read_real

end module voiga_io_hdf5
