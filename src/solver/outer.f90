!> Outer loops around Newton. The Tresca fixed point (docs/robustness.md, "Tresca
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
    use voiga_solver_records, only: solver_stats_t, step_record_t
    use voiga_solver_progress, only: progress_t, fixed_point_report_t
    use voiga_solver_convergence, only: convergence_t, converged, residual_floor
    use voiga_solver_newton, only: newton_t, newton_attempt, attempt_t
    use voiga_text, only: str, real_str
    implicit none
    private

    public :: tresca_fixed_point, frictional

    !> Most Tresca solves (fixed-point iterations) of one retried substep.
    integer, parameter :: max_fixed_point = 40

contains

    !> Whether any contact pair takes part in the Tresca fixed point (frictional GPTS).
    pure logical function frictional(model)
        type(model_t), intent(in) :: model
        integer :: ip
        frictional = any([(model%pairs(ip)%pair%takes_outer(), ip=1, size(model%pairs))])
    end function frictional

    !> Retry a frictional substep at load time `t` by the Tresca fixed point. `u`
    !> holds the last converged state on entry, the accepted one on success; the
    !> contact pairs' trial history is then that of the Coulomb evaluation at it, and
    !> `attempt` holds the Newton iterations of all Tresca solves, the Coulomb
    !> residual and the sign of det K of the Coulomb tangent there. Fails (error code
    !> numeric) when a Tresca solve fails, the bound changes grow three times in a
    !> row, or after `max_fixed_point` solves.
    subroutine tresca_fixed_point(newton, model, step, t, u, stats, rec, progress, attempt, error)
        type(newton_t), intent(inout) :: newton
        type(model_t), intent(inout) :: model
        integer, intent(in) :: step
        real(dp), intent(in) :: t
        real(dp), intent(inout) :: u(:)
        type(solver_stats_t), intent(inout) :: stats
        type(step_record_t), intent(inout) :: rec
        class(progress_t), intent(inout) :: progress
        type(attempt_t), intent(out) :: attempt
        type(error_t), allocatable, intent(out) :: error
        type(error_t), allocatable :: inner_error
        type(attempt_t) :: inner
        type(fixed_point_report_t) :: rep
        type(convergence_t) :: c
        real(dp) :: last_change, growth, log_det
        integer :: fp, growing
        logical :: accepted

        stats%tresca_retries = stats%tresca_retries + 1
        ! initial bounds: mu p_N at the last converged state (p_N depends on u only)
        call assemble(model, u, t, newton%r, stats%assembly, error)
        if (allocated(error)) return
        call capture_slip_bounds(model, rep%change, rep%largest)
        ! the reference of the convergence test: the Coulomb residual at the substep's
        ! start, the first residual of the plain Newton attempt that failed
        call set_prescribed(model, t, u)
        call assemble(model, u, t, newton%r, stats%assembly, error)
        if (allocated(error)) return
        c%first = norm2(merge(0.0_dp, newton%r, model%fixed))
        ! Newton's own tests, on the Coulomb residual, as after a Newton step
        c%iteration = 1
        rep%step = step
        rep%time = t
        rep%reference = c%first
        last_change = huge(1.0_dp)
        growing = 0
        growth = 0.0_dp
        accepted = .false.
        do fp = 1, max_fixed_point
            stats%fixed_point_iterations = stats%fixed_point_iterations + 1
            call apply_slip_bounds(model)
            call newton_attempt(newton, model, step, t, u, stats, rec, progress, inner, inner_error, c%first)
            call release_slip_bounds(model)
            attempt%iterations = attempt%iterations + inner%iterations
            attempt%det_sign = inner%det_sign
            if (allocated(inner_error)) then
                if (stats%signal /= 0) then
                    call move_alloc(inner_error, error)
                    return
                end if
                call fatal_error(error, 'the Tresca problem of fixed-point iteration '//str(fp)//' failed: '// &
                                 inner_error%message, error_code%numeric)
                return
            end if
            ! the Coulomb residual and tangent at the Tresca solution, and the new bounds
            call assemble(model, u, t, newton%r, stats%assembly, error, newton%k, newton%map)
            if (allocated(error)) return
            c%residual = norm2(merge(0.0_dp, newton%r, model%fixed))
            c%floor = residual_floor(newton%k, newton%x0 + u, model%fixed)
            c%scale = max(c%first, stats%r0_max)
            attempt%residual = c%residual
            call capture_slip_bounds(model, rep%change, rep%largest)
            rep%iteration = fp
            rep%newton_iterations = inner%iterations
            rep%residual = c%residual
            call progress%fixed_point(rep)
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
        stats%tresca_accepted = stats%tresca_accepted + 1
        rep%iteration = fp
        rep%newton_iterations = attempt%iterations
        rep%floor = c%floor
        rep%scale = c%scale
        rep%det_sign = attempt%det_sign
        call progress%fixed_point_done(rep)
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
