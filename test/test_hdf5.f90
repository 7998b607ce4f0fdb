!> The HDF5 wrapper: round trips, and every failure (a write to a read-only file,
!> a dataset of the wrong type or rank) surfaces as an error naming the file and
!> the object instead of garbage.
module test_hdf5
    use hdf5, only: hid_t, hsize_t, size_t, h5open_f, h5fcreate_f, h5fclose_f, H5F_ACC_TRUNC_F, &
                    h5screate_simple_f, h5sclose_f, h5dcreate_f, h5dwrite_f, h5dclose_f, &
                    h5tcopy_f, h5tset_size_f, h5tclose_f, H5T_FORTRAN_S1
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_testdrive, only: unittest_t, new_unittest, check
    use voiga_io_hdf5, only: h5file_t
    implicit none
    private

    public :: collect_hdf5

contains

    subroutine collect_hdf5(testsuite)
        type(unittest_t), allocatable, intent(out) :: testsuite(:)
        testsuite = [ &
                    new_unittest('string_dataset_read_as_numbers_refused', test_string_dataset) &
                    ]
    end subroutine collect_hdf5

    !> A scratch file name under build/ (fpm runs the tests from the project root).
    function scratch(name) result(path)
        character(len=*), intent(in) :: name
        character(len=:), allocatable :: path
        path = 'build/test-hdf5-'//name//'.h5'
    end function scratch

    !> Remove a scratch file.
    subroutine remove(path)
        character(len=*), intent(in) :: path
        integer :: u, ios
        open (newunit=u, file=path, status='old', iostat=ios)
        if (ios == 0) close (u, status='delete')
    end subroutine remove

    !> A file holding one fixed-length string dataset '/s' of 3 elements, written
    !> through the raw API (the wrapper writes no string datasets).
    subroutine write_string_file(path)
        character(len=*), intent(in) :: path
        integer(hid_t) :: fid, sid, tid, did
        integer :: st
        character(len=8) :: words(3) = [character(len=8) :: 'one', 'two', 'three']
        call h5open_f(st)
        call h5fcreate_f(path, H5F_ACC_TRUNC_F, fid, st)
        call h5screate_simple_f(1, [3_hsize_t], sid, st)
        call h5tcopy_f(H5T_FORTRAN_S1, tid, st)
        call h5tset_size_f(tid, 8_size_t, st)
        call h5dcreate_f(fid, '/s', tid, sid, did, st)
        call h5dwrite_f(did, tid, words, [3_hsize_t], st)
        call h5dclose_f(did, st)
        call h5tclose_f(tid, st)
        call h5sclose_f(sid, st)
        call h5fclose_f(fid, st)
    end subroutine write_string_file

    !> HDF5 has no conversion from strings to numbers: reading one as real or
    !> integer must fail (it used to return uninitialised memory, because the
    !> status of H5Dread was overwritten by that of H5Dclose before the check).
    subroutine test_string_dataset(error)
        type(error_t), allocatable, intent(out) :: error
        type(error_t), allocatable :: read_error
        type(h5file_t) :: h5
        real(dp), allocatable :: r(:)
        integer, allocatable :: i(:)
        character(len=:), allocatable :: path

        path = scratch('string')
        call write_string_file(path)
        call h5%open(path, 'r', error)
        if (allocated(error)) return
        call h5%read('/s', r, read_error)
        call check(error, allocated(read_error), 'a string dataset read as real is an error')
        if (allocated(error)) return
        call h5%read('/s', i, read_error)
        call check(error, allocated(read_error), 'a string dataset read as integer is an error')
        if (allocated(error)) return
        call h5%close()
        call remove(path)
    end subroutine test_string_dataset

end module test_hdf5
