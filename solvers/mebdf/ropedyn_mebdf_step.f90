!> One MEBDF step: the iteration matrix, the three stage solves (chord Newton), the error
!! test, the history update and the choice of the next step size and order. try_step runs
!! the attempts; each part of one is a procedure of this submodule.
submodule (ropedyn_mebdf) ropedyn_mebdf_step
    implicit none

    !> A stage outcome of this submodule: the local error test failed
    integer, parameter :: STAGE_ERROR_TEST = -1

    !> The failures of one step's attempts (try_step): their counts, whether the next
    !! attempt refreshes the Jacobian, and the cause of the last.
    type :: attempts_t
        integer :: error_fails = 0
        integer :: conv_fails = 0
        logical :: refresh = .false.
        character(len=:), allocatable :: last_cause
    end type attempts_t

contains

    module procedure prepare_matrix
        logical :: new_jacobian
        real(wp) :: start
        status = STATUS_OK
        new_jacobian = refresh .or. self%jacobian_age >= JACOBIAN_MAX_AGE .or. &
                       self%counters%jac_evals == 0
        if (new_jacobian .and. .not. self%jacobian_current) then
            if (self%options%profile) start = clock_seconds()
            call self%matrix%evaluate_jacobian(self%problem, self%t, self%dif(1:self%n, 0), &
                self%w, self%h, status, self%counters%jac_rhs_evals)
            if (self%options%profile) self%counters%time_jac = self%counters%time_jac + &
                                                               (clock_seconds() - start)
            self%counters%jac_evals = self%counters%jac_evals + 1
            if (status /= STATUS_OK) return
            self%jacobian_age = 0
            self%jacobian_current = .true.
            self%matrix%factored = .false.
        end if
        if (.not. self%matrix%factored .or. &
            abs(hbeta - self%matrix%hbeta) > REFACTOR_CHANGE*abs(self%matrix%hbeta)) then
            if (self%options%profile) start = clock_seconds()
            call self%matrix%factor(self%problem, self%t, self%dif(1:self%n, 0), hbeta, status)
            if (self%options%profile) self%counters%time_factor = self%counters%time_factor + &
                                                                  (clock_seconds() - start)
            self%counters%lin_setups = self%counters%lin_setups + 1
            self%crate = 1.0_wp
        end if
    end procedure prepare_matrix

    module procedure stage
        real(wp) :: dnorm, dnorm_old, dcon, start
        integer :: iter, status, n, i
        logical :: mass, profile, fused

        n = self%n
        mass = self%problem%has_mass_matrix()
        profile = self%options%profile
        outcome = STAGE_NO_CONVERGENCE
        dnorm_old = 0.0_wp
        ! Without a mass matrix the quadratures' rates come with each evaluation of f (one
        ! pass, problem_t's rhs_quad): the stage's quadratures then take them at the last
        ! Newton iterate, off the converged point by the last correction (its weighted norm
        ! below NEWTON_TOL over the contraction rate), instead of one more evaluation there
        ! (docs/theory/mebdf.md, "Choices, and why": quadratures).
        fused = self%nq > 0 .and. .not. mass
        do iter = 1, MAX_NEWTON_ITERS
            if (profile) start = clock_seconds()
            if (fused) then
                call self%problem%rhs_quad(tn, z(1:n), self%f, self%gq(1:self%nq), status)
            else
                call self%problem%implicit_rhs(tn, z(1:n), self%f, status)
            end if
            self%counters%rhs_evals = self%counters%rhs_evals + 1
            if (status /= STATUS_OK) then
                outcome = merge(STAGE_FATAL, STAGE_RHS_FAILED, status == STATUS_FATAL)
                return
            end if
            if (mass) then
                call self%matrix%mass_times(self%problem, tn, z(1:n), z(1:n) - c(1:n), &
                                            self%mv, status)
                if (status /= STATUS_OK) then
                    if (status == STATUS_FATAL) outcome = STAGE_FATAL
                    return
                end if
                self%r = hbeta*self%f - self%mv
            else
                do i = 1, n
                    self%r(i) = hbeta*self%f(i) - (z(i) - c(i))
                end do
            end if
            if (profile) then
                self%counters%time_rhs = self%counters%time_rhs + (clock_seconds() - start)
                start = clock_seconds()
            end if
            call self%matrix%solve(self%r)
            if (profile) self%counters%time_solve = self%counters%time_solve + &
                                                    (clock_seconds() - start)
            self%counters%nonlin_iters = self%counters%nonlin_iters + 1
            ! the correction and its norm; a NaN or Inf in it (or a norm beyond the
            ! floating-point range) fails the stage, whose z is then thrown away
            z(1:n) = z(1:n) + self%r
            dnorm = sum_scaled_squares(self%r, self%wi(1:n))
            if (.not. ieee_is_finite(dnorm)) return
            dnorm = sqrt(dnorm/real(n, wp))
            if (iter > 1) then
                if (dnorm > 2.0_wp*dnorm_old) return
                self%crate = max(0.3_wp*self%crate, dnorm/dnorm_old)
            end if
            dcon = dnorm*min(1.0_wp, self%crate)
            if (dcon <= NEWTON_TOL .or. dnorm == 0.0_wp) then
                outcome = STAGE_OK
                exit
            end if
            dnorm_old = dnorm
        end do
        if (outcome /= STAGE_OK) return
        if (self%nq > 0 .and. .not. fused) then
            if (profile) start = clock_seconds()
            call self%problem%quad_rhs(tn, z(1:n), self%gq, status)
            if (profile) self%counters%time_rhs = self%counters%time_rhs + &
                                                  (clock_seconds() - start)
            if (status /= STATUS_OK) then
                outcome = merge(STAGE_FATAL, STAGE_RHS_FAILED, status == STATUS_FATAL)
                return
            end if
        end if
        if (self%nq > 0) z(n + 1:) = c(n + 1:) + hbeta*self%gq(1:self%nq)
    end procedure stage

    module procedure try_step
        type(attempts_t) :: tries
        real(wp) :: tn, err1
        integer :: outcome, status

        tries%last_cause = 'none'
        do
            call begin_attempt(self, tn)
            call check_progress(self, tn, tries%last_cause, err)
            if (allocated(err)) return
            call weights_and_inverses(self%nt, self%options%rtol, self%atol, self%dif, &
                                      self%w, self%wi)
            call self%prepare_matrix(self%h*self%coef(self%k)%beta, tries%refresh, status)
            tries%refresh = .false.
            if (status == STATUS_FATAL) then
                call self%failure(err, 'the Jacobian or mass matrix could not be evaluated')
                return
            end if
            outcome = STAGE_NO_CONVERGENCE
            if (status == STATUS_OK) call three_stages(self, tn, err1, outcome)
            select case (outcome)
            case (STAGE_OK)
                exit
            case (STAGE_ERROR_TEST)
                call error_failed(self, tries, err1, err)
            case default
                call newton_failed(self, tries, outcome, err)
            end select
            if (allocated(err)) return
        end do
        call accept_step(self, tn, err1)
    end procedure try_step

    !> Before an attempt: a step-size or order change that waits is made, and a step that
    !! would reach a stop time ahead (or come within 1 % of a step of it) ends exactly
    !! there (stage 2 still looks one step beyond). tn: where the attempt ends.
    subroutine begin_attempt(self, tn)
        class(mebdf_t), intent(inout) :: self
        real(wp), intent(out) :: tn
        real(wp) :: ratio
        if (self%pending) then
            if (self%pending_k /= self%k) then
                self%k = self%pending_k
            end if
            if (self%pending_ratio /= 1.0_wp) call self%rescale(self%pending_ratio, self%k)
            self%pending = .false.
            self%steps_at_h = 0
        end if
        if (self%t + 1.01_wp*self%h >= self%t_stop .and. self%t < self%t_stop) then
            ratio = (self%t_stop - self%t)/self%h
            if (ratio /= 1.0_wp) call self%rescale(ratio, self%k)
            if (abs(ratio - 1.0_wp) > 0.01_wp) self%steps_at_h = 0
        end if
        tn = self%t + self%h
        if (self%t + 1.01_wp*self%h >= self%t_stop) tn = self%t_stop
    end subroutine begin_attempt

    !> The step budget and the round-off limit of the step size (after `last_cause`).
    subroutine check_progress(self, tn, last_cause, err)
        class(mebdf_t), intent(inout) :: self
        real(wp), intent(in) :: tn
        character(len=*), intent(in) :: last_cause
        type(error_t), allocatable, intent(inout) :: err
        real(wp) :: hmin
        hmin = 16.0_wp*epsilon(1.0_wp)*max(abs(self%t), abs(tn))
        if (self%counters%steps >= self%options%max_steps) then
            call self%failure(err, self%steps_exhausted(self%t))
        else if (self%h < hmin) then
            call self%failure(err, 'step size fell below the round-off limit after: '// &
                              last_cause)
        end if
    end subroutine check_progress

    !> The three stages of a step to tn at order k + 1 (module header) and the error test
    !! on stage 1 (err1, normalized): outcome STAGE_OK, a stage's failure, or
    !! STAGE_ERROR_TEST (err1 then the error the step failed with).
    subroutine three_stages(self, tn, err1, outcome)
        class(mebdf_t), intent(inout) :: self
        real(wp), intent(in) :: tn
        real(wp), intent(out) :: err1
        integer, intent(out) :: outcome
        real(wp) :: beta, hbeta, gam(KMAX_MEBDF)
        integer :: k
        k = self%k
        beta = self%coef(k)%beta
        hbeta = self%h*beta
        gam = 1.0_wp/self%coef%beta   ! gamma_j = sum_{i<=j} 1/i = 1/beta_j
        err1 = 0.0_wp
        call stage_bdf(self, tn, hbeta, gam, outcome)
        if (outcome /= STAGE_OK) return
        call slope_and_correction(self%nt, 1.0_wp/beta, self%ybar1, self%c, self%pred, &
                                  self%hg1, self%d1)
        err1 = self%wnorm(self%d1)/self%coef(k)%tq
        if (self%fixed) err1 = 0.0_wp
        if (.not. (err1 <= 1.0_wp)) then
            outcome = STAGE_ERROR_TEST
            return
        end if
        call stage_bdf_ahead(self, tn, hbeta, gam, outcome)
        if (outcome /= STAGE_OK) return
        self%hg2 = (self%ybar2 - self%c)*(1.0_wp/beta)
        call stage_corrector(self, tn, hbeta, outcome)
        if (outcome /= STAGE_OK) return
        self%tmp = self%y3 - self%ybar1
        if (.not. (self%wnorm(self%tmp) <= EXTRA_CHECK .or. self%fixed)) then
            err1 = max(err1, 1.01_wp)
            outcome = STAGE_ERROR_TEST
        end if
    end subroutine three_stages

    !> Stage 1: the k-step BDF to tn, into ybar1 (its predictor in pred, its known part in
    !! c). pred = sum_{j=0..k} dif_j, psi = sum_{j=1..k} gam_j dif_j (c holds psi until
    !! the last line). With P_j = sum_{i>=j} dif_i (the predictor's differences), psi is
    !! sum_{j=1..k} (1/j) P_j, the BDF's known part. The loops over the components are
    !! innermost (vector instructions); pred stays for the history.
    subroutine stage_bdf(self, tn, hbeta, gam, outcome)
        class(mebdf_t), intent(inout) :: self
        real(wp), intent(in) :: tn, hbeta, gam(:)
        integer, intent(out) :: outcome
        integer :: k
        k = self%k
        call predict_bdf(self%nt, k, self%dif, gam, self%coef(k)%beta, self%pred, self%c, &
                         self%ybar1)
        call self%stage(tn, hbeta, self%c, self%ybar1, outcome)
    end subroutine stage_bdf

    !> Stage 2: the same BDF one step further, ybar1 joining the history, into ybar2. With
    !! P_j = sum_{i=j..k} dif_i, the differences of ybar1 are P_j + d1; the predictor
    !! (summed in ybar2) is their sum and psi (in c) = sum_{i=1..k} gam(i) (P_i + d1); tmp
    !! carries P_i.
    subroutine stage_bdf_ahead(self, tn, hbeta, gam, outcome)
        class(mebdf_t), intent(inout) :: self
        real(wp), intent(in) :: tn, hbeta, gam(:)
        integer, intent(out) :: outcome
        integer :: k
        k = self%k
        call predict_ahead(self%nt, k, self%dif, gam, self%coef(k)%beta, self%ybar1, self%d1, &
                           self%tmp, self%ybar2, self%c)
        call self%stage(tn + self%h, hbeta, self%c, self%ybar2, outcome)
    end subroutine stage_bdf_ahead

    !> Stage 3: the modified extended corrector, into y3. Old values y_{n-i} from the
    !! differences: y_{n-i} = sum_{j=0..i} (-1)^j binom(i, j) dif_j.
    !! c = ... - sum_i ahat(k-1-i) y_{n-i} = ... + sum_j wd(j) dif_j: the weights of the
    !! differences first (scalars), then one pass per difference.
    subroutine stage_corrector(self, tn, hbeta, outcome)
        class(mebdf_t), intent(inout) :: self
        real(wp), intent(in) :: tn, hbeta
        integer, intent(out) :: outcome
        real(wp) :: wd(0:KMAX_MEBDF), binom, beta
        integer :: i, j, k
        k = self%k
        beta = self%coef(k)%beta
        wd = 0.0_wp
        do i = 0, k - 1
            ! point n - i has index k - 1 - i in the corrector's numbering
            binom = 1.0_wp
            do j = 0, i
                wd(j) = wd(j) - self%coef(k)%ahat(k - 1 - i)*binom
                binom = -binom*real(i - j, wp)/real(j + 1, wp)
            end do
        end do
        self%c = (self%coef(k)%bhat_k - beta)*self%hg1 + self%coef(k)%bhat_k1*self%hg2
        do j = 0, k - 1
            self%c = self%c + wd(j)*self%dif(:, j)
        end do
        self%y3 = self%ybar1
        call self%stage(tn, hbeta, self%c, self%y3, outcome)
    end subroutine stage_corrector

    !> The step to tn is accepted: order-change estimates (BDF errors at orders k-1 and
    !! k+1) from the old differences, then the history moves to tn with the MEBDF value,
    !! and the next step's size and order are chosen.
    subroutine accept_step(self, tn, err1)
        class(mebdf_t), intent(inout) :: self
        real(wp), intent(in) :: tn, err1
        real(wp) :: errkm1, errkp1
        integer :: k
        k = self%k
        errkm1 = huge(1.0_wp)
        errkp1 = huge(1.0_wp)
        if (k > 1) then
            self%tmp = self%dif(:, k) + self%d1
            errkm1 = self%wnorm(self%tmp)/self%coef(k - 1)%tq
        end if
        if (k < self%kmax .and. self%steps_at_h >= k + 1) then
            self%tmp = self%d1 - self%dif(:, k + 1)
            errkp1 = self%wnorm(self%tmp)/self%coef(k + 1)%tq
        end if
        ! nabla^{k+1} y_{n+1} = y3 - pred (stage 1's predictor, sum_{j=0..k} dif_j), then
        ! dif_j <- dif_j + dif_{j+1} (the new one) from j = k down
        call update_history(self%nt, k, self%y3, self%pred, self%dif)
        self%t = tn
        self%h_used = self%h
        self%counters%steps = self%counters%steps + 1
        self%counters%order_steps(k + 1) = self%counters%order_steps(k + 1) + 1
        self%counters%last_step = self%h
        self%counters%last_order = k + 1
        self%steps_at_h = self%steps_at_h + 1
        self%jacobian_age = self%jacobian_age + 1
        self%jacobian_current = .false.
        if (self%steps_at_h >= k + 2 .and. .not. self%fixed) &
            call choose_next(self, err1, errkm1, errkp1)
    end subroutine accept_step

    ! The vector work of a step: explicit-shape arrays (dif as (nt, 0:*), the whole
    ! history), each loop one pass over the components doing all that a statement per
    ! vector did, with the same operations in the same order (the same bits).

    !> The error weights w = rtol |y_n| + atol (ropedyn_integrator's error_weights at the
    !! history's y_n) and their inverses wi, in one pass.
    pure subroutine weights_and_inverses(nt, rtol, atol, dif, w, wi)
        integer, intent(in) :: nt
        real(wp), intent(in) :: rtol, atol(nt), dif(nt, 0:*)
        real(wp), intent(out) :: w(nt), wi(nt)
        integer :: i
        do i = 1, nt
            w(i) = rtol*abs(dif(i, 0)) + atol(i)
            wi(i) = 1.0_wp/w(i)
        end do
    end subroutine weights_and_inverses

    !> Stage 1's predictor pred = sum_{j=0..k} dif_j, its known part
    !! c = pred - beta sum_{j=1..k} gam_j dif_j and its start ybar1 = pred: one pass per
    !! difference for pred and c together.
    pure subroutine predict_bdf(nt, k, dif, gam, beta, pred, c, ybar1)
        integer, intent(in) :: nt, k
        real(wp), intent(in) :: dif(nt, 0:*), gam(:), beta
        real(wp), intent(out) :: pred(nt), c(nt), ybar1(nt)
        integer :: i, j
        do i = 1, nt
            pred(i) = dif(i, 0) + dif(i, 1)
            c(i) = gam(1)*dif(i, 1)
        end do
        do j = 2, k
            do i = 1, nt
                pred(i) = pred(i) + dif(i, j)
                c(i) = c(i) + gam(j)*dif(i, j)
            end do
        end do
        do i = 1, nt
            c(i) = pred(i) - beta*c(i)
            ybar1(i) = pred(i)
        end do
    end subroutine predict_bdf

    !> Stage 2's predictor (in ybar2) and known part c (stage_bdf_ahead), p carrying
    !! P_i = sum_{j=i..k} dif_j: one pass per difference for the three together.
    pure subroutine predict_ahead(nt, k, dif, gam, beta, ybar1, d1, p, ybar2, c)
        integer, intent(in) :: nt, k
        real(wp), intent(in) :: dif(nt, 0:*), gam(:), beta, ybar1(nt), d1(nt)
        real(wp), intent(out) :: p(nt), ybar2(nt), c(nt)
        integer :: i, j
        do i = 1, nt
            p(i) = dif(i, k)
            ybar2(i) = ybar1(i) + p(i) + d1(i)
            c(i) = gam(k)*(p(i) + d1(i))
        end do
        do j = k - 1, 1, -1
            do i = 1, nt
                p(i) = p(i) + dif(i, j)
                ybar2(i) = ybar2(i) + p(i) + d1(i)
                c(i) = c(i) + gam(j)*(p(i) + d1(i))
            end do
        end do
        do i = 1, nt
            c(i) = ybar2(i) - beta*c(i)
        end do
    end subroutine predict_ahead

    !> Stage 1's slope h g1 = (ybar1 - c) rbeta (rbeta = 1/beta) and its correction
    !! d1 = ybar1 - pred, in one pass.
    pure subroutine slope_and_correction(nt, rbeta, ybar1, c, pred, hg1, d1)
        integer, intent(in) :: nt
        real(wp), intent(in) :: rbeta, ybar1(nt), c(nt), pred(nt)
        real(wp), intent(out) :: hg1(nt), d1(nt)
        integer :: i
        do i = 1, nt
            hg1(i) = (ybar1(i) - c(i))*rbeta
            d1(i) = ybar1(i) - pred(i)
        end do
    end subroutine slope_and_correction

    !> The history moves to the new point y3: nabla^{k+1} y_{n+1} = y3 - pred (pred the
    !! sum of dif_0 .. dif_k), dif_{k+2} its change, then dif_j <- dif_j + dif_{j+1} from
    !! j = k down.
    pure subroutine update_history(nt, k, y3, pred, dif)
        integer, intent(in) :: nt, k
        real(wp), intent(in) :: y3(nt), pred(nt)
        real(wp), intent(inout) :: dif(nt, 0:k + 2)
        real(wp) :: e
        integer :: i, j
        do i = 1, nt
            e = y3(i) - pred(i)
            dif(i, k + 2) = e - dif(i, k + 1)
            dif(i, k + 1) = e
        end do
        do j = k, 0, -1
            do i = 1, nt
                dif(i, j) = dif(i, j) + dif(i, j + 1)
            end do
        end do
    end subroutine update_history

    !> Step size and order for the next step (after k + 2 steps at this h and k), from the
    !! normalized errors at orders k, k-1 and k+1: the largest growth wins.
    subroutine choose_next(self, err1, errkm1, errkp1)
        class(mebdf_t), intent(inout) :: self
        real(wp), intent(in) :: err1, errkm1, errkp1
        real(wp) :: ratio, r_same, r_down, r_up
        integer :: k, knew
        k = self%k
        r_same = 1.0_wp/(SAFETY_SAME*max(err1, 1.0e-10_wp)**(1.0_wp/real(k + 1, wp)))
        r_down = 0.0_wp
        r_up = 0.0_wp
        if (k > 1) r_down = 1.0_wp/(SAFETY_DOWN*max(errkm1, 1.0e-10_wp)**(1.0_wp/real(k, wp)))
        if (errkp1 < huge(1.0_wp)) then
            r_up = 1.0_wp/(SAFETY_UP*max(errkp1, 1.0e-10_wp)**(1.0_wp/real(k + 2, wp)))
        end if
        knew = k
        ratio = r_same
        if (r_down > ratio) then
            knew = k - 1
            ratio = r_down
        end if
        if (r_up > ratio) then
            knew = k + 1
            ratio = r_up
        end if
        if (ratio > MIN_GROWTH .or. knew /= k) then
            ratio = min(ratio, merge(2.0_wp, 10.0_wp, self%recent_failure))
            self%recent_failure = .false.
            ! (at the start, before any failure, the step does not shrink)
            if (self%counters%steps <= k + 2 .and. .not. self%any_failure) &
                ratio = max(ratio, 1.0_wp)
            ratio = max(ratio, 0.2_wp)
            self%pending = .true.
            self%pending_k = knew
            self%pending_ratio = ratio
        end if
    end subroutine choose_next

    !> A stage failed: a fatal right-hand side ends the run; otherwise refresh an old
    !! Jacobian and retry, else cut the step by 4.
    subroutine newton_failed(self, tries, why, err)
        class(mebdf_t), intent(inout) :: self
        type(attempts_t), intent(inout) :: tries
        integer, intent(in) :: why
        type(error_t), allocatable, intent(inout) :: err
        if (why == STAGE_FATAL) then
            call self%failure(err, 'the right-hand side reported a fatal error')
            return
        end if
        self%counters%nonlin_conv_fails = self%counters%nonlin_conv_fails + 1
        tries%conv_fails = tries%conv_fails + 1
        self%any_failure = .true.
        self%recent_failure = .true.
        if (why == STAGE_RHS_FAILED) then
            tries%last_cause = 'repeated recoverable errors of the right-hand side (e.g. a '// &
                               'NaN or Inf in the forces) during the Newton iteration'
        else
            tries%last_cause = 'repeated Newton convergence failures (or a singular '// &
                               'iteration matrix M - h beta J)'
        end if
        if (tries%conv_fails > MAX_CONV_FAILS) then
            call self%failure(err, tries%last_cause)
            return
        end if
        if (.not. self%jacobian_current .and. why /= STAGE_RHS_FAILED) then
            tries%refresh = .true.
        else
            self%pending = .true.
            self%pending_k = self%k
            self%pending_ratio = 0.25_wp
        end if
    end subroutine newton_failed

    !> Local error test failed with normalized error e: smaller step, maybe lower order.
    subroutine error_failed(self, tries, e, err)
        class(mebdf_t), intent(inout) :: self
        type(attempts_t), intent(inout) :: tries
        real(wp), intent(in) :: e
        type(error_t), allocatable, intent(inout) :: err
        real(wp) :: r, errkm1
        self%counters%err_test_fails = self%counters%err_test_fails + 1
        tries%error_fails = tries%error_fails + 1
        tries%last_cause = 'repeated local error test failures'
        self%any_failure = .true.
        self%recent_failure = .true.
        if (tries%error_fails >= MAX_ERROR_FAILS) then
            call self%failure(err, 'repeated local error test failures')
            return
        end if
        self%pending = .true.
        self%pending_k = self%k
        if (tries%error_fails >= 3) then
            self%pending_k = 1
            self%pending_ratio = 0.1_wp
            return
        end if
        r = 1.0_wp/(SAFETY_FAILED*e**(1.0_wp/real(self%k + 1, wp)))
        if (tries%error_fails == 2) r = min(r, 0.5_wp)
        ! the first step may be far too large: allow a deeper cut there
        self%pending_ratio = min(max(r, merge(1.0e-3_wp, 0.1_wp, &
                                              self%counters%steps == 0)), 0.9_wp)
        if (self%k > 1) then
            self%tmp = self%dif(:, self%k) + self%d1
            errkm1 = self%wnorm(self%tmp)/self%coef(self%k - 1)%tq
            if (errkm1 < e) then
                self%pending_k = self%k - 1
                r = 1.0_wp/(SAFETY_FAILED*max(errkm1, 1.0e-10_wp)** &
                            (1.0_wp/real(self%k, wp)))
                self%pending_ratio = min(max(r, 0.1_wp), 0.9_wp)
            end if
        end if
    end subroutine error_failed

    module procedure failure
        character(len=96) :: where
        write (where, '(a, a, a, a, a, i0)') 't = ', es_text(self%t, 12, 5), &
            ' s, step size ', es_text(self%h, 10, 3), ' s, order ', self%k + 1
        call make_error(err, ERR_SOLVER, 'mebdf failed at '//trim(where)//': '//cause)
    end procedure failure
end submodule ropedyn_mebdf_step
