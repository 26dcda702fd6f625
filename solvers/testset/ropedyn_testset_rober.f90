!> ROBER: Robertson's chemical reaction (1966), 3 equations, t in [0, 1e11].
!! Test Set for IVP Solvers (Bari), release 2.3, problem ROBER; the equations and the
!! reference solution are those of docs/theory/testset.md. y2 is of order 1e-13 at
!! t_end, so the recommended atol is 1e-6 rtol (with atol = rtol the computed y2 and y1
!! are wrong).
module ropedyn_testset_rober
    use ropedyn_kinds, only: wp
    use ropedyn_problem, only: STATUS_OK
    use ropedyn_testset_problem, only: testset_problem_t
    implicit none
    private
    public :: rober_t

    real(wp), parameter :: k1 = 0.04_wp   !< rate constants of the three reactions
    real(wp), parameter :: k2 = 3.0e7_wp
    real(wp), parameter :: k3 = 1.0e4_wp

    type, extends(testset_problem_t) :: rober_t
    contains
        procedure :: setup => rober_setup
        procedure :: rhs => rober_rhs
        procedure :: dense_jacobian => rober_dense_jacobian
    end type rober_t

contains

    subroutine rober_setup(self)
        class(rober_t), intent(inout) :: self
        self%name = 'ROBER'
        self%title = 'Robertson chemical reaction'
        self%t0 = 0.0_wp
        self%t_end = 1.0e11_wp
        self%y0 = [1.0_wp, 0.0_wp, 0.0_wp]
        self%yref = [0.2083340149701255e-7_wp, 0.8333360770334713e-13_wp, &
                     0.9999999791665050_wp]
        self%atol_per_rtol = 1.0e-6_wp
        self%atol_fixed = 0.0_wp
        self%use_mescd = .false.
    end subroutine rober_setup

    subroutine rober_rhs(self, t, y, ydot, status)
        class(rober_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: ydot(:)
        integer, intent(out) :: status
        ydot(1) = -k1*y(1) + k3*y(2)*y(3)
        ydot(3) = k2*y(2)**2
        ydot(2) = -ydot(1) - ydot(3)
        status = STATUS_OK
    end subroutine rober_rhs

    subroutine rober_dense_jacobian(self, t, y, dfdy)
        class(rober_t), intent(in) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: dfdy(:, :)
        dfdy(1, 1) = -k1
        dfdy(1, 2) = k3*y(3)
        dfdy(1, 3) = k3*y(2)
        dfdy(3, 1) = 0.0_wp
        dfdy(3, 2) = 2.0_wp*k2*y(2)
        dfdy(3, 3) = 0.0_wp
        dfdy(2, :) = -dfdy(1, :) - dfdy(3, :)
    end subroutine rober_dense_jacobian
end module ropedyn_testset_rober
