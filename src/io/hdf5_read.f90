!> Reading datasets of the HDF5 file object (`voiga_io_hdf5`): the shape and type
!> of a dataset checked before anything is allocated or read (its rank, its type
!> class, its number of values against a limit, its values stored in the file
!> itself: external raw storage, which HDF5 would open by name, whatever it is, and
!> virtual datasets, which read other files, are refused), then the values read
!> with HDF5's conversions. A submodule only to keep the files short; the
!> interfaces and their documentation are in the module.
submodule(voiga_io_hdf5) voiga_io_hdf5_read
    use hdf5, only: h5dget_create_plist_f, h5pget_layout_f, h5pget_external_count_f, H5D_VIRTUAL_F
    implicit none

    !> Most values a dataset may have when the reader gives no limit of its own:
    !> what a default integer counts.
    integer(int64), parameter :: default_limit = huge(0)

contains

    module procedure read_real
        integer(hsize_t), allocatable :: dims(:)

        call dataset_layout(self, path, rank(array), .true., dims, error, limit)
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
        rank (4)
            ! (a volume's control points)
            allocate (array(dims(1), dims(2), dims(3), dims(4)))
        rank default
            call unsupported_rank(self, path, rank(array), error)
            return
        end select
        call read_dataset(self, path, H5T_NATIVE_DOUBLE, product(dims), c_loc(array), error)
    end procedure read_real

    module procedure read_int
        integer(hsize_t), allocatable :: dims(:)
        integer(int64), allocatable, target :: wide(:)

        call dataset_layout(self, path, rank(array), .false., dims, error, limit)
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
    end procedure read_int

    !> The error for an array rank `read` has no branch for.
    subroutine unsupported_rank(self, path, array_rank, error)
        class(h5file_t), intent(in) :: self
        character(len=*), intent(in) :: path
        integer, intent(in) :: array_rank
        type(error_t), allocatable, intent(out) :: error
        character(len=12) :: buf
        write (buf, '(i0)') array_rank
        call fatal_error(error, self%path//": reading dataset '"//path// &
                         "' into an array of rank "//trim(buf)//' is not supported')
    end subroutine unsupported_rank

    !> Shape (Fortran order) of dataset `path`, checked to be readable as an array of
    !> rank `array_rank` (rank 0 takes a scalar or one-element dataset) holding
    !> reals (`as_real`: integer or float datasets) or integers (integer datasets),
    !> of at most `limit` values (`default_limit` when absent): checked before
    !> anything is allocated or read, so a file that claims a huge dataset costs
    !> nothing.
    subroutine dataset_layout(self, path, array_rank, as_real, dims, error, limit)
        class(h5file_t), intent(in) :: self
        character(len=*), intent(in) :: path
        integer, intent(in) :: array_rank
        logical, intent(in) :: as_real
        integer(hsize_t), allocatable, intent(out) :: dims(:)
        type(error_t), allocatable, intent(out) :: error
        integer(int64), intent(in), optional :: limit
        integer :: type_class
        character(len=64) :: buf
        character(len=:), allocatable :: expected
        integer(int64) :: most

        call dataset_info(self, path, dims, type_class, error)
        if (allocated(error)) return
        most = default_limit
        if (present(limit)) most = limit
        if (.not. at_most(dims, most)) then
            write (buf, '(i0)') most
            call fatal_error(error, self%path//": dataset '"//path//"' has "//shape_text(dims)// &
                             ' values: more than the '//trim(buf)//' it may have', error_code%input)
            return
        end if
        expected = merge('numbers ', 'integers', as_real)
        if (.not. (type_class == H5T_INTEGER_F .or. &
                   (as_real .and. type_class == H5T_FLOAT_F))) then
            call fatal_error(error, self%path//": dataset '"//path//"' holds "// &
                             class_name(type_class)//', not '//trim(expected), error_code%input)
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
        character(len=:), allocatable :: failed, storage

        type_class = -1
        storage = ''
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
            if (allocated(failed)) exit steps
            call storage_kind(did, storage, failed)
        end block steps
        call release(tid, failed)
        call release(sid, failed)
        call release(did, failed)
        if (allocated(failed)) then
            call fatal_error(error, self%path//": inspecting dataset '"//path//"' failed in "//failed, &
                             error_code%input)
        else if (len(storage) > 0) then
            call fatal_error(error, self%path//": dataset '"//path//"' keeps its values "//storage// &
                             ': not read (only values stored in the file itself are)', error_code%input)
        end if
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

    module procedure dataset_shape
        integer(hsize_t), allocatable :: d(:)
        integer :: type_class
        type(error_t), allocatable :: error
        call dataset_info(self, path, d, type_class, error)
        if (allocated(error)) then
            allocate (dims(0))
        else
            dims = int(min(d, int(huge(0), hsize_t)))
        end if
    end procedure dataset_shape

    !> Do the dimensions `dims` hold at most `most` values (without overflowing)?
    pure logical function at_most(dims, most)
        integer(hsize_t), intent(in) :: dims(:)
        integer(int64), intent(in) :: most
        integer(int64) :: n
        integer :: i
        at_most = .true.
        n = 1
        do i = 1, size(dims)
            if (dims(i) == 0) return
        end do
        do i = 1, size(dims)
            if (dims(i) > most .or. n > most/max(dims(i), 1_hsize_t)) then
                at_most = .false.
                return
            end if
            n = n*dims(i)
        end do
    end function at_most

    !> '31623 x 31623 x 2' (the h5py order, slowest axis first).
    pure function shape_text(dims) result(text)
        integer(hsize_t), intent(in) :: dims(:)
        character(len=:), allocatable :: text
        character(len=24) :: buf
        integer :: i
        text = ''
        do i = size(dims), 1, -1
            write (buf, '(i0)') dims(i)
            text = text//trim(buf)
            if (i > 1) text = text//' x '
        end do
    end function shape_text

    !> Where dataset `did` keeps its values, when not in the file itself ('' when
    !> it does): 'in external files' or 'in other files (a virtual dataset)'.
    subroutine storage_kind(did, storage, failed)
        integer(hid_t), intent(in) :: did
        character(len=:), allocatable, intent(out) :: storage
        character(len=:), allocatable, intent(inout) :: failed
        integer(hid_t) :: plist
        integer :: layout, count, st
        storage = ''
        plist = -1
        call h5dget_create_plist_f(did, plist, st)
        call note(st, 'H5Dget_create_plist', failed)
        if (allocated(failed)) return
        call h5pget_layout_f(plist, layout, st)
        call note(st, 'H5Pget_layout', failed)
        call h5pget_external_count_f(plist, count, st)
        call note(st, 'H5Pget_external_count', failed)
        call h5pclose_f(plist, st)
        call note(st, 'H5Pclose', failed)
        if (allocated(failed)) return
        if (count > 0) storage = 'in external files'
        if (layout == H5D_VIRTUAL_F) storage = 'in other files (a virtual dataset)'
    end subroutine storage_kind

end submodule voiga_io_hdf5_read
