!> Closest-point projection of a point onto a NURBS surface (pdim 2, nsd 3): the
!> kernel 3D contact needs (issue 42), kept in `nurbs/` because it is geometry of
!> one patch and knows nothing of DOFs or contact (the 2D one lives in
!> `contact/master_nurbs.f90` because it reads the displaced contact edge; a 3D master
!> will build a `surface_search_t` from its displaced face and call this).
!>
!> Search (built once per configuration by `new_surface_search`): per knot-span cell,
!> the box of its (p + 1)(q + 1) control points, axis-aligned and in the cell's own
!> tangent frame. With positive weights a NURBS cell lies in the convex hull of its
!> control points, so either box's distance is a rigorous lower bound of the cell's
!> distance: no chord-error estimate of a sampled box is needed, and no cell holding
!> the closest point can be pruned by mistake.
!>
!> Query (`project_on_surface`): an upper bound from the nearest start sample of the
!> nearest box; the cells whose boxes are closer than that, nearest first, stopping at
!> the first whose box is no closer than the best point found; in each,
!> a projected Newton iteration on f(u) = |x - S(u)|^2 / 2 over the cell's parameter
!> box from the nearest of a few stored samples: the full Hessian
!> H = a_a . a_b - (x - S) . a_ab when it is positive definite, else the first
!> fundamental form (Gauss-Newton, regularized where a tangent vanishes: a collapsed
!> edge), with a backtracking search on f along the projected path. Directions at a
!> bound with the gradient pushing outward are held (the active set), which makes
!> the iteration end on cell edges and corners, and a collapsed edge, cleanly. A
!> point whose minimum is on the patch's boundary (beyond the patch) is minimized
!> again along the boundary edges, since a cell's Newton may have stopped at a local
!> minimum of the edge it reached first.
module voiga_nurbs_projection
    use voiga_kinds, only: dp
    use voiga_nurbs_patch, only: nurbs_patch_t, cross
    use voiga_nurbs_basis, only: find_span, basis_ders_at, distinct_knots, max_fixed_degree
    use voiga_nurbs_cell_tree, only: cell_tree_t, new_cell_tree, cells_within, nearest_box, box_distance2
    implicit none
    private

    public :: surface_search_t, surface_projection_t, new_surface_search, project_on_surface
    public :: surface_derivatives

    !> Projected Newton iterations per cell, backtracking halvings per iteration.
    integer, parameter :: max_newton = 60, max_halvings = 40
    !> Start samples per direction per cell (cell-centred: none on a collapsed edge).
    integer, parameter :: n_start = 4

    !> The search structure of one surface patch in one configuration.
    type :: surface_search_t
        !> The surface (pdim 2, nsd 3, positive weights).
        type(nurbs_patch_t) :: patch
        !> Breakpoints per direction [ncell_u + 1], [ncell_v + 1].
        real(dp), allocatable :: breaks_u(:), breaks_v(:)
        !> Knot-span index of each cell column and row [ncell_u], [ncell_v].
        integer, allocatable :: span_u(:), span_v(:)
        !> Each cell's box of its control points [xmin, ymin, zmin, xmax, ymax, zmax]
        !> [6, ncell] (cell c = i + (j - 1) ncell_u); the cell's own orthonormal frame
        !> (rows: the unit tangent along u, the in-plane normal to it, the normal at
        !> the cell's centre) [3, 3, ncell] and the box in that frame [6, ncell]: the
        !> first is cheap to test against every cell, the second sharp for the few
        !> that pass.
        real(dp), allocatable :: boxes(:, :), frames(:, :, :), oboxes(:, :)
        !> Start samples [3, n_start**2, ncell], at the cell-centred parameters of
        !> `sample_parameters`.
        real(dp), allocatable :: samples(:, :, :)
        !> Diagonal of the control net's box: the length scale of the tolerances.
        real(dp) :: scale = 1.0_dp
        !> The cells' boxes in a tree (`voiga_nurbs_cell_tree`): a query visits the
        !> nodes within reach, so its cost grows like log(cells) plus the cells it tests.
        type(cell_tree_t) :: tree
    end type surface_search_t

    !> A projection's result. The normal is a1 x a2 / |a1 x a2|: for the zeta = 1 face
    !> of a right-handed volume (det J > 0; `patch_boundary(volume, 3, 1)`) it points
    !> out of the volume, since (a1 x a2) . a3 = det J > 0 and a3 = dX/dzeta points out
    !> at zeta = 1. At a collapsed edge it is the limit from inside the patch.
    type :: surface_projection_t
        !> Parameters (u, v).
        real(dp) :: u(2) = 0.0_dp
        !> Closest point, tangents a1 = dS/du, a2 = dS/dv, second derivatives
        !> a11, a22, a12 and unit normal, each [3].
        real(dp) :: x(3) = 0.0_dp, a1(3) = 0.0_dp, a2(3) = 0.0_dp
        real(dp) :: a11(3) = 0.0_dp, a22(3) = 0.0_dp, a12(3) = 0.0_dp, n(3) = 0.0_dp
        !> |x - S(u, v)|.
        real(dp) :: distance = huge(1.0_dp)
        !> The cell it lies in (i + (j - 1) ncell_u).
        integer :: cell = 0
    end type surface_projection_t

contains

    !> The search structure of `patch` (pdim 2, nsd 3, positive weights, degrees up to
    !> `max_fixed_degree`) in its present control points; rebuild it whenever they move.
    pure subroutine new_surface_search(search, patch)
        type(surface_search_t), intent(out) :: search
        type(nurbs_patch_t), intent(in) :: patch
        real(dp) :: d1(3, 2), d2(3, 3), pts(3, (max_fixed_degree + 1)**2)
        integer :: nu, nv, i, j, c, k, a, b, np, span(2)
        search%patch = patch
        search%breaks_u = distinct_knots(patch%knots(1)%u)
        search%breaks_v = distinct_knots(patch%knots(2)%u)
        nu = size(search%breaks_u) - 1
        nv = size(search%breaks_v) - 1
        allocate (search%span_u(nu), search%span_v(nv), search%boxes(6, nu*nv), search%frames(3, 3, nu*nv), &
                  search%oboxes(6, nu*nv), search%samples(3, n_start**2, nu*nv))
        do i = 1, nu
            search%span_u(i) = find_span(patch%knots(1)%u, patch%degree(1), &
                                         0.5_dp*(search%breaks_u(i) + search%breaks_u(i + 1)))
        end do
        do j = 1, nv
            search%span_v(j) = find_span(patch%knots(2)%u, patch%degree(2), &
                                         0.5_dp*(search%breaks_v(j) + search%breaks_v(j + 1)))
        end do
        search%scale = norm2(maxval(patch%cp, dim=2) - minval(patch%cp, dim=2))
        np = (patch%degree(1) + 1)*(patch%degree(2) + 1)
        do j = 1, nv
            do i = 1, nu
                c = i + (j - 1)*nu
                span = [search%span_u(i), search%span_v(j)]
                k = 0
                do b = span(2) - patch%degree(2), span(2)
                    do a = span(1) - patch%degree(1), span(1)
                        k = k + 1
                        pts(:, k) = patch%cp(:, a + (b - 1)*patch%n(1))
                    end do
                end do
                search%boxes(1:3, c) = minval(pts(:, 1:np), dim=2)
                search%boxes(4:6, c) = maxval(pts(:, 1:np), dim=2)
                search%frames(:, :, c) = cell_frame(search, c, span)
                pts(:, 1:np) = matmul(search%frames(:, :, c), pts(:, 1:np))
                search%oboxes(1:3, c) = minval(pts(:, 1:np), dim=2)
                search%oboxes(4:6, c) = maxval(pts(:, 1:np), dim=2)
                do k = 1, n_start**2
                    call surface_derivatives(patch, sample_parameters(search, c, k), span, &
                                             search%samples(:, k, c), d1, d2)
                end do
            end do
        end do
        call new_cell_tree(search%tree, search%boxes, nu, nv)
    end subroutine new_surface_search

    !> The orthonormal frame [3, 3] (rows) of cell `c` at its centre: a1, then the
    !> part of a2 normal to it, then their normal. Any frame gives a valid box; this
    !> one makes a nearly flat cell's box a thin slab, so that a point above one cell
    !> is not within its neighbours' boxes (the search's pruning is then sharp). A
    !> degenerate centre (no tangent) falls back to the axes.
    pure function cell_frame(search, c, span) result(q)
        type(surface_search_t), intent(in) :: search
        integer, intent(in) :: c, span(2)
        real(dp) :: q(3, 3), x(3), d1(3, 2), d2(3, 3), e(3, 3)
        integer :: i, j
        i = mod(c - 1, size(search%span_u)) + 1
        j = (c - 1)/size(search%span_u) + 1
        call surface_derivatives(search%patch, 0.5_dp*[search%breaks_u(i) + search%breaks_u(i + 1), &
                                                       search%breaks_v(j) + search%breaks_v(j + 1)], span, x, d1, d2)
        e(:, 1) = d1(:, 1)
        e(:, 3) = cross(d1(:, 1), d1(:, 2))
        if (norm2(e(:, 1)) == 0.0_dp .or. norm2(e(:, 3)) <= 1.0e-12_dp*norm2(d1(:, 1))*norm2(d1(:, 2))) then
            q = reshape([1.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 1.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 1.0_dp], [3, 3])
            return
        end if
        e(:, 1) = e(:, 1)/norm2(e(:, 1))
        e(:, 3) = e(:, 3)/norm2(e(:, 3))
        e(:, 2) = cross(e(:, 3), e(:, 1))
        q = transpose(e)
    end function cell_frame

    !> Parameters of start sample k (1 .. n_start**2, u fastest) of cell `c`.
    pure function sample_parameters(search, c, k) result(u)
        type(surface_search_t), intent(in) :: search
        integer, intent(in) :: c, k
        real(dp) :: u(2)
        integer :: i, j
        i = mod(c - 1, size(search%span_u)) + 1
        j = (c - 1)/size(search%span_u) + 1
        associate (bu => search%breaks_u, bv => search%breaks_v)
            u(1) = bu(i) + (bu(i + 1) - bu(i))*(real(mod(k - 1, n_start), dp) + 0.5_dp)/n_start
            u(2) = bv(j) + (bv(j + 1) - bv(j))*(real((k - 1)/n_start, dp) + 0.5_dp)/n_start
        end associate
    end function sample_parameters

    !> Point `x` [3], first derivatives `d1` [3, 2] (dS/du, dS/dv) and second
    !> derivatives `d2` [3, 3] (uu, vv, uv) of the surface at `u` [2], with the basis of
    !> the knot spans `span` [2] (a cell's own at its edges: one-sided across C0 knots).
    !> Homogeneous sums then the quotient rule: no allocation, for the search's loops
    !> (so degrees up to `max_fixed_degree`, 20, as the basis's own fixed buffers).
    pure subroutine surface_derivatives(patch, u, span, x, d1, d2)
        type(nurbs_patch_t), intent(in) :: patch
        real(dp), intent(in) :: u(2)
        integer, intent(in) :: span(2)
        real(dp), intent(out) :: x(3), d1(3, 2), d2(3, 3)
        real(dp) :: bu(3, max_fixed_degree + 1), bv(3, max_fixed_degree + 1), h(4, 6), hw(4)
        integer :: p, q, i, j, k
        p = patch%degree(1)
        q = patch%degree(2)
        call basis_ders_at(patch%knots(1)%u, p, span(1), u(1), 2, bu(:, 1:p + 1))
        call basis_ders_at(patch%knots(2)%u, q, span(2), u(2), 2, bv(:, 1:q + 1))
        ! h(:, m): the homogeneous [w x, w] and its derivatives 0, u, v, uu, vv, uv
        h = 0.0_dp
        do j = 1, q + 1
            do i = 1, p + 1
                k = span(1) - p + i - 1 + (span(2) - q + j - 2)*patch%n(1)
                hw(1:3) = patch%cp(:, k)*patch%w(k)
                hw(4) = patch%w(k)
                h(:, 1) = h(:, 1) + bu(1, i)*bv(1, j)*hw
                h(:, 2) = h(:, 2) + bu(2, i)*bv(1, j)*hw
                h(:, 3) = h(:, 3) + bu(1, i)*bv(2, j)*hw
                h(:, 4) = h(:, 4) + bu(3, i)*bv(1, j)*hw
                h(:, 5) = h(:, 5) + bu(1, i)*bv(3, j)*hw
                h(:, 6) = h(:, 6) + bu(2, i)*bv(2, j)*hw
            end do
        end do
        x = h(1:3, 1)/h(4, 1)
        d1(:, 1) = (h(1:3, 2) - h(4, 2)*x)/h(4, 1)
        d1(:, 2) = (h(1:3, 3) - h(4, 3)*x)/h(4, 1)
        d2(:, 1) = (h(1:3, 4) - 2.0_dp*h(4, 2)*d1(:, 1) - h(4, 4)*x)/h(4, 1)
        d2(:, 2) = (h(1:3, 5) - 2.0_dp*h(4, 3)*d1(:, 2) - h(4, 5)*x)/h(4, 1)
        d2(:, 3) = (h(1:3, 6) - h(4, 2)*d1(:, 2) - h(4, 3)*d1(:, 1) - h(4, 6)*x)/h(4, 1)
    end subroutine surface_derivatives

    !> The cell (1 .. size(breaks) - 1) holding parameter `t` (clamped to the range).
    pure integer function locate(breaks, t) result(i)
        real(dp), intent(in) :: breaks(:), t
        integer :: lo, hi, mid
        lo = 1
        hi = size(breaks) - 1
        do while (lo < hi)
            mid = (lo + hi + 1)/2
            if (t >= breaks(mid)) then
                lo = mid
            else
                hi = mid - 1
            end if
        end do
        i = lo
    end function locate

    !> The closest point `res` of the surface to `x` [3] (see the module comment).
    !> `found`: the closest point is an orthogonal projection (false when it lies on the
    !> patch's boundary with the distance still decreasing outward: beyond the patch, as
    !> 2D's beyond the master's ends). `converged`: its cell's Newton iteration settled.
    !> `start` [2], the last projection's parameters, is tried first in its own cell;
    !> its result is kept when that iteration converges there, and then prunes the
    !> other cells like any best point (the search stays exhaustive).
    pure subroutine project_on_surface(search, x, res, found, converged, start)
        type(surface_search_t), intent(in) :: search
        real(dp), intent(in) :: x(3)
        type(surface_projection_t), intent(out) :: res
        logical, intent(out) :: found, converged
        real(dp), intent(in), optional :: start(2)
        type(surface_projection_t) :: cand
        real(dp) :: lb(size(search%boxes, 2)), key(size(search%boxes, 2)), best2, bound, d2, d0
        integer :: list(size(search%boxes, 2)), cells(size(search%boxes, 2))
        logical :: done(size(search%boxes, 2)), ok
        integer :: c, c0, k, nu, nc, kbest, warm, n, j

        nu = size(search%span_u)
        best2 = huge(1.0_dp)
        converged = .false.
        warm = 0
        if (present(start)) then
            c = locate(search%breaks_u, start(1)) + (locate(search%breaks_v, start(2)) - 1)*nu
            call cell_newton(search, x, c, start, cand, ok)
            if (ok) then
                res = cand
                best2 = cand%distance**2
                converged = .true.
                warm = c
            end if
        end if
        ! an upper bound of the distance (squared): the nearest sample of the nearest
        ! box; the candidates are the cells whose boxes, the axis-aligned and then the
        ! cell-oriented one, are closer, visited nearest first
        ! (the nearest box itself always: its sample may be as far as the box, or a
        ! rounding farther in the rotated frame)
        call nearest_box(search%tree, x, c0, d0)
        call nearest_sample(search, x, c0, kbest, d2)
        bound = min(best2, d2)
        call cells_within(search%tree, x, max(bound, nearest(d0, 1.0_dp)), cells, lb, n)
        nc = 0
        do j = 1, n
            c = cells(j)
            if (c == warm) cycle
            if (c /= c0 .and. lb(j) >= bound) cycle
            d2 = max(lb(j), box_distance2(search%oboxes(:, c), matmul(search%frames(:, :, c), x)))
            if (c == c0) d2 = lb(j)
            if (c /= c0 .and. d2 >= bound) cycle
            nc = nc + 1
            list(nc) = c
            key(nc) = d2
        end do
        done(1:nc) = .false.
        do
            k = minloc(key(1:nc), dim=1, mask=.not. done(1:nc))
            if (k == 0) exit
            if (key(k) >= best2) exit
            done(k) = .true.
            c = list(k)
            call nearest_sample(search, x, c, kbest, d2)
            call cell_newton(search, x, c, sample_parameters(search, c, kbest), cand, ok)
            if (cand%distance**2 < best2) then
                res = cand
                best2 = cand%distance**2
                converged = ok
            end if
        end do
        found = .not. beyond(search, x, res)
        ! beyond: the minimum over the patch is on its boundary, where a cell's Newton
        ! may have stopped at a local one along the edge it reached first; the edges'
        ! own minima decide
        if (.not. found) then
            call cells_within(search%tree, x, res%distance**2, cells, lb, n)
            call boundary_search(search, x, cells(1:n), lb(1:n), res)
            found = .not. beyond(search, x, res)
        end if
        res%n = unit_normal(res, [search%breaks_u(1), search%breaks_v(1)], &
                            [search%breaks_u(nu + 1), search%breaks_v(size(search%breaks_v))])
    end subroutine project_on_surface

    !> Whether `res` lies on a bound of the patch with the distance still decreasing
    !> outward by more than round-off (a cosine of 1e-10 between x - S and the tangent).
    pure logical function beyond(search, x, res)
        type(surface_search_t), intent(in) :: search
        real(dp), intent(in) :: x(3)
        type(surface_projection_t), intent(in) :: res
        real(dp) :: g(2), tol(2), lo(2), hi(2)
        integer :: a
        g = [-dot_product(x - res%x, res%a1), -dot_product(x - res%x, res%a2)]
        tol = 1.0e-10_dp*[norm2(res%a1), norm2(res%a2)]*(res%distance + 1.0e-4_dp*search%scale)
        lo = [search%breaks_u(1), search%breaks_v(1)]
        hi = [search%breaks_u(size(search%breaks_u)), search%breaks_v(size(search%breaks_v))]
        beyond = .false.
        do a = 1, 2
            if (res%u(a) <= lo(a) .and. g(a) > tol(a)) beyond = .true.
            if (res%u(a) >= hi(a) .and. g(a) < -tol(a)) beyond = .true.
        end do
    end function beyond

    !> The closest point of the patch's boundary curves to `x`, if closer than `res`:
    !> per boundary cell whose box is closer than `res`, a
    !> Newton iteration along each of its edges on the patch's boundary (the cell's
    !> parameter box with one direction held), from the nearest of `n_edge` samples.
    pure subroutine boundary_search(search, x, cells, lb, res)
        type(surface_search_t), intent(in) :: search
        real(dp), intent(in) :: x(3), lb(:)
        !> The cells whose boxes (squared distances `lb`) are closer than `res`.
        integer, intent(in) :: cells(:)
        type(surface_projection_t), intent(inout) :: res
        integer, parameter :: n_edge = 9
        type(surface_projection_t) :: cand
        real(dp) :: lo(2), hi(2), elo(2), ehi(2), u(2), best_u(2), y(3), d1(3, 2), d2(3, 3), d, dmin
        integer :: nu, c, a, side, k, span(2), idx(2), counts(2), j
        logical :: ok
        nu = size(search%span_u)
        counts = [nu, size(search%span_v)]
        do j = 1, size(cells)
            c = cells(j)
            if (lb(j) >= res%distance**2) cycle
            idx = [mod(c - 1, nu) + 1, (c - 1)/nu + 1]
            span = [search%span_u(idx(1)), search%span_v(idx(2))]
            lo = [search%breaks_u(idx(1)), search%breaks_v(idx(2))]
            hi = [search%breaks_u(idx(1) + 1), search%breaks_v(idx(2) + 1)]
            do a = 1, 2
                do side = 0, 1
                    if (side == 0 .and. idx(a) /= 1) cycle
                    if (side == 1 .and. idx(a) /= counts(a)) cycle
                    elo = lo
                    ehi = hi
                    elo(a) = merge(lo(a), hi(a), side == 0)
                    ehi(a) = elo(a)
                    dmin = huge(1.0_dp)
                    do k = 0, n_edge - 1
                        u = lo + (hi - lo)*real(k, dp)/(n_edge - 1)
                        u(a) = elo(a)
                        call surface_derivatives(search%patch, u, span, y, d1, d2)
                        d = sum((x - y)**2)
                        if (d < dmin) then
                            dmin = d
                            best_u = u
                        end if
                    end do
                    call box_newton(search, x, c, span, elo, ehi, best_u, cand, ok)
                    if (cand%distance < res%distance) res = cand
                end do
            end do
        end do
    end subroutine boundary_search

    !> The start sample `k` of cell `c` nearest to `x`, and its squared distance `d2`.
    pure subroutine nearest_sample(search, x, c, k, d2)
        type(surface_search_t), intent(in) :: search
        real(dp), intent(in) :: x(3)
        integer, intent(in) :: c
        integer, intent(out) :: k
        real(dp), intent(out) :: d2
        real(dp) :: ds
        integer :: j
        d2 = huge(1.0_dp)
        k = 1
        do j = 1, n_start**2
            ds = sum((x - search%samples(:, j, c))**2)
            if (ds < d2) then
                d2 = ds
                k = j
            end if
        end do
    end subroutine nearest_sample

    !> a1 x a2 / |a1 x a2|; where a tangent vanishes (a collapsed edge: a sphere's
    !> pole) the limit from inside: a1 ~ (v - v_e) a12 near an edge v_e, so
    !> a1 x a2 ~ (v - v_e) a12 x a2 (and likewise for a2 = 0 at an edge u_e).
    pure function unit_normal(res, lo, hi) result(n)
        type(surface_projection_t), intent(in) :: res
        real(dp), intent(in) :: lo(2), hi(2)
        real(dp) :: n(3), s
        n = cross(res%a1, res%a2)
        if (norm2(n) > 1.0e-12_dp*norm2(res%a1)*norm2(res%a2) .and. norm2(n) > 0.0_dp) then
            n = n/norm2(n)
            return
        end if
        if (norm2(res%a1) <= norm2(res%a2)) then
            s = merge(-1.0_dp, 1.0_dp, abs(res%u(2) - hi(2)) < abs(res%u(2) - lo(2)))
            n = s*cross(res%a12, res%a2)
        else
            s = merge(-1.0_dp, 1.0_dp, abs(res%u(1) - hi(1)) < abs(res%u(1) - lo(1)))
            n = s*cross(res%a1, res%a12)
        end if
        if (norm2(n) > 0.0_dp) n = n/norm2(n)
    end function unit_normal

    !> The result record of the surface at `u` in cell `c` for the point `x`.
    pure subroutine evaluate(search, x, c, span, u, res)
        type(surface_search_t), intent(in) :: search
        real(dp), intent(in) :: x(3), u(2)
        integer, intent(in) :: c, span(2)
        type(surface_projection_t), intent(inout) :: res
        real(dp) :: d1(3, 2), d2(3, 3)
        call surface_derivatives(search%patch, u, span, res%x, d1, d2)
        res%u = u
        res%a1 = d1(:, 1)
        res%a2 = d1(:, 2)
        res%a11 = d2(:, 1)
        res%a22 = d2(:, 2)
        res%a12 = d2(:, 3)
        res%distance = norm2(x - res%x)
        res%cell = c
    end subroutine evaluate

    !> The closest point to `x` of cell `c` from `u0` (clamped to the cell): projected
    !> Newton with an active set and backtracking (module comment). `res` is evaluated
    !> at the result; `ok` false if `max_newton` iterations did not settle it.
    pure subroutine cell_newton(search, x, c, u0, res, ok)
        type(surface_search_t), intent(in) :: search
        real(dp), intent(in) :: x(3), u0(2)
        integer, intent(in) :: c
        type(surface_projection_t), intent(out) :: res
        logical, intent(out) :: ok
        integer :: i, j
        i = mod(c - 1, size(search%span_u)) + 1
        j = (c - 1)/size(search%span_u) + 1
        call box_newton(search, x, c, [search%span_u(i), search%span_v(j)], &
                        [search%breaks_u(i), search%breaks_v(j)], [search%breaks_u(i + 1), search%breaks_v(j + 1)], &
                        u0, res, ok)
    end subroutine cell_newton

    !> `cell_newton` on the parameter box [lo, hi] (in cell `c`, whose spans are `span`
    !> [2]); lo(a) = hi(a) holds direction a (an edge).
    pure subroutine box_newton(search, x, c, span, lo, hi, u0, res, ok)
        type(surface_search_t), intent(in) :: search
        real(dp), intent(in) :: x(3), lo(2), hi(2), u0(2)
        integer, intent(in) :: c, span(2)
        type(surface_projection_t), intent(out) :: res
        logical, intent(out) :: ok
        type(surface_projection_t) :: trial
        real(dp) :: u(2), s(2), un(2), g(2), f, fn, gs, scale
        logical :: free(2), exact
        integer :: it, m

        u = min(max(u0, lo), hi)
        scale = search%scale
        call evaluate(search, x, c, span, u, res)
        ok = .false.
        do it = 1, max_newton
            call newton_step(res, x, lo, hi, s, g, free, exact, ok)
            if (ok) return
            f = 0.5_dp*res%distance**2
            ! backtracking along the projected path; a short step of the true Newton
            ! (positive definite) is taken whole: there f's decrease is below round-off
            do m = 0, max_halvings
                un = min(max(u + s*0.5_dp**m, lo), hi)
                call evaluate(search, x, c, span, un, trial)
                fn = 0.5_dp*trial%distance**2
                gs = dot_product(g, un - u)
                if (fn <= f + 1.0e-4_dp*gs + 4.0_dp*epsilon(1.0_dp)*f) exit
                if (exact .and. all(abs(un - u) <= 1.0e-6_dp*(hi - lo))) exit
            end do
            ! settled: a step at round-off of the parameters, or a whole step of the true
            ! Newton that moved the point by 1e-12 of the patch (the next would move it
            ! by its square times the convergence constant); the spatial test is what
            ! ends the iteration near a collapsed edge, where u's round-off is large
            ok = all(abs(un - u) <= 1.0e-14_dp*(hi - lo)) .or. &
                 (exact .and. m == 0 .and. norm2(trial%x - res%x) <= 1.0e-12_dp*scale)
            if (fn <= f .or. exact) then
                res = trial
                u = un
            else
                ! no decrease along the path: u is the cell's minimum to round-off
                ok = .true.
            end if
            if (ok) return
        end do
    end subroutine box_newton

    !> The projected Newton step `s` [2] at `res` (the gradient `g` [2] of f), the free
    !> directions (`free`: not held at a bound by a gradient pointing out), whether the
    !> step is the true Hessian's (`exact`) and whether `res` is already stationary
    !> (`done`: the free gradient at round-off, or no free direction).
    pure subroutine newton_step(res, x, lo, hi, s, g, free, exact, done)
        type(surface_projection_t), intent(in) :: res
        real(dp), intent(in) :: x(3), lo(2), hi(2)
        real(dp), intent(out) :: s(2), g(2)
        logical, intent(out) :: free(2), exact, done
        real(dp) :: r(3), h(2, 2), gn(2, 2), det, mu
        integer :: a
        r = x - res%x
        g = [-dot_product(r, res%a1), -dot_product(r, res%a2)]
        gn(1, 1) = dot_product(res%a1, res%a1)
        gn(2, 2) = dot_product(res%a2, res%a2)
        gn(1, 2) = dot_product(res%a1, res%a2)
        gn(2, 1) = gn(1, 2)
        h(1, 1) = gn(1, 1) - dot_product(r, res%a11)
        h(2, 2) = gn(2, 2) - dot_product(r, res%a22)
        h(1, 2) = gn(1, 2) - dot_product(r, res%a12)
        h(2, 1) = h(1, 2)
        do a = 1, 2
            free(a) = .not. ((res%u(a) <= lo(a) .and. g(a) > 0.0_dp) .or. (res%u(a) >= hi(a) .and. g(a) < 0.0_dp))
        end do
        s = 0.0_dp
        exact = .false.
        done = .true.
        do a = 1, 2
            ! round-off of g: a few ulps of |r| |a| and of |S| |a|
            if (free(a)) done = done .and. abs(g(a)) <= 8.0_dp*epsilon(1.0_dp)*(norm2(r) + norm2(res%x))*sqrt(gn(a, a))
        end do
        if (done) return
        if (all(free)) then
            det = h(1, 1)*h(2, 2) - h(1, 2)**2
            exact = h(1, 1) > 0.0_dp .and. det > 1.0e-14_dp*(h(1, 1)*h(2, 2))
            if (.not. exact) then
                mu = 1.0e-10_dp*(gn(1, 1) + gn(2, 2)) + tiny(1.0_dp)
                h = gn
                h(1, 1) = h(1, 1) + mu
                h(2, 2) = h(2, 2) + mu
                det = h(1, 1)*h(2, 2) - h(1, 2)**2
            end if
            s = -[h(2, 2)*g(1) - h(1, 2)*g(2), h(1, 1)*g(2) - h(1, 2)*g(1)]/det
        else
            do a = 1, 2
                if (.not. free(a)) cycle
                exact = h(a, a) > 0.0_dp
                if (exact) then
                    s(a) = -g(a)/h(a, a)
                else
                    s(a) = -g(a)/(gn(a, a)*(1.0_dp + 1.0e-10_dp) + tiny(1.0_dp))
                end if
            end do
        end if
        ! no step longer than the cell: the projection onto it does the rest
        s = sign(min(abs(s), hi - lo), s)
    end subroutine newton_step

end module voiga_nurbs_projection
