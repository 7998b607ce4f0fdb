!> The `&body` group: a body's name, material and discretization (layout).
module voiga_io_input_case_body
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_io_input_namelist, only: group_error
    use voiga_io_input_case_values, only: check_length, unset, is_unset, max_knots, max_value, &
                                          take_knots, quoted, either
    use voiga_model_body, only: body_settings_t
    use voiga_discretization_layout, only: layout_t
    use voiga_material_factory, only: material_names
    implicit none
    private

    public :: read_body

contains

    !> Read the `ibody`-th `&body` group (of `n_bodies`) from its text and validate it.
    subroutine read_body(text, path, ibody, n_bodies, entry, error)
        !> The group's text (`nml_group_t%text`).
        character(len=*), intent(in) :: text(:)
        character(len=*), intent(in) :: path
        integer, intent(in) :: ibody, n_bodies
        type(body_settings_t), intent(out) :: entry
        type(error_t), allocatable, intent(out) :: error
        ! one character more than kept: a longer value is refused, not cut
        character(len=33) :: name, material, basis, contact_edge, contact_face
        real(dp) :: youngs_modulus, poisson_ratio
        integer :: degree_xi, degree_eta, degree_zeta, nel_xi, nel_eta, nel_zeta, layer_degree, layer_elevations, ios
        real(dp), allocatable :: knots_xi(:), knots_eta(:), knots_zeta(:)
        character(len=512) :: msg
        character(len=:), allocatable :: where
        namelist /body/ name, material, youngs_modulus, poisson_ratio, basis, degree_xi, degree_eta, &
            degree_zeta, nel_xi, nel_eta, nel_zeta, knots_xi, knots_eta, knots_zeta, contact_edge, contact_face, &
            layer_degree, layer_elevations

        name = ''
        material = ''
        youngs_modulus = unset()
        poisson_ratio = unset()
        basis = 'nurbs'
        degree_xi = 2
        degree_eta = 2
        degree_zeta = 2
        nel_xi = 1
        nel_eta = 1
        nel_zeta = 1
        allocate (knots_xi(max_knots), knots_eta(max_knots), knots_zeta(max_knots))
        knots_xi = unset()
        knots_eta = unset()
        knots_zeta = unset()
        contact_edge = ''
        contact_face = ''
        layer_degree = 0
        layer_elevations = 0
        read (text, nml=body, iostat=ios, iomsg=msg)
        if (ios /= 0) then
            if (is_iostat_end(ios)) then
                write (msg, '(a,i0,a,i0,a)') ': n_bodies = ', n_bodies, ' but &body group ', ibody, &
                    ' is missing'
                call fatal_error(error, path//trim(msg), error_code%input)
            else
                call group_error(path, 'body', text, ios, msg, try_body, error)
            end if
            return
        end if
        write (msg, '(a,i0,a)') ': &body (', ibody, ')'
        where = path//trim(msg)
        call check_length(name, 32, 'name', where//': ', error)
        call check_length(material, 32, 'material', where//': ', error)
        call check_length(basis, 32, 'basis', where//': ', error)
        call check_length(contact_edge, 32, 'contact_edge', where//': ', error)
        call check_length(contact_face, 32, 'contact_face', where//': ', error)
        if (allocated(error)) return
        if (len_trim(name) == 0) then
            call fatal_error(error, where//': name is required', error_code%input)
            return
        end if
        where = path//": &body '"//trim(name)//"': "
        entry%name = name
        call check_material(material, youngs_modulus, poisson_ratio, where, error)
        if (allocated(error)) return
        entry%material = material
        entry%youngs_modulus = youngs_modulus
        entry%poisson_ratio = poisson_ratio

        entry%layout%basis = basis
        entry%layout%degree = [degree_xi, degree_eta, degree_zeta]
        entry%layout%nel = [nel_xi, nel_eta, nel_zeta]
        ! an edge of a plane body or a face of a solid: which one the geometry says
        if (len_trim(contact_edge) > 0 .and. len_trim(contact_face) > 0) then
            call fatal_error(error, where//'give contact_edge (a plane body) or contact_face (a solid), '// &
                             'not both', error_code%input)
            return
        end if
        entry%layout%contact_edge = contact_edge
        if (len_trim(contact_face) > 0) entry%layout%contact_edge = contact_face
        entry%contact_key = merge('contact_face', 'contact_edge', len_trim(contact_face) > 0)
        entry%layout%layer_degree = layer_degree
        entry%layout%layer_elevations = layer_elevations
        call check_counts(entry%layout, where, error)
        if (allocated(error)) return
        call take_knots(knots_xi, 'knots_xi', where, entry%layout%knots_xi, error)
        if (allocated(error)) return
        call take_knots(knots_eta, 'knots_eta', where, entry%layout%knots_eta, error)
        if (allocated(error)) return
        call take_knots(knots_zeta, 'knots_zeta', where, entry%layout%knots_zeta, error)
    contains
        !> Read one assignment into the &body group (for diagnosis).
        subroutine try_body(text, ios, msg)
            character(len=*), intent(in) :: text
            integer, intent(out) :: ios
            character(len=*), intent(inout) :: msg
            ! allow(C181): ios goes back to the caller, which reports it
            read (text, nml=body, iostat=ios, iomsg=msg)
        end subroutine try_body
    end subroutine read_body

    !> Each count of `l` in its range before any arithmetic on them (no overflow).
    subroutine check_counts(l, where, error)
        type(layout_t), intent(in) :: l
        character(len=*), intent(in) :: where
        type(error_t), allocatable, intent(out) :: error
        if (l%degree(1) > 20 .or. l%degree(2) > 20 .or. l%degree(3) > 20 .or. l%layer_degree > 20 .or. &
            l%layer_elevations > 20) then
            call fatal_error(error, where//'degrees above 20 are not supported', error_code%input)
            return
        end if
        if (l%layer_degree + l%layer_elevations > 20) then
            call fatal_error(error, where//'layer_degree + layer_elevations above 20 is not supported', &
                             error_code%input)
            return
        end if
        if (l%nel(1) < 1 .or. l%nel(2) < 1 .or. l%nel(1) > max_knots .or. l%nel(2) > max_knots) then
            call fatal_error(error, where//'nel_xi and nel_eta must be between 1 and 100000', error_code%input)
            return
        end if
        if (l%nel(3) < 1 .or. l%nel(3) > max_knots) then
            call fatal_error(error, where//'nel_zeta must be between 1 and 100000', error_code%input)
            return
        end if
        if (l%degree(1) < 1 .or. l%degree(2) < 1 .or. l%layer_degree < 0 .or. l%layer_elevations < 0) then
            call fatal_error(error, where//'degree_xi and degree_eta must be >= 1, layer_degree and '// &
                             'layer_elevations >= 0', error_code%input)
            return
        end if
        if (l%degree(3) < 1) then
            call fatal_error(error, where//'degree_zeta must be >= 1', error_code%input)
            return
        end if
    end subroutine check_counts

    !> The material is one of `material_names`, E finite and positive, nu in (-1, 0.5).
    subroutine check_material(material, youngs_modulus, poisson_ratio, where, error)
        character(len=*), intent(in) :: material, where
        real(dp), intent(in) :: youngs_modulus, poisson_ratio
        type(error_t), allocatable, intent(out) :: error
        if (len_trim(material) == 0) then
            call fatal_error(error, where//'material is required ('//either(material_names)//')', &
                             error_code%input)
            return
        end if
        if (.not. any(material_names == material)) then
            call fatal_error(error, where//"material = '"//trim(material)//"' is not one of "// &
                             quoted(material_names), error_code%input)
            return
        end if
        if (is_unset(youngs_modulus)) then
            call fatal_error(error, where//'youngs_modulus is required', error_code%input)
            return
        end if
        if (.not. (youngs_modulus > 0.0_dp .and. youngs_modulus <= max_value)) then
            call fatal_error(error, where//'youngs_modulus must be > 0 and <= 1e100', error_code%input)
            return
        end if
        if (is_unset(poisson_ratio)) then
            call fatal_error(error, where//'poisson_ratio is required', error_code%input)
            return
        end if
        if (.not. (poisson_ratio > -1.0_dp .and. poisson_ratio < 0.5_dp)) then
            call fatal_error(error, where//'poisson_ratio must lie in (-1, 0.5)', error_code%input)
            return
        end if
    end subroutine check_material

end module voiga_io_input_case_body
