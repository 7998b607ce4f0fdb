!> A contact pair: the slave body's contact edge integrated with Gauss points
!> (full pass: forces on slave and master), a master (another body's contact edge
!> or a rigid line), the penalty/friction law, and the friction history (only
!> when mu > 0). Two methods: Gauss-point-to-surface (GPTS, `voiga_contact_gpts`:
!> the penalty acts at every slave point, history per point) and the mortar-type
!> penalty (`voiga_contact_mortar`: the penalty acts on gaps weighted with the
!> slave edge's functions, once per slave control point, history per control point).
module voiga_contact_pair
    use voiga_kinds, only: dp, i8
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_element_quadrature, only: gauss_legendre
    use voiga_contact_surface, only: contact_surface_t, surface_point_t, surface_point
    use voiga_contact_master, only: contact_master_t, master_point_t
    use voiga_contact_gpts, only: contact_law_t, gpts_point, state_inactive, state_stick, state_slip
    use voiga_contact_mortar, only: mortar_point, mortar_law
    implicit none
    private

    public :: contact_pair_t, setup_points, pair_contribution, pair_commit, pair_reset_trial, &
              contact_point_out_t, pair_wanted_ranges, pair_element_dofs, pair_zone, &
              pair_n_blocks, pair_block_dofs, method_gpts, method_mortar, method_names, &
              pair_crossing_fraction, mortar_snapshot_t

    !> Contact methods (`&contact method`): Gauss-point-to-surface, mortar-type penalty.
    integer, parameter :: method_gpts = 1, method_mortar = 2
    character(len=*), parameter :: method_names(2) = [character(len=6) :: 'gpts', 'mortar']

    !> Per-slave-point output of the last evaluation.
    type :: contact_point_out_t
        !> Reference and current position of the slave point.
        real(dp) :: x0(2) = 0.0_dp, x(2) = 0.0_dp
        real(dp) :: gap = 0.0_dp, pn = 0.0_dp, pt = 0.0_dp
        !> Master convective coordinate of the projection, and the range of master
        !> control points its functions belong to (empty for a rigid master).
        real(dp) :: xi_m = 0.0_dp
        integer :: first = 1, last = 0
        integer :: state = state_inactive
    end type contact_point_out_t

    !> A mortar pair's control points at one evaluation [slave edge control points]
    !> (for the step control of `voiga_solver_newton`, `pair_crossing_fraction`).
    type :: mortar_snapshot_t
        !> Weighted gaps g_A (huge where no point of the support has a projection),
        !> weights D_A = int N_A dA0 (A is active when g_A < gap_tol D_A), trial
        !> tangential tractions (before the return map).
        real(dp), allocatable :: g(:), d(:), t_trial(:)
        !> state_inactive, state_stick or state_slip.
        integer, allocatable :: state(:)
    end type mortar_snapshot_t

    abstract interface
        !> Receives a local stiffness matrix `k` on the global DOFs `dofs`.
        subroutine add_matrix(dofs, k)
            import :: dp
            integer, intent(in) :: dofs(:)
            real(dp), intent(in) :: k(:, :)
        end subroutine add_matrix
    end interface

    !> A slave/master pair.
    type :: contact_pair_t
        character(len=32) :: slave_name = '', master_name = ''
        integer :: slave_body = 0
        !> Master body index, 0 for a rigid master.
        integer :: master_body = 0
        type(contact_surface_t) :: slave
        class(contact_master_t), allocatable :: master
        type(contact_law_t) :: law
        !> `method_gpts` or `method_mortar`.
        integer :: method = method_gpts
        !> Gauss points per slave element.
        integer :: n_gauss = 0
        !> Slave points: parameter, weight (Gauss weight x d xi), knot span [npts].
        real(dp), allocatable :: xi(:), w(:)
        integer, allocatable :: span(:)
        !> Friction history (allocated only when mu > 0) [npts]: committed and trial
        !> stick anchors (master convective coordinate; GPTS only); whether the point
        !> was in contact (GPTS) or had a projection (mortar) at the last converged
        !> state; the projection there.
        real(dp), allocatable :: anchor(:), trial_anchor(:), xi_last(:), trial_xi(:)
        logical, allocatable :: active_last(:), trial_active(:)
        !> Mortar friction history (mu > 0) [slave edge control points]: committed and
        !> trial tangential traction t_A (along the master tangent).
        real(dp), allocatable :: traction(:), trial_traction(:)
        !> Mortar: the control points at the last evaluation.
        type(mortar_snapshot_t) :: last
        !> Tresca mode while allocated (only with mu > 0) [npts]: the slip limit of each
        !> slave point is this prescribed traction instead of mu p_N (the fixed point
        !> of `voiga_solver_newton` sets and deallocates it; never committed).
        real(dp), allocatable :: slip_bound(:)
        !> Output of the last evaluation [npts].
        type(contact_point_out_t), allocatable :: out(:)
        !> Points with gap < gap_tol are active: a point that touches (gap = 0 up to
        !> round-off) carries penalty stiffness, so bodies that start in contact are
        !> supported. 1e-12 of the slave surface's size.
        real(dp) :: gap_tol = 0.0_dp
        !> Resultant contact force on the slave at the last evaluation.
        real(dp) :: force(2) = 0.0_dp
        !> Counters: active point evaluations, of which frictional.
        integer(i8) :: n_evaluations = 0, n_friction = 0
        !> Deformable master: the master control points [mlo(e), mhi(e)] each slave
        !> element e is coupled with in the stiffness pattern (empty: lo > hi;
        !> initially the whole master).
        integer, allocatable :: mlo(:), mhi(:)
        !> Set by an evaluation with a stiffness in which an active point projected
        !> outside its element's range (the range was widened, the point's
        !> stiffness not added: the pattern must be rebuilt and the tangent
        !> assembled again).
        logical :: pattern_miss = .false.
    end type contact_pair_t

contains

    !> Place the slave Gauss points (n_gauss per slave element; 0: degree + 1) and,
    !> for a frictional pair, the history arrays. Set the master first.
    pure subroutine setup_points(self)
        type(contact_pair_t), intent(inout) :: self
        real(dp), allocatable :: gx(:), gw(:)
        integer :: ne, ng, e, i, k
        real(dp) :: a, b

        if (self%n_gauss <= 0) self%n_gauss = self%slave%degree + 1
        ng = self%n_gauss
        ne = size(self%slave%breaks) - 1
        allocate (gx(ng), gw(ng), self%xi(ne*ng), self%w(ne*ng), self%span(ne*ng))
        call gauss_legendre(ng, gx, gw)
        k = 0
        do e = 1, ne
            a = self%slave%breaks(e)
            b = self%slave%breaks(e + 1)
            do i = 1, ng
                k = k + 1
                self%xi(k) = a + 0.5_dp*(b - a)*(gx(i) + 1.0_dp)
                self%w(k) = 0.5_dp*(b - a)*gw(i)
                self%span(k) = self%slave%spans(e)
            end do
        end do
        allocate (self%out(ne*ng))
        ! until the assembly fits them (assemble with refit), every slave element is
        ! coupled with the whole master
        allocate (self%mlo(ne), self%mhi(ne))
        self%mlo = 1
        self%mhi = 0
        if (allocated(self%master)) self%mhi = size(self%master%all_dofs())/2
        self%gap_tol = 1.0e-12_dp*norm2(maxval(self%slave%x0, dim=2) - minval(self%slave%x0, dim=2))
        if (self%law%mu > 0.0_dp) then
            allocate (self%xi_last(ne*ng), self%trial_xi(ne*ng), self%active_last(ne*ng), self%trial_active(ne*ng))
            if (self%method == method_mortar) then
                allocate (self%traction(size(self%slave%cps)), self%trial_traction(size(self%slave%cps)))
                self%traction = 0.0_dp
                self%trial_traction = 0.0_dp
            else
                allocate (self%anchor(ne*ng), self%trial_anchor(ne*ng))
                self%anchor = 0.0_dp
                self%trial_anchor = 0.0_dp
            end if
            self%xi_last = 0.0_dp
            self%trial_xi = 0.0_dp
            self%active_last = .false.
            self%trial_active = .false.
        end if
    end subroutine setup_points

    !> Contact residual and tangent of the pair at displacement `u`, added to `r`
    !> (global) and handed point by point to `add` (global DOFs, local matrix).
    !> Updates the trial history and the output. Fails if a projection does not
    !> converge for a point that may be in contact.
    subroutine pair_contribution(self, u, r, error, add)
        type(contact_pair_t), intent(inout) :: self
        real(dp), intent(in) :: u(:)
        real(dp), intent(inout) :: r(:)
        type(error_t), allocatable, intent(out) :: error
        procedure(add_matrix), optional :: add
        type(surface_point_t) :: sp
        type(master_point_t) :: mp
        real(dp), allocatable :: rl(:), kl(:, :)
        integer, allocatable :: dofs(:)
        real(dp) :: g, pn, pt, anchor, new_anchor
        integer :: k, state, nd
        logical :: found, converged, inside

        if (self%method == method_mortar) then
            call mortar_contribution(self, u, r, error, add)
            return
        end if
        self%force = 0.0_dp
        call self%master%prepare(u)
        do k = 1, size(self%xi)
            call project_point(self, u, k, sp, mp, found, converged)
            if (allocated(self%anchor)) then
                self%trial_xi(k) = mp%xi
                self%trial_active(k) = .false.
                self%trial_anchor(k) = mp%xi
            end if
            if (.not. found) cycle
            if (self%out(k)%gap >= self%gap_tol) cycle
            if (.not. converged) then
                call projection_error(self, k, error)
                return
            end if
            ! a point that was not in contact at the last converged state sticks where
            ! it projected then
            anchor = mp%xi
            if (allocated(self%anchor)) then
                anchor = merge(self%anchor(k), self%xi_last(k), self%active_last(k))
                self%n_friction = self%n_friction + 1
            end if
            nd = size(sp%dofs) + size(mp%dofs)
            if (allocated(rl)) then
                if (size(rl) /= nd) deallocate (rl, kl)
            end if
            if (.not. allocated(rl)) allocate (rl(nd), kl(nd, nd))
            if (allocated(self%slip_bound)) then
                call gpts_point(self%law, self%w(k), sp, mp, anchor, rl, kl, state, g, pn, pt, new_anchor, &
                                self%slip_bound(k))
            else
                call gpts_point(self%law, self%w(k), sp, mp, anchor, rl, kl, state, g, pn, pt, new_anchor)
            end if
            self%n_evaluations = self%n_evaluations + 1
            dofs = [sp%dofs, mp%dofs]
            r(dofs) = r(dofs) + rl
            ! partition of unity: the slave part sums to -da t
            self%force(1) = self%force(1) - sum(rl(1:size(sp%dofs):2))
            self%force(2) = self%force(2) - sum(rl(2:size(sp%dofs):2))
            if (present(add)) then
                call fit_pattern(self, k, mp, inside)
                if (inside) call add(dofs, kl)
            end if
            self%out(k)%state = state
            self%out(k)%pn = pn
            self%out(k)%pt = pt
            if (allocated(self%anchor)) then
                self%trial_active(k) = .true.
                self%trial_anchor(k) = new_anchor
            end if
        end do
    end subroutine pair_contribution

    !> `pair_contribution` of a mortar pair (docs/theory.md, section 7.4): the
    !> weighted gaps and slips of the slave control points from every slave point
    !> with a projection; their pressures and tangential tractions
    !> (`mortar_law`); at every point the interpolated traction's residual and
    !> geometric tangent (`mortar_point`); and per active control point A the
    !> coupling (eps_N / D_A) v_A v_A^T (+ friction: (eps_T / D_A) q_A m_A^T when
    !> sticking, mu s (eps_N / D_A) q_A v_A^T when slipping), with v_A, q_A, m_A the
    !> N_A-weighted sums of the points' `gn`, `gt`, `m`, added on the control
    !> point's block (`pair_block_dofs`).
    subroutine mortar_contribution(self, u, r, error, add)
        type(contact_pair_t), intent(inout) :: self
        real(dp), intent(in) :: u(:)
        real(dp), intent(inout) :: r(:)
        type(error_t), allocatable, intent(out) :: error
        procedure(add_matrix), optional :: add
        !> Per slave point: its derivative vectors over its local DOFs.
        type :: point_vectors_t
            integer, allocatable :: dofs(:)
            real(dp), allocatable :: gn(:), gt(:), m(:)
        end type point_vectors_t
        type(surface_point_t), allocatable :: sps(:)
        type(master_point_t), allocatable :: mps(:)
        type(point_vectors_t), allocatable :: vec(:)
        real(dp), allocatable :: w0(:), dxi(:), d_a(:), g_a(:), ds_a(:), p_a(:), t_a(:), rl(:), kl(:, :)
        ! weight of the points with a projection in each control point's support
        real(dp), allocatable :: d_seen(:)
        ! trial tangential tractions
        real(dp), allocatable :: t_tr(:)
        real(dp), allocatable :: v(:), q(:), mm(:), kc(:, :)
        integer, allocatable :: st_a(:), blk(:), pos(:), mdofs(:)
        logical, allocatable :: valid(:), slip(:)
        real(dp) :: a0(2), pbar, tbar, t_old, c
        integer :: npts, ncp, k, i, a, e, nd, j, ng
        logical :: found, converged, miss, inside

        npts = size(self%xi)
        ncp = size(self%slave%cps)
        ng = self%n_gauss
        self%force = 0.0_dp
        call self%master%prepare(u)
        allocate (sps(npts), mps(npts), vec(npts), w0(npts), dxi(npts), valid(npts), slip(npts))
        allocate (d_a(ncp), g_a(ncp), ds_a(ncp), p_a(ncp), t_a(ncp), st_a(ncp), d_seen(ncp), t_tr(ncp))
        d_a = 0.0_dp
        d_seen = 0.0_dp
        g_a = 0.0_dp
        ds_a = 0.0_dp
        dxi = 0.0_dp
        valid = .false.
        slip = .false.
        ! pass 1: projections, weighted gaps and slips
        do k = 1, npts
            call project_point(self, u, k, sps(k), mps(k), found, converged)
            associate (sp => sps(k), mp => mps(k), out => self%out(k))
                a0 = matmul(self%slave%x0(:, sp%local), sp%dr)
                w0(k) = norm2(a0)*self%w(k)
                d_a(sp%local) = d_a(sp%local) + w0(k)*sp%r
                if (allocated(self%xi_last)) then
                    self%trial_xi(k) = mp%xi
                    self%trial_active(k) = .false.
                end if
                if (.not. found) cycle
                if (.not. converged) then
                    if (out%gap >= self%gap_tol) cycle
                    call projection_error(self, k, error)
                    return
                end if
                valid(k) = .true.
                d_seen(sp%local) = d_seen(sp%local) + w0(k)*sp%r
                g_a(sp%local) = g_a(sp%local) + w0(k)*sp%r*out%gap
                if (allocated(self%xi_last)) then
                    self%trial_active(k) = .true.
                    if (self%active_last(k)) then
                        slip(k) = .true.
                        dxi(k) = mp%xi - self%xi_last(k)
                        ds_a(sp%local) = ds_a(sp%local) + w0(k)*sp%r*dxi(k)*norm2(mp%a)
                    end if
                end if
            end associate
        end do
        ! pass 2: the law at every control point (open where no point of its support
        ! has a projection: its weighted gap is then empty, not zero)
        do a = 1, ncp
            if (d_seen(a) <= 0.0_dp) g_a(a) = huge(1.0_dp)
            t_old = 0.0_dp
            if (allocated(self%traction)) t_old = self%traction(a)
            call mortar_law(self%law, g_a(a), d_a(a), ds_a(a), t_old, self%gap_tol, p_a(a), t_a(a), st_a(a), &
                            t_tr(a))
            if (allocated(self%traction)) self%trial_traction(a) = t_a(a)
        end do
        ! pass 3: every point's interpolated traction
        miss = .false.
        do k = 1, npts
            if (.not. valid(k)) cycle
            associate (sp => sps(k), mp => mps(k), out => self%out(k))
                if (all(st_a(sp%local) == state_inactive)) cycle
                pbar = dot_product(sp%r, p_a(sp%local))
                tbar = dot_product(sp%r, t_a(sp%local))
                nd = size(sp%dofs) + size(mp%dofs)
                if (allocated(rl)) then
                    if (size(rl) /= nd) deallocate (rl, kl)
                end if
                if (.not. allocated(rl)) allocate (rl(nd), kl(nd, nd))
                allocate (vec(k)%gn(nd), vec(k)%gt(nd), vec(k)%m(nd))
                call mortar_point(w0(k), sp, mp, pbar, tbar, dxi(k), slip(k), self%law%mu > 0.0_dp, rl, kl, &
                                  vec(k)%gn, vec(k)%gt, vec(k)%m)
                vec(k)%dofs = [sp%dofs, mp%dofs]
                self%n_evaluations = self%n_evaluations + 1
                if (allocated(self%traction)) self%n_friction = self%n_friction + 1
                r(vec(k)%dofs) = r(vec(k)%dofs) + rl
                self%force(1) = self%force(1) - sum(rl(1:size(sp%dofs):2))
                self%force(2) = self%force(2) - sum(rl(2:size(sp%dofs):2))
                out%pn = pbar
                out%pt = tbar
                out%state = merge(state_slip, state_stick, any(st_a(sp%local) == state_slip))
                if (present(add)) then
                    call fit_pattern(self, k, mp, inside)
                    if (inside) then
                        call add(vec(k)%dofs, kl)
                    else
                        miss = .true.
                    end if
                end if
            end associate
        end do
        self%last = mortar_snapshot_t(g_a, d_a, t_tr, st_a)
        if (.not. present(add) .or. miss) return
        mdofs = self%master%all_dofs()
        ! pass 4: the coupling through the control-point tractions
        do a = 1, ncp
            if (st_a(a) == state_inactive) cycle
            blk = pair_block_dofs(self, a, mdofs)
            allocate (v(size(blk)), q(size(blk)), mm(size(blk)), pos(0))
            v = 0.0_dp
            q = 0.0_dp
            mm = 0.0_dp
            do e = 1, size(self%slave%spans)
                if (a < self%slave%spans(e) - self%slave%degree .or. a > self%slave%spans(e)) cycle
                do k = (e - 1)*ng + 1, e*ng
                    if (.not. allocated(vec(k)%dofs)) cycle
                    i = findloc(sps(k)%local, a, dim=1)
                    c = w0(k)*sps(k)%r(i)
                    pos = [(findloc(blk, vec(k)%dofs(j), dim=1), j=1, size(vec(k)%dofs))]
                    v(pos) = v(pos) + c*vec(k)%gn
                    if (self%law%mu > 0.0_dp) then
                        q(pos) = q(pos) + c*vec(k)%gt
                        mm(pos) = mm(pos) + c*vec(k)%m
                    end if
                end do
            end do
            allocate (kc(size(blk), size(blk)))
            do j = 1, size(blk)
                kc(:, j) = self%law%eps_n/d_a(a)*v*v(j)
            end do
            if (self%law%mu > 0.0_dp) then
                if (st_a(a) == state_slip) then
                    do j = 1, size(blk)
                        kc(:, j) = kc(:, j) + self%law%mu*sign(1.0_dp, t_a(a))*self%law%eps_n/d_a(a)*q*v(j)
                    end do
                else
                    do j = 1, size(blk)
                        kc(:, j) = kc(:, j) + self%law%eps_t/d_a(a)*q*mm(j)
                    end do
                end if
            end if
            call add(blk, kc)
            deallocate (v, q, mm, pos, kc)
        end do
    end subroutine mortar_contribution

    !> Mortar step control: the fraction of the way from the evaluation `before` to
    !> the last one at which the first control point crosses a state boundary the
    !> last tangent did not describe (linear interpolation); 1 if none, always 1 for
    !> GPTS. Two crossings, each a jump the Newton step cannot see:
    !> - a control point open before closes: `overshoot` times the fraction where
    !>   g_A = 0 (just closed, so that the next tangent carries its penalty);
    !> - a control point slipping before has a trial traction of the other sign: the
    !>   fraction where t_A^tr = 0, inside its stick band |t_A^tr| <= mu p_A (a
    !>   slipping point has no tangential stiffness, so the step overshoots a narrow
    !>   stick band and the slip direction flips from iteration to iteration).
    pure real(dp) function pair_crossing_fraction(self, before, overshoot) result(frac)
        type(contact_pair_t), intent(in) :: self
        type(mortar_snapshot_t), intent(in) :: before
        real(dp), intent(in) :: overshoot
        real(dp) :: tol
        integer :: a
        frac = 1.0_dp
        if (self%method /= method_mortar .or. .not. allocated(self%last%g) .or. .not. allocated(before%g)) return
        if (size(before%g) /= size(self%last%g)) return
        do a = 1, size(self%last%g)
            tol = self%gap_tol*self%last%d(a)
            ! (huge: no point of the support had a projection, nothing to interpolate)
            if (before%g(a) >= tol .and. before%g(a) < huge(1.0_dp) .and. self%last%g(a) < tol) &
                frac = min(frac, overshoot*before%g(a)/(before%g(a) - self%last%g(a)))
            if (before%state(a) == state_slip .and. self%last%state(a) /= state_inactive .and. &
                before%t_trial(a)*self%last%t_trial(a) < 0.0_dp) &
                frac = min(frac, before%t_trial(a)/(before%t_trial(a) - self%last%t_trial(a)))
        end do
    end function pair_crossing_fraction

    !> Evaluate slave point `k` at `u` and project it onto the master (`prepare`d):
    !> its output record is reset to not in contact, with its positions, projection
    !> and gap (huge without a projection).
    pure subroutine project_point(self, u, k, sp, mp, found, converged)
        type(contact_pair_t), intent(inout) :: self
        real(dp), intent(in) :: u(:)
        integer, intent(in) :: k
        type(surface_point_t), intent(inout) :: sp
        type(master_point_t), intent(out) :: mp
        logical, intent(out) :: found, converged
        call surface_point(self%slave, u, self%xi(k), sp, self%span(k))
        associate (out => self%out(k))
            out%x0 = matmul(self%slave%x0(:, sp%local), sp%r)
            out%x = sp%x
            out%state = state_inactive
            out%pn = 0.0_dp
            out%pt = 0.0_dp
            call self%master%project(u, sp%x, mp, found, converged)
            out%xi_m = mp%xi
            out%first = mp%first
            out%last = mp%last
            out%gap = huge(1.0_dp)
            if (found) out%gap = dot_product(sp%x - mp%x, mp%n)
        end associate
    end subroutine project_point

    !> The error of a slave point whose projection did not converge.
    pure subroutine projection_error(self, k, error)
        type(contact_pair_t), intent(in) :: self
        integer, intent(in) :: k
        type(error_t), allocatable, intent(out) :: error
        character(len=96) :: buf
        write (buf, '(a,i0,a,es10.3)') 'slave point ', k, ' at xi = ', self%xi(k)
        call fatal_error(error, "contact '"//trim(self%slave_name)//"' on '"// &
                         trim(self%master_name)//"': the closest-point projection of "// &
                         trim(buf)//' did not converge', error_code%numeric)
    end subroutine projection_error

    !> `inside`: whether the master functions of slave point `k`'s projection lie in
    !> its element's range of the stiffness pattern; if not, the range is widened and
    !> `pattern_miss` set (the caller rebuilds the pattern and assembles again).
    pure subroutine fit_pattern(self, k, mp, inside)
        type(contact_pair_t), intent(inout) :: self
        integer, intent(in) :: k
        type(master_point_t), intent(in) :: mp
        logical, intent(out) :: inside
        integer :: e
        e = (k - 1)/self%n_gauss + 1
        inside = mp%first >= self%mlo(e) .and. mp%last <= self%mhi(e)
        if (inside) return
        if (self%mlo(e) > self%mhi(e)) then
            self%mlo(e) = mp%first
            self%mhi(e) = mp%last
        else
            self%mlo(e) = min(self%mlo(e), mp%first)
            self%mhi(e) = max(self%mhi(e), mp%last)
        end if
        self%pattern_miss = .true.
    end subroutine fit_pattern

    !> Number of stiffness-pattern blocks the pair adds to the bodies' elements, some
    !> possibly empty (`pair_block_dofs`): GPTS with a deformable master, one per
    !> slave element; mortar, one per slave control point; none otherwise.
    pure integer function pair_n_blocks(self) result(n)
        type(contact_pair_t), intent(in) :: self
        n = 0
        if (self%method == method_mortar) then
            n = size(self%slave%cps)
        else if (self%master%deformable) then
            n = size(self%mlo)
        end if
    end function pair_n_blocks

    !> Global DOFs of pattern block `b` (1 .. `pair_n_blocks`); `mdofs` =
    !> `self%master%all_dofs()`. GPTS: slave element b's edge DOFs then its master
    !> range's (empty while the range is). Mortar: slave control point b couples
    !> every DOF of every point in its support with every other, so its block is the
    !> edge DOFs and master ranges of all the slave elements its function is nonzero
    !> on (each once).
    pure function pair_block_dofs(self, b, mdofs) result(dofs)
        type(contact_pair_t), intent(in) :: self
        integer, intent(in) :: b
        integer, intent(in) :: mdofs(:)
        integer, allocatable :: dofs(:)
        logical, allocatable :: used(:)
        integer :: e, p, lo, hi

        p = self%slave%degree
        if (self%method /= method_mortar) then
            allocate (dofs(0))
            if (self%mlo(b) <= self%mhi(b)) &
                dofs = [pair_element_dofs(self, b), mdofs(2*self%mlo(b) - 1:2*self%mhi(b))]
            return
        end if
        lo = huge(1)
        hi = 0
        allocate (used(size(mdofs)/2), source=.false.)
        do e = 1, size(self%slave%spans)
            if (b < self%slave%spans(e) - p .or. b > self%slave%spans(e)) cycle
            lo = min(lo, self%slave%spans(e) - p)
            hi = max(hi, self%slave%spans(e))
            if (self%mlo(e) <= self%mhi(e)) used(self%mlo(e):self%mhi(e)) = .true.
        end do
        dofs = reshape(self%slave%dofs(:, lo:hi), [2*(hi - lo + 1)])
        dofs = [dofs, pack(mdofs, reshape(spread(used, 1, 2), [size(mdofs)]))]
    end function pair_block_dofs

    !> Global DOFs of slave element `e`'s control points on the contact edge.
    pure function pair_element_dofs(self, e) result(dofs)
        type(contact_pair_t), intent(in) :: self
        integer, intent(in) :: e
        integer, allocatable :: dofs(:)
        integer :: s, p
        p = self%slave%degree
        s = self%slave%spans(e)
        dofs = reshape(self%slave%dofs(:, s - p:s), [2*(p + 1)])
    end function pair_element_dofs

    !> The master ranges each slave element should be coupled with, from the last
    !> evaluation: the control points of the projections of its points that are
    !> closer than the element's size (gap < diameter of its points' box),
    !> widened by one span on each side and rounded outward to blocks of
    !> `block` control points (so that the pattern changes seldom while the
    !> bodies slide). `n_master` is the master's number of control points.
    pure subroutine pair_wanted_ranges(self, n_master, block, lo, hi)
        type(contact_pair_t), intent(in) :: self
        integer, intent(in) :: n_master, block
        integer, intent(out) :: lo(:), hi(:)
        real(dp) :: h
        integer :: e, k, ng, w
        ng = self%n_gauss
        lo = 1
        hi = 0
        do e = 1, size(lo)
            associate (pts => self%out((e - 1)*ng + 1:e*ng))
                h = norm2(maxval(reshape([(pts(k)%x, k=1, ng)], [2, ng]), dim=2) - &
                          minval(reshape([(pts(k)%x, k=1, ng)], [2, ng]), dim=2))
                do k = 1, ng
                    if (pts(k)%first > pts(k)%last .or. pts(k)%gap >= h) cycle
                    w = pts(k)%last - pts(k)%first
                    if (lo(e) > hi(e)) then
                        lo(e) = pts(k)%first - w
                        hi(e) = pts(k)%last + w
                    else
                        lo(e) = min(lo(e), pts(k)%first - w)
                        hi(e) = max(hi(e), pts(k)%last + w)
                    end if
                end do
            end associate
            if (lo(e) > hi(e)) cycle
            lo(e) = max(1, ((lo(e) - 1)/block)*block + 1)
            hi(e) = min(n_master, ((hi(e) + block - 1)/block)*block)
        end do
    end subroutine pair_wanted_ranges

    !> The step converged: the trial history becomes the committed one.
    pure subroutine pair_commit(self)
        type(contact_pair_t), intent(inout) :: self
        if (.not. allocated(self%xi_last)) return
        if (allocated(self%anchor)) self%anchor = self%trial_anchor
        if (allocated(self%traction)) self%traction = self%trial_traction
        self%active_last = self%trial_active
        self%xi_last = self%trial_xi
    end subroutine pair_commit

    !> The contact zone at the last evaluation, for the over-constraint diagnosis:
    !> `n_active` points in contact; `n_holes` open points lying between active ones
    !> in runs shorter than one slave element (a zone broken up point by point, not
    !> two separate zones), in `n_gaps` such runs; `n_cp` slave control points whose
    !> functions are nonzero at an active point (the degrees of freedom the active
    !> constraints act on).
    pure subroutine pair_zone(self, n_active, n_holes, n_gaps, n_cp)
        type(contact_pair_t), intent(in) :: self
        integer, intent(out) :: n_active, n_holes, n_gaps, n_cp
        logical, allocatable :: active(:)
        integer :: k, first, last, run

        n_active = 0
        n_holes = 0
        n_gaps = 0
        n_cp = 0
        if (.not. allocated(self%out)) return
        active = self%out%state /= state_inactive
        n_active = count(active)
        if (n_active == 0) return
        first = findloc(active, .true., dim=1)
        last = findloc(active, .true., dim=1, back=.true.)
        run = 0
        do k = first, last
            if (active(k)) then
                if (run > 0 .and. run < self%n_gauss) then
                    n_holes = n_holes + run
                    n_gaps = n_gaps + 1
                end if
                run = 0
            else
                run = run + 1
            end if
        end do
        n_cp = maxval(self%span, mask=active) - minval(self%span, mask=active) + self%slave%degree + 1
    end subroutine pair_zone

    !> Forget the trial history (a step is retried).
    pure subroutine pair_reset_trial(self)
        type(contact_pair_t), intent(inout) :: self
        if (.not. allocated(self%xi_last)) return
        if (allocated(self%anchor)) self%trial_anchor = self%anchor
        if (allocated(self%traction)) self%trial_traction = self%traction
        self%trial_active = self%active_last
        self%trial_xi = self%xi_last
    end subroutine pair_reset_trial

end module voiga_contact_pair
