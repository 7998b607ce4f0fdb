!> The numerics of the contact-zone indicator along one line of slave points
!> (`voiga_model_accuracy`): the least-squares fit of p^2 near a free edge, where the
!> fit places the edge, the residual of the pressure from it over the edge elements,
!> and the small quadratures and orderings they use. Everything here takes distances
!> d into the zone from the computed edge (midway between the last point in contact and
!> the first one out), the pressures p there, the edge element's length h and the band
!> `fit_band` w (w the zone's half-width); docs/contact-accuracy.md, steps 1-5.
module voiga_model_accuracy_fit
    use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, ieee_positive_inf, ieee_is_finite
    use voiga_kinds, only: dp
    implicit none
    private

    public :: fit_band, min_band_elements, edge_residual, edge_position, fit_points, quadratic_fit, &
              largest_root_below, stable_order, trapezoid, sorted_trapezoid, interpolate, covered

    !> The fit of p^2 near an edge uses the points within this fraction of the zone's
    !> half-width from the edge (and at least the two elements nearest it).
    real(dp), parameter :: fit_band = 0.5_dp
    !> A band `fit_band` w shorter than this many edge elements (a coarse zone) holds too
    !> few resolved points: the fit takes the zone's points within as many elements.
    real(dp), parameter :: min_band_elements = 3.0_dp

contains

    !> The squared L2 residual over the edge elements (d < 2 h, at most to the zone's
    !> middle) of the pressure `p` at distances `d` into the zone from the least-squares
    !> fit p^2 = c0 + c1 d + c2 d^2 to the points `fit_points` chooses, the fit's edge
    !> (its largest root below the fitted points, 0 (the computed edge) when none),
    !> both NaN with fewer than three points to fit, and whether the pressure vanishes
    !> towards the edge (`vanishing`: the points in contact within the edge element
    !> carry less on average than the fitted ones).
    pure subroutine edge_residual(d, p, h, band, residual, root, vanishing, area)
        real(dp), intent(in) :: d(:), p(:), h, band
        real(dp), intent(out) :: residual, root
        logical, intent(out) :: vanishing
        !> On a face, the area each point integrates: the residual is their sum.
        real(dp), intent(in), optional :: area(:)
        logical :: fit(size(d)), near(size(d))
        real(dp) :: c(3), ref(size(d)), reach
        fit = fit_points(d, p, h, band)
        vanishing = .true.
        if (count(fit) < 3) then
            residual = ieee_value(1.0_dp, ieee_quiet_nan)
            root = residual
            return
        end if
        c = quadratic_fit(pack(d, fit), pack(p, fit)**2)
        ref = sqrt(max(c(1) + c(2)*d + c(3)*d**2, 0.0_dp))
        ! a fit without a root below the zone describes no free edge: the computed one
        root = largest_root_below(c, minval(pack(d, fit)))
        if (.not. ieee_is_finite(root)) root = 0.0_dp
        ! the pressure vanishes towards the edge when the edge element's points carry less
        ! on average than the fitted ones (a punch's corner: a spike there)
        ! (judged where the band resolves the profile: on a coarse zone the edge element's
        ! pressure is the mesh's artefact as often as not)
        near = d >= 0.0_dp .and. d < h .and. p > 0.0_dp
        if (count(near) > 0 .and. band >= min_band_elements*h) &
            vanishing = sum(p, near)/count(near) < sum(p, fit)/count(fit)
        where (d < root) ref = 0.0_dp
        ! the two edge elements, never past the middle of the zone (w = band / fit_band)
        reach = 2.0_dp*h
        if (band/fit_band < reach) reach = band/fit_band
        near = d < reach
        if (present(area)) then
            residual = sum((p - ref)**2*area, near)
        else
            residual = sorted_trapezoid(pack(d, near), pack(p - ref, near)**2)
        end if
    end subroutine edge_residual

    !> Least-squares coefficients c of c1 + c2 t + c3 t^2 ~ y (Householder QR of the
    !> columns scaled to t / max |t|, so that the fit is as well conditioned as it can be).
    pure function quadratic_fit(t, y) result(c)
        real(dp), intent(in) :: t(:), y(:)
        real(dp) :: c(3)
        real(dp) :: a(size(t), 3), b(size(t)), v(size(t)), scale, alpha
        integer :: k, m, j
        m = size(t)
        scale = maxval(abs(t))
        if (scale <= 0.0_dp) scale = 1.0_dp
        a(:, 1) = 1.0_dp
        a(:, 2) = t/scale
        a(:, 3) = (t/scale)**2
        b = y
        do k = 1, 3
            alpha = -sign(norm2(a(k:m, k)), a(k, k))
            v = 0.0_dp
            v(k:m) = a(k:m, k)
            v(k) = v(k) - alpha
            if (norm2(v(k:m)) > 0.0_dp) then
                v(k:m) = v(k:m)/norm2(v(k:m))
                do j = k, 3
                    a(k:m, j) = a(k:m, j) - 2.0_dp*v(k:m)*dot_product(v(k:m), a(k:m, j))
                end do
                b(k:m) = b(k:m) - 2.0_dp*v(k:m)*dot_product(v(k:m), b(k:m))
            end if
        end do
        do k = 3, 1, -1
            c(k) = (b(k) - dot_product(a(k, k + 1:3), c(k + 1:3)))/a(k, k)
        end do
        c = c/[1.0_dp, scale, scale**2]
    end function quadratic_fit

    !> The largest real root of c1 + c2 d + c3 d^2 below `start` (-inf when none).
    pure real(dp) function largest_root_below(c, start) result(root)
        real(dp), intent(in) :: c(3), start
        real(dp) :: disc, q, r(2)
        integer :: k
        root = -ieee_value(1.0_dp, ieee_positive_inf)
        if (c(3) == 0.0_dp) then
            r = -c(1)/c(2)
        else
            disc = c(2)**2 - 4.0_dp*c(3)*c(1)
            if (disc < 0.0_dp) return
            q = -0.5_dp*(c(2) + sign(sqrt(disc), c(2)))
            r(1) = q/c(3)
            r(2) = r(1)
            if (q /= 0.0_dp) r(2) = c(1)/q
        end if
        do k = 1, 2
            if (r(k) < start) root = max(root, r(k))
        end do
    end function largest_root_below

    !> Where the edge is, as a distance into the zone from the computed one: the root
    !> (largest below the fitted points) of the fit of p^2 to the points the mesh
    !> resolves, h <= d <= max(band, 2 h) (fewer than three: all with p > 0), continued
    !> to the edge; -inf without one, NaN with fewer than three points. (Not the
    !> residual's fit on a coarse zone: that one takes the edge element's own points,
    !> which the zone's shape needs but which do not place the edge.)
    pure real(dp) function edge_position(d, p, h, band) result(root)
        real(dp), intent(in) :: d(:), p(:), h, band
        logical :: fit(size(d))
        fit = d >= h .and. d <= max(band, 2.0_dp*h) .and. p > 0.0_dp
        if (count(fit) < 3) fit = p > 0.0_dp
        root = ieee_value(1.0_dp, ieee_quiet_nan)
        if (count(fit) < 3) return
        root = largest_root_below(quadratic_fit(pack(d, fit), pack(p, fit)**2), minval(pack(d, fit)))
    end function edge_position

    !> The points the fit of p^2 near an edge uses: of the zone's (d > 0, p > 0), those
    !> with h <= d <= band when the band holds `min_band_elements` edge elements, else (a
    !> coarse zone) those with d <= `min_band_elements` h, the edge element's too (p^2 is
    !> close to a quadratic across a smooth zone); all of them when fewer than three.
    pure function fit_points(d, p, h, band) result(fit)
        real(dp), intent(in) :: d(:), p(:), h, band
        logical :: fit(size(d)), zone(size(d))
        zone = d > 0.0_dp .and. p > 0.0_dp
        if (band >= min_band_elements*h) then
            fit = zone .and. d >= h .and. d <= band
        else
            fit = zone .and. d <= min_band_elements*h
        end if
        if (count(fit) < 3) fit = zone
    end function fit_points

    !> The trapezoidal integral of `f` over the points `x` taken in ascending order.
    pure real(dp) function sorted_trapezoid(x, f) result(total)
        real(dp), intent(in) :: x(:), f(:)
        integer :: order(size(x))
        order = stable_order(x)
        total = trapezoid(f(order), x(order))
    end function sorted_trapezoid

    !> The permutation that sorts `x` ascending, equal values in their order (insertion:
    !> the slave points come element by element, nearly sorted).
    pure function stable_order(x) result(order)
        real(dp), intent(in) :: x(:)
        integer :: order(size(x))
        integer :: i, j, k
        order = [(i, i=1, size(x))]
        do i = 2, size(x)
            k = order(i)
            j = i - 1
            do while (j >= 1)
                if (x(order(j)) <= x(k)) exit
                order(j + 1) = order(j)
                j = j - 1
            end do
            order(j + 1) = k
        end do
    end function stable_order

    pure real(dp) function trapezoid(f, x) result(total)
        real(dp), intent(in) :: f(:), x(:)
        integer :: n
        n = size(x)
        total = 0.0_dp
        if (n > 1) total = 0.5_dp*sum((f(2:n) + f(1:n - 1))*(x(2:n) - x(1:n - 1)))
    end function trapezoid

    !> Linear interpolation of (xp, fp) at x, xp ascending, constant beyond the ends.
    pure real(dp) function interpolate(x, xp, fp) result(f)
        real(dp), intent(in) :: x, xp(:), fp(:)
        integer :: k
        f = fp(1)
        if (x <= xp(1)) return
        f = fp(size(fp))
        if (x >= xp(size(xp))) return
        do k = 2, size(xp)
            if (xp(k) >= x) exit
        end do
        f = fp(k - 1)
        if (xp(k) > xp(k - 1)) f = fp(k - 1) + (fp(k) - fp(k - 1))*(x - xp(k - 1))/(xp(k) - xp(k - 1))
    end function interpolate

    !> Elements of `breaks` covered by [lo, hi], partly covered ones by their fraction.
    pure real(dp) function covered(breaks, lo, hi) result(n)
        real(dp), intent(in) :: breaks(:), lo, hi
        integer :: k
        n = 0.0_dp
        do k = 1, size(breaks) - 1
            n = n + max(min(breaks(k + 1), hi) - max(breaks(k), lo), 0.0_dp)/(breaks(k + 1) - breaks(k))
        end do
    end function covered

end module voiga_model_accuracy_fit
