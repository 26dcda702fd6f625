!> The step-size choice of the symplectic method (ropedyn_symplectic's header, "Step
!! size"; docs/theory/symplectic.md, "The step").
submodule (ropedyn_symplectic) ropedyn_symplectic_steps
    implicit none

contains

    !> The first step size and the forces at the initial state.
    module procedure begin
        integer :: status
        real(wp) :: h
        character(len=280) :: text
        type(split_table_t) :: tab
        self%started = .true.
        self%vt = self%v
        call self%evaluate(self%t, status, full=.true.)
        if (status /= STATUS_OK) then
            call self%failure(err, 'the forces could not be evaluated at the initial state')
            return
        end if
        if (self%fixed_h > 0.0_wp) then
            self%h = self%fixed_h
            self%respectrum = huge(1_i8)
            call self%log%add(self%t, self%name(), self%tab%order, trim(self%tab%label)// &
                              ' at a fixed step')
            return
        end if
        call stable_step_here(self, tab, h, text)
        if (h <= 0.0_wp) then
            call self%failure(err, 'no estimate of the spectrum to choose the step from')
            return
        end if
        call too_stiff(self, tab, h, err)
        if (allocated(err)) return
        self%tab = tab
        call self%set_step(h, tout, trim(text), .false.)
        call self%budget_reaches_end(err)
    end procedure begin

    !> The run ends at once (ERR_SOLVER) when its rest, to options%t_end, takes more steps at
    !! the step rule than the step budget has left. The step is fixed between estimates of
    !! the spectrum, so the method knows this now: it says so at the start (or where the step
    !! shortens), with the budget that reaches the end, not when the budget runs out. It
    !! counts the steps at the step in use, the rule's fitted to the output interval
    !! (steps_left), which the run takes (never fewer than at the rule's step). A driven
    !! run (the library's simulation) has no end to count to: t_end does not stop it.
    module procedure budget_reaches_end
        integer(i8) :: rest, left
        if (self%options%driven) return
        rest = max(steps_to_end(self%t, self%options%t_end, self%h_rule), self%steps_left(self%t))
        left = self%options%max_steps - self%counters%steps
        if (rest <= left) return
        self%budget_short = .true.
        call self%failure(err, 'the rest of the run, to t = '//real_text(self%options%t_end)// &
            ' s, takes about '//int_text(rest)//' steps of '//significant_text(self%h, 3)// &
            ' s ('//trim(self%tab%label)//' at the step the spectral radius '// &
            significant_text(self%radius, 3)//' 1/s allows, '// &
            significant_text(self%h_rule, 3)//' s, shortened to fit the output interval), '// &
            'more than the '//int_text(left)//' that max_steps leaves: raise '// &
            'solver.max_steps by '//int_text(budget_covering(rest) - left))
    end procedure budget_reaches_end

    !> The run ends (ERR_SOLVER) when the step h of the composition `tab` would take more
    !! than STIFF_STEP_RATE steps per simulated second, as erk's and adams' do: the step of an
    !! explicit method held by the spectral radius, where an implicit method takes steps many
    !! times longer. A step below ACCURACY_HELD of the composition's stable step is held by
    !! the tolerance instead (its order's step at rtol, or the fast modes' energy error): the
    !! message says so. The failure is that of the step and composition it names.
    subroutine too_stiff(self, tab, h, err)
        class(symplectic_t), intent(inout) :: self
        type(split_table_t), intent(in) :: tab
        real(wp), intent(in) :: h
        type(error_t), allocatable, intent(out) :: err
        real(wp), parameter :: ACCURACY_HELD = 0.2_wp
        character(len=:), allocatable :: cause, rate
        if (1.0_wp/h <= STIFF_STEP_RATE) return
        self%h = h
        self%tab = tab
        rate = short_es(1.0_wp/h)
        if (h < ACCURACY_HELD*self%h_stable) then
            cause = 'the tolerance (rtol = '//significant_text(self%options%rtol, 3)// &
                ') asks for steps of '//significant_text(h, 3)//' s of '//trim(tab%label)// &
                ' (order '//int_text(tab%order)//'), '//rate// &
                ' steps per simulated second, where its stable step is '// &
                significant_text(self%h_stable, 3)//' s: '
            if (self%order_limit < 4) then
                cause = cause//'allow the 4th-order compositions (max_order = 4, the '// &
                    'default), loosen rtol, or use method = ''auto'''
            else
                cause = cause//'loosen rtol, or use method = ''auto'' or ''mebdf'''
            end if
        else
            cause = 'the problem is too stiff for an explicit method here: the step is held '// &
                'by stability (spectral radius '//short_es(self%radius)//' 1/s, step '// &
                short_es(h)//' s), which takes '//rate//' steps per simulated second; use '// &
                'method = ''auto'' (it switches to an implicit method where this happens) '// &
                'or ''mebdf'''
        end if
        call self%failure(err, cause)
    contains
        !> x as the message writes it: es9.2 without its leading blanks
        function short_es(x) result(text)
            real(wp), intent(in) :: x
            character(len=:), allocatable :: text
            text = trim(adjustl(es_text(x, 9, 2)))
        end function short_es
    end subroutine too_stiff

    !> The spectrum at the current state again; the step changed when it must shrink or
    !! may grow by GROW_AT (the first output interval from here a whole number of steps).
    module procedure review_step
        real(wp) :: h
        character(len=280) :: text
        type(split_table_t) :: tab
        call stable_step_here(self, tab, h, text)
        if (h <= 0.0_wp) return
        call too_stiff(self, tab, h, err)
        if (allocated(err)) return
        ! the composition and its step change together (the step is the composition's)
        if (tab%kind /= self%tab%kind .or. h < self%h .or. h > GROW_AT*self%h) then
            self%tab = tab
            call self%set_step(h, tout, trim(text), .false.)
            self%respectrum = RESPECTRUM_STEPS
            call self%budget_reaches_end(err)
        else
            self%respectrum = min(RESPECTRUM_MAX, 2*self%respectrum)
        end if
    end procedure review_step

    !> The composition and step for the spectrum at the current state (choose_step; h = 0:
    !! no estimate), and its reason for the log.
    subroutine stable_step_here(self, tab, h, text)
        class(symplectic_t), intent(inout) :: self
        type(split_table_t), intent(out) :: tab
        real(wp), intent(out) :: h
        character(len=*), intent(out) :: text
        type(spectrum_t) :: spec
        logical :: light
        self%y(self%pos) = self%q
        self%y(self%vel) = self%v
        call estimate_spectrum(self%problem, self%t, self%y, spec)
        self%estimated_at = self%counters%steps
        call choose_step(spec, self%options%rtol, self%order_limit, self%rest, tab, h, light, &
                         text, stay_light=self%light_seen, h_stable=self%h_stable)
        self%light_seen = self%light_seen .or. light
        self%radius = spec%radius
        self%fast_damping = spec%fast_damping
    end subroutine stable_step_here

    !> The composition (Verlet, or when max_order >= 4 also Blanes-Moan's and Chin's) and its
    !! step for a spectrum estimate and a tolerance (docs/theory/symplectic.md, "The step"):
    !! each composition's step is its `safety` times its stable step (RESONANT_SAFETY when
    !! the mode that limits it is damped by less than LIGHT_DAMPING), times
    !! (rtol / rtol_at)^(1/order) below the tolerance that step reaches; the cheapest per
    !! simulated second (step_cost over the step) is taken, except that lightly
    !! damped fast modes take a 4th-order composition when allowed (at Verlet's
    !! resonance-safe step its energy error is 100 times larger), each at most the step at
    !! which the energy of an undamped mode at the spectral radius errs by
    !! FAST_SPREAD_PER_RTOL rtol (split_table_t's energy_hw). h = 0: no estimate.
    module procedure choose_step
        type(split_table_t) :: cand
        real(wp) :: hs, hk, he, zeta, safety, scale, here, best
        character(len=80) :: extra
        integer :: kind
        logical :: slight
        h = 0.0_wp
        light = .false.
        text = 'no estimate of the spectrum'
        best = huge(1.0_wp)
        if (present(cost)) cost = 0.0_wp
        if (present(h_stable)) h_stable = 0.0_wp
        tab = split_table(TABLE_VERLET)
        do kind = TABLE_VERLET, TABLE_CHIN
            if (kind /= TABLE_VERLET .and. max_order < 4) exit
            cand = split_table(kind)
            call split_stable_step(cand, spec, hs, zeta)
            if (hs <= 0.0_wp) return
            ! the limiting mode, or any settled fast mode (their combinations); or found so
            ! at an earlier estimate (stay_light)
            slight = zeta < LIGHT_DAMPING .or. spec%settled_damping() < LIGHT_DAMPING
            if (present(stay_light)) slight = slight .or. stay_light
            if (slight .and. kind == TABLE_VERLET .and. max_order >= 4) cycle
            safety = cand%safety
            if (slight) safety = RESONANT_SAFETY
            scale = min(1.0_wp, (rtol/cand%rtol_at)**(1.0_wp/cand%order))
            hk = safety*scale*hs
            ! lightly damped fast modes keep their energy error: at most FAST_SPREAD_PER_RTOL
            ! rtol for the fastest
            he = huge(1.0_wp)
            if (slight .and. spec%radius > 0.0_wp) &
                he = cand%energy_hw(FAST_SPREAD_PER_RTOL*rtol)/spec%radius
            here = step_cost(cand, rest)/min(hk, he)
            if (here >= best) cycle
            best = here
            tab = cand
            h = min(hk, he)
            light = slight
            if (present(cost)) cost = best
            if (present(h_stable)) h_stable = hs
            write (text, '(a, es9.2, a, f6.3, a, es9.2, a, f5.2, a, f5.3, a)') &
                'spectral radius ', spec%radius, ' 1/s, the mode limiting the step damped ', &
                zeta, ', stable step ', hs, ' s, the step ', safety, ' x', scale, ' of it'
            if (he < hk) then
                write (extra, '(a, f5.3, a)') ', shortened to ', h/hs, &
                    ' of it: the fastest mode''s energy within 10 rtol'
                text = trim(text)//extra
            end if
        end do
    end procedure choose_step

    !> A step's work in evaluations of the potential's forces: its evaluations, STEP_WORK,
    !! and REST_WORK when the problem has forces outside the potential.
    pure real(wp) function step_cost(tab, rest) result(work)
        type(split_table_t), intent(in) :: tab
        logical, intent(in) :: rest
        work = tab%evals + STEP_WORK
        if (rest) work = work + REST_WORK
    end function step_cost

    !> The step from now on: `h` at most, fitted so that the interval to tout is a whole
    !! number of steps; the change logged (as a warning when `warn`).
    module procedure set_step
        real(wp) :: span
        character(len=120) :: what
        span = tout - self%t
        self%h_rule = h
        self%h = h
        if (span > 0.0_wp) self%h = span/real(ceiling(span/h*(1.0_wp - 1.0e-12_wp)), wp)
        self%t_base = self%t
        self%k = 0
        what = trim(self%tab%label)//', step '//es_text(self%h, 10, 3)//' s: '
        call self%log%add(self%t, self%name(), self%tab%order, trim(what)//' '//reason, warn)
    end procedure set_step

    !> The stable step of a composition for a spectrum estimate (interface in the module).
    module procedure split_stable_step
        complex(wp), allocatable :: fast(:)
        real(wp) :: w, zeta, hi
        integer :: i
        h = 0.0_wp
        if (present(zeta_limit)) zeta_limit = 0.0_wp
        if (.not. spec%valid) return
        fast = spec%fast(FAST_FRACTION)
        h = huge(1.0_wp)
        do i = 1, size(fast)
            w = abs(fast(i))
            if (w <= 0.0_wp) cycle
            if (abs(aimag(fast(i))) <= 1.0e-8_wp*w .and. real(fast(i), wp) < 0.0_wp) then
                ! a damping rate c = |lambda| alone
                zeta = 1.0_wp
                hi = OVERDAMPED_LIMIT/w
            else
                zeta = max(0.0_wp, -real(fast(i), wp)/w)
                hi = tab%stable_hw(zeta)/w
            end if
            if (hi < h) then
                h = hi
                if (present(zeta_limit)) zeta_limit = zeta
            end if
        end do
        if (h == huge(1.0_wp)) h = 0.0_wp
    end procedure split_stable_step
end submodule ropedyn_symplectic_steps
