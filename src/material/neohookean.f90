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
    use voiga_material, only: material_t, delta
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

    !> Points `neo_hookean_points` takes at once: its per-point arrays have this
    !> fixed size (on the stack; its loops over them are vector loops).
    integer, parameter :: chunk = 16

    !> Compressible Neo-Hookean solid.
    type, extends(material_t) :: neo_hookean_t
    contains
        procedure :: stress => neo_hookean_stress
        procedure :: stress3 => neo_hookean_stress3
        procedure :: stress_points => neo_hookean_points
        procedure :: fields => neo_hookean_fields
        procedure, nopass :: strain_name => neo_hookean_strain_name
    end type neo_hookean_t

    !> The kinematics and stress at up to `chunk` points: J, the isochoric left
    !> Cauchy-Green tensor bbar (in plane, [11, 22, 12]; bbar33 = J^(-2/3)), its 3D
    !> trace and the Kirchhoff stress tau [11, 22, 12] (both symmetric to the bit).
    type :: kirchhoff_t
        real(dp) :: jac(chunk), bbar(chunk, 3), trbbar(chunk), tau(chunk, 3)
    end type kirchhoff_t

contains

    !> J, bbar, tr(bbar) and tau (`k`) at the points q0 .. q0 + n - 1 (n <= chunk) of
    !> the displacement gradients `gu` (q, i, j); `ok` false (and `k` undefined) when
    !> J <= 0 at one of them.
    pure subroutine kirchhoff(self, gu, q0, n, k, ok)
        class(neo_hookean_t), intent(in) :: self
        real(dp), intent(in) :: gu(:, :, :)
        integer, intent(in) :: q0, n
        type(kirchhoff_t), intent(out) :: k
        logical, intent(out) :: ok
        real(dp) :: j23(chunk), f11, f21, f12, f22
        integer :: i, q
        do i = 1, n
            q = q0 + i - 1
            k%jac(i) = (gu(q, 1, 1) + 1.0_dp)*(gu(q, 2, 2) + 1.0_dp) - gu(q, 1, 2)*gu(q, 2, 1)
        end do
        ok = all(k%jac(1:n) > 0.0_dp)
        if (.not. ok) return
        ! J^(-2/3) from C's cbrt (half the time of pow), a call per point outside the
        ! vector loop
        do i = 1, n
            j23(i) = cbrt(k%jac(i))
        end do
        do i = 1, n
            q = q0 + i - 1
            f11 = gu(q, 1, 1) + 1.0_dp
            f21 = gu(q, 2, 1)
            f12 = gu(q, 1, 2)
            f22 = gu(q, 2, 2) + 1.0_dp
            j23(i) = 1.0_dp/(j23(i)*j23(i))
            ! bbar = J^(-2/3) F F^T, the product summed from zero as matmul does it
            k%bbar(i, 1) = j23(i)*(0.0_dp + f11*f11 + f12*f12)
            k%bbar(i, 2) = j23(i)*(0.0_dp + f21*f21 + f22*f22)
            k%bbar(i, 3) = j23(i)*(0.0_dp + f11*f21 + f12*f22)
            ! out-of-plane b33 = 1 enters the trace
            k%trbbar(i) = k%bbar(i, 1) + k%bbar(i, 2) + j23(i)
            k%tau(i, 1) = self%mu*k%bbar(i, 1) - self%mu*k%trbbar(i)/3.0_dp + 0.5_dp*self%kappa*(k%jac(i)**2 - 1.0_dp)
            k%tau(i, 2) = self%mu*k%bbar(i, 2) - self%mu*k%trbbar(i)/3.0_dp + 0.5_dp*self%kappa*(k%jac(i)**2 - 1.0_dp)
            k%tau(i, 3) = self%mu*k%bbar(i, 3)
        end do
    end subroutine kirchhoff

    !> tau and its spatial tangent at one point (`neo_hookean_points` at it).
    pure subroutine neo_hookean_stress(self, grad_u, s, c, ok)
        class(neo_hookean_t), intent(in) :: self
        real(dp), intent(in) :: grad_u(2, 2)
        real(dp), intent(out) :: s(2, 2), c(2, 2, 2, 2)
        logical, intent(out) :: ok
        integer, parameter :: voigt(2, 2) = reshape([1, 3, 3, 2], [2, 2])
        real(dp) :: gu(1, 2, 2), sp(1, 2, 2), cv(1, 3, 3)
        integer :: i, j, m, l
        gu(1, :, :) = grad_u
        call neo_hookean_points(self, 1, gu, sp, cv, ok)
        if (.not. ok) then
            s = 0.0_dp
            c = 0.0_dp
            return
        end if
        s = sp(1, :, :)
        ! the tensor has both minor symmetries exactly
        do l = 1, 2
            do m = 1, 2
                do j = 1, 2
                    do i = 1, 2
                        c(i, j, m, l) = cv(1, voigt(i, j), voigt(m, l))
                    end do
                end do
            end do
        end do
    end subroutine neo_hookean_stress

    !> tau and its spatial tangent in three dimensions, the formulas of the header
    !> with b = F F^T of a 3 x 3 F (the plane-strain kernel is this one with F33 = 1);
    !> `ok` false when J <= 0.
    pure subroutine neo_hookean_stress3(self, grad_u, s, c, ok)
        class(neo_hookean_t), intent(in) :: self
        real(dp), intent(in) :: grad_u(3, 3)
        real(dp), intent(out) :: s(3, 3), c(3, 3, 3, 3)
        logical, intent(out) :: ok
        real(dp) :: f(3, 3), bbar(3, 3), jac, trb, a1, b1, dd, is
        integer :: i, j, k, l
        s = 0.0_dp
        c = 0.0_dp
        f = grad_u
        do i = 1, 3
            f(i, i) = f(i, i) + 1.0_dp
        end do
        jac = f(1, 1)*(f(2, 2)*f(3, 3) - f(2, 3)*f(3, 2)) - f(1, 2)*(f(2, 1)*f(3, 3) - f(2, 3)*f(3, 1)) + &
              f(1, 3)*(f(2, 1)*f(3, 2) - f(2, 2)*f(3, 1))
        ok = jac > 0.0_dp
        if (.not. ok) return
        bbar = matmul(f, transpose(f))/cbrt(jac)**2
        trb = bbar(1, 1) + bbar(2, 2) + bbar(3, 3)
        a1 = self%kappa*jac**2
        b1 = self%kappa*(jac**2 - 1.0_dp)
        do j = 1, 3
            do i = 1, 3
                s(i, j) = self%mu*(bbar(i, j) - trb/3.0_dp*delta(i, j)) + 0.5_dp*b1*delta(i, j)
            end do
        end do
        do l = 1, 3
            do k = 1, 3
                do j = 1, 3
                    do i = 1, 3
                        dd = delta(i, j)*delta(k, l)
                        ! the symmetric identity I_s
                        is = 0.5_dp*(delta(i, k)*delta(j, l) + delta(i, l)*delta(j, k))
                        ! the two bbar terms added first: c_ijkl = c_klij to the bit (the 3D
                        ! element then forms six of the nine blocks of K, voiga_element_solid3)
                        c(i, j, k, l) = a1*dd - b1*is + 2.0_dp*self%mu/3.0_dp*(trb*(is + dd/3.0_dp) - &
                                                                               (bbar(i, j)*delta(k, l) + &
                                                                                delta(i, j)*bbar(k, l)))
                    end do
                end do
            end do
        end do
    end subroutine neo_hookean_stress3

    !> tau and the Voigt tangent at `n` points (`material_t%stress_points`), a chunk
    !> of points at a time: the per-point latency chain (cbrt, two divisions) of
    !> one point overlaps the next's, and the loops are vector loops.
    pure subroutine neo_hookean_points(self, n, gu, s, cv, ok)
        class(neo_hookean_t), intent(in) :: self
        integer, intent(in) :: n
        real(dp), intent(in) :: gu(n, 2, 2)
        real(dp), intent(out) :: s(n, 2, 2), cv(n, 3, 3)
        logical, intent(out) :: ok
        type(kirchhoff_t) :: k
        real(dp) :: a1, b1, m3, mixed
        integer :: q0, m, i, q
        ok = .true.
        m3 = 2.0_dp*self%mu/3.0_dp
        do q0 = 1, n, chunk
            m = min(chunk, n - q0 + 1)
            call kirchhoff(self, gu, q0, m, k, ok)
            if (.not. ok) return
            do i = 1, m
                q = q0 + i - 1
                s(q, 1, 1) = k%tau(i, 1)
                s(q, 2, 1) = k%tau(i, 3)
                s(q, 1, 2) = k%tau(i, 3)
                s(q, 2, 2) = k%tau(i, 2)
                ! c = K J^2 I(x)I - K (J^2 - 1) I_s + 2 mu/3 [tr(bbar) (I_s + I(x)I/3)
                ! - bbar(x)I - I(x)bbar], its Voigt entries (11, 22, 12)
                a1 = self%kappa*k%jac(i)**2
                b1 = self%kappa*(k%jac(i)**2 - 1.0_dp)
                cv(q, 1, 1) = a1 - b1 + m3*(k%trbbar(i)*(1.0_dp + 1.0_dp/3.0_dp) - k%bbar(i, 1) - k%bbar(i, 1))
                cv(q, 2, 2) = a1 - b1 + m3*(k%trbbar(i)*(1.0_dp + 1.0_dp/3.0_dp) - k%bbar(i, 2) - k%bbar(i, 2))
                cv(q, 1, 2) = a1 + m3*(k%trbbar(i)*(1.0_dp/3.0_dp) - k%bbar(i, 1) - k%bbar(i, 2))
                ! (the major symmetry exactly: the element then needs three of the four
                ! blocks of K, voiga_element_solid)
                cv(q, 2, 1) = cv(q, 1, 2)
                cv(q, 3, 3) = -b1*0.5_dp + m3*(k%trbbar(i)*0.5_dp)
                ! one of i = j, k = l, the other pair mixed: only a bbar term
                mixed = m3*(-k%bbar(i, 3))
                cv(q, 3, 1) = mixed
                cv(q, 1, 3) = mixed
                cv(q, 3, 2) = mixed
                cv(q, 2, 3) = mixed
            end do
        end do
    end subroutine neo_hookean_points

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
        type(kirchhoff_t) :: k
        real(dp) :: gu(1, 2, 2), f(2, 2), jac, b(2, 2), theta, c, s, l1, l2
        gu(1, :, :) = grad_u
        call kirchhoff(self, gu, 1, 1, k, ok)
        stress = 0.0_dp
        strain = 0.0_dp
        if (.not. ok) return
        jac = k%jac(1)
        stress = [k%tau(1, 1), k%tau(1, 2), self%mu*(jac**(-2.0_dp/3.0_dp) - k%trbbar(1)/3.0_dp) + &
                  0.5_dp*self%kappa*(jac**2 - 1.0_dp), k%tau(1, 3)]/jac
        f = grad_u
        f(1, 1) = f(1, 1) + 1.0_dp
        f(2, 2) = f(2, 2) + 1.0_dp
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
