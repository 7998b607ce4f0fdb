!> The discretized body: refined bulk patch, optional varying-order (VO) layer,
!> global control-point numbering, elements, named boundary entities and DOF counts,
!> for a plane patch (pdim 2) or a volume (pdim 3) alike.
!>
!> The patch is oriented so that the contact boundary (an edge, or a face) is the
!> end of the last parametric direction, u_pdim = 1 (`patch_orient`). With a layer,
!> the bulk control points on that boundary are replaced by the layer's: in an
!> element touching it the functions are `Nh_k(u') M_m(u_pdim)` (layer of degree q
!> in the boundary's directions u', the bulk's last function M_m across) and the
!> bulk's products with M_j, j < m. The geometry map and the weight function are
!> unchanged (docs/theory.md; the 3D meaning of Np, NNp, NNp.k: docs/formats.md).
module voiga_discretization_patch
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_nurbs_basis, only: find_span, distinct_knots
    use voiga_nurbs_surface, only: nurbs_surface_t, surface_patch
    use voiga_nurbs_patch, only: nurbs_patch_t, knots_t, patch_eval, patch_elevate, patch_insert, point_index, &
                                 patch_boundary, patch_orient, oriented_names, next_index
    use voiga_discretization_layout, only: layout_t, validate_layout, basis_linear, direction_names, &
                                           knot_list
    implicit none
    private

    public :: discretization_t, element_t, boundary_t, new_discretization, boundary_cps, boundary_index, &
              contact_boundary, contact_name, new_knots, orient_for_contact, &
              boundary_word
    !> An ascending copy of a short real vector (also the contact segments' cuts).
    public :: sorted

    !> One element (a knot-span rectangle, or box).
    type :: element_t
        !> Element indices per direction.
        integer :: index(3) = 0
        !> Knot spans in the bulk knot vectors, per direction.
        integer :: span(3) = 0
        !> Knot spans in the layer's knot vectors (its pdim - 1 directions); 0 in an
        !> element that is not a VO element.
        integer :: span_layer(2) = 0
        !> Parametric extent [lo(d), hi(d)] per direction.
        real(dp) :: lo(3) = 0.0_dp, hi(3) = 0.0_dp
        !> Global control points of the nonzero functions, in the order of the
        !> element basis: bulk tensor products (direction 1 fastest), then layer
        !> functions (direction 1 fastest).
        integer, allocatable :: conn(:)
    end type element_t

    !> A named boundary entity of the patch: an edge of a two-dimensional patch, a
    !> face of a three-dimensional one (docs/architecture.md, "Dimension as data").
    type :: boundary_t
        character(len=32) :: name = ''
        !> The parametric direction it is normal to, and its end in that direction
        !> (0: the parameter's start, 1: its end).
        integer :: direction = 0, side = 0
        !> Global ids of the control points on it: the bulk's in the patch's order,
        !> then the layer's.
        integer, allocatable :: cps(:)
    end type boundary_t

    !> A discretized body.
    type :: discretization_t
        !> Spatial dimension (DOFs per control point) and parametric dimension of the
        !> patch (2 and 2: a plane body; 3 and 3: a solid).
        integer :: nsd = 2, pdim = 2
        !> Refined bulk patch (for L1: the degree-1 patch), of parametric dimension
        !> `pdim`.
        type(nurbs_patch_t) :: bulk
        !> Is there a VO layer on the contact boundary?
        logical :: has_layer = .false.
        !> The layer (degree q; a curve for a plane body, a surface for a solid, with
        !> the bulk's first pdim - 1 directions), valid when `has_layer`.
        type(nurbs_patch_t) :: layer
        !> Does the body have a contact boundary (at u_pdim = 1)?
        logical :: has_contact = .false.
        !> Number of control points.
        integer :: ncp = 0
        !> Reference control points, shape [nsd, ncp], and weights [ncp].
        real(dp), allocatable :: x(:, :), w(:)
        !> Global id of every bulk control point (flat, `point_index`); 0 where the
        !> layer replaces it. Bulk points are numbered first, in this order.
        integer, allocatable :: bulk_id(:)
        !> Global ids of the layer control points (flat, in the layer's order).
        integer, allocatable :: layer_id(:)
        !> Elements per direction (1 beyond pdim) and in total.
        integer :: nels(3) = 1, nel = 0
        type(element_t), allocatable :: elements(:)
        !> The boundary entities [2 pdim], direction by direction, the start before the
        !> end: xi0, xi1, eta0, eta1 (, zeta0, zeta1) after orientation; the contact
        !> boundary, if any, is the last (`contact_boundary`).
        type(boundary_t), allocatable :: boundaries(:)
        !> DOF counts (`nsd` per control point): on the contact boundary, the rest, all.
        integer :: interface_dofs = 0, bulk_dofs = 0, total_dofs = 0
    end type discretization_t

    !> Build a discretization from a plane patch (`nurbs_surface_t`, its edge names
    !> with it) or from any patch and its boundary names.
    interface new_discretization
        module procedure new_discretization_surface, new_discretization_patch
    end interface new_discretization

    !> Knots closer than this (in the unit parameter range) are the same knot.
    real(dp), parameter :: knot_tol = 1.0e-12_dp

contains

    !> Build the discretization of the plane patch `coarse` (exact) with `layout`.
    !> `where` prefixes error messages (e.g. "case.nml: &body 'die': ").
    subroutine new_discretization_surface(self, coarse, layout, where, error)
        type(discretization_t), intent(out) :: self
        type(nurbs_surface_t), intent(in) :: coarse
        type(layout_t), intent(in) :: layout
        character(len=*), intent(in) :: where
        type(error_t), allocatable, intent(out) :: error
        call new_discretization_patch(self, surface_patch(coarse), coarse%edge_names, layout, where, error)
    end subroutine new_discretization_surface

    !> Build the discretization of `coarse` (an exact patch, pdim 2 or 3, nsd = pdim)
    !> whose boundaries are called `names` [2 pdim] with `layout`.
    subroutine new_discretization_patch(self, coarse, names, layout, where, error)
        type(discretization_t), intent(out) :: self
        type(nurbs_patch_t), intent(in) :: coarse
        character(len=*), intent(in) :: names(:)
        type(layout_t), intent(in) :: layout
        character(len=*), intent(in) :: where
        type(error_t), allocatable, intent(out) :: error
        type(nurbs_patch_t) :: oriented
        character(len=32) :: oriented_as(size(names))
        type(knots_t) :: inserted(coarse%pdim)
        real(dp), allocatable :: explicit(:)
        integer :: d, nd

        nd = coarse%pdim
        self%pdim = nd
        self%nsd = coarse%nsd
        call validate_layout(layout, nd, where, error)
        if (allocated(error)) return
        call orient_for_contact(coarse, names, layout%contact_edge, oriented, oriented_as, self%has_contact)
        if (len_trim(layout%contact_edge) > 0 .and. .not. self%has_contact) then
            call fatal_error(error, where//trim(contact_key(nd))//" = '"//trim(layout%contact_edge)// &
                             "' is not "//article(nd)//' of this body ('//boundary_word(nd)//'s: '// &
                             name_list(names)//')', error_code%input)
            return
        end if
        do d = 1, nd
            call knot_list(layout, d, explicit)
            inserted(d)%u = new_knots(oriented%knots(d)%u, layout%nel(d), explicit)
        end do
        if (trim(layout%basis) == basis_linear) then
            self%bulk = linear_patch(oriented, inserted)
        else
            if (any(layout%degree(:nd) < oriented%degree)) then
                call fatal_error(error, where//degree_keys(nd)//' must be >= the degree of the exact '// &
                                 'geometry (along the contact '//boundary_word(nd)//' first)', error_code%input)
                return
            end if
            self%bulk = oriented
            ! k-refinement: elevate first, then insert the new knots once
            do d = 1, nd
                call patch_elevate(self%bulk, d, layout%degree(d) - oriented%degree(d))
            end do
            do d = 1, nd
                call patch_insert(self%bulk, d, inserted(d)%u)
            end do
            if (layout%layer_degree > 0) call build_layer(self, oriented, inserted, layout)
        end if
        call number_control_points(self)
        call build_elements(self)
        call build_boundaries(self, oriented_as)
        self%total_dofs = self%nsd*self%ncp
        if (self%has_contact) self%interface_dofs = self%nsd*size(self%boundaries(contact_boundary(self))%cps)
        self%bulk_dofs = self%total_dofs - self%interface_dofs
    end subroutine new_discretization_patch

    !> `coarse` oriented so that the boundary called `contact` is the end of the
    !> last direction (`found`: there is one; `contact` empty: unchanged), and the
    !> names of the oriented patch's boundaries.
    pure subroutine orient_for_contact(coarse, names, contact, oriented, oriented_as, found)
        type(nurbs_patch_t), intent(in) :: coarse
        character(len=*), intent(in) :: names(:), contact
        type(nurbs_patch_t), intent(out) :: oriented
        character(len=*), intent(out) :: oriented_as(:)
        logical, intent(out) :: found
        integer :: perm(coarse%pdim), k
        logical :: flip(coarse%pdim)
        oriented = coarse
        oriented_as = names
        found = .false.
        if (len_trim(contact) == 0) return
        do k = 1, size(names)
            if (trim(names(k)) == trim(contact)) then
                found = .true.
                if (k == size(names)) return
                call patch_orient(coarse, (k + 1)/2, 1 - mod(k, 2), oriented, perm, flip)
                oriented_as = oriented_names(names, perm, flip)
                return
            end if
        end do
    end subroutine orient_for_contact

    !> What a boundary of a patch of parametric dimension `nd` is: 'edge' or 'face'
    !> (the word every message about a body's boundaries uses).
    pure function boundary_word(nd) result(word)
        integer, intent(in) :: nd
        character(len=4) :: word
        word = merge('edge', 'face', nd == 2)
    end function boundary_word

    !> 'an edge' or 'a face'.
    pure function article(nd) result(words)
        integer, intent(in) :: nd
        character(len=:), allocatable :: words
        words = merge('an', 'a ', nd == 2)
        words = trim(words)//' '//boundary_word(nd)
    end function article

    !> The layout's key for the contact boundary of a body of parametric dimension `nd`.
    pure function contact_key(nd) result(key)
        integer, intent(in) :: nd
        character(len=12) :: key
        key = merge('contact_edge', 'contact_face', nd == 2)
    end function contact_key

    !> 'degree_xi/degree_eta' (and '/degree_zeta' for a solid).
    pure function degree_keys(nd) result(keys)
        integer, intent(in) :: nd
        character(len=:), allocatable :: keys
        integer :: d
        keys = 'degree_xi'
        do d = 2, nd
            keys = keys//'/degree_'//trim(direction_names(d))
        end do
    end function degree_keys

    !> Comma-separated, quoted boundary names.
    pure function name_list(names) result(list)
        character(len=*), intent(in) :: names(:)
        character(len=:), allocatable :: list
        integer :: i
        list = ''
        do i = 1, size(names)
            list = list//"'"//trim(names(i))//"'"
            if (i < size(names)) list = list//', '
        end do
    end function name_list

    !> The VO layer: the contact boundary of the oriented exact patch, elevated to
    !> the layer degree in each of its directions, the bulk's new knots inserted,
    !> then `layer_elevations` more elevations (NNq.k).
    pure subroutine build_layer(self, oriented, inserted, layout)
        type(discretization_t), intent(inout) :: self
        type(nurbs_patch_t), intent(in) :: oriented
        type(knots_t), intent(in) :: inserted(:)
        type(layout_t), intent(in) :: layout
        integer :: d
        self%has_layer = .true.
        self%layer = patch_boundary(oriented, self%pdim, 1)
        do d = 1, self%layer%pdim
            call patch_elevate(self%layer, d, layout%layer_degree - self%layer%degree(d))
            call patch_insert(self%layer, d, inserted(d)%u)
            call patch_elevate(self%layer, d, layout%layer_elevations)
        end do
    end subroutine build_layer

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
    pure function linear_patch(exact, inserted) result(lin)
        type(nurbs_patch_t), intent(in) :: exact
        type(knots_t), intent(in) :: inserted(:)
        type(nurbs_patch_t) :: lin
        type(knots_t) :: breaks(exact%pdim)
        integer :: d, k, idx(exact%pdim)

        lin%pdim = exact%pdim
        lin%nsd = exact%nsd
        lin%degree = [(1, d=1, exact%pdim)]
        allocate (lin%n(exact%pdim), lin%knots(exact%pdim))
        do d = 1, exact%pdim
            breaks(d)%u = sorted([distinct_knots(exact%knots(d)%u), inserted(d)%u])
            associate (b => breaks(d)%u)
                lin%knots(d)%u = [b(1), b, b(size(b))]
                lin%n(d) = size(b)
            end associate
        end do
        allocate (lin%cp(exact%nsd, product(lin%n)), lin%w(product(lin%n)))
        lin%w = 1.0_dp
        idx = 1
        do k = 1, product(lin%n)
            call patch_eval(exact, [(breaks(d)%u(idx(d)), d=1, exact%pdim)], lin%cp(:, k))
            call next_index(idx, lin%n)
        end do
    end function linear_patch

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

    !> Bulk control points in the patch's order (direction 1 fastest); with a
    !> layer, its control points replace those on the contact boundary (the last
    !> of the flat order: the last direction is the slowest) and are numbered
    !> after the bulk's.
    pure subroutine number_control_points(self)
        type(discretization_t), intent(inout) :: self
        integer :: nb, nface, id, k

        nb = size(self%bulk%w)
        nface = merge(nb/self%bulk%n(self%pdim), 0, self%has_layer)
        allocate (self%bulk_id(nb))
        self%bulk_id = 0
        do k = 1, nb - nface
            self%bulk_id(k) = k
        end do
        id = nb - nface
        if (self%has_layer) then
            self%layer_id = [(id + k, k=1, size(self%layer%w))]
            id = id + size(self%layer%w)
        else
            allocate (self%layer_id(0))
        end if
        self%ncp = id
        allocate (self%x(self%nsd, id), self%w(id))
        do k = 1, nb - nface
            self%x(:, k) = self%bulk%cp(:, k)
            self%w(k) = self%bulk%w(k)
        end do
        do k = 1, size(self%layer_id)
            self%x(:, self%layer_id(k)) = self%layer%cp(:, k)
            self%w(self%layer_id(k)) = self%layer%w(k)
        end do
    end subroutine number_control_points

    !> One element per nonempty knot-span box (direction 1 fastest); the last layer
    !> of elements across the contact boundary is VO when there is a layer.
    pure subroutine build_elements(self)
        type(discretization_t), intent(inout) :: self
        type(knots_t) :: breaks(self%pdim)
        integer :: idx(self%pdim), d, e, nd

        nd = self%pdim
        do d = 1, nd
            breaks(d)%u = distinct_knots(self%bulk%knots(d)%u)
            self%nels(d) = size(breaks(d)%u) - 1
        end do
        self%nel = product(self%nels(:nd))
        allocate (self%elements(self%nel))
        idx = 1
        do e = 1, self%nel
            associate (el => self%elements(e))
                el%index(:nd) = idx
                do d = 1, nd
                    el%lo(d) = breaks(d)%u(idx(d))
                    el%hi(d) = breaks(d)%u(idx(d) + 1)
                    el%span(d) = find_span(self%bulk%knots(d)%u, self%bulk%degree(d), 0.5_dp*(el%lo(d) + el%hi(d)))
                end do
                if (self%has_layer .and. idx(nd) == self%nels(nd)) then
                    do d = 1, nd - 1
                        el%span_layer(d) = find_span(self%layer%knots(d)%u, self%layer%degree(d), &
                                                     0.5_dp*(el%lo(d) + el%hi(d)))
                    end do
                end if
                el%conn = element_connectivity(self, el)
            end associate
            call next_index(idx, self%nels(:nd))
        end do
    end subroutine build_elements

    !> The global control points of element `el`'s functions: the bulk's tensor
    !> products (in a VO element without the last function across the contact
    !> boundary), then the layer's.
    pure function element_connectivity(self, el) result(conn)
        type(discretization_t), intent(in) :: self
        type(element_t), intent(in) :: el
        integer, allocatable :: conn(:)
        integer :: counts(self%pdim), local(self%pdim), nd, nb, nl, a
        logical :: vo

        nd = self%pdim
        vo = el%span_layer(1) > 0
        counts = self%bulk%degree + 1
        if (vo) counts(nd) = counts(nd) - 1
        nb = product(counts)
        nl = 0
        if (vo) nl = product(self%layer%degree + 1)
        allocate (conn(nb + nl))
        local = 1
        do a = 1, nb
            conn(a) = self%bulk_id(point_index(self%bulk, el%span(:nd) - self%bulk%degree + local - 1))
            call next_index(local, counts)
        end do
        if (.not. vo) return
        local(:nd - 1) = 1
        do a = 1, nl
            conn(nb + a) = self%layer_id(point_index(self%layer, el%span_layer(:nd - 1) - self%layer%degree + &
                                                     local(:nd - 1) - 1))
            call next_index(local(:nd - 1), self%layer%degree + 1)
        end do
    end function element_connectivity

    !> The boundary entities of the patch (names from the oriented patch) and their
    !> control points: the bulk's on it in the patch's order, then the layer's on it
    !> (all of them on the contact boundary; the layer's own boundary row on a side).
    pure subroutine build_boundaries(self, names)
        type(discretization_t), intent(inout) :: self
        !> The names of the oriented patch's boundaries, direction by direction.
        character(len=*), intent(in) :: names(:)
        integer :: k, dir, end_index
        allocate (self%boundaries(2*self%pdim))
        do k = 1, size(self%boundaries)
            associate (b => self%boundaries(k))
                b%name = names(k)
                b%direction = (k + 1)/2
                b%side = 1 - mod(k, 2)
                dir = b%direction
                end_index = merge(self%bulk%n(dir), 1, b%side == 1)
                b%cps = on_boundary(self%bulk, self%bulk_id, dir, end_index)
                if (self%has_layer) then
                    if (dir < self%pdim) then
                        end_index = merge(self%layer%n(dir), 1, b%side == 1)
                        b%cps = [b%cps, on_boundary(self%layer, self%layer_id, dir, end_index)]
                    else if (b%side == 1) then
                        b%cps = [b%cps, self%layer_id]
                    end if
                end if
            end associate
        end do
    end subroutine build_boundaries

    !> The nonzero `ids` of the points of `patch` whose index along `dir` is `at`,
    !> in the patch's order.
    pure function on_boundary(patch, ids, dir, at) result(cps)
        type(nurbs_patch_t), intent(in) :: patch
        integer, intent(in) :: ids(:), dir, at
        integer, allocatable :: cps(:)
        integer :: idx(patch%pdim), k
        logical :: keep(size(ids))
        idx = 1
        do k = 1, size(ids)
            keep(k) = idx(dir) == at .and. ids(k) > 0
            call next_index(idx, patch%n)
        end do
        cps = pack(ids, keep)
    end function on_boundary

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
            call fatal_error(error, 'no '//boundary_word(self%pdim)//" named '"//trim(name)//"'", error_code%input)
            return
        end if
        cps = self%boundaries(i)%cps
    end subroutine boundary_cps

end module voiga_discretization_patch
