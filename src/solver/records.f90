!> What a run records: one record per converged step, one per cut of the load
!> increment, and the run's counters. The solver fills them; the result file
!> (`voiga_io_output_results`) and the terminal (`app/`) show them through
!> `voiga_solver_progress`.
module voiga_solver_records
    use voiga_kinds, only: dp, i8
    use voiga_model_assembly, only: assembly_stats_t
    implicit none
    private

    public :: step_record_t, cut_record_t, solver_stats_t, stage_names, append_cut, wall_seconds, n_cut_records

    !> Stages whose seconds are recorded per step.
    character(len=*), parameter :: stage_names(5) = [character(len=13) :: 'assembly', 'contact', &
                                                     'factorization', 'solve', 'output']

    !> What one converged step reports.
    type :: step_record_t
        integer :: step = 0
        real(dp) :: time = 0.0_dp
        integer :: iterations = 0
        !> Residual norm (free DOFs) before each iteration and after the last, [iterations + 1].
        real(dp), allocatable :: residual_norms(:)
        !> |du . r| of each iteration, [iterations].
        real(dp), allocatable :: energy_norms(:)
        !> Resultant reaction force of each Dirichlet condition, [2, n_dirichlet].
        real(dp), allocatable :: reactions(:, :)
        !> Seconds per stage (order of `stage_names`).
        real(dp) :: seconds(5) = 0.0_dp
        !> Converged substeps the nominal step took (1: no cut) and the cuts on the way.
        integer :: substeps = 1, cuts = 0
        !> Newton iterations of all substeps, failed attempts included (`iterations`,
        !> `residual_norms` and `energy_norms` are those of the last substep).
        integer :: iterations_total = 0
        !> Sign of det(K) (free DOFs) of the last tangent factorized up to this step
        !> (0: singular, or no factorization yet).
        integer :: det_sign = 0
        !> Linear-solver iterations of all Newton iterations of the step (multigrid
        !> GMRES; 0 with the direct solver).
        integer :: linear_iterations = 0
    end type step_record_t

    !> One cut of the load increment (adaptive stepping, docs/robustness.md).
    type :: cut_record_t
        !> Nominal step being solved.
        integer :: step = 0
        !> Load time the failed attempt aimed at.
        real(dp) :: time = 0.0_dp
        !> Increment of the failed attempt and the new one, as fractions of the nominal step.
        real(dp) :: fraction = 0.0_dp, new_fraction = 0.0_dp
        !> Why the attempt failed (fixed length: gfortran 12 corrupts the heap when
        !> arrays of a type with a deferred-length component grow by constructor).
        character(len=256) :: reason = ''
    end type cut_record_t

    !> Counters of a run.
    type :: solver_stats_t
        type(assembly_stats_t) :: assembly
        !> Converged nominal steps; Newton iterations of all attempts.
        integer :: steps = 0, iterations = 0
        integer :: symbolic_factorizations = 0, numeric_factorizations = 0
        !> Substeps whose predicted start failed and that were retried from the last
        !> converged state.
        integer :: predictor_retries = 0
        !> Substeps started from the stick predictor (`stick_predictor`; its linear
        !> step counts as a Newton iteration).
        integer :: stick_predictions = 0
        !> Substeps retried after an augmented-Lagrangian pair softened its penalties.
        integer :: softenings = 0
        !> Residual evaluations spent on shortening Newton steps (halving, natural
        !> damping, the crossing limit).
        integer :: line_search_steps = 0
        !> DOFs of each level of the linear solver's hierarchy (empty with the direct solver).
        integer, allocatable :: multigrid_levels(:)
        !> Substeps retried with the Tresca fixed point, of them accepted, and the
        !> fixed-point iterations (Tresca solves) of all retries.
        integer :: tresca_retries = 0, tresca_accepted = 0, fixed_point_iterations = 0
        !> Multiplier updates of the augmented Lagrangian (every substep's, failed ones too).
        integer :: multiplier_updates = 0
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

    !> The cuts recorded (0 also when a run failed before its steps began, e.g. out of
    !> memory for the stiffness pattern, and nothing was allocated).
    pure integer function n_cut_records(stats) result(n)
        type(solver_stats_t), intent(in) :: stats
        n = 0
        if (allocated(stats%cut_records)) n = size(stats%cut_records)
    end function n_cut_records

    !> Wall-clock seconds since an arbitrary origin.
    real(dp) function wall_seconds()
        integer(i8) :: count, rate
        call system_clock(count, rate)
        wall_seconds = real(count, dp)/real(rate, dp)
    end function wall_seconds

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

end module voiga_solver_records
