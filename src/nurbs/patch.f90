!> Tensor-product NURBS patches of any parametric dimension (1 a curve, 2 a
!> surface, 3 a volume) in any spatial dimension: evaluation, degree elevation and
!> knot insertion along one direction, and the boundary patches (a face of a
!> volume, an edge of a surface).
!>
!> This is the one implementation of the patch operations (docs/architecture.md,
!> "Dimension as data"): the plane body's `nurbs_surface_t` refines and evaluates
!> through it. Control points are stored flat, direction 1 fastest, so a patch has
!> the same shape whatever its dimension: `cp(nsd, n(1) * ... * n(pdim))`.
module voiga_nurbs_patch
    use voiga_kinds, only: dp
    use voiga_nurbs_basis, only: find_span, basis_ders
    use voiga_nurbs_rational, only: rationalize
    use voiga_nurbs_refine, only: insert_knots, elevate_degree
    implicit none
    private

    public :: nurbs_patch_t, knots_t, new_patch, patch_eval, patch_elevate, patch_insert, patch_boundary
    public :: point_index, patch_basis, next_index, jacobian_determinant, cross, patch_orient, oriented_names

    !> One knot vector (a patch has one per parametric direction).
    type :: knots_t
        real(dp), allocatable :: u(:)
    end type knots_t

    !> A NURBS patch.
    type :: nurbs_patch_t
        !> Parametric dimension (1, 2 or 3) and spatial dimension.
        integer :: pdim = 0, nsd = 0
        !> Degree and number of control points per direction [pdim].
        integer, allocatable :: degree(:), n(:)
        !> Knot vectors [pdim], each of length n(d) + degree(d) + 1.
        type(knots_t), allocatable :: knots(:)
        !> Cartesian control points [nsd, product(n)] and weights [product(n)],
        !> direction 1 fastest (`point_index`).
        real(dp), allocatable :: cp(:, :), w(:)
    end type nurbs_patch_t

contains

    !> A patch from its degrees, knot vectors, control-point counts, control points
    !> [nsd, product(n)] and weights.
    pure function new_patch(degree, knots, n, cp, w) result(patch)
        integer, intent(in) :: degree(:), n(:)
        type(knots_t), intent(in) :: knots(:)
        real(dp), intent(in) :: cp(:, :), w(:)
        type(nurbs_patch_t) :: patch
        patch%pdim = size(degree)
        patch%nsd = size(cp, 1)
        patch%degree = degree
        patch%n = n
        patch%knots = knots
        patch%cp = cp
        patch%w = w
    end function new_patch

    !> Flat index of the control point with indices `idx` [pdim] (1-based).
    pure integer function point_index(patch, idx)
        type(nurbs_patch_t), intent(in) :: patch
        integer, intent(in) :: idx(:)
        integer :: d, stride
        point_index = 1
        stride = 1
        do d = 1, patch%pdim
            point_index = point_index + (idx(d) - 1)*stride
            stride = stride*patch%n(d)
        end do
    end function point_index

    !> Point `x` [nsd] and Jacobian `dx` [nsd, pdim] (dx(:, d) = dx/du_d) at the
    !> parameters `u` [pdim].
    pure subroutine patch_eval(patch, u, x, dx)
        type(nurbs_patch_t), intent(in) :: patch
        real(dp), intent(in) :: u(:)
        real(dp), intent(out) :: x(:)
        real(dp), intent(out), optional :: dx(:, :)
        integer, allocatable :: ids(:)
        real(dp), allocatable :: r(:), dr(:, :)
        call patch_basis(patch, u, ids, r, dr)
        x = matmul(patch%cp(:, ids), r)
        if (present(dx)) dx = matmul(patch%cp(:, ids), transpose(dr))
    end subroutine patch_eval

    !> The NURBS functions nonzero at the parameters `u` [pdim]: their flat control
    !> point indices `ids` [nf], values `r` [nf] and first derivatives `dr`
    !> [pdim, nf], nf = product(degree + 1), direction 1 fastest: the tensor-product
    !> loop a solid element of any dimension evaluates at its quadrature points.
    pure subroutine patch_basis(patch, u, ids, r, dr)
        type(nurbs_patch_t), intent(in) :: patch
        real(dp), intent(in) :: u(:)
        integer, allocatable, intent(out) :: ids(:)
        real(dp), allocatable, intent(out) :: r(:), dr(:, :)
        integer :: span(patch%pdim), local(patch%pdim), nf, a, d, e
        real(dp), allocatable :: w(:), b(:), db(:, :), d2b(:, :), d2r(:, :)
        ! B-spline values and first derivatives per direction [2, p + 1, pdim]
        real(dp) :: values(2, maxval(patch%degree) + 1, patch%pdim)

        do d = 1, patch%pdim
            span(d) = find_span(patch%knots(d)%u, patch%degree(d), u(d))
            values(:, 1:patch%degree(d) + 1, d) = basis_ders(patch%knots(d)%u, patch%degree(d), span(d), u(d), 1)
        end do
        nf = product(patch%degree + 1)
        allocate (ids(nf), w(nf), b(nf), db(patch%pdim, nf), d2b(patch%pdim*(patch%pdim + 1)/2, nf), r(nf), &
                  dr(patch%pdim, nf), d2r(patch%pdim*(patch%pdim + 1)/2, nf))
        d2b = 0.0_dp
        local = 1
        do a = 1, nf
            ids(a) = point_index(patch, span - patch%degree + local - 1)
            w(a) = patch%w(ids(a))
            b(a) = 1.0_dp
            db(:, a) = 1.0_dp
            do e = 1, patch%pdim
                b(a) = b(a)*values(1, local(e), e)
                do d = 1, patch%pdim
                    db(d, a) = db(d, a)*values(merge(2, 1, d == e), local(e), e)
                end do
            end do
            call next_index(local, patch%degree + 1)
        end do
        call rationalize(w, b, db, d2b, r, dr, d2r)
    end subroutine patch_basis

    !> The next multi-index after `idx` in [1, counts], the first fastest (the
    !> order of a patch's control points, and of any loop over spans or points).
    pure subroutine next_index(idx, counts)
        integer, intent(inout) :: idx(:)
        integer, intent(in) :: counts(:)
        integer :: d
        do d = 1, size(idx)
            idx(d) = idx(d) + 1
            if (idx(d) <= counts(d)) return
            idx(d) = 1
        end do
    end subroutine next_index

    !> The determinant of a 2 x 2 or 3 x 3 Jacobian (`patch_eval`'s `dx` when pdim = nsd).
    pure real(dp) function jacobian_determinant(a) result(det)
        real(dp), intent(in) :: a(:, :)
        if (size(a, 1) == 2) then
            det = a(1, 1)*a(2, 2) - a(1, 2)*a(2, 1)
        else
            det = a(1, 1)*(a(2, 2)*a(3, 3) - a(2, 3)*a(3, 2)) - a(1, 2)*(a(2, 1)*a(3, 3) - a(2, 3)*a(3, 1)) + &
                  a(1, 3)*(a(2, 1)*a(3, 2) - a(2, 2)*a(3, 1))
        end if
    end function jacobian_determinant

    !> The cross product a x b of two 3-vectors (a face's area vector from its two
    !> tangents, a surface's normal).
    pure function cross(a, b) result(c)
        real(dp), intent(in) :: a(3), b(3)
        real(dp) :: c(3)
        c = [a(2)*b(3) - a(3)*b(2), a(3)*b(1) - a(1)*b(3), a(1)*b(2) - a(2)*b(1)]
    end function cross

    !> Raise the degree along direction `dir` by `t` (each distinct knot gains
    !> multiplicity `t`: the continuity is kept; the geometry is unchanged).
    pure subroutine patch_elevate(patch, dir, t)
        type(nurbs_patch_t), intent(inout) :: patch
        integer, intent(in) :: dir, t
        real(dp) :: none(0)
        if (t > 0) call refine_direction(patch, dir, t, none)
    end subroutine patch_elevate

    !> Insert each of `values` once along direction `dir` (the geometry is unchanged).
    pure subroutine patch_insert(patch, dir, values)
        type(nurbs_patch_t), intent(inout) :: patch
        integer, intent(in) :: dir
        real(dp), intent(in) :: values(:)
        if (size(values) > 0) call refine_direction(patch, dir, 0, values)
    end subroutine patch_insert

    !> Elevate by `t`, then insert `values`, along direction `dir`: every line of
    !> control points along `dir` is one curve of the homogeneous points; the
    !> other directions' points are carried as its extra coordinates.
    pure subroutine refine_direction(patch, dir, t, values)
        type(nurbs_patch_t), intent(inout) :: patch
        integer, intent(in) :: dir, t
        real(dp), intent(in) :: values(:)
        real(dp), allocatable :: lines(:, :), knots(:)
        integer :: p, before, after, nh

        nh = patch%nsd + 1
        before = product(patch%n(1:dir - 1))
        after = product(patch%n(dir + 1:patch%pdim))
        lines = gather_lines(patch, dir, before, after)
        knots = patch%knots(dir)%u
        p = patch%degree(dir)
        if (t > 0) call elevate_degree(p, knots, lines, t)
        if (size(values) > 0) call insert_knots(p, knots, lines, values)
        patch%degree(dir) = p
        patch%knots(dir)%u = knots
        patch%n(dir) = size(lines, 2)
        call scatter_lines(patch, lines, before, after)
    end subroutine refine_direction

    !> The homogeneous control points [w x, w] as lines along `dir`: shape
    !> [(nsd + 1) before after, n(dir)], row (coordinate, point before, point after).
    pure function gather_lines(patch, dir, before, after) result(lines)
        type(nurbs_patch_t), intent(in) :: patch
        integer, intent(in) :: dir, before, after
        real(dp), allocatable :: lines(:, :)
        integer :: nh, ib, ia, k, row, flat
        nh = patch%nsd + 1
        allocate (lines(nh*before*after, patch%n(dir)))
        do ia = 1, after
            do k = 1, patch%n(dir)
                do ib = 1, before
                    flat = ib + (k - 1)*before + (ia - 1)*before*patch%n(dir)
                    row = nh*((ib - 1) + before*(ia - 1))
                    lines(row + 1:row + patch%nsd, k) = patch%cp(:, flat)*patch%w(flat)
                    lines(row + nh, k) = patch%w(flat)
                end do
            end do
        end do
    end function gather_lines

    !> Cartesian points and weights back from `gather_lines`' layout (n(dir) is
    !> the new count).
    pure subroutine scatter_lines(patch, lines, before, after)
        type(nurbs_patch_t), intent(inout) :: patch
        real(dp), intent(in) :: lines(:, :)
        integer, intent(in) :: before, after
        integer :: nh, ib, ia, k, row, flat, nk
        nh = patch%nsd + 1
        nk = size(lines, 2)
        deallocate (patch%cp, patch%w)
        allocate (patch%cp(patch%nsd, before*nk*after), patch%w(before*nk*after))
        do ia = 1, after
            do k = 1, nk
                do ib = 1, before
                    flat = ib + (k - 1)*before + (ia - 1)*before*nk
                    row = nh*((ib - 1) + before*(ia - 1))
                    patch%w(flat) = lines(row + nh, k)
                    patch%cp(:, flat) = lines(row + 1:row + patch%nsd, k)/lines(row + nh, k)
                end do
            end do
        end do
    end subroutine scatter_lines

    !> Re-parametrize `patch` so that its boundary (`dir`, `side`) becomes the end of
    !> the last direction, keeping the orientation (the sign of det J): the other
    !> directions come first, in cyclic order after `dir`, and one parameter is
    !> reversed (u' = a + b - u) where the permutation and the reversal of the last
    !> direction would otherwise turn the patch inside out. New direction d is old
    !> direction `perm(d)`, reversed when `flip(d)`. The geometry is unchanged (the
    !> control points are copied, not computed). For a plane patch these are the
    !> quarter and half turns of the parameter square (a contact edge made eta = 1).
    pure subroutine patch_orient(patch, dir, side, oriented, perm, flip)
        type(nurbs_patch_t), intent(in) :: patch
        integer, intent(in) :: dir, side
        type(nurbs_patch_t), intent(out) :: oriented
        integer, intent(out) :: perm(patch%pdim)
        logical, intent(out) :: flip(patch%pdim)
        integer :: d, nd, old(patch%pdim), new(patch%pdim), k
        logical :: odd

        nd = patch%pdim
        perm = [(mod(dir + d - 1, nd) + 1, d=1, nd)]
        flip = .false.
        flip(nd) = side == 0
        ! a cyclic shift of nd directions is an odd permutation when nd is even
        odd = mod(nd, 2) == 0 .and. perm(1) /= 1
        if (odd .neqv. flip(nd)) flip(1) = .true.
        oriented%pdim = nd
        oriented%nsd = patch%nsd
        oriented%degree = patch%degree(perm)
        oriented%n = patch%n(perm)
        allocate (oriented%knots(nd), oriented%cp(patch%nsd, size(patch%w)), oriented%w(size(patch%w)))
        do d = 1, nd
            associate (u => patch%knots(perm(d))%u)
                if (flip(d)) then
                    oriented%knots(d)%u = u(1) + u(size(u)) - u(size(u):1:-1)
                else
                    oriented%knots(d)%u = u
                end if
            end associate
        end do
        new = 1
        do k = 1, size(patch%w)
            do d = 1, nd
                old(perm(d)) = merge(oriented%n(d) + 1 - new(d), new(d), flip(d))
            end do
            oriented%cp(:, k) = patch%cp(:, point_index(patch, old))
            oriented%w(k) = patch%w(point_index(patch, old))
            call next_index(new, oriented%n)
        end do
    end subroutine patch_orient

    !> The names of the boundaries [2 pdim] (direction by direction, start before
    !> end) of the patch `patch_orient` made with `perm` and `flip`, from `names`.
    pure function oriented_names(names, perm, flip) result(new)
        character(len=*), intent(in) :: names(:)
        integer, intent(in) :: perm(:)
        logical, intent(in) :: flip(:)
        character(len=len(names)) :: new(size(names))
        integer :: d, s
        do d = 1, size(perm)
            do s = 0, 1
                new(2*d - 1 + s) = names(2*perm(d) - 1 + merge(1 - s, s, flip(d)))
            end do
        end do
    end function oriented_names

    !> The boundary patch (parametric dimension pdim - 1) where the parameter of
    !> direction `dir` is at its start (`side` 0) or end (`side` 1); its directions
    !> are the others, in order. A curve (pdim 1) has no boundary patch: `pdim` 0.
    pure function patch_boundary(patch, dir, side) result(face)
        type(nurbs_patch_t), intent(in) :: patch
        integer, intent(in) :: dir, side
        type(nurbs_patch_t) :: face
        integer :: keep(patch%pdim - 1), before, after, ib, ia, k, i
        if (patch%pdim < 2) return
        keep = pack([(i, i=1, patch%pdim)], [(i /= dir, i=1, patch%pdim)])
        face%pdim = patch%pdim - 1
        face%nsd = patch%nsd
        face%degree = patch%degree(keep)
        face%n = patch%n(keep)
        face%knots = patch%knots(keep)
        before = product(patch%n(1:dir - 1))
        after = product(patch%n(dir + 1:patch%pdim))
        k = merge(1, patch%n(dir), side == 0)
        allocate (face%cp(patch%nsd, before*after), face%w(before*after))
        do ia = 1, after
            do ib = 1, before
                i = ib + (k - 1)*before + (ia - 1)*before*patch%n(dir)
                face%cp(:, ib + (ia - 1)*before) = patch%cp(:, i)
                face%w(ib + (ia - 1)*before) = patch%w(i)
            end do
        end do
    end function patch_boundary

end module voiga_nurbs_patch
