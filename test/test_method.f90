!> A contact method with history written as a new method would be: one extension of
!> `contact_pair_t` (here, in the test) that declares its history field and computes
!> its kinematics, and nothing else. The base pair commits, resets, writes and reads
!> the field back; the factory's `build_pair` builds it like the methods it names
!> (docs/architecture.md, "Adding a contact method").
module test_method
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_testdrive, only: unittest_t, new_unittest, check
    use voiga_model, only: model_t
    use voiga_contact_factory, only: contact_settings_t, build_pair
    use voiga_contact_pair, only: contact_pair_t, history_item_t, add_matrix
    use voiga_contact_surface, only: surface_point_t
    use voiga_contact_master, only: master_point_t
    use voiga_contact_law, only: state_stick
    use test_contact, only: two_body_model, penetrating_state
    implicit none
    private

    public :: collect_method

    !> The example method: a frictionless point-to-surface penalty without a tangent,
    !> whose history is the largest pressure each slave point has carried (`peak`).
    type, extends(contact_pair_t) :: peak_pair_t
        integer :: h_peak = 0
    contains
        procedure :: evaluate => peak_evaluate
        procedure :: method_name => peak_method_name
        procedure :: n_blocks => peak_n_blocks
        procedure :: block_dofs => peak_block_dofs
        procedure :: setup_history => peak_setup_history
    end type peak_pair_t

contains

    subroutine collect_method(tests)
        type(unittest_t), allocatable, intent(out) :: tests(:)
        tests = [new_unittest('history_commit_reset_restart', test_history)]
    end subroutine collect_method

    pure subroutine peak_setup_history(self)
        class(peak_pair_t), intent(inout) :: self
        call self%hist%add('peak', size(self%xi), self%h_peak, per_point=.true.)
    end subroutine peak_setup_history

    subroutine peak_evaluate(self, u, r, error, add)
        class(peak_pair_t), intent(inout) :: self
        real(dp), intent(in) :: u(:)
        real(dp), intent(inout) :: r(:)
        type(error_t), allocatable, intent(out) :: error
        procedure(add_matrix), optional :: add
        type(surface_point_t) :: sp
        type(master_point_t) :: mp
        logical :: found, converged
        integer :: k, a
        real(dp) :: pn
        call self%master%prepare(u)
        do k = 1, size(self%xi)
            call self%project_point(u, k, sp, mp, found, converged)
            self%hist%field(self%h_peak)%trial(k) = self%hist%field(self%h_peak)%last(k)
            if (.not. (found .and. converged) .or. self%out(k)%gap >= 0.0_dp) cycle
            pn = -self%law%eps_n*self%out(k)%gap
            do a = 1, size(sp%r)
                r(sp%dofs(2*a - 1:2*a)) = r(sp%dofs(2*a - 1:2*a)) - pn*self%w(k)*norm2(sp%a)*sp%r(a)*mp%n(1:2)
            end do
            self%out(k)%pn = pn
            self%out(k)%state = state_stick
            self%hist%field(self%h_peak)%trial(k) = max(self%hist%field(self%h_peak)%last(k), pn)
        end do
    end subroutine peak_evaluate

    pure function peak_method_name(self) result(name)
        class(peak_pair_t), intent(in) :: self
        character(len=:), allocatable :: name
        name = 'peak'
    end function peak_method_name

    pure integer function peak_n_blocks(self)
        class(peak_pair_t), intent(in) :: self
        peak_n_blocks = 0
    end function peak_n_blocks

    pure function peak_block_dofs(self, b, mdofs) result(dofs)
        class(peak_pair_t), intent(in) :: self
        integer, intent(in) :: b
        integer, intent(in) :: mdofs(:)
        integer, allocatable :: dofs(:)
        allocate (dofs(0))
    end function peak_block_dofs

    !> The example pair built by the factory on the die of the two-body scene against
    !> a rigid line; a penetrating state gives trial peaks that `reset_trial` forgets
    !> and `commit` keeps; `history` names the field, and a new pair set from it
    !> (a restart) continues from the same peaks; a history of another length is
    !> refused with the field's name.
    subroutine test_history(error)
        type(error_t), allocatable, intent(out) :: error
        type(model_t) :: model
        class(contact_pair_t), allocatable :: pair, again
        type(history_item_t), allocatable :: items(:), wrong(:)
        real(dp), allocatable :: u(:), r(:), pn(:)
        character(len=:), allocatable :: message

        call two_body_model('NN2.2', 0.0_dp, .true., model, error)
        if (allocated(error)) return
        call new_peak_pair(model, pair, error)
        if (allocated(error)) return
        call new_peak_pair(model, again, error)
        if (allocated(error)) return
        call penetrating_state(model, u)
        allocate (r(size(u)), source=0.0_dp)
        call pair%evaluate(u, r, error)
        if (allocated(error)) return
        pn = pair%out%pn
        call check(error, maxval(pn) > 0.0_dp .and. all(pair%hist%values('peak') == 0.0_dp), &
                   'a trial peak, none committed')
        if (allocated(error)) return
        call pair%reset_trial()
        call check(error, all(pair%hist%field(1)%trial == 0.0_dp), 'reset_trial forgets the trial peaks')
        if (allocated(error)) return
        call pair%evaluate(u, r, error)
        if (allocated(error)) return
        call pair%commit()
        call check(error, all(pair%hist%values('peak') == pn), 'commit keeps them')
        if (allocated(error)) return
        items = pair%history()
        call check(error, size(items) == 1 .and. trim(items(1)%name) == 'peak', 'history names the field')
        if (allocated(error)) return
        call again%set_history(items, error)
        if (allocated(error)) return
        call check(error, all(again%hist%values('peak') == pn) .and. all(again%hist%field(1)%trial == pn), &
                   'a restart continues from the committed peaks')
        if (allocated(error)) return
        wrong = items
        wrong(1)%values = [wrong(1)%values, 0.0_dp]
        call again%set_history(wrong, error)
        if (.not. allocated(error)) then
            call check(error, .false., 'a history of another length is refused')
            return
        end if
        message = error%message
        deallocate (error)
        call check(error, index(message, 'history peak: wrong length') > 0, message)
    end subroutine test_history

    !> The example pair on the two-body scene's die against its rigid line, built by
    !> the factory's `build_pair` from settings as a case would give them.
    subroutine new_peak_pair(model, pair, error)
        type(model_t), intent(in) :: model
        class(contact_pair_t), allocatable, intent(out) :: pair
        type(error_t), allocatable, intent(out) :: error
        type(contact_settings_t) :: settings
        settings = contact_settings_t(slave='die', master='rigid', penalty_normal=100.0_dp, method='peak')
        allocate (peak_pair_t :: pair)
        associate (scene_pair => model%pairs(1)%pair)
            call build_pair(pair, settings, scene_pair%slave, scene_pair%master, [1, 0], 10.0_dp, model%ndof, error)
        end associate
    end subroutine new_peak_pair

end module test_method
