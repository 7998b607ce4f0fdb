!> The linear solver a case names (`&solver linear_solver`), built once per run.
module voiga_solver_linear_factory
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_model, only: model_t
    use voiga_solver_linear, only: linear_solver_t
    use voiga_solver_umfpack, only: umfpack_t
    use voiga_solver_multigrid, only: multigrid_t
    implicit none
    private

    public :: new_linear_solver, linear_solver_names

    !> The valid values of `&solver linear_solver` (the case reader checks against them).
    character(len=*), parameter :: linear_solver_names(2) = [character(len=9) :: 'direct', 'multigrid']

contains

    !> The linear solver `name` for the tangents of `model`: 'direct' (UMFPACK LU)
    !> or 'multigrid' (GMRES with the multigrid preconditioner, whose hierarchy of
    !> spaces is built here, once).
    subroutine new_linear_solver(solver, name, model, error)
        class(linear_solver_t), allocatable, intent(out) :: solver
        character(len=*), intent(in) :: name
        type(model_t), intent(in) :: model
        type(error_t), allocatable, intent(out) :: error
        select case (trim(name))
        case ('direct')
            allocate (umfpack_t :: solver)
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

end module voiga_solver_linear_factory
