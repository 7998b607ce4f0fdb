!> Quasi-static load stepping with Newton-Raphson and adaptive load increments.
!>
!> Per (sub)step: prescribed displacements are set to their values at the load
!> time, then Newton iterates K du = -r on the free DOFs (the prescribed DOFs are
!> eliminated symmetrically, their corrections are zero) until
!> ||r|| <= tol_residual ||r_0|| or |du.r| <= tol_energy |du_1.r_0|, with r_0 the
!> substep's first residual, or until the residual has reached its round-off level
!> (`residual_floor`): with a stiff penalty, ||K|| is so large that rounding the
!> coordinates alone moves the residual by more than tol_residual ||r_0||.
!>
!> Adaptive stepping (docs/robustness.md): a substep that fails numerically (the
!> iteration cap, a residual that is not finite or grows by `divergence_ratio`, an
!> inverted element, a contact projection that does not converge, a singular
!> matrix) is cut: the last converged state (u and the contact pairs' trial
!> history) is restored and the increment halved, down to `min_step_fraction` of
!> the nominal step; after a substep that converged in at most `grow_iterations`
!> iterations the increment doubles again (never beyond the nominal step). Substeps
!> subdivide a nominal step, so the case's steps are hit exactly and only their
!> converged states are written. SIGINT/SIGTERM (voiga_solver_signals) are polled
!> between iterations: the solve stops with the last converged state.
!>
!> Tresca fixed point (docs/robustness.md, "Tresca fixed point"): a frictional
!> substep whose attempt from the last converged state failed at a fold (contact
!> states switching, det K changing sign) is retried once at the same increment by
!> successive approximations on the slip bounds: Newton on the Tresca problem (slip
!> limit g_i fixed, no mu x penalty_normal coupling in the tangent), then
!> g_i = mu p_N,i, until the Coulomb residual itself meets Newton's convergence test.
module voiga_solver_newton
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use voiga_kinds, only: dp, i8
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_model, only: model_t, phase_value, step_time, n_total_steps
    use voiga_model_assembly, only: assembly_stats_t, assemble, stiffness_pattern, assembly_map_t, &
                                    new_assembly_map
    use voiga_solver_sparse, only: csc_matrix_t
    use voiga_solver_umfpack, only: umfpack_t
    use voiga_solver_multigrid, only: multigrid_t
    use voiga_solver_signals, only: caught_signal, signal_name
    use voiga_io_results, only: results_t, step_record_t, cut_record_t
    use voiga_contact_pair, only: contact_pair_t, pair_commit, pair_reset_trial, pair_zone, method_gpts, &
                                  pair_crossing_fraction, mortar_snapshot_t
    implicit none
    private

    public :: solve_steps, solver_stats_t, wall_seconds, resume_t, stepping_t
    public :: residual_floor, reference_coordinates

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

    !> Most halvings of one Newton step.
    integer, parameter :: max_line_search = 8

    !> Mortar pairs: a Newton step that closes an open control point is shortened to
    !> this multiple of the fraction at which the first one closes (a little beyond,
    !> so that it is active and its stiffness in the next tangent;
    !> `pair_crossing_fraction`).
    real(dp), parameter :: closing_overshoot = 1.01_dp

    !> A Newton iteration whose accepted step is at most this long creeps; an attempt
    !> that fails with half its iterations creeping (residual damping) names natural
    !> damping in its message.
    real(dp), parameter :: creep_step = 0.0625_dp

    !> Natural damping (`damping = 'natural'`): most step reductions of one Newton
    !> iteration, and the smallest step length.
    integer, parameter :: max_natural_damping = 10
    real(dp), parameter :: min_natural_step = 1.0e-4_dp

    !> A Newton iteration whose residual exceeds this multiple of the substep's
    !> first residual has diverged (the substep is cut instead of iterated to the cap).
    real(dp), parameter :: divergence_ratio = 1.0e10_dp

    !> Safety factor of the round-off floor `residual_floor` (rounding errors of a
    !> sum of many element contributions add up; measured over 148 converged
    !> substeps of ironing with penalty 1e6 x E: the final residual is 0.06 to 0.9
    !> times eps || |K| |x| ||, 5.7 at most; docs/robustness.md).
    real(dp), parameter :: floor_factor = 10.0_dp

    !> The round-off floor ends the iteration only when the residual is also below
    !> this fraction of the run's force scale (the largest first residual of a
    !> substep so far, or this substep's): a floor above it (a penalty too stiff for
    !> double precision) fails the substep instead of accepting it. The force scale,
    !> not the substep's own first residual: the floor does not shrink with the load
    !> increment, so a cut substep would otherwise never reach it.
    real(dp), parameter :: floor_cap = 1.0e-6_dp

    !> Relative residual of an iterative linear solve at a Newton iteration whose
    !> contact states differ from the previous iteration's (multigrid only): the
    !> iteration is not in Newton's quadratic range, and its step mostly moves the
    !> active set; after `soft_iterations` GMRES iterations `soft_forcing` is enough.
    !> Measured (docs/performance.md, "Multigrid"): hertz N2 m8, one load step, the
    !> exact-solve forcing takes 82 GMRES iterations in 10 Newton iterations, 1e-2 31
    !> in 10, 1e-1 16 in 11; but 1e-1 costs Newton iterations elsewhere (hertz m3 N2,
    !> 5 steps: 30 instead of 26). The first iteration after contact starts from a
    !> deep penetration is the slow solve (m9: 14 GMRES iterations to 1e-1): the
    !> current-length term of the contact tangent, pressure x d(length)/du, is then
    !> large against the penalty (ratio ~ penetration / element size).
    real(dp), parameter :: active_set_forcing = 1.0e-2_dp, soft_forcing = 1.0e-1_dp
    integer, parameter :: soft_iterations = 10

    !> A contact zone counts as broken up (the locking diagnosis) with at least this
    !> many gaps shorter than a slave element, holding at least this share of its
    !> points. Measured (docs/robustness.md): penalty 1e6 x E, 3 to 5 gaps holding 32 to
    !> 48 %; mu-1.0-deep (penalty 1e2 x E, a smooth pressure), one gap of 4 points
    !> between the zone and a lone point at its edge, 8 %.
    integer, parameter :: min_gaps = 2
    real(dp), parameter :: min_hole_share = 0.2_dp

    !> Most Tresca solves (fixed-point iterations) of one retried substep.
    integer, parameter :: max_fixed_point = 40

    !> Adaptive load stepping settings (`&solver`: min_step_fraction, max_cuts,
    !> grow_iterations; docs/robustness.md).
    type :: stepping_t
        !> Smallest load increment, as a fraction of the nominal step.
        real(dp) :: min_step_fraction = 1.0e-4_dp
        !> Most cuts per nominal step (0: a failed step fails the run).
        integer :: max_cuts = 30
        !> The increment doubles after a substep converged in at most this many iterations.
        integer :: grow_iterations = 5
        !> Start a substep from u_conv + (substep fraction) x (the last nominal step's
        !> increment) when that step is in the same load phase.
        logical :: predictor = .true.
        !> Solve every substep of a frictional model by the Tresca fixed point (from the
        !> last converged state), not only those whose Newton attempt folds: for tests
        !> and comparisons (Fortran API only, not a case-file setting).
        logical :: tresca_always = .false.
    end type stepping_t

    !> Counters of a run.
    type :: solver_stats_t
        type(assembly_stats_t) :: assembly
        !> Converged nominal steps; Newton iterations of all attempts.
        integer :: steps = 0, iterations = 0
        integer :: symbolic_factorizations = 0, numeric_factorizations = 0
        !> Substeps whose predicted start failed and that were retried from the last
        !> converged state.
        integer :: predictor_retries = 0
        !> Residual evaluations spent on shortening Newton steps (halving, or natural damping).
        integer :: line_search_steps = 0
        !> Sign of det(K) of the last factorization (free DOFs), and the iterations of
        !> the last Newton attempt whose tangent had det(K) <= 0 (`newton_solve`).
        integer :: det_sign = 0, attempt_nonpositive_det = 0
        !> DOFs of each multigrid level (empty with the direct solver).
        integer, allocatable :: multigrid_levels(:)
        !> The last Newton attempt failed with contact states switching (a period-2
        !> cycle, or the iteration cap with switches among the last iterations).
        logical :: attempt_switching = .false.
        !> Substeps retried with the Tresca fixed point, of them accepted, and the
        !> fixed-point iterations (Tresca solves) of all retries.
        integer :: tresca_retries = 0, tresca_accepted = 0, fixed_point_iterations = 0
        !> Largest first residual of a step so far: the force scale of the round-off floor.
        real(dp) :: r0_max = 0.0_dp
        !> Converged substeps and cuts of the load increment.
        integer :: substeps = 0, cuts = 0
        !> The signal that interrupted the run (0: none).
        integer :: signal = 0
        !> The record of every converged step (residual and energy norms, reactions, seconds).
        type(step_record_t), allocatable :: records(:)
        !> Every cut of the run.
        type(cut_record_t), allocatable :: cut_records(:)
    end type solver_stats_t

contains

    !> Wall-clock seconds since an arbitrary origin.
    real(dp) function wall_seconds()
        integer(i8) :: count, rate
        call system_clock(count, rate)
        wall_seconds = real(count, dp)/real(rate, dp)
    end function wall_seconds

    !> Run every load step of `model` from zero displacement; write each converged
    !> nominal step to `results` (if present) and report progress (and every cut)
    !> unless `quiet`. `u` holds the last converged displacement on return (also on
    !> failure). An interrupt (stats%signal /= 0) returns an error too.
    subroutine solve_steps(model, u, stats, quiet, error, results, t0, verbose, stepping, resume)
        type(model_t), intent(inout) :: model
        real(dp), allocatable, intent(out) :: u(:)
        type(solver_stats_t), intent(out) :: stats
        logical, intent(in) :: quiet
        type(error_t), allocatable, intent(out) :: error
        type(results_t), intent(inout), optional :: results
        !> Wall time origin of the run (for the time written to the results).
        real(dp), intent(in), optional :: t0
        !> Print every Newton iteration (residual, energy, contact states).
        logical, intent(in), optional :: verbose
        !> Adaptive stepping settings (default: `stepping_t()`).
        type(stepping_t), intent(in), optional :: stepping
        !> Continue an interrupted run instead of starting from zero.
        type(resume_t), intent(in), optional :: resume
        type(stepping_t) :: set
        type(csc_matrix_t) :: k
        type(assembly_map_t) :: map
        type(umfpack_t) :: lu
        type(multigrid_t) :: mg
        type(step_record_t) :: rec
        type(cut_record_t) :: cut
        real(dp), allocatable :: r(:), u_conv(:), u_step(:), u_step_before(:)
        real(dp) :: t, t_begin, t_end, tic, start, frac, s, ds, rn
        integer :: step, nsteps, j, c, ip, it, first_cut, first
        logical :: loud, predicted, unpredicted_retry
        character(len=200) :: msg
        type(error_t), allocatable :: tresca_error
        ! sign of det(K) at the last converged substep; det(K) <= 0 iterations and all
        ! iterations of the last failed attempt started from the converged state
        integer :: conv_det_sign, fold_iterations, fold_total

        start = wall_seconds()
        if (present(t0)) start = t0
        if (present(stepping)) set = stepping
        loud = .false.
        if (present(verbose)) loud = verbose
        call stiffness_pattern(model, k, error)
        if (allocated(error)) return
        call new_assembly_map(model, k, map)
        if (model%linear_solver == 'multigrid') then
            call mg%build(model%bodies(:)%disc, model%bodies(:)%dof0, model%ndof, model%fixed, error)
            if (allocated(error)) return
            stats%multigrid_levels = mg%level_dofs()
            if (present(results)) call results%write_multigrid(stats%multigrid_levels, error)
            if (allocated(error)) return
            if (.not. quiet) write (*, '(a,i0,a,*(1x,i0))') 'multigrid: ', mg%n_levels(), &
                ' levels, DOFs', stats%multigrid_levels
        end if
        allocate (u(model%ndof), r(model%ndof))
        u = 0.0_dp
        u_conv = u
        ! converged states at the ends of the last two nominal steps (step 0: zero)
        u_step = u
        nsteps = n_total_steps(model)
        allocate (stats%records(0), stats%cut_records(0))
        ! the load increment as a fraction of the nominal step; carried over steps
        frac = 1.0_dp
        unpredicted_retry = .false.
        first = 1
        conv_det_sign = 0
        if (present(resume)) then
            if (allocated(resume%u)) then
                u = resume%u
                u_conv = u
                u_step = u
                if (allocated(resume%u_before)) u_step_before = resume%u_before
                frac = resume%fraction
                stats%r0_max = resume%r0_max
                conv_det_sign = resume%det_sign
                first = resume%step + 1
            end if
        end if
        steps: do step = first, nsteps
            t_begin = step_time(model, step - 1)
            t_end = step_time(model, step)
            rec = step_record_t()
            rec%step = step
            rec%time = t_end
            rec%substeps = 0
            first_cut = size(stats%cut_records) + 1
            fold_iterations = 0
            fold_total = 0
            ! s: converged part of the nominal step (sums of powers of 2: exact)
            s = 0.0_dp
            do while (s < 1.0_dp)
                ds = min(frac, 1.0_dp - s)
                t = t_end
                if (s + ds < 1.0_dp) t = t_begin + (s + ds)*(t_end - t_begin)
                predicted = .false.
                if (set%predictor .and. .not. unpredicted_retry .and. allocated(u_step_before) &
                    .and. step >= 2) then
                    if (phase_of_step(model, step - 1) == phase_of_step(model, step)) then
                        u = u + ds*(u_step - u_step_before)
                        predicted = .true.
                    end if
                end if
                unpredicted_retry = .false.
                if (set%tresca_always .and. frictional(model)) then
                    u = u_conv
                    predicted = .false.
                    call tresca_fixed_point(model, step, t, u, r, k, map, lu, mg, stats, rec, it, rn, &
                                            loud, quiet, error)
                else
                    call set_prescribed(model, t, u)
                    call newton_solve(model, step, t, u, r, k, map, lu, mg, stats, rec, it, rn, loud, error)
                end if
                if (allocated(error) .and. .not. predicted .and. .not. set%tresca_always) then
                    fold_iterations = stats%attempt_nonpositive_det
                    fold_total = it
                    ! contact states still switching in a frictional case (a period-2 cycle
                    ! or the cap with switches; at a fold det K also changes sign, but the
                    ! stick/slip switch of a stiff penalty stalls Newton with det K > 0 as
                    ! well): retry the same increment with the Tresca fixed point before cutting
                    if (error%code == error_code%numeric .and. stats%signal == 0 .and. &
                        stats%attempt_switching .and. frictional(model)) then
                        u = u_conv
                        do ip = 1, size(model%pairs)
                            call pair_reset_trial(model%pairs(ip))
                        end do
                        call tresca_fixed_point(model, step, t, u, r, k, map, lu, mg, stats, rec, it, rn, &
                                                loud, quiet, tresca_error)
                        if (allocated(tresca_error)) then
                            if (stats%signal /= 0) then
                                call move_alloc(tresca_error, error)
                            else
                                error%message = error%message//'; retried with the Tresca fixed point: '// &
                                                tresca_error%message
                                deallocate (tresca_error)
                            end if
                        else
                            deallocate (error)
                        end if
                    end if
                end if
                if (.not. allocated(error)) then
                    if (it > 0) conv_det_sign = stats%det_sign
                    u_conv = u
                    do ip = 1, size(model%pairs)
                        call pair_commit(model%pairs(ip))
                    end do
                    s = s + ds
                    rec%substeps = rec%substeps + 1
                    stats%substeps = stats%substeps + 1
                    if (it <= set%grow_iterations) frac = min(1.0_dp, 2.0_dp*frac)
                    cycle
                end if
                ! failed: back to the last converged state, forget the contact trial history
                u = u_conv
                do ip = 1, size(model%pairs)
                    call pair_reset_trial(model%pairs(ip))
                end do
                if (stats%signal /= 0 .or. error%code /= error_code%numeric) exit steps
                if (predicted) then
                    ! a predicted start that fails is retried once from the last converged
                    ! state, at the same increment, before the increment is cut
                    unpredicted_retry = .true.
                    stats%predictor_retries = stats%predictor_retries + 1
                    if (.not. quiet) write (*, '(a,i0,a,f10.6,a)') 'retry step ', step, '  t=', t, &
                        ' from the last converged state (the predicted start failed: '//error%message//')'
                    deallocate (error)
                    cycle
                end if
                if (rec%cuts >= set%max_cuts .or. &
                    0.5_dp*ds < set%min_step_fraction*(1.0_dp - 1.0e-12_dp)) then
                    if (rec%cuts > 0 .or. set%max_cuts > 0) then
                        write (msg, '(a,i0,a,es9.2,a,es9.2,a,i0,a)') ' (after ', rec%cuts, &
                            ' cuts; increment ', ds, ' of the nominal step, minimum ', &
                            set%min_step_fraction, ', max_cuts ', set%max_cuts, ')'
                        error%message = error%message//trim(msg)
                    end if
                    if (fold_iterations > 0 .and. (fold_iterations < fold_total .or. conv_det_sign > 0)) &
                        error%message = error%message//fold_diagnosis(model, fold_iterations, fold_total)
                    call append_locking_diagnosis(model, u_conv, t_begin + s*(t_end - t_begin), stats, &
                                                  error%message)
                    exit steps
                end if
                cut = cut_record_t(step=step, time=t, fraction=ds, new_fraction=0.5_dp*ds, &
                                   reason=error%message)
                call append_cut(stats%cut_records, cut)
                stats%cuts = stats%cuts + 1
                rec%cuts = rec%cuts + 1
                frac = 0.5_dp*ds
                if (.not. quiet) then
                    write (*, '(a,i0,a,f10.6,a,es9.2,a)') 'cut  step ', step, '  t=', t, &
                        '  new increment ', frac, ' of the step: '//error%message
                end if
                deallocate (error)
            end do
            u_conv = u
            u_step_before = u_step
            u_step = u
            stats%steps = step
            rec%det_sign = conv_det_sign
            allocate (rec%reactions(2, size(model%dirichlet)))
            do j = 1, size(model%dirichlet)
                do c = 1, 2
                    rec%reactions(c, j) = sum(r(model%dirichlet(j)%dofs(c, :)))
                end do
            end do
            if (present(results)) then
                tic = wall_seconds()
                call results%write_step(rec, u, wall_seconds() - start, model%pairs, &
                                        stats%cut_records(first_cut:), stats%cuts, frac, &
                                        stats%r0_max, error)
                if (allocated(error)) exit steps
                rec%seconds(5) = wall_seconds() - tic
            end if
            stats%records = [stats%records, rec]
            if (.not. quiet) then
                write (*, '(a,i0,a,i0,a,f8.4,a,i2,a,es9.2,a,f8.3,a)', advance='no') 'step ', step, '/', &
                    nsteps, '  t=', t_end, '  it=', rec%iterations, '  |r|=', rn, '  ', sum(rec%seconds), ' s'
                if (rec%substeps > 1 .or. rec%cuts > 0) then
                    write (*, '(a,i0,a,i0)') '  substeps=', rec%substeps, ' cuts=', rec%cuts
                else
                    write (*, '(a)') ''
                end if
            end if
            ! (a signal during the last step's output: the run is complete anyway)
            if (caught_signal() /= 0 .and. step < nsteps) then
                stats%signal = caught_signal()
                call fatal_error(error, 'interrupted by '//signal_name(stats%signal))
                exit steps
            end if
        end do steps
        if (allocated(error) .and. stats%signal == 0) then
            write (msg, '(a,i0,a,es12.5,a)') 'step ', step, ' (load time ', t, '):'
            error%message = trim(msg)//' '//error%message
        end if
        stats%symbolic_factorizations = lu%n_symbolic
        stats%numeric_factorizations = lu%n_numeric
    end subroutine solve_steps

    !> Why a step that cut down to its limit failed, when the tangent's determinant
    !> changed sign near the last converged state: det K <= 0 in `nonpositive` of
    !> the `total` iterations of the last attempt started there, det K > 0 in the
    !> others or at the converged state. Pieces of the (piecewise smooth)
    !> incremental problem with opposite orientation meet there, so the incremental
    !> map folds (it is not coherently oriented): for some increments it has no
    !> solution nearby. The message does not decide between a limit point of the
    !> path and a passage narrower than the smallest increment (docs/robustness.md,
    !> "Folds of the incremental problem").
    pure function fold_diagnosis(model, nonpositive, total) result(text)
        type(model_t), intent(in) :: model
        integer, intent(in) :: nonpositive, total
        character(len=:), allocatable :: text
        character(len=300) :: buf
        integer :: ip
        write (buf, '(a,i0,a,i0,a)') '; the determinant of the tangent stiffness changes sign near '// &
            'the last converged state (det K <= 0 in ', nonpositive, ' of the ', total, &
            ' iterations of the last attempt, > 0 in the others or at that state)'
        text = trim(buf)//': pieces of the incremental problem with opposite orientation meet '// &
               'there, so it folds (for some increments it has no nearby solution): either the '// &
               'quasi-static path ends here (a limit point; the physical system would move '// &
               'dynamically) or it goes on only through increments below min_step_fraction'
        do ip = 1, size(model%pairs)
            if (model%pairs(ip)%law%mu <= 0.0_dp) cycle
            write (buf, '(a,es8.1,a,es8.1,a)') '; with Coulomb friction (mu = ', model%pairs(ip)%law%mu, &
                ', penalty_normal = ', model%pairs(ip)%law%eps_n, '): slipping points couple the '
            text = text//trim(buf)//' normal penalty into the tangential direction (mu x penalty_normal) '// &
                   'which can make the tangent indefinite (the friction-induced instability); a smaller '// &
                   'penalty_normal or mu keeps the path stable longer'
            exit
        end do
    end function fold_diagnosis

    !> Append to `message` what the contact zones look like at the last converged
    !> state `u` (load time `t`) when one is broken up point by point (at least
    !> `min_gaps` gaps shorter than a slave element, holding at least `min_hole_share`
    !> of the zone's points) while its active points outnumber the slave control
    !> points they act on: Gauss-point-to-surface constraints then over-constrain the
    !> slave edge and, with a stiff penalty, lock (docs/robustness.md,
    !> "Over-constrained contact zones"). GPTS pairs only. Nothing is appended otherwise, or when the
    !> evaluation there fails.
    subroutine append_locking_diagnosis(model, u, t, stats, message)
        type(model_t), intent(inout) :: model
        real(dp), intent(in) :: u(:), t
        type(solver_stats_t), intent(inout) :: stats
        character(len=:), allocatable, intent(inout) :: message
        type(error_t), allocatable :: error
        real(dp), allocatable :: r(:)
        character(len=600) :: buf
        integer :: ip, n_active, n_holes, n_gaps, n_cp

        if (size(model%pairs) == 0) return
        allocate (r(model%ndof))
        call assemble(model, u, t, r, stats%assembly, error)
        do ip = 1, size(model%pairs)
            call pair_reset_trial(model%pairs(ip))
        end do
        if (allocated(error)) return
        do ip = 1, size(model%pairs)
            ! a mortar pair has one constraint per control point: nothing to over-constrain
            if (model%pairs(ip)%method /= method_gpts) cycle
            call pair_zone(model%pairs(ip), n_active, n_holes, n_gaps, n_cp)
            if (n_gaps < min_gaps .or. n_holes < min_hole_share*(n_active + n_holes) .or. &
                n_active <= n_cp) cycle
            associate (pair => model%pairs(ip))
                write (buf, '(a,i0,a,i0,a,i0,a,i0,a,es8.1,a)') '; at the last converged state the contact '// &
                    'zone of '''//trim(pair%slave_name)//''' on '''//trim(pair%master_name)// &
                    ''' is broken up: ', n_holes, ' of its ', n_active + n_holes, ' slave points are open in gaps '// &
                    'shorter than a slave element, and its ', n_active, ' active points act on ', n_cp, &
                    ' control points of the slave edge: the Gauss-point-to-surface constraints outnumber '// &
                    'the edge''s degrees of freedom and, with penalty_normal = ', pair%law%eps_n, &
                    ', lock (the pressure alternates between neighbouring points instead of following '// &
                    'a smooth field)'
                message = message//trim(buf)
                if (pair%law%mu > 0.0_dp) message = message//'; the slip bounds mu p_N then jump from '// &
                    'point to point, which breaks up the stick/slip pattern as well'
                write (buf, '(a,i0,a)') '; one constraint per slave control point (&contact method = '// &
                    '''mortar'') or fewer slave points per element (&contact n_gauss, here ', pair%n_gauss, &
                    ') remove the over-constraint, a smaller penalty_normal eases it'
                message = message//trim(buf)
            end associate
        end do
    end subroutine append_locking_diagnosis

    !> Append `cut` to `list`.
    pure subroutine append_cut(list, cut)
        type(cut_record_t), allocatable, intent(inout) :: list(:)
        type(cut_record_t), intent(in) :: cut
        type(cut_record_t), allocatable :: longer(:)
        integer :: i
        allocate (longer(size(list) + 1))
        do i = 1, size(list)
            longer(i) = list(i)
        end do
        longer(size(list) + 1) = cut
        call move_alloc(longer, list)
    end subroutine append_cut

    !> Load phase (1-based) that nominal step `step` belongs to.
    pure integer function phase_of_step(model, step) result(ph)
        type(model_t), intent(in) :: model
        integer, intent(in) :: step
        integer :: total
        total = 0
        do ph = 1, size(model%n_steps)
            total = total + model%n_steps(ph)
            if (step <= total) return
        end do
        ph = size(model%n_steps)
    end function phase_of_step

    !> Newton iterations at load time `t` from `u` (prescribed values set). On
    !> success `rec` holds the iteration's norms; `it` the iterations, `rn` the final
    !> residual norm. A numerical failure returns an error with code `numeric`; an
    !> interrupt sets stats%signal and returns a generic error. With `r0_ref` the
    !> relative tests (tol_residual, energy, divergence) use it instead of the first
    !> residual (the Tresca solves of a fixed point, measured against the substep's).
    subroutine newton_solve(model, step, t, u, r, k, map, lu, mg, stats, rec, it, rn, verbose, error, r0_ref)
        type(model_t), intent(inout) :: model
        integer, intent(in) :: step
        real(dp), intent(in) :: t
        real(dp), intent(inout) :: u(:)
        !> Residual at the last evaluation, shape [ndof].
        real(dp), intent(inout) :: r(:)
        type(csc_matrix_t), intent(inout) :: k
        type(assembly_map_t), intent(inout) :: map
        type(umfpack_t), intent(inout) :: lu
        !> The multigrid solver (used when model%linear_solver is 'multigrid').
        type(multigrid_t), intent(inout) :: mg
        type(solver_stats_t), intent(inout) :: stats
        type(step_record_t), intent(inout) :: rec
        integer, intent(out) :: it
        real(dp), intent(out) :: rn
        logical, intent(in) :: verbose
        type(error_t), allocatable, intent(out) :: error
        real(dp), intent(in), optional :: r0_ref
        real(dp), allocatable :: du(:), norms(:), energies(:), rhs(:), u_prev(:), x0(:)
        ! contact state of every slave point after each iteration; shape: [npoints, 0:max_iterations]
        integer, allocatable :: states(:, :)
        real(dp) :: r0, e1, en, tic, bulk0, contact0, alpha, rn_prev, floor, log_det, eta
        ! natural damping: simplified correction at the trial point, norms for the
        ! a-priori step estimate
        real(dp), allocatable :: du_bar(:), du_bar_acc(:)
        type(csc_matrix_t) :: k_old
        real(dp) :: theta, h_est, du_norm, du_norm_prev, alpha_prev
        logical :: natural, have_bar, smooth, closing
        ! mortar pairs: the control points of every pair at the last accepted iterate
        type(mortar_snapshot_t), allocatable :: accepted(:)
        real(dp) :: frac
        integer :: nls, ip, flips
        ! iterations whose accepted step was at most creep_step
        integer :: short_steps
        logical :: converged, multigrid, changing
        character(len=800) :: msg

        multigrid = model%linear_solver == 'multigrid'
        natural = model%damping == 'natural' .and. .not. multigrid
        closing = .false.
        short_steps = 0
        allocate (accepted(size(model%pairs)))
        have_bar = .false.
        du_norm = 0.0_dp
        du_norm_prev = 0.0_dp
        alpha_prev = 1.0_dp
        allocate (du(model%ndof), rhs(model%ndof), u_prev(model%ndof), du_bar(model%ndof))
        x0 = reference_coordinates(model)
        allocate (states(sum([(size(model%pairs(ip)%out), ip=1, size(model%pairs))]), &
                         0:model%max_iterations))
        allocate (norms(model%max_iterations + 1), energies(model%max_iterations))
        converged = .false.
        r0 = 0.0_dp
        e1 = 0.0_dp
        en = huge(1.0_dp)
        rn = 0.0_dp
        it = 0
        nls = 0
        alpha = 1.0_dp
        rn_prev = huge(1.0_dp)
        stats%attempt_nonpositive_det = 0
        stats%attempt_switching = .false.
        do
            if (caught_signal() /= 0) then
                stats%signal = caught_signal()
                call fatal_error(error, 'interrupted by '//signal_name(stats%signal))
                exit
            end if
            bulk0 = stats%assembly%seconds_bulk
            contact0 = stats%assembly%seconds_contact
            ! the substep's first assembly also fits the contact pattern to its start
            call assemble(model, u, t, r, stats%assembly, error, k, map, refit=(it == 0 .and. nls == 0))
            rec%seconds(1) = rec%seconds(1) + stats%assembly%seconds_bulk - bulk0
            rec%seconds(2) = rec%seconds(2) + stats%assembly%seconds_contact - contact0
            if (allocated(error)) exit
            rn = norm2(merge(0.0_dp, r, model%fixed))
            if (.not. ieee_is_finite(rn)) then
                call fatal_error(error, 'the residual is not finite', error_code%numeric)
                exit
            end if
            floor = residual_floor(k, x0 + u, model%fixed)
            have_bar = .false.
            ! a step that carries a mortar control point across a state boundary the
            ! tangent did not describe (it closes, or its slip reverses) is shortened to
            ! where the first one crosses (once per iteration), and that point accepted
            if (it > 0 .and. nls == 0 .and. .not. closing) then
                frac = 1.0_dp
                do ip = 1, size(model%pairs)
                    frac = min(frac, pair_crossing_fraction(model%pairs(ip), accepted(ip), closing_overshoot))
                end do
                if (frac < 1.0_dp) then
                    closing = .true.
                    stats%line_search_steps = stats%line_search_steps + 1
                    alpha = alpha*frac
                    u = u_prev + alpha*du
                    cycle
                end if
            end if
            ! where the contact states change the last tangent does not describe the
            ! trial point (a new active set): the residual rule decides there
            smooth = .false.
            if (natural .and. it > 0 .and. .not. closing) smooth = all(contact_states(model) == states(:, it - 1))
            if (smooth .and. du_norm > 0.0_dp .and. rn > floor .and. &
                rn > 1.0e4_dp*epsilon(1.0_dp)*max(r0, stats%r0_max)) then
                ! natural monotonicity test (affine invariant): the simplified Newton
                ! correction at the trial point, with the last iteration's tangent,
                ! must be shorter than (1 - alpha/4) times the Newton correction
                rhs = -merge(0.0_dp, r, model%fixed)
                call lu%solve(k_old, rhs, du_bar, error)
                if (allocated(error)) exit
                theta = norm2(du_bar)/du_norm
                if (theta > 1.0_dp - 0.25_dp*alpha .and. nls < max_natural_damping) then
                    ! Kantorovich estimate of the step the curvature allows
                    h_est = 2.0_dp*norm2(du_bar - (1.0_dp - alpha)*du)/(alpha**2*du_norm)
                    nls = nls + 1
                    stats%line_search_steps = stats%line_search_steps + 1
                    alpha = max(min(0.5_dp*alpha, 1.0_dp/max(h_est, tiny(1.0_dp))), min_natural_step)
                    u = u_prev + alpha*du
                    cycle
                end if
                du_bar_acc = du_bar
                have_bar = .true.
            end if
            ! backtracking: a Newton step that increases the residual is halved
            ! (contact stick/slip and active-set changes can make full steps cycle)
            if (.not. smooth .and. .not. closing .and. it > 0 .and. rn > rn_prev .and. nls < max_line_search .and. &
                rn > floor .and. rn > 1.0e4_dp*epsilon(1.0_dp)*max(r0, stats%r0_max)) then
                nls = nls + 1
                stats%line_search_steps = stats%line_search_steps + 1
                alpha = 0.5_dp*alpha
                u = u_prev + alpha*du
                cycle
            end if
            norms(it + 1) = rn
            states(:, it) = contact_states(model)
            if (it > 0 .and. alpha <= creep_step) short_steps = short_steps + 1
            do ip = 1, size(model%pairs)
                accepted(ip) = model%pairs(ip)%last
            end do
            if (it == 0) then
                r0 = rn
                stats%r0_max = max(stats%r0_max, r0)
                if (present(r0_ref)) r0 = r0_ref
            end if
            if (verbose) call print_iteration(model, step, it, rn, en, alpha, floor)
            if (rn <= model%tol_residual*r0 .or. rn == 0.0_dp) converged = .true.
            ! the energy criterion alone may not hide a stalled residual
            if (it > 1 .and. en <= model%tol_energy*e1 .and. rn <= sqrt(model%tol_residual)*r0) &
                converged = .true.
            ! round-off floor: nothing left to gain relative to the largest first residual
            ! of the run (not the reactions, which can be huge with stiff penalties)
            if (rn <= 1.0e4_dp*epsilon(1.0_dp)*max(r0, stats%r0_max)) converged = .true.
            ! the residual is at the round-off level of the stiffness times the
            ! coordinates (stiff penalties): accepted only after a Newton step and
            ! below floor_cap of the force scale
            if (it > 0 .and. rn <= floor .and. rn <= floor_cap*max(r0, stats%r0_max)) &
                converged = .true.
            if (converged) exit
            if (it > 0 .and. rn > divergence_ratio*r0) then
                write (msg, '(a,es9.2,a,es9.2,a,i0,a)') 'the residual grew from ', r0, ' to ', rn, &
                    ' in ', it, ' iterations'
                call fatal_error(error, trim(msg), error_code%numeric)
                exit
            end if
            ! a limit cycle: the contact states and the residual repeat with period 2
            ! twice in a row; continuing would repeat it up to the iteration cap
            if (it >= 4 .and. .not. (rn <= floor)) then
                if (all(states(:, it) == states(:, it - 2)) .and. &
                    all(states(:, it - 1) == states(:, it - 3)) .and. &
                    any(states(:, it) /= states(:, it - 1)) .and. &
                    abs(rn - norms(it - 1)) <= 1.0e-6_dp*rn .and. &
                    abs(norms(it) - norms(it - 2)) <= 1.0e-6_dp*rn) then
                    flips = count(states(:, it) /= states(:, it - 1))
                    stats%attempt_switching = .true.
                    write (msg, '(a,i0,a,i0,a,es9.2,a,es9.2,a)') 'Newton cycles after ', it, &
                        ' iterations: ', flips, ' contact point(s) switch state (stick/slip or '// &
                        'contact/separation) with every iteration and the residual repeats (', rn, &
                        ', first ', r0, '): the friction and contact laws are not smooth where '// &
                        'the point sits on the stick/slip or contact limit'
                    call fatal_error(error, trim(msg), error_code%numeric)
                    exit
                end if
            end if
            if (it == model%max_iterations) then
                write (msg, '(a,i0,a,es9.2,a,es9.2,a)') 'Newton did not converge in ', &
                    model%max_iterations, ' iterations (residual ', rn, ', first ', r0, ')'
                if (rn <= floor) then
                    write (msg, '(a,es9.2,a,es9.2,a,es9.2,a)') trim(msg)//': the residual is at its '// &
                        'round-off level ', floor, ' (stiffness x rounding of the coordinates), above ', &
                        floor_cap, ' of the force scale ', max(r0, stats%r0_max), &
                        ': the stiffness (penalty) is too large for double precision'
                else
                    flips = count([(any(states(:, ip) /= states(:, ip - 1)), ip=max(1, it - 9), it)])
                    stats%attempt_switching = flips > 0
                    if (flips > 0) write (msg, '(a,i0,a,i0,a)') trim(msg)// &
                        ': contact states still switched in ', flips, ' of the last ', &
                        it - max(1, it - 9) + 1, ' iterations (points on the stick/slip or contact limit)'
                    if (.not. natural .and. 2*short_steps >= model%max_iterations) &
                        write (msg, '(a,i0,a)') trim(msg)//'; ', short_steps, ' of its iterations '// &
                        'took steps of 1/16 or less: the residual rule creeps along the curvature of a '// &
                        'stiff penalty, &solver damping = ''natural'' may pass it (docs/robustness.md, '// &
                        '"Natural damping")'
                end if
                call fatal_error(error, trim(msg), error_code%numeric)
                exit
            end if
            tic = wall_seconds()
            call k%fix_dofs(model%fixed)
            if (multigrid) then
                ! no factors, no determinant: det_sign stays 0 (unknown)
                call mg%setup(k, error)
            else
                call lu%factorize(k, error)
                if (.not. allocated(error)) then
                    ! the orientation of the tangent (O(n) from the factors): a sign
                    ! change marks a fold of the incremental problem (solve_steps)
                    call lu%determinant(stats%det_sign, log_det, error)
                    if (stats%det_sign <= 0) stats%attempt_nonpositive_det = stats%attempt_nonpositive_det + 1
                    if (verbose .and. .not. allocated(error)) write (*, '(a,i0,a,f0.2)') &
                        '    det K: sign ', stats%det_sign, ', log10 |det K| ', log_det
                end if
            end if
            rec%seconds(3) = rec%seconds(3) + wall_seconds() - tic
            if (allocated(error)) exit
            tic = wall_seconds()
            rhs = -merge(0.0_dp, r, model%fixed)
            if (multigrid) then
                eta = forcing(rn, r0, model%tol_residual)
                ! while contact states still change, Newton is not in its quadratic range
                ! and the step mostly moves the active set: a looser solve will do
                changing = .false.
                if (it > 0) changing = any(states(:, it) /= states(:, it - 1))
                if (changing) then
                    eta = max(eta, active_set_forcing)
                    call mg%solve(rhs, du, eta, error, soft_iterations, soft_forcing)
                else
                    call mg%solve(rhs, du, eta, error)
                end if
                if (caught_signal() /= 0) stats%signal = caught_signal()
                rec%linear_iterations = rec%linear_iterations + mg%last_iterations
                if (verbose) write (*, '(a,i0,a,es9.2,a,es9.2,a)') '    gmres: ', mg%last_iterations, &
                    ' iterations, relative residual ', mg%last_residual, ' (asked ', eta, ')'
            else
                call lu%solve(k, rhs, du, error)
            end if
            rec%seconds(4) = rec%seconds(4) + wall_seconds() - tic
            if (allocated(error)) exit
            en = abs(dot_product(du, rhs))
            if (it == 0) e1 = en
            energies(it + 1) = en
            alpha_prev = alpha
            u_prev = u
            rn_prev = rn
            alpha = 1.0_dp
            if (natural) then
                ! the tangent the next trial points are tested with
                k_old = k
                du_norm_prev = du_norm
                du_norm = norm2(du)
                ! a-priori step from the last accepted step's contraction
                if (have_bar .and. du_norm > 0.0_dp) then
                    h_est = norm2(du_bar_acc - du)*du_norm/max(du_norm_prev*norm2(du_bar_acc), tiny(1.0_dp))
                    alpha = max(min(1.0_dp, alpha_prev/max(h_est, tiny(1.0_dp))), min_natural_step)
                end if
            end if
            nls = 0
            closing = .false.
            u = u + alpha*du
            it = it + 1
        end do
        stats%iterations = stats%iterations + it
        rec%iterations_total = rec%iterations_total + it
        if (allocated(error)) return
        rec%iterations = it
        rec%residual_norms = norms(1:it + 1)
        rec%energy_norms = energies(1:it)
    end subroutine newton_solve

    !> Relative residual to which an iterative linear solve is taken at a Newton
    !> iteration with residual `rn` (first residual `r0`): eta = 1e-3 min(1, rn/r0),
    !> so that the linear error, eta rn <= 1e-3 rn^2/r0, does not spoil the quadratic
    !> convergence; never tighter than needed for the Newton tolerance (0.1 tol r0)
    !> nor than 1e-12 (the attainable level in double precision).
    pure real(dp) function forcing(rn, r0, tol) result(eta)
        real(dp), intent(in) :: rn, r0, tol
        eta = 1.0e-3_dp
        if (r0 > 0.0_dp .and. rn > 0.0_dp) then
            eta = 1.0e-3_dp*min(1.0_dp, rn/r0)
            eta = max(eta, 0.1_dp*tol*r0/rn)
        end if
        eta = min(1.0e-3_dp, max(eta, 1.0e-12_dp))
    end function forcing

    !> Retry a frictional substep by successive approximations on the slip bounds
    !> (the fixed point of the existence theory of quasi-static Coulomb friction):
    !> with the bounds g_i fixed, the incremental problem is a Tresca problem, whose
    !> tangent has no mu x penalty_normal coupling; Newton solves it, then
    !> g_i = mu p_N,i from the new state, until the **Coulomb** residual at the
    !> Tresca solution meets Newton's convergence test against the substep's first
    !> Coulomb residual (tol_residual, or the round-off floors): the accepted state
    !> solves the Coulomb problem as a plain Newton result would. `u` holds the last
    !> converged state on entry, the accepted one on success; the contact pairs' trial
    !> history is then that of the Coulomb evaluation at it, and stats%det_sign the
    !> sign of det K of the Coulomb tangent there. Fails (error code numeric) when a
    !> Tresca solve fails, the bound changes grow three times in a row, or after
    !> `max_fixed_point` solves.
    subroutine tresca_fixed_point(model, step, t, u, r, k, map, lu, mg, stats, rec, it, rn, verbose, quiet, &
                                  error)
        type(model_t), intent(inout) :: model
        integer, intent(in) :: step
        real(dp), intent(in) :: t
        real(dp), intent(inout) :: u(:)
        !> Residual at the last evaluation, shape [ndof].
        real(dp), intent(inout) :: r(:)
        type(csc_matrix_t), intent(inout) :: k
        type(assembly_map_t), intent(inout) :: map
        type(umfpack_t), intent(inout) :: lu
        type(multigrid_t), intent(inout) :: mg
        type(solver_stats_t), intent(inout) :: stats
        type(step_record_t), intent(inout) :: rec
        !> Newton iterations of all Tresca solves; the Coulomb residual norm at the end.
        integer, intent(out) :: it
        real(dp), intent(out) :: rn
        logical, intent(in) :: verbose, quiet
        type(error_t), allocatable, intent(out) :: error
        type(error_t), allocatable :: inner
        real(dp), allocatable :: bound(:), new_bound(:), x0(:)
        real(dp) :: r0, floor, change, last_change, gmax, log_det, growth
        integer :: fp, it_inner, growing
        logical :: accepted
        character(len=600) :: msg

        it = 0
        rn = 0.0_dp
        stats%tresca_retries = stats%tresca_retries + 1
        x0 = reference_coordinates(model)
        ! initial bounds: mu p_N at the last converged state (p_N depends on u only)
        call assemble(model, u, t, r, stats%assembly, error)
        if (allocated(error)) return
        bound = slip_bounds(model)
        ! the reference of the convergence test: the Coulomb residual at the substep's
        ! start, the first residual of the plain Newton attempt that failed
        call set_prescribed(model, t, u)
        call assemble(model, u, t, r, stats%assembly, error)
        if (allocated(error)) return
        r0 = norm2(merge(0.0_dp, r, model%fixed))
        last_change = huge(1.0_dp)
        growing = 0
        growth = 0.0_dp
        accepted = .false.
        do fp = 1, max_fixed_point
            stats%fixed_point_iterations = stats%fixed_point_iterations + 1
            call set_slip_bounds(model, bound)
            call newton_solve(model, step, t, u, r, k, map, lu, mg, stats, rec, it_inner, rn, verbose, inner, r0)
            call clear_slip_bounds(model)
            it = it + it_inner
            if (allocated(inner)) then
                if (stats%signal /= 0) then
                    call move_alloc(inner, error)
                    return
                end if
                write (msg, '(a,i0,a)') 'the Tresca problem of fixed-point iteration ', fp, ' failed: '
                call fatal_error(error, trim(msg)//' '//inner%message, error_code%numeric)
                return
            end if
            ! the Coulomb residual and tangent at the Tresca solution, and the new bounds
            call assemble(model, u, t, r, stats%assembly, error, k, map)
            if (allocated(error)) return
            rn = norm2(merge(0.0_dp, r, model%fixed))
            floor = residual_floor(k, x0 + u, model%fixed)
            new_bound = slip_bounds(model)
            change = maxval(abs(new_bound - bound))
            gmax = maxval(new_bound)
            if (verbose) write (*, '(a,i0,a,i0,a,es10.3,a,es10.3,a,es10.3,a,es9.2,a,i0)') '  step ', step, &
                ' fixed point ', fp, '  Coulomb |r|=', rn, '  reference ', r0, '  max |g change|=', change, &
                ' of max g ', gmax, '  Newton it ', it_inner
            ! Newton's own tests (newton_solve), on the Coulomb residual
            if (rn <= model%tol_residual*r0 .or. rn == 0.0_dp .or. &
                rn <= 1.0e4_dp*epsilon(1.0_dp)*max(r0, stats%r0_max) .or. &
                (rn <= floor .and. rn <= floor_cap*max(r0, stats%r0_max))) then
                accepted = .true.
                exit
            end if
            if (.not. ieee_is_finite(rn)) exit
            growing = merge(growing + 1, 0, change > last_change)
            if (growing > 0) growth = max(growth, change/last_change)
            if (growing == 0) growth = 0.0_dp
            if (growing >= 3) exit
            last_change = change
            bound = new_bound
        end do
        if (.not. accepted) then
            write (msg, '(a,i0,a,es9.2,a,es9.2,a,es9.2,a,es9.2,a)') 'the fixed point did not converge in ', &
                fp - merge(1, 0, fp > max_fixed_point), ' iterations (Coulomb residual ', rn, ', reference ', r0, &
                '; last bound change ', change, ' of max bound ', gmax, ')'
            if (growing >= 3) then
                write (msg, '(a,f0.2,a)') trim(msg)//': the successive approximations diverge (the bound '// &
                    'change grew in 3 iterations in a row, by up to ', growth, ' per iteration): the map g -> '// &
                    'mu p_N(g) is not a contraction here'
                call fatal_error(error, trim(msg)//', the condition under which the existence theory of '// &
                                 'quasi-static Coulomb friction guarantees a unique incremental solution '// &
                                 '(small mu); a Coulomb solution may not exist near this state', &
                                 error_code%numeric)
            else
                call fatal_error(error, trim(msg)//': the Coulomb incremental problem may have no '// &
                                 'solution near this state', error_code%numeric)
            end if
            return
        end if
        ! the orientation of the Coulomb tangent at the accepted state (the
        ! multigrid solver has no factors: the sign stays unknown)
        if (model%linear_solver /= 'multigrid') then
            call k%fix_dofs(model%fixed)
            call lu%factorize(k, error)
            if (allocated(error)) return
            call lu%determinant(stats%det_sign, log_det, error)
            if (allocated(error)) return
        end if
        stats%tresca_accepted = stats%tresca_accepted + 1
        if (.not. quiet) write (*, '(a,i0,a,f10.6,a,i0,a,i0,a,6(es9.2,a),i0)') 'tresca step ', &
            step, '  t=', t, ': the Tresca fixed point converged in ', fp, ' iterations (', it, &
            ' Newton iterations); Coulomb residual ', rn, ' (reference ', r0, ', round-off floor ', floor, &
            ', force scale ', max(r0, stats%r0_max), '); last bound change ', change, ' of max bound ', gmax, &
            '; det K sign ', stats%det_sign
    end subroutine tresca_fixed_point

    !> Whether the Tresca fixed point applies to a pair: GPTS with friction (a
    !> mortar pair's slip limits belong to its control points, not to its slave
    !> points; it keeps Coulomb friction).
    pure logical function tresca_pair(pair)
        type(contact_pair_t), intent(in) :: pair
        tresca_pair = pair%law%mu > 0.0_dp .and. pair%method == method_gpts
    end function tresca_pair

    !> Whether any contact pair has friction the Tresca fixed point applies to.
    pure logical function frictional(model)
        type(model_t), intent(in) :: model
        integer :: ip
        frictional = any([(tresca_pair(model%pairs(ip)), ip=1, size(model%pairs))])
    end function frictional

    !> mu p_N at the last evaluation for every slave point of every frictional pair,
    !> in pair order; shape: [sum of the frictional pairs' points].
    pure function slip_bounds(model) result(bound)
        type(model_t), intent(in) :: model
        real(dp), allocatable :: bound(:)
        integer :: ip
        allocate (bound(0))
        do ip = 1, size(model%pairs)
            if (.not. tresca_pair(model%pairs(ip))) cycle
            bound = [bound, model%pairs(ip)%law%mu*max(0.0_dp, model%pairs(ip)%out%pn)]
        end do
    end function slip_bounds

    !> Put every frictional pair in Tresca mode with the bounds `bound` (layout of
    !> `slip_bounds`).
    pure subroutine set_slip_bounds(model, bound)
        type(model_t), intent(inout) :: model
        real(dp), intent(in) :: bound(:)
        integer :: ip, first, n
        first = 0
        do ip = 1, size(model%pairs)
            if (.not. tresca_pair(model%pairs(ip))) cycle
            n = size(model%pairs(ip)%out)
            model%pairs(ip)%slip_bound = bound(first + 1:first + n)
            first = first + n
        end do
    end subroutine set_slip_bounds

    !> Back to Coulomb friction in every pair.
    pure subroutine clear_slip_bounds(model)
        type(model_t), intent(inout) :: model
        integer :: ip
        do ip = 1, size(model%pairs)
            if (allocated(model%pairs(ip)%slip_bound)) deallocate (model%pairs(ip)%slip_bound)
        end do
    end subroutine clear_slip_bounds

    !> One line per Newton iteration: residual, energy norm, contact states.
    subroutine print_iteration(model, step, it, rn, en, alpha, floor)
        type(model_t), intent(in) :: model
        integer, intent(in) :: step, it
        real(dp), intent(in) :: rn, en, alpha, floor
        integer :: ip
        write (*, '(a,i0,a,i0,a,es10.3,a,es10.3,a,f6.4,a,es9.2)', advance='no') '  step ', step, &
            ' it ', it, '  |r|=', rn, '  |du.r|=', merge(en, 0.0_dp, it > 0), '  step length ', alpha, &
            '  floor ', floor
        do ip = 1, size(model%pairs)
            write (*, '(a,i0,a,i0,a,i0)', advance='no') '  stick=', count(model%pairs(ip)%out%state == 1), &
                ' slip=', count(model%pairs(ip)%out%state == 2), ' of ', size(model%pairs(ip)%out)
        end do
        write (*, '(a)') ''
    end subroutine print_iteration

    !> Round-off level of the residual at coordinates `x`: floor_factor eps || |K| |x| ||
    !> on the free DOFs. Rounding every coordinate x_j by its unit round-off eps |x_j|
    !> changes the residual by up to (|K| eps |x|)_i; a residual below that is as
    !> converged as double precision can tell (a componentwise backward error of the
    !> coordinates of order eps). With a stiff penalty ||K|| is large and this floor
    !> lies above tol_residual ||r_0||. `k` is the assembled tangent before the
    !> Dirichlet elimination.
    pure real(dp) function residual_floor(k, x, fixed) result(floor)
        type(csc_matrix_t), intent(in) :: k
        !> Current coordinates (reference + displacement) of every DOF; shape: [ndof].
        real(dp), intent(in) :: x(:)
        !> .true. for a Dirichlet DOF; shape: [ndof].
        logical, intent(in) :: fixed(:)
        real(dp), allocatable :: w(:)
        integer :: j, p
        allocate (w(k%n))
        w = 0.0_dp
        do j = 1, k%n
            do p = k%colptr(j) + 1, k%colptr(j + 1)
                w(k%rowind(p) + 1) = w(k%rowind(p) + 1) + abs(k%values(p))*abs(x(j))
            end do
        end do
        floor = floor_factor*epsilon(1.0_dp)*norm2(merge(0.0_dp, w, fixed))
    end function residual_floor

    !> The contact state (inactive, stick, slip) of every slave point of every pair,
    !> in pair order; shape: [sum of the pairs' points].
    pure function contact_states(model) result(states)
        type(model_t), intent(in) :: model
        integer, allocatable :: states(:)
        integer :: ip, k
        allocate (states(0))
        do ip = 1, size(model%pairs)
            states = [states, (model%pairs(ip)%out(k)%state, k=1, size(model%pairs(ip)%out))]
        end do
    end function contact_states

    !> Reference coordinates of the control point of every DOF; shape: [ndof]
    !> (2(a-1)+i of body b at dof0 + 2(a-1) + i, as the displacement).
    pure function reference_coordinates(model) result(x0)
        type(model_t), intent(in) :: model
        real(dp), allocatable :: x0(:)
        integer :: ib, n
        allocate (x0(model%ndof))
        x0 = 0.0_dp
        do ib = 1, size(model%bodies)
            n = size(model%bodies(ib)%disc%x)
            x0(model%bodies(ib)%dof0 + 1:model%bodies(ib)%dof0 + n) = reshape(model%bodies(ib)%disc%x, [n])
        end do
    end function reference_coordinates

    !> Put the prescribed values at load time `t` into `u`.
    pure subroutine set_prescribed(model, t, u)
        type(model_t), intent(in) :: model
        real(dp), intent(in) :: t
        real(dp), intent(inout) :: u(:)
        integer :: j, c
        do j = 1, size(model%dirichlet)
            do c = 1, 2
                if (model%dirichlet(j)%fix(c)) then
                    u(model%dirichlet(j)%dofs(c, :)) = phase_value(model%dirichlet(j)%values(c, :), t)
                end if
            end do
        end do
    end subroutine set_prescribed

end module voiga_solver_newton
