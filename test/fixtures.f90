!> Shared test fixtures: exact coarse patches of the scenes' shapes, a
!> deterministic pseudo-random sequence, and a scene built from plain settings
!> (no case file).
module voiga_test_fixtures
    use, intrinsic :: iso_fortran_env, only: int64
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_nurbs_surface, only: nurbs_surface_t
    use voiga_nurbs_patch, only: nurbs_patch_t, knots_t, new_patch
    use voiga_discretization_layout, only: layout_t
    use voiga_discretization_patch, only: discretization_t
    use voiga_model, only: model_t, new_model
    use voiga_model_body, only: body_settings_t
    use voiga_model_loads, only: dirichlet_settings_t, pressure_settings_t
    use voiga_contact_factory, only: contact_settings_t
    use voiga_solver_settings, only: solver_settings_t
    use voiga_contact_mortar, only: mortar_pair_t
    implicit none
    private

    public :: mortar_history
    public :: ring_block, layout3
    public :: annulus_sector, rectangle, lcg_t, quadratic, paper_layout, scene_t, scene_model, body_settings

    !> The settings of a test scene, as a case file would give them.
    type :: scene_t
        type(body_settings_t), allocatable :: bodies(:)
        type(solver_settings_t) :: solver
        type(dirichlet_settings_t), allocatable :: dirichlet(:)
        type(pressure_settings_t), allocatable :: pressure(:)
        type(contact_settings_t), allocatable :: contact(:)
    end type scene_t

    !> Park-Miller generator: same numbers on every compiler and run.
    type :: lcg_t
        integer(int64) :: state = 12345_int64
    contains
        procedure :: uniform => lcg_uniform
    end type lcg_t

contains

    !> A solid's layout: bulk degree `p` in each direction, `nel` elements per direction,
    !> layer degree `q` with `k` elevations (q = 0: none) on `face`.
    function layout3(p, nel, q, k, face) result(layout)
        integer, intent(in) :: p, nel(3), q, k
        character(len=*), intent(in) :: face
        type(layout_t) :: layout
        layout%degree = p
        layout%nel = nel
        layout%layer_degree = q
        layout%layer_elevations = k
        layout%contact_edge = face
    end function layout3

    !> Quarter ring r in [1, 2], theta in [0, pi/2] (degree 1 x 2), extruded to
    !> z in [0, 1] (degree 1): 2 x 3 x 2 control points.
    function ring_block() result(patch)
        type(nurbs_patch_t) :: patch
        real(dp) :: cp(3, 12), w(12), arc(2, 3), warc(3)
        integer :: i, j, k, a
        arc = reshape([1.0_dp, 0.0_dp, 1.0_dp, 1.0_dp, 0.0_dp, 1.0_dp], [2, 3])
        warc = [1.0_dp, 1.0_dp/sqrt(2.0_dp), 1.0_dp]
        a = 0
        do k = 1, 2
            do j = 1, 3
                do i = 1, 2
                    a = a + 1
                    cp(:, a) = [real(i, dp)*arc(:, j), real(k - 1, dp)]
                    w(a) = warc(j)
                end do
            end do
        end do
        patch = new_patch([1, 2, 1], [knots_t([0.0_dp, 0.0_dp, 1.0_dp, 1.0_dp]), &
                                      knots_t([0.0_dp, 0.0_dp, 0.0_dp, 1.0_dp, 1.0_dp, 1.0_dp]), &
                                      knots_t([0.0_dp, 0.0_dp, 1.0_dp, 1.0_dp])], [2, 3, 2], cp, w)
    end function ring_block

    !> The model of scene `c` on the discretizations `discs` (one per body); the
    !> load and contact lists default to empty.
    subroutine scene_model(c, discs, model, error)
        type(scene_t), intent(inout) :: c
        type(discretization_t), intent(in) :: discs(:)
        type(model_t), intent(out) :: model
        type(error_t), allocatable, intent(out) :: error
        if (.not. allocated(c%dirichlet)) allocate (c%dirichlet(0))
        if (.not. allocated(c%pressure)) allocate (c%pressure(0))
        if (.not. allocated(c%contact)) allocate (c%contact(0))
        if (.not. allocated(c%solver%n_steps)) c%solver%n_steps = [1]
        call new_model(model, c%bodies, discs, c%solver%n_gauss, c%dirichlet, c%pressure, c%contact, error)
    end subroutine scene_model

    !> A body entry of a test case (Poisson's ratio 0.3).
    function body_settings(name, material, e, layout) result(b)
        character(len=*), intent(in) :: name, material
        real(dp), intent(in) :: e
        type(layout_t), intent(in) :: layout
        type(body_settings_t) :: b
        b%name = name
        b%material = material
        b%youngs_modulus = e
        b%poisson_ratio = 0.3_dp
        b%layout = layout
    end function body_settings

    !> A layout in the paper's notation: 'L1', 'Np' (degree p along the contact edge,
    !> 2 across), 'NNq' (bulk 2 x 2, layer of degree q), 'NNq.k' (k more elevations).
    function paper_layout(name, nel, contact) result(layout)
        character(len=*), intent(in) :: name
        integer, intent(in) :: nel(2)
        character(len=*), intent(in) :: contact
        type(layout_t) :: layout
        integer :: dot, ios
        layout%nel(:2) = nel
        layout%contact_edge = contact
        ios = 0
        if (name == 'L1') then
            layout%basis = 'linear'
            layout%degree(:2) = [1, 1]
        else if (name(1:min(2, len(name))) == 'NN') then
            dot = index(name, '.')
            if (dot == 0) then
                read (name(3:), *, iostat=ios) layout%layer_degree
            else
                read (name(3:dot - 1), *, iostat=ios) layout%layer_degree
                if (ios == 0) read (name(dot + 1:), *, iostat=ios) layout%layer_elevations
            end if
        else if (name(1:1) == 'N') then
            read (name(2:), *, iostat=ios) layout%degree(1)
        else
            ios = 1
        end if
        if (ios /= 0) error stop 'paper_layout: unknown layout name'
    end function paper_layout

    !> Does a Newton residual sequence converge quadratically? In the asymptotic
    !> range (r_k < 1e-3 r_0) and above round-off (r_k+1 > 1e-13 r_0) every
    !> iteration must satisfy r_k+1/r_0 <= 100 (r_k/r_0)^2. A linearly converging
    !> sequence with rate above 0.1 fails this as soon as r_k < 1e-3 r_0. At least
    !> one such iteration is required. `floor`: the solver's round-off estimate of the
    !> residual (`residual_floor`); an iterate below it is above round-off no more.
    logical function quadratic(r, floor)
        real(dp), intent(in) :: r(:)
        real(dp), intent(in), optional :: floor
        integer :: k, n
        quadratic = .true.
        n = 0
        do k = 2, size(r) - 1
            if (r(k) >= 1.0e-3_dp*r(1) .or. r(k + 1) <= 1.0e-13_dp*r(1)) cycle
            if (present(floor)) then
                if (r(k + 1) <= floor) cycle
            end if
            n = n + 1
            if (r(k + 1)/r(1) > 100.0_dp*(r(k)/r(1))**2) quadratic = .false.
        end do
        if (n == 0) quadratic = .false.
    end function quadratic

    !> Next number in [0, 1).
    real(dp) function lcg_uniform(self)
        class(lcg_t), intent(inout) :: self
        ! Park-Miller minimal standard: no integer overflow in 64 bits
        self%state = modulo(16807_int64*self%state, 2147483647_int64)
        lcg_uniform = real(self%state - 1, dp)/2147483646.0_dp
    end function lcg_uniform

    !> Annular sector from angle `a0` over `nq` quarter turns (counter-clockwise),
    !> radii `ri` (eta = 0) to `ro` (eta = 1), centre `c`: exact rational quadratic
    !> arcs along xi (C0 between quarters), degree 1 across.
    function annulus_sector(c, ri, ro, a0, nq) result(s)
        real(dp), intent(in) :: c(2), ri, ro, a0
        integer, intent(in) :: nq
        type(nurbs_surface_t) :: s
        real(dp) :: r(2), ang, h
        integer :: k, j, i

        s%degree = [2, 1]
        allocate (s%knots_xi(2*nq + 4))
        s%knots_xi(1:3) = 0.0_dp
        do k = 1, nq - 1
            s%knots_xi(2*k + 2:2*k + 3) = real(k, dp)/real(nq, dp)
        end do
        s%knots_xi(2*nq + 2:2*nq + 4) = 1.0_dp
        s%knots_eta = [0.0_dp, 0.0_dp, 1.0_dp, 1.0_dp]
        allocate (s%cp(2, 2*nq + 1, 2), s%w(2*nq + 1, 2))
        r = [ri, ro]
        h = 0.25_dp*acos(-1.0_dp)
        do j = 1, 2
            do i = 1, 2*nq + 1
                ang = a0 + real(i - 1, dp)*h
                if (mod(i, 2) == 1) then
                    s%cp(:, i, j) = c + r(j)*[cos(ang), sin(ang)]
                    s%w(i, j) = 1.0_dp
                else
                    s%cp(:, i, j) = c + r(j)/cos(h)*[cos(ang), sin(ang)]
                    s%w(i, j) = cos(h)
                end if
            end do
        end do
        s%edge_names = [character(len=32) :: 'start', 'end', 'inner', 'outer']
    end function annulus_sector

    !> Rectangle [x0, x0+a] x [y0, y0+b], degree (1, 1), eta = 1 on top.
    function rectangle(x0, y0, a, b) result(s)
        real(dp), intent(in) :: x0, y0, a, b
        type(nurbs_surface_t) :: s
        s%degree = [1, 1]
        s%knots_xi = [0.0_dp, 0.0_dp, 1.0_dp, 1.0_dp]
        s%knots_eta = [0.0_dp, 0.0_dp, 1.0_dp, 1.0_dp]
        allocate (s%cp(2, 2, 2), s%w(2, 2))
        s%cp(:, 1, 1) = [x0, y0]
        s%cp(:, 2, 1) = [x0 + a, y0]
        s%cp(:, 1, 2) = [x0, y0 + b]
        s%cp(:, 2, 2) = [x0 + a, y0 + b]
        s%w = 1.0_dp
        s%edge_names = [character(len=32) :: 'left', 'right', 'bottom', 'top']
    end function rectangle

    !> A mortar-type pair's committed history for a tangent check: every point in
    !> contact at the last converged state, projected `shift` before its projection now,
    !> no committed tractions; with `touch`, every control point open then at mean gap
    !> `touch` (it touched in this step).
    subroutine mortar_history(pair, shift, touch)
        class(mortar_pair_t), intent(inout) :: pair
        real(dp), intent(in) :: shift
        real(dp), intent(in), optional :: touch
        pair%hist%field(pair%h_active)%last = 1.0_dp
        pair%hist%field(pair%h_xi)%last = pair%out%xi_m - shift
        pair%hist%field(pair%h_traction)%last = 0.0_dp
        pair%hist%field(pair%h_node_active)%last = 1.0_dp
        if (present(touch)) then
            pair%hist%field(pair%h_node_active)%last = 0.0_dp
            pair%hist%field(pair%h_node_gap)%last = touch
        end if
    end subroutine mortar_history

end module voiga_test_fixtures
