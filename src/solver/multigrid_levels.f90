!> The levels of the multigrid hierarchy (`voiga_solver_multigrid`): their
!> operators' storage, prolongations and smoother lines, and how they are built
!> once per run from the bodies' discretizations (`voiga_discretization_hierarchy`):
!> each level halves the elements per direction of every body that still has
!> removable knots, the prolongation is knot insertion (block diagonal over the
!> bodies, the same for every displacement component), until the coarse problem has
!> at most `coarse_dofs` DOFs or no body can be coarsened. Dirichlet DOFs: the fine
!> ones are dropped from the prolongation, and so is every coarse DOF whose function
!> is nonzero on one.
module voiga_solver_multigrid_levels
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_linalg_csr, only: csr_t, csr_from_triplets, csr_transpose
    use voiga_solver_smoother, only: line_set_t, new_line_set
    use voiga_discretization_patch, only: discretization_t
    use voiga_discretization_hierarchy, only: coarse_space_t, cp_map_t, coarsen_discretization, &
                                              coarsen_space
    implicit none
    private

    public :: mg_level_t, build_levels

    !> One level: its operator and the transfer from the next coarser level.
    type :: mg_level_t
        integer :: n = 0
        type(csr_t) :: a
        !> Prolongation from level + 1 [n, n_coarser] and its transpose (not on the coarsest).
        type(csr_t) :: p, r
        !> a p (kept for its pattern: later set-ups only recompute values).
        type(csr_t) :: ap
        !> Position of each row's diagonal in a%val.
        integer, allocatable :: diag(:)
        !> Smoother lines: rows of control points along xi (1), eta (2) and zeta (3;
        !> empty for plane bodies).
        type(line_set_t) :: lines(3)
        !> DOFs outside the multigrid space (Dirichlet and what they constrain).
        logical, allocatable :: fixed(:)
        !> Work vectors: right-hand side, solution, residual [n]; line solves.
        real(dp), allocatable :: b(:), x(:), res(:), work(:)
    end type mg_level_t

    !> Control points of a body at one level, as the smoother's lines see them: the
    !> ids of its tensor grid (flat, direction 1 fastest; 0: none) and those of the
    !> VO layer's grid (over the first pdim - 1 directions; empty: none).
    type :: body_grid_t
        integer :: pdim = 2, nsd = 2
        !> Points per direction of the grid and of the layer (1 beyond their dimension).
        integer :: n(3) = 1, layer_n(3) = 1
        integer, allocatable :: ids(:), layer(:)
    end type body_grid_t

contains

    !> Build the hierarchy for bodies `discs` whose DOFs start at `dof0` (nsd per
    !> control point: nsd(a-1)+c), `ndof` in all, with the Dirichlet DOFs `fixed`.
    subroutine build_levels(coarse_dofs, discs, dof0, ndof, fixed, built, error)
        !> Largest coarse problem (DOFs) to stop at.
        integer, intent(in) :: coarse_dofs
        type(discretization_t), intent(in) :: discs(:)
        integer, intent(in) :: dof0(:), ndof
        logical, intent(in) :: fixed(:)
        !> The levels, finest first.
        type(mg_level_t), allocatable, intent(out) :: built(:)
        type(error_t), allocatable, intent(out) :: error
        type(mg_level_t), allocatable :: levels(:)
        type(coarse_space_t), allocatable :: spaces(:), next(:)
        type(cp_map_t), allocatable :: maps(:)
        integer, allocatable :: off_f(:), off_c(:), ncp(:), nsd(:)
        ! body is still at its discretization (no coarse space yet)
        logical, allocatable :: at_disc(:), changed(:)
        type(body_grid_t), allocatable :: grids(:)
        integer :: nb, ib, lev, nc, i, d

        nb = size(discs)
        allocate (spaces(nb), next(nb), maps(nb), off_f(nb), off_c(nb), ncp(nb), at_disc(nb), changed(nb))
        nsd = discs(:)%nsd
        allocate (grids(nb))
        at_disc = .true.
        off_f = dof0
        do ib = 1, nb
            ncp(ib) = discs(ib)%ncp
            grids(ib)%pdim = discs(ib)%pdim
            grids(ib)%nsd = discs(ib)%nsd
            grids(ib)%n(:discs(ib)%pdim) = discs(ib)%bulk%n
            grids(ib)%ids = discs(ib)%bulk_id
            grids(ib)%layer = discs(ib)%layer_id
            if (discs(ib)%has_layer) grids(ib)%layer_n(:discs(ib)%pdim - 1) = discs(ib)%layer%n
        end do
        allocate (levels(1))
        levels(1)%n = ndof
        levels(1)%fixed = fixed
        lev = 1
        do while (levels(lev)%n > coarse_dofs)
            do ib = 1, nb
                if (at_disc(ib)) then
                    call coarsen_discretization(discs(ib), next(ib), maps(ib), changed(ib), error)
                else
                    call coarsen_space(spaces(ib), next(ib), maps(ib), changed(ib), error)
                end if
                ! a coarse space that cannot be built (rank-deficient insertion, weights
                ! that do not fit) ends this body's coarsening, not the run
                if (allocated(error)) then
                    deallocate (error)
                    changed(ib) = .false.
                end if
                if (.not. changed(ib)) call identity_map(ncp(ib), maps(ib))
            end do
            if (.not. any(changed)) exit
            nc = 0
            do ib = 1, nb
                off_c(ib) = nc
                nc = nc + grids(ib)%nsd*maps(ib)%n_coarse
            end do
            call make_lines(levels(lev), grids, off_f)
            call append_level(levels, lev, maps, nsd, off_f, off_c, nc)
            do ib = 1, nb
                if (changed(ib)) then
                    ! the coarse control points form a plain tensor grid
                    grids(ib)%n = next(ib)%n
                    grids(ib)%ids = [(i, i=1, size(next(ib)%w))]
                    grids(ib)%layer = [integer ::]
                    grids(ib)%layer_n = 1
                    spaces(ib)%pdim = next(ib)%pdim
                    spaces(ib)%degree = next(ib)%degree
                    spaces(ib)%n = next(ib)%n
                    do d = 1, next(ib)%pdim
                        call move_alloc(next(ib)%knots(d)%u, spaces(ib)%knots(d)%u)
                    end do
                    call move_alloc(next(ib)%w, spaces(ib)%w)
                    at_disc(ib) = .false.
                end if
                ncp(ib) = maps(ib)%n_coarse
            end do
            off_f = off_c
            lev = lev + 1
        end do
        call move_alloc(levels, built)
        do lev = 1, size(built)
            associate (l => built(lev))
                allocate (l%b(l%n), l%x(l%n), l%res(l%n))
                allocate (l%work(max(1, l%lines(1)%longest(), l%lines(2)%longest(), l%lines(3)%longest())))
            end associate
        end do
    end subroutine build_levels

    !> The smoother's lines along each direction of a level whose bodies' DOFs start
    !> at `off` (fixed DOFs are in no line): for each body the grid's lines, then the
    !> layer's along the directions it has.
    subroutine make_lines(level, grids, off)
        type(mg_level_t), intent(inout) :: level
        type(body_grid_t), intent(in) :: grids(:)
        integer, intent(in) :: off(:)
        integer, allocatable :: ptr(:), dofs(:)
        integer :: dir, ib, nl, nd

        do dir = 1, 3
            allocate (ptr(level%n + 1), dofs(level%n))
            ptr(1) = 1
            nl = 0
            nd = 0
            do ib = 1, size(grids)
                associate (g => grids(ib))
                    if (dir <= g%pdim) call add_grid(g%ids, g%n, dir, off(ib), g%nsd)
                    if (dir < g%pdim .and. size(g%layer) > 0) call add_grid(g%layer, g%layer_n, dir, off(ib), g%nsd)
                end associate
            end do
            call new_line_set(level%lines(dir), level%n, ptr(1:nl + 1), dofs(1:nd))
            deallocate (ptr, dofs)
        end do
    contains
        !> The lines along `dir` of a grid of ids [product(n)], in the order of the
        !> other directions' multi-index (the lower fastest).
        subroutine add_grid(ids, n, dir, offset, nsd)
            integer, intent(in) :: ids(:), n(3), dir, offset, nsd
            integer :: stride, o, a0, k
            integer, allocatable :: line(:)
            stride = product(n(1:dir - 1))
            allocate (line(n(dir)))
            do o = 0, size(ids)/n(dir) - 1
                ! o = (index below dir) + stride (index above dir), 0-based
                a0 = mod(o, stride) + (o/stride)*stride*n(dir)
                do k = 1, n(dir)
                    line(k) = ids(a0 + (k - 1)*stride + 1)
                end do
                call add_line(line, offset, nsd)
            end do
        end subroutine add_grid

        subroutine add_line(cps, offset, nsd)
            integer, intent(in) :: cps(:), offset, nsd
            integer :: k, c, d, n0
            n0 = nd
            do k = 1, size(cps)
                if (cps(k) == 0) cycle
                do c = 1, nsd
                    d = offset + nsd*(cps(k) - 1) + c
                    if (level%fixed(d)) cycle
                    nd = nd + 1
                    dofs(nd) = d
                end do
            end do
            if (nd > n0) then
                nl = nl + 1
                ptr(nl + 1) = nd + 1
            end if
        end subroutine add_line
    end subroutine make_lines

    !> The map of a body that is not coarsened further.
    pure subroutine identity_map(n, map)
        integer, intent(in) :: n
        type(cp_map_t), intent(out) :: map
        integer :: i
        map%n_fine = n
        map%n_coarse = n
        map%fine = [(i, i=1, n)]
        map%coarse = map%fine
        map%val = [(1.0_dp, i=1, n)]
    end subroutine identity_map

    !> Add level lev + 1 with nc DOFs: the DOF prolongation from the bodies'
    !> control-point maps, without the fixed fine rows and the coarse columns
    !> that touch them.
    subroutine append_level(levels, lev, maps, nsd, off_f, off_c, nc)
        type(mg_level_t), allocatable, intent(inout) :: levels(:)
        integer, intent(in) :: lev
        type(cp_map_t), intent(in) :: maps(:)
        !> DOFs per control point of each body.
        integer, intent(in) :: nsd(:)
        integer, intent(in) :: off_f(:), off_c(:), nc
        type(mg_level_t), allocatable :: grown(:)
        integer, allocatable :: rows(:), cols(:)
        real(dp), allocatable :: vals(:)
        logical, allocatable :: cfixed(:), keep(:)
        integer :: ib, k, c, n, i, j

        n = sum([(nsd(ib)*size(maps(ib)%val), ib=1, size(maps))])
        allocate (rows(n), cols(n), vals(n), cfixed(nc))
        cfixed = .false.
        n = 0
        do ib = 1, size(maps)
            do k = 1, size(maps(ib)%val)
                do c = 1, nsd(ib)
                    n = n + 1
                    rows(n) = off_f(ib) + nsd(ib)*(maps(ib)%fine(k) - 1) + c
                    cols(n) = off_c(ib) + nsd(ib)*(maps(ib)%coarse(k) - 1) + c
                    vals(n) = maps(ib)%val(k)
                end do
            end do
        end do
        associate (f => levels(lev)%fixed)
            do k = 1, n
                if (f(rows(k))) cfixed(cols(k)) = .true.
            end do
            allocate (keep(n))
            do k = 1, n
                i = rows(k)
                j = cols(k)
                keep(k) = .not. (f(i) .or. cfixed(j))
            end do
        end associate
        allocate (grown(lev + 1))
        grown(1:lev) = levels(1:lev)
        call csr_from_triplets(levels(lev)%n, nc, pack(rows, keep), pack(cols, keep), pack(vals, keep), &
                               grown(lev)%p)
        call csr_transpose(grown(lev)%p, grown(lev)%r)
        grown(lev + 1)%n = nc
        grown(lev + 1)%fixed = cfixed
        call move_alloc(grown, levels)
    end subroutine append_level

end module voiga_solver_multigrid_levels
