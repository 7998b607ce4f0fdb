!> The BLAS routines voiga calls, behind explicit interfaces (reference BLAS or
!> OpenBLAS, whichever `libblas` the system provides).
!>
!> `dgemm` only writes its output argument; its interface is declared `pure` so
!> that pure kernels may use it.
module voiga_linalg_blas
    use, intrinsic :: iso_c_binding, only: c_int
    use voiga_kinds, only: dp
    implicit none
    private

    public :: gemm_tn, gemm_nt, warm_up_blas, default_library_threads, library_threads
    !> The BLAS routine itself, for kernels that pass leading dimensions of sub-blocks.
    public :: dgemm

    !> The environment variables through which a user chooses the thread counts of
    !> OpenBLAS and OpenMP; when none is set, voiga runs them on one thread.
    character(len=*), parameter :: thread_variables(3) = &
        [character(len=20) :: 'OPENBLAS_NUM_THREADS', 'GOTO_NUM_THREADS', 'OMP_NUM_THREADS']

    interface
        pure subroutine dgemm(transa, transb, m, n, k, alpha, a, lda, b, ldb, beta, c, ldc)
            import :: dp
            character(len=1), intent(in) :: transa, transb
            integer, intent(in) :: m, n, k, lda, ldb, ldc
            real(dp), intent(in) :: alpha, beta
            real(dp), intent(in) :: a(lda, *), b(ldb, *)
            real(dp), intent(inout) :: c(ldc, *)
        end subroutine dgemm
        function c_set_library_threads(n) bind(c, name='voiga_set_library_threads') result(found)
            import :: c_int
            integer(c_int), value :: n
            integer(c_int) :: found
        end function c_set_library_threads
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

    !> One OpenBLAS and OpenMP thread unless the environment chooses (any of
    !> `thread_variables` set). voiga's systems (at most some 1e5 unknowns per core
    !> in the committed scenes) gain little from a second thread, and OpenBLAS's
    !> threads wait by spinning: with another process on the cores, hertz m4 NN2.2
    !> took 7-15 s instead of 0.5-1.7 s (docs/performance.md, "Threads").
    subroutine default_library_threads()
        integer(c_int) :: found
        if (len(library_threads()) > 0) return
        found = c_set_library_threads(1_c_int)
    end subroutine default_library_threads

    !> The thread variables the environment sets, as `NAME=value` separated by
    !> blanks; '' when none is (then voiga runs one thread).
    function library_threads() result(set)
        character(len=:), allocatable :: set
        character(len=64) :: value
        integer :: i, status
        set = ''
        do i = 1, size(thread_variables)
            call get_environment_variable(trim(thread_variables(i)), value, status=status)
            if (status == 1) cycle
            if (len(set) > 0) set = set//' '
            set = set//trim(thread_variables(i))//'='//trim(value)
        end do
    end function library_threads

end module voiga_linalg_blas
