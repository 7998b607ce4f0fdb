!> Tensor-product NURBS surfaces (one patch of a 2D body): evaluation,
!> refinement along one direction, edge curves and re-orientation.
module voiga_nurbs_surface
    use voiga_kinds, only: dp
    use voiga_nurbs_basis, only: find_span, basis_ders
    use voiga_nurbs_rational, only: rationalize
    use voiga_nurbs_refine, only: insert_knots, elevate_degree
    use voiga_nurbs_curve, only: nurbs_curve_t
    implicit none
    private

    public :: nurbs_surface_t, surface_eval, surface_elevate, surface_insert, surface_edge_curve
    public :: surface_reorient, edge_index, edge_labels

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

    !> Point `x` and Jacobian `dx` (shape [2, 2]: dx(:, 1) = dx/dxi, dx(:, 2) = dx/deta).
    pure subroutine surface_eval(surf, xi, eta, x, dx)
        type(nurbs_surface_t), intent(in) :: surf
        real(dp), intent(in) :: xi, eta
        real(dp), intent(out) :: x(2)
        real(dp), intent(out), optional :: dx(2, 2)
        integer :: p, q, sx, se, nf, i, j, a
        real(dp), allocatable :: bx(:, :), be(:, :), w(:), b(:), db(:, :), d2b(:, :), &
                                 r(:), dr(:, :), d2r(:, :), pts(:, :)

        p = surf%degree(1)
        q = surf%degree(2)
        sx = find_span(surf%knots_xi, p, xi)
        se = find_span(surf%knots_eta, q, eta)
        bx = basis_ders(surf%knots_xi, p, sx, xi, 1)
        be = basis_ders(surf%knots_eta, q, se, eta, 1)
        nf = (p + 1)*(q + 1)
        allocate (w(nf), b(nf), db(2, nf), d2b(3, nf), r(nf), dr(2, nf), d2r(3, nf), pts(2, nf))
        d2b = 0.0_dp
        a = 0
        do j = 1, q + 1
            do i = 1, p + 1
                a = a + 1
                w(a) = surf%w(sx - p + i - 1, se - q + j - 1)
                pts(:, a) = surf%cp(:, sx - p + i - 1, se - q + j - 1)
                b(a) = bx(1, i)*be(1, j)
                db(1, a) = bx(2, i)*be(1, j)
                db(2, a) = bx(1, i)*be(2, j)
            end do
        end do
        call rationalize(w, b, db, d2b, r, dr, d2r)
        x = matmul(pts, r)
        if (present(dx)) dx = matmul(pts, transpose(dr))
    end subroutine surface_eval

    !> Homogeneous control points of the patch, shape [3, n_xi, n_eta].
    pure function homogeneous(surf) result(pw)
        type(nurbs_surface_t), intent(in) :: surf
        real(dp), allocatable :: pw(:, :, :)
        allocate (pw(3, size(surf%w, 1), size(surf%w, 2)))
        pw(1, :, :) = surf%cp(1, :, :)*surf%w
        pw(2, :, :) = surf%cp(2, :, :)*surf%w
        pw(3, :, :) = surf%w
    end function homogeneous

    pure subroutine set_homogeneous(surf, pw)
        type(nurbs_surface_t), intent(inout) :: surf
        real(dp), intent(in) :: pw(:, :, :)
        surf%w = pw(3, :, :)
        if (allocated(surf%cp)) deallocate (surf%cp)
        allocate (surf%cp(2, size(pw, 2), size(pw, 3)))
        surf%cp(1, :, :) = pw(1, :, :)/pw(3, :, :)
        surf%cp(2, :, :) = pw(2, :, :)/pw(3, :, :)
    end subroutine set_homogeneous

    !> Apply a curve refinement to every row (dir = 1) or column (dir = 2):
    !> the other direction's control points are carried as extra coordinates.
    pure subroutine refine_direction(surf, dir, t, values)
        type(nurbs_surface_t), intent(inout) :: surf
        integer, intent(in) :: dir
        !> Degree elevation steps (0: none).
        integer, intent(in) :: t
        !> Knots to insert (after elevation).
        real(dp), intent(in) :: values(:)
        real(dp), allocatable :: pw3(:, :, :), flat(:, :), knots(:), out(:, :, :)
        integer :: nx, ny, p

        pw3 = homogeneous(surf)
        nx = size(pw3, 2)
        ny = size(pw3, 3)
        if (dir == 1) then
            ! rows: curve index is xi; carry [3*ny] coordinates per xi control point
            flat = reshape(reshape(pw3, [3, ny, nx], order=[1, 3, 2]), [3*ny, nx])
            knots = surf%knots_xi
            p = surf%degree(1)
        else
            flat = reshape(pw3, [3*nx, ny])
            knots = surf%knots_eta
            p = surf%degree(2)
        end if
        if (t > 0) call elevate_degree(p, knots, flat, t)
        if (size(values) > 0) call insert_knots(p, knots, flat, values)
        if (dir == 1) then
            out = reshape(reshape(flat, [3, ny, size(flat, 2)]), [3, size(flat, 2), ny], order=[1, 3, 2])
            surf%knots_xi = knots
            surf%degree(1) = p
        else
            out = reshape(flat, [3, nx, size(flat, 2)])
            surf%knots_eta = knots
            surf%degree(2) = p
        end if
        call set_homogeneous(surf, out)
    end subroutine refine_direction

    !> Raise the degree along direction `dir` (1 = xi, 2 = eta) by `t`.
    pure subroutine surface_elevate(surf, dir, t)
        type(nurbs_surface_t), intent(inout) :: surf
        integer, intent(in) :: dir, t
        real(dp) :: none(0)
        if (t > 0) call refine_direction(surf, dir, t, none)
    end subroutine surface_elevate

    !> Insert each of `values` once along direction `dir`.
    pure subroutine surface_insert(surf, dir, values)
        type(nurbs_surface_t), intent(inout) :: surf
        integer, intent(in) :: dir
        real(dp), intent(in) :: values(:)
        if (size(values) > 0) call refine_direction(surf, dir, 0, values)
    end subroutine surface_insert

    !> The boundary curve on edge `edge` (1..4 = xi0, xi1, eta0, eta1), running in
    !> the direction of the parameter along that edge.
    pure function surface_edge_curve(surf, edge) result(curve)
        type(nurbs_surface_t), intent(in) :: surf
        integer, intent(in) :: edge
        type(nurbs_curve_t) :: curve
        integer :: nx, ny

        nx = size(surf%w, 1)
        ny = size(surf%w, 2)
        select case (edge)
        case (1, 2)
            curve%degree = surf%degree(2)
            curve%knots = surf%knots_eta
            curve%cp = surf%cp(:, merge(1, nx, edge == 1), :)
            curve%w = surf%w(merge(1, nx, edge == 1), :)
        case default
            curve%degree = surf%degree(1)
            curve%knots = surf%knots_xi
            curve%cp = surf%cp(:, :, merge(1, ny, edge == 3))
            curve%w = surf%w(:, merge(1, ny, edge == 3))
        end select
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
