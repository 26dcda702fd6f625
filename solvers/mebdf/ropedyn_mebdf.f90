!> Cash's modified extended backward differentiation formulas (MEBDF) behind the
!! integrator interface: variable step, variable order 2 .. 7, for y' = f(t, y) and for
!! linearly implicit problems M(t, y) y' = F(t, y).
!!
!! One step of order k+1 from t_n to t_n + h (docs/theory/mebdf.md, "One step"):
!!  1. k-step BDF for ybar_{n+1};
!!  2. k-step BDF one step further for ybar_{n+2}, with ybar_{n+1} in the history;
!!  3. the modified extended corrector for y_{n+1}, using the slopes of stages 1 and 2.
!! All three stages share one Newton (iteration) matrix M - h beta_k J.
!!
!! Formulation (see docs/theory/mebdf.md): fixed-step coefficients on a backward-difference
!! history (as in Shampine's ode15s and the classic codes); a step-size change rescales the
!! differences by interpolation. Every stage is an equation of the form
!!     M(t, y) (y - c) = h beta_k F(t, y),
!! with c known, so the slopes h y' = (y - c) / beta_k of stages 1 and 2 come free. The
!! local error test uses stage 1 (the BDF of order k, as the classic codes do): the
!! MEBDF solution, one order higher, is then more accurate than the tolerance asks.
!! Quadrature variables follow the same formulas explicitly (their F does not depend on
!! them) and take part in the error test.
!!
!! All state is in the object: integrators never share anything.
!!
!! This module holds the object's life cycle (init, advance_to, stats, finalize); one step
!! is in the submodule ropedyn_mebdf_step, the first step, the history rescaling and the
!! dense output in ropedyn_mebdf_history.
module ropedyn_mebdf
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use ropedyn_kinds, only: wp, i8
    use ropedyn_sums, only: sum_scaled_squares
    use ropedyn_text, only: int_text, es_text
    use ropedyn_error, only: error_t, make_error, ERR_SOLVER
    use ropedyn_problem, only: problem_t, STATUS_OK, STATUS_FATAL
    use ropedyn_integrator, only: integrator_t, start_t, solver_options_t, solver_stats_t
    use ropedyn_clock, only: clock_seconds
    use ropedyn_mebdf_coefficients, only: mebdf_coefficients_t, mebdf_coefficients, KMAX_MEBDF
    use ropedyn_iteration_matrix, only: iteration_matrix_t
    use ropedyn_spectrum, only: spectrum_t, estimate_spectrum, LIGHT_DAMPING
    use ropedyn_switch_log, only: switch_log_t, switch_event_t
    use ropedyn_methods, only: METHODS, method_index
    implicit none
    private
    public :: mebdf_t

    integer, parameter :: MAX_NEWTON_ITERS = 4     !< per stage
    real(wp), parameter :: NEWTON_TOL = 0.03_wp    !< weighted-norm Newton tolerance per stage
    integer, parameter :: JACOBIAN_MAX_AGE = 50    !< steps before a Jacobian is refreshed
    real(wp), parameter :: REFACTOR_CHANGE = 0.3_wp  !< relative change of h*beta to refactor
    !> consecutive error-test failures allowed in one step (as set for CVODE: at loose
    !! tolerances E5 needs more than the classic 7)
    integer, parameter :: MAX_ERROR_FAILS = 20
    integer, parameter :: MAX_CONV_FAILS = 10      !< consecutive Newton failures allowed
    real(wp), parameter :: EXTRA_CHECK = 2.0_wp    !< limit of |y_MEBDF - ybar_BDF|_w
    !> Safety factors of the step-size ratio at the same, the lower and the higher order.
    !! The classic codes use 1.5, 1.6, 1.7; the error test measures the BDF (order k)
    !! error while the solution is of order k+1, so smaller factors are safe: with
    !! 1.2/1.3/1.4 the test-set step counts at equal accuracy drop by 10-20 % with no
    !! more rejections worth noting (docs/theory/mebdf.md).
    real(wp), parameter :: SAFETY_SAME = 1.2_wp, SAFETY_DOWN = 1.3_wp, SAFETY_UP = 1.4_wp
    !> Safety factor of the new step after a failed error test (the classic value).
    real(wp), parameter :: SAFETY_FAILED = 1.5_wp
    !> A step-size increase smaller than this is not worth a new iteration matrix.
    real(wp), parameter :: MIN_GROWTH = 1.2_wp

    !> Outcome of one stage solve.
    integer, parameter :: STAGE_OK = 0, STAGE_NO_CONVERGENCE = 1, STAGE_FATAL = 2, &
                          STAGE_RHS_FAILED = 3

    type, extends(integrator_t) :: mebdf_t
        private
        type(iteration_matrix_t) :: matrix
        type(mebdf_coefficients_t) :: coef(KMAX_MEBDF)
        type(solver_stats_t) :: counters
        type(switch_log_t) :: log  !< the order limit lowered at the start (light damping)
        integer :: nt = 0          !< n + nq
        integer :: kmax = 0        !< highest number of steps (max_order - 1)
        integer :: k = 1           !< current number of steps (order k + 1)
        real(wp) :: t = 0.0_wp     !< time of the last accepted step
        real(wp) :: h = 0.0_wp     !< step size of the history (the next step's size)
        real(wp) :: h_used = 0.0_wp  !< size of the last accepted step
        logical :: started = .false.     !< the first step size is chosen
        logical :: pending = .false.     !< a step-size/order change waits for the next step
        real(wp) :: pending_ratio = 1.0_wp
        integer :: pending_k = 1
        integer :: steps_at_h = 0        !< steps since the last change of h or k
        integer :: jacobian_age = 0      !< steps since J was evaluated
        logical :: jacobian_current = .false.  !< J evaluated at the current (t, y)
        logical :: any_failure = .false.   !< some step has failed (no first-step boost)
        logical :: recent_failure = .false. !< a step failed since h last grew (growth <= 2)
        logical :: fixed = .false.       !< constant step and order, no error test (tests)
        real(wp) :: crate = 1.0_wp       !< Newton contraction rate estimate
        !> backward differences of the history at t: dif(:, 0) = y_n, dif(:, j) = nabla^j y_n
        real(wp), allocatable :: dif(:, :)
        real(wp), allocatable :: atol(:)  !< absolute tolerance per component (nt)
        real(wp), allocatable :: w(:)     !< error weights rtol |y| + atol (nt)
        real(wp), allocatable :: wi(:)    !< their inverses (the norms multiply)
        !> work (n): F, M times the correction and the Newton correction
        real(wp), allocatable :: f(:), mv(:), r(:)
        !> work of a step (nt), allocated once: stage 1's predictor (kept for the history
        !! update), a stage's known part c, the stage solutions ybar1, ybar2, y3, ybar1's
        !! correction d1 and the slopes h g of stages 1 and 2, and a temporary (stage 2's
        !! partial sums of the differences, the new difference, the vectors of norms)
        real(wp), allocatable :: pred(:), c(:), ybar1(:), ybar2(:), y3(:), d1(:), hg1(:), &
                                 hg2(:), tmp(:)
        real(wp), allocatable :: gq(:)    !< quadrature rhs (nq)
    contains
        procedure :: start => mebdf_start
        procedure :: advance_to => mebdf_advance_to
        procedure :: stats => mebdf_stats
        procedure :: finalize => mebdf_finalize
        procedure :: name => mebdf_name
        procedure :: start_fixed => mebdf_start_fixed
        procedure :: switch_log => mebdf_switch_log
        procedure, private :: initial_step
        procedure, private :: initial_slope
        procedure, private :: try_step
        procedure, private :: stage
        procedure, private :: prepare_matrix
        procedure, private :: wnorm
        procedure, private :: rescale
        procedure, private :: interpolate
        procedure, private :: failure
    end type mebdf_t

    interface
        !> Evaluate J if needed and factor M - h beta J if h beta moved too far.
        module subroutine prepare_matrix(self, hbeta, refresh, status)
            class(mebdf_t), intent(inout) :: self
            real(wp), intent(in) :: hbeta
            logical, intent(in) :: refresh   !< force a new Jacobian
            integer, intent(out) :: status
        end subroutine prepare_matrix

        !> Solve M(tn, y)(y - c) = h beta F(tn, y) for y (start: z on entry) by the chord
        !! Newton method with the current factors; the quadratures follow explicitly:
        !! yq = cq + h beta g(tn, y). On return z holds the stage solution.
        module subroutine stage(self, tn, hbeta, c, z, outcome)
            class(mebdf_t), intent(inout) :: self
            real(wp), intent(in) :: tn
            real(wp), intent(in) :: hbeta
            real(wp), contiguous, intent(in) :: c(:)
            real(wp), contiguous, intent(inout) :: z(:)
            integer, intent(out) :: outcome
        end subroutine stage

        !> Attempt steps until one is accepted (or the integration fails).
        module subroutine try_step(self, err)
            class(mebdf_t), intent(inout) :: self
            type(error_t), allocatable, intent(out) :: err
        end subroutine try_step

        !> The error of a failed integration: time, step size and cause.
        module subroutine failure(self, err, cause)
            class(mebdf_t), intent(in) :: self
            type(error_t), allocatable, intent(out) :: err
            character(len=*), intent(in) :: cause
        end subroutine failure

        !> Value of the history polynomial at time tt (within the last step): the Newton
        !! backward form through the k + 2 points y_n, ..., y_{n-k-1}.
        module subroutine interpolate(self, tt, z)
            class(mebdf_t), intent(in) :: self
            real(wp), intent(in) :: tt
            real(wp), intent(out) :: z(:)
        end subroutine interpolate

        !> The slope y'(t) (M^{-1} F for a problem with a mass matrix) and the quadrature rhs.
        module subroutine initial_slope(self, t, z, slope, status)
            class(mebdf_t), intent(inout) :: self
            real(wp), intent(in) :: t
            real(wp), intent(in) :: z(:)
            real(wp), intent(out) :: slope(:)
            integer, intent(out) :: status
        end subroutine initial_slope

        !> First step size from an estimate of y'' (the first step has order 2 with a
        !! first-order error test: err ~ h^2 |y''|_w / tq(1)), bounded by the span to the
        !! first output time; sets dif(:, 1) = h y'(t0).
        module subroutine initial_step(self, span, err)
            class(mebdf_t), intent(inout) :: self
            real(wp), intent(in) :: span
            type(error_t), allocatable, intent(out) :: err
        end subroutine initial_step

        !> Weighted RMS norm of v, the maximum of the state's and the quadratures' norms.
        module pure real(wp) function wnorm(self, v)
            class(mebdf_t), intent(in) :: self
            real(wp), contiguous, intent(in) :: v(:)
        end function wnorm

        !> Rescale the differences 1 .. kk to a step size ratio*h (interpolation of the
        !! history polynomial at the new spacing; Shampine & Reichelt 1997).
        module subroutine rescale(self, ratio, kk)
            class(mebdf_t), intent(inout) :: self
            real(wp), intent(in) :: ratio
            integer, intent(in) :: kk
        end subroutine rescale
    end interface

contains

    pure function mebdf_name(self) result(name)
        class(mebdf_t), intent(in) :: self
        character(len=:), allocatable :: name
        name = 'mebdf'
    end function mebdf_name

    subroutine mebdf_start(self, start, err)
        class(mebdf_t), intent(inout) :: self
        type(start_t), intent(in) :: start
        type(error_t), allocatable, intent(out) :: err
        integer :: j

        self%nt = self%n + self%nq
        self%kmax = start%max_order - 1
        call self%log%clear()
        call safe_start_order(self, start)
        do j = 1, KMAX_MEBDF
            self%coef(j) = mebdf_coefficients(j)
        end do
        allocate (self%dif(self%nt, 0:KMAX_MEBDF + 2), self%atol(self%nt), self%w(self%nt), &
                  self%wi(self%nt))
        allocate (self%f(self%n), self%mv(self%n), self%r(self%n), &
                  self%gq(max(self%nq, 1)))
        allocate (self%pred(self%nt), self%c(self%nt), self%ybar1(self%nt), &
                  self%ybar2(self%nt), self%y3(self%nt), self%d1(self%nt), self%hg1(self%nt), &
                  self%hg2(self%nt), self%tmp(self%nt))
        self%atol = self%options%atol
        if (allocated(self%options%atol_vector)) self%atol(1:self%n) = self%options%atol_vector
        self%dif = 0.0_wp
        self%dif(1:self%n, 0) = start%y0
        if (self%nq > 0) self%dif(self%n + 1:, 0) = start%yq0
        self%t = start%t0
        self%k = 1
        self%started = .false.
        self%pending = .false.
        self%steps_at_h = 0
        self%jacobian_age = 0
        self%jacobian_current = .false.
        self%any_failure = .false.
        self%recent_failure = .false.
        self%fixed = .false.
        self%crate = 1.0_wp
        self%counters = solver_stats_t()
        call self%matrix%setup(self%problem, implicit_form=.true., &
                               first_order=self%options%first_order_newton, &
                               fd_jacobian=self%options%fd_jacobian)
    end subroutine mebdf_start

    !> The order limit at the start: above the safe (A-stable) order, a mechanical problem
    !! whose fast modes are lightly damped (the settled Ritz values of the spectrum at the
    !! initial state damped by less than LIGHT_DAMPING) starts at the safe order, with a
    !! warning in the log. Orders 5 .. 7 amplify such modes (up to 1.027 .. 1.114 per step on
    !! the imaginary axis), and the order safety of the run driver acts only on a gain of
    !! energy_gain_bound (10) rtol S, S the energy the run moves (about 0.8 m g L on the
    !! lightly damped paper rope: a gain of about 8 rtol m g L, four times the 2 rtol m g L
    !! a run should keep to; docs/validation/order-safety.md).
    subroutine safe_start_order(self, start)
        class(mebdf_t), intent(inout) :: self
        type(start_t), intent(in) :: start
        type(spectrum_t) :: spec
        integer :: safe
        character(len=200) :: text
        safe = METHODS(method_index(self%name()))%safe_order
        if (start%max_order <= safe .or. .not. self%problem%has_second_order()) return
        call estimate_spectrum(self%problem, start%t0, start%y0, spec)
        if (.not. spec%valid) return
        if (spec%settled_damping() >= LIGHT_DAMPING) return
        self%kmax = safe - 1
        write (text, '(a, i0, a, i0, a, f6.4, a)') 'max order ', start%max_order, &
            ' lowered to ', safe, ' at the start: the fast modes are damped by ', &
            spec%settled_damping(), ' (below 1 %), which MEBDF''s orders above 4 amplify'
        call self%log%add(start%t0, self%name(), safe, trim(text), .true.)
    end subroutine safe_start_order

    !> The order limit lowered at the start, if it was (safe_start_order).
    function mebdf_switch_log(self) result(events)
        class(mebdf_t), intent(in) :: self
        type(switch_event_t), allocatable :: events(:)
        events = self%log%items()
    end function mebdf_switch_log

    !> Switch an initialized integrator to constant step h and constant k (order k + 1)
    !! without error test, starting from the exact past values past(:, i) = y(t0 - i h),
    !! i = 0 .. k+1 (past(:, 0) replaces the initial state). Used to measure the order.
    subroutine mebdf_start_fixed(self, h, k, past, err)
        class(mebdf_t), intent(inout) :: self
        real(wp), intent(in) :: h
        integer, intent(in) :: k
        real(wp), intent(in) :: past(:, 0:)
        type(error_t), allocatable, intent(out) :: err
        integer :: i, j
        if (k < 1 .or. k > KMAX_MEBDF .or. ubound(past, 2) < k + 1 .or. &
            size(past, 1) /= self%nt .or. .not. h > 0.0_wp) then
            call make_error(err, ERR_SOLVER, 'mebdf: start_fixed: bad arguments')
            return
        end if
        ! Backward differences of y_0, y_{-1}, ...: dif_j = nabla^j y_0.
        self%dif = 0.0_wp
        do j = 0, k + 1
            do i = 0, j
                self%dif(:, j) = self%dif(:, j) + real((-1)**i, wp)*binomial(j, i)*past(:, i)
            end do
        end do
        self%k = k
        self%kmax = k
        self%h = h
        self%h_used = h
        self%fixed = .true.
        self%started = .true.
        self%steps_at_h = 0
    end subroutine mebdf_start_fixed

    pure real(wp) function binomial(n, m)
        integer, intent(in) :: n, m
        integer :: i
        binomial = 1.0_wp
        do i = 1, m
            binomial = binomial*real(n - m + i, wp)/real(i, wp)
        end do
    end function binomial

    function mebdf_stats(self) result(stats)
        class(mebdf_t), intent(in) :: self
        type(solver_stats_t) :: stats
        stats = self%counters
        stats%reduced_newton = self%matrix%is_reduced()
    end function mebdf_stats

    subroutine mebdf_finalize(self)
        class(mebdf_t), intent(inout) :: self
        self%problem => null()
        if (allocated(self%dif)) deallocate (self%dif)
        if (allocated(self%atol)) deallocate (self%atol)
        if (allocated(self%w)) deallocate (self%w, self%wi)
        if (allocated(self%f)) deallocate (self%f, self%mv, self%r)
        if (allocated(self%gq)) deallocate (self%gq)
        if (allocated(self%pred)) deallocate (self%pred, self%c, self%ybar1, self%ybar2, &
                                              self%y3, self%d1, self%hg1, self%hg2, self%tmp)
    end subroutine mebdf_finalize

    subroutine mebdf_advance_to(self, tout, t, y, yq, err)
        class(mebdf_t), intent(inout) :: self
        real(wp), intent(in) :: tout
        real(wp), intent(out) :: t
        real(wp), intent(inout) :: y(:)
        real(wp), intent(inout) :: yq(:)
        type(error_t), allocatable, intent(out) :: err
        real(wp) :: z(self%nt)

        t = self%t
        if (.not. associated(self%problem)) then
            call make_error(err, ERR_SOLVER, 'mebdf: advance_to called before init')
            return
        end if
        if (.not. self%started) then
            if (tout <= self%t) then
                y = self%dif(1:self%n, 0)
                if (self%nq > 0) yq(1:self%nq) = self%dif(self%n + 1:, 0)
                return
            end if
            call self%initial_step(tout - self%t, err)
            if (allocated(err)) return
            self%started = .true.
        else if (tout < self%t - self%h_used*(1.0_wp + 8.0_wp*epsilon(1.0_wp))) then
            call make_error(err, ERR_SOLVER, 'mebdf: output time lies before the last step')
            return
        end if

        do while (self%t < tout)
            call self%try_step(err)
            if (allocated(err)) then
                t = self%t
                y = self%dif(1:self%n, 0)
                if (self%nq > 0) yq(1:self%nq) = self%dif(self%n + 1:, 0)
                return
            end if
            if (self%t < tout .and. self%stop_here(self%counters%steps)) then
                ! stopped early (on request, at the step cap): the state of this step
                t = self%t
                y = self%dif(1:self%n, 0)
                if (self%nq > 0) yq(1:self%nq) = self%dif(self%n + 1:, 0)
                return
            end if
        end do
        if (self%t == tout .and. tout == self%t_stop) then
            ! the step ended at the stop time: its own end point
            y = self%dif(1:self%n, 0)
            if (self%nq > 0) yq(1:self%nq) = self%dif(self%n + 1:, 0)
        else
            call self%interpolate(tout, z)
            y = z(1:self%n)
            if (self%nq > 0) yq(1:self%nq) = z(self%n + 1:)
        end if
        t = tout
    end subroutine mebdf_advance_to

end module ropedyn_mebdf
