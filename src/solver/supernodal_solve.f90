!> The solves of `supernodal_lu_t` (`voiga_solver_supernodal`) with its factors:
!> forward and backward substitution front by front, and iterative refinement as
!> UMFPACK's when the reciprocal condition estimate is small.
submodule(voiga_solver_supernodal) voiga_solver_supernodal_solve
    use voiga_text, only: str
    implicit none

    !> Solves refine iteratively (at most `max_refine` steps) below this rcond, as
    !> `umfpack_t` does.
    real(dp), parameter :: refine_below_rcond = 1.0e-3_dp
    integer, parameter :: max_refine = 2

contains

    module procedure sn_solve
        if (.not. self%factored) then
            call fatal_error(error, 'supernodal solve: no factorization (factor was not called or failed)')
            return
        end if
        if (self%on_umfpack) then
            call self%umfpack%solve(a, b, x, error)
            return
        end if
        if (a%n /= self%n .or. size(b) /= self%n .or. size(x) /= self%n) then
            call fatal_error(error, 'supernodal solve: n = '//str(a%n)//', size(b) = '//str(size(b))// &
                             ', size(x) = '//str(size(x))//', factorized n = '//str(self%n))
            return
        end if
        call apply_inverse(self, b, x)
        if (self%rcond < refine_below_rcond) call refine(self, a, b, x)
    end procedure sn_solve

    !> x = A^-1 b with the factors: permute and scale, forward with L (the
    !> supernodes' row swaps in their order), backward with U, permute back.
    subroutine apply_inverse(self, b, x)
        class(supernodal_lu_t), intent(inout) :: self
        real(dp), intent(in) :: b(:)
        real(dp), intent(out) :: x(:)
        integer :: s, c, m, k
        do c = 1, self%n
            self%y(c) = b(self%perm(c))*self%rscale(self%perm(c))
        end do
        do s = 1, self%nsuper
            call forward(self%f(self%fptr(s):), self%rptr(s + 1) - self%rptr(s), self%super(s + 1) - self%super(s), &
                         self%rows(self%rptr(s):), self%ipiv(self%super(s):), self%y, self%w)
        end do
        do s = self%nsuper, 1, -1
            m = self%rptr(s + 1) - self%rptr(s)
            k = self%super(s + 1) - self%super(s)
            call backward(self%f(self%fptr(s):), self%f(self%fptr(s) + m*k:), m, k, self%rows(self%rptr(s):), &
                          self%y, self%w)
        end do
        x(self%perm) = self%y
    end subroutine apply_inverse

    !> One supernode of the forward substitution: its row swaps, L's diagonal block,
    !> then its rows below the block, summed in `w` [m - k] and scattered once.
    pure subroutine forward(fr, m, k, rows, piv, y, w)
        integer, intent(in) :: m, k, rows(m), piv(k)
        real(dp), intent(in) :: fr(m, k)
        real(dp), intent(inout) :: y(:)
        real(dp), intent(out) :: w(:)
        real(dp) :: t
        integer :: j, i, f0
        f0 = rows(1)
        do j = 1, k
            if (piv(j) /= j) then
                t = y(f0 + j - 1)
                y(f0 + j - 1) = y(f0 + piv(j) - 1)
                y(f0 + piv(j) - 1) = t
            end if
        end do
        do j = 1, k - 1
            t = y(f0 + j - 1)
            if (t == 0.0_dp) cycle
            do i = j + 1, k
                y(f0 + i - 1) = y(f0 + i - 1) - fr(i, j)*t
            end do
        end do
        if (m == k) return
        w(1:m - k) = 0.0_dp
        do j = 1, k
            t = y(f0 + j - 1)
            if (t == 0.0_dp) cycle
            do i = k + 1, m
                w(i - k) = w(i - k) + fr(i, j)*t
            end do
        end do
        do i = k + 1, m
            y(rows(i)) = y(rows(i)) - w(i - k)
        end do
    end subroutine forward

    !> One supernode of the backward substitution: the rows of U right of the
    !> diagonal block against the solution gathered in `w` [m - k], then the block.
    pure subroutine backward(fr, fu, m, k, rows, y, w)
        integer, intent(in) :: m, k, rows(m)
        !> The front's first k columns [m, k] and the rest of its first k rows [k, m - k].
        real(dp), intent(in) :: fr(m, k), fu(k, m - k)
        real(dp), intent(inout) :: y(:)
        real(dp), intent(out) :: w(:)
        real(dp) :: t
        integer :: j, c, f0
        f0 = rows(1)
        do c = k + 1, m
            w(c - k) = y(rows(c))
        end do
        do c = k + 1, m
            t = w(c - k)
            if (t == 0.0_dp) cycle
            do j = 1, k
                y(f0 + j - 1) = y(f0 + j - 1) - fu(j, c - k)*t
            end do
        end do
        do j = k, 1, -1
            t = y(f0 + j - 1)
            do c = j + 1, k
                t = t - fr(j, c)*y(f0 + c - 1)
            end do
            y(f0 + j - 1) = t/fr(j, j)
        end do
    end subroutine backward

    !> Iterative refinement as UMFPACK's: x += A^-1 (b - A x) while the backward
    !> error max_i |b - A x|_i / (|A| |x| + |b|)_i exceeds the rounding unit and at
    !> least halves, at most `max_refine` times.
    subroutine refine(self, a, b, x)
        class(supernodal_lu_t), intent(inout) :: self
        type(csc_matrix_t), intent(in) :: a
        real(dp), intent(in) :: b(:)
        real(dp), intent(inout) :: x(:)
        real(dp) :: r(size(b)), w(size(b)), dx(size(b)), x_last(size(b))
        real(dp) :: omega, omega_last
        integer :: step, j, p, i
        omega_last = huge(1.0_dp)
        do step = 0, max_refine
            r = b
            w = abs(b)
            do j = 1, a%n
                do p = a%colptr(j) + 1, a%colptr(j + 1)
                    i = a%rowind(p) + 1
                    r(i) = r(i) - a%values(p)*x(j)
                    w(i) = w(i) + abs(a%values(p)*x(j))
                end do
            end do
            omega = maxval(abs(r)/max(w, tiny(1.0_dp)))
            if (omega > 0.5_dp*omega_last) then
                x = x_last
                return
            end if
            if (omega <= epsilon(1.0_dp) .or. step == max_refine) return
            omega_last = omega
            x_last = x
            call apply_inverse(self, r, dx)
            x = x + dx
        end do
    end subroutine refine

end submodule voiga_solver_supernodal_solve
