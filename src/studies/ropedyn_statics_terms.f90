!> The terms of a rope model at rest, on its generalized coordinates: the total length and
!! weight, the potential energy (elastic, gravity, point loads), the generalized force
!! f(q) = -dV/dq and the tangent matrices (stiffness K = -df/dq, mass, damping), for the
!! statics (ropedyn_statics) and the modal analysis (ropedyn_modes). How each model gives
!! them: the header of ropedyn_statics and docs/theory/statics-modes.md. The model is evaluated
!! with its supports at rest (rope_model_t%supports_at_rest, set for the evaluation and
!! restored): a moving support sits where its motion puts it at t = 0, and its velocity
!! and acceleration there do not enter a static force.
module ropedyn_statics_terms
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite, ieee_is_nan
    use ropedyn_kinds, only: wp
    use ropedyn_problem, only: STATUS_OK
    use ropedyn_rope_model, only: rope_model_t, energy_t
    use ropedyn_rope_spec, only: rope_spec_t, N_ATTACH
    use ropedyn_effect_factory, only: locate_on_bodies
    use ropedyn_ldl, only: bandwidth
    implicit none
    private
    public :: generalized_force, tangent_matrices, potential_energy, rope_length, total_weight

    real(wp), parameter :: PI = 4.0_wp*atan(1.0_wp)

contains

    !> Total length of the elements, m.
    real(wp) function rope_length(model) result(length)
        class(rope_model_t), intent(in) :: model
        real(wp) :: lengths(model%n_elements()), masses(model%n_elements())
        call model%element_data(lengths, masses)
        length = sum(lengths)
    end function rope_length

    !> Total weight of the rope in the spec, N (0 when gravity is off).
    real(wp) function total_weight(model, spec) result(weight)
        class(rope_model_t), intent(in) :: model
        type(rope_spec_t), intent(in) :: spec
        real(wp) :: lengths(model%n_elements()), masses(model%n_elements())
        call model%element_data(lengths, masses)
        weight = 0.0_wp
        if (spec%effects%gravity) weight = sum(masses)*spec%rope%gravity
    end function total_weight

    !> Potential energy V = elastic + gravity of state y (velocities are ignored by both), J.
    !! With `spec`, V also holds the potential -F.X of the spec's point loads frozen at
    !! t = 0 (the statics' loads; in a run their work is external work, not part of V).
    real(wp) function potential_energy(model, y, spec) result(v)
        class(rope_model_t), intent(inout) :: model
        real(wp), intent(in) :: y(:)
        type(rope_spec_t), intent(in), optional :: spec
        type(energy_t) :: e
        real(wp) :: yq(max(1, model%quad_size()))
        yq = 0.0_wp
        e = model%energy(0.0_wp, y, yq)
        v = e%elastic + e%gravity
        if (present(spec)) v = v + load_potential(model, spec, y)
    end function potential_energy

    !> Potential -sum F_k(0).X_k of the point loads of a spec (none when `&effects
    !! point_loads` is off), X_k = c + r e the load's point on its element, J. A load of
    !! fixed direction frozen at its t = 0 value F0 + A sin(phase) is conservative.
    real(wp) function load_potential(model, spec, y) result(v)
        class(rope_model_t), intent(in) :: model
        type(rope_spec_t), intent(in) :: spec
        real(wp), intent(in) :: y(:)
        real(wp) :: lengths(model%n_elements()), masses(model%n_elements()), r, force(2)
        real(wp) :: q(3, model%n_elements()), qdot(3, model%n_elements())
        integer :: k, body
        v = 0.0_wp
        if (.not. spec%effects%point_loads) return
        associate (a => spec%attachments)
            if (all(ieee_is_nan(a%load_positions))) return
            call model%element_data(lengths, masses)
            call model%fields(y, q, qdot, 0.0_wp)
            do k = 1, N_ATTACH
                if (ieee_is_nan(a%load_positions(k))) cycle
                call locate_on_bodies(lengths, a%load_positions(k), body, r)
                force = [a%load_force_x(k), a%load_force_y(k)] + [a%load_amplitude_x(k), &
                    a%load_amplitude_y(k)]*sin(a%load_phase_deg(k)*PI/180.0_wp)
                v = v - dot_product(force, q(1:2, body) + r*[cos(q(3, body)), sin(q(3, body))])
            end do
        end associate
    end function load_potential

    !> Generalized force f = M(q) q'' of state y (at rest: -dV/dq), N or N m.
    subroutine generalized_force(model, y, pos, vel, f, status)
        class(rope_model_t), intent(inout) :: model
        real(wp), intent(in) :: y(:)
        integer, intent(in) :: pos(:), vel(:)
        real(wp), intent(out) :: f(:)
        integer, intent(out) :: status
        real(wp), allocatable :: w(:), mm(:, :)
        logical :: held
        held = model%supports_at_rest
        model%supports_at_rest = .true.
        allocate (w(size(y)))
        if (model%has_mass_matrix()) then
            call model%implicit_rhs(0.0_wp, y, w, status)
            f = w(vel)
        else
            call model%rhs(0.0_wp, y, w, status)
            allocate (mm(size(pos), size(pos)))
            call model%coordinate_mass(y, mm)
            f = matmul(mm, w(vel))
        end if
        if (status == STATUS_OK .and. .not. all(ieee_is_finite(f))) status = -1
        model%supports_at_rest = held
    end subroutine generalized_force

    !> Tangent stiffness kt = -df/dq and, if present, damping cv = -df/dq' at state y.
    subroutine tangent_matrices(model, y, pos, vel, kt, status, cv)
        class(rope_model_t), intent(inout) :: model
        real(wp), intent(in) :: y(:)
        integer, intent(in) :: pos(:), vel(:)
        real(wp), intent(out) :: kt(:, :)
        integer, intent(out) :: status
        real(wp), intent(out), optional :: cv(:, :)
        logical :: held
        held = model%supports_at_rest
        model%supports_at_rest = .true.
        call tangents(model, y, pos, vel, kt, status, cv)
        model%supports_at_rest = held
    end subroutine tangent_matrices

    !> tangent_matrices with the supports as the model has them.
    subroutine tangents(model, y, pos, vel, kt, status, cv)
        class(rope_model_t), intent(inout) :: model
        real(wp), intent(in) :: y(:)
        integer, intent(in) :: pos(:), vel(:)
        real(wp), intent(out) :: kt(:, :)
        integer, intent(out) :: status
        real(wp), intent(out), optional :: cv(:, :)
        real(wp), allocatable :: mm(:, :), jb(:, :), yp(:), gp(:), gm(:)
        integer, allocatable :: vel_of_row(:)
        integer :: nd, ns, ml, mu, offset, j, r, c, i, st
        real(wp) :: h
        logical :: implicit

        nd = size(pos)
        ns = size(y)
        status = STATUS_OK
        implicit = model%has_mass_matrix()
        if (.not. implicit) then
            allocate (mm(nd, nd))
            call model%coordinate_mass(y, mm)
        end if
        if (implicit .or. .not. model%has_jacobian()) then
            ! central differences: of f = F(vel) of the implicit form (F is cheap, O(n)), or
            ! of the accelerations of an explicit model without a Jacobian
            allocate (yp(ns), gp(ns), gm(ns))
            do j = 1, nd
                call differenced(pos(j), kt(:, j))
                if (status /= STATUS_OK) return
                if (present(cv)) then
                    call differenced(vel(j), cv(:, j))
                    if (status /= STATUS_OK) return
                end if
            end do
            if (implicit) return
        else
            call model%bandwidths(ml, mu)
            offset = mu + 1
            allocate (jb(ml + mu + 1, ns), vel_of_row(ns))
            jb = 0.0_wp
            call model%jacobian(0.0_wp, y, jb, offset, status)
            if (status /= STATUS_OK) return
            vel_of_row = 0
            vel_of_row(vel) = [(i, i = 1, nd)]
            kt = 0.0_wp
            if (present(cv)) cv = 0.0_wp
            do j = 1, nd
                c = pos(j)
                do r = max(1, c - mu), min(ns, c + ml)
                    if (vel_of_row(r) > 0) kt(vel_of_row(r), j) = jb(offset + r - c, c)
                end do
                if (present(cv)) then
                    c = vel(j)
                    do r = max(1, c - mu), min(ns, c + ml)
                        if (vel_of_row(r) > 0) cv(vel_of_row(r), j) = jb(offset + r - c, c)
                    end do
                end if
            end do
        end if
        ! da/dz -> df/dz = M da/dz at rest (the dM/dq a term vanishes at an equilibrium and
        ! is left out elsewhere: Newton on a(q) = 0 in the metric M)
        call scale_by_mass(mm, kt)
        if (present(cv)) call scale_by_mass(mm, cv)
        kt = -kt
        if (present(cv)) cv = -cv
    contains
        !> By central differences in y(k): -dF(vel)/dy(k) of an implicit model, da/dy(k)
        !! (a = ydot(vel)) of an explicit one.
        subroutine differenced(k, out)
            integer, intent(in) :: k
            real(wp), intent(out) :: out(:)
            ! below the shortest length of the force law, a stiff ground's penetration
            ! (docs/theory/statics-modes.md), at a rounding error of ~1e-8 of the result
            h = 1.0e-8_wp*max(1.0_wp, abs(y(k)))
            yp = y
            yp(k) = y(k) + h
            call evaluate(yp, gp, st)
            yp(k) = y(k) - h
            call evaluate(yp, gm, status)
            if (st /= STATUS_OK) status = st
            if (implicit) then
                out = -(gp(vel) - gm(vel))/(2.0_wp*h)
            else
                out = (gp(vel) - gm(vel))/(2.0_wp*h)
            end if
        end subroutine differenced

        !> F(t = 0, z) of the implicit form, or the right-hand side f(0, z).
        subroutine evaluate(z, g, stat)
            real(wp), intent(in) :: z(:)
            real(wp), intent(out) :: g(:)
            integer, intent(out) :: stat
            if (implicit) then
                call model%implicit_rhs(0.0_wp, z, g, stat)
            else
                call model%rhs(0.0_wp, z, g, stat)
            end if
        end subroutine evaluate
    end subroutine tangents

    !> a <- mm a over the band of the symmetric mm (|i - j| <= its bandwidth kd): O(n^2 kd)
    !! where a dense product is O(n^3) (the RFEM's mass in water is block diagonal, kd = 2).
    subroutine scale_by_mass(mm, a)
        real(wp), intent(in) :: mm(:, :)
        real(wp), intent(inout) :: a(:, :)
        real(wp), allocatable :: b(:, :)
        integer :: i, c, kd, n, lo, hi
        n = size(a, 1)
        kd = bandwidth(mm)
        if (kd == 0) then
            do i = 1, n
                a(i, :) = mm(i, i)*a(i, :)
            end do
            return
        end if
        allocate (b(n, size(a, 2)))
        do c = 1, size(a, 2)
            do i = 1, n
                ! mm is symmetric: its column i is row i, read contiguously
                lo = max(1, i - kd)
                hi = min(n, i + kd)
                b(i, c) = dot_product(mm(lo:hi, i), a(lo:hi, c))
            end do
        end do
        a = b
    end subroutine scale_by_mass
end module ropedyn_statics_terms
