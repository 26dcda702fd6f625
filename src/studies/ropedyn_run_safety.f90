!> The order safety of a run (`&solver order_safety`; the stability guide, "Order safety"):
!! at every output time the energy monitor compares the balance B = T + V + dissipated -
!! work with E0; a gain above `energy_gain_bound` rtol S takes a second look at the
!! method's safe (A-stable) order with 'lower', and ends the run as a failed integration
!! naming the gain with 'stop'. With either, a runaway (B - E0 above a tenth of max(S,
!! m g L), after any second look) ends the run too. The monitor (ropedyn_energy_monitor)
!! holds the rules as pure functions; this submodule carries them out on the run.
submodule (ropedyn_run) ropedyn_run_safety
    use ropedyn_text, only: significant_text, int_text
    use ropedyn_solvers, only: new_integrator
    use ropedyn_energy_monitor, only: high_order_to_blame, sudden_gain, look_budget, &
                                      look_action, LOOK_LOWER, LOOK_NO_VERDICT, LOOK_FAIL
    implicit none

contains

    !> The energy monitor at the output time just reached: on a gain beyond the bound,
    !! lower the order and integrate the interval again ('lower'), or fail ('stop'); on a
    !! runaway of the state it leaves, fail.
    module procedure check_energy
        type(energy_t) :: e
        type(energy_monitor_t) :: next
        type(solver_stats_t) :: stats
        character(len=40) :: what
        real(wp) :: next_bound
        logical :: gained
        e = self%model%energy(self%t, self%y, self%yq)
        if (.not. ieee_is_finite(e%balance())) return   ! `record` says so
        gained = self%monitor%gained(e)
        if (gained) then
            next = self%monitor
            call next%observe(e)
            next_bound = next%bound()
            call self%summary%safety%alarm(next%gain(e), next_bound)
            if (trim(self%scene%solver%order_safety) == 'stop') then
                stats = self%integrator%stats()
                ! (the order limit only for a method that has one: auto's is 0)
                what = ''
                if (self%max_order > 0) what = ', max order '//int_text(self%max_order)
                call make_error(err, ERR_SOLVER, self%integrator%name()//' failed at t = '// &
                    significant_text(self%t_prev, 6)//' s, step size '// &
                    significant_text(stats%last_step, 3)//' s: energy gain '// &
                    significant_text(next%gain(e), 3)//' J above E0 (bound '// &
                    significant_text(next_bound, 3)//' J) at t = '// &
                    significant_text(self%t, 6)//' s'//trim(what)//': the integrator '// &
                    'created energy (&solver order_safety = ''stop''; '// &
                    'docs/theory/energy-balance.md)')
                ! the record with the gain is not written
                call back_to_previous(self)
                return
            end if
            ! (auto's order in use: its implicit method's limit)
            if (self%safe_order > 0 .and. &
                self%integrator%order_in_use() > self%safe_order) then
                call self%second_look(tout, e, next_bound, err)
                if (allocated(err)) return
            else
                call self%summary%safety%unresolved(self%t, self%safe_order == 0)
            end if
        end if
        ! the state the run goes on from (after a second look, perhaps another); auto has
        ! one more way out
        if (self%monitor%runaway(e)) then
            if (trim(self%scene%solver%method) == 'auto' .and. .not. self%rescued .and. &
                trim(self%scene%solver%order_safety) == 'lower') then
                call self%rescue(tout, e, err)
                if (allocated(err)) return
            end if
            ! (e after the rescue: its own runaway ends the run)
            if (self%monitor%runaway(e)) then
                call self%fail_runaway(e, err)
                return
            end if
        end if
        call self%monitor%observe(e)
        self%steps_mark = self%steps_taken()
        if (.not. gained) e_now = e              ! the record of this state takes it
    end procedure check_energy

    !> The run fails at a runaway of state e: the time, the step, the energy created, the
    !! scale it passed, and what to do; the state goes back to the previous record's (which
    !! the record of a run keeps, and a library run at its previous look).
    module procedure fail_runaway
        type(solver_stats_t) :: stats
        stats = self%integrator%stats()
        call make_error(err, ERR_SOLVER, self%integrator%name()//' failed at t = '// &
            significant_text(self%t, 6)//' s, step size '// &
            significant_text(stats%last_step, 3)//' s: it '//runaway_text(self, e)// &
            ': at rtol '//significant_text(self%scene%solver%rtol, 3)//' the integration '// &
            'does not follow this motion; tighten rtol (e.g. rtol = '// &
            significant_text(0.1_wp*self%scene%solver%rtol, 3)//') (docs/theory/'// &
            'energy-balance.md, "A runaway ends the run")')
        call back_to_previous(self)
    end procedure fail_runaway

    !> A gain beyond the bound at the order limit in use: the interval [t_prev, tout]
    !! again at the safe order by a second integrator. When the gain is the order's
    !! (high_order_to_blame: gathered over earlier intervals, or made in this one and the
    !! safe order changed the balance less), the run goes on from tout at the safe order
    !! with that integrator, for good. A gain of this interval that the safe order matches
    !! is the integration error at this tolerance: the second integrator is dropped, the
    !! run goes on as it was and the monitor counts gains from that level on. For such a
    !! gain the safe order has a capped budget (look_budget); if that is not enough, no
    !! verdict: the order is kept so, once. Otherwise it has the whole budget left; its
    !! failure is the run's. e: the energies of the state the run goes on from.
    module procedure second_look
        class(integrator_t), allocatable :: safe
        type(error_t), allocatable :: safe_err
        type(solver_options_t) :: options
        real(wp) :: t_safe, y_safe(size(self%y)), yq_safe(size(self%yq)), gain_prev, &
                    change_high, change_safe
        integer(i8) :: steps_high, budget, max_steps
        logical :: sudden, reached
        integer :: action, high
        character(len=200) :: why
        high = self%integrator%order_in_use()
        gain_prev = self%monitor%gain(self%model%energy(self%t_prev, self%y_prev, &
                                                        self%yq_prev))
        change_high = self%monitor%gain(e) - gain_prev
        change_safe = 0.0_wp
        steps_high = self%steps_taken() - self%steps_mark
        sudden = sudden_gain(change_high, bound)
        max_steps = step_budget(self%scene)
        budget = look_budget(sudden, self%summary%safety%crawled, steps_high, &
                             max_steps - self%stats_before%steps - self%steps_taken())
        t_safe = self%t_prev
        y_safe = self%y_prev
        yq_safe = self%yq_prev
        call create_integrator(self%scene, safe, err)
        if (allocated(err)) return
        options = self%integrator_options(self%stats_before%steps + self%steps_taken())
        options%max_order = self%safe_order
        options%max_steps = max(1_i8, budget)
        call safe%init(self%model, t_safe, y_safe, yq_safe(1:self%nq), options, err)
        if (allocated(err)) return
        call safe%advance_to(tout, t_safe, y_safe, yq_safe(1:self%nq), safe_err)
        reached = .not. allocated(safe_err) .and. t_safe >= tout
        if (reached) change_safe = self%monitor%gain(self%model%energy(t_safe, y_safe, &
                                                                        yq_safe)) - gain_prev
        action = look_action(reached, self%asked_to_stop(), sudden, self%summary%safety%crawled, &
                             high_order_to_blame(change_high, change_safe, bound))
        if (action == LOOK_LOWER .or. action == LOOK_FAIL) then
            ! on from where the safe order got, with it (its failure is the run's)
            if (action == LOOK_LOWER) call self%summary%safety%lowered(self%t_prev, &
                high, self%safe_order)
            call self%retire_integrator(safe)
            ! the whole budget that is left, no longer the second look's (the steps before
            ! it, the retired integrator's included, are those it started after)
            call self%integrator%set_step_budget(max(1_i8, max_steps - self%stats_before%steps))
            self%max_order = self%safe_order
            self%t = t_safe
            self%y = y_safe
            self%yq = yq_safe
            e = self%model%energy(self%t, self%y, self%yq)
            if (allocated(safe_err)) call move_alloc(safe_err, err)
            return
        end if
        if (action == LOOK_NO_VERDICT) then
            self%summary%safety%crawled = .true.
            write (why, '(4(a, i0), a)') 'order ', self%safe_order, &
                ' did not get through the same interval in ', budget, &
                ' steps (order ', high, ' took ', steps_high, '): no verdict'
        else if (reached) then
            write (why, '(a, i0, a, es10.3, a, i0, a, es10.3, a)') 'order ', &
                self%safe_order, ' changed the balance by ', change_safe, ' J over the '// &
                'same interval, order ', high, ' by ', change_high, ' J: the '// &
                'integration error at this rtol'
        else
            why = 'the second look at the safe order was interrupted'
        end if
        ! on at the order asked for; gains counted from this level
        call self%stats_before%add(safe%stats())
        call safe%finalize()
        call self%summary%safety%kept(self%t, trim(why))
        call self%monitor%accept(self%monitor%gain(e))
    end procedure second_look

    !> auto at a runaway: none of its methods has a safe order to fall back on, so the
    !! interval [t_prev, tout] again with MEBDF at its safe order (A-stable: it damps
    !! what it does not resolve, and did not run away at any tolerance of the loose-
    !! tolerance study), and the run on with it for good, from the state it reaches. The
    !! switch is logged as a warning with its cause; its failure is the run's, and a
    !! runaway after it ends the run (check_energy). e: the energies of that state.
    module procedure rescue
        class(integrator_t), allocatable :: safe
        integer :: order
        character(len=:), allocatable :: why
        order = METHODS(method_index('mebdf'))%safe_order
        why = 'energy runaway: by t = '//significant_text(self%t, 6)//' s '// &
            self%integrator%name()//' '//runaway_text(self, e)//' at rtol '// &
            significant_text(self%scene%solver%rtol, 3)//': the interval again from t = '// &
            significant_text(self%t_prev, 6)//' s and on with mebdf at its safe order '// &
            int_text(order)//' (a tighter rtol keeps auto; docs/theory/energy-balance.md, '// &
            '"A runaway ends the run")'
        call new_integrator('mebdf', safe, err)
        if (allocated(err)) return
        call self%retire_integrator(safe)
        call self%switches_before%add(self%t_prev, 'mebdf', order, why, warning=.true.)
        self%rescued = .true.
        self%max_order = order
        self%safe_order = order
        call back_to_previous(self)
        call self%start_integrator(err)
        if (allocated(err)) return
        call self%integrator%advance_to(tout, self%t, self%y, self%yq(1:self%nq), err)
        e = self%model%energy(self%t, self%y, self%yq)
    end procedure rescue

    !> The run's state back at the previous record (or a library run's previous look),
    !! where the order safety looks back to.
    subroutine back_to_previous(self)
        class(run_t), intent(inout) :: self
        self%t = self%t_prev
        self%y = self%y_prev
        self%yq = self%yq_prev
    end subroutine back_to_previous

    !> 'created G J (g m g L) of energy, more than a tenth of the run's energy scale
    !! (max(S, m g L) = X J)': a runaway of state e, for the messages that name it.
    function runaway_text(self, e) result(text)
        class(run_t), intent(in) :: self
        type(energy_t), intent(in) :: e
        character(len=:), allocatable :: text
        real(wp) :: gain
        gain = self%monitor%gain(e)
        text = 'created '//significant_text(gain, 3)//' J'
        if (self%summary%weight_length > 0.0_wp) text = text//' ('// &
            significant_text(gain/self%summary%weight_length, 3)//' m g L)'
        text = text//' of energy, more than a tenth of the run''s energy scale (max(S, '// &
            'm g L) = '//significant_text(10.0_wp*self%monitor%runaway_limit(e), 3)//' J)'
    end function runaway_text

    !> The integrator in use replaced by `next` (moved in): its counters and switches go
    !! to those of the run's earlier integrators.
    module procedure retire_integrator
        call self%stats_before%add(self%integrator%stats())
        call self%keep_switches()
        call self%integrator%finalize()
        call move_alloc(next, self%integrator)
    end procedure retire_integrator

    module procedure keep_switches
        type(switch_event_t), allocatable :: events(:)
        integer :: k
        events = self%integrator%switch_log()
        do k = 1, size(events)
            call self%switches_before%add(events(k)%t, events(k)%method, &
                                          events(k)%max_order, events(k)%reason, &
                                          events(k)%warning)
        end do
    end procedure keep_switches
end submodule ropedyn_run_safety
