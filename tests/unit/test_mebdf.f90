!> Tests of the MEBDF integrator: coefficients against the order conditions and the exact
!! fractions of docs/theory/mebdf.md; observed order at fixed step and order; the mass-matrix
!! form; quadratures; per-component atol; difference Jacobians; re-entrancy; stability
!! on a lightly damped stiff oscillator; failure reports.
module test_mebdf_problems
    use ropedyn_kinds, only: wp
    use ropedyn_problem, only: problem_t, STATUS_OK, STATUS_RECOVERABLE
    implicit none
    private
    public :: linear_t, oscillator_t, implicit_t

    !> y' = A y with A = [[-lambda, -omega], [omega, -lambda]] (a decaying rotation) and a
    !! third stiff component y3' = -mu (y3 - cos t) - sin t (solution y3 = cos t + e^{-mu t}..).
    !! Quadrature q' = y1^2 + y2^2.
    type, extends(problem_t) :: linear_t
        real(wp) :: lambda = 0.5_wp, omega = 3.0_wp, mu = 1.0e3_wp
        logical :: analytic = .true.
        logical :: with_quad = .false.
        real(wp) :: fail_after = huge(1.0_wp)  !< rhs reports a recoverable error after this t
    contains
        procedure :: size => lin_size
        procedure :: bandwidths => lin_bandwidths
        procedure :: rhs => lin_rhs
        procedure :: has_jacobian => lin_has_jacobian
        procedure :: jacobian => lin_jacobian
        procedure :: quad_size => lin_quad_size
        procedure :: quad_rhs => lin_quad_rhs
        procedure :: exact => lin_exact
    end type linear_t

    !> n independent damped oscillators x_i'' + 2 zeta_i omega_i x_i' + omega_i^2 x_i = 0
    !! (state x1, v1, x2, v2, ...; band ml = mu = 1): a lightly damped stiff mode. With
    !! slow_omega > 0 the first oscillator is an undamped slow mode of that frequency.
    type, extends(problem_t) :: oscillator_t
        integer :: n_osc = 1
        real(wp) :: omega = 1.0e3_wp, zeta = 1.0e-4_wp
        real(wp) :: slow_omega = 0.0_wp
    contains
        procedure :: size => osc_size
        procedure :: bandwidths => osc_bandwidths
        procedure :: rhs => osc_rhs
        procedure :: has_jacobian => osc_has_jacobian
        procedure :: jacobian => osc_jacobian
    end type oscillator_t

    !> The same motion as linear_t written as M(y) y' = F(y) with the state-dependent
    !! M = diag(1 + y1^2, 2 + sin y2, 1) (+ an off-diagonal 0.3 y3 in (1, 2)) and F = M g.
    type, extends(linear_t) :: implicit_t
    contains
        procedure :: has_mass_matrix => imp_has_mass
        procedure :: mass_matrix => imp_mass_matrix
        procedure :: implicit_rhs => imp_implicit_rhs
        procedure :: has_implicit_jacobian => imp_has_implicit_jacobian
        procedure :: bandwidths => imp_bandwidths
    end type implicit_t

contains

    pure integer function lin_size(self)
        class(linear_t), intent(in) :: self
        lin_size = 3
    end function lin_size

    pure subroutine lin_bandwidths(self, ml, mu)
        class(linear_t), intent(in) :: self
        integer, intent(out) :: ml, mu
        ml = 2
        mu = 2
    end subroutine lin_bandwidths

    subroutine lin_rhs(self, t, y, ydot, status)
        class(linear_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: ydot(:)
        integer, intent(out) :: status
        ydot(1) = -self%lambda*y(1) - self%omega*y(2)
        ydot(2) = self%omega*y(1) - self%lambda*y(2)
        ydot(3) = -self%mu*(y(3) - cos(t)) - sin(t)
        status = STATUS_OK
        if (t > self%fail_after) status = STATUS_RECOVERABLE
    end subroutine lin_rhs

    pure logical function lin_has_jacobian(self)
        class(linear_t), intent(in) :: self
        lin_has_jacobian = self%analytic
    end function lin_has_jacobian

    subroutine lin_jacobian(self, t, y, jb, offset, status)
        class(linear_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(inout) :: jb(:, :)
        integer, intent(in) :: offset
        integer, intent(out) :: status
        jb(offset, 1) = jb(offset, 1) - self%lambda
        jb(offset - 1, 2) = jb(offset - 1, 2) - self%omega     ! (1, 2)
        jb(offset + 1, 1) = jb(offset + 1, 1) + self%omega     ! (2, 1)
        jb(offset, 2) = jb(offset, 2) - self%lambda
        jb(offset, 3) = jb(offset, 3) - self%mu
        status = STATUS_OK
    end subroutine lin_jacobian

    pure integer function lin_quad_size(self)
        class(linear_t), intent(in) :: self
        lin_quad_size = merge(1, 0, self%with_quad)
    end function lin_quad_size

    subroutine lin_quad_rhs(self, t, y, yqdot, status)
        class(linear_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: yqdot(:)
        integer, intent(out) :: status
        yqdot(1) = y(1)**2 + y(2)**2
        status = STATUS_OK
    end subroutine lin_quad_rhs

    !> Exact solution from y(0) = (1, 0, 2), and the quadrature (1 - e^{-2 lambda t})/(2 lambda).
    pure function lin_exact(self, t) result(z)
        class(linear_t), intent(in) :: self
        real(wp), intent(in) :: t
        real(wp) :: z(4)
        z(1) = exp(-self%lambda*t)*cos(self%omega*t)
        z(2) = exp(-self%lambda*t)*sin(self%omega*t)
        z(3) = cos(t) + exp(-self%mu*t)
        z(4) = (1.0_wp - exp(-2.0_wp*self%lambda*t))/(2.0_wp*self%lambda)
    end function lin_exact

    pure integer function osc_size(self)
        class(oscillator_t), intent(in) :: self
        osc_size = 2*self%n_osc
    end function osc_size

    pure subroutine osc_bandwidths(self, ml, mu)
        class(oscillator_t), intent(in) :: self
        integer, intent(out) :: ml, mu
        ml = 1
        mu = 1
    end subroutine osc_bandwidths

    subroutine osc_rhs(self, t, y, ydot, status)
        class(oscillator_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: ydot(:)
        integer, intent(out) :: status
        integer :: i
        real(wp) :: w, z
        do i = 1, self%n_osc
            call mode(self, i, w, z)
            ydot(2*i - 1) = y(2*i)
            ydot(2*i) = -w**2*y(2*i - 1) - 2.0_wp*z*w*y(2*i)
        end do
        status = STATUS_OK
    end subroutine osc_rhs

    pure logical function osc_has_jacobian(self)
        class(oscillator_t), intent(in) :: self
        osc_has_jacobian = .true.
    end function osc_has_jacobian

    subroutine osc_jacobian(self, t, y, jb, offset, status)
        class(oscillator_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(inout) :: jb(:, :)
        integer, intent(in) :: offset
        integer, intent(out) :: status
        integer :: i
        real(wp) :: w, z
        do i = 1, self%n_osc
            call mode(self, i, w, z)
            jb(offset - 1, 2*i) = jb(offset - 1, 2*i) + 1.0_wp       ! (2i-1, 2i)
            jb(offset + 1, 2*i - 1) = jb(offset + 1, 2*i - 1) - w**2 ! (2i, 2i-1)
            jb(offset, 2*i) = jb(offset, 2*i) - 2.0_wp*z*w          ! (2i, 2i)
        end do
        status = STATUS_OK
    end subroutine osc_jacobian

    pure subroutine mode(self, i, w, z)
        class(oscillator_t), intent(in) :: self
        integer, intent(in) :: i
        real(wp), intent(out) :: w, z
        w = self%omega
        z = self%zeta
        if (i == 1 .and. self%slow_omega > 0.0_wp) then
            w = self%slow_omega
            z = 0.0_wp
        end if
    end subroutine mode

    pure logical function imp_has_mass(self)
        class(implicit_t), intent(in) :: self
        imp_has_mass = .true.
    end function imp_has_mass

    pure logical function imp_has_implicit_jacobian(self)
        class(implicit_t), intent(in) :: self
        imp_has_implicit_jacobian = .false.
    end function imp_has_implicit_jacobian

    pure subroutine imp_bandwidths(self, ml, mu)
        class(implicit_t), intent(in) :: self
        integer, intent(out) :: ml, mu
        ml = 2
        mu = 2
    end subroutine imp_bandwidths

    pure function mass_of(y) result(m)
        real(wp), intent(in) :: y(:)
        real(wp) :: m(3, 3)
        m = 0.0_wp
        m(1, 1) = 1.0_wp + y(1)**2
        m(2, 2) = 2.0_wp + sin(y(2))
        m(3, 3) = 1.0_wp
        m(1, 2) = 0.3_wp*y(3)
    end function mass_of

    subroutine imp_mass_matrix(self, t, y, mb, offset, status)
        class(implicit_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(inout) :: mb(:, :)
        integer, intent(in) :: offset
        integer, intent(out) :: status
        real(wp) :: m(3, 3)
        integer :: i, j
        m = mass_of(y)
        do j = 1, 3
            do i = 1, 3
                mb(offset + i - j, j) = mb(offset + i - j, j) + m(i, j)
            end do
        end do
        status = STATUS_OK
    end subroutine imp_mass_matrix

    subroutine imp_implicit_rhs(self, t, y, f, status)
        class(implicit_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: f(:)
        integer, intent(out) :: status
        real(wp) :: g(3)
        call self%linear_t%rhs(t, y, g, status)
        f = matmul(mass_of(y), g)
    end subroutine imp_implicit_rhs
end module test_mebdf_problems

program test_mebdf
    use ropedyn_kinds, only: wp, i8
    use ropedyn_error, only: error_t
    use ropedyn_assert, only: test_suite_t
    use ropedyn_integrator, only: solver_options_t, solver_stats_t
    use ropedyn_mebdf, only: mebdf_t
    use ropedyn_mebdf_coefficients, only: mebdf_coefficients_t, mebdf_coefficients
    use test_mebdf_problems, only: linear_t, oscillator_t, implicit_t
    implicit none

    type(test_suite_t) :: suite

    suite%name = 'mebdf'
    call test_coefficients()
    call test_observed_order()
    call test_adaptive_accuracy()
    call test_quadrature_and_atol_vector()
    call test_mass_matrix_form()
    call test_difference_jacobian()
    call test_reentrant()
    call test_oscillator_stability()
    call test_hidden_mode()
    call test_failures()
    call suite%finish()

contains

    !> Exact fractions of docs/theory/mebdf.md against the coefficients solved in code, and the
    !! order conditions themselves (including that q = k+2 fails: the order is exactly k+1).
    subroutine test_coefficients()
        type(mebdf_coefficients_t) :: c
        real(wp) :: table(7, 5), res
        character(len=8) :: label
        integer :: k, q, j
        ! beta_k, ahat_0 .. ahat_{k-1}, bhat_k, bhat_{k+1}
        table = 0.0_wp
        table(1:4, 1) = [1.0_wp, -1.0_wp, 1.5_wp, -0.5_wp]
        table(1:5, 2) = [2.0_wp/3, 5.0_wp/23, -28.0_wp/23, 22.0_wp/23, -4.0_wp/23]
        table(1:6, 3) = [6.0_wp/11, -17.0_wp/197, 99.0_wp/197, -279.0_wp/197, 150.0_wp/197, &
                         -18.0_wp/197]
        table(1:7, 4) = [12.0_wp/25, 111.0_wp/2501, -728.0_wp/2501, 2124.0_wp/2501, &
                         -4008.0_wp/2501, 1644.0_wp/2501, -144.0_wp/2501]
        do k = 1, 4
            c = mebdf_coefficients(k)
            write (label, '(a, i0)') 'k = ', k
            call suite%check_close(c%beta, table(1, k), 1.0e-15_wp, 0.0_wp, &
                                   'coefficients '//trim(label)//': beta_k')
            call suite%check_close(c%beta, 1.0_wp/sum([(1.0_wp/j, j=1, k)]), 1.0e-15_wp, &
                                   0.0_wp, 'coefficients '//trim(label)//': beta_k = 1/gamma_k')
            call suite%check_le(maxval(abs(c%ahat(0:k - 1) - table(2:k + 1, k))), 1.0e-15_wp, &
                                'coefficients '//trim(label)//': ahat')
            call suite%check_close(c%bhat_k, table(k + 2, k), 1.0e-15_wp, 0.0_wp, &
                                   'coefficients '//trim(label)//': bhat_k')
            call suite%check_close(c%bhat_k1, table(k + 3, k), 1.0e-15_wp, 0.0_wp, &
                                   'coefficients '//trim(label)//': bhat_k+1')
        end do
        c = mebdf_coefficients(5)
        call suite%check_le(maxval(abs([c%beta, c%ahat(0:4), c%bhat_k, c%bhat_k1] - &
            [60.0_wp/137, -394.0_wp/14919, 975.0_wp/4973, -3200.0_wp/4973, 18700.0_wp/14919, &
             -8850.0_wp/4973, 2940.0_wp/4973, -200.0_wp/4973])), 1.0e-15_wp, &
            'coefficients k = 5: beta, ahat, bhat')
        do k = 1, 6
            c = mebdf_coefficients(k)
            write (label, '(a, i0)') 'k = ', k
            res = 0.0_wp
            do q = 0, k + 1
                res = max(res, abs(sum([(c%ahat(j)*real(j, wp)**q, j=0, k)]) - &
                    q*(c%bhat_k*real(k, wp)**max(q - 1, 0) + &
                       c%bhat_k1*real(k + 1, wp)**max(q - 1, 0))))
            end do
            call suite%check_le(res, 1.0e-9_wp, 'order conditions q <= k+1, '//trim(label))
            call suite%check_true(abs(c%mebdf_error_constant) > 1.0e-4_wp, &
                                  'order exactly k+1 (C_{k+2} /= 0), '//trim(label))
            res = 0.0_wp
            do q = 0, k
                res = max(res, abs(sum([(c%alpha(j)*real(j, wp)**q, j=0, k)]) - &
                    q*c%beta*real(k, wp)**max(q - 1, 0)))
            end do
            call suite%check_le(res, 1.0e-9_wp, 'BDF order conditions, '//trim(label))
        end do
    end subroutine test_coefficients

    !> Fixed step h and order k+1 on the non-stiff part of linear_t from exact back values:
    !! the global error at t = 1 must fall like h^(k+1).
    subroutine test_observed_order()
        type(linear_t), target :: p
        type(mebdf_t) :: integ
        type(solver_options_t) :: opt
        type(error_t), allocatable :: err
        real(wp) :: errs(2), h, y(3), yq(0), t, past(3, 0:7), slope, z(4)
        integer :: k, m, i, nsteps(2)
        character(len=64) :: label
        p%mu = 2.0_wp       ! keep every component smooth and non-stiff here
        p%omega = 2.0_wp
        opt%rtol = 1.0e-13_wp
        opt%atol = 1.0e-13_wp
        opt%max_order = 7
        do k = 1, 6
            nsteps = [10, 20]
            if (k >= 4) nsteps = [5, 10]
            do m = 1, 2
                h = 1.0_wp/nsteps(m)
                do i = 0, k + 1
                    z = p%exact(-i*h)
                    past(:, i) = z(1:3)
                end do
                call integ%init(p, 0.0_wp, past(:, 0), yq, opt, err)
                call integ%start_fixed(h, k, past(:, 0:k + 1), err)
                if (allocated(err)) then
                    call suite%check_true(.false., 'order: '//err%message)
                    return
                end if
                call integ%advance_to(1.0_wp, t, y, yq, err)
                if (allocated(err)) then
                    call suite%check_true(.false., 'order: '//err%message)
                    return
                end if
                z = p%exact(1.0_wp)
                errs(m) = maxval(abs(y - z(1:3)))
            end do
            slope = log(errs(1)/errs(2))/log(2.0_wp)
            write (label, '(a, i0, a, f5.2, a, 2es9.2, a)') 'observed order k = ', k, ': ', &
                slope, ' (errors', errs, ')'
            call suite%check_close(slope, real(k + 1, wp), 0.0_wp, 0.35_wp, trim(label))
        end do
    end subroutine test_observed_order

    !> Adaptive runs on the stiff linear problem: the error is proportional to rtol with the
    !! same factor at every tolerance (measured: 2.41, 2.29, 2.18 rtol at rtol 1e-4, 1e-7,
    !! 1e-10, Debug and Release alike: within 5 % of 2.3), checked to +-15 % of 2.3. The
    !! band is narrow on purpose: it guards the scale of the error estimate (halved, the
    !! error doubles to 4.4 rtol; normalized by (k+2) sum 1/j instead of (k+1) sum 1/j it
    !! grows to 2.83 rtol); the max_order limit is respected.
    subroutine test_adaptive_accuracy()
        type(linear_t), target :: p
        type(mebdf_t) :: integ
        type(solver_options_t) :: opt
        type(error_t), allocatable :: err
        type(solver_stats_t) :: st
        real(wp) :: y(3), yq(0), t, z(4), e(3), tout
        real(wp), parameter :: rtols(3) = [1.0e-4_wp, 1.0e-7_wp, 1.0e-10_wp]
        integer :: m, j
        character(len=80) :: label
        do m = 1, 3
            opt%rtol = rtols(m)
            opt%atol = rtols(m)
            opt%max_order = 0
            call integ%init(p, 0.0_wp, [1.0_wp, 0.0_wp, 2.0_wp], yq, opt, err)
            e(m) = 0.0_wp
            do j = 1, 20
                tout = 0.25_wp*j
                call integ%advance_to(tout, t, y, yq, err)
                if (allocated(err)) exit
                z = p%exact(tout)
                e(m) = max(e(m), maxval(abs(y - z(1:3))))
            end do
            call suite%check_true(.not. allocated(err), 'adaptive run completes')
            st = integ%stats()
            write (label, '(a, es8.1, a, es9.2, a, i0, a)') 'adaptive rtol ', rtols(m), &
                ': max error at 20 output times ', e(m), ' (', st%steps, ' steps)'
            call suite%check_close(e(m)/rtols(m), 2.3_wp, 0.15_wp, 0.0_wp, trim(label)// &
                                   ': error/rtol = 2.3 +- 15 % (the error estimate''s scale)')
            call suite%check_true(all(st%order_steps(5:) == 0) .and. st%order_steps(4) > 0, &
                                  'default max_order 4 is used and respected')
            call suite%check_true(t == tout, 'output time hit exactly')
        end do
        call suite%check_true(e(3) < e(2) .and. e(2) < e(1), 'error falls with rtol')
    end subroutine test_adaptive_accuracy

    subroutine test_quadrature_and_atol_vector()
        type(linear_t), target :: p
        type(mebdf_t) :: integ
        type(solver_options_t) :: opt
        type(error_t), allocatable :: err
        real(wp) :: y(3), yq(1), t, z(4)
        type(solver_stats_t) :: st1, st2
        p%with_quad = .true.
        opt%rtol = 1.0e-8_wp
        opt%atol = 1.0e-10_wp
        yq = 0.0_wp
        call integ%init(p, 0.0_wp, [1.0_wp, 0.0_wp, 2.0_wp], yq, opt, err)
        call integ%advance_to(3.0_wp, t, y, yq, err)
        z = p%exact(3.0_wp)
        call suite%check_close(yq(1), z(4), 1.0e-6_wp, 0.0_wp, &
                               'quadrature integral of |y|^2 (1 - e^-2 lambda t)/(2 lambda)')
        st1 = integ%stats()
        ! A loose atol on the stiff component only: fewer steps, same accuracy elsewhere.
        opt%atol_vector = [1.0e-10_wp, 1.0e-10_wp, 1.0e-2_wp]
        call integ%init(p, 0.0_wp, [1.0_wp, 0.0_wp, 2.0_wp], [0.0_wp], opt, err)
        call integ%advance_to(3.0_wp, t, y, yq, err)
        st2 = integ%stats()
        call suite%check_true(st2%steps < st1%steps, 'per-component atol is used (fewer steps)')
        call suite%check_close(y(1), z(1), 1.0e-6_wp, 1.0e-9_wp, &
                               'per-component atol: tight component still accurate')
    end subroutine test_quadrature_and_atol_vector

    !> M(y) y' = F(y) with a state-dependent M gives the explicit problem's solution.
    subroutine test_mass_matrix_form()
        type(implicit_t), target :: p
        type(mebdf_t) :: integ
        type(solver_options_t) :: opt
        type(error_t), allocatable :: err
        real(wp) :: y(3), yq(0), t, z(4)
        type(solver_stats_t) :: st
        opt%rtol = 1.0e-8_wp
        opt%atol = 1.0e-10_wp
        call integ%init(p, 0.0_wp, [1.0_wp, 0.0_wp, 2.0_wp], yq, opt, err)
        call integ%advance_to(2.0_wp, t, y, yq, err)
        call suite%check_true(.not. allocated(err), 'mass-matrix form runs')
        z = p%exact(2.0_wp)
        call suite%check_le(maxval(abs(y - z(1:3))), 1.0e-6_wp, &
                            'mass-matrix form: state-dependent M, error vs exact solution')
        st = integ%stats()
        call suite%check_true(st%jac_rhs_evals > 0, &
                              'mass-matrix form: dF/dy by differences')
    end subroutine test_mass_matrix_form

    !> Difference Jacobians give the same solution as the analytic one.
    subroutine test_difference_jacobian()
        type(oscillator_t), target :: p
        type(mebdf_t) :: a, b
        type(solver_options_t) :: opt
        type(error_t), allocatable :: err
        real(wp) :: ya(8), yb(8), yq(0), t
        type(solver_stats_t) :: st
        p%n_osc = 4
        p%omega = 50.0_wp
        p%zeta = 0.05_wp
        opt%rtol = 1.0e-8_wp
        opt%atol = 1.0e-10_wp
        call a%init(p, 0.0_wp, [1.0_wp, 0.0_wp, 0.5_wp, 1.0_wp, 0.0_wp, 2.0_wp, 1.0_wp, 1.0_wp], &
                    yq, opt, err)
        call a%advance_to(1.0_wp, t, ya, yq, err)
        opt%fd_jacobian = .true.
        call b%init(p, 0.0_wp, [1.0_wp, 0.0_wp, 0.5_wp, 1.0_wp, 0.0_wp, 2.0_wp, 1.0_wp, 1.0_wp], &
                    yq, opt, err)
        call b%advance_to(1.0_wp, t, yb, yq, err)
        call suite%check_le(maxval(abs(ya - yb)), 1.0e-6_wp*maxval(abs(ya)), &
                            'band difference Jacobian: same solution as analytic')
        ! band width 3 -> 3 column groups + 1 base evaluation per Jacobian
        st = b%stats()
        call suite%check_true(st%jac_rhs_evals == 4*st%jac_evals .and. st%jac_evals > 0, &
                              'band difference Jacobian: column grouping (4 f per Jacobian)')
    end subroutine test_difference_jacobian

    !> Two integrations advanced alternately give exactly what each gives alone.
    subroutine test_reentrant()
        type(linear_t), target :: p1
        type(oscillator_t), target :: p2
        type(mebdf_t) :: a, b
        type(solver_options_t) :: opt
        type(error_t), allocatable :: err
        real(wp) :: ya(3), yb(2), ya_alone(3), yb_alone(2), yq(0), t
        integer :: j
        p2%omega = 20.0_wp
        p2%zeta = 0.1_wp
        call a%init(p1, 0.0_wp, [1.0_wp, 0.0_wp, 2.0_wp], yq, opt, err)
        call b%init(p2, 0.0_wp, [1.0_wp, 0.0_wp], yq, opt, err)
        do j = 1, 10
            call a%advance_to(0.1_wp*j, t, ya, yq, err)
            call b%advance_to(0.1_wp*j, t, yb, yq, err)
        end do
        call a%init(p1, 0.0_wp, [1.0_wp, 0.0_wp, 2.0_wp], yq, opt, err)
        do j = 1, 10
            call a%advance_to(0.1_wp*j, t, ya_alone, yq, err)
        end do
        call b%init(p2, 0.0_wp, [1.0_wp, 0.0_wp], yq, opt, err)
        do j = 1, 10
            call b%advance_to(0.1_wp*j, t, yb_alone, yq, err)
        end do
        call suite%check_true(all(ya == ya_alone) .and. all(yb == yb_alone), &
                              're-entrant: interleaved integrations are bit-identical')
    end subroutine test_reentrant

    !> y'' + 2 zeta omega y' + omega^2 y = 0, omega = 1e3, zeta = 1e-4, 1000 periods with
    !! the default settings: the energy never grows and the run completes. Implicit
    !! damping is allowed, growth is not.
    subroutine test_oscillator_stability()
        type(oscillator_t), target :: p
        type(mebdf_t) :: integ
        type(solver_options_t) :: opt
        type(error_t), allocatable :: err
        real(wp) :: y(2), yq(0), t, e0, e, emax, period, exact
        type(solver_stats_t) :: st
        integer :: j, nout
        character(len=96) :: label
        period = 8.0_wp*atan(1.0_wp)/p%omega
        opt%rtol = 1.0e-6_wp
        opt%atol = 1.0e-8_wp
        call integ%init(p, 0.0_wp, [1.0e-3_wp, 0.0_wp], yq, opt, err)
        e0 = 0.5_wp*p%omega**2*1.0e-6_wp
        emax = 0.0_wp
        nout = 1000
        do j = 1, nout
            call integ%advance_to(j*period, t, y, yq, err)
            if (allocated(err)) exit
            e = 0.5_wp*y(2)**2 + 0.5_wp*p%omega**2*y(1)**2
            emax = max(emax, e)
        end do
        call suite%check_true(.not. allocated(err), 'oscillator: 1000 periods complete')
        exact = e0*exp(-2.0_wp*p%zeta*p%omega*nout*period)
        st = integ%stats()
        write (label, '(a, es10.3, a, es10.3, a, i0, a)') 'oscillator: no energy growth (max ', &
            emax/e0, ' E0; exact end ', exact/e0, ' E0; ', st%steps, ' steps)'
        call suite%check_le(emax, e0*(1.0_wp + 1.0e-3_wp), trim(label))
        call suite%check_close(e, exact, 0.05_wp, 0.0_wp, &
                               'oscillator: end energy within 5 % of exp(-2 zeta omega t)')
    end subroutine test_oscillator_stability

    !> A slow undamped mode (omega 50, amplitude 1) drives the step size; a lightly damped
    !! stiff mode (omega 1e3, zeta 1e-4) sits below the tolerance (amplitude 1e-9). Its
    !! energy must not grow (exact: decays to e^-2 in 10 s). MEBDF up to order 4 is stable
    !! on the imaginary axis; orders 5 and 6 amplify there (docs/theory/mebdf.md), which is why
    !! the default max_order is 4: this test shows both.
    subroutine test_hidden_mode()
        type(oscillator_t), target :: p
        type(mebdf_t) :: integ
        type(solver_options_t) :: opt
        type(error_t), allocatable :: err
        real(wp) :: y(4), yq(0), t, e0, e, emax(2)
        integer :: j, m
        character(len=96) :: label
        p%n_osc = 2
        p%slow_omega = 50.0_wp
        opt%rtol = 1.0e-5_wp
        opt%atol = 1.0e-7_wp
        e0 = 0.5_wp*p%omega**2*1.0e-18_wp
        do m = 1, 2
            opt%max_order = merge(0, 5, m == 1)
            call integ%init(p, 0.0_wp, [1.0_wp, 0.0_wp, 1.0e-9_wp, 0.0_wp], yq, opt, err)
            emax(m) = 0.0_wp
            do j = 1, 200
                call integ%advance_to(0.05_wp*j, t, y, yq, err)
                if (allocated(err)) exit
                e = 0.5_wp*y(4)**2 + 0.5_wp*p%omega**2*y(3)**2
                emax(m) = max(emax(m), e)
            end do
            call suite%check_true(.not. allocated(err), 'hidden mode: run completes')
        end do
        write (label, '(a, es9.2, a)') 'hidden stiff mode, default max_order: max energy ', &
            emax(1)/e0, ' E0 (no growth)'
        call suite%check_le(emax(1), e0, trim(label))
        write (label, '(a, es9.2, a)') 'hidden stiff mode, max_order 5: max energy ', &
            emax(2)/e0, ' E0 (grows: why 5 is not the default)'
        call suite%check_true(emax(2) > 2.0_wp*e0, trim(label))
    end subroutine test_hidden_mode

    !> A right-hand side that keeps failing ends the run with time, step size and cause;
    !! a too small step budget is reported as such.
    subroutine test_failures()
        type(linear_t), target :: p
        type(mebdf_t) :: integ
        type(solver_options_t) :: opt
        type(error_t), allocatable :: err
        real(wp) :: y(3), yq(0), t
        p%fail_after = 0.5_wp
        call integ%init(p, 0.0_wp, [1.0_wp, 0.0_wp, 2.0_wp], yq, opt, err)
        call integ%advance_to(1.0_wp, t, y, yq, err)
        call suite%check_true(allocated(err), 'failing rhs: error returned')
        if (.not. allocated(err)) return
        call suite%check_contains(err%message, 'mebdf failed at t = ', 'failing rhs: time')
        call suite%check_contains(err%message, 'step size', 'failing rhs: step size')
        call suite%check_contains(err%message, 'recoverable errors of the right-hand side', &
                                  'failing rhs: cause')
        call suite%check_true(t <= 0.5_wp .and. t > 0.4_wp, &
                              'failing rhs: the last good state is returned')
        p%fail_after = huge(1.0_wp)
        opt%max_steps = 20_i8
        call integ%init(p, 0.0_wp, [1.0_wp, 0.0_wp, 2.0_wp], yq, opt, err)
        call integ%advance_to(10.0_wp, t, y, yq, err)
        call suite%check_true(allocated(err), 'step budget: error returned')
        if (.not. allocated(err)) return
        call suite%check_contains(err%message, 'max_steps exceeded', 'step budget: cause')
    end subroutine test_failures
end program test_mebdf
