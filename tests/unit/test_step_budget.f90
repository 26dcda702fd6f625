!> The arithmetic of the step budget's messages (solvers/ropedyn_integrator.f90): the steps
!! the rest of a run takes at a step (steps_to_end: rounded up; none when the end is not
!! known), and the budget a message asks for (budget_covering: a tenth more, rounded up to
!! two significant digits), and the default budget of a run that names none
!! (default_step_budget: a floor, or a rate times the run's length). The messages themselves, end to end: tests/hard/
!! test_failure_path.py and tests/e2e/test_methods.py.
program test_step_budget
    use ropedyn_kinds, only: wp, i8
    use ropedyn_assert, only: test_suite_t
    use ropedyn_integrator, only: steps_to_end, budget_covering, default_step_budget, &
                                  DEFAULT_MAX_STEPS, BUDGET_STEP_RATE
    implicit none
    type(test_suite_t) :: suite

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
    call suite%finish()
end program test_step_budget
