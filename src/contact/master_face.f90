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
    use voiga_contact_master, only: contact_master_t, master_point_t, master_no_dofs, master_output_t
    use voiga_contact_surface, only: contact_surface_t, new_contact_surface, face_basis, face_ids, new_patch_surface
    implicit none
    private

    public :: face_master_t, new_face_master, rigid_surface_t, new_rigid_surface, face_outward_sign

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
        procedure :: grid_width => face_grid_width
        procedure :: prepare => face_prepare
    end type face_master_t

    !> A rigid obstacle of a solid case bounded by a surface of the geometry file (a
    !> spherical or cylindrical indenter, a die), without DOFs, moved as a whole by its
    !> prescribed motion: the face master's search and projection run on the surface's
    !> own control points with a zero displacement vector, and `move` translates the
    !> control points (as `voiga_contact_master_curve` does for a curve). Its normal
    !> a_1 x a_2 points out of the obstacle.
    type, extends(face_master_t) :: rigid_surface_t
        !> Control points at load time 0 [3, n], the (zero) displacement vector [3 n],
        !> the translation from there, and the surface's name (for messages).
        real(dp), allocatable :: x_ref(:, :), zero(:)
        real(dp) :: offset(3) = 0.0_dp
        character(len=32) :: name = ''
    contains
        procedure :: project => surface_project
        procedure :: all_dofs => surface_all_dofs
        procedure :: prepare => surface_prepare
        procedure :: move => surface_move
        procedure :: output => surface_output
    end type rigid_surface_t

contains

    !> The obstacle bounded by `patch` (pdim 2, nsd 3) at its reference position.
    pure subroutine new_rigid_surface(self, patch)
        type(rigid_surface_t), intent(out) :: self
        type(nurbs_patch_t), intent(in) :: patch
        self%deformable = .false.
        call new_patch_surface(self%surf, patch)
        self%sign = 1.0_dp
        self%x_ref = patch%cp
        allocate (self%zero(3*size(patch%w)), source=0.0_dp)
    end subroutine new_rigid_surface

    !> The search structure of the surface where it is now.
    pure subroutine surface_prepare(self, u)
        class(rigid_surface_t), intent(inout) :: self
        real(dp), intent(in) :: u(:)
        if (size(u) < 0) return   ! the surface has no DOFs in u
        call face_prepare(self, self%zero)
    end subroutine surface_prepare

    !> The face master's projection, without master functions (no DOFs to couple).
    pure subroutine surface_project(self, u, xs, mp, found, converged, start)
        class(rigid_surface_t), intent(in) :: self
        real(dp), intent(in) :: u(:), xs(:)
        type(master_point_t), intent(out) :: mp
        logical, intent(out) :: found, converged
        real(dp), intent(in), optional :: start(:)
        if (size(u) < 0) return   ! the surface has no DOFs in u
        call face_project(self, self%zero, xs, mp, found, converged, start)
        deallocate (mp%r, mp%dr, mp%drb, mp%dofs)
        allocate (mp%r(0), mp%dr(0), mp%drb(0), mp%dofs(0))
        mp%first = 1
        mp%last = 0
    end subroutine surface_project

    pure function surface_all_dofs(self) result(dofs)
        class(rigid_surface_t), intent(in) :: self
        integer, allocatable :: dofs(:)
        dofs = master_no_dofs(self)
    end function surface_all_dofs

    !> Translate the surface to its reference position plus `offset` [3].
    pure subroutine surface_move(self, offset)
        class(rigid_surface_t), intent(inout) :: self
        real(dp), intent(in) :: offset(:)
        integer :: c
        self%offset = offset
        do c = 1, 3
            self%surf%x0(c, :) = self%x_ref(c, :) + offset(c)
        end do
    end subroutine surface_move

    !> Its translation from load time 0.
    pure function surface_output(self) result(out)
        class(rigid_surface_t), intent(in) :: self
        type(master_output_t) :: out
        out%curve_name = ''
        out%names = [character(len=16) :: 'rigid_offset']
        out%vectors = reshape(self%offset, [3, 1])
    end function surface_output

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

    !> The face's control points per row (its numbering runs xi fastest).
    pure integer function face_grid_width(self) result(width)
        class(face_master_t), intent(in) :: self
        width = self%surf%n_xi
    end function face_grid_width

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
