!> The external forces of the pressures: f_a = -int R_a p N dA over the reference
!> edge (a plane body) or face (a solid), N its outward unit normal; a positive
!> pressure pushes into the body (docs/formats.md, `&pressure`).
module voiga_model_pressure
    use voiga_kinds, only: dp
    use voiga_model, only: model_t
    use voiga_model_body, only: body_t
    use voiga_model_loads, only: phase_value
    use voiga_model_assembly_pattern, only: body_dofs
    use voiga_discretization_element, only: element_basis, element_nfun
    use voiga_element_quadrature, only: gauss_legendre
    use voiga_nurbs_patch, only: cross
    implicit none
    private

    public :: external_forces

contains

    !> External forces `f` [ndof] of the pressures at load time `t`.
    subroutine external_forces(model, t, f)
        type(model_t), intent(in) :: model
        real(dp), intent(in) :: t
        real(dp), intent(out) :: f(:)
        real(dp) :: p
        integer :: k
        f = 0.0_dp
        do k = 1, size(model%pressure)
            p = phase_value(model%pressure(k)%values, t)
            if (p == 0.0_dp) cycle
            associate (body => model%bodies(model%pressure(k)%body))
                if (body%disc%nsd == 2) then
                    call edge_pressure(body, model%pressure(k)%edge, p, f)
                else
                    call face_pressure(body, model%pressure(k)%edge, p, f)
                end if
            end associate
        end do
    end subroutine external_forces

    !> The pressure `p` on edge `edge` (1..4: xi0, xi1, eta0, eta1) of the plane body
    !> `body`, added to `f`.
    subroutine edge_pressure(body, edge, p, f)
        type(body_t), intent(in) :: body
        integer, intent(in) :: edge
        real(dp), intent(in) :: p
        real(dp), intent(inout) :: f(:)
        real(dp), allocatable :: gx(:), wx(:), r(:), dr(:, :), d2r(:, :), x0(:, :)
        integer, allocatable :: dofs(:)
        real(dp) :: s, tang(2), inward(2), normal(2), uv(2), h, jac(2, 2)
        integer :: e, i, a, nen, dir, ng
        logical :: on_edge
        ! along xi for the eta edges (3, 4), along eta for the xi edges (1, 2)
        dir = merge(1, 2, edge >= 3)
        ng = body%n_gauss(dir)
        allocate (gx(ng), wx(ng))
        call gauss_legendre(ng, gx, wx)
        do e = 1, body%disc%nel
            associate (el => body%disc%elements(e))
                ! the edge is normal to direction 3 - dir, at its start (edges 1, 3) or end
                on_edge = el%index(3 - dir) == merge(1, body%disc%nels(3 - dir), mod(edge, 2) == 1)
                if (.not. on_edge) cycle
                nen = element_nfun(body%disc, e)
                allocate (r(nen), dr(2, nen), d2r(3, nen))
                x0 = body%disc%x(:, el%conn)
                dofs = body_dofs(body, e)
                h = 0.5_dp*(el%hi(dir) - el%lo(dir))
                do i = 1, ng
                    s = el%lo(dir) + h*(gx(i) + 1.0_dp)
                    uv(dir) = s
                    uv(3 - dir) = merge(el%lo(3 - dir), el%hi(3 - dir), mod(edge, 2) == 1)
                    call element_basis(body%disc, e, uv, r, dr, d2r)
                    jac = matmul(x0, transpose(dr))
                    tang = jac(:, dir)
                    ! the other parametric direction points inward at a 0-edge
                    inward = jac(:, 3 - dir)*merge(1.0_dp, -1.0_dp, edge == 1 .or. edge == 3)
                    normal = [tang(2), -tang(1)]/norm2(tang)
                    if (dot_product(normal, inward) > 0.0_dp) normal = -normal
                    do a = 1, nen
                        f(dofs(2*a - 1:2*a)) = f(dofs(2*a - 1:2*a)) - p*r(a)*normal*norm2(tang)*wx(i)*h
                    end do
                end do
                deallocate (r, dr, d2r)
            end associate
        end do
    end subroutine edge_pressure

    !> The pressure `p` on face `face` (1..6: xi0, xi1, eta0, eta1, zeta0, zeta1) of
    !> the solid `body`, added to `f`: N dA = t_1 x t_2 du_1 du_2 from the face's two
    !> parametric tangents, turned outward.
    subroutine face_pressure(body, face, p, f)
        type(body_t), intent(in) :: body
        integer, intent(in) :: face
        real(dp), intent(in) :: p
        real(dp), intent(inout) :: f(:)
        real(dp), allocatable :: g1(:), w1(:), g2(:), w2(:), r(:), dr(:, :)
        integer, allocatable :: dofs(:)
        real(dp) :: u(3), jac(3, 3), area(3), h(2), wt
        integer :: e, i, j, a, nen, dir, side, o(2)
        dir = (face + 1)/2
        side = 1 - mod(face, 2)
        o = pack([1, 2, 3], [1, 2, 3] /= dir)
        allocate (g1(body%n_gauss(o(1))), w1(body%n_gauss(o(1))), g2(body%n_gauss(o(2))), w2(body%n_gauss(o(2))))
        call gauss_legendre(size(g1), g1, w1)
        call gauss_legendre(size(g2), g2, w2)
        do e = 1, body%disc%nel
            associate (el => body%disc%elements(e))
                if (el%index(dir) /= merge(body%disc%nels(dir), 1, side == 1)) cycle
                nen = element_nfun(body%disc, e)
                allocate (r(nen), dr(3, nen))
                dofs = body_dofs(body, e)
                h = 0.5_dp*(el%hi(o) - el%lo(o))
                u(dir) = merge(el%hi(dir), el%lo(dir), side == 1)
                do j = 1, size(g2)
                    do i = 1, size(g1)
                        u(o(1)) = el%lo(o(1)) + h(1)*(g1(i) + 1.0_dp)
                        u(o(2)) = el%lo(o(2)) + h(2)*(g2(j) + 1.0_dp)
                        call element_basis(body%disc, e, u, r, dr)
                        jac = matmul(body%disc%x(:, el%conn), transpose(dr))
                        area = cross(jac(:, o(1)), jac(:, o(2)))
                        ! direction `dir` points into the body at the start of its range
                        if (dot_product(area, jac(:, dir))*merge(1.0_dp, -1.0_dp, side == 0) > 0.0_dp) area = -area
                        wt = w1(i)*w2(j)*h(1)*h(2)
                        do a = 1, nen
                            f(dofs(3*a - 2:3*a)) = f(dofs(3*a - 2:3*a)) - p*r(a)*wt*area
                        end do
                    end do
                end do
                deallocate (r, dr)
            end associate
        end do
    end subroutine face_pressure

end module voiga_model_pressure
