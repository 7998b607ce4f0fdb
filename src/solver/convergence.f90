!> When a Newton iteration has converged: one pure assessment used by every
!> iteration (`voiga_solver_newton`) and by the outer loops (`voiga_solver_outer`).
!>
!> Converged when ||r|| <= tol_residual ||r_0|| or |du.r| <= tol_energy |du_1.r_0|
!> (with ||r|| <= sqrt(tol_residual) ||r_0||), r_0 the substep's first residual, or
!> when the residual has reached its round-off level: relative to the run's force
!> scale (the largest first residual so far), or `residual_floor`, the rounding of
!> the coordinates times the stiffness (with a stiff penalty ||K|| is so large that
!> rounding the coordinates alone moves the residual by more than tol ||r_0||).
module voiga_solver_convergence
    use voiga_kinds, only: dp
    use voiga_linalg_sparse, only: csc_matrix_t
    implicit none
    private

    public :: convergence_t, converged, at_roundoff, residual_floor, floor_cap, divergence_ratio

    !> Safety factor of the round-off floor `residual_floor` (rounding errors of a
    !> sum of many element contributions add up; measured over 148 converged
    !> substeps of ironing with penalty 1e6 x E: the final residual is 0.06 to 0.9
    !> times eps || |K| |x| ||, 5.7 at most; docs/robustness.md).
    real(dp), parameter :: floor_factor = 10.0_dp

    !> The round-off floor ends the iteration only when the residual is also below
    !> this fraction of the run's force scale (the largest first residual of a
    !> substep so far, or this substep's): a floor above it (a penalty too stiff for
    !> double precision) fails the substep instead of accepting it. The force scale,
    !> not the substep's own first residual: the floor does not shrink with the load
    !> increment, so a cut substep would otherwise never reach it.
    real(dp), parameter :: floor_cap = 1.0e-6_dp

    !> A Newton iteration whose residual exceeds this multiple of the substep's
    !> first residual has diverged (the substep is cut instead of iterated to the cap).
    real(dp), parameter :: divergence_ratio = 1.0e10_dp

    !> Below this multiple of eps times the force scale the residual is round-off.
    real(dp), parameter :: roundoff_factor = 1.0e4_dp

    !> Where an iteration stands.
    type :: convergence_t
        !> Newton iterations done (0: the substep's first residual).
        integer :: iteration = 0
        !> Residual norm (free DOFs), the substep's first, and the force scale
        !> max(r_0, the largest first residual of the run).
        real(dp) :: residual = 0.0_dp, first = 0.0_dp, scale = 0.0_dp
        !> Round-off floor at the current coordinates (`residual_floor`).
        real(dp) :: floor = 0.0_dp
        !> |du.r| of the last iteration and of the first (huge, 0: none).
        real(dp) :: energy = huge(1.0_dp), first_energy = 0.0_dp
    end type convergence_t

contains

    !> Whether the iteration `c` has converged for the tolerances `tol_residual`,
    !> `tol_energy`. The floor counts only after a Newton step (iteration > 0), the
    !> energy criterion only from the second.
    pure logical function converged(c, tol_residual, tol_energy)
        type(convergence_t), intent(in) :: c
        real(dp), intent(in) :: tol_residual, tol_energy
        converged = c%residual <= tol_residual*c%first .or. c%residual == 0.0_dp
        ! the energy criterion alone may not hide a stalled residual
        if (c%iteration > 1 .and. c%energy <= tol_energy*c%first_energy .and. &
            c%residual <= sqrt(tol_residual)*c%first) converged = .true.
        ! round-off floor: nothing left to gain relative to the largest first residual
        ! of the run (not the reactions, which can be huge with stiff penalties)
        if (c%residual <= roundoff_factor*epsilon(1.0_dp)*c%scale) converged = .true.
        ! the residual is at the round-off level of the stiffness times the
        ! coordinates (stiff penalties): accepted only after a Newton step and
        ! below floor_cap of the force scale
        if (c%iteration > 0 .and. c%residual <= c%floor .and. c%residual <= floor_cap*c%scale) &
            converged = .true.
    end function converged

    !> Whether the residual `rn` is at a round-off level (the floor, or relative
    !> to the force scale `scale`): no step shortening is worth it there.
    pure logical function at_roundoff(rn, floor, scale)
        real(dp), intent(in) :: rn, floor, scale
        at_roundoff = .not. (rn > floor .and. rn > roundoff_factor*epsilon(1.0_dp)*scale)
    end function at_roundoff

    !> Round-off level of the residual at coordinates `x`: floor_factor eps || |K| |x| ||
    !> on the free DOFs. Rounding every coordinate x_j by its unit round-off eps |x_j|
    !> changes the residual by up to (|K| eps |x|)_i; a residual below that is as
    !> converged as double precision can tell (a componentwise backward error of the
    !> coordinates of order eps). With a stiff penalty ||K|| is large and this floor
    !> lies above tol_residual ||r_0||. `k` is the assembled tangent before the
    !> Dirichlet elimination.
    pure real(dp) function residual_floor(k, x, fixed) result(floor)
        type(csc_matrix_t), intent(in) :: k
        !> Current coordinates (reference + displacement) of every DOF; shape: [ndof].
        real(dp), intent(in) :: x(:)
        !> .true. for a Dirichlet DOF; shape: [ndof].
        logical, intent(in) :: fixed(:)
        real(dp), allocatable :: w(:)
        integer :: j, p
        allocate (w(k%n))
        w = 0.0_dp
        do j = 1, k%n
            do p = k%colptr(j) + 1, k%colptr(j + 1)
                w(k%rowind(p) + 1) = w(k%rowind(p) + 1) + abs(k%values(p))*abs(x(j))
            end do
        end do
        floor = floor_factor*epsilon(1.0_dp)*norm2(merge(0.0_dp, w, fixed))
    end function residual_floor

end module voiga_solver_convergence
