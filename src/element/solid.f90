!> Plane-strain solid element kernel: internal force and tangent stiffness of one
!> element from its quadrature points, small strain or finite strain, on any NURBS
!> or VO element.
!>
!> Local DOF order: 2(a-1) + i for function a and component i.
module voiga_element_solid
    use voiga_kinds, only: dp
    use voiga_material, only: material_t
    use voiga_linalg_blas, only: dgemm
    implicit none
    private

    public :: solid_element, solid_element_blocks, solid_element_force, reference_gradients, element_points_t, &
              element_work_t

    !> The quadrature of one element in the reference configuration, computed once
    !> per discretization: reference gradients dN/dX [2, nen, npts] and weights
    !> times |det dX/dxi| (reference volume) [npts].
    type :: element_points_t
        real(dp), allocatable :: dndx(:, :, :), wdv(:)
    end type element_points_t

    !> Work arrays of `solid_element` kept by its caller over the elements of a body
    !> (gfortran puts automatic arrays on the heap: an allocation per array and element):
    !> G [ld, 2 npts], R [4 ld, 2 npts], the blocks of K [ld, 4 ld] and each point's
    !> M^yx [4, npts], grown to the largest element they met; the points' displacement
    !> gradients, stresses, Voigt tangents and F^-1 [npts, ...] (`point_stresses`).
    type :: element_work_t
        real(dp), allocatable :: gt(:, :), rt(:, :), k4(:, :), myx(:, :)
        real(dp), allocatable :: gu(:, :, :), s(:, :, :), cv(:, :, :), finv(:, :, :)
        !> The last element's tangent had the major symmetry at every point: `k4`
        !> holds [K^xx K^xy K^yy] and K^yx = (K^xy)^T; else all four blocks.
        logical :: sym = .true.
    end type element_work_t

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
    !> g = dN/dx = F^-T dN/dX. The four 2 x 2 blocks of K, by displacement component
    !> (i, k), are K^ik_ab = sum_q g_a^T M^ik_q g_b with M^ik_q the 2 x 2 matrix of the
    !> Voigt tangent D = w c that couples the components (i, j) and (k, l) (the
    !> geometric part adds w tau to M^xx and M^yy): all are one product G R^T, G
    !> [nen, 2 npts] the stacked gradients and R [4 nen, 2 npts] the stacked G M^T
    !> (half the flops of B^T D B, whose B is half zeros, plus G^T T G); three of the
    !> four blocks when D is symmetric at every point (then K^yx = (K^xy)^T). `ok` is
    !> false if J <= 0 at a point.
    pure subroutine solid_element(mat, pts, u, fe, ke, ok, work)
        class(material_t), intent(in) :: mat
        type(element_points_t), intent(in) :: pts
        real(dp), intent(in) :: u(:, :)
        real(dp), intent(out) :: fe(:), ke(:, :)
        logical, intent(out) :: ok
        !> G, R and the blocks [K^xx K^xy K^yy K^yx] (allocated here when absent).
        type(element_work_t), intent(inout), optional :: work
        type(element_work_t) :: own
        if (present(work)) then
            call solid_element_blocks(mat, pts, u, fe, ok, work)
            if (ok) call interleave(work, size(u, 2), ke)
        else
            call solid_element_blocks(mat, pts, u, fe, ok, own)
            if (ok) call interleave(own, size(u, 2), ke)
        end if
    end subroutine solid_element

    !> `solid_element` with K left in its blocks, `work%k4` = [K^xx K^xy K^yy K^yx]
    !> [nen, 4 nen] (K^yx only when `work%sym` is false; else K^yx = (K^xy)^T): the
    !> assembly adds them to the global matrix without the interleaved copy.
    pure subroutine solid_element_blocks(mat, pts, u, fe, ok, work)
        class(material_t), intent(in) :: mat
        type(element_points_t), intent(in) :: pts
        real(dp), intent(in) :: u(:, :)
        real(dp), intent(out) :: fe(:)
        logical, intent(out) :: ok
        type(element_work_t), intent(inout) :: work
        call fit_work(work, size(u, 2), size(pts%wdv))
        call element_kernel(mat, pts, u, fe, ok, work)
    end subroutine solid_element_blocks

    !> The internal force `fe` [2 nen] of an element without its tangent: the
    !> operations of `solid_element`'s force in the same order, so the same numbers
    !> (a residual whose tangent is not wanted: a Newton iterate expected to have
    !> converged). `ok` is false if J <= 0 at a point.
    pure subroutine solid_element_force(mat, pts, u, fe, ok, work)
        class(material_t), intent(in) :: mat
        type(element_points_t), intent(in) :: pts
        real(dp), intent(in) :: u(:, :)
        real(dp), intent(out) :: fe(:)
        logical, intent(out) :: ok
        type(element_work_t), intent(inout) :: work
        integer :: nen, np
        nen = size(u, 2)
        np = size(pts%wdv)
        call fit_work(work, nen, np)
        call point_stresses(mat, nen, np, pts%dndx, u, work%gu, work%s, work%cv, work%finv, ok)
        if (.not. ok) return
        call point_forces(mat%finite_strain, nen, np, pts%dndx, pts%wdv, work%s, work%finv, fe, work%gt, &
                          size(work%gt, 1))
    end subroutine solid_element_force

    !> The displacement gradients `gu` (q, i, j) at the `np` points, each summed over
    !> the functions in their order as a loop point by point would (one vector loop
    !> over the points per function instead of a chain of dependent additions per
    !> point), the law's stress `s` and Voigt tangent `cv` there and, at finite
    !> strain, F^-1 (`finv`). `ok` is false if J <= 0 at a point.
    pure subroutine point_stresses(mat, nen, np, dndx, u, gu, s, cv, finv, ok)
        class(material_t), intent(in) :: mat
        integer, intent(in) :: nen, np
        real(dp), intent(in) :: dndx(2, nen, np), u(2, nen)
        real(dp), intent(out) :: gu(np, 2, 2), s(np, 2, 2), cv(np, 3, 3), finv(np, 2, 2)
        logical, intent(out) :: ok
        real(dp) :: f11, f21, f12, f22, det
        integer :: a, q
        gu = 0.0_dp
        do a = 1, nen
            do q = 1, np
                gu(q, 1, 1) = gu(q, 1, 1) + u(1, a)*dndx(1, a, q)
                gu(q, 2, 1) = gu(q, 2, 1) + u(2, a)*dndx(1, a, q)
                gu(q, 1, 2) = gu(q, 1, 2) + u(1, a)*dndx(2, a, q)
                gu(q, 2, 2) = gu(q, 2, 2) + u(2, a)*dndx(2, a, q)
            end do
        end do
        call mat%stress_points(np, gu, s, cv, ok)
        if (.not. ok .or. .not. mat%finite_strain) return
        do q = 1, np
            f11 = gu(q, 1, 1) + 1.0_dp
            f21 = gu(q, 2, 1)
            f12 = gu(q, 1, 2)
            f22 = gu(q, 2, 2) + 1.0_dp
            det = f11*f22 - f12*f21
            finv(q, 1, 1) = f22/det
            finv(q, 2, 1) = -f21/det
            finv(q, 1, 2) = -f12/det
            finv(q, 2, 2) = f11/det
        end do
    end subroutine point_stresses

    !> The gradients g = F^-T dN/dX (dN/dX for small strain) of every point as the
    !> columns of G (`gt` [ld, 2 np]: columns 2q - 1 and 2q for point q) and the
    !> force f_a = sum_q w_q tau g_a (`fe`), from `point_stresses`' results. The
    !> force alone for `solid_element_force`; `point_columns` goes on from G.
    pure subroutine point_forces(finite_strain, nen, np, dndx, wdv, s, finv, fe, gt, ld)
        logical, intent(in) :: finite_strain
        integer, intent(in) :: nen, np, ld
        real(dp), intent(in) :: dndx(2, nen, np), wdv(np), s(np, 2, 2), finv(np, 2, 2)
        real(dp), intent(out) :: fe(2, nen)
        real(dp), intent(inout) :: gt(ld, *)
        real(dp) :: sv(3)
        integer :: q, a, c1, c2
        fe = 0.0_dp
        do q = 1, np
            c1 = 2*q - 1
            c2 = 2*q
            if (finite_strain) then
                do a = 1, nen
                    gt(a, c1) = finv(q, 1, 1)*dndx(1, a, q) + finv(q, 2, 1)*dndx(2, a, q)
                    gt(a, c2) = finv(q, 1, 2)*dndx(1, a, q) + finv(q, 2, 2)*dndx(2, a, q)
                end do
            else
                gt(1:nen, c1) = dndx(1, :, q)
                gt(1:nen, c2) = dndx(2, :, q)
            end if
            sv = wdv(q)*[s(q, 1, 1), s(q, 2, 2), s(q, 1, 2)]
            do a = 1, nen
                fe(1, a) = fe(1, a) + sv(1)*gt(a, c1) + sv(3)*gt(a, c2)
                fe(2, a) = fe(2, a) + sv(2)*gt(a, c2) + sv(3)*gt(a, c1)
            end do
        end do
    end subroutine point_forces

    !> `work` large enough for `nen` functions and `np` points (the per-point
    !> arrays exactly `np` long: explicit shapes in the kernels).
    pure subroutine fit_work(work, nen, np)
        type(element_work_t), intent(inout) :: work
        integer, intent(in) :: nen, np
        integer :: ld, nc
        if (allocated(work%gu)) then
            if (size(work%gu, 1) /= np) deallocate (work%gu, work%s, work%cv, work%finv)
        end if
        if (.not. allocated(work%gu)) allocate (work%gu(np, 2, 2), work%s(np, 2, 2), work%cv(np, 3, 3), &
                                                 work%finv(np, 2, 2))
        if (allocated(work%gt)) then
            if (size(work%gt, 1) >= nen .and. size(work%gt, 2) >= 2*np) return
            ld = max(nen, size(work%gt, 1))
            nc = max(2*np, size(work%gt, 2))
            deallocate (work%gt, work%rt, work%k4, work%myx)
        else
            ld = nen
            nc = 2*np
        end if
        allocate (work%gt(ld, nc), work%rt(4*ld, nc), work%k4(ld, 4*ld), work%myx(4, (nc + 1)/2))
    end subroutine fit_work

    !> `solid_element_blocks` on the work arrays `wk`.
    pure subroutine element_kernel(mat, pts, u, fe, ok, wk)
        class(material_t), intent(in) :: mat
        type(element_points_t), intent(in) :: pts
        real(dp), intent(in) :: u(:, :)
        real(dp), intent(out) :: fe(:)
        logical, intent(out) :: ok
        type(element_work_t), intent(inout) :: wk
        integer :: nen, np, ld, nb

        nen = size(u, 2)
        np = size(pts%wdv)
        ld = size(wk%gt, 1)
        call point_stresses(mat, nen, np, pts%dndx, u, wk%gu, wk%s, wk%cv, wk%finv, ok)
        if (.not. ok) return
        call point_forces(mat%finite_strain, nen, np, pts%dndx, pts%wdv, wk%s, wk%finv, fe, wk%gt, ld)
        call point_columns(mat%finite_strain, nen, np, pts%wdv, wk%s, wk%cv, wk%sym, wk%gt, ld, wk%rt, &
                           size(wk%rt, 1), wk%myx)
        ! [K^xx K^xy K^yy K^yx] = G R^T; K^yx = (K^xy)^T when the tangent has the major
        ! symmetry at every point (hyperelastic and linear laws)
        nb = merge(3, 4, wk%sym)
        call dgemm('N', 'T', nen, nb*nen, 2*np, 1.0_dp, wk%gt, ld, wk%rt, size(wk%rt, 1), 0.0_dp, wk%k4, ld)
    end subroutine element_kernel

    !> The element matrix `ke` [2 nen, 2 nen] (local DOF order) from the blocks in `wk`.
    pure subroutine interleave(wk, nen, ke)
        type(element_work_t), intent(in) :: wk
        integer, intent(in) :: nen
        real(dp), intent(out) :: ke(:, :)
        integer :: a, b
        do b = 1, nen
            do a = 1, nen
                ke(2*a - 1, 2*b - 1) = wk%k4(a, b)
                ke(2*a - 1, 2*b) = wk%k4(a, nen + b)
                ke(2*a, 2*b) = wk%k4(a, 2*nen + b)
            end do
        end do
        if (wk%sym) then
            do b = 1, nen
                do a = 1, nen
                    ke(2*a, 2*b - 1) = wk%k4(b, nen + a)
                end do
            end do
        else
            do b = 1, nen
                do a = 1, nen
                    ke(2*a, 2*b - 1) = wk%k4(a, 3*nen + b)
                end do
            end do
        end if
    end subroutine interleave

    !> The columns of R of every point from G (`point_forces`) and the law's tangent:
    !> R's blocks are G M^T for M^xx, M^xy, M^yy (explicit shapes, so that the loops
    !> over the functions are plain vector loops). R's fourth block (for K^yx) is
    !> formed only when the tangent is not symmetric at some point: `element_kernel`
    !> does not use it otherwise (a quarter of R's work on hyperelastic laws).
    pure subroutine point_columns(finite_strain, nen, np, wdv, s, cv, sym, gt, ld, rt, ldr, myx)
        logical, intent(in) :: finite_strain
        integer, intent(in) :: nen, np, ld, ldr
        real(dp), intent(in) :: wdv(np), s(np, 2, 2), cv(np, 3, 3)
        !> The Voigt tangent was symmetric at every point (M^yx = (M^xy)^T).
        logical, intent(out) :: sym
        real(dp), intent(in) :: gt(ld, *)
        real(dp), intent(inout) :: rt(ldr, *)
        !> Work: M^yx of every point (for R's fourth block).
        real(dp), intent(inout) :: myx(2, 2, *)
        real(dp) :: d(3, 3), ts(2, 2), m(2, 2, 4), w
        integer :: q, i, j, a, blk, off, c1, c2

        sym = .true.
        do q = 1, np
            w = wdv(q)
            c1 = 2*q - 1
            c2 = 2*q
            ! the geometric part (finite strain)
            ts = 0.0_dp
            if (finite_strain) ts = w*s(q, :, :)
            do j = 1, 3
                do i = 1, 3
                    d(i, j) = w*cv(q, i, j)
                end do
            end do
            sym = sym .and. d(1, 2) == d(2, 1) .and. d(1, 3) == d(3, 1) .and. d(2, 3) == d(3, 2)
            ! M^xx, M^xy, M^yy, M^yx (rows: the gradient component of g_a, columns: of g_b)
            call coupling(d, ts, m)
            myx(:, :, q) = m(:, :, 4)
            do blk = 1, 3
                off = (blk - 1)*nen
                do a = 1, nen
                    rt(off + a, c1) = m(1, 1, blk)*gt(a, c1) + m(1, 2, blk)*gt(a, c2)
                    rt(off + a, c2) = m(2, 1, blk)*gt(a, c1) + m(2, 2, blk)*gt(a, c2)
                end do
            end do
        end do
        if (sym) return
        off = 3*nen
        do q = 1, np
            c1 = 2*q - 1
            c2 = 2*q
            do a = 1, nen
                rt(off + a, c1) = myx(1, 1, q)*gt(a, c1) + myx(1, 2, q)*gt(a, c2)
                rt(off + a, c2) = myx(2, 1, q)*gt(a, c1) + myx(2, 2, q)*gt(a, c2)
            end do
        end do
    end subroutine point_columns

    !> The 2 x 2 matrices M^xx, M^xy, M^yy, M^yx of `solid_element` from the Voigt
    !> tangent `d` and the geometric part `ts` (rows: the gradient component of g_a,
    !> columns: of g_b).
    pure subroutine coupling(d, ts, m)
        real(dp), intent(in) :: d(3, 3), ts(2, 2)
        real(dp), intent(out) :: m(2, 2, 4)
        m(1, 1, 1) = d(1, 1) + ts(1, 1)
        m(2, 1, 1) = d(3, 1) + ts(2, 1)
        m(1, 2, 1) = d(1, 3) + ts(1, 2)
        m(2, 2, 1) = d(3, 3) + ts(2, 2)
        m(1, 1, 2) = d(1, 3)
        m(2, 1, 2) = d(3, 3)
        m(1, 2, 2) = d(1, 2)
        m(2, 2, 2) = d(3, 2)
        m(1, 1, 3) = d(3, 3) + ts(1, 1)
        m(2, 1, 3) = d(2, 3) + ts(2, 1)
        m(1, 2, 3) = d(3, 2) + ts(1, 2)
        m(2, 2, 3) = d(2, 2) + ts(2, 2)
        m(1, 1, 4) = d(3, 1)
        m(2, 1, 4) = d(2, 1)
        m(1, 2, 4) = d(3, 3)
        m(2, 2, 4) = d(2, 3)
    end subroutine coupling

end module voiga_element_solid
