!> The plane body's patch as the geometry file gives it: a NURBS surface with named
!> edges, its edge curves and its re-orientation (the contact edge made eta = 1).
!> The discretization refines and evaluates it as a general patch
!> (`surface_patch`, `voiga_nurbs_patch`): one implementation of those operations.
module voiga_nurbs_surface
    use voiga_kinds, only: dp
    use voiga_nurbs_curve, only: nurbs_curve_t, curve_from_patch
    use voiga_nurbs_patch, only: nurbs_patch_t, knots_t, new_patch, patch_eval, patch_boundary
    implicit none
    private

    public :: nurbs_surface_t, surface_eval, surface_edge_curve
    public :: surface_reorient, edge_index, edge_labels, surface_patch

    !> Labels of the four parametric edges, in the order of `edge_names`.
    character(len=4), parameter :: edge_labels(4) = ['xi0 ', 'xi1 ', 'eta0', 'eta1']

    !> A NURBS patch. Directions: 1 = xi, 2 = eta.
    type :: nurbs_surface_t
        !> Degrees [p_xi, p_eta].
        integer :: degree(2) = 0
        !> Knot vectors, shapes [n_xi + p_xi + 1] and [n_eta + p_eta + 1].
        real(dp), allocatable :: knots_xi(:), knots_eta(:)
        !> Cartesian control points, shape [2, n_xi, n_eta].
        real(dp), allocatable :: cp(:, :, :)
        !> Weights, shape [n_xi, n_eta].
        real(dp), allocatable :: w(:, :)
        !> Names of the edges xi = 0, xi = 1, eta = 0, eta = 1.
        character(len=32) :: edge_names(4) = ['xi0 ', 'xi1 ', 'eta0', 'eta1']
    end type nurbs_surface_t

contains

    !> Index (1..4) of the edge called `name`, 0 if there is none.
    pure integer function edge_index(surf, name)
        type(nurbs_surface_t), intent(in) :: surf
        character(len=*), intent(in) :: name
        integer :: i
        edge_index = 0
        do i = 1, 4
            if (trim(surf%edge_names(i)) == trim(name)) edge_index = i
        end do
    end function edge_index

    !> The surface as a general patch (pdim 2, nsd 2), for evaluation (`patch_eval`)
    !> in loops: convert once, evaluate many times.
    pure function surface_patch(surf) result(patch)
        type(nurbs_surface_t), intent(in) :: surf
        type(nurbs_patch_t) :: patch
        integer :: n(2)
        n = shape(surf%w)
        patch = new_patch(surf%degree, [knots_t(surf%knots_xi), knots_t(surf%knots_eta)], n, &
                          reshape(surf%cp, [2, product(n)]), reshape(surf%w, [product(n)]))
    end function surface_patch

    !> Point `x` and Jacobian `dx` (shape [2, 2]: dx(:, 1) = dx/dxi, dx(:, 2) = dx/deta).
    !> (Each call converts the surface: in a loop, evaluate `surface_patch` instead.)
    pure subroutine surface_eval(surf, xi, eta, x, dx)
        type(nurbs_surface_t), intent(in) :: surf
        real(dp), intent(in) :: xi, eta
        real(dp), intent(out) :: x(2)
        real(dp), intent(out), optional :: dx(2, 2)
        call patch_eval(surface_patch(surf), [xi, eta], x, dx)
    end subroutine surface_eval

    !> The boundary curve on edge `edge` (1..4 = xi0, xi1, eta0, eta1), running in
    !> the direction of the parameter along that edge (`patch_boundary`).
    pure function surface_edge_curve(surf, edge) result(curve)
        type(nurbs_surface_t), intent(in) :: surf
        integer, intent(in) :: edge
        type(nurbs_curve_t) :: curve
        ! edges 1, 2 are the ends of direction 1 (xi), edges 3, 4 those of eta
        curve = curve_from_patch(patch_boundary(surface_patch(surf), (edge + 1)/2, 1 - mod(edge, 2)))
    end function surface_edge_curve

    !> Re-parametrize the patch so that edge `edge` (1..4) becomes eta = 1, by a
    !> rotation of the parameter square (orientation is kept). The geometry and the
    !> edge names move with it.
    pure subroutine surface_reorient(surf, edge)
        type(nurbs_surface_t), intent(inout) :: surf
        integer, intent(in) :: edge
        type(nurbs_surface_t) :: old

        if (edge == 4) return
        old = surf
        select case (edge)
        case (3)
            ! rotate by 180 degrees: xi' = 1 - xi, eta' = 1 - eta
            surf%knots_xi = flip_knots(old%knots_xi)
            surf%knots_eta = flip_knots(old%knots_eta)
            surf%cp = old%cp(:, size(old%w, 1):1:-1, size(old%w, 2):1:-1)
            surf%w = old%w(size(old%w, 1):1:-1, size(old%w, 2):1:-1)
            surf%edge_names = old%edge_names([2, 1, 4, 3])
        case (2)
            ! xi' = 1 - eta, eta' = xi
            surf%degree = old%degree([2, 1])
            surf%knots_xi = flip_knots(old%knots_eta)
            surf%knots_eta = old%knots_xi
            call turn(old, .false., surf%cp, surf%w)
            ! new xi0 = old eta1, new xi1 = old eta0, new eta0 = old xi0, new eta1 = old xi1
            surf%edge_names = old%edge_names([4, 3, 1, 2])
        case (1)
            ! xi' = eta, eta' = 1 - xi
            surf%degree = old%degree([2, 1])
            surf%knots_xi = old%knots_eta
            surf%knots_eta = flip_knots(old%knots_xi)
            call turn(old, .true., surf%cp, surf%w)
            ! new xi0 = old eta0, new xi1 = old eta1, new eta0 = old xi1, new eta1 = old xi0
            surf%edge_names = old%edge_names([3, 4, 2, 1])
        case default
            ! edge 4 (returned above) is eta1 already
        end select
    end subroutine surface_reorient

    !> The control net of `old` turned by a quarter, shapes [2, n_eta, n_xi] and
    !> [n_eta, n_xi]: old point (i, j) becomes new point (j, n_xi + 1 - i) when
    !> `flip_xi` (xi' = eta, eta' = 1 - xi), else (n_eta + 1 - j, i) (xi' = 1 - eta,
    !> eta' = xi). Explicit loops into fresh arrays: gfortran 12
    !> gives `x%w = transpose(y%w(n:1:-1, :))` the shape of the old `x%w` when that
    !> is not square (the double free of a non-square patch turned to its xi0 or xi1).
    pure subroutine turn(old, flip_xi, cp, w)
        type(nurbs_surface_t), intent(in) :: old
        logical, intent(in) :: flip_xi
        real(dp), allocatable, intent(out) :: cp(:, :, :), w(:, :)
        integer :: nx, ny, i, j
        nx = size(old%w, 1)
        ny = size(old%w, 2)
        allocate (cp(2, ny, nx), w(ny, nx))
        do j = 1, ny
            do i = 1, nx
                if (flip_xi) then
                    cp(:, j, nx + 1 - i) = old%cp(:, i, j)
                    w(j, nx + 1 - i) = old%w(i, j)
                else
                    cp(:, ny + 1 - j, i) = old%cp(:, i, j)
                    w(ny + 1 - j, i) = old%w(i, j)
                end if
            end do
        end do
    end subroutine turn

    !> Knot vector of the reversed parameter u' = a + b - u.
    pure function flip_knots(knots) result(flipped)
        real(dp), intent(in) :: knots(:)
        real(dp) :: flipped(size(knots))
        flipped = knots(1) + knots(size(knots)) - knots(size(knots):1:-1)
    end function flip_knots

end module voiga_nurbs_surface
