!> Numbers as message text: error messages are built by concatenation from
!> these, so that the library's modules format without I/O statements of their own.
module voiga_text
    use voiga_kinds, only: dp
    implicit none
    private

    public :: str, real_str, fixed_str, short_str

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

    !> A real with `digits` decimals and as few leading characters as it needs
    !> ('0.171', '-0.5', '12.0'): format f0.d with the leading zero that f0.d
    !> leaves out for |x| < 1.
    pure function fixed_str(x, digits) result(text)
        real(dp), intent(in) :: x
        integer, intent(in) :: digits
        character(len=:), allocatable :: text
        text = real_str(x, 'f0.'//str(digits))
        if (text(1:1) == '.') then
            text = '0'//text
        else if (len(text) > 1) then
            if (text(1:2) == '-.') text = '-0'//text(2:)
        end if
    end function fixed_str

    !> A real with up to 7 significant digits and no trailing zeros, as a user
    !> would type it: '0.5', '-1.0', '30.0', '1.25E-05'.
    pure function short_str(x) result(text)
        real(dp), intent(in) :: x
        character(len=:), allocatable :: text
        character(len=:), allocatable :: exponent
        integer :: e
        if (x == 0.0_dp) then
            text = '0.0'
            return
        end if
        if (abs(x) >= 1.0e-3_dp .and. abs(x) < 1.0e7_dp) then
            text = fixed_str(x, max(1, 6 - floor(log10(abs(x)))))
            exponent = ''
        else
            text = trim(adjustl(real_str(x, 'es14.6')))
            e = index(text, 'E')
            exponent = text(e:)
            text = text(:e - 1)
        end if
        do while (text(len(text):len(text)) == '0' .and. text(len(text) - 1:len(text) - 1) /= '.')
            text = text(:len(text) - 1)
        end do
        text = text//exponent
    end function short_str

end module voiga_text
