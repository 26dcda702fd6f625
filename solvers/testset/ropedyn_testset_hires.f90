!> HIRES: "High Irradiance RESponse" of photomorphogenesis (Schaefer 1975), 8 equations,
!! t in [0, 321.8122]. Test Set for IVP Solvers (Bari), release 2.3, problem HIRES; the
!! equations and the reference solution are those of docs/theory/testset.md.
module ropedyn_testset_hires
    use ropedyn_kinds, only: wp
    use ropedyn_problem, only: STATUS_OK
    use ropedyn_testset_problem, only: testset_problem_t
    implicit none
    private
    public :: hires_t

    !> The constant entries of df/dy, one row of the matrix per line (rows 6 to 8 also
    !! depend on y: hires_dense_jacobian sets those entries).
    real(wp), parameter :: JAC_CONSTANT(8, 8) = reshape([ &
        -1.71_wp, 0.43_wp, 8.32_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, &
        1.71_wp, -8.75_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, &
        0.0_wp, 0.0_wp, -10.03_wp, 0.43_wp, 0.035_wp, 0.0_wp, 0.0_wp, 0.0_wp, &
        0.0_wp, 8.32_wp, 1.71_wp, -1.12_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, &
        0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, -1.745_wp, 0.43_wp, 0.43_wp, 0.0_wp, &
        0.0_wp, 0.0_wp, 0.0_wp, 0.69_wp, 1.71_wp, 0.0_wp, 0.69_wp, 0.0_wp, &
        0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, -1.81_wp, 0.0_wp, &
        0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp], [8, 8], order=[2, 1])

    type, extends(testset_problem_t) :: hires_t
    contains
        procedure :: setup => hires_setup
        procedure :: rhs => hires_rhs
        procedure :: dense_jacobian => hires_dense_jacobian
    end type hires_t

contains

    subroutine hires_setup(self)
        class(hires_t), intent(inout) :: self
        self%name = 'HIRES'
        self%title = 'High Irradiance RESponse (plant physiology)'
        self%t0 = 0.0_wp
        self%t_end = 321.8122_wp
        self%y0 = [1.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0057_wp]
        self%yref = [0.7371312573325668e-3_wp, 0.1442485726316185e-3_wp, &
                     0.5888729740967575e-4_wp, 0.1175651343283149e-2_wp, &
                     0.2386356198831331e-2_wp, 0.6238968252742796e-2_wp, &
                     0.2849998395185769e-2_wp, 0.2850001604814231e-2_wp]
        self%atol_per_rtol = 1.0_wp
        self%atol_fixed = 0.0_wp
        self%use_mescd = .false.
    end subroutine hires_setup

    subroutine hires_rhs(self, t, y, ydot, status)
        class(hires_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: ydot(:)
        integer, intent(out) :: status
        ydot(1) = -1.71_wp*y(1) + 0.43_wp*y(2) + 8.32_wp*y(3) + 0.0007_wp
        ydot(2) = 1.71_wp*y(1) - 8.75_wp*y(2)
        ydot(3) = -10.03_wp*y(3) + 0.43_wp*y(4) + 0.035_wp*y(5)
        ydot(4) = 8.32_wp*y(2) + 1.71_wp*y(3) - 1.12_wp*y(4)
        ydot(5) = -1.745_wp*y(5) + 0.43_wp*y(6) + 0.43_wp*y(7)
        ydot(6) = -280.0_wp*y(6)*y(8) + 0.69_wp*y(4) + 1.71_wp*y(5) - 0.43_wp*y(6) &
                  + 0.69_wp*y(7)
        ydot(7) = 280.0_wp*y(6)*y(8) - 1.81_wp*y(7)
        ydot(8) = -ydot(7)
        status = STATUS_OK
    end subroutine hires_rhs

    subroutine hires_dense_jacobian(self, t, y, dfdy)
        class(hires_t), intent(in) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: dfdy(:, :)
        dfdy = JAC_CONSTANT
        dfdy(6, 6) = -280.0_wp*y(8) - 0.43_wp
        dfdy(6, 8) = -280.0_wp*y(6)
        dfdy(7, 6) = 280.0_wp*y(8)
        dfdy(7, 8) = 280.0_wp*y(6)
        dfdy(8, :) = -dfdy(7, :)
    end subroutine hires_dense_jacobian
end module ropedyn_testset_hires
