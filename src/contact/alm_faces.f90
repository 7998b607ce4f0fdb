!> The augmented Lagrangian on a face with friction (`voiga_contact_alm`; a submodule
!> so that the module keeps the edge's and the frictionless face's case, the
!> interfaces are there). The mortar pair's face law (`mortar_faces.f90`) has a
!> tangential traction vector t_A per control point in Cartesian components; here its
!> reference is a multiplier vector tau_A instead of the committed traction:
!>
!>     p_A = max(0, lambda_A - eps_N g_A / D_A),
!>     t_A = return map of  tau_A - eps_T ds_A / D_A  onto the disc |t| <= mu p_A,
!>
!> so Newton solves the mortar pair's problem with its tangent. The constraints of a
!> sticking control point are the two components of its counted weighted slip ds_A on
!> the tangent plane of its node normal n_A (the normalized N_A-weighted master
!> normals of its points), e_i . ds_A = 0, with e_1, e_2 an orthonormal frame of that
!> plane: ds_A's normal component is zero on a flat master (a third constraint would
!> make the Schur complement singular) and second order on a curved one, and each
!> point takes only the tangential part of sum_A N_A t_A. A sticking control point's
!> tau_A moves along e_1, e_2; a slipping one's follows the law (tau_A = t_A).
submodule(voiga_contact_alm) voiga_contact_alm_faces
    use voiga_contact_law, only: control_point_law3
    implicit none

contains

    !> The law at every node on the gaps shifted by the multipliers (as
    !> `alm_control_laws`) with tau_A as the tangential reference; the unshifted gaps,
    !> the slips and normals are kept, the tractions go to the history's trial values.
    module procedure alm_control_laws3
        integer :: a
        self%g = g_a
        self%d = d_a
        self%ds3 = ds
        self%n3 = n_a
        do a = 1, size(g_a)
            if (g_a(a) < huge(1.0_dp)) g_a(a) = g_a(a) - self%hist%field(self%h_lambda)%trial(a)*d_a(a)/self%law%eps_n
            call control_point_law3(self%law, g_a(a), d_a(a), ds(:, a), self%tau3(:, a), self%gap_tol, p_a(a), &
                                    t(:, a), st_a(a), t_tr(:, a))
            self%hist%field(self%h_traction)%trial(a) = t(1, a)
            self%hist%field(self%h_traction_yz(1))%trial(a) = t(2, a)
            self%hist%field(self%h_traction_yz(2))%trial(a) = t(3, a)
        end do
        self%state = st_a
        self%p_last = p_a
        self%t3 = t
        self%ttr3 = t_tr
    end procedure alm_control_laws3

    !> Keep the coupling of active control point `a`: v, the columns of Q, the rows of M.
    module procedure alm_keep_coupling3
        real(dp) :: row(size(blk))
        integer :: i
        self%v(a) = sparse_vector_t(blk, v)
        do i = 1, 3
            self%q3(i, a) = sparse_vector_t(blk, q(:, i))
            ! (through a contiguous copy: gfortran gave the row section m(i, :) to the
            ! constructor as the contiguous values from m(i, 1), the alm_faces_constraints_fd test)
            row = m(i, :)
            self%m3(i, a) = sparse_vector_t(blk, row)
        end do
    end procedure alm_keep_coupling3

    !> g_A = 0 for every active control point (multiplier lambda_A; d r / d lambda_A =
    !> -v_A, and -mu Q_A nu_A more where A slips, nu_A = t_A^tr / |t_A^tr|), then
    !> e_i . ds_A = 0, i = 1, 2, for every sticking one (multiplier tau_A . e_i;
    !> d r / d (tau_A . e_i) = -Q_A e_i, d c / du = e_i^T M_A).
    module procedure face_constraints
        integer, allocatable :: active(:), stick(:)
        real(dp) :: e(3, 2), nu(3)
        integer :: j, a, i, n, row
        active = pack([(a, a=1, size(self%state))], self%state /= state_inactive)
        allocate (stick(0))
        if (self%law%mu > 0.0_dp) stick = pack([(a, a=1, size(self%state))], self%state == state_stick)
        n = size(active) + 2*size(stick)
        allocate (set%c(n), set%rows(n), set%cols(n))
        do j = 1, size(active)
            a = active(j)
            set%c(j) = self%g(a)
            set%rows(j) = self%v(a)
            set%cols(j) = sparse_vector_t(self%v(a)%dofs, -self%v(a)%values)
            if (self%state(a) == state_slip) then
                nu = self%ttr3(:, a)/norm2(self%ttr3(:, a))
                set%cols(j)%values = set%cols(j)%values - self%law%mu*combine(self%q3, a, nu)
            end if
        end do
        do j = 1, size(stick)
            a = stick(j)
            e = tangent_frame(self%n3(:, a))
            do i = 1, 2
                row = size(active) + 2*(j - 1) + i
                set%c(row) = dot_product(e(:, i), self%ds3(:, a))
                set%rows(row) = sparse_vector_t(self%m3(1, a)%dofs, combine(self%m3, a, e(:, i)))
                set%cols(row) = sparse_vector_t(self%q3(1, a)%dofs, -combine(self%q3, a, e(:, i)))
            end do
        end do
    end procedure face_constraints

    !> The normal multipliers as on an edge (`alm_update_multipliers`); a sticking
    !> control point's tau_A by its two steps along e_1, e_2 (order of
    !> `face_constraints`), every other one's to its traction at the last evaluation.
    module procedure face_update
        real(dp) :: e(3, 2)
        integer :: a, j
        call self%normal_update(delta, j)
        do a = 1, size(self%state)
            if (self%law%mu > 0.0_dp .and. self%state(a) == state_stick) then
                e = tangent_frame(self%n3(:, a))
                self%tau3(:, a) = self%tau3(:, a) + delta(j + 1)*e(:, 1) + delta(j + 2)*e(:, 2)
                j = j + 2
            else
                self%tau3(:, a) = self%t3(:, a)
            end if
        end do
    end procedure face_update

    !> The largest |(I - n_A n_A^T) ds_A| / D_A / h_A of the sticking control points.
    module procedure face_slip_residual
        real(dp) :: s(3)
        integer :: a
        residual = 0.0_dp
        if (self%law%mu <= 0.0_dp) return
        do a = 1, size(self%state)
            if (self%state(a) /= state_stick .or. self%h(a) <= 0.0_dp .or. self%d(a) <= 0.0_dp) cycle
            s = self%ds3(:, a) - dot_product(self%n3(:, a), self%ds3(:, a))*self%n3(:, a)
            residual = max(residual, norm2(s)/self%d(a)/self%h(a))
        end do
    end procedure face_slip_residual

    !> sum_i c_i x(i, a)%values of three sparse vectors on the same DOFs.
    pure function combine(x, a, c) result(y)
        type(sparse_vector_t), intent(in) :: x(:, :)
        integer, intent(in) :: a
        real(dp), intent(in) :: c(3)
        real(dp), allocatable :: y(:)
        y = c(1)*x(1, a)%values + c(2)*x(2, a)%values + c(3)*x(3, a)%values
    end function combine

end submodule voiga_contact_alm_faces
