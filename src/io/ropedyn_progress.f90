!> One-line progress display on stderr: simulated time, percent, steps, ETA.
!!
!! Shown when stderr is a terminal or when the scene asks for it (&output progress);
!! silent otherwise. Redraws at most every 0.2 s of wall time.
module ropedyn_progress
    use, intrinsic :: iso_fortran_env, only: error_unit, int64
    use ropedyn_kinds, only: wp, i8
    use ropedyn_os, only: is_terminal
    implicit none
    private
    public :: progress_t

    type :: progress_t
        private
        logical :: enabled = .false.
        real(wp) :: t_end = 1.0_wp
        integer(int64) :: start = 0, last = 0, rate = 1
        logical :: drawn = .false.
    contains
        procedure :: start_run
        procedure :: update
        procedure :: done
    end type progress_t

contains

    !> Decide whether to show progress (forced, or stderr is a terminal).
    subroutine start_run(self, t_end, forced)
        class(progress_t), intent(inout) :: self
        real(wp), intent(in) :: t_end   !< final simulated time, s
        logical, intent(in) :: forced
        self%enabled = forced .or. is_terminal(2)
        self%t_end = t_end
        call system_clock(self%start, self%rate)
        self%last = self%start
        self%drawn = .false.
    end subroutine start_run

    subroutine update(self, t, steps)
        class(progress_t), intent(inout) :: self
        real(wp), intent(in) :: t        !< simulated time reached, s
        integer(i8), intent(in) :: steps
        integer(int64) :: now
        real(wp) :: elapsed, fraction, eta
        character(len=100) :: line
        if (.not. self%enabled) return
        call system_clock(now)
        if (real(now - self%last, wp)/real(self%rate, wp) < 0.2_wp .and. t < self%t_end) return
        self%last = now
        elapsed = real(now - self%start, wp)/real(self%rate, wp)
        fraction = min(1.0_wp, max(t/self%t_end, 1.0e-12_wp))
        eta = elapsed*(1.0_wp - fraction)/fraction
        write (line, '(a, f10.3, a, f6.1, a, i0, a, f8.1, a)') 't =', t, ' s ', &
            100.0_wp*fraction, ' %  steps ', steps, '  ETA', eta, ' s'
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
end module ropedyn_progress
