!> A file voiga writes (a result, a dump) as its readers see it (docs/hdf5.md,
!> "Writing and reading a running result"; docs/formats.md, "Outputs"): an HDF5 file
!> that
!> - is created as `<file>.part`, a new file (never through a link, never over
!>   anything), and renamed to its name once its first step is in it, so an earlier
!>   file there is replaced only by one with a step, and only when the run may
!>   replace it (`--overwrite`);
!> - has one writer, who holds the lock file `<file>.lock` for the whole run (a
!>   second writer is refused, whatever HDF5_USE_FILE_LOCKING says);
!> - is changed only between `begin_write` and `end_write`: first the writer checks
!>   that the file's name still names the file it writes and that its lock file is
!>   still its own (a file moved, replaced or removed, or a lock file removed, under
!>   a running writer ends the run: `lost`), then space is reserved (a full disk or
!>   quota stops the run before the write, the file as it was), an exclusive `flock`
!>   on the file keeps readers out (those that take a shared one, as HDF5's own
!>   locking and `post` do, read only whole steps), and the write is flushed before
!>   readers are let in again;
!> - once a write to it has failed, is `broken`: nothing more may reach it (the
!>   program must leave without HDF5's exit handlers, which would write half a step
!>   over the last flush).
module voiga_io_output_result_file
    use, intrinsic :: iso_fortran_env, only: int64
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_io_hdf5, only: h5file_t, finish_interrupted_flush
    use voiga_platform_os, only: file_info_t, file_status, fd_status, path_kind, fd_size, &
                                 names_file, kind_name, what_is, reserve_space, release_space, &
                                 rename_file, remove_file, path_exists, companion, kind_missing, &
                                 kind_regular
    use voiga_platform_lock, only: lock_t, acquire_lock, release_lock, lock_intact, hold_file, &
                                   let_go_file
    use voiga_platform_process, only: write_failure_cause
    implicit none
    private

    public :: result_file_t

    !> Seconds a writer waits for a reader to let go of the file before it writes
    !> anyway, and how long once a reader has outlasted that (a file left open in
    !> an interactive h5py session must not slow every step down).
    real, parameter :: reader_wait = 30.0, stubborn_reader_wait = 0.1

    !> An open result file and its guards.
    type, extends(h5file_t) :: result_file_t
        !> The file, and where it is written until its first step is in it.
        character(len=:), allocatable :: final_path, part_path
        !> The writer's lock file.
        type(lock_t) :: writer
        !> The file this run writes (device and inode when it was opened): its name
        !> must keep naming it.
        type(file_info_t) :: identity
        !> May an earlier file at the name be replaced (`--overwrite`)?
        logical :: may_replace = .false.
        !> Is the file at its name (a step written, or a restart)? Did a write to it
        !> fail? Was an earlier file at the name kept because this run wrote no step?
        logical :: in_place = .false., broken = .false., kept_earlier = .false.
        !> Was the file moved, replaced or removed under the writer (its name names
        !> something else now)? Could the `.part` file not be given its name (the
        !> steps stay in it)?
        logical :: lost = .false., stuck = .false.
        !> Size before the write under way, and what the last write added (bytes).
        integer(int64) :: size_before = 0, write_bytes = 0
        !> Did the last write get the file to itself (else a reader outlasted the wait)?
        logical :: patient = .true.
    contains
        procedure :: claim => file_claim
        procedure :: create => file_create
        procedure :: resume => file_resume
        procedure :: begin_write => file_begin_write
        procedure :: end_write => file_end_write
        procedure :: place => file_place
        procedure :: settle => file_settle
        procedure :: abandon => file_abandon
        procedure :: at_name => file_at_name
        procedure :: where_steps => file_where_steps
    end type result_file_t

contains

    !> Take the writer's lock of the file `path` (its lock file beside it): refused
    !> while another run writes it. Nothing if this object holds it. A flush that a
    !> killed earlier writer left half done is finished (`finish_interrupted_flush`):
    !> whatever reads the file next (a restart, or a reader while this run has not
    !> replaced it) reads the file of that writer's last flush. `what` names the file
    !> in messages (default 'result file').
    subroutine file_claim(self, path, error, what)
        class(result_file_t), intent(inout) :: self
        character(len=*), intent(in) :: path
        type(error_t), allocatable, intent(out) :: error
        character(len=*), intent(in), optional :: what
        logical :: finished
        character(len=:), allocatable :: name
        if (self%writer%fd >= 0) return
        name = 'result file'
        if (present(what)) name = what
        call acquire_lock(self%writer, companion(path, '.lock'), name//" '"//path//"'", error)
        if (allocated(error)) return
        self%final_path = path
        if (path_kind(path, .false.) == kind_regular) call finish_interrupted_flush(path, finished)
    end subroutine file_claim

    !> Start the file `path` (claimed first): `path`.part, a new file. A `.part` a
    !> killed run left (a regular file with one name) is removed first; anything
    !> else at that name is refused, untouched. `replace`: the file may replace an
    !> earlier one at `path` when it gets its name.
    subroutine file_create(self, path, replace, error, what)
        class(result_file_t), intent(inout) :: self
        character(len=*), intent(in) :: path
        logical, intent(in) :: replace
        type(error_t), allocatable, intent(out) :: error
        character(len=*), intent(in), optional :: what
        type(file_info_t) :: part
        call self%claim(path, error, what)
        if (allocated(error)) return
        self%may_replace = replace
        self%part_path = companion(path, '.part')
        part = file_status(self%part_path, .false.)
        if (part%kind == kind_regular .and. part%links == 1) then
            call remove_file(self%part_path)
        else if (part%kind /= kind_missing) then
            call fatal_error(error, "'"//self%part_path//"' is "//what_is(part)// &
                             ', not a file voiga left: nothing was written; remove it', error_code%input)
            return
        end if
        call self%open(self%part_path, 'x', error)
        if (allocated(error)) then
            error%message = error%message//' (is the folder writable?)'
            return
        end if
        self%identity = fd_status(self%descriptor())
    end subroutine file_create

    !> Open the existing result file `path` (claimed first) to continue it in place.
    subroutine file_resume(self, path, error)
        class(result_file_t), intent(inout) :: self
        character(len=*), intent(in) :: path
        type(error_t), allocatable, intent(out) :: error
        call self%claim(path, error)
        if (allocated(error)) return
        call self%open(path, 'rw', error)
        if (allocated(error)) return
        self%identity = fd_status(self%descriptor())
        self%in_place = .true.
    end subroutine file_resume

    !> Does the file's current name (`.part` or its own) still name the file
    !> this run writes?
    logical function file_at_name(self)
        class(result_file_t), intent(in) :: self
        file_at_name = .false.
        if (.not. allocated(self%path)) return
        file_at_name = names_file(self%path, self%identity)
    end function file_at_name

    !> The file's name still names it and the lock file is still ours; else the
    !> run must stop: a removed lock file lets a second run write the same file
    !> (nothing more is written: `broken`), a file moved, replaced or removed under
    !> the writer is `lost` (its steps are no longer where its name says). The
    !> file's name is looked at before the lock file: another run replaces the
    !> file only after it took the lock, so a replaced file seen here comes with a
    !> lock file seen gone or replaced, and the message names that cause, even when
    !> this run was stopped between the two looks (SIGSTOP).
    subroutine check_names(self, error)
        class(result_file_t), intent(inout) :: self
        type(error_t), allocatable, intent(out) :: error
        logical :: here
        ! (a file opened by hand, without `claim`, `create` or `resume`, has neither)
        if (.not. self%is_open() .or. self%identity%kind == kind_missing) return
        here = self%at_name()
        if (self%writer%fd >= 0 .and. .not. lock_intact(self%writer)) then
            self%broken = .true.
            call fatal_error(error, "the lock file '"//self%writer%path//"' was removed or replaced while "// &
                             "this run wrote '"//self%final_path//"': another run may be writing it now; "// &
                             'this run stopped writing it')
        else if (self%lost .or. .not. here) then
            ! (once lost, always: nothing more is written to it)
            self%lost = .true.
            call fatal_error(error, "'"//self%path//"' is no longer the file this run writes: it was moved, "// &
                             'replaced or removed while the run wrote it')
        end if
    end subroutine check_names

    !> Before a write: check the names (`check_names`), reserve space for it
    !> (`bytes`, or twice what the last write added if more) and, once the file is
    !> at its name, hold the exclusive `flock` readers wait for (waiting at most
    !> `reader_wait` for one that holds the file longer, then only
    !> `stubborn_reader_wait` until the file is free again).
    subroutine file_begin_write(self, bytes, error)
        class(result_file_t), intent(inout) :: self
        integer(int64), intent(in) :: bytes
        type(error_t), allocatable, intent(out) :: error
        logical :: held
        call check_names(self, error)
        if (allocated(error)) return
        self%size_before = fd_size(self%descriptor())
        call reserve_space(self%descriptor(), self%path, max(bytes, 2*self%write_bytes), error)
        if (allocated(error)) return
        if (.not. self%in_place) return
        call hold_file(self%descriptor(), merge(reader_wait, stubborn_reader_wait, self%patient), held)
        self%patient = held
    end subroutine file_begin_write

    !> After a write: flush it (unless `error`, or a failure its writes without an
    !> error argument kept (`check`): either marks the file broken and gets its
    !> likely cause), give back the space it did not use, let readers in again.
    subroutine file_end_write(self, error)
        class(result_file_t), intent(inout) :: self
        type(error_t), allocatable, intent(inout) :: error
        call self%check(error)
        if (.not. allocated(error)) call self%flush(error)
        if (allocated(error)) then
            self%broken = .true.
            error%message = error%message//write_failure_cause(self%path)
        else
            call release_space(self%descriptor())
            self%write_bytes = max(fd_size(self%descriptor()) - self%size_before, 0_int64)
        end if
        call let_go_file(self%descriptor())
    end subroutine file_end_write

    !> Give the file its name; nothing when it has it. An earlier file there is
    !> replaced (at once) only when the run may and it is a regular file; when it
    !> may not, or something else took the name meanwhile, the file keeps its
    !> `.part` name (`stuck`) and the error says so.
    subroutine file_place(self, error)
        class(result_file_t), intent(inout) :: self
        type(error_t), allocatable, intent(out) :: error
        type(file_info_t) :: there
        if (self%in_place) return
        call check_names(self, error)
        if (allocated(error)) return
        there = file_status(self%final_path, .false.)
        if (there%kind /= kind_missing .and. (there%kind /= kind_regular .or. .not. self%may_replace)) then
            self%stuck = .true.
            call fatal_error(error, "'"//self%final_path//"' appeared while this run wrote it ("// &
                             kind_name(there%kind)//'): not replaced')
            return
        end if
        call rename_file(self%part_path, self%final_path, self%may_replace, error)
        if (allocated(error)) then
            self%stuck = .true.
            return
        end if
        self%in_place = .true.
        self%path = self%final_path
    end subroutine file_place

    !> Close the file after its last write: a file not at its name yet gets it, unless
    !> it has no step (`has_steps` false) and an earlier file is there (that one is
    !> kept: `kept_earlier`). The writer's lock is released. `error` keeps the first
    !> error.
    subroutine file_settle(self, has_steps, error)
        class(result_file_t), intent(inout) :: self
        logical, intent(in) :: has_steps
        type(error_t), allocatable, intent(inout) :: error
        type(error_t), allocatable :: close_error
        logical :: ours
        ours = self%at_name()
        call let_go_file(self%descriptor())
        call self%close(close_error)
        if (.not. allocated(error) .and. allocated(close_error)) call move_alloc(close_error, error)
        if (.not. self%in_place .and. allocated(self%part_path) .and. ours .and. .not. self%stuck) then
            if (.not. has_steps .and. path_kind(self%final_path, .false.) /= kind_missing) then
                call remove_file(self%part_path)
                self%kept_earlier = .true.
            else if (.not. allocated(error)) then
                call self%place(error)
            end if
        end if
        call release_lock(self%writer)
    end subroutine file_settle

    !> Leave the file as it is on disk: no HDF5 call (a write failed; the caller
    !> must end the program without exit handlers); a file not at its name yet is
    !> removed (unless its steps are kept there: `stuck`, or the name is no longer
    !> its). The writer's lock is released.
    subroutine file_abandon(self)
        class(result_file_t), intent(inout) :: self
        if (.not. self%in_place .and. allocated(self%part_path) .and. .not. self%stuck) then
            if (self%at_name()) call remove_file(self%part_path)
        end if
        call let_go_file(self%descriptor())
        call release_lock(self%writer)
    end subroutine file_abandon

    !> Where the steps this run wrote are, for its last message: 'are in <file>',
    !> or why they are not there.
    function file_where_steps(self) result(text)
        class(result_file_t), intent(in) :: self
        character(len=:), allocatable :: text
        if (self%kept_earlier) then
            text = '(none) are not written: the earlier '//self%final_path//' is kept as it was'
        else if (self%lost) then
            text = "are not in '"//self%final_path//"': the file this run wrote was moved, replaced or "// &
                   'removed while it ran'
        else if (self%stuck) then
            text = "are in '"//self%part_path//"' ('"//self%final_path//"' was not replaced)"
        else if (.not. path_exists(self%final_path)) then
            text = "are not in '"//self%final_path//"': it does not exist"
        else if (self%in_place .and. .not. self%at_name()) then
            ! (a removed lock file let another run replace it: `broken`, not `lost`)
            text = "are not in '"//self%final_path//"': another file took its name while this run wrote it"
        else
            text = 'are in '//self%final_path
        end if
    end function file_where_steps

end module voiga_io_output_result_file
