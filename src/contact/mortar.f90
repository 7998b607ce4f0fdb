!> Mortar-type penalty contact (`&contact method = 'mortar'`): the gap and the
!> tangential slip are weighted with the slave edge's functions and integrated over
!> the slave's Gauss points, so the penalty acts once per slave control point A
!> instead of once per Gauss point (docs/theory.md, section 7.4):
!>
!>     g_A = int N_A g dA0,   D_A = int N_A dA0,   p_A = -eps_N g_A / D_A   (g_A < 0)
!>
!> and the traction at a slave point is interpolated from the control points,
!> p(xi) = sum_A N_A(xi) p_A. Friction: per control point, the tangential traction
!> t_A is the state variable, with an elastic predictor on the weighted increment
!> of slip ds_A = int N_A (xi_m - xi_m,last) |a_m| dA0 and a return map onto
!> |t_A| <= mu p_A (`voiga_contact_law`; on a face t_A is a vector, `mortar_faces.f90`).
!> The integrals use the reference length dA0 of the slave edge (nominal tractions);
!> the residual at a point is r = -w0 G^T (p n + t t_hat), as in `voiga_contact_gpts`.
!>
!> Step control (`step_limit`): a Newton step that closes an open control point,
!> or reverses the trial traction of a slipping one, is shortened to the first
!> crossing. Local DOFs as in `voiga_contact_kinematics`.
module voiga_contact_mortar
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_contact_surface, only: surface_point_t, surface_point, face_ids, n_elements
    use voiga_contact_master, only: master_point_t
    use voiga_contact_law, only: contact_law_t, control_point_law, state_inactive, state_stick, state_slip
    use voiga_contact_mortar_kernels, only: mortar_point, node_touch_factors
    use voiga_contact_face_kernels, only: mortar_point3
    use voiga_contact_pair, only: contact_pair_t, add_matrix
    use voiga_contact_history, only: flag_value
    implicit none
    private

    public :: mortar_pair_t, mortar_snapshot_t, mortar_point
    !> The evaluation, for extensions that add to it (a call through the parent
    !> component would bind the passes' own calls to the parent's procedures).
    public :: mortar_evaluate

    !> A mortar pair's control points at one evaluation [slave edge control points]
    !> (for the step control, `step_limit`).
    type :: mortar_snapshot_t
        !> Weighted gaps g_A (huge where no point of the support has a projection),
        !> weights D_A = int N_A dA0 (A is active when g_A < gap_tol D_A), trial
        !> tangential tractions (before the return map).
        real(dp), allocatable :: g(:), d(:), t_trial(:)
        !> state_inactive, state_stick or state_slip.
        integer, allocatable :: state(:)
    end type mortar_snapshot_t

    !> A mortar-type penalty pair. Its constraints are weighted with a multiplier
    !> basis on the slave edge, one constraint per basis function ("node"): the
    !> slave edge's own functions (one node per slave control point, the default),
    !> or, with `linear_multipliers`, the piecewise-linear hat functions on its
    !> breakpoints (one node per element end).
    type, extends(contact_pair_t) :: mortar_pair_t
        !> Use the hat functions on the breakpoints as the multiplier basis.
        logical :: linear_multipliers = .false.
        !> The multiplier basis: the nodes whose functions are nonzero at each slave
        !> point and their values there [basis functions per point, points]; the
        !> first and last slave element of each node's support [nodes].
        integer, allocatable :: point_nodes(:, :), node_first(:), node_last(:)
        real(dp), allocatable :: point_values(:, :)
        !> The indices in `hist` of the friction history (mu > 0; 0 without) [nodes]:
        !> the tangential traction t_A (along the master tangent, `traction`), and the
        !> mean gap g_A / D_A (huge where nothing projected, `node_gap`) and whether
        !> the node was in contact (`node_active`, a flag) at the last converged state.
        !> A node that was open there touched in this step where its mean gap,
        !> interpolated linearly from there, vanished: only its slip after that
        !> counts (`touch_factors`).
        !> On a face, the traction is a vector (`mortar_faces.f90`): `traction` its x
        !> component, `h_traction_yz` its y and z ('traction_y', 'traction_z'; 0 on an edge).
        integer :: h_traction = 0, h_node_gap = 0, h_node_active = 0, h_traction_yz(2) = 0
        !> The control points at the last evaluation, and at the last accepted
        !> Newton iterate (`accept_iterate`).
        type(mortar_snapshot_t) :: last, accepted
    contains
        procedure :: evaluate => mortar_evaluate
        procedure :: method_name => mortar_method_name
        procedure :: n_blocks => mortar_n_blocks
        procedure :: block_dofs => mortar_block_dofs
        procedure :: setup_history => mortar_setup_history
        procedure :: accept_iterate => mortar_accept_iterate
        procedure :: contact_last => mortar_contact_last
        procedure :: step_limit => mortar_step_limit
        !> The law at every control point from its weighted gap and slip.
        procedure :: control_laws => mortar_control_laws
        !> Receives the coupling vectors of each active control point (default: no use).
        procedure :: keep_coupling => mortar_keep_coupling
        !> On a face with friction, the same two (`mortar_faces.f90`).
        procedure :: control_laws3 => mortar_control_laws3, keep_coupling3 => mortar_keep_coupling3
    end type mortar_pair_t

    !> Per slave point: its derivative vectors over its local DOFs.
    type :: point_vectors_t
        integer, allocatable :: dofs(:)
        real(dp), allocatable :: gn(:), gt(:), m(:)
    end type point_vectors_t

    !> What one evaluation computes per slave point and per control point, passed
    !> between its passes.
    type :: mortar_work_t
        type(surface_point_t), allocatable :: sps(:)
        type(master_point_t), allocatable :: mps(:)
        type(point_vectors_t), allocatable :: vec(:)
        !> Per point [npts]: reference length weight, master coordinate change since
        !> the last converged state, has a converged projection, had one then.
        real(dp), allocatable :: w0(:), dxi(:)
        logical, allocatable :: valid(:), slip(:)
        !> Per node [nodes]: weights, weighted gaps, weighted slips, pressures,
        !> tangential tractions, their trial values, the weight of the points with a
        !> projection in its support, states.
        real(dp), allocatable :: d_a(:), g_a(:), ds_a(:), p_a(:), t_a(:), t_tr(:), d_seen(:)
        integer, allocatable :: st_a(:)
        !> Per node [nodes] (friction): the share f_A of its slip that counts (1, or
        !> for a node open at the last converged state the part after it touched), the
        !> weighted slip before that scaling, and d f_A / d(g_A / D_A).
        real(dp), allocatable :: f_a(:), ds_raw(:), df_a(:)
    end type mortar_work_t

    interface
        !> A face with friction: the laws, points and coupling with a tangential traction
        !> vector per control point (`mortar_faces.f90`, after `mortar_project`).
        module subroutine face_friction(self, r, wk, add)
            class(mortar_pair_t), intent(inout) :: self
            real(dp), intent(inout) :: r(:)
            type(mortar_work_t), intent(inout) :: wk
            procedure(add_matrix), optional :: add
        end subroutine face_friction
        !> Node b's pattern block on a face (`block_dofs`).
        pure module function face_block_dofs(self, b, mdofs) result(dofs)
            class(mortar_pair_t), intent(in) :: self
            integer, intent(in) :: b, mdofs(:)
            integer, allocatable :: dofs(:)
        end function face_block_dofs
        !> The multiplier basis on a face (`setup_multipliers`).
        pure module subroutine face_multipliers(self)
            class(mortar_pair_t), intent(inout) :: self
        end subroutine face_multipliers
        !> `control_laws` on a face with friction: slips `ds`, node normals `n_a`,
        !> tractions `t` and trial tractions `t_tr` are vectors [3, nodes].
        pure module subroutine mortar_control_laws3(self, g_a, d_a, ds, n_a, p_a, t, st_a, t_tr)
            class(mortar_pair_t), intent(inout) :: self
            real(dp), intent(inout) :: g_a(:)
            real(dp), intent(in) :: d_a(:), ds(:, :), n_a(:, :)
            real(dp), intent(out) :: p_a(:), t(:, :), t_tr(:, :)
            integer, intent(out) :: st_a(:)
        end subroutine mortar_control_laws3
        !> `keep_coupling` on a face with friction: `q` [nb, 3] = -d r / d t_A, `m` [3, nb].
        pure module subroutine mortar_keep_coupling3(self, a, blk, v, q, m)
            class(mortar_pair_t), intent(inout) :: self
            integer, intent(in) :: a, blk(:)
            real(dp), intent(in) :: v(:), q(:, :), m(:, :)
        end subroutine mortar_keep_coupling3
    end interface

contains

    pure function mortar_method_name(self) result(name)
        class(mortar_pair_t), intent(in) :: self
        character(len=:), allocatable :: name
        name = 'mortar'
    end function mortar_method_name

    !> Residual and tangent of a mortar pair (docs/theory.md, section 7.4): the
    !> weighted gaps and slips of the slave control points from every slave point
    !> with a projection (`mortar_project`); their pressures and tangential tractions
    !> (`control_point_law`); at every point the interpolated traction's residual and
    !> geometric tangent (`mortar_points`); and per active control point the
    !> coupling through its traction (`mortar_coupling`).
    subroutine mortar_evaluate(self, u, r, error, add)
        class(mortar_pair_t), intent(inout) :: self
        real(dp), intent(in) :: u(:)
        real(dp), intent(inout) :: r(:)
        type(error_t), allocatable, intent(out) :: error
        procedure(add_matrix), optional :: add
        type(mortar_work_t) :: wk
        logical :: miss

        self%force = 0.0_dp
        call self%master%prepare(u)
        call mortar_project(self, u, wk, error)
        if (allocated(error)) return
        ! open where no point of its support has a projection: its weighted gap is
        ! then empty, not zero
        where (wk%d_seen <= 0.0_dp) wk%g_a = huge(1.0_dp)
        if (self%h_node_gap > 0) then
            call touch_factors(self, wk)
            associate (trial_gap => self%hist%field(self%h_node_gap)%trial)
                trial_gap = huge(1.0_dp)
                where (wk%g_a < huge(1.0_dp) .and. wk%d_a > 0.0_dp) trial_gap = wk%g_a/wk%d_a
            end associate
        end if
        if (self%h_traction_yz(1) > 0) then
            ! (its snapshot has no trial traction: no reversal limit on a face)
            call face_friction(self, r, wk, add)
            self%last = mortar_snapshot_t(wk%g_a, wk%d_a, spread(0.0_dp, 1, size(wk%g_a)), wk%st_a)
            return
        end if
        call self%control_laws(wk%g_a, wk%d_a, wk%ds_a, wk%p_a, wk%t_a, wk%st_a, wk%t_tr)
        if (self%h_node_active > 0) self%hist%field(self%h_node_active)%trial = flag_value(wk%st_a /= state_inactive)
        call mortar_points(self, r, wk, miss, add)
        self%last = mortar_snapshot_t(wk%g_a, wk%d_a, wk%t_tr, wk%st_a)
        if (.not. present(add) .or. miss) return
        call mortar_coupling(self, wk, add)
    end subroutine mortar_evaluate

    !> Pass 1: every slave point's projection, and the weighted gaps, slips and
    !> weights of the control points.
    subroutine mortar_project(self, u, wk, error)
        class(mortar_pair_t), intent(inout) :: self
        real(dp), intent(in) :: u(:)
        type(mortar_work_t), intent(out) :: wk
        type(error_t), allocatable, intent(out) :: error
        real(dp) :: a0(2)
        integer :: npts, ncp, k
        logical :: found, converged

        npts = size(self%xi)
        ncp = size(self%node_first)
        allocate (wk%sps(npts), wk%mps(npts), wk%vec(npts), wk%w0(npts), wk%dxi(npts), wk%valid(npts), &
                  wk%slip(npts))
        allocate (wk%d_a(ncp), wk%g_a(ncp), wk%ds_a(ncp), wk%p_a(ncp), wk%t_a(ncp), wk%st_a(ncp), &
                  wk%d_seen(ncp), wk%t_tr(ncp))
        wk%d_a = 0.0_dp
        wk%d_seen = 0.0_dp
        wk%g_a = 0.0_dp
        wk%ds_a = 0.0_dp
        wk%dxi = 0.0_dp
        wk%valid = .false.
        wk%slip = .false.
        do k = 1, npts
            call self%project_point(u, k, wk%sps(k), wk%mps(k), found, converged)
            associate (sp => wk%sps(k), mp => wk%mps(k), out => self%out(k), nodes => self%point_nodes(:, k), &
                       phi => self%point_values(:, k))
                if (self%slave%npar > 1) then
                    ! a face: the reference area the point integrates (`project_point`)
                    wk%w0(k) = out%area0
                else
                    a0 = matmul(self%slave%x0(:, sp%local), sp%dr)
                    wk%w0(k) = norm2(a0)*self%w(k)
                end if
                wk%d_a(nodes) = wk%d_a(nodes) + wk%w0(k)*phi
                if (self%h_xi > 0) then
                    self%hist%field(self%h_xi)%trial(k) = mp%xi
                    self%hist%field(self%h_active)%trial(k) = 0.0_dp
                end if
                if (.not. found) cycle
                if (.not. converged) then
                    if (out%gap >= self%gap_tol) cycle
                    call self%projection_error(k, error)
                    return
                end if
                wk%valid(k) = .true.
                wk%d_seen(nodes) = wk%d_seen(nodes) + wk%w0(k)*phi
                wk%g_a(nodes) = wk%g_a(nodes) + wk%w0(k)*phi*out%gap
                if (self%h_xi > 0) then
                    self%hist%field(self%h_active)%trial(k) = 1.0_dp
                    if (self%hist%field(self%h_active)%last(k) /= 0.0_dp) then
                        wk%slip(k) = .true.
                        wk%dxi(k) = mp%xi - self%hist%field(self%h_xi)%last(k)
                        wk%ds_a(nodes) = wk%ds_a(nodes) + wk%w0(k)*phi*wk%dxi(k)*norm2(mp%a)
                    end if
                end if
            end associate
        end do
    end subroutine mortar_project

    !> The share of each node's weighted slip that counts (`node_touch_factors`), and
    !> the weighted slips scaled by it.
    pure subroutine touch_factors(self, wk)
        class(mortar_pair_t), intent(in) :: self
        type(mortar_work_t), intent(inout) :: wk
        allocate (wk%f_a(size(wk%g_a)), wk%df_a(size(wk%g_a)))
        call node_touch_factors(self%hist%field(self%h_node_active)%last /= 0.0_dp, &
                                self%hist%field(self%h_node_gap)%last, wk%g_a, wk%d_a, wk%f_a, wk%df_a)
        wk%ds_raw = wk%ds_a
        wk%ds_a = wk%f_a*wk%ds_raw
    end subroutine touch_factors

    !> Pass 3: every point's interpolated traction: residual, resultant, output and
    !> (with `add`) geometric tangent; `miss`: a point fell outside the pattern.
    subroutine mortar_points(self, r, wk, miss, add)
        class(mortar_pair_t), intent(inout) :: self
        real(dp), intent(inout) :: r(:)
        type(mortar_work_t), intent(inout) :: wk
        logical, intent(out) :: miss
        procedure(add_matrix), optional :: add
        real(dp), allocatable :: rl(:), kl(:, :)
        real(dp) :: pbar, tbar
        integer :: k, nd, i
        logical :: inside

        miss = .false.
        do k = 1, size(self%xi)
            if (.not. wk%valid(k)) cycle
            associate (sp => wk%sps(k), mp => wk%mps(k), out => self%out(k), vec => wk%vec(k), &
                       nodes => self%point_nodes(:, k), phi => self%point_values(:, k))
                if (all(wk%st_a(nodes) == state_inactive)) cycle
                pbar = dot_product(phi, wk%p_a(nodes))
                tbar = dot_product(phi, wk%t_a(nodes))
                nd = size(sp%dofs) + size(mp%dofs)
                if (allocated(rl)) then
                    if (size(rl) /= nd) deallocate (rl, kl)
                end if
                if (.not. allocated(rl)) allocate (rl(nd), kl(nd, nd))
                allocate (vec%gn(nd), vec%gt(nd), vec%m(nd))
                if (self%slave%npar > 1) then
                    ! a face without friction (with it: `face_friction`)
                    call mortar_point3(wk%w0(k), sp, mp, pbar, rl, kl, vec%gn)
                    vec%gt = 0.0_dp
                    vec%m = 0.0_dp
                else
                    call mortar_point(wk%w0(k), sp, mp, pbar, tbar, wk%dxi(k), wk%slip(k), self%law%mu > 0.0_dp, &
                                      rl, kl, vec%gn, vec%gt, vec%m)
                end if
                vec%dofs = [sp%dofs, mp%dofs]
                self%n_evaluations = self%n_evaluations + 1
                if (self%h_traction > 0) self%n_friction = self%n_friction + 1
                r(vec%dofs) = r(vec%dofs) + rl
                do i = 1, self%nsd
                    self%force(i) = self%force(i) - sum(rl(i:size(sp%dofs):self%nsd))
                end do
                ! the interpolated tractions act per reference length (w0 = |A_s| w)
                out%pn0 = pbar
                out%pt0 = tbar
                out%pn = pbar/out%stretch
                out%pt = tbar/out%stretch
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
    end subroutine mortar_points

    !> Pass 4: per active control point A the coupling through its traction,
    !> (eps_N / D_A) v_A v_A^T (+ friction: (eps_T / D_A) q_A m_A^T when sticking,
    !> mu s (eps_N / D_A) q_A v_A^T when slipping), with v_A, q_A, m_A the
    !> N_A-weighted sums of the points' `gn`, `gt`, `m`, added on the control
    !> point's block (`block_dofs`).
    subroutine mortar_coupling(self, wk, add)
        class(mortar_pair_t), intent(inout) :: self
        type(mortar_work_t), intent(in) :: wk
        procedure(add_matrix) :: add
        real(dp), allocatable :: v(:), q(:), mm(:), kc(:, :)
        integer, allocatable :: blk(:), pos(:), mdofs(:), at(:)
        real(dp) :: c
        integer :: k, i, a, e, j, rng(2)

        mdofs = self%master%all_dofs()
        ! each block DOF's position in its block (0 elsewhere): no search per point
        allocate (at(max(maxval(self%slave%dofs), maxval([0, mdofs]))), source=0)
        do a = 1, size(self%node_first)
            if (wk%st_a(a) == state_inactive) cycle
            blk = self%block_dofs(a, mdofs)
            at(blk) = [(j, j=1, size(blk))]
            allocate (v(size(blk)), q(size(blk)), mm(size(blk)), pos(0))
            v = 0.0_dp
            q = 0.0_dp
            mm = 0.0_dp
            do e = self%node_first(a), self%node_last(a)
                rng = self%point_range(e)
                do k = rng(1), rng(2)
                    if (.not. allocated(wk%vec(k)%dofs)) cycle
                    i = findloc(self%point_nodes(:, k), a, dim=1)
                    ! (a face's range of cells holds rows beside the node's support)
                    if (i == 0) cycle
                    c = wk%w0(k)*self%point_values(i, k)
                    pos = at(wk%vec(k)%dofs)
                    v(pos) = v(pos) + c*wk%vec(k)%gn
                    if (self%law%mu > 0.0_dp) then
                        q(pos) = q(pos) + c*wk%vec(k)%gt
                        mm(pos) = mm(pos) + c*wk%vec(k)%m
                    end if
                end do
            end do
            ! the counted slip f_A ds_A: d = f_A d ds_A + ds_A f_A' d(g_A / D_A)
            if (allocated(wk%f_a)) mm = wk%f_a(a)*mm + wk%ds_raw(a)*wk%df_a(a)/wk%d_a(a)*v
            allocate (kc(size(blk), size(blk)))
            do j = 1, size(blk)
                kc(:, j) = self%law%eps_n/wk%d_a(a)*v*v(j)
            end do
            if (self%law%mu > 0.0_dp) then
                if (wk%st_a(a) == state_slip) then
                    do j = 1, size(blk)
                        kc(:, j) = kc(:, j) + self%law%mu*sign(1.0_dp, wk%t_a(a))*self%law%eps_n/wk%d_a(a)*q*v(j)
                    end do
                else
                    do j = 1, size(blk)
                        kc(:, j) = kc(:, j) + self%law%eps_t/wk%d_a(a)*q*mm(j)
                    end do
                end if
            end if
            call add(blk, kc)
            call self%keep_coupling(a, blk, v, q, mm)
            at(blk) = 0
            deallocate (v, q, mm, pos, kc)
        end do
    end subroutine mortar_coupling

    !> The law at every control point (`control_point_law`), the committed traction
    !> as the tangential reference; the trial traction is kept for the commit.
    !> `g_a`: weighted gaps (huge where nothing projects), `d_a` weights, `ds_a`
    !> weighted slips; out: pressures, tractions, states, trial tractions.
    !> [slave edge control points] each. An extension may shift the gaps (the
    !> snapshot of the step control sees `g_a` as returned).
    pure subroutine mortar_control_laws(self, g_a, d_a, ds_a, p_a, t_a, st_a, t_tr)
        class(mortar_pair_t), intent(inout) :: self
        real(dp), intent(inout) :: g_a(:)
        real(dp), intent(in) :: d_a(:), ds_a(:)
        real(dp), intent(out) :: p_a(:), t_a(:), t_tr(:)
        integer, intent(out) :: st_a(:)
        real(dp) :: t_old
        integer :: a
        do a = 1, size(g_a)
            t_old = 0.0_dp
            if (self%h_traction > 0) t_old = self%hist%field(self%h_traction)%last(a)
            call control_point_law(self%law, g_a(a), d_a(a), ds_a(a), t_old, self%gap_tol, p_a(a), t_a(a), &
                                   st_a(a), t_tr(a))
            if (self%h_traction > 0) self%hist%field(self%h_traction)%trial(a) = t_a(a)
        end do
    end subroutine mortar_control_laws

    !> The coupling vectors of active control point `a` on the DOFs `blk`: the
    !> derivatives of its weighted gap `v` and weighted slip `m`, and `q`, the
    !> derivative of the residual by its tangential traction (with a minus sign).
    pure subroutine mortar_keep_coupling(self, a, blk, v, q, m)
        class(mortar_pair_t), intent(inout) :: self
        integer, intent(in) :: a, blk(:)
        real(dp), intent(in) :: v(:), q(:), m(:)
    end subroutine mortar_keep_coupling

    !> One pattern block per slave control point.
    pure integer function mortar_n_blocks(self) result(n)
        class(mortar_pair_t), intent(in) :: self
        n = size(self%node_first)
    end function mortar_n_blocks

    !> Node b couples every DOF of every point in its support with every other, so
    !> its block is the edge DOFs and master ranges of all the slave elements its
    !> function is nonzero on (each once).
    pure function mortar_block_dofs(self, b, mdofs) result(dofs)
        class(mortar_pair_t), intent(in) :: self
        integer, intent(in) :: b
        integer, intent(in) :: mdofs(:)
        integer, allocatable :: dofs(:)
        logical, allocatable :: used(:)
        integer :: e, p, lo, hi

        if (self%slave%npar > 1) then
            dofs = face_block_dofs(self, b, mdofs)
            return
        end if
        p = self%slave%degree
        lo = huge(1)
        hi = 0
        allocate (used(size(mdofs)/2), source=.false.)
        do e = self%node_first(b), self%node_last(b)
            lo = min(lo, self%slave%spans(e) - p)
            hi = max(hi, self%slave%spans(e))
            used(self%range_ids(e)) = .true.
        end do
        dofs = reshape(self%slave%dofs(:, lo:hi), [2*(hi - lo + 1)])
        dofs = [dofs, pack(mdofs, reshape(spread(used, 1, 2), [size(mdofs)]))]
    end function mortar_block_dofs

    !> The multiplier basis; with friction the shared history and a tangential
    !> traction per node.
    pure subroutine mortar_setup_history(self)
        class(mortar_pair_t), intent(inout) :: self
        integer :: n
        call setup_multipliers(self)
        if (self%law%mu <= 0.0_dp) return
        n = size(self%node_first)
        call self%hist%add('traction', n, self%h_traction)
        call self%hist%add('node_gap', n, self%h_node_gap, initial=huge(1.0_dp))
        call self%hist%add('node_active', n, self%h_node_active, flags=.true.)
        if (self%slave%npar < 2) return
        call self%hist%add('traction_y', n, self%h_traction_yz(1))
        call self%hist%add('traction_z', n, self%h_traction_yz(2))
    end subroutine mortar_setup_history

    !> The multiplier basis at the slave points and the supports of its nodes: the
    !> slave edge's functions (`surface_point`, as the evaluation computes them), or
    !> the hat functions on the breakpoints, linear in the parameter within an element.
    pure subroutine setup_multipliers(self)
        class(mortar_pair_t), intent(inout) :: self
        type(surface_point_t) :: sp
        real(dp), allocatable :: u0(:)
        real(dp) :: s
        integer :: e, i, k, p, ne, ng, a

        if (self%slave%npar > 1) then
            call face_multipliers(self)
            return
        end if
        ne = size(self%slave%spans)
        ng = self%n_gauss
        p = self%slave%degree
        if (self%linear_multipliers) then
            allocate (self%point_nodes(2, ne*ng), self%point_values(2, ne*ng), self%node_first(ne + 1), &
                      self%node_last(ne + 1))
            do e = 1, ne
                do i = 1, ng
                    k = (e - 1)*ng + i
                    s = (self%xi(k) - self%slave%breaks(e))/(self%slave%breaks(e + 1) - self%slave%breaks(e))
                    self%point_nodes(:, k) = [e, e + 1]
                    self%point_values(:, k) = [1.0_dp - s, s]
                end do
            end do
            self%node_first = [(max(1, a - 1), a=1, ne + 1)]
            self%node_last = [(min(ne, a), a=1, ne + 1)]
            return
        end if
        allocate (self%point_nodes(p + 1, ne*ng), self%point_values(p + 1, ne*ng), &
                  self%node_first(size(self%slave%cps)), self%node_last(size(self%slave%cps)))
        allocate (u0(maxval(self%slave%dofs)), source=0.0_dp)
        do k = 1, ne*ng
            call surface_point(self%slave, u0, self%xi(k), sp, self%span(k))
            self%point_nodes(:, k) = sp%local
            self%point_values(:, k) = sp%r
        end do
        self%node_first = huge(1)
        self%node_last = 0
        do e = 1, ne
            do a = self%slave%spans(e) - p, self%slave%spans(e)
                self%node_first(a) = min(self%node_first(a), e)
                self%node_last(a) = max(self%node_last(a), e)
            end do
        end do
    end subroutine setup_multipliers

    !> A control point was in contact at the last converged state (friction only).
    pure logical function mortar_contact_last(self)
        class(mortar_pair_t), intent(in) :: self
        mortar_contact_last = .false.
        if (self%h_node_active > 0) mortar_contact_last = any(self%hist%field(self%h_node_active)%last /= 0.0_dp)
    end function mortar_contact_last

    !> The last evaluation is an accepted Newton iterate: the reference of `step_limit`.
    pure subroutine mortar_accept_iterate(self)
        class(mortar_pair_t), intent(inout) :: self
        self%accepted = self%last
    end subroutine mortar_accept_iterate

    !> Step control: the fraction of the way from the accepted iterate to the last
    !> evaluation at which the first control point crosses a state boundary the
    !> last tangent did not describe (linear interpolation); 1 if none. Two
    !> crossings, each a jump the Newton step cannot see:
    !> - a control point open before closes: `overshoot` times the fraction where
    !>   g_A = 0 (just closed, so that the next tangent carries its penalty);
    !> - a control point slipping before has a trial traction of the other sign: the
    !>   fraction where t_A^tr = 0, inside its stick band |t_A^tr| <= mu p_A (a
    !>   slipping point has no tangential stiffness, so the step overshoots a narrow
    !>   stick band and the slip direction flips from iteration to iteration).
    pure real(dp) function mortar_step_limit(self, overshoot) result(frac)
        class(mortar_pair_t), intent(in) :: self
        real(dp), intent(in) :: overshoot
        real(dp) :: tol, depth
        integer :: a
        frac = 1.0_dp
        associate (before => self%accepted, last => self%last)
            if (.not. allocated(last%g) .or. .not. allocated(before%g)) return
            if (size(before%g) /= size(last%g)) return
            depth = face_depth(self)
            do a = 1, size(last%g)
                tol = self%gap_tol*last%d(a)
                ! (huge: no point of the support had a projection, nothing to interpolate)
                if (before%g(a) >= tol .and. before%g(a) < huge(1.0_dp) .and. last%g(a) < tol - depth*last%d(a)) &
                    frac = min(frac, overshoot*(before%g(a) + depth*last%d(a))/(before%g(a) - last%g(a)))
                if (before%state(a) == state_slip .and. last%state(a) /= state_inactive .and. &
                    before%t_trial(a)*last%t_trial(a) < 0.0_dp) &
                    frac = min(frac, before%t_trial(a)/(before%t_trial(a) - last%t_trial(a)))
            end do
        end associate
    end function mortar_step_limit

    !> How deep a control point may close in one Newton step without being limited: on
    !> a face, the deepest mean penetration -g_A / D_A (before or after the step) of the
    !> points active at the accepted iterate (closing no deeper adds no more penalty force
    !> than the tangent holds); 0 on an edge. A face's zone edge crosses hundreds of
    !> control points per step: the first crossing's limit took hertz3d m2 NN2.2 57
    !> Newton iterations, this 32.
    pure real(dp) function face_depth(self) result(depth)
        class(mortar_pair_t), intent(in) :: self
        integer :: a
        depth = 0.0_dp
        if (self%slave%npar < 2) return
        associate (before => self%accepted, last => self%last)
            do a = 1, size(before%g)
                if (before%state(a) == state_inactive .or. before%d(a) <= 0.0_dp) cycle
                depth = max(depth, -before%g(a)/before%d(a), -last%g(a)/last%d(a))
            end do
        end associate
    end function face_depth

end module voiga_contact_mortar
