!> Where a pair's slave points lie on a face, and what a slave point sees: its
!> evaluation, reference position and projection onto the master
!> (`voiga_contact_pair`; a submodule only to keep the files short, the interfaces are
!> in the module).
submodule(voiga_contact_pair) voiga_contact_pair_points
    implicit none

contains

    module procedure face_points
        integer :: ng, nu, nv, np, ci, cj, i, j, k
        real(dp) :: lo(2), hi(2)
        ng = size(gx)
        nu = size(self%slave%spans)
        nv = size(self%slave%spans_eta)
        np = (self%slave%degree + 1)*(self%slave%degree_eta + 1)
        allocate (self%xi(nu*nv*ng*ng), self%eta(nu*nv*ng*ng), self%w(nu*nv*ng*ng), &
                  self%span(nu*nv*ng*ng), self%span_eta(nu*nv*ng*ng), self%slave_basis(np, 3, nu*nv*ng*ng))
        k = 0
        do cj = 1, nv
            do ci = 1, nu
                lo = [self%slave%breaks(ci), self%slave%breaks_eta(cj)]
                hi = [self%slave%breaks(ci + 1), self%slave%breaks_eta(cj + 1)]
                do j = 1, ng
                    do i = 1, ng
                        k = k + 1
                        self%xi(k) = lo(1) + 0.5_dp*(hi(1) - lo(1))*(gx(i) + 1.0_dp)
                        self%eta(k) = lo(2) + 0.5_dp*(hi(2) - lo(2))*(gx(j) + 1.0_dp)
                        self%w(k) = 0.25_dp*(hi(1) - lo(1))*(hi(2) - lo(2))*gw(i)*gw(j)
                        self%span(k) = self%slave%spans(ci)
                        self%span_eta(k) = self%slave%spans_eta(cj)
                        call face_basis(self%slave, self%xi(k), self%eta(k), [self%span(k), self%span_eta(k)], &
                                        self%slave_basis(:, 1, k), self%slave_basis(:, 2, k), &
                                        self%slave_basis(:, 3, k))
                    end do
                end do
            end do
        end do
    end procedure face_points

    module procedure pair_project_point
        real(dp) :: a0(3), b0(3), jac0
        if (self%slave%npar > 1) then
            call face_point_at(self%slave, u, self%xi(k), self%eta(k), [self%span(k), self%span_eta(k)], &
                               self%slave_basis(:, 1, k), self%slave_basis(:, 2, k), self%slave_basis(:, 3, k), sp)
        else if (allocated(self%slave_basis)) then
            call surface_point_at(self%slave, u, self%xi(k), self%span(k), self%slave_basis(:, 1, k), &
                                  self%slave_basis(:, 2, k), self%slave_basis(:, 3, k), sp)
        else
            call surface_point(self%slave, u, self%xi(k), sp, self%span(k))
        end if
        associate (out => self%out(k))
            call reference_point(self%slave, sp, out%x0, a0, b0)
            out%x = sp%x
            if (self%slave%npar > 1) then
                jac0 = norm2(cross(a0, b0))
                out%stretch = norm2(cross(sp%a, sp%b))/jac0
            else
                jac0 = norm2(a0(1:2))
                out%stretch = norm2(sp%a(1:2))/jac0
            end if
            out%area0 = self%w(k)*jac0
            out%state = state_inactive
            out%pn = 0.0_dp
            out%pt = 0.0_dp
            out%pn0 = 0.0_dp
            out%pt0 = 0.0_dp
            out%tt = 0.0_dp
            if (self%warm .and. self%slave%npar > 1) then
                call self%master%project(u, sp%x(1:self%nsd), mp, found, converged, [out%xi_m, out%eta_m])
            else if (self%warm) then
                call self%master%project(u, sp%x(1:self%nsd), mp, found, converged, [out%xi_m])
            else
                call self%master%project(u, sp%x(1:self%nsd), mp, found, converged)
            end if
            out%xi_m = mp%xi
            out%eta_m = mp%eta
            out%first = mp%first
            out%last = mp%last
            out%gap = huge(1.0_dp)
            if (found) out%gap = dot_product(sp%x - mp%x, mp%n)
        end associate
    end procedure pair_project_point

    !> The reference position `x0` and tangents `a0` (by xi), `b0` (by eta, on a
    !> face) of the slave point `sp` (its functions at the reference control points).
    pure subroutine reference_point(slave, sp, x0, a0, b0)
        type(contact_surface_t), intent(in) :: slave
        type(surface_point_t), intent(in) :: sp
        real(dp), intent(out) :: x0(3), a0(3), b0(3)
        integer :: j, d
        d = size(slave%x0, 1)
        x0 = 0.0_dp
        a0 = 0.0_dp
        b0 = 0.0_dp
        do j = 1, size(sp%local)
            x0(1:d) = x0(1:d) + slave%x0(:, sp%local(j))*sp%r(j)
            a0(1:d) = a0(1:d) + slave%x0(:, sp%local(j))*sp%dr(j)
            if (slave%npar > 1) b0(1:d) = b0(1:d) + slave%x0(:, sp%local(j))*sp%drb(j)
        end do
    end subroutine reference_point

end submodule voiga_contact_pair_points
