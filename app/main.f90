!> voiga command line: `voiga case.nml [--check] [--dump file.h5] [--quiet] ...`.
!> Parses the arguments, reads the case, checks where the run writes and that it
!> fits, builds the model and runs the solver. The run's progress goes to two
!> observers side by side: the result file (`voiga_io_output_results`) and the terminal
!> (`voiga_app_console`).
program voiga_main
    use voiga_error, only: error_t, error_code
    use voiga_version, only: voiga_version_string
    use voiga_io_input_case, only: case_t, read_case, check_edges
    use voiga_io_output_dump, only: write_dump
    use voiga_io_input_bodies, only: discretize_bodies, read_rigid_curves
    use voiga_io_output_outputs, only: check_outputs, resolve_restart, restart_file
    use voiga_io_output_provenance, only: check_restart
    use voiga_io_output_results, only: results_t, restart_case, read_restart
    use voiga_platform_process, only: leave, address_space_limited, reexec_with_environment, &
                                      ignore_file_size_signal, memory_available, stdout_is_terminal
    use voiga_linalg_blas, only: warm_up_blas
    use voiga_platform_libraries, only: default_library_threads, choose_blas_kernels
    use voiga_discretization_patch, only: discretization_t
    use voiga_discretization_size, only: discretization_size
    use voiga_io_input_resources, only: memory_estimate, gib, solid_time_estimate
    use voiga_model, only: model_t, new_model
    use voiga_model_checks, only: setup_warnings, warning_t, check_overlaps
    use voiga_solver_records, only: solver_stats_t, wall_seconds
    use voiga_solver_stepping, only: solve_steps, resume_t
    use voiga_platform_signals, only: catch_signals, signal_name
    use voiga_platform_heap, only: keep_freed_memory
    use voiga_solver_observers, only: observers_t
    use voiga_app_console, only: console_t
    use voiga_kinds, only: dp
    use voiga_text, only: fixed_str
    use, intrinsic :: iso_fortran_env, only: int64
    implicit none

    character(len=:), allocatable :: case_path, dump_path, restart_path, note
    logical :: check, quiet, verbose, overwrite, force_restart, memory_check, allow_overlap
    type(case_t) :: case
    type(discretization_t), allocatable :: discs(:)
    type(error_t), allocatable :: error, finish_error
    type(model_t) :: model
    type(resume_t) :: resume
    type(results_t), target :: results
    type(console_t), target :: console
    type(observers_t) :: observers
    type(solver_stats_t) :: stats
    type(warning_t), allocatable :: warnings(:)
    real(dp), allocatable :: u(:)
    real(dp) :: t0
    integer :: i, length
    logical :: heap_ok

    call choose_blas_kernels()
    call default_library_threads()
    call single_blas_thread_under_a_memory_limit()
    call ignore_file_size_signal()
    ! reuse freed memory across factorizations (glibc; without it, only slower)
    call keep_freed_memory(heap_ok)
    call parse_arguments()
    ! a run still writing the restart file is refused before the file is read (it may
    ! be mid-step)
    if (allocated(restart_path)) call claim_restart_file()
    if (allocated(restart_path) .and. .not. allocated(case_path)) then
        ! the case the interrupted run was started from
        call restart_case(restart_path, case_path, error)
        if (allocated(error)) call fail(error)
    end if
    if (.not. allocated(case_path)) call fail_usage('no case file given')

    t0 = wall_seconds()
    call read_case(case_path, case, error)
    if (allocated(error)) call fail(error)
    if (allocated(restart_path)) then
        ! the run continues in the restart file, whatever output the case names
        call resolve_restart(restart_path, case, case%output, error)
        if (allocated(error)) call fail(error)
        call check_outputs(case, .false., dump_path, overwrite, error, restart=.true.)
    else
        call check_outputs(case, .not. check, dump_path, overwrite, error)
    end if
    if (allocated(error)) call fail(error)
    ! a second writer of the result file is refused before anything is built
    if (allocated(restart_path) .or. .not. check) call results%claim(case%output, error)
    if (allocated(error)) call fail(error)
    call discretize_bodies(case, discs, error, memory_check)
    if (allocated(error)) call fail(error)
    call read_rigid_curves(case, error)
    if (allocated(error)) call fail(error)

    ! the DOF lines are what --check is for; a --quiet run does without them
    if (check .or. .not. quiet) call print_dofs()
    call check_edges(case, discs, error)
    if (allocated(error)) call fail(error)

    if (len(dump_path) > 0) then
        call write_dump(dump_path, case, discs, overwrite .or. case%overwrite, error)
        if (allocated(error)) call fail(error)
        if (.not. quiet) write (*, '(a)') 'wrote '//dump_path
    end if

    call new_model(model, case%bodies, discs, case%solver%n_gauss, case%dirichlet, case%pressure, &
                   case%contact, error)
    if (allocated(error)) call fail(error)
    ! a set-up that cannot make sense is refused before anything is written (a
    ! restart continues a run that was accepted)
    if (.not. allocated(restart_path)) call check_overlaps(model, case%contact%allow_overlap .or. allow_overlap, error)
    if (check .or. allocated(error)) then
        ! what a run would warn about at its start (a run reports them itself)
        warnings = setup_warnings(model)
        do i = 1, size(warnings)
            write (0, '(a)') 'voiga: warning: '//trim(warnings(i)%text)
        end do
        if (allocated(error)) call fail(error)
        stop
    end if
    console%quiet = quiet
    console%verbose = verbose
    console%live = stdout_is_terminal() .and. .not. (quiet .or. verbose)
    console%t0 = t0
    if (allocated(restart_path)) then
        call restart_in_place()
    else
        call results%open(case, model, overwrite .or. case%overwrite, error)
        ! a write that failed (a full disk): no exit handler may flush the rest
        if (allocated(error) .and. results%is_open()) call stop_writing(error)
        if (allocated(error)) call fail(error)
    end if
    ! from here on SIGINT/SIGTERM stop the solve between iterations and close the file
    call catch_signals()
    ! the result file first: a step is written before the terminal says so
    call observers%add(results)
    call observers%add(console)
    call solve_steps(model, case%solver, u, stats, error, observers, resume, t0)
    call console%clear_live()
    call end_run()

contains

    !> Each body's DOFs and elements, and the total.
    subroutine print_dofs()
        integer :: i, total
        total = 0
        do i = 1, size(discs)
            write (*, '(a,4(a,i0))') 'dofs '//trim(case%bodies(i)%name), ' interface=', &
                discs(i)%interface_dofs, ' bulk=', discs(i)%bulk_dofs, ' total=', discs(i)%total_dofs, &
                ' elements=', discs(i)%nel
            total = total + discs(i)%total_dofs
        end do
        write (*, '(a,i0)') 'dofs all total=', total
        write (*, '(a)') 'memory estimate '//gib(memory_estimate([(discretization_size(discs(i)), i=1, &
                                                                   size(discs))], case%solver%linear_solver))// &
            ' ('//trim(case%solver%linear_solver)//' solver; docs/files.md, "Resources")'
        if (discs(1)%nsd == 3) call print_time_estimate()
    end subroutine print_dofs

    !> A solid's time estimate (`solid_time_estimate`): 3D factors grow fast.
    subroutine print_time_estimate()
        real(dp) :: seconds
        integer :: i
        seconds = solid_time_estimate([(discretization_size(discs(i)), i=1, size(discs))], &
                                      case%solver%linear_solver)
        if (trim(case%solver%linear_solver) == 'multigrid') then
            write (*, '(a)') 'time estimate '//trim(fixed_str(seconds, 1))//' s per Newton iteration '// &
                '(multigrid; docs/performance-solids.md)'
        else
            write (*, '(a)') 'time estimate '//trim(fixed_str(seconds, 1))//' s per factorization (direct: '// &
                "once for linear bodies, every Newton iteration at finite strain; linear_solver = 'multigrid' "// &
                'grows slower; docs/performance-solids.md)'
        end if
    end subroutine print_time_estimate

    !> The run ended (interrupted, failed or converged): the result file's final
    !> status, the last lines and the exit code.
    subroutine end_run()
        if (stats%signal /= 0) then
            call finish('interrupted')
            write (0, '(a,i0,a)') 'voiga: interrupted by '//signal_name(stats%signal)//'; ', stats%steps, &
                ' completed steps '//where_kept()
            ! the shell convention: 128 + the signal number (130 SIGINT, 143 SIGTERM)
            call exit_code(128 + stats%signal)
        end if
        if (allocated(error)) then
            call finish('failed: '//error%message)
            if (results%status_only()) then
                write (0, '(a)') 'voiga: no step converged; '//case%output//' keeps the status and the warnings '// &
                    '(python -m post summary '//case%output//')'
            else
                write (0, '(a)') 'voiga: results of the converged steps '//where_kept()
            end if
            write (0, '(a)') 'voiga: error: '//error%message
            call exit_code(exit_status(error))
        end if
        call finish('converged')
        write (*, '(a,i0,a,i0,a,i0,a,i0,a)') 'converged: ', stats%steps, ' steps (', stats%substeps, &
            ' substeps, ', stats%cuts, ' cuts), ', stats%iterations, ' Newton iterations, '// &
            fixed_str(wall_seconds() - t0, 3)//' s; wrote '//case%output
        if (stats%tresca_retries > 0) write (*, '(a,i0,a,i0,a,i0,a)') 'Tresca fixed point: ', &
            stats%tresca_retries, ' substeps retried, ', stats%tresca_accepted, ' accepted, ', &
            stats%fixed_point_iterations, ' fixed-point iterations'
    end subroutine end_run

    !> Under an address-space limit (`ulimit -v`) an OpenBLAS thread that cannot map
    !> its work buffer (128 MiB of address space each) retries for ever, and the
    !> program never ends: run again with one BLAS thread (whatever
    !> OPENBLAS_NUM_THREADS said; the sparse solver gains little from more), map that
    !> buffer while there is room for it (`warm_up_blas`), or stop if there is none.
    subroutine single_blas_thread_under_a_memory_limit()
        character(len=16) :: threads
        integer :: status
        integer(int64) :: physical, address
        if (.not. address_space_limited()) return
        call get_environment_variable('OPENBLAS_NUM_THREADS', threads, status=status)
        if (status /= 0 .or. trim(threads) /= '1') then
            if (status == 0) write (0, '(a)') 'voiga: note: one BLAS thread under an address-space '// &
                'limit (ulimit -v), not OPENBLAS_NUM_THREADS = '//trim(threads)
            call reexec_with_environment('OPENBLAS_NUM_THREADS', '1')
        end if
        call memory_available(physical, address)
        if (address >= 0 .and. address < 160_int64*2_int64**20) then
            write (0, '(a,i0,a)') 'voiga: error: the address-space limit (ulimit -v) leaves ', &
                address/2_int64**20, ' MB; the BLAS library alone needs 128 MB of address space'
            stop 1, quiet=.true.
        end if
        call warm_up_blas()
    end subroutine single_blas_thread_under_a_memory_limit

    subroutine parse_arguments()
        character(len=:), allocatable :: arg
        integer :: n, k
        check = .false.
        quiet = .false.
        verbose = .false.
        overwrite = .false.
        force_restart = .false.
        memory_check = .true.
        allow_overlap = .false.
        dump_path = ''
        n = command_argument_count()
        k = 0
        do while (k < n)
            k = k + 1
            arg = get_arg(k)
            select case (arg)
            case ('-h', '--help')
                call usage()
                stop
            case ('--version')
                write (*, '(a)') 'voiga '//voiga_version_string
                stop
            case ('--check')
                check = .true.
            case ('--quiet', '-q')
                quiet = .true.
            case ('--verbose', '-v')
                verbose = .true.
            case ('--overwrite')
                overwrite = .true.
            case ('--force-restart')
                force_restart = .true.
            case ('--no-memory-check')
                memory_check = .false.
            case ('--allow-overlap')
                allow_overlap = .true.
            case ('--restart')
                if (k == n) call fail_usage('--restart needs a result file')
                k = k + 1
                restart_path = get_arg(k)
            case ('--dump')
                if (k == n) call fail_usage('--dump needs a file name')
                k = k + 1
                dump_path = get_arg(k)
                if (len(dump_path) == 0) call fail_usage('--dump needs a file name')
            case default
                if (len(arg) == 0) call fail_usage('an empty argument')
                if (arg(1:1) == '-') call fail_usage("unknown option '"//arg//"'")
                if (allocated(case_path)) call fail_usage("more than one case file given ('"// &
                                                          case_path//"', '"//arg//"')")
                case_path = arg
            end select
        end do
        if (force_restart .and. .not. allocated(restart_path)) call fail_usage('--force-restart needs --restart')
    end subroutine parse_arguments

    !> Take the writer's lock of the result file `restart_path` (by its canonical
    !> name, as the run writing it took it) before anything reads it: it may be
    !> mid-step. It must be a regular file (a FIFO or a device is refused before it
    !> is opened); its lock file is created without following links and replaces
    !> only a lock file a killed run left, so nothing is written before the case
    !> is known and compared with it (`resolve_restart`).
    subroutine claim_restart_file()
        character(len=:), allocatable :: resolved
        call restart_file(restart_path, resolved, error)
        if (allocated(error)) call fail(error)
        call results%claim(resolved, error)
        if (allocated(error)) call fail(error)
    end subroutine claim_restart_file

    !> Continue the run of the result file `restart_path` in it (its writer's lock
    !> is taken): the checks (its run did not converge; same case and
    !> geometry unless --force-restart), the state after its last step read.
    subroutine restart_in_place()
        call check_restart(case%output, case, force_restart, note, error)
        if (allocated(error)) call fail(error)
        if (len(note) > 0) write (0, '(a)') 'voiga: warning: --force-restart: '//note
        call read_restart(case%output, model, resume, error)
        if (allocated(error)) call fail(error)
        call results%reopen(case%output, case, error, note)
        if (allocated(error) .and. results%broken()) call stop_writing(error)
        if (allocated(error)) call fail(error)
        if (.not. quiet) write (*, '(a,i0)') 'restart after step ', resume%step
    end subroutine restart_in_place

    !> Set the final status and close the result file; a write that failed (here or
    !> before) ends the program at once (`stop_writing`), after the run's own error.
    subroutine finish(status)
        character(len=*), intent(in) :: status
        call results%finish(status, wall_seconds() - t0, stats, finish_error)
        if (.not. (allocated(finish_error) .or. results%broken())) return
        if (allocated(error)) then
            if (allocated(finish_error)) write (0, '(a)') 'voiga: error: '//error%message
            if (.not. allocated(finish_error)) call move_alloc(error, finish_error)
        end if
        call stop_writing(finish_error)
    end subroutine finish

    !> Where the steps of this run are: 'are in <file>', or why they are not
    !> (none written and the earlier result kept; the file moved or removed under
    !> the run).
    function where_kept() result(text)
        character(len=:), allocatable :: text
        text = results%where_steps()
    end function where_kept

    !> A write to the result file failed: say so and what is on disk, and leave
    !> without exit handlers (HDF5's would write the half-written step).
    subroutine stop_writing(err)
        type(error_t), intent(in) :: err
        character(len=:), allocatable :: kept
        write (0, '(a)') 'voiga: error: '//err%message
        call results%abandon(kept)
        if (len(kept) > 0) write (0, '(a)') 'voiga: '//kept
        call leave(1)
    end subroutine stop_writing

    function get_arg(k) result(val)
        integer, intent(in) :: k
        character(len=:), allocatable :: val
        call get_command_argument(k, length=length)
        allocate (character(len=length) :: val)
        call get_command_argument(k, val)
    end function get_arg

    subroutine usage()
        write (*, '(a)') 'usage: voiga CASE.nml [--check] [--dump FILE.h5] [--overwrite] [--allow-overlap] '// &
            '[--quiet] [--verbose]', &
            '       voiga [CASE.nml] --restart RESULT.h5 [--force-restart] [--quiet] [--verbose]', &
            '  (no option)       solve the case and write the result file it names', &
            '  --check           validate the case, build the discretization, print DOF counts', &
            '  --overwrite       replace an existing result or dump file (else refused)', &
            '  --restart R.h5    continue the interrupted or failed run whose result file is R.h5', &
            '  --force-restart   continue it although its case or geometry file changed', &
            '  --dump FILE       write the refined discretization of every body to FILE (HDF5)', &
            '  --no-memory-check run although the memory estimate exceeds the memory available', &
            '  --allow-overlap   run although most slave points of a pair start inside its master', &
            '  --quiet           no line per step (nor the DOF lines of a run)', &
            '  --verbose         a line per Newton iteration (residual, energy, contact states)', &
            '  --version         print the version', &
            'exit codes: 0 converged, 1 other failure (e.g. a full disk), 2 bad input, 3 numerical', &
            '  failure, 130/143 interrupted by SIGINT/SIGTERM (completed steps kept)'
    end subroutine usage

    subroutine fail_usage(message)
        character(len=*), intent(in) :: message
        write (0, '(a)') 'voiga: '//message
        call usage()
        stop 2, quiet=.true.
    end subroutine fail_usage

    !> Stop with exit code `code`.
    subroutine exit_code(code)
        integer, intent(in) :: code
        stop code, quiet=.true.
    end subroutine exit_code

    !> The exit code of an error: 2 bad input, 3 numerical failure, else 1.
    integer function exit_status(err)
        type(error_t), intent(in) :: err
        select case (err%code)
        case (error_code%input)
            exit_status = 2
        case (error_code%numeric)
            exit_status = 3
        case default
            exit_status = 1
        end select
    end function exit_status

    subroutine fail(err)
        type(error_t), intent(in) :: err
        write (0, '(a)') 'voiga: error: '//err%message
        call results%abandon()
        call exit_code(exit_status(err))
    end subroutine fail

end program voiga_main
