!> A deformable master: another body's contact edge, a NURBS curve (the VO layer
!> when the body has one). Closest-point projection by a local Newton iteration
!> started from the nearest sampled point and bracketed per knot span, so that it
!> is correct across C0 knots and at the ends of the curve.
!>
!> Search: `prepare(u)` samples every knot span once per configuration and boxes
!> each span's control points (a NURBS span with positive weights lies in the
!> convex hull of its control points); a projection then only looks at the
!> samples of spans whose box is closer than the nearest sample found so far.
module voiga_contact_master_nurbs
    use voiga_kinds, only: dp
    use voiga_discretization_patch, only: discretization_t
    use voiga_discretization_element, only: element_basis, element_nfun
    use voiga_contact_master, only: contact_master_t, master_point_t
    use voiga_contact_surface, only: contact_surface_t, new_contact_surface, surface_point_t, &
                                     surface_point, surface_basis, surface_point_at
    implicit none
    private

    public :: nurbs_master_t, new_nurbs_master, outward_sign
    !> The search and projection on the curve, for extensions with another
    !> displacement vector (a rigid curve's, `voiga_contact_master_curve`).
    public :: nurbs_prepare, nurbs_project

    !> Newton iterations of the projection.
    integer, parameter :: max_newton = 50

    !> A body's contact edge acting as master.
    type, extends(contact_master_t) :: nurbs_master_t
        type(contact_surface_t) :: surf
        !> Outward normal = sign * (a_y, -a_x)/|a|, fixed by the patch orientation.
        real(dp) :: sign = 1.0_dp
        !> Search structure of the configuration of the last `prepare`: sample
        !> points [2, n_samples, nspan] (the first and last at the span's ends),
        !> control-point boxes [xmin, ymin, xmax, ymax] [4, nspan], and the first and
        !> second derivatives at each span's ends [4 (a, a2), 2 (start, end), nspan].
        real(dp), allocatable :: samples(:, :, :), boxes(:, :), ends(:, :, :)
        !> The curve's functions at the sample parameters (values, first and second
        !> derivatives) [p + 1, 3, n_samples, nspan]: they do not depend on the
        !> configuration, so `prepare` computes them once.
        real(dp), allocatable :: sample_basis(:, :, :, :)
    contains
        procedure :: project => nurbs_project
        procedure :: all_dofs => nurbs_all_dofs
        procedure :: prepare => nurbs_prepare
    end type nurbs_master_t

contains

    !> The sign s such that s (a_y, -a_x) points out of the body at its eta = 1 edge
    !> (from dX/deta there, in the reference configuration).
    function outward_sign(disc) result(s)
        type(discretization_t), intent(in) :: disc
        real(dp) :: s
        real(dp), allocatable :: r(:), dr(:, :), d2r(:, :)
        real(dp) :: jac(2, 2)
        integer :: e, n
        e = disc%nel - disc%nels(1)/2
        n = element_nfun(disc, e)
        allocate (r(n), dr(2, n), d2r(3, n))
        associate (el => disc%elements(e))
            call element_basis(disc, e, [0.5_dp*(el%lo(1) + el%hi(1)), el%hi(2)], r, dr, d2r)
            jac = matmul(disc%x(:, el%conn), transpose(dr))
        end associate
        ! dX/deta points outward at eta = 1
        s = merge(1.0_dp, -1.0_dp, jac(2, 1)*jac(1, 2) - jac(1, 1)*jac(2, 2) > 0.0_dp)
    end function outward_sign

    !> The contact edge of `disc` (DOFs after `dof0`) as a master.
    subroutine new_nurbs_master(self, disc, dof0)
        type(nurbs_master_t), intent(out) :: self
        type(discretization_t), intent(in) :: disc
        integer, intent(in) :: dof0
        self%deformable = .true.
        call new_contact_surface(self%surf, disc, dof0)
        self%sign = outward_sign(disc)
    end subroutine new_nurbs_master

    !> Samples per knot span (2p + 3, ends included).
    pure integer function n_samples(self)
        class(nurbs_master_t), intent(in) :: self
        n_samples = 2*self%surf%degree + 3
    end function n_samples

    !> Sample every span and box its control points in the configuration `u`;
    !> `project` must be called with the same `u`.
    pure subroutine nurbs_prepare(self, u)
        class(nurbs_master_t), intent(inout) :: self
        real(dp), intent(in) :: u(:)
        type(surface_point_t) :: pt
        real(dp) :: xc(2, self%surf%degree + 1)
        integer :: nspan, m, k, j, s, p

        associate (br => self%surf%breaks, surf => self%surf)
            nspan = size(br) - 1
            m = n_samples(self)
            p = surf%degree
            if (.not. allocated(self%samples)) then
                allocate (self%samples(2, m, nspan), self%boxes(4, nspan), self%ends(4, 2, nspan))
                allocate (self%sample_basis(p + 1, 3, m, nspan))
                do k = 1, nspan
                    do j = 0, m - 1
                        call surface_basis(surf, sample_xi(k, j), surf%spans(k), self%sample_basis(:, 1, j + 1, k), &
                                           self%sample_basis(:, 2, j + 1, k), self%sample_basis(:, 3, j + 1, k), s)
                    end do
                end do
            end if
            do k = 1, nspan
                do j = 0, m - 1
                    call surface_point_at(surf, u, sample_xi(k, j), surf%spans(k), self%sample_basis(:, 1, j + 1, k), &
                                          self%sample_basis(:, 2, j + 1, k), self%sample_basis(:, 3, j + 1, k), pt)
                    self%samples(:, j + 1, k) = pt%x(1:2)
                    if (j == 0) self%ends(:, 1, k) = [pt%a(1:2), pt%a2(1:2)]
                    if (j == m - 1) self%ends(:, 2, k) = [pt%a(1:2), pt%a2(1:2)]
                end do
                s = surf%spans(k)
                xc(1, :) = surf%x0(1, s - p:s) + u(surf%dofs(1, s - p:s))
                xc(2, :) = surf%x0(2, s - p:s) + u(surf%dofs(2, s - p:s))
                self%boxes(1:2, k) = minval(xc, dim=2)
                self%boxes(3:4, k) = maxval(xc, dim=2)
            end do
        end associate
    contains
        !> Sample j (0 .. m - 1) of span k; the last one is the span's end exactly
        !> (`project` reuses the evaluations there).
        pure real(dp) function sample_xi(k, j) result(xi)
            integer, intent(in) :: k, j
            associate (br => self%surf%breaks)
                xi = br(k) + (br(k + 1) - br(k))*real(j, dp)/real(m - 1, dp)
                if (j == m - 1) xi = br(k + 1)
            end associate
        end function sample_xi
    end subroutine nurbs_prepare

    !> Squared distance from `x` to the box [xmin, ymin, xmax, ymax] (0 inside).
    pure real(dp) function box_distance2(box, x)
        real(dp), intent(in) :: box(4), x(2)
        box_distance2 = max(box(1) - x(1), 0.0_dp, x(1) - box(3))**2 + max(box(2) - x(2), 0.0_dp, x(2) - box(4))**2
    end function box_distance2

    pure function nurbs_all_dofs(self) result(dofs)
        class(nurbs_master_t), intent(in) :: self
        integer, allocatable :: dofs(:)
        dofs = reshape(self%surf%dofs, [size(self%surf%dofs)])
    end function nurbs_all_dofs

    !> The closest point of the curve to `xs` (see the module comment); `start`,
    !> the last projection of the same slave point, starts the Newton iteration in
    !> the nearest sample's span when it lies there within a sample spacing of that
    !> sample (between Newton iterations of a step it is off by the iteration's
    !> increment, against a sample spacing of 1/(2p + 2) of a span).
    pure subroutine nurbs_project(self, u, xs, mp, found, converged, start)
        class(nurbs_master_t), intent(in) :: self
        !> The slave point [2].
        real(dp), intent(in) :: u(:), xs(:)
        type(master_point_t), intent(out) :: mp
        logical, intent(out) :: found, converged
        real(dp), intent(in), optional :: start(:)
        ! two evaluation buffers: the current one (cur) and the best so far (ib), whose
        ! roles swap instead of copying a point (and its arrays) on every improvement
        type(surface_point_t) :: pts(2)
        real(dp) :: d, best_d, best, f, tol, end_xi, xi0
        real(dp) :: lb(size(self%surf%breaks) - 1)
        integer :: nspan, k, j, m, best_span, s0, k0, i, cur, ib
        logical :: ok, best_ok, at_end
        real(dp) :: xq(2)

        xq = xs(1:2)
        associate (br => self%surf%breaks)
            nspan = size(br) - 1
            ! 1. nearest sample (2p + 3 points per span), visiting the span whose box
            !    is nearest first and skipping spans whose box is farther than the
            !    nearest sample so far
            !    (squared distances: the same order without square roots)
            m = n_samples(self)
            do k = 1, nspan
                lb(k) = box_distance2(self%boxes(:, k), xq)
            end do
            best_d = huge(1.0_dp)
            best = br(1)
            s0 = 1
            k0 = minloc(lb, dim=1)
            do i = 0, nspan - 1
                k = modulo(k0 - 1 + i, nspan) + 1
                if (lb(k) >= best_d) cycle
                do j = 1, m
                    d = (xq(1) - self%samples(1, j, k))**2 + (xq(2) - self%samples(2, j, k))**2
                    if (d < best_d) then
                        best_d = d
                        best = br(k) + (br(k + 1) - br(k))*real(j - 1, dp)/real(m - 1, dp)
                        s0 = k
                    end if
                end do
            end do
            ! 2. Newton in the sample's span and its neighbours, clamped to each span
            best_d = huge(1.0_dp)
            best_ok = .false.
            best_span = 0
            converged = .true.
            cur = 1
            ib = 0
            at_end = .false.
            do k = max(1, s0 - 1), min(nspan, s0 + 1)
                ! a neighbour span whose Newton would stop at its first point, the end
                ! it shares with the sample's span: that point is known from `prepare`
                ok = .false.
                if (k /= s0) call settles_at_end(self, xq, k, best, ok, j)
                if (ok) then
                    d = norm2(xq - self%samples(:, j, k))
                    if (d < best_d) then
                        best_d = d
                        best_span = k
                        best_ok = .true.
                        at_end = .true.
                        end_xi = br(k + (j - 1)/(m - 1))
                    end if
                    cycle
                end if
                xi0 = best
                if (k == s0 .and. present(start)) then
                    if (abs(start(1) - best) <= (br(k + 1) - br(k))/real(m - 1, dp) .and. &
                        start(1) >= br(k) .and. start(1) <= br(k + 1)) xi0 = start(1)
                end if
                call span_newton(self%surf, u, xq, k, xi0, pts(cur), ok)
                if (.not. ok) converged = .false.
                d = norm2(xq - pts(cur)%x(1:2))
                if (d < best_d) then
                    best_d = d
                    ib = cur
                    cur = 3 - cur
                    best_span = k
                    best_ok = ok
                    at_end = .false.
                end if
            end do
            ! the closest is a span's end not evaluated here: the same evaluation as in
            ! `span_newton` (its first)
            if (at_end) then
                ib = cur
                call surface_point(self%surf, u, end_xi, pts(ib), self%surf%spans(best_span))
            end if
            ! no distance compared (not a number): the last evaluation, not found
            if (ib == 0) ib = cur
            if (.not. best_ok) converged = .false.
            associate (best_pt => pts(ib))
                ! 3. beyond the curve's ends: no orthogonal projection
                found = best_span > 0
                f = dot_product(xq - best_pt%x(1:2), best_pt%a(1:2))
                tol = 1.0e-12_dp*norm2(best_pt%a(1:2))*max(best_d, 1.0_dp)
                if (best_pt%xi <= br(1) .and. f < -tol) found = .false.
                if (best_pt%xi >= br(nspan + 1) .and. f > tol) found = .false.
                mp%xi = best_pt%xi
                mp%x = best_pt%x
                mp%a = best_pt%a
                mp%a2 = best_pt%a2
                mp%n = self%sign*[best_pt%a(2), -best_pt%a(1), 0.0_dp]/norm2(best_pt%a(1:2))
                mp%r = best_pt%r
                mp%dr = best_pt%dr
                mp%dofs = best_pt%dofs
                mp%first = minval(best_pt%local)
                mp%last = maxval(best_pt%local)
            end associate
        end associate
    end subroutine nurbs_project

    !> Whether `span_newton` in span `k` from `start` would stop at its first point,
    !> a span end (the one nearest `start`), with the numbers `prepare` kept there:
    !> the same test on the same values. `j`: that end's sample (1 or n_samples).
    pure subroutine settles_at_end(self, xs, k, start, settles, j)
        class(nurbs_master_t), intent(in) :: self
        real(dp), intent(in) :: xs(2), start
        integer, intent(in) :: k
        logical, intent(out) :: settles
        integer, intent(out) :: j
        real(dp) :: xi, a, b, f, df, step, x(2), t(2), t2(2)
        integer :: e
        a = self%surf%breaks(k)
        b = self%surf%breaks(k + 1)
        xi = min(max(start, a), b)
        settles = .false.
        j = 0
        if (xi /= a .and. xi /= b) return
        e = merge(1, 2, xi == a)
        j = merge(1, n_samples(self), e == 1)
        x = self%samples(:, j, k)
        t = self%ends(1:2, e, k)
        t2 = self%ends(3:4, e, k)
        f = dot_product(xs - x, t)
        df = -dot_product(t, t) + dot_product(xs - x, t2)
        if (df < 0.0_dp) then
            step = -f/df
        else
            ! the bracket is the whole span at the first point
            step = merge(b - xi, a - xi, f > 0.0_dp)
        end if
        settles = abs(step) <= 1.0e-15_dp*max(1.0_dp, abs(xi))
        settles = settles .or. (xi == a .and. f < 0.0_dp) .or. (xi == b .and. f > 0.0_dp)
    end subroutine settles_at_end

    !> The closest point to `xs` of span `k` of `surf`: Newton on (xs - x).a = 0 from
    !> `start` clamped to the span, kept in a bracket of the minimum (a step leaving
    !> it is replaced by bisection). `pt` is the curve at the result (every exit but
    !> the iteration cap has just evaluated it there: no second evaluation), `ok`
    !> false if `max_newton` iterations did not settle it.
    pure subroutine span_newton(surf, u, xs, k, start, pt, ok)
        type(contact_surface_t), intent(in) :: surf
        real(dp), intent(in) :: u(:), xs(2), start
        integer, intent(in) :: k
        type(surface_point_t), intent(inout) :: pt
        logical, intent(out) :: ok
        real(dp) :: xi, xi_s, a, b, lo, hi, f, df, step
        integer :: it
        a = surf%breaks(k)
        b = surf%breaks(k + 1)
        xi = min(max(start, a), b)
        lo = a
        hi = b
        ok = .false.
        do it = 1, max_newton
            call surface_point(surf, u, xi, pt, surf%spans(k))
            f = dot_product(xs - pt%x(1:2), pt%a(1:2))
            df = -dot_product(pt%a(1:2), pt%a(1:2)) + dot_product(xs - pt%x(1:2), pt%a2(1:2))
            ! keep a bracket of the minimum of the distance: f > 0 -> it lies to the right
            if (f > 0.0_dp) then
                lo = xi
            else if (f < 0.0_dp) then
                hi = xi
            end if
            if (df < 0.0_dp) then
                step = -f/df
            else
                step = merge(hi - xi, lo - xi, f > 0.0_dp)
            end if
            ok = abs(step) <= 1.0e-15_dp*max(1.0_dp, abs(xi))
            ! or the minimum over this span is at its end
            ok = ok .or. (xi == a .and. f < 0.0_dp) .or. (xi == b .and. f > 0.0_dp)
            if (ok) return
            xi_s = min(max(xi + step, a), b)
            ! a Newton step that leaves the bracket is replaced by bisection
            if (xi_s < lo .or. xi_s > hi) xi_s = 0.5_dp*(lo + hi)
            ok = xi_s == xi
            if (ok) return
            xi = xi_s
        end do
        call surface_point(surf, u, xi, pt, surf%spans(k))
    end subroutine span_newton

end module voiga_contact_master_nurbs
