!> The case file: a Fortran namelist with a `&case` group and one `&body` group
!> per body (reference in docs/formats.md). Every value is validated and every
!> error names the file, the group and the variable.
module voiga_io_case
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_discretization_layout, only: layout_t
    implicit none
    private

    public :: case_t, body_input_t, read_case, resolve_path

    !> Most explicit knots one direction of one body may list.
    integer, parameter :: max_knots = 100000
    !> Most bodies in a case.
    integer, parameter :: max_bodies = 16
    !> Marks a namelist array entry the file did not set.
    real(dp), parameter :: unset = -huge(1.0_dp)

    !> One body as the case describes it.
    type :: body_input_t
        character(len=32) :: name = ''
        !> 'linear' (small strain) or 'neo-hookean' (finite strain).
        character(len=32) :: material = ''
        real(dp) :: youngs_modulus = 0.0_dp
        real(dp) :: poisson_ratio = 0.0_dp
        type(layout_t) :: layout
    end type body_input_t

    !> A case.
    type :: case_t
        !> The case file and its folder (with trailing '/', or '').
        character(len=:), allocatable :: path, dir
        character(len=:), allocatable :: title, scene, mesh, layout
        !> Geometry and output files, resolved against `dir`.
        character(len=:), allocatable :: geometry, output
        type(body_input_t), allocatable :: bodies(:)
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

    !> Error for a namelist group that could not be read. The group's text is
    !> re-read one assignment at a time through `try` to name the variable at fault.
    subroutine group_error(path, group, occurrence, ios, msg, try, error)
        character(len=*), intent(in) :: path, group
        !> Which occurrence of the group failed (1 for the first).
        integer, intent(in) :: occurrence
        integer, intent(in) :: ios
        character(len=*), intent(in) :: msg
        interface
            subroutine try(text, ios, msg)
                character(len=*), intent(in) :: text
                integer, intent(out) :: ios
                character(len=*), intent(inout) :: msg
            end subroutine try
        end interface
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: assignments(:), name
        character(len=512) :: msg1
        integer :: k, ios1, eq

        if (is_iostat_end(ios)) then
            call fatal_error(error, path//': group &'//group//' is missing', error_code%input)
            return
        end if
        call group_assignments(path, group, occurrence, assignments)
        do k = 1, size(assignments)
            msg1 = ''
            call try('&'//group//' '//assignments(k)//' /', ios1, msg1)
            if (ios1 == 0) cycle
            eq = index(assignments(k), '=')
            name = adjustl(assignments(k)(1:max(eq - 1, 0)))
            name = trim(name)
            if (index(msg1, 'Cannot match namelist object name '//name) > 0 .or. &
                index(msg1, 'Cannot match namelist object name '//lower(name)) > 0) then
                call fatal_error(error, path//': &'//group//": unknown variable '"//name//"'", &
                                 error_code%input)
            else
                call fatal_error(error, path//': &'//group//": variable '"//name// &
                                 "' has a value of the wrong type or form: "// &
                                 trim(adjustl(assignments(k)(eq + 1:)))//' ('//trim(msg1)//')', &
                                 error_code%input)
            end if
            return
        end do
        call fatal_error(error, path//': &'//group//': '//trim(msg), error_code%input)
    end subroutine group_error

    !> The `name = value` assignments of the `occurrence`-th group `group` in file
    !> `path`, one per entry (continuation lines joined). Quoted '=' and '/' are not
    !> special-cased beyond what our case files contain; good enough for diagnosis.
    subroutine group_assignments(path, group, occurrence, assignments)
        character(len=*), intent(in) :: path, group
        integer, intent(in) :: occurrence
        character(len=:), allocatable, intent(out) :: assignments(:)
        character(len=4096) :: line
        character(len=4096), allocatable :: items(:)
        character(len=:), allocatable :: t
        integer :: u, ios, seen, n, width
        logical :: inside

        allocate (items(0))
        n = 0
        seen = 0
        inside = .false.
        open (newunit=u, file=path, status='old', action='read', iostat=ios)
        if (ios /= 0) then
            allocate (character(len=1) :: assignments(0))
            return
        end if
        do
            read (u, '(a)', iostat=ios) line
            if (ios /= 0) exit
            t = trim(adjustl(strip_comment(line)))
            if (.not. inside) then
                if (len(t) > len(group) .and. lower(t(1:min(len(t), len(group) + 1))) == '&'//lower(group)) then
                    seen = seen + 1
                    inside = seen == occurrence
                    t = trim(adjustl(t(len(group) + 2:)))
                    if (.not. inside) cycle
                else
                    cycle
                end if
            end if
            if (len(t) == 0) cycle
            if (t(len(t):len(t)) == '/') then
                t = t(1:len(t) - 1)
                inside = .false.
            end if
            if (len_trim(t) > 0) then
                if (index(t, '=') > 0 .or. n == 0) then
                    items = [character(len=4096) :: items, t]
                    n = n + 1
                else
                    items(n) = trim(items(n))//' '//t
                end if
            end if
            if (.not. inside .and. seen >= occurrence) exit
        end do
        close (u)
        width = 1
        if (n > 0) width = max(1, maxval(len_trim(items)))
        allocate (character(len=width) :: assignments(n))
        assignments = items
    end subroutine group_assignments

    !> The line without a trailing '!' comment (outside quotes).
    pure function strip_comment(line) result(code)
        character(len=*), intent(in) :: line
        character(len=:), allocatable :: code
        integer :: i
        character :: quote
        quote = ' '
        do i = 1, len(line)
            if (quote /= ' ') then
                if (line(i:i) == quote) quote = ' '
            else if (line(i:i) == "'" .or. line(i:i) == '"') then
                quote = line(i:i)
            else if (line(i:i) == '!') then
                code = line(1:i - 1)
                return
            end if
        end do
        code = line
    end function strip_comment

    !> Lower-case ASCII.
    pure function lower(text) result(low)
        character(len=*), intent(in) :: text
        character(len=len(text)) :: low
        integer :: i
        low = text
        do i = 1, len(text)
            if (text(i:i) >= 'A' .and. text(i:i) <= 'Z') low(i:i) = achar(iachar(text(i:i)) + 32)
        end do
    end function lower

end module voiga_io_case
