!> `method = 'auto'` (the default): an explicit or an implicit integrator, whichever is
!! cheaper on the scene at the time, switched during the run as LSODA switches Adams and
!! BDF.
!!
!! - **The two**: `erk` (ropedyn_erk, RK4 with a 3rd-order estimate: the longest stability
!!   interval on the imaginary axis per evaluation of f of the bundled pairs) and `mebdf`.
!! - **Start**: a few Arnoldi steps on the Jacobian at the initial state
!!   (ropedyn_spectrum) give the spectral radius and the damping of the fastest modes. The
!!   explicit pair's stability-limited step h_e follows from them; the run starts explicit
!!   unless that step would take more than START_RATE steps per simulated second. MEBDF's
!!   maximum order follows from the damping of the fast modes (A(alpha) of MEBDF,
!!   docs/solvers.md): order 4, A-stable, when a fast mode is damped by less than 3 %, order
!!   5 (A(88.4 deg)) up to 12 %, order 6 (A(83.1 deg)) above. `max_order` given by the user
!!   caps it.
!! - **Cost**: counted, not timed (runs stay reproducible): explicit, the evaluations of f;
!!   implicit, those plus IMPLICIT_STEP_COST per step for the Newton matrices, solves and
!!   vector work and JACOBIAN_COST per Jacobian (calibrated on the paper's rope, n = 30:
!!   an MEBDF step costs its 4.1 evaluations of f plus about 6 more in the rest).
!! - **Switching** (looked at every WINDOW steps of the method in use): explicit ->
!!   implicit when most steps of the window were held by stability (erk's own estimate of
!!   h rho) and either the implicit method's last measured cost per simulated second was
!!   lower by GAIN, or it has not been measured yet (a trial). Implicit -> explicit when
!!   the explicit cost predicted from the spectrum at the current state (evaluations per
!!   step / h_e) is lower than the implicit method's measured cost by GAIN; a trial of the
!!   implicit method that does not pay (judged on its second window) goes back at once.
!!   A switch that is undone within two windows doubles the wait before the next one.
!! Every switch (time, method, order limit, reason) goes into the switch log.
module ropedyn_auto
    use ropedyn_kinds, only: wp, i8
    use ropedyn_error, only: error_t, make_error, ERR_SOLVER
    use ropedyn_problem, only: problem_t
    use ropedyn_integrator, only: integrator_t, start_t, solver_options_t, solver_stats_t, &
                                  STIFF_STEP_RATE, stop_now
    use ropedyn_erk, only: erk_t
    use ropedyn_mebdf, only: mebdf_t
    use ropedyn_erk_tables, only: erk_table_t, erk_table
    use ropedyn_spectrum, only: spectrum_t, estimate_spectrum, erk_stable_step
    use ropedyn_switch_log, only: switch_log_t, switch_event_t
    implicit none
    private
    public :: auto_t

    integer, parameter :: EXPLICIT = 1, IMPLICIT = 2
    integer, parameter :: ERK_ORDER = 4            !< the explicit pair (RK4, 3rd-order estimate)
    integer, parameter :: WINDOW = 400             !< steps between looks
    real(wp), parameter :: GAIN = 1.3_wp           !< hysteresis of a switch
    !> explicit steps per simulated second above which a run starts implicit
    real(wp), parameter :: START_RATE = 0.25_wp*STIFF_STEP_RATE
    real(wp), parameter :: IMPLICIT_STEP_COST = 6.0_wp  !< f-equivalents per implicit step
    real(wp), parameter :: JACOBIAN_COST = 4.0_wp       !< f-equivalents per Jacobian
    !> the explicit cost predicted from the stability limit, times this (rejected steps,
    !! steps below the limit)
    real(wp), parameter :: EXPLICIT_MARGIN = 1.15_wp
    integer, parameter :: MAX_WAIT = 64            !< windows between switches, at most

    type, extends(integrator_t) :: auto_t
        private
        type(erk_t) :: erk
        type(mebdf_t) :: mebdf
        type(erk_table_t) :: tab
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
        logical :: trial = .false.         !< the implicit method is on trial
        integer :: wait = 0                !< windows to let pass before the next switch
        integer :: backoff = 1
        logical :: initialized = .false.
    contains
        procedure :: start => auto_start
        procedure :: advance_to => auto_advance_to
        procedure :: stats => auto_stats
        procedure :: finalize => auto_finalize
        procedure :: name => auto_name
        procedure :: switch_log => auto_switch_log
        procedure, private :: start_method
        procedure, private :: watch
        procedure, private :: current_stats
        procedure, private :: cost
    end type auto_t

contains

    pure function auto_name(self) result(name)
        class(auto_t), intent(in) :: self
        character(len=:), allocatable :: name
        name = 'auto'
    end function auto_name

    function auto_switch_log(self) result(events)
        class(auto_t), intent(in) :: self
        type(switch_event_t), allocatable :: events(:)
        events = self%log%items()
    end function auto_switch_log

    subroutine auto_start(self, start, err)
        class(auto_t), intent(inout) :: self
        type(start_t), intent(in) :: start
        type(error_t), allocatable, intent(out) :: err
        type(spectrum_t) :: spec
        real(wp) :: h_e, rate
        character(len=200) :: text

        self%user_order = start%max_order
        self%y = start%y0
        self%yq = start%yq0
        self%t = start%t0
        self%tab = erk_table(ERK_ORDER)
        self%done = solver_stats_t()
        call self%log%clear()
        self%rate_explicit = -1.0_wp
        self%rate_implicit = -1.0_wp
        self%trial = .false.
        self%wait = 0
        self%backoff = 1

        call estimate_spectrum(self%problem, start%t0, start%y0, spec)
        self%mebdf_order = mebdf_order_for(spec%fast_damping)
        if (self%user_order /= 0) self%mebdf_order = min(self%mebdf_order, self%user_order)
        h_e = erk_stable_step(self%tab, spec)
        if (spec%valid .and. h_e > 0.0_wp) then
            rate = 1.0_wp/h_e
            write (text, '(a, es9.2, a, f6.3, a, es9.2, a)') 'spectral radius ', &
                spec%radius, ' 1/s, fast modes damped >= ', spec%fast_damping, &
                ', explicit stable step ', h_e, ' s'
        else
            rate = 0.0_wp
            text = 'no spectrum estimate'
        end if
        if (rate > START_RATE) then
            call self%start_method(IMPLICIT, trim(text)//': explicit steps too short', err)
        else
            call self%start_method(EXPLICIT, trim(text), err, h_e)
        end if
        if (allocated(err)) return
        self%initialized = .true.
    end subroutine auto_start

    !> MEBDF's maximum order for fast modes damped by `zeta` (clipped at 0).
    pure integer function mebdf_order_for(zeta) result(order)
        real(wp), intent(in) :: zeta
        if (zeta < 0.03_wp) then
            order = 4
        else if (zeta < 0.12_wp) then
            order = 5
        else
            order = 6
        end if
    end function mebdf_order_for

    !> Initialize `which` at the current state (self%t, y, yq); log the switch.
    subroutine start_method(self, which, reason, err, h_first)
        class(auto_t), intent(inout) :: self
        integer, intent(in) :: which
        character(len=*), intent(in) :: reason
        type(error_t), allocatable, intent(out) :: err
        real(wp), intent(in), optional :: h_first
        type(solver_options_t) :: opts
        type(solver_stats_t) :: old
        if (self%active /= 0) then
            old = self%current_stats()
            call add_counters(self%done, old)
        end if
        if (self%active == EXPLICIT) call self%erk%finalize()
        if (self%active == IMPLICIT) call self%mebdf%finalize()
        opts = self%options
        opts%max_steps = max(1_i8, self%options%max_steps - self%done%steps)
        if (which == EXPLICIT) then
            opts%max_order = ERK_ORDER
            call self%erk%init(self%problem, self%t, self%y, self%yq, opts, err)
            if (allocated(err)) return
            call self%erk%set_stiff_failure(0.0_wp)
            if (present(h_first)) then
                if (h_first > 0.0_wp) call self%erk%set_initial_step(0.5_wp*h_first)
            end if
            call self%log%add(self%t, 'erk', ERK_ORDER, reason)
        else
            opts%max_order = self%mebdf_order
            call self%mebdf%init(self%problem, self%t, self%y, self%yq, opts, err)
            if (allocated(err)) return
            call self%log%add(self%t, 'mebdf', self%mebdf_order, reason)
        end if
        self%active = which
        self%windows = 0
        self%win_t0 = self%t
        self%win_steps0 = 0
        self%win_cost0 = 0.0_wp
    end subroutine start_method

    subroutine auto_advance_to(self, tout, t, y, yq, err)
        class(auto_t), intent(inout) :: self
        real(wp), intent(in) :: tout
        real(wp), intent(out) :: t
        real(wp), intent(inout) :: y(:)
        real(wp), intent(inout) :: yq(:)
        type(error_t), allocatable, intent(out) :: err
        type(solver_stats_t) :: now
        real(wp) :: target

        t = self%t
        if (.not. self%initialized) then
            call make_error(err, ERR_SOLVER, 'auto: advance_to called before init')
            return
        end if
        do while (self%t < tout)
            ! look at the window after at most about WINDOW/4 steps of the method in use
            now = self%current_stats()
            target = tout
            if (now%last_step > 0.0_wp) target = min(tout, self%t + 0.25_wp*WINDOW*now%last_step)
            if (self%active == EXPLICIT) then
                call self%erk%advance_to(target, self%t, self%y, self%yq, err)
            else
                call self%mebdf%advance_to(target, self%t, self%y, self%yq, err)
            end if
            if (allocated(err)) then
                y = self%y
                if (self%nq > 0) yq(1:self%nq) = self%yq
                t = self%t
                err%message = 'auto: '//err%message
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

    !> At the end of a window: measure, compare, switch.
    subroutine watch(self, err)
        class(auto_t), intent(inout) :: self
        type(error_t), allocatable, intent(out) :: err
        type(solver_stats_t) :: now
        type(spectrum_t) :: spec
        real(wp) :: rate, span, h_e, predicted, share
        character(len=240) :: text

        now = self%current_stats()
        if (now%steps - self%win_steps0 < WINDOW) return
        span = self%t - self%win_t0
        if (span <= 0.0_wp) return
        rate = (self%cost(now) - self%win_cost0)/span
        self%windows = self%windows + 1
        self%win_t0 = self%t
        self%win_steps0 = now%steps
        self%win_cost0 = self%cost(now)
        if (self%wait > 0) self%wait = self%wait - 1

        if (self%active == EXPLICIT) then
            self%rate_explicit = rate
            share = self%erk%stiff_share_of_steps()
            if (share < 0.5_wp .or. self%wait > 0) return
            if (self%rate_implicit > 0.0_wp .and. GAIN*self%rate_implicit >= rate) return
            write (text, '(a, i0, a, es9.2, a, es9.2, a)') 'explicit step held by stability (', &
                nint(100*share), ' % of the steps; spectral radius about ', &
                self%erk%spectral_radius(), ' 1/s; cost ', rate, ' f per second)'
            self%trial = self%rate_implicit <= 0.0_wp
            if (self%trial) text = trim(text)//': trying mebdf'
            if (self%windows <= 2) call back_off()
            call self%start_method(IMPLICIT, trim(text), err)
        else
            ! judge the implicit method on its second window on (the first includes its
            ! start at order 1 with small steps)
            if (self%windows < 2) return
            self%rate_implicit = rate
            if (self%trial) then
                self%trial = .false.
                if (self%rate_explicit > 0.0_wp .and. rate > self%rate_explicit) then
                    write (text, '(a, es9.2, a, es9.2, a)') 'mebdf was not cheaper (', &
                        rate, ' against ', self%rate_explicit, ' f per second)'
                    call back_off()
                    call self%start_method(EXPLICIT, trim(text), err)
                    return
                end if
            end if
            if (self%wait > 0) return
            call estimate_spectrum(self%problem, self%t, self%y, spec)
            h_e = erk_stable_step(self%tab, spec)
            if (h_e <= 0.0_wp) return
            predicted = EXPLICIT_MARGIN*self%tab%evals_per_step()/h_e
            if (GAIN*predicted < rate) then
                write (text, '(a, es9.2, a, es9.2, a, es9.2, a)') 'explicit stable step ', h_e, &
                    ' s: predicted cost ', predicted, ' f per second against ', rate, &
                    ' for mebdf'
                if (self%windows <= 2) call back_off()
                call self%start_method(EXPLICIT, trim(text), err, h_e)
            end if
        end if
    contains
        !> A switch soon after the last one: wait longer before the next.
        subroutine back_off()
            self%wait = self%backoff
            self%backoff = min(MAX_WAIT, 2*self%backoff)
        end subroutine back_off
    end subroutine watch

    !> Cost of the work counted in `s` by the method in use, in evaluations of f.
    pure real(wp) function cost(self, s)
        class(auto_t), intent(in) :: self
        type(solver_stats_t), intent(in) :: s
        cost = real(s%rhs_evals + s%jac_rhs_evals, wp)
        if (self%active == IMPLICIT) cost = cost + IMPLICIT_STEP_COST*real(s%steps, wp) + &
                                            JACOBIAN_COST*real(s%jac_evals, wp)
    end function cost

    !> Counters of the segment in progress.
    function current_stats(self) result(s)
        class(auto_t), intent(in) :: self
        type(solver_stats_t) :: s
        select case (self%active)
        case (EXPLICIT)
            s = self%erk%stats()
        case (IMPLICIT)
            s = self%mebdf%stats()
        end select
    end function current_stats

    !> total += part (counters; the last step and order are the part's).
    subroutine add_counters(total, part)
        type(solver_stats_t), intent(inout) :: total
        type(solver_stats_t), intent(in) :: part
        total%steps = total%steps + part%steps
        total%rhs_evals = total%rhs_evals + part%rhs_evals
        total%jac_rhs_evals = total%jac_rhs_evals + part%jac_rhs_evals
        total%jac_evals = total%jac_evals + part%jac_evals
        total%lin_setups = total%lin_setups + part%lin_setups
        total%err_test_fails = total%err_test_fails + part%err_test_fails
        total%nonlin_iters = total%nonlin_iters + part%nonlin_iters
        total%nonlin_conv_fails = total%nonlin_conv_fails + part%nonlin_conv_fails
        total%order_steps = total%order_steps + part%order_steps
        total%time_rhs = total%time_rhs + part%time_rhs
        total%time_jac = total%time_jac + part%time_jac
        total%time_factor = total%time_factor + part%time_factor
        total%time_solve = total%time_solve + part%time_solve
        total%reduced_newton = total%reduced_newton .or. part%reduced_newton
        total%last_step = part%last_step
        total%last_order = part%last_order
    end subroutine add_counters

    function auto_stats(self) result(stats)
        class(auto_t), intent(in) :: self
        type(solver_stats_t) :: stats
        stats = self%done
        if (self%active /= 0) call add_counters(stats, self%current_stats())
    end function auto_stats

    subroutine auto_finalize(self)
        class(auto_t), intent(inout) :: self
        call self%erk%finalize()
        call self%mebdf%finalize()
        self%active = 0
        self%initialized = .false.
        self%problem => null()
    end subroutine auto_finalize
end module ropedyn_auto
