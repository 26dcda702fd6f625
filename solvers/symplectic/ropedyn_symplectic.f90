!> A symplectic splitting method (`method = 'symplectic'`) for mechanical problems with a
!! constant diagonal mass matrix (problem_t's force split; the RFEM offers it): Stormer-
!! Verlet (order 2) or a 4th-order composition (Blanes & Moan's, or Chin's with a force-
!! gradient kick; ropedyn_split_tables) for the forces of the potential, the other forces
!! (damping, drag, loads) between the steps. The derivation, the choice of the step and the
!! measurements are in docs/theory/symplectic.md.
!!
!! - **Step** (Strang splitting, processed): from (q_n, v_n), with the forces at q_n known
!!   from the previous step, v += (h/2) a_r (the second half of the D-map at q_n); the
!!   composition's kicks v += b_i h a_c(t_i, q) and drifts q += a_i h v, t += a_i h; at
!!   q_n+1 one evaluation gives a_c and, at a predicted velocity v~ (the velocity after
!!   the last kick plus (h/2) a_r, both taken from the most recent forces: O(h^2) off),
!!   a_r; then the last kick and v += (h/2) a_r (the first half of the next D-map). Without
!!   other forces this is the composition itself, symplectic and time-reversible; a step
!!   costs `stages` evaluations of the forces (1 for Verlet), and one more for each
!!   force-gradient kick (gradient_force: Chin's middle kick).
!! - **Energy balance**: a D-map changes v at fixed q, t, so it changes only T, by exactly
!!   dT = m d . (v + d/2), d = (h/2) a_r: the quadratures of energy put in (external work)
!!   advance by their rates (h/2) g_r, and the one of energy taken out (dissipated) by what
!!   closes the balance, work - dT (problem_t's split_layout gives the signs). A kick at a
!!   potential that depends on time advances the work by b_i h g_c (the p_t-kick of the
!!   extended phase space). So T + V + dissipated - work changes only in the composition's
!!   steps on the potential, whose energy error is bounded (a modified energy is
!!   conserved), not in the D-maps: the balance error stays bounded, with or without
!!   damping, instead of drifting as an adaptive method's does.
!! - **Step size** (choose_step): fixed, a safety factor times the stable step of the
!!   composition for the fast modes of the spectrum estimate (ropedyn_spectrum: modulus and
!!   damping of each Ritz value; ropedyn_split_tables: stable h w at each damping), shorter
!!   below the tolerance that step reaches; fitted so that the first output interval is a
!!   whole number of steps (the outputs then fall on steps; between steps the state is a
!!   cubic Hermite interpolation, the steps go on undisturbed). The spectrum is estimated
!!   again at an output time after RESPECTRUM_STEPS steps (doubled up to RESPECTRUM_MAX
!!   while the step stays), and the step changed when it must shrink or may grow by
!!   GROW_AT. The composition: whichever is cheapest per simulated second at its step; a
!!   4th-order one where the fast modes are lightly damped (their energy stays, and
!!   Verlet's error on it is 100 times larger).
!! - **Failures**: a force evaluation that is not finite (an unstable step) restarts the
!!   output interval from its start at half the step, up to MAX_RETRIES times (then the
!!   method fails, its state the one at that start, whose forces were finite); a step that
!!   would take more than STIFF_STEP_RATE steps per simulated second ends the run with the
!!   diagnosis erk gives (naming auto and mebdf); a run to options%t_end that takes more
!!   steps at the step chosen than the budget has left ends at once, at the start or where
!!   the step shortens (budget_reaches_end), naming the steps and the budget to add; the
!!   problem must offer the force split (else `init` says why not).
module ropedyn_symplectic
    use ropedyn_kinds, only: wp, i8
    use ropedyn_text, only: int_text, real_text, significant_text, es_text
    use ropedyn_sums, only: sum_products
    use ropedyn_error, only: error_t, make_error, ERR_SOLVER
    use ropedyn_problem, only: problem_t, STATUS_OK, STATUS_FATAL
    use ropedyn_integrator, only: integrator_t, start_t, solver_stats_t, stop_now, &
                                  STIFF_STEP_RATE, steps_to_end, budget_covering, &
                                  integrator_budget_shortfall
    use ropedyn_spectrum, only: spectrum_t, estimate_spectrum, LIGHT_DAMPING, FAST_FRACTION
    use ropedyn_switch_log, only: switch_log_t, switch_event_t
    use ropedyn_split_tables, only: split_table_t, split_table, TABLE_VERLET, TABLE_BM6, &
                                    TABLE_CHIN, OVERDAMPED_LIMIT
    implicit none
    private
    public :: symplectic_t, split_stable_step, choose_step, TABLE_VERLET, TABLE_BM6, TABLE_CHIN

    !> the step over the stable step where the mode that limits it is lightly damped: the
    !! combination frequencies of such modes (up to twice the fastest) near the stability
    !! limit feed an energy drift. On the undamped paper rope at rtol 1e-3 SRKN_6^b drifted
    !! over 300 s at 0.55 (n = 20); Chin's 4A over 1000 s at this factor and at others:
    !! scripts/symplectic_factors, whose table is in docs/theory/symplectic.md ("The step")
    real(wp), parameter :: RESONANT_SAFETY = 0.35_wp
    !> where the fast modes are lightly damped, the relative energy error of an undamped mode
    !! at the spectral radius (the spread of its energy along the numerical orbit) over rtol
    !! at most: they hold a tenth of the energy or less (the elastic energy of the undamped
    !! paper rope reached 13 % of m g L over 300 s at n = 20), so that the balance stays
    !! within about rtol times the energy (docs/theory/symplectic.md, "The step")
    real(wp), parameter :: FAST_SPREAD_PER_RTOL = 10.0_wp
    !> A step's work besides its evaluations of the potential's forces, in such
    !! evaluations (choose_step compares the compositions by their evaluations plus this,
    !! per simulated second): STEP_WORK for the kicks, drifts and checks; REST_WORK more
    !! when the problem has forces outside the potential (their evaluation, once a step, and
    !! the D-maps with their quadratures). Measured on the paper's rope, n = 20 and 30
    !! (docs/theory/symplectic.md, "The step"): undamped, a step of SRKN_6^b (6 evaluations)
    !! took 2.57 us and one of Chin's 4A (3) 1.37 us, so 0.40 us an evaluation and 0.17 us
    !! the rest of a step (2.00 and 1.06 us, 0.31 and 0.12 us, once the D-maps were skipped
    !! without rest forces); damped (callgrind), an evaluation of the potential's forces
    !! 6.0k instructions, one with the rest's 10.8k, a step of Chin's 4A 32k
    real(wp), parameter :: STEP_WORK = 0.5_wp, REST_WORK = 1.8_wp
    !> steps between estimates of the spectrum (at an output time): at first, and at most
    !! (doubled after each estimate that leaves the step as it is)
    integer(i8), parameter :: RESPECTRUM_STEPS = 2000, RESPECTRUM_MAX = 64000
    !> the step grows only when the new target is this much longer
    real(wp), parameter :: GROW_AT = 1.25_wp
    !> restarts of an output interval at half the step after a non-finite force
    integer, parameter :: MAX_RETRIES = 4
    !> a gradient kick's difference over GRADIENT_SHIFT times its shift g h^2 a_c: the
    !! non-gradient part of the force made that much smaller than with the plain shifted
    !! force a_c(q + g h^2 a_c), the rounding of the difference still 1e-12 of the
    !! correction (docs/theory/symplectic.md, "One step")
    real(wp), parameter :: GRADIENT_SHIFT = 1.0e-2_wp

    type, extends(integrator_t) :: symplectic_t
        private
        type(split_table_t) :: tab
        type(solver_stats_t) :: counters
        type(switch_log_t) :: log
        integer :: np = 0                      !< coordinates
        integer, allocatable :: pos(:), vel(:)
        real(wp), allocatable :: mass(:)       !< of the coordinates
        integer, allocatable :: signs(:)       !< the quadratures' signs in the balance
        integer :: closing = 0                 !< the quadrature that closes the balance
        !> the problem has forces outside the potential (problem_t's split_has_rest); without
        !! them a_r = 0, g_r = 0 and the D-maps are the identity, so neither is computed
        logical :: rest = .true.
        ! the grid: t = t_base + k h
        real(wp) :: t_base = 0.0_wp
        real(wp) :: h = 0.0_wp
        integer(i8) :: k = 0
        real(wp) :: t = 0.0_wp
        !> the state at t and the forces there (a_r, g_r at the predicted velocity)
        real(wp), allocatable :: q(:), v(:), yq(:), ac(:), ar(:), gc(:), gr(:)
        !> the previous grid point, for the dense output
        real(wp) :: t_old = 0.0_wp
        real(wp), allocatable :: q_old(:), v_old(:), a_old(:), yq_old(:)
        real(wp), allocatable :: y(:)          !< the problem's state, work
        real(wp), allocatable :: vt(:)         !< the predicted velocity, work
        real(wp), allocatable :: mar(:)        !< m a_r, the force of the rest
        !> a gradient kick's q, a_c and g_c before the shift, work
        real(wp), allocatable :: q_keep(:), a_keep(:), g_keep(:)
        logical :: started = .false.
        !> the state handed out last was the grid point at t (not an interpolation)
        logical :: on_grid = .true.
        integer(i8) :: estimated_at = 0        !< steps at the last spectrum estimate
        integer(i8) :: respectrum = RESPECTRUM_STEPS  !< steps to the next
        real(wp) :: radius = 0.0_wp            !< spectral radius of that estimate, 1/s
        real(wp) :: h_stable = 0.0_wp          !< the composition's stable step there, s
        real(wp) :: fast_damping = 0.0_wp
        integer :: order_limit = 4
        real(wp) :: fixed_h = 0.0_wp           !< fix_step's step (0: the rule's)
        real(wp) :: h_rule = 0.0_wp            !< the rule's step before fitting, s
        !> the run ended because its steps to t_end outnumber the budget left
        logical :: budget_short = .false.
        !> an estimate of the spectrum found lightly damped fast modes (choose_step's
        !! stay_light from then on)
        logical :: light_seen = .false.
        !> the run ended because the forces reported a fatal error (no method can go on)
        logical :: fatal = .false.
    contains
        procedure :: start => symplectic_start
        procedure :: advance_to => symplectic_advance_to
        procedure :: stats => symplectic_stats
        procedure :: finalize => symplectic_finalize
        procedure :: name => symplectic_name
        procedure :: switch_log => symplectic_switch_log
        procedure :: step_size => symplectic_step_size
        procedure :: fix_step => symplectic_fix_step
        procedure :: budget_shortfall => symplectic_budget_shortfall
        procedure, private :: steps_left => symplectic_steps_left
        procedure :: failed_fatally => symplectic_failed_fatally
        procedure :: refusal => symplectic_refusal
        procedure, private :: begin
        procedure, private :: review_step
        procedure, private :: set_step
        procedure, private :: budget_reaches_end
        procedure, private :: step
        procedure, private :: evaluate
        procedure, private :: gradient_force
        procedure, private :: dmap
        procedure, private :: dense
        procedure, private :: failure
    end type symplectic_t

    interface
        !> The first step size (from the spectrum at the initial state) and the forces there
        !! (submodule ropedyn_symplectic_steps, as the rest of the step-size choice).
        module subroutine begin(self, tout, err)
            class(symplectic_t), intent(inout) :: self
            real(wp), intent(in) :: tout
            type(error_t), allocatable, intent(out) :: err
        end subroutine begin

        !> The spectrum at the current state again; the step changed when it must shrink or
        !! may grow by GROW_AT (the interval to tout from here a whole number of steps).
        module subroutine review_step(self, tout, err)
            class(symplectic_t), intent(inout) :: self
            real(wp), intent(in) :: tout
            type(error_t), allocatable, intent(out) :: err
        end subroutine review_step

        !> The step from now on: `h` at most, fitted so that the interval to tout is a whole
        !! number of steps; the change logged (as a warning when `warn`).
        module subroutine set_step(self, h, tout, reason, warn)
            class(symplectic_t), intent(inout) :: self
            real(wp), intent(in) :: h, tout
            character(len=*), intent(in) :: reason
            logical, intent(in) :: warn
        end subroutine set_step

        !> The run ends at once (ERR_SOLVER) when its rest, to options%t_end, takes more
        !! steps at the step rule than the step budget has left.
        module subroutine budget_reaches_end(self, err)
            class(symplectic_t), intent(inout) :: self
            type(error_t), allocatable, intent(out) :: err
        end subroutine budget_reaches_end

        !> The composition and its step for a spectrum estimate, a tolerance and an order
        !! limit (ropedyn_symplectic_steps, where the rule is); `rest`: the problem has
        !! forces outside the potential (problem_t's split_has_rest); `light`: the mode that
        !! limits the step is lightly damped (below LIGHT_DAMPING); `cost`: the step's work
        !! per simulated second, in evaluations of the potential's forces (step_cost over h);
        !! `h_stable`: the stable step of the composition taken; h = 0: no estimate.
        module subroutine choose_step(spec, rtol, max_order, rest, tab, h, light, text, cost, &
                                      stay_light, h_stable)
            type(spectrum_t), intent(in) :: spec
            real(wp), intent(in) :: rtol
            integer, intent(in) :: max_order
            logical, intent(in) :: rest
            type(split_table_t), intent(out) :: tab
            real(wp), intent(out) :: h
            logical, intent(out) :: light
            character(len=*), intent(out) :: text
            real(wp), intent(out), optional :: cost
            !> an earlier estimate of this run found lightly damped fast modes: take them as
            !! such again (the damping of the settled Ritz values varies from one estimate to
            !! the next, and each change between Verlet and a 4th-order composition moves the
            !! modified energy)
            logical, intent(in), optional :: stay_light
            real(wp), intent(out), optional :: h_stable
        end subroutine choose_step

        !> The largest step (s) at which the composition `tab` is stable for every fast Ritz
        !! value of `spec` (|lambda| >= radius/10), each taken as a damped oscillator with
        !! w = |lambda| and zeta = -Re(lambda)/|lambda| (a real lambda < 0: damping alone,
        !! h |lambda| <= OVERDAMPED_LIMIT; a Ritz value in the right half plane: undamped).
        !! 0 when there is no estimate.
        pure module subroutine split_stable_step(tab, spec, h, zeta_limit)
            type(split_table_t), intent(in) :: tab
            type(spectrum_t), intent(in) :: spec
            real(wp), intent(out) :: h
            !> the damping ratio of the Ritz value that limits h (1 for a real one)
            real(wp), intent(out), optional :: zeta_limit
        end subroutine split_stable_step
    end interface

    !> A copy of the stepping state (a restart of an output interval).
    type :: snapshot_t
        real(wp) :: t_base, h, t
        integer(i8) :: k
        real(wp), allocatable :: q(:), v(:), yq(:), ac(:), ar(:), gc(:), gr(:)
    end type snapshot_t

contains

    pure function symplectic_name(self) result(name)
        class(symplectic_t), intent(in) :: self
        character(len=:), allocatable :: name
        name = 'symplectic'
    end function symplectic_name

    function symplectic_switch_log(self) result(events)
        class(symplectic_t), intent(in) :: self
        type(switch_event_t), allocatable :: events(:)
        events = self%log%items()
    end function symplectic_switch_log

    !> The step in use (s; 0 before the first advance_to).
    pure real(wp) function symplectic_step_size(self) result(h)
        class(symplectic_t), intent(in) :: self
        h = self%h
    end function symplectic_step_size

    !> Use the composition `table` (TABLE_VERLET, TABLE_BM6 or TABLE_CHIN) at the step h (s) for the
    !! whole run instead of the rule (tests, studies); call after init, before the first
    !! advance_to.
    subroutine symplectic_fix_step(self, table, h)
        class(symplectic_t), intent(inout) :: self
        integer, intent(in) :: table
        real(wp), intent(in) :: h
        self%tab = split_table(table)
        self%fixed_h = h
    end subroutine symplectic_fix_step

    !> Why the method cannot integrate `problem` ('' when it can): it needs the force split
    !! (a constant diagonal mass matrix, forces from a potential and the rest) and a state of
    !! coordinates and their rates alone.
    function symplectic_refusal(self, problem) result(why)
        class(symplectic_t), intent(in) :: self
        class(problem_t), intent(in) :: problem
        character(len=:), allocatable :: why
        integer, allocatable :: pos(:), vel(:)
        integer :: kl, ku
        why = problem%force_split_refusal()
        if (len(why) > 0 .and. problem%has_mass_matrix()) why = 'the mass matrix '// &
            'depends on the state, which no explicit symplectic method integrates '// &
            '(docs/theory/symplectic.md, "The MPP")'
        if (len(why) == 0 .and. .not. problem%has_second_order()) &
            why = 'the problem has no coordinates and rates'
        if (len(why) == 0) then
            call problem%second_order_layout(pos, vel, kl, ku)
            if (2*size(pos) /= problem%size()) why = 'the problem has unknowns other than '// &
                'coordinates and their rates'
        end if
    end function symplectic_refusal

    subroutine symplectic_start(self, start, err)
        class(symplectic_t), intent(inout) :: self
        type(start_t), intent(in) :: start
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: why
        integer :: kl, ku, j

        why = self%refusal(self%problem)
        if (len(why) > 0) then
            call make_error(err, ERR_SOLVER, 'symplectic: cannot integrate this problem: '// &
                            why//' (use method = ''auto'' or ''erk'')')
            return
        end if
        call self%problem%second_order_layout(self%pos, self%vel, kl, ku)
        self%np = size(self%pos)
        allocate (self%mass(self%np), self%signs(self%nq))
        call self%problem%split_layout(self%mass, self%signs)
        self%closing = 0
        do j = 1, self%nq
            if (self%signs(j) == -1) then
                self%closing = j
                exit
            end if
        end do
        self%y = start%y0
        self%q = start%y0(self%pos)
        self%v = start%y0(self%vel)
        self%yq = start%yq0
        allocate (self%ac(self%np), self%ar(self%np), self%vt(self%np), self%mar(self%np), &
                  self%gc(self%nq), self%gr(self%nq), self%q_keep(self%np), &
                  self%a_keep(self%np), self%g_keep(self%nq))
        self%rest = self%problem%split_has_rest()
        self%ar = 0.0_wp
        self%gr = 0.0_wp
        self%mar = 0.0_wp
        self%q_old = self%q
        self%v_old = self%v
        self%a_old = 0.0_wp*self%q
        self%yq_old = self%yq
        self%t = start%t0
        self%t_old = start%t0
        self%t_base = start%t0
        self%k = 0
        self%h = 0.0_wp
        self%started = .false.
        self%on_grid = .true.
        self%order_limit = start%max_order
        self%respectrum = RESPECTRUM_STEPS
        self%fixed_h = 0.0_wp
        self%budget_short = .false.
        self%light_seen = .false.
        self%fatal = .false.
        self%tab = split_table(merge(TABLE_BM6, TABLE_VERLET, start%max_order >= 4))
        self%counters = solver_stats_t()
        call self%log%clear()
    end subroutine symplectic_start

    subroutine symplectic_advance_to(self, tout, t, y, yq, err)
        class(symplectic_t), intent(inout) :: self
        real(wp), intent(in) :: tout
        real(wp), intent(out) :: t
        real(wp), intent(inout) :: y(:)
        real(wp), intent(inout) :: yq(:)
        type(error_t), allocatable, intent(out) :: err
        type(snapshot_t) :: snap
        integer :: status, retries
        real(wp) :: tol

        t = self%t
        if (.not. associated(self%problem)) then
            call make_error(err, ERR_SOLVER, 'symplectic: advance_to called before init')
            return
        end if
        if (tout <= self%t .and. .not. self%started) then
            call self%dense(self%t, y, yq)
            return
        end if
        if (self%started .and. tout < self%t_old - 1.0e-7_wp*self%h) then
            call make_error(err, ERR_SOLVER, 'symplectic: output time lies before the last step')
            return
        end if
        if (.not. self%started) then
            call self%begin(tout, err)
        else if (self%counters%steps - self%estimated_at >= self%respectrum .and. &
                 self%on_grid) then
            call self%review_step(tout, err)
        end if
        if (allocated(err)) return
        call fit_to_output(self, tout)
        snap = snapshot_t(self%t_base, self%h, self%t, self%k, self%q, self%v, self%yq, &
                          self%ac, self%ar, self%gc, self%gr)
        retries = 0
        tol = 1.0e-7_wp*self%h
        do while (self%t < tout - tol)
            if (self%counters%steps >= self%options%max_steps) then
                call self%failure(err, self%steps_exhausted(self%t))
                exit
            end if
            ! (the state before the step is kept only where the dense output may need it)
            call self%step(status, self%t_base + real(self%k + 1, wp)*self%h > tout - tol)
            if (status == STATUS_FATAL) then
                self%fatal = .true.
                call self%failure(err, 'the forces reported a fatal error')
                exit
            else if (status /= STATUS_OK) then
                ! not finite: the step was unstable; the interval again at half the step
                retries = retries + 1
                call restore(self, snap)
                if (retries > MAX_RETRIES) then
                    ! (the state handed back: the last one whose forces were finite)
                    call self%failure(err, 'the forces are not finite (NaN or Inf) even at '// &
                                      'the step halved '//int_text(MAX_RETRIES)//' times: '// &
                                      'the motion had become unstable before this output '// &
                                      'interval (the energy balance of the records shows '// &
                                      'where); a tighter rtol (a shorter step) or method = '// &
                                      '''auto'' avoids it')
                    exit
                end if
                call self%set_step(0.5_wp*self%h, tout, 'the forces were not finite '// &
                                   '(an unstable step): the output interval again at half '// &
                                   'the step', .true.)
                tol = 1.0e-7_wp*self%h
                cycle
            end if
            if (self%t < tout - tol .and. stop_now(self%options)) exit
        end do
        if (allocated(err) .or. self%t < tout - tol) then
            ! failed or stopped early: the state at the last step
            call self%dense(self%t, y, yq)
            t = self%t
            self%on_grid = .true.
            return
        end if
        self%on_grid = abs(self%t - tout) <= tol
        if (self%on_grid .and. self%t /= tout) then
            ! the grid restarts at the output's time: else its rounding goes into the step
            ! fitted at the next change (span tout - t), the grid drifts off the outputs by
            ! more at each change, and once past tol the outputs are interpolated and the
            ! spectrum is never estimated again (review_step waits for an output on the grid)
            self%t = tout
            self%t_base = tout
            self%k = 0
        end if
        if (self%on_grid) then
            call self%dense(self%t, y, yq)
        else
            call self%dense(tout, y, yq)
        end if
        t = tout
    end subroutine symplectic_advance_to

    !> The output time tout a whole number of steps from t (to 1e-6 of a step): else the
    !! step is fitted to it (after a switch to this method, or a last output off the
    !! interval: once or twice, then every output falls on a step).
    subroutine fit_to_output(self, tout)
        class(symplectic_t), intent(inout) :: self
        real(wp), intent(in) :: tout
        real(wp) :: steps, target
        if (self%fixed_h > 0.0_wp .or. tout <= self%t .or. self%h <= 0.0_wp) return
        steps = (tout - self%t)/self%h
        if (abs(steps - anint(steps)) <= 1.0e-6_wp*max(1.0_wp, steps)) return
        target = self%h_rule
        if (target <= 0.0_wp) target = self%h
        self%h = (tout - self%t)/real(ceiling((tout - self%t)/target*(1.0_wp - 1.0e-12_wp)), wp)
        self%t_base = self%t
        self%k = 0
    end subroutine fit_to_output

    !> The stepping state as it was at the snapshot.
    subroutine restore(self, snap)
        class(symplectic_t), intent(inout) :: self
        type(snapshot_t), intent(in) :: snap
        self%t_base = snap%t_base
        self%h = snap%h
        self%t = snap%t
        self%k = snap%k
        self%q = snap%q
        self%v = snap%v
        self%yq = snap%yq
        self%ac = snap%ac
        self%ar = snap%ar
        self%gc = snap%gc
        self%gr = snap%gr
    end subroutine restore

    !> One step from t to t + h (the module header); status not OK: the state is not usable.
    subroutine step(self, status, keep_old)
        class(symplectic_t), intent(inout) :: self
        integer, intent(out) :: status
        !> keep the state before the step for the dense output (the last step to an output)
        logical, intent(in) :: keep_old
        real(wp) :: h, ti, t_new
        integer :: i, s
        h = self%h
        s = self%tab%stages
        if (keep_old) then
            self%t_old = self%t
            self%q_old = self%q
            self%v_old = self%v
            self%a_old = self%ac + self%ar
            self%yq_old = self%yq
        end if
        t_new = self%t_base + real(self%k + 1, wp)*h
        if (self%rest) call self%dmap(0.5_wp*h)
        ti = self%t
        do i = 1, s
            if (i > 1) then
                call self%evaluate(ti, status, full=.false.)
                if (status /= STATUS_OK) return
            end if
            if (self%tab%grad(i) /= 0.0_wp) then
                call self%gradient_force(ti, self%tab%grad(i)*h*h, status)
                if (status /= STATUS_OK) return
            end if
            self%v = self%v + (self%tab%b(i)*h)*self%ac
            if (self%nq > 0) self%yq = self%yq + (self%tab%b(i)*h)*self%gc
            self%q = self%q + (self%tab%a(i)*h)*self%v
            ti = ti + self%tab%a(i)*h
        end do
        ! the predicted velocity: after the last kick and half the D-map, from the most
        ! recent forces
        if (self%rest) self%vt = self%v + (self%tab%b(s + 1)*h)*self%ac + (0.5_wp*h)*self%ar
        call self%evaluate(t_new, status, full=.true.)
        if (status /= STATUS_OK) return
        self%v = self%v + (self%tab%b(s + 1)*h)*self%ac
        if (self%nq > 0) self%yq = self%yq + (self%tab%b(s + 1)*h)*self%gc
        if (self%rest) call self%dmap(0.5_wp*h)
        self%k = self%k + 1
        self%t = t_new
        self%counters%steps = self%counters%steps + 1
        self%counters%last_step = h
        self%counters%last_order = self%tab%order
        self%counters%order_steps(self%tab%order) = &
            self%counters%order_steps(self%tab%order) + 1
    end subroutine step

    !> The force of a gradient kick at (tt, q) into (ac, gc), from those at q already there:
    !! a + g2 (da/dq) a, the directional derivative by a difference over the shift
    !! GRADIENT_SHIFT g2 a (and the same for gc, the p_t-kick of a potential that depends on
    !! time). With the exact derivative the kick is that of a modified potential, so the step
    !! stays symplectic; the difference departs from it by O(GRADIENT_SHIFT).
    subroutine gradient_force(self, tt, g2, status)
        class(symplectic_t), intent(inout) :: self
        real(wp), intent(in) :: tt, g2
        integer, intent(out) :: status
        integer :: j
        do j = 1, self%np
            self%q_keep(j) = self%q(j)
            self%a_keep(j) = self%ac(j)
            self%q(j) = self%q(j) + (GRADIENT_SHIFT*g2)*self%ac(j)
        end do
        if (self%nq > 0) self%g_keep = self%gc
        call self%evaluate(tt, status, full=.false.)
        do j = 1, self%np
            self%q(j) = self%q_keep(j)
            self%ac(j) = self%a_keep(j) + (self%ac(j) - self%a_keep(j))/GRADIENT_SHIFT
        end do
        if (self%nq > 0) self%gc = self%g_keep + (self%gc - self%g_keep)/GRADIENT_SHIFT
    end subroutine gradient_force

    !> The forces at (tt, q): the potential's (ac, gc) and, when `full` and the problem has
    !! them, the rest's (ar, gr) at the predicted velocity vt.
    subroutine evaluate(self, tt, status, full)
        class(symplectic_t), intent(inout) :: self
        real(wp), intent(in) :: tt
        integer, intent(out) :: status
        logical, intent(in) :: full
        integer :: j
        ! (loops: an assignment through a vector subscript made a temporary, a malloc and a
        ! copy per evaluation)
        do j = 1, self%np
            self%y(self%pos(j)) = self%q(j)
        end do
        if (full .and. self%rest) then
            do j = 1, self%np
                self%y(self%vel(j)) = self%vt(j)
            end do
            call self%problem%split_rhs(tt, self%y, self%ac, self%gc, status, self%ar, self%gr)
            self%mar = self%mass*self%ar
        else
            call self%problem%split_rhs(tt, self%y, self%ac, self%gc, status)
        end if
        self%counters%rhs_evals = self%counters%rhs_evals + 1
    end subroutine evaluate

    !> The D-map over hh at fixed q, t: v += hh a_r; the quadratures of work by their rates,
    !! the closing one by the exact change of T, hh (m a_r) . (v + hh a_r / 2) (the module
    !! header).
    subroutine dmap(self, hh)
        class(symplectic_t), intent(inout) :: self
        real(wp), intent(in) :: hh
        real(wp) :: dt_kin, rest
        integer :: j
        if (self%nq == 0) then
            self%v = self%v + hh*self%ar
            return
        end if
        self%vt = self%v + (0.5_wp*hh)*self%ar
        dt_kin = hh*sum_products(self%mar, self%vt)
        self%v = self%v + hh*self%ar
        ! (no work array: an automatic one was a malloc per D-map)
        rest = 0.0_wp
        do j = 1, self%nq
            if (j == self%closing) cycle
            rest = rest + self%signs(j)*(hh*self%gr(j))
            self%yq(j) = self%yq(j) + hh*self%gr(j)
        end do
        if (self%closing > 0) self%yq(self%closing) = self%yq(self%closing) + &
            (dt_kin - rest)/real(self%signs(self%closing), wp)
    end subroutine dmap

    !> The state at tt in [t_old, t]: the grid point itself, or the cubic Hermite
    !! interpolation of q (with v) and of v (with a = a_c + a_r), the quadratures linear.
    subroutine dense(self, tt, y, yq)
        class(symplectic_t), intent(inout) :: self
        real(wp), intent(in) :: tt
        real(wp), intent(inout) :: y(:), yq(:)
        real(wp) :: dt, s, h00, h10, h01, h11
        if (tt >= self%t .or. self%t <= self%t_old) then
            self%y(self%pos) = self%q
            self%y(self%vel) = self%v
            y = self%y
            if (self%nq > 0) yq(1:self%nq) = self%yq
            return
        end if
        dt = self%t - self%t_old
        s = (tt - self%t_old)/dt
        h00 = (1.0_wp + 2.0_wp*s)*(1.0_wp - s)**2
        h10 = s*(1.0_wp - s)**2
        h01 = s**2*(3.0_wp - 2.0_wp*s)
        h11 = s**2*(s - 1.0_wp)
        y(self%pos) = h00*self%q_old + h10*dt*self%v_old + h01*self%q + h11*dt*self%v
        y(self%vel) = h00*self%v_old + h10*dt*self%a_old + h01*self%v + &
                      h11*dt*(self%ac + self%ar)
        if (self%nq > 0) yq(1:self%nq) = (1.0_wp - s)*self%yq_old + s*self%yq
    end subroutine dense

    subroutine failure(self, err, cause)
        class(symplectic_t), intent(in) :: self
        type(error_t), allocatable, intent(out) :: err
        character(len=*), intent(in) :: cause
        character(len=96) :: buffer
        write (buffer, '(a, a, a, es11.3e3, a, i0)') 't = ', es_text(self%t, 12, 5), &
            ' s, step size ', self%h, ' s, order ', self%tab%order
        call make_error(err, ERR_SOLVER, 'symplectic failed at '//trim(buffer)//': '//cause)
    end subroutine failure

    !> As every method's (integrator_t), and when the run ended at a step whose count to
    !! t_end outnumbers the budget (budget_reaches_end), that count.
    function symplectic_budget_shortfall(self, t) result(rest)
        class(symplectic_t), intent(in) :: self
        real(wp), intent(in) :: t
        integer(i8) :: rest
        rest = integrator_budget_shortfall(self, t)
        if (self%budget_short) rest = max(1_i8, self%steps_left(t))
    end function symplectic_budget_shortfall

    !> The steps from t to options%t_end at the step in use: the rule's, shortened so that an
    !! output interval is a whole number of steps (set_step; an interval of m rule steps and
    !! a fraction takes m + 1). That is what the run takes when its outputs are evenly spaced
    !! and t_end is on them (the rounding of the fit adds no step there); the count at the
    !! rule's step is short by up to one step an interval.
    integer(i8) function symplectic_steps_left(self, t) result(steps)
        class(symplectic_t), intent(in) :: self
        real(wp), intent(in) :: t
        steps = steps_to_end(t, self%options%t_end, self%h*(1.0_wp + 1.0e-12_wp))
    end function symplectic_steps_left

    !> The run ended because the forces reported a fatal error (not for want of steps, nor
    !! at a step that was unstable or too short): no other method can go on from there.
    pure logical function symplectic_failed_fatally(self) result(fatal)
        class(symplectic_t), intent(in) :: self
        fatal = self%fatal
    end function symplectic_failed_fatally

    function symplectic_stats(self) result(stats)
        class(symplectic_t), intent(in) :: self
        type(solver_stats_t) :: stats
        stats = self%counters
    end function symplectic_stats

    subroutine symplectic_finalize(self)
        class(symplectic_t), intent(inout) :: self
        self%problem => null()
        if (allocated(self%mass)) deallocate (self%mass, self%signs)
        if (allocated(self%q)) deallocate (self%q, self%v, self%yq)
        if (allocated(self%ac)) deallocate (self%ac, self%ar, self%gc, self%gr, self%vt, self%mar)
        if (allocated(self%q_keep)) deallocate (self%q_keep, self%a_keep, self%g_keep)
        if (allocated(self%q_old)) deallocate (self%q_old, self%v_old, self%a_old, self%yq_old)
        if (allocated(self%y)) deallocate (self%y)
        if (allocated(self%pos)) deallocate (self%pos, self%vel)
        self%started = .false.
    end subroutine symplectic_finalize
end module ropedyn_symplectic
