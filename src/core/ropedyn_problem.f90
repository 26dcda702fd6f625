!> The one interface between models (src/models) and integrators (solvers/).
!!
!! A problem is a first-order system y' = f(t, y) of `size()` unknowns whose Jacobian
!! df/dy lies in a band of `ml` sub- and `mu` super-diagonals, plus optional quadrature
!! variables yq' = g(t, y) (integrated alongside y but outside the Newton system; the rope
!! models use them for the dissipated energy and the work of the supports).
!!
!! Optional parts, each with a default:
!! - an analytic Jacobian (`has_jacobian`); without one, integrators difference f;
!! - a linearly implicit form M(t, y) y' = F(t, y) (`has_mass_matrix`): `implicit_rhs`
!!   gives F, `mass_matrix` gives M, `implicit_jacobian` gives dF/dy. `rhs` must still give
!!   y' = M^{-1} F for integrators that only take explicit systems. Without a mass matrix
!!   the implicit form is the explicit one with M = I. The band (ml, mu) covers M too.
module ropedyn_problem
    use ropedyn_kinds, only: wp
    implicit none
    private
    public :: problem_t
    public :: STATUS_OK, STATUS_RECOVERABLE, STATUS_FATAL

    !> Return codes of rhs/jacobian/quad_rhs (the CVODE convention).
    integer, parameter :: STATUS_OK = 0           !< success
    integer, parameter :: STATUS_RECOVERABLE = 1  !< e.g. a NaN: the integrator may retry smaller
    integer, parameter :: STATUS_FATAL = -1       !< stop the integration

    type, abstract :: problem_t
    contains
        procedure(size_i), deferred :: size
        procedure(bandwidths_i), deferred :: bandwidths
        procedure(rhs_i), deferred :: rhs
        procedure :: has_jacobian => problem_has_jacobian
        procedure :: jacobian => problem_jacobian
        procedure :: quad_size => problem_quad_size
        procedure :: quad_rhs => problem_quad_rhs
        procedure :: has_mass_matrix => problem_has_mass_matrix
        procedure :: mass_matrix => problem_mass_matrix
        procedure :: implicit_rhs => problem_implicit_rhs
        procedure :: has_implicit_jacobian => problem_has_implicit_jacobian
        procedure :: implicit_jacobian => problem_implicit_jacobian
    end type problem_t

    abstract interface
        !> Number of unknowns of the first-order system.
        pure integer function size_i(self)
            import :: problem_t
            class(problem_t), intent(in) :: self
        end function size_i

        !> Lower and upper bandwidth of df/dy (ml = mu = size-1 for a dense Jacobian).
        pure subroutine bandwidths_i(self, ml, mu)
            import :: problem_t
            class(problem_t), intent(in) :: self
            integer, intent(out) :: ml, mu
        end subroutine bandwidths_i

        !> ydot = f(t, y); status is one of the STATUS_* codes.
        subroutine rhs_i(self, t, y, ydot, status)
            import :: problem_t, wp
            class(problem_t), intent(inout) :: self
            real(wp), intent(in) :: t
            real(wp), intent(in) :: y(:)
            real(wp), intent(out) :: ydot(:)
            integer, intent(out) :: status
        end subroutine rhs_i
    end interface

contains

    !> True when `jacobian` gives df/dy analytically (none unless a problem overrides this).
    pure logical function problem_has_jacobian(self) result(has)
        class(problem_t), intent(in) :: self
        has = .false.
    end function problem_has_jacobian

    !> Add df/dy into band storage: entry (i, j) goes to jb(offset + i - j, j).
    !! The caller zeroes jb; offset >= mu + 1 and size(jb, 1) >= offset + ml.
    !! Only called when `has_jacobian()`; the default reports a fatal status.
    subroutine problem_jacobian(self, t, y, jb, offset, status)
        class(problem_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(inout) :: jb(:, :)
        integer, intent(in) :: offset
        integer, intent(out) :: status
        status = STATUS_FATAL
    end subroutine problem_jacobian

    !> True for a linearly implicit problem M(t, y) y' = F(t, y) with M /= I.
    pure logical function problem_has_mass_matrix(self) result(has)
        class(problem_t), intent(in) :: self
        has = .false.
    end function problem_has_mass_matrix

    !> Add M(t, y) into band storage as `jacobian` does (default: the identity).
    subroutine problem_mass_matrix(self, t, y, mb, offset, status)
        class(problem_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(inout) :: mb(:, :)
        integer, intent(in) :: offset
        integer, intent(out) :: status
        mb(offset, :) = mb(offset, :) + 1.0_wp
        status = STATUS_OK
    end subroutine problem_mass_matrix

    !> F(t, y) of the implicit form (default: f, the explicit right-hand side).
    subroutine problem_implicit_rhs(self, t, y, f, status)
        class(problem_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: f(:)
        integer, intent(out) :: status
        call self%rhs(t, y, f, status)
    end subroutine problem_implicit_rhs

    !> True when `implicit_jacobian` gives dF/dy analytically (default: as `has_jacobian`
    !! for an explicit problem, false for one with a mass matrix).
    pure logical function problem_has_implicit_jacobian(self) result(has)
        class(problem_t), intent(in) :: self
        has = self%has_jacobian() .and. .not. self%has_mass_matrix()
    end function problem_has_implicit_jacobian

    !> Add dF/dy into band storage (default: the explicit Jacobian).
    subroutine problem_implicit_jacobian(self, t, y, jb, offset, status)
        class(problem_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(inout) :: jb(:, :)
        integer, intent(in) :: offset
        integer, intent(out) :: status
        call self%jacobian(t, y, jb, offset, status)
    end subroutine problem_implicit_jacobian

    !> Number of quadrature variables (none unless a problem overrides this).
    pure integer function problem_quad_size(self) result(nq)
        class(problem_t), intent(in) :: self
        nq = 0
    end function problem_quad_size

    !> yqdot = g(t, y) for the quadrature variables.
    subroutine problem_quad_rhs(self, t, y, yqdot, status)
        class(problem_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: yqdot(:)
        integer, intent(out) :: status
        yqdot = 0.0_wp
        status = STATUS_OK
    end subroutine problem_quad_rhs
end module ropedyn_problem
