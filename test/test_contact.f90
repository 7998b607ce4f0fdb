!> GPTS contact: tangent against finite differences in frictionless, stick and
!> slip states for several layer degrees and masters.
module test_contact
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_testdrive, only: unittest_t, new_unittest, check
    use voiga_nurbs_surface, only: nurbs_surface_t
    use voiga_discretization_layout, only: layout_t
    use voiga_discretization_patch, only: discretization_t, new_discretization
    use voiga_io_case, only: case_t, body_input_t, contact_input_t
    use voiga_model, only: model_t, new_model
    use voiga_contact_pair, only: contact_pair_t, pair_contribution
    use voiga_contact_gpts, only: state_inactive, state_stick, state_slip
    use voiga_test_fixtures, only: lcg_t, annulus_sector, rectangle
    implicit none
    private

    public :: collect_contact, two_body_model

    real(dp), parameter :: pi = acos(-1.0_dp)

contains

    subroutine collect_contact(testsuite)
        type(unittest_t), allocatable, intent(out) :: testsuite(:)
        testsuite = [ &
                    new_unittest('tangent_fd_frictionless', test_fd_frictionless), &
                    new_unittest('tangent_fd_stick', test_fd_stick), &
                    new_unittest('tangent_fd_slip', test_fd_slip), &
                    new_unittest('tangent_fd_rigid_master', test_fd_rigid) &
                    ]
    end subroutine collect_contact

    function layout_named(name, nel, contact) result(layout)
        character(len=*), intent(in) :: name
        integer, intent(in) :: nel(2)
        character(len=*), intent(in) :: contact
        type(layout_t) :: layout
        layout%nel = nel
        layout%contact_edge = contact
        select case (name)
        case ('N2'); layout%degree = [2, 2]
        case ('N3'); layout%degree = [3, 2]
        case ('N4'); layout%degree = [4, 2]
        case ('NN4'); layout%layer_degree = 4
        case ('NN2.1'); layout%layer_degree = 2; layout%layer_elevations = 1
        case ('NN2.2'); layout%layer_degree = 2; layout%layer_elevations = 2
        end select
    end function layout_named

    !> Die (half annulus, outer radius 3, lowest point (2.5, 0)) over a 9 x 3 slab,
    !> both with `layout`; the pair die -> slab (or -> a rigid line y = 0).
    subroutine two_body_model(layout, mu, rigid, model, error)
        character(len=*), intent(in) :: layout
        real(dp), intent(in) :: mu
        logical, intent(in) :: rigid
        type(model_t), intent(out) :: model
        type(error_t), allocatable, intent(out) :: error
        type(case_t) :: c
        type(discretization_t) :: discs(2)
        character(len=8), parameter :: names(2) = [character(len=8) :: 'die', 'slab']
        integer :: i

        c%path = 'test'
        c%dir = ''
        allocate (c%bodies(2))
        do i = 1, 2
            c%bodies(i)%name = names(i)
            c%bodies(i)%material = 'neo-hookean'
            c%bodies(i)%youngs_modulus = merge(10.0_dp, 1.0_dp, i == 1)
            c%bodies(i)%poisson_ratio = 0.3_dp
        end do
        c%bodies(1)%layout = layout_named(layout, [12, 1], 'outer')
        c%bodies(2)%layout = layout_named(layout, [8, 2], 'top')
        c%solver%n_steps = [1]
        allocate (c%dirichlet(0), c%pressure(0), c%contact(1))
        c%contact(1)%slave = 'die'
        c%contact(1)%master = merge('rigid', 'slab ', rigid)
        c%contact(1)%rigid_point = [0.0_dp, 0.0_dp]
        c%contact(1)%rigid_normal = [0.0_dp, 1.0_dp]
        c%contact(1)%penalty_normal = 100.0_dp
        c%contact(1)%penalty_tangent = 70.0_dp
        c%contact(1)%friction = mu
        call new_discretization(discs(1), annulus_sector([2.5_dp, 3.0_dp], 2.0_dp, 3.0_dp, pi, 2), &
                                c%bodies(1)%layout, '', error)
        if (allocated(error)) return
        call new_discretization(discs(2), rectangle(0.0_dp, -3.0_dp, 9.0_dp, 3.0_dp), &
                                c%bodies(2)%layout, '', error)
        if (allocated(error)) return
        call new_model(model, c, discs, error)
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
        type(contact_pair_t), intent(inout) :: pair
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
        call pair_contribution(pair, u, r, error, add_dense)
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
            call pair_contribution(pair, u, rp, error)
            if (allocated(error)) return
            u(j) = u(j) - 2*h
            rm = 0.0_dp
            call pair_contribution(pair, u, rm, error)
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

    subroutine run_fd(layouts, mu, rigid, anchor_shift, want_state, error)
        character(len=*), intent(in) :: layouts(:)
        real(dp), intent(in) :: mu
        logical, intent(in) :: rigid
        !> Committed anchor = current projection - shift (friction only).
        real(dp), intent(in) :: anchor_shift
        integer, intent(in) :: want_state
        type(error_t), allocatable, intent(out) :: error
        type(model_t) :: model
        real(dp), allocatable :: u(:), r(:)
        integer :: il

        do il = 1, size(layouts)
            call two_body_model(trim(layouts(il)), mu, rigid, model, error)
            if (allocated(error)) return
            call penetrating_state(model, u)
            if (mu > 0.0_dp) then
                ! committed history: every point was in contact, anchored near or far
                allocate (r(size(u)))
                r = 0.0_dp
                call pair_contribution(model%pairs(1), u, r, error)
                if (allocated(error)) return
                model%pairs(1)%active_last = .true.
                model%pairs(1)%anchor = model%pairs(1)%out%xi_m - anchor_shift
                deallocate (r)
            end if
            call contact_fd(model%pairs(1), u, want_state, trim(layouts(il))// &
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

end module test_contact
