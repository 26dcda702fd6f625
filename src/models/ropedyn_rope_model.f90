!> What every rope model offers beyond the generic problem: its energies, element data for
!! output, the initial state of its spec, the mapping from the ODE state to element
!! fields and to the polyline used for drawing, and the internal forces and support
!! reactions of a state (from the force laws of its right-hand side; definitions in
!! docs/theory/internal-forces.md).
module ropedyn_rope_model
    use ropedyn_kinds, only: wp
    use ropedyn_problem, only: problem_t
    use ropedyn_support_motion, only: support_motion_t
    implicit none
    private
    public :: rope_model_t, energy_t

    !> Energy bookkeeping of a state, all in J.
    type :: energy_t
        real(wp) :: kinetic = 0.0_wp       !< T
        real(wp) :: elastic = 0.0_wp       !< springs (internal and supports), effects
        !> the part of `elastic` whose zero is arbitrary, a potential of the bodies' level as
        !! gravity's is (in water, the buoyancy's): the energy monitor counts its range, not
        !! its value (docs/theory/energy-balance.md)
        real(wp) :: level = 0.0_wp
        real(wp) :: gravity = 0.0_wp       !< -sum m g x
        real(wp) :: dissipated = 0.0_wp    !< integral of the dissipation power so far
        !> external work done on the rope so far: moving supports, point loads, a current
        real(wp) :: support_work = 0.0_wp
    contains
        procedure :: total => energy_total
        procedure :: balance => energy_balance
    end type energy_t

    type, abstract, extends(problem_t) :: rope_model_t
        integer :: n = 0                   !< number of elements (RFEM) or members (MPP)
        logical :: with_work = .false.     !< external work is quadrature 2
        !> statics and modes: every support rests where its motion puts it at the time of
        !! a call, with zero velocity and acceleration (a static force never depends on
        !! them); set by ropedyn_statics_terms around its evaluations, .false. in a run
        logical :: supports_at_rest = .false.
        !> the axial springs carry tension only (&rope compression = .false.; set by the
        !! model's constructor). Not in statics and modes (supports_at_rest): there they
        !! keep the linear law, which a line hanging in tension shares with it
        logical :: tension_only = .false.
        !> the supports (1 top, 2 bottom): their prescribed motions (anchors and angles at
        !! rest in p0, angle0) and whether they move; set by the model's constructor (a
        !! driver changes only a coupled motion's curve: support_motion_t%couple)
        type(support_motion_t) :: motion(2)
        logical :: moving(2) = .false.
    contains
        procedure(energy_i), deferred :: energy
        procedure :: n_elements => rope_n_elements, quad_size => rope_quad_size
        procedure(model_name_i), deferred :: model_name
        procedure(initial_state_i), deferred :: initial_state
        procedure(fields_i), deferred :: fields
        procedure(polyline_i), deferred :: polyline
        procedure(element_data_i), deferred :: element_data
        procedure(internal_forces_i), deferred :: internal_forces
        procedure(support_positions_i), deferred :: support_positions
        procedure(coordinates_i), deferred :: coordinates
        procedure(coordinate_mass_i), deferred :: coordinate_mass
        procedure :: mass_bandwidth => rope_mass_bandwidth
        procedure :: coordinate_mass_band => rope_coordinate_mass_band
        procedure :: angle_coordinates => rope_angle_coordinates
        procedure :: displace => rope_displace
        procedure :: has_second_order => rope_has_second_order, &
                     second_order_layout => rope_second_order_layout
        procedure :: state_from_fields => rope_state_from_fields
        procedure :: spring_stretch => rope_spring_stretch, spring_slope => rope_spring_slope, &
                     stretch_floor => rope_stretch_floor
    end type rope_model_t

    abstract interface
        !> Energies of state y at time t with quadrature values yq.
        function energy_i(self, t, y, yq) result(e)
            import :: rope_model_t, wp, energy_t
            class(rope_model_t), intent(inout) :: self
            real(wp), intent(in) :: t
            real(wp), intent(in) :: y(:)
            real(wp), intent(in) :: yq(:)
            type(energy_t) :: e
        end function energy_i

        !> Number of bodies (rigid elements or pendulum members).
        !> 'rfem' or 'mpp'.
        pure function model_name_i(self) result(name)
            import :: rope_model_t
            class(rope_model_t), intent(in) :: self
            character(len=:), allocatable :: name
        end function model_name_i

        !> The ODE state of the spec's initial configuration.
        subroutine initial_state_i(self, y)
            import :: rope_model_t, wp
            class(rope_model_t), intent(in) :: self
            real(wp), intent(out) :: y(:)
        end subroutine initial_state_i

        !> Element centre x, y (m), angle phi (rad) and their rates, shape (3, elements), at
        !! time t (s, default 0: a model with a moving support needs it).
        subroutine fields_i(self, y, q, qdot, t)
            import :: rope_model_t, wp
            class(rope_model_t), intent(in) :: self
            real(wp), intent(in) :: y(:)
            real(wp), intent(out) :: q(:, :), qdot(:, :)
            real(wp), intent(in), optional :: t
        end subroutine fields_i

        !> End points A_1, B_1, A_2, B_2, ... of the elements, shape (2, 2*elements), m, at
        !! time t (s, default 0).
        subroutine polyline_i(self, y, points, t)
            import :: rope_model_t, wp
            class(rope_model_t), intent(in) :: self
            real(wp), intent(in) :: y(:)
            real(wp), intent(out) :: points(:, :)
            real(wp), intent(in), optional :: t
        end subroutine polyline_i

        !> Length (m) and mass (kg) of each element.
        subroutine element_data_i(self, length, mass)
            import :: rope_model_t, wp
            class(rope_model_t), intent(in) :: self
            real(wp), intent(out) :: length(:), mass(:)
        end subroutine element_data_i

        !> The internal forces of state y at time t, from the same force laws as the
        !! right-hand side (damping included): at every joint j = 0 .. n (0 the top end, n
        !! the bottom end) the axial force (tension > 0, N), the shear force (N) and the
        !! bending moment (N m) that the part of the rope below the joint exerts on the
        !! part above it (at the ends: the rope on the support, the support on the rope),
        !! axial and shear in a frame the model names; and the force of each support on
        !! the rope, reaction(:, 1) the top's, reaction(:, 2) the bottom's (x, y, N; zero
        !! for a free or released end). NaN where the state has no finite forces.
        subroutine internal_forces_i(self, t, y, axial, shear, moment, reaction)
            import :: rope_model_t, wp
            class(rope_model_t), intent(inout) :: self
            real(wp), intent(in) :: t
            real(wp), intent(in) :: y(:)
            real(wp), intent(out) :: axial(0:), shear(0:), moment(0:)  !< (0:n)
            real(wp), intent(out) :: reaction(:, :)                    !< (2, 2)
        end subroutine internal_forces_i

        !> The anchors of the supports at time t from their prescribed motions (fixed ones:
        !! where they are), positions(:, 1) the top's, positions(:, 2) the bottom's (x, y,
        !! m); NaN for a free end (no anchor).
        subroutine support_positions_i(self, t, positions)
            import :: rope_model_t, wp
            class(rope_model_t), intent(in) :: self
            real(wp), intent(in) :: t
            real(wp), intent(out) :: positions(:, :)
        end subroutine support_positions_i

        !> Generalized coordinates in the ODE state (statics and modes, ropedyn_statics):
        !! y(pos(k)) is coordinate k, y(vel(k)) its rate and ydot(vel(k)) its acceleration.
        pure subroutine coordinates_i(self, pos, vel)
            import :: rope_model_t
            class(rope_model_t), intent(in) :: self
            integer, allocatable, intent(out) :: pos(:), vel(:)
        end subroutine coordinates_i

        !> Mass matrix of the generalized coordinates at state y (kinetic energy
        !! T = qdot^T mm qdot / 2), dense, shape (size(pos), size(pos)), kg, kg m, kg m^2.
        subroutine coordinate_mass_i(self, y, mm)
            import :: rope_model_t, wp
            class(rope_model_t), intent(in) :: self
            real(wp), intent(in) :: y(:)
            real(wp), intent(out) :: mm(:, :)
        end subroutine coordinate_mass_i
    end interface
contains

    pure integer function rope_n_elements(self)
        class(rope_model_t), intent(in) :: self
        rope_n_elements = self%n
    end function rope_n_elements

    !> 1: the dissipated energy; 2 (when supports move or effects do work): external work.
    pure integer function rope_quad_size(self)
        class(rope_model_t), intent(in) :: self
        rope_quad_size = merge(2, 1, self%with_work)
    end function rope_quad_size

    !> Every rope model is mechanical: coordinates and their rates, q' = v.
    pure logical function rope_has_second_order(self) result(has)
        class(rope_model_t), intent(in) :: self
        has = .true.
    end function rope_has_second_order

    !> The generalized coordinates (`coordinates`); the reduced blocks are dense unless a
    !! model knows better.
    pure subroutine rope_second_order_layout(self, pos, vel, kl, ku)
        class(rope_model_t), intent(in) :: self
        integer, allocatable, intent(out) :: pos(:), vel(:)
        integer, intent(out) :: kl, ku
        call self%coordinates(pos, vel)
        kl = size(pos) - 1
        ku = kl
    end subroutine rope_second_order_layout

    !> The ODE state y whose element fields (`fields`) at time t are q, qdot: the inverse of
    !! `fields`, to start a run from a stored record (`&initial shape = 'state'`). `ok` is
    !! .false. for a model that cannot do it (the default).
    pure subroutine rope_state_from_fields(self, q, qdot, t, y, ok)
        class(rope_model_t), intent(in) :: self
        real(wp), intent(in) :: q(:, :), qdot(:, :)  !< (3, elements): x, y, phi and rates
        real(wp), intent(in) :: t                    !< s
        real(wp), intent(out) :: y(:)
        logical, intent(out) :: ok
        y = 0.0_wp
        ok = .false.
    end subroutine rope_state_from_fields

    !> The bandwidth kd of `coordinate_mass` (M_ij = 0 for |i - j| > kd). The default: dense.
    pure integer function rope_mass_bandwidth(self) result(kd)
        class(rope_model_t), intent(in) :: self
        integer, allocatable :: pos(:), vel(:)
        call self%coordinates(pos, vel)
        kd = max(0, size(pos) - 1)
    end function rope_mass_bandwidth

    !> `coordinate_mass` as its lower band, mb(i - j, j) = M_ij for 0 <= i - j <= kd,
    !! mb(0:kd, size(pos)) with kd = `mass_bandwidth`. The default: from the dense matrix.
    subroutine rope_coordinate_mass_band(self, y, mb)
        class(rope_model_t), intent(in) :: self
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: mb(0:, :)
        real(wp), allocatable :: mm(:, :)
        integer :: i, j, n
        n = size(mb, 2)
        allocate (mm(n, n))
        call self%coordinate_mass(y, mm)
        mb = 0.0_wp
        do j = 1, n
            do i = j, min(n, j + ubound(mb, 1))
                mb(i - j, j) = mm(i, j)
            end do
        end do
    end subroutine rope_coordinate_mass_band

    !> Which generalized coordinates are angles (rad, the state repeats every 2 pi in each),
    !! in the order of `coordinates`. The default: none.
    pure function rope_angle_coordinates(self) result(angle)
        class(rope_model_t), intent(in) :: self
        logical, allocatable :: angle(:)
        integer, allocatable :: pos(:), vel(:)
        call self%coordinates(pos, vel)
        allocate (angle(size(pos)))
        angle = .false.
    end function rope_angle_coordinates

    !> The state y moved by delta in its generalized coordinates (the order of
    !! `coordinates`), as an iteration on the configuration steps (statics): any update equal
    !! to y + delta to first order in delta. The default: y + delta.
    pure subroutine rope_displace(self, y, delta, y_new)
        class(rope_model_t), intent(in) :: self
        real(wp), intent(in) :: y(:), delta(:)
        real(wp), intent(out) :: y_new(:)
        integer, allocatable :: pos(:), vel(:)
        call self%coordinates(pos, vel)
        y_new = y
        y_new(pos) = y(pos) + delta
    end subroutine rope_displace

    !> T + V (kinetic + elastic + gravity), J.
    pure real(wp) function energy_total(self) result(e)
        class(energy_t), intent(in) :: self
        e = self%kinetic + self%elastic + self%gravity
    end function energy_total

    !> T + V + dissipated - support work: equals E0 for every run, J.
    pure real(wp) function energy_balance(self) result(e)
        class(energy_t), intent(in) :: self
        e = self%kinetic + self%elastic + self%gravity + self%dissipated - self%support_work
    end function energy_balance

    !> The least stretch (m) an axial spring of the line acts on: 0 for a line carrying
    !! tension only (tension_only, outside statics and modes: a compressed chain is slack),
    !! else -huge (none). The spring acts on max(s, floor): spring_stretch. The RFEM's
    !! kernels apply the floor themselves, taken once per pass: a call of spring_stretch
    !! per spring made their right-hand side cost 28 % more instructions at n = 30
    !! (docs/performance/step.md, "The model's kernels").
    pure real(wp) function rope_stretch_floor(self) result(floor)
        class(rope_model_t), intent(in) :: self
        floor = -huge(1.0_wp)
        if (self%tension_only .and. .not. self%supports_at_rest) floor = 0.0_wp
    end function rope_stretch_floor

    !> The stretch s (m) an axial spring of the line acts on: s, or the floor (stretch_floor)
    !! where s is below it. (A NaN s stays NaN.)
    elemental real(wp) function rope_spring_stretch(self, s) result(stretch)
        class(rope_model_t), intent(in) :: self
        real(wp), intent(in) :: s
        real(wp) :: floor
        floor = self%stretch_floor()
        stretch = s
        if (s < floor) stretch = floor
    end function rope_spring_stretch

    !> d spring_stretch / ds at s: 1, or 0 where a line carrying tension only is slack.
    elemental real(wp) function rope_spring_slope(self, s) result(slope)
        class(rope_model_t), intent(in) :: self
        real(wp), intent(in) :: s
        slope = 1.0_wp
        if (s < self%stretch_floor()) slope = 0.0_wp
    end function rope_spring_slope
end module ropedyn_rope_model
