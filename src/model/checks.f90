!> What a run should warn about instead of running silently into a wrong answer
!> (docs/warnings.md): at set-up, bodies that overlap (or a contact
!> edge on the wrong side of a body, whose master normal then points into the
!> slave), a slave contact edge that faces away from its master, a slave stiffer
!> or coarser than its master; after each converged step, a penetration deeper than
!> `deep_fraction` of the slave element; at the end, a pair that never came into
!> contact. Only messages are made here; the solver reports them through
!> `progress_t%warning`, `--check` prints the set-up ones.
!>
!> One set-up cannot make sense and is refused before a run starts
!> (`check_overlaps`): a pair most of whose slave points start inside the master.
!> That is a rigid normal, a rigid curve or a contact edge the wrong way round far
!> more often than an intended interference fit, and the penalty would push the
!> bodies through each other for many load cuts before failing.
module voiga_model_checks
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_text, only: str, real_str, short_str, fixed_str
    use voiga_model, only: model_t
    use voiga_discretization_patch, only: contact_name
    use voiga_contact_pair, only: contact_pair_t
    use voiga_contact_surface, only: contact_surface_t, surface_point_t, surface_point, face_point_at, &
                                     chord_lengths => element_lengths
    use voiga_contact_master_face, only: face_outward_sign
    use voiga_nurbs_patch, only: cross
    use voiga_contact_master, only: master_point_t
    use voiga_contact_master_nurbs, only: nurbs_master_t, outward_sign
    use voiga_contact_master_rigid, only: rigid_line_t
    use voiga_contact_master_curve, only: rigid_curve_t
    use voiga_contact_law, only: state_inactive
    use voiga_element_quadrature, only: gauss_legendre
    use voiga_model_accuracy, only: zone_measure_t, pair_summary, warn_estimate, min_points, &
                                    pair_zones, penalty_smeared
    implicit none
    private

    public :: warning_t, contact_watch_t, new_contact_watch, setup_warnings, deep_fraction, check_overlaps

    !> A penetration deeper than this fraction of its slave element is reported.
    real(dp), parameter :: deep_fraction = 0.1_dp
    !> Bodies overlap at the start when a slave point lies deeper than this fraction
    !> of its slave element inside the master (below: round-off of touching bodies,
    !> or a faceted L1 edge on a curved master).
    real(dp), parameter :: overlap_fraction = 1.0e-3_dp
    !> A slave is coarser than its master when its elements along the contact edge
    !> are longer by this factor on average.
    real(dp), parameter :: coarser_factor = 1.25_dp

    !> One warning (fixed length: arrays of them grow by constructor); `topic`: its
    !> pair and cause in a few words, by which a failure points back to it.
    type :: warning_t
        character(len=1024) :: text = ''
        character(len=160) :: topic = ''
    end type warning_t

    !> The reference lengths of a pair's slave elements [nel].
    type :: lengths_t
        real(dp), allocatable :: h(:)
    end type lengths_t

    !> What the warnings after steps and at the end need to remember per pair.
    type :: contact_watch_t
        !> Has the pair had a point in contact; has its deep penetration been reported?
        logical, allocatable :: ever_active(:), deep_reported(:)
        !> Each pair's slave element lengths (computed once).
        type(lengths_t), allocatable :: slave(:)
        !> Each pair's zone with the largest estimated edge error so far, and its step
        !> (0: none yet).
        type(zone_measure_t), allocatable :: worst(:)
        integer, allocatable :: worst_step(:)
        !> Each pair's first zone whose edges the penalty smears, and its step (0: none).
        type(zone_measure_t), allocatable :: smeared(:)
        integer, allocatable :: smeared_step(:)
    contains
        procedure :: after_step => watch_after_step
        procedure :: at_end => watch_at_end
    end type contact_watch_t

contains

    !> A watch over the pairs of `model`.
    pure subroutine new_contact_watch(self, model)
        type(contact_watch_t), intent(out) :: self
        type(model_t), intent(in) :: model
        integer :: ip
        allocate (self%ever_active(size(model%pairs)), source=.false.)
        allocate (self%deep_reported(size(model%pairs)), source=.false.)
        allocate (self%slave(size(model%pairs)), self%worst(size(model%pairs)), self%smeared(size(model%pairs)))
        allocate (self%worst_step(size(model%pairs)), self%smeared_step(size(model%pairs)), source=0)
        do ip = 1, size(model%pairs)
            self%slave(ip)%h = element_lengths(model%pairs(ip)%pair%slave)
        end do
    end subroutine new_contact_watch

    !> "contact 'slave' on 'master': "
    pure function pair_label(pair) result(label)
        class(contact_pair_t), intent(in) :: pair
        character(len=:), allocatable :: label
        label = "contact '"//trim(pair%slave_name)//"' on '"//trim(pair%master_name)//"': "
    end function pair_label

    !> Reference lengths of the elements of a contact edge [nel] (Gauss, 6 points).
    pure function element_lengths(surf) result(h)
        type(contact_surface_t), intent(in) :: surf
        real(dp), allocatable :: h(:)
        real(dp) :: gx(6), gw(6), u(maxval(surf%dofs))
        type(surface_point_t) :: pt
        integer :: e, i
        ! a face's cells: their size as the contact surface measures it (chords)
        if (surf%npar > 1) then
            h = chord_lengths(surf)
            return
        end if
        call gauss_legendre(6, gx, gw)
        u = 0.0_dp
        allocate (h(size(surf%spans)), source=0.0_dp)
        do e = 1, size(h)
            associate (a => surf%breaks(e), b => surf%breaks(e + 1))
                do i = 1, 6
                    call surface_point(surf, u, a + 0.5_dp*(b - a)*(gx(i) + 1.0_dp), pt, surf%spans(e))
                    h(e) = h(e) + 0.5_dp*(b - a)*gw(i)*norm2(pt%a)
                end do
            end associate
        end do
    end function element_lengths

    !> The depth of each slave point inside the master (-gap) over the reference
    !> length of its slave element, for the points `use` selects (0 for the others).
    pure function depth_ratios(pair, h, use) result(ratio)
        class(contact_pair_t), intent(in) :: pair
        !> The reference lengths of the slave elements.
        real(dp), intent(in) :: h(:)
        logical, intent(in) :: use(:)
        real(dp), allocatable :: ratio(:)
        integer :: k
        allocate (ratio(size(pair%out)), source=0.0_dp)
        do k = 1, size(ratio)
            if (use(k)) ratio(k) = -pair%out(k)%gap/h(pair%point_element(k))
        end do
    end function depth_ratios

    !> "(x, y)" or "(x, y, z)"
    pure function point_str(x) result(text)
        real(dp), intent(in) :: x(:)
        character(len=:), allocatable :: text
        integer :: i
        text = '('//trim(adjustl(real_str(x(1), 'es11.4')))
        do i = 2, size(x)
            text = text//', '//trim(adjustl(real_str(x(i), 'es11.4')))
        end do
        text = text//')'
    end function point_str

    !> The checks of the reference configuration, from each pair's evaluation there
    !> (`new_model` evaluates every pair at u = 0).
    function setup_warnings(model) result(list)
        type(model_t), intent(in) :: model
        type(warning_t), allocatable :: list(:)
        integer :: ip
        allocate (list(0))
        do ip = 1, size(model%pairs)
            associate (pair => model%pairs(ip)%pair)
                call overlap_warning(pair, list)
                call facing_warning(model, pair, list)
                call slave_choice_warning(model, pair, list)
            end associate
        end do
    end function setup_warnings

    !> The slave points of `pair` that start inside the master deeper than
    !> `overlap_fraction` of their slave element (`inside`), of those that have a
    !> projection on it (`found`); `depth`: each point's depth in slave elements;
    !> `share`: the part of the slave edge's length those inside stand for, of the
    !> length of those found (each point stands for its element's length over
    !> the points per element: on a graded edge, many points may cover little length).
    subroutine overlap_counts(pair, depth, inside, found, share)
        class(contact_pair_t), intent(in) :: pair
        real(dp), allocatable, intent(out) :: depth(:)
        integer, intent(out) :: inside, found
        real(dp), intent(out) :: share
        real(dp), allocatable :: h(:), length(:)
        integer :: k
        h = element_lengths(pair%slave)
        depth = depth_ratios(pair, h, pair%out%gap < 1.0e300_dp)
        inside = count(depth > overlap_fraction)
        found = count(pair%out%gap < 1.0e300_dp)
        ! (each point stands for its element's length over the element's points)
        allocate (length(size(depth)))
        do k = 1, size(h)
            associate (range => pair%point_range(k))
                length(range(1):range(2)) = h(k)/real(max(range(2) - range(1) + 1, 1), dp)
            end associate
        end do
        share = 0.0_dp
        if (found > 0) share = sum(length, mask=depth > overlap_fraction)/ &
                               sum(length, mask=pair%out%gap < 1.0e300_dp)
    end subroutine overlap_counts

    !> Slave points inside the master at the start.
    subroutine overlap_warning(pair, list)
        class(contact_pair_t), intent(in) :: pair
        type(warning_t), allocatable, intent(inout) :: list(:)
        real(dp), allocatable :: depth(:)
        real(dp) :: share
        integer :: k, n, found
        call overlap_counts(pair, depth, n, found, share)
        if (n == 0) return
        k = maxloc(depth, dim=1)
        list = [list, warning_t(pair_label(pair)//'the bodies overlap at the start: '//str(n)//' of '// &
                                str(size(depth))//' slave points lie inside the master, the deepest by '// &
                                trim(adjustl(real_str(-pair%out(k)%gap, 'es10.3')))//' at '// &
                                point_str(pair%out(k)%x0(1:pair%nsd))//' ('// &
                                trim(adjustl(real_str(depth(k), 'f6.2')))// &
                                ' slave elements). If the bodies do not overlap, '//wrong_way(pair), &
                                topic=pair_label(pair)//'the bodies overlap at the start')]
    end subroutine overlap_warning

    !> What is the wrong way round when a master seems to hold the slave inside it.
    function wrong_way(pair) result(text)
        class(contact_pair_t), intent(in) :: pair
        character(len=:), allocatable :: text
        select type (m => pair%master)
        type is (rigid_line_t)
            text = 'rigid_normal = '//vector_str(m%n(1:m%nsd))//' points into the slave (the obstacle lies on the '// &
                   'side rigid_normal points away from): check rigid_normal and rigid_point'
        class is (rigid_curve_t)
            text = "the rigid curve '"//trim(m%name)//"' is the wrong way round (the obstacle lies on the "// &
                   "left of the curve's direction, docs/formats.md): check its side ([[curve]] side in a "// &
                   'spec) and its position'
        class default
            text = "a contact edge is on the wrong side of its body (the master's outward normal points "// &
                   'into the slave): check contact_edge of both bodies'
        end select
    end function wrong_way

    !> Refuse (exit 2) a pair most of whose slave edge (by length, of the part that
    !> faces the master) starts inside it, unless `allow(ip)`: the message names the
    !> variable to change.
    subroutine check_overlaps(model, allow, error)
        type(model_t), intent(in) :: model
        !> Per pair: an overlap is intended (`&contact allow_overlap`, `--allow-overlap`).
        logical, intent(in) :: allow(:)
        type(error_t), allocatable, intent(out) :: error
        real(dp), allocatable :: depth(:)
        real(dp) :: share
        integer :: ip, k, n, found
        do ip = 1, size(model%pairs)
            if (allow(ip)) cycle
            associate (pair => model%pairs(ip)%pair)
                call overlap_counts(pair, depth, n, found, share)
                if (share <= 0.5_dp) cycle
                k = maxloc(depth, dim=1)
                call fatal_error(error, pair_label(pair)//'most of the slave edge starts inside the master ('// &
                                 str(n)//' of the '//str(found)//' slave points that face it, '// &
                                 str(nint(100.0_dp*share))//' % of their length; the deepest by '// &
                                 trim(adjustl(real_str(-pair%out(k)%gap, 'es10.3')))//' at '// &
                                 point_str(pair%out(k)%x0(1:pair%nsd))//'): '//overlap_remedy(model, pair, found)// &
                                 '. If the bodies are meant to start overlapping, run with --allow-overlap '// &
                                 '(or allow_overlap = .true. in this &contact)', error_code%input)
                return
            end associate
        end do
    end subroutine check_overlaps

    !> What to change when most of the `found` slave points of `pair` start inside
    !> its master. A rigid master turned round would hold them outside, unless it
    !> cuts through the slave (some points would still be inside it).
    function overlap_remedy(model, pair, found) result(text)
        type(model_t), intent(in) :: model
        class(contact_pair_t), intent(in) :: pair
        integer, intent(in) :: found
        character(len=:), allocatable :: text
        real(dp), allocatable :: h(:)
        integer :: k, behind
        h = element_lengths(pair%slave)
        ! the points that would be inside the master turned round (the gap's sign flipped)
        behind = 0
        do k = 1, size(pair%out)
            if (pair%out(k)%gap < 1.0e300_dp) then
                if (pair%out(k)%gap/h((k - 1)/pair%n_gauss + 1) > overlap_fraction) behind = behind + 1
            end if
        end do
        select type (m => pair%master)
        type is (rigid_line_t)
            if (behind > 0) then
                text = 'the line through rigid_point = '//vector_str(m%p_ref(1:m%nsd))// &
                       ' cuts through the slave body ('// &
                       str(behind)//' of the '//str(found)//' points lie on the side rigid_normal = '// &
                       vector_str(m%n(1:m%nsd))//' points to): move rigid_point (the obstacle lies on the side '// &
                       'rigid_normal points away from)'
            else
                text = 'rigid_normal = '//vector_str(m%n(1:m%nsd))//' points into the slave (the obstacle lies '// &
                       'on the '// &
                       'side rigid_normal points away from): give rigid_normal = '//vector_str(-m%n(1:m%nsd), .false.)
            end if
        class is (rigid_curve_t)
            if (behind > 0) then
                text = "the rigid curve '"//trim(m%name)//"' cuts through the slave body: move it (or the slave)"
            else
                text = "the rigid curve '"//trim(m%name)//"' is the wrong way round (the obstacle lies on the "// &
                       "left of the curve's direction, docs/formats.md): turn it round (in a spec, the "// &
                       "[[curve]]'s other side: 'inside' or 'outside' of an arc, 'left' or 'right' of a "// &
                       'polyline or .g2 curve)'
            end if
        class default
            text = "a contact edge is on the wrong side of its body (the master's outward normal then "// &
                   "points into the slave): check contact_edge of the slave '"//trim(pair%slave_name)// &
                   "' (now '"//contact_name(model%bodies(pair%slave_body)%disc)//"') and of the "// &
                   "master '"//trim(pair%master_name)//"' (now '"// &
                   contact_name(model%bodies(pair%master_body)%disc)//"'), or move the bodies apart"
        end select
    end function overlap_remedy

    !> A vector as a case file takes it: "(a, b)", or "a, b" without `brackets`
    !> (`short_str`: '0.0, -1.0').
    pure function vector_str(x, brackets) result(text)
        real(dp), intent(in) :: x(:)
        logical, intent(in), optional :: brackets
        character(len=:), allocatable :: text
        integer :: i
        text = short_str(x(1))
        do i = 2, size(x)
            text = text//', '//short_str(x(i))
        end do
        if (present(brackets)) then
            if (.not. brackets) return
        end if
        text = '('//text//')'
    end function vector_str



    !> The slave point closest to the master (outside it) must face it: its outward
    !> normal against the master's. Else the slave's contact edge is on the wrong side.
    subroutine facing_warning(model, pair, list)
        type(model_t), intent(in) :: model
        class(contact_pair_t), intent(in) :: pair
        type(warning_t), allocatable, intent(inout) :: list(:)
        type(surface_point_t) :: sp
        type(master_point_t) :: mp
        real(dp), allocatable :: u(:), gap(:)
        real(dp) :: ns(3), s
        integer :: k, d
        logical :: found, converged
        gap = pair%out%gap
        where (gap < 0.0_dp) gap = huge(1.0_dp)
        if (all(gap > 1.0e300_dp)) return
        k = minloc(gap, dim=1)
        allocate (u(model%ndof), source=0.0_dp)
        d = pair%nsd
        ns = 0.0_dp
        if (pair%slave%npar > 1) then
            ! a face: s a_1 x a_2 points out of the body (s the sign of its det J)
            call face_point_at(pair%slave, u, pair%xi(k), pair%eta(k), [pair%span(k), pair%span_eta(k)], &
                               pair%slave_basis(:, 1, k), pair%slave_basis(:, 2, k), pair%slave_basis(:, 3, k), sp)
            s = face_outward_sign(model%bodies(pair%slave_body)%disc)
            ns = s*cross(sp%a, sp%b)/norm2(cross(sp%a, sp%b))
        else
            call surface_point(pair%slave, u, pair%xi(k), sp, pair%span(k))
            s = outward_sign(model%bodies(pair%slave_body)%disc)
            ns(1:2) = s*[sp%a(2), -sp%a(1)]/norm2(sp%a(1:2))
        end if
        call pair%master%project(u, sp%x(1:d), mp, found, converged)
        if (.not. found) return
        if (dot_product(ns, mp%n) <= 0.0_dp) return
        list = [list, warning_t(pair_label(pair)//'the slave point closest to the master, at '// &
                                point_str(sp%x(1:d))// &
                                ", faces away from it: the slave's "//merge('contact_face', 'contact_edge', d == 3)// &
                                " = '"// &
                                contact_name(model%bodies(pair%slave_body)%disc)// &
                                "' is on the side of its body away from the master; choose the "// &
                                merge('face', 'edge', d == 3)//' that faces it'// &
                                rigid_alternative(pair), &
                                topic=pair_label(pair)//'the slave faces away from the master')]
    end subroutine facing_warning

    !> For a rigid master: that its own side may be the wrong one instead.
    function rigid_alternative(pair) result(text)
        class(contact_pair_t), intent(in) :: pair
        character(len=:), allocatable :: text
        select type (m => pair%master)
        type is (rigid_line_t)
            text = ', or rigid_normal = '//vector_str(m%n(1:m%nsd))//' points the wrong way (it points out of the '// &
                   'obstacle, towards the slave)'
        class is (rigid_curve_t)
            text = ", or the rigid curve '"//trim(m%name)//"' is the wrong way round (its side)"
        class default
            text = ''
        end select
    end function rigid_alternative

    !> A deformable master softer or finer than its slave: GPTS enforces the contact
    !> at the slave's points, so the usual choice is the softer, finer body as slave.
    subroutine slave_choice_warning(model, pair, list)
        type(model_t), intent(in) :: model
        class(contact_pair_t), intent(in) :: pair
        type(warning_t), allocatable, intent(inout) :: list(:)
        character(len=:), allocatable :: why
        real(dp) :: es, em, hs, hm
        if (pair%master_body == 0) return
        select type (m => pair%master)
        class is (nurbs_master_t)
            hs = sum(element_lengths(pair%slave))/size(pair%slave%spans)
            hm = sum(element_lengths(m%surf))/size(m%surf%spans)
        class default
            return
        end select
        es = model%bodies(pair%slave_body)%mat%youngs_modulus
        em = model%bodies(pair%master_body)%mat%youngs_modulus
        why = ''
        if (es > em) why = 'stiffer (E = '//trim(adjustl(real_str(es, 'es10.3')))//' against '// &
                           trim(adjustl(real_str(em, 'es10.3')))//')'
        if (hs > coarser_factor*hm) then
            if (len(why) > 0) why = why//' and '
            why = why//'coarser (elements '//trim(adjustl(real_str(hs, 'es10.3')))//' long against '// &
                  trim(adjustl(real_str(hm, 'es10.3')))//' on average along the contact edges)'
        end if
        if (len(why) == 0) return
        list = [list, warning_t(pair_label(pair)//'the slave is '//why//' than its master: the master '// &
                                "may then penetrate between the slave's points; the usual choice is the "// &
                                'softer, finer body as slave (swap slave and master), or more slave points '// &
                                '(n_gauss)', topic=pair_label(pair)//'the slave is '//why//' than its master')]
    end subroutine slave_choice_warning

    !> After converged step `step`: remember which pairs touch, and report (once per
    !> pair) a penetration deeper than `deep_fraction` of its slave element.
    subroutine watch_after_step(self, model, step, list)
        class(contact_watch_t), intent(inout) :: self
        type(model_t), intent(in) :: model
        integer, intent(in) :: step
        type(warning_t), allocatable, intent(out) :: list(:)
        real(dp), allocatable :: ratio(:)
        integer :: ip, k
        allocate (list(0))
        do ip = 1, size(model%pairs)
            call remember_worst(self, model, ip, step)
            associate (pair => model%pairs(ip)%pair)
                if (any(pair%out%state /= state_inactive)) self%ever_active(ip) = .true.
                if (self%deep_reported(ip)) cycle
                ratio = depth_ratios(pair, self%slave(ip)%h, pair%out%state /= state_inactive)
                if (maxval(ratio) <= deep_fraction) cycle
                self%deep_reported(ip) = .true.
                k = maxloc(ratio, dim=1)
                list = [list, warning_t(pair_label(pair)//'step '//str(step)//': a penetration of '// &
                                        trim(adjustl(real_str(-pair%out(k)%gap, 'es10.3')))//' at '// &
                                        point_str(pair%out(k)%x(1:pair%nsd))//' is '// &
                                        trim(adjustl(real_str(ratio(k), 'f6.2')))//' of its slave element '// &
                                        '(more than '//trim(adjustl(real_str(deep_fraction, 'f6.2')))// &
                                        '): the penalty is too soft for this load; raise penalty_normal', &
                                        topic=pair_label(pair)//'step '//str(step)//': a deep penetration')]
            end associate
        end do
    end subroutine watch_after_step

    !> At the end of a run of `n_steps` steps: the pairs that never touched.
    pure subroutine watch_at_end(self, model, n_steps, list)
        class(contact_watch_t), intent(in) :: self
        type(model_t), intent(in) :: model
        integer, intent(in) :: n_steps
        type(warning_t), allocatable, intent(out) :: list(:)
        integer :: ip
        allocate (list(0))
        do ip = 1, size(model%pairs)
            if (self%worst_step(ip) > 0) call accuracy_warning(model%pairs(ip)%pair, self%worst(ip), &
                                                               self%worst_step(ip), list)
            if (self%smeared_step(ip) > 0) call smearing_warning(model%pairs(ip)%pair, self%smeared(ip), &
                                                                 self%smeared_step(ip), list)
            if (self%ever_active(ip)) cycle
            list = [list, warning_t(pair_label(model%pairs(ip)%pair)//'no point came into contact in '// &
                                    str(n_steps)//' steps: check the loads, the contact edges and the gap '// &
                                    'between the bodies', topic=pair_label(model%pairs(ip)%pair)// &
                                    'no point came into contact')]
        end do
    end subroutine watch_at_end

    !> Keep pair `ip`'s zone at `step` when its estimated edge error is the largest so far,
    !> and its first zone whose edges the penalty smears.
    pure subroutine remember_worst(self, model, ip, step)
        type(contact_watch_t), intent(inout) :: self
        type(model_t), intent(in) :: model
        integer, intent(in) :: ip, step
        type(zone_measure_t) :: zone
        type(zone_measure_t), allocatable :: zones(:)
        integer :: i
        zones = pair_zones(model, ip)
        if (self%smeared_step(ip) == 0) then
            do i = 1, size(zones)
                if (.not. penalty_smeared(zones(i))) cycle
                self%smeared(ip) = zones(i)
                self%smeared_step(ip) = step
                exit
            end do
        end if
        if (size(zones) == 0) return
        zone = pair_summary(zones, model%pairs(ip)%pair%slave%npar == 2)
        if (self%worst_step(ip) > 0) then
            if (.not. zone%estimate > self%worst(ip)%estimate) return
        end if
        self%worst(ip) = zone
        self%worst_step(ip) = step
    end subroutine remember_worst

    !> A pair whose largest estimated edge error (docs/contact-accuracy.md) exceeds
    !> `warn_estimate`: the zone, where, and the remedy.
    pure subroutine accuracy_warning(pair, zone, step, list)
        class(contact_pair_t), intent(in) :: pair
        type(zone_measure_t), intent(in) :: zone
        integer, intent(in) :: step
        type(warning_t), allocatable, intent(inout) :: list(:)
        character(len=:), allocatable :: what
        integer :: j
        if (.not. zone%estimate > warn_estimate) return
        if (zone%n_points < min_points) then
            what = 'the contact zone is not resolved at step '//str(step)//' ('//str(zone%n_points)// &
                   ' points in contact'
        else
            what = "the mesh resolves the contact zone's edge poorly: estimated pressure error "// &
                   fixed_str(100.0_dp*zone%estimate, 2)//' % at step '//str(step)//' (above '// &
                   fixed_str(100.0_dp*warn_estimate, 1)//' %'
            do j = 1, zone%n_edges
                what = what//'; h/w '//fixed_str(zone%edges(j)%h_tangent/zone%half_width, 3)//' along, '// &
                       fixed_str(zone%edges(j)%h_normal/zone%half_width, 3)//' across at xi = '// &
                       fixed_str(zone%edges(j)%xi, 4)
            end do
        end if
        what = what//', '//fixed_str(zone%elements_across, 1)//' slave elements across): '
        if (pair%slave%npar == 1) then
            what = what//'refine the zone (python -m pre refine RESULT.h5; docs/contact-accuracy.md)'
        else
            what = what//"refine the slave face's cells around the zone's edge (knots_xi, knots_eta; a grid whose "// &
                   'knot lines follow the edge: docs/hertz3d.md)'
        end if
        list = [list, warning_t(pair_label(pair)//what, topic=pair_label(pair)//'an unresolved contact zone edge')]
    end subroutine accuracy_warning

    !> A pair whose penalty smears a zone's edges over more than the elements that hold
    !> them (`penalty_smeared`): the edge error estimate then holds that smearing, which
    !> refinement does not remove.
    pure subroutine smearing_warning(pair, zone, step, list)
        class(contact_pair_t), intent(in) :: pair
        type(zone_measure_t), intent(in) :: zone
        integer, intent(in) :: step
        type(warning_t), allocatable, intent(inout) :: list(:)
        list = [list, warning_t(pair_label(pair)//'penalty_normal = '//trim(short_str(pair%law%eps_n))// &
                                " smears the contact zone's edges over E*/penalty_normal = "// &
                                trim(short_str(zone%penalty_length))//' ('// &
                                fixed_str(zone%penalty_length/zone%half_width, 2)//" of the zone's half-width) "// &
                                'from step '//str(step)//', more than the elements that hold them: the edge error '// &
                                'estimate includes that smearing, which refining does not remove; a stiffer '// &
                                "penalty_normal (or none: voiga's automatic one) does (docs/contact-accuracy.md)", &
                                topic=pair_label(pair)//'a penalty that smears the contact zone')]
    end subroutine smearing_warning

end module voiga_model_checks
