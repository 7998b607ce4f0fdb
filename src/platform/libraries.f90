!> How the numerical libraries the program is linked with run, set once at start:
!> the thread counts of OpenBLAS and OpenMP (CHOLMOD's loops), and OpenBLAS's
!> kernels on a CPU it does not know. Both are looked up at run time
!> (threads_shim.c, kernels_shim.c: `dlsym`), so that any `libblas` works and
!> nothing is done with one that has neither.
!>
!> What was chosen is kept for the result file's provenance (`blas_kernels`,
!> `library_threads`): the kernels OpenBLAS detected and whether voiga switched
!> them are the two module variables set by `choose_blas_kernels`, once, before
!> the first BLAS call.
module voiga_platform_libraries
    use, intrinsic :: iso_c_binding, only: c_int, c_char, c_ptr, c_null_char, c_associated, c_f_pointer
    implicit none
    private

    public :: default_library_threads, library_threads, choose_blas_kernels, blas_kernels, kernels_for

    !> The environment variables through which a user chooses the thread counts of
    !> OpenBLAS and OpenMP; when none is set, voiga runs them on one thread.
    character(len=*), parameter :: thread_variables(3) = &
        [character(len=20) :: 'OPENBLAS_NUM_THREADS', 'GOTO_NUM_THREADS', 'OMP_NUM_THREADS']

    !> OpenBLAS's kernels were switched by `choose_blas_kernels`, from these.
    logical :: kernels_switched = .false.
    character(len=32) :: kernels_detected = ''

    interface
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
    !> CPU and fell back to its generic ones (src/platform/kernels_shim.c says when);
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

end module voiga_platform_libraries
