!> A rigid flat master (an obstacle without DOFs): in 2D the line of points
!> x = p0 + xi t with outward unit normal n, xi the arc length along t = (n_y, -n_x);
!> in 3D the plane x = p0 + xi t + eta t2, (t, t2, n) a right-handed orthonormal frame
!> (t x t2 = n, as a surface's a1 x a2 is its outward normal). A prescribed motion
!> translates it (`move`: p0 = p_ref + offset).
module voiga_contact_master_rigid
    use voiga_kinds, only: dp
    use voiga_contact_master, only: contact_master_t, master_point_t, master_output_t
    use voiga_nurbs_patch, only: cross
    implicit none
    private

    public :: rigid_line_t, new_rigid_line

    !> A fixed rigid line.
    type, extends(contact_master_t) :: rigid_line_t
        !> Spatial dimension (2: a line, 3: a plane).
        integer :: nsd = 2
        real(dp) :: p0(3) = 0.0_dp, n(3) = [0.0_dp, 1.0_dp, 0.0_dp], t(3) = [1.0_dp, 0.0_dp, 0.0_dp]
        !> The plane's second tangent (0 for a line).
        real(dp) :: t2(3) = 0.0_dp
        !> The point p0 at load time 0.
        real(dp) :: p_ref(3) = 0.0_dp
    contains
        procedure :: project => rigid_project
        procedure :: move => rigid_move
        procedure :: output => rigid_output
    end type rigid_line_t

contains

    !> Line (2D) or plane (3D: `p0`, `normal` of size 3) through `p0` with outward
    !> normal `normal` (normalized here).
    pure subroutine new_rigid_line(self, p0, normal)
        type(rigid_line_t), intent(out) :: self
        real(dp), intent(in) :: p0(:), normal(:)
        integer :: k
        self%deformable = .false.
        self%nsd = size(p0)
        self%p0 = 0.0_dp
        self%n = 0.0_dp
        self%p0(1:self%nsd) = p0
        self%p_ref = self%p0
        self%n(1:self%nsd) = normal/norm2(normal)
        if (self%nsd == 2) then
            self%t = [self%n(2), -self%n(1), 0.0_dp]
            return
        end if
        ! t: the axis least aligned with n, made orthogonal to it; t2 = n x t
        k = minloc(abs(self%n), dim=1)
        self%t = 0.0_dp
        self%t(k) = 1.0_dp
        self%t = self%t - dot_product(self%t, self%n)*self%n
        self%t = self%t/norm2(self%t)
        self%t2 = cross(self%n, self%t)
    end subroutine new_rigid_line

    pure subroutine rigid_project(self, u, xs, mp, found, converged, start)
        class(rigid_line_t), intent(in) :: self
        real(dp), intent(in) :: u(:), xs(:)
        type(master_point_t), intent(out) :: mp
        logical, intent(out) :: found, converged
        !> Not needed: the projection on a line is explicit.
        real(dp), intent(in), optional :: start(:)
        integer :: d
        if (size(u) < 0) return   ! u is not needed: the line has no DOFs
        d = self%nsd
        mp%xi = dot_product(xs - self%p0(1:d), self%t(1:d))
        mp%x = self%p0 + mp%xi*self%t
        if (d == 3) then
            mp%eta = dot_product(xs - self%p0, self%t2)
            mp%x = mp%x + mp%eta*self%t2
            mp%b = self%t2
        end if
        mp%a = self%t
        mp%a2 = 0.0_dp
        mp%n = self%n
        allocate (mp%r(0), mp%dr(0), mp%drb(0), mp%dofs(0))
        found = .true.
        converged = .true.
    end subroutine rigid_project

    pure subroutine rigid_move(self, offset)
        class(rigid_line_t), intent(inout) :: self
        real(dp), intent(in) :: offset(:)
        self%p0(1:self%nsd) = self%p_ref(1:self%nsd) + offset
    end subroutine rigid_move

    !> Where the line is at this step: a point, its normal, and the translation
    !> from load time 0.
    pure function rigid_output(self) result(out)
        class(rigid_line_t), intent(in) :: self
        type(master_output_t) :: out
        out%curve_name = ''
        out%names = [character(len=16) :: 'rigid_point', 'rigid_normal', 'rigid_offset']
        associate (d => self%nsd)
            out%vectors = reshape([self%p0(1:d), self%n(1:d), self%p0(1:d) - self%p_ref(1:d)], [d, 3])
        end associate
    end function rigid_output

end module voiga_contact_master_rigid
