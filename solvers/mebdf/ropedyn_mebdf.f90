!> Cash's modified extended backward differentiation formulas (MEBDF) behind the
!! integrator interface: variable step, variable order 2 .. 7, for y' = f(t, y) and for
!! linearly implicit problems M(t, y) y' = F(t, y).
!!
!! One step of order k+1 from t_n to t_n + h (docs/solvers.md, section 1):
!!  1. k-step BDF for ybar_{n+1};
!!  2. k-step BDF one step further for ybar_{n+2}, with ybar_{n+1} in the history;
!!  3. the modified extended corrector for y_{n+1}, using the slopes of stages 1 and 2.
!! All three stages share one Newton (iteration) matrix M - h beta_k J.
!!
!! Formulation (see docs/mebdf.md): fixed-step coefficients on a backward-difference
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
module ropedyn_mebdf
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use ropedyn_kinds, only: wp, i8
    use ropedyn_text, only: int_text
    use ropedyn_error, only: error_t, make_error, ERR_SOLVER
    use ropedyn_problem, only: problem_t, STATUS_OK, STATUS_FATAL
    use ropedyn_integrator, only: integrator_t, solver_options_t, solver_stats_t
    use ropedyn_mebdf_coefficients, only: mebdf_coefficients_t, mebdf_coefficients, KMAX_MEBDF
    use ropedyn_iteration_matrix, only: iteration_matrix_t
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
    !! more rejections worth noting (docs/mebdf.md).
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
        class(problem_t), pointer :: problem => null()
        type(solver_options_t) :: options
        type(iteration_matrix_t) :: matrix
        type(mebdf_coefficients_t) :: coef(KMAX_MEBDF)
        type(solver_stats_t) :: counters
        integer :: n = 0           !< unknowns of the Newton system
        integer :: nq = 0          !< quadrature variables
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
        real(wp), allocatable :: f(:), mv(:), r(:)  !< work (n)
        real(wp), allocatable :: gq(:)    !< quadrature rhs (nq)
    contains
        procedure :: init => mebdf_init
        procedure :: advance_to => mebdf_advance_to
        procedure :: stats => mebdf_stats
        procedure :: finalize => mebdf_finalize
        procedure :: name => mebdf_name
        procedure :: start_fixed => mebdf_start_fixed
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

contains

    pure function mebdf_name(self) result(name)
        class(mebdf_t), intent(in) :: self
        character(len=:), allocatable :: name
        name = 'mebdf'
    end function mebdf_name

    subroutine mebdf_init(self, problem, t0, y0, yq0, options, err)
        class(mebdf_t), intent(inout) :: self
        class(problem_t), intent(inout), target :: problem
        real(wp), intent(in) :: t0
        real(wp), intent(in) :: y0(:)
        real(wp), intent(in) :: yq0(:)
        type(solver_options_t), intent(in) :: options
        type(error_t), allocatable, intent(out) :: err
        integer :: max_order, j

        call self%finalize()
        self%problem => problem
        self%options = options
        self%n = problem%size()
        self%nq = problem%quad_size()
        self%nt = self%n + self%nq
        max_order = options%max_order
        if (max_order == 0) max_order = self%default_max_order()
        if (max_order < self%min_order() .or. max_order > self%max_order_limit()) then
            call make_error(err, ERR_SOLVER, 'mebdf: max_order must be 2 .. 7')
            return
        end if
        if (options%stab_lim_det) then
            call make_error(err, ERR_SOLVER, 'mebdf: stability-limit detection is a CVODE ' &
                            //'option (MEBDF up to order 4 is A-stable: use max_order)')
            return
        end if
        if (.not. (options%rtol > 0.0_wp .and. options%atol > 0.0_wp)) then
            call make_error(err, ERR_SOLVER, 'mebdf: rtol and atol must be > 0')
            return
        end if
        if (size(y0) /= self%n .or. size(yq0) < self%nq) then
            call make_error(err, ERR_SOLVER, 'mebdf: initial state of the wrong size')
            return
        end if
        self%kmax = max_order - 1
        do j = 1, KMAX_MEBDF
            self%coef(j) = mebdf_coefficients(j)
        end do
        allocate (self%dif(self%nt, 0:KMAX_MEBDF + 2), self%atol(self%nt), self%w(self%nt))
        allocate (self%f(self%n), self%mv(self%n), self%r(self%n), self%gq(max(self%nq, 1)))
        self%atol = options%atol
        if (allocated(options%atol_vector)) then
            if (size(options%atol_vector) /= self%n) then
                call make_error(err, ERR_SOLVER, 'mebdf: atol_vector has the wrong size')
                return
            end if
            self%atol(1:self%n) = options%atol_vector
        end if
        self%dif = 0.0_wp
        self%dif(1:self%n, 0) = y0
        if (self%nq > 0) self%dif(self%n + 1:, 0) = yq0(1:self%nq)
        self%t = t0
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
        call self%matrix%setup(problem)
    end subroutine mebdf_init

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
    end function mebdf_stats

    subroutine mebdf_finalize(self)
        class(mebdf_t), intent(inout) :: self
        self%problem => null()
        if (allocated(self%dif)) deallocate (self%dif)
        if (allocated(self%atol)) deallocate (self%atol)
        if (allocated(self%w)) deallocate (self%w)
        if (allocated(self%f)) deallocate (self%f, self%mv, self%r)
        if (allocated(self%gq)) deallocate (self%gq)
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
        end do
        call self%interpolate(tout, z)
        y = z(1:self%n)
        if (self%nq > 0) yq(1:self%nq) = z(self%n + 1:)
        t = tout
    end subroutine mebdf_advance_to

    !> Value of the history polynomial at time tt (within the last step): the Newton
    !! backward form through the k + 2 points y_n, ..., y_{n-k-1}.
    subroutine interpolate(self, tt, z)
        class(mebdf_t), intent(in) :: self
        real(wp), intent(in) :: tt
        real(wp), intent(out) :: z(:)
        real(wp) :: s, term
        integer :: j
        z = self%dif(:, 0)
        if (tt == self%t .or. self%h_used == 0.0_wp) return
        s = (tt - self%t)/self%h_used
        term = 1.0_wp
        do j = 1, self%k + 1
            term = term*(s + real(j - 1, wp))/real(j, wp)
            z = z + term*self%dif(:, j)
        end do
    end subroutine interpolate

    !> The slope y'(t) (M^{-1} F for a problem with a mass matrix) and the quadrature rhs.
    subroutine initial_slope(self, t, z, slope, status)
        class(mebdf_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: z(:)
        real(wp), intent(out) :: slope(:)
        integer, intent(out) :: status
        if (self%problem%has_mass_matrix()) then
            call self%problem%implicit_rhs(t, z(1:self%n), slope(1:self%n), status)
            self%counters%rhs_evals = self%counters%rhs_evals + 1
            if (status /= STATUS_OK) return
            call self%matrix%factor(self%problem, t, z(1:self%n), 0.0_wp, status)
            self%counters%lin_setups = self%counters%lin_setups + 1
            if (status /= STATUS_OK) return
            call self%matrix%solve(slope(1:self%n))
            self%matrix%factored = .false.
        else
            call self%problem%rhs(t, z(1:self%n), slope(1:self%n), status)
            self%counters%rhs_evals = self%counters%rhs_evals + 1
            if (status /= STATUS_OK) return
        end if
        if (self%nq > 0) call self%problem%quad_rhs(t, z(1:self%n), slope(self%n + 1:), status)
    end subroutine initial_slope

    !> First step size from an estimate of y'' (the first step has order 2 with a
    !! first-order error test: err ~ h^2 |y''|_w / tq(1)), bounded by the span to the
    !! first output time; sets dif(:, 1) = h y'(t0).
    subroutine initial_step(self, span, err)
        class(mebdf_t), intent(inout) :: self
        real(wp), intent(in) :: span
        type(error_t), allocatable, intent(out) :: err
        real(wp) :: y0(self%nt), yp0(self%nt), yp1(self%nt), ytmp(self%nt)
        real(wp) :: hlb, hub, hg, hnew, ypnorm, yddnorm
        integer :: status, iter

        y0 = self%dif(:, 0)
        call self%initial_slope(self%t, y0, yp0, status)
        if (status /= STATUS_OK) then
            call make_error(err, ERR_SOLVER, 'mebdf failed at the initial time: the '// &
                            'right-hand side could not be evaluated at the initial state')
            return
        end if
        self%w = self%options%rtol*abs(y0) + self%atol
        ypnorm = self%wnorm(yp0)
        hlb = 100.0_wp*epsilon(1.0_wp)*max(abs(self%t), abs(self%t + span))
        hub = 0.1_wp*span
        if (ypnorm*hub > 1.0_wp) hub = 1.0_wp/ypnorm
        hg = sqrt(hlb*hub)
        if (hub < hlb) then
            ! fast initial change near a large time (CVODE's rule): the geometric mean
            self%h = hg
            self%h_used = 0.0_wp
            self%dif(:, 1) = self%h*yp0
            self%dif(:, 2:) = 0.0_wp
            self%k = 1
            self%steps_at_h = 0
            return
        end if
        hnew = hub
        do iter = 1, 4
            ytmp = y0 + hg*yp0
            call self%initial_slope(self%t + hg, ytmp, yp1, status)
            if (status /= STATUS_OK) then
                hg = 0.2_wp*hg
                cycle
            end if
            yddnorm = self%wnorm((yp1 - yp0)/hg)
            if (yddnorm*hub*hub > 2.0_wp*self%coef(1)%tq) then
                hnew = sqrt(2.0_wp*self%coef(1)%tq/yddnorm)
            else
                hnew = hub
            end if
            if (hnew > 0.5_wp*hg .and. hnew < 2.0_wp*hg) exit
            hg = hnew
        end do
        self%h = min(max(0.5_wp*hnew, hlb), hub)
        self%h_used = 0.0_wp
        self%dif(:, 1) = self%h*yp0
        self%dif(:, 2:) = 0.0_wp
        self%k = 1
        self%steps_at_h = 0
    end subroutine initial_step

    !> Weighted RMS norm of v, the maximum of the state's and the quadratures' norms.
    pure real(wp) function wnorm(self, v)
        class(mebdf_t), intent(in) :: self
        real(wp), intent(in) :: v(:)
        wnorm = sqrt(sum((v(1:self%n)/self%w(1:self%n))**2)/real(self%n, wp))
        if (self%nq > 0) wnorm = max(wnorm, sqrt(sum((v(self%n + 1:self%nt)/ &
                                                       self%w(self%n + 1:self%nt))**2)/ &
                                                  real(self%nq, wp)))
    end function wnorm

    !> Rescale the differences 1 .. kk to a step size ratio*h (interpolation of the
    !! history polynomial at the new spacing; Shampine & Reichelt 1997).
    subroutine rescale(self, ratio, kk)
        class(mebdf_t), intent(inout) :: self
        real(wp), intent(in) :: ratio
        integer, intent(in) :: kk
        real(wp) :: rmat(kk, kk), umat(kk, kk), ru(kk, kk), tmp(self%nt, kk)
        integer :: i, j
        do j = 1, kk
            rmat(1, j) = -real(j, wp)*ratio
            umat(1, j) = -real(j, wp)
            do i = 2, kk
                rmat(i, j) = rmat(i - 1, j)*(real(i - 1, wp) - real(j, wp)*ratio)/real(i, wp)
                umat(i, j) = umat(i - 1, j)*(real(i - 1, wp) - real(j, wp))/real(i, wp)
            end do
        end do
        ru = matmul(rmat, umat)
        tmp = matmul(self%dif(:, 1:kk), ru)
        self%dif(:, 1:kk) = tmp
        self%h = self%h*ratio
    end subroutine rescale

    !> Evaluate J if needed and factor M - h beta J if h beta moved too far.
    subroutine prepare_matrix(self, hbeta, refresh, status)
        class(mebdf_t), intent(inout) :: self
        real(wp), intent(in) :: hbeta
        logical, intent(in) :: refresh   !< force a new Jacobian
        integer, intent(out) :: status
        logical :: new_jacobian
        status = STATUS_OK
        new_jacobian = refresh .or. self%jacobian_age >= JACOBIAN_MAX_AGE .or. &
                       self%counters%jac_evals == 0
        if (new_jacobian .and. .not. self%jacobian_current) then
            call self%matrix%evaluate_jacobian(self%problem, self%t, self%dif(1:self%n, 0), &
                self%w, self%h, self%options%fd_jacobian .or. &
                .not. self%problem%has_implicit_jacobian(), status, &
                self%counters%jac_rhs_evals)
            self%counters%jac_evals = self%counters%jac_evals + 1
            if (status /= STATUS_OK) return
            self%jacobian_age = 0
            self%jacobian_current = .true.
            self%matrix%factored = .false.
        end if
        if (.not. self%matrix%factored .or. &
            abs(hbeta - self%matrix%hbeta) > REFACTOR_CHANGE*abs(self%matrix%hbeta)) then
            call self%matrix%factor(self%problem, self%t, self%dif(1:self%n, 0), hbeta, status)
            self%counters%lin_setups = self%counters%lin_setups + 1
            self%crate = 1.0_wp
        end if
    end subroutine prepare_matrix

    !> Solve M(tn, y)(y - c) = h beta F(tn, y) for y (start: z on entry) by the chord
    !! Newton method with the current factors; the quadratures follow explicitly:
    !! yq = cq + h beta g(tn, y). On return z holds the stage solution.
    subroutine stage(self, tn, hbeta, c, z, outcome)
        class(mebdf_t), intent(inout) :: self
        real(wp), intent(in) :: tn
        real(wp), intent(in) :: hbeta
        real(wp), intent(in) :: c(:)
        real(wp), intent(inout) :: z(:)
        integer, intent(out) :: outcome
        real(wp) :: dnorm, dnorm_old, dcon
        integer :: iter, status, n
        logical :: mass

        n = self%n
        mass = self%problem%has_mass_matrix()
        outcome = STAGE_NO_CONVERGENCE
        dnorm_old = 0.0_wp
        do iter = 1, MAX_NEWTON_ITERS
            call self%problem%implicit_rhs(tn, z(1:n), self%f, status)
            self%counters%rhs_evals = self%counters%rhs_evals + 1
            if (status /= STATUS_OK) then
                outcome = merge(STAGE_FATAL, STAGE_RHS_FAILED, status == STATUS_FATAL)
                return
            end if
            if (mass) then
                call self%matrix%mass_times(self%problem, tn, z(1:n), z(1:n) - c(1:n), &
                                            self%mv, status)
                if (status /= STATUS_OK) then
                    if (status == STATUS_FATAL) outcome = STAGE_FATAL
                    return
                end if
                self%r = hbeta*self%f - self%mv
            else
                self%r = hbeta*self%f - (z(1:n) - c(1:n))
            end if
            call self%matrix%solve(self%r)
            self%counters%nonlin_iters = self%counters%nonlin_iters + 1
            if (.not. all(ieee_is_finite(self%r))) return
            z(1:n) = z(1:n) + self%r
            dnorm = sqrt(sum((self%r/self%w(1:n))**2)/real(n, wp))
            if (iter > 1) then
                if (dnorm > 2.0_wp*dnorm_old) return
                self%crate = max(0.3_wp*self%crate, dnorm/dnorm_old)
            end if
            dcon = dnorm*min(1.0_wp, self%crate)
            if (dcon <= NEWTON_TOL .or. dnorm == 0.0_wp) then
                outcome = STAGE_OK
                exit
            end if
            dnorm_old = dnorm
        end do
        if (outcome /= STAGE_OK) return
        if (self%nq > 0) then
            call self%problem%quad_rhs(tn, z(1:n), self%gq, status)
            if (status /= STATUS_OK) then
                outcome = merge(STAGE_FATAL, STAGE_RHS_FAILED, status == STATUS_FATAL)
                return
            end if
            z(n + 1:) = c(n + 1:) + hbeta*self%gq(1:self%nq)
        end if
    end subroutine stage

    !> Attempt steps until one is accepted (or the integration fails).
    subroutine try_step(self, err)
        class(mebdf_t), intent(inout) :: self
        type(error_t), allocatable, intent(out) :: err
        real(wp), dimension(self%nt) :: pred, psi, c, ybar1, ybar2, y3, d1, hg1, hg2, p2
        real(wp) :: gam(KMAX_MEBDF), hmin, tn, err1, errkm1, errkp1, beta, hbeta
        real(wp) :: ratio, r_same, r_down, r_up, binom
        integer :: k, j, i, outcome, status, error_fails, conv_fails, knew
        logical :: refresh
        character(len=:), allocatable :: last_cause

        gam = 1.0_wp/self%coef%beta   ! gamma_j = sum_{i<=j} 1/i = 1/beta_j
        error_fails = 0
        conv_fails = 0
        refresh = .false.
        last_cause = 'none'
        attempts: do
            if (self%pending) then
                if (self%pending_k /= self%k) then
                    self%k = self%pending_k
                end if
                if (self%pending_ratio /= 1.0_wp) call self%rescale(self%pending_ratio, self%k)
                self%pending = .false.
                self%steps_at_h = 0
            end if
            k = self%k
            beta = self%coef(k)%beta
            hbeta = self%h*beta
            tn = self%t + self%h
            hmin = 16.0_wp*epsilon(1.0_wp)*max(abs(self%t), abs(tn))
            if (self%counters%steps >= self%options%max_steps) then
                call self%failure(err, 'max_steps exceeded ('// &
                                  trim(int_text(self%options%max_steps))//' steps)')
                return
            end if
            if (self%h < hmin) then
                call self%failure(err, 'step size fell below the round-off limit after: '// &
                                  last_cause)
                return
            end if
            self%w = self%options%rtol*abs(self%dif(:, 0)) + self%atol

            call self%prepare_matrix(hbeta, refresh, status)
            refresh = .false.
            if (status /= STATUS_OK) then
                if (status == STATUS_FATAL) then
                    call self%failure(err, 'the Jacobian or mass matrix could not be evaluated')
                    return
                end if
                call newton_failed(STAGE_NO_CONVERGENCE)
                if (allocated(err)) return
                cycle attempts
            end if

            ! Stage 1: k-step BDF to t_n + h.
            pred = sum(self%dif(:, 0:k), dim=2)
            psi = 0.0_wp
            do j = 1, k
                psi = psi + gam(j)*self%dif(:, j)
            end do
            ! With P_j = sum_{i>=j} dif_i (the predictor's differences), psi above is
            ! sum_{j=1..k} (1/j) P_j, the BDF's known part.
            c = pred - beta*psi
            ybar1 = pred
            call self%stage(tn, hbeta, c, ybar1, outcome)
            if (outcome /= STAGE_OK) then
                call newton_failed(outcome)
                if (allocated(err)) return
                cycle attempts
            end if
            hg1 = (ybar1 - c)/beta
            d1 = ybar1 - pred
            err1 = self%wnorm(d1)/self%coef(k)%tq
            if (self%fixed) err1 = 0.0_wp
            if (.not. (err1 <= 1.0_wp)) then
                call error_failed(err1)
                if (allocated(err)) return
                cycle attempts
            end if

            ! Stage 2: the same BDF one step further, ybar1 joining the history. With
            ! P_j = sum_{i=j..k} dif_i, the differences of ybar1 are P_j + d1; the
            ! predictor is their sum and psi = sum_{i=1..k} gam(i) (P_i + d1).
            pred = ybar1
            psi = 0.0_wp
            p2 = 0.0_wp
            do i = k, 1, -1
                p2 = p2 + self%dif(:, i)
                pred = pred + p2 + d1
                psi = psi + gam(i)*(p2 + d1)
            end do
            c = pred - beta*psi
            ybar2 = pred
            call self%stage(tn + self%h, hbeta, c, ybar2, outcome)
            if (outcome /= STAGE_OK) then
                call newton_failed(outcome)
                if (allocated(err)) return
                cycle attempts
            end if
            hg2 = (ybar2 - c)/beta

            ! Stage 3: the modified extended corrector. Old values y_{n-i} from the
            ! differences: y_{n-i} = sum_{j=0..i} (-1)^j binom(i, j) dif_j.
            c = (self%coef(k)%bhat_k - beta)*hg1 + self%coef(k)%bhat_k1*hg2
            do i = 0, k - 1
                ! point n - i has index k - 1 - i in the corrector's numbering
                p2 = 0.0_wp
                binom = 1.0_wp
                do j = 0, i
                    p2 = p2 + binom*self%dif(:, j)
                    binom = -binom*real(i - j, wp)/real(j + 1, wp)
                end do
                c = c - self%coef(k)%ahat(k - 1 - i)*p2
            end do
            y3 = ybar1
            call self%stage(tn, hbeta, c, y3, outcome)
            if (outcome /= STAGE_OK) then
                call newton_failed(outcome)
                if (allocated(err)) return
                cycle attempts
            end if
            if (.not. (self%wnorm(y3 - ybar1) <= EXTRA_CHECK .or. self%fixed)) then
                call error_failed(max(err1, 1.01_wp))
                if (allocated(err)) return
                cycle attempts
            end if
            exit attempts
        end do attempts

        ! Accepted. Order-change estimates (BDF errors at orders k-1 and k+1) use the old
        ! differences; then the history moves to t_n + h with the MEBDF value.
        errkm1 = huge(1.0_wp)
        errkp1 = huge(1.0_wp)
        if (k > 1) errkm1 = self%wnorm(self%dif(:, k) + d1)/self%coef(k - 1)%tq
        if (k < self%kmax .and. self%steps_at_h >= k + 1) then
            errkp1 = self%wnorm(d1 - self%dif(:, k + 1))/self%coef(k + 1)%tq
        end if
        d1 = y3 - sum(self%dif(:, 0:k), dim=2)
        self%dif(:, k + 2) = d1 - self%dif(:, k + 1)
        self%dif(:, k + 1) = d1
        do j = k, 0, -1
            self%dif(:, j) = self%dif(:, j) + self%dif(:, j + 1)
        end do
        self%t = tn
        self%h_used = self%h
        self%counters%steps = self%counters%steps + 1
        self%counters%order_steps(k + 1) = self%counters%order_steps(k + 1) + 1
        self%counters%last_step = self%h
        self%counters%last_order = k + 1
        self%steps_at_h = self%steps_at_h + 1
        self%jacobian_age = self%jacobian_age + 1
        self%jacobian_current = .false.

        ! Step size and order for the next step (after k + 2 steps at this h and k).
        if (self%steps_at_h >= k + 2 .and. .not. self%fixed) then
            r_same = 1.0_wp/(SAFETY_SAME*max(err1, 1.0e-10_wp)**(1.0_wp/real(k + 1, wp)))
            r_down = 0.0_wp
            r_up = 0.0_wp
            if (k > 1) r_down = 1.0_wp/(SAFETY_DOWN*max(errkm1, 1.0e-10_wp)**(1.0_wp/real(k, wp)))
            if (errkp1 < huge(1.0_wp)) then
                r_up = 1.0_wp/(SAFETY_UP*max(errkp1, 1.0e-10_wp)**(1.0_wp/real(k + 2, wp)))
            end if
            knew = k
            ratio = r_same
            if (r_down > ratio) then
                knew = k - 1
                ratio = r_down
            end if
            if (r_up > ratio) then
                knew = k + 1
                ratio = r_up
            end if
            if (ratio > MIN_GROWTH .or. knew /= k) then
                ratio = min(ratio, merge(2.0_wp, 10.0_wp, self%recent_failure))
                self%recent_failure = .false.
                if (self%counters%steps <= k + 2 .and. .not. self%any_failure) &
                    ratio = min(max(ratio, 1.0_wp), 1.0e4_wp)
                ratio = max(ratio, 0.2_wp)
                self%pending = .true.
                self%pending_k = knew
                self%pending_ratio = ratio
            end if
        end if

    contains

        !> A stage failed: a fatal right-hand side ends the run; otherwise refresh an old
        !! Jacobian and retry, else cut the step by 4.
        subroutine newton_failed(why)
            integer, intent(in) :: why
            if (why == STAGE_FATAL) then
                call self%failure(err, 'the right-hand side reported a fatal error')
                return
            end if
            self%counters%nonlin_conv_fails = self%counters%nonlin_conv_fails + 1
            conv_fails = conv_fails + 1
            self%any_failure = .true.
            self%recent_failure = .true.
            if (why == STAGE_RHS_FAILED) then
                last_cause = 'repeated recoverable errors of the right-hand side (e.g. a NaN '// &
                             'or Inf in the forces) during the Newton iteration'
            else
                last_cause = 'repeated Newton convergence failures (or a singular '// &
                             'iteration matrix M - h beta J)'
            end if
            if (conv_fails > MAX_CONV_FAILS) then
                call self%failure(err, last_cause)
                return
            end if
            if (.not. self%jacobian_current .and. why /= STAGE_RHS_FAILED) then
                refresh = .true.
            else
                self%pending = .true.
                self%pending_k = self%k
                self%pending_ratio = 0.25_wp
            end if
        end subroutine newton_failed

        !> Local error test failed with normalized error e: smaller step, maybe lower order.
        subroutine error_failed(e)
            real(wp), intent(in) :: e
            real(wp) :: r
            self%counters%err_test_fails = self%counters%err_test_fails + 1
            error_fails = error_fails + 1
            last_cause = 'repeated local error test failures'
            self%any_failure = .true.
            self%recent_failure = .true.
            if (error_fails >= MAX_ERROR_FAILS) then
                call self%failure(err, 'repeated local error test failures')
                return
            end if
            self%pending = .true.
            self%pending_k = self%k
            if (error_fails >= 3) then
                self%pending_k = 1
                self%pending_ratio = 0.1_wp
                return
            end if
            r = 1.0_wp/(SAFETY_FAILED*e**(1.0_wp/real(self%k + 1, wp)))
            if (error_fails == 2) r = min(r, 0.5_wp)
            ! the first step may be far too large: allow a deeper cut there
            self%pending_ratio = min(max(r, merge(1.0e-3_wp, 0.1_wp, &
                                                  self%counters%steps == 0)), 0.9_wp)
            if (self%k > 1) then
                errkm1 = self%wnorm(self%dif(:, self%k) + d1)/self%coef(self%k - 1)%tq
                if (errkm1 < e) then
                    self%pending_k = self%k - 1
                    r = 1.0_wp/(SAFETY_FAILED*max(errkm1, 1.0e-10_wp)** &
                                (1.0_wp/real(self%k, wp)))
                    self%pending_ratio = min(max(r, 0.1_wp), 0.9_wp)
                end if
            end if
        end subroutine error_failed
    end subroutine try_step

    !> The error of a failed integration: time, step size and cause.
    subroutine failure(self, err, cause)
        class(mebdf_t), intent(in) :: self
        type(error_t), allocatable, intent(out) :: err
        character(len=*), intent(in) :: cause
        character(len=96) :: where
        write (where, '(a, es12.5, a, es10.3, a, i0)') 't = ', self%t, ' s, step size ', &
            self%h, ' s, order ', self%k + 1
        call make_error(err, ERR_SOLVER, 'mebdf failed at '//trim(where)//': '//cause)
    end subroutine failure

end module ropedyn_mebdf
