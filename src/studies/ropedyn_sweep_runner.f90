!> Running a sweep (docs/sweeps.md): list its cases, run them locally with N worker
!! processes or one case for a Slurm array task, and summarize (the command line is
!! src/app/ropedyn_cmd_sweep.f90).
!!
!! Parallel runs are processes, not threads (the HDF5 library is not thread-safe, and a
!! crashing case must not take the others down): the local runner starts each case as
!! `sh -c '<this executable> sweep SWEEP --task K --quiet ... >case.log 2>&1;
!! echo $? >.case.rc.tmp && mv .case.rc.tmp .case.rc'` with
!! `execute_command_line(wait=.false.)`, keeps at most N of them running, and polls for the
!! `.rc` files, which carry each worker's exit status (including a crash's: the shell
!! writes 128 + signal). The summary is built from the case files only, so the Slurm array
!! and the local runner produce the same summary, and `--summary` can rebuild it at any time.
module ropedyn_sweep_runner

    use, intrinsic :: iso_fortran_env, only: error_unit, output_unit, int64
    use ropedyn_kinds, only: wp
    use ropedyn_os, only: make_dirs, is_terminal, sleep_microseconds, processor_count
    use ropedyn_error, only: error_t, make_error, ERR_USAGE, ERR_SOLVER, ERR_IO
    use ropedyn_simulation, only: run_summary_t, run_scene
    use ropedyn_sweep, only: sweep_t
    use ropedyn_text, only: int_text, enclosed
    use ropedyn_sweep_summary, only: case_row_t, case_status, build_summary
    use ropedyn_case_file, only: write_wall_time
    implicit none
    private
    public :: sweep_options_t, list_cases, run_task, run_local, summarize

    !> Poll interval of the local runner, microseconds.
    integer, parameter :: POLL_US = 50000

    !> The options of one `ropedyn sweep` command line.
    type :: sweep_options_t
        character(len=:), allocatable :: path, output_dir
        logical :: list = .false., count = .false., summary = .false., force = .false., &
            quiet = .false.
        integer :: jobs = 0, task = 0
    end type sweep_options_t

contains

    !> --summary: rebuild the summary from the case files and report it.
    subroutine summarize(sweep, quiet, err)
        type(sweep_t), intent(in) :: sweep
        logical, intent(in) :: quiet
        type(error_t), allocatable, intent(out) :: err
        type(case_row_t), allocatable :: rows(:)
        call make_dirs(sweep%output_dir, err, 'sweep')
        if (allocated(err)) return
        call build_summary(sweep, rows, err)
        if (allocated(err)) return
        call report_summary(sweep, rows, quiet, err)
    end subroutine summarize

    !> --list: one line per case: id, status of its file, overrides.
    subroutine list_cases(sweep, err)
        type(sweep_t), intent(in) :: sweep
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: status, reason, line
        integer :: c, k, width
        width = max(4, len(int_text(size(sweep%cases))))
        write (output_unit, '(a)') 'sweep '//sweep%path//': '//int_text(size(sweep%cases))// &
            ' cases; base '//sweep%base//'; output '//sweep%output_dir
        line = ''
        do k = 1, size(sweep%set)
            line = line//' '//sweep%set(k)%s
        end do
        if (len(line) > 0) write (output_unit, '(a)') 'every case:'//line
        write (output_unit, '(a)') pad('case', width)//'  '//pad('status', 10)//'  overrides'
        do c = 1, size(sweep%cases)
            call case_status(sweep%cases(c), status, reason, err)
            if (allocated(err)) deallocate (err)
            line = ''
            do k = 1, size(sweep%cases(c)%overrides)
                line = line//' '//sweep%cases(c)%overrides(k)%s
            end do
            write (output_unit, '(a)') pad(zero_padded(c, width), width)//'  '// &
                pad(status, 10)//' '//line
        end do
    end subroutine list_cases

    !> Run one case (an array task, or a worker of the local runner).
    subroutine run_task(sweep, k, force, quiet, err)
        type(sweep_t), intent(in) :: sweep
        integer, intent(in) :: k
        logical, intent(in) :: force, quiet
        type(error_t), allocatable, intent(out) :: err
        type(run_summary_t) :: summary
        type(error_t), allocatable :: werr
        character(len=:), allocatable :: status, reason, label
        integer(int64) :: start, finish, rate
        real(wp) :: wall
        logical :: exists

        label = 'sweep: case '//zero_padded(k, max(4, len(int_text(size(sweep%cases)))))
        associate (c => sweep%cases(k))
            if (.not. force) then
                call case_status(c, status, reason, werr)
                if (status == 'complete') then
                    if (.not. quiet) write (output_unit, '(a)') label//': complete already ('// &
                        c%file//'), skipped'
                    return
                end if
            end if
            call make_dirs(sweep%output_dir, err, 'sweep')
            if (allocated(err)) return
            call system_clock(start, rate)
            call run_scene(c%scene, summary, err)
            call system_clock(finish)
            wall = real(finish - start, wp)/real(rate, wp)
            inquire (file=c%file, exist=exists)
            if (exists .and. summary%records > 0) then
                call write_wall_time(c%file, wall, werr)
                if (allocated(werr) .and. .not. allocated(err)) call move_alloc(werr, err)
            end if
            if (allocated(err)) then
                err%message = label//' ('//c%file//'): '//err%message
                return
            end if
            if (.not. quiet) write (output_unit, '(a)') label//': complete: '// &
                int_text(int(summary%stats%steps))//' steps, cpu '// &
                seconds_text(summary%cpu_time)//', wall '//seconds_text(wall)//' -> '//c%file
        end associate
    end subroutine run_task

    !> The local runner: every case not complete yet, at most opt%jobs at a time, each in
    !! its own process; then the summary.
    subroutine run_local(sweep, opt, exe, err)
        type(sweep_t), intent(in) :: sweep
        type(sweep_options_t), intent(in) :: opt
        character(len=*), intent(in) :: exe
        type(error_t), allocatable, intent(out) :: err
        type(error_t), allocatable :: serr
        type(case_row_t), allocatable :: rows(:)
        integer, allocatable :: todo(:), slot(:)
        character(len=:), allocatable :: status, reason, base_cmd, rc_file
        integer :: n, c, next, running, finished, failed, rc, s, width, cmdstat
        integer(int64) :: start, now, rate, last_draw
        logical :: tty, exists, redraw
        character(len=256) :: cmdmsg

        n = size(sweep%cases)
        width = max(4, len(int_text(n)))
        allocate (todo(0))
        do c = 1, n
            if (.not. opt%force) then
                call case_status(sweep%cases(c), status, reason, serr)
                if (status == 'complete') cycle
            end if
            todo = [todo, c]
        end do
        call make_dirs(sweep%output_dir, err, 'sweep')
        if (allocated(err)) return
        tty = is_terminal(2) .and. .not. opt%quiet
        if (.not. opt%quiet) write (error_unit, '(a)') 'sweep '//sweep%path//': '// &
            int_text(n)//' cases, '//int_text(n - size(todo))//' complete already, '// &
            'running '//int_text(size(todo))//' with '//int_text(min(opt%jobs, &
            max(1, size(todo))))//' worker(s) -> '//sweep%output_dir

        base_cmd = quote(exe)//' sweep '//quote(sweep%path)//' --quiet --output-dir '// &
            quote(sweep%output_dir)
        if (opt%force) base_cmd = base_cmd//' --force'
        allocate (slot(opt%jobs), source=0)
        next = 1
        running = 0
        finished = 0
        failed = 0
        call system_clock(start, rate)
        last_draw = start
        do while (finished < size(todo))
            ! start workers
            do s = 1, size(slot)
                if (slot(s) /= 0 .or. next > size(todo)) cycle
                c = todo(next)
                next = next + 1
                rc_file = rc_path(c)
                call remove_file(rc_file)
                call execute_command_line(base_cmd//' --task '//int_text(c)//' >'// &
                    quote(log_path(c))//' 2>&1; echo $? >'//quote(rc_file//'.tmp')// &
                    ' && mv -f '//quote(rc_file//'.tmp')//' '//quote(rc_file), &
                    wait=.false., cmdstat=cmdstat, cmdmsg=cmdmsg)
                if (cmdstat /= 0) then
                    call make_error(err, ERR_IO, 'sweep: cannot start case '//int_text(c)// &
                        ': '//trim(cmdmsg))
                    return
                end if
                slot(s) = c
                running = running + 1
            end do
            call sleep_microseconds(POLL_US)
            ! collect finished workers
            redraw = .false.
            do s = 1, size(slot)
                if (slot(s) == 0) cycle
                c = slot(s)
                rc_file = rc_path(c)
                inquire (file=rc_file, exist=exists)
                if (.not. exists) cycle
                rc = read_exit_code(rc_file)
                call remove_file(rc_file)
                slot(s) = 0
                running = running - 1
                finished = finished + 1
                if (rc /= 0) failed = failed + 1
                if (rc == 0) call remove_if_empty(log_path(c))
                call system_clock(now)
                if (.not. opt%quiet) then
                    if (tty) write (error_unit, '(a)', advance='no') achar(13)//repeat(' ', 78) &
                        //achar(13)
                    if (rc /= 0 .or. .not. tty) write (error_unit, '(a)') 'sweep: case '// &
                        zero_padded(c, width)//' '//outcome(rc, c)//' ('// &
                        progress_text(now)//')'
                end if
                redraw = .true.
            end do
            if (tty) then
                call system_clock(now)
                if (redraw .or. real(now - last_draw, wp)/real(rate, wp) > 0.5_wp) then
                    write (error_unit, '(a)', advance='no') achar(13)//'sweep: '// &
                        progress_text(now)//'   '
                    flush (error_unit)
                    last_draw = now
                end if
            end if
        end do
        if (tty) write (error_unit, '(a)') ''

        call build_summary(sweep, rows, err)
        if (allocated(err)) return
        call report_summary(sweep, rows, opt%quiet, err)
    contains
        function rc_path(id) result(path)
            integer, intent(in) :: id
            character(len=:), allocatable :: path
            path = sweep%output_dir//'/.case_'//zero_padded(id, width)//'.rc'
        end function rc_path

        function log_path(id) result(path)
            integer, intent(in) :: id
            character(len=:), allocatable :: path
            path = sweep%output_dir//'/case_'//zero_padded(id, width)//'.log'
        end function log_path

        function outcome(code, id) result(text)
            integer, intent(in) :: code, id
            character(len=:), allocatable :: text
            if (code == 0) then
                text = 'complete'
            else if (code > 128) then
                text = 'crashed (signal '//int_text(code - 128)//'; see '//log_path(id)//')'
            else
                text = 'failed (exit '//int_text(code)//'; see '//log_path(id)//')'
            end if
        end function outcome

        function progress_text(time_now) result(text)
            integer(int64), intent(in) :: time_now
            character(len=:), allocatable :: text
            real(wp) :: elapsed, eta
            elapsed = real(time_now - start, wp)/real(rate, wp)
            ! a finished worker's slot is refilled at once: count it as running
            text = int_text(finished)//'/'//int_text(size(todo))//' done, '// &
                int_text(min(size(slot), size(todo) - finished))//' running, '// &
                int_text(failed)//' failed, elapsed '//clock_text(elapsed)
            if (finished > 0 .and. finished < size(todo)) then
                eta = elapsed/real(finished, wp)*real(size(todo) - finished, wp)
                text = text//', ETA '//clock_text(eta)
            end if
        end function progress_text
    end subroutine run_local

    !> Print the outcome of the summary; an error (ERR_SOLVER) if a case is not complete.
    subroutine report_summary(sweep, rows, quiet, err)
        type(sweep_t), intent(in) :: sweep
        type(case_row_t), intent(in) :: rows(:)
        logical, intent(in) :: quiet
        type(error_t), allocatable, intent(out) :: err
        integer :: complete, bad
        complete = count([(rows(bad)%status == 'complete', bad=1, size(rows))])
        bad = size(rows) - complete
        if (.not. quiet) write (error_unit, '(a)') 'sweep: '//int_text(complete)//' of '// &
            int_text(size(rows))//' cases complete; summary: '//sweep%output_dir// &
            '/summary.csv, summary.h5'
        if (bad > 0) call make_error(err, ERR_SOLVER, 'sweep: '//int_text(bad)//' of '// &
            int_text(size(rows))//' cases not complete (failed, missing or stale; reasons in '// &
            sweep%output_dir//'/summary.csv)')
    end subroutine report_summary

    ! ------------------------------------------------------------------------------------
    ! Files and text
    ! ------------------------------------------------------------------------------------

    subroutine remove_file(path)
        character(len=*), intent(in) :: path
        integer :: unit, ios
        logical :: exists
        inquire (file=path, exist=exists)
        if (.not. exists) return
        open (newunit=unit, file=path, status='old', iostat=ios)
        if (ios == 0) close (unit, status='delete', iostat=ios)
    end subroutine remove_file

    subroutine remove_if_empty(path)
        character(len=*), intent(in) :: path
        integer :: size_bytes
        logical :: exists
        inquire (file=path, exist=exists, size=size_bytes)
        if (exists .and. size_bytes == 0) call remove_file(path)
    end subroutine remove_if_empty

    !> The exit status a worker's shell wrote; 255 if unreadable.
    integer function read_exit_code(path) result(code)
        character(len=*), intent(in) :: path
        integer :: unit, ios
        code = 255
        open (newunit=unit, file=path, status='old', action='read', iostat=ios)
        if (ios /= 0) return
        read (unit, *, iostat=ios) code
        if (ios /= 0) code = 255
        close (unit)
    end function read_exit_code

    !> A shell word: 'text' with embedded single quotes as '\''.
    pure function quote(text) result(s)
        character(len=*), intent(in) :: text
        character(len=:), allocatable :: s
        s = enclosed(text, "'", "'\''")
    end function quote

    pure function zero_padded(n, width) result(s)
        integer, intent(in) :: n, width
        character(len=:), allocatable :: s
        character(len=16) :: buf
        write (buf, '(i0.'//int_text(width)//')') n
        s = trim(buf)
    end function zero_padded

    pure function pad(text, width) result(s)
        character(len=*), intent(in) :: text
        integer, intent(in) :: width
        character(len=max(width, len(text))) :: s
        s = text
    end function pad

    function seconds_text(x) result(s)
        real(wp), intent(in) :: x
        character(len=:), allocatable :: s
        character(len=16) :: buf
        write (buf, '(f0.3)') x
        s = trim(adjustl(buf))
        if (s(1:1) == '.') s = '0'//s
        s = s//' s'
    end function seconds_text

    !> 42 s, 3m05s, 2h03m.
    function clock_text(x) result(s)
        real(wp), intent(in) :: x
        character(len=:), allocatable :: s
        character(len=16) :: buf
        integer :: t
        t = nint(max(0.0_wp, x))
        if (t < 60) then
            s = int_text(t)//' s'
        else if (t < 3600) then
            write (buf, '(i0, "m", i2.2, "s")') t/60, mod(t, 60)
            s = trim(buf)
        else
            write (buf, '(i0, "h", i2.2, "m")') t/3600, mod(t, 3600)/60
            s = trim(buf)
        end if
    end function clock_text
end module ropedyn_sweep_runner
