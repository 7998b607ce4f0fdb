!> The `&contact` group: a contact pair, its method and its law.
module voiga_io_input_case_contact
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_io_input_namelist, only: group_error
    use voiga_io_input_case_values, only: check_length, unset, is_unset, max_value, max_phases, &
                                          body_index, quoted, phase_values
    use voiga_model_body, only: body_settings_t
    use voiga_contact_factory, only: contact_settings_t, contact_method_names, default_method, automatic
    implicit none
    private

    public :: read_contact

contains

    !> Read the `k`-th `&contact` group from its text for a case with `bodies` and
    !> `nph` load phases, and validate it. penalty_normal not given: automatic;
    !> penalty_tangent defaults to penalty_normal.
    subroutine read_contact(text, path, k, nph, bodies, entry, error)
        !> The group's text (`nml_group_t%text`).
        character(len=*), intent(in) :: text(:)
        integer, intent(in) :: k, nph
        character(len=*), intent(in) :: path
        type(body_settings_t), intent(in) :: bodies(:)
        type(contact_settings_t), intent(out) :: entry
        type(error_t), allocatable, intent(out) :: error
        ! one character more than kept: a longer value is refused, not cut
        character(len=33) :: slave, master, rigid_curve, rigid_surface
        character(len=17) :: method
        real(dp) :: rigid_point(3), rigid_normal(3), penalty_normal, penalty_tangent, tolerance
        real(dp) :: rigid_ux(max_phases), rigid_uy(max_phases), rigid_uz(max_phases), friction(max_phases)
        integer :: n_gauss, ios
        logical :: allow_overlap
        character(len=512) :: msg
        namelist /contact/ slave, master, rigid_point, rigid_normal, penalty_normal, penalty_tangent, &
            friction, n_gauss, method, tolerance, rigid_curve, rigid_surface, rigid_ux, rigid_uy, rigid_uz, &
            allow_overlap

        slave = ''
        master = ''
        rigid_point = unset()
        rigid_normal = unset()
        penalty_normal = unset()
        penalty_tangent = unset()
        friction = unset()
        n_gauss = 0
        method = ''
        tolerance = unset()
        rigid_curve = ''
        rigid_surface = ''
        rigid_ux = unset()
        rigid_uy = unset()
        rigid_uz = unset()
        allow_overlap = .false.
        read (text, nml=contact, iostat=ios, iomsg=msg)
        if (ios /= 0) then
            call group_error(path, 'contact', text, ios, msg, try_contact, error)
            return
        end if
        write (msg, '(a,i0,a)') ': &contact (', k, '): '
        call check_length(slave, 32, 'slave', path//trim(msg)//' ', error)
        call check_length(master, 32, 'master', path//trim(msg)//' ', error)
        call check_length(rigid_curve, 32, 'rigid_curve', path//trim(msg)//' ', error)
        call check_length(rigid_surface, 32, 'rigid_surface', path//trim(msg)//' ', error)
        call check_length(method, 16, 'method', path//trim(msg)//' ', error)
        if (allocated(error)) return
        entry = contact_settings_t(slave=slave, master=master, rigid_curve=rigid_curve, rigid_surface=rigid_surface, &
                                   penalty_normal=penalty_normal, &
                                   penalty_tangent=penalty_tangent, n_gauss=n_gauss, &
                                   method=method, tolerance=tolerance, allow_overlap=allow_overlap)
        write (msg, '(a,i0,a)') ': &contact (', k, '): '
        call take_vector(rigid_point, 'rigid_point', path//trim(msg)//' ', entry%rigid_point, &
                         entry%point_components, error)
        if (allocated(error)) return
        call take_vector(rigid_normal, 'rigid_normal', path//trim(msg)//' ', entry%rigid_normal, &
                         entry%normal_components, error)
        if (allocated(error)) return
        call take_friction(friction, nph, path//trim(msg)//' ', entry, error)
        if (allocated(error)) return
        call check_pair(entry, bodies, path//trim(msg)//' ', error)
        if (allocated(error)) return
        ! none named: the default for the kind of master
        ! (the plane default here; a solid case's is the model's, which knows the dimension)
        entry%method_given = len_trim(entry%method) > 0
        if (.not. entry%method_given) entry%method = default_method(trim(entry%master) == 'rigid', 2)
        call check_law(entry, bodies, path//trim(msg)//' ', error)
        if (allocated(error)) return
        ! not given: left to the pair (the automatic penalty, the tangential one the
        ! normal one's, the method's tolerance)
        if (is_unset(entry%penalty_normal)) entry%penalty_normal = automatic
        if (is_unset(entry%penalty_tangent)) entry%penalty_tangent = entry%penalty_normal
        if (is_unset(entry%tolerance)) entry%tolerance = automatic
        call rigid_motion(entry, rigid_ux, rigid_uy, rigid_uz, nph, path//trim(msg)//' ', error)
    contains
        subroutine try_contact(text, ios, msg)
            character(len=*), intent(in) :: text
            integer, intent(out) :: ios
            character(len=*), intent(inout) :: msg
            ! allow(C181): ios goes back to the caller, which reports it
            read (text, nml=contact, iostat=ios, iomsg=msg)
        end subroutine try_contact
    end subroutine read_contact

    !> `friction`: one coefficient for every phase, or one per load phase (constant
    !> within a phase: a normal preload without friction, then sliding with it); none
    !> given: 0. Each finite and >= 0. Sets `friction` (the largest) and, when the
    !> phases differ, `friction_phases`.
    subroutine take_friction(raw, nph, where, c, error)
        real(dp), intent(in) :: raw(:)
        integer, intent(in) :: nph
        character(len=*), intent(in) :: where
        type(contact_settings_t), intent(inout) :: c
        type(error_t), allocatable, intent(out) :: error
        real(dp), allocatable :: values(:)
        integer :: n
        character(len=128) :: msg
        n = count(.not. is_unset(raw))
        if (n == 0) return
        if (any(is_unset(raw(1:n))) .or. (n /= 1 .and. n /= nph)) then
            write (msg, '(a,i0,a)') 'friction needs one value, or one per load phase (', nph, &
                ' phases in &solver n_steps)'
            call fatal_error(error, where//trim(msg), error_code%input)
            return
        end if
        values = raw(1:n)
        if (.not. all(ieee_is_finite(values))) then
            call fatal_error(error, where//'friction must be finite and >= 0', error_code%input)
            return
        end if
        if (any(values < 0.0_dp)) then
            call fatal_error(error, where//'friction must be finite and >= 0', error_code%input)
            return
        end if
        c%friction = maxval(values)
        if (any(values /= values(1))) c%friction_phases = values
    end subroutine take_friction

    !> The slave and master are bodies of the case with a contact edge (or the
    !> master is a valid rigid line, or a rigid curve).
    subroutine check_pair(c, bodies, where, error)
        type(contact_settings_t), intent(in) :: c
        type(body_settings_t), intent(in) :: bodies(:)
        character(len=*), intent(in) :: where
        type(error_t), allocatable, intent(out) :: error
        integer :: ib
        ib = body_index(bodies, c%slave)
        if (ib == 0) then
            call fatal_error(error, where//"slave = '"//trim(c%slave)//"' is not a body of the case", &
                             error_code%input)
            return
        end if
        if (len_trim(bodies(ib)%layout%contact_edge) == 0) then
            call fatal_error(error, where//"slave = '"//trim(c%slave)//"' has no contact_edge in its &body", &
                             error_code%input)
            return
        end if
        if (trim(c%master) /= 'rigid') then
            ib = body_index(bodies, c%master)
            if (len_trim(c%rigid_curve) > 0) then
                call fatal_error(error, where//"rigid_curve names the curve of a rigid master, but master = '"// &
                                 trim(c%master)//"' (set master = 'rigid')", error_code%input)
            else if (len_trim(c%rigid_surface) > 0) then
                call fatal_error(error, where//"rigid_surface names the surface of a rigid master, but master = '"// &
                                 trim(c%master)//"' (set master = 'rigid')", error_code%input)
            else if (ib == 0) then
                call fatal_error(error, where//"master = '"//trim(c%master)// &
                                 "' is neither a body of the case nor 'rigid'", error_code%input)
            else if (trim(c%master) == trim(c%slave)) then
                call fatal_error(error, where//'master and slave must be different bodies', error_code%input)
            else if (len_trim(bodies(ib)%layout%contact_edge) == 0) then
                call fatal_error(error, where//"master = '"//trim(c%master)// &
                                 "' has no contact_edge in its &body", error_code%input)
            end if
        else if (len_trim(c%rigid_curve) > 0 .and. len_trim(c%rigid_surface) > 0) then
            call fatal_error(error, where//'rigid_curve and rigid_surface: give one (a curve in a plane case, '// &
                             'a surface in a solid one)', error_code%input)
        else if (len_trim(c%rigid_curve) > 0 .or. len_trim(c%rigid_surface) > 0) then
            return   ! the geometry file must have it (checked when it is read)
        else if (.not. all(ieee_is_finite(c%rigid_point)) .or. .not. all(ieee_is_finite(c%rigid_normal)) .or. &
                 norm2(c%rigid_normal) <= 0.0_dp .or. any(abs(c%rigid_point) > max_value) .or. &
                 any(abs(c%rigid_normal) > max_value)) then
            call fatal_error(error, where//'rigid_point must be finite and rigid_normal finite and '// &
                             'nonzero (each entry at most 1e100 in magnitude)', error_code%input)
        end if
    end subroutine check_pair

    !> The rigid master's translation per phase (`rigid_ux`, `rigid_uy`; only for a
    !> rigid master; none given: fixed).
    subroutine rigid_motion(c, ux, uy, uz, nph, where, error)
        type(contact_settings_t), intent(inout) :: c
        real(dp), intent(in) :: ux(:), uy(:), uz(:)
        integer, intent(in) :: nph
        character(len=*), intent(in) :: where
        type(error_t), allocatable, intent(out) :: error
        if (all(is_unset(ux)) .and. all(is_unset(uy)) .and. all(is_unset(uz))) return
        if (trim(c%master) /= 'rigid') then
            call fatal_error(error, where//"rigid_ux, rigid_uy and rigid_uz move a rigid master: master = '"// &
                             trim(c%master)//"' is a body (move it by its &dirichlet)", error_code%input)
            return
        end if
        allocate (c%rigid_motion(3, nph))
        call phase_values(ux, .true., 'rigid_ux', where, nph, c%rigid_motion(1, :), error)
        if (allocated(error)) return
        call phase_values(uy, .true., 'rigid_uy', where, nph, c%rigid_motion(2, :), error)
        if (allocated(error)) return
        call phase_values(uz, .true., 'rigid_uz', where, nph, c%rigid_motion(3, :), error)
        c%motion_z = .not. all(is_unset(uz))
    end subroutine rigid_motion

    !> A rigid master's point or normal as the case gave it (`raw`, unset components
    !> not given): the leading components given, kept in `v` over its default, and
    !> their number `n` (checked against the dimension once the bodies are read:
    !> `voiga_io_input_bodies`). A gap (a component given after one that is not) is
    !> refused.
    subroutine take_vector(raw, name, where, v, n, error)
        real(dp), intent(in) :: raw(3)
        character(len=*), intent(in) :: name, where
        real(dp), intent(inout) :: v(3)
        integer, intent(out) :: n
        type(error_t), allocatable, intent(out) :: error
        n = count(.not. is_unset(raw))
        if (any(is_unset(raw(1:n)))) then
            call fatal_error(error, where//name//' needs its leading components (x, y, and z in a solid case)', &
                             error_code%input)
            return
        end if
        if (n == 0) return
        v = 0.0_dp
        v(1:n) = raw(1:n)
    end subroutine take_vector

    !> Penalties, friction, points and method in range.
    subroutine check_law(c, bodies, where, error)
        type(contact_settings_t), intent(in) :: c
        type(body_settings_t), intent(in) :: bodies(:)
        character(len=*), intent(in) :: where
        type(error_t), allocatable, intent(out) :: error
        real(dp) :: e_max
        if (given_not_positive(c%penalty_normal)) then
            call fatal_error(error, where//'penalty_normal must be finite and > 0 (or not given: automatic)', &
                             error_code%input)
        else if (c%friction > 0.0_dp .and. given_not_positive(c%penalty_tangent)) then
            call fatal_error(error, where//'penalty_tangent must be finite and > 0 (or not given)', &
                             error_code%input)
        else if (given_outside_unit(c%tolerance)) then
            call fatal_error(error, where//'tolerance must lie in (0, 1)', error_code%input)
        else if (c%n_gauss < 0 .or. c%n_gauss > 30) then
            call fatal_error(error, where//'n_gauss must be between 0 (automatic) and 30', error_code%input)
        else if (.not. any(contact_method_names == c%method)) then
            call fatal_error(error, where//"method = '"//trim(c%method)//"' is not one of "// &
                             quoted(contact_method_names), error_code%input)
        end if
        if (allocated(error)) return
        ! conditioning: a penalty above 1e12 x E leaves the stiffness matrix with fewer
        ! than 4 significant digits in double precision
        ! (an automatic penalty, the `unset` NaN, is never compared: an ordered comparison
        ! with a NaN raises IEEE_INVALID, which gfortran reports when the program ends)
        e_max = bodies(body_index(bodies, c%slave))%youngs_modulus
        if (trim(c%master) /= 'rigid') e_max = max(e_max, bodies(body_index(bodies, c%master))%youngs_modulus)
        if (given_above(c%penalty_normal, 1.0e12_dp*e_max) .or. &
            (c%friction > 0.0_dp .and. given_above(c%penalty_tangent, 1.0e12_dp*e_max))) &
            call fatal_error(error, where//'penalty_normal and penalty_tangent must not exceed 1e12 times '// &
                             "the largest Young's modulus of the two bodies (the stiffness matrix would "// &
                             'lose its significant digits)', error_code%input)
    end subroutine check_law

    !> Given (not `unset`) and not in (0, 1); an unset value is never compared (an
    !> ordered comparison with its NaN raises IEEE_INVALID).
    elemental logical function given_outside_unit(x) result(bad)
        real(dp), intent(in) :: x
        bad = .false.
        if (is_unset(x)) return
        bad = .true.
        if (.not. ieee_is_finite(x)) return
        bad = .not. (x > 0.0_dp .and. x < 1.0_dp)
    end function given_outside_unit

    !> Is `x` given (not `unset`) but not a finite positive number? Tested without
    !> comparing a NaN.
    elemental logical function given_not_positive(x)
        real(dp), intent(in) :: x
        given_not_positive = .false.
        if (is_unset(x)) return
        given_not_positive = .true.
        if (.not. ieee_is_finite(x)) return
        given_not_positive = x <= 0.0_dp
    end function given_not_positive

    !> Is `x` given (not `unset`) and above `limit`? Tested without comparing the NaN.
    elemental logical function given_above(x, limit)
        real(dp), intent(in) :: x, limit
        given_above = .false.
        if (is_unset(x)) return
        given_above = x > limit
    end function given_above

end module voiga_io_input_case_contact
