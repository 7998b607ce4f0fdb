!> The `&dirichlet` group: a prescribed displacement on a named edge (a plane body)
!> or face (a solid) of a body.
module voiga_io_input_case_dirichlet
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_io_input_namelist, only: group_error
    use voiga_io_input_case_values, only: check_length, unset, max_phases, phase_values, &
                                          check_body_edge, edge_or_face
    use voiga_model_body, only: body_settings_t
    use voiga_model_loads, only: dirichlet_settings_t
    implicit none
    private

    public :: read_dirichlet

contains

    !> Read the `k`-th `&dirichlet` group from its text for a case with `bodies` and
    !> `nph` load phases, and validate it.
    subroutine read_dirichlet(text, path, k, nph, bodies, entry, error)
        !> The group's text (`nml_group_t%text`).
        character(len=*), intent(in) :: text(:)
        integer, intent(in) :: k, nph
        character(len=*), intent(in) :: path
        type(body_settings_t), intent(in) :: bodies(:)
        type(dirichlet_settings_t), intent(out) :: entry
        type(error_t), allocatable, intent(out) :: error
        ! one character more than kept: a longer value is refused, not cut
        character(len=33) :: body, edge, face
        logical :: fix_x, fix_y, fix_z
        real(dp) :: ux(max_phases), uy(max_phases), uz(max_phases)
        integer :: ios
        character(len=512) :: msg
        character(len=:), allocatable :: where
        namelist /dirichlet/ body, edge, face, fix_x, fix_y, fix_z, ux, uy, uz

        body = ''
        edge = ''
        face = ''
        fix_x = .false.
        fix_y = .false.
        fix_z = .false.
        ux = unset()
        uy = unset()
        uz = unset()
        read (text, nml=dirichlet, iostat=ios, iomsg=msg)
        if (ios /= 0) then
            call group_error(path, 'dirichlet', text, ios, msg, try_dirichlet, error)
            return
        end if
        write (msg, '(a,i0,a)') ': &dirichlet (', k, '): '
        where = path//trim(msg)//' '
        call check_length(body, 32, 'body', where, error)
        call check_length(edge, 32, 'edge', where, error)
        call check_length(face, 32, 'face', where, error)
        if (allocated(error)) return
        call edge_or_face(edge, face, where, error)
        if (allocated(error)) return
        call check_body_edge(bodies, body, edge, where, error)
        if (allocated(error)) return
        if (.not. (fix_x .or. fix_y .or. fix_z)) then
            call fatal_error(error, where//'fix_x or fix_y (or fix_z) must be .true.', error_code%input)
            return
        end if
        entry%body = body
        entry%edge = edge
        entry%fix = [fix_x, fix_y, fix_z]
        allocate (entry%values(3, nph))
        call phase_values(ux, fix_x, 'ux', where, nph, entry%values(1, :), error)
        if (allocated(error)) return
        call phase_values(uy, fix_y, 'uy', where, nph, entry%values(2, :), error)
        if (allocated(error)) return
        call phase_values(uz, fix_z, 'uz', where, nph, entry%values(3, :), error)
    contains
        subroutine try_dirichlet(text, ios, msg)
            character(len=*), intent(in) :: text
            integer, intent(out) :: ios
            character(len=*), intent(inout) :: msg
            ! allow(C181): ios goes back to the caller, which reports it
            read (text, nml=dirichlet, iostat=ios, iomsg=msg)
        end subroutine try_dirichlet
    end subroutine read_dirichlet

end module voiga_io_input_case_dirichlet
