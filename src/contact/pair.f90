!> A contact pair: the slave body's contact edge integrated with Gauss points
!> (full pass: forces on slave and master), a master (another body's contact edge,
!> a rigid line or a rigid curve), the penalty/friction law, and its history (a list
!> of named fields, `voiga_contact_history`: the friction history every method keeps
!> when mu > 0, and the method's own). `contact_pair_t` is abstract: each contact
!> method extends it (`voiga_contact_gpts`: Gauss-point-to-surface,
!> `voiga_contact_mortar`: the mortar-type penalty, `voiga_contact_alm`: augmented
!> Lagrangian, `voiga_contact_segment`: segment-based mortar) and
!> `voiga_contact_factory` builds the one a case names, whole.
!>
!> What the solver needs of a pair: `evaluate` (residual and tangent, trial
!> history), `commit` and `reset_trial` (a step converged, a step is retried),
!> `n_blocks`/`block_dofs` (the stiffness pattern), `accept_iterate`/`step_limit`
!> (step control inside a Newton iteration), the outer-loop hooks
!> (`takes_outer`, `outer_capture`, `outer_apply`, `outer_release`),
!> `failure_diagnosis`, and `history`/`set_history` (the committed history a
!> result file keeps for a restart). Code outside contact/ changes a pair only
!> through its bindings (`set_friction`, `move_master`, `set_penalties`,
!> `set_warm`, `set_pattern_miss`, `refit_ranges`), never its components.
module voiga_contact_pair
    use voiga_kinds, only: dp, i8
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_element_quadrature, only: gauss_legendre
    use voiga_contact_surface, only: contact_surface_t, surface_point_t, surface_point, surface_basis, &
                                     surface_point_at, face_basis, face_point_at, n_elements, face_ids
    use voiga_nurbs_patch, only: cross
    use voiga_contact_master, only: contact_master_t, master_point_t
    use voiga_contact_law, only: contact_law_t, state_inactive
    use voiga_text, only: str, real_str
    use voiga_contact_history, only: history_t, history_item_t
    implicit none
    private

    public :: contact_pair_t, pair_slot_t, contact_point_out_t, history_item_t, add_matrix, &
              sparse_vector_t, constraint_set_t, automatic

    !> The value of a setting (`voiga_contact_factory`'s `contact_settings_t`) that
    !> leaves it to the pair: the automatic normal penalty, the normal penalty for
    !> the tangential one, the method's default tolerance. The one encoding of
    !> "automatic" (a case reader maps a value it was not given to it).
    real(dp), parameter :: automatic = 0.0_dp

    !> Per-slave-point output of the last evaluation.
    type :: contact_point_out_t
        !> Reference and current position of the slave point [nsd; z = 0 in 2D].
        real(dp) :: x0(3) = 0.0_dp, x(3) = 0.0_dp
        !> Normal gap; contact pressure and tangential traction per current length of
        !> the slave edge, and per reference length (nominal: `pn0` = `pn` x `stretch`).
        real(dp) :: gap = 0.0_dp, pn = 0.0_dp, pt = 0.0_dp, pn0 = 0.0_dp, pt0 = 0.0_dp
        !> On a face, the tangential traction vector per current area [3] (`pt` is
        !> its length).
        real(dp) :: tt(3) = 0.0_dp
        !> Current over reference length of the slave edge at the point, |a_s| / |A_s|
        !> (on a face: area, |a_1 x a_2| / |A_1 x A_2|).
        real(dp) :: stretch = 1.0_dp
        !> The reference length (area, on a face) the point integrates: its weight
        !> times |A_s| (|A_1 x A_2|).
        real(dp) :: area0 = 0.0_dp
        !> Master convective coordinate of the projection, and the range of master
        !> control points its functions belong to (empty for a rigid master); `eta_m`
        !> a master surface's second coordinate.
        real(dp) :: xi_m = 0.0_dp, eta_m = 0.0_dp
        integer :: first = 1, last = 0
        integer :: state = state_inactive
    end type contact_point_out_t

    !> A vector on a few global DOFs.
    type :: sparse_vector_t
        integer, allocatable :: dofs(:)
        real(dp), allocatable :: values(:)
    end type sparse_vector_t

    !> The active constraints of a pair with multipliers at its last evaluation, for
    !> a Newton update of the multipliers (`voiga_solver_outer`): per constraint j,
    !> its residual c_j, the derivative of c_j by the DOFs (`rows(j)`), and the
    !> derivative of the residual vector by its multiplier (`cols(j)`).
    type :: constraint_set_t
        real(dp), allocatable :: c(:)
        type(sparse_vector_t), allocatable :: rows(:), cols(:)
    end type constraint_set_t

    abstract interface
        !> Receives a local stiffness matrix `k` on the global DOFs `dofs`.
        subroutine add_matrix(dofs, k)
            import :: dp
            integer, intent(in) :: dofs(:)
            real(dp), intent(in) :: k(:, :)
        end subroutine add_matrix
    end interface

    !> A slave/master pair; the data every method shares.
    type, abstract :: contact_pair_t
        character(len=32) :: slave_name = '', master_name = ''
        !> Spatial dimension (the slave's DOFs per control point).
        integer :: nsd = 2
        integer :: slave_body = 0
        !> Master body index, 0 for a rigid master.
        integer :: master_body = 0
        type(contact_surface_t) :: slave
        class(contact_master_t), allocatable :: master
        type(contact_law_t) :: law
        !> The value of the automatic normal penalty of the pair (what an `automatic`
        !> `penalty_normal` becomes, `voiga_contact_factory`'s `automatic_penalty`;
        !> the floor of ALM's softening).
        real(dp) :: eps_automatic = 0.0_dp
        !> Gauss points per slave element (per direction, on a face).
        integer :: n_gauss = 0
        !> Slave points: parameter, weight (Gauss weight x d xi), knot span [npts];
        !> on a face also the second parameter and its span (weight: x d eta).
        real(dp), allocatable :: xi(:), w(:), eta(:)
        integer, allocatable :: span(:), span_eta(:)
        !> The slave functions at each point (they do not change): values, first and
        !> second derivatives [p + 1, 3, npts] (`surface_basis`); on a face values and
        !> the derivatives by xi and eta [(p + 1)(q + 1), 3, npts] (`face_basis`).
        real(dp), allocatable :: slave_basis(:, :, :)
        !> The pair's history (`voiga_contact_history`): the fields every method
        !> keeps with friction (mu > 0) and those its method adds (`setup_history`).
        type(history_t) :: hist
        !> The shared friction fields' indices in `hist` (0: none, without friction)
        !> [npts]: whether the point was in contact (GPTS) or had a projection
        !> (mortar) at the last converged state (`active_last`, a flag), its
        !> projection there (`xi_last`), and its normal gap there (`gap_last`, huge
        !> without a projection: where between that state and this one a point that
        !> was open first touched).
        integer :: h_xi = 0, h_active = 0, h_gap = 0
        !> On a face, the second coordinate of the projection there (`eta_last`; 0 on an edge).
        integer :: h_eta = 0
        !> Output of the last evaluation [npts].
        type(contact_point_out_t), allocatable :: out(:)
        !> Points with gap < gap_tol are active: a point that touches (gap = 0 up to
        !> round-off) carries penalty stiffness, so bodies that start in contact are
        !> supported. 1e-12 of the slave surface's size.
        real(dp) :: gap_tol = 0.0_dp
        !> Resultant contact force on the slave at the last evaluation [nsd; z = 0 in 2D].
        real(dp) :: force(3) = 0.0_dp
        !> Counters: active point evaluations, of which frictional.
        integer(i8) :: n_evaluations = 0, n_friction = 0
        !> Deformable master: the master control points each slave element e is coupled
        !> with in the stiffness pattern (`range_ids`): the rectangle of the master's grid
        !> (`mwidth` control points per row) with corners mlo(e) and mhi(e), or on an
        !> edge (mwidth = 0) the range [mlo(e), mhi(e)]; empty: lo > hi; initially the
        !> whole master.
        integer, allocatable :: mlo(:), mhi(:)
        integer :: mwidth = 0
        !> Set by an evaluation with a stiffness in which an active point projected
        !> outside its element's range (the range was widened, the point's
        !> stiffness not added: the pattern must be rebuilt and the tangent
        !> assembled again).
        logical :: pattern_miss = .false.
        !> The projections of the last evaluation may start this one's (set by the
        !> assembly after an evaluation, cleared at a substep's first: a restarted run
        !> then projects as the uninterrupted one).
        logical :: warm = .false.
    contains
        !> Residual and (with `add`) tangent at a displacement; updates the trial history.
        procedure(evaluate_interface), deferred :: evaluate
        !> The method's name in case and result files.
        procedure(name_interface), deferred :: method_name
        !> Number of stiffness-pattern blocks and the global DOFs of one.
        procedure(n_blocks_interface), deferred :: n_blocks
        procedure(block_dofs_interface), deferred :: block_dofs
        !> Place the slave points and the history arrays (set the master first).
        procedure :: setup => pair_setup
        !> Add the method's own history fields to `hist` (default: none).
        procedure :: setup_history => pair_no_op
        !> The step converged: the trial history becomes the committed one.
        procedure :: commit => pair_commit
        !> Forget the trial history (a step is retried).
        procedure :: reset_trial => pair_reset_trial
        !> The committed history, and setting it (a restart); the most points a
        !> restart may read for a field per point (-1: as many as now).
        procedure :: history => pair_history
        procedure :: set_history => pair_set_history
        procedure :: most_points => pair_most_points
        !> Step control inside a Newton iteration (default: none).
        procedure :: accept_iterate => pair_accept_iterate
        procedure :: step_limit => pair_step_limit
        !> The Tresca fixed point on the slip limits, an outer loop around Newton on
        !> variables the method fixes for a Newton solve (default: not taking part).
        procedure :: takes_outer => pair_takes_outer
        procedure :: outer_capture => pair_outer_capture
        procedure :: outer_apply => pair_no_op
        procedure :: outer_release => pair_no_op
        !> Multipliers updated between Newton solves (augmented Lagrangian; default:
        !> none): whether the pair has them; the constraint test at the last
        !> evaluation; its active constraints; an update of their multipliers.
        procedure :: has_multipliers => pair_has_multipliers
        procedure :: constraint_test => pair_constraint_test
        procedure :: constraints => pair_constraints
        procedure :: update_multipliers => pair_update_multipliers
        !> The stick predictor (`voiga_solver_newton`): while on, every active point
        !> sticks (no return map); and whether any point (or control point) was in
        !> contact at the last converged state (friction only).
        procedure :: stick_trial => pair_stick_trial
        procedure :: contact_last => pair_contact_last
        !> A substep failed: a pair whose penalties do not decide its solution may
        !> make them softer for the next attempt (default: not; `text` says what changed).
        procedure :: soften => pair_soften
        !> What the pair's state says about a failed step (default: nothing).
        procedure :: failure_diagnosis => pair_failure_diagnosis
        !> Helpers of the methods.
        procedure :: project_point => pair_project_point
        procedure :: projection_error => pair_projection_error
        procedure :: fit_pattern => pair_fit_pattern
        procedure :: element_dofs => pair_element_dofs
        procedure :: range_ids => pair_range_ids
        procedure :: wanted_ranges => pair_wanted_ranges
        !> The slave points of slave element e (first and last index) and the slave
        !> element of point k: `n_gauss` per element in element order unless a method
        !> places its points otherwise (`voiga_contact_segment`).
        procedure :: point_range => pair_point_range
        procedure :: point_element => pair_point_element
        !> What the model and the solver change in a pair, so that nothing outside
        !> contact/ writes its components: the friction coefficient of a load phase,
        !> a rigid master's prescribed translation, the penalties a restart reads back,
        !> whether the last projections start the next ones (`warm`), the pattern flag,
        !> and the master ranges fitted to the last evaluation.
        procedure :: set_friction => pair_set_friction
        procedure :: move_master => pair_move_master
        procedure :: set_penalties => pair_set_penalties
        procedure :: set_warm => pair_set_warm
        procedure :: set_pattern_miss => pair_set_pattern_miss
        procedure :: refit_ranges => pair_refit_ranges
    end type contact_pair_t

    !> An element of an array of pairs of any methods.
    type :: pair_slot_t
        class(contact_pair_t), allocatable :: pair
    end type pair_slot_t

    abstract interface
        subroutine evaluate_interface(self, u, r, error, add)
            import :: contact_pair_t, dp, error_t, add_matrix
            class(contact_pair_t), intent(inout) :: self
            !> Displacement [ndof]; the contact residual is added to `r` [ndof].
            real(dp), intent(in) :: u(:)
            real(dp), intent(inout) :: r(:)
            type(error_t), allocatable, intent(out) :: error
            procedure(add_matrix), optional :: add
        end subroutine evaluate_interface

        pure function name_interface(self) result(name)
            import :: contact_pair_t
            class(contact_pair_t), intent(in) :: self
            character(len=:), allocatable :: name
        end function name_interface

        pure integer function n_blocks_interface(self)
            import :: contact_pair_t
            class(contact_pair_t), intent(in) :: self
        end function n_blocks_interface

        pure function block_dofs_interface(self, b, mdofs) result(dofs)
            import :: contact_pair_t
            class(contact_pair_t), intent(in) :: self
            !> Block 1 .. n_blocks, and `self%master%all_dofs()`.
            integer, intent(in) :: b
            integer, intent(in) :: mdofs(:)
            integer, allocatable :: dofs(:)
        end function block_dofs_interface
    end interface

    !> The stiffness pattern of a pair (`voiga_contact_pair_pattern`): which master
    !> control points each slave element is coupled with.
    interface
        !> `inside`: whether the master functions of slave point `k`'s projection lie in
        !> its element's range of the stiffness pattern; if not, the range is widened and
        !> `pattern_miss` set (the caller rebuilds the pattern and assembles again).
        pure module subroutine pair_fit_pattern(self, k, mp, inside)
            class(contact_pair_t), intent(inout) :: self
            integer, intent(in) :: k
            type(master_point_t), intent(in) :: mp
            logical, intent(out) :: inside
        end subroutine pair_fit_pattern

        !> Global DOFs of slave element `e`'s control points on the contact edge.
        pure module function pair_element_dofs(self, e) result(dofs)
            class(contact_pair_t), intent(in) :: self
            integer, intent(in) :: e
            integer, allocatable :: dofs(:)
        end function pair_element_dofs

        !> The master control points of slave element `e`'s range (`mlo`, `mhi`).
        pure module function pair_range_ids(self, e) result(ids)
            class(contact_pair_t), intent(in) :: self
            integer, intent(in) :: e
            integer, allocatable :: ids(:)
        end function pair_range_ids

        !> The master ranges each slave element should be coupled with, from the last
        !> evaluation: the control points of the projections of its points that are
        !> closer than the element's size (gap < diameter of its points' box), widened
        !> by one span on each side and rounded outward to blocks of `block` control
        !> points (so that the pattern changes seldom while the bodies slide).
        !> `n_master` is the master's number of control points.
        pure module subroutine pair_wanted_ranges(self, n_master, block, lo, hi)
            class(contact_pair_t), intent(in) :: self
            integer, intent(in) :: n_master, block
            integer, intent(out) :: lo(:), hi(:)
        end subroutine pair_wanted_ranges

        !> A deformable master's ranges to `wanted_ranges` (blocks of `block` control
        !> points); `changed`: whether one changed (the pattern must be rebuilt).
        pure module subroutine pair_refit_ranges(self, block, changed)
            class(contact_pair_t), intent(inout) :: self
            integer, intent(in) :: block
            logical, intent(out) :: changed
        end subroutine pair_refit_ranges
    end interface

    !> Where the slave points lie and what they see (`voiga_contact_pair_points`).
    interface
        !> The Gauss points of a face: n_gauss^2 per cell (cells and points xi fastest),
        !> from the 1D rule `gx`, `gw` on [-1, 1], and the functions there.
        pure module subroutine face_points(self, gx, gw)
            class(contact_pair_t), intent(inout) :: self
            real(dp), intent(in) :: gx(:), gw(:)
        end subroutine face_points

        !> Evaluate slave point `k` at `u` and project it onto the master (`prepare`d):
        !> its output record is reset to not in contact, with its positions, projection
        !> and gap (huge without a projection).
        pure module subroutine pair_project_point(self, u, k, sp, mp, found, converged)
            class(contact_pair_t), intent(inout) :: self
            real(dp), intent(in) :: u(:)
            integer, intent(in) :: k
            type(surface_point_t), intent(inout) :: sp
            type(master_point_t), intent(out) :: mp
            logical, intent(out) :: found, converged
        end subroutine pair_project_point
    end interface

contains

    !> Place the slave Gauss points (n_gauss per slave element and direction; 0:
    !> degree + 1), the pattern ranges and the gap tolerance, then the history
    !> (`setup_history`).
    pure subroutine pair_setup(self)
        class(contact_pair_t), intent(inout) :: self
        real(dp), allocatable :: gx(:), gw(:)
        integer :: ne, ng, e, i, k, s
        real(dp) :: a, b

        self%nsd = size(self%slave%dofs, 1)
        if (self%n_gauss <= 0) self%n_gauss = self%slave%degree + 1
        ng = self%n_gauss
        allocate (gx(ng), gw(ng))
        call gauss_legendre(ng, gx, gw)
        if (self%slave%npar > 1) then
            call face_points(self, gx, gw)
        else
            ne = size(self%slave%breaks) - 1
            allocate (self%xi(ne*ng), self%w(ne*ng), self%span(ne*ng))
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
            allocate (self%slave_basis(self%slave%degree + 1, 3, ne*ng))
            do k = 1, ne*ng
                call surface_basis(self%slave, self%xi(k), self%span(k), self%slave_basis(:, 1, k), &
                                   self%slave_basis(:, 2, k), self%slave_basis(:, 3, k), s)
            end do
        end if
        ne = n_elements(self%slave)
        allocate (self%out(size(self%xi)))
        ! until the assembly fits them (assemble with refit), every slave element is
        ! coupled with the whole master
        allocate (self%mlo(ne), self%mhi(ne))
        self%mlo = 1
        self%mhi = 0
        if (allocated(self%master)) then
            self%mhi = size(self%master%all_dofs())/self%nsd
            self%mwidth = self%master%grid_width()
        end if
        self%gap_tol = 1.0e-12_dp*norm2(maxval(self%slave%x0, dim=2) - minval(self%slave%x0, dim=2))
        call shared_history(self)
        call self%setup_history()
    end subroutine pair_setup

    !> The friction history every method keeps (mu > 0): projections, contact and
    !> gaps at the last converged state, one entry per slave point.
    pure subroutine shared_history(self)
        class(contact_pair_t), intent(inout) :: self
        integer :: n
        if (self%law%mu <= 0.0_dp) return
        n = size(self%xi)
        call self%hist%add('xi_last', n, self%h_xi, per_point=.true.)
        call self%hist%add('active_last', n, self%h_active, flags=.true., per_point=.true.)
        call self%hist%add('gap_last', n, self%h_gap, initial=huge(1.0_dp), per_point=.true.)
        if (self%slave%npar > 1) call self%hist%add('eta_last', n, self%h_eta, per_point=.true.)
    end subroutine shared_history

    pure subroutine pair_commit(self)
        class(contact_pair_t), intent(inout) :: self
        call self%hist%commit()
    end subroutine pair_commit

    pure subroutine pair_reset_trial(self)
        class(contact_pair_t), intent(inout) :: self
        call self%hist%reset_trial()
    end subroutine pair_reset_trial

    !> Every field of `hist` (none without friction and method history).
    pure function pair_history(self) result(items)
        class(contact_pair_t), intent(in) :: self
        type(history_item_t), allocatable :: items(:)
        items = self%hist%items(self%most_points())
    end function pair_history

    !> Set the committed (and trial) history from `items` (as `history` names them).
    pure subroutine pair_set_history(self, items, error)
        class(contact_pair_t), intent(inout) :: self
        type(history_item_t), intent(in) :: items(:)
        type(error_t), allocatable, intent(out) :: error
        call self%hist%set_items(items, error)
    end subroutine pair_set_history

    pure integer function pair_most_points(self) result(n)
        class(contact_pair_t), intent(in) :: self
        n = -1
    end function pair_most_points

    pure subroutine pair_accept_iterate(self)
        class(contact_pair_t), intent(inout) :: self
    end subroutine pair_accept_iterate

    !> The fraction of the last Newton step the pair allows (1: all of it).
    pure real(dp) function pair_step_limit(self, overshoot) result(frac)
        class(contact_pair_t), intent(in) :: self
        real(dp), intent(in) :: overshoot
        frac = 1.0_dp
    end function pair_step_limit

    pure logical function pair_takes_outer(self)
        class(contact_pair_t), intent(in) :: self
        pair_takes_outer = .false.
    end function pair_takes_outer

    !> Take the outer variables from the last evaluation; `change`: the largest
    !> change from the previous capture, `largest`: the largest value.
    pure subroutine pair_outer_capture(self, change, largest)
        class(contact_pair_t), intent(inout) :: self
        real(dp), intent(out) :: change, largest
        change = 0.0_dp
        largest = 0.0_dp
    end subroutine pair_outer_capture

    pure logical function pair_has_multipliers(self)
        class(contact_pair_t), intent(in) :: self
        pair_has_multipliers = .false.
    end function pair_has_multipliers

    !> Whether the constraints hold to the pair's tolerance at the last evaluation;
    !> `residual`: how far they are off (relative to the slave element size).
    pure subroutine pair_constraint_test(self, satisfied, residual)
        class(contact_pair_t), intent(in) :: self
        logical, intent(out) :: satisfied
        real(dp), intent(out) :: residual
        satisfied = .true.
        residual = 0.0_dp
    end subroutine pair_constraint_test

    !> The active constraints at the last evaluation (with a tangent).
    pure function pair_constraints(self) result(set)
        class(contact_pair_t), intent(in) :: self
        type(constraint_set_t) :: set
        allocate (set%c(0), set%rows(0), set%cols(0))
    end function pair_constraints

    !> Update the multipliers: those of the active constraints (in the order of
    !> `constraints`) by `delta`, the others from the last evaluation.
    pure subroutine pair_update_multipliers(self, delta)
        class(contact_pair_t), intent(inout) :: self
        real(dp), intent(in) :: delta(:)
    end subroutine pair_update_multipliers

    pure subroutine pair_stick_trial(self, on)
        class(contact_pair_t), intent(inout) :: self
        logical, intent(in) :: on
        self%law%return_map = .not. on
    end subroutine pair_stick_trial

    !> Default (GPTS): a slave point was in contact at the last converged state.
    pure logical function pair_contact_last(self)
        class(contact_pair_t), intent(in) :: self
        pair_contact_last = .false.
        if (self%h_active > 0) pair_contact_last = any(self%hist%field(self%h_active)%last /= 0.0_dp)
    end function pair_contact_last

    pure subroutine pair_soften(self, changed, text)
        class(contact_pair_t), intent(inout) :: self
        logical, intent(out) :: changed
        character(len=:), allocatable, intent(out) :: text
        changed = .false.
        text = ''
    end subroutine pair_soften

    pure subroutine pair_no_op(self)
        class(contact_pair_t), intent(inout) :: self
    end subroutine pair_no_op

    pure function pair_failure_diagnosis(self) result(text)
        class(contact_pair_t), intent(in) :: self
        character(len=:), allocatable :: text
        text = ''
    end function pair_failure_diagnosis

    !> The error of a slave point whose projection did not converge.
    pure subroutine pair_projection_error(self, k, error)
        class(contact_pair_t), intent(in) :: self
        integer, intent(in) :: k
        type(error_t), allocatable, intent(out) :: error
        call fatal_error(error, "contact '"//trim(self%slave_name)//"' on '"// &
                         trim(self%master_name)//"': the closest-point projection of slave point "// &
                         str(k)//' at xi = '//real_str(self%xi(k), 'es10.3')//' did not converge', &
                         error_code%numeric)
    end subroutine pair_projection_error

    !> Points m (e - 1) + 1 .. m e, m = n_gauss^npar: the Gauss points `setup` places.
    pure function pair_point_range(self, e) result(range)
        class(contact_pair_t), intent(in) :: self
        integer, intent(in) :: e
        integer :: range(2), m
        m = self%n_gauss**self%slave%npar
        range = [(e - 1)*m + 1, e*m]
    end function pair_point_range

    pure integer function pair_point_element(self, k) result(e)
        class(contact_pair_t), intent(in) :: self
        integer, intent(in) :: k
        e = (k - 1)/self%n_gauss**self%slave%npar + 1
    end function pair_point_element

    pure subroutine pair_set_friction(self, mu)
        class(contact_pair_t), intent(inout) :: self
        real(dp), intent(in) :: mu
        self%law%mu = mu
    end subroutine pair_set_friction

    !> Put a rigid master at translation `d` from its reference place (no effect on
    !> a deformable one, which moves with its body's displacement).
    pure subroutine pair_move_master(self, d)
        class(contact_pair_t), intent(inout) :: self
        real(dp), intent(in) :: d(:)
        call self%master%move(d)
    end subroutine pair_move_master

    pure subroutine pair_set_penalties(self, eps_n, eps_t)
        class(contact_pair_t), intent(inout) :: self
        real(dp), intent(in) :: eps_n, eps_t
        self%law%eps_n = eps_n
        self%law%eps_t = eps_t
    end subroutine pair_set_penalties

    pure subroutine pair_set_warm(self, warm)
        class(contact_pair_t), intent(inout) :: self
        logical, intent(in) :: warm
        self%warm = warm
    end subroutine pair_set_warm

    pure subroutine pair_set_pattern_miss(self, miss)
        class(contact_pair_t), intent(inout) :: self
        logical, intent(in) :: miss
        self%pattern_miss = miss
    end subroutine pair_set_pattern_miss

end module voiga_contact_pair
