!> Rigid obstacles bounded by a NURBS curve (`voiga_contact_master_curve`): the
!> closest-point projection on an exact circle, its translation, the contact
!> tangent against finite differences (GPTS and mortar, frictionless, stick and
!> slip), and a punch driven by its prescribed motion against the same relative
!> motion applied to the block.
module test_rigid
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_testdrive, only: unittest_t, new_unittest, check
    use voiga_nurbs_curve, only: nurbs_curve_t
    use voiga_nurbs_surface, only: nurbs_surface_t
    use voiga_contact_master, only: master_point_t
    use voiga_contact_master_curve, only: rigid_curve_t, new_rigid_curve
    use voiga_contact_law, only: state_stick, state_slip
    use voiga_contact_factory, only: contact_settings_t
    use voiga_discretization_patch, only: discretization_t, new_discretization
    use voiga_model, only: model_t
    use voiga_model_loads, only: dirichlet_settings_t
    use voiga_solver_records, only: solver_stats_t
    use voiga_solver_stepping, only: solve_steps
    use voiga_test_fixtures, only: annulus_sector, rectangle, lcg_t, paper_layout, scene_t, scene_model, &
                                   body_settings
    use test_contact, only: run_fd
    implicit none
    private

    public :: collect_rigid, circle_arc

    real(dp), parameter :: pi = acos(-1.0_dp)

contains

    subroutine collect_rigid(testsuite)
        type(unittest_t), allocatable, intent(out) :: testsuite(:)
        testsuite = [ &
                    new_unittest('rigid_curve_projection', test_projection), &
                    new_unittest('rigid_curve_motion', test_motion), &
                    new_unittest('tangent_fd_rigid_curve', test_fd_curve), &
                    new_unittest('mortar_tangent_fd_rigid_curve', test_fd_curve_mortar), &
                    new_unittest('rigid_curve_punch_moves_as_the_block', test_punch_relative) &
                    ]
    end subroutine collect_rigid

    !> The circle of centre `c` and radius `r` from angle `a0` over `nq` quarter
    !> turns, counter-clockwise (exact rational quadratic arcs): the boundary of the
    !> disc as an obstacle (on its left).
    function circle_arc(c, r, a0, nq) result(curve)
        real(dp), intent(in) :: c(2), r, a0
        integer, intent(in) :: nq
        type(nurbs_curve_t) :: curve
        type(nurbs_surface_t) :: s
        s = annulus_sector(c, 0.5_dp*r, r, a0, nq)
        curve%degree = s%degree(1)
        curve%knots = s%knots_xi
        curve%cp = s%cp(:, :, 2)
        curve%w = s%w(:, 2)
    end function circle_arc

    !> Points around the upper half circle (radius 2) project onto it exactly: the
    !> closest point along the ray from the centre, the gap |x| - 2, the outward
    !> (radial) normal, no master functions; beyond the arc's ends, no projection.
    subroutine test_projection(error)
        type(error_t), allocatable, intent(out) :: error
        type(rigid_curve_t) :: m
        type(master_point_t) :: mp
        type(lcg_t) :: rng
        real(dp) :: xs(2), ang, rad, n(2), u(4)
        logical :: found, converged
        integer :: i
        call new_rigid_curve(m, circle_arc([0.0_dp, 0.0_dp], 2.0_dp, 0.0_dp, 2))
        u = 0.0_dp
        call m%prepare(u)
        do i = 1, 200
            ang = pi*(0.02_dp + 0.96_dp*rng%uniform())
            rad = 1.5_dp + 1.5_dp*rng%uniform()
            xs = rad*[cos(ang), sin(ang)]
            call m%project(u, xs, mp, found, converged)
            call check(error, found .and. converged, 'a point over the arc projects')
            if (allocated(error)) return
            n = [cos(ang), sin(ang)]
            ! the closest point, normal and gap of an exact circle (round-off of the
            ! rational evaluation and the Newton iteration: 1e-12)
            call check(error, maxval(abs(mp%x(1:2) - 2.0_dp*n)), 0.0_dp, 'closest point on the circle', abs=1.0e-12_dp)
            if (allocated(error)) return
            call check(error, maxval(abs(mp%n(1:2) - n)), 0.0_dp, 'outward radial normal', abs=1.0e-12_dp)
            if (allocated(error)) return
            call check(error, dot_product(xs - mp%x(1:2), mp%n(1:2)), rad - 2.0_dp, 'gap |x| - r', abs=1.0e-12_dp)
            if (allocated(error)) return
            call check(error, size(mp%r) == 0 .and. size(mp%dofs) == 0 .and. mp%first > mp%last, &
                       'no master functions')
            if (allocated(error)) return
        end do
        do i = 1, 20
            ang = -pi*(0.05_dp + 0.4_dp*rng%uniform())
            xs = 2.5_dp*[cos(ang), sin(ang)]
            call m%project(u, xs, mp, found, converged)
            call check(error, .not. found, 'below the arc: no orthogonal projection')
            if (allocated(error)) return
        end do
        call check(error, size(m%all_dofs()) == 0 .and. .not. m%deformable, 'a rigid curve has no DOFs')
    end subroutine test_projection

    !> `move(d)` translates the obstacle: a point moved with it projects at the same
    !> parameter, onto the moved point, with the same normal and gap.
    subroutine test_motion(error)
        type(error_t), allocatable, intent(out) :: error
        type(rigid_curve_t) :: m
        type(master_point_t) :: mp0, mp1
        real(dp), parameter :: d(2) = [0.3_dp, -0.7_dp], xs(2) = [0.4_dp, 2.6_dp]
        real(dp) :: u(4)
        logical :: found, converged
        call new_rigid_curve(m, circle_arc([0.0_dp, 0.0_dp], 2.0_dp, 0.0_dp, 2))
        u = 0.0_dp
        call m%prepare(u)
        call m%project(u, xs, mp0, found, converged)
        call m%move(d)
        call m%prepare(u)
        call m%project(u, xs + d, mp1, found, converged)
        call check(error, found, 'the moved point projects')
        if (allocated(error)) return
        call check(error, mp1%xi, mp0%xi, 'same parameter', abs=1.0e-13_dp)
        if (allocated(error)) return
        call check(error, maxval(abs(mp1%x(1:2) - mp0%x(1:2) - d)), 0.0_dp, 'point moved by d', abs=1.0e-13_dp)
        if (allocated(error)) return
        call check(error, maxval(abs(mp1%n - mp0%n)), 0.0_dp, 'same normal', abs=1.0e-13_dp)
        if (allocated(error)) return
        call m%move([0.0_dp, 0.0_dp])
        call check(error, maxval(abs(m%surf%x0 - m%x_ref)), 0.0_dp, 'back at the reference position')
    end subroutine test_motion

    !> The bump under the die: the circle of radius 20 through the die's lowest point
    !> (curved, |dx/dxi| not 1: every term of the tangent with a2 and |a|).
    function bump() result(curve)
        type(nurbs_curve_t) :: curve
        curve = circle_arc([2.5_dp, -20.0_dp], 20.0_dp, 0.25_dp*pi, 1)
    end function bump

    !> GPTS on a rigid curve: tangent vs central differences, frictionless, stick, slip.
    subroutine test_fd_curve(error)
        type(error_t), allocatable, intent(out) :: error
        call run_fd([character(len=5) :: 'N2', 'NN2.2'], 0.0_dp, .true., 0.0_dp, state_stick, error, curve=bump())
        if (allocated(error)) return
        ! |dx/dxi| = 31 on the bump: a shift of 1e-6 in xi is 3e-5 along it (the line's
        ! test shifts 1e-3), well inside the stick cone
        call run_fd([character(len=5) :: 'N3', 'NN4'], 0.3_dp, .true., 1.0e-6_dp, state_stick, error, &
                    curve=bump())
        if (allocated(error)) return
        call run_fd([character(len=5) :: 'N4', 'NN2.2'], 0.3_dp, .true., 0.05_dp, state_slip, error, curve=bump())
    end subroutine test_fd_curve

    !> The same with the mortar-type penalty.
    subroutine test_fd_curve_mortar(error)
        type(error_t), allocatable, intent(out) :: error
        call run_fd([character(len=5) :: 'N2', 'NN2.2'], 0.0_dp, .true., 0.0_dp, state_stick, error, &
                    method='mortar', curve=bump())
        if (allocated(error)) return
        call run_fd([character(len=5) :: 'N4', 'NN2.2'], 0.3_dp, .true., 0.05_dp, state_slip, error, &
                    method='mortar', curve=bump())
    end subroutine test_fd_curve_mortar

    !> A rigid cylinder (radius 1) pressed 0.05 into a 2 x 1 block (linear, NN2.2,
    !> bottom fixed) by its prescribed motion gives the state of the fixed cylinder
    !> with the block's bottom lifted by 0.05: the same contact force (equal to the
    !> reaction) and the block's displacement shifted by the rigid translation, to
    !> round-off; the obstacle adds no DOF and no stiffness block.
    subroutine test_punch_relative(error)
        type(error_t), allocatable, intent(out) :: error
        real(dp), parameter :: d = 0.05_dp
        type(model_t) :: moved, fixed
        real(dp), allocatable :: u_moved(:), u_fixed(:)
        real(dp) :: f_moved(2), f_fixed(2), reaction(2)
        call punch_run(.true., moved, u_moved, reaction, error)
        if (allocated(error)) return
        call check(error, moved%ndof == 2*moved%bodies(1)%disc%ncp .and. moved%pairs(1)%pair%n_blocks() == 0, &
                   'the obstacle adds no DOF and no stiffness block')
        if (allocated(error)) return
        f_moved = moved%pairs(1)%pair%force(1:2)
        call check(error, f_moved(2) < -1.0e-3_dp, 'the punch presses the block')
        if (allocated(error)) return
        ! equilibrium: the support carries the contact force (to the Newton tolerance)
        call check(error, maxval(abs(f_moved + reaction)), 0.0_dp, 'contact force = reaction', &
                   abs=1.0e-9_dp*abs(f_moved(2)))
        if (allocated(error)) return
        ! symmetry about x = 1
        call check(error, abs(f_moved(1)), 0.0_dp, 'no horizontal force', abs=1.0e-9_dp*abs(f_moved(2)))
        if (allocated(error)) return
        call punch_run(.false., fixed, u_fixed, reaction, error)
        if (allocated(error)) return
        f_fixed = fixed%pairs(1)%pair%force(1:2)
        call check(error, maxval(abs(f_moved - f_fixed)), 0.0_dp, 'same contact force', &
                   abs=1.0e-9_dp*abs(f_fixed(2)))
        if (allocated(error)) return
        u_fixed(2::2) = u_fixed(2::2) - d
        call check(error, maxval(abs(u_moved - u_fixed)), 0.0_dp, 'displacement shifted by the translation', &
                   abs=1.0e-10_dp)
    contains
        !> Press the block: the cylinder moved down (`move`), or the block's bottom up.
        subroutine punch_run(move, model, u, reaction, error)
            logical, intent(in) :: move
            type(model_t), intent(out) :: model
            real(dp), allocatable, intent(out) :: u(:)
            real(dp), intent(out) :: reaction(2)
            type(error_t), allocatable, intent(out) :: error
            type(scene_t) :: c
            type(discretization_t) :: disc(1)
            type(solver_stats_t) :: stats
            c%bodies = [body_settings('block', 'linear', 1.0_dp, paper_layout('NN2.2', [16, 6], 'top'))]
            c%solver%n_steps = [3]
            c%contact = [contact_settings_t(slave='block', master='rigid', rigid_curve='punch', &
                                            penalty_normal=1000.0_dp)]
            c%contact(1)%curve = circle_arc([1.0_dp, 1.0_dp], 1.0_dp, pi, 2)
            allocate (c%dirichlet(1))
            c%dirichlet(1) = dirichlet_settings_t(body='block', edge='bottom', fix=[.true., .true., .false.])
            if (move) then
                c%contact(1)%rigid_motion = reshape([0.0_dp, -d, 0.0_dp], [3, 1])
                c%dirichlet(1)%values = reshape([0.0_dp, 0.0_dp], [2, 1])
            else
                c%dirichlet(1)%values = reshape([0.0_dp, d], [2, 1])
            end if
            call new_discretization(disc(1), rectangle(0.0_dp, -1.0_dp, 2.0_dp, 1.0_dp), c%bodies(1)%layout, &
                                    '', error)
            if (allocated(error)) return
            call scene_model(c, disc, model, error)
            if (allocated(error)) return
            call solve_steps(model, c%solver, u, stats, error)
            if (allocated(error)) return
            reaction = stats%records(size(stats%records))%reactions(:, 1)
        end subroutine punch_run
    end subroutine test_punch_relative

end module test_rigid
