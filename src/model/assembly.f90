!> Assembly of the residual and the tangent stiffness of the whole model: the bulk
!> part (the bodies' elements and pressures, `voiga_model_assembly_bulk`), then every
!> contact pair's part added on the stiffness pattern (`voiga_model_assembly_pattern`),
!> which is refitted at a substep's start and rebuilt, with the contact part evaluated
!> again, when a contact point falls outside it. The rest of the code uses the assembly
!> through this module, which re-exports the bulk's and the pattern's public API.
module voiga_model_assembly
    use voiga_kinds, only: dp, i8
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_model, only: model_t, set_contact_time
    use voiga_linalg_sparse, only: csc_matrix_t, position_cache_t
    use voiga_model_assembly_pattern, only: body_dofs, stiffness_pattern, rebuild_pattern, &
                                            assembly_map_t, new_assembly_map
    use voiga_model_assembly_bulk, only: assembly_stats_t, body_element, assemble_bulk, &
                                         bulk_stiffness, external_forces
    implicit none
    private

    public :: assembly_stats_t, body_element, assemble, assemble_residual, external_forces, stiffness_pattern, body_dofs
    public :: assembly_map_t, new_assembly_map, bulk_stiffness

contains

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
                call model%pairs(ip)%pair%set_warm(.false.)
            end do
        end if
        do pass = 1, 3
            call assemble_contact(model, u, r, stats, error, k)
            do ip = 1, size(model%pairs)
                call model%pairs(ip)%pair%set_warm(.true.)
            end do
            if (allocated(error) .or. .not. present(k)) return
            if (fit) then
                fit = .false.
                if (refit_contact_ranges(model)) then
                    ! the ranges now hold every projection of this evaluation
                    do ip = 1, size(model%pairs)
                        call model%pairs(ip)%pair%set_pattern_miss(.true.)
                    end do
                end if
            end if
            if (.not. any([(model%pairs(ip)%pair%pattern_miss, ip=1, size(model%pairs))])) return
            do ip = 1, size(model%pairs)
                call model%pairs(ip)%pair%set_pattern_miss(.false.)
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
            call model%pairs(ip)%pair%set_warm(.true.)
        end do
        if (allocated(error)) return
        fits = .not. any([(model%pairs(ip)%pair%pattern_miss, ip=1, size(model%pairs))])
    end subroutine assemble_residual

    !> Fit the contact ranges of every deformable-master pair to its last evaluation
    !> (`contact_pair_t%wanted_ranges`); true if a range changed (the pattern must be rebuilt).
    function refit_contact_ranges(model) result(changed)
        type(model_t), intent(inout) :: model
        logical :: changed
        logical :: one
        integer :: ip
        changed = .false.
        do ip = 1, size(model%pairs)
            call model%pairs(ip)%pair%refit_ranges(8, one)
            changed = changed .or. one
        end do
    end function refit_contact_ranges

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

end module voiga_model_assembly
