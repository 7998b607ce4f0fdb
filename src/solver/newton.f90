!> Quasi-static load stepping with Newton-Raphson.
!>
!> Per step: prescribed displacements are set to their values at the step's load
!> time, then Newton iterates K du = -r on the free DOFs (the prescribed DOFs are
!> eliminated symmetrically, their corrections are zero) until
!> ||r|| <= tol_residual ||r_0|| or |du.r| <= tol_energy |du_1.r_0|, with r_0 the
!> step's first residual, or until max_iterations (then the run fails).
module voiga_solver_newton
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use voiga_kinds, only: dp, i8
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_model, only: model_t, phase_value, step_time, n_total_steps
    use voiga_model_assembly, only: assembly_stats_t, assemble, stiffness_pattern, assembly_map_t, &
                                    new_assembly_map
    use voiga_solver_sparse, only: csc_matrix_t
    use voiga_solver_umfpack, only: umfpack_t
    use voiga_io_results, only: results_t, step_record_t
    use voiga_contact_pair, only: pair_commit, pair_reset_trial
    implicit none
    private

    public :: solve_steps, solver_stats_t, wall_seconds

    !> Most halvings of one Newton step.
    integer, parameter :: max_line_search = 8

    !> Counters of a run.
    type :: solver_stats_t
        type(assembly_stats_t) :: assembly
        integer :: steps = 0, iterations = 0
        integer :: symbolic_factorizations = 0, numeric_factorizations = 0
        !> Residual evaluations spent on halving Newton steps.
        integer :: line_search_steps = 0
        !> The record of every converged step (residual and energy norms, reactions, seconds).
        type(step_record_t), allocatable :: records(:)
    end type solver_stats_t

contains

    !> Wall-clock seconds since an arbitrary origin.
    real(dp) function wall_seconds()
        integer(i8) :: count, rate
        call system_clock(count, rate)
        wall_seconds = real(count, dp)/real(rate, dp)
    end function wall_seconds

    !> Run every load step of `model` from zero displacement; write each converged
    !> step to `results` (if present) and report progress unless `quiet`.
    !> `u` holds the last converged displacement on return (also on failure).
    subroutine solve_steps(model, u, stats, quiet, error, results, t0, verbose)
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
        type(csc_matrix_t) :: k
        type(assembly_map_t) :: map
        type(umfpack_t) :: lu
        type(step_record_t) :: rec
        real(dp), allocatable :: r(:), du(:), u_conv(:), norms(:), energies(:), rhs(:)
        real(dp) :: t, r0, rn, e1, en, tic, start, bulk0, contact0, alpha, rn_prev
        real(dp), allocatable :: u_prev(:)
        integer :: step, it, nsteps, j, c, ip, nls
        logical :: converged
        character(len=160) :: msg

        start = wall_seconds()
        if (present(t0)) start = t0
        call stiffness_pattern(model, k, error)
        if (allocated(error)) return
        call new_assembly_map(model, k, map)
        allocate (u(model%ndof), r(model%ndof), du(model%ndof), rhs(model%ndof))
        u = 0.0_dp
        u_conv = u
        nsteps = n_total_steps(model)
        allocate (norms(model%max_iterations + 1), energies(model%max_iterations))
        allocate (stats%records(0))
        do step = 1, nsteps
            t = step_time(model, step)
            rec = step_record_t()
            rec%step = step
            rec%time = t
            call set_prescribed(model, t, u)
            converged = .false.
            r0 = 0.0_dp
            e1 = 0.0_dp
            en = huge(1.0_dp)
            it = 0
            nls = 0
            alpha = 1.0_dp
            rn_prev = huge(1.0_dp)
            do
                bulk0 = stats%assembly%seconds_bulk
                contact0 = stats%assembly%seconds_contact
                call assemble(model, u, t, r, stats%assembly, error, k, map)
                rec%seconds(1) = rec%seconds(1) + stats%assembly%seconds_bulk - bulk0
                rec%seconds(2) = rec%seconds(2) + stats%assembly%seconds_contact - contact0
                if (allocated(error)) exit
                rn = norm2(merge(0.0_dp, r, model%fixed))
                if (.not. ieee_is_finite(rn)) then
                    call fatal_error(error, 'the residual is not finite', error_code%numeric)
                    exit
                end if
                ! backtracking: a Newton step that increases the residual is halved
                ! (contact stick/slip and active-set changes can make full steps cycle)
                if (it > 0 .and. rn > rn_prev .and. nls < max_line_search .and. &
                    rn > 1.0e4_dp*epsilon(1.0_dp)*max(r0, norm2(r))) then
                    nls = nls + 1
                    stats%line_search_steps = stats%line_search_steps + 1
                    alpha = 0.5_dp*alpha
                    u = u_prev + alpha*du
                    cycle
                end if
                norms(it + 1) = rn
                if (it == 0) r0 = rn
                if (present(verbose)) then
                    if (verbose) call print_iteration(model, step, it, rn, en, alpha)
                end if
                if (rn <= model%tol_residual*r0 .or. rn == 0.0_dp) converged = .true.
                if (it > 1 .and. en <= model%tol_energy*e1) converged = .true.
                ! round-off floor: nothing left to gain relative to the forces in play
                if (rn <= 1.0e4_dp*epsilon(1.0_dp)*max(r0, norm2(r))) converged = .true.
                if (converged) exit
                if (it == model%max_iterations) exit
                tic = wall_seconds()
                call k%fix_dofs(model%fixed)
                call lu%factorize(k, error)
                rec%seconds(3) = rec%seconds(3) + wall_seconds() - tic
                if (allocated(error)) exit
                tic = wall_seconds()
                rhs = -merge(0.0_dp, r, model%fixed)
                call lu%solve(k, rhs, du, error)
                rec%seconds(4) = rec%seconds(4) + wall_seconds() - tic
                if (allocated(error)) exit
                en = abs(dot_product(du, rhs))
                if (it == 0) e1 = en
                energies(it + 1) = en
                u_prev = u
                rn_prev = rn
                alpha = 1.0_dp
                nls = 0
                u = u + du
                it = it + 1
            end do
            stats%iterations = stats%iterations + it
            if (.not. allocated(error) .and. .not. converged) then
                write (msg, '(a,i0,a,i0,a,es9.2,a,es9.2)') 'step ', step, ': Newton did not converge in ', &
                    model%max_iterations, ' iterations (residual ', rn, ', first ', r0
                call fatal_error(error, trim(msg)//')', error_code%numeric)
            end if
            if (allocated(error)) then
                write (msg, '(a,i0,a,es12.5,a)') 'step ', step, ' (load time ', t, '): '
                error%message = trim(msg)//' '//error%message
                u = u_conv
                do ip = 1, size(model%pairs)
                    call pair_reset_trial(model%pairs(ip))
                end do
                exit
            end if
            u_conv = u
            do ip = 1, size(model%pairs)
                call pair_commit(model%pairs(ip))
            end do
            stats%steps = step
            rec%iterations = it
            rec%residual_norms = norms(1:it + 1)
            rec%energy_norms = energies(1:it)
            allocate (rec%reactions(2, size(model%dirichlet)))
            do j = 1, size(model%dirichlet)
                do c = 1, 2
                    rec%reactions(c, j) = sum(r(model%dirichlet(j)%dofs(c, :)))
                end do
            end do
            stats%records = [stats%records, rec]
            if (present(results)) then
                tic = wall_seconds()
                call results%write_step(rec, u, wall_seconds() - start, model%pairs)
                rec%seconds(5) = wall_seconds() - tic
            end if
            if (.not. quiet) then
                write (*, '(a,i0,a,i0,a,f8.4,a,i2,a,es9.2,a,f8.3,a)') 'step ', step, '/', nsteps, &
                    '  t=', t, '  it=', it, '  |r|=', rn, '  ', sum(rec%seconds), ' s'
            end if
        end do
        stats%symbolic_factorizations = lu%n_symbolic
        stats%numeric_factorizations = lu%n_numeric
    end subroutine solve_steps

    !> One line per Newton iteration: residual, energy norm, contact states.
    subroutine print_iteration(model, step, it, rn, en, alpha)
        type(model_t), intent(in) :: model
        integer, intent(in) :: step, it
        real(dp), intent(in) :: rn, en, alpha
        integer :: ip
        write (*, '(a,i0,a,i0,a,es10.3,a,es10.3,a,f6.4)', advance='no') '  step ', step, ' it ', it, &
            '  |r|=', rn, '  |du.r|=', merge(en, 0.0_dp, it > 0), '  step length ', alpha
        do ip = 1, size(model%pairs)
            write (*, '(a,i0,a,i0,a,i0)', advance='no') '  stick=', count(model%pairs(ip)%out%state == 1), &
                ' slip=', count(model%pairs(ip)%out%state == 2), ' of ', size(model%pairs(ip)%out)
        end do
        write (*, '(a)') ''
    end subroutine print_iteration

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
