!> The mechanical model: bodies (discretization + material + DOF offset),
!> prescribed displacements and pressures with their load histories.
module voiga_model
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_io_case, only: case_t
    use voiga_material, only: material_t
    use voiga_material_factory, only: new_material
    use voiga_discretization_patch, only: discretization_t, edge_cps
    use voiga_element_quadrature, only: gauss_legendre
    use voiga_element_solid, only: element_points_t, reference_gradients
    use voiga_discretization_element, only: element_basis, element_nfun
    use voiga_contact_pair, only: pair_slot_t
    use voiga_contact_factory, only: contact_settings_t, new_contact_pair
    use voiga_contact_surface, only: new_contact_surface
    use voiga_contact_master_rigid, only: rigid_line_t, new_rigid_line
    use voiga_contact_master_nurbs, only: nurbs_master_t, new_nurbs_master
    implicit none
    private

    public :: model_t, body_t, dirichlet_t, pressure_t, new_model, phase_value, n_total_steps, &
              step_time, body_points

    !> A deformable body.
    type :: body_t
        character(len=32) :: name = ''
        type(discretization_t) :: disc
        class(material_t), allocatable :: mat
        !> Global DOFs of this body are dof0 + 1 .. dof0 + 2 ncp (2(a-1)+i for point a, component i).
        integer :: dof0 = 0
        !> Gauss points per direction used for this body [xi, eta], and the points
        !> and weights on [-1, 1] along xi (gx, wx) and eta (ge, we).
        integer :: n_gauss(2) = 0
        real(dp), allocatable :: gx(:), wx(:), ge(:), we(:)
        !> Every element's quadrature points (reference gradients, weights) [nel].
        type(element_points_t), allocatable :: points(:)
    end type body_t

    !> Prescribed displacement on the control points of an edge.
    type :: dirichlet_t
        integer :: body = 0
        character(len=32) :: edge = ''
        !> Global DOF numbers of the edge's x and y components, shape [2, ncp_edge].
        integer, allocatable :: dofs(:, :)
        logical :: fix(2) = .false.
        !> Value at the end of each phase [2, n_phases].
        real(dp), allocatable :: values(:, :)
    end type dirichlet_t

    !> Pressure on an edge (reference configuration, positive into the body).
    type :: pressure_t
        integer :: body = 0
        !> Edge index 1..4 (xi0, xi1, eta0, eta1) of the oriented patch.
        integer :: edge = 0
        real(dp), allocatable :: values(:)
    end type pressure_t

    !> Everything the solver needs.
    type :: model_t
        type(body_t), allocatable :: bodies(:)
        integer :: ndof = 0
        type(dirichlet_t), allocatable :: dirichlet(:)
        type(pressure_t), allocatable :: pressure(:)
        !> Steps per phase.
        integer, allocatable :: n_steps(:)
        integer :: max_iterations = 25
        real(dp) :: tol_residual = 1.0e-10_dp, tol_energy = 1.0e-20_dp
        !> Linear solver: 'direct' or 'multigrid' (`&solver linear_solver`).
        character(len=16) :: linear_solver = 'direct'
        !> Newton step damping: 'residual' or 'natural' (`&solver damping`).
        character(len=16) :: damping = 'residual'
        !> Is any body finite-strain?
        logical :: finite_strain = .false.
        !> fixed(dof): is the DOF prescribed? shape [ndof]
        logical, allocatable :: fixed(:)
        !> Contact pairs, each of its method's type (their friction history changes
        !> as steps converge).
        type(pair_slot_t), allocatable :: pairs(:)
    end type model_t

contains

    !> Build the model of `case` from its discretized bodies `discs` (moved in).
    subroutine new_model(self, case, discs, error)
        type(model_t), intent(out) :: self
        type(case_t), intent(in) :: case
        type(discretization_t), intent(inout) :: discs(:)
        type(error_t), allocatable, intent(out) :: error
        integer :: i, k, ib, ie, ng
        integer, allocatable :: cps(:)
        character(len=64) :: buf

        allocate (self%bodies(size(case%bodies)))
        self%ndof = 0
        do i = 1, size(case%bodies)
            associate (b => self%bodies(i), inp => case%bodies(i))
                b%name = inp%name
                b%disc = discs(i)
                call new_material(b%mat, inp%material, inp%youngs_modulus, inp%poisson_ratio, error)
                if (allocated(error)) return
                b%dof0 = self%ndof
                self%ndof = self%ndof + 2*b%disc%ncp
                ng = case%solver%n_gauss
                if (ng > 0) then
                    b%n_gauss = ng
                else
                    ! degree + 1 per direction; the VO row needs the layer's degree along xi
                    b%n_gauss(1) = b%disc%bulk%degree(1) + 1
                    if (b%disc%has_layer) b%n_gauss(1) = max(b%n_gauss(1), b%disc%layer%degree + 1)
                    b%n_gauss(2) = b%disc%bulk%degree(2) + 1
                end if
                allocate (b%gx(b%n_gauss(1)), b%wx(b%n_gauss(1)), b%ge(b%n_gauss(2)), b%we(b%n_gauss(2)))
                call gauss_legendre(b%n_gauss(1), b%gx, b%wx)
                call gauss_legendre(b%n_gauss(2), b%ge, b%we)
                call body_points(b)
                self%finite_strain = self%finite_strain .or. b%mat%finite_strain
            end associate
        end do
        self%n_steps = case%solver%n_steps
        self%max_iterations = case%solver%max_iterations
        self%tol_residual = case%solver%tol_residual
        self%tol_energy = case%solver%tol_energy
        self%linear_solver = case%solver%linear_solver
        self%damping = case%solver%damping

        allocate (self%fixed(self%ndof))
        self%fixed = .false.
        allocate (self%dirichlet(size(case%dirichlet)))
        do k = 1, size(case%dirichlet)
            ib = find_body(self, case%dirichlet(k)%body)
            call edge_cps(self%bodies(ib)%disc, case%dirichlet(k)%edge, cps, error)
            if (allocated(error)) then
                write (buf, '(a,i0,a)') ': &dirichlet (', k, '): edge: '
                error%message = case%path//trim(buf)//' '//error%message//" of body '"// &
                                trim(case%dirichlet(k)%body)//"' (edges: "//edge_names(self%bodies(ib)%disc)//')'
                return
            end if
            associate (d => self%dirichlet(k))
                d%body = ib
                d%edge = case%dirichlet(k)%edge
                d%fix = case%dirichlet(k)%fix
                d%values = case%dirichlet(k)%values
                allocate (d%dofs(2, size(cps)))
                d%dofs(1, :) = self%bodies(ib)%dof0 + 2*cps - 1
                d%dofs(2, :) = self%bodies(ib)%dof0 + 2*cps
                if (d%fix(1)) self%fixed(d%dofs(1, :)) = .true.
                if (d%fix(2)) self%fixed(d%dofs(2, :)) = .true.
            end associate
        end do
        allocate (self%pressure(size(case%pressure)))
        do k = 1, size(case%pressure)
            ib = find_body(self, case%pressure(k)%body)
            ie = 0
            do i = 1, 4
                if (trim(self%bodies(ib)%disc%edges(i)%name) == trim(case%pressure(k)%edge)) ie = i
            end do
            if (ie == 0) then
                write (buf, '(a,i0,a)') ': &pressure (', k, '): edge: '
                call fatal_error(error, case%path//trim(buf)//" no edge named '"// &
                                 trim(case%pressure(k)%edge)//"' on body '"//trim(case%pressure(k)%body)// &
                                 "' (edges: "//edge_names(self%bodies(ib)%disc)//')', error_code%input)
                return
            end if
            self%pressure(k)%body = ib
            self%pressure(k)%edge = ie
            self%pressure(k)%values = case%pressure(k)%values
        end do
        if (.not. allocated(case%contact)) then
            allocate (self%pairs(0))
            return
        end if
        allocate (self%pairs(size(case%contact)))
        do k = 1, size(case%contact)
            call new_pair(self, case%contact(k), self%pairs(k), error)
            if (allocated(error)) return
        end do
    end subroutine new_model

    !> Build a contact pair; its history starts from the projections in the
    !> reference configuration.
    subroutine new_pair(self, inp, slot, error)
        type(model_t), intent(in) :: self
        type(contact_settings_t), intent(in) :: inp
        type(pair_slot_t), intent(out) :: slot
        type(error_t), allocatable, intent(out) :: error
        type(rigid_line_t) :: rigid
        type(nurbs_master_t) :: master
        real(dp), allocatable :: u0(:), r0(:)
        integer :: ib

        call new_contact_pair(slot%pair, inp%method, error)
        if (allocated(error)) return
        associate (pair => slot%pair)
        pair%slave_name = inp%slave
        pair%master_name = inp%master
        ib = find_body(self, inp%slave)
        pair%slave_body = ib
        call new_contact_surface(pair%slave, self%bodies(ib)%disc, self%bodies(ib)%dof0)
        if (trim(inp%master) == 'rigid') then
            call new_rigid_line(rigid, inp%rigid_point, inp%rigid_normal)
            allocate (pair%master, source=rigid)
        else
            ib = find_body(self, inp%master)
            pair%master_body = ib
            call new_nurbs_master(master, self%bodies(ib)%disc, self%bodies(ib)%dof0)
            allocate (pair%master, source=master)
        end if
        pair%law%eps_n = inp%penalty_normal
        pair%law%eps_t = inp%penalty_tangent
        pair%law%mu = inp%friction
        pair%n_gauss = inp%n_gauss
        call pair%setup()
        allocate (u0(self%ndof), r0(self%ndof))
        u0 = 0.0_dp
        r0 = 0.0_dp
        call pair%evaluate(u0, r0, error)
        if (allocated(error)) return
        call pair%commit()
        pair%n_evaluations = 0
        pair%n_friction = 0
        end associate
    end subroutine new_pair

    !> The quadrature points of every element of `body` (reference gradients and
    !> weights x |det|), from its discretization and Gauss rule. `new_model` calls
    !> it; call it again after changing the body's reference control points.
    pure subroutine body_points(body)
        type(body_t), intent(inout) :: body
        real(dp), allocatable :: r(:), dr(:, :), x0(:, :)
        real(dp) :: xi, eta, det, hx, he
        integer :: e, i, j, q, nen

        if (allocated(body%points)) deallocate (body%points)
        allocate (body%points(body%disc%nel))
        do e = 1, body%disc%nel
            associate (el => body%disc%elements(e), pts => body%points(e))
                nen = element_nfun(body%disc, e)
                allocate (r(nen), dr(2, nen))
                x0 = body%disc%x(:, el%conn)
                allocate (pts%dndx(2, nen, size(body%gx)*size(body%ge)), pts%wdv(size(body%gx)*size(body%ge)))
                hx = 0.5_dp*(el%xi(2) - el%xi(1))
                he = 0.5_dp*(el%eta(2) - el%eta(1))
                q = 0
                do j = 1, size(body%ge)
                    eta = el%eta(1) + he*(body%ge(j) + 1.0_dp)
                    do i = 1, size(body%gx)
                        xi = el%xi(1) + hx*(body%gx(i) + 1.0_dp)
                        q = q + 1
                        call element_basis(body%disc, e, xi, eta, r, dr)
                        call reference_gradients(x0, dr, pts%dndx(:, :, q), det)
                        pts%wdv(q) = body%wx(i)*body%we(j)*hx*he*abs(det)
                    end do
                end do
                deallocate (r, dr)
            end associate
        end do
    end subroutine body_points

    pure integer function find_body(self, name) result(ib)
        type(model_t), intent(in) :: self
        character(len=*), intent(in) :: name
        integer :: i
        ib = 0
        do i = 1, size(self%bodies)
            if (trim(self%bodies(i)%name) == trim(name)) ib = i
        end do
    end function find_body

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

    !> Total number of load steps over all phases.
    pure integer function n_total_steps(self)
        type(model_t), intent(in) :: self
        n_total_steps = sum(self%n_steps)
    end function n_total_steps

    !> Load "time" at the end of global step `step` (0 = start; phase k ends at time k).
    pure real(dp) function step_time(self, step) result(t)
        type(model_t), intent(in) :: self
        integer, intent(in) :: step
        integer :: k, left
        left = step
        t = 0.0_dp
        do k = 1, size(self%n_steps)
            if (left <= self%n_steps(k)) then
                t = real(k - 1, dp) + real(left, dp)/real(self%n_steps(k), dp)
                return
            end if
            left = left - self%n_steps(k)
        end do
        t = real(size(self%n_steps), dp)
    end function step_time

    !> Value of a phase-wise linear history at load time `t`: 0 at t = 0, `values(k)` at t = k.
    pure real(dp) function phase_value(values, t) result(v)
        real(dp), intent(in) :: values(:)
        real(dp), intent(in) :: t
        integer :: k
        real(dp) :: a, s
        k = min(max(ceiling(t), 1), size(values))
        s = t - real(k - 1, dp)
        a = 0.0_dp
        if (k > 1) a = values(k - 1)
        v = a + s*(values(k) - a)
    end function phase_value

end module voiga_model
