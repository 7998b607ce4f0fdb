!> Linear (small-strain) isotropic elasticity, plane strain:
!> sigma = lambda tr(eps) I + 2 mu eps, eps = sym(grad u).
module voiga_material_linear
    use voiga_kinds, only: dp
    use voiga_material, only: material_t, identity2, delta
    implicit none
    private

    public :: linear_elastic_t

    !> Small-strain Hooke material.
    type, extends(material_t) :: linear_elastic_t
    contains
        procedure :: stress => linear_stress
        procedure :: stress3 => linear_stress3
        procedure :: fields => linear_fields
        procedure, nopass :: strain_name => linear_strain_name
    end type linear_elastic_t

contains

    pure subroutine linear_stress(self, grad_u, s, c, ok)
        class(linear_elastic_t), intent(in) :: self
        real(dp), intent(in) :: grad_u(2, 2)
        real(dp), intent(out) :: s(2, 2), c(2, 2, 2, 2)
        logical, intent(out) :: ok
        real(dp) :: eps(2, 2)
        integer :: i, j, k, l
        eps = 0.5_dp*(grad_u + transpose(grad_u))
        s = 2.0_dp*self%mu*eps
        s(1, 1) = s(1, 1) + self%lambda*(eps(1, 1) + eps(2, 2))
        s(2, 2) = s(2, 2) + self%lambda*(eps(1, 1) + eps(2, 2))
        do l = 1, 2
            do k = 1, 2
                do j = 1, 2
                    do i = 1, 2
                        c(i, j, k, l) = self%lambda*identity2(i, j)*identity2(k, l) + &
                                        self%mu*(identity2(i, k)*identity2(j, l) + identity2(i, l)*identity2(j, k))
                    end do
                end do
            end do
        end do
        ok = .true.
    end subroutine linear_stress

    !> The small-strain stress (plane strain: sigma_zz = lambda tr(eps)) and eps =
    !> sym(grad u), in the reference configuration (the law's own assumption).
    !> Hooke's law in three dimensions: s = lambda tr(eps) I + 2 mu eps, eps the
    !> symmetric part of grad_u; c = lambda I(x)I + 2 mu I_s.
    pure subroutine linear_stress3(self, grad_u, s, c, ok)
        class(linear_elastic_t), intent(in) :: self
        real(dp), intent(in) :: grad_u(3, 3)
        real(dp), intent(out) :: s(3, 3), c(3, 3, 3, 3)
        logical, intent(out) :: ok
        real(dp) :: eps(3, 3)
        integer :: i, j, k, l
        eps = 0.5_dp*(grad_u + transpose(grad_u))
        do j = 1, 3
            do i = 1, 3
                s(i, j) = 2.0_dp*self%mu*eps(i, j) + self%lambda*(eps(1, 1) + eps(2, 2) + eps(3, 3))*delta(i, j)
            end do
        end do
        do l = 1, 3
            do k = 1, 3
                do j = 1, 3
                    do i = 1, 3
                        ! 2 mu I_s = mu (d_ik d_jl + d_il d_jk)
                        c(i, j, k, l) = self%lambda*delta(i, j)*delta(k, l) + &
                                        self%mu*(delta(i, k)*delta(j, l) + delta(i, l)*delta(j, k))
                    end do
                end do
            end do
        end do
        ok = .true.
    end subroutine linear_stress3

    pure subroutine linear_fields(self, grad_u, stress, strain, ok)
        class(linear_elastic_t), intent(in) :: self
        real(dp), intent(in) :: grad_u(2, 2)
        real(dp), intent(out) :: stress(4), strain(4)
        logical, intent(out) :: ok
        real(dp) :: s(2, 2), c(2, 2, 2, 2)
        call self%stress(grad_u, s, c, ok)
        strain = [grad_u(1, 1), grad_u(2, 2), 0.0_dp, 0.5_dp*(grad_u(1, 2) + grad_u(2, 1))]
        stress = [s(1, 1), s(2, 2), self%lambda*(strain(1) + strain(2)), s(1, 2)]
    end subroutine linear_fields

    pure function linear_strain_name() result(name)
        character(len=:), allocatable :: name
        name = 'small strain sym(grad u)'
    end function linear_strain_name


end module voiga_material_linear
