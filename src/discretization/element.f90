!> Basis functions of an element, standard NURBS or varying-order (VO), of a plane
!> body or a solid: tensor products of univariate B-splines, rationalized.
module voiga_discretization_element
    use voiga_kinds, only: dp
    use voiga_nurbs_basis, only: basis_ders
    use voiga_nurbs_rational, only: rationalize, hessian_pair
    use voiga_nurbs_patch, only: next_index
    use voiga_discretization_patch, only: discretization_t, element_t
    implicit none
    private

    public :: element_basis, element_basis_grid, element_nfun, axis_t

    !> Coordinates along one parametric direction (a grid of points is the tensor
    !> product of one axis per direction).
    type :: axis_t
        real(dp), allocatable :: u(:)
    end type axis_t

contains

    !> Number of functions nonzero on element `e` (= size of its connectivity).
    pure integer function element_nfun(disc, e)
        type(discretization_t), intent(in) :: disc
        integer, intent(in) :: e
        element_nfun = size(disc%elements(e)%conn)
    end function element_nfun

    !> NURBS functions of element `e` at the parametric point `u` [pdim], which
    !> should lie in the element's closure. Shapes: `r` [nfun], `dr` [pdim, nfun]
    !> (d/du_d), `d2r` [pdim (pdim + 1)/2, nfun] (the diagonal, then the pairs (1, 2),
    !> (1, 3), (2, 3): xixi, etaeta, xieta in the plane), in the order of
    !> `disc%elements(e)%conn`.
    pure subroutine element_basis(disc, e, u, r, dr, d2r)
        type(discretization_t), intent(in) :: disc
        integer, intent(in) :: e
        real(dp), intent(in) :: u(:)
        real(dp), intent(out) :: r(:), dr(:, :)
        !> Optional: second derivatives are only computed when asked for.
        real(dp), intent(out), optional :: d2r(:, :)
        real(dp) :: f(3, max_count(disc), disc%pdim)
        real(dp), allocatable :: d2rl(:, :)
        integer :: nd, d
        nd = merge(2, 1, present(d2r))
        do d = 1, disc%pdim
            call univariate(disc, disc%elements(e), d, u(d), nd, f(:, :, d))
        end do
        allocate (d2rl((nd - 1)*disc%pdim*(disc%pdim + 1)/2, size(r)))
        call combine(disc, e, f, nd, r, dr, d2rl)
        if (present(d2r)) d2r = d2rl
    end subroutine element_basis

    !> `element_basis` (values and first derivatives) at the tensor grid of the
    !> `axes` [pdim] (point k: direction 1 fastest): the same numbers, with each
    !> univariate basis evaluated once per coordinate instead of once per point
    !> (the quadrature data of a body: `voiga_model_body`). Shapes: `r` [nfun, npts],
    !> `dr` [pdim, nfun, npts].
    pure subroutine element_basis_grid(disc, e, axes, r, dr)
        type(discretization_t), intent(in) :: disc
        integer, intent(in) :: e
        type(axis_t), intent(in) :: axes(:)
        real(dp), intent(out) :: r(:, :), dr(:, :, :)
        real(dp), allocatable :: f(:, :, :, :)
        real(dp) :: g(3, max_count(disc), disc%pdim), none(0, size(r, 1))
        integer :: d, i, k, idx(disc%pdim), counts(disc%pdim)
        counts = [(size(axes(d)%u), d=1, disc%pdim)]
        allocate (f(3, max_count(disc), disc%pdim, maxval(counts)))
        do d = 1, disc%pdim
            do i = 1, counts(d)
                call univariate(disc, disc%elements(e), d, axes(d)%u(i), 1, f(:, :, d, i))
            end do
        end do
        idx = 1
        do k = 1, product(counts)
            do d = 1, disc%pdim
                g(:, :, d) = f(:, :, d, idx(d))
            end do
            call combine(disc, e, g, 1, r(:, k), dr(:, :, k), none)
            call next_index(idx, counts)
        end do
    end subroutine element_basis_grid

    !> The most univariate functions an element has along one direction: the
    !> bulk's p + 1 and the layer's q + 1 along the contact boundary.
    pure integer function max_count(disc) result(n)
        type(discretization_t), intent(in) :: disc
        n = maxval(disc%bulk%degree) + 1
        if (disc%has_layer) n = n + maxval(disc%layer%degree) + 1
    end function max_count

    !> The functions of element `el` along direction `d` at `u` and their `nd`
    !> derivatives, rows 1..nd+1 of `f` [3, max_count] (the rest zero): the bulk's
    !> and, in a VO element along the contact boundary, then the layer's.
    pure subroutine univariate(disc, el, d, u, nd, f)
        type(discretization_t), intent(in) :: disc
        type(element_t), intent(in) :: el
        integer, intent(in) :: d, nd
        real(dp), intent(in) :: u
        real(dp), intent(out) :: f(:, :)
        integer :: p, q
        p = disc%bulk%degree(d)
        f = 0.0_dp
        f(1:nd + 1, :p + 1) = basis_ders(disc%bulk%knots(d)%u, p, el%span(d), u, nd)
        if (el%span_layer(1) > 0 .and. d < disc%pdim) then
            q = disc%layer%degree(d)
            f(1:nd + 1, p + 2:p + q + 2) = basis_ders(disc%layer%knots(d)%u, q, el%span_layer(d), u, nd)
        end if
    end subroutine univariate

    !> The NURBS functions of element `e` from its univariate ones `f` [3, :, pdim]:
    !> bulk tensor products and, in a VO element, the layer functions times the last
    !> function across the contact boundary, M_m, instead of that function's bulk
    !> products; then rationalized.
    pure subroutine combine(disc, e, f, nd, r, dr, d2r)
        type(discretization_t), intent(in) :: disc
        integer, intent(in) :: e, nd
        real(dp), intent(in) :: f(:, :, :)
        real(dp), intent(out) :: r(:), dr(:, :), d2r(:, :)
        real(dp) :: b(size(r)), db(disc%pdim, size(r)), d2b(size(d2r, 1), size(r))
        integer :: counts(disc%pdim), local(disc%pdim), pick(disc%pdim), nb, nl, a, pd
        associate (el => disc%elements(e))
            pd = disc%pdim
            counts = disc%bulk%degree + 1
            if (el%span_layer(1) > 0) counts(pd) = counts(pd) - 1
            nb = product(counts)
            local = 1
            do a = 1, nb
                call tensor(f, local, b(a), db(:, a), d2b(:, a), nd)
                call next_index(local, counts)
            end do
            if (el%span_layer(1) > 0) then
                nl = product(disc%layer%degree + 1)
                local = 1
                do a = nb + 1, nb + nl
                    pick(:pd - 1) = disc%bulk%degree(:pd - 1) + 1 + local(:pd - 1)
                    pick(pd) = disc%bulk%degree(pd) + 1
                    call tensor(f, pick, b(a), db(:, a), d2b(:, a), nd)
                    call next_index(local(:pd - 1), disc%layer%degree + 1)
                end do
            end if
            call rationalize(disc%w(el%conn), b, db, d2b, r, dr, d2r)
        end associate
    end subroutine combine

    !> Product of one univariate function per direction, f(:, pick(d), d) (value,
    !> first and second derivative), and its derivatives: the gradient `db` and,
    !> when nd = 2, the Hessian `d2b` (diagonal, then (1, 2), (1, 3), (2, 3)).
    pure subroutine tensor(f, pick, b, db, d2b, nd)
        real(dp), intent(in) :: f(:, :, :)
        integer, intent(in) :: pick(:), nd
        real(dp), intent(out) :: b, db(:)
        !> Second derivatives [pdim (pdim + 1)/2] when nd = 2 (size 0 otherwise).
        real(dp), intent(out) :: d2b(:)
        integer :: d, e, k, i, j, np
        np = size(pick)
        b = 1.0_dp
        do e = 1, np
            b = b*f(1, pick(e), e)
        end do
        do d = 1, np
            db(d) = 1.0_dp
            do e = 1, np
                db(d) = db(d)*f(merge(2, 1, e == d), pick(e), e)
            end do
        end do
        if (nd /= 2) return
        do k = 1, size(d2b)
            call hessian_pair(np, k, i, j)
            d2b(k) = 1.0_dp
            do e = 1, np
                d2b(k) = d2b(k)*f(1 + merge(1, 0, e == i) + merge(1, 0, e == j), pick(e), e)
            end do
        end do
    end subroutine tensor

end module voiga_discretization_element
