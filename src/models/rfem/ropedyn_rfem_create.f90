!> Building an RFEM model from its spec: element lengths and masses, the spring-damping
!! constants, supports, point masses and effects (docs/theory/rfem.md, docs/theory/effects.md).
submodule (ropedyn_rfem) ropedyn_rfem_create
    implicit none

contains

    module procedure rfem_create
        type(section_t) :: sec
        integer :: n

        n = spec%model%elements
        if (n < 2) then
            call make_error(err, ERR_INPUT, 'rfem: elements must be >= 2')
            return
        end if
        model%n = n
        sec = rope_section(spec%rope)
        call set_elements(model, spec, sec)
        call set_joints(model, spec, sec)
        call set_end_sections(model, spec)
        model%init_angle = initial_angle(spec)
        model%folded = spec%initial%shape == 'folded'
        model%init_velocity = spec%initial%velocity
        call set_masses(model, spec)
        call build_body_effects(spec, model%len, model%effects)
        if (size(model%effects) > 0) then
            model%bodies%n = n
            model%bodies%l = model%len
            allocate (model%bodies%c(2, n), model%bodies%phi(n), model%bodies%v(2, n), &
                      model%bodies%w(n), model%bodies%cs(2, n))
        end if
        call set_support_motion(model, spec)

        model%half = 0.5_wp*model%len
        model%weight = merge(model%mass*model%g, 0.0_wp*model%mass, model%gravity_on)
        allocate (model%cs(2, n), model%phi(n), model%gen(3, n), model%gen_r(3, n), &
                  model%blk(3, 6, -1:1, n))
        model%cs = 0.0_wp
        model%gen = 0.0_wp
        model%gen_r = 0.0_wp
        model%blk = 0.0_wp
    end procedure rfem_create

    !> The elements: lengths (half ones at the ends), masses and rotary inertias, gravity.
    subroutine set_elements(model, spec, sec)
        type(rfem_t), intent(inout) :: model
        type(rope_spec_t), intent(in) :: spec
        type(section_t), intent(in) :: sec
        real(wp) :: dl, total_mass
        integer :: n
        n = model%n
        dl = spec%rope%length/real(n - 1, wp)
        total_mass = sec%mass_per_length*spec%rope%length
        allocate (model%len(n), model%mass(n), model%inertia(n))
        model%len = dl
        model%len(1) = dl/2.0_wp
        model%len(n) = dl/2.0_wp
        model%mass = total_mass*model%len/spec%rope%length
        model%inertia = model%mass*(model%len**2/12.0_wp + sec%diameter**2/16.0_wp)
        model%g = spec%rope%gravity
        model%gravity_on = spec%effects%gravity
    end subroutine set_elements

    !> The spring-damping elements: the internal SDEs' constants (a strain exists only when
    !! its effect is on, its damping only when damping is on), the supports' SDEs (a support
    !! released at t <= 0 is free from the start: no SDE at all) and the release times.
    subroutine set_joints(model, spec, sec)
        type(rfem_t), intent(inout) :: model
        type(rope_spec_t), intent(in) :: spec
        type(section_t), intent(in) :: sec
        real(wp) :: dl, cx, cy, cphi, bx, by, bphi, factor
        logical :: damped
        character(len=:), allocatable :: kinds(:)
        integer :: k, n
        n = model%n
        dl = spec%rope%length/real(n - 1, wp)
        damped = spec%effects%damping

        cx = sec%ea/dl
        cy = sec%ga/(sec%shape_factor*dl)
        cphi = sec%ei/dl
        bx = sec%axial_damping/dl
        by = sec%shear_damping/(sec%shape_factor*dl)
        bphi = sec%bending_damping/dl
        factor = spec%supports%support_stiffness_factor
        model%release = [release_time(spec, 1), release_time(spec, 2)]

        model%tension = spec%effects%tension
        model%tension_only = .not. spec%rope%compression
        model%shear = spec%effects%shear
        model%bending = spec%effects%bending
        if (model%tension) model%cx = cx
        if (model%shear) model%cy = cy
        if (model%bending) model%cp = cphi
        if (damped) then
            if (model%tension) model%bx = bx
            if (model%shear) model%by = by
            if (model%bending) model%bp = bphi
        end if
        model%damped = model%bx > 0.0_wp .or. model%by > 0.0_wp .or. model%bp > 0.0_wp
        ! supports: a support released at t <= 0 is free from the start (no SDE at all)
        kinds = [character(len=8) :: spec%supports%top, spec%supports%bottom]
        do k = 1, 2
            associate (sup => model%sup(k))
                sup%sgn = merge(1.0_wp, -1.0_wp, k == 1)
                sup%elem = merge(1, n, k == 1)
                if (released_at_start(spec, k)) cycle
                sup%translational = kinds(k) == 'pinned' .or. kinds(k) == 'clamped'
                sup%rotational = kinds(k) == 'clamped'
                if (sup%translational) then
                    sup%ct = factor*cx
                    sup%bt = factor*bx
                    sup%damped_t = damped .and. sup%bt > 0.0_wp
                end if
                if (sup%rotational) then
                    sup%cr = factor*cphi
                    sup%br = factor*bphi
                    sup%damped_r = damped .and. sup%br > 0.0_wp
                end if
            end associate
        end do
    end subroutine set_joints

    !> The sections next to a clamp (bending) and, with end_compliance = 'split', next to a
    !! pinned end (tension), shared between the support and its neighbour.
    subroutine set_end_sections(model, spec)
        type(rfem_t), intent(inout) :: model
        type(rope_spec_t), intent(in) :: spec
        integer :: k, n
        n = model%n
        ! Bending next to a clamp. SDE j (between elements j-1 and j, at s = (j - 3/2) dl)
        ! lumps the bending of the primary section [(j-2) dl, (j-1) dl] (EI/dl): the
        ! internal SDEs alone cover the whole rope [0, L]. A clamp's rotational SDE at s = 0
        ! on top of them would add one section's compliance dl/EI, an O(dl) error that at
        ! these n is still in its pre-asymptotic range (the clamp's boundary layer
        ! sqrt(EI/T) = 3 cm is resolved only from n ~ 100: observed order 0.6, -0.2 % at
        ! n = 300). Instead the first section is split between the clamp and its neighbour:
        ! [0, dl/2] lumped at the clamp, [dl/2, dl] at SDE 2, each 2 EI/dl (damping alike),
        ! so the compliance adds up to L/EI and each half is lumped at its end (an O(dl^2)
        ! error). Likewise at a clamped bottom. n = 2 with both ends clamped keeps EI/dl.
        allocate (model%cpj(2:n), model%bpj(2:n))
        model%cpj = model%cp
        model%bpj = model%bp
        if (n > 2 .or. .not. all(model%sup%rotational)) then
            do k = 1, 2
                ! (a clamp released later leaves its neighbour at 2 EI/dl)
                if (.not. model%sup(k)%rotational) cycle
                call share_end_section(merge(2, n, k == 1), model%sup(k)%cr, &
                                       model%sup(k)%br, model%cpj, model%bpj)
            end do
        end if

        ! Axial compliance next to a pinned end. The internal SDEs' tension springs (EA/dl)
        ! lump the sections [(j-2) dl, (j-1) dl] and so cover [0, L] alone; a pinned
        ! support's spring (EA/dl) on top of them adds one section's compliance dl/EA at each
        ! end (the paper's model), an O(dl) error: the Bergdahl chain's static fairlead
        ! tension converges at first order, -0.26 % at dl = 0.2 m. With end_compliance =
        ! 'split' the end section is shared as the clamp's bending is: [0, dl/2] at the
        ! support, [dl/2, dl] at SDE 2, each 2 EA/dl (damping alike), the compliance adds up
        ! to L/EA (second order; docs/theory/rfem.md, Strains).
        allocate (model%cxj(2:n), model%bxj(2:n))
        model%cxj = model%cx
        model%bxj = model%bx
        if (n > 2 .and. spec%supports%end_compliance == 'split') then
            do k = 1, 2
                if (.not. model%sup(k)%translational) cycle
                call share_end_section(merge(2, n, k == 1), model%sup(k)%ct, &
                                       model%sup(k)%bt, model%cxj, model%bxj)
            end do
        end if
    end subroutine set_end_sections

    !> Point masses at their place on the elements (mass, inertia about the centre and the
    !! first moment m r that couples translation and rotation), the accelerations' row
    !! scales, and the added mass in water (every element's accelerations from its block).
    subroutine set_masses(model, spec)
        type(rfem_t), intent(inout) :: model
        type(rope_spec_t), intent(in) :: spec
        integer, allocatable :: pm_body(:)
        real(wp), allocatable :: pm_r(:), pm_m(:)
        integer :: k, i, n
        n = model%n
        call attached_masses(spec, model%len, pm_body, pm_r, pm_m)
        allocate (model%pm_elem(0), model%pm_moment(0))
        do k = 1, size(pm_body)
            i = pm_body(k)
            model%mass(i) = model%mass(i) + pm_m(k)
            model%inertia(i) = model%inertia(i) + pm_m(k)*pm_r(k)**2
            if (.not. any(model%pm_elem == i)) then
                model%pm_elem = [model%pm_elem, i]
                model%pm_moment = [model%pm_moment, 0.0_wp]
            end if
            where (model%pm_elem == i) model%pm_moment = model%pm_moment + pm_m(k)*pm_r(k)
        end do
        allocate (model%rowscale(3, n))
        model%rowscale(1, :) = 1.0_wp/model%mass
        model%rowscale(2, :) = 1.0_wp/model%mass
        model%rowscale(3, :) = 1.0_wp/model%inertia
        model%inv_mass = model%rowscale
        model%rowscale(:, model%pm_elem) = 1.0_wp
        ! in water every element's accelerations come from its mass block
        model%water = spec%effects%water
        if (model%water) then
            model%added = water_added_mass(spec)
            model%rowscale = 1.0_wp
            allocate (model%am_blk(3, 3, n), model%am_g(3, n))
            model%am_blk = 0.0_wp
            model%am_g = 0.0_wp
        end if
    end subroutine set_masses

    !> The supports' anchors and angles (a bottom anchor not given: the rope's lower end in
    !! its initial state) and their prescribed motions (a free or released support has
    !! none); whether the model depends on time and does work.
    subroutine set_support_motion(model, spec)
        type(rfem_t), intent(inout) :: model
        type(rope_spec_t), intent(in) :: spec
        real(wp) :: angles(2)
        real(wp), allocatable :: y0(:)
        integer :: n
        n = model%n
        model%sup(1)%anchor = spec%supports%top_anchor
        angles = clamp_angles(spec)
        model%sup(1)%angle = angles(1)
        model%sup(2)%angle = angles(2)
        model%motion(1)%p0 = model%sup(1)%anchor
        model%motion(1)%angle0 = model%sup(1)%angle
        if (bottom_anchor_given(spec)) then
            model%sup(2)%anchor = spec%supports%bottom_anchor
        else
            ! the rope's lower end in its initial state
            allocate (y0(6*n))
            call model%initial_state(y0)
            model%sup(2)%anchor = y0(6*n - 5:6*n - 4) + 0.5_wp*model%len(n)* &
                                  [cos(y0(6*n - 3)), sin(y0(6*n - 3))]
        end if
        model%motion(2)%p0 = model%sup(2)%anchor
        model%motion(2)%angle0 = model%sup(2)%angle
        ! a free or released support has no motion
        if (spec%effects%support_motion) call configure_motions(spec, &
            [spec%supports%top /= 'free', spec%supports%bottom /= 'free'] .and. &
            model%release > 0.0_wp, model%motion, model%moving)
        model%timed = any(model%moving) .or. any(model%release < huge(1.0_wp))
        model%with_work = any_does_work(model%moving, model%effects)
    end subroutine set_support_motion

    !> An end section shared between a support and its neighbour SDE i (at 2:n): the
    !! support's stiffness c_sup and damping b_sup and the neighbour's cj(i), bj(i) doubled,
    !! each then lumping half the section (rfem_create).
    pure subroutine share_end_section(i, c_sup, b_sup, cj, bj)
        integer, intent(in) :: i
        real(wp), intent(inout) :: c_sup, b_sup, cj(2:), bj(2:)
        c_sup = 2.0_wp*c_sup
        b_sup = 2.0_wp*b_sup
        cj(i) = 2.0_wp*cj(i)
        bj(i) = 2.0_wp*bj(i)
    end subroutine share_end_section
end submodule ropedyn_rfem_create
