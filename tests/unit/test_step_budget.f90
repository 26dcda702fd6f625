!> The arithmetic of the step budget's messages (solvers/ropedyn_integrator.f90): the steps
!! the rest of a run takes at a step (steps_to_end: rounded up; none when the end is not
!! known), and the budget a message asks for (budget_covering: a tenth more, rounded up to
!! two significant digits), and the default budget of a run that names none
!! (default_step_budget: a floor, or a rate times the run's length). And the budget an
!! integrator started again within a run names (budget_left: a run's restart, auto's next
!! method): the whole budget, not what was left of it, and in a simulation driven by its
!! caller the steps since its start, not the rest of a run to t_end. (Checked by breaking
!! it: with the old message, the budget left, 20, and the rest of the run in a simulation.)
!! The messages themselves, end to end: tests/hard/test_failure_path.py,
!! tests/e2e/test_methods.py and tests/e2e/test_python_api.py.
program test_step_budget
    use ropedyn_kinds, only: wp, i8
    use ropedyn_assert, only: test_suite_t
    use ropedyn_error, only: error_t
    use ropedyn_integrator, only: steps_to_end, budget_covering, default_step_budget, &
                                  DEFAULT_MAX_STEPS, BUDGET_STEP_RATE, integrator_t, &
                                  solver_options_t, budget_left
    use ropedyn_solvers, only: new_integrator
    use ropedyn_test_oscillator, only: oscillator_t
    implicit none
    type(test_suite_t) :: suite
    character(len=5), parameter :: NAMES(3) = ['erk  ', 'mebdf', 'auto ']
    integer :: m

    suite%name = 'step_budget'
    call suite%check_true(steps_to_end(0.0_wp, 1.0_wp, 0.25_wp) == 4_i8, &
                          'steps_to_end: a whole number of steps')
    call suite%check_true(steps_to_end(0.0_wp, 1.0_wp, 0.3_wp) == 4_i8, &
                          'steps_to_end: rounded up')
    call suite%check_true(steps_to_end(1.0_wp, 300.0_wp, 2.778e-4_wp) == 1076314_i8, &
                          'steps_to_end: from t to t_end')
    call suite%check_true(steps_to_end(0.0_wp, huge(1.0_wp), 1.0e-3_wp) == 0_i8, &
                          'steps_to_end: the end not known')
    call suite%check_true(steps_to_end(0.0_wp, 1.0_wp, 0.0_wp) == 0_i8, &
                          'steps_to_end: no step')
    call suite%check_true(steps_to_end(2.0_wp, 1.0_wp, 0.1_wp) == 0_i8, &
                          'steps_to_end: past the end')
    call suite%check_true(budget_covering(1083000_i8) == 1200000_i8, &
                          'budget_covering: 1.1 x 1083000 up to two digits')
    call suite%check_true(budget_covering(284_i8) == 320_i8, &
                          'budget_covering: 1.1 x 284 = 312.4 -> 320')
    call suite%check_true(budget_covering(1000_i8) == 1100_i8, &
                          'budget_covering: 1100 exactly stays')
    call suite%check_true(budget_covering(5_i8) == 6_i8, 'budget_covering: small counts')
    call suite%check_true(budget_covering(0_i8) == 0_i8, 'budget_covering: none')
    call suite%check_true(default_step_budget(10.0_wp) == int(DEFAULT_MAX_STEPS, i8), &
                          'default_step_budget: a short run has the floor')
    call suite%check_true(default_step_budget(300.0_wp) == nint(300.0_wp*BUDGET_STEP_RATE, i8), &
                          'default_step_budget: a long run has the rate times its length')
    call suite%check_true(default_step_budget(300.0_wp) >= 1200000_i8, &
                          'default_step_budget: covers the symplectic method on the '// &
                          'undamped paper rope over 300 s (1,078,797 steps and a tenth)')
    call suite%check_true(default_step_budget(1.0e300_wp) > 0_i8, &
                          'default_step_budget: no overflow')
    do m = 1, size(NAMES)
        call check_restarted(trim(NAMES(m)))
    end do
    call suite%finish()

contains

    !> Method `name` started within a budget of 50 steps after 30 of them (budget_left): a
    !! run's message names the budget 50 and the rest of the run; a simulation's (driven)
    !! the budget 50, the 50 steps it took, and solver.max_steps.
    subroutine check_restarted(name)
        character(len=*), intent(in) :: name
        type(oscillator_t), target :: p
        class(integrator_t), allocatable :: integ
        type(solver_options_t) :: outer, options
        type(error_t), allocatable :: err
        real(wp) :: y(2), yq(0), t
        integer :: k
        outer%max_steps = 50
        outer%t_end = 100.0_wp
        options = budget_left(outer, 30_i8)
        call suite%check_true(options%max_steps == 20_i8, name//': budget_left: 20 left')
        do k = 1, 2
            options%driven = k == 2
            call new_integrator(name, integ, err)
            if (allocated(err)) exit
            y = [1.0_wp, 0.0_wp]
            call integ%init(p, 0.0_wp, y, yq, options, err)
            if (allocated(err)) exit
            call integ%advance_to(100.0_wp, t, y, yq, err)
            call suite%check_true(allocated(err), name//': the budget runs out')
            if (.not. allocated(err)) return
            if (k == 1) then
                call suite%check_contains(err%message, 'max_steps exceeded (50 steps); at '// &
                    'the size of the last accepted step', name//': a run names its budget')
                call suite%check_contains(err%message, 'the rest of the run, to t = 100.0 s', &
                                          name//': a run names its end')
            else
                call suite%check_contains(err%message, 'max_steps exceeded (50 steps): the '// &
                    'budget of the whole simulation, which has taken 50 steps since it '// &
                    'started', name//': a simulation names its budget and its steps')
                call suite%check_contains(err%message, 'needs a larger solver.max_steps '// &
                    'in its scene', name//': a simulation names the key')
                call suite%check_true(index(err%message, 'rest of the run') == 0, &
                                      name//': a simulation has no rest of a run')
            end if
            deallocate (err)
            call integ%finalize()
        end do
        if (allocated(err)) call suite%check_true(.false., name//': '//err%message)
    end subroutine check_restarted
end program test_step_budget
