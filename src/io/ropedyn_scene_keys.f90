!> The key table of scene files: one entry per key with its group, name, type, rule, unit and
!! one-line meaning, bound at run time to the component of a `scene_t` that holds its value.
!! The component's default initialization is the key's default. The table drives reading
!! and type conversion (`assign`), `--set`, the per-key checks (`check`), the echo (`echo`)
!! and the listing `ropedyn keys`, which tests/e2e/test_keys.py compares with
!! docs/reference/keys.md. Checks that involve several keys are in `ropedyn_scene_checks`.
module ropedyn_scene_keys
    use ropedyn_kinds, only: wp
    use ropedyn_methods, only: method_list
    use ropedyn_scene_types, only: scene_t, solver_params_t, output_params_t
    use ropedyn_rope_spec, only: rope_params_t, model_params_t, supports_params_t, &
        initial_params_t, effects_params_t, fluid_params_t, ground_params_t, &
        attachments_params_t
    use ropedyn_scene_key, only: scene_key_t, T_REAL, T_INT, T_LOGICAL, T_NAME, T_PATH, &
        T_PAIR, T_LIST, R_NONE, R_FINITE, R_POSITIVE, R_NONNEGATIVE, R_UNIT, R_AT_LEAST, &
        R_NAMES
    use ropedyn_text, only: text_t, append_text, name_hint, int_text, printable
    use ropedyn_integrator, only: DEFAULT_MAX_STEPS, BUDGET_STEP_RATE
    use ropedyn_error, only: error_t, make_error, ERR_INPUT
    implicit none
    private
    public :: bind_keys, find_key, fail, key_hint, group_index, group_list
    public :: GROUP_NAMES, N_GROUPS, G_ROPE, G_MODEL, G_SUPPORTS, G_INITIAL, G_EFFECTS, &
        G_SOLVER, G_OUTPUT, G_FLUID, G_GROUND, G_ATTACHMENTS

    !> Groups, in the order they are read, checked and written.
    integer, parameter :: G_ROPE = 1, G_MODEL = 2, G_SUPPORTS = 3, G_INITIAL = 4, &
        G_EFFECTS = 5, G_SOLVER = 6, G_OUTPUT = 7, G_FLUID = 8, G_GROUND = 9, &
        G_ATTACHMENTS = 10, N_GROUPS = 10
    character(len=*), parameter :: GROUP_NAMES(N_GROUPS) = [character(len=11) :: &
        'rope', 'model', 'supports', 'initial', 'effects', 'solver', 'output', 'fluid', &
        'ground', 'attachments']

    character(len=*), parameter :: SUPPORTS = 'pinned, clamped, free'
    character(len=*), parameter :: NSM2 = 'N s/m^2'
    !> The "not set" texts of the two sets of &rope.
    character(len=*), parameter :: SECTION_GIVEN = 'not set: the section set is given'
    character(len=*), parameter :: SOLID_ROD = 'not set: the solid-rod set is used'

    !> The table being built: its keys (bound to a scene's components) and how many.
    type :: key_table_t
        type(scene_key_t), allocatable :: keys(:)
        integer :: n = 0
    contains
        procedure :: add, add_real, add_int, add_logical, add_name, add_path, add_pair, &
            add_list, add_motion
    end type key_table_t

contains

    !> The table, bound to the components of `scene` (which must outlive `keys`).
    subroutine bind_keys(scene, keys)
        type(scene_t), target, intent(inout) :: scene
        type(scene_key_t), allocatable, intent(out) :: keys(:)
        type(key_table_t) :: t
        integer :: k

        allocate (t%keys(120))
        call bind_rope(t, scene%rope)
        call bind_model(t, scene%model)
        call bind_supports(t, scene%supports)
        call bind_initial(t, scene%initial)
        call bind_effects(t, scene%effects)
        call bind_solver(t, scene%solver)
        call bind_output(t, scene%output)
        call bind_fluid(t, scene%fluid)
        call bind_ground(t, scene%ground)
        call bind_attachments(t, scene%attachments)
        keys = t%keys(:t%n)
        if (allocated(scene%path)) then
            do k = 1, size(keys)
                keys(k)%origin = scene%path
            end do
        end if
    end subroutine bind_keys

    !> The keys of &rope: the rope (its length; its section, a solid rod or EA, EI, m per L).
    subroutine bind_rope(t, r)
        type(key_table_t), intent(inout) :: t
        type(rope_params_t), target, intent(inout) :: r
        call t%add_real(G_ROPE, 'length', r%length, R_POSITIVE, 'm', &
            'unstretched length L of the rope')
        call t%add_real(G_ROPE, 'diameter', r%diameter, R_POSITIVE, 'm', &
            'diameter d of the circular cross-section (section set: hydrodynamic)')
        call t%add_real(G_ROPE, 'density', r%density, R_POSITIVE, 'kg/m^3', &
            'solid rod: mass density', unset=SECTION_GIVEN)
        call t%add_real(G_ROPE, 'young_modulus', r%young_modulus, R_POSITIVE, 'Pa', &
            "solid rod: Young's modulus E", unset=SECTION_GIVEN)
        call t%add_real(G_ROPE, 'shear_modulus', r%shear_modulus, R_POSITIVE, 'Pa', &
            'solid rod: shear modulus G', unset=SECTION_GIVEN)
        call t%add_real(G_ROPE, 'normal_damping', r%normal_damping, R_NONNEGATIVE, NSM2, &
            'solid rod: damping eta of the axial and bending dampers', unset=SECTION_GIVEN)
        call t%add_real(G_ROPE, 'tangential_damping', r%tangential_damping, R_NONNEGATIVE, &
            NSM2, 'solid rod: damping of the shear dampers', &
            unset='not set: eta G/E (eq. 13), or the section set is given')
        call t%add_real(G_ROPE, 'shape_factor', r%shape_factor, R_POSITIVE, '-', &
            'solid rod: shear shape factor chi (10/9 for a circle)', unset=SECTION_GIVEN)
        call t%add_real(G_ROPE, 'mass_per_length', r%mass_per_length, R_POSITIVE, 'kg/m', &
            'section set: mass per length', unset=SOLID_ROD)
        call t%add_real(G_ROPE, 'axial_stiffness', r%axial_stiffness, R_POSITIVE, 'N', &
            'section set: axial stiffness EA', unset=SOLID_ROD)
        call t%add_real(G_ROPE, 'bending_stiffness', r%bending_stiffness, R_NONNEGATIVE, &
            'N m^2', 'section set: bending stiffness EI (0: a chain)', &
            unset='not set: 0 with the section set; else the solid-rod set')
        call t%add_real(G_ROPE, 'shear_stiffness', r%shear_stiffness, R_POSITIVE, 'N', &
            'section set: shear stiffness of the RFEM joint', &
            unset='not set: axial_stiffness with the section set; else the solid-rod set')
        call t%add_real(G_ROPE, 'axial_damping', r%axial_damping, R_NONNEGATIVE, 'N s', &
            'section set: axial damping coefficient', &
            unset='not set: 0 with the section set; else the solid-rod set')
        call t%add_real(G_ROPE, 'shear_damping', r%shear_damping, R_NONNEGATIVE, 'N s', &
            'section set: shear damping coefficient', &
            unset='not set: axial_damping GA/EA with the section set; else the solid rod')
        call t%add_real(G_ROPE, 'bending_damping', r%bending_damping, R_NONNEGATIVE, &
            'N m^2 s', 'section set: bending damping coefficient', &
            unset='not set: axial_damping EI/EA with the section set; else the solid rod')
        call t%add_logical(G_ROPE, 'compression', r%compression, 'the axial springs '// &
            'push back when compressed (.false.: tension only, a chain or a cable that '// &
            'goes slack)')
        call t%add_real(G_ROPE, 'gravity', r%gravity, R_NONNEGATIVE, 'm/s^2', &
            'gravitational acceleration, along +x (down)')
    end subroutine bind_rope

    !> The keys of &model: the discretisation.
    subroutine bind_model(t, m)
        type(key_table_t), intent(inout) :: t
        type(model_params_t), target, intent(inout) :: m
        call t%add_name(G_MODEL, 'kind', m%kind, 'rfem, mpp', 'the discretisation')
        call t%add_int(G_MODEL, 'elements', m%elements, R_AT_LEAST, 2, &
            'number of elements n (mpp: members); at most a memory limit')
        call t%add_real(G_MODEL, 'mpp_axial_damping_factor', m%mpp_axial_damping_factor, &
            R_NONNEGATIVE, '-', "mpp: factor on the member springs' damping")
        call t%add_real(G_MODEL, 'mpp_bending_damping_factor', m%mpp_bending_damping_factor, &
            R_NONNEGATIVE, '-', "mpp: factor on the joints' bending damping")
    end subroutine bind_model

    !> The keys of &supports: the ends, their anchors and motions.
    subroutine bind_supports(t, s)
        type(key_table_t), intent(inout) :: t
        type(supports_params_t), target, intent(inout) :: s
        call t%add_name(G_SUPPORTS, 'top', s%top, SUPPORTS, 'support of the upper end')
        call t%add_name(G_SUPPORTS, 'bottom', s%bottom, SUPPORTS, 'support of the lower end')
        call t%add_pair(G_SUPPORTS, 'top_anchor', s%top_anchor, R_FINITE, 'm', &
            'point (x, y) the top support holds the upper end to')
        call t%add_pair(G_SUPPORTS, 'bottom_anchor', s%bottom_anchor, R_NONE, 'm', &
            'point the bottom support holds the lower end to', &
            "not set: the rope's lower end in its initial state", 'finite, both or neither')
        call t%add_real(G_SUPPORTS, 'top_angle_deg', s%top_angle_deg, R_FINITE, 'deg', &
            'clamp angle of the top support from down x')
        call t%add_real(G_SUPPORTS, 'bottom_angle_deg', s%bottom_angle_deg, R_FINITE, 'deg', &
            'clamp angle of the bottom support from down x')
        call t%add_real(G_SUPPORTS, 'support_stiffness_factor', s%support_stiffness_factor, &
            R_POSITIVE, '-', 'factor on the support springs and dampers')
        call t%add_name(G_SUPPORTS, 'end_compliance', s%end_compliance, 'added, split', &
            "a pinned end's axial compliance: 'added' (the paper's: the support's " &
            //"spring on top of the rope's, one section more), 'split' (the end section " &
            //'shared with the support: the rope is exactly as compliant as L/EA)')
        call t%add_motion('top', s%top_motion, s%top_amplitude, s%top_frequency, &
            s%top_phase_deg, s%top_angle_amplitude_deg, s%top_angle_phase_deg, &
            s%top_ramp_time, s%top_table, s%top_release_time)
        call t%add_motion('bottom', s%bottom_motion, s%bottom_amplitude, &
            s%bottom_frequency, s%bottom_phase_deg, s%bottom_angle_amplitude_deg, &
            s%bottom_angle_phase_deg, s%bottom_ramp_time, s%bottom_table, &
            s%bottom_release_time)
    end subroutine bind_supports

    !> The keys of &initial: the initial state.
    subroutine bind_initial(t, i)
        type(key_table_t), intent(inout) :: t
        type(initial_params_t), target, intent(inout) :: i
        call t%add_name(G_INITIAL, 'shape', i%shape, &
            'straight, hanging, equilibrium, mode, folded, state', 'initial shape of the rope')
        call t%add_real(G_INITIAL, 'angle_deg', i%angle_deg, R_FINITE, 'deg', &
            'angle of the straight initial rope from down x')
        call t%add_int(G_INITIAL, 'mode', i%mode, R_AT_LEAST, 1, &
            "shape 'mode': which mode (1 = lowest; at most the model's number of modes)")
        call t%add_real(G_INITIAL, 'mode_amplitude', i%mode_amplitude, R_FINITE, 'm', &
            "shape 'mode': largest displacement")
        call t%add_pair(G_INITIAL, 'velocity', i%velocity, R_FINITE, 'm/s', &
            'initial velocity (x, y) of every element (shapes straight, hanging, folded)')
        call t%add_path(G_INITIAL, 'state_file', i%state_file, &
            "shape 'state': run file (HDF5) whose record starts the run")
        call t%add_real(G_INITIAL, 'state_time', i%state_time, R_FINITE, 's', &
            "shape 'state': time of the record (nearest); < 0: the last")
    end subroutine bind_initial

    !> The keys of &effects: which effects are computed.
    subroutine bind_effects(t, e)
        type(key_table_t), intent(inout) :: t
        type(effects_params_t), target, intent(inout) :: e
        call t%add_logical(G_EFFECTS, 'gravity', e%gravity, 'the weight of the rope')
        call t%add_logical(G_EFFECTS, 'tension', e%tension, 'the axial springs')
        call t%add_logical(G_EFFECTS, 'shear', e%shear, 'the shear springs')
        call t%add_logical(G_EFFECTS, 'bending', e%bending, 'the rotational springs')
        call t%add_logical(G_EFFECTS, 'damping', e%damping, 'the dampers')
        call t%add_logical(G_EFFECTS, 'drag', e%drag, 'drag of the fluid (&fluid)')
        call t%add_logical(G_EFFECTS, 'ground', e%ground, 'contact with a ground (&ground)')
        call t%add_logical(G_EFFECTS, 'support_motion', e%support_motion, &
            'the motions and releases of &supports')
        call t%add_logical(G_EFFECTS, 'point_masses', e%point_masses, &
            'the point masses of &attachments')
        call t%add_logical(G_EFFECTS, 'point_loads', e%point_loads, &
            'the point loads of &attachments')
        call t%add_logical(G_EFFECTS, 'water', e%water, &
            'water below &fluid surface: buoyancy, added mass, drag of the wetted part')
        call t%add_real(G_EFFECTS, 'fault_nan_after', e%fault_nan_after, R_FINITE, 's', &
            'testing aid: NaN forces after this time; < 0: off')
    end subroutine bind_effects

    !> The keys of &solver: the integration.
    subroutine bind_solver(t, v)
        type(key_table_t), intent(inout) :: t
        type(solver_params_t), target, intent(inout) :: v
        call t%add_name(G_SOLVER, 'method', v%method, method_list(), 'the integrator')
        call t%add_real(G_SOLVER, 'rtol', v%rtol, R_UNIT, '-', 'relative tolerance')
        call t%add_real(G_SOLVER, 'atol', v%atol, R_POSITIVE, 'state units', &
            'absolute tolerance')
        call t%add_int(G_SOLVER, 'max_order', v%max_order, R_NONE, 0, &
            "highest order (0: the method's default)", 'the method''s range, or 0')
        call t%add_int(G_SOLVER, 'max_steps', v%max_steps, R_AT_LEAST, 0, &
            'step budget of a run (0: '//int_text(DEFAULT_MAX_STEPS)//', or '// &
            int_text(nint(BUDGET_STEP_RATE))//' per second of t_end if more; '// &
            'a resume has one of its own)')
        call t%add_real(G_SOLVER, 't_end', v%t_end, R_POSITIVE, 's', &
            'end time; at most a limit')
        call t%add_real(G_SOLVER, 'output_interval', v%output_interval, R_POSITIVE, 's', &
            'time between output records; at most a limit of records')
        call t%add_logical(G_SOLVER, 'stability_limit_detection', &
            v%stability_limit_detection, "cvode only: CVODE's stability-limit detection")
        call t%add_logical(G_SOLVER, 'first_order_newton', v%first_order_newton, &
            'Newton systems on the first-order matrix, not the reduced second-order one')
        call t%add_logical(G_SOLVER, 'profile', v%profile, &
            'time the right-hand side, Jacobian, factorizations and solves')
        call t%add_name(G_SOLVER, 'order_safety', v%order_safety, 'lower, stop, off', &
            'on an energy gain: lower the order to the A-stable one, stop, or off '// &
            '(lower and stop fail a run that creates a tenth of max(S, m g L))')
        call t%add_real(G_SOLVER, 'energy_gain_bound', v%energy_gain_bound, R_POSITIVE, &
            'rtol S', 'energy gain that counts, in units of rtol times the energy scale '// &
            '(at most S / 10)')
    end subroutine bind_solver

    !> The keys of &output: the result file.
    subroutine bind_output(t, o)
        type(key_table_t), intent(inout) :: t
        type(output_params_t), target, intent(inout) :: o
        call t%add_path(G_OUTPUT, 'file', o%file, "HDF5 result file ('': out/<scene>.h5)")
        call t%add_logical(G_OUTPUT, 'progress', o%progress, &
            'progress on stderr (not given: on when stderr is a terminal)')
        ! tri-state: not given means "on when stderr is a terminal" (progress_given)
        t%keys(t%n)%unset = 'not set: on when stderr is a terminal'
    end subroutine bind_output

    !> The keys of &fluid: the water (or air) around the rope.
    subroutine bind_fluid(t, f)
        type(key_table_t), intent(inout) :: t
        type(fluid_params_t), target, intent(inout) :: f
        call t%add_real(G_FLUID, 'density', f%density, R_NONNEGATIVE, 'kg/m^3', &
            'density of the fluid')
        call t%add_real(G_FLUID, 'normal_drag_coefficient', f%normal_drag_coefficient, &
            R_NONNEGATIVE, '-', 'C_n on d l')
        call t%add_real(G_FLUID, 'tangential_drag_coefficient', &
            f%tangential_drag_coefficient, R_NONNEGATIVE, '-', 'C_t on pi d l')
        call t%add_real(G_FLUID, 'linear_normal_drag', f%linear_normal_drag, R_NONNEGATIVE, &
            NSM2, 'linear normal drag per metre')
        call t%add_real(G_FLUID, 'linear_tangential_drag', f%linear_tangential_drag, &
            R_NONNEGATIVE, NSM2, 'linear tangential drag per metre')
        call t%add_pair(G_FLUID, 'current', f%current, R_FINITE, 'm/s', &
            'velocity (x, y) of the fluid')
        call t%add_real(G_FLUID, 'surface', f%surface, R_FINITE, 'm', &
            'water: x of the free surface (water where x > surface; x down)')
        call t%add_real(G_FLUID, 'added_mass_coefficient', f%added_mass_coefficient, &
            R_NONNEGATIVE, '-', 'water: normal added mass C_a on the displaced volume')
        call t%add_real(G_FLUID, 'tangential_added_mass_coefficient', &
            f%tangential_added_mass_coefficient, R_NONNEGATIVE, '-', &
            'water: tangential added mass on the displaced volume')
    end subroutine bind_fluid

    !> The keys of &ground: the seabed or floor.
    subroutine bind_ground(t, g)
        type(key_table_t), intent(inout) :: t
        type(ground_params_t), target, intent(inout) :: g
        call t%add_pair(G_GROUND, 'point', g%point, R_FINITE, 'm', 'a point of the plane')
        call t%add_pair(G_GROUND, 'normal', g%normal, R_NONE, '-', &
            'normal of the plane towards the free side', allowed='finite, non-zero')
        call t%add_real(G_GROUND, 'stiffness', g%stiffness, R_POSITIVE, 'N/m^2', &
            'penalty stiffness per metre of rope')
        call t%add_real(G_GROUND, 'damping', g%damping, R_NONNEGATIVE, NSM2, &
            'contact damping per metre of rope')
        call t%add_real(G_GROUND, 'friction_coefficient', g%friction_coefficient, &
            R_NONNEGATIVE, '-', 'Coulomb mu')
        call t%add_real(G_GROUND, 'friction_regularization_speed', &
            g%friction_regularization_speed, R_POSITIVE, 'm/s', 'v_reg of the friction law')
    end subroutine bind_ground

    !> The keys of &attachments: point masses and loads.
    subroutine bind_attachments(t, a)
        type(key_table_t), intent(inout) :: t
        type(attachments_params_t), target, intent(inout) :: a
        call t%add_list('mass_positions', a%mass_positions, a%mass_positions, 'm', &
            'where the point masses sit (arc length from the top)', '0 .. length')
        call t%add_list('masses', a%masses, a%mass_positions, 'kg', 'the point masses', &
            '> 0 where a position is given')
        call t%add_list('load_positions', a%load_positions, a%load_positions, 'm', &
            'where the point loads act', '0 .. length')
        call t%add_list('load_force_x', a%load_force_x, a%load_positions, 'N', &
            'constant part of each load, x')
        call t%add_list('load_force_y', a%load_force_y, a%load_positions, 'N', &
            'constant part of each load, y')
        call t%add_list('load_amplitude_x', a%load_amplitude_x, a%load_positions, 'N', &
            'harmonic part of each load, x')
        call t%add_list('load_amplitude_y', a%load_amplitude_y, a%load_positions, 'N', &
            'harmonic part of each load, y')
        call t%add_list('load_frequency', a%load_frequency, a%load_positions, 'Hz', &
            'frequency of the harmonic part', '>= 0')
        call t%add_list('load_phase_deg', a%load_phase_deg, a%load_positions, 'deg', &
            'phase of the harmonic part')
    end subroutine bind_attachments

    !> A key of the table with no value bound yet (the add_* bind one of its type).
    subroutine add(t, group, name, type, rule, unit, doc)
        class(key_table_t), intent(inout) :: t
        integer, intent(in) :: group, type, rule
        character(len=*), intent(in) :: name, unit, doc
        t%n = t%n + 1
        t%keys(t%n) = scene_key_t(group=group, name=name, type=type, rule=rule, unit=unit, &
            doc=doc, allowed='', unset='')
    end subroutine add

    subroutine add_real(t, group, name, x, rule, unit, doc, unset)
        class(key_table_t), intent(inout) :: t
        integer, intent(in) :: group, rule
        character(len=*), intent(in) :: name, unit, doc
        real(wp), target, intent(inout) :: x
        character(len=*), intent(in), optional :: unset  !< a NaN default means this
        call t%add(group, name, T_REAL, rule, unit, doc)
        t%keys(t%n)%r => x
        if (present(unset)) t%keys(t%n)%unset = unset
    end subroutine add_real

    subroutine add_int(t, group, name, x, rule, lowest, doc, allowed)
        class(key_table_t), intent(inout) :: t
        integer, intent(in) :: group, rule, lowest
        character(len=*), intent(in) :: name, doc
        integer, target, intent(inout) :: x
        character(len=*), intent(in), optional :: allowed
        call t%add(group, name, T_INT, rule, '-', doc)
        t%keys(t%n)%i => x
        t%keys(t%n)%lowest = lowest
        if (present(allowed)) t%keys(t%n)%allowed = allowed
    end subroutine add_int

    subroutine add_logical(t, group, name, x, doc)
        class(key_table_t), intent(inout) :: t
        integer, intent(in) :: group
        character(len=*), intent(in) :: name, doc
        logical, target, intent(inout) :: x
        call t%add(group, name, T_LOGICAL, R_NONE, '-', doc)
        t%keys(t%n)%l => x
    end subroutine add_logical

    subroutine add_name(t, group, name, x, allowed, doc)
        class(key_table_t), intent(inout) :: t
        integer, intent(in) :: group
        character(len=*), intent(in) :: name, allowed, doc
        character(len=*), target, intent(inout) :: x
        call t%add(group, name, T_NAME, R_NAMES, '-', doc)
        t%keys(t%n)%s => x
        t%keys(t%n)%allowed = allowed
    end subroutine add_name

    subroutine add_path(t, group, name, x, doc)
        class(key_table_t), intent(inout) :: t
        integer, intent(in) :: group
        character(len=*), intent(in) :: name, doc
        character(len=*), target, intent(inout) :: x
        call t%add(group, name, T_PATH, R_NONE, '-', doc)
        t%keys(t%n)%s => x
    end subroutine add_path

    subroutine add_pair(t, group, name, x, rule, unit, doc, unset, allowed)
        class(key_table_t), intent(inout) :: t
        integer, intent(in) :: group, rule
        character(len=*), intent(in) :: name, unit, doc
        real(wp), target, intent(inout) :: x(:)
        character(len=*), intent(in), optional :: unset, allowed
        call t%add(group, name, T_PAIR, rule, unit, doc)
        t%keys(t%n)%v => x
        if (present(unset)) t%keys(t%n)%unset = unset
        if (present(allowed)) t%keys(t%n)%allowed = allowed
    end subroutine add_pair

    subroutine add_list(t, name, x, used, unit, doc, allowed)
        class(key_table_t), intent(inout) :: t
        character(len=*), intent(in) :: name, unit, doc
        real(wp), target, intent(inout) :: x(:), used(:)
        character(len=*), intent(in), optional :: allowed
        call t%add(G_ATTACHMENTS, name, T_LIST, R_NONE, unit, doc)
        t%keys(t%n)%v => x
        t%keys(t%n)%used => used
        t%keys(t%n)%allowed = 'finite'
        if (present(allowed)) t%keys(t%n)%allowed = allowed
    end subroutine add_list

    !> The motion and release keys of one support, 'top' or 'bottom'.
    subroutine add_motion(t, end, motion, amplitude, frequency, phase_deg, &
            angle_amplitude_deg, angle_phase_deg, ramp_time, table, release_time)
        class(key_table_t), intent(inout) :: t
        character(len=*), intent(in) :: end
        character(len=*), target, intent(inout) :: motion, table
        real(wp), target, intent(inout) :: amplitude(:), frequency, phase_deg(:), &
            angle_amplitude_deg, angle_phase_deg, ramp_time, release_time
        call t%add_name(G_SUPPORTS, end//'_motion', motion, 'fixed, harmonic, table, coupled', &
            'prescribed motion of the '//end//' support (coupled: driven through the '// &
            'library, at rest otherwise)')
        call t%add_pair(G_SUPPORTS, end//'_amplitude', amplitude, R_FINITE, 'm', &
            'harmonic: amplitudes (x, y) of the anchor')
        call t%add_real(G_SUPPORTS, end//'_frequency', frequency, R_NONNEGATIVE, 'Hz', &
            'harmonic: frequency (> 0 for harmonic)')
        call t%add_pair(G_SUPPORTS, end//'_phase_deg', phase_deg, R_FINITE, 'deg', &
            'harmonic: phases (x, y)')
        call t%add_real(G_SUPPORTS, end//'_angle_amplitude_deg', angle_amplitude_deg, &
            R_FINITE, 'deg', 'harmonic: amplitude of the clamp angle (clamped only)')
        call t%add_real(G_SUPPORTS, end//'_angle_phase_deg', angle_phase_deg, R_FINITE, &
            'deg', 'harmonic: phase of the clamp angle')
        call t%add_real(G_SUPPORTS, end//'_ramp_time', ramp_time, R_NONNEGATIVE, 's', &
            'harmonic: time over which the amplitudes grow from 0 to full (smoothstep '// &
            '10u^3 - 15u^4 + 6u^5); 0: no ramp')
        call t%add_path(G_SUPPORTS, end//'_table', table, &
            'table: file of rows t dx dy dangle_deg (relative to the scene file)')
        call t%add_real(G_SUPPORTS, end//'_release_time', release_time, R_FINITE, 's', &
            'time at which the support lets go; < 0: never')
    end subroutine add_motion

    !> Index of key `name` (lower case, no index) of group g in `keys`, 0 if there is none.
    pure integer function find_key(keys, g, name) result(k)
        type(scene_key_t), intent(in) :: keys(:)
        integer, intent(in) :: g
        character(len=*), intent(in) :: name
        do k = 1, size(keys)
            if (keys(k)%group == g .and. keys(k)%name == name) return
        end do
        k = 0
    end function find_key

    !> The error of a key whose value is wrong: 'origin: &group: key = value: reason', the
    !! origin being the file or the last `--set` of the key. `key` may carry an index.
    !! `also` ('group.key'): a second key the error is about (a limit of the two together);
    !! when the value of `key` is not from a --set and that of `also` is, that --set is the
    !! origin: the error names the argument that made the scene wrong.
    subroutine fail(keys, g, key, value, reason, err, also)
        type(scene_key_t), intent(in) :: keys(:)
        integer, intent(in) :: g
        character(len=*), intent(in) :: key, value, reason
        type(error_t), allocatable, intent(out) :: err
        character(len=*), intent(in), optional :: also
        character(len=:), allocatable :: origin
        integer :: k, paren, dot, ka
        paren = index(key, '(')
        if (paren == 0) paren = len(key) + 1
        k = max(find_key(keys, g, key(:paren - 1)), 1)
        origin = keys(k)%origin
        if (present(also)) then
            dot = max(index(also, '.'), 1)
            ka = find_key(keys, group_index(also(:dot - 1)), also(dot + 1:))
            if (ka > 0 .and. index(origin, '--set ') /= 1) then
                if (index(keys(ka)%origin, '--set ') == 1) origin = keys(ka)%origin
            end if
        end if
        call make_error(err, ERR_INPUT, origin//': &'//trim(GROUP_NAMES(g))//': ' &
            //key//' = '//printable(value)//': '//reason)
    end subroutine fail

    pure integer function group_index(name) result(g)
        character(len=*), intent(in) :: name
        do g = 1, N_GROUPS
            if (GROUP_NAMES(g) == name) return
        end do
        g = 0
    end function group_index

    pure function group_list() result(list)
        character(len=:), allocatable :: list
        integer :: g
        list = trim(GROUP_NAMES(1))
        do g = 2, N_GROUPS
            list = list//', '//trim(GROUP_NAMES(g))
        end do
    end function group_list

    !> '; did you mean "x"?' for a near miss, else the list of keys of the group.
    function key_hint(keys, g, key) result(text)
        type(scene_key_t), intent(in) :: keys(:)
        integer, intent(in) :: g
        character(len=*), intent(in) :: key
        character(len=:), allocatable :: text
        type(text_t), allocatable :: names(:)
        integer :: k
        allocate (names(0))
        do k = 1, size(keys)
            if (keys(k)%group == g) call append_text(names, keys(k)%name)
        end do
        text = name_hint(names, key)
    end function key_hint
end module ropedyn_scene_keys
