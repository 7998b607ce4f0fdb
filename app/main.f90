!> voiga command line: `voiga case.nml [--check] [--dump file.h5] [--quiet]`. Parses
!> the arguments, reads the case, builds the model and runs the solver; the
!> terminal output is `voiga_app_console`'s.
program voiga_main
    use voiga_error, only: error_t, error_code, fatal_error
    use voiga_version, only: voiga_version_string
    use voiga_io_case, only: case_t, read_case, check_edges
    use voiga_io_dump, only: write_dump
    use voiga_io_bodies, only: discretize_bodies, read_rigid_curves
    use voiga_io_results, only: restart_case, read_restart
    use voiga_discretization_patch, only: discretization_t
    use voiga_model, only: model_t, new_model
    use voiga_model_checks, only: setup_warnings, warning_t
    use voiga_solver_records, only: solver_stats_t, wall_seconds
    use voiga_solver_stepping, only: solve_steps, resume_t
    use voiga_solver_signals, only: catch_signals, signal_name
    use voiga_solver_heap, only: keep_freed_memory
    use voiga_app_console, only: console_t
    use voiga_kinds, only: dp
    implicit none

    character(len=:), allocatable :: case_path, dump_path, arg, restart_path
    logical :: check, quiet, verbose
    type(case_t) :: case
    type(discretization_t), allocatable :: discs(:)
    type(error_t), allocatable :: error, finish_error
    type(model_t) :: model
    type(resume_t) :: resume
    type(console_t) :: results
    type(solver_stats_t) :: stats
    type(warning_t), allocatable :: warnings(:)
    real(dp), allocatable :: u(:)
    real(dp) :: t0
    integer :: i, n, total
    logical :: heap_ok

    ! reuse freed memory across factorizations (glibc; without it, only slower)
    call keep_freed_memory(heap_ok)
    check = .false.
    quiet = .false.
    verbose = .false.
    n = command_argument_count()
    i = 0
    do while (i < n)
        i = i + 1
        arg = get_arg(i)
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
        case ('--restart')
            if (i == n) call fail_usage('--restart needs a result file')
            i = i + 1
            restart_path = get_arg(i)
        case ('--dump')
            if (i == n) call fail_usage('--dump needs a file name')
            i = i + 1
            dump_path = get_arg(i)
        case default
            if (arg(1:1) == '-') call fail_usage("unknown option '"//arg//"'")
            if (allocated(case_path)) call fail_usage("more than one case file given ('"// &
                                                      case_path//"', '"//arg//"')")
            case_path = arg
        end select
    end do
    if (allocated(restart_path) .and. .not. allocated(case_path)) then
        ! the case the interrupted run was started from
        call restart_case(restart_path, case_path, error)
        if (allocated(error)) call fail(error)
    end if
    if (.not. allocated(case_path)) call fail_usage('no case file given')

    t0 = wall_seconds()
    call read_case(case_path, case, error)
    if (allocated(error)) call fail(error)
    call discretize_bodies(case, discs, error)
    if (allocated(error)) call fail(error)
    call read_rigid_curves(case, error)
    if (allocated(error)) call fail(error)

    total = 0
    do i = 1, size(discs)
        write (*, '(a,4(a,i0))') 'dofs '//trim(case%bodies(i)%name), ' interface=', &
            discs(i)%interface_dofs, ' bulk=', discs(i)%bulk_dofs, ' total=', discs(i)%total_dofs, &
            ' elements=', discs(i)%nel
        total = total + discs(i)%total_dofs
    end do
    write (*, '(a,i0)') 'dofs all total=', total
    call check_edges(case, discs, error)
    if (allocated(error)) call fail(error)

    if (allocated(dump_path)) then
        call write_dump(dump_path, case, discs, error)
        if (allocated(error)) call fail(error)
        if (.not. quiet) write (*, '(a)') 'wrote '//dump_path
    end if

    call new_model(model, case%bodies, discs, case%solver%n_gauss, case%dirichlet, case%pressure, &
                   case%contact, error)
    if (allocated(error)) call fail(error)
    if (check) then
        ! what a run would warn about at its start (a run reports them itself)
        warnings = setup_warnings(model)
        do i = 1, size(warnings)
            write (0, '(a)') 'voiga: warning: '//trim(warnings(i)%text)
        end do
        stop
    end if
    results%quiet = quiet
    results%verbose = verbose
    if (allocated(restart_path)) then
        call read_restart(restart_path, model, resume, error)
        if (allocated(error)) call fail(error)
        case%output = restart_path
        call results%reopen(restart_path, case, error)
        if (allocated(error)) call fail(error)
        if (.not. quiet) write (*, '(a,i0)') 'restart after step ', resume%step
    else
        call results%open(case, model, error)
        if (allocated(error)) call fail(error)
    end if
    ! from here on SIGINT/SIGTERM stop the solve between iterations and close the file
    call catch_signals()
    call solve_steps(model, case%solver, u, stats, error, results, resume, t0)
    if (stats%signal /= 0) then
        call results%finish('interrupted', wall_seconds() - t0, stats, finish_error)
        if (allocated(finish_error)) write (0, '(a)') 'voiga: error: '//finish_error%message
        write (0, '(a,i0,a)') 'voiga: interrupted by '//signal_name(stats%signal)//'; ', stats%steps, &
            ' completed steps are in '//case%output
        ! the shell convention: 128 + the signal number (130 SIGINT, 143 SIGTERM)
        call exit_code(128 + stats%signal)
    end if
    if (allocated(error)) then
        call results%finish('failed: '//error%message, wall_seconds() - t0, stats, finish_error)
        if (allocated(finish_error)) then
            write (0, '(a)') 'voiga: error: '//finish_error%message
        else
            write (0, '(a)') 'voiga: results of the converged steps are in '//case%output
        end if
        call fail(error)
    end if
    call results%finish('converged', wall_seconds() - t0, stats, error)
    if (allocated(error)) call fail(error)
    write (*, '(a,i0,a,i0,a,i0,a,i0,a,f0.3,a)') 'converged: ', stats%steps, ' steps (', stats%substeps, &
        ' substeps, ', stats%cuts, ' cuts), ', stats%iterations, ' Newton iterations, ', &
        wall_seconds() - t0, ' s; wrote '//case%output
    if (stats%tresca_retries > 0) write (*, '(a,i0,a,i0,a,i0,a)') 'Tresca fixed point: ', &
        stats%tresca_retries, ' substeps retried, ', stats%tresca_accepted, ' accepted, ', &
        stats%fixed_point_iterations, ' fixed-point iterations'

contains

    function get_arg(k) result(val)
        integer, intent(in) :: k
        character(len=:), allocatable :: val
        integer :: length
        call get_command_argument(k, length=length)
        allocate (character(len=length) :: val)
        call get_command_argument(k, val)
    end function get_arg

    subroutine usage()
        write (*, '(a)') 'usage: voiga CASE.nml [--check] [--dump FILE.h5] [--quiet] [--verbose] [--restart R.h5]', &
            '  (no option)    solve the case and write the result file it names', &
            '  --check        validate the case, build the discretization, print DOF counts', &
            '  --restart R.h5 continue the interrupted or failed run whose result file is R.h5', &
            '  --dump FILE    write the refined discretization of every body to FILE (HDF5)', &
            '  --quiet        no line per step', &
            '  --verbose      a line per Newton iteration (residual, energy, contact states)', &
            '  --version      print the version', &
            'exit codes: 0 converged, 1 other failure, 2 bad input, 3 numerical failure,', &
            '  130/143 interrupted by SIGINT/SIGTERM (completed steps kept)'
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

    subroutine fail(err)
        type(error_t), intent(in) :: err
        write (0, '(a)') 'voiga: error: '//err%message
        select case (err%code)
        case (error_code%input)
            stop 2, quiet=.true.
        case (error_code%numeric)
            stop 3, quiet=.true.
        case default
            stop 1, quiet=.true.
        end select
    end subroutine fail

end program voiga_main
