!> The history of a contact pair: a list of named fields, each with a committed
!> and a trial value per point (or per control point), that the base pair commits
!> (a step converged), resets (a step is retried), writes to a result file and
!> sets from one (a restart) for every method alike. A method declares its fields
!> in `setup_history` (`add`) and reads and writes their values; it writes no
!> commit, reset or serialisation code of its own (docs/architecture.md, "Adding a
!> contact method").
module voiga_contact_history
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    implicit none
    private

    public :: history_t, history_field_t, history_item_t, flag_value

    !> One array of a pair's committed history, named as the result file stores it
    !> (`history/<name>`): real values, or integer flags.
    type :: history_item_t
        character(len=16) :: name = ''
        real(dp), allocatable :: values(:)
        integer, allocatable :: flags(:)
        !> The most values a restart may read for it (-1: as many as it holds now;
        !> a pair whose number of points changes between steps gives its bound).
        integer :: most = -1
    end type history_item_t

    !> One field: committed (`last`) and trial values [entries]. A field of
    !> `flags` holds 0 or 1 (`flag_value`) and is stored as integer flags; a field
    !> `per_point` has one entry per slave point and is resized with the points
    !> (`resize_points`), to `initial` everywhere.
    type :: history_field_t
        character(len=16) :: name = ''
        real(dp), allocatable :: last(:), trial(:)
        real(dp) :: initial = 0.0_dp
        logical :: flags = .false., per_point = .false.
    end type history_field_t

    !> The fields of one pair, in the order they were added.
    type :: history_t
        type(history_field_t), allocatable :: field(:)
    contains
        !> Add a field of `n` entries, all `initial`; its index.
        procedure :: add => history_add
        !> The trial values become the committed ones.
        procedure :: commit => history_commit
        !> The trial values go back to the committed ones.
        procedure :: reset_trial => history_reset_trial
        !> The committed values as result-file items (`most` for the fields per point).
        procedure :: items => history_items
        !> Set the committed and trial values from `items` (a restart).
        procedure :: set_items => history_set_items
        !> Every field per point to `n` entries of its initial value.
        procedure :: resize_points => history_resize_points
        !> The committed values of the field `name` (none if there is no such field).
        procedure :: values => history_values
    end type history_t

contains

    !> 1 for true, 0 for false: the value of a `flags` field.
    elemental real(dp) function flag_value(on)
        logical, intent(in) :: on
        flag_value = merge(1.0_dp, 0.0_dp, on)
    end function flag_value

    pure subroutine history_add(self, name, n, index, initial, flags, per_point)
        class(history_t), intent(inout) :: self
        character(len=*), intent(in) :: name
        integer, intent(in) :: n
        !> The field's index in `field`.
        integer, intent(out) :: index
        real(dp), intent(in), optional :: initial
        logical, intent(in), optional :: flags, per_point
        type(history_field_t) :: f
        f%name = name
        if (present(initial)) f%initial = initial
        if (present(flags)) f%flags = flags
        if (present(per_point)) f%per_point = per_point
        allocate (f%last(n), f%trial(n))
        f%last = f%initial
        f%trial = f%initial
        if (.not. allocated(self%field)) allocate (self%field(0))
        self%field = [self%field, f]
        index = size(self%field)
    end subroutine history_add

    pure subroutine history_commit(self)
        class(history_t), intent(inout) :: self
        integer :: i
        if (.not. allocated(self%field)) return
        do i = 1, size(self%field)
            self%field(i)%last = self%field(i)%trial
        end do
    end subroutine history_commit

    pure subroutine history_reset_trial(self)
        class(history_t), intent(inout) :: self
        integer :: i
        if (.not. allocated(self%field)) return
        do i = 1, size(self%field)
            self%field(i)%trial = self%field(i)%last
        end do
    end subroutine history_reset_trial

    pure function history_items(self, most_points) result(items)
        class(history_t), intent(in) :: self
        !> The most points a restart may read (-1: as many as there are now).
        integer, intent(in) :: most_points
        type(history_item_t), allocatable :: items(:)
        integer :: i
        allocate (items(0))
        if (.not. allocated(self%field)) return
        deallocate (items)
        allocate (items(size(self%field)))
        do i = 1, size(self%field)
            associate (f => self%field(i))
                items(i)%name = f%name
                if (f%flags) then
                    items(i)%flags = nint(f%last)
                else
                    items(i)%values = f%last
                end if
                if (f%per_point) items(i)%most = most_points
            end associate
        end do
    end function history_items

    !> Every field named in `items` takes its values (of the field's length); the
    !> others keep theirs. The trial values follow.
    pure subroutine history_set_items(self, items, error)
        class(history_t), intent(inout) :: self
        type(history_item_t), intent(in) :: items(:)
        type(error_t), allocatable, intent(out) :: error
        integer :: i, j
        if (.not. allocated(self%field)) return
        do j = 1, size(items)
            do i = 1, size(self%field)
                if (trim(self%field(i)%name) /= trim(items(j)%name)) cycle
                call take(items(j), self%field(i), error)
                if (allocated(error)) return
            end do
        end do
        call self%reset_trial()
    end subroutine history_set_items

    pure subroutine take(item, f, error)
        type(history_item_t), intent(in) :: item
        type(history_field_t), intent(inout) :: f
        type(error_t), allocatable, intent(out) :: error
        logical :: fits
        if (f%flags) then
            fits = allocated(item%flags)
            if (fits) fits = size(item%flags) == size(f%last)
        else
            fits = allocated(item%values)
            if (fits) fits = size(item%values) == size(f%last)
        end if
        if (.not. fits) then
            call fatal_error(error, 'history '//trim(f%name)//': wrong length', error_code%input)
            return
        end if
        if (f%flags) then
            f%last = flag_value(item%flags /= 0)
        else
            f%last = item%values
        end if
    end subroutine take

    pure subroutine history_resize_points(self, n)
        class(history_t), intent(inout) :: self
        integer, intent(in) :: n
        integer :: i
        if (.not. allocated(self%field)) return
        do i = 1, size(self%field)
            associate (f => self%field(i))
                if (.not. f%per_point) cycle
                deallocate (f%last, f%trial)
                allocate (f%last(n), f%trial(n))
                f%last = f%initial
                f%trial = f%initial
            end associate
        end do
    end subroutine history_resize_points

    pure function history_values(self, name) result(values)
        class(history_t), intent(in) :: self
        character(len=*), intent(in) :: name
        real(dp), allocatable :: values(:)
        integer :: i
        allocate (values(0))
        if (.not. allocated(self%field)) return
        do i = 1, size(self%field)
            if (trim(self%field(i)%name) == name) values = self%field(i)%last
        end do
    end function history_values

end module voiga_contact_history
