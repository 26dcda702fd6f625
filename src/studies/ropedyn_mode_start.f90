!> The start of `&initial shape = 'mode'` (docs/theory/statics-modes.md, "A mode start"):
!! the rope displaced along one of its linear modes, at rest.
!!
!! The linear mode q_e + s z (z the mode over the position coordinates, s its scale) bends
!! the stiff springs (the axial springs, the pins) at second order in s: on the catenary of
!! input/catenary.nml, at 5 mm, nine tenths of the start's energy above the equilibrium sat
!! in them, and the tension at the bottom pin was 5.24 N against 0.70 N at rest. The start
!! is therefore relaxed onto them: the state at rest of least potential energy V whose
!! modal coordinate c^T (q - q_e), c = M z, is that of q_e + s z. It is the linear mode to
!! first order in s, and its stiff springs carry only what the shape asks of them.
!!
!! Newton on the stationarity of V - mu (c^T (q - q_e) - a), the force f = -grad V:
!!     K dq = f + mu c,   c^T dq = a - c^T (q - q_e),   K = -df/dq,
!! with the multiplier mu of the step's end solved with it: two solves with one
!! factorization of the band of K, z1 = K^-1 f and z2 = K^-1 c, dq = z1 + mu z2, mu from
!! the constraint. For the linear problem the scaled mode is the solution (K z = omega^2 c):
!! the first step is zero, mu = s omega^2. The start q_e + s z meets the constraint, and
!! every step keeps it (c^T dq = 0), so a step too long for the nonlinear shape is halved
!! until V does not rise (beyond its rounding).
module ropedyn_mode_start
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use ropedyn_kinds, only: wp
    use ropedyn_lapack, only: dgbtrf, dgbtrs
    use ropedyn_problem, only: STATUS_OK
    use ropedyn_rope_model, only: rope_model_t
    use ropedyn_rope_spec, only: rope_spec_t
    use ropedyn_statics_terms, only: generalized_force, tangent_band, tangent_bandwidth, &
                                     rope_length, potential_energy
    use ropedyn_ldl, only: band_matvec
    use ropedyn_text, only: int_text
    implicit none
    private
    public :: relaxed_mode_start

    !> Newton steps at most (a large shape takes many halved steps)
    integer, parameter :: MAX_NEWTON = 50
    !> a step below this share of the rope's length (or of a radian) has converged
    real(wp), parameter :: STEP_TOL = 1.0e-10_wp
    !> below this share, a step that is not a tenth of the one before is the rounding of
    !! the solve (quadratic convergence has ended there; stiff ropes end higher)
    real(wp), parameter :: FLOOR_TOL = 1.0e-6_wp
    !> halvings of a step at most
    integer, parameter :: MAX_HALVINGS = 30

contains

    !> The mode start: `y`, the equilibrium at rest on entry, becomes the scaled mode
    !! `scale` z relaxed onto the stiff springs. Where the relaxation does not converge
    !! (a shape far beyond the linear range), y is the scaled linear mode and `note` says
    !! so ('' otherwise).
    subroutine relaxed_mode_start(model, spec, y, z, scale, note)
        class(rope_model_t), intent(inout) :: model
        type(rope_spec_t), intent(in) :: spec
        real(wp), intent(inout) :: y(:)
        real(wp), intent(in) :: z(:), scale
        character(len=:), allocatable, intent(out) :: note
        integer, allocatable :: pos(:), vel(:)
        real(wp), allocatable :: c(:), mb(:, :), y_linear(:), dq(:)
        real(wp) :: step, before, scale_q
        integer :: it
        logical :: failed

        call model%coordinates(pos, vel)
        allocate (mb(0:model%mass_bandwidth(), size(pos)))
        call model%coordinate_mass_band(y, mb)
        c = band_matvec(mb, z)
        y(pos) = y(pos) + scale*z
        y_linear = y
        note = ''
        scale_q = max(1.0_wp, rope_length(model))
        before = huge(1.0_wp)
        do it = 1, MAX_NEWTON
            call newton_step(model, y, pos, vel, c, dq, failed)
            if (.not. failed) call take_step(model, spec, y, pos, dq, failed)
            if (failed) exit
            ! (the Newton step's own size: a step halved many times is not convergence)
            step = maxval(abs(dq))
            if (step <= STEP_TOL*scale_q) return
            if (step <= FLOOR_TOL*scale_q .and. step > 0.1_wp*before) return
            before = step
        end do
        y = y_linear
        note = 'the mode start keeps the linear mode''s shape: relaxing it onto the '// &
            'stiff springs, which that shape stretches at second order in mode_amplitude, '// &
            'did not converge in '//int_text(MAX_NEWTON)//' Newton steps (a smaller '// &
            'mode_amplitude stays in the linear range)'
    end subroutine relaxed_mode_start

    !> The Newton step dq at y that keeps the modal coordinate (c^T dq = 0; its multiplier
    !! is solved with it, so no state is carried); `failed` when the forces, the stiffness
    !! or the solve are not usable.
    subroutine newton_step(model, y, pos, vel, c, dq, failed)
        class(rope_model_t), intent(inout) :: model
        real(wp), intent(in) :: y(:)
        integer, intent(in) :: pos(:), vel(:)
        real(wp), intent(in) :: c(:)
        real(wp), allocatable, intent(out) :: dq(:)
        logical, intent(out) :: failed
        real(wp), allocatable :: f(:), kb(:, :), rhs(:, :)
        real(wp) :: mu
        integer :: status, info, kd

        kd = tangent_bandwidth(model)
        allocate (f(size(pos)), kb(-kd:kd, size(pos)), rhs(size(pos), 2))
        call generalized_force(model, y, pos, vel, f, status)
        failed = status /= STATUS_OK
        if (failed) return
        call tangent_band(model, y, pos, vel, kd, kb, status, hessian=.true.)
        failed = status /= STATUS_OK .or. .not. all(ieee_is_finite(kb))
        if (failed) return
        rhs(:, 1) = f
        rhs(:, 2) = c
        call band_solve(kd, kb, rhs, info)
        failed = info /= 0 .or. .not. all(ieee_is_finite(rhs))
        if (failed) return
        ! z1 = K^-1 f, z2 = K^-1 c, dq = z1 + mu z2 with c^T dq = 0
        mu = -dot_product(c, rhs(:, 1))/dot_product(c, rhs(:, 2))
        dq = rhs(:, 1) + mu*rhs(:, 2)
        failed = .not. all(ieee_is_finite(dq))
    end subroutine newton_step

    !> y := y + alpha dq with alpha the first of 1, 1/2, 1/4, ... at which the potential
    !! energy does not rise beyond its rounding; `failed` when none does.
    subroutine take_step(model, spec, y, pos, dq, failed)
        class(rope_model_t), intent(inout) :: model
        type(rope_spec_t), intent(in) :: spec
        real(wp), intent(inout) :: y(:)
        integer, intent(in) :: pos(:)
        real(wp), intent(in) :: dq(:)
        logical, intent(out) :: failed
        real(wp), allocatable :: trial(:)
        real(wp) :: v, v_trial, alpha
        integer :: k
        v = potential_energy(model, y, spec)
        alpha = 1.0_wp
        failed = .true.
        do k = 1, MAX_HALVINGS
            trial = y
            trial(pos) = y(pos) + alpha*dq
            v_trial = potential_energy(model, trial, spec)
            if (v_trial <= v + 1.0e3_wp*epsilon(1.0_wp)*max(abs(v), abs(v_trial))) then
                failed = .false.
                exit
            end if
            alpha = 0.5_wp*alpha
        end do
        if (failed) return
        y = trial
    end subroutine take_step

    !> b := K^-1 b for the columns of b, K given by its band kb(i - j, j) (tangent_band's
    !! storage; LU, LAPACK dgbtrf/dgbtrs).
    subroutine band_solve(kd, kb, b, info)
        integer, intent(in) :: kd
        real(wp), intent(in) :: kb(-kd:, :)
        real(wp), intent(inout) :: b(:, :)
        integer, intent(out) :: info
        real(wp), allocatable :: ab(:, :)
        integer, allocatable :: ipiv(:)
        integer :: n, i, j
        n = size(kb, 2)
        ! LAPACK's band storage with kd rows for the fill-in: ab(2 kd + 1 + i - j, j)
        allocate (ab(3*kd + 1, n), ipiv(n))
        ab = 0.0_wp
        do j = 1, n
            do i = max(1, j - kd), min(n, j + kd)
                ab(2*kd + 1 + i - j, j) = kb(i - j, j)
            end do
        end do
        call dgbtrf(n, n, kd, kd, ab, 3*kd + 1, ipiv, info)
        if (info /= 0) return
        call dgbtrs('N', n, kd, kd, size(b, 2), ab, 3*kd + 1, ipiv, b, n, info)
    end subroutine band_solve
end module ropedyn_mode_start
