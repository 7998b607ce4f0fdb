!> The stiffness pattern of a contact pair: the master control points each slave
!> element is coupled with, fitted to the projections (`voiga_contact_pair`; a
!> submodule only to keep the files short, the interfaces are in the module).
submodule(voiga_contact_pair) voiga_contact_pair_pattern
    implicit none

contains

    module procedure pair_fit_pattern
        integer :: e, lo(2), hi(2), first(2), last(2)
        inside = mp%first > mp%last   ! no master DOFs (a rigid master)
        if (inside) return
        e = self%point_element(k)
        first = grid_ij(mp%first, self%mwidth)
        last = grid_ij(mp%last, self%mwidth)
        lo = grid_ij(self%mlo(e), self%mwidth)
        hi = grid_ij(self%mhi(e), self%mwidth)
        inside = self%mlo(e) <= self%mhi(e) .and. all(first >= lo) .and. all(last <= hi)
        if (inside) return
        if (self%mlo(e) > self%mhi(e)) then
            lo = first
            hi = last
        else
            lo = min(lo, first)
            hi = max(hi, last)
        end if
        self%mlo(e) = grid_id(lo, self%mwidth)
        self%mhi(e) = grid_id(hi, self%mwidth)
        self%pattern_miss = .true.
    end procedure pair_fit_pattern

    module procedure pair_range_ids
        integer :: lo(2), hi(2), i, j
        if (self%mlo(e) > self%mhi(e)) then
            allocate (ids(0))
        else if (self%mwidth == 0) then
            ids = [(i, i=self%mlo(e), self%mhi(e))]
        else
            lo = grid_ij(self%mlo(e), self%mwidth)
            hi = grid_ij(self%mhi(e), self%mwidth)
            ids = [((i + (j - 1)*self%mwidth, i=lo(1), hi(1)), j=lo(2), hi(2))]
        end if
    end procedure pair_range_ids

    module procedure pair_element_dofs
        integer :: s, p, nu
        integer, allocatable :: ids(:)
        if (self%slave%npar > 1) then
            nu = size(self%slave%spans)
            ids = face_ids(self%slave, [self%slave%spans(modulo(e - 1, nu) + 1), self%slave%spans_eta((e - 1)/nu + 1)])
            dofs = reshape(self%slave%dofs(:, ids), [3*size(ids)])
            return
        end if
        p = self%slave%degree
        s = self%slave%spans(e)
        dofs = reshape(self%slave%dofs(:, s - p:s), [size(self%slave%dofs, 1)*(p + 1)])
    end procedure pair_element_dofs

    module procedure pair_wanted_ranges
        real(dp) :: h
        integer :: e, k, ng, rng(2), first(2), last(2), w(2), wlo(2), whi(2), top(2)
        lo = 1
        hi = 0
        top = grid_ij(n_master, self%mwidth)
        do e = 1, size(lo)
            rng = self%point_range(e)
            ng = rng(2) - rng(1) + 1
            if (ng <= 0) cycle
            wlo = 1
            whi = 0
            associate (pts => self%out(rng(1):rng(2)))
                h = norm2(maxval(reshape([(pts(k)%x(1:self%nsd), k=1, ng)], [self%nsd, ng]), dim=2) - &
                          minval(reshape([(pts(k)%x(1:self%nsd), k=1, ng)], [self%nsd, ng]), dim=2))
                do k = 1, ng
                    if (pts(k)%first > pts(k)%last .or. pts(k)%gap >= h) cycle
                    first = grid_ij(pts(k)%first, self%mwidth)
                    last = grid_ij(pts(k)%last, self%mwidth)
                    ! widened by the support's own size in each direction
                    w = last - first
                    first = first - w
                    last = last + w
                    if (wlo(1) > whi(1)) then
                        wlo = first
                        whi = last
                    else
                        wlo = min(wlo, first)
                        whi = max(whi, last)
                    end if
                end do
            end associate
            if (wlo(1) > whi(1)) cycle
            ! rounded outward to blocks, per direction, within the master's grid
            wlo = max(1, ((wlo - 1)/block)*block + 1)
            whi = min(top, ((whi + block - 1)/block)*block)
            lo(e) = grid_id(wlo, self%mwidth)
            hi(e) = grid_id(whi, self%mwidth)
        end do
    end procedure pair_wanted_ranges

    module procedure pair_refit_ranges
        integer, allocatable :: lo(:), hi(:)
        changed = .false.
        if (.not. self%master%deformable) return
        allocate (lo(size(self%mlo)), hi(size(self%mhi)))
        call self%wanted_ranges(size(self%master%all_dofs())/self%nsd, block, lo, hi)
        changed = any(lo /= self%mlo) .or. any(hi /= self%mhi)
        if (.not. changed) return
        self%mlo = lo
        self%mhi = hi
    end procedure pair_refit_ranges

    !> (i, j) of control point `id` in a grid of `width` per row (0: one row, (id, 1)).
    pure function grid_ij(id, width) result(ij)
        integer, intent(in) :: id, width
        integer :: ij(2)
        if (width == 0) then
            ij = [id, 1]
        else
            ij = [modulo(id - 1, width) + 1, (id - 1)/width + 1]
        end if
    end function grid_ij

    !> The control point at (i, j) of a grid of `width` per row (0: one row).
    pure integer function grid_id(ij, width) result(id)
        integer, intent(in) :: ij(2), width
        id = ij(1)
        if (width > 0) id = ij(1) + (ij(2) - 1)*width
    end function grid_id

end submodule voiga_contact_pair_pattern
