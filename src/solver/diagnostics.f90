!> Why a load step that was cut down to its limit failed: what the solver can say
!> beyond the last attempt's own reason (docs/robustness.md).
!>
!> - A fold of the incremental problem: the tangent's determinant changed sign near
!>   the last converged state.
!> - What the contact pairs say of their state there (`failure_diagnosis`; a GPTS
!>   zone locked by more point constraints than the slave edge has DOFs).
module voiga_solver_diagnostics
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_model, only: model_t
    use voiga_model_assembly, only: assemble, assembly_stats_t
    use voiga_text, only: str, real_str
    implicit none
    private

    public :: fold_diagnosis, append_pair_diagnoses

contains

    !> The determinant of the tangent changed sign near the last converged state:
    !> det K <= 0 in `nonpositive` of the `total` iterations of the last attempt
    !> started there, det K > 0 in the others or at the converged state. Pieces of
    !> the (piecewise smooth) incremental problem with opposite orientation meet
    !> there, so the incremental map folds (it is not coherently oriented): for some
    !> increments it has no solution nearby. The message does not decide between a
    !> limit point of the path and a passage narrower than the smallest increment
    !> (docs/robustness.md, "Folds of the incremental problem").
    pure function fold_diagnosis(model, nonpositive, total) result(text)
        type(model_t), intent(in) :: model
        integer, intent(in) :: nonpositive, total
        character(len=:), allocatable :: text
        integer :: ip
        text = '; the determinant of the tangent stiffness changes sign near the last converged state '// &
               '(det K <= 0 in '//str(nonpositive)//' of the '//str(total)//' iterations of the last '// &
               'attempt, > 0 in the others or at that state)'
        text = text//': pieces of the incremental problem with opposite orientation meet '// &
               'there, so it folds (for some increments it has no nearby solution): either the '// &
               'quasi-static path ends here (a limit point; the physical system would move '// &
               'dynamically) or it goes on only through increments below min_step_fraction'
        do ip = 1, size(model%pairs)
            associate (law => model%pairs(ip)%pair%law)
                if (law%mu <= 0.0_dp) cycle
                text = text//'; with Coulomb friction (mu = '//real_str(law%mu, 'es8.1')//', penalty_normal = '// &
                       real_str(law%eps_n, 'es8.1')//'): slipping points couple the'
            end associate
            text = text//' normal penalty into the tangential direction (mu x penalty_normal) '// &
                   'which can make the tangent indefinite (the friction-induced instability); a smaller '// &
                   'penalty_normal or mu keeps the path stable longer'
            exit
        end do
    end function fold_diagnosis

    !> Append to `message` what each contact pair says of its state at the last
    !> converged state `u` (load time `t`), evaluated afresh; nothing when the
    !> evaluation there fails. The pairs' trial history is reset afterwards.
    subroutine append_pair_diagnoses(model, u, t, stats, message)
        type(model_t), intent(inout) :: model
        real(dp), intent(in) :: u(:), t
        type(assembly_stats_t), intent(inout) :: stats
        character(len=:), allocatable, intent(inout) :: message
        type(error_t), allocatable :: error
        real(dp), allocatable :: r(:)
        integer :: ip

        if (size(model%pairs) == 0) return
        allocate (r(model%ndof))
        call assemble(model, u, t, r, stats, error)
        do ip = 1, size(model%pairs)
            call model%pairs(ip)%pair%reset_trial()
        end do
        if (allocated(error)) return
        do ip = 1, size(model%pairs)
            message = message//model%pairs(ip)%pair%failure_diagnosis()
        end do
    end subroutine append_pair_diagnoses

end module voiga_solver_diagnostics
