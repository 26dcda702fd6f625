!> The compositions of `method = 'symplectic'` (ropedyn_symplectic) and their stable steps.
!!
!! A composition of kicks v += b_i h a_c(q) and drifts q += a_i h v, B A B ... A B (s
!! drifts, s + 1 kicks; the last kick of a step and the first of the next are at the same
!! q, so a step costs s evaluations of the forces):
!! - Stormer-Verlet (velocity Verlet), order 2, s = 1: b = (1/2, 1/2), a = (1).
!! - Blanes & Moan's SRKN_6^b (J. Comput. Appl. Math. 142 (2002) 313, table 3), order 4,
!!   s = 6, symmetric, the smallest error of the 4th-order compositions of that paper per
!!   evaluation.
!! - Chin's 4A (S. A. Chin, Phys. Lett. A 226 (1997) 344), order 4, s = 2: b = (1/6, 2/3,
!!   1/6), a = (1/2, 1/2), the middle kick with the force of the modified potential
!!   V - (h^2/48) F.M^-1 F, whose acceleration is a + (h^2/24) (da/dq) a (grad = 1/24: the
!!   kick's force gradient, ropedyn_symplectic's step takes the directional derivative by
!!   a difference). 3 evaluations per step, stable to h w = 3.46 undamped: the fewest
!!   evaluations per simulated second of the 4th-order methods compared in
!!   docs/theory/symplectic.md, with a larger error on the fastest modes than SRKN_6^b.
!!
!! Stable steps (docs/theory/symplectic.md, "Stability"): the method as ropedyn_symplectic
!! runs it, with the forces other than the potential's in a D-map between steps evaluated
!! at a predicted velocity, applied to the damped oscillator x'' = -w^2 x - 2 zeta w x', is
!! stable for h w below the tabulated limit at zeta (scanned in steps of 5e-4 of h w
!! up to the first step at which the one-step matrix has an eigenvalue above 1 + 1e-10, by
!! scripts/compositions' replica of the step; a unit test checks the table against the
!! integrator itself, and an end-to-end test against that scan). Between the tabulated
!! zetas the limit of the next larger one holds (the limits fall with zeta); beyond
!! zeta = 1 the damping alone limits: h 2 zeta w <= OVERDAMPED_LIMIT.
module ropedyn_split_tables
    use ropedyn_kinds, only: wp
    implicit none
    private
    public :: split_table_t, split_table, TABLE_VERLET, TABLE_BM6, TABLE_CHIN, STABLE_ZETA, &
              OVERDAMPED_LIMIT

    integer, parameter :: TABLE_VERLET = 1, TABLE_BM6 = 2, TABLE_CHIN = 3
    integer, parameter :: NZ = 15
    real(wp), parameter :: STABLE_ZETA(NZ) = [0.0_wp, 0.005_wp, 0.01_wp, 0.02_wp, 0.03_wp, &
        0.05_wp, 0.07_wp, 0.1_wp, 0.15_wp, 0.2_wp, 0.3_wp, 0.4_wp, 0.5_wp, 0.7_wp, 1.0_wp]
    real(wp), parameter :: LIMIT_VERLET(NZ) = [2.0_wp, 1.98_wp, 1.96_wp, 1.9215_wp, &
        1.8835_wp, 1.8095_wp, 1.7395_wp, 1.6395_wp, 1.488_wp, 1.354_wp, 1.132_wp, 0.961_wp, &
        0.828_wp, 0.6405_wp, 0.472_wp]
    real(wp), parameter :: LIMIT_BM6(NZ) = [3.163_wp, 3.163_wp, 3.163_wp, 3.16_wp, &
        3.1545_wp, 3.141_wp, 3.1215_wp, 3.07_wp, 2.8065_wp, 2.3175_wp, 1.6175_wp, 1.2295_wp, &
        0.9895_wp, 0.7105_wp, 0.4985_wp]
    real(wp), parameter :: LIMIT_CHIN(NZ) = [3.464_wp, 3.4335_wp, 3.4025_wp, 3.3375_wp, &
        3.27_wp, 3.1265_wp, 2.974_wp, 2.735_wp, 2.3435_wp, 2.0_wp, 1.495_wp, 1.1735_wp, &
        0.96_wp, 0.699_wp, 0.4945_wp]
    !> h c <= this for c = 2 zeta w, zeta > 1 (every table: 0.944 .. 0.999 measured)
    real(wp), parameter :: OVERDAMPED_LIMIT = 0.94_wp
    !> Chin 4A's rtol_at (split_table_t): on the paper's rope (n = 30, 2 s) the tip errs
    !! 1.2e-8 m at its step, between auto's 3.5e-9 at rtol 3e-6 and 7.3e-8 at 1e-5 (5e-6);
    !! on the shaken support of input/hard (1 s, against cvode at the same rtol) it erred
    !! 37 rtol L at rtol 1e-7 with 5e-6, SRKN_6^b 16; with 2e-5 15.7, at 0.7 of SRKN_6^b's
    !! evaluations (the larger, so that it is no less accurate than SRKN_6^b there)
    real(wp), parameter :: CHIN_RTOL_AT = 2.0e-5_wp

    !> One composition.
    type :: split_table_t
        integer :: kind = 0
        character(len=24) :: label = ''
        integer :: order = 0
        integer :: stages = 0              !< s: drifts, force evaluations per step
        real(wp), allocatable :: a(:)      !< drift coefficients (s)
        real(wp), allocatable :: b(:)      !< kick coefficients (s + 1)
        real(wp), allocatable :: limit(:)  !< stable h w at STABLE_ZETA
        !> per kick (s + 1): g of a force-gradient kick, whose acceleration is
        !! a + g h^2 (da/dq) a (0: a plain kick)
        real(wp), allocatable :: grad(:)
        integer :: evals = 0               !< force evaluations per step (s + gradient kicks)
        !> the step over the stable step where the fast modes are damped
        real(wp) :: safety = 0.0_wp
        !> the tolerance that step reaches (below it the step shrinks as rtol^(1/order)):
        !! the tip of the paper's rope, n = 30, over 2 s, as close to a tight reference as
        !! auto's at this rtol (docs/theory/symplectic.md, "The step")
        real(wp) :: rtol_at = 0.0_wp
    contains
        procedure :: stable_hw => table_stable_hw
        procedure :: energy_spread => table_energy_spread
        procedure :: energy_hw => table_energy_hw
    end type split_table_t

contains

    !> The composition `kind` (TABLE_VERLET, TABLE_BM6 or TABLE_CHIN).
    pure function split_table(kind) result(tab)
        integer, intent(in) :: kind
        type(split_table_t) :: tab
        real(wp), parameter :: b1 = 0.0829844064174052_wp, b2 = 0.396309801498368_wp, &
            b3 = -0.0390563049223486_wp, a1 = 0.245298957184271_wp, &
            a2 = 0.604872665711080_wp
        real(wp) :: a3, b4
        tab%kind = kind
        select case (kind)
        case (TABLE_BM6)
            a3 = 0.5_wp - (a1 + a2)
            b4 = 1.0_wp - 2.0_wp*(b1 + b2 + b3)
            tab%label = 'Blanes-Moan SRKN6b'
            tab%order = 4
            tab%a = [a1, a2, a3, a3, a2, a1]
            tab%b = [b1, b2, b3, b4, b3, b2, b1]
            tab%limit = LIMIT_BM6
            tab%safety = 0.45_wp
            tab%rtol_at = 2.0e-6_wp
        case (TABLE_CHIN)
            tab%label = 'Chin 4A'
            tab%order = 4
            tab%a = [0.5_wp, 0.5_wp]
            tab%b = [1.0_wp/6.0_wp, 2.0_wp/3.0_wp, 1.0_wp/6.0_wp]
            tab%grad = [0.0_wp, 1.0_wp/24.0_wp, 0.0_wp]
            tab%limit = LIMIT_CHIN
            tab%safety = 0.45_wp
            tab%rtol_at = CHIN_RTOL_AT
        case default
            tab%kind = TABLE_VERLET
            tab%label = 'Stormer-Verlet'
            tab%order = 2
            tab%a = [1.0_wp]
            tab%b = [0.5_wp, 0.5_wp]
            tab%limit = LIMIT_VERLET
            tab%safety = 0.5_wp
            tab%rtol_at = 1.0e-4_wp
        end select
        tab%stages = size(tab%a)
        if (.not. allocated(tab%grad)) then
            allocate (tab%grad(tab%stages + 1))
            tab%grad = 0.0_wp
        end if
        tab%evals = tab%stages + count(tab%grad /= 0.0_wp)
    end function split_table

    !> The stable h w of a mode damped by zeta (>= 0; see the module header).
    pure real(wp) function table_stable_hw(self, zeta) result(hw)
        class(split_table_t), intent(in) :: self
        real(wp), intent(in) :: zeta
        integer :: i
        if (zeta > STABLE_ZETA(NZ)) then
            hw = min(self%limit(NZ), OVERDAMPED_LIMIT/(2.0_wp*zeta))
            return
        end if
        do i = 1, NZ
            if (STABLE_ZETA(i) >= zeta) exit
        end do
        hw = self%limit(min(i, NZ))
    end function table_stable_hw

    !> The energy error of an undamped linear mode at h w = x: the relative spread of its
    !! energy (v^2 + w^2 q^2)/2 along the numerical orbit, the ratio of the axes of the
    !! quadratic form the composition conserves minus 1 (0 for the exact flow; huge where x
    !! is unstable). The same formula as scripts/compositions' column.
    pure real(wp) function table_energy_spread(self, x) result(spread)
        class(split_table_t), intent(in) :: self
        real(wp), intent(in) :: x
        real(wp) :: m11, m12, m21, m22, k, d, tr, det, disc, lo, hi
        integer :: i
        m11 = 1.0_wp
        m12 = 0.0_wp
        m21 = 0.0_wp
        m22 = 1.0_wp
        do i = 1, self%stages + 1
            ! a kick on q'' = -q at h = x (a gradient kick's force -q (1 - g x^2))
            k = self%b(i)*x*(1.0_wp - self%grad(i)*x*x)
            m21 = m21 - k*m11
            m22 = m22 - k*m12
            if (i <= self%stages) then
                m11 = m11 + self%a(i)*x*m21
                m12 = m12 + self%a(i)*x*m22
            end if
        end do
        ! the conserved form's matrix [[-m21, d], [d, m12]]: its eigenvalues' ratio
        d = 0.5_wp*(m11 - m22)
        tr = m12 - m21
        det = -m21*m12 - d*d
        disc = sqrt(max(0.0_wp, 0.25_wp*tr*tr - det))
        hi = 0.5_wp*tr + disc
        lo = det/hi
        if (lo <= 0.0_wp) then
            spread = huge(1.0_wp)
        else
            spread = hi/lo - 1.0_wp
        end if
    end function table_energy_spread

    !> The largest h w, below the undamped stability limit, at which an undamped linear
    !! mode's energy spread (table_energy_spread) is at most `spread` (bisection: the
    !! spread grows with h w there).
    pure real(wp) function table_energy_hw(self, spread) result(x)
        class(split_table_t), intent(in) :: self
        real(wp), intent(in) :: spread
        real(wp) :: lo, hi
        integer :: it
        lo = 0.0_wp
        hi = self%limit(1)
        if (self%energy_spread(hi) <= spread) then
            x = hi
            return
        end if
        do it = 1, 60
            x = 0.5_wp*(lo + hi)
            if (self%energy_spread(x) <= spread) then
                lo = x
            else
                hi = x
            end if
        end do
        x = lo
    end function table_energy_hw
end module ropedyn_split_tables
