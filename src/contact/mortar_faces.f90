!> The mortar-type pair on a face (`voiga_contact_mortar`; a submodule because the
!> module is at the file limit, the interfaces are there): the multiplier basis and
!> pattern blocks of a face, and Coulomb friction with a tangential traction vector per
!> slave control point A (docs/verification-faces.md, "Friction on faces"):
!>
!>     ds_A = f_A int N_A (dxi^alpha m_alpha) dA0,   t_A^tr = t_A,last - eps_T ds_A / D_A,
!>     t_A = t_A^tr (stick) or mu p_A t_A^tr / |t_A^tr| (slip, onto the disc |t_A| <= mu p_A)
!>
!> with dxi^alpha = xi_m^alpha - xi_m,last^alpha the point's change of projection in both
!> master coordinates and m_alpha the master tangents there, so that dxi^alpha m_alpha is
!> the point's slip on the master's tangent plane (as GPTS's `coulomb3`); f_A the share
!> after the touch (`node_touch_factors`). t_A is kept in Cartesian components (history
!> `traction`, `traction_y`, `traction_z`): a node's support spans points with different
!> master bases, so no one convected basis holds it. A point's traction is
!> t = p n + (I - n n^T) sum_A N_A t_A (`mortar_friction_point3`).
submodule(voiga_contact_mortar) voiga_contact_mortar_faces
    use voiga_contact_law, only: control_point_law3
    use voiga_contact_face_kernels, only: mortar_friction_point3
    implicit none

    !> Per slave point with friction on a face: its derivative vectors over its local
    !> DOFs (`mortar_friction_point3`: `gn` [nd], `gp` [nd, 3], `ms` [3, nd]).
    type :: face_vectors_t
        integer, allocatable :: dofs(:)
        real(dp), allocatable :: gn(:), gp(:, :), ms(:, :)
    end type face_vectors_t

    !> Friction on a face per node [3, nodes]: the counted weighted slips, those
    !> before the touch factor, the tractions and their trial values; per point [2,
    !> npts] the change of projection since the last converged state, and its vectors.
    type :: face_work_t
        real(dp), allocatable :: ds(:, :), ds_raw(:, :), t(:, :), t_tr(:, :), dxi(:, :)
        !> Per node [3, nodes]: the N_A-weighted sum of the master normals at the points
        !> with a projection, normalized (zero where none has one).
        real(dp), allocatable :: n_a(:, :)
        type(face_vectors_t), allocatable :: vec(:)
    end type face_work_t

contains

    !> Friction on a face, after `mortar_project` and the touch factors: the nodes'
    !> slip vectors, their laws, the points and the coupling.
    module procedure face_friction
        type(face_work_t) :: fw
        logical :: miss
        call face_slips(self, wk, fw)
        call face_laws(self, wk, fw)
        self%hist%field(self%h_node_active)%trial = flag_value(wk%st_a /= state_inactive)
        call face_points(self, r, wk, fw, miss, add)
        if (.not. present(add) .or. miss) return
        call face_coupling(self, wk, fw, add)
    end procedure face_friction

    !> The weighted slip vectors of the nodes from the points that had a projection at
    !> the last converged state (`mortar_project` found them), scaled by the touch
    !> factors; and every point's eta projection for the history.
    pure subroutine face_slips(self, wk, fw)
        class(mortar_pair_t), intent(inout) :: self
        type(mortar_work_t), intent(in) :: wk
        type(face_work_t), intent(out) :: fw
        real(dp) :: s(3)
        integer :: k, i, a
        allocate (fw%ds_raw(3, size(wk%g_a)), fw%n_a(3, size(wk%g_a)), fw%dxi(2, size(self%xi)), source=0.0_dp)
        do k = 1, size(self%xi)
            associate (mp => wk%mps(k), nodes => self%point_nodes(:, k), phi => self%point_values(:, k))
                self%hist%field(self%h_eta)%trial(k) = mp%eta
                if (wk%valid(k)) then
                    do i = 1, size(nodes)
                        fw%n_a(:, nodes(i)) = fw%n_a(:, nodes(i)) + wk%w0(k)*phi(i)*mp%n
                    end do
                end if
                if (.not. wk%slip(k)) cycle
                fw%dxi(:, k) = [wk%dxi(k), mp%eta - self%hist%field(self%h_eta)%last(k)]
                s = fw%dxi(1, k)*mp%a + fw%dxi(2, k)*mp%b
                do i = 1, size(nodes)
                    fw%ds_raw(:, nodes(i)) = fw%ds_raw(:, nodes(i)) + wk%w0(k)*phi(i)*s
                end do
            end associate
        end do
        fw%ds = fw%ds_raw
        do a = 1, size(wk%g_a)
            fw%ds(:, a) = wk%f_a(a)*fw%ds_raw(:, a)
            if (norm2(fw%n_a(:, a)) > 0.0_dp) fw%n_a(:, a) = fw%n_a(:, a)/norm2(fw%n_a(:, a))
        end do
    end subroutine face_slips

    !> The laws at the nodes (`control_laws3`: an extension may shift the gaps and
    !> change the tangential reference).
    pure subroutine face_laws(self, wk, fw)
        class(mortar_pair_t), intent(inout) :: self
        type(mortar_work_t), intent(inout) :: wk
        type(face_work_t), intent(inout) :: fw
        allocate (fw%t(3, size(wk%g_a)), fw%t_tr(3, size(wk%g_a)))
        call self%control_laws3(wk%g_a, wk%d_a, fw%ds, fw%n_a, wk%p_a, fw%t, wk%st_a, fw%t_tr)
    end subroutine face_laws

    !> The law at every node (`control_point_law3`), the committed traction vector as
    !> the reference; the tractions go to the history's trial values.
    module procedure mortar_control_laws3
        integer :: a
        associate (h => self%hist%field, i1 => self%h_traction, i2 => self%h_traction_yz(1), &
                   i3 => self%h_traction_yz(2))
            do a = 1, size(g_a)
                call control_point_law3(self%law, g_a(a), d_a(a), ds(:, a), &
                                        [h(i1)%last(a), h(i2)%last(a), h(i3)%last(a)], self%gap_tol, p_a(a), &
                                        t(:, a), st_a(a), t_tr(:, a))
                h(i1)%trial(a) = t(1, a)
                h(i2)%trial(a) = t(2, a)
                h(i3)%trial(a) = t(3, a)
            end do
        end associate
    end procedure mortar_control_laws3

    !> No use of the coupling by default.
    module procedure mortar_keep_coupling3
    end procedure mortar_keep_coupling3

    !> Every point's interpolated traction (`mortar_friction_point3`): residual,
    !> resultant, output and (with `add`) geometric tangent; `miss`: a point fell
    !> outside the pattern.
    subroutine face_points(self, r, wk, fw, miss, add)
        class(mortar_pair_t), intent(inout) :: self
        real(dp), intent(inout) :: r(:)
        type(mortar_work_t), intent(in) :: wk
        type(face_work_t), intent(inout) :: fw
        logical, intent(out) :: miss
        procedure(add_matrix), optional :: add
        real(dp), allocatable :: rl(:), kl(:, :)
        real(dp) :: pbar, tbar(3), s(3), tt(3)
        integer :: k, nd, i
        logical :: inside

        miss = .false.
        allocate (fw%vec(size(self%xi)))
        do k = 1, size(self%xi)
            if (.not. wk%valid(k)) cycle
            associate (sp => wk%sps(k), mp => wk%mps(k), out => self%out(k), vec => fw%vec(k), &
                       nodes => self%point_nodes(:, k), phi => self%point_values(:, k))
                if (all(wk%st_a(nodes) == state_inactive)) cycle
                pbar = dot_product(phi, wk%p_a(nodes))
                tbar = matmul(fw%t(:, nodes), phi)
                nd = size(sp%dofs) + size(mp%dofs)
                if (allocated(rl)) then
                    if (size(rl) /= nd) deallocate (rl, kl)
                end if
                if (.not. allocated(rl)) allocate (rl(nd), kl(nd, nd))
                allocate (vec%gn(nd), vec%gp(nd, 3), vec%ms(3, nd))
                call mortar_friction_point3(wk%w0(k), sp, mp, pbar, tbar, fw%dxi(:, k), wk%slip(k), rl, kl, &
                                            vec%gn, vec%gp, s, vec%ms, tt)
                vec%dofs = [sp%dofs, mp%dofs]
                self%n_evaluations = self%n_evaluations + 1
                self%n_friction = self%n_friction + 1
                r(vec%dofs) = r(vec%dofs) + rl
                do i = 1, 3
                    self%force(i) = self%force(i) - sum(rl(i:size(sp%dofs):3))
                end do
                ! the interpolated tractions act per reference area
                out%pn0 = pbar
                out%pt0 = norm2(tt)
                out%pn = pbar/out%stretch
                out%pt = out%pt0/out%stretch
                out%tt = tt/out%stretch
                out%state = merge(state_slip, state_stick, any(wk%st_a(nodes) == state_slip))
                if (present(add)) then
                    call self%fit_pattern(k, mp, inside)
                    if (inside) then
                        call add(vec%dofs, kl)
                    else
                        miss = .true.
                    end if
                end if
            end associate
        end do
    end subroutine face_points

    !> Per active node A the coupling through its pressure and traction vector:
    !> (eps_N / D_A) v v^T - Q T with v, Q [nb, 3] and M [3, nb] the N_A-weighted sums of
    !> the points' `gn`, `gp`, `ms` (M for the counted slip f_A ds_A, as on an edge), and
    !> T = d t_A / du: -(eps_T / D_A) M sticking; slipping, with nu = t^tr / |t^tr|,
    !> -mu (eps_N / D_A) nu v^T - mu p_A / |t^tr| (I - nu nu^T) (eps_T / D_A) M.
    subroutine face_coupling(self, wk, fw, add)
        class(mortar_pair_t), intent(inout) :: self
        type(mortar_work_t), intent(in) :: wk
        type(face_work_t), intent(in) :: fw
        procedure(add_matrix) :: add
        real(dp), allocatable :: v(:), q(:, :), mm(:, :), tm(:, :), kc(:, :)
        integer, allocatable :: blk(:), pos(:), mdofs(:), at(:)
        real(dp) :: c, nu(3), size_tr, proj(3, 3)
        integer :: k, i, a, e, j, rng(2)

        mdofs = self%master%all_dofs()
        allocate (at(max(maxval(self%slave%dofs), maxval([0, mdofs]))), source=0)
        do a = 1, size(self%node_first)
            if (wk%st_a(a) == state_inactive) cycle
            blk = self%block_dofs(a, mdofs)
            at(blk) = [(j, j=1, size(blk))]
            allocate (v(size(blk)), q(size(blk), 3), mm(3, size(blk)), source=0.0_dp)
            do e = self%node_first(a), self%node_last(a)
                rng = self%point_range(e)
                do k = rng(1), rng(2)
                    if (.not. allocated(fw%vec(k)%dofs)) cycle
                    i = findloc(self%point_nodes(:, k), a, dim=1)
                    if (i == 0) cycle
                    c = wk%w0(k)*self%point_values(i, k)
                    pos = at(fw%vec(k)%dofs)
                    v(pos) = v(pos) + c*fw%vec(k)%gn
                    q(pos, :) = q(pos, :) + c*fw%vec(k)%gp
                    mm(:, pos) = mm(:, pos) + c*fw%vec(k)%ms
                end do
            end do
            ! the counted slip f_A ds_A: d = f_A d ds_A + ds_A f_A' d(g_A / D_A)
            do j = 1, size(blk)
                mm(:, j) = wk%f_a(a)*mm(:, j) + fw%ds_raw(:, a)*wk%df_a(a)/wk%d_a(a)*v(j)
            end do
            ! a phase without friction (mu = 0 in a pair that has it in another): the
            ! law gives no traction, so nothing couples through it
            tm = merge(-self%law%eps_t/wk%d_a(a), 0.0_dp, self%law%mu > 0.0_dp)*mm
            if (wk%st_a(a) == state_slip) then
                size_tr = norm2(fw%t_tr(:, a))
                nu = fw%t_tr(:, a)/size_tr
                proj = -spread(nu, 2, 3)*spread(nu, 1, 3)
                do j = 1, 3
                    proj(j, j) = proj(j, j) + 1.0_dp
                end do
                tm = self%law%mu*wk%p_a(a)/size_tr*matmul(proj, tm)
                do j = 1, size(blk)
                    tm(:, j) = tm(:, j) - self%law%mu*self%law%eps_n/wk%d_a(a)*nu*v(j)
                end do
            end if
            allocate (kc(size(blk), size(blk)))
            kc = -matmul(q, tm)
            do j = 1, size(blk)
                kc(:, j) = kc(:, j) + self%law%eps_n/wk%d_a(a)*v*v(j)
            end do
            call add(blk, kc)
            call self%keep_coupling3(a, blk, v, q, mm)
            at(blk) = 0
            deallocate (v, q, mm, kc)
        end do
    end subroutine face_coupling

    !> Node b's block on a face: the DOFs of the control points of every cell whose
    !> functions include the node's, then the master ranges of those cells (`mdofs`:
    !> the master's DOFs, 3 per control point; none for a rigid master).
    module procedure face_block_dofs
        integer, allocatable :: ids(:)
        logical :: used(size(self%slave%cps)), mused(size(mdofs)/3)
        integer :: e, nu
        nu = size(self%slave%spans)
        used = .false.
        mused = .false.
        do e = self%node_first(b), self%node_last(b)
            ids = face_ids(self%slave, [self%slave%spans(modulo(e - 1, nu) + 1), self%slave%spans_eta((e - 1)/nu + 1)])
            if (.not. any(ids == b)) cycle
            used(ids) = .true.
            mused(self%range_ids(e)) = .true.
        end do
        dofs = reshape(self%slave%dofs(:, pack([(e, e=1, size(used))], used)), [3*count(used)])
        dofs = [dofs, pack(mdofs, reshape(spread(mused, 1, 3), [size(mdofs)]))]
    end procedure face_block_dofs

    !> The multiplier basis on a face: the slave face's functions at each point (as
    !> `setup` computed them), and each node's support as the range of cells (flat,
    !> xi fastest) from its first to its last.
    module procedure face_multipliers
        integer :: k, e, ne, a, nu
        integer, allocatable :: ids(:)
        ne = n_elements(self%slave)
        nu = size(self%slave%spans)
        allocate (self%point_nodes(size(self%slave_basis, 1), size(self%xi)), &
                  self%node_first(size(self%slave%cps)), self%node_last(size(self%slave%cps)))
        do k = 1, size(self%xi)
            self%point_nodes(:, k) = face_ids(self%slave, [self%span(k), self%span_eta(k)])
        end do
        self%point_values = self%slave_basis(:, 1, :)
        self%node_first = huge(1)
        self%node_last = 0
        do e = 1, ne
            ids = face_ids(self%slave, [self%slave%spans(modulo(e - 1, nu) + 1), self%slave%spans_eta((e - 1)/nu + 1)])
            do a = 1, size(ids)
                self%node_first(ids(a)) = min(self%node_first(ids(a)), e)
                self%node_last(ids(a)) = max(self%node_last(ids(a)), e)
            end do
        end do
    end procedure face_multipliers

end submodule voiga_contact_mortar_faces
