!> The bulk part of the assembly: every element's internal force and tangent (added
!> through the assembly map, or by DOF numbers without one), the constant stiffness of
!> linear-elastic bodies kept and reused, and the external (pressure) forces.
module voiga_model_assembly_bulk
    use voiga_kinds, only: dp, i8
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_model, only: model_t
    use voiga_model_body, only: body_t
    use voiga_model_pressure, only: external_forces
    use voiga_text, only: str
    use voiga_element_solid, only: solid_element, solid_element_blocks, solid_element_force, element_work_t
    use voiga_element_solid3, only: solid3_element, solid3_force, solid3_work_t
    use voiga_linalg_sparse, only: csc_matrix_t, pattern_positions, consecutive_runs
    use voiga_model_assembly_pattern, only: body_dofs, stiffness_pattern, assembly_map_t, &
                                            body_stiffness_t
    implicit none
    private

    public :: assembly_stats_t, body_element, assemble_bulk, bulk_stiffness, external_forces

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

    !> Displacements `ue` [nsd, nen] of the control points of element `e` of `body`.
    pure subroutine gather_displacements(body, e, u, ue)
        type(body_t), intent(in) :: body
        integer, intent(in) :: e
        real(dp), intent(in) :: u(:)
        real(dp), intent(out) :: ue(:, :)
        integer :: a, c, nsd
        nsd = size(ue, 1)
        associate (conn => body%disc%elements(e)%conn)
            do a = 1, size(conn)
                do c = 1, nsd
                    ue(c, a) = u(body%dof0 + nsd*(conn(a) - 1) + c)
                end do
            end do
        end associate
    end subroutine gather_displacements

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
        integer :: ib, npts, idx
        logical :: keep, by_dofs, tangent
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
                ! the kernel of the body's dimension (plane strain or solid)
                if (body%disc%nsd == 2) then
                    call assemble_plane(body, u, r, tangent, by_dofs, idx, error, k, map)
                else
                    call assemble_solid(body, u, r, tangent, by_dofs, idx, error, k, map)
                end if
                if (allocated(error)) return
                if (body%mat%finite_strain) then
                    stats%finite_strain_points = stats%finite_strain_points + int(npts, i8)*body%disc%nel
                else
                    stats%small_strain_points = stats%small_strain_points + int(npts, i8)*body%disc%nel
                    if (keep .and. tangent) &
                        call keep_linear_body(k, body%dof0 + 1, body%dof0 + body%disc%nsd*body%disc%ncp, &
                                             map%linear(ib))
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

    !> The elements of the plane body `body` into `r` and, with `tangent`, `k` (by DOF
    !> numbers when `by_dofs`, else through `map`); `idx` counts the elements of all
    !> bodies so far (the map's index).
    subroutine assemble_plane(body, u, r, tangent, by_dofs, idx, error, k, map)
        type(body_t), intent(in) :: body
        real(dp), intent(in) :: u(:)
        real(dp), intent(inout) :: r(:)
        logical, intent(in) :: tangent, by_dofs
        integer, intent(inout) :: idx
        type(error_t), allocatable, intent(out) :: error
        type(csc_matrix_t), intent(inout), optional :: k
        type(assembly_map_t), intent(in), optional :: map
        real(dp), allocatable :: fe(:), ue(:, :), ke(:, :)
        integer, allocatable :: dofs(:), runs(:)
        type(element_work_t) :: work
        integer :: e, n, nr
        logical :: ok
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
                call inverted(body, e, error)
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
    end subroutine assemble_plane

    !> `assemble_plane` for a solid: the three-dimensional kernel, its element
    !> matrices added by DOF numbers or through `map` (`add_mapped_full`).
    subroutine assemble_solid(body, u, r, tangent, by_dofs, idx, error, k, map)
        type(body_t), intent(in) :: body
        real(dp), intent(in) :: u(:)
        real(dp), intent(inout) :: r(:)
        logical, intent(in) :: tangent, by_dofs
        integer, intent(inout) :: idx
        type(error_t), allocatable, intent(out) :: error
        type(csc_matrix_t), intent(inout), optional :: k
        type(assembly_map_t), intent(in), optional :: map
        real(dp), allocatable :: fe(:), ue(:, :), ke(:, :)
        integer, allocatable :: runs(:)
        type(solid3_work_t) :: work
        integer :: e, n, nr
        logical :: ok
        do e = 1, body%disc%nel
            n = 3*size(body%disc%elements(e)%conn)
            if (allocated(fe)) then
                if (size(fe) /= n) deallocate (fe, ue, ke, runs)
            end if
            if (.not. allocated(fe)) allocate (fe(n), ue(3, n/3), ke(n, n), runs(n/3 + 1))
            call gather_displacements(body, e, u, ue)
            if (tangent) then
                call solid3_element(body%mat, body%points(e), ue, fe, ke, ok, work)
            else
                call solid3_force(body%mat, body%points(e), ue, fe, ok, work)
            end if
            if (.not. ok) then
                call inverted(body, e, error)
                return
            end if
            idx = idx + 1
            call add_force(body, e, fe, r)
            if (by_dofs) then
                call k%add_element(body_dofs(body, e), ke)
            else if (tangent) then
                call consecutive_runs(body%disc%elements(e)%conn, runs, nr)
                call add_mapped_full(k%values, map%pos(map%ptr(idx):map%ptr(idx + 1) - 1), runs(1:nr + 1), 3, ke)
            end if
        end do
    end subroutine assemble_solid

    !> The error of element `e` of `body` whose deformation is inverted.
    subroutine inverted(body, e, error)
        type(body_t), intent(in) :: body
        integer, intent(in) :: e
        type(error_t), allocatable, intent(out) :: error
        call fatal_error(error, "body '"//trim(body%name)//"' element "//str(e)// &
                         ': the deformation is inverted (J <= 0 at a quadrature point)', error_code%numeric)
    end subroutine inverted

    !> values += ke for an element matrix in local DOF order (nsd(a-1) + i) through
    !> the positions of its runs' first rows `starts` (`new_assembly_map`): the rows
    !> of a run are consecutive values in each column.
    pure subroutine add_mapped_full(values, starts, runs, nsd, ke)
        real(dp), intent(inout) :: values(:)
        integer, intent(in) :: runs(:), nsd
        real(dp), intent(in) :: ke(:, :)
        integer, intent(in) :: starts(size(runs) - 1, size(ke, 2))
        integer :: b, t, p, i0, i1
        do b = 1, size(ke, 2)
            do t = 1, size(runs) - 1
                p = starts(t, b)
                i0 = nsd*(runs(t) - 1) + 1
                i1 = nsd*(runs(t + 1) - 1)
                values(p:p + i1 - i0) = values(p:p + i1 - i0) + ke(i0:i1, b)
            end do
        end do
    end subroutine add_mapped_full

    !> r(dofs of element e) += fe (the element's force, local order nsd(a-1) + i).
    pure subroutine add_force(body, e, fe, r)
        type(body_t), intent(in) :: body
        integer, intent(in) :: e
        real(dp), intent(in) :: fe(:)
        real(dp), intent(inout) :: r(:)
        integer :: a, c, i, nsd
        nsd = body%disc%nsd
        associate (conn => body%disc%elements(e)%conn)
            do a = 1, size(conn)
                i = body%dof0 + nsd*(conn(a) - 1)
                do c = 1, nsd
                    r(i + c) = r(i + c) + fe(nsd*(a - 1) + c)
                end do
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

end module voiga_model_assembly_bulk
