!> Three-dimensional solid element kernel: internal force and tangent stiffness of
!> one element (total Lagrangian, large deformation; or small strain) from its
!> quadrature points, on any trivariate NURBS element. The plane-strain kernel is
!> `voiga_element_solid`; this one shares its `element_points_t` (then dN/dX is
!> [3, nen, npts]) and its form: f_a = sum_q w_q tau g_a and K as one product G R^T.
!>
!> Local DOF order: 3(a-1) + i for function a and component i.
module voiga_element_solid3
    use voiga_kinds, only: dp
    use voiga_material, only: material_t
    use voiga_linalg_blas, only: dgemm
    use voiga_nurbs_patch, only: jacobian_determinant
    use voiga_element_solid, only: element_points_t
    implicit none
    private

    public :: solid3_element, solid3_force, reference_gradients3, solid3_work_t

    !> The nine 3 x 3 blocks K^ik of the element matrix (by displacement component:
    !> i of the row function, k of the column function) in the order `solid3_work_t%k9`
    !> holds them: the six with i <= k first (all a law with the major symmetry
    !> needs: K^ki = (K^ik)^T), then K^21, K^31, K^32.
    integer, parameter :: block_i(9) = [1, 1, 1, 2, 2, 3, 2, 3, 3], block_k(9) = [1, 2, 3, 2, 3, 3, 1, 1, 2]
    !> The position of block (i, k) in that order.
    integer, parameter :: block_of(3, 3) = reshape([1, 7, 8, 2, 4, 9, 3, 5, 6], [3, 3])

    !> Work arrays of `solid3_element` kept by its caller over the elements of a body
    !> (gfortran puts automatic arrays on the heap: an allocation per array and
    !> element). G [ld, 3 npts] (columns 3(q-1) + j: the component j of every
    !> function's gradient g at point q), R [9 ld, 3 npts] (the stacked G M^T, one
    !> block per K^ik) and the blocks K^ik side by side [ld, 9 ld], grown to the
    !> largest element they met; per point, exactly [.., npts]: the displacement
    !> gradient, the law's stress, the weighted couplings M^ik of the tangent and F^-1.
    type :: solid3_work_t
        real(dp), allocatable :: gt(:, :), rt(:, :), k9(:, :)
        !> f^T [ld, 3]: the force by function, so that the loops over the functions
        !> are unit-stride vector loops.
        real(dp), allocatable :: ft(:, :)
        !> The displacement gradients du_i/dX_j [3, 3, npts].
        real(dp), allocatable :: gu(:, :, :)
        !> After a call, `s`(:, :, q) is the law's stress at point q (Cauchy at small
        !> strain, Kirchhoff at finite strain) [3, 3, npts].
        real(dp), allocatable :: s(:, :, :)
        !> M^ik_jl = w_q (c_ijkl + delta_ik tau_jl) [3 (j), 3 (l), 9 (block), npts],
        !> and F^-1 [3, 3, npts] (finite strain only).
        real(dp), allocatable :: m(:, :, :, :), finv(:, :, :)
        !> The last element's tangent (`solid3_element`) had the major symmetry at
        !> every point (and tau was symmetric): `k9` then holds only the first six blocks.
        logical :: sym = .true.
    end type solid3_work_t

contains

    !> Reference gradients dN/dX [3, nen] and the Jacobian determinant of the map
    !> X = sum_a R_a X_a from the parametric gradients `dr` [3, nen] and the
    !> reference control points `x0` [3, nen]. `det` keeps its sign (a patch may be
    !> negatively oriented; callers integrate with |det|).
    pure subroutine reference_gradients3(x0, dr, dndx, det)
        real(dp), intent(in) :: x0(:, :), dr(:, :)
        real(dp), intent(out) :: dndx(:, :)
        real(dp), intent(out) :: det
        real(dp) :: jac(3, 3)
        ! jac(i, j) = dX_i / dxi_j
        jac = matmul(x0, transpose(dr))
        det = jacobian_determinant(jac)
        ! dN/dX_i = sum_j dN/dxi_j dxi_j/dX_i
        dndx = matmul(transpose(inverse3(jac, det)), dr)
    end subroutine reference_gradients3

    !> The inverse of a 3 x 3 matrix `a` with determinant `det` (its adjugate / det).
    pure function inverse3(a, det) result(inv)
        real(dp), intent(in) :: a(3, 3), det
        real(dp) :: inv(3, 3)
        inv(1, 1) = (a(2, 2)*a(3, 3) - a(2, 3)*a(3, 2))/det
        inv(1, 2) = (a(1, 3)*a(3, 2) - a(1, 2)*a(3, 3))/det
        inv(1, 3) = (a(1, 2)*a(2, 3) - a(1, 3)*a(2, 2))/det
        inv(2, 1) = (a(2, 3)*a(3, 1) - a(2, 1)*a(3, 3))/det
        inv(2, 2) = (a(1, 1)*a(3, 3) - a(1, 3)*a(3, 1))/det
        inv(2, 3) = (a(1, 3)*a(2, 1) - a(1, 1)*a(2, 3))/det
        inv(3, 1) = (a(2, 1)*a(3, 2) - a(2, 2)*a(3, 1))/det
        inv(3, 2) = (a(1, 2)*a(3, 1) - a(1, 1)*a(3, 2))/det
        inv(3, 3) = (a(1, 1)*a(2, 2) - a(1, 2)*a(2, 1))/det
    end function inverse3

    !> Internal force `fe` [3 nen] and tangent `ke` [3 nen, 3 nen] of a whole element
    !> from its quadrature points `pts` (dndx [3, nen, npts]), with displacements `u`
    !> [3, nen]. Small strain: f = int B^T sigma, K = int B^T c B. Finite strain
    !> (total Lagrangian, spatial form): f_a = int tau g_a dV, K_ab = int (g_a . c . g_b
    !> + (g_a . tau g_b) I) dV, g = dN/dx = F^-T dN/dX. The block K^ik (components i,
    !> k) is K^ik_ab = sum_q g_a^T M^ik_q g_b with M^ik_jl = w (c_ijkl + delta_ik tau_jl):
    !> all nine are one product G R^T (dgemm), G [nen, 3 npts] the stacked gradients
    !> and R [9 nen, 3 npts] the stacked G (M^ik)^T; six when the law's tangent has
    !> the major symmetry at every point (then K^ki = (K^ik)^T). The full tensor c is
    !> used, so a law without the minor symmetries is integrated as it is. `ok` is
    !> false if J <= 0 at a point (finite strain) or the law rejects the state; `fe`
    !> and `ke` are then zero.
    pure subroutine solid3_element(mat, pts, u, fe, ke, ok, work)
        class(material_t), intent(in) :: mat
        type(element_points_t), intent(in) :: pts
        real(dp), intent(in) :: u(:, :)
        real(dp), intent(out) :: fe(:), ke(:, :)
        logical, intent(out) :: ok
        !> The caller's work arrays (allocated here when absent).
        type(solid3_work_t), intent(inout), optional :: work
        type(solid3_work_t) :: own
        if (present(work)) then
            call element_kernel(mat, pts, u, fe, ke, ok, work)
        else
            call element_kernel(mat, pts, u, fe, ke, ok, own)
        end if
    end subroutine solid3_element

    !> The internal force `fe` [3 nen] of an element without its tangent: the
    !> operations of `solid3_element`'s force in the same order, so the same numbers
    !> (a residual whose tangent is not wanted). `ok` as in `solid3_element`.
    pure subroutine solid3_force(mat, pts, u, fe, ok, work)
        class(material_t), intent(in) :: mat
        type(element_points_t), intent(in) :: pts
        real(dp), intent(in) :: u(:, :)
        real(dp), intent(out) :: fe(:)
        logical, intent(out) :: ok
        !> The caller's work arrays (allocated here when absent).
        type(solid3_work_t), intent(inout), optional :: work
        type(solid3_work_t) :: own
        if (present(work)) then
            call force_kernel(mat, pts, u, fe, ok, work)
        else
            call force_kernel(mat, pts, u, fe, ok, own)
        end if
    end subroutine solid3_force

    !> `solid3_force` on the work arrays `wk`.
    pure subroutine force_kernel(mat, pts, u, fe, ok, wk)
        class(material_t), intent(in) :: mat
        type(element_points_t), intent(in) :: pts
        real(dp), intent(in) :: u(:, :)
        real(dp), intent(out) :: fe(:)
        logical, intent(out) :: ok
        type(solid3_work_t), intent(inout) :: wk
        integer :: nen, np
        logical :: sym
        nen = size(u, 2)
        np = size(pts%wdv)
        call fit_work(wk, nen, np)
        call gradients(nen, np, pts%dndx, u, wk%gt, size(wk%gt, 1), wk%gu)
        ! (no tangent: `sym` is not looked at, and `wk%sym` stays the last element's)
        call point_stresses(mat, .false., np, pts%wdv, wk%gu, wk%s, wk%m, wk%finv, sym, ok)
        if (.not. ok) then
            fe = 0.0_dp
            return
        end if
        call point_forces(mat%finite_strain, nen, np, pts%wdv, wk%s, wk%finv, wk%gt, size(wk%gt, 1), wk%ft, fe)
    end subroutine force_kernel

    !> `solid3_element` on the work arrays `wk`.
    pure subroutine element_kernel(mat, pts, u, fe, ke, ok, wk)
        class(material_t), intent(in) :: mat
        type(element_points_t), intent(in) :: pts
        real(dp), intent(in) :: u(:, :)
        real(dp), intent(out) :: fe(:), ke(:, :)
        logical, intent(out) :: ok
        type(solid3_work_t), intent(inout) :: wk
        integer :: nen, np, ld, ldr, nb

        nen = size(u, 2)
        np = size(pts%wdv)
        call fit_work(wk, nen, np)
        ld = size(wk%gt, 1)
        ldr = size(wk%rt, 1)
        call gradients(nen, np, pts%dndx, u, wk%gt, ld, wk%gu)
        call point_stresses(mat, .true., np, pts%wdv, wk%gu, wk%s, wk%m, wk%finv, wk%sym, ok)
        if (.not. ok) then
            fe = 0.0_dp
            ke = 0.0_dp
            return
        end if
        call point_forces(mat%finite_strain, nen, np, pts%wdv, wk%s, wk%finv, wk%gt, ld, wk%ft, fe)
        nb = merge(6, 9, wk%sym)
        call point_columns(nen, np, nb, wk%m, wk%gt, ld, wk%rt, ldr)
        ! [K^11 K^12 K^13 K^22 K^23 K^33 (K^21 K^31 K^32)] = G R^T
        call dgemm('N', 'T', nen, nb*nen, 3*np, 1.0_dp, wk%gt, ld, wk%rt, ldr, 0.0_dp, wk%k9, ld)
        call interleave(wk%k9, ld, nen, wk%sym, ke)
    end subroutine element_kernel

    !> `work` large enough for `nen` functions and `np` points (the per-point
    !> arrays exactly `np` long: explicit shapes in the kernels).
    pure subroutine fit_work(work, nen, np)
        type(solid3_work_t), intent(inout) :: work
        integer, intent(in) :: nen, np
        integer :: ld, nc
        if (allocated(work%s)) then
            if (size(work%s, 3) /= np) deallocate (work%gu, work%s, work%m, work%finv)
        end if
        if (.not. allocated(work%s)) allocate (work%gu(3, 3, np), work%s(3, 3, np), work%m(3, 3, 9, np), &
                                                work%finv(3, 3, np))
        if (allocated(work%gt)) then
            if (size(work%gt, 1) >= nen .and. size(work%gt, 2) >= 3*np) return
            ld = max(nen, size(work%gt, 1))
            nc = max(3*np, size(work%gt, 2))
            deallocate (work%gt, work%rt, work%k9, work%ft)
        else
            ld = nen
            nc = 3*np
        end if
        allocate (work%gt(ld, nc), work%rt(9*ld, nc), work%k9(ld, 9*ld), work%ft(ld, 3))
    end subroutine fit_work

    !> The reference gradients dN/dX of every point as the columns of G (`gt`
    !> [ld, 3 np]: column 3(q-1) + j holds dN_a/dX_j at point q) and the displacement
    !> gradients of all points at once, `gu`(i, 3(q-1) + j) = sum_a u_ia dN_a/dX_j =
    !> (U G)_i,3(q-1)+j (dgemm: dot products over the functions summed as written are
    !> a chain of dependent additions each).
    pure subroutine gradients(nen, np, dndx, u, gt, ld, gu)
        integer, intent(in) :: nen, np, ld
        real(dp), intent(in) :: dndx(3, nen, np), u(3, nen)
        real(dp), intent(inout) :: gt(ld, *)
        real(dp), intent(out) :: gu(3, 3*np)
        integer :: q, a, c
        do q = 1, np
            c = 3*(q - 1)
            do a = 1, nen
                gt(a, c + 1) = dndx(1, a, q)
                gt(a, c + 2) = dndx(2, a, q)
                gt(a, c + 3) = dndx(3, a, q)
            end do
        end do
        call dgemm('N', 'N', 3, 3*np, nen, 1.0_dp, u, 3, gt, ld, 0.0_dp, gu, 3)
    end subroutine gradients

    !> At each of the `np` points, from the displacement gradient `gu`: the law's
    !> stress `s` and, at finite strain, F^-1 (`finv`); with `tangent`, the weighted
    !> couplings `m` of all nine blocks and whether the tangent has the major
    !> symmetry there (`sym`: c_ijkl = c_klij and, at finite strain, tau = tau^T, to
    !> the bit). `ok` is false if J <= 0 at a point (finite strain) or the law says so.
    pure subroutine point_stresses(mat, tangent, np, wdv, gu, s, m, finv, sym, ok)
        class(material_t), intent(in) :: mat
        logical, intent(in) :: tangent
        integer, intent(in) :: np
        real(dp), intent(in) :: wdv(np), gu(3, 3, np)
        real(dp), intent(out) :: s(3, 3, np), m(3, 3, 9, np), finv(3, 3, np)
        logical, intent(out) :: sym, ok
        real(dp) :: f(3, 3), c(3, 3, 3, 3), det
        integer :: q, j

        sym = .true.
        ok = .true.
        do q = 1, np
            if (mat%finite_strain) then
                f = gu(:, :, q)
                do j = 1, 3
                    f(j, j) = f(j, j) + 1.0_dp
                end do
                det = jacobian_determinant(f)
                ok = det > 0.0_dp
                if (.not. ok) return
                finv(:, :, q) = inverse3(f, det)
            end if
            call mat%stress3(gu(:, :, q), s(:, :, q), c, ok)
            if (.not. ok) return
            if (tangent) call couplings(mat%finite_strain, wdv(q), s(:, :, q), c, m(:, :, :, q), sym)
        end do
    end subroutine point_stresses

    !> The weighted couplings M^ik_jl = w (c_ijkl + delta_ik tau_jl) (`m`, blocks in
    !> the order of `block_i`, `block_k`; no tau at small strain) of one point, and
    !> `sym` false unless its tangent has the major symmetry.
    pure subroutine couplings(finite_strain, w, s, c, m, sym)
        logical, intent(in) :: finite_strain
        real(dp), intent(in) :: w, s(3, 3), c(3, 3, 3, 3)
        real(dp), intent(out) :: m(3, 3, 9)
        logical, intent(inout) :: sym
        integer :: blk, i, j, k, l
        do blk = 1, 9
            i = block_i(blk)
            k = block_k(blk)
            do l = 1, 3
                do j = 1, 3
                    m(j, l, blk) = w*c(i, j, k, l)
                end do
            end do
            if (finite_strain .and. i == k) m(:, :, blk) = m(:, :, blk) + w*s
        end do
        if (.not. sym) return
        do l = 1, 3
            do k = 1, 3
                do j = 1, 3
                    do i = 1, 3
                        sym = sym .and. c(i, j, k, l) == c(k, l, i, j)
                    end do
                end do
            end do
        end do
        if (finite_strain) sym = sym .and. all(s == transpose(s))
    end subroutine couplings

    !> The gradients g = F^-T dN/dX of every point in place of dN/dX in G (`gt`,
    !> finite strain; at small strain G stays dN/dX) and the force f_a = sum_q w_q s
    !> g_a (`fe` [3, nen]), summed by component over unit-stride columns (`ft` = f^T):
    !> the force alone for `solid3_force`; `point_columns` goes on from G.
    pure subroutine point_forces(finite_strain, nen, np, wdv, s, finv, gt, ld, ft, fe)
        logical, intent(in) :: finite_strain
        integer, intent(in) :: nen, np, ld
        real(dp), intent(in) :: wdv(np), s(3, 3, np), finv(3, 3, np)
        real(dp), intent(inout) :: gt(ld, *), ft(ld, 3)
        real(dp), intent(out) :: fe(3, nen)
        real(dp) :: sv(3, 3), fi(3, 3), g1, g2, g3
        integer :: q, a, i, c
        ft(1:nen, :) = 0.0_dp
        do q = 1, np
            c = 3*(q - 1)
            if (finite_strain) then
                fi = finv(:, :, q)
                do a = 1, nen
                    g1 = gt(a, c + 1)
                    g2 = gt(a, c + 2)
                    g3 = gt(a, c + 3)
                    gt(a, c + 1) = fi(1, 1)*g1 + fi(2, 1)*g2 + fi(3, 1)*g3
                    gt(a, c + 2) = fi(1, 2)*g1 + fi(2, 2)*g2 + fi(3, 2)*g3
                    gt(a, c + 3) = fi(1, 3)*g1 + fi(2, 3)*g2 + fi(3, 3)*g3
                end do
            end if
            sv = wdv(q)*s(:, :, q)
            do i = 1, 3
                do a = 1, nen
                    ft(a, i) = ft(a, i) + sv(i, 1)*gt(a, c + 1) + sv(i, 2)*gt(a, c + 2) + sv(i, 3)*gt(a, c + 3)
                end do
            end do
        end do
        do a = 1, nen
            fe(:, a) = ft(a, :)
        end do
    end subroutine point_forces

    !> The columns of R from G (`point_forces`) and the couplings `m`: block `blk` of
    !> R holds, for point q, R(b, 3(q-1) + j) = sum_l M^ik_jl g_b^l; the first `nb`
    !> blocks (six when K^ki = (K^ik)^T, else nine). Explicit shapes, so that the
    !> loops over the functions are plain vector loops.
    pure subroutine point_columns(nen, np, nb, m, gt, ld, rt, ldr)
        integer, intent(in) :: nen, np, nb, ld, ldr
        real(dp), intent(in) :: m(3, 3, 9, np)
        real(dp), intent(in) :: gt(ld, *)
        real(dp), intent(inout) :: rt(ldr, *)
        integer :: q, blk, off, c, a, j
        do q = 1, np
            c = 3*(q - 1)
            do blk = 1, nb
                off = (blk - 1)*nen
                do j = 1, 3
                    do a = 1, nen
                        rt(off + a, c + j) = m(j, 1, blk, q)*gt(a, c + 1) + m(j, 2, blk, q)*gt(a, c + 2) + &
                                             m(j, 3, blk, q)*gt(a, c + 3)
                    end do
                end do
            end do
        end do
    end subroutine point_columns

    !> The element matrix `ke` [3 nen, 3 nen] (local DOF order) from the blocks `k9`
    !> [ld, 9 ld] (`block_of`); with `sym`, K^ik for i > k is (K^ki)^T.
    pure subroutine interleave(k9, ld, nen, sym, ke)
        integer, intent(in) :: ld, nen
        real(dp), intent(in) :: k9(ld, *)
        logical, intent(in) :: sym
        real(dp), intent(out) :: ke(3, nen, 3, nen)
        integer :: a, b, i, k, off
        do b = 1, nen
            do k = 1, 3
                do i = 1, 3
                    if (sym .and. i > k) then
                        off = (block_of(k, i) - 1)*nen
                        do a = 1, nen
                            ke(i, a, k, b) = k9(b, off + a)
                        end do
                    else
                        off = (block_of(i, k) - 1)*nen
                        do a = 1, nen
                            ke(i, a, k, b) = k9(a, off + b)
                        end do
                    end if
                end do
            end do
        end do
    end subroutine interleave

end module voiga_element_solid3
