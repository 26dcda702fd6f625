!> `ropedyn keys`: the keys of scene files from the key table, one a line (tab-separated
!! group, key, type, unit, default, allowed values, meaning). tests/e2e/test_keys.py checks
!! that docs/reference/keys.md, written from this listing, is current.
module ropedyn_cmd_keys
    use, intrinsic :: iso_fortran_env, only: output_unit
    use ropedyn_error, only: error_t
    use ropedyn_cli, only: cli_t
    use ropedyn_help, only: print_help
    use ropedyn_text, only: text_t
    use ropedyn_scene, only: scene_key_listing
    implicit none
    private
    public :: keys_command

contains

    subroutine keys_command(cli, err)
        type(cli_t), intent(inout) :: cli
        type(error_t), allocatable, intent(out) :: err
        type(text_t), allocatable :: lines(:)
        integer :: k
        do while (cli%next())
            select case (cli%option)
            case ('--help', '-h')
                call print_help('keys', output_unit)
                return
            case default
                call cli%usage_error('unexpected argument "'//cli%arg//'"', err)
            end select
            if (allocated(err)) return
        end do
        lines = scene_key_listing()
        do k = 1, size(lines)
            write (output_unit, '(a)') lines(k)%s
        end do
    end subroutine keys_command
end module ropedyn_cmd_keys
