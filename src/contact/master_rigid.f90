!> A rigid straight master line (an obstacle without DOFs): the points
!> x = p0 + xi t with outward unit normal n; xi is the arc length along t = (n_y, -n_x).
!> A prescribed motion translates it (`move`: p0 = p_ref + offset).
module voiga_contact_master_rigid
    use voiga_kinds, only: dp
    use voiga_contact_master, only: contact_master_t, master_point_t, master_output_t
    implicit none
    private

    public :: rigid_line_t, new_rigid_line

    !> A fixed rigid line.
    type, extends(contact_master_t) :: rigid_line_t
        real(dp) :: p0(2) = 0.0_dp, n(2) = [0.0_dp, 1.0_dp], t(2) = [1.0_dp, 0.0_dp]
        !> The point p0 at load time 0.
        real(dp) :: p_ref(2) = 0.0_dp
    contains
        procedure :: project => rigid_project
        procedure :: move => rigid_move
        procedure :: output => rigid_output
    end type rigid_line_t

contains

    !> Line through `p0` with outward normal `normal` (normalized here).
    pure subroutine new_rigid_line(self, p0, normal)
        type(rigid_line_t), intent(out) :: self
        real(dp), intent(in) :: p0(2), normal(2)
        self%deformable = .false.
        self%p0 = p0
        self%p_ref = p0
        self%n = normal/norm2(normal)
        self%t = [self%n(2), -self%n(1)]
    end subroutine new_rigid_line

    pure subroutine rigid_project(self, u, xs, mp, found, converged, start)
        class(rigid_line_t), intent(in) :: self
        real(dp), intent(in) :: u(:), xs(2)
        type(master_point_t), intent(out) :: mp
        logical, intent(out) :: found, converged
        !> Not needed: the projection on a line is explicit.
        real(dp), intent(in), optional :: start
        if (size(u) < 0) return   ! u is not needed: the line has no DOFs
        mp%xi = dot_product(xs - self%p0, self%t)
        mp%x = self%p0 + mp%xi*self%t
        mp%a = self%t
        mp%a2 = 0.0_dp
        mp%n = self%n
        allocate (mp%r(0), mp%dr(0), mp%dofs(0))
        found = .true.
        converged = .true.
    end subroutine rigid_project

    pure subroutine rigid_move(self, offset)
        class(rigid_line_t), intent(inout) :: self
        real(dp), intent(in) :: offset(2)
        self%p0 = self%p_ref + offset
    end subroutine rigid_move

    !> Where the line is at this step: a point, its normal, and the translation
    !> from load time 0.
    pure function rigid_output(self) result(out)
        class(rigid_line_t), intent(in) :: self
        type(master_output_t) :: out
        out%curve_name = ''
        out%names = [character(len=16) :: 'rigid_point', 'rigid_normal', 'rigid_offset']
        out%vectors = reshape([self%p0, self%n, self%p0 - self%p_ref], [size(self%p0), 3])
    end function rigid_output

end module voiga_contact_master_rigid
