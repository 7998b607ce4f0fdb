!> Basis functions of an element, standard NURBS or varying-order (VO).
module voiga_discretization_element
    use voiga_kinds, only: dp
    use voiga_nurbs_basis, only: basis_ders
    use voiga_nurbs_rational, only: rationalize
    use voiga_discretization_patch, only: discretization_t, element_t
    implicit none
    private

    public :: element_basis, element_basis_grid, element_nfun

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
        real(dp) :: fx(3, xi_count(disc, e)), fe(3, disc%bulk%degree(2) + 1)
        real(dp), allocatable :: d2rl(:, :)
        integer :: nd
        nd = merge(2, 1, present(d2r))
        call xi_functions(disc, e, xi, nd, fx)
        call eta_functions(disc, e, eta, nd, fe)
        allocate (d2rl(3*(nd - 1), size(r)))
        call combine(disc, e, fx, fe, nd, r, dr, d2rl)
        if (present(d2r)) d2r = d2rl
    end subroutine element_basis

    !> `element_basis` (values and first derivatives) at the tensor grid of points
    !> (xi(i), eta(j)), point k = i + (j - 1) size(xi): the same numbers, with each
    !> univariate basis evaluated once per coordinate instead of once per point
    !> (the quadrature data of a body: `voiga_model_body`). Shapes: `r` [nfun, npts],
    !> `dr` [2, nfun, npts].
    pure subroutine element_basis_grid(disc, e, xi, eta, r, dr)
        type(discretization_t), intent(in) :: disc
        integer, intent(in) :: e
        real(dp), intent(in) :: xi(:), eta(:)
        real(dp), intent(out) :: r(:, :), dr(:, :, :)
        real(dp) :: fx(3, xi_count(disc, e), size(xi)), fe(3, disc%bulk%degree(2) + 1, size(eta))
        real(dp) :: none(0, size(r, 1))
        integer :: i, j
        do i = 1, size(xi)
            call xi_functions(disc, e, xi(i), 1, fx(:, :, i))
        end do
        do j = 1, size(eta)
            call eta_functions(disc, e, eta(j), 1, fe(:, :, j))
        end do
        do j = 1, size(eta)
            do i = 1, size(xi)
                associate (k => i + (j - 1)*size(xi))
                    call combine(disc, e, fx(:, :, i), fe(:, :, j), 1, r(:, k), dr(:, :, k), none)
                end associate
            end do
        end do
    end subroutine element_basis_grid

    !> How many univariate functions of xi element `e` has: the bulk's p + 1 and,
    !> in a VO element, the layer's.
    pure integer function xi_count(disc, e) result(n)
        type(discretization_t), intent(in) :: disc
        integer, intent(in) :: e
        n = disc%bulk%degree(1) + 1
        if (disc%elements(e)%span_layer > 0) n = n + disc%layer%degree + 1
    end function xi_count

    !> The xi functions of element `e` at `xi` and their `nd` derivatives, rows
    !> 1..nd+1 of `fx` [3, xi_count] (the rest zero): the bulk's, then the layer's.
    pure subroutine xi_functions(disc, e, xi, nd, fx)
        type(discretization_t), intent(in) :: disc
        integer, intent(in) :: e, nd
        real(dp), intent(in) :: xi
        real(dp), intent(out) :: fx(:, :)
        integer :: p
        associate (el => disc%elements(e))
            p = disc%bulk%degree(1)
            fx = 0.0_dp
            fx(1:nd + 1, :p + 1) = basis_ders(disc%bulk%knots(1)%u, p, el%span_xi, xi, nd)
            if (el%span_layer > 0) fx(1:nd + 1, p + 2:) = &
                basis_ders(disc%layer%knots, disc%layer%degree, el%span_layer, xi, nd)
        end associate
    end subroutine xi_functions

    !> The bulk's eta functions of element `e` at `eta`, as `xi_functions` ([3, q + 1]).
    pure subroutine eta_functions(disc, e, eta, nd, fe)
        type(discretization_t), intent(in) :: disc
        integer, intent(in) :: e, nd
        real(dp), intent(in) :: eta
        real(dp), intent(out) :: fe(:, :)
        fe = 0.0_dp
        fe(1:nd + 1, :) = basis_ders(disc%bulk%knots(2)%u, disc%bulk%degree(2), disc%elements(e)%span_eta, eta, nd)
    end subroutine eta_functions

    !> The NURBS functions of element `e` from its univariate ones: bulk tensor
    !> products, and in a VO element the layer functions times the last eta
    !> function M_m instead of that function's bulk products; then rationalized.
    pure subroutine combine(disc, e, fx, fe, nd, r, dr, d2r)
        type(discretization_t), intent(in) :: disc
        integer, intent(in) :: e, nd
        real(dp), intent(in) :: fx(:, :), fe(:, :)
        real(dp), intent(out) :: r(:), dr(:, :), d2r(:, :)
        real(dp) :: b(size(r)), db(2, size(r)), d2b(3*(nd - 1), size(r))
        integer :: p, q, i, j, a, nrow
        associate (el => disc%elements(e))
            p = disc%bulk%degree(1)
            q = disc%bulk%degree(2)
            nrow = merge(q, q + 1, el%span_layer > 0)
            a = 0
            do j = 1, nrow
                do i = 1, p + 1
                    a = a + 1
                    call tensor(fx(:, i), fe(:, j), b(a), db(:, a), d2b(:, a), nd)
                end do
            end do
            do i = p + 2, size(fx, 2)
                a = a + 1
                call tensor(fx(:, i), fe(:, q + 1), b(a), db(:, a), d2b(:, a), nd)
            end do
            call rationalize(disc%w(el%conn), b, db, d2b, r, dr, d2r)
        end associate
    end subroutine combine

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
