!> The linear solver of a Newton iteration, behind one abstract type: `factor`
!> prepares solves with a tangent (an LU factorization, or the operators of a
!> preconditioner), `solve` solves with what was prepared. A direct solver also
!> knows the sign of det K (`has_determinant`), which the load stepping uses to
!> recognize folds of the incremental problem; an iterative one solves only to the
!> accuracy it is asked for (`solve_accuracy_t`) and counts its iterations.
!> Implementations: `voiga_solver_supernodal` (the direct LU, handing the matrices it
!> does not take to `voiga_solver_umfpack`), `voiga_solver_bulk_update` (direct solves
!> as updates of the bodies' Cholesky factor, `voiga_solver_cholmod`, when every body
!> is linear-elastic) and `voiga_solver_multigrid` (GMRES with a multigrid
!> preconditioner); `voiga_solver_linear_factory` builds the one a case names.
module voiga_solver_linear
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_linalg_sparse, only: csc_matrix_t
    implicit none
    private

    public :: linear_solver_t, solve_accuracy_t, solve_one_column

    !> How accurately an iterative solver is to solve (direct solvers ignore it).
    type :: solve_accuracy_t
        !> Relative residual ||b - A x|| <= rtol ||b|| (0: as accurately as it can).
        real(dp) :: rtol = 0.0_dp
        !> After this many iterations (0: never) `soft_rtol` is enough.
        integer :: soft_iterations = 0
        real(dp) :: soft_rtol = 0.0_dp
    end type solve_accuracy_t

    !> A linear solver for the (Dirichlet-eliminated) tangent stiffness.
    type, abstract :: linear_solver_t
    contains
        !> Prepare solves with the matrix `a`.
        procedure(factor_interface), deferred :: factor
        !> Solve a x = b with what `factor` prepared (`a`: the matrix passed to it).
        procedure(solve_interface), deferred :: solve
        !> Solve a X = B for several right-hand sides (default: one `solve` each).
        procedure :: solve_columns => linear_solve_columns
        !> Whether it solves iteratively, to the accuracy asked (default: no).
        procedure :: iterative => linear_iterative
        !> Whether `determinant` gives the sign of det(a) (default: no).
        procedure :: has_determinant => linear_has_determinant
        !> Sign and log10 magnitude of det(a) of the last `factor` (default: sign 0, unknown).
        procedure :: determinant => linear_determinant
        !> Iterations of the last solve (0 for a direct solver) and its relative residual.
        procedure :: last_iterations => linear_last_iterations
        procedure :: last_residual => linear_last_residual
        !> DOFs of each level of a hierarchical solver, finest first (empty: one level).
        procedure :: level_dofs => linear_level_dofs
        !> Symbolic analyses and numeric factorizations so far (0 for an iterative solver).
        procedure :: factorizations => linear_factorizations
        !> At the next `factor`, keep what was analysed before only if it was made for
        !> exactly that matrix's nonzeros (default: nothing is kept, nothing to do).
        procedure :: renew_analysis => linear_renew_analysis
    end type linear_solver_t

    abstract interface
        subroutine factor_interface(self, a, error)
            import :: linear_solver_t, csc_matrix_t, error_t
            class(linear_solver_t), intent(inout) :: self
            type(csc_matrix_t), intent(in) :: a
            type(error_t), allocatable, intent(out) :: error
        end subroutine factor_interface

        subroutine solve_interface(self, a, b, x, error, accuracy)
            import :: linear_solver_t, csc_matrix_t, error_t, dp, solve_accuracy_t
            class(linear_solver_t), intent(inout) :: self
            type(csc_matrix_t), intent(in) :: a
            !> Right-hand side and solution; shape: [n].
            real(dp), intent(in) :: b(:)
            real(dp), intent(out) :: x(:)
            type(error_t), allocatable, intent(out) :: error
            type(solve_accuracy_t), intent(in), optional :: accuracy
        end subroutine solve_interface
    end interface

contains

    !> Solve a X = B column by column with `solve`; shapes: [n, nrhs].
    subroutine linear_solve_columns(self, a, b, x, error)
        class(linear_solver_t), intent(inout) :: self
        type(csc_matrix_t), intent(in) :: a
        real(dp), intent(in) :: b(:, :)
        real(dp), intent(out) :: x(:, :)
        type(error_t), allocatable, intent(out) :: error
        integer :: j
        do j = 1, size(b, 2)
            call self%solve(a, b(:, j), x(:, j), error)
            if (allocated(error)) return
        end do
    end subroutine linear_solve_columns

    !> Solve a x = b as one column of `self%solve_columns`: the `solve` of a solver
    !> whose work is done a block of right-hand sides at a time.
    subroutine solve_one_column(self, a, b, x, error)
        class(linear_solver_t), intent(inout) :: self
        type(csc_matrix_t), intent(in) :: a
        real(dp), intent(in) :: b(:)
        real(dp), intent(out) :: x(:)
        type(error_t), allocatable, intent(out) :: error
        real(dp) :: xx(size(x), 1)
        call self%solve_columns(a, reshape(b, [size(b), 1]), xx, error)
        x = xx(:, 1)
    end subroutine solve_one_column

    pure logical function linear_iterative(self)
        class(linear_solver_t), intent(in) :: self
        linear_iterative = .false.
    end function linear_iterative

    pure logical function linear_has_determinant(self)
        class(linear_solver_t), intent(in) :: self
        linear_has_determinant = .false.
    end function linear_has_determinant

    subroutine linear_determinant(self, sign, log10_abs, error)
        class(linear_solver_t), intent(in) :: self
        integer, intent(out) :: sign
        real(dp), intent(out) :: log10_abs
        type(error_t), allocatable, intent(out) :: error
        sign = 0
        log10_abs = -huge(1.0_dp)
    end subroutine linear_determinant

    pure integer function linear_last_iterations(self) result(n)
        class(linear_solver_t), intent(in) :: self
        n = 0
    end function linear_last_iterations

    pure real(dp) function linear_last_residual(self) result(res)
        class(linear_solver_t), intent(in) :: self
        res = 0.0_dp
    end function linear_last_residual

    pure function linear_level_dofs(self) result(n)
        class(linear_solver_t), intent(in) :: self
        integer, allocatable :: n(:)
        allocate (n(0))
    end function linear_level_dofs

    pure subroutine linear_factorizations(self, symbolic, numeric)
        class(linear_solver_t), intent(in) :: self
        integer, intent(out) :: symbolic, numeric
        symbolic = 0
        numeric = 0
    end subroutine linear_factorizations

    pure subroutine linear_renew_analysis(self)
        class(linear_solver_t), intent(inout) :: self
    end subroutine linear_renew_analysis

end module voiga_solver_linear
