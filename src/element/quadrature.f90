!> Gauss-Legendre quadrature on [-1, 1].
module voiga_element_quadrature
    use voiga_kinds, only: dp
    implicit none
    private

    public :: gauss_legendre

contains

    !> `n` points `x` and weights `w` (exact for polynomials of degree 2n-1),
    !> from Newton's method on the Legendre polynomial P_n.
    pure subroutine gauss_legendre(n, x, w)
        integer, intent(in) :: n
        real(dp), intent(out) :: x(n), w(n)
        real(dp), parameter :: pi = acos(-1.0_dp)
        real(dp) :: z, z1, p1, p2, p3, pp
        integer :: i, j, it

        do i = 1, (n + 1)/2
            z = cos(pi*(real(i, dp) - 0.25_dp)/(real(n, dp) + 0.5_dp))
            do it = 1, 100
                p1 = 1.0_dp
                p2 = 0.0_dp
                do j = 1, n
                    p3 = p2
                    p2 = p1
                    p1 = ((2*j - 1)*z*p2 - (j - 1)*p3)/real(j, dp)
                end do
                pp = n*(z*p1 - p2)/(z*z - 1.0_dp)
                z1 = z
                z = z1 - p1/pp
                if (abs(z - z1) <= 1.0e-15_dp) exit
            end do
            x(i) = -z
            x(n + 1 - i) = z
            w(i) = 2.0_dp/((1.0_dp - z*z)*pp*pp)
            w(n + 1 - i) = w(i)
        end do
    end subroutine gauss_legendre

end module voiga_element_quadrature
