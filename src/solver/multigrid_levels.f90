!> The levels of the multigrid hierarchy (`voiga_solver_multigrid`): their
!> operators' storage, prolongations and smoother lines, and how they are built
!> once per run from the bodies' discretizations (`voiga_discretization_hierarchy`):
!> each level halves the elements per direction of every body that still has
!> removable knots, the prolongation is knot insertion (block diagonal over the
!> bodies, the same for both displacement components), until the coarse problem has
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
        !> Smoother lines: rows of control points along xi (1) and along eta (2).
        type(line_set_t) :: lines(2)
        !> DOFs outside the multigrid space (Dirichlet and what they constrain).
        logical, allocatable :: fixed(:)
        !> Work vectors: right-hand side, solution, residual [n]; line solves.
        real(dp), allocatable :: b(:), x(:), res(:), work(:)
    end type mg_level_t

    !> Control points of a body at one level, as the smoother's lines see them:
    !> ids(i, j) of the tensor grid (0: none) and an extra xi line (the VO layer).
    type :: body_grid_t
        integer, allocatable :: ids(:, :), extra(:)
    end type body_grid_t

contains

    !> Build the hierarchy for bodies `discs` whose DOFs start at `dof0` (2 per
    !> control point: 2(a-1)+c), `ndof` in all, with the Dirichlet DOFs `fixed`.
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
        integer, allocatable :: off_f(:), off_c(:), ncp(:)
        ! body is still at its discretization (no coarse space yet)
        logical, allocatable :: at_disc(:), changed(:)
        type(body_grid_t), allocatable :: grids(:)
        integer :: nb, ib, lev, nc, i, j

        nb = size(discs)
        allocate (spaces(nb), next(nb), maps(nb), off_f(nb), off_c(nb), ncp(nb), at_disc(nb), changed(nb))
        allocate (grids(nb))
        at_disc = .true.
        off_f = dof0
        do ib = 1, nb
            ncp(ib) = discs(ib)%ncp
            grids(ib)%ids = reshape(discs(ib)%bulk_id, discs(ib)%bulk%n(1:2))
            grids(ib)%extra = discs(ib)%layer_id
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
                nc = nc + 2*maps(ib)%n_coarse
            end do
            call make_lines(levels(lev), grids, off_f)
            call append_level(levels, lev, maps, off_f, off_c, nc)
            do ib = 1, nb
                if (changed(ib)) then
                    ! the coarse control points form a plain tensor grid
                    deallocate (grids(ib)%ids)
                    allocate (grids(ib)%ids(size(next(ib)%w, 1), size(next(ib)%w, 2)))
                    do j = 1, size(grids(ib)%ids, 2)
                        do i = 1, size(grids(ib)%ids, 1)
                            grids(ib)%ids(i, j) = i + (j - 1)*size(grids(ib)%ids, 1)
                        end do
                    end do
                    grids(ib)%extra = [integer ::]
                    call move_alloc(next(ib)%knots_xi, spaces(ib)%knots_xi)
                    call move_alloc(next(ib)%knots_eta, spaces(ib)%knots_eta)
                    call move_alloc(next(ib)%w, spaces(ib)%w)
                    spaces(ib)%degree = next(ib)%degree
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
                allocate (l%work(max(1, l%lines(1)%longest(), l%lines(2)%longest())))
            end associate
        end do
    end subroutine build_levels

    !> The smoother's xi and eta lines of a level whose bodies' DOFs start at
    !> `off` (fixed DOFs are in no line).
    subroutine make_lines(level, grids, off)
        type(mg_level_t), intent(inout) :: level
        type(body_grid_t), intent(in) :: grids(:)
        integer, intent(in) :: off(:)
        integer, allocatable :: ptr(:), dofs(:)
        integer :: dir, ib, i, j, nl, nd

        do dir = 1, 2
            allocate (ptr(1), dofs(level%n))
            ptr(1) = 1
            nl = 0
            nd = 0
            do ib = 1, size(grids)
                associate (ids => grids(ib)%ids)
                    if (dir == 1) then
                        do j = 1, size(ids, 2)
                            call add_line(ids(:, j), off(ib))
                        end do
                        if (size(grids(ib)%extra) > 0) call add_line(grids(ib)%extra, off(ib))
                    else
                        do i = 1, size(ids, 1)
                            call add_line(ids(i, :), off(ib))
                        end do
                    end if
                end associate
            end do
            call new_line_set(level%lines(dir), level%n, ptr, dofs(1:nd))
            deallocate (ptr, dofs)
        end do
    contains
        subroutine add_line(cps, offset)
            integer, intent(in) :: cps(:), offset
            integer :: k, c, d, n0
            n0 = nd
            do k = 1, size(cps)
                if (cps(k) == 0) cycle
                do c = 1, 2
                    d = offset + 2*(cps(k) - 1) + c
                    if (level%fixed(d)) cycle
                    nd = nd + 1
                    dofs(nd) = d
                end do
            end do
            if (nd > n0) then
                nl = nl + 1
                ptr = [ptr, nd + 1]
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
    subroutine append_level(levels, lev, maps, off_f, off_c, nc)
        type(mg_level_t), allocatable, intent(inout) :: levels(:)
        integer, intent(in) :: lev
        type(cp_map_t), intent(in) :: maps(:)
        integer, intent(in) :: off_f(:), off_c(:), nc
        type(mg_level_t), allocatable :: grown(:)
        integer, allocatable :: rows(:), cols(:)
        real(dp), allocatable :: vals(:)
        logical, allocatable :: cfixed(:), keep(:)
        integer :: ib, k, c, n, i, j

        n = 2*sum([(size(maps(ib)%val), ib=1, size(maps))])
        allocate (rows(n), cols(n), vals(n), cfixed(nc))
        cfixed = .false.
        n = 0
        do ib = 1, size(maps)
            do k = 1, size(maps(ib)%val)
                do c = 1, 2
                    n = n + 1
                    rows(n) = off_f(ib) + 2*(maps(ib)%fine(k) - 1) + c
                    cols(n) = off_c(ib) + 2*(maps(ib)%coarse(k) - 1) + c
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
