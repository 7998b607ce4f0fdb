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
    use voiga_solver_context, only: context_t
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
        !> The substep's context: its step and load time, the step's record, the
        !> run's counters, the progress observer.
        type(context_t) :: ctx
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
        type(stepper_t) :: sp
        integer :: first

        sp%ctx%progress => silent
        if (present(progress)) sp%ctx%progress => progress
        sp%start = wall_seconds()
        if (present(t0)) sp%start = t0
        sp%settings = settings
        if (.not. allocated(sp%settings%n_steps)) sp%settings%n_steps = [1]
        call set_up(sp, model, u, first, error, resume)
        if (.not. allocated(error)) then
            call run_steps(sp, model, first, u, error)
            call sp%newton%linear%factorizations(sp%ctx%stats%symbolic_factorizations, &
                                                 sp%ctx%stats%numeric_factorizations)
        end if
        stats = sp%ctx%stats
    end subroutine solve_steps

    !> The Newton attempts' set-up (a hierarchical linear solver's levels reported),
    !> the start (zero, or `resume`) and the set-up warnings; `first`: the first step
    !> to solve.
    subroutine set_up(sp, model, u, first, error, resume)
        type(stepper_t), intent(inout) :: sp
        type(model_t), intent(inout) :: model
        real(dp), allocatable, intent(out) :: u(:)
        integer, intent(out) :: first
        type(error_t), allocatable, intent(out) :: error
        type(resume_t), intent(in), optional :: resume
        associate (stats => sp%ctx%stats)
            call new_newton(sp%newton, model, sp%settings, stats%assembly, error)
            if (allocated(error)) return
            stats%multigrid_levels = sp%newton%linear%level_dofs()
            if (size(stats%multigrid_levels) > 0) call sp%ctx%progress%set_up(stats%multigrid_levels, error)
            if (allocated(error)) return
            allocate (u(model%ndof))
            u = 0.0_dp
            sp%u_conv = u
            sp%u_step = u
            allocate (stats%records(0), stats%cut_records(0))
        end associate
        first = 1
        if (present(resume)) call resume_from(sp, resume, u, first)
        call new_contact_watch(sp%watch, model)
        allocate (sp%warned(0))
        call report_warnings(sp, setup_warnings(model))
    end subroutine set_up

    !> Every load step from `first`, then the warnings at the end; a failed run's
    !> error names its step and load time (and the warnings it may follow from).
    subroutine run_steps(sp, model, first, u, error)
        type(stepper_t), intent(inout) :: sp
        type(model_t), intent(inout) :: model
        integer, intent(in) :: first
        real(dp), intent(inout) :: u(:)
        type(error_t), allocatable, intent(out) :: error
        type(warning_t), allocatable :: warnings(:)
        integer :: step
        do step = first, sp%settings%total_steps()
            call solve_step(sp, model, step, u, error)
            if (allocated(error)) exit
            ! (a signal during the last step's output: the run is complete anyway)
            if (caught_signal() /= 0 .and. step < sp%settings%total_steps()) then
                sp%ctx%stats%signal = caught_signal()
                call fatal_error(error, 'interrupted by '//signal_name(sp%ctx%stats%signal))
                exit
            end if
        end do
        if (.not. allocated(error)) then
            call sp%watch%at_end(model, sp%settings%total_steps() - first + 1, warnings)
            call report_warnings(sp, warnings)
        end if
        if (allocated(error) .and. sp%ctx%stats%signal == 0) then
            call prefix_step(error, step, sp%ctx%time)
            if (error%code == error_code%numeric) call point_back(error, sp%warned)
        end if
    end subroutine run_steps

    !> Start from the state after `resume%step` of an interrupted run.
    subroutine resume_from(sp, resume, u, first)
        type(stepper_t), intent(inout) :: sp
        type(resume_t), intent(in) :: resume
        real(dp), intent(inout) :: u(:)
        integer, intent(inout) :: first
        if (.not. allocated(resume%u)) return
        u = resume%u
        sp%u_conv = u
        sp%u_step = u
        if (allocated(resume%u_before)) sp%u_step_before = resume%u_before
        sp%frac = resume%fraction
        sp%ctx%stats%r0_max = resume%r0_max
        sp%conv_det_sign = resume%det_sign
        first = resume%step + 1
    end subroutine resume_from

    !> Every warning of `list` to the progress observer; the stepper keeps them.
    subroutine report_warnings(sp, list)
        type(stepper_t), intent(inout) :: sp
        type(warning_t), intent(in) :: list(:)
        integer :: i
        do i = 1, size(list)
            call sp%ctx%progress%warning(trim(list(i)%text))
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
    !> failure; then its reactions and report. `sp%ctx%time`: the load time of the
    !> last attempt.
    subroutine solve_step(sp, model, step, u, error)
        type(stepper_t), intent(inout) :: sp
        type(model_t), intent(inout) :: model
        integer, intent(in) :: step
        real(dp), intent(inout) :: u(:)
        type(error_t), allocatable, intent(out) :: error
        type(attempt_t) :: attempt
        real(dp) :: t_begin, t_end, ds
        integer :: first_cut
        logical :: predicted, stop_run

        t_begin = sp%settings%step_time(step - 1)
        t_end = sp%settings%step_time(step)
        sp%ctx%step = step
        sp%ctx%record = step_record_t(step=step, time=t_end, substeps=0)
        first_cut = size(sp%ctx%stats%cut_records) + 1
        sp%stall_start = sp%ctx%stats%iterations
        sp%fold_iterations = 0
        sp%fold_total = 0
        sp%s = 0.0_dp
        do while (sp%s < 1.0_dp)
            ds = min(sp%frac, 1.0_dp - sp%s)
            sp%ctx%time = t_end
            if (sp%s + ds < 1.0_dp) sp%ctx%time = t_begin + (sp%s + ds)*(t_end - t_begin)
            call sp%ctx%progress%substep(step, sp%settings%total_steps(), sp%ctx%record%substeps + 1, &
                                         sp%ctx%record%cuts, sp%ctx%stats%cuts, sp%ctx%time, ds)
            call attempt_substep(sp, model, ds, u, attempt, predicted, error)
            if (.not. allocated(error)) then
                call accept_substep(sp, model, ds, u, attempt)
                cycle
            end if
            call handle_failure(sp, model, t_begin, t_end, ds, predicted, u, stop_run, error)
            if (stop_run) return
        end do
        call finish_step(sp, model, u, attempt, first_cut, error)
    end subroutine solve_step

    !> One attempt at the substep of `sp%ctx` (increment `ds`): from the predictor
    !> or the converged state, Newton (or, with `tresca_always`, the Tresca fixed
    !> point); a frictional attempt from the converged state that failed with
    !> contact states switching is retried by the Tresca fixed point.
    subroutine attempt_substep(sp, model, ds, u, attempt, predicted, error)
        type(stepper_t), intent(inout) :: sp
        type(model_t), intent(inout) :: model
        real(dp), intent(in) :: ds
        real(dp), intent(inout) :: u(:)
        type(attempt_t), intent(out) :: attempt
        logical, intent(out) :: predicted
        type(error_t), allocatable, intent(out) :: error
        type(error_t), allocatable :: tresca_error
        integer :: ip, step
        logical :: retry

        step = sp%ctx%step
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
            call tresca_fixed_point(sp%newton, model, sp%ctx, u, attempt, error)
            return
        end if
        call set_prescribed(model, sp%ctx%time, u)
        if (.not. predicted .and. .not. retry .and. sp%settings%stick_predictor .and. &
            sliding_start(model, sp%ctx%time)) then
            ! (a failure from this start is retried once from the converged state)
            call stick_predictor(sp%newton, model, sp%ctx, u, error)
            if (allocated(error)) return
            predicted = .true.
        end if
        call substep_attempt(sp%newton, model, sp%ctx, u, attempt, error)
        if (.not. allocated(error) .or. predicted) return
        sp%fold_iterations = attempt%nonpositive_det
        sp%fold_total = attempt%iterations
        ! contact states still switching in a frictional case (a period-2 cycle or the
        ! cap with switches; at a fold det K also changes sign, but the stick/slip
        ! switch of a stiff penalty stalls Newton with det K > 0 as well): retry the
        ! same increment with the Tresca fixed point before cutting
        if (error%code /= error_code%numeric .or. sp%ctx%stats%signal /= 0 .or. .not. attempt%switching .or. &
            .not. frictional(model)) return
        u = sp%u_conv
        do ip = 1, size(model%pairs)
            call model%pairs(ip)%pair%reset_trial()
        end do
        call tresca_fixed_point(sp%newton, model, sp%ctx, u, attempt, tresca_error)
        if (.not. allocated(tresca_error)) then
            deallocate (error)
        else if (sp%ctx%stats%signal /= 0) then
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
    subroutine accept_substep(sp, model, ds, u, attempt)
        type(stepper_t), intent(inout) :: sp
        type(model_t), intent(inout) :: model
        real(dp), intent(in) :: ds, u(:)
        type(attempt_t), intent(in) :: attempt
        integer :: ip
        if (attempt%iterations > 0) sp%conv_det_sign = attempt%det_sign
        sp%u_conv = u
        sp%stall_start = sp%ctx%stats%iterations
        do ip = 1, size(model%pairs)
            call model%pairs(ip)%pair%commit()
        end do
        sp%s = sp%s + ds
        sp%ctx%record%substeps = sp%ctx%record%substeps + 1
        sp%ctx%stats%substeps = sp%ctx%stats%substeps + 1
        if (attempt%iterations <= sp%settings%grow_iterations) sp%frac = min(1.0_dp, 2.0_dp*sp%frac)
    end subroutine accept_substep

    !> A failed substep: back to the last converged state; then retry a predicted
    !> start once from there, or cut the increment, or (at the limit, on a signal or
    !> a non-numerical failure) end the run with the error (`stop_run`).
    subroutine handle_failure(sp, model, t_begin, t_end, ds, predicted, u, stop_run, error)
        type(stepper_t), intent(inout) :: sp
        type(model_t), intent(inout) :: model
        real(dp), intent(in) :: t_begin, t_end, ds
        logical, intent(in) :: predicted
        real(dp), intent(inout) :: u(:)
        logical, intent(out) :: stop_run
        type(error_t), allocatable, intent(inout) :: error
        type(cut_record_t) :: cut
        integer :: ip, stalled

        u = sp%u_conv
        do ip = 1, size(model%pairs)
            call model%pairs(ip)%pair%reset_trial()
        end do
        stop_run = sp%ctx%stats%signal /= 0 .or. error%code /= error_code%numeric
        if (stop_run) return
        if (softened(model, sp%ctx, error%message)) then
            ! a penalty that does not decide the solution was made softer: the same
            ! increment again, as it was attempted
            sp%ctx%stats%softenings = sp%ctx%stats%softenings + 1
            sp%unpredicted_retry = .not. predicted
            deallocate (error)
            return
        end if
        if (predicted) then
            ! a predicted start that fails is retried once from the last converged
            ! state, at the same increment, before the increment is cut
            sp%unpredicted_retry = .true.
            sp%ctx%stats%predictor_retries = sp%ctx%stats%predictor_retries + 1
            call sp%ctx%progress%retried(sp%ctx%step, sp%ctx%time, error%message)
            deallocate (error)
            return
        end if
        stalled = sp%ctx%stats%iterations - sp%stall_start
        if (sp%settings%max_stalled_iterations > 0 .and. stalled >= sp%settings%max_stalled_iterations) then
            call explain_failure(sp, model, t_begin + sp%s*(t_end - t_begin), ds, error, stalled=stalled)
            stop_run = .true.
            return
        end if
        if (sp%ctx%record%cuts >= sp%settings%max_cuts .or. &
            0.5_dp*ds < sp%settings%min_step_fraction*(1.0_dp - 1.0e-12_dp)) then
            call explain_failure(sp, model, t_begin + sp%s*(t_end - t_begin), ds, error)
            stop_run = .true.
            return
        end if
        cut = cut_record_t(step=sp%ctx%step, time=sp%ctx%time, fraction=ds, new_fraction=0.5_dp*ds, &
                           reason=error%message)
        call append_cut(sp%ctx%stats%cut_records, cut)
        sp%ctx%stats%cuts = sp%ctx%stats%cuts + 1
        sp%ctx%record%cuts = sp%ctx%record%cuts + 1
        sp%frac = 0.5_dp*ds
        call sp%ctx%progress%cut(cut, error%message)
        deallocate (error)
    end subroutine handle_failure

    !> Let every pair soften its penalties after a failed substep (`reason`); whether
    !> one did (each says what it changed through the progress observer).
    logical function softened(model, ctx, reason) result(any_changed)
        type(model_t), intent(inout) :: model
        type(context_t), intent(in) :: ctx
        character(len=*), intent(in) :: reason
        character(len=:), allocatable :: what
        logical :: changed
        integer :: ip
        any_changed = .false.
        do ip = 1, size(model%pairs)
            call model%pairs(ip)%pair%soften(changed, what)
            if (.not. changed) cycle
            any_changed = .true.
            call ctx%progress%softened(ctx%step, ctx%time, ip, what, reason)
        end do
    end function softened

    !> The step cannot be cut further, or (`stalled`: the Newton iterations of its
    !> failed attempts since the last converged substep) is given up as hopeless:
    !> the limits it reached, and the diagnoses at the last converged state (load
    !> time `t_conv`).
    subroutine explain_failure(sp, model, t_conv, ds, error, stalled)
        type(stepper_t), intent(inout) :: sp
        type(model_t), intent(inout) :: model
        real(dp), intent(in) :: t_conv, ds
        type(error_t), intent(inout) :: error
        integer, intent(in), optional :: stalled
        if (present(stalled)) then
            error%message = error%message//'; gave the step up: its attempts since the last converged substep '// &
                            'took '//str(stalled)//' Newton iterations without converging (the budget, &solver '// &
                            'max_stalled_iterations = '//str(sp%settings%max_stalled_iterations)//'; '// &
                            str(sp%ctx%record%cuts)//' cuts, increment '//real_str(ds, 'es9.2')// &
                            ' of the nominal step). '// &
                            'The load of a step is likely too large to follow: give more load steps (&solver '// &
                            'n_steps'//steps_now(sp%settings%n_steps)//') or smaller motions per step'
        else if (sp%ctx%record%cuts > 0 .or. sp%settings%max_cuts > 0) then
            error%message = error%message//' (after '//str(sp%ctx%record%cuts)//' cuts; increment '// &
                            real_str(ds, 'es9.2')//' of the nominal step, minimum '// &
                            real_str(sp%settings%min_step_fraction, 'es9.2')//', max_cuts '// &
                            str(sp%settings%max_cuts)//')'
        end if
        if (sp%fold_iterations > 0 .and. (sp%fold_iterations < sp%fold_total .or. sp%conv_det_sign > 0)) &
            error%message = error%message//fold_diagnosis(model, sp%fold_iterations, sp%fold_total)
        call append_pair_diagnoses(model, sp%u_conv, t_conv, sp%ctx%stats%assembly, error%message)
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
    subroutine finish_step(sp, model, u, attempt, first_cut, error)
        type(stepper_t), intent(inout) :: sp
        type(model_t), intent(in) :: model
        real(dp), intent(in) :: u(:)
        type(attempt_t), intent(in) :: attempt
        integer, intent(in) :: first_cut
        type(error_t), allocatable, intent(out) :: error
        type(step_report_t) :: report
        type(warning_t), allocatable :: warnings(:)
        real(dp) :: tic
        integer :: j, c

        sp%u_conv = u
        sp%u_step_before = sp%u_step
        sp%u_step = u
        associate (stats => sp%ctx%stats, rec => sp%ctx%record)
            stats%steps = rec%step
            rec%det_sign = sp%conv_det_sign
            ! one component per spatial axis (the result file's reactions, [nsd, n])
            allocate (rec%reactions(model%nsd, size(model%dirichlet)))
            do j = 1, size(model%dirichlet)
                do c = 1, model%nsd
                    rec%reactions(c, j) = sum(sp%newton%r(model%dirichlet(j)%dofs(c, :)))
                end do
            end do
            tic = wall_seconds()
            report = step_report_t(record=rec, n_steps=sp%settings%total_steps(), residual=attempt%residual, &
                                   wall=tic - sp%start, cuts=stats%cut_records(first_cut:), n_cuts=stats%cuts, &
                                   next_fraction=sp%frac, r0_max=stats%r0_max)
        end associate
        call sp%ctx%progress%step_done(report, u, model, error)
        call sp%watch%after_step(model, sp%ctx%step, warnings)
        call report_warnings(sp, warnings)
        sp%ctx%record%seconds(5) = wall_seconds() - tic
        sp%ctx%stats%records = [sp%ctx%stats%records, sp%ctx%record]
    end subroutine finish_step

end module voiga_solver_stepping
