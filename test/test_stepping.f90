!> Adaptive load stepping (docs/robustness.md): a step that fails at full size is
!> cut and converges to the same state as many small nominal steps; the
!> increment grows back to the nominal step; the minimum increment ends the run
!> with a numerical error; max_cuts = 0 is the old behaviour.
module test_stepping
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, error_code
    use voiga_testdrive, only: unittest_t, new_unittest, check
    use voiga_discretization_layout, only: layout_t
    use voiga_discretization_patch, only: discretization_t, new_discretization
    use voiga_model, only: model_t
    use voiga_model_loads, only: dirichlet_settings_t
    use voiga_solver_settings, only: solver_settings_t
    use voiga_solver_records, only: solver_stats_t
    use voiga_solver_stepping, only: solve_steps
    use voiga_solver_progress, only: progress_t, iteration_report_t, step_report_t
    use voiga_solver_records, only: cut_record_t
    use voiga_test_fixtures, only: rectangle, scene_t, scene_model
    implicit none
    private

    public :: collect_stepping

    !> Counts what the solver reports.
    type, extends(progress_t) :: tally_t
        integer :: iterations = 0, cuts = 0, steps = 0, last_step = 0
        real(dp), allocatable :: u_last(:)
    contains
        procedure :: iteration => tally_iteration
        procedure :: cut => tally_cut
        procedure :: step_done => tally_step_done
    end type tally_t

contains

    subroutine collect_stepping(testsuite)
        type(unittest_t), allocatable, intent(out) :: testsuite(:)
        testsuite = [ &
                    new_unittest('cut_step_converges_to_fine_path', test_cut_converges), &
                    new_unittest('increment_grows_back_to_nominal', test_growth), &
                    new_unittest('minimum_increment_fails_cleanly', test_minimum), &
                    new_unittest('no_cuts_fails_at_full_step', test_no_cuts), &
                    new_unittest('predictor_same_states_fewer_iterations', test_predictor), &
                    new_unittest('progress_reports_every_step', test_progress) &
                    ]
    end subroutine collect_stepping

    !> Unit Neo-Hookean block (N2, 4 x 4 elements), bottom clamped, top pushed down
    !> by `squeeze` per phase (x held), `n` nominal steps per phase.
    subroutine block_model(squeeze, n, model, settings, error)
        real(dp), intent(in) :: squeeze(:)
        integer, intent(in) :: n(:)
        type(model_t), intent(out) :: model
        type(solver_settings_t), intent(out) :: settings
        type(error_t), allocatable, intent(out) :: error
        type(scene_t) :: c
        type(discretization_t) :: discs(1)
        type(layout_t) :: layout
        real(dp), allocatable :: top(:, :)
        allocate (c%bodies(1))
        c%bodies(1)%name = 'block'
        c%bodies(1)%material = 'neo-hookean'
        c%bodies(1)%youngs_modulus = 1.0_dp
        c%bodies(1)%poisson_ratio = 0.3_dp
        layout%nel(:2) = [4, 4]
        layout%degree(:2) = [2, 2]
        layout%contact_edge = 'top'
        c%bodies(1)%layout = layout
        c%solver%n_steps = n
        allocate (c%pressure(0), c%contact(0), top(2, size(squeeze)))
        top(1, :) = 0.0_dp
        top(2, :) = -squeeze
        c%dirichlet = [dirichlet_settings_t(body='block', edge='bottom', fix=[.true., .true., .false.], &
                                            values=0.0_dp*top), &
                       dirichlet_settings_t(body='block', edge='top', fix=[.true., .true., .false.], values=top)]
        settings = c%solver
        call new_discretization(discs(1), rectangle(0.0_dp, 0.0_dp, 1.0_dp, 1.0_dp), layout, '', error)
        if (allocated(error)) return
        call scene_model(c, discs, model, error)
    end subroutine block_model

    !> 60 % compression in one step fails at full size (max_cuts = 0 fails, see
    !> test_no_cuts); the cut solve reaches the same equilibrium as 32 nominal steps.
    subroutine test_cut_converges(error)
        type(error_t), allocatable, intent(out) :: error
        type(model_t) :: model
        type(solver_settings_t) :: settings
        type(solver_stats_t) :: stats
        real(dp), allocatable :: u1(:), u32(:)
        call block_model([0.6_dp], [1], model, settings, error)
        if (allocated(error)) return
        call solve_steps(model, settings, u1, stats, error)
        if (allocated(error)) return
        call check(error, stats%steps, 1, 'the one nominal step converged')
        if (allocated(error)) return
        call check(error, stats%cuts > 0, 'the step was cut')
        if (allocated(error)) return
        call check(error, size(stats%cut_records), stats%cuts, 'every cut recorded')
        if (allocated(error)) return
        call check(error, stats%records(1)%cuts, stats%cuts, 'the cuts counted on the step')
        if (allocated(error)) return
        call check(error, stats%records(1)%substeps > 1, 'substeps taken')
        if (allocated(error)) return
        call check(error, stats%cut_records(1)%new_fraction, 0.5_dp, 'the first cut halves the step')
        if (allocated(error)) return
        call check(error, stats%records(1)%time, 1.0_dp, 'the nominal step is hit exactly')
        if (allocated(error)) return
        call block_model([0.6_dp], [32], model, settings, error)
        if (allocated(error)) return
        call solve_steps(model, settings, u32, stats, error)
        if (allocated(error)) return
        call check(error, stats%cuts, 0, '32 small steps need no cut')
        if (allocated(error)) return
        ! hyperelastic, no history: one equilibrium; both solves end at round-off
        ! (|r| <= 1e-10 |r_0|), u is O(1)
        call check(error, maxval(abs(u1 - u32)), 0.0_dp, 'same final state as 32 steps', abs=1.0e-8_dp)
    end subroutine test_cut_converges

    !> Phase 1 needs cuts; the easy steps of phase 2 are taken whole again.
    subroutine test_growth(error)
        type(error_t), allocatable, intent(out) :: error
        type(model_t) :: model
        type(solver_settings_t) :: settings
        type(solver_stats_t) :: stats
        real(dp), allocatable :: u(:)
        integer :: k
        call block_model([0.6_dp, 0.62_dp], [1, 4], model, settings, error)
        if (allocated(error)) return
        call solve_steps(model, settings, u, stats, error)
        if (allocated(error)) return
        call check(error, stats%steps, 5, 'all steps converged')
        if (allocated(error)) return
        call check(error, stats%records(1)%cuts > 0, 'step 1 was cut')
        if (allocated(error)) return
        do k = 2, 5
            call check(error, stats%records(k)%cuts, 0, 'no cut in phase 2')
            if (allocated(error)) return
        end do
        call check(error, stats%records(5)%substeps, 1, 'the last step is taken whole')
        if (allocated(error)) return
        call check(error, stats%substeps, sum(stats%records%substeps), 'substeps add up')
        if (allocated(error)) return
        call check(error, stats%records(5)%time, 2.0_dp, 'the phase end is hit exactly')
    end subroutine test_growth

    !> With min_step_fraction = 0.5 one cut is allowed, the second would go below:
    !> a numerical error naming the step, no step converged.
    subroutine test_minimum(error)
        type(error_t), allocatable, intent(out) :: error
        type(model_t) :: model
        type(solver_settings_t) :: settings
        type(solver_stats_t) :: stats
        real(dp), allocatable :: u(:)
        type(error_t), allocatable :: run_error
        call block_model([0.6_dp], [1], model, settings, error)
        if (allocated(error)) return
        settings%min_step_fraction = 0.5_dp
        call solve_steps(model, settings, u, stats, run_error)
        call check(error, allocated(run_error), 'the run failed')
        if (allocated(error)) return
        call check(error, run_error%code, error_code%numeric, 'a numerical failure (exit code 3)')
        if (allocated(error)) return
        call check(error, index(run_error%message, 'step 1 ') == 1, 'message names the step: '//run_error%message)
        if (allocated(error)) return
        call check(error, index(run_error%message, 'minimum') > 0, 'message names the minimum: '//run_error%message)
        if (allocated(error)) return
        call check(error, stats%steps, 0, 'no step converged')
        if (allocated(error)) return
        call check(error, stats%cuts, 1, 'one cut, to the minimum')
        if (allocated(error)) return
        call check(error, maxval(abs(u)), 0.0_dp, 'u is the last converged state (zero)')
    end subroutine test_minimum

    !> max_cuts = 0: the first failure fails the run, as without adaptive stepping.
    subroutine test_no_cuts(error)
        type(error_t), allocatable, intent(out) :: error
        type(model_t) :: model
        type(solver_settings_t) :: settings
        type(solver_stats_t) :: stats
        real(dp), allocatable :: u(:)
        type(error_t), allocatable :: run_error
        call block_model([0.6_dp], [1], model, settings, error)
        if (allocated(error)) return
        settings%max_cuts = 0
        call solve_steps(model, settings, u, stats, run_error)
        call check(error, allocated(run_error), 'the run failed')
        if (allocated(error)) return
        call check(error, run_error%code, error_code%numeric, 'a numerical failure')
        if (allocated(error)) return
        call check(error, stats%cuts, 0, 'no cut')
    end subroutine test_no_cuts

    !> The predictor (last step's increment, extrapolated within a phase) reaches
    !> the same states as starting each step from the last one, in fewer Newton
    !> iterations; it is not used across a phase change.
    subroutine test_predictor(error)
        type(error_t), allocatable, intent(out) :: error
        type(model_t) :: model
        type(solver_settings_t) :: settings
        type(solver_stats_t) :: on, off
        real(dp), allocatable :: u_on(:), u_off(:)
        integer :: k
        call block_model([0.3_dp, 0.0_dp], [10, 10], model, settings, error)
        if (allocated(error)) return
        settings%predictor = .false.
        call solve_steps(model, settings, u_off, off, error)
        if (allocated(error)) return
        call block_model([0.3_dp, 0.0_dp], [10, 10], model, settings, error)
        if (allocated(error)) return
        call solve_steps(model, settings, u_on, on, error)
        if (allocated(error)) return
        call check(error, maxval(abs(u_on - u_off)), 0.0_dp, 'same final state', abs=1.0e-8_dp)
        if (allocated(error)) return
        call check(error, sum(on%records%iterations) < sum(off%records%iterations), &
                   'fewer iterations with the predictor')
        if (allocated(error)) return
        ! steps 1 and 11 start a phase: no increment to extrapolate, same first residual
        do k = 1, 11, 10
            call check(error, on%records(k)%iterations, off%records(k)%iterations, &
                       'phase start: no prediction')
            if (allocated(error)) return
        end do
    end subroutine test_predictor

    !> The solver reports every accepted iterate, cut and converged step through the
    !> progress hooks, in step order, with the converged displacement.
    subroutine test_progress(error)
        type(error_t), allocatable, intent(out) :: error
        type(model_t) :: model
        type(solver_settings_t) :: settings
        type(solver_stats_t) :: stats
        type(tally_t) :: tally
        real(dp), allocatable :: u(:)
        call block_model([0.6_dp, 0.62_dp], [1, 4], model, settings, error)
        if (allocated(error)) return
        call solve_steps(model, settings, u, stats, error, tally)
        if (allocated(error)) return
        call check(error, tally%steps, 5, 'every step reported')
        if (allocated(error)) return
        call check(error, tally%last_step, 5, 'in order, the last one last')
        if (allocated(error)) return
        call check(error, tally%cuts, stats%cuts, 'every cut reported')
        if (allocated(error)) return
        call check(error, tally%cuts > 0, 'there were cuts')
        if (allocated(error)) return
        ! an accepted iterate is reported before its convergence test: iterations + 1
        ! per converged attempt, iterations + 1 for a failed one that reached the cap
        call check(error, tally%iterations >= stats%iterations, 'every iteration reported')
        if (allocated(error)) return
        call check(error, maxval(abs(tally%u_last - u)), 0.0_dp, 'the converged displacement reported')
    end subroutine test_progress

    subroutine tally_iteration(self, report)
        class(tally_t), intent(inout) :: self
        type(iteration_report_t), intent(in) :: report
        self%iterations = self%iterations + 1
    end subroutine tally_iteration

    subroutine tally_cut(self, cut, reason)
        class(tally_t), intent(inout) :: self
        type(cut_record_t), intent(in) :: cut
        character(len=*), intent(in) :: reason
        if (len(reason) > 0 .and. cut%step > 0) self%cuts = self%cuts + 1
    end subroutine tally_cut

    subroutine tally_step_done(self, report, u, model, error)
        class(tally_t), intent(inout) :: self
        type(step_report_t), intent(in) :: report
        real(dp), intent(in) :: u(:)
        type(model_t), intent(in) :: model
        type(error_t), allocatable, intent(out) :: error
        self%steps = self%steps + 1
        if (report%record%step /= self%last_step + 1) return
        self%last_step = report%record%step
        if (model%ndof == size(u)) self%u_last = u
    end subroutine tally_step_done

end module test_stepping
