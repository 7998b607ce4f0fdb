!> The `&output` group: which sampled fields the result file gets, at which steps,
!> with how many samples per element (docs/formats.md). Without the group no field
!> is computed.
module voiga_io_input_case_output
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_io_input_namelist, only: group_error
    use voiga_io_input_case_values, only: quoted, check_length
    use voiga_model_fields, only: output_settings_t, field_names
    implicit none
    private

    public :: read_output

    !> Most entries of `steps`.
    integer, parameter :: max_listed = 10000

contains

    !> Read the `&output` group from its text for a run of `n_steps` steps and
    !> validate it. Defaults: every field, 3 samples per element and direction, at
    !> every step.
    subroutine read_output(text, path, n_steps, entry, error)
        !> The group's text (`nml_group_t%text`).
        character(len=*), intent(in) :: text(:)
        integer, intent(in) :: n_steps
        character(len=*), intent(in) :: path
        type(output_settings_t), intent(out) :: entry
        type(error_t), allocatable, intent(out) :: error
        ! one character more than kept: a longer name is refused, not cut
        character(len=17) :: fields(size(field_names) + 1)
        integer :: samples, every, ios, i, k, n
        integer, allocatable :: steps(:), first_read(:)
        logical, allocatable :: given(:)
        character(len=512) :: msg
        character(len=:), allocatable :: where
        namelist /output/ fields, samples, every, steps

        allocate (steps(max_listed))
        fields = ''
        samples = entry%samples
        every = entry%every
        ! the entries of steps the group sets are those two reads with different
        ! fillers agree on (no integer is a marker a user could not write)
        steps = 0
        read (text, nml=output, iostat=ios, iomsg=msg)
        if (ios /= 0) then
            call group_error(path, 'output', text, ios, msg, try_output, error)
            return
        end if
        first_read = steps
        steps = 1
        read (text, nml=output, iostat=ios, iomsg=msg)
        given = steps == first_read
        n = count(given)
        where = path//': &output: '
        do i = 1, size(fields)
            call check_length(fields(i), 16, 'fields', where, error)
            if (allocated(error)) return
        end do
        ! none named: all of them
        if (all(len_trim(fields) == 0)) fields(1:size(field_names)) = field_names
        do i = 1, size(fields)
            if (len_trim(fields(i)) == 0) cycle
            k = findloc(field_names, fields(i), dim=1)
            if (k == 0) then
                call fatal_error(error, where//"fields: '"//trim(fields(i))//"' is not one of "// &
                                 quoted(field_names), error_code%input)
                return
            end if
            entry%fields(k) = .true.
        end do
        if (samples < 1 .or. samples > 20) then
            call fatal_error(error, where//'samples must be between 1 (the element centre) and 20', &
                             error_code%input)
        else if (every < 0) then
            call fatal_error(error, where//'every must be >= 0 (0: the last step only)', error_code%input)
        else if (.not. all(given(1:n))) then
            call fatal_error(error, where//'steps must be one list starting at entry 1', error_code%input)
        else if (any(first_read(1:n) < 1 .or. first_read(1:n) > n_steps)) then
            write (msg, '(a,i0,a)') 'steps must lie between 1 and the number of steps (', n_steps, ')'
            call fatal_error(error, where//trim(msg), error_code%input)
        end if
        if (allocated(error)) return
        entry%samples = samples
        entry%every = every
        if (n > 0) entry%steps = first_read(1:n)
    contains
        subroutine try_output(text, ios, msg)
            character(len=*), intent(in) :: text
            integer, intent(out) :: ios
            character(len=*), intent(inout) :: msg
            ! allow(C181): ios goes back to the caller, which reports it
            read (text, nml=output, iostat=ios, iomsg=msg)
        end subroutine try_output
    end subroutine read_output

end module voiga_io_input_case_output
