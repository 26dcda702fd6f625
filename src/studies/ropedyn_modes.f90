!> Natural frequencies and mode shapes of a rope model about its static equilibrium.
!!
!! Linearizing M(q) q'' = f(q, q') about an equilibrium q_e at rest gives
!!     M dq'' + C dq' + K dq = 0,   K = -df/dq,  C = -df/dq',  M = M(q_e)
!! (ropedyn_statics: `tangent_matrices`). K is the Hessian of the potential energy there,
!! symmetric up to the rounding of the Jacobian (its asymmetry is reported and K is
!! symmetrized). The undamped modes solve the symmetric-definite generalized eigenproblem
!! K z = lambda M z (LAPACK dsbgvx when K and M are narrow-banded, as for RFEM; dsygvx
!! otherwise), omega = sqrt(lambda), lowest first. Each mode also reports
!! - its damping ratio zeta = z^T C z / (2 omega z^T M z) (exact for proportional damping,
!!   a first-order estimate otherwise; the damped eigenvalues are not computed),
!! - the displacement of the drawing polyline per unit shape (central differences of
!!   `polyline`), and the axial fraction: the share of sum |d|^2 of the points that lies
!!   along the rope (the tangent of each element at the equilibrium).
!! A negative lambda (an unstable equilibrium) gives omega = -sqrt(-lambda).
module ropedyn_modes
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use ropedyn_kinds, only: wp
    use ropedyn_lapack, only: dsygvx, dsbgvx
    use ropedyn_error, only: error_t, make_error, ERR_SOLVER, ERR_INPUT, ERR_INTERNAL
    use ropedyn_problem, only: STATUS_OK
    use ropedyn_rope_model, only: energy_t
    use ropedyn_rope_model, only: rope_model_t
    use ropedyn_text, only: int_text, text_t, append_text
    use ropedyn_rope_spec, only: rope_spec_t
    use ropedyn_statics, only: statics_options_t, statics_result_t, &
                               tangent_matrices, rope_length
    use ropedyn_line_equilibrium, only: static_equilibrium
    use ropedyn_ldl, only: bandwidth
    use ropedyn_mode_start, only: relaxed_mode_start
    implicit none
    private
    public :: modes_result_t, compute_modes, equilibrium_initial_state

    !> The lowest modes of a linearization.
    type :: modes_result_t
        integer :: count = 0                          !< modes computed
        integer :: ndof = 0                           !< generalized coordinates
        real(wp), allocatable :: lambda(:)            !< eigenvalues omega^2, 1/s^2
        real(wp), allocatable :: omega(:)             !< rad/s, ascending
        real(wp), allocatable :: shape(:, :)          !< (ndof, count), max |.| = 1
        real(wp), allocatable :: shape_points(:, :, :)  !< (2, 2 elements, count), m per unit
        real(wp), allocatable :: damping_ratio(:)     !< zeta, 1
        real(wp), allocatable :: axial_fraction(:)    !< share of motion along the rope, 1
        real(wp) :: asymmetry = 0.0_wp                !< max |K - K^T| / max |K|
        character(len=:), allocatable :: eigensolver  !< 'dsbgvx' or 'dsygvx'
    end type modes_result_t

contains

    !> The `count` lowest modes about the equilibrium state y (at rest).
    subroutine compute_modes(model, y, count, res, err)
        class(rope_model_t), intent(inout) :: model
        real(wp), intent(in) :: y(:)
        integer, intent(in) :: count
        type(modes_result_t), intent(out) :: res
        type(error_t), allocatable, intent(out) :: err
        integer, allocatable :: pos(:), vel(:), iwork(:), ifail(:)
        real(wp), allocatable :: kt(:, :), cv(:, :), mm(:, :), ks(:, :), z(:, :), w(:)
        real(wp), allocatable :: work(:), ab(:, :), bb(:, :), qmat(:, :)
        real(wp) :: abstol, wq(1), kmax
        integer :: nd, m, info, status, kd_k, kd_m, i, j, k, lwork

        call model%coordinates(pos, vel)
        nd = size(pos)
        res%ndof = nd
        if (count < 1) then
            call make_error(err, ERR_INPUT, 'modes: the number of modes must be >= 1')
            return
        end if
        m = min(count, nd)
        allocate (kt(nd, nd), cv(nd, nd), mm(nd, nd))
        call tangent_matrices(model, y, pos, vel, kt, status, cv)
        if (status /= STATUS_OK .or. .not. all(ieee_is_finite(kt))) then
            call make_error(err, ERR_SOLVER, 'modes: the stiffness matrix is not finite at '// &
                            'the equilibrium')
            return
        end if
        call model%coordinate_mass(y, mm)
        call check_mass(model, y, pos, vel, mm, err)
        if (allocated(err)) return
        kmax = max(maxval(abs(kt)), tiny(1.0_wp))
        res%asymmetry = maxval(abs(kt - transpose(kt)))/kmax
        ks = 0.5_wp*(kt + transpose(kt))
        kd_k = bandwidth(ks)
        kd_m = bandwidth(mm)
        abstol = 2.0_wp*tiny(1.0_wp)
        allocate (w(nd), z(nd, m), iwork(5*nd), ifail(nd))

        if (4*kd_k < nd .and. kd_m <= kd_k) then
            res%eigensolver = 'dsbgvx'
            allocate (ab(kd_k + 1, nd), bb(kd_m + 1, nd), qmat(nd, nd), work(7*nd))
            ab = 0.0_wp
            bb = 0.0_wp
            do j = 1, nd
                do i = max(1, j - kd_k), j
                    ab(kd_k + 1 + i - j, j) = ks(i, j)
                end do
                do i = max(1, j - kd_m), j
                    bb(kd_m + 1 + i - j, j) = mm(i, j)
                end do
            end do
            call dsbgvx('V', 'I', 'U', nd, kd_k, kd_m, ab, kd_k + 1, bb, kd_m + 1, qmat, nd, &
                        0.0_wp, 0.0_wp, 1, m, abstol, k, w, z, nd, work, iwork, ifail, info)
        else
            res%eigensolver = 'dsygvx'
            block
                real(wp), allocatable :: a(:, :), b(:, :)
                a = ks
                b = mm
                call dsygvx(1, 'V', 'I', 'U', nd, a, nd, b, nd, 0.0_wp, 0.0_wp, 1, m, abstol, &
                            k, w, z, nd, wq, -1, iwork, ifail, info)
                lwork = max(8*nd, int(wq(1)))
                allocate (work(lwork))
                call dsygvx(1, 'V', 'I', 'U', nd, a, nd, b, nd, 0.0_wp, 0.0_wp, 1, m, abstol, &
                            k, w, z, nd, work, lwork, iwork, ifail, info)
            end block
        end if
        if (info > nd) then
            call make_error(err, ERR_SOLVER, 'modes: the mass matrix is not positive '// &
                            'definite ('//res%eigensolver//' info '//int_text(info)//')')
            return
        else if (info /= 0 .or. k < m) then
            call make_error(err, ERR_SOLVER, 'modes: the eigensolver '//res%eigensolver// &
                            ' failed (info '//int_text(info)//', '//int_text(k)//' of '// &
                            int_text(m)//' eigenvalues)')
            return
        end if

        res%count = m
        allocate (res%lambda(m), res%omega(m), res%shape(nd, m), res%damping_ratio(m), &
                  res%axial_fraction(m), res%shape_points(2, 2*model%n_elements(), m))
        do k = 1, m
            res%lambda(k) = w(k)
            res%omega(k) = sign(sqrt(abs(w(k))), w(k))
            ! z is M-normalized: z^T M z = 1
            res%damping_ratio(k) = 0.0_wp
            if (res%omega(k) > 0.0_wp) res%damping_ratio(k) = &
                dot_product(z(:, k), matmul(cv, z(:, k)))/(2.0_wp*res%omega(k))
            i = maxloc(abs(z(:, k)), 1)
            res%shape(:, k) = z(:, k)/z(i, k)
            call point_shape(model, y, pos, res%shape(:, k), res%shape_points(:, :, k), &
                             res%axial_fraction(k))
        end do
    end subroutine compute_modes

    !> ERR_INTERNAL unless the kinetic energy of a test velocity equals v^T M v / 2, the
    !! supports at rest as everywhere in the modes (an anchor that moves at t = 0 would add
    !! its velocity to the kinetic energy of the MPP, whose coordinates hang from it).
    subroutine check_mass(model, y, pos, vel, mm, err)
        class(rope_model_t), intent(inout) :: model
        real(wp), intent(in) :: y(:), mm(:, :)
        integer, intent(in) :: pos(:), vel(:)
        type(error_t), allocatable, intent(out) :: err
        real(wp), allocatable :: yv(:), v(:), yq(:)
        real(wp) :: t_model, t_matrix
        type(energy_t) :: e
        integer :: k
        logical :: held
        character(len=120) :: text
        ! rates in [-1, 1) from the golden-ratio sequence (no sin: see ropedyn_spectrum)
        v = [(2.0_wp*modulo(0.6180339887498949_wp*k, 1.0_wp) - 1.0_wp, k = 1, size(pos))]
        yv = y
        yv(vel) = v
        allocate (yq(max(1, model%quad_size())))
        yq = 0.0_wp
        held = model%supports_at_rest
        model%supports_at_rest = .true.
        e = model%energy(0.0_wp, yv, yq)
        model%supports_at_rest = held
        t_model = e%kinetic
        t_matrix = 0.5_wp*dot_product(v, matmul(mm, v))
        if (abs(t_model - t_matrix) > 1.0e-9_wp*abs(t_matrix)) then
            write (text, '(a, es12.5, a, es12.5, a)') ' (T = ', t_model, ' J, v^T M v/2 = ', &
                t_matrix, ' J)'
            call make_error(err, ERR_INTERNAL, 'modes: the '//model%model_name()//' model''s '// &
                            'coordinate_mass does not match its kinetic energy'//trim(text))
        end if
    end subroutine check_mass

    !> Displacement of the polyline points per unit of the coordinate shape dz, and the
    !! share of sum |d|^2 along the elements' equilibrium tangents.
    subroutine point_shape(model, y, pos, dz, dp, axial)
        class(rope_model_t), intent(in) :: model
        real(wp), intent(in) :: y(:), dz(:)
        integer, intent(in) :: pos(:)
        real(wp), intent(out) :: dp(:, :), axial
        real(wp), allocatable :: p0(:, :), pp(:, :), pm(:, :), yp(:)
        real(wp) :: eps, t(2), tn, along, total
        integer :: i, np
        np = size(dp, 2)
        allocate (p0(2, np), pp(2, np), pm(2, np))
        eps = 1.0e-6_wp*rope_length(model)/max(maxval(abs(dz)), tiny(1.0_wp))
        call model%polyline(y, p0)
        yp = y
        yp(pos) = y(pos) + eps*dz
        call model%polyline(yp, pp)
        yp(pos) = y(pos) - eps*dz
        call model%polyline(yp, pm)
        dp = (pp - pm)/(2.0_wp*eps)
        along = 0.0_wp
        total = sum(dp**2)
        do i = 1, np/2
            t = p0(:, 2*i) - p0(:, 2*i - 1)
            tn = norm2(t)
            if (tn <= 0.0_wp) cycle
            t = t/tn
            along = along + dot_product(t, dp(:, 2*i - 1))**2 + dot_product(t, dp(:, 2*i))**2
        end do
        axial = 0.0_wp
        if (total > 0.0_wp) axial = along/total
    end subroutine point_shape

    !> The initial state of `&initial shape = 'equilibrium'` (the static equilibrium, at
    !! rest, found from the 'straight' start in y) or 'mode' (that equilibrium plus mode
    !! `mode` scaled so that its largest point displacement is `mode_amplitude`, relaxed
    !! onto the stiff springs: ropedyn_mode_start; at rest). Other shapes leave y
    !! unchanged. `notes`: the warnings about the start (the statics' caution, the mode's
    !! relaxation), each naming its key.
    subroutine equilibrium_initial_state(model, spec, y, err, notes)
        class(rope_model_t), intent(inout) :: model
        type(rope_spec_t), intent(in) :: spec
        real(wp), intent(inout) :: y(:)
        type(error_t), allocatable, intent(out) :: err
        type(text_t), allocatable, intent(out), optional :: notes(:)
        character(len=:), allocatable :: said
        type(statics_result_t) :: sres
        type(modes_result_t) :: mres
        integer :: k
        real(wp) :: largest

        if (present(notes)) allocate (notes(0))
        select case (trim(spec%initial%shape))
        case ('equilibrium', 'mode')
        case default
            return
        end select
        call static_equilibrium(model, spec, y, statics_options_t(), sres, err)
        if (allocated(err)) then
            err%message = err%message//" (&initial shape = '"//trim(spec%initial%shape)//"')"
            return
        end if
        if (allocated(sres%caution) .and. present(notes)) call append_text(notes, &
            spec%origin('initial.shape')//": &initial: shape = '"// &
            trim(spec%initial%shape)//"': the statics: "//sres%caution)
        if (trim(spec%initial%shape) /= 'mode') return
        k = spec%initial%mode
        call compute_modes(model, y, k, mres, err)
        if (allocated(err)) return
        if (mres%count < k) then
            call make_error(err, ERR_INPUT, spec%origin('initial.mode')//': &initial: mode = '// &
                            int_text(k)// &
                            ': the model has only '//int_text(mres%ndof)//' modes')
            return
        end if
        largest = maxval(norm2(mres%shape_points(:, :, k), dim=1))
        if (.not. largest > 0.0_wp) then
            call make_error(err, ERR_SOLVER, spec%origin('initial.mode')//': &initial: mode = '// &
                            int_text(k)// &
                            ': the mode does not move the rope')
            return
        end if
        call relaxed_mode_start(model, spec, y, mres%shape(:, k), &
                                spec%initial%mode_amplitude/largest, said)
        if (present(notes) .and. len(said) > 0) call append_text(notes, &
            spec%origin('initial.mode_amplitude')//': &initial: '//said)
    end subroutine equilibrium_initial_state

end module ropedyn_modes
