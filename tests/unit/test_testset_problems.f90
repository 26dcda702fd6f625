!> The test-set problems (solvers/testset): sizes, intervals, initial values, f at y0, the
!! conservation laws built into the equations, and every analytic Jacobian against
!! central differences of f at y0, at yref and at an intermediate state.
!!
!! All six right-hand sides are polynomials of degree <= 2 in each single variable, so a
!! central difference is exact up to rounding whatever the step; the step is therefore
!! large (1e-3 of the component's scale) and the tolerance of entry (i, j) is the rounding
!! bound 100 eps M_ij / h_j, with M_ij the size of the terms of f_i while y_j moves, plus
!! 1e-7 relative.
!! The test also proves that it can fail: every nonzero entry of each analytic Jacobian,
!! changed by 1 %, must be rejected by the same comparison.
program test_testset_problems
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t, ERR_INPUT
    use ropedyn_problem, only: STATUS_OK
    use ropedyn_testset, only: testset_problem_t, new_testset_problem, testset_names
    use ropedyn_assert, only: test_suite_t
    implicit none

    type(test_suite_t) :: suite
    class(testset_problem_t), allocatable :: p
    type(error_t), allocatable :: err
    integer :: k

    suite%name = 'test_testset_problems'

    call check_definitions()
    call check_rhs_at_y0()
    call check_factory()
    do k = 1, size(testset_names)
        call new_testset_problem(testset_names(k), p, err)
        call suite%check_true(.not. allocated(err), trim(testset_names(k))//': created')
        if (allocated(err)) cycle
        call check_jacobian(p, p%y0, 'y0')
        call check_jacobian(p, p%yref, 'yref')
        call check_jacobian(p, intermediate(p), 'intermediate state')
    end do
    call suite%finish()

contains

    !> Sizes, intervals, y0 (transcribed again here from docs/theory/testset.md and pollu.f),
    !! reference sizes, bandwidths and tolerance rules.
    subroutine check_definitions()
        real(wp), allocatable :: y0(:)
        real(wp) :: t_end
        integer :: n, ml, mu
        character(len=:), allocatable :: rule
        do k = 1, size(testset_names)
            call new_testset_problem(testset_names(k), p, err)
            if (allocated(err)) then
                call suite%check_true(.false., trim(testset_names(k))//': '//err%message)
                cycle
            end if
            select case (trim(testset_names(k)))
            case ('HIRES')
                y0 = [1.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0057_wp]
                t_end = 321.8122_wp
                rule = 'atol = rtol'
            case ('VDPOL')
                y0 = [2.0_wp, 0.0_wp]
                t_end = 2.0_wp
                rule = 'atol = rtol'
            case ('OREGO')
                y0 = [1.0_wp, 2.0_wp, 3.0_wp]
                t_end = 360.0_wp
                rule = 'atol = rtol'
            case ('ROBER')
                y0 = [1.0_wp, 0.0_wp, 0.0_wp]
                t_end = 1.0e11_wp
                rule = 'atol = 1.0E-06 rtol'
            case ('E5')
                y0 = [1.76e-3_wp, 0.0_wp, 0.0_wp, 0.0_wp]
                t_end = 1.0e13_wp
                rule = 'atol = 1.7E-24'
            case ('POLLU')
                allocate (y0(20), source=0.0_wp)
                y0([2, 4, 7, 8, 9, 17]) = [0.2_wp, 0.04_wp, 0.1_wp, 0.3_wp, 0.01_wp, 0.007_wp]
                t_end = 60.0_wp
                rule = 'atol = rtol'
            case default
                call suite%check_true(.false., 'no expectations for '//testset_names(k))
                cycle
            end select
            n = size(y0)
            call suite%check_true(p%name == trim(testset_names(k)), p%name//': name')
            call suite%check_true(p%size() == n .and. size(p%y0) == n .and. &
                                  size(p%yref) == n, p%name//': size')
            call suite%check_true(all(p%y0 == y0), p%name//': y0')
            call suite%check_true(p%t0 == 0.0_wp .and. p%t_end == t_end, p%name//': interval')
            call p%bandwidths(ml, mu)
            call suite%check_true(ml == n - 1 .and. mu == n - 1, p%name//': dense band')
            call suite%check_true(p%has_jacobian(), p%name//': analytic Jacobian')
            call suite%check_true(p%quad_size() == 0, p%name//': no quadratures')
            call suite%check_true(p%atol_rule() == rule, p%name//': '//p%atol_rule())
            call suite%check_true(p%use_mescd .eqv. (p%name == 'E5'), p%name//': measure')
            deallocate (y0)
        end do
        call new_testset_problem('ROBER', p, err)
        call suite%check_true(all(abs(p%recommended_atol(1.0e-8_wp) - 1.0e-14_wp) <= &
                                  1.0e-12_wp*1.0e-14_wp), 'ROBER: atol(rtol 1e-8) = 1e-14')
        call new_testset_problem('E5', p, err)
        call suite%check_true(all(p%recommended_atol(1.0e-3_wp) == 1.7e-24_wp), &
                              'E5: atol fixed at 1.7e-24')
    end subroutine check_definitions

    !> f(y0) computed by hand, and the conservation laws of the equations at y0, yref and
    !! the intermediate state.
    subroutine check_rhs_at_y0()
        real(wp), allocatable :: f(:), y(:), expected(:)
        real(wp) :: r2, r16, r17
        integer :: status, i
        do k = 1, size(testset_names)
            call new_testset_problem(testset_names(k), p, err)
            allocate (f(p%size()))
            call p%rhs(0.0_wp, p%y0, f, status)
            call suite%check_true(status == STATUS_OK, p%name//': rhs status')
            select case (p%name)
            case ('HIRES')
                expected = [-1.71_wp + 0.0007_wp, 1.71_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, &
                            0.0_wp, 0.0_wp]
            case ('VDPOL')
                expected = [0.0_wp, -2.0e6_wp]
            case ('OREGO')
                expected = [77.27_wp*(1.0_wp - 8.375e-6_wp), -1.0_wp/77.27_wp, -0.322_wp]
            case ('ROBER')
                expected = [-0.04_wp, 0.04_wp, 0.0_wp]
            case ('E5')
                expected = [-1.0_wp, 1.0_wp, 1.0_wp, 0.0_wp]*7.89e-10_wp*1.76e-3_wp
            case ('POLLU')
                r2 = 26.6_wp*0.2_wp*0.04_wp
                r16 = 0.35e-3_wp*0.04_wp
                r17 = 0.175e-1_wp*0.04_wp
                allocate (expected(20), source=0.0_wp)
                expected(1) = r2
                expected(2) = -r2
                expected(3) = r17
                expected(4) = -r2 - r16 - r17
                expected(5) = 2.0_wp*0.86e-3_wp*0.1_wp + 0.13e-3_wp*0.01_wp
                expected(7) = -(0.86e-3_wp + 0.82e-3_wp)*0.1_wp
                expected(8) = (0.86e-3_wp + 0.82e-3_wp)*0.1_wp + 0.13e-3_wp*0.01_wp
                expected(9) = -0.13e-3_wp*0.01_wp
                expected(10) = 0.13e-3_wp*0.01_wp
                expected(16) = r16
            end select
            do i = 1, size(f)
                call suite%check_close(f(i), expected(i), 1.0e-14_wp, 1.0e-300_wp, &
                                       p%name//': f(y0)')
            end do
            y = intermediate(p)
            call p%rhs(0.0_wp, y, f, status)
            select case (p%name)
            case ('HIRES')
                call suite%check_close(f(7) + f(8), 0.0_wp, 0.0_wp, 1.0e-15_wp*abs(f(7)), &
                                       'HIRES: y7 + y8 conserved')
            case ('ROBER')
                call suite%check_close(sum(f), 0.0_wp, 0.0_wp, 1.0e-15_wp*maxval(abs(f)), &
                                       'ROBER: y1 + y2 + y3 conserved')
            case ('E5')
                call suite%check_close(f(2) - f(3) - f(4), 0.0_wp, 0.0_wp, &
                                       1.0e-15_wp*maxval(abs(f)), 'E5: y3 = y2 - y4 rate')
            end select
            deallocate (f, expected)
        end do
    end subroutine check_rhs_at_y0

    subroutine check_factory()
        call new_testset_problem('hires', p, err)
        call suite%check_true(.not. allocated(err), 'factory ignores case')
        if (.not. allocated(err)) call suite%check_true(p%name == 'HIRES', 'hires is HIRES')
        call new_testset_problem('AMPLIFIER', p, err)
        call suite%check_true(allocated(err), 'unknown problem rejected')
        if (allocated(err)) then
            call suite%check_true(err%code == ERR_INPUT, 'unknown problem: input error')
            call suite%check_contains(err%message, 'AMPLIFIER', 'message names the value')
            call suite%check_contains(err%message, 'POLLU', 'message lists the problems')
        end if
    end subroutine check_factory

    !> An intermediate state: the midpoint of y0 and yref. Every component is nonzero
    !! there except E5's y4, on which no Jacobian entry depends.
    function intermediate(problem) result(y)
        class(testset_problem_t), intent(in) :: problem
        real(wp), allocatable :: y(:)
        y = 0.5_wp*(problem%y0 + problem%yref)
    end function intermediate

    !> The band Jacobian (CVODE's layout: offset ml + mu + 1) against central differences.
    subroutine check_jacobian(problem, y, state)
        class(testset_problem_t), intent(inout) :: problem
        real(wp), intent(in) :: y(:)
        character(len=*), intent(in) :: state
        real(wp), allocatable :: jb(:, :), ja(:, :), jd(:, :), tol(:, :), jw(:, :)
        real(wp), allocatable :: yp(:), ym(:), fp(:), fm(:), f0(:), h(:), terms(:)
        real(wp) :: ymax, worst
        integer :: n, ml, mu, offset, i, j, status, missed, nonzero
        character(len=160) :: label

        n = problem%size()
        call problem%bandwidths(ml, mu)
        offset = ml + mu + 1
        allocate (jb(2*ml + mu + 1, n), source=0.0_wp)
        call problem%jacobian(0.0_wp, y, jb, offset, status)
        call suite%check_true(status == STATUS_OK, problem%name//': jacobian status')
        allocate (ja(n, n), jd(n, n), tol(n, n), h(n), f0(n), fp(n), fm(n), terms(n))
        do j = 1, n
            do i = 1, n
                ja(i, j) = jb(offset + i - j, j)
            end do
        end do
        ! nothing outside the band rows written (dense band: rows 1 .. ml are CVODE's
        ! fill-in space and must stay zero)
        call suite%check_true(all(jb(1:ml, :) == 0.0_wp), problem%name// &
                              ': no write above the band ('//state//')')

        ! M_ij, the size of the terms of f_i while y_j moves: |J_ik y_k| covers every
        ! product term at y, |J_ij| h_j the change, |f| the values themselves
        call problem%rhs(0.0_wp, y, f0, status)
        ymax = maxval(abs(y))
        h = 1.0e-3_wp*max(abs(y), 1.0e-3_wp*ymax)
        do i = 1, n
            terms(i) = abs(f0(i)) + sum(abs(ja(i, :)*y))
        end do
        do j = 1, n
            yp = y
            ym = y
            yp(j) = y(j) + h(j)
            ym(j) = y(j) - h(j)
            call problem%rhs(0.0_wp, yp, fp, status)
            call problem%rhs(0.0_wp, ym, fm, status)
            jd(:, j) = (fp - fm)/(2.0_wp*h(j))
            tol(:, j) = 1.0e-7_wp*abs(ja(:, j)) + tiny(1.0_wp) + 100.0_wp*epsilon(1.0_wp)* &
                        (terms + abs(ja(:, j))*h(j) + max(abs(fp), abs(fm)))/h(j)
        end do

        worst = maxval(abs(ja - jd)/tol)
        write (label, '(a, a, a, es9.2, a)') ': Jacobian = central differences at ', &
            state, ' (worst error/tolerance', worst, ')'
        call suite%check_true(worst <= 1.0_wp, problem%name//trim(label))

        ! the comparison must catch a 1 % error in every nonzero entry
        missed = 0
        nonzero = 0
        do j = 1, n
            do i = 1, n
                if (ja(i, j) == 0.0_wp) cycle
                nonzero = nonzero + 1
                jw = ja
                jw(i, j) = 1.01_wp*ja(i, j)
                if (maxval(abs(jw - jd)/tol) <= 1.0_wp) missed = missed + 1
            end do
        end do
        write (label, '(a, a, a, i0, a, i0, a)') ': a 1 % error is detected at ', state, &
            ' in every nonzero entry (missed ', missed, ' of ', nonzero, ')'
        call suite%check_true(missed == 0 .and. nonzero > 0, problem%name//trim(label))
    end subroutine check_jacobian
end program test_testset_problems
