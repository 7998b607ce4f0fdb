!> B-spline and NURBS basis: partition of unity, non-negativity, derivatives
!> against finite differences, knot spans.
module test_basis
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_testdrive, only: unittest_t, new_unittest, check
    use voiga_nurbs_basis, only: find_span, basis_funs, basis_ders, basis_ders_at, max_fixed_degree
    use voiga_contact_surface, only: contact_surface_t, surface_point_t, surface_point, surface_basis, &
                                     surface_point_at
    use voiga_nurbs_curve, only: nurbs_curve_t, curve_basis
    use voiga_test_fixtures, only: lcg_t
    implicit none
    private

    public :: collect_basis

contains

    subroutine collect_basis(testsuite)
        type(unittest_t), allocatable, intent(out) :: testsuite(:)
        testsuite = [ &
                    new_unittest('find_span', test_find_span), &
                    new_unittest('partition_of_unity', test_partition), &
                    new_unittest('derivatives_fd', test_derivatives_fd), &
                    new_unittest('nurbs_curve_fd', test_nurbs_curve_fd), &
                    new_unittest('ders_at_no_heap_path', test_ders_at), &
                    new_unittest('contact_curve_from_cached_basis', test_surface_point_at) &
                    ]
    end subroutine collect_basis

    !> A knot vector of degree p with repeated interior knots (mult up to p).
    function test_knots(p) result(knots)
        integer, intent(in) :: p
        real(dp), allocatable :: knots(:)
        knots = [spread(0.0_dp, 1, p + 1), 0.2_dp, 0.35_dp, 0.35_dp, spread(0.5_dp, 1, p), &
                 0.8_dp, spread(1.0_dp, 1, p + 1)]
    end function test_knots

    subroutine test_find_span(error)
        type(error_t), allocatable, intent(out) :: error
        real(dp), allocatable :: knots(:)
        integer :: p, span
        p = 3
        knots = test_knots(p)   ! 0000 .2 .35 .35 .5 .5 .5 .8 1111
        call check(error, find_span(knots, p, 0.0_dp), 4, 'span at u = 0')
        if (allocated(error)) return
        call check(error, find_span(knots, p, 0.2_dp), 5, 'span at an interior knot')
        if (allocated(error)) return
        call check(error, find_span(knots, p, 0.35_dp), 7, 'span at a double knot')
        if (allocated(error)) return
        call check(error, find_span(knots, p, 0.5_dp), 10, 'span at a triple knot')
        if (allocated(error)) return
        span = find_span(knots, p, 1.0_dp)
        call check(error, span, size(knots) - p - 1, 'u = 1 falls in the last span')
        if (allocated(error)) return
        call check(error, knots(span) < knots(span + 1), 'last span is not empty')
    end subroutine test_find_span

    subroutine test_partition(error)
        type(error_t), allocatable, intent(out) :: error
        real(dp), allocatable :: knots(:), nb(:), ders(:, :)
        type(lcg_t) :: rng
        real(dp) :: u
        integer :: p, k, span

        do p = 1, 7
            knots = test_knots(p)
            do k = 1, 200
                u = rng%uniform()
                span = find_span(knots, p, u)
                nb = basis_funs(knots, p, span, u)
                call check(error, sum(nb), 1.0_dp, 'partition of unity', abs=1.0e-14_dp)
                if (allocated(error)) return
                call check(error, all(nb >= 0.0_dp), 'non-negativity')
                if (allocated(error)) return
                ders = basis_ders(knots, p, span, u, 3)
                call check(error, ders(1, :), nb, 'basis_ders values = basis_funs', abs=1.0e-15_dp)
                if (allocated(error)) return
                ! derivatives of a partition of unity sum to zero; scale by knot spacing^-k
                call check(error, sum(ders(2, :)), 0.0_dp, 'first derivatives sum to zero', abs=1.0e-10_dp)
                if (allocated(error)) return
                call check(error, sum(ders(3, :)), 0.0_dp, 'second derivatives sum to zero', abs=1.0e-8_dp)
                if (allocated(error)) return
            end do
        end do
    end subroutine test_partition

    !> Central differences of values and first derivatives, at points away from knots.
    subroutine test_derivatives_fd(error)
        type(error_t), allocatable, intent(out) :: error
        real(dp), allocatable :: knots(:), d0(:, :), dp1(:, :), dm1(:, :)
        real(dp), parameter :: h = 1.0e-6_dp
        real(dp) :: u
        type(lcg_t) :: rng
        integer :: p, k, span

        do p = 1, 6
            knots = test_knots(p)
            do k = 1, 100
                u = rng%uniform()
                span = find_span(knots, p, u)
                ! stay inside the span so the difference sees one polynomial piece
                if (u - h <= knots(span) .or. u + h >= knots(span + 1)) cycle
                d0 = basis_ders(knots, p, span, u, 2)
                dp1 = basis_ders(knots, p, span, u + h, 2)
                dm1 = basis_ders(knots, p, span, u - h, 2)
                ! central differences have O(h^2) truncation and eps/h round-off:
                ! with |N''| up to ~1e3 on these knot spacings, 1e-5 relative holds
                call check(error, d0(2, :), (dp1(1, :) - dm1(1, :))/(2*h), 'dN/du vs FD', &
                           rel=1.0e-5_dp, abs=1.0e-5_dp)
                if (allocated(error)) return
                call check(error, d0(3, :), (dp1(2, :) - dm1(2, :))/(2*h), 'd2N/du2 vs FD', &
                           rel=1.0e-5_dp, abs=1.0e-3_dp)
                if (allocated(error)) return
            end do
        end do
    end subroutine test_derivatives_fd

    !> NURBS curve basis: partition of unity, positivity and derivatives by FD.
    subroutine test_nurbs_curve_fd(error)
        type(error_t), allocatable, intent(out) :: error
        type(nurbs_curve_t) :: c
        type(lcg_t) :: rng
        real(dp), parameter :: h = 1.0e-6_dp
        real(dp), allocatable :: r(:), dr(:), d2r(:), rp(:), drp(:), d2rp(:), rm(:), drm(:), d2rm(:)
        real(dp) :: u
        integer :: p, k, span, n

        do p = 2, 5
            c%degree = p
            c%knots = test_knots(p)
            n = size(c%knots) - p - 1
            allocate (c%w(n), c%cp(2, n))
            do k = 1, n
                c%w(k) = 0.3_dp + rng%uniform()
                c%cp(:, k) = [rng%uniform(), rng%uniform()]
            end do
            allocate (r(p + 1), dr(p + 1), d2r(p + 1), rp(p + 1), drp(p + 1), d2rp(p + 1), &
                      rm(p + 1), drm(p + 1), d2rm(p + 1))
            do k = 1, 100
                u = rng%uniform()
                span = find_span(c%knots, p, u)
                if (u - h <= c%knots(span) .or. u + h >= c%knots(span + 1)) cycle
                call curve_basis(c, span, u, r, dr, d2r)
                call curve_basis(c, span, u + h, rp, drp, d2rp)
                call curve_basis(c, span, u - h, rm, drm, d2rm)
                call check(error, sum(r), 1.0_dp, 'NURBS partition of unity', abs=1.0e-14_dp)
                if (allocated(error)) return
                call check(error, all(r >= 0.0_dp), 'NURBS non-negativity')
                if (allocated(error)) return
                call check(error, dr, (rp - rm)/(2*h), 'dR/du vs FD', rel=1.0e-5_dp, abs=1.0e-5_dp)
                if (allocated(error)) return
                call check(error, d2r, (drp - drm)/(2*h), 'd2R/du2 vs FD', rel=1.0e-5_dp, abs=1.0e-3_dp)
                if (allocated(error)) return
            end do
            deallocate (c%w, c%cp, r, dr, d2r, rp, drp, d2rp, rm, drm, d2rm)
        end do
    end subroutine test_nurbs_curve_fd

    !> `basis_ders_at` (work arrays in a fixed buffer up to `max_fixed_degree`, on the heap
    !> above) gives `basis_ders` bit for bit, on both sides of the limit.
    subroutine test_ders_at(error)
        type(error_t), allocatable, intent(out) :: error
        real(dp), allocatable :: knots(:), ders(:, :)
        type(lcg_t) :: rng
        real(dp) :: u
        integer :: p, k, span
        do p = 1, max_fixed_degree + 2
            knots = test_knots(p)
            allocate (ders(3, p + 1))
            do k = 1, 20
                u = rng%uniform()
                span = find_span(knots, p, u)
                call basis_ders_at(knots, p, span, u, 2, ders)
                call check(error, all(ders == basis_ders(knots, p, span, u, 2)), &
                           'basis_ders_at = basis_ders, degree '//trim(adjustl(itoa(p))))
                if (allocated(error)) return
            end do
            deallocate (ders)
        end do
    contains
        pure function itoa(i) result(t)
            integer, intent(in) :: i
            character(len=12) :: t
            write (t, '(i0)') i
        end function itoa
    end subroutine test_ders_at

    !> A contact curve evaluated from its functions computed once (`surface_basis`, then
    !> `surface_point_at` in another configuration) is the same point, bit for bit, as
    !> `surface_point` evaluating them again.
    subroutine test_surface_point_at(error)
        type(error_t), allocatable, intent(out) :: error
        type(contact_surface_t) :: c
        type(surface_point_t) :: a, b
        type(lcg_t) :: rng
        real(dp), allocatable :: u(:), r(:), dr(:), d2r(:)
        real(dp) :: xi
        integer :: p, n, k, s, i
        do p = 2, 4
            c%degree = p
            c%knots = test_knots(p)
            n = size(c%knots) - p - 1
            c%w = [(0.5_dp + rng%uniform(), k=1, n)]
            c%x0 = reshape([(rng%uniform(), k=1, 2*n)], [2, n])
            c%dofs = reshape([(k, k=1, 2*n)], [2, n])
            u = [(0.1_dp*rng%uniform(), k=1, 2*n)]
            allocate (r(p + 1), dr(p + 1), d2r(p + 1))
            do i = 1, 20
                xi = rng%uniform()
                call surface_basis(c, xi, 0, r, dr, d2r, s)
                call surface_point(c, u, xi, a)
                call surface_point_at(c, u, xi, s, r, dr, d2r, b)
                call check(error, all([a%x, a%a, a%a2] == [b%x, b%a, b%a2]) .and. all(a%dofs == b%dofs) &
                           .and. all(a%r == b%r), 'surface_point_at = surface_point')
                if (allocated(error)) return
            end do
            deallocate (r, dr, d2r)
        end do
    end subroutine test_surface_point_at

end module test_basis
