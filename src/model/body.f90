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
    use voiga_discretization_element, only: element_basis_grid, element_nfun
    use voiga_element_quadrature, only: gauss_legendre
    use voiga_element_solid, only: element_points_t, reference_gradients
    implicit none
    private

    public :: body_t, body_settings_t, new_body, body_points

    !> One body as a case describes it (docs/formats.md, `&body`).
    type :: body_settings_t
        character(len=32) :: name = ''
        !> One of `material_names`: 'linear' (small strain) or 'neo-hookean' (finite strain).
        character(len=32) :: material = ''
        real(dp) :: youngs_modulus = 0.0_dp
        real(dp) :: poisson_ratio = 0.0_dp
        type(layout_t) :: layout
    end type body_settings_t

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

contains

    !> Body `settings` on the discretization `disc`, its DOFs after `dof0`, with
    !> `n_gauss` points per direction (0: degree + 1 in each direction, the VO
    !> row's layer degree + 1 along xi).
    subroutine new_body(self, settings, disc, dof0, n_gauss, error)
        type(body_t), intent(out) :: self
        type(body_settings_t), intent(in) :: settings
        type(discretization_t), intent(in) :: disc
        integer, intent(in) :: dof0, n_gauss
        type(error_t), allocatable, intent(out) :: error
        self%name = settings%name
        self%disc = disc
        call new_material(self%mat, settings%material, settings%youngs_modulus, settings%poisson_ratio, error)
        if (allocated(error)) return
        self%dof0 = dof0
        if (n_gauss > 0) then
            self%n_gauss = n_gauss
        else
            ! degree + 1 per direction; the VO row needs the layer's degree along xi
            self%n_gauss(1) = self%disc%bulk%degree(1) + 1
            if (self%disc%has_layer) self%n_gauss(1) = max(self%n_gauss(1), self%disc%layer%degree + 1)
            self%n_gauss(2) = self%disc%bulk%degree(2) + 1
        end if
        allocate (self%gx(self%n_gauss(1)), self%wx(self%n_gauss(1)), self%ge(self%n_gauss(2)), &
                  self%we(self%n_gauss(2)))
        call gauss_legendre(self%n_gauss(1), self%gx, self%wx)
        call gauss_legendre(self%n_gauss(2), self%ge, self%we)
        call body_points(self)
    end subroutine new_body

    !> The quadrature points of every element of `body` (reference gradients and
    !> weights x |det|), from its discretization and Gauss rule. `new_model` calls
    !> it; call it again after changing the body's reference control points.
    pure subroutine body_points(body)
        type(body_t), intent(inout) :: body
        real(dp), allocatable :: r(:, :), dr(:, :, :), x0(:, :), xis(:), etas(:)
        real(dp) :: det, hx, he
        integer :: e, i, j, q, nen, npts

        if (allocated(body%points)) deallocate (body%points)
        allocate (body%points(body%disc%nel))
        npts = size(body%gx)*size(body%ge)
        do e = 1, body%disc%nel
            associate (el => body%disc%elements(e), pts => body%points(e))
                nen = element_nfun(body%disc, e)
                allocate (r(nen, npts), dr(2, nen, npts))
                x0 = body%disc%x(:, el%conn)
                allocate (pts%dndx(2, nen, npts), pts%wdv(npts))
                hx = 0.5_dp*(el%xi(2) - el%xi(1))
                he = 0.5_dp*(el%eta(2) - el%eta(1))
                xis = el%xi(1) + hx*(body%gx + 1.0_dp)
                etas = el%eta(1) + he*(body%ge + 1.0_dp)
                call element_basis_grid(body%disc, e, xis, etas, r, dr)
                q = 0
                do j = 1, size(body%ge)
                    do i = 1, size(body%gx)
                        q = q + 1
                        call reference_gradients(x0, dr(:, :, q), pts%dndx(:, :, q), det)
                        pts%wdv(q) = body%wx(i)*body%we(j)*hx*he*abs(det)
                    end do
                end do
                deallocate (r, dr)
            end associate
        end do
    end subroutine body_points

end module voiga_model_body
