!> Where a run writes, checked before it writes or opens anything: no output may be
!> the case file, the geometry file or another output, however the paths are spelt
!> (compared after resolving symbolic links, '.' and '..': `canonical_path`) and
!> whatever other names the files have (compared by identity: device and inode); an
!> output must be a regular file or nothing in an existing folder (a FIFO, a device
!> node, a socket is never opened, whatever the options), and so must the `.part`
!> and `.lock` files beside it; an existing output is replaced only when the run may
!> (`--overwrite` or `&case overwrite = .true.`).
module voiga_io_output_outputs
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_text, only: str
    use voiga_platform_os, only: canonical_path, companion, file_info_t, file_status, path_kind, &
                                 same_file, kind_name, what_is, kind_missing, kind_regular, &
                                 kind_folder, kind_unknown
    use voiga_io_hdf5, only: h5file_t
    use voiga_io_input_case, only: case_t
    implicit none
    private

    public :: check_outputs, resolve_restart, restart_file

    !> The files a run reads or writes so far, which an output must not be.
    type :: taken_t
        character(len=:), allocatable :: path
        character(len=:), allocatable :: name
        type(file_info_t) :: info
    end type taken_t

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
        type(taken_t) :: taken(3)
        character(len=:), allocatable :: out
        logical :: may_replace
        integer :: n

        may_replace = overwrite .or. case%overwrite
        n = 0
        call add(taken, n, case%path, 'the case file', error)
        if (allocated(error)) return
        ! a geometry that cannot be resolved is reported by its reader
        call add(taken, n, case%geometry, 'the geometry file', error)
        if (allocated(error)) deallocate (error)
        if (present(restart)) then
            if (restart) call add(taken, n, case%output, 'the result file', error)
            if (allocated(error)) return
        end if
        if (writes_result) then
            call check_one(case%path//': &case: output', case%output, taken(1:n), may_replace, .true., out, error)
            if (allocated(error)) return
            case%output = out
            call add(taken, n, out, 'the result file', error)
            if (allocated(error)) return
        end if
        if (len(dump) == 0) return
        call check_one('--dump', dump, taken(1:n), may_replace, .false., out, error)
        if (allocated(error)) return
        dump = out
    end subroutine check_outputs

    !> Add the file `path` (called `name`) to the `n` files an output must not be.
    subroutine add(taken, n, path, name, error)
        type(taken_t), intent(inout) :: taken(:)
        integer, intent(inout) :: n
        character(len=*), intent(in) :: path, name
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: resolved
        call canonical_path(path, resolved, error)
        if (allocated(error)) return
        n = n + 1
        taken(n)%path = resolved
        taken(n)%name = name
        taken(n)%info = file_status(resolved, .true.)
    end subroutine add

    !> The canonical path `out` of the output `path` (`what` names it in messages),
    !> which must be none of the files `taken` nor their companions '.part' and
    !> '.lock' of ours, by name or by identity; a regular file or nothing (an
    !> existing one only when `may_replace`; `result`: the message says what the
    !> existing result holds), with its companions regular files of one name or
    !> nothing.
    subroutine check_one(what, path, taken, may_replace, result, out, error)
        character(len=*), intent(in) :: what, path
        type(taken_t), intent(in) :: taken(:)
        logical, intent(in) :: may_replace, result
        character(len=:), allocatable, intent(out) :: out
        type(error_t), allocatable, intent(out) :: error
        type(file_info_t) :: info
        integer :: i
        call canonical_path(path, out, error)
        if (allocated(error)) then
            error%message = what//': '//error%message
            return
        end if
        info = file_status(out, .false.)
        do i = 1, size(taken)
            if (out == taken(i)%path .or. companion(out, '.part') == taken(i)%path .or. &
                companion(out, '.lock') == taken(i)%path .or. same_file(info, taken(i)%info)) then
                call fatal_error(error, what//" '"//path//"' is "//taken(i)%name//" ('"//taken(i)%path// &
                                 "'): an output never replaces an input or another output", error_code%input)
                return
            end if
        end do
        select case (info%kind)
        case (kind_missing)
        case (kind_regular)
            if (.not. may_replace) then
                if (result) then
                    call fatal_error(error, what//" '"//path//"' exists"//describe(out)//'; give --overwrite '// &
                                     '(or &case overwrite = .true.) to replace it', error_code%input)
                else
                    call fatal_error(error, what//" '"//path//"' exists; give --overwrite (or &case "// &
                                     'overwrite = .true.) to replace it', error_code%input)
                end if
                return
            end if
        case (kind_folder)
            call fatal_error(error, what//" '"//path//"' is a folder", error_code%input)
            return
        case (kind_unknown)
            call fatal_error(error, what//" '"//path//"' cannot be examined", error_code%input)
            return
        case default
            call fatal_error(error, what//" '"//path//"' is "//kind_name(info%kind)//', not a regular file: '// &
                             'voiga writes its outputs only as regular files', error_code%input)
            return
        end select
        call check_companion(what, companion(out, '.part'), error)
        if (.not. allocated(error)) call check_companion(what, companion(out, '.lock'), error)
    end subroutine check_one

    !> The `.part` or `.lock` file `path` beside an output: nothing, or a regular
    !> file with one name (one a run of ours left); anything else is not ours to
    !> replace or remove.
    subroutine check_companion(what, path, error)
        character(len=*), intent(in) :: what, path
        type(error_t), allocatable, intent(out) :: error
        type(file_info_t) :: info
        info = file_status(path, .false.)
        if (info%kind == kind_missing .or. (info%kind == kind_regular .and. info%links == 1)) return
        call fatal_error(error, what//": '"//path//"' is "//what_is(info)// &
                         ', not a file voiga left: nothing was written; remove it', error_code%input)
    end subroutine check_companion

    !> What an existing result file holds, for the message that refuses it.
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

    !> The canonical path `resolved` of the result file `path` a restart continues:
    !> it must be an existing regular file (a FIFO or a device is refused before
    !> anything opens it).
    subroutine restart_file(path, resolved, error)
        character(len=*), intent(in) :: path
        character(len=:), allocatable, intent(out) :: resolved
        type(error_t), allocatable, intent(out) :: error
        integer :: kind
        call canonical_path(path, resolved, error)
        if (allocated(error)) then
            error%message = '--restart: '//error%message
            return
        end if
        kind = path_kind(resolved, .true.)
        if (kind == kind_missing) then
            call fatal_error(error, "--restart: file '"//path//"' does not exist", error_code%input)
        else if (kind /= kind_regular) then
            call fatal_error(error, "--restart '"//path//"' is "//kind_name(kind)//', not a result file', &
                             error_code%input)
        end if
    end subroutine restart_file

    !> The canonical path of the result file `path` to restart, which must be an
    !> existing regular file and must not be the case or geometry file of `case`
    !> (by name or identity).
    subroutine resolve_restart(path, case, resolved, error)
        character(len=*), intent(in) :: path
        type(case_t), intent(in) :: case
        character(len=:), allocatable, intent(out) :: resolved
        type(error_t), allocatable, intent(out) :: error
        type(taken_t) :: taken(2)
        type(error_t), allocatable :: ignored
        type(file_info_t) :: info
        integer :: i, n
        call restart_file(path, resolved, error)
        if (allocated(error)) return
        n = 0
        call add(taken, n, case%path, 'the case file', ignored)
        if (allocated(ignored)) deallocate (ignored)
        call add(taken, n, case%geometry, 'the geometry file', ignored)
        info = file_status(resolved, .true.)
        do i = 1, n
            if (resolved == taken(i)%path .or. same_file(info, taken(i)%info)) then
                call fatal_error(error, "--restart '"//path//"' is "//taken(i)%name, error_code%input)
                return
            end if
        end do
    end subroutine resolve_restart

end module voiga_io_output_outputs
