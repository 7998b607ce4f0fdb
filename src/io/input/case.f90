!> The case file: a Fortran namelist with a `&case` group, one `&body` group per
!> body and the groups of the solver, the loads and the contact pairs (reference in
!> docs/formats.md). Each group has its reader and settings type in `io/input/case/`;
!> here the file is opened, its groups are listed and checked, and each is read.
!> Every value is validated and every error names the file, the group and the
!> variable.
module voiga_io_input_case
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_text, only: str
    use voiga_io_input_namelist, only: nml_group_t, scan_groups
    use voiga_platform_os, only: path_kind, kind_name, kind_missing, kind_regular
    use voiga_io_input_case_case, only: case_settings_t, read_case_group, resolve_path
    use voiga_io_input_case_body, only: read_body
    use voiga_io_input_case_solver, only: read_solver
    use voiga_io_input_case_dirichlet, only: read_dirichlet
    use voiga_io_input_case_pressure, only: read_pressure
    use voiga_io_input_case_contact, only: read_contact
    use voiga_io_input_case_output, only: read_output
    use voiga_model_fields, only: output_settings_t
    use voiga_model_body, only: body_settings_t
    use voiga_model_loads, only: dirichlet_settings_t, pressure_settings_t, axis_names
    use voiga_contact_factory, only: contact_settings_t
    use voiga_solver_settings, only: solver_settings_t
    use voiga_discretization_patch, only: discretization_t, boundary_index, boundary_word
    implicit none
    private

    public :: case_t, read_case, resolve_path, known_groups, check_edges

    !> Most groups of one name a case file may have (a case has a few; many
    !> thousands would only cost time and memory).
    integer, parameter :: max_groups = 1000

    !> The namelist groups a case file may contain.
    character(len=*), parameter :: known_groups(7) = [character(len=9) :: 'case', 'body', 'solver', &
                                                      'dirichlet', 'pressure', 'contact', 'output']

    !> A case: its `&case` group and the settings of every other group.
    type, extends(case_settings_t) :: case_t
        !> The case file and its folder (with trailing '/', or '').
        character(len=:), allocatable :: path, dir
        type(body_settings_t), allocatable :: bodies(:)
        type(solver_settings_t) :: solver
        type(dirichlet_settings_t), allocatable :: dirichlet(:)
        type(pressure_settings_t), allocatable :: pressure(:)
        type(contact_settings_t), allocatable :: contact(:)
        !> The sampled fields the result file gets (`&output`).
        type(output_settings_t) :: field_output
    end type case_t

contains

    !> Read and validate the case file `path`.
    subroutine read_case(path, self, error)
        character(len=*), intent(in) :: path
        type(case_t), intent(out) :: self
        type(error_t), allocatable, intent(out) :: error
        type(nml_group_t), allocatable :: groups(:)
        integer :: i, kind

        kind = path_kind(path, .true.)
        if (kind == kind_missing) then
            call fatal_error(error, "case file '"//path//"' does not exist", error_code%input)
            return
        else if (kind /= kind_regular) then
            ! (reading a FIFO would wait for a writer)
            call fatal_error(error, "case file '"//path//"' is "//kind_name(kind)//', not a namelist file', &
                             error_code%input)
            return
        end if
        self%path = path
        i = index(path, '/', back=.true.)
        self%dir = path(1:i)
        call scan_groups(path, groups, error)
        if (allocated(error)) return
        call read_groups(groups, self, error)
    end subroutine read_case

    !> Read every group of the case file (`groups`, as scanned), in dependency
    !> order: `&case`, the bodies, then `&solver` (the number of load phases) and
    !> the loads and pairs that refer to both.
    subroutine read_groups(groups, self, error)
        type(nml_group_t), intent(in) :: groups(:)
        type(case_t), intent(inout) :: self
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: at(:)
        integer :: i, nph

        call check_groups(self%path, groups, error)
        if (allocated(error)) return
        at = where_named(groups, 'case')
        call read_case_group(groups(at(1))%text, self%path, self%dir, self%case_settings_t, error)
        if (allocated(error)) return
        at = where_named(groups, 'body')
        call check_body_count(self%path, size(at), self%n_bodies, error)
        if (allocated(error)) return
        allocate (self%bodies(self%n_bodies))
        do i = 1, self%n_bodies
            call read_body(groups(at(i))%text, self%path, i, self%n_bodies, self%bodies(i), error)
            if (allocated(error)) return
        end do
        do i = 2, self%n_bodies
            if (any(self%bodies(1:i - 1)%name == self%bodies(i)%name)) then
                call fatal_error(error, self%path//": &body: name = '"//trim(self%bodies(i)%name)// &
                                 "' is used by two bodies", error_code%input)
                return
            end if
        end do
        at = where_named(groups, 'solver')
        if (size(at) > 0) then
            call read_solver(groups(at(1))%text, self%path, self%solver, error)
            if (allocated(error)) return
        else
            self%solver%n_steps = [1]
        end if
        nph = size(self%solver%n_steps)
        at = where_named(groups, 'dirichlet')
        allocate (self%dirichlet(size(at)))
        do i = 1, size(at)
            call read_dirichlet(groups(at(i))%text, self%path, i, nph, self%bodies, self%dirichlet(i), error)
            if (allocated(error)) return
        end do
        call check_duplicate_dirichlet(self%path, self%dirichlet, error)
        if (allocated(error)) return
        at = where_named(groups, 'pressure')
        allocate (self%pressure(size(at)))
        do i = 1, size(at)
            call read_pressure(groups(at(i))%text, self%path, i, nph, self%bodies, self%pressure(i), error)
            if (allocated(error)) return
        end do
        at = where_named(groups, 'contact')
        allocate (self%contact(size(at)))
        do i = 1, size(at)
            call read_contact(groups(at(i))%text, self%path, i, nph, self%bodies, self%contact(i), error)
            if (allocated(error)) return
        end do
        call check_duplicate_contact(self%path, self%contact, error)
        if (allocated(error)) return
        at = where_named(groups, 'output')
        if (size(at) > 0) call read_output(groups(at(1))%text, self%path, self%solver%total_steps(), &
                                           self%field_output, error)
    end subroutine read_groups

    !> Indices of the groups called `name`, in file order.
    pure function where_named(groups, name) result(at)
        type(nml_group_t), intent(in) :: groups(:)
        character(len=*), intent(in) :: name
        integer, allocatable :: at(:)
        integer :: i
        at = pack([(i, i=1, size(groups))], groups%name == name)
    end function where_named

    !> Every group in the file is known, `&case` appears once, `&solver` and
    !> `&output` at most once, no group more than `max_groups` times.
    subroutine check_groups(path, groups, error)
        character(len=*), intent(in) :: path
        type(nml_group_t), intent(in) :: groups(:)
        type(error_t), allocatable, intent(out) :: error
        integer :: i, n
        do i = 1, size(groups)
            if (.not. any(known_groups == groups(i)%name)) then
                call fatal_error(error, path//': unknown namelist group &'//trim(groups(i)%name)// &
                                 ' (known: &case, &body, &solver, &dirichlet, &pressure, &contact, &output)', &
                                 error_code%input)
                return
            end if
        end do
        do i = 1, size(known_groups)
            n = count(groups%name == known_groups(i))
            if (n > max_groups) then
                call fatal_error(error, path//': at most '//str(max_groups)//' &'//trim(known_groups(i))// &
                                 ' groups ('//str(n)//' given)', error_code%input)
                return
            end if
        end do
        if (count(groups%name == 'case') == 0) then
            call fatal_error(error, path//': group &case is missing', error_code%input)
        else if (count(groups%name == 'case') > 1 .or. count(groups%name == 'solver') > 1 .or. &
                 count(groups%name == 'output') > 1) then
            call fatal_error(error, path//': groups &case, &solver and &output may appear once each', &
                             error_code%input)
        end if
    end subroutine check_groups

    !> There are exactly n_bodies &body groups.
    subroutine check_body_count(path, found, n_bodies, error)
        character(len=*), intent(in) :: path
        integer, intent(in) :: found, n_bodies
        type(error_t), allocatable, intent(out) :: error
        character(len=128) :: msg
        if (found /= n_bodies) then
            write (msg, '(a,i0,a,i0,a)') ': &case: n_bodies = ', n_bodies, ' but the file has ', found, &
                ' &body groups'
            call fatal_error(error, path//trim(msg), error_code%input)
        end if
    end subroutine check_body_count

    !> No two &dirichlet groups prescribe the same component of the same edge (the
    !> later would silently replace the earlier).
    subroutine check_duplicate_dirichlet(path, dirichlet, error)
        character(len=*), intent(in) :: path
        type(dirichlet_settings_t), intent(in) :: dirichlet(:)
        type(error_t), allocatable, intent(out) :: error
        character(len=128) :: msg
        integer :: i, j, c
        do j = 2, size(dirichlet)
            do i = 1, j - 1
                if (dirichlet(i)%body /= dirichlet(j)%body .or. dirichlet(i)%edge /= dirichlet(j)%edge) cycle
                do c = 1, size(dirichlet(j)%fix)
                    if (.not. (dirichlet(i)%fix(c) .and. dirichlet(j)%fix(c))) cycle
                    write (msg, '(a,i0,a,i0,a)') ': &dirichlet (', i, ') and (', j, ') both prescribe u'
                    call fatal_error(error, path//trim(msg)//axis_names(c)//" of edge '"//trim(dirichlet(j)%edge)// &
                                     "' of body '"//trim(dirichlet(j)%body)//"' (give each component of an "// &
                                     'edge once)', error_code%input)
                    return
                end do
            end do
        end do
    end subroutine check_duplicate_dirichlet

    !> No two &contact groups name the same slave and the same deformable master
    !> (their contact would count twice; rigid masters may repeat: a floor and a wall).
    subroutine check_duplicate_contact(path, contact, error)
        character(len=*), intent(in) :: path
        type(contact_settings_t), intent(in) :: contact(:)
        type(error_t), allocatable, intent(out) :: error
        character(len=128) :: msg
        integer :: i, j
        do j = 2, size(contact)
            do i = 1, j - 1
                if (contact(i)%slave /= contact(j)%slave .or. contact(i)%master /= contact(j)%master .or. &
                    contact(j)%master == 'rigid') cycle
                write (msg, '(a,i0,a,i0,a)') ': &contact (', i, ') and (', j, ') are the same pair'
                call fatal_error(error, path//trim(msg)//" (slave '"//trim(contact(j)%slave)//"', master '"// &
                                 trim(contact(j)%master)//"'): its contact would count twice", error_code%input)
                return
            end do
        end do
    end subroutine check_duplicate_contact

    !> Every edge the loads name exists on its body's discretization `discs` (one
    !> per body, in order): the check that needs the geometry.
    subroutine check_edges(self, discs, error)
        type(case_t), intent(in) :: self
        type(discretization_t), intent(in) :: discs(:)
        type(error_t), allocatable, intent(out) :: error
        character(len=64) :: buf
        integer :: k, ib
        do k = 1, size(self%dirichlet)
            ib = findloc(self%bodies%name, self%dirichlet(k)%body, dim=1)
            if (has_edge(discs(ib), self%dirichlet(k)%edge)) cycle
            write (buf, '(a,i0,a)') ': &dirichlet (', k, '): '
            call missing(self%path//trim(buf), self%dirichlet(k)%edge, ' of body ', self%dirichlet(k)%body, &
                         discs(ib), error)
            return
        end do
        do k = 1, size(self%pressure)
            ib = findloc(self%bodies%name, self%pressure(k)%body, dim=1)
            if (has_edge(discs(ib), self%pressure(k)%edge)) cycle
            write (buf, '(a,i0,a)') ': &pressure (', k, '): '
            call missing(self%path//trim(buf), self%pressure(k)%edge, ' on body ', self%pressure(k)%body, &
                         discs(ib), error)
            return
        end do
    contains
        !> The error of a load on `name`, which is no edge (a plane body) or face (a
        !> solid) of `body`.
        subroutine missing(where, name, link, body, disc, error)
            character(len=*), intent(in) :: where, name, link, body
            type(discretization_t), intent(in) :: disc
            type(error_t), allocatable, intent(out) :: error
            character(len=4) :: entity
            entity = boundary_word(disc%pdim)
            call fatal_error(error, where//entity//': no '//entity//" named '"//trim(name)//"'"//link//"'"// &
                             trim(body)//"' ("//entity//'s: '//edge_names(disc)//')', error_code%input)
        end subroutine missing
    end subroutine check_edges

    pure logical function has_edge(disc, name)
        type(discretization_t), intent(in) :: disc
        character(len=*), intent(in) :: name
        integer :: i
        has_edge = boundary_index(disc, name) > 0
    end function has_edge

    pure function edge_names(disc) result(list)
        type(discretization_t), intent(in) :: disc
        character(len=:), allocatable :: list
        integer :: i
        list = ''
        do i = 1, size(disc%boundaries)
            list = list//"'"//trim(disc%boundaries(i)%name)//"'"
            if (i < size(disc%boundaries)) list = list//', '
        end do
    end function edge_names

end module voiga_io_input_case
