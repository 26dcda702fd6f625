!> ropedyn: command-line driver.
!!
!!   ropedyn run SCENE.nml [--set group.key=value ...]
!!   ropedyn --version | --help
!!
!! Exit codes: 0 success, 2 bad input or command line, 3 integration failed,
!! 4 output could not be written, 5 internal error.
program ropedyn_main
    use, intrinsic :: iso_fortran_env, only: error_unit, output_unit
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t, make_error, ERR_USAGE, exit_code_of
    use ropedyn_scene, only: scene_t, read_scene
    use ropedyn_simulation, only: run_summary_t, run_scene
    use ropedyn_version, only: version_string
    implicit none

    character(len=:), allocatable :: command, scene_path
    character(len=1024), allocatable :: overrides(:)
    type(error_t), allocatable :: err
    type(scene_t) :: scene
    type(run_summary_t) :: summary
    integer :: nargs, i, n_over
    character(len=1024) :: arg

    nargs = command_argument_count()
    if (nargs < 1) then
        call usage(error_unit)
        call fail_usage('no command given')
    end if
    call get_command_argument(1, arg)
    command = trim(arg)
    select case (command)
    case ('--version', 'version')
        write (output_unit, '(a)') 'ropedyn '//version_string
        stop
    case ('--help', '-h', 'help')
        call usage(output_unit)
        stop
    case ('run')
    case default
        call fail_usage('unknown command "'//command//'"')
    end select

    allocate (overrides(nargs))
    n_over = 0
    i = 2
    do while (i <= nargs)
        call get_command_argument(i, arg)
        if (arg == '--set') then
            if (i == nargs) call fail_usage('--set needs group.key=value')
            call get_command_argument(i + 1, arg)
            n_over = n_over + 1
            overrides(n_over) = arg
            i = i + 2
        else if (arg(1:6) == '--set=') then
            n_over = n_over + 1
            overrides(n_over) = arg(7:)
            i = i + 1
        else if (arg(1:1) == '-') then
            call fail_usage('unknown option "'//trim(arg)//'"')
        else
            if (allocated(scene_path)) call fail_usage('more than one scene file: "'// &
                                                       scene_path//'", "'//trim(arg)//'"')
            scene_path = trim(arg)
            i = i + 1
        end if
    end do
    if (.not. allocated(scene_path)) call fail_usage('run needs a scene file')

    call read_scene(scene_path, overrides(1:n_over), scene, err)
    if (allocated(err)) call fail(err)

    call run_scene(scene, summary, err)
    if (summary%records > 0) call print_summary(summary)
    if (allocated(err)) call fail(err)

contains

    subroutine print_summary(s)
        type(run_summary_t), intent(in) :: s
        real(wp) :: e0, drift
        e0 = s%initial_energy%balance()
        drift = s%final_energy%balance() - e0
        write (output_unit, '(a)') 'ropedyn '//version_string//': '//trim(scene%model%kind)// &
            ' model, '//trim(scene%solver%method)//' solver, scene '//scene%path
        write (output_unit, '(a, i0, a, es10.3, a, f9.4, a)') '  elements        ', &
            scene%model%elements, '   rtol ', scene%solver%rtol, '   t = ', s%t_reached, ' s'
        write (output_unit, '(a, i0, a, i0, a, i0, a, i0)') '  steps           ', &
            s%stats%steps, '   rhs evals ', s%stats%rhs_evals, '   jacobians ', &
            s%stats%jac_evals, '   error-test fails ', s%stats%err_test_fails
        write (output_unit, '(a, f10.4, a)') '  cpu time        ', s%cpu_time, ' s'
        write (output_unit, '(a, 5(es13.5))') '  energy (J)      kinetic, elastic, '// &
            'gravity, dissipated, total:'
        write (output_unit, '(a, 5(es13.5))') '                  ', s%final_energy%kinetic, &
            s%final_energy%elastic, s%final_energy%gravity, s%final_energy%dissipated, &
            s%final_energy%total()
        write (output_unit, '(a, es13.5, a, es10.2, a)') '  E0              ', e0, &
            ' J   balance error (T+V+dissipated-E0) ', drift, ' J'
        write (output_unit, '(a)') '  output          '//s%file
    end subroutine print_summary

    subroutine usage(unit)
        integer, intent(in) :: unit
        write (unit, '(a)') 'usage: ropedyn run SCENE.nml [--set group.key=value ...]'
        write (unit, '(a)') '       ropedyn --version | --help'
        write (unit, '(a)') 'exit codes: 0 ok, 2 bad input, 3 integration failed, '// &
            '4 output error, 5 internal error'
        write (unit, '(a)') 'input reference: docs/input.md'
    end subroutine usage

    subroutine fail_usage(message)
        character(len=*), intent(in) :: message
        type(error_t), allocatable :: uerr
        call make_error(uerr, ERR_USAGE, message//' (see ropedyn --help)')
        call fail(uerr)
    end subroutine fail_usage

    subroutine fail(e)
        type(error_t), intent(in) :: e
        write (error_unit, '(a)') 'ropedyn: error: '//e%message
        stop exit_code_of(e%code), quiet=.true.
    end subroutine fail
end program ropedyn_main
