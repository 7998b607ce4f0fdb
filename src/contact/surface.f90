!> A body's contact boundary as a NURBS curve (a plane body's edge) or surface (a
!> solid's face) over its own control points: the VO layer (degree q) when the body
!> has one, else the bulk's last row (eta = 1) or layer (zeta = 1). This is the trace
!> of the element basis on that boundary, so the contact integral uses the layer's
!> degree-q functions (docs/theory.md, section 7). A face has a second parametric
!> direction (eta: `degree_eta`, `knots_eta`, ...; control points xi fastest);
!> everything about the first is named as for an edge.
module voiga_contact_surface
    use voiga_kinds, only: dp
    use voiga_nurbs_basis, only: find_span, basis_ders_at, distinct_knots, max_fixed_degree
    use voiga_nurbs_rational, only: rationalize
    use voiga_nurbs_curve, only: nurbs_curve_t
    use voiga_discretization_patch, only: discretization_t
    use voiga_nurbs_patch, only: knots_t, nurbs_patch_t
    implicit none
    private

    public :: contact_surface_t, new_contact_surface, new_curve_surface, surface_point_t, surface_point, &
              surface_basis, surface_point_at, element_lengths, n_elements, face_basis, face_point_at, face_ids, &
              new_patch_surface

    !> The contact edge of one body.
    type :: contact_surface_t
        !> Parametric directions: 1 (an edge) or 2 (a face).
        integer :: npar = 1
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
        !> A face's second direction: degree, knots, breakpoints and spans (as the
        !> first's), and the control points along xi; unset on an edge.
        integer :: degree_eta = 0, n_xi = 0
        real(dp), allocatable :: knots_eta(:), breaks_eta(:)
        integer, allocatable :: spans_eta(:)
    end type contact_surface_t

    !> The curve at one parameter value, in a given configuration.
    type :: surface_point_t
        !> Parameters (eta: a face's second; 0 on an edge).
        real(dp) :: xi = 0.0_dp, eta = 0.0_dp
        !> Point, first and second derivatives by xi, first by eta [nsd; z = 0 in 2D].
        real(dp) :: x(3) = 0.0_dp, a(3) = 0.0_dp, a2(3) = 0.0_dp, b(3) = 0.0_dp
        !> Nonzero functions: values, first and second derivatives by xi, first by eta
        !> [nfun: p + 1 on an edge, (p + 1)(q + 1) on a face; `drb` empty on an edge].
        real(dp), allocatable :: r(:), dr(:), d2r(:), drb(:)
        !> Global DOFs of those functions [nsd nfun], local order nsd (k-1) + i.
        integer, allocatable :: dofs(:)
        !> Their positions in the surface's arrays [nfun].
        integer, allocatable :: local(:)
    end type surface_point_t

contains

    !> The contact boundary (u_pdim = 1: an edge or a face) of `disc`, whose DOFs
    !> start after `dof0`.
    pure subroutine new_contact_surface(self, disc, dof0)
        type(contact_surface_t), intent(out) :: self
        type(discretization_t), intent(in) :: disc
        integer, intent(in) :: dof0
        integer :: nb, last, c, np
        np = disc%pdim - 1
        if (disc%has_layer) then
            call set_directions(self, disc%layer%degree, disc%layer%knots, disc%layer%n)
            self%w = disc%layer%w
            self%cps = disc%layer_id
        else
            call set_directions(self, disc%bulk%degree(1:np), disc%bulk%knots(1:np), disc%bulk%n(1:np))
            ! the last row (layer) of the flat weights (direction 1 fastest)
            nb = product(disc%bulk%n(1:np))
            last = disc%bulk%n(disc%pdim)
            self%w = disc%bulk%w((last - 1)*nb + 1:last*nb)
            self%cps = disc%bulk_id((last - 1)*nb + 1:last*nb)
        end if
        allocate (self%dofs(disc%nsd, size(self%cps)))
        do c = 1, disc%nsd
            self%dofs(c, :) = dof0 + disc%nsd*(self%cps - 1) + c
        end do
        self%x0 = disc%x(:, self%cps)
        call set_spans(self)
    end subroutine new_contact_surface

    !> Degrees and knots of the boundary's directions (one: an edge; two: a face).
    pure subroutine set_directions(self, degree, knots, n)
        type(contact_surface_t), intent(inout) :: self
        integer, intent(in) :: degree(:), n(:)
        type(knots_t), intent(in) :: knots(:)
        self%npar = size(degree)
        self%degree = degree(1)
        self%knots = knots(1)%u
        if (self%npar < 2) return
        self%degree_eta = degree(2)
        self%knots_eta = knots(2)%u
        self%n_xi = n(1)
    end subroutine set_directions

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

    !> A surface that belongs to no body (a rigid obstacle's, pdim 2, nsd 3), as a face
    !> over a displacement vector of its own: control point k has the DOFs 3k - 2 .. 3k.
    pure subroutine new_patch_surface(self, patch)
        type(contact_surface_t), intent(out) :: self
        type(nurbs_patch_t), intent(in) :: patch
        integer :: k, c
        call set_directions(self, patch%degree, patch%knots, patch%n)
        self%w = patch%w
        self%cps = [(k, k=1, size(patch%w))]
        allocate (self%dofs(3, size(self%cps)))
        do c = 1, 3
            self%dofs(c, :) = 3*(self%cps - 1) + c
        end do
        self%x0 = patch%cp
        call set_spans(self)
    end subroutine new_patch_surface

    !> The breakpoints and the knot span of each element, from the knots (per
    !> direction on a face).
    pure subroutine set_spans(self)
        type(contact_surface_t), intent(inout) :: self
        call direction_spans(self%knots, self%degree, self%breaks, self%spans)
        if (self%npar > 1) call direction_spans(self%knots_eta, self%degree_eta, self%breaks_eta, self%spans_eta)
    end subroutine set_spans

    pure subroutine direction_spans(knots, degree, breaks, spans)
        real(dp), intent(in) :: knots(:)
        integer, intent(in) :: degree
        real(dp), allocatable, intent(out) :: breaks(:)
        integer, allocatable, intent(out) :: spans(:)
        integer :: k
        breaks = distinct_knots(knots)
        allocate (spans(size(breaks) - 1))
        do k = 1, size(spans)
            spans(k) = find_span(knots, degree, 0.5_dp*(breaks(k) + breaks(k + 1)))
        end do
    end subroutine direction_spans

    !> Elements of the boundary: along the edge, or cells of the face (xi fastest).
    pure integer function n_elements(self)
        type(contact_surface_t), intent(in) :: self
        n_elements = size(self%spans)
        if (self%npar > 1) n_elements = n_elements*size(self%spans_eta)
    end function n_elements

    !> Nonzero functions on a face at (`xi`, `eta`) in the cell of spans `s`:
    !> values `r` and first derivatives `dr` (by xi), `drb` (by eta) [(p + 1)(q + 1),
    !> xi fastest]; configuration-independent, like `surface_basis`.
    pure subroutine face_basis(self, xi, eta, s, r, dr, drb)
        type(contact_surface_t), intent(in) :: self
        real(dp), intent(in) :: xi, eta
        integer, intent(in) :: s(2)
        real(dp), intent(out) :: r(:), dr(:), drb(:)
        real(dp) :: bu(2, self%degree + 1), bv(2, self%degree_eta + 1)
        real(dp) :: b(size(r)), db(2, size(r)), d2b(0, size(r)), rd(2, size(r)), r2(0, size(r))
        integer :: i, j, k, p, q
        p = self%degree
        q = self%degree_eta
        call basis_ders_at(self%knots, p, s(1), xi, 1, bu)
        call basis_ders_at(self%knots_eta, q, s(2), eta, 1, bv)
        do j = 1, q + 1
            do i = 1, p + 1
                k = i + (j - 1)*(p + 1)
                b(k) = bu(1, i)*bv(1, j)
                db(1, k) = bu(2, i)*bv(1, j)
                db(2, k) = bu(1, i)*bv(2, j)
            end do
        end do
        call rationalize(self%w(face_ids(self, s)), b, db, d2b, r, rd, r2)
        dr = rd(1, :)
        drb = rd(2, :)
    end subroutine face_basis

    !> Positions in the surface's arrays of the functions of the face cell with
    !> spans `s` [(p + 1)(q + 1), xi fastest].
    pure function face_ids(self, s) result(ids)
        type(contact_surface_t), intent(in) :: self
        integer, intent(in) :: s(2)
        integer :: ids((self%degree + 1)*(self%degree_eta + 1))
        integer :: i, j, p, q
        p = self%degree
        q = self%degree_eta
        do j = 1, q + 1
            do i = 1, p + 1
                ids(i + (j - 1)*(p + 1)) = s(1) - p + i - 1 + (s(2) - q + j - 2)*self%n_xi
            end do
        end do
    end function face_ids

    !> The face at (`xi`, `eta`) in the cell of spans `s` with displacements `u`,
    !> from its functions there (`face_basis`).
    pure subroutine face_point_at(self, u, xi, eta, s, r, dr, drb, pt)
        type(contact_surface_t), intent(in) :: self
        real(dp), intent(in) :: u(:), xi, eta
        integer, intent(in) :: s(2)
        real(dp), intent(in) :: r(:), dr(:), drb(:)
        type(surface_point_t), intent(inout) :: pt
        call reuse_point(pt, size(r), size(self%dofs, 1), .true.)
        pt%r = r
        pt%dr = dr
        pt%d2r = 0.0_dp
        pt%drb = drb
        pt%local = face_ids(self, s)
        pt%eta = eta
        call place_functions(self, u, xi, pt)
    end subroutine face_point_at

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
        call reuse_point(pt, self%degree + 1, size(self%dofs, 1), .false.)
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
        call reuse_point(pt, self%degree + 1, size(self%dofs, 1), .false.)
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
        integer :: p, k
        p = self%degree
        do k = 1, p + 1
            pt%local(k) = s - p + k - 1
        end do
        call place_functions(self, u, xi, pt)
    end subroutine place_point

    !> The point, its derivatives and DOFs from the functions in `pt` and their
    !> positions `pt%local`.
    pure subroutine place_functions(self, u, xi, pt)
        type(contact_surface_t), intent(in) :: self
        real(dp), intent(in) :: u(:), xi
        type(surface_point_t), intent(inout) :: pt
        real(dp) :: x
        integer :: k, id, c, nsd
        nsd = size(self%dofs, 1)
        pt%xi = xi
        pt%x = 0.0_dp
        pt%a = 0.0_dp
        pt%a2 = 0.0_dp
        pt%b = 0.0_dp
        do k = 1, size(pt%local)
            id = pt%local(k)
            do c = 1, nsd
                pt%dofs(nsd*(k - 1) + c) = self%dofs(c, id)
                x = self%x0(c, id) + u(self%dofs(c, id))
                pt%x(c) = pt%x(c) + pt%r(k)*x
                pt%a(c) = pt%a(c) + pt%dr(k)*x
                pt%a2(c) = pt%a2(c) + pt%d2r(k)*x
                if (self%npar > 1) pt%b(c) = pt%b(c) + pt%drb(k)*x
            end do
        end do
    end subroutine place_functions

    !> `pt`'s arrays for `n` functions, kept when they have that size.
    pure subroutine reuse_point(pt, n, nsd, face)
        type(surface_point_t), intent(inout) :: pt
        !> Functions, DOFs per control point, and whether `drb` is needed (a face).
        integer, intent(in) :: n, nsd
        logical, intent(in) :: face
        call reuse(pt%r, n)
        call reuse(pt%dr, n)
        call reuse(pt%d2r, n)
        call reuse(pt%drb, merge(n, 0, face))
        call reuse_int(pt%local, n)
        call reuse_int(pt%dofs, nsd*n)
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

    !> The reference size of every element of the boundary: on an edge the chord
    !> between its ends, on a face the shorter of the chords across the cell's
    !> middle (with `longest`, the longer); shape: [n_elements].
    pure function element_lengths(self, longest) result(h)
        type(contact_surface_t), intent(in) :: self
        logical, intent(in), optional :: longest
        real(dp), allocatable :: h(:), u0(:)
        type(surface_point_t) :: pa, pb
        integer :: e, i, j, ni
        allocate (h(n_elements(self)), u0(maxval(self%dofs)))
        u0 = 0.0_dp
        if (self%npar > 1) then
            ni = size(self%spans)
            do e = 1, size(h)
                i = modulo(e - 1, ni) + 1
                j = (e - 1)/ni + 1
                h(e) = min(face_chord(i, j, 1), face_chord(i, j, 2))
                if (present(longest)) then
                    if (longest) h(e) = max(face_chord(i, j, 1), face_chord(i, j, 2))
                end if
            end do
            return
        end if
        do e = 1, size(self%spans)
            call surface_point(self, u0, self%breaks(e), pa, self%spans(e))
            call surface_point(self, u0, self%breaks(e + 1), pb, self%spans(e))
            h(e) = norm2(pb%x - pa%x)
        end do
    contains
        !> The chord of cell (i, j) across its middle along direction d.
        pure real(dp) function face_chord(i, j, d) result(c)
            integer, intent(in) :: i, j, d
            real(dp) :: ends(2, 2), mid(2)
            real(dp) :: r((self%degree + 1)*(self%degree_eta + 1)), dr(size(r)), drb(size(r))
            type(surface_point_t) :: pa, pb
            integer :: s(2)
            s = [self%spans(i), self%spans_eta(j)]
            ends(:, 1) = self%breaks(i:i + 1)
            ends(:, 2) = self%breaks_eta(j:j + 1)
            mid = 0.5_dp*(ends(1, :) + ends(2, :))
            if (d == 1) then
                call face_basis(self, ends(1, 1), mid(2), s, r, dr, drb)
                call face_point_at(self, u0, ends(1, 1), mid(2), s, r, dr, drb, pa)
                call face_basis(self, ends(2, 1), mid(2), s, r, dr, drb)
                call face_point_at(self, u0, ends(2, 1), mid(2), s, r, dr, drb, pb)
            else
                call face_basis(self, mid(1), ends(1, 2), s, r, dr, drb)
                call face_point_at(self, u0, mid(1), ends(1, 2), s, r, dr, drb, pa)
                call face_basis(self, mid(1), ends(2, 2), s, r, dr, drb)
                call face_point_at(self, u0, mid(1), ends(2, 2), s, r, dr, drb, pb)
            end if
            c = norm2(pb%x - pa%x)
        end function face_chord
    end function element_lengths

end module voiga_contact_surface
