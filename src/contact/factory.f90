!> The contact methods by name (`&contact method`), and the settings of one
!> contact pair as a case gives them (`&contact`; read by `voiga_io_case_contact`).
!> A new method is a new extension of `contact_pair_t` plus one line here.
module voiga_contact_factory
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_nurbs_curve, only: nurbs_curve_t
    use voiga_contact_pair, only: contact_pair_t
    use voiga_contact_gpts, only: gpts_pair_t
    use voiga_contact_mortar, only: mortar_pair_t
    implicit none
    private

    public :: contact_settings_t, contact_method_names, new_contact_pair

    !> The valid values of `&contact method`: Gauss-point-to-surface (the paper's),
    !> mortar-type penalty.
    character(len=*), parameter :: contact_method_names(2) = [character(len=6) :: 'gpts', 'mortar']

    !> One contact pair (`&contact`; docs/formats.md).
    type :: contact_settings_t
        !> Slave body; master body, or 'rigid' for a rigid obstacle.
        character(len=32) :: slave = '', master = ''
        !> Rigid line: a point on it and its outward normal.
        real(dp) :: rigid_point(2) = 0.0_dp, rigid_normal(2) = [0.0_dp, 1.0_dp]
        !> Rigid obstacle bounded by a curve of the geometry file instead of the line:
        !> its name ('' for the line) and the curve (read by `voiga_io_bodies`).
        character(len=32) :: rigid_curve = ''
        type(nurbs_curve_t) :: curve
        !> The rigid master's translation at the end of each load phase, shape
        !> [2, n_phases] (linear within a phase, zero at time 0); unallocated: fixed.
        real(dp), allocatable :: rigid_motion(:, :)
        real(dp) :: penalty_normal = 0.0_dp, penalty_tangent = 0.0_dp, friction = 0.0_dp
        !> Gauss points per slave contact element (0: layer degree + 1).
        integer :: n_gauss = 0
        !> One of `contact_method_names`.
        character(len=16) :: method = 'gpts'
    end type contact_settings_t

contains

    !> An empty pair of the method `method` (its data is set by the caller, then
    !> `setup`).
    subroutine new_contact_pair(pair, method, error)
        class(contact_pair_t), allocatable, intent(out) :: pair
        character(len=*), intent(in) :: method
        type(error_t), allocatable, intent(out) :: error
        select case (trim(method))
        case ('gpts')
            allocate (gpts_pair_t :: pair)
        case ('mortar')
            allocate (mortar_pair_t :: pair)
        case default
            call fatal_error(error, "unknown contact method '"//trim(method)//"'", error_code%input)
        end select
    end subroutine new_contact_pair

end module voiga_contact_factory
