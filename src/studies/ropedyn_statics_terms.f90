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
    use ropedyn_kinds, only: wp, PI
    use ropedyn_problem, only: STATUS_OK
    use ropedyn_rope_model, only: rope_model_t, energy_t
    use ropedyn_rope_spec, only: rope_spec_t, N_ATTACH
    use ropedyn_effect_factory, only: locate_on_bodies
    use ropedyn_ldl, only: band_matvec
    implicit none
    private
    public :: generalized_force, tangent_matrices, potential_energy, rope_length, total_weight
    public :: tangent_band, tangent_bandwidth, at_rest_near


contains

    !> An equilibrium y at rest: its velocities zeroed and, where that changes no force,
    !! each angle brought within pi of q0, where the iteration that found it started it. A
    !! step may turn an element by whole turns; where the model sees its angle only through
    !! its cosine and sine (a chain's links, no bending) that changes nothing but the angle's
    !! value, which the error weights of a run started there would see. A spring on the
    !! difference of two angles (bending, a clamp) sees the turn: its energy changes by about
    !! 2 pi^2 times its stiffness, and the turns are then kept. Taken off only when the
    !! elastic energy changes by no more than its rounding (TURN_ROUNDING eps times the
    !! elastic and gravity energies; gravity and the loads see the positions alone). f: the
    !! generalized force at y (at rest) on entry, at the y returned on exit.
    subroutine at_rest_near(model, y, pos, vel, q0, f)
        class(rope_model_t), intent(inout) :: model
        real(wp), intent(inout) :: y(:)
        integer, intent(in) :: pos(:), vel(:)
        real(wp), intent(in) :: q0(:)
        real(wp), intent(inout) :: f(:)
        real(wp), parameter :: TWO_PI = 2.0_wp*PI, TURN_ROUNDING = 1.0e3_wp
        logical, allocatable :: angle(:)
        real(wp), allocatable :: turned(:), f_turned(:)
        type(energy_t) :: e, e_turned
        integer :: k, status
        y(vel) = 0.0_wp
        angle = model%angle_coordinates()
        turned = y
        do k = 1, size(pos)
            if (angle(k)) turned(pos(k)) = y(pos(k)) - TWO_PI*anint((y(pos(k)) - q0(k))/TWO_PI)
        end do
        if (all(turned == y)) return
        e = rest_energy(model, y)
        e_turned = rest_energy(model, turned)
        if (abs(e_turned%elastic - e%elastic) > TURN_ROUNDING*epsilon(1.0_wp)* &
            (abs(e%elastic) + abs(e%gravity))) return
        allocate (f_turned(size(f)))
        call generalized_force(model, turned, pos, vel, f_turned, status)
        if (status /= STATUS_OK) return
        y = turned
        f = f_turned
    end subroutine at_rest_near

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
        e = rest_energy(model, y)
        v = e%elastic + e%gravity
        if (present(spec)) v = v + load_potential(model, spec, y)
    end function potential_energy

    !> The model's energies at state y with its supports at rest (no quadratures), J.
    type(energy_t) function rest_energy(model, y) result(e)
        class(rope_model_t), intent(inout) :: model
        real(wp), intent(in) :: y(:)
        real(wp) :: yq(max(1, model%quad_size()))
        logical :: held
        yq = 0.0_wp
        held = model%supports_at_rest
        model%supports_at_rest = .true.
        e = model%energy(0.0_wp, y, yq)
        model%supports_at_rest = held
    end function rest_energy

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
        real(wp), allocatable :: w(:), mb(:, :)
        logical :: held
        held = model%supports_at_rest
        model%supports_at_rest = .true.
        allocate (w(size(y)))
        if (model%has_mass_matrix()) then
            call model%implicit_rhs(0.0_wp, y, w, status)
            f = w(vel)
        else
            call model%rhs(0.0_wp, y, w, status)
            allocate (mb(0:model%mass_bandwidth(), size(pos)))
            call model%coordinate_mass_band(y, mb)
            f = band_matvec(mb, w(vel))
        end if
        if (status == STATUS_OK .and. .not. all(ieee_is_finite(f))) status = -1
        model%supports_at_rest = held
    end subroutine generalized_force

    !> The bandwidth of the tangent matrices of `tangent_band`: dense (size(pos) - 1) when
    !! they are differenced or the model is linearly implicit, else that of the model's
    !! second-order blocks plus that of its mass (K = -M da/dq).
    integer function tangent_bandwidth(model) result(kd)
        class(rope_model_t), intent(in) :: model
        integer, allocatable :: pos(:), vel(:)
        integer :: kl, ku
        call model%coordinates(pos, vel)
        kd = size(pos) - 1
        if (model%has_mass_matrix() .or. .not. model%has_jacobian()) return
        call model%second_order_layout(pos, vel, kl, ku)
        kd = min(kd, max(kl, ku) + model%mass_bandwidth())
    end function tangent_bandwidth

    !> Tangent stiffness kt = -df/dq and, if present, damping cv = -df/dq' at state y, dense
    !! (`hessian`: as tangent_band's).
    subroutine tangent_matrices(model, y, pos, vel, kt, status, cv, hessian)
        class(rope_model_t), intent(inout) :: model
        real(wp), intent(in) :: y(:)
        integer, intent(in) :: pos(:), vel(:)
        real(wp), intent(out) :: kt(:, :)
        integer, intent(out) :: status
        real(wp), intent(out), optional :: cv(:, :)
        logical, intent(in), optional :: hessian
        real(wp), allocatable :: kb(:, :), cb(:, :)
        integer :: kd
        kd = tangent_bandwidth(model)
        allocate (kb(-kd:kd, size(pos)))
        if (present(cv)) then
            allocate (cb(-kd:kd, size(pos)))
            call tangent_band(model, y, pos, vel, kd, kb, status, cb, hessian)
            cv = dense_of(cb)
        else
            call tangent_band(model, y, pos, vel, kd, kb, status, hessian=hessian)
        end if
        kt = dense_of(kb)
    end subroutine tangent_matrices

    !> The square matrix of a band b(-kd:kd, n), b(i - j, j) = a(i, j).
    pure function dense_of(b) result(a)
        real(wp), intent(in) :: b(:, :)
        real(wp) :: a(size(b, 2), size(b, 2))
        integer :: i, j, n, kd
        n = size(b, 2)
        kd = (size(b, 1) - 1)/2
        a = 0.0_wp
        do j = 1, n
            do i = max(1, j - kd), min(n, j + kd)
                a(i, j) = b(kd + 1 + i - j, j)
            end do
        end do
    end function dense_of

    !> tangent_matrices in band storage: kb(i - j, j) = K_ij for |i - j| <= kd, kb(-kd:kd,
    !! size(pos)) with kd = `tangent_bandwidth` (and cb likewise for C). With `hessian`
    !! (the equilibrium iterations) K = -df/dq, the Hessian of V, also away from an
    !! equilibrium: it adds -(dM/dq) a (add_mass_slope) to -M da/dq, the linearization of
    !! the motion there, which the modes keep (the two agree at an equilibrium; at one
    !! found to the rounding level the motion's is the closer: a chain in water's lowest
    !! frequency 7e-8 from its closed form, 1e-6 with the Hessian).
    subroutine tangent_band(model, y, pos, vel, kd, kb, status, cb, hessian)
        class(rope_model_t), intent(inout) :: model
        real(wp), intent(in) :: y(:)
        integer, intent(in) :: pos(:), vel(:)
        integer, intent(in) :: kd
        real(wp), intent(out) :: kb(-kd:, :)
        integer, intent(out) :: status
        real(wp), intent(out), optional :: cb(-kd:, :)
        logical, intent(in), optional :: hessian
        logical :: held
        held = model%supports_at_rest
        model%supports_at_rest = .true.
        call tangents(model, y, pos, vel, kd, kb, status, cb, hessian)
        model%supports_at_rest = held
    end subroutine tangent_band

    !> tangent_band with the supports as the model has them.
    subroutine tangents(model, y, pos, vel, kd, kb, status, cb, hessian)
        class(rope_model_t), intent(inout) :: model
        real(wp), intent(in) :: y(:)
        integer, intent(in) :: pos(:), vel(:)
        integer, intent(in) :: kd
        real(wp), intent(out) :: kb(-kd:, :)
        integer, intent(out) :: status
        real(wp), intent(out), optional :: cb(-kd:, :)
        logical, intent(in), optional :: hessian   !< K = -df/dq (tangent_band)
        real(wp), allocatable :: mb(:, :), ka(:, :), ca(:, :), yp(:), gp(:), gm(:)
        real(wp), allocatable :: col(:), unit_mass(:, :)
        integer, allocatable :: lpos(:), lvel(:)
        integer :: nd, ns, kl, ku, ja, j, st
        real(wp) :: h
        logical :: implicit

        nd = size(pos)
        ns = size(y)
        status = STATUS_OK
        implicit = model%has_mass_matrix()
        if (implicit .or. .not. model%has_jacobian()) then
            ! central differences: of f = F(vel) of the implicit form (F is cheap, O(n)), or
            ! of the accelerations of an explicit model without a Jacobian (dense)
            allocate (yp(ns), gp(ns), gm(ns), col(nd))
            ja = merge(kd, nd - 1, implicit)
            allocate (ka(-ja:ja, nd))
            if (present(cb)) allocate (ca(-ja:ja, nd))
            do j = 1, nd
                call differenced(pos(j), col)
                if (status /= STATUS_OK) return
                call store_column(ka, ja, j, col)
                if (present(cb)) then
                    call differenced(vel(j), col)
                    if (status /= STATUS_OK) return
                    call store_column(ca, ja, j, col)
                end if
            end do
            if (implicit) then
                kb = ka
                if (present(cb)) cb = ca
                return
            end if
        else
            call model%second_order_layout(lpos, lvel, kl, ku)
            ja = max(kl, ku)
            allocate (ka(-ja:ja, nd), ca(-ja:ja, nd), unit_mass(-ja:ja, nd))
            ka = 0.0_wp
            ca = 0.0_wp
            unit_mass = 0.0_wp
            ! entry (i, j) at row ja + 1 + i - j of the (2 ja + 1, nd) arrays: ka(i - j, j)
            call model%second_order_blocks(0.0_wp, y, .false., ka, ca, unit_mass, ja + 1, &
                                           status)
            if (status /= STATUS_OK) return
        end if
        ! da/dz -> M da/dz, and for the Hessian df/dz = M da/dz + (dM/dq) a at rest (the
        ! second term vanishes at an equilibrium; add_mass_slope)
        allocate (mb(0:model%mass_bandwidth(), nd))
        call model%coordinate_mass_band(y, mb)
        call mass_times(mb, ubound(mb, 1), ka, ja, kb, kd)
        kb = -kb
        if (present(hessian)) then
            if (hessian) call add_mass_slope(model, y, pos, vel, kd, kb, status)
            if (status /= STATUS_OK) return
        end if
        if (present(cb)) then
            call mass_times(mb, ubound(mb, 1), ca, ja, cb, kd)
            cb = -cb
        end if
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

    !> kb -= (dM/dq) a, a = ydot(vel) the accelerations at y (an explicit model, f = M a):
    !! the part of K = -df/dq that a mass depending on the configuration adds (the RFEM's
    !! point masses off the element centres, water's added mass). Away from an equilibrium
    !! K without it is not the Hessian of V: on a chain with 7.57 kg off its element's
    !! centre (test_statics) its curvature along the chain's swing was 3.5e-12 N m where the
    !! Hessian's is 2.9e-2, and the statics' steps were held to about 1e-4 for over a
    !! thousand iterations. By central differences of the mass, the coordinates perturbed
    !! together in 2 km + 1 colours (km the mass's bandwidth: q_j changes only the rows of
    !! its element, within km of j). A constant mass differences to zero: kb unchanged.
    subroutine add_mass_slope(model, y, pos, vel, kd, kb, status)
        class(rope_model_t), intent(inout) :: model
        real(wp), intent(in) :: y(:)
        integer, intent(in) :: pos(:), vel(:), kd
        real(wp), intent(inout) :: kb(-kd:, :)
        integer, intent(out) :: status
        real(wp), parameter :: H = 1.0e-6_wp   !< m or rad: the mass is smooth in q
        real(wp), allocatable :: ydot(:), a(:), yp(:), ym(:), mp(:, :), mm(:, :), g(:)
        integer :: km, nd, colour, j, i
        nd = size(pos)
        km = model%mass_bandwidth()
        allocate (ydot(size(y)), mp(0:km, nd), mm(0:km, nd))
        call model%rhs(0.0_wp, y, ydot, status)
        if (status /= STATUS_OK) return
        a = ydot(vel)
        do colour = 1, 2*km + 1
            yp = y
            ym = y
            do j = colour, nd, 2*km + 1
                yp(pos(j)) = y(pos(j)) + H
                ym(pos(j)) = y(pos(j)) - H
            end do
            call model%coordinate_mass_band(yp, mp)
            call model%coordinate_mass_band(ym, mm)
            g = band_matvec((mp - mm)/(2.0_wp*H), a)
            do j = colour, nd, 2*km + 1
                do i = max(1, j - min(km, kd)), min(nd, j + min(km, kd))
                    kb(i - j, j) = kb(i - j, j) - g(i)
                end do
            end do
        end do
    end subroutine add_mass_slope

    !> Column j of a matrix into its band b(-kd:kd, n) (the entries outside the band are
    !! dropped: they are zero).
    pure subroutine store_column(b, kd, j, col)
        integer, intent(in) :: kd, j
        real(wp), intent(inout) :: b(-kd:, :)
        real(wp), intent(in) :: col(:)
        integer :: i, n
        n = size(col)
        b(:, j) = 0.0_wp
        do i = max(1, j - kd), min(n, j + kd)
            b(i - j, j) = col(i)
        end do
    end subroutine store_column

    !> c = M a for the symmetric M in lower band storage mb(0:km, n) and a, c in band
    !! storage (-ka:ka, n), (-kc:kc, n): O(n km ka) where a dense product is O(n^3) (the
    !! RFEM's mass is block diagonal, km = 2). Entries of the product outside c's band are
    !! dropped (kc >= km + ka keeps them all).
    pure subroutine mass_times(mb, km, a, ka, c, kc)
        integer, intent(in) :: km, ka, kc
        real(wp), intent(in) :: mb(0:, :)
        real(wp), intent(in) :: a(-ka:, :)
        real(wp), intent(out) :: c(-kc:, :)
        integer :: i, j, k, n
        real(wp) :: mik
        n = size(mb, 2)
        c = 0.0_wp
        do j = 1, n
            do k = max(1, j - ka), min(n, j + ka)
                if (a(k - j, j) == 0.0_wp) cycle
                do i = max(1, k - km, j - kc), min(n, k + km, j + kc)
                    if (i >= k) then
                        mik = mb(i - k, k)
                    else
                        mik = mb(k - i, i)
                    end if
                    c(i - j, j) = c(i - j, j) + mik*a(k - j, j)
                end do
            end do
        end do
    end subroutine mass_times
end module ropedyn_statics_terms
