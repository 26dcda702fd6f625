!> The rope models' parameters: material and geometry of the rope, the discretisation,
!! supports and their motion, the initial state, the effects switched on and their data.
!! Every model (RFEM, MPP) is built from a `rope_spec_t` alone; the scene file is one way to
!! fill it (src/io, whose key table names each component once, with its rule and units).
!! The defaults here are the paper's rope (docs/theory/rfem.md, Table 1).
module ropedyn_rope_spec
    use, intrinsic :: ieee_arithmetic, only: ieee_is_nan
    use ropedyn_kinds, only: wp, i8
    use ropedyn_text, only: text_t
    implicit none
    private
    public :: rope_params_t, model_params_t, supports_params_t, initial_params_t
    public :: effects_params_t, fluid_params_t, ground_params_t, attachments_params_t
    public :: rope_spec_t, bottom_anchor_given, release_time, released_at_start, NOT_SET
    public :: NAME_LEN, PATH_LEN, N_ATTACH

    integer, parameter :: NAME_LEN = 16    !< length of the kind/method/support/shape names
    integer, parameter :: PATH_LEN = 512   !< length of file names
    integer, parameter :: N_ATTACH = 8     !< point masses and point loads at most

    !> A quiet NaN: the value of `bottom_anchor` when it is not given.
    real(wp), parameter :: NOT_SET = transfer(9221120237041090560_i8, 1.0_wp)

    !> `&rope`: the rope's length and section, given by one of two sets (defaults: the
    !! paper's rope). The solid-rod set: density, young_modulus, shear_modulus,
    !! normal_damping, tangential_damping, shape_factor of a solid round rod of `diameter`.
    !! The section set, as engineers give a line: mass_per_length, axial_stiffness (EA),
    !! bending_stiffness (EI), shear_stiffness (of the RFEM joint), axial_damping,
    !! shear_damping, bending_damping; `diameter` is then the hydrodynamic diameter. A value
    !! not set is NaN; ropedyn_rope_section resolves the derived defaults of either set.
    type :: rope_params_t
        real(wp) :: length = 1.0_wp             !< rope length [m]
        real(wp) :: density = 6000.0_wp         !< mass density [kg/m^3]
        !> diameter of the circular cross-section [m] (the section set: of the displaced
        !! volume, for buoyancy, drag and added mass)
        real(wp) :: diameter = 0.005_wp
        real(wp) :: young_modulus = 35.0e6_wp   !< Young's modulus E [Pa]
        real(wp) :: shear_modulus = 14.0e6_wp   !< shear modulus G [Pa]
        real(wp) :: normal_damping = 1.0e3_wp   !< eta [N s/m^2]
        !> eta_bar [N s/m^2]; not set (NaN): normal_damping*shear_modulus/young_modulus,
        !! resolved by the scene reader
        real(wp) :: tangential_damping = NOT_SET
        real(wp) :: shape_factor = 10.0_wp/9.0_wp  !< shear shape factor chi [-]
        real(wp) :: gravity = 9.81_wp           !< gravitational acceleration [m/s^2]
        ! the section set (NaN: not given)
        real(wp) :: mass_per_length = NOT_SET    !< [kg/m]
        real(wp) :: axial_stiffness = NOT_SET    !< EA [N]
        real(wp) :: bending_stiffness = NOT_SET  !< EI [N m^2]; not set: 0
        real(wp) :: shear_stiffness = NOT_SET    !< of the RFEM joint [N]; not set: EA
        real(wp) :: axial_damping = NOT_SET      !< [N s]; not set: 0
        !> [N s]; not set: axial_damping times shear_stiffness/axial_stiffness
        real(wp) :: shear_damping = NOT_SET
        !> [N m^2 s]; not set: axial_damping times bending_stiffness/axial_stiffness
        real(wp) :: bending_damping = NOT_SET
        !> the axial springs push back when compressed; .false.: they carry tension only,
        !! as a chain or a cable that goes slack
        logical :: compression = .true.
    end type rope_params_t

    !> `&model`: which discretisation and how fine.
    type :: model_params_t
        character(len=NAME_LEN) :: kind = 'rfem'  !< 'rfem' | 'mpp'
        integer :: elements = 30                  !< number of elements (mpp: members) [-]
        !> mpp: factor on the member springs' damping eta A / l (the default rule) [-]
        real(wp) :: mpp_axial_damping_factor = 1.0_wp
        !> mpp: factor on the joints' bending damping eta I / l (the default rule) [-]
        real(wp) :: mpp_bending_damping_factor = 1.0_wp
    end type model_params_t

    !> `&supports`: boundary conditions at both ends (x down, y horizontal).
    type :: supports_params_t
        character(len=NAME_LEN) :: top = 'pinned'    !< 'pinned' | 'clamped' | 'free'
        character(len=NAME_LEN) :: bottom = 'free'   !< 'pinned' | 'clamped' | 'free'
        real(wp) :: top_anchor(2) = [0.0_wp, 0.0_wp] !< top anchor point (x, y) [m]
        !> bottom anchor point (x, y) [m]; NaN when not given: the rope's lower end in its
        !! initial state, resolved by the model (see `bottom_anchor_given`)
        real(wp) :: bottom_anchor(2) = [NOT_SET, NOT_SET]
        logical :: bottom_anchor_set = .false.       !< bottom_anchor was given
        real(wp) :: top_angle_deg = 0.0_wp           !< top clamp angle from down x [deg]
        real(wp) :: bottom_angle_deg = 0.0_wp        !< bottom clamp angle from down x [deg]
        real(wp) :: support_stiffness_factor = 1.0_wp  !< support springs/dampers factor [-]
        !> 'added' (the paper's RFEM: a pinned support's spring adds one section's axial
        !! compliance to the rope's L/EA) | 'split' (the end section shared between the
        !! support and its neighbour, each at twice the section's stiffness: exactly L/EA)
        character(len=NAME_LEN) :: end_compliance = 'added'
        !> prescribed motion of each support: 'fixed' | 'harmonic' | 'table' | 'coupled'
        !! (driven through the library; at rest otherwise)
        character(len=NAME_LEN) :: top_motion = 'fixed'
        character(len=NAME_LEN) :: bottom_motion = 'fixed'
        real(wp) :: top_amplitude(2) = 0.0_wp           !< harmonic amplitudes (x, y) [m]
        real(wp) :: bottom_amplitude(2) = 0.0_wp
        real(wp) :: top_frequency = 0.0_wp              !< harmonic frequency [Hz]
        real(wp) :: bottom_frequency = 0.0_wp
        real(wp) :: top_phase_deg(2) = 0.0_wp           !< harmonic phases (x, y) [deg]
        real(wp) :: bottom_phase_deg(2) = 0.0_wp
        real(wp) :: top_angle_amplitude_deg = 0.0_wp    !< harmonic clamp rotation [deg]
        real(wp) :: bottom_angle_amplitude_deg = 0.0_wp
        real(wp) :: top_angle_phase_deg = 0.0_wp        !< its phase [deg]
        real(wp) :: bottom_angle_phase_deg = 0.0_wp
        !> harmonic: the amplitudes grow from 0 to 1 over this time [s]; 0: no ramp
        real(wp) :: top_ramp_time = 0.0_wp
        real(wp) :: bottom_ramp_time = 0.0_wp
        !> motion table files (rows t, dx, dy, dangle_deg); resolved by `read_scene` against
        !! the scene file's directory
        character(len=PATH_LEN) :: top_table = ''
        character(len=PATH_LEN) :: bottom_table = ''
        real(wp) :: top_release_time = -1.0_wp          !< release time [s]; < 0: never
        real(wp) :: bottom_release_time = -1.0_wp
        !> the tables as read by `read_scene`, (4, rows): t [s], dx, dy [m], dangle [rad]
        real(wp), allocatable :: top_table_rows(:, :), bottom_table_rows(:, :)
    end type supports_params_t

    !> `&initial`: initial state of the rope.
    type :: initial_params_t
        !> 'straight' | 'hanging' | 'equilibrium' (static equilibrium, at rest) | 'mode'
        !! (equilibrium plus mode `mode` with largest point displacement `mode_amplitude`)
        !! | 'folded' | 'state' (a record of an earlier run's file: `state_file`, `state_time`)
        character(len=NAME_LEN) :: shape = 'straight'
        real(wp) :: angle_deg = 75.0_wp   !< angle of the straight rope from down x [deg]
        integer :: mode = 1                      !< shape 'mode': which mode (1 = lowest) [-]
        real(wp) :: mode_amplitude = 0.01_wp     !< shape 'mode': largest displacement [m]
        !> shape 'folded': the rope doubled up from its top anchor (both ends there)
        real(wp) :: velocity(2) = 0.0_wp  !< initial velocity of every element (x, y) [m/s]
        !> shape 'state': the run file (HDF5) whose record starts this run
        character(len=PATH_LEN) :: state_file = ''
        !> shape 'state': time of that record [s] (the nearest record); < 0: the last one
        real(wp) :: state_time = -1.0_wp
    end type initial_params_t

    !> `&effects`: switches for the physical effects.
    type :: effects_params_t
        logical :: gravity = .true.   !< gravity load
        logical :: tension = .true.   !< axial springs Cx = EA/dl
        logical :: shear = .true.     !< shear springs Cy = GA/(chi dl)
        logical :: bending = .true.   !< rotational springs Cphi = EI/dl
        logical :: damping = .true.   !< dampers Bx, By, Bphi
        logical :: drag = .false.     !< fluid drag (&fluid)
        logical :: ground = .false.   !< ground contact (&ground)
        logical :: support_motion = .true.  !< the motions and releases given in &supports
        logical :: point_masses = .true.    !< the point masses given in &attachments
        logical :: point_loads = .true.     !< the point loads given in &attachments
        !> water below a free surface (&fluid surface): buoyancy, added mass, drag of the
        !! wetted part
        logical :: water = .false.
        !> testing aid: NaN forces on every body for t > this time, s; < 0: off
        !! (ropedyn_effect_fault)
        real(wp) :: fault_nan_after = -1.0_wp
    end type effects_params_t

    !> `&fluid`: the surrounding fluid (used with `&effects drag = .true.` and `water`).
    type :: fluid_params_t
        real(wp) :: density = 1.225_wp                     !< rho_f [kg/m^3] (air)
        real(wp) :: normal_drag_coefficient = 1.2_wp       !< C_n on d l [-]
        real(wp) :: tangential_drag_coefficient = 0.02_wp  !< C_t on pi d l [-]
        real(wp) :: linear_normal_drag = 0.0_wp            !< [N s/m^2]
        real(wp) :: linear_tangential_drag = 0.0_wp        !< [N s/m^2]
        real(wp) :: current(2) = 0.0_wp                    !< fluid velocity (x, y) [m/s]
        !> with water: x of the free surface (the water where x > surface; x points down) [m]
        real(wp) :: surface = 0.0_wp
        !> with water: normal added mass C_a, on the displaced volume pi d^2/4 per metre [-]
        real(wp) :: added_mass_coefficient = 1.0_wp
        !> with water: tangential added mass, on the displaced volume [-]
        real(wp) :: tangential_added_mass_coefficient = 0.0_wp
    end type fluid_params_t

    !> `&ground`: a ground plane (used with `&effects ground = .true.`).
    type :: ground_params_t
        real(wp) :: point(2) = [1.0_wp, 0.0_wp]    !< a point of the plane (x, y) [m]
        real(wp) :: normal(2) = [-1.0_wp, 0.0_wp]  !< normal to the free side (up) [-]
        real(wp) :: stiffness = 1.0e5_wp           !< per metre of rope [N/m^2]
        real(wp) :: damping = 100.0_wp             !< per metre of rope [N s/m^2]
        real(wp) :: friction_coefficient = 0.5_wp  !< Coulomb mu [-]
        real(wp) :: friction_regularization_speed = 1.0e-3_wp  !< v_reg [m/s]
    end type ground_params_t

    !> `&attachments`: point masses and point loads; an entry is used when its position is
    !! given (NaN: not given). Positions are arc lengths from the top end [m].
    type :: attachments_params_t
        real(wp) :: mass_positions(N_ATTACH) = NOT_SET  !< [m]
        real(wp) :: masses(N_ATTACH) = 0.0_wp           !< [kg]
        real(wp) :: load_positions(N_ATTACH) = NOT_SET  !< [m]
        real(wp) :: load_force_x(N_ATTACH) = 0.0_wp     !< constant part [N]
        real(wp) :: load_force_y(N_ATTACH) = 0.0_wp     !< [N]
        real(wp) :: load_amplitude_x(N_ATTACH) = 0.0_wp !< harmonic part [N]
        real(wp) :: load_amplitude_y(N_ATTACH) = 0.0_wp !< [N]
        real(wp) :: load_frequency(N_ATTACH) = 0.0_wp   !< [Hz]
        real(wp) :: load_phase_deg(N_ATTACH) = 0.0_wp   !< [deg]
    end type attachments_params_t

    !> Everything a rope model is built from.
    type :: rope_spec_t
        character(len=:), allocatable :: path  !< where the values came from (for messages)
        !> the keys a --set gave ('group.key') and the --set argument of each, for messages
        !! about their values (origin); the other keys come from `path`
        type(text_t), allocatable :: set_keys(:), set_origins(:)
        type(rope_params_t) :: rope
        type(model_params_t) :: model
        type(supports_params_t) :: supports
        type(initial_params_t) :: initial
        type(effects_params_t) :: effects
        type(fluid_params_t) :: fluid
        type(ground_params_t) :: ground
        type(attachments_params_t) :: attachments
    contains
        procedure :: origin => spec_origin
    end type rope_spec_t

contains

    !> True when `bottom_anchor` was given (otherwise the model places it at the rope's
    !! lower end in its initial state).
    pure logical function bottom_anchor_given(spec)
        class(rope_spec_t), intent(in) :: spec
        bottom_anchor_given = .not. any(ieee_is_nan(spec%supports%bottom_anchor))
    end function bottom_anchor_given

    !> Where the value of `key` ('group.key') came from, for a message about it: the --set
    !! argument that gave it, else the scene's path.
    pure function spec_origin(self, key) result(origin)
        class(rope_spec_t), intent(in) :: self
        character(len=*), intent(in) :: key
        character(len=:), allocatable :: origin
        integer :: k
        origin = ''
        if (allocated(self%path)) origin = self%path
        if (.not. allocated(self%set_keys)) return
        do k = size(self%set_keys), 1, -1
            if (self%set_keys(k)%s == key) then
                origin = self%set_origins(k)%s
                return
            end if
        end do
    end function spec_origin

    !> When the support at `end` (1: top, 2: bottom) lets the rope go [s]: its
    !! `*_release_time` when one is given (>= 0) and the support motions are on, else
    !! huge (never).
    pure real(wp) function release_time(spec, end)
        class(rope_spec_t), intent(in) :: spec
        integer, intent(in) :: end
        real(wp) :: given
        release_time = huge(1.0_wp)
        if (.not. spec%effects%support_motion) return
        given = merge(spec%supports%top_release_time, spec%supports%bottom_release_time, &
                      end == 1)
        if (given >= 0.0_wp) release_time = given
    end function release_time

    !> True when the support at `end` (1: top, 2: bottom) is released at t = 0: the end is
    !! free from the start, whatever its kind.
    pure logical function released_at_start(spec, end)
        class(rope_spec_t), intent(in) :: spec
        integer, intent(in) :: end
        released_at_start = .not. release_time(spec, end) > 0.0_wp
    end function released_at_start
end module ropedyn_rope_spec
