!> Assembly of the internal force, the tangent stiffness and the external
!> (pressure) forces of all bodies.
module voiga_model_assembly
    use voiga_kinds, only: dp, i8
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_model, only: model_t, set_contact_time
    use voiga_model_body, only: body_t
    use voiga_model_loads, only: phase_value
    use voiga_text, only: str
    use voiga_discretization_element, only: element_basis, element_nfun
    use voiga_element_quadrature, only: gauss_legendre
    use voiga_element_solid, only: solid_element, solid_element_blocks, solid_element_force, element_work_t
    use voiga_solver_sparse, only: csc_matrix_t, new_csc_pattern, pattern_positions, position_cache_t, &
                                   consecutive_runs
    implicit none
    private

    public :: assembly_stats_t, body_element, assemble, assemble_residual, external_forces, stiffness_pattern, body_dofs
    public :: assembly_map_t, new_assembly_map, bulk_stiffness

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
        !> (local order 2(a-1) + i), of the first row of each run of its control points
        !> with consecutive numbers (`consecutive_runs`) [nruns, 2 nen per element]: the rows
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

    !> What the assembly did (to show that a scene simulates only what it asks for).
    type :: assembly_stats_t
        !> Quadrature points evaluated with a finite-strain / small-strain law.
        integer(i8) :: finite_strain_points = 0, small_strain_points = 0
        !> Seconds spent in bulk assembly and in contact (search and assembly).
        real(dp) :: seconds_bulk = 0.0_dp, seconds_contact = 0.0_dp
        !> Times the stiffness pattern was rebuilt for the contact couplings.
        integer :: pattern_rebuilds = 0
    end type assembly_stats_t

contains

    !> Global DOFs of element `e` of `body`, local order 2(a-1)+i, shape [2 nen].
    pure function body_dofs(body, e) result(dofs)
        type(body_t), intent(in) :: body
        integer, intent(in) :: e
        integer :: dofs(2*size(body%disc%elements(e)%conn))
        integer :: a
        associate (conn => body%disc%elements(e)%conn)
            do a = 1, size(conn)
                dofs(2*a - 1) = body%dof0 + 2*conn(a) - 1
                dofs(2*a) = body%dof0 + 2*conn(a)
            end do
        end associate
    end function body_dofs

    !> Internal force `fe` [2 nen] and tangent `ke` [2 nen, 2 nen] of element `e`
    !> of `body` for the global displacement vector `u`. `ok` is false if the
    !> Jacobian of the deformation is not positive at some quadrature point.
    pure subroutine body_element(body, e, u, fe, ke, ok, work)
        type(body_t), intent(in) :: body
        integer, intent(in) :: e
        real(dp), intent(in) :: u(:)
        real(dp), intent(out) :: fe(:), ke(:, :)
        logical, intent(out) :: ok
        !> The element kernel's work arrays, kept by a caller that loops over elements.
        type(element_work_t), intent(inout), optional :: work
        real(dp) :: ue(2, size(fe)/2)
        call gather_displacements(body, e, u, ue)
        call solid_element(body%mat, body%points(e), ue, fe, ke, ok, work)
    end subroutine body_element

    !> Displacements `ue` [2, nen] of the control points of element `e` of `body`.
    pure subroutine gather_displacements(body, e, u, ue)
        type(body_t), intent(in) :: body
        integer, intent(in) :: e
        real(dp), intent(in) :: u(:)
        real(dp), intent(out) :: ue(:, :)
        integer :: a
        associate (conn => body%disc%elements(e)%conn)
            do a = 1, size(conn)
                ue(1, a) = u(body%dof0 + 2*conn(a) - 1)
                ue(2, a) = u(body%dof0 + 2*conn(a))
            end do
        end associate
    end subroutine gather_displacements

    !> The positions of every bulk element's entries in `k` (built on its pattern);
    !> an error when there is no memory for them (the largest array of a model).
    subroutine new_assembly_map(model, k, map, error)
        type(model_t), intent(in) :: model
        type(csc_matrix_t), intent(inout) :: k
        type(assembly_map_t), intent(out) :: map
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: dofs(:), pos(:, :), runs(:)
        integer :: ib, e, nel, m, idx, st, nr
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
                    map%ptr(idx + 1) = map%ptr(idx) + 2*size(conn)*nr
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
                m = size(dofs)
                if (allocated(pos)) then
                    if (size(pos, 1) /= m) deallocate (pos)
                end if
                if (.not. allocated(pos)) allocate (pos(m, m))
                call k%element_positions(dofs, pos)
                call consecutive_runs(model%bodies(ib)%disc%elements(e)%conn, runs, nr)
                call run_positions(pos, runs(1:nr + 1), map%pos(map%ptr(idx):map%ptr(idx + 1) - 1), ok)
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

    !> `starts` [nr, m]: the position of each run's first row (2 runs(t) - 1) in each
    !> column of the element positions `pos` [m, m]; false if a run's rows are not
    !> at consecutive positions (a pattern that lacks one of them).
    pure subroutine run_positions(pos, runs, starts, ok)
        integer, intent(in) :: pos(:, :), runs(:)
        integer, intent(out) :: starts(size(runs) - 1, size(pos, 2))
        logical, intent(out) :: ok
        integer :: c, t, r0, r
        ok = .true.
        do c = 1, size(pos, 2)
            do t = 1, size(runs) - 1
                r0 = 2*runs(t) - 1
                starts(t, c) = pos(r0, c)
                do r = r0 + 1, 2*runs(t + 1) - 2
                    ok = ok .and. pos(r, c) == pos(r0, c) + (r - r0)
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
                n = n + 2*size(model%bodies(ib)%disc%elements(e)%conn)
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
                n = 2*size(model%bodies(ib)%disc%elements(e)%conn)
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

    !> Residual r = f_int(u) - f_ext and (if `k` present) tangent stiffness.
    !> Fails with a numeric error if J <= 0 at a quadrature point.
    !> When a contact point falls outside the stiffness pattern, the pattern (and
    !> `map`) is rebuilt and the contact part evaluated again. With `k` and `map`,
    !> a deformable master and `refit`, the bulk part (elements and external forces)
    !> is kept from before the contact part and carried into the new pattern instead
    !> of being assembled again (the same numbers: the bulk part does not depend on
    !> the pattern); a rebuild at another assembly assembles it again.
    subroutine assemble(model, u, t, r, stats, error, k, map, refit)
        type(model_t), intent(inout) :: model
        real(dp), intent(in) :: u(:)
        !> Load time (for the external forces and the rigid masters' motions).
        real(dp), intent(in) :: t
        real(dp), intent(out) :: r(:)
        type(assembly_stats_t), intent(inout) :: stats
        type(error_t), allocatable, intent(out) :: error
        type(csc_matrix_t), intent(inout), optional :: k
        !> Element positions in `k` (from `new_assembly_map`): no search when given.
        type(assembly_map_t), intent(inout), optional :: map
        !> Fit the contact part of the pattern to `u` (the start of a substep): each
        !> slave element coupled with the master control points near its points
        !> (`contact_pair_t%wanted_ranges`), rebuilt only if a range changed. The pattern then
        !> depends on `u` only, so a restarted run gets the same patterns.
        logical, intent(in), optional :: refit
        ! bulk residual [ndof] and stiffness values [nnz], kept for a rebuild
        real(dp), allocatable :: r_bulk(:), k_bulk(:)
        integer :: pass, ip
        logical :: fit, keep
        call set_contact_time(model, t)
        fit = .false.
        if (present(refit)) fit = refit .and. present(k)
        ! the bulk part is kept for a rebuild at a substep's first assembly, where the
        ! refit makes one likely; elsewhere (a point projecting outside its range: rare)
        ! it is assembled again (the same numbers), not copied at every assembly
        keep = .false.
        if (present(k) .and. present(map) .and. fit) &
            keep = any([(model%pairs(ip)%pair%master%deformable, ip=1, size(model%pairs))])
        call assemble_bulk(model, u, t, r, stats, error, k, map)
        if (allocated(error)) return
        if (keep) then
            r_bulk = r
            k_bulk = k%values
        end if
        ! a substep's first evaluation projects without the last projections as starts
        if (fit) then
            do ip = 1, size(model%pairs)
                model%pairs(ip)%pair%warm = .false.
            end do
        end if
        do pass = 1, 3
            call assemble_contact(model, u, r, stats, error, k)
            do ip = 1, size(model%pairs)
                model%pairs(ip)%pair%warm = .true.
            end do
            if (allocated(error) .or. .not. present(k)) return
            if (fit) then
                fit = .false.
                if (refit_contact_ranges(model)) then
                    ! the ranges now hold every projection of this evaluation
                    do ip = 1, size(model%pairs)
                        model%pairs(ip)%pair%pattern_miss = .true.
                    end do
                end if
            end if
            if (.not. any([(model%pairs(ip)%pair%pattern_miss, ip=1, size(model%pairs))])) return
            do ip = 1, size(model%pairs)
                model%pairs(ip)%pair%pattern_miss = .false.
            end do
            if (keep) then
                call rebuild_pattern(model, k, error, map, k_bulk)
            else
                call rebuild_pattern(model, k, error, map)
            end if
            if (allocated(error)) return
            stats%pattern_rebuilds = stats%pattern_rebuilds + 1
            if (keep) then
                r = r_bulk
                k%values = k_bulk
            else
                call assemble_bulk(model, u, t, r, stats, error, k, map)
                if (allocated(error)) return
            end if
        end do
        call fatal_error(error, 'contact: the stiffness pattern still misses contact couplings '// &
                         'after two rebuilds', error_code%numeric)
    end subroutine assemble

    !> The residual r = f_int(u) - f_ext alone, the same numbers as `assemble`'s
    !> with a tangent: the elements' forces without their stiffness, a kept linear
    !> body's K u on the pattern `k` (whose values are left as they are), the contact
    !> pairs evaluated as with a stiffness (each point's fit to the pattern checked)
    !> but nothing added. `fits` is false when a point fell outside the pattern,
    !> where `assemble` would have rebuilt it and evaluated again: the pairs' ranges
    !> are then widened, and the caller restores the pairs or assembles in full.
    !> For an iterate whose tangent is not wanted (a Newton iterate expected to be
    !> the converged one).
    subroutine assemble_residual(model, u, t, r, stats, error, k, map, fits)
        type(model_t), intent(inout) :: model
        real(dp), intent(in) :: u(:)
        real(dp), intent(in) :: t
        real(dp), intent(out) :: r(:)
        type(assembly_stats_t), intent(inout) :: stats
        type(error_t), allocatable, intent(out) :: error
        type(csc_matrix_t), intent(inout) :: k
        type(assembly_map_t), intent(inout) :: map
        logical, intent(out) :: fits
        integer :: ip
        fits = .false.
        call set_contact_time(model, t)
        call assemble_bulk(model, u, t, r, stats, error, k, map, forces_only=.true.)
        if (allocated(error)) return
        call assemble_contact(model, u, r, stats, error, fit_only=.true.)
        do ip = 1, size(model%pairs)
            model%pairs(ip)%pair%warm = .true.
        end do
        if (allocated(error)) return
        fits = .not. any([(model%pairs(ip)%pair%pattern_miss, ip=1, size(model%pairs))])
    end subroutine assemble_residual

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

    !> Fit the contact ranges of every deformable-master pair to its last evaluation
    !> (`contact_pair_t%wanted_ranges`); true if a range changed (the pattern must be rebuilt).
    function refit_contact_ranges(model) result(changed)
        type(model_t), intent(inout) :: model
        logical :: changed
        integer, allocatable :: lo(:), hi(:)
        integer :: ip
        changed = .false.
        do ip = 1, size(model%pairs)
            associate (pair => model%pairs(ip)%pair)
                if (.not. pair%master%deformable) cycle
                allocate (lo(size(pair%mlo)), hi(size(pair%mhi)))
                call pair%wanted_ranges(size(pair%master%all_dofs())/2, 8, lo, hi)
                if (any(lo /= pair%mlo) .or. any(hi /= pair%mhi)) then
                    changed = .true.
                    pair%mlo = lo
                    pair%mhi = hi
                end if
                deallocate (lo, hi)
            end associate
        end do
    end function refit_contact_ranges

    !> The stiffness of the bodies alone at u = 0, `k0`, on a pattern without
    !> contact couplings: for linear-elastic bodies, the bulk part of every tangent.
    !> It is assembled into the tangent `k` with `map` (the same elements summed in
    !> the same order as `assemble` does), so that with `map%keep_linear` the
    !> linear bodies' stiffness is kept there and the first assembly of the loop
    !> does not integrate them again; `k`'s values are then those of k0. The
    !> quadrature points and time count in `stats`.
    subroutine bulk_stiffness(model, k, map, k0, stats, error)
        type(model_t), intent(in) :: model
        type(csc_matrix_t), intent(inout) :: k
        type(assembly_map_t), intent(inout) :: map
        type(csc_matrix_t), intent(out) :: k0
        type(assembly_stats_t), intent(inout) :: stats
        type(error_t), allocatable, intent(out) :: error
        real(dp), allocatable :: u(:), r(:)
        integer, allocatable :: pos(:)
        allocate (u(model%ndof), r(model%ndof), source=0.0_dp)
        call assemble_bulk(model, u, 0.0_dp, r, stats, error, k, map)
        if (allocated(error)) return
        call stiffness_pattern(model, k0, error, contact=.false.)
        if (allocated(error)) return
        call pattern_positions(k0, k, pos)
        k0%values = k%values(pos)
    end subroutine bulk_stiffness

    !> The bulk part of `assemble`: every element's internal force and tangent, and
    !> the external forces (r = f_int - f_ext; `k` zeroed first). With `forces_only`
    !> the forces alone (`k`: the pattern of a kept linear body's K u, not changed).
    subroutine assemble_bulk(model, u, t, r, stats, error, k, map, forces_only)
        type(model_t), intent(in) :: model
        real(dp), intent(in) :: u(:)
        real(dp), intent(in) :: t
        real(dp), intent(out) :: r(:)
        type(assembly_stats_t), intent(inout) :: stats
        type(error_t), allocatable, intent(out) :: error
        type(csc_matrix_t), intent(inout), optional :: k
        !> With `k`: element positions; the linear bodies' stiffness is kept in it.
        type(assembly_map_t), intent(inout), optional :: map
        logical, intent(in), optional :: forces_only
        real(dp), allocatable :: fe(:), ue(:, :), ke(:, :)
        integer, allocatable :: dofs(:), runs(:)
        type(element_work_t) :: work
        integer :: ib, e, n, npts, idx, nr
        logical :: ok, keep, by_dofs, tangent
        integer(i8) :: c0, c1, rate

        call system_clock(c0, rate)
        r = 0.0_dp
        tangent = present(k)
        if (present(forces_only)) tangent = tangent .and. .not. forces_only
        if (tangent) call k%zero()
        ! without the map, K is added element matrix by element matrix (by DOF numbers);
        ! otherwise it stays in the kernel's blocks (added through the map, or not needed)
        by_dofs = tangent .and. .not. present(map)
        keep = .false.
        if (present(k) .and. present(map)) keep = map%keep_linear
        if (keep) then
            if (.not. allocated(map%linear)) allocate (map%linear(size(model%bodies)))
        end if
        idx = 0
        do ib = 1, size(model%bodies)
            associate (body => model%bodies(ib))
                if (keep) then
                    ! a linear body's stiffness is constant: f_int = K u
                    if (allocated(map%linear(ib)%values)) then
                        call add_linear_body(map%linear(ib), u, k, r, tangent)
                        idx = idx + body%disc%nel
                        cycle
                    end if
                end if
                npts = product(body%n_gauss)
                do e = 1, body%disc%nel
                    n = 2*size(body%disc%elements(e)%conn)
                    if (allocated(fe)) then
                        if (size(fe) /= n) deallocate (fe, ue, runs)
                    end if
                    if (.not. allocated(fe)) allocate (fe(n), ue(2, n/2), runs(n/2 + 1))
                    if (by_dofs) then
                        if (allocated(ke)) then
                            if (size(ke, 1) /= n) deallocate (ke)
                        end if
                        if (.not. allocated(ke)) allocate (ke(n, n))
                        call body_element(body, e, u, fe, ke, ok, work)
                    else
                        call gather_displacements(body, e, u, ue)
                        if (tangent) then
                            call solid_element_blocks(body%mat, body%points(e), ue, fe, ok, work)
                        else
                            call solid_element_force(body%mat, body%points(e), ue, fe, ok, work)
                        end if
                    end if
                    if (.not. ok) then
                        call fatal_error(error, "body '"//trim(body%name)//"' element "//str(e)// &
                                         ': the deformation is inverted (J <= 0 at a quadrature point)', &
                                         error_code%numeric)
                        return
                    end if
                    idx = idx + 1
                    call add_force(body, e, fe, r)
                    if (by_dofs) then
                        dofs = body_dofs(body, e)
                        call k%add_element(dofs, ke)
                    else if (tangent) then
                        call consecutive_runs(body%disc%elements(e)%conn, runs, nr)
                        call add_mapped(k%values, map%pos(map%ptr(idx):map%ptr(idx + 1) - 1), runs(1:nr + 1), &
                                        n/2, work%k4, size(work%k4, 1), work%sym)
                    end if
                end do
                if (body%mat%finite_strain) then
                    stats%finite_strain_points = stats%finite_strain_points + int(npts, i8)*body%disc%nel
                else
                    stats%small_strain_points = stats%small_strain_points + int(npts, i8)*body%disc%nel
                    if (keep .and. tangent) &
                        call keep_linear_body(k, body%dof0 + 1, body%dof0 + 2*body%disc%ncp, map%linear(ib))
                end if
            end associate
        end do
        block
            real(dp), allocatable :: fext(:)
            allocate (fext(size(r)))
            call external_forces(model, t, fext)
            r = r - fext
        end block
        call system_clock(c1)
        stats%seconds_bulk = stats%seconds_bulk + real(c1 - c0, dp)/real(rate, dp)
    end subroutine assemble_bulk

    !> r(dofs of element e) += fe (the element's force, local order 2(a-1) + i).
    pure subroutine add_force(body, e, fe, r)
        type(body_t), intent(in) :: body
        integer, intent(in) :: e
        real(dp), intent(in) :: fe(:)
        real(dp), intent(inout) :: r(:)
        integer :: a, i
        associate (conn => body%disc%elements(e)%conn)
            do a = 1, size(conn)
                i = body%dof0 + 2*conn(a)
                r(i - 1) = r(i - 1) + fe(2*a - 1)
                r(i) = r(i) + fe(2*a)
            end do
        end associate
    end subroutine add_force

    !> Keep the stiffness a linear body just added to `k` (columns `first`..`last`:
    !> its DOFs; only its elements have entries there yet).
    pure subroutine keep_linear_body(k, first, last, kept)
        type(csc_matrix_t), intent(in) :: k
        integer, intent(in) :: first, last
        type(body_stiffness_t), intent(inout) :: kept
        kept%first = first
        kept%last = last
        kept%values = k%values(k%colptr(first) + 1:k%colptr(last + 1))
    end subroutine keep_linear_body

    !> A kept linear body's part of the assembly: its stiffness into `k`, its
    !> internal force K u into `r` (the same as integrating it, to round-off).
    pure subroutine add_linear_body(kept, u, k, r, tangent)
        type(body_stiffness_t), intent(in) :: kept
        real(dp), intent(in) :: u(:)
        type(csc_matrix_t), intent(inout) :: k
        real(dp), intent(inout) :: r(:)
        !> Copy the stiffness into `k` (else only its pattern is read).
        logical, intent(in) :: tangent
        integer :: j, p, p0
        p0 = k%colptr(kept%first)
        if (tangent) k%values(p0 + 1:k%colptr(kept%last + 1)) = kept%values
        do j = kept%first, kept%last
            do p = k%colptr(j) + 1, k%colptr(j + 1)
                r(k%rowind(p) + 1) = r(k%rowind(p) + 1) + kept%values(p - p0)*u(j)
            end do
        end do
    end subroutine add_linear_body

    !> values += K for the entries of an element matrix (the runs of its control
    !> points `runs` and their first rows' positions `starts` from `new_assembly_map`)
    !> from the element kernel's blocks `k4` = [K^xx K^xy K^yy K^yx] [ld, 4 nen]
    !> (`sym`: K^yx = (K^xy)^T, not stored). A run's entries in a column are
    !> consecutive values, x and y rows in turn. An element adds once to each of its
    !> entries, so the sums are those of adding the interleaved matrix.
    pure subroutine add_mapped(values, starts, runs, nen, k4, ld, sym)
        real(dp), intent(inout) :: values(:)
        integer, intent(in) :: runs(:), nen, ld
        integer, intent(in) :: starts(size(runs) - 1, 2*nen)
        real(dp), intent(in) :: k4(ld, *)
        logical, intent(in) :: sym
        integer :: a, b, t, p, q
        do b = 1, nen
            do t = 1, size(runs) - 1
                p = starts(t, 2*b - 1) - 2*runs(t)
                q = starts(t, 2*b) - 2*runs(t)
                if (sym) then
                    do a = runs(t), runs(t + 1) - 1
                        values(p + 2*a) = values(p + 2*a) + k4(a, b)
                        values(p + 2*a + 1) = values(p + 2*a + 1) + k4(b, nen + a)
                    end do
                else
                    do a = runs(t), runs(t + 1) - 1
                        values(p + 2*a) = values(p + 2*a) + k4(a, b)
                        values(p + 2*a + 1) = values(p + 2*a + 1) + k4(a, 3*nen + b)
                    end do
                end if
                do a = runs(t), runs(t + 1) - 1
                    values(q + 2*a) = values(q + 2*a) + k4(a, nen + b)
                    values(q + 2*a + 1) = values(q + 2*a + 1) + k4(a, 2*nen + b)
                end do
            end do
        end do
    end subroutine add_mapped

    !> The contact part of `assemble`: every pair's residual and tangent, added to
    !> `r` and `k`. With `fit_only` the pairs evaluate as with a stiffness (checking
    !> their points' fit to the pattern) but add none.
    subroutine assemble_contact(model, u, r, stats, error, k, fit_only)
        type(model_t), intent(inout) :: model
        real(dp), intent(in) :: u(:)
        real(dp), intent(inout) :: r(:)
        type(assembly_stats_t), intent(inout) :: stats
        type(error_t), allocatable, intent(out) :: error
        type(csc_matrix_t), intent(inout), optional :: k
        logical, intent(in), optional :: fit_only
        integer :: ip
        integer(i8) :: c0, c1, rate
        logical :: fit
        ! the positions of the last point's entries (the next point of a slave element
        ! often projects onto the same master span: the same DOFs)
        type(position_cache_t) :: cache

        call system_clock(c0, rate)
        fit = .false.
        if (present(fit_only)) fit = fit_only
        do ip = 1, size(model%pairs)
            if (fit) then
                call model%pairs(ip)%pair%evaluate(u, r, error, add_nothing)
            else if (present(k)) then
                call model%pairs(ip)%pair%evaluate(u, r, error, add_to_k)
            else
                call model%pairs(ip)%pair%evaluate(u, r, error)
            end if
            if (allocated(error)) exit
        end do
        call system_clock(c1)
        stats%seconds_contact = stats%seconds_contact + real(c1 - c0, dp)/real(rate, dp)
    contains
        subroutine add_to_k(dofs, kl)
            integer, intent(in) :: dofs(:)
            real(dp), intent(in) :: kl(:, :)
            call k%add_cached(dofs, kl, cache)
        end subroutine add_to_k
        subroutine add_nothing(dofs, kl)
            integer, intent(in) :: dofs(:)
            real(dp), intent(in) :: kl(:, :)
        end subroutine add_nothing
    end subroutine assemble_contact

    !> External forces of the pressures at load time `t`: f_a = int R_a (-p N) ds on the
    !> reference edge, N the outward unit normal.
    subroutine external_forces(model, t, f)
        type(model_t), intent(in) :: model
        real(dp), intent(in) :: t
        real(dp), intent(out) :: f(:)
        real(dp), allocatable :: gx(:), wx(:), r(:), dr(:, :), d2r(:, :), x0(:, :)
        integer, allocatable :: dofs(:)
        real(dp) :: p, s, tang(2), inward(2), normal(2), xi, eta, h, jac(2, 2)
        integer :: k, e, i, a, nen, dir, ng
        logical :: on_edge

        f = 0.0_dp
        do k = 1, size(model%pressure)
            p = phase_value(model%pressure(k)%values, t)
            if (p == 0.0_dp) cycle
            associate (body => model%bodies(model%pressure(k)%body), edge => model%pressure(k)%edge)
                ! along xi for the eta edges (3, 4), along eta for the xi edges (1, 2)
                dir = merge(1, 2, edge >= 3)
                ng = body%n_gauss(dir)
                allocate (gx(ng), wx(ng))
                call gauss_legendre(ng, gx, wx)
                do e = 1, body%disc%nel
                    associate (el => body%disc%elements(e))
                        select case (edge)
                        case (1); on_edge = el%ix == 1
                        case (2); on_edge = el%ix == body%disc%nel_xi
                        case (3); on_edge = el%ie == 1
                        case default; on_edge = el%ie == body%disc%nel_eta
                        end select
                        if (.not. on_edge) cycle
                        nen = element_nfun(body%disc, e)
                        allocate (r(nen), dr(2, nen), d2r(3, nen))
                        x0 = body%disc%x(:, el%conn)
                        dofs = body_dofs(body, e)
                        h = 0.5_dp*merge(el%xi(2) - el%xi(1), el%eta(2) - el%eta(1), dir == 1)
                        do i = 1, ng
                            s = merge(el%xi(1), el%eta(1), dir == 1) + h*(gx(i) + 1.0_dp)
                            select case (edge)
                            case (1); xi = el%xi(1); eta = s
                            case (2); xi = el%xi(2); eta = s
                            case (3); xi = s; eta = el%eta(1)
                            case default; xi = s; eta = el%eta(2)
                            end select
                            call element_basis(body%disc, e, xi, eta, r, dr, d2r)
                            jac = matmul(x0, transpose(dr))
                            tang = jac(:, dir)
                            ! the other parametric direction points inward at a 0-edge
                            inward = jac(:, 3 - dir)*merge(1.0_dp, -1.0_dp, edge == 1 .or. edge == 3)
                            normal = [tang(2), -tang(1)]/norm2(tang)
                            if (dot_product(normal, inward) > 0.0_dp) normal = -normal
                            do a = 1, nen
                                f(dofs(2*a - 1:2*a)) = f(dofs(2*a - 1:2*a)) - &
                                                       p*r(a)*normal*norm2(tang)*wx(i)*h
                            end do
                        end do
                        deallocate (r, dr, d2r)
                    end associate
                end do
                deallocate (gx, wx)
            end associate
        end do
    end subroutine external_forces

end module voiga_model_assembly
