!> The namelist groups of a case file, found by our own scanner, and the
!> diagnosis of a group that failed to read (naming the variable at fault).
!>
!> gfortran's sequential namelist read skips everything between groups and the
!> rest of the line after a group's '/', so a group that starts on that line
!> (`/ &dirichlet`) or any text outside groups would be dropped without a word.
!> The scanner reads the whole file, finds every group wherever it starts,
!> refuses text outside groups and groups that do not end, and hands each group's
!> own text to its reader, which reads it from that text (an internal file).
module voiga_io_input_namelist
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_text, only: str
    implicit none
    private

    public :: nml_group_t, scan_groups, group_error, lower, assignment_reader

    !> One namelist group of a file.
    type :: nml_group_t
        !> The group's name, lower case, without '&'.
        character(len=32) :: name = ''
        !> The line where it starts.
        integer :: line = 0
        !> Its text from '&name' to the closing '/' (or '&end'), one record per line.
        character(len=:), allocatable :: text(:)
    end type nml_group_t

    abstract interface
        !> Read the namelist text `text` (one group with one assignment) into a
        !> group's variables: a reader's `try`, for the diagnosis of `group_error`.
        subroutine assignment_reader(text, ios, msg)
            character(len=*), intent(in) :: text
            integer, intent(out) :: ios
            character(len=*), intent(inout) :: msg
        end subroutine assignment_reader
    end interface

contains

    !> Every namelist group of file `path`, in order. Refused (input errors naming
    !> the line): text outside groups, a group that is not closed, a group name
    !> that is missing or too long. A UTF-8 byte-order mark at the start is skipped.
    subroutine scan_groups(path, groups, error)
        character(len=*), intent(in) :: path
        type(nml_group_t), allocatable, intent(out) :: groups(:)
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: text
        integer, allocatable :: starts(:)
        integer :: pos, n, line, first, last, first_line, found
        character :: quote
        character(len=32) :: name

        allocate (groups(0))
        found = 0
        call read_bytes(path, text, error)
        if (allocated(error)) return
        call line_starts(text, starts)
        pos = 1
        if (len(text) >= 3) then
            if (text(1:3) == achar(239)//achar(187)//achar(191)) pos = 4
        end if
        n = len(text)
        do
            ! outside any group: blanks and '!' comments only
            do while (pos <= n)
                if (is_blank(text(pos:pos))) then
                    pos = pos + 1
                else if (text(pos:pos) == '!') then
                    pos = line_end(text, pos) + 1
                else
                    exit
                end if
            end do
            if (pos > n) exit
            line = line_of(starts, pos)
            if (text(pos:pos) /= '&' .and. text(pos:pos) /= '$') then
                call fatal_error(error, path//': line '//str(line)//": text outside any namelist group: '"// &
                                 clip(text(pos:line_end(text, pos)))//"' (a group starts with &name and "// &
                                 'ends with /)', error_code%input)
                return
            end if
            first = pos
            first_line = line
            call group_name(text, pos, name)
            if (len_trim(name) == 0 .or. name == 'end') then
                call fatal_error(error, path//': line '//str(line)//": '"//text(first:pos)// &
                                 "' does not start a namelist group (expected &name)", error_code%input)
                return
            end if
            ! inside: until '/' or '&end' outside quotes and comments
            quote = ' '
            last = 0
            do while (pos <= n)
                associate (c => text(pos:pos))
                    if (quote /= ' ') then
                        if (c == quote) quote = ' '
                    else if (c == "'" .or. c == '"') then
                        quote = c
                    else if (c == '!') then
                        pos = line_end(text, pos)
                    else if (c == '/') then
                        last = pos
                    else if (c == '&' .or. c == '$') then
                        if (lower(text(pos + 1:min(pos + 3, n))) == 'end') then
                            last = pos + 3
                        else
                            call fatal_error(error, path//': line '//str(line_of(starts, pos))//': group &'// &
                                             trim(name)//' (line '//str(first_line)// &
                                             ") is not closed with '/' before the next group starts", &
                                             error_code%input)
                            return
                        end if
                    end if
                end associate
                if (last > 0) exit
                pos = pos + 1
            end do
            if (last == 0) then
                call fatal_error(error, path//': group &'//trim(name)//' (line '//str(first_line)// &
                                 ") is not closed: a group ends with '/'", error_code%input)
                return
            end if
            call append(groups, found, name, first_line, records(text, starts, first, last))
            pos = last + 1
        end do
        call resize(groups, found, found)
    end subroutine scan_groups

    !> Add a group after the `n` of `groups` (its size doubled when full, so that
    !> many groups cost linear time; moved by hand: gfortran 12 corrupts the heap
    !> building an array constructor of this type, whose component is a
    !> deferred-length character array).
    pure subroutine append(groups, n, name, line, text)
        type(nml_group_t), allocatable, intent(inout) :: groups(:)
        integer, intent(inout) :: n
        character(len=*), intent(in) :: name
        integer, intent(in) :: line
        character(len=*), intent(in) :: text(:)
        if (n == size(groups)) call resize(groups, n, max(16, 2*n))
        n = n + 1
        groups(n)%name = name
        groups(n)%line = line
        allocate (character(len=len(text)) :: groups(n)%text(size(text)))
        groups(n)%text = text
    end subroutine append

    !> `groups` with room for `capacity` groups, its first `n` kept.
    pure subroutine resize(groups, n, capacity)
        type(nml_group_t), allocatable, intent(inout) :: groups(:)
        integer, intent(in) :: n, capacity
        type(nml_group_t), allocatable :: grown(:)
        integer :: i
        allocate (grown(capacity))
        do i = 1, n
            grown(i)%name = groups(i)%name
            grown(i)%line = groups(i)%line
            call move_alloc(groups(i)%text, grown(i)%text)
        end do
        call move_alloc(grown, groups)
    end subroutine resize

    !> The whole file as one string (lines separated by LF, as stored).
    subroutine read_bytes(path, text, error)
        character(len=*), intent(in) :: path
        character(len=:), allocatable, intent(out) :: text
        type(error_t), allocatable, intent(out) :: error
        integer :: u, ios, size
        character(len=512) :: msg
        open (newunit=u, file=path, access='stream', form='unformatted', status='old', action='read', &
              iostat=ios, iomsg=msg)
        if (ios /= 0) then
            call fatal_error(error, "case file '"//path//"' cannot be read: "//trim(msg), error_code%input)
            return
        end if
        inquire (unit=u, size=size)
        allocate (character(len=max(size, 0)) :: text)
        if (size > 0) read (u, iostat=ios, iomsg=msg) text
        close (u)
        if (ios /= 0) call fatal_error(error, "case file '"//path//"' cannot be read: "//trim(msg), &
                                       error_code%input)
    end subroutine read_bytes

    !> Positions where each line starts.
    pure subroutine line_starts(text, starts)
        character(len=*), intent(in) :: text
        integer, allocatable, intent(out) :: starts(:)
        integer :: i, k
        allocate (starts(count([(text(i:i) == new_line('a'), i=1, len(text))]) + 1))
        starts(1) = 1
        k = 1
        do i = 1, len(text)
            if (text(i:i) /= new_line('a')) cycle
            k = k + 1
            starts(k) = i + 1
        end do
    end subroutine line_starts

    !> Line number of position `pos` (`starts` ascending: bisection, so that a file
    !> of many groups is scanned in linear time).
    pure integer function line_of(starts, pos)
        integer, intent(in) :: starts(:), pos
        integer :: lo, hi, mid
        ! invariant: starts(lo) <= pos < starts(hi + 1)
        lo = 1
        hi = size(starts)
        do while (lo < hi)
            mid = (lo + hi + 1)/2
            if (starts(mid) <= pos) then
                lo = mid
            else
                hi = mid - 1
            end if
        end do
        line_of = lo
    end function line_of

    !> Position of the last character of the line that holds `pos` (before its LF).
    pure integer function line_end(text, pos)
        character(len=*), intent(in) :: text
        integer, intent(in) :: pos
        line_end = index(text(pos:), new_line('a'))
        if (line_end == 0) then
            line_end = len(text)
        else
            line_end = pos + line_end - 2
        end if
    end function line_end

    !> Read the name after the '&' or '$' at `pos` (letters, digits, '_'), lower
    !> case; `pos` ends on its last character. Longer than 32 characters: ''.
    pure subroutine group_name(text, pos, name)
        character(len=*), intent(in) :: text
        integer, intent(inout) :: pos
        character(len=32), intent(out) :: name
        integer :: i
        i = pos + 1
        do while (i <= len(text))
            if (.not. is_name_char(text(i:i))) exit
            i = i + 1
        end do
        name = ''
        if (i - pos - 1 <= len(name)) name = lower(text(pos + 1:i - 1))
        pos = i - 1
    end subroutine group_name

    pure logical function is_name_char(c)
        character, intent(in) :: c
        is_name_char = (c >= 'a' .and. c <= 'z') .or. (c >= 'A' .and. c <= 'Z') .or. &
                       (c >= '0' .and. c <= '9') .or. c == '_'
    end function is_name_char

    !> Space, tab, CR, LF (and form feed).
    pure logical function is_blank(c)
        character, intent(in) :: c
        is_blank = c == ' ' .or. c == achar(9) .or. c == achar(13) .or. c == achar(10) .or. c == achar(12)
    end function is_blank

    !> The text from `first` to `last` as one record per line (CR removed).
    pure function records(text, starts, first, last) result(lines)
        character(len=*), intent(in) :: text
        integer, intent(in) :: starts(:), first, last
        character(len=:), allocatable :: lines(:)
        integer :: l1, l2, l, a, b, width
        l1 = line_of(starts, first)
        l2 = line_of(starts, last)
        width = 1
        do l = l1, l2
            call bounds(l, a, b)
            width = max(width, b - a + 1)
        end do
        allocate (character(len=width) :: lines(l2 - l1 + 1))
        do l = l1, l2
            call bounds(l, a, b)
            lines(l - l1 + 1) = text(a:b)
        end do
    contains
        pure subroutine bounds(l, a, b)
            integer, intent(in) :: l
            integer, intent(out) :: a, b
            a = max(starts(l), first)
            b = min(line_end(text, starts(l)), last)
            do while (b >= a)
                if (text(b:b) /= achar(13)) exit
                b = b - 1
            end do
        end subroutine bounds
    end function records

    !> At most 60 characters of `text`, '...' when cut.
    pure function clip(text) result(short)
        character(len=*), intent(in) :: text
        character(len=:), allocatable :: short
        if (len(text) > 60) then
            short = text(1:57)//'...'
        else
            short = text
        end if
    end function clip

    !> Error for a namelist group that could not be read. The group's text is
    !> re-read one assignment at a time through `try` to name the variable at fault
    !> and why: unknown, more values than it holds, an index out of range, or a
    !> value of the wrong type or form.
    subroutine group_error(path, group, text, ios, msg, try, error)
        character(len=*), intent(in) :: path, group
        !> The group's text (`nml_group_t%text`).
        character(len=*), intent(in) :: text(:)
        integer, intent(in) :: ios
        character(len=*), intent(in) :: msg
        procedure(assignment_reader) :: try
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: assignments(:), name, value
        character(len=512) :: msg1
        integer :: k, ios1, eq, held

        if (is_iostat_end(ios)) then
            call fatal_error(error, path//': group &'//group//' is missing', error_code%input)
            return
        end if
        call group_assignments(text, assignments)
        do k = 1, size(assignments)
            msg1 = ''
            call try('&'//group//' '//assignments(k)//' /', ios1, msg1)
            if (ios1 == 0) cycle
            eq = index(assignments(k), '=')
            name = trim(adjustl(assignments(k)(1:max(eq - 1, 0))))
            value = trim(adjustl(assignments(k)(eq + 1:)))
            if (index(msg1, 'Cannot match namelist object name '//name) > 0 .or. &
                index(msg1, 'Cannot match namelist object name '//lower(name)) > 0) then
                call fatal_error(error, path//': &'//group//": unknown variable '"//name//"'", &
                                 error_code%input)
            else if (index(msg1, 'out of range') > 0) then
                call fatal_error(error, path//': &'//group//": '"//name//"': index out of range ("// &
                                 trim(msg1)//')', error_code%input)
            else
                held = values_held(group, name, value, try)
                if (held == 1) then
                    call fatal_error(error, path//': &'//group//": variable '"//name//"' takes one value ("// &
                                     str(count_values(value))//' given)', error_code%input)
                else if (held >= 0) then
                    call fatal_error(error, path//': &'//group//": variable '"//name//"' takes at most "// &
                                     str(held)//' values ('//str(count_values(value))//' given)', &
                                     error_code%input)
                else
                    call fatal_error(error, path//': &'//group//": variable '"//name// &
                                     "' has a value of the wrong type or form: "//value//' ('// &
                                     trim(msg1)//')', error_code%input)
                end if
            end if
            return
        end do
        call fatal_error(error, path//': &'//group//': '//trim(msg), error_code%input)
    end subroutine group_error

    !> How many values `name` takes, when `value` (a list that failed to read) fails
    !> only because it is too long: the longest leading part of the list that reads
    !> (by bisection); -1 when the first value alone does not read.
    integer function values_held(group, name, value, try)
        character(len=*), intent(in) :: group, name, value
        procedure(assignment_reader) :: try
        integer, allocatable :: first(:), last(:)
        integer :: lo, hi, mid
        call split_values(value, first, last)
        values_held = -1
        if (size(first) < 2) return
        if (.not. list_reads(group, name, value(1:last(1)), try)) return
        lo = 1
        hi = size(first)
        do while (hi - lo > 1)
            mid = (lo + hi)/2
            if (list_reads(group, name, value(1:last(mid)), try)) then
                lo = mid
            else
                hi = mid
            end if
        end do
        ! a list that fails for another reason at its end (a bad last value) is not too long
        if (hi == size(first)) then
            if (list_reads(group, name, value(first(hi):last(hi)), try)) values_held = lo
        end if
    end function values_held

    !> Does `name = list` read as an assignment of `group`?
    logical function list_reads(group, name, list, try)
        character(len=*), intent(in) :: group, name, list
        procedure(assignment_reader) :: try
        character(len=512) :: msg
        integer :: ios
        msg = ''
        call try('&'//group//' '//name//' = '//list//' /', ios, msg)
        list_reads = ios == 0
    end function list_reads

    !> Where the values of a list are (first and last character of each), split at
    !> commas and blanks outside quotes.
    pure subroutine split_values(value, first, last)
        character(len=*), intent(in) :: value
        integer, allocatable, intent(out) :: first(:), last(:)
        integer, allocatable :: a(:), b(:)
        integer :: i, start, n
        character :: quote
        allocate (a(len(value) + 1), b(len(value) + 1))
        n = 0
        start = 0
        quote = ' '
        do i = 1, len(value) + 1
            if (i <= len(value)) then
                if (quote /= ' ') then
                    if (value(i:i) == quote) quote = ' '
                    cycle
                end if
                if (value(i:i) == "'" .or. value(i:i) == '"') then
                    quote = value(i:i)
                    if (start == 0) start = i
                    cycle
                end if
                if (value(i:i) /= ',' .and. .not. is_blank(value(i:i))) then
                    if (start == 0) start = i
                    cycle
                end if
            end if
            if (start > 0) then
                n = n + 1
                a(n) = start
                b(n) = i - 1
                start = 0
            end if
        end do
        first = a(1:n)
        last = b(1:n)
    end subroutine split_values

    !> Number of values in a list.
    pure integer function count_values(value)
        character(len=*), intent(in) :: value
        integer, allocatable :: first(:), last(:)
        call split_values(value, first, last)
        count_values = size(first)
    end function count_values

    !> The `name = value` assignments of a group's text, one per entry, wherever
    !> they start (several on a line, or one over several lines; the '&name' and
    !> the closing '/' removed): an assignment starts at a name (letters, digits,
    !> '_', '%', an optional `(index)`) followed by '=', outside quotes.
    pure subroutine group_assignments(text, assignments)
        character(len=*), intent(in) :: text(:)
        character(len=:), allocatable, intent(out) :: assignments(:)
        character(len=:), allocatable :: joined, t
        integer, allocatable :: starts(:)
        integer :: l, n, width, k, cut, i, a, b

        joined = ''
        do l = 1, size(text)
            t = trim(strip_comment(text(l)))
            if (l == 1) then
                t = adjustl(t)
                cut = 1
                do while (cut < len(t))
                    if (.not. is_name_char(t(cut + 1:cut + 1))) exit
                    cut = cut + 1
                end do
                t = t(cut + 1:)
            end if
            joined = joined//' '//t
        end do
        joined = trim(joined)
        if (len(joined) > 0) then
            if (joined(len(joined):len(joined)) == '/') joined = joined(1:len(joined) - 1)
        end if
        if (len(joined) >= 4) then
            if (lower(joined(len(joined) - 3:)) == '&end' .or. lower(joined(len(joined) - 3:)) == '$end') &
                joined = joined(1:len(joined) - 4)
        end if
        call assignment_starts(joined, starts)
        n = size(starts)
        allocate (character(len=1) :: assignments(0))
        if (n == 0) return
        starts = [starts, len(joined) + 1]
        width = 1
        do k = 1, n
            width = max(width, starts(k + 1) - starts(k))
        end do
        deallocate (assignments)
        allocate (character(len=width) :: assignments(n))
        do k = 1, n
            a = starts(k)
            b = starts(k + 1) - 1
            ! the separator before the next assignment is not part of this one
            do i = b, a, -1
                if (joined(i:i) /= ',' .and. .not. is_blank(joined(i:i))) exit
                b = i - 1
            end do
            assignments(k) = joined(a:b)
        end do
    end subroutine group_assignments

    !> Where the assignments of a group's joined text start (see `group_assignments`).
    pure subroutine assignment_starts(text, starts)
        character(len=*), intent(in) :: text
        integer, allocatable, intent(out) :: starts(:)
        integer, allocatable :: found(:)
        integer :: i, j, depth, n
        character :: quote
        allocate (found(len(text) + 1))
        n = 0
        quote = ' '
        i = 1
        do while (i <= len(text))
            associate (c => text(i:i))
                if (quote /= ' ') then
                    if (c == quote) quote = ' '
                else if (c == "'" .or. c == '"') then
                    quote = c
                else if (is_name_char(c) .or. c == '%') then
                    if (i == 1 .or. is_separator(text(max(i - 1, 1):max(i - 1, 1)))) then
                        ! a name, an optional (index), blanks, then '='
                        j = i
                        do while (j <= len(text))
                            if (.not. (is_name_char(text(j:j)) .or. text(j:j) == '%')) exit
                            j = j + 1
                        end do
                        if (j <= len(text)) then
                            if (text(j:j) == '(') then
                                depth = index(text(j:), ')')
                                if (depth > 0) j = j + depth
                            end if
                        end if
                        do while (j <= len(text))
                            if (.not. is_blank(text(j:j))) exit
                            j = j + 1
                        end do
                        if (j <= len(text)) then
                            if (text(j:j) == '=') then
                                n = n + 1
                                found(n) = i
                            end if
                        end if
                        i = max(i, j - 1)
                    end if
                end if
            end associate
            i = i + 1
        end do
        starts = found(1:n)
    end subroutine assignment_starts

    !> A blank or ',' (what may come before a name that starts an assignment).
    pure logical function is_separator(c)
        character, intent(in) :: c
        is_separator = is_blank(c) .or. c == ','
    end function is_separator

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

end module voiga_io_input_namelist
