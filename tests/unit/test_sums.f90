!> The integrators' sums of squares (src/core/ropedyn_sums.f90):
!! - exact on integers (no rounding): every component counted once, for every length from 0
!!   to 40 (the eight partial sums, and the tail beyond a multiple of eight);
!! - the order the module header fixes: components i = 8 m + j in partial sum j, the eight
!!   added pairwise; written out here for a vector where another order rounds differently
!!   (squares 1 and nine times 2^-54: a plain sum gives 1, the module's order 1 + 2^-52);
!! - against the plain sum on 600 random values (within rounding);
!! - the sums of products (sum_products) the same way: exact on integers for every length
!!   0 .. 40, equal to sum_squares(x) for y = x;
!! - the sums of scaled squares (sum_scaled_squares(x, s)): sum_squares(x s) bit for bit on
!!   random values at every length 0 .. 40 (the weighted norms of MEBDF rely on it);
!! - all_finite: true for finite vectors (huge and tiny values, negative zero, length 0, a
!!   strided section), false for a NaN, +Inf or -Inf at every position of every length
!!   1 .. 20 (the four running sums and the tail) and in a strided section.
program test_sums
    use ropedyn_kinds, only: wp
    use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, ieee_positive_inf, &
                                             ieee_negative_inf
    use ropedyn_sums, only: sum_squares, sum_scaled_squares, sum_products, all_finite
    use ropedyn_assert, only: test_suite_t
    implicit none

    type(test_suite_t) :: suite
    real(wp), allocatable :: x(:), s(:)
    real(wp) :: a(8), expected, eps, bad(3), grid(4, 5)
    integer :: n, i, k, j
    logical :: caught
    character(len=8) :: label

    suite%name = 'sums'
    do n = 0, 40
        x = [(real(mod(7*i, 11) - 5, wp), i = 1, n)]
        write (label, '(i0)') n
        call suite%check_true(sum_squares(x) == sum(x**2), 'integers, length '//trim(label))
    end do

    ! squares 1 and nine times 2^-54 (exact: x = 2^-27)
    eps = 2.0_wp**(-27)
    x = [1.0_wp, eps, eps, eps, eps, eps, eps, eps, eps, eps]
    a = 0.0_wp
    do i = 1, size(x)
        a(mod(i - 1, 8) + 1) = a(mod(i - 1, 8) + 1) + x(i)**2
    end do
    expected = ((a(1) + a(2)) + (a(3) + a(4))) + ((a(5) + a(6)) + (a(7) + a(8)))
    call suite%check_true(sum_squares(x) == expected, 'the fixed order of the partial sums')
    call suite%check_true(sum_squares(x) /= sum(x**2), '... which is not the plain order here')

    deallocate (x)
    allocate (x(600))
    call random_number(x)
    x = 2.0_wp*x - 1.0_wp
    call suite%check_close(sum_squares(x), sum(x**2), 1.0e-13_wp, 0.0_wp, &
                           '600 random values against the plain sum')
    call suite%check_true(sum_products(x, x) == sum_squares(x), &
                          'sum_products(x, x) is sum_squares(x), bit for bit')
    do n = 0, 40
        x = [(real(mod(7*i, 11) - 5, wp), i = 1, n)]
        write (label, '(i0)') n
        call suite%check_true(sum_products(x, x + 1.0_wp) == sum(x*(x + 1.0_wp)), &
                              'products of integers, length '//trim(label))
    end do

    caught = .true.
    do n = 0, 40
        allocate (s(n))
        call random_number(s)
        x = [(real(mod(7*i, 11) - 5, wp)/3.0_wp, i = 1, n)]
        s = 1.0_wp/(1.0e-3_wp + s)
        if (sum_scaled_squares(x, s) /= sum_squares(x*s)) caught = .false.
        deallocate (s)
    end do
    call suite%check_true(caught, 'sum_scaled_squares(x, s) is sum_squares(x s), bit for '// &
                          'bit, lengths 0 .. 40')

    ! all_finite
    bad = [ieee_value(1.0_wp, ieee_quiet_nan), ieee_value(1.0_wp, ieee_positive_inf), &
           ieee_value(1.0_wp, ieee_negative_inf)]
    call suite%check_true(all_finite(x(1:0)), 'all_finite: an empty vector')
    call suite%check_true(all_finite([huge(1.0_wp), -huge(1.0_wp), tiny(1.0_wp), -0.0_wp, &
                                      1.0_wp, 2.0_wp, 3.0_wp, 4.0_wp, 5.0_wp]), &
                          'all_finite: huge, tiny and negative zero are finite')
    caught = .true.
    do n = 1, 20
        x = [(real(i, wp), i = 1, n)]
        if (.not. all_finite(x)) caught = .false.
        do k = 1, n
            do j = 1, 3
                x(k) = bad(j)
                if (all_finite(x)) caught = .false.
                x(k) = real(k, wp)
            end do
        end do
    end do
    call suite%check_true(caught, 'all_finite: a NaN, +Inf or -Inf anywhere in lengths '// &
                          '1 .. 20 is caught, and only then')
    grid = 1.0_wp
    grid(2, 4) = bad(2)
    call suite%check_true(all_finite(grid(1, :)) .and. .not. all_finite(grid(2, :)), &
                          'all_finite: strided sections')
    call suite%finish()
end program test_sums
