!> Will the run fit? The size of every body's discretization (counted before it
!> is built) against the 32-bit integers that number DOFs and matrix entries, and
!> an estimate of the memory the run needs against what this process may use
!> (/proc/meminfo and `ulimit -v`): refused with the numbers, before anything of
!> that size is allocated.
!>
!> The estimate is fitted to the peak resident memory of runs on this code
!> (docs/files.md, "Resources", has the table and the command): a base of
!> 20 MiB (libraries, the program) plus, per entry of the element stiffness
!> matrices (`body_size_t%entries`), 3.3 x log2(DOFs) bytes with the direct
!> solver (the assembly map, the matrix, and UMFPACK's factors, whose fill grows
!> like n log n) or 2.3 x log2(DOFs) with multigrid; 1.0 x log2(DOFs) for a solid's
!> entries with multigrid (its element matrices, 81^2 entries for quadratic elements,
!> count many more entries per matrix nonzero than a plane body's: 13-16 bytes per
!> entry measured, docs/files.md).
module voiga_io_input_resources
    use, intrinsic :: iso_fortran_env, only: int64
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_discretization_size, only: body_size_t
    use voiga_platform_process, only: memory_available
    implicit none
    private

    public :: memory_estimate, check_size, gib, solid_time_estimate

    real(dp), parameter :: base_bytes = 20.0_dp*2.0_dp**20
    real(dp), parameter :: per_entry_direct = 3.3_dp, per_entry_multigrid = 2.3_dp
    !> A solid's rates are lower: its elements couple more DOFs each (81 to 375 rows
    !> against 18 to 50), so the element-matrix entries grow faster than the factors'
    !> fill (direct) or the operators and hierarchy (multigrid).
    real(dp), parameter :: per_entry_direct_solid = 2.4_dp, per_entry_multigrid_solid = 1.0_dp

contains

    !> Estimated peak memory (bytes) of a run with bodies of `sizes` and the
    !> linear solver `linear_solver` ('direct' or 'multigrid').
    pure real(dp) function memory_estimate(sizes, linear_solver)
        type(body_size_t), intent(in) :: sizes(:)
        character(len=*), intent(in) :: linear_solver
        real(dp) :: ndof, entries, per_entry
        logical :: multigrid, solid
        ndof = real(sum(sizes%nsd*sizes%ncp), dp)
        entries = real(sum(sizes%entries), dp)
        multigrid = trim(linear_solver) == 'multigrid'
        ! a case's bodies are all plane or all solids (`voiga_io_input_bodies`)
        solid = any(sizes%nsd == 3)
        if (solid) then
            per_entry = merge(per_entry_multigrid_solid, per_entry_direct_solid, multigrid)
        else
            per_entry = merge(per_entry_multigrid, per_entry_direct, multigrid)
        end if
        memory_estimate = base_bytes + entries*log(max(ndof, 2.0_dp))/log(2.0_dp)*per_entry
    end function memory_estimate

    !> A solid's expected seconds on the 2-core reference machine: with the direct
    !> solver for one factorization of the stiffness (once per run for linear bodies,
    !> every Newton iteration at finite strain), with multigrid for one Newton
    !> iteration. Fitted to the quadratic box of docs/performance-solids.md (1e4 to
    !> 5e5 DOFs: direct 1.3 to 182 s, DOFs^1.64; multigrid 0.6 to 37 s per iteration,
    !> DOFs^1.055) and taken in element-matrix entries (2187 per DOF there), so that a
    !> higher degree, which couples more DOFs per element, costs more: an order of
    !> magnitude to plan a run by, not a measurement (contact adds to it).
    pure real(dp) function solid_time_estimate(sizes, linear_solver) result(seconds)
        type(body_size_t), intent(in) :: sizes(:)
        character(len=*), intent(in) :: linear_solver
        real(dp), parameter :: per_dof = 2187.0_dp
        real(dp) :: n
        n = real(sum(sizes%entries), dp)/per_dof
        if (trim(linear_solver) == 'multigrid') then
            seconds = 3.6e-5_dp*n**1.055_dp
        else
            seconds = 3.5e-7_dp*n**1.64_dp
        end if
    end function solid_time_estimate

    !> The counts fit the default integers, and (unless `memory_check` is false) the
    !> estimate fits the memory available. `where` prefixes messages.
    subroutine check_size(sizes, linear_solver, memory_check, where, error)
        type(body_size_t), intent(in) :: sizes(:)
        character(len=*), intent(in) :: linear_solver, where
        logical, intent(in) :: memory_check
        type(error_t), allocatable, intent(out) :: error
        integer(int64) :: ndof, entries, limit
        real(dp) :: need
        integer(int64) :: physical, address
        character(len=200) :: counts

        ndof = sum(sizes%nsd*sizes%ncp)
        entries = sum(sizes%entries)
        write (counts, '(i0,a,i0,a,i0,a)') ndof, ' DOFs, ', sum(sizes%nel), ' elements, ', entries, &
            ' element matrix entries'
        limit = huge(0)
        if (ndof > limit .or. entries > limit) then
            call fatal_error(error, where//'the discretization is too large: '//trim(counts)// &
                             ' (DOFs and entries are counted in 32-bit integers, at most 2147483647)', &
                             error_code%input)
            return
        end if
        if (.not. memory_check) return
        ! what the run adds to what the program uses now (libraries, the case)
        need = memory_estimate(sizes, linear_solver) - base_bytes
        call memory_available(physical, address)
        if (physical >= 0 .and. need > real(physical, dp)) then
            call fatal_error(error, where//'the run needs about '//gib(need)//' more memory ('//trim(counts)// &
                             ', '//trim(linear_solver)//' solver) but '//gib(real(physical, dp))// &
                             ' are available (MemAvailable); use fewer elements'//advice(linear_solver)// &
                             ', or --no-memory-check', &
                             error_code%input)
        else if (address >= 0 .and. need > real(address, dp)) then
            call fatal_error(error, where//'the run needs about '//gib(need)//' more memory ('//trim(counts)// &
                             ', '//trim(linear_solver)//' solver) but the address-space limit (ulimit -v) '// &
                             'leaves '//gib(real(address, dp))//'; raise it, use fewer elements'// &
                             advice(linear_solver)//', or --no-memory-check', error_code%input)
        end if
    end subroutine check_size

    !> The remedy besides fewer elements: the multigrid path, when the direct solver's
    !> factors were counted.
    pure function advice(linear_solver) result(text)
        character(len=*), intent(in) :: linear_solver
        character(len=:), allocatable :: text
        text = ''
        if (trim(linear_solver) /= 'multigrid') text = ", &solver linear_solver = 'multigrid' (no factors)"
    end function advice

    !> Bytes as '1.23 GB' (or MB).
    pure function gib(bytes) result(text)
        real(dp), intent(in) :: bytes
        character(len=:), allocatable :: text
        character(len=32) :: buf
        if (bytes >= 2.0_dp**30) then
            write (buf, '(f0.2,a)') bytes/2.0_dp**30, ' GB'
        else
            write (buf, '(f0.1,a)') bytes/2.0_dp**20, ' MB'
        end if
        text = trim(buf)
        if (text(1:1) == '.') text = '0'//text
    end function gib

end module voiga_io_input_resources
