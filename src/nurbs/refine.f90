!> Refinement of B-spline curves in homogeneous form (The NURBS Book, ch. 5):
!> knot insertion (Boehm) and degree elevation (algorithm A5.9).
!>
!> Rational curves are refined through their homogeneous control points
!> `pw(:, i) = [w_i x_i, w_i y_i, ..., w_i]`; both operations keep the curve exactly.
!> Every routine here is dimension-agnostic: `pw` has shape [ndim, n].
module voiga_nurbs_refine
    use voiga_kinds, only: dp
    use voiga_nurbs_basis, only: find_span
    implicit none
    private

    public :: insert_knot, insert_knots, elevate_degree, insertion_matrix

contains

    !> Insert the value `u` once into `knots` (degree `p`), updating `pw`.
    !> `u` must lie strictly inside the knot range.
    pure subroutine insert_knot(p, knots, pw, u)
        integer, intent(in) :: p
        !> Knot vector, shape [n+p+1] on entry, [n+p+2] on exit.
        real(dp), allocatable, intent(inout) :: knots(:)
        !> Homogeneous control points, shape [ndim, n] on entry, [ndim, n+1] on exit.
        real(dp), allocatable, intent(inout) :: pw(:, :)
        real(dp), intent(in) :: u
        real(dp), allocatable :: kn(:), qw(:, :)
        real(dp) :: alpha
        integer :: n, k, i

        n = size(pw, 2)
        ! 1-based span: knots(k) <= u < knots(k+1); functions k-p..k nonzero.
        k = find_span(knots, p, u)
        allocate (kn(size(knots) + 1), qw(size(pw, 1), n + 1))
        kn(1:k) = knots(1:k)
        kn(k + 1) = u
        kn(k + 2:) = knots(k + 1:)
        ! In 1-based terms: Q_i = P_i for i <= k-p, Q_i = P_(i-1) for i >= k+1,
        ! blended in between with alpha_i = (u - U_i)/(U_(i+p) - U_i).
        qw(:, 1:k - p) = pw(:, 1:k - p)
        qw(:, k + 1:n + 1) = pw(:, k:n)
        do i = k - p + 1, k
            alpha = (u - knots(i))/(knots(i + p) - knots(i))
            qw(:, i) = alpha*pw(:, i) + (1.0_dp - alpha)*pw(:, i - 1)
        end do
        call move_alloc(kn, knots)
        call move_alloc(qw, pw)
    end subroutine insert_knot

    !> Knot-insertion matrix from the B-splines of degree `p` on `coarse` to those on
    !> `fine` (which must contain `coarse` as a multiset, same end knots):
    !> `B_coarse(k) = sum_i t(i, k) B_fine(i)`, i.e. control points refine as
    !> `P_fine = t P_coarse`. Shape [n_fine, n_coarse]; dense (1D, small).
    pure function insertion_matrix(p, coarse, fine) result(t)
        integer, intent(in) :: p
        real(dp), intent(in) :: coarse(:), fine(:)
        real(dp), allocatable :: t(:, :)
        real(dp), allocatable :: knots(:), pw(:, :), values(:)
        integer :: n, i, j, m

        n = size(coarse) - p - 1
        ! the fine knots not in the coarse vector (multiset difference; both sorted)
        allocate (values(size(fine)))
        m = 0
        j = 1
        do i = 1, size(fine)
            if (j <= size(coarse)) then
                if (coarse(j) == fine(i)) then
                    j = j + 1
                    cycle
                end if
            end if
            m = m + 1
            values(m) = fine(i)
        end do
        ! refine the identity: column k of the result is coarse function k
        allocate (pw(n, n))
        pw = 0.0_dp
        do i = 1, n
            pw(i, i) = 1.0_dp
        end do
        knots = coarse
        call insert_knots(p, knots, pw, values(1:m))
        t = transpose(pw)
    end function insertion_matrix

    !> Insert each value of `values` once (values may repeat to insert several times).
    pure subroutine insert_knots(p, knots, pw, values)
        integer, intent(in) :: p
        real(dp), allocatable, intent(inout) :: knots(:)
        real(dp), allocatable, intent(inout) :: pw(:, :)
        real(dp), intent(in) :: values(:)
        integer :: i
        do i = 1, size(values)
            call insert_knot(p, knots, pw, values(i))
        end do
    end subroutine insert_knots

    !> Raise the degree of a B-spline curve from `p` to `p + t` (A5.9): every
    !> distinct knot gains multiplicity `t`, so the continuity is unchanged.
    !> Segment by segment: knot insertion makes the segment a Bezier curve
    !> (`to_bezier`), its degree is raised (`elevate_bezier`), and the knots inserted
    !> at its left end are removed again (`remove_left_knot`).
    pure subroutine elevate_degree(p, knots, pw, t)
        !> Degree on entry; `p + t` on exit.
        integer, intent(inout) :: p
        !> Knot vector, shape [n+p+1] on entry, longer on exit.
        real(dp), allocatable, intent(inout) :: knots(:)
        !> Homogeneous control points, shape [ndim, n] on entry, [ndim, n_new] on exit.
        real(dp), allocatable, intent(inout) :: pw(:, :)
        integer, intent(in) :: t
        real(dp), allocatable :: uh(:), qw(:, :), bezalfs(:, :), bpts(:, :), ebpts(:, :), &
                                 nextbpts(:, :)
        real(dp) :: ua, ub
        integer :: nd, n, m, ph, i, j, mh, kind, r, a, b, cind, mul, oldr, lbz, rbz, nbreak

        if (t <= 0) return
        nd = size(pw, 1)
        n = size(pw, 2) - 1          ! book's n: last control point index (0-based)
        m = n + p + 1                ! book's m: last knot index
        ph = p + t
        nbreak = 0
        do i = 2, size(knots)
            if (knots(i) > knots(i - 1)) nbreak = nbreak + 1
        end do
        ! Result sizes: each distinct knot gains t copies.
        allocate (uh(0:size(knots) + t*(nbreak + 1) - 1))
        allocate (qw(nd, 0:size(uh) - ph - 2))
        allocate (bezalfs(0:ph, 0:p), bpts(nd, 0:p), ebpts(nd, 0:ph), nextbpts(nd, 0:max(p - 2, 0)))
        call elevation_coefficients(p, t, bezalfs)
        mh = ph
        kind = ph + 1
        r = -1
        a = p
        b = p + 1
        cind = 1
        ua = knots(1)
        qw(:, 0) = pw(:, 1)
        uh(0:ph) = ua
        do i = 0, p
            bpts(:, i) = pw(:, i + 1)
        end do
        do while (b < m)
            i = b
            do while (b < m)
                if (knots(b + 1) /= knots(b + 2)) exit
                b = b + 1
            end do
            mul = b - i + 1
            mh = mh + mul + t
            ub = knots(b + 1)
            oldr = r
            r = p - mul
            if (oldr > 0) then
                lbz = (oldr + 2)/2
            else
                lbz = 1
            end if
            if (r > 0) then
                rbz = ph - (r + 1)/2
            else
                rbz = ph
            end if
            if (r > 0) call to_bezier(p, knots, a, mul, r, ua, ub, bpts, nextbpts)
            call elevate_bezier(p, t, lbz, bezalfs, bpts, ebpts)
            if (oldr > 1) call remove_left_knot(ph, oldr, kind, cind, lbz, ua, ub, uh, qw, ebpts)
            if (a /= p) then
                do i = 0, ph - oldr - 1
                    uh(kind) = ua
                    kind = kind + 1
                end do
            end if
            do j = lbz, rbz
                qw(:, cind) = ebpts(:, j)
                cind = cind + 1
            end do
            if (b < m) then
                do j = 0, r - 1
                    bpts(:, j) = nextbpts(:, j)
                end do
                do j = r, p
                    bpts(:, j) = pw(:, b - p + j + 1)
                end do
                a = b
                b = b + 1
                ua = ub
            else
                do i = 0, ph
                    uh(kind + i) = ub
                end do
            end if
        end do
        p = ph
        knots = uh(0:mh)
        pw = qw(:, 0:mh - ph - 1)
    end subroutine elevate_degree

    !> Coefficients of degree elevation of a Bezier segment from degree `p` to
    !> `p + t`: elevated point i = sum_j bezalfs(i, j) * point j. Shape [0:p+t, 0:p];
    !> the lower half from binomials, the upper half by symmetry.
    pure subroutine elevation_coefficients(p, t, bezalfs)
        integer, intent(in) :: p, t
        real(dp), intent(out) :: bezalfs(0:, 0:)
        real(dp) :: inv
        integer :: ph, i, j, mpi

        ph = p + t
        bezalfs = 0.0_dp
        bezalfs(0, 0) = 1.0_dp
        bezalfs(ph, p) = 1.0_dp
        do i = 1, ph/2
            inv = 1.0_dp/binomial(ph, i)
            mpi = min(p, i)
            do j = max(0, i - t), mpi
                bezalfs(i, j) = inv*binomial(p, j)*binomial(t, i - j)
            end do
        end do
        do i = ph/2 + 1, ph - 1
            mpi = min(p, i)
            do j = max(0, i - t), mpi
                bezalfs(i, j) = bezalfs(ph - i, p - j)
            end do
        end do
    end subroutine elevation_coefficients

    !> Insert the knot `ub` (multiplicity `mul`) `r` times into the segment [ua, ub]
    !> that starts at knot index `a` (book's, 0-based), turning `bpts` into its
    !> Bezier points; `nextbpts` gets the leading points of the next segment.
    pure subroutine to_bezier(p, knots, a, mul, r, ua, ub, bpts, nextbpts)
        integer, intent(in) :: p
        real(dp), intent(in) :: knots(:)
        integer, intent(in) :: a, mul, r
        real(dp), intent(in) :: ua, ub
        !> shape: [ndim, 0:p]
        real(dp), intent(inout) :: bpts(:, 0:)
        !> shape: [ndim, 0:max(p-2, 0)]
        real(dp), intent(inout) :: nextbpts(:, 0:)
        real(dp) :: alfs(0:max(p - 2, 0)), numer
        integer :: j, k, s

        numer = ub - ua
        do k = p, mul + 1, -1
            alfs(k - mul - 1) = numer/(knots(a + k + 1) - ua)
        end do
        do j = 1, r
            s = mul + j
            do k = p, s, -1
                bpts(:, k) = alfs(k - s)*bpts(:, k) + (1.0_dp - alfs(k - s))*bpts(:, k - 1)
            end do
            nextbpts(:, r - j) = bpts(:, p)
        end do
    end subroutine to_bezier

    !> Degree-elevate the Bezier points `bpts` (degree p) into `ebpts(:, lbz:)` (degree
    !> p + t); `ebpts(:, :lbz-1)` is left as it is.
    pure subroutine elevate_bezier(p, t, lbz, bezalfs, bpts, ebpts)
        integer, intent(in) :: p, t, lbz
        !> shape: [0:p+t, 0:p]
        real(dp), intent(in) :: bezalfs(0:, 0:)
        !> shape: [ndim, 0:p]
        real(dp), intent(in) :: bpts(:, 0:)
        !> shape: [ndim, 0:p+t]
        real(dp), intent(inout) :: ebpts(:, 0:)
        integer :: i, j, mpi

        do i = lbz, p + t
            ebpts(:, i) = 0.0_dp
            mpi = min(p, i)
            do j = max(0, i - t), mpi
                ebpts(:, i) = ebpts(:, i) + bezalfs(i, j)*bpts(:, j)
            end do
        end do
    end subroutine elevate_bezier

    !> Remove the knot `ua` `oldr - 1` times, where the last elevated segment (in `qw`,
    !> up to `cind - 1`, and `uh` up to `kind - 1`) meets the new one (`ebpts`).
    pure subroutine remove_left_knot(ph, oldr, kind, cind, lbz, ua, ub, uh, qw, ebpts)
        integer, intent(in) :: ph, oldr, kind, cind, lbz
        real(dp), intent(in) :: ua, ub
        !> The elevated knots so far; shape: [0:mh_final]
        real(dp), intent(in) :: uh(0:)
        !> The elevated control points so far; shape: [ndim, 0:n_final]
        real(dp), intent(inout) :: qw(:, 0:)
        !> shape: [ndim, 0:ph]
        real(dp), intent(inout) :: ebpts(:, 0:)
        real(dp) :: den, bet, alf, gam
        integer :: i, j, kj, tr, first, last

        first = kind - 2
        last = kind
        den = ub - ua
        bet = (ub - uh(kind - 1))/den
        do tr = 1, oldr - 1
            i = first
            j = last
            kj = j - kind + 1
            do while (j - i > tr)
                if (i < cind) then
                    alf = (ub - uh(i))/(ua - uh(i))
                    qw(:, i) = alf*qw(:, i) + (1.0_dp - alf)*qw(:, i - 1)
                end if
                if (j >= lbz) then
                    if (j - tr <= kind - ph + oldr) then
                        gam = (ub - uh(j - tr))/den
                        ebpts(:, kj) = gam*ebpts(:, kj) + (1.0_dp - gam)*ebpts(:, kj + 1)
                    else
                        ebpts(:, kj) = bet*ebpts(:, kj) + (1.0_dp - bet)*ebpts(:, kj + 1)
                    end if
                end if
                i = i + 1
                j = j - 1
                kj = kj - 1
            end do
            first = first - 1
            last = last + 1
        end do
    end subroutine remove_left_knot

    pure real(dp) function binomial(n, k)
        integer, intent(in) :: n, k
        integer :: i
        binomial = 1.0_dp
        do i = 1, k
            binomial = binomial*real(n - k + i, dp)/real(i, dp)
        end do
    end function binomial

end module voiga_nurbs_refine
