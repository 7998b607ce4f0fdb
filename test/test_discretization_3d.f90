!> The discretization of a solid (a volume patch): the varying-order layer on any
!> of its six faces. Counts follow the formula of docs/formats.md; the VO basis is
!> a partition of unity whose derivatives match finite differences, maps the
!> refined exact geometry unchanged, and is conforming across the layer's
!> boundary; each face's control points lie on the face.
module test_discretization_3d
    use, intrinsic :: iso_fortran_env, only: int64
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_testdrive, only: unittest_t, new_unittest, check
    use voiga_nurbs_patch, only: nurbs_patch_t, patch_eval, jacobian_determinant
    use voiga_discretization_layout, only: layout_t
    use voiga_discretization_patch, only: discretization_t, new_discretization, contact_boundary, boundary_index
    use voiga_discretization_size, only: body_size_t, body_size
    use voiga_discretization_element, only: element_basis, element_nfun
    use voiga_element_quadrature, only: gauss_legendre
    use voiga_test_fixtures, only: lcg_t, ring_block, layout3
    implicit none
    private

    public :: collect_discretization_3d

    real(dp), parameter :: pi = acos(-1.0_dp)
    !> The ring block's faces: r = 1, r = 2, y = 0, x = 0, z = 0, z = 1.
    character(len=32), parameter :: faces(6) = [character(len=32) :: 'inner', 'outer', 'start', 'end', &
                                                 'bottom', 'top']

contains

    subroutine collect_discretization_3d(testsuite)
        type(unittest_t), allocatable, intent(out) :: testsuite(:)
        testsuite = [ &
                    new_unittest('dof_formula', test_dof_formula), &
                    new_unittest('vo_basis_partition_and_geometry', test_partition), &
                    new_unittest('vo_basis_derivatives_fd', test_derivatives), &
                    new_unittest('vo_layer_conforming', test_conforming), &
                    new_unittest('face_control_points_on_the_face', test_faces), &
                    new_unittest('every_face_as_contact_face', test_every_face), &
                    new_unittest('bad_layouts_refused', test_bad) &
                    ]
    end subroutine collect_discretization_3d

    !> Build the ring block's discretization or stop the test.
    subroutine build(d, layout, error)
        type(discretization_t), intent(out) :: d
        type(layout_t), intent(in) :: layout
        type(error_t), allocatable, intent(out) :: error
        call new_discretization(d, ring_block(), faces, layout, '', error)
    end subroutine build

    !> With no interior knots in the coarse patch, direction d has n_d = p + nel_d
    !> bulk functions and m_d = q + nel_d (1 + k) layer functions (docs/formats.md):
    !> DOFs = 3 (n_1 n_2 (n_3 - 1) + m_1 m_2) with a layer, 3 n_1 n_2 n_3 without,
    !> the contact face's 3 m_1 m_2 (or 3 n_1 n_2). `body_size` counts the same.
    subroutine test_dof_formula(error)
        type(error_t), allocatable, intent(out) :: error
        integer, parameter :: cases(6, 6) = reshape([ &
                                                     2, 0, 0, 2, 3, 1, &
                                                     3, 0, 0, 1, 2, 2, &
                                                     2, 2, 0, 3, 2, 2, &
                                                     2, 3, 0, 2, 2, 3, &
                                                     2, 2, 1, 4, 3, 2, &
                                                     2, 3, 2, 2, 1, 1], [6, 6])
        type(discretization_t) :: d
        type(body_size_t) :: counted
        integer :: c, f, n(3), m(2), expected, iface, nen
        integer(int64) :: entries
        do c = 1, size(cases, 2)
            associate (p => cases(1, c), q => cases(2, c), k => cases(3, c), nel => cases(4:6, c))
                do f = 1, size(faces)
                    call build(d, layout3(p, nel, q, k, faces(f)), error)
                    if (allocated(error)) return
                    n = p + nel
                    m = q + nel(1:2)*(1 + k)
                    if (q > 0) then
                        expected = 3*(n(1)*n(2)*(n(3) - 1) + m(1)*m(2))
                        iface = 3*m(1)*m(2)
                    else
                        expected = 3*product(n)
                        iface = 3*n(1)*n(2)
                    end if
                    call check(error, d%total_dofs == expected .and. d%interface_dofs == iface .and. &
                               d%nel == product(nel), 'DOFs of case '//char(48 + c)//' on '//trim(faces(f)))
                    if (allocated(error)) return
                    counted = body_size(ring_block(), faces, layout3(p, nel, q, k, faces(f)))
                    entries = 0
                    do nen = 1, d%nel
                        entries = entries + (3_int64*size(d%elements(nen)%conn))**2
                    end do
                    call check(error, 3*counted%ncp == d%total_dofs .and. counted%nel == d%nel .and. &
                               counted%entries == entries, 'body_size of case '//char(48 + c)//' on '// &
                               trim(faces(f)))
                    if (allocated(error)) return
                end do
            end associate
        end do
    end subroutine test_dof_formula

    !> A random parametric point inside element `e` (a fraction `margin` away from
    !> its faces).
    function inside(d, e, rng, margin) result(u)
        type(discretization_t), intent(in) :: d
        integer, intent(in) :: e
        type(lcg_t), intent(inout) :: rng
        real(dp), intent(in) :: margin
        real(dp) :: u(3)
        integer :: i
        do i = 1, 3
            u(i) = d%elements(e)%lo(i) + (margin + (1 - 2*margin)*rng%uniform())*(d%elements(e)%hi(i) - &
                                                                                  d%elements(e)%lo(i))
        end do
    end function inside

    !> sum R_a = 1 and sum R_a X_a = the refined exact map (the layer changes the
    !> functions, not the geometry), in every element of NN3.1 layouts.
    subroutine test_partition(error)
        type(error_t), allocatable, intent(out) :: error
        type(discretization_t) :: d
        type(lcg_t) :: rng
        real(dp), allocatable :: r(:), dr(:, :)
        real(dp) :: u(3), x(3), xb(3)
        integer :: e, f, k
        do f = 1, size(faces)
            call build(d, layout3(2, [2, 3, 2], 3, 1, faces(f)), error)
            if (allocated(error)) return
            do e = 1, d%nel
                allocate (r(element_nfun(d, e)), dr(3, element_nfun(d, e)))
                do k = 1, 3
                    u = inside(d, e, rng, 0.0_dp)
                    call element_basis(d, e, u, r, dr)
                    x = matmul(d%x(:, d%elements(e)%conn), r)
                    call patch_eval(d%bulk, u, xb)
                    call check(error, abs(sum(r) - 1.0_dp) < 1.0e-13_dp .and. maxval(abs(x - xb)) < 1.0e-12_dp, &
                               'partition or geometry on '//trim(faces(f)))
                    if (allocated(error)) return
                end do
                deallocate (r, dr)
            end do
        end do
    end subroutine test_partition

    !> dR/du against central differences of R, and d2R against those of dR, in VO
    !> elements of NN3.2 on the top face.
    subroutine test_derivatives(error)
        type(error_t), allocatable, intent(out) :: error
        type(discretization_t) :: d
        type(lcg_t) :: rng
        real(dp), allocatable :: r(:), dr(:, :), d2r(:, :), rp(:), drp(:, :), rm(:), drm(:, :)
        real(dp), parameter :: h = 1.0e-6_dp
        integer, parameter :: pair(2, 6) = reshape([1, 1, 2, 2, 3, 3, 1, 2, 1, 3, 2, 3], [2, 6])
        real(dp) :: u(3), step(3)
        integer :: e, i, n, k
        call build(d, layout3(2, [3, 2, 2], 3, 2, 'top'), error)
        if (allocated(error)) return
        do k = 1, 6
            e = d%nel - int(rng%uniform()*d%nels(1)*d%nels(2))
            call check(error, d%elements(e)%span_layer(1) > 0, 'a VO element')
            if (allocated(error)) return
            n = element_nfun(d, e)
            allocate (r(n), dr(3, n), d2r(6, n), rp(n), drp(3, n), rm(n), drm(3, n))
            u = inside(d, e, rng, 0.05_dp)
            call element_basis(d, e, u, r, dr, d2r)
            do i = 1, 3
                step = 0.0_dp
                step(i) = h
                call element_basis(d, e, u + step, rp, drp)
                call element_basis(d, e, u - step, rm, drm)
                call check(error, maxval(abs((rp - rm)/(2*h) - dr(i, :))) < 1.0e-6_dp*maxval(abs(dr)), &
                           'dR/du against differences')
                if (allocated(error)) return
            end do
            do i = 1, 6
                step = 0.0_dp
                step(pair(2, i)) = h
                call element_basis(d, e, u + step, rp, drp)
                call element_basis(d, e, u - step, rm, drm)
                call check(error, maxval(abs((drp(pair(1, i), :) - drm(pair(1, i), :))/(2*h) - d2r(i, :))) < &
                           1.0e-5_dp*maxval(abs(d2r)), 'd2R/du2 against differences')
                if (allocated(error)) return
            end do
            deallocate (r, dr, d2r, rp, drp, rm, drm)
        end do
    end subroutine test_derivatives

    !> A field sum u_a R_a is continuous across the faces of the VO elements: with
    !> the element below (zeta) and with the next VO element (xi), for random u.
    subroutine test_conforming(error)
        type(error_t), allocatable, intent(out) :: error
        type(discretization_t) :: d
        type(lcg_t) :: rng
        real(dp), allocatable :: uc(:)
        real(dp) :: u(3)
        integer :: e, below, nxt, k, i
        call build(d, layout3(2, [3, 2, 3], 4, 1, 'outer'), error)
        if (allocated(error)) return
        allocate (uc(d%ncp))
        do i = 1, d%ncp
            uc(i) = rng%uniform() - 0.5_dp
        end do
        do k = 1, 8
            e = d%nel - int(rng%uniform()*d%nels(1)*d%nels(2))
            below = e - d%nels(1)*d%nels(2)
            u = inside(d, e, rng, 0.0_dp)
            u(3) = d%elements(e)%lo(3)
            call check(error, abs(field(d, e, uc, u) - field(d, below, uc, u)) < 1.0e-13_dp, &
                       'the field jumps across the layer boundary')
            if (allocated(error)) return
            if (d%elements(e)%index(1) < d%nels(1)) then
                nxt = e + 1
                u = inside(d, e, rng, 0.0_dp)
                u(1) = d%elements(e)%hi(1)
                call check(error, abs(field(d, e, uc, u) - field(d, nxt, uc, u)) < 1.0e-13_dp, &
                           'the field jumps between VO elements')
                if (allocated(error)) return
            end if
        end do
    end subroutine test_conforming

    !> sum u_a R_a in element `e` at `u`.
    real(dp) function field(d, e, uc, u)
        type(discretization_t), intent(in) :: d
        integer, intent(in) :: e
        real(dp), intent(in) :: uc(:), u(3)
        real(dp) :: r(element_nfun(d, e)), dr(3, element_nfun(d, e))
        call element_basis(d, e, u, r, dr)
        field = dot_product(uc(d%elements(e)%conn), r)
    end function field

    !> The control points of each plane face lie in its plane (y = 0, x = 0, z = 0,
    !> z = 1), the layer's too, whichever face carries the layer; a face has as many
    !> points as functions are nonzero on it.
    subroutine test_faces(error)
        type(error_t), allocatable, intent(out) :: error
        type(discretization_t) :: d
        integer, parameter :: axis(3:6) = [2, 1, 3, 3]
        real(dp), parameter :: level(3:6) = [0.0_dp, 0.0_dp, 0.0_dp, 1.0_dp]
        integer :: f, b, g
        do f = 1, size(faces)
            call build(d, layout3(2, [2, 2, 3], 3, 0, faces(f)), error)
            if (allocated(error)) return
            do g = 3, 6
                b = boundary_index(d, faces(g))
                call check(error, b > 0, 'face '//trim(faces(g))//' named')
                if (allocated(error)) return
                associate (cps => d%boundaries(b)%cps)
                    call check(error, maxval(abs(d%x(axis(g), cps) - level(g))) < 1.0e-14_dp, &
                               trim(faces(g))//' with the layer on '//trim(faces(f)))
                    if (allocated(error)) return
                    call check(error, size(cps) == count_on_face(d, b), 'points on '//trim(faces(g)))
                    if (allocated(error)) return
                end associate
            end do
        end do
    end subroutine test_faces

    !> How many distinct functions are nonzero somewhere on boundary `b`: the
    !> control points of the elements touching it whose function is not zero on the
    !> face (sampled at the face's Gauss points).
    integer function count_on_face(d, b) result(n)
        type(discretization_t), intent(in) :: d
        integer, intent(in) :: b
        logical :: seen(d%ncp)
        real(dp), allocatable :: r(:), dr(:, :)
        real(dp) :: u(3), g(4), w(4)
        integer :: e, i, j, dir, a, o(2)
        call gauss_legendre(4, g, w)
        seen = .false.
        dir = d%boundaries(b)%direction
        o = pack([1, 2, 3], [1, 2, 3] /= dir)
        do e = 1, d%nel
            associate (el => d%elements(e))
                if (el%index(dir) /= merge(d%nels(dir), 1, d%boundaries(b)%side == 1)) cycle
                allocate (r(size(el%conn)), dr(3, size(el%conn)))
                do j = 1, 4
                    do i = 1, 4
                        u(dir) = merge(el%hi(dir), el%lo(dir), d%boundaries(b)%side == 1)
                        u(o(1)) = el%lo(o(1)) + 0.5_dp*(g(i) + 1)*(el%hi(o(1)) - el%lo(o(1)))
                        u(o(2)) = el%lo(o(2)) + 0.5_dp*(g(j) + 1)*(el%hi(o(2)) - el%lo(o(2)))
                        call element_basis(d, e, u, r, dr)
                        do a = 1, size(r)
                            if (abs(r(a)) > 1.0e-14_dp) seen(el%conn(a)) = .true.
                        end do
                    end do
                end do
                deallocate (r, dr)
            end associate
        end do
        n = count(seen)
    end function count_on_face

    !> Each face as the contact face: it becomes the last boundary, det J stays
    !> positive (the orientation is kept), and the volume by quadrature is the
    !> quarter ring's 3 pi/4 (8 Gauss points per direction: 1e-12).
    subroutine test_every_face(error)
        type(error_t), allocatable, intent(out) :: error
        type(discretization_t) :: d
        real(dp), allocatable :: r(:), dr(:, :)
        ! 8 points: det J is rational in the angle (the ring block's test in test_patch)
        real(dp) :: g(8), w(8), u(3), jac(3, 3), vol, det, wt
        integer :: f, e, i, j, k, n
        call gauss_legendre(8, g, w)
        do f = 1, size(faces)
            call build(d, layout3(2, [2, 2, 2], 3, 1, faces(f)), error)
            if (allocated(error)) return
            call check(error, trim(d%boundaries(contact_boundary(d))%name) == trim(faces(f)), &
                       trim(faces(f))//' is the contact boundary')
            if (allocated(error)) return
            vol = 0.0_dp
            do e = 1, d%nel
                associate (el => d%elements(e))
                    n = size(el%conn)
                    allocate (r(n), dr(3, n))
                    do k = 1, 8
                        do j = 1, 8
                            do i = 1, 8
                                u = el%lo + 0.5_dp*([g(i), g(j), g(k)] + 1)*(el%hi - el%lo)
                                call element_basis(d, e, u, r, dr)
                                jac = matmul(d%x(:, el%conn), transpose(dr))
                                det = jacobian_determinant(jac)
                                call check(error, det > 0.0_dp, 'orientation kept with '//trim(faces(f)))
                                if (allocated(error)) return
                                wt = w(i)*w(j)*w(k)*product(0.5_dp*(el%hi - el%lo))
                                vol = vol + wt*det
                            end do
                        end do
                    end do
                    deallocate (r, dr)
                end associate
            end do
            call check(error, vol, 0.75_dp*pi, 'volume with the layer on '//trim(faces(f)), rel=1.0e-12_dp)
            if (allocated(error)) return
        end do
    end subroutine test_every_face

    !> Layouts that cannot be built are refused with their cause named.
    subroutine test_bad(error)
        type(error_t), allocatable, intent(out) :: error
        type(discretization_t) :: d
        type(error_t), allocatable :: err
        call new_discretization(d, ring_block(), faces, layout3(2, [1, 1, 1], 3, 0, 'lid'), 'x: ', err)
        call expect(err, "contact_face = 'lid' is not a face of this body")
        if (allocated(error)) return
        call new_discretization(d, ring_block(), faces, layout3(2, [1, 1, 0], 0, 0, ''), 'x: ', err)
        call expect(err, 'nel_xi, nel_eta and nel_zeta must be >= 1')
        if (allocated(error)) return
        call new_discretization(d, ring_block(), faces, layout3(3, [1, 1, 1], 2, 0, 'top'), 'x: ', err)
        call expect(err, 'layer_degree must be >= degree_xi and degree_eta')
        if (allocated(error)) return
        call new_discretization(d, ring_block(), faces, layout3(1, [1, 1, 1], 0, 0, 'top'), 'x: ', err)
        call expect(err, 'degree_xi/degree_eta/degree_zeta must be >= the degree of the exact geometry')
    contains
        subroutine expect(got, text)
            type(error_t), allocatable, intent(in) :: got
            character(len=*), intent(in) :: text
            call check(error, allocated(got), 'refused: '//text)
            if (allocated(error)) return
            call check(error, index(got%message, text) > 0, 'message names the cause: '//got%message)
        end subroutine expect
    end subroutine test_bad

end module test_discretization_3d
