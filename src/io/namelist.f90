!> Namelist helpers for the case reader: diagnosis of a group that failed to
!> read (naming the variable at fault) and the list of groups in a file.
module voiga_io_namelist
    use voiga_error, only: error_t, fatal_error, error_code
    implicit none
    private

    public :: group_error, group_names, lower

contains

    !> Error for a namelist group that could not be read. The group's text is
    !> re-read one assignment at a time through `try` to name the variable at fault.
    subroutine group_error(path, group, occurrence, ios, msg, try, error)
        character(len=*), intent(in) :: path, group
        !> Which occurrence of the group failed (1 for the first).
        integer, intent(in) :: occurrence
        integer, intent(in) :: ios
        character(len=*), intent(in) :: msg
        interface
            subroutine try(text, ios, msg)
                character(len=*), intent(in) :: text
                integer, intent(out) :: ios
                character(len=*), intent(inout) :: msg
            end subroutine try
        end interface
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: assignments(:), name
        character(len=512) :: msg1
        integer :: k, ios1, eq

        if (is_iostat_end(ios)) then
            call fatal_error(error, path//': group &'//group//' is missing', error_code%input)
            return
        end if
        call group_assignments(path, group, occurrence, assignments)
        do k = 1, size(assignments)
            msg1 = ''
            call try('&'//group//' '//assignments(k)//' /', ios1, msg1)
            if (ios1 == 0) cycle
            eq = index(assignments(k), '=')
            name = adjustl(assignments(k)(1:max(eq - 1, 0)))
            name = trim(name)
            if (index(msg1, 'Cannot match namelist object name '//name) > 0 .or. &
                index(msg1, 'Cannot match namelist object name '//lower(name)) > 0) then
                call fatal_error(error, path//': &'//group//": unknown variable '"//name//"'", &
                                 error_code%input)
            else
                call fatal_error(error, path//': &'//group//": variable '"//name// &
                                 "' has a value of the wrong type or form: "// &
                                 trim(adjustl(assignments(k)(eq + 1:)))//' ('//trim(msg1)//')', &
                                 error_code%input)
            end if
            return
        end do
        call fatal_error(error, path//': &'//group//': '//trim(msg), error_code%input)
    end subroutine group_error

    !> The `name = value` assignments of the `occurrence`-th group `group` in file
    !> `path`, one per entry (continuation lines joined). Quoted '=' and '/' are not
    !> special-cased beyond what our case files contain; good enough for diagnosis.
    subroutine group_assignments(path, group, occurrence, assignments)
        character(len=*), intent(in) :: path, group
        integer, intent(in) :: occurrence
        character(len=:), allocatable, intent(out) :: assignments(:)
        character(len=4096) :: line
        character(len=4096), allocatable :: items(:)
        character(len=:), allocatable :: t
        integer :: u, ios, seen, n, width
        logical :: inside

        allocate (items(0))
        n = 0
        seen = 0
        inside = .false.
        open (newunit=u, file=path, status='old', action='read', iostat=ios)
        if (ios /= 0) then
            allocate (character(len=1) :: assignments(0))
            return
        end if
        do
            read (u, '(a)', iostat=ios) line
            if (ios /= 0) exit
            t = trim(adjustl(strip_comment(line)))
            if (.not. inside) then
                if (len(t) > len(group) .and. lower(t(1:min(len(t), len(group) + 1))) == '&'//lower(group)) then
                    seen = seen + 1
                    inside = seen == occurrence
                    t = trim(adjustl(t(len(group) + 2:)))
                    if (.not. inside) cycle
                else
                    cycle
                end if
            end if
            if (len(t) == 0) cycle
            if (t(len(t):len(t)) == '/') then
                t = t(1:len(t) - 1)
                inside = .false.
            end if
            if (len_trim(t) > 0) then
                if (index(t, '=') > 0 .or. n == 0) then
                    items = [character(len=4096) :: items, t]
                    n = n + 1
                else
                    items(n) = trim(items(n))//' '//t
                end if
            end if
            if (.not. inside .and. seen >= occurrence) exit
        end do
        close (u)
        width = 1
        if (n > 0) width = max(1, maxval(len_trim(items)))
        allocate (character(len=width) :: assignments(n))
        assignments = items
    end subroutine group_assignments

    !> The line without a trailing '!' comment (outside quotes).
    pure function strip_comment(line) result(code)
        character(len=*), intent(in) :: line
        character(len=:), allocatable :: code
        integer :: i
        character :: quote
        quote = ' '
        do i = 1, len(line)
            if (quote /= ' ') then
                if (line(i:i) == quote) quote = ' '
            else if (line(i:i) == "'" .or. line(i:i) == '"') then
                quote = line(i:i)
            else if (line(i:i) == '!') then
                code = line(1:i - 1)
                return
            end if
        end do
        code = line
    end function strip_comment

    !> Lower-case ASCII.
    pure function lower(text) result(low)
        character(len=*), intent(in) :: text
        character(len=len(text)) :: low
        integer :: i
        low = text
        do i = 1, len(text)
            if (text(i:i) >= 'A' .and. text(i:i) <= 'Z') low(i:i) = achar(iachar(text(i:i)) + 32)
        end do
    end function lower

    !> Names (lower case, without '&') of every namelist group in file `path`, in order.
    subroutine group_names(path, names)
        character(len=*), intent(in) :: path
        character(len=32), allocatable, intent(out) :: names(:)
        character(len=4096) :: line
        character(len=:), allocatable :: t
        integer :: u, ios, k
        allocate (names(0))
        open (newunit=u, file=path, status='old', action='read', iostat=ios)
        if (ios /= 0) return
        do
            read (u, '(a)', iostat=ios) line
            if (ios /= 0) exit
            t = trim(adjustl(strip_comment(line)))
            if (len(t) < 2) cycle
            if (t(1:1) /= '&') cycle
            k = scan(t(2:), ' /,')
            if (k == 0) k = len(t)
            names = [character(len=32) :: names, lower(t(2:k))]
        end do
        close (u)
    end subroutine group_names

end module voiga_io_namelist
