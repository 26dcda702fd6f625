!> The energy monitor of the order safety (src/studies/ropedyn_energy_monitor.f90), on
!! energies made up by hand:
!! - S is max T + max elastic + gravity range + |dissipated| over the records seen, as
!!   stability_metrics.analyse computes it from a file (python);
!! - the gain is B - E0 with B = T + V + dissipated - work (external work counted: a support
!!   that feeds energy in is no gain);
!! - `gained` is true exactly above factor rtol S, with the record's own energies in S, and
!!   does not change the monitor (only `observe` does);
!! - losses (numerical damping) never count.
!! - the order safety's rules (order_safety_t) over a run: lower at the first gain; a gain
!!   again at the safe order restores the order asked for, once; after that a gain that
!!   grew by another bound lowers for good, a smaller one is only reported; a method
!!   without a safe order, or at it from the start, only reports.
!! The end-to-end part (the order lowered at a gain, 'stop', the HDF5 record, the restore
!! on every_effect_mpp_n7) is tests/hard/test_order_safety.py; the long runs tests/long.
program test_energy_monitor
    use ropedyn_kinds, only: wp
    use ropedyn_rope_model, only: energy_t
    use ropedyn_energy_monitor, only: energy_monitor_t, order_safety_t, SAFETY_KEEP, &
                                      SAFETY_LOWER, SAFETY_RESTORE
    use ropedyn_assert, only: test_suite_t
    implicit none

    type(test_suite_t) :: suite
    type(energy_monitor_t) :: m
    type(energy_t) :: e0, e1, e2
    type(order_safety_t) :: safety
    integer :: action
    real(wp) :: x
    real(wp), parameter :: rtol = 1.0e-4_wp, factor = 10.0_wp

    suite%name = 'energy_monitor'
    ! start: hanging at rest, some elastic energy, gravity -1 J
    e0 = energy_t(kinetic=0.0_wp, elastic=0.1_wp, gravity=-1.0_wp, dissipated=0.0_wp, &
                  support_work=0.0_wp)
    call m%start(e0, rtol, factor)
    call suite%check_close(m%scale(), 0.1_wp, 1.0e-15_wp, 0.0_wp, 'S at the start')
    call suite%check_close(m%e0, -0.9_wp, 1.0e-15_wp, 0.0_wp, 'E0 = T + V + D - W')

    ! swinging: 0.5 J kinetic from 0.5 J of gravity, 0.01 J dissipated: S = 0.5 + 0.1 + 0.51
    ! + 0.01, balance exactly E0
    e1 = energy_t(kinetic=0.5_wp, elastic=0.1_wp, gravity=-1.51_wp, dissipated=0.01_wp, &
                  support_work=0.0_wp)
    call suite%check_true(.not. m%gained(e1), 'an exact balance is no gain')
    call suite%check_close(m%scale(), 0.1_wp, 1.0e-15_wp, 0.0_wp, 'gained does not observe')
    call m%observe(e1)
    call suite%check_close(m%scale(), 1.12_wp, 1.0e-14_wp, 0.0_wp, 'S after a record')
    call suite%check_close(m%bound(), factor*rtol*1.12_wp, 1.0e-14_wp, 0.0_wp, 'bound')

    ! a gain x in the dissipated energy alone: S = 1.12 + x, so it counts from
    ! x* = factor rtol 1.12 / (1 - factor rtol) on
    x = factor*rtol*1.12_wp/(1.0_wp - factor*rtol)
    e2 = e1
    e2%dissipated = e1%dissipated + 0.99_wp*x
    call suite%check_true(.not. m%gained(e2), 'a gain below the bound')
    e2%dissipated = e1%dissipated + 1.01_wp*x
    call suite%check_true(m%gained(e2), 'a gain above the bound')
    call suite%check_close(m%gain(e2), 1.01_wp*x, 1.0e-10_wp, 0.0_wp, 'gain = B - E0')

    ! numerical damping: a large loss is never a gain
    e2 = e1
    e2%kinetic = 0.0_wp
    call suite%check_true(.not. m%gained(e2), 'a loss is no gain')
    call suite%check_true(m%gain(e2) < 0.0_wp, 'a loss is negative')

    ! external work: the support did 2 J, the rope has them: no gain
    e2 = e1
    e2%kinetic = e1%kinetic + 2.0_wp
    e2%support_work = 2.0_wp
    call suite%check_true(.not. m%gained(e2), 'work done on the rope is no gain')
    ! ... but 2 J of kinetic energy without the work is
    e2%support_work = 0.0_wp
    call suite%check_true(m%gained(e2), 'energy from nowhere is a gain')

    ! the gravity range counts into S, not the gravity energy itself (its zero is arbitrary)
    call m%start(energy_t(kinetic=0.0_wp, elastic=0.0_wp, gravity=-100.0_wp, &
                          dissipated=0.0_wp, support_work=0.0_wp), rtol, factor)
    call suite%check_close(m%scale(), 0.0_wp, 0.0_wp, 1.0e-300_wp, 'gravity zero arbitrary')

    ! the order safety over a run: CVODE (safe order 2) asked for order 5, bound 1 J
    action = safety%action(2.0_wp, 1.0_wp, 5, 2)
    call suite%check_true(action == SAFETY_LOWER, 'a first gain lowers')
    call safety%take(action, 0.1_wp, 0.2_wp, 2.0_wp, 5, 2)
    call suite%check_close(safety%lowered_at, 0.1_wp, 0.0_wp, 0.0_wp, 'lowered from t_prev')
    call suite%check_true(safety%order_before == 5 .and. safety%order_after == 2, &
                          'orders before and after')
    action = safety%action(2.5_wp, 1.0_wp, 2, 2)
    call suite%check_true(action == SAFETY_RESTORE, 'a gain at the safe order restores')
    call safety%take(action, 0.3_wp, 0.4_wp, 2.5_wp, 2, 2)
    call suite%check_close(safety%restored_at, 0.4_wp, 0.0_wp, 0.0_wp, 'restored at t')
    call suite%check_close(safety%unresolved_at, 0.4_wp, 0.0_wp, 0.0_wp, 'reported at t')
    action = safety%action(3.4_wp, 1.0_wp, 5, 2)
    call suite%check_true(action == SAFETY_KEEP, 'after a restore: less than another bound')
    call safety%take(action, 0.5_wp, 0.6_wp, 3.4_wp, 5, 2)
    call suite%check_true(safety%lowered_again_at < 0.0_wp, 'not lowered again')
    action = safety%action(3.6_wp, 1.0_wp, 5, 2)
    call suite%check_true(action == SAFETY_LOWER, 'after a restore: another bound lowers')
    call safety%take(action, 0.7_wp, 0.8_wp, 3.6_wp, 5, 2)
    call suite%check_close(safety%lowered_again_at, 0.7_wp, 0.0_wp, 0.0_wp, 'lowered again')
    call suite%check_close(safety%lowered_at, 0.1_wp, 0.0_wp, 0.0_wp, 'first lowering kept')
    action = safety%action(9.0_wp, 1.0_wp, 2, 2)
    call suite%check_true(action == SAFETY_KEEP, 'lowered again: for good')
    ! at the safe order from the start (or no safe order): only reported
    safety = order_safety_t()
    action = safety%action(2.0_wp, 1.0_wp, 2, 2)
    call suite%check_true(action == SAFETY_KEEP, 'at the safe order from the start')
    call safety%take(action, 0.1_wp, 0.2_wp, 2.0_wp, 2, 2)
    call suite%check_close(safety%unresolved_at, 0.2_wp, 0.0_wp, 0.0_wp, 'reported')
    call suite%check_true(safety%action(5.0_wp, 1.0_wp, 2, 2) == SAFETY_KEEP, 'never restores')
    safety = order_safety_t()
    call suite%check_true(safety%action(2.0_wp, 1.0_wp, 12, 0) == SAFETY_KEEP, 'no safe order')
    call suite%finish()
end program test_energy_monitor
