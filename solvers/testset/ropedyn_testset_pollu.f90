!> POLLU: the chemistry of the RIVM air-pollution model (Verwer 1994, SIAM J. Sci. Comput.
!! 15(5):1243-1259), 20 species, 25 reactions, t in [0, 60] (minutes, ppm).
!!
!! Source of the definition and the numbers: the test set's own file pollu.f (Test Set for
!! IVP Solvers, Bari, revision "pollu.F,v 1.2 2006/10/02", the one shipped with release
!! 2.3), read in the copy github.com/volpatto/pside, problems/Pollution/pollu.f (commit
!! f00d1057cd22a2fcdfa324f47f996257cb6e7e86): rate constants k1..k25, the reaction rates
!! r1..r25, f = the species balances, y0, and the reference solution of subroutine solut
!! ("true double precision RADAU5 on Cray C90, uround = 1.01e-19, rtol = atol = h0 =
!! 1.1e-18"). The same constants and reference values appear in SciML's
!! SciMLBenchmarks.jl (StiffODE/Pollution) and in deSolve's Pollution.R example.
!! The test set uses rtol = atol for this problem.
!!
!! The right-hand side is linear in the reaction rates (f = S r with a constant
!! stoichiometric matrix S), so the analytic Jacobian is S dr/dy: `pollu_combine`
!! applies S and is shared by `rhs` and `dense_jacobian`.
module ropedyn_testset_pollu
    use ropedyn_kinds, only: wp
    use ropedyn_problem, only: STATUS_OK
    use ropedyn_testset_problem, only: testset_problem_t
    implicit none
    private
    public :: pollu_t

    integer, parameter :: n_species = 20
    integer, parameter :: n_reactions = 25

    !> Rate constants k1 .. k25 (1/min or 1/(ppm min)).
    real(wp), parameter :: k(n_reactions) = [ &
        0.35_wp, 0.266e2_wp, 0.123e5_wp, 0.86e-3_wp, 0.82e-3_wp, &
        0.15e5_wp, 0.13e-3_wp, 0.24e5_wp, 0.165e5_wp, 0.9e4_wp, &
        0.22e-1_wp, 0.12e5_wp, 0.188e1_wp, 0.163e5_wp, 0.48e7_wp, &
        0.35e-3_wp, 0.175e-1_wp, 0.1e9_wp, 0.444e12_wp, 0.124e4_wp, &
        0.21e1_wp, 0.578e1_wp, 0.474e-1_wp, 0.178e4_wp, 0.312e1_wp]

    !> Reaction m has rate k(m) y(first(m)) y(second(m)), where index `one` stands for a
    !! factor 1 (first-order reactions).
    integer, parameter :: one = n_species + 1
    integer, parameter :: first(n_reactions) = [ &
        1, 2, 5, 7, 7, 7, 9, 9, 11, 11, 13, 10, 14, 1, 3, 4, 4, 16, 16, 17, 19, 19, 1, 19, 20]
    integer, parameter :: second(n_reactions) = [ &
        one, 4, 2, one, one, 6, one, 6, 2, 1, one, 2, one, 6, one, one, one, one, one, 6, &
        one, one, 4, 1, one]

    type, extends(testset_problem_t) :: pollu_t
    contains
        procedure :: setup => pollu_setup
        procedure :: rhs => pollu_rhs
        procedure :: dense_jacobian => pollu_dense_jacobian
    end type pollu_t

contains

    subroutine pollu_setup(self)
        class(pollu_t), intent(inout) :: self
        self%name = 'POLLU'
        self%title = 'air pollution chemistry (RIVM model, Verwer 1994)'
        self%t0 = 0.0_wp
        self%t_end = 60.0_wp
        allocate (self%y0(n_species), source=0.0_wp)
        self%y0(2) = 0.2_wp
        self%y0(4) = 0.04_wp
        self%y0(7) = 0.1_wp
        self%y0(8) = 0.3_wp
        self%y0(9) = 0.01_wp
        self%y0(17) = 0.007_wp
        self%yref = [0.5646255480022769e-01_wp, 0.1342484130422339e+00_wp, &
                     0.4139734331099427e-08_wp, 0.5523140207484359e-02_wp, &
                     0.2018977262302196e-06_wp, 0.1464541863493966e-06_wp, &
                     0.7784249118997964e-01_wp, 0.3245075353396018e+00_wp, &
                     0.7494013383880406e-02_wp, 0.1622293157301561e-07_wp, &
                     0.1135863833257075e-07_wp, 0.2230505975721359e-02_wp, &
                     0.2087162882798630e-03_wp, 0.1396921016840158e-04_wp, &
                     0.8964884856898295e-02_wp, 0.4352846369330103e-17_wp, &
                     0.6899219696263405e-02_wp, 0.1007803037365946e-03_wp, &
                     0.1772146513969984e-05_wp, 0.5682943292316392e-04_wp]
        self%atol_per_rtol = 1.0_wp
        self%atol_fixed = 0.0_wp
        self%use_mescd = .false.
    end subroutine pollu_setup

    !> Reaction rates r(m) at y.
    pure function pollu_rates(y) result(r)
        real(wp), intent(in) :: y(:)
        real(wp) :: r(n_reactions)
        real(wp) :: y1(one)
        y1 = [y(1:n_species), 1.0_wp]
        r = k*y1(first)*y1(second)
    end function pollu_rates

    !> Species balances f = S r (linear in r; used with r = rates or r = d rates / dy_j).
    pure subroutine pollu_combine(r, f)
        real(wp), intent(in) :: r(:)
        real(wp), intent(out) :: f(:)
        f(1) = -r(1) - r(10) - r(14) - r(23) - r(24) &
               + r(2) + r(3) + r(9) + r(11) + r(12) + r(22) + r(25)
        f(2) = -r(2) - r(3) - r(9) - r(12) + r(1) + r(21)
        f(3) = -r(15) + r(1) + r(17) + r(19) + r(22)
        f(4) = -r(2) - r(16) - r(17) - r(23) + r(15)
        f(5) = -r(3) + r(4) + r(4) + r(6) + r(7) + r(13) + r(20)
        f(6) = -r(6) - r(8) - r(14) - r(20) + r(3) + r(18) + r(18)
        f(7) = -r(4) - r(5) - r(6) + r(13)
        f(8) = r(4) + r(5) + r(6) + r(7)
        f(9) = -r(7) - r(8)
        f(10) = -r(12) + r(7) + r(9)
        f(11) = -r(9) - r(10) + r(8) + r(11)
        f(12) = r(9)
        f(13) = -r(11) + r(10)
        f(14) = -r(13) + r(12)
        f(15) = r(14)
        f(16) = -r(18) - r(19) + r(16)
        f(17) = -r(20)
        f(18) = r(20)
        f(19) = -r(21) - r(22) - r(24) + r(23) + r(25)
        f(20) = -r(25) + r(24)
    end subroutine pollu_combine

    subroutine pollu_rhs(self, t, y, ydot, status)
        class(pollu_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: ydot(:)
        integer, intent(out) :: status
        call pollu_combine(pollu_rates(y), ydot)
        status = STATUS_OK
    end subroutine pollu_rhs

    !> df/dy = S dr/dy, column by column.
    subroutine pollu_dense_jacobian(self, t, y, dfdy)
        class(pollu_t), intent(in) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: dfdy(:, :)
        real(wp) :: drdy(n_reactions, one), y1(one)
        integer :: m, j
        y1 = [y(1:n_species), 1.0_wp]
        drdy = 0.0_wp
        do m = 1, n_reactions   ! d(k y_a y_b) = k y_b dy_a + k y_a dy_b (column `one` unused)
            drdy(m, first(m)) = drdy(m, first(m)) + k(m)*y1(second(m))
            drdy(m, second(m)) = drdy(m, second(m)) + k(m)*y1(first(m))
        end do
        do j = 1, n_species
            call pollu_combine(drdy(:, j), dfdy(:, j))
        end do
    end subroutine pollu_dense_jacobian
end module ropedyn_testset_pollu
