!> The stiffness pattern of a contact pair: the master control points each slave
!> element is coupled with, fitted to the projections (`voiga_contact_pair`; a
!> submodule only to keep the files short, the interfaces are in the module).
submodule(voiga_contact_pair) voiga_contact_pair_pattern
    implicit none

contains

    module procedure pair_fit_pattern
        integer :: e
        e = self%point_element(k)
        inside = mp%first >= self%mlo(e) .and. mp%last <= self%mhi(e)
        if (inside) return
        if (self%mlo(e) > self%mhi(e)) then
            self%mlo(e) = mp%first
            self%mhi(e) = mp%last
        else
            self%mlo(e) = min(self%mlo(e), mp%first)
            self%mhi(e) = max(self%mhi(e), mp%last)
        end if
        self%pattern_miss = .true.
    end procedure pair_fit_pattern

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
        integer :: e, k, ng, w, rng(2)
        lo = 1
        hi = 0
        do e = 1, size(lo)
            rng = self%point_range(e)
            ng = rng(2) - rng(1) + 1
            if (ng <= 0) cycle
            associate (pts => self%out(rng(1):rng(2)))
                h = norm2(maxval(reshape([(pts(k)%x(1:self%nsd), k=1, ng)], [self%nsd, ng]), dim=2) - &
                          minval(reshape([(pts(k)%x(1:self%nsd), k=1, ng)], [self%nsd, ng]), dim=2))
                do k = 1, ng
                    if (pts(k)%first > pts(k)%last .or. pts(k)%gap >= h) cycle
                    w = pts(k)%last - pts(k)%first
                    if (lo(e) > hi(e)) then
                        lo(e) = pts(k)%first - w
                        hi(e) = pts(k)%last + w
                    else
                        lo(e) = min(lo(e), pts(k)%first - w)
                        hi(e) = max(hi(e), pts(k)%last + w)
                    end if
                end do
            end associate
            if (lo(e) > hi(e)) cycle
            lo(e) = max(1, ((lo(e) - 1)/block)*block + 1)
            hi(e) = min(n_master, ((hi(e) + block - 1)/block)*block)
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

end submodule voiga_contact_pair_pattern
