!> OREGO: the Oregonator (Belousov-Zhabotinskii reaction, Field and Noyes 1974),
!! 3 equations, t in [0, 360]. Test Set for IVP Solvers (Bari), release 2.3, problem
!! OREGO; the equations and the reference solution are those of docs/theory/testset.md.
module ropedyn_testset_orego
    use ropedyn_kinds, only: wp
    use ropedyn_problem, only: STATUS_OK
    use ropedyn_testset_problem, only: testset_problem_t
    implicit none
    private
    public :: orego_t

    real(wp), parameter :: s = 77.27_wp      !< time-scale parameter
    real(wp), parameter :: q = 8.375e-6_wp   !< quadratic-loss parameter
    real(wp), parameter :: w = 0.161_wp      !< relaxation rate of y3

    type, extends(testset_problem_t) :: orego_t
    contains
        procedure :: setup => orego_setup
        procedure :: rhs => orego_rhs
        procedure :: dense_jacobian => orego_dense_jacobian
    end type orego_t

contains

    subroutine orego_setup(self)
        class(orego_t), intent(inout) :: self
        self%name = 'OREGO'
        self%title = 'Oregonator (Belousov-Zhabotinskii reaction)'
        self%t0 = 0.0_wp
        self%t_end = 360.0_wp
        self%y0 = [1.0_wp, 2.0_wp, 3.0_wp]
        self%yref = [0.1000814870318523e1_wp, 0.1228178521549917e4_wp, &
                     0.1320554942846706e3_wp]
        self%atol_per_rtol = 1.0_wp
        self%atol_fixed = 0.0_wp
        self%use_mescd = .false.
    end subroutine orego_setup

    subroutine orego_rhs(self, t, y, ydot, status)
        class(orego_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: ydot(:)
        integer, intent(out) :: status
        ydot(1) = s*(y(2) + y(1)*(1.0_wp - q*y(1) - y(2)))
        ydot(2) = (y(3) - (1.0_wp + y(1))*y(2))/s
        ydot(3) = w*(y(1) - y(3))
        status = STATUS_OK
    end subroutine orego_rhs

    subroutine orego_dense_jacobian(self, t, y, dfdy)
        class(orego_t), intent(in) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: dfdy(:, :)
        dfdy(1, 1) = s*(1.0_wp - 2.0_wp*q*y(1) - y(2))
        dfdy(1, 2) = s*(1.0_wp - y(1))
        dfdy(1, 3) = 0.0_wp
        dfdy(2, 1) = -y(2)/s
        dfdy(2, 2) = -(1.0_wp + y(1))/s
        dfdy(2, 3) = 1.0_wp/s
        dfdy(3, 1) = w
        dfdy(3, 2) = 0.0_wp
        dfdy(3, 3) = -w
    end subroutine orego_dense_jacobian
end module ropedyn_testset_orego
