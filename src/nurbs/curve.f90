!> NURBS curves in the plane: evaluation (the contact kernels' hot path); refinement is the
!> general patch's (`voiga_nurbs_patch`).
module voiga_nurbs_curve
    use voiga_kinds, only: dp
    use voiga_nurbs_basis, only: find_span, basis_ders
    use voiga_nurbs_rational, only: rationalize
    use voiga_nurbs_patch, only: nurbs_patch_t, knots_t, new_patch, patch_elevate, patch_insert
    implicit none
    private

    public :: nurbs_curve_t, curve_eval, curve_basis, curve_elevate, curve_insert
    public :: curve_patch, curve_from_patch

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

    !> The curve as a general patch (pdim 1): its refinement is the patch's.
    pure function curve_patch(curve) result(patch)
        type(nurbs_curve_t), intent(in) :: curve
        type(nurbs_patch_t) :: patch
        patch = new_patch([curve%degree], [knots_t(curve%knots)], [size(curve%w)], curve%cp, curve%w)
    end function curve_patch

    !> The curve of a patch of parametric dimension 1 in the plane.
    pure function curve_from_patch(patch) result(curve)
        type(nurbs_patch_t), intent(in) :: patch
        type(nurbs_curve_t) :: curve
        curve%degree = patch%degree(1)
        curve%knots = patch%knots(1)%u
        curve%cp = patch%cp
        curve%w = patch%w
    end function curve_from_patch

    !> Raise the degree of `curve` by `t` (each distinct knot gains multiplicity t).
    pure subroutine curve_elevate(curve, t)
        type(nurbs_curve_t), intent(inout) :: curve
        integer, intent(in) :: t
        type(nurbs_patch_t) :: patch
        if (t <= 0) return
        patch = curve_patch(curve)
        call patch_elevate(patch, 1, t)
        curve = curve_from_patch(patch)
    end subroutine curve_elevate

    !> Insert each of `values` once into `curve`.
    pure subroutine curve_insert(curve, values)
        type(nurbs_curve_t), intent(inout) :: curve
        real(dp), intent(in) :: values(:)
        type(nurbs_patch_t) :: patch
        if (size(values) == 0) return
        patch = curve_patch(curve)
        call patch_insert(patch, 1, values)
        curve = curve_from_patch(patch)
    end subroutine curve_insert

end module voiga_nurbs_curve
