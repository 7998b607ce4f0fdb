!> A rigid obstacle of any shape: a NURBS curve of the geometry file (a flat
!> punch with rounded corners, a cylinder, a die profile) without DOFs, moved as a
!> whole by its prescribed motion. The closest-point search and projection are the
!> deformable master's (`voiga_contact_master_nurbs`), run on the curve's own
!> control points: its displacement vector is zero and `move` translates the
!> control points instead, so a projection carries no master functions and the
!> pair couples no master DOF.
!>
!> Side: the curve runs like a body's boundary, counter-clockwise around the
!> obstacle: the obstacle lies to the left as the parameter increases, and its
!> outward normal is n = (a_y, -a_x)/|a| (a = dx/dxi; docs/formats.md).
module voiga_contact_master_curve
    use voiga_kinds, only: dp
    use voiga_nurbs_curve, only: nurbs_curve_t
    use voiga_contact_master, only: master_point_t, master_no_dofs, master_output_t
    use voiga_contact_master_nurbs, only: nurbs_master_t, nurbs_prepare, nurbs_project
    use voiga_contact_surface, only: new_curve_surface
    implicit none
    private

    public :: rigid_curve_t, new_rigid_curve

    !> A rigid curve master.
    type, extends(nurbs_master_t) :: rigid_curve_t
        !> Control points at load time 0 [2, n].
        real(dp), allocatable :: x_ref(:, :)
        !> The curve's displacement vector: always zero [2 n] (the motion is in the
        !> control points, `surf%x0`).
        real(dp), allocatable :: zero(:)
        !> The current translation from the reference position.
        real(dp) :: offset(2) = 0.0_dp
        !> The curve's name in the geometry file (`&contact rigid_curve`), for messages.
        character(len=32) :: name = ''
    contains
        procedure :: project => curve_project
        procedure :: all_dofs => curve_all_dofs
        procedure :: prepare => curve_prepare
        procedure :: move => curve_move
        procedure :: output => curve_output
    end type rigid_curve_t

contains

    !> The obstacle bounded by `curve` (on its left, see the module comment), at
    !> its reference position.
    pure subroutine new_rigid_curve(self, curve)
        type(rigid_curve_t), intent(out) :: self
        type(nurbs_curve_t), intent(in) :: curve
        self%deformable = .false.
        call new_curve_surface(self%surf, curve)
        ! n = sign (a_y, -a_x)/|a| (voiga_contact_master_nurbs): the right-hand normal
        self%sign = 1.0_dp
        self%x_ref = curve%cp
        allocate (self%zero(2*size(curve%w)), source=0.0_dp)
    end subroutine new_rigid_curve

    !> The search structure of the curve where it is now (`u`, the bodies'
    !> displacements, does not move it).
    pure subroutine curve_prepare(self, u)
        class(rigid_curve_t), intent(inout) :: self
        real(dp), intent(in) :: u(:)
        if (size(u) < 0) return   ! the curve has no DOFs in u
        call nurbs_prepare(self, self%zero)
    end subroutine curve_prepare

    !> The deformable master's projection on the curve where it is now, without
    !> master functions (no DOFs to couple).
    pure subroutine curve_project(self, u, xs, mp, found, converged, start)
        class(rigid_curve_t), intent(in) :: self
        real(dp), intent(in) :: u(:), xs(:)
        type(master_point_t), intent(out) :: mp
        logical, intent(out) :: found, converged
        real(dp), intent(in), optional :: start(:)
        if (size(u) < 0) return   ! the curve has no DOFs in u
        call nurbs_project(self, self%zero, xs, mp, found, converged, start)
        deallocate (mp%r, mp%dr, mp%dofs)
        allocate (mp%r(0), mp%dr(0), mp%dofs(0))
        mp%first = 1
        mp%last = 0
    end subroutine curve_project

    !> None (the NURBS master's would be the curve's own control points).
    pure function curve_all_dofs(self) result(dofs)
        class(rigid_curve_t), intent(in) :: self
        integer, allocatable :: dofs(:)
        dofs = master_no_dofs(self)
    end function curve_all_dofs

    !> Translate the curve to its reference position plus `offset`.
    pure subroutine curve_move(self, offset)
        class(rigid_curve_t), intent(inout) :: self
        real(dp), intent(in) :: offset(:)
        self%offset = offset
        self%surf%x0(1, :) = self%x_ref(1, :) + offset(1)
        self%surf%x0(2, :) = self%x_ref(2, :) + offset(2)
    end subroutine curve_move

    !> The curve where it is at this step, and its translation from load time 0.
    pure function curve_output(self) result(out)
        class(rigid_curve_t), intent(in) :: self
        type(master_output_t) :: out
        out%curve_name = 'rigid_curve'
        out%curve = nurbs_curve_t(self%surf%degree, self%surf%knots, self%surf%x0, self%surf%w)
        out%names = [character(len=16) :: 'rigid_offset']
        out%vectors = reshape(self%offset, [size(self%offset), 1])
    end function curve_output

end module voiga_contact_master_curve
