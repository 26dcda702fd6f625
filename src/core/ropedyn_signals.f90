!> Signals: SIGINT and SIGTERM caught as a flag that the program polls (nested catches
!! count), optionally ending the process at a second signal. Through the C glue
!! `ropedyn_process.c`. Used by the run driver and the sweep runner (the output guide,
!! "Interrupts").
module ropedyn_signals
    use, intrinsic :: iso_c_binding, only: c_int
    use ropedyn_error, only: error_t, make_error, ERR_IO
    use ropedyn_text, only: int_text
    implicit none
    private
    public :: catch_signals, release_signals, signal_received, signal_name
    public :: end_on_second_signal
    public :: SIGINT, SIGKILL, SIGTERM

    !> Signal numbers (the same on every POSIX system ropedyn runs on).
    integer, parameter :: SIGINT = 2, SIGKILL = 9, SIGTERM = 15

    interface
        integer(c_int) function c_catch_signals() bind(C, name='ropedyn_catch_signals')
            import :: c_int
        end function c_catch_signals
        subroutine release_signals() bind(C, name='ropedyn_release_signals')
        end subroutine release_signals
        subroutine c_second_signal_ends(on) bind(C, name='ropedyn_second_signal_ends')
            import :: c_int
            integer(c_int), value :: on
        end subroutine c_second_signal_ends
        integer(c_int) function c_signal_received() bind(C, name='ropedyn_signal_received')
            import :: c_int
        end function c_signal_received
    end interface

contains

    !> Catch SIGINT and SIGTERM from now on: `signal_received()` tells which came first.
    subroutine catch_signals(err)
        type(error_t), allocatable, intent(out) :: err
        integer(c_int) :: rc
        rc = c_catch_signals()
        if (rc /= 0) call make_error(err, ERR_IO, 'cannot install signal handlers (errno '// &
            int_text(int(rc))//')')
    end subroutine catch_signals

    !> With `on`, a SIGINT or SIGTERM that arrives after one was caught ends the process at
    !! once, by that signal (exit status 128 + N); off again with the last `release_signals`.
    subroutine end_on_second_signal(on)
        logical, intent(in) :: on
        call c_second_signal_ends(merge(1_c_int, 0_c_int, on))
    end subroutine end_on_second_signal

    !> The first SIGINT or SIGTERM caught since `catch_signals` (its number), or 0.
    integer function signal_received()
        signal_received = int(c_signal_received())
    end function signal_received

    !> 'SIGTERM', 'SIGINT', else 'signal N'.
    pure function signal_name(sig) result(name)
        integer, intent(in) :: sig
        character(len=:), allocatable :: name
        select case (sig)
        case (SIGINT)
            name = 'SIGINT'
        case (SIGTERM)
            name = 'SIGTERM'
        case (SIGKILL)
            name = 'SIGKILL'
        case default
            name = 'signal '//int_text(sig)
        end select
    end function signal_name
end module ropedyn_signals
