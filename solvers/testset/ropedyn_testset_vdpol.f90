!> VDPOL: the van der Pol oscillator in relaxation form, epsilon = 1e-6, 2 equations,
!! t in [0, 2]. Test Set for IVP Solvers (Bari), release 2.3, problem VDPOL; the
!! equations and the reference solution are those of docs/theory/testset.md.
module ropedyn_testset_vdpol
    use ropedyn_kinds, only: wp
    use ropedyn_problem, only: STATUS_OK
    use ropedyn_testset_problem, only: testset_problem_t
    implicit none
    private
    public :: vdpol_t

    real(wp), parameter :: eps = 1.0e-6_wp  !< stiffness parameter epsilon

    type, extends(testset_problem_t) :: vdpol_t
    contains
        procedure :: setup => vdpol_setup
        procedure :: rhs => vdpol_rhs
        procedure :: dense_jacobian => vdpol_dense_jacobian
    end type vdpol_t

contains

    subroutine vdpol_setup(self)
        class(vdpol_t), intent(inout) :: self
        self%name = 'VDPOL'
        self%title = 'van der Pol oscillator, epsilon = 1e-6'
        self%t0 = 0.0_wp
        self%t_end = 2.0_wp
        self%y0 = [2.0_wp, 0.0_wp]
        self%yref = [0.1706167732170483e1_wp, -0.8928097010247975e0_wp]
        self%atol_per_rtol = 1.0_wp
        self%atol_fixed = 0.0_wp
        self%use_mescd = .false.
    end subroutine vdpol_setup

    subroutine vdpol_rhs(self, t, y, ydot, status)
        class(vdpol_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: ydot(:)
        integer, intent(out) :: status
        ydot(1) = y(2)
        ydot(2) = ((1.0_wp - y(1)**2)*y(2) - y(1))/eps
        status = STATUS_OK
    end subroutine vdpol_rhs

    subroutine vdpol_dense_jacobian(self, t, y, dfdy)
        class(vdpol_t), intent(in) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: dfdy(:, :)
        dfdy(1, 1) = 0.0_wp
        dfdy(1, 2) = 1.0_wp
        dfdy(2, 1) = (-2.0_wp*y(1)*y(2) - 1.0_wp)/eps
        dfdy(2, 2) = (1.0_wp - y(1)**2)/eps
    end subroutine vdpol_dense_jacobian
end module ropedyn_testset_vdpol
