!> The rigid finite element (RFEM) rope model of Kaminski & Fritzkowski.
!!
!! n rigid elements (end elements of length dl/2, the others dl, dl = L/(n-1)) joined by
!! spring-damping elements (SDEs). SDE j (j = 1 .. n+1) joins element j-1 to element j;
!! elements 0 and n+1 are the supports. Its deformation, in the frame of element j-1, is
!! (tension, shear, bending) = (e_{j-1}.d, n_{j-1}.d, phi_j - phi_{j-1}), d = A_j - B_{j-1}.
!! The derivation (forces, the analytic Jacobian) is in docs/physics-rfem.md.
!!
!! Every deformation measure ("strain") s(q) enters as energy C s^2/2 and dissipation
!! B (ds/dt)^2/2, so its generalized force is -(C s + B s') grad s. Strains of one kind
!! form a family; a family exists only when its effect is on in &effects, and damping
!! terms are evaluated only when damping is on. Nothing is computed for an effect that is
!! off.
!!
!! External effects (drag, ground contact, point loads; ropedyn_effect) act on the elements
!! as bodies and exist only when the spec enables them. Supports may move (their anchor
!! and angle are functions of time, evaluated once per call) or be released at a time
!! (their families are then off). Point masses sit at their true place on an element, which
!! makes that element's 3x3 mass block non-diagonal; it is solved locally.
!!
!! State y (size 6n), element by element: x_i, y_i, phi_i, x_i', y_i', phi_i'.
!!
!! This module builds the model and maps its state (creation, supports in time, geometry);
!! the force, Jacobian and energy kernels are in the submodule ropedyn_rfem_kernels.
module ropedyn_rfem
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t, make_error, ERR_INPUT
    use ropedyn_problem, only: STATUS_OK, STATUS_RECOVERABLE
    use ropedyn_rope_model, only: rope_model_t, energy_t
    use ropedyn_rope_spec, only: rope_spec_t, bottom_anchor_given
    use ropedyn_effect, only: effect_box_t, bodies_t, add_forces_of, add_jacobians_of, &
                              add_energies_of, add_powers_of
    use ropedyn_effect_factory, only: build_body_effects, attached_masses
    use ropedyn_support_motion, only: support_motion_t, motion_state_t
    use ropedyn_rope_setup, only: cross_section, initial_angle, clamp_angles, &
                                  configure_motions, any_does_work
    implicit none
    private
    public :: rfem_t, rfem_create

    real(wp), parameter :: pi = acos(-1.0_wp)

    !> Strain families.
    integer, parameter :: FAM_TENSION = 1, FAM_SHEAR = 2, FAM_BEND = 3
    integer, parameter :: FAM_TOP_X = 4, FAM_TOP_Y = 5, FAM_TOP_ROT = 6
    integer, parameter :: FAM_BOTTOM_X = 7, FAM_BOTTOM_Y = 8, FAM_BOTTOM_ROT = 9

    !> A set of SDE strains of one kind with common stiffness and damping.
    type :: family_t
        integer :: kind = 0
        integer :: first = 0, last = -1  !< SDE range
        real(wp) :: c = 0.0_wp           !< stiffness (N/m or N m/rad)
        real(wp) :: b = 0.0_wp           !< damping (N s/m or N m s/rad)
        logical :: damped = .false.
        integer :: end = 0               !< 0 internal, 1 top support, 2 bottom support
        logical :: active = .true.       !< false once its support is released
        real(wp) :: st = 0.0_wp          !< explicit rate ds/dt of a moving support's strain
    end type family_t

    type, extends(rope_model_t) :: rfem_t
        private
        integer :: n = 0                       !< number of rigid elements
        real(wp), allocatable :: len(:)        !< element lengths, m
        real(wp), allocatable :: mass(:)       !< element masses, kg
        real(wp), allocatable :: inertia(:)    !< central moments of inertia, kg m^2
        real(wp) :: g = 0.0_wp                 !< gravity, m/s^2
        logical :: gravity_on = .false.
        type(family_t), allocatable :: families(:)
        real(wp) :: top_anchor(2) = 0.0_wp     !< m
        real(wp) :: bottom_anchor(2) = 0.0_wp  !< m
        real(wp) :: top_angle = 0.0_wp         !< clamp angle, rad
        real(wp) :: bottom_angle = 0.0_wp      !< clamp angle, rad
        real(wp) :: init_angle = 0.0_wp        !< angle of the straight initial state, rad
        real(wp) :: init_velocity(2) = 0.0_wp  !< initial velocity of every element, m/s
        logical :: folded = .false.            !< initial shape 'folded'
        ! supports (index 1 top, 2 bottom): base anchors and prescribed motions; the anchors
        ! and angles above are their values at the time of the current call
        type(support_motion_t) :: motion(2)
        logical :: moving(2) = .false.
        real(wp) :: release(2) = huge(1.0_wp)  !< release times, s
        logical :: timed = .false.             !< the supports depend on time
        real(wp) :: anchor_vel(2, 2) = 0.0_wp  !< anchor velocities (top, bottom), m/s
        real(wp) :: angle_rate(2) = 0.0_wp     !< support angle rates, rad/s
        logical :: with_work = .false.         !< external work is quadrature 2
        ! external effects (only those enabled) and their workspace
        type(effect_box_t), allocatable :: effects(:)
        type(bodies_t) :: bodies
        real(wp), allocatable :: ejac(:, :, :)  !< (3, 6, n)
        ! point masses: elements carrying them and their first moment sum m r (kg m);
        ! mass and inertia above include them
        integer, allocatable :: pm_elem(:)
        real(wp), allocatable :: pm_moment(:)
        real(wp), allocatable :: rowscale(:, :)  !< (3, n): 1/m, 1/m, 1/J; 1 on pm elements
        ! workspace (no state is kept between calls)
        real(wp), allocatable :: s(:)          !< strains of the current family
        real(wp), allocatable :: grad(:, :)    !< their gradients, (6, n+1)
        real(wp), allocatable :: force(:)      !< C s + B s' per SDE
        real(wp), allocatable :: gen(:, :)     !< generalized forces, (3, n)
    contains
        procedure :: size => rfem_size
        procedure :: bandwidths => rfem_bandwidths
        procedure :: rhs => rfem_rhs
        procedure :: has_jacobian => rfem_has_jacobian
        procedure :: jacobian => rfem_jacobian
        procedure :: energy => rfem_energy
        procedure :: quad_size => rfem_quad_size
        procedure :: quad_rhs => rfem_quad_rhs
        procedure :: n_elements => rfem_n_elements
        procedure :: model_name => rfem_model_name
        procedure :: initial_state => rfem_initial_state
        procedure :: fields => rfem_fields
        procedure :: polyline => rfem_polyline
        procedure :: element_data => rfem_element_data
        procedure :: coordinates => rfem_coordinates
        procedure :: second_order_layout => rfem_second_order_layout
        procedure :: coordinate_mass => rfem_coordinate_mass
        procedure :: generalized_forces => rfem_generalized_forces
        procedure :: potential_energy => rfem_potential_energy
        procedure, private :: strain
        procedure, private :: local_rates
        procedure, private :: set_time
        procedure, private :: fill_bodies
        procedure, private :: point_mass_accelerations
    end type rfem_t

    interface
        !> Strain s and gradient g (local dofs: x, y, phi of element j-1, then of element j)
        !! of SDE j in family `kind`; optionally the Hessian h.
        module pure subroutine strain(self, kind, j, y, s, g, h)
            class(rfem_t), intent(in) :: self
            integer, intent(in) :: kind, j
            real(wp), intent(in) :: y(:)
            real(wp), intent(out) :: s, g(6)
            real(wp), intent(out), optional :: h(6, 6)
        end subroutine strain

        !> Velocities of the local dofs of SDE j (zero for a support).
        module pure function local_rates(self, j, y) result(v)
            class(rfem_t), intent(in) :: self
            integer, intent(in) :: j
            real(wp), intent(in) :: y(:)
            real(wp) :: v(6)
        end function local_rates

        !> Element kinematics for the effects.
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
    end interface

contains

    !> Build the model of a spec (its values are already validated).
    subroutine rfem_create(model, spec, err)
        type(rfem_t), intent(out) :: model
        type(rope_spec_t), intent(in) :: spec
        type(error_t), allocatable, intent(out) :: err
        integer :: n, nf, k, i
        real(wp) :: area, second_moment, dl, total_mass, cx, cy, cphi, bx, by, bphi, factor
        real(wp) :: angles(2)
        type(family_t) :: fams(9)
        logical :: damped
        integer, allocatable :: pm_body(:)
        real(wp), allocatable :: pm_r(:), pm_m(:), y0(:)

        n = spec%model%elements
        if (n < 2) then
            call make_error(err, ERR_INPUT, 'rfem: elements must be >= 2')
            return
        end if
        model%n = n
        call cross_section(spec, area, second_moment)
        dl = spec%rope%length/real(n - 1, wp)
        total_mass = spec%rope%density*area*spec%rope%length
        allocate (model%len(n), model%mass(n), model%inertia(n))
        model%len = dl
        model%len(1) = dl/2.0_wp
        model%len(n) = dl/2.0_wp
        model%mass = total_mass*model%len/spec%rope%length
        model%inertia = model%mass*(model%len**2/12.0_wp + spec%rope%diameter**2/16.0_wp)

        model%g = spec%rope%gravity
        model%gravity_on = spec%effects%gravity
        damped = spec%effects%damping

        cx = spec%rope%young_modulus*area/dl
        cy = spec%rope%shear_modulus*area/(spec%rope%shape_factor*dl)
        cphi = spec%rope%young_modulus*second_moment/dl
        bx = spec%rope%normal_damping*area/dl
        by = spec%rope%tangential_damping*area/(spec%rope%shape_factor*dl)
        bphi = spec%rope%normal_damping*second_moment/dl
        factor = spec%supports%support_stiffness_factor
        if (spec%effects%support_motion) then
            associate (s => spec%supports)
                if (s%top_release_time >= 0.0_wp) model%release(1) = s%top_release_time
                if (s%bottom_release_time >= 0.0_wp) model%release(2) = s%bottom_release_time
            end associate
        end if

        nf = 0
        if (spec%effects%tension) call add(FAM_TENSION, 2, n, cx, bx)
        if (spec%effects%shear) call add(FAM_SHEAR, 2, n, cy, by)
        if (spec%effects%bending) call add(FAM_BEND, 2, n, cphi, bphi)
        ! a support released at t <= 0 is free from the start: no family at all
        if (model%release(1) > 0.0_wp) then
            select case (spec%supports%top)
            case ('pinned')
                call add(FAM_TOP_X, 1, 1, factor*cx, factor*bx, 1)
                call add(FAM_TOP_Y, 1, 1, factor*cx, factor*bx, 1)
            case ('clamped')
                call add(FAM_TOP_X, 1, 1, factor*cx, factor*bx, 1)
                call add(FAM_TOP_Y, 1, 1, factor*cx, factor*bx, 1)
                call add(FAM_TOP_ROT, 1, 1, factor*cphi, factor*bphi, 1)
            end select
        end if
        if (model%release(2) > 0.0_wp) then
            select case (spec%supports%bottom)
            case ('pinned')
                call add(FAM_BOTTOM_X, n + 1, n + 1, factor*cx, factor*bx, 2)
                call add(FAM_BOTTOM_Y, n + 1, n + 1, factor*cx, factor*bx, 2)
            case ('clamped')
                call add(FAM_BOTTOM_X, n + 1, n + 1, factor*cx, factor*bx, 2)
                call add(FAM_BOTTOM_Y, n + 1, n + 1, factor*cx, factor*bx, 2)
                call add(FAM_BOTTOM_ROT, n + 1, n + 1, factor*cphi, factor*bphi, 2)
            end select
        end if
        model%families = fams(1:nf)

        model%init_angle = initial_angle(spec)
        model%folded = spec%initial%shape == 'folded'
        model%init_velocity = spec%initial%velocity
        model%top_anchor = spec%supports%top_anchor
        angles = clamp_angles(spec)
        model%top_angle = angles(1)
        model%bottom_angle = angles(2)

        ! point masses at their place on the elements: mass, inertia about the centre and
        ! the first moment m r that couples translation and rotation
        call attached_masses(spec, model%len, pm_body, pm_r, pm_m)
        allocate (model%pm_elem(0), model%pm_moment(0))
        do k = 1, size(pm_body)
            i = pm_body(k)
            model%mass(i) = model%mass(i) + pm_m(k)
            model%inertia(i) = model%inertia(i) + pm_m(k)*pm_r(k)**2
            if (.not. any(model%pm_elem == i)) then
                model%pm_elem = [model%pm_elem, i]
                model%pm_moment = [model%pm_moment, 0.0_wp]
            end if
            where (model%pm_elem == i) model%pm_moment = model%pm_moment + pm_m(k)*pm_r(k)
        end do
        allocate (model%rowscale(3, n))
        model%rowscale(1, :) = 1.0_wp/model%mass
        model%rowscale(2, :) = 1.0_wp/model%mass
        model%rowscale(3, :) = 1.0_wp/model%inertia
        model%rowscale(:, model%pm_elem) = 1.0_wp

        call build_body_effects(spec, model%len, model%effects)
        if (size(model%effects) > 0) then
            model%bodies%n = n
            model%bodies%l = model%len
            allocate (model%bodies%c(2, n), model%bodies%phi(n), model%bodies%v(2, n), &
                      model%bodies%w(n), model%ejac(3, 6, n))
        end if

        ! supports: base anchor and angle, prescribed motion
        model%motion(1)%p0 = model%top_anchor
        model%motion(1)%angle0 = model%top_angle
        if (bottom_anchor_given(spec)) then
            model%bottom_anchor = spec%supports%bottom_anchor
        else
            ! the rope's lower end in its initial state
            allocate (y0(6*n))
            call model%initial_state(y0)
            model%bottom_anchor = y0(6*n - 5:6*n - 4) + 0.5_wp*model%len(n)* &
                                  [cos(y0(6*n - 3)), sin(y0(6*n - 3))]
        end if
        model%motion(2)%p0 = model%bottom_anchor
        model%motion(2)%angle0 = model%bottom_angle
        ! a free or released support has no motion
        if (spec%effects%support_motion) call configure_motions(spec, &
            [spec%supports%top /= 'free', spec%supports%bottom /= 'free'] .and. &
            model%release > 0.0_wp, model%motion, model%moving)
        model%timed = any(model%moving) .or. any(model%release < huge(1.0_wp))
        model%with_work = any_does_work(model%moving, model%effects)

        allocate (model%s(n + 1), model%grad(6, n + 1), model%force(n + 1), model%gen(3, n))
        model%s = 0.0_wp
        model%grad = 0.0_wp
        model%force = 0.0_wp
        model%gen = 0.0_wp
    contains
        subroutine add(kind, first, last, c, b, end)
            integer, intent(in) :: kind, first, last
            real(wp), intent(in) :: c, b
            integer, intent(in), optional :: end
            nf = nf + 1
            fams(nf) = family_t(kind=kind, first=first, last=last, c=c, b=b, &
                                damped=damped .and. b > 0.0_wp)
            if (present(end)) fams(nf)%end = end
        end subroutine add
    end subroutine rfem_create

    !> Supports at time t: anchors, angles and their rates from the prescribed motions; the
    !! families of released supports switched off. Once per call, never per element.
    subroutine set_time(self, t)
        class(rfem_t), intent(inout) :: self
        real(wp), intent(in) :: t
        type(motion_state_t) :: ms
        integer :: f, k
        if (.not. self%timed) return
        do k = 1, 2
            if (.not. self%moving(k)) cycle
            ms = self%motion(k)%state(t)
            if (k == 1) then
                self%top_anchor = ms%p
                self%top_angle = ms%angle
            else
                self%bottom_anchor = ms%p
                self%bottom_angle = ms%angle
            end if
            self%anchor_vel(:, k) = ms%v
            self%angle_rate(k) = ms%rate
        end do
        do f = 1, size(self%families)
            associate (fam => self%families(f))
                if (fam%end == 0) cycle
                fam%active = t < self%release(fam%end)
                if (.not. self%moving(fam%end)) cycle
                ! ds/dt at fixed q: top strains are u . (A_1 - P), phi_1 - psi; bottom
                ! strains u . (P - B_n), psi - phi_n
                select case (fam%kind)
                case (FAM_TOP_X)
                    fam%st = -self%anchor_vel(1, 1)
                case (FAM_TOP_Y)
                    fam%st = -self%anchor_vel(2, 1)
                case (FAM_TOP_ROT)
                    fam%st = -self%angle_rate(1)
                case (FAM_BOTTOM_X)
                    fam%st = self%anchor_vel(1, 2)
                case (FAM_BOTTOM_Y)
                    fam%st = self%anchor_vel(2, 2)
                case (FAM_BOTTOM_ROT)
                    fam%st = self%angle_rate(2)
                end select
            end associate
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

    !> 1: the dissipated energy; 2 (when supports move or effects do work): external work.
    pure integer function rfem_quad_size(self)
        class(rfem_t), intent(in) :: self
        rfem_quad_size = merge(2, 1, self%with_work)
    end function rfem_quad_size

    pure integer function rfem_n_elements(self)
        class(rfem_t), intent(in) :: self
        rfem_n_elements = self%n
    end function rfem_n_elements

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

    !> The mass matrix of the coordinates: diag(m_i, m_i, J_i), plus the translation-rotation
    !! coupling s n_i of elements with point masses off their centre.
    subroutine rfem_coordinate_mass(self, y, mm)
        class(rfem_t), intent(in) :: self
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: mm(:, :)
        integer :: i, k
        mm = 0.0_wp
        do i = 1, self%n
            k = 3*(i - 1)
            mm(k + 1, k + 1) = self%mass(i)
            mm(k + 2, k + 2) = self%mass(i)
            mm(k + 3, k + 3) = self%inertia(i)
        end do
        ! point masses off the element centres couple translation and rotation: s n
        do i = 1, size(self%pm_elem)
            k = 3*(self%pm_elem(i) - 1)
            mm(k + 1:k + 2, k + 3) = self%pm_moment(i)* &
                [-sin(y(6*self%pm_elem(i) - 3)), cos(y(6*self%pm_elem(i) - 3))]
            mm(k + 3, k + 1:k + 2) = mm(k + 1:k + 2, k + 3)
        end do
    end subroutine rfem_coordinate_mass
end module ropedyn_rfem
