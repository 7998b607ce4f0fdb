!> How a body is discretized: bulk degrees and mesh, contact edge, and the
!> varying-order (VO) layer. Names follow the paper: Np, NNp, NNp.k, L1
!> (see docs/formats.md for the mapping to these fields).
module voiga_discretization_layout
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    implicit none
    private

    public :: layout_t, validate_layout, basis_nurbs, basis_linear, direction_names, knot_list

    !> The parametric directions, as the case and geometry files name them.
    character(len=4), parameter :: direction_names(3) = ['xi  ', 'eta ', 'zeta']

    character(len=*), parameter :: basis_nurbs = 'nurbs'
    !> L1: a degree-1 patch whose nodes lie on the exact geometry.
    character(len=*), parameter :: basis_linear = 'linear'

    !> Discretization choices of one body.
    type :: layout_t
        !> 'nurbs' (refined exact patch) or 'linear' (L1).
        character(len=16) :: basis = basis_nurbs
        !> Bulk degrees [p_xi, p_eta, p_zeta] (a plane body uses the first two).
        integer :: degree(3) = [2, 2, 2]
        !> Uniform element counts [nel_xi, nel_eta, nel_zeta]: knots i/nel are inserted.
        integer :: nel(3) = [1, 1, 1]
        !> Explicit interior knots to insert along xi / eta / zeta (used when allocated).
        real(dp), allocatable :: knots_xi(:), knots_eta(:), knots_zeta(:)
        !> Name of the contact boundary ('' for none): an edge of a plane body
        !> (`contact_edge` in the case file), a face of a solid (`contact_face`).
        character(len=32) :: contact_edge = ''
        !> Degree q of the VO layer along the contact boundary (0: no layer).
        integer :: layer_degree = 0
        !> Extra order elevations k of the layer (NNq.k).
        integer :: layer_elevations = 0
    end type layout_t

contains

    !> Check the values that do not depend on the geometry, for a body of parametric
    !> dimension `pdim` (2 or 3: the directions it uses). `where` prefixes messages.
    pure subroutine validate_layout(layout, pdim, where, error)
        type(layout_t), intent(in) :: layout
        integer, intent(in) :: pdim
        character(len=*), intent(in) :: where
        type(error_t), allocatable, intent(out) :: error
        real(dp), allocatable :: knots(:)
        integer :: d

        select case (trim(layout%basis))
        case (basis_nurbs, basis_linear)
        case default
            call fatal_error(error, where//"basis = '"//trim(layout%basis)// &
                             "' is not one of 'nurbs', 'linear'", error_code%input)
            return
        end select
        if (any(layout%degree(:pdim) < 1)) then
            call fatal_error(error, where//keys('degree', pdim, ' and ')//' must be >= 1', error_code%input)
            return
        end if
        if (trim(layout%basis) == basis_linear) then
            if (any(layout%degree(:pdim) /= 1)) then
                call fatal_error(error, where//"basis = 'linear' needs "//keys('degree', pdim, ' = ')//' = 1', &
                                 error_code%input)
                return
            end if
            if (layout%layer_degree /= 0) then
                call fatal_error(error, where//"basis = 'linear' cannot have a layer (layer_degree = 0)", &
                                 error_code%input)
                return
            end if
        end if
        do d = 1, pdim
            call knot_list(layout, d, knots)
            if (.not. allocated(knots) .and. layout%nel(d) < 1) then
                call fatal_error(error, where//keys('nel', pdim, ' and ')//' must be >= 1', error_code%input)
                return
            end if
        end do
        do d = 1, pdim
            call knot_list(layout, d, knots)
            if (allocated(knots)) call check_knot_list(knots, 'knots_'//trim(direction_names(d)), where, error)
            if (allocated(error)) return
        end do
        call check_layer(layout, pdim, where, error)
    end subroutine validate_layout

    !> The layer's values: q >= the bulk degrees along the contact boundary, and a
    !> contact boundary to put it on.
    pure subroutine check_layer(layout, pdim, where, error)
        type(layout_t), intent(in) :: layout
        integer, intent(in) :: pdim
        character(len=*), intent(in) :: where
        type(error_t), allocatable, intent(out) :: error
        if (layout%layer_degree < 0 .or. layout%layer_elevations < 0) then
            call fatal_error(error, where//'layer_degree and layer_elevations must be >= 0', &
                             error_code%input)
            return
        end if
        if (layout%layer_degree > 0) then
            if (layout%layer_degree < maxval(layout%degree(:pdim - 1))) then
                call fatal_error(error, where//'layer_degree must be >= '//keys('degree', pdim - 1, ' and ')// &
                                 ' (the layer cannot have a lower degree than the bulk it replaces)', &
                                 error_code%input)
                return
            end if
            if (len_trim(layout%contact_edge) == 0) then
                call fatal_error(error, where//'a layer (layer_degree > 0) needs a '// &
                                 trim(merge('contact_edge', 'contact_face', pdim == 2)), error_code%input)
                return
            end if
        else if (layout%layer_elevations > 0) then
            call fatal_error(error, where//'layer_elevations > 0 needs layer_degree > 0', error_code%input)
            return
        end if
    end subroutine check_layer

    !> 'degree_xi and degree_eta' (prefix 'degree', n 2, separator ' and '),
    !> 'degree_xi, degree_eta and degree_zeta' (n 3).
    pure function keys(prefix, n, separator) result(list)
        character(len=*), intent(in) :: prefix, separator
        integer, intent(in) :: n
        character(len=:), allocatable :: list
        integer :: d
        list = prefix//'_'//trim(direction_names(1))
        do d = 2, n
            if (d < n) then
                list = list//', '//prefix//'_'//trim(direction_names(d))
            else
                list = list//separator//prefix//'_'//trim(direction_names(d))
            end if
        end do
    end function keys

    !> The explicit knots of direction `d` (unallocated: none).
    pure subroutine knot_list(layout, d, knots)
        type(layout_t), intent(in) :: layout
        integer, intent(in) :: d
        real(dp), allocatable, intent(out) :: knots(:)
        select case (d)
        case (1); if (allocated(layout%knots_xi)) knots = layout%knots_xi
        case (2); if (allocated(layout%knots_eta)) knots = layout%knots_eta
        case default; if (allocated(layout%knots_zeta)) knots = layout%knots_zeta
        end select
    end subroutine knot_list

    pure subroutine check_knot_list(knots, name, where, error)
        real(dp), intent(in) :: knots(:)
        character(len=*), intent(in) :: name, where
        type(error_t), allocatable, intent(out) :: error
        integer :: i
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
