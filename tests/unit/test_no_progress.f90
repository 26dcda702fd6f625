!> Every integrator ends, with an error that says so, when its step cannot advance t: a
!! step below the round-off of t (t + h == t). Two ways to get there: a start at t0 = 1e16
!! (the round-off of t is 2 s, any step of a 1 rad/s oscillator is below it) and a very
!! fast oscillator (w = 1e20 rad/s: a stable explicit step of 1e-20 s at t0 = 1). `auto`
!! used to loop for ever in both: its look-ahead t + 0.25 WINDOW h rounded back to t, so
!! erk was asked to advance by nothing, took no step and never reached its own round-off
!! check or the stop request. A hang shows as this test's timeout.
program test_no_progress
    use ropedyn_kinds, only: wp, i8
    use ropedyn_error, only: error_t, ERR_SOLVER
    use ropedyn_integrator, only: integrator_t, solver_options_t
    use ropedyn_solvers, only: new_integrator
    use ropedyn_assert, only: test_suite_t
    use ropedyn_test_oscillator, only: oscillator_t
    implicit none

    character(len=*), parameter :: METHOD_LIST(5) = [character(len=5) :: 'auto', 'erk', &
        'mebdf', 'cvode', 'adams']
    type(test_suite_t) :: suite
    integer :: k

    suite%name = 'no_progress'
    do k = 1, size(METHOD_LIST)
        call no_progress(trim(METHOD_LIST(k)), 1.0_wp, 1.0e16_wp, 'late start')
        call no_progress(trim(METHOD_LIST(k)), 1.0e20_wp, 1.0_wp, 'fast oscillator')
    end do
    call suite%finish()

contains

    !> Integrate y'' = -w^2 y from t0 over 10 s: the integrator must return an ERR_SOLVER
    !! error naming the round-off, with t where it stopped (t0: no step advanced t).
    subroutine no_progress(method, w, t0, what)
        character(len=*), intent(in) :: method, what
        real(wp), intent(in) :: w, t0
        class(integrator_t), allocatable :: integrator
        type(oscillator_t), target :: problem
        type(solver_options_t) :: options
        type(error_t), allocatable :: err
        real(wp) :: y(2), yq(0), t
        character(len=:), allocatable :: label
        label = method//', '//what
        problem%w = w
        y = [1.0e-3_wp, 0.0_wp]
        options%rtol = 1.0e-6_wp
        options%atol = 1.0e-9_wp
        options%max_steps = 100000_i8
        call new_integrator(method, integrator, err)
        call suite%check_true(.not. allocated(err), label//': created')
        if (allocated(err)) return
        call integrator%init(problem, t0, y, yq, options, err)
        call suite%check_true(.not. allocated(err), label//': started')
        if (allocated(err)) return
        call integrator%advance_to(t0 + 10.0_wp, t, y, yq, err)
        call suite%check_true(allocated(err), label//': ends with an error')
        if (.not. allocated(err)) return
        call suite%check_true(err%code == ERR_SOLVER, label//': a failed integration')
        call suite%check_contains(err%message, 'round-off', label//': says why')
        call suite%check_true(t >= t0 .and. t < t0 + 10.0_wp, label//': t where it stopped')
        call integrator%finalize()
    end subroutine no_progress
end program test_no_progress
