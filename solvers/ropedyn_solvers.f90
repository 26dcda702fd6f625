!> The integrators ropedyn offers, by the name used in `&solver method` (the names and
!! their order ranges are plain data in ropedyn_methods).
module ropedyn_solvers
    use ropedyn_error, only: error_t, make_error, ERR_INPUT
    use ropedyn_methods, only: METHODS, method_index, method_list
    use ropedyn_integrator, only: integrator_t
    use ropedyn_cvode, only: cvode_t, adams_t
    use ropedyn_mebdf, only: mebdf_t
    use ropedyn_erk, only: erk_t
    use ropedyn_auto, only: auto_t
    use ropedyn_symplectic, only: symplectic_t
    implicit none
    private
    public :: new_integrator, method_order_range

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
        case ('erk')
            allocate (erk_t :: integrator)
        case ('adams')
            allocate (adams_t :: integrator)
        case ('auto')
            allocate (auto_t :: integrator)
        case ('symplectic')
            allocate (symplectic_t :: integrator)
        case default
            call make_error(err, ERR_INPUT, 'unknown integration method "'//method// &
                            '" (available: '//method_list()//')')
        end select
    end subroutine new_integrator

    !> Lowest and highest allowed max_order of a method.
    subroutine method_order_range(method, lowest, highest, err)
        character(len=*), intent(in) :: method
        integer, intent(out) :: lowest, highest
        type(error_t), allocatable, intent(out) :: err
        integer :: k
        lowest = 0
        highest = 0
        k = method_index(method)
        if (k == 0) then
            call make_error(err, ERR_INPUT, 'unknown integration method "'//method// &
                            '" (available: '//method_list()//')')
            return
        end if
        lowest = METHODS(k)%lowest_order
        highest = METHODS(k)%highest_order
    end subroutine method_order_range
end module ropedyn_solvers
