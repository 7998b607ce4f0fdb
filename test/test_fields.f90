!> The fields a result file shows (`material_t%fields`, `voiga_model_fields`): the
!> laws' Cauchy stress and strain measures against closed forms, and the sampling
!> of a body (every sample of a linear displacement field on a VO body has its
!> exact strain).
module test_fields
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_testdrive, only: unittest_t, new_unittest, check
    use voiga_material, only: material_t, von_mises
    use voiga_material_factory, only: new_material
    use voiga_discretization_patch, only: discretization_t
    use voiga_model, only: model_t
    use voiga_model_fields, only: output_settings_t, field_samples_t, sample_fields
    use voiga_test_fixtures, only: annulus_sector, paper_layout, scene_t, scene_model, lcg_t, body_settings
    use voiga_discretization_patch, only: new_discretization
    implicit none
    private

    public :: collect_fields

contains

    subroutine collect_fields(testsuite)
        type(unittest_t), allocatable, intent(out) :: testsuite(:)
        testsuite = [ &
                    new_unittest('neo_hookean_cauchy_and_hencky', test_neo_hookean), &
                    new_unittest('linear_stress_plane_strain', test_linear), &
                    new_unittest('samples_of_a_linear_field', test_samples), &
                    new_unittest('output_steps', test_steps) &
                    ]
    end subroutine collect_fields

    !> F = V R with V = Q diag(l1, l2) Q^T (Q a rotation by phi, R by psi): the Hencky
    !> strain is Q diag(ln l1, ln l2) Q^T, the in-plane Cauchy stress tau/J with the
    !> law's tau (`stress`), and sigma_zz = (mu (J^(-2/3) - tr(bbar)/3) + K/2 (J^2 - 1))/J.
    subroutine test_neo_hookean(error)
        type(error_t), allocatable, intent(out) :: error
        class(material_t), allocatable :: mat
        type(lcg_t) :: rng
        real(dp) :: q(2, 2), r(2, 2), v(2, 2), f(2, 2), h(2, 2), tau(2, 2), c(2, 2, 2, 2)
        real(dp) :: stress(4), strain(4), l(2), phi, psi, jac, tr
        logical :: ok
        integer :: k
        call new_material(mat, 'neo-hookean', 2.0_dp, 0.3_dp, error)
        if (allocated(error)) return
        do k = 1, 20
            l = [0.6_dp + 0.8_dp*rng%uniform(), 0.6_dp + 0.8_dp*rng%uniform()]
            if (k == 1) l = [0.9_dp, 0.9_dp]   ! equal stretches: any eigenvectors
            phi = 6.0_dp*rng%uniform()
            psi = 6.0_dp*rng%uniform()
            q = reshape([cos(phi), sin(phi), -sin(phi), cos(phi)], [2, 2])
            r = reshape([cos(psi), sin(psi), -sin(psi), cos(psi)], [2, 2])
            v = matmul(q, matmul(reshape([l(1), 0.0_dp, 0.0_dp, l(2)], [2, 2]), transpose(q)))
            h = matmul(q, matmul(reshape([log(l(1)), 0.0_dp, 0.0_dp, log(l(2))], [2, 2]), transpose(q)))
            f = matmul(v, r)
            call mat%fields(f - reshape([1.0_dp, 0.0_dp, 0.0_dp, 1.0_dp], [2, 2]), stress, strain, ok)
            call check(error, ok, 'admissible')
            if (allocated(error)) return
            ! closed forms evaluated in double precision: 1e-13
            call check(error, maxval(abs(strain - [h(1, 1), h(2, 2), 0.0_dp, h(1, 2)])), 0.0_dp, &
                       'Hencky strain ln V', abs=1.0e-13_dp)
            if (allocated(error)) return
            call mat%stress(f - reshape([1.0_dp, 0.0_dp, 0.0_dp, 1.0_dp], [2, 2]), tau, c, ok)
            jac = l(1)*l(2)
            tr = jac**(-2.0_dp/3.0_dp)*(l(1)**2 + l(2)**2 + 1.0_dp)
            call check(error, maxval(abs(stress - [tau(1, 1), tau(2, 2), &
                                                   mat%mu*(jac**(-2.0_dp/3.0_dp) - tr/3.0_dp) + &
                                                   0.5_dp*mat%kappa*(jac**2 - 1.0_dp), tau(1, 2)]/jac)), 0.0_dp, &
                       'Cauchy stress tau/J', abs=1.0e-13_dp)
            if (allocated(error)) return
        end do
        call mat%fields(reshape([-1.5_dp, 0.0_dp, 0.0_dp, 0.0_dp], [2, 2]), stress, strain, ok)
        call check(error, .not. ok, 'J <= 0 is refused')
    end subroutine test_neo_hookean

    !> Small strain: sigma_zz = nu (sigma_xx + sigma_yy), the strain is sym(grad u)
    !> (tensor shear), von Mises of a pure shear is sqrt(3) |tau|.
    subroutine test_linear(error)
        type(error_t), allocatable, intent(out) :: error
        class(material_t), allocatable :: mat
        real(dp) :: stress(4), strain(4)
        logical :: ok
        call new_material(mat, 'linear', 3.0_dp, 0.25_dp, error)
        if (allocated(error)) return
        call mat%fields(reshape([1.0e-3_dp, 4.0e-3_dp, -2.0e-3_dp, -5.0e-4_dp], [2, 2]), stress, strain, ok)
        call check(error, maxval(abs(strain - [1.0e-3_dp, -5.0e-4_dp, 0.0_dp, 1.0e-3_dp])), 0.0_dp, &
                   'eps = sym(grad u)', abs=1.0e-18_dp)
        if (allocated(error)) return
        call check(error, stress(3), 0.25_dp*(stress(1) + stress(2)), 'sigma_zz = nu (sigma_xx + sigma_yy)', &
                   rel=1.0e-14_dp)
        if (allocated(error)) return
        call check(error, stress(4), 2.0_dp*mat%mu*1.0e-3_dp, 'sigma_xy = 2 mu eps_xy', rel=1.0e-14_dp)
        if (allocated(error)) return
        call check(error, von_mises([0.0_dp, 0.0_dp, 0.0_dp, 2.0_dp]), sqrt(3.0_dp)*2.0_dp, 'pure shear', &
                   rel=1.0e-15_dp)
    end subroutine test_linear

    !> A linear displacement u = G X on a curved VO body (NN2.2, an annular sector
    !> with its layer): every sample's strain is sym(G), to round-off, at points
    !> ordered element by element, xi fastest, ends included.
    subroutine test_samples(error)
        type(error_t), allocatable, intent(out) :: error
        type(scene_t) :: c
        type(discretization_t) :: disc(1)
        type(model_t) :: model
        type(field_samples_t) :: f
        real(dp), parameter :: g(2, 2) = reshape([2.0e-3_dp, -1.0e-3_dp, 3.0e-3_dp, -4.0e-3_dp], [2, 2])
        real(dp), allocatable :: u(:)
        integer :: a
        c%bodies = [body_settings('ring', 'linear', 1.0_dp, paper_layout('NN2.2', [4, 2], 'outer'))]
        call new_discretization(disc(1), annulus_sector([0.0_dp, 0.0_dp], 1.0_dp, 2.0_dp, 0.0_dp, 2), &
                                c%bodies(1)%layout, '', error)
        if (allocated(error)) return
        call scene_model(c, disc, model, error)
        if (allocated(error)) return
        allocate (u(model%ndof))
        do a = 1, model%bodies(1)%disc%ncp
            u(2*a - 1:2*a) = matmul(g, model%bodies(1)%disc%x(:, a))
        end do
        call sample_fields(model%bodies(1), u, 3, f, error)
        if (allocated(error)) return
        call check(error, size(f%xi) == 9*model%bodies(1)%disc%nel, '3 x 3 samples per element')
        if (allocated(error)) return
        call check(error, maxval(abs(f%strain(1, :) - g(1, 1))) + maxval(abs(f%strain(2, :) - g(2, 2))) + &
                   maxval(abs(f%strain(4, :) - 0.5_dp*(g(1, 2) + g(2, 1)))), 0.0_dp, 'exact strain', abs=1.0e-14_dp)
        if (allocated(error)) return
        associate (e1 => model%bodies(1)%disc%elements(1))
            call check(error, f%element(1) == 1 .and. f%element(10) == 2 .and. f%xi(1) == e1%lo(1) .and. &
                       f%xi(2) == 0.5_dp*(e1%lo(1) + e1%hi(1)) .and. f%eta(4) == 0.5_dp*(e1%lo(2) + e1%hi(2)), &
                       'order: element by element, xi fastest, ends included')
        end associate
    end subroutine test_samples

    !> `every` (with the last step always), `every = 0` (the last only), explicit
    !> `steps`, and nothing without fields.
    subroutine test_steps(error)
        type(error_t), allocatable, intent(out) :: error
        type(output_settings_t) :: o
        integer :: k
        call check(error, .not. any([(o%wants(k, 5), k=1, 5)]), 'no fields: no step')
        if (allocated(error)) return
        o%fields = [.true., .false., .false.]
        o%every = 2
        call check(error, all([(o%wants(k, 5), k=1, 5)] .eqv. [.false., .true., .false., .true., .true.]), &
                   'every 2nd and the last')
        if (allocated(error)) return
        o%every = 0
        call check(error, all([(o%wants(k, 5), k=1, 5)] .eqv. [.false., .false., .false., .false., .true.]), &
                   'the last only')
        if (allocated(error)) return
        o%steps = [1, 3]
        call check(error, all([(o%wants(k, 5), k=1, 5)] .eqv. [.true., .false., .true., .false., .false.]), &
                   'the listed steps')
    end subroutine test_steps

end module test_fields
