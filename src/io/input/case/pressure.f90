!> The `&pressure` group: a pressure on a named edge (a plane body) or face (a
!> solid) of a body.
module voiga_io_input_case_pressure
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_io_input_namelist, only: group_error
    use voiga_io_input_case_values, only: check_length, unset, max_phases, phase_values, &
                                          check_body_edge, edge_or_face
    use voiga_model_body, only: body_settings_t
    use voiga_model_loads, only: pressure_settings_t
    implicit none
    private

    public :: read_pressure

contains

    !> Read the `k`-th `&pressure` group from its text for a case with `bodies` and
    !> `nph` load phases, and validate it.
    subroutine read_pressure(text, path, k, nph, bodies, entry, error)
        !> The group's text (`nml_group_t%text`).
        character(len=*), intent(in) :: text(:)
        integer, intent(in) :: k, nph
        character(len=*), intent(in) :: path
        type(body_settings_t), intent(in) :: bodies(:)
        type(pressure_settings_t), intent(out) :: entry
        type(error_t), allocatable, intent(out) :: error
        ! one character more than kept: a longer value is refused, not cut
        character(len=33) :: body, edge, face
        real(dp) :: p(max_phases)
        integer :: ios
        character(len=512) :: msg
        character(len=:), allocatable :: where
        namelist /pressure/ body, edge, face, p

        body = ''
        edge = ''
        face = ''
        p = unset()
        read (text, nml=pressure, iostat=ios, iomsg=msg)
        if (ios /= 0) then
            call group_error(path, 'pressure', text, ios, msg, try_pressure, error)
            return
        end if
        write (msg, '(a,i0,a)') ': &pressure (', k, '): '
        where = path//trim(msg)//' '
        call check_length(body, 32, 'body', where, error)
        call check_length(edge, 32, 'edge', where, error)
        call check_length(face, 32, 'face', where, error)
        if (allocated(error)) return
        call edge_or_face(edge, face, where, error)
        if (allocated(error)) return
        call check_body_edge(bodies, body, edge, where, error)
        if (allocated(error)) return
        entry%body = body
        entry%edge = edge
        allocate (entry%values(nph))
        call phase_values(p, .true., 'p', where, nph, entry%values, error)
    contains
        subroutine try_pressure(text, ios, msg)
            character(len=*), intent(in) :: text
            integer, intent(out) :: ios
            character(len=*), intent(inout) :: msg
            ! allow(C181): ios goes back to the caller, which reports it
            read (text, nml=pressure, iostat=ios, iomsg=msg)
        end subroutine try_pressure
    end subroutine read_pressure

end module voiga_io_input_case_pressure
