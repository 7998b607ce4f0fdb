!> Augmented Lagrangian contact (`&contact method = 'alm'`) on the constraints of
!> the mortar-type penalty: one normal and one tangential condition per slave
!> control point A, on the weighted gap g_A and weighted slip ds_A
!> (`voiga_contact_mortar`), so the constraints never outnumber the slave edge's
!> degrees of freedom (exact enforcement on Gauss-point constraints locks).
!>
!> Each control point carries multipliers: a nominal pressure lambda_A and a
!> tangential traction tau_A. With them fixed, the pressure and traction are those
!> of the mortar-type penalty on the shifted gap and reference traction,
!>
!>     p_A = max(0, lambda_A - eps_N g_A / D_A),
!>     t_A = return map of  tau_A - eps_T ds_A / D_A  onto |t| <= mu p_A,
!>
!> so Newton solves the same problem as the penalty, with the same tangent. Between
!> Newton solves (`voiga_solver_outer`) the multipliers of the active constraints
!> (g_A = 0 where A is active, ds_A = 0 where it sticks) take a Newton step on the
!> constraints through the Schur complement of the factorized tangent, and the
!> others follow the law (lambda_A = 0 where A is open, tau_A = t_A where it slips),
!> until every constraint holds to `tolerance` times the slave element size. The
!> penalties then only set how the active set is found and how stiff each Newton
!> solve is, not the solution (docs/theory.md, section 7, "Augmented Lagrangian").
!>
!> Why this rather than plain Uzawa updates (lambda_A <- p_A): those converge by a
!> factor 1 / (1 + eps C) per update, C the compliance of the constraint mode, and
!> the oscillating modes of a degree-q spline multiplier have a tiny compliance (the
!> spline's mass matrix filters them): on hertz m3 NN2.2 with penalty 1e3 x E the
!> plain update shrank the gap by 0.88 per update. The Newton step on the constraints
!> is exact for a fixed active set of a linear problem, whatever the penalty. Why
!> not multipliers as unknowns of the global system: the solvers, the stiffness
!> pattern and the result file keep the displacement unknowns only.
!>
!> On a solid's face (issue 42) the same pair: one normal multiplier per control point
!> of the slave face, the face's weighted gaps from the mortar pair's face path
!> (`mortar_point3`), and as element size of the tolerance the longer chord across the
!> middle of the cells of the control point's support (`face_sizes`). With friction the
!> tangential multiplier is a vector, the reference of the mortar pair's traction vector
!> per control point, and a sticking control point has two slip constraints on its
!> tangent plane (`alm_faces.f90`).
module voiga_contact_alm
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_text, only: real_str
    use voiga_contact_law, only: control_point_law, state_inactive, state_stick, state_slip
    use voiga_contact_surface, only: element_lengths, face_ids
    use voiga_contact_pair, only: history_item_t, sparse_vector_t, constraint_set_t, automatic
    use voiga_contact_mortar, only: mortar_pair_t
    implicit none
    private

    public :: alm_pair_t, alm_pair, default_alm_tolerance, softening_factor, tangent_frame

    !> Default constraint tolerance, relative to the slave element size: the mean
    !> weighted gap of an active control point and the mean weighted slip of a
    !> sticking one must be below it.
    real(dp), parameter :: default_alm_tolerance = 1.0e-6_dp
    !> A failed substep divides the penalties by this (`alm_soften`).
    real(dp), parameter :: softening_factor = 10.0_dp

    !> An augmented Lagrangian pair.
    type, extends(mortar_pair_t) :: alm_pair_t
        !> Constraint tolerance relative to the slave element size.
        real(dp) :: tolerance = default_alm_tolerance
        !> The index in `hist` of the normal multipliers (nominal pressure, `multiplier`)
        !> [slave edge control points]: the trial values are the current ones.
        integer :: h_lambda = 0
        !> Tangential multipliers (mu > 0) [slave edge control points]; the committed
        !> ones are the mortar pair's `traction`.
        real(dp), allocatable :: tau(:)
        !> At the last evaluation [slave edge control points]: weighted gaps (huge
        !> where nothing projects), weights D_A, weighted slips, states, pressures,
        !> tangential tractions.
        real(dp), allocatable :: g(:), d(:), ds(:), p_last(:), t_last(:)
        integer, allocatable :: state(:)
        !> Coupling vectors of the active control points at the last evaluation with
        !> a tangent: d g_A / du, d ds_A / du, and q_A (-d r / d t_A).
        type(sparse_vector_t), allocatable :: v(:), m(:), q(:)
        !> Reference length of the slave elements in each control point's support
        !> (the largest) [slave edge control points].
        real(dp), allocatable :: h(:)
        !> On a face with friction (`alm_faces.f90`) [3, slave face control points]: the
        !> tangential multipliers (vectors, as the mortar pair's tractions), and at the
        !> last evaluation the counted weighted slips, tractions, trial tractions and the
        !> node normals; with a tangent, the columns of Q (-d r / d t_A) and the rows of
        !> M (d ds_A / du) of the active control points [3, control points].
        real(dp), allocatable :: tau3(:, :), ds3(:, :), t3(:, :), ttr3(:, :), n3(:, :)
        type(sparse_vector_t), allocatable :: q3(:, :), m3(:, :)
    contains
        procedure :: method_name => alm_method_name
        procedure :: control_laws => alm_control_laws
        procedure :: keep_coupling => alm_keep_coupling
        procedure :: setup_history => alm_setup_history
        procedure :: commit => alm_commit
        procedure :: reset_trial => alm_reset_trial
        procedure :: set_history => alm_set_history
        procedure :: has_multipliers => alm_has_multipliers
        procedure :: constraint_test => alm_constraint_test
        procedure :: constraints => alm_constraints
        procedure :: update_multipliers => alm_update_multipliers
        !> The normal multipliers' step (shared by the edge's and the face's update).
        procedure, private :: normal_update => alm_normal_update
        procedure :: soften => alm_soften
        procedure :: control_laws3 => alm_control_laws3
        procedure :: keep_coupling3 => alm_keep_coupling3
    end type alm_pair_t

    interface
        !> `control_laws` on a face with friction (`alm_faces.f90`).
        pure module subroutine alm_control_laws3(self, g_a, d_a, ds, n_a, p_a, t, st_a, t_tr)
            class(alm_pair_t), intent(inout) :: self
            real(dp), intent(inout) :: g_a(:)
            real(dp), intent(in) :: d_a(:), ds(:, :), n_a(:, :)
            real(dp), intent(out) :: p_a(:), t(:, :), t_tr(:, :)
            integer, intent(out) :: st_a(:)
        end subroutine alm_control_laws3
        !> `keep_coupling` on a face with friction (`alm_faces.f90`).
        pure module subroutine alm_keep_coupling3(self, a, blk, v, q, m)
            class(alm_pair_t), intent(inout) :: self
            integer, intent(in) :: a, blk(:)
            real(dp), intent(in) :: v(:), q(:, :), m(:, :)
        end subroutine alm_keep_coupling3
        !> The active constraints of a face with friction (`constraints`).
        pure module function face_constraints(self) result(set)
            class(alm_pair_t), intent(in) :: self
            type(constraint_set_t) :: set
        end function face_constraints
        !> The multiplier update of a face with friction (`update_multipliers`).
        pure module subroutine face_update(self, delta)
            class(alm_pair_t), intent(inout) :: self
            real(dp), intent(in) :: delta(:)
        end subroutine face_update
        !> The largest tangential slip residual of the sticking control points of a face
        !> with friction, relative to their sizes (`constraint_test`).
        pure module function face_slip_residual(self) result(residual)
            class(alm_pair_t), intent(in) :: self
            real(dp) :: residual
        end function face_slip_residual
    end interface

contains

    !> An empty augmented Lagrangian pair with constraint tolerance `tolerance`
    !> (`automatic`: `default_alm_tolerance`).
    pure function alm_pair(tolerance) result(pair)
        real(dp), intent(in) :: tolerance
        type(alm_pair_t) :: pair
        if (tolerance /= automatic) pair%tolerance = tolerance
    end function alm_pair

    pure function alm_method_name(self) result(name)
        class(alm_pair_t), intent(in) :: self
        character(len=:), allocatable :: name
        name = 'alm'
    end function alm_method_name

    !> The mortar-type law on the gaps shifted by the multipliers,
    !> g_A - lambda_A D_A / eps_N (so that p_A = max(0, lambda_A - eps_N g_A / D_A)), with
    !> tau_A as the tangential reference; the unshifted gaps and slips are kept.
    pure subroutine alm_control_laws(self, g_a, d_a, ds_a, p_a, t_a, st_a, t_tr)
        class(alm_pair_t), intent(inout) :: self
        real(dp), intent(inout) :: g_a(:)
        real(dp), intent(in) :: d_a(:), ds_a(:)
        real(dp), intent(out) :: p_a(:), t_a(:), t_tr(:)
        integer, intent(out) :: st_a(:)
        real(dp) :: t_old
        integer :: a
        self%g = g_a
        self%d = d_a
        self%ds = ds_a
        do a = 1, size(g_a)
            if (g_a(a) < huge(1.0_dp)) g_a(a) = g_a(a) - self%hist%field(self%h_lambda)%trial(a)*d_a(a)/self%law%eps_n
            t_old = 0.0_dp
            if (allocated(self%tau)) t_old = self%tau(a)
            call control_point_law(self%law, g_a(a), d_a(a), ds_a(a), t_old, self%gap_tol, p_a(a), t_a(a), &
                                   st_a(a), t_tr(a))
            if (self%h_traction > 0) self%hist%field(self%h_traction)%trial(a) = t_a(a)
        end do
        self%state = st_a
        self%p_last = p_a
        self%t_last = t_a
    end subroutine alm_control_laws

    !> Keep the coupling vectors of active control point `a`.
    pure subroutine alm_keep_coupling(self, a, blk, v, q, m)
        class(alm_pair_t), intent(inout) :: self
        integer, intent(in) :: a, blk(:)
        real(dp), intent(in) :: v(:), q(:), m(:)
        self%v(a) = sparse_vector_t(blk, v)
        self%q(a) = sparse_vector_t(blk, q)
        self%m(a) = sparse_vector_t(blk, m)
    end subroutine alm_keep_coupling

    !> A substep failed: divide both penalties by `softening_factor` (the normal one
    !> not below the pair's automatic penalty, the tangential one by the same
    !> factor), and say so. The penalties only regularize the Newton solves between multiplier
    !> updates; the converged state satisfies the constraints whatever they are, so
    !> a stiff one costs iterations and cuts (its curvature) without changing the
    !> result (docs/theory.md, section 7, "Augmented Lagrangian"). A penalty given
    !> below the automatic one is never changed.
    pure subroutine alm_soften(self, changed, text)
        class(alm_pair_t), intent(inout) :: self
        logical, intent(out) :: changed
        character(len=:), allocatable, intent(out) :: text
        real(dp) :: old_n, old_t, factor
        old_n = self%law%eps_n
        old_t = self%law%eps_t
        factor = min(softening_factor, old_n/max(self%eps_automatic, tiny(1.0_dp)))
        changed = factor > 1.0_dp*(1.0_dp + 1.0e-12_dp)
        text = ''
        if (.not. changed) return
        self%law%eps_n = old_n/factor
        self%law%eps_t = old_t/factor
        text = 'penalty_normal '//real_str(old_n, 'es10.3')//' -> '//real_str(self%law%eps_n, 'es10.3')// &
               ', penalty_tangent '//real_str(old_t, 'es10.3')//' -> '//real_str(self%law%eps_t, 'es10.3')
    end subroutine alm_soften

    !> The mortar pair's history, the multipliers (zero: the first Newton solve is
    !> the penalty's) and the element sizes of the constraint test.
    pure subroutine alm_setup_history(self)
        class(alm_pair_t), intent(inout) :: self
        real(dp), allocatable :: lengths(:)
        integer :: n, i
        call self%mortar_pair_t%setup_history()
        n = size(self%node_first)
        call self%hist%add('multiplier', n, self%h_lambda)
        allocate (self%g(n), self%d(n), self%ds(n), self%state(n), &
                  self%p_last(n), self%t_last(n), self%v(n), self%m(n), self%q(n), self%h(n))
        self%g = huge(1.0_dp)
        self%d = 0.0_dp
        self%ds = 0.0_dp
        self%state = state_inactive
        self%p_last = 0.0_dp
        self%t_last = 0.0_dp
        if (self%law%mu > 0.0_dp .and. self%slave%npar > 1) then
            allocate (self%tau3(3, n), self%ds3(3, n), self%t3(3, n), self%ttr3(3, n), self%n3(3, n), &
                      source=0.0_dp)
            allocate (self%q3(3, n), self%m3(3, n))
        else if (self%law%mu > 0.0_dp) then
            allocate (self%tau(n))
            self%tau = 0.0_dp
        end if
        if (self%slave%npar > 1) then
            call face_sizes(self)
            return
        end if
        lengths = element_lengths(self%slave)
        do i = 1, n
            self%h(i) = maxval(lengths(self%node_first(i):self%node_last(i)))
        end do
    end subroutine alm_setup_history

    !> On a face, each control point's reference size: the largest over the cells of
    !> its support of the cell's longer chord across its middle. The longer, as an
    !> edge's chord, is the cell's extent whatever its aspect: the cells of a polar
    !> grid narrow to wedges at its collapsed axis, whose shorter chord (or the square
    !> root of their area) would tighten the tolerance there for no accuracy. The
    !> cells of a support come from their control points (`face_ids`): a node's range
    !> of cells, flat from first to last, holds cells beside its support.
    pure subroutine face_sizes(self)
        class(alm_pair_t), intent(inout) :: self
        real(dp), allocatable :: lengths(:)
        integer, allocatable :: ids(:)
        integer :: e, nu
        lengths = element_lengths(self%slave, longest=.true.)
        nu = size(self%slave%spans)
        self%h = 0.0_dp
        do e = 1, size(lengths)
            ids = face_ids(self%slave, [self%slave%spans(modulo(e - 1, nu) + 1), self%slave%spans_eta((e - 1)/nu + 1)])
            self%h(ids) = max(self%h(ids), lengths(e))
        end do
    end subroutine face_sizes

    !> The step converged (the multipliers become the committed ones), a step is
    !> retried, or the history is set (a restart): the tangential multipliers go on
    !> from the committed tractions, so that a run does not depend on whether it was
    !> interrupted (at convergence they agree to the tolerance).
    pure subroutine alm_commit(self)
        class(alm_pair_t), intent(inout) :: self
        call self%mortar_pair_t%commit()
        call tau_from_traction(self)
    end subroutine alm_commit

    pure subroutine alm_reset_trial(self)
        class(alm_pair_t), intent(inout) :: self
        call self%mortar_pair_t%reset_trial()
        call tau_from_traction(self)
    end subroutine alm_reset_trial

    pure subroutine alm_set_history(self, items, error)
        class(alm_pair_t), intent(inout) :: self
        type(history_item_t), intent(in) :: items(:)
        type(error_t), allocatable, intent(out) :: error
        call self%mortar_pair_t%set_history(items, error)
        call tau_from_traction(self)
    end subroutine alm_set_history

    pure subroutine tau_from_traction(self)
        class(alm_pair_t), intent(inout) :: self
        if (allocated(self%tau)) self%tau = self%hist%field(self%h_traction)%last
        if (.not. allocated(self%tau3)) return
        self%tau3(1, :) = self%hist%field(self%h_traction)%last
        self%tau3(2, :) = self%hist%field(self%h_traction_yz(1))%last
        self%tau3(3, :) = self%hist%field(self%h_traction_yz(2))%last
    end subroutine tau_from_traction

    pure logical function alm_has_multipliers(self)
        class(alm_pair_t), intent(in) :: self
        alm_has_multipliers = .true.
    end function alm_has_multipliers

    !> `satisfied` when every active control point's mean gap g_A / D_A and every
    !> sticking one's mean slip ds_A / D_A are within `tolerance` of its element
    !> size; `residual`: the largest of these ratios.
    pure subroutine alm_constraint_test(self, satisfied, residual)
        class(alm_pair_t), intent(in) :: self
        logical, intent(out) :: satisfied
        real(dp), intent(out) :: residual
        integer :: a
        residual = 0.0_dp
        do a = 1, size(self%state)
            if (self%state(a) == state_inactive .or. self%h(a) <= 0.0_dp .or. self%d(a) <= 0.0_dp) cycle
            residual = max(residual, abs(self%g(a)/self%d(a))/self%h(a))
            if (allocated(self%tau) .and. self%law%mu > 0.0_dp .and. self%state(a) == state_stick) &
                residual = max(residual, abs(self%ds(a)/self%d(a))/self%h(a))
        end do
        if (allocated(self%tau3)) residual = max(residual, face_slip_residual(self))
        satisfied = residual <= self%tolerance
    end subroutine alm_constraint_test

    !> The active constraints: g_A = 0 for every active control point (multiplier
    !> lambda_A; d r / d lambda_A = -v_A, and -mu s q_A more where A slips with
    !> direction s), then ds_A = 0 for every sticking one (multiplier tau_A;
    !> d r / d tau_A = -q_A).
    pure function alm_constraints(self) result(set)
        class(alm_pair_t), intent(in) :: self
        type(constraint_set_t) :: set
        integer, allocatable :: active(:), stick(:)
        integer :: j, a, n
        if (allocated(self%tau3)) then
            set = face_constraints(self)
            return
        end if
        active = pack([(a, a=1, size(self%state))], self%state /= state_inactive)
        allocate (stick(0))
        ! (a phase without friction has no tangential constraints)
        if (allocated(self%tau) .and. self%law%mu > 0.0_dp) &
            stick = pack([(a, a=1, size(self%state))], self%state == state_stick)
        n = size(active) + size(stick)
        allocate (set%c(n), set%rows(n), set%cols(n))
        do j = 1, size(active)
            a = active(j)
            set%c(j) = self%g(a)
            set%rows(j) = self%v(a)
            set%cols(j) = sparse_vector_t(self%v(a)%dofs, -self%v(a)%values)
            if (self%state(a) == state_slip) set%cols(j)%values = set%cols(j)%values &
                - self%law%mu*sign(1.0_dp, self%t_last(a))*self%q(a)%values
        end do
        do j = 1, size(stick)
            a = stick(j)
            set%c(size(active) + j) = self%ds(a)
            set%rows(size(active) + j) = self%m(a)
            set%cols(size(active) + j) = sparse_vector_t(self%q(a)%dofs, -self%q(a)%values)
        end do
    end function alm_constraints

    !> Each active control point's lambda_A by its step in `delta` (kept >= 0), the open
    !> ones' to 0; `j` the steps taken (the tangential ones follow in `delta`).
    pure subroutine alm_normal_update(self, delta, j)
        class(alm_pair_t), intent(inout) :: self
        real(dp), intent(in) :: delta(:)
        integer, intent(out) :: j
        integer :: a
        j = 0
        associate (lambda => self%hist%field(self%h_lambda)%trial)
            do a = 1, size(self%state)
                if (self%state(a) == state_inactive) then
                    lambda(a) = 0.0_dp
                else
                    j = j + 1
                    lambda(a) = max(0.0_dp, lambda(a) + delta(j))
                end if
            end do
        end associate
    end subroutine alm_normal_update

    !> Update the multipliers: those of the active constraints (order of
    !> `constraints`) by `delta` (lambda_A kept >= 0), the others from the law at the
    !> last evaluation (lambda_A = 0 where A is open, tau_A = t_A where it slips).
    pure subroutine alm_update_multipliers(self, delta)
        class(alm_pair_t), intent(inout) :: self
        real(dp), intent(in) :: delta(:)
        integer :: a, j
        if (allocated(self%tau3)) then
            call face_update(self, delta)
            return
        end if
        call self%normal_update(delta, j)
        if (.not. allocated(self%tau)) return
        do a = 1, size(self%state)
            if (self%law%mu > 0.0_dp .and. self%state(a) == state_stick) then
                j = j + 1
                self%tau(a) = self%tau(a) + delta(j)
            else
                self%tau(a) = self%t_last(a)
            end if
        end do
    end subroutine alm_update_multipliers

    !> An orthonormal frame [3, 2] of the plane normal to the unit vector `n`: the axis
    !> least aligned with n made orthogonal to it, and n x that (as the rigid plane's).
    pure function tangent_frame(n) result(e)
        real(dp), intent(in) :: n(3)
        real(dp) :: e(3, 2)
        integer :: k
        k = minloc(abs(n), dim=1)
        e(:, 1) = -n(k)*n
        e(k, 1) = e(k, 1) + 1.0_dp
        e(:, 1) = e(:, 1)/norm2(e(:, 1))
        e(:, 2) = [n(2)*e(3, 1) - n(3)*e(2, 1), n(3)*e(1, 1) - n(1)*e(3, 1), n(1)*e(2, 1) - n(2)*e(1, 1)]
    end function tangent_frame

end module voiga_contact_alm
