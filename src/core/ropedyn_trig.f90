!> Cosine and sine of many angles at once, for the model kernels.
!!
!! The RFEM right-hand side needs cos and sin of every element's angle on every call; the C
!! library's scalar `sincos` was a fifth of the paper run's time (perf, docs/performance/step.md).
!! Here the loop over the angles is branch-free and vectorizes: Cody-Waite reduction by
!! pi/2 (three-part constant, exact for |x| < 2^19 pi/2) to r in [-pi/4, pi/4], fdlibm's
!! minimax polynomials for sin r and cos r (errors below 1 ulp of 1 on that interval), and
!! the quadrant chosen with `merge`. Angles beyond the reduction's range (more than about
!! 10^5 turns) fall back to the intrinsics.
!!
!! Accuracy: |error| <= 2.5e-16 in each of cos and sin (test_trig checks it against the
!! intrinsics over 10^5 angles in [-1000, 1000] and at the quadrant boundaries).
module ropedyn_trig
    use ropedyn_kinds, only: wp
    implicit none
    private
    public :: cos_sin

    !> 2/pi, and pi/2 in three parts (fdlibm's pio2_1, pio2_2, pio2_3: the first two hold
    !! 33 bits each, so that k * part is exact for |k| < 2^20)
    real(wp), parameter :: TWO_OVER_PI = 6.36619772367581382433e-01_wp
    real(wp), parameter :: PIO2_1 = 1.57079632673412561417e+00_wp
    real(wp), parameter :: PIO2_2 = 6.07710050630396597660e-11_wp
    real(wp), parameter :: PIO2_3 = 2.02226624871116645580e-21_wp
    !> 1.5 2^52: (z + SHIFTER) - SHIFTER rounds z to the nearest integer (|z| < 2^51)
    !! without a library call, so that the loop vectorizes
    real(wp), parameter :: SHIFTER = 6755399441055744.0_wp
    !> largest |x| reduced here (k < 2^19)
    real(wp), parameter :: REDUCE_LIMIT = 8.0e5_wp
    !> sin r = r + r^3 (S1 + r^2 (S2 + ... )) on [-pi/4, pi/4] (fdlibm __kernel_sin)
    real(wp), parameter :: S1 = -1.66666666666666324348e-01_wp, &
                           S2 = 8.33333333332248946124e-03_wp, &
                           S3 = -1.98412698298579493134e-04_wp, &
                           S4 = 2.75573137070700676789e-06_wp, &
                           S5 = -2.50507602534068634195e-08_wp, &
                           S6 = 1.58969099521155010221e-10_wp
    !> cos r = 1 - r^2/2 + r^4 (C1 + r^2 (C2 + ... )) (fdlibm __kernel_cos)
    real(wp), parameter :: C1 = 4.16666666666666019037e-02_wp, &
                           C2 = -1.38888888888741095749e-03_wp, &
                           C3 = 2.48015872894767294178e-05_wp, &
                           C4 = -2.75573143513906633035e-07_wp, &
                           C5 = 2.08757232129817482790e-09_wp, &
                           C6 = -1.13596475577881948265e-11_wp

contains

    !> cs(1, i) = cos(x(i)), cs(2, i) = sin(x(i)).
    pure subroutine cos_sin(x, cs)
        real(wp), contiguous, intent(in) :: x(:)
        real(wp), contiguous, intent(inout) :: cs(:, :)   !< (2, size(x)) at least
        real(wp) :: fk, r, z, sr, cr, hz, w
        integer :: i, q

        if (any(abs(x) > REDUCE_LIMIT)) then
            do i = 1, size(x)
                cs(1, i) = cos(x(i))
                cs(2, i) = sin(x(i))
            end do
            return
        end if
        do i = 1, size(x)
            fk = (x(i)*TWO_OVER_PI + SHIFTER) - SHIFTER
            r = ((x(i) - fk*PIO2_1) - fk*PIO2_2) - fk*PIO2_3
            z = r*r
            sr = r + r*z*(S1 + z*(S2 + z*(S3 + z*(S4 + z*(S5 + z*S6)))))
            hz = 0.5_wp*z
            w = 1.0_wp - hz
            cr = w + (((1.0_wp - w) - hz) + z*z*(C1 + z*(C2 + z*(C3 + z*(C4 + z*(C5 + &
                                                                                  z*C6))))))
            q = iand(int(fk), 3)
            ! quadrant 0: (cos r, sin r); 1: (-sin r, cos r); 2: (-cos r, -sin r);
            ! 3: (sin r, -cos r)
            cs(1, i) = merge(cr, sr, iand(q, 1) == 0)
            cs(2, i) = merge(sr, cr, iand(q, 1) == 0)
            cs(1, i) = merge(-cs(1, i), cs(1, i), q == 1 .or. q == 2)
            cs(2, i) = merge(-cs(2, i), cs(2, i), q >= 2)
        end do
    end subroutine cos_sin
end module ropedyn_trig
