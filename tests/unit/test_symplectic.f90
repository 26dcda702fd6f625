!> A damped linear oscillator m q'' = -m w^2 q - m c q' with the force split (problem_t):
!! the spring is the potential, the damper the rest; one quadrature, the dissipated energy
!! (rate m c v^2, sign -1 in the balance). With w_slow > 0 a second, undamped mode
!! q2'' = -w_slow^2 q2 beside it (two coordinates: q = (q1, q2), y = (q1, q2, v1, v2)): a
!! slow motion that a method must follow, and a fast mode that holds its step. Its forces
!! are reported not finite (STATUS_RECOVERABLE) as a model's are.
module test_symplectic_oscillator
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use ropedyn_kinds, only: wp
    use ropedyn_problem, only: problem_t, STATUS_OK, STATUS_RECOVERABLE
    implicit none
    private
    public :: oscillator_t

    type, extends(problem_t) :: oscillator_t
        real(wp) :: w = 1.0_wp    !< 1/s
        real(wp) :: c = 0.0_wp    !< 1/s
        real(wp) :: m = 2.0_wp    !< kg
        real(wp) :: w_slow = 0.0_wp  !< 1/s (0: no second mode)
    contains
        procedure :: size => osc_size
        procedure :: bandwidths => osc_bandwidths
        procedure :: rhs => osc_rhs
        procedure :: has_jacobian => osc_has_jacobian
        procedure :: jacobian => osc_jacobian
        procedure :: quad_size => osc_quad_size
        procedure :: quad_rhs => osc_quad_rhs
        procedure :: has_second_order => osc_has_second_order
        procedure :: second_order_layout => osc_layout
        procedure :: force_split_refusal => osc_refusal
        procedure :: split_layout => osc_split_layout
        procedure :: split_rhs => osc_split_rhs
        procedure, private :: dof
    end type oscillator_t

contains

    pure integer function dof(self)
        class(oscillator_t), intent(in) :: self
        dof = merge(2, 1, self%w_slow > 0.0_wp)
    end function dof

    pure integer function osc_size(self)
        class(oscillator_t), intent(in) :: self
        osc_size = 2*self%dof()
    end function osc_size

    pure subroutine osc_bandwidths(self, ml, mu)
        class(oscillator_t), intent(in) :: self
        integer, intent(out) :: ml, mu
        ml = self%dof()
        mu = self%dof()
    end subroutine osc_bandwidths

    !> The accelerations of the springs (ac) and of the damper (ar) at y.
    pure subroutine accelerations(self, y, ac, ar)
        class(oscillator_t), intent(in) :: self
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: ac(:), ar(:)
        integer :: n
        n = self%dof()
        ac(1) = -self%w**2*y(1)
        ar = 0.0_wp
        ar(1) = -self%c*y(n + 1)
        if (n == 2) ac(2) = -self%w_slow**2*y(2)
    end subroutine accelerations

    subroutine osc_rhs(self, t, y, ydot, status)
        class(oscillator_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: ydot(:)
        integer, intent(out) :: status
        real(wp) :: ac(2), ar(2)
        integer :: n
        n = self%dof()
        call accelerations(self, y, ac, ar)
        ydot(1:n) = y(n + 1:2*n)
        ydot(n + 1:2*n) = ac(1:n) + ar(1:n)
        status = merge(STATUS_OK, STATUS_RECOVERABLE, all(ieee_is_finite(ydot)))
    end subroutine osc_rhs

    pure logical function osc_has_jacobian(self) result(has)
        class(oscillator_t), intent(in) :: self
        has = .true.
    end function osc_has_jacobian

    subroutine osc_jacobian(self, t, y, jb, offset, status)
        class(oscillator_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(inout) :: jb(:, :)
        integer, intent(in) :: offset
        integer, intent(out) :: status
        integer :: n, i
        ! (band storage: the entry of row i, column j at jb(offset + i - j, j))
        n = self%dof()
        do i = 1, n
            jb(offset - n, n + i) = jb(offset - n, n + i) + 1.0_wp      ! d q_i'/d v_i
        end do
        jb(offset + n, 1) = jb(offset + n, 1) - self%w**2               ! d v_1'/d q_1
        jb(offset, n + 1) = jb(offset, n + 1) - self%c                  ! d v_1'/d v_1
        if (n == 2) jb(offset + n, 2) = jb(offset + n, 2) - self%w_slow**2
        status = STATUS_OK
    end subroutine osc_jacobian

    pure integer function osc_quad_size(self) result(nq)
        class(oscillator_t), intent(in) :: self
        nq = 1
    end function osc_quad_size

    subroutine osc_quad_rhs(self, t, y, yqdot, status)
        class(oscillator_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: yqdot(:)
        integer, intent(out) :: status
        yqdot(1) = self%m*self%c*y(self%dof() + 1)**2
        status = STATUS_OK
    end subroutine osc_quad_rhs

    pure logical function osc_has_second_order(self) result(has)
        class(oscillator_t), intent(in) :: self
        has = .true.
    end function osc_has_second_order

    pure subroutine osc_layout(self, pos, vel, kl, ku)
        class(oscillator_t), intent(in) :: self
        integer, allocatable, intent(out) :: pos(:), vel(:)
        integer, intent(out) :: kl, ku
        integer :: i, n
        n = self%dof()
        pos = [(i, i=1, n)]
        vel = [(n + i, i=1, n)]
        kl = 0
        ku = 0
    end subroutine osc_layout

    pure function osc_refusal(self) result(why)
        class(oscillator_t), intent(in) :: self
        character(len=:), allocatable :: why
        why = ''
    end function osc_refusal

    pure subroutine osc_split_layout(self, mass, signs)
        class(oscillator_t), intent(in) :: self
        real(wp), intent(out) :: mass(:)
        integer, intent(out) :: signs(:)
        mass = self%m
        signs = -1
    end subroutine osc_split_layout

    subroutine osc_split_rhs(self, t, y, ac, gc, status, ar, gr)
        class(oscillator_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: ac(:), gc(:)
        integer, intent(out) :: status
        real(wp), intent(out), optional :: ar(:), gr(:)
        real(wp) :: a_rest(2)
        call accelerations(self, y, ac, a_rest)
        gc = 0.0_wp
        if (present(ar)) ar = a_rest(1:size(ar))
        if (present(gr)) gr(1) = self%m*self%c*y(self%dof() + 1)**2
        status = merge(STATUS_OK, STATUS_RECOVERABLE, all(ieee_is_finite(ac)))
    end subroutine osc_split_rhs
end module test_symplectic_oscillator

!> The symplectic method (solvers/symplectic, docs/theory/symplectic.md):
!! - its stability tables against the method itself, on the damped oscillator at fixed
!!   steps: bounded at 0.97 of the tabulated h w, growing at 1.03 of it (Blanes-Moan
!!   undamped: in its narrow gap at h w = 3.166);
!! - its order on the oscillator (error at t = 10 at h and h/2: ratio 4 for Verlet, 16 for
!!   the 4th-order compositions), and the energy balance with damping bounded over 500
!!   periods (the D-map's dissipated energy closes it);
!! - each composition's energy spread of an undamped mode, formula against orbit;
!! - bounded energy on an undamped 4-element rope over 20 s (about 2,200 periods of its
!!   fastest mode): |T + V - E0| <= 1e-3 m g L at every record for the symplectic method,
!!   and 1e-4 at rtol 1e-5, while erk's error passes 1e-3 (rtol 1e-3 both);
!! - the balance with light damping and a shaken clamped top (the work of the support by
!!   its springs' kicks and dampers' D-maps) stays within 1e-3 m g L, with work done;
!! - a step unstable at every retry: the method fails with the last finite state; auto,
!!   whose symplectic run outgrows the step budget mid-run, goes on with erk to the end;
!! - refusals: point masses off the element centres, ground contact, the MPP.
program test_symplectic
    use ropedyn_kinds, only: wp, i8
    use ropedyn_error, only: error_t
    use ropedyn_integrator, only: integrator_t, solver_options_t
    use ropedyn_solvers, only: new_integrator
    use ropedyn_switch_log, only: switch_event_t
    use ropedyn_symplectic, only: symplectic_t, choose_step, TABLE_VERLET, TABLE_BM6, TABLE_CHIN
    use ropedyn_spectrum, only: spectrum_t
    use ropedyn_split_tables, only: split_table, split_table_t
    use ropedyn_assert, only: test_suite_t
    use ropedyn_test_run, only: run_t, simulate, completed, SET_LEN
    use test_symplectic_oscillator, only: oscillator_t
    implicit none

    real(wp), parameter :: MGL = 6000.0_wp*acos(-1.0_wp)*0.005_wp**2/4.0_wp*9.81_wp
    type(test_suite_t) :: suite

    suite%name = 'symplectic'
    call stability_table()
    call order_and_balance()
    call energy_spreads()
    call step_costs()
    call step_follows_spectrum()
    call unstable_to_the_end()
    call auto_leaves_symplectic()
    call auto_returns_to_symplectic()
    call undamped_rope()
    call shaken_rope()
    call refusals()
    call suite%finish()

contains

    !> The oscillator (w = 1) at a fixed step from q = 1, v = 0 over `steps` steps: the
    !! largest |q| at the outputs (every step) and the balance T + V + dissipated - E0 at each.
    subroutine run_fixed(table, zeta, h, steps, qmax, balance, q_end, err)
        integer, intent(in) :: table
        real(wp), intent(in) :: zeta, h
        integer, intent(in) :: steps
        real(wp), intent(out) :: qmax
        real(wp), allocatable, intent(out) :: balance(:)
        real(wp), intent(out) :: q_end
        type(error_t), allocatable, intent(out) :: err
        type(oscillator_t), target :: osc
        type(symplectic_t) :: integ
        type(solver_options_t) :: options
        real(wp) :: y(2), yq(1), t, e0
        integer :: k
        osc%c = 2.0_wp*zeta*osc%w
        y = [1.0_wp, 0.0_wp]
        yq = 0.0_wp
        e0 = 0.5_wp*osc%m*osc%w**2
        call integ%init(osc, 0.0_wp, y, yq, options, err)
        if (allocated(err)) return
        call integ%fix_step(table, h)
        allocate (balance(steps))
        qmax = 0.0_wp
        do k = 1, steps
            call integ%advance_to(real(k, wp)*h, t, y, yq, err)
            if (allocated(err)) return
            qmax = max(qmax, abs(y(1)))
            balance(k) = 0.5_wp*osc%m*(y(2)**2 + osc%w**2*y(1)**2) + yq(1) - e0
        end do
        q_end = y(1)
    end subroutine run_fixed

    subroutine stability_table()
        real(wp), parameter :: ZETAS(3) = [0.0_wp, 0.05_wp, 0.3_wp]
        character(len=12), parameter :: NAMES(3) = [character(len=12) :: 'Verlet', &
            'Blanes-Moan', 'Chin 4A']
        integer, parameter :: KINDS(3) = [TABLE_VERLET, TABLE_BM6, TABLE_CHIN]
        real(wp), allocatable :: balance(:)
        real(wp) :: qmax, q_end, x
        type(error_t), allocatable :: err
        type(split_table_t) :: tab
        character(len=80) :: label
        integer :: i, j
        do j = 1, 3
            tab = split_table(KINDS(j))
            do i = 1, 3
                ! the tabulated limit (ropedyn_split_tables)
                x = tab%stable_hw(ZETAS(i))
                write (label, '(a, a, f4.2)') trim(NAMES(j)), ', zeta = ', ZETAS(i)
                call run_fixed(KINDS(j), ZETAS(i), 0.97_wp*x, 3000, qmax, balance, q_end, err)
                call suite%check_true(.not. allocated(err) .and. qmax <= 10.0_wp, &
                                      trim(label)//': bounded at 0.97 of the table''s h w')
                ! (Blanes-Moan: past its first limit, stable again for a stretch when
                ! lightly damped; undamped, its narrow gap at 3.166)
                if (KINDS(j) == TABLE_BM6 .and. i == 2) cycle
                if (KINDS(j) == TABLE_BM6 .and. i == 1) x = 3.166_wp/1.03_wp
                call run_fixed(KINDS(j), ZETAS(i), 1.03_wp*x, 3000, qmax, balance, q_end, err)
                call suite%check_true(allocated(err) .or. qmax > 100.0_wp, &
                                      trim(label)//': growing at 1.03 of it')
            end do
        end do
    end subroutine stability_table

    !> Each composition's energy spread of an undamped mode (split_table_t's energy_spread,
    !! which sets the step where the fast modes are lightly damped) against the integrator's
    !! orbit at h w = 0.9: the largest energy over the smallest, minus 1.
    subroutine energy_spreads()
        integer, parameter :: KINDS(3) = [TABLE_VERLET, TABLE_BM6, TABLE_CHIN]
        real(wp), allocatable :: balance(:)
        ! (h w = 0.9: the orbit's points fill the ellipse; at h w = 1 Verlet's repeat every
        ! 6 steps)
        real(wp), parameter :: X = 0.9_wp
        real(wp) :: qmax, q_end, e0, measured, formula
        type(error_t), allocatable :: err
        type(split_table_t) :: tab
        type(oscillator_t) :: osc
        character(len=100) :: label
        integer :: j
        e0 = 0.5_wp*osc%m*osc%w**2
        do j = 1, 3
            tab = split_table(KINDS(j))
            call run_fixed(KINDS(j), 0.0_wp, X/osc%w, 3000, qmax, balance, q_end, err)
            measured = maxval(balance + e0)/minval(balance + e0) - 1.0_wp
            formula = tab%energy_spread(X)
            write (label, '(a, a, 2es10.3)') trim(tab%label), &
                ': energy spread at h w = 0.9, orbit and formula', measured, formula
            call suite%check_true(abs(measured - formula) <= 0.02_wp*formula, trim(label))
        end do
        call suite%check_true(tab%energy_hw(1.0e-3_wp) < tab%energy_hw(1.0e-2_wp), &
                              trim(tab%label)//': a smaller energy spread takes a shorter step')
    end subroutine energy_spreads

    subroutine order_and_balance()
        real(wp), allocatable :: balance(:)
        real(wp) :: qmax, q1, e1, e2, e3
        type(error_t), allocatable :: err
        call check_order(TABLE_VERLET, 0.1_wp, 4.0_wp)
        call check_order(TABLE_BM6, 0.2_wp, 16.0_wp)
        call check_order(TABLE_CHIN, 0.2_wp, 16.0_wp)
        ! damped by 1 % over 500 periods: the balance oscillates, it does not drift (the
        ! D-maps' dissipated energy is the change of T they make)
        e1 = late_over_early(TABLE_VERLET, 0.5_wp)
        e3 = late_over_early(TABLE_CHIN, 1.0_wp)
        call run_fixed(TABLE_BM6, 0.01_wp, 1.0_wp, 3142, qmax, balance, q1, err)
        e2 = maxval(abs(balance))
        call suite%check_le(e2, 1.0e-3_wp, 'Blanes-Moan, zeta = 0.01, h w = 1: |balance| '// &
                            '<= 1e-3 E0 over 500 periods')
        call suite%check_true(e1 > 0.0_wp .and. e2 < e1 .and. e3 < e1, 'the 4th orders'' '// &
                              'balance errors are below Verlet''s')
    end subroutine order_and_balance

    !> The error at t = 10 on the undamped oscillator at h and h/2: their ratio is 2^order.
    subroutine check_order(table, h, expected)
        integer, intent(in) :: table
        real(wp), intent(in) :: h, expected
        real(wp), allocatable :: balance(:)
        real(wp) :: qmax, q1, q2, exact, ratio
        type(error_t), allocatable :: err
        type(split_table_t) :: tab
        character(len=120) :: label
        exact = cos(10.0_wp)
        tab = split_table(table)
        call run_fixed(table, 0.0_wp, h, nint(10.0_wp/h), qmax, balance, q1, err)
        call run_fixed(table, 0.0_wp, h/2, nint(20.0_wp/h), qmax, balance, q2, err)
        ratio = abs(q1 - exact)/abs(q2 - exact)
        write (label, '(a, a, f6.2, a, f5.1)') trim(tab%label), ': error ratio at h and h/2 ', &
            ratio, ', order ', log(expected)/log(2.0_wp)
        call suite%check_true(abs(ratio/expected - 1.0_wp) < 0.1_wp, trim(label))
    end subroutine check_order

    !> The damped oscillator (zeta = 0.01) at h w over 500 periods: the balance in the last
    !! 50 periods at most 1.1 times the first 50 (checked); its largest value.
    real(wp) function late_over_early(table, hw) result(worst)
        integer, intent(in) :: table
        real(wp), intent(in) :: hw
        real(wp), allocatable :: balance(:)
        real(wp) :: qmax, q_end, early, late
        type(error_t), allocatable :: err
        type(split_table_t) :: tab
        character(len=120) :: label
        integer :: n, tenth
        tab = split_table(table)
        n = nint(1000.0_wp*acos(-1.0_wp)/hw)
        tenth = n/10
        call run_fixed(table, 0.01_wp, hw, n, qmax, balance, q_end, err)
        early = maxval(abs(balance(1:tenth)))
        late = maxval(abs(balance(n - tenth:n)))
        worst = maxval(abs(balance))
        write (label, '(a, a, es9.2, a, es9.2)') trim(tab%label), ', zeta = 0.01, 500 '// &
            'periods: balance in the first 50 periods ', early, ', in the last ', late
        call suite%check_le(late, 1.1_wp*early, trim(label))
    end function late_over_early

    !> The largest |T + V + dissipated - work - E0| over a run's records, in m g L.
    real(wp) function worst_balance(run) result(worst)
        type(run_t), intent(in) :: run
        integer :: k
        worst = 0.0_wp
        do k = 0, run%last()
            worst = max(worst, abs(run%e(k)%balance() - run%e(0)%balance()))
        end do
        worst = worst/MGL
    end function worst_balance

    !> The choice between the compositions counts a step's whole work: on a fast mode damped
    !! by 9.4 % (the paper's rope, n = 30) at rtol 4e-6 Chin's 4A steps 0.6 of SRKN_6^b's,
    !! which is cheaper per simulated second with its 3 evaluations against 6 when the
    !! potential's forces are all (3.5 against 6.5 a step), dearer when the rest's forces
    !! and D-maps come on top (5.3 against 8.3; callgrind: 1.2 times the instructions). And
    !! the RFEM says whether it has such forces.
    subroutine step_costs()
        real(wp), parameter :: RHO = 6.57e3_wp, ZETA = 0.094_wp
        type(spectrum_t) :: spec
        type(split_table_t) :: tab
        type(run_t) :: run
        real(wp) :: h, cost_rest
        logical :: light
        character(len=300) :: text
        spec%ritz = RHO*[cmplx(-ZETA, sqrt(1.0_wp - ZETA**2), wp), &
                         cmplx(-ZETA, -sqrt(1.0_wp - ZETA**2), wp)]
        spec%radius = RHO
        spec%fast_damping = ZETA
        spec%valid = .true.
        call choose_step(spec, 4.0e-6_wp, 4, .false., tab, h, light, text)
        call suite%check_true(tab%kind == TABLE_CHIN, 'damped fast modes, rtol 4e-6, the '// &
                              'potential''s forces only: Chin''s 4A, got '//trim(tab%label))
        call choose_step(spec, 4.0e-6_wp, 4, .true., tab, h, light, text, cost_rest)
        call suite%check_true(tab%kind == TABLE_BM6, 'the same with forces outside the '// &
                              'potential: Blanes-Moan, got '//trim(tab%label))
        call suite%check_close(cost_rest*h, tab%evals + 2.3_wp, 1.0e-12_wp, 0.0_wp, &
                               'its cost per step: 6 evaluations and 2.3 of other work')
        ! at rtol 1e-3 the damped mode takes Verlet at half its stable step; once an earlier
        ! estimate found lightly damped fast modes, a 4th-order composition at 0.35 (the
        ! shaken support flipped between the two at every estimate, its balance error 6e-4
        ! m g L over 10 s against 1e-7 when it stays)
        call choose_step(spec, 1.0e-3_wp, 4, .true., tab, h, light, text)
        call suite%check_true(tab%kind == TABLE_VERLET .and. .not. light, 'damped fast '// &
                              'modes, rtol 1e-3: Verlet, got '//trim(tab%label))
        call choose_step(spec, 1.0e-3_wp, 4, .true., tab, h, light, text, stay_light=.true.)
        call suite%check_true(tab%order == 4 .and. light .and. index(text, ' 0.35 x') > 0, &
                              'the same after lightly damped fast modes were seen: a '// &
                              '4th-order composition at 0.35 of its stable step, got '// &
                              trim(tab%label)//': '//trim(text))
        call simulate([character(len=SET_LEN) :: 'model.elements = 4'], 0.02_wp, 0.01_wp, &
                      1.0e-3_wp, run, 'symplectic')
        call suite%check_true(run%model%split_has_rest(), 'the damped RFEM has forces '// &
                              'outside the potential')
        call simulate([character(len=SET_LEN) :: 'model.elements = 4', &
                       'effects.damping = .false.'], 0.02_wp, 0.01_wp, 1.0e-3_wp, run, &
                      'symplectic')
        call suite%check_true(.not. run%model%split_has_rest(), 'the undamped one has none')
    end subroutine step_costs

    subroutine undamped_rope()
        real(wp) :: worst
        worst = undamped_worst(1.0e-3_wp, 'symplectic')
        call suite%check_le(worst, 1.0e-3_wp, 'undamped 4-element rope, 20 s, symplectic: '// &
                            'max |T + V - E0| (m g L) <= 1e-3')
        ! the energy follows the tolerance (the step keeps the fastest mode's energy within
        ! 10 rtol)
        worst = undamped_worst(1.0e-5_wp, 'symplectic')
        call suite%check_le(worst, 1.0e-4_wp, 'undamped 4-element rope, 20 s, rtol 1e-5: '// &
                            'max |T + V - E0| (m g L) <= 1e-4')
        worst = undamped_worst(1.0e-3_wp, 'erk')
        call suite%check_true(worst > 1.0e-3_wp .and. worst < huge(1.0_wp), &
                              'undamped 4-element rope, 20 s, erk (RK4): max |T + V - E0| > '// &
                              '1e-3 m g L (it drifts)')
    end subroutine undamped_rope

    !> The undamped 4-element rope over 20 s at rtol with `method`: the largest |T + V - E0|
    !! over its records, m g L (huge when the run did not complete).
    real(wp) function undamped_worst(rtol, method) result(worst)
        real(wp), intent(in) :: rtol
        character(len=*), intent(in) :: method
        character(len=SET_LEN), parameter :: SETS(2) = [character(len=SET_LEN) :: &
            'model.elements = 4', 'effects.damping = .false.']
        type(run_t) :: run
        character(len=80) :: label
        write (label, '(a, a, a, es8.1)') 'undamped 4-element rope, ', method, ', rtol ', rtol
        worst = huge(1.0_wp)
        call simulate(SETS, 20.0_wp, 0.1_wp, rtol, run, method)
        if (completed(suite, run, trim(label))) worst = worst_balance(run)
    end function undamped_worst

    subroutine shaken_rope()
        character(len=SET_LEN), parameter :: SETS(8) = [character(len=SET_LEN) :: &
            'model.elements = 6', 'rope.normal_damping = 0.1', &
            'rope.tangential_damping = 0.04', 'supports.top = "clamped"', &
            'supports.top_motion = "harmonic"', 'supports.top_amplitude = 0.02, 0.05', &
            'supports.top_frequency = 3.0', 'initial.angle_deg = 20']
        type(run_t) :: run
        real(wp) :: worst
        character(len=100) :: label
        call simulate(SETS, 5.0_wp, 0.05_wp, 1.0e-3_wp, run, 'symplectic')
        if (completed(suite, run, 'shaken lightly damped rope, symplectic')) then
            worst = worst_balance(run)
            write (label, '(a, es9.2, a)') 'shaken lightly damped rope, 5 s: max |T + V + '// &
                'dissipated - work - E0| = ', worst, ' m g L <= 1e-3'
            call suite%check_le(worst, 1.0e-3_wp, trim(label))
            call suite%check_true(abs(run%e(run%last())%support_work) > 10.0_wp*worst*MGL, &
                                  'shaken rope: the support did work (10 times the balance error)')
            call suite%check_true(run%e(run%last())%dissipated > 0.0_wp, &
                                  'shaken rope: energy was dissipated')
        end if
    end subroutine shaken_rope

    !> Over a long run the step follows the spectrum: an oscillator at about the paper
    !! rope's spectral radius (4,000 1/s: some 300 steps per output, outputs 0.1 s apart)
    !! whose w grows by 0.3 % every 6 outputs (so that the step shrinks at most estimates
    !! of the spectrum) and then by 10 % at once, ends at a step no longer than the rule's
    !! for its last w (0.35 of Chin's stable step) after more than the longest wait
    !! between estimates (RESPECTRUM_MAX steps). For that the grid must stay on the
    !! outputs: each change of the step refits it from the time of an output.
    subroutine step_follows_spectrum()
        type(oscillator_t), target :: osc
        type(symplectic_t) :: integ
        type(solver_options_t) :: options
        type(error_t), allocatable :: err
        type(split_table_t) :: tab
        real(wp) :: y(2), yq(1), t, rule
        character(len=120) :: label
        integer :: k
        osc%w = 4000.0_wp
        y = [1.0_wp, 0.0_wp]
        yq = 0.0_wp
        options%rtol = 1.0e-3_wp
        call integ%init(osc, 0.0_wp, y, yq, options, err)
        do k = 1, 700
            if (allocated(err)) exit
            if (mod(k, 6) == 0 .and. k <= 300) osc%w = 1.003_wp*osc%w
            if (k == 400) osc%w = 1.1_wp*osc%w
            call integ%advance_to(0.1_wp*real(k, wp), t, y, yq, err)
        end do
        tab = split_table(TABLE_CHIN)
        rule = 0.35_wp*tab%stable_hw(0.0_wp)/osc%w
        write (label, '(a, es11.4, a, es11.4, a)') 'oscillator, w up 0.3 % 50 times, then '// &
            '10 %: the last step', integ%step_size(), ' s, the rule''s', rule, ' s'
        call suite%check_true(.not. allocated(err) .and. &
                              integ%step_size() <= rule*(1.0_wp + 1.0e-9_wp), trim(label))
    end subroutine step_follows_spectrum

    !> A step unstable even when halved MAX_RETRIES (4) times (Verlet at h w = 100 on the
    !! oscillator, w = 1, to its 4th retry at 6.25: the forces overflow within the
    !! interval): the method fails, and hands back the state at the start of the interval,
    !! whose forces were finite (what auto goes on from), not the overflowed one.
    subroutine unstable_to_the_end()
        type(oscillator_t), target :: osc
        type(symplectic_t) :: integ
        type(solver_options_t) :: options
        type(error_t), allocatable :: err
        real(wp) :: y(2), yq(1), t
        y = [1.0_wp, 0.0_wp]
        yq = 0.0_wp
        call integ%init(osc, 0.0_wp, y, yq, options, err)
        call integ%fix_step(TABLE_VERLET, 100.0_wp)
        call integ%advance_to(1.0e5_wp, t, y, yq, err)
        call suite%check_true(allocated(err), 'Verlet at h w = 100: fails')
        if (.not. allocated(err)) return
        call suite%check_contains(err%message, 'not finite', 'the failure says why')
        call suite%check_true(t == 0.0_wp .and. all(y == [1.0_wp, 0.0_wp]) .and. &
                              .not. integ%failed_fatally(), 'the state handed back is '// &
                              'the last finite one (the start), the failure not fatal')
    end subroutine unstable_to_the_end

    !> auto on a slow mode (w = 1) beside a fast one (w = 4,000, undamped: auto takes the
    !! symplectic method, Chin's 4A at 3.0e-4 s), 10 s, with a step budget that covers its
    !! run (33,000 steps, 36,300 with the tenth to spare) and not much more (37,000). At 1 s
    !! the fast mode stiffens 1.5 times: at the next estimate of the spectrum the step
    !! shortens to 2.0e-4 s, and the rest of the run no longer fits the budget. auto goes
    !! on with erk from where the method stopped (not the symplectic method again) and
    !! finishes, the slow mode where it should be; the switch log in time order.
    subroutine auto_leaves_symplectic()
        type(oscillator_t), target :: osc
        class(integrator_t), allocatable :: integ
        type(error_t), allocatable :: err
        type(switch_event_t), allocatable :: events(:)
        real(wp) :: y(4), yq(1), t
        integer :: k, n
        character(len=160) :: label
        call auto_on_two_modes(osc, 1.0_wp, 10.0_wp, 37000_i8, integ, y, yq, err)
        do k = 1, 100
            if (allocated(err)) exit
            if (k == 11) osc%w = 1.5_wp*osc%w
            call integ%advance_to(0.1_wp*real(k, wp), t, y, yq, err)
        end do
        if (allocated(err)) then
            call suite%check_true(.false., 'auto, fast mode stiffened within a tight '// &
                                  'budget: completes: '//err%message)
            return
        end if
        events = integ%switch_log()
        n = size(events)
        call suite%check_true(trim(events(1)%method) == 'symplectic', &
                              'auto starts with the symplectic method')
        do k = n, 1, -1
            if (index(events(k)%reason, 'without the symplectic method') > 0) exit
        end do
        call suite%check_true(k > 0, 'auto leaves the symplectic method')
        if (k == 0) return
        call suite%check_true(trim(events(k)%method) == 'erk' .and. events(k)%t > 1.0_wp &
                              .and. index(events(k)%reason, 'max_steps') > 0 .and. &
                              events(k)%warning, &
                              'for erk (a warning), after the fast mode stiffened, for the '// &
                              'step budget: '// &
                              events(k)%reason(1:min(200, len(events(k)%reason))))
        call suite%check_true(all(events(k:n)%method /= 'symplectic'), &
                              'and does not take the symplectic method again')
        call suite%check_true(all(events(2:n)%t >= events(1:n - 1)%t), &
                              'the switch log is in time order')
        write (label, '(a, es9.2)') 'the slow mode at 10 s: |q2 - cos(10)| = ', &
            abs(y(2) - cos(10.0_wp))
        call suite%check_le(abs(y(2) - cos(10.0_wp)), 1.0e-2_wp, trim(label))
    end subroutine auto_leaves_symplectic

    !> auto runs the symplectic method twice: the fast mode stiffens 25 times over 1-4 s
    !! (the method's step follows the spectrum until it is too short: auto leaves it), eases
    !! back from 5 s and drops to its first frequency at 5.3 s, during mebdf's trial, whose
    !! window then finds the method cheaper. The switch log keeps the method's own events
    !! of both runs (its init clears its log).
    subroutine auto_returns_to_symplectic()
        type(oscillator_t), target :: osc
        class(integrator_t), allocatable :: integ
        type(error_t), allocatable :: err
        type(switch_event_t), allocatable :: events(:)
        real(wp) :: y(4), yq(1), t, tk, t_left, t_back
        integer :: k, n
        call auto_on_two_modes(osc, 1500.0_wp, 30.0_wp, 100000000_i8, integ, y, yq, err)
        do k = 1, 600
            if (allocated(err)) exit
            tk = 0.01_wp*real(k, wp)
            osc%w = 4000.0_wp*25.0_wp**max(0.0_wp, min(1.0_wp, (tk - 1.0_wp)/3.0_wp, &
                                                        (8.0_wp - tk)/3.0_wp))
            if (tk > 5.3_wp) osc%w = 4000.0_wp
            call integ%advance_to(tk, t, y, yq, err)
        end do
        if (allocated(err)) then
            call suite%check_true(.false., 'auto, fast mode stiffened and eased: runs: '// &
                                  err%message)
            return
        end if
        events = integ%switch_log()
        n = size(events)
        ! (auto's switches name the method; the method's own events its composition)
        t_left = -1.0_wp
        t_back = -1.0_wp
        do k = 2, n
            if (events(k)%method /= 'symplectic' .and. events(k - 1)%method == 'symplectic' &
                .and. t_left < 0.0_wp) t_left = events(k)%t
            if (events(k)%method == 'symplectic' .and. events(k - 1)%method /= 'symplectic' &
                .and. t_left >= 0.0_wp) t_back = events(k)%t
        end do
        call suite%check_true(trim(events(1)%method) == 'symplectic' .and. t_left > 1.0_wp &
                              .and. t_back > t_left, 'auto starts with the symplectic '// &
                              'method, leaves it and takes it again')
        call suite%check_true(count(events%method == 'symplectic' .and. &
                                    index_all(events, 'Chin 4A, step') .and. &
                                    events%t > 0.5_wp .and. events%t < t_left) >= 2, &
                              'the log keeps the first run''s own step changes')
        call suite%check_true(count(events%method == 'symplectic' .and. &
                                    index_all(events, 'Chin 4A, step') .and. &
                                    events%t >= t_back) >= 1, &
                              'and the second run''s')
        call suite%check_true(all(events(2:n)%t >= events(1:n - 1)%t), &
                              'the switch log is in time order')
    end subroutine auto_returns_to_symplectic

    !> Whether each event's reason contains `text`.
    pure function index_all(events, text) result(has)
        type(switch_event_t), intent(in) :: events(:)
        character(len=*), intent(in) :: text
        logical :: has(size(events))
        integer :: k
        do k = 1, size(events)
            has(k) = index(events(k)%reason, text) > 0
        end do
    end function index_all

    !> auto started on the two-mode oscillator (the fast mode at w = 4000/s from 1e-7,
    !! the slow one, undamped at w_slow, from 1), rtol 1e-3, atol 1e-6.
    subroutine auto_on_two_modes(osc, w_slow, t_end, max_steps, integ, y, yq, err)
        type(oscillator_t), target, intent(inout) :: osc
        real(wp), intent(in) :: w_slow, t_end
        integer(i8), intent(in) :: max_steps
        class(integrator_t), allocatable, intent(out) :: integ
        real(wp), intent(out) :: y(4), yq(1)
        type(error_t), allocatable, intent(out) :: err
        type(solver_options_t) :: options
        osc%w = 4000.0_wp
        osc%w_slow = w_slow
        y = [1.0e-7_wp, 1.0_wp, 0.0_wp, 0.0_wp]
        yq = 0.0_wp
        options%rtol = 1.0e-3_wp
        options%atol = 1.0e-6_wp
        options%t_end = t_end
        options%max_steps = max_steps
        call new_integrator('auto', integ, err)
        if (.not. allocated(err)) call integ%init(osc, 0.0_wp, y, yq, options, err)
    end subroutine auto_on_two_modes

    subroutine refusals()
        character(len=SET_LEN) :: sets(3)
        type(run_t) :: run
        sets(1) = 'model.elements = 6'
        sets(2) = 'attachments.mass_positions = 0.9'
        sets(3) = 'attachments.masses = 0.05'
        call simulate(sets, 0.1_wp, 0.05_wp, 1.0e-3_wp, run, 'symplectic')
        call suite%check_true(.not. run%ok, 'a point mass off an element centre is refused')
        call suite%check_contains(run%message, 'point masses off the element centres', &
                                  'the refusal says why')
        sets(2) = 'effects.ground = .true.'
        sets(3) = 'model.elements = 6'
        call simulate(sets, 0.1_wp, 0.05_wp, 1.0e-3_wp, run, 'symplectic')
        call suite%check_contains(run%message, 'ground contact', 'ground contact is refused')
        sets(2) = 'model.kind = "mpp"'
        call simulate(sets, 0.1_wp, 0.05_wp, 1.0e-3_wp, run, 'symplectic')
        call suite%check_contains(run%message, 'mass matrix depends on the state', &
                                  'the MPP is refused, saying why')
    end subroutine refusals
end program test_symplectic
