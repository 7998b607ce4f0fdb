!> The numeric factorization of `supernodal_lu_t` (`voiga_solver_supernodal`),
!> multifrontal on the analysed supernodes: the scaled entries of `a` written into the
!> fronts, each front eliminating its own columns with pivots inside its diagonal
!> block and adding its Schur complement to its parent's front; then the determinant
!> and the reciprocal condition estimate from the pivots.
submodule(voiga_solver_supernodal) voiga_solver_supernodal_factor
    use voiga_linalg_sparse, only: consecutive_runs
    use voiga_linalg_blas, only: dgemm, dtrsm
    implicit none

    !> A diagonal pivot is kept while it is at least this fraction of the largest
    !> entry of its column inside the supernode's diagonal block.
    real(dp), parameter :: prefer_diagonal = 0.1_dp
    !> A multiplier (entry of L) larger than this means a pivot too small for its
    !> column outside the block: UMFPACK factorizes that matrix instead.
    real(dp), parameter :: max_multiplier = 1.0e3_dp
    !> Supernodes of at least this many columns are factorized with LAPACK and BLAS 3
    !> (`blocked_factor`); smaller ones by loops, cheaper than the calls there.
    integer, parameter :: blas_from = 24

    interface
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

    module procedure numeric
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
    end procedure numeric

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

    module procedure diagonal_summary
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
    end procedure diagonal_summary

end submodule voiga_solver_supernodal_factor
