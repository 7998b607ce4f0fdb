!> Segment-based mortar contact on a solid's face (`&contact method = 'segment'` with
!> a face as the slave): the constraints, law and tangent of the mortar-type penalty
!> on faces (`voiga_contact_mortar`, `mortar_point3`), one constraint per slave control
!> point, but each slave cell's integrals are split where the master's cells begin and
!> end, so that within every piece the master functions N_B(xi_m(xi_s)) have no kink
!> and the mortar integrals int N_A N_B dA0 are exact to the quadrature of a
!> polynomial: the uniform pressure of the contact patch test is then an exact
!> discrete solution on non-matching faces (docs/verification-faces.md, "Contact
!> patch test"; docs/theory.md, section 7). The segmentation is made, frozen and
!> written as the edge's (`voiga_contact_segment`): at the reference state and at
!> every converged state, constant within a substep's Newton iterations.
!>
!> The pieces, per slave cell (a rectangle in the slave's parameters):
!> - the master cells its image can touch: those of the projections of 3 x 3 points
!>   of the cell, one cell more on each side, and a ghost cell beyond each edge of
!>   the master that range reaches (the part of the slave cell that sees no master);
!>   a cell farther from the master than it is wide is not cut;
!> - each master node (breakpoint pair) mapped into the slave cell's parameters where
!>   the master's normal line through it meets the slave cell's surface (its
!>   polynomial piece, continued beyond the cell): the closest-point projection
!>   sends a slave point to a master node exactly when the slave point lies on that
!>   line, so these are the exact preimages of the master nodes. Projecting the
!>   nodes onto the slave along the slave's normal instead would be exact only for
!>   parallel faces; projecting slave points onto the master and clipping there
!>   would need the inverse of the projection to place the points. For flat faces
!>   with affine parametrizations (both blocks of the patch test, tilted or not) the
!>   map is affine, the master cells' preimages are the convex quadrilaterals of
!>   their mapped nodes, and the pieces are exact; on curved faces the preimages'
!>   curved sides are replaced by their chords (the pieces still tile the cell: the
!>   neighbours share the mapped nodes);
!> - each quadrilateral clipped to the cell's rectangle (Sutherland-Hodgman, the
!>   rectangle's four half-planes: exact for any simple quadrilateral), fanned into
!>   triangles, integrated with the collapsed (Duffy) Gauss rule of `n_gauss` points
!>   per direction: exact for polynomials of total degree 2 n_gauss - 2 in the slave
!>   parameters. A cell inside one master cell keeps the tensor rule of n_gauss^2
!>   points on its rectangle. A cell whose pieces do not tile it (a mapping that did
!>   not converge, a folded preimage) falls back to that tensor rule too.
module voiga_contact_segment_faces
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_element_quadrature, only: gauss_legendre
    use voiga_nurbs_patch, only: nurbs_patch_t, knots_t, new_patch, cross
    use voiga_nurbs_projection, only: surface_derivatives
    use voiga_contact_surface, only: contact_surface_t, surface_point_t, face_basis, face_ids, n_elements
    use voiga_contact_master, only: master_point_t
    use voiga_contact_master_face, only: face_master_t
    use voiga_contact_pair, only: history_item_t
    use voiga_contact_history, only: flag_value
    use voiga_contact_law, only: state_inactive
    use voiga_contact_segment, only: segment_pair_t, interpolated_output
    use voiga_contact_clip, only: clip_to_rectangle, signed_area, rectangle_rule, triangle_rule
    implicit none
    private

    public :: segment_face_pair_t, default_face_segment_points, face_segment_points

    !> Newton iterations of a master node's mapping onto the slave cell.
    integer, parameter :: max_newton = 30
    !> A piece smaller than this fraction of its cell adds nothing; pieces whose
    !> areas miss the cell's by more than `tile_tol` of it do not tile it.
    real(dp), parameter :: sliver = 1.0e-12_dp, tile_tol = 1.0e-9_dp

    !> The segment-based mortar pair of a face.
    type, extends(segment_pair_t) :: segment_face_pair_t
    contains
        procedure :: setup => face_setup
        procedure :: commit => face_commit
        procedure :: history => face_history
        procedure :: set_history => face_set_history
        procedure :: most_points => face_most_points
    end type segment_face_pair_t

    !> The triangles of one slave cell's pieces [2, 3, triangles] and whether the cell
    !> lies in one piece (`whole`: the tensor rule).
    type :: cell_pieces_t
        real(dp), allocatable :: tri(:, :, :)
        logical :: whole = .true.
    end type cell_pieces_t

contains

    !> Points per direction of the collapsed rule by default: exact for the total
    !> degree d = p_xi + p_eta + q_xi + q_eta of N_A N_B (slave degrees p, master q;
    !> 0 for a rigid plane) under an affine map, which needs 2 n - 2 >= d.
    pure integer function default_face_segment_points(slave_degrees, master_degrees) result(n)
        integer, intent(in) :: slave_degrees(2), master_degrees(2)
        n = (sum(slave_degrees) + sum(master_degrees) + 1)/2 + 1
    end function default_face_segment_points

    !> The mortar pair's set-up (with the default points), then the segmentation of
    !> the reference configuration.
    pure subroutine face_setup(self)
        class(segment_face_pair_t), intent(inout) :: self
        real(dp), allocatable :: u0(:)
        integer :: qm(2), n
        if (self%n_gauss <= 0) then
            qm = 0
            select type (m => self%master)
            class is (face_master_t)
                qm = [m%surf%degree, m%surf%degree_eta]
            end select
            self%n_gauss = default_face_segment_points([self%slave%degree, self%slave%degree_eta], qm)
        end if
        call self%segment_pair_t%mortar_pair_t%setup()
        n = maxval(self%slave%dofs)
        if (size(self%master%all_dofs()) > 0) n = max(n, maxval(self%master%all_dofs()))
        allocate (u0(n), source=0.0_dp)
        call resegment(self, u0)
    end subroutine face_setup

    !> The step converged at the last evaluation: commit the mortar history, then
    !> segment the slave face there for the next substep.
    pure subroutine face_commit(self)
        class(segment_face_pair_t), intent(inout) :: self
        call self%segment_pair_t%mortar_pair_t%commit()
        if (allocated(self%u_last)) call resegment(self, self%u_last)
    end subroutine face_commit

    !> Segment the slave face at `u` (the master where it is now), place the points,
    !> and give them the converged state's output (as the edge's `resegment`).
    pure subroutine resegment(self, u)
        class(segment_face_pair_t), intent(inout) :: self
        real(dp), intent(in) :: u(:)
        real(dp), allocatable :: xi(:), eta(:), w(:)
        integer, allocatable :: elem(:)
        type(surface_point_t) :: sp
        type(master_point_t) :: mp
        logical :: found, converged, warm
        integer :: k
        call self%master%prepare(u)
        call face_segment_points(self, u, xi, eta, w, elem)
        call place_face_points(self, xi, eta, w, elem)
        warm = self%warm
        self%warm = .false.
        do k = 1, size(self%xi)
            call self%project_point(u, k, sp, mp, found, converged)
            found = found .and. converged
            if (self%h_xi > 0) then
                self%hist%field(self%h_xi)%last(k) = mp%xi
                self%hist%field(self%h_eta)%last(k) = mp%eta
                self%hist%field(self%h_active)%last(k) = flag_value(found)
            end if
            if (found) call interpolated_output(self, k)
            if (found .and. self%h_traction > 0) call traction_output(self, k, mp%n)
        end do
        self%warm = warm
        call self%hist%reset_trial()
    end subroutine resegment

    !> A new point's traction vector (`interpolated_output` gives the pressure): the
    !> committed control-point vectors (Cartesian, history `traction`, `traction_y`,
    !> `traction_z`) interpolated there and projected on the master's tangent plane
    !> (normal `n`), as the face mortar evaluation makes it.
    pure subroutine traction_output(self, k, n)
        class(segment_face_pair_t), intent(inout) :: self
        integer, intent(in) :: k
        real(dp), intent(in) :: n(3)
        real(dp) :: tbar(3)
        associate (nodes => self%point_nodes(:, k), phi => self%point_values(:, k), out => self%out(k), &
                   h => self%hist%field)
            if (out%state == state_inactive) return
            tbar = [dot_product(phi, h(self%h_traction)%last(nodes)), &
                    dot_product(phi, h(self%h_traction_yz(1))%last(nodes)), &
                    dot_product(phi, h(self%h_traction_yz(2))%last(nodes))]
            tbar = tbar - dot_product(n, tbar)*n
            out%pt0 = norm2(tbar)
            out%pt = out%pt0/out%stretch
            out%tt = tbar/out%stretch
        end associate
    end subroutine traction_output

    !> The segmented quadrature of the slave face at `u` (`prepare`d master): per
    !> slave cell (xi fastest) its pieces (`cell_pieces`) and their points:
    !> parameters `xi`, `eta`, weights `w` (rule weight x parameter area) and slave
    !> cells `elem` [points].
    pure subroutine face_segment_points(self, u, xi, eta, w, elem)
        class(segment_face_pair_t), intent(in) :: self
        real(dp), intent(in) :: u(:)
        real(dp), allocatable, intent(out) :: xi(:), eta(:), w(:)
        integer, allocatable, intent(out) :: elem(:)
        type(nurbs_patch_t) :: slave_patch
        type(cell_pieces_t) :: pcs
        real(dp), allocatable :: gx(:), gw(:), px(:, :), pw(:)
        real(dp) :: lo(2), hi(2)
        integer :: ci, cj, nu, nv, ng
        ng = self%n_gauss
        allocate (gx(ng), gw(ng))
        call gauss_legendre(ng, gx, gw)
        ! the rule on [0, 1]
        gx = 0.5_dp*(gx + 1.0_dp)
        gw = 0.5_dp*gw
        nu = size(self%slave%spans)
        nv = size(self%slave%spans_eta)
        slave_patch = displaced_patch(self%slave, u)
        allocate (xi(0), eta(0), w(0), elem(0))
        do cj = 1, nv
            do ci = 1, nu
                lo = [self%slave%breaks(ci), self%slave%breaks_eta(cj)]
                hi = [self%slave%breaks(ci + 1), self%slave%breaks_eta(cj + 1)]
                pcs%whole = .true.
                select type (m => self%master)
                class is (face_master_t)
                    pcs = cell_pieces(m, u, slave_patch, [self%slave%spans(ci), self%slave%spans_eta(cj)], lo, hi)
                end select
                if (pcs%whole) then
                    call rectangle_rule(lo, hi, gx, gw, px, pw)
                else
                    call triangle_rule(pcs%tri, gx, gw, px, pw)
                end if
                xi = [xi, px(1, :)]
                eta = [eta, px(2, :)]
                w = [w, pw]
                elem = [elem, spread(ci + (cj - 1)*nu, 1, size(pw))]
            end do
        end do
    end subroutine face_segment_points

    !> The face displaced by `u` as a patch (as the face master's search builds it).
    pure function displaced_patch(s, u) result(patch)
        type(contact_surface_t), intent(in) :: s
        real(dp), intent(in) :: u(:)
        type(nurbs_patch_t) :: patch
        real(dp) :: cp(3, size(s%cps))
        integer :: c
        do c = 1, 3
            cp(c, :) = s%x0(c, :) + u(s%dofs(c, :))
        end do
        patch = new_patch([s%degree, s%degree_eta], [knots_t(s%knots), knots_t(s%knots_eta)], &
                          [s%n_xi, size(s%cps)/s%n_xi], cp, s%w)
    end function displaced_patch

    !> The pieces of the slave cell [lo, hi] (knot spans `span` of `slave`) cut by the
    !> cells of the master `m` (see the module comment): triangles, or `whole`.
    pure function cell_pieces(m, u, slave, span, lo, hi) result(pcs)
        class(face_master_t), intent(in) :: m
        real(dp), intent(in) :: u(:), lo(2), hi(2)
        type(nurbs_patch_t), intent(in) :: slave
        integer, intent(in) :: span(2)
        type(cell_pieces_t) :: pcs
        real(dp), allocatable :: p(:, :, :), poly(:, :)
        real(dp) :: area, total, cell_area
        integer :: rng(2, 2), i, j, k, n_pieces
        logical :: ok, far
        pcs%whole = .true.
        allocate (pcs%tri(2, 3, 0))
        call master_range(m, u, slave, span, lo, hi, rng, far)
        if (far) return
        call mapped_nodes(m, slave, span, lo, hi, rng, p, ok)
        if (.not. ok) return
        cell_area = product(hi - lo)
        total = 0.0_dp
        n_pieces = 0
        do j = rng(1, 2), rng(2, 2)
            do i = rng(1, 1), rng(2, 1)
                poly = clip_to_rectangle(reshape([p(:, i, j), p(:, i + 1, j), p(:, i + 1, j + 1), p(:, i, j + 1)], &
                                                 [2, 4]), lo, hi)
                if (size(poly, 2) < 3) cycle
                area = signed_area(poly)
                if (abs(area) <= sliver*cell_area) cycle
                ! counterclockwise (a master whose parameters turn the other way maps mirrored)
                if (area < 0.0_dp) poly = poly(:, size(poly, 2):1:-1)
                total = total + abs(area)
                n_pieces = n_pieces + 1
                do k = 2, size(poly, 2) - 1
                    pcs%tri = reshape([pcs%tri, poly(:, 1), poly(:, k), poly(:, k + 1)], [2, 3, size(pcs%tri, 3) + 1])
                end do
            end do
        end do
        pcs%whole = n_pieces <= 1 .or. abs(total - cell_area) > tile_tol*cell_area
    end function cell_pieces

    !> The master cells [first, last] per direction `rng` [2 (first, last), 2 (u, v)]
    !> the slave cell can touch: those of the projections of 3 x 3 points of it, one
    !> more on each side, and the ghost cell (0 or the number of cells + 1) beyond a
    !> master edge that range reaches. `far`: every point is farther from the master
    !> than the points' box is wide (as the pattern's ranges count a point near): the
    !> cell keeps the tensor rule until a converged state finds it near (cutting a cell
    !> far from the master costs the mapping of every master node its wide range holds).
    pure subroutine master_range(m, u, slave, span, lo, hi, rng, far)
        class(face_master_t), intent(in) :: m
        real(dp), intent(in) :: u(:), lo(2), hi(2)
        type(nurbs_patch_t), intent(in) :: slave
        integer, intent(in) :: span(2)
        integer, intent(out) :: rng(2, 2)
        logical, intent(out) :: far
        type(master_point_t) :: mp
        real(dp) :: x(3), d1(3, 2), d2(3, 3), xlo(3), xhi(3), nearest
        integer :: a, b, c(2), n(2)
        logical :: found, converged
        n = [size(m%search%breaks_u), size(m%search%breaks_v)] - 1
        rng(1, :) = huge(1)
        rng(2, :) = -huge(1)
        xlo = huge(1.0_dp)
        xhi = -huge(1.0_dp)
        nearest = huge(1.0_dp)
        do b = 0, 2
            do a = 0, 2
                call surface_derivatives(slave, lo + 0.5_dp*[a, b]*(hi - lo), span, x, d1, d2)
                call m%project(u, x, mp, found, converged)
                c = [cell_of(m%search%breaks_u, mp%xi), cell_of(m%search%breaks_v, mp%eta)]
                rng(1, :) = min(rng(1, :), c)
                rng(2, :) = max(rng(2, :), c)
                xlo = min(xlo, x)
                xhi = max(xhi, x)
                nearest = min(nearest, norm2(x - mp%x))
            end do
        end do
        far = nearest > norm2(xhi - xlo)
        rng(1, :) = max(1, rng(1, :) - 1)
        rng(2, :) = min(n, rng(2, :) + 1)
        where (rng(1, :) == 1) rng(1, :) = 0
        where (rng(2, :) == n) rng(2, :) = n + 1
    end subroutine master_range

    !> The cell (1 .. size(breaks) - 1) holding `t` (clamped).
    pure integer function cell_of(breaks, t) result(i)
        real(dp), intent(in) :: breaks(:), t
        i = count(breaks(2:size(breaks) - 1) <= t) + 1
    end function cell_of

    !> The master nodes of the cells `rng` mapped into the slave cell's parameters
    !> [2, nodes u, nodes v] (node i: breakpoint i; 0 and n + 2: ghosts). A real node
    !> goes where the master's normal line through it meets the slave cell's surface
    !> (`line_meets_surface`); a ghost node lies beyond its edge's node, along the
    !> mapped cell's side, far enough to cover the slave cell (the same distance for
    !> all, so an affine grid stays affine). `ok`: every real node mapped.
    pure subroutine mapped_nodes(m, slave, span, lo, hi, rng, p, ok)
        class(face_master_t), intent(in) :: m
        type(nurbs_patch_t), intent(in) :: slave
        integer, intent(in) :: span(2), rng(2, 2)
        real(dp), intent(in) :: lo(2), hi(2)
        real(dp), allocatable, intent(out) :: p(:, :, :)
        logical, intent(out) :: ok
        real(dp) :: x(3), d1(3, 2), d2(3, 3), nrm(3), reach, centre(2)
        integer :: i, j, n(2), first(2), last(2)
        n = [size(m%search%breaks_u), size(m%search%breaks_v)] - 1
        allocate (p(2, rng(1, 1):rng(2, 1) + 1, rng(1, 2):rng(2, 2) + 1))
        first = max(rng(1, :), 1)
        last = min(rng(2, :) + 1, n + 1)
        centre = 0.5_dp*(lo + hi)
        reach = norm2(hi - lo)
        do j = first(2), last(2)
            do i = first(1), last(1)
                call surface_derivatives(m%search%patch, [m%search%breaks_u(i), m%search%breaks_v(j)], &
                                         [m%search%span_u(min(i, n(1))), m%search%span_v(min(j, n(2)))], x, d1, d2)
                nrm = cross(d1(:, 1), d1(:, 2))
                call line_meets_surface(slave, span, centre, x, nrm/norm2(nrm), p(:, i, j), ok)
                if (.not. ok) return
                reach = max(reach, norm2(p(:, i, j) - centre))
            end do
        end do
        reach = 10.0_dp*reach
        ! ghosts along u on the real rows, then along v on every column
        do j = first(2), last(2)
            if (rng(1, 1) == 0) p(:, 0, j) = beyond(p(:, 1, j), p(:, 2, j), reach)
            if (rng(2, 1) == n(1) + 1) p(:, n(1) + 2, j) = beyond(p(:, n(1) + 1, j), p(:, n(1), j), reach)
        end do
        do i = rng(1, 1), rng(2, 1) + 1
            if (rng(1, 2) == 0) p(:, i, 0) = beyond(p(:, i, 1), p(:, i, 2), reach)
            if (rng(2, 2) == n(2) + 1) p(:, i, n(2) + 2) = beyond(p(:, i, n(2) + 1), p(:, i, n(2)), reach)
        end do
    end subroutine mapped_nodes

    !> The point `reach` beyond `edge` on the ray from `inner` through it (`edge` if
    !> they coincide: a collapsed master edge; its ghost has no area).
    pure function beyond(edge, inner, reach) result(q)
        real(dp), intent(in) :: edge(2), inner(2), reach
        real(dp) :: q(2)
        q = edge
        if (norm2(edge - inner) > 0.0_dp) q = edge + reach*(edge - inner)/norm2(edge - inner)
    end function beyond

    !> The parameters `s` [2] where the line x + t n meets the slave cell's surface
    !> (`slave` in the knot spans `span`, continued beyond the cell), by Newton's
    !> method on S(s) - x - t n = 0 from `start`; `ok`: converged.
    pure subroutine line_meets_surface(slave, span, start, x, n, s, ok)
        type(nurbs_patch_t), intent(in) :: slave
        integer, intent(in) :: span(2)
        real(dp), intent(in) :: start(2), x(3), n(3)
        real(dp), intent(out) :: s(2)
        logical, intent(out) :: ok
        real(dp) :: y(3), d1(3, 2), d2(3, 3), f(3), det, step(3)
        integer :: it
        s = start
        ok = .false.
        do it = 1, max_newton
            call surface_derivatives(slave, s, span, y, d1, d2)
            f = y - x
            f = f - dot_product(f, n)*n
            ! the components of f across n: J = [a1, a2, -n] by Cramer's rule
            det = dot_product(cross(d1(:, 1), d1(:, 2)), -n)
            if (abs(det) <= 1.0e-14_dp*norm2(d1(:, 1))*norm2(d1(:, 2))) return
            step(1) = dot_product(cross(f, d1(:, 2)), -n)/det
            step(2) = dot_product(cross(d1(:, 1), f), -n)/det
            s = s - step(1:2)
            if (norm2(step(1:2)) <= 1.0e-14_dp*max(1.0_dp, norm2(s))) then
                ok = .true.
                return
            end if
        end do
    end subroutine line_meets_surface

    !> Make `xi`, `eta`, `w`, `elem` the pair's points: spans, slave functions (the
    !> multiplier basis), cell ranges, output records and per-point history.
    pure subroutine place_face_points(self, xi, eta, w, elem)
        class(segment_face_pair_t), intent(inout) :: self
        real(dp), intent(in) :: xi(:), eta(:), w(:)
        integer, intent(in) :: elem(:)
        integer :: n, k, e, nu, np
        n = size(xi)
        nu = size(self%slave%spans)
        np = (self%slave%degree + 1)*(self%slave%degree_eta + 1)
        self%xi = xi
        self%eta = eta
        self%w = w
        self%elem = elem
        self%span = self%slave%spans(modulo(elem - 1, nu) + 1)
        self%span_eta = self%slave%spans_eta((elem - 1)/nu + 1)
        if (allocated(self%slave_basis)) deallocate (self%slave_basis)
        allocate (self%slave_basis(np, 3, n))
        if (allocated(self%point_nodes)) deallocate (self%point_nodes, self%point_values)
        allocate (self%point_nodes(np, n), self%point_values(np, n))
        do k = 1, n
            call face_basis(self%slave, xi(k), eta(k), [self%span(k), self%span_eta(k)], self%slave_basis(:, 1, k), &
                            self%slave_basis(:, 2, k), self%slave_basis(:, 3, k))
            self%point_nodes(:, k) = face_ids(self%slave, [self%span(k), self%span_eta(k)])
            self%point_values(:, k) = self%slave_basis(:, 1, k)
        end do
        if (allocated(self%first)) deallocate (self%first)
        allocate (self%first(n_elements(self%slave) + 1))
        do e = 1, size(self%first)
            self%first(e) = count(elem < e) + 1
        end do
        if (allocated(self%out)) deallocate (self%out)
        allocate (self%out(n))
        call self%hist%resize_points(n)
    end subroutine place_face_points

    !> The points (`point_xi`, `point_eta`, `point_w`, `point_element`), then the
    !> mortar pair's history.
    pure function face_history(self) result(items)
        class(segment_face_pair_t), intent(in) :: self
        type(history_item_t), allocatable :: items(:)
        type(history_item_t) :: xi, eta, w, elem
        xi%name = 'point_xi'
        xi%values = self%xi
        eta%name = 'point_eta'
        eta%values = self%eta
        w%name = 'point_w'
        w%values = self%w
        elem%name = 'point_element'
        elem%flags = self%elem
        xi%most = self%most_points()
        eta%most = xi%most
        w%most = xi%most
        elem%most = xi%most
        items = [xi, eta, w, elem, self%hist%items(xi%most)]
    end function face_history

    !> The most points a segmentation can have: per slave cell, n_gauss^2 on each
    !> triangle, at most 6 per piece (a quadrilateral clipped to a rectangle has at
    !> most 8 vertices) and one piece per master cell and ghost.
    pure integer function face_most_points(self) result(n)
        class(segment_face_pair_t), intent(in) :: self
        real(dp) :: most
        integer :: cells
        cells = 1
        select type (m => self%master)
        class is (face_master_t)
            cells = (size(m%search%breaks_u) + 1)*(size(m%search%breaks_v) + 1)
        end select
        most = real(n_elements(self%slave), dp)*real(self%n_gauss, dp)**2*6.0_dp*real(cells, dp)
        n = int(min(most, real(huge(1)/2, dp)))
    end function face_most_points

    !> Continue on the points of `items` (checked to lie in their cells with positive
    !> weights, cells in order), then the mortar pair's history.
    pure subroutine face_set_history(self, items, error)
        class(segment_face_pair_t), intent(inout) :: self
        type(history_item_t), intent(in) :: items(:)
        type(error_t), allocatable, intent(out) :: error
        real(dp), allocatable :: xi(:), eta(:), w(:)
        integer, allocatable :: elem(:), ci(:), cj(:)
        integer :: i, n, nu
        do i = 1, size(items)
            select case (trim(items(i)%name))
            case ('point_xi')
                xi = items(i)%values
            case ('point_eta')
                eta = items(i)%values
            case ('point_w')
                w = items(i)%values
            case ('point_element')
                elem = items(i)%flags
            case default
                ! the mortar pair's fields: read by its set_history below
            end select
        end do
        if (.not. (allocated(xi) .and. allocated(eta) .and. allocated(w) .and. allocated(elem))) then
            call fatal_error(error, 'history point_xi, point_eta, point_w, point_element: missing', error_code%input)
            return
        end if
        n = size(xi)
        if (size(eta) /= n .or. size(w) /= n .or. size(elem) /= n) then
            call fatal_error(error, 'history point_xi, point_eta, point_w, point_element: different lengths', &
                             error_code%input)
            return
        end if
        if (n == 0 .or. any(elem < 1 .or. elem > n_elements(self%slave))) then
            call fatal_error(error, 'history point_element: not a cell of this slave face', error_code%input)
            return
        end if
        nu = size(self%slave%spans)
        ci = modulo(elem - 1, nu) + 1
        cj = (elem - 1)/nu + 1
        if (any(.not. (w > 0.0_dp)) .or. any(xi < self%slave%breaks(ci) .or. xi > self%slave%breaks(ci + 1)) .or. &
            any(eta < self%slave%breaks_eta(cj) .or. eta > self%slave%breaks_eta(cj + 1))) then
            call fatal_error(error, 'history point_xi, point_eta, point_w: a point outside its cell or without '// &
                             'weight', error_code%input)
            return
        end if
        if (any(elem(2:) < elem(:n - 1))) then
            call fatal_error(error, 'history point_element: points not in cell order', error_code%input)
            return
        end if
        call place_face_points(self, xi, eta, w, elem)
        call self%segment_pair_t%mortar_pair_t%set_history(items, error)
    end subroutine face_set_history

end module voiga_contact_segment_faces
