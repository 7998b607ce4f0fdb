!> The BLAS routines voiga calls, behind explicit interfaces (reference BLAS or
!> OpenBLAS, whichever `libblas` the system provides).
!>
!> `dgemm` only writes its output argument; its interface is declared `pure` so
!> that pure kernels may use it.
module voiga_linalg_blas
    use, intrinsic :: iso_c_binding, only: c_int, c_char, c_ptr, c_null_char, c_associated, c_f_pointer
    use voiga_kinds, only: dp
    implicit none
    private

    public :: gemm_tn, gemm_nt, triangular_solve, warm_up_blas, default_library_threads, library_threads
    public :: choose_blas_kernels, blas_kernels, kernels_for
    !> The BLAS routines themselves, for kernels that pass leading dimensions of sub-blocks.
    public :: dgemm, dtrsm

    !> The environment variables through which a user chooses the thread counts of
    !> OpenBLAS and OpenMP; when none is set, voiga runs them on one thread.
    character(len=*), parameter :: thread_variables(3) = &
        [character(len=20) :: 'OPENBLAS_NUM_THREADS', 'GOTO_NUM_THREADS', 'OMP_NUM_THREADS']

    !> OpenBLAS's kernels were switched by `choose_blas_kernels`, from these.
    logical :: kernels_switched = .false.
    character(len=32) :: kernels_detected = ''

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
        subroutine c_blas_kernels(buf, len) bind(c, name='voiga_blas_kernels')
            import :: c_int, c_char
            character(kind=c_char), intent(out) :: buf(*)
            integer(c_int), value :: len
        end subroutine c_blas_kernels
        function c_choose_blas_kernels() bind(c, name='voiga_choose_blas_kernels') result(switched)
            import :: c_int
            integer(c_int) :: switched
        end function c_choose_blas_kernels
        function c_kernels_for(detected, avx512, avx2, avx) bind(c, name='voiga_kernels_for') result(name)
            import :: c_int, c_char, c_ptr
            character(kind=c_char), intent(in) :: detected(*)
            integer(c_int), value :: avx512, avx2, avx
            type(c_ptr) :: name
        end function c_kernels_for
        function c_set_library_threads(n) bind(c, name='voiga_set_library_threads') result(found)
            import :: c_int
            integer(c_int), value :: n
            integer(c_int) :: found
        end function c_set_library_threads
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

    !> Run OpenBLAS's kernels for the CPU's features where OpenBLAS does not know the
    !> CPU and fell back to its generic ones (src/linalg/kernels_shim.c says when);
    !> before any BLAS call. Nothing is done under a user's `OPENBLAS_CORETYPE` or
    !> with another BLAS.
    subroutine choose_blas_kernels()
        kernels_detected = blas_kernel_name()
        kernels_switched = c_choose_blas_kernels() /= 0
    end subroutine choose_blas_kernels

    !> The kernels the BLAS runs, and who chose them, for the result file's
    !> provenance: 'SkylakeX (OpenBLAS)', 'Prescott (environment: OPENBLAS_CORETYPE)',
    !> 'SkylakeX (voiga, for the CPU's features; OpenBLAS chose Prescott)';
    !> 'not OpenBLAS' for another BLAS.
    function blas_kernels() result(text)
        character(len=:), allocatable :: text
        character(len=64) :: value
        integer :: status
        text = blas_kernel_name()
        if (len(text) == 0) then
            text = 'not OpenBLAS'
            return
        end if
        call get_environment_variable('OPENBLAS_CORETYPE', value, status=status)
        if (kernels_switched) then
            text = text//' (voiga, for the CPU''s features; OpenBLAS chose '//trim(kernels_detected)//')'
        else if (status /= 1) then
            text = text//' (environment: OPENBLAS_CORETYPE='//trim(value)//')'
        else
            text = text//' (OpenBLAS)'
        end if
    end function blas_kernels

    !> The kernels voiga runs instead of OpenBLAS's `detected` ones on a CPU with
    !> these features ('' to keep them).
    function kernels_for(detected, avx512, avx2, avx) result(name)
        character(len=*), intent(in) :: detected
        logical, intent(in) :: avx512, avx2, avx
        character(len=:), allocatable :: name
        type(c_ptr) :: p
        p = c_kernels_for(detected//c_null_char, merge(1_c_int, 0_c_int, avx512), &
                          merge(1_c_int, 0_c_int, avx2), merge(1_c_int, 0_c_int, avx))
        name = c_string(p)
    end function kernels_for

    !> OpenBLAS's name of the kernels it runs ('' another BLAS).
    function blas_kernel_name() result(name)
        character(len=:), allocatable :: name
        character(kind=c_char) :: buf(64)
        integer :: i
        call c_blas_kernels(buf, int(size(buf), c_int))
        name = ''
        do i = 1, size(buf)
            if (buf(i) == c_null_char) exit
            name = name//buf(i)
        end do
    end function blas_kernel_name

    !> The zero-terminated C string at `p` ('' for a null pointer).
    function c_string(p) result(text)
        type(c_ptr), intent(in) :: p
        character(len=:), allocatable :: text
        character(kind=c_char), pointer :: chars(:)
        integer :: n
        text = ''
        if (.not. c_associated(p)) return
        call c_f_pointer(p, chars, [64])
        do n = 1, 64
            if (chars(n) == c_null_char) exit
            text = text//chars(n)
        end do
    end function c_string

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
