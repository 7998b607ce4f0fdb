!> A Newton attempt evaluates an iterate it expects to be the converged one without
!> its tangent (`voiga_solver_newton`): the attempt must reach the same iterates,
!> bit for bit, as one that assembles every tangent, and a caller that keeps the
!> tangent (the augmented Lagrangian's multiplier step) must get the converged one.
module test_newton
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_testdrive, only: unittest_t, new_unittest, check
    use voiga_model, only: model_t, set_prescribed
    use voiga_model_assembly, only: assemble, assembly_stats_t
    use voiga_linalg_sparse, only: csc_matrix_t
    use voiga_solver_records, only: solver_stats_t
    use voiga_solver_context, only: context_t
    use voiga_solver_stepping, only: solve_steps
    use voiga_solver_newton, only: newton_t, new_newton, newton_attempt, attempt_t
    use voiga_solver_progress, only: progress_t, iteration_report_t
    use voiga_test_fixtures, only: scene_t, lcg_t
    use test_contact, only: small_ironing
    implicit none
    private

    public :: collect_newton

    !> The round-off floor each iteration reported (negative: not computed, the
    !> iterate was evaluated without its tangent).
    type, extends(progress_t) :: floors_t
        real(dp), allocatable :: floor(:)
    contains
        procedure :: iteration => floors_iteration
    end type floors_t

    !> One attempt's outcome.
    type :: outcome_t
        real(dp), allocatable :: u(:)
        integer :: iterations = 0
        type(floors_t) :: floors
        type(newton_t) :: newton
        type(model_t) :: model
    end type outcome_t

contains

    subroutine collect_newton(testsuite)
        type(unittest_t), allocatable, intent(out) :: testsuite(:)
        testsuite = [ &
                    new_unittest('converged_iterate_without_tangent_gpts', test_without_tangent_gpts), &
                    new_unittest('converged_iterate_without_tangent_mortar', test_without_tangent_mortar), &
                    new_unittest('kept_tangent_is_the_converged_ones', test_kept_tangent) &
                    ]
    end subroutine collect_newton

    subroutine test_without_tangent_gpts(error)
        type(error_t), allocatable, intent(out) :: error
        call without_tangent('gpts', error)
    end subroutine test_without_tangent_gpts

    subroutine test_without_tangent_mortar(error)
        type(error_t), allocatable, intent(out) :: error
        call without_tangent('mortar', error)
    end subroutine test_without_tangent_mortar

    !> From a perturbed sliding state of the small ironing scene, an attempt that
    !> keeps the tangent and one that need not: the same number of iterations and
    !> the same displacements, residual and contact state bit for bit; only the second skips
    !> the tangent of its last iterate.
    subroutine without_tangent(method, error)
        character(len=*), intent(in) :: method
        type(error_t), allocatable, intent(out) :: error
        type(outcome_t) :: kept, lazy
        integer :: n
        call attempts(method, kept, lazy, error)
        if (allocated(error)) return
        n = kept%iterations
        call check(error, n >= 3 .and. lazy%iterations == n, method//': the same iterations (3 or more)')
        if (allocated(error)) return
        call check(error, all(kept%floors%floor >= 0.0_dp), method//': every iterate''s floor with the tangent kept')
        if (allocated(error)) return
        call check(error, lazy%floors%floor(n + 1) < 0.0_dp .and. all(lazy%floors%floor(1:n) >= 0.0_dp), &
                   method//': the converged iterate alone evaluated without its tangent')
        if (allocated(error)) return
        call check(error, all(kept%u == lazy%u), method//': the same displacements, bit for bit')
        if (allocated(error)) return
        ! the residual at the converged iterate gives the reactions and the contact force
        call check(error, all(kept%newton%r == lazy%newton%r), method//': the same residual, bit for bit')
        if (allocated(error)) return
        associate (a => kept%model%pairs(1)%pair%out, b => lazy%model%pairs(1)%pair%out)
            call check(error, all(a%state == b%state) .and. all(a%pn == b%pn) .and. all(a%pt == b%pt) .and. &
                       all(a%xi_m == b%xi_m), method//': the same contact states, pressures and projections')
        end associate
    end subroutine without_tangent

    !> With `keep_tangent` the attempt leaves the tangent of its converged iterate
    !> in `newton%k` (the multiplier step solves with it): equal to one assembled
    !> afresh there, to the rounding of the contact projections' last digits.
    subroutine test_kept_tangent(error)
        type(error_t), allocatable, intent(out) :: error
        type(outcome_t) :: kept, lazy
        type(csc_matrix_t) :: k
        type(assembly_stats_t) :: as
        real(dp), allocatable :: r(:)
        real(dp) :: t
        call attempts('gpts', kept, lazy, error, t)
        if (allocated(error)) return
        k = kept%newton%k
        allocate (r(size(kept%u)))
        call assemble(kept%model, kept%u, t, r, as, error, k, kept%newton%map)
        if (allocated(error)) return
        call check(error, maxval(abs(k%values - kept%newton%k%values)) <= 1.0e-10_dp*maxval(abs(k%values)), &
                   'the kept tangent is the converged iterate''s')
    end subroutine test_kept_tangent

    !> The small ironing scene solved to its end, its free displacements perturbed
    !> by up to 1e-3, and one Newton attempt from there at the last load time with
    !> the tangent kept (`kept`) and one without (`lazy`), each on its own copy.
    subroutine attempts(method, kept, lazy, error, t_end)
        character(len=*), intent(in) :: method
        type(outcome_t), intent(out) :: kept, lazy
        type(error_t), allocatable, intent(out) :: error
        real(dp), intent(out), optional :: t_end
        type(scene_t) :: c
        type(model_t) :: model
        type(solver_stats_t) :: stats
        type(lcg_t) :: rng
        real(dp), allocatable :: u(:)
        real(dp) :: t
        integer :: j
        call small_ironing(method, c, model, error)
        if (allocated(error)) return
        call solve_steps(model, c%solver, u, stats, error)
        if (allocated(error)) return
        t = stats%records(size(stats%records))%time
        if (present(t_end)) t_end = t
        do j = 1, size(u)
            if (.not. model%fixed(j)) u(j) = u(j) + 1.0e-3_dp*(rng%uniform() - 0.5_dp)
        end do
        call set_prescribed(model, t, u)
        call one_attempt(model, c, t, u, .true., kept, error)
        if (allocated(error)) return
        call one_attempt(model, c, t, u, .false., lazy, error)
    end subroutine attempts

    subroutine one_attempt(model, c, t, u, keep, out, error)
        type(model_t), intent(in) :: model
        type(scene_t), intent(in) :: c
        real(dp), intent(in) :: t, u(:)
        logical, intent(in) :: keep
        type(outcome_t), intent(inout), target :: out
        type(error_t), allocatable, intent(out) :: error
        type(context_t) :: ctx
        type(attempt_t) :: attempt
        out%model = model
        out%u = u
        allocate (out%floors%floor(0))
        call new_newton(out%newton, out%model, c%solver, ctx%stats%assembly, error)
        if (allocated(error)) return
        ctx%step = 16
        ctx%time = t
        ctx%progress => out%floors
        call newton_attempt(out%newton, out%model, ctx, out%u, attempt, error, keep_tangent=keep)
        out%iterations = attempt%iterations
    end subroutine one_attempt

    subroutine floors_iteration(self, report)
        class(floors_t), intent(inout) :: self
        type(iteration_report_t), intent(in) :: report
        self%floor = [self%floor, report%floor]
    end subroutine floors_iteration

end module test_newton
