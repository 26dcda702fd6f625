!> Testing aid: a problem that wraps another and turns its right-hand side into NaN after a
!! given time (`&solver fault_nan_after`, docs/input.md).
!!
!! It exists to test the failure path end to end: a NaN or Inf in the forces must reach the
!! integrator as a recoverable error (`STATUS_RECOVERABLE`: the step is cut and retried),
!! repeated failures must end the run with a diagnosis (time, step size, cause), and the
!! output file must be marked failed while keeping the records before the failure. Every
!! other procedure delegates to the wrapped problem unchanged, so up to the fault time a run
!! with the wrapper is the run without it.
module ropedyn_fault
    use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, ieee_is_finite
    use ropedyn_kinds, only: wp
    use ropedyn_problem, only: problem_t, STATUS_OK, STATUS_RECOVERABLE
    implicit none
    private
    public :: fault_problem_t, fault_wrap

    !> `inner` with f(t, y) = NaN for t > t_fault.
    type, extends(problem_t) :: fault_problem_t
        private
        class(problem_t), pointer :: inner => null()
        real(wp) :: t_fault = huge(1.0_wp)   !< s
    contains
        procedure :: size => fault_size
        procedure :: bandwidths => fault_bandwidths
        procedure :: rhs => fault_rhs
        procedure :: has_jacobian => fault_has_jacobian
        procedure :: jacobian => fault_jacobian
        procedure :: quad_size => fault_quad_size
        procedure :: quad_rhs => fault_quad_rhs
        procedure :: has_mass_matrix => fault_has_mass_matrix
        procedure :: mass_matrix => fault_mass_matrix
        procedure :: implicit_rhs => fault_implicit_rhs
        procedure :: has_implicit_jacobian => fault_has_implicit_jacobian
        procedure :: implicit_jacobian => fault_implicit_jacobian
        procedure :: has_second_order => fault_has_second_order
        procedure :: second_order_layout => fault_second_order_layout
        procedure :: second_order_blocks => fault_second_order_blocks
    end type fault_problem_t

contains

    !> Wrap `inner` (which must outlive the wrapper): NaN right-hand side for t > t_fault (s).
    subroutine fault_wrap(wrapper, inner, t_fault)
        type(fault_problem_t), intent(out) :: wrapper
        class(problem_t), intent(in), target :: inner
        real(wp), intent(in) :: t_fault
        wrapper%inner => inner
        wrapper%t_fault = t_fault
    end subroutine fault_wrap

    !> After the fault time every component is NaN; the status then follows the rule every
    !! model applies to its own forces: a non-finite value is a recoverable error.
    subroutine inject(self, t, f, status)
        class(fault_problem_t), intent(in) :: self
        real(wp), intent(in) :: t
        real(wp), intent(inout) :: f(:)
        integer, intent(inout) :: status
        if (t > self%t_fault) f = ieee_value(1.0_wp, ieee_quiet_nan)
        if (status == STATUS_OK .and. .not. all(ieee_is_finite(f))) status = STATUS_RECOVERABLE
    end subroutine inject

    pure integer function fault_size(self)
        class(fault_problem_t), intent(in) :: self
        fault_size = self%inner%size()
    end function fault_size

    pure subroutine fault_bandwidths(self, ml, mu)
        class(fault_problem_t), intent(in) :: self
        integer, intent(out) :: ml, mu
        call self%inner%bandwidths(ml, mu)
    end subroutine fault_bandwidths

    subroutine fault_rhs(self, t, y, ydot, status)
        class(fault_problem_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: ydot(:)
        integer, intent(out) :: status
        call self%inner%rhs(t, y, ydot, status)
        call inject(self, t, ydot, status)
    end subroutine fault_rhs

    pure logical function fault_has_jacobian(self) result(has)
        class(fault_problem_t), intent(in) :: self
        has = self%inner%has_jacobian()
    end function fault_has_jacobian

    subroutine fault_jacobian(self, t, y, jb, offset, status)
        class(fault_problem_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(inout) :: jb(:, :)
        integer, intent(in) :: offset
        integer, intent(out) :: status
        call self%inner%jacobian(t, y, jb, offset, status)
    end subroutine fault_jacobian

    pure integer function fault_quad_size(self) result(nq)
        class(fault_problem_t), intent(in) :: self
        nq = self%inner%quad_size()
    end function fault_quad_size

    subroutine fault_quad_rhs(self, t, y, yqdot, status)
        class(fault_problem_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: yqdot(:)
        integer, intent(out) :: status
        call self%inner%quad_rhs(t, y, yqdot, status)
    end subroutine fault_quad_rhs

    pure logical function fault_has_mass_matrix(self) result(has)
        class(fault_problem_t), intent(in) :: self
        has = self%inner%has_mass_matrix()
    end function fault_has_mass_matrix

    subroutine fault_mass_matrix(self, t, y, mb, offset, status)
        class(fault_problem_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(inout) :: mb(:, :)
        integer, intent(in) :: offset
        integer, intent(out) :: status
        call self%inner%mass_matrix(t, y, mb, offset, status)
    end subroutine fault_mass_matrix

    subroutine fault_implicit_rhs(self, t, y, f, status)
        class(fault_problem_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: f(:)
        integer, intent(out) :: status
        call self%inner%implicit_rhs(t, y, f, status)
        call inject(self, t, f, status)
    end subroutine fault_implicit_rhs

    pure logical function fault_has_implicit_jacobian(self) result(has)
        class(fault_problem_t), intent(in) :: self
        has = self%inner%has_implicit_jacobian()
    end function fault_has_implicit_jacobian

    subroutine fault_implicit_jacobian(self, t, y, jb, offset, status)
        class(fault_problem_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(inout) :: jb(:, :)
        integer, intent(in) :: offset
        integer, intent(out) :: status
        call self%inner%implicit_jacobian(t, y, jb, offset, status)
    end subroutine fault_implicit_jacobian

    pure logical function fault_has_second_order(self) result(has)
        class(fault_problem_t), intent(in) :: self
        has = self%inner%has_second_order()
    end function fault_has_second_order

    pure subroutine fault_second_order_layout(self, pos, vel, kl, ku)
        class(fault_problem_t), intent(in) :: self
        integer, allocatable, intent(out) :: pos(:), vel(:)
        integer, intent(out) :: kl, ku
        call self%inner%second_order_layout(pos, vel, kl, ku)
    end subroutine fault_second_order_layout

    subroutine fault_second_order_blocks(self, t, y, implicit_form, kb, cb, mb, offset, status)
        class(fault_problem_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        logical, intent(in) :: implicit_form
        real(wp), intent(inout) :: kb(:, :), cb(:, :), mb(:, :)
        integer, intent(in) :: offset
        integer, intent(out) :: status
        call self%inner%second_order_blocks(t, y, implicit_form, kb, cb, mb, offset, status)
    end subroutine fault_second_order_blocks
end module ropedyn_fault
