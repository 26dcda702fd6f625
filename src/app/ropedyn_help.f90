!> Help of the program and its subcommands: the texts of src/app/help/COMMAND.txt (compiled
!! into ropedyn_help_text by CMake), printed with their {name} placeholders filled in.
module ropedyn_help
    use ropedyn_text, only: text_t
    use ropedyn_help_text, only: help_text
    implicit none
    private
    public :: print_help

contains

    !> Print the help of `command` ('ropedyn' for the program) to `unit`; `{name}` stands
    !! for `value` where both are given.
    subroutine print_help(command, unit, name, value)
        character(len=*), intent(in) :: command
        integer, intent(in) :: unit
        character(len=*), intent(in), optional :: name, value
        type(text_t), allocatable :: lines(:)
        character(len=:), allocatable :: line
        integer :: k, at
        call help_text(command, lines)
        do k = 1, size(lines)
            line = lines(k)%s
            if (present(name) .and. present(value)) then
                at = index(line, '{'//name//'}')
                if (at > 0) line = line(:at - 1)//value//line(at + len(name) + 2:)
            end if
            write (unit, '(a)') line
        end do
    end subroutine print_help
end module ropedyn_help
