!> Butcher tables of the embedded explicit Runge-Kutta pairs behind `method = 'erk'`
!! (docs/theory/erk.md says how they were chosen).
!!
!! Each table is first-same-as-last (FSAL): its last stage is f at the new solution and
!! serves as the first stage of the next step, so a step costs `stages - 1` evaluations
!! of f. The propagated solution has order `order`; the embedded one, whose difference
!! gives the error estimate, order `order - 1`. A combination of the stages estimates the
!! spectral radius along the error (Hairer's stiffness detection) at no cost: the last two,
!! both at c = 1 (Dormand-Prince), or `rho_alpha` (the other two pairs).
!!
!! | max_order | pair | stages (f per step) | on the imaginary axis |
!! |---|---|---|---|
!! | 3 | Bogacki-Shampine 3(2) | 4 (3) | stable for h omega <= 1.73 |
!! | 4 | RK4 (Kutta's 3/8 rule) with a 3rd-order estimate from every stage | 5 (4) | 2.83 |
!! | 5 | Dormand-Prince 5(4) | 7 (6) | 0.997 (3.3 with the rope's damping) |
module ropedyn_erk_tables
    use ropedyn_kinds, only: wp
    implicit none
    private
    public :: erk_table_t, erk_table, ERK_MAX_STAGES

    integer, parameter :: ERK_MAX_STAGES = 7

    !> One embedded pair.
    type :: erk_table_t
        character(len=32) :: name = ''
        integer :: order = 0                 !< order of the propagated solution
        integer :: stages = 0                !< stages per step, the FSAL stage included
        real(wp) :: a(ERK_MAX_STAGES, ERK_MAX_STAGES) = 0.0_wp  !< a(i, j), j < i
        real(wp) :: b(ERK_MAX_STAGES) = 0.0_wp   !< weights of the solution (= a(stages, :))
        real(wp) :: c(ERK_MAX_STAGES) = 0.0_wp   !< nodes
        real(wp) :: e(ERK_MAX_STAGES) = 0.0_wp   !< b - bhat: the error estimate is h sum e_i k_i
        !> Hairer's continuous extension of Dormand-Prince 5(4) (4th order); without it,
        !! the cubic Hermite interpolant of y and f at both ends of the step (3rd order)
        logical :: dp5_dense = .false.
        real(wp) :: d(ERK_MAX_STAGES) = 0.0_wp   !< its coefficients
        !> h |lambda| below which every eigenvalue near the imaginary axis is stable (what
        !! the stiffness test of the step compares h rho with)
        real(wp) :: stability_limit = 0.0_wp
        !> coefficients of the stability polynomial R(z) = sum_k gamma(k) z^k
        real(wp) :: gamma(0:ERK_MAX_STAGES) = 0.0_wp
        !> the stages whose combination estimates the spectral radius: rho = |sum alpha_i
        !! k_i| / |sum alpha_i Y_i|, sum alpha_i Y_i = h sum beta_j k_j with beta = A^T alpha
        !! (Y_i the stage arguments). Without (all 0): the last two stages, both at c = 1.
        real(wp) :: rho_alpha(ERK_MAX_STAGES) = 0.0_wp
        real(wp) :: rho_beta(ERK_MAX_STAGES) = 0.0_wp
    contains
        procedure :: evals_per_step => table_evals_per_step
        procedure :: amplification => table_amplification
    end type erk_table_t

contains

    !> The pair of a given order (3, 4 or 5); an empty table (stages = 0) for any other.
    pure function erk_table(order) result(tab)
        integer, intent(in) :: order
        type(erk_table_t) :: tab
        select case (order)
        case (3)
            tab = bogacki_shampine()
        case (4)
            tab = rk4_fsal()
        case (5)
            tab = dormand_prince()
        case default
            return
        end select
        call set_gamma(tab)
        tab%rho_beta = matmul(transpose(tab%a), tab%rho_alpha)
    end function erk_table

    !> Evaluations of f per accepted step without rejections (the FSAL stage is reused).
    pure integer function table_evals_per_step(self) result(evals)
        class(erk_table_t), intent(in) :: self
        evals = self%stages - 1
    end function table_evals_per_step

    !> |R(z)|: the amplification of one step for y' = lambda y, z = h lambda.
    pure real(wp) function table_amplification(self, z) result(amp)
        class(erk_table_t), intent(in) :: self
        complex(wp), intent(in) :: z
        complex(wp) :: r
        integer :: k
        r = cmplx(self%gamma(self%stages), 0.0_wp, wp)
        do k = self%stages - 1, 0, -1
            r = r*z + self%gamma(k)
        end do
        amp = abs(r)
    end function table_amplification

    !> gamma(k) = b^T A^(k-1) 1 (gamma(0) = 1): the stability polynomial of the table.
    pure subroutine set_gamma(tab)
        type(erk_table_t), intent(inout) :: tab
        real(wp) :: v(ERK_MAX_STAGES)
        integer :: k, s
        s = tab%stages
        tab%gamma = 0.0_wp
        tab%gamma(0) = 1.0_wp
        v = 0.0_wp
        v(1:s) = 1.0_wp
        do k = 1, s
            tab%gamma(k) = dot_product(tab%b(1:s), v(1:s))
            v(1:s) = matmul(tab%a(1:s, 1:s), v(1:s))
        end do
    end subroutine set_gamma

    !> Bogacki & Shampine (1989), the 3(2) pair of MATLAB's ode23.
    pure function bogacki_shampine() result(tab)
        type(erk_table_t) :: tab
        tab%name = 'Bogacki-Shampine 3(2)'
        tab%order = 3
        tab%stages = 4
        tab%c(1:4) = [0.0_wp, 0.5_wp, 0.75_wp, 1.0_wp]
        tab%a(2, 1) = 0.5_wp
        tab%a(3, 2) = 0.75_wp
        tab%a(4, 1:3) = [2.0_wp/9.0_wp, 1.0_wp/3.0_wp, 4.0_wp/9.0_wp]
        tab%b(1:4) = tab%a(4, 1:4)
        ! bhat = (7/24, 1/4, 1/3, 1/8)
        tab%e(1:4) = tab%b(1:4) - [7.0_wp/24.0_wp, 0.25_wp, 1.0_wp/3.0_wp, 0.125_wp]
        tab%stability_limit = sqrt(3.0_wp)
        ! The spectral radius along the error: its last two stages are at c = 3/4 and 1, and
        ! Y4 - Y3 would be y0 (z/4 + z^2/8 + z^3/6) on y' = lambda y, so slow modes would
        ! weigh in at O(z) and pull the estimate down (the steel wire at max_order = 3 ran
        ! at 2.8e5 steps per simulated second undiagnosed). Y1 - 4 Y3 + 3 Y4 = y0 z^3/2 has
        ! no constant, z or z^2 term, and sum alpha_i c_i = 0 (no f_t term); it is the one
        ! such combination (up to a factor).
        tab%rho_alpha(1:4) = [1.0_wp, 0.0_wp, -4.0_wp, 3.0_wp]
    end function bogacki_shampine

    !> Kutta's 3/8 rule (4th order, 4 stages: the same stability polynomial as the classical
    !! RK4, 2 sqrt(2) on the imaginary axis for 4 evaluations, the longest per evaluation of
    !! the three pairs), with a fifth stage f(y1) (FSAL) and a 3rd-order embedded solution
    !! that uses every stage: bhat = b - e with e = s (1/4, -3/4, 3/4, 3/4, -1), the one-
    !! parameter family of 3rd-order solutions on these stages (order conditions checked in
    !! tests/unit/test_erk_tables.f90).
    !!
    !! Why not the classical RK4: on its nodes (0, 1/2, 1/2, 1, 1) the 3rd-order embedded
    !! solutions differ from RK4 only in the two stages at c = 1, so its estimate,
    !! h (k4 - k5)/6, looks at the end of the step alone and misses what happens inside
    !! it: on the ground contact (a kink of the normal force, a steep friction law) erk at
    !! rtol 1e-6 ended 4.6e-3 m from a tight reference after 1 s of whip_ground, where
    !! cvode at the same rtol is within 6.6e-5 m, and tightening to 1e-10 still left
    !! 2.6e-5 m. With this pair: 1.9e-5 m at rtol 1e-6, 1.9e-6 m at 1e-8.
    !!
    !! s = 0.15: the norm of the embedded solution's 4th-order error coefficients,
    !! -(sum e c^3, sum e c (A c), sum e A c^2, sum e A^2 c) = s (1/18, 1/12, 0, -1/12), is
    !! then that of the classical pair, (0, 0, 1/72, -1/72) (docs/theory/erk.md), so steps
    !! on smooth motion stay as long
    !! (scripts/auto_table: every scene within the noise of the classical pair's CPU).
    pure function rk4_fsal() result(tab)
        type(erk_table_t) :: tab
        real(wp), parameter :: s = 0.15_wp
        tab%name = 'RK4 3/8 rule, 3rd-order estimate'
        tab%order = 4
        tab%stages = 5
        tab%c(1:5) = [0.0_wp, 1.0_wp/3.0_wp, 2.0_wp/3.0_wp, 1.0_wp, 1.0_wp]
        tab%a(2, 1) = 1.0_wp/3.0_wp
        tab%a(3, 1:2) = [-1.0_wp/3.0_wp, 1.0_wp]
        tab%a(4, 1:3) = [1.0_wp, -1.0_wp, 1.0_wp]
        tab%a(5, 1:4) = [0.125_wp, 0.375_wp, 0.375_wp, 0.125_wp]
        tab%b(1:5) = tab%a(5, 1:5)
        tab%e(1:5) = s*[0.25_wp, -0.75_wp, 0.75_wp, 0.75_wp, -1.0_wp]
        tab%stability_limit = 2.0_wp*sqrt(2.0_wp)
        ! The spectral radius along the error: Y5 - Y4 (both at c = 1) would be y0 (z^2/6 -
        ! z^3/6 + z^4/24) on y' = lambda y, z = h lambda, so slow modes (small z) would weigh
        ! in at O(z^2) against O(1) for the fast ones and pull the estimate down (erk no
        ! longer saw the 1000-element rope's stiffness). Y5 - Y4 + Y2 - (Y1 + Y3)/2 has no
        ! constant, z or z^2 term (and sum alpha_i c_i = 0: no f_t term): y0 (-z^3/6 +
        ! z^4/24), as the classical RK4's Y5 - Y4 (-z^3/12 + z^4/24). (Y5 - 3/2 Y3 + Y1/2,
        ! also free of them, weighs positions and velocities otherwise: on the paper's rope
        ! it gave twice the spectral radius, the first-order form's J being far from normal.)
        tab%rho_alpha(1:5) = [-0.5_wp, 1.0_wp, -0.5_wp, -1.0_wp, 1.0_wp]
    end function rk4_fsal

    !> Dormand & Prince (1980), the 5(4) pair of DOPRI5 and MATLAB's ode45, with Hairer's
    !! continuous extension (Hairer, Norsett & Wanner, Solving ODEs I, II.6).
    pure function dormand_prince() result(tab)
        type(erk_table_t) :: tab
        tab%name = 'Dormand-Prince 5(4)'
        tab%order = 5
        tab%stages = 7
        tab%c(1:7) = [0.0_wp, 0.2_wp, 0.3_wp, 0.8_wp, 8.0_wp/9.0_wp, 1.0_wp, 1.0_wp]
        tab%a(2, 1) = 0.2_wp
        tab%a(3, 1:2) = [3.0_wp/40.0_wp, 9.0_wp/40.0_wp]
        tab%a(4, 1:3) = [44.0_wp/45.0_wp, -56.0_wp/15.0_wp, 32.0_wp/9.0_wp]
        tab%a(5, 1:4) = [19372.0_wp/6561.0_wp, -25360.0_wp/2187.0_wp, 64448.0_wp/6561.0_wp, &
                         -212.0_wp/729.0_wp]
        tab%a(6, 1:5) = [9017.0_wp/3168.0_wp, -355.0_wp/33.0_wp, 46732.0_wp/5247.0_wp, &
                         49.0_wp/176.0_wp, -5103.0_wp/18656.0_wp]
        tab%a(7, 1:6) = [35.0_wp/384.0_wp, 0.0_wp, 500.0_wp/1113.0_wp, 125.0_wp/192.0_wp, &
                         -2187.0_wp/6784.0_wp, 11.0_wp/84.0_wp]
        tab%b(1:7) = tab%a(7, 1:7)
        tab%e(1:7) = [71.0_wp/57600.0_wp, 0.0_wp, -71.0_wp/16695.0_wp, 71.0_wp/1920.0_wp, &
                      -17253.0_wp/339200.0_wp, 22.0_wp/525.0_wp, -1.0_wp/40.0_wp]
        tab%dp5_dense = .true.
        tab%d(1:7) = [-12715105075.0_wp/11282082432.0_wp, 0.0_wp, &
                      87487479700.0_wp/32700410799.0_wp, -10690763975.0_wp/1880347072.0_wp, &
                      701980252875.0_wp/199316789632.0_wp, -1453857185.0_wp/822651844.0_wp, &
                      69997945.0_wp/29380423.0_wp]
        ! Hairer's stiffness test for DOPRI5 compares h rho with 3.25
        tab%stability_limit = 3.25_wp
    end function dormand_prince
end module ropedyn_erk_tables
