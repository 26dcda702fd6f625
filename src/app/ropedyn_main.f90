!> ropedyn: command-line driver. One module per subcommand (src/app/ropedyn_cmd_*.f90);
!! this program only dispatches and turns an error into its message and exit code.
!!
!!   ropedyn run SCENE.nml [--set group.key=value ...]
!!   ropedyn testset PROBLEM|all [--method M] [--rtol R] [--atol A] [--max-order K]
!!                   [--repeat-time S] [--csv]      (docs/reference/cli.md)
!!   ropedyn testset --list
!!   ropedyn sweep SWEEP.nml [--jobs N | --task LIST | --summary | --list | --count | --status]
!!                   [--force] [--quiet] [--output-dir DIR]   (docs/reference/cli.md)
!!   ropedyn statics SCENE.nml [--set ...] [-o FILE.h5] [--max-iterations N]
!!   ropedyn modes SCENE.nml [--count K] [--set ...] [-o FILE.h5]  (docs/reference/cli.md)
!!   ropedyn keys              (every key of a scene file with its default; docs/reference/keys.md)
!!   ropedyn --version | --help
!!
!! Exit codes: 0 success, 2 bad input or command line, 3 integration failed,
!! 4 output could not be written, 5 internal error, 130 stopped by SIGINT/SIGTERM.
program ropedyn_main
    use, intrinsic :: iso_fortran_env, only: error_unit, output_unit
    use ropedyn_error, only: error_t, make_error, ERR_USAGE, exit_code_of
    use ropedyn_version, only: version_string
    use ropedyn_text, only: name_hint, text_t, append_text, printable
    use ropedyn_cli, only: cli_t, cli_from_command_line
    use ropedyn_cmd_run, only: run_command
    use ropedyn_cmd_testset, only: testset_command
    use ropedyn_cmd_sweep, only: sweep_command
    use ropedyn_help, only: print_help
    use ropedyn_cmd_statics, only: analysis_command
    use ropedyn_cmd_modes, only: modes_command
    use ropedyn_cmd_keys, only: keys_command
    implicit none

    type(cli_t) :: cli
    type(error_t), allocatable :: err
    character(len=4096) :: exe

    cli = cli_from_command_line()
    select case (cli%command)
    case ('')
        call print_help('ropedyn', error_unit)
        call make_error(err, ERR_USAGE, 'no command given (see ropedyn --help)')
    case ('--version', 'version', '--help', '-h', 'help')
        if (cli%count() > 0) then
            call make_error(err, ERR_USAGE, cli%command//' takes no arguments ("'// &
                            cli%args(1)%s//'") (see ropedyn --help)')
        else if (cli%command == '--version' .or. cli%command == 'version') then
            write (output_unit, '(a)') 'ropedyn '//version_string
        else
            call print_help('ropedyn', output_unit)
        end if
    case ('run')
        call run_command(cli, err)
    case ('testset')
        call testset_command(cli, err)
    case ('sweep')
        call get_command_argument(0, exe)
        call sweep_command(cli, trim(exe), err)
    case ('statics')
        call analysis_command('statics', cli, err)
    case ('modes')
        call modes_command(cli, err)
    case ('keys')
        call keys_command(cli, err)
    case default
        call make_error(err, ERR_USAGE, 'unknown command "'//cli%command//'"'// &
                        name_hint(commands(), cli%command, 'commands')//' (see ropedyn --help)')
    end select
    if (allocated(err)) then
        ! one line whatever an argument held (a newline, CR, an invisible character)
        write (error_unit, '(a)') 'ropedyn: error: '//printable(err%message)
        stop exit_code_of(err%code), quiet=.true.
    end if

contains

    !> The subcommands, for a near miss's hint.
    function commands() result(list)
        type(text_t), allocatable :: list(:)
        character(len=*), parameter :: NAMES(*) = [character(len=7) :: 'run', 'sweep', &
            'statics', 'modes', 'testset', 'keys', 'version', 'help']
        integer :: k
        allocate (list(0))
        do k = 1, size(NAMES)
            call append_text(list, trim(NAMES(k)))
        end do
    end function commands
end program ropedyn_main
