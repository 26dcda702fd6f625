!> The lock of a sweep case: one writer per case (docs/development/internals.md, "One writer per case").
!!
!! A writer creates `<output_dir>/.case_<id>.lock`, if it does not exist, with who it is
!! already in it (`create_whole`: the lock appears whole or not at all):
!!
!!     ropedyn sweep case lock
!!     host=node12
!!     boot=8a3c...             (/proc/sys/kernel/random/boot_id: this machine since its boot)
!!     pid=4711
!!     start_ticks=123456        (the process's start, /proc/PID/stat; tells a reused pid)
!!     started=2024-05-01T12:34:56Z
!!     job=8812_3                (SLURM_ARRAY_JOB_ID_SLURM_ARRAY_TASK_ID, or SLURM_JOB_ID)
!!
!! A thread touches the file every LOCK_BEAT s (its heartbeat) while the case runs. The
!! writer removes the lock when the case file is in place. A lock is *live* while its writer
!! runs and *abandoned* when it is gone:
!!
!! - it records a signal (`signal=15`, appended by writers of earlier versions when a
!!   signal ended them; a writer now stops its case itself): abandoned;
!! - it records why its writer is gone (`gone=...`: a lock handed back by a process that
!!   took it over and then did not write, `hand_back_lock`): abandoned;
!! - on this machine (the same host name and boot id): live while process `pid` exists
!!   with the same start time, abandoned as soon as it does not;
!! - on another machine: live while its heartbeat is at most LOCK_ABANDONED_AFTER s old (the
!!   file's modification time against this host's clock: clocks must agree within that).
!!
!! A second writer finds a live lock and gives up with a message naming the holder; an
!! abandoned lock is taken over under a second exclusive lock, `<lock>.break`, so that of
!! two writers finding the same abandoned lock only one takes it (a `.break` older than
!! BREAK_ABANDONED_AFTER s is left by a writer that died while breaking, and is removed).
module ropedyn_sweep_lock
    use, intrinsic :: iso_fortran_env, only: int64
    use ropedyn_error, only: error_t, make_error, ERR_IO
    use ropedyn_text, only: int_text
    use ropedyn_os, only: delete_file, rename_file, special_file_reason, create_whole, &
        errno_text, ERRNO_EEXIST
    use ropedyn_clock, only: utc_timestamp, utc_text, unix_time
    use ropedyn_signals, only: signal_name
    use ropedyn_process, only: process_id, process_start, host_name, file_mtime, &
        start_heartbeat, stop_heartbeat, slurm_job, heartbeat_t
    implicit none
    private
    public :: lock_t, read_lock, take_lock, drop_lock, hand_back_lock, LOCK_BEAT
    public :: LOCK_ABANDONED_AFTER
    public :: heartbeat_t

    integer, parameter :: LOCK_BEAT = 15                !< s between heartbeats
    integer, parameter :: LOCK_ABANDONED_AFTER = 120    !< s: a lock of another host is gone
    integer, parameter :: BREAK_ABANDONED_AFTER = 30    !< s: a .break lock is gone
    !> The first line of every lock
    character(len=*), parameter :: LOCK_HEADER = 'ropedyn sweep case lock'

    !> What a lock file says, and whether its writer runs.
    type :: lock_t
        logical :: exists = .false.
        logical :: live = .false.      !< its writer runs (or may run: see the rule)
        logical :: mine = .false.      !< held by this process
        character(len=:), allocatable :: host, boot, job, started
        integer :: pid = 0
        integer(int64) :: start_ticks = 0
        integer :: signal = 0          !< the signal that ended the writer (0: none recorded)
        integer(int64) :: changed = 0  !< last heartbeat (or the signal), s since 1970
        integer(int64) :: age = 0      !< s since then
        !> '' or why the lock's path cannot be a lock (not a regular file: a FIFO, ...)
        character(len=:), allocatable :: problem
        !> the file's lines as read (without `gone=`), for `hand_back_lock`
        character(len=:), allocatable :: text
        !> why its writer is gone, as a `gone=` line of a handed-back lock says ('': none)
        character(len=:), allocatable :: gone_note
    contains
        procedure :: holder => lock_holder
        procedure :: gone => lock_gone
    end type lock_t

contains

    !> Read the lock file `path` and decide whether its writer runs.
    subroutine read_lock(path, lock)
        character(len=*), intent(in) :: path
        type(lock_t), intent(out) :: lock
        character(len=512) :: line
        integer :: unit, ios, eq
        integer(int64) :: ticks
        logical :: empty, known

        lock%host = ''
        lock%boot = ''
        lock%job = ''
        lock%started = ''
        lock%text = ''
        lock%gone_note = ''
        lock%problem = special_file_reason(path)
        if (len(lock%problem) > 0) then
            ! a FIFO would block the open: not a lock of ropedyn, nor is a device
            lock%exists = .true.
            lock%problem = path//': '//lock%problem//' (a lock is a regular file: remove it)'
            return
        end if
        ! open first: on NFS, an open revalidates the attributes (close-to-open)
        open (newunit=unit, file=path, status='old', action='read', iostat=ios)
        if (ios /= 0) return
        lock%exists = .true.
        empty = .true.
        known = .false.
        do
            read (unit, '(a)', iostat=ios) line
            if (ios /= 0) exit
            empty = .false.
            if (line == LOCK_HEADER) known = .true.
            eq = index(line, '=')
            ! every line but `gone=`, the header too (hand_back_lock writes them back)
            if (line(:len('gone=')) /= 'gone=') lock%text = lock%text//trim(line)//new_line('a')
            if (eq < 2) cycle
            select case (line(:eq - 1))
            case ('host', 'boot', 'job', 'started', 'pid', 'start_ticks', 'signal', 'gone')
                known = .true.
            end select
            select case (line(:eq - 1))
            case ('host')
                lock%host = trim(line(eq + 1:))
            case ('boot')
                lock%boot = trim(line(eq + 1:))
            case ('job')
                lock%job = trim(line(eq + 1:))
            case ('started')
                lock%started = trim(line(eq + 1:))
            case ('pid')
                read (line(eq + 1:), *, iostat=ios) lock%pid
            case ('start_ticks')
                read (line(eq + 1:), *, iostat=ios) lock%start_ticks
            case ('signal')
                read (line(eq + 1:), *, iostat=ios) lock%signal
            case ('gone')
                lock%gone_note = trim(line(eq + 1:))
            end select
        end do
        close (unit)
        if (.not. empty .and. .not. known) then
            ! not a lock of ropedyn (the user's FILE.lock): never taken over (removed); an
            ! empty file is a lock whose writer has not said who it is yet
            lock%problem = path//': not a lock of ropedyn (no "'//LOCK_HEADER//'" line, '// &
                'no host=, pid=): left as it is; remove it or write elsewhere'
            return
        end if
        lock%changed = file_mtime(path)
        if (lock%changed < 0) then   ! removed meanwhile
            lock%exists = .false.
            return
        end if
        lock%age = max(0_int64, unix_time() - lock%changed)
        if (lock%signal > 0 .or. len(lock%gone_note) > 0) then
            lock%live = .false.
        else if (lock%pid <= 0) then
            ! not written yet (just created) or damaged: live while young
            lock%live = lock%age <= LOCK_ABANDONED_AFTER
        else if (this_machine(lock)) then
            ticks = process_start(lock%pid)
            lock%live = ticks >= 0
            if (ticks > 0 .and. lock%start_ticks > 0) lock%live = ticks == lock%start_ticks
            lock%mine = lock%live .and. lock%pid == process_id()
        else
            lock%live = lock%age <= LOCK_ABANDONED_AFTER
        end if
    end subroutine read_lock

    !> Whether the lock was written on this machine: the same host name and, when both are
    !! known, the same boot id (two machines with one host name are told apart).
    logical function this_machine(lock)
        type(lock_t), intent(in) :: lock
        character(len=:), allocatable :: boot
        this_machine = len(lock%host) > 0 .and. lock%host == host_name()
        if (.not. this_machine .or. len(lock%boot) == 0) return
        boot = boot_id()
        if (len(boot) > 0) this_machine = lock%boot == boot
    end function this_machine

    !> This machine's boot id ('' where there is none).
    function boot_id() result(id)
        character(len=:), allocatable :: id
        character(len=64) :: line
        integer :: unit, ios
        id = ''
        open (newunit=unit, file='/proc/sys/kernel/random/boot_id', status='old', &
              action='read', iostat=ios)
        if (ios /= 0) return
        read (unit, '(a)', iostat=ios) line
        close (unit)
        if (ios == 0) id = trim(line)
    end function boot_id

    !> 'host H, pid P, Slurm job J, since T' (what is known of it).
    function lock_holder(self) result(text)
        class(lock_t), intent(in) :: self
        character(len=:), allocatable :: text
        text = 'host '//self%host//', pid '//int_text(self%pid)
        if (len(self%host) == 0) text = 'a writer that has not said who it is yet'
        if (len(self%job) > 0) text = text//', Slurm job '//self%job
        if (len(self%started) > 0) text = text//', since '//self%started
    end function lock_holder

    !> Why an abandoned lock's writer is gone, for the reason of an interrupted case.
    function lock_gone(self) result(text)
        class(lock_t), intent(in) :: self
        character(len=:), allocatable :: text
        if (len(self%gone_note) > 0) then
            text = self%gone_note
        else if (self%signal > 0) then
            text = 'stopped by '//signal_name(self%signal)//' at '//utc_text(self%changed)// &
                ' ('//self%holder()//')'
        else if (this_machine(self)) then
            text = 'its writer ended without finishing: killed or crashed ('// &
                self%holder()//'; that process is gone)'
        else
            text = 'its writer ended without finishing: killed, crashed or its node failed ('// &
                self%holder()//'; no heartbeat for '//int_text(int(self%age))//' s)'
        end if
    end function lock_gone

    !> Take the lock `path` for this process (and start its heartbeat `beat`): create it, or
    !! take over an abandoned one. A live lock is an ERR_IO error naming its holder.
    subroutine take_lock(path, beat, err)
        character(len=*), intent(in) :: path
        type(heartbeat_t), intent(out) :: beat
        type(error_t), allocatable, intent(out) :: err
        type(lock_t) :: lock
        logical :: created, removed
        integer :: attempt
        character(len=:), allocatable :: holder

        ! who this writer is, found before the lock is made and written in the open that
        ! makes it: a writer killed in between leaves no lock, or a whole one
        holder = holder_text()
        do attempt = 1, 2
            call create_exclusive(path, created, err, holder)
            if (allocated(err)) return
            if (created) exit
            call read_lock(path, lock)
            if (.not. lock%exists) cycle        ! removed meanwhile: try again
            if (len(lock%problem) > 0) then
                call make_error(err, ERR_IO, lock%problem)
                return
            end if
            if (lock%live) then
                call make_error(err, ERR_IO, 'being written by '//lock%holder()//' (lock '// &
                    path//'): a file is written by one process at a time')
                return
            end if
            ! abandoned: break it under the lock <path>.break
            call create_exclusive(path//'.break', created, err)
            if (allocated(err)) return
            if (.not. created) then
                if (unix_time() - file_mtime(path//'.break') > BREAK_ABANDONED_AFTER) then
                    removed = delete_file(path//'.break')
                    cycle
                end if
                call make_error(err, ERR_IO, 'another process is taking over the abandoned ' &
                    //'lock '//path)
                return
            end if
            call read_lock(path, lock)
            if (lock%exists .and. lock%live) then
                removed = delete_file(path//'.break')
                call make_error(err, ERR_IO, 'being written by '//lock%holder()//' (lock '// &
                    path//'): a file is written by one process at a time')
                return
            end if
            if (lock%exists) removed = delete_file(path)
            call create_exclusive(path, created, err, holder)
            removed = delete_file(path//'.break')
            if (allocated(err)) return
            if (.not. created) then
                call make_error(err, ERR_IO, 'being written by another process (lock '// &
                    path//' was taken meanwhile)')
                return
            end if
            exit
        end do
        if (.not. created) then
            call make_error(err, ERR_IO, path//': cannot take the lock')
            return
        end if
        call start_heartbeat(path, LOCK_BEAT, beat, err)
    end subroutine take_lock

    !> Stop the lock's heartbeat and remove the lock (and a `path`.back left by a process
    !! killed while it handed the lock back, `hand_back_lock`).
    subroutine drop_lock(path, beat)
        character(len=*), intent(in) :: path
        type(heartbeat_t), intent(inout) :: beat
        logical :: removed
        call stop_heartbeat(beat)
        removed = delete_file(path//'.back')
        removed = delete_file(path)
    end subroutine drop_lock

    !> Stop the lock's heartbeat and give the lock `path` back to the writer that held it
    !! before this process took it over (`before`, abandoned, as read then): its lines, and
    !! why that writer is gone (`gone=`), so that the lock stays abandoned and goes on naming
    !! it. For a process that took over an abandoned lock and then wrote nothing (a refused
    !! resume). The lines are written to `path`.back and renamed over the lock, so that a kill
    !! leaves this process's own lock (abandoned as soon as it is gone), never an empty one
    !! (which would hold the file for LOCK_ABANDONED_AFTER s). The lock is removed when it
    !! cannot be written.
    subroutine hand_back_lock(path, beat, before)
        character(len=*), intent(in) :: path
        type(heartbeat_t), intent(inout) :: beat
        type(lock_t), intent(in) :: before
        type(error_t), allocatable :: err
        integer :: unit, ios
        logical :: removed
        call stop_heartbeat(beat)
        open (newunit=unit, file=path//'.back', status='replace', action='write', iostat=ios)
        if (ios == 0) write (unit, '(a)', iostat=ios) before%text//'gone='//before%gone()
        if (ios == 0) close (unit, iostat=ios)
        if (ios == 0) call rename_file(path//'.back', path, err)
        if (ios /= 0 .or. allocated(err)) then
            removed = delete_file(path//'.back')
            removed = delete_file(path)
        end if
    end subroutine hand_back_lock

    !> Create `path` if it does not exist, with the lines `text` if given (empty otherwise),
    !! whole or not at all (`create_whole`: a lock that does not say who holds it would hold
    !! its file for LOCK_ABANDONED_AFTER s); `created` false if it existed.
    subroutine create_exclusive(path, created, err, text)
        character(len=*), intent(in) :: path
        logical, intent(out) :: created
        type(error_t), allocatable, intent(out) :: err
        character(len=*), intent(in), optional :: text
        integer :: rc
        if (present(text)) then
            rc = create_whole(path, text//new_line('a'))
        else
            rc = create_whole(path, '')
        end if
        created = rc == 0
        if (rc /= 0 .and. rc /= ERRNO_EEXIST) &
            call make_error(err, ERR_IO, path//': cannot create: '//errno_text(rc))
    end subroutine create_exclusive

    !> Who holds a lock this process takes: the lines written into it.
    function holder_text() result(text)
        character(len=:), allocatable :: text
        text = LOCK_HEADER//new_line('a')//'host='//host_name()//new_line('a')//'boot='// &
            boot_id()//new_line('a')//'pid='//int_text(process_id())//new_line('a')// &
            'start_ticks='//int_text(process_start(0))//new_line('a')//'started='// &
            utc_timestamp()//new_line('a')//'job='//slurm_job()
    end function holder_text
end module ropedyn_sweep_lock
