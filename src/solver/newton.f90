!> One Newton attempt at a load time: K du = -r on the free DOFs (the prescribed
!> DOFs are eliminated symmetrically, their corrections are zero), iterated from a
!> given start until `voiga_solver_convergence` says it has converged, or until it
!> fails with a reason (the iteration cap, a residual that is not finite or grows
!> by `divergence_ratio`, contact states cycling, an inverted element, a contact
!> projection that does not converge, a singular matrix). The load stepping
!> (`voiga_solver_stepping`) decides what a failure leads to; the step length of
!> each iteration follows `voiga_solver_step_length`. SIGINT/SIGTERM
!> (voiga_platform_signals) are polled between iterations.
module voiga_solver_newton
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_model, only: model_t, reference_coordinates
    use voiga_model_assembly, only: assemble, assemble_residual, stiffness_pattern, assembly_map_t, new_assembly_map, &
                                    bulk_stiffness, assembly_stats_t
    use voiga_contact_law, only: state_stick, state_slip
    use voiga_contact_pair, only: pair_slot_t
    use voiga_linalg_sparse, only: csc_matrix_t
    use voiga_solver_linear, only: linear_solver_t, solve_accuracy_t
    use voiga_solver_linear_factory, only: new_linear_solver
    use voiga_solver_settings, only: solver_settings_t
    use voiga_platform_signals, only: caught_signal, signal_name
    use voiga_solver_records, only: solver_stats_t, wall_seconds
    use voiga_solver_progress, only: iteration_report_t
    use voiga_solver_context, only: context_t
    use voiga_solver_convergence, only: convergence_t, converged, at_roundoff, residual_floor, floor_cap, &
                                        divergence_ratio
    use voiga_text, only: str, real_str
    use voiga_solver_step_length, only: crossing_limit, backtracks, natural_reduction, natural_first_step, &
                                        creep_step
    implicit none
    private

    public :: newton_t, new_newton, attempt_t, newton_attempt, contact_states

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

    !> What a run's Newton attempts share, set up once: the settings, the tangent's
    !> pattern and element map, the linear solver, the reference coordinates.
    type :: newton_t
        type(solver_settings_t) :: settings
        !> The tangent (its pattern follows the contact couplings) and, with natural
        !> damping, the tangent of the last factorization.
        type(csc_matrix_t) :: k, k_old
        type(assembly_map_t) :: map
        class(linear_solver_t), allocatable :: linear
        !> Natural damping (`&solver damping = 'natural'`).
        logical :: natural = .false.
        !> Reference coordinates of every DOF's control point; residual at the last
        !> evaluation. Shapes: [ndof].
        real(dp), allocatable :: x0(:), r(:)
    end type newton_t

    !> How an attempt ended (its error, if it failed, says why).
    type :: attempt_t
        !> Newton iterations, and the residual norm at the end.
        integer :: iterations = 0
        real(dp) :: residual = 0.0_dp
        !> Sign of det K of the last tangent factorized (0: none, or unknown), and the
        !> iterations whose tangent had det K <= 0.
        integer :: det_sign = 0, nonpositive_det = 0
        !> The attempt failed with contact states switching (a period-2 cycle, or the
        !> iteration cap with switches among the last iterations).
        logical :: switching = .false.
    end type attempt_t

    !> One attempt's state between iterations.
    type :: iterate_t
        !> Iterations done, step reductions of the current one, iterations whose
        !> accepted step was at most `creep_step`.
        integer :: it = 0, nls = 0, short_steps = 0
        type(convergence_t) :: c
        real(dp) :: alpha = 1.0_dp, alpha_prev = 1.0_dp, rn_prev = huge(1.0_dp)
        !> Natural damping: norms of the last two corrections.
        real(dp) :: du_norm = 0.0_dp, du_norm_prev = 0.0_dp
        !> The step was cut to a contact crossing; the simplified correction of the
        !> accepted point is known.
        logical :: closing = .false., have_bar = .false.
        !> The caller wants the tangent at the converged iterate (else an iterate
        !> expected to converge is first evaluated without one).
        logical :: keep_tangent = .false.
        real(dp), allocatable :: du(:), u_prev(:), rhs(:), du_bar(:), du_bar_acc(:)
        !> Residual before each iteration and after the last; |du.r| of each.
        real(dp), allocatable :: norms(:), energies(:)
        !> Contact state of every slave point after each iteration; shape: [npoints, 0:max_iterations].
        integer, allocatable :: states(:, :)
    end type iterate_t

contains

    !> Set up the attempts of a run of `model`: the tangent's pattern, the element
    !> map, the linear solver the settings name. The bodies' stiffness assembled
    !> here (every body linear) counts in `assembly`.
    subroutine new_newton(self, model, settings, assembly, error)
        type(newton_t), intent(out) :: self
        type(model_t), intent(in) :: model
        type(solver_settings_t), intent(in) :: settings
        type(assembly_stats_t), intent(inout) :: assembly
        type(error_t), allocatable, intent(out) :: error
        type(csc_matrix_t) :: k0
        self%settings = settings
        call stiffness_pattern(model, self%k, error)
        if (allocated(error)) return
        call new_assembly_map(model, self%k, self%map, error)
        if (allocated(error)) return
        self%map%keep_linear = settings%reuse_linear_bulk
        if (settings%reuse_linear_bulk .and. .not. model%finite_strain) then
            ! every body linear: their stiffness, kept in the map for the loop's assemblies
            ! and factorized once by a direct solver
            call bulk_stiffness(model, self%k, self%map, k0, assembly, error)
            if (allocated(error)) return
            call new_linear_solver(self%linear, settings%linear_solver, model, error, k0)
        else
            call new_linear_solver(self%linear, settings%linear_solver, model, error)
        end if
        if (allocated(error)) return
        self%natural = trim(settings%damping) == 'natural'
        self%x0 = reference_coordinates(model)
        allocate (self%r(model%ndof))
        self%r = 0.0_dp
    end subroutine new_newton

    !> Newton iterations at the load time of `ctx` from `u` (prescribed values set).
    !> On success `ctx%record` holds the iteration's norms. A numerical failure
    !> returns an error with code `numeric` and its reason; an interrupt sets
    !> ctx%stats%signal and returns a generic error. With `r0_ref` the relative tests (tol_residual,
    !> energy, divergence) use it instead of the first residual (the Tresca solves of
    !> a fixed point, measured against the substep's). `keep_tangent`: `self%k` holds
    !> the tangent at the converged iterate on return (else it may be an earlier
    !> iterate's: the converged one's is not assembled when it is not needed).
    subroutine newton_attempt(self, model, ctx, u, attempt, error, r0_ref, keep_tangent)
        type(newton_t), intent(inout) :: self
        type(model_t), intent(inout) :: model
        type(context_t), intent(inout) :: ctx
        real(dp), intent(inout) :: u(:)
        type(attempt_t), intent(out) :: attempt
        type(error_t), allocatable, intent(out) :: error
        real(dp), intent(in), optional :: r0_ref
        logical, intent(in), optional :: keep_tangent
        type(iterate_t) :: st
        logical :: done

        call start_iterate(self, model, st)
        if (present(keep_tangent)) st%keep_tangent = keep_tangent
        do
            if (caught_signal() /= 0) then
                ctx%stats%signal = caught_signal()
                call fatal_error(error, 'interrupted by '//signal_name(ctx%stats%signal))
                exit
            end if
            call evaluate(self, model, ctx, u, st, error)
            if (allocated(error)) exit
            if (shortened(self, model, st, ctx%stats, error)) then
                u = st%u_prev + st%alpha*st%du
                cycle
            end if
            if (allocated(error)) exit
            call accept_iterate(model, st, ctx%stats, r0_ref)
            call report_iteration(model, ctx, st)
            call assess(self%settings, self%natural, st, attempt, done, error)
            if (done) exit
            call direction(self, model, ctx, st, attempt, error)
            if (allocated(error)) exit
            call advance(self, st)
            st%u_prev = u
            u = u + st%alpha*st%du
            st%it = st%it + 1
        end do
        attempt%iterations = st%it
        attempt%residual = st%c%residual
        ctx%stats%iterations = ctx%stats%iterations + st%it
        ctx%record%iterations_total = ctx%record%iterations_total + st%it
        if (allocated(error)) return
        ctx%record%iterations = st%it
        ctx%record%residual_norms = st%norms(1:st%it + 1)
        ctx%record%energy_norms = st%energies(1:st%it)
    end subroutine newton_attempt

    !> A fresh attempt's state.
    subroutine start_iterate(self, model, st)
        type(newton_t), intent(in) :: self
        type(model_t), intent(in) :: model
        type(iterate_t), intent(out) :: st
        integer :: ip, n
        n = model%ndof
        allocate (st%du(n), st%rhs(n), st%u_prev(n), st%du_bar(n))
        allocate (st%states(sum([(size(model%pairs(ip)%pair%out), ip=1, size(model%pairs))]), &
                            0:self%settings%max_iterations))
        allocate (st%norms(self%settings%max_iterations + 1), st%energies(self%settings%max_iterations))
    end subroutine start_iterate

    !> Residual and tangent at the trial point `u`, and the round-off floor there.
    !> The substep's first assembly also fits the contact pattern to its start. A
    !> trial point expected to converge (`expect_converged`) is first evaluated
    !> without the tangent (`converged_without_tangent`).
    subroutine evaluate(self, model, ctx, u, st, error)
        type(newton_t), intent(inout) :: self
        type(model_t), intent(inout) :: model
        type(context_t), intent(inout) :: ctx
        real(dp), intent(in) :: u(:)
        type(iterate_t), intent(inout) :: st
        type(error_t), allocatable, intent(out) :: error
        real(dp) :: bulk0, contact0
        logical :: enough
        associate (stats => ctx%stats, rec => ctx%record)
            bulk0 = stats%assembly%seconds_bulk
            contact0 = stats%assembly%seconds_contact
            enough = .false.
            if (expect_converged(self, st)) &
                enough = converged_without_tangent(self, model, ctx%time, u, st, stats)
            if (.not. enough) call assemble(model, u, ctx%time, self%r, stats%assembly, error, self%k, &
                                            self%map, refit=(st%it == 0 .and. st%nls == 0))
            rec%seconds(1) = rec%seconds(1) + stats%assembly%seconds_bulk - bulk0
            rec%seconds(2) = rec%seconds(2) + stats%assembly%seconds_contact - contact0
        end associate
        if (enough .or. allocated(error)) return
        st%c%residual = norm2(merge(0.0_dp, self%r, model%fixed))
        if (.not. ieee_is_finite(st%c%residual)) then
            call fatal_error(error, 'the residual is not finite', error_code%numeric)
            return
        end if
        st%c%floor = residual_floor(self%k, self%x0 + u, model%fixed)
        st%have_bar = .false.
    end subroutine evaluate

    !> Whether the trial point `u` is expected to be the converged iterate, so that
    !> its tangent (and the round-off floor, which needs it) will not be wanted: a
    !> full Newton step after two or more, whose residual, falling by the factor of
    !> the last step again, would be below the tolerance (convergence is at least
    !> that fast near the solution), or whose last correction already meets the
    !> energy test. Not with natural damping (its step test needs the floor) nor
    !> when the caller keeps the tangent.
    pure logical function expect_converged(self, st) result(expect)
        type(newton_t), intent(in) :: self
        type(iterate_t), intent(in) :: st
        real(dp) :: last, before
        expect = .false.
        if (st%it < 2 .or. st%nls > 0 .or. st%closing .or. self%natural .or. st%keep_tangent) return
        last = st%norms(st%it)
        before = st%norms(st%it - 1)
        if (before > 0.0_dp) expect = last*(last/before) <= self%settings%tol_residual*st%c%first
        expect = expect .or. st%c%energy <= self%settings%tol_energy*st%c%first_energy
    end function expect_converged

    !> Evaluate the trial point `u` without the tangent (`assemble_residual`) and
    !> tell whether that is enough: the iterate has converged by a test that needs
    !> no round-off floor (`converged` with none), its residual is not above the last
    !> one (the step rules do not backtrack) and the contact points fit the
    !> stiffness pattern. Then `st%c` holds the residual and no floor (-1: not
    !> computed); else the contact pairs are as before the call, for the full
    !> evaluation to follow, which gives the same numbers as without this one.
    logical function converged_without_tangent(self, model, t, u, st, stats) result(enough)
        type(newton_t), intent(inout) :: self
        type(model_t), intent(inout) :: model
        real(dp), intent(in) :: t, u(:)
        type(iterate_t), intent(inout) :: st
        type(solver_stats_t), intent(inout) :: stats
        type(pair_slot_t), allocatable :: saved(:)
        type(error_t), allocatable :: error
        type(convergence_t) :: c
        logical :: fits
        saved = model%pairs
        call assemble_residual(model, u, t, self%r, stats%assembly, error, self%k, self%map, fits)
        enough = .false.
        if (.not. allocated(error) .and. fits) then
            c = st%c
            c%residual = norm2(merge(0.0_dp, self%r, model%fixed))
            c%iteration = st%it
            c%scale = max(c%first, stats%r0_max)
            c%floor = -1.0_dp
            enough = ieee_is_finite(c%residual) .and. c%residual <= st%rn_prev .and. &
                     converged(c, self%settings%tol_residual, self%settings%tol_energy)
        end if
        if (enough) then
            st%c%residual = c%residual
            st%c%floor = c%floor
            st%have_bar = .false.
        else
            call move_alloc(saved, model%pairs)
        end if
    end function converged_without_tangent

    !> Whether the step-length rules shorten the step to the trial point (then
    !> `st%alpha` is the new length); `voiga_solver_step_length`.
    logical function shortened(self, model, st, stats, error) result(shorten)
        type(newton_t), intent(inout) :: self
        type(model_t), intent(in) :: model
        type(iterate_t), intent(inout) :: st
        type(solver_stats_t), intent(inout) :: stats
        type(error_t), allocatable, intent(out) :: error
        real(dp) :: frac, new_alpha
        logical :: smooth, roundoff, reduce

        shorten = .false.
        ! a step that carries a mortar control point across a state boundary the
        ! tangent did not describe (it closes, or its slip reverses) is shortened to
        ! where the first one crosses (once per iteration), and that point accepted
        if (st%it > 0 .and. st%nls == 0 .and. .not. st%closing) then
            frac = crossing_limit(model)
            if (frac < 1.0_dp) then
                st%closing = .true.
                stats%line_search_steps = stats%line_search_steps + 1
                st%alpha = st%alpha*frac
                shorten = .true.
                return
            end if
        end if
        roundoff = at_roundoff(st%c%residual, st%c%floor, max(st%c%first, stats%r0_max))
        ! where the contact states change the last tangent does not describe the
        ! trial point (a new active set): the residual rule decides there
        smooth = .false.
        if (self%natural .and. st%it > 0 .and. .not. st%closing) &
            smooth = all(contact_states(model) == st%states(:, st%it - 1))
        if (smooth .and. st%du_norm > 0.0_dp .and. .not. roundoff) then
            ! natural monotonicity test (affine invariant): the simplified Newton
            ! correction at the trial point, with the last iteration's tangent
            st%rhs = -merge(0.0_dp, self%r, model%fixed)
            call self%linear%solve(self%k_old, st%rhs, st%du_bar, error)
            if (allocated(error)) return
            call natural_reduction(st%du_bar, st%du, st%du_norm, st%alpha, st%nls, reduce, new_alpha)
            if (reduce) then
                st%nls = st%nls + 1
                stats%line_search_steps = stats%line_search_steps + 1
                st%alpha = new_alpha
                shorten = .true.
                return
            end if
            st%du_bar_acc = st%du_bar
            st%have_bar = .true.
        end if
        ! backtracking: a Newton step that increases the residual is halved
        ! (contact stick/slip and active-set changes can make full steps cycle)
        if (.not. smooth .and. .not. st%closing .and. st%it > 0) then
            if (backtracks(st%c%residual, st%rn_prev, st%nls, roundoff)) then
                st%nls = st%nls + 1
                stats%line_search_steps = stats%line_search_steps + 1
                st%alpha = 0.5_dp*st%alpha
                shorten = .true.
            end if
        end if
    end function shortened

    !> The trial point is the next iterate: record its residual and contact states,
    !> let the pairs take it as the reference of their step control; the first sets
    !> the substep's reference residual.
    subroutine accept_iterate(model, st, stats, r0_ref)
        type(model_t), intent(inout) :: model
        type(iterate_t), intent(inout) :: st
        type(solver_stats_t), intent(inout) :: stats
        real(dp), intent(in), optional :: r0_ref
        integer :: ip
        st%norms(st%it + 1) = st%c%residual
        st%states(:, st%it) = contact_states(model)
        if (st%it > 0 .and. st%alpha <= creep_step) st%short_steps = st%short_steps + 1
        do ip = 1, size(model%pairs)
            call model%pairs(ip)%pair%accept_iterate()
        end do
        if (st%it == 0) then
            st%c%first = st%c%residual
            stats%r0_max = max(stats%r0_max, st%c%first)
            if (present(r0_ref)) st%c%first = r0_ref
        end if
        st%c%iteration = st%it
        st%c%scale = max(st%c%first, stats%r0_max)
    end subroutine accept_iterate

    !> One line's worth of the iteration for the progress hooks.
    subroutine report_iteration(model, ctx, st)
        type(model_t), intent(in) :: model
        type(context_t), intent(in) :: ctx
        type(iterate_t), intent(in) :: st
        type(iteration_report_t) :: report
        integer :: ip
        report%step = ctx%step
        report%iteration = st%it
        report%residual = st%c%residual
        report%energy = merge(st%c%energy, 0.0_dp, st%it > 0)
        report%step_length = st%alpha
        report%floor = st%c%floor
        allocate (report%stick(size(model%pairs)), report%slip(size(model%pairs)), report%points(size(model%pairs)))
        do ip = 1, size(model%pairs)
            associate (out => model%pairs(ip)%pair%out)
                report%stick(ip) = count(out%state == state_stick)
                report%slip(ip) = count(out%state == state_slip)
                report%points(ip) = size(out)
            end associate
        end do
        call ctx%progress%iteration(report)
    end subroutine report_iteration

    !> Converged, or failed with a reason, or go on (`done` false): the single
    !> assessment of an accepted iterate.
    pure subroutine assess(settings, natural, st, attempt, done, error)
        type(solver_settings_t), intent(in) :: settings
        logical, intent(in) :: natural
        type(iterate_t), intent(in) :: st
        type(attempt_t), intent(inout) :: attempt
        logical, intent(out) :: done
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: msg
        integer :: flips, ip

        done = converged(st%c, settings%tol_residual, settings%tol_energy)
        if (done) return
        done = .true.
        associate (it => st%it, rn => st%c%residual, r0 => st%c%first, states => st%states)
            if (it > 0 .and. rn > divergence_ratio*r0) then
                call fatal_error(error, 'the residual grew from '//real_str(r0, 'es9.2')//' to '// &
                                 real_str(rn, 'es9.2')//' in '//str(it)//' iterations', error_code%numeric)
                return
            end if
            ! a limit cycle: the contact states and the residual repeat with period 2
            ! twice in a row; continuing would repeat it up to the iteration cap
            if (it >= 4 .and. .not. (rn <= st%c%floor)) then
                if (all(states(:, it) == states(:, it - 2)) .and. all(states(:, it - 1) == states(:, it - 3)) .and. &
                    any(states(:, it) /= states(:, it - 1)) .and. abs(rn - st%norms(it - 1)) <= 1.0e-6_dp*rn .and. &
                    abs(st%norms(it) - st%norms(it - 2)) <= 1.0e-6_dp*rn) then
                    flips = count(states(:, it) /= states(:, it - 1))
                    attempt%switching = .true.
                    call fatal_error(error, 'Newton cycles after '//str(it)//' iterations: '//str(flips)// &
                                     ' contact point(s) switch state (stick/slip or contact/separation) with '// &
                                     'every iteration and the residual repeats ('//real_str(rn, 'es9.2')// &
                                     ', first '//real_str(r0, 'es9.2')//'): the friction and contact laws '// &
                                     'are not smooth where the point sits on the stick/slip or contact limit', &
                                     error_code%numeric)
                    return
                end if
            end if
            if (it == settings%max_iterations) then
                msg = 'Newton did not converge in '//str(settings%max_iterations)//' iterations (residual '// &
                      real_str(rn, 'es9.2')//', first '//real_str(r0, 'es9.2')//')'
                if (rn <= st%c%floor) then
                    msg = msg//': the residual is at its round-off level '//real_str(st%c%floor, 'es9.2')// &
                          ' (stiffness x rounding of the coordinates), above '//real_str(floor_cap, 'es9.2')// &
                          ' of the force scale '//real_str(st%c%scale, 'es9.2')// &
                          ': the stiffness (penalty) is too large for double precision'
                else
                    flips = count([(any(states(:, ip) /= states(:, ip - 1)), ip=max(1, it - 9), it)])
                    attempt%switching = flips > 0
                    if (flips > 0) msg = msg//': contact states still switched in '//str(flips)//' of the last '// &
                                         str(it - max(1, it - 9) + 1)// &
                                         ' iterations (points on the stick/slip or contact limit)'
                    if (.not. natural .and. 2*st%short_steps >= settings%max_iterations) &
                        msg = msg//'; '//str(st%short_steps)//' of its iterations took steps of 1/16 or less: '// &
                              'the residual rule creeps along the curvature of a stiff penalty, &solver '// &
                              'damping = ''natural'' may pass it (docs/robustness.md, "Natural damping")'
                end if
                call fatal_error(error, msg, error_code%numeric)
                return
            end if
        end associate
        done = .false.
    end subroutine assess

    !> The Newton correction: factor the tangent (with its determinant's sign where
    !> the linear solver knows it) and solve K du = -r.
    subroutine direction(self, model, ctx, st, attempt, error)
        type(newton_t), intent(inout) :: self
        type(model_t), intent(in) :: model
        type(context_t), intent(inout) :: ctx
        type(iterate_t), intent(inout) :: st
        type(attempt_t), intent(inout) :: attempt
        type(error_t), allocatable, intent(out) :: error
        type(solve_accuracy_t) :: accuracy
        real(dp) :: tic, log_det
        logical :: changing

        tic = wall_seconds()
        call self%k%fix_dofs(model%fixed)
        ! a substep's first tangent: its analysis depends on this matrix only (restarts)
        if (st%it == 0 .and. st%nls == 0) call self%linear%renew_analysis()
        call self%linear%factor(self%k, error)
        if (.not. allocated(error) .and. self%linear%has_determinant()) then
            ! the orientation of the tangent (O(n) from the factors): a sign
            ! change marks a fold of the incremental problem (voiga_solver_stepping)
            call self%linear%determinant(attempt%det_sign, log_det, error)
            if (attempt%det_sign <= 0) attempt%nonpositive_det = attempt%nonpositive_det + 1
            if (.not. allocated(error)) call ctx%progress%factorized(attempt%det_sign, log_det)
        end if
        ctx%record%seconds(3) = ctx%record%seconds(3) + wall_seconds() - tic
        if (allocated(error)) return
        tic = wall_seconds()
        st%rhs = -merge(0.0_dp, self%r, model%fixed)
        ! an iterative solve: while contact states still change, Newton is not in its
        ! quadratic range and the step mostly moves the active set: a looser solve will do
        accuracy%rtol = forcing(st%c%residual, st%c%first, self%settings%tol_residual)
        changing = .false.
        if (st%it > 0) changing = any(st%states(:, st%it) /= st%states(:, st%it - 1))
        if (changing) accuracy = solve_accuracy_t(max(accuracy%rtol, active_set_forcing), soft_iterations, &
                                                  soft_forcing)
        call self%linear%solve(self%k, st%rhs, st%du, error, accuracy)
        if (caught_signal() /= 0) ctx%stats%signal = caught_signal()
        if (self%linear%iterative()) then
            ctx%record%linear_iterations = ctx%record%linear_iterations + self%linear%last_iterations()
            call ctx%progress%linear_solved(self%linear%last_iterations(), self%linear%last_residual(), &
                                            accuracy%rtol)
        end if
        ctx%record%seconds(4) = ctx%record%seconds(4) + wall_seconds() - tic
    end subroutine direction

    !> After the correction: its energy norm, the previous iterate kept for the step
    !> rules, and the next step length (1; natural damping: its a-priori estimate).
    subroutine advance(self, st)
        type(newton_t), intent(inout) :: self
        type(iterate_t), intent(inout) :: st
        st%c%energy = abs(dot_product(st%du, st%rhs))
        if (st%it == 0) st%c%first_energy = st%c%energy
        st%energies(st%it + 1) = st%c%energy
        st%alpha_prev = st%alpha
        st%rn_prev = st%c%residual
        st%alpha = 1.0_dp
        if (self%natural) then
            ! the tangent the next trial points are tested with
            self%k_old = self%k
            st%du_norm_prev = st%du_norm
            st%du_norm = norm2(st%du)
            ! a-priori step from the last accepted step's contraction
            if (st%have_bar .and. st%du_norm > 0.0_dp) &
                st%alpha = natural_first_step(st%du_bar_acc, st%du, st%du_norm, st%du_norm_prev, st%alpha_prev)
        end if
        st%nls = 0
        st%closing = .false.
    end subroutine advance

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

    !> The contact state (inactive, stick, slip) of every slave point of every pair,
    !> in pair order; shape: [sum of the pairs' points].
    pure function contact_states(model) result(states)
        type(model_t), intent(in) :: model
        integer, allocatable :: states(:)
        integer :: ip, n
        allocate (states(sum([(size(model%pairs(ip)%pair%out), ip=1, size(model%pairs))])))
        n = 0
        do ip = 1, size(model%pairs)
            associate (out => model%pairs(ip)%pair%out)
                states(n + 1:n + size(out)) = out%state
                n = n + size(out)
            end associate
        end do
    end function contact_states

end module voiga_solver_newton
