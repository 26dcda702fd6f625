!> `ropedyn statics SCENE.nml [options]`: the static equilibrium of a scene, and the command
!! line shared with `ropedyn modes` (docs/guide/statics-modes.md).
!!
!!   ropedyn statics SCENE.nml [--set group.key=value ...] [-o FILE.h5] [--max-iterations N]
!!                             [--no-continuation] [--force]
module ropedyn_cmd_statics
    use, intrinsic :: iso_fortran_env, only: output_unit
    use ropedyn_error, only: error_t
    use ropedyn_cli, only: cli_t
    use ropedyn_help, only: print_help
    use ropedyn_scene, only: scene_t, read_scene
    use ropedyn_scene_warnings, only: print_warnings
    use ropedyn_statics, only: statics_options_t
    use ropedyn_analysis, only: run_analysis, DEFAULT_MODE_COUNT
    implicit none
    private
    public :: analysis_command

contains

    !> Read the options and the scene of `ropedyn statics|modes` and run the analysis.
    subroutine analysis_command(command, cli, err)
        character(len=*), intent(in) :: command   !< 'statics' or 'modes'
        type(cli_t), intent(inout) :: cli
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: out_path
        type(statics_options_t) :: options
        type(scene_t) :: scene
        integer :: count
        logical :: force

        count = DEFAULT_MODE_COUNT
        out_path = ''
        force = .false.
        do while (cli%next())
            select case (cli%option)
            case ('--help', '-h')
                call cli%flag(err)
                if (allocated(err)) return
                call print_help(command, output_unit)
                return
            case ('--no-continuation')
                call cli%flag(err)
                options%continuation = .false.
            case ('--force')
                call cli%flag(err)
                force = .true.
            case ('-o', '--output')
                if (len(out_path) > 0) then
                    call cli%usage_error(cli%option//' is given twice', err)
                else
                    call cli%take_value(out_path, err)
                end if
            case ('--count')
                if (command == 'modes') then
                    call cli%int_value(count, 1, err)
                else
                    call cli%usage_error('--count is an option of "ropedyn modes"', err)
                end if
            case ('--max-iterations')
                call cli%int_value(options%max_iterations, 1, err)
            case default
                call cli%scene_argument(err)
            end select
            if (allocated(err)) return
        end do
        call cli%require(cli%scene_path, 'a scene file', err)
        if (allocated(err)) return
        call read_scene(cli%scene_path, cli%scene_overrides(), scene, err)
        if (allocated(err)) return
        call print_warnings(scene)
        call run_analysis(command, scene, options, count, out_path, err, force)
    end subroutine analysis_command


end module ropedyn_cmd_statics
