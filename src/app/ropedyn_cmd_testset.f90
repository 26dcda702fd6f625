!> `ropedyn testset PROBLEM|all [options]` and `ropedyn testset --list`: the stiff test
!! problems of the Bari test set against their reference solutions (docs/theory/testset.md).
module ropedyn_cmd_testset
    use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t, make_error, ERR_SOLVER
    use ropedyn_text, only: int_text, real_text, fixed_text
    use ropedyn_methods, only: method_index
    use ropedyn_cli, only: cli_t
    use ropedyn_help, only: print_help
    use ropedyn_testset, only: testset_problem_t, new_testset_problem, testset_names, &
                               testset_name_list
    use ropedyn_testset_driver, only: testset_run_t, run_testset, DEFAULT_REPEAT_TIME, &
                                      methods_for
    implicit none
    private
    public :: testset_command

    !> The command line of `ropedyn testset`.
    type :: testset_options_t
        character(len=:), allocatable :: problem_name    !< a problem, or 'all'
        character(len=:), allocatable :: method
        real(wp) :: rtol = 1.0e-6_wp
        real(wp) :: atol = 0.0_wp
        logical :: have_atol = .false.
        integer :: max_order = 0                         !< 0: the method's own
        real(wp) :: repeat_time = DEFAULT_REPEAT_TIME    !< s of repeats for the CPU time
        logical :: csv = .false.
        logical :: list = .false.
        logical :: help = .false.                        !< --help (printed)
    end type testset_options_t

contains

    !> ropedyn testset PROBLEM|all [options] | --list
    subroutine testset_command(cli, err)
        type(cli_t), intent(inout) :: cli
        type(error_t), allocatable, intent(out) :: err
        type(testset_options_t) :: opts
        class(testset_problem_t), allocatable :: problem
        type(error_t), allocatable :: terr
        integer :: first, last

        call read_options(cli, opts, err)
        if (allocated(err) .or. opts%help) return
        if (opts%list) then
            if (allocated(opts%problem_name)) then
                call cli%usage_error('--list lists every problem: give no problem ("'// &
                                     opts%problem_name//'")', err)
                return
            end if
            call list_problems(err)
            return
        end if
        if (.not. allocated(opts%problem_name)) then
            call cli%usage_error('needs a problem name or "all" (available: '// &
                                 testset_name_list()//')', err)
            return
        end if
        if (opts%problem_name == 'all' .or. opts%problem_name == 'ALL') then
            first = 1
            last = size(testset_names)
        else
            call new_testset_problem(opts%problem_name, problem, terr)
            if (allocated(terr)) then
                call cli%usage_error(terr%message, err)
                return
            end if
            first = 0
            last = 0
        end if
        call run_problems(cli, opts, problem, first, last, err)
    end subroutine testset_command

    !> The command's options and its problem name (--help prints the help: opts%help).
    subroutine read_options(cli, opts, err)
        type(cli_t), intent(inout) :: cli
        type(testset_options_t), intent(inout) :: opts
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: value
        opts%method = 'cvode'
        do while (cli%next())
            select case (cli%option)
            case ('--help', '-h')
                call cli%flag(err)
                if (allocated(err)) return
                call print_help('testset', output_unit, 'default_repeat_time', &
                                real_text(DEFAULT_REPEAT_TIME, compact=.true.))
                opts%help = .true.
                return
            case ('--list')
                call cli%flag(err)
                opts%list = .true.
            case ('--csv')
                call cli%flag(err)
                opts%csv = .true.
            case ('--method')
                call cli%take_value(value, err)
                if (.not. allocated(err)) then
                    opts%method = value
                    if (method_index(value) == 0) call cli%usage_error('--method "'//value// &
                        '": unknown method (available: '//offered_methods()//')', err)
                end if
            case ('--rtol')
                call cli%real_value(opts%rtol, err)
                if (.not. allocated(err) .and. &
                    .not. (opts%rtol > 0.0_wp .and. opts%rtol < 1.0_wp)) &
                    call cli%usage_error('--rtol '//cli%value//': must be > 0 and < 1', err)
            case ('--atol')
                call cli%real_value(opts%atol, err)
                if (.not. allocated(err) .and. .not. (opts%atol > 0.0_wp)) &
                    call cli%usage_error('--atol '//cli%value//': must be > 0', err)
                opts%have_atol = .true.
            case ('--max-order')
                call cli%int_value(opts%max_order, 0, err)
            case ('--repeat-time')
                call cli%real_value(opts%repeat_time, err)
                if (.not. allocated(err) .and. &
                    .not. (opts%repeat_time >= 0.0_wp .and. opts%repeat_time <= 3600.0_wp)) &
                    call cli%usage_error('--repeat-time '//cli%value//': must be 0 .. 3600 s', err)
            case default
                call cli%positional('problem', opts%problem_name, err)
            end select
            if (allocated(err)) return
        end do
    end subroutine read_options

    !> The problems first .. last of the test set (0 .. 0: `problem`), each against its
    !! reference: a table each, or CSV rows; a failed integration is counted (and ends a
    !! single problem's run), bad settings are a usage error.
    subroutine run_problems(cli, opts, problem, first, last, err)
        type(cli_t), intent(inout) :: cli
        type(testset_options_t), intent(in) :: opts
        class(testset_problem_t), allocatable, intent(inout) :: problem
        integer, intent(in) :: first, last
        type(error_t), allocatable, intent(out) :: err
        type(testset_run_t) :: result
        type(error_t), allocatable :: terr
        integer :: k, failures
        if (opts%csv) call write_csv_header()
        failures = 0
        do k = first, last
            if (k > 0) then
                call new_testset_problem(testset_names(k), problem, err)
                if (allocated(err)) return
            end if
            if (opts%have_atol) then
                call run_testset(problem, opts%method, opts%rtol, result, terr, atol=opts%atol, &
                                 max_order=opts%max_order, repeat_time=opts%repeat_time)
            else
                call run_testset(problem, opts%method, opts%rtol, result, terr, &
                                 max_order=opts%max_order, repeat_time=opts%repeat_time)
            end if
            if (allocated(terr)) then
                if (terr%code /= ERR_SOLVER) then
                    call cli%usage_error(terr%message, err)
                    return
                end if
                failures = failures + 1
                if (first == 0) then
                    call move_alloc(terr, err)
                    return
                end if
                write (error_unit, '(a)') 'ropedyn: error: '//terr%message
                cycle
            end if
            if (opts%csv) then
                call write_csv_row(result)
            else
                if (k > first) write (output_unit, '(a)') ''
                call print_testset_result(problem, result, opts%have_atol)
            end if
        end do
        if (failures > 0) call make_error(err, ERR_SOLVER, 'testset: '//int_text(failures)// &
            ' of '//int_text(last - first + 1)//' test problems failed')
    end subroutine run_problems

    subroutine list_problems(err)
        type(error_t), allocatable, intent(out) :: err
        class(testset_problem_t), allocatable :: problem
        integer :: k
        write (output_unit, '(a)') pad('problem', 8)//pad('n', 4)//pad('interval', 24)// &
            pad('atol rule', 22)//pad('measure', 9)//'description'
        do k = 1, size(testset_names)
            call new_testset_problem(testset_names(k), problem, err)
            if (allocated(err)) return
            write (output_unit, '(a)') pad(problem%name, 8)//pad(int_text(problem%size()), 4)// &
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
            r%method, number(r%rtol), atol_text(r), int_text(r%max_order), fixed_text(r%scd, 4), &
            fixed_text(r%mescd, 4), merge('mescd', 'scd  ', r%use_mescd), &
            fixed_text(r%accuracy(), 4), &
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

    pure function remove_blanks(text) result(out)
        character(len=*), intent(in) :: text
        character(len=:), allocatable :: out
        integer :: j
        out = ''
        do j = 1, len_trim(text)
            if (text(j:j) /= ' ') out = out//text(j:j)
        end do
    end function remove_blanks

    !> The methods that integrate the test problems, for messages (those of the first
    !! problem: every problem is a plain ODE, refused or taken alike).
    function offered_methods() result(list)
        character(len=:), allocatable :: list
        class(testset_problem_t), allocatable :: problem
        type(error_t), allocatable :: err
        call new_testset_problem(testset_names(1), problem, err)
        list = ''
        if (.not. allocated(err)) list = methods_for(problem)
    end function offered_methods
end module ropedyn_cmd_testset
