!> The master side of a contact pair: a deformable body's contact edge (NURBS),
!> or a rigid obstacle without DOFs (a straight line, or any NURBS curve of the
!> geometry file). Each answers the closest-point projection of a slave point
!> with a `master_point_t`; a rigid one is moved by its prescribed motion
!> (`move`, called by the model at the load time before every assembly). Each
!> also says what of it a step's contact output records (`output`).
module voiga_contact_master
    use voiga_kinds, only: dp
    use voiga_nurbs_curve, only: nurbs_curve_t
    implicit none
    private

    public :: contact_master_t, master_point_t, master_no_dofs, master_output_t

    !> The master at the projection of a slave point.
    type :: master_point_t
        !> Convective coordinates (eta: a surface's second; 0 on a curve).
        real(dp) :: xi = 0.0_dp, eta = 0.0_dp
        !> Point, tangent dx/dxi, second derivative d2x/dxi2 [nsd; z = 0 in 2D]; on a
        !> surface also dx/deta, d2x/deta2 and d2x/dxi deta.
        real(dp) :: x(3) = 0.0_dp, a(3) = 0.0_dp, a2(3) = 0.0_dp
        real(dp) :: b(3) = 0.0_dp, b2(3) = 0.0_dp, ab(3) = 0.0_dp
        !> Outward unit normal of the master body at the point.
        real(dp) :: n(3) = 0.0_dp
        !> Function values and derivatives at xi (by eta: `drb`, a surface's) [nm]
        !> (empty for a rigid master).
        real(dp), allocatable :: r(:), dr(:), drb(:)
        !> Global DOFs of those functions [2 nm], order 2(k-1) + i.
        integer, allocatable :: dofs(:)
        !> Range of the master's control points (positions in `all_dofs` / 2) that
        !> those functions belong to; empty (first > last) for a rigid master.
        integer :: first = 1, last = 0
    end type master_point_t

    !> What a master's kind adds to a pair's output at a step (docs/hdf5.md,
    !> `/steps/<k>/contact/<p>`): named vectors and, for a rigid curve, the curve
    !> where it is. The result writer (`voiga_io_output_results`) stores it as it is, in
    !> this order, so the master decides what describes it and contact/ calls no
    !> HDF5.
    type :: master_output_t
        !> A curve written first as the group `curve_name` (empty: none).
        character(len=:), allocatable :: curve_name
        type(nurbs_curve_t) :: curve
        !> Datasets of one value per spatial axis each: `names(j)` holds `vectors(:, j)`;
        !> shape [nsd, n] (its first extent is the master's points', never a literal 2).
        character(len=16), allocatable :: names(:)
        real(dp), allocatable :: vectors(:, :)
    end type master_output_t

    !> A master surface.
    type, abstract :: contact_master_t
        !> Does it carry DOFs?
        logical :: deformable = .false.
    contains
        procedure(project_interface), deferred :: project
        !> Every DOF the master may couple to (for the stiffness pattern); default: none.
        procedure :: all_dofs => master_no_dofs
        !> Control points per row of the master's numbering when they form a grid (a
        !> face: n_xi), else 0 (one row: an edge). The pair's pattern ranges are
        !> rectangles of that grid, not bands of whole rows.
        procedure :: grid_width => master_grid_width
        procedure :: prepare => master_prepare
        procedure :: move => master_move
        !> What a step's contact output records of it; default: nothing (a
        !> deformable master is in its body's displacement).
        procedure :: output => master_output
    end type contact_master_t

    abstract interface
        !> Closest point on the master to `xs` in the configuration `u`; `found` is
        !> false when the orthogonal projection falls beyond the master's ends.
        !> `prepare(u)` must have been called with the same `u` first.
        pure subroutine project_interface(self, u, xs, mp, found, converged, start)
            import :: contact_master_t, master_point_t, dp
            class(contact_master_t), intent(in) :: self
            !> `xs`: the slave point [nsd].
            real(dp), intent(in) :: u(:), xs(:)
            type(master_point_t), intent(out) :: mp
            logical, intent(out) :: found
            !> False if the local Newton iteration did not converge.
            logical, intent(out) :: converged
            !> Where the same slave point projected at the last evaluation (its
            !> parameters: [xi] on a curve, [xi, eta] on a surface): a start for the
            !> local iteration (its result does not depend on it but by rounding).
            real(dp), intent(in), optional :: start(:)
        end subroutine project_interface
    end interface

contains

    !> No DOFs: a rigid master.
    pure function master_no_dofs(self) result(dofs)
        class(contact_master_t), intent(in) :: self
        integer, allocatable :: dofs(:)
        allocate (dofs(0))
        if (self%deformable) dofs = [integer ::]   ! (a deformable master overrides this)
    end function master_no_dofs

    !> One row (an edge or a rigid master): 0.
    pure integer function master_grid_width(self) result(width)
        class(contact_master_t), intent(in) :: self
        width = 0
        if (self%deformable) width = 0   ! (a face master overrides this)
    end function master_grid_width

    !> Update whatever the master's search needs for the configuration `u` (called
    !> once per evaluation of a pair, before its projections). Default: nothing.
    pure subroutine master_prepare(self, u)
        class(contact_master_t), intent(inout) :: self
        real(dp), intent(in) :: u(:)
        ! a rigid master has nothing to update
    end subroutine master_prepare

    !> Put a rigid master at its reference position translated by `offset` [nsd]
    !> (its prescribed motion at the current load time). Default: nothing (a
    !> deformable master moves with its body's DOFs).
    pure subroutine master_move(self, offset)
        class(contact_master_t), intent(inout) :: self
        real(dp), intent(in) :: offset(:)
    end subroutine master_move

    !> Nothing: a deformable master's position is its body's.
    pure function master_output(self) result(out)
        class(contact_master_t), intent(in) :: self
        type(master_output_t) :: out
        out%curve_name = ''
        allocate (out%names(0), out%vectors(2, 0))
        if (self%deformable) return   ! (whatever the master; a rigid one overrides this)
    end function master_output

end module voiga_contact_master
