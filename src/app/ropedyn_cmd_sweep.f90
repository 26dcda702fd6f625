!> `ropedyn sweep SWEEP.nml [options]`: list, run and summarize a sweep (docs/guide/sweeps.md).
!!
!!     ropedyn sweep SWEEP.nml [--jobs N] [--force] [--quiet] [--output-dir DIR]
!!     ropedyn sweep SWEEP.nml --list | --count | --status
!!     ropedyn sweep SWEEP.nml --task LIST [--force] [--quiet] [--output-dir DIR]
!!     ropedyn sweep SWEEP.nml --summary [--output-dir DIR]
module ropedyn_cmd_sweep
    use, intrinsic :: iso_fortran_env, only: output_unit
    use ropedyn_error, only: error_t, make_error, ERR_USAGE
    use ropedyn_text, only: int_text
    use ropedyn_os, only: processor_count
    use ropedyn_cli, only: cli_t
    use ropedyn_help, only: print_help
    use ropedyn_sweep, only: sweep_t, read_sweep
    use ropedyn_sweep_runner, only: sweep_options_t, list_cases, status_report, run_local, &
        summarize
    use ropedyn_sweep_task, only: run_cases
    implicit none
    private
    public :: sweep_command

contains

    !> `ropedyn sweep ARGS`: `cli` holds the arguments after `sweep`; `exe` is how this
    !! program was started (argument 0), used to start the workers.
    subroutine sweep_command(cli, exe, err)
        type(cli_t), intent(inout) :: cli
        character(len=*), intent(in) :: exe
        type(error_t), allocatable, intent(out) :: err
        type(sweep_options_t) :: opt
        type(sweep_t) :: sweep

        call parse_options(cli, opt, err)
        if (allocated(err)) return
        if (.not. allocated(opt%path)) return   ! --help
        call read_sweep(opt%path, sweep, err, opt%output_dir)
        if (allocated(err)) return
        if (opt%count) then
            write (output_unit, '(i0)') size(sweep%cases)
        else if (opt%list) then
            call list_cases(sweep)
        else if (opt%status) then
            call status_report(sweep, err)
        else if (size(opt%tasks) > 0) then
            if (maxval(opt%tasks) > size(sweep%cases)) then
                call make_error(err, ERR_USAGE, 'sweep: --task '//int_text(maxval(opt%tasks))// &
                    ': no such case ('//opt%path//' has '//int_text(size(sweep%cases))// &
                    ' cases, 1 .. '//int_text(size(sweep%cases))//')')
                return
            end if
            call run_cases(sweep, once(opt%tasks, size(sweep%cases)), opt%force, opt%quiet, &
                           err)
        else if (opt%summary) then
            call summarize(sweep, opt%quiet, err)
        else
            call run_local(sweep, opt, exe, err)
        end if
    end subroutine sweep_command

    subroutine parse_options(cli, opt, err)
        type(cli_t), intent(inout) :: cli
        type(sweep_options_t), intent(out) :: opt
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: value
        integer :: modes
        logical :: have_jobs, ok

        have_jobs = .false.
        allocate (opt%tasks(0))
        do while (cli%next())
            select case (cli%option)
            case ('--help', '-h')
                call cli%flag(err)
                if (allocated(err)) return
                call print_help('sweep', output_unit)
                if (allocated(opt%path)) deallocate (opt%path)  ! nothing else is done
                return
            case ('--list')
                call cli%flag(err)
                opt%list = .true.
            case ('--count')
                call cli%flag(err)
                opt%count = .true.
            case ('--summary')
                call cli%flag(err)
                opt%summary = .true.
            case ('--status')
                call cli%flag(err)
                opt%status = .true.
            case ('--force')
                call cli%flag(err)
                opt%force = .true.
            case ('--quiet')
                call cli%flag(err)
                opt%quiet = .true.
            case ('--output-dir')
                if (allocated(opt%output_dir)) then
                    call cli%usage_error('--output-dir is given twice', err)
                    return
                end if
                call cli%take_value(value, err)
                if (.not. allocated(err)) then
                    opt%output_dir = value
                    if (len(value) == 0) call cli%usage_error('--output-dir needs a directory', err)
                end if
            case ('--jobs')
                if (have_jobs) call cli%usage_error('--jobs is given twice', err)
                if (.not. allocated(err)) call cli%int_value(opt%jobs, 1, err)
                have_jobs = .true.
            case ('--task')
                if (size(opt%tasks) > 0) then
                    call cli%usage_error('--task is given twice', err)
                    return
                end if
                call cli%take_value(value, err)
                if (.not. allocated(err)) then
                    call parse_ids(value, opt%tasks, ok)
                    if (.not. ok) call cli%usage_error('--task "'//value//'": expected a '// &
                        'whole number >= 1, a range K-L or a comma-separated list of them', err)
                end if
            case default
                call cli%positional('sweep file', opt%path, err)
            end select
            if (allocated(err)) return
        end do
        call cli%require(opt%path, 'a sweep file', err)
        if (allocated(err)) return
        if (.not. allocated(opt%output_dir)) opt%output_dir = ''
        modes = count([opt%list, opt%count, opt%summary, opt%status, size(opt%tasks) > 0])
        if (modes > 1) then
            call cli%usage_error('--list, --count, --status, --summary and --task exclude '// &
                'each other', err)
        else if (have_jobs .and. modes > 0) then
            call cli%usage_error('--jobs is for running the whole sweep', err)
        else if (opt%force .and. (opt%list .or. opt%count .or. opt%summary .or. opt%status)) &
            then
            call cli%usage_error('--force is for running cases', err)
        end if
        if (.not. have_jobs) opt%jobs = processor_count()
    end subroutine parse_options

    !> Each id of `ids` (1 .. n) once, at its first place: `--task 1,1-2` runs case 1 once
    !! (with --force it ran twice).
    pure function once(ids, n) result(kept)
        integer, intent(in) :: ids(:), n
        integer, allocatable :: kept(:)
        logical :: seen(n)
        integer :: k, m
        allocate (kept(size(ids)))
        seen = .false.
        m = 0
        do k = 1, size(ids)
            if (seen(ids(k))) cycle
            seen(ids(k)) = .true.
            m = m + 1
            kept(m) = ids(k)
        end do
        kept = kept(:m)
    end function once

    !> Case ids from '7', '3-5' or '1,3-5,9' (each >= 1; at most 100000 of them), in the
    !! order given.
    subroutine parse_ids(text, ids, ok)
        character(len=*), intent(in) :: text
        integer, allocatable, intent(out) :: ids(:)
        logical, intent(out) :: ok
        integer, parameter :: MOST = 100000
        integer :: start, comma, dash, first, last, ios, k, n
        integer, allocatable :: buffer(:)
        allocate (buffer(16))
        n = 0
        ok = len(text) > 0 .and. text(len(text):) /= ','
        start = 1
        do while (ok .and. start <= len(text))
            comma = index(text(start:), ',')
            if (comma == 0) comma = len(text) - start + 2
            associate (item => text(start:start + comma - 2))
                dash = index(item, '-')
                ok = len(item) > 0 .and. len(item) < 20 .and. &
                    verify(item, '0123456789-') == 0 .and. dash /= 1 .and. &
                    dash /= len(item) .and. index(item(dash + 1:), '-') == 0
                if (.not. ok) exit
                if (dash == 0) then
                    read (item, *, iostat=ios) first
                    last = first
                else
                    read (item(:dash - 1), *, iostat=ios) first
                    if (ios == 0) read (item(dash + 1:), *, iostat=ios) last
                end if
                ok = ios == 0
                if (ok) ok = first >= 1 .and. last >= first .and. last - first < MOST - n
                if (.not. ok) exit
                do while (n + last - first + 1 > size(buffer))
                    buffer = [buffer, buffer]
                end do
                buffer(n + 1:n + last - first + 1) = [(k, k=first, last)]
                n = n + last - first + 1
            end associate
            start = start + comma
        end do
        ids = buffer(:n)
        if (.not. ok) ids = buffer(:0)
    end subroutine parse_ids
end module ropedyn_cmd_sweep
