!> Writing a body's discretization (refined bulk patch, VO layer, DOF counts)
!> to HDF5, in the schema of docs/formats.md ("discretization dump").
module voiga_io_output_dump
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_io_hdf5, only: h5file_t
    use voiga_discretization_patch, only: discretization_t
    use voiga_nurbs_curve, only: nurbs_curve_t, curve_from_patch
    use voiga_nurbs_patch, only: nurbs_patch_t
    use voiga_discretization_layout, only: direction_names
    use voiga_io_input_case, only: case_t
    use voiga_io_output_result_file, only: result_file_t
    use voiga_version, only: voiga_version_string
    implicit none
    private

    public :: write_discretization, write_dump, write_curve, write_elements

contains

    !> The dump file `path` (`voiga --dump`): the case's metadata and the refined
    !> bulk patch and VO layer of every body (`discs`, one per body). Written as a
    !> result file is (`result_file_t`): under its lock, as `path`.part, a new file,
    !> renamed to `path` when complete; an earlier file at `path` is replaced only
    !> when `replace` (`--overwrite`), and a failed write leaves it as it was.
    subroutine write_dump(path, case, discs, replace, error)
        character(len=*), intent(in) :: path
        type(case_t), intent(in) :: case
        type(discretization_t), intent(in) :: discs(:)
        logical, intent(in) :: replace
        type(error_t), allocatable, intent(out) :: error
        type(result_file_t) :: h5
        type(error_t), allocatable :: ignored
        integer :: i
        call h5%create(path, replace, error, 'dump file')
        if (allocated(error)) then
            call h5%abandon()
            return
        end if
        call h5%write_attr('/', 'title', case%title)
        call h5%write_attr('/', 'scene', case%scene)
        call h5%write_attr('/', 'mesh', case%mesh)
        call h5%write_attr('/', 'layout', case%layout)
        call h5%write_attr('/', 'voiga_version', voiga_version_string)
        do i = 1, size(discs)
            call write_discretization(h5, '/bodies/'//trim(case%bodies(i)%name), discs(i))
        end do
        call h5%check(error)
        if (allocated(error)) then
            ! nothing of a failed dump is kept
            call h5%close(ignored)
            call h5%abandon()
            return
        end if
        call h5%settle(.true., error)
    end subroutine write_dump

    !> Write `disc` under group `group` (e.g. '/bodies/die') of the open file `h5`;
    !> a failure is kept in `h5` (`h5file_t%check`).
    subroutine write_discretization(h5, group, disc)
        class(h5file_t), intent(inout) :: h5
        character(len=*), intent(in) :: group
        type(discretization_t), intent(in) :: disc
        integer :: d
        call h5%create_group(group)
        call h5%write_attr(group, 'interface_dofs', disc%interface_dofs)
        call h5%write_attr(group, 'bulk_dofs', disc%bulk_dofs)
        call h5%write_attr(group, 'total_dofs', disc%total_dofs)
        call h5%write_attr(group, 'n_elements', disc%nel)
        call h5%write(group//'/bulk/degree', disc%bulk%degree)
        do d = 1, disc%pdim
            call h5%write(group//'/bulk/knots_'//trim(direction_names(d)), disc%bulk%knots(d)%u)
        end do
        ! the patch's arrays shaped [nsd, n_xi, n_eta(, n_zeta)] and [n_xi, n_eta(, n_zeta)]
        ! (h5py: the geometry file's axis order)
        if (disc%pdim == 2) then
            call h5%write(group//'/bulk/control_points', reshape(disc%bulk%cp, [disc%nsd, disc%bulk%n(1), &
                                                                                disc%bulk%n(2)]))
            call h5%write(group//'/bulk/weights', reshape(disc%bulk%w, [disc%bulk%n(1), disc%bulk%n(2)]))
        else
            call h5%write(group//'/bulk/control_points', reshape(disc%bulk%cp, [disc%nsd, disc%bulk%n(1), &
                                                                                disc%bulk%n(2), disc%bulk%n(3)]))
            call h5%write(group//'/bulk/weights', reshape(disc%bulk%w, [disc%bulk%n(1), disc%bulk%n(2), &
                                                                        disc%bulk%n(3)]))
        end if
        if (disc%has_layer) call write_layer(h5, group//'/layer', disc%layer)
    end subroutine write_discretization

    !> Write the VO layer `layer` as the group `group`: degree (pdim,), its knots
    !> (`knots` for a curve, `knots_xi` and `knots_eta` for a surface), control_points
    !> (n, nsd) and weights in h5py's shapes (the schema in docs/formats.md); a
    !> failure is kept in `h5`.
    subroutine write_layer(h5, group, layer)
        class(h5file_t), intent(inout) :: h5
        character(len=*), intent(in) :: group
        type(nurbs_patch_t), intent(in) :: layer
        integer :: d
        if (layer%pdim == 1) then
            call write_curve(h5, group, curve_from_patch(layer))
            return
        end if
        call h5%write(group//'/degree', layer%degree)
        do d = 1, layer%pdim
            call h5%write(group//'/knots_'//trim(direction_names(d)), layer%knots(d)%u)
        end do
        call h5%write(group//'/control_points', layer%cp)
        call h5%write(group//'/weights', layer%w)
    end subroutine write_layer

    !> Write `curve` as the group `group` (degree (1,), knots, control_points (n, 2)
    !> and weights in h5py's shapes; docs/formats.md); a failure is kept in `h5`.
    subroutine write_curve(h5, group, curve)
        class(h5file_t), intent(inout) :: h5
        character(len=*), intent(in) :: group
        type(nurbs_curve_t), intent(in) :: curve
        call h5%write(group//'/degree', [curve%degree])
        call h5%write(group//'/knots', curve%knots)
        call h5%write(group//'/control_points', curve%cp)
        call h5%write(group//'/weights', curve%w)
    end subroutine write_curve

    !> The refined control net of `disc` under group `g` of a result file, and its
    !> element layout as post reads it: elements/ptr and conn (CSR of each element's
    !> control points), elements/vo (1 in the VO layer), elements/range ([xi0, xi1,
    !> eta0, eta1] per element) and each edge's control points (docs/hdf5.md); a
    !> failure is kept in `h5`.
    subroutine write_elements(h5, g, disc)
        class(h5file_t), intent(inout) :: h5
        character(len=*), intent(in) :: g
        type(discretization_t), intent(in) :: disc
        integer :: k, d
        integer, allocatable :: ptr(:), conn(:), vo(:)
        real(dp), allocatable :: ranges(:, :)

        call h5%write(g//'/control_points', disc%x)
        call h5%write(g//'/weights', disc%w)
        allocate (ptr(disc%nel + 1), vo(disc%nel), ranges(2*disc%pdim, disc%nel))
        ptr(1) = 1
        do k = 1, disc%nel
            ptr(k + 1) = ptr(k) + size(disc%elements(k)%conn)
            vo(k) = merge(1, 0, disc%elements(k)%span_layer(1) > 0)
            do d = 1, disc%pdim
                ranges(2*d - 1:2*d, k) = [disc%elements(k)%lo(d), disc%elements(k)%hi(d)]
            end do
        end do
        allocate (conn(ptr(disc%nel + 1) - 1))
        do k = 1, disc%nel
            conn(ptr(k):ptr(k + 1) - 1) = disc%elements(k)%conn
        end do
        call h5%write(g//'/elements/ptr', ptr)
        call h5%write(g//'/elements/conn', conn)
        call h5%write(g//'/elements/vo', vo)
        call h5%write(g//'/elements/range', ranges)
        ! a plane body's boundaries are its edges, a solid's its faces
        do k = 1, size(disc%boundaries)
            call h5%write(g//'/'//trim(merge('edges', 'faces', disc%pdim == 2))//'/'// &
                          trim(disc%boundaries(k)%name), disc%boundaries(k)%cps)
        end do
    end subroutine write_elements

end module voiga_io_output_dump
