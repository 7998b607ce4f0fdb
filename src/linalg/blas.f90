!> The BLAS routines voiga calls, behind explicit interfaces (reference BLAS or
!> OpenBLAS, whichever `libblas` the system provides).
!>
!> `dgemm` only writes its output argument; its interface is declared `pure` so
!> that pure kernels may use it.
module voiga_linalg_blas
    use voiga_kinds, only: dp
    implicit none
    private

    public :: gemm_tn, gemm_nt, warm_up_blas

    interface
        pure subroutine dgemm(transa, transb, m, n, k, alpha, a, lda, b, ldb, beta, c, ldc)
            import :: dp
            character(len=1), intent(in) :: transa, transb
            integer, intent(in) :: m, n, k, lda, ldb, ldc
            real(dp), intent(in) :: alpha, beta
            real(dp), intent(in) :: a(lda, *), b(ldb, *)
            real(dp), intent(inout) :: c(ldc, *)
        end subroutine dgemm
    end interface

contains

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
