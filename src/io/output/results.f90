!> The result file of a run (schema in docs/hdf5.md): metadata and the discretization first, then
!> one group per converged step (its cuts, the contact zones' accuracy), written and flushed when
!> it converges; the run's cuts and its final status ('converged', 'failed: ...', 'interrupted').
!> Every write goes through `result_file_t`'s guards (what readers see, a second
!> writer, a full disk: voiga_io_output_result_file). The writes of one step or record
!> keep their first failure in the file (`h5file_t%check`), which the end of the
!> write (`end_write`) reports: one check per step, not one per call.
module voiga_io_output_results
    use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
    use, intrinsic :: iso_fortran_env, only: int64
    use voiga_kinds, only: dp, i8
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_version, only: voiga_version_string
    use voiga_text, only: str
    use voiga_io_hdf5, only: h5file_t
    use voiga_io_input_case, only: case_t
    use voiga_io_output_dump, only: write_discretization, write_curve, write_elements
    use voiga_io_input_geometry, only: geometry_units
    use voiga_platform_os, only: path_exists
    use voiga_io_output_result_file, only: result_file_t
    use voiga_io_output_provenance, only: write_provenance
    use voiga_model, only: model_t
    use voiga_model_loads, only: axis_names
    use voiga_model_fields, only: output_settings_t, field_samples_t
    use voiga_io_output_fields, only: write_fields, sample_bodies
    use voiga_io_output_accuracy, only: write_accuracy
    use voiga_contact_master, only: master_output_t
    use voiga_contact_pair, only: contact_pair_t, pair_slot_t, history_item_t, contact_point_out_t
    use voiga_solver_records, only: step_record_t, cut_record_t, stage_names, solver_stats_t, n_cut_records
    use voiga_solver_progress, only: progress_t, step_report_t
    use voiga_solver_stepping, only: resume_t
    implicit none
    private

    public :: results_t, restart_case, read_restart

    !> Most characters of the attribute listing the cuts' reasons (HDF5 keeps an
    !> attribute in the object header, at most 64 KB).
    integer, parameter :: max_reasons = 60000

    !> An open result file; as a `progress_t` it writes every converged step the
    !> solver reports (and the levels of a multigrid solver). It is one observer of
    !> a run beside the terminal (`voiga_solver_observers`); the program asks it,
    !> not its file, what became of the file.
    type, extends(progress_t) :: results_t
        type(result_file_t) :: h5
        integer :: n_written = 0
        !> The sampled fields the case asks for (`&output`) and the run's last step.
        type(output_settings_t) :: fields
        integer :: last_step = 0
        !> A step's fields could not be sampled (warned once; the steps are written).
        logical :: fields_failed = .false.
        !> The spatial dimension of the file (its root attribute `dimension`): the
        !> length of every spatial axis the writer shapes itself (the contact points'
        !> positions); the model's at `open`, the file's at `reopen`.
        integer :: nsd = 2
    contains
        !> Take the writer's lock of the file (before anything is built or read).
        procedure :: claim => results_claim
        procedure :: open => results_open
        procedure :: reopen => results_reopen
        procedure :: write_step => results_write_step
        procedure :: finish => results_finish
        !> Record the DOFs of each multigrid level (/multigrid_level_dofs).
        procedure :: write_multigrid => results_write_multigrid
        procedure :: set_up => results_set_up
        procedure :: step_done => results_step_done
        procedure :: warning => results_warning
        procedure :: is_open => results_is_open
        procedure :: broken => results_broken
        procedure :: status_only => results_status_only
        procedure :: where_steps => results_where_steps
        procedure :: abandon => results_abandon
    end type results_t

    interface
        !> The case file recorded in the result file `path`.
        module subroutine restart_case(path, case_file, error)
            character(len=*), intent(in) :: path
            character(len=:), allocatable, intent(out) :: case_file
            type(error_t), allocatable, intent(out) :: error
        end subroutine restart_case

        !> The state after the last written step of the result file `path` (as
        !> `write_step` wrote it): displacement, the solver's substep fraction, force
        !> scale and det K sign, and the committed history of each contact pair of
        !> `model`, which is set on the pairs. The file is only read; it must hold
        !> no more values than the model has (checked before anything is read).
        module subroutine read_restart(path, model, state, error)
            character(len=*), intent(in) :: path
            type(model_t), intent(inout) :: model
            type(resume_t), intent(out) :: state
            type(error_t), allocatable, intent(out) :: error
        end subroutine read_restart
    end interface

contains

    !> Take the writer's lock of the result file `path` (`result_file_t%claim`).
    subroutine results_claim(self, path, error)
        class(results_t), intent(inout) :: self
        character(len=*), intent(in) :: path
        type(error_t), allocatable, intent(out) :: error
        call self%h5%claim(path, error)
    end subroutine results_claim

    !> Create the file (status 'running') with metadata and the discretization of
    !> each body; it replaces an earlier file at its name (once it has a step) only
    !> when `replace` (`--overwrite`).
    subroutine results_open(self, case, model, replace, error)
        class(results_t), intent(inout) :: self
        type(case_t), intent(in) :: case
        type(model_t), intent(in) :: model
        logical, intent(in) :: replace
        type(error_t), allocatable, intent(out) :: error
        integer :: i, k

        self%fields = case%field_output
        self%last_step = case%solver%total_steps()
        self%nsd = model%nsd
        call self%h5%create(case%output, replace, error)
        if (allocated(error)) return
        ! (each write keeps its failure in the file: checked once, below)
        call self%h5%write_attr('/', 'voiga_version', voiga_version_string)
        call self%h5%write_attr('/', 'title', case%title)
        call self%h5%write_attr('/', 'scene', case%scene)
        call self%h5%write_attr('/', 'mesh', case%mesh)
        call self%h5%write_attr('/', 'layout', case%layout)
        call self%h5%write_attr('/', 'case_file', case%path)
        call self%h5%write_attr('/', 'status', 'running')
        call self%h5%write_attr('/', 'n_dofs', model%ndof)
        ! the length of every spatial axis in the file (docs/hdf5.md); a restart
        ! continues only a file of its model's dimension (`read_restart`)
        call self%h5%write_attr('/', 'dimension', model%nsd)
        call self%h5%write_attr('/', 'linear_solver', trim(case%solver%linear_solver))
        call self%h5%write_attr('/', 'damping', trim(case%solver%damping))
        call self%h5%write_attr('/', 'n_steps_planned', case%solver%total_steps())
        call self%h5%write_attr('/', 'n_steps_done', 0)
        call self%h5%write_attr('/', 'n_cuts', 0)
        call self%h5%write_attr('/', 'wall_time', 0.0_dp)
        ! the run's warnings, one per line (results_warning); none yet
        call self%h5%write_attr('/', 'warnings', '')
        do i = 1, size(model%bodies)
            call write_body(self%h5, model, i, trim(case%bodies(i)%material))
        end do
        do k = 1, size(model%dirichlet)
            call write_dirichlet(self%h5, model, k)
        end do
        ! the geometry's units ('mm, N' from pre), else just consistent ones
        call self%h5%write_attr('/', 'units', geometry_units(case%geometry, 'consistent'))
        if (.not. self%h5%failed()) call write_provenance(self%h5, case, error)
        call self%h5%check(error)
        if (.not. allocated(error)) call self%h5%flush(error)
    end subroutine results_open

    !> The discretization, material and element layout of body `i` of `model` under
    !> /bodies/<name>.
    subroutine write_body(h5, model, i, material)
        class(h5file_t), intent(inout) :: h5
        type(model_t), intent(in) :: model
        integer, intent(in) :: i
        !> Name of the body's material law.
        character(len=*), intent(in) :: material
        character(len=:), allocatable :: g

        associate (b => model%bodies(i))
            g = '/bodies/'//trim(b%name)
            call write_discretization(h5, g, b%disc)
            call h5%write_attr(g, 'material', material)
            call h5%write_attr(g, 'youngs_modulus', b%mat%youngs_modulus)
            call h5%write_attr(g, 'poisson_ratio', b%mat%poisson_ratio)
            call h5%write_attr(g, 'dof_offset', b%dof0)
            call write_elements(h5, g, b%disc)
        end associate
    end subroutine write_body

    !> Dirichlet condition `k` of `model` under /dirichlet/<k>.
    subroutine write_dirichlet(h5, model, k)
        class(h5file_t), intent(inout) :: h5
        type(model_t), intent(in) :: model
        integer, intent(in) :: k
        character(len=:), allocatable :: g
        ! (the model's axes of the [3, n_phases] values)
        real(dp), allocatable :: values(:, :)
        integer :: c

        associate (d => model%dirichlet(k))
            g = '/dirichlet/'//str(k)
            call h5%create_group(g)
            call h5%write_attr(g, 'body', trim(model%bodies(d%body)%name))
            call h5%write_attr(g, 'edge', trim(d%edge))
            ! one flag per axis of the model: fix_x, fix_y (, fix_z)
            do c = 1, model%nsd
                call h5%write_attr(g, 'fix_'//axis_names(c), merge(1, 0, d%fix(c)))
            end do
            values = d%values(1:model%nsd, :)
            call h5%write(g//'/values', values)
        end associate
    end subroutine write_dirichlet

    !> Reopen the result file of an earlier run of `case` to continue it in place
    !> (its writer's lock taken first): status 'running', the steps it holds counted
    !> as written; `note` (a forced restart's overrides) is recorded as `restart_forced`.
    subroutine results_reopen(self, path, case, error, note)
        class(results_t), intent(inout) :: self
        character(len=*), intent(in) :: path
        type(case_t), intent(in) :: case
        type(error_t), allocatable, intent(out) :: error
        character(len=*), intent(in), optional :: note
        self%fields = case%field_output
        self%last_step = case%solver%total_steps()
        call self%h5%resume(path, error)
        if (allocated(error)) return
        call self%h5%read_attr_int('/', 'n_steps_done', self%n_written, error)
        if (allocated(error)) return
        ! (a file without it is of an older voiga: 2D; `read_restart` has compared it
        ! with the model's)
        self%nsd = 2
        if (self%h5%has_attr('/', 'dimension')) call self%h5%read_attr_int('/', 'dimension', self%nsd, error)
        if (allocated(error)) return
        call self%h5%begin_write(65536_int64, error)
        if (allocated(error)) return
        call self%h5%write_attr('/', 'status', 'running')
        if (present(note)) then
            if (len(note) > 0) call self%h5%write_attr('/', 'restart_forced', note)
        end if
        call self%h5%end_write(error)
    end subroutine results_reopen

    !> Write one converged step (space reserved, readers kept out, flushed); the
    !> first step gives the file its name. Its writes keep their failure in the
    !> file, which `end_write` hands over: one check per step.
    subroutine results_write_step(self, rec, u, wall, pairs, cuts, n_cuts, next_fraction, r0_max, &
                                  error, model)
        class(results_t), intent(inout) :: self
        type(step_record_t), intent(in) :: rec
        real(dp), intent(in) :: u(:)
        type(pair_slot_t), intent(in) :: pairs(:)
        real(dp), intent(in) :: wall
        type(cut_record_t), intent(in), optional :: cuts(:)
        integer, intent(in), optional :: n_cuts
        real(dp), intent(in), optional :: next_fraction, r0_max
        type(error_t), allocatable, intent(out) :: error
        !> The model of `u` (its bodies' sampled fields, when `&output` asks for them).
        type(model_t), intent(in), optional :: model
        type(field_samples_t), allocatable :: samples(:)
        type(error_t), allocatable :: sampling
        if (self%h5%broken) return
        if (present(model)) then
            ! an output sample that cannot be evaluated does not undo a converged step:
            ! the step is written without its fields, and the run says so once
            if (self%fields%wants(rec%step, self%last_step)) &
                call sample_bodies(self%fields, model, u, samples, sampling)
            if (allocated(sampling)) then
                deallocate (samples)
                if (.not. self%fields_failed) call self%warning('step '//str(rec%step)// &
                    ': its sampled fields are not written (nor those of a later step where this happens): '// &
                    sampling%message)
                self%fields_failed = .true.
            end if
        end if
        ! at least 1 MiB, and for the first step its displacement, contact output
        ! and metadata, generously
        call self%h5%begin_write(max(1048576_int64, 64_int64*size(u, kind=int64)), error)
        if (allocated(error)) return
        call write_step_groups(self, rec, u, pairs, cuts, next_fraction, r0_max, model, samples)
        call write_counters(self, wall, n_cuts)
        call self%h5%end_write(error)
        if (.not. allocated(error)) call self%h5%place(error)
    end subroutine results_write_step

    !> Write one converged step and the current displacement.
    subroutine write_step_groups(self, rec, u, pairs, cuts, next_fraction, r0_max, model, samples)
        class(results_t), intent(inout) :: self
        type(step_record_t), intent(in) :: rec
        real(dp), intent(in) :: u(:)
        !> Contact pairs with the output of their last evaluation.
        type(pair_slot_t), intent(in) :: pairs(:)
        !> The cuts made while solving this step.
        type(cut_record_t), intent(in), optional :: cuts(:)
        !> Solver state needed to restart after this step: the substep fraction carried
        !> to the next step and the run's largest first residual.
        real(dp), intent(in), optional :: next_fraction, r0_max
        !> The model of `u` and its bodies' sampled fields (allocated when `&output`
        !> asks for them at this step).
        type(model_t), intent(in), optional :: model
        type(field_samples_t), allocatable, intent(in), optional :: samples(:)
        character(len=:), allocatable :: g
        character(len=8) :: buf
        integer :: k
        integer(i8) :: c0, c1, rate

        call system_clock(c0, rate)
        write (buf, '(i6.6)') rec%step
        g = '/steps/'//trim(buf)
        call self%h5%create_group(g)
        call self%h5%write_attr(g, 'step', rec%step)
        call self%h5%write_attr(g, 'time', rec%time)
        call self%h5%write_attr(g, 'iterations', rec%iterations)
        call self%h5%write_attr(g, 'iterations_total', max(rec%iterations_total, rec%iterations))
        call self%h5%write_attr(g, 'tangent_det_sign', rec%det_sign)
        call self%h5%write_attr(g, 'linear_iterations', rec%linear_iterations)
        call self%h5%write_attr(g, 'substeps', rec%substeps)
        call self%h5%write_attr(g, 'cuts', rec%cuts)
        if (present(next_fraction)) call self%h5%write_attr(g, 'next_fraction', next_fraction)
        if (present(r0_max)) call self%h5%write_attr(g, 'r0_max', r0_max)
        if (present(cuts)) then
            if (size(cuts) > 0) call write_cuts(self%h5, g, cuts)
        end if
        do k = 1, size(stage_names)
            call self%h5%write_attr(g, 'seconds_'//trim(stage_names(k)), rec%seconds(k))
        end do
        call self%h5%write(g//'/residual_norms', rec%residual_norms)
        call self%h5%write(g//'/energy_norms', rec%energy_norms)
        if (size(rec%reactions, 2) > 0) call self%h5%write(g//'/reactions', rec%reactions)
        call self%h5%write(g//'/displacement', u)
        do k = 1, size(pairs)
            call write_contact(self%h5, g//'/contact/'//str(k), pairs(k)%pair, self%nsd)
        end do
        if (present(model)) call write_accuracy(self%h5, g, model)
        if (present(model) .and. present(samples)) then
            if (allocated(samples)) call write_fields(self%h5, g, self%fields, model, samples)
        end if
        ! this step's own output time (the record was made before it was written)
        call system_clock(c1)
        call self%h5%write_attr(g, 'seconds_output', real(c1 - c0, dp)/real(rate, dp))
    end subroutine write_step_groups

    !> The root's counters after a step, flushed with it: the flush is journaled
    !> (journal_vfd.c), so the step and its count reach the file together or not at
    !> all, and n_steps_done counts whole steps only.
    subroutine write_counters(self, wall, n_cuts)
        class(results_t), intent(inout) :: self
        real(dp), intent(in) :: wall
        integer, intent(in), optional :: n_cuts
        self%n_written = self%n_written + 1
        if (present(n_cuts)) call self%h5%write_attr('/', 'n_cuts', n_cuts)
        call self%h5%write_attr('/', 'n_steps_done', self%n_written)
        call self%h5%write_attr('/', 'wall_time', wall)
    end subroutine write_counters

    !> Per-slave-point contact output of `pair` as the group `c`: the pair's law,
    !> what its master's kind records (`contact_master_t%output`), the points'
    !> output of the last evaluation and the committed history.
    subroutine write_contact(h5, c, pair, nsd)
        class(h5file_t), intent(inout) :: h5
        character(len=*), intent(in) :: c
        class(contact_pair_t), intent(in) :: pair
        !> The spatial dimension (the points' positions have `nsd` components).
        integer, intent(in) :: nsd
        integer :: i
        call h5%create_group(c)
        call h5%write_attr(c, 'slave', trim(pair%slave_name))
        call h5%write_attr(c, 'master', trim(pair%master_name))
        call h5%write_attr(c, 'penalty_normal', pair%law%eps_n)
        call h5%write_attr(c, 'penalty_tangent', pair%law%eps_t)
        call h5%write_attr(c, 'friction', pair%law%mu)
        call h5%write_attr(c, 'method', pair%method_name())
        call write_master(h5, c, pair%master%output())
        call h5%write(c//'/force', pair%force(1:nsd))
        call write_points(h5, c, pair%out, nsd)
        ! (a face: (xi, eta) per point, [2, n], h5py: (n, 2))
        if (allocated(pair%eta)) call h5%write(c//'/xi_slave', reshape([(pair%xi(i), pair%eta(i), &
                                                                           i=1, size(pair%xi))], [2, size(pair%xi)]))
        if (.not. allocated(pair%eta)) call h5%write(c//'/xi_slave', pair%xi)
        ! committed friction history: what a restart needs
        call write_history(h5, c//'/history/', pair%history())
    end subroutine write_contact

    !> What a master's kind records at a step, under the pair's group `c`.
    subroutine write_master(h5, c, master)
        class(h5file_t), intent(inout) :: h5
        character(len=*), intent(in) :: c
        type(master_output_t), intent(in) :: master
        integer :: j
        if (len(master%curve_name) > 0) call write_curve(h5, c//'/'//master%curve_name, master%curve)
        do j = 1, size(master%names)
            call h5%write(c//'/'//trim(master%names(j)), master%vectors(:, j))
        end do
    end subroutine write_master

    !> Each slave point's output `out` as one dataset per quantity under `c`; the
    !> positions as [nsd, n] (h5py: (n, nsd)).
    subroutine write_points(h5, c, out, nsd)
        class(h5file_t), intent(inout) :: h5
        character(len=*), intent(in) :: c
        type(contact_point_out_t), intent(in) :: out(:)
        integer, intent(in) :: nsd
        real(dp), allocatable :: a1(:)
        integer :: i
        call h5%write(c//'/x_ref', reshape([(out(i)%x0(1:nsd), i=1, size(out))], [nsd, size(out)]))
        call h5%write(c//'/x', reshape([(out(i)%x(1:nsd), i=1, size(out))], [nsd, size(out)]))
        a1 = out%gap
        ! no orthogonal projection onto the master: NaN
        where (a1 > 1.0e300_dp) a1 = ieee_value(1.0_dp, ieee_quiet_nan)
        call h5%write(c//'/gap', a1)
        ! ([ ]: contiguous copies of the points' components)
        call h5%write(c//'/p_n', [out%pn])
        call h5%write(c//'/p_n_nominal', [out%pn0])
        if (nsd == 3) then
            ! a face: the tangential traction vector (per current and per reference area),
            ! the projection's two parameters
            call h5%write(c//'/p_t', reshape([(out(i)%tt, i=1, size(out))], [3, size(out)]))
            call h5%write(c//'/p_t_nominal', reshape([(out(i)%tt*out(i)%stretch, i=1, size(out))], [3, size(out)]))
            call h5%write(c//'/xi_master', reshape([(out(i)%xi_m, out(i)%eta_m, i=1, size(out))], [2, size(out)]))
        else
            call h5%write(c//'/p_t', [out%pt])
            call h5%write(c//'/p_t_nominal', [out%pt0])
            call h5%write(c//'/xi_master', [out%xi_m])
        end if
        call h5%write(c//'/stretch', [out%stretch])
        call h5%write(c//'/area_ref', [out%area0])
        call h5%write(c//'/state', [out%state])
    end subroutine write_points

    !> A pair's committed history items, each as the dataset `prefix`<name>.
    subroutine write_history(h5, prefix, history)
        class(h5file_t), intent(inout) :: h5
        character(len=*), intent(in) :: prefix
        type(history_item_t), intent(in) :: history(:)
        integer :: i
        do i = 1, size(history)
            if (allocated(history(i)%values)) then
                call h5%write(prefix//trim(history(i)%name), history(i)%values)
            else
                call h5%write(prefix//trim(history(i)%name), history(i)%flags)
            end if
        end do
    end subroutine write_history

    !> Cuts as the dataset `g`/cuts, shape [4, n] (h5py: (n, 4)), rows (step, time,
    !> fraction, new fraction), with their reasons as its attribute `reasons` (one line each).
    subroutine write_cuts(h5, g, cuts)
        class(h5file_t), intent(inout) :: h5
        character(len=*), intent(in) :: g
        type(cut_record_t), intent(in) :: cuts(:)
        real(dp), allocatable :: rows(:, :)
        character(len=:), allocatable :: reasons
        integer :: i, width
        allocate (rows(4, size(cuts)))
        ! an HDF5 attribute holds at most 64 KB: a run with hundreds of cuts keeps the
        ! start of each reason here (every step's own /cuts keeps them whole)
        width = max(16, (max_reasons - size(cuts))/max(1, size(cuts)))
        reasons = ''
        do i = 1, size(cuts)
            rows(:, i) = [real(cuts(i)%step, dp), cuts(i)%time, cuts(i)%fraction, cuts(i)%new_fraction]
            if (i > 1) reasons = reasons//new_line('a')
            reasons = reasons//trim(cuts(i)%reason(1:min(width, len(cuts(i)%reason))))
        end do
        call h5%write(g//'/cuts', rows)
        call h5%write_attr(g//'/cuts', 'reasons', reasons)
    end subroutine write_cuts

    !> Set the final status ('converged', 'failed: <reason>' or 'interrupted') and the
    !> run's counters of `stats` (every cut as /cuts when there is one, the Tresca
    !> fixed point's, the multiplier updates), and close. The file is closed whatever fails (the first error is
    !> returned) and given its name (`result_file_t%settle`); a broken file is not touched
    !> (`abandon`), nor one with no room left for the status, nor one moved, replaced
    !> or removed under the run (`lost`; they stay 'running', every step written
    !> readable).
    subroutine results_finish(self, status, wall, stats, error)
        class(results_t), intent(inout) :: self
        character(len=*), intent(in) :: status
        real(dp), intent(in) :: wall
        type(solver_stats_t), intent(in) :: stats
        type(error_t), allocatable, intent(out) :: error
        if (self%h5%broken) then
            call self%h5%abandon()
            return
        end if
        if (self%h5%lost) then
            ! the run's error says so: the file is closed as its last flush left it
            call self%h5%settle(self%n_written > 0, error)
            return
        end if
        if (self%h5%is_open()) call self%h5%begin_write(65536_int64, error)
        if (self%h5%is_open() .and. .not. allocated(error)) then
            call self%h5%write_attr('/', 'n_cuts', n_cut_records(stats))
            if (n_cut_records(stats) > 0) call write_cuts(self%h5, '', stats%cut_records)
            call self%h5%write_attr('/', 'tresca_retries', stats%tresca_retries)
            call self%h5%write_attr('/', 'tresca_accepted', stats%tresca_accepted)
            call self%h5%write_attr('/', 'fixed_point_iterations', stats%fixed_point_iterations)
            call self%h5%write_attr('/', 'multiplier_updates', stats%multiplier_updates)
            call self%h5%write_attr('/', 'stick_predictions', stats%stick_predictions)
            call self%h5%write_attr('/', 'newton_iterations', stats%iterations)
            call self%h5%write_attr('/', 'status', status)
            call self%h5%write_attr('/', 'wall_time', wall)
            call self%h5%end_write(error)
        end if
        if (self%h5%broken) then
            call self%h5%abandon()
        else
            call self%h5%settle(self%n_written > 0, error)
        end if
    end subroutine results_finish

    !> The solver is set up: the levels of its multigrid hierarchy.
    subroutine results_set_up(self, level_dofs, error)
        class(results_t), intent(inout) :: self
        integer, intent(in) :: level_dofs(:)
        type(error_t), allocatable, intent(out) :: error
        call self%write_multigrid(level_dofs, error)
    end subroutine results_set_up

    !> A converged step: written with the contact output of `model`'s pairs.
    subroutine results_step_done(self, report, u, model, error)
        class(results_t), intent(inout) :: self
        type(step_report_t), intent(in) :: report
        real(dp), intent(in) :: u(:)
        type(model_t), intent(in) :: model
        type(error_t), allocatable, intent(out) :: error
        call self%write_step(report%record, u, report%wall, model%pairs, report%cuts, report%n_cuts, &
                             report%next_fraction, report%r0_max, error, model)
    end subroutine results_step_done

    !> A warning: one more line of the root attribute `warnings` (a line the file
    !> has already, e.g. a set-up warning repeated by a restart, is not repeated).
    !> Written at once (space reserved, readers kept out, flushed); a failure to
    !> write it is not the run's.
    subroutine results_warning(self, text)
        class(results_t), intent(inout) :: self
        character(len=*), intent(in) :: text
        type(error_t), allocatable :: error
        character(len=:), allocatable :: lines
        if (.not. self%h5%is_open() .or. self%h5%broken) return
        lines = ''
        if (self%h5%has_attr('/', 'warnings')) call self%h5%read_attr_str('/', 'warnings', lines, error)
        if (allocated(error)) return
        if (index(new_line('a')//lines//new_line('a'), new_line('a')//text//new_line('a')) > 0) return
        if (len(lines) > 0) lines = lines//new_line('a')
        call self%h5%begin_write(65536_int64, error)
        if (allocated(error)) return
        call self%h5%write_attr('/', 'warnings', lines//text, error)
        call self%h5%end_write(error)
    end subroutine results_warning

    !> Write /multigrid_level_dofs (finest first) unless the file has it (restart).
    subroutine results_write_multigrid(self, level_dofs, error)
        class(results_t), intent(inout) :: self
        integer, intent(in) :: level_dofs(:)
        type(error_t), allocatable, intent(out) :: error
        if (.not. self%h5%is_open() .or. self%h5%broken) return
        if (self%h5%exists('/multigrid_level_dofs')) return
        call self%h5%begin_write(65536_int64, error)
        if (allocated(error)) return
        call self%h5%write('/multigrid_level_dofs', level_dofs, error)
        call self%h5%end_write(error)
    end subroutine results_write_multigrid

    !> Is the file open (written to since `open` or `reopen`)?
    logical function results_is_open(self)
        class(results_t), intent(in) :: self
        results_is_open = self%h5%is_open()
    end function results_is_open

    !> Has a write to the file failed (nothing more may reach it: `abandon`, and
    !> leave without HDF5's exit handlers)?
    logical function results_broken(self)
        class(results_t), intent(in) :: self
        results_broken = self%h5%broken
    end function results_broken

    !> Does the file at the output's name hold this run's status and warnings but
    !> no step (none written, and no earlier file kept in its place)?
    logical function results_status_only(self)
        class(results_t), intent(in) :: self
        results_status_only = self%n_written == 0 .and. .not. self%h5%kept_earlier
    end function results_status_only

    !> Where the steps this run wrote are ('are in <file>', or why they are not).
    function results_where_steps(self) result(text)
        class(results_t), intent(in) :: self
        character(len=:), allocatable :: text
        text = self%h5%where_steps()
    end function results_where_steps

    !> Leave the file as it is on disk (`result_file_t%abandon`: no HDF5 call) after
    !> a failed write or a failed run's set-up. `kept`: what a user finds on disk, one
    !> line ('' when there is nothing to say).
    subroutine results_abandon(self, kept)
        class(results_t), intent(inout) :: self
        character(len=:), allocatable, intent(out), optional :: kept
        character(len=:), allocatable :: text
        call self%h5%abandon()
        if (.not. present(kept)) return
        kept = ''
        if (self%h5%in_place .or. self%h5%lost .or. self%h5%stuck) then
            text = self%h5%where_steps()
            if (self%h5%in_place .and. index(text, 'are in ') == 1) then
                kept = 'the '//str(self%n_written)//' steps written before are readable in '// &
                       self%h5%final_path//" (its status may still say 'running')"
            else
                kept = 'the '//str(self%n_written)//' steps written before '//text
            end if
        else if (self%h5%kept_earlier) then
            kept = self%h5%final_path//' is kept as it was'
        end if
    end subroutine results_abandon

end module voiga_io_output_results
