!> Which case and geometry a result file belongs to, and whether a restart may
!> continue it. A new result records the SHA-256 of the bytes of its case file and
!> of its geometry file (root attributes `case_sha256`, `geometry_sha256`) and the
!> case's absolute path (`case_path`). `--restart` continues a file only if both
!> files are unchanged: otherwise it is refused with the difference named (the
!> values the result file records beside its steps: the bodies' materials, the
!> load steps, the solver, the Dirichlet conditions and the contact laws), unless
!> the restart is forced (`--force-restart`), which the file then records. It also
!> records the thread counts its timings were measured with (`library_threads`).
module voiga_io_output_provenance
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_text, only: str, real_str
    use voiga_io_hdf5, only: h5file_t
    use voiga_platform_sha256, only: sha256_file
    use voiga_platform_os, only: canonical_path
    use voiga_io_input_case, only: case_t
    use voiga_model_loads, only: phase_of, axis_names
    use voiga_platform_libraries, only: library_threads, blas_kernels
    implicit none
    private

    public :: write_provenance, check_restart

contains

    !> Record the fingerprints of the case and geometry files of `case` in the open
    !> result file `h5`.
    subroutine write_provenance(h5, case, error)
        class(h5file_t), intent(inout) :: h5
        type(case_t), intent(in) :: case
        type(error_t), allocatable, intent(out) :: error
        character(len=64) :: hex
        character(len=:), allocatable :: absolute, threads
        type(error_t), allocatable :: ignored
        call sha256_file(case%path, hex, error)
        if (allocated(error)) return
        call h5%write_attr('/', 'case_sha256', hex, error)
        if (allocated(error)) return
        call sha256_file(case%geometry, hex, error)
        if (allocated(error)) return
        call h5%write_attr('/', 'geometry_sha256', hex, error)
        if (allocated(error)) return
        call canonical_path(case%path, absolute, ignored)
        if (.not. allocated(ignored)) call h5%write_attr('/', 'case_path', absolute, error)
        if (allocated(error)) return
        ! what the run's timings were measured with
        threads = library_threads()
        if (len(threads) == 0) then
            call h5%write_attr('/', 'library_threads', '1 (voiga''s default)', error)
        else
            call h5%write_attr('/', 'library_threads', threads//' (environment)', error)
        end if
        if (allocated(error)) return
        call h5%write_attr('/', 'blas_kernels', blas_kernels(), error)
    end subroutine write_provenance

    !> May the result file `path` be continued with `case`? Not when its run
    !> converged (nothing to continue); not when the case or geometry file differs
    !> from the fingerprints the file keeps, unless `force`. `note` tells what a
    !> forced restart overrode ('' when nothing).
    subroutine check_restart(path, case, force, note, error)
        character(len=*), intent(in) :: path
        type(case_t), intent(in) :: case
        logical, intent(in) :: force
        character(len=:), allocatable, intent(out) :: note
        type(error_t), allocatable, intent(out) :: error
        type(h5file_t) :: h5
        type(error_t), allocatable :: close_error
        character(len=:), allocatable :: status, changed, differences

        note = ''
        call h5%open(path, 'r', error)
        if (allocated(error)) return
        checks: block
            call h5%read_attr_str('/', 'status', status, error)
            if (allocated(error)) exit checks
            if (status == 'converged') then
                call fatal_error(error, path//': --restart: the run converged; there is nothing to continue '// &
                                 '(to run it again, give the case with --overwrite)', error_code%input)
                exit checks
            end if
            call changed_files(h5, case, changed, error)
            if (allocated(error)) exit checks
            if (len(changed) == 0) exit checks
            call recorded_differences(h5, case, differences)
            if (force) then
                note = changed//differences
            else
                call fatal_error(error, path//': --restart: '//changed//differences// &
                                 '; give --force-restart to continue anyway', error_code%input)
            end if
        end block checks
        call h5%close(close_error)
        if (.not. allocated(error) .and. allocated(close_error)) call move_alloc(close_error, error)
    end subroutine check_restart

    !> Which of the case and geometry files differ from the fingerprints in `h5`
    !> ('' when neither does).
    subroutine changed_files(h5, case, changed, error)
        type(h5file_t), intent(inout) :: h5
        type(case_t), intent(in) :: case
        character(len=:), allocatable, intent(out) :: changed
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: recorded
        character(len=64) :: hex
        changed = ''
        if (.not. (h5%has_attr('/', 'case_sha256') .and. h5%has_attr('/', 'geometry_sha256'))) then
            changed = 'the result file keeps no fingerprint of its case and geometry (written by an older '// &
                      'voiga), so they cannot be checked'
            return
        end if
        call h5%read_attr_str('/', 'case_sha256', recorded, error)
        if (allocated(error)) return
        call sha256_file(case%path, hex, error)
        if (allocated(error)) return
        if (recorded /= hex) changed = "the case file '"//case%path//"' has changed since the run started"
        call h5%read_attr_str('/', 'geometry_sha256', recorded, error)
        if (allocated(error)) return
        call sha256_file(case%geometry, hex, error)
        if (allocated(error)) return
        if (recorded /= hex) then
            if (len(changed) > 0) changed = changed//', and '
            changed = changed//"the geometry file '"//case%geometry//"' has changed since the run started"
        end if
    end subroutine changed_files

    !> The values the result file records that differ from `case`, as
    !> ' (<what>: <now> in the case, <then> in the result file; ...)', or ''.
    subroutine recorded_differences(h5, case, text)
        type(h5file_t), intent(inout) :: h5
        type(case_t), intent(in) :: case
        character(len=:), allocatable, intent(out) :: text
        character(len=:), allocatable :: g, s
        type(error_t), allocatable :: error
        integer :: i, n, c, nsd
        text = ''
        ! the model's dimension (a file without the attribute is a plane model's)
        nsd = 2
        if (h5%has_attr('/', 'dimension')) call h5%read_attr_int('/', 'dimension', nsd, error)
        if (allocated(error) .or. nsd < 2 .or. nsd > 3) nsd = 2
        if (allocated(error)) deallocate (error)
        call compare_int(h5, '/', 'n_steps_planned', case%solver%total_steps(), '&solver n_steps (steps in all)', text)
        call compare_str(h5, '/', 'linear_solver', trim(case%solver%linear_solver), '&solver linear_solver', text)
        call compare_str(h5, '/', 'damping', trim(case%solver%damping), '&solver damping', text)
        do i = 1, size(case%bodies)
            associate (b => case%bodies(i))
                g = '/bodies/'//trim(b%name)
                if (.not. h5%exists(g)) then
                    call add(text, "&body '"//trim(b%name)//"' is not in the result file")
                    cycle
                end if
                call compare_str(h5, g, 'material', trim(b%material), "&body '"//trim(b%name)//"' material", text)
                call compare_real(h5, g, 'youngs_modulus', b%youngs_modulus, "&body '"//trim(b%name)// &
                                  "' youngs_modulus", text)
                call compare_real(h5, g, 'poisson_ratio', b%poisson_ratio, "&body '"//trim(b%name)// &
                                  "' poisson_ratio", text)
            end associate
        end do
        do i = 1, size(case%dirichlet)
            g = '/dirichlet/'//str(i)
            s = '&dirichlet ('//str(i)//')'
            call compare_str(h5, g, 'body', trim(case%dirichlet(i)%body), s//' body', text)
            call compare_str(h5, g, 'edge', trim(case%dirichlet(i)%edge), s//' edge', text)
            ! (the flags and values the writer writes: one per axis of the model,
            ! `results.f90` write_dirichlet)
            do c = 1, nsd
                call compare_int(h5, g, 'fix_'//axis_names(c), merge(1, 0, case%dirichlet(i)%fix(c)), &
                                 s//' fix_'//axis_names(c), text)
            end do
            call compare_values(h5, g//'/values', case%dirichlet(i)%values(1:nsd, :), s//' '//components(nsd), text)
        end do
        call h5%read_attr_int('/', 'n_steps_done', n, error)
        if (.not. allocated(error)) call compare_contact(h5, case, n, text)
        if (len(text) > 0) text = ' ('//text//')'
    end subroutine recorded_differences

    !> The names of the displacement components of a model of dimension `nsd`:
    !> 'ux, uy' or 'ux, uy, uz'.
    pure function components(nsd) result(names)
        integer, intent(in) :: nsd
        character(len=:), allocatable :: names
        integer :: c
        names = 'u'//axis_names(1)
        do c = 2, nsd
            names = names//', u'//axis_names(c)
        end do
    end function components

    !> The contact laws recorded with the last written step.
    subroutine compare_contact(h5, case, step, text)
        type(h5file_t), intent(inout) :: h5
        type(case_t), intent(in) :: case
        integer, intent(in) :: step
        character(len=:), allocatable, intent(inout) :: text
        character(len=:), allocatable :: g, s
        character(len=8) :: buf
        type(error_t), allocatable :: error
        real(dp) :: t, mu
        integer :: k
        if (step < 1) return
        write (buf, '(i6.6)') step
        t = 0.0_dp
        call h5%read_attr_real('/steps/'//trim(buf), 'time', t, error)
        do k = 1, size(case%contact)
            g = '/steps/'//trim(buf)//'/contact/'//str(k)
            if (.not. h5%exists(g)) cycle
            s = '&contact ('//str(k)//')'
            call compare_str(h5, g, 'slave', trim(case%contact(k)%slave), s//' slave', text)
            call compare_str(h5, g, 'master', trim(case%contact(k)%master), s//' master', text)
            call compare_str(h5, g, 'method', trim(case%contact(k)%method), s//' method', text)
            call compare_real(h5, g, 'penalty_normal', case%contact(k)%penalty_normal, s//' penalty_normal', text)
            ! (the step's: friction may change with the phase)
            mu = case%contact(k)%friction
            if (allocated(case%contact(k)%friction_phases)) &
                mu = case%contact(k)%friction_phases(phase_of(t, size(case%contact(k)%friction_phases)))
            call compare_real(h5, g, 'friction', mu, s//' friction', text)
            if (case%contact(k)%friction > 0.0_dp) call compare_real(h5, g, 'penalty_tangent', &
                                                                      case%contact(k)%penalty_tangent, &
                                                                      s//' penalty_tangent', text)
        end do
    end subroutine compare_contact

    subroutine add(text, item)
        character(len=:), allocatable, intent(inout) :: text
        character(len=*), intent(in) :: item
        if (len(text) > 0) text = text//'; '
        text = text//item
    end subroutine add

    subroutine compare_str(h5, g, name, now, what, text)
        type(h5file_t), intent(inout) :: h5
        character(len=*), intent(in) :: g, name, now, what
        character(len=:), allocatable, intent(inout) :: text
        character(len=:), allocatable :: then
        type(error_t), allocatable :: error
        if (.not. h5%has_attr(g, name)) return
        call h5%read_attr_str(g, name, then, error)
        if (allocated(error)) return
        if (then /= now) call add(text, what//": '"//now//"' in the case, '"//then//"' in the result file")
    end subroutine compare_str

    subroutine compare_int(h5, g, name, now, what, text)
        type(h5file_t), intent(inout) :: h5
        character(len=*), intent(in) :: g, name, what
        integer, intent(in) :: now
        character(len=:), allocatable, intent(inout) :: text
        integer :: then
        type(error_t), allocatable :: error
        if (.not. h5%has_attr(g, name)) return
        call h5%read_attr_int(g, name, then, error)
        if (allocated(error)) return
        if (then /= now) call add(text, what//': '//str(now)//' in the case, '//str(then)//' in the result file')
    end subroutine compare_int

    subroutine compare_real(h5, g, name, now, what, text)
        type(h5file_t), intent(inout) :: h5
        character(len=*), intent(in) :: g, name, what
        real(dp), intent(in) :: now
        character(len=:), allocatable, intent(inout) :: text
        real(dp) :: then
        type(error_t), allocatable :: error
        if (.not. h5%has_attr(g, name)) return
        call h5%read_attr_real(g, name, then, error)
        if (allocated(error)) return
        if (then /= now) call add(text, what//': '//short(now)//' in the case, '//short(then)//' in the result file')
    end subroutine compare_real

    !> A real with the fewest digits that read back as it, e.g. '200', '0.3',
    !> '1.5E+020'.
    pure function short(x) result(text)
        real(dp), intent(in) :: x
        character(len=:), allocatable :: text
        real(dp) :: back
        integer :: d, ios
        logical :: fixed
        fixed = x == 0.0_dp .or. (abs(x) >= 1.0e-4_dp .and. abs(x) < 1.0e15_dp)
        do d = 0, 17
            if (fixed) then
                text = trim(adjustl(real_str(x, 'f0.'//str(d))))
            else
                text = trim(adjustl(real_str(x, 'es'//str(d + 10)//'.'//str(d)//'e3')))
            end if
            read (text, *, iostat=ios) back
            if (ios == 0 .and. back == x) exit
        end do
        if (text(len(text):len(text)) == '.') text = text(1:len(text) - 1)
        if (len(text) > 1) then
            if (text(1:2) == '-.') text = '-0'//text(2:)
        end if
        if (text(1:1) == '.') text = '0'//text
    end function short

    subroutine compare_values(h5, path, now, what, text)
        type(h5file_t), intent(inout) :: h5
        character(len=*), intent(in) :: path, what
        real(dp), intent(in) :: now(:, :)
        character(len=:), allocatable, intent(inout) :: text
        real(dp), allocatable :: then(:, :)
        type(error_t), allocatable :: error
        if (.not. h5%exists(path)) return
        call h5%read(path, then, error)
        if (allocated(error)) return
        if (any(shape(then) /= shape(now))) then
            call add(text, what//': a different number of load phases')
        else if (any(then /= now)) then
            call add(text, what//': other values in the case than in the result file')
        end if
    end subroutine compare_values

end module voiga_io_output_provenance
