!> A test problem for the integrators' bookkeeping (budgets, round-off, stop times): the
!! harmonic oscillator y1' = y2, y2' = -w^2 y1, banded (1, 1), no Jacobian of its own.
module ropedyn_test_oscillator
    use ropedyn_kinds, only: wp
    use ropedyn_problem, only: problem_t, STATUS_OK
    implicit none
    private
    public :: oscillator_t

    !> y = (x, v): x' = v, v' = -w^2 x.
    type, extends(problem_t) :: oscillator_t
        real(wp) :: w = 1.0_wp    !< rad/s
    contains
        procedure :: size => oscillator_size
        procedure :: bandwidths => oscillator_bandwidths
        procedure :: rhs => oscillator_rhs
    end type oscillator_t

contains

    pure integer function oscillator_size(self) result(n)
        class(oscillator_t), intent(in) :: self
        n = 2
    end function oscillator_size

    pure subroutine oscillator_bandwidths(self, ml, mu)
        class(oscillator_t), intent(in) :: self
        integer, intent(out) :: ml, mu
        ml = 1
        mu = 1
    end subroutine oscillator_bandwidths

    subroutine oscillator_rhs(self, t, y, ydot, status)
        class(oscillator_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: ydot(:)
        integer, intent(out) :: status
        ydot = [y(2), -self%w**2*y(1)]
        status = STATUS_OK
    end subroutine oscillator_rhs
end module ropedyn_test_oscillator
