!> Numbers as message text: error messages are built by concatenation from
!> these, so that the library's modules format without I/O statements of their own.
module voiga_text
    use voiga_kinds, only: dp
    implicit none
    private

    public :: str, real_str

contains

    !> An integer, as few digits as it needs (format i0).
    pure function str(i) result(text)
        integer, intent(in) :: i
        character(len=:), allocatable :: text
        character(len=24) :: buf
        write (buf, '(i0)') i
        text = trim(buf)
    end function str

    !> A real in the edit descriptor `edit` (e.g. 'es9.2', 'f0.2'), the field as
    !> it is written (leading blanks of a fixed width kept, trailing ones dropped).
    pure function real_str(x, edit) result(text)
        real(dp), intent(in) :: x
        character(len=*), intent(in) :: edit
        character(len=:), allocatable :: text
        character(len=64) :: buf
        write (buf, '('//edit//')') x
        text = trim(buf)
    end function real_str

end module voiga_text
