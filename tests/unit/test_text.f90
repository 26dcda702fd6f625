!> Text of numbers (src/core/ropedyn_text.f90): real_text writes the shortest decimal that
!! reads back to the value; significant_text rounds a measured value to its significant
!! digits first, so that a table shows 0.091687 and not the noise 0.09168699999999999;
!! decimal_product multiplies the decimals as written (0.01*1e-4 = 1e-6, not the binary
!! 1.0000000000000002e-6).
program test_text
    use ropedyn_kinds, only: wp
    use ropedyn_text, only: real_text, significant_text, decimal_product, replaced, es_text
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
    ! es_text: ESw.d, with a three-digit exponent where two do not hold it
    call suite%check_true(es_text(2.48364_wp, 12, 5) == ' 2.48364E+00', 'es_text: '// &
                          es_text(2.48364_wp, 12, 5))
    call suite%check_true(es_text(2.2346e-153_wp, 12, 5) == ' 2.23460E-153', &
                          'es_text, exponent -153: '//es_text(2.2346e-153_wp, 12, 5))
    call suite%check_true(es_text(-9.9999e99_wp, 10, 3) == '-1.000E+100', &
                          'es_text, rounded to exponent 100: '//es_text(-9.9999e99_wp, 10, 3))
    x = 0.0_wp
    call suite%check_true(significant_text(x, 6) == '0.0', 'zero')
    x = huge(1.0_wp)
    call suite%check_true(significant_text(x, 6) == '1.79769e308', 'huge, rounded down: '// &
                          significant_text(x, 6))
    x = ieee_nan()
    call suite%check_true(significant_text(x, 6) == 'NaN', 'NaN')
    call check_product(0.01_wp, 1.0e-4_wp, '1e-6')
    call check_product(0.01_wp, 1.0e-5_wp, '1e-7')
    call check_product(0.01_wp, 1.0e-9_wp, '1e-11')
    call check_product(3.0_wp, 0.1_wp, '0.3')
    call check_product(-0.1_wp, 0.2_wp, '-0.02')
    call check_product(1.5_wp, 2.5e-7_wp, '3.75e-7')
    ! 17 digits times 17: the exact 34-digit product, rounded once
    call check_product(0.1_wp + epsilon(1.0_wp)/8.0_wp, 1.0_wp/3.0_wp, '0.03333333333333334')
    call check_product(1.0_wp/3.0_wp, 3.0_wp, '0.9999999999999999')
    call check_product(0.0_wp, 5.0_wp, '0.0')
    call check_product(huge(1.0_wp), 10.0_wp, '+Infinity')
    call check_product(1.0e-300_wp, 1.0e-300_wp, '0.0')
    ! every occurrence, left to right, none overlapping the replacement (a part file's
    ! name in a message renamed to its file's)
    call suite%check_true(replaced('a.h5.part: x; a.h5.part', 'a.h5.part', 'a.h5') == &
                          'a.h5: x; a.h5', 'replaced: every occurrence')
    call suite%check_true(replaced('aaa', 'a', 'aa') == 'aaaaaa', 'replaced: not again')
    call suite%check_true(replaced('none', 'x', 'y') == 'none', 'replaced: none')
    call suite%finish()
contains
    !> decimal_product(a, b) reads as `expected` (real_text: shortest, every digit).
    subroutine check_product(a, b, expected)
        real(wp), intent(in) :: a, b
        character(len=*), intent(in) :: expected
        character(len=:), allocatable :: got
        got = real_text(decimal_product(a, b), compact=.true.)
        call suite%check_true(got == expected, 'decimal_product('//real_text(a)//', '// &
                              real_text(b)//') = '//got//' (expected '//expected// &
                              ', binary '//real_text(a*b, compact=.true.)//')')
    end subroutine check_product
    real(wp) function ieee_nan() result(y)
        use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
        y = ieee_value(1.0_wp, ieee_quiet_nan)
    end function ieee_nan
end program test_text
