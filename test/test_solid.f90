!> The solid solver: consistent tangents, patch tests, the thick-walled
!> cylinder (Lame) convergence, quadratic Newton convergence at finite strain,
!> and that a small-strain case runs no finite-strain code.
module test_solid
    use voiga_kinds, only: dp, i8
    use voiga_error, only: error_t
    use voiga_testdrive, only: unittest_t, new_unittest, check
    use voiga_nurbs_surface, only: nurbs_surface_t
    use voiga_discretization_layout, only: layout_t
    use voiga_discretization_patch, only: discretization_t, new_discretization
    use voiga_discretization_element, only: element_basis, element_nfun
    use voiga_model, only: model_t
    use voiga_model_body, only: body_points
    use voiga_model_loads, only: dirichlet_settings_t, pressure_settings_t
    use voiga_model_assembly, only: body_element, body_dofs, assemble, assembly_stats_t
    use voiga_element_quadrature, only: gauss_legendre
    use voiga_element_solid, only: reference_gradients
    use voiga_linalg_sparse, only: csc_matrix_t
    use voiga_solver_records, only: solver_stats_t
    use voiga_solver_stepping, only: solve_steps
    use voiga_test_fixtures, only: paper_layout, lcg_t, annulus_sector, rectangle, quadratic, scene_t, scene_model
    implicit none
    private

    public :: collect_solid, lame_table

    real(dp), parameter :: pi = acos(-1.0_dp)

contains

    subroutine collect_solid(testsuite)
        type(unittest_t), allocatable, intent(out) :: testsuite(:)
        testsuite = [ &
                    new_unittest('element_tangent_fd', test_element_tangent), &
                    new_unittest('global_tangent_fd', test_global_tangent), &
                    new_unittest('patch_test_dirichlet', test_patch_dirichlet), &
                    new_unittest('patch_test_pressure', test_patch_pressure), &
                    new_unittest('lame_convergence', test_lame), &
                    new_unittest('newton_quadratic', test_quadratic), &
                    new_unittest('small_strain_runs_linear_only', test_small_strain_only) &
                    ]
    end subroutine collect_solid

    !> A one-body case on `surf` with the given material and layout.
    function one_body_case(material, layout, e, nu) result(c)
        character(len=*), intent(in) :: material
        type(layout_t), intent(in) :: layout
        real(dp), intent(in) :: e, nu
        type(scene_t) :: c
        allocate (c%bodies(1))
        c%bodies(1)%name = 'block'
        c%bodies(1)%material = material
        c%bodies(1)%youngs_modulus = e
        c%bodies(1)%poisson_ratio = nu
        c%bodies(1)%layout = layout
        c%solver%n_steps = [1]
        allocate (c%dirichlet(0), c%pressure(0), c%contact(0))
    end function one_body_case

    !> Append a Dirichlet condition.
    subroutine add_dirichlet(c, edge, fix, values)
        type(scene_t), intent(inout) :: c
        character(len=*), intent(in) :: edge
        logical, intent(in) :: fix(2)
        real(dp), intent(in) :: values(:, :)
        type(dirichlet_settings_t) :: d
        d%body = 'block'
        d%edge = edge
        d%fix(:2) = fix
        d%values = values
        c%dirichlet = [c%dirichlet, d]
    end subroutine add_dirichlet


    !> Build model from a case and one coarse patch.
    subroutine build(c, coarse, model, error)
        type(scene_t), intent(in) :: c
        type(nurbs_surface_t), intent(in) :: coarse
        type(model_t), intent(out) :: model
        type(error_t), allocatable, intent(out) :: error
        type(discretization_t) :: discs(1)
        type(scene_t) :: scene
        call new_discretization(discs(1), coarse, c%bodies(1)%layout, '', error)
        if (allocated(error)) return
        scene = c
        call scene_model(scene, discs, model, error)
    end subroutine build

    !> Random displacement of a die-shaped body with 0.6 <= J <= 1.6 (checked).
    subroutine large_deformation(model, rng, u)
        type(model_t), intent(in) :: model
        type(lcg_t), intent(inout) :: rng
        real(dp), intent(out) :: u(:)
        real(dp) :: g(2, 2)
        integer :: a
        ! a smooth non-homogeneous stretch, shear and bending (J from ~0.75 to ~1.3
        ! over the die) plus a small random perturbation of every control point
        do a = 1, model%bodies(1)%disc%ncp
            g(:, 1) = model%bodies(1)%disc%x(:, a) - [2.5_dp, 1.5_dp]
            u(2*a - 1) = 0.15_dp*g(1, 1) + 0.05_dp*g(2, 1)**2 + 0.02_dp*(rng%uniform() - 0.5_dp)
            u(2*a) = 0.08_dp*g(2, 1)*g(1, 1) - 0.1_dp*(g(2, 1) + 1.5_dp) + 0.02_dp*(rng%uniform() - 0.5_dp)
        end do
    end subroutine large_deformation

    !> Range of J over the quadrature points of body 1.
    subroutine j_range(model, u, jmin, jmax)
        type(model_t), intent(in) :: model
        real(dp), intent(in) :: u(:)
        real(dp), intent(out) :: jmin, jmax
        real(dp), allocatable :: r(:), dr(:, :), d2r(:, :), dndx(:, :), ue(:, :)
        real(dp) :: gx(4), wx(4), det, f(2, 2)
        integer :: e, i, j, n
        call gauss_legendre(4, gx, wx)
        jmin = huge(1.0_dp)
        jmax = -huge(1.0_dp)
        associate (b => model%bodies(1))
            do e = 1, b%disc%nel
                n = element_nfun(b%disc, e)
                allocate (r(n), dr(2, n), d2r(3, n), dndx(2, n))
                ue = reshape(u(body_dofs(b, e)), [2, n])
                do j = 1, 4
                    do i = 1, 4
                        associate (el => b%disc%elements(e))
                            call element_basis(b%disc, e, [el%lo(1) + (gx(i) + 1)/2*(el%hi(1) - el%lo(1)), &
                                               el%lo(2) + (gx(j) + 1)/2*(el%hi(2) - el%lo(2))], r, dr, d2r)
                        end associate
                        call reference_gradients(b%disc%x(:, b%disc%elements(e)%conn), dr, dndx, det)
                        f = matmul(ue, transpose(dndx))
                        f(1, 1) = f(1, 1) + 1
                        f(2, 2) = f(2, 2) + 1
                        jmin = min(jmin, f(1, 1)*f(2, 2) - f(1, 2)*f(2, 1))
                        jmax = max(jmax, f(1, 1)*f(2, 2) - f(1, 2)*f(2, 1))
                    end do
                end do
                deallocate (r, dr, d2r, dndx)
            end do
        end associate
    end subroutine j_range

    !> Element stiffness against central differences of the element force.
    subroutine test_element_tangent(error)
        type(error_t), allocatable, intent(out) :: error
        character(len=5), parameter :: names(3) = [character(len=5) :: 'N2', 'NN2.2', 'NN4']
        character(len=11), parameter :: mats(2) = [character(len=11) :: 'neo-hookean', 'linear']
        type(model_t) :: model
        type(lcg_t) :: rng
        real(dp), allocatable :: u(:), fe(:), ke(:, :), fp(:), fm(:), kp(:, :), kfd(:, :)
        real(dp) :: h, jmin, jmax, err
        integer :: il, im, e, n, col
        integer, allocatable :: dofs(:)
        logical :: ok

        do im = 1, 2
            do il = 1, 3
                call build(one_body_case(trim(mats(im)), paper_layout(trim(names(il)), [4, 2], 'outer'), &
                                         10.0_dp, 0.3_dp), &
                           annulus_sector([2.5_dp, 3.0_dp], 2.0_dp, 3.0_dp, pi, 2), model, error)
                if (allocated(error)) return
                allocate (u(model%ndof))
                call large_deformation(model, rng, u)
                call j_range(model, u, jmin, jmax)
                call check(error, jmin > 0.6_dp .and. jmax < 1.6_dp .and. jmax - jmin > 0.2_dp, &
                           'test deformation has 0.6 < J < 1.6 and varies')
                if (allocated(error)) return
                ! a VO element (last row) and a bulk element
                do e = 1, model%bodies(1)%disc%nel, model%bodies(1)%disc%nel - 1
                    dofs = body_dofs(model%bodies(1), e)
                    n = size(dofs)
                    allocate (fe(n), ke(n, n), fp(n), fm(n), kp(n, n), kfd(n, n))
                    call body_element(model%bodies(1), e, u, fe, ke, ok)
                    do col = 1, n
                        ! step relative to the displacement scale; central differences
                        ! are O(h^2) accurate: 1e-6 relative is met with margin
                        h = 1.0e-6_dp
                        u(dofs(col)) = u(dofs(col)) + h
                        call body_element(model%bodies(1), e, u, fp, kp, ok)
                        u(dofs(col)) = u(dofs(col)) - 2*h
                        call body_element(model%bodies(1), e, u, fm, kp, ok)
                        u(dofs(col)) = u(dofs(col)) + h
                        kfd(:, col) = (fp - fm)/(2*h)
                    end do
                    err = maxval(abs(ke - kfd))/maxval(abs(ke))
                    call check(error, err, 0.0_dp, trim(mats(im))//' '//trim(names(il))// &
                               ' element tangent vs FD (relative)', abs=1.0e-6_dp)
                    if (allocated(error)) return
                    call check(error, maxval(abs(ke - transpose(ke)))/maxval(abs(ke)), 0.0_dp, &
                               'tangent symmetric (hyperelastic)', abs=1.0e-12_dp)
                    if (allocated(error)) return
                    deallocate (fe, ke, fp, fm, kp, kfd)
                end do
                deallocate (u)
            end do
        end do
    end subroutine test_element_tangent

    !> Global stiffness against central differences of the global residual (NN2.2, Neo-Hookean).
    subroutine test_global_tangent(error)
        type(error_t), allocatable, intent(out) :: error
        type(model_t) :: model
        type(scene_t) :: c
        type(lcg_t) :: rng
        type(csc_matrix_t) :: k
        type(assembly_stats_t) :: stats
        real(dp), allocatable :: u(:), r(:), rp(:), rm(:), col(:), e(:), kcol(:)
        real(dp), parameter :: h = 1.0e-6_dp
        real(dp) :: worst, scale
        integer :: j

        c = one_body_case('neo-hookean', paper_layout('NN2.2', [3, 2], 'outer'), 10.0_dp, 0.3_dp)
        call add_dirichlet(c, 'inner', [.true., .true.], reshape([0.0_dp, 0.0_dp], [2, 1]))
        c%pressure = [pressure_settings_t(body='block', edge='outer', values=[0.3_dp])]
        call build(c, annulus_sector([2.5_dp, 3.0_dp], 2.0_dp, 3.0_dp, pi, 2), model, error)
        if (allocated(error)) return
        allocate (u(model%ndof), r(model%ndof), rp(model%ndof), rm(model%ndof), col(model%ndof), &
                  e(model%ndof), kcol(model%ndof))
        call large_deformation(model, rng, u)
        call stiffness_of(model, u, k, r, stats, error)
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
            col = (rp - rm)/(2*h)
            e = 0.0_dp
            e(j) = 1.0_dp
            call k%matvec(e, kcol)
            worst = max(worst, maxval(abs(kcol - col))/scale)
        end do
        call check(error, worst, 0.0_dp, 'global tangent vs FD (relative to max |K|)', abs=1.0e-6_dp)
    end subroutine test_global_tangent

    subroutine stiffness_of(model, u, k, r, stats, error)
        type(model_t), intent(inout) :: model
        real(dp), intent(in) :: u(:)
        type(csc_matrix_t), intent(out) :: k
        real(dp), intent(out) :: r(:)
        type(assembly_stats_t), intent(inout) :: stats
        type(error_t), allocatable, intent(out) :: error
        use_pattern: block
            use voiga_model_assembly, only: stiffness_pattern
            call stiffness_pattern(model, k, error)
            if (allocated(error)) return
        end block use_pattern
        call assemble(model, u, 0.5_dp, r, stats, error, k)
    end subroutine stiffness_of

    !> Distort the interior control points (the boundary, hence the geometry, stays).
    subroutine distort_interior(model, rng, amount)
        type(model_t), intent(inout) :: model
        type(lcg_t), intent(inout) :: rng
        real(dp), intent(in) :: amount
        logical, allocatable :: boundary(:)
        integer :: a, k
        associate (d => model%bodies(1)%disc)
            allocate (boundary(d%ncp))
            boundary = .false.
            do k = 1, 4
                boundary(d%boundaries(k)%cps) = .true.
            end do
            do a = 1, d%ncp
                if (.not. boundary(a)) d%x(:, a) = d%x(:, a) + amount*[rng%uniform() - 0.5_dp, &
                                                                       rng%uniform() - 0.5_dp]
            end do
        end associate
        call body_points(model%bodies(1))
    end subroutine distort_interior

    !> Uniaxial stretch by Dirichlet conditions: the exact field is linear.
    subroutine test_patch_dirichlet(error)
        type(error_t), allocatable, intent(out) :: error
        call patch_test(error, .false.)
    end subroutine test_patch_dirichlet

    !> Uniaxial tension by a pressure (negative: traction) on the right edge.
    subroutine test_patch_pressure(error)
        type(error_t), allocatable, intent(out) :: error
        call patch_test(error, .true.)
    end subroutine test_patch_pressure

    subroutine patch_test(error, by_pressure)
        type(error_t), allocatable, intent(out) :: error
        logical, intent(in) :: by_pressure
        character(len=5), parameter :: names(4) = [character(len=5) :: 'N2', 'N4', 'NN2.2', 'NN4']
        type(model_t) :: model
        type(scene_t) :: c
        type(lcg_t) :: rng
        type(solver_stats_t) :: stats
        real(dp), allocatable :: u(:)
        real(dp) :: ex, ey, worst, x(2), sxx
        integer :: il, a

        ! plane strain, sigma_yy = 0: eps_yy = -nu/(1-nu) eps_xx; sigma_xx = E/(1-nu^2) eps_xx
        ex = 0.01_dp
        ey = -0.3_dp/0.7_dp*ex
        sxx = 2.0_dp/(1.0_dp - 0.09_dp)*ex
        do il = 1, size(names)
            c = one_body_case('linear', paper_layout(trim(names(il)), [4, 3], 'top'), 2.0_dp, 0.3_dp)
            call add_dirichlet(c, 'left', [.true., .false.], reshape([0.0_dp, 0.0_dp], [2, 1]))
            call add_dirichlet(c, 'bottom', [.false., .true.], reshape([0.0_dp, 0.0_dp], [2, 1]))
            if (by_pressure) then
                ! force per length: a negative pressure pulls
                c%pressure = [pressure_settings_t(body='block', edge='right', values=[-sxx])]
            else
                call add_dirichlet(c, 'right', [.true., .false.], reshape([ex*3.0_dp, 0.0_dp], [2, 1]))
            end if
            call build(c, rectangle(0.0_dp, 0.0_dp, 3.0_dp, 2.0_dp), model, error)
            if (allocated(error)) return
            call distort_interior(model, rng, 0.15_dp)
            call solve_steps(model, c%solver, u, stats, error)
            if (allocated(error)) return
            worst = 0.0_dp
            do a = 1, model%bodies(1)%disc%ncp
                x = model%bodies(1)%disc%x(:, a)
                worst = max(worst, abs(u(2*a - 1) - ex*x(1)), abs(u(2*a) - ey*x(2)))
            end do
            ! the exact field lies in every space: only round-off (cond(K) ~ 1e4) remains
            call check(error, worst, 0.0_dp, trim(names(il))//' patch test, max |u - u_exact|', &
                       abs=1.0e-10_dp)
            if (allocated(error)) return
        end do
    end subroutine patch_test

    !> Exact Lame displacement (plane strain) for inner radius ra, outer rb, pressure p.
    pure function lame_u(x, ra, rb, p, e, nu) result(u)
        real(dp), intent(in) :: x(2), ra, rb, p, e, nu
        real(dp) :: u(2), r, aa, bb, ur
        r = norm2(x)
        aa = p*ra**2/(rb**2 - ra**2)
        bb = p*ra**2*rb**2/(rb**2 - ra**2)
        ur = (1.0_dp + nu)/e*((1.0_dp - 2.0_dp*nu)*aa*r + bb/r)
        u = ur*x/r
    end function lame_u

    !> Relative L2 error of the displacement for the Lame problem on nel x nel, degree p.
    subroutine lame_error(p, nel, err, ndof, error)
        integer, intent(in) :: p, nel
        real(dp), intent(out) :: err
        integer, intent(out) :: ndof
        type(error_t), allocatable, intent(out) :: error
        type(model_t) :: model
        type(scene_t) :: c
        type(layout_t) :: layout
        type(solver_stats_t) :: stats
        real(dp), allocatable :: u(:), r(:), dr(:, :), d2r(:, :), dndx(:, :), gx(:), wx(:)
        real(dp) :: num, den, x(2), uh(2), ue(2), det, xi, eta
        integer :: e, i, j, n, ng
        integer, allocatable :: dofs(:)

        layout%degree(:2) = [p, p]
        layout%nel(:2) = [nel, nel]
        c = one_body_case('linear', layout, 1000.0_dp, 0.3_dp)
        c%solver%n_gauss = 6
        ! quarter annulus 1 <= r <= 2 in the first quadrant: xi from angle 0 to 90 deg
        call add_dirichlet(c, 'start', [.false., .true.], reshape([0.0_dp, 0.0_dp], [2, 1]))
        call add_dirichlet(c, 'end', [.true., .false.], reshape([0.0_dp, 0.0_dp], [2, 1]))
        c%pressure = [pressure_settings_t(body='block', edge='inner', values=[1.0_dp])]
        call build(c, annulus_sector([0.0_dp, 0.0_dp], 1.0_dp, 2.0_dp, 0.0_dp, 1), model, error)
        if (allocated(error)) return
        call solve_steps(model, c%solver, u, stats, error)
        if (allocated(error)) return
        ndof = model%ndof
        ng = p + 2
        allocate (gx(ng), wx(ng))
        call gauss_legendre(ng, gx, wx)
        num = 0.0_dp
        den = 0.0_dp
        associate (b => model%bodies(1))
            do e = 1, b%disc%nel
                n = element_nfun(b%disc, e)
                allocate (r(n), dr(2, n), d2r(3, n), dndx(2, n))
                dofs = body_dofs(b, e)
                associate (el => b%disc%elements(e))
                    do j = 1, ng
                        do i = 1, ng
                            xi = el%lo(1) + (gx(i) + 1)/2*(el%hi(1) - el%lo(1))
                            eta = el%lo(2) + (gx(j) + 1)/2*(el%hi(2) - el%lo(2))
                            call element_basis(b%disc, e, [xi, eta], r, dr, d2r)
                            call reference_gradients(b%disc%x(:, el%conn), dr, dndx, det)
                            x = matmul(b%disc%x(:, el%conn), r)
                            uh = matmul(reshape(u(dofs), [2, n]), r)
                            ue = lame_u(x, 1.0_dp, 2.0_dp, 1.0_dp, 1000.0_dp, 0.3_dp)
                            num = num + sum((uh - ue)**2)*wx(i)*wx(j)*abs(det)
                            den = den + sum(ue**2)*wx(i)*wx(j)*abs(det)
                        end do
                    end do
                end associate
                deallocate (r, dr, d2r, dndx)
            end do
        end associate
        err = sqrt(num/den)
    end subroutine lame_error

    !> Print the Lame convergence table (docs/verification.md) and return the
    !> observed rates between successive meshes, shape [n_meshes - 1, 2] (p = 2, 3).
    subroutine lame_table(rates, error, verbose)
        real(dp), intent(out) :: rates(5, 3)
        type(error_t), allocatable, intent(out) :: error
        logical, intent(in) :: verbose
        integer, parameter :: meshes(6) = [2, 4, 8, 16, 32, 64]
        real(dp) :: err(6), rate
        integer :: p, m, ndof
        if (verbose) write (*, '(a)') '| p | elements | DOFs | rel. L2 error | rate |', '|---|---|---|---|---|'
        do p = 2, 4
            do m = 1, size(meshes)
                call lame_error(p, meshes(m), err(m), ndof, error)
                if (allocated(error)) return
                rate = 0.0_dp
                if (m > 1) then
                    rate = log(err(m - 1)/err(m))/log(2.0_dp)
                    rates(m - 1, p - 1) = rate
                end if
                if (verbose) write (*, '(a,i0,a,i0,a,i0,a,i0,a,es10.3,a,f5.2,a)') '| ', p, ' | ', &
                    meshes(m), ' x ', meshes(m), ' | ', ndof, ' | ', err(m), ' | ', rate, ' |'
            end do
        end do
    end subroutine lame_table

    !> L2 displacement error converges at rate p + 1 under h-refinement.
    !> p = 2 reaches 3 from above (3.06, 3.03, 3.01, 3.00). p = 3 and 4 approach 4 and
    !> 5 from below, the deficit halving with each refinement (p = 3: 3.77, 3.83, 3.91,
    !> 3.96; p = 4: 4.28, 4.72, 4.91, 4.97): we assert that their rates keep rising and
    !> are within 0.05 of p + 1 on the finest pair (docs/verification.md).
    subroutine test_lame(error)
        type(error_t), allocatable, intent(out) :: error
        real(dp) :: rates(5, 3)
        integer :: p
        call lame_table(rates, error, .false.)
        if (allocated(error)) return
        call check(error, rates(5, 1) >= 3.0_dp .and. rates(4, 1) >= 3.0_dp, &
                   'Lame p = 2: L2 rate >= 3 on the two finest pairs')
        if (allocated(error)) return
        do p = 3, 4
            call check(error, rates(3, p - 1) < rates(4, p - 1) .and. rates(4, p - 1) < rates(5, p - 1), &
                       'Lame p = 3, 4: rate still rising towards p + 1')
            if (allocated(error)) return
            call check(error, rates(5, p - 1) >= real(p + 1, dp) - 0.05_dp, &
                       'Lame p = 3, 4: L2 rate within 0.05 of p + 1 on 32 -> 64')
            if (allocated(error)) return
        end do
    end subroutine test_lame

    !> Block compressed by 30 % (Neo-Hookean, bottom clamped): Newton converges
    !> quadratically.
    subroutine test_quadratic(error)
        type(error_t), allocatable, intent(out) :: error
        type(model_t) :: model
        type(scene_t) :: c
        type(solver_stats_t) :: stats
        real(dp), allocatable :: u(:)
        integer :: k
        call quadratic_model(c)
        call build(c, rectangle(0.0_dp, 0.0_dp, 1.0_dp, 1.0_dp), model, error)
        if (allocated(error)) return
        ! the tangent is what is tested: every step starts from the last state
        c%solver%predictor = .false.
        call solve_steps(model, c%solver, u, stats, error)
        if (allocated(error)) return
        call check(error, stats%steps, 3, 'all steps converged')
        if (allocated(error)) return
        ! measured: local orders log(r_k+1/r_k)/log(r_k/r_k-1) of 1.96-1.99
        do k = 1, 3
            call check(error, quadratic(stats%records(k)%residual_norms), 'quadratic convergence')
            if (allocated(error)) return
        end do
    end subroutine test_quadratic

    subroutine quadratic_model(c)
        type(scene_t), intent(out) :: c
        c = one_body_case('neo-hookean', paper_layout('N2', [4, 4], 'top'), 1.0_dp, 0.3_dp)
        c%solver%n_steps = [3]
        call add_dirichlet(c, 'bottom', [.true., .true.], reshape([0.0_dp, 0.0_dp], [2, 1]))
        call add_dirichlet(c, 'top', [.true., .true.], reshape([0.0_dp, -0.3_dp], [2, 1]))
    end subroutine quadratic_model

    !> A linear case: one Newton iteration per step, no finite-strain evaluation.
    subroutine test_small_strain_only(error)
        type(error_t), allocatable, intent(out) :: error
        type(model_t) :: model
        type(scene_t) :: c
        type(solver_stats_t) :: stats
        real(dp), allocatable :: u(:)
        real(dp), allocatable :: u_first(:)
        c = one_body_case('linear', paper_layout('NN2.2', [4, 3], 'top'), 2.0_dp, 0.3_dp)
        c%solver%n_steps = [4]
        call add_dirichlet(c, 'bottom', [.true., .true.], reshape([0.0_dp, 0.0_dp], [2, 1]))
        call add_dirichlet(c, 'top', [.true., .true.], reshape([0.01_dp, -0.02_dp], [2, 1]))
        call build(c, rectangle(0.0_dp, 0.0_dp, 3.0_dp, 2.0_dp), model, error)
        if (allocated(error)) return
        c%solver%predictor = .false.
        call solve_steps(model, c%solver, u, stats, error)
        if (allocated(error)) return
        call check(error, stats%iterations, 4, 'one Newton iteration per step')
        if (allocated(error)) return
        ! with the predictor, proportional loading of a linear problem is extrapolated
        ! exactly: steps 2-4 start in equilibrium (to round-off) and need no iteration
        u_first = u
        call build(c, rectangle(0.0_dp, 0.0_dp, 3.0_dp, 2.0_dp), model, error)
        if (allocated(error)) return
        c%solver%predictor = .true.
        call solve_steps(model, c%solver, u, stats, error)
        if (allocated(error)) return
        call check(error, stats%iterations, 1, 'predictor: one Newton iteration in all')
        if (allocated(error)) return
        call check(error, maxval(abs(u - u_first)), 0.0_dp, 'predictor: same state', abs=1.0e-12_dp)
        if (allocated(error)) return
        call check(error, stats%assembly%finite_strain_points == 0_i8, 'no finite-strain law evaluated')
        if (allocated(error)) return
        call check(error, stats%assembly%small_strain_points > 0_i8, 'small-strain law evaluated')
        if (allocated(error)) return
        call check(error, stats%symbolic_factorizations, 1, 'one symbolic factorization for the run')
    end subroutine test_small_strain_only

end module test_solid
