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
!>
!> The three phases are submodules, since all of them work on the private state of
!> `supernodal_lu_t`: `supernodal_analysis.f90` (analysis), `supernodal_factor.f90`
!> (numeric factorization), `supernodal_solve.f90` (solves); the type, the
!> interfaces of what one file calls in another, and the factorization's driver are
!> here.
module voiga_solver_supernodal
    use, intrinsic :: iso_c_binding, only: c_int
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error
    use voiga_linalg_sparse, only: csc_matrix_t
    use voiga_solver_linear, only: linear_solver_t, solve_accuracy_t
    use voiga_solver_umfpack, only: umfpack_t
    implicit none
    private

    public :: supernodal_lu_t

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
        !> Make the analysis fit `a`: keep it while `a`'s pattern and nonzeros fall in
        !> the analysed fronts (a new pattern is mapped into them), else analyse anew
        !> (always after `renew_analysis` unless the nonzeros are the same). `ok` false:
        !> UMFPACK must factorize `a` (pattern not taken, analysis failed).
        module subroutine update_analysis(self, a, ok)
            class(supernodal_lu_t), intent(inout) :: self
            type(csc_matrix_t), intent(in) :: a
            logical, intent(out) :: ok
        end subroutine update_analysis

        !> The numeric factorization on the analysed structure; `ok` false when a pivot
        !> is zero or a multiplier exceeds `max_multiplier` (the caller hands the matrix
        !> to UMFPACK).
        module subroutine numeric(self, a, ok)
            class(supernodal_lu_t), intent(inout) :: self
            type(csc_matrix_t), intent(in) :: a
            logical, intent(out) :: ok
        end subroutine numeric

        !> Sign and log10 |det| of the factorized matrix, and rcond = min |u_jj| / max |u_jj|.
        module subroutine diagonal_summary(self)
            class(supernodal_lu_t), intent(inout) :: self
        end subroutine diagonal_summary

        !> Solve A x = b with the last factorization (`a`: the matrix factorized, used for
        !> iterative refinement when rcond < `refine_below_rcond`).
        module subroutine sn_solve(self, a, b, x, error, accuracy)
            class(supernodal_lu_t), intent(inout) :: self
            type(csc_matrix_t), intent(in) :: a
            real(dp), intent(in) :: b(:)
            real(dp), intent(out) :: x(:)
            type(error_t), allocatable, intent(out) :: error
            !> Ignored: a direct solve is as accurate as the factorization.
            type(solve_accuracy_t), intent(in), optional :: accuracy
        end subroutine sn_solve
    end interface

contains

    !> Factorize `a`: analysis when its pattern or its nonzero pattern is new, then
    !> the supernodal factorization, or UMFPACK's where that is not stable.
    subroutine sn_factor(self, a, error)
        class(supernodal_lu_t), intent(inout) :: self
        type(csc_matrix_t), intent(in) :: a
        type(error_t), allocatable, intent(out) :: error
        logical :: ok

        self%factored = .false.
        if (a%n < 1 .or. .not. (allocated(a%colptr) .and. allocated(a%rowind) .and. allocated(a%values))) then
            call fatal_error(error, 'supernodal factorize: matrix has no pattern (build it with new_csc_pattern)')
            return
        end if
        call update_analysis(self, a, ok)
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
