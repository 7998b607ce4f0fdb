!> Rational (NURBS) basis functions from weighted B-spline products.
!>
!> Given the B-spline functions `b_a` nonzero at a point (tensor products for
!> surfaces, or any other set such as the varying-order element's), their
!> parametric derivatives and the weights `w_a`, the NURBS functions are
!> `R_a = w_a b_a / W` with `W = sum_a w_a b_a`. Shared by standard and VO elements.
module voiga_nurbs_rational
    use voiga_kinds, only: dp
    implicit none
    private

    public :: rationalize, hessian_pair

contains

    !> NURBS values and parametric derivatives (first and second) from B-spline ones.
    !>
    !> `npar` parametric directions (1 for curves, 2 for surfaces, 3 for volumes);
    !> second derivatives are stored as the `npar*(npar+1)/2` entries of the
    !> symmetric Hessian, the diagonal first: [uu] for curves, [xixi, etaeta,
    !> xieta] for surfaces, [11, 22, 33, 12, 13, 23] for volumes.
    pure subroutine rationalize(w, b, db, d2b, r, dr, d2r)
        !> Weights, shape [nfun].
        real(dp), intent(in) :: w(:)
        !> B-spline values, shape [nfun].
        real(dp), intent(in) :: b(:)
        !> B-spline first derivatives, shape [npar, nfun].
        real(dp), intent(in) :: db(:, :)
        !> B-spline second derivatives, shape [npar*(npar+1)/2, nfun].
        real(dp), intent(in) :: d2b(:, :)
        !> NURBS values, shape [nfun].
        real(dp), intent(out) :: r(:)
        !> NURBS first derivatives, shape [npar, nfun].
        real(dp), intent(out) :: dr(:, :)
        !> NURBS second derivatives, shape [npar*(npar+1)/2, nfun].
        real(dp), intent(out) :: d2r(:, :)
        ! fixed sizes (npar <= 3): no heap allocation per call
        real(dp) :: ww, dw(3), d2w(6)
        integer :: a, npar, i, j, k

        npar = size(db, 1)
        ww = sum(w*b)
        do i = 1, npar
            dw(i) = sum(w*db(i, :))
        end do
        do k = 1, size(d2b, 1)
            d2w(k) = sum(w*d2b(k, :))
        end do
        do a = 1, size(w)
            r(a) = w(a)*b(a)/ww
            do i = 1, npar
                dr(i, a) = (w(a)*db(i, a) - r(a)*dw(i))/ww
            end do
            do k = 1, size(d2b, 1)
                call hessian_pair(npar, k, i, j)
                d2r(k, a) = (w(a)*d2b(k, a) - dr(i, a)*dw(j) - dr(j, a)*dw(i) - r(a)*d2w(k))/ww
            end do
        end do
    end subroutine rationalize

    !> Index pair (i, j) of the k-th stored Hessian entry.
    pure subroutine hessian_pair(npar, k, i, j)
        integer, intent(in) :: npar, k
        integer, intent(out) :: i, j
        ! the pairs after the diagonal: (1, 2) in 2D; (1, 2), (1, 3), (2, 3) in 3D
        integer, parameter :: first(3) = [1, 1, 2], second(3) = [2, 3, 3]
        if (k <= npar) then
            i = k
            j = k
        else
            i = first(k - npar)
            j = second(k - npar)
        end if
    end subroutine hessian_pair

end module voiga_nurbs_rational
