!> Unit test of ropedyn_scene: defaults, values, overrides, group order, the namelist echo
!! round trip, and the error message of every kind of malformed input.
!!
!! Scene files are written into test_scene_tmp/ under the working directory.
program test_scene
    use ropedyn_kinds, only: wp, i8
    use ropedyn_error, only: error_t, ERR_INPUT
    use ropedyn_scene, only: scene_t, read_scene, scene_namelist_text
    use ropedyn_scene_solver, only: step_budget
    use ropedyn_integrator, only: default_step_budget
    use ropedyn_rope_spec, only: bottom_anchor_given
    use ropedyn_assert, only: test_suite_t
    implicit none

    character(len=*), parameter :: DIR = 'test_scene_tmp'
    character(len=1), parameter :: NO_SET(0) = [character(len=1) ::]
    real(wp), parameter :: TIGHT = 1.0e-12_wp
    type(test_suite_t) :: suite
    integer :: stat

    suite%name = 'scene'
    call execute_command_line('mkdir -p '//DIR, exitstat=stat)
    call suite%check_true(stat == 0, 'create '//DIR)

    call test_defaults()
    call test_values()
    call test_overrides()
    call test_group_order()
    call test_round_trip()
    call test_errors()
    call test_effect_keys()

    call suite%finish()

contains

    !> Write a file, one element of `lines` per line (trailing blanks removed).
    subroutine write_file(path, lines)
        character(len=*), intent(in) :: path
        character(len=*), intent(in) :: lines(:)
        integer :: unit, ios, i
        character(len=256) :: msg
        open (newunit=unit, file=path, status='replace', action='write', iostat=ios, &
            iomsg=msg)
        if (ios /= 0) then
            call suite%check_true(.false., 'open '//path//': '//trim(msg))
            return
        end if
        do i = 1, size(lines)
            write (unit, '(a)', iostat=ios, iomsg=msg) trim(lines(i))
            if (ios /= 0) then
                call suite%check_true(.false., 'write '//path//': '//trim(msg))
                exit
            end if
        end do
        close (unit)
    end subroutine write_file

    !> Read a scene that must be valid.
    subroutine read_ok(path, overrides, scene, label)
        character(len=*), intent(in) :: path
        character(len=*), intent(in) :: overrides(:)
        type(scene_t), intent(out) :: scene
        character(len=*), intent(in) :: label
        type(error_t), allocatable :: err
        call read_scene(path, overrides, scene, err)
        if (allocated(err)) then
            call suite%check_true(.false., label//': unexpected error: '//err%message)
        else
            call suite%check_true(.true., label//': read without error')
        end if
    end subroutine read_ok

    subroutine test_defaults()
        type(scene_t) :: s
        character(len=*), parameter :: PATH = DIR//'/defaults.nml'
        call write_file(PATH, [character(len=20) :: '&model /'])
        call read_ok(PATH, NO_SET, s, 'defaults')
        call suite%check_true(s%path == PATH, 'defaults: path')
        call suite%check_close(s%rope%length, 1.0_wp, TIGHT, 0.0_wp, 'defaults: length')
        call suite%check_close(s%rope%density, 6000.0_wp, TIGHT, 0.0_wp, 'defaults: density')
        call suite%check_close(s%rope%diameter, 0.005_wp, TIGHT, 0.0_wp, 'defaults: diameter')
        call suite%check_close(s%rope%young_modulus, 35.0e6_wp, TIGHT, 0.0_wp, 'defaults: E')
        call suite%check_close(s%rope%shear_modulus, 14.0e6_wp, TIGHT, 0.0_wp, 'defaults: G')
        call suite%check_close(s%rope%normal_damping, 1.0e3_wp, TIGHT, 0.0_wp, 'defaults: eta')
        call suite%check_close(s%rope%tangential_damping, 400.0_wp, TIGHT, 0.0_wp, &
            'defaults: eta_bar = eta G/E')
        call suite%check_close(s%rope%shape_factor, 10.0_wp/9.0_wp, TIGHT, 0.0_wp, &
            'defaults: chi')
        call suite%check_close(s%rope%gravity, 9.81_wp, TIGHT, 0.0_wp, 'defaults: gravity')
        call suite%check_true(s%model%kind == 'rfem', 'defaults: kind')
        call suite%check_true(s%model%elements == 30, 'defaults: elements')
        call suite%check_true(s%supports%top == 'pinned', 'defaults: top')
        call suite%check_true(s%supports%bottom == 'free', 'defaults: bottom')
        call suite%check_true(all(eq(s%supports%top_anchor, 0.0_wp)), 'defaults: top_anchor')
        call suite%check_true(.not. bottom_anchor_given(s), 'defaults: bottom_anchor not given')
        call suite%check_true(.not. s%supports%bottom_anchor_set, &
            'defaults: bottom_anchor_set false')
        call suite%check_close(s%supports%support_stiffness_factor, 1.0_wp, TIGHT, 0.0_wp, &
            'defaults: support_stiffness_factor')
        call suite%check_true(s%initial%shape == 'straight', 'defaults: shape')
        call suite%check_close(s%initial%angle_deg, 75.0_wp, TIGHT, 0.0_wp, 'defaults: angle')
        call suite%check_true(s%effects%gravity .and. s%effects%tension .and. &
            s%effects%shear .and. s%effects%bending .and. s%effects%damping, &
            'defaults: all effects on')
        call suite%check_true(s%solver%method == 'auto', 'defaults: method')
        call suite%check_close(s%solver%rtol, 1.0e-6_wp, TIGHT, 0.0_wp, 'defaults: rtol')
        call suite%check_close(s%solver%atol, 1.0e-8_wp, TIGHT, 0.0_wp, 'defaults: atol')
        call suite%check_true(s%solver%max_order == 0, 'defaults: max_order')
        call suite%check_true(s%solver%max_steps == 0, 'defaults: max_steps (0: by t_end)')
        call suite%check_true(step_budget(s) == default_step_budget(s%solver%t_end), &
            'defaults: the step budget is the default of the run''s length')
        s%solver%t_end = 600.0_wp
        call suite%check_true(step_budget(s) == default_step_budget(600.0_wp) .and. &
            step_budget(s) > default_step_budget(30.0_wp), &
            'defaults: a longer run has a larger budget')
        s%solver%t_end = 30.0_wp
        call suite%check_close(s%solver%t_end, 30.0_wp, TIGHT, 0.0_wp, 'defaults: t_end')
        call suite%check_close(s%solver%output_interval, 0.01_wp, TIGHT, 0.0_wp, &
            'defaults: output_interval')
        call suite%check_true(.not. s%solver%stability_limit_detection, &
            'defaults: stability_limit_detection off')
        call suite%check_true(s%effects%fault_nan_after < 0.0_wp, 'defaults: fault_nan_after off')
        call suite%check_true(index(scene_namelist_text(s), &
            'stability_limit_detection = .false.') > 0, &
            'defaults: echo of stability_limit_detection')
        call suite%check_true(s%output%file == 'out/defaults.h5', &
            'defaults: output file "'//trim(s%output%file)//'"')
        call suite%check_true(.not. s%output%progress, 'defaults: progress')
        call suite%check_true(index(scene_namelist_text(s), 'tangential_damping = 400.0') > 0, &
            'defaults: echo of eta_bar')
        call suite%check_true(index(scene_namelist_text(s), "file = 'out/defaults.h5'") > 0, &
            'defaults: echo of the resolved output file')
    end subroutine test_defaults

    subroutine test_values()
        type(scene_t) :: s
        character(len=*), parameter :: PATH = DIR//'/values.nml'
        call write_file(PATH, [character(len=60) :: &
            '! a scene with every group', &
            '&rope', &
            '    length = 2.5        ! m', &
            '    density = 7800.0, diameter = 0.01', &
            '    young_modulus = 2.1e11', &
            '    shear_modulus = 8.0e10', &
            '    normal_damping = 0.1', &
            '    tangential_damping = 0.04', &
            '    shape_factor = 1.2', &
            '    gravity = 0.0', &
            '/', &
            '', &
            '&MODEL kind = ''RFEM'', elements = 12 /', &
            '&supports', &
            '    top = ''Clamped'', bottom = "clamped"', &
            '    top_anchor = 0.1, -0.2', &
            '    bottom_anchor = 2.6, 0.0', &
            '    top_angle_deg = 10.0', &
            '    bottom_angle_deg = -5.0', &
            '    support_stiffness_factor = 100.0', &
            '/', &
            '&initial shape = ''hanging'', angle_deg = 0.0 /', &
            '&effects', &
            '    gravity = .false., tension = T, shear = .false.', &
            '    bending = F, damping = .true., fault_nan_after = 1.5', &
            '/', &
            '&solver', &
            '    method = ''cvode'', rtol = 1e-9, atol = 1e-12', &
            '    max_order = 3, max_steps = 5000', &
            '    t_end = 2.0, output_interval = 0.5', &
            '    stability_limit_detection = T', &
            '/', &
            '&output file = ''results/run 1.h5'', progress = .true. /'])
        call read_ok(PATH, NO_SET, s, 'values')
        call suite%check_close(s%rope%length, 2.5_wp, TIGHT, 0.0_wp, 'values: length')
        call suite%check_close(s%rope%density, 7800.0_wp, TIGHT, 0.0_wp, 'values: density')
        call suite%check_close(s%rope%diameter, 0.01_wp, TIGHT, 0.0_wp, 'values: diameter')
        call suite%check_close(s%rope%young_modulus, 2.1e11_wp, TIGHT, 0.0_wp, 'values: E')
        call suite%check_close(s%rope%tangential_damping, 0.04_wp, TIGHT, 0.0_wp, &
            'values: eta_bar given')
        call suite%check_close(s%rope%gravity, 0.0_wp, TIGHT, 0.0_wp, 'values: gravity 0')
        call suite%check_true(s%model%kind == 'rfem', 'values: kind stored in lower case')
        call suite%check_true(s%model%elements == 12, 'values: elements')
        call suite%check_true(s%supports%top == 'clamped', 'values: top lower case')
        call suite%check_true(s%supports%bottom == 'clamped', 'values: bottom')
        call suite%check_close(s%supports%top_anchor(2), -0.2_wp, TIGHT, 0.0_wp, &
            'values: top_anchor(2)')
        call suite%check_true(bottom_anchor_given(s) .and. s%supports%bottom_anchor_set, &
            'values: bottom_anchor given')
        call suite%check_close(s%supports%bottom_anchor(1), 2.6_wp, TIGHT, 0.0_wp, &
            'values: bottom_anchor(1)')
        call suite%check_close(s%supports%bottom_angle_deg, -5.0_wp, TIGHT, 0.0_wp, &
            'values: bottom_angle_deg')
        call suite%check_close(s%supports%support_stiffness_factor, 100.0_wp, TIGHT, 0.0_wp, &
            'values: support_stiffness_factor')
        call suite%check_true(s%initial%shape == 'hanging', 'values: shape')
        call suite%check_true(.not. s%effects%gravity .and. s%effects%tension .and. &
            .not. s%effects%shear .and. .not. s%effects%bending .and. s%effects%damping, &
            'values: effects')
        call suite%check_close(s%solver%rtol, 1.0e-9_wp, TIGHT, 0.0_wp, 'values: rtol')
        call suite%check_true(s%solver%max_order == 3 .and. s%solver%max_steps == 5000, &
            'values: max_order, max_steps')
        call suite%check_true(step_budget(s) == 5000_i8, 'values: the step budget is max_steps')
        call suite%check_close(s%solver%output_interval, 0.5_wp, TIGHT, 0.0_wp, &
            'values: output_interval')
        call suite%check_true(s%solver%stability_limit_detection, &
            'values: stability_limit_detection')
        call suite%check_close(s%effects%fault_nan_after, 1.5_wp, TIGHT, 0.0_wp, &
            'values: fault_nan_after')
        call suite%check_true(s%output%file == 'results/run 1.h5', 'values: file')
        call suite%check_true(s%output%progress, 'values: progress')
    end subroutine test_values

    subroutine test_overrides()
        type(scene_t) :: s
        character(len=*), parameter :: PATH = DIR//'/overrides.nml'
        call write_file(PATH, [character(len=40) :: &
            '&model elements = 40 /', '&solver rtol = 1e-4 /', '&rope normal_damping = 5.0 /'])
        call read_ok(PATH, [character(len=40) :: 'model.elements=70', ' solver.rtol=1e-8 ', &
            'rope.normal_damping = 0.1', 'supports.top=clamped', 'SUPPORTS.Bottom="Pinned"', &
            'output.file=out/a b/c.h5', 'supports.bottom_anchor=1.0, 0.5', &
            'effects.bending=.false.', 'supports.top_anchor(2)=0.25'], s, 'overrides')
        call suite%check_true(s%model%elements == 70, 'overrides: elements 70 over file 40')
        call suite%check_close(s%solver%rtol, 1.0e-8_wp, TIGHT, 0.0_wp, &
            'overrides: rtol over file')
        call suite%check_close(s%rope%tangential_damping, 0.04_wp, TIGHT, 0.0_wp, &
            'overrides: eta_bar derived from overridden eta')
        call suite%check_true(s%supports%top == 'clamped', 'overrides: unquoted string')
        call suite%check_true(s%supports%bottom == 'pinned', 'overrides: quoted string')
        call suite%check_true(s%output%file == 'out/a b/c.h5', 'overrides: path with / and blank')
        call suite%check_close(s%supports%bottom_anchor(2), 0.5_wp, TIGHT, 0.0_wp, &
            'overrides: array value')
        call suite%check_close(s%supports%top_anchor(2), 0.25_wp, TIGHT, 0.0_wp, &
            'overrides: indexed element')
        call suite%check_true(.not. s%effects%bending, 'overrides: logical')
        call read_ok(PATH, [character(len=40) :: 'model.elements=50', 'model.elements=60'], &
            s, 'overrides twice')
        call suite%check_true(s%model%elements == 60, 'overrides: the last one wins')
    end subroutine test_overrides

    subroutine test_group_order()
        type(scene_t) :: s
        character(len=*), parameter :: PATH = DIR//'/order.nml'
        call write_file(PATH, [character(len=40) :: &
            '&output progress = .true. /', &
            '&solver t_end = 5.0 /', &
            '&effects damping = .false. /', &
            '&initial angle_deg = 30.0 /', &
            '&supports bottom = ''pinned'' /', &
            '&rope length = 3.0 /', &
            '  &model', '  elements = 8', '  /'])
        call read_ok(PATH, NO_SET, s, 'order')
        call suite%check_true(s%output%progress .and. .not. s%effects%damping .and. &
            s%supports%bottom == 'pinned' .and. s%model%elements == 8, 'order: groups read')
        call suite%check_close(s%solver%t_end, 5.0_wp, TIGHT, 0.0_wp, 'order: t_end')
        call suite%check_close(s%initial%angle_deg, 30.0_wp, TIGHT, 0.0_wp, 'order: angle')
        call suite%check_close(s%rope%length, 3.0_wp, TIGHT, 0.0_wp, 'order: length')
        call suite%check_true(s%output%file == 'out/order.h5', 'order: output file default')
    end subroutine test_group_order

    !> The echo of a scene read back gives the same scene.
    subroutine test_round_trip()
        call round_trip(DIR//'/values.nml', 'round trip values')
        call round_trip(DIR//'/defaults.nml', 'round trip defaults')
    end subroutine test_round_trip

    subroutine round_trip(path, label)
        character(len=*), intent(in) :: path, label
        type(scene_t) :: a, b
        character(len=:), allocatable :: text
        integer :: unit, ios
        character(len=256) :: msg
        msg = ''
        call read_ok(path, NO_SET, a, label//' (first read)')
        text = scene_namelist_text(a)
        open (newunit=unit, file=DIR//'/echo.nml', status='replace', action='write', &
            iostat=ios, iomsg=msg)
        call suite%check_true(ios == 0, label//': open echo file '//trim(msg))
        if (ios /= 0) return
        write (unit, '(a)') text
        close (unit)
        call read_ok(DIR//'/echo.nml', NO_SET, b, label//' (echo read)')
        call suite%check_true(index(text, '&rope') > 0 .and. index(text, '&model') > 0 .and. &
            index(text, '&supports') > 0 .and. index(text, '&initial') > 0 .and. &
            index(text, '&effects') > 0 .and. index(text, '&solver') > 0 .and. &
            index(text, '&output') > 0, label//': all groups in the echo')
        call suite%check_true(same_scene(a, b), label//': same values after the round trip')
        call suite%check_true(index(text, new_line('a')//'    young_modulus = ') > 0, &
            label//': one key a line, indented')
    end subroutine round_trip

    logical function same_scene(a, b)
        type(scene_t), intent(in) :: a, b
        same_scene = eq(a%rope%length, b%rope%length) &
            .and. eq(a%rope%density, b%rope%density) &
            .and. eq(a%rope%diameter, b%rope%diameter) &
            .and. eq(a%rope%young_modulus, b%rope%young_modulus) &
            .and. eq(a%rope%shear_modulus, b%rope%shear_modulus) &
            .and. eq(a%rope%normal_damping, b%rope%normal_damping) &
            .and. eq(a%rope%tangential_damping, b%rope%tangential_damping) &
            .and. eq(a%rope%shape_factor, b%rope%shape_factor) &
            .and. eq(a%rope%gravity, b%rope%gravity) &
            .and. a%model%kind == b%model%kind &
            .and. a%model%elements == b%model%elements &
            .and. a%supports%top == b%supports%top &
            .and. a%supports%bottom == b%supports%bottom &
            .and. all(eq(a%supports%top_anchor, b%supports%top_anchor)) &
            .and. (bottom_anchor_given(a) .eqv. bottom_anchor_given(b)) &
            .and. eq(a%supports%top_angle_deg, b%supports%top_angle_deg) &
            .and. eq(a%supports%bottom_angle_deg, b%supports%bottom_angle_deg) &
            .and. eq(a%supports%support_stiffness_factor, b%supports%support_stiffness_factor) &
            .and. a%initial%shape == b%initial%shape &
            .and. eq(a%initial%angle_deg, b%initial%angle_deg) &
            .and. (a%effects%gravity .eqv. b%effects%gravity) &
            .and. (a%effects%tension .eqv. b%effects%tension) &
            .and. (a%effects%shear .eqv. b%effects%shear) &
            .and. (a%effects%bending .eqv. b%effects%bending) &
            .and. (a%effects%damping .eqv. b%effects%damping) &
            .and. a%solver%method == b%solver%method &
            .and. eq(a%solver%rtol, b%solver%rtol) &
            .and. eq(a%solver%atol, b%solver%atol) &
            .and. a%solver%max_order == b%solver%max_order &
            .and. a%solver%max_steps == b%solver%max_steps &
            .and. eq(a%solver%t_end, b%solver%t_end) &
            .and. eq(a%solver%output_interval, b%solver%output_interval) &
            .and. (a%solver%stability_limit_detection .eqv. b%solver%stability_limit_detection) &
            .and. eq(a%effects%fault_nan_after, b%effects%fault_nan_after) &
            .and. a%output%file == b%output%file &
            .and. (a%output%progress .eqv. b%output%progress)
        if (bottom_anchor_given(a) .and. bottom_anchor_given(b)) then
            same_scene = same_scene .and. &
                all(eq(a%supports%bottom_anchor, b%supports%bottom_anchor))
        end if
    end function same_scene

    !> Exact equality without -Wcompare-reals noise.
    elemental logical function eq(a, b)
        real(wp), intent(in) :: a, b
        eq = a <= b .and. a >= b
    end function eq

    !> Write a scene file (unless `lines` is empty), read it with the overrides and check
    !! that the error is ERR_INPUT and its message holds every one of `parts`.
    subroutine expect_error(name, lines, overrides, parts)
        character(len=*), intent(in) :: name
        character(len=*), intent(in) :: lines(:), overrides(:), parts(:)
        type(scene_t) :: s
        type(error_t), allocatable :: err
        character(len=:), allocatable :: path
        integer :: i
        path = DIR//'/'//name//'.nml'
        if (size(lines) > 0) call write_file(path, lines)
        call read_scene(path, overrides, s, err)
        if (.not. allocated(err)) then
            call suite%check_true(.false., name//': expected an error, got none')
            return
        end if
        write (*, '(a)') '      message: '//err%message
        call suite%check_true(err%code == ERR_INPUT, name//': class ERR_INPUT')
        do i = 1, size(parts)
            call suite%check_contains(err%message, trim(parts(i)), name//': message')
        end do
    end subroutine expect_error

    subroutine test_errors()
        character(len=*), parameter :: P = DIR//'/'
        integer, parameter :: L = 100
        character(len=L), parameter :: MODEL(1) = [character(len=L) :: '&model /']

        ! The file
        call expect_error('missing', [character(len=L) ::], NO_SET, [character(len=L) :: &
            P//'missing.nml: cannot open: '])
        call expect_error('no_model', [character(len=L) :: '&rope length = 2.0 /'], NO_SET, &
            [character(len=L) :: P//'no_model.nml: no &model group (found &rope): not a scene file'])
        call expect_error('not_closed', [character(len=L) :: '&rope', '  length = 2.0', &
            '&model /'], NO_SET, [character(len=L) :: P//'not_closed.nml: &rope: ', &
            'not closed by "/" before line 3', '"&model /"'])
        call expect_error('not_closed_eof', [character(len=L) :: '&model /', '&rope', &
            '  length = 2.0'], NO_SET, [character(len=L) :: P//'not_closed_eof.nml: &rope: ', &
            'not closed by "/" before the end of the file'])
        call expect_error('unknown_group', [character(len=L) :: '&model /', '&rop', &
            '  length = 2.0', '/'], NO_SET, [character(len=L) :: &
            P//'unknown_group.nml: &rop: unknown group', 'line 2'])
        call expect_error('twice', [character(len=L) :: '&model /', '&model elements = 3 /'], &
            NO_SET, [character(len=L) :: P//'twice.nml: &model: group given twice', &
            'lines 1 and 2'])
        call expect_error('outside', [character(len=L) :: '&model /', 'length = 2.0'], &
            NO_SET, [character(len=L) :: P//'outside.nml: line 2: text outside any group', &
            '"length = 2.0"'])

        ! A group that cannot be read
        call expect_error('garbage', [character(len=L) :: '&model /', '&rope', &
            '  density = 10.0, length = 2.0 garbage', '/'], NO_SET, [character(len=L) :: &
            P//'garbage.nml: &rope: cannot read length = 2.0 garbage', 'expected a real number', &
            '(line 3: "  density = 10.0, length = 2.0 garbage")'])
        call expect_error('wrong_type', [character(len=L) :: '&model', '  kind = ''rfem''', &
            '  elements = ''many''', '/'], NO_SET, [character(len=L) :: &
            P//'wrong_type.nml: &model: cannot read elements = ''many''', &
            'expected an integer', '(line 3: "  elements = ''many''")'])
        call expect_error('not_a_real', [character(len=L) :: '&model /', '&rope', &
            '  length = ''abc''', '/'], NO_SET, [character(len=L) :: &
            P//'not_a_real.nml: &rope: cannot read length = ''abc''', 'expected a real number', &
            'line 3'])
        call expect_error('unquoted', [character(len=L) :: '&model kind = rfem /'], NO_SET, &
            [character(len=L) :: P//'unquoted.nml: &model: cannot read kind = rfem', &
            'expected a quoted string (kind = ''rfem'')', 'line 1'])
        call expect_error('bad_logical', [character(len=L) :: '&model /', &
            '&effects bending = yes /'], NO_SET, [character(len=L) :: &
            P//'bad_logical.nml: &effects: cannot read bending = yes', &
            'expected .true. or .false.'])
        call expect_error('too_many', [character(len=L) :: '&model /', &
            '&supports top_anchor = 1.0, 2.0, 3.0 /'], NO_SET, [character(len=L) :: &
            P//'too_many.nml: &supports: cannot read top_anchor = 1.0, 2.0, 3.0', &
            'expected two real numbers'])
        call expect_error('unknown_key', [character(len=L) :: '&model /', '&rope', &
            '  lenght = 2.0', '/'], NO_SET, [character(len=L) :: &
            P//'unknown_key.nml: &rope: unknown key "lenght"', '(line 3: "  lenght = 2.0")', &
            'did you mean "length"?'])
        call expect_error('unknown_key_far', [character(len=L) :: '&model colour = 1 /'], &
            NO_SET, [character(len=L) :: P//'unknown_key_far.nml: &model: unknown key "colour"', &
            'keys: kind, elements'])

        ! Values out of range
        call expect_error('length', [character(len=L) :: MODEL, '&rope length = -1.0 /'], &
            NO_SET, [character(len=L) :: P//'length.nml: &rope: length = -1.0: must be > 0'])
        call expect_error('length_zero', [character(len=L) :: MODEL, '&rope length = 0 /'], &
            NO_SET, [character(len=L) :: P//'length_zero.nml: &rope: length = 0.0: must be > 0'])
        call expect_error('diameter', [character(len=L) :: MODEL, '&rope diameter = 0.0 /'], &
            NO_SET, [character(len=L) :: P//'diameter.nml: &rope: diameter = 0.0: must be > 0'])
        call expect_error('density', [character(len=L) :: MODEL, '&rope density = -6e3 /'], &
            NO_SET, [character(len=L) :: P//'density.nml: &rope: density = -6000.0: must be > 0'])
        call expect_error('young', [character(len=L) :: MODEL, '&rope young_modulus = -35e6 /'], &
            NO_SET, [character(len=L) :: &
            P//'young.nml: &rope: young_modulus = -3.5e7: must be > 0'])
        call expect_error('eta', [character(len=L) :: MODEL, '&rope normal_damping = -1.0 /'], &
            NO_SET, [character(len=L) :: P//'eta.nml: &rope: normal_damping = -1.0: must be >= 0'])
        call expect_error('infinite', [character(len=L) :: MODEL, '&rope gravity = 1e400 /'], &
            NO_SET, [character(len=L) :: P//'infinite.nml: &rope: gravity = +Infinity: ', &
            'must be finite'])
        call expect_error('elements', [character(len=L) :: '&model elements = 1 /'], NO_SET, &
            [character(len=L) :: P//'elements.nml: &model: elements = 1: must be >= 2'])
        call expect_error('rtol', [character(len=L) :: MODEL, '&solver rtol = 0.0 /'], NO_SET, &
            [character(len=L) :: P//'rtol.nml: &solver: rtol = 0.0: must be > 0'])
        call expect_error('rtol_big', [character(len=L) :: MODEL, '&solver rtol = 1.5 /'], &
            NO_SET, [character(len=L) :: P//'rtol_big.nml: &solver: rtol = 1.5: must be < 1'])
        call expect_error('atol', [character(len=L) :: MODEL, '&solver atol = -1e-8 /'], &
            NO_SET, [character(len=L) :: P//'atol.nml: &solver: atol = -1.0e-8: must be > 0'])
        call expect_error('max_order', [character(len=L) :: MODEL, &
            '&solver method = ''cvode'', max_order = 6 /'], NO_SET, &
            [character(len=L) :: P//'max_order.nml: &solver: max_order = 6: ', &
            'out of range for method cvode (allowed: 1 .. 5, or 0 for the default 5)'])
        call expect_error('max_order_mebdf', [character(len=L) :: MODEL, &
            '&solver method = ''mebdf'', max_order = 1 /'], NO_SET, [character(len=L) :: &
            P//'max_order_mebdf.nml: &solver: max_order = 1: ', &
            'out of range for method mebdf (allowed: 2 .. 7, or 0 for the default 4)'])
        ! auto has no default order: 0 lets it choose (it said "the default 0")
        call expect_error('max_order_auto', [character(len=L) :: MODEL, &
            '&solver method = ''auto'', max_order = 9 /'], NO_SET, [character(len=L) :: &
            P//'max_order_auto.nml: &solver: max_order = 9: ', &
            'out of range for method auto (allowed: 2 .. 7, or 0 for the method''s own choice)'])
        call expect_error('stab_lim_det_mebdf', [character(len=L) :: MODEL, &
            '&solver method = ''mebdf'', stability_limit_detection = .true. /'], NO_SET, &
            [character(len=L) :: P//'stab_lim_det_mebdf.nml: &solver: ', &
            'stability_limit_detection = .true.: only for method cvode'])
        ! auto too, whose max_order stays 0 (it read, and the run failed with exit 3)
        call expect_error('stab_lim_det_auto', [character(len=L) :: MODEL, &
            '&solver stability_limit_detection = .true. /'], NO_SET, &
            [character(len=L) :: P//'stab_lim_det_auto.nml: &solver: ', &
            'stability_limit_detection = .true.: only for method cvode (method auto'])
        call expect_error('set_stab_lim_det_mebdf', MODEL, [character(len=L) :: &
            'solver.method=mebdf', 'solver.stability_limit_detection=T'], [character(len=L) :: &
            '--set solver.stability_limit_detection=T: &solver: stability_limit_detection', &
            'only for method cvode'])
        call expect_error('fault_nan_after', [character(len=L) :: MODEL, &
            '&effects fault_nan_after = 1e999 /'], NO_SET, [character(len=L) :: &
            P//'fault_nan_after.nml: &effects: fault_nan_after = +Infinity: must be finite'])
        call expect_error('max_steps', [character(len=L) :: MODEL, '&solver max_steps = -1 /'], &
            NO_SET, [character(len=L) :: P//'max_steps.nml: &solver: max_steps = -1: ', &
            'must be >= 0'])
        call expect_error('t_end', [character(len=L) :: MODEL, '&solver t_end = 0.0 /'], &
            NO_SET, [character(len=L) :: P//'t_end.nml: &solver: t_end = 0.0: must be > 0'])
        call expect_error('interval', [character(len=L) :: MODEL, &
            '&solver output_interval = -0.01 /'], NO_SET, [character(len=L) :: &
            P//'interval.nml: &solver: output_interval = -0.01: must be > 0'])
        call expect_error('anchor_half', [character(len=L) :: MODEL, &
            '&supports bottom_anchor(1) = 0.3 /'], NO_SET, [character(len=L) :: &
            P//'anchor_half.nml: &supports: bottom_anchor = 0.3, NaN: give both components'])
        call expect_error('factor', [character(len=L) :: MODEL, &
            '&supports support_stiffness_factor = 0 /'], NO_SET, [character(len=L) :: &
            P//'factor.nml: &supports: support_stiffness_factor = 0.0: must be > 0'])

        ! Names
        call expect_error('kind', [character(len=L) :: '&model kind = ''fem'' /'], NO_SET, &
            [character(len=L) :: P//'kind.nml: &model: kind = "fem": unknown (allowed: rfem, mpp)'])
        call expect_error('mpp_free_top', [character(len=L) :: '&model kind = ''MPP'' /', &
            '&supports top = ''free'' /'], NO_SET, [character(len=L) :: &
            P//'mpp_free_top.nml: &supports: top = "free": the mpp model hangs from its top'])
        call expect_error('mpp_damping_factor', [character(len=L) :: &
            '&model kind = ''mpp'', mpp_axial_damping_factor = -1 /'], NO_SET, &
            [character(len=L) :: P//'mpp_damping_factor.nml: &model: ', &
            'mpp_axial_damping_factor = -1.0: must be >= 0'])
        call expect_error('method', [character(len=L) :: MODEL, '&solver method = ''euler'' /'], &
            NO_SET, [character(len=L) :: P//'method.nml: &solver: method = "euler": ', &
            'unknown (allowed: cvode, mebdf, erk, adams, auto, symplectic)'])
        call expect_error('support', [character(len=L) :: MODEL, '&supports top = ''glued'' /'], &
            NO_SET, [character(len=L) :: P//'support.nml: &supports: top = "glued": ', &
            'unknown (allowed: pinned, clamped, free)'])
        call expect_error('shape', [character(len=L) :: MODEL, '&initial shape = ''curly'' /'], &
            NO_SET, [character(len=L) :: P//'shape.nml: &initial: shape = "curly": ', &
            'unknown (allowed: straight, hanging'])

        ! --set
        call expect_error('set_syntax', MODEL, [character(len=L) :: 'rope.length'], &
            [character(len=L) :: '--set rope.length: expected group.key=value'])
        call expect_error('set_no_dot', MODEL, [character(len=L) :: 'length=2'], &
            [character(len=L) :: '--set length=2: expected group.key=value'])
        call expect_error('set_group', MODEL, [character(len=L) :: 'foo.bar=1'], &
            [character(len=L) :: '--set foo.bar=1: unknown group "foo" ', &
            '(groups: rope, model, supports, initial, effects, solver, output, fluid, ground, '// &
            'attachments)'])
        call expect_error('set_key', MODEL, [character(len=L) :: 'rope.lenght=2'], &
            [character(len=L) :: '--set rope.lenght=2: &rope: unknown key "lenght"'])
        call expect_error('set_type', MODEL, [character(len=L) :: 'model.elements=abc'], &
            [character(len=L) :: '--set model.elements=abc: &model: cannot read elements = abc', &
            'expected an integer'])
        call expect_error('set_two_keys', MODEL, [character(len=L) :: &
            'rope.length=2 density=3'], [character(len=L) :: &
            '--set rope.length=2 density=3: &rope: cannot read length = 2 density=3'])
        call expect_error('set_range', MODEL, [character(len=L) :: 'rope.length=-2'], &
            [character(len=L) :: '--set rope.length=-2: &rope: length = -2.0: must be > 0'])
        call expect_error('set_name', MODEL, [character(len=L) :: 'supports.bottom=glued'], &
            [character(len=L) :: '--set supports.bottom=glued: &supports: bottom = "glued": ', &
            'unknown (allowed: pinned, clamped, free)'])
    end subroutine test_errors

    !> The keys of the effects beyond springs and gravity: defaults, values, the motion
    !! table (read relative to the scene file), the echo round trip and one error per group.
    subroutine test_effect_keys()
        type(scene_t) :: s, b
        character(len=*), parameter :: PATH = DIR//'/effects.nml', ECHO = DIR//'/effects_echo.nml'
        character(len=*), parameter :: P = DIR//'/'
        integer, parameter :: L = 100
        character(len=L), parameter :: MODEL(1) = [character(len=L) :: '&model /']
        character(len=:), allocatable :: text
        integer :: unit

        call write_file(DIR//'/defaults.nml', [character(len=20) :: '&model /'])
        call read_ok(DIR//'/defaults.nml', NO_SET, s, 'effect keys: defaults')
        call suite%check_true(.not. s%effects%drag .and. .not. s%effects%ground .and. &
            s%effects%support_motion .and. s%effects%point_masses .and. s%effects%point_loads, &
            'effect keys: defaults of the switches (drag, ground off)')
        call suite%check_true(s%supports%top_motion == 'fixed' .and. &
            s%supports%bottom_motion == 'fixed' .and. s%supports%top_release_time < 0.0_wp &
            .and. s%supports%bottom_release_time < 0.0_wp, &
            'effect keys: supports fixed, never released')
        call suite%check_true(all(eq(s%initial%velocity, 0.0_wp)), 'effect keys: at rest')
        call suite%check_close(s%fluid%density, 1.225_wp, TIGHT, 0.0_wp, 'effect keys: air')
        call suite%check_close(s%fluid%normal_drag_coefficient, 1.2_wp, TIGHT, 0.0_wp, &
            'effect keys: C_n')
        call suite%check_close(s%fluid%tangential_drag_coefficient, 0.02_wp, TIGHT, 0.0_wp, &
            'effect keys: C_t')
        call suite%check_true(all(eq(s%ground%point, [1.0_wp, 0.0_wp])) .and. &
            all(eq(s%ground%normal, [-1.0_wp, 0.0_wp])), 'effect keys: ground 1 m below, up')
        call suite%check_close(s%ground%stiffness, 1.0e5_wp, TIGHT, 0.0_wp, 'effect keys: k')
        call suite%check_close(s%ground%friction_coefficient, 0.5_wp, TIGHT, 0.0_wp, &
            'effect keys: mu')
        call suite%check_true(all(s%attachments%mass_positions /= s%attachments%mass_positions) &
            .and. all(s%attachments%load_positions /= s%attachments%load_positions), &
            'effect keys: no attachments (positions NaN)')

        call write_file(DIR//'/shake.dat', [character(len=40) :: '# t dx dy dangle', &
            '0 0 0 0', '0.5, 0.01, -0.02, 4', '1.0 0 0 0'])
        call write_file(PATH, [character(len=L) :: &
            '&model elements = 9 /', &
            '&supports top = ''clamped'', top_motion = ''Harmonic'', top_amplitude = 0.01, 0.02', &
            '   top_frequency = 2.5, top_phase_deg = 10, 20, top_angle_amplitude_deg = 3', &
            '   top_angle_phase_deg = 45, bottom = ''pinned'', bottom_motion = ''table''', &
            '   bottom_table = ''shake.dat'', bottom_release_time = 0.75 /', &
            '&initial shape = ''folded'', velocity = 0.1, -0.2 /', &
            '&effects drag = T, ground = T, point_loads = F /', &
            '&fluid density = 1000, normal_drag_coefficient = 1.1, current = 0.3, 0 /', &
            '&ground point = 0.8, 0.1, normal = -1, 0.5, stiffness = 2e4, damping = 10 /', &
            '&attachments mass_positions = 1.0, 0.5, masses = 0.2, 0.1', &
            '   load_positions(3) = 0.25, load_force_x(3) = 1.5, load_frequency(3) = 2 /'])
        call read_ok(PATH, NO_SET, s, 'effect keys: values')
        call suite%check_true(s%supports%top_motion == 'harmonic', 'effect keys: motion lower case')
        call suite%check_close(s%supports%top_amplitude(2), 0.02_wp, TIGHT, 0.0_wp, &
            'effect keys: top_amplitude(2)')
        call suite%check_true(allocated(s%supports%bottom_table_rows), 'effect keys: table read')
        if (allocated(s%supports%bottom_table_rows)) then
            call suite%check_true(size(s%supports%bottom_table_rows, 2) == 3, &
                'effect keys: three table rows')
            call suite%check_close(s%supports%bottom_table_rows(4, 2), &
                4.0_wp*acos(-1.0_wp)/180.0_wp, &
                TIGHT, 0.0_wp, 'effect keys: table angle in rad')
        end if
        call suite%check_true(s%supports%bottom_table(1:1) == '/' .and. index(s%supports% &
            bottom_table, DIR//'/shake.dat') > 0, 'effect keys: table resolved against the '// &
            'scene directory, absolute: '//trim(s%supports%bottom_table))
        call suite%check_true(s%initial%shape == 'folded' .and. eq(s%initial%velocity(2), &
            -0.2_wp), 'effect keys: folded, velocity')
        call suite%check_true(s%effects%drag .and. s%effects%ground .and. &
            .not. s%effects%point_loads, 'effect keys: switches')
        call suite%check_close(s%attachments%masses(1), 0.2_wp, TIGHT, 0.0_wp, &
            'effect keys: masses(1)')
        call suite%check_close(s%attachments%load_force_x(3), 1.5_wp, TIGHT, 0.0_wp, &
            'effect keys: load_force_x(3)')
        text = scene_namelist_text(s)
        call suite%check_true(index(text, '&fluid') > 0 .and. index(text, '&ground') > 0 .and. &
            index(text, '&attachments') > 0, 'effect keys: the new groups in the echo')
        call suite%check_true(index(text, 'mass_positions = 1.0, 0.5') > 0 .and. &
            index(text, 'load_positions = NaN, NaN, 0.25') > 0, 'effect keys: lists in the echo')
        open (newunit=unit, file=ECHO, status='replace', action='write')
        write (unit, '(a)') text
        close (unit)
        call read_ok(ECHO, NO_SET, b, 'effect keys: echo read')
        call suite%check_true(scene_namelist_text(b) == text, 'effect keys: the echo reads '// &
            'back to the same scene')

        ! one error per group (at least)
        call expect_error('motion_name', [character(len=L) :: MODEL, &
            '&supports top_motion = ''wobble'' /'], NO_SET, [character(len=L) :: &
            P//'motion_name.nml: &supports: top_motion = "wobble": ', &
            'unknown (allowed: fixed, harmonic, table, coupled)'])
        call expect_error('motion_frequency', [character(len=L) :: MODEL, &
            '&supports top_motion = ''harmonic'', top_amplitude = 0.01, 0 /'], NO_SET, &
            [character(len=L) :: P//'motion_frequency.nml: &supports: top_frequency = 0.0: ', &
            'must be > 0 for top_motion = ''harmonic'''])
        call expect_error('motion_free', [character(len=L) :: MODEL, &
            '&supports bottom_motion = ''harmonic'', bottom_frequency = 1 /'], NO_SET, &
            [character(len=L) :: P//'motion_free.nml: &supports: bottom_motion = "harmonic": '// &
            'the bottom end is free'])
        call expect_error('release_free', [character(len=L) :: MODEL, &
            '&supports bottom_release_time = 0.5 /'], NO_SET, [character(len=L) :: &
            P//'release_free.nml: &supports: bottom_release_time = 0.5: the bottom end is free'])
        call expect_error('angle_pinned', [character(len=L) :: MODEL, &
            '&supports top_motion = ''harmonic'', top_frequency = 1, '// &
            'top_angle_amplitude_deg = 2 /'], &
            NO_SET, [character(len=L) :: P//'angle_pinned.nml: &supports: ', &
            'top_angle_amplitude_deg = 2.0: only a clamped support turns'])
        call expect_error('table_missing', [character(len=L) :: MODEL, &
            '&supports top_motion = ''table'', top_table = ''nowhere.dat'' /'], NO_SET, &
            [character(len=L) :: P//'table_missing.nml: &supports: top_table = "', &
            'nowhere.dat": cannot open'])
        call write_file(DIR//'/bad_table.dat', [character(len=20) :: '0 0 0 0', '0.5 0 0', &
            '1 0 0 0'])
        call expect_error('table_bad', [character(len=L) :: MODEL, &
            '&supports top_motion = ''table'', top_table = ''bad_table.dat'' /'], NO_SET, &
            [character(len=L) :: 'bad_table.dat": line 2 ("0.5 0 0"): expected four numbers'])
        call expect_error('table_none', [character(len=L) :: MODEL, &
            '&supports top_motion = ''table'' /'], NO_SET, [character(len=L) :: &
            P//'table_none.nml: &supports: top_table = '''': a file is needed'])
        call expect_error('mpp_release', [character(len=L) :: '&model kind = ''mpp'' /', &
            '&supports top_release_time = 0 /'], NO_SET, [character(len=L) :: &
            P//'mpp_release.nml: &supports: top_release_time = 0.0: the mpp model hangs'])
        call expect_error('folded_even', [character(len=L) :: '&model elements = 10 /', &
            '&initial shape = ''folded'' /'], NO_SET, [character(len=L) :: &
            P//'folded_even.nml: &initial: shape = "folded": needs an odd number of elements'])
        ! the other key of the check came from a --set: the error names that argument
        call expect_error('folded_set_n', [character(len=L) :: '&model elements = 11 /', &
            '&initial shape = ''folded'' /'], [character(len=L) :: 'model.elements=10'], &
            [character(len=L) :: '--set model.elements=10: &initial: shape = "folded": needs'])
        call expect_error('records_set_t_end', MODEL, [character(len=L) :: &
            'solver.t_end=1e6', 'solver.output_interval=0.001'], [character(len=L) :: &
            '--set solver.output_interval=0.001: &solver: output_interval = 0.001: with t_end'])
        call expect_error('records_file_t_end', [character(len=L) :: MODEL, &
            '&solver output_interval = 0.001 /'], [character(len=L) :: 'solver.t_end=1e6'], &
            [character(len=L) :: '--set solver.t_end=1e6: &solver: output_interval = 0.001: '])
        call expect_error('mpp_velocity', [character(len=L) :: '&model kind = ''mpp'' /', &
            '&initial velocity = 1, 0 /'], NO_SET, [character(len=L) :: &
            P//'mpp_velocity.nml: &initial: velocity = 1.0, 0.0: the mpp model starts at rest'])
        call expect_error('drag_zero', [character(len=L) :: MODEL, '&effects drag = T /', &
            '&fluid density = 0 /'], NO_SET, [character(len=L) :: &
            P//'drag_zero.nml: &effects: drag = .true.: every drag coefficient of &fluid is zero'])
        call expect_error('fluid_density', [character(len=L) :: MODEL, &
            '&fluid density = -1 /'], NO_SET, [character(len=L) :: &
            P//'fluid_density.nml: &fluid: density = -1.0: must be >= 0'])
        call expect_error('ground_normal', [character(len=L) :: MODEL, &
            '&ground normal = 0, 0 /'], NO_SET, [character(len=L) :: &
            P//'ground_normal.nml: &ground: normal = 0.0, 0.0: must be a finite, non-zero vector'])
        call expect_error('ground_stiffness', [character(len=L) :: MODEL, &
            '&ground stiffness = 0 /'], NO_SET, [character(len=L) :: &
            P//'ground_stiffness.nml: &ground: stiffness = 0.0: must be > 0'])
        call expect_error('mass_position', [character(len=L) :: MODEL, &
            '&attachments mass_positions = 1.5, masses = 0.1 /'], NO_SET, [character(len=L) :: &
            P//'mass_position.nml: &attachments: mass_positions(1) = 1.5: must be in 0 .. 1'])
        call expect_error('mass_value', [character(len=L) :: MODEL, &
            '&attachments mass_positions = 0.5, 0.7, masses = 0.1 /'], NO_SET, &
            [character(len=L) :: P//'mass_value.nml: &attachments: masses(2) = 0.0: must be > 0'])
        ! no masses at all: the position names the error, and where it came from
        call expect_error('mass_missing', [character(len=L) :: MODEL, &
            '&attachments mass_positions = 0.5 /'], NO_SET, [character(len=L) :: &
            P//'mass_missing.nml: &attachments: mass_positions(1) = 0.5: a point mass', &
            'mass_positions(1) = 0.5: a point mass there needs masses(1) > 0 (kg), not given'])
        call expect_error('set_mass_missing', MODEL, [character(len=L) :: &
            'attachments.mass_positions=0.5'], [character(len=L) :: &
            '--set attachments.mass_positions=0.5: &attachments: mass_positions(1) = 0.5: a', &
            'mass_positions(1) = 0.5: a point mass there needs masses(1) > 0 (kg), not given'])
        call expect_error('set_mass_unused', MODEL, [character(len=L) :: &
            'attachments.masses(2)=0.5'], [character(len=L) :: &
            '--set attachments.masses(2)=0.5: &attachments: masses(2) = 0.5: no '// &
            'mass_positions(2) given'])
        call expect_error('load_frequency', [character(len=L) :: MODEL, &
            '&attachments load_positions = 0.5, load_frequency = -1 /'], NO_SET, &
            [character(len=L) :: P//'load_frequency.nml: &attachments: load_frequency(1) = '// &
            '-1.0: must be >= 0'])
        call expect_error('too_many_masses', [character(len=L) :: MODEL, &
            '&attachments masses = 1, 2, 3, 4, 5, 6, 7, 8, 9 /'], NO_SET, [character(len=L) :: &
            P//'too_many_masses.nml: &attachments: cannot read masses', &
            'expected up to 8 real numbers'])
    end subroutine test_effect_keys
end program test_scene
