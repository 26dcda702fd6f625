!> CVODE (BDF, Newton, band linear solver with the problem's analytic Jacobian) behind
!! the integrator interface.
!!
!! For a problem with second-order structure (ropedyn_problem) the Newton systems are solved
!! on the reduced matrix I - gamma C - gamma^2 K of the coordinates (ropedyn_iteration_matrix)
!! by a linear solver of our own: a direct SUNLinearSolver with an empty SUNMatrix and our
!! linear-system function (CVodeSetLinSysFn). CVODE keeps all its own rules that way: when to
!! set up (gamma changed by > 30 %, every 20 steps, after failures), when the Jacobian is
!! stale (jok: every 51 steps, after a convergence failure with an old one), the scaling of
!! the correction by 2/(1 + gamma/gamma_setup) for a lagged setup, its counters; the linear
!! system function evaluates the blocks when CVODE asks for a new Jacobian, the solver's
!! setup factors the reduced matrix for CVODE's gamma, its solve does the reduction.
!!
!! We link CVODES, CVODE's superset from the same SUNDIALS release, for its quadrature
!! feature: the problem's quadrature variables (dissipated energy, support work) are then
!! integrated with error control but outside the Newton system. Every SUNDIALS-version
!! detail (6.4.1: `fsundials_context_mod`, the band-matrix data pointer of extent 1) is
!! kept inside this module.
module ropedyn_cvode
    use, intrinsic :: iso_c_binding
    use ropedyn_kinds, only: wp, i8
    use ropedyn_text, only: int_text
    use ropedyn_error, only: error_t, make_error, ERR_SOLVER
    use ropedyn_problem, only: problem_t, STATUS_OK
    use ropedyn_integrator, only: integrator_t, solver_options_t, solver_stats_t, clock_seconds, &
        stop_now
    use ropedyn_iteration_matrix, only: iteration_matrix_t
    use fsundials_context_mod, only: FSUNContext_Create, FSUNContext_Free
    use fsundials_nvector_mod, only: N_Vector, FN_VDestroy, FN_VGetArrayPointer
    use fsundials_matrix_mod, only: SUNMatrix, FSUNMatDestroy, FSUNMatNewEmpty
    use fsundials_linearsolver_mod, only: SUNLinearSolver, FSUNLinSolFree, SUNLinearSolver_Ops, &
                                          FSUNLinSolNewEmpty, FSUNLinSolFreeEmpty, &
                                          SUNLinearSolver_Type, SUNLINEARSOLVER_DIRECT
    use fnvector_serial_mod, only: FN_VMake_Serial
    use fsunmatrix_band_mod, only: FSUNBandMatrix, FSUNBandMatrix_Data, FSUNBandMatrix_LDim, &
                                   FSUNBandMatrix_StoredUpperBandwidth, FSUNBandMatrix_Columns
    use fsunlinsol_band_mod, only: FSUNLinSol_Band
    use fsunmatrix_dense_mod, only: FSUNDenseMatrix, FSUNDenseMatrix_Data
    use fsunlinsol_dense_mod, only: FSUNLinSol_Dense
    use fcvodes_mod
    implicit none
    private
    public :: cvode_t

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
        type(solver_options_t) :: options
        integer :: n = 0, nq = 0
        real(wp) :: t = 0.0_wp    !< time of the state last returned (the last tout)
        real(wp) :: tn = 0.0_wp   !< CVODE's internal time (end of its last step), >= t
    contains
        procedure :: init => cvode_init
        procedure :: advance_to => cvode_advance_to
        procedure :: stats => cvode_stats
        procedure :: finalize => cvode_finalize
        procedure :: name => cvode_name
        procedure, private :: attach_linear_solver
        final :: cvode_destroy
    end type cvode_t

    !> What `evaluate` evaluates.
    integer, parameter :: EVAL_RHS = 1, EVAL_QUAD = 2

    interface
        !> Our compiled vector operations for a serial N_Vector (ropedyn_nvector_ops.c).
        integer(c_int) function nvector_fast_ops(v) bind(C, name='ropedyn_nvector_fast_ops')
            import :: c_int, N_Vector
            type(N_Vector) :: v
        end function nvector_fast_ops
        pure integer(c_size_t) function c_strlen(s) bind(C, name='strlen')
            import :: c_ptr, c_size_t
            type(c_ptr), value, intent(in) :: s
        end function c_strlen
    end interface

contains

    pure function cvode_name(self) result(name)
        class(cvode_t), intent(in) :: self
        character(len=:), allocatable :: name
        name = 'cvode'
    end function cvode_name

    subroutine cvode_init(self, problem, t0, y0, yq0, options, err)
        class(cvode_t), intent(inout) :: self
        class(problem_t), intent(inout), target :: problem
        real(wp), intent(in) :: t0
        real(wp), intent(in) :: y0(:)
        real(wp), intent(in) :: yq0(:)
        type(solver_options_t), intent(in) :: options
        type(error_t), allocatable, intent(out) :: err
        integer :: max_order
        integer(c_int) :: flag
        type(N_Vector), pointer :: nv_atol
        real(c_double), allocatable, target :: atol(:)

        call self%finalize()
        self%options = options
        self%n = problem%size()
        self%nq = problem%quad_size()
        call self%check_options(options, self%n, max_order, err)
        if (allocated(err)) return
        self%t = t0
        self%tn = t0
        allocate (self%ctx)
        self%ctx%problem => problem
        self%ctx%message = ''
        allocate (self%y(self%n), self%yq(max(self%nq, 1)))
        self%y = y0
        self%yq = 0.0_wp
        if (self%nq > 0) self%yq(1:self%nq) = yq0(1:self%nq)

        flag = FSUNContext_Create(c_null_ptr, self%sunctx)
        if (check(flag, 'FSUNContext_Create')) return
        self%nv_y => FN_VMake_Serial(int(self%n, c_int64_t), self%y, self%sunctx)
        if (.not. associated(self%nv_y)) then
            call make_error(err, ERR_SOLVER, 'cvode: cannot create the state vector')
            return
        end if
        ! CVODE clones all its vectors from this one: they inherit the compiled operations.
        flag = nvector_fast_ops(self%nv_y)
        if (check(flag, 'ropedyn_nvector_fast_ops')) return
        self%mem = FCVodeCreate(CV_BDF, self%sunctx)
        if (.not. c_associated(self%mem)) then
            call make_error(err, ERR_SOLVER, 'cvode: FCVodeCreate failed')
            return
        end if
        flag = FCVodeSetErrHandlerFn(self%mem, c_funloc(cv_error_handler), c_loc(self%ctx))
        if (check(flag, 'FCVodeSetErrHandlerFn')) return
        flag = FCVodeInit(self%mem, c_funloc(cv_rhs), real(t0, c_double), self%nv_y)
        if (check(flag, 'FCVodeInit')) return
        flag = FCVodeSetUserData(self%mem, c_loc(self%ctx))
        if (check(flag, 'FCVodeSetUserData')) return
        if (allocated(options%atol_vector)) then
            atol = options%atol_vector
            nv_atol => FN_VMake_Serial(int(self%n, c_int64_t), atol, self%sunctx)
            flag = nvector_fast_ops(nv_atol)
            flag = FCVodeSVtolerances(self%mem, real(options%rtol, c_double), nv_atol)
            call FN_VDestroy(nv_atol)
            if (check(flag, 'FCVodeSVtolerances')) return
        else
            flag = FCVodeSStolerances(self%mem, real(options%rtol, c_double), &
                                      real(options%atol, c_double))
            if (check(flag, 'FCVodeSStolerances')) return
        end if
        flag = FCVodeSetMaxOrd(self%mem, int(max_order, c_int))
        if (check(flag, 'FCVodeSetMaxOrd')) return
        ! Stability-limit detection: CVODE watches the BDF error history at orders >= 3
        ! and lowers the order when a mode approaches the stability boundary.
        flag = FCVodeSetStabLimDet(self%mem, merge(1_c_int, 0_c_int, options%stab_lim_det))
        if (check(flag, 'FCVodeSetStabLimDet')) return
        ! CVODE's default of 7 error-test failures in one step stops it at the steep fronts
        ! of OREGO and E5 at loose tolerances; MEBDF allows the same 7 but restarts at low
        ! order after 3. 20 lets CVODE through (measured by the test-set sweep).
        flag = FCVodeSetMaxErrTestFails(self%mem, 20_c_int)
        if (check(flag, 'FCVodeSetMaxErrTestFails')) return
        flag = FCVodeSetMaxHnilWarns(self%mem, -1_c_int)
        if (check(flag, 'FCVodeSetMaxHnilWarns')) return

        self%ctx%profile = options%profile
        call self%attach_linear_solver(problem, options, err)
        if (allocated(err)) return

        if (self%nq > 0) then
            self%nv_q => FN_VMake_Serial(int(self%nq, c_int64_t), self%yq, self%sunctx)
            flag = nvector_fast_ops(self%nv_q)
            if (check(flag, 'ropedyn_nvector_fast_ops')) return
            flag = FCVodeQuadInit(self%mem, c_funloc(cv_quad), self%nv_q)
            if (check(flag, 'FCVodeQuadInit')) return
            flag = FCVodeQuadSStolerances(self%mem, real(options%rtol, c_double), &
                                          real(options%atol, c_double))
            if (check(flag, 'FCVodeQuadSStolerances')) return
            flag = FCVodeSetQuadErrCon(self%mem, 1_c_int)
            if (check(flag, 'FCVodeSetQuadErrCon')) return
        end if
    contains
        logical function check(flag, what)
            integer(c_int), intent(in) :: flag
            character(len=*), intent(in) :: what
            check = flag < 0
            if (check) call make_error(err, ERR_SOLVER, 'cvode: '//what//' failed: '// &
                                       flag_name(flag)//' '//self%ctx%message)
        end function check
    end subroutine cvode_init

    !> The linear solver: our reduced second-order one when the problem allows it, else
    !! SUNDIALS' band (dense for a nearly full band) LU with the problem's analytic Jacobian
    !! (CVODE's difference quotients without one).
    subroutine attach_linear_solver(self, problem, options, err)
        class(cvode_t), intent(inout) :: self
        class(problem_t), intent(inout), target :: problem
        type(solver_options_t), intent(in) :: options
        type(error_t), allocatable, intent(out) :: err
        integer :: ml, mu
        logical :: dense
        integer(c_int) :: flag

        if (problem%has_second_order() .and. problem%has_jacobian() .and. &
            .not. (options%first_order_newton .or. options%fd_jacobian)) then
            call self%ctx%newton%setup(problem, implicit_form=.false., first_order=.false., &
                                       fd_jacobian=.false.)
            self%ctx%reduced = self%ctx%newton%is_reduced()
        end if
        if (self%ctx%reduced) then
            allocate (self%ctx%ones(self%n))
            self%ctx%ones = 1.0_wp
            self%matrix => FSUNMatNewEmpty(self%sunctx)
            self%solver => reduced_solver(self%ctx, self%sunctx)
            if (.not. (associated(self%matrix) .and. associated(self%solver))) then
                call make_error(err, ERR_SOLVER, 'cvode: cannot create the linear solver')
                return
            end if
            flag = FCVodeSetLinearSolver(self%mem, self%solver, self%matrix)
            if (check(flag, 'FCVodeSetLinearSolver')) return
            flag = FCVodeSetLinSysFn(self%mem, c_funloc(cv_linsys))
            if (check(flag, 'FCVodeSetLinSysFn')) return
            return
        end if

        call problem%bandwidths(ml, mu)
        ml = min(ml, self%n - 1)
        mu = min(mu, self%n - 1)
        self%ctx%ml = ml
        self%ctx%mu = mu
        ! A nearly full band: dense LU (LAPACK-style, blocked) beats the band LU.
        dense = 2*ml + mu + 1 >= self%n
        if (dense) then
            self%matrix => FSUNDenseMatrix(int(self%n, c_int64_t), int(self%n, c_int64_t), &
                                           self%sunctx)
            self%solver => FSUNLinSol_Dense(self%nv_y, self%matrix, self%sunctx)
            allocate (self%ctx%band(ml + mu + 1, self%n))
        else
            self%matrix => FSUNBandMatrix(int(self%n, c_int64_t), int(mu, c_int64_t), &
                                          int(ml, c_int64_t), self%sunctx)
            self%solver => FSUNLinSol_Band(self%nv_y, self%matrix, self%sunctx)
        end if
        if (.not. (associated(self%matrix) .and. associated(self%solver))) then
            call make_error(err, ERR_SOLVER, 'cvode: cannot create the linear solver')
            return
        end if
        flag = FCVodeSetLinearSolver(self%mem, self%solver, self%matrix)
        if (check(flag, 'FCVodeSetLinearSolver')) return
        if (problem%has_jacobian() .and. .not. options%fd_jacobian) then
            flag = FCVodeSetJacFn(self%mem, c_funloc(cv_jacobian))
            if (check(flag, 'FCVodeSetJacFn')) return
        end if
    contains
        logical function check(flag, what)
            integer(c_int), intent(in) :: flag
            character(len=*), intent(in) :: what
            check = flag < 0
            if (check) call make_error(err, ERR_SOLVER, 'cvode: '//what//' failed: '// &
                                       flag_name(flag)//' '//self%ctx%message)
        end function check
    end subroutine attach_linear_solver


    !> CVODE in one-step mode, so that every step is seen: the step budget and the
    !! round-off floor (as MEBDF's: a step h < 16 eps |t| ends the run) are checked after
    !! each step, then the solution is interpolated at tout (what CV_NORMAL does inside;
    !! the steps taken are the same). CVODE by itself accepts steps with t + h == t: a run
    !! that runs into a region where f keeps failing (a NaN ahead) would crawl there until
    !! max_steps. With `options%stop_requested` saying so after a step, it returns there
    !! (t = the step's end < tout; the quadratures at that time).
    subroutine cvode_advance_to(self, tout, t, y, yq, err)
        class(cvode_t), intent(inout) :: self
        real(wp), intent(in) :: tout
        real(wp), intent(out) :: t
        real(wp), intent(inout) :: y(:)
        real(wp), intent(inout) :: yq(:)
        type(error_t), allocatable, intent(out) :: err
        real(c_double) :: tret(1), hlast(1)
        integer(c_long) :: nsteps(1)
        integer(c_int) :: flag, qflag
        character(len=:), allocatable :: cause

        if (.not. c_associated(self%mem)) then
            call make_error(err, ERR_SOLVER, 'cvode: advance_to called before init')
            return
        end if
        self%ctx%message = ''
        self%ctx%recoverable = 0
        flag = CV_SUCCESS
        cause = ''
        do while (self%tn < tout)
            qflag = FCVodeGetNumSteps(self%mem, nsteps)
            if (int(nsteps(1), i8) >= self%options%max_steps) then
                cause = 'max_steps exceeded ('//int_text(self%options%max_steps)//' steps)'
                exit
            end if
            tret = self%tn
            flag = FCVode(self%mem, real(tout, c_double), self%nv_y, tret, CV_ONE_STEP)
            if (flag < 0) exit
            self%tn = tret(1)
            hlast = 0.0_c_double
            qflag = FCVodeGetLastStep(self%mem, hlast)
            if (hlast(1) < 16.0_wp*epsilon(1.0_wp)*abs(self%tn)) then
                cause = 'step size fell below the round-off limit'
                if (self%ctx%recoverable > 0) cause = cause//' after repeated recoverable '// &
                    'errors of the right-hand side (e.g. a NaN or Inf in the forces)'
                exit
            end if
            if (self%tn < tout .and. stop_now(self%options)) then
                ! stopped early on request: the state at the end of this step
                self%t = self%tn
                y = self%y
                if (self%nq > 0) then
                    tret = self%tn
                    qflag = FCVodeGetQuad(self%mem, tret, self%nv_q)
                    yq(1:self%nq) = self%yq(1:self%nq)
                end if
                t = self%t
                return
            end if
        end do

        if (flag >= 0 .and. len(cause) == 0) then
            ! the step that reached tout is done: interpolate there
            flag = FCVodeGetDky(self%mem, real(tout, c_double), 0_c_int, self%nv_y)
            if (self%nq > 0 .and. flag >= 0) &
                flag = FCVodeGetQuadDky(self%mem, real(tout, c_double), 0_c_int, self%nv_q)
            if (flag >= 0) then
                self%t = tout
                y = self%y
                if (self%nq > 0) yq(1:self%nq) = self%yq(1:self%nq)
                t = self%t
                return
            end if
            cause = flag_name(flag)//': interpolation at tout failed '//self%ctx%message
        end if

        ! Failure: the last good state is CVODE's current one (in y after a one-step call).
        self%t = self%tn
        if (self%nq > 0) then
            tret = self%tn
            qflag = FCVodeGetQuad(self%mem, tret, self%nv_q)
            if (qflag >= 0) yq(1:self%nq) = self%yq(1:self%nq)
        end if
        y = self%y
        t = self%t
        ! the step being attempted when CVODE gave up (the last successful one if none)
        hlast = 0.0_c_double
        qflag = FCVodeGetCurrentStep(self%mem, hlast)
        if (hlast(1) == 0.0_c_double) qflag = FCVodeGetLastStep(self%mem, hlast)
        if (len(cause) == 0) then
            cause = flag_name(flag)//': '//self%ctx%message
            if (flag == CV_REPTD_RHSFUNC_ERR .or. flag == CV_REPTD_QRHSFUNC_ERR) &
                cause = cause//' (the model returned a recoverable error, e.g. a NaN or '// &
                'Inf in the forces)'
        end if
        call make_error(err, ERR_SOLVER, 'cvode failed at '//where_text(t, hlast(1))// &
                        ': '//cause)
    end subroutine cvode_advance_to

    !> 't = ... s, step size ... s' for messages.
    function where_text(t, h) result(text)
        real(wp), intent(in) :: t, h
        character(len=:), allocatable :: text
        character(len=64) :: buffer
        write (buffer, '(a, es12.5, a, es11.3e3, a)') 't = ', t, ' s, step size ', h, ' s'
        text = trim(buffer)
    end function where_text

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
        stats%steps = steps(1)
        stats%rhs_evals = rhs_evals(1)
        stats%lin_setups = lin_setups(1)
        stats%err_test_fails = err_test_fails(1)
        stats%last_step = h(1)
        stats%last_order = order(1)
        flag = FCVodeGetNonlinSolvStats(self%mem, v, w)
        stats%nonlin_iters = v(1)
        stats%nonlin_conv_fails = w(1)
        flag = FCVodeGetNumJacEvals(self%mem, v)
        stats%jac_evals = v(1)
        flag = FCVodeGetNumLinRhsEvals(self%mem, v)
        stats%jac_rhs_evals = v(1)
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

    ! ---- the reduced second-order linear solver --------------------------------------

    !> A direct SUNLinearSolver whose content is the context (set-up: factor the reduced
    !! matrix for the gamma of the last linear-system call; solve: the reduction).
    function reduced_solver(ctx, sunctx) result(ls)
        type(cvode_context_t), pointer, intent(in) :: ctx
        type(c_ptr), intent(in) :: sunctx
        type(SUNLinearSolver), pointer :: ls
        type(SUNLinearSolver_Ops), pointer :: ops
        ls => FSUNLinSolNewEmpty(sunctx)
        if (.not. associated(ls)) return
        ls%content = c_loc(ctx)
        call c_f_pointer(ls%ops, ops)
        ops%gettype = c_funloc(ls_type)
        ops%setup = c_funloc(ls_setup)
        ops%solve = c_funloc(ls_solve)
        ops%free = c_funloc(ls_free)
    end function reduced_solver

    integer(SUNLinearSolver_Type) function ls_type(ls) result(kind) bind(C)
        type(SUNLinearSolver) :: ls
        kind = SUNLINEARSOLVER_DIRECT
    end function ls_type

    !> CVODE's linear-system function: new blocks at (t, y) unless CVODE says the old ones
    !! will do (jok); the factorization follows in ls_setup with this gamma.
    integer(c_int) function cv_linsys(t, nv_y, nv_f, mat, jok, jcur, gamma, user_data, &
                                      tmp1, tmp2, tmp3) result(ierr) bind(C)
        real(c_double), value :: t
        type(N_Vector) :: nv_y, nv_f
        type(SUNMatrix) :: mat
        integer(c_int), value :: jok
        integer(c_int) :: jcur
        real(c_double), value :: gamma
        type(c_ptr), value :: user_data
        type(N_Vector) :: tmp1, tmp2, tmp3
        type(cvode_context_t), pointer :: ctx
        real(c_double), pointer :: y(:)
        integer(i8) :: nevals
        integer :: status
        real(wp) :: start
        call c_f_pointer(user_data, ctx)
        ctx%gamma = gamma
        jcur = 0_c_int
        ierr = 0_c_int
        if (jok /= 0_c_int) return
        if (ctx%profile) start = clock_seconds()
        y => FN_VGetArrayPointer(nv_y)
        nevals = 0
        call ctx%newton%evaluate_jacobian(ctx%problem, t, y, ctx%ones, 0.0_wp, status, nevals)
        if (ctx%profile) ctx%time_jac = ctx%time_jac + (clock_seconds() - start)
        ctx%last_status = status
        jcur = 1_c_int
        ierr = int(status, c_int)
    end function cv_linsys

    integer(c_int) function ls_setup(ls, mat) result(ierr) bind(C)
        type(SUNLinearSolver) :: ls
        type(SUNMatrix) :: mat
        type(cvode_context_t), pointer :: ctx
        integer :: status
        real(wp) :: start
        call c_f_pointer(ls%content, ctx)
        if (ctx%profile) start = clock_seconds()
        call ctx%newton%factor(ctx%problem, 0.0_wp, ctx%ones, ctx%gamma, status)
        if (ctx%profile) ctx%time_factor = ctx%time_factor + (clock_seconds() - start)
        ierr = int(status, c_int)   ! a singular matrix is recoverable (CVODE cuts h)
    end function ls_setup

    integer(c_int) function ls_solve(ls, mat, nv_x, nv_b, tol) result(ierr) bind(C)
        type(SUNLinearSolver) :: ls
        type(SUNMatrix) :: mat
        type(N_Vector) :: nv_x, nv_b
        real(c_double), value :: tol
        type(cvode_context_t), pointer :: ctx
        real(c_double), pointer :: x(:), b(:)
        real(wp) :: start
        call c_f_pointer(ls%content, ctx)
        if (ctx%profile) start = clock_seconds()
        x => FN_VGetArrayPointer(nv_x)
        b => FN_VGetArrayPointer(nv_b)
        x = b
        call ctx%newton%solve(x)
        if (ctx%profile) ctx%time_solve = ctx%time_solve + (clock_seconds() - start)
        ierr = 0_c_int
    end function ls_solve

    !> The content is the context, owned by cvode_t: only the solver object goes.
    integer(c_int) function ls_free(ls) result(ierr) bind(C)
        type(SUNLinearSolver), target :: ls
        ls%content = c_null_ptr
        call FSUNLinSolFreeEmpty(ls)
        ierr = 0_c_int
    end function ls_free

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

    function c_string(p) result(s)
        type(c_ptr), intent(in) :: p
        character(len=:), allocatable :: s
        character(kind=c_char), pointer :: chars(:)
        integer :: i, n
        if (.not. c_associated(p)) then
            s = ''
            return
        end if
        n = int(c_strlen(p))
        call c_f_pointer(p, chars, [n])
        allocate (character(len=n) :: s)
        do i = 1, n
            s(i:i) = chars(i)
        end do
    end function c_string

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
