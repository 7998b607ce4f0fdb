!> Compressible Neo-Hookean material at finite strain, plane strain (F33 = 1),
!> in the form used by Sauer and De Lorenzis:
!>   sigma = K/2 (J^2 - 1)/J I + mu J^(-5/3) (b - tr(b)/3 I),
!> i.e. Kirchhoff stress tau = J sigma = K/2 (J^2 - 1) I + mu dev(bbar), bbar = J^(-2/3) b,
!> with b = F F^T (3D, b33 = 1). Spatial tangent of tau (derivation in docs/theory.md):
!>   c = K J^2 I(x)I - K (J^2 - 1) I_s
!>     + 2 mu/3 [ tr(bbar) (I_s + I(x)I/3) - bbar(x)I - I(x)bbar ].
module voiga_material_neohookean
    use, intrinsic :: iso_c_binding, only: c_double
    use voiga_kinds, only: dp
    use voiga_material, only: material_t, identity2
    implicit none
    private

    public :: neo_hookean_t

    interface
        !> The real cube root (C99, libm).
        pure function cbrt(x) bind(c, name='cbrt')
            import :: c_double
            real(c_double), value, intent(in) :: x
            real(c_double) :: cbrt
        end function cbrt
    end interface

    !> Compressible Neo-Hookean solid.
    type, extends(material_t) :: neo_hookean_t
    contains
        procedure :: stress => neo_hookean_stress
        procedure :: fields => neo_hookean_fields
        procedure, nopass :: strain_name => neo_hookean_strain_name
    end type neo_hookean_t

contains

    !> Deformation gradient, J, the isochoric left Cauchy-Green tensor bbar (in
    !> plane, bbar33 = J^(-2/3)), its 3D trace and the Kirchhoff stress tau (in plane)
    !> at `grad_u`; `ok` false (and the rest undefined) when J <= 0.
    pure subroutine kirchhoff(self, grad_u, f, jac, bbar, trbbar, tau, ok)
        class(neo_hookean_t), intent(in) :: self
        real(dp), intent(in) :: grad_u(2, 2)
        real(dp), intent(out) :: f(2, 2), jac, bbar(2, 2), trbbar, tau(2, 2)
        logical, intent(out) :: ok
        real(dp) :: b(2, 2), j23
        integer :: i
        f = grad_u
        f(1, 1) = f(1, 1) + 1.0_dp
        f(2, 2) = f(2, 2) + 1.0_dp
        jac = f(1, 1)*f(2, 2) - f(1, 2)*f(2, 1)
        ok = jac > 0.0_dp
        if (.not. ok) return
        b = matmul(f, transpose(f))
        ! J^(-2/3) from C's cbrt (half the time of pow, a per-quadrature-point cost)
        j23 = cbrt(jac)
        j23 = 1.0_dp/(j23*j23)
        bbar = j23*b
        ! out-of-plane b33 = 1 enters the trace
        trbbar = bbar(1, 1) + bbar(2, 2) + j23
        tau = self%mu*bbar
        do i = 1, 2
            tau(i, i) = tau(i, i) - self%mu*trbbar/3.0_dp + 0.5_dp*self%kappa*(jac**2 - 1.0_dp)
        end do
    end subroutine kirchhoff

    pure subroutine neo_hookean_stress(self, grad_u, s, c, ok)
        class(neo_hookean_t), intent(in) :: self
        real(dp), intent(in) :: grad_u(2, 2)
        real(dp), intent(out) :: s(2, 2), c(2, 2, 2, 2)
        logical, intent(out) :: ok
        real(dp) :: f(2, 2), bbar(2, 2), jac, trbbar, a1, b1, m3, shear

        call kirchhoff(self, grad_u, f, jac, bbar, trbbar, s, ok)
        if (.not. ok) then
            s = 0.0_dp
            c = 0.0_dp
            return
        end if
        ! the tensor above written out entry by entry (the same terms in the same order
        ! as a loop over i, j, k, l with the identities' ones and zeros; that loop was
        ! half of the element kernel's time)
        a1 = self%kappa*jac**2
        b1 = self%kappa*(jac**2 - 1.0_dp)
        m3 = 2.0_dp*self%mu/3.0_dp
        c(1, 1, 1, 1) = a1 - b1 + m3*(trbbar*(1.0_dp + 1.0_dp/3.0_dp) - bbar(1, 1) - bbar(1, 1))
        c(2, 2, 2, 2) = a1 - b1 + m3*(trbbar*(1.0_dp + 1.0_dp/3.0_dp) - bbar(2, 2) - bbar(2, 2))
        c(1, 1, 2, 2) = a1 + m3*(trbbar*(1.0_dp/3.0_dp) - bbar(1, 1) - bbar(2, 2))
        ! (the tensor's major symmetry exactly: the element then needs three of the four
        ! blocks of K, voiga_element_solid)
        c(2, 2, 1, 1) = c(1, 1, 2, 2)
        shear = -b1*0.5_dp + m3*(trbbar*0.5_dp)
        c(1, 2, 1, 2) = shear
        c(2, 1, 2, 1) = shear
        c(1, 2, 2, 1) = shear
        c(2, 1, 1, 2) = shear
        ! one of i = j, k = l, the other pair mixed: only a bbar term
        c(1, 1, 1, 2) = m3*(-bbar(1, 2))
        c(1, 1, 2, 1) = m3*(-bbar(2, 1))
        c(2, 2, 1, 2) = m3*(-bbar(1, 2))
        c(2, 2, 2, 1) = m3*(-bbar(2, 1))
        c(1, 2, 1, 1) = m3*(-bbar(1, 2))
        c(2, 1, 1, 1) = m3*(-bbar(2, 1))
        c(1, 2, 2, 2) = m3*(-bbar(1, 2))
        c(2, 1, 2, 2) = m3*(-bbar(2, 1))
    end subroutine neo_hookean_stress

    !> The Cauchy stress sigma = tau/J (sigma_zz from tau33 = mu (J^(-2/3) -
    !> tr(bbar)/3) + K/2 (J^2 - 1)) and the logarithmic (Hencky) strain ln V =
    !> 1/2 ln b in the current configuration (zz: ln 1 = 0). ln b from the
    !> eigenvectors of the in-plane b (a rotation by theta with tan 2 theta =
    !> 2 b12/(b11 - b22)): exact also for equal eigenvalues.
    pure subroutine neo_hookean_fields(self, grad_u, stress, strain, ok)
        class(neo_hookean_t), intent(in) :: self
        real(dp), intent(in) :: grad_u(2, 2)
        real(dp), intent(out) :: stress(4), strain(4)
        logical, intent(out) :: ok
        real(dp) :: f(2, 2), bbar(2, 2), jac, trbbar, tau(2, 2), b(2, 2), theta, c, s, l1, l2
        call kirchhoff(self, grad_u, f, jac, bbar, trbbar, tau, ok)
        stress = 0.0_dp
        strain = 0.0_dp
        if (.not. ok) return
        stress = [tau(1, 1), tau(2, 2), self%mu*(jac**(-2.0_dp/3.0_dp) - trbbar/3.0_dp) + &
                  0.5_dp*self%kappa*(jac**2 - 1.0_dp), tau(1, 2)]/jac
        b = matmul(f, transpose(f))
        theta = 0.5_dp*atan2(2.0_dp*b(1, 2), b(1, 1) - b(2, 2))
        c = cos(theta)
        s = sin(theta)
        l1 = 0.5_dp*log(c*c*b(1, 1) + 2.0_dp*c*s*b(1, 2) + s*s*b(2, 2))
        l2 = 0.5_dp*log(s*s*b(1, 1) - 2.0_dp*c*s*b(1, 2) + c*c*b(2, 2))
        strain = [l1*c*c + l2*s*s, l1*s*s + l2*c*c, 0.0_dp, (l1 - l2)*c*s]
    end subroutine neo_hookean_fields

    pure function neo_hookean_strain_name() result(name)
        character(len=:), allocatable :: name
        name = 'logarithmic (Hencky) strain ln V = ln(b)/2'
    end function neo_hookean_strain_name


end module voiga_material_neohookean
