!> Keep freed heap memory in the process (glibc `mallopt`).
!>
!> UMFPACK allocates its Numeric object (10 MB for ironing m4 N6, hundreds of MB
!> for the large hertz meshes) and its work arrays afresh for every numeric
!> factorization and frees them afterwards. With glibc's defaults, blocks above
!> the mmap threshold (dynamic, at most 32 MB) are mapped and unmapped every
!> time, and freed memory at the top of the heap beyond the trim threshold is
!> returned to the kernel: every factorization then page-faults its memory in
!> again and the kernel zeroes each page (measured on ironing m4 N6: 12 % of the
!> run in page faults and page clearing, 0.9 million minor faults in 30 steps).
!> Raising both thresholds keeps the freed memory for the next factorization.
!> Nothing numerical changes: the result files are identical bit for bit.
!>
!> `mallopt` is called in libc.c, where glibc's `malloc.h` names its parameters
!> (M_MMAP_THRESHOLD, M_TRIM_THRESHOLD).
module voiga_platform_heap
    use, intrinsic :: iso_c_binding, only: c_int
    implicit none
    private

    public :: keep_freed_memory

    !> Blocks below this size come from the heap, and this much free memory may stay
    !> at its top (bytes; 1 GiB: the largest Numeric object of `make bench`, hertz m8,
    !> is about 1 GB; larger blocks are still mapped and unmapped).
    integer(c_int), parameter :: threshold = 1073741824_c_int

    interface
        !> Both thresholds set to `bytes` (libc.c): 1 when glibc took both.
        function c_keep_freed_memory(bytes) result(ok) bind(c, name='voiga_keep_freed_memory')
            import :: c_int
            integer(c_int), value :: bytes
            integer(c_int) :: ok
        end function c_keep_freed_memory
    end interface

contains

    !> Raise glibc's mmap and trim thresholds so that memory freed by one
    !> factorization is reused by the next instead of being returned to the kernel.
    !> Call once at program start. `ok` is false if glibc refused a setting (the
    !> program works either way, only slower).
    subroutine keep_freed_memory(ok)
        logical, intent(out) :: ok
        ok = c_keep_freed_memory(threshold) == 1_c_int
    end subroutine keep_freed_memory

end module voiga_platform_heap
