!> CVODE (BDF, Newton, band linear solver with the problem's analytic Jacobian) behind
!! the integrator interface.
!!
!! For a problem with second-order structure (ropedyn_problem) the Newton systems are solved
!! on the reduced matrix I - gamma C - gamma^2 K of the coordinates (ropedyn_iteration_matrix)
!! by a linear solver of our own: a direct SUNLinearSolver with an empty SUNMatrix and our
!! linear-system function (CVodeSetLinSysFn). CVODE keeps all its own rules that way: when to
!! set up (gamma changed by > 30 %, every 20 steps, after failures), when the Jacobian is
!! stale (jok: every 51 steps, after a convergence failure with an old one), the scaling of
!! the correction by 2/(1 + gamma/gamma_setup) for a lagged setup, its counters (submodule
!! ropedyn_cvode_linsol).
!!
!! We link CVODES, CVODE's superset from the same SUNDIALS release, for its quadrature
!! feature: the problem's quadrature variables (dissipated energy, support work) are then
!! integrated with error control but outside the Newton system. Every SUNDIALS-version
!! detail (6.4.1: `fsundials_context_mod`, the band-matrix data pointer of extent 1) is
!! kept inside this module.
module ropedyn_cvode
    use, intrinsic :: iso_c_binding
    use ropedyn_kinds, only: wp, i8
    use ropedyn_text, only: int_text, es_text
    use ropedyn_c_strings, only: c_string
    use ropedyn_error, only: error_t, make_error, ERR_SOLVER
    use ropedyn_problem, only: problem_t, STATUS_OK
    use ropedyn_integrator, only: integrator_t, start_t, solver_options_t, solver_stats_t
    use ropedyn_clock, only: clock_seconds
    use ropedyn_iteration_matrix, only: iteration_matrix_t, factored_dense
    use ropedyn_switch_log, only: switch_log_t, switch_event_t
    use fsundials_context_mod, only: FSUNContext_Create, FSUNContext_Free
    use fsundials_nvector_mod, only: N_Vector, FN_VDestroy, FN_VGetArrayPointer
    use fsundials_matrix_mod, only: SUNMatrix, FSUNMatDestroy, FSUNMatNewEmpty
    use fsundials_linearsolver_mod, only: SUNLinearSolver, FSUNLinSolFree
    use fnvector_serial_mod, only: FN_VMake_Serial
    use fsunmatrix_band_mod, only: FSUNBandMatrix, FSUNBandMatrix_Data, FSUNBandMatrix_LDim, &
                                   FSUNBandMatrix_StoredUpperBandwidth, FSUNBandMatrix_Columns
    use fsunlinsol_band_mod, only: FSUNLinSol_Band
    use fsunmatrix_dense_mod, only: FSUNDenseMatrix, FSUNDenseMatrix_Data
    use fsunlinsol_dense_mod, only: FSUNLinSol_Dense
    use fsundials_nonlinearsolver_mod, only: SUNNonlinearSolver, FSUNNonlinSolFree
    use fsunnonlinsol_fixedpoint_mod, only: FSUNNonlinSol_FixedPoint
    use fcvodes_mod
    implicit none
    private
    public :: cvode_t, adams_t
    !> public only so that gfortran emits it for the submodule (it inlines private ones)
    public :: flag_name

    !> What the C callbacks see through user_data (non-polymorphic, so c_loc is valid).
    type :: cvode_context_t
        class(problem_t), pointer :: problem => null()
        character(len=:), allocatable :: message  !< last message of CVODE's error handler
        integer :: last_status = STATUS_OK        !< last status returned by the problem
        integer :: recoverable = 0                !< recoverable errors of f in this call
        integer :: ml = 0, mu = 0                 !< the problem's bandwidths
        !> band work array for a dense Jacobian (the problem writes band storage)
        real(wp), allocatable :: band(:, :)
        !> the reduced Newton matrix (when `reduced`)
        logical :: reduced = .false.
        type(iteration_matrix_t) :: newton
        real(wp) :: gamma = 0.0_wp                !< CVODE's gamma of the last set-up
        real(wp), allocatable :: ones(:)          !< unit weights (the blocks need none)
        !> time split (options%profile): rhs, Jacobian, factorization, solves, s
        logical :: profile = .false.
        real(wp) :: time_rhs = 0.0_wp, time_jac = 0.0_wp, time_factor = 0.0_wp, &
                    time_solve = 0.0_wp
    end type cvode_context_t

    !> What the stepping loop watches to tell a stability-limited crawl at high BDF order
    !! (or a stiff problem under Adams) from steps that accuracy limits
    !! (ropedyn_cvode_stepping explains the rule).
    type :: cvode_monitor_t
        integer :: qmax_user = 5          !< the order limit asked for
        integer :: qmax = 5               !< the order limit in force
        integer(i8) :: window_steps0 = 0  !< total steps at the window's start
        integer(i8) :: window_fails0 = 0  !< total error-test failures at the window's start
        real(wp) :: window_t0 = 0.0_wp    !< time at the window's start
        real(wp) :: t_start = 0.0_wp      !< time at the start of the run
        !> state of the order control: 0 watching, 1 and 3 trying the low order (first
        !! and second window), 2 at the low order (crawl confirmed)
        integer :: mode = 0
        real(wp) :: rate_before = 0.0_wp  !< steps per second before the trial
        integer :: wait_windows = 0       !< windows to let pass before the next trial
        integer :: backoff = 1            !< windows to wait after a trial that did not pay
        integer :: stay_windows = 0       !< windows at the low order before trying again
        integer :: stay = 16              !< windows at the low order after a confirmation
        integer :: stiff_windows = 0      !< consecutive windows above STIFF_STEP_RATE
        integer :: trial_windows = 0      !< windows of the current trial so far
        logical :: warned = .false.       !< the crawl warning is in the log
    end type cvode_monitor_t

    type, extends(integrator_t) :: cvode_t
        private
        type(c_ptr) :: sunctx = c_null_ptr
        type(c_ptr) :: mem = c_null_ptr
        type(N_Vector), pointer :: nv_y => null()
        type(N_Vector), pointer :: nv_q => null()
        type(SUNMatrix), pointer :: matrix => null()
        type(SUNLinearSolver), pointer :: solver => null()
        real(c_double), pointer, contiguous :: y(:) => null()   !< storage wrapped by nv_y
        real(c_double), pointer, contiguous :: yq(:) => null()  !< storage wrapped by nv_q
        type(cvode_context_t), pointer :: ctx => null()
        real(wp) :: t = 0.0_wp    !< time of the state last returned (the last tout)
        real(wp) :: tn = 0.0_wp   !< CVODE's internal time (end of its last step), >= t
        !> Adams-Moulton with fixed-point iteration (adams_t) instead of BDF with Newton
        logical :: adams = .false.
        type(SUNNonlinearSolver), pointer :: nls => null()  !< the fixed-point solver (Adams)
        !> the stepping loop's watch on crawling (ropedyn_cvode_stepping)
        type(cvode_monitor_t) :: monitor
        !> counters of the integration before CVODE was last re-initialized (the order
        !! control restarts CVODE, which zeroes its own counters)
        type(solver_stats_t) :: base
        type(switch_log_t) :: log  !< order changes made by the stepping loop
    contains
        procedure :: start => cvode_start
        procedure :: advance_to => cvode_advance_to
        procedure :: stats => cvode_stats
        procedure :: finalize => cvode_finalize
        procedure :: name => cvode_name
        procedure :: switch_log => cvode_switch_log
        procedure, private :: watch => cvode_watch
        procedure, private :: restart => cvode_restart
        procedure, private :: attach_linear_solver
        final :: cvode_destroy
    end type cvode_t

    !> CVODE's Adams-Moulton methods (orders 1 .. 12) with fixed-point iteration:
    !! `method = 'adams'`.
    type, extends(cvode_t) :: adams_t
    contains
        procedure :: name => adams_name
    end type adams_t

    !> What `evaluate` evaluates.
    integer, parameter :: EVAL_RHS = 1, EVAL_QUAD = 2

    interface
        !> Integrate to tout one CVODE step at a time, watching for a crawl
        !! (submodule ropedyn_cvode_stepping).
        module subroutine cvode_advance_to(self, tout, t, y, yq, err)
            class(cvode_t), intent(inout) :: self
            real(wp), intent(in) :: tout
            real(wp), intent(out) :: t
            real(wp), intent(inout) :: y(:)
            real(wp), intent(inout) :: yq(:)
            type(error_t), allocatable, intent(out) :: err
        end subroutine cvode_advance_to

        !> After each window of steps: lower, keep or restore the maximum BDF order, or
        !! end an Adams run that the problem's stiffness holds at a crawl (cause set).
        module subroutine cvode_watch(self, cause)
            class(cvode_t), intent(inout) :: self
            character(len=:), allocatable, intent(inout) :: cause
        end subroutine cvode_watch

        !> Restart CVODE at its current state (tn, y, yq) with order limit qmax and first
        !! step h, keeping the counters so far in self%base.
        module subroutine cvode_restart(self, qmax, h, ok)
            class(cvode_t), intent(inout) :: self
            integer, intent(in) :: qmax
            real(wp), intent(in) :: h
            logical, intent(out) :: ok
        end subroutine cvode_restart

        !> A direct SUNLinearSolver whose content is the context (set-up: factor the
        !! reduced matrix for the gamma of the last linear-system call; solve: the
        !! reduction); submodule ropedyn_cvode_linsol.
        module function reduced_solver(ctx, sunctx) result(ls)
            type(cvode_context_t), pointer, intent(in) :: ctx
            type(c_ptr), intent(in) :: sunctx
            type(SUNLinearSolver), pointer :: ls
        end function reduced_solver

        !> CVODE's linear-system function: new blocks at (t, y) unless CVODE says the old
        !! ones will do (jok); the factorization follows in the solver's set-up with this
        !! gamma.
        module function cv_linsys(t, nv_y, nv_f, mat, jok, jcur, gamma, user_data, tmp1, &
                                  tmp2, tmp3) result(ierr) bind(C)
            real(c_double), value :: t
            type(N_Vector) :: nv_y, nv_f
            type(SUNMatrix) :: mat
            integer(c_int), value :: jok
            integer(c_int) :: jcur
            real(c_double), value :: gamma
            type(c_ptr), value :: user_data
            type(N_Vector) :: tmp1, tmp2, tmp3
            integer(c_int) :: ierr
        end function cv_linsys
    end interface

    interface
        !> Our compiled vector operations for a serial N_Vector (ropedyn_nvector_ops.c).
        integer(c_int) function nvector_fast_ops(v) bind(C, name='ropedyn_nvector_fast_ops')
            import :: c_int, N_Vector
            type(N_Vector) :: v
        end function nvector_fast_ops
    end interface

contains

    pure function cvode_name(self) result(name)
        class(cvode_t), intent(in) :: self
        character(len=:), allocatable :: name
        name = 'cvode'
    end function cvode_name

    pure function adams_name(self) result(name)
        class(adams_t), intent(in) :: self
        character(len=:), allocatable :: name
        name = 'adams'
    end function adams_name

    !> The order changes of the stepping loop (none unless it lowered the order).
    function cvode_switch_log(self) result(events)
        class(cvode_t), intent(in) :: self
        type(switch_event_t), allocatable :: events(:)
        events = self%log%items()
    end function cvode_switch_log

    subroutine cvode_start(self, start, err)
        class(cvode_t), intent(inout) :: self
        type(start_t), intent(in) :: start
        type(error_t), allocatable, intent(out) :: err
        integer(c_int) :: flag
        type(N_Vector), pointer :: nv_atol
        real(c_double), allocatable, target :: atol(:)

        self%adams = self%name() == 'adams'
        self%monitor = cvode_monitor_t(qmax_user=start%max_order, qmax=start%max_order, &
                                       window_t0=start%t0, t_start=start%t0)
        self%base = solver_stats_t()
        call self%log%clear()
        self%t = start%t0
        self%tn = start%t0
        allocate (self%ctx)
        self%ctx%problem => self%problem
        self%ctx%message = ''
        allocate (self%y(self%n), self%yq(max(self%nq, 1)))
        self%y = start%y0
        self%yq = 0.0_wp
        if (self%nq > 0) self%yq(1:self%nq) = start%yq0

        flag = FSUNContext_Create(c_null_ptr, self%sunctx)
        if (failed(self, flag, err, 'FSUNContext_Create')) return
        self%nv_y => FN_VMake_Serial(int(self%n, c_int64_t), self%y, self%sunctx)
        if (.not. associated(self%nv_y)) then
            call make_error(err, ERR_SOLVER, 'cvode: cannot create the state vector')
            return
        end if
        ! CVODE clones all its vectors from this one: they inherit the compiled operations.
        flag = nvector_fast_ops(self%nv_y)
        if (failed(self, flag, err, 'ropedyn_nvector_fast_ops')) return
        self%mem = FCVodeCreate(merge(CV_ADAMS, CV_BDF, self%adams), self%sunctx)
        if (.not. c_associated(self%mem)) then
            call make_error(err, ERR_SOLVER, 'cvode: FCVodeCreate failed')
            return
        end if
        flag = FCVodeSetErrHandlerFn(self%mem, c_funloc(cv_error_handler), c_loc(self%ctx))
        if (failed(self, flag, err, 'FCVodeSetErrHandlerFn')) return
        flag = FCVodeInit(self%mem, c_funloc(cv_rhs), real(start%t0, c_double), self%nv_y)
        if (failed(self, flag, err, 'FCVodeInit')) return
        flag = FCVodeSetUserData(self%mem, c_loc(self%ctx))
        if (failed(self, flag, err, 'FCVodeSetUserData')) return
        if (allocated(self%options%atol_vector)) then
            atol = self%options%atol_vector
            nv_atol => FN_VMake_Serial(int(self%n, c_int64_t), atol, self%sunctx)
            flag = nvector_fast_ops(nv_atol)
            flag = FCVodeSVtolerances(self%mem, real(self%options%rtol, c_double), nv_atol)
            call FN_VDestroy(nv_atol)
            if (failed(self, flag, err, 'FCVodeSVtolerances')) return
        else
            flag = FCVodeSStolerances(self%mem, real(self%options%rtol, c_double), &
                                      real(self%options%atol, c_double))
            if (failed(self, flag, err, 'FCVodeSStolerances')) return
        end if
        flag = FCVodeSetMaxOrd(self%mem, int(start%max_order, c_int))
        if (failed(self, flag, err, 'FCVodeSetMaxOrd')) return
        ! Stability-limit detection: CVODE watches the BDF error history at orders >= 3
        ! and lowers the order when a mode approaches the stability boundary.
        flag = FCVodeSetStabLimDet(self%mem, merge(1_c_int, 0_c_int, self%options%stab_lim_det))
        if (failed(self, flag, err, 'FCVodeSetStabLimDet')) return
        ! CVODE's default of 7 error-test failures in one step stops it at the steep fronts
        ! of OREGO and E5 at loose tolerances; MEBDF allows the same 7 but restarts at low
        ! order after 3. 20 lets CVODE through (measured by the test-set sweep).
        flag = FCVodeSetMaxErrTestFails(self%mem, 20_c_int)
        if (failed(self, flag, err, 'FCVodeSetMaxErrTestFails')) return
        flag = FCVodeSetMaxHnilWarns(self%mem, -1_c_int)
        if (failed(self, flag, err, 'FCVodeSetMaxHnilWarns')) return

        self%ctx%profile = self%options%profile
        call self%attach_linear_solver(err)
        if (allocated(err)) return

        if (self%nq > 0) then
            self%nv_q => FN_VMake_Serial(int(self%nq, c_int64_t), self%yq, self%sunctx)
            flag = nvector_fast_ops(self%nv_q)
            if (failed(self, flag, err, 'ropedyn_nvector_fast_ops')) return
            flag = FCVodeQuadInit(self%mem, c_funloc(cv_quad), self%nv_q)
            if (failed(self, flag, err, 'FCVodeQuadInit')) return
            flag = FCVodeQuadSStolerances(self%mem, real(self%options%rtol, c_double), &
                                          real(self%options%atol, c_double))
            if (failed(self, flag, err, 'FCVodeQuadSStolerances')) return
            flag = FCVodeSetQuadErrCon(self%mem, 1_c_int)
            if (failed(self, flag, err, 'FCVodeSetQuadErrCon')) return
        end if
        if (self%adams) then
            ! Adams: fixed-point (functional) iteration, as for nonstiff problems; it
            ! replaces the Newton solver, so the linear solver above is never used
            self%nls => FSUNNonlinSol_FixedPoint(self%nv_y, 0_c_int, self%sunctx)
            if (.not. associated(self%nls)) then
                call make_error(err, ERR_SOLVER, 'adams: cannot create the fixed-point solver')
                return
            end if
            flag = FCVodeSetNonlinearSolver(self%mem, self%nls)
            if (failed(self, flag, err, 'FCVodeSetNonlinearSolver')) return
        end if
    end subroutine cvode_start

    !> Whether a SUNDIALS call returned a failure flag; then err says which call, the flag
    !! and CVODE's own message.
    logical function failed(self, flag, err, what)
        class(cvode_t), intent(in) :: self
        integer(c_int), intent(in) :: flag
        type(error_t), allocatable, intent(inout) :: err
        character(len=*), intent(in) :: what
        failed = flag < 0
        if (failed) call make_error(err, ERR_SOLVER, 'cvode: '//what//' failed: '// &
                                    flag_name(flag)//' '//self%ctx%message)
    end function failed

    !> The linear solver: our reduced second-order one when the problem allows it, else
    !! SUNDIALS' band (dense for a nearly full band) LU with the problem's analytic Jacobian
    !! (CVODE's difference quotients without one).
    subroutine attach_linear_solver(self, err)
        class(cvode_t), intent(inout) :: self
        type(error_t), allocatable, intent(out) :: err
        integer :: ml, mu
        logical :: dense
        integer(c_int) :: flag

        if (self%problem%has_second_order() .and. self%problem%has_jacobian() .and. &
            .not. (self%options%first_order_newton .or. self%options%fd_jacobian)) then
            call self%ctx%newton%setup(self%problem, implicit_form=.false., first_order=.false., &
                                       fd_jacobian=.false.)
            self%ctx%reduced = self%ctx%newton%is_reduced()
        end if
        if (self%ctx%reduced) then
            allocate (self%ctx%ones(self%n))
            self%ctx%ones = 1.0_wp
            self%matrix => FSUNMatNewEmpty(self%sunctx)
            self%solver => reduced_solver(self%ctx, self%sunctx)
        else
            call self%problem%bandwidths(ml, mu)
            ml = min(ml, self%n - 1)
            mu = min(mu, self%n - 1)
            self%ctx%ml = ml
            self%ctx%mu = mu
            ! A nearly full band: dense LU (LAPACK-style, blocked) beats the band LU.
            dense = factored_dense(self%n, ml, mu)
            if (dense) then
                self%matrix => FSUNDenseMatrix(int(self%n, c_int64_t), &
                                               int(self%n, c_int64_t), self%sunctx)
                self%solver => FSUNLinSol_Dense(self%nv_y, self%matrix, self%sunctx)
                allocate (self%ctx%band(ml + mu + 1, self%n))
            else
                self%matrix => FSUNBandMatrix(int(self%n, c_int64_t), int(mu, c_int64_t), &
                                              int(ml, c_int64_t), self%sunctx)
                self%solver => FSUNLinSol_Band(self%nv_y, self%matrix, self%sunctx)
            end if
        end if
        if (.not. (associated(self%matrix) .and. associated(self%solver))) then
            call make_error(err, ERR_SOLVER, 'cvode: cannot create the linear solver')
            return
        end if
        flag = FCVodeSetLinearSolver(self%mem, self%solver, self%matrix)
        if (failed(self, flag, err, 'FCVodeSetLinearSolver')) return
        if (self%ctx%reduced) then
            flag = FCVodeSetLinSysFn(self%mem, c_funloc(cv_linsys))
            if (failed(self, flag, err, 'FCVodeSetLinSysFn')) return
        else if (self%problem%has_jacobian() .and. .not. self%options%fd_jacobian) then
            flag = FCVodeSetJacFn(self%mem, c_funloc(cv_jacobian))
            if (failed(self, flag, err, 'FCVodeSetJacFn')) return
        end if
    end subroutine attach_linear_solver

    function cvode_stats(self) result(stats)
        class(cvode_t), intent(in) :: self
        type(solver_stats_t) :: stats
        integer(c_long) :: steps(1), rhs_evals(1), lin_setups(1), err_test_fails(1), v(1), w(1)
        integer(c_int) :: flag, order(1), next_order(1)
        real(c_double) :: h0(1), h(1), h_next(1), tcur(1)

        if (.not. c_associated(self%mem)) return
        h = 0.0_c_double
        order = 0
        flag = FCVodeGetIntegratorStats(self%mem, steps, rhs_evals, lin_setups, err_test_fails, &
                                        order, next_order, h0, h, h_next, tcur)
        stats%steps = self%base%steps + steps(1)
        stats%rhs_evals = self%base%rhs_evals + rhs_evals(1)
        stats%lin_setups = self%base%lin_setups + lin_setups(1)
        stats%err_test_fails = self%base%err_test_fails + err_test_fails(1)
        stats%last_step = h(1)
        stats%last_order = order(1)
        flag = FCVodeGetNonlinSolvStats(self%mem, v, w)
        stats%nonlin_iters = self%base%nonlin_iters + v(1)
        stats%nonlin_conv_fails = self%base%nonlin_conv_fails + w(1)
        flag = FCVodeGetNumJacEvals(self%mem, v)
        stats%jac_evals = self%base%jac_evals + v(1)
        flag = FCVodeGetNumLinRhsEvals(self%mem, v)
        stats%jac_rhs_evals = self%base%jac_rhs_evals + v(1)
        stats%reduced_newton = self%ctx%reduced
        stats%time_rhs = self%ctx%time_rhs
        stats%time_jac = self%ctx%time_jac
        stats%time_factor = self%ctx%time_factor
        stats%time_solve = self%ctx%time_solve
    end function cvode_stats

    subroutine cvode_finalize(self)
        class(cvode_t), intent(inout) :: self
        integer(c_int) :: flag
        if (c_associated(self%mem)) call FCVodeFree(self%mem)
        self%mem = c_null_ptr
        if (associated(self%nls)) flag = FSUNNonlinSolFree(self%nls)
        self%nls => null()
        if (associated(self%solver)) flag = FSUNLinSolFree(self%solver)
        self%solver => null()
        if (associated(self%matrix)) call FSUNMatDestroy(self%matrix)
        self%matrix => null()
        if (associated(self%nv_y)) call FN_VDestroy(self%nv_y)
        self%nv_y => null()
        if (associated(self%nv_q)) call FN_VDestroy(self%nv_q)
        self%nv_q => null()
        if (c_associated(self%sunctx)) flag = FSUNContext_Free(self%sunctx)
        self%sunctx = c_null_ptr
        if (associated(self%y)) deallocate (self%y)
        if (associated(self%yq)) deallocate (self%yq)
        if (associated(self%ctx)) deallocate (self%ctx)
    end subroutine cvode_finalize

    subroutine cvode_destroy(self)
        type(cvode_t), intent(inout) :: self
        call self%finalize()
    end subroutine cvode_destroy

    ! ---- C callbacks -------------------------------------------------------------

    integer(c_int) function cv_rhs(t, nv_y, nv_f, user_data) result(ierr) bind(C)
        real(c_double), value :: t
        type(N_Vector) :: nv_y, nv_f
        type(c_ptr), value :: user_data
        ierr = evaluate(EVAL_RHS, t, nv_y, nv_f, user_data)
    end function cv_rhs

    integer(c_int) function cv_quad(t, nv_y, nv_qdot, user_data) result(ierr) bind(C)
        real(c_double), value :: t
        type(N_Vector) :: nv_y, nv_qdot
        type(c_ptr), value :: user_data
        ierr = evaluate(EVAL_QUAD, t, nv_y, nv_qdot, user_data)
    end function cv_quad

    !> The problem's right-hand side (EVAL_RHS) or quadrature right-hand side (EVAL_QUAD)
    !! at (t, y) into f; its status is kept for the messages and returned to CVODE.
    integer(c_int) function evaluate(what, t, nv_y, nv_f, user_data) result(ierr)
        integer, intent(in) :: what
        real(c_double), intent(in) :: t
        type(N_Vector) :: nv_y, nv_f
        type(c_ptr), intent(in) :: user_data
        type(cvode_context_t), pointer :: ctx
        real(c_double), pointer :: y(:), f(:)
        integer :: status
        real(wp) :: start
        call c_f_pointer(user_data, ctx)
        y => FN_VGetArrayPointer(nv_y)
        f => FN_VGetArrayPointer(nv_f)
        if (ctx%profile) start = clock_seconds()
        if (what == EVAL_RHS) then
            call ctx%problem%rhs(t, y, f, status)
        else
            call ctx%problem%quad_rhs(t, y, f, status)
        end if
        if (ctx%profile) ctx%time_rhs = ctx%time_rhs + (clock_seconds() - start)
        ctx%last_status = status
        if (status > 0) ctx%recoverable = ctx%recoverable + 1
        ierr = int(status, c_int)
    end function evaluate

    !> The problem's Jacobian, which it writes in band storage: straight into a band matrix
    !! or, for a dense matrix (ml = mu = n - 1 then), into the band work array and copied
    !! from there (column-major n x n).
    integer(c_int) function cv_jacobian(t, nv_y, nv_f, mat, user_data, tmp1, tmp2, tmp3) &
        result(ierr) bind(C)
        real(c_double), value :: t
        type(N_Vector) :: nv_y, nv_f
        type(SUNMatrix) :: mat
        type(c_ptr), value :: user_data
        type(N_Vector) :: tmp1, tmp2, tmp3
        type(cvode_context_t), pointer :: ctx
        real(c_double), pointer :: y(:), data1(:), jb(:, :), a(:, :)
        integer :: status, ldim, ncols, smu, n, i, j
        real(wp) :: start
        call c_f_pointer(user_data, ctx)
        if (ctx%profile) start = clock_seconds()
        y => FN_VGetArrayPointer(nv_y)
        if (allocated(ctx%band)) then
            n = size(y)
            ! SUNDIALS 6.4.1: FSUNDenseMatrix_Data returns a pointer of extent 1; re-map it.
            data1 => FSUNDenseMatrix_Data(mat)
            call c_f_pointer(c_loc(data1(1)), a, [n, n])
            ctx%band = 0.0_wp
            call ctx%problem%jacobian(t, y, ctx%band, ctx%mu + 1, status)
            do j = 1, n
                do i = 1, n
                    if (i - j > ctx%ml .or. j - i > ctx%mu) then
                        a(i, j) = 0.0_c_double
                    else
                        a(i, j) = ctx%band(ctx%mu + 1 + i - j, j)
                    end if
                end do
            end do
        else
            ! SUNDIALS 6.4.1: FSUNBandMatrix_Data returns a pointer of extent 1; re-map it.
            data1 => FSUNBandMatrix_Data(mat)
            ldim = int(FSUNBandMatrix_LDim(mat))
            ncols = int(FSUNBandMatrix_Columns(mat))
            smu = int(FSUNBandMatrix_StoredUpperBandwidth(mat))
            call c_f_pointer(c_loc(data1(1)), jb, [ldim, ncols])
            jb = 0.0_c_double
            call ctx%problem%jacobian(t, y, jb, smu + 1, status)
        end if
        if (ctx%profile) ctx%time_jac = ctx%time_jac + (clock_seconds() - start)
        ctx%last_status = status
        ierr = int(status, c_int)
    end function cv_jacobian

    !> Keeps CVODE's messages for our error text instead of printing them.
    subroutine cv_error_handler(code, module, function, msg, user_data) bind(C)
        integer(c_int), value :: code
        type(c_ptr), value :: module, function, msg, user_data
        type(cvode_context_t), pointer :: ctx
        if (.not. c_associated(user_data)) return
        call c_f_pointer(user_data, ctx)
        if (code < 0) ctx%message = c_string(msg)
        if (c_associated(module) .and. c_associated(function)) continue
    end subroutine cv_error_handler

    !> Name of a CVODE return flag.
    function flag_name(flag) result(name)
        integer(c_int), intent(in) :: flag
        character(len=:), allocatable :: name
        character(len=16) :: buffer
        select case (flag)
        case (CV_TOO_MUCH_WORK); name = 'CV_TOO_MUCH_WORK'
        case (CV_TOO_MUCH_ACC); name = 'CV_TOO_MUCH_ACC'
        case (CV_ERR_FAILURE); name = 'CV_ERR_FAILURE'
        case (CV_CONV_FAILURE); name = 'CV_CONV_FAILURE'
        case (CV_LINIT_FAIL); name = 'CV_LINIT_FAIL'
        case (CV_LSETUP_FAIL); name = 'CV_LSETUP_FAIL'
        case (CV_LSOLVE_FAIL); name = 'CV_LSOLVE_FAIL'
        case (CV_RHSFUNC_FAIL); name = 'CV_RHSFUNC_FAIL'
        case (CV_FIRST_RHSFUNC_ERR); name = 'CV_FIRST_RHSFUNC_ERR'
        case (CV_REPTD_RHSFUNC_ERR); name = 'CV_REPTD_RHSFUNC_ERR'
        case (CV_UNREC_RHSFUNC_ERR); name = 'CV_UNREC_RHSFUNC_ERR'
        case (CV_QRHSFUNC_FAIL); name = 'CV_QRHSFUNC_FAIL'
        case (CV_FIRST_QRHSFUNC_ERR); name = 'CV_FIRST_QRHSFUNC_ERR'
        case (CV_REPTD_QRHSFUNC_ERR); name = 'CV_REPTD_QRHSFUNC_ERR'
        case (CV_UNREC_QRHSFUNC_ERR); name = 'CV_UNREC_QRHSFUNC_ERR'
        case (CV_NLS_FAIL); name = 'CV_NLS_FAIL'
        case (CV_NLS_INIT_FAIL); name = 'CV_NLS_INIT_FAIL'
        case (CV_NLS_SETUP_FAIL); name = 'CV_NLS_SETUP_FAIL'
        case (CV_MEM_FAIL); name = 'CV_MEM_FAIL'
        case (CV_MEM_NULL); name = 'CV_MEM_NULL'
        case (CV_ILL_INPUT); name = 'CV_ILL_INPUT'
        case (CV_NO_MALLOC); name = 'CV_NO_MALLOC'
        case (CV_TOO_CLOSE); name = 'CV_TOO_CLOSE'
        case (CV_VECTOROP_ERR); name = 'CV_VECTOROP_ERR'
        case default
            write (buffer, '(a, i0)') 'CV flag ', flag
            name = trim(buffer)
        end select
    end function flag_name
end module ropedyn_cvode
