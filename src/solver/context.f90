!> The context of a substep (tblite's `context_type` is the model): where the
!> solver is, what it records and where it reports, passed as one argument
!> through the load stepping (`voiga_solver_stepping`), its stick predictor, the
!> outer loops (`voiga_solver_outer`) and a Newton attempt (`voiga_solver_newton`)
!> instead of the same five arguments to each.
!>
!> What is not in it, and why: the model and the displacement `u` are what those
!> procedures work on (each says by its intents whether it changes them, and the
!> stepping resets `u` to the converged state between attempts); the Newton
!> workspace (`newton_t`: tangent, linear solver) is the `self` of an attempt;
!> how an attempt ended (`attempt_t`) and its error are its results; the
!> stepping's own state between substeps (increment, converged states) is the
!> stepper's.
module voiga_solver_context
    use voiga_kinds, only: dp
    use voiga_solver_records, only: solver_stats_t, step_record_t
    use voiga_solver_progress, only: progress_t
    implicit none
    private

    public :: context_t

    !> A substep's context.
    type :: context_t
        !> The nominal step being solved, and the load time the attempt aims at.
        integer :: step = 0
        real(dp) :: time = 0.0_dp
        !> The nominal step's record (the last substep's norms, every substep's
        !> seconds and iterations, its cuts), appended to `stats%records` when the
        !> step converges.
        type(step_record_t) :: record
        !> The run's counters.
        type(solver_stats_t) :: stats
        !> Where progress goes: the caller's observer, which outlives the run.
        class(progress_t), pointer :: progress => null()
    end type context_t

end module voiga_solver_context
