!> Static equilibrium of a rope model and the linearization about it.
!!
!! Works on any `rope_model_t` through its generalized coordinates (`coordinates`: where q
!! and q' sit in the ODE state) and their mass matrix (`coordinate_mass`). At rest (q' = 0)
!! the generalized force is f(q) = M(q) q'' = -dV/dq (damping vanishes), so an equilibrium is
!! a zero of f, and the tangent stiffness K(q) = -df/dq is the Hessian of the potential
!! energy V (elastic + gravity) there. f and K come from the model:
!! - explicit models (RFEM): f = M a with a = ydot(vel) from `rhs`, K = -M da/dq from the
!!   analytic band Jacobian (rows vel, columns pos);
!! - linearly implicit models (MPP: M(y) y' = F(y)): f = F(vel) from `implicit_rhs` (O(n))
!!   and K by central differences of it (step 1e-6, error ~1e-12 relative).
!!
!! Solver (`solve_statics`): a trust-region (Levenberg-Marquardt) Newton iteration on V,
!!     (K + sigma M + E) delta = f,    q <- q + delta,
!! E >= 0 from a modified Cholesky factorization (Gill, Murray & Wright), so that every step
!! descends even where K is indefinite (a compressed rope); a step is accepted when V falls
!! by at least 1e-4 of the quadratic model's prediction, after up to two second-order
!! (chord) corrections; sigma shrinks after good steps, grows after poor or rejected ones,
!! and is 0 (Newton) near the solution. Converged when a Newton step is below
!! step_tolerance * L, or when max |f| is at the rounding level of the stiffness
!! (10 eps sum_j |K_kj| (|q_j| + L)). `find_equilibrium` adds a continuation in the support
!! stiffness for a bottom anchor far from the start. Derivation and limits:
!! docs/theory/statics-modes.md.
module ropedyn_statics
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t, make_error, ERR_SOLVER
    use ropedyn_problem, only: STATUS_OK
    use ropedyn_rope_model, only: rope_model_t, energy_t
    use ropedyn_model_factory, only: create_model
    use ropedyn_text, only: int_text, fixed_text
    use ropedyn_rope_spec, only: rope_spec_t, bottom_anchor_given
    use ropedyn_ldl, only: ldl_t, ldl_factor, ldl_solve
    use ropedyn_statics_terms, only: generalized_force, tangent_matrices, potential_energy, &
                                     rope_length, total_weight
    implicit none
    private
    public :: statics_options_t, statics_result_t
    public :: solve_statics, find_equilibrium, check_equilibrium_exists
    public :: generalized_force, tangent_matrices, potential_energy, rope_length, total_weight

    !> Controls of `solve_statics`.
    type :: statics_options_t
        integer :: max_iterations = 2000           !< linear solves (accepted + rejected steps)
        real(wp) :: step_tolerance = 1.0e-10_wp    !< final Newton step / rope length
        logical :: continuation = .true.           !< find_equilibrium may use continuation
    end type statics_options_t

    !> What `solve_statics` reports.
    type :: statics_result_t
        integer :: iterations = 0          !< linear solves (accepted and rejected steps)
        integer :: rejected = 0            !< steps rejected (energy rise, singular, non-finite)
        integer :: newton_steps = 0        !< accepted steps with sigma = 0
        integer :: stages = 0              !< continuation stages (0: solved directly; the
                                           !! iterations of an abandoned continuation count)
        real(wp) :: residual = 0.0_wp      !< max |f_k| at the equilibrium, N or N m
        real(wp) :: residual_relative = 0.0_wp  !< residual / total weight (/ 1 N without gravity)
        real(wp) :: rounding_level = 0.0_wp     !< residual / its rounding floor
        real(wp) :: last_step = 0.0_wp     !< max |delta q| of the last accepted step, m or rad
        real(wp) :: weight = 0.0_wp        !< total weight of the rope, N (0 without gravity)
        real(wp) :: elastic = 0.0_wp       !< elastic energy at the equilibrium, J
        real(wp) :: gravity = 0.0_wp       !< gravity potential at the equilibrium, J
        character(len=:), allocatable :: criterion  !< 'newton step' or 'rounding level'
    end type statics_result_t

contains

    !> ERR_SOLVER when the spec cannot have an equilibrium: both ends free under gravity.
    subroutine check_equilibrium_exists(spec, err)
        type(rope_spec_t), intent(in) :: spec
        type(error_t), allocatable, intent(out) :: err
        if (trim(spec%supports%top) == 'free' .and. trim(spec%supports%bottom) == 'free' &
            .and. spec%effects%gravity .and. spec%rope%gravity > 0.0_wp) then
            call make_error(err, ERR_SOLVER, spec%path//': statics: no equilibrium: both '// &
                "supports are free (&supports top = 'free', bottom = 'free') and gravity is "// &
                'on, so the rope falls freely; pin or clamp an end, or switch gravity off')
        end if
    end subroutine check_equilibrium_exists

    !> The equilibrium of the spec from the starting state y. When the bottom end is
    !! pinned or clamped to an anchor far (> L/1000) from the lower end of the starting
    !! configuration, the support spring starts hugely stretched: its pull (~ EA/dl times the
    !! distance) dwarfs the weight and pushes the straight rope along its axis, a saddle
    !! (compression) where the steps must be tiny. Then the solution is
    !! first continued in `support_stiffness_factor`: from the value at which the spring pulls
    !! with 0.3 times the weight up to the spec's value in geometric stages, each started
    !! from the previous equilibrium (models rebuilt); a stage multiplies the
    !! factor by 10 at first, by 100 after an easy stage, and its step is cut by 4 after a
    !! failure. If the first stage fails or the continuation stalls (RFEM: its top support
    !! softens too and the rope drops far), it solves directly from the start, which the
    !! RFEM's Cartesian coordinates tolerate. Otherwise it is `solve_statics`.
    subroutine find_equilibrium(model, spec, y, options, result, err)
        class(rope_model_t), intent(inout) :: model
        type(rope_spec_t), intent(in) :: spec
        real(wp), intent(inout) :: y(:)
        type(statics_options_t), intent(in) :: options
        type(statics_result_t), intent(out) :: result
        type(error_t), allocatable, intent(out) :: err
        type(rope_spec_t) :: stage_spec
        class(rope_model_t), allocatable :: stage_model
        type(statics_result_t) :: stage
        type(statics_options_t) :: stage_options
        type(error_t), allocatable :: stage_err
        real(wp), allocatable :: points(:, :), y_try(:), y_start(:)
        real(wp) :: p_end(2), target(2), distance, pull, weight, log_f0, log_f1, s, ds, s_try
        character(len=:), allocatable :: fallback
        integer :: iterations, rejected, stages

        iterations = 0
        rejected = 0
        stages = 0
        fallback = ''
        call check_equilibrium_exists(spec, err)
        if (allocated(err)) return
        weight = total_weight(model, spec)
        continuation: if (options%continuation .and. &
                          trim(spec%supports%bottom) /= 'free' .and. &
                          bottom_anchor_given(spec) .and. weight > 0.0_wp) then
            allocate (points(2, 2*model%n_elements()))
            call model%polyline(y, points)
            p_end = points(:, size(points, 2))
            target = spec%supports%bottom_anchor
            distance = norm2(target - p_end)
            if (distance <= 1.0e-3_wp*rope_length(model)) exit continuation
            ! the spring's pull at the start: dV/d(anchor) along the anchor's offset
            pull = anchor_pull()
            if (allocated(err)) return
            if (pull <= 0.3_wp*weight) exit continuation
            y_start = y
            log_f1 = log(spec%supports%support_stiffness_factor)
            log_f0 = log_f1 + log(0.3_wp*weight/pull)
            stage_options%max_iterations = 100
            stage_options%step_tolerance = 1.0e-8_wp
            s = 0.0_wp
            ds = log(10.0_wp)/(log_f1 - log_f0)
            ! the first stage starts at s = 0 itself
            s_try = 0.0_wp
            do
                stage_spec = spec
                stage_spec%supports%support_stiffness_factor = &
                    exp(log_f0 + s_try*(log_f1 - log_f0))
                call create_model(stage_spec, stage_model, err)
                if (allocated(err)) return
                y_try = y
                call solve_statics(stage_model, stage_spec, y_try, stage_options, stage, &
                                   stage_err)
                iterations = iterations + stage%iterations
                rejected = rejected + stage%rejected
                stages = stages + 1
                if (allocated(stage_err)) then
                    deallocate (stage_err)
                    ds = 0.25_wp*ds
                    if (ds < 1.0e-3_wp .or. stages == 1) then
                        ! give up the continuation: solve directly from the start
                        fallback = 'continuation in support_stiffness_factor stalled at '// &
                                   fixed_text(100*s, 1)//' % of the way, then '
                        y = y_start
                        stages = 0
                        exit
                    end if
                else
                    y = y_try
                    s = s_try
                    if (s >= 1.0_wp) exit
                    if (stage%iterations < 15) ds = 2.0_wp*ds
                end if
                s_try = min(1.0_wp, s + ds)
                if (s_try > 1.0_wp - 1.0e-9_wp) s_try = 1.0_wp
            end do
        end if continuation
        call solve_statics(model, spec, y, options, result, err)
        if (allocated(err) .and. len(fallback) > 0) then
            err%message = err%message//' ('//fallback//'solved directly from the start)'
        end if
        result%iterations = result%iterations + iterations
        result%rejected = result%rejected + rejected
        result%stages = stages
    contains
        !> |dV/d(anchor)| along the unit offset of the bottom anchor, N (central differences).
        real(wp) function anchor_pull() result(r)
            type(rope_spec_t) :: moved
            class(rope_model_t), allocatable :: probe
            real(wp) :: u(2), h, vp, vm
            u = (target - p_end)/distance
            h = 1.0e-4_wp*rope_length(model)
            r = 0.0_wp
            moved = spec
            moved%supports%bottom_anchor = target + h*u
            call create_model(moved, probe, err)
            if (allocated(err)) return
            vp = potential_energy(probe, y, moved)
            moved%supports%bottom_anchor = target - h*u
            call create_model(moved, probe, err)
            if (allocated(err)) return
            vm = potential_energy(probe, y, moved)
            r = abs(vp - vm)/(2*h)
        end function anchor_pull
    end subroutine find_equilibrium

    !> Find the static equilibrium reached from the state y by descending the potential energy.
    !! On entry y holds the starting configuration (velocities are set to zero); on
    !! success it holds the equilibrium at rest. Errors (ERR_SOLVER) name the cause:
    !! no equilibrium (free-free under gravity), no convergence, divergence, non-finite
    !! forces, or no step that lowers the energy.
    subroutine solve_statics(model, spec, y, options, result, err)
        class(rope_model_t), intent(inout) :: model
        type(rope_spec_t), intent(in) :: spec
        real(wp), intent(inout) :: y(:)
        type(statics_options_t), intent(in) :: options
        type(statics_result_t), intent(out) :: result
        type(error_t), allocatable, intent(out) :: err
        integer, allocatable :: pos(:), vel(:)
        real(wp), allocatable :: f(:), f_new(:), kt(:, :), mm(:, :), delta(:)
        real(wp), allocatable :: y_new(:), q0(:), mdiag(:), qscale(:), kd(:)
        real(wp) :: length, v_old, v_new, sigma, sigma0, sigma_used, step, noise, rho
        real(wp) :: predicted, lambda_step, dmdd, step_limit, sigma_good
        integer :: nd, status, consecutive, k
        logical :: accept, fresh, modified, newton
        type(ldl_t) :: fac
        character(len=200) :: text

        call check_equilibrium_exists(spec, err)
        if (allocated(err)) return
        call model%coordinates(pos, vel)
        nd = size(pos)
        allocate (f(nd), f_new(nd), kt(nd, nd), mm(nd, nd), delta(nd), mdiag(nd), kd(nd))
        y(vel) = 0.0_wp
        length = rope_length(model)
        step_limit = 0.5_wp*max(length, 1.0_wp)
        result%weight = total_weight(model, spec)
        q0 = y(pos)

        call generalized_force(model, y, pos, vel, f, status)
        if (status /= STATUS_OK) then
            call make_error(err, ERR_SOLVER, spec%path//': statics: non-finite forces '// &
                            'in the starting configuration')
            return
        end if
        v_old = potential_energy(model, y, spec)
        call model%coordinate_mass(y, mm)
        mdiag = [(mm(k, k), k = 1, nd)]
        ! shift scale: a step of the freest coordinate of L/10 (explicit estimate); the
        ! iteration starts as Newton (sigma = 0) and shifts only when it must
        sigma0 = maxval(abs(f)/mdiag)/(0.1_wp*max(length, 1.0e-3_wp))
        sigma0 = max(sigma0, sqrt(tiny(1.0_wp)))
        sigma = 0.0_wp
        sigma_good = 0.0_wp
        consecutive = 0
        fresh = .true.

        do
            if (fresh) then
                call tangent_matrices(model, y, pos, vel, kt, status)
                if (status /= STATUS_OK) then
                    call make_error(err, ERR_SOLVER, spec%path//': statics: the stiffness '// &
                                    'matrix is not finite at iteration '// &
                                    int_text(result%iterations))
                    return
                end if
                kt = 0.5_wp*(kt + transpose(kt))
                if (at_rounding_level()) then
                    result%criterion = 'rounding level'
                    exit
                end if
                call model%coordinate_mass(y, mm)
                fresh = .false.
            end if
            if (result%iterations >= options%max_iterations) then
                write (text, '(a, i0, a, es10.3, a, es10.3, a, es9.2)') 'no convergence in ', &
                    result%iterations, ' iterations (max |f| = ', maxval(abs(f)), &
                    ' N, last step ', result%last_step, ' m or rad, shift ', sigma
                call make_error(err, ERR_SOLVER, spec%path//': statics: '//trim(text)// &
                    '); the rope may have no stable equilibrium near the start, or needs '// &
                    'more iterations (--max-iterations)')
                return
            end if
            sigma_used = sigma
            result%iterations = result%iterations + 1
            ! (K + sigma M + E) delta = f, E >= 0 from the modified Cholesky factorization
            call ldl_factor(kt + sigma*mm, 1.0_wp/sqrt(mdiag), fac, modified)
            newton = sigma == 0.0_wp .and. .not. modified
            delta = ldl_solve(fac, f)
            accept = all(ieee_is_finite(delta))
            status = STATUS_OK
            if (accept) then
                call limit_step(delta)
                kd = matmul(kt, delta)
                predicted = dot_product(f, delta) - 0.5_wp*dot_product(delta, kd)
                call try_step(delta, accept)
                ! second-order corrections: chord steps with the same matrix pull the trial
                ! point back towards the manifold the linear step left (stiff springs
                ! stretched by a linearized rotation), judged against the same prediction
                do k = 1, 2
                    if (accept .or. status /= STATUS_OK) exit
                    delta = delta + ldl_solve(fac, f_new)
                    call limit_step(delta)
                    call try_step(delta, accept)
                    rho = min(rho, 0.5_wp)
                end do
            end if
            if (.not. accept) then
                result%rejected = result%rejected + 1
                consecutive = consecutive + 1
                if (consecutive > 40) then
                    call make_error(err, ERR_SOLVER, spec%path//': statics: no step lowers '// &
                        'the potential energy (40 rejections in a row at iteration '// &
                        int_text(result%iterations)//'); the forces may be inconsistent with '// &
                        'the energy, or the equilibrium is singular')
                    return
                end if
                if (sigma == 0.0_wp) then
                    ! Newton failed: back to the last shift that worked
                    sigma = sigma_good
                    if (sigma == 0.0_wp) sigma = 1.0e-6_wp*sigma0
                else
                    sigma = 4.0_wp*sigma
                end if
                cycle
            end if

            ! accepted
            consecutive = 0
            fresh = .true.
            y = y_new
            result%last_step = step
            if (newton) result%newton_steps = result%newton_steps + 1
            if (maxval(abs(y(pos) - q0)) > 1.0e4_wp*(length + maxval(abs(q0)))) then
                call make_error(err, ERR_SOLVER, spec%path//': statics: diverged: the '// &
                    'rope moves away without bound (no equilibrium?)')
                return
            end if
            f = f_new
            v_old = v_new
            if (newton .and. step <= options%step_tolerance*length) then
                result%criterion = 'newton step'
                exit
            end if
            ! shift update (Levenberg-Marquardt): good model -> smaller shift, and Newton
            ! once the shift is small against the stiffness along the step
            if (rho > 0.75_wp) then
                sigma = 0.0625_wp*sigma
            else if (rho < 0.25_wp) then
                sigma = 4.0_wp*sigma
            end if
            dmdd = dot_product(delta, matmul(mm, delta))
            lambda_step = 0.0_wp
            if (dmdd > 0.0_wp) lambda_step = dot_product(delta, kd)/dmdd
            if (sigma_used > 0.0_wp) sigma_good = sigma_used
            if ((sigma < 1.0e-3_wp*lambda_step .and. step <= 1.0e-2_wp*length) .or. &
                sigma < 1.0e-12_wp*sigma0) sigma = 0.0_wp
        end do

        y(vel) = 0.0_wp
        result%residual = maxval(abs(f))
        result%residual_relative = result%residual/merge(result%weight, 1.0_wp, &
                                                          result%weight > 0.0_wp)
        block
            type(energy_t) :: e
            real(wp) :: yq(max(1, model%quad_size()))
            yq = 0.0_wp
            e = model%energy(0.0_wp, y, yq)
            result%elastic = e%elastic
            result%gravity = e%gravity
        end block
    contains
        !> Scale delta down to at most step_limit in every coordinate.
        subroutine limit_step(dq)
            real(wp), intent(inout) :: dq(:)
            step = maxval(abs(dq))
            if (step > step_limit) dq = dq*(step_limit/step)
            step = maxval(abs(dq))
        end subroutine limit_step

        !> Evaluate q + dq: accept when V falls by at least 1e-4 of the predicted decrease.
        subroutine try_step(dq, ok)
            real(wp), intent(in) :: dq(:)
            logical, intent(out) :: ok
            ok = .false.
            y_new = y
            y_new(pos) = y(pos) + dq
            call generalized_force(model, y_new, pos, vel, f_new, status)
            if (status /= STATUS_OK) return
            v_new = potential_energy(model, y_new, spec)
            if (.not. ieee_is_finite(v_new)) then
                status = -1
                return
            end if
            noise = 1.0e-13_wp*(abs(v_old) + result%weight*length) + tiny(1.0_wp)
            if (predicted <= noise) then
                ! at the rounding level of V: judge by the forces
                rho = 1.0_wp
                ok = maxval(abs(f_new)) <= maxval(abs(f)) .or. v_new <= v_old + noise
            else
                rho = (v_old - v_new)/predicted
                ok = rho > 1.0e-4_wp
            end if
        end subroutine try_step

        !> max |f| is within the rounding error of the stiffness forces.
        logical function at_rounding_level() result(yes)
            real(wp) :: floor_k
            integer :: i
            qscale = abs(y(pos)) + length
            result%rounding_level = 0.0_wp
            do i = 1, nd
                floor_k = 10.0_wp*epsilon(1.0_wp)*(sum(abs(kt(i, :))*qscale) &
                                                   + result%weight) + tiny(1.0_wp)
                result%rounding_level = max(result%rounding_level, abs(f(i))/floor_k)
            end do
            yes = result%rounding_level <= 1.0_wp
        end function at_rounding_level
    end subroutine solve_statics
end module ropedyn_statics
