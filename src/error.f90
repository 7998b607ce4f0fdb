!> Error handling: anything that can fail takes `type(error_t), allocatable,
!> intent(out) :: error` as its last argument and allocates it on failure.
!> Callers test `if (allocated(error)) return` and pass it up; only `app/` and
!> `test/` turn an error into a message and an exit code.
module voiga_error
    implicit none
    private

    public :: error_t, fatal_error, error_code

    !> Exit codes and error categories.
    enum, bind(c)
        enumerator :: error_code_generic = 1
        !> Bad input: a malformed case file, an invalid value, a missing file.
        enumerator :: error_code_input = 2
        !> A numerical failure (divergence, singular matrix, inverted element).
        enumerator :: error_code_numeric = 3
    end enum

    !> Named error codes, used as `code=` in `fatal_error` and as process exit codes.
    type :: error_code_list
        integer :: generic = error_code_generic
        integer :: input = error_code_input
        integer :: numeric = error_code_numeric
    end type error_code_list

    !> The codes: `error_code%input` etc.
    type(error_code_list), parameter :: error_code = error_code_list()

    !> An error with a human-readable message naming its cause.
    type :: error_t
        !> Category, one of `error_code`.
        integer :: code = error_code_generic
        !> What went wrong, naming the file, group, variable or entity involved.
        character(len=:), allocatable :: message
    end type error_t

contains

    !> Allocate `error` with `message` (and a category, default generic).
    pure subroutine fatal_error(error, message, code)
        type(error_t), allocatable, intent(out) :: error
        character(len=*), intent(in) :: message
        integer, intent(in), optional :: code

        allocate (error)
        error%message = message
        if (present(code)) error%code = code
    end subroutine fatal_error

end module voiga_error
