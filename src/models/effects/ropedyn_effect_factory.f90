!> Builds the external effects a spec enables, for a model whose bodies tile the rope:
!! body i covers the arc lengths [s_i, s_i + l_i] of the unstretched rope from its top end.
!! Only enabled effects are allocated (docs/guide/effects.md, `&effects`).
module ropedyn_effect_factory
    use, intrinsic :: ieee_arithmetic, only: ieee_is_nan
    use ropedyn_kinds, only: wp, PI
    use ropedyn_rope_spec, only: rope_spec_t, N_ATTACH
    use ropedyn_effect, only: effect_box_t
    use ropedyn_effect_drag, only: drag_effect
    use ropedyn_effect_ground, only: ground_effect
    use ropedyn_effect_loads, only: loads_effect_t, point_load_t
    use ropedyn_effect_fault, only: fault_effect_t
    use ropedyn_effect_buoyancy, only: buoyancy_effect
    use ropedyn_wetting, only: wetting_t
    use ropedyn_added_mass, only: added_mass_t
    implicit none
    private
    public :: build_body_effects, locate_on_bodies, attached_masses, water_of, water_added_mass


contains

    !> The body containing arc length s (m) and the offset r (m) of that point from the
    !! body's centre along the body. A point on a joint belongs to the body below it (the
    !! last body for s = L).
    pure subroutine locate_on_bodies(lengths, s, body, r)
        real(wp), intent(in) :: lengths(:)
        real(wp), intent(in) :: s
        integer, intent(out) :: body
        real(wp), intent(out) :: r
        real(wp) :: start
        integer :: i
        start = 0.0_wp
        body = size(lengths)
        do i = 1, size(lengths)
            if (s < start + lengths(i) .or. i == size(lengths)) then
                body = i
                exit
            end if
            start = start + lengths(i)
        end do
        r = s - (start + 0.5_wp*lengths(body))
    end subroutine locate_on_bodies

    !> The effects of a spec acting on bodies of the given lengths (m): drag, ground contact,
    !! point loads, each only when enabled and given, and the testing aid's NaN forces.
    subroutine build_body_effects(spec, lengths, effects)
        type(rope_spec_t), intent(in) :: spec
        real(wp), intent(in) :: lengths(:)
        type(effect_box_t), allocatable, intent(out) :: effects(:)
        type(loads_effect_t) :: loads
        integer :: n_eff, k, m, j
        logical :: with_loads

        with_loads = .false.
        if (spec%effects%point_loads) &
            with_loads = any(.not. ieee_is_nan(spec%attachments%load_positions))
        n_eff = count([spec%effects%drag, spec%effects%ground, with_loads, &
                       spec%effects%fault_nan_after >= 0.0_wp, buoyant(spec)])
        allocate (effects(n_eff))
        k = 0
        if (spec%effects%drag) then
            k = k + 1
            associate (f => spec%fluid)
                if (spec%effects%water) then
                    allocate (effects(k)%e, source=drag_effect(f%density, &
                        f%normal_drag_coefficient, f%tangential_drag_coefficient, &
                        f%linear_normal_drag, f%linear_tangential_drag, f%current, &
                        spec%rope%diameter, water_of(spec)))
                else
                    allocate (effects(k)%e, source=drag_effect(f%density, &
                        f%normal_drag_coefficient, f%tangential_drag_coefficient, &
                        f%linear_normal_drag, f%linear_tangential_drag, f%current, &
                        spec%rope%diameter))
                end if
            end associate
        end if
        if (buoyant(spec)) then
            k = k + 1
            allocate (effects(k)%e, source=buoyancy_effect(spec%fluid%density, &
                spec%rope%gravity, pi*spec%rope%diameter**2/4.0_wp, water_of(spec)))
        end if
        if (spec%effects%ground) then
            k = k + 1
            associate (g => spec%ground)
                allocate (effects(k)%e, source=ground_effect(g%point, g%normal, g%stiffness, &
                    g%damping, g%friction_coefficient, g%friction_regularization_speed))
            end associate
        end if
        if (with_loads) then
            k = k + 1
            associate (a => spec%attachments)
                allocate (loads%loads(count(.not. ieee_is_nan(a%load_positions))))
                m = 0
                do j = 1, N_ATTACH
                    if (ieee_is_nan(a%load_positions(j))) cycle
                    m = m + 1
                    call locate_on_bodies(lengths, a%load_positions(j), loads%loads(m)%body, &
                                          loads%loads(m)%r)
                    loads%loads(m)%f0 = [a%load_force_x(j), a%load_force_y(j)]
                    loads%loads(m)%amplitude = [a%load_amplitude_x(j), a%load_amplitude_y(j)]
                    loads%loads(m)%omega = 2.0_wp*pi*a%load_frequency(j)
                    loads%loads(m)%phase = a%load_phase_deg(j)*pi/180.0_wp
                end do
            end associate
            allocate (effects(k)%e, source=loads)
        end if
        if (spec%effects%fault_nan_after >= 0.0_wp) &
            allocate (effects(n_eff)%e, source=fault_effect_t(spec%effects%fault_nan_after))
    end subroutine build_body_effects

    !> Whether the spec's rope floats in water that pushes it up: water and gravity on.
    pure logical function buoyant(spec)
        type(rope_spec_t), intent(in) :: spec
        buoyant = spec%effects%water .and. spec%effects%gravity .and. spec%rope%gravity > 0.0_wp
    end function buoyant

    !> Where the spec's water is: the free surface of &fluid, the step smoothed over half
    !! the rope's (hydrodynamic) diameter, the thickness with which a section crosses it.
    pure function water_of(spec) result(w)
        type(rope_spec_t), intent(in) :: spec
        type(wetting_t) :: w
        w%surface = spec%fluid%surface
        w%delta = 0.5_wp*spec%rope%diameter
    end function water_of

    !> The water's added mass on the spec's bodies (with `&effects water`; zero added mass
    !! without): normal C_a rho A and tangential C_at rho A per metre, A = pi d^2/4, with
    !! the current of &fluid.
    pure function water_added_mass(spec) result(am)
        type(rope_spec_t), intent(in) :: spec
        type(added_mass_t) :: am
        real(wp) :: area
        if (.not. spec%effects%water) return
        area = pi*spec%rope%diameter**2/4.0_wp
        am%man = spec%fluid%added_mass_coefficient*spec%fluid%density*area
        am%mat = spec%fluid%tangential_added_mass_coefficient*spec%fluid%density*area
        am%u = spec%fluid%current
        am%wetting = water_of(spec)
    end function water_added_mass

    !> The point masses of a spec (none when `&effects point_masses` is off): for each, the
    !! body, the offset r (m) from the body's centre along it, and the mass (kg).
    subroutine attached_masses(spec, lengths, body, r, mass)
        type(rope_spec_t), intent(in) :: spec
        real(wp), intent(in) :: lengths(:)
        integer, allocatable, intent(out) :: body(:)
        real(wp), allocatable, intent(out) :: r(:), mass(:)
        integer :: k, m, n
        n = 0
        if (spec%effects%point_masses) &
            n = count(.not. ieee_is_nan(spec%attachments%mass_positions))
        allocate (body(n), r(n), mass(n))
        m = 0
        if (n == 0) return
        do k = 1, N_ATTACH
            if (ieee_is_nan(spec%attachments%mass_positions(k))) cycle
            m = m + 1
            call locate_on_bodies(lengths, spec%attachments%mass_positions(k), body(m), r(m))
            mass(m) = spec%attachments%masses(k)
        end do
    end subroutine attached_masses
end module ropedyn_effect_factory
