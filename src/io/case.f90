!> The case file: a Fortran namelist with a `&case` group, one `&body` group per
!> body and the groups of the solver, the loads and the contact pairs (reference in
!> docs/formats.md). Each group has its reader and settings type in `io/case/`;
!> here the file is opened, its groups are listed and checked, and each is read.
!> Every value is validated and every error names the file, the group and the
!> variable.
module voiga_io_case
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_io_namelist, only: group_names
    use voiga_io_case_case, only: case_settings_t, read_case_group, resolve_path
    use voiga_io_case_body, only: read_body
    use voiga_io_case_solver, only: read_solver
    use voiga_io_case_dirichlet, only: read_dirichlet
    use voiga_io_case_pressure, only: read_pressure
    use voiga_io_case_contact, only: read_contact
    use voiga_io_case_output, only: read_output
    use voiga_model_fields, only: output_settings_t
    use voiga_model_body, only: body_settings_t
    use voiga_model_loads, only: dirichlet_settings_t, pressure_settings_t
    use voiga_contact_factory, only: contact_settings_t
    use voiga_solver_settings, only: solver_settings_t
    use voiga_discretization_patch, only: discretization_t
    implicit none
    private

    public :: case_t, read_case, resolve_path, known_groups, check_edges

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
        integer :: u, ios, i
        character(len=512) :: msg
        logical :: exists

        inquire (file=path, exist=exists)
        if (.not. exists) then
            call fatal_error(error, "case file '"//path//"' does not exist", error_code%input)
            return
        end if
        self%path = path
        i = index(path, '/', back=.true.)
        self%dir = path(1:i)
        open (newunit=u, file=path, status='old', action='read', iostat=ios, iomsg=msg)
        if (ios /= 0) then
            call fatal_error(error, "case file '"//path//"' cannot be read: "//trim(msg), error_code%input)
            return
        end if
        call read_groups(u, self, error)
        close (u)
    end subroutine read_case

    !> Read every group of the case file open on unit `u`, in dependency order:
    !> `&case`, the bodies, then `&solver` (the number of load phases) and the loads
    !> and pairs that refer to both.
    subroutine read_groups(u, self, error)
        integer, intent(in) :: u
        type(case_t), intent(inout) :: self
        type(error_t), allocatable, intent(out) :: error
        character(len=32), allocatable :: names(:)
        integer :: i, nph

        call read_case_group(u, self%path, self%dir, self%case_settings_t, error)
        if (allocated(error)) return
        call group_names(self%path, names)
        call check_groups(self%path, names, self%n_bodies, error)
        if (allocated(error)) return
        allocate (self%bodies(self%n_bodies))
        rewind (u)
        do i = 1, self%n_bodies
            call read_body(u, self%path, i, self%n_bodies, self%bodies(i), error)
            if (allocated(error)) return
        end do
        do i = 2, self%n_bodies
            if (any(self%bodies(1:i - 1)%name == self%bodies(i)%name)) then
                call fatal_error(error, self%path//": &body: name = '"//trim(self%bodies(i)%name)// &
                                 "' is used by two bodies", error_code%input)
                return
            end if
        end do
        if (any(names == 'solver')) then
            call read_solver(u, self%path, self%solver, error)
            if (allocated(error)) return
        else
            self%solver%n_steps = [1]
        end if
        nph = size(self%solver%n_steps)
        allocate (self%dirichlet(count(names == 'dirichlet')), self%pressure(count(names == 'pressure')), &
                  self%contact(count(names == 'contact')))
        rewind (u)
        do i = 1, size(self%dirichlet)
            call read_dirichlet(u, self%path, i, nph, self%bodies, self%dirichlet(i), error)
            if (allocated(error)) return
        end do
        rewind (u)
        do i = 1, size(self%pressure)
            call read_pressure(u, self%path, i, nph, self%bodies, self%pressure(i), error)
            if (allocated(error)) return
        end do
        rewind (u)
        do i = 1, size(self%contact)
            call read_contact(u, self%path, i, nph, self%bodies, self%contact(i), error)
            if (allocated(error)) return
        end do
        if (any(names == 'output')) call read_output(u, self%path, self%solver%total_steps(), self%field_output, &
                                                     error)
    end subroutine read_groups

    !> Every group in the file is known, and there are exactly n_bodies &body groups.
    subroutine check_groups(path, names, n_bodies, error)
        character(len=*), intent(in) :: path
        character(len=*), intent(in) :: names(:)
        integer, intent(in) :: n_bodies
        type(error_t), allocatable, intent(out) :: error
        character(len=128) :: msg
        integer :: i
        do i = 1, size(names)
            if (.not. any(known_groups == names(i))) then
                call fatal_error(error, path//': unknown namelist group &'//trim(names(i))// &
                                 ' (known: &case, &body, &solver, &dirichlet, &pressure, &contact, &output)', &
                                 error_code%input)
                return
            end if
        end do
        if (count(names == 'body') /= n_bodies) then
            write (msg, '(a,i0,a,i0,a)') ': &case: n_bodies = ', n_bodies, ' but the file has ', &
                count(names == 'body'), ' &body groups'
            call fatal_error(error, path//trim(msg), error_code%input)
            return
        end if
        if (count(names == 'case') /= 1 .or. count(names == 'solver') > 1 .or. count(names == 'output') > 1) then
            call fatal_error(error, path//': groups &case, &solver and &output may appear once each', &
                             error_code%input)
            return
        end if
    end subroutine check_groups

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
            write (buf, '(a,i0,a)') ': &dirichlet (', k, '): edge: '
            call fatal_error(error, self%path//trim(buf)//" no edge named '"//trim(self%dirichlet(k)%edge)// &
                             "' of body '"//trim(self%dirichlet(k)%body)//"' (edges: "// &
                             edge_names(discs(ib))//')', error_code%input)
            return
        end do
        do k = 1, size(self%pressure)
            ib = findloc(self%bodies%name, self%pressure(k)%body, dim=1)
            if (has_edge(discs(ib), self%pressure(k)%edge)) cycle
            write (buf, '(a,i0,a)') ': &pressure (', k, '): edge: '
            call fatal_error(error, self%path//trim(buf)//" no edge named '"//trim(self%pressure(k)%edge)// &
                             "' on body '"//trim(self%pressure(k)%body)//"' (edges: "// &
                             edge_names(discs(ib))//')', error_code%input)
            return
        end do
    end subroutine check_edges

    pure logical function has_edge(disc, name)
        type(discretization_t), intent(in) :: disc
        character(len=*), intent(in) :: name
        integer :: i
        has_edge = any([(trim(disc%edges(i)%name) == trim(name), i=1, 4)])
    end function has_edge

    pure function edge_names(disc) result(list)
        type(discretization_t), intent(in) :: disc
        character(len=:), allocatable :: list
        integer :: i
        list = ''
        do i = 1, 4
            list = list//"'"//trim(disc%edges(i)%name)//"'"
            if (i < 4) list = list//', '
        end do
    end function edge_names

end module voiga_io_case
