!> The closest-point projection onto a NURBS surface (`voiga_nurbs_projection`) on exact
!> surfaces taken from volumes' faces: the outer sphere of the shell octant (its pole
!> edge collapsed), the cylinder face of the ring block, a flat distorted plane, and a
!> curved distorted surface against brute force. `fpm test -- --projection-timing`
!> prints the queries per second on a 32 x 32-span surface.
module test_projection
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_testdrive, only: unittest_t, new_unittest, check
    use voiga_nurbs_patch, only: nurbs_patch_t, knots_t, new_patch, patch_boundary, patch_insert, patch_elevate
    use voiga_nurbs_basis, only: find_span
    use voiga_nurbs_projection, only: surface_search_t, surface_projection_t, new_surface_search, &
                                      project_on_surface, surface_derivatives
    use voiga_test_fixtures, only: lcg_t, ring_block
    use test_lame_sphere, only: shell_octant
    implicit none
    private

    public :: collect_projection, projection_timing

    real(dp), parameter :: pi = acos(-1.0_dp)
    !> Closest points of exact surfaces: Newton ends at round-off of O(1) coordinates
    !> (measured 1e-15 .. 4e-15), the brief asks 1e-12.
    real(dp), parameter :: tol = 1.0e-12_dp

contains

    subroutine collect_projection(testsuite)
        type(unittest_t), allocatable, intent(out) :: testsuite(:)
        testsuite = [ &
                    new_unittest('sphere_octant_against_exact', test_sphere), &
                    new_unittest('sphere_pole_collapsed_edge', test_pole), &
                    new_unittest('cylinder_sector_against_exact', test_cylinder), &
                    new_unittest('flat_distorted_plane', test_plane), &
                    new_unittest('curved_surface_against_brute_force', test_brute_force), &
                    new_unittest('warm_start_equals_cold', test_warm_start), &
                    new_unittest('derivatives_against_differences', test_derivatives) &
                    ]
    end subroutine collect_projection

    !> The outer sphere (r = 2) of the shell octant, its zeta = 1 face; `cells` > 1
    !> inserts knots (cells - 1 per direction) so that the search visits several cells.
    function sphere_face(cells) result(face)
        integer, intent(in) :: cells
        type(nurbs_patch_t) :: face, vol
        integer :: k
        vol = shell_octant()
        if (cells > 1) then
            call patch_insert(vol, 1, [(real(k, dp)/cells, k=1, cells - 1)])
            call patch_insert(vol, 2, [(real(k, dp)/cells, k=1, cells - 1)])
        end if
        face = patch_boundary(vol, 3, 1)
    end function sphere_face

    !> A random unit direction with every component >= `margin` (inside the octant) or,
    !> for `inside` false, with at least one component <= -margin.
    function direction(rng, inside, margin) result(e)
        type(lcg_t), intent(inout) :: rng
        logical, intent(in) :: inside
        real(dp), intent(in) :: margin
        real(dp) :: e(3)
        do
            e = [rng%uniform(), rng%uniform(), rng%uniform()]*2.0_dp - 1.0_dp
            if (norm2(e) < 0.1_dp .or. norm2(e) > 1.0_dp) cycle
            e = e/norm2(e)
            if (inside) e = abs(e)
            if (inside .and. minval(e) >= margin) exit
            if (.not. inside .and. minval(e) <= -margin) exit
        end do
    end function direction

    !> |(x - S) . a_alpha| / |a_alpha|, the larger of the two (a vanishing tangent: 0).
    pure real(dp) function orthogonality(x, res) result(o)
        real(dp), intent(in) :: x(3)
        type(surface_projection_t), intent(in) :: res
        o = 0.0_dp
        if (norm2(res%a1) > 0.0_dp) o = abs(dot_product(x - res%x, res%a1))/norm2(res%a1)
        if (norm2(res%a2) > 0.0_dp) o = max(o, abs(dot_product(x - res%x, res%a2))/norm2(res%a2))
    end function orthogonality

    !> Points inside the octant's cone at radii 0.6 .. 6 and 100 project to 2 x/|x| with
    !> the outward normal x/|x| (a1 x a2 on a right-handed volume's zeta = 1 face);
    !> points with a negative coordinate are beyond the patch: not found.
    subroutine test_sphere(error)
        type(error_t), allocatable, intent(out) :: error
        type(surface_search_t) :: search
        type(surface_projection_t) :: res
        type(lcg_t) :: rng
        real(dp) :: e(3), x(3), r, worst, worst_n, worst_o
        integer :: k, cells, nbad
        logical :: found, converged
        worst = 0.0_dp
        worst_n = 0.0_dp
        worst_o = 0.0_dp
        nbad = 0
        do cells = 1, 4, 3
            call new_surface_search(search, sphere_face(cells))
            do k = 1, 200
                e = direction(rng, .true., 0.02_dp)
                r = merge(100.0_dp, 0.6_dp + 5.4_dp*rng%uniform(), mod(k, 10) == 0)
                x = r*e
                call project_on_surface(search, x, res, found, converged)
                if (.not. (found .and. converged)) nbad = nbad + 1
                worst = max(worst, norm2(res%x - 2.0_dp*e)/max(1.0_dp, r/10), abs(res%distance - abs(r - 2.0_dp)))
                worst_n = max(worst_n, norm2(res%n - e))
                worst_o = max(worst_o, orthogonality(x, res)/max(1.0_dp, r/10))
            end do
            do k = 1, 100
                x = (0.6_dp + 3.0_dp*rng%uniform())*direction(rng, .false., 0.02_dp)
                call project_on_surface(search, x, res, found, converged)
                if (found) nbad = nbad + 1
                ! the patch is on the sphere: no closer than the sphere's distance
                if (res%distance < abs(norm2(x) - 2.0_dp) - tol) nbad = nbad + 1
            end do
        end do
        print '(a, 3es10.2)', '    sphere: point, normal, orthogonality errors', worst, worst_n, worst_o
        call check(error, nbad == 0, 'a point inside the cone not found or one outside found')
        if (allocated(error)) return
        ! far points (r = 100): the relative error of r x/|x| is what double precision gives
        call check(error, worst < tol .and. worst_n < tol .and. worst_o < tol, 'the sphere is not projected to 1e-12')
    end subroutine test_sphere

    !> On and near the collapsed pole (a1 = 0 on v = 1): points on the z axis project to
    !> the pole (found, normal +z); a point over the pole but outside the octant's cone
    !> is beyond the patch; points just inside the cone near the axis are exact.
    subroutine test_pole(error)
        type(error_t), allocatable, intent(out) :: error
        type(surface_search_t) :: search
        type(surface_projection_t) :: res
        real(dp), parameter :: heights(3) = [0.5_dp, 3.0_dp, 50.0_dp]
        real(dp) :: x(3), e(3), worst
        integer :: cells, k
        logical :: found, converged, ok
        ok = .true.
        worst = 0.0_dp
        do cells = 1, 3, 2
            call new_surface_search(search, sphere_face(cells))
            do k = 1, 3
                x = [0.0_dp, 0.0_dp, heights(k)]
                call project_on_surface(search, x, res, found, converged)
                ok = ok .and. found .and. converged .and. abs(res%u(2) - 1.0_dp) <= tol
                worst = max(worst, norm2(res%x - [0.0_dp, 0.0_dp, 2.0_dp]), norm2(res%n - [0.0_dp, 0.0_dp, 1.0_dp]))
            end do
            call project_on_surface(search, [-0.1_dp, -0.05_dp, 3.0_dp], res, found, converged)
            ok = ok .and. .not. found
            do k = 1, 4
                e = [1.0e-3_dp*k, 2.0e-4_dp*k**2, 1.0_dp]
                e = e/norm2(e)
                x = 3.0_dp*e
                call project_on_surface(search, x, res, found, converged)
                ok = ok .and. found .and. converged
                worst = max(worst, norm2(res%x - 2.0_dp*e), norm2(res%n - e))
            end do
        end do
        print '(a, es10.2)', '    pole: worst point or normal error', worst
        call check(error, ok, 'the pole is not the projection of the axis, or a point beyond it is found')
        if (allocated(error)) return
        call check(error, worst < tol, 'the pole region is not projected to 1e-12')
    end subroutine test_pole

    !> The ring block's outer face r = 2 (angle, height), refined to 4 x 2 cells of
    !> degree 2 x 2: points at radii 0.4 .. 5 and 60 inside the sector and height range
    !> project to (2 cos t, 2 sin t, z) with the normal (cos t, sin t, 0); points beyond
    !> the angle or the height are not found.
    subroutine test_cylinder(error)
        type(error_t), allocatable, intent(out) :: error
        type(surface_search_t) :: search
        type(surface_projection_t) :: res
        type(nurbs_patch_t) :: vol
        type(lcg_t) :: rng
        real(dp) :: x(3), t, z, rho, worst, worst_o
        integer :: k, nbad
        logical :: found, converged
        vol = ring_block()
        call patch_elevate(vol, 3, 1)
        call patch_insert(vol, 2, [0.25_dp, 0.5_dp, 0.75_dp])
        call patch_insert(vol, 3, [0.5_dp])
        call new_surface_search(search, patch_boundary(vol, 1, 1))
        worst = 0.0_dp
        worst_o = 0.0_dp
        nbad = 0
        do k = 1, 300
            t = 0.5_dp*pi*(0.01_dp + 0.98_dp*rng%uniform())
            z = 0.01_dp + 0.98_dp*rng%uniform()
            rho = merge(60.0_dp, 0.4_dp + 4.6_dp*rng%uniform(), mod(k, 10) == 0)
            x = [rho*cos(t), rho*sin(t), z]
            call project_on_surface(search, x, res, found, converged)
            if (.not. (found .and. converged)) nbad = nbad + 1
            worst = max(worst, norm2(res%x - [2*cos(t), 2*sin(t), z])/max(1.0_dp, rho/10), &
                        norm2(res%n - [cos(t), sin(t), 0.0_dp]), abs(res%distance - abs(rho - 2)))
            worst_o = max(worst_o, orthogonality(x, res)/max(1.0_dp, rho/10))
        end do
        do k = 1, 100
            t = 0.5_dp*pi*rng%uniform()
            z = 0.5_dp
            ! even k: beyond the angle's ends by 0.1 .. 0.6; odd k: beyond the heights
            if (mod(k, 4) == 0) t = -0.1_dp - 0.5_dp*rng%uniform()
            if (mod(k, 4) == 2) t = 0.5_dp*pi + 0.1_dp + 0.5_dp*rng%uniform()
            if (mod(k, 4) == 1) z = -0.05_dp - rng%uniform()
            if (mod(k, 4) == 3) z = 1.05_dp + rng%uniform()
            rho = 0.5_dp + 3.0_dp*rng%uniform()
            call project_on_surface(search, [rho*cos(t), rho*sin(t), z], res, found, converged)
            if (found) nbad = nbad + 1
        end do
        ! a corner of four cells (angle pi/4 is the knot 0.5; z = 0.5 a knot), a corner
        ! of the patch, and beyond that corner (found false, the corner still closest)
        do k = 1, 3
            rho = merge(0.7_dp, 3.0_dp, k == 1)
            x = [rho*cos(0.25_dp*pi), rho*sin(0.25_dp*pi), 0.5_dp]
            if (k > 1) x = [rho, 0.0_dp, 0.0_dp]
            if (k == 3) x = x - [0.0_dp, 0.1_dp, 0.1_dp]
            call project_on_surface(search, x, res, found, converged)
            if ((found .neqv. k < 3) .or. .not. converged) nbad = nbad + 1
            if (k == 1) worst = max(worst, norm2(res%x - [sqrt(2.0_dp), sqrt(2.0_dp), 0.5_dp]))
            if (k > 1) worst = max(worst, norm2(res%x - [2.0_dp, 0.0_dp, 0.0_dp]))
        end do
        print '(a, 2es10.2)', '    cylinder: point/normal, orthogonality errors', worst, worst_o
        call check(error, nbad == 0, 'a point over the sector not found or one beyond it found')
        if (allocated(error)) return
        call check(error, worst < tol .and. worst_o < tol, 'the cylinder is not projected to 1e-12')
    end subroutine test_cylinder

    !> A distorted control net (`nx` x `ny` points over [0, 3] x [0, 2], interior and
    !> edge points moved by up to 15 % of the spacing, weights 0.6 .. 1.5), degree 2 x 3,
    !> with the heights `zamp` times a random number in [-1, 1] (0: a plane).
    function distorted(nx, ny, zamp, seed) result(patch)
        integer, intent(in) :: nx, ny
        real(dp), intent(in) :: zamp
        integer, intent(in) :: seed
        type(nurbs_patch_t) :: patch
        type(lcg_t) :: rng
        type(knots_t) :: knots(2)
        real(dp) :: cp(3, nx*ny), w(nx*ny), h(2)
        integer :: i, j, a
        rng%state = seed
        h = [3.0_dp/(nx - 1), 2.0_dp/(ny - 1)]
        do j = 1, ny
            do i = 1, nx
                a = i + (j - 1)*nx
                cp(1:2, a) = [i - 1, j - 1]*h + 0.3_dp*h*([rng%uniform(), rng%uniform()] - 0.5_dp)
                cp(3, a) = zamp*(2.0_dp*rng%uniform() - 1.0_dp)
                w(a) = 0.6_dp + 0.9_dp*rng%uniform()
            end do
        end do
        knots(1)%u = open_knots(nx, 2)
        knots(2)%u = open_knots(ny, 3)
        patch = new_patch([2, 3], knots, [nx, ny], cp, w)
    end function distorted

    !> Open uniform knots on [0, 1] for n functions of degree p.
    pure function open_knots(n, p) result(u)
        integer, intent(in) :: n, p
        real(dp) :: u(n + p + 1)
        integer :: k
        u(1:p + 1) = 0.0_dp
        u(n + 1:n + p + 1) = 1.0_dp
        do k = 1, n - p - 1
            u(p + 1 + k) = real(k, dp)/(n - p)
        end do
    end function open_knots

    !> The flat distorted plane z = 0: points over its middle at heights -2 .. 2 (and
    !> 80) project to (x, y, 0) with the normal +z (the net is counter-clockwise seen
    !> from +z); points well beyond its sides are not found.
    subroutine test_plane(error)
        type(error_t), allocatable, intent(out) :: error
        type(surface_search_t) :: search
        type(surface_projection_t) :: res
        type(lcg_t) :: rng
        real(dp) :: x(3), worst, worst_o
        integer :: k, nbad
        logical :: found, converged
        call new_surface_search(search, distorted(7, 6, 0.0_dp, 777))
        worst = 0.0_dp
        worst_o = 0.0_dp
        nbad = 0
        do k = 1, 300
            x = [0.5_dp + 2.0_dp*rng%uniform(), 0.4_dp + 1.2_dp*rng%uniform(), 4.0_dp*rng%uniform() - 2.0_dp]
            if (mod(k, 10) == 0) x(3) = 80.0_dp
            call project_on_surface(search, x, res, found, converged)
            if (.not. (found .and. converged)) nbad = nbad + 1
            worst = max(worst, norm2(res%x - [x(1:2), 0.0_dp]), abs(res%distance - abs(x(3))), &
                        norm2(res%n - [0.0_dp, 0.0_dp, 1.0_dp]))
            worst_o = max(worst_o, orthogonality(x, res))
        end do
        do k = 1, 50
            x = [merge(-0.6_dp, 3.6_dp, mod(k, 2) == 0), 2.0_dp*rng%uniform(), rng%uniform() - 0.5_dp]
            call project_on_surface(search, x, res, found, converged)
            if (found) nbad = nbad + 1
        end do
        print '(a, 2es10.2)', '    plane: point/normal, orthogonality errors', worst, worst_o
        call check(error, nbad == 0, 'a point over the plane not found or one beyond it found')
        if (allocated(error)) return
        call check(error, worst < tol .and. worst_o < tol, 'the plane is not projected to 1e-12')
    end subroutine test_plane

    !> The closest point of `patch` to `x` by brute force: a 161 x 161 grid, then
    !> 11 x 11 grids on windows halved 48 times around the best sample (no Newton).
    subroutine brute_force(patch, x, u, d)
        type(nurbs_patch_t), intent(in) :: patch
        real(dp), intent(in) :: x(3)
        real(dp), intent(out) :: u(2), d
        real(dp) :: h, c(2), t(2), dt
        integer :: i, j, round
        d = huge(1.0_dp)
        do j = 0, 160
            do i = 0, 160
                call try([i, j]/160.0_dp)
            end do
        end do
        h = 1.0_dp/160
        do round = 1, 48
            c = u
            do j = -5, 5
                do i = -5, 5
                    call try(min(max(c + [i, j]*h/5, 0.0_dp), 1.0_dp))
                end do
            end do
            h = 0.5_dp*h
        end do
    contains
        subroutine try(s)
            real(dp), intent(in) :: s(2)
            real(dp) :: y(3), d1(3, 2), d2(3, 3)
            call surface_derivatives(patch, s, [find_span(patch%knots(1)%u, patch%degree(1), s(1)), &
                                                find_span(patch%knots(2)%u, patch%degree(2), s(2))], y, d1, d2)
            dt = norm2(x - y)
            if (dt < d) then
                d = dt
                u = s
                t = s
            end if
        end subroutine try
    end subroutine brute_force

    !> A curved distorted surface (heights up to 0.4 over a 3 x 2 net of 8 x 7 points):
    !> the distance and point of brute force, for points near, far, inside and beyond;
    !> found only where the point is no boundary point with the distance decreasing out.
    subroutine test_brute_force(error)
        type(error_t), allocatable, intent(out) :: error
        type(surface_search_t) :: search
        type(surface_projection_t) :: res
        type(nurbs_patch_t) :: patch
        type(lcg_t) :: rng
        real(dp) :: x(3), u(2), d, worst_d, worst_x, y(3), d1(3, 2), d2(3, 3)
        integer :: k, nbad
        logical :: found, converged
        patch = distorted(8, 7, 0.4_dp, 4242)
        call new_surface_search(search, patch)
        worst_d = 0.0_dp
        worst_x = 0.0_dp
        nbad = 0
        do k = 1, 60
            x = [4.0_dp*rng%uniform() - 0.5_dp, 3.0_dp*rng%uniform() - 0.5_dp, 2.0_dp*rng%uniform() - 1.0_dp]
            if (mod(k, 6) == 0) x = 30.0_dp*x
            call project_on_surface(search, x, res, found, converged)
            call brute_force(patch, x, u, d)
            call surface_derivatives(patch, u, [find_span(patch%knots(1)%u, 2, u(1)), &
                                                find_span(patch%knots(2)%u, 3, u(2))], y, d1, d2)
            if (.not. converged) nbad = nbad + 1
            ! the projection is never farther than brute force (it is the minimum)
            worst_d = max(worst_d, (res%distance - d)/max(1.0_dp, d))
            worst_x = max(worst_x, norm2(res%x - y)/max(1.0_dp, d))
            ! an interior brute-force minimum is orthogonal: found
            if (all(u > 1.0e-6_dp .and. u < 1.0_dp - 1.0e-6_dp) .neqv. found) nbad = nbad + 1
        end do
        print '(a, 2es10.2)', '    brute force: distance excess, point difference', worst_d, worst_x
        call check(error, nbad == 0, 'not converged, or found where brute force ends on the boundary')
        if (allocated(error)) return
        ! the distance is flat at the minimum: brute force's point is good to sqrt of
        ! its distance's round-off (1e-8), the distance to round-off
        call check(error, worst_d < tol .and. worst_x < 1.0e-6_dp, 'the projection differs from brute force')
    end subroutine test_brute_force

    !> Warm starts from the cold answer moved by 1e-3 .. 5e-2 in parameters give the same
    !> point to 1e-14 (not bitwise: Newton from another start ends at another point of
    !> the round-off ball), and the cold answer itself as start gives it bitwise.
    subroutine test_warm_start(error)
        type(error_t), allocatable, intent(out) :: error
        type(surface_search_t) :: search
        type(surface_projection_t) :: cold, warm
        type(lcg_t) :: rng
        real(dp) :: x(3), worst, du(2)
        integer :: k, s, nbad
        logical :: found, converged, fw, cw
        worst = 0.0_dp
        nbad = 0
        do s = 1, 3
            select case (s)
            case (1)
                call new_surface_search(search, sphere_face(3))
            case (2)
                call new_surface_search(search, distorted(8, 7, 0.4_dp, 4242))
            case (3)
                call new_surface_search(search, distorted(7, 6, 0.0_dp, 777))
            end select
            do k = 1, 100
                if (s == 1) then
                    x = (1.5_dp + rng%uniform())*direction(rng, .true., 0.02_dp)
                else
                    x = [0.3_dp + 2.4_dp*rng%uniform(), 0.3_dp + 1.4_dp*rng%uniform(), rng%uniform() - 0.5_dp]
                end if
                call project_on_surface(search, x, cold, found, converged)
                du = (1.0e-3_dp + 0.05_dp*rng%uniform())*[1.0_dp, -1.0_dp]
                call project_on_surface(search, x, warm, fw, cw, min(max(cold%u + du, 0.0_dp), 1.0_dp))
                worst = max(worst, norm2(warm%x - cold%x), abs(warm%distance - cold%distance))
                if ((fw .neqv. found) .or. (cw .neqv. converged)) nbad = nbad + 1
                call project_on_surface(search, x, warm, fw, cw, cold%u)
                if (any(warm%x /= cold%x) .or. any(warm%u /= cold%u)) nbad = nbad + 1
            end do
        end do
        print '(a, es10.2)', '    warm start: worst point difference', worst
        call check(error, nbad == 0, 'a warm start changes found/converged, or its own answer is not bitwise')
        if (allocated(error)) return
        call check(error, worst < 1.0e-14_dp, 'a warm start differs from the cold answer by more than 1e-14')
    end subroutine test_warm_start

    !> The tangents and second derivatives that a projection returns (the 3D contact
    !> tangent's curvature terms) against central differences of the point and the
    !> tangents on the curved distorted surface, at interior parameters of random cells.
    subroutine test_derivatives(error)
        type(error_t), allocatable, intent(out) :: error
        type(nurbs_patch_t) :: patch
        type(lcg_t) :: rng
        real(dp), parameter :: h = 1.0e-6_dp
        real(dp) :: u(2), x(3), d1(3, 2), d2(3, 3), xp(3), xm(3), dp1(3, 2), dm1(3, 2), e(3, 3), worst
        integer :: k, a, span(2)
        patch = distorted(8, 7, 0.4_dp, 4242)
        worst = 0.0_dp
        do k = 1, 50
            u = 0.02_dp + 0.96_dp*[rng%uniform(), rng%uniform()]
            span = [find_span(patch%knots(1)%u, 2, u(1)), find_span(patch%knots(2)%u, 3, u(2))]
            call surface_derivatives(patch, u, span, x, d1, d2)
            do a = 1, 2
                call surface_derivatives(patch, u + h*merge(1.0_dp, 0.0_dp, [1, 2] == a), span, xp, dp1, e)
                call surface_derivatives(patch, u - h*merge(1.0_dp, 0.0_dp, [1, 2] == a), span, xm, dm1, e)
                worst = max(worst, norm2((xp - xm)/(2*h) - d1(:, a)), norm2((dp1(:, a) - dm1(:, a))/(2*h) - d2(:, a)))
                ! the mixed derivative both ways
                worst = max(worst, norm2((dp1(:, 3 - a) - dm1(:, 3 - a))/(2*h) - d2(:, 3)))
            end do
        end do
        print '(a, es10.2)', '    derivatives: worst difference from central differences', worst
        ! central differences with h = 1e-6 on O(1) derivatives: truncation ~1e-11,
        ! round-off ~1e-10
        call check(error, worst < 1.0e-7_dp, 'a derivative differs from central differences')
    end subroutine test_derivatives

    !> Queries per second on two 32 x 32-span surfaces, printed, not asserted: the
    !> outer sphere of the shell octant (degree 2, a Hertz ball's contact face) with
    !> points within 0.05 of it, and a wavy degree 2 x 3 surface (heights of +-0.1 on
    !> a control spacing of 0.09) with points within 0.1; cold, and warm-started from
    !> the answer moved by 1e-3 (a Newton iteration's change).
    subroutine projection_timing()
        type(surface_search_t) :: search
        type(nurbs_patch_t) :: vol
        type(lcg_t) :: rng
        integer, parameter :: nq = 100000
        real(dp), allocatable :: x(:, :)
        real(dp) :: tb0, tb1
        integer :: k
        call cpu_time(tb0)
        vol = shell_octant()
        call patch_insert(vol, 1, [(real(k, dp)/32, k=1, 31)])
        call patch_insert(vol, 2, [(real(k, dp)/32, k=1, 31)])
        call new_surface_search(search, patch_boundary(vol, 3, 1))
        call cpu_time(tb1)
        print '(a, f8.4, a)', 'sphere, 32 x 32 spans: search built in ', tb1 - tb0, ' s'
        allocate (x(3, nq))
        do k = 1, nq
            x(:, k) = (1.95_dp + 0.1_dp*rng%uniform())*direction(rng, .true., 0.0_dp)
        end do
        call time_queries(search, x)
        call cpu_time(tb0)
        call new_surface_search(search, distorted(34, 35, 0.1_dp, 99))
        call cpu_time(tb1)
        print '(a, f8.4, a)', 'wavy surface, 32 x 32 spans: search built in ', tb1 - tb0, ' s'
        do k = 1, nq
            x(:, k) = [3.0_dp*rng%uniform(), 2.0_dp*rng%uniform(), 0.2_dp*rng%uniform() - 0.1_dp]
        end do
        call time_queries(search, x)
    end subroutine projection_timing

    !> Cold and warm queries per second of the points `x` [3, n] on `search`.
    subroutine time_queries(search, x)
        type(surface_search_t), intent(in) :: search
        real(dp), intent(in) :: x(:, :)
        type(surface_projection_t) :: res
        real(dp) :: us(2, size(x, 2)), t0, t1, sink
        integer :: k
        logical :: found, converged
        sink = 0.0_dp
        call cpu_time(t0)
        do k = 1, size(x, 2)
            call project_on_surface(search, x(:, k), res, found, converged)
            us(:, k) = res%u
            sink = sink + res%distance
        end do
        call cpu_time(t1)
        print '(a, es10.3, a)', '  cold: ', size(x, 2)/(t1 - t0), ' queries/s'
        call cpu_time(t0)
        do k = 1, size(x, 2)
            call project_on_surface(search, x(:, k), res, found, converged, &
                                    min(max(us(:, k) + 1.0e-3_dp, 0.0_dp), 1.0_dp))
            sink = sink + res%distance
        end do
        call cpu_time(t1)
        print '(a, es10.3, a, es12.5)', '  warm: ', size(x, 2)/(t1 - t0), ' queries/s; checksum ', sink
    end subroutine time_queries

end module test_projection
