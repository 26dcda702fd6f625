!> Runs one scene from start to end on the command line's terms: a `run_t` (ropedyn_run)
!! stepped from record to record, with SIGINT and SIGTERM caught while it integrates.
!!
!! Signals: the integrator stops at the end of its current step, that state is written as
!! a last record (off the output grid when between two output times), with the counters,
!! status 'interrupted' and a reason naming the signal and the time reached; the error is
!! ERR_INTERRUPTED (exit 130). A second signal ends the process at once (by that signal).
module ropedyn_simulation
    use ropedyn_text, only: real_text
    use ropedyn_error, only: error_t, make_error, ERR_INTERRUPTED
    use ropedyn_signals, only: catch_signals, release_signals, signal_received, signal_name, &
                               end_on_second_signal
    use ropedyn_process, only: process_text
    use ropedyn_scene, only: scene_t
    use ropedyn_run, only: run_t, run_summary_t, STEP_RECORDED, STEP_STOPPED
    implicit none
    private
    public :: run_summary_t, run_scene

contains

    !> Whether the run should stop at the step just taken: a SIGINT or SIGTERM was caught.
    logical function stop_on_signal()
        stop_on_signal = signal_received() /= 0
    end function stop_on_signal

    !> Run a validated scene to its end, or with `resume` continue the run file
    !! scene%output%file to the scene's t_end. The file is written as the run goes; a failed
    !! integration leaves the data up to the failure and status 'failed'. The output file
    !! is guarded (run_t%open) unless `guard` is .false. (a sweep case guards its own);
    !! `force` lets the run replace a file the guard would keep. Signals are caught before
    !! the file is opened: one that comes while the run starts (its lock and FILE.part
    !! made, the start computed) stops it at its first step, as interrupted, and never
    !! kills it with the lock and the part file left behind.
    subroutine run_scene(scene, summary, err, resume, guard, force)
        type(scene_t), intent(in) :: scene
        type(run_summary_t), intent(out) :: summary
        type(error_t), allocatable, intent(out) :: err
        logical, intent(in), optional :: resume, guard, force
        type(run_t) :: run
        integer :: outcome
        call catch_signals(err)
        if (allocated(err)) then
            summary = run%summary
            return
        end if
        call end_on_second_signal(.true.)
        call run%open(scene, err, resume, guard, force)
        if (allocated(err)) then
            call release_signals()
            summary = run%summary
            return
        end if
        call run%begin(err, stop_on_signal)
        if (allocated(err)) then
            call run%finish('failed', (err%message), err)
        else
            outcome = STEP_RECORDED
            do while (.not. run%done() .and. outcome == STEP_RECORDED)
                call run%step(outcome, err)
            end do
            if (outcome == STEP_STOPPED) then
                call make_error(err, ERR_INTERRUPTED, run%final_file_name()// &
                    ': interrupted by '//signal_name(signal_received())//' at t = '//real_text(run%time())// &
                    ' s of '//real_text(run%end_time())//' s (its last record; '// &
                    process_text()//')')
                call run%finish('interrupted', (err%message), err)
            else if (outcome == STEP_RECORDED) then
                call run%finish('complete', '', err)
            end if
        end if
        call release_signals()
        summary = run%summary
    end subroutine run_scene
end module ropedyn_simulation
