!> Static equilibrium of a rope model and the linearization about it.
!!
!! Works on any `rope_model_t` through its generalized coordinates (`coordinates`: where q
!! and q' sit in the ODE state) and their mass matrix (`coordinate_mass`). At rest (q' = 0)
!! the generalized force is f(q) = M(q) q'' = -dV/dq (damping vanishes), so an equilibrium is
!! a zero of f, and the tangent stiffness K(q) = -df/dq is the Hessian of the potential
!! energy V (elastic + gravity) there. f and K come from the model:
!! - explicit models (RFEM): f = M a with a = ydot(vel) from `rhs`, K = -M da/dq from the
!!   analytic band Jacobian (rows vel, columns pos) less (dM/dq) a, differenced, for a mass
!!   that turns with the elements (ropedyn_statics_terms);
!! - linearly implicit models (MPP: M(y) y' = F(y)): f = F(vel) from `implicit_rhs` (O(n))
!!   and K by central differences of it (step 1e-8: below a stiff ground's penetration;
!!   docs/theory/statics-modes.md).
!!
!! Solver (`solve_statics`): a trust-region (Levenberg-Marquardt) Newton iteration on V,
!!     (K + sigma M + E) delta = f,    q <- q + delta,
!! the trial point q + delta or, where it lowers V further, the model's `displace` (for the
!! RFEM exact for joined elements that turn, so that the stiff joints do not shorten the
!! steps);
!! E >= 0 from a modified Cholesky factorization (Gill, Murray & Wright), so that every step
!! descends even where K is indefinite (a compressed rope); a step is accepted when V falls
!! by at least 1e-4 of the quadratic model's prediction, after up to two second-order
!! (chord) corrections; sigma shrinks after good steps, grows after poor or rejected ones
!! (Nielsen's rule), and is 0 (Newton) near the solution. Converged when a Newton step is below
!! step_tolerance * L, or when max |f| is at the rounding level of the stiffness
!! (10 eps sum_j |K_kj| (|q_j| + L)). The iteration's state is a `descent_t` whose steps
!! are start, assemble (K, M, the rounding test), trial (solve, corrections), accept or
!! reject (the shift), finish. `find_equilibrium` adds a continuation in the support
!! stiffness for a bottom anchor far from the start (`continuation_t`: plan, run), and in a
!! current, whose drag has no potential, a continuation in the current's speed on the
!! residual instead (submodule ropedyn_statics_flow).
!! Derivation and limits: docs/theory/statics-modes.md.
module ropedyn_statics
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t, make_error, ERR_SOLVER
    use ropedyn_problem, only: STATUS_OK
    use ropedyn_rope_model, only: rope_model_t, energy_t
    use ropedyn_model_factory, only: create_model
    use ropedyn_text, only: int_text, fixed_text
    use ropedyn_rope_spec, only: rope_spec_t, bottom_anchor_given, released_at_start
    use ropedyn_ldl, only: ldl_t, ldl_factor, ldl_solve, band_matvec
    use ropedyn_statics_terms, only: generalized_force, tangent_matrices, potential_energy, &
                                     rope_length, total_weight, tangent_band, tangent_bandwidth, &
                                     at_rest_near
    implicit none
    private
    public :: statics_options_t, statics_result_t
    public :: solve_statics, find_equilibrium, check_equilibrium_exists
    public :: generalized_force, tangent_matrices, potential_energy, rope_length, total_weight

    !> Controls of `solve_statics`.
    type :: statics_options_t
        !> linear solves (accepted + rejected steps) of a solve: the direct one, and each
        !! stage of a continuation (which has STAGE_ITERATIONS when that is less)
        integer :: max_iterations = 2000
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
        !> where the equilibrium was found again from, and why: 'a catenary between the
        !! supports (...)' or 'its equilibrium with the whole turns taken off (...)'
        !! (ropedyn_line_equilibrium); unallocated when the scene's start gave it
        character(len=:), allocatable :: restart
        !> what is left of a false equilibrium, said (ropedyn_line_equilibrium: a line
        !! that carries tension only left compressed, a wound line); unallocated when
        !! nothing is
        character(len=:), allocatable :: caution
    contains
        procedure :: report => result_report
    end type statics_result_t

    !> the parameters `find_equilibrium` continues in
    integer, parameter :: ON_SUPPORT = 1, ON_GROUND = 2
    !> the ground's continuation starts where the rope's weight per metre sinks it by this
    !! fraction of its length, and is needed above 100 times that stiffness
    real(wp), parameter :: GROUND_START_SINK = 1.0e-3_wp, GROUND_CONTINUED_ABOVE = 100.0_wp
    !> the iterations of one continuation stage
    integer, parameter :: STAGE_ITERATIONS = 150

    !> A continuation of `find_equilibrium`: in the support stiffness (ON_SUPPORT) or in the
    !! ground's stiffness (ON_GROUND); the log of the parameter at its start (s = 0) and end
    !! (s = 1), and what it cost.
    type :: continuation_t
        integer :: which = ON_SUPPORT
        real(wp) :: log_f0 = 0.0_wp, log_f1 = 0.0_wp
        integer :: iterations = 0, rejected = 0   !< of all its stages
        integer :: stages = 0                     !< 0 when given up
        !> linear solves a stage may take: STAGE_ITERATIONS, or the caller's limit of a
        !! solve when that is smaller (statics_options_t%max_iterations)
        integer :: stage_limit = STAGE_ITERATIONS
        character(len=:), allocatable :: fallback !< '' or how far it got before given up
    contains
        procedure :: plan => continuation_plan
        procedure :: plan_ground => continuation_plan_ground
        procedure :: stage => continuation_stage
        procedure :: run => continuation_run
        procedure :: name => continuation_name
        procedure :: account => continuation_account
    end type continuation_t

    !> The state of `solve_statics`' iteration at y, and its steps (the module header).
    type :: descent_t
        integer, allocatable :: pos(:), vel(:)      !< where q and q' sit in y
        real(wp), allocatable :: f(:), f_new(:)     !< generalized force at y, at the trial
        !> stiffness (symmetrized) and mass at y, lower bands kt(0:kw, n), mm(0:km, n)
        real(wp), allocatable :: kt(:, :), mm(:, :)
        real(wp), allocatable :: kfull(:, :)        !< the stiffness's band kfull(-kw:kw, n)
        real(wp), allocatable :: shifted(:, :)      !< K + sigma M, lower band (0:kw, n)
        integer :: kw = 0, km = 0                   !< bandwidths of K and M
        real(wp), allocatable :: mdiag(:)           !< diagonal of the starting mass
        real(wp), allocatable :: delta(:), kd(:)    !< the step, K delta
        real(wp), allocatable :: y_new(:), q0(:)    !< the trial state; the starting q
        type(ldl_t) :: fac                          !< the factors of K + sigma M + E
        real(wp) :: length = 0.0_wp, step_limit = 0.0_wp  !< rope length, largest step
        real(wp) :: v_old = 0.0_wp, v_new = 0.0_wp  !< potential energy at y, at the trial
        !> the shift: now, its scale, of the last solve, of the last good shifted step
        real(wp) :: sigma = 0.0_wp, sigma0 = 0.0_wp, sigma_used = 0.0_wp, sigma_good = 0.0_wp
        real(wp) :: growth = 2.0_wp     !< the factor of the shift at the next rejection
        real(wp) :: step = 0.0_wp       !< max |delta|
        real(wp) :: predicted = 0.0_wp  !< decrease of V the quadratic model predicts
        real(wp) :: rho = 0.0_wp        !< actual / predicted decrease
        integer :: status = STATUS_OK   !< of the last evaluation of the forces
        integer :: consecutive = 0      !< rejections in a row
        logical :: fresh = .true.       !< y moved: the stiffness is to be evaluated
        logical :: newton = .false.     !< the last solve was a Newton step
        type(statics_result_t) :: result
    contains
        procedure :: start => descent_start
        procedure :: iterate => descent_iterate
        procedure :: assemble => descent_assemble
        procedure :: measure_rounding => descent_measure_rounding
        procedure :: no_convergence => descent_no_convergence
        procedure :: trial => descent_trial
        procedure :: limit_step => descent_limit_step
        procedure :: try_step => descent_try_step
        procedure :: trial_point => descent_trial_point
        procedure :: evaluate => descent_evaluate
        procedure :: energy_noise => descent_energy_noise
        procedure :: reject => descent_reject
        procedure :: accept => descent_accept
        procedure :: update_shift => descent_update_shift
        procedure :: finish => descent_finish
    end type descent_t

    interface
        !> True when the spec's current drags the rope at rest (submodule
        !! ropedyn_statics_flow): drag or water on, and a current.
        module function current_drags(spec) result(drags)
            type(rope_spec_t), intent(in) :: spec
            logical :: drags
        end function current_drags

        !> The equilibrium in a current (submodule ropedyn_statics_flow): without the
        !! current by find_equilibrium, then continued in the current's speed by a
        !! pseudo-transient continuation on the residual.
        recursive module subroutine flow_equilibrium(model, spec, y, options, result, err)
            class(rope_model_t), intent(inout) :: model
            type(rope_spec_t), intent(in) :: spec
            real(wp), intent(inout) :: y(:)
            type(statics_options_t), intent(in) :: options
            type(statics_result_t), intent(out) :: result
            type(error_t), allocatable, intent(out) :: err
        end subroutine flow_equilibrium
    end interface

contains

    !> ERR_SOLVER when the spec cannot have an equilibrium: both ends free under gravity,
    !! an end released at t = 0 (with the support motions on) counting as free; or no
    !! unique one: an RFEM without shear (and no ground to hold its elements), whose joints
    !! slide across the rope without a force (docs/theory/statics-modes.md, Errors).
    subroutine check_equilibrium_exists(spec, err)
        type(rope_spec_t), intent(in) :: spec
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: top, bottom, origin
        associate (s => spec%supports)
            top = end_key('top', s%top, 1)
            bottom = end_key('bottom', s%bottom, 2)
        end associate
        if (len(top) > 0 .and. len(bottom) > 0 .and. spec%effects%gravity .and. &
            spec%rope%gravity > 0.0_wp) then
            ! (named by the --set that freed an end, if one did)
            origin = spec%origin('supports.'//top)
            if (origin == spec%origin('')) origin = spec%origin('supports.'//bottom)
            call make_error(err, ERR_SOLVER, origin//': statics: no equilibrium: both '// &
                'supports are free (&supports '//end_text(top)//', '//end_text(bottom)// &
                ') and gravity is on, so the rope falls freely; pin or clamp an end, or '// &
                'switch gravity off')
        else if (spec%model%kind == 'rfem' .and. spec%model%elements > 1 .and. &
                 .not. spec%effects%tension .and. .not. spec%effects%ground) then
            ! (the MPP's members are then rigid pendulum links: it has an equilibrium)
            call make_error(err, ERR_SOLVER, spec%origin('effects.tension')//': &effects: '// &
                "tension = .false.: statics: no equilibrium: without tension the RFEM's "// &
                'joints hold nothing along the rope, so its elements fall apart; switch '// &
                'tension on for statics and modes')
        else if (spec%model%kind == 'rfem' .and. spec%model%elements > 1 .and. &
                 .not. spec%effects%shear .and. .not. spec%effects%ground) then
            call make_error(err, ERR_SOLVER, spec%origin('effects.shear')//': &effects: '// &
                'shear = .false.: statics: no unique equilibrium: without shear the '// &
                "RFEM's joints have no stiffness across the rope (their springs keep "// &
                'tension and bending only), so the ends of neighbouring elements slide '// &
                'apart freely; switch shear on for statics and modes')
        end if
    contains
        !> The key that frees the end at t = 0: "top" (its kind 'free') or
        !! "top_release_time" (released at t = 0), else ''.
        function end_key(end, kind, k) result(key)
            character(len=*), intent(in) :: end, kind
            integer, intent(in) :: k
            character(len=:), allocatable :: key
            key = ''
            if (trim(kind) == 'free') then
                key = end
            else if (released_at_start(spec, k)) then
                key = end//'_release_time'
            end if
        end function end_key

        !> "top = 'free'" or "top_release_time = 0.0" for the key end_key gave.
        pure function end_text(key) result(text)
            character(len=*), intent(in) :: key
            character(len=:), allocatable :: text
            if (index(key, '_release_time') > 0) then
                text = key//' = 0.0'
            else
                text = key//" = 'free'"
            end if
        end function end_text
    end subroutine check_equilibrium_exists

    !> The equilibrium of the spec from the starting state y. On a ground much stiffer than
    !! the rope's weight needs (GROUND_CONTINUED_ABOVE), the descent meets a penalty far
    !! stiffer than the rope wherever a step reaches into the ground, and its steps must be
    !! tiny. Then the solution is first continued in the ground's stiffness
    !! (continuation_t, ON_GROUND): the equilibrium on a soft ground (the rope sinks by
    !! GROUND_START_SINK of its length), then geometric stages up to the spec's stiffness,
    !! each from the previous equilibrium, as in `equilibrium_of`'s continuation. If that
    !! fails, `equilibrium_of` solves directly from the start. In a current whose drag has
    !! no potential (current_drags), flow_equilibrium instead.
    recursive subroutine find_equilibrium(model, spec, y, options, result, err)
        class(rope_model_t), intent(inout) :: model
        type(rope_spec_t), intent(in) :: spec
        real(wp), intent(inout) :: y(:)
        type(statics_options_t), intent(in) :: options
        type(statics_result_t), intent(out) :: result
        type(error_t), allocatable, intent(out) :: err
        type(continuation_t) :: ground
        type(rope_spec_t) :: soft
        class(rope_model_t), allocatable :: soft_model
        type(statics_result_t) :: first
        type(error_t), allocatable :: soft_err
        real(wp), allocatable :: y_start(:)
        logical :: needed

        ground%fallback = ''
        ground%stage_limit = min(STAGE_ITERATIONS, options%max_iterations)
        call check_equilibrium_exists(spec, err)
        if (allocated(err)) return
        if (current_drags(spec)) then
            ! drag without a potential: the descent on V cannot take it
            call flow_equilibrium(model, spec, y, options, result, err)
            return
        end if
        needed = .false.
        if (options%continuation) call ground%plan_ground(model, spec, needed)
        if (needed) then
            y_start = y
            soft = ground%stage(spec, 0.0_wp)
            call create_model(soft, soft_model, err)
            if (allocated(err)) return
            call equilibrium_of(soft_model, soft, y, options, first, soft_err)
            ground%iterations = first%iterations
            ground%rejected = first%rejected
            if (allocated(soft_err)) then
                ground%fallback = 'continuation in '//ground%name()//' failed at its start, then '
                y = y_start
            else
                ground%stages = 1 + first%stages
                call ground%run(spec, y, err, start_solved=.true.)
                if (allocated(err)) return
                if (ground%stages == 0) y = y_start     ! given up
            end if
        end if
        call equilibrium_of(model, spec, y, options, result, err)
        call ground%account(result, err)
    end subroutine find_equilibrium

    !> The equilibrium of the spec from the starting state y. When the bottom end is
    !! pinned or clamped to an anchor far (> L/1000) from the lower end of the starting
    !! configuration, the support spring starts hugely stretched: its pull (~ EA/dl times the
    !! distance) dwarfs the weight and pushes the straight rope along its axis, a saddle
    !! (compression) where the steps must be tiny. Then the solution is
    !! first continued in `support_stiffness_factor` (continuation_t): from the value at
    !! which the spring pulls with 0.3 times the weight up to the spec's value in geometric
    !! stages, each started from the previous equilibrium (models rebuilt); a stage
    !! multiplies the factor by 10 at first, by 100 after an easy stage, and its step is cut
    !! by 4 after a failure. If the first stage fails or the continuation stalls (RFEM: its
    !! top support softens too and the rope drops far), it solves directly from the start,
    !! which the RFEM's Cartesian coordinates tolerate. Otherwise it is `solve_statics`.
    subroutine equilibrium_of(model, spec, y, options, result, err)
        class(rope_model_t), intent(inout) :: model
        type(rope_spec_t), intent(in) :: spec
        real(wp), intent(inout) :: y(:)
        type(statics_options_t), intent(in) :: options
        type(statics_result_t), intent(out) :: result
        type(error_t), allocatable, intent(out) :: err
        type(continuation_t) :: path
        logical :: needed

        path%fallback = ''
        path%stage_limit = min(STAGE_ITERATIONS, options%max_iterations)
        if (options%continuation) then
            call path%plan(model, spec, y, needed, err)
            if (allocated(err)) return
            if (needed) call path%run(spec, y, err)
            if (allocated(err)) return
        end if
        call solve_statics(model, spec, y, options, result, err)
        call path%account(result, err)
    end subroutine equilibrium_of

    !> Add what the continuation cost to the result of the solve after it, and to that
    !! solve's error, when the continuation was given up, how far it got.
    subroutine continuation_account(self, result, err)
        class(continuation_t), intent(in) :: self
        type(statics_result_t), intent(inout) :: result
        type(error_t), allocatable, intent(inout) :: err
        if (allocated(err) .and. len(self%fallback) > 0) then
            err%message = err%message//' ('//self%fallback//'solved directly from the start)'
        end if
        result%iterations = result%iterations + self%iterations
        result%rejected = result%rejected + self%rejected
        result%stages = result%stages + self%stages
    end subroutine continuation_account

    !> The name of the continued parameter, for messages.
    pure function continuation_name(self) result(name)
        class(continuation_t), intent(in) :: self
        character(len=:), allocatable :: name
        if (self%which == ON_GROUND) then
            name = 'the ground stiffness'
        else
            name = 'support_stiffness_factor'
        end if
    end function continuation_name

    !> Whether the ground needs the continuation (ON_GROUND): gravity, ground contact and a
    !! stiffness above GROUND_CONTINUED_ABOVE times k0, the stiffness at which the rope's
    !! weight per metre w sinks it by GROUND_START_SINK of its length L, k0 = w/(s L).
    subroutine continuation_plan_ground(self, model, spec, needed)
        class(continuation_t), intent(inout) :: self
        class(rope_model_t), intent(in) :: model
        type(rope_spec_t), intent(in) :: spec
        logical, intent(out) :: needed
        real(wp) :: weight, length, k0
        needed = .false.
        self%which = ON_GROUND
        if (.not. spec%effects%ground) return
        weight = total_weight(model, spec)
        length = rope_length(model)
        if (weight <= 0.0_wp .or. length <= 0.0_wp) return
        k0 = weight/length/(GROUND_START_SINK*length)
        if (spec%ground%stiffness <= GROUND_CONTINUED_ABOVE*k0) return
        self%log_f0 = log(k0)
        self%log_f1 = log(spec%ground%stiffness)
        needed = .true.
    end subroutine continuation_plan_ground

    !> The spec at s of the way (0 <= s <= 1) along the continued parameter.
    function continuation_stage(self, spec, s) result(stage_spec)
        class(continuation_t), intent(in) :: self
        type(rope_spec_t), intent(in) :: spec
        real(wp), intent(in) :: s
        type(rope_spec_t) :: stage_spec
        real(wp) :: value
        stage_spec = spec
        value = exp(self%log_f0 + s*(self%log_f1 - self%log_f0))
        if (self%which == ON_GROUND) then
            ! at s = 1 the spec's own stiffness, to the bit
            if (s < 1.0_wp) stage_spec%ground%stiffness = value
        else
            stage_spec%supports%support_stiffness_factor = value
        end if
    end function continuation_stage

    !> Whether the equilibrium from y needs the continuation (a bottom pin or clamp far from
    !! the start, its spring pulling with more than 0.3 times the weight), and if so its
    !! range: log_f1 the spec's support_stiffness_factor, log_f0 the pull of 0.3 weights.
    subroutine continuation_plan(self, model, spec, y, needed, err)
        class(continuation_t), intent(inout) :: self
        class(rope_model_t), intent(inout) :: model
        type(rope_spec_t), intent(in) :: spec
        real(wp), intent(in) :: y(:)
        logical, intent(out) :: needed
        type(error_t), allocatable, intent(out) :: err
        real(wp), allocatable :: points(:, :)
        real(wp) :: p_end(2), target(2), distance, pull, weight

        needed = .false.
        weight = total_weight(model, spec)
        if (.not. (trim(spec%supports%bottom) /= 'free' .and. bottom_anchor_given(spec) &
                   .and. weight > 0.0_wp)) return
        allocate (points(2, 2*model%n_elements()))
        call model%polyline(y, points)
        p_end = points(:, size(points, 2))
        target = spec%supports%bottom_anchor
        distance = norm2(target - p_end)
        if (distance <= 1.0e-3_wp*rope_length(model)) return
        ! the spring's pull at the start: dV/d(anchor) along the anchor's offset
        pull = anchor_pull(model, spec, y, (target - p_end)/distance, err)
        if (allocated(err)) return
        if (pull <= 0.3_wp*weight) return
        self%log_f1 = log(spec%supports%support_stiffness_factor)
        self%log_f0 = self%log_f1 + log(0.3_wp*weight/pull)
        needed = .true.
    end subroutine continuation_plan

    !> The stages of the continuation, from s = 0 (log_f0) to s = 1 (log_f1): y is the
    !! equilibrium of the last stage, or the start again when it was given up (fallback).
    subroutine continuation_run(self, spec, y, err, start_solved)
        class(continuation_t), intent(inout) :: self
        type(rope_spec_t), intent(in) :: spec
        real(wp), intent(inout) :: y(:)
        type(error_t), allocatable, intent(out) :: err
        logical, intent(in), optional :: start_solved  !< y is the equilibrium at s = 0
        type(rope_spec_t) :: stage_spec
        class(rope_model_t), allocatable :: stage_model
        type(statics_result_t) :: stage
        type(statics_options_t) :: stage_options
        type(error_t), allocatable :: stage_err
        real(wp), allocatable :: y_try(:), y_start(:)
        real(wp) :: s, ds, s_try
        logical :: solved

        y_start = y
        stage_options%max_iterations = self%stage_limit
        stage_options%step_tolerance = 1.0e-8_wp
        s = 0.0_wp
        ds = log(10.0_wp)/(self%log_f1 - self%log_f0)
        ! the first stage starts at s = 0 itself, unless that is solved
        solved = .false.
        if (present(start_solved)) solved = start_solved
        s_try = merge(min(1.0_wp, ds), 0.0_wp, solved)
        do
            stage_spec = self%stage(spec, s_try)
            call create_model(stage_spec, stage_model, err)
            if (allocated(err)) return
            y_try = y
            call solve_statics(stage_model, stage_spec, y_try, stage_options, stage, stage_err)
            self%iterations = self%iterations + stage%iterations
            self%rejected = self%rejected + stage%rejected
            self%stages = self%stages + 1
            if (allocated(stage_err)) then
                deallocate (stage_err)
                ds = 0.25_wp*ds
                if (ds < 1.0e-3_wp .or. (self%stages == 1 .and. .not. solved)) then
                    ! give up the continuation: solve directly from the start
                    self%fallback = 'continuation in '//self%name()//' stalled at '// &
                                    fixed_text(100*s, 1)//' % of the way, then '
                    y = y_start
                    self%stages = 0
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
    end subroutine continuation_run

    !> |dV/d(anchor)| along the unit vector u from the bottom anchor, N (central
    !! differences, models rebuilt with the anchor moved).
    real(wp) function anchor_pull(model, spec, y, u, err) result(r)
        class(rope_model_t), intent(in) :: model
        type(rope_spec_t), intent(in) :: spec
        real(wp), intent(in) :: y(:), u(2)
        type(error_t), allocatable, intent(out) :: err
        type(rope_spec_t) :: moved
        class(rope_model_t), allocatable :: probe
        real(wp) :: h, vp, vm
        h = 1.0e-4_wp*rope_length(model)
        r = 0.0_wp
        moved = spec
        moved%supports%bottom_anchor = spec%supports%bottom_anchor + h*u
        call create_model(moved, probe, err)
        if (allocated(err)) return
        vp = potential_energy(probe, y, moved)
        moved%supports%bottom_anchor = spec%supports%bottom_anchor - h*u
        call create_model(moved, probe, err)
        if (allocated(err)) return
        vm = potential_energy(probe, y, moved)
        r = abs(vp - vm)/(2*h)
    end function anchor_pull

    !> Find the static equilibrium reached from the state y by descending the potential energy.
    !! On entry y holds the starting configuration (velocities are set to zero); on
    !! success it holds the equilibrium at rest. Errors (ERR_SOLVER) name the cause:
    !! no equilibrium (free-free under gravity), no convergence, divergence, non-finite
    !! forces, or no step that lowers the energy. The iteration's state and steps: descent_t.
    subroutine solve_statics(model, spec, y, options, result, err)
        class(rope_model_t), intent(inout) :: model
        type(rope_spec_t), intent(in) :: spec
        real(wp), intent(inout) :: y(:)
        type(statics_options_t), intent(in) :: options
        type(statics_result_t), intent(out) :: result
        type(error_t), allocatable, intent(out) :: err
        type(descent_t) :: descent

        call check_equilibrium_exists(spec, err)
        if (allocated(err)) return
        call descent%start(model, spec, y, err)
        if (.not. allocated(err)) call descent%iterate(model, spec, y, options, err)
        if (.not. allocated(err)) call descent%finish(model, y)
        result = descent%result
    end subroutine solve_statics

    !> Set up the iteration at y (velocities zeroed): coordinates, force, energy, mass, and
    !! the shift scale; ERR_SOLVER if the forces are not finite there.
    subroutine descent_start(self, model, spec, y, err)
        class(descent_t), intent(inout) :: self
        class(rope_model_t), intent(inout) :: model
        type(rope_spec_t), intent(in) :: spec
        real(wp), intent(inout) :: y(:)
        type(error_t), allocatable, intent(out) :: err
        integer :: nd

        call model%coordinates(self%pos, self%vel)
        nd = size(self%pos)
        self%km = model%mass_bandwidth()
        self%kw = max(tangent_bandwidth(model), self%km)
        allocate (self%f(nd), self%f_new(nd), self%kt(0:self%kw, nd), &
                  self%mm(0:self%km, nd), self%kfull(-self%kw:self%kw, nd), &
                  self%shifted(0:self%kw, nd), self%delta(nd), self%mdiag(nd), self%kd(nd), &
                  self%y_new(size(y)))
        y(self%vel) = 0.0_wp
        self%length = rope_length(model)
        self%step_limit = 0.5_wp*max(self%length, 1.0_wp)
        self%result%weight = total_weight(model, spec)
        self%q0 = y(self%pos)

        call generalized_force(model, y, self%pos, self%vel, self%f, self%status)
        if (self%status /= STATUS_OK) then
            call make_error(err, ERR_SOLVER, spec%path//': statics: non-finite forces '// &
                            'in the starting configuration')
            return
        end if
        self%v_old = potential_energy(model, y, spec)
        call model%coordinate_mass_band(y, self%mm)
        self%mdiag = self%mm(0, :)
        ! shift scale: a step of the freest coordinate of L/10 (explicit estimate); the
        ! iteration starts as Newton (sigma = 0) and shifts only when it must
        self%sigma0 = maxval(abs(self%f)/self%mdiag)/(0.1_wp*max(self%length, 1.0e-3_wp))
        self%sigma0 = max(self%sigma0, sqrt(tiny(1.0_wp)))
        self%sigma = 0.0_wp
        self%sigma_good = 0.0_wp
        self%consecutive = 0
        self%fresh = .true.
    end subroutine descent_start

    !> Steps until converged (result%criterion) or an error: after each accepted step the
    !! stiffness is evaluated afresh and the rounding level tested; a rejected step raises
    !! the shift and tries again with the same matrices.
    subroutine descent_iterate(self, model, spec, y, options, err)
        class(descent_t), intent(inout) :: self
        class(rope_model_t), intent(inout) :: model
        type(rope_spec_t), intent(in) :: spec
        real(wp), intent(inout) :: y(:)
        type(statics_options_t), intent(in) :: options
        type(error_t), allocatable, intent(out) :: err
        logical :: accept, converged

        do
            if (self%fresh) then
                call self%assemble(model, spec, y, converged, err)
                if (allocated(err) .or. converged) return
            end if
            if (self%result%iterations >= options%max_iterations) then
                call self%no_convergence(spec, err)
                return
            end if
            call self%trial(model, spec, y, accept)
            if (accept) then
                call self%accept(spec, y, options, converged, err)
                if (allocated(err) .or. converged) return
            else
                call self%reject(spec, err)
                if (allocated(err)) return
            end if
        end do
    end subroutine descent_iterate

    !> The symmetrized tangent stiffness and the mass at y; `converged` (and no mass) when
    !! max |f| is at the rounding level of the stiffness there.
    subroutine descent_assemble(self, model, spec, y, converged, err)
        class(descent_t), intent(inout) :: self
        class(rope_model_t), intent(inout) :: model
        type(rope_spec_t), intent(in) :: spec
        real(wp), intent(in) :: y(:)
        logical, intent(out) :: converged
        type(error_t), allocatable, intent(out) :: err

        integer :: i, j
        converged = .false.
        call tangent_band(model, y, self%pos, self%vel, self%kw, self%kfull, self%status, &
                          hessian=.true.)
        if (self%status /= STATUS_OK) then
            call make_error(err, ERR_SOLVER, spec%path//': statics: the stiffness '// &
                            'matrix is not finite at iteration '// &
                            int_text(self%result%iterations))
            return
        end if
        ! the symmetric part, K_ij = (K_ij + K_ji)/2, i >= j: kfull(i - j, j), kfull(j - i, i)
        do j = 1, size(self%pos)
            do i = 0, min(self%kw, size(self%pos) - j)
                self%kt(i, j) = 0.5_wp*(self%kfull(i, j) + self%kfull(-i, j + i))
            end do
        end do
        call self%measure_rounding(y)
        if (self%result%rounding_level <= 1.0_wp) then
            self%result%criterion = 'rounding level'
            converged = .true.
            return
        end if
        call model%coordinate_mass_band(y, self%mm)
        self%fresh = .false.
    end subroutine descent_assemble

    !> result%rounding_level: max |f| over its rounding floor, the rounding error of the
    !! stiffness forces (10 eps sum_j |K_kj| (|q_j| + L), plus the weight).
    subroutine descent_measure_rounding(self, y)
        class(descent_t), intent(inout) :: self
        real(wp), intent(in) :: y(:)
        real(wp), allocatable :: qscale(:), row(:)
        real(wp) :: floor_k
        integer :: i, j, n
        n = size(self%pos)
        qscale = abs(y(self%pos)) + self%length
        ! row(i) = sum_j |K_ij| qscale_j over the symmetric band
        allocate (row(n))
        row = 0.0_wp
        do j = 1, n
            row(j) = row(j) + abs(self%kt(0, j))*qscale(j)
            do i = j + 1, min(n, j + self%kw)
                row(i) = row(i) + abs(self%kt(i - j, j))*qscale(j)
                row(j) = row(j) + abs(self%kt(i - j, j))*qscale(i)
            end do
        end do
        self%result%rounding_level = 0.0_wp
        do i = 1, n
            floor_k = 10.0_wp*epsilon(1.0_wp)*(row(i) + self%result%weight) + tiny(1.0_wp)
            self%result%rounding_level = max(self%result%rounding_level, &
                                             abs(self%f(i))/floor_k)
        end do
    end subroutine descent_measure_rounding

    !> ERR_SOLVER: the iterations are used up.
    subroutine descent_no_convergence(self, spec, err)
        class(descent_t), intent(in) :: self
        type(rope_spec_t), intent(in) :: spec
        type(error_t), allocatable, intent(out) :: err
        character(len=200) :: text
        character(len=:), allocatable :: hint
        write (text, '(a, i0, a, es10.3, a, es10.3, a, es9.2)') 'no convergence in ', &
            self%result%iterations, ' iterations (max |f| = ', maxval(abs(self%f)), &
            ' N, last step ', self%result%last_step, ' m or rad, shift ', self%sigma
        hint = ''
        ! a line on the seabed: the MPP's iteration crawls where the RFEM's does not
        ! (docs/theory/statics-modes.md, "Stiff ground: continuation")
        if (spec%model%kind == 'mpp' .and. spec%effects%ground) hint = '; on a ground '// &
            "the MPP can need several thousand iterations (--max-iterations 10000), "// &
            "the RFEM (--set model.kind='rfem') far fewer"
        call make_error(err, ERR_SOLVER, spec%path//': statics: '//trim(text)// &
            '); the rope may have no stable equilibrium near the start, or needs '// &
            'more iterations (--max-iterations)'//hint)
    end subroutine descent_no_convergence

    !> One linear solve and its trial point: (K + sigma M + E) delta = f, E >= 0 from the
    !! modified Cholesky factorization; `accept` when the energy falls enough there, after
    !! up to two second-order corrections.
    subroutine descent_trial(self, model, spec, y, accept)
        class(descent_t), intent(inout) :: self
        class(rope_model_t), intent(inout) :: model
        type(rope_spec_t), intent(in) :: spec
        real(wp), intent(in) :: y(:)
        logical, intent(out) :: accept
        logical :: modified
        integer :: k

        self%sigma_used = self%sigma
        self%result%iterations = self%result%iterations + 1
        self%shifted = self%kt
        self%shifted(0:self%km, :) = self%shifted(0:self%km, :) + self%sigma*self%mm
        call ldl_factor(self%shifted, 1.0_wp/sqrt(self%mdiag), self%fac, modified)
        self%newton = self%sigma == 0.0_wp .and. .not. modified
        self%delta = ldl_solve(self%fac, self%f)
        accept = all(ieee_is_finite(self%delta))
        self%status = STATUS_OK
        if (.not. accept) return
        call self%limit_step()
        self%kd = band_matvec(self%kt, self%delta)
        self%predicted = dot_product(self%f, self%delta) - &
                         0.5_wp*dot_product(self%delta, self%kd)
        call self%try_step(model, spec, y, accept)
        ! second-order corrections: chord steps with the same matrix pull the trial
        ! point back towards the manifold the step left (stiff springs stretched at
        ! second order where the model's displace is linear), judged against the same
        ! prediction
        do k = 1, 2
            if (accept .or. self%status /= STATUS_OK) exit
            self%delta = self%delta + ldl_solve(self%fac, self%f_new)
            call self%limit_step()
            call self%try_step(model, spec, y, accept)
            self%rho = min(self%rho, 0.5_wp)
        end do
    end subroutine descent_trial

    !> Scale delta down to at most step_limit in every coordinate; step is its max |entry|.
    subroutine descent_limit_step(self)
        class(descent_t), intent(inout) :: self
        self%step = maxval(abs(self%delta))
        if (self%step > self%step_limit) self%delta = self%delta*(self%step_limit/self%step)
        self%step = maxval(abs(self%delta))
    end subroutine descent_limit_step

    !> Evaluate the trial point of the step delta (y_new, f_new, v_new: `trial_point`): `ok`
    !! when V falls by at least 1e-4 of the predicted decrease (rho: the ratio); status /=
    !! STATUS_OK when it is not finite.
    subroutine descent_try_step(self, model, spec, y, ok)
        class(descent_t), intent(inout) :: self
        class(rope_model_t), intent(inout) :: model
        type(rope_spec_t), intent(in) :: spec
        real(wp), intent(in) :: y(:)
        logical, intent(out) :: ok
        real(wp) :: noise
        ok = .false.
        call self%trial_point(model, spec, y)
        if (self%status /= STATUS_OK) return
        noise = self%energy_noise()
        if (self%predicted <= noise) then
            ! at the rounding level of V: judge by the forces
            self%rho = 1.0_wp
            ok = maxval(abs(self%f_new)) <= maxval(abs(self%f)) .or. &
                 self%v_new <= self%v_old + noise
        else
            self%rho = (self%v_old - self%v_new)/self%predicted
            ok = self%rho > 1.0e-4_wp
        end if
    end subroutine descent_try_step

    !> The trial point of the step delta: y + delta, or the model's `displace` of y by delta
    !! where that differs and lowers V further (by more than its rounding noise; within it:
    !! the one with the smaller forces). The displacement turns an RFEM's joined elements
    !! without stretching the joints, which lets a soft rope swing in long steps; y + delta
    !! keeps Newton's last steps exact along the stiff springs (a pinned bottom end, to which
    !! the displacement's second-order turn of every element above adds up).
    subroutine descent_trial_point(self, model, spec, y)
        class(descent_t), intent(inout) :: self
        class(rope_model_t), intent(inout) :: model
        type(rope_spec_t), intent(in) :: spec
        real(wp), intent(in) :: y(:)
        real(wp), allocatable :: y_turned(:), y_lin(:), f_lin(:)
        real(wp) :: v_lin, noise
        integer :: status_lin
        logical :: better
        y_lin = y
        y_lin(self%pos) = y(self%pos) + self%delta
        call self%evaluate(model, spec, y_lin)
        allocate (y_turned(size(y)))
        call model%displace(y, self%delta, y_turned)
        if (all(y_turned == y_lin)) return
        f_lin = self%f_new
        v_lin = self%v_new
        status_lin = self%status
        call self%evaluate(model, spec, y_turned)
        if (status_lin /= STATUS_OK .or. self%status /= STATUS_OK) then
            better = self%status == STATUS_OK
        else
            noise = self%energy_noise()
            better = self%v_new < v_lin - noise .or. (self%v_new <= v_lin + noise .and. &
                     maxval(abs(self%f_new)) < maxval(abs(f_lin)))
        end if
        if (better) return
        self%y_new = y_lin
        self%f_new = f_lin
        self%v_new = v_lin
        self%status = status_lin
    end subroutine descent_trial_point

    !> The forces and the potential energy at the state y_trial (y_new, f_new, v_new);
    !! status /= STATUS_OK when they are not finite.
    subroutine descent_evaluate(self, model, spec, y_trial)
        class(descent_t), intent(inout) :: self
        class(rope_model_t), intent(inout) :: model
        type(rope_spec_t), intent(in) :: spec
        real(wp), intent(in) :: y_trial(:)
        self%y_new = y_trial
        self%v_new = huge(1.0_wp)
        call generalized_force(model, self%y_new, self%pos, self%vel, self%f_new, self%status)
        if (self%status /= STATUS_OK) return
        self%v_new = potential_energy(model, self%y_new, spec)
        if (.not. ieee_is_finite(self%v_new)) self%status = -1
    end subroutine descent_evaluate

    !> The rounding noise of V at the iteration's scale, J.
    pure real(wp) function descent_energy_noise(self) result(noise)
        class(descent_t), intent(in) :: self
        noise = 1.0e-13_wp*(abs(self%v_old) + self%result%weight*self%length) + tiny(1.0_wp)
    end function descent_energy_noise

    !> A rejected step: a larger shift (back to the last one that worked after a failed
    !! Newton step); ERR_SOLVER after 40 rejections in a row.
    subroutine descent_reject(self, spec, err)
        class(descent_t), intent(inout) :: self
        type(rope_spec_t), intent(in) :: spec
        type(error_t), allocatable, intent(out) :: err
        self%result%rejected = self%result%rejected + 1
        self%consecutive = self%consecutive + 1
        if (self%consecutive > 40) then
            call make_error(err, ERR_SOLVER, spec%path//': statics: no step lowers '// &
                'the potential energy (40 rejections in a row at iteration '// &
                int_text(self%result%iterations)//'); the forces may be inconsistent with '// &
                'the energy, or the equilibrium is singular')
            return
        end if
        if (self%sigma == 0.0_wp) then
            ! Newton failed: back to the last shift that worked
            self%sigma = self%sigma_good
            if (self%sigma == 0.0_wp) self%sigma = 1.0e-6_wp*self%sigma0
        else
            ! x2, x4, x8, ... for rejections in a row
            self%sigma = self%growth*self%sigma
            self%growth = 2.0_wp*self%growth
        end if
    end subroutine descent_reject

    !> An accepted step: y moves to the trial point; `converged` after a small Newton step;
    !! ERR_SOLVER if the rope moves away without bound. Then the shift update.
    subroutine descent_accept(self, spec, y, options, converged, err)
        class(descent_t), intent(inout) :: self
        type(rope_spec_t), intent(in) :: spec
        real(wp), intent(inout) :: y(:)
        type(statics_options_t), intent(in) :: options
        logical, intent(out) :: converged
        type(error_t), allocatable, intent(out) :: err

        converged = .false.
        self%consecutive = 0
        self%fresh = .true.
        y = self%y_new
        self%result%last_step = self%step
        if (self%newton) self%result%newton_steps = self%result%newton_steps + 1
        if (maxval(abs(y(self%pos) - self%q0)) > &
            1.0e4_wp*(self%length + maxval(abs(self%q0)))) then
            call make_error(err, ERR_SOLVER, spec%path//': statics: diverged: the '// &
                'rope moves away without bound (no equilibrium?)')
            return
        end if
        self%f = self%f_new
        self%v_old = self%v_new
        if (self%newton .and. self%step <= options%step_tolerance*self%length) then
            self%result%criterion = 'newton step'
            converged = .true.
            return
        end if
        call self%update_shift()
    end subroutine descent_accept

    !> The shift after an accepted step (Levenberg-Marquardt, Nielsen's rule): times
    !! max(1/3, 1 - (2 rho - 1)^3), smaller the better the model predicted the step, and the
    !! factor of the next rejection back to 2; Newton once the shift is small against the
    !! stiffness along the step.
    subroutine descent_update_shift(self)
        class(descent_t), intent(inout) :: self
        real(wp) :: dmdd, lambda_step
        self%sigma = self%sigma*max(1.0_wp/3.0_wp, 1.0_wp - (2.0_wp*self%rho - 1.0_wp)**3)
        self%growth = 2.0_wp
        dmdd = dot_product(self%delta, band_matvec(self%mm, self%delta))
        lambda_step = 0.0_wp
        if (dmdd > 0.0_wp) lambda_step = dot_product(self%delta, self%kd)/dmdd
        if (self%sigma_used > 0.0_wp) self%sigma_good = self%sigma_used
        if ((self%sigma < 1.0e-3_wp*lambda_step .and. self%step <= 1.0e-2_wp*self%length) &
            .or. self%sigma < 1.0e-12_wp*self%sigma0) self%sigma = 0.0_wp
    end subroutine descent_update_shift

    !> The equilibrium's results: velocities zeroed, each angle within pi of where the
    !! iteration started it where that changes no force (at_rest_near), the residual there,
    !! the energies.
    subroutine descent_finish(self, model, y)
        class(descent_t), intent(inout) :: self
        class(rope_model_t), intent(inout) :: model
        real(wp), intent(inout) :: y(:)
        call at_rest_near(model, y, self%pos, self%vel, self%q0, self%f)
        call self%result%report(model, y, self%f)
    end subroutine descent_finish

    !> What an equilibrium iteration (the descent, the flow in a current) reports at the
    !! equilibrium y with its generalized force f: the residual max |f| (absolute and over
    !! self%weight, which the iteration set), the elastic and gravity energies.
    subroutine result_report(self, model, y, f)
        class(statics_result_t), intent(inout) :: self
        class(rope_model_t), intent(inout) :: model
        real(wp), intent(in) :: y(:), f(:)
        type(energy_t) :: e
        real(wp) :: yq(max(1, model%quad_size()))
        self%residual = maxval(abs(f))
        self%residual_relative = self%residual/merge(self%weight, 1.0_wp, self%weight > 0.0_wp)
        yq = 0.0_wp
        e = model%energy(0.0_wp, y, yq)
        self%elastic = e%elastic
        self%gravity = e%gravity
    end subroutine result_report
end module ropedyn_statics
