!> The sampled fields of a step in the result file (`/steps/<k>/fields/<body>`,
!> docs/hdf5.md): what `&output` asks for, computed by `voiga_model_fields`.
module voiga_io_output_fields
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_io_hdf5, only: h5file_t
    use voiga_model, only: model_t
    use voiga_model_fields, only: output_settings_t, field_samples_t, sample_fields, field_names
    implicit none
    private

    public :: write_fields, sample_bodies

contains

    !> The sampled fields of every body of `model` at `u` (`samples` [n_bodies]):
    !> computed before the step is written, so that a field that cannot be computed
    !> fails the step as a numerical error and leaves the file as it was.
    subroutine sample_bodies(settings, model, u, samples, error)
        type(output_settings_t), intent(in) :: settings
        type(model_t), intent(in) :: model
        real(dp), intent(in) :: u(:)
        type(field_samples_t), allocatable, intent(out) :: samples(:)
        type(error_t), allocatable, intent(out) :: error
        integer :: ib
        allocate (samples(size(model%bodies)))
        do ib = 1, size(model%bodies)
            call sample_fields(model%bodies(ib), u, settings%samples, samples(ib), error)
            if (allocated(error)) return
        end do
    end subroutine sample_bodies

    !> The sampled fields `settings` asks for (`samples`, from `sample_bodies`), of
    !> every body of `model`, under `g`/fields/<body> (docs/hdf5.md); a failure is
    !> kept in `h5` (`h5file_t%check`).
    subroutine write_fields(h5, g, settings, model, samples)
        class(h5file_t), intent(inout) :: h5
        character(len=*), intent(in) :: g
        type(output_settings_t), intent(in) :: settings
        type(model_t), intent(in) :: model
        type(field_samples_t), intent(in) :: samples(:)
        character(len=:), allocatable :: b
        integer :: ib
        do ib = 1, size(model%bodies)
            associate (f => samples(ib))
            b = g//'/fields/'//trim(model%bodies(ib)%name)
            call h5%create_group(b)
            call h5%write_attr(b, 'samples', settings%samples)
            call h5%write_attr(b, 'components', trim(merge('xx yy zz xy      ', 'xx yy zz xy yz xz', &
                                                           size(f%stress, 1) == 4)))
            call h5%write_attr(b, 'stress_measure', 'Cauchy')
            call h5%write_attr(b, 'strain_measure', model%bodies(ib)%mat%strain_name())
            call h5%write(b//'/xi', f%xi)
            call h5%write(b//'/eta', f%eta)
            if (allocated(f%zeta)) call h5%write(b//'/zeta', f%zeta)
            call h5%write(b//'/element', f%element)
            if (settings%fields(1)) call h5%write(b//'/'//trim(field_names(1)), f%stress)
            if (settings%fields(2)) call h5%write(b//'/'//trim(field_names(2)), f%strain)
            if (settings%fields(3)) call h5%write(b//'/'//trim(field_names(3)), f%von_mises)
            end associate
        end do
    end subroutine write_fields

end module voiga_io_output_fields
