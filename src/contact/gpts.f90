!> Gauss-point-to-surface (GPTS) penalty contact, the paper's method: the
!> penalty acts at every slave Gauss point, with a normal penalty, Coulomb friction
!> by an elastic predictor and return map on the convected master coordinate, and a
!> consistent tangent (docs/theory.md, section 7); the friction history is kept per
!> slave point.
!>
!> Tresca mode (`outer_apply`, the outer-loop hook): the slip limit of each point
!> is a fixed bound instead of mu p_N; its tangent has no normal-tangential
!> coupling (the fixed point of `voiga_solver_outer`, docs/robustness.md).
!>
!> Local DOFs of a point: the slave point's functions first (2 per function), then
!> the master's (none for a rigid master); `voiga_contact_kinematics`.
module voiga_contact_gpts
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_contact_surface, only: surface_point_t
    use voiga_nurbs_basis, only: max_fixed_degree
    use voiga_contact_master, only: master_point_t
    use voiga_contact_law, only: contact_law_t, state_inactive, state_stick, state_slip
    use voiga_contact_kinematics, only: point_operators
    use voiga_text, only: str, real_str
    use voiga_contact_pair, only: contact_pair_t, add_matrix
    use voiga_contact_face_kernels, only: gpts_point3
    implicit none
    private

    public :: gpts_pair_t, gpts_point

    !> A contact zone counts as broken up (the locking diagnosis) with at least this
    !> many gaps shorter than a slave element, holding at least this share of its
    !> points. Measured (docs/robustness.md): penalty 1e6 x E, 3 to 5 gaps holding 32 to
    !> 48 %; mu-1.0-deep (penalty 1e2 x E, a smooth pressure), one gap of 4 points
    !> between the zone and a lone point at its edge, 8 %.
    integer, parameter :: min_gaps = 2
    real(dp), parameter :: min_hole_share = 0.2_dp
    !> Local DOFs of a point whose operators fit `gpts_point`'s fixed buffers: a
    !> slave and a master function set of degree up to `max_fixed_degree` each.
    integer, parameter :: max_nd = 4*(max_fixed_degree + 1)

    !> A GPTS pair.
    type, extends(contact_pair_t) :: gpts_pair_t
        !> The index in `hist` of the stick anchors (master convective coordinate)
        !> [npts]; 0 without friction.
        integer :: h_anchor = 0
        !> On a face, the anchors' second coordinate (`anchor_eta`).
        integer :: h_anchor_eta = 0
        !> Tresca mode while allocated (only with mu > 0) [npts]: the slip limit of each
        !> slave point is this prescribed traction instead of mu p_N (never committed).
        real(dp), allocatable :: slip_bound(:)
        !> The bounds of the last `outer_capture` [npts].
        real(dp), allocatable :: captured_bound(:)
    contains
        procedure :: evaluate => gpts_evaluate
        procedure :: method_name => gpts_method_name
        procedure :: n_blocks => gpts_n_blocks
        procedure :: block_dofs => gpts_block_dofs
        procedure :: setup_history => gpts_setup_history
        procedure :: takes_outer => gpts_takes_outer
        procedure :: outer_capture => gpts_outer_capture
        procedure :: outer_apply => gpts_outer_apply
        procedure :: outer_release => gpts_outer_release
        procedure :: failure_diagnosis => gpts_failure_diagnosis
        !> The contact zone at the last evaluation (for the locking diagnosis).
        procedure :: zone => gpts_zone
    end type gpts_pair_t

contains

    pure function gpts_method_name(self) result(name)
        class(gpts_pair_t), intent(in) :: self
        character(len=:), allocatable :: name
        name = 'gpts'
    end function gpts_method_name

    !> Contact residual and tangent of the pair at displacement `u`, added to `r`
    !> (global) and handed point by point to `add` (global DOFs, local matrix).
    !> Updates the trial history and the output. Fails if a projection does not
    !> converge for a point that may be in contact.
    subroutine gpts_evaluate(self, u, r, error, add)
        class(gpts_pair_t), intent(inout) :: self
        real(dp), intent(in) :: u(:)
        real(dp), intent(inout) :: r(:)
        type(error_t), allocatable, intent(out) :: error
        procedure(add_matrix), optional :: add
        type(surface_point_t) :: sp
        type(master_point_t) :: mp
        real(dp), allocatable :: rl(:), kl(:, :)
        integer, allocatable :: dofs(:)
        real(dp) :: g, pn, pt, anchor, new_anchor, gap0, new_anchor2(2)
        integer :: k, state, nd, j
        logical :: found, converged, inside, touch

        self%force = 0.0_dp
        allocate (dofs(0))
        call self%master%prepare(u)
        do k = 1, size(self%xi)
            call self%project_point(u, k, sp, mp, found, converged)
            if (self%h_anchor > 0) then
                self%hist%field(self%h_xi)%trial(k) = mp%xi
                self%hist%field(self%h_active)%trial(k) = 0.0_dp
                self%hist%field(self%h_anchor)%trial(k) = mp%xi
                self%hist%field(self%h_gap)%trial(k) = self%out(k)%gap
            end if
            if (self%h_anchor_eta > 0) then
                self%hist%field(self%h_eta)%trial(k) = mp%eta
                self%hist%field(self%h_anchor_eta)%trial(k) = mp%eta
            end if
            if (.not. found) cycle
            if (self%out(k)%gap >= self%gap_tol) cycle
            if (.not. converged) then
                call self%projection_error(k, error)
                return
            end if
            ! a point that was not in contact at the last converged state sticks where
            ! it projected then
            anchor = mp%xi
            touch = .false.
            gap0 = huge(1.0_dp)
            if (self%h_anchor > 0) then
                ! a point open at the last converged state touched in this step: its slip
                ! counts from where its gap, interpolated linearly from there, vanished
                touch = self%hist%field(self%h_active)%last(k) == 0.0_dp
                anchor = merge(self%hist%field(self%h_xi)%last(k), self%hist%field(self%h_anchor)%last(k), touch)
                gap0 = self%hist%field(self%h_gap)%last(k)
                self%n_friction = self%n_friction + 1
            end if
            nd = size(sp%dofs) + size(mp%dofs)
            if (allocated(rl)) then
                if (size(rl) /= nd) deallocate (rl, kl)
            end if
            if (.not. allocated(rl)) allocate (rl(nd), kl(nd, nd))
            if (self%nsd == 3) then
                call face_point(self, k, sp, mp, touch, gap0, rl, kl, state, pn, new_anchor2)
                pt = norm2(self%out(k)%tt)
                new_anchor = new_anchor2(1)
            else if (allocated(self%slip_bound)) then
                call gpts_point(self%law, self%w(k), sp, mp, anchor, touch, gap0, rl, kl, state, g, pn, pt, &
                                new_anchor, self%slip_bound(k))
            else
                call gpts_point(self%law, self%w(k), sp, mp, anchor, touch, gap0, rl, kl, state, g, pn, pt, &
                                new_anchor)
            end if
            self%n_evaluations = self%n_evaluations + 1
            if (size(dofs) /= nd) then
                deallocate (dofs)
                allocate (dofs(nd))
            end if
            dofs(1:size(sp%dofs)) = sp%dofs
            dofs(size(sp%dofs) + 1:nd) = mp%dofs
            do j = 1, nd
                r(dofs(j)) = r(dofs(j)) + rl(j)
            end do
            ! partition of unity: the slave part sums to -da t
            do j = 1, self%nsd
                self%force(j) = self%force(j) - sum(rl(j:size(sp%dofs):self%nsd))
            end do
            if (present(add)) then
                call self%fit_pattern(k, mp, inside)
                if (inside) call add(dofs, kl)
            end if
            self%out(k)%state = state
            self%out(k)%pn = pn
            self%out(k)%pt = pt
            ! the point's traction acts per current length (da = |a_s| w)
            self%out(k)%pn0 = pn*self%out(k)%stretch
            self%out(k)%pt0 = pt*self%out(k)%stretch
            if (self%h_anchor > 0) then
                self%hist%field(self%h_active)%trial(k) = 1.0_dp
                ! frictionless (a phase without friction): the point slides freely
                if (self%law%mu <= 0.0_dp) new_anchor = mp%xi
                self%hist%field(self%h_anchor)%trial(k) = new_anchor
            end if
            if (self%h_anchor_eta > 0) then
                if (self%law%mu <= 0.0_dp) new_anchor2(2) = mp%eta
                self%hist%field(self%h_anchor_eta)%trial(k) = new_anchor2(2)
            end if
        end do
    end subroutine gpts_evaluate

    !> `gpts_point3` at slave point `k` of a face, with its committed anchor (both
    !> coordinates; for a point that touched in this step, its projection at the last
    !> converged state) and, in Tresca mode, its slip bound; the tangential traction
    !> goes to the point's output.
    pure subroutine face_point(self, k, sp, mp, touch, gap0, rl, kl, state, pn, new_anchor)
        class(gpts_pair_t), intent(inout) :: self
        integer, intent(in) :: k
        type(surface_point_t), intent(in) :: sp
        type(master_point_t), intent(in) :: mp
        logical, intent(in) :: touch
        real(dp), intent(in) :: gap0
        real(dp), intent(out) :: rl(:), kl(:, :), pn, new_anchor(2)
        integer, intent(out) :: state
        real(dp) :: anchor(2), g
        anchor = [mp%xi, mp%eta]
        if (self%h_anchor_eta > 0) then
            if (touch) then
                anchor = [self%hist%field(self%h_xi)%last(k), self%hist%field(self%h_eta)%last(k)]
            else
                anchor = [self%hist%field(self%h_anchor)%last(k), self%hist%field(self%h_anchor_eta)%last(k)]
            end if
        end if
        if (allocated(self%slip_bound)) then
            call gpts_point3(self%law, self%w(k), sp, mp, anchor, touch, gap0, rl, kl, state, g, pn, &
                             self%out(k)%tt, new_anchor, self%slip_bound(k))
        else
            call gpts_point3(self%law, self%w(k), sp, mp, anchor, touch, gap0, rl, kl, state, g, pn, &
                             self%out(k)%tt, new_anchor)
        end if
    end subroutine face_point

    !> With a deformable master, one pattern block per slave element (its edge DOFs
    !> and its master range); none with a rigid master.
    pure integer function gpts_n_blocks(self) result(n)
        class(gpts_pair_t), intent(in) :: self
        n = 0
        if (self%master%deformable) n = size(self%mlo)
    end function gpts_n_blocks

    !> Slave element b's edge DOFs then its master range's (empty while the range is).
    pure function gpts_block_dofs(self, b, mdofs) result(dofs)
        class(gpts_pair_t), intent(in) :: self
        integer, intent(in) :: b
        integer, intent(in) :: mdofs(:)
        integer, allocatable :: dofs(:), ids(:)
        integer :: i, c
        allocate (dofs(0))
        if (self%mlo(b) > self%mhi(b)) return
        ids = self%range_ids(b)
        dofs = [self%element_dofs(b), [((mdofs(self%nsd*(ids(i) - 1) + c), c=1, self%nsd), i=1, size(ids))]]
    end function gpts_block_dofs

    !> With friction: a stick anchor per slave point (`anchor`).
    pure subroutine gpts_setup_history(self)
        class(gpts_pair_t), intent(inout) :: self
        if (self%law%mu <= 0.0_dp) return
        call self%hist%add('anchor', size(self%xi), self%h_anchor)
        if (self%slave%npar > 1) call self%hist%add('anchor_eta', size(self%xi), self%h_anchor_eta)
    end subroutine gpts_setup_history

    !> The Tresca fixed point applies to a frictional GPTS pair (its slip limits
    !> belong to slave points).
    pure logical function gpts_takes_outer(self)
        class(gpts_pair_t), intent(in) :: self
        gpts_takes_outer = self%law%mu > 0.0_dp
    end function gpts_takes_outer

    !> The slip bounds mu p_N of the last evaluation become the captured ones;
    !> `change`: the largest change from the previous capture (0 at the first),
    !> `largest`: the largest bound.
    pure subroutine gpts_outer_capture(self, change, largest)
        class(gpts_pair_t), intent(inout) :: self
        real(dp), intent(out) :: change, largest
        real(dp), allocatable :: bound(:)
        bound = self%law%mu*max(0.0_dp, self%out%pn)
        change = 0.0_dp
        if (allocated(self%captured_bound)) change = maxval(abs(bound - self%captured_bound))
        largest = maxval(bound)
        call move_alloc(bound, self%captured_bound)
    end subroutine gpts_outer_capture

    !> Tresca mode: the captured bounds are the slip limits.
    pure subroutine gpts_outer_apply(self)
        class(gpts_pair_t), intent(inout) :: self
        self%slip_bound = self%captured_bound
    end subroutine gpts_outer_apply

    !> Back to Coulomb friction (the captured bounds are kept for the next change).
    pure subroutine gpts_outer_release(self)
        class(gpts_pair_t), intent(inout) :: self
        if (allocated(self%slip_bound)) deallocate (self%slip_bound)
    end subroutine gpts_outer_release

    !> What the contact zone looks like at the last evaluation when it is broken up
    !> point by point (at least `min_gaps` gaps shorter than a slave element, holding
    !> at least `min_hole_share` of the zone's points) while its active points
    !> outnumber the slave control points they act on: the Gauss-point-to-surface
    !> constraints then over-constrain the slave edge and, with a stiff penalty,
    !> lock (docs/robustness.md, "Over-constrained contact zones"). Empty otherwise.
    pure function gpts_failure_diagnosis(self) result(text)
        class(gpts_pair_t), intent(in) :: self
        character(len=:), allocatable :: text
        integer :: n_active, n_holes, n_gaps, n_cp

        text = ''
        ! (the diagnosis reads the points along an edge)
        if (self%slave%npar > 1) return
        call self%zone(n_active, n_holes, n_gaps, n_cp)
        if (n_gaps < min_gaps .or. n_holes < min_hole_share*(n_active + n_holes) .or. &
            n_active <= n_cp) return
        text = '; at the last converged state the contact zone of '''//trim(self%slave_name)//''' on '''// &
               trim(self%master_name)//''' is broken up: '//str(n_holes)//' of its '//str(n_active + n_holes)// &
               ' slave points are open in gaps shorter than a slave element, and its '//str(n_active)// &
               ' active points act on '//str(n_cp)//' control points of the slave edge: the '// &
               'Gauss-point-to-surface constraints outnumber the edge''s degrees of freedom and, with '// &
               'penalty_normal = '//real_str(self%law%eps_n, 'es8.1')//', lock (the pressure alternates '// &
               'between neighbouring points instead of following a smooth field)'
        if (self%law%mu > 0.0_dp) text = text//'; the slip bounds mu p_N then jump from '// &
                                         'point to point, which breaks up the stick/slip pattern as well'
        text = text//'; one constraint per slave control point (&contact method = ''mortar'') or fewer '// &
               'slave points per element (&contact n_gauss, here '//str(self%n_gauss)// &
               ') remove the over-constraint, a smaller penalty_normal eases it'
    end function gpts_failure_diagnosis

    !> The contact zone at the last evaluation: `n_active` points in contact;
    !> `n_holes` open points lying between active ones in runs shorter than one slave
    !> element (a zone broken up point by point, not two separate zones), in `n_gaps`
    !> such runs; `n_cp` slave control points whose functions are nonzero at an active
    !> point (the degrees of freedom the active constraints act on).
    pure subroutine gpts_zone(self, n_active, n_holes, n_gaps, n_cp)
        class(gpts_pair_t), intent(in) :: self
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
    end subroutine gpts_zone

    !> Residual `r` (internal-force sign: r = -int G^T t da) and tangent `k` of an
    !> active point, with the traction t on the slave. Frictionless when mu = 0
    !> (no friction code runs). `anchor` is the committed stick point (convected
    !> master coordinate); `new_anchor` the one to commit if the step converges.
    !> With `bound` (and mu > 0) the slip limit |t_T| <= bound is prescribed (Tresca
    !> friction) instead of mu pn; without it the Coulomb code below runs unchanged.
    pure subroutine gpts_point(law, w, sp, mp, anchor, touch, gap0, r, k, state, g, pn, pt, new_anchor, bound)
        type(contact_law_t), intent(in) :: law
        !> Quadrature weight times d(xi_s)/d(reference parameter): da = |a_s| w.
        real(dp), intent(in) :: w
        type(surface_point_t), intent(in) :: sp
        type(master_point_t), intent(in) :: mp
        real(dp), intent(in) :: anchor
        !> Whether the point was open at the last converged state, and its gap there
        !> (huge: no projection). Such a point touched in this step where its gap,
        !> interpolated linearly from that state, vanished; `anchor` is then its
        !> projection at that state, and only the fraction -g / (gap0 - g) of its slip
        !> since, the part after the touch, counts (none without a projection then).
        logical, intent(in) :: touch
        real(dp), intent(in) :: gap0
        real(dp), intent(out) :: r(:), k(:, :)
        integer, intent(out) :: state
        !> Normal gap, contact pressure (>= 0) and tangential traction t . t_hat.
        real(dp), intent(out) :: g, pn, pt
        real(dp), intent(out) :: new_anchor
        !> Prescribed slip bound (traction, >= 0): Tresca mode.
        real(dp), intent(in), optional :: bound
        ! the operators of a point with up to `max_nd` local DOFs in fixed (stack)
        ! buffers: gfortran puts automatic arrays on the heap, eleven per point
        real(dp) :: ops(2, max_nd, 5), vecs(max_nd, 7)
        real(dp), allocatable :: big_ops(:, :, :), big_vecs(:, :)
        integer :: nd
        nd = size(r)
        if (nd <= max_nd) then
            call point_law(law, w, sp, mp, anchor, touch, gap0, r, k, state, g, pn, pt, new_anchor, ops(:, 1:nd, 1), &
                           ops(:, 1:nd, 2), ops(:, 1:nd, 3), ops(:, 1:nd, 4), ops(:, 1:nd, 5), vecs(1:nd, 1), &
                           vecs(1:nd, 2), vecs(1:nd, 3), vecs(1:nd, 4), vecs(1:nd, 5), vecs(1:nd, 6), &
                           vecs(1:nd, 7), bound)
        else
            allocate (big_ops(2, nd, 5), big_vecs(nd, 7))
            call point_law(law, w, sp, mp, anchor, touch, gap0, r, k, state, g, pn, pt, new_anchor, big_ops(:, :, 1), &
                           big_ops(:, :, 2), big_ops(:, :, 3), big_ops(:, :, 4), big_ops(:, :, 5), big_vecs(:, 1), &
                           big_vecs(:, 2), big_vecs(:, 3), big_vecs(:, 4), big_vecs(:, 5), big_vecs(:, 6), &
                           big_vecs(:, 7), bound)
        end if
    end subroutine gpts_point

    !> `gpts_point` on its work arrays [2, nd] and [nd].
    pure subroutine point_law(law, w, sp, mp, anchor, touch, gap0, r, k, state, g, pn, pt, new_anchor, gm, dm, ds, &
                              amat, tmat, c, ng, na, gt, dmt, dst, dslip, bound)
        type(contact_law_t), intent(in) :: law
        real(dp), intent(in) :: w
        type(surface_point_t), intent(in) :: sp
        type(master_point_t), intent(in) :: mp
        real(dp), intent(in) :: anchor, gap0
        logical, intent(in) :: touch
        real(dp), intent(out) :: r(:), k(:, :)
        integer, intent(out) :: state
        real(dp), intent(out) :: g, pn, pt
        real(dp), intent(out) :: new_anchor
        real(dp), intent(out) :: gm(:, :), dm(:, :), ds(:, :), amat(:, :), tmat(:, :)
        real(dp), intent(out) :: c(:), ng(:), na(:), gt(:), dmt(:), dst(:), dslip(:)
        real(dp), intent(in), optional :: bound
        real(dp) :: n(2), that(2), ts(2), t(2), la, las, den, da, slip, ttr, s
        integer :: a, b

        call point_operators(sp, mp, gm, dm, ds)
        n = mp%n(1:2)
        la = norm2(mp%a(1:2))
        that = mp%a(1:2)/la
        las = norm2(sp%a(1:2))
        ts = sp%a(1:2)/las
        da = las*w
        g = dot_product(sp%x(1:2) - mp%x(1:2), n)
        pn = -law%eps_n*g
        ! linearization of the projection: dxi = c . du
        den = dot_product(mp%a(1:2), mp%a(1:2)) - g*dot_product(n, mp%a2(1:2))
        do a = 1, size(r)
            c(a) = ((mp%a(1)*gm(1, a) + mp%a(2)*gm(2, a)) + g*(n(1)*dm(1, a) + n(2)*dm(2, a)))/den
        end do
        ! total change of the master tangent: A = Dm + a2 (x) c
        amat(1, :) = dm(1, :) + mp%a2(1)*c
        amat(2, :) = dm(2, :) + mp%a2(2)*c
        do a = 1, size(r)
            ng(a) = n(1)*gm(1, a) + n(2)*gm(2, a)                ! d g
            na(a) = (n(1)*amat(1, a) + n(2)*amat(2, a))/la     ! n . dA / |a|: dn = -t_hat na, dt_hat = n na
        end do

        ! normal traction and its derivative
        t = pn*n
        tmat(1, :) = -law%eps_n*(n(1)*ng - g*that(1)*na)
        tmat(2, :) = -law%eps_n*(n(2)*ng - g*that(2)*na)
        state = state_stick
        pt = 0.0_dp
        new_anchor = anchor
        if (law%mu > 0.0_dp) call touch_slip(mp%xi, anchor, touch, gap0, g, c, ng, slip, dslip, new_anchor)
        if (law%mu > 0.0_dp .and. present(bound)) then
            ! Tresca: the same predictor and return map with the slip limit fixed
            ttr = law%eps_t*abs(slip)*la
            if (ttr <= bound) then
                t = t - law%eps_t*slip*mp%a(1:2)
                tmat(1, :) = tmat(1, :) - law%eps_t*(mp%a(1)*dslip + slip*amat(1, :))
                tmat(2, :) = tmat(2, :) - law%eps_t*(mp%a(2)*dslip + slip*amat(2, :))
                pt = -law%eps_t*slip*la
            else
                ! t_T = -bound s t_hat; only t_hat moves (dt_hat = n na)
                state = state_slip
                s = sign(1.0_dp, slip)
                t = t - bound*s*that
                tmat(1, :) = tmat(1, :) - bound*s*n(1)*na
                tmat(2, :) = tmat(2, :) - bound*s*n(2)*na
                pt = -bound*s
                new_anchor = mp%xi - s*bound/(law%eps_t*la)
            end if
        else if (law%mu > 0.0_dp) then
            ! elastic predictor on the convected coordinate
            ttr = law%eps_t*abs(slip)*la
            if (ttr <= law%mu*pn .or. .not. law%return_map) then
                t = t - law%eps_t*slip*mp%a(1:2)
                tmat(1, :) = tmat(1, :) - law%eps_t*(mp%a(1)*dslip + slip*amat(1, :))
                tmat(2, :) = tmat(2, :) - law%eps_t*(mp%a(2)*dslip + slip*amat(2, :))
                pt = -law%eps_t*slip*la
            else
                ! return map: |t_T| = mu pn, the anchor follows the slave point
                state = state_slip
                s = sign(1.0_dp, slip)
                t = t - law%mu*pn*s*that
                tmat(1, :) = tmat(1, :) + law%mu*law%eps_n*s*(that(1)*ng + g*n(1)*na)
                tmat(2, :) = tmat(2, :) + law%mu*law%eps_n*s*(that(2)*ng + g*n(2)*na)
                pt = -law%mu*pn*s
                new_anchor = mp%xi - s*law%mu*pn/(law%eps_t*la)
            end if
        end if

        do a = 1, size(r)
            gt(a) = t(1)*gm(1, a) + t(2)*gm(2, a)      ! G^T t
            dmt(a) = t(1)*dm(1, a) + t(2)*dm(2, a)     ! Dm^T t
            dst(a) = ts(1)*ds(1, a) + ts(2)*ds(2, a)   ! t_s . Ds
        end do
        r = -da*gt
        do a = 1, size(r)
            ! K = -da G^T T + da (Dm^T t) c^T - w (G^T t)(t_s^T Ds)
            do b = 1, size(r)
                k(b, a) = -da*(gm(1, b)*tmat(1, a) + gm(2, b)*tmat(2, a)) + da*dmt(b)*c(a) - w*gt(b)*dst(a)
            end do
        end do
    end subroutine point_law

    !> The slip (master parameter) since the stick anchor and its derivative by the
    !> local DOFs, `c` being that of xi: xi - anchor and c; for a point that touched in
    !> this step (`touch`, open at the last converged state with gap `gap0`) only the
    !> part after the touch, f (xi - anchor) with f = -g / (gap0 - g) the share of the
    !> step after the gap, interpolated linearly, vanished (dg = `ng`), and the anchor
    !> to commit when it sticks is there, xi - slip; none without a projection then.
    !> Without it a point that closes in a step sticks where it projected at the
    !> step's start, and the motion of the open surface before it touched (a body's
    !> surface sliding along a rigid one under a growing load) becomes stick traction.
    pure subroutine touch_slip(xi, anchor, touch, gap0, g, c, ng, slip, dslip, new_anchor)
        real(dp), intent(in) :: xi, anchor, gap0, g, c(:), ng(:)
        logical, intent(in) :: touch
        real(dp), intent(out) :: slip, dslip(:)
        real(dp), intent(inout) :: new_anchor
        real(dp) :: f
        slip = xi - anchor
        dslip = c
        if (.not. touch) return
        if (gap0 < huge(1.0_dp) .and. gap0 > g) then
            f = -g/(gap0 - g)
            dslip = f*c - slip*gap0/(gap0 - g)**2*ng
            slip = f*slip
        else
            slip = 0.0_dp
            dslip = 0.0_dp
        end if
        new_anchor = xi - slip
    end subroutine touch_slip
end module voiga_contact_gpts
