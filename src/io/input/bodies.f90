!> From a case to the discretized bodies: read each body's coarse patch from the
!> geometry file, check that the discretizations the case asks for fit (their
!> size counted first, `voiga_io_input_resources`), then build each with the case's layout;
!> and read the curves of the rigid obstacles the contact pairs name.
module voiga_io_input_bodies
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_io_input_case, only: case_t
    use voiga_io_hdf5, only: h5file_t
    use voiga_io_input_geometry, only: read_patch, read_volume, read_curve
    use voiga_io_input_resources, only: check_size
    use voiga_nurbs_surface, only: nurbs_surface_t
    use voiga_nurbs_patch, only: nurbs_patch_t
    use voiga_discretization_patch, only: discretization_t, new_discretization
    use voiga_discretization_size, only: body_size_t, body_size
    use voiga_discretization_layout, only: validate_layout
    implicit none
    private

    public :: discretize_bodies, read_rigid_curves

contains

    !> Discretize every body of `case`; `discs` has one entry per body, in order.
    !> `memory_check` (default true): refuse a run whose memory estimate exceeds
    !> the memory available.
    subroutine discretize_bodies(case, discs, error, memory_check)
        type(case_t), intent(in) :: case
        type(discretization_t), allocatable, intent(out) :: discs(:)
        type(error_t), allocatable, intent(out) :: error
        logical, intent(in), optional :: memory_check
        type(nurbs_surface_t), allocatable :: coarse(:)
        type(body_size_t), allocatable :: sizes(:)
        logical :: check_memory
        integer :: i

        check_memory = .true.
        if (present(memory_check)) check_memory = memory_check
        call read_patches(case, coarse, error)
        if (allocated(error)) return
        allocate (sizes(size(coarse)))
        do i = 1, size(coarse)
            ! the counts are taken from a layout known to be valid
            call validate_layout(case%bodies(i)%layout, case%path//": &body '"//trim(case%bodies(i)%name)// &
                                 "': ", error)
            if (allocated(error)) return
            sizes(i) = body_size(coarse(i), case%bodies(i)%layout)
        end do
        call check_size(sizes, case%solver%linear_solver, check_memory, case%path//': ', error)
        if (allocated(error)) return
        allocate (discs(size(case%bodies)))
        do i = 1, size(case%bodies)
            call new_discretization(discs(i), coarse(i), case%bodies(i)%layout, &
                                    case%path//": &body '"//trim(case%bodies(i)%name)//"': ", error)
            if (allocated(error)) return
        end do
    end subroutine discretize_bodies

    !> The coarse patch of every body of `case`, from its geometry file.
    subroutine read_patches(case, coarse, error)
        type(case_t), intent(in) :: case
        type(nurbs_surface_t), allocatable, intent(out) :: coarse(:)
        type(error_t), allocatable, intent(out) :: error
        type(h5file_t) :: geo
        type(error_t), allocatable :: close_error
        integer, allocatable :: dims(:)
        integer :: i

        call geo%open(case%geometry, 'r', error)
        if (allocated(error)) then
            error%message = case%path//': &case: geometry: '//error%message
            return
        end if
        allocate (coarse(size(case%bodies)))
        do i = 1, size(case%bodies)
            ! (three degrees: a volume)
            dims = geo%shape('/bodies/'//trim(case%bodies(i)%name)//'/degree')
            if (size(dims) == 1 .and. sum(dims) == 3) then
                call refuse_volume(geo, case%bodies(i)%name, error)
            else
                call read_patch(geo, case%bodies(i)%name, coarse(i), error)
            end if
            if (allocated(error)) then
                error%message = case%path//": &body '"//trim(case%bodies(i)%name)//"': name: "// &
                                error%message
                exit
            end if
        end do
        call geo%close(close_error)
        if (.not. allocated(error) .and. allocated(close_error)) call move_alloc(close_error, error)
    end subroutine read_patches

    !> A volume (a three-dimensional body): read and checked as any patch (a bad one
    !> is refused for its fault), then refused, since the solver takes plane bodies
    !> only so far.
    subroutine refuse_volume(geo, name, error)
        type(h5file_t), intent(inout) :: geo
        character(len=*), intent(in) :: name
        type(error_t), allocatable, intent(out) :: error
        type(nurbs_patch_t) :: volume
        character(len=32) :: faces(6)
        call read_volume(geo, name, volume, faces, error)
        if (allocated(error)) return
        call fatal_error(error, geo%path//": body '"//trim(name)//"' is a volume (a three-dimensional body, "// &
                         'valid): voiga solves plane bodies only so far; docs/formats.md', error_code%input)
    end subroutine refuse_volume

    !> Read the curve of every contact pair whose rigid master is one
    !> (`&contact rigid_curve`) from the geometry file into `case%contact(k)%curve`.
    subroutine read_rigid_curves(case, error)
        type(case_t), intent(inout) :: case
        type(error_t), allocatable, intent(out) :: error
        type(h5file_t) :: geo
        type(error_t), allocatable :: close_error
        character(len=16) :: buf
        integer :: k

        if (all([(len_trim(case%contact(k)%rigid_curve) == 0, k=1, size(case%contact))])) return
        call geo%open(case%geometry, 'r', error)
        if (allocated(error)) then
            error%message = case%path//': &case: geometry: '//error%message
            return
        end if
        do k = 1, size(case%contact)
            if (len_trim(case%contact(k)%rigid_curve) == 0) cycle
            call read_curve(geo, case%contact(k)%rigid_curve, case%contact(k)%curve, error)
            if (allocated(error)) then
                write (buf, '(i0)') k
                error%message = case%path//': &contact ('//trim(buf)//'): rigid_curve: '//error%message
                exit
            end if
        end do
        call geo%close(close_error)
        if (.not. allocated(error) .and. allocated(close_error)) call move_alloc(close_error, error)
    end subroutine read_rigid_curves

end module voiga_io_input_bodies
