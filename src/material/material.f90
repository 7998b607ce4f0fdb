!> Material laws for plane-strain solids. A law returns, for a displacement
!> gradient, the stress and the tangent moduli that the element needs:
!> small strain: Cauchy stress sigma = c : eps with constant c;
!> finite strain: Kirchhoff stress tau(F) and the spatial tangent c_tau with
!> L_v tau = c_tau : d (d the rate of deformation), so that the tangent
!> stiffness is int (grad_x N_a . c_tau . grad_x N_b + grad_x N_a . tau grad_x N_b I) dV.
!> All in-plane: 2 x 2 stresses, 2 x 2 x 2 x 2 moduli; plane strain means F33 = 1.
!> For output (`fields`), each law also gives the Cauchy stress with its
!> out-of-plane component and its own strain measure, as [xx, yy, zz, xy].
module voiga_material
    use voiga_kinds, only: dp
    implicit none
    private

    public :: material_t, lame_from_young, delta, identity2, von_mises, voigt_i, voigt_j

    !> The 2 x 2 identity: delta(i, j) as a constant array, for the inner loops of
    !> the laws (a lookup instead of a call; same values as `delta`).
    real(dp), parameter :: identity2(2, 2) = reshape([1.0_dp, 0.0_dp, 0.0_dp, 1.0_dp], [2, 2])

    !> The Kronecker delta delta(i, j) as a constant 3 x 3 array, for the 3D laws'
    !> elasticity tensors (the symmetric identity I_s = (d_ik d_jl + d_il d_jk) / 2
    !> among them): a lookup in their loops over 81 entries. As a function of this
    !> module it was a call per entry (not inlined across modules): 0.9 us per
    !> evaluation of a law, so the 27 points of a degree-2 3D element took as long as
    !> its product K = G R^T; 0.06 us (Hooke) and 0.18 us (Neo-Hookean) now.
    real(dp), parameter :: delta(3, 3) = reshape([1.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 1.0_dp, 0.0_dp, &
                                                  0.0_dp, 0.0_dp, 1.0_dp], [3, 3])

    !> The index pairs (i, j) of the Voigt components 11, 22, 12: `stress_points`'
    !> tangent cv(q, I, J) = c(voigt_i(I), voigt_j(I), voigt_i(J), voigt_j(J)).
    integer, parameter :: voigt_i(3) = [1, 2, 1], voigt_j(3) = [1, 2, 2]

    !> A material law.
    type, abstract :: material_t
        !> Young's modulus and Poisson's ratio (input), Lame constants and bulk modulus.
        real(dp) :: youngs_modulus = 0.0_dp, poisson_ratio = 0.0_dp
        real(dp) :: lambda = 0.0_dp, mu = 0.0_dp, kappa = 0.0_dp
        !> Does the law need finite-strain kinematics (F, current configuration)?
        logical :: finite_strain = .false.
    contains
        procedure(stress_interface), deferred :: stress
        !> The same law on a three-dimensional body (3 x 3 gradients): the kernel
        !> 3D elements call, beside the plane-strain one.
        procedure(stress3_interface), deferred :: stress3
        procedure :: stress_points => material_stress_points
        procedure :: fields3 => material_fields3
        procedure(fields_interface), deferred :: fields
        procedure(strain_name_interface), deferred, nopass :: strain_name
    end type material_t

    abstract interface
        !> Stress and tangent for the in-plane displacement gradient `grad_u` = du/dX.
        !> Small strain: `s` = Cauchy stress, `c` = elasticity tensor (constant).
        !> Finite strain: `s` = Kirchhoff stress tau, `c` = spatial tangent c_tau.
        !> `ok` is false when the state is inadmissible (J <= 0).
        pure subroutine stress_interface(self, grad_u, s, c, ok)
            import :: material_t, dp
            class(material_t), intent(in) :: self
            real(dp), intent(in) :: grad_u(2, 2)
            real(dp), intent(out) :: s(2, 2), c(2, 2, 2, 2)
            logical, intent(out) :: ok
        end subroutine stress_interface

        !> What a result file shows at a point with displacement gradient `grad_u` =
        !> du/dX: the Cauchy stress (current configuration, plane strain: with its
        !> out-of-plane sigma_zz) and the law's strain measure (`strain_name`), each
        !> [xx, yy, zz, xy] (tensor components: eps_xy, not the engineering shear).
        !> `ok` is false when the state is inadmissible (J <= 0).
        !> `stress` in three dimensions: grad_u, s [3, 3], c [3, 3, 3, 3].
        pure subroutine stress3_interface(self, grad_u, s, c, ok)
            import :: material_t, dp
            class(material_t), intent(in) :: self
            real(dp), intent(in) :: grad_u(3, 3)
            real(dp), intent(out) :: s(3, 3), c(3, 3, 3, 3)
            logical, intent(out) :: ok
        end subroutine stress3_interface

        pure subroutine fields_interface(self, grad_u, stress, strain, ok)
            import :: material_t, dp
            class(material_t), intent(in) :: self
            real(dp), intent(in) :: grad_u(2, 2)
            real(dp), intent(out) :: stress(4), strain(4)
            logical, intent(out) :: ok
        end subroutine fields_interface

        !> The strain measure `fields` gives, as the result file names it.
        pure function strain_name_interface() result(name)
            character(len=:), allocatable :: name
        end function strain_name_interface
    end interface

contains

    !> `stress` at the `n` quadrature points of an element, point index first (the
    !> element kernel's loops over the points are then vector loops): `gu`(q, i, j) =
    !> du_i/dX_j at point q, the stress `s`(q, i, j) and the Voigt tangent
    !> `cv`(q, I, J) (`voigt_i`, `voigt_j`: the components the element uses).
    !> `ok` is false when the state is inadmissible at a point (the rest is then
    !> undefined). This default calls `stress` point by point; a law overrides it
    !> when its own loop over the points is faster, with the same numbers.
    pure subroutine material_stress_points(self, n, gu, s, cv, ok)
        class(material_t), intent(in) :: self
        integer, intent(in) :: n
        real(dp), intent(in) :: gu(n, 2, 2)
        real(dp), intent(out) :: s(n, 2, 2), cv(n, 3, 3)
        logical, intent(out) :: ok
        real(dp) :: g(2, 2), sq(2, 2), c(2, 2, 2, 2)
        integer :: q, i, j
        ok = .true.
        do q = 1, n
            g = gu(q, :, :)
            call self%stress(g, sq, c, ok)
            if (.not. ok) return
            s(q, :, :) = sq
            do j = 1, 3
                do i = 1, 3
                    cv(q, i, j) = c(voigt_i(i), voigt_j(i), voigt_i(j), voigt_j(j))
                end do
            end do
        end do
    end subroutine material_stress_points

    !> Fill the Lame constants and the bulk modulus from E and nu (3D relations;
    !> plane strain uses them unchanged).
    pure subroutine lame_from_young(self, youngs_modulus, poisson_ratio)
        class(material_t), intent(inout) :: self
        real(dp), intent(in) :: youngs_modulus, poisson_ratio
        self%youngs_modulus = youngs_modulus
        self%poisson_ratio = poisson_ratio
        self%mu = youngs_modulus/(2.0_dp*(1.0_dp + poisson_ratio))
        self%lambda = youngs_modulus*poisson_ratio/((1.0_dp + poisson_ratio)*(1.0_dp - 2.0_dp*poisson_ratio))
        self%kappa = youngs_modulus/(3.0_dp*(1.0_dp - 2.0_dp*poisson_ratio))
    end subroutine lame_from_young

    !> The von Mises stress of the stress `s`: [xx, yy, zz, xy] (plane strain: the
    !> out-of-plane component counts) or [xx, yy, zz, xy, yz, xz] (a solid).
    pure real(dp) function von_mises(s)
        real(dp), intent(in) :: s(:)
        von_mises = sqrt(0.5_dp*((s(1) - s(2))**2 + (s(2) - s(3))**2 + (s(3) - s(1))**2) + 3.0_dp*sum(s(4:)**2))
    end function von_mises

    !> What a result file shows of a solid at a point with displacement gradient
    !> `grad_u` (3 x 3): the Cauchy stress and the law's strain measure, each [xx, yy,
    !> zz, xy, yz, xz] (tensor components). From the law's `stress3`: at small strain
    !> its stress and sym(grad u); at finite strain sigma = tau / J and the logarithmic
    !> strain ln V = ln(b)/2 (`strain_name`). `ok` is false when J <= 0.
    pure subroutine material_fields3(self, grad_u, stress, strain, ok)
        class(material_t), intent(in) :: self
        real(dp), intent(in) :: grad_u(3, 3)
        real(dp), intent(out) :: stress(6), strain(6)
        logical, intent(out) :: ok
        real(dp) :: s(3, 3), c(3, 3, 3, 3), f(3, 3), e(3, 3), jac
        call self%stress3(grad_u, s, c, ok)
        stress = 0.0_dp
        strain = 0.0_dp
        if (.not. ok) return
        if (self%finite_strain) then
            f = grad_u + delta
            jac = f(1, 1)*(f(2, 2)*f(3, 3) - f(2, 3)*f(3, 2)) - f(1, 2)*(f(2, 1)*f(3, 3) - f(2, 3)*f(3, 1)) + &
                  f(1, 3)*(f(2, 1)*f(3, 2) - f(2, 2)*f(3, 1))
            s = s/jac
            e = 0.5_dp*symmetric_log(matmul(f, transpose(f)))
        else
            e = 0.5_dp*(grad_u + transpose(grad_u))
        end if
        stress = [s(1, 1), s(2, 2), s(3, 3), s(1, 2), s(2, 3), s(1, 3)]
        strain = [e(1, 1), e(2, 2), e(3, 3), e(1, 2), e(2, 3), e(1, 3)]
    end subroutine material_fields3

    !> The logarithm of a symmetric positive definite 3 x 3 matrix, from its
    !> eigenpairs (cyclic Jacobi rotations until the off-diagonal part is below
    !> round-off of the diagonal).
    pure function symmetric_log(a) result(l)
        real(dp), intent(in) :: a(3, 3)
        real(dp) :: l(3, 3), d(3, 3), v(3, 3), t, c, sn, theta, r(3, 3)
        integer :: sweep, p, q, k
        d = a
        v = delta
        do sweep = 1, 50
            if (sqrt(d(1, 2)**2 + d(1, 3)**2 + d(2, 3)**2) <= 1.0e-15_dp*sqrt(sum([(d(k, k)**2, k=1, 3)]))) exit
            do p = 1, 2
                do q = p + 1, 3
                    if (d(p, q) == 0.0_dp) cycle
                    theta = (d(q, q) - d(p, p))/(2.0_dp*d(p, q))
                    t = sign(1.0_dp, theta)/(abs(theta) + sqrt(theta**2 + 1.0_dp))
                    c = 1.0_dp/sqrt(t**2 + 1.0_dp)
                    sn = t*c
                    r = delta
                    r(p, p) = c
                    r(q, q) = c
                    r(p, q) = sn
                    r(q, p) = -sn
                    d = matmul(transpose(r), matmul(d, r))
                    v = matmul(v, r)
                end do
            end do
        end do
        l = 0.0_dp
        do k = 1, 3
            l = l + log(d(k, k))*spread(v(:, k), 2, 3)*spread(v(:, k), 1, 3)
        end do
    end function symmetric_log

end module voiga_material
