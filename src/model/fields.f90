!> Stress, strain and von Mises stress sampled in every element of a body, for the
!> result file (`&output`; read by `voiga_io_input_case_output`, written by
!> `voiga_io_output_results` at the steps the case asks for, and only then). The values
!> come from the body's material law (`material_t%fields`): the Cauchy stress and
!> the law's strain measure at each sample point.
!>
!> Samples: `samples` x `samples` points per element on a uniform grid of its
!> parameter range, ends included (`samples` = 1: the element's centre), in the
!> body's oriented patch (contact edge at eta = 1); element by element, xi fastest.
module voiga_model_fields
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_text, only: str, real_str
    use voiga_material, only: von_mises
    use voiga_discretization_element, only: element_basis, element_nfun
    use voiga_element_solid, only: reference_gradients
    use voiga_element_solid3, only: reference_gradients3
    use voiga_nurbs_patch, only: next_index
    use voiga_model_body, only: body_t
    implicit none
    private

    public :: output_settings_t, field_samples_t, sample_fields, field_names

    !> A sample point whose |det dX/dxi| is at most `degenerate` times the element
    !> centre's is degenerate; it is sampled `nudge` of the way to the centre instead
    !> (and recorded at its nominal parameters). Why 1 %: at a collapsed face (a polar
    !> ball's axis) the coincident control points move apart by the discretization's
    !> error, which the gradient divides by the distance from the axis; at 1e-6 of the
    !> way that gave shears of 14 p0 under a Hertz contact, at 1 % it is below 0.2 %.
    real(dp), parameter :: degenerate = 1.0e-8_dp, nudge = 1.0e-2_dp

    !> The fields `&output fields` may name.
    character(len=*), parameter :: field_names(3) = [character(len=9) :: 'stress', 'strain', 'von_mises']

    !> What a case asks to be written besides the displacements (`&output`;
    !> docs/formats.md). Without the group: nothing.
    type :: output_settings_t
        !> Which of `field_names` to write (none: no fields are computed).
        logical :: fields(3) = .false.
        !> Samples per element and direction.
        integer :: samples = 3
        !> Write at every `every`-th step (and the last); 0: at the last step only.
        integer :: every = 1
        !> Or exactly at these steps (overrides `every` when allocated).
        integer, allocatable :: steps(:)
    contains
        procedure :: wants => output_wants
    end type output_settings_t

    !> The fields of one body at its sample points (n of them).
    type :: field_samples_t
        !> Parameters (oriented patch; zeta for a solid only) and element of each point [n].
        real(dp), allocatable :: xi(:), eta(:), zeta(:)
        integer, allocatable :: element(:)
        !> Cauchy stress and strain [4, n] ([xx, yy, zz, xy]; a solid's [6, n], [xx, yy,
        !> zz, xy, yz, xz]), von Mises stress [n].
        real(dp), allocatable :: stress(:, :), strain(:, :), von_mises(:)
    end type field_samples_t

contains

    !> Are fields written at step `step` of `last`?
    pure logical function output_wants(self, step, last) result(wants)
        class(output_settings_t), intent(in) :: self
        integer, intent(in) :: step, last
        wants = .false.
        if (.not. any(self%fields)) return
        if (allocated(self%steps)) then
            wants = any(self%steps == step)
        else
            wants = step == last
            if (self%every > 0) wants = wants .or. mod(step, self%every) == 0
        end if
    end function output_wants

    !> The fields of `body` with the global displacement `u` at `samples` x `samples`
    !> points per element. Fails (numeric) where the deformation is inverted. Where
    !> the reference map is degenerate (det dX/dxi = 0: the centre of a solid disc
    !> sector, whose inner edge is one point, or a corner of 180 degrees), the
    !> gradient is undefined: the point is sampled `nudge` of the way towards the
    !> element's centre instead (the field's limit there), and recorded where it is.
    subroutine sample_fields(body, u, samples, out, error)
        type(body_t), intent(in) :: body
        real(dp), intent(in) :: u(:)
        integer, intent(in) :: samples
        type(field_samples_t), intent(out) :: out
        type(error_t), allocatable, intent(out) :: error
        if (body%disc%pdim == 3) then
            call sample_solid(body, u, samples, out, error)
        else
            call sample_plane(body, u, samples, out, error)
        end if
    end subroutine sample_fields

    !> `sample_fields` of a plane body (samples x samples points per element).
    subroutine sample_plane(body, u, samples, out, error)
        type(body_t), intent(in) :: body
        real(dp), intent(in) :: u(:)
        integer, intent(in) :: samples
        type(field_samples_t), intent(out) :: out
        type(error_t), allocatable, intent(out) :: error
        real(dp), allocatable :: r(:), dr(:, :), dndx(:, :), ue(:, :)
        real(dp) :: t(samples), det, det_centre, grad_u(2, 2), xi, eta, xc, ec
        integer :: e, i, j, q, n, a
        logical :: ok

        n = body%disc%nel*samples**2
        allocate (out%xi(n), out%eta(n), out%element(n), out%stress(4, n), out%strain(4, n), out%von_mises(n))
        t = 0.5_dp
        if (samples > 1) t = [(real(i, dp)/real(samples - 1, dp), i=0, samples - 1)]
        q = 0
        do e = 1, body%disc%nel
            associate (el => body%disc%elements(e))
                allocate (r(element_nfun(body%disc, e)), dr(2, element_nfun(body%disc, e)), &
                          dndx(2, element_nfun(body%disc, e)))
                allocate (ue(2, size(el%conn)))
                do a = 1, size(el%conn)
                    ue(:, a) = u(body%dof0 + 2*el%conn(a) - 1:body%dof0 + 2*el%conn(a))
                end do
                xc = 0.5_dp*(el%lo(1) + el%hi(1))
                ec = 0.5_dp*(el%lo(2) + el%hi(2))
                call element_basis(body%disc, e, [xc, ec], r, dr)
                det_centre = reference_det(body%disc%x(:, el%conn), dr)
                do j = 1, samples
                    eta = el%lo(2) + t(j)*(el%hi(2) - el%lo(2))
                    do i = 1, samples
                        xi = el%lo(1) + t(i)*(el%hi(1) - el%lo(1))
                        q = q + 1
                        call element_basis(body%disc, e, [xi, eta], r, dr)
                        if (abs(reference_det(body%disc%x(:, el%conn), dr)) <= degenerate*abs(det_centre)) &
                            call element_basis(body%disc, e, [xi + nudge*(xc - xi), eta + nudge*(ec - eta)], r, dr)
                        call reference_gradients(body%disc%x(:, el%conn), dr, dndx, det)
                        grad_u = matmul(ue, transpose(dndx))
                        call body%mat%fields(grad_u, out%stress(:, q), out%strain(:, q), ok)
                        if (.not. ok) then
                            call fatal_error(error, "fields: body '"//trim(body%name)//"' element "//str(e)// &
                                             ': the deformation is inverted (J <= 0) at the sample (xi, eta) = ('// &
                                             trim(adjustl(real_str(xi, 'f8.5')))//', '// &
                                             trim(adjustl(real_str(eta, 'f8.5')))//'), between the quadrature '// &
                                             'points, which are not (a corner of 180 degrees in the patch, a '// &
                                             'coarse mesh): a finer mesh there, or &output samples = 1 (the '// &
                                             'element centres)', error_code%numeric)
                            return
                        end if
                        out%von_mises(q) = von_mises(out%stress(:, q))
                        out%xi(q) = xi
                        out%eta(q) = eta
                        out%element(q) = e
                    end do
                end do
                deallocate (r, dr, dndx, ue)
            end associate
        end do
    end subroutine sample_plane

    !> `sample_fields` of a solid: samples^3 points per element (xi fastest), the law's
    !> `fields3`.
    subroutine sample_solid(body, u, samples, out, error)
        type(body_t), intent(in) :: body
        real(dp), intent(in) :: u(:)
        integer, intent(in) :: samples
        type(field_samples_t), intent(out) :: out
        type(error_t), allocatable, intent(out) :: error
        real(dp), allocatable :: r(:), dr(:, :), dndx(:, :), ue(:, :)
        real(dp) :: t(samples), det, det_centre, grad_u(3, 3), uc(3), us(3)
        integer :: e, i, q, n, a, idx(3)
        logical :: ok

        n = body%disc%nel*samples**3
        allocate (out%xi(n), out%eta(n), out%zeta(n), out%element(n), out%stress(6, n), out%strain(6, n), &
                  out%von_mises(n))
        t = 0.5_dp
        if (samples > 1) t = [(real(i, dp)/real(samples - 1, dp), i=0, samples - 1)]
        q = 0
        do e = 1, body%disc%nel
            associate (el => body%disc%elements(e), nen => element_nfun(body%disc, e))
                allocate (r(nen), dr(3, nen), dndx(3, nen), ue(3, nen))
                do a = 1, nen
                    ue(:, a) = u(body%dof0 + 3*el%conn(a) - 2:body%dof0 + 3*el%conn(a))
                end do
                uc = 0.5_dp*(el%lo + el%hi)
                call element_basis(body%disc, e, uc, r, dr)
                call reference_gradients3(body%disc%x(:, el%conn), dr, dndx, det_centre)
                idx = 1
                do i = 1, samples**3
                    q = q + 1
                    us = el%lo + t(idx)*(el%hi - el%lo)
                    call element_basis(body%disc, e, us, r, dr)
                    call reference_gradients3(body%disc%x(:, el%conn), dr, dndx, det)
                    if (abs(det) <= degenerate*abs(det_centre)) then
                        call element_basis(body%disc, e, us + nudge*(uc - us), r, dr)
                        call reference_gradients3(body%disc%x(:, el%conn), dr, dndx, det)
                    end if
                    grad_u = matmul(ue, transpose(dndx))
                    call body%mat%fields3(grad_u, out%stress(:, q), out%strain(:, q), ok)
                    if (.not. ok) then
                        call fatal_error(error, "fields: body '"//trim(body%name)//"' element "//str(e)// &
                                         ': the deformation is inverted (J <= 0) at the sample (xi, eta, zeta) '// &
                                         '= ('//trim(adjustl(real_str(us(1), 'f8.5')))//', '// &
                                         trim(adjustl(real_str(us(2), 'f8.5')))//', '// &
                                         trim(adjustl(real_str(us(3), 'f8.5')))//'), between the quadrature '// &
                                         'points: a finer mesh there, or &output samples = 1', error_code%numeric)
                        return
                    end if
                    out%von_mises(q) = von_mises(out%stress(:, q))
                    out%xi(q) = us(1)
                    out%eta(q) = us(2)
                    out%zeta(q) = us(3)
                    out%element(q) = e
                    call next_index(idx, [samples, samples, samples])
                end do
                deallocate (r, dr, dndx, ue)
            end associate
        end do
    end subroutine sample_solid

    !> det dX/dxi of the reference map at a point (`x0` [2, nen], `dr` [2, nen]).
    pure real(dp) function reference_det(x0, dr) result(det)
        real(dp), intent(in) :: x0(:, :), dr(:, :)
        real(dp) :: jac(2, 2)
        jac = matmul(x0, transpose(dr))
        det = jac(1, 1)*jac(2, 2) - jac(1, 2)*jac(2, 1)
    end function reference_det

end module voiga_model_fields
