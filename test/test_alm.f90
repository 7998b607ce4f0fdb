!> The augmented Lagrangian (`&contact method = 'alm'`), the automatic penalty and
!> the nominal contact pressure: the tangent at fixed multipliers against finite
!> differences, exact constraints whatever the penalty, one multiplier update per
!> step where the problem is linear, exact stick and Coulomb slip, the penalty
!> chosen when none is given, and the pressure per reference length.
module test_alm
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_testdrive, only: unittest_t, new_unittest, check
    use voiga_model, only: model_t
    use voiga_model_loads, only: pressure_settings_t
    use voiga_contact_factory, only: contact_settings_t
    use voiga_contact_alm, only: alm_pair_t
    use voiga_contact_law, only: state_inactive, state_stick, state_slip
    use voiga_contact_surface, only: element_lengths
    use voiga_solver_records, only: solver_stats_t
    use voiga_solver_stepping, only: solve_steps
    use voiga_test_fixtures, only: paper_layout, rectangle, scene_t, body => body_settings
    use test_contact, only: two_body_model, penetrating_state, contact_fd, bc, build_model
    implicit none
    private

    public :: collect_alm

contains

    subroutine collect_alm(testsuite)
        type(unittest_t), allocatable, intent(out) :: testsuite(:)
        testsuite = [ &
                    new_unittest('alm_tangent_fd', test_tangent_fd), &
                    new_unittest('alm_patch_exact_any_penalty', test_patch_exact), &
                    new_unittest('alm_one_update_when_linear', test_one_update), &
                    new_unittest('alm_friction_stick_and_slip', test_friction), &
                    new_unittest('automatic_penalty', test_automatic_penalty), &
                    new_unittest('alm_soften_to_automatic', test_soften), &
                    new_unittest('nominal_pressure_integrates_to_force', test_nominal_pressure) &
                    ]
    end subroutine collect_alm

    !> At fixed nonzero multipliers the tangent is the derivative of the residual
    !> (frictionless, sticking and slipping control points, deformable master).
    subroutine test_tangent_fd(error)
        type(error_t), allocatable, intent(out) :: error
        type(model_t) :: model
        real(dp), allocatable :: u(:), r(:)
        real(dp) :: mu, shift
        integer :: k, j, want
        do k = 1, 3
            mu = merge(0.0_dp, 0.3_dp, k == 1)
            shift = merge(1.0e-4_dp, 0.5_dp, k < 3)
            want = merge(state_slip, state_stick, k == 3)
            call two_body_model('NN2.2', mu, .false., model, error, 'alm')
            if (allocated(error)) return
            call penetrating_state(model, u)
            allocate (r(size(u)), source=0.0_dp)
            call model%pairs(1)%pair%evaluate(u, r, error)
            if (allocated(error)) return
            select type (pair => model%pairs(1)%pair)
            type is (alm_pair_t)
                ! multipliers of the order of the penalty pressures, varying along the edge
                associate (lambda => pair%hist%field(pair%h_lambda)%trial)
                    lambda = [(0.01_dp*(1.0_dp + 0.5_dp*sin(7.0_dp*j)), j=1, size(lambda))]
                end associate
                if (mu > 0.0_dp) then
                    pair%hist%field(pair%h_active)%last = 1.0_dp
                    pair%hist%field(pair%h_xi)%last = pair%out%xi_m - shift
                    pair%hist%field(pair%h_node_active)%last = 1.0_dp
                    pair%tau = 0.0_dp
                end if
            end select
            deallocate (r)
            call contact_fd(model%pairs(1)%pair, u, want, 'alm', error)
            if (allocated(error)) return
        end do
    end subroutine test_tangent_fd

    !> Upper block pressed by p onto a lower one: on matching meshes the nominal
    !> pressure is p at every slave point; on non-matching ones (where the
    !> quadrature of the weighted gaps over the master's element boundaries leaves a
    !> spread of about 5e-4, as with the mortar-type penalty) the solution does not
    !> depend on the penalty: 1e1 and 1e5 x E give the same displacement.
    subroutine test_patch_exact(error)
        type(error_t), allocatable, intent(out) :: error
        type(model_t) :: soft, stiff
        type(solver_stats_t) :: stats
        real(dp), allocatable :: u_soft(:), u_stiff(:)
        real(dp), parameter :: p = 0.01_dp
        call pressed_blocks(10.0_dp, 0.0_dp, soft, u_soft, stats, error, slave_elements=5)
        if (allocated(error)) return
        associate (out => soft%pairs(1)%pair%out)
            call check(error, all(out%state /= state_inactive), 'every slave point in contact')
            if (allocated(error)) return
            ! the pressure is interpolated from the control points, exact on a uniform field
            call check(error, maxval(abs(out%pn0 - p)), 0.0_dp, 'matching meshes: nominal pressure = p', &
                       abs=1.0e-12_dp)
            if (allocated(error)) return
        end associate
        call pressed_blocks(10.0_dp, 0.0_dp, soft, u_soft, stats, error)
        if (allocated(error)) return
        call pressed_blocks(1.0e5_dp, 0.0_dp, stiff, u_stiff, stats, error)
        if (allocated(error)) return
        ! both solve the same constrained problem to the constraint tolerance (1e-6 of
        ! the element size on displacements of ~1e-2)
        call check(error, maxval(abs(u_soft - u_stiff)), 0.0_dp, 'the same solution at 1e1 and 1e5 x E', &
                   abs=1.0e-8_dp)
    end subroutine test_patch_exact

    !> A linear, frictionless problem with a fixed active set: the Newton step on
    !> the constraints is exact, so each load step needs one multiplier update.
    subroutine test_one_update(error)
        type(error_t), allocatable, intent(out) :: error
        type(model_t) :: model
        type(solver_stats_t) :: stats
        real(dp), allocatable :: u(:)
        call pressed_blocks(100.0_dp, 0.0_dp, model, u, stats, error, n_steps=3)
        if (allocated(error)) return
        call check(error, stats%multiplier_updates, 3, 'one multiplier update per step')
    end subroutine test_one_update

    !> A block pressed onto a rigid plane and pushed: barely pushed with mu = 1 the
    !> middle of its bottom sticks, and does not slip beyond the constraint tolerance
    !> (penalty_tangent 1 x E, where the mortar-type penalty alone lets it slip
    !> elastically by t / eps_T); pushed 0.1 with mu = 0.3 it slides with F_T = mu F_N.
    subroutine test_friction(error)
        type(error_t), allocatable, intent(out) :: error
        type(model_t) :: model
        real(dp), allocatable :: u(:)
        real(dp) :: slip_penalty, slip_alm
        call block_on_plane(1.0e-4_dp, 1.0_dp, 'mortar', model, u, error)
        if (allocated(error)) return
        slip_penalty = middle_slip(model)
        call block_on_plane(1.0e-4_dp, 1.0_dp, 'alm', model, u, error)
        if (allocated(error)) return
        select type (pair => model%pairs(1)%pair)
        type is (alm_pair_t)
            ! the corners carry the singular pressure of a pressed block; the
            ! control points of the middle stick
            call check(error, all(pair%state(4:size(pair%state) - 3) == state_stick), 'the middle sticks')
            if (allocated(error)) return
        end select
        slip_alm = middle_slip(model)
        ! measured: penalty 6.0e-4, augmented Lagrangian 8.4e-6. The constraint holds the
        ! weighted slip of every sticking control point to 2.5e-7 (1e-6 of the element
        ! size); the slip at a point also carries, through the edge's spline, the slip
        ! of the corners' control points, which slide
        call check(error, slip_alm < 0.05_dp*slip_penalty, 'stick: the penalty''s elastic slip is gone')
        if (allocated(error)) return
        call block_on_plane(0.1_dp, 0.3_dp, 'alm', model, u, error)
        if (allocated(error)) return
        associate (pair => model%pairs(1)%pair)
            call check(error, abs(pair%force(1)), 0.3_dp*abs(pair%force(2)), 'F_T = mu F_N', rel=1.0e-8_dp)
            if (allocated(error)) return
            call check(error, pair%force(1) < 0.0_dp, 'friction opposes the push')
        end associate
    end subroutine test_friction

    !> The largest slip along the rigid plane of the slave points in the middle half.
    pure real(dp) function middle_slip(model) result(slip)
        type(model_t), intent(in) :: model
        integer :: k
        slip = 0.0_dp
        associate (out => model%pairs(1)%pair%out)
            do k = 1, size(out)
                if (abs(out(k)%x0(1) - 0.5_dp) <= 0.25_dp) slip = max(slip, abs(out(k)%x(1) - out(k)%x0(1)))
            end do
        end associate
    end function middle_slip

    !> Without penalty_normal the pair gets 10 E* q / h, with E* of both bodies
    !> (1/E* = sum (1 - nu^2)/E), q the slave edge's degree and h its smallest
    !> element; penalty_tangent follows it.
    subroutine test_automatic_penalty(error)
        type(error_t), allocatable, intent(out) :: error
        type(model_t) :: model
        type(solver_stats_t) :: stats
        real(dp), allocatable :: u(:)
        real(dp) :: e_star, h
        call pressed_blocks(0.0_dp, 0.0_dp, model, u, stats, error)
        if (allocated(error)) return
        e_star = 1.0_dp/(2.0_dp*(1.0_dp - 0.3_dp**2)/1.0_dp)
        associate (pair => model%pairs(1)%pair)
            h = minval(element_lengths(pair%slave))
            call check(error, h, 2.0_dp/3.0_dp, 'slave elements 2/3 long', rel=1.0e-12_dp)
            if (allocated(error)) return
            call check(error, pair%law%eps_n, 10.0_dp*e_star*2.0_dp/h, 'penalty_normal = 10 E* q / h', &
                       rel=1.0e-12_dp)
            if (allocated(error)) return
            call check(error, pair%law%eps_t, pair%law%eps_n, 'penalty_tangent = penalty_normal')
        end associate
    end subroutine test_automatic_penalty

    !> After a failed substep an alm pair divides both penalties by 10, the normal one
    !> not below the automatic penalty (then it stops and says nothing changed); a
    !> penalty given below the automatic one, and a pair of another method, never
    !> change. The solution does not depend on them (`alm_patch_exact_any_penalty`).
    subroutine test_soften(error)
        type(error_t), allocatable, intent(out) :: error
        type(model_t) :: model
        type(solver_stats_t) :: stats
        real(dp), allocatable :: u(:)
        character(len=:), allocatable :: text
        real(dp) :: auto, eps
        logical :: changed
        integer :: k
        call pressed_blocks(1.0e5_dp, 0.0_dp, model, u, stats, error)
        if (allocated(error)) return
        associate (pair => model%pairs(1)%pair)
            auto = pair%eps_automatic
            call check(error, auto, 10.0_dp*(1.0_dp/(2.0_dp*(1.0_dp - 0.3_dp**2)))*2.0_dp/(2.0_dp/3.0_dp), &
                       'the automatic penalty is known to the pair', rel=1.0e-12_dp)
            if (allocated(error)) return
            eps = pair%law%eps_n
            do k = 1, 10
                call pair%soften(changed, text)
                if (.not. changed) exit
                call check(error, pair%law%eps_n, max(eps/10.0_dp, auto), 'divided by 10, not below', rel=1.0e-14_dp)
                if (allocated(error)) return
                call check(error, pair%law%eps_t, pair%law%eps_n, 'the tangential one alike', rel=1.0e-14_dp)
                if (allocated(error)) return
                call check(error, index(text, '->') > 0, 'says what changed')
                if (allocated(error)) return
                eps = pair%law%eps_n
            end do
            call check(error, k, 5, '1e5 x E reaches the automatic penalty (15.9) in 4 softenings')
            if (allocated(error)) return
            call check(error, pair%law%eps_n, auto, 'ends at the automatic penalty', rel=1.0e-14_dp)
            if (allocated(error)) return
        end associate
        call pressed_blocks(1.0_dp, 0.0_dp, model, u, stats, error)
        if (allocated(error)) return
        call model%pairs(1)%pair%soften(changed, text)
        call check(error, .not. changed .and. model%pairs(1)%pair%law%eps_n == 1.0_dp, &
                   'a penalty below the automatic one is kept')
        if (allocated(error)) return
        call pressed_blocks(1.0e5_dp, 0.0_dp, model, u, stats, error, method='mortar')
        if (allocated(error)) return
        call model%pairs(1)%pair%soften(changed, text)
        call check(error, .not. changed .and. model%pairs(1)%pair%law%eps_n == 1.0e5_dp, &
                   'a mortar penalty decides the solution: kept')
    end subroutine test_soften

    !> The nominal pressure (per reference length) integrates over the reference
    !> edge to the contact force, for GPTS (whose pressure acts per current length)
    !> and the mortar-type penalty, on blocks compressed by 10 % along the edge.
    subroutine test_nominal_pressure(error)
        type(error_t), allocatable, intent(out) :: error
        character(len=6), parameter :: methods(2) = [character(len=6) :: 'gpts', 'mortar']
        type(model_t) :: model
        type(solver_stats_t) :: stats
        real(dp), allocatable :: u(:)
        real(dp) :: nominal, current
        integer :: im
        do im = 1, 2
            call pressed_blocks(1000.0_dp, 0.1_dp, model, u, stats, error, method=trim(methods(im)))
            if (allocated(error)) return
            associate (pair => model%pairs(1)%pair)
                ! the slave edge is straight: |dX/dxi| = its length 2
                nominal = sum(pair%out%pn0*pair%w)*2.0_dp
                current = sum(pair%out%pn*pair%out%stretch*pair%w)*2.0_dp
                ! (F_y = int p_n0 n_y dA0: the master edge bends slightly under the
                ! pressure, n_y = 1 - O(slope^2))
                call check(error, nominal, pair%force(2), trim(methods(im))//': int p_n0 dA0 = F', rel=1.0e-8_dp)
                if (allocated(error)) return
                call check(error, current, nominal, trim(methods(im))//': p_n0 = p_n x stretch', rel=1.0e-12_dp)
                if (allocated(error)) return
                call check(error, maxval(pair%out%stretch) < 0.95_dp, trim(methods(im))// &
                           ': the edge is compressed')
                if (allocated(error)) return
            end associate
        end do
    end subroutine test_nominal_pressure

    !> Upper block (slave, 3 or `slave_elements` elements) pressed by p = 0.01 onto a lower one (master,
    !> 5 elements), both linear; penalty `eps` x E (0: automatic); the upper block's
    !> left edge pushed by `squeeze` x its width along x (compressing it along the edge).
    subroutine pressed_blocks(eps, squeeze, model, u, stats, error, n_steps, method, slave_elements)
        real(dp), intent(in) :: eps, squeeze
        type(model_t), intent(out) :: model
        real(dp), allocatable, intent(out) :: u(:)
        type(solver_stats_t), intent(out) :: stats
        type(error_t), allocatable, intent(out) :: error
        integer, intent(in), optional :: n_steps
        character(len=*), intent(in), optional :: method
        !> Elements along the slave edge (default 3; 5 matches the master).
        integer, intent(in), optional :: slave_elements
        type(scene_t) :: c
        integer :: ns
        ns = 3
        if (present(slave_elements)) ns = slave_elements
        c%bodies = [body('upper', 'linear', 1.0_dp, paper_layout('N2', [ns, 2], 'bottom')), &
                    body('lower', 'linear', 1.0_dp, paper_layout('N2', [5, 2], 'top'))]
        c%solver%n_steps = [1]
        if (present(n_steps)) c%solver%n_steps = [n_steps]
        c%dirichlet = [bc('lower', 'bottom', [.false., .true.], reshape([0.0_dp, 0.0_dp], [2, 1])), &
                       bc('lower', 'left', [.true., .false.], reshape([0.0_dp, 0.0_dp], [2, 1])), &
                       bc('upper', 'left', [.true., .false.], reshape([0.0_dp, 0.0_dp], [2, 1]))]
        if (squeeze > 0.0_dp) c%dirichlet = [c%dirichlet, &
                                             bc('upper', 'right', [.true., .false.], &
                                                reshape([-2.0_dp*squeeze, 0.0_dp], [2, 1])), &
                                             bc('lower', 'right', [.true., .false.], &
                                                reshape([-2.0_dp*squeeze, 0.0_dp], [2, 1]))]
        c%pressure = [pressure_settings_t(body='upper', edge='top', values=[0.01_dp])]
        allocate (c%contact(1))
        ! the constraints to 1e-10 of the element size: differences between solutions
        ! are then round-off
        c%contact(1) = contact_settings_t(slave='upper', master='lower', penalty_normal=eps, n_gauss=9, &
                                          method='alm', tolerance=1.0e-10_dp)
        if (present(method)) c%contact(1)%method = method
        call build_model(c, [rectangle(0.0_dp, 1.0_dp, 2.0_dp, 1.0_dp), &
                             rectangle(0.0_dp, 0.0_dp, 2.0_dp, 1.0_dp)], model, error)
        if (allocated(error)) return
        call solve_steps(model, c%solver, u, stats, error)
    end subroutine pressed_blocks

    !> A linear block (NN2.2, 4 x 2 elements) pressed 0.01 onto a rigid plane, then
    !> pushed by `push` along it, friction `mu`, penalties 1e1 (normal) and 1 x E
    !> (tangential), contact method `method`.
    subroutine block_on_plane(push, mu, method, model, u, error)
        real(dp), intent(in) :: push, mu
        character(len=*), intent(in) :: method
        type(model_t), intent(out) :: model
        real(dp), allocatable, intent(out) :: u(:)
        type(error_t), allocatable, intent(out) :: error
        type(scene_t) :: c
        type(solver_stats_t) :: stats
        c%bodies = [body('block', 'linear', 1.0_dp, paper_layout('NN2.2', [4, 2], 'bottom'))]
        c%solver%n_steps = [2, 4]
        c%dirichlet = [bc('block', 'top', [.true., .true.], reshape([0.0_dp, -0.01_dp, push, -0.01_dp], [2, 2]))]
        allocate (c%contact(1))
        c%contact(1) = contact_settings_t(slave='block', master='rigid', rigid_point=[0.0_dp, 0.0_dp, 0.0_dp], &
                                          rigid_normal=[0.0_dp, 1.0_dp, 0.0_dp], penalty_normal=10.0_dp, &
                                          penalty_tangent=1.0_dp, friction=mu, method=method)
        call build_model(c, [rectangle(0.0_dp, 0.0_dp, 1.0_dp, 1.0_dp)], model, error)
        if (allocated(error)) return
        call solve_steps(model, c%solver, u, stats, error)
    end subroutine block_on_plane

end module test_alm
