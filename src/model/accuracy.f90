!> How well the mesh resolves the edges of a contact zone: the indicator of
!> docs/contact-accuracy.md, per contact pair and converged step, for the result file
!> (`voiga_io_output_results`), the console's step line and the warning at the end of a
!> run (`voiga_model_checks`). `post/indicator.py` computes the same from a result file
!> (and reads these values when the file has them; a test compares the two).
!>
!> A zone is a run of slave points in contact with positive pressure, in slave-parameter
!> order, measured on the slave's contact edge in the reference configuration: the slave
!> elements it covers, and at each free edge (a zone reaching the first or last slave
!> point ends at a symmetry cut or at the end of the edge, not at a free edge) the slave
!> element's length and the surface row's thickness relative to the zone's half-width w,
!> and an estimate of the relative L2 pressure error made there: near a free edge p^2 is
!> smooth in the distance d into the zone (Hertz: exactly quadratic), so a least-squares
!> fit of p^2 = c0 + c1 d + c2 d^2 to the points the mesh resolves (d between one edge
!> element and `fit_band` w) continued to its root is the reference of the two edge
!> elements; the L2 difference of the computed pressure from it there, relative to the
!> zone's L2 norm and times `calibration`, is the estimate (docs/theory.md derives its
!> order, docs/contact-accuracy.md calibrates it).
!>
!> On a solid's face the zone's boundary is a curve, not two points: every line of slave
!> points (constant eta, constant xi) is measured as an edge is, with the points' areas
!> as the integration weights, and the face's estimate sums the lines of each direction
!> (`face_summary`). A flat punch's corner, where the pressure rises instead of
!> vanishing, is not estimated (`edge_measure_t%vanishing`).
module voiga_model_accuracy
    use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_positive_inf, ieee_quiet_nan, ieee_is_finite
    use voiga_kinds, only: dp
    use voiga_contact_pair, only: contact_pair_t
    use voiga_contact_law, only: state_inactive
    use voiga_discretization_patch, only: discretization_t
    use voiga_nurbs_patch, only: patch_eval
    use voiga_model, only: model_t, plane_modulus
    use voiga_model_accuracy_fit, only: fit_band, edge_residual, edge_position, stable_order, trapezoid, &
                                        interpolate, covered
    implicit none
    private

    public :: edge_measure_t, zone_measure_t, measure_zones, pair_zones, worst_of_pair, pair_summary, face_summary, &
              penalty_smeared
    public :: fit_band, calibration, warn_estimate, min_points

    !> Scales the raw estimate to the measured L2 error at the edges.
    real(dp), parameter :: calibration = 0.65_dp
    !> A pair whose estimated edge error exceeds this (0.5 %) is warned about.
    real(dp), parameter :: warn_estimate = 0.005_dp
    !> Fewer points in contact than this: the zone is not resolved at all.
    integer, parameter :: min_points = 3

    !> One free edge of a zone.
    type :: edge_measure_t
        !> Slave parameter of the edge: the fit's root when it lies between the last
        !> point in contact and the first one out, else midway between them.
        real(dp) :: xi = 0.0_dp
        !> +1: the zone lies at smaller xi (the edge is its upper end); -1: larger.
        integer :: side = 0
        !> Reference length of the slave element holding the edge, and thickness of the
        !> surface element row there.
        real(dp) :: h_tangent = 0.0_dp, h_normal = 0.0_dp
        !> The uncalibrated estimate, and the reference distance between the points
        !> that bracket the edge.
        real(dp) :: raw = 0.0_dp, bracket = 0.0_dp
        !> Does the pressure vanish towards the edge (less on average in the edge element
        !> than over the fitted points)? Where it does not (a punch's corner, a
        !> conforming edge: p rises towards the edge, or is singular there) the
        !> square-root model does not hold and the edge is not estimated (raw = 0).
        logical :: vanishing = .true.
    end type edge_measure_t

    !> One zone of a pair at a step: on an edge a run of points in contact; on a face
    !> such a run along one line of slave points (constant eta: `direction` 1, or
    !> constant xi: 2, at the parameter `line`), measured along the line.
    type :: zone_measure_t
        integer :: direction = 1
        real(dp) :: line = 0.0_dp
        !> Slave parameters (along the line) of its first and last points in contact.
        real(dp) :: xi_range(2) = 0.0_dp
        !> w (half the length between two free edges, the whole from a cut to one).
        real(dp) :: half_width = 0.0_dp
        !> Slave elements covered (partly covered ones by their fraction).
        real(dp) :: elements_across = 0.0_dp
        integer :: n_points = 0, n_edges = 0
        type(edge_measure_t) :: edges(2)
        !> The squared L2 norm of its pressure (reference; on a face the sum of p^2 times
        !> the area its points integrate): what a face's estimate sums the lines with.
        real(dp) :: norm = 0.0_dp
        !> Estimated relative L2 pressure error made at its edges: on a line the root of
        !> the sum of its edges' squares (infinite for fewer than `min_points` points); a
        !> face's summary holds the face's (`face_summary`).
        real(dp) :: estimate = 0.0_dp
        !> The pair's E* / penalty_normal: the length over which the penalty's compliance
        !> smears a free edge (0 for ALM, which enforces the contact exactly).
        real(dp) :: penalty_length = 0.0_dp
    end type zone_measure_t

    !> Slave points along one line (an edge: all of them) in parameter order: parameter
    !> along the line, reference arc length, nominal pressure, reference positions; the
    !> line's direction and parameters (`at`: the other one's value on a face).
    type :: profile_t
        real(dp), allocatable :: xi(:), s(:), p(:), x0(:, :)
        logical, allocatable :: on(:)
        integer :: direction = 1
        real(dp) :: at(2) = 0.0_dp
        !> On a face, the reference area each point integrates (its integrals are the
        !> points' sums, so that the lines of one direction add up to the face's).
        real(dp), allocatable :: area(:)
    end type profile_t

contains

    !> The zones of pair `k` of `model` as it was last evaluated.
    pure function pair_zones(model, k) result(zones)
        type(model_t), intent(in) :: model
        integer, intent(in) :: k
        type(zone_measure_t), allocatable :: zones(:)
        associate (pair => model%pairs(k)%pair)
            call measure_zones(pair, model%bodies(pair%slave_body)%disc, zones)
            if (pair%method_name() /= 'alm') &
                zones%penalty_length = plane_modulus(model, pair%slave_body, pair%master_body)/pair%law%eps_n
        end associate
    end function pair_zones

    !> Does the penalty smear an edge of `zone` over more than the element holding it?
    !> Under a pressure p the penalty eps lets the bodies overlap by p / eps, the bodies
    !> deflect by about p l / E* over a length l: the two match at l = E* / eps, so an
    !> edge resolved finer than that is the penalty's profile, which refinement does not
    !> change (the automatic penalty's length is a tenth of an element / degree).
    pure logical function penalty_smeared(zone)
        type(zone_measure_t), intent(in) :: zone
        penalty_smeared = any(zone%penalty_length > zone%edges(1:zone%n_edges)%h_tangent)
    end function penalty_smeared

    !> What pair `k` of `model` reports (`pair_summary` of its zones); `found` is false
    !> when the pair has no zone (out of contact).
    pure subroutine worst_of_pair(model, k, zone, found)
        type(model_t), intent(in) :: model
        integer, intent(in) :: k
        type(zone_measure_t), intent(out) :: zone
        logical, intent(out) :: found
        type(zone_measure_t), allocatable :: zones(:)
        zones = pair_zones(model, k)
        found = size(zones) > 0
        if (found) zone = pair_summary(zones, model%pairs(k)%pair%slave%npar == 2)
    end subroutine worst_of_pair

    !> What a pair's `zones` (at least one) report: on an edge the zone with the largest
    !> estimate, on a `face` the face's summary (`face_summary`).
    pure function pair_summary(zones, face) result(zone)
        type(zone_measure_t), intent(in) :: zones(:)
        logical, intent(in) :: face
        type(zone_measure_t) :: zone
        integer :: i, worst
        if (face) then
            zone = face_summary(zones)
            return
        end if
        worst = 1
        do i = 2, size(zones)
            if (zones(i)%estimate > zones(worst)%estimate) worst = i
        end do
        zone = zones(worst)
    end function pair_summary

    !> A face's zones (along the lines of both directions) as one: its points in
    !> contact, the most elements and the largest half-width across along a line, and
    !> the estimate: per direction, calibration x sqrt(sum of raw^2 norm / sum of norm)
    !> over its lines' zones (the squared L2 error at the edges and norm over the face,
    !> as every point lies on one line of each direction), the larger of the two (lines that graze the
    !> edge see none of it: a polar grid's circles); a line's zone of fewer than
    !> `min_points` points counts in the norm only; infinite when no zone has as many.
    pure function face_summary(zones) result(face)
        type(zone_measure_t), intent(in) :: zones(:)
        type(zone_measure_t) :: face
        real(dp) :: error, norm
        integer :: d, i
        face%direction = 0
        face%n_points = sum(zones%n_points, zones%direction == 1)
        face%elements_across = maxval(zones%elements_across)
        face%half_width = maxval(zones%half_width)
        face%penalty_length = zones(1)%penalty_length
        face%estimate = ieee_value(1.0_dp, ieee_positive_inf)
        if (all(zones%n_points < min_points)) return
        face%estimate = 0.0_dp
        do d = 1, 2
            error = 0.0_dp
            norm = 0.0_dp
            do i = 1, size(zones)
                if (zones(i)%direction /= d) cycle
                norm = norm + zones(i)%norm
                if (zones(i)%n_points < min_points) cycle
                error = error + sum(zones(i)%edges(1:zones(i)%n_edges)%raw**2)*zones(i)%norm
            end do
            if (norm > 0.0_dp) face%estimate = max(face%estimate, calibration*sqrt(error/norm))
        end do
    end function face_summary

    !> The zones of `pair` as it was last evaluated, on the slave discretization
    !> `disc`: along an edge, or along every line of slave points of a face in both
    !> directions.
    pure subroutine measure_zones(pair, disc, zones)
        class(contact_pair_t), intent(in) :: pair
        type(discretization_t), intent(in) :: disc
        type(zone_measure_t), allocatable, intent(out) :: zones(:)
        real(dp), allocatable :: other(:)
        logical, allocatable :: done(:)
        integer :: n, i, d
        integer, allocatable :: every(:)
        allocate (zones(0))
        n = size(pair%out)
        if (n == 0) return
        every = [(i, i=1, n)]
        if (pair%slave%npar == 1) then
            zones = line_zones(profile(pair, every, 1), disc)
            return
        end if
        do d = 1, 2
            ! the lines of direction d: the points sharing the other parameter
            other = pair%eta
            if (d == 2) other = pair%xi
            allocate (done(n), source=.false.)
            do i = 1, n
                if (done(i)) cycle
                done = done .or. other == other(i)
                zones = [zones, line_zones(profile(pair, pack(every, other == other(i)), d), disc)]
            end do
            deallocate (done)
        end do
    end subroutine measure_zones

    !> The zones (runs of points in contact) along the line `prof`.
    pure function line_zones(prof, disc) result(zones)
        type(profile_t), intent(in) :: prof
        type(discretization_t), intent(in) :: disc
        type(zone_measure_t), allocatable :: zones(:)
        real(dp), allocatable :: breaks(:)
        integer :: n, i, i0
        allocate (zones(0))
        breaks = element_breaks(disc, prof%direction)
        n = size(prof%xi)
        i = 1
        do while (i <= n)
            if (.not. prof%on(i)) then
                i = i + 1
                cycle
            end if
            i0 = i
            do while (i < n)
                if (.not. prof%on(i + 1)) exit
                i = i + 1
            end do
            zones = [zones, measure_zone(prof, disc, breaks, i0, i)]
            i = i + 1
        end do
    end function line_zones

    !> The slave points `ids` of `pair` along their line of direction `d` (an edge's:
    !> 1), in parameter order (stable).
    pure function profile(pair, ids, d) result(prof)
        class(contact_pair_t), intent(in) :: pair
        integer, intent(in) :: ids(:), d
        type(profile_t) :: prof
        integer, allocatable :: perm(:), order(:)
        integer :: n, i
        n = size(ids)
        if (d == 1) prof%xi = pair%xi(ids)
        if (d == 2) prof%xi = pair%eta(ids)
        perm = stable_order(prof%xi)
        order = ids(perm)
        prof%xi = prof%xi(perm)
        prof%direction = d
        prof%at(1) = pair%xi(ids(1))
        if (allocated(pair%eta)) prof%at(2) = pair%eta(ids(1))
        prof%p = pair%out(order)%pn0
        prof%x0 = reshape([(pair%out(order(i))%x0, i=1, n)], [3, n])
        prof%on = pair%out(order)%state /= state_inactive .and. prof%p > 0.0_dp
        allocate (prof%s(n))
        prof%s(1) = 0.0_dp
        do i = 2, n
            prof%s(i) = prof%s(i - 1) + norm2(prof%x0(:, i) - prof%x0(:, i - 1))
        end do
        if (pair%slave%npar == 2) prof%area = pair%out(order)%area0
    end function profile

    !> The element boundaries of `disc` in parametric direction `d` (its elements come
    !> in the patch's order, direction 1 fastest: the first element of each row).
    pure function element_breaks(disc, d) result(b)
        type(discretization_t), intent(in) :: disc
        integer, intent(in) :: d
        real(dp), allocatable :: b(:)
        integer :: stride, k
        stride = product(disc%nels(1:d - 1))
        b = [(disc%elements(1 + k*stride)%lo(d), k=0, disc%nels(d) - 1), &
             disc%elements(1 + (disc%nels(d) - 1)*stride)%hi(d)]
    end function element_breaks

    !> The zone of points i0..i1 of `prof`.
    pure function measure_zone(prof, disc, breaks, i0, i1) result(zone)
        type(profile_t), intent(in) :: prof
        type(discretization_t), intent(in) :: disc
        real(dp), intent(in) :: breaks(:)
        integer, intent(in) :: i0, i1
        type(zone_measure_t) :: zone
        real(dp) :: s_lo, s_hi, xi_lo, xi_hi, w, norm
        integer :: n, lo, hi
        n = size(prof%xi)
        s_lo = prof%s(1)
        s_hi = prof%s(n)
        xi_lo = breaks(1)
        xi_hi = breaks(size(breaks))
        if (i0 > 1) then
            s_lo = 0.5_dp*(prof%s(i0) + prof%s(i0 - 1))
            xi_lo = 0.5_dp*(prof%xi(i0) + prof%xi(i0 - 1))
        end if
        if (i1 < n) then
            s_hi = 0.5_dp*(prof%s(i1) + prof%s(i1 + 1))
            xi_hi = 0.5_dp*(prof%xi(i1) + prof%xi(i1 + 1))
        end if
        w = s_hi - s_lo
        if (i0 > 1 .and. i1 < n) w = 0.5_dp*w
        lo = max(i0 - 1, 1)
        hi = min(i1 + 1, n)
        if (allocated(prof%area)) then
            norm = sum(prof%p(lo:hi)**2*prof%area(lo:hi))
        else
            norm = trapezoid(prof%p(lo:hi)**2, prof%s(lo:hi))
        end if
        zone%direction = prof%direction
        zone%line = prof%at(3 - prof%direction)
        zone%xi_range = [prof%xi(i0), prof%xi(i1)]
        zone%half_width = w
        zone%elements_across = covered(breaks, xi_lo, xi_hi)
        zone%n_points = i1 - i0 + 1
        zone%norm = norm
        if (i0 > 1) call add_edge(zone, measure_edge(prof, disc, breaks, [i0, i1], i0, -1, w, norm))
        if (i1 < n) call add_edge(zone, measure_edge(prof, disc, breaks, [i0, i1], i1, +1, w, norm))
        zone%estimate = ieee_value(1.0_dp, ieee_positive_inf)
        if (zone%n_points >= min_points) zone%estimate = calibration*sqrt(sum(zone%edges(1:zone%n_edges)%raw**2))
    end function measure_zone

    pure subroutine add_edge(zone, edge)
        type(zone_measure_t), intent(inout) :: zone
        type(edge_measure_t), intent(in) :: edge
        zone%n_edges = zone%n_edges + 1
        zone%edges(zone%n_edges) = edge
    end subroutine add_edge

    !> The free edge of the zone `zone` (first, last point) after its point `i`
    !> (`side` +1: its upper end, -1: its lower end); `w` its half-width, `norm` its
    !> squared L2 norm.
    pure function measure_edge(prof, disc, breaks, zone, i, side, w, norm) result(edge)
        type(profile_t), intent(in) :: prof
        type(discretization_t), intent(in) :: disc
        real(dp), intent(in) :: breaks(:), w, norm
        integer, intent(in) :: zone(2), i, side
        type(edge_measure_t) :: edge
        real(dp), allocatable :: d(:)
        logical, allocatable :: mask(:)
        real(dp) :: se, h, residual, root
        integer :: j
        j = i + side
        edge%xi = 0.5_dp*(prof%xi(i) + prof%xi(j))
        se = 0.5_dp*(prof%s(i) + prof%s(j))
        h = element_size(prof, breaks, edge%xi)
        d = side*(se - prof%s)
        ! the zone's points, and those out of contact within two elements of the edge
        allocate (mask(size(d)), source=.false.)
        mask(zone(1):zone(2)) = .true.
        mask = mask .or. (d < 0.0_dp .and. d > -2.0_dp*h)
        if (allocated(prof%area)) then
            call edge_residual(pack(d, mask), pack(prof%p, mask), h, fit_band*w, residual, root, edge%vanishing, &
                               pack(prof%area, mask))
        else
            call edge_residual(pack(d, mask), pack(prof%p, mask), h, fit_band*w, residual, root, edge%vanishing)
        end if
        edge%bracket = abs(prof%s(j) - prof%s(i))
        root = edge_position(pack(d, mask), pack(prof%p, mask), h, fit_band*w)
        if (abs(root) <= edge%bracket) edge%xi = interpolate(se - side*root, prof%s, prof%xi)
        edge%side = side
        edge%h_tangent = h
        edge%h_normal = normal_size(disc, prof, edge%xi)
        edge%raw = ieee_value(1.0_dp, ieee_positive_inf)
        if (norm > 0.0_dp .and. ieee_is_finite(residual)) edge%raw = sqrt(residual/norm)
        if (.not. edge%vanishing) edge%raw = 0.0_dp
    end function measure_edge

    !> Reference length of the slave element holding parameter `xi`: the polyline
    !> through its points, scaled from their parameter range to the element's (NaN
    !> with fewer than two points in it).
    pure real(dp) function element_size(prof, breaks, xi) result(h)
        type(profile_t), intent(in) :: prof
        real(dp), intent(in) :: breaks(:), xi
        real(dp) :: a, b, length
        integer :: k, first, last, i
        k = size(breaks) - 1
        do i = 1, size(breaks) - 1
            if (breaks(i + 1) > xi) then
                k = i
                exit
            end if
        end do
        a = breaks(k)
        b = breaks(k + 1)
        h = ieee_value(1.0_dp, ieee_quiet_nan)
        first = 0
        last = 0
        length = 0.0_dp
        do i = 1, size(prof%xi)
            if (prof%xi(i) < a .or. prof%xi(i) > b) cycle
            if (first == 0) first = i
            if (last > 0) length = length + norm2(prof%x0(:, i) - prof%x0(:, last))
            last = i
        end do
        if (first == 0 .or. last == first) return
        if (prof%xi(last) > prof%xi(first)) h = length*(b - a)/(prof%xi(last) - prof%xi(first))
    end function element_size

    !> Reference distance across the surface element row at the parameter `xi` along
    !> the line `prof`: from the contact boundary (the last parameter = 1) to the row's
    !> inner boundary.
    pure real(dp) function normal_size(disc, prof, xi) result(hn)
        type(discretization_t), intent(in) :: disc
        type(profile_t), intent(in) :: prof
        real(dp), intent(in) :: xi
        real(dp), allocatable :: across(:)
        real(dp) :: u(disc%pdim), x1(disc%bulk%nsd), x2(disc%bulk%nsd)
        across = element_breaks(disc, disc%pdim)
        u(1:disc%pdim - 1) = prof%at(1:disc%pdim - 1)
        u(prof%direction) = xi
        u(disc%pdim) = 1.0_dp
        call patch_eval(disc%bulk, u, x1)
        u(disc%pdim) = 0.0_dp
        if (size(across) > 1) u(disc%pdim) = across(size(across) - 1)
        call patch_eval(disc%bulk, u, x2)
        hn = norm2(x1 - x2)
    end function normal_size

end module voiga_model_accuracy
