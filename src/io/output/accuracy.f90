!> The contact-zone accuracy indicator of a converged step in the result file
!> (`voiga_model_accuracy`; schema in docs/hdf5.md): per contact pair on an edge, the
!> group `contact/<k>/accuracy` with one entry per zone and one per free edge.
module voiga_io_output_accuracy
    use voiga_text, only: str
    use voiga_io_hdf5, only: h5file_t
    use voiga_model, only: model_t
    use voiga_model_accuracy, only: zone_measure_t, edge_measure_t, pair_zones, face_summary, calibration, warn_estimate
    implicit none
    private

    public :: write_accuracy

contains

    !> Every pair's zones of `model` as last evaluated, under the step group `g`
    !> (`g`/contact/<k>/accuracy).
    subroutine write_accuracy(h5, g, model)
        class(h5file_t), intent(inout) :: h5
        character(len=*), intent(in) :: g
        type(model_t), intent(in) :: model
        type(zone_measure_t), allocatable :: zones(:)
        integer :: k
        do k = 1, size(model%pairs)
            zones = pair_zones(model, k)
            call write_zones(h5, g//'/contact/'//str(k)//'/accuracy', zones, model%pairs(k)%pair%slave%npar == 2)
        end do
    end subroutine write_accuracy

    !> The zones as the group `a`: per zone [nz] and per free edge [ne] datasets; the
    !> pair's estimate (of a `face`: its summary's) as an attribute.
    subroutine write_zones(h5, a, zones, face)
        class(h5file_t), intent(inout) :: h5
        character(len=*), intent(in) :: a
        type(zone_measure_t), intent(in) :: zones(:)
        logical, intent(in) :: face
        type(zone_measure_t) :: summary
        integer :: i, j
        integer, allocatable :: owner(:)
        type(edge_measure_t), allocatable :: edges(:)
        call h5%create_group(a)
        call h5%write_attr(a, 'zones', size(zones))
        call h5%write_attr(a, 'calibration', calibration)
        call h5%write_attr(a, 'warn_estimate', warn_estimate)
        if (size(zones) == 0) return
        if (face) then
            summary = face_summary(zones)
            call h5%write_attr(a, 'pair_estimate', summary%estimate)
        else
            call h5%write_attr(a, 'pair_estimate', maxval(zones%estimate))
        end if
        call h5%write(a//'/direction', [zones%direction])
        call h5%write(a//'/line', [zones%line])
        call h5%write(a//'/norm', [zones%norm])
        call h5%write(a//'/n_points', [zones%n_points])
        call h5%write(a//'/elements_across', [zones%elements_across])
        call h5%write(a//'/half_width', [zones%half_width])
        call h5%write(a//'/estimate', [zones%estimate])
        call h5%write(a//'/xi_range', reshape([(zones(i)%xi_range, i=1, size(zones))], [2, size(zones)]))
        owner = [((i, j=1, zones(i)%n_edges), i=1, size(zones))]
        if (size(owner) == 0) return
        edges = [((zones(i)%edges(j), j=1, zones(i)%n_edges), i=1, size(zones))]
        call h5%write(a//'/edge_zone', owner)
        call h5%write(a//'/edge_side', [edges%side])
        call h5%write(a//'/edge_xi', [edges%xi])
        call h5%write(a//'/edge_h_tangent', [edges%h_tangent])
        call h5%write(a//'/edge_h_normal', [edges%h_normal])
        call h5%write(a//'/edge_raw', [edges%raw])
        call h5%write(a//'/edge_bracket', [edges%bracket])
        call h5%write(a//'/edge_vanishing', merge(1, 0, edges%vanishing))
    end subroutine write_zones

end module voiga_io_output_accuracy
