!> `ropedyn statics SCENE.nml [options]`: the static equilibrium of a scene, and the command
!! line shared with `ropedyn modes` (docs/statics-modes.md).
!!
!!   ropedyn statics SCENE.nml [--set group.key=value ...] [-o FILE.h5] [--max-iterations N]
module ropedyn_cmd_statics
    use, intrinsic :: iso_fortran_env, only: output_unit
    use ropedyn_error, only: error_t
    use ropedyn_cli, only: cli_t
    use ropedyn_text, only: text_t, append_text, text_array
    use ropedyn_scene, only: scene_t, read_scene
    use ropedyn_statics, only: statics_options_t
    use ropedyn_analysis, only: run_analysis, DEFAULT_MODE_COUNT
    implicit none
    private
    public :: statics_command, analysis_command, analysis_usage

contains

    subroutine statics_command(cli, err)
        type(cli_t), intent(inout) :: cli
        type(error_t), allocatable, intent(out) :: err
        call analysis_command('statics', cli, err)
    end subroutine statics_command

    !> Read the options and the scene of `ropedyn statics|modes` and run the analysis.
    subroutine analysis_command(command, cli, err)
        character(len=*), intent(in) :: command   !< 'statics' or 'modes'
        type(cli_t), intent(inout) :: cli
        type(error_t), allocatable, intent(out) :: err
        type(text_t), allocatable :: overrides(:)
        character(len=:), allocatable :: scene_path, out_path, value
        type(statics_options_t) :: options
        type(scene_t) :: scene
        integer :: count

        allocate (overrides(0))
        count = DEFAULT_MODE_COUNT
        out_path = ''
        do while (cli%next())
            select case (cli%option)
            case ('--help', '-h')
                call analysis_usage(command)
                return
            case ('--no-continuation')
                options%continuation = .false.
            case ('--set')
                call cli%take_value(value, err)
                if (allocated(err)) return
                call append_text(overrides, value)
            case ('-o', '--output')
                call cli%take_value(out_path, err)
                if (allocated(err)) return
            case ('--count')
                if (command /= 'modes') then
                    call cli%usage_error('--count is an option of "ropedyn modes"', err)
                    return
                end if
                call cli%int_value(count, 1, err)
                if (allocated(err)) return
            case ('--max-iterations')
                call cli%int_value(options%max_iterations, 1, err)
                if (allocated(err)) return
            case default
                call cli%positional('scene file', scene_path, err)
                if (allocated(err)) return
            end select
        end do
        if (.not. allocated(scene_path)) then
            call cli%usage_error('needs a scene file', err)
            return
        end if
        call read_scene(scene_path, text_array(overrides), scene, err)
        if (allocated(err)) return
        call run_analysis(command, scene, options, count, out_path, err)
    end subroutine analysis_command

    !> Help of `ropedyn statics` or `ropedyn modes`.
    subroutine analysis_usage(command)
        character(len=*), intent(in) :: command
        if (command == 'modes') then
            write (output_unit, '(a)') 'usage: ropedyn modes SCENE.nml [--count K] '// &
                '[--set group.key=value ...] [-o FILE.h5] [--max-iterations N]'
            write (output_unit, '(a)') 'The lowest K (default 10) natural frequencies and '// &
                'mode shapes about the static equilibrium'
            write (output_unit, '(a)') '(undamped, linearized), printed and written to '// &
                'FILE.h5 (default out/<scene>_modes.h5).'
        else
            write (output_unit, '(a)') 'usage: ropedyn statics SCENE.nml '// &
                '[--set group.key=value ...] [-o FILE.h5] [--max-iterations N]'
            write (output_unit, '(a)') 'The static equilibrium of the scene (started from '// &
                'its &initial shape), printed and'
            write (output_unit, '(a)') 'written to FILE.h5 (default out/<scene>_statics.h5).'
        end if
        write (output_unit, '(a)') '  --max-iterations N  limit of the equilibrium iteration '// &
            '(default 2000)'
        write (output_unit, '(a)') '  --no-continuation   solve directly even when the bottom '// &
            'anchor is far from the start'
        write (output_unit, '(a)') 'exit codes: 0 ok, 2 bad input, 3 no equilibrium or '// &
            'solver failure, 4 output error'
        write (output_unit, '(a)') 'See docs/statics-modes.md.'
    end subroutine analysis_usage

end module ropedyn_cmd_statics
