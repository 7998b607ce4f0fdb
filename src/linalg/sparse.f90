!> Compressed-sparse-column (CSC) matrices for the global stiffness.
!>
!> The pattern is built once from the element connectivity (`new_csc_pattern`) and
!> kept for the whole simulation; each Newton iteration only zeroes and refills the
!> values. The arrays are stored exactly as UMFPACK wants them (0-based `c_int`
!> column pointers and row indices, rows sorted within each column), so a solve
!> converts nothing. The pattern is structurally symmetric and always holds the
!> full diagonal.
module voiga_linalg_sparse
    use, intrinsic :: iso_c_binding, only: c_int, c_double
    use voiga_kinds, only: dp, i8
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_text, only: str
    implicit none
    private

    !> The pattern buffer's first size is at most this many entries per block entry
    !> (`collect_columns`).
    integer(i8), parameter :: guess_cap = 64_i8

    public :: csc_matrix_t, new_csc_pattern, pattern_positions, position_cache_t, consecutive_runs

    !> The positions in `values` of the last element `add_cached` was given (its
    !> DOFs and their entries' positions), for a caller that adds many element
    !> matrices on the same DOFs in a row (the contact points of a slave element
    !> that project onto the same master span). Valid for one pattern: a caller
    !> keeps it only while the pattern does not change.
    type :: position_cache_t
        integer, allocatable :: dofs(:), pos(:, :)
    end type position_cache_t

    !> A square n x n matrix in compressed-sparse-column form (0-based indices).
    type :: csc_matrix_t
        !> Number of rows and columns.
        integer :: n = 0
        !> Start of each column in `rowind`/`values`, 0-based; shape: [n+1],
        !> `colptr(1) = 0`, `colptr(n+1) = nnz`.
        integer(c_int), allocatable :: colptr(:)
        !> Row of each stored entry, 0-based, ascending within a column; shape: [nnz].
        integer(c_int), allocatable :: rowind(:)
        !> Value of each stored entry; shape: [nnz].
        real(c_double), allocatable :: values(:)
        !> Number of (row, column) pairs that `add_element`/`element_positions` were
        !> asked for but that are not in the pattern (or outside 1..n). Always 0 in a
        !> correct program: assembly code and tests check it, nothing resets it.
        integer :: missed = 0
    contains
        !> Set every stored value to zero, keeping the pattern.
        procedure :: zero => csc_zero
        !> Scatter-add an element matrix by global DOF numbers.
        procedure :: add_element => csc_add_element
        !> Scatter-add an element matrix, reusing the positions of the last one
        !> when it has the same DOFs (`position_cache_t`).
        procedure :: add_cached => csc_add_cached
        !> Index into `values` of every (row, column) pair of an element, to cache.
        procedure :: element_positions => csc_element_positions
        !> Scatter-add an element matrix through cached positions.
        procedure :: add_at => csc_add_at
        !> Index into `values` of one entry (1-based row and column), 0 if not stored.
        procedure :: index_of => csc_index_of
        !> y = A x.
        procedure :: matvec => csc_matvec
        !> Number of stored entries.
        procedure :: nnz => csc_nnz
        !> Symmetric elimination of Dirichlet DOFs.
        procedure :: fix_dofs => csc_fix_dofs
    end type csc_matrix_t

contains

    !> The runs of consecutive integers in `v` (entries v(i) = v(i - 1) + 1 continue a
    !> run): run t is v(runs(t):runs(t + 1) - 1), `nr` runs (`runs`: at least nr + 1
    !> entries; size(v) + 1 always do). Consecutive row numbers of a CSC column, or
    !> consecutive positions, are contiguous values: a run is one vector operation.
    pure subroutine consecutive_runs(v, runs, nr)
        integer, intent(in) :: v(:)
        integer, intent(inout) :: runs(:)
        integer, intent(out) :: nr
        integer :: a
        nr = 0
        do a = 1, size(v)
            if (a > 1) then
                if (v(a) == v(a - 1) + 1) cycle
            end if
            nr = nr + 1
            runs(nr) = a
        end do
        runs(nr + 1) = size(v) + 1
    end subroutine consecutive_runs

    !> Build the sparsity pattern (values all zero) of an n x n matrix assembled
    !> from elements: element `e` couples every DOF of
    !> `elem_dofs(elem_ptr(e) : elem_ptr(e+1)-1)` with every other one (1-based;
    !> entries <= 0 are ignored, so constrained or absent DOFs can stay in the
    !> lists). The diagonal is always stored for every DOF 1..n, so DOFs that no
    !> element touches, or that `fix_dofs` eliminates, keep a nonsingular matrix.
    !>
    !> Cost: O(sum over elements of size^2) time and O(n + nnz + size(elem_dofs))
    !> memory; no dense n x n work array. Each column is collected with a marker
    !> array through a DOF-to-element map, then one counting-sort transpose of the
    !> (structurally symmetric) pattern sorts every column at O(nnz).
    subroutine new_csc_pattern(self, n, elem_ptr, elem_dofs, error)
        !> The new matrix.
        type(csc_matrix_t), intent(out) :: self
        !> Number of DOFs (rows and columns), >= 0.
        integer, intent(in) :: n
        !> Start of each element's DOFs in `elem_dofs`, 1-based; shape: [nelem+1],
        !> `elem_ptr(1) = 1`, non-decreasing.
        integer, intent(in) :: elem_ptr(:)
        !> Global DOF numbers of all elements, concatenated (1..n; <= 0 ignored);
        !> shape: [elem_ptr(nelem+1) - 1] or longer.
        integer, intent(in) :: elem_dofs(:)
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: dof_ptr(:), dof_elems(:), rows(:)
        integer(i8) :: sumsq
        integer :: st

        call check_element_lists(n, elem_ptr, elem_dofs, error)
        if (allocated(error)) return
        call dof_element_map(n, elem_ptr, elem_dofs, dof_ptr, dof_elems, sumsq)
        allocate (self%colptr(n + 1))
        call collect_columns(n, elem_ptr, elem_dofs, dof_ptr, dof_elems, sumsq, self%colptr, rows, &
                             error)
        if (allocated(error)) return
        deallocate (dof_elems, dof_ptr)
        call sort_columns(n, self%colptr, rows, self%rowind)
        allocate (self%values(size(self%rowind)), source=0.0_c_double, stat=st)
        if (st /= 0) then
            call fatal_error(error, 'out of memory: the stiffness matrix needs '// &
                             str(size(self%rowind)/131072)//' MB')
            return
        end if
        self%n = n
        self%missed = 0
    end subroutine new_csc_pattern

    !> The checks of `new_csc_pattern` on its arguments (see there).
    subroutine check_element_lists(n, elem_ptr, elem_dofs, error)
        integer, intent(in) :: n, elem_ptr(:), elem_dofs(:)
        type(error_t), allocatable, intent(out) :: error
        integer :: nelem, e, last

        if (n < 0) then
            call fatal_error(error, 'new_csc_pattern: negative number of DOFs n = '//str(n))
            return
        end if
        nelem = size(elem_ptr) - 1
        if (nelem < 0) then
            call fatal_error(error, 'new_csc_pattern: elem_ptr is empty (needs nelem+1 entries)')
            return
        end if
        if (elem_ptr(1) /= 1) then
            call fatal_error(error, 'new_csc_pattern: elem_ptr(1) must be 1')
            return
        end if
        do e = 1, nelem
            if (elem_ptr(e + 1) < elem_ptr(e)) then
                call fatal_error(error, 'new_csc_pattern: elem_ptr decreases at element '//str(e))
                return
            end if
        end do
        last = elem_ptr(nelem + 1) - 1
        if (last > size(elem_dofs)) then
            call fatal_error(error, 'new_csc_pattern: elem_ptr ends at '//str(last)//' but elem_dofs has '// &
                             str(size(elem_dofs)))
            return
        end if
        if (last > 0) then
            if (maxval(elem_dofs(1:last)) > n) then
                call fatal_error(error, 'new_csc_pattern: DOF '//str(maxval(elem_dofs(1:last)))// &
                                 ' exceeds n = '//str(n))
                return
            end if
        end if
    end subroutine check_element_lists

    !> The elements touching each DOF, in CSR form: those of DOF d are
    !> `dof_elems(dof_ptr(d) : dof_ptr(d+1)-1)` (shapes: [n+1], [number of entries > 0
    !> in the element lists]); `sumsq` is the sum over elements of (DOFs > 0)^2.
    pure subroutine dof_element_map(n, elem_ptr, elem_dofs, dof_ptr, dof_elems, sumsq)
        integer, intent(in) :: n, elem_ptr(:), elem_dofs(:)
        integer, allocatable, intent(out) :: dof_ptr(:), dof_elems(:)
        integer(i8), intent(out) :: sumsq
        integer, allocatable :: next(:)
        integer :: e, q, d, k

        allocate (dof_ptr(n + 1), source=0)
        sumsq = 0
        do e = 1, size(elem_ptr) - 1
            k = 0
            do q = elem_ptr(e), elem_ptr(e + 1) - 1
                d = elem_dofs(q)
                if (d > 0) then
                    dof_ptr(d + 1) = dof_ptr(d + 1) + 1
                    k = k + 1
                end if
            end do
            sumsq = sumsq + int(k, i8)*int(k, i8)
        end do
        dof_ptr(1) = 1
        do d = 1, n
            dof_ptr(d + 1) = dof_ptr(d + 1) + dof_ptr(d)
        end do
        allocate (dof_elems(dof_ptr(n + 1) - 1))
        allocate (next(n))
        next = dof_ptr(1:n)
        do e = 1, size(elem_ptr) - 1
            do q = elem_ptr(e), elem_ptr(e + 1) - 1
                d = elem_dofs(q)
                if (d > 0) then
                    dof_elems(next(d)) = e
                    next(d) = next(d) + 1
                end if
            end do
        end do
    end subroutine dof_element_map

    !> The rows of every column, unsorted: column j (the diagonal first, then the DOFs
    !> of the elements touching j, each once by a marker) is
    !> `rows(colptr(j)+1 : colptr(j+1))`. Element overlaps make sum(size^2) a few
    !> times nnz, hence the initial guess of the buffer size; it grows when needed.
    !> Dense contact blocks that overlap much more (a mortar node's block on a face
    !> holds every DOF its weighted gap sees, and its neighbours' nearly the same)
    !> would make that guess many times nnz: it is capped at `guess_cap` entries per
    !> block entry.
    subroutine collect_columns(n, elem_ptr, elem_dofs, dof_ptr, dof_elems, sumsq, colptr, rows, &
                               error)
        integer, intent(in) :: n, elem_ptr(:), elem_dofs(:), dof_ptr(:), dof_elems(:)
        integer(i8), intent(in) :: sumsq
        !> 0-based column starts; shape: [n+1]
        integer(c_int), intent(out) :: colptr(:)
        !> 1-based rows; shape: [colptr(n+1)] or longer
        integer, allocatable, intent(out) :: rows(:)
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: mark(:), rows_new(:)
        integer :: e, q, p, i, j, st
        integer(i8) :: top, cap, bound

        cap = max(int(n, i8) + min(sumsq/3, guess_cap*size(elem_dofs, kind=i8)), 16_i8)
        allocate (rows(cap), stat=st)
        if (st /= 0) then
            call fatal_error(error, 'out of memory: the stiffness pattern needs '//str(int(cap/262144))//' MB')
            return
        end if
        allocate (mark(n), source=0)
        top = 0
        colptr(1) = 0
        do j = 1, n
            bound = 1
            do p = dof_ptr(j), dof_ptr(j + 1) - 1
                e = dof_elems(p)
                bound = bound + (elem_ptr(e + 1) - elem_ptr(e))
            end do
            if (top + bound > cap) then
                cap = max(cap + cap/2, top + bound)
                allocate (rows_new(cap), stat=st)
                if (st /= 0) then
                    call fatal_error(error, 'out of memory: the stiffness pattern needs '// &
                                     str(int(cap/262144))//' MB')
                    return
                end if
                rows_new(1:top) = rows(1:top)
                call move_alloc(rows_new, rows)
            end if
            top = top + 1
            rows(top) = j
            mark(j) = j
            do p = dof_ptr(j), dof_ptr(j + 1) - 1
                e = dof_elems(p)
                do q = elem_ptr(e), elem_ptr(e + 1) - 1
                    i = elem_dofs(q)
                    if (i <= 0) cycle
                    if (mark(i) == j) cycle
                    mark(i) = j
                    top = top + 1
                    rows(top) = i
                end do
            end do
            if (top > int(huge(0_c_int), i8)) then
                call fatal_error(error, 'new_csc_pattern: more than huge(c_int) stored '// &
                                 'entries; UMFPACK''s int interface cannot hold this matrix', &
                                 error_code%numeric)
                return
            end if
            colptr(j + 1) = int(top, c_int)
        end do
    end subroutine collect_columns

    !> Counting-sort transpose: scanning columns j in ascending order and appending j
    !> to column i for every stored (i, j) gives each column its rows in ascending
    !> order; by structural symmetry the pattern is the same. `rowind`: 0-based rows,
    !> shape [colptr(n+1)].
    pure subroutine sort_columns(n, colptr, rows, rowind)
        integer, intent(in) :: n
        integer(c_int), intent(in) :: colptr(:)
        integer, intent(in) :: rows(:)
        integer(c_int), allocatable, intent(out) :: rowind(:)
        integer, allocatable :: next(:)
        integer :: i, j, k

        allocate (rowind(colptr(n + 1)), next(n))
        do i = 1, n
            next(i) = colptr(i)
        end do
        do j = 1, n
            do k = colptr(j) + 1, colptr(j + 1)
                i = rows(k)
                next(i) = next(i) + 1
                rowind(next(i)) = int(j - 1, c_int)
            end do
        end do
    end subroutine sort_columns

    !> Where each stored entry of `old` is in `new` (same n, both patterns from
    !> `new_csc_pattern`): `old2new(p)` is the index into `new%values` of the entry
    !> `old` stores at index p, 0 when `new` does not store it; shape: [nnz of old].
    !> One merge of the sorted rows of each column, O(nnz(old) + nnz(new)): values
    !> and cached element positions move to a rebuilt pattern without any search.
    pure subroutine pattern_positions(old, new, old2new)
        type(csc_matrix_t), intent(in) :: old, new
        integer, allocatable, intent(out) :: old2new(:)
        integer :: j, p, q, qend

        allocate (old2new(old%nnz()))
        old2new = 0
        do j = 1, min(old%n, new%n)
            q = new%colptr(j) + 1
            qend = new%colptr(j + 1)
            do p = old%colptr(j) + 1, old%colptr(j + 1)
                do while (q <= qend)
                    if (new%rowind(q) >= old%rowind(p)) exit
                    q = q + 1
                end do
                if (q > qend) exit
                if (new%rowind(q) == old%rowind(p)) old2new(p) = q
            end do
        end do
    end subroutine pattern_positions

    !> Set every stored value to zero (the pattern and `missed` are kept).
    pure subroutine csc_zero(self)
        class(csc_matrix_t), intent(inout) :: self
        self%values = 0.0_c_double
    end subroutine csc_zero

    !> Index into `values` of entry (i, j), 1-based row and column; 0 when the
    !> entry is not in the pattern or out of range. Binary search in column j.
    pure integer function csc_index_of(self, i, j) result(pos)
        class(csc_matrix_t), intent(in) :: self
        !> Row, 1-based.
        integer, intent(in) :: i
        !> Column, 1-based.
        integer, intent(in) :: j
        integer :: lo, hi, mid, r

        pos = 0
        if (i < 1 .or. i > self%n .or. j < 1 .or. j > self%n) return
        lo = self%colptr(j) + 1
        hi = self%colptr(j + 1)
        r = i - 1
        do while (lo <= hi)
            mid = (lo + hi)/2
            if (self%rowind(mid) == r) then
                pos = mid
                return
            else if (self%rowind(mid) < r) then
                lo = mid + 1
            else
                hi = mid - 1
            end if
        end do
    end function csc_index_of

    !> A(dofs(a), dofs(b)) += ke(a, b) for every pair whose DOFs are both > 0.
    !> A pair missing from the pattern (or a DOF > n) is a programming error: it
    !> is not stored and counts in `self%missed`.
    pure subroutine csc_add_element(self, dofs, ke)
        class(csc_matrix_t), intent(inout) :: self
        !> Global DOF numbers, 1-based, <= 0 skipped; shape: [m].
        integer, intent(in) :: dofs(:)
        !> Element matrix; shape: [m, m].
        real(dp), intent(in) :: ke(:, :)
        integer :: a, b, pos, last

        do b = 1, size(dofs)
            if (dofs(b) <= 0) cycle
            pos = 0
            do a = 1, size(dofs)
                if (dofs(a) <= 0) then
                    pos = 0
                    cycle
                end if
                ! the y row of a control point follows its x row in the column (rows sorted):
                ! found without a search
                last = pos
                pos = 0
                if (a > 1 .and. last > 0 .and. last < self%colptr(min(dofs(b), self%n) + 1)) then
                    if (dofs(a) == dofs(a - 1) + 1 .and. self%rowind(last + 1) == dofs(a) - 1) pos = last + 1
                end if
                if (pos == 0) pos = self%index_of(dofs(a), dofs(b))
                if (pos > 0) then
                    self%values(pos) = self%values(pos) + ke(a, b)
                else
                    self%missed = self%missed + 1
                end if
            end do
        end do
    end subroutine csc_add_element

    !> `add_element` (the same sums in the same order, the same count of missed
    !> pairs) with the positions of the last element of `cache` when `dofs` are its DOFs.
    pure subroutine csc_add_cached(self, dofs, ke, cache)
        class(csc_matrix_t), intent(inout) :: self
        !> Global DOF numbers, 1-based, <= 0 skipped; shape: [m].
        integer, intent(in) :: dofs(:)
        !> Element matrix; shape: [m, m].
        real(dp), intent(in) :: ke(:, :)
        type(position_cache_t), intent(inout) :: cache
        integer :: a, b, m
        logical :: same
        m = size(dofs)
        same = .false.
        if (allocated(cache%dofs)) then
            if (size(cache%dofs) == m) same = all(cache%dofs == dofs)
        end if
        if (.not. same) then
            cache%dofs = dofs
            if (allocated(cache%pos)) then
                if (size(cache%pos, 1) /= m) deallocate (cache%pos)
            end if
            if (.not. allocated(cache%pos)) allocate (cache%pos(m, m))
            call element_positions_quiet(self, dofs, cache%pos)
        end if
        do b = 1, m
            if (dofs(b) <= 0) cycle
            do a = 1, m
                if (dofs(a) <= 0) cycle
                if (cache%pos(a, b) > 0) then
                    self%values(cache%pos(a, b)) = self%values(cache%pos(a, b)) + ke(a, b)
                else
                    self%missed = self%missed + 1
                end if
            end do
        end do
    end subroutine csc_add_cached

    !> The positions `element_positions` finds (0 for a DOF <= 0 or a pair not in
    !> the pattern), without counting the missed pairs; the search of
    !> `add_element` (the y row of a control point right after its x row).
    pure subroutine element_positions_quiet(self, dofs, pos)
        class(csc_matrix_t), intent(in) :: self
        integer, intent(in) :: dofs(:)
        integer, intent(out) :: pos(:, :)
        integer :: a, b, last
        pos = 0
        do b = 1, size(dofs)
            if (dofs(b) <= 0) cycle
            last = 0
            do a = 1, size(dofs)
                if (dofs(a) <= 0) then
                    last = 0
                    cycle
                end if
                if (a > 1 .and. last > 0 .and. last < self%colptr(min(dofs(b), self%n) + 1)) then
                    if (dofs(a) == dofs(a - 1) + 1 .and. self%rowind(last + 1) == dofs(a) - 1) pos(a, b) = last + 1
                end if
                if (pos(a, b) == 0) pos(a, b) = self%index_of(dofs(a), dofs(b))
                last = pos(a, b)
            end do
        end do
    end subroutine element_positions_quiet

    !> Positions of an element's entries in `values`, for repeated assembly
    !> without searching: compute `pos` once per element after the pattern is
    !> built, keep it, and every iteration call `a%add_at(pos, ke)`. Entries
    !> whose DOF is <= 0 get 0 (skipped by `add_at`); a pair not in the pattern
    !> also gets 0 and counts in `self%missed`. The positions stay valid as long
    !> as the pattern does (`zero` keeps it; a new `new_csc_pattern` does not).
    pure subroutine csc_element_positions(self, dofs, pos)
        class(csc_matrix_t), intent(inout) :: self
        !> Global DOF numbers, 1-based, <= 0 skipped; shape: [m].
        integer, intent(in) :: dofs(:)
        !> Index into `values` of entry (dofs(a), dofs(b)), or 0; shape: [m, m].
        integer, intent(out) :: pos(:, :)
        integer :: a, b

        do b = 1, size(dofs)
            do a = 1, size(dofs)
                pos(a, b) = 0
                if (dofs(a) <= 0 .or. dofs(b) <= 0) cycle
                pos(a, b) = self%index_of(dofs(a), dofs(b))
                if (pos(a, b) == 0) self%missed = self%missed + 1
            end do
        end do
    end subroutine csc_element_positions

    !> values(pos(a, b)) += ke(a, b) wherever pos(a, b) > 0 (positions from
    !> `element_positions`).
    pure subroutine csc_add_at(self, pos, ke)
        class(csc_matrix_t), intent(inout) :: self
        !> Cached positions; shape: [m, m].
        integer, intent(in) :: pos(:, :)
        !> Element matrix; shape: [m, m].
        real(dp), intent(in) :: ke(:, :)
        integer :: a, b

        do b = 1, size(pos, 2)
            do a = 1, size(pos, 1)
                if (pos(a, b) > 0) self%values(pos(a, b)) = self%values(pos(a, b)) + ke(a, b)
            end do
        end do
    end subroutine csc_add_at

    !> y = A x.
    pure subroutine csc_matvec(self, x, y)
        class(csc_matrix_t), intent(in) :: self
        !> shape: [n]
        real(dp), intent(in) :: x(:)
        !> shape: [n]
        real(dp), intent(out) :: y(:)
        integer :: j, k
        real(dp) :: xj

        y(1:self%n) = 0.0_dp
        do j = 1, self%n
            xj = x(j)
            do k = self%colptr(j) + 1, self%colptr(j + 1)
                y(self%rowind(k) + 1) = y(self%rowind(k) + 1) + self%values(k)*xj
            end do
        end do
    end subroutine csc_matvec

    !> Number of stored entries (0 before a pattern is built).
    pure integer function csc_nnz(self) result(nnz)
        class(csc_matrix_t), intent(in) :: self
        nnz = 0
        if (allocated(self%colptr)) nnz = self%colptr(self%n + 1)
    end function csc_nnz

    !> Symmetric elimination of Dirichlet DOFs: zero the rows and columns of every
    !> fixed DOF and put 1 on its diagonal. Meant for Newton corrections that are
    !> zero on Dirichlet DOFs: the caller also sets the right-hand side of the
    !> fixed DOFs to 0, so their correction comes out exactly 0 and the free
    !> block is unchanged (and stays symmetric).
    pure subroutine csc_fix_dofs(self, fixed)
        class(csc_matrix_t), intent(inout) :: self
        !> .true. for a fixed DOF; shape: [n].
        logical, intent(in) :: fixed(:)
        integer :: i, j, k

        do j = 1, self%n
            if (fixed(j)) then
                ! the whole column
                do k = self%colptr(j) + 1, self%colptr(j + 1)
                    self%values(k) = merge(1.0_c_double, 0.0_c_double, self%rowind(k) + 1 == j)
                end do
            else
                do k = self%colptr(j) + 1, self%colptr(j + 1)
                    i = self%rowind(k) + 1
                    if (fixed(i)) self%values(k) = 0.0_c_double
                end do
            end if
        end do
    end subroutine csc_fix_dofs

end module voiga_linalg_sparse
