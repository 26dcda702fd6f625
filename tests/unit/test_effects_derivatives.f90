!> Effects beyond springs and gravity (drag with a current, ground contact with friction,
!! point loads, point masses, moving and released supports), with every effect on:
!! RFEM's analytic band Jacobian against central differences, conservative forces against
!! -grad V, and for RFEM and MPP the instantaneous energy bookkeeping
!!     d(T + V)/dt = external power - dissipation power
!! along the flow (the time derivative by differences of the energy routine), the MPP mass
!! matrix against the residual, and the MPP Jacobian against differences.
program test_effects_derivatives
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t
    use ropedyn_rope_model, only: energy_t
    use ropedyn_scene, only: scene_t, read_scene
    use ropedyn_rope_model, only: rope_model_t
    use ropedyn_rfem, only: rfem_t, rfem_create
    use ropedyn_mpp, only: mpp_t, mpp_create
    use ropedyn_assert, only: test_suite_t
    use ropedyn_problem, only: STATUS_OK
    implicit none

    type(test_suite_t) :: suite
    character(len=*), parameter :: TABLE = 'test_effects_table.dat'
    !> every effect on (the rfem and mpp runs add their own supports)
    character(len=64), parameter :: ALL(*) = [character(len=64) :: &
        'effects.drag = .true.', 'effects.ground = .true.', &
        'fluid.density = 1000', 'fluid.linear_normal_drag = 0.3', &
        'fluid.linear_tangential_drag = 0.1', 'fluid.current = 0.2, -0.4', &
        'ground.point = 0.15, 0.0', 'ground.normal = -1.0, 0.3', 'ground.stiffness = 2e3', &
        'ground.damping = 5.0', 'ground.friction_coefficient = 0.4', &
        'ground.friction_regularization_speed = 0.05', &
        'attachments.mass_positions = 0.37, 1.0', 'attachments.masses = 0.03, 0.08', &
        'attachments.load_positions = 0.2, 0.81', 'attachments.load_force_x = 0.1, -0.2', &
        'attachments.load_force_y = 0.3, 0.05', 'attachments.load_amplitude_y = 0.0, 0.4', &
        'attachments.load_frequency = 0.0, 1.5', 'attachments.load_phase_deg = 0.0, 30.0']

    suite%name = 'effects_derivatives'
    call write_table()
    call rfem_checks()
    call mpp_checks()
    call suite%finish()

contains

    subroutine write_table()
        integer :: unit
        open (newunit=unit, file=TABLE, status='replace', action='write')
        write (unit, '(a)') '# t  dx  dy  dangle_deg'
        write (unit, '(a)') '0.0  0.0   0.0    0.0'
        write (unit, '(a)') '0.2  0.01  -0.02  3.0'
        write (unit, '(a)') '0.5, -0.01, 0.03, -2.0'
        write (unit, '(a)') '0.9  0.02  0.0    1.0'
        close (unit)
    end subroutine write_table

    !> The paper's rope (the defaults) with overrides; the scene file is written into the
    !! working directory, so that the motion table's relative path resolves there.
    subroutine make_scene(sets, scene)
        character(len=*), intent(in) :: sets(:)
        type(scene_t), intent(out) :: scene
        type(error_t), allocatable :: err
        integer :: unit
        open (newunit=unit, file='test_effects_scene.nml', status='replace', action='write')
        write (unit, '(a)') '&model /'
        close (unit)
        call read_scene('test_effects_scene.nml', sets, scene, err)
        if (allocated(err)) then
            call suite%check_true(.false., 'scene: '//err%message)
            call suite%finish()
        end if
    end subroutine make_scene

    subroutine rfem_checks()
        type(scene_t) :: scene
        type(rfem_t) :: model
        type(error_t), allocatable :: err
        real(wp), allocatable :: y(:)
        integer :: trial
        character(len=64) :: sets(size(ALL) + 9)
        sets(1:size(ALL)) = ALL
        sets(size(ALL) + 1:) = [character(len=64) :: 'model.elements = 7', &
            'supports.top = "clamped"', 'supports.top_motion = "harmonic"', &
            'supports.top_amplitude = 0.02, 0.03', 'supports.top_frequency = 2.0', &
            'supports.top_angle_amplitude_deg = 5', 'supports.bottom = "pinned"', &
            'supports.bottom_motion = "table"', 'supports.bottom_table = "'//TABLE//'"']
        call make_scene(sets, scene)
        call rfem_create(model, scene%rope_spec_t, err)
        call suite%check_true(.not. allocated(err), 'rfem: create with every effect')
        if (allocated(err)) return
        do trial = 1, 3
            call random_state(model, trial, y)
            call rfem_jacobian_check(model, y, trial)
            call power_balance(model, y, 0.31_wp*trial, 'rfem')
        end do
        call rfem_gradient_check()
        ! the same in water through the rope's middle: buoyancy, added mass (with the
        ! current), the drag of the wetted part; a thick rope, so the smoothed surface is 1 cm
        block
            character(len=64) :: wet(size(sets) + 5)
            wet(1:size(sets)) = sets
            wet(size(sets) + 1:) = [character(len=64) :: 'effects.water = .true.', &
                'fluid.surface = 0.13', 'fluid.added_mass_coefficient = 1.0', &
                'fluid.tangential_added_mass_coefficient = 0.3', 'rope.diameter = 0.02']
            call make_scene(wet, scene)
            call rfem_create(model, scene%rope_spec_t, err)
            call suite%check_true(.not. allocated(err), 'rfem: create in water')
            if (allocated(err)) return
            do trial = 1, 3
                call random_state(model, trial, y)
                call rfem_jacobian_check(model, y, trial)
                call power_balance(model, y, 0.31_wp*trial, 'rfem in water')
            end do
        end block
    end subroutine rfem_checks

    !> A state near the initial one: positions by 2 mm, angles by 0.5 rad, velocities up to
    !! 1 m/s and 3 rad/s (rfem); angles, rates and stretches (mpp).
    subroutine random_state(model, trial, y)
        class(rope_model_t), intent(in) :: model
        integer, intent(in) :: trial
        real(wp), allocatable, intent(out) :: y(:)
        real(wp), allocatable :: r(:)
        integer :: i
        allocate (y(model%size()), r(model%size()))
        call model%initial_state(y)
        do i = 1, size(r)
            r(i) = sin(1.7_wp*i + 0.9_wp*trial)
        end do
        select type (model)
        type is (rfem_t)
            do i = 0, size(y)/6 - 1
                y(6*i + 1:6*i + 2) = y(6*i + 1:6*i + 2) + 2.0e-3_wp*r(6*i + 1:6*i + 2)
                y(6*i + 3) = y(6*i + 3) + 0.5_wp*r(6*i + 3)
                y(6*i + 4:6*i + 5) = r(6*i + 4:6*i + 5)
                y(6*i + 6) = 3.0_wp*r(6*i + 6)
            end do
        class default
            y = y + 0.3_wp*r
            if (size(y)/2 > model%n_elements()) then
                y(model%n_elements() + 1:size(y)/2) = 1.0e-3_wp*r(model%n_elements() + 1:size(y)/2)
            end if
        end select
    end subroutine random_state

    subroutine rfem_jacobian_check(model, y, trial)
        type(rfem_t), intent(inout) :: model
        real(wp), intent(in) :: y(:)
        integer, intent(in) :: trial
        real(wp), allocatable :: yp(:), ym(:), fp(:), fm(:), jb(:, :), jfd(:, :), jan(:, :)
        real(wp) :: h, worst, col_scale, t
        integer :: n, ml, mu, i, j, status, offset
        logical :: outside_ok
        character(len=40) :: tag
        write (tag, '(a, i0)') ' (rfem, trial ', trial
        tag = trim(tag)//')'
        t = 0.37_wp*trial
        n = size(y)
        allocate (yp(n), ym(n), fp(n), fm(n), jfd(n, n), jan(n, n))
        call model%bandwidths(ml, mu)
        offset = ml + mu + 1
        allocate (jb(2*ml + mu + 1, n))
        jb = 0.0_wp
        call model%jacobian(t, y, jb, offset, status)
        jan = 0.0_wp
        do j = 1, n
            do i = max(1, j - mu), min(n, j + ml)
                jan(i, j) = jb(offset + i - j, j)
            end do
        end do
        ! velocity columns: a larger step (the accelerations reach 1e5, so rounding would
        ! dominate at 1e-6; drag and friction are smooth on that scale)
        do j = 1, n
            h = 1.0e-6_wp*max(1.0_wp, abs(y(j)))
            if (mod(j - 1, 6) >= 3) h = 1.0e-4_wp
            yp = y
            ym = y
            yp(j) = y(j) + h
            ym(j) = y(j) - h
            call model%rhs(t, yp, fp, status)
            call model%rhs(t, ym, fm, status)
            jfd(:, j) = (fp - fm)/(2.0_wp*h)
        end do
        worst = 0.0_wp
        do j = 1, n
            col_scale = max(maxval(abs(jfd(:, j))), 1.0_wp)
            worst = max(worst, maxval(abs(jfd(:, j) - jan(:, j)))/col_scale)
        end do
        call suite%check_le(worst, 1.0e-6_wp, 'jacobian vs central differences, every '// &
                            'effect on'//trim(tag))
        outside_ok = .true.
        do j = 1, n
            do i = 1, n
                if (i - j > ml .or. j - i > mu) then
                    if (abs(jfd(i, j)) > 1.0e-9_wp*max(1.0_wp, maxval(abs(jfd(:, j))))) &
                        outside_ok = .false.
                end if
            end do
        end do
        call suite%check_true(outside_ok, 'jacobian lies inside its band'//trim(tag))
    end subroutine rfem_jacobian_check

    !> d(T + V)/dt along the flow (differences of the energy routine in t and y) equals the
    !! external power minus the dissipation power (the quadrature rates).
    subroutine power_balance(model, y, t, label)
        class(rope_model_t), intent(inout) :: model
        real(wp), intent(in) :: y(:), t
        character(len=*), intent(in) :: label
        real(wp) :: ydot(size(y)), yq(2), rates(2), h, dedt, scale
        type(energy_t) :: ep, em
        integer :: status
        character(len=80) :: tag
        call model%rhs(t, y, ydot, status)
        rates = 0.0_wp
        call model%quad_rhs(t, y, rates(1:model%quad_size()), status)
        call suite%check_true(model%quad_size() == 2, label//': external work is integrated')
        ! the central difference's truncation error is O(h^2) (the MPP in water at h = 1e-6:
        ! 4.4e-6 relative, 4.0e-5 at 3e-6; 1.7e-7 at 1e-7, where rounding begins to show)
        h = 1.0e-7_wp
        yq = 0.0_wp
        ep = model%energy(t + h, y + h*ydot, yq)
        em = model%energy(t - h, y - h*ydot, yq)
        dedt = (ep%total() - em%total())/(2.0_wp*h)
        scale = abs(rates(1)) + abs(rates(2)) + abs(dedt)
        write (tag, '(a, f5.2, a, 3es11.3)') ' at t =', t, ': dE/dt, work, dissipation', &
            dedt, rates(2), rates(1)
        call suite%check_le(abs(dedt - (rates(2) - rates(1)))/scale, 1.0e-6_wp, &
                            label//': d(T+V)/dt = work - dissipation'//trim(tag))
        call suite%check_true(rates(1) > 0.0_wp, label//': dissipation positive')
        ! the one-call form the explicit pairs use at every stage gives the same f and g
        ! (the RFEM sums the dissipation power inside its force pass)
        block
            real(wp) :: f2(size(y)), g2(2)
            g2 = 0.0_wp
            call model%rhs_quad(t, y, f2, g2(1:model%quad_size()), status)
            call suite%check_true(status == STATUS_OK .and. &
                                  maxval(abs(f2 - ydot)) == 0.0_wp .and. &
                                  maxval(abs(g2 - rates)) <= 1.0e-14_wp*maxval(abs(rates)), &
                                  label//': rhs_quad = rhs and quad_rhs')
        end block
    end subroutine power_balance

    !> Conservative forces (zero velocity, no current and no loads: drag and friction vanish)
    !! equal -grad V, with ground contact, point masses and a moved top anchor.
    subroutine rfem_gradient_check()
        type(scene_t) :: scene
        type(rfem_t) :: model
        type(error_t), allocatable :: err
        real(wp), allocatable :: y(:), yp(:), ym(:), gen(:, :)
        real(wp) :: h, grad_err, grad_scale
        integer :: i, c, k, ne
        ! damping off: a moving anchor's damper pulls even on a rope at rest
        call make_scene([character(len=64) :: 'model.elements = 7', 'effects.drag = .true.', &
            'effects.damping = .false.', &
            'effects.ground = .true.', 'ground.point = 0.15, 0.0', &
            'ground.normal = -1.0, 0.3', 'ground.stiffness = 2e3', &
            'attachments.mass_positions = 0.37, 1.0', 'attachments.masses = 0.03, 0.08', &
            'supports.top = "clamped"', 'supports.top_motion = "harmonic"', &
            'supports.top_amplitude = 0.02, 0.03', 'supports.top_frequency = 2.0', &
            'supports.top_phase_deg = 40, 70', 'supports.top_angle_amplitude_deg = 5', &
            'supports.top_angle_phase_deg = 60'], scene)
        call rfem_create(model, scene%rope_spec_t, err)
        call random_state(model, 5, y)
        ne = model%n_elements()
        do i = 1, ne
            y(6*(i - 1) + 4:6*(i - 1) + 6) = 0.0_wp
        end do
        allocate (gen(3, ne), yp(size(y)), ym(size(y)))
        call model%generalized_forces(y, gen)
        grad_err = 0.0_wp
        grad_scale = maxval(abs(gen))
        do i = 1, ne
            do c = 1, 3
                k = 6*(i - 1) + c
                h = 1.0e-6_wp
                yp = y
                ym = y
                yp(k) = yp(k) + h
                ym(k) = ym(k) - h
                grad_err = max(grad_err, abs(gen(c, i) + (model%potential_energy(yp) &
                                                          - model%potential_energy(ym))/(2*h)))
            end do
        end do
        call suite%check_le(grad_err/grad_scale, 1.0e-6_wp, 'rfem: forces = -grad V with '// &
                            'ground, point masses and a moved clamp')
    end subroutine rfem_gradient_check

    subroutine mpp_checks()
        type(scene_t) :: scene
        type(mpp_t) :: model
        type(error_t), allocatable :: err
        character(len=64) :: sets(size(ALL) + 10)
        sets(1:size(ALL)) = ALL
        sets(size(ALL) + 1:) = [character(len=64) :: 'model.kind = "mpp"', &
            'model.elements = 5', 'supports.top = "clamped"', &
            'supports.top_motion = "harmonic"', 'supports.top_amplitude = 0.02, 0.03', &
            'supports.top_frequency = 2.0', 'supports.top_angle_amplitude_deg = 5', &
            'supports.bottom = "clamped"', 'supports.bottom_motion = "table"', '']
        sets(size(sets)) = 'supports.bottom_table = "'//TABLE//'"'
        call make_scene(sets, scene)
        call mpp_create(model, scene%rope_spec_t, err)
        call suite%check_true(.not. allocated(err), 'mpp: create with every effect')
        if (allocated(err)) return
        call mpp_trials(model, 'mpp')
        ! the same in water through the rope's middle (as for the rfem): buoyancy, the rods'
        ! added mass (with the current), the drag of the wetted part
        block
            character(len=64) :: wet(size(sets) + 5)
            wet(1:size(sets)) = sets
            wet(size(sets) + 1:) = [character(len=64) :: 'effects.water = .true.', &
                'fluid.surface = 0.13', 'fluid.added_mass_coefficient = 1.0', &
                'fluid.tangential_added_mass_coefficient = 0.3', 'rope.diameter = 0.02']
            call make_scene(wet, scene)
            call mpp_create(model, scene%rope_spec_t, err)
            call suite%check_true(.not. allocated(err), 'mpp: create in water')
            if (allocated(err)) return
            call mpp_trials(model, 'mpp in water')
        end block
    end subroutine mpp_checks

    !> The power balance, M(q) a = r(0) - r(a) and the Jacobian against central differences
    !! of the rhs, in three states.
    subroutine mpp_trials(model, label)
        type(mpp_t), intent(inout) :: model
        character(len=*), intent(in) :: label
        real(wp), allocatable :: y(:), acc(:), r0(:), ra(:), mm(:, :), jb(:, :), yp(:)
        real(wp), allocatable :: f1(:), f0(:)
        real(wp) :: err_m, err_j, scale, h, t
        integer :: trial, nd, j, k, i, status
        do trial = 1, 3
            t = 0.29_wp*trial
            call random_state(model, trial, y)
            call power_balance(model, y, t, label)
            nd = size(y)/2
            allocate (acc(nd), r0(nd), ra(nd), mm(nd, nd))
            do j = 1, nd
                acc(j) = 2.0_wp*sin(0.9_wp*j + 0.2_wp)
            end do
            call model%residual(y, 0.0_wp*acc, r0, t)
            call model%residual(y, acc, ra, t)
            call model%mass_dense(y, mm, t)
            err_m = maxval(abs(matmul(mm, acc) - (r0 - ra)))/maxval(abs(matmul(mm, acc)))
            call suite%check_le(err_m, 1.0e-10_wp, label//': M(q) a = r(0) - r(a) with '// &
                                'point masses')
            allocate (jb(4*size(y), size(y)), f0(size(y)), f1(size(y)))
            jb = 0.0_wp
            call model%jacobian(t, y, jb, 2*size(y), status)
            err_j = 0.0_wp
            scale = 0.0_wp
            do k = 1, size(y)
                yp = y
                h = 1.0e-6_wp*max(1.0_wp, abs(y(k)))
                yp(k) = y(k) + h
                call model%rhs(t, yp, f1, status)
                yp(k) = y(k) - h
                call model%rhs(t, yp, f0, status)
                do i = 1, size(y)
                    err_j = max(err_j, abs((f1(i) - f0(i))/(2*h) - jb(2*size(y) + i - k, k)))
                    scale = max(scale, abs(jb(2*size(y) + i - k, k)))
                end do
            end do
            call suite%check_le(err_j/scale, 1.0e-4_wp, label//': jacobian vs differences, '// &
                                'every effect on')
            deallocate (acc, r0, ra, mm, jb, f0, f1)
        end do
    end subroutine mpp_trials

end program test_effects_derivatives
