!> The solid (three-dimensional) body in the model: patch tests on a distorted
!> rational trivariate patch, with and without a VO layer, exact to round-off;
!> the assembled tangent against finite differences of the residual; quadratic
!> Newton convergence under a large stretch.
module test_solid_3d
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_testdrive, only: unittest_t, new_unittest, check
    use voiga_nurbs_patch, only: nurbs_patch_t, knots_t, new_patch, next_index
    use voiga_discretization_layout, only: layout_t
    use voiga_discretization_patch, only: discretization_t, new_discretization
    use voiga_model, only: model_t
    use voiga_model_loads, only: dirichlet_settings_t, pressure_settings_t
    use voiga_model_assembly, only: assemble, assembly_stats_t
    use voiga_linalg_sparse, only: csc_matrix_t
    use voiga_solver_records, only: solver_stats_t
    use voiga_solver_stepping, only: solve_steps
    use voiga_material_neohookean, only: neo_hookean_t
    use voiga_material, only: lame_from_young
    use voiga_test_fixtures, only: lcg_t, quadratic, scene_t, scene_model, body_settings, layout3
    implicit none
    private

    public :: collect_solid_3d

    !> The box's faces: x = 0, x = 3, y = 0, y = 2, z = 0, z = 1.
    character(len=32), parameter :: faces(6) = [character(len=32) :: 'left', 'right', 'front', 'back', &
                                                 'bottom', 'top']
    real(dp), parameter :: extent(3) = [3.0_dp, 2.0_dp, 1.0_dp]

contains

    subroutine collect_solid_3d(testsuite)
        type(unittest_t), allocatable, intent(out) :: testsuite(:)
        testsuite = [ &
                    new_unittest('patch_test_linear', test_patch_linear), &
                    new_unittest('patch_test_neo_hookean_large_stretch', test_patch_neo_hookean), &
                    new_unittest('patch_test_rational_by_quadrature', test_patch_rational), &
                    new_unittest('patch_test_pressure', test_patch_pressure), &
                    new_unittest('global_tangent_fd', test_global_tangent), &
                    new_unittest('newton_quadratic', test_quadratic) &
                    ]
    end subroutine collect_solid_3d

    !> The box [0, 3] x [0, 2] x [0, 1] as a degree-2 patch whose centre control
    !> point is moved and weighted (0.7): a rational map, distorted inside, with
    !> plane faces.
    function distorted_box(weight) result(patch)
        !> The centre point's weight (1: a polynomial map).
        real(dp), intent(in) :: weight
        type(nurbs_patch_t) :: patch
        real(dp) :: cp(3, 27), w(27)
        integer :: idx(3), a
        type(knots_t) :: knots(3)
        idx = 1
        do a = 1, 27
            cp(:, a) = 0.5_dp*real(idx - 1, dp)*extent
            call next_index(idx, [3, 3, 3])
        end do
        w = 1.0_dp
        cp(:, 14) = cp(:, 14) + [0.4_dp, -0.25_dp, 0.15_dp]
        w(14) = weight
        do a = 1, 3
            knots(a)%u = [0.0_dp, 0.0_dp, 0.0_dp, 1.0_dp, 1.0_dp, 1.0_dp]
        end do
        patch = new_patch([2, 2, 2], knots, [3, 3, 3], cp, w)
    end function distorted_box

    !> A Dirichlet condition on `face`: components `fix` [3] at `value` (one phase).
    function on_face(face, fix, value) result(d)
        character(len=*), intent(in) :: face
        logical, intent(in) :: fix(3)
        real(dp), intent(in) :: value(3)
        type(dirichlet_settings_t) :: d
        d%body = 'block'
        d%edge = face
        d%fix = fix
        d%values = reshape(value, [3, 1])
    end function on_face

    !> The model of the distorted box with `layout`, `material` (E = 2, nu = 0.3),
    !> `n_steps` steps, a uniaxial stretch by `stretch` (ux on 'right') and the
    !> symmetry planes 'left', 'front', 'bottom'.
    subroutine uniaxial(layout, material, stretch, n_steps, c, model, error, weight, n_gauss)
        type(layout_t), intent(in) :: layout
        character(len=*), intent(in) :: material
        real(dp), intent(in) :: stretch
        integer, intent(in) :: n_steps
        type(scene_t), intent(out) :: c
        type(model_t), intent(out) :: model
        type(error_t), allocatable, intent(out) :: error
        !> The centre control point's weight (default 1: a polynomial map), and Gauss
        !> points per direction (default 0: degree + 1).
        real(dp), intent(in), optional :: weight
        integer, intent(in), optional :: n_gauss
        type(discretization_t) :: discs(1)
        real(dp) :: w
        w = 1.0_dp
        if (present(weight)) w = weight
        c%bodies = [body_settings('block', material, 2.0_dp, layout)]
        if (present(n_gauss)) c%solver%n_gauss = n_gauss
        c%solver%n_steps = [n_steps]
        allocate (c%pressure(0), c%contact(0))
        c%dirichlet = [on_face('left', [.true., .false., .false.], [0.0_dp, 0.0_dp, 0.0_dp]), &
                       on_face('front', [.false., .true., .false.], [0.0_dp, 0.0_dp, 0.0_dp]), &
                       on_face('bottom', [.false., .false., .true.], [0.0_dp, 0.0_dp, 0.0_dp]), &
                       on_face('right', [.true., .false., .false.], [stretch*extent(1), 0.0_dp, 0.0_dp])]
        call new_discretization(discs(1), distorted_box(w), faces, layout, '', error)
        if (allocated(error)) return
        call scene_model(c, discs, model, error)
    end subroutine uniaxial

    !> Uniaxial stress by a prescribed stretch: u = eps (x, -nu y, -nu z) lies in
    !> every space (NURBS reproduce linear fields), so the control values are it to
    !> round-off; with a layer on a face across (top) and along (right) the stretch.
    subroutine test_patch_linear(error)
        type(error_t), allocatable, intent(out) :: error
        type(layout_t) :: layouts(4)
        type(scene_t) :: c
        type(model_t) :: model
        type(solver_stats_t) :: stats
        real(dp), allocatable :: u(:)
        real(dp), parameter :: eps = 0.01_dp, nu = 0.3_dp
        real(dp) :: worst, x(3)
        integer :: il, a
        layouts = [layout3(2, [2, 2, 2], 0, 0, ''), layout3(3, [2, 1, 2], 0, 0, ''), &
                   layout3(2, [2, 2, 2], 3, 0, 'top'), layout3(2, [2, 3, 2], 3, 1, 'right')]
        do il = 1, size(layouts)
            call uniaxial(layouts(il), 'linear', eps, 1, c, model, error)
            if (allocated(error)) return
            call solve_steps(model, c%solver, u, stats, error)
            if (allocated(error)) return
            worst = 0.0_dp
            do a = 1, model%bodies(1)%disc%ncp
                x = model%bodies(1)%disc%x(:, a)
                worst = max(worst, maxval(abs(u(3*a - 2:3*a) - eps*[x(1), -nu*x(2), -nu*x(3)])))
            end do
            ! only round-off remains (cond(K) ~ 1e4 - 1e5)
            call check(error, worst, 0.0_dp, 'layout '//char(48 + il)//': max |u - u_exact|', abs=1.0e-11_dp)
            if (allocated(error)) return
        end do
    end subroutine test_patch_linear

    !> Uniaxial tension by a traction (a negative pressure) on the face x = 3 of the
    !> distorted box, layer on top: u = sigma/E (x, -nu y, -nu z) to round-off.
    subroutine test_patch_pressure(error)
        type(error_t), allocatable, intent(out) :: error
        type(scene_t) :: c
        type(model_t) :: model
        type(solver_stats_t) :: stats
        real(dp), allocatable :: u(:)
        real(dp), parameter :: sigma = 0.02_dp, e = 2.0_dp, nu = 0.3_dp
        real(dp) :: worst, x(3)
        integer :: a
        call uniaxial(layout3(2, [2, 2, 2], 3, 1, 'top'), 'linear', 0.0_dp, 1, c, model, error)
        if (allocated(error)) return
        ! the same supports, the stretch replaced by the traction
        c%dirichlet = c%dirichlet(1:3)
        c%pressure = [pressure_settings_t(body='block', edge='right', values=[-sigma])]
        block
            type(discretization_t) :: discs(1)
            discs(1) = model%bodies(1)%disc
            call scene_model(c, discs, model, error)
            if (allocated(error)) return
        end block
        call solve_steps(model, c%solver, u, stats, error)
        if (allocated(error)) return
        worst = 0.0_dp
        do a = 1, model%bodies(1)%disc%ncp
            x = model%bodies(1)%disc%x(:, a)
            worst = max(worst, maxval(abs(u(3*a - 2:3*a) - sigma/e*[x(1), -nu*x(2), -nu*x(3)])))
        end do
        call check(error, worst, 0.0_dp, 'max |u - u_exact|', abs=1.0e-11_dp)
    end subroutine test_patch_pressure

    !> On a rational map (the centre weight 0.7) the patch test holds to the
    !> accuracy of the quadrature, not exactly: int grad R_a dV is no longer a
    !> polynomial integral. The error falls to round-off as the Gauss points grow.
    subroutine test_patch_rational(error)
        type(error_t), allocatable, intent(out) :: error
        type(scene_t) :: c
        type(model_t) :: model
        type(solver_stats_t) :: stats
        real(dp), allocatable :: u(:)
        real(dp), parameter :: eps = 0.01_dp, nu = 0.3_dp
        integer, parameter :: points(4) = [3, 5, 8, 12]
        real(dp) :: worst(size(points)), x(3)
        integer :: k, a
        do k = 1, size(points)
            call uniaxial(layout3(2, [2, 2, 2], 3, 0, 'top'), 'linear', eps, 1, c, model, error, 0.7_dp, points(k))
            if (allocated(error)) return
            call solve_steps(model, c%solver, u, stats, error)
            if (allocated(error)) return
            worst(k) = 0.0_dp
            do a = 1, model%bodies(1)%disc%ncp
                x = model%bodies(1)%disc%x(:, a)
                worst(k) = max(worst(k), maxval(abs(u(3*a - 2:3*a) - eps*[x(1), -nu*x(2), -nu*x(3)])))
            end do
        end do
        ! measured: 7.3e-7, 1.1e-11, 1.0e-16, 1.2e-16
        call check(error, worst(1) > worst(2) .and. worst(2) > worst(3), 'the error falls with more points')
        if (allocated(error)) return
        call check(error, maxval(worst(3:)), 0.0_dp, 'round-off with 8 and 12 points', abs=1.0e-13_dp)
    end subroutine test_patch_rational

    !> A Neo-Hookean stretch by 30 %: the homogeneous deformation F = diag(1.3, s, s)
    !> lies in the space; the lateral stretch s is the one with tau_yy = 0.
    subroutine test_patch_neo_hookean(error)
        type(error_t), allocatable, intent(out) :: error
        type(scene_t) :: c
        type(model_t) :: model
        type(solver_stats_t) :: stats
        type(neo_hookean_t) :: law
        real(dp), allocatable :: u(:)
        real(dp) :: s, worst, x(3), tau(3, 3), tangent(3, 3, 3, 3), g(3, 3)
        integer :: a
        logical :: ok
        call uniaxial(layout3(2, [2, 2, 2], 3, 1, 'top'), 'neo-hookean', 0.3_dp, 3, c, model, error)
        if (allocated(error)) return
        call solve_steps(model, c%solver, u, stats, error)
        if (allocated(error)) return
        ! the lateral stretch from the point farthest from the y = 0 plane
        a = maxloc(model%bodies(1)%disc%x(2, :), 1)
        s = 1.0_dp + u(3*a - 1)/model%bodies(1)%disc%x(2, a)
        worst = 0.0_dp
        do a = 1, model%bodies(1)%disc%ncp
            x = model%bodies(1)%disc%x(:, a)
            worst = max(worst, maxval(abs(u(3*a - 2:3*a) - [0.3_dp*x(1), (s - 1)*x(2), (s - 1)*x(3)])))
        end do
        call check(error, worst, 0.0_dp, 'homogeneous deformation, max |u - u_exact|', abs=1.0e-10_dp)
        if (allocated(error)) return
        call lame_from_young(law, 2.0_dp, 0.3_dp)
        g = 0.0_dp
        g(1, 1) = 0.3_dp
        g(2, 2) = s - 1
        g(3, 3) = s - 1
        call law%stress3(g, tau, tangent, ok)
        call check(error, ok .and. abs(tau(2, 2)) < 1.0e-10_dp*abs(tau(1, 1)), 'tau_yy = 0 at the lateral stretch')
    end subroutine test_patch_neo_hookean

    !> The assembled tangent of a Neo-Hookean VO body at a random finite deformation
    !> against central differences of the residual, column by column.
    subroutine test_global_tangent(error)
        type(error_t), allocatable, intent(out) :: error
        type(scene_t) :: c
        type(model_t) :: model
        type(csc_matrix_t) :: k
        type(assembly_stats_t) :: stats
        type(lcg_t) :: rng
        real(dp), allocatable :: u(:), r(:), rp(:), rm(:), e(:), kcol(:)
        real(dp), parameter :: h = 1.0e-6_dp
        real(dp) :: worst, scale, x(3)
        integer :: j, a
        call uniaxial(layout3(2, [2, 1, 1], 3, 0, 'top'), 'neo-hookean', 0.0_dp, 1, c, model, error)
        if (allocated(error)) return
        allocate (u(model%ndof), r(model%ndof), rp(model%ndof), rm(model%ndof), e(model%ndof), kcol(model%ndof))
        do a = 1, model%bodies(1)%disc%ncp
            x = model%bodies(1)%disc%x(:, a)
            u(3*a - 2:3*a) = [0.1_dp*x(1) + 0.05_dp*x(2)*x(3), -0.08_dp*x(2) + 0.04_dp*x(1)**2, 0.06_dp*x(1)*x(3)] + &
                             0.02_dp*[rng%uniform(), rng%uniform(), rng%uniform()] - 0.01_dp
        end do
        use_pattern: block
            use voiga_model_assembly, only: stiffness_pattern
            call stiffness_pattern(model, k, error)
            if (allocated(error)) return
        end block use_pattern
        call assemble(model, u, 0.5_dp, r, stats, error, k)
        if (allocated(error)) return
        worst = 0.0_dp
        scale = maxval(abs(k%values))
        do j = 1, model%ndof
            u(j) = u(j) + h
            call assemble(model, u, 0.5_dp, rp, stats, error)
            u(j) = u(j) - 2*h
            call assemble(model, u, 0.5_dp, rm, stats, error)
            u(j) = u(j) + h
            if (allocated(error)) return
            e = 0.0_dp
            e(j) = 1.0_dp
            call k%matvec(e, kcol)
            worst = max(worst, maxval(abs(kcol - (rp - rm)/(2*h)))/scale)
        end do
        call check(error, worst, 0.0_dp, 'global tangent vs FD (relative to max |K|)', abs=1.0e-6_dp)
    end subroutine test_global_tangent

    !> A Neo-Hookean VO box stretched by 40 % in three steps, each step from the last
    !> state (no predictor): every step converges quadratically.
    subroutine test_quadratic(error)
        type(error_t), allocatable, intent(out) :: error
        type(scene_t) :: c
        type(model_t) :: model
        type(solver_stats_t) :: stats
        real(dp), allocatable :: u(:)
        integer :: k
        call uniaxial(layout3(2, [2, 2, 1], 3, 1, 'right'), 'neo-hookean', 0.4_dp, 3, c, model, error)
        if (allocated(error)) return
        c%solver%predictor = .false.
        call solve_steps(model, c%solver, u, stats, error)
        if (allocated(error)) return
        call check(error, stats%steps, 3, 'all steps converged')
        if (allocated(error)) return
        do k = 1, 3
            call check(error, quadratic(stats%records(k)%residual_norms), 'quadratic convergence')
            if (allocated(error)) return
        end do
    end subroutine test_quadratic

end module test_solid_3d
