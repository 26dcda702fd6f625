!> The limits of a scene (docs/reference/scene-file.md, "Limits"), checked when it is read so that no run
!! allocates more than it can or starts from a non-finite state:
!!
!! - memory: the state and Jacobian storage of the model and its integrator, estimated from
!!   `elements` (RFEM: band storage, ~6 kB per element; MPP: dense n^2 matrices), at most
!!   MEMORY_LIMIT bytes;
!! - output: t_end/output_interval at most MAX_RECORDS records;
!! - magnitudes: the derived values of the rope (element mass and inertia, spring and damper
!!   constants, energies and forces at the start) within MAGNITUDE_LIMIT (masses and inertias
!!   at least 1/MAGNITUDE_LIMIT). A value beyond them would make the initial state, the energy
!!   or the first right-hand side non-finite; the message names the most extreme of the keys
!!   the derived value depends on (the one furthest from 1 in decades).
module ropedyn_scene_limits
    use, intrinsic :: ieee_arithmetic, only: ieee_is_nan
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t
    use ropedyn_text, only: int_text, real_text
    use ropedyn_rope_spec, only: N_ATTACH
    use ropedyn_scene_types, only: scene_t
    use ropedyn_scene_key, only: scene_key_t, T_INT, T_REAL, T_LIST
    use ropedyn_scene_keys, only: find_key, fail, group_index, G_MODEL, G_SOLVER
    implicit none
    private
    public :: check_limits, MAX_RECORDS, MEMORY_LIMIT, MAGNITUDE_LIMIT

    integer, parameter :: MAX_RECORDS = 10000000          !< output records of one run
    real(wp), parameter :: MEMORY_LIMIT = 8.0_wp*1024.0_wp**3  !< bytes (8 GiB)
    real(wp), parameter :: MAGNITUDE_LIMIT = 1.0e100_wp   !< derived values, SI units

    real(wp), parameter :: pi = acos(-1.0_wp)
    integer, parameter :: KL = 40
    ! The keys each derived value depends on.
    character(len=KL), parameter :: MASS_KEYS(3) = [character(len=KL) :: 'rope.density', &
        'rope.diameter', 'rope.length']
    character(len=KL), parameter :: STIFF_KEYS(6) = [character(len=KL) :: &
        'rope.young_modulus', 'rope.shear_modulus', 'rope.shape_factor', 'rope.diameter', &
        'rope.length', 'supports.support_stiffness_factor']
    character(len=KL), parameter :: DAMP_KEYS(6) = [character(len=KL) :: &
        'rope.normal_damping', 'rope.tangential_damping', 'rope.shape_factor', &
        'rope.diameter', 'rope.length', 'supports.support_stiffness_factor']
    character(len=KL), parameter :: REACH_KEYS(7) = [character(len=KL) :: &
        'supports.top_anchor', 'rope.length', 'supports.bottom_anchor', 'ground.point', &
        'initial.mode_amplitude', 'supports.top_amplitude', 'supports.bottom_amplitude']
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
                ' GiB (docs/input.md, Limits)', err)
            return
        end if
        records = scene%solver%t_end/scene%solver%output_interval
        if (.not. records <= real(MAX_RECORDS, wp)) then
            call fail(keys, G_SOLVER, 'output_interval', real_text(scene%solver%output_interval), &
                'with t_end = '//real_text(scene%solver%t_end)//' that makes '// &
                real_text(records)//' output records, more than the limit '// &
                int_text(MAX_RECORDS)//' (docs/input.md, Limits)', err)
        end if
    end subroutine check_sizes

    !> The derived values of the rope within MAGNITUDE_LIMIT.
    subroutine check_magnitudes(keys, scene, err)
        type(scene_key_t), intent(in) :: keys(:)
        type(scene_t), intent(in) :: scene
        type(error_t), allocatable, intent(out) :: err
        real(wp) :: area, second, dl, m_e, mass, reach, speed, c, b, factor, loads, drag, &
            motion
        logical :: given(N_ATTACH)
        integer :: k

        associate (r => scene%rope, s => scene%supports, a => scene%attachments, &
                f => scene%fluid, g => scene%ground)
            area = pi*r%diameter**2/4.0_wp
            second = pi*r%diameter**4/64.0_wp
            dl = r%length/real(max(scene%model%elements - 1, 1), wp)
            factor = max(1.0_wp, s%support_stiffness_factor)
            m_e = r%density*area*dl/2.0_wp
            call bound(m_e, "an element's mass", 'kg', ELEMENT_KEYS, .true.)
            call bound(m_e*(dl**2/12.0_wp + r%diameter**2/16.0_wp), "an element's rotary " &
                //'inertia', 'kg m^2', ELEMENT_KEYS, .true.)
            given = .not. ieee_is_nan(a%mass_positions)
            mass = r%density*area*r%length + sum(a%masses, mask=given)
            call bound(mass, 'the mass', 'kg', TOTAL_KEYS, .false.)
            c = max(r%young_modulus, r%shear_modulus/r%shape_factor)*area/dl*factor
            call bound(c, 'a spring constant', 'N/m', SPRING_KEYS, .false.)
            call bound(r%young_modulus*second/dl*factor, 'a bending spring constant', 'N m', &
                SPRING_KEYS, .false.)
            b = max(r%normal_damping, r%tangential_damping/r%shape_factor)*area/dl*factor
            call bound(b, 'a damper constant', 'N s/m', DAMPER_KEYS, .false.)
            call bound(r%normal_damping*second/dl*factor, 'a bending damper constant', &
                'N m s', DAMPER_KEYS, .false.)

            reach = norm2(s%top_anchor) + r%length + abs(scene%initial%mode_amplitude) &
                + norm2(s%top_amplitude) + norm2(s%bottom_amplitude)
            if (s%bottom_anchor_set) reach = reach + norm2(s%bottom_anchor)
            if (scene%effects%ground) reach = reach + norm2(g%point)
            speed = norm2(scene%initial%velocity) + 2.0_wp*pi*(s%top_frequency* &
                norm2(s%top_amplitude) + s%bottom_frequency*norm2(s%bottom_amplitude))
            if (scene%effects%drag) speed = speed + norm2(f%current)
            call bound(mass*r%gravity*reach, 'the gravity energy', 'J', GRAVITY_KEYS, .false.)
            call bound(mass*speed**2, 'the kinetic energy', 'J', KINETIC_KEYS, .false.)
            call bound(c*reach**2, 'the energy of a spring', 'J', [SPRING_KEYS, REACH_KEYS], &
                .false.)
            motion = mass*(2.0_wp*pi)**2*(s%top_frequency**2*norm2(s%top_amplitude) + &
                s%bottom_frequency**2*norm2(s%bottom_amplitude))*reach
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
                real_text(x)//' '//unit//' ('//limit//'; docs/input.md, Limits)', err)
        end subroutine bound
    end subroutine check_magnitudes

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
