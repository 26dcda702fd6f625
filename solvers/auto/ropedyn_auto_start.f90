!> auto's start (ropedyn_auto's header, "Start"): the spectrum estimate, the width of the
!! Newton matrix, and the first method: implicit, symplectic or erk.
submodule (ropedyn_auto) ropedyn_auto_start
    implicit none

contains

    module procedure auto_start
        type(spectrum_t) :: spec
        real(wp) :: h_e, h_a, rate
        character(len=280) :: text
        character(len=100) :: slow
        character(len=WHY_LEN) :: why_sym
        logical :: warns    !< why_sym is a warning (symplectic_fits)

        self%user_order = start%max_order
        self%y = start%y0
        self%yq = start%yq0
        self%t = start%t0
        self%tab = erk_table(ERK_ORDER)
        self%tab_high = erk_table(HIGH_ORDER)
        self%done = solver_stats_t()
        call self%log%clear()
        call self%sym_past%clear()
        self%budget_said = .false.
        self%rate_explicit = -1.0_wp
        self%rate_implicit = -1.0_wp
        self%implicit_age = 0
        self%stale_after = STALE_WINDOWS
        self%rate_accurate = -1.0_wp
        self%accurate = merge(ADAMS, HIGH, self%problem%has_mass_matrix())
        self%trial = .false.
        self%wait = 0
        self%backoff = 1
        self%h_stable = 0.0_wp
        self%h_stable_high = 0.0_wp
        self%explicit_age = 0
        self%radius = 0.0_wp
        self%sym_order = 0
        self%sym_wait = 0
        self%sym_backoff = STALE_WINDOWS
        self%sym_barred = .false.

        call newton_widths(self%problem, self%lambda, self%mebdf_eval_cost)
        call estimate_spectrum(self%problem, start%t0, start%y0, spec)
        ! (a limit below BDF's order 5 asks for an A-stable implicit method: BDF is one
        ! only up to order 2, MEBDF up to 4; the order safety lowers auto to 4)
        self%use_bdf = spec%valid .and. spec%fast_damping >= BDF_DAMPING .and. &
                       (self%user_order == 0 .or. self%user_order >= BDF_ORDER)
        ! (without an estimate the fast modes may be undamped: the A-stable order)
        self%mebdf_order = mebdf_order_for(merge(spec%fast_damping, 0.0_wp, spec%valid))
        if (self%use_bdf) self%mebdf_order = BDF_ORDER
        if (self%user_order /= 0) self%mebdf_order = min(self%mebdf_order, self%user_order)
        h_e = erk_stable_step(self%tab, spec)
        if (self%accurate == HIGH) self%h_stable_high = erk_stable_step(self%tab_high, spec)
        self%radius = spec%radius
        self%h_chunk = h_e
        if (spec%valid .and. h_e > 0.0_wp) then
            rate = 1.0_wp/h_e
            write (text, '(a, es9.2, a, f6.3, a, es9.2, a)') 'spectral radius ', &
                spec%radius, ' 1/s, fast modes damped >= ', spec%fast_damping, &
                ', explicit stable step ', h_e, ' s'
        else
            rate = 0.0_wp
            text = 'no spectrum estimate'
        end if
        h_a = 0.0_wp
        why_sym = ''
        if (rate > 0.0_wp .and. rate <= START_RATE) &
            h_a = accuracy_step(self%problem, start%t0, start%y0, self%options, h_e)
        if (rate > START_RATE) then
            call self%start_method(IMPLICIT, trim(text)//': explicit steps too short', err)
        else if (self%symplectic_fits(spec, h_e, start%t0, why_sym, warns)) then
            ! (before the slow start's test: a lightly damped rope released from rest is
            ! slow only at first, and its long run is the symplectic method's)
            call self%start_method(SYMPLECTIC, trim(text)//'; '//trim(why_sym), err)
        else if (h_a > START_ACCURACY*h_e) then
            write (slow, '(a, es9.2, a)') '; a first-order step of ', h_a, &
                ' s within the tolerance: motion too slow for explicit steps'
            call self%start_method(IMPLICIT, trim(text)//trim(slow), err)
        else
            call self%start_method(EXPLICIT, trim(text), err, h_e)
        end if
        if (allocated(err)) return
        if (self%active /= SYMPLECTIC .and. len_trim(why_sym) > 0) &
            call self%add_note(trim(why_sym), warns)
        self%initialized = .true.
    end procedure auto_start

    !> Whether the run should go symplectic (ropedyn_auto_switching's header, "Symplectic"):
    !! the problem offers the force split, the run is long, the mode that limits the
    !! symplectic step is lightly damped, the step takes at most START_RATE steps per
    !! simulated second, and its cost (choose_step's: its evaluations and the rest of its
    !! work per simulated second) is at most LIGHT_COST_LIMIT times erk's predicted cost
    !! (evaluations per step over the stable step h_e, with EXPLICIT_MARGIN), and under
    !! `below` when given; with `measured`, `below` is erk's measured cost over GAIN and
    !! replaces the limit against the predicted one; last, its probe (ropedyn_auto_probe)
    !! must pass. `why`: the reason for the log (a warning when `warns`). Where
    !! the method is offered and lightly damped but left out, its cost stays in
    !! self%sym_cost for the measured look (watch); else that is -1. While a failed
    !! probe's wait lasts (sym_wait), and after the method stopped in this run
    !! (sym_barred), it is not weighed at all.
    module procedure symplectic_fits
        type(split_table_t) :: tab
        real(wp) :: h, cost_s, cost_e
        integer(i8) :: rest, left
        type(solver_stats_t) :: used
        logical :: light
        character(len=280) :: text
        logical :: by_measure
        fits = .false.
        why = ''
        warns = .true.
        ! (after a probe that failed: its cost stays for the measured look when the wait is over)
        if (self%sym_wait > 0 .or. self%sym_barred) return
        self%sym_cost = -1.0_wp
        by_measure = .false.
        if (present(measured)) by_measure = measured .and. present(below)
        if (len(self%problem%force_split_refusal()) > 0 .or. h_e <= 0.0_wp) return
        if (self%options%t_end - t0 < LONG_RUN) return
        call choose_step(spec, self%options%rtol, 4, self%problem%split_has_rest(), tab, h, &
                         light, text, cost_s)
        ! (as for the start: a step so short is the implicit method's)
        if (.not. light .or. h <= 0.0_wp .or. 1.0_wp/h > START_RATE) return
        self%sym_cost = cost_s
        cost_e = EXPLICIT_MARGIN*self%tab%evals_per_step()/h_e
        if (cost_s > LIGHT_COST_LIMIT*cost_e .and. .not. by_measure) return
        if (present(below)) then
            if (cost_s >= below) return
        end if
        ! (its steps are known in advance: a run it cannot finish goes on with the others;
        ! a tenth to spare, as the step may shorten on the way)
        rest = steps_to_end(t0, self%options%t_end, h)
        used = self%stats()
        left = self%options%max_steps - used%steps
        if (budget_covering(rest) > left) then
            if (.not. self%budget_said) why = 'the symplectic method would keep the '// &
                'energy bounded (the fast modes are lightly damped), but the rest of the '// &
                'run, to t = '//real_text(self%options%t_end)//' s, takes about '// &
                int_text(rest)//' of its steps ('//significant_text(h, 3)//' s), with a '// &
                'tenth to spare more than the '//int_text(left)//' that max_steps leaves: '// &
                'raise solver.max_steps by '//int_text(budget_covering(rest) - left)// &
                ' to use it'
            self%budget_said = .true.
            self%sym_cost = -1.0_wp
            return
        end if
        ! (is it accurate here? its step has no error estimate: ropedyn_auto_probe)
        call self%probe_symplectic(tab, h, fits, text)
        if (.not. fits) then
            why = 'the symplectic method would be used (the fast modes are lightly damped), '// &
                  'but '//trim(text)
            warns = .false.
            return
        end if
        self%sym_order = tab%order
        if (by_measure) then
            write (why, '(a, f4.2, a)') 'the fast modes are lightly damped and the '// &
                'symplectic method costs less than erk as measured (', &
                cost_s/(GAIN*below), ' times its cost; '//trim(tab%label)//'), with an '// &
                'energy balance that stays bounded'
        else
            write (why, '(a, f4.2, a)') 'the fast modes are lightly damped: an adaptive '// &
                'method''s energy balance drifts over a long run, the symplectic method''s '// &
                'stays bounded (', cost_s/cost_e, ' times erk''s predicted cost; '// &
                trim(tab%label)//')'
        end if
        if (len_trim(text) > 0) why = trim(why)//'; '//trim(text)
    end procedure symplectic_fits

    !> The width of the implicit methods' Newton matrix (the reduced second-order one when
    !! the problem has the structure, else the first-order one; dense: all its rows) over
    !! the RFEM's, at least 1; and the cost of an MEBDF evaluation of f, which for a problem
    !! with a mass matrix includes M(q) v (see Cost).
    subroutine newton_widths(problem, lambda, eval_cost)
        class(problem_t), intent(in) :: problem
        real(wp), intent(out) :: lambda, eval_cost
        integer, allocatable :: pos(:), vel(:)
        integer :: np, kl, ku, width
        call problem%second_order_layout(pos, vel, kl, ku)
        np = size(pos)
        if (np == 0) then
            np = problem%size()
            call problem%bandwidths(kl, ku)
        end if
        kl = min(max(kl, 0), np - 1)
        ku = min(max(ku, 0), np - 1)
        width = kl + ku + 1
        if (factored_dense(np, kl, ku)) width = np
        lambda = max(1.0_wp, real(width, wp)/REFERENCE_WIDTH)
        eval_cost = 1.0_wp
        if (problem%has_mass_matrix()) eval_cost = 1.0_wp + MASS_COST*real(width, wp)
    end subroutine newton_widths

    !> A step the implicit method may take at the start, by accuracy alone: sqrt(2 / |y''|)
    !! in the error weights (|y''| from a difference of f along f over h_probe), the
    !! step of a first-order method with a local error of one tolerance unit (CVODE's
    !! first-step estimate). 0 when f fails; huge when y'' is 0.
    real(wp) function accuracy_step(problem, t, y, options, h_probe) result(h)
        class(problem_t), intent(inout) :: problem
        real(wp), intent(in) :: t, y(:), h_probe
        type(solver_options_t), intent(in) :: options
        real(wp), allocatable :: w(:), f0(:), f1(:)
        real(wp) :: d2
        integer :: status
        h = 0.0_wp
        if (h_probe <= 0.0_wp) return
        allocate (w(size(y)), f0(size(y)), f1(size(y)))
        w = error_weights(options, y)
        call problem%rhs(t, y, f0, status)
        if (status /= STATUS_OK) return
        call problem%rhs(t + h_probe, y + h_probe*f0, f1, status)
        if (status /= STATUS_OK) return
        d2 = sqrt(sum(((f1 - f0)/w)**2)/size(y))/h_probe
        h = huge(1.0_wp)
        if (d2 > 0.0_wp) h = sqrt(2.0_wp/d2)
    end function accuracy_step

    !> MEBDF's maximum order for fast modes damped by `zeta` (clipped at 0).
    pure integer function mebdf_order_for(zeta) result(order)
        real(wp), intent(in) :: zeta
        if (zeta < MEBDF_A_STABLE_DAMPING) then
            order = 4
        else if (zeta < BDF_DAMPING) then
            order = 5
        else
            order = 6
        end if
    end function mebdf_order_for
end submodule ropedyn_auto_start
