!> auto's start when the spectrum cannot be estimated (solvers/auto/ropedyn_auto_start.f90):
!! y' = -k(t) (y - cos t), with k = 0 up to T_STIFF and 1e7 1/s after. At t = 0 the
!! Jacobian is zero, so the estimate finds no spectral radius; auto starts erk, whose
!! steps collapse once the problem turns stiff, and goes implicit. Without an estimate
!! of the fast modes' damping it must assume the worst (undamped: MEBDF at its A-stable
!! order 4, docs/theory/auto.md), not the best (it took order 6, which amplifies lightly
!! damped modes).
module test_auto_start_relax
    use ropedyn_kinds, only: wp
    use ropedyn_problem, only: problem_t, STATUS_OK
    implicit none
    private
    public :: relax_t, T_STIFF

    real(wp), parameter :: T_STIFF = 0.01_wp   !< s, when the relaxation switches on
    real(wp), parameter :: RATE = 1.0e7_wp     !< 1/s, its rate after

    type, extends(problem_t) :: relax_t
    contains
        procedure :: size => relax_size
        procedure :: bandwidths => relax_bandwidths
        procedure :: rhs => relax_rhs
    end type relax_t

contains

    pure integer function relax_size(self) result(n)
        class(relax_t), intent(in) :: self
        n = 1
    end function relax_size

    pure subroutine relax_bandwidths(self, ml, mu)
        class(relax_t), intent(in) :: self
        integer, intent(out) :: ml, mu
        ml = 0
        mu = 0
    end subroutine relax_bandwidths

    subroutine relax_rhs(self, t, y, ydot, status)
        class(relax_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: ydot(:)
        integer, intent(out) :: status
        ydot = 0.0_wp
        if (t > T_STIFF) ydot = -RATE*(y - cos(t))
        status = STATUS_OK
    end subroutine relax_rhs
end module test_auto_start_relax

program test_auto_start
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t
    use ropedyn_integrator, only: integrator_t, solver_options_t
    use ropedyn_switch_log, only: switch_event_t
    use ropedyn_solvers, only: new_integrator
    use ropedyn_assert, only: test_suite_t
    use test_auto_start_relax, only: relax_t
    implicit none
    type(test_suite_t) :: suite
    type(relax_t), target :: problem
    class(integrator_t), allocatable :: integ
    type(solver_options_t) :: opts
    type(error_t), allocatable :: err
    type(switch_event_t), allocatable :: events(:)
    real(wp) :: y(1), yq(0), t
    integer :: k

    suite%name = 'auto_start'
    opts%rtol = 1.0e-6_wp
    opts%atol = 1.0e-9_wp
    call new_integrator('auto', integ, err)
    if (.not. allocated(err)) call integ%init(problem, 0.0_wp, [1.0_wp], yq, opts, err)
    do k = 1, 20
        if (allocated(err)) exit
        call integ%advance_to(0.01_wp*k, t, y, yq, err)
    end do
    call suite%check_true(.not. allocated(err), 'auto integrates through the switch-on')
    if (allocated(err)) call suite%finish()
    events = integ%switch_log()
    do k = 1, size(events)
        print '(a, f8.4, a, i0, a)', '  switch at t = ', events(k)%t, ' s: '// &
            trim(events(k)%method)//' (max order ', events(k)%max_order, '): '// &
            events(k)%reason(1:min(100, len(events(k)%reason)))
    end do
    call suite%check_true(trim(events(1)%method) == 'erk' .and. &
                          index(events(1)%reason, 'no spectrum estimate') > 0, &
                          'no estimate at the start: erk')
    k = findloc(events%method, 'mebdf', 1)
    call suite%check_true(k > 0, 'implicit once the problem is stiff: mebdf')
    if (k > 0) call suite%check_true(events(k)%max_order == 4, &
                                     'without an estimate, MEBDF at its A-stable order 4')
    call suite%check_close(y(1), cos(t), 1.0e-5_wp, 0.0_wp, 'y follows cos t')
    call suite%finish()
end program test_auto_start
