!> Nested coarse spaces of a discretized body, for geometric multigrid
!> (`voiga_solver_multigrid`), for a plane patch (pdim 2) or a volume (pdim 3) by
!> the same code (docs/architecture.md, "Dimension as data").
!>
!> A coarse space is a tensor-product NURBS space on the bulk patch's degrees with
!> every other removable knot taken out in each direction: the knots of
!> multiplicity 1 form runs between the knots of higher multiplicity (those of the
!> exact geometry after degree elevation), and in each run the 1st, 3rd, ...
!> are removed. On a uniformly refined patch this halves the elements per
!> direction. The coarse B-splines are combinations of the fine ones (knot
!> insertion, `insertion_matrix`); the coarse weights are the least-squares fit of
!> the fine weight function, exact when the fine weights come from knot insertion
!> (then the coarse NURBS space lies in the fine one).
!>
!> The prolongation maps coarse control-point coefficients to fine ones,
!> `R_coarse(b) = sum_a p(a, b) R_fine(a)`: for NURBS
!> `p(a, b) = t_1(i_1, k_1) ... t_pdim(i_pdim, k_pdim) w_coarse(b) / w_fine(a)` with
!> a = (i_1, ..., i_pdim), b = (k_1, ..., k_pdim). A body with a VO layer has the
!> layer's functions in place of the bulk's last layer of functions across the
!> contact boundary (u_pdim = 1); the bulk functions of that layer are mapped onto
!> the layer functions by their L2 projection along each boundary direction (a
!> tensor product of 1D projections; exact when the bulk's space lies in the
!> layer's, e.g. layer degree = bulk degree; otherwise the first coarse space is not
!> nested, which a Galerkin coarse operator tolerates).
module voiga_discretization_hierarchy
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error
    use voiga_nurbs_basis, only: find_span, basis_funs, distinct_knots, n_basis
    use voiga_nurbs_refine, only: insertion_matrix
    use voiga_nurbs_patch, only: knots_t, next_index
    use voiga_element_quadrature, only: gauss_legendre
    use voiga_linalg_lapack, only: solve_spd
    use voiga_discretization_patch, only: discretization_t
    implicit none
    private

    public :: coarse_space_t, cp_map_t, coarsen_discretization, coarsen_space

    !> A bulk tensor-product NURBS space of parametric dimension `pdim`; control
    !> point (i_1, ..., i_pdim) has the flat id i_1 + (i_2 - 1) n(1) + ...
    !> (direction 1 fastest, as a patch's points).
    type :: coarse_space_t
        integer :: pdim = 2
        !> Degree and control points per direction (1 beyond pdim).
        integer :: degree(3) = 0, n(3) = 1
        !> Knot vectors per direction (allocated up to pdim).
        type(knots_t) :: knots(3)
        !> Weights, flat [product(n)].
        real(dp), allocatable :: w(:)
    end type coarse_space_t

    !> A sparse control-point map (triplets): fine coefficient(fine(k)) +=
    !> val(k) coarse coefficient(coarse(k)).
    type :: cp_map_t
        integer :: n_fine = 0, n_coarse = 0
        integer, allocatable :: fine(:), coarse(:)
        real(dp), allocatable :: val(:)
    end type cp_map_t

    !> A dense matrix (one per direction: 1D insertion and projection matrices).
    type :: dense_t
        real(dp), allocatable :: a(:, :)
        !> First and last row of each column with an entry above drop_tol.
        integer, allocatable :: lo(:), hi(:)
    end type dense_t

    !> Entries of the 1D maps below this magnitude are dropped.
    real(dp), parameter :: drop_tol = 1.0e-14_dp

contains

    !> The first coarse space of a discretization and its prolongation (fine ids:
    !> the discretization's control-point numbering). `changed` is false when no
    !> knot can be removed in any direction (then `space` and `map` are unset).
    subroutine coarsen_discretization(disc, space, map, changed, error)
        type(discretization_t), intent(in) :: disc
        type(coarse_space_t), intent(out) :: space
        type(cp_map_t), intent(out) :: map
        logical, intent(out) :: changed
        type(error_t), allocatable, intent(out) :: error
        type(coarse_space_t) :: fine
        type(dense_t), allocatable :: proj(:)
        integer :: d, nd

        nd = disc%pdim
        fine%pdim = nd
        fine%degree(:nd) = disc%bulk%degree
        fine%n(:nd) = disc%bulk%n
        do d = 1, nd
            fine%knots(d)%u = disc%bulk%knots(d)%u
        end do
        fine%w = disc%bulk%w
        if (disc%has_layer) then
            allocate (proj(nd - 1))
            do d = 1, nd - 1
                call layer_projection(disc, d, proj(d)%a, error)
                if (allocated(error)) return
            end do
            call coarsen(fine, disc%bulk_id, space, map, changed, error, proj, disc%layer_id, disc%layer%w)
        else
            call coarsen(fine, disc%bulk_id, space, map, changed, error)
        end if
        map%n_fine = disc%ncp
    end subroutine coarsen_discretization

    !> The next coarse space of a coarse space, and its prolongation.
    subroutine coarsen_space(fine, space, map, changed, error)
        type(coarse_space_t), intent(in) :: fine
        type(coarse_space_t), intent(out) :: space
        type(cp_map_t), intent(out) :: map
        logical, intent(out) :: changed
        type(error_t), allocatable, intent(out) :: error
        integer :: i

        call coarsen(fine, [(i, i=1, size(fine%w))], space, map, changed, error)
        map%n_fine = size(fine%w)
    end subroutine coarsen_space

    !> Knot vector with every other removable knot taken out (see the module
    !> description); `changed` tells whether any was.
    pure subroutine coarsen_knots(knots, coarse, changed)
        real(dp), intent(in) :: knots(:)
        real(dp), allocatable, intent(out) :: coarse(:)
        logical, intent(out) :: changed
        real(dp), allocatable :: breaks(:)
        logical, allocatable :: drop(:)
        integer :: i, run, k, n

        breaks = distinct_knots(knots)
        n = size(breaks)
        allocate (drop(n))
        drop = .false.
        run = 0
        do i = 2, n - 1
            if (count(knots == breaks(i)) == 1) then
                run = run + 1
                drop(i) = mod(run, 2) == 1
            else
                run = 0
            end if
        end do
        changed = any(drop)
        allocate (coarse(size(knots) - count(drop)))
        k = 0
        do i = 1, size(knots)
            if (any(drop .and. breaks == knots(i))) cycle
            k = k + 1
            coarse(k) = knots(i)
        end do
    end subroutine coarsen_knots

    !> Coarsen a tensor-product space whose control point a (flat) has id ids(a)
    !> (0: replaced by the layer, whose functions along each boundary direction d are
    !> `B_bulk(i) = sum_k proj(d)%a(k, i) B_layer(k)`, ids `layer_ids`, weights
    !> `layer_w`, both flat in the layer's order).
    subroutine coarsen(fine, ids, space, map, changed, error, proj, layer_ids, layer_w)
        type(coarse_space_t), intent(in) :: fine
        integer, intent(in) :: ids(:)
        type(coarse_space_t), intent(out) :: space
        type(cp_map_t), intent(out) :: map
        logical, intent(out) :: changed
        type(error_t), allocatable, intent(out) :: error
        type(dense_t), intent(in), optional :: proj(:)
        integer, intent(in), optional :: layer_ids(:)
        real(dp), intent(in), optional :: layer_w(:)
        type(dense_t) :: t(3), lt(2)
        logical :: cd
        integer :: nd, d, cidx(3), b, n

        nd = fine%pdim
        space%pdim = nd
        changed = .false.
        do d = 1, nd
            call coarsen_knots(fine%knots(d)%u, space%knots(d)%u, cd)
            changed = changed .or. cd
        end do
        if (.not. changed) return
        space%degree = fine%degree
        do d = 1, nd
            t(d)%a = insertion_matrix(fine%degree(d), space%knots(d)%u, fine%knots(d)%u)
            space%n(d) = size(t(d)%a, 2)
            ! the nonzero rows of each column (local supports)
            call column_ranges(t(d)%a, t(d)%lo, t(d)%hi)
        end do
        call fit_weights(t(:nd), fine%w, space%w, error)
        if (allocated(error)) return
        ! (layer function, coarse function) coefficients of the last bulk layer
        if (present(proj)) then
            do d = 1, nd - 1
                lt(d)%a = matmul(proj(d)%a, t(d)%a)
                call column_ranges(lt(d)%a, lt(d)%lo, lt(d)%hi)
            end do
        end if
        allocate (map%fine(16), map%coarse(16), map%val(16))
        n = 0
        cidx = 1
        do b = 1, product(space%n)
            call bulk_column(t, fine, space, ids, b, cidx, map, n)
            if (present(proj)) call layer_column(t, lt, fine, space, layer_ids, layer_w, b, cidx, map, n)
            call next_index(cidx, space%n)
        end do
        map%n_coarse = product(space%n)
        map%fine = map%fine(1:n)
        map%coarse = map%coarse(1:n)
        map%val = map%val(1:n)
    end subroutine coarsen

    !> Push the fine bulk points of coarse point b (indices cidx) onto the first n
    !> entries of `map`: fine index i along direction 1 innermost, the others as a
    !> multi-index, direction 2 fastest; t: the 1D insertion matrices.
    pure subroutine bulk_column(t, fine, space, ids, b, cidx, map, n)
        type(dense_t), intent(in) :: t(:)
        type(coarse_space_t), intent(in) :: fine, space
        integer, intent(in) :: ids(:), b, cidx(3)
        type(cp_map_t), intent(inout) :: map
        integer, intent(inout) :: n
        integer :: jdx(3), lo(3), hi(3), kk(3), cnt(3), i, o, a0, d, nd
        real(dp) :: v
        nd = fine%pdim
        lo = 1
        hi = 1
        do d = 1, nd
            lo(d) = t(d)%lo(cidx(d))
            hi(d) = t(d)%hi(cidx(d))
        end do
        if (any(hi < lo)) return
        cnt = hi - lo + 1
        cnt(1) = 1
        kk = 1
        outer: do o = 1, product(cnt)
            if (o > 1) call next_index(kk, cnt)
            jdx = lo + kk - 1
            do d = 2, nd
                if (abs(t(d)%a(jdx(d), cidx(d))) <= drop_tol) cycle outer
            end do
            a0 = flat([1, jdx(2), jdx(3)], fine%n) - 1
            do i = lo(1), hi(1)
                if (abs(t(1)%a(i, cidx(1))) <= drop_tol) cycle
                if (ids(a0 + i) == 0) cycle
                v = t(1)%a(i, cidx(1))
                do d = 2, nd
                    v = v*t(d)%a(jdx(d), cidx(d))
                end do
                call push(map, n, ids(a0 + i), b, v*space%w(b)/fine%w(a0 + i))
            end do
        end do outer
    end subroutine bulk_column

    !> Push the layer points of coarse point b: through the last bulk layer
    !> (i_pdim = n(pdim)), the tensor product of the projected 1D maps lt.
    pure subroutine layer_column(t, lt, fine, space, layer_ids, layer_w, b, cidx, map, n)
        type(dense_t), intent(in) :: t(:), lt(:)
        type(coarse_space_t), intent(in) :: fine, space
        integer, intent(in) :: layer_ids(:), b, cidx(3)
        real(dp), intent(in) :: layer_w(:)
        type(cp_map_t), intent(inout) :: map
        integer, intent(inout) :: n
        integer :: kdx(3), lo(3), hi(3), nl(3), kk(3), cnt(3), o, d, nd
        real(dp) :: v, across
        nd = fine%pdim
        if (t(nd)%hi(cidx(nd)) /= fine%n(nd)) return
        across = t(nd)%a(fine%n(nd), cidx(nd))
        if (abs(across) <= drop_tol) return
        lo = 1
        hi = 1
        nl = 1
        do d = 1, nd - 1
            lo(d) = lt(d)%lo(cidx(d))
            hi(d) = lt(d)%hi(cidx(d))
            nl(d) = size(lt(d)%a, 1)
        end do
        if (any(hi < lo)) return
        cnt = hi - lo + 1
        kk = 1
        outer: do o = 1, product(cnt)
            if (o > 1) call next_index(kk, cnt)
            kdx = lo + kk - 1
            do d = 1, nd - 1
                if (abs(lt(d)%a(kdx(d), cidx(d))) <= drop_tol) cycle outer
            end do
            v = lt(1)%a(kdx(1), cidx(1))
            do d = 2, nd - 1
                v = v*lt(d)%a(kdx(d), cidx(d))
            end do
            call push(map, n, layer_ids(flat(kdx, nl)), b, v*across*space%w(b)/layer_w(flat(kdx, nl)))
        end do outer
    end subroutine layer_column

    !> Append the triplet (a, b, v) as entry n + 1 of `map` (doubling its arrays
    !> when full).
    pure subroutine push(map, n, a, b, v)
        type(cp_map_t), intent(inout) :: map
        integer, intent(inout) :: n
        integer, intent(in) :: a, b
        real(dp), intent(in) :: v
        if (n == size(map%fine)) then
            call grow_int(map%fine, 2*n)
            call grow_int(map%coarse, 2*n)
            call grow_real(map%val, 2*n)
        end if
        n = n + 1
        map%fine(n) = a
        map%coarse(n) = b
        map%val(n) = v
    end subroutine push

    !> Flat index of idx in a grid of n points per direction (the first fastest).
    pure integer function flat(idx, n)
        integer, intent(in) :: idx(3), n(3)
        flat = idx(1) + (idx(2) - 1)*n(1) + (idx(3) - 1)*n(1)*n(2)
    end function flat

    !> First and last row of each column of `t` with an entry above drop_tol.
    pure subroutine column_ranges(t, lo, hi)
        real(dp), intent(in) :: t(:, :)
        integer, allocatable, intent(out) :: lo(:), hi(:)
        integer :: k, i
        allocate (lo(size(t, 2)), hi(size(t, 2)))
        do k = 1, size(t, 2)
            lo(k) = size(t, 1) + 1
            hi(k) = 0
            do i = 1, size(t, 1)
                if (abs(t(i, k)) > drop_tol) then
                    lo(k) = min(lo(k), i)
                    hi(k) = i
                end if
            end do
        end do
    end subroutine column_ranges

    pure subroutine grow_int(a, cap)
        integer, allocatable, intent(inout) :: a(:)
        integer, intent(in) :: cap
        integer, allocatable :: b(:)
        allocate (b(cap))
        b(1:size(a)) = a
        call move_alloc(b, a)
    end subroutine grow_int

    pure subroutine grow_real(a, cap)
        real(dp), allocatable, intent(inout) :: a(:)
        integer, intent(in) :: cap
        real(dp), allocatable :: b(:)
        allocate (b(cap))
        b(1:size(a)) = a
        call move_alloc(b, a)
    end subroutine grow_real

    !> Least-squares coarse weights: the fine weights wf [product of the fine
    !> counts] = (t_pdim x ... x t_1) wc, one direction after the other (the normal
    !> equations of a tensor product separate; exact when representable).
    subroutine fit_weights(t, wf, wc, error)
        type(dense_t), intent(in) :: t(:)
        real(dp), intent(in) :: wf(:)
        real(dp), allocatable, intent(out) :: wc(:)
        type(error_t), allocatable, intent(out) :: error
        real(dp), allocatable :: g(:, :), b(:, :), x(:, :), grid(:, :, :), out(:, :, :)
        integer :: info, d, nd, cur(3), before, after, ia

        nd = size(t)
        cur = 1
        do d = 1, nd
            cur(d) = size(t(d)%a, 1)
        end do
        g = matmul(transpose(t(1)%a), t(1)%a)
        b = matmul(transpose(t(1)%a), reshape(wf, [cur(1), size(wf)/cur(1)]))
        call solve_spd(g, b, info)
        cur(1) = size(t(1)%a, 2)
        wc = reshape(b, [size(b)])
        do d = 2, nd
            if (info /= 0) exit
            ! the coefficients as [points before d, along d, after d]; each slice's
            ! transpose is a right-hand side block of direction d's normal equations
            before = product(cur(1:d - 1))
            after = product(cur(d + 1:))
            grid = reshape(wc, [before, cur(d), after])
            allocate (x(size(t(d)%a, 2), before*after))
            do ia = 1, after
                x(:, (ia - 1)*before + 1:ia*before) = matmul(transpose(t(d)%a), transpose(grid(:, :, ia)))
            end do
            g = matmul(transpose(t(d)%a), t(d)%a)
            call solve_spd(g, x, info)
            cur(d) = size(t(d)%a, 2)
            allocate (out(before, cur(d), after))
            do ia = 1, after
                out(:, :, ia) = transpose(x(:, (ia - 1)*before + 1:ia*before))
            end do
            wc = reshape(out, [size(out)])
            deallocate (x, out)
        end do
        if (info /= 0) then
            call fatal_error(error, 'multigrid: the knot-insertion matrix of a coarse space is rank deficient')
            return
        end if
        if (any(wc <= 0.0_dp)) call fatal_error(error, &
            'multigrid: a coarse space has a non-positive weight (the fine weights are not smooth enough)')
    end subroutine fit_weights

    !> L2 projection along the boundary direction `dir` of the bulk B-splines onto
    !> the layer's: `B_bulk(i) ~ sum_k proj(k, i) B_layer(k)`, shape [n_layer, n_bulk];
    !> exact (Gauss rule of the layer degree + 1 points per span, both piecewise
    !> polynomials on the same breakpoints).
    subroutine layer_projection(disc, dir, proj, error)
        type(discretization_t), intent(in) :: disc
        integer, intent(in) :: dir
        real(dp), allocatable, intent(out) :: proj(:, :)
        type(error_t), allocatable, intent(out) :: error
        real(dp), allocatable :: breaks(:), gp(:), gw(:), m(:, :), bl(:), bb(:)
        integer :: p, q, nl, nb, e, g, sl, sb, info, i, k
        real(dp) :: u, wt

        associate (kl => disc%layer%knots(dir)%u, kb => disc%bulk%knots(dir)%u)
            p = disc%bulk%degree(dir)
            q = disc%layer%degree(dir)
            nl = n_basis(kl, q)
            nb = n_basis(kb, p)
            allocate (m(nl, nl), proj(nl, nb), gp(q + 1), gw(q + 1))
            m = 0.0_dp
            proj = 0.0_dp
            call gauss_legendre(q + 1, gp, gw)
            ! the layer has the bulk breakpoints along the boundary (docs/theory.md)
            breaks = distinct_knots(kl)
            do e = 1, size(breaks) - 1
                do g = 1, q + 1
                    u = 0.5_dp*(breaks(e) + breaks(e + 1)) + 0.5_dp*(breaks(e + 1) - breaks(e))*gp(g)
                    wt = 0.5_dp*(breaks(e + 1) - breaks(e))*gw(g)
                    sl = find_span(kl, q, u)
                    sb = find_span(kb, p, u)
                    bl = basis_funs(kl, q, sl, u)
                    bb = basis_funs(kb, p, sb, u)
                    do k = 1, q + 1
                        do i = 1, q + 1
                            m(sl - q + i - 1, sl - q + k - 1) = m(sl - q + i - 1, sl - q + k - 1) + wt*bl(i)*bl(k)
                        end do
                        do i = 1, p + 1
                            proj(sl - q + k - 1, sb - p + i - 1) = proj(sl - q + k - 1, sb - p + i - 1) + &
                                                                   wt*bl(k)*bb(i)
                        end do
                    end do
                end do
            end do
        end associate
        call solve_spd(m, proj, info)
        if (info /= 0) call fatal_error(error, 'multigrid: the layer mass matrix is not positive definite')
    end subroutine layer_projection

end module voiga_discretization_hierarchy
