!> The loads of the model: prescribed displacements and pressures on named edges,
!> each with a value at the end of every load phase (linear within a phase); and
!> the settings a case gives for one (`&dirichlet`, `&pressure`, read by
!> `voiga_io_input_case_dirichlet` and `voiga_io_input_case_pressure`).
module voiga_model_loads
    use voiga_kinds, only: dp
    implicit none
    private

    public :: dirichlet_t, pressure_t, dirichlet_settings_t, pressure_settings_t, phase_value
    public :: obstacle_motion_t, phase_friction_t, phase_of, axis_names

    !> The names of the spatial axes, in order; a model of dimension nsd uses the first
    !> nsd (`axis_names(1:nsd)`). The one list of them: the result file's per-axis
    !> attributes (`fix_x`, `fix_y` of a Dirichlet group) and the messages that name a
    !> component (`ux`) take their letters from here, so that a third axis is a
    !> change of nsd, not of every place that names one.
    character(len=1), parameter :: axis_names(3) = ['x', 'y', 'z']

    !> A prescribed displacement on a named edge or face (docs/formats.md, `&dirichlet`).
    type :: dirichlet_settings_t
        !> The body, and the name of its edge or face.
        character(len=32) :: body = '', edge = ''
        !> Which components are prescribed [x, y, z] (a plane body has no z).
        logical :: fix(3) = .false.
        !> Value at the end of each phase, shape [3, n_phases] (linear within a phase).
        real(dp), allocatable :: values(:, :)
    end type dirichlet_settings_t

    !> A pressure (force per length, normal to the edge, reference configuration)
    !> on a named edge (`&pressure`); positive pushes into the body.
    type :: pressure_settings_t
        character(len=32) :: body = '', edge = ''
        !> Value at the end of each phase, shape [n_phases].
        real(dp), allocatable :: values(:)
    end type pressure_settings_t

    !> Prescribed displacement on the control points of an edge or face.
    type :: dirichlet_t
        integer :: body = 0
        character(len=32) :: edge = ''
        !> Global DOF numbers of its points' components, shape [nsd, ncp_edge].
        integer, allocatable :: dofs(:, :)
        !> Which components are prescribed [x, y, z] (the first nsd used).
        logical :: fix(3) = .false.
        !> Value at the end of each phase [3, n_phases] (the first nsd rows used).
        real(dp), allocatable :: values(:, :)
    end type dirichlet_t

    !> Pressure on an edge (reference configuration, positive into the body).
    type :: pressure_t
        integer :: body = 0
        !> Edge index 1..4 (xi0, xi1, eta0, eta1) of the oriented patch.
        integer :: edge = 0
        real(dp), allocatable :: values(:)
    end type pressure_t

    !> The prescribed translation of a rigid contact master (`&contact rigid_ux`,
    !> `rigid_uy`).
    type :: obstacle_motion_t
        !> The contact pair whose master moves.
        integer :: pair = 0
        !> Translation at the end of each phase [2, n_phases].
        real(dp), allocatable :: values(:, :)
    end type obstacle_motion_t

    !> A contact pair whose friction coefficient changes with the load phase (one
    !> value per phase, constant within it: `&contact friction` with one value per phase).
    type :: phase_friction_t
        !> The contact pair.
        integer :: pair = 0
        !> Its friction coefficient in each phase [n_phases].
        real(dp), allocatable :: values(:)
    end type phase_friction_t

contains

    !> The load phase of load time `t` out of `n`: phase k runs over (k - 1, k], phase 1
    !> from t = 0.
    pure integer function phase_of(t, n) result(k)
        real(dp), intent(in) :: t
        integer, intent(in) :: n
        k = min(max(ceiling(t), 1), n)
    end function phase_of

    !> Value of a phase-wise linear history at load time `t`: 0 at t = 0, `values(k)` at t = k.
    pure real(dp) function phase_value(values, t) result(v)
        real(dp), intent(in) :: values(:)
        real(dp), intent(in) :: t
        integer :: k
        real(dp) :: a, s
        k = phase_of(t, size(values))
        s = t - real(k - 1, dp)
        a = 0.0_dp
        if (k > 1) a = values(k - 1)
        v = a + s*(values(k) - a)
    end function phase_value

end module voiga_model_loads
