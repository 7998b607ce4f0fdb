!> The three-dimensional solid element kernel (`voiga_element_solid3`) on one
!> element of a real trivariate NURBS patch (a quarter-ring block of degree 2, or 3,
!> in every direction with moved control points and weights: distorted and rational):
!> its tangent against central differences of its force for Hooke, Neo-Hookean and
!> two laws without the major symmetry (one small strain, one finite strain); the
!> element patch test (u = A X gives the law's stress at every point and the force
!> sum_q w_q tau g_a, self-equilibrated and equal to the boundary traction's
!> integral); zero force under a rigid rotation; an inverted point rejected; the
!> force alone bitwise the element's; symmetric tangents; and an extruded element
!> in plane strain against the plane-strain kernel.
module test_element_kernel_3d
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_testdrive, only: unittest_t, new_unittest, check
    use voiga_material, only: material_t
    use voiga_material_factory, only: new_material
    use voiga_nurbs_patch, only: nurbs_patch_t, knots_t, new_patch, patch_basis, patch_elevate, next_index
    use voiga_element_quadrature, only: gauss_legendre
    use voiga_element_solid, only: element_points_t, reference_gradients, solid_element
    use voiga_element_solid3, only: solid3_element, solid3_force, reference_gradients3, solid3_work_t
    use voiga_test_fixtures, only: lcg_t, ring_block
    implicit none
    private

    public :: collect_element_kernel_3d

    real(dp), parameter :: youngs = 210.0_dp, poisson = 0.3_dp

    !> A small-strain law sigma = c : grad_u with random moduli c_ijkl /= c_klij (not
    !> a physical law: a tangent the symmetric shortcut would get wrong).
    type, extends(material_t) :: skew_law_t
        real(dp) :: c3(3, 3, 3, 3) = 0.0_dp
    contains
        procedure :: stress => no_plane_stress
        procedure :: stress3 => skew_stress3
        procedure :: fields => no_fields
        procedure, nopass :: strain_name => no_strain_name
    end type skew_law_t

    !> A finite-strain Cauchy-elastic law that is not hyperelastic: S = mu tr(C^2) I,
    !> so tau = mu tr(b^2) b and c = 4 mu b (x) b^2 (the push-forward of 2 dS/dC =
    !> 4 mu I (x) C), without the major symmetry. It accepts every F, J <= 0 too: the
    !> kernel's own check must reject an inverted point.
    type, extends(skew_law_t) :: cauchy_law_t
    contains
        procedure :: stress3 => cauchy_stress3
    end type cauchy_law_t

contains

    subroutine collect_element_kernel_3d(testsuite)
        type(unittest_t), allocatable, intent(out) :: testsuite(:)
        testsuite = [ &
                    new_unittest('tangent_fd_linear', test_fd_linear), &
                    new_unittest('tangent_fd_neo_hookean', test_fd_neo_hookean), &
                    new_unittest('tangent_fd_unsymmetric_small_strain', test_fd_skew), &
                    new_unittest('tangent_fd_unsymmetric_finite_strain', test_fd_cauchy), &
                    new_unittest('constant_gradient_linear', test_constant_linear), &
                    new_unittest('constant_gradient_neo_hookean', test_constant_neo_hookean), &
                    new_unittest('force_is_boundary_traction', test_boundary_traction), &
                    new_unittest('rigid_rotation_no_force', test_rotation), &
                    new_unittest('inverted_point_rejected', test_inverted), &
                    new_unittest('force_alone_is_element_force', test_force_bitwise), &
                    new_unittest('symmetric_tangents', test_symmetric), &
                    new_unittest('extruded_plane_strain_is_2d_kernel', test_plane_strain) &
                    ]
    end subroutine collect_element_kernel_3d

    ! ---------------------------------------------------------------- test laws

    pure subroutine no_plane_stress(self, grad_u, s, c, ok)
        class(skew_law_t), intent(in) :: self
        real(dp), intent(in) :: grad_u(2, 2)
        real(dp), intent(out) :: s(2, 2), c(2, 2, 2, 2)
        logical, intent(out) :: ok
        s = 0.0_dp*grad_u
        c = 0.0_dp
        ok = .false. .and. self%finite_strain
    end subroutine no_plane_stress

    pure subroutine no_fields(self, grad_u, stress, strain, ok)
        class(skew_law_t), intent(in) :: self
        real(dp), intent(in) :: grad_u(2, 2)
        real(dp), intent(out) :: stress(4), strain(4)
        logical, intent(out) :: ok
        stress = 0.0_dp*grad_u(1, 1)
        strain = 0.0_dp
        ok = .false. .and. self%finite_strain
    end subroutine no_fields

    pure function no_strain_name() result(name)
        character(len=:), allocatable :: name
        name = 'none'
    end function no_strain_name

    pure subroutine skew_stress3(self, grad_u, s, c, ok)
        class(skew_law_t), intent(in) :: self
        real(dp), intent(in) :: grad_u(3, 3)
        real(dp), intent(out) :: s(3, 3), c(3, 3, 3, 3)
        logical, intent(out) :: ok
        integer :: i, j
        do j = 1, 3
            do i = 1, 3
                s(i, j) = sum(self%c3(i, j, :, :)*grad_u)
            end do
        end do
        c = self%c3
        ok = .true.
    end subroutine skew_stress3

    pure subroutine cauchy_stress3(self, grad_u, s, c, ok)
        class(cauchy_law_t), intent(in) :: self
        real(dp), intent(in) :: grad_u(3, 3)
        real(dp), intent(out) :: s(3, 3), c(3, 3, 3, 3)
        logical, intent(out) :: ok
        real(dp) :: f(3, 3), b(3, 3), b2(3, 3)
        integer :: i, j
        f = grad_u
        do i = 1, 3
            f(i, i) = f(i, i) + 1.0_dp
        end do
        b = matmul(f, transpose(f))
        b2 = matmul(b, b)
        s = self%mu*(b2(1, 1) + b2(2, 2) + b2(3, 3))*b
        do j = 1, 3
            do i = 1, 3
                c(i, j, :, :) = 4.0_dp*self%mu*b(i, j)*b2
            end do
        end do
        ok = .true.
    end subroutine cauchy_stress3

    !> The skew law: Hooke's moduli plus random ones of a tenth of E.
    function skew_law(rng) result(law)
        type(lcg_t), intent(inout) :: rng
        type(skew_law_t) :: law
        class(material_t), allocatable :: hooke
        type(error_t), allocatable :: error
        real(dp) :: s(3, 3)
        integer :: i, j, k, l
        logical :: ok
        call new_material(hooke, 'linear', youngs, poisson, error)
        call hooke%stress3(0.0_dp*s, s, law%c3, ok)
        do l = 1, 3
            do k = 1, 3
                do j = 1, 3
                    do i = 1, 3
                        law%c3(i, j, k, l) = law%c3(i, j, k, l) + 0.1_dp*youngs*(rng%uniform() - 0.5_dp)
                    end do
                end do
            end do
        end do
    end function skew_law

    function cauchy_law() result(law)
        type(cauchy_law_t) :: law
        law%mu = 0.5_dp*youngs
        law%finite_strain = .true.
    end function cauchy_law

    function law(name) result(mat)
        character(len=*), intent(in) :: name
        class(material_t), allocatable :: mat
        type(error_t), allocatable :: error
        call new_material(mat, name, youngs, poisson, error)
    end function law

    ! ---------------------------------------------------------------- geometry

    !> A quarter of the ring r 1..2, theta 0..pi/2, extruded to z 0..1 (exact arcs
    !> of weight 1/sqrt 2) raised to degree `p` (2 or 3) in every direction: one
    !> element of (p + 1)^3 functions. Every control point is then moved by up to
    !> 0.05 in each coordinate and every weight scaled by 0.8 .. 1.2, so the map is
    !> distorted and rational in all three directions (J stays positive).
    function distorted_block(p) result(patch)
        integer, intent(in) :: p
        type(nurbs_patch_t) :: patch
        type(lcg_t) :: rng
        integer :: a
        patch = ring_block()
        call patch_elevate(patch, 1, p - 1)
        call patch_elevate(patch, 2, p - 2)
        call patch_elevate(patch, 3, p - 1)
        do a = 1, size(patch%w)
            patch%cp(:, a) = patch%cp(:, a) + 0.1_dp*([rng%uniform(), rng%uniform(), rng%uniform()] - 0.5_dp)
            patch%w(a) = patch%w(a)*(0.8_dp + 0.4_dp*rng%uniform())
        end do
    end function distorted_block

    !> The quadrature of a one-element patch of parametric dimension 3: `ng`^3 Gauss
    !> points on [0, 1]^3, dN/dX and w |det J| (`pts`); its control points `x0`
    !> [3, nen] in the order of the element's functions; `detmin` the least det J.
    subroutine element_points3(patch, ng, pts, x0, detmin)
        type(nurbs_patch_t), intent(in) :: patch
        integer, intent(in) :: ng
        type(element_points_t), intent(out) :: pts
        real(dp), allocatable, intent(out) :: x0(:, :)
        real(dp), intent(out) :: detmin
        integer, allocatable :: ids(:)
        real(dp), allocatable :: r(:), dr(:, :)
        real(dp) :: gx(ng), gw(ng), det
        integer :: idx(3), q, nen
        call gauss_legendre(ng, gx, gw)
        nen = size(patch%w)
        allocate (pts%dndx(3, nen, ng**3), pts%wdv(ng**3))
        detmin = huge(1.0_dp)
        idx = 1
        do q = 1, ng**3
            ! one element: the same functions (ids) at every point
            call patch_basis(patch, 0.5_dp*(1.0_dp + gx(idx)), ids, r, dr)
            x0 = patch%cp(:, ids)
            call reference_gradients3(x0, dr, pts%dndx(:, :, q), det)
            pts%wdv(q) = 0.125_dp*product(gw(idx))*abs(det)
            detmin = min(detmin, det)
            call next_index(idx, [ng, ng, ng])
        end do
    end subroutine element_points3

    !> The degree-`p` distorted element with (p + 1)^3 Gauss points.
    subroutine distorted_element(p, pts, x0, error)
        integer, intent(in) :: p
        type(element_points_t), intent(out) :: pts
        real(dp), allocatable, intent(out) :: x0(:, :)
        type(error_t), allocatable, intent(out) :: error
        real(dp) :: detmin
        call element_points3(distorted_block(p), p + 1, pts, x0, detmin)
        call check(error, detmin > 0.0_dp, 'the distorted element has det J > 0')
    end subroutine distorted_element

    !> A random 3 x 3 matrix with entries in [-amp, amp].
    function random_matrix(rng, amp) result(a)
        type(lcg_t), intent(inout) :: rng
        real(dp), intent(in) :: amp
        real(dp) :: a(3, 3)
        integer :: i, j
        do j = 1, 3
            do i = 1, 3
                a(i, j) = amp*(2.0_dp*rng%uniform() - 1.0_dp)
            end do
        end do
    end function random_matrix

    !> A finite deformation: u = A X (|A_ij| <= 0.2) plus random control point
    !> displacements of up to 0.03: F varies over the element, J stays positive.
    function random_displacement(rng, x0) result(u)
        type(lcg_t), intent(inout) :: rng
        real(dp), intent(in) :: x0(:, :)
        real(dp) :: u(3, size(x0, 2))
        integer :: a
        u = matmul(random_matrix(rng, 0.2_dp), x0)
        do a = 1, size(x0, 2)
            u(:, a) = u(:, a) + 0.03_dp*([rng%uniform(), rng%uniform(), rng%uniform()] - 0.5_dp)*2.0_dp
        end do
    end function random_displacement

    ! ---------------------------------------------------------------- tangents

    !> max |K - K_fd| / max |K|, K_fd by central differences of `solid3_force` with
    !> step `h` in each displacement (a negative value if a state is rejected).
    function fd_error(mat, pts, u, h) result(err)
        class(material_t), intent(in) :: mat
        type(element_points_t), intent(in) :: pts
        real(dp), intent(in) :: u(:, :), h
        real(dp) :: err
        real(dp) :: fe(size(u)), ke(size(u), size(u)), kfd(size(u), size(u)), fp(size(u)), fm(size(u))
        real(dp) :: up(size(u, 1), size(u, 2))
        type(solid3_work_t) :: work
        integer :: a, i
        logical :: ok, okp, okm
        err = -1.0_dp
        call solid3_element(mat, pts, u, fe, ke, ok, work)
        if (.not. ok) return
        do a = 1, size(u, 2)
            do i = 1, 3
                up = u
                up(i, a) = u(i, a) + h
                call solid3_force(mat, pts, up, fp, okp, work)
                up(i, a) = u(i, a) - h
                call solid3_force(mat, pts, up, fm, okm, work)
                if (.not. (okp .and. okm)) return
                kfd(:, 3*(a - 1) + i) = (fp - fm)/(2.0_dp*h)
            end do
        end do
        err = maxval(abs(ke - kfd))/maxval(abs(ke))
    end function fd_error

    !> max |K - K^T| / max |K| of the element's tangent at `u`.
    function asymmetry(mat, pts, u) result(asym)
        class(material_t), intent(in) :: mat
        type(element_points_t), intent(in) :: pts
        real(dp), intent(in) :: u(:, :)
        real(dp) :: asym
        real(dp) :: fe(size(u)), ke(size(u), size(u))
        logical :: ok
        call solid3_element(mat, pts, u, fe, ke, ok)
        asym = maxval(abs(ke - transpose(ke)))/maxval(abs(ke))
    end function asymmetry

    !> Hooke's law: f is linear in u, so the differences are exact but for round-off
    !> (about eps |f| / (h |K|) = 1e-16 0.2 / 1e-3); a large step (2e-13 measured).
    subroutine test_fd_linear(error)
        type(error_t), allocatable, intent(out) :: error
        type(element_points_t) :: pts
        real(dp), allocatable :: x0(:, :)
        type(lcg_t) :: rng
        call distorted_element(2, pts, x0, error)
        if (allocated(error)) return
        call check(error, fd_error(law('linear'), pts, random_displacement(rng, x0), 1.0e-3_dp), 0.0_dp, &
                   'Hooke: K against differences', abs=1.0e-11_dp)
    end subroutine test_fd_linear

    !> Neo-Hookean at a finite deformation (|grad u| up to about 0.3): truncation
    !> h^2 |f'''| / 6 and round-off eps |f| / h balance near h = 1e-5 (measured:
    !> 9e-9 at h = 1e-4, 1e-10 at 1e-5, 1.5e-10 at 1e-6, 1e-9 at 1e-7; 4e-10 on the
    !> degree-3 element); 5e-9 allowed.
    subroutine test_fd_neo_hookean(error)
        type(error_t), allocatable, intent(out) :: error
        type(element_points_t) :: pts
        real(dp), allocatable :: x0(:, :)
        type(lcg_t) :: rng
        call distorted_element(2, pts, x0, error)
        if (allocated(error)) return
        call check(error, fd_error(law('neo-hookean'), pts, random_displacement(rng, x0), 1.0e-5_dp), 0.0_dp, &
                   'Neo-Hookean: K against differences', abs=5.0e-9_dp)
        if (allocated(error)) return
        ! and on the degree-3 element (64 functions, 64 points)
        call distorted_element(3, pts, x0, error)
        if (allocated(error)) return
        call check(error, fd_error(law('neo-hookean'), pts, random_displacement(rng, x0), 1.0e-5_dp), 0.0_dp, &
                   'Neo-Hookean, degree 3: K against differences', abs=5.0e-9_dp)
    end subroutine test_fd_neo_hookean

    !> The small-strain law without the major symmetry: the kernel forms all nine
    !> blocks of K; K is unsymmetric and still the exact derivative (f linear in u:
    !> round-off as for Hooke's law, 1e-13 measured).
    subroutine test_fd_skew(error)
        type(error_t), allocatable, intent(out) :: error
        type(element_points_t) :: pts
        real(dp), allocatable :: x0(:, :), u(:, :)
        type(lcg_t) :: rng
        type(skew_law_t) :: mat
        call distorted_element(2, pts, x0, error)
        if (allocated(error)) return
        mat = skew_law(rng)
        u = random_displacement(rng, x0)
        call check(error, asymmetry(mat, pts, u) > 1.0e-2_dp, 'the skew law gives an unsymmetric K')
        if (allocated(error)) return
        call check(error, fd_error(mat, pts, u, 1.0e-3_dp), 0.0_dp, 'skew law: K against differences', &
                   abs=1.0e-11_dp)
    end subroutine test_fd_skew

    !> The finite-strain law without the major symmetry (tau = mu tr(b^2) b): an
    !> unsymmetric K with the geometric part, against differences (as Neo-Hookean:
    !> 2e-10 measured).
    subroutine test_fd_cauchy(error)
        type(error_t), allocatable, intent(out) :: error
        type(element_points_t) :: pts
        real(dp), allocatable :: x0(:, :), u(:, :)
        type(lcg_t) :: rng
        call distorted_element(2, pts, x0, error)
        if (allocated(error)) return
        u = random_displacement(rng, x0)
        call check(error, asymmetry(cauchy_law(), pts, u) > 1.0e-2_dp, 'the Cauchy-elastic law gives an unsymmetric K')
        if (allocated(error)) return
        call check(error, fd_error(cauchy_law(), pts, u, 1.0e-5_dp), 0.0_dp, &
                   'Cauchy-elastic law: K against differences', abs=5.0e-9_dp)
    end subroutine test_fd_cauchy

    ! ---------------------------------------------------------------- patch test

    !> The inverse of a 3 x 3 matrix by cross products of its columns (not the
    !> kernel's formula): rows (a2 x a3, a3 x a1, a1 x a2) / det.
    pure function inverse_by_columns(a) result(inv)
        real(dp), intent(in) :: a(3, 3)
        real(dp) :: inv(3, 3), det
        inv(1, :) = cross(a(:, 2), a(:, 3))
        inv(2, :) = cross(a(:, 3), a(:, 1))
        inv(3, :) = cross(a(:, 1), a(:, 2))
        det = dot_product(a(:, 1), inv(1, :))
        inv = inv/det
    end function inverse_by_columns

    pure function cross(x, y) result(z)
        real(dp), intent(in) :: x(3), y(3)
        real(dp) :: z(3)
        z = [x(2)*y(3) - x(3)*y(2), x(3)*y(1) - x(1)*y(3), x(1)*y(2) - x(2)*y(1)]
    end function cross

    !> u = A X on the distorted element: the NURBS functions reproduce the linear
    !> field, so grad u = A at every point and the stress there is the law's
    !> stress3(A); the force is sum_q w_q s g_a with g = (I + A)^-T dN/dX (dN/dX at
    !> small strain), s and g computed here apart from the kernel, and sums to zero
    !> over the functions (they sum to one). All to round-off: 1.5e-15 measured,
    !> 1e-13 allowed.
    subroutine constant_gradient(mat, amp, error)
        class(material_t), intent(in) :: mat
        real(dp), intent(in) :: amp
        type(error_t), allocatable, intent(out) :: error
        type(element_points_t) :: pts
        type(solid3_work_t) :: work
        type(lcg_t) :: rng
        real(dp), allocatable :: x0(:, :), fe(:), ke(:, :), fref(:, :)
        real(dp) :: a(3, 3), sa(3, 3), c(3, 3, 3, 3), fi(3, 3), g(3), worst
        integer :: nen, q, b
        logical :: ok
        call distorted_element(2, pts, x0, error)
        if (allocated(error)) return
        nen = size(x0, 2)
        a = random_matrix(rng, amp)
        allocate (fe(3*nen), ke(3*nen, 3*nen), fref(3, nen))
        call solid3_element(mat, pts, matmul(a, x0), fe, ke, ok, work)
        call mat%stress3(a, sa, c, ok)
        worst = 0.0_dp
        do q = 1, size(pts%wdv)
            worst = max(worst, maxval(abs(work%s(:, :, q) - sa)))
        end do
        call check(error, worst/maxval(abs(sa)), 0.0_dp, 'the stress at a point is stress3(A)', abs=1.0e-13_dp)
        if (allocated(error)) return
        fi = 0.0_dp
        do q = 1, 3
            fi(q, q) = 1.0_dp
        end do
        if (mat%finite_strain) fi = inverse_by_columns(fi + a)
        fref = 0.0_dp
        do q = 1, size(pts%wdv)
            do b = 1, nen
                g = matmul(transpose(fi), pts%dndx(:, b, q))
                fref(:, b) = fref(:, b) + pts%wdv(q)*matmul(sa, g)
            end do
        end do
        call check(error, maxval(abs(fe - reshape(fref, [3*nen])))/maxval(abs(fref)), 0.0_dp, &
                   'the force is sum_q w_q s g_a', abs=1.0e-13_dp)
        if (allocated(error)) return
        call check(error, maxval(abs(sum(reshape(fe, [3, nen]), 2)))/maxval(abs(fe)), 0.0_dp, &
                   'the force is self-equilibrated', abs=1.0e-13_dp)
    end subroutine constant_gradient

    subroutine test_constant_linear(error)
        type(error_t), allocatable, intent(out) :: error
        call constant_gradient(law('linear'), 1.0e-3_dp, error)
    end subroutine test_constant_linear

    subroutine test_constant_neo_hookean(error)
        type(error_t), allocatable, intent(out) :: error
        call constant_gradient(law('neo-hookean'), 0.3_dp, error)
    end subroutine test_constant_neo_hookean

    !> At a constant F the first Piola-Kirchhoff stress P = tau F^-T is constant and
    !> f_a = int P grad_X N_a dV = int_dOmega N_a P N dA: the element force against
    !> the traction integrated over the six faces of the distorted element (Neo-Hookean,
    !> finite A). Both integrands are rational, so neither quadrature is exact: with 12
    !> Gauss points per direction they agree to 1e-13 of the force (8 points: 9e-9);
    !> 1e-11 allowed.
    subroutine test_boundary_traction(error)
        type(error_t), allocatable, intent(out) :: error
        integer, parameter :: ng = 12
        type(nurbs_patch_t) :: patch
        type(element_points_t) :: pts
        type(lcg_t) :: rng
        class(material_t), allocatable :: mat
        real(dp), allocatable :: x0(:, :), fe(:), fb(:, :)
        real(dp) :: a(3, 3), tau(3, 3), c(3, 3, 3, 3), p(3, 3), detmin
        integer :: i
        logical :: ok
        patch = distorted_block(2)
        call element_points3(patch, ng, pts, x0, detmin)
        mat = law('neo-hookean')
        a = random_matrix(rng, 0.3_dp)
        allocate (fe(size(x0)))
        call solid3_force(mat, pts, matmul(a, x0), fe, ok)
        call mat%stress3(a, tau, c, ok)
        p = a
        do i = 1, 3
            p(i, i) = p(i, i) + 1.0_dp
        end do
        p = matmul(tau, transpose(inverse_by_columns(p)))
        fb = face_integral(patch, ng, x0, p)
        call check(error, ok, 'the state is admissible')
        if (allocated(error)) return
        call check(error, maxval(abs(fe - reshape(fb, [size(fe)])))/maxval(abs(fe)), 0.0_dp, &
                   'the force is the boundary traction''s integral', abs=1.0e-11_dp)
    end subroutine test_boundary_traction

    !> int_dOmega N_a P N dA [3, nen] over the six faces of a one-element patch, `ng`^2
    !> Gauss points on each; N dA = +-(dX/du_d1 x dX/du_d2) du, outward (pointing
    !> along dX/du_dir on the face u_dir = 1, against it on u_dir = 0).
    function face_integral(patch, ng, x0, p) result(fb)
        type(nurbs_patch_t), intent(in) :: patch
        integer, intent(in) :: ng
        real(dp), intent(in) :: x0(:, :), p(3, 3)
        real(dp), allocatable :: fb(:, :)
        integer, allocatable :: ids(:)
        real(dp), allocatable :: r(:), dr(:, :)
        real(dp) :: gx(ng), gw(ng), u(3), na(3), t(3, 3), traction(3)
        integer :: dir, side, other(2), idx(2), q, b
        call gauss_legendre(ng, gx, gw)
        allocate (fb(3, size(x0, 2)))
        fb = 0.0_dp
        do dir = 1, 3
            other = pack([1, 2, 3], [1, 2, 3] /= dir)
            do side = 0, 1
                idx = 1
                do q = 1, ng**2
                    u(dir) = real(side, dp)
                    u(other) = 0.5_dp*(1.0_dp + gx(idx))
                    call patch_basis(patch, u, ids, r, dr)
                    t = matmul(x0, transpose(dr))
                    na = cross(t(:, other(1)), t(:, other(2)))
                    if ((dot_product(na, t(:, dir)) > 0.0_dp) .neqv. (side == 1)) na = -na
                    traction = 0.25_dp*product(gw(idx))*matmul(p, na)
                    do b = 1, size(x0, 2)
                        fb(:, b) = fb(:, b) + r(b)*traction
                    end do
                    call next_index(idx, [ng, ng])
                end do
            end do
        end do
    end function face_integral

    !> u = (Q - I) X, Q a rotation by 1 rad about a skew axis: F = Q, b = I, so tau =
    !> 0 and the Neo-Hookean force vanishes; round-off in b (1e-16) gives forces of
    !> about 1e-16 E V (V the element's volume; 4e-17 measured); 1e-14 E V allowed.
    subroutine test_rotation(error)
        type(error_t), allocatable, intent(out) :: error
        type(element_points_t) :: pts
        real(dp), allocatable :: x0(:, :), fe(:), ke(:, :)
        real(dp) :: n(3), k(3, 3), q(3, 3)
        integer :: i
        logical :: ok
        call distorted_element(2, pts, x0, error)
        if (allocated(error)) return
        n = [1.0_dp, -2.0_dp, 2.0_dp]/3.0_dp
        k = reshape([0.0_dp, n(3), -n(2), -n(3), 0.0_dp, n(1), n(2), -n(1), 0.0_dp], [3, 3])
        q = sin(1.0_dp)*k + (1.0_dp - cos(1.0_dp))*matmul(k, k)
        do i = 1, 3
            q(i, i) = q(i, i) + 1.0_dp
        end do
        allocate (fe(size(x0)), ke(size(x0), size(x0)))
        call solid3_element(law('neo-hookean'), pts, matmul(q, x0) - x0, fe, ke, ok)
        call check(error, ok, 'the rotation is admissible')
        if (allocated(error)) return
        call check(error, maxval(abs(fe))/(youngs*sum(pts%wdv)), 0.0_dp, 'no force under a rigid rotation', &
                   abs=1.0e-14_dp)
    end subroutine test_rotation

    !> u = A X with A11 = -1.5 (F11 = -0.5, J < 0 everywhere) is rejected by the
    !> element and the force, by Neo-Hookean (whose law rejects it) and by the
    !> Cauchy-elastic law (which does not: the kernel's own J check); A11 = -0.5 is
    !> accepted by both.
    subroutine test_inverted(error)
        type(error_t), allocatable, intent(out) :: error
        type(element_points_t) :: pts
        real(dp), allocatable :: x0(:, :), fe(:), ke(:, :)
        real(dp) :: a(3, 3)
        logical :: ok(4)
        call distorted_element(2, pts, x0, error)
        if (allocated(error)) return
        allocate (fe(size(x0)), ke(size(x0), size(x0)))
        a = 0.0_dp
        a(1, 1) = -0.5_dp
        call solid3_element(law('neo-hookean'), pts, matmul(a, x0), fe, ke, ok(1))
        call solid3_element(cauchy_law(), pts, matmul(a, x0), fe, ke, ok(2))
        call check(error, all(ok(1:2)), 'F11 = 0.5 is admissible')
        if (allocated(error)) return
        a(1, 1) = -1.5_dp
        call solid3_element(law('neo-hookean'), pts, matmul(a, x0), fe, ke, ok(1))
        call solid3_force(law('neo-hookean'), pts, matmul(a, x0), fe, ok(2))
        call solid3_element(cauchy_law(), pts, matmul(a, x0), fe, ke, ok(3))
        call solid3_force(cauchy_law(), pts, matmul(a, x0), fe, ok(4))
        call check(error, .not. any(ok), 'J < 0 is rejected')
    end subroutine test_inverted

    ! ---------------------------------------------------------------- bitwise, symmetry

    !> The force alone is the element's force to the bit, for each law (symmetric
    !> and not), with and without work arrays; and work arrays reused over elements
    !> of 64, 27 and 64 functions give the numbers of fresh ones.
    subroutine test_force_bitwise(error)
        type(error_t), allocatable, intent(out) :: error
        type(element_points_t) :: pts2, pts3
        type(solid3_work_t) :: shared
        type(lcg_t) :: rng
        real(dp), allocatable :: x2(:, :), x3(:, :), u2(:, :), u3(:, :)
        real(dp), allocatable :: fe(:), ke(:, :), fa(:), fb(:), ka(:, :), f3(:), k3(:, :)
        class(material_t), allocatable :: mat
        integer :: m
        logical :: ok(4), same
        call distorted_element(2, pts2, x2, error)
        if (allocated(error)) return
        call distorted_element(3, pts3, x3, error)
        if (allocated(error)) return
        u2 = random_displacement(rng, x2)
        u3 = random_displacement(rng, x3)
        allocate (fe(size(x2)), ke(size(x2), size(x2)), fa(size(x2)), fb(size(x2)), ka(size(x2), size(x2)), &
                  f3(size(x3)), k3(size(x3), size(x3)))
        same = .true.
        do m = 1, 4
            select case (m)
            case (1)
                mat = law('linear')
            case (2)
                mat = law('neo-hookean')
            case (3)
                allocate (mat, source=skew_law(rng))
            case default
                allocate (mat, source=cauchy_law())
            end select
            call solid3_element(mat, pts2, u2, fe, ke, ok(1))
            call solid3_force(mat, pts2, u2, fa, ok(2))
            ! the shared work meets the degree-3 element before and after each degree-2 one
            call solid3_force(mat, pts3, u3, f3, ok(3), shared)
            call solid3_element(mat, pts2, u2, fb, ka, ok(4), shared)
            same = same .and. all(ok) .and. all(fe == fa) .and. all(fe == fb) .and. all(ke == ka)
            call solid3_force(mat, pts2, u2, fb, ok(1), shared)
            same = same .and. ok(1) .and. all(fe == fb)
            call solid3_element(mat, pts3, u3, f3, k3, ok(1), shared)
            deallocate (mat)
        end do
        call check(error, same, 'the force alone and reused work give the element''s numbers to the bit')
    end subroutine test_force_bitwise

    !> Hooke's and the Neo-Hookean law have the major symmetry to the bit, so the
    !> kernel forms six blocks (`work%sym`) and mirrors the others; K's diagonal
    !> blocks are G R^T of dgemm, symmetric to round-off (2e-16 measured, 1e-14
    !> allowed).
    subroutine test_symmetric(error)
        type(error_t), allocatable, intent(out) :: error
        type(element_points_t) :: pts
        type(solid3_work_t) :: work
        type(lcg_t) :: rng
        real(dp), allocatable :: x0(:, :), u(:, :), fe(:), ke(:, :)
        real(dp) :: a(3, 3)
        logical :: ok
        character(len=11), parameter :: names(2) = ['linear     ', 'neo-hookean']
        integer :: m
        call distorted_element(2, pts, x0, error)
        if (allocated(error)) return
        u = random_displacement(rng, x0)
        allocate (fe(size(x0)), ke(size(x0), size(x0)))
        do m = 1, 2
            call solid3_element(law(trim(names(m))), pts, u, fe, ke, ok, work)
            call check(error, ok .and. work%sym, trim(names(m))//': the tangent has the major symmetry')
            if (allocated(error)) return
            call check(error, maxval(abs(ke - transpose(ke)))/maxval(abs(ke)), 0.0_dp, &
                       trim(names(m))//': K is symmetric', abs=1.0e-14_dp)
            if (allocated(error)) return
        end do
        ! a large stretch, F about diag(3, 0.5, 1): bbar far from tr(bbar)/3, where the
        ! order of the law's two bbar terms decides whether c_1122 = c_2211 to the bit
        a = 0.0_dp
        a(1, 1) = 2.0_dp
        a(2, 2) = -0.5_dp
        call solid3_element(law('neo-hookean'), pts, u + matmul(a, x0), fe, ke, ok, work)
        call check(error, ok .and. work%sym, 'neo-hookean, large stretch: the tangent has the major symmetry')
        if (allocated(error)) return
        call solid3_element(cauchy_law(), pts, u, fe, ke, ok, work)
        call check(error, ok .and. .not. work%sym, 'the Cauchy-elastic law: nine blocks')
    end subroutine test_symmetric

    ! ---------------------------------------------------------------- plane strain

    !> A distorted rational quarter annulus of degree 2 (9 functions) and its
    !> extrusion to z 0..1, degree 1 in z (18 functions, the same control points
    !> and weights on both layers).
    subroutine annulus_and_extrusion(patch2, patch3)
        type(nurbs_patch_t), intent(out) :: patch2, patch3
        type(lcg_t) :: rng
        real(dp) :: cp(2, 6), w(6), arc(2, 3), warc(3), cp3(3, 18)
        integer :: i, j, a
        arc = reshape([1.0_dp, 0.0_dp, 1.0_dp, 1.0_dp, 0.0_dp, 1.0_dp], [2, 3])
        warc = [1.0_dp, 1.0_dp/sqrt(2.0_dp), 1.0_dp]
        a = 0
        do j = 1, 3
            do i = 1, 2
                a = a + 1
                cp(:, a) = real(i, dp)*arc(:, j)
                w(a) = warc(j)
            end do
        end do
        patch2 = new_patch([1, 2], [knots_t([0.0_dp, 0.0_dp, 1.0_dp, 1.0_dp]), &
                                    knots_t([0.0_dp, 0.0_dp, 0.0_dp, 1.0_dp, 1.0_dp, 1.0_dp])], [2, 3], cp, w)
        call patch_elevate(patch2, 1, 1)
        do a = 1, 9
            patch2%cp(:, a) = patch2%cp(:, a) + 0.1_dp*([rng%uniform(), rng%uniform()] - 0.5_dp)
            patch2%w(a) = patch2%w(a)*(0.8_dp + 0.4_dp*rng%uniform())
        end do
        do a = 1, 9
            cp3(:, a) = [patch2%cp(:, a), 0.0_dp]
            cp3(:, 9 + a) = [patch2%cp(:, a), 1.0_dp]
        end do
        patch3 = new_patch([2, 2, 1], [patch2%knots, knots_t([0.0_dp, 0.0_dp, 1.0_dp, 1.0_dp])], [3, 3, 2], cp3, &
                           [patch2%w, patch2%w])
    end subroutine annulus_and_extrusion

    !> The extruded element under an in-plane displacement the same on both layers
    !> (F33 = 1, F independent of z, thickness 1) is the plane-strain element: summed
    !> over the layers, its in-plane force and in-plane blocks of K are the 2D
    !> kernel's, and its z force sums to zero (Neo-Hookean; the 2D law's point loop
    !> and stress3 differ in round-off only: 3e-15 measured, 1e-12 allowed).
    subroutine test_plane_strain(error)
        type(error_t), allocatable, intent(out) :: error
        type(nurbs_patch_t) :: patch2, patch3
        type(element_points_t) :: pts2, pts3
        type(lcg_t) :: rng
        class(material_t), allocatable :: mat
        integer, allocatable :: ids(:)
        real(dp), allocatable :: x3(:, :), r(:), dr(:, :)
        real(dp) :: u2(2, 9), u3(3, 18), fe2(18), ke2(18, 18), fe3(54), ke3(54, 54), fs(3, 9), ks(18, 18)
        real(dp) :: gx(3), gw(3), det, detmin
        integer :: idx(2), q, a, b, i, k, la, lb
        logical :: ok(2)
        call annulus_and_extrusion(patch2, patch3)
        call gauss_legendre(3, gx, gw)
        allocate (pts2%dndx(2, 9, 9), pts2%wdv(9))
        idx = 1
        do q = 1, 9
            call patch_basis(patch2, 0.5_dp*(1.0_dp + gx(idx)), ids, r, dr)
            call reference_gradients(patch2%cp(:, ids), dr, pts2%dndx(:, :, q), det)
            pts2%wdv(q) = 0.25_dp*product(gw(idx))*abs(det)
            call next_index(idx, [3, 3])
        end do
        call element_points3(patch3, 3, pts3, x3, detmin)
        mat = law('neo-hookean')
        do a = 1, 9
            u2(:, a) = 0.1_dp*([rng%uniform(), rng%uniform()] - 0.5_dp)
            u3(:, a) = [u2(:, a), 0.0_dp]
            u3(:, 9 + a) = [u2(:, a), 0.0_dp]
        end do
        call solid_element(mat, pts2, u2, fe2, ke2, ok(1))
        call solid3_element(mat, pts3, u3, fe3, ke3, ok(2))
        call check(error, all(ok) .and. detmin > 0.0_dp, 'both elements accept the state')
        if (allocated(error)) return
        fs = 0.0_dp
        ks = 0.0_dp
        do a = 1, 9
            do la = 0, 1
                fs(:, a) = fs(:, a) + fe3(3*(a + 9*la - 1) + 1:3*(a + 9*la))
                do b = 1, 9
                    do lb = 0, 1
                        do k = 1, 2
                            do i = 1, 2
                                ks(2*(a - 1) + i, 2*(b - 1) + k) = ks(2*(a - 1) + i, 2*(b - 1) + k) + &
                                                                   ke3(3*(a + 9*la - 1) + i, 3*(b + 9*lb - 1) + k)
                            end do
                        end do
                    end do
                end do
            end do
        end do
        call check(error, maxval(abs(reshape(fs(1:2, :), [18]) - fe2))/maxval(abs(fe2)), 0.0_dp, &
                   'the in-plane force is the 2D kernel''s', abs=1.0e-12_dp)
        if (allocated(error)) return
        call check(error, maxval(abs(fs(3, :)))/maxval(abs(fe2)), 0.0_dp, 'the z force sums to zero', abs=1.0e-12_dp)
        if (allocated(error)) return
        call check(error, maxval(abs(ks - ke2))/maxval(abs(ke2)), 0.0_dp, 'the in-plane K is the 2D kernel''s', &
                   abs=1.0e-12_dp)
    end subroutine test_plane_strain

end module test_element_kernel_3d
