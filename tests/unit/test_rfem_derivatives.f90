!> RFEM model derivatives: the analytic band Jacobian against central differences of
!! the right-hand side, conservative forces against minus the gradient of the potential
!! energy, and the damping forces against the dissipation power. Configurations 4 and 5
!! are in water crossing its surface (buoyancy, added mass, the drag of the wetted part;
!! 5 with a current and a point mass): their Jacobian rows go through each element's mass
!! block. (Their velocity-dependent forces include the added mass's, which do no work on
!! balance but are not dissipation: the damping check is for configurations 1 to 3.)
!! Configurations 6 and 7 carry tension only (compression = .false.), pinned at both ends,
!! with element 1 (6) or element n (7) pushed 3 mm along its axis towards its pin: the
!! slack pin's spring acts across the rope only (pin_offset), its own Jacobian.
program test_rfem_derivatives
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t
    use ropedyn_scene, only: scene_t
    use ropedyn_rfem, only: rfem_t, rfem_create
    use ropedyn_assert, only: test_suite_t
    implicit none
    type(test_suite_t) :: suite
    integer :: config

    suite%name = 'rfem_derivatives'
    call random_seed_fixed()
    do config = 1, 7
        call check_config(config)
    end do
    call check_effects_off()
    call suite%finish()

contains

    subroutine random_seed_fixed()
        integer :: n
        integer, allocatable :: seed(:)
        call random_seed(size=n)
        allocate (seed(n))
        seed = 12345
        call random_seed(put=seed)
    end subroutine random_seed_fixed

    !> 1: pinned top, free bottom (the paper); 2: clamped top, pinned bottom;
    !! 3: free top, clamped bottom, gravity off.
    subroutine check_config(config)
        integer, intent(in) :: config
        type(scene_t) :: scene
        type(rfem_t) :: model
        type(error_t), allocatable :: err
        character(len=40) :: tag
        integer :: trial

        scene%model%elements = 7
        scene%effects%damping = .true.
        select case (config)
        case (1)
            scene%supports%top = 'pinned'
            scene%supports%bottom = 'free'
        case (2)
            scene%supports%top = 'clamped'
            scene%supports%bottom = 'pinned'
            scene%supports%top_angle_deg = 10.0_wp
        case (3)
            scene%supports%top = 'free'
            scene%supports%bottom = 'clamped'
            scene%effects%gravity = .false.
        case (6, 7)
            scene%supports%bottom = 'pinned'
            scene%supports%bottom_anchor = [0.9_wp, 0.3_wp]
            scene%rope%compression = .false.
        case (4, 5)
            ! the rope's middle at the surface; a thick rope: the smoothed surface 1 cm wide
            scene%rope%diameter = 0.02_wp
            scene%effects%water = .true.
            scene%fluid%density = 1000.0_wp
            scene%fluid%surface = 0.13_wp
            scene%fluid%added_mass_coefficient = 1.0_wp
            scene%fluid%tangential_added_mass_coefficient = 0.3_wp
            scene%effects%drag = config == 4
            if (config == 5) then
                scene%fluid%current = [0.3_wp, -0.2_wp]
                scene%attachments%mass_positions(1) = 0.4_wp
                scene%attachments%masses(1) = 0.05_wp
            end if
        end select
        call rfem_create(model, scene%rope_spec_t, err)
        call suite%check_true(.not. allocated(err), 'create model')
        if (allocated(err)) return
        do trial = 1, 3
            write (tag, '(a, i0, a, i0)') ' config ', config, ' trial ', trial
            if (config >= 6) then
                call check_state(model, trim(tag), .true., merge(1, 7, config == 6))
            else
                call check_state(model, trim(tag), config <= 3)
            end if
        end do
    end subroutine check_config

    subroutine check_state(model, tag, dissipative_only, pushed)
        type(rfem_t), intent(inout) :: model
        character(len=*), intent(in) :: tag
        !> the velocity-dependent forces are the dampers' alone (no added mass)
        logical, intent(in) :: dissipative_only
        !> this end element (1 or n) pushed 3 mm along its axis towards its pin
        integer, intent(in), optional :: pushed
        real(wp), allocatable :: y(:), yp(:), ym(:), fp(:), fm(:), f0(:), jb(:, :), jfd(:, :)
        real(wp), allocatable :: jan(:, :), gen(:, :), gen0(:, :), y0v(:)
        real(wp) :: h, worst, col_scale, vp, vm, grad_err, grad_scale, power, power_check
        real(wp) :: qdot_quad(1)
        integer :: n, ml, mu, i, j, status, offset, ne, k, c
        logical :: outside_ok

        n = model%size()
        ne = model%n_elements()
        allocate (y(n), yp(n), ym(n), fp(n), fm(n), f0(n), jfd(n, n), jan(n, n))
        call model%initial_state(y)
        call random_state(y)
        if (present(pushed)) then
            k = 6*(pushed - 1)
            y(k + 1:k + 2) = y(k + 1:k + 2) + merge(-3.0e-3_wp, 3.0e-3_wp, pushed == 1)* &
                             [cos(y(k + 3)), sin(y(k + 3))]
        end if
        call model%bandwidths(ml, mu)
        offset = ml + mu + 1
        allocate (jb(2*ml + mu + 1, n))
        jb = 0.0_wp
        call model%jacobian(0.0_wp, y, jb, offset, status)
        jan = 0.0_wp
        do j = 1, n
            do i = max(1, j - mu), min(n, j + ml)
                jan(i, j) = jb(offset + i - j, j)
            end do
        end do
        ! central differences, column by column. F is linear in the velocities, so their
        ! columns take a large step (no truncation error, less rounding: the angular
        ! accelerations are ~1e6 rad/s^2 while their damping derivatives are ~10).
        do j = 1, n
            h = 1.0e-6_wp*max(1.0_wp, abs(y(j)))
            if (mod(j - 1, 6) >= 3) h = 1.0e-2_wp
            yp = y
            ym = y
            yp(j) = y(j) + h
            ym(j) = y(j) - h
            call model%rhs(0.0_wp, yp, fp, status)
            call model%rhs(0.0_wp, ym, fm, status)
            jfd(:, j) = (fp - fm)/(2.0_wp*h)
        end do
        worst = 0.0_wp
        do j = 1, n
            col_scale = max(maxval(abs(jfd(:, j))), 1.0_wp)
            worst = max(worst, maxval(abs(jfd(:, j) - jan(:, j)))/col_scale)
        end do
        call suite%check_le(worst, 1.0e-6_wp, 'jacobian vs central differences'//tag)
        ! nothing outside the declared band
        outside_ok = .true.
        do j = 1, n
            do i = 1, n
                if (i - j > ml .or. j - i > mu) then
                    if (abs(jfd(i, j)) > 1.0e-9_wp*max(1.0_wp, maxval(abs(jfd(:, j))))) &
                        outside_ok = .false.
                end if
            end do
        end do
        call suite%check_true(outside_ok, 'jacobian lies inside its band'//tag)

        ! conservative forces = -grad V (at zero velocity, damping forces vanish)
        allocate (gen(3, ne), gen0(3, ne), y0v(n))
        y0v = y
        do i = 1, ne
            y0v(6*(i - 1) + 4:6*(i - 1) + 6) = 0.0_wp
        end do
        call model%generalized_forces(y0v, gen)
        grad_err = 0.0_wp
        grad_scale = maxval(abs(gen))
        do i = 1, ne
            do c = 1, 3
                k = 6*(i - 1) + c
                h = 1.0e-6_wp
                yp = y0v
                ym = y0v
                yp(k) = yp(k) + h
                ym(k) = ym(k) - h
                vp = model%potential_energy(yp)
                vm = model%potential_energy(ym)
                grad_err = max(grad_err, abs(gen(c, i) + (vp - vm)/(2.0_wp*h)))
            end do
        end do
        call suite%check_le(grad_err/grad_scale, 1.0e-6_wp, 'forces = -grad V'//tag)

        if (.not. dissipative_only) return
        ! damping forces F_d = F(q, q') - F(q, 0) satisfy -F_d . q' = 2D, the dissipation
        ! power that quad_rhs integrates
        call model%generalized_forces(y, gen)
        call model%generalized_forces(y0v, gen0)
        power_check = 0.0_wp
        do i = 1, ne
            power_check = power_check - dot_product(gen(:, i) - gen0(:, i), &
                                                    y(6*(i - 1) + 4:6*(i - 1) + 6))
        end do
        call model%quad_rhs(0.0_wp, y, qdot_quad, status)
        power = qdot_quad(1)
        call suite%check_close(power_check, power, 1.0e-10_wp, 1.0e-14_wp, &
                               'quadrature rate = dissipation power -F_damp . qdot'//tag)
        call suite%check_true(power > 0.0_wp, 'dissipation power positive'//tag)
    end subroutine check_state

    !> Effects that are off contribute nothing: with tension, shear and bending off, a
    !! deformed rope with free ends falls freely; with gravity off as well it feels no
    !! force at all, and the pinned top still holds (supports are not effects).
    subroutine check_effects_off()
        type(scene_t) :: scene
        type(rfem_t) :: model
        type(error_t), allocatable :: err
        real(wp), allocatable :: y(:), ydot(:), gen(:, :)
        real(wp) :: e_el
        integer :: status

        scene%model%elements = 6
        scene%effects%tension = .false.
        scene%effects%shear = .false.
        scene%effects%bending = .false.
        scene%supports%top = 'free'
        call rfem_create(model, scene%rope_spec_t, err)
        allocate (y(model%size()), ydot(model%size()))
        call model%initial_state(y)
        call random_state(y)
        call model%rhs(0.0_wp, y, ydot, status)
        call suite%check_true(all(ydot(4::6) == scene%rope%gravity) .and. &
                              all(ydot(5::6) == 0.0_wp) .and. all(ydot(6::6) == 0.0_wp), &
                              'springs off, free ends: every element falls with g exactly')
        allocate (gen(3, model%n_elements()))
        call model%generalized_forces(y, gen, elastic=e_el)
        call suite%check_true(e_el == 0.0_wp, 'springs off: no elastic energy')

        scene%effects%gravity = .false.
        scene%supports%top = 'pinned'
        call rfem_create(model, scene%rope_spec_t, err)
        call model%initial_state(y)
        call model%rhs(0.0_wp, y, ydot, status)
        call suite%check_true(all(ydot(4::6) == 0.0_wp), &
                              'all effects off, undeformed: no acceleration')
        y(1) = y(1) + 1.0e-3_wp  ! pull element 1 away from the pin
        call model%rhs(0.0_wp, y, ydot, status)
        call suite%check_true(ydot(4) < 0.0_wp .and. all(ydot(10::6) == 0.0_wp), &
                              'the pin pulls element 1 back; the others feel nothing')
    end subroutine check_effects_off

    !> Perturb a straight state: positions by up to 2 mm, angles by up to 0.5 rad,
    !! velocities up to 1 m/s and 3 rad/s.
    subroutine random_state(y)
        real(wp), intent(inout) :: y(:)
        real(wp), allocatable :: r(:)
        integer :: i
        allocate (r(size(y)))
        call random_number(r)
        r = 2.0_wp*r - 1.0_wp
        do i = 0, size(y)/6 - 1
            y(6*i + 1:6*i + 2) = y(6*i + 1:6*i + 2) + 2.0e-3_wp*r(6*i + 1:6*i + 2)
            y(6*i + 3) = y(6*i + 3) + 0.5_wp*r(6*i + 3)
            y(6*i + 4:6*i + 5) = r(6*i + 4:6*i + 5)
            y(6*i + 6) = 3.0_wp*r(6*i + 6)
        end do
    end subroutine random_state
end program test_rfem_derivatives
