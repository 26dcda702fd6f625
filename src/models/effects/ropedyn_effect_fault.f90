!> Testing aid: forces and moments that turn NaN after a given time (`&effects
!! fault_nan_after`, docs/guide/effects.md).
!!
!! It exists to test the failure path end to end through a real model: a NaN in the forces
!! must make the model report a recoverable error (`STATUS_RECOVERABLE`: the integrator cuts
!! the step and retries), repeated failures must end the run with a diagnosis (time, step
!! size, cause), and the output file must be marked failed while keeping the records before
!! the failure. Up to the fault time it adds nothing, so a run with it is, bit for bit, the
!! run without it.
module ropedyn_effect_fault
    use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
    use ropedyn_kinds, only: wp
    use ropedyn_effect, only: body_effect_t, bodies_t
    implicit none
    private
    public :: fault_effect_t

    type, extends(body_effect_t) :: fault_effect_t
        real(wp) :: t_fault = huge(1.0_wp)   !< s
    contains
        procedure :: name => fault_name
        procedure :: add_forces => fault_add_forces
        procedure :: add_jacobian => fault_add_jacobian
    end type fault_effect_t

contains

    pure function fault_name(self) result(name)
        class(fault_effect_t), intent(in) :: self
        character(len=:), allocatable :: name
        name = 'fault'
    end function fault_name

    !> NaN forces and moments on every body for t > t_fault, nothing before.
    pure subroutine fault_add_forces(self, t, b, f, m)
        class(fault_effect_t), intent(in) :: self
        real(wp), intent(in) :: t
        type(bodies_t), intent(in) :: b
        real(wp), intent(inout) :: f(:, :), m(:)
        if (t <= self%t_fault) return
        f = ieee_value(1.0_wp, ieee_quiet_nan)
        m = ieee_value(1.0_wp, ieee_quiet_nan)
    end subroutine fault_add_forces

    !> No derivatives: before the fault there is no force, after it no finite one.
    pure subroutine fault_add_jacobian(self, t, b, jac)
        class(fault_effect_t), intent(in) :: self
        real(wp), intent(in) :: t
        type(bodies_t), intent(in) :: b
        real(wp), intent(inout) :: jac(:, :, :)
    end subroutine fault_add_jacobian
end module ropedyn_effect_fault
