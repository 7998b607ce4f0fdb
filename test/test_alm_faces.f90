!> The augmented Lagrangian on a solid's face (`&contact method = 'alm'`, issue 42,
!> frictionless): the tangent at fixed nonzero multipliers against finite differences
!> (a curved slave face against a tilted rigid plane, and two blocks with a deformable
!> master), and the element size of the constraint test per control point.
module test_alm_faces
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_testdrive, only: unittest_t, new_unittest, check
    use voiga_discretization_patch, only: discretization_t, new_discretization
    use voiga_contact_factory, only: contact_settings_t
    use voiga_contact_alm, only: alm_pair_t
    use voiga_contact_law, only: state_stick
    use voiga_contact_pair, only: contact_pair_t
    use voiga_model, only: model_t
    use voiga_test_fixtures, only: layout3, scene_t, scene_model, body_settings, lcg_t
    use voiga_text, only: str
    use test_contact, only: contact_fd
    use test_contact_3d, only: ring_on_plane, unit_box, box_faces
    implicit none
    private

    public :: collect_alm_faces

contains

    subroutine collect_alm_faces(testsuite)
        type(unittest_t), allocatable, intent(out) :: testsuite(:)
        testsuite = [ &
                    new_unittest('alm_faces_tangent_fd', test_tangent_fd), &
                    new_unittest('alm_faces_tangent_fd_deformable', test_tangent_fd_deformable), &
                    new_unittest('alm_faces_element_size', test_element_size) &
                    ]
    end subroutine collect_alm_faces

    !> The quarter ring's outer cylinder against the tilted plane (`ring_on_plane`), every
    !> DOF moved by up to 1e-3, the multipliers of the order of the penalty pressures
    !> and varying over the face: K of the pair against central differences (the
    !> multipliers shift the gap by lambda_A D_A / eps_N, a constant of u), N2 and NN3.1.
    subroutine test_tangent_fd(error)
        type(error_t), allocatable, intent(out) :: error
        type(model_t) :: model
        type(lcg_t) :: rng
        real(dp), allocatable :: u(:)
        integer :: il, j
        do il = 1, 2
            if (il == 1) then
                call ring_on_plane(layout3(2, [2, 3, 2], 0, 0, 'outer'), model, error, method='alm')
            else
                call ring_on_plane(layout3(2, [1, 2, 1], 3, 1, 'outer'), model, error, method='alm')
            end if
            if (allocated(error)) return
            allocate (u(model%ndof))
            do j = 1, size(u)
                u(j) = 1.0e-3_dp*(2.0_dp*rng%uniform() - 1.0_dp)
            end do
            call set_multipliers(model%pairs(1)%pair, 0.01_dp, error)
            if (allocated(error)) return
            call contact_fd(model%pairs(1)%pair, u, state_stick, 'alm ring layout '//char(48 + il), error)
            if (allocated(error)) return
            deallocate (u)
        end do
    end subroutine test_tangent_fd

    !> The two blocks of `contact_3d_tangent_fd_deformable` (the upper one's bottom face
    !> pressed 0.02 into the lower one's top face, 2 x 2 cells on 3 x 2, every DOF moved
    !> by up to 2e-3) with ALM and multipliers of the order of the penalty pressures:
    !> K against central differences, N2 and NN3.
    subroutine test_tangent_fd_deformable(error)
        type(error_t), allocatable, intent(out) :: error
        type(model_t) :: model
        type(lcg_t) :: rng
        real(dp), allocatable :: u(:)
        integer :: iq, j
        do iq = 0, 3, 3
            call pressed_blocks(iq, [2, 2], model, error)
            if (allocated(error)) return
            allocate (u(model%ndof))
            do j = 1, size(u)
                u(j) = 2.0e-3_dp*(2.0_dp*rng%uniform() - 1.0_dp)
            end do
            call set_multipliers(model%pairs(1)%pair, 0.5_dp, error)
            if (allocated(error)) return
            call contact_fd(model%pairs(1)%pair, u, state_stick, 'alm blocks, layer '//char(48 + iq), error)
            if (allocated(error)) return
            call check_shift(model%pairs(1)%pair, error)
            if (allocated(error)) return
            deallocate (u)
        end do
    end subroutine test_tangent_fd_deformable

    !> At the last evaluation every active control point's pressure is the shifted law's,
    !> p_A = lambda_A - eps_N g_A / D_A (the face's mortar path called the pair's laws).
    subroutine check_shift(pair, error)
        class(contact_pair_t), intent(in) :: pair
        type(error_t), allocatable, intent(out) :: error
        integer :: a
        select type (pair)
        type is (alm_pair_t)
            call check(error, count(pair%state == state_stick) >= 3, 'at least 3 active control points')
            if (allocated(error)) return
            associate (lambda => pair%hist%field(pair%h_lambda)%trial)
                do a = 1, size(pair%state)
                    if (pair%state(a) /= state_stick) cycle
                    call check(error, pair%p_last(a), lambda(a) - pair%law%eps_n*pair%g(a)/pair%d(a), &
                               'p_A = lambda_A - eps_N g_A / D_A at control point '//str(a), rel=1.0e-12_dp)
                    if (allocated(error)) return
                end do
            end associate
        class default
            call check(error, .false., 'the pair is an alm pair')
        end select
    end subroutine check_shift

    !> The constraint test's size of a control point on a face is the longer chord of the
    !> cells of its support: 3 x 2 cells on the unit square are 1/3 x 1/2, so every
    !> control point's is 1/2 (the shorter, 1/3, would be the automatic penalty's).
    subroutine test_element_size(error)
        type(error_t), allocatable, intent(out) :: error
        type(model_t) :: model
        call pressed_blocks(0, [3, 2], model, error)
        if (allocated(error)) return
        select type (pair => model%pairs(1)%pair)
        type is (alm_pair_t)
            call check(error, size(pair%h) == size(pair%slave%cps), 'one size per control point of the face')
            if (allocated(error)) return
            call check(error, maxval(abs(pair%h - 0.5_dp)), 0.0_dp, 'every size the cells'' longer chord 1/2', &
                       abs=1.0e-12_dp)
        class default
            call check(error, .false., 'the pair is an alm pair')
        end select
    end subroutine test_element_size

    !> Multipliers lambda_A = `scale` (1 + 0.5 sin 7A) (nominal pressures) on every
    !> control point of an alm pair.
    subroutine set_multipliers(pair, scale, error)
        class(contact_pair_t), intent(inout) :: pair
        real(dp), intent(in) :: scale
        type(error_t), allocatable, intent(out) :: error
        integer :: j
        select type (pair)
        type is (alm_pair_t)
            associate (lambda => pair%hist%field(pair%h_lambda)%trial)
                lambda = [(scale*(1.0_dp + 0.5_dp*sin(7.0_dp*j)), j=1, size(lambda))]
            end associate
        class default
            call check(error, .false., 'the pair is an alm pair')
        end select
    end subroutine set_multipliers

    !> The upper unit block (slave, its bottom face `cells` cells, layer degree `iq`)
    !> 0.02 into the lower one (master, 3 x 2 cells on its top face), ALM.
    subroutine pressed_blocks(iq, cells, model, error)
        integer, intent(in) :: iq, cells(2)
        type(model_t), intent(out) :: model
        type(error_t), allocatable, intent(out) :: error
        type(scene_t) :: c
        type(discretization_t) :: discs(2)
        type(contact_settings_t) :: contact
        c%bodies = [body_settings('upper', 'linear', 1.0_dp, layout3(2, [cells(1), cells(2), 1], iq, 0, 'bottom')), &
                    body_settings('lower', 'linear', 1.0_dp, layout3(2, [3, 2, 1], 0, 0, 'top'))]
        contact%slave = 'upper'
        contact%master = 'lower'
        contact%method = 'alm'
        c%contact = [contact]
        call new_discretization(discs(1), unit_box(-0.02_dp), box_faces, c%bodies(1)%layout, '', error)
        if (allocated(error)) return
        call new_discretization(discs(2), unit_box(-1.0_dp), box_faces, c%bodies(2)%layout, '', error)
        if (allocated(error)) return
        call scene_model(c, discs, model, error)
    end subroutine pressed_blocks

end module test_alm_faces
