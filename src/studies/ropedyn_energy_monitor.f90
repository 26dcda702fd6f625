!> The energy monitor of a run (order safety, docs/stability.md): watches the energy balance
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
!! max elastic + (max - min) of the gravity energy + the energy dissipated (J); one accepted
!! step moves B by about rtol times the energies in play, so the bound rtol S follows the
!! tolerance. The monitor knows nothing of integrators: the run driver
!! (`ropedyn_simulation`) decides what a gain means (lower the order, stop), on the rules of
!! `order_safety_t` below (orders as plain numbers).
module ropedyn_energy_monitor
    use ropedyn_kinds, only: wp
    use ropedyn_rope_model, only: energy_t
    implicit none
    private
    public :: energy_monitor_t, order_safety_t
    public :: SAFETY_KEEP, SAFETY_LOWER, SAFETY_RESTORE

    !> What the order safety does at a record whose gain is beyond the bound
    integer, parameter :: SAFETY_KEEP = 0     !< go on as it is (the gain is only reported)
    integer, parameter :: SAFETY_LOWER = 1    !< back to the previous record, on at the safe order
    integer, parameter :: SAFETY_RESTORE = 2  !< on from this record at the order asked for

    type :: energy_monitor_t
        real(wp) :: e0 = 0.0_wp             !< B at the start, J
        real(wp) :: rtol = 0.0_wp           !< relative tolerance of the run
        real(wp) :: factor = 0.0_wp         !< the bound in units of rtol S
        real(wp) :: max_kinetic = 0.0_wp    !< J
        real(wp) :: max_elastic = 0.0_wp    !< J
        real(wp) :: min_gravity = 0.0_wp    !< J
        real(wp) :: max_gravity = 0.0_wp    !< J
        real(wp) :: dissipated = 0.0_wp     !< |dissipated| at the last record, J
    contains
        procedure :: start => monitor_start
        procedure :: observe => monitor_observe
        procedure :: scale => monitor_scale
        procedure :: bound => monitor_bound
        procedure :: gain => monitor_gain
        procedure :: gained => monitor_gained
    end type energy_monitor_t

    !> The order safety's rules and what it did in a run (times in s, < 0: never). At a
    !! gain beyond the bound: lower the order limit to the method's safe (A-stable) order
    !! and integrate the interval again; if a gain is seen again at the safe order, it was
    !! not an order instability (the integration error of a scene with external work at a
    !! tight rtol): restore the order asked for, once, rather than stay at an order that may
    !! crawl; should the gain then grow by another bound, lowering was right after all:
    !! lower again, for good. A method without a safe order, or at it from the start, only
    !! reports the gain.
    type :: order_safety_t
        real(wp) :: lowered_at = -1.0_wp        !< first lowering, from this record
        integer :: order_before = 0             !< the order limit asked for
        integer :: order_after = 0              !< the safe order
        real(wp) :: unresolved_at = -1.0_wp     !< first gain at the safe order (or none)
        real(wp) :: restored_at = -1.0_wp       !< the order asked for restored
        real(wp) :: lowered_again_at = -1.0_wp  !< lowered again, for good
        real(wp) :: gain_restored = 0.0_wp      !< the gain when restored, J
    contains
        procedure :: action => safety_action
        procedure :: take => safety_take
    end type order_safety_t

contains

    !> The action at a record whose gain (J) is beyond the bound (J), the run being at
    !! order limit `max_order` of a method whose safe order is `safe_order` (0: none).
    pure integer function safety_action(self, gain, bound, max_order, safe_order) &
        result(action)
        class(order_safety_t), intent(in) :: self
        real(wp), intent(in) :: gain, bound
        integer, intent(in) :: max_order, safe_order
        action = SAFETY_KEEP
        if (safe_order > 0 .and. max_order > safe_order) then
            if (self%restored_at < 0.0_wp) then
                action = SAFETY_LOWER
            else if (self%lowered_again_at < 0.0_wp .and. &
                     gain > self%gain_restored + bound) then
                action = SAFETY_LOWER
            end if
        else if (self%lowered_at >= 0.0_wp .and. self%restored_at < 0.0_wp .and. &
                 max_order < self%order_before) then
            action = SAFETY_RESTORE
        end if
    end function safety_action

    !> Remember `action`, taken at the record at time t (the previous record at t_prev).
    pure subroutine safety_take(self, action, t_prev, t, gain, max_order, safe_order)
        class(order_safety_t), intent(inout) :: self
        integer, intent(in) :: action
        real(wp), intent(in) :: t_prev, t, gain
        integer, intent(in) :: max_order, safe_order
        select case (action)
        case (SAFETY_LOWER)
            if (self%restored_at < 0.0_wp) then
                self%lowered_at = t_prev
                self%order_before = max_order
                self%order_after = safe_order
            else
                self%lowered_again_at = t_prev
            end if
        case default
            if (self%unresolved_at < 0.0_wp) self%unresolved_at = t
            if (action == SAFETY_RESTORE) then
                self%restored_at = t
                self%gain_restored = gain
            end if
        end select
    end subroutine safety_take

    !> Start from the energies of the initial state.
    pure subroutine monitor_start(self, e, rtol, factor)
        class(energy_monitor_t), intent(inout) :: self
        type(energy_t), intent(in) :: e
        real(wp), intent(in) :: rtol, factor
        self%e0 = e%balance()
        self%rtol = rtol
        self%factor = factor
        self%max_kinetic = e%kinetic
        self%max_elastic = e%elastic
        self%min_gravity = e%gravity
        self%max_gravity = e%gravity
        self%dissipated = abs(e%dissipated)
    end subroutine monitor_start

    !> Take the energies of one more record into the scale S.
    pure subroutine monitor_observe(self, e)
        class(energy_monitor_t), intent(inout) :: self
        type(energy_t), intent(in) :: e
        self%max_kinetic = max(self%max_kinetic, e%kinetic)
        self%max_elastic = max(self%max_elastic, e%elastic)
        self%min_gravity = min(self%min_gravity, e%gravity)
        self%max_gravity = max(self%max_gravity, e%gravity)
        self%dissipated = abs(e%dissipated)
    end subroutine monitor_observe

    !> S, the energy scale so far (J).
    pure real(wp) function monitor_scale(self) result(s)
        class(energy_monitor_t), intent(in) :: self
        s = self%max_kinetic + self%max_elastic + (self%max_gravity - self%min_gravity) + &
            self%dissipated
    end function monitor_scale

    !> The gain that counts: factor rtol S (J).
    pure real(wp) function monitor_bound(self) result(b)
        class(energy_monitor_t), intent(in) :: self
        b = self%factor*self%rtol*self%scale()
    end function monitor_bound

    !> B - E0 of a state (J; positive: energy created).
    pure real(wp) function monitor_gain(self, e) result(g)
        class(energy_monitor_t), intent(in) :: self
        type(energy_t), intent(in) :: e
        g = e%balance() - self%e0
    end function monitor_gain

    !> True when a state's balance lies above E0 by more than the bound, with its energies
    !! counted into S first (so a record that itself moves much energy raises its own bound).
    pure logical function monitor_gained(self, e) result(yes)
        class(energy_monitor_t), intent(in) :: self
        type(energy_t), intent(in) :: e
        type(energy_monitor_t) :: next
        next = self
        call next%observe(e)
        yes = next%gain(e) > next%bound()
    end function monitor_gained
end module ropedyn_energy_monitor
