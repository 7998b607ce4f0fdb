!> The discretization: DOF counts of the paper's Table 2, geometry invariance of
!> every layout, the VO element basis (partition of unity, non-negativity,
!> derivatives by finite differences) and its conformity with the next row.
module test_discretization
    use, intrinsic :: iso_fortran_env, only: int64
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_testdrive, only: unittest_t, new_unittest, check
    use voiga_nurbs_surface, only: nurbs_surface_t, surface_eval, surface_patch
    use voiga_discretization_layout, only: layout_t
    use voiga_discretization_patch, only: discretization_t, new_discretization, contact_boundary
    use voiga_discretization_size, only: body_size_t, body_size
    use voiga_discretization_element, only: element_basis, element_nfun
    use voiga_test_fixtures, only: paper_layout, lcg_t, annulus_sector, rectangle
    implicit none
    private

    public :: collect_discretization

    real(dp), parameter :: pi = acos(-1.0_dp)

contains

    subroutine collect_discretization(testsuite)
        type(unittest_t), allocatable, intent(out) :: testsuite(:)
        testsuite = [ &
                    new_unittest('table2_dofs', test_table2), &
                    new_unittest('geometry_invariance', test_invariance), &
                    new_unittest('reoriented_contact_edge', test_reorient), &
                    new_unittest('vo_basis_partition', test_vo_partition), &
                    new_unittest('vo_basis_derivatives_fd', test_vo_fd), &
                    new_unittest('vo_row_conforming', test_vo_conforming), &
                    new_unittest('bad_layouts_refused', test_bad_layouts), &
                    new_unittest('size_counted_without_building', test_size) &
                    ]
    end subroutine collect_discretization


    function die() result(s)
        type(nurbs_surface_t) :: s
        s = annulus_sector([2.5_dp, 3.0_dp], 2.0_dp, 3.0_dp, pi, 2)
    end function die

    !> The names of the die's edges.
    function die_edges() result(names)
        character(len=32) :: names(4)
        type(nurbs_surface_t) :: s
        s = die()
        names = s%edge_names
    end function die_edges

    function slab() result(s)
        type(nurbs_surface_t) :: s
        s = rectangle(0.0_dp, -3.0_dp, 9.0_dp, 3.0_dp)
    end function slab

    !> Table 2 of the paper (ironing, m1): interface / bulk DOFs of die and slab.
    subroutine test_table2(error)
        type(error_t), allocatable, intent(out) :: error
        character(len=5), parameter :: names(8) = [character(len=5) :: 'N2', 'N4', 'N6', 'NN4', &
                                                    'NN6', 'NN2.1', 'NN2.2', 'NN2.3']
        integer, parameter :: expected(4, 8) = reshape([ &
                                                       18, 36, 20, 60, &
                                                       26, 52, 24, 72, &
                                                       34, 68, 28, 84, &
                                                       26, 36, 24, 60, &
                                                       34, 36, 28, 60, &
                                                       30, 36, 36, 60, &
                                                       42, 36, 52, 60, &
                                                       54, 36, 68, 60], [4, 8])
        type(discretization_t) :: d, s
        integer :: k

        do k = 1, size(names)
            call new_discretization(d, die(), paper_layout(trim(names(k)), [6, 1], 'outer'), '', error)
            if (allocated(error)) return
            call new_discretization(s, slab(), paper_layout(trim(names(k)), [8, 2], 'top'), '', error)
            if (allocated(error)) return
            call check(error, d%interface_dofs, expected(1, k), trim(names(k))//' die interface')
            if (allocated(error)) return
            call check(error, d%bulk_dofs, expected(2, k), trim(names(k))//' die bulk')
            if (allocated(error)) return
            call check(error, s%interface_dofs, expected(3, k), trim(names(k))//' slab interface')
            if (allocated(error)) return
            call check(error, s%bulk_dofs, expected(4, k), trim(names(k))//' slab bulk')
            if (allocated(error)) return
            call check(error, d%nel, 6, trim(names(k))//' die elements')
            if (allocated(error)) return
            call check(error, s%nel, 16, trim(names(k))//' slab elements')
            if (allocated(error)) return
        end do
    end subroutine test_table2

    !> Map (xi, eta) through element e's basis: point and Jacobian.
    subroutine element_map(disc, e, xi, eta, x, jac)
        type(discretization_t), intent(in) :: disc
        integer, intent(in) :: e
        real(dp), intent(in) :: xi, eta
        real(dp), intent(out) :: x(2), jac(2, 2)
        real(dp), allocatable :: r(:), dr(:, :), d2r(:, :)
        integer :: n
        n = element_nfun(disc, e)
        allocate (r(n), dr(2, n), d2r(3, n))
        call element_basis(disc, e, [xi, eta], r, dr, d2r)
        x = matmul(disc%x(:, disc%elements(e)%conn), r)
        jac = matmul(disc%x(:, disc%elements(e)%conn), transpose(dr))
    end subroutine element_map

    !> Worst point and Jacobian mismatch between the element map of `disc` and
    !> the surface `exact` at 1000 points (20 per element row/column mix).
    subroutine worst_mismatch(disc, exact, dx, djac, dnormal)
        type(discretization_t), intent(in) :: disc
        type(nurbs_surface_t), intent(in) :: exact
        real(dp), intent(out) :: dx, djac, dnormal
        type(lcg_t) :: rng
        real(dp) :: xi, eta, x(2), xe(2), jac(2, 2), jace(2, 2), n1(2), n2(2)
        integer :: k, e
        dx = 0.0_dp
        djac = 0.0_dp
        dnormal = 0.0_dp
        do k = 1, 1000
            e = 1 + int(rng%uniform()*disc%nel)
            associate (el => disc%elements(e))
                xi = el%lo(1) + rng%uniform()*(el%hi(1) - el%lo(1))
                eta = el%lo(2) + rng%uniform()*(el%hi(2) - el%lo(2))
                ! every fifth point on the contact edge, where normals matter
                if (mod(k, 5) == 0 .and. el%index(2) == disc%nels(2)) eta = el%hi(2)
            end associate
            call element_map(disc, e, xi, eta, x, jac)
            call surface_eval(exact, xi, eta, xe, jace)
            dx = max(dx, norm2(x - xe))
            djac = max(djac, maxval(abs(jac - jace))/maxval(abs(jace)))
            ! unit normal of the eta = const line through the point
            n1 = [jac(2, 1), -jac(1, 1)]/norm2(jac(:, 1))
            n2 = [jace(2, 1), -jace(1, 1)]/norm2(jace(:, 1))
            dnormal = max(dnormal, norm2(n1 - n2))
        end do
    end subroutine worst_mismatch

    !> After every refinement the element maps reproduce the exact patch.
    subroutine test_invariance(error)
        type(error_t), allocatable, intent(out) :: error
        character(len=5), parameter :: names(9) = [character(len=5) :: 'N2', 'N4', 'N6', 'NN4', &
                                                    'NN6', 'NN2.1', 'NN2.2', 'NN2.3', 'NN3.2']
        type(discretization_t) :: d
        type(nurbs_surface_t) :: exact
        real(dp) :: dx, djac, dnormal
        integer :: k, ib

        do ib = 1, 3
            select case (ib)
            case (1); exact = die()
            case (2); exact = slab()
            case (3); exact = annulus_sector([0.0_dp, 0.0_dp], 0.05_dp, 1.0_dp, -pi/2, 1)
            end select
            do k = 1, size(names)
                call new_discretization(d, exact, paper_layout(trim(names(k)), [12, 3], 'outer'), &
                                        '', error)
                if (ib == 2) then
                    call new_discretization(d, exact, paper_layout(trim(names(k)), [12, 3], 'top'), &
                                            '', error)
                end if
                if (allocated(error)) return
                call worst_mismatch(d, exact, dx, djac, dnormal)
                call check(error, dx, 0.0_dp, trim(names(k))//': mapped points', abs=1.0e-12_dp)
                if (allocated(error)) return
                call check(error, djac, 0.0_dp, trim(names(k))//': Jacobian', abs=1.0e-12_dp)
                if (allocated(error)) return
                call check(error, dnormal, 0.0_dp, trim(names(k))//': normals', abs=1.0e-12_dp)
                if (allocated(error)) return
            end do
        end do
    end subroutine test_invariance

    !> A contact edge that is not eta = 1 gives the same counts and the same
    !> geometry (the patch is rotated in parameter space, not in space).
    subroutine test_reorient(error)
        type(error_t), allocatable, intent(out) :: error
        type(discretization_t) :: a, b
        type(nurbs_surface_t) :: s
        character(len=8), parameter :: edges(4) = [character(len=8) :: 'left', 'right', 'bottom', 'top']
        real(dp) :: x(2), xe(2), jac(2, 2), xi, eta
        type(lcg_t) :: rng
        integer :: k, i, e

        s = slab()
        call new_discretization(a, s, paper_layout('NN2.2', [4, 4], 'top'), '', error)
        if (allocated(error)) return
        do k = 1, 4
            call new_discretization(b, s, paper_layout('NN2.2', [4, 4], trim(edges(k))), '', error)
            if (allocated(error)) return
            call check(error, b%interface_dofs, a%interface_dofs, 'interface DOFs with contact edge '// &
                       trim(edges(k)))
            if (allocated(error)) return
            call check(error, trim(b%boundaries(contact_boundary(b))%name), trim(edges(k)), 'contact edge is eta = 1')
            if (allocated(error)) return
            ! every point of the oriented map lies in the slab, and the contact edge on its edge
            do i = 1, 200
                e = 1 + int(rng%uniform()*b%nel)
                xi = b%elements(e)%lo(1) + rng%uniform()*(b%elements(e)%hi(1) - b%elements(e)%lo(1))
                eta = 1.0_dp
                if (b%elements(e)%index(2) /= b%nels(2)) eta = b%elements(e)%lo(2)
                call element_map(b, e, xi, eta, x, jac)
                if (b%elements(e)%index(2) == b%nels(2)) then
                    select case (k)
                    case (1); xe = [0.0_dp, x(2)]
                    case (2); xe = [9.0_dp, x(2)]
                    case (3); xe = [x(1), -3.0_dp]
                    case (4); xe = [x(1), 0.0_dp]
                    end select
                    call check(error, norm2(x - xe), 0.0_dp, 'contact edge point on edge '// &
                               trim(edges(k)), abs=1.0e-12_dp)
                    if (allocated(error)) return
                end if
                call check(error, x(1) >= -1e-12_dp .and. x(1) <= 9 + 1e-12_dp .and. &
                           x(2) >= -3 - 1e-12_dp .and. x(2) <= 1e-12_dp, 'point inside the slab')
                if (allocated(error)) return
            end do
        end do
    end subroutine test_reorient

    !> Partition of unity and non-negativity of VO and standard elements.
    subroutine test_vo_partition(error)
        type(error_t), allocatable, intent(out) :: error
        type(discretization_t) :: d
        type(lcg_t) :: rng
        real(dp), allocatable :: r(:), dr(:, :), d2r(:, :)
        real(dp) :: xi, eta
        integer :: k, e, n, il
        character(len=5), parameter :: names(4) = [character(len=5) :: 'NN4', 'NN2.2', 'NN3.2', 'N4']

        do il = 1, size(names)
            call new_discretization(d, die(), paper_layout(trim(names(il)), [6, 2], 'outer'), '', error)
            if (allocated(error)) return
            do k = 1, 500
                e = 1 + int(rng%uniform()*d%nel)
                xi = d%elements(e)%lo(1) + rng%uniform()*(d%elements(e)%hi(1) - d%elements(e)%lo(1))
                eta = d%elements(e)%lo(2) + rng%uniform()*(d%elements(e)%hi(2) - d%elements(e)%lo(2))
                n = element_nfun(d, e)
                allocate (r(n), dr(2, n), d2r(3, n))
                call element_basis(d, e, [xi, eta], r, dr, d2r)
                call check(error, sum(r), 1.0_dp, trim(names(il))//': partition of unity', abs=1.0e-14_dp)
                if (allocated(error)) return
                call check(error, all(r >= 0.0_dp), trim(names(il))//': non-negativity')
                if (allocated(error)) return
                call check(error, sum(dr(1, :)), 0.0_dp, trim(names(il))//': sum dR/dxi', abs=1.0e-11_dp)
                if (allocated(error)) return
                call check(error, sum(d2r(3, :)), 0.0_dp, trim(names(il))//': sum d2R/dxideta', &
                           abs=1.0e-9_dp)
                if (allocated(error)) return
                deallocate (r, dr, d2r)
            end do
            if (trim(names(il)) == 'NN3.2') then
                ! a contact-row element has (q+1) + (p+1)*p_eta functions: degree 5 layer -> 6 + 3*2
                call check(error, element_nfun(d, d%nel), 6 + 3*2, 'functions in an NN3.2 contact element')
                if (allocated(error)) return
            end if
        end do
    end subroutine test_vo_partition

    !> First and second parametric derivatives of VO element functions by central differences.
    subroutine test_vo_fd(error)
        type(error_t), allocatable, intent(out) :: error
        type(discretization_t) :: d
        type(lcg_t) :: rng
        real(dp), parameter :: h = 1.0e-6_dp
        real(dp), allocatable :: r(:), dr(:, :), d2r(:, :), rp(:), drp(:, :), d2rp(:, :), &
                                 rm(:), drm(:, :), d2rm(:, :)
        real(dp) :: xi, eta, off(2)
        integer :: k, e, n, dir

        call new_discretization(d, die(), paper_layout('NN2.2', [6, 2], 'outer'), '', error)
        if (allocated(error)) return
        do k = 1, 200
            ! VO elements are the last row
            e = d%nel - d%nels(1) + 1 + int(rng%uniform()*d%nels(1))
            xi = d%elements(e)%lo(1) + (0.05_dp + 0.9_dp*rng%uniform())*(d%elements(e)%hi(1) - d%elements(e)%lo(1))
            eta = d%elements(e)%lo(2) + (0.05_dp + 0.9_dp*rng%uniform())*(d%elements(e)%hi(2) - d%elements(e)%lo(2))
            n = element_nfun(d, e)
            allocate (r(n), dr(2, n), d2r(3, n), rp(n), drp(2, n), d2rp(3, n), rm(n), drm(2, n), d2rm(3, n))
            call element_basis(d, e, [xi, eta], r, dr, d2r)
            do dir = 1, 2
                off = 0.0_dp
                off(dir) = h
                call element_basis(d, e, [xi + off(1), eta + off(2)], rp, drp, d2rp)
                call element_basis(d, e, [xi - off(1), eta - off(2)], rm, drm, d2rm)
                ! O(h^2) truncation and eps/h round-off: 1e-6 relative to O(10) derivatives
                call check(error, dr(dir, :), (rp - rm)/(2*h), 'dR vs FD', rel=1.0e-6_dp, abs=1.0e-6_dp)
                if (allocated(error)) return
                call check(error, d2r(dir, :), (drp(dir, :) - drm(dir, :))/(2*h), 'd2R (pure) vs FD', &
                           rel=1.0e-5_dp, abs=1.0e-4_dp)
                if (allocated(error)) return
                call check(error, d2r(3, :), (drp(3 - dir, :) - drm(3 - dir, :))/(2*h), &
                           'd2R (mixed) vs FD', rel=1.0e-5_dp, abs=1.0e-4_dp)
                if (allocated(error)) return
            end do
            deallocate (r, dr, d2r, rp, drp, d2rp, rm, drm, d2rm)
        end do
    end subroutine test_vo_fd

    !> A random field is continuous (value and derivative along xi) across the
    !> boundary between the VO row and the row below it.
    subroutine test_vo_conforming(error)
        type(error_t), allocatable, intent(out) :: error
        type(discretization_t) :: d
        type(lcg_t) :: rng
        real(dp), allocatable :: u(:), r(:), dr(:, :), d2r(:, :)
        real(dp) :: xi, eta, above, below, dabove, dbelow
        integer :: k, e_top, e_low, i

        call new_discretization(d, die(), paper_layout('NN2.3', [6, 3], 'outer'), '', error)
        if (allocated(error)) return
        allocate (u(d%ncp))
        do i = 1, d%ncp
            u(i) = rng%uniform()
        end do
        do k = 1, 100
            e_top = d%nel - d%nels(1) + 1 + int(rng%uniform()*d%nels(1))
            e_low = e_top - d%nels(1)
            xi = d%elements(e_top)%lo(1) + rng%uniform()*(d%elements(e_top)%hi(1) - d%elements(e_top)%lo(1))
            eta = d%elements(e_top)%lo(2)
            call eval(e_top, above, dabove)
            call eval(e_low, below, dbelow)
            call check(error, above, below, 'field across the VO row boundary', abs=1.0e-13_dp)
            if (allocated(error)) return
            call check(error, dabove, dbelow, 'd/dxi across the VO row boundary', abs=1.0e-12_dp)
            if (allocated(error)) return
        end do
    contains
        subroutine eval(e, val, dval)
            integer, intent(in) :: e
            real(dp), intent(out) :: val, dval
            integer :: n
            n = element_nfun(d, e)
            allocate (r(n), dr(2, n), d2r(3, n))
            call element_basis(d, e, [xi, eta], r, dr, d2r)
            val = dot_product(u(d%elements(e)%conn), r)
            dval = dot_product(u(d%elements(e)%conn), dr(1, :))
            deallocate (r, dr, d2r)
        end subroutine eval
    end subroutine test_vo_conforming

    !> Layouts that make no sense are refused with a message naming the field.
    subroutine test_bad_layouts(error)
        type(error_t), allocatable, intent(out) :: error
        type(discretization_t) :: d
        type(layout_t) :: layout
        type(error_t), allocatable :: err

        layout = paper_layout('NN4', [6, 1], 'outer')
        layout%layer_degree = 1
        call new_discretization(d, die(), layout, 'x: ', err)
        call expect(err, 'layer_degree')
        if (allocated(error)) return
        layout = paper_layout('N2', [6, 1], 'nowhere')
        call new_discretization(d, die(), layout, 'x: ', err)
        call expect(err, "contact_edge = 'nowhere'")
        if (allocated(error)) return
        layout = paper_layout('N2', [6, 1], 'outer')
        layout%degree(:2) = [1, 2]
        call new_discretization(d, die(), layout, 'x: ', err)
        call expect(err, 'degree_xi')
        if (allocated(error)) return
        layout = paper_layout('N2', [6, 1], 'outer')
        layout%knots_xi = [0.5_dp, 0.25_dp]
        call new_discretization(d, die(), layout, 'x: ', err)
        call expect(err, 'knots_xi must be strictly increasing')
        if (allocated(error)) return
        layout = paper_layout('N2', [6, 1], '')
        layout%layer_elevations = 1
        call new_discretization(d, die(), layout, 'x: ', err)
        call expect(err, 'layer_elevations')
    contains
        subroutine expect(got, text)
            type(error_t), allocatable, intent(inout) :: got
            character(len=*), intent(in) :: text
            if (.not. allocated(got)) then
                call check(error, .false., 'expected an error mentioning '//text)
                return
            end if
            call check(error, index(got%message, text) > 0, "message '"//got%message// &
                       "' should mention "//text)
            deallocate (got)
        end subroutine expect
    end subroutine test_bad_layouts

    !> The counts the memory check uses (`body_size`) are those of the built
    !> discretization, for every layout of the paper, each contact edge, a patch
    !> with a C0 interior knot (the die: multiplicity 2), mesh counts that do and do
    !> not meet it, and explicit knots.
    subroutine test_size(error)
        type(error_t), allocatable, intent(out) :: error
        character(len=5), parameter :: names(9) = [character(len=5) :: 'L1', 'N2', 'N4', 'N6', 'NN4', &
                                                    'NN6', 'NN2.1', 'NN2.2', 'NN2.3']
        character(len=5), parameter :: edges(4) = [character(len=5) :: 'start', 'end', 'inner', 'outer']
        integer, parameter :: meshes(2, 3) = reshape([6, 1, 5, 3, 3, 2], [2, 3])
        type(discretization_t) :: d
        type(layout_t) :: layout
        type(body_size_t) :: counted
        integer(int64) :: entries
        integer :: k, e, m, el

        do k = 1, size(names)
            do e = 1, size(edges)
                do m = 1, size(meshes, 2)
                    layout = paper_layout(trim(names(k)), meshes(:, m), trim(edges(e)))
                    if (m == 3) layout%knots_xi = [0.2_dp, 0.5_dp, 0.7_dp]
                    call new_discretization(d, die(), layout, '', error)
                    if (allocated(error)) return
                    counted = body_size(surface_patch(die()), die_edges(), layout)
                    entries = 0
                    do el = 1, d%nel
                        entries = entries + (2_int64*size(d%elements(el)%conn))**2
                    end do
                    call check(error, counted%ncp == d%ncp .and. counted%nel == d%nel .and. &
                               counted%entries == entries, &
                               'counts of '//trim(names(k))//' with contact edge '//trim(edges(e)))
                    if (allocated(error)) return
                end do
            end do
        end do
    end subroutine test_size

end module test_discretization
