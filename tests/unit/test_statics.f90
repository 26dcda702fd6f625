!> Static equilibrium (ropedyn_statics) of both models against closed forms:
!! - the hanging rope's static stretch (exact for each discretization) and support force,
!!   reached from a straight start at 75 degrees;
!! - the elastic catenary (Irvine; docs/theory/statics-modes.md): sag, H and T_max of a stiff
!!   (EA = 687.22 N) and a soft (EA = 10 N) rope hung between two pins 0.8 m apart, started
!!   hanging vertically with the bottom support spring stretched by 1.28 m;
!! - the equilibrium residual, the 'equilibrium' and 'mode' initial shapes, and the errors
!!   for a scene without equilibrium (free-free under gravity) and a capped iteration;
!! - the rope in a current (normal drag only): a straight line at the angle theta from the
!!   vertical where the normal drag balances the weight's normal part,
!!   q_n U^2 cos^2 theta = w sin theta, RFEM and MPP, slow and fast, either way; and a
!!   current that does not reach the rope at rest, whose budget the equilibrium without it
!!   can use up (said so);
!! - the RFEM's displace (the statics' trial point): y + delta to first order, and exact for
!!   joined elements turned as one; and the soft rope with a heavy point mass that swings
!!   down in a few hundred iterations with it (over 5000 with y + delta alone);
!! - the tangent stiffness of a rope with a heavy point mass off its element's centre,
!!   away from an equilibrium: symmetric and -df/dq by differences (with the (dM/dq) a
!!   term of its configuration-dependent mass), and the chain (bending off) that swings
!!   down with it in tens of iterations (over a thousand without the term);
!! - the equilibrium handed back is the one solved: its residual there is the one reported
!!   and no joint is bent by a whole turn (at_rest_near takes whole turns off an angle only
!!   where that changes no force: without bending, not with it).
program test_statics
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t, ERR_SOLVER
    use ropedyn_scene, only: scene_t, read_scene
    use ropedyn_rope_model, only: rope_model_t
    use ropedyn_model_factory, only: create_model
    use ropedyn_rfem, only: rfem_t, rfem_create
    use ropedyn_statics, only: statics_options_t, statics_result_t, find_equilibrium, &
                               generalized_force, tangent_matrices
    use ropedyn_statics_terms, only: at_rest_near
    use ropedyn_modes, only: equilibrium_initial_state
    use ropedyn_analysis, only: support_forces
    use ropedyn_assert, only: test_suite_t
    implicit none

    real(wp), parameter :: PI = 4.0_wp*atan(1.0_wp)
    real(wp), parameter :: AREA = PI*0.005_wp**2/4.0_wp       !< m^2
    real(wp), parameter :: W_LEN = 6000.0_wp*AREA*9.81_wp     !< weight per length, N/m
    type(test_suite_t) :: suite
    character(len=1024) :: source_dir

    suite%name = 'statics'
    call get_command_argument(1, source_dir)
    if (len_trim(source_dir) == 0) source_dir = '.'
    call test_hanging('rfem')
    call test_hanging('mpp')
    ! Irvine's elastic catenary, span 0.8 m, supports at equal height (docs/theory/statics-modes.md)
    call test_catenary('rfem', 100, 35.0e6_wp, 0.389941_wp, 0.265999_wp, 0.697117_wp)
    call test_catenary('rfem', 100, 10.0_wp/AREA, 0.340871_wp, 0.300012_wp, 0.670904_wp)
    call test_catenary('mpp', 50, 35.0e6_wp, 0.389941_wp, 0.265999_wp, 0.697117_wp)
    call test_catenary('mpp', 50, 10.0_wp/AREA, 0.340871_wp, 0.300012_wp, 0.670904_wp)
    call test_initial_shapes()
    call test_errors()
    call test_current('rfem', 0.5_wp)
    call test_current('mpp', 0.5_wp)
    call test_current('rfem', -3.0_wp)
    call test_current('mpp', 3.0_wp)
    call test_dry_current('rfem')
    call test_dry_current('mpp')
    call test_whole_turns('rfem')
    call test_whole_turns('mpp')
    call test_turn_taken_off('rfem', .true.)
    call test_turn_taken_off('rfem', .false.)
    call test_turn_taken_off('mpp', .true.)
    call test_displace()
    call test_soft_swing()
    call test_mass_slope()
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

    !> Equilibrium of the scene from its initial state; stops the test on an error.
    subroutine equilibrium(scene, model, y, res)
        type(scene_t), intent(in) :: scene
        class(rope_model_t), allocatable, intent(out) :: model
        real(wp), allocatable, intent(out) :: y(:)
        type(statics_result_t), intent(out) :: res
        type(error_t), allocatable :: err
        call create_model(scene%rope_spec_t, model, err)
        if (allocated(err)) then
            call suite%check_true(.false., err%message)
            call suite%finish()
        end if
        allocate (y(model%size()))
        call model%initial_state(y)
        call find_equilibrium(model, scene%rope_spec_t, y, statics_options_t(), res, err)
        if (allocated(err)) then
            call suite%check_true(.false., 'equilibrium found: '//err%message)
        else
            call suite%check_true(.true., 'equilibrium found')
        end if
        if (allocated(err)) call suite%finish()
    end subroutine equilibrium

    !> n = 100, bending off, from the straight rope at 75 degrees. Static stretch of the tip:
    !! RFEM sum_j T_j dl/EA = w L^2/(2 EA) exactly, plus W dl/EA in the top support spring;
    !! MPP sum_k T_k l/EA = W L (n+1)/(2 n EA). Top support force (-W, 0).
    subroutine test_hanging(kind)
        character(len=*), intent(in) :: kind
        type(scene_t) :: scene
        class(rope_model_t), allocatable :: model
        real(wp), allocatable :: y(:), points(:, :)
        type(statics_result_t) :: res
        type(error_t), allocatable :: err
        real(wp) :: stretch, top(2), bottom(2), ea
        integer, parameter :: n = 100
        character(len=120) :: label
        character(len=64) :: sets(3)

        sets(1) = 'model.kind = "'//kind//'"'   ! (gfortran: no concatenation in [character :: ])
        sets(2) = 'model.elements = 100'
        sets(3) = 'effects.bending = .false.'
        call scene_of(sets, scene)
        call equilibrium(scene, model, y, res)
        write (label, '(a, i0, a, i0, a, es9.2)') kind//' hanging from 75 deg: ', &
            res%iterations, ' iterations (', res%rejected, ' rejected), residual ', &
            res%residual_relative
        call suite%check_le(res%residual_relative, 1.0e-9_wp, trim(label))
        allocate (points(2, 2*n))
        call model%polyline(y, points)
        ea = 35.0e6_wp*AREA
        if (kind == 'rfem') then
            stretch = W_LEN/(2*ea) + W_LEN*(1.0_wp/(n - 1))/ea
        else
            stretch = W_LEN*(n + 1)/(2.0_wp*n*ea)
        end if
        call suite%check_close(points(1, 2*n) - 1.0_wp, stretch, 1.0e-7_wp, 0.0_wp, &
                               kind//': static stretch of the tip (discrete closed form)')
        ! to the iteration's rounding level: a sideways force of the residual's bound (1e-9
        ! W) moves the tip by up to its lateral compliance, about ln(n)/w = 4 m/N, times it
        call suite%check_le(abs(points(2, 2*n)), 1.0e-8_wp, kind//': hangs vertically (m)')
        call support_forces(scene%rope_spec_t, model, y, top, bottom, err)
        call suite%check_close(top(1), -W_LEN, 1.0e-9_wp, 0.0_wp, kind// &
                               ': top support force = -weight')
        call suite%check_le(abs(top(2)), 1.0e-9_wp, kind//': no horizontal support force')
    end subroutine test_hanging

    !> Two pins at equal height 0.8 m apart (support_stiffness_factor 100: nearly rigid
    !! pins; at 1 the pins' own compliance adds a joint's stretch at each end, +0.3 % sag
    !! for EA = 10 N), bending off, started hanging vertically. Sag (lowest polyline point),
    !! H and T_max against the closed form within 0.5 %.
    subroutine test_catenary(kind, n, young, h_ref, sag_ref, t_ref)
        character(len=*), intent(in) :: kind
        integer, intent(in) :: n
        real(wp), intent(in) :: young, h_ref, sag_ref, t_ref
        type(scene_t) :: scene
        class(rope_model_t), allocatable :: model
        real(wp), allocatable :: y(:), points(:, :)
        type(statics_result_t) :: res
        type(error_t), allocatable :: err
        real(wp) :: top(2), bottom(2)
        character(len=64) :: sets(8)
        character(len=120) :: label

        sets(1) = 'model.kind = "'//kind//'"'
        write (sets(2), '(a, i0)') 'model.elements = ', n
        write (sets(3), '(a, es22.15)') 'rope.young_modulus = ', young
        sets(4) = 'supports.bottom = "pinned"'
        sets(5) = 'supports.bottom_anchor = 0.0, 0.8'
        sets(6) = 'supports.support_stiffness_factor = 100'
        sets(7) = 'initial.shape = "hanging"'
        sets(8) = 'effects.bending = .false.'
        call scene_of(sets, scene)
        call equilibrium(scene, model, y, res)
        write (label, '(a, i0, a, f7.2, a, i0, a, i0, a, es9.2)') kind//' n = ', n, &
            ', EA = ', young*AREA, ' N: ', res%iterations, ' iterations, ', res%stages, &
            ' continuation stages, residual ', res%residual_relative
        ! stiff pins (100 EA/dl): the rounding floor of the forces is ~1e-9 of the weight;
        ! the MPP's reaches every angle through its lever arm, and the iteration stops
        ! anywhere below it: up to a few 1e-8 (2.3e-8 measured for n = 50, EA = 687 N)
        call suite%check_le(res%residual_relative, 5.0e-8_wp, trim(label))
        allocate (points(2, 2*n))
        call model%polyline(y, points)
        call suite%check_close(maxval(points(1, :)), sag_ref, 5.0e-3_wp, 0.0_wp, &
                               kind//': catenary sag (0.5 %)')
        call suite%check_close(points(2, maxloc(points(1, :), 1)), 0.4_wp, 0.0_wp, 2.0e-3_wp, &
                               kind//': lowest point at midspan')
        call support_forces(scene%rope_spec_t, model, y, top, bottom, err)
        call suite%check_true(.not. allocated(err), kind//': support forces')
        call suite%check_close(abs(top(2)), h_ref, 5.0e-3_wp, 0.0_wp, kind//': H (0.5 %)')
        call suite%check_close(bottom(2), -top(2), 1.0e-9_wp, 0.0_wp, &
                               kind//': horizontal forces balance')
        call suite%check_close(-(top(1) + bottom(1)), W_LEN, 1.0e-9_wp, 0.0_wp, &
                               kind//': vertical forces carry the weight')
        call suite%check_close(max(norm2(top), norm2(bottom)), t_ref, 5.0e-3_wp, 0.0_wp, &
                               kind//': T_max (0.5 %)')
    end subroutine test_catenary

    !> &initial shape = 'equilibrium' starts at the equilibrium, at rest (forces ~ 0);
    !! 'mode' adds mode 1 with its largest point displacement = mode_amplitude.
    subroutine test_initial_shapes()
        type(scene_t) :: scene
        class(rope_model_t), allocatable :: model
        real(wp), allocatable :: y(:), y_eq(:), f(:), p0(:, :), p1(:, :)
        integer, allocatable :: pos(:), vel(:)
        type(error_t), allocatable :: err
        integer :: status
        real(wp) :: largest

        call scene_of([character(len=64) :: 'model.elements = 20', &
                       'initial.shape = "equilibrium"'], scene)
        call create_model(scene%rope_spec_t, model, err)
        allocate (y(model%size()), p0(2, 40), p1(2, 40))
        call model%initial_state(y)
        call equilibrium_initial_state(model, scene%rope_spec_t, y, err)
        call suite%check_true(.not. allocated(err), "shape = 'equilibrium': solved")
        call model%coordinates(pos, vel)
        allocate (f(size(pos)))
        call generalized_force(model, y, pos, vel, f, status)
        call suite%check_le(maxval(abs(f)), 1.0e-9_wp, "shape = 'equilibrium': max |f| (N)")
        call suite%check_true(all(y(vel) == 0.0_wp), "shape = 'equilibrium': at rest")
        y_eq = y
        call model%polyline(y_eq, p0)

        call scene_of([character(len=64) :: 'model.elements = 20', 'initial.shape = "mode"', &
                       'initial.mode = 1', 'initial.mode_amplitude = 0.002'], scene)
        call create_model(scene%rope_spec_t, model, err)
        call model%initial_state(y)
        call equilibrium_initial_state(model, scene%rope_spec_t, y, err)
        call suite%check_true(.not. allocated(err), "shape = 'mode': solved")
        call model%polyline(y, p1)
        largest = maxval(norm2(p1 - p0, dim=1))
        call suite%check_close(largest, 0.002_wp, 1.0e-3_wp, 0.0_wp, &
                               "shape = 'mode': largest point displacement = mode_amplitude")
        call suite%check_true(all(y(vel) == 0.0_wp), "shape = 'mode': at rest")

        call scene_of([character(len=64) :: 'model.elements = 4', 'initial.shape = "mode"', &
                       'initial.mode = 99'], scene)
        call create_model(scene%rope_spec_t, model, err)
        deallocate (y)
        allocate (y(model%size()))
        call model%initial_state(y)
        call equilibrium_initial_state(model, scene%rope_spec_t, y, err)
        call suite%check_true(allocated(err), "shape = 'mode', mode = 99 > 12 modes: error")
        if (allocated(err)) call suite%check_contains(err%message, 'only 12 modes', &
                                                      'mode beyond the count')
    end subroutine test_initial_shapes

    !> No equilibrium (both ends free under gravity) and a capped iteration: ERR_SOLVER with
    !! a message naming the cause.
    subroutine test_errors()
        type(scene_t) :: scene
        class(rope_model_t), allocatable :: model
        real(wp), allocatable :: y(:)
        type(statics_result_t) :: res
        type(statics_options_t) :: options
        type(error_t), allocatable :: err

        call scene_of([character(len=64) :: 'supports.top = "free"', &
                       'supports.bottom = "free"'], scene)
        call create_model(scene%rope_spec_t, model, err)
        allocate (y(model%size()))
        call model%initial_state(y)
        call find_equilibrium(model, scene%rope_spec_t, y, statics_options_t(), res, err)
        call suite%check_true(allocated(err), 'free-free with gravity: error')
        if (allocated(err)) then
            call suite%check_true(err%code == ERR_SOLVER, 'free-free: class ERR_SOLVER (exit 3)')
            call suite%check_contains(err%message, 'no equilibrium', 'free-free: message')
            call suite%check_contains(err%message, "bottom = 'free'", 'free-free: names keys')
        end if

        ! gravity off: a free rope at rest is in (neutral) equilibrium already
        call scene_of([character(len=64) :: 'supports.top = "free"', &
                       'supports.bottom = "free"', 'effects.gravity = .false.'], scene)
        call create_model(scene%rope_spec_t, model, err)
        call model%initial_state(y)
        call find_equilibrium(model, scene%rope_spec_t, y, statics_options_t(), res, err)
        call suite%check_true(.not. allocated(err) .and. res%iterations == 0, &
                              'free-free without gravity: the start is an equilibrium')

        call scene_of([character(len=64) :: 'model.elements = 30'], scene)
        call create_model(scene%rope_spec_t, model, err)
        deallocate (y)
        allocate (y(model%size()))
        call model%initial_state(y)
        options%max_iterations = 3
        call find_equilibrium(model, scene%rope_spec_t, y, options, res, err)
        call suite%check_true(allocated(err), 'capped iteration: error')
        if (allocated(err)) then
            call suite%check_true(err%code == ERR_SOLVER, 'capped: class ERR_SOLVER')
            call suite%check_contains(err%message, 'no convergence in 3 iterations', &
                                      'capped: message')
        end if
    end subroutine test_errors

    !> The paper's rope (n = 30) pinned at the top in a current U across gravity, drag on
    !! with the normal part only (fluid density 1000 kg/m^3, C_n = 1.2, C_t = 0): every
    !! element lies at theta from the vertical, sin theta = (sqrt(1 + 4 k^2) - 1)/(2 k),
    !! k = q_n U^2/w, q_n = rho C_n d/2 (the normal drag per length q_n U^2 cos^2 theta
    !! balances the weight's normal part w sin theta; the weight's part along the rope is
    !! the tension's gradient). The drag has no potential: the equilibrium is continued
    !! in the current's speed (ropedyn_statics_flow).
    subroutine test_current(kind, u)
        character(len=*), intent(in) :: kind
        real(wp), intent(in) :: u
        real(wp), parameter :: QN = 0.5_wp*1000.0_wp*1.2_wp*0.005_wp
        type(scene_t) :: scene
        class(rope_model_t), allocatable :: model
        real(wp), allocatable :: y(:), points(:, :)
        type(statics_result_t) :: res
        real(wp) :: k, theta, worst, seg(2)
        integer :: i
        character(len=64) :: sets(6)
        character(len=120) :: label

        write (sets(1), '(a)') 'model.kind = "'//kind//'"'
        sets(2) = 'model.elements = 30'
        sets(3) = 'effects.drag = .true.'
        sets(4) = 'fluid.density = 1000.0'
        sets(5) = 'fluid.tangential_drag_coefficient = 0.0'
        write (sets(6), '(a, es12.5)') 'fluid.current = 0.0, ', u
        call scene_of(sets, scene)
        call equilibrium(scene, model, y, res)
        k = QN*u**2/W_LEN
        theta = sign(asin((sqrt(1.0_wp + 4.0_wp*k**2) - 1.0_wp)/(2.0_wp*k)), u)
        allocate (points(2, 2*30))
        call model%polyline(y, points)
        worst = 0.0_wp
        do i = 1, size(points, 2) - 1
            seg = points(:, i + 1) - points(:, i)
            if (norm2(seg) > 1.0e-6_wp) worst = max(worst, abs(atan2(seg(2), seg(1)) - theta))
        end do
        write (label, '(a, f5.1, a, f8.4, a, i0, a)') kind//' in a current of ', u, &
            ' m/s: every element at theta = ', theta*180/PI, ' deg (', res%stages, ' stages)'
        call suite%check_le(worst, 1.0e-8_wp, trim(label))
        call suite%check_true(res%stages >= 1, kind//': continued in the current')
        call suite%check_le(res%residual_relative, 1.0e-9_wp, kind//': residual in the current')
    end subroutine test_current

    !> A current that does not act on the rope at rest: water on, drag off, the rope
    !! hanging wholly above the surface. The statics goes through the continuation in the
    !! current (current_drags) and must find the still equilibrium, which every stage
    !! starts at: the residual is rounding from the first iteration. (The pseudo-transient
    !! shift halved only after a step that lowered the residual, so it never reached Newton
    !! there and each stage ran out of iterations: a random scene's "no equilibrium in the
    !! current".)
    subroutine test_dry_current(kind)
        character(len=*), intent(in) :: kind
        type(scene_t) :: scene
        class(rope_model_t), allocatable :: model, still_model
        real(wp), allocatable :: y(:), y_still(:)
        type(statics_result_t) :: res, still
        type(statics_options_t) :: options
        type(error_t), allocatable :: err
        integer :: total
        character(len=64) :: sets(6)

        write (sets(1), '(a)') 'model.kind = "'//kind//'"'
        sets(2) = 'model.elements = 10'
        sets(3) = 'effects.water = .true.'
        sets(4) = 'effects.drag = .false.'
        sets(5) = 'fluid.surface = 10.0'
        sets(6) = 'fluid.current = 0.0, 0.0'
        call scene_of(sets, scene)
        call equilibrium(scene, still_model, y_still, still)
        sets(6) = 'fluid.current = 0.3, 1.0'
        call scene_of(sets, scene)
        call equilibrium(scene, model, y, res)
        call suite%check_true(res%stages >= 1, kind//', dry in a current: continued in it')
        call suite%check_le(maxval(abs(y - y_still)), 1.0e-10_wp, &
                            kind//', dry in a current: the still equilibrium')
        ! each stage: the shift halved about ten times to Newton (NEWTON_BELOW), then a
        ! Newton step at rounding; far below one stage's budget of 200
        call suite%check_le(real(res%iterations - still%iterations, wp), 100.0_wp, &
                            kind//', dry in a current: the stages reach Newton')
        ! the continuation in the current has a budget of its own, as the equilibrium
        ! without it has: a budget one short of both together finds it (a shared budget
        ! stalled the continuation one iteration short, and failed one that had not begun
        ! where the still equilibrium's own stages had passed the budget: 2049 of 2000, a
        ! random scene)
        total = res%iterations
        call create_model(scene%rope_spec_t, model, err)
        deallocate (y)
        allocate (y(model%size()))
        call model%initial_state(y)
        options%max_iterations = total - 1
        call find_equilibrium(model, scene%rope_spec_t, y, options, res, err)
        print '(a, i0, a, i0)', kind//': iterations without the current ', still%iterations, &
            ', in all ', total
        call suite%check_true(.not. allocated(err), kind//', dry in a current, a budget '// &
                              'short of both together: found')
        call suite%check_true(res%iterations == total, kind//', dry in a current: the same '// &
                              'iterations with its own budget')
        call suite%check_le(maxval(abs(y - y_still)), 1.0e-10_wp, &
                            kind//', dry in a current, its own budget: the still equilibrium')
    end subroutine test_dry_current

    !> A folded start of three elements with a point load near the top: to the equilibrium
    !! the elements turn by about half a turn, some past pi from their start and some not.
    !! Bringing each angle within pi of its start would turn some elements by a whole turn
    !! and not their neighbours: with bending (a moment on the difference of two angles)
    !! that bends the joint between them by 2 pi, a state far from equilibrium. The state
    !! handed back must be the equilibrium solved: its residual, evaluated there, the one
    !! reported (rounding level), and every joint bent by less than a radian (the angles of
    !! neighbouring elements, model%angle_coordinates in element order).
    subroutine test_whole_turns(kind)
        character(len=*), intent(in) :: kind
        type(scene_t) :: scene
        class(rope_model_t), allocatable :: model
        real(wp), allocatable :: y(:), f(:), phi(:)
        integer, allocatable :: pos(:), vel(:)
        type(statics_result_t) :: res
        integer :: status

        call scene_of(folded_sets(kind, .true.), scene)
        call equilibrium(scene, model, y, res)
        call model%coordinates(pos, vel)
        allocate (f(size(pos)))
        call generalized_force(model, y, pos, vel, f, status)
        call suite%check_le(maxval(abs(f)), max(2.0_wp*res%residual, 1.0e-12_wp*res%weight), &
                            kind//', folded: the residual at the state handed back, N')
        call suite%check_le(res%residual_relative, 1.0e-9_wp, kind//', folded: residual / weight')
        phi = y(pack(pos, model%angle_coordinates()))
        call suite%check_le(maxval(abs(phi(2:) - phi(:size(phi) - 1))), 1.0_wp, &
                            kind//', folded: no joint bent by a whole turn (rad)')
    end subroutine test_whole_turns

    !> at_rest_near at the equilibrium of test_whole_turns' scene, given a start q0 one turn
    !! away in the middle element's angle: the turn is taken off (that angle ends within pi
    !! of q0, the forces the same) without bending, and kept with it (the state unchanged).
    subroutine test_turn_taken_off(kind, bending)
        character(len=*), intent(in) :: kind
        logical, intent(in) :: bending
        type(scene_t) :: scene
        class(rope_model_t), allocatable :: model
        real(wp), allocatable :: y(:), y_eq(:), q0(:), f(:), f_eq(:)
        integer, allocatable :: pos(:), vel(:)
        type(statics_result_t) :: res
        character(len=:), allocatable :: label
        logical, allocatable :: angle(:)
        integer :: status, k

        label = kind//merge(', bending:    ', ', no bending: ', bending)
        call scene_of(folded_sets(kind, bending), scene)
        call equilibrium(scene, model, y_eq, res)
        call model%coordinates(pos, vel)
        angle = model%angle_coordinates()
        k = findloc(angle, .true., dim=1)
        k = k + findloc(angle(k + 1:), .true., dim=1)   ! the second angle coordinate
        allocate (f_eq(size(pos)))
        call generalized_force(model, y_eq, pos, vel, f_eq, status)
        q0 = y_eq(pos)
        q0(k) = q0(k) + 2.0_wp*PI
        y = y_eq
        f = f_eq
        call at_rest_near(model, y, pos, vel, q0, f)
        if (bending) then
            call suite%check_true(all(y == y_eq), label//'the turn is kept')
        else
            call suite%check_le(abs(y(pos(k)) - q0(k)), 1.0e-12_wp, &
                                label//'the turn is taken off (rad)')
        end if
        call suite%check_le(maxval(abs(f - f_eq)), max(10.0_wp*maxval(abs(f_eq)), &
                            1.0e-12_wp*res%weight), label//'the force the same, to rounding (N)')
    end subroutine test_turn_taken_off

    !> test_whole_turns' scene: three elements, folded, a point load near the top.
    function folded_sets(kind, bending) result(sets)
        character(len=*), intent(in) :: kind
        logical, intent(in) :: bending
        character(len=64) :: sets(8)
        write (sets(1), '(a)') 'model.kind = "'//kind//'"'
        sets(2) = 'model.elements = 3'
        sets(3) = 'initial.shape = "folded"'
        sets(4) = 'attachments.mass_positions = 0.2104'
        sets(5) = 'attachments.masses = 0.00205'
        sets(6) = 'attachments.load_positions = 0.06462'
        sets(7) = 'attachments.load_force_y = -1.44'
        write (sets(8), '(a, l1)') 'effects.bending = ', bending
    end function folded_sets

    !> rfem_t%displace: equal to y + delta to first order (the difference quarters when
    !! delta halves), and for the straight rope turned as one about its top end by 0.3 rad
    !! (delta: that turn linearized) exactly the turned rope, joints closed, where y + delta
    !! opens each joint by about l theta^2/2.
    subroutine test_displace()
        real(wp), parameter :: THETA = 0.3_wp
        type(scene_t) :: scene
        type(rfem_t) :: model
        type(error_t), allocatable :: err
        real(wp), allocatable :: y(:), y_new(:), y_lin(:), delta(:)
        real(wp), allocatable :: points(:, :), expected(:, :)
        integer, allocatable :: pos(:), vel(:)
        real(wp) :: top(2), c(2), gap(2)
        integer :: i, n

        call scene_of([character(len=64) :: 'model.elements = 6'], scene)
        call rfem_create(model, scene%rope_spec_t, err)
        n = model%n_elements()
        allocate (y(model%size()), y_new(model%size()), points(2, 2*n), expected(2, 2*n))
        call model%initial_state(y)                  ! straight at 75 degrees, joints closed
        call model%coordinates(pos, vel)
        allocate (delta(size(pos)))
        call random_number(delta)
        delta = delta - 0.5_wp
        do i = 1, 2                                  ! delta of 1e-3 and 5e-4 (m or rad)
            call model%displace(y, (1.0e-3_wp/i)*delta, y_new)
            y_lin = y
            y_lin(pos) = y(pos) + (1.0e-3_wp/i)*delta
            gap(i) = maxval(abs(y_new - y_lin))
        end do
        call suite%check_close(gap(1)/gap(2), 4.0_wp, 0.05_wp, 0.0_wp, &
                               'displace - (y + delta) is second order in delta')
        ! the rigid turn about the top end, linearized: dphi = theta, dc = theta J (c - top)
        call model%polyline(y, points)
        top = points(:, 1)
        do i = 1, n
            c = y(6*(i - 1) + 1:6*(i - 1) + 2)
            delta(3*(i - 1) + 1:3*(i - 1) + 3) = THETA*[-(c(2) - top(2)), c(1) - top(1), 1.0_wp]
            expected(:, 2*i - 1) = top + turned(points(:, 2*i - 1) - top, THETA)
            expected(:, 2*i) = top + turned(points(:, 2*i) - top, THETA)
        end do
        call model%displace(y, delta, y_new)
        call model%polyline(y_new, points)
        call suite%check_le(maxval(abs(points - expected)), 1.0e-15_wp, &
                            'displace: the straight rope turned as one, exactly (m)')
        y_lin = y
        y_lin(pos) = y(pos) + delta
        call model%polyline(y_lin, points)
        call suite%check_close(maxval(norm2(points(:, 3:2*n:2) - points(:, 2:2*n - 1:2), &
                                            dim=1)), (1.0_wp/n)*THETA**2/2, 0.5_wp, 0.0_wp, &
                               'y + delta opens the joints by about l theta^2/2 (m)')
    end subroutine test_displace

    !> v turned by the angle a.
    pure function turned(v, a) result(r)
        real(wp), intent(in) :: v(2), a
        real(wp) :: r(2)
        r = [cos(a)*v(1) - sin(a)*v(2), sin(a)*v(1) + cos(a)*v(2)]
    end function turned

    !> A soft rope (the paper's, EI = 1.1e-3 N m^2, 1.8 m, n = 25) with a point mass of 3.4 kg
    !! near its end and a sideways load, started straight at -75 degrees: it swings down in
    !! long turning steps. With y + delta alone each step stretched the stiff joints and
    !! the iteration took 5065 iterations (at 202c34b); with the displacement 147.
    subroutine test_soft_swing()
        type(scene_t) :: scene
        class(rope_model_t), allocatable :: model
        real(wp), allocatable :: y(:)
        type(statics_result_t) :: res
        character(len=120) :: label
        call scene_of([character(len=64) :: 'model.elements = 25', 'rope.length = 1.8', &
                       'attachments.mass_positions = 1.6', 'attachments.masses = 3.4', &
                       'attachments.load_positions = 1.2', 'attachments.load_force_y = 2.0', &
                       'initial.angle_deg = -75'], scene)
        call equilibrium(scene, model, y, res)
        write (label, '(a, i0, a, es9.2)') 'soft rope with a heavy mass swings down: ', &
            res%iterations, ' iterations, residual ', res%residual_relative
        call suite%check_le(res%residual_relative, 1.0e-9_wp, trim(label))
        call suite%check_le(real(res%iterations, wp), 1000.0_wp, &
                            'soft rope with a heavy mass: iterations')
    end subroutine test_soft_swing

    !> The paper's rope as a chain (bending off, n = 10) with 7.57 kg at 0.97 m (off its
    !! element's centre, so that the mass matrix turns with the element), straight at 100
    !! degrees, far from its equilibrium: K = -df/dq (tangent_matrices, the Hessian the
    !! equilibrium iteration uses) is symmetric and
    !! matches central differences of f along the chain's swing about its pin (where the
    !! stiff joint springs, which dwarf the other entries, do not act). Without the (dM/dq) a
    !! term that curvature was wrong (printed), and the statics took 1095 iterations; now 17.
    subroutine test_mass_slope()
        type(scene_t) :: scene
        class(rope_model_t), allocatable :: model
        real(wp), allocatable :: y(:), kt(:, :), fp(:), fm(:), fd(:, :), yp(:), v(:)
        integer, allocatable :: pos(:), vel(:)
        type(error_t), allocatable :: err
        type(statics_result_t) :: res
        character(len=120) :: label
        integer :: j, status
        real(wp) :: h, scale
        call scene_of([character(len=64) :: 'model.elements = 10', 'effects.bending = .false.', &
                       'attachments.mass_positions = 0.97', 'attachments.masses = 7.57', &
                       'initial.angle_deg = 100'], scene)
        call create_model(scene%rope_spec_t, model, err)
        allocate (y(model%size()))
        call model%initial_state(y)
        call model%coordinates(pos, vel)
        allocate (kt(size(pos), size(pos)), fp(size(pos)), fm(size(pos)), &
                  fd(size(pos), size(pos)))
        call tangent_matrices(model, y, pos, vel, kt, status, hessian=.true.)
        do j = 1, size(pos)
            h = 1.0e-6_wp
            yp = y
            yp(pos(j)) = y(pos(j)) + h
            call generalized_force(model, yp, pos, vel, fp, status)
            yp(pos(j)) = y(pos(j)) - h
            call generalized_force(model, yp, pos, vel, fm, status)
            fd(:, j) = -(fp - fm)/(2*h)
        end do
        scale = maxval(abs(kt))
        write (label, '(a, es9.2)') 'heavy mass off centre: K symmetric, max |K - K^T| / '// &
            'max |K| = ', maxval(abs(kt - transpose(kt)))/scale
        call suite%check_le(maxval(abs(kt - transpose(kt)))/scale, 1.0e-7_wp, trim(label))
        ! along the chain's swing about the pin (each centre turned about the origin, each
        ! angle by the same), where the joint springs do not act: v K v, the swing's
        ! curvature, against v K_fd v
        allocate (v(size(pos)))
        v(1::3) = -y(pos(2::3))
        v(2::3) = y(pos(1::3))
        v(3::3) = 1.0_wp
        write (label, '(a, 2es11.3)') 'heavy mass off centre: the swing''s curvature v K v, '// &
            'by differences (N m) ', dot_product(v, matmul(kt, v)), dot_product(v, matmul(fd, v))
        call suite%check_close(dot_product(v, matmul(kt, v)), dot_product(v, matmul(fd, v)), &
                               1.0e-4_wp, 0.0_wp, trim(label))
        call equilibrium(scene, model, y, res)
        write (label, '(a, i0, a)') 'chain with a heavy mass swings down: ', res%iterations, &
            ' iterations'
        call suite%check_le(real(res%iterations, wp), 100.0_wp, trim(label))
    end subroutine test_mass_slope
end program test_statics
