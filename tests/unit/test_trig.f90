!> The vectorized cosine and sine of the kernels (src/core/ropedyn_trig.f90) against the
!! intrinsics: over 10^5 angles spread over [-1000, 1000] rad, at and next to the quadrant
!! boundaries k pi/2 (where the reduction switches quadrant), small angles, and angles beyond
!! the reduction's range (the intrinsics' fallback). A wrong quadrant, sign, coefficient or
!! reduction constant gives errors of order 1e-2 .. 1; the bound is about 1 ulp of 1.
program test_trig
    use ropedyn_kinds, only: wp
    use ropedyn_trig, only: cos_sin
    use ropedyn_assert, only: test_suite_t
    implicit none

    integer, parameter :: N = 100000
    real(wp), parameter :: BOUND = 2.5e-16_wp
    real(wp), parameter :: PI = acos(-1.0_wp)
    type(test_suite_t) :: suite
    real(wp), allocatable :: x(:)
    integer :: i, k

    suite%name = 'trig'
    allocate (x(N))
    do i = 1, N
        x(i) = -1000.0_wp + 2000.0_wp*real(i - 1, wp)/real(N - 1, wp) + &
               1.0e-3_wp*sin(real(i, wp))
    end do
    call check(x, 'spread over [-1000, 1000] rad')
    x = [([(k*PI/2 + i*1.0e-15_wp, i = -2, 2)], k = -40, 40)]
    call check(x, 'at and next to k pi/2, k = -40 .. 40')
    x = [0.0_wp, 1.0e-300_wp, -1.0e-20_wp, 1.0e-8_wp, -3.0e-5_wp, 0.1_wp, PI/4, -PI/4, &
         3*PI/4, PI, -PI, 2*PI]
    call check(x, 'small angles and multiples of pi/4')
    x = [1.0e6_wp, -3.0e7_wp, 1.0_wp]
    call check(x, 'beyond the reduction range (intrinsics)')
    call suite%finish()

contains

    subroutine check(x, what)
        real(wp), intent(in) :: x(:)
        character(len=*), intent(in) :: what
        real(wp), allocatable :: cs(:, :)
        real(wp) :: err_c, err_s
        allocate (cs(2, size(x)))
        call cos_sin(x, cs)
        err_c = maxval(abs(cs(1, :) - cos(x)))
        err_s = maxval(abs(cs(2, :) - sin(x)))
        write (*, '(a, 2es10.2)') '      '//what//': max |error| cos, sin', err_c, err_s
        call suite%check_le(err_c, BOUND, 'cos, '//what)
        call suite%check_le(err_s, BOUND, 'sin, '//what)
    end subroutine check
end program test_trig
