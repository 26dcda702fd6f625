!> The internal forces and support reactions of the rope models (rope_model_t%
!! internal_forces; docs/theory/internal-forces.md), for RFEM and MPP:
!! - the reactions at a moving support against the whole rope's momentum balance, sum of
!!   the external forces = d/dt sum m v (the rods' centre velocities), at one state in
!!   motion, for a harmonic and a table-driven top (and a pinned bottom), to 1e-6; a
!!   released bottom: its reaction and joint forces zero after the release, the balance
!!   holding before and after;
!! - a 3-element rope at rest against a hand calculation of every joint force;
!! - the MPP's member tension against its spring law k u + d u' in motion;
!! - the tension along a hanging rope at equilibrium: w (L - s), linear in arc length;
!! - statics with a moving top: the rope hangs straight, no sideways reaction, and the
!!   model's static reactions equal the virtual-work ones (catenary, both ends pinned).
program test_internal_forces
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t
    use ropedyn_problem, only: STATUS_OK
    use ropedyn_scene, only: scene_t, read_scene
    use ropedyn_rope_model, only: rope_model_t
    use ropedyn_model_factory, only: create_model
    use ropedyn_statics, only: statics_options_t, statics_result_t, find_equilibrium
    use ropedyn_analysis, only: support_forces
    use ropedyn_assert, only: test_suite_t
    implicit none

    real(wp), parameter :: PI = 4.0_wp*atan(1.0_wp)
    real(wp), parameter :: G = 9.81_wp
    real(wp), parameter :: AREA = PI*0.005_wp**2/4.0_wp       !< m^2 (input/paper.nml)
    real(wp), parameter :: EA = 35.0e6_wp*AREA                !< N
    real(wp), parameter :: EI = 35.0e6_wp*PI*0.005_wp**4/64.0_wp  !< N m^2
    real(wp), parameter :: W_LEN = 6000.0_wp*AREA*G           !< weight per length, N/m
    type(test_suite_t) :: suite
    character(len=1024) :: source_dir
    character(len=:), allocatable :: table

    suite%name = 'internal_forces'
    call get_command_argument(1, source_dir)
    if (len_trim(source_dir) == 0) source_dir = '.'
    table = trim(source_dir)//'/input/top_motion.dat'
    call test_momentum('rfem', 'harmonic')
    call test_momentum('rfem', 'table')
    call test_momentum('mpp', 'harmonic')
    call test_momentum('mpp', 'table')
    call test_released('rfem')
    call test_released('mpp')
    call test_rfem_by_hand()
    call test_mpp_by_hand()
    call test_mpp_spring_law()
    call test_hanging_tension('rfem')
    call test_hanging_tension('mpp')
    call test_static_moving_top('rfem')
    call test_static_moving_top('mpp')
    call test_static_reactions('rfem')
    call test_static_reactions('mpp')
    call suite%finish()

contains

    subroutine scene_of(sets, scene)
        character(len=*), intent(in) :: sets(:)
        type(scene_t), intent(out) :: scene
        type(error_t), allocatable :: err
        call read_scene(trim(source_dir)//'/input/paper.nml', sets, scene, err)
        if (allocated(err)) then
            call suite%check_true(.false., err%message)
            call suite%finish()
        end if
    end subroutine scene_of

    subroutine model_of(sets, model)
        character(len=*), intent(in) :: sets(:)
        class(rope_model_t), allocatable, intent(out) :: model
        type(scene_t) :: scene
        type(error_t), allocatable :: err
        call scene_of(sets, scene)
        call create_model(scene%rope_spec_t, model, err)
        if (allocated(err)) then
            call suite%check_true(.false., err%message)
            call suite%finish()
        end if
    end subroutine model_of

    !> Total momentum sum m_i v_i of the bodies (element or rod centres) of state y at t.
    function momentum(model, t, y) result(p)
        class(rope_model_t), intent(inout) :: model
        real(wp), intent(in) :: t, y(:)
        real(wp) :: p(2)
        real(wp) :: q(3, model%n_elements()), qdot(3, model%n_elements())
        real(wp) :: lengths(model%n_elements()), masses(model%n_elements())
        call model%element_data(lengths, masses)
        call model%fields(y, q, qdot, t)
        p = matmul(qdot(1:2, :), masses)
    end function momentum

    !> A state in motion: the model's initial state (straight at 75 degrees) with every
    !! coordinate and rate moved by a fixed pattern (stretches ~ 1e-4 m, turns ~ 0.05 rad,
    !! rates ~ 0.3 m/s, 1 rad/s), so that every spring and damper works.
    subroutine moving_state(model, y)
        class(rope_model_t), intent(inout) :: model
        real(wp), allocatable, intent(out) :: y(:)
        integer, allocatable :: pos(:), vel(:)
        integer :: k
        allocate (y(model%size()))
        call model%initial_state(y)
        call model%coordinates(pos, vel)
        do k = 1, size(pos)
            y(pos(k)) = y(pos(k)) + merge(0.05_wp, 1.0e-4_wp, mod(k, 3) == 0)*sin(1.3_wp*k)
            y(vel(k)) = merge(1.0_wp, 0.3_wp, mod(k, 3) == 0)*cos(0.7_wp*k)
        end do
    end subroutine moving_state

    !> Momentum balance of the whole rope at a moving top: W + R_top + R_bottom = dp/dt,
    !! dp/dt along the motion by a fourth-order central difference of the momentum at
    !! (t + s h, y + s h y'), s = -2 .. 2 (exact for RFEM's linear momentum, O(h^4) for the
    !! MPP's rod centres). Top pinned (harmonic, phase 30 degrees: velocity and
    !! acceleration both nonzero) or clamped (the table: shift and turn), bottom pinned
    !! 0.2 mm off the lower end; n = 6, no effects but gravity and the springs.
    subroutine test_momentum(kind, motion)
        character(len=*), intent(in) :: kind, motion
        class(rope_model_t), allocatable :: model
        real(wp), allocatable :: y(:), ydot(:), axial(:), shear(:), moment(:)
        real(wp) :: t, h, reaction(2, 2), dpdt(2), external(2), weight(2), scale
        real(wp) :: lengths(6), masses(6)
        integer :: status
        character(len=96) :: sets(9)
        character(len=:), allocatable :: label

        sets(1) = 'model.kind = "'//kind//'"'
        sets(2) = 'model.elements = 6'
        sets(3) = 'supports.bottom = "pinned"'
        sets(4) = 'supports.bottom_anchor = 0.9849, 0.1738'
        sets(5) = 'initial.angle_deg = 10.0'
        if (motion == 'harmonic') then
            sets(6) = 'supports.top_motion = "harmonic"'
            sets(7) = 'supports.top_amplitude = 0.03, 0.05'
            sets(8) = 'supports.top_phase_deg = 30.0, 30.0'
            sets(9) = 'supports.top_frequency = 1.3'
            t = 0.37_wp
        else
            sets(6) = 'supports.top = "clamped"'
            sets(7) = 'supports.top_motion = "table"'
            sets(8) = 'supports.top_table = "'//table//'"'
            sets(9) = 'model.elements = 6'
            t = 0.13_wp
        end if
        call model_of(sets, model)
        call moving_state(model, y)
        allocate (ydot(size(y)), axial(0:6), shear(0:6), moment(0:6))
        call model%rhs(t, y, ydot, status)
        call model%internal_forces(t, y, axial, shear, moment, reaction)
        h = 1.0e-5_wp
        dpdt = (8.0_wp*(momentum(model, t + h, y + h*ydot) - momentum(model, t - h, y - h*ydot)) &
                - (momentum(model, t + 2*h, y + 2*h*ydot) &
                   - momentum(model, t - 2*h, y - 2*h*ydot)))/(12.0_wp*h)
        call model%element_data(lengths, masses)
        weight = [sum(masses)*G, 0.0_wp]
        external = weight + reaction(:, 1) + reaction(:, 2)
        scale = max(norm2(reaction(:, 1)), norm2(reaction(:, 2)), norm2(dpdt), weight(1))
        label = kind//', '//motion//' top: momentum balance W + R_top + R_bottom = dp/dt'
        call suite%check_true(status == STATUS_OK, label//': rhs ok')
        call suite%check_le(norm2(external - dpdt)/scale, 1.0e-6_wp, label)
        ! the tolerance is a thousandth of each reaction: the check sees an error in either
        call suite%check_le(1.0e-3_wp*scale, norm2(reaction(:, 1)), label// &
                            ': 1e-6 scale < 1e-3 |R_top|')
        call suite%check_le(1.0e-3_wp*scale, norm2(reaction(:, 2)), label// &
                            ': 1e-6 scale < 1e-3 |R_bottom|')
    end subroutine test_momentum

    !> W + R_top + R_bottom - dp/dt relative to the largest of them, at state y and time t
    !! (dp/dt as in test_momentum); the reactions out.
    real(wp) function imbalance(model, t, y, reaction) result(r)
        class(rope_model_t), intent(inout) :: model
        real(wp), intent(in) :: t, y(:)
        real(wp), intent(out) :: reaction(2, 2)
        real(wp) :: ydot(size(y)), axial(0:model%n_elements()), shear(0:model%n_elements())
        real(wp) :: moment(0:model%n_elements()), dpdt(2), weight(2), h
        real(wp) :: lengths(model%n_elements()), masses(model%n_elements())
        integer :: status
        call model%rhs(t, y, ydot, status)
        call model%internal_forces(t, y, axial, shear, moment, reaction)
        h = 1.0e-5_wp
        dpdt = (8.0_wp*(momentum(model, t + h, y + h*ydot) - momentum(model, t - h, y - h*ydot)) &
                - (momentum(model, t + 2*h, y + 2*h*ydot) &
                   - momentum(model, t - 2*h, y - 2*h*ydot)))/(12.0_wp*h)
        call model%element_data(lengths, masses)
        weight = [sum(masses)*G, 0.0_wp]
        r = norm2(weight + reaction(:, 1) + reaction(:, 2) - dpdt)/ &
            max(norm2(reaction(:, 1)), norm2(reaction(:, 2)), norm2(dpdt), weight(1))
    end function imbalance

    !> A clamped bottom released at t = 0.2 s (pinned 0.2 mm off the lower end, the top
    !! harmonic): before the release its reaction and end moment are the support's, after
    !! it they are zero and the free end carries nothing; the momentum balance holds at both
    !! times (the state of `moving_state`).
    subroutine test_released(kind)
        character(len=*), intent(in) :: kind
        class(rope_model_t), allocatable :: model
        real(wp), allocatable :: y(:)
        real(wp) :: reaction(2, 2), axial(0:6), shear(0:6), moment(0:6), r
        character(len=64) :: sets(9)
        character(len=:), allocatable :: label
        sets = [character(len=64) :: '', 'model.elements = 6', 'supports.bottom = "clamped"', &
                'supports.bottom_anchor = 0.9849, 0.1738', 'initial.angle_deg = 10.0', &
                'supports.bottom_angle_deg = 10.0', 'supports.bottom_release_time = 0.2', &
                'supports.top_motion = "harmonic"', 'supports.top_frequency = 1.3']
        sets(1) = 'model.kind = "'//kind//'"'
        call model_of(sets, model)
        call moving_state(model, y)
        label = kind//', bottom released at 0.2 s'
        r = imbalance(model, 0.1_wp, y, reaction)
        call suite%check_le(r, 1.0e-6_wp, label//': momentum balance at 0.1 s')
        call suite%check_le(1.0e-3_wp, norm2(reaction(:, 2)), label//': held at 0.1 s')
        r = imbalance(model, 0.3_wp, y, reaction)
        call suite%check_le(r, 1.0e-6_wp, label//': momentum balance at 0.3 s')
        call model%internal_forces(0.3_wp, y, axial, shear, moment, reaction)
        call suite%check_true(all(reaction(:, 2) == 0.0_wp) .and. axial(6) == 0.0_wp .and. &
                              shear(6) == 0.0_wp .and. moment(6) == 0.0_wp, label// &
                              ': no reaction, no end force at 0.3 s')
        call model%internal_forces(0.1_wp, y, axial, shear, moment, reaction)
        call suite%check_le(1.0e-9_wp, abs(moment(6)), label//': end moment at 0.1 s')
    end subroutine test_released

    !> RFEM, 3 elements (lengths dl/2, dl, dl/2, dl = L/2), at rest in a deformed state:
    !! angles (0, a, 0), the centres placed so that the SDEs are stretched and sheared,
    !! top clamped at the origin (angle 0), bottom pinned at P. Every joint's forces by
    !! hand: SDE j (joints 1, 2) in the frame of the element above, d = A_b - B_a,
    !! tension EA/dl e.d, shear GA/(chi dl) n.d, moment 2 EI/dl (phi_2 - phi_1) at the
    !! clamp's neighbour and EI/dl (phi_3 - phi_2) at the other; the clamp's d = A_1 - 0
    !! (its reaction -EA/dl d, its moment 2 EI/dl (phi_1 - 0)); the bottom pin's
    !! d = P - B_3 (reaction EA/dl d). At rest the dampers do nothing.
    subroutine test_rfem_by_hand()
        class(rope_model_t), allocatable :: model
        real(wp) :: y(18), phi(3), c(2, 3), h(3), e(2, 3), nv(2, 3), d(2), p(2)
        real(wp) :: axial(0:3), shear(0:3), moment(0:3), reaction(2, 2), dl, ct, cs, cb
        real(wp) :: want(3, 0:3), want_r(2, 2), got(3, 0:3)
        integer :: i, j
        character(len=80) :: label
        character(len=*), parameter :: what(3) = [character(len=6) :: 'axial', 'shear', 'moment']

        call model_of([character(len=64) :: 'model.elements = 3', 'supports.top = "clamped"', &
                       'supports.bottom = "pinned"', 'supports.bottom_anchor = 1.0003, 0.002'], &
                      model)
        dl = 0.5_wp
        ct = EA/dl
        cs = 14.0e6_wp*AREA/((10.0_wp/9.0_wp)*dl)
        cb = EI/dl
        h = [dl/4, dl/2, dl/4]
        phi = [0.01_wp, 0.03_wp, -0.02_wp]
        c(:, 1) = [h(1) + 1.0e-4_wp, 2.0e-4_wp]
        c(:, 2) = [2*h(1) + h(2) + 3.0e-4_wp, -1.0e-4_wp]
        c(:, 3) = [2*h(1) + 2*h(2) + h(3) + 2.0e-4_wp, 5.0e-4_wp]
        y = 0.0_wp
        do i = 1, 3
            y(6*i - 5:6*i - 4) = c(:, i)
            y(6*i - 3) = phi(i)
            e(:, i) = [cos(phi(i)), sin(phi(i))]
            nv(:, i) = [-sin(phi(i)), cos(phi(i))]
        end do
        call model%internal_forces(0.0_wp, y, axial, shear, moment, reaction)
        ! the clamp at the origin: d = A_1 - 0, the rope's force on it ct d, in element 1's frame
        d = c(:, 1) - h(1)*e(:, 1)
        want(:, 0) = [ct*dot_product(e(:, 1), d), ct*dot_product(nv(:, 1), d), 2*cb*phi(1)]
        want_r(:, 1) = -ct*d
        do j = 1, 2
            d = (c(:, j + 1) - h(j + 1)*e(:, j + 1)) - (c(:, j) + h(j)*e(:, j))
            want(:, j) = [ct*dot_product(e(:, j), d), cs*dot_product(nv(:, j), d), &
                          merge(2.0_wp, 1.0_wp, j == 1)*cb*(phi(j + 1) - phi(j))]
        end do
        p = [1.0003_wp, 0.002_wp]
        d = p - (c(:, 3) + h(3)*e(:, 3))
        want(:, 3) = [ct*dot_product(e(:, 3), d), ct*dot_product(nv(:, 3), d), 0.0_wp]
        want_r(:, 2) = ct*d
        got(1, :) = axial
        got(2, :) = shear
        got(3, :) = moment
        do j = 0, 3
            do i = 1, 3
                write (label, '(a, i0, a)') 'rfem 3 elements at rest, joint ', j, ': '// &
                    trim(what(i))//' by hand'
                call suite%check_close(got(i, j), want(i, j), 1.0e-12_wp, 1.0e-12_wp, &
                                       trim(label))
            end do
        end do
        do j = 1, 2
            do i = 1, 2
                write (label, '(a, i0, a, i0, a)') 'rfem 3 elements at rest, reaction ', j, &
                    ' component ', i, ' by hand'
                call suite%check_close(reaction(i, j), want_r(i, j), 1.0e-12_wp, 1.0e-12_wp, &
                                       trim(label))
            end do
        end do
    end subroutine test_rfem_by_hand

    !> MPP, 3 extensible members (l = L/3, mass m), top clamped at the origin (angle 0),
    !! bottom free, at rest. Hanging straight with u_k = (4 - k) m g/k_s, the exact
    !! equilibrium: joint k - 1 carries the weight of members k .. 3, (4 - k) m g, no shear,
    !! no moment; the top's reaction (-3 m g, 0). Bent (angles 0.02, -0.01, 0.03): the
    !! clamp's moment 2 EI/l (phi_1 - 0), the joints' EI/l (phi_{k+1} - phi_k), 0 at the
    !! free end; the tension k_s u_k (the springs at rest).
    subroutine test_mpp_by_hand()
        class(rope_model_t), allocatable :: model
        real(wp) :: y(12), axial(0:3), shear(0:3), moment(0:3), reaction(2, 2), l, m, ks
        real(wp) :: phi(3), want(0:3)
        integer :: j
        character(len=80) :: label

        call model_of([character(len=64) :: 'model.kind = "mpp"', 'model.elements = 3', &
                       'supports.top = "clamped"'], model)
        l = 1.0_wp/3
        m = 6000.0_wp*AREA*l
        ks = EA/l
        y = 0.0_wp
        y(4:6) = [3, 2, 1]*m*G/ks
        call model%internal_forces(0.0_wp, y, axial, shear, moment, reaction)
        want = [3, 2, 1, 0]*m*G
        do j = 0, 3
            write (label, '(a, i0, a)') 'mpp 3 members hanging at rest, joint ', j, &
                ': tension = weight below'
            call suite%check_close(axial(j), want(j), 1.0e-10_wp, 1.0e-14_wp, trim(label))
            write (label, '(a, i0, a)') 'mpp 3 members hanging at rest, joint ', j, &
                ': no shear, no moment'
            call suite%check_le(max(abs(shear(j)), abs(moment(j))), 1.0e-12_wp, trim(label))
        end do
        call suite%check_close(reaction(1, 1), -3*m*G, 1.0e-10_wp, 0.0_wp, &
                               'mpp 3 members hanging at rest: top reaction -W')
        call suite%check_le(maxval(abs([reaction(2, 1), reaction(:, 2)])), 1.0e-14_wp, &
                            'mpp 3 members hanging at rest: no other reaction')
        phi = [0.02_wp, -0.01_wp, 0.03_wp]
        y(1:3) = phi
        call model%internal_forces(0.0_wp, y, axial, shear, moment, reaction)
        want = [2*EI/l*phi(1), EI/l*(phi(2) - phi(1)), EI/l*(phi(3) - phi(2)), 0.0_wp]
        do j = 0, 3
            write (label, '(a, i0, a)') 'mpp 3 members bent at rest, joint ', j, &
                ': moment by hand'
            call suite%check_close(moment(j), want(j), 1.0e-12_wp, 1.0e-15_wp, trim(label))
        end do
        do j = 0, 2
            write (label, '(a, i0, a)') 'mpp 3 members bent at rest, joint ', j, &
                ': tension = k_s u of the member below'
            call suite%check_close(axial(j), ks*y(4 + j), 1.0e-9_wp, 0.0_wp, trim(label))
        end do
    end subroutine test_mpp_by_hand

    !> Extensible MPP in motion (a harmonic top, the state of `moving_state`): the axial
    !! force at joint k - 1, from the suffix sums at the true accelerations, equals member
    !! k's spring and damper, k_s u_k + d_s u_k' (d_s = factor eta A/l).
    subroutine test_mpp_spring_law()
        class(rope_model_t), allocatable :: model
        real(wp), allocatable :: y(:)
        real(wp) :: axial(0:5), shear(0:5), moment(0:5), reaction(2, 2), l, ks, ds, spring
        integer :: k
        character(len=80) :: label

        call model_of([character(len=64) :: 'model.kind = "mpp"', 'model.elements = 5', &
                       'supports.top_motion = "harmonic"', &
                       'supports.top_amplitude = 0.03, 0.05', 'supports.top_frequency = 1.3', &
                       'model.mpp_axial_damping_factor = 0.5'], model)
        call moving_state(model, y)
        call model%internal_forces(0.21_wp, y, axial, shear, moment, reaction)
        l = 0.2_wp
        ks = EA/l
        ds = 0.5_wp*1.0e3_wp*AREA/l
        do k = 1, 5
            spring = ks*y(5 + k) + ds*y(15 + k)
            write (label, '(a, i0, a)') 'mpp in motion, joint ', k - 1, &
                ': tension = k_s u + d_s u'' of the member below'
            call suite%check_close(axial(k - 1), spring, 1.0e-8_wp, 1.0e-9_wp*abs(ks*1.0e-4_wp), &
                                   trim(label))
        end do
        call suite%check_le(abs(axial(5)), 0.0_wp, 'mpp in motion: free end carries nothing')
    end subroutine test_mpp_spring_law

    !> A rope hanging at its static equilibrium (found from 75 degrees, n = 20): the
    !! tension at the joint at arc length s is the weight below it, w (L - s), linear in
    !! s; no shear, no moment.
    subroutine test_hanging_tension(kind)
        character(len=*), intent(in) :: kind
        type(scene_t) :: scene
        class(rope_model_t), allocatable :: model
        real(wp), allocatable :: y(:)
        real(wp) :: axial(0:20), shear(0:20), moment(0:20), reaction(2, 2)
        real(wp) :: lengths(20), masses(20), worst, other
        type(statics_result_t) :: res
        type(error_t), allocatable :: err
        character(len=64) :: sets(2)
        integer :: j

        sets(1) = 'model.kind = "'//kind//'"'   ! (gfortran: no concatenation in [character :: ])
        sets(2) = 'model.elements = 20'
        call scene_of(sets, scene)
        call create_model(scene%rope_spec_t, model, err)
        allocate (y(model%size()))
        call model%initial_state(y)
        if (.not. allocated(err)) &
            call find_equilibrium(model, scene%rope_spec_t, y, statics_options_t(), res, err)
        call suite%check_true(.not. allocated(err), kind//' hanging: equilibrium found')
        if (allocated(err)) return
        call model%internal_forces(0.0_wp, y, axial, shear, moment, reaction)
        call model%element_data(lengths, masses)
        worst = 0.0_wp
        other = 0.0_wp
        do j = 0, 20
            worst = max(worst, abs(axial(j) - W_LEN*(1.0_wp - sum(lengths(1:j)))))
            other = max(other, abs(shear(j)), abs(moment(j)))
        end do
        call suite%check_le(worst/W_LEN, 1.0e-9_wp, kind// &
                            ' hanging: tension = w (L - s) at every joint (/ w L)')
        call suite%check_le(other/W_LEN, 1.0e-9_wp, kind//' hanging: no shear, no moment')
        call suite%check_close(reaction(1, 1), -W_LEN, 1.0e-9_wp, 0.0_wp, kind// &
                               ' hanging: top reaction -w L')
    end subroutine test_hanging_tension

    !> Statics with a top moving sideways (0.5 m at 0.2 Hz, phase 30 degrees: at t = 0 it
    !! has a velocity and an acceleration): the rope hangs straight below the anchor, and
    !! the top's reaction is (-W, 0). A static force never depends on the support's
    !! velocity or acceleration.
    subroutine test_static_moving_top(kind)
        character(len=*), intent(in) :: kind
        type(scene_t) :: scene
        class(rope_model_t), allocatable :: model
        real(wp), allocatable :: y(:), points(:, :)
        real(wp) :: axial(0:10), shear(0:10), moment(0:10), reaction(2, 2), anchors(2, 2)
        type(statics_result_t) :: res
        type(error_t), allocatable :: err
        character(len=64) :: sets(7)

        sets = [character(len=64) :: '', 'model.elements = 10', 'initial.shape = "hanging"', &
                'supports.top_motion = "harmonic"', 'supports.top_amplitude = 0.0, 0.5', &
                'supports.top_frequency = 0.2', 'supports.top_phase_deg = 0.0, 30.0']
        sets(1) = 'model.kind = "'//kind//'"'
        call scene_of(sets, scene)
        call create_model(scene%rope_spec_t, model, err)
        allocate (y(model%size()), points(2, 20))
        call model%initial_state(y)
        if (.not. allocated(err)) &
            call find_equilibrium(model, scene%rope_spec_t, y, statics_options_t(), res, err)
        call suite%check_true(.not. allocated(err), kind//' moving top: equilibrium found')
        if (allocated(err)) return
        call suite%check_true(.not. model%supports_at_rest, kind// &
                              ' moving top: the statics leave the model as it was')
        call model%polyline(y, points)
        call model%support_positions(0.0_wp, anchors)
        ! the statics stop at the rounding level of the stiff springs' forces, ~10 eps EA/dl
        ! L ~ 1e-10 N, which the pendulum's stiffness W/L turns into ~1e-10 m sideways
        call suite%check_le(abs(points(2, 20) - anchors(2, 1)), 1.0e-10_wp, kind// &
                            ' moving top: hangs straight below the anchor')
        model%supports_at_rest = .true.
        call model%internal_forces(0.0_wp, y, axial, shear, moment, reaction)
        call suite%check_le(abs(reaction(2, 1)), 1.0e-9_wp*W_LEN, kind// &
                            ' moving top: no sideways static reaction')
        call suite%check_close(reaction(1, 1), -W_LEN, 1.0e-9_wp, 0.0_wp, kind// &
                               ' moving top: static reaction -W')
    end subroutine test_static_moving_top

    !> The elastic catenary (two pins 0.8 m apart, bending off, n = 20): the model's static
    !! reactions (its support laws, supports at rest) equal the virtual-work ones, dV/dP by
    !! differences of the potential energy (ropedyn_analysis's support_forces).
    subroutine test_static_reactions(kind)
        character(len=*), intent(in) :: kind
        type(scene_t) :: scene
        class(rope_model_t), allocatable :: model
        real(wp), allocatable :: y(:)
        real(wp) :: axial(0:20), shear(0:20), moment(0:20), reaction(2, 2), top(2), bottom(2)
        type(statics_result_t) :: res
        type(error_t), allocatable :: err
        character(len=64) :: sets(6)

        sets = [character(len=64) :: '', 'model.elements = 20', 'effects.bending = .false.', &
                'supports.bottom = "pinned"', 'supports.bottom_anchor = 0.0, 0.8', &
                'initial.shape = "hanging"']
        sets(1) = 'model.kind = "'//kind//'"'
        call scene_of(sets, scene)
        call create_model(scene%rope_spec_t, model, err)
        allocate (y(model%size()))
        call model%initial_state(y)
        if (.not. allocated(err)) &
            call find_equilibrium(model, scene%rope_spec_t, y, statics_options_t(), res, err)
        if (.not. allocated(err)) &
            call support_forces(scene%rope_spec_t, model, y, top, bottom, err)
        call suite%check_true(.not. allocated(err), kind//' catenary: equilibrium found')
        if (allocated(err)) return
        model%supports_at_rest = .true.
        call model%internal_forces(0.0_wp, y, axial, shear, moment, reaction)
        call suite%check_le(norm2(reaction(:, 1) - top)/norm2(top), 1.0e-7_wp, kind// &
                            ' catenary: top reaction = dV/dP')
        call suite%check_le(norm2(reaction(:, 2) - bottom)/norm2(bottom), 1.0e-7_wp, kind// &
                            ' catenary: bottom reaction = dV/dP')
    end subroutine test_static_reactions
end program test_internal_forces
