!> Adaptive explicit Runge-Kutta integration (`method = 'erk'`) behind the integrator
!! interface: one of the embedded FSAL pairs of ropedyn_erk_tables (max_order 3, 4 or 5),
!! a PI step-size controller, dense output, and a stiffness monitor that ends the run
!! with a diagnosis when the step is held by stability at a crawl.
!!
!! Why a bundled method and not ARKODE's ERKStep: on the rope the step of every explicit
!! method is limited by stability, so what counts is f evaluations per simulated second
!! and the cost around each one; ARKODE adds about 2 us per f call, more than a whole
!! RHS costs at n = 30 once the kernels are fast (docs/theory/erk.md, "Why a bundled
!! method").
!!
!! - **Error test**: the weighted RMS norm of h sum e_i k_i with weights
!!   rtol max(|y_n|, |y_n+1|) + atol (atol per component when given) must be <= 1.
!! - **Step size**: a PI controller (Gustafsson 1991), h_new = h fac err^-alpha
!!   err_old^beta, which keeps the step steady where stability, not accuracy, limits it
!!   (with gains of its own there: K_I_STABLE, K_P_STABLE);
!!   growth at most 5x (1x right after a rejection), reduction at most 10x.
!! - **Quadratures** (dissipated energy, support work) are integrated by the same pair
!!   from their right-hand side g at every stage, yq += h sum b_i g_i, with its error
!!   estimate h sum e_i g_i in the error test (weights rtol max(|yq|, |yq + dq|) + atol,
!!   the norm the larger of the state's and the quadratures'), as CVODE does with its
!!   quadratures.
!!   The quadratures are then the pair's solution of the augmented system, so the
!!   energy balance T + V + dissipated = E0 holds to the pair's accuracy even where g is
!!   rough (impacts, stick-slip), where g at the step points alone aliases the
!!   element-scale oscillations that a stability-held step does not resolve.
!! - **Stiffness**: Dormand-Prince's last two stages are both at t + h, so rho =
!!   |k_s - k_s-1| / |Y_s - Y_s-1| estimates the spectral radius along the error for free
!!   (Hairer's test); the pairs of order 3 and 4 take a combination of their stages
!!   instead, every 4th step (ropedyn_erk_tables: rho_alpha, and why). When most of the
!!   last 500 steps had h rho near the stability limit and they averaged more than 2e5
!!   steps per simulated second, the run ends (ERR_SOLVER) with a message naming the
!!   implicit methods.
!! - **Failures**: a recoverable status of f (e.g. NaN) cuts h by 4; below the round-off
!!   floor 16 eps |t| or past max_steps the integration ends with the last good state.
module ropedyn_erk
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use ropedyn_kinds, only: wp, i8
    use ropedyn_sums, only: sum_squares
    use ropedyn_text, only: int_text, es_text
    use ropedyn_error, only: error_t, make_error, ERR_SOLVER
    use ropedyn_problem, only: problem_t, STATUS_OK, STATUS_FATAL
    use ropedyn_integrator, only: integrator_t, start_t, solver_options_t, solver_stats_t, &
                                  STIFF_STEP_RATE
    use ropedyn_erk_tables, only: erk_table_t, erk_table, ERK_MAX_STAGES
    implicit none
    private
    public :: erk_t
    !> Accepted steps the stiffness monitor looks back over.
    integer, parameter :: STIFF_WINDOW = 500
    !> accepted steps between estimates of the spectral radius from a combination of all
    !! stages (the tables with rho_alpha); the last estimate holds in between
    integer, parameter :: RHO_EVERY = 4
    !> h rho above this fraction of the stability limit counts as stability-limited.
    real(wp), parameter :: STIFF_FRACTION = 0.7_wp
    !> ... or h between STIFF_FRACTION and NEAR_STABLE times the stable step known from the
    !! Jacobian's spectrum (set_stable_step). A step longer than that shows the estimate
    !! too low: on steel_wire the Ritz values give 1.5e-6 s, erk's steps are 6e-6 s (its
    !! steps near the limit reach 1.3 times it: drag_fall).
    real(wp), parameter :: NEAR_STABLE = 2.0_wp
    real(wp), parameter :: SAFETY = 0.9_wp      !< step-size safety factor
    real(wp), parameter :: GROW_MAX = 5.0_wp    !< largest growth of h per step
    real(wp), parameter :: SHRINK_MAX = 0.1_wp  !< largest reduction of h per step
    !> PI controller exponents, over the order of the error estimate + 1 (Gustafsson's
    !! k_I = 0.3/k, k_P = 0.4/k: err^-(k_I + k_P) err_old^k_P)
    real(wp), parameter :: K_I = 0.3_wp, K_P = 0.4_wp
    !> ... and where the step is held by stability (h rho above STABLE_CONTROL times the
    !! stability limit): a smaller integral and a larger proportional gain, which damp the
    !! controller's cycle of growing into the unstable region and being rejected there.
    !! Measured with the 3/8 pair on the paper rope at rtol 1e-2, 30 s: 12 % of the
    !! steps rejected at n = 30 with (0.3, 0.4), 4.6 % with (0.15, 0.5); f evaluations
    !! 289,722 -> 267,566 (n = 30), 915,082 -> 860,850 (n = 100), 484,706 -> 446,302
    !! (n = 50); the accuracy-held runs (rtol 1e-6, n = 10 and 30) take the same steps.
    real(wp), parameter :: K_I_STABLE = 0.15_wp, K_P_STABLE = 0.5_wp
    real(wp), parameter :: STABLE_CONTROL = 0.8_wp

    type, extends(integrator_t) :: erk_t
        private
        type(erk_table_t) :: tab
        type(solver_stats_t) :: counters
        integer :: s = 0
        real(wp) :: t = 0.0_wp          !< time of the last accepted step point
        real(wp) :: h = 0.0_wp          !< size of the next step (0: not chosen yet)
        real(wp) :: t_old = 0.0_wp      !< start of the last accepted step
        real(wp) :: h_old = 0.0_wp      !< size of the last accepted step
        real(wp) :: err_old = 1.0e-4_wp !< error norm of the last accepted step
        logical :: started = .false.    !< k(:, 1) holds f(t, y)
        !> f changed at t (`rhs_changed`): the next step evaluates its first stage anew
        !! instead of taking the last stage of the step before
        logical :: fsal_stale = .false.
        logical :: rejected = .false.   !< the last attempt was rejected
        real(wp), allocatable :: y(:), y_old(:), ynew(:), ytmp(:), yprev(:), k(:, :), atol(:)
        real(wp), allocatable :: dk(:), dy(:)  !< the spectral estimate's stage combinations
        !> the table estimates rho from its last two stages (Y_s-1 kept in yprev), not
        !! from a combination of all (rho_alpha: dk, dy)
        logical :: rho_last_two = .true.
        real(wp), allocatable :: yq(:), yq_old(:)
        !> the quadratures' increment over the step just computed and its error estimate
        real(wp), allocatable :: dq(:), eq(:)
        !> the quadratures' right-hand side g at the stages of the current step (FSAL as k)
        real(wp), allocatable :: gk(:, :)
        !> stiffness monitor over the last STIFF_WINDOW accepted steps
        real(wp) :: rho = 0.0_wp        !< last estimate of the spectral radius, 1/s
        integer :: stiff_steps = 0      !< stability-limited steps in the current window
        integer :: window_steps = 0     !< steps in the current window
        real(wp) :: window_start = 0.0_wp
        real(wp) :: stiff_share = 0.0_wp  !< stability-limited share of the last window
        !> a stable step known from the Jacobian's spectrum (set_stable_step; 0: none)
        real(wp) :: h_stable = 0.0_wp
        real(wp) :: fail_rate = STIFF_STEP_RATE  !< 0 disables the stiffness failure
        logical :: stiff_stop = .false.  !< the last failure was the stiffness monitor's
    contains
        procedure :: start => erk_start
        procedure :: advance_to => erk_advance_to
        procedure :: stats => erk_stats
        procedure :: finalize => erk_finalize
        procedure :: name => erk_name
        procedure :: table => erk_table_of
        procedure :: spectral_radius => erk_spectral_radius
        procedure :: stiff_share_of_steps => erk_stiff_share
        procedure :: set_stiff_failure => erk_set_stiff_failure
        procedure :: set_initial_step => erk_set_initial_step
        procedure :: set_stable_step => erk_set_stable_step
        procedure :: stopped_by_stiffness => erk_stopped_by_stiffness
        procedure :: rhs_changed => erk_rhs_changed
        procedure, private :: attempt_step, run_stages, step_error, accept_step, next_step
        procedure, private :: first_step, first_stage
        procedure, private :: quad_step
        procedure, private :: dense
        procedure, private :: failure
        procedure, private :: monitor_stiffness
        procedure, private :: stage_state
        procedure, private :: error_norm
    end type erk_t

    interface
        !> The quadratures' increment over the step just computed and the weighted norm
        !! of its error estimate (submodule ropedyn_erk_dense, as dense).
        module subroutine quad_step(self, h, errq)
            class(erk_t), intent(inout) :: self
            real(wp), intent(in) :: h
            real(wp), intent(out) :: errq
        end subroutine quad_step

        !> out = base + sum_j (h c_j) k(:, j) over the nonzero c_j, left to right (without base:
        !! the sum alone, its first term assigned, no zero fill): the argument of a stage, the
        !! error estimate, the quadratures' increment and its estimate. One vectorized update
        !! per nonzero entry of the table, no array temporaries.
        !! (in submodule ropedyn_erk_dense, which uses it too)
        pure module subroutine combine(c, h, k, out, base)
            real(wp), intent(in) :: c(:)              !< coefficients of the first size(c) stages
            real(wp), intent(in) :: h
            real(wp), intent(in), contiguous :: k(:, :)
            real(wp), intent(out), contiguous :: out(:)
            real(wp), intent(in), contiguous, optional :: base(:)
        end subroutine combine

        !> The solution at tt within the last accepted step (t_old .. t).
        module subroutine dense(self, tt, y, yq)
            class(erk_t), intent(in) :: self
            real(wp), intent(in) :: tt
            real(wp), intent(inout) :: y(:)
            real(wp), intent(inout) :: yq(:)
        end subroutine dense
    end interface

contains

    pure function erk_name(self) result(name)
        class(erk_t), intent(in) :: self
        character(len=:), allocatable :: name
        name = 'erk'
    end function erk_name

    !> The pair in use (after init).
    pure function erk_table_of(self) result(tab)
        class(erk_t), intent(in) :: self
        type(erk_table_t) :: tab
        tab = self%tab
    end function erk_table_of

    !> The last estimate of the spectral radius along the error (1/s; 0 before a step).
    pure real(wp) function erk_spectral_radius(self) result(rho)
        class(erk_t), intent(in) :: self
        rho = self%rho
    end function erk_spectral_radius

    !> Share of the steps of the last full window (or of the current one, once it has at
    !! least `min_steps` steps: 51 unless given) that were limited by stability (h rho
    !! near the stability limit).
    pure real(wp) function erk_stiff_share(self, min_steps) result(share)
        class(erk_t), intent(in) :: self
        integer, intent(in), optional :: min_steps
        integer :: least
        least = 51
        if (present(min_steps)) least = max(1, min_steps)
        share = self%stiff_share
        if (self%window_steps >= least) share = real(self%stiff_steps, wp)/self%window_steps
    end function erk_stiff_share

    !> Steps per simulated second above which a stability-limited run fails (default
    !! STIFF_STEP_RATE; 0 or less: never). Call after init.
    subroutine erk_set_stiff_failure(self, rate)
        class(erk_t), intent(inout) :: self
        real(wp), intent(in) :: rate
        self%fail_rate = rate
    end subroutine erk_set_stiff_failure

    !> The last advance_to ended because the step was held by stability at a crawl.
    pure logical function erk_stopped_by_stiffness(self) result(stopped)
        class(erk_t), intent(in) :: self
        stopped = self%stiff_stop
    end function erk_stopped_by_stiffness

    !> Size of the first step (instead of the estimate from the derivatives); call after
    !! init, before the first advance_to.
    subroutine erk_set_initial_step(self, h)
        class(erk_t), intent(inout) :: self
        real(wp), intent(in) :: h
        if (h > 0.0_wp) self%h = h
    end subroutine erk_set_initial_step

    !> The stability-limited step from the Jacobian's spectrum (auto's Arnoldi estimate):
    !! the stiffness monitor counts a step near it (STIFF_FRACTION .. NEAR_STABLE times) as
    !! held by stability too. The estimate from the last stages sees only the modes the
    !! solution excites: on a rope falling flat (drag_fall) it gives 1.8e3 1/s against the
    !! Jacobian's 5.1e3, and steps at the stable step looked held by accuracy. Call after
    !! init; 0 or less: none.
    subroutine erk_set_stable_step(self, h)
        class(erk_t), intent(inout) :: self
        real(wp), intent(in) :: h
        self%h_stable = max(h, 0.0_wp)
    end subroutine erk_set_stable_step

    subroutine erk_start(self, start, err)
        class(erk_t), intent(inout) :: self
        type(start_t), intent(in) :: start
        type(error_t), allocatable, intent(out) :: err

        self%tab = erk_table(start%max_order)
        self%s = self%tab%stages
        self%rho_last_two = all(self%tab%rho_alpha == 0.0_wp)
        allocate (self%y(self%n), self%y_old(self%n), self%ynew(self%n), self%ytmp(self%n), &
                  self%yprev(self%n), self%k(self%n, self%s), self%atol(self%n), &
                  self%dk(self%n), self%dy(self%n))
        allocate (self%yq(self%nq), self%yq_old(self%nq), self%gk(self%nq, self%s), &
                  self%dq(self%nq), self%eq(self%nq))
        self%atol = self%options%atol
        if (allocated(self%options%atol_vector)) self%atol = self%options%atol_vector
        self%y = start%y0
        self%yq = start%yq0
        self%t = start%t0
        self%t_old = start%t0
        self%h = 0.0_wp
        self%h_old = 0.0_wp
        self%err_old = 1.0e-4_wp
        self%started = .false.
        self%fsal_stale = .false.
        self%rejected = .false.
        self%rho = 0.0_wp
        self%stiff_steps = 0
        self%window_steps = 0
        self%window_start = start%t0
        self%stiff_share = 0.0_wp
        self%h_stable = 0.0_wp
        self%fail_rate = STIFF_STEP_RATE
        self%stiff_stop = .false.
        self%counters = solver_stats_t()
    end subroutine erk_start

    !> f has changed from the current time on: the next step evaluates its first stage.
    subroutine erk_rhs_changed(self)
        class(erk_t), intent(inout) :: self
        if (self%started) self%fsal_stale = .true.
    end subroutine erk_rhs_changed

    subroutine erk_advance_to(self, tout, t, y, yq, err)
        class(erk_t), intent(inout) :: self
        real(wp), intent(in) :: tout
        real(wp), intent(out) :: t
        real(wp), intent(inout) :: y(:)
        real(wp), intent(inout) :: yq(:)
        type(error_t), allocatable, intent(out) :: err

        t = self%t
        if (.not. associated(self%problem)) then
            call make_error(err, ERR_SOLVER, 'erk: advance_to called before init')
            return
        end if
        if (.not. self%started) then
            if (tout <= self%t) then
                y = self%y
                if (self%nq > 0) yq(1:self%nq) = self%yq
                return
            end if
            call self%first_step(tout - self%t, err)
            if (allocated(err)) then
                y = self%y
                return
            end if
        else if (tout < self%t_old - self%h_old*8.0_wp*epsilon(1.0_wp)) then
            call make_error(err, ERR_SOLVER, 'erk: output time lies before the last step')
            return
        end if
        do while (self%t < tout)
            call self%attempt_step(err)
            if (allocated(err) .or. (self%t < tout .and. &
                                     self%stop_here(self%counters%steps))) then
                ! failed, or stopped early (on request, at the step cap): the state at the
                ! end of the last step
                t = self%t
                y = self%y
                if (self%nq > 0) yq(1:self%nq) = self%yq
                return
            end if
        end do
        if (self%t == tout .and. tout == self%t_stop) then
            ! the step ended at the stop time: its own end point, not the interpolant's
            y = self%y
            if (self%nq > 0) yq(1:self%nq) = self%yq
        else
            call self%dense(tout, y, yq)
        end if
        t = tout
    end subroutine erk_advance_to

    !> f at the initial point and the first step size (Hairer's starting-step algorithm,
    !! Solving ODEs I, II.4), bounded by the span to the first output time.
    subroutine first_step(self, span, err)
        class(erk_t), intent(inout) :: self
        real(wp), intent(in) :: span
        type(error_t), allocatable, intent(out) :: err
        real(wp) :: d0, d1, d2, h0, h1, w(self%n)
        integer :: status, p

        call self%first_stage(err)
        if (allocated(err)) return
        self%started = .true.
        if (self%h > 0.0_wp) then
            self%h = min(self%h, span)
            return
        end if
        p = self%tab%order
        w = self%options%rtol*abs(self%y) + self%atol
        d0 = rms(self%y/w)
        d1 = rms(self%k(:, 1)/w)
        if (d0 < 1.0e-5_wp .or. d1 < 1.0e-5_wp) then
            h0 = 1.0e-6_wp
        else
            h0 = 0.01_wp*d0/d1
        end if
        h0 = min(h0, span)
        self%ytmp = self%y + h0*self%k(:, 1)
        call self%problem%rhs(self%t + h0, self%ytmp, self%k(:, 2), status)
        self%counters%rhs_evals = self%counters%rhs_evals + 1
        if (status /= STATUS_OK) then
            self%h = h0/4.0_wp
            return
        end if
        d2 = rms((self%k(:, 2) - self%k(:, 1))/w)/h0
        if (max(d1, d2) <= 1.0e-15_wp) then
            h1 = max(1.0e-6_wp, h0*1.0e-3_wp)
        else
            h1 = (0.01_wp/max(d1, d2))**(1.0_wp/(p + 1))
        end if
        self%h = min(100.0_wp*h0, h1, span)
    end subroutine first_step

    !> f (and the quadratures' g) at the current point into the first stage.
    subroutine first_stage(self, err)
        class(erk_t), intent(inout) :: self
        type(error_t), allocatable, intent(out) :: err
        integer :: status
        self%fsal_stale = .false.
        call self%problem%rhs(self%t, self%y, self%k(:, 1), status)
        self%counters%rhs_evals = self%counters%rhs_evals + 1
        if (status /= STATUS_OK .or. .not. all(ieee_is_finite(self%k(:, 1)))) then
            call self%failure(err, 'the right-hand side could not be evaluated at the '// &
                              merge('initial', 'current', .not. self%started)//' state')
            return
        end if
        if (self%nq > 0) then
            call self%problem%quad_rhs(self%t, self%y, self%gk(:, 1), status)
            if (status /= STATUS_OK .or. .not. all(ieee_is_finite(self%gk(:, 1)))) then
                call self%failure(err, 'the quadrature right-hand side could not be '// &
                                  'evaluated at the '//merge('initial', 'current', &
                                  .not. self%started)//' state')
                return
            end if
        end if
    end subroutine first_stage

    !> Attempt steps until one is accepted; then self%t, self%y have moved on and the
    !! stages of that step are kept for dense output.
    subroutine attempt_step(self, err)
        class(erk_t), intent(inout) :: self
        type(error_t), allocatable, intent(out) :: err
        real(wp) :: h, errnorm, h_wanted
        integer :: status
        logical :: recoverable, clipped

        recoverable = .false.
        ! FSAL: the last stage of the previous step is f at this step's start (kept in
        ! place until now for the dense output of the previous step)
        if (self%counters%steps > 0) then
            self%k(:, 1) = self%k(:, self%s)
            if (self%nq > 0) self%gk(:, 1) = self%gk(:, self%s)
        end if
        if (self%fsal_stale) then
            ! f changed at t (a coupled support's new motion): the first stage anew
            call self%first_stage(err)
            if (allocated(err)) return
        end if
        clipped = .false.
        h_wanted = 0.0_wp
        attempts: do
            if (self%counters%steps >= self%options%max_steps) then
                call self%failure(err, self%steps_exhausted(self%t))
                return
            end if
            h = self%h
            ! a stop time ahead: the step that would reach it (or come within 1 % of a
            ! step of it) ends exactly there
            clipped = self%t + 1.01_wp*h >= self%t_stop
            if (clipped) then
                h_wanted = merge(0.0_wp, h, self%rejected)
                h = self%t_stop - self%t
            end if
            if (h < 16.0_wp*epsilon(1.0_wp)*max(abs(self%t), tiny(1.0_wp))) then
                if (recoverable) then
                    call self%failure(err, 'step size fell below the round-off limit after '// &
                                      'repeated recoverable errors of the right-hand side '// &
                                      '(e.g. a NaN or Inf in the forces)')
                else
                    call self%failure(err, 'step size fell below the round-off limit')
                end if
                return
            end if
            call self%run_stages(h, status)
            if (status == STATUS_FATAL) then
                call self%failure(err, 'the right-hand side reported a fatal error')
                return
            else if (status /= STATUS_OK) then
                ! recoverable (e.g. NaN): retry smaller, as CVODE does
                recoverable = .true.
                self%h = h/4.0_wp
                self%rejected = .true.
                cycle attempts
            end if
            errnorm = self%step_error(h)
            if (errnorm > 1.0_wp) then
                self%counters%err_test_fails = self%counters%err_test_fails + 1
                self%h = h*max(SHRINK_MAX, SAFETY*errnorm**(-1.0_wp/self%tab%order))
                self%rejected = .true.
                cycle attempts
            end if
            exit attempts
        end do attempts
        call self%accept_step(h, merge(self%t_stop, self%t + h, clipped), errnorm)
        ! a step cut short by the stop time: the next one as long as the one wanted
        if (clipped) self%h = max(self%h, h_wanted)
        call self%monitor_stiffness(h, err)
    end subroutine attempt_step

    !> Stages 2 .. s of a step of size h (stage 1 is f at the step's start, already
    !! known), the last at the new solution, left in ynew (FSAL). Loops over the components
    !! with the table's nonzero entries only (no array temporaries). status: the right-hand
    !! side's, STATUS_OK when every stage was evaluated.
    subroutine run_stages(self, h, status)
        class(erk_t), intent(inout) :: self
        real(wp), intent(in) :: h
        integer, intent(out) :: status
        integer :: i, s
        s = self%s
        do i = 2, s
            call self%stage_state(i, h)
            if (i == s - 1 .and. self%rho_last_two) self%yprev(:) = self%ytmp
            if (self%nq > 0) then
                ! with the quadratures' right-hand side at the same stage
                call self%problem%rhs_quad(self%t + self%tab%c(i)*h, self%ytmp, &
                                           self%k(:, i), self%gk(:, i), status)
            else
                call self%problem%rhs(self%t + self%tab%c(i)*h, self%ytmp, self%k(:, i), &
                                      status)
            end if
            self%counters%rhs_evals = self%counters%rhs_evals + 1
            if (status /= STATUS_OK) return
        end do
        call swap(self%ynew, self%ytmp)
    end subroutine run_stages

    !> The weighted norm of the step's error estimate, the quadratures' included (their
    !! increment over the step computed here); huge for a norm that is not finite.
    real(wp) function step_error(self, h) result(errnorm)
        class(erk_t), intent(inout) :: self
        real(wp), intent(in) :: h
        real(wp) :: errq
        errnorm = self%error_norm(h)
        if (self%nq > 0) then
            call self%quad_step(h, errq)
            errnorm = max(errnorm, errq)
        end if
        if (.not. ieee_is_finite(errnorm)) errnorm = huge(1.0_wp)
    end function step_error

    !> The step of size h to tnew is accepted with error errnorm: the spectral radius
    !! estimate, the history, the counters, and the next step size.
    subroutine accept_step(self, h, tnew, errnorm)
        class(erk_t), intent(inout) :: self
        real(wp), intent(in) :: h, tnew, errnorm
        integer :: s
        s = self%s
        if (self%rho_last_two) then
            self%dk = self%k(:, s) - self%k(:, s - 1)
            self%dy = self%ynew - self%yprev
            self%rho = norm_ratio(self%dk, self%dy)
        else if (mod(self%counters%steps, int(RHO_EVERY, i8)) == 0) then
            ! a combination of all stages (ropedyn_erk_tables: rho_alpha), every RHO_EVERY
            ! steps (two more passes over the stages: 8 % of the paper run at every step,
            ! measured before combine fused its passes)
            call combine(self%tab%rho_alpha(1:s), 1.0_wp, self%k, self%dk)
            call combine(self%tab%rho_beta(1:s), h, self%k, self%dy)
            self%rho = norm_ratio(self%dk, self%dy)
        end if
        self%t_old = self%t
        self%h_old = h
        call swap(self%y_old, self%y)
        call swap(self%y, self%ynew)
        self%t = tnew
        if (self%nq > 0) then
            self%yq_old = self%yq
            self%yq = self%yq + self%dq
        end if
        self%counters%steps = self%counters%steps + 1
        self%counters%last_step = h
        self%counters%last_order = self%tab%order
        self%counters%order_steps(self%tab%order) = self%counters%order_steps(self%tab%order) + 1
        call self%next_step(h, errnorm)
    end subroutine accept_step

    !> The next step size after an accepted step of size h with error errnorm: a PI
    !! controller (order of the estimate + 1 = order of the method), with the gains for a
    !! stability-held step where h rho is near the stability limit.
    subroutine next_step(self, h, errnorm)
        class(erk_t), intent(inout) :: self
        real(wp), intent(in) :: h, errnorm
        real(wp) :: e, fac, gain_i, gain_p
        e = max(errnorm, 1.0e-10_wp)
        gain_i = K_I
        gain_p = K_P
        if (h*self%rho > STABLE_CONTROL*self%tab%stability_limit) then
            gain_i = K_I_STABLE
            gain_p = K_P_STABLE
        end if
        fac = SAFETY*e**(-(gain_i + gain_p)/self%tab%order)*self%err_old**(gain_p/self%tab%order)
        fac = min(GROW_MAX, max(SHRINK_MAX, fac))
        if (self%rejected) fac = min(1.0_wp, fac)
        self%err_old = e
        self%rejected = .false.
        self%h = h*fac
    end subroutine next_step

    !> ytmp = y + h sum_j a(i, j) k(:, j): the argument of stage i (one vectorized
    !! update per nonzero entry of the table).
    subroutine stage_state(self, i, h)
        class(erk_t), intent(inout) :: self
        integer, intent(in) :: i
        real(wp), intent(in) :: h
        call combine(self%tab%a(i, 1:i - 1), h, self%k, self%ytmp, self%y)
    end subroutine stage_state

    !> Weighted RMS norm of the error estimate h sum_j e_j k(:, j), with weights
    !! rtol max(|y|, |ynew|) + atol (uses ytmp as work).
    real(wp) function error_norm(self, h) result(norm)
        class(erk_t), intent(inout) :: self
        real(wp), intent(in) :: h
        real(wp) :: rtol
        integer :: l
        call combine(self%tab%e(1:self%s), h, self%k, self%ytmp)
        rtol = self%options%rtol
        do l = 1, self%n
            self%ytmp(l) = self%ytmp(l)/(rtol*max(abs(self%y(l)), abs(self%ynew(l))) &
                                         + self%atol(l))
        end do
        norm = sqrt(sum_squares(self%ytmp)/max(1, self%n))
    end function error_norm


    !> Exchange two work arrays without copying.
    subroutine swap(a, b)
        real(wp), allocatable, intent(inout) :: a(:), b(:)
        real(wp), allocatable :: tmp(:)
        call move_alloc(a, tmp)
        call move_alloc(b, a)
        call move_alloc(tmp, b)
    end subroutine swap

    !> Root mean square of v.
    pure real(wp) function rms(v)
        real(wp), intent(in) :: v(:)
        rms = sqrt(sum(v**2)/max(1, size(v)))
    end function rms

    !> |a| / |b| (0 when b = 0), the sums in ropedyn_sums' order.
    pure real(wp) function norm_ratio(a, b) result(r)
        real(wp), contiguous, intent(in) :: a(:), b(:)
        real(wp) :: na, nb
        na = sum_squares(a)
        nb = sum_squares(b)
        r = 0.0_wp
        if (nb > 0.0_wp) r = sqrt(na/nb)
    end function norm_ratio

    !> Count stability-limited steps; fail when a whole window was held at a crawl.
    subroutine monitor_stiffness(self, h, err)
        class(erk_t), intent(inout) :: self
        real(wp), intent(in) :: h
        type(error_t), allocatable, intent(out) :: err
        real(wp) :: rate
        character(len=320) :: buffer
        self%window_steps = self%window_steps + 1
        if (h*self%rho > STIFF_FRACTION*self%tab%stability_limit .or. &
            (h > STIFF_FRACTION*self%h_stable .and. h < NEAR_STABLE*self%h_stable)) &
            self%stiff_steps = self%stiff_steps + 1
        if (self%window_steps < STIFF_WINDOW) return
        rate = self%window_steps/max(self%t - self%window_start, tiny(1.0_wp))
        self%stiff_share = real(self%stiff_steps, wp)/self%window_steps
        if (self%fail_rate > 0.0_wp .and. rate > self%fail_rate .and. &
            self%stiff_share >= 0.5_wp) then
            write (buffer, '(a, es9.2, a, es9.2, a, es9.2, a)') 'the problem is too stiff '// &
                'for an explicit method here: the step is held by stability (h rho = ', &
                h*self%rho, ' with a spectral radius rho of about ', self%rho, &
                ' 1/s), which takes ', rate, ' steps per simulated second'
            self%stiff_stop = .true.
            call self%failure(err, trim(buffer)//'; use method = ''auto'' (it switches '// &
                              'to an implicit method where this happens) or ''mebdf''')
            return
        end if
        self%window_steps = 0
        self%stiff_steps = 0
        self%window_start = self%t
    end subroutine monitor_stiffness

    subroutine failure(self, err, cause)
        class(erk_t), intent(in) :: self
        type(error_t), allocatable, intent(out) :: err
        character(len=*), intent(in) :: cause
        character(len=96) :: buffer
        write (buffer, '(a, a, a, es11.3e3, a, i0)') 't = ', es_text(self%t, 12, 5), &
            ' s, step size ', self%h, ' s, order ', self%tab%order
        call make_error(err, ERR_SOLVER, 'erk failed at '//trim(buffer)//': '//cause)
    end subroutine failure

    function erk_stats(self) result(stats)
        class(erk_t), intent(in) :: self
        type(solver_stats_t) :: stats
        stats = self%counters
    end function erk_stats

    subroutine erk_finalize(self)
        class(erk_t), intent(inout) :: self
        self%problem => null()
        if (allocated(self%y)) deallocate (self%y, self%y_old, self%ynew, self%ytmp, &
                                           self%yprev, self%k, self%atol, self%dk, self%dy)
        if (allocated(self%yq)) deallocate (self%yq, self%yq_old, self%gk, self%dq, self%eq)
        self%started = .false.
    end subroutine erk_finalize
end module ropedyn_erk
