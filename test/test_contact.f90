!> GPTS contact: tangent against finite differences in frictionless, stick and
!> slip states for several layer degrees and masters.
module test_contact
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_testdrive, only: unittest_t, new_unittest, check
    use voiga_nurbs_surface, only: nurbs_surface_t
    use voiga_discretization_patch, only: discretization_t, new_discretization
    use voiga_model, only: model_t
    use voiga_contact_factory, only: contact_settings_t
    use voiga_model_assembly, only: assemble, assembly_stats_t, stiffness_pattern, assembly_map_t, &
                                    new_assembly_map
    use voiga_linalg_sparse, only: csc_matrix_t
    use voiga_solver_records, only: solver_stats_t
    use voiga_solver_settings, only: solver_settings_t
    use voiga_solver_stepping, only: solve_steps
    use voiga_solver_convergence, only: residual_floor
    use voiga_model, only: reference_coordinates
    use voiga_model_loads, only: dirichlet_settings_t, pressure_settings_t
    use voiga_contact_pair, only: contact_pair_t
    use voiga_contact_gpts, only: gpts_pair_t
    use voiga_contact_mortar, only: mortar_pair_t, mortar_snapshot_t
    use voiga_contact_law, only: state_inactive, state_stick, state_slip
    use voiga_nurbs_curve, only: nurbs_curve_t
    use voiga_test_fixtures, only: paper_layout, lcg_t, annulus_sector, rectangle, quadratic, scene_t, scene_model, &
                                   body_settings, mortar_history
    implicit none
    private

    public :: collect_contact, two_body_model, penetrating_state, contact_fd, bc, build_model, run_fd, &
              small_ironing, ironing_quadratic, block_on_plane

    real(dp), parameter :: pi = acos(-1.0_dp)

contains

    subroutine collect_contact(testsuite)
        type(unittest_t), allocatable, intent(out) :: testsuite(:)
        testsuite = [ &
                    new_unittest('tangent_fd_frictionless', test_fd_frictionless), &
                    new_unittest('tangent_fd_stick', test_fd_stick), &
                    new_unittest('tangent_fd_slip', test_fd_slip), &
                    new_unittest('tangent_fd_touch', test_fd_touch), &
                    new_unittest('friction_per_phase_and_stick_predictor', test_friction_phases), &
                    new_unittest('tangent_fd_rigid_master', test_fd_rigid), &
                    new_unittest('tangent_fd_tresca', test_fd_tresca), &
                    new_unittest('contact_patch_test', test_patch), &
                    new_unittest('friction_block_slip', test_block_slip), &
                    new_unittest('friction_block_stick', test_block_stick), &
                    new_unittest('tresca_fixed_point_solves_coulomb', test_tresca_fixed_point), &
                    new_unittest('frictionless_runs_no_friction_code', test_no_friction_code), &
                    new_unittest('rigid_master_adds_no_dofs', test_rigid_no_dofs), &
                    new_unittest('ironing_newton_quadratic', test_ironing_quadratic), &
                    new_unittest('fitted_pattern_keeps_couplings', test_fitted_pattern), &
                    new_unittest('contact_zone_holes_and_support', test_pair_zone), &
                    new_unittest('mortar_tangent_fd_frictionless', test_fd_mortar_frictionless), &
                    new_unittest('mortar_tangent_fd_stick', test_fd_mortar_stick), &
                    new_unittest('mortar_tangent_fd_slip', test_fd_mortar_slip), &
                    new_unittest('mortar_tangent_fd_rigid_master', test_fd_mortar_rigid), &
                    new_unittest('mortar_patch_test', test_patch_mortar), &
                    new_unittest('mortar_ironing_newton_quadratic', test_ironing_quadratic_mortar), &
                    new_unittest('mortar_crossing_fraction', test_crossing_fraction), &
                    new_unittest('mortar_friction_block_slip', test_block_slip_mortar), &
                    new_unittest('mortar_frictionless_runs_no_friction_code', test_no_friction_code_mortar), &
                    new_unittest('mortar_unprojected_control_points_open', test_mortar_unprojected_open) &
                    ]
    end subroutine collect_contact


    !> Die (half annulus, outer radius 3, lowest point (2.5, 0)) over a 9 x 3 slab,
    !> both with `layout`; the pair die -> slab (or -> a rigid line y = 0, or with
    !> `curve` the rigid obstacle it bounds).
    subroutine two_body_model(layout, mu, rigid, model, error, method, curve)
        character(len=*), intent(in) :: layout
        real(dp), intent(in) :: mu
        logical, intent(in) :: rigid
        type(model_t), intent(out) :: model
        type(error_t), allocatable, intent(out) :: error
        !> Contact method ('gpts' when absent).
        character(len=*), intent(in), optional :: method
        !> A rigid master bounded by this curve instead of the line (with `rigid`).
        type(nurbs_curve_t), intent(in), optional :: curve
        type(scene_t) :: c
        type(discretization_t) :: discs(2)
        character(len=8), parameter :: names(2) = [character(len=8) :: 'die', 'slab']
        integer :: i

        allocate (c%bodies(2))
        do i = 1, 2
            c%bodies(i)%name = names(i)
            c%bodies(i)%material = 'neo-hookean'
            c%bodies(i)%youngs_modulus = merge(10.0_dp, 1.0_dp, i == 1)
            c%bodies(i)%poisson_ratio = 0.3_dp
        end do
        c%bodies(1)%layout = paper_layout(layout, [12, 1], 'outer')
        c%bodies(2)%layout = paper_layout(layout, [8, 2], 'top')
        c%solver%n_steps = [1]
        allocate (c%dirichlet(0), c%pressure(0), c%contact(1))
        c%contact(1)%slave = 'die'
        c%contact(1)%master = merge('rigid', 'slab ', rigid)
        c%contact(1)%rigid_point = [0.0_dp, 0.0_dp, 0.0_dp]
        c%contact(1)%rigid_normal = [0.0_dp, 1.0_dp, 0.0_dp]
        c%contact(1)%penalty_normal = 100.0_dp
        c%contact(1)%penalty_tangent = 70.0_dp
        c%contact(1)%friction = mu
        if (present(method)) c%contact(1)%method = method
        if (present(curve)) then
            c%contact(1)%rigid_curve = 'curve'
            c%contact(1)%curve = curve
        end if
        call new_discretization(discs(1), annulus_sector([2.5_dp, 3.0_dp], 2.0_dp, 3.0_dp, pi, 2), &
                                c%bodies(1)%layout, '', error)
        if (allocated(error)) return
        call new_discretization(discs(2), rectangle(0.0_dp, -3.0_dp, 9.0_dp, 3.0_dp), &
                                c%bodies(2)%layout, '', error)
        if (allocated(error)) return
        call scene_model(c, discs, model, error)
    end subroutine two_body_model

    !> A deformed, penetrating configuration: die moved down by 0.06 and sheared,
    !> slab bent, both with small random perturbations.
    subroutine penetrating_state(model, u)
        type(model_t), intent(in) :: model
        real(dp), allocatable, intent(out) :: u(:)
        type(lcg_t) :: rng
        real(dp) :: x(2)
        integer :: ib, a, d
        allocate (u(model%ndof))
        do ib = 1, 2
            associate (b => model%bodies(ib))
                do a = 1, b%disc%ncp
                    x = b%disc%x(:, a)
                    d = b%dof0 + 2*a - 1
                    if (ib == 1) then
                        u(d) = 0.03_dp*(3.0_dp - x(2)) + 0.003_dp*(rng%uniform() - 0.5_dp)
                        u(d + 1) = -0.1_dp + 0.01_dp*(x(1) - 2.5_dp)**2/9 + 0.003_dp*(rng%uniform() - 0.5_dp)
                    else
                        u(d) = 0.01_dp*x(2) + 0.003_dp*(rng%uniform() - 0.5_dp)
                        u(d + 1) = -0.01_dp*sin(x(1)/3.0_dp)*(x(2) + 3.0_dp)/3 + 0.003_dp*(rng%uniform() - 0.5_dp)
                    end if
                end do
            end associate
        end do
    end subroutine penetrating_state

    !> Dense contact tangent vs central differences of the contact residual.
    subroutine contact_fd(pair, u, want_state, label, error)
        class(contact_pair_t), intent(inout) :: pair
        real(dp), intent(inout) :: u(:)
        integer, intent(in) :: want_state
        character(len=*), intent(in) :: label
        type(error_t), allocatable, intent(out) :: error
        real(dp), allocatable :: kd(:, :), r(:), rp(:), rm(:), kfd(:, :)
        integer, allocatable :: used(:)
        real(dp), parameter :: h = 1.0e-7_dp
        real(dp) :: err, scale
        integer :: j, n, nact

        n = size(u)
        allocate (kd(n, n), r(n), rp(n), rm(n), kfd(n, n))
        kd = 0.0_dp
        r = 0.0_dp
        call pair%evaluate(u, r, error, add_dense)
        if (allocated(error)) return
        nact = count(pair%out%state /= state_inactive)
        call check(error, nact >= 3, label//': at least 3 active points')
        if (allocated(error)) return
        call check(error, all(pair%out%state == state_inactive .or. pair%out%state == want_state), &
                   label//': every active point is in the wanted state')
        if (allocated(error)) return
        do j = 1, n
            u(j) = u(j) + h
            rp = 0.0_dp
            call pair%evaluate(u, rp, error)
            if (allocated(error)) return
            u(j) = u(j) - 2*h
            rm = 0.0_dp
            call pair%evaluate(u, rm, error)
            if (allocated(error)) return
            u(j) = u(j) + h
            kfd(:, j) = (rp - rm)/(2*h)
        end do
        used = pack([(j, j=1, n)], any(kd /= 0.0_dp, dim=1) .or. any(kfd /= 0.0_dp, dim=1))
        scale = maxval(abs(kd))
        err = maxval(abs(kd - kfd))/scale
        ! central differences, h = 1e-7 on O(1) coordinates: truncation ~1e-12 and
        ! round-off ~1e-9 relative; 1e-6 is the acceptance bound
        call check(error, err, 0.0_dp, label//': contact tangent vs FD (max error / max |K|)', abs=1.0e-6_dp)
        if (allocated(error)) return
        call check(error, size(used) > 0, label//': tangent not empty')
    contains
        subroutine add_dense(dofs, k)
            integer, intent(in) :: dofs(:)
            real(dp), intent(in) :: k(:, :)
            kd(dofs, dofs) = kd(dofs, dofs) + k
        end subroutine add_dense
    end subroutine contact_fd

    subroutine run_fd(layouts, mu, rigid, anchor_shift, want_state, error, tresca, method, curve, touch)
        character(len=*), intent(in) :: layouts(:)
        real(dp), intent(in) :: mu
        logical, intent(in) :: rigid
        !> Committed anchor = current projection - shift (friction only).
        real(dp), intent(in) :: anchor_shift
        integer, intent(in) :: want_state
        type(error_t), allocatable, intent(out) :: error
        !> Tresca mode: slip bound = this factor x mu p_N of the state (fixed for the FD).
        real(dp), intent(in), optional :: tresca
        !> Contact method ('gpts' when absent); mortar: the shift is that of the last
        !> converged projections, the committed tractions are zero.
        character(len=*), intent(in), optional :: method
        !> A rigid master bounded by this curve (with `rigid`).
        type(nurbs_curve_t), intent(in), optional :: curve
        !> Every point (GPTS) or control point (mortar) was open at the last converged
        !> state, its gap there this (> 0): it touched in this step (the slip after the
        !> interpolated touch counts, and its derivative by the gap).
        real(dp), intent(in), optional :: touch
        type(model_t) :: model
        real(dp), allocatable :: u(:), r(:)
        integer :: il

        do il = 1, size(layouts)
            call two_body_model(trim(layouts(il)), mu, rigid, model, error, method, curve)
            if (allocated(error)) return
            call penetrating_state(model, u)
            if (mu > 0.0_dp) then
                ! committed history: every point was in contact, anchored near or far
                allocate (r(size(u)))
                r = 0.0_dp
                call model%pairs(1)%pair%evaluate(u, r, error)
                if (allocated(error)) return
                select type (pair => model%pairs(1)%pair)
                type is (gpts_pair_t)
                    pair%hist%field(pair%h_active)%last = 1.0_dp
                    pair%hist%field(pair%h_anchor)%last = pair%out%xi_m - anchor_shift
                    if (present(tresca)) pair%slip_bound = tresca*mu*max(0.0_dp, pair%out%pn)
                    if (present(touch)) then
                        pair%hist%field(pair%h_active)%last = 0.0_dp
                        pair%hist%field(pair%h_xi)%last = pair%out%xi_m - anchor_shift
                        pair%hist%field(pair%h_gap)%last = touch
                    end if
                type is (mortar_pair_t)
                    call mortar_history(pair, anchor_shift, touch)
                end select
                deallocate (r)
            end if
            call contact_fd(model%pairs(1)%pair, u, want_state, trim(layouts(il))// &
                            merge(' rigid', '      ', rigid), error)
            if (allocated(error)) return
        end do
    end subroutine run_fd

    subroutine test_fd_frictionless(error)
        type(error_t), allocatable, intent(out) :: error
        call run_fd([character(len=5) :: 'N2', 'N3', 'N4', 'NN4', 'NN2.1', 'NN2.2'], 0.0_dp, .false., &
                    0.0_dp, state_stick, error)
    end subroutine test_fd_frictionless

    subroutine test_fd_stick(error)
        type(error_t), allocatable, intent(out) :: error
        ! a shift of 1e-4 in the master parameter: |t_T| ~ 70 * 1e-4 * 9 << mu p_N
        call run_fd([character(len=5) :: 'N2', 'N3', 'N4', 'NN4', 'NN2.2'], 0.5_dp, .false., &
                    1.0e-4_dp, state_stick, error)
    end subroutine test_fd_stick

    !> Points open at the last converged state (gap 1e-3 there) that touched in this
    !> step: only their slip after the interpolated touch counts, f (xi - xi_last) with
    !> f = -g / (g0 - g); the tangent carries the derivative of f by the gap. Sticking
    !> and slipping, GPTS and mortar (per control point), deformable and rigid masters.
    subroutine test_fd_touch(error)
        type(error_t), allocatable, intent(out) :: error
        call run_fd([character(len=5) :: 'N2', 'N4', 'NN2.2'], 0.5_dp, .false., 1.0e-4_dp, state_stick, error, &
                    touch=1.0e-3_dp)
        if (allocated(error)) return
        call run_fd([character(len=5) :: 'N2', 'NN2.2'], 0.3_dp, .false., 0.05_dp, state_slip, error, &
                    touch=1.0e-3_dp)
        if (allocated(error)) return
        call run_fd([character(len=5) :: 'N3', 'NN4'], 0.3_dp, .true., 1.0e-3_dp, state_stick, error, touch=1.0e-3_dp)
        if (allocated(error)) return
        call run_fd([character(len=5) :: 'N2', 'N4', 'NN2.2'], 0.5_dp, .false., 1.0e-4_dp, state_stick, error, &
                    method='mortar', touch=1.0e-3_dp)
        if (allocated(error)) return
        call run_fd([character(len=5) :: 'N3', 'NN4'], 0.3_dp, .true., 1.0e-3_dp, state_stick, error, &
                    method='mortar', touch=1.0e-3_dp)
    end subroutine test_fd_touch

    subroutine test_fd_slip(error)
        type(error_t), allocatable, intent(out) :: error
        call run_fd([character(len=5) :: 'N2', 'N3', 'N4', 'NN4', 'NN2.2'], 0.3_dp, .false., &
                    0.05_dp, state_slip, error)
    end subroutine test_fd_slip

    subroutine test_fd_rigid(error)
        type(error_t), allocatable, intent(out) :: error
        call run_fd([character(len=5) :: 'N2', 'NN2.2'], 0.0_dp, .true., 0.0_dp, state_stick, error)
        if (allocated(error)) return
        call run_fd([character(len=5) :: 'N3', 'NN4'], 0.3_dp, .true., 1.0e-3_dp, state_stick, error)
        if (allocated(error)) return
        call run_fd([character(len=5) :: 'N4', 'NN2.2'], 0.3_dp, .true., 0.5_dp, state_slip, error)
    end subroutine test_fd_rigid

    !> Tresca mode (prescribed slip bounds, the fixed point of the Newton solver):
    !> its tangent has no normal-tangential coupling; checked against FD with the
    !> bounds held fixed, sticking (bounds 10 mu p_N, a small shift) and slipping.
    subroutine test_fd_tresca(error)
        type(error_t), allocatable, intent(out) :: error
        call run_fd([character(len=5) :: 'N2', 'N4', 'NN2.2'], 0.3_dp, .false., 1.0e-4_dp, state_stick, &
                    error, tresca=10.0_dp)
        if (allocated(error)) return
        call run_fd([character(len=5) :: 'N2', 'N4', 'NN2.2'], 0.3_dp, .false., 0.05_dp, state_slip, &
                    error, tresca=0.7_dp)
        if (allocated(error)) return
        call run_fd([character(len=5) :: 'N3', 'NN4'], 0.3_dp, .true., 0.5_dp, state_slip, error, tresca=1.0_dp)
    end subroutine test_fd_tresca

    !> Mortar pairs: the tangent, with the couplings through the control-point
    !> tractions, against central differences of the residual.
    subroutine test_fd_mortar_frictionless(error)
        type(error_t), allocatable, intent(out) :: error
        call run_fd([character(len=5) :: 'N2', 'N3', 'N4', 'NN4', 'NN2.1', 'NN2.2'], 0.0_dp, .false., &
                    0.0_dp, state_stick, error, method='mortar')
    end subroutine test_fd_mortar_frictionless

    subroutine test_fd_mortar_stick(error)
        type(error_t), allocatable, intent(out) :: error
        call run_fd([character(len=5) :: 'N2', 'N3', 'N4', 'NN4', 'NN2.2'], 0.5_dp, .false., &
                    1.0e-4_dp, state_stick, error, method='mortar')
    end subroutine test_fd_mortar_stick

    subroutine test_fd_mortar_slip(error)
        type(error_t), allocatable, intent(out) :: error
        call run_fd([character(len=5) :: 'N2', 'N3', 'N4', 'NN4', 'NN2.2'], 0.3_dp, .false., &
                    0.05_dp, state_slip, error, method='mortar')
    end subroutine test_fd_mortar_slip

    subroutine test_fd_mortar_rigid(error)
        type(error_t), allocatable, intent(out) :: error
        call run_fd([character(len=5) :: 'N2', 'NN2.2'], 0.0_dp, .true., 0.0_dp, state_stick, error, &
                    method='mortar')
        if (allocated(error)) return
        call run_fd([character(len=5) :: 'N3', 'NN4'], 0.3_dp, .true., 1.0e-3_dp, state_stick, error, &
                    method='mortar')
        if (allocated(error)) return
        call run_fd([character(len=5) :: 'N4', 'NN2.2'], 0.3_dp, .true., 0.5_dp, state_slip, error, &
                    method='mortar')
    end subroutine test_fd_mortar_rigid

    !> The contact patch test with the mortar-type penalty: uniform pressure on
    !> matching meshes; on non-matching ones a spread that falls with more slave
    !> points and stays below GPTS's with as many (the pressure is interpolated from
    !> the control points instead of sampled point by point). Measured spread for 3,
    !> 9, 15, 21 points: 1.2e-2, 7.8e-4, 2.0e-4, 6.1e-5 (GPTS: 0.22 .. 4.8e-4).
    subroutine test_patch_mortar(error)
        type(error_t), allocatable, intent(out) :: error
        real(dp) :: spread, gpts, prev
        integer :: i, ngp
        call patch_spread(5, 3, spread, error, 'mortar')
        if (allocated(error)) return
        call check(error, spread <= 1.0e-9_dp, 'mortar, matching meshes: uniform contact pressure')
        if (allocated(error)) return
        prev = huge(1.0_dp)
        do i = 1, 4
            ngp = 3 + 6*(i - 1)
            call patch_spread(3, ngp, spread, error, 'mortar')
            if (allocated(error)) return
            call patch_spread(3, ngp, gpts, error)
            if (allocated(error)) return
            call check(error, spread < prev, 'mortar, non-matching: spread falls with more slave points')
            if (allocated(error)) return
            call check(error, spread < gpts, 'mortar, non-matching: spread below GPTS''s')
            if (allocated(error)) return
            prev = spread
        end do
    end subroutine test_patch_mortar

    !> The step control of mortar pairs (`step_limit`): the fraction of a
    !> step at which the first control point closes (times the overshoot) or its slip
    !> reverses (where the trial traction is zero); 1 for GPTS and for steps that
    !> cross nothing the tangent did not describe.
    subroutine test_crossing_fraction(error)
        type(error_t), allocatable, intent(out) :: error
        type(mortar_pair_t) :: pair
        type(gpts_pair_t) :: gpts
        real(dp), parameter :: one(3) = 1.0_dp
        pair%gap_tol = 0.0_dp
        ! A1 closes at 1/2 of the way, A2 stays open, A3 slips and its trial traction
        ! goes from +1 to -3: zero at 1/4
        pair%accepted = mortar_snapshot_t([1.0_dp, 1.0_dp, -2.0_dp], one, [0.0_dp, 0.0_dp, 1.0_dp], &
                                          [state_inactive, state_inactive, state_slip])
        pair%last = mortar_snapshot_t([-1.0_dp, 0.5_dp, -2.0_dp], one, [0.0_dp, 0.0_dp, -3.0_dp], &
                                      [state_stick, state_inactive, state_slip])
        call check(error, pair%step_limit(1.01_dp), 0.25_dp, 'slip reversal first', &
                   abs=1.0e-15_dp)
        if (allocated(error)) return
        ! without the reversal: the closing, with the overshoot
        pair%last%t_trial(3) = 0.5_dp
        call check(error, pair%step_limit(1.01_dp), 0.505_dp, 'closing', abs=1.0e-15_dp)
        if (allocated(error)) return
        ! a sticking point whose trial traction changes sign, a closed point that
        ! stays closed: nothing the tangent did not describe
        pair%accepted%g(1) = -0.5_dp
        pair%accepted%state(3) = state_stick
        pair%last%t_trial(3) = -3.0_dp
        call check(error, pair%step_limit(1.01_dp), 1.0_dp, 'nothing crossed')
        if (allocated(error)) return
        ! the same reversal in a GPTS pair: no step control
        pair%accepted%state(3) = state_slip
        call check(error, pair%step_limit(1.01_dp) < 1.0_dp, 'mortar: reversal seen')
        if (allocated(error)) return
        call check(error, gpts%step_limit(1.01_dp), 1.0_dp, 'GPTS: no step control')
    end subroutine test_crossing_fraction

    !> A mortar control point none of whose support's slave points has a projection
    !> (the die's edge beyond the slab's start) is open, not active with an empty
    !> weighted gap; every active one has projected points in its support.
    subroutine test_mortar_unprojected_open(error)
        type(error_t), allocatable, intent(out) :: error
        type(model_t) :: model
        real(dp), allocatable :: u(:), r(:)
        logical, allocatable :: seen(:)
        integer :: k, n_unseen
        call two_body_model('NN2.2', 0.0_dp, .false., model, error, 'mortar')
        if (allocated(error)) return
        call penetrating_state(model, u)
        allocate (r(size(u)), source=0.0_dp)
        call model%pairs(1)%pair%evaluate(u, r, error)
        if (allocated(error)) return
        select type (pair => model%pairs(1)%pair)
        type is (mortar_pair_t)
            ! control points whose function is nonzero at a projected slave point
            allocate (seen(size(pair%slave%cps)), source=.false.)
            do k = 1, size(pair%xi)
                if (pair%out(k)%gap < huge(1.0_dp)) &
                    seen(pair%span(k) - pair%slave%degree:pair%span(k)) = .true.
            end do
            n_unseen = count(.not. seen)
            call check(error, n_unseen > 0, 'some control points have no projected point')
            if (allocated(error)) return
            call check(error, all(pair%last%state(pack([(k, k=1, size(seen))], .not. seen)) == state_inactive), &
                       'those are open')
            if (allocated(error)) return
            call check(error, count(pair%last%state /= state_inactive) >= 2, 'others are active')
        class default
            call check(error, .false., 'a mortar pair')
        end select
    end subroutine test_mortar_unprojected_open

    function bc(b, edge, fix, values) result(d)
        character(len=*), intent(in) :: b, edge
        logical, intent(in) :: fix(2)
        real(dp), intent(in) :: values(:, :)
        type(dirichlet_settings_t) :: d
        d%body = b
        d%edge = edge
        d%fix(:2) = fix
        d%values = values
    end function bc

    !> Build a model from a case and the coarse patches of its bodies.
    subroutine build_model(c, coarse, model, error)
        type(scene_t), intent(inout) :: c
        type(nurbs_surface_t), intent(in) :: coarse(:)
        type(model_t), intent(out) :: model
        type(error_t), allocatable, intent(out) :: error
        type(discretization_t), allocatable :: discs(:)
        integer :: i
        allocate (discs(size(coarse)))
        do i = 1, size(coarse)
            call new_discretization(discs(i), coarse(i), c%bodies(i)%layout, '', error)
            if (allocated(error)) return
        end do
        call scene_model(c, discs, model, error)
    end subroutine build_model

    !> Two stacked blocks under uniform pressure. Matching meshes: the contact
    !> pressure is uniform to round-off. Non-matching meshes: its spread is the
    !> quadrature error of GPTS (the master's functions integrated with the
    !> slave's points) and falls as the slave points are refined. Measured spread
    !> (max - min)/mean for 3, 9, 15, 21 points per slave element: 0.22, 5.1e-3,
    !> 1.8e-3, 4.8e-4; matching meshes: 5e-11 (docs/verification.md).
    subroutine test_patch(error)
        type(error_t), allocatable, intent(out) :: error
        real(dp) :: spread(4), prev
        integer :: i
        call patch_spread(5, 3, spread(1), error)
        if (allocated(error)) return
        ! the penalty (1000 x E) amplifies round-off of the displacements
        call check(error, spread(1) <= 1.0e-9_dp, 'matching meshes: uniform contact pressure')
        if (allocated(error)) return
        prev = huge(1.0_dp)
        do i = 1, 4
            call patch_spread(3, 3 + 6*(i - 1), spread(i), error)
            if (allocated(error)) return
            call check(error, spread(i) < prev, 'non-matching: spread falls with more slave points')
            if (allocated(error)) return
            prev = spread(i)
        end do
        call check(error, spread(4) <= 1.0e-3_dp, 'non-matching, 21 points: spread below 0.1%')
    end subroutine test_patch

    !> Upper block (slave, `nel_upper` elements) on a lower one (master, 5
    !> elements); spread of p_N over the slave points with `ngp` points each.
    subroutine patch_spread(nel_upper, ngp, spread, error, method)
        integer, intent(in) :: nel_upper, ngp
        real(dp), intent(out) :: spread
        type(error_t), allocatable, intent(out) :: error
        !> Contact method ('gpts' when absent).
        character(len=*), intent(in), optional :: method
        type(scene_t) :: c
        type(model_t) :: model
        type(solver_stats_t) :: stats
        real(dp), allocatable :: u(:)
        real(dp), parameter :: p = 0.01_dp

        c%bodies = [body_settings('upper', 'linear', 1.0_dp, paper_layout('N2', [nel_upper, 2], 'bottom')), &
                    body_settings('lower', 'linear', 1.0_dp, paper_layout('N2', [5, 2], 'top'))]
        c%solver%n_steps = [1]
        c%dirichlet = [bc('lower', 'bottom', [.false., .true.], reshape([0.0_dp, 0.0_dp], [2, 1])), &
                       bc('lower', 'left', [.true., .false.], reshape([0.0_dp, 0.0_dp], [2, 1])), &
                       bc('upper', 'left', [.true., .false.], reshape([0.0_dp, 0.0_dp], [2, 1]))]
        c%pressure = [pressure_settings_t(body='upper', edge='top', values=[p])]
        allocate (c%contact(1))
        c%contact(1) = contact_settings_t(slave='upper', master='lower', penalty_normal=1000.0_dp, n_gauss=ngp)
        if (present(method)) c%contact(1)%method = method
        call build_model(c, [rectangle(0.0_dp, 1.0_dp, 2.0_dp, 1.0_dp), &
                             rectangle(0.0_dp, 0.0_dp, 2.0_dp, 1.0_dp)], model, error)
        if (allocated(error)) return
        call solve_steps(model, c%solver, u, stats, error)
        if (allocated(error)) return
        associate (out => model%pairs(1)%pair%out)
            call check(error, all(out%state /= state_inactive), 'every slave point in contact')
            if (allocated(error)) return
            spread = (maxval(out%pn) - minval(out%pn))/(sum(out%pn)/size(out))
        end associate
        ! momentum: the contact force carries the applied load exactly
        call check(error, model%pairs(1)%pair%force(2), 2.0_dp*p, 'total contact force = applied load', &
                   rel=1.0e-10_dp)
    end subroutine patch_spread

    !> A block on a rigid plane, pressed then pushed (or barely pushed); with
    !> `tresca_always`, every substep solved by the Tresca fixed point.
    subroutine block_on_plane(push, mu, model, u, error, tresca_always, stats_out, method, phases, stick_predictor)
        real(dp), intent(in) :: push, mu
        type(model_t), intent(out) :: model
        real(dp), allocatable, intent(out) :: u(:)
        type(error_t), allocatable, intent(out) :: error
        logical, intent(in), optional :: tresca_always
        type(solver_stats_t), intent(out), optional :: stats_out
        !> Contact method ('gpts' when absent).
        character(len=*), intent(in), optional :: method
        !> The friction coefficient of each of the two phases (instead of `mu` in both).
        real(dp), intent(in), optional :: phases(2)
        !> `solver_settings_t%stick_predictor` (default: on).
        logical, intent(in), optional :: stick_predictor
        type(scene_t) :: c
        type(solver_stats_t) :: stats
        c%bodies = [body_settings('block', 'linear', 1.0_dp, paper_layout('NN2.2', [4, 2], 'bottom'))]
        c%solver%n_steps = [2, 4]
        c%dirichlet = [bc('block', 'top', [.true., .true.], reshape([0.0_dp, -0.01_dp, push, -0.01_dp], [2, 2]))]
        allocate (c%contact(1))
        c%contact(1) = contact_settings_t(slave='block', master='rigid', rigid_point=[0.0_dp, 0.0_dp, 0.0_dp], &
                                       rigid_normal=[0.0_dp, 1.0_dp, 0.0_dp], penalty_normal=1000.0_dp, &
                                       penalty_tangent=1000.0_dp, friction=mu)
        if (present(method)) c%contact(1)%method = method
        if (present(phases)) then
            c%contact(1)%friction = maxval(phases)
            c%contact(1)%friction_phases = phases
        end if
        if (present(stick_predictor)) c%solver%stick_predictor = stick_predictor
        call build_model(c, [rectangle(0.0_dp, 0.0_dp, 1.0_dp, 1.0_dp)], model, error)
        if (allocated(error)) return
        if (present(tresca_always)) c%solver%tresca_always = tresca_always
        call solve_steps(model, c%solver, u, stats, error)
        if (present(stats_out)) stats_out = stats
    end subroutine block_on_plane

    !> Friction per load phase: the block pressed without friction (phase 1: no
    !> tangential traction, the pair records mu = 0), then pushed with mu = 0.3
    !> (phase 2). Its first sliding substep starts from the stick predictor: with
    !> it and without it the same state (both solve the same incremental problems to
    !> tol_residual), the predictor counted once (the only substep of a frictional
    !> phase without an increment to extrapolate) and no more iterations with it.
    !> The hertz rigid-flat scene where it matters (16 cuts without it) is in
    !> test/python/test_cattaneo.py.
    subroutine test_friction_phases(error)
        type(error_t), allocatable, intent(out) :: error
        type(model_t) :: ma, mb, mc
        type(solver_stats_t) :: sa, sb, sc
        real(dp), allocatable :: ua(:), ub(:), uc(:)
        integer :: ip
        ! one substep of the press: the state after it, frictionless
        call block_on_plane(0.0_dp, 0.0_dp, mc, uc, error, stats_out=sc, phases=[0.0_dp, 0.3_dp])
        if (allocated(error)) return
        call block_on_plane(2.0e-3_dp, 0.0_dp, ma, ua, error, stats_out=sa, phases=[0.0_dp, 0.3_dp])
        if (allocated(error)) return
        call block_on_plane(2.0e-3_dp, 0.0_dp, mb, ub, error, stats_out=sb, phases=[0.0_dp, 0.3_dp], &
                            stick_predictor=.false.)
        if (allocated(error)) return
        call check(error, ma%pairs(1)%pair%law%mu, 0.3_dp, 'phase 2 with friction')
        if (allocated(error)) return
        call check(error, count(ma%pairs(1)%pair%out%state /= state_inactive) > 0 .and. &
                   any(abs(ma%pairs(1)%pair%out%pt) > 0.0_dp), 'phase 2: tangential tractions')
        if (allocated(error)) return
        call check(error, sa%stick_predictions, 1, 'one stick prediction: the first sliding substep')
        if (allocated(error)) return
        call check(error, sb%stick_predictions, 0, 'none when switched off')
        if (allocated(error)) return
        call check(error, sa%iterations <= sb%iterations, 'no more iterations with the predictor')
        if (allocated(error)) return
        call check(error, maxval(abs(ub - ua)) <= 1.0e-8_dp*maxval(abs(ua)), 'same state with and without it')
        if (allocated(error)) return
        ! a run that ends after the press (push 0 in phase 2, which starts stuck):
        ! phase 1 left no tangential traction anywhere
        do ip = 1, size(mc%pairs)
            call check(error, mc%pairs(ip)%pair%law%mu, 0.3_dp, 'friction of the last phase')
            if (allocated(error)) return
        end do
        call check(error, maxval(abs(mc%pairs(1)%pair%out%pt)) <= 1.0e-12_dp*maxval(mc%pairs(1)%pair%out%pn), &
                   'no tangential traction after a frictionless press and no push')
    end subroutine test_friction_phases

    !> The Tresca fixed point of the solver (successive approximations on the slip
    !> bounds; here for every substep, `solver_settings_t%tresca_always`) solves the Coulomb
    !> problem: the block pressed and slid on a rigid plane (mu = 0.3, slipping)
    !> reaches plain Newton's state, and the Coulomb residual there is converged.
    subroutine test_tresca_fixed_point(error)
        type(error_t), allocatable, intent(out) :: error
        type(model_t) :: ma, mb
        type(solver_stats_t) :: sa, sb
        type(assembly_stats_t) :: as
        real(dp), allocatable :: ua(:), ub(:), r(:)
        real(dp) :: rn
        call block_on_plane(0.1_dp, 0.3_dp, ma, ua, error, stats_out=sa)
        if (allocated(error)) return
        call block_on_plane(0.1_dp, 0.3_dp, mb, ub, error, .true., sb)
        if (allocated(error)) return
        call check(error, sa%tresca_retries == 0, 'plain Newton needed no fixed point')
        if (allocated(error)) return
        call check(error, sb%tresca_accepted == sb%substeps .and. sb%tresca_retries == sb%substeps, &
                   'every substep solved by the fixed point')
        if (allocated(error)) return
        call check(error, sb%fixed_point_iterations > sb%substeps, 'some substeps needed several bounds')
        if (allocated(error)) return
        ! both are solutions of the same incremental problems to tol_residual = 1e-10 of
        ! each substep's first residual: they agree far below 1e-8 of the displacement
        call check(error, maxval(abs(ub - ua)) <= 1.0e-8_dp*maxval(abs(ua)), 'same state as plain Newton')
        if (allocated(error)) return
        select type (pair => mb%pairs(1)%pair)
        type is (gpts_pair_t)
            call check(error, .not. allocated(pair%slip_bound), 'back in Coulomb mode')
        end select
        if (allocated(error)) return
        ! the Coulomb residual of the accepted last state (re-evaluated with the committed
        ! anchors: slipping points then sit on the slip limit, the same traction); the
        ! substeps' first residuals are below the force scale r0_max, and the fixed point
        ! accepts at tol_residual = 1e-10 of them or at round-off floors below this
        allocate (r(size(ub)))
        call assemble(mb, ub, 2.0_dp, r, as, error)
        if (allocated(error)) return
        rn = norm2(merge(0.0_dp, r, mb%fixed))
        call check(error, rn <= 1.0e-9_dp*sb%r0_max, 'Coulomb residual converged at the accepted state')
        if (allocated(error)) return
        call check(error, abs(mb%pairs(1)%pair%force(1)), 0.3_dp*abs(mb%pairs(1)%pair%force(2)), 'F_T = mu F_N', &
                   rel=1.0e-8_dp)
    end subroutine test_tresca_fixed_point

    subroutine test_block_slip(error)
        type(error_t), allocatable, intent(out) :: error
        call block_slip(error, 'gpts')
    end subroutine test_block_slip

    !> The same with the mortar-type penalty (its states per control point).
    subroutine test_block_slip_mortar(error)
        type(error_t), allocatable, intent(out) :: error
        call block_slip(error, 'mortar')
    end subroutine test_block_slip_mortar

    !> The block pushed 0.1 over the plane, mu = 0.3: every point (GPTS) or control
    !> point (mortar) in contact slips, and the tangential force is mu times the
    !> normal one, opposing the push.
    subroutine block_slip(error, method)
        type(error_t), allocatable, intent(out) :: error
        character(len=*), intent(in) :: method
        type(model_t) :: model
        real(dp), allocatable :: u(:)
        logical :: slipping
        call block_on_plane(0.1_dp, 0.3_dp, model, u, error, method=method)
        if (allocated(error)) return
        associate (pair => model%pairs(1)%pair)
            select type (pair)
            type is (mortar_pair_t)
                slipping = count(pair%last%state == state_slip) >= 2 .and. all(pair%last%state /= state_stick)
            class default
                ! the leading corner may lift off under the friction moment
                slipping = all(pair%out%state == state_slip .or. pair%out%state == state_inactive) &
                           .and. count(pair%out%state == state_slip) >= size(pair%out) - 2
            end select
            call check(error, slipping, method//': every point in contact slips')
            if (allocated(error)) return
            call check(error, abs(pair%force(1)), 0.3_dp*abs(pair%force(2)), method//': F_T = mu F_N', &
                       rel=1.0e-8_dp)
            if (allocated(error)) return
            call check(error, pair%force(1) < 0.0_dp, method//': friction opposes the push')
        end associate
    end subroutine block_slip

    subroutine test_block_stick(error)
        type(error_t), allocatable, intent(out) :: error
        type(model_t) :: model
        real(dp), allocatable :: u(:)
        real(dp) :: limit
        integer :: k
        call block_on_plane(1.0e-4_dp, 1.0_dp, model, u, error)
        if (allocated(error)) return
        select type (pair => model%pairs(1)%pair)
        type is (gpts_pair_t)
            call check(error, all(pair%out%state == state_stick), 'every point sticks')
            if (allocated(error)) return
            call check(error, abs(pair%force(1)) < abs(pair%force(2)), '|F_T| < mu F_N')
            if (allocated(error)) return
            ! no sliding beyond the penalty's elastic compliance t_T / eps_T
            do k = 1, size(pair%out)
                limit = abs(pair%out(k)%pt)/1000.0_dp*(1.0_dp + 1.0e-8_dp) + 1.0e-15_dp
                call check(error, abs(pair%out(k)%x(1) - pair%out(k)%x0(1) - &
                                      (pair%out(k)%xi_m - pair%out(k)%x0(1))) <= 1.0e-15_dp, &
                           'projection of a point below it on the plane')
                if (allocated(error)) return
                call check(error, abs(pair%out(k)%xi_m - pair%hist%field(pair%h_anchor)%last(k)) <= limit, &
                           'stick: no slip beyond the penalty compliance')
                if (allocated(error)) return
            end do
        end select
    end subroutine test_block_stick

    !> mu = 0: no friction history, no friction evaluation.
    subroutine test_no_friction_code(error)
        type(error_t), allocatable, intent(out) :: error
        call no_friction_code(error, 'gpts')
    end subroutine test_no_friction_code

    subroutine test_no_friction_code_mortar(error)
        type(error_t), allocatable, intent(out) :: error
        call no_friction_code(error, 'mortar')
    end subroutine test_no_friction_code_mortar

    !> A frictionless block pressed onto the plane: no friction history (anchors,
    !> tractions, projections), no friction evaluation, no tangential traction.
    subroutine no_friction_code(error, method)
        type(error_t), allocatable, intent(out) :: error
        character(len=*), intent(in) :: method
        type(model_t) :: model
        real(dp), allocatable :: u(:)
        call block_on_plane(0.0_dp, 0.0_dp, model, u, error, method=method)
        if (allocated(error)) return
        associate (pair => model%pairs(1)%pair)
            call check(error, size(pair%history()) == 0 .and. pair%h_xi == 0, &
                       method//': no friction history stored')
            if (allocated(error)) return
            select type (pair)
            type is (gpts_pair_t)
                call check(error, pair%h_anchor == 0, method//': no anchors')
            type is (mortar_pair_t)
                call check(error, pair%h_traction == 0, method//': no tractions')
            end select
            if (allocated(error)) return
            call check(error, pair%n_friction == 0, method//': no friction evaluation')
            if (allocated(error)) return
            call check(error, pair%n_evaluations > 0, method//': contact evaluated')
            if (allocated(error)) return
            call check(error, all(pair%out%pt == 0.0_dp), method//': no tangential traction')
        end associate
    end subroutine no_friction_code

    !> A rigid master has no DOFs: the model's DOFs are the bodies' only.
    subroutine test_rigid_no_dofs(error)
        type(error_t), allocatable, intent(out) :: error
        type(model_t) :: model
        real(dp), allocatable :: u(:)
        call block_on_plane(0.0_dp, 0.3_dp, model, u, error)
        if (allocated(error)) return
        call check(error, model%ndof, model%bodies(1)%disc%total_dofs, 'DOFs of the body only')
        if (allocated(error)) return
        call check(error, size(model%pairs(1)%pair%master%all_dofs()), 0, 'rigid master couples no DOF')
    end subroutine test_rigid_no_dofs

    !> Frictional ironing (m1, NN2.2): press, then slide; Newton converges
    !> quadratically in a sliding step.
    subroutine test_ironing_quadratic(error)
        type(error_t), allocatable, intent(out) :: error
        call ironing_quadratic(error, 'gpts')
    end subroutine test_ironing_quadratic

    !> The same with the mortar-type penalty: its tangent, with the couplings through
    !> the control-point tractions, is consistent in the sliding phase too.
    subroutine test_ironing_quadratic_mortar(error)
        type(error_t), allocatable, intent(out) :: error
        call ironing_quadratic(error, 'mortar')
    end subroutine test_ironing_quadratic_mortar

    subroutine ironing_quadratic(error, method)
        type(error_t), allocatable, intent(out) :: error
        character(len=*), intent(in) :: method
        type(scene_t) :: c
        type(model_t) :: model
        type(solver_stats_t) :: stats
        type(csc_matrix_t) :: k
        type(assembly_stats_t) :: as
        real(dp), allocatable :: u(:), r(:)
        real(dp) :: floor
        integer :: i

        call small_ironing(method, c, model, error)
        if (allocated(error)) return
        ! the tangent is what is tested: every step starts from the last state (no
        ! predictor of either kind: the stick predictor's start leaves too few
        ! iterations above the round-off floor to see the rate)
        c%solver%predictor = .false.
        c%solver%stick_predictor = .false.
        call solve_steps(model, c%solver, u, stats, error)
        if (allocated(error)) return
        call check(error, count(model%pairs(1)%pair%out%state == state_slip) > 0, method//': points slip while ironing')
        if (allocated(error)) return
        ! the solver's round-off level of the residual at the end (the last iterate of
        ! a step may lie on it: mortar, step 12, 4.1e-14 after 6.1e-10)
        call stiffness_pattern(model, k, error)
        if (allocated(error)) return
        allocate (r(model%ndof))
        call assemble(model, u, 1.0_dp, r, as, error, k)
        if (allocated(error)) return
        ! (both methods: GPTS used only the fixture's cut, 1e-13 of the first residual,
        ! 4e-14 here, while the floor is 2.0e-12; step 13's last residual, round-off
        ! after 3.7e-10, fell on either side of that cut with the rounding of the
        ! linear solver: 4.5e-14 with the supernodal LU, below 4e-14 with UMFPACK's)
        floor = residual_floor(k, reference_coordinates(model) + u, model%fixed)
        do i = 11, 15
            call check(error, quadratic(stats%records(i)%residual_norms, floor), &
                       method//': quadratic convergence, step 11-15')
            if (allocated(error)) then
                print '(a,*(es9.2))', '        residuals: ', stats%records(i)%residual_norms
                return
            end if
        end do
    end subroutine ironing_quadratic

    !> A small frictional ironing scene (Neo-Hookean die on a slab, NN2.2, mu = 0.3):
    !> pressed 0.5 in 10 steps, then 5 of the paper's 200 sliding steps of 0.02.
    subroutine small_ironing(method, c, model, error)
        character(len=*), intent(in) :: method
        type(scene_t), intent(out) :: c
        type(model_t), intent(out) :: model
        type(error_t), allocatable, intent(out) :: error
        c%bodies = [body_settings('die', 'neo-hookean', 10.0_dp, paper_layout('NN2.2', [6, 1], 'outer')), &
                    body_settings('slab', 'neo-hookean', 1.0_dp, paper_layout('NN2.2', [8, 2], 'top'))]
        c%solver%n_steps = [10, 5]
        c%dirichlet = [bc('die', 'inner', [.true., .true.], reshape([0.0_dp, -0.5_dp, 0.1_dp, -0.5_dp], [2, 2])), &
                       bc('slab', 'bottom', [.true., .true.], reshape([0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp], [2, 2]))]
        allocate (c%contact(1))
        c%contact(1) = contact_settings_t(slave='die', master='slab', penalty_normal=100.0_dp, &
                                       penalty_tangent=100.0_dp, friction=0.3_dp, method=method)
        call build_model(c, [annulus_sector([2.5_dp, 3.0_dp], 2.0_dp, 3.0_dp, pi, 2), &
                             rectangle(0.0_dp, -3.0_dp, 9.0_dp, 3.0_dp)], model, error)
    end subroutine small_ironing

    !> The contact part of the stiffness pattern fitted to the configuration
    !> (assemble with refit) is smaller than the whole-master coupling but loses
    !> no entry: the tangent assembled on it equals the one on the full pattern.
    subroutine test_fitted_pattern(error)
        type(error_t), allocatable, intent(out) :: error
        character(len=5), parameter :: layouts(3) = [character(len=5) :: 'N2', 'NN4', 'NN2.2']
        type(model_t) :: model
        type(csc_matrix_t) :: k
        type(assembly_map_t) :: map
        type(assembly_stats_t) :: stats
        real(dp), allocatable :: u(:), r(:), k_full(:, :), k_fit(:, :)
        integer :: il, nnz_full

        do il = 1, size(layouts)
            call two_body_model(trim(layouts(il)), 0.3_dp, .false., model, error)
            if (allocated(error)) return
            call penetrating_state(model, u)
            allocate (r(size(u)))
            call stiffness_pattern(model, k, error)
            if (allocated(error)) return
            call new_assembly_map(model, k, map, error)
            if (allocated(error)) return
            nnz_full = k%nnz()
            call assemble(model, u, 1.0_dp, r, stats, error, k, map)
            if (allocated(error)) return
            k_full = dense(k)
            ! the first assembly of a substep fits the pattern to its configuration
            call assemble(model, u, 1.0_dp, r, stats, error, k, map, refit=.true.)
            if (allocated(error)) return
            call check(error, stats%pattern_rebuilds, 1, trim(layouts(il))//': pattern rebuilds')
            if (allocated(error)) return
            call assemble(model, u, 1.0_dp, r, stats, error, k, map)
            if (allocated(error)) return
            call check(error, stats%pattern_rebuilds, 1, trim(layouts(il))//': rebuilds after assembly '// &
                       '(a miss would rebuild again)')
            if (allocated(error)) return
            call check(error, k%nnz() < nnz_full, trim(layouts(il))//': fitted pattern is smaller')
            if (allocated(error)) return
            call check(error, k%missed, 0, trim(layouts(il))//': entries missed')
            if (allocated(error)) return
            k_fit = dense(k)
            call check(error, maxval(abs(k_fit - k_full))/maxval(abs(k_full)), 0.0_dp, &
                       trim(layouts(il))//': tangent on the fitted pattern vs the full one', abs=1.0e-14_dp)
            if (allocated(error)) return
            deallocate (r)
            stats = assembly_stats_t()
        end do
    contains
        function dense(a) result(d)
            type(csc_matrix_t), intent(in) :: a
            real(dp), allocatable :: d(:, :)
            integer :: j, p
            allocate (d(a%n, a%n))
            d = 0.0_dp
            do j = 1, a%n
                do p = a%colptr(j) + 1, a%colptr(j + 1)
                    d(a%rowind(p) + 1, j) = a%values(p)
                end do
            end do
        end function dense
    end subroutine test_fitted_pattern

    !> The contact-zone counts of the over-constraint diagnosis: open points inside
    !> the zone count as holes only in runs shorter than one slave element; the
    !> control points are those whose functions are nonzero at an active point.
    subroutine test_pair_zone(error)
        type(error_t), allocatable, intent(out) :: error
        type(gpts_pair_t) :: pair
        integer :: n_active, n_holes, n_gaps, n_cp

        ! 3 slave elements of degree 2, 4 points each (knot spans 3, 4, 5)
        pair%n_gauss = 4
        pair%slave%degree = 2
        pair%span = [3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5]
        allocate (pair%out(12))
        call pair%zone(n_active, n_holes, n_gaps, n_cp)
        call check(error, n_active == 0 .and. n_holes == 0 .and. n_gaps == 0 .and. n_cp == 0, &
                   'no contact: all counts 0')
        if (allocated(error)) return
        ! a zone in elements 1-2 broken by the single open points 4 and 6
        pair%out([2, 3, 5, 7, 8])%state = state_slip
        call pair%zone(n_active, n_holes, n_gaps, n_cp)
        call check(error, n_active == 5, 'five active points')
        if (allocated(error)) return
        call check(error, n_holes == 2 .and. n_gaps == 2, 'two single-point holes')
        if (allocated(error)) return
        call check(error, n_cp == 4, 'spans 3..4 of degree 2: 4 control points')
        if (allocated(error)) return
        ! two zones 4 open points (one element) apart, then a 3-point gap
        pair%out%state = state_inactive
        pair%out([1, 2, 7, 8, 12])%state = state_stick
        call pair%zone(n_active, n_holes, n_gaps, n_cp)
        call check(error, n_holes == 3 .and. n_gaps == 1, 'the 4-point gap is not a hole, the 3-point gap is')
        if (allocated(error)) return
        call check(error, n_cp == 5, 'spans 3..5 of degree 2: 5 control points')
    end subroutine test_pair_zone

end module test_contact
