!> One-line progress display on stderr: simulated time, percent, rate (simulated seconds per
!! wall-clock second), steps and the estimated time left.
!!
!! On by default when stderr is a terminal, off otherwise (batch jobs, pipes, files);
!! `&output progress = .true.` or `.false.` forces it either way. Redraws at most every
!! 0.2 s of wall time.
module ropedyn_progress
    use, intrinsic :: iso_fortran_env, only: error_unit, int64
    use ropedyn_clock, only: clock_seconds
    use ropedyn_kinds, only: wp, i8
    use ropedyn_os, only: is_terminal
    implicit none
    private
    public :: progress_t, progress_shown

    type :: progress_t
        private
        logical :: enabled = .false.
        real(wp) :: t0 = 0.0_wp
        real(wp) :: t_end = 1.0_wp
        real(wp) :: start = 0.0_wp, last = 0.0_wp   !< the monotonic clock, s
        logical :: drawn = .false.
    contains
        procedure :: start_run
        procedure :: update
        procedure :: done
    end type progress_t

contains

    !> Whether progress is shown: `value` when `given` (the scene sets it), else whether
    !! stderr is a terminal.
    logical function progress_shown(value, given) result(shown)
        logical, intent(in) :: value, given
        if (given) then
            shown = value
        else
            shown = is_terminal(2)
        end if
    end function progress_shown

    !> Start the display for a run from t0 to t_end (shown as `progress_shown` says).
    subroutine start_run(self, t0, t_end, value, given)
        class(progress_t), intent(inout) :: self
        real(wp), intent(in) :: t0      !< simulated time at the start (a resumed run: > 0), s
        real(wp), intent(in) :: t_end   !< final simulated time, s
        logical, intent(in) :: value    !< &output progress
        logical, intent(in) :: given    !< whether the scene sets it
        self%enabled = progress_shown(value, given)
        self%t0 = t0
        self%t_end = t_end
        self%start = clock_seconds()
        self%last = self%start
        self%drawn = .false.
    end subroutine start_run

    subroutine update(self, t, steps)
        class(progress_t), intent(inout) :: self
        real(wp), intent(in) :: t        !< simulated time reached, s
        integer(i8), intent(in) :: steps
        real(wp) :: now
        real(wp) :: elapsed, fraction, eta, rate
        character(len=120) :: line
        if (.not. self%enabled) return
        now = clock_seconds()
        if (now - self%last < 0.2_wp .and. t < self%t_end) return
        self%last = now
        elapsed = max(now - self%start, 1.0e-9_wp)
        fraction = min(1.0_wp, max((t - self%t0)/max(self%t_end - self%t0, tiny(1.0_wp)), &
                                   1.0e-12_wp))
        eta = elapsed*(1.0_wp - fraction)/fraction
        rate = (t - self%t0)/elapsed
        write (line, '(a, f10.3, a, f6.1, a, es9.2, a, i0, a, a)') 't =', t, ' s ', &
            100.0_wp*min(1.0_wp, t/self%t_end), ' %  ', rate, ' s/s  steps ', steps, &
            '  left ', duration_text(eta)
        write (error_unit, '(a, a)', advance='no') achar(13), trim(line)//'   '
        flush (error_unit)
        self%drawn = .true.
    end subroutine update

    !> End the progress line.
    subroutine done(self)
        class(progress_t), intent(inout) :: self
        if (self%enabled .and. self%drawn) write (error_unit, '(a)') ''
        self%drawn = .false.
    end subroutine done

    !> '42 s', '12 min 05 s', '3 h 07 min'.
    function duration_text(seconds) result(text)
        real(wp), intent(in) :: seconds
        character(len=:), allocatable :: text
        character(len=32) :: buf
        integer(int64) :: s
        s = nint(min(seconds, 1.0e9_wp), int64)
        if (s < 60) then
            write (buf, '(i0, a)') s, ' s'
        else if (s < 3600) then
            write (buf, '(i0, a, i2.2, a)') s/60, ' min ', mod(s, 60_int64), ' s'
        else
            write (buf, '(i0, a, i2.2, a)') s/3600, ' h ', mod(s, 3600_int64)/60, ' min'
        end if
        text = trim(buf)
    end function duration_text
end module ropedyn_progress
