!> Static equilibrium in a current (ropedyn_statics' find_equilibrium when a current drags
!! the resting rope; docs/theory/statics-modes.md, "In a current").
!!
!! A current's drag on a rope at rest depends on each element's orientation to the current
!! (the normal and tangential parts of the relative velocity), so it has no potential: the
!! descent on V, whose steps must lower the potential energy, stalls. Here the equilibrium
!! is first found without the current (find_equilibrium, the descent), then continued in
!! the current's velocity, U s for s from 0 to 1, each stage by a pseudo-transient
!! continuation on the residual (`flow_solve`):
!!     (K + sigma M) delta = f,   q <- q + delta (or the model's `displace`),
!! K = -df/dq the whole tangent stiffness, the drag's unsymmetric part included (LAPACK
!! band LU, dgbtrf), M the mass: a backward Euler step of the flow M q' = f of pseudo-time
!! 1/sigma. sigma starts at the descent's scale (a step of L/10), follows the residual's
!! norm r (r^2 = sum f_k^2 / |K_kk| at the stage's start; switched evolution relaxation:
!! sigma r_new / r_old), halved again after a step that did not raise r, and is 0 (Newton)
!! once it fell to a thousandth of its start (NEWTON_BELOW). Every step is taken unless r^2
!! grows by GROWTH_ALLOWED (then sigma grows); up to two chord corrections with the same
!! factors pull a trial point back towards the stiff springs' manifold. Converged after a
!! Newton step below step_tolerance L. A stage that fails is retried with a quarter of the
!! increment in s; a stage that succeeds doubles it.
submodule (ropedyn_statics) ropedyn_statics_flow
    use ropedyn_lapack, only: dgbtrf, dgbtrs
    implicit none

    !> the first increment of the current's scale s, and the smallest before giving up
    real(wp), parameter :: FIRST_STAGE = 0.25_wp, LEAST_STAGE = 1.0e-3_wp
    !> the iterations one stage may take
    integer, parameter :: FLOW_STAGE_ITERATIONS = 200
    !> the largest step of one coordinate, as a share of the rope's length
    real(wp), parameter :: FLOW_STEP_SHARE = 0.1_wp
    !> Newton (no shift) once the shift has fallen to this share of its scale, the residual
    !! by as much from the stage's start
    real(wp), parameter :: NEWTON_BELOW = 1.0e-3_wp
    !> a step is taken unless it raises the residual's norm squared by more than this
    real(wp), parameter :: GROWTH_ALLOWED = 1.0e4_wp

    !> The iteration of one stage at y: the residual f, its norm phi, the tangent band,
    !! the mass band and the factors of K + sigma M.
    type :: flow_t
        integer, allocatable :: pos(:), vel(:), ipiv(:)
        real(wp), allocatable :: f(:), f_new(:), delta(:), y_new(:), mdiag(:), weight(:)
        real(wp), allocatable :: kb(:, :), mm(:, :), ab(:, :)
        integer :: kw = 0, km = 0
        real(wp) :: phi = 0.0_wp, sigma = 0.0_wp, sigma0 = 0.0_wp, length = 0.0_wp
        logical :: fresh = .true.
    contains
        procedure :: start => flow_start
        procedure :: factor => flow_factor
        procedure :: solve => flow_solve
        procedure :: trial => flow_trial
        procedure :: evaluate => flow_evaluate
    end type flow_t

contains

    !> True when the spec's current drags the rope at rest: drag or water on and a current.
    module procedure current_drags
        drags = (spec%effects%drag .or. spec%effects%water) .and. &
                any(spec%fluid%current /= 0.0_wp)
    end procedure current_drags

    !> The equilibrium in the current from the starting state y: without the current first,
    !! then continued in its speed (the submodule header). Each has options%max_iterations
    !! of its own, as the descent's final iteration and each of its continuation stages
    !! have: the equilibrium without the current may take more than max_iterations in all
    !! (2049 of 2000 in a random scene), and a shared budget then failed a continuation
    !! that had not begun. `result` counts the iterations of both, its stages those of the
    !! current.
    module procedure flow_equilibrium
        type(rope_spec_t) :: still, stage_spec
        class(rope_model_t), allocatable :: stage_model
        type(statics_result_t) :: first
        real(wp), allocatable :: y_try(:), q0(:)
        real(wp) :: s, ds, s_try
        integer, allocatable :: pos(:), vel(:)
        integer :: used
        logical :: ok

        still = spec
        still%fluid%current = 0.0_wp
        call create_model(still, stage_model, err)
        if (allocated(err)) return
        call find_equilibrium(stage_model, still, y, options, first, err)
        if (allocated(err)) then
            err%message = err%message//' (the rope without its current, where the '// &
                          'equilibrium in the current starts)'
            return
        end if
        call model%coordinates(pos, vel)
        q0 = y(pos)
        used = 0
        result = first
        result%stages = 0
        s = 0.0_wp
        ds = FIRST_STAGE
        do while (s < 1.0_wp)
            s_try = min(1.0_wp, s + ds)
            y_try = y
            if (s_try < 1.0_wp) then
                stage_spec = spec
                stage_spec%fluid%current = s_try*spec%fluid%current
                call create_model(stage_spec, stage_model, err)
                if (allocated(err)) return
                call stage_iterate(stage_model, y_try, options, used, result, ok)
            else
                call stage_iterate(model, y_try, options, used, result, ok)
            end if
            if (ok) then
                y = y_try
                s = s_try
                ds = 2.0_wp*ds
                result%stages = result%stages + 1
            else
                ds = 0.25_wp*ds
            end if
            if (ds < LEAST_STAGE .or. used >= options%max_iterations) then
                call stalled(spec, s, used, first%iterations, err)
                return
            end if
        end do
        result%iterations = first%iterations + used
        call flow_finish(model, spec, y, q0, result)
    end procedure flow_equilibrium

    !> One stage: flow_solve from y, within the iterations left; `used` and `result`'s
    !! counters advance by what it took.
    subroutine stage_iterate(model, y, options, used, result, ok)
        class(rope_model_t), intent(inout) :: model
        real(wp), intent(inout) :: y(:)
        type(statics_options_t), intent(in) :: options
        integer, intent(inout) :: used
        type(statics_result_t), intent(inout) :: result
        logical, intent(out) :: ok
        type(flow_t) :: flow
        integer :: budget, taken
        budget = min(FLOW_STAGE_ITERATIONS, options%max_iterations - used)
        taken = 0
        call flow%start(model, y, ok)
        if (ok) call flow%solve(model, y, options, budget, result, ok, taken)
        used = used + taken
    end subroutine stage_iterate

    !> ERR_SOLVER: the continuation in the current stalled at the share s of its speed,
    !! after `used` iterations of its own, the equilibrium without it having taken `still`.
    subroutine stalled(spec, s, used, still, err)
        type(rope_spec_t), intent(in) :: spec
        real(wp), intent(in) :: s
        integer, intent(in) :: used, still
        type(error_t), allocatable, intent(out) :: err
        call make_error(err, ERR_SOLVER, spec%path//': statics: no equilibrium in the '// &
            'current (&fluid current = '//fixed_text(spec%fluid%current(1), 3)//', '// &
            fixed_text(spec%fluid%current(2), 3)//' m/s): the continuation in its speed '// &
            'stalled at '//fixed_text(s, 3)//' of it after '//int_text(used)// &
            ' iterations in it (and '//int_text(still)//' without it before); the rope '// &
            'may have no steady state in this current (run the dynamics from rest '// &
            'instead), or needs more iterations (--max-iterations)')
    end subroutine stalled

    !> Set up the iteration at y (velocities zeroed): coordinates, residual, mass, tangent
    !! (the norm's weights, and the first step's matrix); `ok` false when the forces or the
    !! tangent are not finite.
    subroutine flow_start(self, model, y, ok)
        class(flow_t), intent(inout) :: self
        class(rope_model_t), intent(inout) :: model
        real(wp), intent(inout) :: y(:)
        logical, intent(out) :: ok
        integer :: nd, status
        call model%coordinates(self%pos, self%vel)
        nd = size(self%pos)
        self%km = model%mass_bandwidth()
        self%kw = max(tangent_bandwidth(model), self%km)
        allocate (self%f(nd), self%f_new(nd), self%delta(nd), self%mdiag(nd), self%ipiv(nd), &
                  self%weight(nd), self%y_new(size(y)), &
                  self%kb(-self%kw:self%kw, nd), self%mm(0:self%km, nd), &
                  self%ab(3*self%kw + 1, nd))
        y(self%vel) = 0.0_wp
        self%length = rope_length(model)
        call generalized_force(model, y, self%pos, self%vel, self%f, status)
        ok = status == STATUS_OK
        if (.not. ok) return
        call model%coordinate_mass_band(y, self%mm)
        self%mdiag = self%mm(0, :)
        ! the residual's norm weighs each coordinate by its stiffness, 1/|K_ii| at the start
        ! (units of energy: a moment and a force count alike)
        call tangent_band(model, y, self%pos, self%vel, self%kw, self%kb, status, &
                          hessian=.true.)
        ok = status == STATUS_OK
        if (.not. ok) return
        self%weight = 1.0_wp/max(abs(self%kb(0, :)), tiny(1.0_wp))
        self%phi = sum(self%weight*self%f**2)
        ! the shift's scale: a step of the freest coordinate of L/10 (as the descent's)
        self%sigma0 = maxval(abs(self%f)/self%mdiag)/(0.1_wp*max(self%length, 1.0e-3_wp))
        self%sigma0 = max(self%sigma0, sqrt(tiny(1.0_wp)))
        self%sigma = self%sigma0
        self%fresh = .false.            ! kb and mm are those of y
    end subroutine flow_start

    !> K + sigma M in LAPACK's band storage, factored; `ok` false when it is singular.
    subroutine flow_factor(self, ok)
        class(flow_t), intent(inout) :: self
        logical, intent(out) :: ok
        integer :: i, j, n, kw, info
        n = size(self%pos)
        kw = self%kw
        self%ab = 0.0_wp
        do j = 1, n
            do i = max(1, j - kw), min(n, j + kw)
                self%ab(2*kw + 1 + i - j, j) = self%kb(i - j, j)
            end do
            do i = j, min(n, j + self%km)      ! M(i, j) = M(j, i) = mm(i - j, j)
                self%ab(2*kw + 1 + i - j, j) = self%ab(2*kw + 1 + i - j, j) + &
                                               self%sigma*self%mm(i - j, j)
                if (i /= j) self%ab(2*kw + 1 + j - i, i) = self%ab(2*kw + 1 + j - i, i) + &
                                                           self%sigma*self%mm(i - j, j)
            end do
        end do
        call dgbtrf(n, n, kw, kw, self%ab, 3*kw + 1, self%ipiv, info)
        ok = info == 0
    end subroutine flow_factor

    !> Pseudo-transient continuation steps on the residual from y (the submodule header), at
    !! most `budget` linear solves;
    !! `ok` when a Newton step falls below options%step_tolerance times the length; `used`:
    !! the linear solves it took.
    subroutine flow_solve(self, model, y, options, budget, result, ok, used)
        class(flow_t), intent(inout) :: self
        class(rope_model_t), intent(inout) :: model
        real(wp), intent(inout) :: y(:)
        type(statics_options_t), intent(in) :: options
        integer, intent(in) :: budget
        integer, intent(out) :: used
        type(statics_result_t), intent(inout) :: result
        logical, intent(out) :: ok
        integer :: it, k, status, info
        real(wp) :: step, phi_new
        real(wp), allocatable :: step_k(:)
        logical :: factored
        ok = .false.
        used = 0
        allocate (step_k(size(self%pos)))
        do it = 1, budget
            if (self%fresh) then
                call tangent_band(model, y, self%pos, self%vel, self%kw, self%kb, status, &
                                  hessian=.true.)
                if (status /= STATUS_OK) return
                call model%coordinate_mass_band(y, self%mm)
                self%fresh = .false.
            end if
            used = it
            call self%factor(factored)
            if (factored) then
                self%delta = 0.0_wp
                self%f_new = self%f
                ! the step, then up to two chord corrections with the same factors: they pull
                ! the trial point back towards the manifold the step left (stiff springs
                ! stretched at second order), as in the descent
                do k = 0, 2
                    step_k = self%f_new
                    call dgbtrs('N', size(self%pos), self%kw, self%kw, 1, self%ab, &
                                3*self%kw + 1, self%ipiv, step_k, size(self%pos), info)
                    self%delta = self%delta + step_k
                    if (k == 0) step = maxval(abs(self%delta))
                    if (maxval(abs(self%delta)) > FLOW_STEP_SHARE*self%length) self%delta = &
                        self%delta*(FLOW_STEP_SHARE*self%length/maxval(abs(self%delta)))
                    call self%trial(model, y, phi_new, status)
                    if (phi_new < self%phi .or. status /= STATUS_OK) exit
                end do
                if (self%sigma == 0.0_wp .and. step <= options%step_tolerance*self%length &
                    .and. status == STATUS_OK) then
                    ! a Newton step this small: converged (its trial point kept if better)
                    if (phi_new <= self%phi) call accept_trial()
                    result%criterion = 'newton step'
                    ok = .true.
                    return
                end if
                if (phi_new <= GROWTH_ALLOWED*self%phi) then
                    ! pseudo-transient continuation: every finite step is taken, and the
                    ! shift follows the residual (switched evolution relaxation), halved
                    ! besides after a step that did not raise it (the pseudo-time step
                    ! doubles; also where the stage starts at its equilibrium, where the
                    ! residual stays at rounding and only Newton can say it converged)
                    if (self%sigma == 0.0_wp) result%newton_steps = result%newton_steps + 1
                    self%sigma = self%sigma*sqrt(phi_new/self%phi)
                    if (phi_new <= self%phi) self%sigma = 0.5_wp*self%sigma
                    if (self%sigma < NEWTON_BELOW*self%sigma0) self%sigma = 0.0_wp
                    call accept_trial()
                    cycle
                end if
            end if
            result%rejected = result%rejected + 1
            self%sigma = max(4.0_wp*self%sigma, self%sigma0)
        end do
    contains
        subroutine accept_trial()
            y = self%y_new
            self%f = self%f_new
            self%phi = phi_new
            self%fresh = .true.
            result%last_step = maxval(abs(self%delta))
        end subroutine accept_trial
    end subroutine flow_solve

    !> The trial point of the step delta (y_new, f_new; phi_new, huge when the forces are not
    !! finite): y + delta, or the model's `displace` of y by delta where that differs and
    !! has the smaller residual, as the descent chooses it (ropedyn_statics, trial_point).
    subroutine flow_trial(self, model, y, phi_new, status)
        class(flow_t), intent(inout) :: self
        class(rope_model_t), intent(inout) :: model
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: phi_new
        integer, intent(out) :: status
        real(wp), allocatable :: y_lin(:), y_turned(:), f_lin(:)
        real(wp) :: phi_lin
        integer :: status_lin
        y_lin = y
        y_lin(self%pos) = y(self%pos) + self%delta
        call self%evaluate(model, y_lin, phi_new, status)
        allocate (y_turned(size(y)))
        call model%displace(y, self%delta, y_turned)
        if (all(y_turned == y_lin)) return
        f_lin = self%f_new
        phi_lin = phi_new
        status_lin = status
        call self%evaluate(model, y_turned, phi_new, status)
        if (phi_new < phi_lin) return
        self%y_new = y_lin
        self%f_new = f_lin
        phi_new = phi_lin
        status = status_lin
    end subroutine flow_trial

    !> The residual at the state y_trial (y_new, f_new) and its weighted norm squared
    !! phi_new, huge when it is not finite.
    subroutine flow_evaluate(self, model, y_trial, phi_new, status)
        class(flow_t), intent(inout) :: self
        class(rope_model_t), intent(inout) :: model
        real(wp), intent(in) :: y_trial(:)
        real(wp), intent(out) :: phi_new
        integer, intent(out) :: status
        self%y_new = y_trial
        call generalized_force(model, self%y_new, self%pos, self%vel, self%f_new, status)
        phi_new = huge(1.0_wp)
        if (status == STATUS_OK) phi_new = sum(self%weight*self%f_new**2)
    end subroutine flow_evaluate

    !> The equilibrium's results as the descent's (at_rest_near, statics_result_t%report),
    !! the residual evaluated at the end (the stages' iterations keep theirs).
    subroutine flow_finish(model, spec, y, q0, result)
        class(rope_model_t), intent(inout) :: model
        type(rope_spec_t), intent(in) :: spec
        real(wp), intent(inout) :: y(:)
        real(wp), intent(in) :: q0(:)
        type(statics_result_t), intent(inout) :: result
        real(wp), allocatable :: f(:)
        integer, allocatable :: pos(:), vel(:)
        integer :: status
        call model%coordinates(pos, vel)
        allocate (f(size(pos)))
        y(vel) = 0.0_wp
        call generalized_force(model, y, pos, vel, f, status)
        call at_rest_near(model, y, pos, vel, q0, f)
        result%weight = total_weight(model, spec)
        result%rounding_level = 0.0_wp
        call result%report(model, y, f)
    end subroutine flow_finish
end submodule ropedyn_statics_flow
