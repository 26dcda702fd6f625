!> The MPP model's equations against its Lagrangian: M(q) from the residual, the residual
!! from difference quotients of T, V and D computed independently from positions and
!! velocities (also in water, where T holds the added mass's energy: every term of the
!! residual at non-zero accelerations, which the Newton matrix and the internal forces
!! use), the explicit Jacobian, and energy conservation/balance in time.
program test_mpp
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t
    use ropedyn_rope_model, only: energy_t
    use ropedyn_scene, only: scene_t, read_scene
    use ropedyn_mpp, only: mpp_t, mpp_create
    use ropedyn_integrator, only: integrator_t, solver_options_t
    use ropedyn_solvers, only: new_integrator
    use ropedyn_assert, only: test_suite_t
    implicit none

    type(test_suite_t) :: suite
    character(len=1024) :: source_dir

    suite%name = 'mpp'
    call get_command_argument(1, source_dir)
    if (len_trim(source_dir) == 0) source_dir = '.'
    call test_equations('extensible, clamped top, pinned bottom', [character(len=64) :: &
        'model.elements = 4', 'supports.top = "clamped"', 'supports.bottom = "pinned"', &
        'supports.bottom_anchor = 0.6, 0.5', 'rope.normal_damping = 50'])
    call test_equations('inextensible, pinned top, clamped bottom', [character(len=64) :: &
        'model.elements = 3', 'effects.tension = .false.', 'supports.bottom = "clamped"', &
        'supports.bottom_anchor = 0.5, 0.6', 'rope.normal_damping = 50'])
    call test_equations('point masses, ground contact (no damping, no friction)', &
        [character(len=64) :: 'model.elements = 4', 'attachments.mass_positions = 0.4, 1.0', &
        'attachments.masses = 0.05, 0.1', 'effects.ground = .true.', 'ground.point = 0.5, 0.0', &
        'ground.stiffness = 50', 'ground.damping = 0', 'ground.friction_coefficient = 0', &
        'rope.normal_damping = 50'])
    ! (still water: with a current the run's energies count the water's kinetic energy
    ! with v, not v - u, and hold no Lagrangian; docs/theory/water.md)
    call test_equations('in water across the surface, added mass', &
        [character(len=64) :: 'model.elements = 4', 'rope.diameter = 0.03', &
        'effects.water = .true.', 'fluid.density = 1000', 'fluid.surface = 0.45', &
        'fluid.added_mass_coefficient = 1.0', 'fluid.tangential_added_mass_coefficient = 0.3', &
        'rope.normal_damping = 50'])
    ! the tip of some_state 1 cm past the anchor along the last member (and 3 mm across): a
    ! slack pin on a line that carries tension only acts across the rope, with a couple.
    ! (Inextensible members: the difference quotients' step, 1e-4, would cross the kink of
    ! a tension-only member spring stretched by 2e-5 in some_state.)
    call test_equations('tension only, the bottom pin slack', [character(len=64) :: &
        'model.elements = 4', 'effects.tension = .false.', 'rope.compression = .false.', &
        'supports.bottom = "pinned"', 'supports.bottom_anchor = 0.895713, 0.309175', &
        'rope.normal_damping = 50'])
    call test_energy()
    call suite%finish()

contains

    subroutine make(sets, model)
        character(len=*), intent(in) :: sets(:)
        type(mpp_t), intent(out) :: model
        type(scene_t) :: scene
        type(error_t), allocatable :: err
        character(len=64) :: all_sets(size(sets) + 1)
        all_sets(1) = 'model.kind = "mpp"'
        all_sets(2:) = sets
        call read_scene(trim(source_dir)//'/input/paper.nml', all_sets, scene, err)
        if (.not. allocated(err)) call mpp_create(model, scene%rope_spec_t, err)
        if (allocated(err)) then
            call suite%check_true(.false., err%message)
            call suite%finish()
        end if
    end subroutine make

    !> A state far from equilibrium (angles, stretches and rates all non-zero).
    subroutine some_state(model, y)
        type(mpp_t), intent(in) :: model
        real(wp), allocatable, intent(out) :: y(:)
        integer :: j, nd
        allocate (y(model%size()))
        nd = size(y)/2
        do j = 1, nd
            y(j) = 0.3_wp + 0.4_wp*sin(1.7_wp*j)
            y(nd + j) = 1.1_wp*cos(2.3_wp*j)
        end do
        if (nd > model%n_elements()) then   ! elongations are small
            y(model%n_elements() + 1:nd) = 1.0e-3_wp*y(model%n_elements() + 1:nd)
            y(nd + model%n_elements() + 1:) = 1.0e-2_wp*y(nd + model%n_elements() + 1:)
        end if
    end subroutine some_state

    !> T, V (elastic + gravity) and D (= power/2) of (q, qdot), from the model's energy
    !! routine (positions and velocities), independent of the residual.
    subroutine tvd(model, q, qd, t, v, d)
        type(mpp_t), intent(inout) :: model
        real(wp), intent(in) :: q(:), qd(:)
        real(wp), intent(out) :: t, v, d
        type(energy_t) :: e
        real(wp) :: p(1)
        integer :: j_status
        e = model%energy(0.0_wp, [q, qd], [0.0_wp])
        t = e%kinetic
        v = e%elastic + e%gravity
        call model%quad_rhs(0.0_wp, [q, qd], p, j_status)
        d = 0.5_wp*p(1)
    end subroutine tvd

    subroutine test_equations(label, sets)
        character(len=*), intent(in) :: label
        character(len=*), intent(in) :: sets(:)
        type(mpp_t) :: model
        real(wp), allocatable :: y(:), q(:), qd(:), acc(:), r0(:), ra(:), mm(:, :)
        real(wp), allocatable :: lhs(:), jb(:, :), ydot0(:), ydot1(:), yp(:)
        real(wp) :: h, tp, tm, vp, vm, dp, dm, t0, v0, d0, err_m, err_l, err_j, scale
        real(wp) :: hess
        integer :: nd, j, k, status, i
        call make(sets, model)
        call some_state(model, y)
        nd = size(y)/2
        q = y(1:nd)
        qd = y(nd + 1:)
        allocate (acc(nd), r0(nd), ra(nd), mm(nd, nd), lhs(nd))
        do j = 1, nd
            acc(j) = 2.0_wp*sin(0.9_wp*j + 0.2_wp)
        end do
        ! 1. M a = r(q, q', 0) - r(q, q', a)
        call model%residual(y, 0.0_wp*acc, r0)
        call model%residual(y, acc, ra)
        call model%mass_dense(y, mm)
        err_m = maxval(abs(matmul(mm, acc) - (r0 - ra)))/maxval(abs(matmul(mm, acc)))
        call suite%check_le(err_m, 1.0e-10_wp, label//': M(q) a equals r(0) - r(a)')
        call suite%check_le(maxval(abs(mm - transpose(mm))), 0.0_wp, label//': M symmetric')

        ! 2. Lagrange's equations by difference quotients of T, V, D:
        !    d/dt dT/dq'_j - dT/dq_j + dV/dq_j + dD/dq'_j = -r_j(q, q', a)
        h = 1.0e-4_wp
        do j = 1, nd
            lhs(j) = 0.0_wp
            ! d/dt (dT/dq'_j) = sum_k d2T/dq'_j dq'_k a_k + d2T/dq'_j dq_k q'_k
            do k = 1, nd
                hess = mixed(model, y, j, k, .true.)
                lhs(j) = lhs(j) + hess*acc(k)
                hess = mixed(model, y, j, k, .false.)
                lhs(j) = lhs(j) + hess*qd(k)
            end do
            q(j) = y(j) + h
            call tvd(model, q, qd, tp, vp, dp)
            q(j) = y(j) - h
            call tvd(model, q, qd, tm, vm, dm)
            q(j) = y(j)
            lhs(j) = lhs(j) - (tp - tm)/(2*h) + (vp - vm)/(2*h)
            qd(j) = y(nd + j) + h
            call tvd(model, q, qd, tp, vp, dp)
            qd(j) = y(nd + j) - h
            call tvd(model, q, qd, tm, vm, dm)
            qd(j) = y(nd + j)
            lhs(j) = lhs(j) + (dp - dm)/(2*h)
        end do
        call tvd(model, q, qd, t0, v0, d0)
        scale = maxval(abs(ra)) + maxval(abs(matmul(mm, acc)))
        err_l = maxval(abs(lhs + ra))/scale
        call suite%check_le(err_l, 1.0e-5_wp, label//': residual = Lagrange equations by '// &
                            'difference quotients of T, V, D')

        ! 3. Explicit Jacobian against central differences of the right-hand side.
        allocate (jb(4*size(y), size(y)), ydot0(size(y)), ydot1(size(y)))
        jb = 0.0_wp
        call model%jacobian(0.0_wp, y, jb, 2*size(y), status)
        err_j = 0.0_wp
        scale = 0.0_wp
        do k = 1, size(y)
            yp = y
            h = 1.0e-6_wp*max(1.0_wp, abs(y(k)))
            yp(k) = y(k) + h
            call model%rhs(0.0_wp, yp, ydot1, status)
            yp(k) = y(k) - h
            call model%rhs(0.0_wp, yp, ydot0, status)
            do i = 1, size(y)
                err_j = max(err_j, abs((ydot1(i) - ydot0(i))/(2*h) - jb(2*size(y) + i - k, k)))
                scale = max(scale, abs(jb(2*size(y) + i - k, k)))
            end do
        end do
        call suite%check_le(err_j/scale, 1.0e-4_wp, label//': explicit Jacobian vs differences')
    end subroutine test_equations

    !> d2T/dq'_j dq'_k (wrt_rates) or d2T/dq'_j dq_k at y, central differences.
    real(wp) function mixed(model, y, jj, kk, wrt_rates) result(val)
        type(mpp_t), intent(inout) :: model
        real(wp), intent(in) :: y(:)
        integer, intent(in) :: jj, kk
        logical, intent(in) :: wrt_rates
        real(wp) :: f(4), dummy1, dummy2, hh, q(size(y)/2), qd(size(y)/2)
        integer :: s, nd
        real(wp), parameter :: sj(4) = [1, 1, -1, -1], sk(4) = [1, -1, 1, -1]
        hh = 1.0e-3_wp
        nd = size(y)/2
        do s = 1, 4
            q = y(1:nd)
            qd = y(nd + 1:)
            qd(jj) = qd(jj) + sj(s)*hh
            if (wrt_rates) then
                qd(kk) = qd(kk) + sk(s)*hh
            else
                q(kk) = q(kk) + sk(s)*hh
            end if
            call tvd(model, q, qd, f(s), dummy1, dummy2)
        end do
        val = (f(1) - f(2) - f(3) + f(4))/(4*hh*hh)
    end function mixed

    !> Undamped: T + V conserved within a tolerance-bounded drift (both solvers); damped:
    !! T + V + dissipated = E0 and T + V never increases.
    subroutine test_energy()
        type(mpp_t), target :: model
        class(integrator_t), allocatable :: integ
        type(solver_options_t) :: opt
        type(error_t), allocatable :: err
        type(energy_t) :: e0, e
        real(wp), allocatable :: y(:)
        real(wp) :: yq(1), t, drift, balance, emax, previous
        integer :: m, j
        character(len=5), parameter :: methods(2) = ['cvode', 'mebdf']
        character(len=100) :: label
        do m = 1, 2
            call make([character(len=64) :: 'model.elements = 8', 'effects.damping = .false.'], &
                      model)
            allocate (y(model%size()))
            call model%initial_state(y)
            yq = 0.0_wp
            e0 = model%energy(0.0_wp, y, yq)
            opt%rtol = 1.0e-8_wp
            opt%atol = 1.0e-10_wp
            call new_integrator(methods(m), integ, err)
            call integ%init(model, 0.0_wp, y, yq, opt, err)
            call integ%advance_to(0.5_wp, t, y, yq, err)
            call suite%check_true(.not. allocated(err), methods(m)//': undamped run completes')
            e = model%energy(t, y, yq)
            drift = abs(e%total() - e0%total())
            write (label, '(a, es9.2, a)') methods(m)//': undamped energy drift ', drift, &
                ' J <= 100 rtol |E0|'
            call suite%check_le(drift, 100.0_wp*opt%rtol*abs(e0%total()), trim(label))
            deallocate (y)

            call make([character(len=64) :: 'model.elements = 8'], model)
            allocate (y(model%size()))
            call model%initial_state(y)
            yq = 0.0_wp
            e0 = model%energy(0.0_wp, y, yq)
            call integ%init(model, 0.0_wp, y, yq, opt, err)
            emax = -huge(1.0_wp)     ! largest increase of T + V between outputs
            e = e0
            do j = 1, 20
                previous = e%total()
                call integ%advance_to(0.025_wp*j, t, y, yq, err)
                e = model%energy(t, y, yq)
                emax = max(emax, e%total() - previous)
            end do
            call suite%check_le(emax, 10.0_wp*opt%rtol*abs(e0%total()), &
                                methods(m)//': damped T + V never increases between outputs (J)')
            balance = abs(e%balance() - e0%balance())
            write (label, '(a, es9.2, a, es9.2, a)') methods(m)//': damped balance error ', &
                balance, ' J (dissipated ', e%dissipated, ' J)'
            call suite%check_le(balance, 10.0_wp*opt%rtol*abs(e0%total()), trim(label))
            call suite%check_true(e%dissipated > 0.0_wp, methods(m)//': energy is dissipated')
            deallocate (y)
        end do
    end subroutine test_energy
end program test_mpp
