!> The terminal side of a run, an observer of its progress beside the result file
!> (`voiga_solver_observers`): one line per converged step, cut and retry (none with --quiet), and with
!> --verbose one per Newton iteration and linear solve; warnings go to stderr
!> (also with --quiet). On a terminal (not a pipe or a file; not with --quiet or
!> --verbose) a live line shows where a long step is: step, substep, cuts, the
!> Newton iteration and the elapsed time, rewritten in place (carriage return) at
!> every attempt and at most four times a second in between, and wiped before any
!> other line.
module voiga_app_console
    use, intrinsic :: iso_fortran_env, only: output_unit
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use voiga_kinds, only: dp
    use voiga_text, only: str, fixed_str, real_str
    use voiga_error, only: error_t
    use voiga_model, only: model_t
    use voiga_model_accuracy, only: zone_measure_t, worst_of_pair
    use voiga_solver_records, only: cut_record_t, wall_seconds
    use voiga_solver_progress, only: progress_t, iteration_report_t, fixed_point_report_t, step_report_t
    implicit none
    private

    public :: console_t

    !> Prints.
    type, extends(progress_t) :: console_t
        logical :: quiet = .false., verbose = .false.
        !> Show the live line (a terminal, neither --quiet nor --verbose); is it shown now?
        logical :: live = .false., shown = .false.
        !> The run's wall-time origin and when the live line was last written.
        real(dp) :: t0 = 0.0_dp, last = 0.0_dp
        !> Where the run is: step, steps, substep, cuts of the step and of the run, iteration.
        integer :: step = 0, n_steps = 0, sub = 0, cuts = 0, run_cuts = 0, it = 0
        real(dp) :: time = 0.0_dp, fraction = 1.0_dp
    contains
        procedure :: set_up => console_set_up
        procedure :: substep => console_substep
        procedure :: show_live
        procedure :: clear_live
        procedure :: iteration => console_iteration
        procedure :: factorized => console_factorized
        procedure :: linear_solved => console_linear_solved
        procedure :: retried => console_retried
        procedure :: softened => console_softened
        procedure :: cut => console_cut
        procedure :: fixed_point => console_fixed_point
        procedure :: fixed_point_done => console_fixed_point_done
        procedure :: multipliers_updated => console_multipliers_updated
        procedure :: step_done => console_step_done
        procedure :: warning => console_warning
    end type console_t

    !> Seconds between two updates of the live line within an attempt.
    real(dp), parameter :: live_interval = 0.25_dp

contains

    subroutine console_set_up(self, level_dofs, error)
        class(console_t), intent(inout) :: self
        integer, intent(in) :: level_dofs(:)
        type(error_t), allocatable, intent(out) :: error
        call self%clear_live()
        if (.not. self%quiet) write (*, '(a,i0,a,*(1x,i0))') 'multigrid: ', size(level_dofs), &
            ' levels, DOFs', level_dofs
    end subroutine console_set_up

    !> An attempt begins: the live line says where.
    subroutine console_substep(self, step, n_steps, substep, cuts, run_cuts, time, fraction)
        class(console_t), intent(inout) :: self
        integer, intent(in) :: step, n_steps, substep, cuts, run_cuts
        real(dp), intent(in) :: time, fraction
        self%step = step
        self%n_steps = n_steps
        self%sub = substep
        self%cuts = cuts
        self%run_cuts = run_cuts
        self%time = time
        self%fraction = fraction
        self%it = 0
        call self%show_live(.true.)
    end subroutine console_substep

    !> Write the live line (`always`, or when it is older than `live_interval`).
    subroutine show_live(self, always)
        class(console_t), intent(inout) :: self
        logical, intent(in) :: always
        real(dp) :: now
        if (.not. self%live) return
        now = wall_seconds()
        if (.not. always .and. now - self%last < live_interval) return
        self%last = now
        write (*, '(a)', advance='no') achar(13)//'  step '//str(self%step)//'/'//str(self%n_steps)// &
            '  substep '//str(self%sub)//'  cuts '//str(self%cuts)//' (run '//str(self%run_cuts)// &
            ')  t='//fixed_str(self%time, 4)//'  increment '//trim(adjustl(real_str(self%fraction, 'es8.1')))// &
            '  iteration '//str(self%it)//'  elapsed '// &
            fixed_str(now - self%t0, 1)//' s'//achar(27)//'[K'
        flush (output_unit)
        self%shown = .true.
    end subroutine show_live

    !> Wipe the live line, so that the next line starts on an empty one.
    subroutine clear_live(self)
        class(console_t), intent(inout) :: self
        if (.not. self%shown) return
        write (*, '(a)', advance='no') achar(13)//achar(27)//'[K'
        flush (output_unit)
        self%shown = .false.
    end subroutine clear_live

    !> Residual, energy norm, step length, round-off floor and contact states.
    subroutine console_iteration(self, report)
        class(console_t), intent(inout) :: self
        type(iteration_report_t), intent(in) :: report
        integer :: ip
        if (.not. self%verbose) then
            self%it = report%iteration
            call self%show_live(.false.)
            return
        end if
        write (*, '(a,i0,a,i0,a,es10.3,a,es10.3,a,f6.4,a)', advance='no') '  step ', report%step, &
            ' it ', report%iteration, '  |r|=', report%residual, '  |du.r|=', report%energy, '  step length ', &
            report%step_length, '  floor '
        ! a converged iterate evaluated without its tangent has no floor (it needs K)
        if (report%floor >= 0.0_dp) then
            write (*, '(es9.2)', advance='no') report%floor
        else
            write (*, '(a)', advance='no') '    (n/a)'
        end if
        do ip = 1, size(report%points)
            write (*, '(a,i0,a,i0,a,i0)', advance='no') '  stick=', report%stick(ip), ' slip=', report%slip(ip), &
                ' of ', report%points(ip)
        end do
        write (*, '(a)') ''
    end subroutine console_iteration

    subroutine console_factorized(self, sign, log10_det)
        class(console_t), intent(inout) :: self
        integer, intent(in) :: sign
        real(dp), intent(in) :: log10_det
        if (self%verbose) write (*, '(a,i0,a)') '    det K: sign ', sign, ', log10 |det K| '//fixed_str(log10_det, 2)
    end subroutine console_factorized

    subroutine console_linear_solved(self, iterations, residual, asked)
        class(console_t), intent(inout) :: self
        integer, intent(in) :: iterations
        real(dp), intent(in) :: residual, asked
        if (self%verbose) write (*, '(a,i0,a,es9.2,a,es9.2,a)') '    gmres: ', iterations, &
            ' iterations, relative residual ', residual, ' (asked ', asked, ')'
    end subroutine console_linear_solved

    subroutine console_retried(self, step, time, reason)
        class(console_t), intent(inout) :: self
        integer, intent(in) :: step
        real(dp), intent(in) :: time
        character(len=*), intent(in) :: reason
        call self%clear_live()
        if (.not. self%quiet) write (*, '(a,i0,a,f10.6,a)') 'retry step ', step, '  t=', time, &
            ' from the last converged state (the predicted start failed: '//reason//')'
    end subroutine console_retried

    subroutine console_softened(self, step, time, pair, what, reason)
        class(console_t), intent(inout) :: self
        integer, intent(in) :: step, pair
        real(dp), intent(in) :: time
        character(len=*), intent(in) :: what, reason
        call self%clear_live()
        if (.not. self%quiet) write (*, '(a,i0,a,f10.6,a,i0,a)') 'soften step ', step, '  t=', time, &
            ' pair ', pair, ' (alm): '//what//', the same increment again (it failed: '//reason//')'
    end subroutine console_softened

    subroutine console_cut(self, cut, reason)
        class(console_t), intent(inout) :: self
        type(cut_record_t), intent(in) :: cut
        character(len=*), intent(in) :: reason
        call self%clear_live()
        if (.not. self%quiet) write (*, '(a,i0,a,f10.6,a,es9.2,a)') 'cut  step ', cut%step, '  t=', cut%time, &
            '  new increment ', cut%new_fraction, ' of the step: '//reason
    end subroutine console_cut

    subroutine console_fixed_point(self, report)
        class(console_t), intent(inout) :: self
        type(fixed_point_report_t), intent(in) :: report
        if (self%verbose) write (*, '(a,i0,a,i0,a,es10.3,a,es10.3,a,es10.3,a,es9.2,a,i0)') '  step ', &
            report%step, ' fixed point ', report%iteration, '  Coulomb |r|=', report%residual, '  reference ', &
            report%reference, '  max |g change|=', report%change, ' of max g ', report%largest, '  Newton it ', &
            report%newton_iterations
    end subroutine console_fixed_point

    subroutine console_fixed_point_done(self, report)
        class(console_t), intent(inout) :: self
        type(fixed_point_report_t), intent(in) :: report
        call self%clear_live()
        if (.not. self%quiet) write (*, '(a,i0,a,f10.6,a,i0,a,i0,a,6(es9.2,a),i0)') 'tresca step ', &
            report%step, '  t=', report%time, ': the Tresca fixed point converged in ', report%iteration, &
            ' iterations (', report%newton_iterations, ' Newton iterations); Coulomb residual ', report%residual, &
            ' (reference ', report%reference, ', round-off floor ', report%floor, ', force scale ', report%scale, &
            '); last bound change ', report%change, ' of max bound ', report%largest, '; det K sign ', &
            report%det_sign
    end subroutine console_fixed_point_done

    subroutine console_multipliers_updated(self, step, update, residual)
        class(console_t), intent(inout) :: self
        integer, intent(in) :: step, update
        real(dp), intent(in) :: residual
        if (self%verbose) write (*, '(a,i0,a,i0,a,es9.2,a)') '  step ', step, ' multiplier update ', update, &
            '  constraint residual ', residual, ' of the element size'
    end subroutine console_multipliers_updated

    !> One line: step, load time, Newton iterations, residual, seconds (the result
    !> file's writing included: the result file is the observer before this one),
    !> substeps and cuts.
    subroutine console_step_done(self, report, u, model, error)
        class(console_t), intent(inout) :: self
        type(step_report_t), intent(in) :: report
        real(dp), intent(in) :: u(:)
        type(model_t), intent(in) :: model
        type(error_t), allocatable, intent(out) :: error
        real(dp) :: seconds
        call self%clear_live()
        if (self%quiet) return
        associate (rec => report%record)
            ! the step's stages and what passed since the report was made (report%wall,
            ! from the run's origin t0)
            seconds = sum(rec%seconds(1:4)) + wall_seconds() - (self%t0 + report%wall)
            write (*, '(a,i0,a,i0,a,f8.4,a,i2,a,es9.2,a,f8.3,a)', advance='no') 'step ', rec%step, '/', &
                report%n_steps, '  t=', rec%time, '  it=', rec%iterations, '  |r|=', report%residual, '  ', &
                seconds, ' s'
            if (rec%substeps > 1 .or. rec%cuts > 0) write (*, '(a,i0,a,i0)', advance='no') &
                '  substeps=', rec%substeps, ' cuts=', rec%cuts
            write (*, '(a)') edge_errors(model)
        end associate
    end subroutine console_step_done

    !> "  edge error 0.41%" per contact pair on an edge with a zone (the estimate of the
    !> contact-zone indicator, docs/contact-accuracy.md; "unresolved" for a zone of too few
    !> points), "" without one.
    function edge_errors(model) result(text)
        type(model_t), intent(in) :: model
        character(len=:), allocatable :: text
        type(zone_measure_t) :: zone
        logical :: found
        real(dp) :: e
        integer :: k
        text = ''
        do k = 1, size(model%pairs)
            call worst_of_pair(model, k, zone, found)
            if (.not. found) cycle
            e = zone%estimate
            if (ieee_is_finite(e)) then
                text = text//'  edge error '//fixed_str(100.0_dp*e, 2)//'%'
            else
                text = text//'  edge error unresolved'
            end if
        end do
    end function edge_errors

    !> `voiga: warning: <text>` on stderr.
    subroutine console_warning(self, text)
        class(console_t), intent(inout) :: self
        character(len=*), intent(in) :: text
        call self%clear_live()
        write (0, '(a)') 'voiga: warning: '//text
    end subroutine console_warning

end module voiga_app_console
