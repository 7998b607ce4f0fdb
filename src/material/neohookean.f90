!> Compressible Neo-Hookean material at finite strain, plane strain (F33 = 1),
!> in the form used by Sauer and De Lorenzis:
!>   sigma = K/2 (J^2 - 1)/J I + mu J^(-5/3) (b - tr(b)/3 I),
!> i.e. Kirchhoff stress tau = J sigma = K/2 (J^2 - 1) I + mu dev(bbar), bbar = J^(-2/3) b,
!> with b = F F^T (3D, b33 = 1). Spatial tangent of tau (derivation in docs/theory.md):
!>   c = K J^2 I(x)I - K (J^2 - 1) I_s
!>     + 2 mu/3 [ tr(bbar) (I_s + I(x)I/3) - bbar(x)I - I(x)bbar ].
module voiga_material_neohookean
    use voiga_kinds, only: dp
    use voiga_material, only: material_t, identity2
    implicit none
    private

    public :: neo_hookean_t

    !> Compressible Neo-Hookean solid.
    type, extends(material_t) :: neo_hookean_t
    contains
        procedure :: stress => neo_hookean_stress
    end type neo_hookean_t

contains

    pure subroutine neo_hookean_stress(self, grad_u, s, c, ok)
        class(neo_hookean_t), intent(in) :: self
        real(dp), intent(in) :: grad_u(2, 2)
        real(dp), intent(out) :: s(2, 2), c(2, 2, 2, 2)
        logical, intent(out) :: ok
        real(dp) :: f(2, 2), b(2, 2), bbar(2, 2), jac, trbbar, j23
        integer :: i, j, k, l
        real(dp) :: isym

        f = grad_u
        f(1, 1) = f(1, 1) + 1.0_dp
        f(2, 2) = f(2, 2) + 1.0_dp
        jac = f(1, 1)*f(2, 2) - f(1, 2)*f(2, 1)
        ok = jac > 0.0_dp
        if (.not. ok) then
            s = 0.0_dp
            c = 0.0_dp
            return
        end if
        b = matmul(f, transpose(f))
        j23 = jac**(-2.0_dp/3.0_dp)
        bbar = j23*b
        ! out-of-plane b33 = 1 enters the trace
        trbbar = bbar(1, 1) + bbar(2, 2) + j23
        s = self%mu*bbar
        do i = 1, 2
            s(i, i) = s(i, i) - self%mu*trbbar/3.0_dp + 0.5_dp*self%kappa*(jac**2 - 1.0_dp)
        end do
        do l = 1, 2
            do k = 1, 2
                do j = 1, 2
                    do i = 1, 2
                        isym = 0.5_dp*(identity2(i, k)*identity2(j, l) + identity2(i, l)*identity2(j, k))
                        c(i, j, k, l) = self%kappa*jac**2*identity2(i, j)*identity2(k, l) &
                                        - self%kappa*(jac**2 - 1.0_dp)*isym &
                                        + 2.0_dp*self%mu/3.0_dp*(trbbar*(isym + identity2(i, j)*identity2(k, l)/3.0_dp) &
                                                                 - bbar(i, j)*identity2(k, l) - identity2(i, j)*bbar(k, l))
                    end do
                end do
            end do
        end do
    end subroutine neo_hookean_stress


end module voiga_material_neohookean
