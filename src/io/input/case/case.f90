!> The `&case` group: what the run is (title, scene, mesh, layout), where its
!> geometry is and where its result goes, and how many bodies it has.
module voiga_io_input_case_case
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_io_input_namelist, only: group_error
    use voiga_io_input_case_values, only: check_length
    implicit none
    private

    public :: case_settings_t, read_case_group, resolve_path

    !> Most bodies in a case.
    integer, parameter :: max_bodies = 16
    !> Longest text value of the group (Linux's PATH_MAX, 4096 with its NUL).
    integer, parameter :: max_text = 4095

    !> The `&case` group (docs/formats.md).
    type :: case_settings_t
        character(len=:), allocatable :: title, scene, mesh, layout
        !> Geometry and output files, resolved against the case file's folder.
        character(len=:), allocatable :: geometry, output
        integer :: n_bodies = 0
        !> May the run replace an existing result file at `output`?
        logical :: overwrite = .false.
    end type case_settings_t

contains

    !> `name` relative to `dir` unless it is absolute.
    pure function resolve_path(dir, name) result(path)
        character(len=*), intent(in) :: dir, name
        character(len=:), allocatable :: path
        if (len(name) > 0) then
            if (name(1:1) == '/') then
                path = name
                return
            end if
        end if
        path = dir//name
    end function resolve_path

    !> Read the `&case` group of the case file `path` (folder `dir`) from its text
    !> and validate it. The output defaults to the case file's name with `.h5`.
    subroutine read_case_group(text, path, dir, self, error)
        !> The group's text (`nml_group_t%text`).
        character(len=*), intent(in) :: text(:)
        character(len=*), intent(in) :: path, dir
        type(case_settings_t), intent(inout) :: self
        type(error_t), allocatable, intent(out) :: error
        ! one character more than kept (and than a path may have): refused, not cut
        character(len=max_text + 1) :: title, scene, mesh, layout, geometry, output
        integer :: n_bodies, ios, i
        logical :: overwrite
        character(len=512) :: msg
        namelist /case/ title, scene, mesh, layout, geometry, output, n_bodies, overwrite

        title = ''
        scene = ''
        mesh = ''
        layout = ''
        geometry = ''
        output = ''
        n_bodies = 0
        overwrite = .false.
        read (text, nml=case, iostat=ios, iomsg=msg)
        if (ios /= 0) then
            call group_error(path, 'case', text, ios, msg, try_case, error)
            return
        end if
        call check_length(title, max_text, 'title', path//': &case: ', error)
        call check_length(scene, max_text, 'scene', path//': &case: ', error)
        call check_length(mesh, max_text, 'mesh', path//': &case: ', error)
        call check_length(layout, max_text, 'layout', path//': &case: ', error)
        call check_length(geometry, max_text, 'geometry', path//': &case: ', error)
        call check_length(output, max_text, 'output', path//': &case: ', error)
        if (allocated(error)) return
        self%overwrite = overwrite
        self%title = trim(title)
        self%scene = trim(scene)
        self%mesh = trim(mesh)
        self%layout = trim(layout)
        if (len_trim(geometry) == 0) then
            call fatal_error(error, path//': &case: geometry is required (the geometry HDF5 file)', &
                             error_code%input)
            return
        end if
        self%geometry = resolve_path(dir, trim(geometry))
        if (len_trim(output) == 0) then
            i = index(path, '.', back=.true.)
            if (i <= index(path, '/', back=.true.)) i = len(path) + 1
            self%output = path(1:i - 1)//'.h5'
        else
            self%output = resolve_path(dir, trim(output))
        end if
        if (n_bodies < 1 .or. n_bodies > max_bodies) then
            write (msg, '(a,i0,a,i0,a)') ': &case: n_bodies = ', n_bodies, ' must be between 1 and ', &
                max_bodies, ''
            call fatal_error(error, path//trim(msg), error_code%input)
            return
        end if
        self%n_bodies = n_bodies
    contains
        !> Read one assignment into the &case group (for diagnosis).
        subroutine try_case(text, ios, msg)
            character(len=*), intent(in) :: text
            integer, intent(out) :: ios
            character(len=*), intent(inout) :: msg
            ! allow(C181): ios goes back to the caller, which reports it
            read (text, nml=case, iostat=ios, iomsg=msg)
        end subroutine try_case
    end subroutine read_case_group

end module voiga_io_input_case_case
