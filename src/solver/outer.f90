!> Outer loops around Newton.
!>
!> The augmented Lagrangian (docs/theory.md, section 7, "Augmented Lagrangian"): with the contact
!> multipliers fixed Newton solves the substep, then every pair with multipliers
!> updates them from the solution and tests its constraints; repeated until every
!> pair's constraints hold to its tolerance. `substep_attempt` runs it when a pair
!> has multipliers, a plain Newton attempt otherwise.
!>
!> The Tresca fixed point (docs/robustness.md, "Tresca
!> fixed point"): a frictional substep whose Newton attempt from the last
!> converged state failed with contact states switching is retried at the same
!> increment by successive approximations on the slip bounds, the fixed point of
!> the existence theory of quasi-static Coulomb friction: with the bounds g_i fixed
!> the incremental problem is a Tresca problem, whose tangent has no
!> mu x penalty_normal coupling; Newton solves it, then g_i = mu p_N,i from the new
!> state, until the **Coulomb** residual at the Tresca solution meets Newton's
!> convergence test against the substep's first Coulomb residual. The pairs take
!> part through their outer-loop hooks (`contact_pair_t%takes_outer`,
!> `outer_capture`, `outer_apply`, `outer_release`).
module voiga_solver_outer
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_model, only: model_t, set_prescribed
    use voiga_model_assembly, only: assemble
    use voiga_solver_records, only: step_record_t
    use voiga_solver_progress, only: fixed_point_report_t
    use voiga_solver_context, only: context_t
    use voiga_solver_convergence, only: convergence_t, converged, residual_floor
    use voiga_solver_newton, only: newton_t, newton_attempt, attempt_t
    use voiga_solver_records, only: wall_seconds
    use voiga_contact_pair, only: constraint_set_t
    use voiga_linalg_lapack, only: solve_general, solve_least_squares
    use voiga_text, only: str, real_str
    implicit none
    private

    public :: tresca_fixed_point, frictional, substep_attempt

    !> Most Tresca solves (fixed-point iterations) of one retried substep.
    integer, parameter :: max_fixed_point = 40

    !> Most multiplier updates of one substep (augmented Lagrangian); the constraint
    !> error falls by a roughly constant factor per update, small for stiff penalties
    !> (docs/theory.md, section 7, "Augmented Lagrangian").
    integer, parameter :: max_updates = 100
    !> The smallest fraction of a multiplier step, and the updates without a new
    !> smallest constraint residual after which the step is halved
    !> (`substep_attempt`).
    real(dp), parameter :: min_damping = 1.0_dp/64.0_dp
    integer, parameter :: stall = 3
    !> An LU pivot of the constraints' Schur complement below this times the largest
    !> marks them dependent (`multiplier_step`); also the least-squares solve's cutoff.
    real(dp), parameter :: dependent_pivot = 1.0e-10_dp

contains

    !> Solve the substep of `ctx` from `u` (prescribed values set): Newton,
    !> inside the augmented Lagrangian's multiplier updates when a pair has
    !> multipliers: after each Newton solve, if a pair's constraints do not hold to its
    !> tolerance, the multipliers take a Newton step on the constraints
    !> (`multiplier_step`) and Newton solves again from the predicted state. A
    !> control point on the stick/slip limit can make full steps cycle between active
    !> sets: after `stall` updates without a new smallest constraint residual the
    !> steps are halved. Fails like a Newton attempt, or when `max_updates` updates do
    !> not satisfy the constraints.
    subroutine substep_attempt(newton, model, ctx, u, attempt, error)
        type(newton_t), intent(inout) :: newton
        type(model_t), intent(inout) :: model
        type(context_t), intent(inout) :: ctx
        real(dp), intent(inout) :: u(:)
        type(attempt_t), intent(out) :: attempt
        type(error_t), allocatable, intent(out) :: error
        type(attempt_t) :: inner
        real(dp) :: r0, worst, best, damping
        integer :: k, stalled
        logical :: satisfied

        if (.not. any([(model%pairs(k)%pair%has_multipliers(), k=1, size(model%pairs))])) then
            call newton_attempt(newton, model, ctx, u, attempt, error)
            return
        end if
        best = huge(1.0_dp)
        stalled = 0
        damping = 1.0_dp
        do k = 1, max_updates
            ! after the first solve, Newton's tolerance is relative to the substep's
            ! first residual (a multiplier update leaves a small one)
            if (k == 1) then
                call newton_attempt(newton, model, ctx, u, inner, error, keep_tangent=.true.)
            else
                call newton_attempt(newton, model, ctx, u, inner, error, r0, keep_tangent=.true.)
            end if
            attempt%iterations = attempt%iterations + inner%iterations
            attempt%residual = inner%residual
            ! a solve that starts converged (after a multiplier step) factorizes nothing:
            ! the sign is the last factorized tangent's
            if (inner%iterations > 0) attempt%det_sign = inner%det_sign
            attempt%nonpositive_det = attempt%nonpositive_det + inner%nonpositive_det
            attempt%switching = inner%switching
            if (allocated(error)) return
            if (k == 1) r0 = ctx%record%residual_norms(1)
            call constraint_test(model, satisfied, worst)
            call ctx%progress%multipliers_updated(ctx%step, k, worst)
            if (satisfied) return
            ! full steps (a semi-smooth Newton step may raise the residual while the
            ! active set settles); halved after `stall` updates without a new
            ! smallest residual (the active set cycles), doubled back with each one
            if (worst < best) then
                best = worst
                stalled = 0
                damping = min(1.0_dp, 2.0_dp*damping)
            else
                stalled = stalled + 1
                if (stalled >= stall) then
                    damping = max(0.5_dp*damping, min_damping)
                    stalled = 0
                end if
            end if
            call multiplier_step(newton, model, damping, u, ctx%record, error)
            ctx%stats%multiplier_updates = ctx%stats%multiplier_updates + 1
            if (allocated(error)) return
        end do
        call fatal_error(error, 'the augmented Lagrangian did not satisfy the contact constraints in '// &
                         str(max_updates)//' multiplier updates (largest gap or stick slip '// &
                         real_str(worst, 'es9.2')//' of the slave element size)', error_code%numeric)
    end subroutine substep_attempt

    !> Whether every pair's constraints hold at its last evaluation, and the largest
    !> constraint residual (relative to the slave element size).
    pure subroutine constraint_test(model, satisfied, worst)
        type(model_t), intent(in) :: model
        logical, intent(out) :: satisfied
        real(dp), intent(out) :: worst
        real(dp) :: residual
        logical :: ok
        integer :: ip
        satisfied = .true.
        worst = 0.0_dp
        do ip = 1, size(model%pairs)
            call model%pairs(ip)%pair%constraint_test(ok, residual)
            satisfied = satisfied .and. ok
            worst = max(worst, residual)
        end do
    end subroutine constraint_test

    !> A Newton step on the active constraints c(u(mu)) = 0 of every pair with
    !> multipliers mu, at the converged state `u` of fixed multipliers: with the
    !> tangent K there, a change dmu moves the equilibrium by du = -K^-1 C dmu (C: the
    !> columns d r / d mu) and the constraints by R du (R: their rows), so
    !> (R K^-1 C) dmu = c; `u` moves by du (the next Newton solve starts at the
    !> predicted equilibrium). Exact for a linear problem with a fixed active set,
    !> whatever the penalty. Costs one factorization and one solve per constraint.
    !> `damping` < 1 takes that fraction of the step. Dependent constraints (`dependent`)
    !> take the least-squares step of least norm (SVD): the multipliers' part that only
    !> loads fixed DOFs stays.
    subroutine multiplier_step(newton, model, damping, u, rec, error)
        type(newton_t), intent(inout) :: newton
        type(model_t), intent(inout) :: model
        !> The fraction of the step taken.
        real(dp), intent(in) :: damping
        real(dp), intent(inout) :: u(:)
        type(step_record_t), intent(inout) :: rec
        type(error_t), allocatable, intent(out) :: error
        type(constraint_set_t), allocatable :: sets(:)
        real(dp), allocatable :: w(:, :), s(:, :), delta(:, :), s_copy(:, :), c_copy(:, :)
        real(dp) :: tic
        integer :: ip, j, n, first, info, rank

        allocate (sets(size(model%pairs)))
        do ip = 1, size(model%pairs)
            sets(ip) = model%pairs(ip)%pair%constraints()
        end do
        n = sum([(size(sets(ip)%c), ip=1, size(sets))])
        allocate (w(model%ndof, n), s(n, n), delta(n, 1))
        if (n > 0) then
            tic = wall_seconds()
            call newton%k%fix_dofs(model%fixed)
            call newton%linear%factor(newton%k, error)
            rec%seconds(3) = rec%seconds(3) + wall_seconds() - tic
            if (allocated(error)) return
            tic = wall_seconds()
            call schur_complement(newton, model%fixed, sets, w, s, delta(:, 1), error)
            rec%seconds(4) = rec%seconds(4) + wall_seconds() - tic
            if (allocated(error)) return
            s_copy = s
            c_copy = delta
            call solve_general(s, delta, info)
            if (info /= 0 .or. dependent(s)) then
                call solve_least_squares(s_copy, c_copy, dependent_pivot, rank, info)
                if (info /= 0) then
                    call fatal_error(error, 'the augmented Lagrangian''s multiplier step failed (the SVD of the '// &
                                     'constraints'' Schur complement did not converge)', error_code%numeric)
                    return
                end if
                delta = c_copy
            end if
            delta = damping*delta
            u = u - matmul(w, delta(:, 1))
        end if
        first = 0
        do ip = 1, size(sets)
            call model%pairs(ip)%pair%update_multipliers(delta(first + 1:first + size(sets(ip)%c), 1))
            first = first + size(sets(ip)%c)
        end do
    end subroutine multiplier_step

    !> Whether the LU factors `lu` (of `solve_general`) have a pivot below
    !> `dependent_pivot` times the largest: the constraints are dependent. A solid's
    !> face held by a symmetry plane is one: the slips of its sticking control points
    !> along the plane's normal outnumber the face's DOFs free in that direction (those on
    !> the plane are fixed); they are consistent (they vanish together), but the LU's last
    !> pivots are round-off and its step is garbage (the box of test_contact3d.py pressed
    !> with mu = 2: 9 of 60 dependent).
    pure logical function dependent(lu)
        real(dp), intent(in) :: lu(:, :)
        real(dp) :: pivots(size(lu, 1))
        integer :: i
        pivots = [(abs(lu(i, i)), i=1, size(lu, 1))]
        dependent = minval(pivots) < dependent_pivot*maxval(pivots)
    end function dependent

    !> The constraints of `sets` in order: w(:, j) = K^-1 C_j (the factorized tangent),
    !> the Schur complement s = R K^-1 C and the residuals c.
    subroutine schur_complement(newton, fixed, sets, w, s, c, error)
        type(newton_t), intent(inout) :: newton
        logical, intent(in) :: fixed(:)
        type(constraint_set_t), intent(in) :: sets(:)
        real(dp), intent(out) :: w(:, :), s(:, :), c(:)
        type(error_t), allocatable, intent(out) :: error
        real(dp), allocatable :: rhs(:, :)
        integer :: ip, i, j
        allocate (rhs(size(fixed), size(w, 2)))
        j = 0
        do ip = 1, size(sets)
            do i = 1, size(sets(ip)%c)
                j = j + 1
                c(j) = sets(ip)%c(i)
                rhs(:, j) = 0.0_dp
                rhs(sets(ip)%cols(i)%dofs, j) = rhs(sets(ip)%cols(i)%dofs, j) + sets(ip)%cols(i)%values
                rhs(:, j) = merge(0.0_dp, rhs(:, j), fixed)
            end do
        end do
        ! all columns at once: a solver with a multi-column solve (bulk_update_t) uses it
        call newton%linear%solve_columns(newton%k, rhs, w, error)
        if (allocated(error)) return
        i = 0
        do ip = 1, size(sets)
            do j = 1, size(sets(ip)%c)
                i = i + 1
                s(i, :) = matmul(sets(ip)%rows(j)%values, w(sets(ip)%rows(j)%dofs, :))
            end do
        end do
    end subroutine schur_complement

    !> Whether any contact pair takes part in the Tresca fixed point (frictional GPTS).
    pure logical function frictional(model)
        type(model_t), intent(in) :: model
        integer :: ip
        frictional = any([(model%pairs(ip)%pair%takes_outer(), ip=1, size(model%pairs))])
    end function frictional

    !> Retry a frictional substep (`ctx`) by the Tresca fixed point. `u`
    !> holds the last converged state on entry, the accepted one on success; the
    !> contact pairs' trial history is then that of the Coulomb evaluation at it, and
    !> `attempt` holds the Newton iterations of all Tresca solves, the Coulomb
    !> residual and the sign of det K of the Coulomb tangent there. Fails (error code
    !> numeric) when a Tresca solve fails, the bound changes grow three times in a
    !> row, or after `max_fixed_point` solves.
    subroutine tresca_fixed_point(newton, model, ctx, u, attempt, error)
        type(newton_t), intent(inout) :: newton
        type(model_t), intent(inout) :: model
        type(context_t), intent(inout) :: ctx
        real(dp), intent(inout) :: u(:)
        type(attempt_t), intent(out) :: attempt
        type(error_t), allocatable, intent(out) :: error
        type(error_t), allocatable :: inner_error
        type(attempt_t) :: inner
        type(fixed_point_report_t) :: rep
        type(convergence_t) :: c
        real(dp) :: last_change, growth, log_det
        integer :: fp, growing
        logical :: accepted

        ctx%stats%tresca_retries = ctx%stats%tresca_retries + 1
        ! initial bounds: mu p_N at the last converged state (p_N depends on u only)
        call assemble(model, u, ctx%time, newton%r, ctx%stats%assembly, error)
        if (allocated(error)) return
        call capture_slip_bounds(model, rep%change, rep%largest)
        ! the reference of the convergence test: the Coulomb residual at the substep's
        ! start, the first residual of the plain Newton attempt that failed
        call set_prescribed(model, ctx%time, u)
        call assemble(model, u, ctx%time, newton%r, ctx%stats%assembly, error)
        if (allocated(error)) return
        c%first = norm2(merge(0.0_dp, newton%r, model%fixed))
        ! Newton's own tests, on the Coulomb residual, as after a Newton step
        c%iteration = 1
        rep%step = ctx%step
        rep%time = ctx%time
        rep%reference = c%first
        last_change = huge(1.0_dp)
        growing = 0
        growth = 0.0_dp
        accepted = .false.
        do fp = 1, max_fixed_point
            ctx%stats%fixed_point_iterations = ctx%stats%fixed_point_iterations + 1
            call apply_slip_bounds(model)
            call newton_attempt(newton, model, ctx, u, inner, inner_error, c%first)
            call release_slip_bounds(model)
            attempt%iterations = attempt%iterations + inner%iterations
            attempt%det_sign = inner%det_sign
            if (allocated(inner_error)) then
                if (ctx%stats%signal /= 0) then
                    call move_alloc(inner_error, error)
                    return
                end if
                call fatal_error(error, 'the Tresca problem of fixed-point iteration '//str(fp)//' failed: '// &
                                 inner_error%message, error_code%numeric)
                return
            end if
            ! the Coulomb residual and tangent at the Tresca solution, and the new bounds
            call assemble(model, u, ctx%time, newton%r, ctx%stats%assembly, error, newton%k, newton%map)
            if (allocated(error)) return
            c%residual = norm2(merge(0.0_dp, newton%r, model%fixed))
            c%floor = residual_floor(newton%k, newton%x0 + u, model%fixed)
            c%scale = max(c%first, ctx%stats%r0_max)
            attempt%residual = c%residual
            call capture_slip_bounds(model, rep%change, rep%largest)
            rep%iteration = fp
            rep%newton_iterations = inner%iterations
            rep%residual = c%residual
            call ctx%progress%fixed_point(rep)
            if (converged(c, newton%settings%tol_residual, newton%settings%tol_energy)) then
                accepted = .true.
                exit
            end if
            if (.not. ieee_is_finite(c%residual)) exit
            growing = merge(growing + 1, 0, rep%change > last_change)
            if (growing > 0) growth = max(growth, rep%change/last_change)
            if (growing == 0) growth = 0.0_dp
            if (growing >= 3) exit
            last_change = rep%change
        end do
        if (.not. accepted) then
            call not_converged_error(fp - merge(1, 0, fp > max_fixed_point), rep, growing >= 3, growth, error)
            return
        end if
        ! the orientation of the Coulomb tangent at the accepted state (a solver
        ! without determinant, multigrid, leaves the sign unknown)
        if (newton%linear%has_determinant()) then
            call newton%k%fix_dofs(model%fixed)
            call newton%linear%factor(newton%k, error)
            if (allocated(error)) return
            call newton%linear%determinant(attempt%det_sign, log_det, error)
            if (allocated(error)) return
        end if
        ctx%stats%tresca_accepted = ctx%stats%tresca_accepted + 1
        rep%iteration = fp
        rep%newton_iterations = attempt%iterations
        rep%floor = c%floor
        rep%scale = c%scale
        rep%det_sign = attempt%det_sign
        call ctx%progress%fixed_point_done(rep)
    end subroutine tresca_fixed_point

    !> Why the fixed point ended without converging after `n` iterations.
    pure subroutine not_converged_error(n, rep, diverging, growth, error)
        integer, intent(in) :: n
        type(fixed_point_report_t), intent(in) :: rep
        logical, intent(in) :: diverging
        real(dp), intent(in) :: growth
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: msg
        msg = 'the fixed point did not converge in '//str(n)//' iterations (Coulomb residual '// &
              real_str(rep%residual, 'es9.2')//', reference '//real_str(rep%reference, 'es9.2')// &
              '; last bound change '//real_str(rep%change, 'es9.2')//' of max bound '// &
              real_str(rep%largest, 'es9.2')//')'
        if (diverging) then
            msg = msg//': the successive approximations diverge (the bound change grew in 3 iterations in '// &
                  'a row, by up to '//real_str(growth, 'f0.2')//' per iteration): the map g -> mu p_N(g) is '// &
                  'not a contraction here'
            call fatal_error(error, msg//', the condition under which the existence theory of '// &
                             'quasi-static Coulomb friction guarantees a unique incremental solution '// &
                             '(small mu); a Coulomb solution may not exist near this state', &
                             error_code%numeric)
        else
            call fatal_error(error, msg//': the Coulomb incremental problem may have no '// &
                             'solution near this state', error_code%numeric)
        end if
    end subroutine not_converged_error

    !> Every frictional pair captures the slip bounds mu p_N of its last evaluation;
    !> the largest change from the previous capture and the largest bound.
    pure subroutine capture_slip_bounds(model, change, largest)
        type(model_t), intent(inout) :: model
        real(dp), intent(out) :: change, largest
        real(dp) :: c, g
        integer :: ip
        change = -huge(1.0_dp)
        largest = -huge(1.0_dp)
        do ip = 1, size(model%pairs)
            if (.not. model%pairs(ip)%pair%takes_outer()) cycle
            call model%pairs(ip)%pair%outer_capture(c, g)
            change = max(change, c)
            largest = max(largest, g)
        end do
    end subroutine capture_slip_bounds

    !> Put every frictional pair in Tresca mode with its captured bounds.
    pure subroutine apply_slip_bounds(model)
        type(model_t), intent(inout) :: model
        integer :: ip
        do ip = 1, size(model%pairs)
            if (model%pairs(ip)%pair%takes_outer()) call model%pairs(ip)%pair%outer_apply()
        end do
    end subroutine apply_slip_bounds

    !> Back to Coulomb friction in every pair.
    pure subroutine release_slip_bounds(model)
        type(model_t), intent(inout) :: model
        integer :: ip
        do ip = 1, size(model%pairs)
            call model%pairs(ip)%pair%outer_release()
        end do
    end subroutine release_slip_bounds

end module voiga_solver_outer
