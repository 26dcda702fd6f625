!> `method = 'auto'` (the default): an explicit, an Adams or an implicit integrator,
!! whichever is cheaper on the scene at the time, switched during the run as LSODA switches
!! Adams and BDF.
!!
!! - **The methods**: `erk` (ropedyn_erk, RK4 with a 3rd-order estimate: the longest
!!   stability interval on the imaginary axis per evaluation of f of the bundled pairs),
!!   `adams` (below) and an implicit method: `mebdf` when the fastest modes are barely
!!   damped (below BDF_DAMPING: its order 4 is A-stable, BDF's orders 3 .. 5 are not and
!!   can amplify such modes), else `cvode` (BDF up to order 5, a cheaper step: on the
!!   elements_1000 .. 10000 scenes, fast modes damped by >= 12 %, CVODE took 1.5 .. 2.8
!!   times less CPU than MEBDF at the order auto chose for it).
!! - **Start**: a few Arnoldi steps on the Jacobian at the initial state
!!   (ropedyn_spectrum) give the spectral radius and the damping of the fastest modes. The
!!   explicit pair's stability-limited step h_e follows from them; the run starts explicit
!!   unless that step would take more than START_RATE steps per simulated second, or the
!!   motion at the start is so slow that a first-order step within the tolerance
!!   (sqrt(2 / |y''|) in the error weights, CVODE's first-step estimate, |y''| from a
!!   difference of f along f) is longer than START_ACCURACY = 5 explicit stable steps:
!!   an implicit step of order >= 1 is at least that long, and costs about 2.5 explicit
!!   steps (a rope hanging at rest, catenary: 13 x h_e; every other scene in input/ and
!!   input/hard/ is below 1, a rope released from rest at 0.001 .. 0.5). MEBDF's
!!   maximum order follows from the damping of the fast modes (A(alpha) of MEBDF,
!!   docs/theory/mebdf.md): order 4, A-stable, when a fast mode is damped by less than 3 %, order
!!   5 (A(88.4 deg)) up to BDF_DAMPING = 12 %; above, CVODE's BDF at up to order 5.
!!   `max_order` given by the user caps either; below 5 it makes the implicit method
!!   MEBDF (BDF's orders 3 and 4 are not A-stable). That is how the run's order safety
!!   lowers auto: to max_order 4 (ropedyn_methods' safe order), MEBDF at most at order 4.
!! - **Cost**: counted, not timed (runs stay reproducible): explicit, the evaluations of f;
!!   implicit, those plus IMPLICIT_STEP_COST (MEBDF) or BDF_STEP_COST (CVODE) per step
!!   for the Newton matrices, solves and vector work, FACTOR_BASE per factorization (both)
!!   and JACOBIAN_COST per Jacobian (calibrated on the paper's rope, n = 30: an MEBDF step
!!   costs its 4.1 evaluations of f plus about 6 more in the rest, a CVODE step its 1.2
!!   plus about 5; scripts/cost_model over n = 10 .. 100 and rtol 1e-2 .. 1e-8 split
!!   MEBDF's 6 into 5.3 per step and 5 per factorization: at rtol 1e-2 it makes 0.29 ..
!!   0.34 factorizations per step against 0.14 at 1e-6, and was counted 17 .. 25 % too
!!   cheap there, at n = 30 .. 100). These hold for a Newton matrix of the RFEM's row
!!   width (11, block tridiagonal); a wider one (the MPP's is dense: width = its np rows)
!!   costs more against f, which stays O(n): with
!!   lambda = width / 11 (at least 1), a step costs SOLVE_COST (lambda - 1) more for its
!!   solves, a factorization FACTOR_COST (lambda^2 - 1), a Jacobian JACOBIAN_COST lambda,
!!   and an MEBDF evaluation of a problem with a mass matrix 1 + MASS_COST width (its
!!   Newton residual multiplies by M(q), assembled in O(width) per row). Calibrated on the
!!   MPP, n = 30 / 100 / 200 (MEBDF, solver.profile, f the explicit one of erk: 2.3 / 7.4 /
!!   14.6 us): a residual with M(q) v costs 4.4 / 10.3 / 16.6 f, the solves and vector work
!!   of a step 11 / 27 / 45 f, a factorization 29 / 225 / 664 f, a Jacobian 26 / 92 /
!!   149 f. At lambda = 1 and no mass matrix the counts are those of the RFEM above.
!! - **Switching**, **Adams** and **Symplectic** (the symplectic method where the fast
!!   modes are lightly damped): the rules of `watch`, with their measurements, are in the
!!   submodule ropedyn_auto_switching.
!! Every switch (time, method, order limit, reason) goes into the switch log.
module ropedyn_auto
    use ropedyn_kinds, only: wp, i8
    use ropedyn_error, only: error_t, make_error, ERR_SOLVER
    use ropedyn_problem, only: problem_t, STATUS_OK
    use ropedyn_text, only: int_text, real_text, significant_text
    use ropedyn_integrator, only: integrator_t, start_t, solver_options_t, solver_stats_t, &
                                  BUDGET_STEP_RATE, stop_now, steps_to_end, budget_covering, &
                                  last_warning, budget_left, error_weights
    use ropedyn_erk, only: erk_t
    use ropedyn_mebdf, only: mebdf_t
    use ropedyn_cvode, only: cvode_t, adams_t
    use ropedyn_erk_tables, only: erk_table_t, erk_table
    use ropedyn_spectrum, only: spectrum_t, estimate_spectrum, erk_stable_step
    use ropedyn_band_lu, only: factored_dense
    use ropedyn_switch_log, only: switch_log_t, switch_event_t, merged_events
    use ropedyn_symplectic, only: symplectic_t, choose_step
    use ropedyn_split_tables, only: split_table_t
    implicit none
    private
    public :: auto_t

    !> The methods: erk's order-4 pair, the implicit method, Adams, erk's order-5 pair, the
    !! symplectic method
    integer, parameter :: EXPLICIT = 1, IMPLICIT = 2, ADAMS = 3, HIGH = 4, SYMPLECTIC = 5
    !> What one advance of the method in use came to (run_active)
    integer, parameter :: RUN_DONE = 0, RUN_AGAIN = 1, RUN_STOPPED = 2
    !> the symplectic method for lightly damped fast modes (ropedyn_auto_switching's
    !! header, "Symplectic"): when its step costs at most this many times erk's predicted
    !! cost per simulated second, on a run at least LONG_RUN long (options%t_end)
    real(wp), parameter :: LIGHT_COST_LIMIT = 4.0_wp
    real(wp), parameter :: LONG_RUN = 5.0_wp
    !> the symplectic method's probe before auto takes it (ropedyn_auto_probe): its error
    !! over PROBE_STEPS of its steps
    integer, parameter :: PROBE_STEPS = 400
    !> the length of a reason symplectic_fits gives for taking or refusing the method
    integer, parameter :: WHY_LEN = 640
    integer, parameter :: ERK_ORDER = 4            !< the explicit pair (RK4, 3rd-order estimate)
    !> the explicit pair for stretches held by accuracy on problems without a mass matrix
    !! (Dormand-Prince 5(4))
    integer, parameter :: HIGH_ORDER = 5
    integer, parameter :: WINDOW = 400             !< steps between looks
    !> a chunk ends early once its window has taken this many windows' steps (cap_chunk:
    !! steps that collapsed within a chunk sized by time)
    integer, parameter :: OVERDUE_WINDOWS = 10
    !> an earlier first look at erk, before the implicit method's cost is known: after
    !! EARLY_WINDOW steps, when at least EARLY_SHARE of them were held by stability
    integer, parameter :: EARLY_WINDOW = 50
    real(wp), parameter :: EARLY_SHARE = 0.9_wp
    real(wp), parameter :: GAIN = 1.3_wp           !< hysteresis of a switch
    !> explicit steps per simulated second above which a run starts implicit: the rate
    !! that the default step budget allows (so that a run of any length can finish)
    real(wp), parameter :: START_RATE = BUDGET_STEP_RATE
    !> ... or when a first-order step within the tolerance at the initial state is longer
    !! than this many explicit stable steps (a rope at rest: catenary)
    real(wp), parameter :: START_ACCURACY = 5.0_wp
    real(wp), parameter :: IMPLICIT_STEP_COST = 5.3_wp  !< f-equivalents per MEBDF step
    real(wp), parameter :: BDF_STEP_COST = 5.0_wp       !< f-equivalents per CVODE step
    real(wp), parameter :: ADAMS_STEP_COST = 1.0_wp     !< f-equivalents per Adams step
    !> Adams' order limit (CVODE's own; a user's max_order caps only the implicit method)
    integer, parameter :: ADAMS_ORDER = 12
    !> damping ratio of the fastest modes from which the implicit method is CVODE's BDF
    !! (and below which MEBDF stops at order 5: mebdf_order_for)
    real(wp), parameter :: BDF_DAMPING = 0.12_wp
    !> damping ratio below which MEBDF stops at its A-stable order 4 (mebdf_order_for)
    real(wp), parameter :: MEBDF_A_STABLE_DAMPING = 0.03_wp
    integer, parameter :: BDF_ORDER = 5                 !< CVODE's order limit (its own)
    real(wp), parameter :: JACOBIAN_COST = 4.0_wp       !< f-equivalents per Jacobian
    !> the width scaling of the Newton matrix's costs (see Cost above): the RFEM's row width,
    !! f-equivalents per step and unit of lambda - 1 for MEBDF's solves (about 3.5 per step)
    !! and CVODE's (about 1.3), per factorization and unit of lambda^2 - 1, and per entry of
    !! a row of M(q) in an MEBDF evaluation of f
    real(wp), parameter :: REFERENCE_WIDTH = 11.0_wp
    real(wp), parameter :: SOLVE_COST = 1.2_wp, BDF_SOLVE_COST = 0.45_wp
    real(wp), parameter :: FACTOR_COST = 0.6_wp
    !> f-equivalents per factorization of the RFEM's band (scripts/cost_model)
    real(wp), parameter :: FACTOR_BASE = 5.0_wp
    real(wp), parameter :: MASS_COST = 0.045_wp
    !> the explicit cost predicted from the stability limit, times this (rejected steps,
    !! steps below the limit)
    real(wp), parameter :: EXPLICIT_MARGIN = 1.15_wp
    integer, parameter :: MAX_WAIT = 64            !< windows between switches, at most
    !> explicit windows after which the implicit method's, or the accuracy method's,
    !! measured cost is stale (times the cost ratio, at least 2, of each of its trials that
    !! does not pay)
    integer, parameter :: STALE_WINDOWS = 32

    type, extends(integrator_t) :: auto_t
        private
        type(erk_t) :: erk
        type(erk_t) :: erk_high            !< the order-5 pair (HIGH)
        type(mebdf_t) :: mebdf
        type(cvode_t) :: bdf
        type(adams_t) :: am
        type(symplectic_t) :: sym
        integer :: sym_order = 0           !< the symplectic method's order at its start
        !> the symplectic method's own events of its runs that ended (its init clears its
        !! log, and auto may run it again)
        type(switch_log_t) :: sym_past
        logical :: use_bdf = .false.       !< the implicit method is cvode (else mebdf)
        type(erk_table_t) :: tab
        type(erk_table_t) :: tab_high      !< the order-5 pair's
        integer :: active = 0
        integer :: mebdf_order = 4
        integer :: user_order = 0          !< max_order given (0: from the damping)
        type(solver_stats_t) :: done       !< counters of the finished segments
        type(switch_log_t) :: log
        real(wp) :: t = 0.0_wp
        real(wp), allocatable :: y(:), yq(:)
        ! the window of the method in use
        real(wp) :: win_t0 = 0.0_wp
        real(wp) :: win_cost0 = 0.0_wp
        integer(i8) :: win_steps0 = 0
        integer :: windows = 0             !< windows since the last switch
        real(wp) :: rate_explicit = -1.0_wp  !< measured cost per simulated second (< 0: none)
        real(wp) :: rate_implicit = -1.0_wp
        !> explicit windows since rate_implicit was measured, and how many make it stale
        integer :: implicit_age = 0
        integer :: stale_after = STALE_WINDOWS
        !> the method for stretches where erk's step is held by accuracy: Adams where f
        !! solves with a mass matrix, else erk's order-5 pair (HIGH)
        integer :: accurate = ADAMS
        real(wp) :: rate_accurate = -1.0_wp  !< its measured cost per simulated second
        !> explicit windows since rate_accurate was measured, and how many make it stale
        integer :: accurate_age = 0
        integer :: accurate_stale_after = STALE_WINDOWS
        !> windows of the accuracy method since rate_explicit was measured
        integer :: explicit_age = 0
        !> its cost in its last window that was not dearer than erk's by GAIN (< 0: none)
        real(wp) :: calm_accurate = -1.0_wp
        !> the method just started (the implicit or the accuracy method) is on trial
        logical :: trial = .false.
        !> windows in a row the accuracy method cost more than erk's order-4 pair by GAIN
        integer :: dearer = 0
        integer :: wait = 0                !< windows to let pass before the next switch
        integer :: backoff = 1
        logical :: initialized = .false.
        !> the symplectic method was left out once for the step budget (said once, as a
        !! warning in the log)
        logical :: budget_said = .false.
        !> the symplectic method's cost per simulated second at the last look at it, where
        !! the fast modes were lightly damped and only its cost against erk's predicted one
        !! kept it out (< 0: none): erk's measured cost may later show it cheaper
        real(wp) :: sym_cost = -1.0_wp
        !> the symplectic method's probe (ropedyn_auto_probe), with its own instance (the
        !! method's log stays that of its runs); windows of the other methods until auto
        !! may weigh the method again after a probe that failed, and how many the next
        !! failure makes it (doubled each time)
        type(symplectic_t) :: sym_probe
        integer :: sym_wait = 0
        integer :: sym_backoff = STALE_WINDOWS
        !> the symplectic method stopped during this run (its step budget, a step too short
        !! or unstable): not weighed again
        logical :: sym_barred = .false.
        !> the Newton matrix's width over the RFEM's (>= 1), and the cost of one MEBDF
        !! evaluation of f in evaluations of the explicit f (see Cost)
        real(wp) :: lambda = 1.0_wp
        real(wp) :: mebdf_eval_cost = 1.0_wp
        !> erk's stable step when it was last started from a spectrum estimate (s; 0: none)
        real(wp) :: h_stable = 0.0_wp
        !> the order-5 pair's stable step from the same estimate, where it is the accuracy
        !! method (s; 0: none)
        real(wp) :: h_stable_high = 0.0_wp
        real(wp) :: radius = 0.0_wp        !< the last estimate's spectral radius, 1/s
        !> the step that sizes a segment's first chunk, before its method has stepped (s;
        !! 0: none): the stable step h_e at the start, the step the previous method ended
        !! with after a switch (h_e when erk is restarted from a spectrum estimate)
        real(wp) :: h_chunk = 0.0_wp
    contains
        procedure :: start => auto_start
        procedure :: advance_to => auto_advance_to
        procedure :: stats => auto_stats
        procedure :: finalize => auto_finalize
        procedure :: name => auto_name
        procedure :: switch_log => auto_switch_log
        procedure :: rhs_changed => auto_rhs_changed
        procedure :: budget_shortfall => auto_budget_shortfall
        procedure :: order_in_use => auto_order_in_use
        procedure :: set_step_budget => auto_set_step_budget
        procedure, private :: start_method
        procedure, private :: watch
        procedure, private :: current_stats
        procedure, private :: active_method
        procedure, private :: cost
        procedure, private :: implicit_name
        procedure, private :: accurate_name
        procedure, private :: trials_are_cheap
        procedure, private :: symplectic_fits
        procedure, private :: probe_symplectic
        procedure, private :: add_note
    end type auto_t

    interface
        !> The spectrum at the start and the first method (submodule ropedyn_auto_start).
        module subroutine auto_start(self, start, err)
            class(auto_t), intent(inout) :: self
            type(start_t), intent(in) :: start
            type(error_t), allocatable, intent(out) :: err
        end subroutine auto_start

        !> Whether the run goes symplectic, and why (submodule ropedyn_auto_start); when it
        !! would but for the step budget, .false. with the warning to log in `why` (once,
        !! `warns`); when its probe fails, .false. with a note in `why`.
        module function symplectic_fits(self, spec, h_e, t0, why, warns, below, measured) &
            result(fits)
            class(auto_t), intent(inout) :: self
            type(spectrum_t), intent(in) :: spec
            real(wp), intent(in) :: h_e, t0
            character(len=*), intent(out) :: why
            !> `why` is a warning (printed while the run goes on), not a note
            logical, intent(out) :: warns
            !> a cost per simulated second (evaluations of f) the symplectic method must
            !! stay under (the implicit method's measured cost over GAIN, or erk's)
            real(wp), intent(in), optional :: below
            !> .true.: `below` is erk's own measured cost over GAIN, which replaces the
            !! limit against erk's predicted cost (LIGHT_COST_LIMIT)
            logical, intent(in), optional :: measured
            logical :: fits
        end function symplectic_fits

        !> Whether the symplectic method is accurate enough to take, from the state now
        !! (submodule ropedyn_auto_probe): its error after PROBE_STEPS of its steps of
        !! composition `tab` at the step h at most sqrt(PROBE_STEPS) tolerances; `text`
        !! says what the probe found. After a probe that fails, auto waits sym_wait windows
        !! before it weighs the method again.
        module subroutine probe_symplectic(self, tab, h, passed, text)
            class(auto_t), intent(inout) :: self
            type(split_table_t), intent(in) :: tab
            real(wp), intent(in) :: h
            logical, intent(out) :: passed
            character(len=*), intent(out) :: text
        end subroutine probe_symplectic

        !> At the end of a window: measure, compare, switch (submodule ropedyn_auto_switching).
        module subroutine watch(self, err)
            class(auto_t), intent(inout) :: self
            type(error_t), allocatable, intent(out) :: err
        end subroutine watch
    end interface

contains

    pure function auto_name(self) result(name)
        class(auto_t), intent(in) :: self
        character(len=:), allocatable :: name
        name = 'auto'
    end function auto_name

    !> f has changed from the current time on: the method in use is told.
    subroutine auto_rhs_changed(self)
        class(auto_t), intent(inout) :: self
        select case (self%active)
        case (EXPLICIT)
            call self%erk%rhs_changed()
        case (HIGH)
            call self%erk_high%rhs_changed()
        case (ADAMS)
            call self%am%rhs_changed()
        case (IMPLICIT)
            call self%mebdf%rhs_changed()
            call self%bdf%rhs_changed()
        end select
    end subroutine auto_rhs_changed

    !> auto's switches and, when it ran, the symplectic method's own choices of its step,
    !! in time order.
    function auto_switch_log(self) result(events)
        class(auto_t), intent(in) :: self
        type(switch_event_t), allocatable :: events(:)
        type(switch_event_t), allocatable :: sym_events(:)
        events = self%log%items()
        sym_events = self%sym_past%items()
        if (self%active == SYMPLECTIC) sym_events = [sym_events, self%sym%switch_log()]
        if (size(sym_events) > 0) events = merged_events(events, sym_events)
    end function auto_switch_log

    !> Initialize `which` at the current state (self%t, y, yq); log the switch (erk's, with
    !! `warn`, as a warning: printed while the run goes on).
    subroutine start_method(self, which, reason, err, h_first, warn)
        class(auto_t), intent(inout) :: self
        integer, intent(in) :: which
        character(len=*), intent(in) :: reason
        type(error_t), allocatable, intent(out) :: err
        real(wp), intent(in), optional :: h_first
        logical, intent(in), optional :: warn
        type(solver_options_t) :: opts
        type(solver_stats_t) :: old
        if (self%active /= 0) then
            old = self%current_stats()
            call add_counters(self%done, old)
            if (old%last_step > 0.0_wp) self%h_chunk = old%last_step
        end if
        if (present(h_first)) then
            if (h_first > 0.0_wp) self%h_chunk = h_first
        end if
        if (self%active == EXPLICIT) call self%erk%finalize()
        if (self%active == HIGH) call self%erk_high%finalize()
        if (self%active == ADAMS) call self%am%finalize()
        if (self%active == IMPLICIT) then
            call self%mebdf%finalize()
            call self%bdf%finalize()
        end if
        if (self%active == SYMPLECTIC) then
            call self%sym_past%add_all(self%sym%switch_log())
            call self%sym%finalize()
        end if
        opts = budget_left(self%options, self%done%steps)
        if (which == EXPLICIT) then
            opts%max_order = ERK_ORDER
            call self%erk%init(self%problem, self%t, self%y, self%yq, opts, err)
            if (allocated(err)) return
            call self%erk%set_stiff_failure(0.0_wp)
            if (present(h_first)) then
                if (h_first > 0.0_wp) then
                    call self%erk%set_initial_step(0.5_wp*h_first)
                    self%h_stable = h_first
                end if
            end if
            if (self%trials_are_cheap()) call self%erk%set_stable_step(self%h_stable)
            call self%log%add(self%t, 'erk', ERK_ORDER, reason, warning=warn)
        else if (which == HIGH) then
            self%calm_accurate = -1.0_wp
            opts%max_order = HIGH_ORDER
            call self%erk_high%init(self%problem, self%t, self%y, self%yq, opts, err)
            if (allocated(err)) return
            call self%erk_high%set_stiff_failure(0.0_wp)
            ! the order-4 pair's last step, held by accuracy, is a safe first step
            if (self%h_chunk > 0.0_wp) call self%erk_high%set_initial_step(self%h_chunk)
            call self%erk_high%set_stable_step(self%h_stable_high)
            self%explicit_age = 0
            call self%log%add(self%t, 'erk', HIGH_ORDER, reason)
        else if (which == SYMPLECTIC) then
            opts%max_order = 4
            call self%sym%init(self%problem, self%t, self%y, self%yq, opts, err)
            if (allocated(err)) return
            call self%log%add(self%t, 'symplectic', self%sym_order, reason)
        else if (which == ADAMS) then
            self%calm_accurate = -1.0_wp
            opts%max_order = ADAMS_ORDER
            call self%am%init(self%problem, self%t, self%y, self%yq, opts, err)
            if (allocated(err)) return
            self%explicit_age = 0
            call self%log%add(self%t, 'adams', ADAMS_ORDER, reason)
        else
            opts%max_order = self%mebdf_order
            if (self%use_bdf) then
                call self%bdf%init(self%problem, self%t, self%y, self%yq, opts, err)
                if (allocated(err)) return
                call self%log%add(self%t, 'cvode', self%mebdf_order, reason)
            else
                call self%mebdf%init(self%problem, self%t, self%y, self%yq, opts, err)
                if (allocated(err)) return
                call self%log%add(self%t, 'mebdf', self%mebdf_order, reason)
            end if
        end if
        self%active = which
        self%windows = 0
        self%dearer = 0
        self%win_t0 = self%t
        self%win_steps0 = 0
        self%win_cost0 = 0.0_wp
    end subroutine start_method

    !> A note in the log at the current time, for the method and order limit in use (an
    !! event that changes neither: the method chain does not count it as a switch); a
    !! `warning` is also printed while the run goes on.
    subroutine add_note(self, text, warning)
        class(auto_t), intent(inout) :: self
        character(len=*), intent(in) :: text
        logical, intent(in) :: warning
        type(switch_event_t), allocatable :: events(:)
        events = self%log%items()
        if (size(events) == 0) return
        associate (last => events(size(events)))
            call self%log%add(self%t, last%method, last%max_order, text, warning=warning)
        end associate
    end subroutine add_note

    subroutine auto_advance_to(self, tout, t, y, yq, err)
        class(auto_t), intent(inout) :: self
        real(wp), intent(in) :: tout
        real(wp), intent(out) :: t
        real(wp), intent(inout) :: y(:)
        real(wp), intent(inout) :: yq(:)
        type(error_t), allocatable, intent(out) :: err
        type(solver_stats_t) :: now
        real(wp) :: target
        integer :: outcome

        t = self%t
        if (.not. self%initialized) then
            call make_error(err, ERR_SOLVER, 'auto: advance_to called before init')
            return
        end if
        do while (self%t < tout)
            target = look_ahead(self, tout)
            ! the stop time holds for every method it runs (the symplectic method's steps
            ! end on the output time, never beyond it)
            call self%erk%set_stop_time(self%t_stop)
            call self%erk_high%set_stop_time(self%t_stop)
            call self%am%set_stop_time(self%t_stop)
            call self%bdf%set_stop_time(self%t_stop)
            call self%mebdf%set_stop_time(self%t_stop)
            call cap_chunk(self)
            call run_active(self, tout, target, outcome, err)
            if (outcome == RUN_AGAIN) cycle
            if (outcome == RUN_STOPPED) exit
            if (allocated(err)) then
                y = self%y
                if (self%nq > 0) yq(1:self%nq) = self%yq
                t = self%t
                err%message = 'auto: '//err%message
                now = self%stats()
                if (now%steps >= self%options%max_steps) call budget_spent(self, err%message)
                return
            end if
            if (self%t < target .and. stop_now(self%options)) exit   ! stopped on request
            call self%watch(err)
            if (allocated(err)) exit
        end do
        y = self%y
        if (self%nq > 0) yq(1:self%nq) = self%yq
        t = self%t
    end subroutine auto_advance_to

    !> Where the method in use advances to next: the window is looked at after at most
    !! about WINDOW/4 of its steps (before its first step, of h_chunk), not only at the
    !! next output time tout.
    real(wp) function look_ahead(self, tout) result(target)
        class(auto_t), intent(inout) :: self
        real(wp), intent(in) :: tout
        type(solver_stats_t) :: now
        real(wp) :: h_look
        now = self%current_stats()
        h_look = now%last_step
        if (h_look <= 0.0_wp) h_look = self%h_chunk
        target = tout
        if (h_look > 0.0_wp) target = min(tout, self%t + 0.25_wp*WINDOW*h_look)
        ! a look-ahead below the round-off of t rounds back to t: the method would take
        ! no step (and never reach its own round-off limit): on to tout instead
        if (target <= self%t) target = tout
    end function look_ahead

    !> The method in use advances to target (the symplectic method: to tout, where its
    !! steps fall; target becomes tout). outcome RUN_DONE (err: the method's failure, if
    !! any), RUN_AGAIN (the symplectic method or Adams gave up and erk goes on: advance
    !! again) or RUN_STOPPED (going on with erk failed: err).
    subroutine run_active(self, tout, target, outcome, err)
        class(auto_t), intent(inout) :: self
        real(wp), intent(in) :: tout
        real(wp), intent(inout) :: target
        integer, intent(out) :: outcome
        type(error_t), allocatable, intent(out) :: err
        type(solver_stats_t) :: now
        outcome = RUN_DONE
        if (self%active == SYMPLECTIC) then
            ! kept, to the output time (where its steps fall)
            target = tout
            call self%sym%advance_to(tout, self%t, self%y, self%yq, err)
            if (allocated(err)) then
                if (.not. self%sym%failed_fatally()) then
                    call leave_symplectic(self, err)
                    outcome = merge(RUN_STOPPED, RUN_AGAIN, allocated(err))
                end if
            end if
        else if (self%active == EXPLICIT) then
            call self%erk%advance_to(target, self%t, self%y, self%yq, err)
        else if (self%active == HIGH) then
            call self%erk_high%advance_to(target, self%t, self%y, self%yq, err)
        else if (self%active == ADAMS) then
            call self%am%advance_to(target, self%t, self%y, self%yq, err)
            if (allocated(err)) then
                ! Adams gave up (e.g. no convergence: stiff); on with erk unless the step
                ! budget is spent
                now = self%stats()
                if (now%steps < self%options%max_steps) then
                    self%rate_accurate = huge(1.0_wp)
                    call self%start_method(EXPLICIT, 'adams failed: '// &
                                           trim(err%message(1:min(160, len(err%message)))), &
                                           err)
                    outcome = merge(RUN_STOPPED, RUN_AGAIN, allocated(err))
                end if
            end if
        else if (self%use_bdf) then
            call self%bdf%advance_to(target, self%t, self%y, self%yq, err)
        else
            call self%mebdf%advance_to(target, self%t, self%y, self%yq, err)
        end if
    end subroutine run_active

    !> The symplectic method stopped (`err`: its step budget ran short, its step became
    !! unstable or too short) at the last state it reached: on with erk from there, whose
    !! steps adapt (and auto's switches from erk), without the symplectic method for the
    !! rest of the run, and a warning (the balance may drift from here; a larger max_steps
    !! keeps the method). `err` is then erk's start's, if it failed.
    subroutine leave_symplectic(self, err)
        class(auto_t), intent(inout) :: self
        type(error_t), allocatable, intent(inout) :: err
        character(len=:), allocatable :: cause
        cause = err%message(1:min(WHY_LEN - 120, len(err%message)))
        deallocate (err)
        self%sym_barred = .true.
        self%sym_cost = -1.0_wp
        call self%start_method(EXPLICIT, cause//'; on with erk, without the symplectic '// &
                               'method for the rest of the run', err, warn=.true.)
    end subroutine leave_symplectic

    !> The message of a method that spent the budget auto left it (which names the run's
    !! own budget: budget_left), with auto's own diagnosis (the symplectic method left out)
    !! at the end.
    subroutine budget_spent(self, message)
        class(auto_t), intent(inout) :: self
        character(len=:), allocatable, intent(inout) :: message
        message = message//last_warning(self%log%items())
    end subroutine budget_spent


    !> Name of the method for stretches held by accuracy.
    pure function accurate_name(self) result(name)
        class(auto_t), intent(in) :: self
        character(len=:), allocatable :: name
        name = 'adams'
        if (self%accurate == HIGH) name = 'the order-5 pair'
    end function accurate_name

    !> The order limit of the implicit method of this run (what a user's max_order caps, and
    !! the run's order safety lowers: ropedyn_methods).
    pure integer function auto_order_in_use(self) result(order)
        class(auto_t), intent(in) :: self
        order = self%mebdf_order
    end function auto_order_in_use

    !> A new step budget: auto's, and what it leaves the method in use (which got what was
    !! left of the old one when it started).
    subroutine auto_set_step_budget(self, max_steps)
        class(auto_t), intent(inout), target :: self
        integer(i8), intent(in) :: max_steps
        class(integrator_t), pointer :: method
        type(solver_options_t) :: left
        self%options%max_steps = max_steps
        left = budget_left(self%options, self%done%steps)
        method => self%active_method()
        if (associated(method)) call method%set_step_budget(left%max_steps)
    end subroutine auto_set_step_budget

    !> Name of the implicit method of this run.
    pure function implicit_name(self) result(name)
        class(auto_t), intent(in) :: self
        character(len=:), allocatable :: name
        name = 'mebdf'
        if (self%use_bdf) name = 'cvode'
    end function implicit_name

    !> Whether a trial of the implicit method is a cheap experiment, so that weaker evidence
    !! may bring one: erk's steps near the stable step of the spectrum estimate, the early
    !! first look, a measured cost gone stale. Not for a problem with a mass matrix (the
    !! MPP: M(q) in MEBDF's residual, a dense Newton matrix; a trial there costs 6 to 12
    !! times erk's; see the submodule's header, Switching).
    pure logical function trials_are_cheap(self)
        class(auto_t), intent(in) :: self
        trials_are_cheap = .not. self%problem%has_mass_matrix()
    end function trials_are_cheap

    !> Cost of the work counted in `s` by the method in use, in evaluations of f.
    pure real(wp) function cost(self, s)
        class(auto_t), intent(in) :: self
        type(solver_stats_t), intent(in) :: s
        cost = real(s%rhs_evals + s%jac_rhs_evals, wp)
        if (self%active == ADAMS) cost = cost + ADAMS_STEP_COST*real(s%steps, wp)
        if (self%active == IMPLICIT) then
            associate (lambda => self%lambda)
                if (self%use_bdf) then
                    cost = cost + (BDF_STEP_COST + BDF_SOLVE_COST*(lambda - 1.0_wp))* &
                           real(s%steps, wp)
                else
                    cost = self%mebdf_eval_cost*cost + (IMPLICIT_STEP_COST + SOLVE_COST* &
                                                        (lambda - 1.0_wp))*real(s%steps, wp)
                end if
                cost = cost + (FACTOR_BASE + FACTOR_COST*(lambda**2 - 1.0_wp))* &
                       real(s%lin_setups, wp) &
                       + JACOBIAN_COST*lambda*real(s%jac_evals, wp)
            end associate
        end if
    end function cost

    !> The method of the segment in progress (null before the first).
    function active_method(self) result(method)
        class(auto_t), intent(in), target :: self
        class(integrator_t), pointer :: method
        method => null()
        select case (self%active)
        case (EXPLICIT)
            method => self%erk
        case (HIGH)
            method => self%erk_high
        case (ADAMS)
            method => self%am
        case (SYMPLECTIC)
            method => self%sym
        case (IMPLICIT)
            if (self%use_bdf) then
                method => self%bdf
            else
                method => self%mebdf
            end if
        end select
    end function active_method

    !> The step count of the method in use at which its chunk ends early: OVERDUE_WINDOWS
    !! windows' steps after its window began. A chunk is sized by time, from the last
    !! step, so steps that collapse within it would otherwise run unlooked-at (a straight
    !! start reaching 3 m into a stiff ground took erk's steps from 1e-3 to 1e-9 s within
    !! its first chunk and spent the whole step budget, a million steps, on 0.5 ms). The
    !! symplectic method's steps do not adapt: no cap.
    subroutine cap_chunk(self)
        class(auto_t), intent(inout) :: self
        integer(i8) :: cap
        cap = self%win_steps0 + OVERDUE_WINDOWS*WINDOW
        select case (self%active)
        case (EXPLICIT)
            call self%erk%set_step_cap(cap)
        case (HIGH)
            call self%erk_high%set_step_cap(cap)
        case (ADAMS)
            call self%am%set_step_cap(cap)
        case (IMPLICIT)
            call self%bdf%set_step_cap(cap)
            call self%mebdf%set_step_cap(cap)
        end select
    end subroutine cap_chunk

    !> Counters of the segment in progress.
    function current_stats(self) result(s)
        class(auto_t), intent(in), target :: self
        type(solver_stats_t) :: s
        class(integrator_t), pointer :: method
        method => self%active_method()
        if (associated(method)) s = method%stats()
    end function current_stats

    !> total += part (counters; the last step and order are the part's once it has taken a
    !! step: a method switched to at an output time has none yet, and the record there
    !! keeps the step before the switch; the reduced Newton path counts when either part
    !! used it).
    subroutine add_counters(total, part)
        type(solver_stats_t), intent(inout) :: total
        type(solver_stats_t), intent(in) :: part
        call total%add(part)
        total%reduced_newton = total%reduced_newton .or. part%reduced_newton
        if (part%steps == 0) return
        total%last_step = part%last_step
        total%last_order = part%last_order
    end subroutine add_counters

    !> After a failure: the shortfall of the method that failed (integrator_t's
    !! budget_shortfall; it had the budget auto left it).
    function auto_budget_shortfall(self, t) result(rest)
        class(auto_t), intent(in) :: self
        real(wp), intent(in) :: t
        integer(i8) :: rest
        rest = active_shortfall(self, t)
    end function auto_budget_shortfall

    !> auto_budget_shortfall's work (its binding's interface has no target for the pointer).
    function active_shortfall(self, t) result(rest)
        class(auto_t), intent(in), target :: self
        real(wp), intent(in) :: t
        integer(i8) :: rest
        class(integrator_t), pointer :: method
        rest = 0
        method => self%active_method()
        if (associated(method)) rest = method%budget_shortfall(t)
    end function active_shortfall

    function auto_stats(self) result(stats)
        class(auto_t), intent(in) :: self
        type(solver_stats_t) :: stats
        stats = self%done
        if (self%active /= 0) call add_counters(stats, self%current_stats())
    end function auto_stats

    subroutine auto_finalize(self)
        class(auto_t), intent(inout) :: self
        ! (the log stays readable after the run)
        if (self%active == SYMPLECTIC) call self%sym_past%add_all(self%sym%switch_log())
        call self%erk%finalize()
        call self%erk_high%finalize()
        call self%mebdf%finalize()
        call self%bdf%finalize()
        call self%am%finalize()
        call self%sym%finalize()
        call self%sym_probe%finalize()
        self%active = 0
        self%initialized = .false.
        self%problem => null()
    end subroutine auto_finalize
end module ropedyn_auto
