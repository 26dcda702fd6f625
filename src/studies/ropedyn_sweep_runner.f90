!> Running a sweep (docs/guide/sweeps.md): list its cases and their status, run them locally with
!! N worker processes, and summarize (the command line is src/app/ropedyn_cmd_sweep.f90;
!! one case in one process is ropedyn_sweep_task).
!!
!! Parallel runs are processes, not threads (the HDF5 library is not thread-safe, and a
!! crashing case must not take the others down): the local runner starts each case as
!! `<this executable> sweep SWEEP --task K --quiet --output-dir DIR` in a process group of
!! its own with stdout and stderr in `case_<id>.log`, keeps at most N of them running, and
!! reaps them (waitpid) for their exit status. SIGINT and SIGTERM are forwarded to every
!! worker's group; the runner waits for them (SIGKILL after STOP_GRACE s), removes their
!! empty logs and stops with ERR_INTERRUPTED (exit 130). The runner's state (slots,
!! processes, counters, clock) is a `local_runner_t` with a step per part of its loop. The
!! summary is built from the case files only, so the Slurm array and the local runner
!! produce the same summary, and `--summary` can rebuild it at any time.
module ropedyn_sweep_runner

    use, intrinsic :: iso_fortran_env, only: error_unit, output_unit
    use ropedyn_kinds, only: wp
    use ropedyn_os, only: make_dirs, is_terminal, sleep_microseconds, delete_file
    use ropedyn_clock, only: clock_seconds
    use ropedyn_signals, only: catch_signals, release_signals, signal_received, signal_name, &
        SIGKILL
    use ropedyn_process, only: spawn, reap, signal_group, watch_children, unwatch_children, &
        wait_children
    use ropedyn_error, only: error_t, make_error, ERR_SOLVER, ERR_INTERRUPTED, exit_code_of
    use ropedyn_sweep, only: sweep_t, sweep_case_t, text_t
    use ropedyn_text, only: int_text
    use ropedyn_sweep_status, only: case_state_t, case_state, STATUS_NAMES
    use ropedyn_sweep_summary, only: case_row_t, build_summary, RUN_WARNING_JOIN
    use ropedyn_sweep_task, only: case_label, id_width, drop_stale_lock
    implicit none
    private
    public :: sweep_options_t, list_cases, status_report, run_local, summarize

    !> The local runner's longest wait for a worker's end (it wakes at once when one ends),
    !! and its poll interval while it stops workers, microseconds.
    integer, parameter :: POLL_US = 50000
    !> s a stopped worker has to end after the forwarded signal, before SIGKILL.
    integer, parameter :: STOP_GRACE = 10
    !> Reasons shown per status by --status (the summary holds them all).
    integer, parameter :: MAX_REASONS = 10

    !> The options of one `ropedyn sweep` command line.
    type :: sweep_options_t
        character(len=:), allocatable :: path, output_dir
        logical :: list = .false., count = .false., summary = .false., force = .false., &
            quiet = .false., status = .false.
        integer :: jobs = 0
        integer, allocatable :: tasks(:)    !< --task LIST: the case ids (empty: none)
    end type sweep_options_t

    !> The local runner of `run_local`: the cases it runs, its worker slots and their
    !! processes, its counters and clock; a type-bound step for each part of its loop.
    type :: local_runner_t
        private
        character(len=:), allocatable :: path, output_dir  !< the sweep file, its output
        logical :: quiet = .false.
        logical :: tty = .false.             !< a progress line on the terminal
        integer :: width = 4                 !< digits of a case id (id_width)
        integer, allocatable :: todo(:)      !< the cases to run here, in order
        integer, allocatable :: elsewhere(:) !< the cases another process is writing
        character(len=:), allocatable :: args(:)  !< a worker's command line, its case last
        integer, allocatable :: slot(:)      !< the case of each worker slot (0: free)
        integer, allocatable :: pid(:)       !< the process of each busy slot
        integer :: next = 1                  !< the next case of todo to start
        integer :: finished = 0, failed = 0  !< workers ended, of them failed (not stopped)
        real(wp) :: start = 0.0_wp           !< monotonic clock at the first start, s
        real(wp) :: last_draw = 0.0_wp       !< ... at the last progress line, s
    contains
        procedure :: select_cases => runner_select_cases
        procedure :: announce => runner_announce
        procedure :: set_arguments => runner_set_arguments
        procedure :: run_workers => runner_run_workers
        procedure :: start_workers => runner_start_workers
        procedure :: collect => runner_collect
        procedure :: report_case => runner_report_case
        procedure :: draw_progress => runner_draw_progress
        procedure :: stop_workers => runner_stop_workers
        procedure :: log_path => runner_log_path
        procedure :: stopped_text => runner_stopped_text
        procedure :: outcome => runner_outcome
        procedure :: progress_text => runner_progress_text
    end type local_runner_t

contains

    !> --summary: rebuild the summary from the case files and report it.
    subroutine summarize(sweep, quiet, err)
        type(sweep_t), intent(in) :: sweep
        logical, intent(in) :: quiet
        type(error_t), allocatable, intent(out) :: err
        type(case_row_t), allocatable :: rows(:)
        type(text_t), allocatable :: warnings(:)
        call make_dirs(sweep%output_dir, err, 'sweep')
        if (allocated(err)) return
        call build_summary(sweep, rows, warnings, err)
        if (allocated(err)) return
        call report_summary(sweep, rows, warnings, quiet, err)
    end subroutine summarize

    !> --list: one line per case: id, status, overrides.
    subroutine list_cases(sweep)
        type(sweep_t), intent(in) :: sweep
        type(case_state_t) :: state
        character(len=:), allocatable :: line
        integer :: c, k, width
        width = id_width(sweep)
        write (output_unit, '(a)') 'sweep '//sweep%path//': '//int_text(size(sweep%cases))// &
            ' cases; base '//sweep%base//'; output '//sweep%output_dir
        line = ''
        do k = 1, size(sweep%set)
            line = line//' '//sweep%set(k)%s
        end do
        if (len(line) > 0) write (output_unit, '(a)') 'every case:'//line
        write (output_unit, '(a)') pad('case', width)//'  '//pad('status', 11)//'  overrides'
        do c = 1, size(sweep%cases)
            call case_state(sweep%cases(c), state)
            line = ''
            do k = 1, size(sweep%cases(c)%overrides)
                line = line//' '//sweep%cases(c)%overrides(k)%s
            end do
            write (output_unit, '(a)') zero_padded(c, width)//'  '//pad(state%status, 11)// &
                ' '//line
        end do
    end subroutine list_cases

    !> --status: the cases counted by status, with their ids and reasons; an error
    !! (ERR_SOLVER, exit 3) when a case is not complete.
    subroutine status_report(sweep, err)
        type(sweep_t), intent(in) :: sweep
        type(error_t), allocatable, intent(out) :: err
        type(case_state_t) :: state
        type(text_t), allocatable :: status(:), reason(:)
        character(len=:), allocatable :: ids
        integer :: c, k, n, shown, width, not_done

        n = size(sweep%cases)
        width = id_width(sweep)
        allocate (status(n), reason(n))
        do c = 1, n
            call case_state(sweep%cases(c), state)
            status(c)%s = state%status
            reason(c)%s = state%reason
        end do
        write (output_unit, '(a)') 'sweep '//sweep%path//': '//int_text(n)//' cases; output '// &
            sweep%output_dir
        not_done = 0
        do k = 1, size(STATUS_NAMES)
            ids = ''
            shown = 0
            do c = 1, n
                if (status(c)%s /= trim(STATUS_NAMES(k))) cycle
                shown = shown + 1
                if (k == 1) cycle
                if (shown == 1) ids = ' '
                if (shown <= 20) ids = ids//' '//zero_padded(c, width)
            end do
            if (shown > 20) ids = ids//' ... ('//int_text(shown - 20)//' more)'
            if (k > 1) not_done = not_done + shown
            write (output_unit, '(a)') '  '//pad(trim(STATUS_NAMES(k)), 11)// &
                repeat(' ', max(1, 7 - len(int_text(shown))))//int_text(shown)//ids
        end do
        do k = 2, size(STATUS_NAMES)
            shown = 0
            do c = 1, n
                if (status(c)%s /= trim(STATUS_NAMES(k)) .or. len(reason(c)%s) == 0) cycle
                shown = shown + 1
                if (shown > MAX_REASONS) cycle
                write (output_unit, '(a)') zero_padded(c, width)//' '//status(c)%s//': '// &
                    reason(c)%s
            end do
            if (shown > MAX_REASONS) write (output_unit, '(a)') '... and '// &
                int_text(shown - MAX_REASONS)//' more '//trim(STATUS_NAMES(k))// &
                ' (every reason: --summary, column reason of summary.csv)'
        end do
        if (not_done > 0) call make_error(err, ERR_SOLVER, 'sweep: '//int_text(not_done)// &
            ' of '//int_text(n)//' cases not complete')
    end subroutine status_report

    !> The local runner: every case not complete yet (and not being written by another
    !! process), at most opt%jobs at a time, each in its own process; then the summary.
    subroutine run_local(sweep, opt, exe, err)
        type(sweep_t), intent(in) :: sweep
        type(sweep_options_t), intent(in) :: opt
        character(len=*), intent(in) :: exe
        type(error_t), allocatable, intent(out) :: err
        type(local_runner_t) :: runner
        type(case_row_t), allocatable :: rows(:)
        type(text_t), allocatable :: warnings(:)

        call runner%select_cases(sweep, opt)
        call make_dirs(sweep%output_dir, err, 'sweep')
        if (allocated(err)) return
        runner%tty = is_terminal(2) .and. .not. opt%quiet
        if (.not. opt%quiet) call runner%announce(size(sweep%cases), opt%jobs)
        call runner%set_arguments(exe, opt%force)
        call catch_signals(err)
        if (allocated(err)) return
        call watch_children(err)
        if (allocated(err)) then
            call release_signals()
            return
        end if
        call runner%run_workers(sweep, opt%jobs, err)
        call unwatch_children()
        call release_signals()
        if (allocated(err)) return

        call build_summary(sweep, rows, warnings, err)
        if (allocated(err)) return
        call report_summary(sweep, rows, warnings, opt%quiet, err)
    end subroutine run_local

    !> The cases to run here: not complete (or all with --force), and not being written by
    !! another process (those are listed apart). The abandoned locks of complete cases go
    !! (drop_stale_lock), and so do their empty logs: a
    !! runner killed by SIGKILL could not remove those of the cases its workers finished
    !! on their own, which run no more (the logs of the cases run here go when their
    !! workers end; a complete case is not started by another runner, which could be
    !! about to write to its log).
    subroutine runner_select_cases(self, sweep, opt)
        class(local_runner_t), intent(inout) :: self
        type(sweep_t), intent(in) :: sweep
        type(sweep_options_t), intent(in) :: opt
        type(case_state_t) :: state
        integer :: c
        self%path = sweep%path
        self%output_dir = sweep%output_dir
        self%quiet = opt%quiet
        self%width = id_width(sweep)
        allocate (self%todo(0), self%elsewhere(0))
        do c = 1, size(sweep%cases)
            call case_state(sweep%cases(c), state)
            if (state%status == 'running') then
                self%elsewhere = [self%elsewhere, c]
                cycle
            end if
            if (state%status == 'complete') then
                call remove_if_empty(self%log_path(c))
                ! (the lock its writer, killed after the rename, left)
                call drop_stale_lock(sweep%cases(c), state)
            end if
            if (state%status == 'complete' .and. .not. opt%force) cycle
            self%todo = [self%todo, c]
        end do
    end subroutine runner_select_cases

    !> The opening lines: what runs, with how many workers, where; the cases left to others.
    subroutine runner_announce(self, n, jobs)
        class(local_runner_t), intent(in) :: self
        integer, intent(in) :: n      !< cases of the sweep
        integer, intent(in) :: jobs   !< --jobs
        write (error_unit, '(a)') 'sweep '//self%path//': '//int_text(n)//' cases, '// &
            int_text(n - size(self%todo) - size(self%elsewhere))//' complete already, '// &
            'running '//int_text(size(self%todo))//' with '// &
            int_text(min(jobs, max(1, size(self%todo))))//' worker(s) -> '//self%output_dir
        if (size(self%elsewhere) > 0) write (error_unit, '(a)') 'sweep: '// &
            int_text(size(self%elsewhere))//' case(s) being written by another process, not ' &
            //'started here: '//id_text(self%elsewhere, self%width)//' (ropedyn sweep '// &
            self%path//' --status names the writers)'
    end subroutine runner_announce

    !> A worker's arguments: exe sweep SWEEP --quiet --output-dir DIR [--force] --task K
    !! (K, the last, is set per worker).
    subroutine runner_set_arguments(self, exe, force)
        class(local_runner_t), intent(inout) :: self
        character(len=*), intent(in) :: exe
        logical, intent(in) :: force
        allocate (character(len=max(len(exe), len(self%path), len(self%output_dir), 16)) :: &
            self%args(merge(9, 8, force)))
        self%args(:6) = [character(len=12) :: '', 'sweep', '', '--quiet', '--output-dir', '']
        self%args(1) = exe
        self%args(3) = self%path
        self%args(6) = self%output_dir
        if (force) self%args(7) = '--force'
        self%args(size(self%args) - 1) = '--task'
    end subroutine runner_set_arguments

    !> Run the cases with `jobs` workers until all have ended or a signal came; on a signal
    !! the workers are stopped and `err` is ERR_INTERRUPTED. The caller watches the children
    !! and catches the signals around it.
    subroutine runner_run_workers(self, sweep, jobs, err)
        class(local_runner_t), intent(inout) :: self
        type(sweep_t), intent(in) :: sweep
        integer, intent(in) :: jobs
        type(error_t), allocatable, intent(out) :: err
        integer :: sig
        logical :: redraw, woken
        allocate (self%slot(jobs), self%pid(jobs), source=0)
        self%next = 1
        self%finished = 0
        self%failed = 0
        self%start = clock_seconds()
        self%last_draw = self%start
        do while (self%finished < size(self%todo))
            if (signal_received() /= 0) exit
            call self%start_workers(err)
            if (allocated(err)) return
            ! until a worker ends (or a signal, or POLL_US for the progress line)
            woken = wait_children(POLL_US)
            call self%collect(sweep, redraw)
            if (self%tty) call self%draw_progress(redraw)
        end do
        if (self%tty) write (error_unit, '(a)') ''
        sig = signal_received()
        if (sig /= 0) then
            call self%stop_workers(sig)
            call make_error(err, ERR_INTERRUPTED, 'sweep: stopped by '//signal_name(sig)// &
                ': '//int_text(self%finished)//' of '//int_text(size(self%todo))// &
                ' cases ended, '//int_text(count(self%slot /= 0))//' interrupted'// &
                self%stopped_text()//', '//int_text(size(self%todo) - self%next + 1)// &
                ' not started; no summary written (ropedyn sweep '//self%path//' --status '// &
                'tells each case''s status; running the sweep again goes on from there)')
        end if
    end subroutine runner_run_workers

    !> Start the next cases in the free slots; a worker that cannot start stops the others
    !! (SIGKILL) and is the error.
    subroutine runner_start_workers(self, err)
        class(local_runner_t), intent(inout) :: self
        type(error_t), allocatable, intent(out) :: err
        integer :: s, c
        do s = 1, size(self%slot)
            if (self%slot(s) /= 0 .or. self%next > size(self%todo)) cycle
            c = self%todo(self%next)
            self%args(size(self%args)) = int_text(c)
            call spawn(self%args, self%log_path(c), self%pid(s), err)
            if (allocated(err)) then
                err%message = 'sweep: case '//zero_padded(c, self%width)//': '//err%message
                call self%stop_workers(SIGKILL)
                return
            end if
            self%next = self%next + 1
            self%slot(s) = c
        end do
    end subroutine runner_start_workers

    !> Reap the workers that have ended, count and report them; `redraw` when one did.
    subroutine runner_collect(self, sweep, redraw)
        class(local_runner_t), intent(inout) :: self
        type(sweep_t), intent(in) :: sweep
        logical, intent(out) :: redraw
        character(len=:), allocatable :: other
        integer :: s, c, rc
        redraw = .false.
        do s = 1, size(self%slot)
            if (self%slot(s) == 0) cycle
            if (.not. reap(self%pid(s), rc)) cycle
            c = self%slot(s)
            self%slot(s) = 0
            self%finished = self%finished + 1
            ! a worker that found the case being written by another runner did not fail
            other = ''
            if (rc /= 0) other = written_elsewhere(sweep%cases(c))
            ! nor did one ended by a signal (its case is interrupted: its lock abandoned)
            if (rc /= 0 .and. rc /= exit_code_of(ERR_INTERRUPTED) .and. rc <= 128 .and. &
                len(other) == 0) self%failed = self%failed + 1
            call remove_if_empty(self%log_path(c))
            if (.not. self%quiet) call self%report_case(c, rc, other)
            redraw = .true.
        end do
    end subroutine runner_collect

    !> The line of an ended case (on a terminal only when it did not complete), with the
    !! progress: `other` is the process that writes it instead ('': none), `rc` its exit code.
    subroutine runner_report_case(self, c, rc, other)
        class(local_runner_t), intent(in) :: self
        integer, intent(in) :: c, rc
        character(len=*), intent(in) :: other
        real(wp) :: now
        now = clock_seconds()
        if (self%tty) write (error_unit, '(a)', advance='no') achar(13)//repeat(' ', 78)// &
            achar(13)
        if (len(other) > 0) then
            write (error_unit, '(a)') 'sweep: case '//zero_padded(c, self%width)// &
                ' not run here: '//other//' ('//self%progress_text(now)//')'
        else if (rc /= 0 .or. .not. self%tty) then
            write (error_unit, '(a)') 'sweep: case '//zero_padded(c, self%width)//' '// &
                self%outcome(rc, c)//' ('//self%progress_text(now)//')'
        end if
    end subroutine runner_report_case

    !> The progress line on the terminal: after a case ended, else every 0.5 s.
    subroutine runner_draw_progress(self, redraw)
        class(local_runner_t), intent(inout) :: self
        logical, intent(in) :: redraw
        real(wp) :: now
        now = clock_seconds()
        if (redraw .or. now - self%last_draw > 0.5_wp) then
            write (error_unit, '(a)', advance='no') achar(13)//'sweep: '// &
                self%progress_text(now)//'   '
            flush (error_unit)
            self%last_draw = now
        end if
    end subroutine runner_draw_progress

    !> Forward `signal` to every running worker's process group and wait for them (at
    !! most STOP_GRACE s, then SIGKILL); their empty logs go. `slot` keeps the cases of
    !! the workers that were running.
    subroutine runner_stop_workers(self, signal)
        class(local_runner_t), intent(in) :: self
        integer, intent(in) :: signal
        integer :: waited, code, k
        logical :: sent, all_ended
        logical :: ended(size(self%slot))
        ended = self%slot == 0
        do k = 1, size(self%slot)
            if (.not. ended(k)) sent = signal_group(self%pid(k), signal)
        end do
        do waited = 1, STOP_GRACE*1000000/POLL_US + 40
            if (waited == STOP_GRACE*1000000/POLL_US) then
                do k = 1, size(self%slot)
                    if (.not. ended(k)) sent = signal_group(self%pid(k), SIGKILL)
                end do
            end if
            all_ended = .true.
            do k = 1, size(self%slot)
                if (ended(k)) cycle
                ended(k) = reap(self%pid(k), code)
                if (ended(k)) call remove_if_empty(self%log_path(self%slot(k)))
                all_ended = all_ended .and. ended(k)
            end do
            if (all_ended) exit
            call sleep_microseconds(POLL_US)
        end do
    end subroutine runner_stop_workers

    function runner_log_path(self, id) result(path)
        class(local_runner_t), intent(in) :: self
        integer, intent(in) :: id
        character(len=:), allocatable :: path
        path = self%output_dir//'/case_'//zero_padded(id, self%width)//'.log'
    end function runner_log_path

    !> ' (ids)' of the workers running, '' when none.
    function runner_stopped_text(self) result(text)
        class(local_runner_t), intent(in) :: self
        character(len=:), allocatable :: text
        text = ''
        if (count(self%slot /= 0) > 0) text = ' ('//id_text(pack(self%slot, self%slot /= 0), &
                                                            self%width)//')'
    end function runner_stopped_text

    !> How a worker ended, from its exit code.
    function runner_outcome(self, code, id) result(text)
        class(local_runner_t), intent(in) :: self
        integer, intent(in) :: code, id
        character(len=:), allocatable :: text
        if (code == 0) then
            text = 'complete'
        else if (code == exit_code_of(ERR_INTERRUPTED)) then
            ! ropedyn's own end after SIGINT or SIGTERM (its case written interrupted), not
            ! necessarily 128 + SIGINT: the log names the signal
            text = 'interrupted (exit '//int_text(code)//': stopped by a signal; see '// &
                self%log_path(id)//')'
        else if (code > 128) then
            text = 'ended by '//signal_name(code - 128)//' (see '//self%log_path(id)//')'
        else
            text = 'failed (exit '//int_text(code)//'; see '//self%log_path(id)//')'
        end if
    end function runner_outcome

    function runner_progress_text(self, time_now) result(text)
        class(local_runner_t), intent(in) :: self
        real(wp), intent(in) :: time_now   !< the monotonic clock, s
        character(len=:), allocatable :: text
        real(wp) :: elapsed, eta
        integer :: n
        n = size(self%todo)
        elapsed = time_now - self%start
        ! a finished worker's slot is refilled at once: count it as running
        text = int_text(self%finished)//'/'//int_text(n)//' done, '// &
            int_text(min(size(self%slot), n - self%finished))//' running, '// &
            int_text(self%failed)//' failed, elapsed '//clock_text(elapsed)
        if (self%finished > 0 .and. self%finished < n) then
            eta = elapsed/real(self%finished, wp)*real(n - self%finished, wp)
            text = text//', ETA '//clock_text(eta)
        end if
    end function runner_progress_text

    !> '' unless the case is written, or was completed, by another process (another runner
    !! of the same sweep, whose lock made this one's worker give up): then that.
    function written_elsewhere(the_case) result(text)
        type(sweep_case_t), intent(in) :: the_case
        character(len=:), allocatable :: text
        type(case_state_t) :: state
        call case_state(the_case, state)
        text = ''
        if (state%status == 'running') text = state%reason
        if (state%status == 'complete') text = 'completed by another process'
    end function written_elsewhere

    !> The ids, zero-padded to `width`, the first 20 of them.
    function id_text(ids, width) result(text)
        integer, intent(in) :: ids(:), width
        character(len=:), allocatable :: text
        integer :: k
        text = ''
        do k = 1, min(size(ids), 20)
            if (k > 1) text = text//' '
            text = text//zero_padded(ids(k), width)
        end do
        if (size(ids) > 20) text = text//' ...'
    end function id_text

    !> Print the outcome of the summary: the reference fallbacks as warnings, the cases not
    !! complete with their reasons; an error (ERR_SOLVER) if a case is not complete.
    subroutine report_summary(sweep, rows, warnings, quiet, err)
        type(sweep_t), intent(in) :: sweep
        type(case_row_t), intent(in) :: rows(:)
        type(text_t), intent(in) :: warnings(:)
        logical, intent(in) :: quiet
        type(error_t), allocatable, intent(out) :: err
        integer :: complete, bad, c, shown
        do c = 1, size(warnings)
            write (error_unit, '(a)') 'sweep: warning: '//warnings(c)%s
        end do
        complete = count([(rows(c)%status == 'complete', c=1, size(rows))])
        bad = size(rows) - complete
        if (.not. quiet) write (error_unit, '(a)') 'sweep: '//int_text(complete)//' of '// &
            int_text(size(rows))//' cases complete; summary: '//sweep%output_dir// &
            '/summary.csv, summary.h5 (reference: '//sweep%reference_setting()//')'
        call report_run_warnings(sweep, rows)
        if (bad == 0) return
        shown = 0
        do c = 1, size(rows)
            if (rows(c)%status == 'complete') cycle
            shown = shown + 1
            if (shown > 20) exit
            write (error_unit, '(a)') case_label(sweep, c)//': '//rows(c)%status// &
                reason_text(rows(c)%reason)
        end do
        if (bad > 20) write (error_unit, '(a)') 'sweep: ... and '//int_text(bad - 20)// &
            ' more (summary.csv)'
        call make_error(err, ERR_SOLVER, 'sweep: '//int_text(bad)//' of '// &
            int_text(size(rows))//' cases not complete (reasons in '//sweep%output_dir// &
            '/summary.csv)')
    contains
        function reason_text(reason) result(text)
            character(len=*), intent(in) :: reason
            character(len=:), allocatable :: text
            text = ''
            if (len(reason) > 0) text = ': '//reason
        end function reason_text
    end subroutine report_summary

    !> One line naming the cases whose runs warned (the first 20 ids, as id_text writes
    !! them), what the first of them said first, and where the rest is: the run_warnings
    !! column.
    subroutine report_run_warnings(sweep, rows)
        type(sweep_t), intent(in) :: sweep
        type(case_row_t), intent(in) :: rows(:)
        character(len=:), allocatable :: first
        integer, allocatable :: warned(:)
        integer :: c, bar
        warned = pack([(c, c=1, size(rows))], [(len(rows(c)%run_warnings) > 0, c=1, size(rows))])
        if (size(warned) == 0) return
        first = rows(warned(1))%run_warnings
        bar = index(first, RUN_WARNING_JOIN)
        if (bar > 0) first = first(:bar - 1)
        write (error_unit, '(a)') 'sweep: warning: '//int_text(size(warned))//' of '// &
            int_text(size(rows))//' cases warned in their runs (cases '// &
            id_text(warned, id_width(sweep))//'), the first: '//first//' (all in '// &
            sweep%output_dir//'/summary.csv, run_warnings)'
    end subroutine report_run_warnings

    ! ------------------------------------------------------------------------------------
    ! Files and text
    ! ------------------------------------------------------------------------------------

    subroutine remove_if_empty(path)
        character(len=*), intent(in) :: path
        integer :: size_bytes
        logical :: exists
        inquire (file=path, exist=exists, size=size_bytes)
        if (exists .and. size_bytes == 0) exists = .not. delete_file(path)
    end subroutine remove_if_empty

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
