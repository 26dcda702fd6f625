!> Running sweep cases in this process: `ropedyn sweep SWEEP --task LIST`, what every local
!! worker and every Slurm array task runs (docs/development/internals.md, "One writer per case").
!!
!! For each case: skip it when it is complete (unless forced); take its lock (a live lock
!! of another writer: the case is not run, with a message naming that writer); run the
!! scene with its output going to `.case_<id>.h5.part`; finish that file (wall time, the
!! case's scene) and rename it to `case_<id>.h5` once its status is final (complete or
!! failed, with the reason); remove the lock. A reader therefore never sees a case file
!! being written, and a file in place is always a finished run.
!!
!! Signals: SIGINT and SIGTERM are caught. While a case runs, the run driver stops at the
!! end of its current step, writes that state, the counters and status `interrupted` with
!! the reason, and the interrupted file is renamed into place like a failed one; the task
!! then ends (ERR_INTERRUPTED, exit 130) before its next case. A second signal ends the
!! process at once (the case then keeps its lock, which reads as abandoned, and its .part).
!!
!! Resume: a case whose file says `interrupted` is continued from its last record (the file
!! is moved back to its .part name under the lock, `run_scene(..., resume=.true.)` appends
!! to it, and it is renamed into place again), unless forced, which runs it anew. So is the
!! .part a killed writer left (status `running` or `interrupted`, records beyond the start,
!! this case's scene): it is continued where it is. A .part that holds a finished run of
!! the case (status complete: its writer was killed before the rename) is put in place.
module ropedyn_sweep_task
    use, intrinsic :: iso_fortran_env, only: error_unit, output_unit
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use ropedyn_kinds, only: wp
    use ropedyn_text, only: int_text, fixed_text, replaced
    use ropedyn_error, only: error_t, make_error, ERR_IO, ERR_INPUT, ERR_INTERRUPTED
    use ropedyn_os, only: make_dirs, rename_file, delete_file
    use ropedyn_clock, only: clock_seconds
    use ropedyn_signals, only: catch_signals, release_signals, signal_received, signal_name
    use ropedyn_scene, only: scene_t, scene_namelist_text
    use ropedyn_simulation, only: run_summary_t, run_scene
    use ropedyn_case_file, only: case_data_t, read_case_file, finish_case_file
    use ropedyn_h5, only: held_open
    use ropedyn_sweep_lock, only: take_lock, drop_lock, heartbeat_t
    use ropedyn_sweep, only: sweep_t, sweep_case_t
    use ropedyn_sweep_status, only: case_state_t, case_state, lock_path, part_path, &
        holds_case_scene, &
        write_failure_note, drop_failure_note
    implicit none
    private
    public :: run_cases, case_label, case_id, id_width, drop_stale_lock

contains

    !> 'sweep: case 0007'.
    function case_label(sweep, k) result(label)
        type(sweep_t), intent(in) :: sweep
        integer, intent(in) :: k
        character(len=:), allocatable :: label
        label = 'sweep: case '//case_id(sweep, k)
    end function case_label

    !> '0007': the id as in the case's file name.
    function case_id(sweep, k) result(id)
        type(sweep_t), intent(in) :: sweep
        integer, intent(in) :: k
        character(len=:), allocatable :: id
        character(len=16) :: buf
        write (buf, '(i0.'//int_text(id_width(sweep))//')') k
        id = trim(buf)
    end function case_id

    !> The digits of a case id: 4, or those of the number of cases when more.
    pure integer function id_width(sweep)
        type(sweep_t), intent(in) :: sweep
        id_width = max(4, len(int_text(size(sweep%cases))))
    end function id_width

    !> Run the cases `ids` one after the other. A case that fails does not stop the others;
    !! its message goes to stderr at once when there are several. The error: the case's
    !! own when there is one case, else a list of the cases not complete (the class: the
    !! highest of theirs); ERR_INTERRUPTED when a signal stopped the loop.
    subroutine run_cases(sweep, ids, force, quiet, err)
        type(sweep_t), intent(in) :: sweep
        integer, intent(in) :: ids(:)
        logical, intent(in) :: force, quiet
        type(error_t), allocatable, intent(out) :: err
        type(error_t), allocatable :: case_err
        character(len=:), allocatable :: failures
        integer :: k, bad, code

        call catch_signals(err)
        if (allocated(err)) return
        failures = ''
        bad = 0
        code = 0
        do k = 1, size(ids)
            if (signal_received() /= 0) then
                call make_error(err, ERR_INTERRUPTED, 'sweep: stopped by '// &
                    signal_name(signal_received())//' before '// &
                    'case '//case_id(sweep, ids(k))//' ('//int_text(size(ids) - k + 1)// &
                    ' case(s) of this task not run)')
                exit
            end if
            call run_one(sweep, ids(k), force, quiet, case_err)
            if (.not. allocated(case_err)) cycle
            if (size(ids) == 1) then
                call move_alloc(case_err, err)
                exit
            end if
            write (error_unit, '(a)') 'ropedyn: error: '//case_err%message
            bad = bad + 1
            code = max(code, case_err%code)
            if (len(failures) > 0) failures = failures//', '
            failures = failures//case_id(sweep, ids(k))
        end do
        call release_signals()
        if (bad > 0 .and. .not. allocated(err)) call make_error(err, code, 'sweep: '// &
            int_text(bad)//' of '//int_text(size(ids))//' cases of this task not complete: '// &
            failures)
    end subroutine run_cases

    !> One case: skip if complete, lock, run into the .part file, finish, rename, unlock.
    subroutine run_one(sweep, k, force, quiet, err)
        type(sweep_t), intent(in) :: sweep
        integer, intent(in) :: k
        logical, intent(in) :: force, quiet
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: label, lock, part
        type(heartbeat_t) :: beat
        logical :: done

        label = case_label(sweep, k)
        associate (c => sweep%cases(k))
            lock = lock_path(c%file)
            part = part_path(c%file)
            if (len(part) > len(c%scene%output%file)) then
                call make_error(err, ERR_INPUT, label//': '//part//': the file name is too ' &
                    //'long (at most '//int_text(len(c%scene%output%file))//' characters)')
                return
            end if
            if (.not. force) then
                call check_complete(c, label, quiet, done)
                if (done) return
            end if
            call make_dirs(sweep%output_dir, err, 'sweep')
            if (allocated(err)) return
            call take_lock(lock, beat, err)
            if (allocated(err)) then
                err%message = label//' ('//c%file//'): not run: '//err%message
                return
            end if
            call run_locked(c, label, part, force, quiet, err)
            call drop_lock(lock, beat)
        end associate
    end subroutine run_one

    !> Case c, its lock held: not when a signal came or another writer completed it
    !! meanwhile; an interrupted case continues from its last record (run anew when it
    !! cannot be continued); the file put in place and the outcome said.
    subroutine run_locked(c, label, part, force, quiet, err)
        type(sweep_case_t), intent(in) :: c
        character(len=*), intent(in) :: label, part
        logical, intent(in) :: force, quiet
        type(error_t), allocatable, intent(out) :: err
        type(run_summary_t) :: summary
        type(case_state_t) :: state
        type(scene_t) :: scene
        real(wp) :: start, wall, earlier
        logical :: removed, resume, done

        if (signal_received() /= 0) then
            call make_error(err, ERR_INTERRUPTED, label//': not run: stopped by '// &
                signal_name(signal_received()))
            return
        end if
        ! complete meanwhile (a writer that finished just before this one locked)?
        if (.not. force) then
            call check_complete(c, label, quiet, done)
            if (done) return
        end if
        ! a run of this case that finished, whose writer was killed before it renamed the
        ! file: put in place, not run again
        if (.not. force) then
            if (finished_part(c, part, wall)) then
                call put_in_place(c, part, wall, err)
                if (allocated(err)) then
                    err%message = label//' ('//c%file//'): '//err%message
                else
                    write (error_unit, '(a)') label//': complete in '//part//' (its writer '// &
                        'was killed before it renamed the file): put in place as '//c%file// &
                        ', not run again'
                end if
                return
            end if
        end if
        scene = c%scene
        scene%output%file = part
        ! an interrupted case continues from its last record, and so does the .part of a
        ! case whose writer was killed (its lock, abandoned, is this task's now)
        resume = .false.
        if (.not. force) then
            call case_state(c, state)
            resume = state%status == 'interrupted' .and. file_status(c%file) == 'interrupted'
        end if
        if (resume) then
            removed = delete_file(part)
            call rename_file(c%file, part, err)
            if (allocated(err)) return
            if (.not. quiet) write (output_unit, '(a)') label//': interrupted '// &
                'before: continuing it from its last record'
        else if (.not. force .and. killed_part(c, part, err)) then
            resume = .true.
            if (.not. quiet) write (output_unit, '(a)') label//': its writer was killed: '// &
                'continuing '//part//' from its last record'
        else if (allocated(err)) then
            ! (held open by another writer: not this task's to remove)
            err%message = label//': not run: '//err%message
            return
        else
            removed = delete_file(part)
        end if
        ! a continued case's wall time is its parts' (a killed part wrote none)
        earlier = 0.0_wp
        if (resume) earlier = wall_before(part)
        start = clock_seconds()
        call run_scene(scene, summary, err, resume=resume, guard=.false.)
        if (resume .and. allocated(err)) then
            ! not to be continued (nothing left, no restart data, ...): run it anew; so is
            ! a .part the resume could not read back (a writer killed in the middle of a
            ! flush can leave records HDF5 cannot read), which it left `running`
            if (err%code == ERR_INPUT .or. unread_part(part, err)) then
                write (error_unit, '(a)') label//': cannot be continued ('// &
                    err%message//'): running it anew'
                removed = delete_file(part)
                earlier = 0.0_wp
                start = clock_seconds()
                call run_scene(scene, summary, err, guard=.false.)
            end if
        end if
        call finish_case(c, label, part, earlier + clock_seconds() - start, summary, quiet, &
                         err)
    end subroutine run_locked

    !> The run's file put in place (part -> the case file, wall time its) and the failure
    !! note of a run without a file; the outcome said: the error named after the case, or
    !! the completion line.
    subroutine finish_case(c, label, part, wall, summary, quiet, err)
        type(sweep_case_t), intent(in) :: c
        character(len=*), intent(in) :: label, part
        real(wp), intent(in) :: wall
        type(run_summary_t), intent(in) :: summary
        logical, intent(in) :: quiet
        type(error_t), allocatable, intent(inout) :: err
        type(error_t), allocatable :: ferr
        call put_in_place(c, part, wall, ferr)
        if (allocated(ferr) .and. .not. allocated(err)) call move_alloc(ferr, err)
        ! a run that failed without a file leaves its message for the status
        call drop_failure_note(c%file)
        if (allocated(err)) then
            if (err%code /= ERR_INTERRUPTED .and. len(file_status(c%file)) == 0) &
                call write_failure_note(c%file, err%message)
            err%message = label//' ('//c%file//'): '//replaced(err%message, part, c%file)
            if (err%code == ERR_INTERRUPTED) err%message = err%message// &
                '; running the sweep again continues it'
            return
        end if
        if (.not. quiet) write (output_unit, '(a)') label//': complete: '// &
            int_text(int(summary%stats%steps))//' steps, cpu '// &
            fixed_text(summary%cpu_time, 3)//' s, wall '//fixed_text(wall, 3)//' s -> '// &
            c%file
    end subroutine finish_case

    !> Whether case c is complete already (done; then it is skipped, and said unless quiet).
    subroutine check_complete(c, label, quiet, done)
        type(sweep_case_t), intent(in) :: c
        character(len=*), intent(in) :: label
        logical, intent(in) :: quiet
        logical, intent(out) :: done
        type(case_state_t) :: state
        call case_state(c, state)
        done = state%status == 'complete'
        if (done) call drop_stale_lock(c, state)
        if (done .and. .not. quiet) write (output_unit, '(a)') label//': complete already ('// &
            c%file//'), skipped'
    end subroutine check_complete

    !> The abandoned lock of a complete case c (`state`: its status, read now) is removed:
    !! its writer was killed after it renamed the case file into place, before it removed
    !! the lock, and a complete case is not run again to remove it. It is taken over and
    !! dropped, as by any writer (a live lock, or one taken meanwhile, stays). A lock with
    !! a .part beside it (a killed rerun, --force) stays with its .part.
    subroutine drop_stale_lock(c, state)
        type(sweep_case_t), intent(in) :: c
        type(case_state_t), intent(in) :: state
        type(heartbeat_t) :: beat
        type(error_t), allocatable :: err
        logical :: partial
        if (state%status /= 'complete' .or. .not. state%lock%exists) return
        if (state%lock%live .or. len(state%lock%problem) > 0) return
        inquire (file=part_path(c%file), exist=partial)
        if (partial) return
        call take_lock(lock_path(c%file), beat, err)
        if (.not. allocated(err)) call drop_lock(lock_path(c%file), beat)
    end subroutine drop_stale_lock

    !> The .part file of a finished run becomes the case file: with its wall time and the
    !! case's scene, renamed into place. A run that did not finish its file (an error before
    !! the file was made, or an output error) leaves no case file: its .part is removed.
    subroutine put_in_place(c, part, wall, err)
        type(sweep_case_t), intent(in) :: c
        character(len=*), intent(in) :: part
        real(wp), intent(in) :: wall
        type(error_t), allocatable, intent(out) :: err
        type(case_data_t) :: data
        character(len=:), allocatable :: reason
        logical :: removed
        integer :: k
        call read_case_file(part, data, err)
        if (.not. data%exists) return
        if (allocated(err) .or. (data%status /= 'complete' .and. data%status /= 'failed' .and. &
                                 data%status /= 'interrupted')) then
            removed = delete_file(part)
            return
        end if
        ! the run named its file by the .part name in its reason and warnings (a continued
        ! run: the file it continued): name the case file
        reason = ''
        if (allocated(data%reason)) reason = replaced(data%reason, part, c%file)
        do k = 1, size(data%warnings)
            data%warnings(k)%s = replaced(data%warnings(k)%s, part, c%file)
        end do
        call finish_case_file(part, wall, scene_namelist_text(c%scene), err, reason, &
                              data%warnings)
        if (.not. allocated(err)) call rename_file(part, c%file, err)
        if (allocated(err)) removed = delete_file(part)
    end subroutine put_in_place

    !> The wall time (s) the earlier parts of a case wrote into `part`, the file a run is
    !! about to continue; 0 when it holds none (a killed part writes none).
    real(wp) function wall_before(part) result(wall)
        character(len=*), intent(in) :: part
        type(case_data_t) :: data
        type(error_t), allocatable :: err
        wall = 0.0_wp
        call read_case_file(part, data, err)
        if (allocated(err) .or. .not. data%exists) return
        if (ieee_is_finite(data%wall_time)) wall = data%wall_time
    end function wall_before

    !> `part` is a finished run of this very case (status complete, its data reads back)
    !! whose writer was killed after the run ended, before it renamed the file into place.
    !! `wall`: the wall time the file holds (NaN: the writer was killed before it wrote
    !! it). A `part` that cannot be read (or is held open) is not: killed_part says which.
    logical function finished_part(c, part, wall)
        type(sweep_case_t), intent(in) :: c
        character(len=*), intent(in) :: part
        real(wp), intent(out) :: wall
        type(case_data_t) :: data
        type(error_t), allocatable :: err
        call read_case_file(part, data, err, series=.true.)
        wall = data%wall_time
        finished_part = .false.
        if (allocated(err) .or. .not. data%exists) return
        finished_part = data%status == 'complete' .and. data%records >= 1 .and. &
            holds_case_scene(c, data%scene)
    end function finished_part

    !> `part` holds records of this very case beyond its start, written by a run that was
    !! killed (status still `running`, or `interrupted`: the writer was killed after it
    !! moved an interrupted case file back to its .part name, before the run reopened it;
    !! its writer's lock is this task's now). A `part` that another process holds open
    !! (HDF5's lock) is an ERR_IO error: not to be removed.
    logical function killed_part(c, part, err)
        type(sweep_case_t), intent(in) :: c
        character(len=*), intent(in) :: part
        type(error_t), allocatable, intent(out) :: err
        type(case_data_t) :: data
        killed_part = .false.
        call read_case_file(part, data, err)
        if (allocated(err)) then
            ! unreadable (damaged): run anew; locked: the caller's error
            if (.not. held_open(err)) deallocate (err)
            return
        end if
        if (.not. data%exists) return
        ! `interrupted`: an interrupted case file moved back to its .part name, or a run
        ! stopped by a signal, whose writer was killed before it renamed the file
        killed_part = (data%status == 'running' .or. data%status == 'interrupted') .and. &
            data%records >= 2 .and. holds_case_scene(c, data%scene)
    end function killed_part

    !> The resume of the killed writer's `part` failed with `err` and left it as it was
    !! (status `running`: a resume that ran closes its file with a final status): its
    !! records do not read back. Not for a signal, nor a file another process holds open.
    logical function unread_part(part, err)
        character(len=*), intent(in) :: part
        type(error_t), intent(in) :: err
        unread_part = .false.
        if (err%code == ERR_INTERRUPTED .or. signal_received() /= 0) return
        unread_part = file_status(part) == 'running'
    end function unread_part

    !> The status attribute of the run file `path` ('' when it cannot be read).
    function file_status(path) result(status)
        character(len=*), intent(in) :: path
        character(len=:), allocatable :: status
        type(case_data_t) :: data
        type(error_t), allocatable :: err
        call read_case_file(path, data, err)
        status = ''
        if (.not. allocated(err) .and. data%exists .and. allocated(data%status)) &
            status = data%status
    end function file_status
end module ropedyn_sweep_task
