!> The linear solver a case names (`&solver linear_solver`), built once per run.
module voiga_solver_linear_factory
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_model, only: model_t, contact_reach
    use voiga_linalg_sparse, only: csc_matrix_t
    use voiga_solver_linear, only: linear_solver_t
    use voiga_solver_umfpack, only: umfpack_t
    use voiga_solver_supernodal, only: supernodal_lu_t
    use voiga_solver_bulk_update, only: bulk_update_t, new_bulk_update
    use voiga_solver_multigrid, only: multigrid_t
    implicit none
    private

    public :: new_linear_solver, linear_solver_names

    !> The valid values of `&solver linear_solver` (the case reader checks against them).
    character(len=*), parameter :: linear_solver_names(2) = [character(len=9) :: 'direct', 'multigrid']

contains

    !> The linear solver `name` for the tangents of `model`: 'direct' (UMFPACK LU)
    !> or 'multigrid' (GMRES with the multigrid preconditioner, whose hierarchy of
    !> spaces is built here, once). With 'direct' and `bulk`, the bodies' stiffness
    !> when every body is linear-elastic (`voiga_model_assembly_bulk%bulk_stiffness`), it is
    !> factorized here, once, and every tangent solved as an update of it
    !> (`voiga_solver_bulk_update`).
    subroutine new_linear_solver(solver, name, model, error, bulk)
        class(linear_solver_t), allocatable, intent(out) :: solver
        character(len=*), intent(in) :: name
        type(model_t), intent(in) :: model
        type(error_t), allocatable, intent(out) :: error
        type(csc_matrix_t), intent(in), optional :: bulk
        select case (trim(name))
        case ('direct')
            if (present(bulk)) call bulk_solver(solver, model, bulk)
            if (.not. allocated(solver)) allocate (supernodal_lu_t :: solver)
        case ('multigrid')
            allocate (multigrid_t :: solver)
            select type (solver)
            type is (multigrid_t)
                call solver%build(model%bodies(:)%disc, model%bodies(:)%dof0, model%ndof, model%fixed, error)
            end select
        case default
            call fatal_error(error, "unknown linear solver '"//trim(name)//"' (known: "// &
                             "'direct', 'multigrid')", error_code%input)
        end select
    end subroutine new_linear_solver

    !> The bulk-update solver of a model whose bodies are all linear-elastic, with
    !> their stiffness `k0`; not allocated when it alone is singular (a body that
    !> only contact holds in place): every tangent is then factorized whole.
    subroutine bulk_solver(solver, model, k0)
        class(linear_solver_t), allocatable, intent(inout) :: solver
        type(model_t), intent(in) :: model
        type(csc_matrix_t), intent(in) :: k0
        type(error_t), allocatable :: error
        allocate (bulk_update_t :: solver)
        select type (solver)
        type is (bulk_update_t)
            call new_bulk_update(solver, k0, model%fixed, contact_reach(model), error)
        end select
        if (allocated(error)) deallocate (solver)
    end subroutine bulk_solver

end module voiga_solver_linear_factory
