!> The LAPACK routines voiga calls, behind explicit interfaces.
module voiga_linalg_lapack
    use voiga_kinds, only: dp
    implicit none
    private

    public :: solve_spd, solve_general, solve_least_squares, band_factor, lu_factor, lu_solve, triangular_inverse

    interface
        pure subroutine dposv(uplo, n, nrhs, a, lda, b, ldb, info)
            import :: dp
            character(len=1), intent(in) :: uplo
            integer, intent(in) :: n, nrhs, lda, ldb
            real(dp), intent(inout) :: a(lda, *), b(ldb, *)
            integer, intent(out) :: info
        end subroutine dposv
        pure subroutine dgesv(n, nrhs, a, lda, ipiv, b, ldb, info)
            import :: dp
            integer, intent(in) :: n, nrhs, lda, ldb
            real(dp), intent(inout) :: a(lda, *), b(ldb, *)
            integer, intent(out) :: ipiv(*), info
        end subroutine dgesv
        pure subroutine dgelss(m, n, nrhs, a, lda, b, ldb, s, rcond, rank, work, lwork, info)
            import :: dp
            integer, intent(in) :: m, n, nrhs, lda, ldb, lwork
            real(dp), intent(inout) :: a(lda, *), b(ldb, *)
            real(dp), intent(out) :: s(*), work(*)
            real(dp), intent(in) :: rcond
            integer, intent(out) :: rank, info
        end subroutine dgelss
        pure subroutine dgetrf(m, n, a, lda, ipiv, info)
            import :: dp
            integer, intent(in) :: m, n, lda
            real(dp), intent(inout) :: a(lda, *)
            integer, intent(out) :: ipiv(*), info
        end subroutine dgetrf
        pure subroutine dgetrs(trans, n, nrhs, a, lda, ipiv, b, ldb, info)
            import :: dp
            character(len=1), intent(in) :: trans
            integer, intent(in) :: n, nrhs, lda, ldb
            real(dp), intent(in) :: a(lda, *)
            integer, intent(in) :: ipiv(*)
            real(dp), intent(inout) :: b(ldb, *)
            integer, intent(out) :: info
        end subroutine dgetrs
        pure subroutine dtrtri(uplo, diag, n, a, lda, info)
            import :: dp
            character(len=1), intent(in) :: uplo, diag
            integer, intent(in) :: n, lda
            real(dp), intent(inout) :: a(lda, *)
            integer, intent(out) :: info
        end subroutine dtrtri
        pure subroutine dgbtrf(m, n, kl, ku, ab, ldab, ipiv, info)
            import :: dp
            integer, intent(in) :: m, n, kl, ku, ldab
            real(dp), intent(inout) :: ab(ldab, *)
            integer, intent(out) :: ipiv(*), info
        end subroutine dgbtrf
    end interface

contains

    !> Solve a x = b for a symmetric positive definite `a` (Cholesky, LAPACK dposv).
    !> On exit `b` holds x; `a` is overwritten by its factor. `info` /= 0: `a` is
    !> not positive definite (or an argument is wrong), `b` is then undefined.
    pure subroutine solve_spd(a, b, info)
        !> shape: [n, n]
        real(dp), intent(inout) :: a(:, :)
        !> shape: [n, nrhs]
        real(dp), intent(inout) :: b(:, :)
        integer, intent(out) :: info
        call dposv('L', size(a, 1), size(b, 2), a, size(a, 1), b, size(b, 1), info)
    end subroutine solve_spd

    !> Solve a x = b for a general square `a` (LU with partial pivoting, LAPACK
    !> dgesv). On exit `b` holds x; `a` is overwritten by its factors. `info` > 0:
    !> `a` is singular, `b` is then undefined.
    pure subroutine solve_general(a, b, info)
        !> shape: [n, n]
        real(dp), intent(inout) :: a(:, :)
        !> shape: [n, nrhs]
        real(dp), intent(inout) :: b(:, :)
        integer, intent(out) :: info
        integer :: ipiv(size(a, 1))
        call dgesv(size(a, 1), size(b, 2), a, size(a, 1), ipiv, b, size(b, 1), info)
    end subroutine solve_general

    !> The least-squares solution of least norm of a x = b for a square `a` of any rank
    !> (SVD, LAPACK dgelss): singular values below `rcond` times the largest count as
    !> zero. On exit `b` holds x and `rank` the rank used; `a` is overwritten. `info` > 0:
    !> the SVD did not converge.
    pure subroutine solve_least_squares(a, b, rcond, rank, info)
        !> shape: [n, n]
        real(dp), intent(inout) :: a(:, :)
        !> shape: [n, nrhs]
        real(dp), intent(inout) :: b(:, :)
        real(dp), intent(in) :: rcond
        integer, intent(out) :: rank, info
        real(dp) :: s(size(a, 1)), query(1)
        real(dp), allocatable :: work(:)
        integer :: n
        n = size(a, 1)
        call dgelss(n, n, size(b, 2), a, max(1, n), b, max(1, n), s, rcond, rank, query, -1, info)
        if (info /= 0) return
        allocate (work(max(1, int(query(1)))))
        call dgelss(n, n, size(b, 2), a, max(1, n), b, max(1, n), s, rcond, rank, work, size(work), info)
    end subroutine solve_least_squares

    !> LU factorization with partial pivoting of a square `a` (LAPACK dgetrf), kept
    !> for several `lu_solve`s. On exit `a` holds L and U, `ipiv` [n] the row
    !> interchanges; `info` > 0: `a` is singular.
    pure subroutine lu_factor(a, ipiv, info)
        !> shape: [n, n]
        real(dp), intent(inout) :: a(:, :)
        integer, intent(out) :: ipiv(:), info
        call dgetrf(size(a, 1), size(a, 2), a, size(a, 1), ipiv, info)
    end subroutine lu_factor

    !> Solve a X = B with the factors of `lu_factor` (LAPACK dgetrs); `b` [n, nrhs]
    !> holds X on exit.
    pure subroutine lu_solve(lu, ipiv, b, info)
        real(dp), intent(in) :: lu(:, :)
        integer, intent(in) :: ipiv(:)
        real(dp), intent(inout) :: b(:, :)
        integer, intent(out) :: info
        call dgetrs('N', size(lu, 1), size(b, 2), lu, max(1, size(lu, 1)), ipiv, b, max(1, size(b, 1)), info)
    end subroutine lu_solve

    !> Inverse of a lower triangular `a` [n, n] in place (LAPACK dtrtri; the upper
    !> triangle is not referenced). `info` > 0: diagonal entry `info` is zero.
    pure subroutine triangular_inverse(a, info)
        real(dp), intent(inout) :: a(:, :)
        integer, intent(out) :: info
        info = 0
        if (size(a, 1) == 0) return
        call dtrtri('L', 'N', size(a, 1), a, size(a, 1), info)
    end subroutine triangular_inverse

    !> LU factorization with partial pivoting of an n x n band matrix with `kl`
    !> sub- and `ku` superdiagonals (LAPACK dgbtrf). `ab` has shape [2 kl + ku + 1, n]
    !> (explicit shape: a section of a longer array may be passed by its first element):
    !> entry (i, j) of the matrix in ab(kl + ku + 1 + i - j, j); rows 1..kl are
    !> workspace. `info` > 0: the matrix is singular.
    pure subroutine band_factor(n, kl, ku, ab, ipiv, info)
        integer, intent(in) :: n, kl, ku
        real(dp), intent(inout) :: ab(2*kl + ku + 1, n)
        integer, intent(out) :: ipiv(n), info
        call dgbtrf(n, n, kl, ku, ab, 2*kl + ku + 1, ipiv, info)
    end subroutine band_factor

end module voiga_linalg_lapack
