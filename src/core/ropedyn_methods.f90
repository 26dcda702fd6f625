!> The integration methods by name, with the orders each allows: plain data shared by the
!! scene reader (which checks `&solver max_order`) and the integrators (which apply it), so
!! that input checking needs no solver module.
!!
!! Why the defaults: CVODE keeps its own limit, BDF order 5, after measuring orders 2 .. 5
!! with and without stability-limit detection on the hard scenes (docs/validation/cvode-order.md): orders
!! 3 and 4 let undamped modes gain energy, order 2 crawls where the rope's oscillations must
!! be resolved, and order 5 never amplified. MEBDF defaults to order 4 (k = 3), the highest
!! at which it is A-stable and does not amplify undamped oscillations (order 5 amplifies by
!! up to 1.027 per step on the imaginary axis, order 6 by 1.114; docs/theory/mebdf.md).
!! The safe orders: BDF is A-stable up to order 2, MEBDF up to order 4; auto's is the
!! limit 4 on its implicit method, which makes that method MEBDF (ropedyn_auto, "Start").
module ropedyn_methods
    implicit none
    private
    public :: method_info_t, METHODS, method_index, method_list, resolved_max_order

    !> One method: its name in `&solver method` and the orders of accuracy it allows.
    type :: method_info_t
        character(len=10) :: name = ''
        integer :: lowest_order = 1     !< smallest allowed max_order
        integer :: highest_order = 1    !< largest allowed max_order
        !> the max_order used when max_order = 0 (0 for auto: it chooses MEBDF's limit
        !! from the damping of the scene's fast modes, ropedyn_auto)
        integer :: default_order = 1
        !> the highest order at which the method never amplifies an undamped oscillation
        !! (A-stable; 0: none known): the order ropedyn's energy monitor lowers it to when
        !! the energy balance shows a gain (&solver order_safety, docs/theory/energy-balance.md)
        integer :: safe_order = 0
    end type method_info_t

    type(method_info_t), parameter :: METHODS(*) = [ &
        method_info_t('cvode', 1, 5, 5, safe_order=2), &
        method_info_t('mebdf', 2, 7, 4, safe_order=4), &
        method_info_t('erk', 3, 5, 4), &
        method_info_t('adams', 1, 12, 12, safe_order=2), &
        method_info_t('auto', 2, 7, 0, safe_order=4), &
        method_info_t('symplectic', 2, 4, 4)]

contains

    !> Index of a method in METHODS, 0 if there is none of that name.
    pure integer function method_index(name) result(k)
        character(len=*), intent(in) :: name
        do k = 1, size(METHODS)
            if (trim(METHODS(k)%name) == trim(name)) return
        end do
        k = 0
    end function method_index

    !> The order limit a method uses for `max_order`: max_order itself, or when it is 0 the
    !! method's default (0 for auto: it chooses). The one place where 0 means the default.
    pure integer function resolved_max_order(name, max_order) result(order)
        character(len=*), intent(in) :: name
        integer, intent(in) :: max_order
        order = max_order
        if (order == 0 .and. method_index(name) > 0) &
            order = METHODS(method_index(name))%default_order
    end function resolved_max_order

    !> 'cvode, mebdf': the names for messages.
    pure function method_list() result(list)
        character(len=:), allocatable :: list
        integer :: k
        list = trim(METHODS(1)%name)
        do k = 2, size(METHODS)
            list = list//', '//trim(METHODS(k)%name)
        end do
    end function method_list
end module ropedyn_methods
