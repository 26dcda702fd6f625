!> Error objects returned by every procedure that can fail.
!!
!! Procedures take `type(error_t), allocatable, intent(out) :: err`; an unallocated
!! `err` means success. The class of an error maps to the process exit code in the
!! driver, so that batch scripts can tell bad input from a failed integration.
module ropedyn_error
    implicit none
    private
    public :: error_t, make_error
    public :: ERR_USAGE, ERR_INPUT, ERR_SOLVER, ERR_IO, ERR_INTERNAL, ERR_INTERRUPTED
    public :: exit_code_of

    !> Error classes. The exit codes of `ropedyn` are documented in docs/reference/exit-codes.md.
    integer, parameter :: ERR_USAGE = 1     !< bad command line
    integer, parameter :: ERR_INPUT = 2     !< bad scene file or override
    integer, parameter :: ERR_SOLVER = 3    !< integration failed
    integer, parameter :: ERR_IO = 4        !< output could not be written
    integer, parameter :: ERR_INTERNAL = 5  !< a bug: an invariant did not hold
    integer, parameter :: ERR_INTERRUPTED = 6  !< stopped by SIGINT or SIGTERM (exit 130)

    type :: error_t
        integer :: code = ERR_INTERNAL          !< one of the ERR_* classes
        character(len=:), allocatable :: message !< says where, what and which value
    end type error_t

contains

    !> Allocate `err` with a class and a message.
    subroutine make_error(err, code, message)
        type(error_t), allocatable, intent(out) :: err
        integer, intent(in) :: code
        character(len=*), intent(in) :: message
        allocate (err)
        err%code = code
        err%message = message
    end subroutine make_error

    !> Process exit code of an error class (0 is success).
    pure integer function exit_code_of(code) result(exit_code)
        integer, intent(in) :: code
        select case (code)
        case (ERR_USAGE, ERR_INPUT)
            exit_code = 2
        case (ERR_SOLVER)
            exit_code = 3
        case (ERR_IO)
            exit_code = 4
        case (ERR_INTERRUPTED)
            exit_code = 130
        case default
            exit_code = 5
        end select
    end function exit_code_of
end module ropedyn_error
