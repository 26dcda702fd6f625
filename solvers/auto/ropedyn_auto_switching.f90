!> The switching rules of auto (ropedyn_auto): `watch`, at the end of each window of the
!! method in use, on the counted costs of ropedyn_auto's header (Cost); one routine per
!! method in use (explicit_window, accurate_window, implicit_window) and the helpers they
!! share.
!!
!! - **Looks**: the method in use runs in chunks of about WINDOW/4 of its last step, each
!!   cut at the next output time, and `watch` runs after each. Before a method's first
!!   step the chunk is sized from h_chunk (the stable step h_e at the start, the previous
!!   method's last step after a switch), not left to run to the next output: with outputs
!!   1 s apart drag_fall's first look came at 1.0 s (1,088 steps against 266).
!! - **Switching** (looked at every WINDOW steps of the method in use): explicit ->
!!   implicit when most steps of the window were held by stability (erk's own estimate of
!!   h rho near the limit, or h within 0.7 .. 2 times the stable step from the last
!!   spectrum estimate: the stages' estimate misses fast modes the solution does not
!!   excite, 1e2 .. 3e3 1/s against the Jacobian's 5.1e3 on a rope falling flat,
!!   drag_fall) and either the implicit method's last measured cost per simulated second
!!   was lower by GAIN, or it has not been measured yet (a trial). Before that cost is
!!   known, erk's first window ends after EARLY_WINDOW = 50 steps when 90 % of them were
!!   held by stability, the share counted over those steps (erk's own share waits for 51):
!!   drag_fall tries mebdf at 0.05 s (0.77 s with WINDOW, 0.1 s after 100 steps; with
!!   outputs 1 s apart 0.09 s, 0.19 s after 100), and its CPU over mebdf alone went from
!!   1.27 to 1.20 (min of 30 runs; the rest is the spectrum estimate at the start, about
!!   0.2 ms of its 1.9). Both only for problems without a mass matrix: on the
!!   MPP (M(q) in MEBDF's residual, a dense Newton matrix) an implicit step costs far
!!   more, a trial there is no cheap experiment, and erk's own estimate decides alone.
!!   With the stable step there, the 0.5 s windows of docs/validation/accuracy.md at rtol 1e-2 went
!!   to mebdf at once: 1.02 s against 0.093 (n = 100), 0.063 against 0.0087 (n = 30).
!!   Implicit -> explicit when
!!   the explicit cost predicted from the spectrum at the current state (evaluations per
!!   step / h_e) is lower than the implicit method's measured cost by GAIN; a trial of the
!!   implicit method that does not pay (judged on its second window) goes back at once.
!!   The implicit method's measured cost is evidence for STALE_WINDOWS = 32 explicit
!!   windows (times the cost ratio of each trial that does not pay, at least 2); after
!!   that erk's steps held by stability bring a new trial even where the old cost was
!!   higher. steel_wire (5 ms
!!   outputs): mebdf's second window, at 5.4 ms, is in the ringing after the release (steps
!!   of 1e-6 s, 9.2e6 f per second) and auto rightly went to erk (0.7e6); mebdf's steps
!!   later grow to 4e-5 s (2.3e5 f per second on its own run), but the old cost kept it out
!!   to the end: 0.54 s CPU against mebdf's 0.36 .. 0.41. Now a trial at 0.10 s (not
!!   cheaper yet) and one at 0.30 s (kept): 0.35 s. With 8 windows there were four trials
!!   (0.46 s), and on the paper's rope at rtol 2.9e-4 three failed ones in 30 s, not one.
!!   (Since the first chunk is sized from a step (Looks), mebdf's cost is measured at
!!   0.4 ms, erk follows at once, and the trials come at 0.077 s and 0.27 s: 0.24 s.)
!!   Only for problems without a mass matrix, as the stable-step evidence: on the MPP a
!!   trial of the dense MEBDF costs 8 to 12 times erk's; with retrials (doubling) fig4's
!!   MPP runs at rtol 1e-2 went from 24 to 47 s at n = 200 and 58 to 155 s at n = 300, and
!!   with waits grown by the cost ratio still to 30 and 82 s.
!!   A switch that is undone within two windows doubles the wait before the next one.
!! - **Adams** (CVODE's Adams-Moulton, fixed-point iteration) for the explicit method's
!!   other weakness: a step held by accuracy, not stability, where f is costly: Adams takes
!!   about one evaluation of f per step against erk's four, but CVODE's own work per step
!!   (about 2.7 us at n = 30) costs more than that saves where f is cheap. Counted costs
!!   cannot tell (an RFEM f costs 1.0 us at n = 30, an MPP f 2.6 us), so Adams is tried
!!   only for problems with a mass matrix (the MPP: f solves with it); on the RFEM scenes
!!   where it was tried it kept Adams at up to twice erk's CPU (table_motion).
!!   When most steps of an explicit window were not held by stability, auto tries Adams
!!   (a trial, judged on its second window against the explicit cost, goes back at once
!!   unless it is cheaper by GAIN) and later switches to it when its measured cost is
!!   lower by GAIN. That cost is evidence for STALE_WINDOWS explicit windows (times the
!!   cost ratio, at least 2, of each trial that does not pay), as the implicit method's;
!!   then the next window held by accuracy tries Adams again. Without that, one trial in
!!   a short stretch decided a whole run: on the Bergdahl chain's MPP at atol 1e-8, Adams
!!   tried for 0.02 s at 1.1 s (in the ramp's first cycle) was dearer, and erk ran to the
!!   end with 2.1e6 evaluations of f in 24 s, against 0.54e6 for a neighbouring case that
!!   kept Adams (316 s of CPU against 84); mpp_undamped tries it again at 2.5 s. From
!!   Adams it goes back to erk when erk's last measured cost is lower
!!   by GAIN in two windows in a row (snap_load_mpp: Adams measured once at 6.6e4 f/s in the
!!   window of the snap sent auto back to erk, whose cost of 4.5e4 measured before the
!!   snap then kept Adams out for the remaining 9 s: 1.36 s CPU against Adams' 0.82);
!!   leaving, it keeps as Adams' cost that of its last window that was not dearer, so
!!   that a stretch longer than two windows (a contact) does not keep Adams out once it
!!   is over (whip_ground_mpp: 3.2 s CPU on erk from 1.25 s against 2.6 s),
!!   or at once when Adams fails (e.g. the fixed-point iteration does not
!!   converge: the problem has become stiff). erk's measured cost is evidence for
!!   STALE_WINDOWS windows of Adams, as for the order-5 pair; then erk runs again to
!!   measure it. Without that, a cost measured in a transient kept Adams to the end: a
!!   stiff two-rod MPP pendulum at rtol 1e-9 (test_methods) measured erk at 3.2e5 f per
!!   second in the release's first 0.007 s, and Adams, its steps then held by the stiff
!!   modes' stability (11 % failed their error test), ran the remaining 6 s on 255,612
!!   evaluations of f against erk's own 136,506 (cvode: 1,585); measured again at
!!   0.37 s, erk's steps were held by stability and auto went to cvode: 21,127, and
!!   0.28 s of CPU became 0.033. On the shipped MPP scenes that keep Adams, the
!!   measurements cost 4 to 7 % more CPU (mpp_light_damping_n30/n70, mpp_undamped,
!!   snap_load_mpp; heavy_mass_mpp and mpp_light_damping the same) and whip_ground_mpp,
!!   which found erk cheaper late in its run, 29 % less (Release, the least of two runs
!!   each, by hand on 2026-11-30). Adams' cost: its evaluations of f plus
!!   ADAMS_STEP_COST per step (CVODE's vector work per step: measured about 2 f on the
!!   paper's rope at n = 30, where f is cheap, and about 1.2 f on the MPP at n = 30).
!! - **The order-5 pair** (erk's Dormand-Prince 5(4), HIGH) is the method for a step held
!!   by accuracy on a problem without a mass matrix (the RFEM), by the rules of Adams
!!   above (the "accuracy method": tried once when most steps of an order-4 window were
!!   held by accuracy, kept when cheaper by GAIN on its second window, left when the
!!   order-4 pair was cheaper by GAIN two windows in a row). Its steps are longer where
!!   accuracy holds them (folded_n301 at rtol 1e-6: 196,076 f against 359,070 for the
!!   order-4 pair over 0.6 s; light_damping 1.18e6 against 2.23e6 over 10 s), but its
!!   stable interval on the imaginary axis is a third of the 3/8 pair's per step, so on
!!   lightly damped element modes near the limit it is the dearer one (paper: 884,876 f
!!   against 817,662; steel_wire 1.17e6 against 0.68e6). Two more rules for it: when most
!!   of a window's steps were held by stability (its own stable step from the same
!!   spectrum estimate), back to the order-4 pair at once, from which the implicit
!!   method may be tried, and the waits double (steel_wire went back and forth eight
!!   times in 0.7 s without that); and the order-4 pair's measured cost is evidence for
!!   STALE_WINDOWS windows of the order-5 pair, after which auto measures it again
!!   (shaken_top: the order-5 pair paid in the first 0.03 s and then ran to the end at
!!   1.18 times the order-4 pair's evaluations of f).
!! - **Symplectic** (ropedyn_symplectic; docs/theory/symplectic.md): where the fast modes
!!   are lightly damped (the mode that limits the symplectic step damped by less than
!!   1 %), an adaptive method's energy balance drifts over a long run (the undamped paper
!!   rope, n = 20, rtol 1e-3: erk and auto lost 0.11 m g L in 30 s, 0.15 in 300 s),
!!   biasing the energy, dissipation and spectra a long run is for; the symplectic
!!   method's stays bounded (1.1e-4 m g L over 300 s). So auto takes it, at the start
!!   (before the slow start's test) or instead of erk when leaving the implicit method,
!!   on a problem that offers the force split (the RFEM without ground contact or point
!!   masses off centre), a run at least LONG_RUN long (options%t_end; not known: long),
!!   a step of at most START_RATE steps per simulated second (and, leaving the implicit
!!   method, a cost below its measured one by GAIN), and a cost of at most
!!   LIGHT_COST_LIMIT = 4 times erk's predicted one (choose_step's, counting the step's
!!   whole work: Chin's 4A at 0.35 of its stable step, 1.8 times on that rope; on the
!!   damped paper rope at n = 10, whose fast modes the estimate finds lightly damped,
!!   4.8 times, so not there), and steps to t_end within the step budget left (its step is
!!   fixed: it knows the count in advance; else a warning, once, names the budget at
!!   which it would). Erk's predicted cost assumes its stable step; where erk's steps
!!   are held by accuracy instead, its measured cost is higher: from erk's second window
!!   on (and the order-5 pair's), when the symplectic method's cost at its last look
!!   (sym_cost) is below the window's measured cost by GAIN, auto estimates the spectrum
!!   again and takes it if it still fits, with that measured cost in place of the limit
!!   against the predicted one (input/hard/light_damping.nml, n = 30, rtol 1e-6, 10 s:
!!   erk held by accuracy at 1.4e5 f per second, the symplectic method 0.41 of that;
!!   auto 0.9 s CPU before, 0.27 s after, its tip over 2 s 2.5e-8 m from cvode at rtol
!!   1e-10 against 6.7e-8 before). Whichever way auto comes to it, the method must first
!!   pass a probe of its error from the state reached (ropedyn_auto_probe: 400 steps at its
!!   step and at half of it, at most 20 tolerances; a support shaken at 20 Hz fails it).
!!   It keeps it unless its step gets too short (START_RATE: then the implicit method; no
!!   second probe, see ropedyn_auto_probe), or the method stops: the rest of the run
!!   outgrows the step budget where the step shortens, or a step is unstable at a half,
!!   a quarter ... a sixteenth (then erk from the last state it reached, and not the
!!   symplectic method again in that run); its own log of the step joins the switch log.
submodule (ropedyn_auto) ropedyn_auto_switching
    implicit none

contains

    !> At the end of a window: measure, compare, switch (the header; one routine per kind
    !! of method in use below).
    module procedure watch
        type(solver_stats_t) :: now
        real(wp) :: rate, span
        logical :: early    !< erk's early first window (early_look)
        character(len=240) :: text

        now = self%current_stats()
        if (self%active == SYMPLECTIC) then
            ! kept (the header, Symplectic) unless its steps have become too short
            if (now%last_step > 0.0_wp) then
                if (1.0_wp/now%last_step > START_RATE) then
                    write (text, '(a, es9.2, a)') 'symplectic step ', now%last_step, &
                        ' s: explicit steps too short'
                    call self%start_method(IMPLICIT, trim(text), err)
                end if
            end if
            return
        end if
        early = .false.
        if (now%steps - self%win_steps0 < WINDOW) then
            early = early_look(self, now)
            if (.not. early) return
        end if
        span = self%t - self%win_t0
        if (span <= 0.0_wp) return
        rate = (self%cost(now) - self%win_cost0)/span
        self%windows = self%windows + 1
        self%win_t0 = self%t
        self%win_steps0 = now%steps
        self%win_cost0 = self%cost(now)
        if (self%wait > 0) self%wait = self%wait - 1
        if (self%sym_wait > 0) self%sym_wait = self%sym_wait - 1

        if (self%active == EXPLICIT) then
            call explicit_window(self, rate, early, err)
        else if (self%active == self%accurate) then
            call accurate_window(self, rate, err)
        else
            call implicit_window(self, rate, err)
        end if
    end procedure watch

    !> A window of erk's order-4 pair that cost `rate` (f per simulated second; `early`:
    !! the early first look): to the symplectic method, the accuracy method or the
    !! implicit one when it pays (the header, Switching).
    subroutine explicit_window(self, rate, early, err)
        class(auto_t), intent(inout) :: self
        real(wp), intent(in) :: rate
        logical, intent(in) :: early
        type(error_t), allocatable, intent(out) :: err
        real(wp) :: share
        logical :: stale    !< the implicit or accuracy method's measured cost is old
        character(len=240) :: text
        self%rate_explicit = rate
        if (self%rate_implicit > 0.0_wp) self%implicit_age = self%implicit_age + 1
        if (self%rate_accurate > 0.0_wp) self%accurate_age = self%accurate_age + 1
        call try_symplectic(self, rate, err)
        if (self%active /= EXPLICIT .or. allocated(err)) return
        if (early) then
            share = self%erk%stiff_share_of_steps(EARLY_WINDOW)
        else
            share = self%erk%stiff_share_of_steps()
        end if
        if (self%wait > 0) return
        if (share < 0.5_wp) then
            ! held by accuracy: the accuracy method may need fewer evaluations of f
            ! (judged on the explicit method's second window on: the first includes its
            ! start)
            if (self%windows < 2) return
            ! its measured cost is evidence for accurate_stale_after windows: a trial
            ! in a short stretch of the start (the MPP's Adams, 0.02 s at 1.1 s of
            ! the Bergdahl chain) must not keep it out of a long run
            stale = self%rate_accurate > 0.0_wp .and. &
                    self%accurate_age >= self%accurate_stale_after
            if (self%rate_accurate > 0.0_wp .and. GAIN*self%rate_accurate >= rate .and. &
                .not. stale) return
            write (text, '(a, i0, a, es9.2, a)') 'explicit step held by accuracy (', &
                nint(100*(1 - share)), ' % of the steps; cost ', rate, ' f per second)'
            self%trial = self%rate_accurate <= 0.0_wp .or. stale
            call add_trial(self, text, self%accurate_name(), stale, self%accurate_age)
            if (self%windows <= 2) call back_off(self)
            call self%start_method(self%accurate, trim(text), err)
            return
        end if
        stale = self%rate_implicit > 0.0_wp .and. self%implicit_age >= self%stale_after &
                .and. self%trials_are_cheap()
        if (self%rate_implicit > 0.0_wp .and. GAIN*self%rate_implicit >= rate .and. &
            .not. stale) return
        write (text, '(a, i0, a, es9.2, a, es9.2, a)') 'explicit step held by stability (', &
            nint(100*share), ' % of the steps; spectral radius about ', &
            max(self%erk%spectral_radius(), self%radius), ' 1/s; cost ', rate, &
            ' f per second)'
        self%trial = self%rate_implicit <= 0.0_wp .or. stale
        call add_trial(self, text, self%implicit_name(), stale, self%implicit_age)
        if (self%windows <= 2) call back_off(self)
        call self%start_method(IMPLICIT, trim(text), err)
    end subroutine explicit_window

    !> A window of the accuracy method (Adams or the order-5 pair) that cost `rate`: kept,
    !! or back to erk when erk is cheaper (the header, Adams and the order-5 pair).
    subroutine accurate_window(self, rate, err)
        class(auto_t), intent(inout) :: self
        real(wp), intent(in) :: rate
        type(error_t), allocatable, intent(out) :: err
        logical :: dearer   !< its window cost more than erk's last by GAIN
        character(len=240) :: text
        if (self%active == HIGH) then
            call high_pair_looks(self, err)
            if (self%active /= HIGH .or. allocated(err)) return
        end if
        if (self%windows < 2) return
        self%rate_accurate = rate
        self%accurate_age = 0
        if (self%active == HIGH) then
            call try_symplectic(self, rate, err)
            if (self%active /= HIGH .or. allocated(err)) return
        end if
        if (self%trial) then
            ! kept only when cheaper by GAIN: Adams' counted cost misses CVODE's fixed
            ! work per step, which weighs most where f is cheap (the RFEM at small n);
            ! the order-5 pair is not worth a switch for less either
            self%trial = .false.
            if (self%rate_explicit > 0.0_wp .and. GAIN*rate > self%rate_explicit) then
                self%accurate_stale_after = grown(self, self%accurate_stale_after, rate)
                call trial_failed(self, self%accurate_name()//' was not cheaper by 1.3', &
                                  rate, err)
                return
            end if
        end if
        dearer = self%rate_explicit > 0.0_wp .and. GAIN*self%rate_explicit < rate
        if (.not. dearer) self%calm_accurate = rate
        if (self%wait > 0) return
        ! two windows in a row: one window of a transient (a snap) must not send auto
        ! back to erk, whose cost, measured before, then keeps Adams out for the rest
        ! of the run
        if (dearer) then
            self%dearer = self%dearer + 1
        else
            self%dearer = 0
        end if
        if (self%dearer >= 2) then
            write (text, '(a, es9.2, a, es9.2, a)') 'erk was cheaper (', &
                self%rate_explicit, ' against ', rate, ' f per second for '// &
                self%accurate_name()//', two windows in a row)'
            ! windows 2 and 3 are the earliest two that can send it back (the rate is
            ! kept from window 2 on): leaving then undoes the switch at once
            if (self%windows <= 3) call back_off(self)
            ! Adams' cost in the stretch that sent it back (a contact) must not keep
            ! it out once that stretch is over (whip_ground_mpp: 1.16e6 f per second
            ! in a contact at 1.25 s against erk's 3.3e5 kept erk for the last 8.7 s,
            ! 3.2 s CPU against Adams' 2.4): erk is weighed against Adams' cost in its
            ! last window that was not dearer
            if (self%calm_accurate > 0.0_wp) self%rate_accurate = self%calm_accurate
            call self%start_method(EXPLICIT, trim(text), err)
            return
        end if
        if (self%active == ADAMS) call explicit_cost_ages(self, err)
    end subroutine accurate_window

    !> The order-5 pair's own looks before its cost is weighed: back to the order-4 pair
    !! when its steps were held by stability, or when the order-4 pair's cost is stale.
    subroutine high_pair_looks(self, err)
        class(auto_t), intent(inout) :: self
        type(error_t), allocatable, intent(out) :: err
        real(wp) :: share
        character(len=240) :: text
        ! the order-5 pair held by stability: the order-4 pair's stable step is
        ! longer per evaluation of f, and from it auto may try the implicit method
        share = self%erk_high%stiff_share_of_steps()
        ! (a switch that did not pay: the waits double, against a ping-pong where
        ! both pairs step near their limits: steel_wire)
        if (share >= 0.5_wp) then
            write (text, '(a, i0, a)') 'order-5 pair held by stability (', &
                nint(100*share), ' % of the steps)'
            call back_off(self)
            call self%start_method(EXPLICIT, trim(text), err)
            return
        end if
        ! (the order-4 pair's cost measured before the motion changed: shaken_top's
        ! order-5 pair paid in the first 0.03 s, not over the run)
        if (self%windows >= 2) call explicit_cost_ages(self, err)
    end subroutine high_pair_looks

    !> One more window of the accuracy method since erk's order-4 pair was measured: that
    !! cost is evidence for STALE_WINDOWS windows, then erk runs again to measure it (the
    !! header, Adams and the order-5 pair).
    subroutine explicit_cost_ages(self, err)
        class(auto_t), intent(inout) :: self
        type(error_t), allocatable, intent(out) :: err
        character(len=240) :: text
        self%explicit_age = self%explicit_age + 1
        if (self%explicit_age >= STALE_WINDOWS .and. self%wait == 0) then
            write (text, '(a, i0, a)') 'the order-4 pair''s cost was measured ', &
                self%explicit_age, ' windows ago: measuring it again'
            call self%start_method(EXPLICIT, trim(text), err)
        end if
    end subroutine explicit_cost_ages

    !> A window of the implicit method that cost `rate`: judged on trial, and left for erk
    !! (or the symplectic method) when erk's predicted cost is lower by GAIN.
    subroutine implicit_window(self, rate, err)
        class(auto_t), intent(inout) :: self
        real(wp), intent(in) :: rate
        type(error_t), allocatable, intent(out) :: err
        type(spectrum_t) :: spec
        real(wp) :: h_e, predicted
        character(len=240) :: text
        character(len=WHY_LEN) :: why_sym
        logical :: warns    !< why_sym is a warning (symplectic_fits)
        ! judge the implicit method on its second window on (the first includes its
        ! start at order 1 with small steps)
        if (self%windows < 2) return
        self%rate_implicit = rate
        self%implicit_age = 0
        if (self%trial) then
            self%trial = .false.
            if (self%rate_explicit > 0.0_wp .and. rate > self%rate_explicit) then
                ! the dearer the trial, the longer until the next: times the cost
                ! ratio rounded up, at least 2 (capped below integer overflow)
                self%stale_after = grown(self, self%stale_after, rate)
                call trial_failed(self, self%implicit_name()//' was not cheaper', rate, err)
                return
            end if
        end if
        if (self%wait > 0) return
        call estimate_spectrum(self%problem, self%t, self%y, spec)
        h_e = erk_stable_step(self%tab, spec)
        if (h_e <= 0.0_wp) return
        if (self%accurate == HIGH) &
            self%h_stable_high = erk_stable_step(self%tab_high, spec)
        self%radius = spec%radius
        predicted = EXPLICIT_MARGIN*self%tab%evals_per_step()/h_e
        if (GAIN*predicted < rate) then
            write (text, '(a, es9.2, a, es9.2, a, es9.2, a)') 'explicit stable step ', h_e, &
                ' s: predicted cost ', predicted, ' f per second against ', rate, &
                ' for '//self%implicit_name()
            if (self%windows <= 2) call back_off(self)
            if (self%symplectic_fits(spec, h_e, self%t, why_sym, warns, rate/GAIN)) then
                call self%start_method(SYMPLECTIC, trim(text)//'; '//trim(why_sym), err)
            else
                call self%start_method(EXPLICIT, trim(text), err, h_e)
                if (.not. allocated(err) .and. len_trim(why_sym) > 0) &
                    call self%add_note(trim(why_sym), warns)
            end if
        end if
    end subroutine implicit_window

    !> To the symplectic method when its cost (self%sym_cost, from its last look) is below
    !! the measured cost `rate` of erk's window by GAIN and it still fits at the state now
    !! (a new spectrum estimate, only then): a lightly damped rope whose erk steps are held
    !! by accuracy, not by the stability that erk's predicted cost assumes
    !! (input/hard/light_damping.nml: erk 1.63 s, the symplectic method 0.27 s).
    subroutine try_symplectic(self, rate, err)
        class(auto_t), intent(inout) :: self
        real(wp), intent(in) :: rate
        type(error_t), allocatable, intent(out) :: err
        type(spectrum_t) :: spec
        real(wp) :: h_e
        character(len=240) :: text
        character(len=WHY_LEN) :: why_sym
        logical :: warns    !< why_sym is a warning (symplectic_fits)
        if (self%windows < 2 .or. .not. (self%sym_cost > 0.0_wp)) return
        if (GAIN*self%sym_cost >= rate .or. self%sym_wait > 0) return
        call estimate_spectrum(self%problem, self%t, self%y, spec)
        h_e = erk_stable_step(self%tab, spec)
        if (self%symplectic_fits(spec, h_e, self%t, why_sym, warns, rate/GAIN, &
                                 .true.)) then
            write (text, '(a, es9.2, a)') 'erk''s cost ', rate, ' f per second'
            call self%start_method(SYMPLECTIC, trim(text)//'; '//trim(why_sym), err)
        else if (len_trim(why_sym) > 0) then
            call self%add_note(trim(why_sym), warns)
        end if
    end subroutine try_symplectic

    !> Add to text what the switch tries: `what` on trial, or again when its cost,
    !! measured `windows_ago` explicit windows ago, is stale.
    subroutine add_trial(self, text, what, is_stale, windows_ago)
        class(auto_t), intent(in) :: self
        character(len=*), intent(inout) :: text
        character(len=*), intent(in) :: what
        logical, intent(in) :: is_stale
        integer, intent(in) :: windows_ago
        if (is_stale) then
            text = trim(text)//': trying '//what//' again (its cost was measured '// &
                   int_text(windows_ago)//' windows ago)'
        else if (self%trial) then
            text = trim(text)//': trying '//what
        end if
    end subroutine add_trial

    !> A stale-cost wait after a trial that cost `rate` against erk's: `windows` times the
    !! cost ratio rounded up, at least 2 (capped below integer overflow).
    integer function grown(self, windows, rate)
        class(auto_t), intent(in) :: self
        integer, intent(in) :: windows
        real(wp), intent(in) :: rate
        real(wp) :: growth
        growth = max(2.0_wp, real(ceiling(min(rate/self%rate_explicit, 1.0e9_wp)), wp))
        grown = int(min(0.5_wp*real(huge(0), wp), growth*windows))
    end function grown

    !> A switch soon after the last one: wait longer before the next.
    subroutine back_off(self)
        class(auto_t), intent(inout) :: self
        self%wait = self%backoff
        self%backoff = min(MAX_WAIT, 2*self%backoff)
    end subroutine back_off

    !> The method on trial (`what`) cost `rate`, more than erk: back to erk, and wait longer.
    subroutine trial_failed(self, what, rate, err)
        class(auto_t), intent(inout) :: self
        character(len=*), intent(in) :: what
        real(wp), intent(in) :: rate
        type(error_t), allocatable, intent(out) :: err
        character(len=240) :: text
        write (text, '(a, es9.2, a, es9.2, a)') what//' (', rate, ' against ', &
            self%rate_explicit, ' f per second)'
        call back_off(self)
        call self%start_method(EXPLICIT, trim(text), err)
    end subroutine trial_failed

    !> erk's first window since the start (its counters `now`), nearly every step held by
    !! stability and the implicit method not yet tried: no need to wait for WINDOW steps
    !! (drag_fall: 400 steps take 0.38 of its 2 s, where mebdf needs 156 steps in all)
    logical function early_look(self, now)
        class(auto_t), intent(in) :: self
        type(solver_stats_t), intent(in) :: now
        early_look = self%active == EXPLICIT .and. self%windows == 0 .and. &
                     self%rate_implicit < 0.0_wp .and. self%trials_are_cheap() .and. &
                     now%steps - self%win_steps0 >= EARLY_WINDOW
        if (early_look) &
            early_look = self%erk%stiff_share_of_steps(EARLY_WINDOW) >= EARLY_SHARE
    end function early_look
end submodule ropedyn_auto_switching
