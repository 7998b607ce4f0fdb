!> A thick spherical shell under internal pressure (linear elastic, the exact rational
!> NURBS octant with its pole collapsed onto the z axis, Lame's solution): relative L2
!> errors of the displacement and the stress under h-refinement, degrees 2 and 3, with
!> and without a VO layer on the inner face (`fpm test -- --lame-sphere-table` prints
!> the table of docs/verification.md; `fpm test -- lame_sphere` asserts the rates).
module test_lame_sphere
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_testdrive, only: unittest_t, new_unittest, check
    use voiga_nurbs_patch, only: nurbs_patch_t, knots_t, new_patch, next_index
    use voiga_discretization_layout, only: layout_t
    use voiga_discretization_patch, only: discretization_t, new_discretization
    use voiga_discretization_element, only: element_basis
    use voiga_element_quadrature, only: gauss_legendre
    use voiga_element_solid3, only: reference_gradients3
    use voiga_model, only: model_t
    use voiga_model_loads, only: dirichlet_settings_t, pressure_settings_t
    use voiga_solver_records, only: solver_stats_t
    use voiga_solver_stepping, only: solve_steps
    use voiga_test_fixtures, only: scene_t, scene_model, body_settings
    implicit none
    private

    public :: collect_lame_sphere, lame_sphere_table, shell_octant

    !> Inner and outer radius, pressure, E, nu.
    real(dp), parameter :: ra = 1.0_dp, rb = 2.0_dp, pressure = 1.0_dp, young = 1000.0_dp, nu = 0.3_dp
    character(len=32), parameter :: faces(6) = [character(len=32) :: 'start', 'end', 'equator', 'pole', &
                                                'inner', 'outer']

contains

    subroutine collect_lame_sphere(testsuite)
        type(unittest_t), allocatable, intent(out) :: testsuite(:)
        testsuite = [new_unittest('optimal_rates', test_rates)]
    end subroutine collect_lame_sphere

    !> The octant x, y, z >= 0 of the shell ra <= r <= rb: the tensor product of two
    !> quarter arcs (longitude xi, latitude eta; weights w_i w_j, w = (1, 1/sqrt 2, 1))
    !> and the radial line zeta; the pole row (eta = 1) collapses onto the z axis.
    function shell_octant() result(patch)
        type(nurbs_patch_t) :: patch
        real(dp), parameter :: arc(2, 3) = reshape([1.0_dp, 0.0_dp, 1.0_dp, 1.0_dp, 0.0_dp, 1.0_dp], [2, 3])
        real(dp) :: cp(3, 18), w(18), warc(3)
        type(knots_t) :: knots(3)
        integer :: idx(3), a
        warc = [1.0_dp, sqrt(0.5_dp), 1.0_dp]
        idx = 1
        do a = 1, 18
            associate (lon => arc(:, idx(1)), lat => arc(:, idx(2)), r => merge(ra, rb, idx(3) == 1))
                cp(:, a) = r*[lon(1)*lat(1), lon(2)*lat(1), lat(2)]
                w(a) = warc(idx(1))*warc(idx(2))
            end associate
            call next_index(idx, [3, 3, 2])
        end do
        knots(1)%u = [0.0_dp, 0.0_dp, 0.0_dp, 1.0_dp, 1.0_dp, 1.0_dp]
        knots(2)%u = knots(1)%u
        knots(3)%u = [0.0_dp, 0.0_dp, 1.0_dp, 1.0_dp]
        patch = new_patch([2, 2, 1], knots, [3, 3, 2], cp, w)
    end function shell_octant

    !> Lame's displacement at `x`: u_r = p a^3/(E (b^3 - a^3)) ((1 - 2 nu) r + (1 + nu) b^3/(2 r^2)).
    pure function exact_u(x) result(u)
        real(dp), intent(in) :: x(3)
        real(dp) :: u(3), r
        r = norm2(x)
        u = pressure*ra**3/(young*(rb**3 - ra**3))*((1 - 2*nu)*r + (1 + nu)*rb**3/(2*r**2))*x/r
    end function exact_u

    !> Lame's stress at `x`: sigma = s_tt I + (s_rr - s_tt) e_r e_r^T with
    !> s_rr = c (1 - b^3/r^3), s_tt = c (1 + b^3/(2 r^3)), c = p a^3/(b^3 - a^3).
    pure function exact_stress(x) result(s)
        real(dp), intent(in) :: x(3)
        real(dp) :: s(3, 3), r, c, srr, stt, e(3)
        integer :: i
        r = norm2(x)
        e = x/r
        c = pressure*ra**3/(rb**3 - ra**3)
        srr = c*(1 - rb**3/r**3)
        stt = c*(1 + rb**3/(2*r**3))
        s = (srr - stt)*spread(e, 2, 3)*spread(e, 1, 3)
        do i = 1, 3
            s(i, i) = s(i, i) + stt
        end do
    end function exact_stress

    !> Solve the shell with degree `p`, `nel` elements per direction and a layer of
    !> degree `q` (0: none) on the inner face; relative L2 errors of u and sigma over the
    !> reference volume (Gauss points p + 3 per direction), and the DOFs.
    subroutine lame_errors(p, nel, q, err_u, err_s, ndof, error)
        integer, intent(in) :: p, nel, q
        real(dp), intent(out) :: err_u, err_s
        integer, intent(out) :: ndof
        type(error_t), allocatable, intent(out) :: error
        type(scene_t) :: c
        type(layout_t) :: layout
        type(discretization_t) :: discs(1)
        type(model_t) :: model
        type(solver_stats_t) :: stats
        real(dp), allocatable :: u(:)
        real(dp) :: num(2), den(2)

        layout%degree = p
        layout%nel = nel
        layout%layer_degree = q
        if (q > 0) layout%contact_edge = 'inner'
        c%bodies = [body_settings('shell', 'linear', young, layout)]
        c%solver%n_steps = [1]
        allocate (c%contact(0))
        c%dirichlet = [fixed('start', 2), fixed('end', 1), fixed('equator', 3)]
        c%pressure = [pressure_settings_t(body='shell', edge='inner', values=[pressure])]
        call new_discretization(discs(1), shell_octant(), faces, layout, '', error)
        if (allocated(error)) return
        call scene_model(c, discs, model, error)
        if (allocated(error)) return
        call solve_steps(model, c%solver, u, stats, error)
        if (allocated(error)) return
        ndof = model%ndof
        call integrate_errors(model, u, p + 3, num, den)
        err_u = sqrt(num(1)/den(1))
        err_s = sqrt(num(2)/den(2))
    end subroutine lame_errors

    !> The symmetry condition u_c = 0 on `face`.
    function fixed(face, component) result(d)
        character(len=*), intent(in) :: face
        integer, intent(in) :: component
        type(dirichlet_settings_t) :: d
        d%body = 'shell'
        d%edge = face
        d%fix = .false.
        d%fix(component) = .true.
        d%values = reshape([0.0_dp, 0.0_dp, 0.0_dp], [3, 1])
    end function fixed

    !> int |u_h - u|^2, int |u|^2 (num(1), den(1)) and the same for the stress (Frobenius
    !> norm; num(2), den(2)) over the body of `model`, with `ng` Gauss points per direction.
    subroutine integrate_errors(model, u, ng, num, den)
        type(model_t), intent(in) :: model
        real(dp), intent(in) :: u(:)
        integer, intent(in) :: ng
        real(dp), intent(out) :: num(2), den(2)
        real(dp) :: g(ng), w(ng), uu(3), x(3), uh(3), gradu(3, 3), eps(3, 3), sh(3, 3), se(3, 3), det, wt
        real(dp), allocatable :: r(:), dr(:, :), dndx(:, :), ue(:, :)
        integer :: e, a, k, idx(3), i
        call gauss_legendre(ng, g, w)
        num = 0.0_dp
        den = 0.0_dp
        associate (disc => model%bodies(1)%disc, mat => model%bodies(1)%mat)
            do e = 1, disc%nel
                associate (el => disc%elements(e))
                    allocate (r(size(el%conn)), dr(3, size(el%conn)), dndx(3, size(el%conn)), ue(3, size(el%conn)))
                    do a = 1, size(el%conn)
                        ue(:, a) = u(3*el%conn(a) - 2:3*el%conn(a))
                    end do
                    idx = 1
                    do k = 1, ng**3
                        uu = el%lo + 0.5_dp*(g(idx) + 1.0_dp)*(el%hi - el%lo)
                        call element_basis(disc, e, uu, r, dr)
                        call reference_gradients3(disc%x(:, el%conn), dr, dndx, det)
                        x = matmul(disc%x(:, el%conn), r)
                        uh = matmul(ue, r)
                        gradu = matmul(ue, transpose(dndx))
                        eps = 0.5_dp*(gradu + transpose(gradu))
                        sh = 2*mat%mu*eps
                        do i = 1, 3
                            sh(i, i) = sh(i, i) + mat%lambda*(eps(1, 1) + eps(2, 2) + eps(3, 3))
                        end do
                        se = exact_stress(x)
                        wt = w(idx(1))*w(idx(2))*w(idx(3))*product(0.5_dp*(el%hi - el%lo))*abs(det)
                        num = num + wt*[sum((uh - exact_u(x))**2), sum((sh - se)**2)]
                        den = den + wt*[sum(exact_u(x)**2), sum(se**2)]
                        call next_index(idx, [ng, ng, ng])
                    end do
                    deallocate (r, dr, dndx, ue)
                end associate
            end do
        end associate
    end subroutine integrate_errors

    !> Errors and observed rates (log2 of the ratio between successive meshes) for
    !> degrees 2 and 3, nel = 1, 2, 4, 8, without a layer and with one of degree p + 1
    !> on the inner face: rates(mesh, quantity (u, sigma), case).
    subroutine lame_sphere_table(rates, error, verbose)
        real(dp), intent(out) :: rates(3, 2, 4)
        type(error_t), allocatable, intent(out) :: error
        logical, intent(in) :: verbose
        integer, parameter :: meshes(4) = [1, 2, 4, 8]
        real(dp) :: eu(4), es(4)
        integer :: ic, m, p, q, ndof
        character(len=160) :: line
        if (verbose) write (*, '(a)') '| p | layer | elements | DOFs | L2 error u | rate | L2 error sigma | rate |', &
            '|---|---|---|---|---|---|---|---|'
        do ic = 1, 4
            p = 2 + (ic - 1)/2
            q = merge(0, p + 1, mod(ic, 2) == 1)
            do m = 1, size(meshes)
                call lame_errors(p, meshes(m), q, eu(m), es(m), ndof, error)
                if (allocated(error)) return
                if (m > 1) rates(m - 1, :, ic) = log([eu(m - 1)/eu(m), es(m - 1)/es(m)])/log(2.0_dp)
                if (verbose) then
                    write (line, '(a,i0,a,a,a,3(i0,a),i0,a,es10.3,a,f5.2,a,es10.3,a,f5.2,a)') '| ', p, ' | ', &
                        trim(merge('none   ', 'NN     ', q == 0)), ' | ', meshes(m), ' x ', meshes(m), ' x ', &
                        meshes(m), ' | ', ndof, ' | ', eu(m), ' | ', &
                        merge(0.0_dp, rates(max(m - 1, 1), 1, ic), m == 1), ' | ', es(m), ' | ', &
                        merge(0.0_dp, rates(max(m - 1, 1), 2, ic), m == 1), ' |'
                    if (q > 0) line = line(:index(line, 'NN') + 1)//achar(48 + q)//line(index(line, 'NN') + 2:)
                    write (*, '(a)') trim(line)
                end if
            end do
        end do
    end subroutine lame_sphere_table

    !> The last rates are the optimal p + 1 (displacement) and p (stress), within 0.3,
    !> with and without the layer on the inner face.
    subroutine test_rates(error)
        type(error_t), allocatable, intent(out) :: error
        real(dp) :: rates(3, 2, 4)
        integer :: ic, p
        call lame_sphere_table(rates, error, .false.)
        if (allocated(error)) return
        do ic = 1, 4
            p = 2 + (ic - 1)/2
            call check(error, abs(rates(3, 1, ic) - (p + 1)) < 0.3_dp .and. abs(rates(3, 2, ic) - p) < 0.3_dp, &
                       'optimal rates, case '//achar(48 + ic))
            if (allocated(error)) return
        end do
    end subroutine test_rates

end module test_lame_sphere
