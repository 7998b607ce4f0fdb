!> Contact on a solid's face (issue 42, the first step: frictionless GPTS against a
!> rigid plane): the contact tangent of a curved face (a cylinder, with and without
!> a VO layer) against finite differences, and the pair's geometry (reference area
!> of the points, the plane's frame).
module test_contact_3d
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_testdrive, only: unittest_t, new_unittest, check
    use voiga_discretization_patch, only: discretization_t, new_discretization
    use voiga_discretization_layout, only: layout_t
    use voiga_contact_factory, only: contact_settings_t
    use voiga_contact_law, only: contact_law_t, control_point_law3, state_stick, state_slip
    use voiga_contact_gpts, only: gpts_pair_t
    use voiga_contact_mortar, only: mortar_pair_t
    use voiga_contact_master_face, only: rigid_surface_t, face_master_t
    use voiga_contact_segment_faces, only: segment_face_pair_t, default_face_segment_points
    use voiga_contact_pair, only: history_item_t
    use voiga_contact_master_rigid, only: rigid_line_t, new_rigid_line
    use voiga_model, only: model_t
    use voiga_test_fixtures, only: ring_block, layout3, scene_t, scene_model, body_settings, lcg_t
    use voiga_nurbs_patch, only: nurbs_patch_t, new_patch, knots_t
    use test_contact, only: contact_fd
    use voiga_text, only: str
    implicit none
    private

    public :: collect_contact_3d
    !> For the augmented Lagrangian's tests on faces (`test_alm_faces`).
    public :: ring_on_plane, unit_box, box_faces, mortar_friction_state

    !> The quarter ring's faces (`ring_block`): r = 1, r = 2, theta = 0, theta = 90 deg,
    !> z = 0, z = 1.
    character(len=32), parameter :: faces(6) = [character(len=32) :: 'inner', 'outer', 'start', 'end', &
                                                 'bottom', 'top']

    !> A box's faces: x = x0, x1, y = y0, y1, z = z0, z1.
    character(len=32), parameter :: box_faces(6) = [character(len=32) :: 'left', 'right', 'front', 'back', &
                                                     'bottom', 'top']

contains

    subroutine collect_contact_3d(testsuite)
        type(unittest_t), allocatable, intent(out) :: testsuite(:)
        testsuite = [ &
                    new_unittest('contact_3d_tangent_fd', test_tangent_fd), &
                    new_unittest('contact_3d_tangent_fd_deformable', test_tangent_fd_deformable), &
                    new_unittest('segment_faces_pieces', test_segment_pieces), &
                    new_unittest('segment_faces_tangent_fd_curved', test_segment_curved), &
                    new_unittest('segment_faces_history', test_segment_history), &
                    new_unittest('contact_3d_friction_tangent_fd', test_friction_fd), &
                    new_unittest('contact_3d_mortar_friction_fd', test_mortar_friction_fd), &
                    new_unittest('contact_3d_mortar_friction_fd_deformable', test_mortar_friction_fd_deformable), &
                    new_unittest('contact_3d_mortar_law_at_zero_pressure', test_law3_zero_pressure), &
                    new_unittest('rigid_surface_flat_is_the_plane', test_flat_surface), &
                    new_unittest('rigid_surface_tangent_fd', test_surface_fd), &
                    new_unittest('contact_3d_face_area', test_face_area), &
                    new_unittest('rigid_plane_frame', test_plane_frame) &
                    ]
    end subroutine collect_contact_3d

    !> The quarter ring (E = 1) whose outer cylinder r = 2 is the slave face, against
    !> the tilted plane through (1.9, 0, 0.5) whose obstacle lies beyond it (outward
    !> normal towards the ring): the cylinder's points near theta = 0 penetrate.
    subroutine ring_on_plane(layout, model, error, mu, method)
        type(layout_t), intent(in) :: layout
        type(model_t), intent(out) :: model
        type(error_t), allocatable, intent(out) :: error
        !> Coulomb's coefficient (default 0).
        real(dp), intent(in), optional :: mu
        !> The contact method (default 'gpts').
        character(len=*), intent(in), optional :: method
        type(scene_t) :: c
        type(discretization_t) :: discs(1)
        type(contact_settings_t) :: contact
        c%bodies = [body_settings('ring', 'linear', 1.0_dp, layout)]
        contact%slave = 'ring'
        contact%master = 'rigid'
        contact%method = 'gpts'
        if (present(method)) contact%method = method
        contact%rigid_point = [1.9_dp, 0.0_dp, 0.5_dp]
        contact%rigid_normal = [-1.0_dp, -0.2_dp, 0.1_dp]
        contact%point_components = 3
        contact%normal_components = 3
        if (present(mu)) contact%friction = mu
        c%contact = [contact]
        call new_discretization(discs(1), ring_block(), faces, layout, '', error)
        if (allocated(error)) return
        call scene_model(c, discs, model, error)
    end subroutine ring_on_plane

    !> K of the pair against central differences of its residual at a perturbed
    !> state (every DOF moved by up to 1e-3): the normal penalty, the area element of
    !> the slave's face and its rotation; N2, a layer of degree 3 (NN3) and NN3.1,
    !> with 2 and 3 Gauss points per direction.
    subroutine test_tangent_fd(error)
        type(error_t), allocatable, intent(out) :: error
        type(layout_t) :: layouts(3)
        type(model_t) :: model
        type(lcg_t) :: rng
        real(dp), allocatable :: u(:)
        integer :: il, j
        layouts = [layout3(2, [2, 3, 2], 0, 0, 'outer'), layout3(2, [1, 2, 2], 3, 0, 'outer'), &
                   layout3(2, [1, 2, 1], 3, 1, 'outer')]
        do il = 1, size(layouts)
            call ring_on_plane(layouts(il), model, error)
            if (allocated(error)) return
            allocate (u(model%ndof))
            do j = 1, size(u)
                u(j) = 1.0e-3_dp*(2.0_dp*rng%uniform() - 1.0_dp)
            end do
            call contact_fd(model%pairs(1)%pair, u, state_stick, 'ring layout '//char(48 + il), error)
            if (allocated(error)) return
            deallocate (u)
        end do
    end subroutine test_tangent_fd

    !> Two blocks, the upper one's bottom face (slave) pressed 0.02 into the lower
    !> one's top face (master), non-matching, at a perturbed state (every DOF moved by
    !> up to 2e-3, so both faces are curved and the master's tangents and curvature
    !> enter): K of the pair against central differences, GPTS, mortar and segment (on
    !> the reference state's segments), N2 and NN3.
    subroutine test_tangent_fd_deformable(error)
        type(error_t), allocatable, intent(out) :: error
        character(len=7), parameter :: methods(3) = [character(len=7) :: 'gpts', 'mortar', 'segment']
        type(scene_t) :: c
        type(discretization_t) :: discs(2)
        type(contact_settings_t) :: contact
        type(model_t) :: model
        type(lcg_t) :: rng
        real(dp), allocatable :: u(:)
        integer :: im, iq, j
        do im = 1, size(methods)
            do iq = 0, 3, 3
                c%bodies = [body_settings('upper', 'linear', 1.0_dp, layout3(2, [2, 2, 1], iq, 0, 'bottom')), &
                            body_settings('lower', 'linear', 1.0_dp, layout3(2, [3, 2, 1], 0, 0, 'top'))]
                contact%slave = 'upper'
                contact%master = 'lower'
                contact%method = methods(im)
                c%contact = [contact]
                call new_discretization(discs(1), unit_box(-0.02_dp), box_faces, c%bodies(1)%layout, '', error)
                if (allocated(error)) return
                call new_discretization(discs(2), unit_box(-1.0_dp), box_faces, c%bodies(2)%layout, '', error)
                if (allocated(error)) return
                call scene_model(c, discs, model, error)
                if (allocated(error)) return
                allocate (u(model%ndof))
                do j = 1, size(u)
                    u(j) = 2.0e-3_dp*(2.0_dp*rng%uniform() - 1.0_dp)
                end do
                call contact_fd(model%pairs(1)%pair, u, state_stick, trim(methods(im))//' blocks, layer '// &
                                char(48 + iq), error)
                if (allocated(error)) return
                deallocate (u)
            end do
        end do
        ! the pattern's master ranges start from the reference projections: on a finer
        ! master (40 x 8 cells) a slave cell is not coupled with all of it, and its range
        ! is a rectangle of the master's grid, not the band of whole rows between its
        ! corners (fewer control points than that band)
        c%bodies(2)%layout = layout3(2, [40, 8, 1], 0, 0, 'top')
        call new_discretization(discs(2), unit_box(-1.0_dp), box_faces, c%bodies(2)%layout, '', error)
        if (allocated(error)) return
        call scene_model(c, discs, model, error)
        if (allocated(error)) return
        associate (pair => model%pairs(1)%pair)
            call check(error, all(pair%mhi - pair%mlo + 1 < size(pair%master%all_dofs())/3), &
                       'no slave cell coupled with the whole master face')
            if (allocated(error)) return
            call check(error, sum([(size(pair%range_ids(j)), j=1, size(pair%mlo))]) < sum(pair%mhi - pair%mlo + 1), &
                       'the ranges are rectangles of the master grid, narrower than bands of rows')
        end associate
    end subroutine test_tangent_fd_deformable

    !> Coulomb friction on the tangent plane: every point in contact at the last
    !> converged state, anchored `shift` (in both master coordinates) behind its present
    !> projection; K against central differences when every point sticks (mu = 0.5, a
    !> shift of 1e-5) and when every point slips (mu = 0.3, 0.05), on the ring against
    !> the tilted plane (N2, NN3) and in Tresca mode (a fixed bound of 0.2 mu p_N, the
    !> outer loop's); and a point that touched in this step (open at the last converged
    !> state with a gap of 1e-3 there: only the slip after the touch counts).
    subroutine test_friction_fd(error)
        type(error_t), allocatable, intent(out) :: error
        type(layout_t) :: layouts(2)
        integer :: il
        layouts = [layout3(2, [2, 3, 2], 0, 0, 'outer'), layout3(2, [1, 2, 2], 3, 0, 'outer')]
        do il = 1, 2
            call friction_fd(layouts(il), 0.5_dp, 1.0e-5_dp, state_stick, 'stick', error)
            if (allocated(error)) return
            call friction_fd(layouts(il), 0.3_dp, 0.05_dp, state_slip, 'slip', error)
            if (allocated(error)) return
        end do
        call friction_fd(layouts(1), 0.3_dp, 0.05_dp, state_slip, 'tresca', error, tresca=0.2_dp)
        if (allocated(error)) return
        call friction_fd(layouts(2), 0.5_dp, 1.0e-5_dp, state_stick, 'touch', error, touch=1.0e-3_dp)
    end subroutine test_friction_fd

    subroutine friction_fd(layout, mu, shift, want, label, error, tresca, touch)
        type(layout_t), intent(in) :: layout
        real(dp), intent(in) :: mu, shift
        integer, intent(in) :: want
        character(len=*), intent(in) :: label
        type(error_t), allocatable, intent(out) :: error
        real(dp), intent(in), optional :: tresca, touch
        type(model_t) :: model
        type(lcg_t) :: rng
        real(dp), allocatable :: u(:), r(:)
        integer :: j
        call ring_on_plane(layout, model, error, mu)
        if (allocated(error)) return
        allocate (u(model%ndof), r(model%ndof))
        do j = 1, size(u)
            u(j) = 1.0e-3_dp*(2.0_dp*rng%uniform() - 1.0_dp)
        end do
        r = 0.0_dp
        call model%pairs(1)%pair%evaluate(u, r, error)
        if (allocated(error)) return
        select type (pair => model%pairs(1)%pair)
        type is (gpts_pair_t)
            associate (h => pair%hist%field)
                h(pair%h_active)%last = 1.0_dp
                h(pair%h_anchor)%last = pair%out%xi_m - shift
                h(pair%h_anchor_eta)%last = pair%out%eta_m - shift
                if (present(tresca)) pair%slip_bound = tresca*mu*max(0.0_dp, pair%out%pn)
                if (present(touch)) then
                    h(pair%h_active)%last = 0.0_dp
                    h(pair%h_xi)%last = pair%out%xi_m - shift
                    h(pair%h_eta)%last = pair%out%eta_m - shift
                    h(pair%h_gap)%last = touch
                end if
            end associate
        class default
            call check(error, .false., 'a GPTS pair')
            return
        end select
        call contact_fd(model%pairs(1)%pair, u, want, 'friction '//label, error)
    end subroutine friction_fd

    !> The mortar-type pair's Coulomb friction on a face (a traction vector per slave
    !> control point, `mortar_faces.f90`): every point had a projection at the last
    !> converged state `shift` behind its present one in both master coordinates, every
    !> control point was in contact with a committed traction of 0.2 mu p_A in a direction
    !> off the tangent plane; K against central differences when every control point
    !> sticks (mu = 0.5, 1e-5) and slips (mu = 0.3, 0.05) on the ring against the tilted
    !> plane (N2, NN3), and for control points that touched in this step (open at the
    !> last converged state at mean gap 1e-3: only the slip after the touch counts).
    subroutine test_mortar_friction_fd(error)
        type(error_t), allocatable, intent(out) :: error
        type(layout_t) :: layouts(2)
        type(model_t) :: model
        real(dp), allocatable :: u(:)
        integer :: il
        layouts = [layout3(2, [2, 3, 2], 0, 0, 'outer'), layout3(2, [1, 2, 2], 3, 0, 'outer')]
        do il = 1, 2
            call ring_on_plane(layouts(il), model, error, 0.5_dp, 'mortar')
            if (allocated(error)) return
            call mortar_friction_state(model, 1.0e-3_dp, 1.0e-5_dp, u, error)
            if (allocated(error)) return
            call contact_fd(model%pairs(1)%pair, u, state_stick, 'mortar friction stick '//str(il), error)
            if (allocated(error)) return
            call ring_on_plane(layouts(il), model, error, 0.3_dp, 'mortar')
            if (allocated(error)) return
            call mortar_friction_state(model, 1.0e-3_dp, 0.05_dp, u, error)
            if (allocated(error)) return
            call contact_fd(model%pairs(1)%pair, u, state_slip, 'mortar friction slip '//str(il), error)
            if (allocated(error)) return
        end do
        call ring_on_plane(layouts(2), model, error, 0.5_dp, 'mortar')
        if (allocated(error)) return
        call mortar_friction_state(model, 1.0e-3_dp, 1.0e-5_dp, u, error, touch=1.0e-3_dp)
        if (allocated(error)) return
        call contact_fd(model%pairs(1)%pair, u, state_stick, 'mortar friction touch', error)
    end subroutine test_mortar_friction_fd

    !> The two blocks of `test_tangent_fd_deformable` (N2 on 3 x 2 cells) with friction,
    !> mortar and segment (its points cut at the master's cells): the master's tangents
    !> and curvature enter the slip and the projection of the traction; stick and slip
    !> as in `test_mortar_friction_fd`.
    subroutine test_mortar_friction_fd_deformable(error)
        type(error_t), allocatable, intent(out) :: error
        type(scene_t) :: c
        type(discretization_t) :: discs(2)
        type(contact_settings_t) :: contact
        type(model_t) :: model
        real(dp), allocatable :: u(:)
        real(dp) :: mu(2), shift(2)
        integer :: want(2), i, im
        character(len=7), parameter :: methods(2) = [character(len=7) :: 'mortar', 'segment']
        mu = [0.5_dp, 0.3_dp]
        shift = [1.0e-5_dp, 0.05_dp]
        want = [state_stick, state_slip]
        do im = 1, 2
        do i = 1, 2
            c%bodies = [body_settings('upper', 'linear', 1.0_dp, layout3(2, [2, 2, 1], 0, 0, 'bottom')), &
                        body_settings('lower', 'linear', 1.0_dp, layout3(2, [3, 2, 1], 0, 0, 'top'))]
            contact%slave = 'upper'
            contact%master = 'lower'
            contact%method = methods(im)
            contact%friction = mu(i)
            c%contact = [contact]
            call new_discretization(discs(1), unit_box(-0.02_dp), box_faces, c%bodies(1)%layout, '', error)
            if (allocated(error)) return
            call new_discretization(discs(2), unit_box(-1.0_dp), box_faces, c%bodies(2)%layout, '', error)
            if (allocated(error)) return
            call scene_model(c, discs, model, error)
            if (allocated(error)) return
            call mortar_friction_state(model, 2.0e-3_dp, shift(i), u, error)
            if (allocated(error)) return
            call contact_fd(model%pairs(1)%pair, u, want(i), trim(methods(im))//' friction blocks '//str(i), error)
            if (allocated(error)) return
        end do
        end do
    end subroutine test_mortar_friction_fd_deformable

    !> A control point active with a gap just below gap_tol D_A has a pressure a round-off
    !> below 0; with no committed traction and no slip (a node that just touched), its
    !> trial traction is zero: it sticks with zero traction, not 0/0 (the m1 NN2.2 ironing
    !> with mortar stopped there, "the residual is not finite"); with a trial traction it
    !> slips at |t| = mu |p|, as on an edge.
    subroutine test_law3_zero_pressure(error)
        type(error_t), allocatable, intent(out) :: error
        type(contact_law_t) :: law
        real(dp) :: p, t(3), ttr(3)
        integer :: state
        law = contact_law_t(eps_n=10.0_dp, eps_t=10.0_dp, mu=0.3_dp)
        call control_point_law3(law, 1.0e-14_dp, 1.0_dp, [0.0_dp, 0.0_dp, 0.0_dp], [0.0_dp, 0.0_dp, 0.0_dp], &
                                1.0e-12_dp, p, t, state, ttr)
        call check(error, p < 0.0_dp .and. state == state_stick .and. all(t == 0.0_dp), &
                   'zero trial traction at p < 0: sticks with t = 0')
        if (allocated(error)) return
        call control_point_law3(law, 1.0e-14_dp, 1.0_dp, [1.0e-6_dp, 0.0_dp, 0.0_dp], [0.0_dp, 0.0_dp, 0.0_dp], &
                                1.0e-12_dp, p, t, state, ttr)
        call check(error, state == state_slip .and. abs(norm2(t) - law%mu*abs(p)) <= 1.0e-15_dp*abs(p), &
                   'a trial traction at p < 0 slips at mu |p|')
    end subroutine test_law3_zero_pressure

    !> A perturbed state `u` (every DOF moved by up to `amplitude`) of the model's
    !> mortar pair (or an extension's) and its committed friction history (`test_mortar_friction_fd`); with
    !> `touch`, every control point open at the last converged state at that mean gap.
    subroutine mortar_friction_state(model, amplitude, shift, u, error, touch)
        type(model_t), intent(inout) :: model
        real(dp), intent(in) :: amplitude, shift
        real(dp), allocatable, intent(out) :: u(:)
        type(error_t), allocatable, intent(out) :: error
        real(dp), intent(in), optional :: touch
        type(lcg_t) :: rng
        real(dp), allocatable :: r(:), p(:)
        integer :: j
        allocate (u(model%ndof), r(model%ndof))
        do j = 1, size(u)
            u(j) = amplitude*(2.0_dp*rng%uniform() - 1.0_dp)
        end do
        r = 0.0_dp
        call model%pairs(1)%pair%evaluate(u, r, error)
        if (allocated(error)) return
        select type (pair => model%pairs(1)%pair)
        class is (mortar_pair_t)
            call check(error, pair%h_traction_yz(2) > 0, 'a traction vector per control point')
            if (allocated(error)) return
            associate (h => pair%hist%field)
                h(pair%h_active)%last = 1.0_dp
                h(pair%h_xi)%last = pair%out%xi_m - shift
                h(pair%h_eta)%last = pair%out%eta_m - shift
                h(pair%h_node_active)%last = 1.0_dp
                p = pair%law%mu*pair%law%eps_n*max(0.0_dp, -pair%last%g/max(pair%last%d, tiny(1.0_dp)))
                h(pair%h_traction)%last = 0.12_dp*p
                h(pair%h_traction_yz(1))%last = -0.1_dp*p
                h(pair%h_traction_yz(2))%last = 0.09_dp*p
                if (present(touch)) then
                    h(pair%h_node_active)%last = 0.0_dp
                    h(pair%h_node_gap)%last = touch
                    h(pair%h_traction)%last = 0.0_dp
                    h(pair%h_traction_yz(1))%last = 0.0_dp
                    h(pair%h_traction_yz(2))%last = 0.0_dp
                end if
            end associate
        class default
            call check(error, .false., 'a mortar pair')
        end select
    end subroutine mortar_friction_state

    !> A flat rigid NURBS surface (the plane z = 0.02 as a bilinear patch over
    !> [-1, 2]^2, its normal +z) acts as the rigid plane through the same point: the
    !> residual, tangent and pressures of the box pressed onto it agree to round-off.
    subroutine test_flat_surface(error)
        type(error_t), allocatable, intent(out) :: error
        type(model_t) :: plane, surf
        real(dp), allocatable :: u(:), r1(:), r2(:)
        type(lcg_t) :: rng
        integer :: j
        call box_on_rigid(bump_patch(0.02_dp, 0.0_dp, 1), .false., plane, error)
        if (allocated(error)) return
        call box_on_rigid(bump_patch(0.02_dp, 0.0_dp, 1), .true., surf, error)
        if (allocated(error)) return
        allocate (u(plane%ndof), r1(plane%ndof), r2(plane%ndof))
        do j = 1, size(u)
            u(j) = 1.0e-3_dp*(2.0_dp*rng%uniform() - 1.0_dp)
        end do
        r1 = 0.0_dp
        r2 = 0.0_dp
        call plane%pairs(1)%pair%evaluate(u, r1, error)
        if (allocated(error)) return
        call surf%pairs(1)%pair%evaluate(u, r2, error)
        if (allocated(error)) return
        call check(error, maxval(abs(r1 - r2)) <= 1.0e-12_dp*maxval(abs(r1)) .and. maxval(abs(r1)) > 0.0_dp, &
                   'the same contact residual on the plane and on the flat surface')
        if (allocated(error)) return
        call check(error, maxval(abs(plane%pairs(1)%pair%out%pn - surf%pairs(1)%pair%out%pn)), 0.0_dp, &
                   'the same pressures', abs=1.0e-12_dp)
    end subroutine test_flat_surface

    !> A curved rigid surface (a biquadratic bump whose top rises 0.04 into the box's
    !> bottom face): the contact tangent against differences, with the master's curvature in
    !> the projection and the normal (GPTS and mortar).
    subroutine test_surface_fd(error)
        type(error_t), allocatable, intent(out) :: error
        character(len=6), parameter :: methods(2) = [character(len=6) :: 'gpts', 'mortar']
        type(model_t) :: model
        type(lcg_t) :: rng
        real(dp), allocatable :: u(:)
        integer :: im, j
        do im = 1, 2
            call box_on_rigid(bump_patch(-0.01_dp, 0.2_dp, 2), .true., model, error, methods(im))
            if (allocated(error)) return
            allocate (u(model%ndof))
            do j = 1, size(u)
                u(j) = 1.0e-3_dp*(2.0_dp*rng%uniform() - 1.0_dp)
            end do
            call contact_fd(model%pairs(1)%pair, u, state_stick, 'rigid bump '//trim(methods(im)), error)
            if (allocated(error)) return
            deallocate (u)
        end do
    end subroutine test_surface_fd

    !> The unit box (N2, 2 x 2 cells on its bottom) over a rigid obstacle: the surface
    !> `patch` (with `surface`), else the plane z = 0.02.
    subroutine box_on_rigid(patch, surface, model, error, method)
        type(nurbs_patch_t), intent(in) :: patch
        logical, intent(in) :: surface
        type(model_t), intent(out) :: model
        type(error_t), allocatable, intent(out) :: error
        character(len=*), intent(in), optional :: method
        type(scene_t) :: c
        type(discretization_t) :: discs(1)
        type(contact_settings_t) :: contact
        c%bodies = [body_settings('box', 'linear', 1.0_dp, layout3(2, [2, 2, 1], 0, 0, 'bottom'))]
        contact%slave = 'box'
        contact%master = 'rigid'
        contact%method = 'gpts'
        if (present(method)) contact%method = method
        contact%rigid_point = [0.0_dp, 0.0_dp, 0.02_dp]
        contact%rigid_normal = [0.0_dp, 0.0_dp, 1.0_dp]
        contact%point_components = 3
        contact%normal_components = 3
        if (surface) then
            contact%rigid_surface = 'bump'
            contact%surface = patch
        end if
        c%contact = [contact]
        call new_discretization(discs(1), unit_box(0.0_dp), box_faces, c%bodies(1)%layout, '', error)
        if (allocated(error)) return
        call scene_model(c, discs, model, error)
        if (allocated(error)) return
        select type (m => model%pairs(1)%pair%master)
        type is (rigid_surface_t)
            call check(error, surface, 'the plane was asked for, not the surface')
        class default
            call check(error, .not. surface, 'the surface was asked for, not the plane')
        end select
    end subroutine box_on_rigid

    !> The upper block (2 x 2 cells, layer `iq`) pressed 0.02 into the lower one (3 x 2
    !> cells), non-matching, with `method`.
    subroutine pressed_blocks(method, iq, model, error)
        character(len=*), intent(in) :: method
        integer, intent(in) :: iq
        type(model_t), intent(out) :: model
        type(error_t), allocatable, intent(out) :: error
        type(scene_t) :: c
        type(discretization_t) :: discs(2)
        type(contact_settings_t) :: contact
        c%bodies = [body_settings('upper', 'linear', 1.0_dp, layout3(2, [2, 2, 1], iq, 0, 'bottom')), &
                    body_settings('lower', 'linear', 1.0_dp, layout3(2, [3, 2, 1], 0, 0, 'top'))]
        contact%slave = 'upper'
        contact%master = 'lower'
        contact%method = method
        c%contact = [contact]
        call new_discretization(discs(1), unit_box(-0.02_dp), box_faces, c%bodies(1)%layout, '', error)
        if (allocated(error)) return
        call new_discretization(discs(2), unit_box(-1.0_dp), box_faces, c%bodies(2)%layout, '', error)
        if (allocated(error)) return
        call scene_model(c, discs, model, error)
    end subroutine pressed_blocks

    !> Segment on faces, the flat pressed blocks: the default points per direction
    !> (exact for N_A N_B: 5 for degree 2 on both), every slave cell's weights add up to
    !> its parameter area (its pieces tile it), the cells cut by the master's cell
    !> boundaries have more points than n_gauss^2, and the n_gauss^2 points of each
    !> triangle (or whole cell) project into one master cell: no master kink inside
    !> a piece.
    subroutine test_segment_pieces(error)
        type(error_t), allocatable, intent(out) :: error
        type(model_t) :: model
        real(dp), allocatable :: u(:), r(:)
        integer :: e, k, k0, ng, nu, n_split, cell(2), cell0(2)
        call pressed_blocks('segment', 0, model, error)
        if (allocated(error)) return
        allocate (u(model%ndof), r(model%ndof), source=0.0_dp)
        call model%pairs(1)%pair%evaluate(u, r, error)
        if (allocated(error)) return
        select type (pair => model%pairs(1)%pair)
        type is (segment_face_pair_t)
            select type (m => pair%master)
            class is (face_master_t)
                ng = pair%n_gauss
                call check(error, ng, default_face_segment_points([2, 2], [2, 2]), 'default points per direction')
                if (allocated(error)) return
                call check(error, ng, 5, 'default points per direction for degree 2')
                if (allocated(error)) return
                nu = size(pair%slave%spans)
                n_split = 0
                do e = 1, size(pair%first) - 1
                    associate (rng => pair%point_range(e), ci => modulo(e - 1, nu) + 1, cj => (e - 1)/nu + 1)
                        ! the weights: the cell's parameter area to round-off (1e-13)
                        call check(error, sum(pair%w(rng(1):rng(2))), &
                                   (pair%slave%breaks(ci + 1) - pair%slave%breaks(ci))* &
                                   (pair%slave%breaks_eta(cj + 1) - pair%slave%breaks_eta(cj)), &
                                   'cell '//str(e)//': the pieces tile it', rel=1.0e-13_dp)
                        if (allocated(error)) return
                        call check(error, mod(rng(2) - rng(1) + 1, ng*ng), 0, 'n_gauss^2 points per piece')
                        if (allocated(error)) return
                        if (rng(2) - rng(1) + 1 > ng*ng) n_split = n_split + 1
                        do k0 = rng(1), rng(2), ng*ng
                            cell0 = master_cell(m, pair%out(k0)%xi_m, pair%out(k0)%eta_m)
                            do k = k0 + 1, k0 + ng*ng - 1
                                cell = master_cell(m, pair%out(k)%xi_m, pair%out(k)%eta_m)
                                call check(error, all(cell == cell0), 'cell '//str(e)//', point '//str(k)// &
                                           ': the points of a piece project into one master cell')
                                if (allocated(error)) return
                            end do
                        end do
                    end associate
                end do
                ! 2 x 2 on 3 x 2: the master's boundary at x = 1/3 crosses slave cell 1, 2/3 cell 2
                call check(error, n_split, size(pair%first) - 1, 'every slave cell is cut')
            end select
        class default
            call check(error, .false., 'a segment pair on faces')
        end select
    end subroutine test_segment_pieces

    !> Segment on faces, a restart: the points of a pair segmented at a perturbed state
    !> (`history`) set on a pair fresh from the reference state (`set_history`) give it
    !> the same points, weights and cells; a history with a point outside its cell is
    !> refused.
    subroutine test_segment_history(error)
        type(error_t), allocatable, intent(out) :: error
        type(error_t), allocatable :: refused
        type(model_t) :: a, b
        type(lcg_t) :: rng
        type(history_item_t), allocatable :: items(:)
        real(dp), allocatable :: u(:), r(:)
        integer :: j, i
        call pressed_blocks('segment', 0, a, error)
        if (allocated(error)) return
        call pressed_blocks('segment', 0, b, error)
        if (allocated(error)) return
        allocate (u(a%ndof), r(a%ndof), source=0.0_dp)
        do j = 1, size(u)
            u(j) = 2.0e-3_dp*(2.0_dp*rng%uniform() - 1.0_dp)
        end do
        call a%pairs(1)%pair%evaluate(u, r, error)
        if (allocated(error)) return
        call a%pairs(1)%pair%commit()
        items = a%pairs(1)%pair%history()
        call b%pairs(1)%pair%set_history(items, error)
        if (allocated(error)) return
        select type (pa => a%pairs(1)%pair)
        type is (segment_face_pair_t)
            select type (pb => b%pairs(1)%pair)
            type is (segment_face_pair_t)
                call check(error, size(pb%xi) == size(pa%xi) .and. size(pa%xi) /= 6*pa%n_gauss**2, &
                           'the segmented number of points')
                if (allocated(error)) return
                call check(error, all(pb%xi == pa%xi) .and. all(pb%eta == pa%eta) .and. all(pb%w == pa%w) .and. &
                           all(pb%elem == pa%elem) .and. all(pb%first == pa%first), 'the same points')
                if (allocated(error)) return
                call check(error, size(pb%out) == size(pa%xi) .and. size(pb%point_nodes, 2) == size(pa%xi), &
                           'output and multiplier basis per point')
                if (allocated(error)) return
            end select
        end select
        i = findloc([(items(j)%name == 'point_eta', j=1, size(items))], .true., dim=1)
        items(i)%values(1) = 2.0_dp
        call b%pairs(1)%pair%set_history(items, refused)
        call check(error, allocated(refused), 'a point outside its cell is refused')
        if (allocated(error)) return
        call check(error, index(refused%message, 'outside its cell') > 0, 'the message names it: '//refused%message)
    end subroutine test_segment_history

    !> The master cell (i, j) of the parameters (xi, eta).
    pure function master_cell(m, xi, eta) result(cell)
        type(face_master_t), intent(in) :: m
        real(dp), intent(in) :: xi, eta
        integer :: cell(2)
        cell = [count(m%search%breaks_u(2:size(m%search%breaks_u) - 1) <= xi) + 1, &
                count(m%search%breaks_v(2:size(m%search%breaks_v) - 1) <= eta) + 1]
    end function master_cell

    !> Segment on curved faces: the pressed blocks at a perturbed state (every DOF moved
    !> by up to 2e-3), segmented there (a commit after an evaluation), N2 and NN3 on the
    !> slave: the pieces still tile every cell, and K of the pair against central
    !> differences on those points.
    subroutine test_segment_curved(error)
        type(error_t), allocatable, intent(out) :: error
        type(model_t) :: model
        type(lcg_t) :: rng
        real(dp), allocatable :: u(:), r(:)
        real(dp) :: total, area
        integer :: iq, j, e
        do iq = 0, 3, 3
            call pressed_blocks('segment', iq, model, error)
            if (allocated(error)) return
            allocate (u(model%ndof), r(model%ndof), source=0.0_dp)
            do j = 1, size(u)
                u(j) = 2.0e-3_dp*(2.0_dp*rng%uniform() - 1.0_dp)
            end do
            call model%pairs(1)%pair%evaluate(u, r, error)
            if (allocated(error)) return
            call model%pairs(1)%pair%commit()
            select type (pair => model%pairs(1)%pair)
            type is (segment_face_pair_t)
                area = (pair%slave%breaks(size(pair%slave%breaks)) - pair%slave%breaks(1))* &
                       (pair%slave%breaks_eta(size(pair%slave%breaks_eta)) - pair%slave%breaks_eta(1))
                total = sum(pair%w)
                call check(error, total, area, 'curved, layer '//char(48 + iq)//': the pieces tile the face', &
                           rel=1.0e-12_dp)
                if (allocated(error)) return
                e = size(pair%xi)
                call check(error, e > n_elements_of(pair)*pair%n_gauss**2, 'curved: cells are cut')
                if (allocated(error)) return
            end select
            call contact_fd(model%pairs(1)%pair, u, state_stick, 'segment curved blocks, layer '//char(48 + iq), &
                            error)
            if (allocated(error)) return
            deallocate (u, r)
        end do
    end subroutine test_segment_curved

    pure integer function n_elements_of(pair) result(n)
        type(segment_face_pair_t), intent(in) :: pair
        n = size(pair%first) - 1
    end function n_elements_of

    !> The surface over [-1, 2]^2 of degree `p` (1 or 2) at z = `z0`, its middle control
    !> point raised by `rise` (degree 2: a bump into the box above), normal +z.
    function bump_patch(z0, rise, p) result(patch)
        real(dp), intent(in) :: z0, rise
        integer, intent(in) :: p
        type(nurbs_patch_t) :: patch
        real(dp) :: cp(3, (p + 1)**2)
        type(knots_t) :: kv
        integer :: i, j, a
        a = 0
        do j = 0, p
            do i = 0, p
                a = a + 1
                cp(:, a) = [-1.0_dp + 3.0_dp*real(i, dp)/real(p, dp), -1.0_dp + 3.0_dp*real(j, dp)/real(p, dp), z0]
            end do
        end do
        if (p == 2) cp(3, 5) = cp(3, 5) + rise
        kv = knots_t([(0.0_dp, i=0, p), (1.0_dp, i=0, p)])
        patch = new_patch([p, p], [kv, kv], [p + 1, p + 1], cp, [(1.0_dp, a=1, (p + 1)**2)])
    end function bump_patch

    !> The box [0, 1] x [0, 1] x [z0, z0 + 1] (degree 1).
    function unit_box(z0) result(patch)
        real(dp), intent(in) :: z0
        type(nurbs_patch_t) :: patch
        real(dp) :: cp(3, 8)
        integer :: i, j, k, a
        type(knots_t) :: lin
        a = 0
        do k = 0, 1
            do j = 0, 1
                do i = 0, 1
                    a = a + 1
                    cp(:, a) = [real(i, dp), real(j, dp), z0 + real(k, dp)]
                end do
            end do
        end do
        lin = knots_t([0.0_dp, 0.0_dp, 1.0_dp, 1.0_dp])
        patch = new_patch([1, 1, 1], [lin, lin, lin], [2, 2, 2], cp, [(1.0_dp, a=1, 8)])
    end function unit_box

    !> The points' reference areas add up to the face's: the quarter cylinder r = 2,
    !> z in [0, 1], pi (its rational map integrated to the quadrature's accuracy).
    subroutine test_face_area(error)
        type(error_t), allocatable, intent(out) :: error
        type(model_t) :: model
        call ring_on_plane(layout3(2, [1, 4, 2], 3, 0, 'outer'), model, error)
        if (allocated(error)) return
        associate (pair => model%pairs(1)%pair)
            call check(error, sum(pair%out%area0), acos(-1.0_dp), 'reference area of the slave face', &
                       rel=1.0e-5_dp)
            if (allocated(error)) return
            ! layer degree 3: q + 1 = 4 points per direction and cell; the face's cells
            ! are nel_xi x nel_eta = 1 x 4 (a layout counts along the patch turned so
            ! that the contact face is zeta = 1)
            call check(error, pair%nsd == 3 .and. size(pair%xi) == 4*16, '4 x 4 points on each of 4 cells, got '// &
                       str(size(pair%xi)))
        end associate
    end subroutine test_face_area

    !> The plane's frame: t, t2, n orthonormal and right-handed (t x t2 = n, as a
    !> surface's a1 x a2 is its outward normal), for normals along and off the axes.
    subroutine test_plane_frame(error)
        type(error_t), allocatable, intent(out) :: error
        type(rigid_line_t) :: m
        real(dp) :: normals(3, 4), f(3, 3), c(3)
        integer :: i
        normals = reshape([0.0_dp, 0.0_dp, 1.0_dp, 1.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, -1.0_dp, 0.0_dp, &
                           -1.0_dp, -0.2_dp, 0.1_dp], [3, 4])
        do i = 1, 4
            call new_rigid_line(m, [0.0_dp, 0.0_dp, 0.0_dp], normals(:, i))
            f(:, 1) = m%t
            f(:, 2) = m%t2
            f(:, 3) = m%n
            call check(error, maxval(abs(matmul(transpose(f), f) - reshape([1.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, &
                       1.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 1.0_dp], [3, 3]))) < 1.0e-14_dp, 'orthonormal frame')
            if (allocated(error)) return
            c = [m%t(2)*m%t2(3) - m%t(3)*m%t2(2), m%t(3)*m%t2(1) - m%t(1)*m%t2(3), m%t(1)*m%t2(2) - m%t(2)*m%t2(1)]
            call check(error, maxval(abs(c - m%n)) < 1.0e-14_dp, 't x t2 = n')
            if (allocated(error)) return
        end do
    end subroutine test_plane_frame

end module test_contact_3d
