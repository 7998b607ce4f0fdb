!> Basis functions of an element, standard NURBS or varying-order (VO).
module voiga_discretization_element
    use voiga_kinds, only: dp
    use voiga_nurbs_basis, only: basis_ders
    use voiga_nurbs_rational, only: rationalize
    use voiga_discretization_patch, only: discretization_t, element_t
    implicit none
    private

    public :: element_basis, element_nfun

contains

    !> Number of functions nonzero on element `e` (= size of its connectivity).
    pure integer function element_nfun(disc, e)
        type(discretization_t), intent(in) :: disc
        integer, intent(in) :: e
        element_nfun = size(disc%elements(e)%conn)
    end function element_nfun

    !> NURBS functions of element `e` at the parametric point (xi, eta), which
    !> should lie in the element's closure. Shapes: `r` [nfun], `dr` [2, nfun]
    !> (d/dxi, d/deta), `d2r` [3, nfun] (xixi, etaeta, xieta), in the order of
    !> `disc%elements(e)%conn`.
    pure subroutine element_basis(disc, e, xi, eta, r, dr, d2r)
        type(discretization_t), intent(in) :: disc
        integer, intent(in) :: e
        real(dp), intent(in) :: xi, eta
        real(dp), intent(out) :: r(:), dr(:, :)
        !> Optional: second derivatives are only computed when asked for.
        real(dp), intent(out), optional :: d2r(:, :)
        real(dp) :: bx(3, disc%bulk%degree(1) + 1), be(3, disc%bulk%degree(2) + 1)
        real(dp), allocatable :: bl(:, :), d2b(:, :), d2rl(:, :)
        real(dp) :: b(size(r)), db(2, size(r)), w(size(r))
        integer :: p, q, i, j, a, nrow, k, ql, nd

        associate (el => disc%elements(e))
            p = disc%bulk%degree(1)
            q = disc%bulk%degree(2)
            nd = merge(2, 1, present(d2r))
            bx = 0.0_dp
            be = 0.0_dp
            bx(1:nd + 1, :) = basis_ders(disc%bulk%knots_xi, p, el%span_xi, xi, nd)
            be(1:nd + 1, :) = basis_ders(disc%bulk%knots_eta, q, el%span_eta, eta, nd)
            allocate (d2b(3*(nd - 1), size(r)), d2rl(3*(nd - 1), size(r)))
            ! bulk tensor products; in a VO element the last eta function is left out
            nrow = merge(q, q + 1, el%span_layer > 0)
            a = 0
            do j = 1, nrow
                do i = 1, p + 1
                    a = a + 1
                    call tensor(bx(:, i), be(:, j), b(a), db(:, a), d2b(:, a), nd)
                end do
            end do
            if (el%span_layer > 0) then
                ! layer functions times the last eta function M_m
                ql = disc%layer%degree
                allocate (bl(3, ql + 1))
                bl = 0.0_dp
                bl(1:nd + 1, :) = basis_ders(disc%layer%knots, ql, el%span_layer, xi, nd)
                do k = 1, ql + 1
                    a = a + 1
                    call tensor(bl(:, k), be(:, q + 1), b(a), db(:, a), d2b(:, a), nd)
                end do
            end if
            w = disc%w(el%conn)
        end associate
        call rationalize(w, b, db, d2b, r, dr, d2rl)
        if (present(d2r)) d2r = d2rl
    end subroutine element_basis

    !> Product of univariate functions f(xi) g(eta) and its derivatives.
    pure subroutine tensor(f, g, b, db, d2b, nd)
        !> Value, first and second derivative of each factor, shape [3].
        real(dp), intent(in) :: f(3), g(3)
        real(dp), intent(out) :: b, db(2)
        !> Second derivatives [3] when nd = 2 (size 0 otherwise).
        real(dp), intent(out) :: d2b(:)
        integer, intent(in) :: nd
        b = f(1)*g(1)
        db = [f(2)*g(1), f(1)*g(2)]
        if (nd == 2) d2b = [f(3)*g(1), f(1)*g(3), f(2)*g(2)]
    end subroutine tensor

end module voiga_discretization_element
