!> The energy monitor of a run (order safety, docs/theory/energy-balance.md): watches the energy balance
!! B = T + V + dissipated - external work at the output times and says when B has risen
!! above its start E0 by more than `factor` rtol S.
!!
!! Why: B equals E0 for the exact solution of every rope scene. An integrator that damps
!! numerically lowers B; one that amplifies a barely damped mode (BDF at orders 3-5, MEBDF
!! at orders 5-7: not A-stable) raises it, often where its error test does not look. A rise
!! beyond the integration error is therefore an instability, and it is cheap to see: the
!! models give the energies and the dissipated energy and work as quadratures.
!!
!! S is the energy the run moves around so far, as in `stability_metrics` (python): max T +
!! max elastic + (max - min) of the gravity energy + the energy dissipated (J), the part of
!! the elastic energy whose zero is arbitrary (energy_t%level: in water the buoyancy's, which
!! grows with the depth below the surface) counted with gravity, by its range (the python
!! study reads files without that part, and its scenes have no water); one accepted
!! step moves B by about rtol times the energies in play, so the bound rtol S follows the
!! tolerance. The monitor knows nothing of integrators: the run driver
!! (`ropedyn_run`) decides what a gain means (lower the order, stop), and may
!! `accept` a gain as the integration error of the run: gains are then counted from there.
!!
!! Whether a gain is the high order's (an instability) or the integration error is decided
!! by `high_order_to_blame` from the same interval integrated at both orders.
!!
!! A loss (`lost`) is measured against the energy the motion took in, I: the largest T + V +
!! dissipated over the records above the lowest gravity energy (E0 - min V for a rope
!! released from rest, plus the work put in). S counts that energy about twice (the kinetic
!! energy at its peak and the range of the gravity energy are the same energy at two
!! times): on the undamped paper rope S = 2.1 I and m g L = 2.7 I, and a loss of a quarter
!! of I went unsaid against a tenth of max(S, m g L).
!!
!! A runaway (`runaway`): B - E0 above a tenth of max(S, m g L), the gain accepted or not.
!! No tolerance makes that an integration error, and no lower order is left to cure it
!! when the driver sees it (erk and auto at rtol 0.3 on the paper's rope created 89 and 18
!! m g L over 30 s and ended with exit 0; docs/validation/order-safety.md, "Loose
!! tolerances"): the run fails. m g L (`floor`) keeps the first records of a rope released
!! from rest, where S is still small, from counting a tiny gain as one;
!! RUNAWAY_LEAST_SCALE keeps a rope at rest without gravity, whose energies are round-off.
module ropedyn_energy_monitor
    use ropedyn_kinds, only: wp, i8
    use ropedyn_rope_model, only: energy_t
    use ropedyn_text, only: int_text, significant_text
    implicit none
    private
    public :: energy_monitor_t, safety_record_t, high_order_to_blame, sudden_gain, loss_warning
    public :: look_budget, look_action, LOOK_LOWER, LOOK_KEEP, LOOK_NO_VERDICT, LOOK_FAIL

    !> the largest bound, as a share of S, whatever factor rtol is: at rtol 0.1 the default
    !! 10 rtol S would be S itself, and energy created and then dissipated raises S with the
    !! gain, so no gain ever passed (CVODE on the paper rope, n = 30, rtol 0.1, atol 1e-3:
    !! a gain of 975 J, 844 m g L, by 30 s with exit 0; capped, BDF2 from 0.3 s keeps 0.03
    !! m g L). A tenth of the energy moved is never an integration error a run may keep.
    real(wp), parameter :: MAX_BOUND_SHARE = 0.1_wp
    !> the least energy scale of a runaway, J: a rope at rest without gravity moves round-off
    !! (a weightless paper rope over 0.1 s: S = 2e-27 J, "created" 1e-27 J), and no rope
    !! this code is for moves less than a nanojoule in earnest
    real(wp), parameter :: RUNAWAY_LEAST_SCALE = 1.0e-9_wp
    !> the share of the bound a gain must have made in the last interval to be judged by a
    !! comparison with the safe order over that interval (high_order_to_blame)
    real(wp), parameter :: SUDDEN_SHARE = 0.5_wp
    !> The second look at a sudden gain: the safe order may take this many times the steps
    !! that the order in use took over the interval (at least SAFE_STEPS_MIN); more is a
    !! crawl (BDF2 at rtol 1e-11 took 20 .. 60 times BDF5's steps on every_effect_mpp_n7)
    integer(i8), parameter :: SAFE_STEPS_FACTOR = 20, SAFE_STEPS_MIN = 500

    !> What the second look decides (look_action)
    integer, parameter :: LOOK_LOWER = 1       !< on at the safe order, for good
    integer, parameter :: LOOK_KEEP = 2        !< the gain is the integration error: order kept
    integer, parameter :: LOOK_NO_VERDICT = 3  !< the safe order ran out of a capped budget
    integer, parameter :: LOOK_FAIL = 4        !< ... of the whole budget: the run fails

    type :: energy_monitor_t
        real(wp) :: e0 = 0.0_wp             !< B at the start, J
        real(wp) :: rtol = 0.0_wp           !< relative tolerance of the run
        real(wp) :: factor = 0.0_wp         !< the bound in units of rtol S
        real(wp) :: max_kinetic = 0.0_wp    !< J
        real(wp) :: max_elastic = 0.0_wp    !< of elastic - level, J
        real(wp) :: min_gravity = 0.0_wp    !< of gravity + level, J
        real(wp) :: max_gravity = 0.0_wp    !< of gravity + level, J
        real(wp) :: dissipated = 0.0_wp     !< |dissipated| at the last record, J
        !> the largest T + V + dissipated over the records, J (the intake's top; E0 plus the
        !! work put in so far, for the exact motion)
        real(wp) :: max_held = -huge(1.0_wp)
        real(wp) :: accepted = 0.0_wp       !< gain accepted as integration error, J
        real(wp) :: floor = 0.0_wp          !< the runaway's least scale (m g L), J
    contains
        procedure :: start => monitor_start
        procedure :: observe => monitor_observe
        procedure :: scale => monitor_scale
        procedure :: bound => monitor_bound
        procedure :: gain => monitor_gain
        procedure :: gained => monitor_gained
        procedure :: accept => monitor_accept
        procedure :: runaway_limit => monitor_runaway_limit
        procedure :: runaway => monitor_runaway
        procedure :: floored_scale => monitor_floored_scale
        procedure :: big_change => monitor_big_change
        procedure :: intake => monitor_intake
        procedure :: loss => monitor_loss
        procedure :: lost => monitor_lost
    end type energy_monitor_t

    !> What the order safety did in a run (docs/theory/energy-balance.md; times in s, < 0: never).
    type :: safety_record_t
        real(wp) :: energy_gain = 0.0_wp        !< the first gain beyond the bound, J
        real(wp) :: energy_gain_bound = 0.0_wp  !< ... and its bound, J
        real(wp) :: lowered_at = -1.0_wp        !< the order lowered from this record on
        integer :: order_before = 0             !< ... from this order limit
        integer :: order_after = 0              !< ... to the safe order
        !> a gain that lowering could not cure (at the safe order, or a method without one)
        real(wp) :: unresolved_at = -1.0_wp
        logical :: orderless = .false.          !< ... of a method without a safe order
        real(wp) :: kept_at = -1.0_wp           !< a gain judged the integration error
        integer :: kept_count = 0               !< ... how many
        character(len=:), allocatable :: kept_reason  !< ... why, the first time
        !> a second look ran out of its capped budget (no verdict): later looks get all
        logical :: crawled = .false.
    contains
        procedure :: alarm => record_alarm
        procedure :: lowered => record_lowered
        procedure :: unresolved => record_unresolved
        procedure :: kept => record_kept
    end type safety_record_t

contains

    !> A gain (J) beyond the bound (J): remembered if it is the first.
    pure subroutine record_alarm(self, gain, bound)
        class(safety_record_t), intent(inout) :: self
        real(wp), intent(in) :: gain, bound
        if (self%unresolved_at >= 0.0_wp .or. self%lowered_at >= 0.0_wp .or. &
            self%kept_at >= 0.0_wp) return
        self%energy_gain = gain
        self%energy_gain_bound = bound
    end subroutine record_alarm

    !> The order limit lowered from `from` to `to`, from the record at time t on.
    pure subroutine record_lowered(self, t, from, to)
        class(safety_record_t), intent(inout) :: self
        real(wp), intent(in) :: t
        integer, intent(in) :: from, to
        self%lowered_at = t
        self%order_before = from
        self%order_after = to
    end subroutine record_lowered

    !> A gain at time t that lowering cannot cure (`orderless`: the method has no order to
    !! lower, else it runs at its safe order): remembered if it is the first.
    pure subroutine record_unresolved(self, t, orderless)
        class(safety_record_t), intent(inout) :: self
        real(wp), intent(in) :: t
        logical, intent(in) :: orderless
        if (self%unresolved_at >= 0.0_wp) return
        self%unresolved_at = t
        self%orderless = orderless
    end subroutine record_unresolved

    !> The order kept at time t at a gain judged the integration error, for reason `why`.
    pure subroutine record_kept(self, t, why)
        class(safety_record_t), intent(inout) :: self
        real(wp), intent(in) :: t
        character(len=*), intent(in) :: why
        if (self%kept_at < 0.0_wp) then
            self%kept_at = t
            self%kept_reason = why
        end if
        self%kept_count = self%kept_count + 1
    end subroutine record_kept

    !> Whether a gain beyond `bound` (J) was made by the order in use, the interval since
    !! the previous record having been integrated again at the method's safe (A-stable)
    !! order; `change_high` and `change_safe` are the changes of B - E0 over it at the two
    !! orders (J).
    !! - A gain gathered over earlier intervals (this one made less than SUDDEN_SHARE of the
    !!   bound): the order's. An amplified mode grows slowly, record after record, while the
    !!   safe order's error over one interval may be the larger (BDF2's damping): no
    !!   comparison over one interval clears the order (ADAMS 12 on the undamped rope at
    !!   rtol 1e-3: +8e-5 J in the interval of the alarm against the trapezoidal rule's
    !!   -3.7e-4 J, then another bound of gain within 1.2 s).
    !! - A gain made in this interval: the order's when the safe order changed the balance
    !!   less over it; when the safe order changed it as much or more (a larger integration
    !!   error, often a loss), the gain is the integration error of the run at its
    !!   tolerance, not an instability (CVODE at rtol 1e-11 on every_effect_mpp_n7: +2.3e-9 J
    !!   at order 5 in its first interval, -4.1e-8 J at BDF2).
    pure logical function high_order_to_blame(change_high, change_safe, bound) result(yes)
        real(wp), intent(in) :: change_high, change_safe, bound
        yes = .not. sudden_gain(change_high, bound) .or. abs(change_safe) < abs(change_high)
    end function high_order_to_blame

    !> The step budget of the safe order's second look: `left`, the run's budget left, for
    !! a gain gathered over earlier intervals (lowered whatever it costs) or after a look
    !! without verdict (`crawled`); for a sudden gain SAFE_STEPS_FACTOR times the
    !! `steps_high` the order in use took over the interval (at least SAFE_STEPS_MIN).
    pure integer(i8) function look_budget(sudden, crawled, steps_high, left) result(budget)
        logical, intent(in) :: sudden, crawled
        integer(i8), intent(in) :: steps_high, left
        budget = left
        if (sudden .and. .not. crawled) &
            budget = min(left, max(SAFE_STEPS_MIN, SAFE_STEPS_FACTOR*steps_high))
    end function look_budget

    !> What the second look decides: the safe order `reached` the end of the interval
    !! (then `blame`, high_order_to_blame, decides), or it stopped on a signal
    !! (`interrupted`: the order kept, the run stops), or it ran out of its budget: with
    !! the capped one of a sudden gain's first look no verdict, with the whole one the run
    !! fails as any integration does.
    pure integer function look_action(reached, interrupted, sudden, crawled, blame) &
        result(action)
        logical, intent(in) :: reached, interrupted, sudden, crawled, blame
        if (reached) then
            action = merge(LOOK_LOWER, LOOK_KEEP, blame)
        else if (interrupted) then
            action = LOOK_KEEP
        else if (sudden .and. .not. crawled) then
            action = LOOK_NO_VERDICT
        else
            action = LOOK_FAIL
        end if
    end function look_action

    !> True when the last interval made SUDDEN_SHARE of the bound or more (see
    !! high_order_to_blame): only then does the safe order's run of that interval decide.
    pure logical function sudden_gain(change_high, bound) result(yes)
        real(wp), intent(in) :: change_high, bound
        yes = change_high >= SUDDEN_SHARE*bound
    end function sudden_gain

    !> Count gains from `gain` (J, a gain beyond the bound judged the integration error) on.
    pure subroutine monitor_accept(self, gain)
        class(energy_monitor_t), intent(inout) :: self
        real(wp), intent(in) :: gain
        self%accepted = max(self%accepted, gain)
    end subroutine monitor_accept

    !> Start from the energies of the initial state; `floor` (J, default 0): the least
    !! scale of a runaway, the rope's m g L.
    pure subroutine monitor_start(self, e, rtol, factor, floor)
        class(energy_monitor_t), intent(inout) :: self
        type(energy_t), intent(in) :: e
        real(wp), intent(in) :: rtol, factor
        real(wp), intent(in), optional :: floor
        self%e0 = e%balance()
        self%rtol = rtol
        self%factor = factor
        self%floor = 0.0_wp
        if (present(floor)) self%floor = max(0.0_wp, floor)
        self%accepted = 0.0_wp
        self%max_kinetic = e%kinetic
        self%max_elastic = e%elastic - e%level
        self%min_gravity = e%gravity + e%level
        self%max_gravity = e%gravity + e%level
        self%dissipated = abs(e%dissipated)
        self%max_held = e%total() + e%dissipated
    end subroutine monitor_start

    !> Take the energies of one more record into the scale S.
    pure subroutine monitor_observe(self, e)
        class(energy_monitor_t), intent(inout) :: self
        type(energy_t), intent(in) :: e
        self%max_kinetic = max(self%max_kinetic, e%kinetic)
        self%max_elastic = max(self%max_elastic, e%elastic - e%level)
        self%min_gravity = min(self%min_gravity, e%gravity + e%level)
        self%max_gravity = max(self%max_gravity, e%gravity + e%level)
        self%dissipated = abs(e%dissipated)
        self%max_held = max(self%max_held, e%total() + e%dissipated)
    end subroutine monitor_observe

    !> S, the energy scale so far (J).
    pure real(wp) function monitor_scale(self) result(s)
        class(energy_monitor_t), intent(in) :: self
        s = self%max_kinetic + self%max_elastic + (self%max_gravity - self%min_gravity) + &
            self%dissipated
    end function monitor_scale

    !> The gain that counts: factor rtol S, at most MAX_BOUND_SHARE S (J).
    pure real(wp) function monitor_bound(self) result(b)
        class(energy_monitor_t), intent(in) :: self
        b = min(self%factor*self%rtol, MAX_BOUND_SHARE)*self%scale()
    end function monitor_bound

    !> B - E0 of a state (J; positive: energy created).
    pure real(wp) function monitor_gain(self, e) result(g)
        class(energy_monitor_t), intent(in) :: self
        type(energy_t), intent(in) :: e
        g = e%balance() - self%e0
    end function monitor_gain

    !> True when a state's balance lies above E0 (and above the gain accepted) by more than
    !! the bound, with its energies counted into S first (so a record that itself moves much
    !! energy raises its own bound).
    pure logical function monitor_gained(self, e) result(yes)
        class(energy_monitor_t), intent(in) :: self
        type(energy_t), intent(in) :: e
        type(energy_monitor_t) :: next
        next = self
        call next%observe(e)
        yes = next%gain(e) - next%accepted > next%bound()
    end function monitor_gained

    !> The gain (J) above which a state's balance is a runaway: MAX_BOUND_SHARE max(S,
    !! floor, RUNAWAY_LEAST_SCALE), the state's energies counted into S first.
    pure real(wp) function monitor_runaway_limit(self, e) result(limit)
        class(energy_monitor_t), intent(in) :: self
        type(energy_t), intent(in) :: e
        type(energy_monitor_t) :: next
        next = self
        call next%observe(e)
        limit = next%big_change()
    end function monitor_runaway_limit

    !> max(S, floor, RUNAWAY_LEAST_SCALE), S as observed so far (J): the scale of a runaway.
    pure real(wp) function monitor_floored_scale(self) result(scale)
        class(energy_monitor_t), intent(in) :: self
        scale = max(self%scale(), self%floor, RUNAWAY_LEAST_SCALE)
    end function monitor_floored_scale

    !> A gain of B that no tolerance makes an integration error a run may keep (J):
    !! MAX_BOUND_SHARE times the floored scale; a gain that large fails the run (a runaway).
    pure real(wp) function monitor_big_change(self) result(limit)
        class(energy_monitor_t), intent(in) :: self
        limit = MAX_BOUND_SHARE*self%floored_scale()
    end function monitor_big_change

    !> I, the energy the motion took in so far (J): the largest T + V + dissipated over the
    !! records above the lowest gravity + level energy, at least RUNAWAY_LEAST_SCALE (a
    !! rope at rest without gravity).
    pure real(wp) function monitor_intake(self) result(intake)
        class(energy_monitor_t), intent(in) :: self
        intake = max(self%max_held - self%min_gravity, RUNAWAY_LEAST_SCALE)
    end function monitor_intake

    !> How far a state's balance has fallen below E0, J (negative: it rose).
    pure real(wp) function monitor_loss(self, e) result(loss)
        class(energy_monitor_t), intent(in) :: self
        type(energy_t), intent(in) :: e
        loss = self%e0 - e%balance()
    end function monitor_loss

    !> True when the balance of a state observed last has fallen below E0 by more than
    !! MAX_BOUND_SHARE of the intake: the integrator damped a tenth of the energy the motion
    !! took in (adaptive methods on a lightly damped rope over long runs;
    !! docs/theory/energy-balance.md).
    pure logical function monitor_lost(self, e) result(yes)
        class(energy_monitor_t), intent(in) :: self
        type(energy_t), intent(in) :: e
        yes = self%loss(e) > MAX_BOUND_SHARE*self%intake()
    end function monitor_lost

    !> The warning of a loss `lost` (J: `loss`) of the balance that `lost` found, `intake`
    !! (J) the energy the motion took in, at tolerance `rtol`: how much, of what, and what
    !! keeps it.
    function loss_warning(lost, intake, rtol) result(text)
        real(wp), intent(in) :: lost, intake, rtol
        character(len=:), allocatable :: text
        character(len=16) :: number
        write (number, '(es10.2)') lost
        text = 'the integration lost '//trim(adjustl(number))//' J of the balance, '// &
               int_text(nint(100*lost/intake))//' % of the '//significant_text(intake, 3)// &
               ' J the motion took in (the largest kinetic + elastic + gravity + '// &
               'dissipated above the lowest gravity energy): numerical damping at rtol '// &
               significant_text(rtol, 3)//'; a tighter rtol keeps more, and on a lightly '// &
               'damped RFEM rope method = ''symplectic'' keeps the balance '// &
               '(docs/guide/choosing.md)'
    end function loss_warning

    !> True when a state's B - E0 is above runaway_limit, whatever gain was accepted.
    pure logical function monitor_runaway(self, e) result(yes)
        class(energy_monitor_t), intent(in) :: self
        type(energy_t), intent(in) :: e
        yes = self%gain(e) > self%runaway_limit(e)
    end function monitor_runaway
end module ropedyn_energy_monitor
