!> The analysis of `supernodal_lu_t` (`voiga_solver_supernodal`): what depends on the
!> pattern only and is done once per pattern. The pattern analysed is that of the
!> entries nonzero in `a` or its transpose, ordered by AMD with CHOLMOD's symbolic
!> supernodal factorization (`supernodal_shim.c`); then each supernode's dense front,
!> the position of every entry of `a` in a front and of every row of a front in its
!> parent's front, and the update blocks' places in their pool. A new CSC pattern or
!> new nonzeros are first mapped into the fronts there are.
submodule(voiga_solver_supernodal) voiga_solver_supernodal_analysis
    use, intrinsic :: iso_c_binding, only: c_ptr, c_null_ptr
    use voiga_kinds, only: i8
    implicit none

    !> Most reals all fronts together may hold (128 MiB); larger systems keep UMFPACK.
    integer(i8), parameter :: max_front_storage = 16777216_i8

    interface
        function voiga_supernodal_analyze(n, colptr, rowind, handle, nsuper, nrows) result(status) &
            bind(c, name='voiga_supernodal_analyze')
            import :: c_int, c_ptr
            integer(c_int), value :: n
            integer(c_int), intent(in) :: colptr(*), rowind(*)
            type(c_ptr), intent(out) :: handle
            integer(c_int), intent(out) :: nsuper, nrows
            integer(c_int) :: status
        end function voiga_supernodal_analyze

        subroutine voiga_supernodal_copy(handle, perm, super, rptr, rows) bind(c, name='voiga_supernodal_copy')
            import :: c_int, c_ptr
            type(c_ptr), value :: handle
            integer(c_int), intent(out) :: perm(*), super(*), rptr(*), rows(*)
        end subroutine voiga_supernodal_copy

        subroutine voiga_supernodal_free(handle) bind(c, name='voiga_supernodal_free')
            import :: c_ptr
            type(c_ptr), value :: handle
        end subroutine voiga_supernodal_free

    end interface

contains

    module procedure update_analysis
        logical :: new_pattern
        new_pattern = .not. same_csc(self, a)
        if (new_pattern) call take_pattern(self, a)
        ok = .not. self%umfpack_only
        if (ok .and. self%renew .and. self%nsuper > 0) then
            if (.not. same_nonzeros(self, a)) self%nsuper = 0
        end if
        self%renew = .false.
        if (ok .and. self%nsuper == 0) then
            call analyse(self, a, ok)
        else if (ok) then
            ! a new CSC pattern (the contact couplings refitted) or new nonzeros: the
            ! supernodes analysed before take them while they fall in their fronts
            if (new_pattern) then
                call map_or_analyse(self, a, ok)
            else if (.not. covered(self, a)) then
                call map_or_analyse(self, a, ok)
            end if
        end if
    end procedure update_analysis

    !> The nonzeros of `a`'s lower triangle (diagonal always; an off-diagonal pair
    !> where either of a(i, j), a(j, i) is nonzero), CSC with 0-based rows: what the
    !> analysis orders.
    pure subroutine nonzero_pattern(self, a, lcol, lrow)
        class(supernodal_lu_t), intent(in) :: self
        type(csc_matrix_t), intent(in) :: a
        integer(c_int), allocatable, intent(out) :: lcol(:), lrow(:)
        integer :: i, j, p, q
        allocate (lcol(a%n + 1), lrow(size(a%rowind)))
        q = 0
        do j = 1, a%n
            lcol(j) = int(q, c_int)
            do p = a%colptr(j) + 1, a%colptr(j + 1)
                i = a%rowind(p) + 1
                if (i < j) cycle
                if (i /= j .and. a%values(p) == 0.0_dp .and. a%values(self%tpos(p)) == 0.0_dp) cycle
                q = q + 1
                lrow(q) = int(i - 1, c_int)
            end do
        end do
        lcol(a%n + 1) = int(q, c_int)
    end subroutine nonzero_pattern

    !> Whether `a`'s nonzeros are those the analysis was made for.
    pure logical function same_nonzeros(self, a)
        class(supernodal_lu_t), intent(in) :: self
        type(csc_matrix_t), intent(in) :: a
        integer(c_int), allocatable :: lcol(:), lrow(:)
        integer :: q
        same_nonzeros = .false.
        if (.not. (allocated(self%an_col) .and. allocated(self%an_row))) return
        call nonzero_pattern(self, a, lcol, lrow)
        if (size(lcol) /= size(self%an_col)) return
        if (any(lcol /= self%an_col)) return
        q = int(lcol(size(lcol)))
        if (q > size(self%an_row)) return
        same_nonzeros = all(lrow(:q) == self%an_row(:q))
    end function same_nonzeros

    !> Whether `a` has the CSC pattern the maps were made for.
    pure logical function same_csc(self, a)
        class(supernodal_lu_t), intent(in) :: self
        type(csc_matrix_t), intent(in) :: a
        same_csc = .false.
        if (.not. allocated(self%colptr) .or. self%n /= a%n) return
        if (size(self%rowind) /= size(a%rowind)) return
        if (any(self%colptr /= a%colptr)) return
        if (any(self%rowind /= a%rowind)) return
        same_csc = .true.
    end function same_csc

    !> The positions of `a`'s nonzeros in the analysed fronts, or (when one falls
    !> outside them) a new analysis.
    subroutine map_or_analyse(self, a, ok)
        class(supernodal_lu_t), intent(inout) :: self
        type(csc_matrix_t), intent(in) :: a
        logical, intent(out) :: ok
        integer, allocatable :: pos(:)
        allocate (pos(a%n), source=0)
        call entry_positions(self, a, pos, ok)
        if (ok) then
            self%n_mapped = self%n_mapped + 1
        else
            call analyse(self, a, ok)
        end if
    end subroutine map_or_analyse

    !> Take a new CSC pattern: its transpose map (the analysis, if any, is kept for
    !> `map_or_analyse`). A pattern that is not structurally symmetric is left to
    !> UMFPACK.
    subroutine take_pattern(self, a)
        class(supernodal_lu_t), intent(inout) :: self
        type(csc_matrix_t), intent(in) :: a
        integer, allocatable :: cursor(:)
        integer :: i, j, p
        if (a%n /= self%n) self%nsuper = 0
        self%n = a%n
        self%colptr = a%colptr
        self%rowind = a%rowind
        self%umfpack_only = .false.
        if (allocated(self%tpos)) deallocate (self%tpos)
        allocate (self%tpos(size(a%rowind)), cursor(a%n))
        cursor = a%colptr(1:a%n)
        do j = 1, a%n
            do p = a%colptr(j) + 1, a%colptr(j + 1)
                i = a%rowind(p) + 1
                cursor(i) = cursor(i) + 1
                if (cursor(i) > a%colptr(i + 1)) then
                    self%umfpack_only = .true.
                    return
                end if
                if (a%rowind(cursor(i)) /= j - 1) then
                    self%umfpack_only = .true.
                    return
                end if
                self%tpos(p) = cursor(i)
            end do
        end do
    end subroutine take_pattern

    !> Whether every nonzero of `a` lies in the analysed pattern.
    pure logical function covered(self, a)
        class(supernodal_lu_t), intent(in) :: self
        type(csc_matrix_t), intent(in) :: a
        integer :: p
        covered = .false.
        do p = 1, size(self%dest)
            if (self%dest(p) == 0 .and. a%values(p) /= 0.0_dp) return
        end do
        covered = .true.
    end function covered

    !> Analyse the nonzero pattern of `a` (with its transpose, and the diagonal): the
    !> ordering and supernodes (CHOLMOD), then the fronts' maps. `ok` false: CHOLMOD
    !> failed or the fronts are too large (UMFPACK then takes every matrix of this pattern).
    subroutine analyse(self, a, ok)
        class(supernodal_lu_t), intent(inout) :: self
        type(csc_matrix_t), intent(in) :: a
        logical, intent(out) :: ok
        integer(c_int), allocatable :: lcol(:), lrow(:)
        type(c_ptr) :: handle
        integer(c_int) :: ns, nr, status
        integer :: j
        integer(i8) :: storage

        call nonzero_pattern(self, a, lcol, lrow)
        self%an_col = lcol
        self%an_row = lrow
        handle = c_null_ptr
        status = voiga_supernodal_analyze(int(a%n, c_int), lcol, lrow, handle, ns, nr)
        ok = status == 0
        if (.not. ok) then
            self%umfpack_only = .true.
            return
        end if
        self%nsuper = ns
        if (allocated(self%perm)) deallocate (self%perm, self%super, self%rptr, self%rows)
        allocate (self%perm(a%n), self%super(ns + 1), self%rptr(ns + 1), self%rows(nr))
        call voiga_supernodal_copy(handle, self%perm, self%super, self%rptr, self%rows)
        call voiga_supernodal_free(handle)
        self%perm = self%perm + 1
        self%super = self%super + 1
        self%rptr = self%rptr + 1
        self%rows = self%rows + 1
        storage = 0
        do j = 1, ns
            storage = storage + int(self%rptr(j + 1) - self%rptr(j), i8)**2
        end do
        ok = storage <= max_front_storage
        if (ok) call front_maps(self, a, ok)
        if (.not. ok) then
            self%nsuper = 0
            self%umfpack_only = .true.
            return
        end if
        self%n_symbolic = self%n_symbolic + 1
    end subroutine analyse

    !> From the supernodes: each one's parent, the positions of its update rows in
    !> the parent's front, the fronts' offsets, and the position of every analysed
    !> entry of `a` in a front. `ok` false if the structure does not hold an entry.
    subroutine front_maps(self, a, ok)
        class(supernodal_lu_t), intent(inout) :: self
        type(csc_matrix_t), intent(in) :: a
        logical, intent(out) :: ok
        integer, allocatable :: owner(:), pos(:)
        integer :: s, m, k, r0, par, i

        ok = .false.
        allocate (owner(a%n), pos(a%n), source=0)
        do s = 1, self%nsuper
            owner(self%super(s):self%super(s + 1) - 1) = s
        end do
        if (allocated(self%parent)) deallocate (self%parent, self%rel, self%fptr)
        allocate (self%parent(self%nsuper), self%rel(size(self%rows)), self%fptr(self%nsuper + 1))
        self%rel = 0
        self%fptr(1) = 1
        do s = 1, self%nsuper
            r0 = self%rptr(s)
            m = self%rptr(s + 1) - r0
            k = self%super(s + 1) - self%super(s)
            self%fptr(s + 1) = self%fptr(s) + m*k + k*(m - k)
            self%parent(s) = 0
            if (m == k) cycle
            par = owner(self%rows(r0 + k))
            self%parent(s) = par
            do i = self%rptr(par), self%rptr(par + 1) - 1
                pos(self%rows(i)) = i - self%rptr(par) + 1
            end do
            do i = r0 + k, r0 + m - 1
                self%rel(i) = pos(self%rows(i))
                if (self%rel(i) == 0) return
            end do
            pos(self%rows(self%rptr(par):self%rptr(par + 1) - 1)) = 0
        end do
        call children(self)
        call update_offsets(self)
        call entry_positions(self, a, pos, ok)
        if (.not. ok) return
        if (allocated(self%f)) deallocate (self%f)
        allocate (self%f(self%fptr(self%nsuper + 1) - 1))
        if (allocated(self%ipiv)) deallocate (self%ipiv, self%runs, self%scale, self%rscale, self%y, self%w)
        allocate (self%ipiv(a%n), self%runs(a%n + 1), self%scale(a%n), self%rscale(a%n), self%y(a%n), &
                  self%w(a%n))
    end subroutine front_maps

    !> The update blocks' places in the pool (uoff, upool): supernodes are in
    !> postorder, so when a front is assembled its children's blocks are the top of
    !> the stack of their depth's parity; its own block goes on the other stack.
    !> Should the tree not be in postorder, every block gets its own place.
    subroutine update_offsets(self)
        class(supernodal_lu_t), intent(inout) :: self
        integer :: parity(self%nsuper), size_of(self%nsuper)
        integer :: top(0:1), peak(0:1), s, p, low, held
        logical :: stacked
        if (allocated(self%uoff)) deallocate (self%uoff)
        allocate (self%uoff(self%nsuper))
        do s = 1, self%nsuper
            size_of(s) = (self%rptr(s + 1) - self%rptr(s) - self%super(s + 1) + self%super(s))**2
        end do
        stacked = all(self%parent == 0 .or. self%parent > [(s, s=1, self%nsuper)])
        parity = 0
        do s = self%nsuper, 1, -1
            if (self%parent(s) > 0) parity(s) = 1 - parity(self%parent(s))
        end do
        top = 0
        peak = 0
        do s = 1, self%nsuper
            p = parity(s)
            self%uoff(s) = top(p)
            top(p) = top(p) + size_of(s)
            peak(p) = max(peak(p), top(p))
            if (self%cptr(s + 1) == self%cptr(s)) cycle
            ! the children's blocks, read by this front's assembly, are then free
            low = minval(self%uoff(self%kids(self%cptr(s):self%cptr(s + 1) - 1)))
            held = sum(size_of(self%kids(self%cptr(s):self%cptr(s + 1) - 1)))
            if (top(1 - p) - low /= held) stacked = .false.
            top(1 - p) = low
        end do
        if (stacked) then
            do s = 1, self%nsuper
                self%uoff(s) = self%uoff(s) + 1 + merge(0, peak(0), parity(s) == 0)
            end do
        else
            self%uoff(1) = 1
            do s = 2, self%nsuper
                self%uoff(s) = self%uoff(s - 1) + size_of(s - 1)
            end do
            peak = [sum(size_of), 0]
        end if
        where (size_of == 0) self%uoff = 1
        if (allocated(self%upool)) deallocate (self%upool)
        allocate (self%upool(max(1, peak(0) + peak(1))))
    end subroutine update_offsets

    !> The children of every supernode (cptr, kids; ascending), from the parents.
    pure subroutine children(self)
        class(supernodal_lu_t), intent(inout) :: self
        integer :: s, par
        integer :: next(self%nsuper)
        if (allocated(self%cptr)) deallocate (self%cptr, self%kids)
        allocate (self%cptr(self%nsuper + 1), self%kids(count(self%parent > 0)))
        next = 0
        do s = 1, self%nsuper
            if (self%parent(s) > 0) next(self%parent(s)) = next(self%parent(s)) + 1
        end do
        self%cptr(1) = 1
        do s = 1, self%nsuper
            self%cptr(s + 1) = self%cptr(s) + next(s)
        end do
        next = self%cptr(1:self%nsuper)
        do s = 1, self%nsuper
            par = self%parent(s)
            if (par == 0) cycle
            self%kids(next(par)) = s
            next(par) = next(par) + 1
        end do
    end subroutine children

    !> dest: where each analysed entry of `a` goes in the fronts (entry (i, j), new
    !> indices pi, pj, belongs to the front of the supernode of min(pi, pj)), and
    !> the entries of each front (aptr, apos); `pos` is a zero work array [n], left zero.
    subroutine entry_positions(self, a, pos, ok)
        class(supernodal_lu_t), intent(inout) :: self
        type(csc_matrix_t), intent(in) :: a
        integer, intent(inout) :: pos(:)
        logical, intent(out) :: ok
        integer, allocatable :: iperm(:)
        integer :: s, c, j, p, i, pi, r, m, k, f0, base, q

        ok = .false.
        q = 0
        allocate (iperm(a%n))
        iperm(self%perm) = [(c, c=1, a%n)]
        if (allocated(self%dest)) deallocate (self%dest, self%aptr, self%apos)
        allocate (self%dest(size(a%rowind)), self%apos(size(a%rowind)), self%aptr(self%nsuper + 1))
        self%dest = 0
        self%aptr(1) = 1
        do s = 1, self%nsuper
            f0 = self%super(s)
            m = self%rptr(s + 1) - self%rptr(s)
            k = self%super(s + 1) - f0
            base = self%fptr(s)
            do r = 1, m
                pos(self%rows(self%rptr(s) + r - 1)) = r
            end do
            do c = f0, self%super(s + 1) - 1
                j = self%perm(c)
                do p = a%colptr(j) + 1, a%colptr(j + 1)
                    i = a%rowind(p) + 1
                    if (i /= j .and. a%values(p) == 0.0_dp .and. a%values(self%tpos(p)) == 0.0_dp) cycle
                    pi = iperm(i)
                    if (pi < c) cycle
                    r = pos(pi)
                    if (r == 0) then
                        pos(self%rows(self%rptr(s):self%rptr(s + 1) - 1)) = 0
                        return
                    end if
                    ! F(r, c - f0 + 1) and, above the diagonal, F(c - f0 + 1, r): in
                    ! the front's first k columns, or for r > k in U12
                    self%dest(p) = base + (c - f0)*m + r - 1
                    q = q + 1
                    self%apos(q) = p
                    if (pi /= c) then
                        if (r <= k) then
                            self%dest(self%tpos(p)) = base + (r - 1)*m + c - f0
                        else
                            self%dest(self%tpos(p)) = base + m*k + (r - k - 1)*k + c - f0
                        end if
                        q = q + 1
                        self%apos(q) = self%tpos(p)
                    end if
                end do
            end do
            pos(self%rows(self%rptr(s):self%rptr(s + 1) - 1)) = 0
            self%aptr(s + 1) = q + 1
        end do
        ok = .true.
    end subroutine entry_positions

end submodule voiga_solver_supernodal_analysis
