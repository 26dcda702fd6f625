!> The rigid finite element (RFEM) rope model of Kaminski & Fritzkowski.
!!
!! n rigid elements (end elements of length dl/2, the others dl, dl = L/(n-1)) joined by
!! spring-damping elements (SDEs). SDE j (j = 1 .. n+1) joins element j-1 to element j;
!! elements 0 and n+1 are the supports. Its deformation, in the frame of element j-1, is
!! (tension, shear, bending) = (e_{j-1}.d, n_{j-1}.d, phi_j - phi_{j-1}), d = A_j - B_{j-1}.
!! The derivation (forces, the analytic Jacobian) is in docs/theory/rfem.md.
!!
!! Every deformation measure ("strain") s(q) enters as energy C s^2/2 and dissipation
!! B (ds/dt)^2/2, so its generalized force is -(C s + B s') grad s. A strain kind exists
!! only when its effect is on in &effects, and damping terms are evaluated only when
!! damping is on. The kernels (ropedyn_rfem_kernels) make one pass over the internal SDEs
!! per call, with the cosine and sine of every angle computed once per call into a work
!! array, all three strains of an SDE and their rates together, and the Jacobian directly
!! as 3x3 blocks of element pairs; supports and effects are small separate steps, taken
!! only when present.
!!
!! External effects (drag, ground contact, point loads; ropedyn_effect) act on the elements
!! as bodies and exist only when the spec enables them. Supports may move (their anchor
!! and angle are functions of time, evaluated once per call) or be released at a time
!! (their SDEs are then off). Point masses sit at their true place on an element, which
!! makes that element's 3x3 mass block non-diagonal; it is solved locally.
!!
!! State y (size 6n), element by element: x_i, y_i, phi_i, x_i', y_i', phi_i'.
!!
!! This module builds the model and maps its state (creation, supports in time, geometry);
!! the force, Jacobian and energy kernels are in the submodule ropedyn_rfem_kernels.
module ropedyn_rfem
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use ropedyn_kinds, only: wp, PI
    use ropedyn_sums, only: all_finite
    use ropedyn_error, only: error_t, make_error, ERR_INPUT
    use ropedyn_problem, only: STATUS_OK, STATUS_RECOVERABLE
    use ropedyn_rope_model, only: rope_model_t, energy_t
    use ropedyn_rope_spec, only: rope_spec_t, bottom_anchor_given, release_time, released_at_start
    use ropedyn_effect, only: effect_box_t, bodies_t, add_forces_of, add_jacobians_of, &
                              add_energies_of, add_powers_of, add_forces_powers_of, &
                              add_level_energies_of
    use ropedyn_effect_factory, only: build_body_effects, attached_masses, water_added_mass
    use ropedyn_added_mass, only: added_mass_t
    use ropedyn_support_motion, only: motion_state_t
    use ropedyn_rope_section, only: section_t, rope_section
    use ropedyn_rope_setup, only: initial_angle, clamp_angles, &
                                  configure_motions, any_does_work
    implicit none
    private
    public :: rfem_t, rfem_create


    !> A support's SDE (1 top: d = A_1 - P, 2 bottom: d = P - B_n, P the anchor): an
    !! isotropic translational spring and damper on d (pinned or clamped) and a rotational
    !! one on s = sgn (phi - psi) (clamped), psi the clamp angle. With sgn = +1 (top) or -1
    !! (bottom) and h half the element's length, d = sgn (c - P) - h e.
    type :: support_t
        logical :: translational = .false.  !< pinned or clamped (and not released at t <= 0)
        logical :: rotational = .false.     !< clamped
        real(wp) :: ct = 0.0_wp             !< translational stiffness, N/m
        real(wp) :: bt = 0.0_wp             !< translational damping, N s/m
        real(wp) :: cr = 0.0_wp             !< rotational stiffness, N m/rad
        real(wp) :: br = 0.0_wp             !< rotational damping, N m s/rad
        logical :: damped_t = .false., damped_r = .false.
        logical :: active = .true.          !< false once the support is released
        real(wp) :: sgn = 1.0_wp            !< +1 top, -1 bottom
        integer :: elem = 1                 !< the element it holds (1 or n)
        real(wp) :: anchor(2) = 0.0_wp      !< anchor P at the time of the current call, m
        real(wp) :: angle = 0.0_wp          !< clamp angle psi at that time, rad
        real(wp) :: anchor_vel(2) = 0.0_wp  !< P', m/s
        real(wp) :: angle_rate = 0.0_wp     !< psi', rad/s
    end type support_t

    type, extends(rope_model_t) :: rfem_t
        private
        real(wp), allocatable :: len(:)        !< element lengths, m
        real(wp), allocatable :: mass(:)       !< element masses, kg
        real(wp), allocatable :: inertia(:)    !< central moments of inertia, kg m^2
        real(wp), allocatable :: half(:)       !< half lengths l_i/2, m
        real(wp), allocatable :: weight(:)     !< m_i g (zero when gravity is off), N
        real(wp) :: g = 0.0_wp                 !< gravity, m/s^2
        logical :: gravity_on = .false.
        ! internal SDEs 2 .. n: the strains that exist, stiffness (N/m, N/m, N m/rad) and
        ! damping (N s/m, N s/m, N m s/rad), zero for a strain that is off or undamped
        logical :: tension = .false., shear = .false., bending = .false.
        logical :: damped = .false.            !< damping on (some internal B > 0)
        real(wp) :: cx = 0.0_wp, cy = 0.0_wp, cp = 0.0_wp
        real(wp) :: bx = 0.0_wp, by = 0.0_wp, bp = 0.0_wp
        !> bending stiffness and damping of each internal SDE j = 2 .. n: cp and bp, doubled
        !! next to a clamp (the clamp and its neighbour share one primary section; see
        !! rfem_create)
        real(wp), allocatable :: cpj(:), bpj(:)
        !> axial stiffness and damping of internal SDE j (2:n): cx, bx but next to a pinned
        !! end with supports%end_compliance = 'split' (twice: ropedyn_rfem_create)
        real(wp), allocatable :: cxj(:), bxj(:)
        type(support_t) :: sup(2)              !< top, bottom
        real(wp) :: init_angle = 0.0_wp        !< angle of the straight initial state, rad
        real(wp) :: init_velocity(2) = 0.0_wp  !< initial velocity of every element, m/s
        logical :: folded = .false.            !< initial shape 'folded'
        ! supports (index 1 top, 2 bottom; their motions: rope_model_t%motion): the anchors
        ! and angles above are their values at the time of the current call
        real(wp) :: release(2) = huge(1.0_wp)  !< release times, s
        logical :: timed = .false.             !< the supports depend on time
        ! external effects (only those enabled) and their workspace
        type(effect_box_t), allocatable :: effects(:)
        type(bodies_t) :: bodies
        ! point masses: elements carrying them and their first moment sum m r (kg m);
        ! mass and inertia above include them
        integer, allocatable :: pm_elem(:)
        real(wp), allocatable :: pm_moment(:)
        real(wp), allocatable :: rowscale(:, :)  !< (3, n): 1/m, 1/m, 1/J; 1 on pm elements
        !> in water (&effects water): every element's mass block holds its added mass, its
        !! accelerations solve it (submodule ropedyn_rfem_water); rowscale is 1 then
        logical :: water = .false.
        type(added_mass_t) :: added
        real(wp), allocatable :: inv_mass(:, :)  !< (3, n): 1/m, 1/m, 1/J (the force split)
        ! workspace, allocated once (no state is kept between calls)
        real(wp), allocatable :: cs(:, :)      !< cos, sin of every angle, (2, n)
        real(wp), allocatable :: phi(:)        !< every angle, gathered from y (n)
        real(wp), allocatable :: gen(:, :)     !< generalized forces, (3, n)
        !> in water: every element's added-mass block (3, 3, n) and force (3, n) at the
        !! state of the last `forces` (water_forces), for the accelerations at that state
        real(wp), allocatable :: am_blk(:, :, :), am_g(:, :)
        !> the forces other than the potential's (damping, effects), (3, n): split_forces
        real(wp), allocatable :: gen_r(:, :)
        !> Jacobian blocks (3, 6, -1:1, n): blk(r, l, o, i) is the derivative of row r of
        !! element i (force x, y, moment; times rowscale(r, i) its acceleration, and after
        !! `point_mass_rows` the acceleration on elements with point masses) with respect
        !! to coordinate l (x, y, phi, x', y', phi') of element i + o
        real(wp), allocatable :: blk(:, :, :, :)
    contains
        procedure :: size => rfem_size
        procedure :: bandwidths => rfem_bandwidths
        procedure :: rhs => rfem_rhs
        procedure :: has_jacobian => rfem_has_jacobian
        procedure :: jacobian => rfem_jacobian
        procedure :: energy => rfem_energy
        procedure :: quad_rhs => rfem_quad_rhs
        procedure :: rhs_quad => rfem_rhs_quad
        procedure :: model_name => rfem_model_name
        procedure :: initial_state => rfem_initial_state
        procedure :: fields => rfem_fields
        procedure :: state_from_fields => rfem_state_from_fields
        procedure :: polyline => rfem_polyline
        procedure :: element_data => rfem_element_data
        procedure :: internal_forces => rfem_internal_forces
        procedure :: support_positions => rfem_support_positions
        procedure :: coordinates => rfem_coordinates
        procedure :: second_order_layout => rfem_second_order_layout
        procedure :: coordinate_mass => rfem_coordinate_mass
        procedure :: mass_bandwidth => rfem_mass_bandwidth
        procedure :: angle_coordinates => rfem_angle_coordinates
        procedure :: displace => rfem_displace
        procedure :: coordinate_mass_band => rfem_coordinate_mass_band
        procedure :: second_order_blocks => rfem_second_order_blocks
        procedure :: generalized_forces => rfem_generalized_forces
        procedure :: potential_energy => rfem_potential_energy
        procedure :: force_split_refusal => rfem_force_split_refusal, &
                     split_layout => rfem_split_layout, split_rhs => rfem_split_rhs, &
                     split_has_rest => rfem_split_has_rest
        procedure, private :: forces
        procedure, private :: jacobian_blocks
        procedure, private :: point_mass_rows
        procedure, private :: set_time
        procedure, private :: fill_bodies
        procedure, private :: point_mass_accelerations
        procedure, private :: water_forces, water_accelerations, water_kinetic, water_rows
    end type rfem_t

    interface
        !> The generalized forces (3, n) of everything at time t and state y into self%gen
        !! (one pass over the SDEs); optionally the elastic energy (J, springs and the
        !! effects' potential energy).
        module subroutine forces(self, t, y, elastic, power, joint, support, rest, work)
            class(rfem_t), intent(inout) :: self
            real(wp), intent(in) :: t
            real(wp), intent(in) :: y(6*self%n)
            real(wp), intent(out), optional :: elastic
            !> when present: the internal SDEs' dissipation power sum B s'^2
            real(wp), intent(out), optional :: power
            !> when present: the forces fx, fy (N) and fp (N m) of the internal SDEs j = 2 ..
            !! n in joint(:, j - 1) (columns 0 and n, the supports', are left as they are)
            real(wp), intent(inout), optional :: joint(3, 0:self%n)
            !> when present: the support SDEs' forces fs (x, y, N) and fr (N m), top and
            !! bottom (zero for a free or released end; support_force in the kernels)
            real(wp), intent(out), optional :: support(3, 2)
            !> when present, the force split (ropedyn_rfem_energy): self%gen holds the
            !! potential's forces alone (springs, supports' springs, gravity) and, when
            !! .true., self%gen_r the rest (dampers, effects); .false.: the rest is not
            !! evaluated
            logical, intent(in), optional :: rest
            !> when present (with power, without rest): the supports' and the effects'
            !! dissipation added to power and their external work rate, W, as store_powers
            !! adds them (the same terms in the same order), each effect's with its forces
            real(wp), intent(out), optional :: work
        end subroutine forces

        !> The derivatives of the generalized forces with respect to the coordinates and
        !! their rates, as 3x6 blocks of element pairs, into self%blk (one pass over the
        !! SDEs; effects added on the diagonal blocks).
        module subroutine jacobian_blocks(self, t, y)
            class(rfem_t), intent(inout) :: self
            real(wp), intent(in) :: t
            real(wp), intent(in) :: y(6*self%n)
        end subroutine jacobian_blocks

        !> The rows of self%blk of elements with point masses from force rows to
        !! acceleration rows: multiplied by the inverse of their mass block, with the
        !! derivatives of the mass block and of the centripetal and weight terms.
        module subroutine point_mass_rows(self, t, y)
            class(rfem_t), intent(inout) :: self
            real(wp), intent(in) :: t
            real(wp), intent(in) :: y(:)
        end subroutine point_mass_rows

        !> Element kinematics for the effects (self%cs holding the angles of y).
        module subroutine fill_bodies(self, y)
            class(rfem_t), intent(inout) :: self
            real(wp), intent(in) :: y(:)
        end subroutine fill_bodies

        !> Accelerations of the elements carrying point masses: with s = sum m r, the mass block
        !! [[m, 0, s n_x], [0, m, s n_y], [s n_x, s n_y, J]] times (x'', y'', phi'') equals the
        !! generalized force plus s w^2 e (the point masses' centripetal term).
        module subroutine point_mass_accelerations(self, y, gen, ydot)
            class(rfem_t), intent(in) :: self
            real(wp), intent(in) :: y(:), gen(:, :)
            real(wp), intent(inout) :: ydot(:)
        end subroutine point_mass_accelerations

        !> Generalized forces (3, n) of all enabled effects at state y and time t (default 0);
        !! optionally the elastic energy (J, with the effects' potential energy). (The
        !! dissipation power is `quad_rhs`.)
        module subroutine rfem_generalized_forces(self, y, gen, elastic, t)
            class(rfem_t), intent(inout) :: self
            real(wp), intent(in) :: y(:)
            real(wp), intent(out) :: gen(:, :)
            real(wp), intent(out), optional :: elastic
            real(wp), intent(in), optional :: t
        end subroutine rfem_generalized_forces

        module subroutine rfem_rhs(self, t, y, ydot, status)
            class(rfem_t), intent(inout) :: self
            real(wp), intent(in) :: t
            real(wp), intent(in) :: y(:)
            real(wp), intent(out) :: ydot(:)
            integer, intent(out) :: status
        end subroutine rfem_rhs

        !> The RFEM Jacobian is analytic.
        module pure logical function rfem_has_jacobian(self) result(has)
            class(rfem_t), intent(in) :: self
        end function rfem_has_jacobian

        !> Analytic Jacobian of the first-order system, banded. For each strain:
        !! dF/dq = -C g g^T - (C s + B s') H - B g (H q')^T,  dF/dq' = -B g g^T.
        module subroutine rfem_jacobian(self, t, y, jb, offset, status)
            class(rfem_t), intent(inout) :: self
            real(wp), intent(in) :: t
            real(wp), intent(in) :: y(:)
            real(wp), intent(inout) :: jb(:, :)
            integer, intent(in) :: offset
            integer, intent(out) :: status
        end subroutine rfem_jacobian

        !> K = d(acceleration)/dq, C = d(acceleration)/dq' (the velocity rows of the
        !! Jacobian) and the identity mass block, in band storage with kl = ku = 5, from the
        !! same blocks as the Jacobian. RFEM has no mass matrix: the implicit form is the
        !! explicit one.
        module subroutine rfem_second_order_blocks(self, t, y, implicit_form, kb, cb, mb, &
                                                   offset, status)
            class(rfem_t), intent(inout) :: self
            real(wp), intent(in) :: t
            real(wp), intent(in) :: y(:)
            logical, intent(in) :: implicit_form
            real(wp), intent(inout) :: kb(:, :), cb(:, :), mb(:, :)
            integer, intent(in) :: offset
            integer, intent(out) :: status
        end subroutine rfem_second_order_blocks

        !> Potential energy V = elastic + gravity, J (used by the gradient test).
        module function rfem_potential_energy(self, y) result(v)
            class(rfem_t), intent(inout) :: self
            real(wp), intent(in) :: y(:)
            real(wp) :: v
        end function rfem_potential_energy

        module function rfem_energy(self, t, y, yq) result(e)
            class(rfem_t), intent(inout) :: self
            real(wp), intent(in) :: t
            real(wp), intent(in) :: y(:)
            real(wp), intent(in) :: yq(:)
            type(energy_t) :: e
        end function rfem_energy

        !> Quadratures: the dissipation power 2D = sum B s'^2 (+ the effects' dissipation), W;
        !! with moving supports or working effects also the external power: sum over moving
        !! support strains of (C s + B s') ds/dt (the support's force on the rope times the
        !! anchor's velocity) plus the effects' work rate, W.
        module subroutine rfem_quad_rhs(self, t, y, yqdot, status)
            class(rfem_t), intent(inout) :: self
            real(wp), intent(in) :: t
            real(wp), intent(in) :: y(:)
            real(wp), intent(out) :: yqdot(:)
            integer, intent(out) :: status
        end subroutine rfem_quad_rhs

        !> rfem_rhs and rfem_quad_rhs in one pass: the internal SDEs' dissipation power
        !! is summed where their damping forces are formed (same values, same order).
        module subroutine rfem_rhs_quad(self, t, y, ydot, yqdot, status)
            class(rfem_t), intent(inout) :: self
            real(wp), intent(in) :: t
            real(wp), intent(in) :: y(:)
            real(wp), intent(out) :: ydot(:)
            real(wp), intent(out) :: yqdot(:)
            integer, intent(out) :: status
        end subroutine rfem_rhs_quad
        !> The added mass's forces at y into self%gen; with e_el, its potential added (the
        !! current's, J). Submodule ropedyn_rfem_water.
        module subroutine water_forces(self, y, e_el)
            class(rfem_t), intent(inout) :: self
            real(wp), intent(in) :: y(:)
            real(wp), intent(inout), optional :: e_el
        end subroutine water_forces

        !> Every element's accelerations from its mass block (in water; self%am_blk and
        !! self%am_g at y, from `forces`).
        module subroutine water_accelerations(self, y, gen, ydot)
            class(rfem_t), intent(in) :: self
            real(wp), intent(in) :: y(:), gen(:, :)
            real(wp), intent(inout) :: ydot(:)
        end subroutine water_accelerations

        !> The added mass's kinetic energy at y, J.
        module function water_kinetic(self, y) result(e_k)
            class(rfem_t), intent(in) :: self
            real(wp), intent(in) :: y(:)
            real(wp) :: e_k
        end function water_kinetic

        !> self%blk's rows to acceleration rows through the elements' mass blocks (in
        !! water); self%gen must hold the forces at (t, y).
        module subroutine water_rows(self, t, y)
            class(rfem_t), intent(inout) :: self
            real(wp), intent(in) :: t
            real(wp), intent(in) :: y(:)
        end subroutine water_rows

        !> Why the model offers no force split ('' when it does; submodule ropedyn_rfem_energy).
        module pure function rfem_force_split_refusal(self) result(why)
            class(rfem_t), intent(in) :: self
            character(len=:), allocatable :: why
        end function rfem_force_split_refusal

        !> Whether the split has forces outside the potential: dampers of the joints or the
        !! supports, or effects (submodule ropedyn_rfem_energy).
        module pure logical function rfem_split_has_rest(self) result(rest)
            class(rfem_t), intent(in) :: self
        end function rfem_split_has_rest

        !> The masses of the coordinates (m, m, J per element) and the balance signs of the
        !! quadratures (dissipated -1, external work +1).
        module pure subroutine rfem_split_layout(self, mass, signs)
            class(rfem_t), intent(in) :: self
            real(wp), intent(out) :: mass(:)
            integer, intent(out) :: signs(:)
        end subroutine rfem_split_layout

        !> The accelerations of the springs, supports' springs and gravity (the potential)
        !! and, with `ar`, of the rest (dampers, effects), with the quadratures' rates split
        !! the same way (problem_t's split_rhs; submodule ropedyn_rfem_energy).
        module subroutine rfem_split_rhs(self, t, y, ac, gc, status, ar, gr)
            class(rfem_t), intent(inout) :: self
            real(wp), intent(in) :: t
            real(wp), intent(in) :: y(:)
            real(wp), intent(out) :: ac(:), gc(:)
            integer, intent(out) :: status
            real(wp), intent(out), optional :: ar(:), gr(:)
        end subroutine rfem_split_rhs

        !> Build the model of a spec (its values are already validated; submodule
        !! ropedyn_rfem_create).
        module subroutine rfem_create(model, spec, err)
            type(rfem_t), intent(out) :: model
            type(rope_spec_t), intent(in) :: spec
            type(error_t), allocatable, intent(out) :: err
        end subroutine rfem_create

        !> cos and sin of every angle of y into the model's work array, once per call.
        module subroutine angles(self, y)
            class(rfem_t), intent(inout) :: self
            real(wp), intent(in) :: y(:)
        end subroutine angles

        !> The internal forces of the SDEs (submodule ropedyn_rfem_forces): joint j is SDE
        !! j + 1, axial and shear its tension and shear force, components of its force on
        !! the element above in that element's frame (e, n) (joint 0, the top support: the
        !! force of the rope on the support in the frame of element 1), the moment its
        !! rotational spring and damper's.
        module subroutine rfem_internal_forces(self, t, y, axial, shear, moment, reaction)
            class(rfem_t), intent(inout) :: self
            real(wp), intent(in) :: t
            real(wp), intent(in) :: y(:)
            real(wp), intent(out) :: axial(0:), shear(0:), moment(0:)
            real(wp), intent(out) :: reaction(:, :)
        end subroutine rfem_internal_forces

        !> The anchors at time t (submodule ropedyn_rfem_forces).
        module subroutine rfem_support_positions(self, t, positions)
            class(rfem_t), intent(in) :: self
            real(wp), intent(in) :: t
            real(wp), intent(out) :: positions(:, :)
        end subroutine rfem_support_positions
    end interface

contains

    !> Supports at time t: anchors, angles and their rates from the prescribed motions;
    !! released supports switched off. Once per call, never per element.
    subroutine set_time(self, t)
        class(rfem_t), intent(inout) :: self
        real(wp), intent(in) :: t
        type(motion_state_t) :: ms
        integer :: k
        if (.not. self%timed) return
        do k = 1, 2
            self%sup(k)%active = t < self%release(k)
            if (.not. self%moving(k)) cycle
            ms = self%motion(k)%state(t)
            self%sup(k)%anchor = ms%p
            self%sup(k)%angle = ms%angle
            self%sup(k)%anchor_vel = ms%v
            self%sup(k)%angle_rate = ms%rate
            if (self%supports_at_rest) then
                self%sup(k)%anchor_vel = 0.0_wp
                self%sup(k)%angle_rate = 0.0_wp
            end if
        end do
    end subroutine set_time

    pure integer function rfem_size(self)
        class(rfem_t), intent(in) :: self
        rfem_size = 6*self%n
    end function rfem_size

    !> Element i's accelerations depend on elements i-1, i, i+1 (see the module header).
    pure subroutine rfem_bandwidths(self, ml, mu)
        class(rfem_t), intent(in) :: self
        integer, intent(out) :: ml, mu
        ml = min(11, 6*self%n - 1)
        mu = min(8, 6*self%n - 1)
    end subroutine rfem_bandwidths

    pure function rfem_model_name(self) result(name)
        class(rfem_t), intent(in) :: self
        character(len=:), allocatable :: name
        name = 'rfem'
    end function rfem_model_name

    subroutine rfem_element_data(self, length, mass)
        class(rfem_t), intent(in) :: self
        real(wp), intent(out) :: length(:), mass(:)
        length = self%len
        mass = self%mass
    end subroutine rfem_element_data

    !> Straight rope from the top anchor at the initial angle, at rest, unstretched.
    subroutine rfem_initial_state(self, y)
        class(rfem_t), intent(in) :: self
        real(wp), intent(out) :: y(:)
        integer :: i, k
        real(wp) :: s_start, dir(2)
        dir = [cos(self%init_angle), sin(self%init_angle)]
        y = 0.0_wp
        s_start = 0.0_wp
        do i = 1, self%n
            k = 6*(i - 1)
            y(k + 1:k + 2) = self%motion(1)%p0 + (s_start + self%len(i)/2.0_wp)*dir
            y(k + 3) = self%init_angle
            y(k + 4:k + 5) = self%init_velocity
            s_start = s_start + self%len(i)
        end do
        if (self%folded) call fold(y)
    contains
        !> 'folded' (n odd): elements 1 .. m = (n-1)/2 hang down from the anchor, element
        !! m+1 lies horizontal (the fold, towards +y), elements m+2 .. n go back up: two
        !! straight halves side by side, one element length dl apart.
        pure subroutine fold(y)
            real(wp), intent(inout) :: y(:)
            real(wp) :: depth, gap, s_up
            integer :: m, j, kk
            m = (self%n - 1)/2
            depth = sum(self%len(1:m))
            gap = self%len(m + 1)
            kk = 6*m
            y(kk + 1:kk + 2) = self%motion(1)%p0 + [depth, 0.5_wp*gap]
            y(kk + 3) = 0.5_wp*pi
            s_up = 0.0_wp
            do j = m + 2, self%n
                kk = 6*(j - 1)
                y(kk + 1:kk + 2) = self%motion(1)%p0 + [depth - s_up - 0.5_wp*self%len(j), gap]
                y(kk + 3) = pi
                s_up = s_up + self%len(j)
            end do
        end subroutine fold
    end subroutine rfem_initial_state

    subroutine rfem_fields(self, y, q, qdot, t)
        class(rfem_t), intent(in) :: self
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: q(:, :), qdot(:, :)
        real(wp), intent(in), optional :: t  !< not needed: the state holds every position
        integer :: i
        do i = 1, self%n
            q(:, i) = y(6*(i - 1) + 1:6*(i - 1) + 3)
            qdot(:, i) = y(6*(i - 1) + 4:6*(i - 1) + 6)
        end do
    end subroutine rfem_fields

    !> The state holds the fields themselves: y(6(i-1)+1..3) = q(:, i), +4..6 = qdot(:, i).
    pure subroutine rfem_state_from_fields(self, q, qdot, t, y, ok)
        class(rfem_t), intent(in) :: self
        real(wp), intent(in) :: q(:, :), qdot(:, :)
        real(wp), intent(in) :: t  !< not needed
        real(wp), intent(out) :: y(:)
        logical, intent(out) :: ok
        integer :: i
        y = 0.0_wp
        ok = size(q, 2) == self%n .and. size(qdot, 2) == self%n .and. size(y) == 6*self%n
        if (.not. ok) return
        do i = 1, self%n
            y(6*(i - 1) + 1:6*(i - 1) + 3) = q(:, i)
            y(6*(i - 1) + 4:6*(i - 1) + 6) = qdot(:, i)
        end do
    end subroutine rfem_state_from_fields

    subroutine rfem_polyline(self, y, points, t)
        class(rfem_t), intent(in) :: self
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: points(:, :)
        real(wp), intent(in), optional :: t  !< not needed: the state holds every position
        integer :: i, k
        real(wp) :: e(2)
        do i = 1, self%n
            k = 6*(i - 1)
            e = [cos(y(k + 3)), sin(y(k + 3))]
            points(:, 2*i - 1) = y(k + 1:k + 2) - (self%len(i)/2.0_wp)*e
            points(:, 2*i) = y(k + 1:k + 2) + (self%len(i)/2.0_wp)*e
        end do
    end subroutine rfem_polyline

    !> Coordinates x_i, y_i, phi_i of each element: y(6(i-1)+1..3), rates y(6(i-1)+4..6).
    pure subroutine rfem_coordinates(self, pos, vel)
        class(rfem_t), intent(in) :: self
        integer, allocatable, intent(out) :: pos(:), vel(:)
        integer :: i, c
        allocate (pos(3*self%n), vel(3*self%n))
        do i = 1, self%n
            do c = 1, 3
                pos(3*(i - 1) + c) = 6*(i - 1) + c
                vel(3*(i - 1) + c) = 6*(i - 1) + 3 + c
            end do
        end do
    end subroutine rfem_coordinates

    !> The coordinates; element i couples to i-1 and i+1 only, so the reduced blocks have
    !! three 3x3 blocks a row: bandwidths 5 and 5.
    pure subroutine rfem_second_order_layout(self, pos, vel, kl, ku)
        class(rfem_t), intent(in) :: self
        integer, allocatable, intent(out) :: pos(:), vel(:)
        integer, intent(out) :: kl, ku
        call self%coordinates(pos, vel)
        kl = min(5, size(pos) - 1)
        ku = kl
    end subroutine rfem_second_order_layout

    !> The mass matrix of the coordinates, dense (from `rfem_coordinate_mass_band`).
    subroutine rfem_coordinate_mass(self, y, mm)
        class(rfem_t), intent(in) :: self
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: mm(:, :)
        real(wp) :: mb(0:2, 3*self%n)
        integer :: i, j
        call self%coordinate_mass_band(y, mb)
        mm = 0.0_wp
        do j = 1, 3*self%n
            do i = j, min(3*self%n, j + 2)
                mm(i, j) = mb(i - j, j)
                mm(j, i) = mb(i - j, j)
            end do
        end do
    end subroutine rfem_coordinate_mass

    !> The coordinates (x, y, phi) of each element: every third is an angle.
    pure function rfem_angle_coordinates(self) result(angle)
        class(rfem_t), intent(in) :: self
        logical, allocatable :: angle(:)
        integer :: k
        angle = [(mod(k, 3) == 0, k = 1, 3*self%n)]
    end function rfem_angle_coordinates

    !> The state y moved by delta = (dx, dy, dphi) per element so that the joints move as
    !! rigid links: the angles take phi + dphi; the top end of element 1 and each joint's gap
    !! (end A of element i+1 minus end B of element i) take their changes linearized in
    !! delta; the centres are then chained from the top. Equal to y + delta to first order,
    !! and exact for a rotation of joined elements, which y + delta would stretch at second
    !! order by l dphi^2/2 in each joint: the stiff joint springs then make every step of an
    !! iteration on a soft rope short (docs/theory/statics-modes.md, "Steps that turn").
    pure subroutine rfem_displace(self, y, delta, y_new)
        class(rfem_t), intent(in) :: self
        real(wp), intent(in) :: y(:), delta(:)
        real(wp), intent(out) :: y_new(:)
        real(wp) :: e(2), de(2), e_new(2), b_old(2), db_old(2), a_old(2), da(2), end_b(2)
        integer :: i, k, d
        y_new = y
        do i = 1, self%n
            k = 6*(i - 1)
            d = 3*(i - 1)
            e = [cos(y(k + 3)), sin(y(k + 3))]
            de = [-e(2), e(1)]*delta(d + 3)             ! the change of e, linearized
            a_old = y(k + 1:k + 2) - 0.5_wp*self%len(i)*e
            da = delta(d + 1:d + 2) - 0.5_wp*self%len(i)*de
            y_new(k + 3) = y(k + 3) + delta(d + 3)
            e_new = [cos(y_new(k + 3)), sin(y_new(k + 3))]
            if (i == 1) then
                y_new(k + 1:k + 2) = a_old + da + 0.5_wp*self%len(i)*e_new
            else                                        ! end B of i-1, plus the new gap
                y_new(k + 1:k + 2) = end_b + (a_old - b_old) + (da - db_old) + &
                                     0.5_wp*self%len(i)*e_new
            end if
            b_old = y(k + 1:k + 2) + 0.5_wp*self%len(i)*e
            db_old = delta(d + 1:d + 2) + 0.5_wp*self%len(i)*de
            end_b = y_new(k + 1:k + 2) + 0.5_wp*self%len(i)*e_new
        end do
    end subroutine rfem_displace

    !> The mass matrix is block diagonal (3x3 per element): bandwidth 2.
    pure integer function rfem_mass_bandwidth(self) result(kd)
        class(rfem_t), intent(in) :: self
        kd = min(2, 3*self%n - 1)
    end function rfem_mass_bandwidth

    !> The mass matrix of the coordinates as its lower band mb(0:2, 3n): diag(m_i, m_i,
    !! J_i), plus the translation-rotation coupling s n_i of elements with point masses off
    !! their centre, plus in water each element's added-mass block.
    subroutine rfem_coordinate_mass_band(self, y, mb)
        class(rfem_t), intent(in) :: self
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: mb(0:, :)
        integer :: i, k, r, c
        real(wp) :: blk(3, 3), g(3), coupling(2)
        mb = 0.0_wp
        do i = 1, self%n
            k = 3*(i - 1)
            mb(0, k + 1) = self%mass(i)
            mb(0, k + 2) = self%mass(i)
            mb(0, k + 3) = self%inertia(i)
        end do
        ! point masses off the element centres couple translation and rotation: s n
        ! (entries (k+3, k+1) and (k+3, k+2) of the lower band)
        do i = 1, size(self%pm_elem)
            k = 3*(self%pm_elem(i) - 1)
            coupling = self%pm_moment(i)* &
                [-sin(y(6*self%pm_elem(i) - 3)), cos(y(6*self%pm_elem(i) - 3))]
            mb(2, k + 1) = coupling(1)
            mb(1, k + 2) = coupling(2)
        end do
        ! the water's added mass (at the state's coordinates and rates)
        if (self%water) then
            do i = 1, self%n
                k = 6*(i - 1)
                call self%added%terms(y(k + 1:k + 2), y(k + 3), y(k + 4:k + 5), y(k + 6), &
                                      self%len(i), blk, g)
                do c = 1, 3
                    do r = c, 3
                        mb(r - c, 3*(i - 1) + c) = mb(r - c, 3*(i - 1) + c) + blk(r, c)
                    end do
                end do
            end do
        end if
    end subroutine rfem_coordinate_mass_band
end module ropedyn_rfem
