!> NURBS curves in the plane: evaluation and refinement.
module voiga_nurbs_curve
    use voiga_kinds, only: dp
    use voiga_nurbs_basis, only: find_span, basis_ders
    use voiga_nurbs_rational, only: rationalize
    use voiga_nurbs_refine, only: insert_knots, elevate_degree
    implicit none
    private

    public :: nurbs_curve_t, curve_eval, curve_basis, curve_elevate, curve_insert, curve_from_homogeneous

    !> A planar NURBS curve.
    type :: nurbs_curve_t
        integer :: degree = 0
        !> Knot vector, shape [n + degree + 1].
        real(dp), allocatable :: knots(:)
        !> Cartesian control points, shape [2, n].
        real(dp), allocatable :: cp(:, :)
        !> Weights, shape [n].
        real(dp), allocatable :: w(:)
    end type nurbs_curve_t

contains

    !> NURBS basis of `curve` at `u` on knot span `span`: values `r` [p+1],
    !> first and second derivatives `dr`, `d2r` [p+1]; functions `span-p .. span`.
    pure subroutine curve_basis(curve, span, u, r, dr, d2r)
        type(nurbs_curve_t), intent(in) :: curve
        integer, intent(in) :: span
        real(dp), intent(in) :: u
        real(dp), intent(out) :: r(:), dr(:), d2r(:)
        real(dp) :: ders(3, curve%degree + 1), dr2(1, curve%degree + 1), d2r2(1, curve%degree + 1)
        integer :: p

        p = curve%degree
        ders = basis_ders(curve%knots, p, span, u, 2)
        call rationalize(curve%w(span - p:span), ders(1, :), ders(2:2, :), ders(3:3, :), &
                         r, dr2, d2r2)
        dr = dr2(1, :)
        d2r = d2r2(1, :)
    end subroutine curve_basis

    !> Point `x`, first derivative `dx` and second derivative `d2x` of `curve` at `u`.
    pure subroutine curve_eval(curve, u, x, dx, d2x)
        type(nurbs_curve_t), intent(in) :: curve
        real(dp), intent(in) :: u
        real(dp), intent(out) :: x(2)
        real(dp), intent(out), optional :: dx(2), d2x(2)
        real(dp) :: r(curve%degree + 1), dr(curve%degree + 1), d2r(curve%degree + 1)
        integer :: span, p

        p = curve%degree
        span = find_span(curve%knots, p, u)
        call curve_basis(curve, span, u, r, dr, d2r)
        x = matmul(curve%cp(:, span - p:span), r)
        if (present(dx)) dx = matmul(curve%cp(:, span - p:span), dr)
        if (present(d2x)) d2x = matmul(curve%cp(:, span - p:span), d2r)
    end subroutine curve_eval

    !> Homogeneous control points [w x, w y, w], shape [3, n].
    pure function to_homogeneous(curve) result(pw)
        type(nurbs_curve_t), intent(in) :: curve
        real(dp), allocatable :: pw(:, :)
        allocate (pw(3, size(curve%w)))
        pw(1, :) = curve%cp(1, :)*curve%w
        pw(2, :) = curve%cp(2, :)*curve%w
        pw(3, :) = curve%w
    end function to_homogeneous

    !> Build a curve from degree, knots and homogeneous control points [3, n].
    pure function curve_from_homogeneous(p, knots, pw) result(curve)
        integer, intent(in) :: p
        real(dp), intent(in) :: knots(:), pw(:, :)
        type(nurbs_curve_t) :: curve
        curve%degree = p
        curve%knots = knots
        curve%w = pw(3, :)
        allocate (curve%cp(2, size(pw, 2)))
        curve%cp(1, :) = pw(1, :)/pw(3, :)
        curve%cp(2, :) = pw(2, :)/pw(3, :)
    end function curve_from_homogeneous

    !> Raise the degree of `curve` by `t` (each distinct knot gains multiplicity t).
    pure subroutine curve_elevate(curve, t)
        type(nurbs_curve_t), intent(inout) :: curve
        integer, intent(in) :: t
        real(dp), allocatable :: pw(:, :), knots(:)
        integer :: p
        if (t <= 0) return
        pw = to_homogeneous(curve)
        knots = curve%knots
        p = curve%degree
        call elevate_degree(p, knots, pw, t)
        curve = curve_from_homogeneous(p, knots, pw)
    end subroutine curve_elevate

    !> Insert each of `values` once into `curve`.
    pure subroutine curve_insert(curve, values)
        type(nurbs_curve_t), intent(inout) :: curve
        real(dp), intent(in) :: values(:)
        real(dp), allocatable :: pw(:, :), knots(:)
        if (size(values) == 0) return
        pw = to_homogeneous(curve)
        knots = curve%knots
        call insert_knots(curve%degree, knots, pw, values)
        curve = curve_from_homogeneous(curve%degree, knots, pw)
    end subroutine curve_insert

end module voiga_nurbs_curve
