!> E5: a chemical pyrolysis model (Enright, Hull and Lindberg's stiff set), 4 equations,
!! t in [0, 1e13]. Test Set for IVP Solvers (Bari), release 2.3, problem E5; the equations
!! and the reference solution are those of docs/theory/testset.md.
!!
!! The solution is tiny (y2, y3 ~ 1e-22 at t_end, y1 ~ 1e-290, y4 = 0), so the test set
!! uses a fixed atol = 1.7e-24 whatever rtol is and judges accuracy by mescd.
module ropedyn_testset_e5
    use ropedyn_kinds, only: wp
    use ropedyn_problem, only: STATUS_OK
    use ropedyn_testset_problem, only: testset_problem_t
    implicit none
    private
    public :: e5_t

    real(wp), parameter :: a = 7.89e-10_wp   !< rate constants
    real(wp), parameter :: b = 1.1e7_wp
    real(wp), parameter :: c = 1.13e3_wp
    real(wp), parameter :: mc = 1.13e9_wp    !< M C with M = 1e6

    type, extends(testset_problem_t) :: e5_t
    contains
        procedure :: setup => e5_setup
        procedure :: rhs => e5_rhs
        procedure :: dense_jacobian => e5_dense_jacobian
    end type e5_t

contains

    subroutine e5_setup(self)
        class(e5_t), intent(inout) :: self
        self%name = 'E5'
        self%title = 'chemical pyrolysis (stiff set E5)'
        self%t0 = 0.0_wp
        self%t_end = 1.0e13_wp
        self%y0 = [1.76e-3_wp, 0.0_wp, 0.0_wp, 0.0_wp]
        self%yref = [0.1152903278711829e-290_wp, 0.8867655517642120e-22_wp, &
                     0.8854814626268838e-22_wp, 0.0_wp]
        self%atol_per_rtol = 1.0_wp
        self%atol_fixed = 1.7e-24_wp
        self%use_mescd = .true.
    end subroutine e5_setup

    subroutine e5_rhs(self, t, y, ydot, status)
        class(e5_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: ydot(:)
        integer, intent(out) :: status
        real(wp) :: r1, r2, r3, r4
        r1 = a*y(1)
        r2 = b*y(1)*y(3)
        r3 = mc*y(2)*y(3)
        r4 = c*y(4)
        ydot(1) = -r1 - r2
        ydot(2) = r1 - r3
        ydot(4) = r2 - r4
        ydot(3) = ydot(2) - ydot(4)
        status = STATUS_OK
    end subroutine e5_rhs

    subroutine e5_dense_jacobian(self, t, y, dfdy)
        class(e5_t), intent(in) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: dfdy(:, :)
        dfdy(1, :) = [-a - b*y(3), 0.0_wp, -b*y(1), 0.0_wp]
        dfdy(2, :) = [a, -mc*y(3), -mc*y(2), 0.0_wp]
        dfdy(4, :) = [b*y(3), 0.0_wp, b*y(1), -c]
        dfdy(3, :) = dfdy(2, :) - dfdy(4, :)
    end subroutine e5_dense_jacobian
end module ropedyn_testset_e5
