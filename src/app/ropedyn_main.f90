!> ropedyn: command-line driver.
!!
!!   ropedyn run SCENE.nml [--set group.key=value ...]
!!   ropedyn testset PROBLEM|all [--method M] [--rtol R] [--atol A] [--max-order K]
!!                   [--repeat-time S] [--csv]      (docs/testset.md)
!!   ropedyn testset --list
!!   ropedyn sweep SWEEP.nml [--jobs N | --task K | --summary | --list | --count]
!!                   [--force] [--quiet] [--output-dir DIR]   (docs/sweeps.md)
!!   ropedyn statics SCENE.nml [--set ...] [-o FILE.h5] [--max-iterations N]
!!   ropedyn modes SCENE.nml [--count K] [--set ...] [-o FILE.h5]  (docs/statics-modes.md)
!!   ropedyn --version | --help
!!
!! Exit codes: 0 success, 2 bad input or command line, 3 integration failed,
!! 4 output could not be written, 5 internal error.
program ropedyn_main
    use, intrinsic :: iso_fortran_env, only: error_unit, output_unit
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t, make_error, ERR_USAGE, ERR_SOLVER, exit_code_of
    use ropedyn_scene, only: scene_t, read_scene
    use ropedyn_simulation, only: run_summary_t, run_scene
    use ropedyn_version, only: version_string
    use ropedyn_solvers, only: method_names
    use ropedyn_testset, only: testset_problem_t, new_testset_problem, testset_names, &
                               testset_name_list
    use ropedyn_testset_driver, only: testset_run_t, run_testset, DEFAULT_REPEAT_TIME
    use ropedyn_sweep_runner, only: sweep_command
    use ropedyn_analysis, only: analysis_command
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
    case ('testset')
        call testset_command()
        stop
    case ('sweep')
        call run_sweep_command()
        stop
    case ('statics', 'modes')
        call run_analysis_command()
        stop
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
        write (unit, '(a)') '       ropedyn testset PROBLEM|all [--method cvode|mebdf] '// &
            '[--rtol R] [--atol A]'
        write (unit, '(a)') '                       [--max-order K] [--repeat-time SECONDS] '// &
            '[--csv]'
        write (unit, '(a)') '       ropedyn testset --list'
        write (unit, '(a)') '       ropedyn sweep SWEEP.nml [--jobs N | --task K | --summary '// &
            '| --list | --count] ...'
        write (unit, '(a)') '       ropedyn statics SCENE.nml [--set ...] [-o FILE.h5] '// &
            '[--max-iterations N]'
        write (unit, '(a)') '       ropedyn modes SCENE.nml [--count K] [--set ...] [-o FILE.h5]'
        write (unit, '(a)') '       ropedyn --version | --help'
        write (unit, '(a)') 'exit codes: 0 ok, 2 bad input, 3 integration failed, '// &
            '4 output error, 5 internal error'
        write (unit, '(a)') 'input reference: docs/input.md; test problems: docs/testset.md '// &
            '(ropedyn testset --help)'
    end subroutine usage

    subroutine testset_usage(unit)
        integer, intent(in) :: unit
        write (unit, '(a)') 'usage: ropedyn testset PROBLEM|all [options]   '// &
            '(ropedyn testset --list: the problems)'
        write (unit, '(a)') 'Solves a stiff problem of the Bari Test Set for IVP Solvers '// &
            'from t0 to t_end'
        write (unit, '(a)') 'and compares with its reference solution (docs/testset.md).'
        write (unit, '(a)') '  --method M          integrator: cvode (default) or mebdf'
        write (unit, '(a)') '  --rtol R            relative tolerance, 0 < R < 1 '// &
            '(default 1e-6)'
        write (unit, '(a)') '  --atol A            absolute tolerance, A > 0 (default: '// &
            'the test-set rule:'
        write (unit, '(a)') '                      atol = rtol; ROBER atol = 1e-6 rtol; '// &
            'E5 atol = 1.7e-24)'
        write (unit, '(a)') '  --max-order K       highest order (0 = method default: '// &
            'cvode 5, mebdf 4)'
        write (unit, '(a, f3.1, a)') '  --repeat-time S     repeat until S s of CPU time '// &
            '(default ', DEFAULT_REPEAT_TIME, '; 0: one run);'
        write (unit, '(a)') '                      the median CPU time per run is reported'
        write (unit, '(a)') '  --csv               one header line and one line per problem'
        write (unit, '(a)') 'Accuracy: scd = -log10 max |y - yref|/|yref| (|yref| >= 1e-200), '// &
            'mescd = -log10 max'
        write (unit, '(a)') '|y - yref|/(atol/rtol + |yref|); E5 is judged by mescd.'
        write (unit, '(a)') 'exit codes: 0 ok, 2 bad arguments, 3 integration failed'
    end subroutine testset_usage

    !> ropedyn statics|modes SCENE.nml [options]: ropedyn_analysis does the work.
    subroutine run_analysis_command()
        character(len=1024), allocatable :: analysis_args(:)
        type(error_t), allocatable :: aerr
        integer :: k
        allocate (analysis_args(nargs - 1))
        do k = 2, nargs
            call get_command_argument(k, analysis_args(k - 1))
        end do
        call analysis_command(command, analysis_args, aerr)
        if (allocated(aerr)) call fail(aerr)
    end subroutine run_analysis_command

    !> ropedyn sweep SWEEP.nml [options]: ropedyn_sweep_runner does the work.
    subroutine run_sweep_command()
        character(len=4096), allocatable :: sweep_args(:)
        character(len=4096) :: exe
        type(error_t), allocatable :: serr
        integer :: k
        allocate (sweep_args(nargs - 1))
        do k = 2, nargs
            call get_command_argument(k, sweep_args(k - 1))
        end do
        call get_command_argument(0, exe)
        call sweep_command(sweep_args, trim(exe), serr)
        if (allocated(serr)) call fail(serr)
    end subroutine run_sweep_command

    !> ropedyn testset PROBLEM|all [options] | --list
    subroutine testset_command()
        character(len=:), allocatable :: problem_name, method, option, value
        class(testset_problem_t), allocatable :: problem
        type(testset_run_t) :: result
        type(error_t), allocatable :: terr
        real(wp) :: rtol, atol, repeat_time
        integer :: max_order, k, first, last, failures, eq
        logical :: have_atol, csv, list, has_value

        method = 'cvode'
        rtol = 1.0e-6_wp
        atol = 0.0_wp
        have_atol = .false.
        max_order = 0
        repeat_time = DEFAULT_REPEAT_TIME
        csv = .false.
        list = .false.
        i = 2
        do while (i <= nargs)
            call get_command_argument(i, arg)
            i = i + 1
            option = trim(arg)
            has_value = .false.
            eq = index(option, '=')
            if (option(1:min(2, len(option))) == '--' .and. eq > 0) then
                value = option(eq + 1:)
                option = option(1:eq - 1)
                has_value = .true.
            end if
            select case (option)
            case ('--help', '-h')
                call testset_usage(output_unit)
                stop
            case ('--list')
                list = .true.
            case ('--csv')
                csv = .true.
            case ('--method', '--rtol', '--atol', '--max-order', '--repeat-time')
                if (.not. has_value) then
                    if (i > nargs) call fail_usage('testset: '//option//' needs a value')
                    call get_command_argument(i, arg)
                    i = i + 1
                    value = trim(arg)
                end if
                select case (option)
                case ('--method')
                    if (.not. any(method_names == value)) call fail_usage('testset: '// &
                        '--method "'//value//'": unknown method (available: cvode, mebdf)')
                    method = value
                case ('--rtol')
                    rtol = real_value(option, value)
                    if (.not. (rtol > 0.0_wp .and. rtol < 1.0_wp)) call fail_usage( &
                        'testset: --rtol '//value//': must be > 0 and < 1')
                case ('--atol')
                    atol = real_value(option, value)
                    if (.not. (atol > 0.0_wp)) call fail_usage('testset: --atol '//value// &
                                                             ': must be > 0')
                    have_atol = .true.
                case ('--max-order')
                    max_order = integer_value(option, value)
                case ('--repeat-time')
                    repeat_time = real_value(option, value)
                    if (.not. (repeat_time >= 0.0_wp .and. repeat_time <= 3600.0_wp)) &
                        call fail_usage('testset: --repeat-time '//value// &
                                        ': must be 0 .. 3600 s')
                end select
            case default
                if (len(option) == 0) call fail_usage('testset: empty argument')
                if (option(1:1) == '-') call fail_usage('testset: unknown option "'// &
                                                        trim(arg)//'"')
                if (allocated(problem_name)) call fail_usage('testset: more than one '// &
                    'problem: "'//problem_name//'", "'//option//'"')
                problem_name = option
            end select
        end do

        if (list) then
            call list_problems()
            return
        end if
        if (.not. allocated(problem_name)) call fail_usage('testset needs a problem name '// &
            'or "all" (available: '//testset_name_list()//')')
        if (problem_name == 'all' .or. problem_name == 'ALL') then
            first = 1
            last = size(testset_names)
        else
            call new_testset_problem(problem_name, problem, terr)
            if (allocated(terr)) call fail_usage('testset: '//terr%message)
            first = 0
            last = 0
        end if

        if (csv) call write_csv_header()
        failures = 0
        do k = first, last
            if (k > 0) then
                call new_testset_problem(testset_names(k), problem, terr)
                if (allocated(terr)) call fail(terr)
            end if
            if (have_atol) then
                call run_testset(problem, method, rtol, result, terr, atol=atol, &
                                 max_order=max_order, repeat_time=repeat_time)
            else
                call run_testset(problem, method, rtol, result, terr, max_order=max_order, &
                                 repeat_time=repeat_time)
            end if
            if (allocated(terr)) then
                if (terr%code /= ERR_SOLVER) call fail_usage('testset: '//terr%message)
                failures = failures + 1
                if (first == 0) call fail(terr)
                write (error_unit, '(a)') 'ropedyn: error: '//terr%message
                cycle
            end if
            if (csv) then
                call write_csv_row(result)
            else
                if (k > first) write (output_unit, '(a)') ''
                call print_testset_result(problem, result, have_atol)
            end if
        end do
        if (failures > 0) then
            write (arg, '(i0, a, i0, a)') failures, ' of ', last - first + 1, &
                ' test problems failed'
            call make_error(terr, ERR_SOLVER, 'testset: '//trim(arg))
            call fail(terr)
        end if
    end subroutine testset_command

    subroutine list_problems()
        class(testset_problem_t), allocatable :: problem
        type(error_t), allocatable :: lerr
        integer :: k
        write (output_unit, '(a)') pad('problem', 8)//pad('n', 4)//pad('interval', 24)// &
            pad('atol rule', 22)//pad('measure', 9)//'description'
        do k = 1, size(testset_names)
            call new_testset_problem(testset_names(k), problem, lerr)
            if (allocated(lerr)) call fail(lerr)
            write (output_unit, '(a)') pad(problem%name, 8)//pad(itoa(problem%size()), 4)// &
                pad('t = '//number(problem%t0)//' .. '//number(problem%t_end), 24)// &
                pad(problem%atol_rule(), 22)//pad(merge('mescd', 'scd  ', problem%use_mescd), 9)// &
                problem%title
        end do
    end subroutine list_problems

    subroutine print_testset_result(problem, r, atol_given)
        class(testset_problem_t), intent(in) :: problem
        type(testset_run_t), intent(in) :: r
        logical, intent(in) :: atol_given
        character(len=:), allocatable :: rule
        write (output_unit, '(a, i0, a)') 'ropedyn testset '//problem%name//': '// &
            problem%title//', ', problem%size(), ' equations, t = '//number(problem%t0)// &
            ' .. '//number(problem%t_end)
        write (output_unit, '(a, i0, a)') '  method          '//r%method//' (max order ', &
            r%max_order, ')'
        if (atol_given) then
            rule = 'given'
        else
            rule = problem%atol_rule()
        end if
        write (output_unit, '(a)') '  rtol            '//number(r%rtol)//'   atol '// &
            atol_text(r)//' ('//rule//')'
        write (output_unit, '(a, f7.3, a, f7.3, a)') '  accuracy        scd ', r%scd, &
            '   mescd ', r%mescd, '   ('//trim(merge('mescd', 'scd  ', r%use_mescd))// &
            ' is the measure for this problem)'
        write (output_unit, '(a, i0, a, i0)') '  steps           ', r%stats%steps, &
            '   rejected (error test) ', r%stats%err_test_fails
        write (output_unit, '(a, i0, a, i0, a)') '  f evaluations   ', r%stats%rhs_evals, &
            '   (+ ', r%stats%jac_rhs_evals, ' for Jacobian differencing)'
        write (output_unit, '(a, i0, a, i0)') '  Jacobians       ', r%stats%jac_evals, &
            '   LU factorizations ', r%stats%lin_setups
        write (output_unit, '(a, i0, a, i0)') '  Newton          iterations ', &
            r%stats%nonlin_iters, '   convergence failures ', r%stats%nonlin_conv_fails
        if (any(r%stats%order_steps > 0)) write (output_unit, '(a, 7(1x, i0))') &
            '  steps at order 1..7', r%stats%order_steps
        write (output_unit, '(a, es10.3, a, i0, a)') '  cpu time        ', r%cpu_time, &
            ' s per run (median of ', r%runs, ' runs)'
    end subroutine print_testset_result

    subroutine write_csv_header()
        write (output_unit, '(a)') 'problem,method,rtol,atol,max_order,scd,mescd,measure,'// &
            'accuracy,steps,rejected,rhs_evals,jac_rhs_evals,jac_evals,lin_setups,'// &
            'nonlin_iters,nonlin_conv_fails,cpu_time,runs'
    end subroutine write_csv_header

    subroutine write_csv_row(r)
        type(testset_run_t), intent(in) :: r
        character(len=400) :: line
        write (line, '(9(a, ","), 8(i0, ","), es12.5, ",", i0)') r%problem, &
            r%method, number(r%rtol), atol_text(r), itoa(r%max_order), decimal(r%scd), &
            decimal(r%mescd), merge('mescd', 'scd  ', r%use_mescd), decimal(r%accuracy()), &
            r%stats%steps, r%stats%err_test_fails, r%stats%rhs_evals, r%stats%jac_rhs_evals, &
            r%stats%jac_evals, r%stats%lin_setups, r%stats%nonlin_iters, &
            r%stats%nonlin_conv_fails, r%cpu_time, r%runs
        write (output_unit, '(a)') remove_blanks(line)
    end subroutine write_csv_row

    !> The atol of a run: one number, or 'vector' when components differ.
    function atol_text(r) result(text)
        type(testset_run_t), intent(in) :: r
        character(len=:), allocatable :: text
        if (r%uniform_atol()) then
            text = number(r%atol(1))
        else
            text = 'vector'
        end if
    end function atol_text

    !> A real in short form: 321.8122, 60, 1.00000E-06.
    function number(x) result(text)
        real(wp), intent(in) :: x
        character(len=:), allocatable :: text
        character(len=32) :: buffer
        if (x == 0.0_wp) then
            text = '0'
        else if (abs(x) >= 1.0e-3_wp .and. abs(x) < 1.0e6_wp) then
            write (buffer, '(f0.10)') x
            text = trim(adjustl(buffer))
            do while (text(len(text):len(text)) == '0')
                text = text(1:len(text) - 1)
            end do
            if (text(len(text):len(text)) == '.') text = text(1:len(text) - 1)
            if (text(1:1) == '.') text = '0'//text
        else
            write (buffer, '(es12.5)') x
            text = trim(adjustl(buffer))
        end if
    end function number

    !> text, left-justified in a field of the given width (at least one blank after it).
    pure function pad(text, width) result(field)
        character(len=*), intent(in) :: text
        integer, intent(in) :: width
        character(len=max(width, len(text) + 1)) :: field
        field = text
    end function pad

    !> A real with 4 decimals: 2.5125, 0.5813, -0.1200.
    function decimal(x) result(text)
        real(wp), intent(in) :: x
        character(len=:), allocatable :: text
        character(len=32) :: buffer
        write (buffer, '(f0.4)') x
        text = trim(adjustl(buffer))
        if (text(1:1) == '.') then
            text = '0'//text
        else if (text(1:min(2, len(text))) == '-.') then
            text = '-0'//text(2:)
        end if
    end function decimal

    function itoa(n) result(text)
        integer, intent(in) :: n
        character(len=:), allocatable :: text
        character(len=16) :: buffer
        write (buffer, '(i0)') n
        text = trim(buffer)
    end function itoa

    pure function remove_blanks(text) result(out)
        character(len=*), intent(in) :: text
        character(len=:), allocatable :: out
        integer :: j
        out = ''
        do j = 1, len_trim(text)
            if (text(j:j) /= ' ') out = out//text(j:j)
        end do
    end function remove_blanks

    !> The value of a real option, or a usage error naming option and value.
    real(wp) function real_value(option, text) result(x)
        character(len=*), intent(in) :: option, text
        integer :: ios
        x = 0.0_wp
        ios = 1
        if (len_trim(text) > 0 .and. verify(trim(text), '0123456789.+-eEdD') == 0) then
            read (text, *, iostat=ios) x
        end if
        if (ios /= 0) call fail_usage('testset: '//option//' "'//text//'": not a number')
    end function real_value

    !> The value of an integer option, or a usage error naming option and value.
    integer function integer_value(option, text) result(n)
        character(len=*), intent(in) :: option, text
        integer :: ios
        n = 0
        ios = 1
        if (len_trim(text) > 0 .and. verify(trim(text), '0123456789+-') == 0) then
            read (text, *, iostat=ios) n
        end if
        if (ios /= 0) call fail_usage('testset: '//option//' "'//text//'": not an integer')
    end function integer_value

    subroutine fail_usage(message)
        character(len=*), intent(in) :: message
        type(error_t), allocatable :: uerr
        if (command == 'testset') then
            call make_error(uerr, ERR_USAGE, message//' (see ropedyn testset --help)')
        else
            call make_error(uerr, ERR_USAGE, message//' (see ropedyn --help)')
        end if
        call fail(uerr)
    end subroutine fail_usage

    subroutine fail(e)
        type(error_t), intent(in) :: e
        write (error_unit, '(a)') 'ropedyn: error: '//e%message
        stop exit_code_of(e%code), quiet=.true.
    end subroutine fail
end program ropedyn_main
