!> A deformable body of the model: its discretization, material law, DOF offset
!> and quadrature; and the settings a case gives for one (`&body`, read by
!> `voiga_io_input_case_body`).
module voiga_model_body
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_material, only: material_t
    use voiga_material_factory, only: new_material
    use voiga_discretization_layout, only: layout_t
    use voiga_discretization_patch, only: discretization_t
    use voiga_discretization_element, only: element_basis_grid, element_nfun, axis_t
    use voiga_element_quadrature, only: gauss_legendre
    use voiga_element_solid, only: element_points_t, reference_gradients
    use voiga_element_solid3, only: reference_gradients3
    use voiga_nurbs_patch, only: next_index
    implicit none
    private

    public :: body_t, body_settings_t, new_body, body_points, gauss_rule_t

    !> One body as a case describes it (docs/formats.md, `&body`).
    type :: body_settings_t
        character(len=32) :: name = ''
        !> One of `material_names`: 'linear' (small strain) or 'neo-hookean' (finite strain).
        character(len=32) :: material = ''
        real(dp) :: youngs_modulus = 0.0_dp
        real(dp) :: poisson_ratio = 0.0_dp
        type(layout_t) :: layout
        !> The case file's name for the contact boundary: 'contact_edge' (a plane
        !> body) or 'contact_face' (a solid), for messages.
        character(len=12) :: contact_key = 'contact_edge'
    end type body_settings_t

    !> Gauss points `x` and weights `w` on [-1, 1] along one direction.
    type :: gauss_rule_t
        real(dp), allocatable :: x(:), w(:)
    end type gauss_rule_t

    !> A deformable body.
    type :: body_t
        character(len=32) :: name = ''
        type(discretization_t) :: disc
        class(material_t), allocatable :: mat
        !> Global DOFs of this body are dof0 + 1 .. dof0 + nsd ncp (nsd (a-1) + i for
        !> point a, component i).
        integer :: dof0 = 0
        !> Gauss points per direction used for this body (1 beyond pdim), and the
        !> rule of each direction [pdim].
        integer :: n_gauss(3) = 1
        type(gauss_rule_t), allocatable :: rules(:)
        !> Every element's quadrature points (reference gradients, weights) [nel].
        type(element_points_t), allocatable :: points(:)
    end type body_t

contains

    !> Body `settings` on the discretization `disc`, its DOFs after `dof0`, with
    !> `n_gauss` points per direction (0: degree + 1 in each direction, along the
    !> contact boundary at least the layer's degree + 1).
    subroutine new_body(self, settings, disc, dof0, n_gauss, error)
        type(body_t), intent(out) :: self
        type(body_settings_t), intent(in) :: settings
        type(discretization_t), intent(in) :: disc
        integer, intent(in) :: dof0, n_gauss
        type(error_t), allocatable, intent(out) :: error
        integer :: d, nd
        self%name = settings%name
        self%disc = disc
        call new_material(self%mat, settings%material, settings%youngs_modulus, settings%poisson_ratio, error)
        if (allocated(error)) return
        self%dof0 = dof0
        nd = disc%pdim
        if (n_gauss > 0) then
            self%n_gauss(:nd) = n_gauss
        else
            ! degree + 1 per direction; the VO layer needs its degree along the boundary
            self%n_gauss(:nd) = self%disc%bulk%degree + 1
            if (self%disc%has_layer) self%n_gauss(:nd - 1) = max(self%n_gauss(:nd - 1), self%disc%layer%degree + 1)
        end if
        allocate (self%rules(nd))
        do d = 1, nd
            allocate (self%rules(d)%x(self%n_gauss(d)), self%rules(d)%w(self%n_gauss(d)))
            call gauss_legendre(self%n_gauss(d), self%rules(d)%x, self%rules(d)%w)
        end do
        call body_points(self)
    end subroutine new_body

    !> The quadrature points of every element of `body` (reference gradients and
    !> weights x |det|), from its discretization and Gauss rule. `new_model` calls
    !> it; call it again after changing the body's reference control points.
    pure subroutine body_points(body)
        type(body_t), intent(inout) :: body
        real(dp), allocatable :: r(:, :), dr(:, :, :), x0(:, :)
        type(axis_t) :: axes(body%disc%pdim)
        real(dp) :: det, h(body%disc%pdim), w
        integer :: e, d, q, nen, npts, nd, idx(body%disc%pdim)

        if (allocated(body%points)) deallocate (body%points)
        allocate (body%points(body%disc%nel))
        nd = body%disc%pdim
        npts = product(body%n_gauss(:nd))
        do e = 1, body%disc%nel
            associate (el => body%disc%elements(e), pts => body%points(e))
                nen = element_nfun(body%disc, e)
                allocate (r(nen, npts), dr(nd, nen, npts))
                x0 = body%disc%x(:, el%conn)
                allocate (pts%dndx(nd, nen, npts), pts%wdv(npts))
                do d = 1, nd
                    h(d) = 0.5_dp*(el%hi(d) - el%lo(d))
                    axes(d)%u = el%lo(d) + h(d)*(body%rules(d)%x + 1.0_dp)
                end do
                call element_basis_grid(body%disc, e, axes, r, dr)
                idx = 1
                do q = 1, npts
                    if (nd == 2) then
                        call reference_gradients(x0, dr(:, :, q), pts%dndx(:, :, q), det)
                    else
                        call reference_gradients3(x0, dr(:, :, q), pts%dndx(:, :, q), det)
                    end if
                    ! the product in the order w_1 w_2 .. h_1 h_2 .. |det|
                    w = 1.0_dp
                    do d = 1, nd
                        w = w*body%rules(d)%w(idx(d))
                    end do
                    do d = 1, nd
                        w = w*h(d)
                    end do
                    pts%wdv(q) = w*abs(det)
                    call next_index(idx, body%n_gauss(:nd))
                end do
                deallocate (r, dr)
            end associate
        end do
    end subroutine body_points

end module voiga_model_body
