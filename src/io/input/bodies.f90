!> From a case to the discretized bodies: read each body's coarse patch from the
!> geometry file, check that the discretizations the case asks for fit (their
!> size counted first, `voiga_io_input_resources`), then build each with the case's layout;
!> and read the curves of the rigid obstacles the contact pairs name.
module voiga_io_input_bodies
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_io_input_case, only: case_t
    use voiga_model_body, only: body_settings_t
    use voiga_io_hdf5, only: h5file_t
    use voiga_io_input_geometry, only: read_patch, read_volume, read_curve, read_surface
    use voiga_io_input_resources, only: check_size
    use voiga_nurbs_surface, only: nurbs_surface_t, surface_patch
    use voiga_nurbs_patch, only: nurbs_patch_t
    use voiga_discretization_patch, only: discretization_t, new_discretization
    use voiga_discretization_size, only: body_size_t, body_size
    use voiga_discretization_layout, only: validate_layout
    use voiga_contact_factory, only: contact_settings_t
    use voiga_text, only: str
    use voiga_kinds, only: dp
    implicit none
    private

    public :: discretize_bodies, read_rigid_curves

    !> A body's exact patch as the geometry file gives it, and its boundaries' names.
    type :: coarse_body_t
        type(nurbs_patch_t) :: patch
        character(len=32), allocatable :: names(:)
    end type coarse_body_t

contains

    !> Discretize every body of `case`; `discs` has one entry per body, in order.
    !> `memory_check` (default true): refuse a run whose memory estimate exceeds
    !> the memory available.
    subroutine discretize_bodies(case, discs, error, memory_check)
        type(case_t), intent(in) :: case
        type(discretization_t), allocatable, intent(out) :: discs(:)
        type(error_t), allocatable, intent(out) :: error
        logical, intent(in), optional :: memory_check
        type(coarse_body_t), allocatable :: coarse(:)
        type(body_size_t), allocatable :: sizes(:)
        logical :: check_memory
        integer :: i

        check_memory = .true.
        if (present(memory_check)) check_memory = memory_check
        call read_patches(case, coarse, error)
        if (allocated(error)) return
        call check_dimensions(case, coarse, error)
        if (allocated(error)) return
        allocate (sizes(size(coarse)))
        do i = 1, size(coarse)
            call check_contact_key(case%bodies(i), coarse(i)%patch%pdim, case%path, error)
            if (allocated(error)) return
            ! the counts are taken from a layout known to be valid
            call validate_layout(case%bodies(i)%layout, coarse(i)%patch%pdim, case%path//": &body '"// &
                                 trim(case%bodies(i)%name)//"': ", error)
            if (allocated(error)) return
            sizes(i) = body_size(coarse(i)%patch, coarse(i)%names, case%bodies(i)%layout)
        end do
        call check_size(sizes, case%solver%linear_solver, check_memory, case%path//': ', error)
        if (allocated(error)) return
        allocate (discs(size(case%bodies)))
        do i = 1, size(case%bodies)
            call new_discretization(discs(i), coarse(i)%patch, coarse(i)%names, case%bodies(i)%layout, &
                                    case%path//": &body '"//trim(case%bodies(i)%name)//"': ", error)
            if (allocated(error)) return
        end do
    end subroutine discretize_bodies

    !> The bodies of a case are all plane or all solid, and its `&contact` groups fit
    !> that dimension (`check_contact_dimension`).
    subroutine check_dimensions(case, coarse, error)
        type(case_t), intent(in) :: case
        type(coarse_body_t), intent(in) :: coarse(:)
        type(error_t), allocatable, intent(out) :: error
        integer :: i
        do i = 2, size(coarse)
            if (coarse(i)%patch%pdim /= coarse(1)%patch%pdim) then
                call fatal_error(error, case%path//": &body '"//trim(case%bodies(i)%name)//"' is "// &
                                 kind_of(coarse(i)%patch%pdim)//" but &body '"//trim(case%bodies(1)%name)// &
                                 "' is "//kind_of(coarse(1)%patch%pdim)//': the bodies of a case must all be '// &
                                 'plane or all be solids', error_code%input)
                return
            end if
        end do
        if (size(coarse) == 0) return
        do i = 1, size(case%contact)
            call check_contact_dimension(case%contact(i), coarse(1)%patch%pdim, &
                                         case%path//': &contact ('//str(i)//'): ', error)
            if (allocated(error)) return
        end do
    end subroutine check_dimensions

    !> A rigid master's point and normal have `nsd` components (or none given: the
    !> origin, and the normal +y in 2D, +z in 3D: `rigid_normal_of`); rigid_uz only in a solid case,
    !> rigid_curve only in a plane one, rigid_surface only in a solid one. Every method, with or
    !> without friction, runs in both dimensions.
    subroutine check_contact_dimension(c, nsd, where, error)
        type(contact_settings_t), intent(in) :: c
        integer, intent(in) :: nsd
        character(len=*), intent(in) :: where
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: what
        if (all(c%point_components /= [0, nsd])) then
            what = 'rigid_point needs '//str(nsd)//' components'
        else if (all(c%normal_components /= [0, nsd])) then
            what = 'rigid_normal needs '//str(nsd)//' components'
        else if (nsd == 2 .and. c%motion_z) then
            what = 'rigid_uz moves a rigid master along z: a plane case has no z'
        else if (nsd == 2 .and. len_trim(c%rigid_surface) > 0) then
            what = 'rigid_surface bounds a rigid obstacle of a solid case: in a plane case use rigid_curve'
        else if (nsd == 3 .and. len_trim(c%rigid_curve) > 0) then
            what = 'rigid_curve bounds a rigid obstacle of a plane case: in a solid case use rigid_surface '// &
                   '(a surface of the geometry file)'
        end if
        if (allocated(what)) call fatal_error(error, where//what, error_code%input)
    end subroutine check_contact_dimension

    !> 'a plane body' or 'a solid'.
    pure function kind_of(pdim) result(words)
        integer, intent(in) :: pdim
        character(len=:), allocatable :: words
        words = 'a solid'
        if (pdim == 2) words = 'a plane body'
    end function kind_of

    !> A plane body's contact boundary is an edge (`contact_edge`), a solid's a face
    !> (`contact_face`): the key the case used must fit the body's geometry.
    subroutine check_contact_key(body, pdim, path, error)
        type(body_settings_t), intent(in) :: body
        integer, intent(in) :: pdim
        character(len=*), intent(in) :: path
        type(error_t), allocatable, intent(out) :: error
        character(len=12) :: expected
        character(len=:), allocatable :: what
        if (len_trim(body%layout%contact_edge) == 0) return
        expected = merge('contact_edge', 'contact_face', pdim == 2)
        if (body%contact_key == expected) return
        what = 'a volume (its boundaries are faces)'
        if (pdim == 2) what = 'a plane patch (its boundaries are edges)'
        call fatal_error(error, path//": &body '"//trim(body%name)//"': "//trim(body%contact_key)//" = '"// &
                         trim(body%layout%contact_edge)//"': the body is "//what//': use '//trim(expected), &
                         error_code%input)
    end subroutine check_contact_key

    !> The coarse patch of every body of `case`, from its geometry file.
    subroutine read_patches(case, coarse, error)
        type(case_t), intent(in) :: case
        type(coarse_body_t), allocatable, intent(out) :: coarse(:)
        type(error_t), allocatable, intent(out) :: error
        type(h5file_t) :: geo
        type(error_t), allocatable :: close_error
        type(nurbs_surface_t) :: plane
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
                allocate (coarse(i)%names(6))
                call read_volume(geo, case%bodies(i)%name, coarse(i)%patch, coarse(i)%names, error)
            else
                call read_patch(geo, case%bodies(i)%name, plane, error)
                if (.not. allocated(error)) then
                    coarse(i)%patch = surface_patch(plane)
                    coarse(i)%names = plane%edge_names
                end if
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

    !> Read the curve of every contact pair whose rigid master is one
    !> (`&contact rigid_curve`) from the geometry file into `case%contact(k)%curve`.
    subroutine read_rigid_curves(case, error)
        type(case_t), intent(inout) :: case
        type(error_t), allocatable, intent(out) :: error
        type(h5file_t) :: geo
        type(error_t), allocatable :: close_error
        character(len=16) :: buf
        integer :: k

        if (all([(len_trim(case%contact(k)%rigid_curve) == 0 .and. len_trim(case%contact(k)%rigid_surface) == 0, &
                  k=1, size(case%contact))])) return
        call geo%open(case%geometry, 'r', error)
        if (allocated(error)) then
            error%message = case%path//': &case: geometry: '//error%message
            return
        end if
        do k = 1, size(case%contact)
            write (buf, '(i0)') k
            if (len_trim(case%contact(k)%rigid_surface) > 0) then
                call read_surface(geo, case%contact(k)%rigid_surface, case%contact(k)%surface, error)
                if (allocated(error)) error%message = case%path//': &contact ('//trim(buf)//'): rigid_surface: '// &
                                                      error%message
            end if
            if (allocated(error)) exit
            if (len_trim(case%contact(k)%rigid_curve) == 0) cycle
            call read_curve(geo, case%contact(k)%rigid_curve, case%contact(k)%curve, error)
            if (allocated(error)) then
                error%message = case%path//': &contact ('//trim(buf)//'): rigid_curve: '//error%message
                exit
            end if
        end do
        call geo%close(close_error)
        if (.not. allocated(error) .and. allocated(close_error)) call move_alloc(close_error, error)
    end subroutine read_rigid_curves

end module voiga_io_input_bodies
