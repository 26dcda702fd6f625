!> The abstract integrator: what every time integrator in solvers/ offers.
!!
!! Life cycle: `init` (problem, initial state, options) -> `advance_to` (repeatedly, with
!! increasing output times; the state is returned exactly at tout) -> `stats` -> `finalize`.
!! An integrator keeps all its state in the object: two integrators never interfere.
!!
!! Stopping early: with `options%stop_requested` set, an integrator asks it after every
!! accepted step and, when it says .true., returns from `advance_to` at once with t < tout
!! and the state at t (no error). The run driver uses it to end a run at the next step after
!! a signal (docs/development/internals.md, "Interrupts"). An integrator that does not ask simply returns at
!! tout; the driver then stops there.
!!
!! Stop time: an integrator steps past tout and interpolates back to it, unless `t_stop`
!! (`set_stop_time`) bounds it: then no step ends beyond t_stop, and the step that reaches
!! it ends exactly there. A driver whose right-hand side changes at a known time (a support
!! coupled to another program, whose motion is known only up to the next exchange) stops
!! there and, after changing it, calls `rhs_changed`: a method that carries f from the end
!! of its last step into the next (erk's first-same-as-last stage) evaluates it again.
module ropedyn_integrator
    use ropedyn_kinds, only: wp, i8
    use ropedyn_error, only: error_t, make_error, ERR_SOLVER
    use ropedyn_text, only: int_text, real_text, significant_text, es_text
    use ropedyn_problem, only: problem_t
    use ropedyn_methods, only: METHODS, method_index, resolved_max_order
    use ropedyn_switch_log, only: switch_event_t
    implicit none
    private
    public :: integrator_t, start_t, solver_options_t, solver_stats_t, MAX_ORDER_LIMIT, &
        STIFF_STEP_RATE
    public :: stop_query_i, stop_now, steps_to_end, budget_covering, last_warning, &
        exceeded_text, integrator_budget_shortfall, default_step_budget, error_weights, &
        budget_left
    public :: DEFAULT_RTOL, DEFAULT_ATOL, DEFAULT_MAX_STEPS, BUDGET_STEP_RATE

    !> The defaults of the options every method shares; the scene's &solver keys take
    !! theirs from here.
    real(wp), parameter :: DEFAULT_RTOL = 1.0e-6_wp      !< relative tolerance
    real(wp), parameter :: DEFAULT_ATOL = 1.0e-8_wp      !< absolute tolerance (state units)
    !> step budget of a whole run: at least this many steps (default_step_budget)
    integer, parameter :: DEFAULT_MAX_STEPS = 1000000

    !> No integrator here goes beyond this order of accuracy.
    integer, parameter :: MAX_ORDER_LIMIT = 7

    !> Steps per simulated second beyond which a method held at a crawl by the problem's
    !! stiffness gives up with a diagnosis (erk, adams) instead of running on: the step
    !! guarantee of the hard scenes (docs/validation/hard-scenes.md).
    real(wp), parameter :: STIFF_STEP_RATE = 2.0e5_wp
    !> ... and the steps per simulated second that the default step budget allows a run of
    !! any length (default_step_budget): a quarter of that crawl, the rate up to which auto
    !! runs an explicit method at all (its START_RATE)
    real(wp), parameter :: BUDGET_STEP_RATE = 0.25_wp*STIFF_STEP_RATE

    !> Options shared by all integrators (same meaning for every method).
    !! The error test of every method keeps the local error of component i near or below
    !! rtol * |y_i| + atol_i.
    type :: solver_options_t
        real(wp) :: rtol = DEFAULT_RTOL      !< relative tolerance
        real(wp) :: atol = DEFAULT_ATOL      !< absolute tolerance (state units)
        !> per-component absolute tolerances; when allocated (size of the state) they
        !! replace `atol` for the state (quadratures keep `atol`)
        real(wp), allocatable :: atol_vector(:)
        integer :: max_order = 0             !< highest order of accuracy (0: method default)
        !> step budget of this integrator: the whole run's, or what is left of it to an
        !! integrator started within the run (budget_left)
        integer(i8) :: max_steps = DEFAULT_MAX_STEPS
        !> what a message about a spent budget names (steps_exhausted): the budget of the
        !! whole run or simulation this integration is part of (0: max_steps), and the steps
        !! counted against it before this integrator started (an integrator started again
        !! within the run: a library simulation's restore, the order safety's second look;
        !! budget_left sets the three)
        integer(i8) :: whole_budget = 0
        integer(i8) :: steps_before = 0
        !> the caller drives the integration advance by advance (a library simulation):
        !! t_end is the scene's, not where the integration ends, so a message about the
        !! budget speaks of the simulation instead of the rest of a run
        logical :: driven = .false.
        logical :: fd_jacobian = .false.     !< difference f even if the problem has a Jacobian
        !> CVODE's BDF stability-limit detection (order reduction when a lightly damped
        !! oscillatory mode nears the stability boundary); other methods reject .true.
        logical :: stab_lim_det = .false.
        !> asked after every accepted step: .true. ends `advance_to` there (t < tout, no
        !! error); not associated: never
        procedure(stop_query_i), pointer, nopass :: stop_requested => null()
        !> solve the Newton systems on the first-order matrix even when the problem has
        !! second-order structure (the reduced matrix M - g C - g^2 K of half the size is
        !! the default then; ropedyn_iteration_matrix)
        logical :: first_order_newton = .false.
        !> the end of the run (s), when the caller knows it (huge: not known); auto starts
        !! the symplectic method for its bounded energy only on runs long enough for an
        !! adaptive method's energy drift to matter (ropedyn_auto, LONG_RUN)
        real(wp) :: t_end = huge(1.0_wp)
        !> time the parts of a step (right-hand side, Jacobian, factorizations, solves) into
        !! the stats' time_* fields (a clock reading costs about 30 ns: a few % of a step of a
        !! small rope, so it is off unless asked for)
        logical :: profile = .false.
    end type solver_options_t

    !> Counters of an integration so far.
    type :: solver_stats_t
        integer(i8) :: steps = 0              !< accepted steps
        integer(i8) :: rhs_evals = 0          !< f evaluations (without Jacobian differencing)
        integer(i8) :: jac_rhs_evals = 0      !< f evaluations spent differencing Jacobians
        integer(i8) :: jac_evals = 0          !< Jacobian evaluations (analytic or differenced)
        integer(i8) :: lin_setups = 0         !< linear solver setups (LU factorizations)
        integer(i8) :: err_test_fails = 0     !< rejected steps (local error test)
        integer(i8) :: nonlin_iters = 0       !< Newton iterations
        integer(i8) :: nonlin_conv_fails = 0  !< Newton convergence failures
        real(wp) :: last_step = 0.0_wp        !< size of the last step taken, s
        integer :: last_order = 0             !< order of the last step taken
        !> accepted steps taken at each order of accuracy (zero when a method does not say)
        integer(i8) :: order_steps(MAX_ORDER_LIMIT) = 0
        !> Where the time went (s, monotonic clock; with options%profile only, else 0):
        !! right-hand side evaluations (f, F and M v of a mass matrix, quadratures),
        !! Jacobians (or the reduced blocks), factorizations of the Newton matrix, and the
        !! linear solves, out of the whole time spent in `advance_to` (time_advance, measured
        !! by the caller: ropedyn_simulation); the rest of that is the integrator's own work.
        real(wp) :: time_advance = 0.0_wp
        real(wp) :: time_rhs = 0.0_wp
        real(wp) :: time_jac = 0.0_wp
        real(wp) :: time_factor = 0.0_wp
        real(wp) :: time_solve = 0.0_wp
        !> the Newton systems were solved on the reduced second-order matrix
        logical :: reduced_newton = .false.
    contains
        procedure :: add => stats_add
    end type solver_stats_t

    !> The start of an integration as `init` hands it to a method's `start`, checked:
    !! the initial state and the order limit to use.
    type :: start_t
        real(wp) :: t0 = 0.0_wp
        real(wp), allocatable :: y0(:)   !< state (problem%size())
        real(wp), allocatable :: yq0(:)  !< quadratures (problem%quad_size())
        !> options%max_order within the method's range, or the method's default when 0
        !! (0 for auto when none was asked: it chooses)
        integer :: max_order = 0
    end type start_t

    !> What every integrator does and holds. `init` (here, for all) checks the options and
    !! the initial state against the problem, sets the components below and calls the
    !! method's `start`; a method reads them but never sets them.
    type, abstract :: integrator_t
        class(problem_t), pointer :: problem => null()  !< referenced, not copied
        type(solver_options_t) :: options
        integer :: n = 0   !< unknowns of the state
        integer :: nq = 0  !< quadrature variables
        !> no step ends beyond this time, s (`set_stop_time`; huge: no bound; `init`
        !! clears it)
        real(wp) :: t_stop = huge(1.0_wp)
        !> advance_to returns early (t < tout, no error) after the accepted step that
        !! brings the method's step count to this (`set_step_cap`, for auto's looks at a
        !! method whose steps collapsed within a stretch; huge: never; `init` clears it)
        integer(i8) :: step_cap = huge(1_i8)
    contains
        procedure :: init => integrator_init
        procedure :: set_stop_time => integrator_set_stop_time
        procedure :: set_step_cap => integrator_set_step_cap
        procedure :: stop_here => integrator_stop_here
        procedure :: rhs_changed => integrator_rhs_changed
        procedure(start_i), deferred :: start
        procedure(advance_to_i), deferred :: advance_to
        procedure(stats_i), deferred :: stats
        procedure(finalize_i), deferred :: finalize
        procedure(name_i), deferred :: name
        ! the method's order range, one statement
        procedure :: min_order => integrator_min_order, &
                     max_order_limit => integrator_max_order_limit
        procedure :: order_in_use => integrator_order_in_use
        procedure :: set_step_budget => integrator_set_step_budget
        procedure :: switch_log => integrator_switch_log
        procedure :: steps_exhausted => integrator_steps_exhausted
        procedure :: budget_shortfall => integrator_budget_shortfall
        procedure :: refusal => integrator_refusal
    end type integrator_t

    abstract interface
        !> Whether the integration should stop at the step just taken.
        logical function stop_query_i()
        end function stop_query_i

        !> The method's own preparation, after `init` has set problem, options, n, nq.
        subroutine start_i(self, start, err)
            import :: integrator_t, start_t, error_t
            class(integrator_t), intent(inout) :: self
            type(start_t), intent(in) :: start
            type(error_t), allocatable, intent(out) :: err
        end subroutine start_i

        !> Integrate to tout and return the state there. On failure `err` says the
        !! simulated time, the last step size and the cause; y, yq then hold the last
        !! good state and t its time.
        subroutine advance_to_i(self, tout, t, y, yq, err)
            import :: integrator_t, wp, error_t
            class(integrator_t), intent(inout) :: self
            real(wp), intent(in) :: tout
            real(wp), intent(out) :: t
            real(wp), intent(inout) :: y(:)
            real(wp), intent(inout) :: yq(:)
            type(error_t), allocatable, intent(out) :: err
        end subroutine advance_to_i

        !> Counters so far.
        function stats_i(self) result(stats)
            import :: integrator_t, solver_stats_t
            class(integrator_t), intent(in) :: self
            type(solver_stats_t) :: stats
        end function stats_i

        !> Release all resources; the object may be initialized again afterwards.
        subroutine finalize_i(self)
            import :: integrator_t
            class(integrator_t), intent(inout) :: self
        end subroutine finalize_i

        !> Method name as in &solver method.
        pure function name_i(self) result(name)
            import :: integrator_t
            class(integrator_t), intent(in) :: self
            character(len=:), allocatable :: name
        end function name_i
    end interface
contains

    !> Whether `options` asks to stop now (`stop_requested` set and .true.).
    logical function stop_now(options)
        type(solver_options_t), intent(in) :: options
        stop_now = .false.
        if (associated(options%stop_requested)) stop_now = options%stop_requested()
    end function stop_now

    !> Add the counters and times of `part` (another integration, or an earlier part of this
    !! one) to `self`; time_advance, the last step and order and the Newton path stay
    !! those of `self`.
    pure subroutine stats_add(self, part)
        class(solver_stats_t), intent(inout) :: self
        type(solver_stats_t), intent(in) :: part
        self%steps = self%steps + part%steps
        self%rhs_evals = self%rhs_evals + part%rhs_evals
        self%jac_rhs_evals = self%jac_rhs_evals + part%jac_rhs_evals
        self%jac_evals = self%jac_evals + part%jac_evals
        self%lin_setups = self%lin_setups + part%lin_setups
        self%err_test_fails = self%err_test_fails + part%err_test_fails
        self%nonlin_iters = self%nonlin_iters + part%nonlin_iters
        self%nonlin_conv_fails = self%nonlin_conv_fails + part%nonlin_conv_fails
        self%order_steps = self%order_steps + part%order_steps
        self%time_rhs = self%time_rhs + part%time_rhs
        self%time_jac = self%time_jac + part%time_jac
        self%time_factor = self%time_factor + part%time_factor
        self%time_solve = self%time_solve + part%time_solve
    end subroutine stats_add

    !> No step of the following `advance_to` calls ends beyond t_stop (s; huge(1.0_wp): no
    !! bound again); the step that reaches it ends there.
    subroutine integrator_set_stop_time(self, t_stop)
        class(integrator_t), intent(inout) :: self
        real(wp), intent(in) :: t_stop
        self%t_stop = t_stop
    end subroutine integrator_set_stop_time

    !> End advance_to early after the accepted step that brings the method's step count
    !! (its stats' steps) to `steps` (huge: never).
    subroutine integrator_set_step_cap(self, steps)
        class(integrator_t), intent(inout) :: self
        integer(i8), intent(in) :: steps
        self%step_cap = steps
    end subroutine integrator_set_step_cap

    !> Whether advance_to ends after the accepted step that brought the method's step count
    !! to `steps`: stopped on request (options%stop_requested) or at the step cap.
    logical function integrator_stop_here(self, steps) result(stop)
        class(integrator_t), intent(in) :: self
        integer(i8), intent(in) :: steps
        stop = steps >= self%step_cap
        if (.not. stop) stop = stop_now(self%options)
    end function integrator_stop_here

    !> The right-hand side has changed from the current time on (the driver changed what
    !! f depends on, at a time the integration stopped at): a method that keeps f of its
    !! current point evaluates it again. Nothing to do for most methods.
    subroutine integrator_rhs_changed(self)
        class(integrator_t), intent(inout) :: self
    end subroutine integrator_rhs_changed

    !> The lowest value options%max_order may take for this method.
    pure integer function integrator_min_order(self) result(order)
        class(integrator_t), intent(in) :: self
        order = METHODS(method_index(self%name()))%lowest_order
    end function integrator_min_order

    !> The highest value options%max_order may take for this method.
    pure integer function integrator_max_order_limit(self) result(order)
        class(integrator_t), intent(in) :: self
        order = METHODS(method_index(self%name()))%highest_order
    end function integrator_max_order_limit

    !> The order limit the method runs at: options%max_order or, when 0, its default (auto
    !! overrides it: its implicit method's).
    pure integer function integrator_order_in_use(self) result(order)
        class(integrator_t), intent(in) :: self
        order = resolved_max_order(self%name(), self%options%max_order)
    end function integrator_order_in_use

    !> A new step budget (options%max_steps) for the integration under way: the run's whole
    !! budget for the integrator that took over from a second look with a capped one.
    subroutine integrator_set_step_budget(self, max_steps)
        class(integrator_t), intent(inout), target :: self
        integer(i8), intent(in) :: max_steps
        self%options%max_steps = max_steps
    end subroutine integrator_set_step_budget

    !> The changes of method or order limit made during the run so far, oldest first
    !! (ropedyn_switch_log); none for an integrator that never changes them.
    function integrator_switch_log(self) result(events)
        class(integrator_t), intent(in) :: self
        type(switch_event_t), allocatable :: events(:)
        allocate (events(0))
    end function integrator_switch_log

    !> The cause of a run that ran out of its step budget at time t: the budget (the whole
    !! run's or simulation's, not what was left of it to this integrator), what the rest of
    !! the run takes at the last step size (when the end is known), or in a simulation its
    !! steps so far and how to raise the budget; and, when the integrator's own log
    !! diagnosed something on the way (its last warning: cvode's lightly damped stiff modes,
    !! with the methods that avoid them), that diagnosis, so that the message names the
    !! cause and the cure.
    function integrator_steps_exhausted(self, t) result(cause)
        class(integrator_t), intent(in) :: self
        real(wp), intent(in) :: t
        character(len=:), allocatable :: cause
        type(solver_stats_t) :: stats
        integer(i8) :: rest
        real(wp) :: h
        stats = self%stats()
        cause = exceeded_text(whole_budget(self%options))
        if (self%options%driven) then
            cause = cause//': the budget of the whole simulation, which has taken '// &
                int_text(self%options%steps_before + stats%steps)//' steps since it '// &
                'started (those before a restore too); a simulation that goes on longer '// &
                'needs a larger solver.max_steps in its scene'
        else
            h = stats%last_step
            rest = steps_to_end(t, self%options%t_end, h)
            if (rest > 0) cause = cause//'; at the size of the last accepted step ('// &
                significant_text(h, 3)//' s) the rest of the run, to t = '// &
                real_text(self%options%t_end)//' s, takes about '//int_text(rest)// &
                ' steps more'
        end if
        cause = cause//last_warning(self%switch_log())
    end function integrator_steps_exhausted

    !> After a failure at time t: when the run ended for its step budget, the steps the rest
    !! of it, to options%t_end, takes at the last step size (at least 1); else 0. A method
    !! that foresees the shortfall (the symplectic method) says it before its budget is
    !! spent.
    function integrator_budget_shortfall(self, t) result(rest)
        class(integrator_t), intent(in) :: self
        real(wp), intent(in) :: t
        integer(i8) :: rest
        type(solver_stats_t) :: stats
        rest = 0
        stats = self%stats()
        if (stats%steps < self%options%max_steps) return
        rest = max(1_i8, steps_to_end(t, self%options%t_end, stats%last_step))
    end function integrator_budget_shortfall

    !> Why the method cannot integrate `problem` at all ('' when it can): asked before a
    !! run starts, so that a method the scene names for a problem it does not fit is bad
    !! input, not a failed integration. The default: every method fits every problem.
    function integrator_refusal(self, problem) result(why)
        class(integrator_t), intent(in) :: self
        class(problem_t), intent(in) :: problem
        character(len=:), allocatable :: why
        why = ''
    end function integrator_refusal

    !> The options of an integrator that goes on within the step budget of `outer` after
    !! `used` steps counted against it (by integrators before it in the run, or in a method
    !! made of others): what is left of it (at least one step) as its max_steps, and the
    !! whole budget and the steps before for its messages.
    function budget_left(outer, used) result(options)
        type(solver_options_t), intent(in) :: outer
        integer(i8), intent(in) :: used
        type(solver_options_t) :: options
        options = outer
        options%max_steps = max(1_i8, outer%max_steps - used)
        options%whole_budget = whole_budget(outer)
        options%steps_before = outer%steps_before + used
    end function budget_left

    !> The budget of the whole run or simulation `options` is part of (solver_options_t).
    pure integer(i8) function whole_budget(options) result(budget)
        type(solver_options_t), intent(in) :: options
        budget = options%whole_budget
        if (budget <= 0) budget = options%max_steps
    end function whole_budget

    !> 'max_steps exceeded (N steps)': how a message says that a budget of N steps ran out.
    pure function exceeded_text(max_steps) result(text)
        integer(i8), intent(in) :: max_steps
        character(len=:), allocatable :: text
        text = 'max_steps exceeded ('//int_text(max_steps)//' steps)'
    end function exceeded_text

    !> '; the run had diagnosed at t = T s: REASON', the last warning of a switch log (the
    !! diagnosis a failure's message ends with), or '' when it has none.
    function last_warning(events) result(text)
        type(switch_event_t), intent(in) :: events(:)
        character(len=:), allocatable :: text
        integer :: k
        text = ''
        do k = size(events), 1, -1
            if (.not. events(k)%warning) cycle
            text = '; the run had diagnosed at t = '//trim(adjustl(es_text(events(k)%t, 10, 3)))// &
                ' s: '//events(k)%reason
            exit
        end do
    end function last_warning

    !> The steps from t to t_end at the step h, rounded up: what the rest of a run takes at
    !! that step (0 when t_end is not known, huge, or h <= 0).
    pure integer(i8) function steps_to_end(t, t_end, h) result(steps)
        real(wp), intent(in) :: t, t_end, h
        steps = 0
        if (.not. (h > 0.0_wp) .or. t_end >= huge(1.0_wp) .or. .not. (t_end > t)) return
        steps = ceiling(min((t_end - t)/h, 1.0e18_wp), i8)
    end function steps_to_end

    !> The step budget of a run to t_end (s) that names none: DEFAULT_MAX_STEPS, or
    !! BUDGET_STEP_RATE steps per simulated second when that is more. A fixed budget
    !! would fail long runs that are not crawling (the undamped paper rope, n = 20, takes
    !! 1.08 million steps of the symplectic method over 300 s, 3600 per second), while a
    !! crawl (steps per second beyond the rate) still ends with the diagnosis of a spent
    !! budget.
    pure integer(i8) function default_step_budget(t_end) result(budget)
        real(wp), intent(in) :: t_end
        budget = int(DEFAULT_MAX_STEPS, i8)
        if (.not. (t_end > 0.0_wp)) return
        budget = max(budget, ceiling(min(BUDGET_STEP_RATE*t_end, 1.0e18_wp), i8))
    end function default_step_budget

    !> The weights of the error test at the state y (the type's comment): rtol |y_i| + atol_i.
    pure function error_weights(options, y) result(w)
        type(solver_options_t), intent(in) :: options
        real(wp), intent(in) :: y(:)
        real(wp) :: w(size(y))
        if (allocated(options%atol_vector)) then
            w = options%rtol*abs(y) + options%atol_vector
        else
            w = options%rtol*abs(y) + options%atol
        end if
    end function error_weights

    !> A step budget for `steps` steps: a tenth more (a step may shorten on the way), rounded
    !! up to two significant digits (1,083,000 -> 1,200,000); 0 for none.
    pure integer(i8) function budget_covering(steps) result(budget)
        integer(i8), intent(in) :: steps
        real(wp) :: x, unit
        budget = 0
        if (steps <= 0) return
        x = 1.1_wp*real(steps, wp)
        unit = 10.0_wp**max(0, floor(log10(x)) - 1)
        budget = int(ceiling(x/unit - 1.0e-9_wp)*unit, i8)
    end function budget_covering

    !> Prepare to integrate `problem` from (t0, y0, yq0). The problem must outlive the
    !! integrator (it is referenced, not copied). The checks every method shares: the order
    !! limit (options%max_order, the method's default when 0) within the method's range,
    !! tolerances > 0, stability-limit detection only for CVODE, the sizes of the initial
    !! state and of per-component absolute tolerances. Recursive: auto's `start` initializes
    !! the method it runs through this same `init`.
    recursive subroutine integrator_init(self, problem, t0, y0, yq0, options, err)
        class(integrator_t), intent(inout) :: self
        class(problem_t), intent(inout), target :: problem
        real(wp), intent(in) :: t0
        real(wp), intent(in) :: y0(:)
        real(wp), intent(in) :: yq0(:)
        type(solver_options_t), intent(in) :: options
        type(error_t), allocatable, intent(out) :: err
        type(start_t) :: start
        character(len=:), allocatable :: name

        call self%finalize()
        name = self%name()
        self%problem => problem
        self%options = options
        self%t_stop = huge(1.0_wp)
        self%step_cap = huge(1_i8)
        self%n = problem%size()
        self%nq = problem%quad_size()
        start%max_order = resolved_max_order(name, options%max_order)
        if (start%max_order /= 0 .and. (start%max_order < self%min_order() .or. &
                                        start%max_order > self%max_order_limit())) then
            call make_error(err, ERR_SOLVER, name//': max_order must be '// &
                            int_text(self%min_order())//' .. '//int_text(self%max_order_limit()))
        else if (options%stab_lim_det .and. all(name /= ['cvode', 'adams'])) then
            call make_error(err, ERR_SOLVER, name//': stability-limit detection is a CVODE '// &
                            'option (method = ''cvode'')')
        else if (.not. (options%rtol > 0.0_wp .and. options%atol > 0.0_wp)) then
            call make_error(err, ERR_SOLVER, name//': rtol and atol must be > 0')
        else if (size(y0) /= self%n .or. size(yq0) < self%nq) then
            call make_error(err, ERR_SOLVER, name//': initial state of the wrong size')
        else if (allocated(options%atol_vector)) then
            if (size(options%atol_vector) /= self%n) &
                call make_error(err, ERR_SOLVER, name//': atol_vector has the wrong size')
        end if
        if (allocated(err)) return
        start%t0 = t0
        start%y0 = y0
        start%yq0 = yq0(1:self%nq)
        call self%start(start, err)
    end subroutine integrator_init
end module ropedyn_integrator
