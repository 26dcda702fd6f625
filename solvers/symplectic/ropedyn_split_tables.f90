!> The compositions of `method = 'symplectic'` (ropedyn_symplectic) and their stable steps.
!!
!! A composition of kicks v += b_i h a_c(q) and drifts q += a_i h v, B A B ... A B (s
!! drifts, s + 1 kicks; the last kick of a step and the first of the next are at the same
!! q, so a step costs s evaluations of the forces):
!! - Stormer-Verlet (velocity Verlet), order 2, s = 1: b = (1/2, 1/2), a = (1).
!! - Blanes & Moan's SRKN_6^b (J. Comput. Appl. Math. 142 (2002) 313, table 3), order 4,
!!   s = 6, symmetric, the smallest error of the 4th-order compositions of that paper per
!!   evaluation.
!!
!! Stable steps (docs/theory/symplectic.md, "Stability"): the method as ropedyn_symplectic
!! runs it, with the forces other than the potential's in a D-map between steps evaluated
!! at a predicted velocity, applied to the damped oscillator x'' = -w^2 x - 2 zeta w x', is
!! stable for h w below the tabulated limit at zeta (scanned in steps of 5e-4 of h w
!! up to the first step at which the one-step matrix has an eigenvalue above 1 + 1e-10;
!! a unit test checks the table against the integrator itself). Between the tabulated
!! zetas the limit of the next larger one holds (the limits fall with zeta); beyond
!! zeta = 1 the damping alone limits: h 2 zeta w <= OVERDAMPED_LIMIT.
module ropedyn_split_tables
    use ropedyn_kinds, only: wp
    implicit none
    private
    public :: split_table_t, split_table, TABLE_VERLET, TABLE_BM6, STABLE_ZETA, OVERDAMPED_LIMIT

    integer, parameter :: TABLE_VERLET = 1, TABLE_BM6 = 2
    integer, parameter :: NZ = 15
    real(wp), parameter :: STABLE_ZETA(NZ) = [0.0_wp, 0.005_wp, 0.01_wp, 0.02_wp, 0.03_wp, &
        0.05_wp, 0.07_wp, 0.1_wp, 0.15_wp, 0.2_wp, 0.3_wp, 0.4_wp, 0.5_wp, 0.7_wp, 1.0_wp]
    real(wp), parameter :: LIMIT_VERLET(NZ) = [2.0_wp, 1.98_wp, 1.96_wp, 1.9215_wp, &
        1.8835_wp, 1.8095_wp, 1.7395_wp, 1.6395_wp, 1.488_wp, 1.354_wp, 1.132_wp, 0.961_wp, &
        0.828_wp, 0.6405_wp, 0.472_wp]
    real(wp), parameter :: LIMIT_BM6(NZ) = [3.163_wp, 3.163_wp, 3.163_wp, 3.16_wp, &
        3.1545_wp, 3.141_wp, 3.1215_wp, 3.07_wp, 2.8065_wp, 2.3175_wp, 1.6175_wp, 1.2295_wp, &
        0.9895_wp, 0.7105_wp, 0.4985_wp]
    !> h c <= this for c = 2 zeta w, zeta > 1 (both tables: 0.944 .. 0.999 measured)
    real(wp), parameter :: OVERDAMPED_LIMIT = 0.94_wp

    !> One composition.
    type :: split_table_t
        integer :: kind = 0
        character(len=24) :: label = ''
        integer :: order = 0
        integer :: stages = 0              !< s: drifts, force evaluations per step
        real(wp), allocatable :: a(:)      !< drift coefficients (s)
        real(wp), allocatable :: b(:)      !< kick coefficients (s + 1)
        real(wp), allocatable :: limit(:)  !< stable h w at STABLE_ZETA
        !> the step over the stable step where the fast modes are damped
        real(wp) :: safety = 0.0_wp
        !> the tolerance that step reaches (below it the step shrinks as rtol^(1/order)):
        !! the tip of the paper's rope, n = 30, over 2 s, as close to a tight reference as
        !! auto's at this rtol (docs/theory/symplectic.md, "The step")
        real(wp) :: rtol_at = 0.0_wp
    contains
        procedure :: stable_hw => table_stable_hw
    end type split_table_t

contains

    !> The composition `kind` (TABLE_VERLET or TABLE_BM6).
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
end module ropedyn_split_tables
