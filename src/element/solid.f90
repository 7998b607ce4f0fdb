!> Plane-strain solid element kernel: internal force and tangent stiffness of one
!> element from its quadrature points, small strain or finite strain, on any NURBS
!> or VO element.
!>
!> Local DOF order: 2(a-1) + i for function a and component i.
module voiga_element_solid
    use voiga_kinds, only: dp
    use voiga_material, only: material_t
    use voiga_linalg_blas, only: gemm_nt
    implicit none
    private

    public :: solid_element, reference_gradients, element_points_t

    !> The quadrature of one element in the reference configuration, computed once
    !> per discretization: reference gradients dN/dX [2, nen, npts] and weights
    !> times |det dX/dxi| (reference volume) [npts].
    type :: element_points_t
        real(dp), allocatable :: dndx(:, :, :), wdv(:)
    end type element_points_t

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

    !> Internal force `fe` [2 nen] and tangent `ke` [2 nen, 2 nen] of a whole element
    !> from its quadrature points `pts`, with displacements `u` [2, nen]. Small
    !> strain: f = int B^T sigma, K = int B^T c B. Finite strain (total Lagrangian,
    !> spatial form): f_a = int tau g_a dV, K_ab = int (g_a . c . g_b + (g_a . tau g_b) I) dV,
    !> g = dN/dx = F^-T dN/dX. Evaluated as matrix products over all points:
    !> K = B^T D B (material part, Voigt form; the tangents of both laws have minor
    !> symmetries) + G^T T G (geometric part, finite strain only) with B, D, G, T
    !> stacked over the points. The stacks are stored transposed (one column per
    !> point and Voigt component, so that every point fills contiguous columns) and
    !> D B is formed from the gradients directly, without the zeros of B.
    !> `ok` is false if J <= 0 at a point.
    pure subroutine solid_element(mat, pts, u, fe, ke, ok)
        class(material_t), intent(in) :: mat
        type(element_points_t), intent(in) :: pts
        real(dp), intent(in) :: u(:, :)
        real(dp), intent(out) :: fe(:), ke(:, :)
        logical, intent(out) :: ok
        ! B^T and (D B)^T; shape: [2 nen, 3 npts]. Automatic (stack) arrays: no heap
        ! allocation per element; gt, tgt, kg are used by the finite-strain law only
        real(dp) :: bt(2*size(u, 2), 3*size(pts%wdv)), dbt(2*size(u, 2), 3*size(pts%wdv))
        ! G^T and (T G)^T; shape: [nen, 2 npts]
        real(dp) :: gt(size(u, 2), 2*size(pts%wdv)), tgt(size(u, 2), 2*size(pts%wdv)), &
                    kg(size(u, 2), size(u, 2))
        real(dp) :: grad_u(2, 2), s(2, 2), c(2, 2, 2, 2), f(2, 2), finv(2, 2), det, d(3, 3), sv(3)
        real(dp) :: g(2, size(u, 2))
        integer, parameter :: vi(3) = [1, 2, 1], vj(3) = [1, 2, 2]
        integer :: q, nen, i, j, r, a

        nen = size(u, 2)
        fe = 0.0_dp
        do q = 1, size(pts%wdv)
            grad_u = 0.0_dp
            do a = 1, nen
                grad_u(:, 1) = grad_u(:, 1) + u(:, a)*pts%dndx(1, a, q)
                grad_u(:, 2) = grad_u(:, 2) + u(:, a)*pts%dndx(2, a, q)
            end do
            call mat%stress(grad_u, s, c, ok)
            if (.not. ok) return
            if (mat%finite_strain) then
                f = grad_u
                f(1, 1) = f(1, 1) + 1.0_dp
                f(2, 2) = f(2, 2) + 1.0_dp
                det = f(1, 1)*f(2, 2) - f(1, 2)*f(2, 1)
                finv = reshape([f(2, 2), -f(2, 1), -f(1, 2), f(1, 1)], [2, 2])/det
                ! g = finv^T dN/dX
                do a = 1, nen
                    g(1, a) = finv(1, 1)*pts%dndx(1, a, q) + finv(2, 1)*pts%dndx(2, a, q)
                    g(2, a) = finv(1, 2)*pts%dndx(1, a, q) + finv(2, 2)*pts%dndx(2, a, q)
                end do
                gt(:, 2*q - 1) = g(1, :)
                gt(:, 2*q) = g(2, :)
                tgt(:, 2*q - 1) = pts%wdv(q)*(s(1, 1)*g(1, :) + s(1, 2)*g(2, :))
                tgt(:, 2*q) = pts%wdv(q)*(s(2, 1)*g(1, :) + s(2, 2)*g(2, :))
            else
                g = pts%dndx(:, :, q)
            end if
            do j = 1, 3
                do i = 1, 3
                    d(i, j) = pts%wdv(q)*c(vi(i), vj(i), vi(j), vj(j))
                end do
            end do
            sv = pts%wdv(q)*[s(1, 1), s(2, 2), s(1, 2)]
            r = 3*q - 3
            ! columns of B^T: [g1 0], [0 g2], [g2 g1] per function (x, y interleaved)
            bt(1::2, r + 1) = g(1, :)
            bt(2::2, r + 1) = 0.0_dp
            bt(1::2, r + 2) = 0.0_dp
            bt(2::2, r + 2) = g(2, :)
            bt(1::2, r + 3) = g(2, :)
            bt(2::2, r + 3) = g(1, :)
            do i = 1, 3
                dbt(1::2, r + i) = d(i, 1)*g(1, :) + d(i, 3)*g(2, :)
                dbt(2::2, r + i) = d(i, 2)*g(2, :) + d(i, 3)*g(1, :)
            end do
            ! the same sums, in the same order, as f + B^T sv
            fe(1::2) = fe(1::2) + sv(1)*g(1, :) + sv(3)*g(2, :)
            fe(2::2) = fe(2::2) + sv(2)*g(2, :) + sv(3)*g(1, :)
        end do
        call gemm_nt(bt, dbt, ke, 0.0_dp)
        if (mat%finite_strain) then
            call gemm_nt(gt, tgt, kg, 0.0_dp)
            ke(1::2, 1::2) = ke(1::2, 1::2) + kg
            ke(2::2, 2::2) = ke(2::2, 2::2) + kg
        end if
    end subroutine solid_element

end module voiga_element_solid
