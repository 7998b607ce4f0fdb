!> The contact methods by name (`&contact method`), the settings of one contact
!> pair as a case gives them (`&contact`; read by `voiga_io_input_case_contact`), and the
!> one place a pair is built: its method, law (with the automatic penalty),
!> quadrature, history and reference state, from the settings and the bodies the
!> model gives. A new method is a new extension of `contact_pair_t` plus one line
!> here (docs/architecture.md, "Adding a contact method").
module voiga_contact_factory
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_nurbs_curve, only: nurbs_curve_t
    use voiga_nurbs_patch, only: nurbs_patch_t
    use voiga_contact_surface, only: contact_surface_t, element_lengths
    use voiga_contact_master, only: contact_master_t
    use voiga_contact_pair, only: contact_pair_t, automatic
    use voiga_contact_gpts, only: gpts_pair_t
    use voiga_contact_mortar, only: mortar_pair_t
    use voiga_contact_alm, only: alm_pair
    use voiga_contact_segment, only: segment_pair_t
    use voiga_contact_segment_faces, only: segment_face_pair_t
    implicit none
    private

    public :: rigid_normal_of
    public :: contact_settings_t, contact_method_names, new_contact_pair, build_pair, automatic_penalty, &
              default_method, automatic

    !> The automatic normal penalty is this multiple of E* q / h (`automatic_penalty`).
    real(dp), parameter :: penalty_factor = 10.0_dp

    !> The valid values of `&contact method`: Gauss-point-to-surface (the paper's),
    !> mortar-type penalty, augmented Lagrangian on the mortar-type constraints,
    !> segment-based mortar (the mortar-type penalty integrated exactly per segment).
    character(len=*), parameter :: contact_method_names(4) = [character(len=7) :: 'gpts', 'mortar', 'alm', &
                                                               'segment']

    !> The method of a pair whose case names none: the segment-based mortar between
    !> two bodies (it passes the contact patch test on non-matching meshes, where GPTS
    !> is off by up to 20 %, keeps stick tractions smooth, and costs about 1.3 x GPTS on
    !> ironing; docs/verification.md, "The contact patch test"), GPTS against a rigid
    !> obstacle (the paper's method: as accurate there, the cheapest).
    character(len=*), parameter :: default_deformable = 'segment', default_rigid = 'gpts'
    !> On solids: the mortar-type penalty, whichever the master. GPTS's n_gauss^2
    !> constraints per face cell lock against the ~1 control point a cell adds: on the
    !> Hertz sphere its pressure scatters by up to the peak pressure with the automatic
    !> penalty, the mortar-type one's by 16 % at the coarsest mesh (docs/verification.md,
    !> "Contact on faces"). Segment passes the patch test on non-matching faces too, at
    !> several times mortar's points (docs/verification-faces.md).
    character(len=*), parameter :: default_face = 'mortar'

    !> One contact pair (`&contact`; docs/formats.md).
    type :: contact_settings_t
        !> Slave body; master body, or 'rigid' for a rigid obstacle.
        character(len=32) :: slave = '', master = ''
        !> Rigid line (2D) or plane (3D): a point on it and its outward normal [nsd:
        !> the first two in 2D]; how many components the case gave of each (0: the
        !> default, the origin and the normal +y in 2D, +z in 3D).
        real(dp) :: rigid_point(3) = 0.0_dp, rigid_normal(3) = [0.0_dp, 1.0_dp, 0.0_dp]
        integer :: point_components = 0, normal_components = 0
        !> Rigid obstacle bounded by a curve of the geometry file instead of the line:
        !> its name ('' for the line) and the curve (read by `voiga_io_input_bodies`).
        character(len=32) :: rigid_curve = ''
        type(nurbs_curve_t) :: curve
        !> In a solid case, a rigid obstacle bounded by a surface of the geometry file
        !> (/surfaces/<name>; its normal a_1 x a_2 points out of the obstacle): its name
        !> ('' for the plane) and the surface (read by `voiga_io_input_bodies`).
        character(len=32) :: rigid_surface = ''
        type(nurbs_patch_t) :: surface
        !> The rigid master's translation at the end of each load phase, shape
        !> [3, n_phases] (z: 0 in 2D) (linear within a phase, zero at time 0); unallocated: fixed.
        real(dp), allocatable :: rigid_motion(:, :)
        !> Whether the case gave rigid_uz (only a solid case may).
        logical :: motion_z = .false.
        !> Penalties (`automatic`: `automatic_penalty`, and the normal one for the
        !> tangential one) and the friction coefficient (the largest, when it changes
        !> with the phase).
        real(dp) :: penalty_normal = automatic, penalty_tangent = automatic, friction = 0.0_dp
        !> The friction coefficient of each load phase [n_phases], when the case gives
        !> one per phase (unallocated: `friction` in every phase).
        real(dp), allocatable :: friction_phases(:)
        !> Gauss points per slave contact element (0: layer degree + 1); with
        !> `segment`, per segment (0: `default_segment_points`).
        integer :: n_gauss = 0
        !> One of `contact_method_names`; `method_given`: the case named it (else the
        !> model takes `default_method` for the case's dimension).
        character(len=16) :: method = 'gpts'
        logical :: method_given = .true.
        !> Augmented Lagrangian: constraint tolerance relative to the slave element
        !> size (`automatic`: the method's default).
        real(dp) :: tolerance = automatic
        !> Run although most slave points start inside the master (an intended
        !> interference fit); else such a set-up is refused (`voiga_model_checks`).
        logical :: allow_overlap = .false.
    end type contact_settings_t

contains

    !> The rigid master's outward normal in `nsd` dimensions: as given, or (none
    !> given) +y in 2D, +z in 3D.
    pure function rigid_normal_of(c, nsd) result(n)
        type(contact_settings_t), intent(in) :: c
        integer, intent(in) :: nsd
        real(dp) :: n(nsd)
        n = c%rigid_normal(1:nsd)
        if (c%normal_components == 0 .and. nsd == 3) n = [0.0_dp, 0.0_dp, 1.0_dp]
    end function rigid_normal_of

    !> The method of a pair whose case names none (`default_deformable`,
    !> `default_rigid`); on solids (`nsd` = 3) `default_face`.
    pure function default_method(rigid_master, nsd) result(name)
        logical, intent(in) :: rigid_master
        integer, intent(in) :: nsd
        character(len=:), allocatable :: name
        if (nsd == 3) then
            name = default_face
        else if (rigid_master) then
            name = default_rigid
        else
            name = default_deformable
        end if
    end function default_method

    !> The pair `settings` describe between the contact edge `slave` of body
    !> `bodies(1)` and `master` (of body `bodies(2)`, 0 for a rigid one), whose
    !> plane-strain modulus is `e_star` (1/E* = sum over its deformable bodies of
    !> (1 - nu^2)/E): its method's type with the method's own settings, its law
    !> (the automatic penalty where the case gives none), its slave points and
    !> history (`setup`), and its history started from the projections in the
    !> reference configuration (`ndof` DOFs, all zero).
    subroutine new_contact_pair(pair, settings, slave, master, bodies, e_star, ndof, error)
        class(contact_pair_t), allocatable, intent(out) :: pair
        type(contact_settings_t), intent(in) :: settings
        type(contact_surface_t), intent(in) :: slave
        class(contact_master_t), intent(in) :: master
        integer, intent(in) :: bodies(2), ndof
        real(dp), intent(in) :: e_star
        type(error_t), allocatable, intent(out) :: error
        call new_method(pair, settings, slave%npar, error)
        if (allocated(error)) return
        call build_pair(pair, settings, slave, master, bodies, e_star, ndof, error)
    end subroutine new_contact_pair

    !> Everything `new_contact_pair` does after choosing the method, on a pair of any
    !> method (a test builds a method that is not in the factory with it).
    subroutine build_pair(pair, settings, slave, master, bodies, e_star, ndof, error)
        class(contact_pair_t), intent(inout) :: pair
        type(contact_settings_t), intent(in) :: settings
        type(contact_surface_t), intent(in) :: slave
        class(contact_master_t), intent(in) :: master
        integer, intent(in) :: bodies(2), ndof
        real(dp), intent(in) :: e_star
        type(error_t), allocatable, intent(out) :: error
        real(dp), allocatable :: u0(:), r0(:)
        logical :: refitted
        pair%slave_name = settings%slave
        pair%master_name = settings%master
        pair%slave_body = bodies(1)
        pair%master_body = bodies(2)
        pair%slave = slave
        allocate (pair%master, source=master)
        pair%eps_automatic = automatic_penalty(e_star, slave%degree, minval(element_lengths(slave)))
        pair%law%eps_n = settings%penalty_normal
        if (pair%law%eps_n == automatic) pair%law%eps_n = pair%eps_automatic
        pair%law%eps_t = settings%penalty_tangent
        if (pair%law%eps_t == automatic) pair%law%eps_t = pair%law%eps_n
        ! the largest coefficient decides what friction history the pair keeps; the
        ! one of the first phase holds from the start (the model's `set_contact_time`)
        pair%law%mu = settings%friction
        pair%n_gauss = settings%n_gauss
        call pair%setup()
        if (allocated(settings%friction_phases)) pair%law%mu = settings%friction_phases(1)
        allocate (u0(ndof), r0(ndof))
        u0 = 0.0_dp
        r0 = 0.0_dp
        call pair%evaluate(u0, r0, error)
        if (allocated(error)) return
        call pair%commit()
        ! a face's master is too large to couple every slave cell with all of it in the
        ! first pattern (an edge's is not): its ranges start from these projections
        if (pair%slave%npar > 1) call pair%refit_ranges(8, refitted)
        pair%n_evaluations = 0
        pair%n_friction = 0
    end subroutine build_pair

    !> An empty pair of the method `settings%method`, with the method's own settings,
    !> for a slave edge (`npar` = 1) or face (2).
    subroutine new_method(pair, settings, npar, error)
        class(contact_pair_t), allocatable, intent(out) :: pair
        type(contact_settings_t), intent(in) :: settings
        integer, intent(in) :: npar
        type(error_t), allocatable, intent(out) :: error
        select case (trim(settings%method))
        case ('gpts')
            allocate (gpts_pair_t :: pair)
        case ('mortar')
            allocate (mortar_pair_t :: pair)
        case ('alm')
            pair = alm_pair(settings%tolerance)
        case ('segment')
            if (npar > 1) then
                allocate (segment_face_pair_t :: pair)
            else
                allocate (segment_pair_t :: pair)
            end if
        case default
            call fatal_error(error, "unknown contact method '"//trim(settings%method)//"'", error_code%input)
        end select
    end subroutine new_method

    !> The normal penalty used when the case gives none: `penalty_factor` E* q / h,
    !> with E* the plane-strain modulus of the pair (1/E* = sum over its deformable
    !> bodies of (1 - nu^2)/E), q the slave edge's degree and h its smallest element
    !> (reference length). A penalty of E* / h makes the contact as stiff as an
    !> element of size h, and q / h is the spacing of the edge's control points;
    !> the factor keeps the penalty's own compliance (about E* / (eps a) of the
    !> pressure over a zone of size a) small without making the tangent stiff
    !> (docs/theory.md, section 7, "Automatic penalty"; docs/howto.md, "Choose contact settings").
    pure real(dp) function automatic_penalty(e_star, degree, h) result(eps)
        real(dp), intent(in) :: e_star, h
        integer, intent(in) :: degree
        eps = penalty_factor*e_star*real(degree, dp)/h
    end function automatic_penalty

end module voiga_contact_factory
