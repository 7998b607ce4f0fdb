!> How a body is discretized: bulk degrees and mesh, contact edge, and the
!> varying-order (VO) layer. Names follow the paper: Np, NNp, NNp.k, L1
!> (see docs/formats.md for the mapping to these fields).
module voiga_discretization_layout
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    implicit none
    private

    public :: layout_t, validate_layout, basis_nurbs, basis_linear

    character(len=*), parameter :: basis_nurbs = 'nurbs'
    !> L1: a degree-1 patch whose nodes lie on the exact geometry.
    character(len=*), parameter :: basis_linear = 'linear'

    !> Discretization choices of one body.
    type :: layout_t
        !> 'nurbs' (refined exact patch) or 'linear' (L1).
        character(len=16) :: basis = basis_nurbs
        !> Bulk degrees [p_xi, p_eta].
        integer :: degree(2) = [2, 2]
        !> Uniform element counts [nel_xi, nel_eta]: knots i/nel are inserted.
        integer :: nel(2) = [1, 1]
        !> Explicit interior knots to insert along xi / eta (used when allocated).
        real(dp), allocatable :: knots_xi(:), knots_eta(:)
        !> Name of the contact edge ('' for none).
        character(len=32) :: contact_edge = ''
        !> Degree q of the VO layer along the contact edge (0: no layer).
        integer :: layer_degree = 0
        !> Extra order elevations k of the layer (NNq.k).
        integer :: layer_elevations = 0
    end type layout_t

contains

    !> Check the values that do not depend on the geometry. `where` prefixes messages.
    pure subroutine validate_layout(layout, where, error)
        type(layout_t), intent(in) :: layout
        character(len=*), intent(in) :: where
        type(error_t), allocatable, intent(out) :: error

        select case (trim(layout%basis))
        case (basis_nurbs, basis_linear)
        case default
            call fatal_error(error, where//"basis = '"//trim(layout%basis)// &
                             "' is not one of 'nurbs', 'linear'", error_code%input)
            return
        end select
        if (any(layout%degree < 1)) then
            call fatal_error(error, where//'degree_xi and degree_eta must be >= 1', error_code%input)
            return
        end if
        if (trim(layout%basis) == basis_linear) then
            if (any(layout%degree /= 1)) then
                call fatal_error(error, where//"basis = 'linear' needs degree_xi = degree_eta = 1", &
                                 error_code%input)
                return
            end if
            if (layout%layer_degree /= 0) then
                call fatal_error(error, where//"basis = 'linear' cannot have a layer (layer_degree = 0)", &
                                 error_code%input)
                return
            end if
        end if
        if (.not. allocated(layout%knots_xi) .and. layout%nel(1) < 1 .or. &
            .not. allocated(layout%knots_eta) .and. layout%nel(2) < 1) then
            call fatal_error(error, where//'nel_xi and nel_eta must be >= 1', error_code%input)
            return
        end if
        call check_knot_list(layout%knots_xi, 'knots_xi', where, error)
        if (allocated(error)) return
        call check_knot_list(layout%knots_eta, 'knots_eta', where, error)
        if (allocated(error)) return
        if (layout%layer_degree < 0 .or. layout%layer_elevations < 0) then
            call fatal_error(error, where//'layer_degree and layer_elevations must be >= 0', &
                             error_code%input)
            return
        end if
        if (layout%layer_degree > 0) then
            if (layout%layer_degree < layout%degree(1)) then
                call fatal_error(error, where//'layer_degree must be >= degree_xi (the layer '// &
                                 'cannot have a lower degree than the bulk it replaces)', error_code%input)
                return
            end if
            if (len_trim(layout%contact_edge) == 0) then
                call fatal_error(error, where//'a layer (layer_degree > 0) needs a contact_edge', &
                                 error_code%input)
                return
            end if
        else if (layout%layer_elevations > 0) then
            call fatal_error(error, where//'layer_elevations > 0 needs layer_degree > 0', error_code%input)
            return
        end if
    end subroutine validate_layout

    pure subroutine check_knot_list(knots, name, where, error)
        real(dp), allocatable, intent(in) :: knots(:)
        character(len=*), intent(in) :: name, where
        type(error_t), allocatable, intent(out) :: error
        integer :: i
        if (.not. allocated(knots)) return
        do i = 1, size(knots)
            if (.not. (knots(i) > 0.0_dp .and. knots(i) < 1.0_dp)) then
                call fatal_error(error, where//name//' values must lie strictly inside (0, 1)', &
                                 error_code%input)
                return
            end if
            if (i > 1) then
                if (.not. (knots(i) > knots(i - 1))) then
                    call fatal_error(error, where//name//' must be strictly increasing', error_code%input)
                    return
                end if
            end if
        end do
    end subroutine check_knot_list

end module voiga_discretization_layout
