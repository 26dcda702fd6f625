!> The embedded pairs behind `method = 'erk'` (solvers/erk/ropedyn_erk_tables.f90) against the
!! Runge-Kutta order conditions (Butcher's trees up to order 5): the propagated solution b
!! satisfies every condition up to the pair's order and misses one of the next, the
!! embedded solution b - e every condition up to order - 1 and misses one of order `order`
!! (else the estimate would vanish to that order); the tables are explicit, FSAL (last row
!! of a = b, last node 1) with c_i = sum_j a_ij; the order-4 pair's estimate uses the stages
!! inside the step (the classical RK4's estimate, h (k4 - k5)/6, looked only at c = 1 and
!! missed the ground contact: see the table's comment); and the stability limit on the
!! imaginary axis (orders 3 and 4) is where |R(i y)| first exceeds 1. A wrong coefficient
!! breaks one of these conditions by far more than the bound (1e-14).
program test_erk_tables
    use ropedyn_kinds, only: wp
    use ropedyn_erk_tables, only: erk_table_t, erk_table
    use ropedyn_assert, only: test_suite_t
    implicit none

    real(wp), parameter :: TOL = 1.0e-14_wp
    type(test_suite_t) :: suite
    type(erk_table_t) :: tab
    integer :: order, s, i
    character(len=40) :: label
    real(wp), allocatable :: bhat(:)

    suite%name = 'erk_tables'
    do order = 3, 5
        tab = erk_table(order)
        s = tab%stages
        write (label, '(a, i0)') 'pair of order ', order
        call suite%check_true(s >= order + 1, trim(label)//': stages')
        call suite%check_true(tab%order == order, trim(label)//': order field')
        ! explicit, FSAL, consistent nodes
        do i = 1, s
            call suite%check_le(maxval(abs(tab%a(i, i:))), 0.0_wp, trim(label)//': explicit')
            call suite%check_le(abs(sum(tab%a(i, 1:i - 1)) - tab%c(i)), TOL, &
                                trim(label)//': c = row sums of a')
        end do
        call suite%check_le(maxval(abs(tab%a(s, 1:s) - tab%b(1:s))), 0.0_wp, &
                            trim(label)//': FSAL, last row of a = b')
        call suite%check_le(abs(tab%c(s) - 1.0_wp), 0.0_wp, trim(label)//': last node 1')
        ! the propagated solution: order `order`, not order + 1 (up to 5 checked)
        call suite%check_le(worst(tab, tab%b(1:s), order), TOL, trim(label)//': b to its order')
        if (order < 5) call suite%check_true(worst(tab, tab%b(1:s), order + 1) > 1.0e-6_wp, &
                                             trim(label)//': b not of the next order')
        ! the embedded solution: order - 1, not order
        bhat = tab%b(1:s) - tab%e(1:s)
        call suite%check_le(worst(tab, bhat, order - 1), TOL, trim(label)//': bhat to order - 1')
        call suite%check_true(worst(tab, bhat, order) > 1.0e-4_wp, &
                              trim(label)//': bhat not of the pair''s order')
        call suite%check_le(abs(sum(tab%e(1:s))), TOL, trim(label)//': sum of e = 0')
        ! the stability limit on the imaginary axis (orders 3, 4; order 5's is Hairer's
        ! 3.25 of DOPRI5's stiffness test, with damping: its region barely reaches the axis)
        if (order < 5) then
            call suite%check_le(tab%amplification(cmplx(0.0_wp, 0.999_wp*tab%stability_limit, &
                                                        wp)), 1.0_wp, trim(label)//': stable below')
            call suite%check_true(tab%amplification(cmplx(0.0_wp, 1.01_wp* &
                                                          tab%stability_limit, wp)) > 1.0_wp, &
                                  trim(label)//': unstable above')
        end if
    end do
    ! the order-4 pair's estimate weighs the stages inside the step, not only those at c = 1
    tab = erk_table(4)
    call suite%check_true(any(abs(tab%e(1:tab%stages)) > 0.0_wp .and. &
                              tab%c(1:tab%stages) > 0.0_wp .and. tab%c(1:tab%stages) < 1.0_wp), &
                          'order 4: the estimate uses the stages inside the step')
    ! the spectral estimate's stage combination of the pairs of order 3 and 4 (their last
    ! two stages are not both at c = 1): sum alpha_i Y_i on y' = lambda y has no term
    ! below z^3 (slow modes would pull the estimate of the fastest one down), is not zero,
    ! and has no f_t term (sum alpha_i c_i = 0); beta = A^T alpha
    do order = 3, 4
        tab = erk_table(order)
        write (label, '(a, i0)') 'order ', order
        s = tab%stages
        call suite%check_le(abs(combination(tab, (1.0e-2_wp, 0.0_wp))), 1.0e-6_wp, &
                            trim(label)//': spectral estimate, stage combination O(z^3)')
        call suite%check_true(abs(combination(tab, (1.0_wp, 0.0_wp))) > 0.01_wp, &
                              trim(label)//': spectral estimate, stage combination not 0')
        call suite%check_le(abs(sum(tab%rho_alpha(1:s)*tab%c(1:s))), TOL, &
                            trim(label)//': spectral estimate, sum alpha c = 0')
        call suite%check_le(maxval(abs(tab%rho_beta(1:s) - &
                                       matmul(transpose(tab%a(1:s, 1:s)), &
                                              tab%rho_alpha(1:s)))), &
                            TOL, trim(label)//': spectral estimate, beta = A^T alpha')
    end do
    call suite%finish()

contains

    !> sum alpha_i Y_i(z) for y' = lambda y, y0 = 1, z = h lambda.
    complex(wp) function combination(tab, z) result(d)
        type(erk_table_t), intent(in) :: tab
        complex(wp), intent(in) :: z
        complex(wp) :: y(tab%stages)
        integer :: i, j
        do i = 1, tab%stages
            y(i) = 1.0_wp
            do j = 1, i - 1
                y(i) = y(i) + z*tab%a(i, j)*y(j)
            end do
        end do
        d = sum(tab%rho_alpha(1:tab%stages)*y)
    end function combination

    !> The largest |Phi(t) - 1/gamma(t)| over the trees t of order 1 .. p (p <= 5) for the
    !! weights w on the table's a and c.
    real(wp) function worst(tab, w, p) result(res)
        type(erk_table_t), intent(in) :: tab
        real(wp), intent(in) :: w(:)
        integer, intent(in) :: p
        real(wp), allocatable :: a(:, :), c(:), ac(:), ac2(:), aac(:), ac3(:), acac(:), &
                                 aac2(:), aaac(:)
        integer :: n
        n = size(w)
        a = tab%a(1:n, 1:n)
        c = tab%c(1:n)
        ac = matmul(a, c)
        ac2 = matmul(a, c**2)
        aac = matmul(a, ac)
        ac3 = matmul(a, c**3)
        acac = matmul(a, c*ac)
        aac2 = matmul(a, ac2)
        aaac = matmul(a, aac)
        res = abs(sum(w) - 1.0_wp)
        if (p >= 2) res = max(res, abs(sum(w*c) - 1.0_wp/2))
        if (p >= 3) res = max(res, abs(sum(w*c**2) - 1.0_wp/3), abs(sum(w*ac) - 1.0_wp/6))
        if (p >= 4) res = max(res, abs(sum(w*c**3) - 1.0_wp/4), abs(sum(w*c*ac) - 1.0_wp/8), &
                              abs(sum(w*ac2) - 1.0_wp/12), abs(sum(w*aac) - 1.0_wp/24))
        if (p >= 5) res = max(res, abs(sum(w*c**4) - 1.0_wp/5), &
                              abs(sum(w*c**2*ac) - 1.0_wp/10), abs(sum(w*c*ac2) - 1.0_wp/15), &
                              abs(sum(w*c*aac) - 1.0_wp/30), abs(sum(w*ac**2) - 1.0_wp/20), &
                              abs(sum(w*ac3) - 1.0_wp/20), abs(sum(w*acac) - 1.0_wp/40), &
                              abs(sum(w*aac2) - 1.0_wp/60), abs(sum(w*aaac) - 1.0_wp/120))
    end function worst
end program test_erk_tables
