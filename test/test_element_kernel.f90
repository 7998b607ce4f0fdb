!> The element kernel (`voiga_element_solid`) against the tangent written out
!> term by term, for a law whose tangent lacks the major symmetry: the kernel then
!> forms the fourth block of K (K^yx) instead of transposing K^xy; and the
!> assembly that adds the kernel's blocks through the element map against the one
!> that adds the interleaved element matrices by DOF numbers; and a law at many
!> points at once (`stress_points`) against the same law point by point.
module test_element_kernel
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_testdrive, only: unittest_t, new_unittest, check
    use, intrinsic :: iso_fortran_env, only: int64
    use voiga_material, only: material_t, voigt_i, voigt_j
    use voiga_material_factory, only: new_material
    use voiga_element_solid, only: solid_element, element_points_t, element_work_t
    use voiga_test_fixtures, only: lcg_t, annulus_sector, paper_layout, scene_t, scene_model, body_settings
    use voiga_discretization_patch, only: discretization_t, new_discretization
    use voiga_model, only: model_t
    use voiga_model_assembly, only: assemble, assembly_stats_t, stiffness_pattern, assembly_map_t, new_assembly_map
    use voiga_linalg_sparse, only: csc_matrix_t
    implicit none
    private

    public :: collect_element_kernel

    !> A small-strain law sigma = c : grad_u with moduli that have the minor
    !> symmetries but not the major one (c_ijkl /= c_klij); not a physical law, a
    !> tangent the symmetric shortcut would get wrong.
    type, extends(material_t) :: skew_law_t
        real(dp) :: c(2, 2, 2, 2) = 0.0_dp
        !> The moduli on three-dimensional gradients (every law has both kernels).
        real(dp) :: c3(3, 3, 3, 3) = 0.0_dp
    contains
        procedure :: stress => skew_stress
        procedure :: stress3 => skew_stress3
        procedure :: fields => skew_fields
        procedure, nopass :: strain_name => skew_strain_name
    end type skew_law_t

contains

    subroutine collect_element_kernel(testsuite)
        type(unittest_t), allocatable, intent(out) :: testsuite(:)
        testsuite = [new_unittest('unsymmetric_tangent_blocks', test_unsymmetric), &
                     new_unittest('mapped_blocks_match_element_matrices', test_mapped_blocks), &
                     new_unittest('law_at_points_is_law_point_by_point', test_law_points)]
    end subroutine collect_element_kernel

    pure subroutine skew_stress(self, grad_u, s, c, ok)
        class(skew_law_t), intent(in) :: self
        real(dp), intent(in) :: grad_u(2, 2)
        real(dp), intent(out) :: s(2, 2), c(2, 2, 2, 2)
        logical, intent(out) :: ok
        integer :: i, j
        do j = 1, 2
            do i = 1, 2
                s(i, j) = sum(self%c(i, j, :, :)*grad_u)
            end do
        end do
        c = self%c
        ok = .true.
    end subroutine skew_stress

    pure subroutine skew_stress3(self, grad_u, s, c, ok)
        class(skew_law_t), intent(in) :: self
        real(dp), intent(in) :: grad_u(3, 3)
        real(dp), intent(out) :: s(3, 3), c(3, 3, 3, 3)
        logical, intent(out) :: ok
        integer :: i, j
        do j = 1, 3
            do i = 1, 3
                s(i, j) = sum(self%c3(i, j, :, :)*grad_u)
            end do
        end do
        c = self%c3
        ok = .true.
    end subroutine skew_stress3

    pure subroutine skew_fields(self, grad_u, stress, strain, ok)
        class(skew_law_t), intent(in) :: self
        real(dp), intent(in) :: grad_u(2, 2)
        real(dp), intent(out) :: stress(4), strain(4)
        logical, intent(out) :: ok
        stress = 0.0_dp
        strain = 0.0_dp
        ok = self%finite_strain .eqv. .false.
    end subroutine skew_fields

    pure function skew_strain_name() result(name)
        character(len=:), allocatable :: name
        name = 'none'
    end function skew_strain_name

    !> Random gradients, weights and displacements on 9 functions and 9 points:
    !> K_(a,i)(b,k) = sum_q w_q sum_jl dN_a/dX_j c_ijkl dN_b/dX_l and
    !> f_(a,i) = sum_q w_q sum_j sigma_ij dN_a/dX_j, against the kernel.
    subroutine test_unsymmetric(error)
        type(error_t), allocatable, intent(out) :: error
        integer, parameter :: nen = 9, np = 9
        type(skew_law_t) :: law
        type(element_points_t) :: pts
        type(element_work_t) :: work
        type(lcg_t) :: rng
        real(dp) :: u(2, nen), fe(2*nen), ke(2*nen, 2*nen), fref(2*nen), kref(2*nen, 2*nen)
        real(dp) :: grad_u(2, 2), s(2, 2), c(2, 2, 2, 2)
        integer :: i, j, k, l, a, b, q
        logical :: ok

        law = skew_law(rng)
        allocate (pts%dndx(2, nen, np), pts%wdv(np))
        do q = 1, np
            pts%wdv(q) = 0.5_dp + rng%uniform()
            do a = 1, nen
                pts%dndx(:, a, q) = [rng%uniform(), rng%uniform()] - 0.5_dp
            end do
        end do
        do a = 1, nen
            u(:, a) = 0.01_dp*([rng%uniform(), rng%uniform()] - 0.5_dp)
        end do

        fref = 0.0_dp
        kref = 0.0_dp
        do q = 1, np
            grad_u = matmul(u, transpose(pts%dndx(:, :, q)))
            call law%stress(grad_u, s, c, ok)
            do a = 1, nen
                do i = 1, 2
                    fref(2*(a - 1) + i) = fref(2*(a - 1) + i) + pts%wdv(q)*sum(s(i, :)*pts%dndx(:, a, q))
                    do b = 1, nen
                        do k = 1, 2
                            do j = 1, 2
                                do l = 1, 2
                                    kref(2*(a - 1) + i, 2*(b - 1) + k) = kref(2*(a - 1) + i, 2*(b - 1) + k) + &
                                        pts%wdv(q)*pts%dndx(j, a, q)*law%c(i, j, k, l)*pts%dndx(l, b, q)
                                end do
                            end do
                        end do
                    end do
                end do
            end do
        end do

        call solid_element(law, pts, u, fe, ke, ok, work)
        call check(error, ok, 'the kernel accepts the state')
        if (allocated(error)) return
        call check(error, maxval(abs(kref - transpose(kref)))/maxval(abs(kref)) > 1.0e-3_dp, &
                   'the reference tangent is unsymmetric')
        if (allocated(error)) return
        call check(error, maxval(abs(ke - kref))/maxval(abs(kref)), 0.0_dp, 'K against the written-out sum', &
                   abs=1.0e-13_dp)
        if (allocated(error)) return
        call check(error, maxval(abs(fe - fref))/maxval(abs(fref)), 0.0_dp, 'f against the written-out sum', &
                   abs=1.0e-13_dp)
    end subroutine test_unsymmetric

    !> `stress_points` at 37 random points (more than one of the Neo-Hookean law's
    !> chunks of 16, and a partial one) gives, bit for bit, what `stress` gives point
    !> by point: the stress and the Voigt entries of the tangent, for the Neo-Hookean
    !> law (its own loop over the points) and for a law that has only `stress` (the
    !> default); and `ok` false when J <= 0 at one point of the last chunk.
    subroutine test_law_points(error)
        type(error_t), allocatable, intent(out) :: error
        integer, parameter :: n = 37
        class(material_t), allocatable :: neo
        type(skew_law_t) :: skew
        type(lcg_t) :: rng
        real(dp) :: gu(n, 2, 2), s(n, 2, 2), cv(n, 3, 3), sq(2, 2), c(2, 2, 2, 2), g(2, 2)
        integer :: q, i, j, law, wrong
        logical :: ok

        call new_material(neo, 'neo-hookean', 3.0_dp, 0.3_dp, error)
        if (allocated(error)) return
        skew = skew_law(rng)
        do q = 1, n
            do j = 1, 2
                do i = 1, 2
                    gu(q, i, j) = 0.6_dp*(rng%uniform() - 0.5_dp)
                end do
            end do
        end do
        gu(5, :, :) = 0.0_dp
        wrong = 0
        do law = 1, 2
            if (law == 1) call neo%stress_points(n, gu, s, cv, ok)
            if (law == 2) call skew%stress_points(n, gu, s, cv, ok)
            call check(error, ok, 'stress_points refused admissible gradients')
            if (allocated(error)) return
            do q = 1, n
                g = gu(q, :, :)
                if (law == 1) call neo%stress(g, sq, c, ok)
                if (law == 2) call skew%stress(g, sq, c, ok)
                if (any(transfer(sq, 1_int64, 4) /= transfer(s(q, :, :), 1_int64, 4))) wrong = wrong + 1
                do j = 1, 3
                    do i = 1, 3
                        if (transfer(c(voigt_i(i), voigt_j(i), voigt_i(j), voigt_j(j)), 1_int64) /= &
                            transfer(cv(q, i, j), 1_int64)) wrong = wrong + 1
                    end do
                end do
            end do
        end do
        call check(error, wrong, 0, 'entries that differ from the law point by point')
        if (allocated(error)) return
        ! F = diag(-1, 1) at point 35: J = -1
        gu(35, :, :) = reshape([-2.0_dp, 0.0_dp, 0.0_dp, 0.0_dp], [2, 2])
        call neo%stress_points(n, gu, s, cv, ok)
        call check(error, .not. ok, 'J <= 0 at one point not refused')
    end subroutine test_law_points

    !> A law with minor but not major symmetry (random Voigt matrix d, made
    !> diagonally dominant).
    function skew_law(rng) result(law)
        type(lcg_t), intent(inout) :: rng
        type(skew_law_t) :: law
        real(dp) :: d(3, 3)
        integer, parameter :: vi(3) = [1, 2, 1], vj(3) = [1, 2, 2]
        integer :: m, n
        do n = 1, 3
            do m = 1, 3
                d(m, n) = rng%uniform() + merge(2.0_dp, 0.0_dp, m == n)
            end do
        end do
        do n = 1, 3
            do m = 1, 3
                law%c(vi(m), vj(m), vi(n), vj(n)) = d(m, n)
                law%c(vj(m), vi(m), vi(n), vj(n)) = d(m, n)
                law%c(vi(m), vj(m), vj(n), vi(n)) = d(m, n)
                law%c(vj(m), vi(m), vj(n), vi(n)) = d(m, n)
            end do
        end do
    end function skew_law

    !> One body (NN2.2 on an annulus sector, its VO layer included) under a random
    !> displacement: the stiffness assembled through the element map (the kernel's
    !> blocks added in place) equals, entry by entry and exactly, the one assembled
    !> from the interleaved element matrices, for the Neo-Hookean law (K^yx taken
    !> as (K^xy)^T) and for a law without the major symmetry (K^yx formed).
    subroutine test_mapped_blocks(error)
        type(error_t), allocatable, intent(out) :: error
        type(scene_t) :: c
        type(discretization_t) :: discs(1)
        type(model_t) :: model
        type(lcg_t) :: rng
        type(csc_matrix_t) :: k_dofs, k_map
        type(assembly_map_t) :: map
        type(assembly_stats_t) :: stats
        real(dp), allocatable :: u(:), r_dofs(:), r_map(:)
        integer :: law, j

        c%bodies = [body_settings('block', 'neo-hookean', 10.0_dp, paper_layout('NN2.2', [3, 2], 'outer'))]
        call new_discretization(discs(1), annulus_sector([2.5_dp, 3.0_dp], 2.0_dp, 3.0_dp, acos(-1.0_dp), 2), &
                                c%bodies(1)%layout, '', error)
        if (allocated(error)) return
        call scene_model(c, discs, model, error)
        if (allocated(error)) return
        allocate (u(model%ndof), r_dofs(model%ndof), r_map(model%ndof))
        do j = 1, model%ndof
            u(j) = 0.02_dp*(rng%uniform() - 0.5_dp)
        end do
        do law = 1, 2
            if (law == 2) then
                deallocate (model%bodies(1)%mat)
                allocate (model%bodies(1)%mat, source=skew_law(rng))
            end if
            call stiffness_pattern(model, k_dofs, error)
            if (allocated(error)) return
            k_map = k_dofs
            call new_assembly_map(model, k_map, map, error)
            if (allocated(error)) return
            map%keep_linear = .false.
            call assemble(model, u, 0.0_dp, r_dofs, stats, error, k_dofs)
            if (allocated(error)) return
            call assemble(model, u, 0.0_dp, r_map, stats, error, k_map, map)
            if (allocated(error)) return
            call check(error, maxval(abs(k_map%values)) > 0.0_dp .and. k_map%missed == 0 .and. k_dofs%missed == 0, &
                       'both assemblies filled their pattern')
            if (allocated(error)) return
            call check(error, maxval(abs(k_map%values - k_dofs%values)), 0.0_dp, &
                       'K through the map against K by DOF numbers, law '//achar(48 + law))
            if (allocated(error)) return
            call check(error, maxval(abs(r_map - r_dofs)), 0.0_dp, 'the residuals, law '//achar(48 + law))
            if (allocated(error)) return
        end do
        call check(error, unsymmetric(k_map), 'the second law gives an unsymmetric K')
    end subroutine test_mapped_blocks

    !> Whether the stored entries of `k` differ from their transposes somewhere.
    logical function unsymmetric(k)
        type(csc_matrix_t), intent(in) :: k
        integer :: j, p
        unsymmetric = .false.
        do j = 1, k%n
            do p = k%colptr(j) + 1, k%colptr(j + 1)
                if (abs(k%values(p) - k%values(k%index_of(j, k%rowind(p) + 1))) > 1.0e-8_dp*maxval(abs(k%values))) &
                    unsymmetric = .true.
            end do
        end do
    end function unsymmetric

end module test_element_kernel
