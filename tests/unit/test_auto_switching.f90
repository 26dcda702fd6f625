!> `method = 'auto'` through a short transient: a lightly damped oscillator driven at
!! w = 20 rad/s, y1'' = -400 y1 - 0.1 y1' + w^2 cos(w t), with a mass matrix (the identity:
!! auto tries Adams only where f solves with one), whose drive jumps to w = 2000 rad/s for
!! 0.06 s at t = 6 s. erk's step is held by accuracy; auto tries Adams, which is cheaper
!! (1.2e3 against erk's 1.2e3 x 1.3 and more f per second) and keeps it. The burst costs
!! Adams 2e4 f per second for about one window. Leaving Adams on that one window (as auto
!! did before it asked for two windows in a row) sends it back to erk, whose cost measured
!! before the burst then keeps Adams out for the rest of the run: 2.1e4 evaluations of f
!! over 20 s against 7.5e3 (measured with a one-window rule, burst lengths 0.05-0.08 s).
module test_auto_switching_burst
    use ropedyn_kinds, only: wp
    use ropedyn_problem, only: problem_t, STATUS_OK
    implicit none
    private
    public :: burst_t, T_BURST, BURST

    real(wp), parameter :: T_BURST = 6.0_wp   !< s, start of the burst
    real(wp), parameter :: BURST = 0.06_wp    !< s, its length

    type, extends(problem_t) :: burst_t
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
        has = .true.
    end function burst_has_mass_matrix

    subroutine burst_rhs(self, t, y, ydot, status)
        class(burst_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: ydot(:)
        integer, intent(out) :: status
        real(wp) :: w
        w = 20.0_wp
        if (t >= T_BURST .and. t < T_BURST + BURST) w = 2000.0_wp
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
    type(burst_t), target :: problem
    class(integrator_t), allocatable :: integ
    type(solver_options_t) :: opts
    type(error_t), allocatable :: err
    type(switch_event_t), allocatable :: events(:)
    type(solver_stats_t) :: stats
    real(wp) :: y(2), yq(0), t
    integer :: k, n
    character(len=200) :: line

    suite%name = 'auto_switching'
    opts%rtol = 1.0e-6_wp
    opts%atol = 1.0e-9_wp
    call new_integrator('auto', integ, err)
    if (.not. allocated(err)) call integ%init(problem, 0.0_wp, [1.0_wp, 0.0_wp], yq, opts, err)
    ! output every 0.01 s, as a run does (auto looks at its window between outputs)
    do k = 1, nint(100*T_END)
        if (allocated(err)) exit
        call integ%advance_to(0.01_wp*k, t, y, yq, err)
    end do
    call suite%check_true(.not. allocated(err), 'auto integrates through the burst')
    if (allocated(err)) call suite%finish()
    events = integ%switch_log()
    stats = integ%stats()
    n = size(events)
    do k = 1, n
        write (line, '(a, f8.4, a)') '  switch at t = ', events(k)%t, ' s: '// &
            trim(events(k)%method)//': '//events(k)%reason(1:min(120, len(events(k)%reason)))
        print '(a)', trim(line)
    end do
    print '(a, i0, a, i0)', '  steps ', stats%steps, ', f evaluations ', stats%rhs_evals
    call suite%check_true(n >= 2, 'auto tries adams')
    if (n < 2) call suite%finish()
    call suite%check_true(trim(events(1)%method) == 'erk' .and. &
                          trim(events(n)%method) == 'adams' .and. events(n)%t < T_BURST, &
                          'erk, then adams before the burst, kept to the end')
    call suite%check_le(real(stats%rhs_evals, wp), 1.2e4_wp, &
                        'f evaluations over 20 s (2.1e4 when the burst sends it to erk)')
    call suite%finish()
end program test_auto_switching
