!> The HDF5 wrapper: round trips, and every failure (a write to a read-only file,
!> a dataset or attribute of the wrong type, rank or size) surfaces as an error
!> naming the file and the object instead of garbage.
module test_hdf5
    use, intrinsic :: iso_c_binding, only: c_loc
    use, intrinsic :: iso_fortran_env, only: int64
    use hdf5, only: hid_t, hsize_t, size_t, h5open_f, h5fcreate_f, h5fclose_f, H5F_ACC_TRUNC_F, &
                    h5screate_simple_f, h5sclose_f, h5dcreate_f, h5dwrite_f, h5dclose_f, &
                    h5tcopy_f, h5tset_size_f, h5tclose_f, h5tcreate_f, h5tinsert_f, h5acreate_f, &
                    h5awrite_f, h5aclose_f, H5T_FORTRAN_S1, H5T_COMPOUND_F, H5T_NATIVE_INTEGER, &
                    h5kind_to_type, H5_INTEGER_KIND, h5fget_obj_count_f, H5F_OBJ_ALL_F
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_testdrive, only: unittest_t, new_unittest, check, test_failed
    use voiga_io_hdf5, only: h5file_t
    use voiga_io_output_results, only: results_t
    use voiga_solver_records, only: solver_stats_t, cut_record_t
    implicit none
    private

    public :: collect_hdf5

contains

    subroutine collect_hdf5(testsuite)
        type(unittest_t), allocatable, intent(out) :: testsuite(:)
        testsuite = [ &
                    new_unittest('round_trip_every_rank', test_round_trip), &
                    new_unittest('attributes_round_trip', test_attributes), &
                    new_unittest('write_to_read_only_file_fails', test_read_only), &
                    new_unittest('writes_without_error_keep_the_first', test_kept_failure), &
                    new_unittest('closed_file_refused', test_closed), &
                    new_unittest('string_dataset_read_as_numbers_refused', test_string_dataset), &
                    new_unittest('wrong_type_or_rank_refused', test_wrong_type), &
                    new_unittest('wide_integers_range_checked', test_wide_integers), &
                    new_unittest('wrong_attributes_refused', test_wrong_attributes), &
                    new_unittest('hundreds_of_cuts_finish_the_file', test_many_cuts), &
                    new_unittest('failure_before_any_step_finishes_the_file', test_no_records) &
                    ]
    end subroutine collect_hdf5

    !> A run with 400 cuts of 256-character reasons (more than an HDF5 attribute
    !> holds) still finishes its result file with its status: the reasons the root's
    !> /cuts lists are shortened to fit (penalty-1e5 of the hard cases has 386).
    subroutine test_many_cuts(error)
        type(error_t), allocatable, intent(out) :: error
        type(results_t) :: results
        type(solver_stats_t) :: stats
        character(len=:), allocatable :: path, status, reasons
        integer :: i
        path = scratch('many-cuts')
        call results%h5%open(path, 'w', error)
        if (allocated(error)) return
        allocate (stats%cut_records(400))
        do i = 1, 400
            stats%cut_records(i) = cut_record_t(step=i, time=1.0_dp, fraction=0.5_dp, new_fraction=0.25_dp, &
                                                reason=repeat('x', 255)//'y')
        end do
        call results%finish('converged', 1.0_dp, stats, error)
        if (allocated(error)) return
        call results%h5%open(path, 'r', error)
        if (allocated(error)) return
        call results%h5%read_attr_str('/', 'status', status, error)
        if (allocated(error)) return
        call check(error, status == 'converged', 'status written: '//status)
        if (allocated(error)) return
        call results%h5%read_attr_str('/cuts', 'reasons', reasons, error)
        if (allocated(error)) return
        call check(error, len(reasons) > 400*16 .and. len(reasons) <= 60000, 'the reasons, shortened')
        if (allocated(error)) return
        call results%h5%close(error)
        call remove(path)
    end subroutine test_many_cuts

    !> A run that failed before its steps began (the stiffness pattern out of memory:
    !> hertz3d m3 NN2.2 on a block) has no records allocated: its result file still
    !> gets its status and no cut (the writer read the size of the unallocated
    !> records and died, losing the message).
    subroutine test_no_records(error)
        type(error_t), allocatable, intent(out) :: error
        type(results_t) :: results
        type(solver_stats_t) :: stats
        character(len=:), allocatable :: path, status
        integer :: n
        path = scratch('no-records')
        call results%h5%open(path, 'w', error)
        if (allocated(error)) return
        call results%finish('failed: out of memory', 1.0_dp, stats, error)
        if (allocated(error)) return
        call results%h5%open(path, 'r', error)
        if (allocated(error)) return
        call results%h5%read_attr_str('/', 'status', status, error)
        if (allocated(error)) return
        call results%h5%read_attr_int('/', 'n_cuts', n, error)
        if (allocated(error)) return
        call check(error, status == 'failed: out of memory' .and. n == 0, 'status and no cuts: '//status)
        if (allocated(error)) return
        call results%h5%close(error)
        call remove(path)
    end subroutine test_no_records

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

    !> The raw-API fixture (`write_foreign_file`) as scratch file `name`, opened
    !> read-write in `h5`.
    subroutine open_foreign(name, h5, path, error)
        character(len=*), intent(in) :: name
        type(h5file_t), intent(inout) :: h5
        character(len=:), allocatable, intent(out) :: path
        type(error_t), allocatable, intent(out) :: error
        path = scratch(name)
        call write_foreign_file(path, error)
        if (allocated(error)) return
        call h5%open(path, 'rw', error)
    end subroutine open_foreign

    !> After a test's calls: nothing but the file itself is left open in `h5` (every
    !> handle closed, on the failure paths too); close it and remove the file.
    subroutine close_scratch(h5, path, error)
        type(h5file_t), intent(inout) :: h5
        character(len=*), intent(in) :: path
        type(error_t), allocatable, intent(out) :: error
        call check(error, open_objects(h5), 1, 'open HDF5 objects but the file')
        if (allocated(error)) return
        call h5%close(error)
        if (allocated(error)) return
        call remove(path)
    end subroutine close_scratch

    !> Fail unless `got` is an error whose message names `word1` (and `word2`, `word3`).
    subroutine check_error(error, got, what, word1, word2, word3)
        type(error_t), allocatable, intent(out) :: error
        type(error_t), allocatable, intent(in) :: got
        character(len=*), intent(in) :: what, word1
        character(len=*), intent(in), optional :: word2, word3
        if (.not. allocated(got)) then
            call test_failed(error, what//': no error')
            return
        end if
        call check(error, index(got%message, word1) > 0, what//": the message names '"//word1// &
                   "': "//got%message)
        if (allocated(error)) return
        if (present(word2)) call check(error, index(got%message, word2) > 0, what// &
                                       ": the message names '"//word2//"': "//got%message)
        if (allocated(error)) return
        if (present(word3)) call check(error, index(got%message, word3) > 0, what// &
                                       ": the message names '"//word3//"': "//got%message)
    end subroutine check_error

    !> Number of HDF5 objects open in the file of `h5`, the file itself included
    !> (datasets, groups, attributes, named types; HDF5 counts no dataspaces or
    !> transient types per file): unchanged by any call of the wrapper when every
    !> handle is closed on every path.
    integer function open_objects(h5) result(n)
        type(h5file_t), intent(in) :: h5
        integer(size_t) :: count
        integer :: st
        call h5fget_obj_count_f(h5%id, H5F_OBJ_ALL_F, count, st)
        n = int(count)
        if (st /= 0) n = -1
    end function open_objects


    !> Datasets the wrapper cannot write, through the raw API: '/s' three fixed-length
    !> strings, '/c' a compound {a: integer}, '/wide' 64-bit integers [1, -7] and
    !> '/huge' [1, 2**40], and the attribute 'three' of '/', three integers.
    subroutine write_foreign_file(path, error)
        character(len=*), intent(in) :: path
        type(error_t), allocatable, intent(out) :: error
        integer(hid_t) :: fid, sid, tid, did, i64
        integer :: st, bad
        character(len=8), target, save :: words(3) = [character(len=8) :: 'one', 'two', 'three']
        integer(int64), target, save :: wide(2, 2) = reshape([1_int64, -7_int64, 1_int64, 2_int64**40], &
                                                       [2, 2])
        integer, target, save :: three(3) = [1, 2, 3]

        bad = 0
        call h5open_f(st)
        call h5fcreate_f(path, H5F_ACC_TRUNC_F, fid, st)
        bad = bad + abs(st)
        call h5screate_simple_f(1, [3_hsize_t], sid, st)
        call h5tcopy_f(H5T_FORTRAN_S1, tid, st)
        call h5tset_size_f(tid, 8_size_t, st)
        call h5dcreate_f(fid, '/s', tid, sid, did, st)
        call h5dwrite_f(did, tid, c_loc(words), st)
        bad = bad + abs(st)
        call h5dclose_f(did, st)
        call h5tclose_f(tid, st)
        call h5acreate_f(fid, 'three', H5T_NATIVE_INTEGER, sid, did, st)
        call h5awrite_f(did, H5T_NATIVE_INTEGER, c_loc(three), st)
        bad = bad + abs(st)
        call h5aclose_f(did, st)
        call h5tcreate_f(H5T_COMPOUND_F, 4_size_t, tid, st)
        call h5tinsert_f(tid, 'a', 0_size_t, H5T_NATIVE_INTEGER, st)
        call h5dcreate_f(fid, '/c', tid, sid, did, st)
        bad = bad + abs(st)
        call h5dclose_f(did, st)
        call h5tclose_f(tid, st)
        call h5sclose_f(sid, st)
        i64 = h5kind_to_type(int64, H5_INTEGER_KIND)
        call h5screate_simple_f(1, [2_hsize_t], sid, st)
        call h5dcreate_f(fid, '/wide', i64, sid, did, st)
        call h5dwrite_f(did, i64, c_loc(wide(:, 1)), st)
        bad = bad + abs(st)
        call h5dclose_f(did, st)
        call h5dcreate_f(fid, '/huge', i64, sid, did, st)
        call h5dwrite_f(did, i64, c_loc(wide(:, 2)), st)
        bad = bad + abs(st)
        call h5dclose_f(did, st)
        call h5sclose_f(sid, st)
        call h5fclose_f(fid, st)
        bad = bad + abs(st)
        call check(error, bad == 0, 'the raw-API fixture file '//path//' was written')
    end subroutine write_foreign_file

    !> Real ranks 0-3 and integer ranks 0-1 come back with their shapes and values; a
    !> scalar is stored as one element of shape (1,); a dataset written twice is
    !> replaced; an empty dataset reads back empty.
    subroutine test_round_trip(error)
        type(error_t), allocatable, intent(out) :: error
        type(h5file_t) :: h5
        real(dp) :: a3(2, 3, 4)
        real(dp), allocatable :: r0, r1(:), r2(:, :), r3(:, :, :)
        integer, allocatable :: i0, i1(:)
        character(len=:), allocatable :: path
        integer :: k

        path = scratch('round-trip')
        a3 = reshape([(real(k, dp)/7.0_dp, k=1, 24)], shape(a3))
        call h5%open(path, 'w', error)
        if (allocated(error)) return
        call h5%write('/g/scalar', 2.5_dp, error)
        if (allocated(error)) return
        call h5%write('/g/r1', [1.0_dp, 2.0_dp], error)
        if (allocated(error)) return
        ! written twice: the second replaces the first
        call h5%write('/g/r1', a3(:, 1, 1), error)
        if (allocated(error)) return
        call h5%write('/g/r2', a3(:, :, 2), error)
        if (allocated(error)) return
        call h5%write('/g/r3', a3, error)
        if (allocated(error)) return
        call h5%write('/i0', -3, error)
        if (allocated(error)) return
        call h5%write('/i1', [4, 5, 6], error)
        if (allocated(error)) return
        call h5%write('/empty', [real(dp) ::], error)
        if (allocated(error)) return
        call h5%close(error)
        if (allocated(error)) return

        call h5%open(path, 'r', error)
        if (allocated(error)) return
        call check(error, all(h5%shape('/g/scalar') == [1]) .and. &
                   size(h5%shape('/g/scalar')) == 1, 'a scalar is a dataset of shape (1,)')
        if (allocated(error)) return
        call check(error, all(h5%shape('/g/r3') == [2, 3, 4]), 'shape of a rank-3 dataset')
        if (allocated(error)) return
        call h5%read('/g/scalar', r0, error)
        if (allocated(error)) return
        call check(error, r0 == 2.5_dp, 'real scalar')
        if (allocated(error)) return
        call h5%read('/g/r1', r1, error)
        if (allocated(error)) return
        call check(error, all(r1 == a3(:, 1, 1)) .and. size(r1) == 2, 'real rank 1, replaced')
        if (allocated(error)) return
        call h5%read('/g/r2', r2, error)
        if (allocated(error)) return
        call check(error, all(shape(r2) == [2, 3]) .and. all(r2 == a3(:, :, 2)), 'real rank 2')
        if (allocated(error)) return
        call h5%read('/g/r3', r3, error)
        if (allocated(error)) return
        call check(error, all(shape(r3) == [2, 3, 4]) .and. all(r3 == a3), 'real rank 3')
        if (allocated(error)) return
        call h5%read('/i0', i0, error)
        if (allocated(error)) return
        call check(error, i0, -3, 'integer scalar')
        if (allocated(error)) return
        call h5%read('/i1', i1, error)
        if (allocated(error)) return
        call check(error, all(i1 == [4, 5, 6]) .and. size(i1) == 3, 'integer rank 1')
        if (allocated(error)) return
        ! integers read as reals: HDF5 converts them exactly
        call h5%read('/i1', r1, error)
        if (allocated(error)) return
        call check(error, all(r1 == [4.0_dp, 5.0_dp, 6.0_dp]), 'integers read as reals')
        if (allocated(error)) return
        call h5%read('/empty', r1, error)
        if (allocated(error)) return
        call check(error, size(r1), 0, 'an empty dataset')
        if (allocated(error)) return
        call close_scratch(h5, path, error)
    end subroutine test_round_trip

    !> String (fixed and empty), integer and real attributes, on the root, a group and a
    !> dataset, replaced when written twice; a missing one is an error.
    subroutine test_attributes(error)
        type(error_t), allocatable, intent(out) :: error
        type(error_t), allocatable :: got
        type(h5file_t) :: h5
        character(len=:), allocatable :: path, text
        integer :: n
        real(dp) :: x

        path = scratch('attributes')
        call h5%open(path, 'w', error)
        if (allocated(error)) return
        call h5%write_attr('/', 'title', 'first', error)
        if (allocated(error)) return
        call h5%write_attr('/', 'title', 'second title', error)
        if (allocated(error)) return
        call h5%write_attr('/', 'empty', '', error)
        if (allocated(error)) return
        ! a missing group is created for the attribute
        call h5%write_attr('/a/b', 'n', 42, error)
        if (allocated(error)) return
        call h5%write('/a/d', [1.0_dp], error)
        if (allocated(error)) return
        call h5%write_attr('/a/d', 'x', -0.125_dp, error)
        if (allocated(error)) return
        call h5%close(error)
        if (allocated(error)) return

        call h5%open(path, 'r', error)
        if (allocated(error)) return
        call h5%read_attr_str('/', 'title', text, error)
        if (allocated(error)) return
        call check(error, text, 'second title', 'string attribute, replaced')
        if (allocated(error)) return
        call h5%read_attr_str('/', 'empty', text, error)
        if (allocated(error)) return
        call check(error, text, '', 'empty string attribute')
        if (allocated(error)) return
        call h5%read_attr_int('/a/b', 'n', n, error)
        if (allocated(error)) return
        call check(error, n, 42, 'integer attribute')
        if (allocated(error)) return
        call h5%read_attr_real('/a/d', 'x', x, error)
        if (allocated(error)) return
        call check(error, x == -0.125_dp, 'real attribute')
        if (allocated(error)) return
        ! integers read as reals
        call h5%read_attr_real('/a/b', 'n', x, error)
        if (allocated(error)) return
        call check(error, x == 42.0_dp, 'integer attribute read as real')
        if (allocated(error)) return
        call h5%read_attr_int('/', 'nothing', n, got)
        call check_error(error, got, 'missing attribute', path, 'nothing', 'missing')
        if (allocated(error)) return
        call close_scratch(h5, path, error)
    end subroutine test_attributes

    !> Writing to a file opened read-only fails in HDF5 (the cheap stand-in for a full
    !> disk): each kind of write must say so, naming the file and the object.
    subroutine test_read_only(error)
        type(error_t), allocatable, intent(out) :: error
        type(error_t), allocatable :: got
        type(h5file_t) :: h5
        character(len=:), allocatable :: path

        path = scratch('read-only')
        call h5%open(path, 'w', error)
        if (allocated(error)) return
        call h5%write('/old', [1.0_dp], error)
        if (allocated(error)) return
        call h5%close(error)
        if (allocated(error)) return
        call h5%open(path, 'r', error)
        if (allocated(error)) return
        call h5%write('/new/x', [1.0_dp, 2.0_dp], got)
        call check_error(error, got, 'dataset in a new group', path, "'/new'", 'H5Gcreate')
        if (allocated(error)) return
        ! an existing dataset is replaced: the delete fails first
        call h5%write('/old', [3], got)
        call check_error(error, got, 'dataset replacing one', path, "'/old'", 'H5Ldelete')
        if (allocated(error)) return
        call h5%write('/x', 1.0_dp, got)
        call check_error(error, got, 'new dataset', path, "'/x'", 'H5Dcreate')
        if (allocated(error)) return
        call h5%write_attr('/', 'status', 'converged', got)
        call check_error(error, got, 'string attribute', path, "'status'", 'H5Acreate')
        if (allocated(error)) return
        call h5%write_attr('/old', 'n', 1, got)
        call check_error(error, got, 'integer attribute', path, "'n'", "'/old'")
        if (allocated(error)) return
        call h5%create_group('/g', got)
        call check_error(error, got, 'group', path, "'/g'")
        if (allocated(error)) return
        call h5%flush(error)
        if (allocated(error)) return
        call close_scratch(h5, path, error)
    end subroutine test_read_only

    !> Writes without an error argument keep their first failure in the file: the
    !> writes after it do nothing (they open nothing and write nothing, not even
    !> where they could), `check` hands over the first failure once, and a write
    !> with its own `error` is not affected.
    subroutine test_kept_failure(error)
        type(error_t), allocatable, intent(out) :: error
        type(error_t), allocatable :: got
        type(h5file_t) :: h5, back
        character(len=:), allocatable :: path
        integer :: before

        path = scratch('kept-failure')
        call h5%open(path, 'w', error)
        if (allocated(error)) return
        call h5%write('/a', [1.0_dp])
        call check(error, .not. h5%failed(), 'a write that succeeds keeps nothing')
        if (allocated(error)) return
        before = open_objects(h5)
        ! (the dataset's parent '/a' is a dataset, not a group: H5Dcreate fails)
        call h5%write('/a/b', [2.0_dp])
        call h5%write_attr('/', 'later', 1)
        call h5%write('/c', [3])
        call h5%create_group('/g')
        call check(error, h5%failed() .and. open_objects(h5) == before, 'failed, every handle closed')
        if (allocated(error)) return
        call h5%write_attr('/', 'with_error', 2, got)
        call check(error, .not. allocated(got), 'a write with its own error argument still writes')
        if (allocated(error)) return
        call h5%check(got)
        call check_error(error, got, 'the kept failure', "'/a/b'")
        if (allocated(error)) return
        deallocate (got)
        call h5%check(got)
        call check(error, .not. (allocated(got) .or. h5%failed()), 'handed over once')
        if (allocated(error)) return
        call h5%close(error)
        if (allocated(error)) return
        call back%open(path, 'r', error)
        if (allocated(error)) return
        call check(error, back%has_attr('/', 'with_error') .and. .not. (back%has_attr('/', 'later') .or. &
                   back%exists('/c') .or. back%exists('/g')), 'nothing written after the failure')
        if (allocated(error)) return
        call close_scratch(back, path, error)
    end subroutine test_kept_failure

    !> A file object that is not open refuses writes and reads; closing it is harmless.
    subroutine test_closed(error)
        type(error_t), allocatable, intent(out) :: error
        type(error_t), allocatable :: got
        type(h5file_t) :: h5
        real(dp), allocatable :: r(:)

        call h5%write('/x', [1.0_dp], got)
        call check_error(error, got, 'write', "'/x'", 'no file is open')
        if (allocated(error)) return
        call h5%read('/x', r, got)
        call check_error(error, got, 'read', "'/x'", 'no file is open')
        if (allocated(error)) return
        call h5%write_attr('/', 'a', 1, got)
        call check_error(error, got, 'attribute', "'/'", 'no file is open')
        if (allocated(error)) return
        call h5%close(error)
    end subroutine test_closed

    !> HDF5 has no conversion from strings to numbers: reading one as real or
    !> integer must fail (it used to return uninitialised memory, because the
    !> status of H5Dread was overwritten by that of H5Dclose before the check).
    subroutine test_string_dataset(error)
        type(error_t), allocatable, intent(out) :: error
        type(error_t), allocatable :: got
        type(h5file_t) :: h5
        real(dp), allocatable :: r(:)
        integer, allocatable :: i(:)
        character(len=:), allocatable :: path

        call open_foreign('string', h5, path, error)
        if (allocated(error)) return
        call h5%read('/s', r, got)
        call check_error(error, got, 'strings as reals', path, "'/s'", 'strings')
        if (allocated(error)) return
        call h5%read('/s', i, got)
        call check_error(error, got, 'strings as integers', path, "'/s'", 'strings')
        if (allocated(error)) return
        call close_scratch(h5, path, error)
    end subroutine test_string_dataset

    !> A compound dataset, floats read as integers (HDF5 would truncate: 2.7 -> 2), a
    !> rank other than the array's and a missing dataset are refused, by name.
    subroutine test_wrong_type(error)
        type(error_t), allocatable, intent(out) :: error
        type(error_t), allocatable :: got
        type(h5file_t) :: h5
        real(dp), allocatable :: r0, r1(:), r2(:, :)
        integer, allocatable :: i1(:)
        character(len=:), allocatable :: path

        call open_foreign('wrong-type', h5, path, error)
        if (allocated(error)) return
        call h5%write('/f', [2.7_dp, -1.5_dp], error)
        if (allocated(error)) return
        call h5%write('/m', reshape([1.0_dp, 2.0_dp, 3.0_dp, 4.0_dp], [2, 2]), error)
        if (allocated(error)) return
        call h5%read('/c', r1, got)
        call check_error(error, got, 'compound as reals', path, "'/c'", 'compound')
        if (allocated(error)) return
        call h5%read('/f', i1, got)
        call check_error(error, got, 'floats as integers', "'/f'", 'floating-point', 'not integers')
        if (allocated(error)) return
        call h5%read('/m', r1, got)
        call check_error(error, got, 'rank 2 as rank 1', "'/m'", 'rank 2, expected 1')
        if (allocated(error)) return
        call h5%read('/f', r2, got)
        call check_error(error, got, 'rank 1 as rank 2', "'/f'", 'rank 1, expected 2')
        if (allocated(error)) return
        call h5%read('/f', r0, got)
        call check_error(error, got, 'two values as a scalar', "'/f'", 'rank 1, expected 0')
        if (allocated(error)) return
        call h5%read('/nothing/here', r1, got)
        call check_error(error, got, 'missing dataset', "'/nothing/here'", 'missing')
        if (allocated(error)) return
        call close_scratch(h5, path, error)
    end subroutine test_wrong_type

    !> 64-bit integer datasets (h5py's default) read when their values fit a default
    !> integer; HDF5 would clamp 2**40 to huge(0) silently, so that is an error.
    subroutine test_wide_integers(error)
        type(error_t), allocatable, intent(out) :: error
        type(error_t), allocatable :: got
        type(h5file_t) :: h5
        integer, allocatable :: i1(:)
        real(dp), allocatable :: r1(:)
        character(len=:), allocatable :: path

        call open_foreign('wide', h5, path, error)
        if (allocated(error)) return
        call h5%read('/wide', i1, error)
        if (allocated(error)) return
        call check(error, all(i1 == [1, -7]) .and. size(i1) == 2, '64-bit integers that fit')
        if (allocated(error)) return
        call h5%read('/huge', i1, got)
        call check_error(error, got, '2**40', path, "'/huge'", 'too large')
        if (allocated(error)) return
        call h5%read('/huge', r1, error)
        if (allocated(error)) return
        call check(error, r1(2) == 2.0_dp**40, '2**40 read as real')
        if (allocated(error)) return
        call close_scratch(h5, path, error)
    end subroutine test_wide_integers

    !> An attribute of three values (which would overflow a scalar) and one of the
    !> wrong class are refused.
    subroutine test_wrong_attributes(error)
        type(error_t), allocatable, intent(out) :: error
        type(error_t), allocatable :: got
        type(h5file_t) :: h5
        character(len=:), allocatable :: path, text
        integer :: n
        real(dp) :: x

        call open_foreign('wrong-attributes', h5, path, error)
        if (allocated(error)) return
        call h5%write_attr('/', 'name', 'text', error)
        if (allocated(error)) return
        call h5%write_attr('/', 'x', 1.5_dp, error)
        if (allocated(error)) return
        call h5%read_attr_int('/', 'three', n, got)
        call check_error(error, got, 'three values as a scalar', path, "'three'", 'more than one')
        if (allocated(error)) return
        call h5%read_attr_int('/', 'name', n, got)
        call check_error(error, got, 'string as integer', "'name'", 'strings', 'not an integer')
        if (allocated(error)) return
        call h5%read_attr_real('/', 'name', x, got)
        call check_error(error, got, 'string as real', "'name'", 'strings')
        if (allocated(error)) return
        call h5%read_attr_int('/', 'x', n, got)
        call check_error(error, got, 'real as integer', "'x'", 'floating-point')
        if (allocated(error)) return
        call h5%read_attr_str('/', 'x', text, got)
        call check_error(error, got, 'real as string', "'x'", 'not a string')
        if (allocated(error)) return
        call close_scratch(h5, path, error)
    end subroutine test_wrong_attributes

end module test_hdf5
