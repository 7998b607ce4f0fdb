!> Segment-based mortar contact (`&contact method = 'segment'`): the constraints,
!> laws, friction and tangent of the mortar-type penalty (`voiga_contact_mortar`),
!> one constraint per slave control point A with
!>
!>     g_A = int N_A g dA0,   D_A = int N_A dA0,   p_A = -eps_N g_A / D_A,
!>
!> but the integrals are split into segments: each slave element is cut at the
!> slave parameters whose closest-point projection is a breakpoint of the master
!> (a knot of a deformable master's edge or of a rigid curve; a rigid line has
!> none), and every segment carries `n_gauss` Gauss points. Within a segment the
!> master functions N_B(xi_m(xi)) have no kink, so each mortar integral is exact
!> to the quadrature of its polynomial pieces: with the default number of points
!> the uniform pressure of the contact patch test is an exact discrete solution on
!> non-matching meshes (the master's nodal forces int p N_B dA0 are integrated
!> exactly), where the slave-element quadrature of the mortar-type penalty leaves a
!> spread of about 1 % (docs/theory.md, section 7, "Segment-based mortar").
!>
!> The segmentation is part of the state: it is made at every converged state
!> (`commit`, from the displacement and the master position of the last
!> evaluation) and frozen during the next substep's Newton iterations, so the
!> residual is smooth within a substep, the tangent is the mortar pair's, and the
!> new points' friction history is their projection at the state they start from.
!> Their number changes between substeps; the points are written with each step
!> (the history items `point_xi`, `point_w`, `point_element`) and a restart
!> continues on them.
module voiga_contact_segment
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_element_quadrature, only: gauss_legendre
    use voiga_discretization_patch, only: sorted
    use voiga_contact_surface, only: contact_surface_t, surface_point_t, surface_point, surface_basis
    use voiga_contact_master, only: master_point_t
    use voiga_contact_master_nurbs, only: nurbs_master_t
    use voiga_contact_master_curve, only: rigid_curve_t
    use voiga_contact_law, only: state_inactive, state_stick, state_slip
    use voiga_contact_pair, only: add_matrix, history_item_t
    use voiga_contact_history, only: flag_value
    use voiga_contact_mortar, only: mortar_pair_t, mortar_evaluate
    implicit none
    private

    public :: segment_pair_t, segment_points, default_segment_points
    !> For the face pair (`voiga_contact_segment_faces`), which segments as this one does.
    public :: interpolated_output

    !> Two cuts (or a cut and an element end) closer than this fraction of their
    !> slave element are one: a segment that short adds nothing to the integrals.
    real(dp), parameter :: merge_fraction = 1.0e-9_dp
    !> Iterations of the bracketed Newton search for a cut.
    integer, parameter :: max_newton = 60

    !> A segment-based mortar pair.
    type, extends(mortar_pair_t) :: segment_pair_t
        !> The slave element of each point [npts] and the first point of each slave
        !> element [elements + 1] (points of element e: first(e) .. first(e + 1) - 1,
        !> `n_gauss` per segment, segments in order).
        integer, allocatable :: elem(:), first(:)
        !> The displacement of the last evaluation: at a commit, the converged state
        !> the next segmentation is made at [ndof].
        real(dp), allocatable :: u_last(:)
    contains
        procedure :: method_name => segment_method_name
        procedure :: setup => segment_setup
        procedure :: evaluate => segment_evaluate
        procedure :: commit => segment_commit
        procedure :: history => segment_history
        procedure :: set_history => segment_set_history
        procedure :: most_points => segment_most_points
        procedure :: point_range => segment_point_range
        procedure :: point_element => segment_point_element
    end type segment_pair_t

contains

    pure function segment_method_name(self) result(name)
        class(segment_pair_t), intent(in) :: self
        character(len=:), allocatable :: name
        name = 'segment'
    end function segment_method_name

    !> Gauss points per segment by default: exact for the products of a slave and a
    !> master polynomial piece and of two slave pieces (degrees q_s + max(q_s, q_m);
    !> q_m = 0 for a rigid line), as the integrals of N_A N_B and N_A g need for
    !> polynomial (weight-1) edges. With equal degrees: q + 1, the mortar pair's
    !> default per element.
    pure integer function default_segment_points(slave_degree, master_degree) result(n)
        integer, intent(in) :: slave_degree, master_degree
        n = (slave_degree + max(slave_degree, master_degree))/2 + 1
    end function default_segment_points

    !> The mortar pair's set-up (points per element, history, multiplier basis),
    !> then the segmentation of the reference configuration.
    pure subroutine segment_setup(self)
        class(segment_pair_t), intent(inout) :: self
        real(dp), allocatable :: u0(:)
        integer :: qm, n
        if (self%n_gauss <= 0) then
            qm = 0
            select type (m => self%master)
            class is (nurbs_master_t)
                qm = m%surf%degree
            end select
            self%n_gauss = default_segment_points(self%slave%degree, qm)
        end if
        call self%mortar_pair_t%setup()
        n = maxval(self%slave%dofs)
        if (size(self%master%all_dofs()) > 0) n = max(n, maxval(self%master%all_dofs()))
        allocate (u0(n), source=0.0_dp)
        call resegment(self, u0)
    end subroutine segment_setup

    !> The mortar pair's evaluation on the points of this substep; the
    !> displacement is kept for the segmentation at the commit.
    subroutine segment_evaluate(self, u, r, error, add)
        class(segment_pair_t), intent(inout) :: self
        real(dp), intent(in) :: u(:)
        real(dp), intent(inout) :: r(:)
        type(error_t), allocatable, intent(out) :: error
        procedure(add_matrix), optional :: add
        self%u_last = u
        call mortar_evaluate(self, u, r, error, add)
    end subroutine segment_evaluate

    !> The step converged at the last evaluation: commit the mortar history, then
    !> segment the slave edge there for the next substep.
    pure subroutine segment_commit(self)
        class(segment_pair_t), intent(inout) :: self
        call self%mortar_pair_t%commit()
        if (allocated(self%u_last)) call resegment(self, self%u_last)
    end subroutine segment_commit

    pure function segment_point_range(self, e) result(range)
        class(segment_pair_t), intent(in) :: self
        integer, intent(in) :: e
        integer :: range(2)
        range = [self%first(e), self%first(e + 1) - 1]
    end function segment_point_range

    pure integer function segment_point_element(self, k) result(e)
        class(segment_pair_t), intent(in) :: self
        integer, intent(in) :: k
        e = self%elem(k)
    end function segment_point_element

    !> Segment the slave edge at the configuration `u` (the master where it is now):
    !> new points (`segment_points`), their friction history (their projection at
    !> `u`: a point with a converged projection was in contact there, `xi_last`
    !> its master coordinate) and their output (positions, gaps, projections, and
    !> the tractions interpolated from the control points' at the last evaluation:
    !> the converged state's contact field sampled at the new points).
    pure subroutine resegment(self, u)
        class(segment_pair_t), intent(inout) :: self
        real(dp), intent(in) :: u(:)
        real(dp), allocatable :: xi(:), w(:)
        integer, allocatable :: elem(:)
        type(surface_point_t) :: sp
        type(master_point_t) :: mp
        logical :: found, converged, warm
        integer :: k

        call self%master%prepare(u)
        call segment_points(self, u, xi, w, elem)
        call place_points(self, xi, w, elem)
        ! the projections start afresh (the last evaluation's belong to other points)
        warm = self%warm
        self%warm = .false.
        do k = 1, size(self%xi)
            call self%project_point(u, k, sp, mp, found, converged)
            found = found .and. converged
            if (self%h_xi > 0) then
                self%hist%field(self%h_xi)%last(k) = mp%xi
                self%hist%field(self%h_active)%last(k) = flag_value(found)
            end if
            if (found) call interpolated_output(self, k)
        end do
        self%warm = warm
        call self%hist%reset_trial()
    end subroutine resegment

    !> Point `k`'s tractions and state from the control points' at the last
    !> evaluation (`last`: p_A = -eps_N g_A / D_A where active; the committed t_A).
    pure subroutine interpolated_output(self, k)
        class(segment_pair_t), intent(inout) :: self
        integer, intent(in) :: k
        real(dp) :: pbar, tbar
        integer :: i, a
        if (.not. allocated(self%last%state)) return
        associate (nodes => self%point_nodes(:, k), phi => self%point_values(:, k), out => self%out(k))
            if (all(self%last%state(nodes) == state_inactive)) return
            pbar = 0.0_dp
            tbar = 0.0_dp
            do i = 1, size(nodes)
                a = nodes(i)
                if (self%last%state(a) == state_inactive) cycle
                pbar = pbar - phi(i)*self%law%eps_n*self%last%g(a)/self%last%d(a)
                if (self%h_traction > 0) tbar = tbar + phi(i)*self%hist%field(self%h_traction)%last(a)
            end do
            out%pn0 = pbar
            out%pt0 = tbar
            out%pn = pbar/out%stretch
            out%pt = tbar/out%stretch
            out%state = merge(state_slip, state_stick, any(self%last%state(nodes) == state_slip))
        end associate
    end subroutine interpolated_output

    !> The segmented quadrature of the slave edge at the configuration `u`
    !> (`prepare`d master): per slave element, its cuts (`element_cuts`) split it
    !> into segments and each segment gets `n_gauss` Gauss points: parameters `xi`,
    !> weights `w` (Gauss weight x d xi) and slave elements `elem` [points].
    pure subroutine segment_points(self, u, xi, w, elem)
        class(segment_pair_t), intent(in) :: self
        real(dp), intent(in) :: u(:)
        real(dp), allocatable, intent(out) :: xi(:), w(:)
        integer, allocatable, intent(out) :: elem(:)
        real(dp), allocatable :: lines(:, :), cuts(:), ends(:), gx(:), gw(:)
        integer :: e, s, i, ng, n
        ng = self%n_gauss
        allocate (gx(ng), gw(ng))
        call gauss_legendre(ng, gx, gw)
        call master_lines(self, u, lines)
        allocate (xi(0), w(0), elem(0))
        do e = 1, size(self%slave%spans)
            cuts = element_cuts(self, u, e, lines)
            ends = [self%slave%breaks(e), cuts, self%slave%breaks(e + 1)]
            n = size(ends) - 1
            do s = 1, n
                associate (a => ends(s), b => ends(s + 1))
                    xi = [xi, (a + 0.5_dp*(b - a)*(gx(i) + 1.0_dp), i=1, ng)]
                    w = [w, (0.5_dp*(b - a)*gw(i), i=1, ng)]
                end associate
            end do
            elem = [elem, spread(e, 1, n*ng)]
        end do
    end subroutine segment_points

    !> The master's normal lines at its breakpoints, where a slave point projecting
    !> there would lie: columns (X, t, eta) = point, tangent, parameter [5, lines].
    !> A breakpoint where the tangent turns (a C0 knot) has one line per side; the
    !> slave points between them all project onto it. None for a rigid line.
    pure subroutine master_lines(self, u, lines)
        class(segment_pair_t), intent(in) :: self
        real(dp), intent(in) :: u(:)
        real(dp), allocatable, intent(out) :: lines(:, :)
        allocate (lines(5, 0))
        select type (m => self%master)
        type is (rigid_curve_t)
            call breakpoint_lines(m%surf, m%zero, lines)
        class is (nurbs_master_t)
            call breakpoint_lines(m%surf, u, lines)
        end select
    end subroutine master_lines

    pure subroutine breakpoint_lines(surf, u, lines)
        type(contact_surface_t), intent(in) :: surf
        real(dp), intent(in) :: u(:)
        real(dp), intent(inout), allocatable :: lines(:, :)
        type(surface_point_t) :: left, right
        integer :: j, nb
        real(dp) :: turn
        nb = size(surf%breaks)
        do j = 1, nb
            if (j > 1) call surface_point(surf, u, surf%breaks(j), left, surf%spans(j - 1))
            if (j < nb) call surface_point(surf, u, surf%breaks(j), right, surf%spans(j))
            if (j > 1) lines = reshape([lines, left%x(1:2), left%a(1:2), surf%breaks(j)], [5, size(lines, 2) + 1])
            if (j == 1 .or. j == nb) then
                if (j == 1) lines = reshape([lines, right%x(1:2), right%a(1:2), surf%breaks(j)], &
                                            [5, size(lines, 2) + 1])
                cycle
            end if
            ! the same line unless the tangent turns at the knot
            turn = abs(left%a(1)*right%a(2) - left%a(2)*right%a(1))/(norm2(left%a)*norm2(right%a))
            if (turn > 1.0e-12_dp .or. dot_product(left%a, right%a) <= 0.0_dp) &
                lines = reshape([lines, right%x(1:2), right%a(1:2), surf%breaks(j)], [5, size(lines, 2) + 1])
        end do
    end subroutine breakpoint_lines

    !> The cuts of slave element `e` (ascending, inside it): the parameters where
    !> the slave edge crosses one of the master's normal lines `lines` at a point
    !> whose closest-point projection is that line's breakpoint (so not a crossing
    !> far away, on a part of the slave facing another part of the master). The
    !> crossings are bracketed on 2q + 3 samples of the element and found by a
    !> bracketed Newton iteration; cuts closer than `merge_fraction` of the element
    !> to each other or to its ends are dropped.
    pure function element_cuts(self, u, e, lines) result(cuts)
        class(segment_pair_t), intent(in) :: self
        real(dp), intent(in) :: u(:)
        integer, intent(in) :: e
        real(dp), intent(in) :: lines(:, :)
        real(dp), allocatable :: cuts(:)
        type(surface_point_t) :: pt
        type(master_point_t) :: mp
        real(dp), allocatable :: s(:), x(:, :), f(:), kept(:)
        real(dp) :: a, b, root, tol_eta
        integer :: m, j, il
        logical :: found, converged

        allocate (cuts(0))
        if (size(lines, 2) == 0) return
        a = self%slave%breaks(e)
        b = self%slave%breaks(e + 1)
        m = 2*self%slave%degree + 3
        s = [(a + (b - a)*real(j, dp)/real(m - 1, dp), j=0, m - 1)]
        s(m) = b
        allocate (x(2, m), f(m))
        do j = 1, m
            call surface_point(self%slave, u, s(j), pt, self%slave%spans(e))
            x(:, j) = pt%x(1:2)
        end do
        tol_eta = 1.0e-8_dp*(maxval(lines(5, :)) - minval(lines(5, :)))
        do il = 1, size(lines, 2)
            associate (xm => lines(1:2, il), t => lines(3:4, il), eta => lines(5, il))
                do j = 1, m
                    f(j) = dot_product(x(:, j) - xm, t)
                end do
                do j = 1, m - 1
                    if (f(j) == 0.0_dp .and. j > 1) then
                        root = s(j)
                    else if (f(j)*f(j + 1) < 0.0_dp) then
                        root = crossing(self%slave, u, e, xm, t, s(j), s(j + 1), f(j))
                    else
                        cycle
                    end if
                    call surface_point(self%slave, u, root, pt, self%slave%spans(e))
                    call self%master%project(u, pt%x(1:2), mp, found, converged)
                    if (.not. (found .and. converged)) cycle
                    if (abs(mp%xi - eta) > tol_eta) cycle
                    cuts = [cuts, root]
                end do
            end associate
        end do
        ! ascending, without near-duplicates and without cuts at the element's ends
        cuts = sorted(cuts)
        allocate (kept(0))
        do j = 1, size(cuts)
            if (cuts(j) - a <= merge_fraction*(b - a) .or. b - cuts(j) <= merge_fraction*(b - a)) cycle
            if (size(kept) > 0) then
                if (cuts(j) - kept(size(kept)) <= merge_fraction*(b - a)) cycle
            end if
            kept = [kept, cuts(j)]
        end do
        cuts = kept
    end function element_cuts

    !> The parameter in (lo, hi) of slave element `e` where (x_s - xm) . t = 0, the
    !> function changing sign between lo and hi (`f_lo` its value at lo): Newton
    !> kept in the bracket (a step leaving it is replaced by bisection).
    pure real(dp) function crossing(slave, u, e, xm, t, lo_in, hi_in, f_lo) result(xi)
        type(contact_surface_t), intent(in) :: slave
        real(dp), intent(in) :: u(:), xm(2), t(2), lo_in, hi_in, f_lo
        integer, intent(in) :: e
        type(surface_point_t) :: pt
        real(dp) :: lo, hi, f, df, next
        integer :: it
        lo = lo_in
        hi = hi_in
        xi = 0.5_dp*(lo + hi)
        do it = 1, max_newton
            call surface_point(slave, u, xi, pt, slave%spans(e))
            f = dot_product(pt%x(1:2) - xm, t)
            if (f == 0.0_dp) return
            ! keep the sign change inside [lo, hi]
            if (sign(1.0_dp, f) == sign(1.0_dp, f_lo)) then
                lo = xi
            else
                hi = xi
            end if
            df = dot_product(pt%a(1:2), t)
            next = 0.5_dp*(lo + hi)
            if (df /= 0.0_dp) next = xi - f/df
            if (next <= lo .or. next >= hi) next = 0.5_dp*(lo + hi)
            if (abs(next - xi) <= 1.0e-15_dp*max(1.0_dp, abs(xi))) then
                xi = next
                return
            end if
            xi = next
        end do
    end function crossing

    !> Make `xi`, `w`, `elem` the pair's points: their spans, slave functions,
    !> multiplier values (the slave functions), element ranges, output records, and
    !> per-point friction arrays of their number (not in contact, to be set).
    pure subroutine place_points(self, xi, w, elem)
        class(segment_pair_t), intent(inout) :: self
        real(dp), intent(in) :: xi(:), w(:)
        integer, intent(in) :: elem(:)
        integer :: n, k, e, p, s
        n = size(xi)
        p = self%slave%degree
        self%xi = xi
        self%w = w
        self%elem = elem
        self%span = self%slave%spans(elem)
        if (allocated(self%slave_basis)) deallocate (self%slave_basis)
        allocate (self%slave_basis(p + 1, 3, n))
        if (allocated(self%point_nodes)) deallocate (self%point_nodes, self%point_values)
        allocate (self%point_nodes(p + 1, n), self%point_values(p + 1, n))
        do k = 1, n
            call surface_basis(self%slave, xi(k), self%span(k), self%slave_basis(:, 1, k), &
                               self%slave_basis(:, 2, k), self%slave_basis(:, 3, k), s)
            self%point_nodes(:, k) = [(s - p + e, e=0, p)]
            self%point_values(:, k) = self%slave_basis(:, 1, k)
        end do
        if (allocated(self%first)) deallocate (self%first)
        allocate (self%first(size(self%slave%spans) + 1))
        do e = 1, size(self%first)
            self%first(e) = count(elem < e) + 1
        end do
        if (allocated(self%out)) deallocate (self%out)
        allocate (self%out(n))
        call self%hist%resize_points(n)
    end subroutine place_points

    !> The points (`point_xi`, `point_w`, `point_element`), then the mortar pair's
    !> history (friction only).
    pure function segment_history(self) result(items)
        class(segment_pair_t), intent(in) :: self
        type(history_item_t), allocatable :: items(:)
        type(history_item_t) :: xi, w, elem
        xi%name = 'point_xi'
        xi%values = self%xi
        w%name = 'point_w'
        w%values = self%w
        elem%name = 'point_element'
        elem%flags = self%elem
        xi%most = self%most_points()
        w%most = xi%most
        elem%most = xi%most
        items = [xi, w, elem, self%hist%items(xi%most)]
    end function segment_history

    !> The most points a segmentation can have: per slave element, `n_gauss` on each
    !> of its segments, at most 2q + 2 cuts (one per bracket of `element_cuts`) for
    !> each of the master's normal lines (at most two per breakpoint).
    pure integer function segment_most_points(self) result(n)
        class(segment_pair_t), intent(in) :: self
        integer :: n_lines
        n_lines = 0
        select type (m => self%master)
        type is (rigid_curve_t)
            n_lines = 2*size(m%surf%breaks)
        class is (nurbs_master_t)
            n_lines = 2*size(m%surf%breaks)
        end select
        n = size(self%slave%spans)*self%n_gauss*(1 + (2*self%slave%degree + 2)*n_lines)
    end function segment_most_points

    !> Continue on the points of `items` (checked to be a segmentation of this slave
    !> edge with `n_gauss` points per segment), then the mortar pair's history.
    pure subroutine segment_set_history(self, items, error)
        class(segment_pair_t), intent(inout) :: self
        type(history_item_t), intent(in) :: items(:)
        type(error_t), allocatable, intent(out) :: error
        real(dp), allocatable :: xi(:), w(:)
        integer, allocatable :: elem(:)
        integer :: i, e, n
        do i = 1, size(items)
            select case (trim(items(i)%name))
            case ('point_xi')
                xi = items(i)%values
            case ('point_w')
                w = items(i)%values
            case ('point_element')
                elem = items(i)%flags
            case default
                ! the mortar pair's fields: read by its set_history below
            end select
        end do
        if (.not. (allocated(xi) .and. allocated(w) .and. allocated(elem))) then
            call fatal_error(error, 'history point_xi, point_w, point_element: missing', error_code%input)
            return
        end if
        n = size(xi)
        if (size(w) /= n .or. size(elem) /= n) then
            call fatal_error(error, 'history point_xi, point_w, point_element: different lengths', error_code%input)
            return
        end if
        if (any(elem < 1 .or. elem > size(self%slave%spans))) then
            call fatal_error(error, 'history point_element: not an element of this slave edge', error_code%input)
            return
        end if
        if (any(.not. (w > 0.0_dp)) .or. any(xi < self%slave%breaks(elem) .or. xi > self%slave%breaks(elem + 1))) then
            call fatal_error(error, 'history point_xi, point_w: a point outside its element or without weight', &
                             error_code%input)
            return
        end if
        do e = 1, size(self%slave%spans)
            if (mod(count(elem == e), self%n_gauss) /= 0 .or. count(elem == e) == 0) then
                call fatal_error(error, 'history point_element: not a segmentation of this slave edge '// &
                                 'with n_gauss points per segment', error_code%input)
                return
            end if
        end do
        if (any(elem(2:) < elem(:n - 1))) then
            call fatal_error(error, 'history point_element: points not in element order', error_code%input)
            return
        end if
        call place_points(self, xi, w, elem)
        call self%mortar_pair_t%set_history(items, error)
    end subroutine segment_set_history

end module voiga_contact_segment
