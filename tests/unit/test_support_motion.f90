!> Support motions (src/models/ropedyn_support_motion.f90): the harmonic motion's ramp
!! (smoothstep 10u^3 - 15u^4 + 6u^5 over top_ramp_time) starts from rest, reaches the full
!! motion at the ramp time with the same position, velocity and acceleration, and its
!! velocity and acceleration are the derivatives of its position (central differences);
!! a coupled support rests at its anchor until the first exchange, then follows the cubic
!! Hermite curve to the prescribed position and velocity, C1 across exchanges, with the
!! curve's own derivatives.
program test_support_motion
    use ropedyn_kinds, only: wp
    use ropedyn_support_motion, only: support_motion_t, motion_state_t
    use ropedyn_assert, only: test_suite_t
    implicit none

    real(wp), parameter :: RAMP = 2.0_wp, H = 1.0e-5_wp
    type(test_suite_t) :: suite
    type(support_motion_t) :: ramped, plain, coupled
    type(motion_state_t) :: s, r
    real(wp), allocatable :: none(:, :)
    real(wp) :: t
    integer :: k
    logical :: moving

    suite%name = 'support_motion'
    ramped%p0 = [0.5_wp, -0.25_wp]
    plain%p0 = ramped%p0
    moving = ramped%configure('harmonic', [0.1_wp, 0.05_wp], 0.7_wp, [30.0_wp, 0.0_wp], &
                              0.0_wp, 0.0_wp, none, RAMP)
    moving = plain%configure('harmonic', [0.1_wp, 0.05_wp], 0.7_wp, [30.0_wp, 0.0_wp], &
                             0.0_wp, 0.0_wp, none, 0.0_wp)
    s = ramped%state(0.0_wp)
    call suite%check_le(maxval(abs(s%p - ramped%p0)) + maxval(abs(s%v)) + maxval(abs(s%a)), &
                        0.0_wp, 'ramp: at rest at the anchor at t = 0')
    do k = 0, 3
        t = RAMP + k*0.3_wp
        s = ramped%state(t)
        r = plain%state(t)
        call suite%check_le(maxval(abs(s%p - r%p)) + maxval(abs(s%v - r%v)) + &
                            maxval(abs(s%a - r%a)), 1.0e-15_wp, 'ramp: the full motion from T on')
    end do
    do k = 1, 9
        t = k*0.25_wp
        call check_derivatives(ramped, t, 'ramp')
    end do
    ! across the end of the ramp: the same derivatives from either side
    call check_derivatives(ramped, RAMP, 'ramp at T')

    coupled%p0 = [1.0_wp, 0.0_wp]
    moving = coupled%configure('coupled', [0.0_wp, 0.0_wp], 0.0_wp, [0.0_wp, 0.0_wp], &
                               0.0_wp, 0.0_wp, none, 0.0_wp)
    call suite%check_true(moving, 'coupled: a moving support')
    s = coupled%state(0.7_wp)
    call suite%check_le(maxval(abs(s%p - coupled%p0)) + maxval(abs(s%v)), 0.0_wp, &
                        'coupled: at rest before the first exchange')
    call coupled%couple(0.0_wp, 0.1_wp, [1.0_wp, 0.02_wp], [0.0_wp, 0.3_wp])
    s = coupled%state(0.1_wp)
    call suite%check_le(maxval(abs(s%p - [1.0_wp, 0.02_wp])) + &
                        maxval(abs(s%v - [0.0_wp, 0.3_wp])), 1.0e-15_wp, &
                        'coupled: at the prescribed position and velocity')
    call check_derivatives(coupled, 0.05_wp, 'coupled')
    r = coupled%state(0.1_wp)
    call coupled%couple(0.1_wp, 0.25_wp, [1.01_wp, 0.05_wp], [0.1_wp, 0.1_wp])
    s = coupled%state(0.1_wp)
    call suite%check_le(maxval(abs(s%p - r%p)) + maxval(abs(s%v - r%v)), 1.0e-15_wp, &
                        'coupled: C1 across an exchange')
    call check_derivatives(coupled, 0.2_wp, 'coupled, second curve')
    call suite%finish()

contains

    !> v and a against central differences of p and v at t.
    subroutine check_derivatives(motion, t, label)
        type(support_motion_t), intent(in) :: motion
        real(wp), intent(in) :: t
        character(len=*), intent(in) :: label
        type(motion_state_t) :: s, lo, hi
        s = motion%state(t)
        lo = motion%state(t - H)
        hi = motion%state(t + H)
        call suite%check_le(maxval(abs((hi%p - lo%p)/(2*H) - s%v)), 1.0e-8_wp, &
                            label//': velocity = dp/dt')
        call suite%check_le(maxval(abs((hi%v - lo%v)/(2*H) - s%a)), 1.0e-6_wp, &
                            label//': acceleration = dv/dt')
    end subroutine check_derivatives
end program test_support_motion
