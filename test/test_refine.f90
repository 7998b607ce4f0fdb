!> Knot insertion and degree elevation keep the curve exactly; circles stay circles.
module test_refine
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_testdrive, only: unittest_t, new_unittest, check
    use voiga_nurbs_basis, only: distinct_knots, multiplicity
    use voiga_nurbs_curve, only: nurbs_curve_t, curve_eval, curve_elevate, curve_insert
    use voiga_nurbs_surface, only: nurbs_surface_t, surface_edge_curve, surface_eval, surface_reorient
    use voiga_test_fixtures, only: lcg_t, annulus_sector
    implicit none
    private

    public :: collect_refine

    !> Invariance tolerance: the refinements are exact; 1e-12 leaves room for
    !> round-off of up to ~20 elevation/insertion steps on O(1) coordinates.
    real(dp), parameter :: tol = 1.0e-12_dp

contains

    subroutine collect_refine(testsuite)
        type(unittest_t), allocatable, intent(out) :: testsuite(:)
        testsuite = [ &
                    new_unittest('insert_keeps_curve', test_insert), &
                    new_unittest('elevate_keeps_curve', test_elevate), &
                    new_unittest('elevate_multiplicities', test_elevate_mult), &
                    new_unittest('circle_stays_circle', test_circle), &
                    new_unittest('turned_patch_keeps_the_map', test_turn) &
                    ]
    end subroutine collect_refine

    function random_curve(rng, p, knots) result(c)
        type(lcg_t), intent(inout) :: rng
        integer, intent(in) :: p
        real(dp), intent(in) :: knots(:)
        type(nurbs_curve_t) :: c
        integer :: k, n
        c%degree = p
        c%knots = knots
        n = size(knots) - p - 1
        allocate (c%w(n), c%cp(2, n))
        do k = 1, n
            c%w(k) = 0.3_dp + rng%uniform()
            c%cp(:, k) = [rng%uniform(), rng%uniform()]
        end do
    end function random_curve

    !> Max distance between two curves (and their first derivatives) at 1000 points.
    subroutine compare_curves(a, b, dist, ddist)
        type(nurbs_curve_t), intent(in) :: a, b
        real(dp), intent(out) :: dist, ddist
        real(dp) :: xa(2), xb(2), da(2), db(2), u
        integer :: k
        dist = 0.0_dp
        ddist = 0.0_dp
        do k = 0, 999
            u = real(k, dp)/999.0_dp
            call curve_eval(a, u, xa, da)
            call curve_eval(b, u, xb, db)
            dist = max(dist, norm2(xa - xb))
            ddist = max(ddist, norm2(da - db)/max(1.0_dp, norm2(da)))
        end do
    end subroutine compare_curves

    subroutine test_insert(error)
        type(error_t), allocatable, intent(out) :: error
        type(lcg_t) :: rng
        type(nurbs_curve_t) :: c, r
        real(dp) :: dist, ddist
        integer :: p
        do p = 1, 5
            c = random_curve(rng, p, [spread(0.0_dp, 1, p + 1), 0.3_dp, 0.6_dp, spread(1.0_dp, 1, p + 1)])
            r = c
            ! new knots, an existing one (raising multiplicity) and a repeated one
            call curve_insert(r, [0.1_dp, 0.3_dp, 0.45_dp, 0.45_dp, 0.9_dp])
            call check(error, size(r%w), size(c%w) + 5, 'one control point per inserted knot')
            if (allocated(error)) return
            call compare_curves(c, r, dist, ddist)
            call check(error, dist, 0.0_dp, 'knot insertion moved the curve', abs=tol)
            if (allocated(error)) return
            call check(error, ddist, 0.0_dp, 'knot insertion changed the tangent', abs=tol)
            if (allocated(error)) return
        end do
    end subroutine test_insert

    subroutine test_elevate(error)
        type(error_t), allocatable, intent(out) :: error
        type(lcg_t) :: rng
        type(nurbs_curve_t) :: c, r
        real(dp) :: dist, ddist
        integer :: p, t
        do p = 1, 5
            do t = 1, 4
                ! interior knots of multiplicity 1, 2 and p (a C0 corner)
                c = random_curve(rng, p, [spread(0.0_dp, 1, p + 1), 0.2_dp, 0.4_dp, 0.4_dp, &
                                          spread(0.7_dp, 1, p), spread(1.0_dp, 1, p + 1)])
                if (p == 1) c = random_curve(rng, p, [0.0_dp, 0.0_dp, 0.2_dp, 0.4_dp, 0.7_dp, 1.0_dp, 1.0_dp])
                r = c
                call curve_elevate(r, t)
                call check(error, r%degree, p + t, 'elevated degree')
                if (allocated(error)) return
                call compare_curves(c, r, dist, ddist)
                call check(error, dist, 0.0_dp, 'degree elevation moved the curve', abs=tol)
                if (allocated(error)) return
                call check(error, ddist, 0.0_dp, 'degree elevation changed the tangent', abs=tol)
                if (allocated(error)) return
            end do
        end do
    end subroutine test_elevate

    !> Every distinct knot gains multiplicity t; the count of control points follows.
    subroutine test_elevate_mult(error)
        type(error_t), allocatable, intent(out) :: error
        type(lcg_t) :: rng
        type(nurbs_curve_t) :: c, r
        real(dp), allocatable :: br(:)
        integer :: i
        c = random_curve(rng, 2, [0.0_dp, 0.0_dp, 0.0_dp, 0.25_dp, 0.5_dp, 0.5_dp, 0.75_dp, &
                                  1.0_dp, 1.0_dp, 1.0_dp])
        r = c
        call curve_elevate(r, 2)
        br = distinct_knots(c%knots)
        do i = 1, size(br)
            call check(error, multiplicity(r%knots, br(i)), multiplicity(c%knots, br(i)) + 2, &
                       'multiplicity after elevation by 2')
            if (allocated(error)) return
        end do
        ! 7 functions of degree 2 with 3 interior breakpoints -> 7 + 2*(3+1) = 15
        call check(error, size(r%w), 15, 'control points after elevation')
    end subroutine test_elevate_mult

    !> A semicircle of two exact quarter arcs stays on its circle under h, p, k refinement.
    subroutine test_circle(error)
        type(error_t), allocatable, intent(out) :: error
        type(nurbs_surface_t) :: s
        type(nurbs_curve_t) :: arc
        real(dp) :: x(2), worst, u
        integer :: step, k

        s = annulus_sector([2.5_dp, 3.0_dp], 2.0_dp, 3.0_dp, acos(-1.0_dp), 2)
        arc = surface_edge_curve(s, 4)
        do step = 1, 4
            select case (step)
            case (1)
                call curve_insert(arc, [1.0_dp/6, 1.0_dp/3, 2.0_dp/3, 5.0_dp/6])
            case (2)
                call curve_elevate(arc, 2)
            case (3)
                call curve_insert(arc, [0.1_dp, 0.55_dp])
            case (4)
                call curve_elevate(arc, 3)
            end select
            worst = 0.0_dp
            do k = 0, 999
                u = real(k, dp)/999.0_dp
                call curve_eval(arc, u, x)
                worst = max(worst, abs(norm2(x - [2.5_dp, 3.0_dp]) - 3.0_dp))
            end do
            call check(error, worst, 0.0_dp, 'distance from the circle', abs=tol)
            if (allocated(error)) return
        end do
    end subroutine test_circle

    !> A patch turned so that each of its edges becomes eta = 1 describes the same
    !> map with the same orientation; the net is not square (5 x 2 control points),
    !> the case gfortran 12 got wrong with `transpose` of a reversed section.
    subroutine test_turn(error)
        type(error_t), allocatable, intent(out) :: error
        type(nurbs_surface_t) :: s, t
        type(lcg_t) :: rng
        real(dp) :: xs(2), xt(2), js(2, 2), jt(2, 2), a, b, old(2)
        integer :: edge, k

        s = annulus_sector([0.0_dp, 0.0_dp], 1.0_dp, 2.0_dp, 0.3_dp, 2)
        do edge = 1, 4
            t = s
            call surface_reorient(t, edge)
            call check(error, all(shape(t%cp) == [2, size(t%w, 1), size(t%w, 2)]) .and. &
                       size(t%w, 1) == size(t%knots_xi) - t%degree(1) - 1 .and. &
                       size(t%w, 2) == size(t%knots_eta) - t%degree(2) - 1, 'turned net and knots agree')
            if (allocated(error)) return
            do k = 1, 50
                a = rng%uniform()
                b = rng%uniform()
                select case (edge)
                case (1); old = [1.0_dp - b, a]
                case (2); old = [b, 1.0_dp - a]
                case (3); old = [1.0_dp - a, 1.0_dp - b]
                case default; old = [a, b]
                end select
                call surface_eval(s, old(1), old(2), xs, js)
                call surface_eval(t, a, b, xt, jt)
                call check(error, norm2(xt - xs), 0.0_dp, 'turned patch: same point', abs=tol)
                if (allocated(error)) return
                call check(error, jt(1, 1)*jt(2, 2) - jt(1, 2)*jt(2, 1), js(1, 1)*js(2, 2) - js(1, 2)*js(2, 1), &
                           'turned patch: same det J (orientation kept)', rel=tol)
                if (allocated(error)) return
            end do
        end do
    end subroutine test_turn

end module test_refine
