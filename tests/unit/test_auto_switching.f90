!> `method = 'auto'` through a short transient: a lightly damped oscillator driven at
!! w = 20 rad/s, y1'' = -400 y1 - 0.1 y1' + w^2 cos(w t), with a mass matrix (the identity:
!! auto tries Adams only where f solves with one), whose drive jumps to w = 2000 rad/s for
!! 0.06 s at t = 6 s. erk's step is held by accuracy; auto tries Adams, which is cheaper
!! (1.2e3 against erk's 1.2e3 x 1.3 and more f per second) and keeps it. The burst costs
!! Adams 2e4 f per second for about one window. Leaving Adams on that one window (as auto
!! did before it asked for two windows in a row) sends it back to erk, whose cost measured
!! before the burst then keeps Adams out for the rest of the run: 2.1e4 evaluations of f
!! over 20 s against 7.5e3 (measured with a one-window rule, burst lengths 0.05-0.08 s).
!! A second run has a burst of 1 s, which does send auto to erk: after it, auto must go
!! back to Adams (see the program). A third run has no mass matrix: there auto's method
!! for a step held by accuracy is erk's order-5 pair (Dormand-Prince 5(4)), and it must
!! take fewer evaluations of f than the order-4 pair alone.
module test_auto_switching_burst
    use ropedyn_kinds, only: wp
    use ropedyn_problem, only: problem_t, STATUS_OK
    implicit none
    private
    public :: burst_t, T_BURST, BURST

    real(wp), parameter :: T_BURST = 6.0_wp   !< s, start of the burst
    real(wp), parameter :: BURST = 0.06_wp    !< s, its length

    type, extends(problem_t) :: burst_t
        real(wp) :: length = BURST              !< s, the burst's length
        logical :: mass = .true.                !< weighed as a problem with a mass matrix
    contains
        procedure :: size => burst_size
        procedure :: bandwidths => burst_bandwidths
        procedure :: rhs => burst_rhs
        procedure :: has_mass_matrix => burst_has_mass_matrix
    end type burst_t

contains

    pure integer function burst_size(self) result(n)
        class(burst_t), intent(in) :: self
        n = 2
    end function burst_size

    pure subroutine burst_bandwidths(self, ml, mu)
        class(burst_t), intent(in) :: self
        integer, intent(out) :: ml, mu
        ml = 1
        mu = 1
    end subroutine burst_bandwidths

    !> M = I: never assembled (only Adams and erk run here), but auto weighs the problem as
    !! one whose f solves with a mass matrix.
    pure logical function burst_has_mass_matrix(self) result(has)
        class(burst_t), intent(in) :: self
        has = self%mass
    end function burst_has_mass_matrix

    subroutine burst_rhs(self, t, y, ydot, status)
        class(burst_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: ydot(:)
        integer, intent(out) :: status
        real(wp) :: w
        w = 20.0_wp
        if (t >= T_BURST .and. t < T_BURST + self%length) w = 2000.0_wp
        ydot(1) = y(2)
        ydot(2) = -400.0_wp*y(1) - 0.1_wp*y(2) + w**2*cos(w*t)
        status = STATUS_OK
    end subroutine burst_rhs
end module test_auto_switching_burst

program test_auto_switching
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t
    use ropedyn_integrator, only: integrator_t, solver_options_t, solver_stats_t
    use ropedyn_switch_log, only: switch_event_t
    use ropedyn_solvers, only: new_integrator
    use ropedyn_assert, only: test_suite_t
    use test_auto_switching_burst, only: burst_t, T_BURST
    implicit none

    real(wp), parameter :: T_END = 20.0_wp
    type(test_suite_t) :: suite
    type(burst_t), target :: short_burst, long_burst, no_mass
    type(solver_stats_t) :: erk4
    type(switch_event_t), allocatable :: events(:)
    type(solver_stats_t) :: stats
    logical :: ok
    integer :: n

    suite%name = 'auto_switching'

    call integrate(short_burst, events, stats, ok)
    call suite%check_true(ok, 'auto integrates through the burst')
    n = size(events)
    call suite%check_true(n >= 2, 'auto tries adams')
    if (.not. ok .or. n < 2) call suite%finish()
    call suite%check_true(trim(events(1)%method) == 'erk' .and. &
                          trim(events(n)%method) == 'adams' .and. events(n)%t < T_BURST, &
                          'erk, then adams before the burst, kept to the end')
    call suite%check_le(real(stats%rhs_evals, wp), 1.2e4_wp, &
                        'f evaluations over 20 s (2.1e4 when the burst sends it to erk)')

    ! A burst of 1 s: Adams is dearer than erk for more than two windows and auto goes to
    ! erk (and tries mebdf in the burst, where erk's step is held by stability); once the
    ! burst is over, erk is weighed against Adams' cost before the burst (its last window
    ! that was not dearer), not its cost in the burst (2e4 f per second), and auto goes
    ! back to Adams for the rest of the run (at 8.5 s, after the wait of its back-off).
    ! With the burst's cost held against Adams, erk ran from 6.15 s to the end: 8.2e4
    ! evaluations of f against 7.1e4.
    long_burst%length = 1.0_wp
    call integrate(long_burst, events, stats, ok)
    call suite%check_true(ok, 'auto integrates through the long burst')
    n = size(events)
    if (.not. ok .or. n < 2) call suite%finish()
    call suite%check_true(any(events(1:n - 1)%t > T_BURST .and. &
                              events(1:n - 1)%method == 'erk'), 'erk in the long burst')
    call suite%check_true(trim(events(n)%method) == 'adams' .and. &
                          events(n)%t > T_BURST + long_burst%length .and. &
                          events(n)%t < T_END - 5.0_wp, &
                          'back to adams after the long burst, kept to the end')
    call suite%check_le(real(stats%rhs_evals, wp), 7.6e4_wp, &
                        'f evaluations over 20 s with the long burst (8.2e4 on erk)')

    ! No mass matrix (and no burst): the step is held by accuracy, and the order-5 pair
    ! takes longer steps for the same tolerance than the order-4 pair; auto must find that
    ! out and use it
    no_mass%mass = .false.
    no_mass%length = 0.0_wp
    call integrate(no_mass, events, erk4, ok, 'erk')
    call suite%check_true(ok, 'erk integrates the problem without a mass matrix')
    call integrate(no_mass, events, stats, ok)
    call suite%check_true(ok, 'auto integrates the problem without a mass matrix')
    n = size(events)
    if (.not. ok .or. n < 2) call suite%finish()
    call suite%check_true(trim(events(1)%method) == 'erk' .and. events(1)%max_order == 4 &
                          .and. any(events(2:)%method == 'erk' .and. events(2:)%max_order == 5), &
                          'without a mass matrix: erk 4, then the order-5 pair')
    call suite%check_true(all(events%method == 'erk'), &
                          'without a mass matrix: no adams, no implicit method')
    call suite%check_le(1.3_wp*real(stats%rhs_evals, wp), real(erk4%rhs_evals, wp), &
                        'f evaluations: auto at least 1.3 times fewer than the order-4 pair')
    call suite%finish()

contains

    !> auto over [0, T_END], an output every 0.01 s as a run has (auto looks at its window
    !! between outputs); prints the switches.
    subroutine integrate(problem, events, stats, ok, method)
        type(burst_t), target, intent(inout) :: problem
        type(switch_event_t), allocatable, intent(out) :: events(:)
        type(solver_stats_t), intent(out) :: stats
        logical, intent(out) :: ok
        character(len=*), intent(in), optional :: method   !< default 'auto'
        class(integrator_t), allocatable :: integ
        type(solver_options_t) :: opts
        type(error_t), allocatable :: err
        real(wp) :: y(2), yq(0), t
        integer :: k
        character(len=200) :: line
        opts%rtol = 1.0e-6_wp
        opts%atol = 1.0e-9_wp
        if (present(method)) then
            call new_integrator(method, integ, err)
        else
            call new_integrator('auto', integ, err)
        end if
        if (.not. allocated(err)) call integ%init(problem, 0.0_wp, [1.0_wp, 0.0_wp], yq, &
                                                  opts, err)
        do k = 1, nint(100*T_END)
            if (allocated(err)) exit
            call integ%advance_to(0.01_wp*k, t, y, yq, err)
        end do
        ok = .not. allocated(err)
        allocate (events(0))
        if (.not. ok) return
        events = integ%switch_log()
        stats = integ%stats()
        print '(a, f5.2, a, l1, a)', '  burst of ', problem%length, ' s (mass matrix: ', &
            problem%mass, '):'
        do k = 1, size(events)
            write (line, '(a, f8.4, a)') '  switch at t = ', events(k)%t, ' s: '// &
                trim(events(k)%method)//': '//events(k)%reason(1:min(120, len(events(k)%reason)))
            print '(a)', trim(line)
        end do
        print '(a, i0, a, i0)', '  steps ', stats%steps, ', f evaluations ', stats%rhs_evals
    end subroutine integrate
end program test_auto_switching
