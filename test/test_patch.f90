!> The general NURBS patch in three parametric directions: a quarter of a thick
!> ring extruded along z (exact: radius 1 + u1, angle pi/2 u2, height u3) keeps its
!> map exactly under degree elevation and knot insertion in each direction, its
!> Jacobian matches finite differences, and its faces are the volume at the face.
module test_patch
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_testdrive, only: unittest_t, new_unittest, check
    use voiga_nurbs_patch, only: nurbs_patch_t, knots_t, new_patch, patch_eval, patch_elevate, &
                                 patch_insert, patch_boundary, point_index, patch_basis, &
                                 next_index, jacobian_determinant
    use voiga_nurbs_basis, only: distinct_knots
    use voiga_element_quadrature, only: gauss_legendre
    use voiga_nurbs_rational, only: rationalize
    use voiga_test_fixtures, only: lcg_t, ring_block
    implicit none
    private

    public :: collect_patch

    real(dp), parameter :: pi = acos(-1.0_dp)
    !> The refinements are exact: round-off of a few steps on O(1) coordinates.
    real(dp), parameter :: tol = 1.0e-12_dp

contains

    subroutine collect_patch(testsuite)
        type(unittest_t), allocatable, intent(out) :: testsuite(:)
        testsuite = [ &
                    new_unittest('volume_is_exact', test_exact), &
                    new_unittest('volume_refined_keeps_the_map', test_refined), &
                    new_unittest('volume_jacobian_against_differences', test_jacobian), &
                    new_unittest('face_is_the_volume_there', test_faces), &
                    new_unittest('rational_derivatives_in_three_directions', test_rational_3d), &
                    new_unittest('volume_by_quadrature_of_the_basis', test_volume_quadrature) &
                    ]
    end subroutine collect_patch

    !> Largest distance of the patch's map from the exact ring block at 200 random
    !> parameter points.
    real(dp) function distance_from_exact(patch) result(dist)
        type(nurbs_patch_t), intent(in) :: patch
        type(lcg_t) :: rng
        real(dp) :: u(3), x(3), r
        integer :: k
        dist = 0.0_dp
        do k = 1, 200
            u = [rng%uniform(), rng%uniform(), rng%uniform()]
            call patch_eval(patch, u, x)
            r = norm2(x(1:2))
            ! the angle is not linear in u2 (rational arc): check radius and height,
            ! and that the point lies in the quarter
            dist = max(dist, abs(r - (1.0_dp + u(1))), abs(x(3) - u(3)), max(-x(1), -x(2), 0.0_dp))
        end do
    end function distance_from_exact

    subroutine test_exact(error)
        type(error_t), allocatable, intent(out) :: error
        real(dp) :: x(3)
        call check(error, distance_from_exact(ring_block()) < tol, 'the ring block is not exact')
        if (allocated(error)) return
        call patch_eval(ring_block(), [0.5_dp, 0.5_dp, 0.25_dp], x)
        call check(error, norm2(x - [1.5_dp/sqrt(2.0_dp), 1.5_dp/sqrt(2.0_dp), 0.25_dp]) < tol, &
                   'the middle of the arc is not at 45 degrees')
    end subroutine test_exact

    !> Elevate and insert in every direction: the map is unchanged, the counts follow.
    subroutine test_refined(error)
        type(error_t), allocatable, intent(out) :: error
        type(nurbs_patch_t) :: patch
        patch = ring_block()
        call patch_elevate(patch, 1, 2)
        call patch_elevate(patch, 2, 1)
        call patch_elevate(patch, 3, 1)
        call patch_insert(patch, 1, [0.25_dp, 0.5_dp, 0.5_dp])
        call patch_insert(patch, 2, [0.3_dp, 0.7_dp])
        call patch_insert(patch, 3, [0.5_dp])
        call check(error, all(patch%degree == [3, 3, 2]), 'degrees after elevation')
        if (allocated(error)) return
        ! elevation adds t per distinct knot span end; insertion one point per knot
        call check(error, all(patch%n == [4 + 3, 4 + 2, 3 + 1]), 'control points per direction')
        if (allocated(error)) return
        call check(error, size(patch%w) == product(patch%n) .and. size(patch%cp, 2) == product(patch%n), &
                   'flat storage')
        if (allocated(error)) return
        call check(error, distance_from_exact(patch) < tol, 'refinement changed the map')
    end subroutine test_refined

    !> dx(:, d) against central differences along each direction, on a refined patch.
    subroutine test_jacobian(error)
        type(error_t), allocatable, intent(out) :: error
        type(nurbs_patch_t) :: patch
        real(dp), parameter :: h = 1.0e-6_dp
        real(dp) :: u(3), x(3), dx(3, 3), xp(3), xm(3), worst
        integer :: d
        patch = ring_block()
        call patch_elevate(patch, 3, 2)
        call patch_insert(patch, 2, [0.4_dp])
        u = [0.3_dp, 0.55_dp, 0.7_dp]
        call patch_eval(patch, u, x, dx)
        worst = 0.0_dp
        do d = 1, 3
            call patch_eval(patch, u + h*unit(d), xp)
            call patch_eval(patch, u - h*unit(d), xm)
            worst = max(worst, norm2((xp - xm)/(2*h) - dx(:, d)))
        end do
        call check(error, worst < 1.0e-8_dp, 'the Jacobian differs from finite differences')
    end subroutine test_jacobian

    pure function unit(d) result(e)
        integer, intent(in) :: d
        real(dp) :: e(3)
        e = 0.0_dp
        e(d) = 1.0_dp
    end function unit

    !> Each of the six faces of a refined block is the volume there; the outer face
    !> (u1 = 1) is the cylinder r = 2; a curve has no boundary patch.
    subroutine test_faces(error)
        type(error_t), allocatable, intent(out) :: error
        type(nurbs_patch_t) :: patch, face, edge
        real(dp) :: v(2), u(3), xf(3), xv(3), worst
        integer :: dir, side, k, keep(2)
        patch = ring_block()
        call patch_elevate(patch, 1, 1)
        call patch_insert(patch, 3, [0.6_dp])
        worst = 0.0_dp
        do dir = 1, 3
            keep = pack([1, 2, 3], [1, 2, 3] /= dir)
            do side = 0, 1
                face = patch_boundary(patch, dir, side)
                call check(error, face%pdim == 2 .and. face%nsd == 3 .and. all(face%n == patch%n(keep)), &
                           'face shape')
                if (allocated(error)) return
                do k = 1, 5
                    v = [0.1_dp*k, 1.0_dp - 0.13_dp*k]
                    u(keep) = v
                    u(dir) = real(side, dp)
                    call patch_eval(face, v, xf)
                    call patch_eval(patch, u, xv)
                    worst = max(worst, norm2(xf - xv))
                end do
            end do
        end do
        call check(error, worst < tol, 'a face is not the volume at the face')
        if (allocated(error)) return
        face = patch_boundary(patch, 1, 1)
        call patch_eval(face, [0.37_dp, 0.81_dp], xf)
        call check(error, abs(norm2(xf(1:2)) - 2.0_dp) < tol, 'the outer face is not the cylinder r = 2')
        if (allocated(error)) return
        edge = patch_boundary(patch_boundary(face, 2, 0), 1, 0)
        call check(error, edge%pdim == 0 .and. point_index(face, [1, 1]) == 1, 'a curve has no boundary patch')
    end subroutine test_faces

    !> The trilinear Bernstein products (8 functions) at `u` with their first and
    !> second derivatives, the Hessian stored diagonal first: 11, 22, 33, 12, 13, 23.
    pure subroutine trilinear(u, b, db, d2b)
        real(dp), intent(in) :: u(3)
        real(dp), intent(out) :: b(8), db(3, 8), d2b(6, 8)
        real(dp) :: v(2, 3), dv(2, 3)
        integer :: i, j, k, a
        integer, parameter :: first(3) = [1, 1, 2], second(3) = [2, 3, 3]
        integer :: idx(3), d, m
        v(1, :) = 1.0_dp - u
        v(2, :) = u
        dv(1, :) = -1.0_dp
        dv(2, :) = 1.0_dp
        a = 0
        do k = 1, 2
            do j = 1, 2
                do i = 1, 2
                    a = a + 1
                    idx = [i, j, k]
                    b(a) = v(i, 1)*v(j, 2)*v(k, 3)
                    do d = 1, 3
                        db(d, a) = term(v, dv, idx, [1, 2, 3] == d)
                    end do
                    ! linear in each direction: the diagonal vanishes
                    d2b(1:3, a) = 0.0_dp
                    do m = 1, 3
                        d2b(3 + m, a) = term(v, dv, idx, [1, 2, 3] == first(m) .or. [1, 2, 3] == second(m))
                    end do
                end do
            end do
        end do
    end subroutine trilinear

    !> The product over the directions e of v(idx(e), e), its derivative where `derive(e)`.
    pure real(dp) function term(v, dv, idx, derive)
        real(dp), intent(in) :: v(2, 3), dv(2, 3)
        integer, intent(in) :: idx(3)
        logical, intent(in) :: derive(3)
        integer :: e
        term = 1.0_dp
        do e = 1, 3
            term = term*merge(dv(idx(e), e), v(idx(e), e), derive(e))
        end do
    end function term

    !> `rationalize` in three directions: first and second derivatives of the NURBS
    !> functions against central differences of the values and of the first
    !> derivatives, for random weights.
    subroutine test_rational_3d(error)
        type(error_t), allocatable, intent(out) :: error
        real(dp), parameter :: h = 1.0e-6_dp
        integer, parameter :: first(3) = [1, 1, 2], second(3) = [2, 3, 3]
        type(lcg_t) :: rng
        real(dp) :: w(8), u(3), b(8), db(3, 8), d2b(6, 8), r(8), dr(3, 8), d2r(6, 8)
        real(dp) :: rp(8), rm(8), drp(3, 8), drm(3, 8), d2p(6, 8), worst1, worst2
        integer :: a, d, m
        do a = 1, 8
            w(a) = 0.4_dp + rng%uniform()
        end do
        u = [0.3_dp, 0.6_dp, 0.45_dp]
        call trilinear(u, b, db, d2b)
        call rationalize(w, b, db, d2b, r, dr, d2r)
        worst1 = 0.0_dp
        worst2 = 0.0_dp
        do d = 1, 3
            call trilinear(u + h*unit(d), b, db, d2b)
            call rationalize(w, b, db, d2b, rp, drp, d2p)
            call trilinear(u - h*unit(d), b, db, d2b)
            call rationalize(w, b, db, d2b, rm, drm, d2p)
            worst1 = max(worst1, maxval(abs((rp - rm)/(2*h) - dr(d, :))))
            ! d/du_d of dr(d, :) is the diagonal entry d; of dr(e, :), e > d, the pair (d, e)
            worst2 = max(worst2, maxval(abs((drp(d, :) - drm(d, :))/(2*h) - d2r(d, :))))
            do m = 1, 3
                if (first(m) == d) worst2 = max(worst2, maxval(abs((drp(second(m), :) - drm(second(m), :))/(2*h) &
                                                                   - d2r(3 + m, :))))
            end do
        end do
        call check(error, abs(sum(r) - 1.0_dp) < tol .and. maxval(abs(sum(dr, 2))) < tol .and. &
                   maxval(abs(sum(d2r, 2))) < tol, 'the NURBS functions are not a partition of unity')
        if (allocated(error)) return
        call check(error, worst1 < 1.0e-8_dp, 'first derivatives differ from finite differences')
        if (allocated(error)) return
        call check(error, worst2 < 1.0e-7_dp, 'second derivatives differ from finite differences')
    end subroutine test_rational_3d

    !> The volume of a refined ring block by Gauss quadrature of det J over its knot
    !> spans, with J from `patch_basis` (the functions a brick element uses): the exact
    !> 3 pi / 4 (a quarter of the ring r 1..2, height 1), to round-off; the functions
    !> are a partition of unity with derivatives summing to zero.
    subroutine test_volume_quadrature(error)
        type(error_t), allocatable, intent(out) :: error
        ! Gauss points per span and direction: det J of the rational arc is not a
        ! polynomial (4 points: 5.7e-10 off), 8 points reach round-off
        integer, parameter :: ng = 8
        type(nurbs_patch_t) :: patch
        type(knots_t) :: breaks(3)
        integer, allocatable :: ids(:)
        real(dp), allocatable :: r(:), dr(:, :)
        real(dp) :: gx(ng), gw(ng), u(3), mid(3), half(3), jac(3, 3), volume, unity
        integer :: span(3), q(3), d, s, m
        patch = ring_block()
        call patch_elevate(patch, 1, 1)
        call patch_insert(patch, 1, [0.5_dp])
        call patch_insert(patch, 2, [0.25_dp, 0.6_dp])
        call patch_insert(patch, 3, [0.3_dp])
        call gauss_legendre(ng, gx, gw)
        do d = 1, 3
            breaks(d)%u = distinct_knots(patch%knots(d)%u)
        end do
        volume = 0.0_dp
        unity = 0.0_dp
        span = 1
        do s = 1, product([(size(breaks(d)%u) - 1, d=1, 3)])
            do d = 1, 3
                mid(d) = 0.5_dp*(breaks(d)%u(span(d)) + breaks(d)%u(span(d) + 1))
                half(d) = 0.5_dp*(breaks(d)%u(span(d) + 1) - breaks(d)%u(span(d)))
            end do
            q = 1
            do m = 1, ng**3
                u = mid + half*gx(q)
                call patch_basis(patch, u, ids, r, dr)
                jac = matmul(patch%cp(:, ids), transpose(dr))
                volume = volume + jacobian_determinant(jac)*product(gw(q))*product(half)
                unity = max(unity, abs(sum(r) - 1.0_dp), maxval(abs(sum(dr, 2))))
                call next_index(q, [ng, ng, ng])
            end do
            call next_index(span, [(size(breaks(d)%u) - 1, d=1, 3)])
        end do
        call check(error, unity < tol, 'the functions are not a partition of unity')
        if (allocated(error)) return
        call check(error, abs(volume - 0.75_dp*pi) < 1.0e-12_dp, 'the volume is not 3 pi / 4')
    end subroutine test_volume_quadrature

end module test_patch
