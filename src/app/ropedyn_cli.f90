!> The command line of a subcommand: its arguments one at a time, `--option value` and
!! `--option=value`, and usage errors that point to the subcommand's help.
module ropedyn_cli
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t, make_error, ERR_USAGE
    use ropedyn_text, only: int_text, text_t, append_text, text_array
    use ropedyn_scene, only: override_target
    implicit none
    private
    public :: cli_t, cli_from_command_line

    type :: cli_t
        character(len=:), allocatable :: command  !< the subcommand, for messages
        type(text_t), allocatable :: args(:)      !< arguments after the subcommand
        integer :: next_index = 1
        character(len=:), allocatable :: arg      !< the current argument as given
        character(len=:), allocatable :: option   !< ... without an '=value' part
        character(len=:), allocatable :: inline   !< the '=value' part of '--option=value'
        logical :: has_inline = .false.
        character(len=:), allocatable :: value    !< the value taken last (`take_value`)
        !> what `scene_argument` took: the scene file (not allocated until given) and the
        !! `--set group.key=value` overrides in the order given
        character(len=:), allocatable :: scene_path
        type(text_t), allocatable :: overrides(:)
    contains
        procedure :: next => cli_next
        procedure :: take_value => cli_take_value
        procedure :: flag => cli_flag
        procedure :: usage_error => cli_usage_error
        procedure :: real_value => cli_real_value
        procedure :: int_value => cli_int_value
        procedure :: count => cli_count
        procedure :: positional => cli_positional
        procedure :: scene_argument => cli_scene_argument
        procedure :: scene_overrides => cli_scene_overrides
        procedure :: require => cli_require
    end type cli_t

contains

    !> The arguments after the subcommand (argument 1) of this process.
    function cli_from_command_line() result(cli)
        type(cli_t) :: cli
        integer :: k, n, length
        n = command_argument_count()
        allocate (cli%args(max(0, n - 1)))
        if (n >= 1) then
            call get_command_argument(1, length=length)
            allocate (character(len=length) :: cli%command)
            call get_command_argument(1, cli%command)
        else
            cli%command = ''
        end if
        do k = 2, n
            call get_command_argument(k, length=length)
            allocate (character(len=length) :: cli%args(k - 1)%s)
            call get_command_argument(k, cli%args(k - 1)%s)
        end do
    end function cli_from_command_line

    !> Number of arguments after the subcommand.
    pure integer function cli_count(self)
        class(cli_t), intent(in) :: self
        cli_count = size(self%args)
    end function cli_count

    !> Move to the next argument; false when there is none. `option` is the argument, or
    !! for '--name=value' the '--name' part (the value is then taken by `take_value`).
    logical function cli_next(self) result(more)
        class(cli_t), intent(inout) :: self
        integer :: eq
        more = self%next_index <= size(self%args)
        if (.not. more) return
        self%arg = self%args(self%next_index)%s
        self%next_index = self%next_index + 1
        self%option = self%arg
        self%has_inline = .false.
        eq = index(self%arg, '=')
        if (len(self%arg) > 2 .and. eq > 3) then
            if (self%arg(1:2) == '--') then
                self%option = self%arg(:eq - 1)
                self%inline = self%arg(eq + 1:)
                self%has_inline = .true.
            end if
        end if
    end function cli_next

    !> The value of the current option: after '=' or the next argument.
    subroutine cli_take_value(self, value, err)
        class(cli_t), intent(inout) :: self
        character(len=:), allocatable, intent(out) :: value
        type(error_t), allocatable, intent(out) :: err
        if (self%has_inline) then
            value = self%inline
        else if (self%next_index > size(self%args)) then
            call self%usage_error(self%option//' needs a value', err)
            return
        else
            value = self%args(self%next_index)%s
            self%next_index = self%next_index + 1
        end if
        self%value = value
    end subroutine cli_take_value

    !> The current option is a flag, which takes no value: '--flag=value' is a usage error
    !! (a value there would be ignored, and '--force=no' would force).
    subroutine cli_flag(self, err)
        class(cli_t), intent(in) :: self
        type(error_t), allocatable, intent(out) :: err
        if (self%has_inline) call self%usage_error(self%option//' takes no value ("'// &
            self%arg//'"): give '//self%option//' alone, or leave it out', err)
    end subroutine cli_flag

    !> A usage error: 'COMMAND: message (see ropedyn COMMAND --help)'.
    subroutine cli_usage_error(self, message, err)
        class(cli_t), intent(in) :: self
        character(len=*), intent(in) :: message
        type(error_t), allocatable, intent(out) :: err
        call make_error(err, ERR_USAGE, self%command//': '//message//' (see ropedyn '// &
                        self%command//' --help)')
    end subroutine cli_usage_error

    !> The current argument as the one file the subcommand takes (`what`, e.g. 'scene
    !! file'): an empty argument, an option the subcommand does not know or a second file is
    !! a usage error.
    subroutine cli_positional(self, what, path, err)
        class(cli_t), intent(in) :: self
        character(len=*), intent(in) :: what
        character(len=:), allocatable, intent(inout) :: path
        type(error_t), allocatable, intent(out) :: err
        if (len(self%arg) == 0) then
            call self%usage_error('empty argument', err)
        else if (self%arg(1:1) == '-') then
            call self%usage_error('unknown option "'//self%arg//'"', err)
        else if (allocated(path)) then
            call self%usage_error('more than one '//what//': "'//path//'", "'//self%arg//'"', &
                                  err)
        else
            path = self%arg
        end if
    end subroutine cli_positional

    !> The arguments of a command that reads a scene, other than its own options:
    !! `--set group.key=value` (appended to self%overrides, its 'group.key' as the scene
    !! reads it: `--set ' OUTPUT.File = x'` is `output.file=x`) or the scene file
    !! (self%scene_path).
    subroutine cli_scene_argument(self, err)
        class(cli_t), intent(inout) :: self
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: value
        if (self%option == '--set') then
            call self%take_value(value, err)
            if (allocated(err)) return
            ! as the scene reads it: 'group.key' in lower case, without blanks around it
            if (len(override_target(value)) > 0) value = override_target(value)//'='// &
                trim(adjustl(value(index(value, '=') + 1:)))
            call append_text(self%overrides, value)
        else
            call self%positional('scene file', self%scene_path, err)
        end if
    end subroutine cli_scene_argument

    !> The `--set` overrides taken so far, in order (none: an empty list).
    pure function cli_scene_overrides(self) result(list)
        class(cli_t), intent(in) :: self
        character(len=:), allocatable :: list(:)
        if (allocated(self%overrides)) then
            list = text_array(self%overrides)
        else
            allocate (character(len=1) :: list(0))
        end if
    end function cli_scene_overrides

    !> A usage error 'needs WHAT' unless `path` was given.
    subroutine cli_require(self, path, what, err)
        class(cli_t), intent(in) :: self
        character(len=:), allocatable, intent(in) :: path
        character(len=*), intent(in) :: what
        type(error_t), allocatable, intent(out) :: err
        if (.not. allocated(path)) call self%usage_error('needs '//what, err)
    end subroutine cli_require

    !> The current option's value as a real number.
    subroutine cli_real_value(self, x, err)
        class(cli_t), intent(inout) :: self
        real(wp), intent(out) :: x
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: text
        integer :: ios
        x = 0.0_wp
        call self%take_value(text, err)
        if (allocated(err)) return
        ios = 1
        if (len_trim(text) > 0 .and. verify(trim(text), '0123456789.+-eEdD') == 0) &
            read (text, *, iostat=ios) x
        if (ios /= 0) call self%usage_error(self%option//' "'//text//'": not a number', err)
    end subroutine cli_real_value

    !> The current option's value as a whole number >= lowest.
    subroutine cli_int_value(self, n, lowest, err)
        class(cli_t), intent(inout) :: self
        integer, intent(out) :: n
        integer, intent(in) :: lowest
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: text
        integer :: ios
        n = 0
        call self%take_value(text, err)
        if (allocated(err)) return
        ios = 1
        if (len_trim(text) > 0 .and. len_trim(text) < 10 .and. &
            verify(trim(text), '0123456789+-') == 0) read (text, *, iostat=ios) n
        if (ios /= 0 .or. n < lowest) call self%usage_error(self%option//' "'//text// &
            '": expected a whole number >= '//int_text(lowest), err)
    end subroutine cli_int_value
end module ropedyn_cli
