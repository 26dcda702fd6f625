!> The reduced second-order linear solver CVODE calls: a direct SUNLinearSolver whose
!! content is the integrator's context (ropedyn_cvode). CVODE's linear-system function
!! evaluates the blocks K, C, M_v when it asks for a new Jacobian; the solver's set-up
!! factors M - g C - g^2 K for CVODE's gamma; its solve does the reduction
!! (ropedyn_iteration_matrix).
submodule(ropedyn_cvode) ropedyn_cvode_linsol
    use fsundials_linearsolver_mod, only: SUNLinearSolver_Ops, FSUNLinSolNewEmpty, &
                                          FSUNLinSolFreeEmpty, SUNLinearSolver_Type, &
                                          SUNLINEARSOLVER_DIRECT
    implicit none

contains

    module procedure reduced_solver
        type(SUNLinearSolver_Ops), pointer :: ops
        ls => FSUNLinSolNewEmpty(sunctx)
        if (.not. associated(ls)) return
        ls%content = c_loc(ctx)
        call c_f_pointer(ls%ops, ops)
        ops%gettype = c_funloc(ls_type)
        ops%setup = c_funloc(ls_setup)
        ops%solve = c_funloc(ls_solve)
        ops%free = c_funloc(ls_free)
    end procedure reduced_solver

    integer(SUNLinearSolver_Type) function ls_type(ls) result(kind) bind(C)
        type(SUNLinearSolver) :: ls
        kind = SUNLINEARSOLVER_DIRECT
    end function ls_type

    module procedure cv_linsys
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
    end procedure cv_linsys

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
end submodule ropedyn_cvode_linsol
