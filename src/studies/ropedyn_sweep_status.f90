!> The status of a sweep case, from its lock (src/io/ropedyn_sweep_lock.f90) and its file
!! (docs/guide/sweeps.md, "Status of a case"):
!!
!! - running: its lock is live: a writer is at it (here or on another host);
!! - complete: its file holds this case's scene, status complete, and its data reads back;
!! - failed: its file says the run failed (with the reason);
!! - interrupted: its writer stopped before the end: a signal (Ctrl-C, scancel, a time
!!   limit), a kill, a crash or a node failure (an abandoned lock), or a file with status
!!   interrupted;
!! - stale: its file holds another scene (where the file is aside): the sweep changed;
!! - unreadable: its file is there but does not read back (the reason says what failed);
!! - missing: no file, no lock (but a run that failed before it made its file, a statics
!!   start that found no equilibrium for one, left a note `.case_<id>.failed` with its
!!   message: the case is then failed, for that reason).
!!
!! Only `complete` counts as done; every other status runs again (`running` only once its
!! writer is gone).
module ropedyn_sweep_status
    use ropedyn_error, only: error_t
    use ropedyn_os, only: rename_file, delete_file
    use ropedyn_scene, only: scene_namelist_text, echo_without_output_file
    use ropedyn_case_file, only: case_data_t, read_case_file
    use ropedyn_sweep_lock, only: lock_t, read_lock
    use ropedyn_sweep, only: sweep_case_t
    implicit none
    private
    public :: case_state_t, case_state, lock_path, part_path, holds_case_scene, STATUS_NAMES
    public :: write_failure_note, drop_failure_note

    !> Every status, in the order of `--status`.
    character(len=*), parameter :: STATUS_NAMES(7) = [character(len=11) :: 'complete', &
        'failed', 'interrupted', 'running', 'stale', 'unreadable', 'missing']

    !> A case's status, why (empty for complete and missing), its lock and what its file
    !! holds (the series too, for a complete case).
    type :: case_state_t
        character(len=:), allocatable :: status
        character(len=:), allocatable :: reason
        type(lock_t) :: lock
        type(case_data_t) :: data
    end type case_state_t

contains

    !> A run file whose effective scene is `stored` holds case c: the same scene, its own
    !! &output file aside (the output directory may be spelled another way, or moved, and
    !! a .part names itself).
    function holds_case_scene(c, stored) result(holds)
        type(sweep_case_t), intent(in) :: c
        character(len=*), intent(in) :: stored
        logical :: holds
        holds = echo_without_output_file(stored) == &
            echo_without_output_file(scene_namelist_text(c%scene))
    end function holds_case_scene

    !> `<output_dir>/.case_<id>.lock`, the lock of the case file `file`.
    pure function lock_path(file) result(path)
        character(len=*), intent(in) :: file
        character(len=:), allocatable :: path
        path = hidden(file)
        path = path(:len(path) - 3)//'.lock'
    end function lock_path

    !> `<output_dir>/.case_<id>.h5.part`, the file a writer writes before it is complete.
    pure function part_path(file) result(path)
        character(len=*), intent(in) :: file
        character(len=:), allocatable :: path
        path = hidden(file)//'.part'
    end function part_path

    !> The case's status. A lock held by this very process does not make it `running`.
    subroutine case_state(c, state)
        type(sweep_case_t), intent(in) :: c
        type(case_state_t), intent(out) :: state
        type(error_t), allocatable :: err
        logical :: partial

        state%reason = ''
        call read_lock(lock_path(c%file), state%lock)
        associate (lock => state%lock)
            if (len(lock%problem) > 0) then
                state%status = 'unreadable'
                state%reason = lock%problem
                return
            end if
            if (lock%live .and. .not. lock%mine) then
                state%status = 'running'
                state%reason = 'being written by '//lock%holder()
                return
            end if
            call read_case_file(c%file, state%data, err, series=.true.)
            if (allocated(err)) then
                state%status = 'unreadable'
                state%reason = err%message
            else if (.not. state%data%exists) then
                state%status = 'missing'
                state%reason = failure_note(c%file)
                if (len(state%reason) > 0) state%status = 'failed'
                if (state%status == 'missing') state%reason = finished_part_note(c)
            else if (.not. holds_case_scene(c, state%data%scene)) then
                state%status = 'stale'
                state%reason = 'the file holds another scene than this case (the sweep ' &
                    //'changed); run the sweep again'
            else
                select case (state%data%status)
                case ('complete')
                    state%status = 'complete'
                    if (state%data%records < 1) then
                        state%status = 'unreadable'
                        state%reason = c%file//': status complete but no output record'
                    end if
                case ('failed')
                    state%status = 'failed'
                    state%reason = state%data%reason
                case ('interrupted')
                    state%status = 'interrupted'
                    state%reason = state%data%reason
                case default
                    state%status = 'interrupted'
                    state%reason = 'the run in the file did not finish (status "'// &
                        state%data%status//'": its writer was killed or crashed)'
                end select
            end if
            ! an abandoned lock: the latest attempt stopped; what the file holds is older
            if (lock%exists .and. .not. lock%live .and. .not. lock%mine .and. &
                state%status /= 'complete') then
                state%status = 'interrupted'
                state%reason = lock%gone()
                inquire (file=part_path(c%file), exist=partial)
                if (partial) then
                    if (len(finished_part_note(c)) > 0) then
                        state%reason = state%reason//'; '//finished_part_note(c)
                    else
                        state%reason = state%reason//'; partial output in '//part_path(c%file)
                    end if
                end if
            end if
        end associate
    end subroutine case_state

    !> '' unless the case's .part holds a finished run of the case (status complete), left
    !! by a writer killed before it renamed the file: then that, and that the next sweep
    !! puts it in place (ropedyn_sweep_task).
    function finished_part_note(c) result(text)
        type(sweep_case_t), intent(in) :: c
        character(len=:), allocatable :: text
        type(case_data_t) :: data
        type(error_t), allocatable :: err
        text = ''
        call read_case_file(part_path(c%file), data, err)
        if (allocated(err) .or. .not. data%exists) return
        if (data%status /= 'complete' .or. .not. holds_case_scene(c, data%scene)) return
        text = part_path(c%file)//' holds the finished run (its writer was killed before '// &
            'it renamed the file): the next sweep puts it in place'
    end function finished_part_note

    !> `<output_dir>/.case_<id>.failed`, the note of a case whose run failed before it made
    !! its file (`file` the case file).
    pure function note_path(file) result(path)
        character(len=*), intent(in) :: file
        character(len=:), allocatable :: path
        path = hidden(file)
        path = path(:len(path) - 3)//'.failed'
    end function note_path

    !> Leave the note of a run of case file `file` that failed with `message` and made no
    !! file (written aside and renamed: a reader sees the whole message or none). A note
    !! that cannot be written is left out: the message went to the task's output as well.
    subroutine write_failure_note(file, message)
        character(len=*), intent(in) :: file, message
        type(error_t), allocatable :: err
        integer :: unit, ios
        logical :: removed
        open (newunit=unit, file=note_path(file)//'.tmp', status='replace', action='write', &
              iostat=ios)
        if (ios /= 0) return
        write (unit, '(a)', iostat=ios) message
        close (unit)
        if (ios == 0) call rename_file(note_path(file)//'.tmp', note_path(file), err)
        if (ios /= 0 .or. allocated(err)) removed = delete_file(note_path(file)//'.tmp')
    end subroutine write_failure_note

    !> Remove the note of case file `file` (a run that made its file says itself how it
    !! ended).
    subroutine drop_failure_note(file)
        character(len=*), intent(in) :: file
        logical :: removed
        removed = delete_file(note_path(file))
    end subroutine drop_failure_note

    !> The message of the note of case file `file` ('' when there is none).
    function failure_note(file) result(message)
        character(len=*), intent(in) :: file
        character(len=:), allocatable :: message
        character(len=4096) :: line
        integer :: unit, ios
        message = ''
        open (newunit=unit, file=note_path(file), status='old', action='read', iostat=ios)
        if (ios /= 0) return
        read (unit, '(a)', iostat=ios) line
        close (unit)
        if (ios == 0) message = 'not run: '//trim(line)
    end function failure_note

    !> `dir/.name` for `dir/name`.
    pure function hidden(file) result(path)
        character(len=*), intent(in) :: file
        character(len=:), allocatable :: path
        integer :: slash
        slash = index(file, '/', back=.true.)
        path = file(:slash)//'.'//file(slash + 1:)
    end function hidden
end module ropedyn_sweep_status
