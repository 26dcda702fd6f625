!> Worker processes and what identifies a process, through the C glue `ropedyn_process.c`
!! (and a few libc calls): worker processes in their own process group (spawn, reap,
!! signal, wait for their end), a lock file's heartbeat, process ids and start times, the
!! host name, the Slurm job, file times. Used by the sweep runner and a sweep case's lock
!! (the sweeps guide). Signals are ropedyn_signals', clocks ropedyn_clock's.
module ropedyn_process
    use, intrinsic :: iso_c_binding, only: c_char, c_int, c_long, c_long_long, c_null_char, &
        c_size_t, c_ptr, c_null_ptr
    use, intrinsic :: iso_fortran_env, only: int64
    use ropedyn_error, only: error_t, make_error, ERR_IO
    use ropedyn_text, only: int_text
    implicit none
    private
    public :: slurm_job, process_text
    public :: heartbeat_t, start_heartbeat, stop_heartbeat
    public :: spawn, reap, signal_group, process_id, process_start, host_name
    public :: watch_children, unwatch_children, wait_children
    public :: file_mtime

    !> A lock file's heartbeat (start_heartbeat .. stop_heartbeat): each lock has its own.
    type :: heartbeat_t
        private
        type(c_ptr) :: handle = c_null_ptr
    end type heartbeat_t

    interface
        integer(c_int) function c_start_heartbeat(path, seconds, handle) &
                bind(C, name='ropedyn_start_heartbeat')
            import :: c_char, c_int, c_ptr
            character(kind=c_char), intent(in) :: path(*)
            integer(c_int), value :: seconds
            type(c_ptr), intent(out) :: handle
        end function c_start_heartbeat
        subroutine c_stop_heartbeat(handle) bind(C, name='ropedyn_stop_heartbeat')
            import :: c_ptr
            type(c_ptr), value :: handle
        end subroutine c_stop_heartbeat
        integer(c_int) function c_spawn(args, nargs, log, pid) bind(C, name='ropedyn_spawn')
            import :: c_char, c_int
            character(kind=c_char), intent(in) :: args(*), log(*)
            integer(c_int), value :: nargs
            integer(c_int), intent(out) :: pid
        end function c_spawn
        integer(c_int) function c_reap(pid, code) bind(C, name='ropedyn_reap')
            import :: c_int
            integer(c_int), value :: pid
            integer(c_int), intent(out) :: code
        end function c_reap
        integer(c_int) function c_watch_children() bind(C, name='ropedyn_watch_children')
            import :: c_int
        end function c_watch_children
        subroutine unwatch_children() bind(C, name='ropedyn_unwatch_children')
        end subroutine unwatch_children
        integer(c_int) function c_wait_children(microseconds) &
                bind(C, name='ropedyn_wait_children')
            import :: c_int, c_long
            integer(c_long), value :: microseconds
        end function c_wait_children
        integer(c_int) function c_signal_group(pgid, sig) bind(C, name='ropedyn_signal_group')
            import :: c_int
            integer(c_int), value :: pgid, sig
        end function c_signal_group
        integer(c_long_long) function c_process_start(pid) bind(C, name='ropedyn_process_start')
            import :: c_int, c_long_long
            integer(c_int), value :: pid
        end function c_process_start
        integer(c_long_long) function c_file_mtime(path) bind(C, name='ropedyn_file_mtime')
            import :: c_char, c_long_long
            character(kind=c_char), intent(in) :: path(*)
        end function c_file_mtime
        integer(c_int) function c_getpid() bind(C, name='getpid')
            import :: c_int
        end function c_getpid
        integer(c_int) function c_gethostname(name, size) bind(C, name='gethostname')
            import :: c_char, c_int, c_size_t
            character(kind=c_char), intent(out) :: name(*)
            integer(c_size_t), value :: size
        end function c_gethostname
    end interface

contains

    !> Touch the file `path` now and every `seconds` s (from a thread of its own) until
    !! stop_heartbeat(beat).
    subroutine start_heartbeat(path, seconds, beat, err)
        character(len=*), intent(in) :: path
        integer, intent(in) :: seconds
        type(heartbeat_t), intent(out) :: beat
        type(error_t), allocatable, intent(out) :: err
        integer(c_int) :: rc
        rc = c_start_heartbeat(path//c_null_char, int(seconds, c_int), beat%handle)
        if (rc /= 0) call make_error(err, ERR_IO, path//': cannot start its heartbeat (errno ' &
            //int_text(int(rc))//')')
    end subroutine start_heartbeat

    !> Stop a heartbeat (one never started, or stopped already: nothing).
    subroutine stop_heartbeat(beat)
        type(heartbeat_t), intent(inout) :: beat
        call c_stop_heartbeat(beat%handle)
        beat%handle = c_null_ptr
    end subroutine stop_heartbeat

    !> Start `args(1)` (looked up in PATH when it has no '/') with the other arguments in a
    !! process group of its own, stdin from /dev/null, stdout and stderr appended to the file
    !! `log`.
    subroutine spawn(args, log, pid, err)
        character(len=*), intent(in) :: args(:)
        character(len=*), intent(in) :: log
        integer, intent(out) :: pid
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: packed
        integer(c_int) :: rc, cpid
        integer :: k
        packed = ''
        do k = 1, size(args)
            packed = packed//trim(args(k))//c_null_char
        end do
        pid = 0
        rc = c_spawn(packed, int(size(args), c_int), log//c_null_char, cpid)
        if (rc /= 0) then
            call make_error(err, ERR_IO, 'cannot start '//trim(args(1))//' (errno '// &
                int_text(int(rc))//')')
            return
        end if
        pid = int(cpid)
    end subroutine spawn

    !> Whether child `pid` has ended; if so `code` is its exit status or 128 + the signal
    !! that ended it (255 if it cannot be told). Does not wait.
    logical function reap(pid, code) result(ended)
        integer, intent(in) :: pid
        integer, intent(out) :: code
        integer(c_int) :: rc, c
        rc = c_reap(int(pid, c_int), c)
        ended = rc /= 0
        code = int(c)
        if (rc < 0) code = 255
    end function reap

    !> From now on until `unwatch_children`, the end of a child wakes `wait_children`
    !! (SIGCHLD is blocked outside it, so that an end between a reap and the wait is kept).
    subroutine watch_children(err)
        type(error_t), allocatable, intent(out) :: err
        integer(c_int) :: rc
        rc = c_watch_children()
        if (rc /= 0) call make_error(err, ERR_IO, 'cannot watch for the end of worker '// &
            'processes (errno '//int_text(int(rc))//')')
    end subroutine watch_children

    !> Sleep until a watched child ends or a signal is caught (true), or at most
    !! `microseconds` (false: the time passed).
    logical function wait_children(microseconds) result(woken)
        integer, intent(in) :: microseconds
        woken = c_wait_children(int(microseconds, c_long)) /= 0
    end function wait_children

    !> Send `sig` to the process group `pgid` (a spawned worker's pid); false if it is gone.
    logical function signal_group(pgid, sig) result(sent)
        integer, intent(in) :: pgid, sig
        sent = c_signal_group(int(pgid, c_int), int(sig, c_int)) == 0
    end function signal_group

    integer function process_id()
        process_id = int(c_getpid())
    end function process_id

    !> Start time of process `pid` (0: this process) in clock ticks after boot; 0 when the
    !! process exists but its start time is unknown; -1 when there is no such process, or
    !! it has ended and waits for its parent to reap it (a zombie).
    integer(int64) function process_start(pid)
        integer, intent(in) :: pid
        process_start = int(c_process_start(int(pid, c_int)), int64)
    end function process_start

    !> The Slurm job this process runs in: 'ARRAYJOB_TASK' for an array task, else the job
    !! id; '' outside Slurm.
    function slurm_job() result(job)
        character(len=:), allocatable :: job
        character(len=64) :: array_job, array_task, id
        integer :: n1, n2, n3
        call get_environment_variable('SLURM_ARRAY_JOB_ID', array_job, n1)
        call get_environment_variable('SLURM_ARRAY_TASK_ID', array_task, n2)
        call get_environment_variable('SLURM_JOB_ID', id, n3)
        if (n1 > 0 .and. n2 > 0) then
            job = trim(array_job)//'_'//trim(array_task)
        else if (n3 > 0) then
            job = trim(id)
        else
            job = ''
        end if
    end function slurm_job

    !> 'host H, pid P' and ', Slurm job J' inside Slurm: who this process is, for messages.
    function process_text() result(text)
        character(len=:), allocatable :: text
        text = 'host '//host_name()//', pid '//int_text(process_id())
        if (len(slurm_job()) > 0) text = text//', Slurm job '//slurm_job()
    end function process_text

    !> This host's name ('unknown' if it cannot be had).
    function host_name() result(name)
        character(len=:), allocatable :: name
        character(kind=c_char, len=256) :: buf
        integer :: k
        buf = repeat(c_null_char, len(buf))
        name = 'unknown'
        if (c_gethostname(buf, int(len(buf) - 1, c_size_t)) /= 0) return
        k = index(buf, c_null_char)
        if (k > 1) name = buf(:k - 1)
    end function host_name

    !> Modification time of `path` in s since 1970; -1 when it does not exist.
    integer(int64) function file_mtime(path)
        character(len=*), intent(in) :: path
        file_mtime = int(c_file_mtime(path//c_null_char), int64)
    end function file_mtime
end module ropedyn_process
