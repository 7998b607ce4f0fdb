!> The BLAS routines voiga calls, behind explicit interfaces (reference BLAS or
!> OpenBLAS, whichever `libblas` the system provides). How the BLAS runs (its
!> threads, OpenBLAS's kernels) is set at start by `voiga_platform_libraries`.
!>
!> `dgemm` only writes its output argument; its interface is declared `pure` so
!> that pure kernels may use it.
module voiga_linalg_blas
    use voiga_kinds, only: dp
    implicit none
    private

    public :: gemm_tn, gemm_nt, triangular_solve, warm_up_blas
    !> The BLAS routines themselves, for kernels that pass leading dimensions of sub-blocks.
    public :: dgemm, dtrsm

    interface
        pure subroutine dgemm(transa, transb, m, n, k, alpha, a, lda, b, ldb, beta, c, ldc)
            import :: dp
            character(len=1), intent(in) :: transa, transb
            integer, intent(in) :: m, n, k, lda, ldb, ldc
            real(dp), intent(in) :: alpha, beta
            real(dp), intent(in) :: a(lda, *), b(ldb, *)
            real(dp), intent(inout) :: c(ldc, *)
        end subroutine dgemm
        pure subroutine dtrsm(side, uplo, transa, diag, m, n, alpha, a, lda, b, ldb)
            import :: dp
            character(len=1), intent(in) :: side, uplo, transa, diag
            integer, intent(in) :: m, n, lda, ldb
            real(dp), intent(in) :: alpha
            real(dp), intent(in) :: a(lda, *)
            real(dp), intent(inout) :: b(ldb, *)
        end subroutine dtrsm
    end interface

contains

    !> b := l^-1 b, or l^-T b when `transposed`, for a lower triangular l [m, m]
    !> (upper triangle not referenced) and b [m, n] (BLAS dtrsm).
    pure subroutine triangular_solve(l, b, transposed)
        real(dp), intent(in) :: l(:, :)
        real(dp), intent(inout) :: b(:, :)
        logical, intent(in) :: transposed
        if (size(b, 1) == 0 .or. size(b, 2) == 0) return
        call dtrsm('L', 'L', merge('T', 'N', transposed), 'N', size(b, 1), size(b, 2), 1.0_dp, l, &
                   size(l, 1), b, size(b, 1))
    end subroutine triangular_solve

    !> c = beta c + a^T b, with a [k, m], b [k, n], c [m, n] (contiguous arrays).
    pure subroutine gemm_tn(a, b, c, beta)
        real(dp), intent(in) :: a(:, :), b(:, :)
        real(dp), intent(inout) :: c(:, :)
        real(dp), intent(in) :: beta
        call dgemm('T', 'N', size(a, 2), size(b, 2), size(a, 1), 1.0_dp, a, size(a, 1), &
                   b, size(b, 1), beta, c, size(c, 1))
    end subroutine gemm_tn

    !> c = beta c + a b^T, with a [m, k], b [n, k], c [m, n] (contiguous arrays).
    pure subroutine gemm_nt(a, b, c, beta)
        real(dp), intent(in) :: a(:, :), b(:, :)
        real(dp), intent(inout) :: c(:, :)
        real(dp), intent(in) :: beta
        call dgemm('N', 'T', size(a, 1), size(b, 1), size(a, 2), 1.0_dp, a, size(a, 1), &
                   b, size(b, 1), beta, c, size(c, 1))
    end subroutine gemm_nt

    !> One product of 128 x 128 matrices: OpenBLAS maps its work buffer (128 MiB of
    !> address space) at the first product of that size and keeps it. Under an
    !> address-space limit (`ulimit -v`) a program calls this first, while there is
    !> room: OpenBLAS retries a buffer it cannot map for ever, so a run that filled
    !> its address space before its first large product would hang there.
    subroutine warm_up_blas()
        real(dp), allocatable :: a(:, :), b(:, :), c(:, :)
        allocate (a(128, 128), b(128, 128), c(128, 128))
        a = 1.0_dp
        b = 1.0_dp
        c = 0.0_dp
        call gemm_nt(a, b, c, 0.0_dp)
    end subroutine warm_up_blas

end module voiga_linalg_blas
