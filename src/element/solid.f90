!> Plane-strain solid element kernels: internal force and tangent stiffness of one
!> quadrature point, small strain or finite strain, on any NURBS or VO element.
!>
!> Local DOF order: 2(a-1) + i for function a and component i.
module voiga_element_solid
    use voiga_kinds, only: dp
    use voiga_material, only: material_t
    implicit none
    private

    public :: solid_point, reference_gradients

contains

    !> Reference gradients dN/dX [2, nen] and Jacobian determinant of the map
    !> X = sum_a R_a X_a from the parametric gradients `dr` [2, nen] and the
    !> reference control points `x0` [2, nen]. `det` keeps its sign (a patch
    !> may be negatively oriented; callers integrate with |det|).
    pure subroutine reference_gradients(x0, dr, dndx, det)
        real(dp), intent(in) :: x0(:, :), dr(:, :)
        real(dp), intent(out) :: dndx(:, :)
        real(dp), intent(out) :: det
        real(dp) :: jac(2, 2), inv(2, 2)
        ! jac(i, j) = dX_i / dxi_j
        jac = matmul(x0, transpose(dr))
        det = jac(1, 1)*jac(2, 2) - jac(1, 2)*jac(2, 1)
        inv(1, 1) = jac(2, 2)/det
        inv(2, 2) = jac(1, 1)/det
        inv(1, 2) = -jac(1, 2)/det
        inv(2, 1) = -jac(2, 1)/det
        ! dN/dX_i = sum_j dN/dxi_j dxi_j/dX_i
        dndx = matmul(transpose(inv), dr)
    end subroutine reference_gradients

    !> Add one quadrature point's contribution to `fe` [2 nen] and `ke` [2 nen, 2 nen].
    !> `dndx` [2, nen] reference gradients, `u` [2, nen] displacements, `wdv` the
    !> point's weight times |det| (reference volume). Small strain: f = int B^T sigma,
    !> K = int B^T c B. Finite strain (total Lagrangian, spatial form):
    !> f_a = int tau g_a dV, K_ab = int (g_a . c . g_b + (g_a . tau g_b) I) dV,
    !> g = dN/dx = F^-T dN/dX. `ok` is false if J <= 0 at the point.
    pure subroutine solid_point(mat, dndx, u, wdv, fe, ke, ok)
        class(material_t), intent(in) :: mat
        real(dp), intent(in) :: dndx(:, :), u(:, :)
        real(dp), intent(in) :: wdv
        real(dp), intent(inout) :: fe(:), ke(:, :)
        logical, intent(out) :: ok
        real(dp) :: grad_u(2, 2), s(2, 2), c(2, 2, 2, 2), f(2, 2), finv(2, 2), det, geo
        real(dp) :: g(2, size(dndx, 2)), sg(2), cg(2, 2, 2)
        integer :: a, b, i, k, nen

        nen = size(dndx, 2)
        grad_u = matmul(u, transpose(dndx))
        call mat%stress(grad_u, s, c, ok)
        if (.not. ok) return
        if (mat%finite_strain) then
            f = grad_u
            f(1, 1) = f(1, 1) + 1.0_dp
            f(2, 2) = f(2, 2) + 1.0_dp
            det = f(1, 1)*f(2, 2) - f(1, 2)*f(2, 1)
            finv = reshape([f(2, 2), -f(2, 1), -f(1, 2), f(1, 1)], [2, 2])/det
            g = matmul(transpose(finv), dndx)
        else
            g = dndx
        end if
        do a = 1, nen
            sg = matmul(s, g(:, a))
            fe(2*a - 1:2*a) = fe(2*a - 1:2*a) + wdv*sg
            ! cg(i, k, l) = sum_j g_a,j c(i, j, k, l)
            do i = 1, 2
                cg(i, :, :) = g(1, a)*c(i, 1, :, :) + g(2, a)*c(i, 2, :, :)
            end do
            do b = 1, nen
                do k = 1, 2
                    do i = 1, 2
                        ke(2*a - 2 + i, 2*b - 2 + k) = ke(2*a - 2 + i, 2*b - 2 + k) + &
                                                       wdv*(cg(i, k, 1)*g(1, b) + cg(i, k, 2)*g(2, b))
                    end do
                end do
                if (mat%finite_strain) then
                    geo = wdv*dot_product(g(:, a), matmul(s, g(:, b)))
                    ke(2*a - 1, 2*b - 1) = ke(2*a - 1, 2*b - 1) + geo
                    ke(2*a, 2*b) = ke(2*a, 2*b) + geo
                end if
            end do
        end do
    end subroutine solid_point

end module voiga_element_solid
