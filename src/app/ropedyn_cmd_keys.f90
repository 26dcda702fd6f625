!> `ropedyn keys [GROUP]`: the keys of scene files from the key table, one a line
!! (tab-separated group, key, type, unit, default, allowed values, meaning); with GROUP
!! that group's only. tests/e2e/test_keys.py checks that
!! docs/reference/keys.md, written from the whole listing, is current.
module ropedyn_cmd_keys
    use, intrinsic :: iso_fortran_env, only: output_unit
    use ropedyn_error, only: error_t
    use ropedyn_cli, only: cli_t
    use ropedyn_help, only: print_help
    use ropedyn_text, only: text_t, append_text, name_hint, lower
    use ropedyn_scene, only: scene_key_listing
    use ropedyn_scene_keys, only: GROUP_NAMES, group_index
    implicit none
    private
    public :: keys_command

contains

    subroutine keys_command(cli, err)
        type(cli_t), intent(inout) :: cli
        type(error_t), allocatable, intent(out) :: err
        type(text_t), allocatable :: lines(:), groups(:)
        character(len=:), allocatable :: group
        integer :: k
        do while (cli%next())
            select case (cli%option)
            case ('--help', '-h')
                call cli%flag(err)
                if (allocated(err)) return
                call print_help('keys', output_unit)
                return
            case default
                call cli%positional('group', group, err)
            end select
            if (allocated(err)) return
        end do
        if (allocated(group)) then
            ! group names are case-insensitive, as in a scene file
            if (group_index(lower(group)) == 0) then
                allocate (groups(0))
                do k = 1, size(GROUP_NAMES)
                    call append_text(groups, trim(GROUP_NAMES(k)))
                end do
                call cli%usage_error('no group "'//group//'"'// &
                                     name_hint(groups, group, 'groups'), err)
                return
            end if
            lines = scene_key_listing(lower(group))
        else
            lines = scene_key_listing()
        end if
        do k = 1, size(lines)
            write (output_unit, '(a)') lines(k)%s
        end do
    end subroutine keys_command
end module ropedyn_cmd_keys
