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
    use voiga_nurbs_surface, only: nurbs_surface_t, surface_reorient, edge_index
    use voiga_discretization_layout, only: layout_t, basis_linear
    use voiga_discretization_patch, only: new_knots
    implicit none
    private

    public :: body_size_t, body_size

    !> Counts of one discretized body.
    type :: body_size_t
        !> Control points (2 DOFs each) and elements.
        integer(int64) :: ncp = 0, nel = 0
        !> Sum over the elements of (2 x control points of the element)^2: the
        !> entries of all element stiffness matrices, the size of the assembly map.
        integer(int64) :: entries = 0
    end type body_size_t

contains

    !> The counts `new_discretization` would give `coarse` with `layout` (the
    !> layout is assumed valid: `validate_layout`, and the contact edge an edge of
    !> the patch; degrees below the geometry's count as the geometry's).
    pure function body_size(coarse, layout) result(counts)
        type(nurbs_surface_t), intent(in) :: coarse
        type(layout_t), intent(in) :: layout
        type(body_size_t) :: counts
        type(nurbs_surface_t) :: oriented
        integer(int64) :: n(2), spans(2), n_layer, nen, nen_vo
        integer :: p(2), d, edge

        oriented = coarse
        if (len_trim(layout%contact_edge) > 0) then
            edge = edge_index(coarse, layout%contact_edge)
            if (edge > 0) call surface_reorient(oriented, edge)
        end if
        do d = 1, 2
            if (trim(layout%basis) == basis_linear) then
                p(d) = 1
            else
                p(d) = max(layout%degree(d), oriented%degree(d))
            end if
            call direction(d, p(d), n(d), spans(d))
        end do
        counts%ncp = n(1)*n(2)
        counts%nel = spans(1)*spans(2)
        nen = int(p(1) + 1, int64)*(p(2) + 1)
        counts%entries = counts%nel*(2*nen)**2
        if (layout%layer_degree > 0 .and. trim(layout%basis) /= basis_linear) then
            n_layer = layer_functions()
            counts%ncp = counts%ncp - n(1) + n_layer
            nen_vo = int(p(1) + 1, int64)*p(2) + layout%layer_degree + layout%layer_elevations + 1
            counts%entries = counts%entries - spans(1)*(2*nen)**2 + spans(1)*(2*nen_vo)**2
        end if
    contains
        !> Functions `n_dir` and element spans along direction `dir` at degree `deg`.
        pure subroutine direction(dir, deg, n_dir, spans_dir)
            integer, intent(in) :: dir, deg
            integer(int64), intent(out) :: n_dir, spans_dir
            real(dp), allocatable :: knots(:), inserted(:), breaks(:), explicit(:)
            integer :: pc, k
            if (dir == 1) then
                knots = oriented%knots_xi
                if (allocated(layout%knots_xi)) explicit = layout%knots_xi
            else
                knots = oriented%knots_eta
                if (allocated(layout%knots_eta)) explicit = layout%knots_eta
            end if
            pc = oriented%degree(dir)
            inserted = new_knots(knots, layout%nel(dir), explicit)
            breaks = distinct_knots(knots)
            spans_dir = int(size(breaks) - 1, int64) + size(inserted)
            if (trim(layout%basis) == basis_linear) then
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

        !> Functions of the VO layer: the contact edge's curve elevated to the layer
        !> degree, the new knots inserted, then `layer_elevations` more elevations.
        pure integer(int64) function layer_functions()
            real(dp), allocatable :: knots(:), inserted(:), breaks(:), explicit(:)
            integer :: q, e, pc, k
            knots = oriented%knots_xi
            if (allocated(layout%knots_xi)) explicit = layout%knots_xi
            pc = oriented%degree(1)
            q = layout%layer_degree
            e = layout%layer_elevations
            inserted = new_knots(knots, layout%nel(1), explicit)
            breaks = distinct_knots(knots)
            layer_functions = q + e + 1 + int(size(inserted), int64)*(1 + e)
            do k = 2, size(breaks) - 1
                layer_functions = layer_functions + multiplicity(knots, breaks(k)) + (q - pc) + e
            end do
        end function layer_functions
    end function body_size

end module voiga_discretization_size
