!> Compressed-sparse-row (CSR) matrices for the multigrid solver: conversion from
!> and to the CSC stiffness (`voiga_linalg_sparse`), transpose, product, matvec.
!>
!> Indices are 1-based. Every routine that builds a matrix sorts the column
!> indices of each row (through a counting-sort transpose), so the results are
!> deterministic and `csr_to_csc` hands UMFPACK what it wants.
module voiga_linalg_csr
    use, intrinsic :: iso_c_binding, only: c_int
    use voiga_kinds, only: dp
    use voiga_linalg_sparse, only: csc_matrix_t
    implicit none
    private

    public :: csr_t, csr_from_csc, csr_from_triplets, csr_transpose, csr_matmul, csr_to_csc, &
              csr_matvec, csr_diagonal_positions, csr_matmul_numeric

    !> An nrow x ncol matrix; row i holds entries ptr(i) .. ptr(i+1)-1.
    type :: csr_t
        integer :: nrow = 0, ncol = 0
        !> Row starts, shape [nrow+1], ptr(1) = 1.
        integer, allocatable :: ptr(:)
        !> Column of each entry (ascending within a row), shape [nnz].
        integer, allocatable :: col(:)
        !> Value of each entry, shape [nnz].
        real(dp), allocatable :: val(:)
    end type csr_t

contains

    !> CSR copy of a CSC matrix (same matrix, not its transpose), in one pass over its
    !> entries (no copy of the CSC arrays: the tangent of a solid is the largest array).
    pure subroutine csr_from_csc(a, b, perm)
        type(csc_matrix_t), intent(in) :: a
        type(csr_t), intent(out) :: b
        !> Optional: the position in `a%values` of each entry of `b` [nnz].
        integer, allocatable, intent(out), optional :: perm(:)
        integer, allocatable :: next(:)
        integer :: i, j, q, k, nnz

        ! a counting-sort transpose of the CSC arrays: columns ascend within each row
        b%nrow = a%n
        b%ncol = a%n
        nnz = int(a%colptr(a%n + 1))
        allocate (b%ptr(a%n + 1), b%col(nnz), b%val(nnz))
        if (present(perm)) allocate (perm(nnz))
        b%ptr = 0
        do q = 1, nnz
            b%ptr(a%rowind(q) + 2) = b%ptr(a%rowind(q) + 2) + 1
        end do
        b%ptr(1) = 1
        do i = 1, a%n
            b%ptr(i + 1) = b%ptr(i + 1) + b%ptr(i)
        end do
        next = b%ptr(1:a%n)
        do j = 1, a%n
            do q = int(a%colptr(j)) + 1, int(a%colptr(j + 1))
                i = a%rowind(q) + 1
                k = next(i)
                b%col(k) = j
                b%val(k) = a%values(q)
                if (present(perm)) perm(k) = q
                next(i) = k + 1
            end do
        end do
    end subroutine csr_from_csc

    !> CSC copy (0-based, rows sorted within columns) of a square CSR matrix.
    pure subroutine csr_to_csc(a, b)
        type(csr_t), intent(in) :: a
        type(csc_matrix_t), intent(out) :: b
        type(csr_t) :: t

        call csr_transpose(a, t)
        b%n = a%nrow
        b%colptr = int(t%ptr - 1, c_int)
        b%rowind = int(t%col - 1, c_int)
        b%values = t%val
    end subroutine csr_to_csc

    !> The matrix sum of triplets (rows, cols, vals) of shape nrow x ncol;
    !> repeated pairs are summed.
    pure subroutine csr_from_triplets(nrow, ncol, rows, cols, vals, a)
        integer, intent(in) :: nrow, ncol
        integer, intent(in) :: rows(:), cols(:)
        real(dp), intent(in) :: vals(:)
        type(csr_t), intent(out) :: a
        type(csr_t) :: t
        integer, allocatable :: next(:)
        integer :: k, i

        t%nrow = nrow
        t%ncol = ncol
        allocate (t%ptr(nrow + 1), t%col(size(rows)), t%val(size(rows)))
        t%ptr = 0
        do k = 1, size(rows)
            t%ptr(rows(k) + 1) = t%ptr(rows(k) + 1) + 1
        end do
        t%ptr(1) = 1
        do i = 1, nrow
            t%ptr(i + 1) = t%ptr(i + 1) + t%ptr(i)
        end do
        next = t%ptr(1:nrow)
        do k = 1, size(rows)
            i = rows(k)
            t%col(next(i)) = cols(k)
            t%val(next(i)) = vals(k)
            next(i) = next(i) + 1
        end do
        ! times the identity: sums the repeated entries, sorts the columns
        call csr_matmul(t, identity(ncol), a, sorted=.true.)
    end subroutine csr_from_triplets

    !> The n x n identity.
    pure function identity(n) result(e)
        integer, intent(in) :: n
        type(csr_t) :: e
        integer :: i
        e%nrow = n
        e%ncol = n
        e%ptr = [(i, i=1, n + 1)]
        e%col = [(i, i=1, n)]
        e%val = [(1.0_dp, i=1, n)]
    end function identity

    !> b = a^T (columns of each row of b come out ascending).
    pure subroutine csr_transpose(a, b)
        type(csr_t), intent(in) :: a
        type(csr_t), intent(out) :: b
        integer, allocatable :: next(:)
        integer :: i, k, j

        b%nrow = a%ncol
        b%ncol = a%nrow
        allocate (b%ptr(a%ncol + 1), b%col(size(a%col)), b%val(size(a%col)))
        b%ptr = 0
        do k = 1, size(a%col)
            b%ptr(a%col(k) + 1) = b%ptr(a%col(k) + 1) + 1
        end do
        b%ptr(1) = 1
        do j = 1, a%ncol
            b%ptr(j + 1) = b%ptr(j + 1) + b%ptr(j)
        end do
        next = b%ptr(1:a%ncol)
        do i = 1, a%nrow
            do k = a%ptr(i), a%ptr(i + 1) - 1
                j = a%col(k)
                b%col(next(j)) = i
                b%val(next(j)) = a%val(k)
                next(j) = next(j) + 1
            end do
        end do
    end subroutine csr_transpose

    !> c = a b (Gustavson's row-by-row product; columns of c unsorted unless
    !> `sorted`, which costs two transposes).
    pure subroutine csr_matmul(a, b, c, sorted)
        type(csr_t), intent(in) :: a, b
        type(csr_t), intent(out) :: c
        logical, intent(in), optional :: sorted
        integer, allocatable :: mark(:), cols(:)
        real(dp), allocatable :: acc(:)
        integer :: i, k, kb, j, n, nnz
        real(dp) :: aik

        allocate (mark(b%ncol), cols(b%ncol), acc(b%ncol))
        mark = 0
        c%nrow = a%nrow
        c%ncol = b%ncol
        allocate (c%ptr(a%nrow + 1))
        ! symbolic pass: the number of entries of each row
        nnz = 0
        c%ptr(1) = 1
        do i = 1, a%nrow
            do k = a%ptr(i), a%ptr(i + 1) - 1
                do kb = b%ptr(a%col(k)), b%ptr(a%col(k) + 1) - 1
                    j = b%col(kb)
                    if (mark(j) /= i) then
                        mark(j) = i
                        nnz = nnz + 1
                    end if
                end do
            end do
            c%ptr(i + 1) = nnz + 1
        end do
        allocate (c%col(nnz), c%val(nnz))
        mark = 0
        acc = 0.0_dp
        do i = 1, a%nrow
            n = 0
            do k = a%ptr(i), a%ptr(i + 1) - 1
                aik = a%val(k)
                do kb = b%ptr(a%col(k)), b%ptr(a%col(k) + 1) - 1
                    j = b%col(kb)
                    if (mark(j) /= i) then
                        mark(j) = i
                        n = n + 1
                        cols(n) = j
                        acc(j) = 0.0_dp
                    end if
                    acc(j) = acc(j) + aik*b%val(kb)
                end do
            end do
            c%col(c%ptr(i):c%ptr(i + 1) - 1) = cols(1:n)
            c%val(c%ptr(i):c%ptr(i + 1) - 1) = acc(cols(1:n))
        end do
        if (present(sorted)) then
            if (sorted) then
                block
                    type(csr_t) :: t, u
                    call csr_transpose(c, t)
                    call csr_transpose(t, u)
                    call move_alloc(u%col, c%col)
                    call move_alloc(u%val, c%val)
                end block
            end if
        end if
    end subroutine csr_matmul

    !> The values of c = a b into the existing pattern of `c`, which must hold every
    !> entry of the product (a pattern from `csr_matmul` of matrices with the same
    !> patterns as a and b, possibly with more entries, which come out 0).
    pure subroutine csr_matmul_numeric(a, b, c)
        type(csr_t), intent(in) :: a, b
        type(csr_t), intent(inout) :: c
        integer, allocatable :: at(:)
        integer :: i, k, kb, q
        real(dp) :: aik

        allocate (at(c%ncol))
        do i = 1, a%nrow
            do q = c%ptr(i), c%ptr(i + 1) - 1
                at(c%col(q)) = q
                c%val(q) = 0.0_dp
            end do
            do k = a%ptr(i), a%ptr(i + 1) - 1
                aik = a%val(k)
                do kb = b%ptr(a%col(k)), b%ptr(a%col(k) + 1) - 1
                    q = at(b%col(kb))
                    c%val(q) = c%val(q) + aik*b%val(kb)
                end do
            end do
        end do
    end subroutine csr_matmul_numeric

    !> y = a x.
    pure subroutine csr_matvec(a, x, y)
        type(csr_t), intent(in) :: a
        real(dp), intent(in) :: x(:)
        real(dp), intent(out) :: y(:)
        integer :: i, k
        real(dp) :: s

        do i = 1, a%nrow
            s = 0.0_dp
            do k = a%ptr(i), a%ptr(i + 1) - 1
                s = s + a%val(k)*x(a%col(k))
            end do
            y(i) = s
        end do
    end subroutine csr_matvec

    !> Position of each row's diagonal entry in `col`/`val`, 0 where none is stored.
    pure function csr_diagonal_positions(a) result(pos)
        type(csr_t), intent(in) :: a
        integer :: pos(a%nrow)
        integer :: i, k

        pos = 0
        do i = 1, a%nrow
            do k = a%ptr(i), a%ptr(i + 1) - 1
                if (a%col(k) == i) then
                    pos(i) = k
                    exit
                end if
            end do
        end do
    end function csr_diagonal_positions

end module voiga_linalg_csr
