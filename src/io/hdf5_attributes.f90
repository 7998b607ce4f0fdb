!> Attributes of the HDF5 file object (`voiga_io_hdf5`): scalar string, integer and
!> real attributes written and read with every status checked. A submodule only to
!> keep the files short; the interfaces and their documentation are in the module.
submodule(voiga_io_hdf5) voiga_io_hdf5_attributes
    use, intrinsic :: iso_c_binding, only: c_f_pointer, c_char, c_null_char, c_associated
    use hdf5, only: size_t, h5acreate_f, h5aopen_f, h5awrite_f, h5aread_f, h5aexists_f, &
                    h5adelete_f, h5aget_type_f, h5aget_space_f, h5screate_f, H5S_SCALAR_F, &
                    h5sget_simple_extent_npoints_f, h5tcopy_f, h5tset_size_f, h5tget_size_f, &
                    h5tis_variable_str_f, H5T_STRING_F, H5T_FORTRAN_S1, h5dvlen_reclaim_f, &
                    H5P_DEFAULT_F, h5oopen_f, h5oclose_f
    implicit none

contains

    module procedure attr_write_str
        type(error_t), allocatable :: outcome
        if (self%skips(present(error))) return
        call write_string(self, path, name, value, outcome)
        call self%hand_over(outcome, error)
    end procedure attr_write_str

    module procedure attr_write_int
        call write_scalar(self, path, name, H5T_NATIVE_INTEGER, c_loc(value), error)
    end procedure attr_write_int

    module procedure attr_write_real
        call write_scalar(self, path, name, H5T_NATIVE_DOUBLE, c_loc(value), error)
    end procedure attr_write_real

    !> `write_attribute`, its failure to `error` or, without one, kept by the file.
    subroutine write_scalar(self, path, name, dtype, buf, error)
        class(h5file_t), intent(inout) :: self
        character(len=*), intent(in) :: path, name
        integer(hid_t), intent(in) :: dtype
        type(c_ptr), intent(in) :: buf
        type(error_t), allocatable, intent(out), optional :: error
        type(error_t), allocatable :: outcome
        if (self%skips(present(error))) return
        call write_attribute(self, path, name, dtype, buf, outcome)
        call self%hand_over(outcome, error)
    end subroutine write_scalar

    !> Write the string attribute `name` of `path` (`attr_write_str`).
    subroutine write_string(self, path, name, value, error)
        class(h5file_t), intent(inout) :: self
        character(len=*), intent(in) :: path, name, value
        type(error_t), allocatable, intent(out) :: error
        character(len=max(len(value), 1)), target :: text
        integer(hid_t) :: tid
        integer :: st
        character(len=:), allocatable :: failed

        text = value
        tid = -1
        call h5tcopy_f(H5T_FORTRAN_S1, tid, st)
        call note(st, 'H5Tcopy', failed)
        if (.not. allocated(failed)) then
            call h5tset_size_f(tid, int(len(text), size_t), st)
            call note(st, 'H5Tset_size', failed)
        end if
        if (.not. allocated(failed)) call write_attribute(self, path, name, tid, c_loc(text), error)
        call release(tid, failed)
        if (allocated(failed) .and. .not. allocated(error)) &
            call fatal_error(error, self%path//": writing attribute '"//name//"' of '"//path// &
                             "' failed in "//failed)
    end subroutine write_string

    !> Write the scalar attribute `name` of object `path` (a group is created if
    !> `path` is missing; '/' is the root) from `buf`, of type `dtype` in memory and
    !> in the file, replacing an attribute of that name.
    subroutine write_attribute(self, path, name, dtype, buf, error)
        class(h5file_t), intent(inout) :: self
        character(len=*), intent(in) :: path, name
        integer(hid_t), intent(in) :: dtype
        type(c_ptr), intent(in) :: buf
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: oid, sid, aid
        integer :: st
        logical :: exists
        character(len=:), allocatable :: failed

        if (not_open(self%id, path, error)) return
        if (path /= '/' .and. .not. self%exists(path)) then
            call self%create_group(path, error)
            if (allocated(error)) return
        end if
        oid = -1
        sid = -1
        aid = -1
        steps: block
            call h5oopen_f(self%id, path, oid, st)
            call note(st, 'H5Oopen', failed)
            if (allocated(failed)) exit steps
            call h5aexists_f(oid, name, exists, st)
            call note(st, 'H5Aexists', failed)
            if (allocated(failed)) exit steps
            if (exists) call h5adelete_f(oid, name, st)
            call note(st, 'H5Adelete', failed)
            if (allocated(failed)) exit steps
            call h5screate_f(H5S_SCALAR_F, sid, st)
            call note(st, 'H5Screate', failed)
            if (allocated(failed)) exit steps
            call h5acreate_f(oid, name, dtype, sid, aid, st)
            call note(st, 'H5Acreate', failed)
            if (allocated(failed)) exit steps
            call h5awrite_f(aid, dtype, buf, st)
            call note(st, 'H5Awrite', failed)
        end block steps
        call release(aid, failed)
        call release(sid, failed)
        call release(oid, failed)
        if (allocated(failed)) call fatal_error(error, self%path//": writing attribute '"//name// &
                                                "' of '"//path//"' failed in "//failed)
    end subroutine write_attribute

    module procedure attr_exists
        integer(hid_t) :: oid
        integer :: st
        attr_exists = .false.
        if (path /= '/' .and. .not. self%exists(path)) return
        call h5oopen_f(self%id, path, oid, st)
        if (st /= 0) return
        call h5aexists_f(oid, name, attr_exists, st)
        if (st /= 0) attr_exists = .false.
        call h5oclose_f(oid, st)
    end procedure attr_exists

    !> Open attribute `name` of object `path` (handles `oid`, `aid`, -1 when not
    !> opened), its file type `tid` and its type class, checked to hold one value of a
    !> type class in `classes`; `what` names the expected kind in messages.
    subroutine attr_open(self, path, name, classes, what, oid, aid, tid, error)
        class(h5file_t), intent(inout) :: self
        character(len=*), intent(in) :: path, name
        integer, intent(in) :: classes(:)
        character(len=*), intent(in) :: what
        integer(hid_t), intent(out) :: oid, aid, tid
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: sid
        integer(hsize_t) :: npoints
        integer :: st, type_class
        character(len=:), allocatable :: failed, object

        oid = -1
        aid = -1
        tid = -1
        sid = -1
        object = self%path//": attribute '"//name//"' of '"//path//"'"
        if (.not. self%has_attr(path, name)) then
            call fatal_error(error, object//' is missing', error_code%input)
            return
        end if
        steps: block
            call h5oopen_f(self%id, path, oid, st)
            call note(st, 'H5Oopen', failed)
            if (allocated(failed)) exit steps
            call h5aopen_f(oid, name, aid, st)
            call note(st, 'H5Aopen', failed)
            if (allocated(failed)) exit steps
            call h5aget_space_f(aid, sid, st)
            call note(st, 'H5Aget_space', failed)
            if (allocated(failed)) exit steps
            call h5sget_simple_extent_npoints_f(sid, npoints, st)
            call note(st, 'H5Sget_simple_extent_npoints', failed)
            call h5aget_type_f(aid, tid, st)
            call note(st, 'H5Aget_type', failed)
            if (allocated(failed)) exit steps
            call h5tget_class_f(tid, type_class, st)
            call note(st, 'H5Tget_class', failed)
        end block steps
        call release(sid, failed)
        if (allocated(failed)) then
            call fatal_error(error, object//': reading failed in '//failed, error_code%input)
        else if (npoints /= 1) then
            call fatal_error(error, object//' holds more than one value', error_code%input)
        else if (all(classes /= type_class)) then
            call fatal_error(error, object//' holds '//class_name(type_class)//', not '//what, &
                             error_code%input)
        end if
        if (allocated(error)) call attr_close(oid, aid, tid, failed)
    end subroutine attr_open

    !> Close what `attr_open` opened; the first failure is kept in `failed`.
    subroutine attr_close(oid, aid, tid, failed)
        integer(hid_t), intent(inout) :: oid, aid, tid
        character(len=:), allocatable, intent(inout) :: failed
        call release(tid, failed)
        call release(aid, failed)
        call release(oid, failed)
    end subroutine attr_close

    module procedure attr_read_str
        integer(hid_t) :: oid, aid, ftid, mtid
        integer(size_t) :: n
        integer :: st
        logical :: is_vlen
        character(len=:), allocatable :: failed

        value = ''
        call attr_open(self, path, name, [H5T_STRING_F], 'a string', oid, aid, ftid, error)
        if (allocated(error)) return
        mtid = -1
        steps: block
            call h5tis_variable_str_f(ftid, is_vlen, st)
            call note(st, 'H5Tis_variable_str', failed)
            if (allocated(failed)) exit steps
            if (is_vlen) then
                call read_vlen_string(aid, ftid, value, failed)
                exit steps
            end if
            call h5tget_size_f(ftid, n, st)
            call note(st, 'H5Tget_size', failed)
            if (allocated(failed)) exit steps
            call h5tcopy_f(H5T_FORTRAN_S1, mtid, st)
            call note(st, 'H5Tcopy', failed)
            if (allocated(failed)) exit steps
            call h5tset_size_f(mtid, n, st)
            call note(st, 'H5Tset_size', failed)
            if (allocated(failed)) exit steps
            call read_fixed_string(aid, mtid, int(n), value, failed)
        end block steps
        call release(mtid, failed)
        call attr_close(oid, aid, ftid, failed)
        if (allocated(failed)) call fatal_error(error, self%path//": reading attribute '"// &
                                                name//"' of '"//path//"' failed in "//failed, &
                                                error_code%input)
    end procedure attr_read_str

    !> Read the fixed-length string attribute `aid` (memory type `mtid`, `n` characters).
    subroutine read_fixed_string(aid, mtid, n, value, failed)
        integer(hid_t), intent(in) :: aid, mtid
        integer, intent(in) :: n
        character(len=:), allocatable, intent(out) :: value
        character(len=:), allocatable, intent(inout) :: failed
        character(len=:), allocatable, target :: buf
        type(c_ptr) :: p
        integer :: st, i

        allocate (character(len=n) :: buf)
        p = c_loc(buf)
        call h5aread_f(aid, mtid, p, st)
        call note(st, 'H5Aread', failed)
        do i = 1, len(buf)
            if (buf(i:i) == c_null_char) buf(i:i) = ' '
        end do
        value = trim(buf)
    end subroutine read_fixed_string

    !> Read the variable-length string attribute `aid` of file type `ftid` (the
    !> memory type too: HDF5 converts no variable-length to fixed-length strings),
    !> up to its NUL or 4096 characters, and give HDF5 back the memory it allocated.
    subroutine read_vlen_string(aid, ftid, value, failed)
        integer(hid_t), intent(in) :: aid, ftid
        character(len=:), allocatable, intent(out) :: value
        character(len=:), allocatable, intent(inout) :: failed
        integer, parameter :: max_len = 4096
        type(c_ptr), target :: vptr(1)
        character(kind=c_char), pointer :: cstr(:)
        type(c_ptr) :: p
        integer(hid_t) :: sid
        integer :: st, i

        value = ''
        sid = -1
        p = c_loc(vptr(1))
        call h5aread_f(aid, ftid, p, st)
        call note(st, 'H5Aread', failed)
        if (allocated(failed)) return
        if (c_associated(vptr(1))) then
            call c_f_pointer(vptr(1), cstr, [max_len])
            do i = 1, max_len
                if (cstr(i) == c_null_char) exit
                value = value//cstr(i)
            end do
        end if
        call h5aget_space_f(aid, sid, st)
        call note(st, 'H5Aget_space', failed)
        if (st == 0) then
            call h5dvlen_reclaim_f(ftid, sid, H5P_DEFAULT_F, p, st)
            call note(st, 'H5Dvlen_reclaim', failed)
        end if
        call release(sid, failed)
    end subroutine read_vlen_string

    module procedure attr_read_int
        integer(int64), target :: wide(1)

        value = 0
        call read_attribute(self, path, name, [H5T_INTEGER_F], 'an integer', &
                            h5kind_to_type(int64, H5_INTEGER_KIND), c_loc(wide), error)
        if (allocated(error)) return
        if (.not. fits_integer(wide)) then
            call fatal_error(error, self%path//": attribute '"//name//"' of '"//path// &
                             "' is too large for a default integer", error_code%input)
            return
        end if
        value = int(wide(1))
    end procedure attr_read_int

    module procedure attr_read_real
        value = 0.0_dp
        call read_attribute(self, path, name, [H5T_INTEGER_F, H5T_FLOAT_F], 'a number', &
                            H5T_NATIVE_DOUBLE, c_loc(value), error)
    end procedure attr_read_real

    !> Read the one value of attribute `name` of `path`, of a type class in `classes`, as
    !> HDF5 type `mem_type` into `buf`.
    subroutine read_attribute(self, path, name, classes, what, mem_type, buf, error)
        class(h5file_t), intent(inout) :: self
        character(len=*), intent(in) :: path, name
        integer, intent(in) :: classes(:)
        character(len=*), intent(in) :: what
        integer(hid_t), intent(in) :: mem_type
        type(c_ptr), intent(in) :: buf
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: oid, aid, tid
        integer :: st
        character(len=:), allocatable :: failed
        type(c_ptr) :: p

        call attr_open(self, path, name, classes, what, oid, aid, tid, error)
        if (allocated(error)) return
        p = buf
        call h5aread_f(aid, mem_type, p, st)
        call note(st, 'H5Aread', failed)
        call attr_close(oid, aid, tid, failed)
        if (allocated(failed)) call fatal_error(error, self%path//": reading attribute '"// &
                                                name//"' of '"//path//"' failed in "//failed, &
                                                error_code%input)
    end subroutine read_attribute

end submodule voiga_io_hdf5_attributes
