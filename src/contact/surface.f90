!> A body's contact edge as a univariate NURBS curve over its own control points:
!> the VO layer (degree q) when the body has one, else the bulk's eta = 1 row. This
!> is the trace of the element basis on eta = 1, so the contact integral uses the
!> layer's degree-q functions (docs/theory.md, section 7).
module voiga_contact_surface
    use voiga_kinds, only: dp
    use voiga_nurbs_basis, only: find_span, basis_ders_at, distinct_knots, max_fixed_degree
    use voiga_nurbs_rational, only: rationalize
    use voiga_nurbs_curve, only: nurbs_curve_t
    use voiga_discretization_patch, only: discretization_t
    implicit none
    private

    public :: contact_surface_t, new_contact_surface, new_curve_surface, surface_point_t, surface_point, &
              surface_basis, surface_point_at, element_lengths

    !> The contact edge of one body.
    type :: contact_surface_t
        integer :: degree = 0
        !> Knot vector [n + degree + 1] and weights [n].
        real(dp), allocatable :: knots(:), w(:)
        !> Body-local control point ids [n] and their global DOFs [nsd, n].
        integer, allocatable :: cps(:), dofs(:, :)
        !> Reference control points [2, n].
        real(dp), allocatable :: x0(:, :)
        !> Breakpoints (element boundaries along the edge) [nel + 1].
        real(dp), allocatable :: breaks(:)
        !> Knot-span index of each element along the edge [nel].
        integer, allocatable :: spans(:)
    end type contact_surface_t

    !> The curve at one parameter value, in a given configuration.
    type :: surface_point_t
        real(dp) :: xi = 0.0_dp
        !> Point, first and second parametric derivatives.
        real(dp) :: x(2) = 0.0_dp, a(2) = 0.0_dp, a2(2) = 0.0_dp
        !> Nonzero functions: values, first and second derivatives [p + 1].
        real(dp), allocatable :: r(:), dr(:), d2r(:)
        !> Global DOFs of those functions [2 (p + 1)], local order 2(k-1) + i.
        integer, allocatable :: dofs(:)
        !> Their positions in the surface's arrays [p + 1].
        integer, allocatable :: local(:)
    end type surface_point_t

contains

    !> The contact edge (eta = 1) of `disc`, whose DOFs start after `dof0`.
    pure subroutine new_contact_surface(self, disc, dof0)
        type(contact_surface_t), intent(out) :: self
        type(discretization_t), intent(in) :: disc
        integer, intent(in) :: dof0
        integer :: ny, c
        if (disc%has_layer) then
            self%degree = disc%layer%degree(1)
            self%knots = disc%layer%knots(1)%u
            self%w = disc%layer%w
            self%cps = disc%layer_id
        else
            ny = disc%bulk%n(2)
            self%degree = disc%bulk%degree(1)
            self%knots = disc%bulk%knots(1)%u
            ! the last eta row of the flat weights (xi fastest)
            self%w = disc%bulk%w((ny - 1)*disc%bulk%n(1) + 1:ny*disc%bulk%n(1))
            self%cps = disc%bulk_id((ny - 1)*disc%bulk%n(1) + 1:ny*disc%bulk%n(1))
        end if
        allocate (self%dofs(disc%nsd, size(self%cps)))
        do c = 1, disc%nsd
            self%dofs(c, :) = dof0 + disc%nsd*(self%cps - 1) + c
        end do
        self%x0 = disc%x(:, self%cps)
        call set_spans(self)
    end subroutine new_contact_surface

    !> A curve that belongs to no body (a rigid obstacle's), as a surface over a
    !> displacement vector of its own: control point k has the DOFs 2k - 1, 2k.
    pure subroutine new_curve_surface(self, curve)
        type(contact_surface_t), intent(out) :: self
        type(nurbs_curve_t), intent(in) :: curve
        integer :: k
        self%degree = curve%degree
        self%knots = curve%knots
        self%w = curve%w
        self%cps = [(k, k=1, size(curve%w))]
        allocate (self%dofs(2, size(self%cps)))
        self%dofs(1, :) = 2*self%cps - 1
        self%dofs(2, :) = 2*self%cps
        self%x0 = curve%cp
        call set_spans(self)
    end subroutine new_curve_surface

    !> The breakpoints and the knot span of each element, from the knots.
    pure subroutine set_spans(self)
        type(contact_surface_t), intent(inout) :: self
        integer :: k
        self%breaks = distinct_knots(self%knots)
        allocate (self%spans(size(self%breaks) - 1))
        do k = 1, size(self%spans)
            self%spans(k) = find_span(self%knots, self%degree, 0.5_dp*(self%breaks(k) + self%breaks(k + 1)))
        end do
    end subroutine set_spans

    !> The nonzero functions of the curve at `xi` in knot span `span` (0: found from
    !> xi): values `r`, first and second derivatives `dr`, `d2r` [p + 1], and the span
    !> `s` used. They do not depend on the configuration: a caller that evaluates the
    !> same parameter in many configurations keeps them (`surface_point_at`).
    pure subroutine surface_basis(self, xi, span, r, dr, d2r, s)
        type(contact_surface_t), intent(in) :: self
        real(dp), intent(in) :: xi
        integer, intent(in) :: span
        real(dp), intent(out) :: r(:), dr(:), d2r(:)
        integer, intent(out) :: s
        ! fixed sizes up to max_fixed_degree: no heap allocation per evaluation
        real(dp) :: fixed(3, max_fixed_degree + 1), dr1(1, max_fixed_degree + 1), &
                    d2r1(1, max_fixed_degree + 1)
        real(dp), allocatable :: ders(:, :), dr2(:, :), d2r2(:, :)
        integer :: p
        p = self%degree
        s = span
        ! the search only when no span is forced (a projection forces it at every step)
        if (s <= 0) s = find_span(self%knots, p, xi)
        if (p <= max_fixed_degree) then
            associate (d => fixed(:, 1:p + 1))
                call basis_ders_at(self%knots, p, s, xi, 2, d)
                call rationalize(self%w(s - p:s), d(1, :), d(2:2, :), d(3:3, :), r, dr1(:, 1:p + 1), &
                                 d2r1(:, 1:p + 1))
            end associate
            dr = dr1(1, 1:p + 1)
            d2r = d2r1(1, 1:p + 1)
        else
            allocate (ders(3, p + 1), dr2(1, p + 1), d2r2(1, p + 1))
            call basis_ders_at(self%knots, p, s, xi, 2, ders)
            call rationalize(self%w(s - p:s), ders(1, :), ders(2:2, :), ders(3:3, :), r, dr2, d2r2)
            dr = dr2(1, :)
            d2r = d2r2(1, :)
        end if
    end subroutine surface_basis

    !> Evaluate the surface at `xi` with displacements `u` (global vector). `span`
    !> forces the knot span (0: found from xi), so that a point on an element
    !> boundary can be evaluated from either side. Every component of `pt` is set;
    !> its arrays are reused when they have the right size (a projection evaluates
    !> the curve some ten times per slave point: allocating them afresh each time
    !> was a third of the contact time).
    pure subroutine surface_point(self, u, xi, pt, span)
        type(contact_surface_t), intent(in) :: self
        real(dp), intent(in) :: u(:)
        real(dp), intent(in) :: xi
        type(surface_point_t), intent(inout) :: pt
        integer, intent(in), optional :: span
        integer :: forced, s
        forced = 0
        if (present(span)) forced = span
        call reuse_point(pt, self%degree + 1)
        call surface_basis(self, xi, forced, pt%r, pt%dr, pt%d2r, s)
        call place_point(self, u, xi, s, pt)
    end subroutine surface_point

    !> `surface_point` at `xi` in span `s` from the functions there (`surface_basis`:
    !> `r`, `dr`, `d2r` [p + 1]); the same numbers without evaluating them again.
    pure subroutine surface_point_at(self, u, xi, s, r, dr, d2r, pt)
        type(contact_surface_t), intent(in) :: self
        real(dp), intent(in) :: u(:), xi
        integer, intent(in) :: s
        real(dp), intent(in) :: r(:), dr(:), d2r(:)
        type(surface_point_t), intent(inout) :: pt
        call reuse_point(pt, self%degree + 1)
        pt%r = r
        pt%dr = dr
        pt%d2r = d2r
        call place_point(self, u, xi, s, pt)
    end subroutine surface_point_at

    !> The point, its derivatives and DOFs from the functions in `pt` (span `s`).
    pure subroutine place_point(self, u, xi, s, pt)
        type(contact_surface_t), intent(in) :: self
        real(dp), intent(in) :: u(:), xi
        integer, intent(in) :: s
        type(surface_point_t), intent(inout) :: pt
        real(dp) :: x(2)
        integer :: p, k, id
        p = self%degree
        pt%xi = xi
        pt%x = 0.0_dp
        pt%a = 0.0_dp
        pt%a2 = 0.0_dp
        do k = 1, p + 1
            id = s - p + k - 1
            pt%local(k) = id
            pt%dofs(2*k - 1) = self%dofs(1, id)
            pt%dofs(2*k) = self%dofs(2, id)
            x(1) = self%x0(1, id) + u(self%dofs(1, id))
            x(2) = self%x0(2, id) + u(self%dofs(2, id))
            pt%x = pt%x + pt%r(k)*x
            pt%a = pt%a + pt%dr(k)*x
            pt%a2 = pt%a2 + pt%d2r(k)*x
        end do
    end subroutine place_point

    !> `pt`'s arrays for `n` functions, kept when they have that size.
    pure subroutine reuse_point(pt, n)
        type(surface_point_t), intent(inout) :: pt
        integer, intent(in) :: n
        call reuse(pt%r, n)
        call reuse(pt%dr, n)
        call reuse(pt%d2r, n)
        call reuse_int(pt%local, n)
        call reuse_int(pt%dofs, 2*n)
    contains
        pure subroutine reuse(a, n)
            real(dp), allocatable, intent(inout) :: a(:)
            integer, intent(in) :: n
            if (allocated(a)) then
                if (size(a) == n) return
                deallocate (a)
            end if
            allocate (a(n))
        end subroutine reuse

        pure subroutine reuse_int(a, n)
            integer, allocatable, intent(inout) :: a(:)
            integer, intent(in) :: n
            if (allocated(a)) then
                if (size(a) == n) return
                deallocate (a)
            end if
            allocate (a(n))
        end subroutine reuse_int
    end subroutine reuse_point

    !> The reference length of every element of the edge, as the chord between its
    !> ends; shape: [elements along the edge].
    pure function element_lengths(self) result(h)
        type(contact_surface_t), intent(in) :: self
        real(dp), allocatable :: h(:), u0(:)
        type(surface_point_t) :: pa, pb
        integer :: e
        allocate (h(size(self%spans)), u0(maxval(self%dofs)))
        u0 = 0.0_dp
        do e = 1, size(self%spans)
            call surface_point(self, u0, self%breaks(e), pa, self%spans(e))
            call surface_point(self, u0, self%breaks(e + 1), pb, self%spans(e))
            h(e) = norm2(pb%x - pa%x)
        end do
    end function element_lengths

end module voiga_contact_surface
