!> The size of a body's discretization, counted from its coarse patch and its
!> layout without building it: control points, elements and the entries of the
!> element stiffness matrices. The run checks these against the memory it may
!> use, and against the range of the default integers that number DOFs and
!> matrix entries, before anything of that size is allocated (64-bit counts:
!> `nel_xi = nel_eta = 100000` gives 10^10 elements, which must be refused, not
!> overflow).
module voiga_discretization_size
    use, intrinsic :: iso_fortran_env, only: int64
    use voiga_kinds, only: dp
    use voiga_nurbs_basis, only: distinct_knots, multiplicity
    use voiga_nurbs_patch, only: nurbs_patch_t
    use voiga_discretization_layout, only: layout_t, basis_linear, knot_list
    use voiga_discretization_patch, only: discretization_t, new_knots, orient_for_contact
    implicit none
    private

    public :: body_size_t, body_size, discretization_size

    !> Counts of one discretized body.
    type :: body_size_t
        !> Control points (nsd DOFs each) and elements.
        integer(int64) :: ncp = 0, nel = 0
        !> Spatial dimension (DOFs per control point).
        integer :: nsd = 2
        !> Sum over the elements of (nsd x control points of the element)^2: the
        !> entries of all element stiffness matrices, the size of the assembly map.
        integer(int64) :: entries = 0
    end type body_size_t

contains

    !> The counts `new_discretization` would give `coarse` (boundaries `names`) with
    !> `layout` (the layout is assumed valid: `validate_layout`; a contact name
    !> that is not a boundary leaves the patch as it is; degrees below the
    !> geometry's count as the geometry's).
    pure function body_size(coarse, names, layout) result(counts)
        type(nurbs_patch_t), intent(in) :: coarse
        character(len=*), intent(in) :: names(:)
        type(layout_t), intent(in) :: layout
        type(body_size_t) :: counts
        type(nurbs_patch_t) :: oriented
        character(len=32) :: oriented_as(size(names))
        integer(int64) :: n(coarse%pdim), spans(coarse%pdim), n_layer, nen, nen_vo, nface, nsd
        real(dp), allocatable :: explicit(:)
        integer :: p(coarse%pdim), d, nd
        logical :: found

        nd = coarse%pdim
        nsd = coarse%nsd
        call orient_for_contact(coarse, names, layout%contact_edge, oriented, oriented_as, found)
        do d = 1, nd
            if (trim(layout%basis) == basis_linear) then
                p(d) = 1
            else
                p(d) = max(layout%degree(d), oriented%degree(d))
            end if
            call knot_list(layout, d, explicit)
            call direction(oriented%knots(d)%u, oriented%degree(d), p(d), layout%nel(d), explicit, &
                           trim(layout%basis) == basis_linear, n(d), spans(d))
        end do
        counts%nsd = coarse%nsd
        counts%ncp = product(n)
        counts%nel = product(spans)
        nen = product(int(p + 1, int64))
        counts%entries = counts%nel*(nsd*nen)**2
        if (layout%layer_degree > 0 .and. trim(layout%basis) /= basis_linear) then
            ! the layer replaces the bulk's points on the contact boundary; its
            ! elements (one layer of spans across) have the layer's functions instead
            ! of the bulk's last row
            nface = counts%ncp/n(nd)
            n_layer = 1
            do d = 1, nd - 1
                call knot_list(layout, d, explicit)
                n_layer = n_layer*layer_functions(oriented%knots(d)%u, oriented%degree(d), layout, d, explicit)
            end do
            counts%ncp = counts%ncp - nface + n_layer
            nen_vo = nen/(p(nd) + 1)*p(nd) + int(layout%layer_degree + layout%layer_elevations + 1, int64)**(nd - 1)
            counts%entries = counts%entries + counts%nel/spans(nd)*((nsd*nen_vo)**2 - (nsd*nen)**2)
        end if
    end function body_size

    !> The counts of a built discretization (the same as `body_size` gave before it
    !> was built).
    pure function discretization_size(disc) result(counts)
        type(discretization_t), intent(in) :: disc
        type(body_size_t) :: counts
        integer :: e
        counts%nsd = disc%nsd
        counts%ncp = disc%ncp
        counts%nel = disc%nel
        do e = 1, disc%nel
            counts%entries = counts%entries + (int(disc%nsd, int64)*size(disc%elements(e)%conn))**2
        end do
    end function discretization_size

    !> Functions `n_dir` and element spans along one direction of knots `knots`
    !> (degree `pc`) at degree `deg`, `nel` uniform elements or the `explicit` knots.
    pure subroutine direction(knots, pc, deg, nel, explicit, linear, n_dir, spans_dir)
        real(dp), intent(in) :: knots(:)
        integer, intent(in) :: pc, deg, nel
        real(dp), allocatable, intent(in) :: explicit(:)
        logical, intent(in) :: linear
        integer(int64), intent(out) :: n_dir, spans_dir
        real(dp), allocatable :: inserted(:), breaks(:)
        integer :: k
        inserted = new_knots(knots, nel, explicit)
        breaks = distinct_knots(knots)
        spans_dir = int(size(breaks) - 1, int64) + size(inserted)
        if (linear) then
            n_dir = spans_dir + 1
            return
        end if
        ! elevation raises every distinct knot's multiplicity by deg - pc; each
        ! inserted knot adds one function
        n_dir = deg + 1 + size(inserted)
        do k = 2, size(breaks) - 1
            n_dir = n_dir + multiplicity(knots, breaks(k)) + (deg - pc)
        end do
    end subroutine direction

    !> Functions of the VO layer along direction `d` of the contact boundary: the
    !> boundary's knots (degree `pc`) elevated to the layer degree, the new knots
    !> inserted, then `layer_elevations` more elevations.
    pure integer(int64) function layer_functions(knots, pc, layout, d, explicit)
        real(dp), intent(in) :: knots(:)
        integer, intent(in) :: pc, d
        type(layout_t), intent(in) :: layout
        real(dp), allocatable, intent(in) :: explicit(:)
        real(dp), allocatable :: inserted(:), breaks(:)
        integer :: q, e, k
        q = layout%layer_degree
        e = layout%layer_elevations
        inserted = new_knots(knots, layout%nel(d), explicit)
        breaks = distinct_knots(knots)
        layer_functions = q + e + 1 + int(size(inserted), int64)*(1 + e)
        do k = 2, size(breaks) - 1
            layer_functions = layer_functions + multiplicity(knots, breaks(k)) + (q - pc) + e
        end do
    end function layer_functions

end module voiga_discretization_size
