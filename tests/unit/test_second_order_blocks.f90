!> A problem that keeps the default second-order blocks of problem_t (taken from the
!! first-order Jacobian) while delegating everything else to a model: the reference against
!! which the models' direct assembly is checked.
module test_second_order_default
    use ropedyn_kinds, only: wp
    use ropedyn_problem, only: problem_t
    implicit none
    private
    public :: default_blocks_t

    type, extends(problem_t) :: default_blocks_t
        class(problem_t), pointer :: inner => null()
    contains
        procedure :: size => plain_size
        procedure :: bandwidths => plain_bandwidths
        procedure :: rhs => plain_rhs
        procedure :: has_jacobian => plain_has_jacobian
        procedure :: jacobian => plain_jacobian
        procedure :: has_second_order => plain_has_second_order
        procedure :: second_order_layout => plain_second_order_layout
    end type default_blocks_t

contains

    pure integer function plain_size(self)
        class(default_blocks_t), intent(in) :: self
        plain_size = self%inner%size()
    end function plain_size

    pure subroutine plain_bandwidths(self, ml, mu)
        class(default_blocks_t), intent(in) :: self
        integer, intent(out) :: ml, mu
        call self%inner%bandwidths(ml, mu)
    end subroutine plain_bandwidths

    subroutine plain_rhs(self, t, y, ydot, status)
        class(default_blocks_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: ydot(:)
        integer, intent(out) :: status
        call self%inner%rhs(t, y, ydot, status)
    end subroutine plain_rhs

    pure logical function plain_has_jacobian(self) result(has)
        class(default_blocks_t), intent(in) :: self
        has = self%inner%has_jacobian()
    end function plain_has_jacobian

    subroutine plain_jacobian(self, t, y, jb, offset, status)
        class(default_blocks_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(inout) :: jb(:, :)
        integer, intent(in) :: offset
        integer, intent(out) :: status
        call self%inner%jacobian(t, y, jb, offset, status)
    end subroutine plain_jacobian

    pure logical function plain_has_second_order(self) result(has)
        class(default_blocks_t), intent(in) :: self
        has = self%inner%has_second_order()
    end function plain_has_second_order

    pure subroutine plain_second_order_layout(self, pos, vel, kl, ku)
        class(default_blocks_t), intent(in) :: self
        integer, allocatable, intent(out) :: pos(:), vel(:)
        integer, intent(out) :: kl, ku
        call self%inner%second_order_layout(pos, vel, kl, ku)
    end subroutine plain_second_order_layout
end module test_second_order_default

!> The second-order blocks K = dF_v/dq, C = dF_v/dv and M of the rate rows that the models
!! assemble directly (ropedyn_problem, `second_order_blocks`):
!! - explicit form, RFEM (every effect on, point masses, a clamped moving top, a pinned
!!   bottom following a table; and the paper's rope) and MPP (every effect on): equal to the
!!   default taken from the first-order Jacobian; RFEM's implicit form equals its explicit
!!   one (no mass matrix);
!! - implicit form, MPP (K with d(M(q) a)/dq at the current accelerations): the reduced
!!   solve (M - g C - g^2 K) dv = r_v + g K r_q, dq = r_q + g dv gives the solution of the
!!   first-order Newton system (blockdiag(I, M) - g J) (dq, dv) = (r_q, r_v), J the
!!   Jacobian of the residual formulation by central differences, solved densely;
!! - the MPP's O(n) solve: M(q) times the accelerations of `rhs` equals f = r(q, q', 0).
program test_second_order_blocks
    use ropedyn_kinds, only: wp
    use ropedyn_lapack, only: dgesv
    use ropedyn_error, only: error_t
    use ropedyn_problem, only: problem_t, STATUS_OK
    use ropedyn_scene, only: scene_t, read_scene
    use ropedyn_rope_model, only: rope_model_t
    use ropedyn_rfem, only: rfem_t, rfem_create
    use ropedyn_mpp, only: mpp_t, mpp_create
    use ropedyn_assert, only: test_suite_t
    use test_second_order_default, only: default_blocks_t
    implicit none

    type(test_suite_t) :: suite
    character(len=*), parameter :: TABLE = 'test_blocks_table.dat'
    !> every effect on (the rfem and mpp cases add their own supports)
    character(len=64), parameter :: EVERY_EFFECT(*) = [character(len=64) :: &
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

    suite%name = 'second_order_blocks'
    call write_table()
    call rfem_cases()
    call mpp_cases()
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
        open (newunit=unit, file='test_blocks_scene.nml', status='replace', action='write')
        write (unit, '(a)') '&model /'
        close (unit)
        call read_scene('test_blocks_scene.nml', sets, scene, err)
        if (allocated(err)) then
            call suite%check_true(.false., 'scene: '//err%message)
            call suite%finish()
        end if
    end subroutine make_scene

    !> A state near the initial one: positions by 2 mm, angles by 0.5 rad, velocities up to
    !! 1 m/s and 3 rad/s (rfem); angles, rates and stretches (mpp).
    subroutine some_state(model, trial, y)
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
    end subroutine some_state

    !> The blocks of `model` (band storage with LU room, as an integrator allocates them)
    !! as dense matrices.
    subroutine dense_blocks(model, t, y, implicit_form, k, c, m, status)
        class(problem_t), intent(inout) :: model
        real(wp), intent(in) :: t, y(:)
        logical, intent(in) :: implicit_form
        real(wp), allocatable, intent(out) :: k(:, :), c(:, :), m(:, :)
        integer, intent(out) :: status
        integer, allocatable :: pos(:), vel(:)
        real(wp), allocatable :: kb(:, :), cb(:, :), mb(:, :)
        integer :: kl, ku, np, off, i, j
        call model%second_order_layout(pos, vel, kl, ku)
        np = size(pos)
        off = kl + ku + 1
        allocate (kb(2*kl + ku + 1, np), cb(2*kl + ku + 1, np), mb(2*kl + ku + 1, np))
        kb = 0.0_wp
        cb = 0.0_wp
        mb = 0.0_wp
        call model%second_order_blocks(t, y, implicit_form, kb, cb, mb, off, status)
        allocate (k(np, np), c(np, np), m(np, np))
        k = 0.0_wp
        c = 0.0_wp
        m = 0.0_wp
        do j = 1, np
            do i = max(1, j - ku), min(np, j + kl)
                k(i, j) = kb(off + i - j, j)
                c(i, j) = cb(off + i - j, j)
                m(i, j) = mb(off + i - j, j)
            end do
        end do
        ! nothing may have been written outside the band
        if (any(kb(1:off - ku - 1, :) /= 0.0_wp) .or. any(cb(1:off - ku - 1, :) /= 0.0_wp)) &
            status = -99
    end subroutine dense_blocks

    !> Direct blocks of `model` against the default extraction (explicit form).
    subroutine against_default(model, t, y, label)
        class(problem_t), intent(inout), target :: model
        real(wp), intent(in) :: t, y(:)
        character(len=*), intent(in) :: label
        type(default_blocks_t) :: plain
        real(wp), allocatable :: k(:, :), c(:, :), m(:, :), k0(:, :), c0(:, :), m0(:, :)
        integer :: status, status0
        plain%inner => model
        call dense_blocks(model, t, y, .false., k, c, m, status)
        call dense_blocks(plain, t, y, .false., k0, c0, m0, status0)
        call suite%check_true(status == STATUS_OK .and. status0 == STATUS_OK, &
                              label//': blocks assembled (direct and default), inside the band')
        call suite%check_le(maxval(abs(k - k0))/maxval(abs(k0)), 1.0e-12_wp, &
                            label//': K = default from the Jacobian (relative)')
        call suite%check_le(maxval(abs(c - c0))/maxval(abs(c0)), 1.0e-12_wp, &
                            label//': C = default from the Jacobian (relative)')
        call suite%check_le(maxval(abs(m - m0)), 0.0_wp, label//': mass block = identity')
    end subroutine against_default

    subroutine rfem_cases()
        type(scene_t) :: scene
        type(rfem_t), target :: model
        type(error_t), allocatable :: err
        real(wp), allocatable :: y(:), k(:, :), c(:, :), m(:, :), ki(:, :), ci(:, :), mi(:, :)
        integer :: trial, status
        character(len=64) :: sets(size(EVERY_EFFECT) + 9)
        character(len=40) :: tag
        sets(1:size(EVERY_EFFECT)) = EVERY_EFFECT
        sets(size(EVERY_EFFECT) + 1:) = [character(len=64) :: 'model.elements = 7', &
            'supports.top = "clamped"', 'supports.top_motion = "harmonic"', &
            'supports.top_amplitude = 0.02, 0.03', 'supports.top_frequency = 2.0', &
            'supports.top_angle_amplitude_deg = 5', 'supports.bottom = "pinned"', &
            'supports.bottom_motion = "table"', 'supports.bottom_table = "'//TABLE//'"']
        call make_scene(sets, scene)
        call rfem_create(model, scene%rope_spec_t, err)
        call suite%check_true(.not. allocated(err), 'rfem: create with every effect')
        if (allocated(err)) return
        do trial = 1, 2
            write (tag, '(a, i0)') 'rfem, every effect, trial ', trial
            call some_state(model, trial, y)
            call against_default(model, 0.37_wp*trial, y, trim(tag))
            call dense_blocks(model, 0.37_wp*trial, y, .false., k, c, m, status)
            call dense_blocks(model, 0.37_wp*trial, y, .true., ki, ci, mi, status)
            call suite%check_true(all(k == ki) .and. all(c == ci) .and. all(m == mi), &
                                  trim(tag)//': implicit form = explicit form')
        end do
        call make_scene([character(len=64) :: 'model.elements = 30'], scene)
        call rfem_create(model, scene%rope_spec_t, err)
        call some_state(model, 3, y)
        call against_default(model, 0.0_wp, y, 'rfem, the paper''s rope, n = 30')
    end subroutine rfem_cases

    subroutine mpp_cases()
        type(scene_t) :: scene
        type(mpp_t), target :: model
        type(error_t), allocatable :: err
        real(wp), allocatable :: y(:)
        integer :: trial
        character(len=64) :: sets(size(EVERY_EFFECT) + 10)
        character(len=40) :: tag
        sets(1:size(EVERY_EFFECT)) = EVERY_EFFECT
        sets(size(EVERY_EFFECT) + 1:) = [character(len=64) :: 'model.kind = "mpp"', &
            'model.elements = 5', 'supports.top = "clamped"', &
            'supports.top_motion = "harmonic"', 'supports.top_amplitude = 0.02, 0.03', &
            'supports.top_frequency = 2.0', 'supports.top_angle_amplitude_deg = 5', &
            'supports.bottom = "clamped"', 'supports.bottom_motion = "table"', '']
        sets(size(sets)) = 'supports.bottom_table = "'//TABLE//'"'
        call make_scene(sets, scene)
        call mpp_create(model, scene%rope_spec_t, err)
        call suite%check_true(.not. allocated(err), 'mpp: create with every effect')
        if (allocated(err)) return
        do trial = 1, 2
            write (tag, '(a, i0)') 'mpp, every effect, trial ', trial
            call some_state(model, trial, y)
            call against_default(model, 0.29_wp*trial, y, trim(tag))
            call mass_solve_check(model, 0.29_wp*trial, y, trim(tag))
            call implicit_identity(model, 0.29_wp*trial, y, trim(tag))
        end do
        ! the same in water through the rope's middle: the rods' added mass in M(q), in the
        ! O(n) solve and in K (the derivative of M(q) a)
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
            do trial = 1, 2
                write (tag, '(a, i0)') 'mpp in water, trial ', trial
                call some_state(model, trial, y)
                call against_default(model, 0.29_wp*trial, y, trim(tag))
                call mass_solve_check(model, 0.29_wp*trial, y, trim(tag))
                call implicit_identity(model, 0.29_wp*trial, y, trim(tag))
            end do
        end block
        ! inextensible members, pinned top: the angle rows alone
        call make_scene([character(len=64) :: 'model.kind = "mpp"', 'model.elements = 6', &
                         'effects.tension = .false.', 'supports.bottom = "pinned"', &
                         'supports.bottom_anchor = 0.5, 0.6'], scene)
        call mpp_create(model, scene%rope_spec_t, err)
        call some_state(model, 3, y)
        call against_default(model, 0.0_wp, y, 'mpp, inextensible')
        call mass_solve_check(model, 0.0_wp, y, 'mpp, inextensible')
        call implicit_identity(model, 0.0_wp, y, 'mpp, inextensible')
        ! inextensible in water (the angle rows of the O(n) solve with the added mass)
        call make_scene([character(len=64) :: 'model.kind = "mpp"', 'model.elements = 6', &
                         'effects.tension = .false.', 'supports.bottom = "pinned"', &
                         'supports.bottom_anchor = 0.5, 0.6', 'effects.water = .true.', &
                         'fluid.surface = 0.3', 'fluid.added_mass_coefficient = 1.0', &
                         'fluid.tangential_added_mass_coefficient = 0.3', &
                         'fluid.current = 0.2, -0.4', 'rope.diameter = 0.02'], scene)
        call mpp_create(model, scene%rope_spec_t, err)
        call some_state(model, 3, y)
        call against_default(model, 0.0_wp, y, 'mpp, inextensible, in water')
        call mass_solve_check(model, 0.0_wp, y, 'mpp, inextensible, in water')
        call implicit_identity(model, 0.0_wp, y, 'mpp, inextensible, in water')
    end subroutine mpp_cases

    !> M(q) a = f for the accelerations a of `rhs` (the O(n) solve) and f = r(q, q', 0).
    subroutine mass_solve_check(model, t, y, label)
        type(mpp_t), intent(inout) :: model
        real(wp), intent(in) :: t, y(:)
        character(len=*), intent(in) :: label
        real(wp) :: ydot(size(y)), f(size(y)/2), zero(size(y)/2), mm(size(y)/2, size(y)/2)
        integer :: nd, status
        nd = size(y)/2
        zero = 0.0_wp
        call model%rhs(t, y, ydot, status)
        call model%residual(y, zero, f, t)
        call model%mass_dense(y, mm, t)
        call suite%check_le(maxval(abs(matmul(mm, ydot(nd + 1:)) - f))/maxval(abs(f)), &
                            1.0e-12_wp, label//': M(q) (rhs accelerations) = f (O(n) solve)')
    end subroutine mass_solve_check

    !> Implicit-form blocks: the reduced solve equals the dense first-order solve.
    subroutine implicit_identity(model, t, y, label)
        type(mpp_t), intent(inout) :: model
        real(wp), intent(in) :: t, y(:)
        character(len=*), intent(in) :: label
        real(wp), allocatable :: k(:, :), c(:, :), m(:, :), a(:, :), jf(:, :), big(:, :)
        real(wp), allocatable :: rp(:), rm(:), acc(:), f(:), yp(:), x(:, :), rhs(:), dv(:, :)
        real(wp), parameter :: g = 2.0e-3_wp
        integer, allocatable :: ipiv(:)
        integer :: nd, j, status, info
        real(wp) :: h, err_v, err_q
        character(len=12) :: text
        nd = size(y)/2
        call dense_blocks(model, t, y, .true., k, c, m, status)
        call suite%check_true(status == STATUS_OK, label//': implicit blocks assembled')
        ! accelerations a = M^{-1} f, densely
        allocate (acc(nd), f(nd), a(nd, nd), ipiv(2*nd), rp(nd), rm(nd), yp(size(y)))
        call model%mass_dense(y, a, t)
        call suite%check_le(maxval(abs(m - a)), 0.0_wp, label//': implicit mass block = M(q)')
        acc = 0.0_wp
        call model%residual(y, acc, f, t)
        acc = f
        call dgesv(nd, 1, a, nd, ipiv, acc, nd, info)
        ! J of the residual formulation: rows (0, I), (dr(q, q', a)/dq, dr/dq'), central
        ! differences at fixed a
        allocate (jf(2*nd, 2*nd))
        jf = 0.0_wp
        do j = 1, nd
            jf(j, nd + j) = 1.0_wp
        end do
        do j = 1, 2*nd
            h = 1.0e-6_wp*max(1.0_wp, abs(y(j)))
            yp = y
            yp(j) = y(j) + h
            call model%residual(yp, acc, rp, t)
            yp(j) = y(j) - h
            call model%residual(yp, acc, rm, t)
            jf(nd + 1:, j) = (rp - rm)/(2.0_wp*h)
        end do
        ! dense first-order solve of (blockdiag(I, M) - g J) x = r
        allocate (big(2*nd, 2*nd), x(2*nd, 1), rhs(2*nd))
        call model%mass_dense(y, a, t)
        big = -g*jf
        do j = 1, nd
            big(j, j) = big(j, j) + 1.0_wp
        end do
        big(nd + 1:, nd + 1:) = big(nd + 1:, nd + 1:) + a
        do j = 1, 2*nd
            rhs(j) = cos(0.7_wp*j) + 0.1_wp
        end do
        x(:, 1) = rhs
        call dgesv(2*nd, 1, big, 2*nd, ipiv, x, 2*nd, info)
        ! reduced: (M - g C - g^2 K) dv = r_v + g K r_q, dq = r_q + g dv
        allocate (dv(nd, 1))
        a = m - g*c - g**2*k
        dv(:, 1) = rhs(nd + 1:) + g*matmul(k, rhs(1:nd))
        call dgesv(nd, 1, a, nd, ipiv, dv, nd, info)
        err_v = maxval(abs(dv(:, 1) - x(nd + 1:, 1)))/maxval(abs(x(nd + 1:, 1)))
        err_q = maxval(abs(rhs(1:nd) + g*dv(:, 1) - x(1:nd, 1)))/maxval(abs(x(1:nd, 1)))
        call suite%check_le(max(err_v, err_q), 1.0e-6_wp, label//': reduced solve with the '// &
                            'implicit blocks = dense first-order Newton solve (relative; '// &
                            'central differences in J)')
        ! the check can tell: K without d(M a)/dq (df/dq, the residual at zero acceleration)
        ! misses the first-order solution by far more
        acc = 0.0_wp
        do j = 1, nd
            h = 1.0e-6_wp*max(1.0_wp, abs(y(j)))
            yp = y
            yp(j) = y(j) + h
            call model%residual(yp, acc, rp, t)
            yp(j) = y(j) - h
            call model%residual(yp, acc, rm, t)
            k(:, j) = (rp - rm)/(2.0_wp*h)
        end do
        a = m - g*c - g**2*k
        dv(:, 1) = rhs(nd + 1:) + g*matmul(k, rhs(1:nd))
        call dgesv(nd, 1, a, nd, ipiv, dv, nd, info)
        err_v = maxval(abs(dv(:, 1) - x(nd + 1:, 1)))/maxval(abs(x(nd + 1:, 1)))
        write (text, '(es9.2)') err_v
        call suite%check_true(err_v > 1.0e-4_wp, label//': without d(M a)/dq in K the '// &
                              'reduced solve is off by '//trim(text)//' (the check discriminates)')
    end subroutine implicit_identity
end program test_second_order_blocks
