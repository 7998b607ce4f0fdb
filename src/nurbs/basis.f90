!> B-spline basis functions on a knot vector (The NURBS Book, ch. 2).
!>
!> Conventions: a knot vector `knots(1:n+p+1)` with `n` basis functions of degree `p`;
!> spans are 1-based, `span` is the index `i` with `knots(i) <= u < knots(i+1)` and
!> `p+1 <= span <= n`; the functions nonzero on the span are `span-p .. span`.
module voiga_nurbs_basis
    use voiga_kinds, only: dp
    implicit none
    private

    public :: find_span, basis_funs, basis_ders, basis_ders_at, n_basis, distinct_knots, multiplicity
    public :: max_fixed_degree

    !> Highest degree whose basis evaluation (`basis_ders_at`) and contact curve
    !> evaluation need no heap allocation (the case reader accepts degrees up to 20).
    integer, parameter :: max_fixed_degree = 20

contains

    !> Number of basis functions of degree `p` on `knots`.
    pure integer function n_basis(knots, p)
        real(dp), intent(in) :: knots(:)
        integer, intent(in) :: p
        n_basis = size(knots) - p - 1
    end function n_basis

    !> Knot span containing `u`; `u` equal to the last knot falls in the last
    !> non-empty span. `u` outside the knot range is clamped to the first or last span.
    pure integer function find_span(knots, p, u) result(span)
        real(dp), intent(in) :: knots(:)
        integer, intent(in) :: p
        real(dp), intent(in) :: u
        integer :: n, low, high, mid

        n = size(knots) - p - 1
        if (u >= knots(n + 1)) then
            span = n
            ! skip back over repeated end knots to the last non-empty span
            do while (span > p + 1)
                if (knots(span) < knots(span + 1)) exit
                span = span - 1
            end do
            return
        end if
        if (u <= knots(p + 1)) then
            span = p + 1
            do while (span < n)
                if (knots(span) < knots(span + 1)) exit
                span = span + 1
            end do
            return
        end if
        low = p + 1
        high = n + 1
        mid = (low + high)/2
        do while (u < knots(mid) .or. u >= knots(mid + 1))
            if (u < knots(mid)) then
                high = mid
            else
                low = mid
            end if
            mid = (low + high)/2
        end do
        span = mid
    end function find_span

    !> Values of the `p+1` basis functions nonzero on `span` at `u`.
    pure function basis_funs(knots, p, span, u) result(nb)
        real(dp), intent(in) :: knots(:)
        integer, intent(in) :: p, span
        real(dp), intent(in) :: u
        real(dp) :: nb(p + 1)
        real(dp) :: left(p), right(p), saved, temp
        integer :: j, r

        nb(1) = 1.0_dp
        do j = 1, p
            left(j) = u - knots(span + 1 - j)
            right(j) = knots(span + j) - u
            saved = 0.0_dp
            do r = 0, j - 1
                temp = nb(r + 1)/(right(r + 1) + left(j - r))
                nb(r + 1) = saved + right(r + 1)*temp
                saved = left(j - r)*temp
            end do
            nb(j + 1) = saved
        end do
    end function basis_funs

    !> Values and derivatives up to order `nd` of the `p+1` basis functions
    !> nonzero on `span` at `u`. Shape: [nd+1, p+1]; row k+1 holds the k-th derivative.
    !> Derivatives above `p` are zero.
    pure function basis_ders(knots, p, span, u, nd) result(ders)
        real(dp), intent(in) :: knots(:)
        integer, intent(in) :: p, span, nd
        real(dp), intent(in) :: u
        real(dp) :: ders(nd + 1, p + 1)
        call basis_ders_at(knots, p, span, u, nd, ders)
    end function basis_ders

    !> `basis_ders` into `ders` [nd+1, p+1] without a heap allocation up to degree
    !> `max_fixed_degree` (its work arrays then live in a fixed buffer; gfortran puts
    !> arrays whose size is known only at run time on the heap): the contact search
    !> evaluates curves some ten thousand times per Newton iteration.
    pure subroutine basis_ders_at(knots, p, span, u, nd, ders)
        real(dp), intent(in) :: knots(:)
        integer, intent(in) :: p, span, nd
        real(dp), intent(in) :: u
        real(dp), intent(out) :: ders(:, :)
        real(dp) :: fixed((max_fixed_degree + 1)*(max_fixed_degree + 5))
        real(dp), allocatable :: work(:)
        integer :: n
        ! ndu(0:p, 0:p), a(0:1, 0:p), left(p), right(p)
        n = (p + 1)*(p + 1)
        if (p <= max_fixed_degree) then
            call ders_kernel(knots, p, span, u, nd, ders, fixed, fixed(n + 1), fixed(n + 2*p + 3), &
                             fixed(n + 3*p + 3))
        else
            allocate (work((p + 1)*(p + 5)))
            call ders_kernel(knots, p, span, u, nd, ders, work, work(n + 1), work(n + 2*p + 3), &
                             work(n + 3*p + 3))
        end if
    end subroutine basis_ders_at

    !> The algorithm of `basis_ders` (The NURBS Book, A2.3) on work arrays of the caller.
    pure subroutine ders_kernel(knots, p, span, u, nd, ders, ndu, a, left, right)
        real(dp), intent(in) :: knots(:)
        integer, intent(in) :: p, span, nd
        real(dp), intent(in) :: u
        real(dp), intent(out) :: ders(:, :)
        real(dp), intent(inout) :: ndu(0:p, 0:p), a(0:1, 0:p), left(p), right(p)
        real(dp) :: saved, temp, d
        integer :: j, r, k, s1, s2, rk, pk, j1, j2, jj

        ders = 0.0_dp
        ndu(0, 0) = 1.0_dp
        do j = 1, p
            left(j) = u - knots(span + 1 - j)
            right(j) = knots(span + j) - u
            saved = 0.0_dp
            do r = 0, j - 1
                ! lower triangle: knot differences
                ndu(j, r) = right(r + 1) + left(j - r)
                temp = ndu(r, j - 1)/ndu(j, r)
                ! upper triangle: basis values
                ndu(r, j) = saved + right(r + 1)*temp
                saved = left(j - r)*temp
            end do
            ndu(j, j) = saved
        end do
        do j = 0, p
            ders(1, j + 1) = ndu(j, p)
        end do
        do r = 0, p
            s1 = 0
            s2 = 1
            a(0, 0) = 1.0_dp
            do k = 1, min(nd, p)
                d = 0.0_dp
                rk = r - k
                pk = p - k
                if (r >= k) then
                    a(s2, 0) = a(s1, 0)/ndu(pk + 1, rk)
                    d = a(s2, 0)*ndu(rk, pk)
                end if
                j1 = merge(1, -rk, rk >= -1)
                j2 = merge(k - 1, p - r, r - 1 <= pk)
                do jj = j1, j2
                    a(s2, jj) = (a(s1, jj) - a(s1, jj - 1))/ndu(pk + 1, rk + jj)
                    d = d + a(s2, jj)*ndu(rk + jj, pk)
                end do
                if (r <= pk) then
                    a(s2, k) = -a(s1, k - 1)/ndu(pk + 1, r)
                    d = d + a(s2, k)*ndu(r, pk)
                end if
                ders(k + 1, r + 1) = d
                jj = s1
                s1 = s2
                s2 = jj
            end do
        end do
        r = p
        do k = 1, min(nd, p)
            ders(k + 1, :) = ders(k + 1, :)*r
            r = r*(p - k)
        end do
    end subroutine ders_kernel

    !> Distinct knot values (breakpoints) of a knot vector, in increasing order.
    pure function distinct_knots(knots) result(breaks)
        real(dp), intent(in) :: knots(:)
        real(dp), allocatable :: breaks(:)
        integer :: i, n
        logical :: keep(size(knots))

        keep = .false.
        if (size(knots) > 0) keep(1) = .true.
        do i = 2, size(knots)
            keep(i) = knots(i) > knots(i - 1)
        end do
        n = count(keep)
        breaks = pack(knots, keep)
        if (size(breaks) /= n) breaks = breaks(1:n)
    end function distinct_knots

    !> How many times the value `u` occurs in `knots` (exact comparison).
    pure integer function multiplicity(knots, u)
        real(dp), intent(in) :: knots(:)
        real(dp), intent(in) :: u
        multiplicity = count(knots == u)
    end function multiplicity

end module voiga_nurbs_basis
