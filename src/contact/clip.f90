!> Polygon kernels of the segment-based mortar on faces (`voiga_contact_segment_faces`):
!> clipping a master cell's image to a slave cell (Sutherland-Hodgman), polygon areas,
!> and the quadrature rules of the pieces (the tensor rule of a rectangle, the collapsed
!> Duffy rule of a triangle). Pure geometry on parameter planes: no contact state.
module voiga_contact_clip
    use voiga_kinds, only: dp
    implicit none
    private

    public :: clip_to_rectangle, signed_area, rectangle_rule, triangle_rule

contains

    !> The part of the quadrilateral `q` [2, 4] inside the rectangle [lo, hi]
    !> (Sutherland-Hodgman against its four half-planes) [2, vertices].
    pure function clip_to_rectangle(q, lo, hi) result(poly)
        real(dp), intent(in) :: q(:, :), lo(2), hi(2)
        real(dp), allocatable :: poly(:, :)
        integer :: a
        poly = q
        do a = 1, 2
            poly = clip_half(poly, a, lo(a), 1.0_dp)
            poly = clip_half(poly, a, hi(a), -1.0_dp)
        end do
    end function clip_to_rectangle

    !> The part of `poly` [2, n] where side (x_a - c) >= 0.
    pure function clip_half(poly, a, c, side) result(out)
        real(dp), intent(in) :: poly(:, :), c, side
        integer, intent(in) :: a
        real(dp), allocatable :: out(:, :)
        real(dp) :: d0, d1, pt(2)
        integer :: k, n
        n = size(poly, 2)
        allocate (out(2, 0))
        do k = 1, n
            associate (p0 => poly(:, k), p1 => poly(:, modulo(k, n) + 1))
                d0 = side*(p0(a) - c)
                d1 = side*(p1(a) - c)
                if (d0 >= 0.0_dp) out = reshape([out, p0], [2, size(out, 2) + 1])
                if ((d0 >= 0.0_dp) .neqv. (d1 >= 0.0_dp)) then
                    pt = p0 + d0/(d0 - d1)*(p1 - p0)
                    ! exactly on the line (no round-off across it)
                    pt(a) = c
                    out = reshape([out, pt], [2, size(out, 2) + 1])
                end if
            end associate
        end do
    end function clip_half

    !> The signed area of the polygon `poly` [2, n] (positive counterclockwise).
    pure real(dp) function signed_area(poly) result(area)
        real(dp), intent(in) :: poly(:, :)
        integer :: k, n
        n = size(poly, 2)
        area = 0.0_dp
        do k = 1, n
            area = area + poly(1, k)*poly(2, modulo(k, n) + 1) - poly(2, k)*poly(1, modulo(k, n) + 1)
        end do
        area = 0.5_dp*area
    end function signed_area

    !> The tensor rule (`gx`, `gw` on [0, 1]) on the rectangle [lo, hi]: points `px`
    !> [2, n^2] and weights `pw` [n^2].
    pure subroutine rectangle_rule(lo, hi, gx, gw, px, pw)
        real(dp), intent(in) :: lo(2), hi(2), gx(:), gw(:)
        real(dp), allocatable, intent(out) :: px(:, :), pw(:)
        integer :: i, j, k, n
        n = size(gx)
        allocate (px(2, n*n), pw(n*n))
        k = 0
        do j = 1, n
            do i = 1, n
                k = k + 1
                px(:, k) = lo + [gx(i), gx(j)]*(hi - lo)
                pw(k) = gw(i)*gw(j)*product(hi - lo)
            end do
        end do
    end subroutine rectangle_rule

    !> The collapsed Gauss rule on each triangle of `tri` [2, 3, triangles]: with s, t
    !> the rule's points on [0, 1], x = v1 + s (v2 - v1) + s t (v3 - v2), weight
    !> w_s w_t s |det(v2 - v1, v3 - v2)|. A monomial of total degree d becomes one of
    !> degree d + 1 in s (the Jacobian's s) and d in t: exact for d <= 2 n - 2.
    pure subroutine triangle_rule(tri, gx, gw, px, pw)
        real(dp), intent(in) :: tri(:, :, :), gx(:), gw(:)
        real(dp), allocatable, intent(out) :: px(:, :), pw(:)
        real(dp) :: det
        integer :: i, j, k, it, n
        n = size(gx)
        allocate (px(2, n*n*size(tri, 3)), pw(n*n*size(tri, 3)))
        k = 0
        do it = 1, size(tri, 3)
            associate (v1 => tri(:, 1, it), v2 => tri(:, 2, it), v3 => tri(:, 3, it))
                det = abs((v2(1) - v1(1))*(v3(2) - v2(2)) - (v2(2) - v1(2))*(v3(1) - v2(1)))
                do j = 1, n
                    do i = 1, n
                        k = k + 1
                        px(:, k) = v1 + gx(i)*(v2 - v1) + gx(i)*gx(j)*(v3 - v2)
                        pw(k) = gw(i)*gw(j)*gx(i)*det
                    end do
                end do
            end associate
        end do
    end subroutine triangle_rule

end module voiga_contact_clip
