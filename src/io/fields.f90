!> The sampled fields of a step in the result file (`/steps/<k>/fields/<body>`,
!> docs/hdf5.md): what `&output` asks for, computed by `voiga_model_fields`.
module voiga_io_fields
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_io_hdf5, only: h5file_t
    use voiga_model, only: model_t
    use voiga_model_fields, only: output_settings_t, field_samples_t, sample_fields, field_names
    implicit none
    private

    public :: write_fields

contains

    !> The sampled fields `settings` asks for, of every body of `model` at `u`, under
    !> `g`/fields/<body> (docs/hdf5.md).
    subroutine write_fields(h5, g, settings, model, u, error)
        class(h5file_t), intent(inout) :: h5
        character(len=*), intent(in) :: g
        type(output_settings_t), intent(in) :: settings
        type(model_t), intent(in) :: model
        real(dp), intent(in) :: u(:)
        type(error_t), allocatable, intent(out) :: error
        type(field_samples_t) :: f
        character(len=:), allocatable :: b
        integer :: ib
        do ib = 1, size(model%bodies)
            call sample_fields(model%bodies(ib), u, settings%samples, f, error)
            if (allocated(error)) return
            b = g//'/fields/'//trim(model%bodies(ib)%name)
            call h5%create_group(b, error)
            if (allocated(error)) return
            call h5%write_attr(b, 'samples', settings%samples, error)
            if (allocated(error)) return
            call h5%write_attr(b, 'components', 'xx yy zz xy', error)
            if (allocated(error)) return
            call h5%write_attr(b, 'stress_measure', 'Cauchy', error)
            if (allocated(error)) return
            call h5%write_attr(b, 'strain_measure', model%bodies(ib)%mat%strain_name(), error)
            if (allocated(error)) return
            call h5%write(b//'/xi', f%xi, error)
            if (allocated(error)) return
            call h5%write(b//'/eta', f%eta, error)
            if (allocated(error)) return
            call h5%write(b//'/element', f%element, error)
            if (allocated(error)) return
            if (settings%fields(1)) call h5%write(b//'/'//trim(field_names(1)), f%stress, error)
            if (allocated(error)) return
            if (settings%fields(2)) call h5%write(b//'/'//trim(field_names(2)), f%strain, error)
            if (allocated(error)) return
            if (settings%fields(3)) call h5%write(b//'/'//trim(field_names(3)), f%von_mises, error)
            if (allocated(error)) return
        end do
    end subroutine write_fields

end module voiga_io_fields
