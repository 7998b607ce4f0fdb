!> Nested coarse spaces of a discretized body, for geometric multigrid
!> (`voiga_solver_multigrid`).
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
!> `p(a, b) = t_xi(i, k) t_eta(j, l) w_coarse(b) / w_fine(a)` with a = (i, j),
!> b = (k, l). A body with a VO layer has the layer's functions in place of the
!> bulk's last eta row; the bulk functions of that row are mapped onto the layer
!> functions by their L2 projection along xi (exact when the bulk xi space lies in
!> the layer's, e.g. layer degree = bulk degree; otherwise the first coarse space
!> is not nested, which a Galerkin coarse operator tolerates).
module voiga_discretization_hierarchy
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error
    use voiga_nurbs_basis, only: find_span, basis_funs, distinct_knots, n_basis
    use voiga_nurbs_refine, only: insertion_matrix
    use voiga_element_quadrature, only: gauss_legendre
    use voiga_linalg_lapack, only: solve_spd
    use voiga_discretization_patch, only: discretization_t
    implicit none
    private

    public :: coarse_space_t, cp_map_t, coarsen_discretization, coarsen_space

    !> A bulk tensor-product NURBS space; control point (i, j) has id i + (j-1) nx.
    type :: coarse_space_t
        integer :: degree(2) = 0
        real(dp), allocatable :: knots_xi(:), knots_eta(:)
        !> Weights, shape [nx, ne].
        real(dp), allocatable :: w(:, :)
    end type coarse_space_t

    !> A sparse control-point map (triplets): fine coefficient(fine(k)) +=
    !> val(k) coarse coefficient(coarse(k)).
    type :: cp_map_t
        integer :: n_fine = 0, n_coarse = 0
        integer, allocatable :: fine(:), coarse(:)
        real(dp), allocatable :: val(:)
    end type cp_map_t

    !> Entries of the 1D maps below this magnitude are dropped.
    real(dp), parameter :: drop_tol = 1.0e-14_dp

contains

    !> The first coarse space of a discretization and its prolongation (fine ids:
    !> the discretization's control-point numbering). `changed` is false when no
    !> knot can be removed in either direction (then `space` and `map` are unset).
    subroutine coarsen_discretization(disc, space, map, changed, error)
        type(discretization_t), intent(in) :: disc
        type(coarse_space_t), intent(out) :: space
        type(cp_map_t), intent(out) :: map
        logical, intent(out) :: changed
        type(error_t), allocatable, intent(out) :: error
        type(coarse_space_t) :: fine
        real(dp), allocatable :: proj(:, :)

        fine%degree = disc%bulk%degree
        fine%knots_xi = disc%bulk%knots(1)%u
        fine%knots_eta = disc%bulk%knots(2)%u
        fine%w = reshape(disc%bulk%w, [disc%bulk%n(1), disc%bulk%n(2)])
        if (disc%has_layer) then
            call layer_projection(disc, proj, error)
            if (allocated(error)) return
            call coarsen(fine, reshape(disc%bulk_id, disc%bulk%n(1:2)), space, map, changed, error, proj, &
                         disc%layer_id, disc%layer%w)
        else
            call coarsen(fine, reshape(disc%bulk_id, disc%bulk%n(1:2)), space, map, changed, error)
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
        integer, allocatable :: ids(:, :)
        integer :: i, j, nx, ne

        nx = size(fine%w, 1)
        ne = size(fine%w, 2)
        allocate (ids(nx, ne))
        do j = 1, ne
            do i = 1, nx
                ids(i, j) = i + (j - 1)*nx
            end do
        end do
        call coarsen(fine, ids, space, map, changed, error)
        map%n_fine = nx*ne
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

    !> Coarsen a tensor-product space whose control point (i, j) has id ids(i, j)
    !> (0: replaced by the layer, whose functions along xi are
    !> `B_bulk(i) = sum_k proj(k, i) B_layer(k)`, ids `layer_ids`, weights `layer_w`).
    subroutine coarsen(fine, ids, space, map, changed, error, proj, layer_ids, layer_w)
        type(coarse_space_t), intent(in) :: fine
        integer, intent(in) :: ids(:, :)
        type(coarse_space_t), intent(out) :: space
        type(cp_map_t), intent(out) :: map
        logical, intent(out) :: changed
        type(error_t), allocatable, intent(out) :: error
        real(dp), intent(in), optional :: proj(:, :)
        integer, intent(in), optional :: layer_ids(:)
        real(dp), intent(in), optional :: layer_w(:)
        real(dp), allocatable :: tx(:, :), te(:, :), lt(:, :)
        integer, allocatable :: xlo(:), xhi(:), elo(:), ehi(:)
        logical :: cx, ce
        integer :: nxf, nef, nxc, nec, i, j, k, l, n, kk, cap

        call coarsen_knots(fine%knots_xi, space%knots_xi, cx)
        call coarsen_knots(fine%knots_eta, space%knots_eta, ce)
        changed = cx .or. ce
        if (.not. changed) return
        space%degree = fine%degree
        tx = insertion_matrix(fine%degree(1), space%knots_xi, fine%knots_xi)
        te = insertion_matrix(fine%degree(2), space%knots_eta, fine%knots_eta)
        nxf = size(tx, 1)
        nxc = size(tx, 2)
        nef = size(te, 1)
        nec = size(te, 2)
        call fit_weights(tx, te, fine%w, space%w, error)
        if (allocated(error)) return
        ! (layer function, coarse xi function) coefficients of the last bulk row
        if (present(proj)) lt = matmul(proj, tx)
        cap = 16
        allocate (map%fine(cap), map%coarse(cap), map%val(cap))
        n = 0
        ! the nonzero rows of each column of tx and te (local supports)
        call column_ranges(tx, xlo, xhi)
        call column_ranges(te, elo, ehi)
        do l = 1, nec
            do k = 1, nxc
                do j = elo(l), ehi(l)
                    if (abs(te(j, l)) <= drop_tol) cycle
                    do i = xlo(k), xhi(k)
                        if (abs(tx(i, k)) <= drop_tol) cycle
                        if (ids(i, j) == 0) cycle
                        call push(ids(i, j), k + (l - 1)*nxc, &
                                  tx(i, k)*te(j, l)*space%w(k, l)/fine%w(i, j))
                    end do
                    if (present(proj) .and. j == nef) then
                        do kk = 1, size(layer_ids)
                            if (abs(lt(kk, k)) <= drop_tol) cycle
                            call push(layer_ids(kk), k + (l - 1)*nxc, &
                                      lt(kk, k)*te(j, l)*space%w(k, l)/layer_w(kk))
                        end do
                    end if
                end do
            end do
        end do
        map%n_coarse = nxc*nec
        map%fine = map%fine(1:n)
        map%coarse = map%coarse(1:n)
        map%val = map%val(1:n)
    contains
        subroutine push(a, b, v)
            integer, intent(in) :: a, b
            real(dp), intent(in) :: v
            if (n == cap) then
                cap = 2*cap
                call grow_int(map%fine, cap)
                call grow_int(map%coarse, cap)
                call grow_real(map%val, cap)
            end if
            n = n + 1
            map%fine(n) = a
            map%coarse(n) = b
            map%val(n) = v
        end subroutine push
    end subroutine coarsen

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

    !> Least-squares coarse weights: tx wc te^T = wf (exact when representable).
    subroutine fit_weights(tx, te, wf, wc, error)
        real(dp), intent(in) :: tx(:, :), te(:, :), wf(:, :)
        real(dp), allocatable, intent(out) :: wc(:, :)
        type(error_t), allocatable, intent(out) :: error
        real(dp), allocatable :: gx(:, :), ge(:, :), b(:, :)
        integer :: info

        gx = matmul(transpose(tx), tx)
        b = matmul(transpose(tx), wf)
        call solve_spd(gx, b, info)
        if (info == 0) then
            ! b = wc te^T, so te^T te wc^T = te^T b^T
            ge = matmul(transpose(te), te)
            wc = matmul(transpose(te), transpose(b))
            call solve_spd(ge, wc, info)
        end if
        if (info /= 0) then
            call fatal_error(error, 'multigrid: the knot-insertion matrix of a coarse space is rank deficient')
            return
        end if
        wc = transpose(wc)
        if (any(wc <= 0.0_dp)) call fatal_error(error, &
            'multigrid: a coarse space has a non-positive weight (the fine weights are not smooth enough)')
    end subroutine fit_weights

    !> L2 projection along xi of the bulk B-splines onto the layer's:
    !> `B_bulk(i) ~ sum_k proj(k, i) B_layer(k)`, shape [n_layer, n_xi]; exact
    !> (Gauss rule of the layer degree + 1 points per span, both piecewise
    !> polynomials on the same breakpoints).
    subroutine layer_projection(disc, proj, error)
        type(discretization_t), intent(in) :: disc
        real(dp), allocatable, intent(out) :: proj(:, :)
        type(error_t), allocatable, intent(out) :: error
        real(dp), allocatable :: breaks(:), gp(:), gw(:), m(:, :), bl(:), bb(:)
        integer :: p, q, nl, nb, e, g, sl, sb, info, i, k
        real(dp) :: u, wt

        p = disc%bulk%degree(1)
        q = disc%layer%degree(1)
        nl = n_basis(disc%layer%knots(1)%u, q)
        nb = n_basis(disc%bulk%knots(1)%u, p)
        allocate (m(nl, nl), proj(nl, nb), gp(q + 1), gw(q + 1))
        m = 0.0_dp
        proj = 0.0_dp
        call gauss_legendre(q + 1, gp, gw)
        ! the layer has the bulk breakpoints along xi (docs/theory.md)
        breaks = distinct_knots(disc%layer%knots(1)%u)
        do e = 1, size(breaks) - 1
            do g = 1, q + 1
                u = 0.5_dp*(breaks(e) + breaks(e + 1)) + 0.5_dp*(breaks(e + 1) - breaks(e))*gp(g)
                wt = 0.5_dp*(breaks(e + 1) - breaks(e))*gw(g)
                sl = find_span(disc%layer%knots(1)%u, q, u)
                sb = find_span(disc%bulk%knots(1)%u, p, u)
                bl = basis_funs(disc%layer%knots(1)%u, q, sl, u)
                bb = basis_funs(disc%bulk%knots(1)%u, p, sb, u)
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
        call solve_spd(m, proj, info)
        if (info /= 0) call fatal_error(error, 'multigrid: the layer mass matrix is not positive definite')
    end subroutine layer_projection

end module voiga_discretization_hierarchy
