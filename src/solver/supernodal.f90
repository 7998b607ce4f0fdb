!> Sparse LU of the tangent by supernodes, for the small finite-strain systems where
!> UMFPACK's per-factorization bookkeeping costs more than its arithmetic.
!>
!> On ironing m3 NN2.2 (1,228 DOFs) a numeric UMFPACK factorization took 4.7-5 ms
!> for 7 Mflop (docs/performance.md): assembling fronts, searching pivots and
!> storing L and U, not the dense kernels. Here everything that depends on the
!> pattern is done once per pattern, and a factorization is three loops:
!>
!> - **Analysis** (again only when a nonzero falls outside the analysed fronts: a
!>   new pattern of `a` or new nonzeros are first mapped into the fronts there are):
!>   the pattern is that of the entries that are nonzero in `a` or its transpose
!>   (the Dirichlet DOFs' eliminated couplings and the contact blocks no slave point
!>   uses are left out: half the flops on ironing m3), ordered by AMD with CHOLMOD's
!>   symbolic supernodal factorization (`supernodal_shim.c`). Each supernode's dense
!>   front, the position of every entry of `a` in a front and of every row of a
!>   front in its parent's front are computed then.
!> - **Factorization** (multifrontal): the entries of `a`, rows scaled by their sums
!>   of absolute values (UMFPACK's default scaling), are written into the fronts;
!>   each front eliminates its own columns with pivots chosen inside its diagonal
!>   block (the diagonal while it is at least `prefer_diagonal` of the block
!>   column's largest entry), forms its U rows, updates its
!>   remainder with one `dgemm` and adds it to its parent's front.
!> - **Fallback**: a multiplier above `max_multiplier` (a pivot the block cannot
!>   make stable), a zero pivot, or a pattern this type does not take (not
!>   structurally symmetric, fronts above `max_front_storage`) hands the matrix to
!>   UMFPACK, which pivots freely; its solves and determinant are then UMFPACK's.
!>
!> Solves refine iteratively, as UMFPACK's, only when the reciprocal condition
!> estimate min |u_jj| / max |u_jj| (of the scaled matrix) is below 1e-3.
module voiga_solver_supernodal
    use, intrinsic :: iso_c_binding, only: c_int, c_ptr, c_null_ptr
    use voiga_kinds, only: dp, i8
    use voiga_error, only: error_t, fatal_error
    use voiga_text, only: str
    use voiga_solver_sparse, only: csc_matrix_t, consecutive_runs
    use voiga_solver_linear, only: linear_solver_t, solve_accuracy_t
    use voiga_solver_umfpack, only: umfpack_t
    use voiga_linalg_blas, only: dgemm, dtrsm
    implicit none
    private

    public :: supernodal_lu_t

    !> A diagonal pivot is kept while it is at least this fraction of the largest
    !> entry of its column inside the supernode's diagonal block.
    real(dp), parameter :: prefer_diagonal = 0.1_dp
    !> A multiplier (entry of L) larger than this means a pivot too small for its
    !> column outside the block: UMFPACK factorizes that matrix instead.
    real(dp), parameter :: max_multiplier = 1.0e3_dp
    !> Solves refine iteratively (at most `max_refine` steps) below this rcond, as
    !> `umfpack_t` does.
    real(dp), parameter :: refine_below_rcond = 1.0e-3_dp
    integer, parameter :: max_refine = 2
    !> Most reals all fronts together may hold (128 MiB); larger systems keep UMFPACK.
    integer(i8), parameter :: max_front_storage = 16777216_i8
    !> Supernodes of at least this many columns are factorized with LAPACK and BLAS 3
    !> (`blocked_factor`); smaller ones by loops, cheaper than the calls there.
    integer, parameter :: blas_from = 24

    !> Supernodal LU with pivots inside supernodes and UMFPACK as its fallback.
    type, extends(linear_solver_t) :: supernodal_lu_t
        !> Analyses, numeric factorizations (this type's and UMFPACK's), of these the
        !> factorizations left to UMFPACK, and the new patterns or nonzeros that the
        !> analysed supernodes took without a new analysis (read only).
        integer :: n_symbolic = 0, n_numeric = 0, n_fallback = 0, n_mapped = 0
        !> Reciprocal condition estimate of the last factorization (read only).
        real(dp) :: rcond = 0.0_dp
        type(umfpack_t), private :: umfpack
        !> The last factorization is UMFPACK's; every one is (the pattern is not taken).
        logical, private :: on_umfpack = .false., umfpack_only = .false.
        logical, private :: factored = .false.
        !> The next factorization keeps the analysis only for the same nonzeros
        !> (`renew_analysis`); the nonzeros analysed (lower triangle, CSC, 0-based).
        logical, private :: renew = .false.
        integer(c_int), allocatable, private :: an_col(:), an_row(:)
        !> The CSC pattern the maps were made for, and the position of each entry's
        !> transpose in it (1-based) [nnz].
        integer, private :: n = 0
        integer(c_int), allocatable, private :: colptr(:), rowind(:)
        integer, allocatable, private :: tpos(:)
        !> The analysis: supernodes, perm [n] (perm(c): the DOF eliminated c-th),
        !> super [nsuper+1] (first column of each), rptr [nsuper+1] and rows (row
        !> structure, new indices, own columns first), parent [nsuper] (0: a root),
        !> rel (aligned with rows: position of an update row in the parent's front),
        !> fptr [nsuper+1] (start of each front in f), dest [nnz] (position of each
        !> entry of `a` in the fronts, 0: outside the analysed pattern).
        integer, private :: nsuper = 0
        integer, allocatable, private :: perm(:), super(:), rptr(:), rows(:), parent(:), rel(:), fptr(:), &
                                         dest(:)
        !> Each supernode's children (cptr [nsuper+1], kids) and the entries of `a` that
        !> go into its front (aptr [nsuper+1], apos: positions in `a`), so that a front
        !> is zeroed, filled and factorized while it is in cache.
        integer, allocatable, private :: cptr(:), kids(:), aptr(:), apos(:)
        !> The fronts' L and U parts (front s at fptr(s): its first k columns [m, k],
        !> then U12, the rest of its first k rows [k, m - k]; after a factorization:
        !> L and U), the row scale factors and their reciprocals [n], a solve's work
        !> vectors [n].
        real(dp), allocatable, private :: f(:), scale(:), rscale(:), y(:), w(:)
        !> The fronts' update blocks [(m - k) x (m - k)], each at uoff(s) in `upool`,
        !> alive from its front's elimination to its parent's assembly: two stacks,
        !> one for the supernodes at even depths of the tree and one for the odd, so
        !> that a front's block and its children's never overlap and the pool stays
        !> small (in cache) where all the update blocks in `f` were not.
        integer, allocatable, private :: uoff(:)
        real(dp), allocatable, private :: upool(:)
        !> The local pivot rows [n]; work of the extend-adds [n + 1].
        integer, allocatable, private :: ipiv(:), runs(:)
        integer, private :: det_sign = 0
        real(dp), private :: det_log10 = 0.0_dp
    contains
        procedure :: factor => sn_factor
        procedure :: solve => sn_solve
        procedure :: determinant => sn_determinant
        procedure :: has_determinant => sn_has_determinant
        procedure :: factorizations => sn_factorizations
        procedure :: renew_analysis => sn_renew_analysis
    end type supernodal_lu_t

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

        pure subroutine dgetrf(m, n, a, lda, ipiv, info)
            import :: dp
            integer, intent(in) :: m, n, lda
            real(dp), intent(inout) :: a(lda, *)
            integer, intent(out) :: ipiv(*), info
        end subroutine dgetrf

        pure subroutine dlaswp(n, a, lda, k1, k2, ipiv, incx)
            import :: dp
            integer, intent(in) :: n, lda, k1, k2, incx
            real(dp), intent(inout) :: a(lda, *)
            integer, intent(in) :: ipiv(*)
        end subroutine dlaswp

    end interface

contains

    !> Factorize `a`: analysis when its pattern or its nonzero pattern is new, then
    !> the supernodal factorization, or UMFPACK's where that is not stable.
    subroutine sn_factor(self, a, error)
        class(supernodal_lu_t), intent(inout) :: self
        type(csc_matrix_t), intent(in) :: a
        type(error_t), allocatable, intent(out) :: error
        logical :: ok, new_pattern

        self%factored = .false.
        if (a%n < 1 .or. .not. (allocated(a%colptr) .and. allocated(a%rowind) .and. allocated(a%values))) then
            call fatal_error(error, 'supernodal factorize: matrix has no pattern (build it with new_csc_pattern)')
            return
        end if
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
        if (ok) call numeric(self, a, ok)
        self%on_umfpack = .not. ok
        if (ok) then
            call diagonal_summary(self)
        else
            if (.not. self%umfpack_only) self%n_fallback = self%n_fallback + 1
            call self%umfpack%factor(a, error)
            if (allocated(error)) return
            self%rcond = self%umfpack%rcond
        end if
        self%n_numeric = self%n_numeric + 1
        self%factored = .true.
    end subroutine sn_factor

    !> Keep the analysis at the next factorization only if it was made for the same
    !> nonzeros: the analysis kept otherwise depends on the nonzeros of the matrices
    !> before (a stick predictor's, contact states of earlier steps), while a
    !> restarted run analyses the matrix it starts with; called at the start of each
    !> substep, it makes the order of elimination, and so the round-off, depend on
    !> that substep's matrix only, and a restart reproduces the run bit for bit.
    pure subroutine sn_renew_analysis(self)
        class(supernodal_lu_t), intent(inout) :: self
        self%renew = .true.
    end subroutine sn_renew_analysis

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

    !> The numeric factorization on the analysed structure; `ok` false when a pivot
    !> is zero or a multiplier exceeds `max_multiplier` (the caller hands the matrix
    !> to UMFPACK).
    subroutine numeric(self, a, ok)
        class(supernodal_lu_t), intent(inout) :: self
        type(csc_matrix_t), intent(in) :: a
        logical, intent(out) :: ok
        integer :: s, p, m, k, t, c, nc, u0, f0

        ! UMFPACK's default scaling: each row divided by the sum of its absolute values
        self%scale = 0.0_dp
        do p = 1, size(a%rowind)
            self%scale(a%rowind(p) + 1) = self%scale(a%rowind(p) + 1) + abs(a%values(p))
        end do
        where (self%scale == 0.0_dp) self%scale = 1.0_dp
        self%rscale = 1.0_dp/self%scale
        ! front by front (postorder): zero its L and U parts and its update block,
        ! write a's entries (all in the L and U parts), add the children's updates,
        ! eliminate
        do s = 1, self%nsuper
            m = self%rptr(s + 1) - self%rptr(s)
            k = self%super(s + 1) - self%super(s)
            u0 = self%uoff(s)
            f0 = self%fptr(s)
            self%f(f0:self%fptr(s + 1) - 1) = 0.0_dp
            self%upool(u0:u0 + (m - k)**2 - 1) = 0.0_dp
            do t = self%aptr(s), self%aptr(s + 1) - 1
                p = self%apos(t)
                self%f(self%dest(p)) = a%values(p)*self%rscale(a%rowind(p) + 1)
            end do
            do t = self%cptr(s), self%cptr(s + 1) - 1
                c = self%kids(t)
                nc = self%rptr(c + 1) - self%rptr(c) - self%super(c + 1) + self%super(c)
                call extend_add(self%f(f0:f0 + m*k - 1), self%f(f0 + m*k:self%fptr(s + 1) - 1), &
                                self%upool(u0:u0 + (m - k)**2 - 1), m, k, &
                                self%upool(self%uoff(c):self%uoff(c) + nc**2 - 1), nc, &
                                self%rel(self%rptr(c + 1) - nc:), self%runs)
            end do
            call partial_factor(self%f(f0:f0 + m*k - 1), self%f(f0 + m*k:self%fptr(s + 1) - 1), m, k, &
                                self%ipiv(self%super(s):), self%upool(u0:u0 + (m - k)**2 - 1), ok)
            if (.not. ok) return
        end do
    end subroutine numeric

    !> Eliminate the first k columns of an m x m front (its first k columns `fr`
    !> [m, k], the rest of its first k rows `u12` [k, m - k]): pivots from the
    !> diagonal block (row swaps inside it, recorded in `piv`), L below and U right
    !> of it, and the update block `upd` [m - k, m - k] (the front's remainder)
    !> updated to the Schur complement (one dgemm).
    subroutine partial_factor(fr, u12, m, k, piv, upd, ok)
        integer, intent(in) :: m, k
        real(dp), intent(inout) :: fr(m, k), u12(k, m - k)
        integer, intent(out) :: piv(k)
        real(dp), intent(inout) :: upd(m - k, m - k)
        logical, intent(out) :: ok
        real(dp) :: big, d, t
        integer :: j, i, c, p

        if (k >= blas_from) then
            call blocked_factor(fr, u12, m, k, piv, upd, ok)
            return
        end if
        ok = .false.
        do j = 1, k
            p = j
            big = abs(fr(j, j))
            do i = j + 1, k
                if (abs(fr(i, j)) > big) then
                    big = abs(fr(i, j))
                    p = i
                end if
            end do
            if (big == 0.0_dp) return
            if (abs(fr(j, j)) >= prefer_diagonal*big) p = j
            piv(j) = p
            if (p /= j) then
                do c = 1, k
                    t = fr(j, c)
                    fr(j, c) = fr(p, c)
                    fr(p, c) = t
                end do
                do c = 1, m - k
                    t = u12(j, c)
                    u12(j, c) = u12(p, c)
                    u12(p, c) = t
                end do
            end if
            d = 1.0_dp/fr(j, j)
            ! L's column and its largest multiplier in one pass
            big = 0.0_dp
            do i = j + 1, m
                fr(i, j) = fr(i, j)*d
                big = max(big, abs(fr(i, j)))
            end do
            if (big > max_multiplier) return
            do c = j + 1, k
                fr(j + 1:m, c) = fr(j + 1:m, c) - fr(j + 1:m, j)*fr(j, c)
            end do
        end do
        if (m > k) then
            ! U12 = L11^-1 F12 (its rows swapped with the block's) column by column (BLAS's
            ! dtrsm costs more than the flops at these sizes), then the Schur complement
            do c = 1, m - k
                do j = 1, k - 1
                    t = u12(j, c)
                    if (t /= 0.0_dp) u12(j + 1:k, c) = u12(j + 1:k, c) - fr(j + 1:k, j)*t
                end do
            end do
            call dgemm('N', 'N', m - k, m - k, k, -1.0_dp, fr(k + 1, 1), m, u12, k, 1.0_dp, upd, m - k)
        end if
        ok = .true.
    end subroutine partial_factor

    !> `partial_factor` of a supernode of `blas_from` columns or more, with LAPACK
    !> and BLAS 3: the diagonal block by dgetrf (partial pivoting inside it), its row
    !> swaps applied to U's part, L21 = F21 U11^-1 and U12 = L11^-1 F12 by dtrsm, the
    !> Schur complement by dgemm; `ok` false for a zero pivot or a multiplier of L21
    !> above `max_multiplier`.
    subroutine blocked_factor(fr, u12, m, k, piv, upd, ok)
        integer, intent(in) :: m, k
        real(dp), intent(inout) :: fr(m, k), u12(k, m - k)
        integer, intent(out) :: piv(k)
        real(dp), intent(inout) :: upd(m - k, m - k)
        logical, intent(out) :: ok
        integer :: info
        ok = .false.
        call dgetrf(k, k, fr, m, piv, info)
        if (info /= 0) return
        if (m > k) then
            call dlaswp(m - k, u12, k, 1, k, piv, 1)
            call dtrsm('R', 'U', 'N', 'N', m - k, k, 1.0_dp, fr, m, fr(k + 1, 1), m)
            if (maxval(abs(fr(k + 1:m, 1:k))) > max_multiplier) return
            call dtrsm('L', 'L', 'N', 'U', k, m - k, 1.0_dp, fr, m, u12, k)
            call dgemm('N', 'N', m - k, m - k, k, -1.0_dp, fr(k + 1, 1), m, u12, k, 1.0_dp, upd, m - k)
        end if
        ok = .true.
    end subroutine blocked_factor

    !> Add a child's update block `uc` [nc, nc] into its parent's front (kp pivots:
    !> its first kp columns `fp` [mp, kp], the rest of its first kp rows `fu`
    !> [kp, mp - kp], its update block `up` [mp - kp, mp - kp]) at the front
    !> positions `rel` [nc] (ascending: the rows 1..na land in the parent's pivot
    !> rows). The rows go in runs of consecutive positions (`runs` [nc + 1]: work),
    !> split at the pivot rows' end, each column of a run one vector add: the same
    !> additions as entry by entry.
    pure subroutine extend_add(fp, fu, up, mp, kp, uc, nc, rel, runs)
        integer, intent(in) :: mp, kp, nc
        real(dp), intent(inout) :: fp(mp, kp), fu(kp, mp - kp), up(mp - kp, mp - kp)
        real(dp), intent(in) :: uc(nc, nc)
        integer, intent(in) :: rel(nc)
        integer, intent(inout) :: runs(nc + 1)
        integer :: b, cb, na, n1, nr, t, r0, a0, len
        na = 0
        do while (na < nc)
            if (rel(na + 1) > kp) exit
            na = na + 1
        end do
        call consecutive_runs(rel(1:na), runs, n1)
        call consecutive_runs(rel(na + 1:nc), runs(n1 + 1:), nr)
        runs(n1 + 1:n1 + nr + 1) = runs(n1 + 1:n1 + nr + 1) + na
        nr = n1 + nr
        do b = 1, nc
            cb = rel(b)
            do t = 1, nr
                a0 = runs(t)
                len = runs(t + 1) - a0
                r0 = rel(a0)
                if (cb <= kp) then
                    fp(r0:r0 + len - 1, cb) = fp(r0:r0 + len - 1, cb) + uc(a0:a0 + len - 1, b)
                else if (t <= n1) then
                    fu(r0:r0 + len - 1, cb - kp) = fu(r0:r0 + len - 1, cb - kp) + uc(a0:a0 + len - 1, b)
                else
                    up(r0 - kp:r0 - kp + len - 1, cb - kp) = up(r0 - kp:r0 - kp + len - 1, cb - kp) + &
                                                             uc(a0:a0 + len - 1, b)
                end if
            end do
        end do
    end subroutine extend_add

    !> Sign and log10 |det| of the factorized matrix, and rcond = min |u_jj| / max |u_jj|.
    subroutine diagonal_summary(self)
        class(supernodal_lu_t), intent(inout) :: self
        real(dp) :: d, dmin, dmax
        integer :: s, j, m, f0, k
        self%det_sign = 1
        self%det_log10 = sum(log10(self%scale))
        dmin = huge(1.0_dp)
        dmax = 0.0_dp
        do s = 1, self%nsuper
            m = self%rptr(s + 1) - self%rptr(s)
            f0 = self%super(s)
            k = self%super(s + 1) - f0
            do j = 1, k
                d = self%f(self%fptr(s) + (j - 1)*m + j - 1)
                if (d < 0.0_dp) self%det_sign = -self%det_sign
                if (self%ipiv(f0 + j - 1) /= j) self%det_sign = -self%det_sign
                self%det_log10 = self%det_log10 + log10(abs(d))
                dmin = min(dmin, abs(d))
                dmax = max(dmax, abs(d))
            end do
        end do
        self%rcond = dmin/dmax
    end subroutine diagonal_summary

    !> Solve A x = b with the last factorization (`a`: the matrix factorized, used for
    !> iterative refinement when rcond < `refine_below_rcond`).
    subroutine sn_solve(self, a, b, x, error, accuracy)
        class(supernodal_lu_t), intent(inout) :: self
        type(csc_matrix_t), intent(in) :: a
        real(dp), intent(in) :: b(:)
        real(dp), intent(out) :: x(:)
        type(error_t), allocatable, intent(out) :: error
        !> Ignored: a direct solve is as accurate as the factorization.
        type(solve_accuracy_t), intent(in), optional :: accuracy
        if (.not. self%factored) then
            call fatal_error(error, 'supernodal solve: no factorization (factor was not called or failed)')
            return
        end if
        if (self%on_umfpack) then
            call self%umfpack%solve(a, b, x, error)
            return
        end if
        if (a%n /= self%n .or. size(b) /= self%n .or. size(x) /= self%n) then
            call fatal_error(error, 'supernodal solve: n = '//str(a%n)//', size(b) = '//str(size(b))// &
                             ', size(x) = '//str(size(x))//', factorized n = '//str(self%n))
            return
        end if
        call apply_inverse(self, b, x)
        if (self%rcond < refine_below_rcond) call refine(self, a, b, x)
    end subroutine sn_solve

    !> x = A^-1 b with the factors: permute and scale, forward with L (the
    !> supernodes' row swaps in their order), backward with U, permute back.
    subroutine apply_inverse(self, b, x)
        class(supernodal_lu_t), intent(inout) :: self
        real(dp), intent(in) :: b(:)
        real(dp), intent(out) :: x(:)
        integer :: s, c, m, k
        do c = 1, self%n
            self%y(c) = b(self%perm(c))*self%rscale(self%perm(c))
        end do
        do s = 1, self%nsuper
            call forward(self%f(self%fptr(s):), self%rptr(s + 1) - self%rptr(s), self%super(s + 1) - self%super(s), &
                         self%rows(self%rptr(s):), self%ipiv(self%super(s):), self%y, self%w)
        end do
        do s = self%nsuper, 1, -1
            m = self%rptr(s + 1) - self%rptr(s)
            k = self%super(s + 1) - self%super(s)
            call backward(self%f(self%fptr(s):), self%f(self%fptr(s) + m*k:), m, k, self%rows(self%rptr(s):), &
                          self%y, self%w)
        end do
        x(self%perm) = self%y
    end subroutine apply_inverse

    !> One supernode of the forward substitution: its row swaps, L's diagonal block,
    !> then its rows below the block, summed in `w` [m - k] and scattered once.
    pure subroutine forward(fr, m, k, rows, piv, y, w)
        integer, intent(in) :: m, k, rows(m), piv(k)
        real(dp), intent(in) :: fr(m, k)
        real(dp), intent(inout) :: y(:)
        real(dp), intent(out) :: w(:)
        real(dp) :: t
        integer :: j, i, f0
        f0 = rows(1)
        do j = 1, k
            if (piv(j) /= j) then
                t = y(f0 + j - 1)
                y(f0 + j - 1) = y(f0 + piv(j) - 1)
                y(f0 + piv(j) - 1) = t
            end if
        end do
        do j = 1, k - 1
            t = y(f0 + j - 1)
            if (t == 0.0_dp) cycle
            do i = j + 1, k
                y(f0 + i - 1) = y(f0 + i - 1) - fr(i, j)*t
            end do
        end do
        if (m == k) return
        w(1:m - k) = 0.0_dp
        do j = 1, k
            t = y(f0 + j - 1)
            if (t == 0.0_dp) cycle
            do i = k + 1, m
                w(i - k) = w(i - k) + fr(i, j)*t
            end do
        end do
        do i = k + 1, m
            y(rows(i)) = y(rows(i)) - w(i - k)
        end do
    end subroutine forward

    !> One supernode of the backward substitution: the rows of U right of the
    !> diagonal block against the solution gathered in `w` [m - k], then the block.
    pure subroutine backward(fr, fu, m, k, rows, y, w)
        integer, intent(in) :: m, k, rows(m)
        !> The front's first k columns [m, k] and the rest of its first k rows [k, m - k].
        real(dp), intent(in) :: fr(m, k), fu(k, m - k)
        real(dp), intent(inout) :: y(:)
        real(dp), intent(out) :: w(:)
        real(dp) :: t
        integer :: j, c, f0
        f0 = rows(1)
        do c = k + 1, m
            w(c - k) = y(rows(c))
        end do
        do c = k + 1, m
            t = w(c - k)
            if (t == 0.0_dp) cycle
            do j = 1, k
                y(f0 + j - 1) = y(f0 + j - 1) - fu(j, c - k)*t
            end do
        end do
        do j = k, 1, -1
            t = y(f0 + j - 1)
            do c = j + 1, k
                t = t - fr(j, c)*y(f0 + c - 1)
            end do
            y(f0 + j - 1) = t/fr(j, j)
        end do
    end subroutine backward

    !> Iterative refinement as UMFPACK's: x += A^-1 (b - A x) while the backward
    !> error max_i |b - A x|_i / (|A| |x| + |b|)_i exceeds the rounding unit and at
    !> least halves, at most `max_refine` times.
    subroutine refine(self, a, b, x)
        class(supernodal_lu_t), intent(inout) :: self
        type(csc_matrix_t), intent(in) :: a
        real(dp), intent(in) :: b(:)
        real(dp), intent(inout) :: x(:)
        real(dp) :: r(size(b)), w(size(b)), dx(size(b)), x_last(size(b))
        real(dp) :: omega, omega_last
        integer :: step, j, p, i
        omega_last = huge(1.0_dp)
        do step = 0, max_refine
            r = b
            w = abs(b)
            do j = 1, a%n
                do p = a%colptr(j) + 1, a%colptr(j + 1)
                    i = a%rowind(p) + 1
                    r(i) = r(i) - a%values(p)*x(j)
                    w(i) = w(i) + abs(a%values(p)*x(j))
                end do
            end do
            omega = maxval(abs(r)/max(w, tiny(1.0_dp)))
            if (omega > 0.5_dp*omega_last) then
                x = x_last
                return
            end if
            if (omega <= epsilon(1.0_dp) .or. step == max_refine) return
            omega_last = omega
            x_last = x
            call apply_inverse(self, r, dx)
            x = x + dx
        end do
    end subroutine refine

    !> det(A) = sign x 10**log10_abs of the last factorization.
    subroutine sn_determinant(self, sign, log10_abs, error)
        class(supernodal_lu_t), intent(in) :: self
        integer, intent(out) :: sign
        real(dp), intent(out) :: log10_abs
        type(error_t), allocatable, intent(out) :: error
        sign = 0
        log10_abs = -huge(1.0_dp)
        if (.not. self%factored) then
            call fatal_error(error, 'supernodal determinant: no factorization')
            return
        end if
        if (self%on_umfpack) then
            call self%umfpack%determinant(sign, log10_abs, error)
            return
        end if
        sign = self%det_sign
        log10_abs = self%det_log10
    end subroutine sn_determinant

    pure logical function sn_has_determinant(self)
        class(supernodal_lu_t), intent(in) :: self
        sn_has_determinant = .true.
    end function sn_has_determinant

    !> Analyses (this type's and UMFPACK's) and numeric factorizations so far.
    pure subroutine sn_factorizations(self, symbolic, numeric)
        class(supernodal_lu_t), intent(in) :: self
        integer, intent(out) :: symbolic, numeric
        symbolic = self%n_symbolic + self%umfpack%n_symbolic
        numeric = self%n_numeric
    end subroutine sn_factorizations

end module voiga_solver_supernodal
