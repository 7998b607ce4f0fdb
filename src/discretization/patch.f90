!> The discretized body: refined bulk patch, optional varying-order (VO) layer,
!> global control-point numbering, elements, named boundary entities and DOF counts.
!>
!> The patch is oriented so that the contact edge is eta = 1 with xi along it.
!> With a layer, the bulk control points of the last eta row are replaced by the
!> layer's: in an element of the row touching the contact edge the functions are
!> `Nh_k(xi) M_m(eta)` (layer, degree q) and `N_i(xi) M_j(eta)`, j < m (bulk).
!> The geometry map and the weight function are unchanged (docs/theory.md).
module voiga_discretization_patch
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_nurbs_basis, only: find_span, distinct_knots
    use voiga_nurbs_curve, only: nurbs_curve_t, curve_elevate, curve_insert
    use voiga_nurbs_surface, only: nurbs_surface_t, surface_patch, surface_edge_curve, surface_reorient, &
                                   edge_index
    use voiga_nurbs_patch, only: nurbs_patch_t, patch_eval, patch_elevate, patch_insert, point_index
    use voiga_discretization_layout, only: layout_t, validate_layout, basis_linear
    implicit none
    private

    public :: discretization_t, element_t, boundary_t, new_discretization, boundary_cps, boundary_index, &
              contact_boundary, contact_name, new_knots
    !> An ascending copy of a short real vector (also the contact segments' cuts).
    public :: sorted

    !> One element (a knot-span rectangle).
    type :: element_t
        !> Element indices along xi and eta.
        integer :: ix = 0, ie = 0
        !> Knot spans in the bulk knot vectors, and in the layer's (0: not a VO element).
        integer :: span_xi = 0, span_eta = 0, span_layer = 0
        !> Parametric extent [xi_a, xi_b] and [eta_a, eta_b].
        real(dp) :: xi(2) = 0.0_dp, eta(2) = 0.0_dp
        !> Global control points of the nonzero functions, in the order of the
        !> element basis: bulk tensor products (xi fastest), then layer functions.
        integer, allocatable :: conn(:)
    end type element_t

    !> A named boundary entity of the patch: an edge of a two-dimensional patch, a
    !> face of a three-dimensional one (docs/architecture.md, "Dimension as data").
    type :: boundary_t
        character(len=32) :: name = ''
        !> The parametric direction it is normal to, and its end in that direction
        !> (0: the parameter's start, 1: its end).
        integer :: direction = 0, side = 0
        !> Global ids of the control points on it, in its parameter order.
        integer, allocatable :: cps(:)
    end type boundary_t

    !> A discretized body.
    type :: discretization_t
        !> Spatial dimension (DOFs per control point) and parametric dimension of the
        !> patch (2 and 2: a plane body).
        integer :: nsd = 2, pdim = 2
        !> Refined bulk patch (for L1: the degree-1 patch), of parametric dimension
        !> `pdim`.
        type(nurbs_patch_t) :: bulk
        !> Is there a VO layer on the contact edge?
        logical :: has_layer = .false.
        !> The layer curve (degree q), valid when `has_layer`.
        type(nurbs_curve_t) :: layer
        !> Does the body have a contact edge (at eta = 1)?
        logical :: has_contact = .false.
        !> Number of control points.
        integer :: ncp = 0
        !> Reference control points, shape [2, ncp], and weights [ncp].
        real(dp), allocatable :: x(:, :), w(:)
        !> Global id of bulk control point (i, j), shape [n_xi, n_eta]; 0 where the
        !> layer replaces it.
        integer, allocatable :: bulk_id(:, :)
        !> Global ids of the layer control points, shape [n_layer].
        integer, allocatable :: layer_id(:)
        !> Elements per direction and in total.
        integer :: nel_xi = 0, nel_eta = 0, nel = 0
        type(element_t), allocatable :: elements(:)
        !> The boundary entities [2 pdim], direction by direction, the start before the
        !> end: xi0, xi1, eta0, eta1 (after re-orientation; the contact edge, if any,
        !> is the last: `contact_boundary`).
        type(boundary_t), allocatable :: boundaries(:)
        !> DOF counts (`nsd` per control point): on the contact edge, the rest, all.
        integer :: interface_dofs = 0, bulk_dofs = 0, total_dofs = 0
    end type discretization_t

    !> Knots closer than this (in the unit parameter range) are the same knot.
    real(dp), parameter :: knot_tol = 1.0e-12_dp

contains

    !> Build the discretization of `coarse` (an exact patch) with `layout`.
    !> `where` prefixes error messages (e.g. "case.nml: &body 'die': ").
    subroutine new_discretization(self, coarse, layout, where, error)
        type(discretization_t), intent(out) :: self
        type(nurbs_surface_t), intent(in) :: coarse
        type(layout_t), intent(in) :: layout
        character(len=*), intent(in) :: where
        type(error_t), allocatable, intent(out) :: error
        type(nurbs_surface_t) :: oriented, linear
        real(dp), allocatable :: new_xi(:), new_eta(:)
        integer :: edge

        call validate_layout(layout, where, error)
        if (allocated(error)) return
        oriented = coarse
        if (len_trim(layout%contact_edge) > 0) then
            edge = edge_index(coarse, layout%contact_edge)
            if (edge == 0) then
                call fatal_error(error, where//"contact_edge = '"//trim(layout%contact_edge)// &
                                 "' is not an edge of this body (edges: "//edge_list(coarse)//')', &
                                 error_code%input)
                return
            end if
            call surface_reorient(oriented, edge)
            self%has_contact = .true.
        end if
        new_xi = new_knots(oriented%knots_xi, layout%nel(1), layout%knots_xi)
        new_eta = new_knots(oriented%knots_eta, layout%nel(2), layout%knots_eta)

        if (trim(layout%basis) == basis_linear) then
            call build_linear(linear, oriented, new_xi, new_eta)
            self%bulk = surface_patch(linear)
        else
            if (layout%degree(1) < oriented%degree(1) .or. layout%degree(2) < oriented%degree(2)) then
                call fatal_error(error, where//'degree_xi/degree_eta must be >= the degree of the '// &
                                 'exact geometry (along the contact edge first)', error_code%input)
                return
            end if
            self%bulk = surface_patch(oriented)
            ! k-refinement: elevate first, then insert the new knots once
            call patch_elevate(self%bulk, 1, layout%degree(1) - oriented%degree(1))
            call patch_elevate(self%bulk, 2, layout%degree(2) - oriented%degree(2))
            call patch_insert(self%bulk, 1, new_xi)
            call patch_insert(self%bulk, 2, new_eta)
            if (layout%layer_degree > 0) then
                self%has_layer = .true.
                self%layer = surface_edge_curve(oriented, 4)
                call curve_elevate(self%layer, layout%layer_degree - self%layer%degree)
                call curve_insert(self%layer, new_xi)
                call curve_elevate(self%layer, layout%layer_elevations)
            end if
        end if
        call number_control_points(self)
        call build_elements(self)
        call build_boundaries(self, oriented%edge_names)
        self%total_dofs = self%nsd*self%ncp
        if (self%has_contact) self%interface_dofs = self%nsd*size(self%boundaries(contact_boundary(self))%cps)
        self%bulk_dofs = self%total_dofs - self%interface_dofs
    end subroutine new_discretization

    !> Comma-separated edge names of a patch.
    pure function edge_list(surf) result(list)
        type(nurbs_surface_t), intent(in) :: surf
        character(len=:), allocatable :: list
        integer :: i
        list = ''
        do i = 1, 4
            list = list//"'"//trim(surf%edge_names(i))//"'"
            if (i < 4) list = list//', '
        end do
    end function edge_list

    !> The interior knots to insert: explicit ones, or i/nel, minus existing knots.
    pure function new_knots(existing, nel, explicit) result(values)
        real(dp), intent(in) :: existing(:)
        integer, intent(in) :: nel
        real(dp), allocatable, intent(in) :: explicit(:)
        real(dp), allocatable :: values(:), candidates(:)
        logical, allocatable :: keep(:)
        integer :: i
        real(dp) :: a, b

        a = existing(1)
        b = existing(size(existing))
        if (allocated(explicit)) then
            candidates = a + (b - a)*explicit
        else
            candidates = [(a + (b - a)*real(i, dp)/real(nel, dp), i=1, nel - 1)]
        end if
        allocate (keep(size(candidates)))
        do i = 1, size(candidates)
            keep(i) = all(abs(existing - candidates(i)) > knot_tol)
        end do
        values = pack(candidates, keep)
    end function new_knots

    !> L1: degree-1 patch through the exact geometry at the breakpoint grid.
    pure subroutine build_linear(lin, exact, new_xi, new_eta)
        type(nurbs_surface_t), intent(out) :: lin
        type(nurbs_surface_t), intent(in) :: exact
        real(dp), intent(in) :: new_xi(:), new_eta(:)
        real(dp), allocatable :: bx(:), be(:)
        integer :: i, j
        type(nurbs_patch_t) :: patch

        patch = surface_patch(exact)
        bx = sorted([distinct_knots(exact%knots_xi), new_xi])
        be = sorted([distinct_knots(exact%knots_eta), new_eta])
        lin%degree = [1, 1]
        lin%knots_xi = [bx(1), bx, bx(size(bx))]
        lin%knots_eta = [be(1), be, be(size(be))]
        lin%edge_names = exact%edge_names
        allocate (lin%cp(2, size(bx), size(be)), lin%w(size(bx), size(be)))
        lin%w = 1.0_dp
        do j = 1, size(be)
            do i = 1, size(bx)
                call patch_eval(patch, [bx(i), be(j)], lin%cp(:, i, j))
            end do
        end do
    end subroutine build_linear

    !> Insertion sort (short arrays).
    pure function sorted(values) result(s)
        real(dp), intent(in) :: values(:)
        real(dp) :: s(size(values)), v
        integer :: i, j
        s = values
        do i = 2, size(s)
            v = s(i)
            j = i - 1
            do while (j >= 1)
                if (s(j) <= v) exit
                s(j + 1) = s(j)
                j = j - 1
            end do
            s(j + 1) = v
        end do
    end function sorted

    !> Bulk control points row by row (xi fastest); with a layer, its control
    !> points replace the last row and are numbered after the bulk.
    pure subroutine number_control_points(self)
        type(discretization_t), intent(inout) :: self
        integer :: nx, ny, nrow, i, j, id, k

        nx = self%bulk%n(1)
        ny = self%bulk%n(2)
        nrow = merge(ny - 1, ny, self%has_layer)
        allocate (self%bulk_id(nx, ny))
        self%bulk_id = 0
        id = 0
        do j = 1, nrow
            do i = 1, nx
                id = id + 1
                self%bulk_id(i, j) = id
            end do
        end do
        if (self%has_layer) then
            allocate (self%layer_id(size(self%layer%w)))
            do k = 1, size(self%layer_id)
                id = id + 1
                self%layer_id(k) = id
            end do
        else
            allocate (self%layer_id(0))
        end if
        self%ncp = id
        allocate (self%x(2, id), self%w(id))
        do j = 1, nrow
            do i = 1, nx
                self%x(:, self%bulk_id(i, j)) = self%bulk%cp(:, point_index(self%bulk, [i, j]))
                self%w(self%bulk_id(i, j)) = self%bulk%w(point_index(self%bulk, [i, j]))
            end do
        end do
        do k = 1, size(self%layer_id)
            self%x(:, self%layer_id(k)) = self%layer%cp(:, k)
            self%w(self%layer_id(k)) = self%layer%w(k)
        end do
    end subroutine number_control_points

    !> One element per nonempty knot-span rectangle; the last eta row is VO when
    !> there is a layer.
    pure subroutine build_elements(self)
        type(discretization_t), intent(inout) :: self
        real(dp), allocatable :: bx(:), be(:)
        integer :: ix, ie, e, p, q, ql, i, j, a, sx, se, sl
        real(dp) :: xm, em

        bx = distinct_knots(self%bulk%knots(1)%u)
        be = distinct_knots(self%bulk%knots(2)%u)
        self%nel_xi = size(bx) - 1
        self%nel_eta = size(be) - 1
        self%nel = self%nel_xi*self%nel_eta
        p = self%bulk%degree(1)
        q = self%bulk%degree(2)
        ql = self%layer%degree
        allocate (self%elements(self%nel))
        e = 0
        do ie = 1, self%nel_eta
            do ix = 1, self%nel_xi
                e = e + 1
                xm = 0.5_dp*(bx(ix) + bx(ix + 1))
                em = 0.5_dp*(be(ie) + be(ie + 1))
                sx = find_span(self%bulk%knots(1)%u, p, xm)
                se = find_span(self%bulk%knots(2)%u, q, em)
                associate (el => self%elements(e))
                    el%ix = ix
                    el%ie = ie
                    el%xi = bx(ix:ix + 1)
                    el%eta = be(ie:ie + 1)
                    el%span_xi = sx
                    el%span_eta = se
                    if (self%has_layer .and. ie == self%nel_eta) then
                        sl = find_span(self%layer%knots, ql, xm)
                        el%span_layer = sl
                        allocate (el%conn((p + 1)*q + ql + 1))
                        a = 0
                        do j = 1, q
                            do i = 1, p + 1
                                a = a + 1
                                el%conn(a) = self%bulk_id(sx - p + i - 1, se - q + j - 1)
                            end do
                        end do
                        el%conn(a + 1:) = self%layer_id(sl - ql:sl)
                    else
                        allocate (el%conn((p + 1)*(q + 1)))
                        a = 0
                        do j = 1, q + 1
                            do i = 1, p + 1
                                a = a + 1
                                el%conn(a) = self%bulk_id(sx - p + i - 1, se - q + j - 1)
                            end do
                        end do
                    end if
                end associate
            end do
        end do
    end subroutine build_elements

    !> The boundary entities of the plane patch, its four edges (names from the
    !> oriented patch), and their control points.
    pure subroutine build_boundaries(self, names)
        type(discretization_t), intent(inout) :: self
        !> The names of the oriented patch's edges, xi0, xi1, eta0, eta1.
        character(len=*), intent(in) :: names(:)
        integer :: nx, ny, nl, k

        nx = size(self%bulk_id, 1)
        ny = size(self%bulk_id, 2)
        allocate (self%boundaries(2*self%pdim))
        do k = 1, size(self%boundaries)
            self%boundaries(k)%name = names(k)
            self%boundaries(k)%direction = (k + 1)/2
            self%boundaries(k)%side = 1 - mod(k, 2)
        end do
        associate (b => self%boundaries)
            if (self%has_layer) then
                nl = size(self%layer_id)
                b(1)%cps = [self%bulk_id(1, 1:ny - 1), self%layer_id(1)]
                b(2)%cps = [self%bulk_id(nx, 1:ny - 1), self%layer_id(nl)]
                b(4)%cps = self%layer_id
            else
                b(1)%cps = self%bulk_id(1, :)
                b(2)%cps = self%bulk_id(nx, :)
                b(4)%cps = self%bulk_id(:, ny)
            end if
            b(3)%cps = self%bulk_id(:, 1)
        end associate
    end subroutine build_boundaries

    !> The index in `boundaries` of the contact edge or face: the end of the last
    !> parametric direction (the patch is oriented so).
    pure integer function contact_boundary(self)
        type(discretization_t), intent(in) :: self
        contact_boundary = 2*self%pdim
    end function contact_boundary

    !> The name of the contact edge or face (as the case file knows it).
    pure function contact_name(self) result(name)
        type(discretization_t), intent(in) :: self
        character(len=:), allocatable :: name
        name = trim(self%boundaries(contact_boundary(self))%name)
    end function contact_name

    !> The index in `boundaries` of the entity called `name`, 0 if there is none.
    pure integer function boundary_index(self, name)
        type(discretization_t), intent(in) :: self
        character(len=*), intent(in) :: name
        integer :: i
        boundary_index = 0
        do i = 1, size(self%boundaries)
            if (trim(self%boundaries(i)%name) == trim(name)) boundary_index = i
        end do
    end function boundary_index

    !> Control points of the boundary entity called `name`; error if there is none.
    subroutine boundary_cps(self, name, cps, error)
        type(discretization_t), intent(in) :: self
        character(len=*), intent(in) :: name
        integer, allocatable, intent(out) :: cps(:)
        type(error_t), allocatable, intent(out) :: error
        integer :: i
        i = boundary_index(self, name)
        if (i == 0) then
            call fatal_error(error, "no edge named '"//trim(name)//"'", error_code%input)
            return
        end if
        cps = self%boundaries(i)%cps
    end subroutine boundary_cps

end module voiga_discretization_patch
