!> The case file: a Fortran namelist with a `&case` group and one `&body` group
!> per body (reference in docs/formats.md). Every value is validated and every
!> error names the file, the group and the variable.
module voiga_io_case
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_discretization_layout, only: layout_t
    use voiga_io_namelist, only: group_error, group_names, lower
    use voiga_contact_factory, only: contact_input_t => contact_settings_t
    implicit none
    private

    public :: case_t, body_input_t, solver_input_t, dirichlet_input_t, pressure_input_t, contact_input_t
    public :: read_case, resolve_path, known_groups

    !> Most explicit knots one direction of one body may list.
    integer, parameter :: max_knots = 100000
    !> Most bodies in a case.
    integer, parameter :: max_bodies = 16
    !> Marks a namelist array entry the file did not set.
    real(dp), parameter :: unset = -huge(1.0_dp)
    !> Most load phases.
    integer, parameter :: max_phases = 64
    !> The namelist groups a case file may contain.
    character(len=*), parameter :: known_groups(6) = [character(len=9) :: 'case', 'body', 'solver', &
                                                      'dirichlet', 'pressure', 'contact']

    !> One body as the case describes it.
    type :: body_input_t
        character(len=32) :: name = ''
        !> 'linear' (small strain) or 'neo-hookean' (finite strain).
        character(len=32) :: material = ''
        real(dp) :: youngs_modulus = 0.0_dp
        real(dp) :: poisson_ratio = 0.0_dp
        type(layout_t) :: layout
    end type body_input_t

    !> Load stepping and Newton settings (`&solver`).
    type :: solver_input_t
        !> Load steps of each phase; the number of entries is the number of phases.
        integer, allocatable :: n_steps(:)
        !> Newton iteration cap per step.
        integer :: max_iterations = 25
        !> Converged when ||r|| <= tol_residual ||r_0|| (r_0: the step's first residual) ...
        real(dp) :: tol_residual = 1.0e-10_dp
        !> ... or |du . r| <= tol_energy |du_1 . r_0|.
        real(dp) :: tol_energy = 1.0e-20_dp
        !> Gauss points per direction (0: degree + 1 in each direction).
        integer :: n_gauss = 0
        !> Adaptive load stepping (docs/robustness.md): a failed load increment is
        !> halved down to min_step_fraction of the nominal step ...
        real(dp) :: min_step_fraction = 1.0e-4_dp
        !> ... at most max_cuts times per nominal step (0: no cutting, a failed step fails the run) ...
        integer :: max_cuts = 30
        !> ... and doubled (never beyond the nominal step) after a substep that
        !> converged in at most grow_iterations Newton iterations.
        integer :: grow_iterations = 5
        !> Start each substep from the last step's increment, extrapolated (within a
        !> load phase; docs/robustness.md).
        logical :: predictor = .true.
        !> Linear solver of each Newton iteration: 'direct' (UMFPACK LU) or
        !> 'multigrid' (GMRES preconditioned by geometric multigrid over the
        !> nested spline spaces; docs/performance.md).
        character(len=16) :: linear_solver = 'direct'
        !> Newton step damping: 'residual' (halve a step that increases the residual
        !> norm) or 'natural' (affine-invariant: the simplified Newton correction must
        !> shrink; direct solver only; docs/robustness.md).
        character(len=16) :: damping = 'residual'
    end type solver_input_t

    !> A prescribed displacement on a named edge (`&dirichlet`).
    type :: dirichlet_input_t
        character(len=32) :: body = '', edge = ''
        !> Which components are prescribed [x, y].
        logical :: fix(2) = .false.
        !> Value at the end of each phase, shape [2, n_phases] (linear within a phase).
        real(dp), allocatable :: values(:, :)
    end type dirichlet_input_t

    !> A pressure (force per length, normal to the edge, reference configuration)
    !> on a named edge (`&pressure`); positive pushes into the body.
    type :: pressure_input_t
        character(len=32) :: body = '', edge = ''
        !> Value at the end of each phase, shape [n_phases].
        real(dp), allocatable :: values(:)
    end type pressure_input_t


    !> A case.
    type :: case_t
        !> The case file and its folder (with trailing '/', or '').
        character(len=:), allocatable :: path, dir
        character(len=:), allocatable :: title, scene, mesh, layout
        !> Geometry and output files, resolved against `dir`.
        character(len=:), allocatable :: geometry, output
        type(body_input_t), allocatable :: bodies(:)
        type(solver_input_t) :: solver
        type(dirichlet_input_t), allocatable :: dirichlet(:)
        type(pressure_input_t), allocatable :: pressure(:)
        type(contact_input_t), allocatable :: contact(:)
    end type case_t

contains

    !> `name` relative to `dir` unless it is absolute.
    pure function resolve_path(dir, name) result(path)
        character(len=*), intent(in) :: dir, name
        character(len=:), allocatable :: path
        if (len(name) > 0) then
            if (name(1:1) == '/') then
                path = name
                return
            end if
        end if
        path = dir//name
    end function resolve_path

    !> Read and validate the case file `path`.
    subroutine read_case(path, self, error)
        character(len=*), intent(in) :: path
        type(case_t), intent(out) :: self
        type(error_t), allocatable, intent(out) :: error
        character(len=256) :: title, scene, mesh, layout, geometry, output
        integer :: n_bodies, u, ios, i
        character(len=512) :: msg
        logical :: exists
        namelist /case/ title, scene, mesh, layout, geometry, output, n_bodies

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

        title = ''
        scene = ''
        mesh = ''
        layout = ''
        geometry = ''
        output = ''
        n_bodies = 0
        read (u, nml=case, iostat=ios, iomsg=msg)
        if (ios /= 0) then
            call group_error(path, 'case', 1, ios, msg, try_case, error)
            close (u)
            return
        end if
        self%title = trim(title)
        self%scene = trim(scene)
        self%mesh = trim(mesh)
        self%layout = trim(layout)
        if (len_trim(geometry) == 0) then
            call fatal_error(error, path//': &case: geometry is required (the geometry HDF5 file)', &
                             error_code%input)
            close (u)
            return
        end if
        self%geometry = resolve_path(self%dir, trim(geometry))
        if (len_trim(output) == 0) then
            i = index(path, '.', back=.true.)
            if (i <= index(path, '/', back=.true.)) i = len(path) + 1
            self%output = path(1:i - 1)//'.h5'
        else
            self%output = resolve_path(self%dir, trim(output))
        end if
        if (n_bodies < 1 .or. n_bodies > max_bodies) then
            write (msg, '(a,i0,a,i0,a)') ': &case: n_bodies = ', n_bodies, ' must be between 1 and ', &
                max_bodies, ''
            call fatal_error(error, path//trim(msg), error_code%input)
            close (u)
            return
        end if

        call check_groups(path, n_bodies, error)
        if (allocated(error)) then
            close (u)
            return
        end if
        allocate (self%bodies(n_bodies))
        rewind (u)
        do i = 1, n_bodies
            call read_body(u, path, i, n_bodies, self%bodies(i), error)
            if (allocated(error)) then
                close (u)
                return
            end if
        end do
        close (u)
        do i = 2, n_bodies
            if (any(self%bodies(1:i - 1)%name == self%bodies(i)%name)) then
                call fatal_error(error, path//": &body: name = '"//trim(self%bodies(i)%name)// &
                                 "' is used by two bodies", error_code%input)
                return
            end if
        end do
        call read_loads(path, self, error)
    contains
        !> Read one assignment into the &case group (for diagnosis).
        subroutine try_case(text, ios, msg)
            character(len=*), intent(in) :: text
            integer, intent(out) :: ios
            character(len=*), intent(inout) :: msg
            read (text, nml=case, iostat=ios, iomsg=msg)
        end subroutine try_case
    end subroutine read_case

    !> Read the next `&body` group from unit `u` and validate it.
    subroutine read_body(u, path, ibody, n_bodies, entry, error)
        integer, intent(in) :: u
        character(len=*), intent(in) :: path
        integer, intent(in) :: ibody, n_bodies
        type(body_input_t), intent(out) :: entry
        type(error_t), allocatable, intent(out) :: error
        character(len=32) :: name, material, basis, contact_edge
        real(dp) :: youngs_modulus, poisson_ratio
        integer :: degree_xi, degree_eta, nel_xi, nel_eta, layer_degree, layer_elevations, ios
        real(dp), allocatable :: knots_xi(:), knots_eta(:)
        character(len=512) :: msg
        character(len=:), allocatable :: where
        namelist /body/ name, material, youngs_modulus, poisson_ratio, basis, degree_xi, degree_eta, &
            nel_xi, nel_eta, knots_xi, knots_eta, contact_edge, layer_degree, layer_elevations

        name = ''
        material = ''
        youngs_modulus = unset
        poisson_ratio = unset
        basis = 'nurbs'
        degree_xi = 2
        degree_eta = 2
        nel_xi = 1
        nel_eta = 1
        allocate (knots_xi(max_knots), knots_eta(max_knots))
        knots_xi = unset
        knots_eta = unset
        contact_edge = ''
        layer_degree = 0
        layer_elevations = 0
        read (u, nml=body, iostat=ios, iomsg=msg)
        if (ios /= 0) then
            if (is_iostat_end(ios)) then
                write (msg, '(a,i0,a,i0,a)') ': n_bodies = ', n_bodies, ' but &body group ', ibody, &
                    ' is missing'
                call fatal_error(error, path//trim(msg), error_code%input)
            else
                call group_error(path, 'body', ibody, ios, msg, try_body, error)
            end if
            return
        end if
        write (msg, '(a,i0,a)') ': &body (', ibody, ')'
        where = path//trim(msg)
        if (len_trim(name) == 0) then
            call fatal_error(error, where//': name is required', error_code%input)
            return
        end if
        where = path//": &body '"//trim(name)//"': "
        entry%name = name

        entry%material = material
        select case (trim(material))
        case ('linear', 'neo-hookean')
        case ('')
            call fatal_error(error, where//"material is required ('linear' or 'neo-hookean')", &
                             error_code%input)
            return
        case default
            call fatal_error(error, where//"material = '"//trim(material)// &
                             "' is not one of 'linear', 'neo-hookean'", error_code%input)
            return
        end select
        if (youngs_modulus == unset) then
            call fatal_error(error, where//'youngs_modulus is required', error_code%input)
            return
        end if
        if (.not. (youngs_modulus > 0.0_dp .and. ieee_is_finite(youngs_modulus))) then
            call fatal_error(error, where//'youngs_modulus must be finite and > 0', error_code%input)
            return
        end if
        if (poisson_ratio == unset) then
            call fatal_error(error, where//'poisson_ratio is required', error_code%input)
            return
        end if
        if (.not. (poisson_ratio > -1.0_dp .and. poisson_ratio < 0.5_dp)) then
            call fatal_error(error, where//'poisson_ratio must lie in (-1, 0.5)', error_code%input)
            return
        end if
        entry%youngs_modulus = youngs_modulus
        entry%poisson_ratio = poisson_ratio

        entry%layout%basis = basis
        entry%layout%degree = [degree_xi, degree_eta]
        entry%layout%nel = [nel_xi, nel_eta]
        entry%layout%contact_edge = contact_edge
        entry%layout%layer_degree = layer_degree
        entry%layout%layer_elevations = layer_elevations
        if (degree_xi > 20 .or. degree_eta > 20 .or. layer_degree + layer_elevations > 20) then
            call fatal_error(error, where//'degrees above 20 are not supported', error_code%input)
            return
        end if
        if (nel_xi > max_knots .or. nel_eta > max_knots) then
            call fatal_error(error, where//'nel_xi and nel_eta must be <= 100000', error_code%input)
            return
        end if
        call take_knots(knots_xi, 'knots_xi', where, entry%layout%knots_xi, error)
        if (allocated(error)) return
        call take_knots(knots_eta, 'knots_eta', where, entry%layout%knots_eta, error)
    contains
        !> Read one assignment into the &body group (for diagnosis).
        subroutine try_body(text, ios, msg)
            character(len=*), intent(in) :: text
            integer, intent(out) :: ios
            character(len=*), intent(inout) :: msg
            read (text, nml=body, iostat=ios, iomsg=msg)
        end subroutine try_body
    end subroutine read_body

    !> Every group in the file is known, and there are exactly n_bodies &body groups.
    subroutine check_groups(path, n_bodies, error)
        character(len=*), intent(in) :: path
        integer, intent(in) :: n_bodies
        type(error_t), allocatable, intent(out) :: error
        character(len=32), allocatable :: names(:)
        character(len=128) :: msg
        integer :: i
        call group_names(path, names)
        do i = 1, size(names)
            if (.not. any(known_groups == names(i))) then
                call fatal_error(error, path//': unknown namelist group &'//trim(names(i))// &
                                 ' (known: &case, &body, &solver, &dirichlet, &pressure, &contact)', &
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
        if (count(names == 'case') /= 1 .or. count(names == 'solver') > 1) then
            call fatal_error(error, path//': groups &case and &solver may appear once each', &
                             error_code%input)
            return
        end if
    end subroutine check_groups

    !> Read `&solver`, every `&dirichlet` and every `&pressure` group.
    subroutine read_loads(path, self, error)
        character(len=*), intent(in) :: path
        type(case_t), intent(inout) :: self
        type(error_t), allocatable, intent(out) :: error
        character(len=32), allocatable :: names(:)
        integer :: u, ios, i, nph
        character(len=512) :: msg

        call group_names(path, names)
        open (newunit=u, file=path, status='old', action='read', iostat=ios, iomsg=msg)
        if (ios /= 0) then
            call fatal_error(error, "case file '"//path//"' cannot be read: "//trim(msg), error_code%input)
            return
        end if
        if (any(names == 'solver')) then
            call read_solver(u, path, self%solver, error)
            if (allocated(error)) then
                close (u)
                return
            end if
        else
            self%solver%n_steps = [1]
        end if
        nph = size(self%solver%n_steps)
        allocate (self%dirichlet(count(names == 'dirichlet')))
        rewind (u)
        do i = 1, size(self%dirichlet)
            call read_dirichlet(u, path, i, nph, self, self%dirichlet(i), error)
            if (allocated(error)) exit
        end do
        if (.not. allocated(error)) then
            allocate (self%pressure(count(names == 'pressure')))
            rewind (u)
            do i = 1, size(self%pressure)
                call read_pressure(u, path, i, nph, self, self%pressure(i), error)
                if (allocated(error)) exit
            end do
        end if
        if (.not. allocated(error)) then
            allocate (self%contact(count(names == 'contact')))
            rewind (u)
            do i = 1, size(self%contact)
                call read_contact(u, path, i, self, self%contact(i), error)
                if (allocated(error)) exit
            end do
        end if
        close (u)
    end subroutine read_loads

    subroutine read_solver(u, path, entry, error)
        integer, intent(in) :: u
        character(len=*), intent(in) :: path
        type(solver_input_t), intent(out) :: entry
        type(error_t), allocatable, intent(out) :: error
        integer :: n_steps(max_phases), max_iterations, n_gauss, ios, nph, max_cuts, grow_iterations
        real(dp) :: tol_residual, tol_energy, min_step_fraction
        logical :: predictor
        character(len=16) :: linear_solver, damping
        character(len=512) :: msg
        character(len=:), allocatable :: where
        namelist /solver/ n_steps, max_iterations, tol_residual, tol_energy, n_gauss, &
            min_step_fraction, max_cuts, grow_iterations, predictor, linear_solver, damping

        n_steps = -1
        max_iterations = entry%max_iterations
        tol_residual = entry%tol_residual
        tol_energy = entry%tol_energy
        n_gauss = entry%n_gauss
        min_step_fraction = entry%min_step_fraction
        max_cuts = entry%max_cuts
        grow_iterations = entry%grow_iterations
        predictor = entry%predictor
        linear_solver = entry%linear_solver
        damping = entry%damping
        rewind (u)
        read (u, nml=solver, iostat=ios, iomsg=msg)
        if (ios /= 0) then
            call group_error(path, 'solver', 1, ios, msg, try_solver, error)
            return
        end if
        where = path//': &solver: '
        nph = count(n_steps /= -1)
        if (nph == 0) then
            n_steps(1) = 1
            nph = 1
        end if
        if (any(n_steps(1:nph) == -1)) then
            call fatal_error(error, where//'n_steps must be one list starting at entry 1', error_code%input)
            return
        end if
        if (any(n_steps(1:nph) < 1)) then
            call fatal_error(error, where//'n_steps must be >= 1 in every phase', error_code%input)
            return
        end if
        if (max_iterations < 1) then
            call fatal_error(error, where//'max_iterations must be >= 1', error_code%input)
            return
        end if
        if (.not. (tol_residual > 0.0_dp .and. tol_residual < 1.0_dp)) then
            call fatal_error(error, where//'tol_residual must lie in (0, 1)', error_code%input)
            return
        end if
        if (.not. (tol_energy >= 0.0_dp .and. tol_energy < 1.0_dp)) then
            call fatal_error(error, where//'tol_energy must lie in [0, 1)', error_code%input)
            return
        end if
        if (n_gauss < 0 .or. n_gauss > 30) then
            call fatal_error(error, where//'n_gauss must be between 0 (automatic) and 30', error_code%input)
            return
        end if
        if (.not. (min_step_fraction > 0.0_dp .and. min_step_fraction <= 1.0_dp)) then
            call fatal_error(error, where//'min_step_fraction must lie in (0, 1]', error_code%input)
            return
        end if
        if (max_cuts < 0) then
            call fatal_error(error, where//'max_cuts must be >= 0', error_code%input)
            return
        end if
        if (grow_iterations < 0) then
            call fatal_error(error, where//'grow_iterations must be >= 0', error_code%input)
            return
        end if
        if (trim(linear_solver) /= 'direct' .and. trim(linear_solver) /= 'multigrid') then
            call fatal_error(error, where//"linear_solver = '"//trim(linear_solver)// &
                             "': must be 'direct' or 'multigrid'", error_code%input)
            return
        end if
        if (trim(damping) /= 'residual' .and. trim(damping) /= 'natural') then
            call fatal_error(error, where//"damping = '"//trim(damping)// &
                             "': must be 'residual' or 'natural'", error_code%input)
            return
        end if
        if (trim(damping) == 'natural' .and. trim(linear_solver) == 'multigrid') then
            call fatal_error(error, where//"damping = 'natural' needs linear_solver = 'direct' "// &
                             "(its test solves with the last factorization)", error_code%input)
            return
        end if
        entry%linear_solver = linear_solver
        entry%damping = damping
        entry%n_steps = n_steps(1:nph)
        entry%min_step_fraction = min_step_fraction
        entry%max_cuts = max_cuts
        entry%grow_iterations = grow_iterations
        entry%predictor = predictor
        entry%max_iterations = max_iterations
        entry%tol_residual = tol_residual
        entry%tol_energy = tol_energy
        entry%n_gauss = n_gauss
    contains
        subroutine try_solver(text, ios, msg)
            character(len=*), intent(in) :: text
            integer, intent(out) :: ios
            character(len=*), intent(inout) :: msg
            read (text, nml=solver, iostat=ios, iomsg=msg)
        end subroutine try_solver
    end subroutine read_solver

    !> Index of body `name` in the case, 0 if none.
    pure integer function body_index(self, name)
        type(case_t), intent(in) :: self
        character(len=*), intent(in) :: name
        integer :: i
        body_index = 0
        do i = 1, size(self%bodies)
            if (trim(self%bodies(i)%name) == trim(name)) body_index = i
        end do
    end function body_index

    subroutine read_dirichlet(u, path, k, nph, self, entry, error)
        integer, intent(in) :: u, k, nph
        character(len=*), intent(in) :: path
        type(case_t), intent(in) :: self
        type(dirichlet_input_t), intent(out) :: entry
        type(error_t), allocatable, intent(out) :: error
        character(len=32) :: body, edge
        logical :: fix_x, fix_y
        real(dp) :: ux(max_phases), uy(max_phases)
        integer :: ios
        character(len=512) :: msg
        character(len=:), allocatable :: where
        namelist /dirichlet/ body, edge, fix_x, fix_y, ux, uy

        body = ''
        edge = ''
        fix_x = .false.
        fix_y = .false.
        ux = unset
        uy = unset
        read (u, nml=dirichlet, iostat=ios, iomsg=msg)
        if (ios /= 0) then
            call group_error(path, 'dirichlet', k, ios, msg, try_dirichlet, error)
            return
        end if
        write (msg, '(a,i0,a)') ': &dirichlet (', k, '): '
        where = path//trim(msg)//' '
        call check_body_edge(self, body, edge, where, error)
        if (allocated(error)) return
        if (.not. (fix_x .or. fix_y)) then
            call fatal_error(error, where//'fix_x or fix_y must be .true.', error_code%input)
            return
        end if
        entry%body = body
        entry%edge = edge
        entry%fix = [fix_x, fix_y]
        allocate (entry%values(2, nph))
        call phase_values(ux, fix_x, 'ux', where, nph, entry%values(1, :), error)
        if (allocated(error)) return
        call phase_values(uy, fix_y, 'uy', where, nph, entry%values(2, :), error)
    contains
        subroutine try_dirichlet(text, ios, msg)
            character(len=*), intent(in) :: text
            integer, intent(out) :: ios
            character(len=*), intent(inout) :: msg
            read (text, nml=dirichlet, iostat=ios, iomsg=msg)
        end subroutine try_dirichlet
    end subroutine read_dirichlet

    subroutine read_pressure(u, path, k, nph, self, entry, error)
        integer, intent(in) :: u, k, nph
        character(len=*), intent(in) :: path
        type(case_t), intent(in) :: self
        type(pressure_input_t), intent(out) :: entry
        type(error_t), allocatable, intent(out) :: error
        character(len=32) :: body, edge
        real(dp) :: p(max_phases)
        integer :: ios
        character(len=512) :: msg
        character(len=:), allocatable :: where
        namelist /pressure/ body, edge, p

        body = ''
        edge = ''
        p = unset
        read (u, nml=pressure, iostat=ios, iomsg=msg)
        if (ios /= 0) then
            call group_error(path, 'pressure', k, ios, msg, try_pressure, error)
            return
        end if
        write (msg, '(a,i0,a)') ': &pressure (', k, '): '
        where = path//trim(msg)//' '
        call check_body_edge(self, body, edge, where, error)
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
            read (text, nml=pressure, iostat=ios, iomsg=msg)
        end subroutine try_pressure
    end subroutine read_pressure

    subroutine read_contact(u, path, k, self, entry, error)
        integer, intent(in) :: u, k
        character(len=*), intent(in) :: path
        type(case_t), intent(in) :: self
        type(contact_input_t), intent(out) :: entry
        type(error_t), allocatable, intent(out) :: error
        character(len=32) :: slave, master
        character(len=16) :: method
        real(dp) :: rigid_point(2), rigid_normal(2), penalty_normal, penalty_tangent, friction, e_max
        integer :: n_gauss, ios, ib
        character(len=512) :: msg
        character(len=:), allocatable :: where
        namelist /contact/ slave, master, rigid_point, rigid_normal, penalty_normal, penalty_tangent, &
            friction, n_gauss, method

        slave = ''
        master = ''
        rigid_point = 0.0_dp
        rigid_normal = [0.0_dp, 1.0_dp]
        penalty_normal = unset
        penalty_tangent = unset
        friction = 0.0_dp
        n_gauss = 0
        method = 'gpts'
        read (u, nml=contact, iostat=ios, iomsg=msg)
        if (ios /= 0) then
            call group_error(path, 'contact', k, ios, msg, try_contact, error)
            return
        end if
        write (msg, '(a,i0,a)') ': &contact (', k, '): '
        where = path//trim(msg)//' '
        ib = body_index(self, slave)
        if (ib == 0) then
            call fatal_error(error, where//"slave = '"//trim(slave)//"' is not a body of the case", &
                             error_code%input)
            return
        end if
        if (len_trim(self%bodies(ib)%layout%contact_edge) == 0) then
            call fatal_error(error, where//"slave = '"//trim(slave)//"' has no contact_edge in its &body", &
                             error_code%input)
            return
        end if
        if (trim(master) /= 'rigid') then
            ib = body_index(self, master)
            if (ib == 0) then
                call fatal_error(error, where//"master = '"//trim(master)// &
                                 "' is neither a body of the case nor 'rigid'", error_code%input)
                return
            end if
            if (trim(master) == trim(slave)) then
                call fatal_error(error, where//'master and slave must be different bodies', error_code%input)
                return
            end if
            if (len_trim(self%bodies(ib)%layout%contact_edge) == 0) then
                call fatal_error(error, where//"master = '"//trim(master)// &
                                 "' has no contact_edge in its &body", error_code%input)
                return
            end if
        else
            if (.not. all(ieee_is_finite(rigid_point)) .or. .not. all(ieee_is_finite(rigid_normal)) .or. &
                norm2(rigid_normal) <= 0.0_dp) then
                call fatal_error(error, where//'rigid_point must be finite and rigid_normal finite and '// &
                                 'nonzero', error_code%input)
                return
            end if
        end if
        if (penalty_normal == unset) then
            call fatal_error(error, where//'penalty_normal is required', error_code%input)
            return
        end if
        if (.not. (penalty_normal > 0.0_dp .and. ieee_is_finite(penalty_normal))) then
            call fatal_error(error, where//'penalty_normal must be finite and > 0', error_code%input)
            return
        end if
        if (.not. (friction >= 0.0_dp .and. ieee_is_finite(friction))) then
            call fatal_error(error, where//'friction must be finite and >= 0', error_code%input)
            return
        end if
        if (penalty_tangent == unset) penalty_tangent = penalty_normal
        if (friction > 0.0_dp .and. .not. (penalty_tangent > 0.0_dp .and. ieee_is_finite(penalty_tangent))) then
            call fatal_error(error, where//'penalty_tangent must be finite and > 0', error_code%input)
            return
        end if
        if (n_gauss < 0 .or. n_gauss > 30) then
            call fatal_error(error, where//'n_gauss must be between 0 (automatic) and 30', error_code%input)
            return
        end if
        if (trim(method) /= 'gpts' .and. trim(method) /= 'mortar') then
            call fatal_error(error, where//"method = '"//trim(method)//"' is not one of 'gpts', 'mortar'", &
                             error_code%input)
            return
        end if
        ! conditioning: a penalty above 1e12 x E leaves the stiffness matrix with fewer
        ! than 4 significant digits in double precision
        e_max = self%bodies(body_index(self, slave))%youngs_modulus
        if (trim(master) /= 'rigid') e_max = max(e_max, self%bodies(body_index(self, master))%youngs_modulus)
        if (penalty_normal > 1.0e12_dp*e_max .or. (friction > 0.0_dp .and. penalty_tangent > 1.0e12_dp*e_max)) then
            call fatal_error(error, where//'penalty_normal and penalty_tangent must not exceed 1e12 times '// &
                             "the largest Young's modulus of the two bodies (the stiffness matrix would "// &
                             'lose its significant digits)', error_code%input)
            return
        end if
        entry = contact_input_t(slave, master, rigid_point, rigid_normal, penalty_normal, penalty_tangent, &
                                friction, n_gauss, method)
    contains
        subroutine try_contact(text, ios, msg)
            character(len=*), intent(in) :: text
            integer, intent(out) :: ios
            character(len=*), intent(inout) :: msg
            read (text, nml=contact, iostat=ios, iomsg=msg)
        end subroutine try_contact
    end subroutine read_contact

    !> A load group names a body of the case and an edge (checked against the
    !> body's edges once it is discretized).
    subroutine check_body_edge(self, body, edge, where, error)
        type(case_t), intent(in) :: self
        character(len=*), intent(in) :: body, edge, where
        type(error_t), allocatable, intent(out) :: error
        if (body_index(self, body) == 0) then
            call fatal_error(error, where//"body = '"//trim(body)//"' is not a body of the case", &
                             error_code%input)
            return
        end if
        if (len_trim(edge) == 0) call fatal_error(error, where//'edge is required', error_code%input)
    end subroutine check_body_edge

    !> Values at the end of each phase: exactly one per phase when given; all
    !> zero when the component is prescribed but no value is given.
    subroutine phase_values(raw, used, name, where, nph, values, error)
        real(dp), intent(in) :: raw(:)
        logical, intent(in) :: used
        character(len=*), intent(in) :: name, where
        integer, intent(in) :: nph
        real(dp), intent(out) :: values(:)
        type(error_t), allocatable, intent(out) :: error
        integer :: n
        character(len=128) :: msg
        values = 0.0_dp
        n = count(raw /= unset)
        if (n == 0) return
        if (.not. used) then
            call fatal_error(error, where//name//' is given but its component is not fixed', &
                             error_code%input)
            return
        end if
        if (n /= nph .or. any(raw(1:nph) == unset)) then
            write (msg, '(a,i0,a)') ' needs one value per load phase (', nph, ' phases in &solver n_steps)'
            call fatal_error(error, where//name//trim(msg), error_code%input)
            return
        end if
        if (.not. all(ieee_is_finite(raw(1:nph)))) then
            call fatal_error(error, where//name//' must be finite', error_code%input)
            return
        end if
        values = raw(1:nph)
    end subroutine phase_values

    !> The entries the file set, which must be a leading block of the array.
    subroutine take_knots(raw, name, where, knots, error)
        real(dp), intent(in) :: raw(:)
        character(len=*), intent(in) :: name, where
        real(dp), allocatable, intent(out) :: knots(:)
        type(error_t), allocatable, intent(out) :: error
        integer :: n
        n = count(raw /= unset)
        if (n == 0) return
        if (any(raw(1:n) == unset)) then
            call fatal_error(error, where//name//' must be given as one list starting at entry 1', &
                             error_code%input)
            return
        end if
        if (.not. all(ieee_is_finite(raw(1:n)))) then
            call fatal_error(error, where//name//' must be finite', error_code%input)
            return
        end if
        knots = raw(1:n)
    end subroutine take_knots

end module voiga_io_case
