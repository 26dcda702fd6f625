!> Scene files: the namelist input of ropedyn (rope, model, supports, initial state, effects,
!! solver and output), read with defaults, `--set group.key=value` overrides and a check of
!! every key.
!!
!! Reading follows the Quantum ESPRESSO pattern: defaults -> for each group, look for its
!! header in the file and, if present, read it from the file's lines in memory -> apply the
!! overrides of that group by an internal namelist read -> resolve derived defaults -> check
!! every key. Every error is one message of class `ERR_INPUT` naming the file (or the
!! `--set` argument), the group, the key and the value. The reference is docs/input.md.
module ropedyn_scene
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite, ieee_is_nan
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t, make_error, ERR_INPUT
    use ropedyn_text, only: int_text, real_text, pair_text, logical_text, quoted, lower, &
                            line_quote
    use ropedyn_os, only: absolute_path
    use ropedyn_methods, only: METHODS, method_index
    use ropedyn_rope_spec, only: rope_spec_t, rope_params_t, model_params_t, &
        supports_params_t, initial_params_t, effects_params_t, fluid_params_t, &
        ground_params_t, attachments_params_t, bottom_anchor_given, NOT_SET, NAME_LEN, &
        PATH_LEN, N_ATTACH
    use ropedyn_motion_table, only: read_motion_table
    implicit none
    private
    public :: solver_params_t, output_params_t, scene_t
    public :: read_scene, scene_namelist_text

    !> `&solver`: time integration.
    type :: solver_params_t
        character(len=NAME_LEN) :: method = 'cvode'  !< 'cvode' | 'mebdf'
        real(wp) :: rtol = 1.0e-6_wp          !< relative tolerance [-]
        real(wp) :: atol = 1.0e-8_wp          !< absolute tolerance [state units]
        !> highest order of accuracy; 0 in the file: the method's default (resolved by
        !! `read_scene`: 5 for cvode, 4 for mebdf)
        integer :: max_order = 0
        integer :: max_steps = 1000000        !< step budget for the whole run [-]
        real(wp) :: t_end = 30.0_wp           !< end time [s]
        real(wp) :: output_interval = 0.01_wp !< time between output records [s]
        !> CVODE only: BDF stability-limit detection (lowers the order near the stability
        !! boundary of lightly damped oscillatory modes)
        logical :: stability_limit_detection = .false.
        !> Newton systems on the first-order matrix of all unknowns instead of the reduced
        !! second-order one (half the size; the default for the rope models)
        logical :: first_order_newton = .false.
        !> time the parts of the integration (right-hand side, Jacobian, factorizations,
        !! solves): printed and written to /solver (costs a few % on small ropes)
        logical :: profile = .false.
        !> testing aid: the right-hand side returns NaN for t > this time [s]; < 0: off
        real(wp) :: fault_nan_after = -1.0_wp
    end type solver_params_t

    !> `&output`: where results go.
    type :: output_params_t
        !> HDF5 file; resolved by `read_scene` ('' in the file: out/<scene name>.h5)
        character(len=PATH_LEN) :: file = ''
        logical :: progress = .false.         !< print progress while integrating
    end type output_params_t

    !> A complete scene: the rope models' parameters (the parent `rope_spec_t`, whose
    !! `path` is the file the scene was read from), the solver and the output.
    type, extends(rope_spec_t) :: scene_t
        type(solver_params_t) :: solver
        type(output_params_t) :: output
    end type scene_t

    ! Groups, in the order they are read, checked and written.
    integer, parameter :: G_ROPE = 1, G_MODEL = 2, G_SUPPORTS = 3, G_INITIAL = 4, &
        G_EFFECTS = 5, G_SOLVER = 6, G_OUTPUT = 7, G_FLUID = 8, G_GROUND = 9, &
        G_ATTACHMENTS = 10, N_GROUPS = 10
    character(len=*), parameter :: GROUP_NAMES(N_GROUPS) = [character(len=11) :: &
        'rope', 'model', 'supports', 'initial', 'effects', 'solver', 'output', 'fluid', &
        'ground', 'attachments']

    ! Key types.
    integer, parameter :: T_REAL = 1, T_INT = 2, T_LOGICAL = 3, T_STRING = 4, T_REAL2 = 5
    integer, parameter :: T_REALN = 6  !< an array of N_ATTACH reals

    type :: key_info_t
        integer :: group
        character(len=32) :: name
        integer :: type
    end type key_info_t

    type(key_info_t), parameter :: KEYS(*) = [ &
        key_info_t(G_ROPE, 'length', T_REAL), &
        key_info_t(G_ROPE, 'density', T_REAL), &
        key_info_t(G_ROPE, 'diameter', T_REAL), &
        key_info_t(G_ROPE, 'young_modulus', T_REAL), &
        key_info_t(G_ROPE, 'shear_modulus', T_REAL), &
        key_info_t(G_ROPE, 'normal_damping', T_REAL), &
        key_info_t(G_ROPE, 'tangential_damping', T_REAL), &
        key_info_t(G_ROPE, 'shape_factor', T_REAL), &
        key_info_t(G_ROPE, 'gravity', T_REAL), &
        key_info_t(G_MODEL, 'kind', T_STRING), &
        key_info_t(G_MODEL, 'elements', T_INT), &
        key_info_t(G_MODEL, 'mpp_axial_damping_factor', T_REAL), &
        key_info_t(G_MODEL, 'mpp_bending_damping_factor', T_REAL), &
        key_info_t(G_SUPPORTS, 'top', T_STRING), &
        key_info_t(G_SUPPORTS, 'bottom', T_STRING), &
        key_info_t(G_SUPPORTS, 'top_anchor', T_REAL2), &
        key_info_t(G_SUPPORTS, 'bottom_anchor', T_REAL2), &
        key_info_t(G_SUPPORTS, 'top_angle_deg', T_REAL), &
        key_info_t(G_SUPPORTS, 'bottom_angle_deg', T_REAL), &
        key_info_t(G_SUPPORTS, 'support_stiffness_factor', T_REAL), &
        key_info_t(G_SUPPORTS, 'top_motion', T_STRING), &
        key_info_t(G_SUPPORTS, 'bottom_motion', T_STRING), &
        key_info_t(G_SUPPORTS, 'top_amplitude', T_REAL2), &
        key_info_t(G_SUPPORTS, 'bottom_amplitude', T_REAL2), &
        key_info_t(G_SUPPORTS, 'top_frequency', T_REAL), &
        key_info_t(G_SUPPORTS, 'bottom_frequency', T_REAL), &
        key_info_t(G_SUPPORTS, 'top_phase_deg', T_REAL2), &
        key_info_t(G_SUPPORTS, 'bottom_phase_deg', T_REAL2), &
        key_info_t(G_SUPPORTS, 'top_angle_amplitude_deg', T_REAL), &
        key_info_t(G_SUPPORTS, 'bottom_angle_amplitude_deg', T_REAL), &
        key_info_t(G_SUPPORTS, 'top_angle_phase_deg', T_REAL), &
        key_info_t(G_SUPPORTS, 'bottom_angle_phase_deg', T_REAL), &
        key_info_t(G_SUPPORTS, 'top_table', T_STRING), &
        key_info_t(G_SUPPORTS, 'bottom_table', T_STRING), &
        key_info_t(G_SUPPORTS, 'top_release_time', T_REAL), &
        key_info_t(G_SUPPORTS, 'bottom_release_time', T_REAL), &
        key_info_t(G_INITIAL, 'shape', T_STRING), &
        key_info_t(G_INITIAL, 'angle_deg', T_REAL), &
        key_info_t(G_INITIAL, 'mode', T_INT), &
        key_info_t(G_INITIAL, 'mode_amplitude', T_REAL), &
        key_info_t(G_INITIAL, 'velocity', T_REAL2), &
        key_info_t(G_EFFECTS, 'gravity', T_LOGICAL), &
        key_info_t(G_EFFECTS, 'tension', T_LOGICAL), &
        key_info_t(G_EFFECTS, 'shear', T_LOGICAL), &
        key_info_t(G_EFFECTS, 'bending', T_LOGICAL), &
        key_info_t(G_EFFECTS, 'damping', T_LOGICAL), &
        key_info_t(G_EFFECTS, 'drag', T_LOGICAL), &
        key_info_t(G_EFFECTS, 'ground', T_LOGICAL), &
        key_info_t(G_EFFECTS, 'support_motion', T_LOGICAL), &
        key_info_t(G_EFFECTS, 'point_masses', T_LOGICAL), &
        key_info_t(G_EFFECTS, 'point_loads', T_LOGICAL), &
        key_info_t(G_SOLVER, 'method', T_STRING), &
        key_info_t(G_SOLVER, 'rtol', T_REAL), &
        key_info_t(G_SOLVER, 'atol', T_REAL), &
        key_info_t(G_SOLVER, 'max_order', T_INT), &
        key_info_t(G_SOLVER, 'max_steps', T_INT), &
        key_info_t(G_SOLVER, 't_end', T_REAL), &
        key_info_t(G_SOLVER, 'output_interval', T_REAL), &
        key_info_t(G_SOLVER, 'stability_limit_detection', T_LOGICAL), &
        key_info_t(G_SOLVER, 'first_order_newton', T_LOGICAL), &
        key_info_t(G_SOLVER, 'profile', T_LOGICAL), &
        key_info_t(G_SOLVER, 'fault_nan_after', T_REAL), &
        key_info_t(G_OUTPUT, 'file', T_STRING), &
        key_info_t(G_OUTPUT, 'progress', T_LOGICAL), &
        key_info_t(G_FLUID, 'density', T_REAL), &
        key_info_t(G_FLUID, 'normal_drag_coefficient', T_REAL), &
        key_info_t(G_FLUID, 'tangential_drag_coefficient', T_REAL), &
        key_info_t(G_FLUID, 'linear_normal_drag', T_REAL), &
        key_info_t(G_FLUID, 'linear_tangential_drag', T_REAL), &
        key_info_t(G_FLUID, 'current', T_REAL2), &
        key_info_t(G_GROUND, 'point', T_REAL2), &
        key_info_t(G_GROUND, 'normal', T_REAL2), &
        key_info_t(G_GROUND, 'stiffness', T_REAL), &
        key_info_t(G_GROUND, 'damping', T_REAL), &
        key_info_t(G_GROUND, 'friction_coefficient', T_REAL), &
        key_info_t(G_GROUND, 'friction_regularization_speed', T_REAL), &
        key_info_t(G_ATTACHMENTS, 'mass_positions', T_REALN), &
        key_info_t(G_ATTACHMENTS, 'masses', T_REALN), &
        key_info_t(G_ATTACHMENTS, 'load_positions', T_REALN), &
        key_info_t(G_ATTACHMENTS, 'load_force_x', T_REALN), &
        key_info_t(G_ATTACHMENTS, 'load_force_y', T_REALN), &
        key_info_t(G_ATTACHMENTS, 'load_amplitude_x', T_REALN), &
        key_info_t(G_ATTACHMENTS, 'load_amplitude_y', T_REALN), &
        key_info_t(G_ATTACHMENTS, 'load_frequency', T_REALN), &
        key_info_t(G_ATTACHMENTS, 'load_phase_deg', T_REALN)]

    ! Allowed values of the name keys; "known" values are recognised but not available yet.
    character(len=*), parameter :: KINDS_ALLOWED(2) = [character(len=8) :: 'rfem', 'mpp']
    character(len=*), parameter :: SUPPORTS_ALLOWED(3) = [character(len=8) :: &
        'pinned', 'clamped', 'free']
    character(len=*), parameter :: SHAPES_ALLOWED(5) = [character(len=11) :: &
        'straight', 'hanging', 'equilibrium', 'mode', 'folded']
    character(len=*), parameter :: MOTIONS_ALLOWED(3) = [character(len=8) :: &
        'fixed', 'harmonic', 'table']
    character(len=*), parameter :: NONE_KNOWN(0) = [character(len=8) ::]

    ! Pseudo iostat of a string value longer than its component (message in iomsg).
    integer, parameter :: IOS_TOO_LONG = -12345
    ! Length of the namelist buffers of string keys and of iomsg buffers.
    integer, parameter :: BUF_LEN = 2048
    character(len=*), parameter :: TAB = achar(9)

    type :: line_t
        character(len=:), allocatable :: s
    end type line_t

    !> One `--set group.key=value` argument.
    type :: override_t
        character(len=:), allocatable :: text   !< as given (trimmed)
        integer :: group = 0
        character(len=:), allocatable :: key    !< key as given (may carry an index)
        character(len=:), allocatable :: base   !< key without index, lower case
        character(len=:), allocatable :: value  !< value as given
        character(len=:), allocatable :: nml    !< '&group key = value /'
    end type override_t

    !> Where values came from, for messages.
    type :: context_t
        character(len=:), allocatable :: path
        type(override_t), allocatable :: overrides(:)
    end type context_t

contains

    !> Read a scene file, apply overrides, resolve derived defaults and check every key.
    !!
    !! `overrides` holds `group.key=value` strings (the `--set` arguments), applied after the
    !! file in the order given. On error `err` is allocated with class ERR_INPUT and a message
    !! naming the file (or the `--set` argument), group, key and value; `scene` is then not
    !! a valid scene.
    subroutine read_scene(path, overrides, scene, err)
        character(len=*), intent(in) :: path          !< scene file
        character(len=*), intent(in) :: overrides(:)  !< 'group.key=value', may be empty
        type(scene_t), intent(out) :: scene
        type(error_t), allocatable, intent(out) :: err
        type(context_t) :: ctx
        type(line_t), allocatable :: lines(:)
        integer :: first(N_GROUPS), last(N_GROUPS)
        integer :: unit, ios, i, g
        character(len=BUF_LEN) :: msg
        character(len=:), allocatable :: recs(:)

        scene%path = trim(path)
        ctx%path = trim(path)
        allocate (ctx%overrides(size(overrides)))
        do i = 1, size(overrides)
            call parse_override(overrides(i), ctx%overrides(i), err)
            if (allocated(err)) return
        end do

        msg = ''
        open (newunit=unit, file=ctx%path, status='old', action='read', form='formatted', &
            access='sequential', iostat=ios, iomsg=msg)
        if (ios /= 0) then
            call make_error(err, ERR_INPUT, ctx%path//': cannot open: '//trim(msg))
            return
        end if
        call read_lines(unit, lines, ios, msg)
        if (ios /= 0) then
            call make_error(err, ERR_INPUT, ctx%path//': cannot read: '//trim(msg))
            close (unit)
            return
        end if
        close (unit)
        call locate_groups(ctx%path, lines, first, last, err)
        if (allocated(err)) return
        ! Groups are read from the lines in memory (an internal file), which also accepts
        ! a last line without a newline.
        allocate (character(len=max_len(lines)) :: recs(size(lines) + 1))
        call fill_records(lines, '', recs)

        ! Sentinels of the derived defaults.
        scene%rope%tangential_damping = NOT_SET
        scene%output%file = ''

        do g = 1, N_GROUPS
            if (first(g) > 0) then
                msg = ''
                call read_group(g, scene, ios, msg, recs=recs)
                if (ios /= 0) then
                    call file_read_error(ctx%path, g, lines, first(g), last(g), ios, msg, err)
                    return
                end if
            end if
            do i = 1, size(ctx%overrides)
                if (ctx%overrides(i)%group /= g) cycle
                call apply_override(ctx%overrides(i), scene, err)
                if (allocated(err)) return
            end do
        end do

        call check_scene(ctx, scene, err)
        if (allocated(err)) return
        call resolve_defaults(scene)
    end subroutine read_scene

    !> The effective scene as namelist text: all groups and keys, one per line,
    !! re-readable by `read_scene`.
    function scene_namelist_text(scene) result(text)
        type(scene_t), intent(in) :: scene
        character(len=:), allocatable :: text
        character(len=*), parameter :: I4 = '    '
        character(len=1), parameter :: NL = new_line('a')

        associate (r => scene%rope, m => scene%model, s => scene%supports, &
                i => scene%initial, e => scene%effects, v => scene%solver, o => scene%output)
            text = '&rope'//NL &
                //I4//'length = '//real_text(r%length)//NL &
                //I4//'density = '//real_text(r%density)//NL &
                //I4//'diameter = '//real_text(r%diameter)//NL &
                //I4//'young_modulus = '//real_text(r%young_modulus)//NL &
                //I4//'shear_modulus = '//real_text(r%shear_modulus)//NL &
                //I4//'normal_damping = '//real_text(r%normal_damping)//NL &
                //I4//'tangential_damping = '//real_text(r%tangential_damping)//NL &
                //I4//'shape_factor = '//real_text(r%shape_factor)//NL &
                //I4//'gravity = '//real_text(r%gravity)//NL//'/'//NL
            text = text//'&model'//NL &
                //I4//'kind = '//quoted(trim(m%kind))//NL &
                //I4//'elements = '//int_text(m%elements)//NL &
                //I4//'mpp_axial_damping_factor = '//real_text(m%mpp_axial_damping_factor)//NL &
                //I4//'mpp_bending_damping_factor = '// &
                real_text(m%mpp_bending_damping_factor)//NL//'/'//NL
            text = text//'&supports'//NL &
                //I4//'top = '//quoted(trim(s%top))//NL &
                //I4//'bottom = '//quoted(trim(s%bottom))//NL &
                //I4//'top_anchor = '//pair_text(s%top_anchor)//NL &
                //I4//'bottom_anchor = '//pair_text(s%bottom_anchor)
            if (.not. bottom_anchor_given(scene)) then
                text = text//"  ! not set: the rope's lower end in its initial state"
            end if
            text = text//NL &
                //I4//'top_angle_deg = '//real_text(s%top_angle_deg)//NL &
                //I4//'bottom_angle_deg = '//real_text(s%bottom_angle_deg)//NL &
                //I4//'support_stiffness_factor = '//real_text(s%support_stiffness_factor) &
                //NL//motion_text('top', s%top_motion, s%top_amplitude, s%top_frequency, &
                s%top_phase_deg, s%top_angle_amplitude_deg, s%top_angle_phase_deg, &
                s%top_table, s%top_release_time) &
                //motion_text('bottom', s%bottom_motion, s%bottom_amplitude, &
                s%bottom_frequency, s%bottom_phase_deg, s%bottom_angle_amplitude_deg, &
                s%bottom_angle_phase_deg, s%bottom_table, s%bottom_release_time)//'/'//NL
            text = text//'&initial'//NL &
                //I4//'shape = '//quoted(trim(i%shape))//NL &
                //I4//'angle_deg = '//real_text(i%angle_deg)//NL &
                //I4//'mode = '//int_text(i%mode)//NL &
                //I4//'mode_amplitude = '//real_text(i%mode_amplitude)//NL &
                //I4//'velocity = '//pair_text(i%velocity)//NL//'/'//NL
            text = text//'&effects'//NL &
                //I4//'gravity = '//logical_text(e%gravity)//NL &
                //I4//'tension = '//logical_text(e%tension)//NL &
                //I4//'shear = '//logical_text(e%shear)//NL &
                //I4//'bending = '//logical_text(e%bending)//NL &
                //I4//'damping = '//logical_text(e%damping)//NL &
                //I4//'drag = '//logical_text(e%drag)//NL &
                //I4//'ground = '//logical_text(e%ground)//NL &
                //I4//'support_motion = '//logical_text(e%support_motion)//NL &
                //I4//'point_masses = '//logical_text(e%point_masses)//NL &
                //I4//'point_loads = '//logical_text(e%point_loads)//NL//'/'//NL
            text = text//'&solver'//NL &
                //I4//'method = '//quoted(trim(v%method))//NL &
                //I4//'rtol = '//real_text(v%rtol)//NL &
                //I4//'atol = '//real_text(v%atol)//NL &
                //I4//'max_order = '//int_text(v%max_order)//NL &
                //I4//'max_steps = '//int_text(v%max_steps)//NL &
                //I4//'t_end = '//real_text(v%t_end)//NL &
                //I4//'output_interval = '//real_text(v%output_interval)//NL &
                //I4//'stability_limit_detection = '// &
                logical_text(v%stability_limit_detection)//NL &
                //I4//'first_order_newton = '//logical_text(v%first_order_newton)//NL &
                //I4//'profile = '//logical_text(v%profile)//NL &
                //I4//'fault_nan_after = '//real_text(v%fault_nan_after)//NL//'/'//NL
            text = text//'&output'//NL &
                //I4//'file = '//quoted(trim(o%file))//NL &
                //I4//'progress = '//logical_text(o%progress)//NL//'/'
        end associate
        associate (f => scene%fluid, g => scene%ground, a => scene%attachments)
            text = text//NL//'&fluid'//NL &
                //I4//'density = '//real_text(f%density)//NL &
                //I4//'normal_drag_coefficient = '//real_text(f%normal_drag_coefficient)//NL &
                //I4//'tangential_drag_coefficient = '// &
                real_text(f%tangential_drag_coefficient)//NL &
                //I4//'linear_normal_drag = '//real_text(f%linear_normal_drag)//NL &
                //I4//'linear_tangential_drag = '//real_text(f%linear_tangential_drag)//NL &
                //I4//'current = '//pair_text(f%current)//NL//'/'//NL
            text = text//'&ground'//NL &
                //I4//'point = '//pair_text(g%point)//NL &
                //I4//'normal = '//pair_text(g%normal)//NL &
                //I4//'stiffness = '//real_text(g%stiffness)//NL &
                //I4//'damping = '//real_text(g%damping)//NL &
                //I4//'friction_coefficient = '//real_text(g%friction_coefficient)//NL &
                //I4//'friction_regularization_speed = '// &
                real_text(g%friction_regularization_speed)//NL//'/'//NL
            text = text//'&attachments'//NL &
                //list_text('mass_positions', a%mass_positions, a%mass_positions) &
                //list_text('masses', a%masses, a%mass_positions) &
                //list_text('load_positions', a%load_positions, a%load_positions) &
                //list_text('load_force_x', a%load_force_x, a%load_positions) &
                //list_text('load_force_y', a%load_force_y, a%load_positions) &
                //list_text('load_amplitude_x', a%load_amplitude_x, a%load_positions) &
                //list_text('load_amplitude_y', a%load_amplitude_y, a%load_positions) &
                //list_text('load_frequency', a%load_frequency, a%load_positions) &
                //list_text('load_phase_deg', a%load_phase_deg, a%load_positions)//'/'
        end associate
    end function scene_namelist_text

    !> The motion keys of one support ('top' or 'bottom') for the echo, one a line.
    function motion_text(end, motion, amplitude, frequency, phase_deg, angle_amplitude_deg, &
            angle_phase_deg, table, release_time) result(text)
        character(len=*), intent(in) :: end, motion, table
        real(wp), intent(in) :: amplitude(2), frequency, phase_deg(2), angle_amplitude_deg, &
            angle_phase_deg, release_time
        character(len=:), allocatable :: text
        character(len=*), parameter :: I4 = '    '
        character(len=1), parameter :: NL = new_line('a')
        text = I4//end//'_motion = '//quoted(trim(motion))//NL &
            //I4//end//'_amplitude = '//pair_text(amplitude)//NL &
            //I4//end//'_frequency = '//real_text(frequency)//NL &
            //I4//end//'_phase_deg = '//pair_text(phase_deg)//NL &
            //I4//end//'_angle_amplitude_deg = '//real_text(angle_amplitude_deg)//NL &
            //I4//end//'_angle_phase_deg = '//real_text(angle_phase_deg)//NL &
            //I4//end//'_table = '//quoted(trim(table))//NL &
            //I4//end//'_release_time = '//real_text(release_time)//NL
    end function motion_text

    !> `key = v(1), ..., v(k)` with k the last entry whose position `used` is given; ''
    !! when none is (the key keeps its default).
    function list_text(key, v, used) result(text)
        character(len=*), intent(in) :: key
        real(wp), intent(in) :: v(:), used(:)
        character(len=:), allocatable :: text
        integer :: i, last
        text = ''
        last = 0
        do i = 1, size(used)
            if (.not. ieee_is_nan(used(i))) last = i
        end do
        if (last == 0) return
        text = '    '//key//' = '//real_text(v(1))
        do i = 2, last
            text = text//', '//real_text(v(i))
        end do
        text = text//new_line('a')
    end function list_text

    ! ------------------------------------------------------------------------------------
    ! Namelist reads, one procedure per group (the keys of two groups share names).
    ! Every group is read from an internal file (`recs`): the scene's lines or an override.
    ! ------------------------------------------------------------------------------------

    subroutine read_group(g, scene, ios, msg, recs)
        integer, intent(in) :: g
        type(scene_t), intent(inout) :: scene
        integer, intent(out) :: ios
        character(len=*), intent(inout) :: msg
        character(len=*), intent(in) :: recs(:)
        select case (g)
        case (G_ROPE)
            call nml_rope(scene%rope, ios, msg, recs)
        case (G_MODEL)
            call nml_model(scene%model, ios, msg, recs)
        case (G_SUPPORTS)
            call nml_supports(scene%supports, ios, msg, recs)
        case (G_INITIAL)
            call nml_initial(scene%initial, ios, msg, recs)
        case (G_EFFECTS)
            call nml_effects(scene%effects, ios, msg, recs)
        case (G_SOLVER)
            call nml_solver(scene%solver, ios, msg, recs)
        case (G_OUTPUT)
            call nml_output(scene%output, ios, msg, recs)
        case (G_FLUID)
            call nml_fluid(scene%fluid, ios, msg, recs)
        case (G_GROUND)
            call nml_ground(scene%ground, ios, msg, recs)
        case (G_ATTACHMENTS)
            call nml_attachments(scene%attachments, ios, msg, recs)
        case default
            ios = -1
            msg = 'internal error: no such group'
        end select
    end subroutine read_group

    subroutine nml_rope(p, ios, msg, recs)
        type(rope_params_t), intent(inout) :: p
        integer, intent(out) :: ios
        character(len=*), intent(inout) :: msg
        character(len=*), intent(in) :: recs(:)
        real(wp) :: length, density, diameter, young_modulus, shear_modulus, normal_damping, &
            tangential_damping, shape_factor, gravity
        namelist /rope/ length, density, diameter, young_modulus, shear_modulus, &
            normal_damping, tangential_damping, shape_factor, gravity
        length = p%length
        density = p%density
        diameter = p%diameter
        young_modulus = p%young_modulus
        shear_modulus = p%shear_modulus
        normal_damping = p%normal_damping
        tangential_damping = p%tangential_damping
        shape_factor = p%shape_factor
        gravity = p%gravity
        read (recs, nml=rope, iostat=ios, iomsg=msg)
        if (ios /= 0) return
        p%length = length
        p%density = density
        p%diameter = diameter
        p%young_modulus = young_modulus
        p%shear_modulus = shear_modulus
        p%normal_damping = normal_damping
        p%tangential_damping = tangential_damping
        p%shape_factor = shape_factor
        p%gravity = gravity
    end subroutine nml_rope

    subroutine nml_model(p, ios, msg, recs)
        type(model_params_t), intent(inout) :: p
        integer, intent(out) :: ios
        character(len=*), intent(inout) :: msg
        character(len=*), intent(in) :: recs(:)
        character(len=BUF_LEN) :: kind
        integer :: elements
        real(wp) :: mpp_axial_damping_factor, mpp_bending_damping_factor
        namelist /model/ kind, elements, mpp_axial_damping_factor, mpp_bending_damping_factor
        kind = p%kind
        elements = p%elements
        mpp_axial_damping_factor = p%mpp_axial_damping_factor
        mpp_bending_damping_factor = p%mpp_bending_damping_factor
        read (recs, nml=model, iostat=ios, iomsg=msg)
        if (ios /= 0) return
        call store_string(kind, 'kind', p%kind, ios, msg)
        p%elements = elements
        p%mpp_axial_damping_factor = mpp_axial_damping_factor
        p%mpp_bending_damping_factor = mpp_bending_damping_factor
    end subroutine nml_model

    subroutine nml_supports(p, ios, msg, recs)
        type(supports_params_t), intent(inout) :: p
        integer, intent(out) :: ios
        character(len=*), intent(inout) :: msg
        character(len=*), intent(in) :: recs(:)
        character(len=BUF_LEN) :: top, bottom, top_motion, bottom_motion, top_table, bottom_table
        real(wp) :: top_anchor(2), bottom_anchor(2), top_angle_deg, bottom_angle_deg, &
            support_stiffness_factor
        real(wp) :: top_amplitude(2), bottom_amplitude(2), top_frequency, bottom_frequency, &
            top_phase_deg(2), bottom_phase_deg(2), top_angle_amplitude_deg, &
            bottom_angle_amplitude_deg, top_angle_phase_deg, bottom_angle_phase_deg, &
            top_release_time, bottom_release_time
        namelist /supports/ top, bottom, top_anchor, bottom_anchor, top_angle_deg, &
            bottom_angle_deg, support_stiffness_factor, top_motion, bottom_motion, &
            top_amplitude, bottom_amplitude, top_frequency, bottom_frequency, top_phase_deg, &
            bottom_phase_deg, top_angle_amplitude_deg, bottom_angle_amplitude_deg, &
            top_angle_phase_deg, bottom_angle_phase_deg, top_table, bottom_table, &
            top_release_time, bottom_release_time
        top_motion = p%top_motion
        bottom_motion = p%bottom_motion
        top_amplitude = p%top_amplitude
        bottom_amplitude = p%bottom_amplitude
        top_frequency = p%top_frequency
        bottom_frequency = p%bottom_frequency
        top_phase_deg = p%top_phase_deg
        bottom_phase_deg = p%bottom_phase_deg
        top_angle_amplitude_deg = p%top_angle_amplitude_deg
        bottom_angle_amplitude_deg = p%bottom_angle_amplitude_deg
        top_angle_phase_deg = p%top_angle_phase_deg
        bottom_angle_phase_deg = p%bottom_angle_phase_deg
        top_table = p%top_table
        bottom_table = p%bottom_table
        top_release_time = p%top_release_time
        bottom_release_time = p%bottom_release_time
        top = p%top
        bottom = p%bottom
        top_anchor = p%top_anchor
        bottom_anchor = p%bottom_anchor
        top_angle_deg = p%top_angle_deg
        bottom_angle_deg = p%bottom_angle_deg
        support_stiffness_factor = p%support_stiffness_factor
        read (recs, nml=supports, iostat=ios, iomsg=msg)
        if (ios /= 0) return
        call store_string(top, 'top', p%top, ios, msg)
        call store_string(bottom, 'bottom', p%bottom, ios, msg)
        p%top_anchor = top_anchor
        p%bottom_anchor = bottom_anchor
        p%top_angle_deg = top_angle_deg
        p%bottom_angle_deg = bottom_angle_deg
        p%support_stiffness_factor = support_stiffness_factor
        call store_string(top_motion, 'top_motion', p%top_motion, ios, msg)
        call store_string(bottom_motion, 'bottom_motion', p%bottom_motion, ios, msg)
        call store_string(top_table, 'top_table', p%top_table, ios, msg)
        call store_string(bottom_table, 'bottom_table', p%bottom_table, ios, msg)
        p%top_amplitude = top_amplitude
        p%bottom_amplitude = bottom_amplitude
        p%top_frequency = top_frequency
        p%bottom_frequency = bottom_frequency
        p%top_phase_deg = top_phase_deg
        p%bottom_phase_deg = bottom_phase_deg
        p%top_angle_amplitude_deg = top_angle_amplitude_deg
        p%bottom_angle_amplitude_deg = bottom_angle_amplitude_deg
        p%top_angle_phase_deg = top_angle_phase_deg
        p%bottom_angle_phase_deg = bottom_angle_phase_deg
        p%top_release_time = top_release_time
        p%bottom_release_time = bottom_release_time
    end subroutine nml_supports

    subroutine nml_initial(p, ios, msg, recs)
        type(initial_params_t), intent(inout) :: p
        integer, intent(out) :: ios
        character(len=*), intent(inout) :: msg
        character(len=*), intent(in) :: recs(:)
        character(len=BUF_LEN) :: shape
        real(wp) :: angle_deg, mode_amplitude, velocity(2)
        integer :: mode
        namelist /initial/ shape, angle_deg, mode, mode_amplitude, velocity
        velocity = p%velocity
        shape = p%shape
        angle_deg = p%angle_deg
        mode = p%mode
        mode_amplitude = p%mode_amplitude
        read (recs, nml=initial, iostat=ios, iomsg=msg)
        if (ios /= 0) return
        call store_string(shape, 'shape', p%shape, ios, msg)
        p%angle_deg = angle_deg
        p%mode = mode
        p%mode_amplitude = mode_amplitude
        p%velocity = velocity
    end subroutine nml_initial

    subroutine nml_effects(p, ios, msg, recs)
        type(effects_params_t), intent(inout) :: p
        integer, intent(out) :: ios
        character(len=*), intent(inout) :: msg
        character(len=*), intent(in) :: recs(:)
        logical :: gravity, tension, shear, bending, damping, drag, ground, support_motion, &
            point_masses, point_loads
        namelist /effects/ gravity, tension, shear, bending, damping, drag, ground, &
            support_motion, point_masses, point_loads
        drag = p%drag
        ground = p%ground
        support_motion = p%support_motion
        point_masses = p%point_masses
        point_loads = p%point_loads
        gravity = p%gravity
        tension = p%tension
        shear = p%shear
        bending = p%bending
        damping = p%damping
        read (recs, nml=effects, iostat=ios, iomsg=msg)
        if (ios /= 0) return
        p%gravity = gravity
        p%tension = tension
        p%shear = shear
        p%bending = bending
        p%damping = damping
        p%drag = drag
        p%ground = ground
        p%support_motion = support_motion
        p%point_masses = point_masses
        p%point_loads = point_loads
    end subroutine nml_effects

    subroutine nml_fluid(p, ios, msg, recs)
        type(fluid_params_t), intent(inout) :: p
        integer, intent(out) :: ios
        character(len=*), intent(inout) :: msg
        character(len=*), intent(in) :: recs(:)
        real(wp) :: density, normal_drag_coefficient, tangential_drag_coefficient, &
            linear_normal_drag, linear_tangential_drag, current(2)
        namelist /fluid/ density, normal_drag_coefficient, tangential_drag_coefficient, &
            linear_normal_drag, linear_tangential_drag, current
        density = p%density
        normal_drag_coefficient = p%normal_drag_coefficient
        tangential_drag_coefficient = p%tangential_drag_coefficient
        linear_normal_drag = p%linear_normal_drag
        linear_tangential_drag = p%linear_tangential_drag
        current = p%current
        read (recs, nml=fluid, iostat=ios, iomsg=msg)
        if (ios /= 0) return
        p%density = density
        p%normal_drag_coefficient = normal_drag_coefficient
        p%tangential_drag_coefficient = tangential_drag_coefficient
        p%linear_normal_drag = linear_normal_drag
        p%linear_tangential_drag = linear_tangential_drag
        p%current = current
    end subroutine nml_fluid

    subroutine nml_ground(p, ios, msg, recs)
        type(ground_params_t), intent(inout) :: p
        integer, intent(out) :: ios
        character(len=*), intent(inout) :: msg
        character(len=*), intent(in) :: recs(:)
        real(wp) :: point(2), normal(2), stiffness, damping, friction_coefficient, &
            friction_regularization_speed
        namelist /ground/ point, normal, stiffness, damping, friction_coefficient, &
            friction_regularization_speed
        point = p%point
        normal = p%normal
        stiffness = p%stiffness
        damping = p%damping
        friction_coefficient = p%friction_coefficient
        friction_regularization_speed = p%friction_regularization_speed
        read (recs, nml=ground, iostat=ios, iomsg=msg)
        if (ios /= 0) return
        p%point = point
        p%normal = normal
        p%stiffness = stiffness
        p%damping = damping
        p%friction_coefficient = friction_coefficient
        p%friction_regularization_speed = friction_regularization_speed
    end subroutine nml_ground

    subroutine nml_attachments(p, ios, msg, recs)
        type(attachments_params_t), intent(inout) :: p
        integer, intent(out) :: ios
        character(len=*), intent(inout) :: msg
        character(len=*), intent(in) :: recs(:)
        real(wp), dimension(N_ATTACH) :: mass_positions, masses, load_positions, load_force_x, &
            load_force_y, load_amplitude_x, load_amplitude_y, load_frequency, load_phase_deg
        namelist /attachments/ mass_positions, masses, load_positions, load_force_x, &
            load_force_y, load_amplitude_x, load_amplitude_y, load_frequency, load_phase_deg
        mass_positions = p%mass_positions
        masses = p%masses
        load_positions = p%load_positions
        load_force_x = p%load_force_x
        load_force_y = p%load_force_y
        load_amplitude_x = p%load_amplitude_x
        load_amplitude_y = p%load_amplitude_y
        load_frequency = p%load_frequency
        load_phase_deg = p%load_phase_deg
        read (recs, nml=attachments, iostat=ios, iomsg=msg)
        if (ios /= 0) return
        p%mass_positions = mass_positions
        p%masses = masses
        p%load_positions = load_positions
        p%load_force_x = load_force_x
        p%load_force_y = load_force_y
        p%load_amplitude_x = load_amplitude_x
        p%load_amplitude_y = load_amplitude_y
        p%load_frequency = load_frequency
        p%load_phase_deg = load_phase_deg
    end subroutine nml_attachments

    subroutine nml_solver(p, ios, msg, recs)
        type(solver_params_t), intent(inout) :: p
        integer, intent(out) :: ios
        character(len=*), intent(inout) :: msg
        character(len=*), intent(in) :: recs(:)
        character(len=BUF_LEN) :: method
        real(wp) :: rtol, atol, t_end, output_interval, fault_nan_after
        integer :: max_order, max_steps
        logical :: stability_limit_detection, first_order_newton, profile
        namelist /solver/ method, rtol, atol, max_order, max_steps, t_end, output_interval, &
            stability_limit_detection, first_order_newton, profile, fault_nan_after
        method = p%method
        rtol = p%rtol
        atol = p%atol
        max_order = p%max_order
        max_steps = p%max_steps
        t_end = p%t_end
        output_interval = p%output_interval
        stability_limit_detection = p%stability_limit_detection
        first_order_newton = p%first_order_newton
        profile = p%profile
        fault_nan_after = p%fault_nan_after
        read (recs, nml=solver, iostat=ios, iomsg=msg)
        if (ios /= 0) return
        call store_string(method, 'method', p%method, ios, msg)
        p%rtol = rtol
        p%atol = atol
        p%max_order = max_order
        p%max_steps = max_steps
        p%t_end = t_end
        p%output_interval = output_interval
        p%stability_limit_detection = stability_limit_detection
        p%first_order_newton = first_order_newton
        p%profile = profile
        p%fault_nan_after = fault_nan_after
    end subroutine nml_solver

    subroutine nml_output(p, ios, msg, recs)
        type(output_params_t), intent(inout) :: p
        integer, intent(out) :: ios
        character(len=*), intent(inout) :: msg
        character(len=*), intent(in) :: recs(:)
        character(len=BUF_LEN) :: file
        logical :: progress
        namelist /output/ file, progress
        file = p%file
        progress = p%progress
        read (recs, nml=output, iostat=ios, iomsg=msg)
        if (ios /= 0) return
        call store_string(file, 'file', p%file, ios, msg)
        p%progress = progress
    end subroutine nml_output

    !> Store a string value read into a long buffer, or report that it does not fit.
    subroutine store_string(value, key, dest, ios, msg)
        character(len=*), intent(in) :: value, key
        character(len=*), intent(inout) :: dest
        integer, intent(inout) :: ios
        character(len=*), intent(inout) :: msg
        character(len=:), allocatable :: v
        if (ios /= 0) return
        v = trim(adjustl(value))
        if (len(v) > len(dest)) then
            ios = IOS_TOO_LONG
            msg = key//' = "'//v(:min(len(v), 40))//'...": too long (at most ' &
                //int_text(len(dest))//' characters)'
            return
        end if
        dest = v
    end subroutine store_string

    ! ------------------------------------------------------------------------------------
    ! The file: lines, group headers, errors of a group read.
    ! ------------------------------------------------------------------------------------

    !> Read all lines of an open file (any length).
    subroutine read_lines(unit, lines, ios, msg)
        integer, intent(in) :: unit
        type(line_t), allocatable, intent(out) :: lines(:)
        integer, intent(out) :: ios
        character(len=*), intent(inout) :: msg
        type(line_t), allocatable :: grown(:)
        character(len=256) :: chunk
        character(len=:), allocatable :: line
        integer :: n, sz
        logical :: last

        allocate (lines(64))
        n = 0
        last = .false.
        do while (.not. last)
            line = ''
            do
                read (unit, '(a)', advance='no', size=sz, iostat=ios, iomsg=msg) chunk
                line = line//chunk(:sz)
                if (ios /= 0) exit
            end do
            if (is_iostat_eor(ios)) then
                ios = 0
            else if (is_iostat_end(ios)) then
                ios = 0
                last = .true.
                if (len(line) == 0) exit
            else
                return
            end if
            if (n == size(lines)) then
                allocate (grown(2*n))
                grown(:n) = lines
                call move_alloc(grown, lines)
            end if
            n = n + 1
            lines(n)%s = line
        end do
        lines = lines(:n)
    end subroutine read_lines

    !> Find the first and last line of every group; check that the file holds nothing but
    !! known groups (each at most once, each closed by '/'), blank lines and comments.
    subroutine locate_groups(path, lines, first, last, err)
        character(len=*), intent(in) :: path
        type(line_t), intent(in) :: lines(:)
        integer, intent(out) :: first(N_GROUPS), last(N_GROUPS)
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: name
        integer :: i, g, open_group, after, lead

        first = 0
        last = 0
        ! A file without &model is not a scene file: say so before anything else.
        if (size(lines) == 0) then
            call make_error(err, ERR_INPUT, path//': no &model group (the file is empty): '// &
                'not a scene file (a scene needs at least &model)')
            return
        else if (.not. any([(header_name(lines(i)%s) == 'model', i = 1, size(lines))])) then
            call make_error(err, ERR_INPUT, path//': no &model group: not a scene file '// &
                '(a scene needs at least &model)')
            return
        end if

        open_group = 0
        do i = 1, size(lines)
            lead = first_nonblank(lines(i)%s)
            name = header_name(lines(i)%s, after)
            if (open_group > 0) then
                if (is_header(lines(i)%s)) then
                    if (name == 'end') then
                        last(open_group) = i
                        open_group = 0
                        cycle
                    end if
                    call make_error(err, ERR_INPUT, path//': &'//trim(GROUP_NAMES(open_group)) &
                        //': not closed by "/" before line '//int_text(i)//' ('// &
                        line_quote(lines(i)%s)//')')
                    return
                else if (find_close(lines(i)%s, 1) > 0) then
                    last(open_group) = i
                    open_group = 0
                end if
                cycle
            end if
            if (lead == 0) cycle
            if (lines(i)%s(lead:lead) == '!') cycle
            if (len(name) == 0) then
                call make_error(err, ERR_INPUT, path//': line '//int_text(i) &
                    //': text outside any group: '//line_quote(lines(i)%s) &
                    //' (a group starts with &name and ends with /)')
                return
            end if
            g = group_index(name)
            if (g == 0) then
                call make_error(err, ERR_INPUT, path//': &'//name//': unknown group (line ' &
                    //int_text(i)//': '//line_quote(lines(i)%s)//'; groups: ' &
                    //group_list()//')')
                return
            end if
            if (first(g) > 0) then
                call make_error(err, ERR_INPUT, path//': &'//name//': group given twice ' &
                    //'(lines '//int_text(first(g))//' and '//int_text(i)//')')
                return
            end if
            first(g) = i
            if (find_close(lines(i)%s, after) > 0) then
                last(g) = i
            else
                open_group = g
            end if
        end do
        if (open_group > 0) then
            call make_error(err, ERR_INPUT, path//': &'//trim(GROUP_NAMES(open_group)) &
                //': not closed by "/" before the end of the file (group starts at line ' &
                //int_text(first(open_group))//')')
        end if
    end subroutine locate_groups

    !> True if the line starts with '&' (after blanks).
    pure logical function is_header(s)
        character(len=*), intent(in) :: s
        integer :: i
        i = first_nonblank(s)
        is_header = .false.
        if (i > 0) is_header = s(i:i) == '&'
    end function is_header

    !> Name (lower case) of the group header `&name` starting the line, or ''.
    !! `after` is the position after the name.
    function header_name(s, after) result(name)
        character(len=*), intent(in) :: s
        integer, intent(out), optional :: after
        character(len=:), allocatable :: name
        integer :: i, j
        name = ''
        if (present(after)) after = len(s) + 1
        i = first_nonblank(s)
        if (i == 0) return
        if (s(i:i) /= '&') return
        j = i + 1
        do while (j <= len(s))
            if (scan(s(j:j), ' /!,'//TAB) > 0) exit
            j = j + 1
        end do
        name = lower(s(i + 1:j - 1))
        if (present(after)) after = j
    end function header_name

    !> Position of the '/' closing a group in `s` from `start` on (outside strings and
    !! comments), or 0.
    pure integer function find_close(s, start) result(pos)
        character(len=*), intent(in) :: s
        integer, intent(in) :: start
        character :: quote
        integer :: i
        quote = ' '
        pos = 0
        do i = start, len(s)
            if (quote /= ' ') then
                if (s(i:i) == quote) quote = ' '
                cycle
            end if
            select case (s(i:i))
            case ("'", '"')
                quote = s(i:i)
            case ('!')
                return
            case ('/')
                pos = i
                return
            end select
        end do
    end function find_close

    !> The error of a failed read of group `g` (lines first..last of the file): find the
    !! offending line by reading growing prefixes of the group, then the offending
    !! `key = value` on that line, and name both.
    subroutine file_read_error(path, g, lines, first, last, ios, msg, err)
        character(len=*), intent(in) :: path
        integer, intent(in) :: g
        type(line_t), intent(in) :: lines(:)
        integer, intent(in) :: first, last
        integer, intent(in) :: ios
        character(len=*), intent(in) :: msg
        type(error_t), allocatable, intent(out) :: err
        type(scene_t) :: scratch
        character(len=:), allocatable :: prefix, key, value, reason
        character(len=BUF_LEN) :: msg2
        integer :: k, ios2, bad

        prefix = path//': &'//trim(GROUP_NAMES(g))//': '
        if (ios == IOS_TOO_LONG) then
            call make_error(err, ERR_INPUT, prefix//trim(msg))
            return
        end if
        bad = 0
        do k = first, last
            block
                character(len=max_len(lines(first:k))) :: recs(k - first + 2)
                call fill_records(lines(first:k), '/', recs)
                msg2 = ''
                call read_group(g, scratch, ios2, msg2, recs=recs)
            end block
            if (ios2 /= 0) then
                bad = k
                exit
            end if
        end do
        if (bad == 0) then
            call make_error(err, ERR_INPUT, prefix//'cannot read: '//trim(msg)//' (group at line ' &
                //int_text(first)//')')
            return
        end if
        call find_bad_assignment(g, lines(bad)%s, key, value, reason, msg2)
        if (len(key) == 0) then
            call make_error(err, ERR_INPUT, prefix//'cannot read: '//trim(msg2)//' (line ' &
                //int_text(bad)//': '//line_quote(lines(bad)%s)//')')
        else if (len(reason) == 0) then
            call make_error(err, ERR_INPUT, prefix//'unknown key "'//key//'" (line ' &
                //int_text(bad)//': '//line_quote(lines(bad)%s)//')'//key_hint(g, key))
        else
            call make_error(err, ERR_INPUT, prefix//'cannot read '//key//' = '//value//': ' &
                //reason//' (line '//int_text(bad)//': '//line_quote(lines(bad)%s)//') [' &
                //trim(msg2)//']')
        end if
    end subroutine file_read_error

    !> On a line that cannot be read, find the first `key = value` that cannot be read on
    !! its own. `key` is '' if none is found; `reason` is '' for an unknown key.
    subroutine find_bad_assignment(g, line, key, value, reason, msg)
        integer, intent(in) :: g
        character(len=*), intent(in) :: line
        character(len=:), allocatable, intent(out) :: key, value, reason
        character(len=*), intent(inout) :: msg
        type(scene_t) :: scratch
        integer, allocatable :: starts(:)
        integer :: i, ios, seg_end, eq
        character(len=:), allocatable :: seg
        character(len=BUF_LEN) :: seg_msg

        key = ''
        value = ''
        reason = ''
        call assignment_starts(line, starts)
        do i = 1, size(starts)
            if (i < size(starts)) then
                seg_end = starts(i + 1) - 1
            else
                seg_end = len(line)
            end if
            seg = line(starts(i):seg_end)
            seg_msg = ''
            block
                character(len=max(len(seg), len(GROUP_NAMES(g)) + 1)) :: recs(3)
                recs(1) = '&'//trim(GROUP_NAMES(g))
                recs(2) = seg
                recs(3) = '/'
                call read_group(g, scratch, ios, seg_msg, recs=recs)
            end block
            if (ios == 0) cycle
            msg = seg_msg
            eq = index(seg, '=')
            key = trim(seg(:eq - 1))
            value = value_part(seg(eq + 1:))
            if (key_index(g, base_key(key)) > 0) then
                reason = expected_text(g, key, value)
            end if
            return
        end do
    end subroutine find_bad_assignment

    !> Start positions of `name =` or `name(...) =` assignments on a line (outside strings
    !! and comments).
    subroutine assignment_starts(s, starts)
        character(len=*), intent(in) :: s
        integer, allocatable, intent(out) :: starts(:)
        character :: quote, c, prev
        integer :: i, j, p
        allocate (starts(0))
        quote = ' '
        i = 1
        do while (i <= len(s))
            c = s(i:i)
            if (quote /= ' ') then
                if (c == quote) quote = ' '
                i = i + 1
                cycle
            end if
            if (c == "'" .or. c == '"') then
                quote = c
                i = i + 1
                cycle
            end if
            if (c == '!') exit
            prev = ' '
            if (i > 1) prev = s(i - 1:i - 1)
            if (is_letter(c) .and. .not. (is_name_char(prev) .or. scan(prev, '.&%$') > 0)) then
                j = i
                do while (j <= len(s))
                    if (.not. is_name_char(s(j:j))) exit
                    j = j + 1
                end do
                j = skip_blanks(s, j)
                if (j <= len(s)) then
                    if (s(j:j) == '(') then
                        p = index(s(j:), ')')
                        if (p == 0) then
                            j = len(s) + 1
                        else
                            j = skip_blanks(s, j + p)
                        end if
                    end if
                end if
                if (j <= len(s)) then
                    if (s(j:j) == '=') starts = [starts, i]
                end if
                i = max(j, i + 1)
                cycle
            end if
            i = i + 1
        end do
    end subroutine assignment_starts

    !> The value of `key = value`, without a trailing separator, '/' or comment.
    function value_part(s) result(v)
        character(len=*), intent(in) :: s
        character(len=:), allocatable :: v
        character :: quote
        integer :: i, stop_at
        quote = ' '
        stop_at = len(s) + 1
        do i = 1, len(s)
            if (quote /= ' ') then
                if (s(i:i) == quote) quote = ' '
                cycle
            end if
            select case (s(i:i))
            case ("'", '"')
                quote = s(i:i)
            case ('!', '/')
                stop_at = i
                exit
            end select
        end do
        v = trim(adjustl(s(:stop_at - 1)))
        do while (len(v) > 0)
            if (v(len(v):len(v)) /= ',') exit
            v = trim(v(:len(v) - 1))
        end do
    end function value_part

    !> What a key of group g expects, as a reason for a failed read.
    function expected_text(g, key, value) result(text)
        integer, intent(in) :: g
        character(len=*), intent(in) :: key, value
        character(len=:), allocatable :: text
        select case (KEYS(key_index(g, base_key(key)))%type)
        case (T_REAL)
            text = 'expected a real number'
        case (T_INT)
            text = 'expected an integer'
        case (T_LOGICAL)
            text = 'expected .true. or .false.'
        case (T_REAL2)
            if (index(key, '(') > 0) then
                text = 'expected a real number at an index 1 or 2'
            else
                text = 'expected two real numbers (x, y)'
            end if
        case (T_REALN)
            if (index(key, '(') > 0) then
                text = 'expected a real number at an index 1 .. '//int_text(N_ATTACH)
            else
                text = 'expected up to '//int_text(N_ATTACH)//' real numbers'
            end if
        case default
            text = 'expected a quoted string'
            if (len(value) > 0) then
                if (value(1:1) /= "'" .and. value(1:1) /= '"') then
                    text = text//' ('//key//' = '//quoted(value)//')'
                end if
            end if
        end select
    end function expected_text

    !> Length of the longest line, at least 1.
    pure integer function max_len(lines) result(n)
        type(line_t), intent(in) :: lines(:)
        integer :: i
        n = 1
        do i = 1, size(lines)
            n = max(n, len(lines(i)%s))
        end do
    end function max_len

    !> The lines and one more record as an internal file.
    subroutine fill_records(lines, extra, recs)
        type(line_t), intent(in) :: lines(:)
        character(len=*), intent(in) :: extra
        character(len=*), intent(out) :: recs(:)
        integer :: i
        do i = 1, size(lines)
            recs(i) = lines(i)%s
        end do
        recs(size(lines) + 1) = extra
    end subroutine fill_records

    ! ------------------------------------------------------------------------------------
    ! Overrides
    ! ------------------------------------------------------------------------------------

    !> Parse and check one `group.key=value` argument; build its namelist text.
    subroutine parse_override(arg, ov, err)
        character(len=*), intent(in) :: arg
        type(override_t), intent(out) :: ov
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: s, lhs, group, loc
        integer :: eq, dot, ki

        s = trim(adjustl(arg))
        ov%text = s
        loc = '--set '//s
        eq = index(s, '=')
        if (eq <= 1) then
            call make_error(err, ERR_INPUT, loc//': expected group.key=value')
            return
        end if
        lhs = trim(s(:eq - 1))
        ov%value = trim(adjustl(s(eq + 1:)))
        dot = index(lhs, '.')
        if (dot <= 1 .or. dot >= len(lhs) .or. len(ov%value) == 0) then
            call make_error(err, ERR_INPUT, loc//': expected group.key=value')
            return
        end if
        group = lower(trim(lhs(:dot - 1)))
        ov%key = lower(trim(adjustl(lhs(dot + 1:))))
        ov%base = base_key(ov%key)
        ov%group = group_index(group)
        if (ov%group == 0) then
            call make_error(err, ERR_INPUT, loc//': unknown group "'//group//'" (groups: ' &
                //group_list()//')')
            return
        end if
        loc = loc//': &'//group//': '
        ki = key_index(ov%group, ov%base)
        if (ki == 0 .or. verify(ov%key, 'abcdefghijklmnopqrstuvwxyz0123456789_() ') > 0) then
            call make_error(err, ERR_INPUT, loc//'unknown key "'//ov%key//'"' &
                //key_hint(ov%group, ov%base))
            return
        end if
        if (KEYS(ki)%type == T_STRING) then
            if (ov%value(1:1) == "'" .or. ov%value(1:1) == '"') then
                if (.not. is_single_literal(ov%value)) then
                    call make_error(err, ERR_INPUT, loc//'cannot read '//ov%key//' = ' &
                        //ov%value//': unbalanced quotes')
                    return
                end if
                ov%nml = '&'//group//' '//ov%key//' = '//ov%value//' /'
            else
                ov%nml = '&'//group//' '//ov%key//' = '//quoted(ov%value)//' /'
            end if
        else
            if (scan(ov%value, '=/&$!''"') > 0) then
                call make_error(err, ERR_INPUT, loc//'cannot read '//ov%key//' = ' &
                    //ov%value//': '//expected_text(ov%group, ov%key, ov%value))
                return
            end if
            ov%nml = '&'//group//' '//ov%key//' = '//ov%value//' /'
        end if
    end subroutine parse_override

    !> Read one override into the scene.
    subroutine apply_override(ov, scene, err)
        type(override_t), intent(in) :: ov
        type(scene_t), intent(inout) :: scene
        type(error_t), allocatable, intent(out) :: err
        character(len=BUF_LEN) :: msg
        character(len=:), allocatable :: loc
        integer :: ios
        msg = ''
        call read_group(ov%group, scene, ios, msg, recs=[character(len=len(ov%nml)) :: ov%nml])
        if (ios == 0) return
        loc = '--set '//ov%text//': &'//trim(GROUP_NAMES(ov%group))//': '
        if (ios == IOS_TOO_LONG) then
            call make_error(err, ERR_INPUT, loc//trim(msg))
        else
            call make_error(err, ERR_INPUT, loc//'cannot read '//ov%key//' = '//ov%value &
                //': '//expected_text(ov%group, ov%key, ov%value)//' ['//trim(msg)//']')
        end if
    end subroutine apply_override

    ! ------------------------------------------------------------------------------------
    ! Checks and derived defaults
    ! ------------------------------------------------------------------------------------

    !> Check every key; names are stored in lower case.
    subroutine check_scene(ctx, scene, err)
        type(context_t), intent(in) :: ctx
        type(scene_t), intent(inout) :: scene
        type(error_t), allocatable, intent(out) :: err
        integer :: lowest, highest, default
        character(len=len(METHODS%name)), allocatable :: method_names(:)

        associate (r => scene%rope)
            call check_real(ctx, G_ROPE, 'length', r%length, '>', 0.0_wp, err)
            if (allocated(err)) return
            call check_real(ctx, G_ROPE, 'density', r%density, '>', 0.0_wp, err)
            if (allocated(err)) return
            call check_real(ctx, G_ROPE, 'diameter', r%diameter, '>', 0.0_wp, err)
            if (allocated(err)) return
            call check_real(ctx, G_ROPE, 'young_modulus', r%young_modulus, '>', 0.0_wp, err)
            if (allocated(err)) return
            call check_real(ctx, G_ROPE, 'shear_modulus', r%shear_modulus, '>', 0.0_wp, err)
            if (allocated(err)) return
            call check_real(ctx, G_ROPE, 'normal_damping', r%normal_damping, '>=', 0.0_wp, err)
            if (allocated(err)) return
            if (.not. ieee_is_nan(r%tangential_damping)) then
                call check_real(ctx, G_ROPE, 'tangential_damping', r%tangential_damping, &
                    '>=', 0.0_wp, err)
                if (allocated(err)) return
            end if
            call check_real(ctx, G_ROPE, 'shape_factor', r%shape_factor, '>', 0.0_wp, err)
            if (allocated(err)) return
            call check_real(ctx, G_ROPE, 'gravity', r%gravity, '>=', 0.0_wp, err)
            if (allocated(err)) return
        end associate

        call check_name(ctx, G_MODEL, 'kind', scene%model%kind, KINDS_ALLOWED, NONE_KNOWN, err)
        if (allocated(err)) return
        call check_int(ctx, G_MODEL, 'elements', scene%model%elements, 2, huge(1), err)
        if (allocated(err)) return
        call check_real(ctx, G_MODEL, 'mpp_axial_damping_factor', &
            scene%model%mpp_axial_damping_factor, '>=', 0.0_wp, err)
        if (allocated(err)) return
        call check_real(ctx, G_MODEL, 'mpp_bending_damping_factor', &
            scene%model%mpp_bending_damping_factor, '>=', 0.0_wp, err)
        if (allocated(err)) return

        associate (s => scene%supports)
            call check_name(ctx, G_SUPPORTS, 'top', s%top, SUPPORTS_ALLOWED, NONE_KNOWN, err)
            if (allocated(err)) return
            if (scene%model%kind == 'mpp' .and. s%top == 'free') then
                call fail(ctx, G_SUPPORTS, 'top', '"free"', 'the mpp model hangs from its '// &
                    'top joint: use pinned or clamped (or the rfem model)', err)
                return
            end if
            call check_name(ctx, G_SUPPORTS, 'bottom', s%bottom, SUPPORTS_ALLOWED, NONE_KNOWN, &
                err)
            if (allocated(err)) return
            if (.not. all(ieee_is_finite(s%top_anchor))) then
                call fail(ctx, G_SUPPORTS, 'top_anchor', pair_text(s%top_anchor), &
                    'must be finite', err)
                return
            end if
            s%bottom_anchor_set = .not. any(ieee_is_nan(s%bottom_anchor))
            if (any(ieee_is_nan(s%bottom_anchor)) .and. .not. all(ieee_is_nan(s%bottom_anchor))) &
                then
                call fail(ctx, G_SUPPORTS, 'bottom_anchor', pair_text(s%bottom_anchor), &
                    "give both components (or neither, for the rope's lower end in its " &
                    //'initial state)', err)
                return
            end if
            if (s%bottom_anchor_set .and. .not. all(ieee_is_finite(s%bottom_anchor))) then
                call fail(ctx, G_SUPPORTS, 'bottom_anchor', pair_text(s%bottom_anchor), &
                    'must be finite', err)
                return
            end if
            call check_real(ctx, G_SUPPORTS, 'top_angle_deg', s%top_angle_deg, '', 0.0_wp, err)
            if (allocated(err)) return
            call check_real(ctx, G_SUPPORTS, 'bottom_angle_deg', s%bottom_angle_deg, '', &
                0.0_wp, err)
            if (allocated(err)) return
            call check_real(ctx, G_SUPPORTS, 'support_stiffness_factor', &
                s%support_stiffness_factor, '>', 0.0_wp, err)
            if (allocated(err)) return
        end associate

        call check_name(ctx, G_INITIAL, 'shape', scene%initial%shape, SHAPES_ALLOWED, &
            NONE_KNOWN, err)
        if (allocated(err)) return
        call check_real(ctx, G_INITIAL, 'angle_deg', scene%initial%angle_deg, '', 0.0_wp, err)
        if (allocated(err)) return
        call check_int(ctx, G_INITIAL, 'mode', scene%initial%mode, 1, huge(1), err)
        if (allocated(err)) return
        call check_real(ctx, G_INITIAL, 'mode_amplitude', scene%initial%mode_amplitude, '', &
            0.0_wp, err)
        if (allocated(err)) return
        call check_effect_keys(ctx, scene, err)
        if (allocated(err)) return

        associate (v => scene%solver)
            method_names = METHODS%name
            call check_name(ctx, G_SOLVER, 'method', v%method, method_names, NONE_KNOWN, &
                err)
            if (allocated(err)) return
            call check_real(ctx, G_SOLVER, 'rtol', v%rtol, '>', 0.0_wp, err)
            if (allocated(err)) return
            call check_real(ctx, G_SOLVER, 'rtol', v%rtol, '<', 1.0_wp, err)
            if (allocated(err)) return
            call check_real(ctx, G_SOLVER, 'atol', v%atol, '>', 0.0_wp, err)
            if (allocated(err)) return
            associate (m => METHODS(method_index(v%method)))
                lowest = m%lowest_order
                highest = m%highest_order
                default = m%default_order
            end associate
            if (v%max_order == 0) v%max_order = default
            if (v%max_order < lowest .or. v%max_order > highest) then
                call fail(ctx, G_SOLVER, 'max_order', int_text(v%max_order), &
                    'out of range for method '//trim(v%method)//' (allowed: '// &
                    int_text(lowest)//' .. '//int_text(highest)//', or 0 for the default '// &
                    int_text(default)//')', err)
                return
            end if
            call check_int(ctx, G_SOLVER, 'max_steps', v%max_steps, 1, huge(1), err)
            if (allocated(err)) return
            call check_real(ctx, G_SOLVER, 't_end', v%t_end, '>', 0.0_wp, err)
            if (allocated(err)) return
            call check_real(ctx, G_SOLVER, 'output_interval', v%output_interval, '>', 0.0_wp, &
                err)
            if (allocated(err)) return
            if (v%stability_limit_detection .and. v%method /= 'cvode') then
                call fail(ctx, G_SOLVER, 'stability_limit_detection', '.true.', &
                    'only for method cvode (method '//trim(v%method)//' has no such option; '// &
                    'limit its order with max_order)', err)
                return
            end if
            call check_real(ctx, G_SOLVER, 'fault_nan_after', v%fault_nan_after, '', 0.0_wp, &
                err)
            if (allocated(err)) return
        end associate
    end subroutine check_scene

    !> Fill in the derived defaults: tangential damping (eq. 13 of the paper) and the
    !! output file.
    subroutine resolve_defaults(scene)
        type(scene_t), intent(inout) :: scene
        character(len=:), allocatable :: base
        integer :: slash
        associate (r => scene%rope)
            if (ieee_is_nan(r%tangential_damping)) then
                r%tangential_damping = r%normal_damping*r%shear_modulus/r%young_modulus
            end if
        end associate
        if (len_trim(scene%output%file) == 0) then
            slash = index(scene%path, '/', back=.true.)
            base = scene%path(slash + 1:)
            if (len(base) > 4) then
                if (lower(base(len(base) - 3:)) == '.nml') base = base(:len(base) - 4)
            end if
            scene%output%file = 'out/'//base//'.h5'
        end if
    end subroutine resolve_defaults

    !> Checks of the keys of the effects beyond the paper's springs and gravity: motion and
    !! release of the supports (&supports; reads the motion tables), the initial velocity and
    !! the folded shape (&initial), &fluid, &ground and &attachments.
    subroutine check_effect_keys(ctx, scene, err)
        type(context_t), intent(in) :: ctx
        type(scene_t), intent(inout) :: scene
        type(error_t), allocatable, intent(out) :: err
        integer :: k
        logical :: any_drag

        associate (s => scene%supports)
            call check_motion(ctx, 'top', s%top, s%top_motion, s%top_amplitude, &
                s%top_frequency, s%top_phase_deg, s%top_angle_amplitude_deg, &
                s%top_angle_phase_deg, s%top_table, s%top_release_time, s%top_table_rows, &
                scene%path, err)
            if (allocated(err)) return
            call check_motion(ctx, 'bottom', s%bottom, s%bottom_motion, s%bottom_amplitude, &
                s%bottom_frequency, s%bottom_phase_deg, s%bottom_angle_amplitude_deg, &
                s%bottom_angle_phase_deg, s%bottom_table, s%bottom_release_time, &
                s%bottom_table_rows, scene%path, err)
            if (allocated(err)) return
            if (scene%model%kind == 'mpp' .and. s%top_release_time >= 0.0_wp) then
                call fail(ctx, G_SUPPORTS, 'top_release_time', real_text(s%top_release_time), &
                    'the mpp model hangs from its top joint, which cannot be released (use ' &
                    //'the rfem model)', err)
                return
            end if
        end associate

        associate (i => scene%initial)
            if (.not. all(ieee_is_finite(i%velocity))) then
                call fail(ctx, G_INITIAL, 'velocity', pair_text(i%velocity), 'must be finite', &
                    err)
                return
            end if
            if (scene%model%kind == 'mpp' .and. any(abs(i%velocity) > 0.0_wp)) then
                call fail(ctx, G_INITIAL, 'velocity', pair_text(i%velocity), 'the mpp model ' &
                    //'starts at rest from its pinned top joint (use the rfem model)', err)
                return
            end if
            if (i%shape == 'folded' .and. mod(scene%model%elements, 2) /= 1) then
                call fail(ctx, G_INITIAL, 'shape', '"folded"', 'needs an odd number of ' &
                    //'elements (two equal halves and one across the fold; elements = ' &
                    //int_text(scene%model%elements)//')', err)
                return
            end if
        end associate

        associate (f => scene%fluid)
            call check_real(ctx, G_FLUID, 'density', f%density, '>=', 0.0_wp, err)
            if (allocated(err)) return
            call check_real(ctx, G_FLUID, 'normal_drag_coefficient', f%normal_drag_coefficient, &
                '>=', 0.0_wp, err)
            if (allocated(err)) return
            call check_real(ctx, G_FLUID, 'tangential_drag_coefficient', &
                f%tangential_drag_coefficient, '>=', 0.0_wp, err)
            if (allocated(err)) return
            call check_real(ctx, G_FLUID, 'linear_normal_drag', f%linear_normal_drag, '>=', &
                0.0_wp, err)
            if (allocated(err)) return
            call check_real(ctx, G_FLUID, 'linear_tangential_drag', f%linear_tangential_drag, &
                '>=', 0.0_wp, err)
            if (allocated(err)) return
            if (.not. all(ieee_is_finite(f%current))) then
                call fail(ctx, G_FLUID, 'current', pair_text(f%current), 'must be finite', err)
                return
            end if
            any_drag = f%density*(f%normal_drag_coefficient + f%tangential_drag_coefficient) &
                > 0.0_wp .or. f%linear_normal_drag + f%linear_tangential_drag > 0.0_wp
            if (scene%effects%drag .and. .not. any_drag) then
                call fail(ctx, G_EFFECTS, 'drag', '.true.', 'every drag coefficient of &fluid ' &
                    //'is zero (give density and a drag coefficient, or a linear drag)', err)
                return
            end if
        end associate

        associate (g => scene%ground)
            if (.not. all(ieee_is_finite(g%point))) then
                call fail(ctx, G_GROUND, 'point', pair_text(g%point), 'must be finite', err)
                return
            end if
            if (.not. all(ieee_is_finite(g%normal)) .or. .not. norm2(g%normal) > 0.0_wp) then
                call fail(ctx, G_GROUND, 'normal', pair_text(g%normal), 'must be a finite, ' &
                    //'non-zero vector (towards the free side; (-1, 0) is up)', err)
                return
            end if
            call check_real(ctx, G_GROUND, 'stiffness', g%stiffness, '>', 0.0_wp, err)
            if (allocated(err)) return
            call check_real(ctx, G_GROUND, 'damping', g%damping, '>=', 0.0_wp, err)
            if (allocated(err)) return
            call check_real(ctx, G_GROUND, 'friction_coefficient', g%friction_coefficient, '>=', &
                0.0_wp, err)
            if (allocated(err)) return
            call check_real(ctx, G_GROUND, 'friction_regularization_speed', &
                g%friction_regularization_speed, '>', 0.0_wp, err)
            if (allocated(err)) return
        end associate

        associate (a => scene%attachments)
            do k = 1, N_ATTACH
                if (ieee_is_nan(a%mass_positions(k))) then
                    call unused(k, 'masses', a%masses(k), 'mass_positions')
                else
                    call position(k, 'mass_positions', a%mass_positions(k))
                    if (allocated(err)) return
                    if (.not. (ieee_is_finite(a%masses(k)) .and. a%masses(k) > 0.0_wp)) &
                        call fail_at(k, 'masses', a%masses(k), 'must be > 0 (a mass at ' &
                        //'mass_positions('//int_text(k)//') = ' &
                        //real_text(a%mass_positions(k))//' m)')
                end if
                if (allocated(err)) return
                if (ieee_is_nan(a%load_positions(k))) then
                    call unused(k, 'load_force_x', a%load_force_x(k), 'load_positions')
                    if (.not. allocated(err)) &
                        call unused(k, 'load_force_y', a%load_force_y(k), 'load_positions')
                    if (.not. allocated(err)) &
                        call unused(k, 'load_amplitude_x', a%load_amplitude_x(k), 'load_positions')
                    if (.not. allocated(err)) &
                        call unused(k, 'load_amplitude_y', a%load_amplitude_y(k), 'load_positions')
                else
                    call position(k, 'load_positions', a%load_positions(k))
                    if (.not. allocated(err)) call finite(k, 'load_force_x', a%load_force_x(k))
                    if (.not. allocated(err)) call finite(k, 'load_force_y', a%load_force_y(k))
                    if (.not. allocated(err)) &
                        call finite(k, 'load_amplitude_x', a%load_amplitude_x(k))
                    if (.not. allocated(err)) &
                        call finite(k, 'load_amplitude_y', a%load_amplitude_y(k))
                    if (.not. allocated(err)) call finite(k, 'load_phase_deg', a%load_phase_deg(k))
                    if (.not. allocated(err)) then
                        if (.not. (ieee_is_finite(a%load_frequency(k)) .and. &
                            a%load_frequency(k) >= 0.0_wp)) call fail_at(k, 'load_frequency', &
                            a%load_frequency(k), 'must be >= 0')
                    end if
                end if
                if (allocated(err)) return
            end do
        end associate
    contains
        subroutine fail_at(k, key, x, reason)
            integer, intent(in) :: k
            character(len=*), intent(in) :: key, reason
            real(wp), intent(in) :: x
            call make_error(err, ERR_INPUT, origin(ctx, G_ATTACHMENTS, key)//': &attachments: ' &
                //key//'('//int_text(k)//') = '//real_text(x)//': '//reason)
        end subroutine fail_at

        subroutine position(k, key, x)
            integer, intent(in) :: k
            character(len=*), intent(in) :: key
            real(wp), intent(in) :: x
            if (.not. (ieee_is_finite(x) .and. x >= 0.0_wp .and. x <= scene%rope%length)) &
                call fail_at(k, key, x, 'must be in 0 .. '//real_text(scene%rope%length) &
                //' (m along the rope from its top end; length = ' &
                //real_text(scene%rope%length)//')')
        end subroutine position

        subroutine finite(k, key, x)
            integer, intent(in) :: k
            character(len=*), intent(in) :: key
            real(wp), intent(in) :: x
            if (.not. ieee_is_finite(x)) call fail_at(k, key, x, 'must be finite')
        end subroutine finite

        subroutine unused(k, key, x, position_key)
            integer, intent(in) :: k
            character(len=*), intent(in) :: key, position_key
            real(wp), intent(in) :: x
            if (abs(x) > 0.0_wp .or. ieee_is_nan(x)) call fail_at(k, key, x, 'no ' &
                //position_key//'('//int_text(k)//') given (an entry is used when its ' &
                //'position is given)')
        end subroutine unused
    end subroutine check_effect_keys

    !> Check the motion and release keys of one support ('top' or 'bottom'); read its
    !! motion table, resolving a relative path against the scene file's directory.
    subroutine check_motion(ctx, end, support, motion, amplitude, frequency, phase_deg, &
            angle_amplitude_deg, angle_phase_deg, table, release_time, rows, scene_path, err)
        type(context_t), intent(in) :: ctx
        character(len=*), intent(in) :: end, support, scene_path
        character(len=*), intent(inout) :: motion, table
        real(wp), intent(in) :: amplitude(2), frequency, phase_deg(2), angle_amplitude_deg, &
            angle_phase_deg, release_time
        real(wp), allocatable, intent(out) :: rows(:, :)
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: full

        call check_name(ctx, G_SUPPORTS, end//'_motion', motion, MOTIONS_ALLOWED, NONE_KNOWN, &
            err)
        if (allocated(err)) return
        if (.not. all(ieee_is_finite(amplitude))) then
            call fail(ctx, G_SUPPORTS, end//'_amplitude', pair_text(amplitude), 'must be finite', &
                err)
            return
        end if
        if (.not. all(ieee_is_finite(phase_deg))) then
            call fail(ctx, G_SUPPORTS, end//'_phase_deg', pair_text(phase_deg), &
                'must be finite', err)
            return
        end if
        call check_real(ctx, G_SUPPORTS, end//'_frequency', frequency, '>=', 0.0_wp, err)
        if (allocated(err)) return
        call check_real(ctx, G_SUPPORTS, end//'_angle_amplitude_deg', angle_amplitude_deg, '', &
            0.0_wp, err)
        if (allocated(err)) return
        call check_real(ctx, G_SUPPORTS, end//'_angle_phase_deg', angle_phase_deg, '', 0.0_wp, &
            err)
        if (allocated(err)) return
        call check_real(ctx, G_SUPPORTS, end//'_release_time', release_time, '', 0.0_wp, err)
        if (allocated(err)) return
        if (motion /= 'fixed' .and. support == 'free') then
            call fail(ctx, G_SUPPORTS, end//'_motion', '"'//trim(motion)//'"', 'the '//end// &
                ' end is free: there is no support to move (set '//end//' = ''pinned'' or ' &
                //'''clamped'')', err)
            return
        end if
        if (release_time >= 0.0_wp .and. support == 'free') then
            call fail(ctx, G_SUPPORTS, end//'_release_time', real_text(release_time), 'the ' &
                //end//' end is free already (a release needs '//end//' = ''pinned'' or ' &
                //'''clamped''; < 0 means never)', err)
            return
        end if
        select case (motion)
        case ('harmonic')
            if (.not. frequency > 0.0_wp) then
                call fail(ctx, G_SUPPORTS, end//'_frequency', real_text(frequency), 'must be ' &
                    //'> 0 for '//end//'_motion = ''harmonic''', err)
                return
            end if
            if (abs(angle_amplitude_deg) > 0.0_wp .and. support /= 'clamped') then
                call fail(ctx, G_SUPPORTS, end//'_angle_amplitude_deg', &
                    real_text(angle_amplitude_deg), 'only a clamped support turns (' &
                    //end//' = "'//trim(support)//'")', err)
                return
            end if
        case ('table')
            if (len_trim(table) == 0) then
                call fail(ctx, G_SUPPORTS, end//'_table', "''", 'a file is needed for ' &
                    //end//'_motion = ''table'' (rows t, dx, dy, dangle_deg)', err)
                return
            end if
            full = resolve_input_path(scene_path, trim(table))
            if (len(full) > len(table)) then
                call fail(ctx, G_SUPPORTS, end//'_table', '"'//full(:40)//'..."', &
                    'too long (at most '//int_text(len(table))//' characters)', err)
                return
            end if
            table = full
            call read_motion_table(full, origin(ctx, G_SUPPORTS, end//'_table')// &
                ': &supports: '//end//'_table', rows, err)
            if (allocated(err)) return
        end select
    end subroutine check_motion

    !> A file named in a scene: absolute as given, else relative to the scene file's
    !! directory, made absolute so that the echo of the scene reads from anywhere.
    function resolve_input_path(scene_path, name) result(full)
        character(len=*), intent(in) :: scene_path, name
        character(len=:), allocatable :: full
        full = absolute_path(name, scene_path)
    end function resolve_input_path

    !> Check that x is finite and, unless `op` is '', that `x op bound` holds.
    subroutine check_real(ctx, g, key, x, op, bound, err)
        type(context_t), intent(in) :: ctx
        integer, intent(in) :: g
        character(len=*), intent(in) :: key, op
        real(wp), intent(in) :: x, bound
        type(error_t), allocatable, intent(out) :: err
        logical :: ok
        if (.not. ieee_is_finite(x)) then
            call fail(ctx, g, key, real_text(x), 'must be finite', err)
            return
        end if
        select case (op)
        case ('>')
            ok = x > bound
        case ('>=')
            ok = x >= bound
        case ('<')
            ok = x < bound
        case default
            ok = .true.
        end select
        if (.not. ok) call fail(ctx, g, key, real_text(x), 'must be '//op//' '// &
            bound_text(bound), err)
    end subroutine check_real

    !> Check lo <= n <= hi.
    subroutine check_int(ctx, g, key, n, lo, hi, err)
        type(context_t), intent(in) :: ctx
        integer, intent(in) :: g
        character(len=*), intent(in) :: key
        integer, intent(in) :: n, lo, hi
        type(error_t), allocatable, intent(out) :: err
        if (n < lo) then
            if (hi == huge(hi)) then
                call fail(ctx, g, key, int_text(n), 'must be >= '//int_text(lo), err)
            else
                call fail(ctx, g, key, int_text(n), 'must be in '//int_text(lo)//'..' &
                    //int_text(hi), err)
            end if
        else if (n > hi) then
            call fail(ctx, g, key, int_text(n), 'must be in '//int_text(lo)//'..' &
                //int_text(hi), err)
        end if
    end subroutine check_int

    !> Check a name against its allowed values (case-insensitive); store it in lower case.
    subroutine check_name(ctx, g, key, name, allowed, known, err)
        type(context_t), intent(in) :: ctx
        integer, intent(in) :: g
        character(len=*), intent(in) :: key
        character(len=*), intent(inout) :: name
        character(len=*), intent(in) :: allowed(:), known(:)
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: v, list
        integer :: i
        v = lower(trim(adjustl(name)))
        if (any(allowed == v)) then
            name = v
            return
        end if
        list = trim(allowed(1))
        do i = 2, size(allowed)
            list = list//', '//trim(allowed(i))
        end do
        if (any(known == v)) then
            call fail(ctx, g, key, '"'//trim(name)//'"', 'not available yet in this version ' &
                //'(allowed: '//list//')', err)
        else
            call fail(ctx, g, key, '"'//trim(name)//'"', 'unknown (allowed: '//list//')', err)
        end if
    end subroutine check_name

    !> Make the error of a key whose value is wrong.
    subroutine fail(ctx, g, key, value, reason, err)
        type(context_t), intent(in) :: ctx
        integer, intent(in) :: g
        character(len=*), intent(in) :: key, value, reason
        type(error_t), allocatable, intent(out) :: err
        call make_error(err, ERR_INPUT, origin(ctx, g, key)//': &'//trim(GROUP_NAMES(g)) &
            //': '//key//' = '//value//': '//reason)
    end subroutine fail

    !> Where the value of a key came from: its last `--set`, else the file.
    function origin(ctx, g, key) result(text)
        type(context_t), intent(in) :: ctx
        integer, intent(in) :: g
        character(len=*), intent(in) :: key
        character(len=:), allocatable :: text
        integer :: i
        do i = size(ctx%overrides), 1, -1
            if (ctx%overrides(i)%group == g .and. ctx%overrides(i)%base == key) then
                text = '--set '//ctx%overrides(i)%text
                return
            end if
        end do
        text = ctx%path
    end function origin

    ! ------------------------------------------------------------------------------------
    ! Keys and groups
    ! ------------------------------------------------------------------------------------

    pure integer function group_index(name) result(g)
        character(len=*), intent(in) :: name
        do g = 1, N_GROUPS
            if (GROUP_NAMES(g) == name) return
        end do
        g = 0
    end function group_index

    pure integer function key_index(g, name) result(k)
        integer, intent(in) :: g
        character(len=*), intent(in) :: name
        do k = 1, size(KEYS)
            if (KEYS(k)%group == g .and. KEYS(k)%name == lower(name)) return
        end do
        k = 0
    end function key_index

    !> A key without its index, lower case: 'top_anchor(2)' -> 'top_anchor'.
    pure function base_key(key) result(base)
        character(len=*), intent(in) :: key
        character(len=:), allocatable :: base
        integer :: p
        p = index(key, '(')
        if (p == 0) p = len(key) + 1
        base = lower(trim(adjustl(key(:p - 1))))
    end function base_key

    function group_list() result(list)
        character(len=:), allocatable :: list
        integer :: g
        list = trim(GROUP_NAMES(1))
        do g = 2, N_GROUPS
            list = list//', '//trim(GROUP_NAMES(g))
        end do
    end function group_list

    !> '; did you mean "x"?' for a near miss, else the list of keys of the group.
    function key_hint(g, key) result(text)
        integer, intent(in) :: g
        character(len=*), intent(in) :: key
        character(len=:), allocatable :: text
        integer :: k, d, best, best_k
        best = huge(1)
        best_k = 0
        text = ''
        do k = 1, size(KEYS)
            if (KEYS(k)%group /= g) cycle
            d = edit_distance(lower(key), trim(KEYS(k)%name))
            if (d < best) then
                best = d
                best_k = k
            end if
            if (len(text) == 0) then
                text = trim(KEYS(k)%name)
            else
                text = text//', '//trim(KEYS(k)%name)
            end if
        end do
        if (best_k > 0 .and. best <= 2) then
            text = '; did you mean "'//trim(KEYS(best_k)%name)//'"?'
        else
            text = '; keys: '//text
        end if
    end function key_hint

    !> Optimal string alignment distance (Levenshtein with transpositions).
    pure integer function edit_distance(a, b) result(dist)
        character(len=*), intent(in) :: a, b
        integer :: d(0:len(a), 0:len(b)), i, j, cost
        do i = 0, len(a)
            d(i, 0) = i
        end do
        do j = 0, len(b)
            d(0, j) = j
        end do
        do j = 1, len(b)
            do i = 1, len(a)
                cost = merge(0, 1, a(i:i) == b(j:j))
                d(i, j) = min(d(i - 1, j) + 1, d(i, j - 1) + 1, d(i - 1, j - 1) + cost)
                if (i > 1 .and. j > 1) then
                    if (a(i:i) == b(j - 1:j - 1) .and. a(i - 1:i - 1) == b(j:j)) then
                        d(i, j) = min(d(i, j), d(max(i - 2, 0), max(j - 2, 0)) + 1)
                    end if
                end if
            end do
        end do
        dist = d(len(a), len(b))
    end function edit_distance

    ! ------------------------------------------------------------------------------------
    ! Text helpers
    ! ------------------------------------------------------------------------------------


    !> A bound for a message: '0', '1', else as real_text.
    function bound_text(x) result(s)
        real(wp), intent(in) :: x
        character(len=:), allocatable :: s
        if (abs(x - anint(x)) <= 0.0_wp .and. abs(x) < 1.0e9_wp) then
            s = int_text(nint(x))
        else
            s = real_text(x)
        end if
    end function bound_text





    !> True if s is exactly one quoted literal ('a', "a", 'it''s').
    pure logical function is_single_literal(s) result(ok)
        character(len=*), intent(in) :: s
        character :: q
        integer :: i, p
        ok = .false.
        if (len(s) < 2) return
        q = s(1:1)
        i = 2
        do
            p = index(s(i:), q)
            if (p == 0) return
            p = p + i - 1
            if (p < len(s)) then
                if (s(p + 1:p + 1) == q) then
                    i = p + 2
                    cycle
                end if
            end if
            ok = p == len(s)
            return
        end do
    end function is_single_literal



    pure integer function first_nonblank(s) result(i)
        character(len=*), intent(in) :: s
        i = verify(s, ' '//TAB)
    end function first_nonblank

    pure integer function skip_blanks(s, start) result(i)
        character(len=*), intent(in) :: s
        integer, intent(in) :: start
        i = start
        do while (i <= len(s))
            if (s(i:i) /= ' ' .and. s(i:i) /= TAB) exit
            i = i + 1
        end do
    end function skip_blanks

    pure logical function is_letter(c)
        character, intent(in) :: c
        is_letter = (c >= 'a' .and. c <= 'z') .or. (c >= 'A' .and. c <= 'Z')
    end function is_letter

    pure logical function is_name_char(c)
        character, intent(in) :: c
        is_name_char = is_letter(c) .or. (c >= '0' .and. c <= '9') .or. c == '_'
    end function is_name_char
end module ropedyn_scene
