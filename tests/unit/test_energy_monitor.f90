!> The energy monitor of the order safety (src/studies/ropedyn_energy_monitor.f90), on
!! energies made up by hand:
!! - S is max T + max elastic + gravity range + |dissipated| over the records seen, as
!!   stability_metrics.analyse computes it from a file (python);
!! - the gain is B - E0 with B = T + V + dissipated - work (external work counted: a support
!!   that feeds energy in is no gain);
!! - `gained` is true exactly above factor rtol S (at most S / 10), with the record's own
!!   energies in S, and does not change the monitor (only `observe` does);
!! - losses (numerical damping) never count;
!! - a gain accepted as integration error is counted from: the next alarm is a bound above
!!   it (and accepting never lowers the level);
!! - `high_order_to_blame`: the order in use made a gain gathered over earlier intervals
!!   (less than half the bound in the last one) whatever the safe order did; a gain of the
!!   last interval exactly when the safe order, over the same interval, changed the balance
!!   less (a gain or a loss alike);
!! - a runaway: B - E0 above a tenth of max(S, m g L), whatever was accepted;
!! - a loss is `lost` (the run summary's warning) beyond a tenth of the intake I, the
!!   largest T + V + dissipated over the records above the lowest gravity energy (not S,
!!   which counts a fall's energy as kinetic and again as gravity; nor floored by m g L),
!!   work put in by a support counted into I;
!! - the second look's budget (20 times the interval's steps, at least 500, for a sudden
!!   gain's first look; else all that is left) and its action in every case (lower, keep,
!!   no verdict once, the run's failure).
!! The end-to-end part (the order lowered at a gain, 'stop', the HDF5 record) is
!! tests/hard/test_order_safety.py; the long runs tests/long.
program test_energy_monitor
    use ropedyn_kinds, only: wp, i8
    use ropedyn_rope_model, only: energy_t
    use ropedyn_energy_monitor, only: energy_monitor_t, high_order_to_blame, sudden_gain, &
                                      look_budget, look_action, LOOK_LOWER, LOOK_KEEP, &
                                      LOOK_NO_VERDICT, LOOK_FAIL
    use ropedyn_assert, only: test_suite_t
    implicit none

    type(test_suite_t) :: suite
    type(energy_monitor_t) :: m
    type(energy_t) :: e0, e1, e2
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

    ! accepted: a gain of 1.01 x* taken as the integration error; the next alarm is one
    ! bound above it (the bound of a record with that dissipation in S)
    e2 = e1
    e2%dissipated = e1%dissipated + 1.01_wp*x
    call m%accept(m%gain(e2))
    call suite%check_true(.not. m%gained(e2), 'an accepted gain is no alarm')
    e2%dissipated = e1%dissipated + 1.99_wp*x
    call suite%check_true(.not. m%gained(e2), 'below a bound above the accepted gain')
    e2%dissipated = e1%dissipated + 2.03_wp*x
    call suite%check_true(m%gained(e2), 'a bound above the accepted gain')
    call m%accept(0.0_wp)
    call suite%check_true(m%gained(e2), 'accepting less keeps the level')

    ! who made the gain: the change of B - E0 over the interval at each order, bound 1e-3
    call suite%check_true(high_order_to_blame(2.0e-3_wp, 1.0e-4_wp, 1.0e-3_wp), &
                          'the safe order gains less: the high order made it')
    call suite%check_true(high_order_to_blame(2.0e-3_wp, -1.0e-4_wp, 1.0e-3_wp), &
                          'the safe order loses less: the high order made it')
    call suite%check_true(.not. high_order_to_blame(2.0e-3_wp, -4.0e-3_wp, 1.0e-3_wp), &
                          'the safe order loses more: integration error')
    call suite%check_true(.not. high_order_to_blame(1.0e-3_wp, 1.0e-3_wp, 1.0e-3_wp), &
                          'the same change: integration error')
    call suite%check_true(.not. high_order_to_blame(0.5e-3_wp, -4.0e-3_wp, 1.0e-3_wp), &
                          'half the bound in the interval is sudden')
    call suite%check_true(high_order_to_blame(0.49e-3_wp, -4.0e-3_wp, 1.0e-3_wp), &
                          'a gain gathered before: the order, however the safe one does')
    call suite%check_true(sudden_gain(0.5e-3_wp, 1.0e-3_wp) .and. &
                          .not. sudden_gain(0.49e-3_wp, 1.0e-3_wp), 'sudden from half')

    ! the second look's budget: capped for a sudden gain's first look, else all that is left
    call suite%check_true(look_budget(.true., .false., 3076_i8, 10**6_i8) == 61520_i8, &
                          'budget: 20 times the steps of the interval')
    call suite%check_true(look_budget(.true., .false., 3_i8, 10**6_i8) == 500_i8, &
                          'budget: at least 500')
    call suite%check_true(look_budget(.true., .false., 3076_i8, 1000_i8) == 1000_i8, &
                          'budget: no more than is left')
    call suite%check_true(look_budget(.false., .false., 3076_i8, 10**6_i8) == 10**6_i8, &
                          'budget: a gathered gain gets all that is left')
    call suite%check_true(look_budget(.true., .true., 3076_i8, 10**6_i8) == 10**6_i8, &
                          'budget: after a look without verdict, all that is left')
    ! ... and its action
    call suite%check_true(look_action(.true., .false., .true., .false., .true.) == LOOK_LOWER, &
                          'reached, the order to blame: lower')
    call suite%check_true(look_action(.true., .false., .true., .false., .false.) == LOOK_KEEP, &
                          'reached, integration error: keep')
    call suite%check_true(look_action(.false., .true., .true., .false., .true.) == LOOK_KEEP, &
                          'interrupted: keep (the run stops)')
    call suite%check_true(look_action(.false., .false., .true., .false., .true.) == &
                          LOOK_NO_VERDICT, 'a sudden gain, capped budget run out: no verdict')
    call suite%check_true(look_action(.false., .false., .true., .true., .true.) == LOOK_FAIL, &
                          'after a look without verdict: the safe order fails the run')
    call suite%check_true(look_action(.false., .false., .false., .false., .true.) == LOOK_FAIL, &
                          'a gathered gain: the safe order fails the run')

    ! the gravity range counts into S, not the gravity energy itself (its zero is arbitrary)
    call m%start(energy_t(kinetic=0.0_wp, elastic=0.0_wp, gravity=-100.0_wp, &
                          dissipated=0.0_wp, support_work=0.0_wp), rtol, factor)
    call suite%check_close(m%scale(), 0.0_wp, 0.0_wp, 1.0e-300_wp, 'gravity zero arbitrary')

    ! the level part of the elastic energy (in water the buoyancy's potential, which grows
    ! with the depth below the surface) counts with gravity, by its range: the records of
    ! 'S after a record' 1000 m deeper (level and elastic raised alike) give the same S and I
    e2 = e0
    e2%elastic = e0%elastic + 1000.0_wp
    e2%level = 1000.0_wp
    call m%start(e2, rtol, factor)
    e2 = e1
    e2%elastic = e1%elastic + 1000.0_wp
    e2%level = 1000.0_wp
    call m%observe(e2)
    call suite%check_close(m%scale(), 1.12_wp, 1.0e-10_wp, 0.0_wp, 'S: the level by its range')
    x = m%intake()
    call m%start(e0, rtol, factor)
    call m%observe(e1)
    call suite%check_close(x, m%intake(), 1.0e-10_wp, 0.0_wp, 'I: the level by its range')

    ! at a loose tolerance the bound is at most a tenth of S: energy created and then
    ! dissipated raises S with it, and 10 rtol S at rtol 0.1 (S itself) would never be passed
    call m%start(e0, 0.1_wp, factor)
    call m%observe(e1)
    call suite%check_close(m%bound(), 0.1_wp*1.12_wp, 1.0e-14_wp, 0.0_wp, &
                           'the bound at rtol 0.1 is a tenth of S')
    e2 = e1
    e2%dissipated = e1%dissipated + 5.0_wp
    call suite%check_true(m%gained(e2), 'a runaway in the dissipated energy is a gain, '// &
                          'however loose the tolerance')

    ! a runaway: B - E0 above a tenth of max(S, m g L), counted with the record's energies
    ! in S, whatever gain was accepted. S = 1.12 J after e1; with the dissipated energy
    ! raised by y, S = 1.12 + y and the limit y* = 0.112 / 0.9
    x = 0.1_wp*1.12_wp/0.9_wp
    e2 = e1
    e2%dissipated = e1%dissipated + 0.99_wp*x
    call suite%check_true(.not. m%runaway(e2), 'no runaway below a tenth of S')
    call suite%check_close(m%runaway_limit(e2), 0.1_wp*(1.12_wp + 0.99_wp*x), 1.0e-14_wp, &
                           0.0_wp, 'the runaway limit counts the record into S')
    e2%dissipated = e1%dissipated + 1.01_wp*x
    call suite%check_true(m%runaway(e2), 'a runaway above a tenth of S')
    call m%accept(10.0_wp)
    call suite%check_true(m%runaway(e2), 'an accepted gain is still a runaway')
    ! released from rest, S is small at first: m g L is the least scale
    call m%start(e0, 0.1_wp, factor, floor=2.0_wp)
    e2 = e0
    e2%kinetic = 0.15_wp                       ! from nowhere: S = 0.25, gain 0.15
    call suite%check_true(m%gained(e2), 'a gain beyond the bound of a small S')
    call suite%check_true(.not. m%runaway(e2), 'below a tenth of m g L: no runaway')
    call suite%check_close(m%runaway_limit(e2), 0.2_wp, 1.0e-15_wp, 0.0_wp, &
                           'the limit is a tenth of m g L while S is smaller')
    e2%kinetic = 0.21_wp
    call suite%check_true(m%runaway(e2), 'above a tenth of m g L: a runaway')
    call m%accept(10.0_wp)
    call m%start(e0, 0.1_wp, factor)
    call suite%check_true(m%runaway(e2), 'without m g L, S alone')
    call suite%check_true(m%gained(e2), 'a restart forgets the accepted gain')

    ! a loss of more than a tenth of the intake I is `lost` (the summary warns), a gain or a
    ! smaller loss not. After e1, I = max(T + V + D) - min(gravity) = -0.9 + 1.51 = 0.61 J:
    ! the fall's 0.51 J and the elastic 0.1 J (S = 1.12 J counts the 0.5 J twice); m g L
    ! (20 J here) does not floor it. The kinetic energy of e1 falls by y, B by y, I stays
    call m%start(e0, 0.1_wp, factor, floor=20.0_wp)
    call m%observe(e1)
    call suite%check_close(m%intake(), 0.61_wp, 1.0e-14_wp, 0.0_wp, 'I after a record')
    e2 = e1
    e2%kinetic = e1%kinetic - 0.99_wp*0.061_wp
    call suite%check_true(.not. m%lost(e2), 'a loss below a tenth of I is not lost')
    e2%kinetic = e1%kinetic - 1.01_wp*0.061_wp
    call suite%check_true(m%lost(e2), 'a loss above a tenth of I (a twentieth of S) is lost')
    ! the loss the summary reports is the one judged: from the balance at the start
    call suite%check_close(m%loss(e2), e0%balance() - e2%balance(), 1.0e-14_wp, 0.0_wp, &
                           'the loss is E0 - B')
    e2%kinetic = e1%kinetic + 0.05_wp
    call suite%check_true(.not. m%lost(e2), 'a gain is not lost')
    ! a support that puts 1 J in (kinetic and work both up by 1 J, B unchanged) raises I by
    ! 1 J, and a later loss counts against the larger I
    e2 = e1
    e2%kinetic = e1%kinetic + 1.0_wp
    e2%support_work = 1.0_wp
    call m%observe(e2)
    call suite%check_close(m%intake(), 1.61_wp, 1.0e-14_wp, 0.0_wp, 'I counts work put in')
    e2%kinetic = e2%kinetic - 0.99_wp*0.161_wp
    call suite%check_true(.not. m%lost(e2), 'below a tenth of the larger I: not lost')
    e2%kinetic = e2%kinetic - 0.03_wp*0.161_wp
    call suite%check_true(m%lost(e2), 'above it: lost')

    ! without gravity, at rest: energies of round-off (S = 2e-27 J) are no runaway
    e2 = energy_t(kinetic=0.0_wp, elastic=9.0e-28_wp, gravity=0.0_wp, dissipated=0.0_wp, &
                  support_work=0.0_wp)
    call m%start(e2, 1.0e-6_wp, factor)
    e2%elastic = 2.1e-27_wp
    call suite%check_true(.not. m%runaway(e2), 'round-off at rest is no runaway')
    e2%kinetic = 1.0e-9_wp
    call suite%check_true(m%runaway(e2), 'a nanojoule from nothing is one')
    call suite%finish()
end program test_energy_monitor
