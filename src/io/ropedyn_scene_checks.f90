!> The checks of a scene after reading: every key's own rule (from the key table), then the
!! checks that involve several keys (support motion against the support kind, the MPP's
!! restrictions, `max_order` per method from `ropedyn_methods`, attachments, ...), the
!! derived defaults, and the limits of `ropedyn_scene_limits`. This is the one place of
!! each check; the models keep only defensive checks that agree with it.
module ropedyn_scene_checks
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite, ieee_is_nan
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t, make_error, ERR_INPUT
    use ropedyn_text, only: int_text, real_text, pair_text, lower
    use ropedyn_os, only: absolute_path
    use ropedyn_methods, only: METHODS, method_index, resolved_max_order
    use ropedyn_rope_spec, only: N_ATTACH, NOT_SET
    use ropedyn_rope_section, only: resolved_rope, section_set_given
    use ropedyn_motion_table, only: read_motion_table
    use ropedyn_scene_types, only: scene_t
    use ropedyn_scene_key, only: scene_key_t
    use ropedyn_scene_keys, only: find_key, fail, G_ROPE, G_SUPPORTS, G_INITIAL, &
        G_EFFECTS, G_SOLVER, G_GROUND, G_ATTACHMENTS
    use ropedyn_scene_limits, only: check_limits
    implicit none
    private
    public :: check_scene

contains

    !> Check every key, resolve the derived defaults (max_order 0, tangential_damping,
    !! output file), read the motion tables. `keys` is the table bound to `scene`.
    subroutine check_scene(keys, scene, err)
        type(scene_key_t), intent(inout) :: keys(:)
        type(scene_t), intent(inout) :: scene
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: reason
        integer :: k

        do k = 1, size(keys)
            reason = keys(k)%check()
            if (len(reason) > 0) then
                call fail(keys, keys(k)%group, keys(k)%name, keys(k)%value_text(), reason, err)
                return
            end if
        end do
        call check_rope_sets(keys, scene, err)
        if (allocated(err)) return
        call check_supports(keys, scene, err)
        if (allocated(err)) return
        call check_motion(keys, scene, 'top', scene%supports%top_table_rows, err)
        if (allocated(err)) return
        call check_motion(keys, scene, 'bottom', scene%supports%bottom_table_rows, err)
        if (allocated(err)) return
        call check_initial_and_fluid(keys, scene, err)
        if (allocated(err)) return
        call check_state_file(keys, scene, err)
        if (allocated(err)) return
        call check_attachments(keys, scene, err)
        if (allocated(err)) return
        call check_solver(keys, scene, err)
        if (allocated(err)) return
        call resolve_defaults(keys, scene, err)
        if (allocated(err)) return
        call check_limits(keys, scene, err)
    end subroutine check_scene

    !> &rope is given by one of its two sets (ropedyn_rope_section): a key of the solid-rod
    !! set given with the section set is an error naming both; the section set needs its
    !! mass per length and EA. With the section set the solid-rod values are not set (NaN),
    !! so that the effective scene says so.
    subroutine check_rope_sets(keys, scene, err)
        type(scene_key_t), intent(in) :: keys(:)
        type(scene_t), intent(inout) :: scene
        type(error_t), allocatable, intent(out) :: err
        character(len=*), parameter :: SOLID(6) = [character(len=18) :: 'density', &
            'young_modulus', 'shear_modulus', 'normal_damping', 'tangential_damping', &
            'shape_factor']
        character(len=*), parameter :: SECTION(7) = [character(len=17) :: 'mass_per_length', &
            'axial_stiffness', 'bending_stiffness', 'shear_stiffness', 'axial_damping', &
            'shear_damping', 'bending_damping']
        integer :: a, b, ka, kb
        if (.not. section_set_given(scene%rope)) return
        do a = 1, size(SOLID)
            ka = find_key(keys, G_ROPE, trim(SOLID(a)))
            if (.not. keys(ka)%given) cycle
            do b = 1, size(SECTION)
                kb = find_key(keys, G_ROPE, trim(SECTION(b)))
                if (keys(kb)%given) exit
            end do
            b = min(b, size(SECTION))
            call fail(keys, G_ROPE, trim(SOLID(a)), keys(ka)%value_text(), 'a key of the '// &
                'solid-rod set, but '//trim(SECTION(b))//' = '//keys(kb)%value_text()// &
                ' gives the section set: give one set (solid rod: density, young_modulus, '// &
                'shear_modulus, normal_damping, tangential_damping, shape_factor; section: '// &
                'mass_per_length, axial_stiffness, bending_stiffness, shear_stiffness and '// &
                'the dampings)', err, also='rope.'//trim(SECTION(b)))
            return
        end do
        do b = 1, 2
            kb = find_key(keys, G_ROPE, trim(SECTION(b)))
            if (keys(kb)%given) cycle
            call fail(keys, G_ROPE, trim(SECTION(b)), 'not set', 'needed with the section '// &
                'set (given: '//given_section_keys()//')', err, also=set_section_key())
            return
        end do
        associate (r => scene%rope)
            r%density = NOT_SET
            r%young_modulus = NOT_SET
            r%shear_modulus = NOT_SET
            r%normal_damping = NOT_SET
            r%tangential_damping = NOT_SET
            r%shape_factor = NOT_SET
        end associate
    contains
        !> 'rope.KEY' of a section key given by a --set (the first), else of the first given.
        function set_section_key() result(name)
            character(len=:), allocatable :: name
            integer :: k, ks
            name = ''
            do k = 1, size(SECTION)
                ks = find_key(keys, G_ROPE, trim(SECTION(k)))
                if (.not. keys(ks)%given) cycle
                if (len(name) == 0) name = 'rope.'//trim(SECTION(k))
                if (index(keys(ks)%origin, '--set ') == 1) then
                    name = 'rope.'//trim(SECTION(k))
                    return
                end if
            end do
        end function set_section_key

        function given_section_keys() result(list)
            character(len=:), allocatable :: list
            integer :: k
            list = ''
            do k = 1, size(SECTION)
                if (.not. keys(find_key(keys, G_ROPE, trim(SECTION(k))))%given) cycle
                if (len(list) > 0) list = list//', '
                list = list//trim(SECTION(k))
            end do
        end function given_section_keys
    end subroutine check_rope_sets

    subroutine check_supports(keys, scene, err)
        type(scene_key_t), intent(in) :: keys(:)
        type(scene_t), intent(inout) :: scene
        type(error_t), allocatable, intent(out) :: err
        associate (s => scene%supports)
            if (scene%model%kind == 'mpp' .and. s%top == 'free') then
                call fail(keys, G_SUPPORTS, 'top', '"free"', 'the mpp model hangs from its '// &
                    'top joint: use pinned or clamped (or the rfem model)', err)
                return
            end if
            s%bottom_anchor_set = .not. any(ieee_is_nan(s%bottom_anchor))
            if (any(ieee_is_nan(s%bottom_anchor)) .and. .not. all(ieee_is_nan(s%bottom_anchor))) &
                then
                call fail(keys, G_SUPPORTS, 'bottom_anchor', pair_text(s%bottom_anchor), &
                    "give both components (or neither, for the rope's lower end in its " &
                    //'initial state)', err)
            else if (s%bottom_anchor_set .and. .not. all(ieee_is_finite(s%bottom_anchor))) then
                call fail(keys, G_SUPPORTS, 'bottom_anchor', pair_text(s%bottom_anchor), &
                    'must be finite', err)
            else if (s%bottom_anchor_set .and. s%bottom == 'free') then
                call fail(keys, G_SUPPORTS, 'bottom_anchor', pair_text(s%bottom_anchor), &
                    'the bottom end is free: no support holds it there (set bottom = ' &
                    //'''pinned'' or ''clamped'', or leave bottom_anchor out)', err)
            else if (scene%model%kind == 'mpp' .and. s%top_release_time >= 0.0_wp) then
                call fail(keys, G_SUPPORTS, 'top_release_time', real_text(s%top_release_time), &
                    'the mpp model hangs from its top joint, which cannot be released (use ' &
                    //'the rfem model)', err)
            end if
        end associate
    end subroutine check_supports

    !> The motion and release keys of one support ('top' or 'bottom') against its kind; read
    !! its motion table, resolving a relative path against the scene file's directory.
    subroutine check_motion(keys, scene, end, rows, err)
        type(scene_key_t), intent(inout) :: keys(:)
        type(scene_t), intent(in) :: scene
        character(len=*), intent(in) :: end
        real(wp), allocatable, intent(out) :: rows(:, :)
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: support, motion, full
        real(wp) :: frequency, angle_amplitude, release, angle
        integer :: k

        support = trim(keys(find_key(keys, G_SUPPORTS, end))%s)
        angle = keys(find_key(keys, G_SUPPORTS, end//'_angle_deg'))%r
        if (angle /= 0.0_wp .and. support /= 'clamped') then
            call fail(keys, G_SUPPORTS, end//'_angle_deg', real_text(angle), 'only a ' &
                //'clamped support holds its end at an angle ('//end//' = "'//support// &
                '"; set '//end//' = ''clamped'' or leave '//end//'_angle_deg out)', err)
            return
        end if
        motion = trim(keys(find_key(keys, G_SUPPORTS, end//'_motion'))%s)
        frequency = keys(find_key(keys, G_SUPPORTS, end//'_frequency'))%r
        angle_amplitude = keys(find_key(keys, G_SUPPORTS, end//'_angle_amplitude_deg'))%r
        release = keys(find_key(keys, G_SUPPORTS, end//'_release_time'))%r
        if (motion /= 'fixed' .and. support == 'free') then
            call fail(keys, G_SUPPORTS, end//'_motion', '"'//motion//'"', 'the '//end// &
                ' end is free: there is no support to move (set '//end//' = ''pinned'' or ' &
                //'''clamped'')', err)
        else if (release >= 0.0_wp .and. support == 'free') then
            call fail(keys, G_SUPPORTS, end//'_release_time', real_text(release), 'the ' &
                //end//' end is free already (a release needs '//end//' = ''pinned'' or ' &
                //'''clamped''; < 0 means never)', err)
        else if (motion == 'harmonic' .and. .not. frequency > 0.0_wp) then
            call fail(keys, G_SUPPORTS, end//'_frequency', real_text(frequency), 'must be ' &
                //'> 0 for '//end//'_motion = ''harmonic''', err)
        else if (motion == 'harmonic' .and. abs(angle_amplitude) > 0.0_wp .and. &
                 support /= 'clamped') then
            call fail(keys, G_SUPPORTS, end//'_angle_amplitude_deg', real_text(angle_amplitude), &
                'only a clamped support turns ('//end//' = "'//support//'")', err)
        else if (motion == 'table') then
            k = find_key(keys, G_SUPPORTS, end//'_table')
            if (len_trim(keys(k)%s) == 0) then
                call fail(keys, G_SUPPORTS, end//'_table', "''", 'a file is needed for ' &
                    //end//'_motion = ''table'' (rows t, dx, dy, dangle_deg)', err)
                return
            end if
            full = absolute_path(trim(keys(k)%s), scene%path)
            if (len(full) > len(keys(k)%s)) then
                call fail(keys, G_SUPPORTS, end//'_table', '"'//full(:40)//'..."', &
                    'too long (at most '//int_text(len(keys(k)%s))//' characters)', err)
                return
            end if
            keys(k)%s = full
            call read_motion_table(full, keys(k)%origin//': &supports: '//end//'_table', &
                rows, err)
        end if
    end subroutine check_motion

    !> `&initial shape = 'state'` needs `state_file`, an existing file (a relative path is
    !! resolved against the scene file's directory); the record is read by the run.
    subroutine check_state_file(keys, scene, err)
        type(scene_key_t), intent(inout) :: keys(:)
        type(scene_t), intent(in) :: scene
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: full
        logical :: exists
        integer :: k
        if (scene%initial%shape /= 'state') return
        k = find_key(keys, G_INITIAL, 'state_file')
        if (len_trim(keys(k)%s) == 0) then
            call fail(keys, G_INITIAL, 'state_file', "''", 'a run file (HDF5) is needed for ' &
                //'shape = ''state'' (and state_time: the time of its record, < 0 the last)', err)
            return
        end if
        full = absolute_path(trim(keys(k)%s), scene%path)
        if (len(full) > len(keys(k)%s)) then
            call fail(keys, G_INITIAL, 'state_file', '"'//full(:40)//'..."', &
                'too long (at most '//int_text(len(keys(k)%s))//' characters)', err)
            return
        end if
        inquire (file=full, exist=exists)
        if (.not. exists) then
            call fail(keys, G_INITIAL, 'state_file', '"'//trim(keys(k)%s)//'"', 'no such file (' &
                //full//')', err)
            return
        end if
        keys(k)%s = full
    end subroutine check_state_file

    subroutine check_initial_and_fluid(keys, scene, err)
        type(scene_key_t), intent(in) :: keys(:)
        type(scene_t), intent(in) :: scene
        type(error_t), allocatable, intent(out) :: err
        logical :: any_drag
        associate (i => scene%initial, f => scene%fluid, g => scene%ground)
            any_drag = f%density*(f%normal_drag_coefficient + f%tangential_drag_coefficient) &
                > 0.0_wp .or. f%linear_normal_drag + f%linear_tangential_drag > 0.0_wp
            if (scene%model%kind == 'mpp' .and. any(abs(i%velocity) > 0.0_wp)) then
                call fail(keys, G_INITIAL, 'velocity', pair_text(i%velocity), 'the mpp model ' &
                    //'starts at rest from its pinned top joint (use the rfem model)', err)
            else if (i%shape == 'folded' .and. mod(scene%model%elements, 2) /= 1) then
                call fail(keys, G_INITIAL, 'shape', '"folded"', 'needs an odd number of ' &
                    //'elements (two equal halves and one across the fold; elements = ' &
                    //int_text(scene%model%elements)//')', err, also='model.elements')
            else if (scene%effects%drag .and. .not. any_drag) then
                call fail(keys, G_EFFECTS, 'drag', '.true.', 'every drag coefficient of &fluid ' &
                    //'is zero (give density and a drag coefficient, or a linear drag)', err)
            else if (.not. all(ieee_is_finite(g%normal)) .or. .not. norm2(g%normal) > 0.0_wp) &
                then
                call fail(keys, G_GROUND, 'normal', pair_text(g%normal), 'must be a finite, ' &
                    //'non-zero vector (towards the free side; (-1, 0) is up)', err)
            end if
        end associate
    end subroutine check_initial_and_fluid

    !> An entry k of the attachments is used when its position is given (not NaN): the
    !! position within the rope, its values valid; no value without a position.
    subroutine check_attachments(keys, scene, err)
        type(scene_key_t), intent(in) :: keys(:)
        type(scene_t), intent(in) :: scene
        type(error_t), allocatable, intent(out) :: err
        integer :: k
        associate (a => scene%attachments)
            do k = 1, N_ATTACH
                if (ieee_is_nan(a%mass_positions(k))) then
                    call unused('masses', a%masses(k), 'mass_positions')
                else
                    call position('mass_positions', a%mass_positions(k))
                    if (allocated(err)) return
                    if (ieee_is_finite(a%masses(k)) .and. a%masses(k) > 0.0_wp) then
                        continue
                    else if (.not. keys(find_key(keys, G_ATTACHMENTS, 'masses'))%given) then
                        ! (named by the position: where it came from, masses from nowhere)
                        call fail_at('mass_positions', a%mass_positions(k), 'a point mass ' &
                            //'there needs masses('//int_text(k)//') > 0 (kg), not given')
                    else
                        call fail_at('masses', a%masses(k), 'must be > 0 (a mass at ' &
                            //'mass_positions('//int_text(k)//') = ' &
                            //real_text(a%mass_positions(k))//' m)')
                    end if
                end if
                if (allocated(err)) return
                if (ieee_is_nan(a%load_positions(k))) then
                    call unused('load_force_x', a%load_force_x(k), 'load_positions')
                    call unused('load_force_y', a%load_force_y(k), 'load_positions')
                    call unused('load_amplitude_x', a%load_amplitude_x(k), 'load_positions')
                    call unused('load_amplitude_y', a%load_amplitude_y(k), 'load_positions')
                    call unused('load_frequency', a%load_frequency(k), 'load_positions')
                    call unused('load_phase_deg', a%load_phase_deg(k), 'load_positions')
                else
                    call position('load_positions', a%load_positions(k))
                    call finite('load_force_x', a%load_force_x(k))
                    call finite('load_force_y', a%load_force_y(k))
                    call finite('load_amplitude_x', a%load_amplitude_x(k))
                    call finite('load_amplitude_y', a%load_amplitude_y(k))
                    call finite('load_phase_deg', a%load_phase_deg(k))
                    if (.not. (ieee_is_finite(a%load_frequency(k)) .and. &
                        a%load_frequency(k) >= 0.0_wp)) call fail_at('load_frequency', &
                        a%load_frequency(k), 'must be >= 0')
                end if
                if (allocated(err)) return
            end do
        end associate
    contains
        subroutine fail_at(key, x, reason)
            character(len=*), intent(in) :: key, reason
            real(wp), intent(in) :: x
            if (allocated(err)) return
            call fail(keys, G_ATTACHMENTS, key//'('//int_text(k)//')', real_text(x), reason, err)
        end subroutine fail_at

        subroutine position(key, x)
            character(len=*), intent(in) :: key
            real(wp), intent(in) :: x
            if (.not. (ieee_is_finite(x) .and. x >= 0.0_wp .and. x <= scene%rope%length)) &
                call fail_at(key, x, 'must be in 0 .. '//real_text(scene%rope%length) &
                //' (m along the rope from its top end; length = ' &
                //real_text(scene%rope%length)//')')
        end subroutine position

        subroutine finite(key, x)
            character(len=*), intent(in) :: key
            real(wp), intent(in) :: x
            if (.not. ieee_is_finite(x)) call fail_at(key, x, 'must be finite')
        end subroutine finite

        subroutine unused(key, x, position_key)
            character(len=*), intent(in) :: key, position_key
            real(wp), intent(in) :: x
            if (abs(x) > 0.0_wp .or. ieee_is_nan(x)) call fail_at(key, x, 'no ' &
                //position_key//'('//int_text(k)//') given (an entry is used when its ' &
                //'position is given)')
        end subroutine unused
    end subroutine check_attachments

    !> max_order within the method's range (0: its default, resolved here) and the
    !! CVODE-only stability-limit detection.
    subroutine check_solver(keys, scene, err)
        type(scene_key_t), intent(in) :: keys(:)
        type(scene_t), intent(inout) :: scene
        type(error_t), allocatable, intent(out) :: err
        associate (v => scene%solver, m => METHODS(method_index(scene%solver%method)))
            v%max_order = resolved_max_order(v%method, v%max_order)
            ! max_order 0 after resolving: the method chooses (auto); the stability-limit
            ! check below applies to it too
            if (v%max_order /= 0 .and. (v%max_order < m%lowest_order .or. &
                                        v%max_order > m%highest_order)) then
                call fail(keys, G_SOLVER, 'max_order', int_text(v%max_order), &
                    'out of range for method '//trim(v%method)//' (allowed: '// &
                    int_text(m%lowest_order)//' .. '//int_text(m%highest_order)// &
                    ', or 0 for '//default_order_text(m%default_order)//')', err)
            else if (v%stability_limit_detection .and. v%method /= 'cvode') then
                call fail(keys, G_SOLVER, 'stability_limit_detection', '.true.', &
                    'only for method cvode (method '//trim(v%method)//' has no such option; '// &
                    'limit its order with max_order)', err)
            end if
        end associate
    end subroutine check_solver

    !> What max_order = 0 means for a method whose default order is `order` (0: it chooses).
    pure function default_order_text(order) result(text)
        integer, intent(in) :: order
        character(len=:), allocatable :: text
        if (order == 0) then
            text = 'the method''s own choice'
        else
            text = 'the default '//int_text(order)
        end if
    end function default_order_text

    !> The derived defaults: those of the rope's set (resolved_rope: tangential damping, eq.
    !! 13 of the paper; the section set's EI, joint shear stiffness and dampings), and the
    !! output file out/<scene file name without .nml>.h5 when empty.
    subroutine resolve_defaults(keys, scene, err)
        type(scene_key_t), intent(in) :: keys(:)
        type(scene_t), intent(inout) :: scene
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: base
        integer :: slash
        scene%rope = resolved_rope(scene%rope)
        if (len_trim(scene%output%file) == 0) then
            slash = index(scene%path, '/', back=.true.)
            base = scene%path(slash + 1:)
            if (len(base) > 4) then
                if (lower(base(len(base) - 3:)) == '.nml') base = base(:len(base) - 4)
            end if
            if (len('out/'//base//'.h5') > len(scene%output%file)) then
                call make_error(err, ERR_INPUT, scene%path//': &output: file = '''': the ' &
                    //'default out/<scene>.h5 is too long (at most '// &
                    int_text(len(scene%output%file))//' characters): give a file')
                return
            end if
            scene%output%file = 'out/'//base//'.h5'
        end if
    end subroutine resolve_defaults
end module ropedyn_scene_checks
