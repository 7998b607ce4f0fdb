!> The mechanical model: bodies (discretization + material + DOF offset),
!> prescribed displacements and pressures with their load histories, and the
!> contact pairs. Physics only: how it is solved is the solver's (`&solver`).
module voiga_model
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_discretization_patch, only: discretization_t, boundary_cps, boundary_index, boundary_word
    use voiga_model_body, only: body_t, body_settings_t, new_body
    use voiga_model_loads, only: dirichlet_t, pressure_t, dirichlet_settings_t, pressure_settings_t, phase_value, &
                                 obstacle_motion_t, phase_friction_t, phase_of
    use voiga_contact_pair, only: pair_slot_t
    use voiga_contact_factory, only: contact_settings_t, new_contact_pair, rigid_normal_of, default_method
    use voiga_contact_surface, only: contact_surface_t, new_contact_surface
    use voiga_contact_master, only: contact_master_t
    use voiga_contact_master_rigid, only: rigid_line_t, new_rigid_line
    use voiga_contact_master_nurbs, only: nurbs_master_t, new_nurbs_master
    use voiga_contact_master_face, only: face_master_t, new_face_master, rigid_surface_t, new_rigid_surface
    use voiga_contact_master_curve, only: rigid_curve_t, new_rigid_curve
    implicit none
    private

    public :: model_t, new_model, set_prescribed, reference_coordinates, set_contact_time, contact_reach, plane_modulus

    !> Everything the solver needs to know of the physics.
    type :: model_t
        type(body_t), allocatable :: bodies(:)
        !> Spatial dimension (the first body's; every body has the same; DOFs per
        !> control point), and the number of DOFs.
        integer :: nsd = 2
        integer :: ndof = 0
        type(dirichlet_t), allocatable :: dirichlet(:)
        type(pressure_t), allocatable :: pressure(:)
        !> Is any body finite-strain?
        logical :: finite_strain = .false.
        !> fixed(dof): is the DOF prescribed? shape [ndof]
        logical, allocatable :: fixed(:)
        !> Contact pairs, each of its method's type (their friction history changes
        !> as steps converge).
        type(pair_slot_t), allocatable :: pairs(:)
        !> The prescribed motions of rigid masters (only those that move).
        type(obstacle_motion_t), allocatable :: motions(:)
        !> The friction coefficients of pairs whose friction changes with the phase.
        type(phase_friction_t), allocatable :: frictions(:)
    end type model_t

contains

    !> Build the model of bodies `bodies` discretized by `discs` (one each, in
    !> order), with `n_gauss` points per direction (0: automatic), the loads and the
    !> contact pairs. The names in the loads and pairs must be valid (the case
    !> reader checks them); an unknown edge is an error.
    subroutine new_model(self, bodies, discs, n_gauss, dirichlet, pressure, contact, error)
        type(model_t), intent(out) :: self
        type(body_settings_t), intent(in) :: bodies(:)
        type(discretization_t), intent(in) :: discs(:)
        integer, intent(in) :: n_gauss
        type(dirichlet_settings_t), intent(in) :: dirichlet(:)
        type(pressure_settings_t), intent(in) :: pressure(:)
        type(contact_settings_t), intent(in) :: contact(:)
        type(error_t), allocatable, intent(out) :: error
        integer :: i, k

        allocate (self%bodies(size(bodies)))
        self%ndof = 0
        if (size(discs) > 0) self%nsd = discs(1)%nsd
        do i = 1, size(bodies)
            call new_body(self%bodies(i), bodies(i), discs(i), self%ndof, n_gauss, error)
            if (allocated(error)) return
            self%ndof = self%ndof + self%nsd*self%bodies(i)%disc%ncp
            self%finite_strain = self%finite_strain .or. self%bodies(i)%mat%finite_strain
        end do
        allocate (self%fixed(self%ndof))
        self%fixed = .false.
        allocate (self%dirichlet(size(dirichlet)))
        do k = 1, size(dirichlet)
            call new_dirichlet(self, dirichlet(k), self%dirichlet(k), error)
            if (allocated(error)) return
        end do
        allocate (self%pressure(size(pressure)))
        do k = 1, size(pressure)
            call new_pressure(self, pressure(k), self%pressure(k), error)
            if (allocated(error)) return
        end do
        allocate (self%pairs(size(contact)))
        do k = 1, size(contact)
            call new_pair(self, contact(k), self%pairs(k), error)
            if (allocated(error)) return
        end do
        allocate (self%motions(count([(allocated(contact(k)%rigid_motion), k=1, size(contact))])))
        i = 0
        do k = 1, size(contact)
            if (.not. allocated(contact(k)%rigid_motion)) cycle
            i = i + 1
            self%motions(i)%pair = k
            self%motions(i)%values = contact(k)%rigid_motion
        end do
        allocate (self%frictions(count([(allocated(contact(k)%friction_phases), k=1, size(contact))])))
        i = 0
        do k = 1, size(contact)
            if (.not. allocated(contact(k)%friction_phases)) cycle
            i = i + 1
            self%frictions(i)%pair = k
            self%frictions(i)%values = contact(k)%friction_phases
        end do
    end subroutine new_model

    !> A prescribed displacement on its edge's control points; marks them fixed.
    subroutine new_dirichlet(self, inp, d, error)
        type(model_t), intent(inout) :: self
        type(dirichlet_settings_t), intent(in) :: inp
        type(dirichlet_t), intent(out) :: d
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: cps(:)
        integer :: ib, c
        ib = find_body(self, inp%body)
        call boundary_cps(self%bodies(ib)%disc, inp%edge, cps, error)
        if (allocated(error)) then
            error%message = 'dirichlet: '//error%message//" of body '"//trim(inp%body)//"'"
            return
        end if
        if (any(inp%fix(self%nsd + 1:))) then
            call fatal_error(error, "dirichlet: fix_z on the plane body '"//trim(inp%body)// &
                             "' (a plane body has the components x and y only)", error_code%input)
            return
        end if
        d%body = ib
        d%edge = inp%edge
        d%fix = inp%fix
        d%values = inp%values
        allocate (d%dofs(self%nsd, size(cps)))
        do c = 1, self%nsd
            d%dofs(c, :) = self%bodies(ib)%dof0 + self%nsd*(cps - 1) + c
            if (d%fix(c)) self%fixed(d%dofs(c, :)) = .true.
        end do
    end subroutine new_dirichlet

    !> A pressure on its edge (by the edge's index in the oriented patch).
    subroutine new_pressure(self, inp, p, error)
        type(model_t), intent(in) :: self
        type(pressure_settings_t), intent(in) :: inp
        type(pressure_t), intent(out) :: p
        type(error_t), allocatable, intent(out) :: error
        integer :: ib, i
        ib = find_body(self, inp%body)
        p%body = ib
        p%edge = boundary_index(self%bodies(ib)%disc, inp%edge)
        if (p%edge == 0) then
            call fatal_error(error, 'pressure: no '//boundary_word(self%nsd)//" named '"// &
                             trim(inp%edge)//"' on body '"//trim(inp%body)//"'", error_code%input)
            return
        end if
        p%values = inp%values
    end subroutine new_pressure

    !> The slave edge and the master of the pair `inp` describes, from the bodies,
    !> and the pair the contact factory builds on them.
    subroutine new_pair(self, inp, slot, error)
        type(model_t), intent(in) :: self
        type(contact_settings_t), intent(in) :: inp
        type(pair_slot_t), intent(out) :: slot
        type(error_t), allocatable, intent(out) :: error
        type(contact_surface_t) :: slave
        class(contact_master_t), allocatable :: master
        type(rigid_line_t) :: rigid
        type(rigid_curve_t) :: curve
        type(nurbs_master_t) :: body_master
        type(face_master_t) :: face_master
        type(rigid_surface_t) :: surface
        type(contact_settings_t) :: settings
        integer :: ib, im

        ib = find_body(self, inp%slave)
        im = 0
        call new_contact_surface(slave, self%bodies(ib)%disc, self%bodies(ib)%dof0)
        if (trim(inp%master) == 'rigid' .and. len_trim(inp%rigid_curve) > 0) then
            if (.not. allocated(inp%curve%w)) then
                call fatal_error(error, "contact: the rigid curve '"//trim(inp%rigid_curve)// &
                                 "' was not read", error_code%input)
                return
            end if
            call new_rigid_curve(curve, inp%curve)
            curve%name = inp%rigid_curve
            allocate (master, source=curve)
        else if (trim(inp%master) == 'rigid' .and. len_trim(inp%rigid_surface) > 0) then
            call new_rigid_surface(surface, inp%surface)
            surface%name = inp%rigid_surface
            allocate (master, source=surface)
        else if (trim(inp%master) == 'rigid') then
            call new_rigid_line(rigid, inp%rigid_point(1:self%nsd), rigid_normal_of(inp, self%nsd))
            allocate (master, source=rigid)
        else if (self%nsd == 3) then
            im = find_body(self, inp%master)
            call new_face_master(face_master, self%bodies(im)%disc, self%bodies(im)%dof0)
            allocate (master, source=face_master)
        else
            im = find_body(self, inp%master)
            call new_nurbs_master(body_master, self%bodies(im)%disc, self%bodies(im)%dof0)
            allocate (master, source=body_master)
        end if
        settings = inp
        if (.not. inp%method_given) settings%method = default_method(trim(inp%master) == 'rigid', self%nsd)
        call new_contact_pair(slot%pair, settings, slave, master, [ib, im], plane_modulus(self, ib, im), &
                              self%ndof, error)
    end subroutine new_pair

    !> The plane-strain modulus E* of a pair: 1/E* = sum over its deformable bodies
    !> (the master 0: rigid) of (1 - nu^2)/E.
    pure real(dp) function plane_modulus(self, slave, master) result(e_star)
        type(model_t), intent(in) :: self
        integer, intent(in) :: slave, master
        real(dp) :: compliance
        integer :: ib, k
        compliance = 0.0_dp
        do k = 1, 2
            ib = merge(slave, master, k == 1)
            if (ib == 0) cycle
            associate (mat => self%bodies(ib)%mat)
                compliance = compliance + (1.0_dp - mat%poisson_ratio**2)/mat%youngs_modulus
            end associate
        end do
        e_star = 1.0_dp/compliance
    end function plane_modulus

    pure integer function find_body(self, name) result(ib)
        type(model_t), intent(in) :: self
        character(len=*), intent(in) :: name
        integer :: i
        ib = 0
        do i = 1, size(self%bodies)
            if (trim(self%bodies(i)%name) == trim(name)) ib = i
        end do
    end function find_body

    !> Put the prescribed values at load time `t` into `u`.
    pure subroutine set_prescribed(model, t, u)
        type(model_t), intent(in) :: model
        real(dp), intent(in) :: t
        real(dp), intent(inout) :: u(:)
        integer :: j, c
        do j = 1, size(model%dirichlet)
            do c = 1, size(model%dirichlet(j)%dofs, 1)
                if (model%dirichlet(j)%fix(c)) then
                    u(model%dirichlet(j)%dofs(c, :)) = phase_value(model%dirichlet(j)%values(c, :), t)
                end if
            end do
        end do
    end subroutine set_prescribed

    !> The contact pairs at load time `t`: where the rigid masters that move are
    !> (`&contact rigid_ux, rigid_uy`), and the friction coefficient of the phase of
    !> the pairs whose friction changes with it.
    pure subroutine set_contact_time(model, t)
        type(model_t), intent(inout) :: model
        real(dp), intent(in) :: t
        integer :: k, c
        do k = 1, size(model%frictions)
            associate (f => model%frictions(k))
                call model%pairs(f%pair)%pair%set_friction(f%values(phase_of(t, size(f%values))))
            end associate
        end do
        do k = 1, size(model%motions)
            associate (m => model%motions(k))
                call model%pairs(m%pair)%pair%move_master([(phase_value(m%values(c, :), t), &
                                                             c=1, model%nsd)])
            end associate
        end do
    end subroutine set_contact_time

    !> Reference coordinates of the control point of every DOF; shape: [ndof]
    !> (2(a-1)+i of body b at dof0 + 2(a-1) + i, as the displacement).
    pure function reference_coordinates(model) result(x0)
        type(model_t), intent(in) :: model
        real(dp), allocatable :: x0(:)
        integer :: ib, n
        allocate (x0(model%ndof))
        x0 = 0.0_dp
        do ib = 1, size(model%bodies)
            n = size(model%bodies(ib)%disc%x)
            x0(model%bodies(ib)%dof0 + 1:model%bodies(ib)%dof0 + n) = reshape(model%bodies(ib)%disc%x, [n])
        end do
    end function reference_coordinates

    !> The DOFs contact can couple (ascending, once each): those of every pair's
    !> slave control points on the contact edge and of all control points of a
    !> deformable master (whatever part of it the pattern holds now).
    pure function contact_reach(model) result(dofs)
        type(model_t), intent(in) :: model
        integer, allocatable :: dofs(:)
        logical :: mark(model%ndof)
        integer :: ip, i
        mark = .false.
        do ip = 1, size(model%pairs)
            mark(model%pairs(ip)%pair%master%all_dofs()) = .true.
            mark(pack(model%pairs(ip)%pair%slave%dofs, .true.)) = .true.
        end do
        dofs = pack([(i, i=1, model%ndof)], mark)
    end function contact_reach

end module voiga_model
