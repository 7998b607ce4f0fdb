!> Numeric kinds used throughout voiga.
module voiga_kinds
    use, intrinsic :: iso_fortran_env, only: real64, int32, int64
    implicit none
    private

    !> Double precision: every real in voiga is `real(dp)`.
    integer, parameter, public :: dp = real64
    !> Default integer kinds, re-exported for explicit use.
    integer, parameter, public :: i4 = int32, i8 = int64

end module voiga_kinds
