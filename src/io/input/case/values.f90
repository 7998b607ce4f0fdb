!> What the readers of the case file's groups share: the marker of a namelist
!> array entry the file did not set, the limits of list lengths, per-phase values
!> and knot lists taken from namelist arrays, and the lookup of a body by name.
module voiga_io_input_case_values
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use, intrinsic :: iso_fortran_env, only: int64
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_model_body, only: body_settings_t
    implicit none
    private

    public :: check_length, unset, is_unset, max_phases, max_knots, max_value, phase_values, take_knots, body_index, &
              check_body_edge, edge_or_face, quoted, either

    !> The bits of `unset`: a quiet NaN with a payload no input can give (the
    !> namelist reader gives every NaN it reads, `NaN(...)` included, the default
    !> payload 0x7FF8000000000000).
    integer(int64), parameter :: unset_bits = int(z'7FF8DEAD0000BEEF', int64)
    !> Largest magnitude of a value (loads, moduli, coordinates): beyond it squares
    !> and products in the residual overflow.
    real(dp), parameter :: max_value = 1.0e100_dp
    !> Most load phases.
    integer, parameter :: max_phases = 64
    !> Most explicit knots one direction of one body may list.
    integer, parameter :: max_knots = 100000

contains

    !> A text value the reader read into a variable longer than `max_length` (the
    !> length kept) is not longer than that: nothing is cut off without a word.
    subroutine check_length(value, max_length, name, where, error)
        character(len=*), intent(in) :: value, name, where
        integer, intent(in) :: max_length
        type(error_t), allocatable, intent(inout) :: error
        character(len=16) :: buf
        if (allocated(error)) return
        if (len_trim(value) <= max_length) return
        write (buf, '(i0)') max_length
        call fatal_error(error, where//name//' is longer than '//trim(buf)//' characters', error_code%input)
    end subroutine check_length

    !> The marker of a namelist entry the file did not set (every real value a user
    !> can write means itself); test with `is_unset`, never with `==` (a NaN). A
    !> function, not a named constant: a module file keeps a NaN constant without
    !> its payload.
    elemental real(dp) function unset()
        unset = transfer(unset_bits, 1.0_dp)
    end function unset

    !> Is `x` the marker of an entry the file did not set?
    elemental logical function is_unset(x)
        real(dp), intent(in) :: x
        is_unset = transfer(x, 0_int64) == unset_bits
    end function is_unset

    !> The names of a list as a message shows them: 'a', 'b', 'c'.
    pure function quoted(names) result(text)
        character(len=*), intent(in) :: names(:)
        character(len=:), allocatable :: text
        integer :: i
        text = ''
        do i = 1, size(names)
            if (i > 1) text = text//', '
            text = text//"'"//trim(names(i))//"'"
        end do
    end function quoted

    !> Values at the end of each phase: exactly one per phase when given; all
    !> zero when the component is prescribed but no value is given.
    subroutine phase_values(raw, used, name, where, nph, values, error)
        real(dp), intent(in) :: raw(:)
        logical, intent(in) :: used
        character(len=*), intent(in) :: name, where
        integer, intent(in) :: nph
        real(dp), intent(out) :: values(:)
        type(error_t), allocatable, intent(out) :: error
        integer :: n
        character(len=128) :: msg
        values = 0.0_dp
        n = count(.not. is_unset(raw))
        if (n == 0) return
        if (.not. used) then
            call fatal_error(error, where//name//' is given but its component is not fixed', &
                             error_code%input)
            return
        end if
        if (n /= nph .or. any(is_unset(raw(1:nph)))) then
            write (msg, '(a,i0,a)') ' needs one value per load phase (', nph, ' phases in &solver n_steps)'
            call fatal_error(error, where//name//trim(msg), error_code%input)
            return
        end if
        if (.not. all(ieee_is_finite(raw(1:nph)))) then
            call fatal_error(error, where//name//' must be finite', error_code%input)
            return
        end if
        if (any(abs(raw(1:nph)) > max_value)) then
            call fatal_error(error, where//name//' must not exceed 1e100 in magnitude', error_code%input)
            return
        end if
        values = raw(1:nph)
    end subroutine phase_values

    !> The entries the file set, which must be a leading block of the array.
    subroutine take_knots(raw, name, where, knots, error)
        real(dp), intent(in) :: raw(:)
        character(len=*), intent(in) :: name, where
        real(dp), allocatable, intent(out) :: knots(:)
        type(error_t), allocatable, intent(out) :: error
        integer :: n
        n = count(.not. is_unset(raw))
        if (n == 0) return
        if (any(is_unset(raw(1:n)))) then
            call fatal_error(error, where//name//' must be given as one list starting at entry 1', &
                             error_code%input)
            return
        end if
        if (.not. all(ieee_is_finite(raw(1:n)))) then
            call fatal_error(error, where//name//' must be finite', error_code%input)
            return
        end if
        knots = raw(1:n)
    end subroutine take_knots

    !> The names of a list as alternatives: 'a' or 'b'; 'a', 'b' or 'c'.
    pure function either(names) result(text)
        character(len=*), intent(in) :: names(:)
        character(len=:), allocatable :: text
        integer :: n
        n = size(names)
        text = quoted(names(n:n))
        if (n > 1) text = quoted(names(1:n - 1))//' or '//text
    end function either

    !> Index of body `name` in `bodies`, 0 if none.
    pure integer function body_index(bodies, name)
        type(body_settings_t), intent(in) :: bodies(:)
        character(len=*), intent(in) :: name
        integer :: i
        body_index = 0
        do i = 1, size(bodies)
            if (trim(bodies(i)%name) == trim(name)) body_index = i
        end do
    end function body_index

    !> A load group names a body of the case and an edge (checked against the
    !> body's edges once it is discretized, `voiga_io_input_case`).
    !> A load names an edge (`edge`, a plane body) or a face (`face`, a solid): one
    !> of them; `edge` holds the name given.
    subroutine edge_or_face(edge, face, where, error)
        character(len=*), intent(inout) :: edge
        character(len=*), intent(in) :: face, where
        type(error_t), allocatable, intent(out) :: error
        if (len_trim(face) == 0) return
        if (len_trim(edge) > 0) then
            call fatal_error(error, where//'give edge (a plane body) or face (a solid), not both', error_code%input)
            return
        end if
        edge = face
    end subroutine edge_or_face

    subroutine check_body_edge(bodies, body, edge, where, error)
        type(body_settings_t), intent(in) :: bodies(:)
        character(len=*), intent(in) :: body, edge, where
        type(error_t), allocatable, intent(out) :: error
        if (body_index(bodies, body) == 0) then
            call fatal_error(error, where//"body = '"//trim(body)//"' is not a body of the case", &
                             error_code%input)
            return
        end if
        if (len_trim(edge) == 0) call fatal_error(error, where//'edge (or face) is required', error_code%input)
    end subroutine check_body_edge

end module voiga_io_input_case_values
