!> The integrators ropedyn offers, by the name used in `&solver method`.
module ropedyn_solvers
    use ropedyn_error, only: error_t, make_error, ERR_INPUT
    use ropedyn_integrator, only: integrator_t
    use ropedyn_cvode, only: cvode_t
    use ropedyn_mebdf, only: mebdf_t
    implicit none
    private
    public :: new_integrator, method_names, method_order_range

    !> Names of the available methods.
    character(len=*), parameter :: method_names(2) = [character(len=8) :: 'cvode', 'mebdf']

contains

    !> A fresh integrator of the named method (not initialized).
    subroutine new_integrator(method, integrator, err)
        character(len=*), intent(in) :: method
        class(integrator_t), allocatable, intent(out) :: integrator
        type(error_t), allocatable, intent(out) :: err
        select case (method)
        case ('cvode')
            allocate (cvode_t :: integrator)
        case ('mebdf')
            allocate (mebdf_t :: integrator)
        case default
            call make_error(err, ERR_INPUT, 'unknown integration method "'//method// &
                            '" (available: cvode, mebdf)')
        end select
    end subroutine new_integrator

    !> Lowest and highest allowed max_order of a method, and its default.
    subroutine method_order_range(method, lowest, highest, default, err)
        character(len=*), intent(in) :: method
        integer, intent(out) :: lowest, highest, default
        type(error_t), allocatable, intent(out) :: err
        class(integrator_t), allocatable :: integrator
        lowest = 0
        highest = 0
        default = 0
        call new_integrator(method, integrator, err)
        if (allocated(err)) return
        lowest = integrator%min_order()
        highest = integrator%max_order_limit()
        default = integrator%default_max_order()
    end subroutine method_order_range
end module ropedyn_solvers
