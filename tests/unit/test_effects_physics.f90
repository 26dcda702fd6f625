!> One physics check per effect (docs/theory/effects.md):
!! - drag: the terminal speed of a falling horizontal rope against the balance of weight and
!!   quadratic drag; with linear drag and a current, the drift velocity (lambda g / c_n, u);
!! - ground: a rope sliding along the ground carries its weight in contact force and stops
!!   after v0^2/(2 mu g) (Coulomb friction); a body lying on it gets the distributed law's
!!   force and moments (k l delta, k l^3/12 per radian, c l^3/12 per rad/s); the Jacobian
!!   of a body touching with a part equals central differences, also where the part's end
!!   moves with the state;
!! - moving support: the work of a shaken top equals the energy change of an undamped rope
!!   (RFEM and MPP);
!! - release: a folded rope with one end released falls with tip acceleration > g and the
!!   fall distance of the energy-conserving chain theory (Calkin & March);
!! - point mass: a tip mass lowers the swing frequency to the value of a heavy chain with
!!   a tip mass (Bessel functions) and of a compound-pendulum estimate (RFEM and MPP);
!! - all effects at once: T + V + dissipated - external work = E0 over a run.
!! Bounds are about three times the larger of the values measured with the Debug and the
!! Release build (CVODE at the rtol given; printed by each check): e.g. the drag balances
!! 8.0e-9 and 3.9e-8 J, the every-effect balance 3.1e-8 (RFEM, Release 8.0e-8) and 6.5e-8 of
!! the energy moved (docs/development/testing.md). Without the quadratures' error control the drag
!! balances reach 4.1e-8 and 2.3e-7 J and fail.
program test_effects_physics
    use ropedyn_kinds, only: wp
    use ropedyn_test_run, only: run_t, simulate_scene => simulate, kind_set, SET_LEN
    use ropedyn_effect, only: bodies_t, set_axes
    use ropedyn_effect_ground, only: ground_effect_t, ground_effect
    use ropedyn_assert, only: test_suite_t
    implicit none

    type(test_suite_t) :: suite
    real(wp), parameter :: pi = acos(-1.0_wp), g = 9.81_wp
    !> weight per length of the paper's rope, N/m, and its mass, kg
    real(wp), parameter :: lam = 6000.0_wp*pi*0.005_wp**2/4.0_wp, rope_mass = lam

    suite%name = 'effects_physics'
    call drag_terminal_speed()
    call ground_friction()
    call ground_lying_body()
    call ground_tilted_body()
    call ground_moving_ends('landing', 0.3_wp, 0.7_wp, 1)
    call ground_moving_ends('leaving', -0.3_wp, 0.7_wp, 2)
    call shaken_top('rfem')
    call shaken_top('mpp')
    call folded_fall()
    call tip_mass('rfem')
    call tip_mass('mpp')
    call every_effect_balance('rfem')
    call every_effect_balance('mpp')
    call suite%finish()

contains

    !> The scene of defaults (the paper's rope) plus `sets`, integrated with CVODE to t_end
    !! and recorded every dt (ropedyn_test_run); a failure is a failed check.
    subroutine simulate(sets, t_end, dt, rtol, run)
        character(len=*), intent(in) :: sets(:)
        real(wp), intent(in) :: t_end, dt, rtol
        type(run_t), intent(out) :: run
        call simulate_scene(sets, t_end, dt, rtol, run, scene_file='test_effects_physics.nml')
        if (.not. run%ok) call suite%check_true(.false., run%message)
    end subroutine simulate

    !> Element fields (centre x, y, angle and rates) of record k.
    subroutine fields_at(run, k, q, qdot)
        type(run_t), intent(in) :: run
        integer, intent(in) :: k
        real(wp), allocatable, intent(out) :: q(:, :), qdot(:, :)
        allocate (q(3, run%model%n_elements()), qdot(3, run%model%n_elements()))
        call run%model%fields(run%y(:, k), q, qdot, run%t(k))
    end subroutine fields_at

    !> The free tip (last polyline point) of record k.
    function tip_at(run, k) result(tip)
        type(run_t), intent(in) :: run
        integer, intent(in) :: k
        real(wp) :: tip(2)
        real(wp) :: points(2, 2*run%model%n_elements())
        call run%model%polyline(run%y(:, k), points, run%t(k))
        tip = points(:, size(points, 2))
    end function tip_at

    !> A horizontal rope with free ends falls in water: every element reaches
    !! sqrt(2 lambda g / (rho C_n d)) (normal drag balancing the weight). With linear drag
    !! and a current along the rope, the rope drifts at (lambda g / c_n, u_y).
    subroutine drag_terminal_speed()
        type(run_t) :: run
        real(wp), allocatable :: q(:, :), qdot(:, :)
        real(wp) :: v_term
        character(len=64), parameter :: base(*) = [character(len=64) :: 'model.elements = 6', &
            'supports.top = "free"', 'initial.angle_deg = 90', 'effects.drag = .true.']
        call simulate([character(len=64) :: base, 'fluid.density = 1000', &
            'fluid.normal_drag_coefficient = 1.2'], 0.6_wp, 0.1_wp, 1.0e-7_wp, run)
        if (.not. run%ok) return
        call fields_at(run, ubound(run%t, 1), q, qdot)
        v_term = sqrt(2.0_wp*lam*g/(1000.0_wp*1.2_wp*0.005_wp))
        write (*, '(a, 2f12.7, a)') '  drag: speed', maxval(qdot(1, :)), v_term, ' m/s'
        call suite%check_le(maxval(abs(qdot(1, :) - v_term))/v_term, 5.0e-8_wp, &
                            'drag: terminal speed = sqrt(2 lambda g/(rho C_n d))')
        call suite%check_le(abs(run%e(ubound(run%e, 1))%balance() - run%e(0)%balance()), &
                            3.0e-8_wp, 'drag: energy balance')

        call simulate([character(len=64) :: base, 'fluid.density = 0', &
            'fluid.linear_normal_drag = 2.0', 'fluid.linear_tangential_drag = 2.0', &
            'fluid.current = 0.0, 0.3'], 1.0_wp, 0.1_wp, 1.0e-7_wp, run)
        if (.not. run%ok) return
        call fields_at(run, ubound(run%t, 1), q, qdot)
        write (*, '(a, 2f12.7, a)') '  linear drag: velocity', sum(qdot(1:2, :), 2)/size(q, 2), &
            ' m/s'
        call suite%check_le(maxval(abs(qdot(1, :) - lam*g/2.0_wp)), 1.0e-7_wp, &
                            'linear drag: terminal speed = lambda g / c_n')
        call suite%check_le(maxval(abs(qdot(2, :) - 0.3_wp)), 5.0e-8_wp, &
                            'linear drag: the rope drifts with the current')
        call suite%check_le(abs(run%e(ubound(run%e, 1))%balance() - run%e(0)%balance()), &
                            1.5e-7_wp, 'linear drag with current: T + V + dissipated - W = E0')
    end subroutine drag_terminal_speed

    !> A rope lying on the ground slides along its length at 1 m/s: Coulomb friction stops
    !! it after v0^2/(2 mu g); at rest the contact forces carry its weight.
    subroutine ground_friction()
        type(run_t) :: run
        type(ground_effect_t) :: ground
        type(bodies_t) :: b
        real(wp), allocatable :: q(:, :), qdot(:, :), q0(:, :), qdot0(:, :), len(:), mass(:)
        real(wp) :: slide, expected, normal_force, weight, mu
        integer :: last, n
        mu = 0.3_wp
        call simulate([character(len=64) :: 'model.elements = 10', 'supports.top = "free"', &
            'supports.top_anchor = 1.0, 0.0', 'initial.angle_deg = 90', &
            'initial.velocity = 0.0, 1.0', 'effects.ground = .true.', &
            'ground.point = 1.0, 0.0', 'ground.stiffness = 1e5', 'ground.damping = 200', &
            'ground.friction_coefficient = 0.3', 'ground.friction_regularization_speed = 1e-3'], &
            0.6_wp, 0.05_wp, 1.0e-7_wp, run)
        if (.not. run%ok) return
        last = ubound(run%t, 1)
        call fields_at(run, 0, q0, qdot0)
        call fields_at(run, last, q, qdot)
        n = size(q, 2)
        allocate (len(n), mass(n))
        call run%model%element_data(len, mass)
        slide = sum(mass*(q(2, :) - q0(2, :)))/sum(mass)
        expected = 1.0_wp/(2.0_wp*mu*g)
        write (*, '(a, 2f12.7, a)') '  ground: slide', slide, expected, ' m'
        call suite%check_close(slide, expected, 1.0e-4_wp, 0.0_wp, &
                               'ground: sliding distance = v0^2/(2 mu g)')
        ! at rest to the tolerance (atol 1e-9 m/s): what is left is the integrator's error,
        ! which follows the step sequence and so the last bits of the forces and the Newton
        ! path: 5.4e-15 m/s (first-order Newton) and 7.0e-12 m/s (reduced) with the old
        ! kernels, 2.4e-12 m/s with the one-pass kernels (first-order Newton); the bound is
        ! about 3 times the largest measured
        call suite%check_le(maxval(abs(qdot(1:2, :))), 2.0e-11_wp, 'ground: the rope comes to rest')
        ground = ground_effect([1.0_wp, 0.0_wp], [-1.0_wp, 0.0_wp], 1.0e5_wp, 200.0_wp, mu, &
                               1.0e-3_wp)
        b%n = n
        b%c = q(1:2, :)
        b%phi = q(3, :)
        b%v = qdot(1:2, :)
        b%w = qdot(3, :)
        b%l = len
        call set_axes(b)
        normal_force = ground%total_normal_force(b)
        weight = sum(mass)*g
        write (*, '(a, 2f12.8, a)') '  ground: contact force, weight', normal_force, weight, ' N'
        call suite%check_close(normal_force, weight, 5.0e-11_wp, 0.0_wp, &
                               'ground: the contact forces carry the weight')
        call suite%check_le(abs(run%e(last)%balance() - run%e(0)%balance()), 1.5e-9_wp, &
                            'ground: T + V + dissipated = E0 (friction and contact damping)')
    end subroutine ground_friction

    !> One body of length l lying on the ground (along y, x down), its centre delta below the
    !! plane: the contact is the per-metre law integrated along the body, force k l delta up;
    !! tilted by dphi, the moment -k l^3/12 dphi; turning at w, the moment -c l^3/12 w. (At
    !! the body's end points the moments would be three times these.)
    subroutine ground_lying_body()
        real(wp), parameter :: k = 1.0e5_wp, c = 200.0_wp, l = 0.2_wp, delta = 1.0e-4_wp
        type(ground_effect_t) :: ground
        type(bodies_t) :: b
        real(wp) :: f(2, 1), m(1), dphi, w
        ground = ground_effect([1.0_wp, 0.0_wp], [-1.0_wp, 0.0_wp], k, c, 0.3_wp, 1.0e-3_wp)
        b%n = 1
        b%c = reshape([1.0_wp + delta, 0.5_wp], [2, 1])
        b%v = reshape([0.0_wp, 0.0_wp], [2, 1])
        b%l = [l]
        dphi = 1.0e-4_wp
        w = 0.0_wp
        call lying_forces(ground, b, dphi, w, f, m)
        write (*, '(a, 2es14.6, a)') '  ground: lying body, force and tilt moment', f(1, 1), m(1)
        call suite%check_close(f(1, 1), -k*l*delta, 1.0e-12_wp, 0.0_wp, &
                               'ground: a lying body carries k l delta')
        call suite%check_close(m(1), -k*l**3/12.0_wp*dphi, 1.0e-6_wp, 0.0_wp, &
                               'ground: the tilt moment of a lying body is k l^3/12 dphi')
        dphi = 0.0_wp
        w = 0.05_wp
        call lying_forces(ground, b, dphi, w, f, m)
        write (*, '(a, es14.6, a)') '  ground: lying body turning, moment', m(1), ' N m'
        call suite%check_close(m(1), -c*l**3/12.0_wp*w, 1.0e-6_wp, 0.0_wp, &
                               'ground: the damping moment of a lying body is c l^3/12 w')
    end subroutine ground_lying_body

    !> One body of length l, tilted by theta so that only its end B is below the plane, by
    !! p: the law integrated over the part below, r in [r0, l/2] (r0 = l/2 - p/sin theta),
    !! gives the force k p^2/(2 sin theta), the moment cos theta k int r delta dr about the
    !! centre and the springs' energy k p^3/(6 sin theta). Here p/sin theta < 0.21 l: both
    !! Gauss points of the whole body are above the plane, and a rule at fixed points
    !! would let the end (a joint of the rope) sink freely.
    subroutine ground_tilted_body()
        real(wp), parameter :: k = 1.0e5_wp, c = 200.0_wp, l = 0.2_wp, p = 1.0e-3_wp, &
                               theta = 0.1_wp
        type(ground_effect_t) :: ground
        type(bodies_t) :: b
        real(wp) :: f(2, 1), m(1), a, r0, h, moment
        ground = ground_effect([1.0_wp, 0.0_wp], [-1.0_wp, 0.0_wp], k, c, 0.3_wp, 1.0e-3_wp)
        a = sin(theta)
        h = 0.5_wp*l
        r0 = h - p/a
        b%n = 1
        b%c = reshape([1.0_wp + p - h*a, 0.5_wp], [2, 1])
        b%v = reshape([0.0_wp, 0.0_wp], [2, 1])
        b%l = [l]
        call lying_forces(ground, b, -theta, 0.0_wp, f, m)
        moment = cos(theta)*k*a*((h**3 - r0**3)/3.0_wp - r0*(h**2 - r0**2)/2.0_wp)
        write (*, '(a, 3es14.6, a)') '  ground: tilted body, force, moment, energy', f(1, 1), &
            m(1), ground%energy(0.0_wp, b), ' (N, N m, J)'
        call suite%check_close(f(1, 1), -k*p**2/(2.0_wp*a), 1.0e-12_wp, 0.0_wp, &
                               'ground: a body touching with its end carries k p^2/(2 sin theta)')
        call suite%check_close(m(1), moment, 1.0e-10_wp, 0.0_wp, &
                               'ground: the moment of a body touching with its end')
        call suite%check_close(ground%energy(0.0_wp, b), k*p**3/(6.0_wp*a), 1.0e-12_wp, &
                               0.0_wp, 'ground: the springs of a body touching with its end')
    end subroutine ground_tilted_body

    !> A body tilted by 0.1 rad with one end 1 mm below the plane, sinking at v_x (x is
    !! down) and turning at w: the ground's Jacobian (add_jacobian) against central
    !! differences of its force and moment. Landing (v_x > 0) the force acts on all the part
    !! below the plane, whose end, where delta = 0, carries f = c delta' > 0 and moves with
    !! the body; leaving (v_x < 0) the force ends inside that part, where k delta + c delta'
    !! = 0. The end's motion is part of the Jacobian: without it the landing body's differs
    !! by a third of its largest entry (at an end where f = 0 the integrand vanishes, and the
    !! term is almost nothing). `end_kind` is the kind of end the case must have.
    subroutine ground_moving_ends(label, vx, w, end_kind)
        character(len=*), intent(in) :: label
        real(wp), intent(in) :: vx, w
        integer, intent(in) :: end_kind
        real(wp), parameter :: k = 1.0e5_wp, c = 200.0_wp, l = 0.2_wp, p = 1.0e-3_wp, &
                               theta = 0.1_wp
        real(wp), parameter :: steps(6) = [1.0e-8_wp, 1.0e-8_wp, 1.0e-7_wp, 1.0e-6_wp, &
                                           1.0e-6_wp, 1.0e-6_wp]
        type(ground_effect_t) :: ground
        type(bodies_t) :: b
        real(wp) :: z(6), jac(3, 6, 1), fd(3, 6), gp(3), gm(3), worst, scale, full
        integer :: col
        ground = ground_effect([1.0_wp, 0.0_wp], [-1.0_wp, 0.0_wp], k, c, 0.3_wp, 5.0e-2_wp)
        z = [1.0_wp + p - 0.5_wp*l*sin(theta), 0.5_wp, 0.5_wp*pi - theta, vx, 0.2_wp, w]
        call body_state(b, z, l)
        jac = 0.0_wp
        call ground%add_jacobian(0.0_wp, b, jac)
        do col = 1, 6
            call body_state(b, z + steps(col)*unit(col), l)
            gp = generalized(ground, b)
            call body_state(b, z - steps(col)*unit(col), l)
            gm = generalized(ground, b)
            fd(:, col) = (gp - gm)/(2.0_wp*steps(col))
        end do
        scale = maxval(abs(fd))
        worst = maxval(abs(jac(:, :, 1) - fd))/scale
        full = maxval(abs(fd(1:2, 1)))
        write (*, '(a, 2es11.3)') '  ground: '//label//' body, largest entry, jacobian - '// &
            'differences (relative)', scale, worst
        call suite%check_true(ground_end_kind(z, l) == end_kind, 'ground: the '// &
                              label//' body''s force interval ends where the case says')
        call suite%check_true(full > 0.0_wp, 'ground: the '//label//' body is in contact')
        call suite%check_le(worst, 1.0e-6_wp, 'ground: jacobian of a '//label//' body '// &
                            '(its force interval''s end moving) = central differences')
    end subroutine ground_moving_ends

    !> The j-th unit vector of six.
    pure function unit(j) result(u)
        integer, intent(in) :: j
        real(wp) :: u(6)
        u = 0.0_wp
        u(j) = 1.0_wp
    end function unit

    !> One body of length l at z = (x, y, phi, v_x, v_y, w).
    subroutine body_state(b, z, l)
        type(bodies_t), intent(inout) :: b
        real(wp), intent(in) :: z(6), l
        b%n = 1
        b%c = reshape(z(1:2), [2, 1])
        b%phi = [z(3)]
        b%v = reshape(z(4:5), [2, 1])
        b%w = [z(6)]
        b%l = [l]
        call set_axes(b)
    end subroutine body_state

    !> The ground's (F_x, F_y, M) on the one body of b.
    function generalized(ground, b) result(gen)
        type(ground_effect_t), intent(in) :: ground
        type(bodies_t), intent(in) :: b
        real(wp) :: gen(3), f(2, 1), m(1)
        f = 0.0_wp
        m = 0.0_wp
        call ground%add_forces(0.0_wp, b, f, m)
        gen = [f(:, 1), m(1)]
    end function generalized

    !> 1: the body's force interval ends at the plane (delta = 0) with a force there; 2: it
    !! ends where k delta + c delta' = 0, inside the part below the plane. From the
    !! per-metre law along the body at z (the plane x = 1, x down), independently of the
    !! effect's own search.
    integer function ground_end_kind(z, l) result(kind)
        real(wp), intent(in) :: z(6), l
        real(wp) :: e(2), nv(2), r0, rate0
        e = [cos(z(3)), sin(z(3))]
        nv = [-e(2), e(1)]
        ! delta(r) = x(r) - 1 along the body; its zero r0, and delta' there
        r0 = (1.0_wp - z(1))/e(1)
        rate0 = z(4) + z(6)*r0*nv(1)
        kind = merge(1, 2, rate0 > 0.0_wp)
        if (abs(r0) > 0.5_wp*l) kind = 0
    end function ground_end_kind

    !> The ground's force f and moment m on body b turned by dphi from lying along y and
    !! turning at w.
    subroutine lying_forces(ground, b, dphi, w, f, m)
        type(ground_effect_t), intent(in) :: ground
        type(bodies_t), intent(inout) :: b
        real(wp), intent(in) :: dphi, w
        real(wp), intent(out) :: f(:, :), m(:)
        b%phi = [0.5_wp*pi + dphi]
        b%w = [w]
        call set_axes(b)
        f = 0.0_wp
        m = 0.0_wp
        call ground%add_forces(0.0_wp, b, f, m)
    end subroutine lying_forces

    !> An undamped rope whose top is shaken (2 Hz, 1 cm and 2 cm): the work of the support
    !! equals the change of T + V.
    subroutine shaken_top(kind)
        character(len=*), intent(in) :: kind
        type(run_t) :: run
        real(wp) :: worst, work, de
        integer :: k
        call simulate([character(len=SET_LEN) :: kind_set(kind), 'model.elements = 8', &
            'initial.shape = "hanging"', 'effects.damping = .false.', &
            'supports.top_motion = "harmonic"', 'supports.top_amplitude = 0.01, 0.02', &
            'supports.top_frequency = 2.0'], 1.0_wp, 0.02_wp, 1.0e-8_wp, run)
        if (.not. run%ok) return
        worst = 0.0_wp
        work = 0.0_wp
        do k = 1, ubound(run%t, 1)
            work = max(work, abs(run%e(k)%support_work))
            de = run%e(k)%total() - run%e(0)%total()
            worst = max(worst, abs(de - run%e(k)%support_work))
        end do
        write (*, '(a, 3es11.3, a)') '  shaken '//kind//': final T+V-E0, work, worst mismatch', &
            run%e(ubound(run%e, 1))%total() - run%e(0)%total(), &
            run%e(ubound(run%e, 1))%support_work, worst, ' J'
        call suite%check_true(work > 1.0e-3_wp, kind//': the shaken top does work')
        call suite%check_le(worst/work, merge(1.0e-5_wp, 5.0e-8_wp, kind == 'rfem'), &
                            kind//': support work = change of T + V '// &
                            '(undamped, shaken top)')
    end subroutine shaken_top

    !> Folded rope (both halves hanging from the top, bending off as for a chain), the free
    !! end released at t = 0: the tip falls faster than g (theory: x = 0.04946, 0.20363 m
    !! at 0.1, 0.2 s; a/g = 1.288 at 0.2 s).
    subroutine folded_fall()
        type(run_t) :: run
        real(wp) :: x(0:60), a_rel, tip(2), tip0(2)
        integer :: k
        call simulate([character(len=64) :: 'model.elements = 41', 'supports.bottom = "pinned"', &
            'supports.bottom_release_time = 0', 'initial.shape = "folded"', &
            'effects.bending = .false.'], 0.3_wp, 0.005_wp, 1.0e-7_wp, run)
        if (.not. run%ok) return
        tip0 = tip_at(run, 0)
        do k = 0, 60
            tip = tip_at(run, k)
            x(k) = tip(1) - tip0(1)
        end do
        write (*, '(a, 3f10.5, a)') '  folded: tip fall at 0.1, 0.2, 0.3 s', x(20), x(40), &
            x(60), ' m (theory 0.04946, 0.20363, 0.48980)'
        call suite%check_close(x(20), 0.04946_wp, 0.01_wp, 0.0_wp, 'folded: fall at 0.1 s')
        call suite%check_close(x(40), 0.20363_wp, 0.01_wp, 0.0_wp, 'folded: fall at 0.2 s')
        call suite%check_close(x(60), 0.48980_wp, 0.02_wp, 0.0_wp, 'folded: fall at 0.3 s')
        a_rel = (x(42) - 2.0_wp*x(40) + x(38))/(0.01_wp**2*g)
        write (*, '(a, f8.4, a)') '  folded: a/g at 0.2 s', a_rel, ' (theory 1.288)'
        call suite%check_true(a_rel > 1.15_wp, 'folded: tip acceleration > g')
        call suite%check_true(x(60) > 0.5_wp*g*0.3_wp**2, 'folded: faster than free fall')
        call suite%check_le(abs(run%e(60)%balance() - run%e(0)%balance()), &
                            2.0e-8_wp, 'folded: T + V + dissipated = E0')
    end subroutine folded_fall

    !> A tip mass equal to the rope's mass: the small-swing frequency against the heavy
    !! chain with a tip mass (continuum, EI = 0: J2(xi_a) Y0(xi_L) = Y2(xi_a) J0(xi_L),
    !! xi = 2 omega sqrt(z/g), z_a = m_p/lambda, z_L = L + z_a) and the compound-pendulum
    !! estimate omega^2 = g (M/2 + m_p) / (L (M/3 + m_p)).
    subroutine tip_mass(kind)
        character(len=*), intent(in) :: kind
        type(run_t) :: run
        real(wp) :: crossings(8), y_prev, y_now, omega, chain, compound, tc, tip_prev(2), tip(2)
        integer :: k, nc
        character(len=64) :: mass_key
        write (mass_key, '(a, es24.16)') 'attachments.masses = ', rope_mass
        call simulate([character(len=SET_LEN) :: kind_set(kind), 'model.elements = 10', &
            'initial.angle_deg = 2', 'attachments.mass_positions = 1.0', mass_key], &
            5.5_wp, 0.005_wp, 1.0e-7_wp, run)
        if (.not. run%ok) return
        nc = 0
        tip_prev = tip_at(run, 0)
        do k = 1, ubound(run%t, 1)
            tip = tip_at(run, k)
            y_prev = tip_prev(2)
            y_now = tip(2)
            if (y_prev < 0.0_wp .and. y_now >= 0.0_wp .and. nc < size(crossings)) then
                tc = run%t(k - 1) + (run%t(k) - run%t(k - 1))*(-y_prev)/(y_now - y_prev)
                nc = nc + 1
                crossings(nc) = tc
            end if
            tip_prev = tip
        end do
        call suite%check_true(nc >= 3, kind//': tip mass: two full swings')
        if (nc < 2) return
        omega = 2.0_wp*pi*real(nc - 1, wp)/(crossings(nc) - crossings(1))
        chain = chain_with_tip_mass(rope_mass)
        compound = sqrt(g*(rope_mass/2.0_wp + rope_mass)/(rope_mass/3.0_wp + rope_mass))
        write (*, '(a, 4f11.6, a)') '  '//kind//' tip mass: omega, chain+tip, compound, '// &
            'bare chain', omega, chain, compound, chain_with_tip_mass(0.0_wp), ' rad/s'
        call suite%check_close(omega, chain, 3.0e-3_wp, 0.0_wp, &
                               kind//': tip mass: omega = heavy chain with tip mass')
        call suite%check_close(omega, compound, 1.0e-2_wp, 0.0_wp, &
                               kind//': tip mass: omega = compound-pendulum estimate')
        call suite%check_true(omega < 0.9_wp*chain_with_tip_mass(0.0_wp), &
                              kind//': the tip mass lowers the frequency')
    end subroutine tip_mass

    !> First frequency of a hanging chain (L = 1, weight lambda g per length) with a tip mass
    !! m_p (rad/s), by bisection of the Bessel determinant.
    real(wp) function chain_with_tip_mass(mp) result(omega)
        real(wp), intent(in) :: mp
        real(wp) :: lo, hi, mid
        integer :: it
        lo = 2.5_wp
        hi = 3.9_wp
        do it = 1, 100
            mid = 0.5_wp*(lo + hi)
            if (bessel_det(lo, mp)*bessel_det(mid, mp) <= 0.0_wp) then
                hi = mid
            else
                lo = mid
            end if
        end do
        omega = 0.5_wp*(lo + hi)
    end function chain_with_tip_mass

    !> The frequency determinant of the chain with a tip mass at omega = w.
    real(wp) function bessel_det(w, mp) result(det)
        real(wp), intent(in) :: w, mp
        real(wp) :: a, xa, xl
        a = mp/lam
        xl = 2.0_wp*w*sqrt((1.0_wp + a)/g)
        if (a <= 0.0_wp) then
            det = bessel_j0(xl)
        else
            xa = 2.0_wp*w*sqrt(a/g)
            det = bessel_jn(2, xa)*bessel_y0(xl) - bessel_yn(2, xa)*bessel_j0(xl)
        end if
    end function bessel_det

    !> Every effect at once (damping, drag with a current, ground contact with friction,
    !! point loads, point masses, a shaken clamped top, a pinned bottom following a
    !! harmonic motion): T + V + dissipated - external work stays E0.
    subroutine every_effect_balance(kind)
        character(len=*), intent(in) :: kind
        type(run_t) :: run
        real(wp) :: worst, scale
        integer :: k
        call simulate([character(len=SET_LEN) :: kind_set(kind), 'model.elements = 7', &
            'effects.drag = .true.', 'effects.ground = .true.', 'fluid.density = 1000', &
            'fluid.current = 0.1, -0.2', 'ground.point = 0.2, 0.0', &
            'ground.normal = -1.0, 0.2', 'ground.stiffness = 1e4', &
            'ground.friction_regularization_speed = 0.01', &
            'attachments.mass_positions = 0.4, 1.0', 'attachments.masses = 0.02, 0.05', &
            'attachments.load_positions = 0.7', 'attachments.load_force_y = 0.2', &
            'attachments.load_amplitude_x = 0.3', 'attachments.load_frequency = 3', &
            'supports.top = "clamped"', 'supports.top_motion = "harmonic"', &
            'supports.top_amplitude = 0.01, 0.02', 'supports.top_frequency = 2', &
            'supports.top_angle_amplitude_deg = 3', 'supports.bottom = "pinned"', &
            'supports.bottom_anchor = 0.25, 0.9', 'supports.bottom_motion = "harmonic"', &
            'supports.bottom_amplitude = 0.0, 0.02', 'supports.bottom_frequency = 1'], &
            0.5_wp, 0.01_wp, 1.0e-8_wp, run)
        if (.not. run%ok) return
        worst = 0.0_wp
        scale = 0.0_wp
        do k = 1, ubound(run%t, 1)
            worst = max(worst, abs(run%e(k)%balance() - run%e(0)%balance()))
            scale = max(scale, abs(run%e(k)%dissipated) + abs(run%e(k)%support_work))
        end do
        write (*, '(a, 3es11.3, a)') '  '//kind//' every effect: dissipated, work, balance '// &
            'error', run%e(ubound(run%e, 1))%dissipated, run%e(ubound(run%e, 1))%support_work, &
            worst, ' J'
        call suite%check_true(run%e(ubound(run%e, 1))%dissipated > 0.0_wp .and. &
                              abs(run%e(ubound(run%e, 1))%support_work) > 0.0_wp, &
                              kind//': every effect: energy is dissipated and work is done')
        ! the balance error is the integrator's (rtol 1e-8): measured 2.6e-7 of `scale` (mpp,
        ! since the clamp's rotational spring is 2 EI/l: a stiffer turning clamp), bound ~4x
        call suite%check_le(worst, 1.0e-6_wp*scale, kind//': every effect: T + V + '// &
                            'dissipated - work = E0')
    end subroutine every_effect_balance
end program test_effects_physics
