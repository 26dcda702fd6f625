!> Unit test of the one-writer-per-case machinery: ropedyn_sweep_lock (take, read, drop; a
!! second taker refused; an abandoned lock of this host taken over; a recorded signal),
!! the heartbeat of ropedyn_process (the lock's time advances), process start times and
!! utc_text. Files go to test_sweep_lock_tmp/ under the working directory.
program test_sweep_lock
    use, intrinsic :: iso_fortran_env, only: int64
    use ropedyn_error, only: error_t, ERR_IO
    use ropedyn_os, only: make_dirs, sleep_microseconds
    use ropedyn_clock, only: utc_text
    use ropedyn_process, only: process_id, process_start, host_name, file_mtime, &
        start_heartbeat, stop_heartbeat, heartbeat_t
    use ropedyn_sweep_lock, only: lock_t, read_lock, take_lock, drop_lock
    use ropedyn_assert, only: test_suite_t
    implicit none

    character(len=*), parameter :: DIR = 'test_sweep_lock_tmp'
    type(test_suite_t) :: suite
    type(error_t), allocatable :: err
    type(heartbeat_t) :: beat

    suite%name = 'sweep_lock'
    call make_dirs(DIR, err)
    call suite%check_true(.not. allocated(err), 'create '//DIR)
    call test_times()
    call test_take_and_drop()
    call test_abandoned()
    call test_heartbeat()
    call suite%finish()

contains

    subroutine write_lines(path, lines)
        character(len=*), intent(in) :: path
        character(len=*), intent(in) :: lines(:)
        integer :: unit, i
        open (newunit=unit, file=path, status='replace', action='write')
        do i = 1, size(lines)
            write (unit, '(a)') trim(lines(i))
        end do
        close (unit)
    end subroutine write_lines

    subroutine test_times()
        call suite%check_true(utc_text(0_int64) == '1970-01-01T00:00:00Z', 'utc_text(0)')
        call suite%check_true(utc_text(951782400_int64 + 3723_int64) == &
                              '2000-02-29T01:02:03Z', 'utc_text: a leap day')
        call suite%check_true(process_start(0) > 0, 'process_start: this process')
        call suite%check_true(process_start(process_id()) == process_start(0), &
                              'process_start: own pid')
        call suite%check_true(process_start(2147483000) == -1, 'process_start: no such pid')
        call suite%check_true(len(host_name()) > 0, 'host_name')
    end subroutine test_times

    subroutine test_take_and_drop()
        character(len=*), parameter :: PATH = DIR//'/.case_0001.lock'
        type(lock_t) :: lock
        logical :: exists
        call drop_lock(PATH, beat)
        call take_lock(PATH, beat, err)
        call suite%check_true(.not. allocated(err), 'take a free lock')
        call read_lock(PATH, lock)
        call suite%check_true(lock%exists .and. lock%live .and. lock%mine, 'own lock: live, mine')
        call suite%check_true(lock%pid == process_id() .and. lock%host == host_name(), &
                              'own lock: pid and host')
        call suite%check_contains(lock%holder(), 'pid ', 'holder')
        ! a second taker (this process again: the lock is live) is refused
        call take_lock(PATH, beat, err)
        call suite%check_true(allocated(err), 'a live lock is refused')
        if (allocated(err)) then
            call suite%check_true(err%code == ERR_IO, 'refused: ERR_IO')
            call suite%check_contains(err%message, 'being written by host '//host_name(), &
                                      'refused: names the holder')
        end if
        call drop_lock(PATH, beat)
        inquire (file=PATH, exist=exists)
        call suite%check_true(.not. exists, 'drop removes the lock')
        call read_lock(PATH, lock)
        call suite%check_true(.not. lock%exists .and. .not. lock%live, 'no lock: not live')
    end subroutine test_take_and_drop

    subroutine test_abandoned()
        character(len=*), parameter :: PATH = DIR//'/.case_0002.lock'
        type(lock_t) :: lock
        ! (lines built one by one: gfortran 12 mishandles a typed array constructor whose
        ! elements are deferred-length function results)
        character(len=64) :: lines(4)
        ! this host, a pid that does not run: abandoned at once
        lines = ''
        lines(1) = 'ropedyn sweep case lock'
        lines(2) = 'host='//host_name()
        lines(3) = 'pid=2147483000'
        lines(4) = 'job=5_2'
        call write_lines(PATH, lines(:4))
        call read_lock(PATH, lock)
        call suite%check_true(lock%exists .and. .not. lock%live, 'dead pid: abandoned')
        call suite%check_contains(lock%gone(), 'that process is gone', 'dead pid: why')
        call suite%check_contains(lock%gone(), 'Slurm job 5_2', 'dead pid: the job')
        ! this host, this process, but another start time: a reused pid, abandoned
        lines = ''
        lines(1) = 'host='//host_name()
        lines(2) = 'pid='//text(process_id())
        lines(3) = 'start_ticks=1'
        call write_lines(PATH, lines(:3))
        call read_lock(PATH, lock)
        call suite%check_true(.not. lock%live, 'reused pid: abandoned')
        ! the same host name on another machine (another boot id): the heartbeat decides
        lines = ''
        lines(1) = 'host='//host_name()
        lines(2) = 'boot=00000000-0000-0000-0000-000000000000'
        lines(3) = 'pid=2147483000'
        call write_lines(PATH, lines(:3))
        call read_lock(PATH, lock)
        call suite%check_true(lock%live, 'same host name, another boot id: fresh, live')
        ! a recorded signal
        lines = ''
        lines(1) = 'host=elsewhere'
        lines(2) = 'pid=12'
        lines(3) = 'signal=15'
        call write_lines(PATH, lines(:3))
        call read_lock(PATH, lock)
        call suite%check_true(.not. lock%live .and. lock%signal == 15, 'signal: abandoned')
        call suite%check_contains(lock%gone(), 'stopped by SIGTERM at ', 'signal: why')
        ! another host with a fresh heartbeat: live
        lines = ''
        lines(1) = 'host=elsewhere'
        lines(2) = 'pid=12'
        call write_lines(PATH, lines(:2))
        call read_lock(PATH, lock)
        call suite%check_true(lock%live .and. .not. lock%mine, 'other host, fresh: live')
        call take_lock(PATH, beat, err)
        call suite%check_true(allocated(err), 'other host, fresh: refused')
        ! an abandoned lock is taken over
        lines = ''
        lines(1) = 'host='//host_name()
        lines(2) = 'pid=2147483000'
        call write_lines(PATH, lines(:2))
        call take_lock(PATH, beat, err)
        call suite%check_true(.not. allocated(err), 'abandoned: taken over')
        call read_lock(PATH, lock)
        call suite%check_true(lock%mine .and. lock%pid == process_id(), 'taken over: mine')
        call drop_lock(PATH, beat)
    end subroutine test_abandoned

    !> The heartbeat touches the file: its time moves on within about a second. Two locks
    !! have two heartbeats at once (one per lock, not one per process).
    subroutine test_heartbeat()
        character(len=*), parameter :: PATH = DIR//'/beat', OTHER = DIR//'/beat2'
        type(heartbeat_t) :: beat, beat2
        integer(int64) :: before, before2
        integer :: k
        call write_lines(PATH, ['x'])
        call write_lines(OTHER, ['x'])
        before = file_mtime(PATH)
        call sleep_microseconds(1100000)
        call start_heartbeat(PATH, 1, beat, err)
        call suite%check_true(.not. allocated(err), 'heartbeat: started')
        call start_heartbeat(OTHER, 1, beat2, err)
        call suite%check_true(.not. allocated(err), 'a second heartbeat: started')
        call suite%check_true(file_mtime(PATH) > before, 'heartbeat: touched at the start')
        before = file_mtime(PATH)
        before2 = file_mtime(OTHER)
        do k = 1, 30
            call sleep_microseconds(100000)
            if (file_mtime(PATH) > before .and. file_mtime(OTHER) > before2) exit
        end do
        call suite%check_true(file_mtime(PATH) > before, 'heartbeat: touched again')
        call suite%check_true(file_mtime(OTHER) > before2, 'second heartbeat: touched again')
        call stop_heartbeat(beat)
        call stop_heartbeat(beat2)
        before = file_mtime(PATH)
        call sleep_microseconds(1200000)
        call suite%check_true(file_mtime(PATH) == before, 'heartbeat: stopped')
    end subroutine test_heartbeat

    pure function text(n) result(s)
        integer, intent(in) :: n
        character(len=:), allocatable :: s
        character(len=16) :: buf
        write (buf, '(i0)') n
        s = trim(buf)
    end function text
end program test_sweep_lock
