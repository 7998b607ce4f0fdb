!> Status chaining for raw HDF5 calls: keep the name of the first call that failed,
!> close handles of any kind on every path, name type classes in messages, and the
!> checks shared by the file object's module and its attribute submodule.
!> Used by `voiga_io_hdf5`; a procedure runs its calls while nothing has failed,
!> then releases every handle it opened and turns `failed` into an `error_t`.
module voiga_io_hdf5_status
    use, intrinsic :: iso_fortran_env, only: int64
    use hdf5, only: hid_t, h5dclose_f, h5sclose_f, h5tclose_f, h5aclose_f, h5gclose_f, h5oclose_f, &
                    h5iget_type_f, H5I_DATASET_F, H5I_DATASPACE_F, H5I_DATATYPE_F, H5I_ATTR_F, &
                    H5I_GROUP_F, H5T_INTEGER_F, H5T_FLOAT_F, H5T_STRING_F, H5T_COMPOUND_F, &
                    H5T_ENUM_F
    use voiga_error, only: error_t, fatal_error
    implicit none
    private

    public :: note, release, class_name, not_open, fits_integer

contains

    !> Keep the name of the first HDF5 call that failed (status `st` /= 0) in `failed`.
    subroutine note(st, call_name, failed)
        integer, intent(in) :: st
        character(len=*), intent(in) :: call_name
        character(len=:), allocatable, intent(inout) :: failed
        if (st /= 0 .and. .not. allocated(failed)) failed = call_name
    end subroutine note

    !> Close the handle `id` of whatever kind (nothing if it is < 0) and set it to -1;
    !> a failure to close is noted like any other.
    subroutine release(id, failed)
        integer(hid_t), intent(inout) :: id
        character(len=:), allocatable, intent(inout) :: failed
        integer :: kind, st
        if (id < 0) return
        kind = -1
        call h5iget_type_f(id, kind, st)
        call note(st, 'H5Iget_type', failed)
        if (kind == H5I_DATASET_F) then
            call h5dclose_f(id, st)
            call note(st, 'H5Dclose', failed)
        else if (kind == H5I_DATASPACE_F) then
            call h5sclose_f(id, st)
            call note(st, 'H5Sclose', failed)
        else if (kind == H5I_DATATYPE_F) then
            call h5tclose_f(id, st)
            call note(st, 'H5Tclose', failed)
        else if (kind == H5I_ATTR_F) then
            call h5aclose_f(id, st)
            call note(st, 'H5Aclose', failed)
        else if (kind == H5I_GROUP_F) then
            call h5gclose_f(id, st)
            call note(st, 'H5Gclose', failed)
        else
            call h5oclose_f(id, st)
            call note(st, 'H5Oclose', failed)
        end if
        id = -1
    end subroutine release

    !> What an HDF5 type class holds, for messages.
    function class_name(type_class) result(name)
        integer, intent(in) :: type_class
        character(len=:), allocatable :: name
        if (type_class == H5T_INTEGER_F) then
            name = 'integers'
        else if (type_class == H5T_FLOAT_F) then
            name = 'floating-point numbers'
        else if (type_class == H5T_STRING_F) then
            name = 'strings'
        else if (type_class == H5T_COMPOUND_F) then
            name = 'compound values'
        else if (type_class == H5T_ENUM_F) then
            name = 'enumeration values'
        else
            name = 'values of another HDF5 type class'
        end if
    end function class_name

    !> True (with `error` set) when the file is not open.
    logical function not_open(id, path, error)
        !> The file's handle, < 0 when it is not open.
        integer(hid_t), intent(in) :: id
        character(len=*), intent(in) :: path
        type(error_t), allocatable, intent(out) :: error
        not_open = id < 0
        if (not_open) call fatal_error(error, "HDF5: cannot access '"//path//"': no file is open")
    end function not_open

    !> Do all values fit a default integer?
    pure logical function fits_integer(values)
        integer(int64), intent(in) :: values(:)
        fits_integer = all(values >= int(-huge(0), int64) - 1 .and. values <= int(huge(0), int64))
    end function fits_integer

end module voiga_io_hdf5_status
