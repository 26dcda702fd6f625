!> CVODE's stepping loop: one step at a time, with the step budget, the round-off floor
!! and the watch on crawling.
!!
!! **Crawl detection and order control (BDF).** BDF orders 3-5 amplify lightly damped
!! oscillations near the imaginary axis (docs/theory/cvode.md). When a barely damped stiff mode
!! is present, CVODE at order 5 either lets it grow or, more often, its error test catches
!! the growth, rejects steps and holds h far below what the smooth motion needs: a crawl
!! (the steel wire: 8.5e5 steps per simulated second at order 5, 9e4 at order 2). The loop
!! looks at every window of WINDOW steps: when the window and the whole run so far took
!! more than CRAWL_RATE steps per simulated second (the run: VDPOL's fronts alone reach
!! it), the order in use is >= 3 and at least FAIL_SHARE of the steps failed the error
!! test (the signature of a step held by stability: on the steel wire 5 %, against under
!! 1 % where accuracy limits the step), it tries the A-stable BDF2 for one window (CVODE
!! re-initialized at its current state: `CVodeSetMaxOrd` cannot lower the order in force,
!! only its limit). If order 2 covers the time in no more steps (ACCEPT) in its third
!! window, the crawl is confirmed: the limit stays at
!! 2 for a stretch, the run gets a warning naming the cause, and after the stretch the
!! original limit is restored (without restart) to see whether the stiff modes have died
!! away; a crawl that comes back doubles the next stretch. If order 2 is not faster (the
!! rope's resolved bending oscillations, where order 5 is right), the limit is restored
!! and the next trial waits longer (the wait grows by at least 2, by twice the ratio of the
!! step rates when order 2 lost more; docs/theory/cvode.md). Every change goes into the
!! switch log.
!!
!! **Adams.** Its fixed-point iteration converges only for h |lambda| < 1: on a stiff
!! problem the step collapses. After FAIL_WINDOWS consecutive windows at more than
!! STIFF_STEP_RATE steps per simulated second the run ends with a diagnosis naming the
!! stiff methods.
submodule(ropedyn_cvode) ropedyn_cvode_stepping
    use ropedyn_integrator, only: STIFF_STEP_RATE
    implicit none

    integer, parameter :: WINDOW = 400           !< steps per watch window
    real(wp), parameter :: FAIL_SHARE = 0.02_wp  !< error-test failures per step of a crawl
    !> order 2 stays when it needs at most this many times the steps per simulated second
    !! of the order it replaced (the trial starts from a restart at order 1, which costs it)
    real(wp), parameter :: ACCEPT = 1.0_wp
    !> Only windows above this many steps per simulated second are looked at (the step
    !! guarantee of the hard scenes; a tenth or a half of it changed the converged
    !! rtol-1e-10 regression references, whose windows reach 1.4e5, and the steel wire's
    !! energy balance): the paper's rope at order 5 shows the same
    !! share of error-test failures (5-9 %) at 7e3 steps per second, where order 2 is not
    !! faster, and no problem of the stiff test set comes near it
    real(wp), parameter :: CRAWL_RATE = STIFF_STEP_RATE
    integer, parameter :: LOW_ORDER = 2          !< the A-stable order of the cure
    integer, parameter :: MAX_BACKOFF = 64       !< windows between trials, at most
    integer, parameter :: FIRST_STAY = 16        !< windows at order 2 after a confirmation
    integer, parameter :: MAX_STAY = 1024        !< windows at order 2, at most
    integer, parameter :: FAIL_WINDOWS = 5       !< Adams windows above STIFF_STEP_RATE
    integer, parameter :: TRIAL_WINDOWS = 3      !< windows at order 2 before the judgement

contains

    !> CVODE in one-step mode, so that every step is seen: the step budget and the
    !! round-off floor (as MEBDF's: a step h < 16 eps |t| ends the run) are checked after
    !! each step, then the solution is interpolated at tout (what CV_NORMAL does inside;
    !! the steps taken are the same). CVODE by itself accepts steps with t + h == t: a run
    !! that runs into a region where f keeps failing (a NaN ahead) would crawl there until
    !! max_steps.
    module procedure cvode_advance_to
        real(c_double) :: tret(1), hlast(1)
        integer(c_long) :: nsteps(1)
        integer(c_int) :: flag, qflag
        character(len=:), allocatable :: cause

        if (.not. c_associated(self%mem)) then
            call make_error(err, ERR_SOLVER, self%name()//': advance_to called before init')
            return
        end if
        self%ctx%message = ''
        self%ctx%recoverable = 0
        flag = CV_SUCCESS
        cause = ''
        do while (self%tn < tout)
            qflag = FCVodeGetNumSteps(self%mem, nsteps)
            if (self%base%steps + int(nsteps(1), i8) >= self%options%max_steps) then
                cause = self%steps_exhausted(self%tn)
                exit
            end if
            tret = self%tn
            ! a stop time: CVODE ends the step that reaches it there (and forgets it then)
            if (self%t_stop < huge(1.0_wp)) then
                flag = FCVodeSetStopTime(self%mem, real(self%t_stop, c_double))
                if (flag < 0) exit
            end if
            flag = FCVode(self%mem, real(tout, c_double), self%nv_y, tret, CV_ONE_STEP)
            if (flag < 0) exit
            self%tn = tret(1)
            hlast = 0.0_c_double
            qflag = FCVodeGetLastStep(self%mem, hlast)
            if (hlast(1) < 16.0_wp*epsilon(1.0_wp)*abs(self%tn)) then
                cause = 'step size fell below the round-off limit'
                if (self%ctx%recoverable > 0) cause = cause//' after repeated recoverable '// &
                    'errors of the right-hand side (e.g. a NaN or Inf in the forces)'
                exit
            end if
            ! (not after the step that reached tout: a restart would lose the history the
            ! interpolation at tout needs)
            if (self%tn < tout .and. self%base%steps + int(nsteps(1), i8) + 1 - &
                self%monitor%window_steps0 >= WINDOW) then
                call self%watch(cause)
                if (len(cause) > 0) exit
            end if
            if (self%tn < tout .and. self%stop_here(self%base%steps + int(nsteps(1), i8) + 1)) &
                then
                ! stopped early (on request, at the step cap): the state at the end of this
                ! step
                self%t = self%tn
                y = self%y
                if (self%nq > 0) then
                    tret = self%tn
                    qflag = FCVodeGetQuad(self%mem, tret, self%nv_q)
                    yq(1:self%nq) = self%yq(1:self%nq)
                end if
                t = self%t
                return
            end if
        end do

        if (flag >= 0 .and. len(cause) == 0) then
            ! the step that reached tout is done: interpolate there
            flag = FCVodeGetDky(self%mem, real(tout, c_double), 0_c_int, self%nv_y)
            if (self%nq > 0 .and. flag >= 0) &
                flag = FCVodeGetQuadDky(self%mem, real(tout, c_double), 0_c_int, self%nv_q)
            if (flag >= 0) then
                self%t = tout
                y = self%y
                if (self%nq > 0) yq(1:self%nq) = self%yq(1:self%nq)
                t = self%t
                return
            end if
            cause = flag_name(flag)//': interpolation at tout failed '//self%ctx%message
        end if

        ! Failure: the last good state is CVODE's current one (in y after a one-step call).
        self%t = self%tn
        if (self%nq > 0) then
            tret = self%tn
            qflag = FCVodeGetQuad(self%mem, tret, self%nv_q)
            if (qflag >= 0) yq(1:self%nq) = self%yq(1:self%nq)
        end if
        y = self%y
        t = self%t
        ! the step being attempted when CVODE gave up (the last successful one if none)
        hlast = 0.0_c_double
        qflag = FCVodeGetCurrentStep(self%mem, hlast)
        if (hlast(1) == 0.0_c_double) qflag = FCVodeGetLastStep(self%mem, hlast)
        if (len(cause) == 0) then
            cause = flag_name(flag)//': '//self%ctx%message
            if (flag == CV_REPTD_RHSFUNC_ERR .or. flag == CV_REPTD_QRHSFUNC_ERR) &
                cause = cause//' (the model returned a recoverable error, e.g. a NaN or '// &
                'Inf in the forces)'
        end if
        call make_error(err, ERR_SOLVER, self%name()//' failed at '// &
                        where_text(t, hlast(1))//': '//cause)
    end procedure cvode_advance_to

    module procedure cvode_watch
        type(solver_stats_t) :: now
        real(wp) :: rate, share, span
        integer(i8) :: steps, fails
        integer(c_int) :: flag, order(1)

        now = self%stats()
        steps = now%steps - self%monitor%window_steps0
        fails = now%err_test_fails - self%monitor%window_fails0
        span = max(self%tn - self%monitor%window_t0, tiny(1.0_wp))
        rate = real(steps, wp)/span
        share = real(fails, wp)/max(1_i8, steps)
        order = 0
        flag = FCVodeGetCurrentOrder(self%mem, order)
        if (self%adams) then
            call watch_adams(self, rate, cause)
        else
            call watch_bdf_order(self, now, rate, share, int(order(1)))
        end if
        self%monitor%window_steps0 = now%steps
        self%monitor%window_fails0 = now%err_test_fails
        self%monitor%window_t0 = self%tn
    end procedure cvode_watch

    !> Adams: FAIL_WINDOWS windows in a row above STIFF_STEP_RATE steps per simulated
    !! second (its fixed-point iteration needs h |lambda| < 1) end the run, with `cause`.
    subroutine watch_adams(self, rate, cause)
        class(cvode_t), intent(inout) :: self
        real(wp), intent(in) :: rate
        character(len=:), allocatable, intent(inout) :: cause
        character(len=200) :: text
        associate (m => self%monitor)
            m%stiff_windows = merge(m%stiff_windows + 1, 0, rate > STIFF_STEP_RATE)
            if (m%stiff_windows >= FAIL_WINDOWS) then
                write (text, '(a, es9.2, a)') 'the problem is stiff here: the fixed-point '// &
                    'iteration of the Adams method converges only for h |lambda| < 1, '// &
                    'which takes ', rate, ' steps per simulated second'
                cause = trim(text)//'; use method = ''auto'', ''mebdf'' or ''cvode'''
            end if
        end associate
    end subroutine watch_adams

    !> BDF: the order trial of the module header, one window at a time. Mode 0: watching
    !! (a crawl at order > 2 starts a trial of order 2); 1: the trial's first windows;
    !! 3: the trial judged (order 2 kept for a stretch, or the limit restored and the next
    !! trial deferred); 2: the stretch at order 2, then the limit restored.
    subroutine watch_bdf_order(self, now, rate, share, order)
        class(cvode_t), intent(inout) :: self
        type(solver_stats_t), intent(in) :: now
        real(wp), intent(in) :: rate, share
        integer, intent(in) :: order
        integer(c_int) :: flag
        logical :: ok
        character(len=200) :: text
        associate (m => self%monitor)
            select case (m%mode)
            case (0)
                if (m%wait_windows > 0) then
                    m%wait_windows = m%wait_windows - 1
                else if (m%qmax > LOW_ORDER .and. order > LOW_ORDER .and. &
                         share >= FAIL_SHARE .and. rate >= CRAWL_RATE .and. &
                         real(now%steps, wp) >= CRAWL_RATE*(self%tn - m%t_start)) then
                    ! a crawl? try the A-stable order for one window
                    m%rate_before = rate
                    call self%restart(LOW_ORDER, 8.0_wp*now%last_step, ok)
                    if (ok) then
                        m%mode = 1
                        m%trial_windows = 1
                        write (text, '(a, i0, a, f5.1, a, es9.2, a)') 'trying max order 2: '// &
                            'step held at order ', order, ' (', 100.0_wp*share, &
                            ' % error-test failures, ', rate, ' steps per second)'
                        call note(self, trim(text))
                    end if
                end if
            case (1)
                ! the first windows at order 2 include CVODE's restart at order 1 and the
                ! decay of what the high order kept ringing: judge on the last one
                m%trial_windows = m%trial_windows + 1
                if (m%trial_windows >= TRIAL_WINDOWS) m%mode = 3
            case (3)
                call judge_low_order(self, rate)
            case (2)
                m%stay_windows = m%stay_windows - 1
                if (m%stay_windows <= 0) then
                    flag = FCVodeSetMaxOrd(self%mem, int(m%qmax_user, c_int))
                    m%qmax = m%qmax_user
                    m%mode = 0
                    m%wait_windows = 0
                    call note(self, 'max order back to '//int_text(m%qmax_user)// &
                              ': has the stability limit passed?')
                end if
            end select
        end associate
    end subroutine watch_bdf_order

    !> The trial of order 2 judged on its last window (rate, steps per simulated second):
    !! no more steps than before (ACCEPT): the crawl is confirmed, order 2 stays for a
    !! stretch (doubled each time) with the run's one warning; else the limit is restored
    !! and the next trial waits the longer, the more order 2 lost.
    subroutine judge_low_order(self, rate)
        class(cvode_t), intent(inout) :: self
        real(wp), intent(in) :: rate
        integer(c_int) :: flag
        character(len=200) :: text
        associate (m => self%monitor)
            if (rate <= ACCEPT*m%rate_before) then
                m%mode = 2
                m%stay_windows = m%stay
                m%stay = min(2*m%stay, MAX_STAY)
                write (text, '(a, i0, a, es9.2, a, es9.2, a)') 'the step size was '// &
                    'held by stability at BDF order ', m%qmax_user, ' (', &
                    m%rate_before, ' steps per simulated second; at order 2: ', &
                    rate, '): lightly damped stiff modes'
                call note(self, 'max order stays 2: '//trim(text), .not. m%warned)
                if (.not. m%warned) then
                    ! the one warning of the run, with the cure
                    self%log%events(self%log%count)%reason = trim(text)// &
                        '; the maximum order is lowered to 2 while this lasts '// &
                        '(method = ''mebdf'' or ''auto'' avoids it)'
                    m%warned = .true.
                end if
            else
                flag = FCVodeSetMaxOrd(self%mem, int(m%qmax_user, c_int))
                m%qmax = m%qmax_user
                m%mode = 0
                m%wait_windows = m%backoff
                m%backoff = min(MAX_BACKOFF, ceiling(m%backoff*max(2.0_wp, &
                                2.0_wp*rate/max(m%rate_before, tiny(1.0_wp)))))
                write (text, '(a, i0, a, es9.2, a, es9.2, a)') 'max order back to ', &
                    m%qmax_user, ': order 2 was not faster (', rate, &
                    ' steps per second against ', m%rate_before, ')'
                call note(self, trim(text))
            end if
        end associate
    end subroutine judge_low_order

    !> Log a change of the order limit at the current time (the first one after the limit
    !! the run started with, logged at the run's start: in force from there).
    subroutine note(self, reason, warning)
        class(cvode_t), intent(inout) :: self
        character(len=*), intent(in) :: reason
        logical, intent(in), optional :: warning
        if (self%log%count == 0) call self%log%add(self%monitor%t_start, self%name(), &
            self%monitor%qmax_user, 'start')
        call self%log%add(self%tn, self%name(), self%monitor%qmax, reason, warning)
    end subroutine note

    module procedure cvode_restart
        real(c_double) :: tret(1)
        integer(c_int) :: flag
        ok = .false.
        self%base = self%stats()
        if (self%nq > 0) then
            tret = self%tn
            flag = FCVodeGetQuad(self%mem, tret, self%nv_q)
            if (flag < 0) return
        end if
        flag = FCVodeReInit(self%mem, real(self%tn, c_double), self%nv_y)
        if (flag < 0) return
        if (self%nq > 0) then
            flag = FCVodeQuadReInit(self%mem, self%nv_q)
            if (flag < 0) return
        end if
        flag = FCVodeSetMaxOrd(self%mem, int(qmax, c_int))
        if (flag < 0) return
        if (h > 0.0_wp) flag = FCVodeSetInitStep(self%mem, real(h, c_double))
        self%monitor%qmax = qmax
        ok = flag >= 0
    end procedure cvode_restart

    !> 't = ... s, step size ... s' for messages.
    function where_text(t, h) result(text)
        real(wp), intent(in) :: t, h
        character(len=:), allocatable :: text
        character(len=64) :: buffer
        write (buffer, '(a, a, a, es11.3e3, a)') 't = ', es_text(t, 12, 5), ' s, step size ', &
            h, ' s'
        text = trim(buffer)
    end function where_text
end submodule ropedyn_cvode_stepping
