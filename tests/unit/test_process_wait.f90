!> Unit test of the sweep runner's wait for its workers (ropedyn_process: watch_children,
!! wait_children, unwatch_children): the end of a watched child wakes the wait, also when
!! the child ended before the wait began (SIGCHLD kept pending, not lost in a sleep before
!! it); without a child the wait runs out its time; after unwatch_children an ended child
!! no longer wakes it. Each wait that should be woken is given 20 s, so a wait that runs
!! out its time instead (returns false) is the failure, not a slow machine.
program test_process_wait
    use ropedyn_error, only: error_t
    use ropedyn_os, only: sleep_microseconds, delete_file
    use ropedyn_process, only: spawn, reap, watch_children, unwatch_children, wait_children
    use ropedyn_assert, only: test_suite_t
    implicit none

    character(len=*), parameter :: LOG = 'test_process_wait.log'
    integer, parameter :: LONG_WAIT = 20000000   !< us: "woken", not "timed out"
    type(test_suite_t) :: suite
    type(error_t), allocatable :: err
    integer :: pid, code

    suite%name = 'process_wait'
    call watch_children(err)
    call suite%check_true(.not. allocated(err), 'watch_children')

    ! a child that ends while we wait wakes the wait
    call spawn([character(len=8) :: 'sleep', '0.2'], LOG, pid, err)
    call suite%check_true(.not. allocated(err), 'spawn sleep 0.2')
    call suite%check_true(wait_children(LONG_WAIT), 'woken by a child that ends during the wait')
    call suite%check_true(reaped(pid, code), 'the child is reaped')
    call suite%check_true(code == 0, 'its exit status is 0')

    ! a child that ends before the wait (while we sleep) still wakes it at once
    call spawn([character(len=8) :: 'true'], LOG, pid, err)
    call suite%check_true(.not. allocated(err), 'spawn true')
    call sleep_microseconds(500000)
    call suite%check_true(wait_children(LONG_WAIT), &
                          'woken by a child that ended before the wait')
    call suite%check_true(reaped(pid, code), 'that child is reaped')

    ! nothing ends: the time runs out
    call suite%check_true(.not. wait_children(20000), 'no child: the wait runs out its time')

    ! not watched: an ended child does not end the wait
    call unwatch_children()
    call spawn([character(len=8) :: 'true'], LOG, pid, err)
    call suite%check_true(.not. allocated(err), 'spawn true (unwatched)')
    call suite%check_true(.not. wait_children(500000), &
                          'unwatched: the end of a child does not wake the wait')
    call suite%check_true(reaped(pid, code), 'the unwatched child is reaped')

    call suite%check_true(delete_file(LOG), 'remove '//LOG)
    call suite%finish()

contains

    !> Reap child `pid`, waiting up to 20 s for its end (a poll, so that this test does not
    !! depend on the wait it tests).
    logical function reaped(pid, code)
        integer, intent(in) :: pid
        integer, intent(out) :: code
        integer :: k
        reaped = .false.
        code = -1
        do k = 1, 2000
            reaped = reap(pid, code)
            if (reaped) return
            call sleep_microseconds(10000)
        end do
    end function reaped
end program test_process_wait
