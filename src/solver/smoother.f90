!> Line Gauss-Seidel smoothing for the multigrid solver (`voiga_solver_multigrid`).
!>
!> A line is the set of DOFs of one row of control points of a patch (along xi,
!> or along eta). A sweep visits the lines in order and solves each line's block
!> exactly (band LU: LAPACK dgbtrf, and its solve inline) with the latest values of all other
!> DOFs: block Gauss-Seidel. Point Gauss-Seidel smooths only errors that vary on
!> the scale of the elements in every direction; on stretched elements (the thin
!> inner elements of the Hertz annulus, the penalty-stiffened contact row) the
!> coupling along one direction dominates and only a line solve in that direction
!> removes the error there. Alternating xi- and eta-line sweeps cover both.
module voiga_solver_smoother
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_text, only: str
    use voiga_linalg_csr, only: csr_t
    use voiga_linalg_lapack, only: band_factor
    implicit none
    private

    public :: line_set_t, new_line_set

    !> A set of disjoint lines and the band LU factors of their blocks.
    type :: line_set_t
        !> Number of lines; DOFs of line l: dofs(ptr(l) : ptr(l+1)-1).
        integer :: n = 0
        integer, allocatable :: ptr(:), dofs(:)
        !> Line of each DOF (0: in no line) and its position there [ndof].
        integer, allocatable :: line_of(:), pos(:)
        !> Per line: sub/superdiagonals of its block and offsets into `band`/`ipiv`.
        integer, allocatable :: kl(:), ku(:), band_start(:), piv_start(:)
        !> Band LU factors of every line's block (column-major, leading dimension
        !> 2 kl + ku + 1), one after another, and their pivots.
        real(dp), allocatable :: band(:)
        integer, allocatable :: ipiv(:)
        !> Every line-block entry: its position in the matrix values (src) and in
        !> `band` (dst).
        integer, allocatable :: src(:), dst(:)
    contains
        !> Bandwidths, band layout and gather map for a matrix pattern.
        procedure :: analyse => lines_analyse
        !> Gather and factorize every line's block of a matrix.
        procedure :: factor => lines_factor
        !> One block Gauss-Seidel sweep over the lines.
        procedure :: sweep => lines_sweep
        !> Length of the longest line.
        procedure :: longest
    end type line_set_t

contains

    !> A line set of an ndof-DOF problem from lines given as DOF lists
    !> (`dofs(ptr(l):ptr(l+1)-1)`, disjoint).
    pure subroutine new_line_set(self, ndof, ptr, dofs)
        type(line_set_t), intent(out) :: self
        integer, intent(in) :: ndof
        integer, intent(in) :: ptr(:), dofs(:)
        integer :: l, k

        self%n = size(ptr) - 1
        self%ptr = ptr
        self%dofs = dofs
        allocate (self%line_of(ndof), self%pos(ndof))
        self%line_of = 0
        self%pos = 0
        do l = 1, self%n
            do k = ptr(l), ptr(l + 1) - 1
                self%line_of(dofs(k)) = l
                self%pos(dofs(k)) = k - ptr(l) + 1
            end do
        end do
        allocate (self%kl(self%n), self%ku(self%n), self%band_start(self%n), self%piv_start(self%n))
    end subroutine new_line_set

    !> For the pattern of `a`: every line's bandwidths, its place in the band
    !> storage, and where each of its entries comes from in `a` (once per pattern).
    pure subroutine lines_analyse(self, a)
        class(line_set_t), intent(inout) :: self
        type(csr_t), intent(in) :: a
        integer :: l, k, q, i, j, r, c, m, nb, np, ne, pass, ld

        ! pass 1: bandwidths and entry count; pass 2: the gather map
        do pass = 1, 2
            if (pass == 1) then
                self%kl = 0
                self%ku = 0
            end if
            ne = 0
            do l = 1, self%n
                ld = 2*self%kl(l) + self%ku(l) + 1
                do k = self%ptr(l), self%ptr(l + 1) - 1
                    i = self%dofs(k)
                    r = self%pos(i)
                    do q = a%ptr(i), a%ptr(i + 1) - 1
                        j = a%col(q)
                        if (self%line_of(j) /= l) cycle
                        c = self%pos(j)
                        ne = ne + 1
                        if (pass == 1) then
                            self%kl(l) = max(self%kl(l), r - c)
                            self%ku(l) = max(self%ku(l), c - r)
                        else
                            ! entry (r, c) at ab(kl + ku + 1 + r - c, c)
                            self%src(ne) = q
                            self%dst(ne) = self%band_start(l) + (c - 1)*ld + self%kl(l) + self%ku(l) + r - c
                        end if
                    end do
                end do
            end do
            if (pass == 1) then
                nb = 0
                np = 0
                do l = 1, self%n
                    m = self%ptr(l + 1) - self%ptr(l)
                    self%band_start(l) = nb + 1
                    self%piv_start(l) = np + 1
                    nb = nb + (2*self%kl(l) + self%ku(l) + 1)*m
                    np = np + m
                end do
                if (allocated(self%band)) deallocate (self%band, self%ipiv, self%src, self%dst)
                allocate (self%band(nb), self%ipiv(np), self%src(ne), self%dst(ne))
            end if
        end do
    end subroutine lines_analyse

    !> Band LU factors of the lines' blocks of `a` (pattern as in the last `analyse`).
    subroutine lines_factor(self, a, error)
        class(line_set_t), intent(inout) :: self
        type(csr_t), intent(in) :: a
        type(error_t), allocatable, intent(out) :: error
        integer :: l, m, info

        self%band = 0.0_dp
        self%band(self%dst) = a%val(self%src)
        do l = 1, self%n
            m = self%ptr(l + 1) - self%ptr(l)
            call band_factor(m, self%kl(l), self%ku(l), self%band(self%band_start(l)), &
                             self%ipiv(self%piv_start(l)), info)
            if (info /= 0) then
                call fatal_error(error, 'multigrid smoother: the block of line '//str(l)//' is singular', &
                                 error_code%numeric)
                return
            end if
        end do
    end subroutine lines_factor

    !> One block Gauss-Seidel sweep for a x = b over the lines (in increasing
    !> order, or decreasing when not `forward`); DOFs in no line keep their values.
    !> `work` needs the length of the longest line.
    pure subroutine lines_sweep(self, a, b, x, forward, work)
        class(line_set_t), intent(in) :: self
        type(csr_t), intent(in) :: a
        real(dp), intent(in) :: b(:)
        real(dp), intent(inout) :: x(:)
        logical, intent(in) :: forward
        real(dp), intent(inout) :: work(:)
        integer :: l, k, q, i, m, first, last, step
        real(dp) :: s

        if (forward) then
            first = 1
            last = self%n
            step = 1
        else
            first = self%n
            last = 1
            step = -1
        end if
        do l = first, last, step
            m = self%ptr(l + 1) - self%ptr(l)
            do k = self%ptr(l), self%ptr(l + 1) - 1
                i = self%dofs(k)
                s = b(i)
                do q = a%ptr(i), a%ptr(i + 1) - 1
                    s = s - a%val(q)*x(a%col(q))
                end do
                work(k - self%ptr(l) + 1) = s
            end do
            call band_lu_solve(m, self%kl(l), self%ku(l), self%band(self%band_start(l)), &
                               self%ipiv(self%piv_start(l)), work)
            do k = self%ptr(l), self%ptr(l + 1) - 1
                x(self%dofs(k)) = x(self%dofs(k)) + work(k - self%ptr(l) + 1)
            end do
        end do
    end subroutine lines_sweep

    !> Longest line (the length of `lines_sweep`'s work array).
    pure integer function longest(self)
        class(line_set_t), intent(in) :: self
        integer :: l
        longest = 0
        do l = 1, self%n
            longest = max(longest, self%ptr(l + 1) - self%ptr(l))
        end do
    end function longest

    !> Solve with the band LU factors of LAPACK's dgbtrf (the steps of dgbtrs,
    !> 'N', one right-hand side), inline: the lines are short and narrow (bandwidth
    !> 5 for quadratic splines), where the library's per-call overhead dominates.
    pure subroutine band_lu_solve(n, kl, ku, ab, ipiv, b)
        integer, intent(in) :: n, kl, ku
        real(dp), intent(in) :: ab(2*kl + ku + 1, n)
        integer, intent(in) :: ipiv(n)
        real(dp), intent(inout) :: b(:)
        integer :: j, i, lm, p, kd
        real(dp) :: t

        kd = kl + ku + 1
        ! L: row interchanges and the multipliers below the diagonal
        do j = 1, n - 1
            lm = min(kl, n - j)
            p = ipiv(j)
            t = b(p)
            if (p /= j) then
                b(p) = b(j)
                b(j) = t
            end if
            do i = 1, lm
                b(j + i) = b(j + i) - t*ab(kd + i, j)
            end do
        end do
        ! U: kl + ku superdiagonals, diagonal in row kd
        do j = n, 1, -1
            b(j) = b(j)/ab(kd, j)
            t = b(j)
            do i = max(1, j - kl - ku), j - 1
                b(i) = b(i) - t*ab(kd + i - j, j)
            end do
        end do
    end subroutine band_lu_solve

end module voiga_solver_smoother
