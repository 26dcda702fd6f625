!> The limits of a scene (docs/reference/scene-file.md, "Limits"), checked when it is read so that no run
!! allocates more than it can or starts from a non-finite state:
!!
!! - memory: the state and Jacobian storage of the model and its integrator, estimated from
!!   `elements` (RFEM: band storage, ~6 kB per element; MPP: dense n^2 matrices), at most
!!   MEMORY_LIMIT bytes;
!! - output: t_end/output_interval at most MAX_RECORDS records, t_end at most MAX_TIME (and
!!   so the time of a record a run starts from: ropedyn_run_record);
!! - magnitudes: the derived values of the rope (element mass and inertia, spring and damper
!!   constants, energies and forces at the start) within MAGNITUDE_LIMIT (masses and inertias
!!   at least 1/MAGNITUDE_LIMIT). A value beyond them would make the initial state, the energy
!!   or the first right-hand side non-finite; the message names the most extreme of the keys
!!   the derived value depends on (the one furthest from 1 in decades).
module ropedyn_scene_limits
    use, intrinsic :: ieee_arithmetic, only: ieee_is_nan
    use ropedyn_kinds, only: wp, PI
    use ropedyn_error, only: error_t
    use ropedyn_text, only: int_text, real_text
    use ropedyn_rope_spec, only: N_ATTACH
    use ropedyn_rope_section, only: section_t, rope_section
    use ropedyn_scene_types, only: scene_t
    use ropedyn_scene_key, only: scene_key_t, T_INT, T_REAL, T_LIST
    use ropedyn_scene_keys, only: find_key, fail, group_index, G_MODEL, G_SOLVER, G_SUPPORTS
    implicit none
    private
    public :: check_limits, MAX_RECORDS, MEMORY_LIMIT, MAGNITUDE_LIMIT, MAX_TIME

    integer, parameter :: MAX_RECORDS = 10000000          !< output records of one run
    real(wp), parameter :: MEMORY_LIMIT = 8.0_wp*1024.0_wp**3  !< bytes (8 GiB)
    real(wp), parameter :: MAGNITUDE_LIMIT = 1.0e100_wp   !< derived values, SI units
    !> The latest time of a run, s (about 32 years): beyond it the round-off of t (1.2e-7 s)
    !! is coarser than the steps of a rope's motion, and no integrator could advance t.
    real(wp), parameter :: MAX_TIME = 1.0e9_wp

    integer, parameter :: KL = 40
    ! The keys each derived value depends on.
    character(len=KL), parameter :: MASS_KEYS(4) = [character(len=KL) :: 'rope.density', &
        'rope.diameter', 'rope.length', 'rope.mass_per_length']
    character(len=KL), parameter :: STIFF_KEYS(9) = [character(len=KL) :: &
        'rope.young_modulus', 'rope.shear_modulus', 'rope.shape_factor', 'rope.diameter', &
        'rope.length', 'supports.support_stiffness_factor', 'rope.axial_stiffness', &
        'rope.shear_stiffness', 'rope.bending_stiffness']
    character(len=KL), parameter :: DAMP_KEYS(9) = [character(len=KL) :: &
        'rope.normal_damping', 'rope.tangential_damping', 'rope.shape_factor', &
        'rope.diameter', 'rope.length', 'supports.support_stiffness_factor', &
        'rope.axial_damping', 'rope.shear_damping', 'rope.bending_damping']
    character(len=KL), parameter :: REACH_KEYS(11) = [character(len=KL) :: &
        'supports.top_anchor', 'rope.length', 'supports.bottom_anchor', 'ground.point', &
        'initial.mode_amplitude', 'supports.top_amplitude', 'supports.bottom_amplitude', &
        'supports.top_angle_deg', 'supports.bottom_angle_deg', &
        'supports.top_angle_amplitude_deg', 'supports.bottom_angle_amplitude_deg']
    character(len=KL), parameter :: SPEED_KEYS(6) = [character(len=KL) :: 'initial.velocity', &
        'fluid.current', 'supports.top_frequency', 'supports.top_amplitude', &
        'supports.bottom_frequency', 'supports.bottom_amplitude']
    character(len=KL), parameter :: FLUID_KEYS(5) = [character(len=KL) :: 'fluid.density', &
        'fluid.normal_drag_coefficient', 'fluid.tangential_drag_coefficient', &
        'fluid.linear_normal_drag', 'fluid.linear_tangential_drag']
    character(len=KL), parameter :: LOAD_KEYS(4) = [character(len=KL) :: &
        'attachments.load_force_x', 'attachments.load_force_y', &
        'attachments.load_amplitude_x', 'attachments.load_amplitude_y']

    character(len=KL), parameter :: ELEMENT_KEYS(*) = [character(len=KL) :: MASS_KEYS, &
        'model.elements']
    character(len=KL), parameter :: TOTAL_KEYS(*) = [character(len=KL) :: MASS_KEYS, &
        'attachments.masses']
    character(len=KL), parameter :: SPRING_KEYS(*) = [character(len=KL) :: STIFF_KEYS, &
        'model.elements']
    character(len=KL), parameter :: DAMPER_KEYS(*) = [character(len=KL) :: DAMP_KEYS, &
        'model.elements']
    character(len=KL), parameter :: GRAVITY_KEYS(*) = [character(len=KL) :: TOTAL_KEYS, &
        'rope.gravity', REACH_KEYS]
    character(len=KL), parameter :: KINETIC_KEYS(*) = [TOTAL_KEYS, SPEED_KEYS]
    character(len=KL), parameter :: MOTION_KEYS(*) = [TOTAL_KEYS, SPEED_KEYS, REACH_KEYS]
    character(len=KL), parameter :: GROUND_KEYS(*) = [character(len=KL) :: 'ground.stiffness', &
        'ground.damping', REACH_KEYS, SPEED_KEYS]
    character(len=KL), parameter :: DRAG_KEYS(*) = [character(len=KL) :: FLUID_KEYS, &
        'rope.diameter', SPEED_KEYS, REACH_KEYS]

contains

    subroutine check_limits(keys, scene, err)
        type(scene_key_t), intent(in) :: keys(:)
        type(scene_t), intent(in) :: scene
        type(error_t), allocatable, intent(out) :: err
        call check_sizes(keys, scene, err)
        if (allocated(err)) return
        call check_magnitudes(keys, scene, err)
    end subroutine check_limits

    !> Memory of the state and the Jacobian, and the number of output records.
    subroutine check_sizes(keys, scene, err)
        type(scene_key_t), intent(in) :: keys(:)
        type(scene_t), intent(in) :: scene
        type(error_t), allocatable, intent(out) :: err
        real(wp) :: n, neq, matrix, bytes, records
        n = real(scene%model%elements, wp)
        if (scene%model%kind == 'mpp') then
            neq = 2.0_wp*(n + merge(n, 0.0_wp, scene%effects%tension))
            matrix = neq**2                 ! dense: M(q), the Jacobian and its LU
        else
            neq = 6.0_wp*n
            matrix = 31.0_wp*neq            ! band storage 2 ml + mu + 1 (ml = 11, mu = 8)
        end if
        bytes = 8.0_wp*(3.0_wp*matrix + 40.0_wp*neq)
        if (bytes > MEMORY_LIMIT) then
            call fail(keys, G_MODEL, 'elements', int_text(scene%model%elements), 'too many: ' &
                //'the state and Jacobian of the '//trim(scene%model%kind)//' model would ' &
                //'need about '//real_text(anint(bytes/1.0e9_wp))// &
                ' GB, more than the limit of '//int_text(nint(MEMORY_LIMIT/1024.0_wp**3))// &
                ' GiB (docs/reference/scene-file.md, Limits)', err)
            return
        end if
        records = scene%solver%t_end/scene%solver%output_interval
        if (.not. records <= real(MAX_RECORDS, wp)) then
            call fail(keys, G_SOLVER, 'output_interval', real_text(scene%solver%output_interval), &
                'with t_end = '//real_text(scene%solver%t_end)//' that makes '// &
                real_text(records)//' output records, more than the limit '// &
                int_text(MAX_RECORDS)//' (docs/reference/scene-file.md, Limits)', err, &
                also='solver.t_end')
        end if
        if (.not. allocated(err) .and. scene%solver%t_end > MAX_TIME) call fail(keys, G_SOLVER, &
            't_end', real_text(scene%solver%t_end), 'out of range (at most '// &
            real_text(MAX_TIME)//' s; docs/reference/scene-file.md, Limits)', err)
    end subroutine check_sizes

    !> The derived values of the rope within MAGNITUDE_LIMIT.
    subroutine check_magnitudes(keys, scene, err)
        type(scene_key_t), intent(in) :: keys(:)
        type(scene_t), intent(in) :: scene
        type(error_t), allocatable, intent(out) :: err
        type(section_t) :: sec
        real(wp) :: dl, m_e, mass, reach, speed, c, b, factor, loads, drag, motion, &
            table_reach, table_speed, table_accel
        logical :: given(N_ATTACH)
        integer :: k

        table_reach = 0.0_wp
        table_speed = 0.0_wp
        table_accel = 0.0_wp
        associate (r => scene%rope, s => scene%supports, a => scene%attachments, &
                f => scene%fluid, g => scene%ground)
            sec = rope_section(r)
            dl = r%length/real(max(scene%model%elements - 1, 1), wp)
            factor = max(1.0_wp, s%support_stiffness_factor)
            if (s%end_compliance == 'split') factor = 2.0_wp*factor
            m_e = sec%mass_per_length*dl/2.0_wp
            call bound(m_e, "an element's mass", 'kg', ELEMENT_KEYS, .true.)
            call bound(m_e*(dl**2/12.0_wp + r%diameter**2/16.0_wp), "an element's rotary " &
                //'inertia', 'kg m^2', ELEMENT_KEYS, .true.)
            given = .not. ieee_is_nan(a%mass_positions)
            mass = sec%mass_per_length*r%length + sum(a%masses, mask=given)
            call bound(mass, 'the mass', 'kg', TOTAL_KEYS, .false.)
            c = max(sec%ea, sec%ga/sec%shape_factor)/dl*factor
            call bound(c, 'a spring constant', 'N/m', SPRING_KEYS, .false.)
            call bound(sec%ei/dl*factor, 'a bending spring constant', 'N m', SPRING_KEYS, &
                .false.)
            b = max(sec%axial_damping, sec%shear_damping/sec%shape_factor)/dl*factor
            call bound(b, 'a damper constant', 'N s/m', DAMPER_KEYS, .false.)
            call bound(sec%bending_damping/dl*factor, 'a bending damper constant', 'N m s', &
                DAMPER_KEYS, .false.)

            ! the motion tables: each alone (naming the table and its row), then with the rest
            call table_bounds(keys, scene, 'top', s%top_table, s%top_table_rows, mass, c, &
                              table_reach, table_speed, table_accel, err)
            call table_bounds(keys, scene, 'bottom', s%bottom_table, s%bottom_table_rows, &
                              mass, c, table_reach, table_speed, table_accel, err)
            if (allocated(err)) return
            reach = norm2(s%top_anchor) + r%length + abs(scene%initial%mode_amplitude) &
                + norm2(s%top_amplitude) + norm2(s%bottom_amplitude) + table_reach &
                + r%length*pi/180.0_wp*(abs(s%top_angle_deg) + abs(s%bottom_angle_deg) + &
                abs(s%top_angle_amplitude_deg) + abs(s%bottom_angle_amplitude_deg))
            if (s%bottom_anchor_set) reach = reach + norm2(s%bottom_anchor)
            if (scene%effects%ground) reach = reach + norm2(g%point)
            speed = norm2(scene%initial%velocity) + 2.0_wp*pi*(s%top_frequency* &
                norm2(s%top_amplitude) + s%bottom_frequency*norm2(s%bottom_amplitude)) + &
                table_speed
            if (scene%effects%drag) speed = speed + norm2(f%current)
            call bound(mass*r%gravity*reach, 'the gravity energy', 'J', GRAVITY_KEYS, .false.)
            call bound(mass*speed**2, 'the kinetic energy', 'J', KINETIC_KEYS, .false.)
            call bound(c*reach**2, 'the energy of a spring', 'J', [SPRING_KEYS, REACH_KEYS], &
                .false.)
            ! (f sqrt(a))^2, not f^2 a: a huge frequency without an amplitude is no NaN
            motion = mass*((2.0_wp*pi)**2*((s%top_frequency*sqrt(norm2(s%top_amplitude)))**2 &
                + (s%bottom_frequency*sqrt(norm2(s%bottom_amplitude)))**2) + table_accel)*reach
            call bound(motion, 'the work of a moving support', 'J', MOTION_KEYS, .false.)
            if (scene%effects%ground) call bound((g%stiffness*reach + g%damping*speed)* &
                r%length*reach, 'the ground contact energy', 'J', GROUND_KEYS, .false.)
            loads = 0.0_wp
            do k = 1, N_ATTACH
                if (ieee_is_nan(a%load_positions(k))) cycle
                loads = loads + abs(a%load_force_x(k)) + abs(a%load_force_y(k)) + &
                    abs(a%load_amplitude_x(k)) + abs(a%load_amplitude_y(k))
            end do
            call bound(loads*reach, 'the work of the point loads', 'J', [LOAD_KEYS, REACH_KEYS], &
                .false.)
            if (scene%effects%drag) then
                drag = (f%density*(f%normal_drag_coefficient + pi*f%tangential_drag_coefficient) &
                    *r%diameter*speed + f%linear_normal_drag + f%linear_tangential_drag)* &
                    r%length*speed*reach
                call bound(drag, 'the work of the drag', 'J', DRAG_KEYS, .false.)
            end if
        end associate
    contains
        !> x must be <= MAGNITUDE_LIMIT (and, with `positive`, >= 1/MAGNITUDE_LIMIT).
        subroutine bound(x, what, unit, names, positive)
            real(wp), intent(in) :: x
            character(len=*), intent(in) :: what, unit
            character(len=*), intent(in) :: names(:)
            logical, intent(in) :: positive
            character(len=:), allocatable :: key, value, limit
            integer :: k, g
            if (allocated(err)) return
            if (x <= MAGNITUDE_LIMIT .and. (.not. positive .or. x >= 1.0_wp/MAGNITUDE_LIMIT)) &
                return
            limit = 'at most '//real_text(MAGNITUDE_LIMIT)
            if (x <= MAGNITUDE_LIMIT) limit = 'at least '//real_text(1.0_wp/MAGNITUDE_LIMIT)
            call culprit(keys, names, k, key, value)
            g = keys(k)%group
            call fail(keys, g, key, value, 'out of range: it makes '//what//' '// &
                real_text(x)//' '//unit//' ('//limit//'; docs/reference/scene-file.md, Limits)', err)
        end subroutine bound
    end subroutine check_magnitudes

    !> The motion table of the `end` support (`path`, its rows t, dx, dy, dangle) of a rope
    !! of `mass` (kg), spring constant `c` (N/m): its largest displacement, speed and
    !! acceleration (the angle's rates times the rope's length) each make an energy within
    !! MAGNITUDE_LIMIT, else ERR_INPUT naming the table and the row; added to reach (m),
    !! speed (m/s) and accel (m/s^2).
    subroutine table_bounds(keys, scene, end, path, rows, mass, c, reach, speed, accel, err)
        type(scene_key_t), intent(in) :: keys(:)
        type(scene_t), intent(in) :: scene
        character(len=*), intent(in) :: end, path
        real(wp), allocatable, intent(in) :: rows(:, :)
        real(wp), intent(in) :: mass, c
        real(wp), intent(inout) :: reach, speed, accel
        type(error_t), allocatable, intent(inout) :: err
        character(len=*), parameter :: HOW(3) = [character(len=12) :: 'displacement', &
            'speed', 'acceleration']
        character(len=*), parameter :: UNIT(3) = [character(len=6) :: 'm', 'm/s', 'm/s^2']
        real(wp) :: d, v, a, worst(3), span
        integer :: k, at(3)
        if (.not. allocated(rows) .or. allocated(err)) return
        worst = 0.0_wp
        at = 1
        do k = 1, size(rows, 2)
            d = norm2(rows(2:3, k)) + abs(rows(4, k))*scene%rope%length
            if (.not. d <= worst(1)) at(1) = k
            worst(1) = max(worst(1), d)
            if (k == 1) cycle
            ! the spline's slopes reach 1.5 times a segment's, its acceleration some 6
            ! times a slope over the segment's span
            span = rows(1, k) - rows(1, k - 1)
            v = 2.0_wp*(norm2(rows(2:3, k) - rows(2:3, k - 1)) + &
                        abs(rows(4, k) - rows(4, k - 1))*scene%rope%length)/span
            a = 3.0_wp*v/span
            if (.not. v <= worst(2)) at(2) = k
            if (.not. a <= worst(3)) at(3) = k
            worst(2) = max(worst(2), v)
            worst(3) = max(worst(3), a)
        end do
        reach = reach + worst(1)
        speed = speed + worst(2)
        accel = accel + worst(3)
        call table_bound(mass*scene%rope%gravity*worst(1), 'the gravity energy', 1)
        call table_bound(c*worst(1)**2, 'the energy of a spring', 1)
        call table_bound(mass*worst(2)**2, 'the kinetic energy', 2)
        call table_bound(mass*worst(3)*worst(1), 'the work of the moving support', 3)
    contains
        subroutine table_bound(x, what, which)
            real(wp), intent(in) :: x
            character(len=*), intent(in) :: what
            integer, intent(in) :: which
            if (allocated(err) .or. x <= MAGNITUDE_LIMIT) return
            call fail(keys, G_SUPPORTS, end//'_table', '"'//trim(path)//'"', 'row '// &
                int_text(at(which))//' (t = '//real_text(rows(1, at(which)))//' s): a '// &
                trim(HOW(which))//' of '//real_text(worst(which))//' '//trim(UNIT(which))// &
                ' makes '//what//' '//real_text(x)//' J (at most '// &
                real_text(MAGNITUDE_LIMIT)//'; docs/reference/scene-file.md, Limits)', err)
        end subroutine table_bound
    end subroutine table_bounds

    !> Of the keys `names` ('group.key'), the one whose value is furthest from 1 in decades
    !! (zero and NaN entries count as 1): its index, its name (a list's with the entry's
    !! index) and its value as text.
    subroutine culprit(keys, names, best, key, value)
        type(scene_key_t), intent(in) :: keys(:)
        character(len=*), intent(in) :: names(:)
        integer, intent(out) :: best
        character(len=:), allocatable, intent(out) :: key, value
        real(wp) :: worst, d
        real(wp), allocatable :: x(:)
        integer :: i, k, dot, entry, j
        worst = -1.0_wp
        best = 1
        entry = 0
        do i = 1, size(names)
            dot = index(names(i), '.')
            k = find_key(keys, group_index(names(i)(:dot - 1)), trim(names(i)(dot + 1:)))
            if (k == 0) cycle
            select case (keys(k)%type)
            case (T_REAL)
                x = [keys(k)%r]
            case (T_INT)
                x = [real(keys(k)%i, wp)]
            case default
                x = keys(k)%v
            end select
            do j = 1, size(x)
                d = 0.0_wp
                if (abs(x(j)) > 0.0_wp .and. .not. ieee_is_nan(x(j))) d = abs(log10(abs(x(j))))
                if (d > worst) then
                    worst = d
                    best = k
                    entry = j
                end if
            end do
        end do
        key = keys(best)%name
        value = keys(best)%value_text()
        if (keys(best)%type == T_LIST) then
            key = key//'('//int_text(entry)//')'
            value = real_text(keys(best)%v(entry))
        end if
    end subroutine culprit
end module ropedyn_scene_limits
