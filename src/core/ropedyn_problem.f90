!> The one interface between models (src/) and integrators (solvers/).
!!
!! A problem is a first-order system y' = f(t, y) of `size()` unknowns whose Jacobian
!! df/dy lies in a band of `ml` sub- and `mu` super-diagonals, plus optional quadrature
!! variables yq' = g(t, y) (integrated alongside y but outside the Newton system; the rope
!! models use them for the dissipated energy and the work of the supports).
module ropedyn_problem
    use ropedyn_kinds, only: wp
    implicit none
    private
    public :: problem_t, energy_t
    public :: STATUS_OK, STATUS_RECOVERABLE, STATUS_FATAL

    !> Return codes of rhs/jacobian/quad_rhs (the CVODE convention).
    integer, parameter :: STATUS_OK = 0           !< success
    integer, parameter :: STATUS_RECOVERABLE = 1  !< e.g. a NaN: the integrator may retry smaller
    integer, parameter :: STATUS_FATAL = -1       !< stop the integration

    !> Energy bookkeeping of a state, all in J.
    type :: energy_t
        real(wp) :: kinetic = 0.0_wp       !< T
        real(wp) :: elastic = 0.0_wp       !< springs (internal and supports)
        real(wp) :: gravity = 0.0_wp       !< -sum m g x
        real(wp) :: dissipated = 0.0_wp    !< integral of the dissipation power so far
        real(wp) :: support_work = 0.0_wp  !< work done on the rope by moving supports so far
    contains
        procedure :: total => energy_total
        procedure :: balance => energy_balance
    end type energy_t

    type, abstract :: problem_t
    contains
        procedure(size_i), deferred :: size
        procedure(bandwidths_i), deferred :: bandwidths
        procedure(rhs_i), deferred :: rhs
        procedure(jacobian_i), deferred :: jacobian
        procedure(energy_i), deferred :: energy
        procedure :: quad_size => problem_quad_size
        procedure :: quad_rhs => problem_quad_rhs
    end type problem_t

    abstract interface
        !> Number of unknowns of the first-order system.
        pure integer function size_i(self)
            import :: problem_t
            class(problem_t), intent(in) :: self
        end function size_i

        !> Lower and upper bandwidth of df/dy (ml = mu = size-1 for a dense Jacobian).
        pure subroutine bandwidths_i(self, ml, mu)
            import :: problem_t
            class(problem_t), intent(in) :: self
            integer, intent(out) :: ml, mu
        end subroutine bandwidths_i

        !> ydot = f(t, y); status is one of the STATUS_* codes.
        subroutine rhs_i(self, t, y, ydot, status)
            import :: problem_t, wp
            class(problem_t), intent(inout) :: self
            real(wp), intent(in) :: t
            real(wp), intent(in) :: y(:)
            real(wp), intent(out) :: ydot(:)
            integer, intent(out) :: status
        end subroutine rhs_i

        !> Add df/dy into band storage: entry (i, j) goes to jb(offset + i - j, j).
        !! The caller zeroes jb; offset >= mu + 1 and size(jb, 1) >= offset + ml.
        subroutine jacobian_i(self, t, y, jb, offset, status)
            import :: problem_t, wp
            class(problem_t), intent(inout) :: self
            real(wp), intent(in) :: t
            real(wp), intent(in) :: y(:)
            real(wp), intent(inout) :: jb(:, :)
            integer, intent(in) :: offset
            integer, intent(out) :: status
        end subroutine jacobian_i

        !> Energies of state y at time t with quadrature values yq.
        function energy_i(self, t, y, yq) result(e)
            import :: problem_t, wp, energy_t
            class(problem_t), intent(inout) :: self
            real(wp), intent(in) :: t
            real(wp), intent(in) :: y(:)
            real(wp), intent(in) :: yq(:)
            type(energy_t) :: e
        end function energy_i
    end interface

contains

    !> Number of quadrature variables (none unless a problem overrides this).
    pure integer function problem_quad_size(self) result(nq)
        class(problem_t), intent(in) :: self
        nq = 0
    end function problem_quad_size

    !> yqdot = g(t, y) for the quadrature variables.
    subroutine problem_quad_rhs(self, t, y, yqdot, status)
        class(problem_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: yqdot(:)
        integer, intent(out) :: status
        yqdot = 0.0_wp
        status = STATUS_OK
    end subroutine problem_quad_rhs

    !> T + V (kinetic + elastic + gravity), J.
    pure real(wp) function energy_total(self) result(e)
        class(energy_t), intent(in) :: self
        e = self%kinetic + self%elastic + self%gravity
    end function energy_total

    !> T + V + dissipated - support work: equals E0 for every run, J.
    pure real(wp) function energy_balance(self) result(e)
        class(energy_t), intent(in) :: self
        e = self%kinetic + self%elastic + self%gravity + self%dissipated - self%support_work
    end function energy_balance
end module ropedyn_problem
