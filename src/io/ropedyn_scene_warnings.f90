!> Warnings for a scene whose values are legal but probably a unit slip: a diameter in mm (more
!! than a tenth of the length), a modulus or stiffness in the wrong unit (the static strain under
!! the rope's own weight and its point masses above 10 %), a damping coefficient in the wrong unit
!! (an element's axial damping ratio below 1e-6 or above 1000), air's density for water, a straight
!! start or a support's anchor inside the ground (x points down: a ground point in the wrong sign;
!! an anchor deeper than ten times the rope's own sinking),
!! a key of a support's motion that its `*_motion` does not use (a harmonic key or a table with
!! another motion), a release or a ramp that the run ends before, a key of &ground or &fluid set
!! away from its default while the effects that use it are off (a ground or a water given and not
!! switched on; a current or drag keys under water without drag), a line lighter than 10 kg/m^3 (a
!! diameter in mm on a long line), a support_stiffness_factor that scales the rope's own end
!! section (a clamp, a 'split' end), anchors further apart than the rope can reach without
!! stretching by more than 10 %, a ground so soft that the rope's weight sinks it deeper than a
!! thousandth of its length (a stiffness in kN/m^2?), a friction coefficient above 1 (a
!! percentage?). Each warning names the key, its value and why; a run goes ahead.
module ropedyn_scene_warnings
    use, intrinsic :: iso_fortran_env, only: error_unit
    use, intrinsic :: ieee_arithmetic, only: ieee_is_nan
    use ropedyn_kinds, only: wp
    use ropedyn_text, only: text_t, append_text, real_text, significant_text, pair_text, &
        int_text
    use ropedyn_rope_section, only: section_t, rope_section, section_set_given
    use ropedyn_scene_types, only: scene_t
    use ropedyn_rope_spec, only: bottom_anchor_given
    use ropedyn_rope_setup, only: initial_angle
    use ropedyn_support_motion, only: ramp
    use ropedyn_scene_key, only: scene_key_t
    use ropedyn_scene_keys, only: bind_keys, GROUP_NAMES, G_FLUID, G_GROUND
    implicit none
    private
    public :: scene_warnings, print_warnings

    !> The bounds of the checks.
    real(wp), parameter :: MAX_DIAMETER_SHARE = 0.1_wp   !< of the length
    real(wp), parameter :: MAX_SELF_STRAIN = 0.1_wp      !< under the rope's own weight
    !> the stretch a line held at both ends needs to reach its anchors (their distance over
    !! the length, less 1): a taut mooring leg stretches by a few per cent, a chain or wire
    !! breaks near 1 to 2 %
    real(wp), parameter :: MAX_REACH_STRAIN = 0.1_wp
    !> an element's axial damping ratio (as computed below) grows with n: the paper's rope
    !! with its heavy damping reading has 0.032 at n = 30 and 10.9 at n = 10,000 (10, the
    !! issue's example, warned there); a coefficient in N s/m^2 given as N s, or the
    !! reverse, is off by the section area, 1e4 .. 1e8 for ropes
    real(wp), parameter :: MIN_DAMPING_RATIO = 1.0e-6_wp, MAX_DAMPING_RATIO = 1.0e3_wp
    real(wp), parameter :: MIN_WATER_DENSITY = 100.0_wp  !< kg/m^3
    !> a line's mean density mass_per_length/(pi d^2/4), kg/m^3: a diameter in mm makes the
    !! area 1e6 times too large, so a steel or fibre line's 1000 .. 8000 becomes 1e-3 ..
    !! 1e-2 (in cm: 0.1 .. 0.8), a slip the tenth of the length misses on a long line (12
    !! for 12 mm on a 200 m cable); lines with floats or air in them stay above 100
    real(wp), parameter :: MIN_LINE_DENSITY = 10.0_wp
    !> a straight start may touch the ground (a rope laid on the seabed) but not reach
    !! deeper into it than this share of its length
    real(wp), parameter :: MAX_START_DEPTH_SHARE = 1.0e-3_wp
    !> a Coulomb coefficient of a rope or chain on the ground lies between 0.1 and 1 (a
    !! chain across a seabed about 1, along it 0.7); 60 for 0.6 is a percentage
    real(wp), parameter :: MAX_FRICTION_COEFFICIENT = 1.0_wp
    !> an anchor may lie in the ground by up to this many times the depth w/k the rope's
    !! weight sinks it: deeper, the contact pushes the rope up against the anchor by more
    !! than ten times its weight per metre (a 100 m chain of 981 N/m on k = 1e7 N/m^2,
    !! w/k = 0.1 mm, its anchor's force 53.8 kN along the seabed and 0.3 kN across it on
    !! the seabed; across it 2.8 kN 1 mm deep, 19 kN 1 cm, 88 kN 5 cm, all within the
    !! thousandth of the length)
    real(wp), parameter :: ANCHOR_SINK_FACTOR = 10.0_wp

contains

    !> Print the scene's warnings on stderr, each once: 'ropedyn: warning: ...'.
    subroutine print_warnings(scene)
        type(scene_t), intent(in) :: scene
        type(text_t), allocatable :: list(:)
        integer :: k
        list = scene_warnings(scene)
        do k = 1, size(list)
            write (error_unit, '(a)') 'ropedyn: warning: '//list(k)%s
        end do
    end subroutine print_warnings

    !> The warnings of a checked scene, each one line: 'FILE: &group: key = value: why'.
    function scene_warnings(scene) result(list)
        type(scene_t), intent(in) :: scene
        type(text_t), allocatable :: list(:)
        type(section_t) :: sec
        real(wp) :: strain, dl, zeta, payload
        logical :: section
        allocate (list(0))
        sec = rope_section(scene%rope)
        section = section_set_given(scene%rope)
        if (scene%rope%diameter > MAX_DIAMETER_SHARE*scene%rope%length) &
            call append_text(list, at('diameter')//'diameter = '//real_text(scene%rope%diameter)// &
                ': more than a tenth of the length ('//real_text(scene%rope%length)// &
                ' m): a diameter in mm? (the unit is m)')
        call light_line(scene, sec, section, list)
        if (scene%effects%gravity .and. scene%effects%tension) then
            ! the top section carries the rope and its point masses (a crane's payload)
            payload = 0.0_wp
            if (scene%effects%point_masses) payload = sum(scene%attachments%masses, &
                mask=.not. ieee_is_nan(scene%attachments%mass_positions))
            strain = (sec%mass_per_length*scene%rope%length + payload)* &
                     scene%rope%gravity/sec%ea
            if (strain > MAX_SELF_STRAIN) call append_text(list, &
                at(trim(merge('axial_stiffness', 'young_modulus  ', section)))// &
                trim(merge('axial_stiffness', 'young_modulus  ', section))//' = '// &
                stiffness_text()//': the rope stretches by '// &
                significant_text(100.0_wp*strain, 3)//' % under its own weight'// &
                trim(merge(' and its point masses ((m L + M) g / EA)', &
                           ' (m g L / EA)                           ', payload > 0.0_wp))// &
                ': '//trim(merge('EA in kN?        ', 'a modulus in GPa?', section))// &
                ' (the unit is '//trim(merge('N ', 'Pa', section))//')')
        end if
        if (scene%effects%damping .and. scene%effects%tension .and. sec%axial_damping > 0.0_wp) &
            then
            dl = scene%rope%length/real(max(1, scene%model%elements - 1), wp)
            if (scene%model%kind == 'mpp') dl = scene%rope%length/real(scene%model%elements, wp)
            ! B/(2 sqrt(K m)) of an element: B = eta_a/dl, K = EA/dl, m = mu dl
            zeta = sec%axial_damping/(2.0_wp*dl*sqrt(sec%ea*sec%mass_per_length))
            if (zeta < MIN_DAMPING_RATIO .or. zeta > MAX_DAMPING_RATIO) call append_text(list, &
                at(trim(merge('axial_damping ', 'normal_damping', section)))// &
                trim(merge('axial_damping ', 'normal_damping', section))//' = '// &
                damping_text()//": an element's axial damping ratio is "// &
                significant_text(zeta, 3)//' (plausible: '//real_text(MIN_DAMPING_RATIO)// &
                ' .. '//real_text(MAX_DAMPING_RATIO)//'): a coefficient in the wrong unit? '// &
                '(the unit is '//trim(merge('N s    ', 'N s/m^2', section))//')')
        end if
        if (scene%effects%water) call water_slips(scene, list)
        if (scene%effects%ground) call ground_start(scene, list)
        if (scene%effects%ground) call ground_anchors(scene, sec, list)
        if (scene%effects%ground) call ground_law(scene, sec, list)
        call anchor_reach(scene, sec, list)
        call idle_groups(scene, list)
        call shared_section_factor(scene, sec, list)
        call tolerance_below_rounding(scene, list)
        ! a start that sets the velocities itself (at rest, or the record's)
        associate (i => scene%initial)
            if (any(i%velocity /= 0.0_wp) .and. (i%shape == 'equilibrium' .or. &
                i%shape == 'mode' .or. i%shape == 'state')) call append_text(list, &
                scene%origin('initial.velocity')//': &initial: velocity = '// &
                pair_text(i%velocity)//": does nothing: shape = '"//trim(i%shape)//"' "// &
                trim(merge('starts from the record''s velocities', &
                           'starts at rest                     ', &
                           i%shape == 'state'))//' (it is used with the shapes straight, '// &
                'hanging and folded)')
        end associate
        associate (s => scene%supports)
            call idle_motion_keys(scene, 'top', s%top_motion, s%top_amplitude, &
                s%top_frequency, s%top_phase_deg, s%top_angle_amplitude_deg, &
                s%top_angle_phase_deg, s%top_ramp_time, s%top_table, list)
            call idle_motion_keys(scene, 'bottom', s%bottom_motion, s%bottom_amplitude, &
                s%bottom_frequency, s%bottom_phase_deg, s%bottom_angle_amplitude_deg, &
                s%bottom_angle_phase_deg, s%bottom_ramp_time, s%bottom_table, list)
            call late_motion(scene, 'top', s%top_motion, s%top_ramp_time, &
                s%top_release_time, scene%solver%t_end, list)
            call late_motion(scene, 'bottom', s%bottom_motion, s%bottom_ramp_time, &
                s%bottom_release_time, scene%solver%t_end, list)
        end associate
    contains
        !> 'ORIGIN: &rope: ', ORIGIN where the &rope key `key` was given
        function at(key) result(text)
            character(len=*), intent(in) :: key
            character(len=:), allocatable :: text
            text = scene%origin('rope.'//key)//': &rope: '
        end function at

        function stiffness_text() result(text)
            character(len=:), allocatable :: text
            if (section) then
                text = real_text(scene%rope%axial_stiffness)
            else
                text = real_text(scene%rope%young_modulus)
            end if
        end function stiffness_text

        function damping_text() result(text)
            character(len=:), allocatable :: text
            if (section) then
                text = real_text(scene%rope%axial_damping)
            else
                text = real_text(scene%rope%normal_damping)
            end if
        end function damping_text
    end function scene_warnings

    !> With water on: air's density for water's, and a current without drag (it drags
    !! nothing; it moves only the water's added mass).
    subroutine water_slips(scene, list)
        type(scene_t), intent(in) :: scene
        type(text_t), allocatable, intent(inout) :: list(:)
        if (scene%fluid%density < MIN_WATER_DENSITY) &
            call append_text(list, scene%origin('fluid.density')//': &fluid: density = '// &
                real_text(scene%fluid%density)//': water = .true. in a fluid this light '// &
                '(air is 1.225 kg/m^3): water is about 1000 (fresh) or 1025 (sea)')
        if (.not. scene%effects%drag .and. any(scene%fluid%current /= 0.0_wp)) &
            call append_text(list, scene%origin('fluid.current')//': &fluid: current = '// &
            pair_text(scene%fluid%current)//': effects.drag is .false.: the current drags '// &
            'nothing (it moves only the water''s added mass); a rope in a current needs '// &
            'effects.drag = .true.')
    end subroutine water_slips

    !> A line given by its section set whose mean density mass_per_length/(pi d^2/4) is
    !! below MIN_LINE_DENSITY while drag or water uses its diameter: a diameter in mm on a
    !! line long enough that the tenth of its length (warned of before, and then not here)
    !! misses it. Its buoyancy and drag are then a million times too large.
    subroutine light_line(scene, sec, section, list)
        type(scene_t), intent(in) :: scene
        type(section_t), intent(in) :: sec
        logical, intent(in) :: section   !< the section set is given
        type(text_t), allocatable, intent(inout) :: list(:)
        real(wp) :: density
        if (.not. section .or. .not. (scene%effects%drag .or. scene%effects%water)) return
        if (scene%rope%diameter > MAX_DIAMETER_SHARE*scene%rope%length) return
        density = sec%mass_per_length/sec%area
        if (.not. density < MIN_LINE_DENSITY) return
        call append_text(list, scene%origin('rope.diameter')//': &rope: diameter = '// &
            real_text(scene%rope%diameter)//': the line''s mean density, mass_per_length / '// &
            '(pi d^2/4), is '//significant_text(density, 3)//' kg/m^3 (a real line''s is 100 '// &
            'or more): a diameter in mm? (the unit is m)')
    end subroutine light_line

    !> A support_stiffness_factor other than 1 where a support's spring is the rope's own
    !! end section (docs/theory/rfem.md, "Supports"): a clamp's rotational spring (its
    !! first half section in bending) and, with end_compliance = 'split', a held end's
    !! spring (its half section in tension; the MPP's top is an ideal pin). The factor
    !! stiffens that section too: a first-order error, where it is meant for the added pins.
    subroutine shared_section_factor(scene, sec, list)
        type(scene_t), intent(in) :: scene
        type(section_t), intent(in) :: sec
        type(text_t), allocatable, intent(inout) :: list(:)
        character(len=:), allocatable :: ends
        associate (s => scene%supports)
            if (s%support_stiffness_factor == 1.0_wp) return
            ends = ''
            call shared_end('top', s%top, s%top_release_time, scene%model%kind /= 'mpp')
            call shared_end('bottom', s%bottom, s%bottom_release_time, .true.)
            if (len(ends) == 0) return
            call append_text(list, scene%origin('supports.support_stiffness_factor')// &
                ': &supports: support_stiffness_factor = '// &
                real_text(s%support_stiffness_factor)//': it scales the rope''s own end '// &
                'section too at the '//ends//' (an error that shrinks only as the element '// &
                'length); keep it at 1 with a clamp and with end_compliance = ''split'' (it '// &
                'is meant for the springs a pin adds)')
        end associate
    contains
        !> Add END's name to `ends` when its support shares the rope's end section.
        subroutine shared_end(end, kind, release_time, spring)
            character(len=*), intent(in) :: end, kind
            real(wp), intent(in) :: release_time
            logical, intent(in) :: spring     !< a pinned END has a spring of its own
            character(len=:), allocatable :: how
            if (kind == 'free' .or. release_time == 0.0_wp) return
            how = ''
            if (kind == 'clamped' .and. sec%ei > 0.0_wp) how = 'clamped '
            if (scene%supports%end_compliance == 'split' .and. spring .and. &
                scene%effects%tension) how = trim(merge('split pinned ', 'split clamped', &
                                                        kind == 'pinned'))//' '
            if (len(how) == 0) return
            if (len(ends) > 0) ends = ends//' and the '
            ends = ends//how//end
        end subroutine shared_end
    end subroutine shared_section_factor

    !> A relative tolerance below what double precision resolves: a step's error estimate
    !! is then rounding noise, no method meets the tolerance, and the steps shrink to the
    !! rounding limit until the step budget runs out (rtol 1e-20 on the paper's rope: a
    !! million steps for the first 5e-8 s).
    subroutine tolerance_below_rounding(scene, list)
        type(scene_t), intent(in) :: scene
        type(text_t), allocatable, intent(inout) :: list(:)
        real(wp), parameter :: LEAST_RTOL = 100.0_wp*epsilon(1.0_wp)
        if (scene%solver%rtol >= LEAST_RTOL) return
        call append_text(list, scene%origin('solver.rtol')//': &solver: rtol = '// &
            real_text(scene%solver%rtol)//': below what double precision resolves ('// &
            significant_text(LEAST_RTOL, 2)//', 100 times its rounding unit): no method '// &
            'meets it, and its steps shrink to the rounding limit')
    end subroutine tolerance_below_rounding

    !> The first key of the `end` support's motion that its motion does not use: a harmonic
    !! key (amplitude, frequency, phase, angle amplitude and phase, ramp) other than 0 without
    !! `*_motion = 'harmonic'`, a table without `*_motion = 'table'`. Such a key does nothing
    !! (a sweep may still vary the motion over a base that gives them, so it is no error).
    subroutine idle_motion_keys(scene, end, motion, amplitude, frequency, phase_deg, &
            angle_amplitude_deg, angle_phase_deg, ramp_time, table, list)
        type(scene_t), intent(in) :: scene
        character(len=*), intent(in) :: end, motion, table
        real(wp), intent(in) :: amplitude(2), frequency, phase_deg(2), angle_amplitude_deg, &
            angle_phase_deg, ramp_time
        type(text_t), allocatable, intent(inout) :: list(:)
        character(len=:), allocatable :: key, value, used_by
        key = ''
        if (trim(motion) /= 'harmonic') then
            used_by = 'harmonic'
            if (any(amplitude /= 0.0_wp)) then
                key = '_amplitude'
                value = pair_text(amplitude)
            else if (frequency /= 0.0_wp) then
                key = '_frequency'
                value = real_text(frequency)
            else if (any(phase_deg /= 0.0_wp)) then
                key = '_phase_deg'
                value = pair_text(phase_deg)
            else if (angle_amplitude_deg /= 0.0_wp) then
                key = '_angle_amplitude_deg'
                value = real_text(angle_amplitude_deg)
            else if (angle_phase_deg /= 0.0_wp) then
                key = '_angle_phase_deg'
                value = real_text(angle_phase_deg)
            else if (ramp_time /= 0.0_wp) then
                key = '_ramp_time'
                value = real_text(ramp_time)
            end if
        end if
        if (len(key) == 0 .and. trim(motion) /= 'table' .and. len_trim(table) > 0) then
            used_by = 'table'
            key = '_table'
            value = '"'//trim(table)//'"'
        end if
        if (len(key) == 0) return
        call append_text(list, scene%origin('supports.'//end//key)//': &supports: '//end// &
            key//' = '//value// &
            ': does nothing: '//end//"_motion = '"//trim(motion)//"' (it is used with "// &
            end//"_motion = '"//used_by//"')")
    end subroutine idle_motion_keys

    !> The keys of &ground set away from their defaults while effects%ground is off, and
    !! those of &fluid while drag and water are both off (or its water keys while water
    !! is): one warning a group, naming the first such key and how many more. Such keys do
    !! nothing (a sweep may still switch the effect over a base that gives them, so it is
    !! no error); an effective scene's echo of the defaults says nothing.
    subroutine idle_groups(scene, list)
        type(scene_t), intent(in) :: scene
        type(text_t), allocatable, intent(inout) :: list(:)
        type(scene_t), target :: mine, base
        type(scene_key_t), allocatable :: keys(:), defaults(:)
        character(len=*), parameter :: WATER_KEYS = &
            ' surface added_mass_coefficient tangential_added_mass_coefficient '
        character(len=*), parameter :: DRAG_KEYS = ' normal_drag_coefficient '// &
            'tangential_drag_coefficient linear_normal_drag linear_tangential_drag '
        mine = scene
        call bind_keys(mine, keys)
        call bind_keys(base, defaults)
        if (.not. scene%effects%ground) &
            call idle(G_GROUND, '', 'effects.ground is .false.')
        if (.not. (scene%effects%drag .or. scene%effects%water)) then
            call idle(G_FLUID, '', 'effects.drag and effects.water are .false.')
        else if (.not. scene%effects%water) then
            call idle(G_FLUID, WATER_KEYS, 'effects.water is .false. (only water uses it)')
        else if (.not. scene%effects%drag) then
            call idle(G_FLUID, DRAG_KEYS, 'effects.drag is .false. (only drag uses it)')
        end if
    contains
        !> The warning for group g's keys (those named in `names` when not ''), if any.
        subroutine idle(g, names, why)
            integer, intent(in) :: g
            character(len=*), intent(in) :: names, why
            integer :: k, first, more
            character(len=:), allocatable :: also, group, key
            first = 0
            more = 0
            do k = 1, size(keys)
                if (keys(k)%group /= g) cycle
                if (len(names) > 0 .and. index(names, ' '//keys(k)%name//' ') == 0) cycle
                if (keys(k)%value_text() == defaults(k)%value_text()) cycle
                if (first == 0) then
                    first = k
                else
                    more = more + 1
                end if
            end do
            if (first == 0) return
            group = trim(GROUP_NAMES(g))
            key = keys(first)%name
            also = ''
            if (more == 1) also = '; so does 1 more key of &'//group
            if (more > 1) also = '; so do '//int_text(more)//' more keys of &'//group
            call append_text(list, scene%origin(group//'.'//key)//': &'//group//': '// &
                key//' = '//keys(first)%value_text()//': does nothing: '//why//also)
        end subroutine idle
    end subroutine idle_groups

    !> A release of the `end` support at or after t_end (it never happens in the run), and a
    !! harmonic ramp longer than the run (the amplitudes never reach their full size).
    subroutine late_motion(scene, end, motion, ramp_time, release_time, t_end, list)
        type(scene_t), intent(in) :: scene
        character(len=*), intent(in) :: end, motion
        real(wp), intent(in) :: ramp_time, release_time, t_end
        type(text_t), allocatable, intent(inout) :: list(:)
        real(wp) :: share(0:2)
        if (release_time > 0.0_wp .and. release_time >= t_end) call append_text(list, &
            scene%origin('supports.'//end//'_release_time')//': &supports: '//end// &
            '_release_time = '//real_text(release_time)// &
            ': at or after t_end = '//real_text(t_end)//' s: the support is not released '// &
            'in the run (< 0: never)')
        if (trim(motion) == 'harmonic' .and. ramp_time > t_end) then
            share = ramp(t_end, ramp_time)
            call append_text(list, scene%origin('supports.'//end//'_ramp_time')// &
                ': &supports: '//end//'_ramp_time = '// &
                real_text(ramp_time)//': longer than the run (t_end = '//real_text(t_end)// &
                ' s): the amplitudes reach only '// &
                significant_text(100.0_wp*share(0), 3)// &
                ' % of their size by t_end')
        end if
    end subroutine late_motion

    !> The depth of the point p in the scene's ground (m; below 0 on the free side):
    !! -(p - point).normal/|normal|, the normal pointing to the free side; 0 without a normal.
    pure real(wp) function ground_depth(scene, p) result(depth)
        type(scene_t), intent(in) :: scene
        real(wp), intent(in) :: p(2)
        depth = 0.0_wp
        if (.not. norm2(scene%ground%normal) > 0.0_wp) return
        depth = -dot_product(scene%ground%normal/norm2(scene%ground%normal), &
                             p - scene%ground%point)
    end function ground_depth

    !> The pinned or clamped ends whose anchor lies deeper in the ground than
    !! MAX_START_DEPTH_SHARE of the length, or than ANCHOR_SINK_FACTOR times the depth the
    !! rope's weight sinks it (sinking_depth): the contact springs push the rope out against
    !! the support for good, so the equilibrium holds the rope pressed into the ground (and
    !! its iteration meets two stiff springs at odds), and the anchor takes the push. An
    !! anchor on the ground (a chain's on the seabed) is within both.
    subroutine ground_anchors(scene, sec, list)
        type(scene_t), intent(in) :: scene
        type(section_t), intent(in) :: sec
        type(text_t), allocatable, intent(inout) :: list(:)
        real(wp) :: sinking, limit
        character(len=:), allocatable :: why
        sinking = sinking_depth(scene, sec)
        limit = MAX_START_DEPTH_SHARE*scene%rope%length
        why = ''
        if (sinking > 0.0_wp .and. ANCHOR_SINK_FACTOR*sinking < limit) then
            limit = ANCHOR_SINK_FACTOR*sinking
            why = ", more than "//int_text(nint(ANCHOR_SINK_FACTOR))//" times the "// &
                significant_text(sinking, 3)//" m the rope's weight sinks it"
        end if
        if (scene%supports%top /= 'free') &
            call held_end('top', scene%supports%top, scene%supports%top_anchor)
        if (scene%supports%bottom /= 'free' .and. bottom_anchor_given(scene%rope_spec_t)) &
            call held_end('bottom', scene%supports%bottom, scene%supports%bottom_anchor)
    contains
        !> The warning of the end `end_name`, held as `kind`, when its anchor is too deep.
        subroutine held_end(end_name, kind, anchor)
            character(len=*), intent(in) :: end_name, kind
            real(wp), intent(in) :: anchor(2)
            real(wp) :: depth
            depth = ground_depth(scene, anchor)
            if (depth > limit) call append_text(list, &
                scene%origin('supports.'//end_name//'_anchor')//': &supports: '// &
                end_name//'_anchor = '// &
                significant_text(anchor(1), 6)//', '//significant_text(anchor(2), 6)// &
                ': the '//end_name//' end is '//trim(kind)//' '// &
                significant_text(depth, 3)//' m inside the ground'//why//' (&ground point = '// &
                real_text(scene%ground%point(1))//', '//real_text(scene%ground%point(2))// &
                '; x points down, the normal to the free side): the contact springs push '// &
                'the rope against the support for good; move the anchor or the ground')
        end subroutine held_end
    end subroutine ground_anchors

    !> Both ends held and their anchors further apart than the rope's length by more than
    !! MAX_REACH_STRAIN: the line is stretched by that much to reach them, at a tension of
    !! about EA times the stretch, which the statics and the run then show without a word
    !! (a newcomer's 120 m mooring chain between anchors 137.9 m apart: 8.7e7 N).
    subroutine anchor_reach(scene, sec, list)
        type(scene_t), intent(in) :: scene
        type(section_t), intent(in) :: sec
        type(text_t), allocatable, intent(inout) :: list(:)
        real(wp) :: distance, strain
        if (scene%supports%top == 'free' .or. scene%supports%bottom == 'free') return
        if (.not. bottom_anchor_given(scene%rope_spec_t)) return
        distance = norm2(scene%supports%bottom_anchor - scene%supports%top_anchor)
        strain = distance/scene%rope%length - 1.0_wp
        if (.not. strain > MAX_REACH_STRAIN) return
        call append_text(list, scene%origin('supports.bottom_anchor')// &
            ': &supports: bottom_anchor = '// &
            significant_text(scene%supports%bottom_anchor(1), 6)//', '// &
            significant_text(scene%supports%bottom_anchor(2), 6)//': '// &
            significant_text(distance, 4)//' m from the top anchor, more than the rope''s '// &
            'length ('//significant_text(scene%rope%length, 6)//' m): the line must stretch '// &
            'by '//significant_text(100.0_wp*strain, 3)//' % to reach it, at a tension of '// &
            'about '//significant_text(strain*sec%ea, 3)//' N (EA times the stretch); '// &
            'an anchor out of reach, or a length in the wrong unit?')
    end subroutine anchor_reach

    !> The ground's law: a stiffness under which the rope's weight per metre w (in water
    !! less its buoyancy) sinks it by w/k, deeper than MAX_START_DEPTH_SHARE of its length
    !! (a stiffness in kN/m^2 where N/m^2 is meant sinks it a thousand times deeper; the
    !! guide asks for k of 1000 w or more, a millimetre), and a friction coefficient above
    !! MAX_FRICTION_COEFFICIENT. The buoyancy is taken off whenever water is on, also where
    !! the ground lies above the surface: that sinking is the smaller one, and warns less.
    subroutine ground_law(scene, sec, list)
        type(scene_t), intent(in) :: scene
        type(section_t), intent(in) :: sec
        type(text_t), allocatable, intent(inout) :: list(:)
        real(wp) :: sinking
        associate (g => scene%ground)
            sinking = sinking_depth(scene, sec)
            if (sinking > 0.0_wp) then
                if (sinking > MAX_START_DEPTH_SHARE*scene%rope%length) call append_text(list, &
                    scene%origin('ground.stiffness')//': &ground: stiffness = '// &
                    real_text(g%stiffness)//": the rope's weight, "// &
                    significant_text(sinking*g%stiffness, 4)//' N/m'// &
                    trim(merge(' in water', '         ', scene%effects%water))// &
                    ', sinks it '//significant_text(sinking, 3)//' m into the ground, more '// &
                    'than a thousandth of its length: a stiffness in kN/m^2? (the unit is '// &
                    'N/m^2; 1000 times the weight per metre sinks it 1 mm)')
            end if
            if (g%friction_coefficient > MAX_FRICTION_COEFFICIENT) call append_text(list, &
                scene%origin('ground.friction_coefficient')// &
                ': &ground: friction_coefficient = '//real_text(g%friction_coefficient)// &
                ': above 1, more than a rope or chain has on the ground (0.1 .. 1): '// &
                'a percentage? (0.6, not 60)')
        end associate
    end subroutine ground_law

    !> The depth w/k the rope's weight per metre w (in water less its buoyancy, whenever
    !! water is on) sinks it into the ground of stiffness k, m; 0 without gravity or for a
    !! rope that floats.
    pure real(wp) function sinking_depth(scene, sec) result(depth)
        type(scene_t), intent(in) :: scene
        type(section_t), intent(in) :: sec
        real(wp) :: w
        depth = 0.0_wp
        if (.not. scene%effects%gravity .or. .not. scene%ground%stiffness > 0.0_wp) return
        w = sec%mass_per_length*scene%rope%gravity
        if (scene%effects%water) w = w - scene%fluid%density*scene%rope%gravity*sec%area
        depth = max(0.0_wp, w/scene%ground%stiffness)
    end function sinking_depth

    !> The straight starts ('straight', 'hanging': from &supports top_anchor along the
    !! initial angle) whose far end lies deeper in the ground than MAX_START_DEPTH_SHARE of
    !! the length: the contact springs hold that penetration at the start and throw the rope
    !! out at once. The depth of a point p is -(p - point).normal/|normal|, the normal
    !! pointing to the free side; along a straight rope it is deepest at an end.
    subroutine ground_start(scene, list)
        type(scene_t), intent(in) :: scene
        type(text_t), allocatable, intent(inout) :: list(:)
        real(wp) :: ends(2, 2), depth
        real(wp) :: angle
        if (scene%initial%shape /= 'straight' .and. scene%initial%shape /= 'hanging') return
        angle = initial_angle(scene%rope_spec_t)
        ends(:, 1) = scene%supports%top_anchor
        ends(:, 2) = ends(:, 1) + scene%rope%length*[cos(angle), sin(angle)]
        depth = max(ground_depth(scene, ends(:, 1)), ground_depth(scene, ends(:, 2)))
        if (depth > MAX_START_DEPTH_SHARE*scene%rope%length) call append_text(list, &
            scene%origin('ground.point')//': &ground: point = '// &
            real_text(scene%ground%point(1))//', '// &
            real_text(scene%ground%point(2))//": the rope's "//trim(scene%initial%shape)// &
            ' start reaches '//significant_text(depth, 3)//' m into the ground (its ends: '// &
            real_text(ends(1, 1))//', '//real_text(ends(2, 1))//' and '// &
            significant_text(ends(1, 2), 6)//', '//significant_text(ends(2, 2), 6)// &
            ' m; x points down, the normal to the free side): the contact springs throw '// &
            'it out at once; move the ground or the start, or start from the equilibrium '// &
            "(&initial shape = 'equilibrium')")
    end subroutine ground_start
end module ropedyn_scene_warnings
