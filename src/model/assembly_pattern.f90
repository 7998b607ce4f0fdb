!> Where the assembly's entries go: each element's global DOFs, the stiffness pattern
!> of the bodies and the contact couplings, and the map of every element's entries in
!> the CSC values (computed once per pattern, carried over when contact rebuilds it).
module voiga_model_assembly_pattern
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error
    use voiga_model, only: model_t
    use voiga_model_body, only: body_t
    use voiga_text, only: str
    use voiga_linalg_sparse, only: csc_matrix_t, new_csc_pattern, pattern_positions, &
                                   consecutive_runs
    implicit none
    private

    public :: body_dofs, stiffness_pattern, rebuild_pattern, assembly_map_t, new_assembly_map
    public :: body_stiffness_t

    !> The stiffness of one linear-elastic body on the tangent's pattern: the values
    !> of its DOFs' columns (a contiguous range of the CSC values; no other body and,
    !> before contact is added, no coupling has entries there).
    type :: body_stiffness_t
        !> Columns of the body's DOFs, 1-based, and their values [colptr(last + 1) - colptr(first)].
        integer :: first = 0, last = -1
        real(dp), allocatable :: values(:)
    end type body_stiffness_t

    !> Where each element's stiffness entries go in the CSC values, computed once per
    !> pattern so that assembly needs no search; and, once assembled, the constant
    !> stiffness of each linear-elastic body, so that it is not integrated again.
    type :: assembly_map_t
        !> Start of each element's entries in `pos`, over all bodies in order [nel_total + 1].
        integer, allocatable :: ptr(:)
        !> Index into the matrix values, for each column of each element's matrix
        !> (local order nsd(a-1) + i), of the first row of each run of its control points
        !> with consecutive numbers (`consecutive_runs`) [nruns, nsd nen per element]: the rows
        !> of a run are consecutive DOFs, so their entries are consecutive in any CSC
        !> pattern that has them.
        integer, allocatable :: pos(:)
        !> Keep the linear-elastic bodies' stiffness (false: integrate every body at
        !> every assembly, as for nonlinear ones).
        logical :: keep_linear = .true.
        !> Per body [nbodies]: its stiffness when it is linear-elastic and was assembled
        !> on this pattern (values allocated), else nothing.
        type(body_stiffness_t), allocatable :: linear(:)
    end type assembly_map_t

contains

    !> Global DOFs of element `e` of `body`, local order nsd(a-1)+i, shape [nsd nen].
    pure function body_dofs(body, e) result(dofs)
        type(body_t), intent(in) :: body
        integer, intent(in) :: e
        integer :: dofs(body%disc%nsd*size(body%disc%elements(e)%conn))
        integer :: a, c, nsd
        nsd = body%disc%nsd
        associate (conn => body%disc%elements(e)%conn)
            do a = 1, size(conn)
                do c = 1, nsd
                    dofs(nsd*(a - 1) + c) = body%dof0 + nsd*(conn(a) - 1) + c
                end do
            end do
        end associate
    end function body_dofs

    !> The positions of every bulk element's entries in `k` (built on its pattern);
    !> an error when there is no memory for them (the largest array of a model).
    subroutine new_assembly_map(model, k, map, error)
        type(model_t), intent(in) :: model
        type(csc_matrix_t), intent(inout) :: k
        type(assembly_map_t), intent(out) :: map
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: dofs(:), runs(:)
        integer :: ib, e, nel, idx, st, nr
        logical :: ok
        nel = sum([(model%bodies(ib)%disc%nel, ib=1, size(model%bodies))])
        allocate (map%ptr(nel + 1))
        map%ptr(1) = 1
        idx = 0
        do ib = 1, size(model%bodies)
            do e = 1, model%bodies(ib)%disc%nel
                idx = idx + 1
                associate (conn => model%bodies(ib)%disc%elements(e)%conn)
                    call reserve(runs, size(conn) + 1)
                    call consecutive_runs(conn, runs, nr)
                    map%ptr(idx + 1) = map%ptr(idx) + model%bodies(ib)%disc%nsd*size(conn)*nr
                end associate
            end do
        end do
        allocate (map%pos(map%ptr(nel + 1) - 1), stat=st)
        if (st /= 0) then
            call fatal_error(error, 'out of memory: the assembly map needs '// &
                             str((map%ptr(nel + 1) - 1)/262144)//' MB')
            return
        end if
        idx = 0
        do ib = 1, size(model%bodies)
            do e = 1, model%bodies(ib)%disc%nel
                idx = idx + 1
                dofs = body_dofs(model%bodies(ib), e)
                call consecutive_runs(model%bodies(ib)%disc%elements(e)%conn, runs, nr)
                call run_positions(k, dofs, runs(1:nr + 1), model%bodies(ib)%disc%nsd, &
                                   map%pos(map%ptr(idx):map%ptr(idx + 1) - 1), ok)
                if (.not. ok) then
                    call fatal_error(error, 'new_assembly_map: the entries of a run of DOFs are not '// &
                                     'consecutive in the stiffness pattern')
                    return
                end if
            end do
        end do
    end subroutine new_assembly_map

    !> `a` with at least n entries.
    pure subroutine reserve(a, n)
        integer, allocatable, intent(inout) :: a(:)
        integer, intent(in) :: n
        if (allocated(a)) then
            if (size(a) >= n) return
            deallocate (a)
        end if
        allocate (a(n))
    end subroutine reserve

    !> The position in `k` of the first row of each run of control points (`runs`
    !> of the element's connectivity, `nsd` DOFs each) in every column of the
    !> element's DOFs `dofs` [m]: starts [number of runs, m]; `ok` is false unless
    !> every run's rows follow their first one in the column (one search per run and
    !> column: nr m of them, not m^2; 3D quadratic elements: 9 x 81 against 81^2).
    pure subroutine run_positions(k, dofs, runs, nsd, starts, ok)
        type(csc_matrix_t), intent(in) :: k
        integer, intent(in) :: dofs(:), runs(:), nsd
        integer, intent(out) :: starts(size(runs) - 1, size(dofs))
        logical, intent(out) :: ok
        integer :: c, t, r0, r, p0
        ok = .true.
        do c = 1, size(dofs)
            do t = 1, size(runs) - 1
                r0 = nsd*(runs(t) - 1) + 1
                p0 = k%index_of(dofs(r0), dofs(c))
                starts(t, c) = p0
                ! rows ascend within a column: row dofs(r) of the run must be at p0 + (r - r0)
                if (p0 == 0 .or. p0 + nsd*(runs(t + 1) - runs(t)) - 1 > k%colptr(dofs(c) + 1)) then
                    ok = .false.
                    cycle
                end if
                do r = r0 + 1, nsd*(runs(t + 1) - 1)
                    ok = ok .and. k%rowind(p0 + r - r0) == dofs(r) - 1
                end do
            end do
        end do
    end subroutine run_positions

    !> The stiffness pattern of all bodies (every element couples its DOFs) and,
    !> unless `contact` is false, of the contact pairs' couplings.
    subroutine stiffness_pattern(model, k, error, contact)
        type(model_t), intent(in) :: model
        type(csc_matrix_t), intent(out) :: k
        type(error_t), allocatable, intent(out) :: error
        logical, intent(in), optional :: contact
        integer, allocatable :: ptr(:), dofs(:), mdofs(:)
        !> The DOFs of one contact block.
        type :: dof_block_t
            integer, allocatable :: dofs(:)
        end type dof_block_t
        type(dof_block_t), allocatable :: blocks(:)
        integer :: ib, e, nel, n, pos, ip, npairs

        nel = 0
        n = 0
        do ib = 1, size(model%bodies)
            nel = nel + model%bodies(ib)%disc%nel
            do e = 1, model%bodies(ib)%disc%nel
                n = n + model%bodies(ib)%disc%nsd*size(model%bodies(ib)%disc%elements(e)%conn)
            end do
        end do
        ! the contact pairs' nonempty blocks (contact_pair_t%block_dofs): with a deformable master
        ! each slave element's edge DOFs with the master's control points in its range
        ! (contact_pair_t%mlo, mhi); a mortar pair, each slave control point's support
        npairs = size(model%pairs)
        if (present(contact)) then
            if (.not. contact) npairs = 0
        end if
        allocate (blocks(sum([(model%pairs(ip)%pair%n_blocks(), ip=1, npairs)])))
        pos = 0
        do ip = 1, npairs
            mdofs = model%pairs(ip)%pair%master%all_dofs()
            do e = 1, model%pairs(ip)%pair%n_blocks()
                pos = pos + 1
                blocks(pos)%dofs = model%pairs(ip)%pair%block_dofs(e, mdofs)
                if (size(blocks(pos)%dofs) == 0) cycle
                nel = nel + 1
                n = n + size(blocks(pos)%dofs)
            end do
        end do
        allocate (ptr(nel + 1), dofs(n))
        ptr(1) = 1
        pos = 0
        do ib = 1, size(model%bodies)
            do e = 1, model%bodies(ib)%disc%nel
                pos = pos + 1
                n = model%bodies(ib)%disc%nsd*size(model%bodies(ib)%disc%elements(e)%conn)
                ptr(pos + 1) = ptr(pos) + n
                dofs(ptr(pos):ptr(pos + 1) - 1) = body_dofs(model%bodies(ib), e)
            end do
        end do
        do e = 1, size(blocks)
            if (size(blocks(e)%dofs) == 0) cycle
            pos = pos + 1
            ptr(pos + 1) = ptr(pos) + size(blocks(e)%dofs)
            dofs(ptr(pos):ptr(pos + 1) - 1) = blocks(e)%dofs
        end do
        call new_csc_pattern(k, model%ndof, ptr, dofs, error)
    end subroutine stiffness_pattern

    !> Rebuild the stiffness pattern `k` (values lost) and, if given, `map`. The
    !> map's positions are translated from the old pattern to the new one (every
    !> bulk entry is in both); `k_bulk` [nnz of the old pattern], if given, is carried
    !> into the new pattern (entries the new one lacks must be zero: bulk values
    !> before any contact part).
    subroutine rebuild_pattern(model, k, error, map, k_bulk)
        type(model_t), intent(in) :: model
        type(csc_matrix_t), intent(inout) :: k
        type(error_t), allocatable, intent(out) :: error
        type(assembly_map_t), intent(inout), optional :: map
        real(dp), allocatable, intent(inout), optional :: k_bulk(:)
        type(csc_matrix_t) :: old
        integer, allocatable :: old2new(:)
        real(dp), allocatable :: moved(:)
        integer :: p
        logical :: keep_linear

        if (.not. present(map)) then
            call stiffness_pattern(model, k, error)
            return
        end if
        old%n = k%n
        call move_alloc(k%colptr, old%colptr)
        call move_alloc(k%rowind, old%rowind)
        call stiffness_pattern(model, k, error)
        if (allocated(error)) return
        call pattern_positions(old, k, old2new)
        ! the bodies' cached stiffness is integrated again on the new pattern
        if (allocated(map%linear)) deallocate (map%linear)
        if (all(old2new(map%pos) > 0)) then
            map%pos = old2new(map%pos)
        else
            keep_linear = map%keep_linear
            call new_assembly_map(model, k, map, error)
            if (allocated(error)) return
            map%keep_linear = keep_linear
        end if
        if (present(k_bulk)) then
            allocate (moved(k%nnz()), source=0.0_dp)
            do p = 1, size(old2new)
                if (old2new(p) > 0) then
                    moved(old2new(p)) = k_bulk(p)
                else if (k_bulk(p) /= 0.0_dp) then
                    call fatal_error(error, 'rebuild_pattern: the new stiffness pattern lacks a '// &
                                     'bulk entry')
                    return
                end if
            end do
            call move_alloc(moved, k_bulk)
        end if
    end subroutine rebuild_pattern

end module voiga_model_assembly_pattern
