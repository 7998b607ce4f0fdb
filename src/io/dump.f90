!> Writing a body's discretization (refined bulk patch, VO layer, DOF counts)
!> to HDF5, in the schema of docs/formats.md ("discretization dump").
module voiga_io_dump
    use voiga_io_hdf5, only: h5file_t
    use voiga_discretization_patch, only: discretization_t
    implicit none
    private

    public :: write_discretization

contains

    !> Write `disc` under group `group` (e.g. '/bodies/die') of the open file `h5`.
    subroutine write_discretization(h5, group, disc)
        type(h5file_t), intent(inout) :: h5
        character(len=*), intent(in) :: group
        type(discretization_t), intent(in) :: disc

        call h5%create_group(group)
        call h5%write_attr(group, 'interface_dofs', disc%interface_dofs)
        call h5%write_attr(group, 'bulk_dofs', disc%bulk_dofs)
        call h5%write_attr(group, 'total_dofs', disc%total_dofs)
        call h5%write_attr(group, 'n_elements', disc%nel)
        call h5%write(group//'/bulk/degree', disc%bulk%degree)
        call h5%write(group//'/bulk/knots_xi', disc%bulk%knots_xi)
        call h5%write(group//'/bulk/knots_eta', disc%bulk%knots_eta)
        call h5%write(group//'/bulk/control_points', disc%bulk%cp)
        call h5%write(group//'/bulk/weights', disc%bulk%w)
        if (disc%has_layer) then
            call h5%write(group//'/layer/degree', [disc%layer%degree])
            call h5%write(group//'/layer/knots', disc%layer%knots)
            call h5%write(group//'/layer/control_points', disc%layer%cp)
            call h5%write(group//'/layer/weights', disc%layer%w)
        end if
    end subroutine write_discretization

end module voiga_io_dump
