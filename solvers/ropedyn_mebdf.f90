!> MEBDF skeleton (being written).
module ropedyn_mebdf
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t, make_error, ERR_SOLVER
    use ropedyn_problem, only: problem_t
    use ropedyn_integrator, only: integrator_t, solver_options_t, solver_stats_t
    implicit none
    private
    public :: mebdf_t
    type, extends(integrator_t) :: mebdf_t
        private
        type(solver_stats_t) :: counters
    contains
        procedure :: init => mebdf_init
        procedure :: advance_to => mebdf_advance_to
        procedure :: stats => mebdf_stats
        procedure :: finalize => mebdf_finalize
        procedure :: name => mebdf_name
        procedure :: default_max_order => mebdf_default_max_order
        procedure :: min_order => mebdf_min_order
        procedure :: max_order_limit => mebdf_max_order_limit
    end type mebdf_t
contains
    pure function mebdf_name(self) result(name)
        class(mebdf_t), intent(in) :: self
        character(len=:), allocatable :: name
        name = 'mebdf'
    end function mebdf_name
    pure integer function mebdf_default_max_order(self) result(order)
        class(mebdf_t), intent(in) :: self
        order = 4
    end function mebdf_default_max_order
    pure integer function mebdf_min_order(self) result(order)
        class(mebdf_t), intent(in) :: self
        order = 2
    end function mebdf_min_order
    pure integer function mebdf_max_order_limit(self) result(order)
        class(mebdf_t), intent(in) :: self
        order = 6
    end function mebdf_max_order_limit
    subroutine mebdf_init(self, problem, t0, y0, yq0, options, err)
        class(mebdf_t), intent(inout) :: self
        class(problem_t), intent(inout), target :: problem
        real(wp), intent(in) :: t0
        real(wp), intent(in) :: y0(:)
        real(wp), intent(in) :: yq0(:)
        type(solver_options_t), intent(in) :: options
        type(error_t), allocatable, intent(out) :: err
        call make_error(err, ERR_SOLVER, 'mebdf: not implemented yet')
    end subroutine mebdf_init
    subroutine mebdf_advance_to(self, tout, t, y, yq, err)
        class(mebdf_t), intent(inout) :: self
        real(wp), intent(in) :: tout
        real(wp), intent(out) :: t
        real(wp), intent(inout) :: y(:)
        real(wp), intent(inout) :: yq(:)
        type(error_t), allocatable, intent(out) :: err
        t = tout
        call make_error(err, ERR_SOLVER, 'mebdf: not implemented yet')
    end subroutine mebdf_advance_to
    function mebdf_stats(self) result(stats)
        class(mebdf_t), intent(in) :: self
        type(solver_stats_t) :: stats
        stats = self%counters
    end function mebdf_stats
    subroutine mebdf_finalize(self)
        class(mebdf_t), intent(inout) :: self
    end subroutine mebdf_finalize
end module ropedyn_mebdf
