!> The multiple physical pendulum (MPP) rope model: n identical members, each a massless
!! spring (elongation u_i) followed by a uniform rigid rod (length l = L/n, mass m = M/n),
!! joined by elastic-dissipative joints; Lagrange's equations M(q) q'' = f(t, q, q').
!! Derivation and parameter rules: docs/theory/mpp.md.
!!
!! Coordinates q = (phi_1 .. phi_n, u_1 .. u_nu) with nu = n (extensible, &effects
!! tension = .true.) or nu = 0 (inextensible members). State y = (q, q').
!! Joint positions P_i = P_0 + sum_{k<=i} (l + u_k) e_k, rod centres
!! C_i = P_{i-1} + (u_i + l/2) e_i, e_k = (cos phi_k, sin phi_k), n_k = de_k/dphi_k.
!!
!! The whole dynamics is one O(n) routine, the Lagrange residual
!!     r(q, q', q'') = Q(q, q') - sum_i m J_i^T C_i'' - J phi'' ,   J_i = dC_i/dq,
!! so that f = r(q, q', 0) and M q'' = f - r(q, q', q''). The explicit right-hand side
!! solves M(q) q'' = f in O(n) as well: M is the mass matrix of a chain whose members hang
!! from the previous joint by a translation only (the angles are absolute), so the tip-to-
!! root recursion of articulated-body inertias (2x2 per joint) factors it and two sweeps
!! solve (mass_factor, ab_solve; docs/theory/mpp.md). The dense M(q) is assembled (O(n^2),
!! cos/sin of each angle once) only for the implicit form and the modal analysis.
!!
!! External effects (drag, ground contact, point loads; ropedyn_effect) act on the rods as
!! bodies: w_i gains the body force, r[phi_i] the body moment. Point masses sit at their
!! place on a rod (they enter the residual like the rods' own inertia, and M(q) as
!! m_p J_p^T J_p). The top joint may follow a prescribed motion P_0(t) (its acceleration
!! starts the prefix sums); the bottom support may move or be released.
!!
!! In water (&effects water) each rod also carries the water's added mass
!! (ropedyn_added_mass): its inertia becomes m I + A_i(q) (2x2) in translation and J + J_a,i
!! in rotation, and its force gains the added mass's g_i; the residual, the O(n) solve, the
!! dense M(q), the energy and the tangent take them (submodule ropedyn_mpp_water).
!!
!! This module builds the model and maps its state (creation, supports, joint positions);
!! the residual and mass matrix kernels are in the submodule ropedyn_mpp_kernels, their
!! tangent in ropedyn_mpp_tangent, the energies and powers in ropedyn_mpp_energy.
module ropedyn_mpp
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use ropedyn_kinds, only: wp, PI
    use ropedyn_error, only: error_t, make_error, ERR_INPUT
    use ropedyn_problem, only: STATUS_OK, STATUS_RECOVERABLE
    use ropedyn_rope_model, only: rope_model_t, energy_t
    use ropedyn_rope_spec, only: rope_spec_t, bottom_anchor_given, release_time, released_at_start
    use ropedyn_effect, only: effect_box_t, bodies_t, add_forces_of, add_jacobians_of, &
                              add_energies_of, add_forces_powers_of, set_axes, &
                              add_level_energies_of
    use ropedyn_effect_factory, only: build_body_effects, attached_masses, water_added_mass
    use ropedyn_added_mass, only: added_mass_t
    use ropedyn_support_motion, only: motion_state_t
    use ropedyn_rope_section, only: section_t, rope_section
    use ropedyn_rope_setup, only: initial_angle, clamp_angles, &
                                  configure_motions, any_does_work
    implicit none
    private
    public :: mpp_t, mpp_create


    type, extends(rope_model_t) :: mpp_t
        private
        integer :: nu = 0           !< spring coordinates (n or 0)
        integer :: ndof = 0         !< n + nu
        real(wp) :: l = 0.0_wp      !< member length, m
        real(wp) :: m = 0.0_wp      !< member mass, kg
        real(wp) :: inertia = 0.0_wp  !< rod inertia about its centre (with rotary inertia), kg m^2
        real(wp) :: g = 0.0_wp      !< gravity, m/s^2 (0 when off)
        real(wp) :: ks = 0.0_wp, ds = 0.0_wp  !< member spring stiffness N/m, damping N s/m
        !> each member's (n): ks, ds but the last next to a pinned bottom with
        !! supports%end_compliance = 'split' (twice)
        real(wp), allocatable :: ksj(:), dsj(:)
        real(wp) :: cb = 0.0_wp, db = 0.0_wp  !< joint bending stiffness N m, damping N m s
        logical :: top_clamped = .false.
        integer :: bottom = 0       !< 0 free, 1 pinned, 2 clamped
        real(wp) :: k_sup = 0.0_wp, d_sup = 0.0_wp    !< bottom pin spring and damper
        real(wp) :: c_rot = 0.0_wp, d_rot = 0.0_wp    !< support rotational spring and damper
        real(wp) :: top_anchor(2) = 0.0_wp, bottom_anchor(2) = 0.0_wp
        real(wp) :: top_angle = 0.0_wp, bottom_angle = 0.0_wp
        real(wp) :: init_angle = 0.0_wp
        logical :: folded = .false.    !< initial shape 'folded' (n odd)
        ! supports (1 top joint, 2 bottom): base anchors and angles in top_anchor, ...;
        ! their motions: rope_model_t%motion
        real(wp) :: bottom_release = huge(1.0_wp)  !< s
        type(effect_box_t), allocatable :: effects(:)
        !> in water (&effects water): the rods' added mass (submodule ropedyn_mpp_water)
        logical :: water = .false.
        type(added_mass_t) :: added
        ! point masses: rod, offset from the rod's centre along it (m), mass (kg)
        integer, allocatable :: pm_body(:)
        real(wp), allocatable :: pm_r(:), pm_m(:)
        ! per rod with its point masses: mass (kg), first and second moment of the point
        ! masses about the rod's centre (kg m, kg m^2)
        real(wp), allocatable :: mbar(:), pm_s1(:), pm_s2(:)
        ! workspace, allocated once (no state is kept between calls)
        real(wp), allocatable :: cs(:, :)     !< cos, sin of the angles (2, n)
        real(wp), allocatable :: w(:, :)      !< applied-minus-inertial force on the rods (2, n)
        real(wp), allocatable :: cacc(:, :)   !< rod centre accelerations (2, n)
        real(wp), allocatable :: mom(:)       !< moments on the rods (n)
        !> suffix sums sum_{i>=k} w_i + F_b (2, n+1), column n+1 the bottom support's force
        real(wp), allocatable :: wsum(:, :)
        !> the moments of the joints' and the clamps' rotational springs and dampers (0:n),
        !! joint k between members k and k+1 (0, n: the supports), docs/theory/internal-forces.md
        real(wp), allocatable :: jmom(:)
        !> the lower end P_n and its velocity at the last residual_core, m and m/s
        real(wp) :: tip(2) = 0.0_wp, tipd(2) = 0.0_wp
        type(bodies_t) :: bodies              !< the rods as bodies for the effects
        real(wp), allocatable :: ejac(:, :, :)  !< the effects' (and the water's) blocks (3, 6, n)
        !> in water: the rods' added-mass blocks (3x3 on centre and angle) at the state of the
        !! last residual_core (3, 3, n)
        real(wp), allocatable :: wblk(:, :, :)
        !> factors of M(q) (mass_factor): per member the 2x2 blocks G, H = D^{-1} G^T,
        !! D^{-1} (rows and columns: angle, elongation) and the member length lambda
        real(wp), allocatable :: ab_g(:, :, :), ab_h(:, :, :), ab_dinv(:, :, :), ab_lam(:)
        real(wp), allocatable :: acc(:)       !< accelerations M^{-1} f (ndof)
        real(wp), allocatable :: r0(:)        !< the residual at them (ndof)
        real(wp), allocatable :: dr(:, :)     !< d r(q, q', acc)/d(q, q') (ndof, 2 ndof)
        real(wp), allocatable :: mm(:, :)     !< M(q) (ndof, ndof)
    contains
        procedure :: size => mpp_size
        procedure :: bandwidths => mpp_bandwidths
        procedure :: rhs => mpp_rhs
        procedure :: has_jacobian => mpp_has_jacobian
        procedure :: jacobian => mpp_jacobian
        procedure :: has_mass_matrix => mpp_has_mass_matrix
        procedure :: mass_matrix => mpp_mass_matrix
        procedure :: implicit_rhs => mpp_implicit_rhs
        procedure :: energy => mpp_energy
        procedure :: quad_rhs => mpp_quad_rhs
        procedure :: rhs_quad => mpp_rhs_quad
        procedure :: model_name => mpp_model_name
        procedure :: initial_state => mpp_initial_state
        procedure :: fields => mpp_fields
        procedure :: state_from_fields => mpp_state_from_fields
        procedure :: polyline => mpp_polyline
        procedure :: element_data => mpp_element_data
        procedure :: internal_forces => mpp_internal_forces
        procedure :: support_positions => mpp_support_positions
        procedure :: residual => mpp_residual
        procedure :: mass_dense => mpp_mass_dense
        procedure :: coordinates => mpp_coordinates
        procedure :: coordinate_mass => mpp_coordinate_mass
        procedure :: angle_coordinates => mpp_angle_coordinates
        procedure :: second_order_blocks => mpp_second_order_blocks
        procedure, private :: positions
        procedure, private :: supports_at, bottom_pin_spring
        procedure, private :: residual_core
        procedure, private :: residual_column
        procedure, private :: mass_factor
        procedure, private :: derivatives
    end type mpp_t

    interface
        !> Split y into angles, elongations and their rates (elongations 0 if inextensible).
        module pure subroutine unpack(self, y, phi, u, phid, ud)
            class(mpp_t), intent(in) :: self
            real(wp), intent(in) :: y(:)
            real(wp), intent(out) :: phi(:), u(:), phid(:), ud(:)
        end subroutine unpack

        !> The Lagrange residual r = Q(q, q') - sum_i m J_i^T C_i''(q, q', q'') - J phi''
        !! (and the point masses' inertia) for the generalized accelerations qacc (size ndof)
        !! at time t (default 0), O(n). `pin`: the force of the top joint on the rope (N),
        !! meaningful when qacc are the true accelerations.
        module subroutine mpp_residual(self, y, qacc, r, t, pin)
            class(mpp_t), intent(inout) :: self
            real(wp), intent(in) :: y(:)
            real(wp), intent(in) :: qacc(:)
            real(wp), intent(out) :: r(:)
            real(wp), intent(in), optional :: t
            real(wp), intent(out), optional :: pin(2)
        end subroutine mpp_residual

        !> The residual with self%cs holding cos and sin of the angles of y (mpp_residual
        !! without that step; the Jacobian calls it at the accelerations and takes its tangent
        !! from what it leaves: residual_column).
        !! With `powers`, the effects' dissipation and work rates (W) are added to it, from
        !! the same pass as their forces.
        module subroutine residual_core(self, t, y, qacc, r, pin, powers)
            class(mpp_t), intent(inout) :: self
            real(wp), intent(in) :: t
            real(wp), intent(in) :: y(:)
            real(wp), intent(in) :: qacc(:)
            real(wp), intent(out) :: r(:)
            real(wp), intent(out), optional :: pin(2)
            real(wp), intent(inout), optional :: powers(2)
        end subroutine residual_core

        !> mpp_rhs; with `powers`, the effects' dissipation and work rates (W) at (t, y) are
        !! added to it (residual_core).
        module subroutine rhs_powers(self, t, y, ydot, status, powers)
            class(mpp_t), intent(inout) :: self
            real(wp), intent(in) :: t
            real(wp), intent(in) :: y(:)
            real(wp), intent(out) :: ydot(:)
            integer, intent(out) :: status
            real(wp), intent(inout), optional :: powers(2)
        end subroutine rhs_powers

        !> The force of the top joint on the rope (N) at the accelerations qacc, the last
        !! residual_core having been at y with zero accelerations (O(n), no effect again).
        module pure function pin_force(self, y, qacc) result(pin)
            class(mpp_t), intent(in) :: self
            real(wp), intent(in) :: y(:)
            real(wp), intent(in) :: qacc(:)
            real(wp) :: pin(2)
        end function pin_force

        !> cos and sin of every angle of y into self%cs, once per call.
        module subroutine angles(self, y)
            class(mpp_t), intent(inout) :: self
            real(wp), intent(in) :: y(:)
        end subroutine angles

        !> Solve M x = b in place with the model's current factors (mass_factor).
        module subroutine mass_solve(self, b)
            class(mpp_t), intent(in) :: self
            real(wp), intent(inout) :: b(:)
        end subroutine mass_solve

        !> The rods as bodies (centre, angle, their rates, length l) for the effects.
        pure module subroutine rod_bodies(self, y, top, b)
            class(mpp_t), intent(in) :: self
            real(wp), intent(in) :: y(:)
            type(motion_state_t), intent(in) :: top
            type(bodies_t), intent(out) :: b
        end subroutine rod_bodies

        !> Column j of d r(q, q', qacc)/d(q, q') (j <= ndof: coordinate j, else rate j - ndof),
        !! exact: the tangent of residual_core, O(n), from the quantities its last call left
        !! (self%w, mom, cacc, wsum, bodies) and the effects' blocks self%ejac.
        module subroutine residual_column(self, t, y, qacc, j, col)
            class(mpp_t), intent(inout) :: self
            real(wp), intent(in) :: t
            real(wp), intent(in) :: y(:)
            real(wp), intent(in) :: qacc(:)
            integer, intent(in) :: j
            real(wp), intent(out) :: col(:)
        end subroutine residual_column

        !> Factor M(q) (self%cs holding the angles of y; in water self%wblk the added-mass
        !! blocks, as residual_core at y leaves them): the articulated-body recursion from
        !! the tip into self%ab_*; ab_solve then solves M x = b in O(n). status is
        !! STATUS_RECOVERABLE when a pivot is not positive (an impossible configuration).
        module subroutine mass_factor(self, y, status)
            class(mpp_t), intent(inout) :: self
            real(wp), intent(in) :: y(:)
            integer, intent(out) :: status
        end subroutine mass_factor

        !> At (t, y): cos/sin, the factors of M, the accelerations self%acc = M^{-1} f, the
        !! residual self%r0 there and self%dr = d r(q, q', acc)/d(q, q'), exact (the tangent
        !! of the O(n) residual, column by column: O(n^2)); with `solved`, M^{-1} applied to
        !! its columns (da/d(q, q'), the explicit system's rows). STATUS_RECOVERABLE when a
        !! factor or a column is not finite.
        module subroutine derivatives(self, t, y, solved, status)
            class(mpp_t), intent(inout) :: self
            real(wp), intent(in) :: t
            real(wp), intent(in) :: y(:)
            logical, intent(in) :: solved
            integer, intent(out) :: status
        end subroutine derivatives

        !> The dense mass matrix M(q) (ndof x ndof), O(n^2); in water with the added mass of
        !! the rods placed with the top joint at time t (default 0).
        module pure subroutine mpp_mass_dense(self, y, mm, t)
            class(mpp_t), intent(in) :: self
            real(wp), intent(in) :: y(:)
            real(wp), intent(out) :: mm(:, :)
            real(wp), intent(in), optional :: t
        end subroutine mpp_mass_dense

        !> In water: the added mass's force on every rod at the accelerations qacc (self%bodies
        !! and self%cacc as residual_core fills them), w_i += g_i - A_i C_i'', moment
        !! += g_i(3) - J_a,i phi_i'', and the blocks into self%wblk (submodule
        !! ropedyn_mpp_water).
        module subroutine water_forces(self, qacc)
            class(mpp_t), intent(inout) :: self
            real(wp), intent(in) :: qacc(:)
        end subroutine water_forces

        !> In water: add to self%ejac every rod's 3x6 block of d(g - blk acc)/d(centre, angle,
        !! velocity, rate) at fixed accelerations (qacc, self%cacc of the last residual_core).
        module subroutine water_jacobian(self, qacc)
            class(mpp_t), intent(inout) :: self
            real(wp), intent(in) :: qacc(:)
        end subroutine water_jacobian

        !> In water: the added mass's kinetic energy and the current's potential of the rods
        !! as bodies b, J.
        module pure subroutine water_energy(self, b, kinetic, potential)
            class(mpp_t), intent(in) :: self
            type(bodies_t), intent(in) :: b
            real(wp), intent(out) :: kinetic, potential
        end subroutine water_energy

        !> In water: add the rods' added mass sum_i J_i^T blk_i J_i to the dense mm at (t, y).
        module pure subroutine water_mass_dense(self, t, y, mm)
            class(mpp_t), intent(in) :: self
            real(wp), intent(in) :: t
            real(wp), intent(in) :: y(:)
            real(wp), intent(inout) :: mm(:, :)
        end subroutine water_mass_dense

        !> y' = (q', M^{-1} f): f = r(q, q', 0), solved in O(n) (mass_factor, ab_solve).
        module subroutine mpp_rhs(self, t, y, ydot, status)
            class(mpp_t), intent(inout) :: self
            real(wp), intent(in) :: t
            real(wp), intent(in) :: y(:)
            real(wp), intent(out) :: ydot(:)
            integer, intent(out) :: status
        end subroutine mpp_rhs

        !> F = (q', f(q, q')) of the implicit form M(y) y' = F, O(n).
        module subroutine mpp_implicit_rhs(self, t, y, f, status)
            class(mpp_t), intent(inout) :: self
            real(wp), intent(in) :: t
            real(wp), intent(in) :: y(:)
            real(wp), intent(out) :: f(:)
            integer, intent(out) :: status
        end subroutine mpp_implicit_rhs

        !> blockdiag(I, M(q)) in band storage (the band is the full matrix).
        module subroutine mpp_mass_matrix(self, t, y, mb, offset, status)
            class(mpp_t), intent(inout) :: self
            real(wp), intent(in) :: t
            real(wp), intent(in) :: y(:)
            real(wp), intent(inout) :: mb(:, :)
            integer, intent(in) :: offset
            integer, intent(out) :: status
        end subroutine mpp_mass_matrix

        !> Jacobian of y' = (q', a), a = M^{-1} f. With a0 = a(y) held fixed, M a = f gives
        !! da/dz = M^{-1} d r(q, q', a0)/dz (z = q or q'), exact: each column of the
        !! residual's tangent is O(n) (residual_column), then an O(n) solve per column:
        !! O(n^2) in all.
        module subroutine mpp_jacobian(self, t, y, jb, offset, status)
            class(mpp_t), intent(inout) :: self
            real(wp), intent(in) :: t
            real(wp), intent(in) :: y(:)
            real(wp), intent(inout) :: jb(:, :)
            integer, intent(in) :: offset
            integer, intent(out) :: status
        end subroutine mpp_jacobian

        !> The blocks of the rate rows (dense, kl = ku = ndof - 1). Explicit form: the rows of
        !! the Jacobian, K = M^{-1} dr/dq, C = M^{-1} dr/dq', mass block I. Implicit form
        !! (M(q) q'' = f): K = dr(q, q', a)/dq = df/dq - d(M(q) a)/dq at the current
        !! accelerations a = M^{-1} f, C = df/dq', and M(q), so that M - g C - g^2 K is the
        !! exact reduced Newton matrix of the implicit form.
        module subroutine mpp_second_order_blocks(self, t, y, implicit_form, kb, cb, mb, &
                                                  offset, status)
            class(mpp_t), intent(inout) :: self
            real(wp), intent(in) :: t
            real(wp), intent(in) :: y(:)
            logical, intent(in) :: implicit_form
            real(wp), intent(inout) :: kb(:, :), cb(:, :), mb(:, :)
            integer, intent(in) :: offset
            integer, intent(out) :: status
        end subroutine mpp_second_order_blocks

        !> The internal forces (submodule ropedyn_mpp_forces): the suffix sums of the
        !! residual at the true accelerations resolved in the frame of the member below the
        !! joint (joint n: member n), the joints' moments of the residual.
        module subroutine mpp_internal_forces(self, t, y, axial, shear, moment, reaction)
            class(mpp_t), intent(inout) :: self
            real(wp), intent(in) :: t
            real(wp), intent(in) :: y(:)
            real(wp), intent(out) :: axial(0:), shear(0:), moment(0:)
            real(wp), intent(out) :: reaction(:, :)
        end subroutine mpp_internal_forces

        !> The anchors at time t (submodule ropedyn_mpp_forces).
        module subroutine mpp_support_positions(self, t, positions)
            class(mpp_t), intent(in) :: self
            real(wp), intent(in) :: t
            real(wp), intent(out) :: positions(:, :)
        end subroutine mpp_support_positions

        module function mpp_energy(self, t, y, yq) result(en)
            class(mpp_t), intent(inout) :: self
            real(wp), intent(in) :: t
            real(wp), intent(in) :: y(:)
            real(wp), intent(in) :: yq(:)
            type(energy_t) :: en
        end function mpp_energy

        !> Dissipation power 2D (W) and, with moving supports or working effects, the external
        !! power (W): the top joint's force on the rope (from the residual at the true
        !! accelerations) times its velocity, the support springs' forces and moments times
        !! their anchors' rates, and the effects' work rate.
        module subroutine mpp_quad_rhs(self, t, y, yqdot, status)
            class(mpp_t), intent(inout) :: self
            real(wp), intent(in) :: t
            real(wp), intent(in) :: y(:)
            real(wp), intent(out) :: yqdot(:)
            integer, intent(out) :: status
        end subroutine mpp_quad_rhs

        !> mpp_rhs and mpp_quad_rhs in one call: the quadratures take the rods as bodies,
        !! the tip, the residual at zero accelerations and the factors of M the right-hand
        !! side leaves, and the pin force at the accelerations it solved for (pin_force; the
        !! same numbers as the two calls).
        module subroutine mpp_rhs_quad(self, t, y, ydot, yqdot, status)
            class(mpp_t), intent(inout) :: self
            real(wp), intent(in) :: t
            real(wp), intent(in) :: y(:)
            real(wp), intent(out) :: ydot(:)
            real(wp), intent(out) :: yqdot(:)
            integer, intent(out) :: status
        end subroutine mpp_rhs_quad
    end interface

contains

    subroutine mpp_create(model, spec, err)
        type(mpp_t), intent(out) :: model
        type(rope_spec_t), intent(in) :: spec
        type(error_t), allocatable, intent(out) :: err
        type(section_t) :: sec

        model%n = spec%model%elements
        if (model%n < 2) then
            call make_error(err, ERR_INPUT, 'mpp: elements must be >= 2')
            return
        end if
        if (spec%supports%top == 'free') then
            call make_error(err, ERR_INPUT, 'mpp: the top support must be pinned or clamped')
            return
        end if
        sec = rope_section(spec%rope)
        call set_members(model, spec, sec)
        call set_support_springs(model, spec, sec)
        call set_anchors(model, spec)
        call set_masses(model, spec)
        call set_support_motion(model, spec)
        call allocate_work(model)
    end subroutine mpp_create

    !> The members: degrees of freedom, length, mass, inertia, gravity, and the springs and
    !! dampers of the joints.
    subroutine set_members(model, spec, sec)
        type(mpp_t), intent(inout) :: model
        type(rope_spec_t), intent(in) :: spec
        type(section_t), intent(in) :: sec
        real(wp) :: total_mass
        model%nu = merge(model%n, 0, spec%effects%tension)
        model%tension_only = .not. spec%rope%compression
        model%ndof = model%n + model%nu
        total_mass = sec%mass_per_length*spec%rope%length
        model%l = spec%rope%length/real(model%n, wp)
        model%m = total_mass/real(model%n, wp)
        model%inertia = model%m*(model%l**2/12.0_wp + sec%diameter**2/16.0_wp)
        model%g = merge(spec%rope%gravity, 0.0_wp, spec%effects%gravity)
        model%ks = sec%ea/model%l
        if (spec%effects%bending) model%cb = sec%ei/model%l
        if (spec%effects%damping) then
            model%ds = spec%model%mpp_axial_damping_factor*sec%axial_damping/model%l
            if (spec%effects%bending) model%db = spec%model%mpp_bending_damping_factor* &
                                                  sec%bending_damping/model%l
        end if
    end subroutine set_members

    !> The supports' springs and dampers (the rope's own, times the factor; a clamp's
    !! rotational one lumps a half member) and, with end_compliance = 'split', the last
    !! member shared with the bottom pin.
    subroutine set_support_springs(model, spec, sec)
        type(mpp_t), intent(inout) :: model
        type(rope_spec_t), intent(in) :: spec
        type(section_t), intent(in) :: sec
        real(wp) :: factor
        logical :: free_from_start
        factor = spec%supports%support_stiffness_factor
        ! a bottom released at t = 0 is free (set_support_motion): it shares no section
        free_from_start = released_at_start(spec, 2)
        model%top_clamped = spec%supports%top == 'clamped'
        select case (spec%supports%bottom)
        case ('pinned')
            model%bottom = 1
        case ('clamped')
            model%bottom = 2
        case default
            model%bottom = 0
        end select
        ! Supports take the values of the rope's own springs (as in RFEM), times the factor.
        model%k_sup = factor*sec%ea/model%l
        ! A clamp's rotational spring lumps the half member [0, l/2] that no joint covers
        ! (joint i, at s = i l, lumps [(i - 1/2) l, (i + 1/2) l]): 2 EI/l, so the bending
        ! compliance adds up to L/EI (EI/l would add l/(2 EI): a first-order error, -0.09 %
        ! on omega_1 at n = 300 in its pre-asymptotic range). Damping alike.
        model%c_rot = 2.0_wp*factor*sec%ei/model%l
        if (spec%effects%damping) then
            model%d_sup = factor*sec%axial_damping/model%l
            model%d_rot = 2.0_wp*factor*sec%bending_damping/model%l
        end if

        ! The members' springs (EA/l) cover [0, L]; the top pin is ideal, but the bottom
        ! pin's spring adds one member's compliance l/EA (an O(l) error, as RFEM's supports).
        ! With end_compliance = 'split' the last member is shared with it: each 2 EA/l, the
        ! compliance adds up to L/EA; the pin's half of the section damps as the member's
        ! other half, 2 d_s (with the MPP's damping factor), so that the line's axial
        ! damping stays proportional to its stiffness (docs/theory/mpp.md).
        allocate (model%ksj(model%n), model%dsj(model%n))
        model%ksj = model%ks
        model%dsj = model%ds
        if (model%bottom > 0 .and. .not. free_from_start .and. &
            spec%supports%end_compliance == 'split') then
            model%ksj(model%n) = 2.0_wp*model%ks
            model%dsj(model%n) = 2.0_wp*model%ds
            model%k_sup = 2.0_wp*model%k_sup
            if (spec%effects%damping) model%d_sup = 2.0_wp*factor*model%ds
        end if
    end subroutine set_support_springs

    !> The initial shape's angle, the anchors and the clamps' angles (a bottom anchor not
    !! given: the lower end of the initial state).
    subroutine set_anchors(model, spec)
        type(mpp_t), intent(inout) :: model
        type(rope_spec_t), intent(in) :: spec
        real(wp) :: angles(2)
        model%init_angle = initial_angle(spec)
        model%folded = spec%initial%shape == 'folded'
        model%top_anchor = spec%supports%top_anchor
        angles = clamp_angles(spec)
        model%top_angle = angles(1)
        model%bottom_angle = angles(2)
        if (bottom_anchor_given(spec)) then
            model%bottom_anchor = spec%supports%bottom_anchor
        else
            ! the lower end P_n of the initial state (the top anchor when folded)
            model%bottom_anchor = model%top_anchor + spec%rope%length* &
                                  [cos(model%init_angle), sin(model%init_angle)]
            if (model%folded) model%bottom_anchor = model%top_anchor + [0.0_wp, model%l]
        end if
    end subroutine set_anchors

    !> Point masses on the members (their sums m, m r, m r^2 per member), the effects on
    !! the members and the added mass in water.
    subroutine set_masses(model, spec)
        type(mpp_t), intent(inout) :: model
        type(rope_spec_t), intent(in) :: spec
        integer :: k
        call attached_masses(spec, [(model%l, k = 1, model%n)], model%pm_body, model%pm_r, &
                             model%pm_m)
        allocate (model%mbar(model%n), model%pm_s1(model%n), model%pm_s2(model%n))
        model%mbar = model%m
        model%pm_s1 = 0.0_wp
        model%pm_s2 = 0.0_wp
        do k = 1, size(model%pm_body)
            associate (i => model%pm_body(k))
                model%mbar(i) = model%mbar(i) + model%pm_m(k)
                model%pm_s1(i) = model%pm_s1(i) + model%pm_m(k)*model%pm_r(k)
                model%pm_s2(i) = model%pm_s2(i) + model%pm_m(k)*model%pm_r(k)**2
            end associate
        end do
        call build_body_effects(spec, [(model%l, k = 1, model%n)], model%effects)
        model%water = spec%effects%water
        if (model%water) model%added = water_added_mass(spec)
        if (size(model%effects) > 0 .or. model%water) then
            model%bodies%n = model%n
            allocate (model%bodies%c(2, model%n), model%bodies%v(2, model%n), &
                      model%bodies%phi(model%n), model%bodies%w(model%n), &
                      model%bodies%cs(2, model%n))
            model%bodies%l = [(model%l, k = 1, model%n)]
        end if
    end subroutine set_masses

    !> The supports' prescribed motions (the top joint is never free; a free or released
    !! bottom has none) and whether the model does work.
    subroutine set_support_motion(model, spec)
        type(mpp_t), intent(inout) :: model
        type(rope_spec_t), intent(in) :: spec
        model%motion(1)%p0 = model%top_anchor
        model%motion(1)%angle0 = model%top_angle
        model%motion(2)%p0 = model%bottom_anchor
        model%motion(2)%angle0 = model%bottom_angle
        if (spec%effects%support_motion) then
            model%bottom_release = release_time(spec, 2)
            if (released_at_start(spec, 2)) model%bottom = 0
            ! the top joint is never free; a free or released bottom has no motion
            call configure_motions(spec, [.true., model%bottom > 0], model%motion, model%moving)
        end if
        model%with_work = any_does_work(model%moving, model%effects)
    end subroutine set_support_motion

    !> The work arrays of the right-hand side and its Jacobian, zeroed.
    subroutine allocate_work(model)
        type(mpp_t), intent(inout) :: model
        associate (n => model%n, nd => model%ndof)
            allocate (model%cs(2, n), model%w(2, n), model%cacc(2, n), model%mom(n), &
                      model%ab_g(2, 2, n), model%ab_h(2, 2, n), model%ab_dinv(2, 2, n), &
                      model%ab_lam(n), model%acc(nd), model%r0(nd), model%dr(nd, 2*nd), &
                      model%mm(nd, nd), model%wsum(2, n + 1), model%ejac(3, 6, n), &
                      model%jmom(0:n), model%wblk(3, 3, n))
        end associate
        model%cs = 0.0_wp
        model%w = 0.0_wp
        model%cacc = 0.0_wp
        model%mom = 0.0_wp
        model%ab_g = 0.0_wp
        model%ab_h = 0.0_wp
        model%ab_dinv = 0.0_wp
        model%ab_lam = 0.0_wp
        model%acc = 0.0_wp
        model%r0 = 0.0_wp
        model%dr = 0.0_wp
        model%mm = 0.0_wp
        model%wsum = 0.0_wp
        model%ejac = 0.0_wp
        model%jmom = 0.0_wp
        model%wblk = 0.0_wp
    end subroutine allocate_work

    !> The supports at time t: top joint, bottom anchor (motion states) and whether the
    !! bottom support still holds. At rest (statics): no velocities, accelerations, rates.
    pure subroutine supports_at(self, t, top, bottom, bottom_on)
        class(mpp_t), intent(in) :: self
        real(wp), intent(in) :: t
        type(motion_state_t), intent(out) :: top, bottom
        logical, intent(out) :: bottom_on
        if (self%moving(1)) then
            top = self%motion(1)%state(t)
        else
            top%p = self%top_anchor
            top%angle = self%top_angle
        end if
        if (self%moving(2)) then
            bottom = self%motion(2)%state(t)
        else
            bottom%p = self%bottom_anchor
            bottom%angle = self%bottom_angle
        end if
        bottom_on = self%bottom > 0 .and. t < self%bottom_release
        if (self%supports_at_rest) then
            top = motion_state_t(p=top%p, angle=top%angle)
            bottom = motion_state_t(p=bottom%p, angle=bottom%angle)
        end if
    end subroutine supports_at

    pure integer function mpp_size(self)
        class(mpp_t), intent(in) :: self
        mpp_size = 2*self%ndof
    end function mpp_size

    !> M(q) and the Jacobian are dense.
    pure subroutine mpp_bandwidths(self, ml, mu)
        class(mpp_t), intent(in) :: self
        integer, intent(out) :: ml, mu
        ml = 2*self%ndof - 1
        mu = 2*self%ndof - 1
    end subroutine mpp_bandwidths

    pure function mpp_model_name(self) result(name)
        class(mpp_t), intent(in) :: self
        character(len=:), allocatable :: name
        name = 'mpp'
    end function mpp_model_name

    pure logical function mpp_has_jacobian(self)
        class(mpp_t), intent(in) :: self
        mpp_has_jacobian = .true.
    end function mpp_has_jacobian

    pure logical function mpp_has_mass_matrix(self)
        class(mpp_t), intent(in) :: self
        mpp_has_mass_matrix = .true.
    end function mpp_has_mass_matrix

    !> Length (m) and mass (kg) of each member, its point masses included (as the RFEM's
    !! element masses include theirs): the rope's m g L, the statics' weight and the run
    !! file's /rope/element_mass are the same for both models.
    subroutine mpp_element_data(self, length, mass)
        class(mpp_t), intent(in) :: self
        real(wp), intent(out) :: length(:), mass(:)
        length = self%l
        mass = self%mbar
    end subroutine mpp_element_data

    subroutine mpp_initial_state(self, y)
        class(mpp_t), intent(in) :: self
        real(wp), intent(out) :: y(:)
        y = 0.0_wp
        y(1:self%n) = self%init_angle
        ! folded (n odd): (n-1)/2 members down, the middle one horizontal (towards +y), the
        ! rest back up: two halves side by side, one member length apart
        if (self%folded) then
            y((self%n + 1)/2) = 0.5_wp*pi
            y((self%n + 3)/2:self%n) = pi
        end if
    end subroutine mpp_initial_state

    !> Joints P_0 .. P_n, rod centres C_i, and their velocities at time t (default 0).
    pure subroutine positions(self, y, p, c, pd, cd, t)
        class(mpp_t), intent(in) :: self
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: p(2, 0:self%n), c(2, self%n), pd(2, 0:self%n), cd(2, self%n)
        real(wp), intent(in), optional :: t
        real(wp), dimension(self%n) :: phi, u, phid, ud
        real(wp) :: e(2), nv(2)
        type(motion_state_t) :: top
        integer :: k
        call unpack(self, y, phi, u, phid, ud)
        p(:, 0) = self%top_anchor
        pd(:, 0) = 0.0_wp
        if (self%moving(1)) then
            top = self%motion(1)%state(0.0_wp)
            if (present(t)) top = self%motion(1)%state(t)
            p(:, 0) = top%p
            pd(:, 0) = top%v
            if (self%supports_at_rest) pd(:, 0) = 0.0_wp
        end if
        do k = 1, self%n
            e = [cos(phi(k)), sin(phi(k))]
            nv = [-e(2), e(1)]
            c(:, k) = p(:, k - 1) + (u(k) + 0.5_wp*self%l)*e
            cd(:, k) = pd(:, k - 1) + (u(k) + 0.5_wp*self%l)*phid(k)*nv + ud(k)*e
            p(:, k) = p(:, k - 1) + (self%l + u(k))*e
            pd(:, k) = pd(:, k - 1) + (self%l + u(k))*phid(k)*nv + ud(k)*e
        end do
    end subroutine positions

    !> Members as elements: rod centre, angle and their rates.
    subroutine mpp_fields(self, y, q, qdot, t)
        class(mpp_t), intent(in) :: self
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: q(:, :), qdot(:, :)
        real(wp), intent(in), optional :: t  !< s: places a moving top joint
        real(wp) :: p(2, 0:self%n), c(2, self%n), pd(2, 0:self%n), cd(2, self%n)
        call self%positions(y, p, c, pd, cd, t)
        q(1:2, :) = c
        q(3, :) = y(1:self%n)
        qdot(1:2, :) = cd
        qdot(3, :) = y(self%ndof + 1:self%ndof + self%n)
    end subroutine mpp_fields

    !> The inverse of `mpp_fields`: phi_i and its rate are stored; the elongation follows
    !! from the rod centre, C_i = P_{i-1} + (u_i + l/2) e_i, with P_i = C_i + (l/2) e_i and
    !! P_0 the top joint at t, and its rate u_i' = (C_i' - P_{i-1}') . e_i (C_i - P_{i-1} is
    !! along e_i, so e_i' = phi_i' n_i drops out), P_i' = C_i' + (l/2) phi_i' n_i.
    pure subroutine mpp_state_from_fields(self, q, qdot, t, y, ok)
        class(mpp_t), intent(in) :: self
        real(wp), intent(in) :: q(:, :), qdot(:, :)
        real(wp), intent(in) :: t  !< s: places a moving top joint
        real(wp), intent(out) :: y(:)
        logical, intent(out) :: ok
        real(wp) :: p(2, 0:self%n), c(2, self%n), pd(2, 0:self%n), cd(2, self%n)
        real(wp) :: prev(2), prevd(2), e(2), nv(2)
        integer :: k
        y = 0.0_wp
        ok = size(q, 2) == self%n .and. size(qdot, 2) == self%n .and. &
             size(y) == 2*self%ndof
        if (.not. ok) return
        call self%positions(y, p, c, pd, cd, t)
        prev = p(:, 0)
        prevd = pd(:, 0)
        do k = 1, self%n
            e = [cos(q(3, k)), sin(q(3, k))]
            nv = [-e(2), e(1)]
            y(k) = q(3, k)
            y(self%ndof + k) = qdot(3, k)
            if (self%nu > 0) then
                y(self%n + k) = dot_product(q(1:2, k) - prev, e) - 0.5_wp*self%l
                y(self%ndof + self%n + k) = dot_product(qdot(1:2, k) - prevd, e)
            end if
            prev = q(1:2, k) + 0.5_wp*self%l*e
            prevd = qdot(1:2, k) + 0.5_wp*self%l*qdot(3, k)*nv
        end do
    end subroutine mpp_state_from_fields

    !> Member i drawn from joint P_{i-1} to joint P_i (spring and rod).
    subroutine mpp_polyline(self, y, points, t)
        class(mpp_t), intent(in) :: self
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: points(:, :)
        real(wp), intent(in), optional :: t  !< s: places a moving top joint
        real(wp) :: p(2, 0:self%n), c(2, self%n), pd(2, 0:self%n), cd(2, self%n)
        integer :: i
        call self%positions(y, p, c, pd, cd, t)
        do i = 1, self%n
            points(:, 2*i - 1) = p(:, i - 1)
            points(:, 2*i) = p(:, i)
        end do
    end subroutine mpp_polyline

    !> Coordinates q = y(1..ndof) (angles, then elongations), rates y(ndof+1..2 ndof).
    pure subroutine mpp_coordinates(self, pos, vel)
        class(mpp_t), intent(in) :: self
        integer, allocatable, intent(out) :: pos(:), vel(:)
        integer :: k
        pos = [(k, k = 1, self%ndof)]
        vel = [(self%ndof + k, k = 1, self%ndof)]
    end subroutine mpp_coordinates

    !> The configuration-dependent mass matrix M(q) (mass_dense; in water with the added
    !! mass, the top joint where it is at t = 0).
    subroutine mpp_coordinate_mass(self, y, mm)
        class(mpp_t), intent(in) :: self
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: mm(:, :)
        call self%mass_dense(y, mm)
    end subroutine mpp_coordinate_mass

    !> The offset the bottom pin's spring acts on, for d = P_n - P_bottom and e the last
    !! member's axis: d, or on a line that carries tension only (stretch_floor) with the
    !! tip pushed past the anchor along the rope (s = -e.d below the floor: the end section
    !! the spring stands for is slack) d's part across the rope, u n with u = n.d; and the
    !! couple on member n of that spring's energy k u^2/2, which turns with the member:
    !! dV/dphi_n at a fixed d, k u s (0 where the spring is not slack). As the RFEM's pins
    !! (docs/theory/mpp.md, Supports).
    pure subroutine bottom_pin_spring(self, d, e, offset, couple)
        class(mpp_t), intent(in) :: self
        real(wp), intent(in) :: d(2), e(2)
        real(wp), intent(out) :: offset(2), couple
        real(wp) :: s, u
        offset = d
        couple = 0.0_wp
        s = -(e(1)*d(1) + e(2)*d(2))
        if (s < self%stretch_floor()) then
            u = e(1)*d(2) - e(2)*d(1)
            offset = u*[-e(2), e(1)]
            couple = self%k_sup*u*s
        end if
    end subroutine bottom_pin_spring

    !> The coordinates (phi_1 .. phi_n, u_1 .. u_nu): the first n are angles.
    pure function mpp_angle_coordinates(self) result(angle)
        class(mpp_t), intent(in) :: self
        logical, allocatable :: angle(:)
        integer :: k
        angle = [(k <= self%n, k = 1, self%ndof)]
    end function mpp_angle_coordinates
end module ropedyn_mpp
