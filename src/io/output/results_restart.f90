!> Reading a result file back for a restart (`voiga_io_output_results`): the case the run
!> was started from and the state after its last written step, read as
!> `results_write_step` wrote it (symmetric persistence: the writer's module reads
!> it back). A submodule only to keep the files short; the interfaces and their
!> documentation are in the module.
submodule(voiga_io_output_results) voiga_io_output_results_restart
    implicit none

contains

    module procedure restart_case
        type(h5file_t) :: f
        character(len=:), allocatable :: absolute
        call f%open(path, 'r', error)
        if (allocated(error)) return
        call f%read_attr_str('/', 'case_file', case_file, error)
        ! run from another folder: the absolute path recorded beside it
        if (.not. allocated(error) .and. .not. path_exists(case_file) .and. f%has_attr('/', 'case_path')) then
            call f%read_attr_str('/', 'case_path', absolute, error)
            if (.not. allocated(error)) case_file = absolute
        end if
        call close_read(f, error)
        if (allocated(error)) error%message = '--restart: '//error%message
    end procedure restart_case

    module procedure read_restart
        type(h5file_t) :: h5
        call h5%open(path, 'r', error)
        if (allocated(error)) return
        call check_dimension(h5, model%nsd, error)
        if (.not. allocated(error)) call read_state(h5, model, state, error)
        call close_read(h5, error)
    end procedure read_restart

    !> A restart continues only a file of its model's spatial dimension `nsd` (every
    !> spatial axis of the file has that length; a 2D displacement read as 3D would
    !> mix the components of different control points). A file without the root
    !> attribute `dimension` was written before voiga wrote it, by a 2D voiga: 2.
    !> Refused whatever `--force-restart` says.
    subroutine check_dimension(h5, nsd, error)
        type(h5file_t), intent(inout) :: h5
        integer, intent(in) :: nsd
        type(error_t), allocatable, intent(out) :: error
        integer :: recorded
        recorded = 2
        if (h5%has_attr('/', 'dimension')) call h5%read_attr_int('/', 'dimension', recorded, error)
        if (allocated(error)) return
        if (recorded /= nsd) &
            call fatal_error(error, h5%path//': --restart: the result file is of dimension '//str(recorded)// &
                             ' (its root attribute dimension) but the case''s model is of dimension '// &
                             str(nsd)//': a restart continues only a run of its own dimension', &
                             error_code%input)
    end subroutine check_dimension

    !> Close a file that was only read; `error` keeps the first error.
    subroutine close_read(h5, error)
        type(h5file_t), intent(inout) :: h5
        type(error_t), allocatable, intent(inout) :: error
        type(error_t), allocatable :: close_error
        call h5%close(close_error)
        if (.not. allocated(error) .and. allocated(close_error)) call move_alloc(close_error, error)
    end subroutine close_read

    subroutine read_state(h5, model, state, error)
        type(h5file_t), intent(inout) :: h5
        type(model_t), intent(inout) :: model
        type(resume_t), intent(out) :: state
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: g
        character(len=16) :: buf
        integer :: done, ip

        call h5%read_attr_int('/', 'n_steps_done', done, error)
        if (allocated(error)) return
        state%step = done
        allocate (state%u(model%ndof))
        state%u = 0.0_dp
        if (done == 0) return
        write (buf, '(i6.6)') done
        g = '/steps/'//trim(buf)
        ! (at most the model's DOFs are read: a file that claims more is refused
        ! before anything is allocated)
        call h5%read(g//'/displacement', state%u, error, int(model%ndof, int64))
        if (allocated(error)) return
        ! the step before (the predictor extrapolates the last step's increment)
        allocate (state%u_before(size(state%u)))
        state%u_before = 0.0_dp
        if (done > 1) then
            write (buf, '(i6.6)') done - 1
            call h5%read('/steps/'//trim(buf)//'/displacement', state%u_before, error, int(model%ndof, int64))
            if (allocated(error)) return
        end if
        if (size(state%u) /= model%ndof) then
            call fatal_error(error, h5%path//': --restart: the result file does not belong to this '// &
                             'case (different number of DOFs)', error_code%input)
            return
        end if
        if (h5%has_attr(g, 'next_fraction')) call h5%read_attr_real(g, 'next_fraction', state%fraction, error)
        if (allocated(error)) return
        if (h5%has_attr(g, 'r0_max')) call h5%read_attr_real(g, 'r0_max', state%r0_max, error)
        if (allocated(error)) return
        if (h5%has_attr(g, 'tangent_det_sign')) &
            call h5%read_attr_int(g, 'tangent_det_sign', state%det_sign, error)
        if (allocated(error)) return
        do ip = 1, size(model%pairs)
            write (buf, '(i0)') ip
            call read_history(h5, g//'/contact/'//trim(buf)//'/history', model%pairs(ip)%pair, error)
            if (allocated(error)) return
            call read_penalties(h5, g//'/contact/'//trim(buf), model%pairs(ip)%pair, error)
            if (allocated(error)) return
        end do
    end subroutine read_state

    !> The penalties a pair with multipliers used at the step of group `c` (it may
    !> have softened them, `alm_soften`): a restart goes on with them, as the run
    !> did. Other pairs keep the case's (a user may restart with another penalty);
    !> so do files without the attributes.
    subroutine read_penalties(h5, c, pair, error)
        type(h5file_t), intent(inout) :: h5
        character(len=*), intent(in) :: c
        class(contact_pair_t), intent(inout) :: pair
        type(error_t), allocatable, intent(out) :: error
        real(dp) :: eps_n, eps_t
        if (.not. pair%has_multipliers()) return
        eps_n = pair%law%eps_n
        eps_t = pair%law%eps_t
        if (h5%has_attr(c, 'penalty_normal')) call h5%read_attr_real(c, 'penalty_normal', eps_n, error)
        if (allocated(error)) return
        if (h5%has_attr(c, 'penalty_tangent')) call h5%read_attr_real(c, 'penalty_tangent', eps_t, error)
        if (allocated(error)) return
        call pair%set_penalties(eps_n, eps_t)
    end subroutine read_penalties

    !> Read the committed history `pair` keeps (its `history` names the arrays) from
    !> group `c` and set it on the pair.
    subroutine read_history(h5, c, pair, error)
        type(h5file_t), intent(inout) :: h5
        character(len=*), intent(in) :: c
        class(contact_pair_t), intent(inout) :: pair
        type(error_t), allocatable, intent(out) :: error
        type(history_item_t), allocatable :: history(:)
        integer(int64) :: most
        integer :: i
        history = pair%history()
        if (size(history) == 0) return
        do i = 1, size(history)
            ! (at most as many values as the pair keeps: counted before the read
            ! reallocates the array)
            if (allocated(history(i)%values)) then
                most = size(history(i)%values, kind=int64)
            else
                most = size(history(i)%flags, kind=int64)
            end if
            if (history(i)%most >= 0) most = history(i)%most
            if (allocated(history(i)%values)) then
                call h5%read(c//'/'//trim(history(i)%name), history(i)%values, error, most)
            else
                call h5%read(c//'/'//trim(history(i)%name), history(i)%flags, error, most)
            end if
            if (allocated(error)) return
        end do
        call pair%set_history(history, error)
    end subroutine read_history

end submodule voiga_io_output_results_restart
