!> Quasi-static load stepping with adaptive load increments (docs/stepping.md).
!>
!> Per (sub)step the prescribed displacements are set to their values at the load
!> time and a Newton attempt (`voiga_solver_newton`) solves the step. A substep
!> that fails numerically is cut: the last converged state (u and the contact
!> pairs' trial history) is restored and the increment halved, down to
!> `min_step_fraction` of the nominal step; after a substep that converged in at
!> most `grow_iterations` iterations the increment doubles again (never beyond the
!> nominal step). Substeps subdivide a nominal step, so the case's steps are hit
!> exactly and only their converged states are reported. A substep may start from
!> the last step's increment, extrapolated (`predictor`); a predicted start that
!> fails is retried once from the last converged state. A frictional substep whose
!> attempt from the last converged state failed with contact states switching is
!> retried once by the Tresca fixed point (`voiga_solver_outer`) before it is cut.
!> A step that fails at its limit gets the diagnoses of `voiga_solver_diagnostics`.
!> A step whose failed attempts since its last converged substep have taken
!> `max_stalled_iterations` Newton iterations is given up as hopeless, with the
!> suggestion of more load steps. A failed run names the warnings reported before
!> (`voiga_model_checks`): they often explain the failure.
module voiga_solver_stepping
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_model, only: model_t, set_prescribed, set_contact_time
    use voiga_solver_settings, only: solver_settings_t
    use voiga_platform_signals, only: caught_signal, signal_name
    use voiga_solver_records, only: solver_stats_t, step_record_t, cut_record_t, append_cut, wall_seconds
    use voiga_solver_progress, only: progress_t, step_report_t
    use voiga_solver_newton, only: newton_t, new_newton, attempt_t
    use voiga_solver_stick_predictor, only: stick_predictor
    use voiga_solver_outer, only: tresca_fixed_point, frictional, substep_attempt
    use voiga_solver_diagnostics, only: fold_diagnosis, append_pair_diagnoses
    use voiga_model_checks, only: contact_watch_t, new_contact_watch, setup_warnings, warning_t
    use voiga_text, only: str, real_str
    implicit none
    private

    public :: solve_steps, resume_t

    !> Where a restarted run continues: after step `step`, from displacement `u`, with
    !> the substep fraction and force scale the interrupted run had there (the contact
    !> pairs' committed history is set on the model by the caller).
    type :: resume_t
        integer :: step = 0
        !> Displacement after `step` and after the step before it.
        real(dp), allocatable :: u(:), u_before(:)
        real(dp) :: fraction = 1.0_dp, r0_max = 0.0_dp
        !> Sign of det K of the last tangent factorized before `step` was written.
        integer :: det_sign = 0
    end type resume_t

    !> The load stepping's state between substeps.
    type :: stepper_t
        type(solver_settings_t) :: settings
        type(newton_t) :: newton
        !> Converged state, and the converged states at the ends of the last two
        !> nominal steps (step 0: zero).
        real(dp), allocatable :: u_conv(:), u_step(:), u_step_before(:)
        !> The load increment as a fraction of the nominal step (carried over steps);
        !> the converged part of the current nominal step (sums of powers of 2: exact).
        real(dp) :: frac = 1.0_dp, s = 0.0_dp
        !> The next attempt starts from the converged state, not the predictor.
        logical :: unpredicted_retry = .false.
        !> Sign of det K at the last converged substep; det K <= 0 iterations and all
        !> iterations of the last failed attempt started from the converged state.
        integer :: conv_det_sign = 0, fold_iterations = 0, fold_total = 0
        !> Wall time origin of the run.
        real(dp) :: start = 0.0_dp
        !> What the warnings after each step and at the end remember.
        type(contact_watch_t) :: watch
        !> Every warning reported so far (a failure points back to them).
        type(warning_t), allocatable :: warned(:)
        !> The run's Newton iterations when the last substep converged (or the step began).
        integer :: stall_start = 0
    end type stepper_t

contains

    !> Run every load step of `model` (from zero displacement, or from `resume`)
    !> with the solver `settings`; report progress and each converged step through
    !> `progress`. `u` holds the last converged displacement on return (also on
    !> failure). An interrupt (stats%signal /= 0) returns an error too.
    subroutine solve_steps(model, settings, u, stats, error, progress, resume, t0)
        type(model_t), intent(inout) :: model
        type(solver_settings_t), intent(in) :: settings
        real(dp), allocatable, intent(out) :: u(:)
        type(solver_stats_t), intent(out) :: stats
        type(error_t), allocatable, intent(out) :: error
        !> Where progress and converged steps go (default: nowhere).
        class(progress_t), intent(inout), optional, target :: progress
        !> Continue an interrupted run instead of starting from zero.
        type(resume_t), intent(in), optional :: resume
        !> Wall time origin of the run (for the times reported).
        real(dp), intent(in), optional :: t0
        type(progress_t), target :: silent
        class(progress_t), pointer :: out
        type(stepper_t) :: sp
        type(warning_t), allocatable :: warnings(:)
        integer :: step, first
        real(dp) :: t

        out => silent
        if (present(progress)) out => progress
        sp%start = wall_seconds()
        if (present(t0)) sp%start = t0
        sp%settings = settings
        if (.not. allocated(sp%settings%n_steps)) sp%settings%n_steps = [1]
        call new_newton(sp%newton, model, sp%settings, stats%assembly, error)
        if (allocated(error)) return
        stats%multigrid_levels = sp%newton%linear%level_dofs()
        if (size(stats%multigrid_levels) > 0) call out%set_up(stats%multigrid_levels, error)
        if (allocated(error)) return
        allocate (u(model%ndof))
        u = 0.0_dp
        sp%u_conv = u
        sp%u_step = u
        allocate (stats%records(0), stats%cut_records(0))
        first = 1
        if (present(resume)) call resume_from(sp, resume, u, stats, first)
        call new_contact_watch(sp%watch, model)
        allocate (sp%warned(0))
        call report_warnings(sp, out, setup_warnings(model))
        t = 0.0_dp
        do step = first, sp%settings%total_steps()
            call solve_step(sp, model, step, u, stats, out, t, error)
            if (allocated(error)) exit
            ! (a signal during the last step's output: the run is complete anyway)
            if (caught_signal() /= 0 .and. step < sp%settings%total_steps()) then
                stats%signal = caught_signal()
                call fatal_error(error, 'interrupted by '//signal_name(stats%signal))
                exit
            end if
        end do
        if (.not. allocated(error)) then
            call sp%watch%at_end(model, sp%settings%total_steps() - first + 1, warnings)
            call report_warnings(sp, out, warnings)
        end if
        if (allocated(error) .and. stats%signal == 0) then
            call prefix_step(error, step, t)
            if (error%code == error_code%numeric) call point_back(error, sp%warned)
        end if
        call sp%newton%linear%factorizations(stats%symbolic_factorizations, stats%numeric_factorizations)
    end subroutine solve_steps

    !> Start from the state after `resume%step` of an interrupted run.
    subroutine resume_from(sp, resume, u, stats, first)
        type(stepper_t), intent(inout) :: sp
        type(resume_t), intent(in) :: resume
        real(dp), intent(inout) :: u(:)
        type(solver_stats_t), intent(inout) :: stats
        integer, intent(inout) :: first
        if (.not. allocated(resume%u)) return
        u = resume%u
        sp%u_conv = u
        sp%u_step = u
        if (allocated(resume%u_before)) sp%u_step_before = resume%u_before
        sp%frac = resume%fraction
        stats%r0_max = resume%r0_max
        sp%conv_det_sign = resume%det_sign
        first = resume%step + 1
    end subroutine resume_from

    !> Every warning of `list` to `progress`; the stepper keeps them.
    subroutine report_warnings(sp, progress, list)
        type(stepper_t), intent(inout) :: sp
        class(progress_t), intent(inout) :: progress
        type(warning_t), intent(in) :: list(:)
        integer :: i
        do i = 1, size(list)
            call progress%warning(trim(list(i)%text))
        end do
        sp%warned = [sp%warned, list]
    end subroutine report_warnings

    !> A numerical failure after warnings: name them (their topics), since a wrong
    !> set-up or a soft penalty often explains the failure.
    pure subroutine point_back(error, warned)
        type(error_t), intent(inout) :: error
        type(warning_t), intent(in) :: warned(:)
        integer :: i
        if (size(warned) == 0) return
        error%message = error%message//'. It may follow from the warning'
        if (size(warned) > 1) error%message = error%message//'s'
        error%message = error%message//' reported before (stderr, and in the result file: post summary): '
        do i = 1, size(warned)
            if (i > 1) error%message = error%message//'; '
            error%message = error%message//trim(warned(i)%topic)
        end do
    end subroutine point_back

    !> "step N (load time t): " before the reason of a failed run.
    pure subroutine prefix_step(error, step, t)
        type(error_t), intent(inout) :: error
        integer, intent(in) :: step
        real(dp), intent(in) :: t
        error%message = 'step '//str(step)//' (load time '//real_str(t, 'es12.5')//'): '//error%message
    end subroutine prefix_step

    !> Nominal step `step`: substeps until it is complete, cutting the increment on
    !> failure; then its reactions and report. `t`: the load time of the last attempt.
    subroutine solve_step(sp, model, step, u, stats, progress, t, error)
        type(stepper_t), intent(inout) :: sp
        type(model_t), intent(inout) :: model
        integer, intent(in) :: step
        real(dp), intent(inout) :: u(:)
        type(solver_stats_t), intent(inout) :: stats
        class(progress_t), intent(inout) :: progress
        real(dp), intent(out) :: t
        type(error_t), allocatable, intent(out) :: error
        type(step_record_t) :: rec
        type(attempt_t) :: attempt
        real(dp) :: t_begin, t_end, ds
        integer :: first_cut
        logical :: predicted, stop_run

        t_begin = sp%settings%step_time(step - 1)
        t_end = sp%settings%step_time(step)
        rec = step_record_t()
        rec%step = step
        rec%time = t_end
        rec%substeps = 0
        first_cut = size(stats%cut_records) + 1
        sp%stall_start = stats%iterations
        sp%fold_iterations = 0
        sp%fold_total = 0
        sp%s = 0.0_dp
        do while (sp%s < 1.0_dp)
            ds = min(sp%frac, 1.0_dp - sp%s)
            t = t_end
            if (sp%s + ds < 1.0_dp) t = t_begin + (sp%s + ds)*(t_end - t_begin)
            call progress%substep(step, sp%settings%total_steps(), rec%substeps + 1, rec%cuts, stats%cuts, t, ds)
            call attempt_substep(sp, model, step, t, ds, u, stats, rec, progress, attempt, predicted, error)
            if (.not. allocated(error)) then
                call accept_substep(sp, model, ds, u, attempt, stats, rec)
                cycle
            end if
            call handle_failure(sp, model, step, t, t_begin, t_end, ds, predicted, u, stats, rec, progress, &
                                stop_run, error)
            if (stop_run) return
        end do
        call finish_step(sp, model, step, u, attempt, stats, rec, first_cut, progress, error)
    end subroutine solve_step

    !> One attempt at the substep ending at load time `t` (increment `ds`): from
    !> the predictor or the converged state, Newton (or, with `tresca_always`, the
    !> Tresca fixed point); a frictional attempt from the converged state that failed
    !> with contact states switching is retried by the Tresca fixed point.
    subroutine attempt_substep(sp, model, step, t, ds, u, stats, rec, progress, attempt, predicted, error)
        type(stepper_t), intent(inout) :: sp
        type(model_t), intent(inout) :: model
        integer, intent(in) :: step
        real(dp), intent(in) :: t, ds
        real(dp), intent(inout) :: u(:)
        type(solver_stats_t), intent(inout) :: stats
        type(step_record_t), intent(inout) :: rec
        class(progress_t), intent(inout) :: progress
        type(attempt_t), intent(out) :: attempt
        logical, intent(out) :: predicted
        type(error_t), allocatable, intent(out) :: error
        type(error_t), allocatable :: tresca_error
        integer :: ip
        logical :: retry

        predicted = .false.
        retry = sp%unpredicted_retry
        if (sp%settings%predictor .and. .not. retry .and. allocated(sp%u_step_before) &
            .and. step >= 2) then
            if (sp%settings%phase_of_step(step - 1) == sp%settings%phase_of_step(step)) then
                u = u + ds*(sp%u_step - sp%u_step_before)
                predicted = .true.
            end if
        end if
        sp%unpredicted_retry = .false.
        if (sp%settings%tresca_always .and. frictional(model)) then
            u = sp%u_conv
            predicted = .false.
            call tresca_fixed_point(sp%newton, model, step, t, u, stats, rec, progress, attempt, error)
            return
        end if
        call set_prescribed(model, t, u)
        if (.not. predicted .and. .not. retry .and. sp%settings%stick_predictor .and. sliding_start(model, t)) then
            ! (a failure from this start is retried once from the converged state)
            call stick_predictor(sp%newton, model, t, u, stats, rec, error)
            if (allocated(error)) return
            predicted = .true.
        end if
        call substep_attempt(sp%newton, model, step, t, u, stats, rec, progress, attempt, error)
        if (.not. allocated(error) .or. predicted) return
        sp%fold_iterations = attempt%nonpositive_det
        sp%fold_total = attempt%iterations
        ! contact states still switching in a frictional case (a period-2 cycle or the
        ! cap with switches; at a fold det K also changes sign, but the stick/slip
        ! switch of a stiff penalty stalls Newton with det K > 0 as well): retry the
        ! same increment with the Tresca fixed point before cutting
        if (error%code /= error_code%numeric .or. stats%signal /= 0 .or. .not. attempt%switching .or. &
            .not. frictional(model)) return
        u = sp%u_conv
        do ip = 1, size(model%pairs)
            call model%pairs(ip)%pair%reset_trial()
        end do
        call tresca_fixed_point(sp%newton, model, step, t, u, stats, rec, progress, attempt, tresca_error)
        if (.not. allocated(tresca_error)) then
            deallocate (error)
        else if (stats%signal /= 0) then
            call move_alloc(tresca_error, error)
        else
            error%message = error%message//'; retried with the Tresca fixed point: '//tresca_error%message
        end if
    end subroutine attempt_substep

    !> Whether a substep at load time `t` starts with points that may stick: a pair
    !> with friction at `t` and a point in contact at the last converged state.
    logical function sliding_start(model, t)
        type(model_t), intent(inout) :: model
        real(dp), intent(in) :: t
        integer :: ip
        call set_contact_time(model, t)
        sliding_start = .false.
        do ip = 1, size(model%pairs)
            if (model%pairs(ip)%pair%law%mu > 0.0_dp .and. model%pairs(ip)%pair%contact_last()) &
                sliding_start = .true.
        end do
    end function sliding_start

    !> The substep converged: it is the new converged state; the increment grows
    !> after an easy substep.
    subroutine accept_substep(sp, model, ds, u, attempt, stats, rec)
        type(stepper_t), intent(inout) :: sp
        type(model_t), intent(inout) :: model
        real(dp), intent(in) :: ds, u(:)
        type(attempt_t), intent(in) :: attempt
        type(solver_stats_t), intent(inout) :: stats
        type(step_record_t), intent(inout) :: rec
        integer :: ip
        if (attempt%iterations > 0) sp%conv_det_sign = attempt%det_sign
        sp%u_conv = u
        sp%stall_start = stats%iterations
        do ip = 1, size(model%pairs)
            call model%pairs(ip)%pair%commit()
        end do
        sp%s = sp%s + ds
        rec%substeps = rec%substeps + 1
        stats%substeps = stats%substeps + 1
        if (attempt%iterations <= sp%settings%grow_iterations) sp%frac = min(1.0_dp, 2.0_dp*sp%frac)
    end subroutine accept_substep

    !> A failed substep: back to the last converged state; then retry a predicted
    !> start once from there, or cut the increment, or (at the limit, on a signal or
    !> a non-numerical failure) end the run with the error (`stop_run`).
    subroutine handle_failure(sp, model, step, t, t_begin, t_end, ds, predicted, u, stats, rec, progress, &
                              stop_run, error)
        type(stepper_t), intent(inout) :: sp
        type(model_t), intent(inout) :: model
        integer, intent(in) :: step
        real(dp), intent(in) :: t, t_begin, t_end, ds
        logical, intent(in) :: predicted
        real(dp), intent(inout) :: u(:)
        type(solver_stats_t), intent(inout) :: stats
        type(step_record_t), intent(inout) :: rec
        class(progress_t), intent(inout) :: progress
        logical, intent(out) :: stop_run
        type(error_t), allocatable, intent(inout) :: error
        type(cut_record_t) :: cut
        integer :: ip

        u = sp%u_conv
        do ip = 1, size(model%pairs)
            call model%pairs(ip)%pair%reset_trial()
        end do
        stop_run = stats%signal /= 0 .or. error%code /= error_code%numeric
        if (stop_run) return
        if (softened(model, step, t, progress, error%message)) then
            ! a penalty that does not decide the solution was made softer: the same
            ! increment again, as it was attempted
            stats%softenings = stats%softenings + 1
            sp%unpredicted_retry = .not. predicted
            deallocate (error)
            return
        end if
        if (predicted) then
            ! a predicted start that fails is retried once from the last converged
            ! state, at the same increment, before the increment is cut
            sp%unpredicted_retry = .true.
            stats%predictor_retries = stats%predictor_retries + 1
            call progress%retried(step, t, error%message)
            deallocate (error)
            return
        end if
        if (sp%settings%max_stalled_iterations > 0 .and. &
            stats%iterations - sp%stall_start >= sp%settings%max_stalled_iterations) then
            call explain_failure(sp, model, t_begin + sp%s*(t_end - t_begin), ds, rec, stats, error, &
                                 stalled=stats%iterations - sp%stall_start)
            stop_run = .true.
            return
        end if
        if (rec%cuts >= sp%settings%max_cuts .or. &
            0.5_dp*ds < sp%settings%min_step_fraction*(1.0_dp - 1.0e-12_dp)) then
            call explain_failure(sp, model, t_begin + sp%s*(t_end - t_begin), ds, rec, stats, error)
            stop_run = .true.
            return
        end if
        cut = cut_record_t(step=step, time=t, fraction=ds, new_fraction=0.5_dp*ds, reason=error%message)
        call append_cut(stats%cut_records, cut)
        stats%cuts = stats%cuts + 1
        rec%cuts = rec%cuts + 1
        sp%frac = 0.5_dp*ds
        call progress%cut(cut, error%message)
        deallocate (error)
    end subroutine handle_failure

    !> Let every pair soften its penalties after a failed substep (`reason`); whether
    !> one did (each says what it changed through `progress`).
    logical function softened(model, step, t, progress, reason) result(any_changed)
        type(model_t), intent(inout) :: model
        integer, intent(in) :: step
        real(dp), intent(in) :: t
        class(progress_t), intent(inout) :: progress
        character(len=*), intent(in) :: reason
        character(len=:), allocatable :: what
        logical :: changed
        integer :: ip
        any_changed = .false.
        do ip = 1, size(model%pairs)
            call model%pairs(ip)%pair%soften(changed, what)
            if (.not. changed) cycle
            any_changed = .true.
            call progress%softened(step, t, ip, what, reason)
        end do
    end function softened

    !> The step cannot be cut further, or (`stalled`: the Newton iterations of its
    !> failed attempts since the last converged substep) is given up as hopeless:
    !> the limits it reached, and the diagnoses at the last converged state (load
    !> time `t_conv`).
    subroutine explain_failure(sp, model, t_conv, ds, rec, stats, error, stalled)
        type(stepper_t), intent(inout) :: sp
        type(model_t), intent(inout) :: model
        real(dp), intent(in) :: t_conv, ds
        type(step_record_t), intent(in) :: rec
        type(solver_stats_t), intent(inout) :: stats
        type(error_t), intent(inout) :: error
        integer, intent(in), optional :: stalled
        if (present(stalled)) then
            error%message = error%message//'; gave the step up: its attempts since the last converged substep '// &
                            'took '//str(stalled)//' Newton iterations without converging (the budget, &solver '// &
                            'max_stalled_iterations = '//str(sp%settings%max_stalled_iterations)//'; '// &
                            str(rec%cuts)//' cuts, increment '//real_str(ds, 'es9.2')//' of the nominal step). '// &
                            'The load of a step is likely too large to follow: give more load steps (&solver '// &
                            'n_steps'//steps_now(sp%settings%n_steps)//') or smaller motions per step'
        else if (rec%cuts > 0 .or. sp%settings%max_cuts > 0) then
            error%message = error%message//' (after '//str(rec%cuts)//' cuts; increment '// &
                            real_str(ds, 'es9.2')//' of the nominal step, minimum '// &
                            real_str(sp%settings%min_step_fraction, 'es9.2')//', max_cuts '// &
                            str(sp%settings%max_cuts)//')'
        end if
        if (sp%fold_iterations > 0 .and. (sp%fold_iterations < sp%fold_total .or. sp%conv_det_sign > 0)) &
            error%message = error%message//fold_diagnosis(model, sp%fold_iterations, sp%fold_total)
        call append_pair_diagnoses(model, sp%u_conv, t_conv, stats%assembly, error%message)
    end subroutine explain_failure

    !> " now a, b" (the load steps of each phase).
    pure function steps_now(n_steps) result(text)
        integer, intent(in) :: n_steps(:)
        character(len=:), allocatable :: text
        integer :: k
        text = ', now'
        do k = 1, size(n_steps)
            if (k > 1) text = text//','
            text = text//' '//str(n_steps(k))
        end do
    end function steps_now

    !> The nominal step converged: its reactions, its report (the result file writes
    !> it), its record.
    subroutine finish_step(sp, model, step, u, attempt, stats, rec, first_cut, progress, error)
        type(stepper_t), intent(inout) :: sp
        type(model_t), intent(in) :: model
        integer, intent(in) :: step
        real(dp), intent(in) :: u(:)
        type(attempt_t), intent(in) :: attempt
        type(solver_stats_t), intent(inout) :: stats
        type(step_record_t), intent(inout) :: rec
        integer, intent(in) :: first_cut
        class(progress_t), intent(inout) :: progress
        type(error_t), allocatable, intent(out) :: error
        type(step_report_t) :: report
        type(warning_t), allocatable :: warnings(:)
        real(dp) :: tic
        integer :: j, c

        sp%u_conv = u
        sp%u_step_before = sp%u_step
        sp%u_step = u
        stats%steps = step
        rec%det_sign = sp%conv_det_sign
        allocate (rec%reactions(2, size(model%dirichlet)))
        do j = 1, size(model%dirichlet)
            do c = 1, 2
                rec%reactions(c, j) = sum(sp%newton%r(model%dirichlet(j)%dofs(c, :)))
            end do
        end do
        tic = wall_seconds()
        report = step_report_t(record=rec, n_steps=sp%settings%total_steps(), residual=attempt%residual, &
                               wall=tic - sp%start, cuts=stats%cut_records(first_cut:), n_cuts=stats%cuts, &
                               next_fraction=sp%frac, r0_max=stats%r0_max)
        call progress%step_done(report, u, model, error)
        call sp%watch%after_step(model, step, warnings)
        call report_warnings(sp, progress, warnings)
        rec%seconds(5) = wall_seconds() - tic
        stats%records = [stats%records, rec]
    end subroutine finish_step

end module voiga_solver_stepping
