!> A deformable master on a solid: another body's contact face, a NURBS surface over
!> its control points (the VO layer when the body has one). The closest-point search
!> and projection are the surface kernel's (`voiga_nurbs_projection`: a tree of the
!> cells' control-point boxes, a projected Newton iteration per candidate cell),
!> rebuilt on the displaced face by `prepare(u)` once per evaluation; a projection is
!> warm-started from the same slave point's last one.
module voiga_contact_master_face
    use voiga_kinds, only: dp
    use voiga_discretization_patch, only: discretization_t
    use voiga_discretization_element, only: element_basis, element_nfun
    use voiga_nurbs_patch, only: nurbs_patch_t, knots_t, new_patch, jacobian_determinant
    use voiga_nurbs_projection, only: surface_search_t, surface_projection_t, new_surface_search, &
                                      project_on_surface
    use voiga_contact_master, only: contact_master_t, master_point_t
    use voiga_contact_surface, only: contact_surface_t, new_contact_surface, face_basis, face_ids
    implicit none
    private

    public :: face_master_t, new_face_master

    !> A body's contact face acting as master.
    type, extends(contact_master_t) :: face_master_t
        type(contact_surface_t) :: surf
        !> +1 when a_1 x a_2 points out of the body (a right-handed volume), else -1.
        real(dp) :: sign = 1.0_dp
        !> The search structure of the configuration of the last `prepare`.
        type(surface_search_t) :: search
    contains
        procedure :: project => face_project
        procedure :: all_dofs => face_all_dofs
        procedure :: prepare => face_prepare
    end type face_master_t

contains

    !> The contact face of `disc` (DOFs after `dof0`) as a master.
    subroutine new_face_master(self, disc, dof0)
        type(face_master_t), intent(out) :: self
        type(discretization_t), intent(in) :: disc
        integer, intent(in) :: dof0
        self%deformable = .true.
        call new_contact_surface(self%surf, disc, dof0)
        self%sign = face_outward_sign(disc)
    end subroutine new_face_master

    !> The sign s such that s a_1 x a_2 points out of the body at its zeta = 1 face:
    !> the sign of det dX/du there (dX/dzeta points outward at zeta = 1, and
    !> (a_1 x a_2) . a_3 = det).
    function face_outward_sign(disc) result(s)
        type(discretization_t), intent(in) :: disc
        real(dp) :: s
        real(dp), allocatable :: r(:), dr(:, :)
        real(dp) :: jac(3, 3)
        integer :: e
        e = disc%nel
        allocate (r(element_nfun(disc, e)), dr(3, element_nfun(disc, e)))
        associate (el => disc%elements(e))
            call element_basis(disc, e, [0.5_dp*(el%lo(1) + el%hi(1)), 0.5_dp*(el%lo(2) + el%hi(2)), el%hi(3)], &
                               r, dr)
            jac = matmul(disc%x(:, el%conn), transpose(dr))
        end associate
        s = merge(1.0_dp, -1.0_dp, jacobian_determinant(jac) > 0.0_dp)
    end function face_outward_sign

    !> The search structure of the face displaced by `u`.
    pure subroutine face_prepare(self, u)
        class(face_master_t), intent(inout) :: self
        real(dp), intent(in) :: u(:)
        type(nurbs_patch_t) :: patch
        real(dp) :: cp(3, size(self%surf%cps))
        integer :: c
        do c = 1, 3
            cp(c, :) = self%surf%x0(c, :) + u(self%surf%dofs(c, :))
        end do
        associate (s => self%surf)
            patch = new_patch([s%degree, s%degree_eta], [knots_t(s%knots), knots_t(s%knots_eta)], &
                              [s%n_xi, size(s%cps)/s%n_xi], cp, s%w)
        end associate
        call new_surface_search(self%search, patch)
    end subroutine face_prepare

    pure function face_all_dofs(self) result(dofs)
        class(face_master_t), intent(in) :: self
        integer, allocatable :: dofs(:)
        dofs = reshape(self%surf%dofs, [size(self%surf%dofs)])
    end function face_all_dofs

    !> The closest point of the face to `xs` [3] (`prepare`d with the same `u`),
    !> warm-started from `start` [2] (the same slave point's last projection), with the
    !> face's functions there and their DOFs.
    pure subroutine face_project(self, u, xs, mp, found, converged, start)
        class(face_master_t), intent(in) :: self
        real(dp), intent(in) :: u(:), xs(:)
        type(master_point_t), intent(out) :: mp
        logical, intent(out) :: found, converged
        real(dp), intent(in), optional :: start(:)
        type(surface_projection_t) :: res
        integer :: nf, nu, s(2), k
        integer, allocatable :: ids(:)
        if (size(u) < 0) return   ! (the search holds the displaced face)
        if (present(start)) then
            call project_on_surface(self%search, xs, res, found, converged, start)
        else
            call project_on_surface(self%search, xs, res, found, converged)
        end if
        mp%xi = res%u(1)
        mp%eta = res%u(2)
        mp%x = res%x
        mp%a = res%a1
        mp%b = res%a2
        mp%a2 = res%a11
        mp%b2 = res%a22
        mp%ab = res%a12
        mp%n = self%sign*res%n
        nu = size(self%search%span_u)
        s = [self%search%span_u(modulo(res%cell - 1, nu) + 1), self%search%span_v((res%cell - 1)/nu + 1)]
        nf = (self%surf%degree + 1)*(self%surf%degree_eta + 1)
        allocate (mp%r(nf), mp%dr(nf), mp%drb(nf))
        call face_basis(self%surf, mp%xi, mp%eta, s, mp%r, mp%dr, mp%drb)
        ids = face_ids(self%surf, s)
        allocate (mp%dofs(3*nf))
        do k = 1, nf
            mp%dofs(3*k - 2:3*k) = self%surf%dofs(:, ids(k))
        end do
        mp%first = minval(ids)
        mp%last = maxval(ids)
    end subroutine face_project

end module voiga_contact_master_face
