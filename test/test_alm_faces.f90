!> The augmented Lagrangian on a solid's face (`&contact method = 'alm'`, issue 42):
!> the tangent at fixed nonzero multipliers against finite differences (a curved slave
!> face against a tilted rigid plane, and two blocks with a deformable master),
!> frictionless and with friction in stick and slip, and the element size of the
!> constraint test per control point.
module test_alm_faces
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_testdrive, only: unittest_t, new_unittest, check
    use voiga_discretization_patch, only: discretization_t, new_discretization
    use voiga_contact_factory, only: contact_settings_t
    use voiga_contact_alm, only: alm_pair_t, tangent_frame
    use voiga_contact_law, only: state_stick, state_slip
    use voiga_contact_pair, only: contact_pair_t, constraint_set_t
    use voiga_model, only: model_t
    use voiga_test_fixtures, only: layout3, scene_t, scene_model, body_settings, lcg_t
    use voiga_text, only: str
    use test_contact, only: contact_fd
    use test_contact_3d, only: ring_on_plane, unit_box, box_faces, mortar_friction_state
    implicit none
    private

    public :: collect_alm_faces

contains

    subroutine collect_alm_faces(testsuite)
        type(unittest_t), allocatable, intent(out) :: testsuite(:)
        testsuite = [ &
                    new_unittest('alm_faces_tangent_fd', test_tangent_fd), &
                    new_unittest('alm_faces_tangent_fd_deformable', test_tangent_fd_deformable), &
                    new_unittest('alm_faces_friction_fd', test_friction_fd), &
                    new_unittest('alm_faces_constraints_fd', test_constraints_fd), &
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

    !> At the last evaluation every active control point (in state `want`, default stick)
    !> has the shifted law's pressure, p_A = lambda_A - eps_N g_A / D_A (the face's mortar
    !> path called the pair's laws); with friction a sticking one's trial traction is
    !> tau_A - eps_T ds_A / D_A.
    subroutine check_shift(pair, error, want)
        class(contact_pair_t), intent(in) :: pair
        type(error_t), allocatable, intent(out) :: error
        integer, intent(in), optional :: want
        integer :: a, state
        state = state_stick
        if (present(want)) state = want
        select type (pair)
        type is (alm_pair_t)
            call check(error, count(pair%state == state) >= 3, 'at least 3 active control points')
            if (allocated(error)) return
            associate (lambda => pair%hist%field(pair%h_lambda)%trial)
                do a = 1, size(pair%state)
                    if (pair%state(a) /= state) cycle
                    call check(error, pair%p_last(a), lambda(a) - pair%law%eps_n*pair%g(a)/pair%d(a), &
                               'p_A = lambda_A - eps_N g_A / D_A at control point '//str(a), rel=1.0e-12_dp)
                    if (allocated(error)) return
                    if (.not. allocated(pair%tau3) .or. state /= state_stick) cycle
                    call check(error, maxval(abs(pair%ttr3(:, a) - pair%tau3(:, a) &
                                                 + pair%law%eps_t*pair%ds3(:, a)/pair%d(a))) &
                               <= 1.0e-12_dp*maxval(abs(pair%ttr3(:, a))), &
                               't_A^tr = tau_A - eps_T ds_A / D_A at control point '//str(a))
                    if (allocated(error)) return
                end do
            end associate
        class default
            call check(error, .false., 'the pair is an alm pair')
        end select
    end subroutine check_shift

    !> With friction (`alm_faces.f90`): the state of `contact_3d_mortar_friction_fd` (every
    !> point projected at the last converged state `shift` behind its present projection,
    !> every control point in contact there) with tangential multipliers tau_A of 0.2 mu p_A
    !> off the tangent plane and normal ones of the order of the penalty pressures: K
    !> against central differences when every control point sticks (mu = 0.5, 1e-5) and
    !> slips (mu = 0.3, 0.05), on the ring against the tilted plane (N2, NN3) and on the
    !> two blocks (N2); the multipliers shift the law (`check_shift`).
    subroutine test_friction_fd(error)
        type(error_t), allocatable, intent(out) :: error
        type(model_t) :: model
        real(dp), allocatable :: u(:)
        real(dp) :: mu(2), shift(2)
        integer :: want(2), il, i
        character(len=:), allocatable :: label
        mu = [0.5_dp, 0.3_dp]
        shift = [1.0e-5_dp, 0.05_dp]
        want = [state_stick, state_slip]
        do il = 1, 3
            do i = 1, 2
                select case (il)
                case (1)
                    call ring_on_plane(layout3(2, [2, 3, 2], 0, 0, 'outer'), model, error, mu(i), 'alm')
                case (2)
                    call ring_on_plane(layout3(2, [1, 2, 2], 3, 0, 'outer'), model, error, mu(i), 'alm')
                case default
                    call pressed_blocks(0, [2, 2], model, error, mu(i))
                end select
                if (allocated(error)) return
                call mortar_friction_state(model, merge(1.0e-3_dp, 2.0e-3_dp, il < 3), shift(i), u, error)
                if (allocated(error)) return
                ! the tangential multipliers from the committed tractions, then the normal ones
                call model%pairs(1)%pair%reset_trial()
                call set_multipliers(model%pairs(1)%pair, merge(0.01_dp, 0.5_dp, il < 3), error)
                if (allocated(error)) return
                label = 'alm friction '//trim(merge('stick', 'slip ', i == 1))//' '//str(il)
                call contact_fd(model%pairs(1)%pair, u, want(i), label, error)
                if (allocated(error)) return
                call check_shift(model%pairs(1)%pair, error, want(i))
                if (allocated(error)) return
            end do
        end do
    end subroutine test_friction_fd

    !> The constraint set of a face with friction (`face_constraints`) against central
    !> differences, at the sticking and slipping states of `alm_faces_friction_fd` on the
    !> ring against the tilted plane (N2): each row (d c_j / du) from the constraint values
    !> at u -+ h e_k, and each column (d r / d mu_j) from the residuals at the multipliers
    !> moved by -+ h along the constraint's (lambda_A, or tau_A along the frame vector).
    subroutine test_constraints_fd(error)
        type(error_t), allocatable, intent(out) :: error
        type(model_t) :: model
        real(dp), allocatable :: u(:)
        real(dp) :: mu(2), shift(2)
        integer :: want(2), i
        mu = [0.5_dp, 0.3_dp]
        shift = [1.0e-5_dp, 0.05_dp]
        want = [state_stick, state_slip]
        do i = 1, 2
            call ring_on_plane(layout3(2, [2, 3, 2], 0, 0, 'outer'), model, error, mu(i), 'alm')
            if (allocated(error)) return
            call mortar_friction_state(model, 1.0e-3_dp, shift(i), u, error)
            if (allocated(error)) return
            call model%pairs(1)%pair%reset_trial()
            call set_multipliers(model%pairs(1)%pair, 0.01_dp, error)
            if (allocated(error)) return
            call constraints_fd(model%pairs(1)%pair, u, want(i), error)
            if (allocated(error)) return
        end do
    end subroutine test_constraints_fd

    !> `test_constraints_fd` at one state.
    subroutine constraints_fd(pair, u, want, error)
        class(contact_pair_t), intent(inout) :: pair
        real(dp), intent(inout) :: u(:)
        integer, intent(in) :: want
        type(error_t), allocatable, intent(out) :: error
        real(dp), parameter :: h = 1.0e-7_dp
        type(constraint_set_t) :: set, plus, minus
        real(dp), allocatable :: r(:), rp(:), rm(:), dense(:), fd(:)
        integer, allocatable :: active(:), stick(:)
        real(dp) :: err, scale, e(3, 2)
        integer :: j, k, a
        allocate (r(size(u)), rp(size(u)), rm(size(u)), dense(size(u)))
        r = 0.0_dp
        call pair%evaluate(u, r, error, ignore)
        if (allocated(error)) return
        set = pair%constraints()
        call check(error, size(set%c) > 0, 'active constraints')
        if (allocated(error)) return
        call check(error, any(pair%out%state == want), 'control points in the wanted state')
        if (allocated(error)) return
        ! rows: d c / du
        allocate (fd(size(set%c)))
        err = 0.0_dp
        scale = 0.0_dp
        do k = 1, size(u)
            u(k) = u(k) + h
            rp = 0.0_dp
            call pair%evaluate(u, rp, error)
            plus = pair%constraints()
            u(k) = u(k) - 2*h
            call pair%evaluate(u, rp, error)
            minus = pair%constraints()
            u(k) = u(k) + h
            if (size(plus%c) /= size(set%c) .or. size(minus%c) /= size(set%c)) cycle
            fd = (plus%c - minus%c)/(2*h)
            do j = 1, size(set%c)
                dense = 0.0_dp
                dense(set%rows(j)%dofs) = set%rows(j)%values
                err = max(err, abs(dense(k) - fd(j)))
                scale = max(scale, abs(dense(k)))
            end do
        end do
        call check(error, err/scale, 0.0_dp, 'constraint rows vs FD', abs=1.0e-6_dp)
        if (allocated(error)) return
        ! columns: d r / d mu_j, the multiplier moved by -+ h (lambda_A, or tau_A along e_i)
        select type (pair)
        type is (alm_pair_t)
            active = pack([(j, j=1, size(pair%state))], pair%state /= 0)
            stick = pack([(j, j=1, size(pair%state))], pair%state == state_stick)
            err = 0.0_dp
            scale = 0.0_dp
            do j = 1, size(set%c)
                do k = 1, 2
                    if (j <= size(active)) then
                        associate (lambda => pair%hist%field(pair%h_lambda)%trial(active(j)))
                            lambda = lambda + merge(h, -2*h, k == 1)
                        end associate
                    else
                        a = stick((j - size(active) + 1)/2)
                        e = tangent_frame(pair%n3(:, a))
                        pair%tau3(:, a) = pair%tau3(:, a) + merge(h, -2*h, k == 1)*e(:, 2 - mod(j - size(active), 2))
                    end if
                    if (k == 1) then
                        rp = 0.0_dp
                        call pair%evaluate(u, rp, error)
                    else
                        rm = 0.0_dp
                        call pair%evaluate(u, rm, error)
                    end if
                end do
                if (j <= size(active)) then
                    associate (lambda => pair%hist%field(pair%h_lambda)%trial(active(j)))
                        lambda = lambda + h
                    end associate
                else
                    pair%tau3(:, a) = pair%tau3(:, a) + h*e(:, 2 - mod(j - size(active), 2))
                end if
                dense = 0.0_dp
                dense(set%cols(j)%dofs) = set%cols(j)%values
                err = max(err, maxval(abs(dense - (rp - rm)/(2*h))))
                scale = max(scale, maxval(abs(dense)))
            end do
        end select
        call check(error, err/scale, 0.0_dp, 'constraint columns vs FD', abs=1.0e-6_dp)
    contains
        subroutine ignore(dofs, k)
            integer, intent(in) :: dofs(:)
            real(dp), intent(in) :: k(:, :)
        end subroutine ignore
    end subroutine constraints_fd

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
    !> 0.02 into the lower one (master, 3 x 2 cells on its top face), ALM, friction `mu`.
    subroutine pressed_blocks(iq, cells, model, error, mu)
        integer, intent(in) :: iq, cells(2)
        type(model_t), intent(out) :: model
        type(error_t), allocatable, intent(out) :: error
        !> Coulomb's coefficient (default 0).
        real(dp), intent(in), optional :: mu
        type(scene_t) :: c
        type(discretization_t) :: discs(2)
        type(contact_settings_t) :: contact
        c%bodies = [body_settings('upper', 'linear', 1.0_dp, layout3(2, [cells(1), cells(2), 1], iq, 0, 'bottom')), &
                    body_settings('lower', 'linear', 1.0_dp, layout3(2, [3, 2, 1], 0, 0, 'top'))]
        contact%slave = 'upper'
        contact%master = 'lower'
        contact%method = 'alm'
        if (present(mu)) contact%friction = mu
        c%contact = [contact]
        call new_discretization(discs(1), unit_box(-0.02_dp), box_faces, c%bodies(1)%layout, '', error)
        if (allocated(error)) return
        call new_discretization(discs(2), unit_box(-1.0_dp), box_faces, c%bodies(2)%layout, '', error)
        if (allocated(error)) return
        call scene_model(c, discs, model, error)
    end subroutine pressed_blocks

end module test_alm_faces
