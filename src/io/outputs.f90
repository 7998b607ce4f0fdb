!> Where a run writes, checked before it writes anything: no output may be the
!> case file, the geometry file or another output, however the paths are spelt
!> (compared after resolving symbolic links, '.' and '..': `canonical_path`), an
!> output must be a file in an existing folder, and an existing result file is
!> replaced only when the run may (`--overwrite` or `&case overwrite = .true.`).
module voiga_io_outputs
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_text, only: str
    use voiga_io_os, only: canonical_path, path_exists, is_directory, companion
    use voiga_io_hdf5, only: h5file_t
    use voiga_io_case, only: case_t
    implicit none
    private

    public :: check_outputs, resolve_restart

contains

    !> Check the outputs of a run of `case`: its result file (`case%output`) when
    !> `writes_result`, and the dump file `dump` when given ('' for none). Both are
    !> replaced by their canonical paths. With `restart`, `case%output` is the
    !> (canonical) result file the run continues: only the dump is checked, also
    !> against it.
    subroutine check_outputs(case, writes_result, dump, overwrite, error, restart)
        type(case_t), intent(inout) :: case
        logical, intent(in) :: writes_result, overwrite
        character(len=:), allocatable, intent(inout) :: dump
        type(error_t), allocatable, intent(out) :: error
        logical, intent(in), optional :: restart
        character(len=:), allocatable :: inputs(:), names(:), out
        character(len=:), allocatable :: case_real, geometry_real

        call canonical_path(case%path, case_real, error)
        if (allocated(error)) return
        call canonical_path(case%geometry, geometry_real, error)
        ! a geometry that cannot be resolved is reported by its reader
        if (allocated(error)) deallocate (error)
        if (.not. allocated(geometry_real)) geometry_real = '/'
        inputs = [character(len=max(len(case_real), len(geometry_real))) :: case_real, geometry_real]
        names = [character(len=18) :: 'the case file', 'the geometry file']
        if (present(restart)) then
            if (restart) then
                inputs = [character(len=max(len(inputs), len(case%output))) :: inputs, case%output]
                names = [character(len=18) :: names, 'the result file']
            end if
        end if
        if (writes_result) then
            call check_one(case%path//': &case: output', case%output, inputs, names, out, error)
            if (allocated(error)) return
            if (is_directory(out)) then
                call fatal_error(error, case%path//": &case: output '"//case%output//"' is a folder", &
                                 error_code%input)
                return
            end if
            if (path_exists(out) .and. .not. (overwrite .or. case%overwrite)) then
                call fatal_error(error, case%path//": &case: output '"//case%output//"' exists"// &
                                 describe(out)//'; give --overwrite (or &case overwrite = .true.) to '// &
                                 'replace it', error_code%input)
                return
            end if
            case%output = out
            inputs = [character(len=max(len(inputs), len(out))) :: inputs, out]
            names = [character(len=18) :: names, 'the result file']
        end if
        if (len(dump) == 0) return
        call check_one('--dump', dump, inputs, names, out, error)
        if (allocated(error)) return
        if (is_directory(out)) then
            call fatal_error(error, "--dump '"//dump//"' is a folder", error_code%input)
            return
        end if
        dump = out
    end subroutine check_outputs

    !> The canonical path `out` of the output `path` (`what` names it in messages),
    !> which must not be any of `inputs` (called `names`), nor their companions
    !> '.part' and '.lock' of ours.
    subroutine check_one(what, path, inputs, names, out, error)
        character(len=*), intent(in) :: what, path, inputs(:), names(:)
        character(len=:), allocatable, intent(out) :: out
        type(error_t), allocatable, intent(out) :: error
        integer :: i
        call canonical_path(path, out, error)
        if (allocated(error)) then
            error%message = what//': '//error%message
            return
        end if
        do i = 1, size(inputs)
            if (out == trim(inputs(i)) .or. companion(out, '.part') == trim(inputs(i)) .or. &
                companion(out, '.lock') == trim(inputs(i))) then
                call fatal_error(error, what//" '"//path//"' is "//trim(names(i))//" ('"//trim(inputs(i))// &
                                 "'): an output never replaces an input or another output", error_code%input)
                return
            end if
        end do
    end subroutine check_one

    !> What an existing output file holds, for the message that refuses it.
    function describe(path) result(text)
        character(len=*), intent(in) :: path
        character(len=:), allocatable :: text
        type(h5file_t) :: h5
        type(error_t), allocatable :: error
        character(len=:), allocatable :: status
        integer :: steps
        text = ' (not a voiga result file)'
        call h5%open(path, 'r', error)
        if (allocated(error)) return
        call h5%read_attr_str('/', 'status', status, error)
        if (.not. allocated(error)) call h5%read_attr_int('/', 'n_steps_done', steps, error)
        if (.not. allocated(error)) then
            text = " (a result: status '"//status//"', "//str(steps)//' step'//trim(merge('s', ' ', steps /= 1))
            if (status /= 'converged') text = text//'; --restart '//path//' continues it'
            text = text//')'
        end if
        call h5%close(error)
    end function describe

    !> The canonical path of the result file `path` to restart, which must exist
    !> and must not be the case or geometry file of `case`.
    subroutine resolve_restart(path, case, resolved, error)
        character(len=*), intent(in) :: path
        type(case_t), intent(in) :: case
        character(len=:), allocatable, intent(out) :: resolved
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: other
        type(error_t), allocatable :: ignored
        call canonical_path(path, resolved, error)
        if (allocated(error)) then
            error%message = '--restart: '//error%message
            return
        end if
        call canonical_path(case%path, other, ignored)
        if (.not. allocated(ignored) .and. other == resolved) &
            call fatal_error(error, "--restart '"//path//"' is the case file", error_code%input)
        call canonical_path(case%geometry, other, ignored)
        if (.not. allocated(ignored) .and. other == resolved .and. .not. allocated(error)) &
            call fatal_error(error, "--restart '"//path//"' is the geometry file", error_code%input)
    end subroutine resolve_restart

end module voiga_io_outputs
