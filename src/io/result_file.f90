!> A result file as its readers see it (docs/hdf5.md, "Writing and reading a
!> running result"; docs/formats.md, "Outputs"): an HDF5 file that
!> - is written as `<result>.part` and renamed to its name once its first step is in
!>   it, so an earlier file there is replaced only by one with a step;
!> - has one writer, who holds the lock file `<result>.lock` for the whole run (a
!>   second writer is refused, whatever HDF5_USE_FILE_LOCKING says);
!> - is changed only between `begin_write` and `end_write`: space is reserved first
!>   (a full disk or quota stops the run before the write, the file as it was), an
!>   exclusive `flock` on the file keeps readers out (those that take a shared
!>   one, as HDF5's own locking and `post` do, read only whole steps), and the
!>   write is flushed before readers are let in again;
!> - once a write to it has failed, is `broken`: nothing more may reach it (the
!>   program must leave without HDF5's exit handlers, which would write half a step
!>   over the last flush).
module voiga_io_result_file
    use, intrinsic :: iso_fortran_env, only: int64
    use voiga_error, only: error_t
    use voiga_io_hdf5, only: h5file_t, finish_interrupted_flush
    use voiga_io_os, only: lock_t, acquire_lock, release_lock, hold_exclusive, let_go, reserve_space, &
                           release_space, rename_file, remove_file, path_exists, companion
    use voiga_io_process, only: write_failure_cause
    implicit none
    private

    public :: result_file_t

    !> Seconds a writer waits for a reader to let go of the file before it writes
    !> anyway, and how long once a reader has outlasted that (a file left open in
    !> an interactive h5py session must not slow every step down).
    real, parameter :: reader_wait = 30.0, stubborn_reader_wait = 0.1

    !> An open result file and its guards.
    type, extends(h5file_t) :: result_file_t
        !> The result file, and where it is written until its first step is in it.
        character(len=:), allocatable :: final_path, part_path
        !> The writer's lock file, and the `flock` held on the file while writing.
        type(lock_t) :: writer, window
        !> Is the file at its name (a step written, or a restart)? Did a write to it
        !> fail? Was an earlier file at the name kept because this run wrote no step?
        logical :: in_place = .false., broken = .false., kept_earlier = .false.
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
    end type result_file_t

contains

    !> Take the writer's lock of the result file `path` (its lock file beside it):
    !> refused while another run writes it. Nothing if this object holds it. A flush
    !> that a killed earlier writer left half done is finished (`finish_interrupted_flush`):
    !> whatever reads the file next (a restart, or a reader while this run has not
    !> replaced it) reads the file of that writer's last flush.
    subroutine file_claim(self, path, error)
        class(result_file_t), intent(inout) :: self
        character(len=*), intent(in) :: path
        type(error_t), allocatable, intent(out) :: error
        logical :: finished
        if (self%writer%fd >= 0) return
        call acquire_lock(self%writer, companion(path, '.lock'), "result file '"//path//"'", error)
        if (allocated(error)) return
        self%final_path = path
        if (path_exists(path)) call finish_interrupted_flush(path, finished)
    end subroutine file_claim

    !> Start a new result file `path` (claimed first): `path`.part, created afresh.
    subroutine file_create(self, path, error)
        class(result_file_t), intent(inout) :: self
        character(len=*), intent(in) :: path
        type(error_t), allocatable, intent(out) :: error
        call self%claim(path, error)
        if (allocated(error)) return
        self%part_path = companion(path, '.part')
        call remove_file(self%part_path)
        call self%open(self%part_path, 'w', error)
        if (allocated(error)) error%message = error%message//' (is the folder writable?)'
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
        self%in_place = .true.
    end subroutine file_resume

    !> Before a write: reserve space for it (`bytes`, or twice what the last write
    !> added if more) and, once the file is at its name, hold the exclusive `flock`
    !> readers wait for (waiting at most `reader_wait` for one that holds the file
    !> longer, then only `stubborn_reader_wait` until the file is free again).
    subroutine file_begin_write(self, bytes, error)
        class(result_file_t), intent(inout) :: self
        integer(int64), intent(in) :: bytes
        type(error_t), allocatable, intent(out) :: error
        logical :: held
        inquire (file=self%path, size=self%size_before)
        call reserve_space(self%path, max(bytes, 2*self%write_bytes), error)
        if (allocated(error)) return
        if (.not. self%in_place) return
        call hold_exclusive(self%window, self%final_path, merge(reader_wait, stubborn_reader_wait, self%patient), &
                            held)
        self%patient = held
    end subroutine file_begin_write

    !> After a write: flush it (unless `error`, which marks the file broken and gets
    !> its likely cause), give back the space it did not use, let readers in again.
    subroutine file_end_write(self, error)
        class(result_file_t), intent(inout) :: self
        type(error_t), allocatable, intent(inout) :: error
        integer(int64) :: after
        if (.not. allocated(error)) call self%flush(error)
        if (allocated(error)) then
            self%broken = .true.
            error%message = error%message//write_failure_cause(self%path)
        else
            call release_space(self%path)
            inquire (file=self%path, size=after)
            self%write_bytes = max(after - self%size_before, 0_int64)
        end if
        call let_go(self%window)
    end subroutine file_end_write

    !> Give the file its name (an earlier file there is replaced at once); nothing
    !> when it has it.
    subroutine file_place(self, error)
        class(result_file_t), intent(inout) :: self
        type(error_t), allocatable, intent(out) :: error
        if (self%in_place) return
        call rename_file(self%part_path, self%final_path, error)
        if (allocated(error)) return
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
        call self%close(close_error)
        call let_go(self%window)
        if (.not. allocated(error) .and. allocated(close_error)) call move_alloc(close_error, error)
        if (.not. self%in_place .and. allocated(self%part_path)) then
            if (.not. has_steps .and. path_exists(self%final_path)) then
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
    !> removed. The writer's lock is released.
    subroutine file_abandon(self)
        class(result_file_t), intent(inout) :: self
        if (.not. self%in_place .and. allocated(self%part_path)) call remove_file(self%part_path)
        call let_go(self%window)
        call release_lock(self%writer)
    end subroutine file_abandon

end module voiga_io_result_file
