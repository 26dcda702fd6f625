!> The record of what an integrator changed during a run: which method it ran from when,
!! with which order limit, and why (`method = 'auto'` switching between an explicit and an
!! implicit integrator, CVODE lowering and restoring its maximum order). The run driver
!! writes it to `/solver/switch_*` and prints it in the run summary (docs/reference/file-format.md).
module ropedyn_switch_log
    use ropedyn_kinds, only: wp
    implicit none
    private
    public :: switch_event_t, switch_log_t, merged_events

    !> One change: from time t on, `method` runs with order limit `max_order`.
    type :: switch_event_t
        real(wp) :: t = 0.0_wp                   !< s
        character(len=16) :: method = ''         !< the integrator in use from t on
        integer :: max_order = 0                 !< its order limit from t on
        character(len=:), allocatable :: reason  !< why, for people
        !> the user should be told while the run goes on (printed once on stderr)
        logical :: warning = .false.
    end type switch_event_t

    !> A growing list of events.
    type :: switch_log_t
        type(switch_event_t), allocatable :: events(:)
        integer :: count = 0
    contains
        procedure :: add => log_add
        procedure :: add_all => log_add_all
        procedure :: items => log_items
        procedure :: clear => log_clear
    end type switch_log_t

contains

    subroutine log_add(self, t, method, max_order, reason, warning)
        class(switch_log_t), intent(inout) :: self
        real(wp), intent(in) :: t
        character(len=*), intent(in) :: method
        integer, intent(in) :: max_order
        character(len=*), intent(in) :: reason
        logical, intent(in), optional :: warning
        type(switch_event_t), allocatable :: grown(:)
        if (.not. allocated(self%events)) allocate (self%events(8))
        if (self%count == size(self%events)) then
            allocate (grown(2*size(self%events)))
            grown(1:self%count) = self%events(1:self%count)
            call move_alloc(grown, self%events)
        end if
        self%count = self%count + 1
        associate (e => self%events(self%count))
            e%t = t
            e%method = method
            e%max_order = max_order
            e%reason = reason
            e%warning = .false.
            if (present(warning)) e%warning = warning
        end associate
    end subroutine log_add

    !> Events of another log appended, in their order.
    subroutine log_add_all(self, events)
        class(switch_log_t), intent(inout) :: self
        type(switch_event_t), intent(in) :: events(:)
        integer :: k
        do k = 1, size(events)
            call self%add(events(k)%t, events(k)%method, events(k)%max_order, &
                          events(k)%reason, events(k)%warning)
        end do
    end subroutine log_add_all

    !> The events so far, oldest first.
    function log_items(self) result(events)
        class(switch_log_t), intent(in) :: self
        type(switch_event_t), allocatable :: events(:)
        if (self%count == 0) then
            allocate (events(0))
        else
            events = self%events(1:self%count)
        end if
    end function log_items

    !> The events of two logs, each oldest first, as one in time order: auto's switches (a)
    !! and the events of a method it ran (b). At the same time a's event comes first when it
    !! names the same method (auto's switch to it, then the method's own start), else b's
    !! (the method's last event, then auto's switch away from it).
    function merged_events(a, b) result(events)
        type(switch_event_t), intent(in) :: a(:), b(:)
        type(switch_event_t), allocatable :: events(:)
        integer :: i, j, k
        allocate (events(size(a) + size(b)))
        i = 1
        j = 1
        do k = 1, size(events)
            if (j > size(b)) then
                events(k) = a(i)
                i = i + 1
            else if (i > size(a)) then
                events(k) = b(j)
                j = j + 1
            else if (b(j)%t < a(i)%t .or. (b(j)%t == a(i)%t .and. &
                                            a(i)%method /= b(j)%method)) then
                events(k) = b(j)
                j = j + 1
            else
                events(k) = a(i)
                i = i + 1
            end if
        end do
    end function merged_events

    subroutine log_clear(self)
        class(switch_log_t), intent(inout) :: self
        self%count = 0
    end subroutine log_clear
end module ropedyn_switch_log
