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
!!   the implicit form is the explicit one with M = I. The band (ml, mu) covers M too;
!! - second-order structure (`has_second_order`): the unknowns are coordinates q = y(pos)
!!   and their rates v = y(vel) with q' = v exactly, and the rate equations are
!!   M(q) v' = F_v(t, q, v) (M = I in the explicit form). Integrators then solve their
!!   Newton systems on the reduced matrix M - g C - g^2 K of size(pos) unknowns
!!   (K = dF_v/dq, C = dF_v/dv, g the Newton matrix's multiple of the Jacobian) instead
!!   of the first-order one of twice that size: (I - g J) (dq, dv) = (r_q, r_v) becomes
!!   (M - g C - g^2 K) dv = r_v + g K r_q, dq = r_q + g dv (for the implicit form with
!!   r_v the residual of the rate rows, M dv - ...). `second_order_blocks` gives K, C, M in
!!   band storage (default: taken from the first-order Jacobian, so every problem with a
!!   Jacobian can use the reduced path; models override it with a direct assembly).
!! - a force split (`force_split_refusal` empty) for splitting methods (solvers/symplectic):
!!   a second-order problem whose mass matrix of the coordinates is constant and diagonal,
!!   M = diag(m), and whose rate equations are m v' = F_c(t, q) + F_r(t, q, v), F_c =
!!   -dV/dq the forces of a potential V(t, q) and F_r the rest (damping, drag, friction,
!!   loads). `split_rhs` gives the accelerations F_c/m and F_r/m and the quadratures'
!!   rates split the same way; `split_layout` gives m and which quadratures are energy
!!   taken out (dissipated) or put in (external work), so that T + V - sum s_k yq_k is
!!   constant (T = sum m v^2/2); `split_has_rest` whether F_r is there at all (a splitting
!!   method counts its cost). Default: refused (no split).
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
        ! The optional capabilities, one statement each: its query (or size) and what it
        ! provides. The defaults: none (no Jacobian, no quadrature, no second-order blocks),
        ! the identity mass matrix, and the explicit form as the implicit one.
        procedure :: has_jacobian => problem_has_jacobian, jacobian => problem_jacobian
        procedure :: quad_size => problem_quad_size, quad_rhs => problem_quad_rhs, &
                     rhs_quad => problem_rhs_quad
        procedure :: has_mass_matrix => problem_has_mass_matrix, mass_matrix => problem_mass_matrix
        procedure :: implicit_rhs => problem_implicit_rhs, &
                     has_implicit_jacobian => problem_has_implicit_jacobian, &
                     implicit_jacobian => problem_implicit_jacobian
        procedure :: has_second_order => problem_has_second_order, &
                     second_order_layout => problem_second_order_layout, &
                     second_order_blocks => problem_second_order_blocks
        procedure :: force_split_refusal => problem_force_split_refusal, &
                     split_layout => problem_split_layout, split_rhs => problem_split_rhs, &
                     split_has_rest => problem_split_has_rest
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

    !> ydot = f(t, y) and yqdot = g(t, y) in one call, for integrators that need both at
    !! every stage (the explicit Runge-Kutta pairs); a problem whose g falls out of f's
    !! evaluation overrides this to share the work.
    subroutine problem_rhs_quad(self, t, y, ydot, yqdot, status)
        class(problem_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: ydot(:)
        real(wp), intent(out) :: yqdot(:)
        integer, intent(out) :: status
        call self%rhs(t, y, ydot, status)
        if (status /= STATUS_OK) return
        call self%quad_rhs(t, y, yqdot, status)
    end subroutine problem_rhs_quad

    !> True when the problem has the second-order structure described in the module header
    !! (none unless a problem overrides this).
    pure logical function problem_has_second_order(self) result(has)
        class(problem_t), intent(in) :: self
        has = .false.
    end function problem_has_second_order

    !> Where the coordinates and their rates are in y (y(pos(k)) is q_k, y(vel(k)) its rate)
    !! and the lower and upper bandwidths kl, ku of the reduced blocks K, C, M (matrices of
    !! size(pos) rows and columns, in the order of pos). Only called when
    !! `has_second_order()`; the default has no coordinates.
    pure subroutine problem_second_order_layout(self, pos, vel, kl, ku)
        class(problem_t), intent(in) :: self
        integer, allocatable, intent(out) :: pos(:), vel(:)
        integer, intent(out) :: kl, ku
        allocate (pos(0), vel(0))
        kl = 0
        ku = 0
    end subroutine problem_second_order_layout

    !> Add the blocks of the rate rows into band storage (entry (i, j) of a block goes to
    !! b(offset + i - j, j), offset >= ku + 1, size(b, 1) >= offset + kl; the caller zeroes
    !! them): K = dF_v/dq into kb, C = dF_v/dv into cb and the mass block into mb. With
    !! `implicit_form` false they are the rows of the explicit system y' = f (M^{-1} applied;
    !! the mass block is I); true: of the implicit form M(t, y) y' = F. The default takes them
    !! from the first-order (implicit) Jacobian and mass matrix, and reports STATUS_FATAL when
    !! the problem has no analytic one (integrators then keep the first-order path).
    subroutine problem_second_order_blocks(self, t, y, implicit_form, kb, cb, mb, offset, &
                                           status)
        class(problem_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        logical, intent(in) :: implicit_form
        real(wp), intent(inout) :: kb(:, :), cb(:, :), mb(:, :)
        integer, intent(in) :: offset
        integer, intent(out) :: status
        integer, allocatable :: pos(:), vel(:)
        real(wp), allocatable :: jb(:, :), massb(:, :)
        integer :: ml, mu, kl, ku, a, b, joff
        logical :: with_mass

        call self%second_order_layout(pos, vel, kl, ku)
        call self%bandwidths(ml, mu)
        joff = mu + 1
        allocate (jb(ml + mu + 1, self%size()))
        jb = 0.0_wp
        with_mass = implicit_form .and. self%has_mass_matrix()
        status = STATUS_FATAL
        if (with_mass .and. .not. self%has_implicit_jacobian()) return
        if (.not. with_mass .and. .not. self%has_jacobian()) return
        if (with_mass) then
            call self%implicit_jacobian(t, y, jb, joff, status)
        else
            call self%jacobian(t, y, jb, joff, status)
        end if
        if (status /= STATUS_OK) return
        if (with_mass) then
            allocate (massb(ml + mu + 1, self%size()))
            massb = 0.0_wp
            call self%mass_matrix(t, y, massb, joff, status)
            if (status /= STATUS_OK) return
        end if
        do b = 1, size(pos)
            do a = max(1, b - ku), min(size(pos), b + kl)
                kb(offset + a - b, b) = kb(offset + a - b, b) + entry(jb, vel(a), pos(b))
                cb(offset + a - b, b) = cb(offset + a - b, b) + entry(jb, vel(a), vel(b))
                if (with_mass) then
                    mb(offset + a - b, b) = mb(offset + a - b, b) + entry(massb, vel(a), vel(b))
                else if (a == b) then
                    mb(offset, b) = mb(offset, b) + 1.0_wp
                end if
            end do
        end do
    contains
        !> Entry (i, j) of a first-order band matrix, zero outside the band.
        pure real(wp) function entry(band, i, j) result(x)
            real(wp), intent(in) :: band(:, :)
            integer, intent(in) :: i, j
            x = 0.0_wp
            if (i - j <= ml .and. j - i <= mu) x = band(joff + i - j, j)
        end function entry
    end subroutine problem_second_order_blocks

    !> Why the problem offers no force split ('' when it does; see the module header). The
    !! default: none.
    pure function problem_force_split_refusal(self) result(why)
        class(problem_t), intent(in) :: self
        character(len=:), allocatable :: why
        why = 'the problem does not split its forces into those of a potential and the rest'
    end function problem_force_split_refusal

    !> The split's constants: the diagonal of the constant mass matrix of the coordinates
    !! (size(pos), in the order of `second_order_layout`'s pos) and, for each quadrature,
    !! its sign in the energy balance: -1 energy taken out (dissipated), +1 put in (external
    !! work), 0 not energy. Only called when the split is offered (the default: m = 1, 0).
    pure subroutine problem_split_layout(self, mass, signs)
        class(problem_t), intent(in) :: self
        real(wp), intent(out) :: mass(:)
        integer, intent(out) :: signs(:)
        mass = 1.0_wp
        signs = 0
    end subroutine problem_split_layout

    !> Whether the split has forces outside the potential (dampers, drag, loads: `ar` of
    !! split_rhs not always zero). A splitting method counts their cost in choosing its
    !! step. The default: yes (the dearer assumption).
    pure logical function problem_split_has_rest(self) result(rest)
        class(problem_t), intent(in) :: self
        rest = .true.
    end function problem_split_has_rest

    !> The split at (t, y): ac = F_c(t, q)/m, the accelerations of the potential's forces
    !! (size(pos), in the order of pos), and gc the quadratures' rates that depend on (t, q)
    !! alone (the work of a potential that depends on time: dV/dt at fixed q, e.g. a spring
    !! to a moving anchor); with `ar` present also ar = F_r(t, q, v)/m and gr, the rates of
    !! the rest (dissipation and work of the other forces), so that gc + gr is the whole of
    !! quad_rhs. Without `ar` only the potential's part is evaluated (the cheaper call).
    !! Only called when the split is offered (the default reports STATUS_FATAL).
    subroutine problem_split_rhs(self, t, y, ac, gc, status, ar, gr)
        class(problem_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: ac(:), gc(:)
        integer, intent(out) :: status
        real(wp), intent(out), optional :: ar(:), gr(:)
        ac = 0.0_wp
        gc = 0.0_wp
        if (present(ar)) ar = 0.0_wp
        if (present(gr)) gr = 0.0_wp
        status = STATUS_FATAL
    end subroutine problem_split_rhs
end module ropedyn_problem
