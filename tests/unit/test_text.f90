!> Text of numbers (src/core/ropedyn_text.f90): real_text writes the shortest decimal that
!! reads back to the value; significant_text rounds a measured value to its significant
!! digits first, so that a table shows 0.091687 and not the noise 0.09168699999999999.
program test_text
    use ropedyn_kinds, only: wp
    use ropedyn_text, only: real_text, significant_text
    use ropedyn_assert, only: test_suite_t
    implicit none

    type(test_suite_t) :: suite
    real(wp) :: noisy, x

    suite%name = 'text'
    noisy = 0.091687_wp + 3.0_wp*epsilon(1.0_wp)*0.091687_wp
    call suite%check_true(real_text(noisy) /= '0.091687', 'real_text keeps every digit: '// &
                          real_text(noisy))
    call suite%check_true(significant_text(noisy, 6) == '0.091687', &
                          'six significant digits: '//significant_text(noisy, 6))
    call suite%check_true(significant_text(123456.789_wp, 4) == '123500.0', &
                          'four of a large number: '//significant_text(123456.789_wp, 4))
    call suite%check_true(significant_text(-2.71828e-9_wp, 3, compact=.true.) == '-2.72e-9', &
                          'compact, small and negative: '// &
                          significant_text(-2.71828e-9_wp, 3, compact=.true.))
    x = 0.0_wp
    call suite%check_true(significant_text(x, 6) == '0.0', 'zero')
    x = huge(1.0_wp)
    call suite%check_true(significant_text(x, 6) == '1.79769e308', 'huge, rounded down: '// &
                          significant_text(x, 6))
    x = ieee_nan()
    call suite%check_true(significant_text(x, 6) == 'NaN', 'NaN')
    call suite%finish()
contains
    real(wp) function ieee_nan() result(y)
        use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
        y = ieee_value(1.0_wp, ieee_quiet_nan)
    end function ieee_nan
end program test_text
