!> The symplectic method's probe before auto takes it (ropedyn_auto_switching's header,
!! "Symplectic"; docs/theory/symplectic.md, "auto"). The method's step is fixed by the
!! spectrum and has no error estimate; where a forcing outpaces that step (a support shaken
!! at 20 Hz) its error at the same rtol is 10 to 20 times erk's. So before auto takes it
!! (at the start, leaving the implicit method, or on erk's measured cost) it estimates
!! the method's error from the state it has reached.
!!
!! - **The probe**: PROBE_STEPS steps of the composition at the step h and twice as many at
!!   h/2 (a fixed step, no spectrum estimate; cut at t_end and at the stop time, and not
!!   made when fewer than a tenth of them fit). The error at h is |y_h - y_h/2| 2^p /
!!   (2^p - 1) in the error test's weighted RMS norm over the coordinates: p is the
!!   composition's order, 2 where the problem has other forces (their Strang splitting is
!!   of order 2; the larger factor is the safe side).
!! - **Coordinates, not rates**: the rates of the lightly damped fast modes, which the
!!   method does not follow in phase at these steps (it keeps their energy, not their
!!   phase), differ from erk's by 3 .. 84 tolerances where the coordinates agree to
!!   1e-3 .. 5e-2 (input/hard/light_damping.nml and its neighbours, over erk's window
!!   before auto's switch).
!! - **The limit**: sqrt(PROBE_STEPS) = 20 tolerances, what PROBE_STEPS errors of one
!!   tolerance each (the error test's promise per step) add up to at random. Measured:
!!   3e-3 .. 6e-2 on the scenes auto switched on (light_damping, undamped,
!!   paper_light_damping, long_rope), 1e-2 on snap_load and up to 7 on shaken_top with
!!   light damping (where the method's error over 0.5 s is 1.4 times erk's), 36 .. 1.7e3
!!   where the support is shaken at 20 .. 80 Hz (10 to 20 times erk's).
!! - A probe that fails keeps the method out for STALE_WINDOWS windows of the others,
!!   doubled after each failure; its note (not a warning) is in the switch log. The
!!   probe's evaluations of the forces count in the run's (its steps do not: they are
!!   not steps of the run).
!! - **Only before**: while the method runs, auto does not probe it again. Where a long
!!   run turns chaotic (a whip's crack, the fold of a long rope) the method's local error
!!   exceeds the tolerance (3 to 30 tolerances per step: the undamped 4-element rope at
!!   rtol 1e-3 after 60 s, long_rope after 7 s, whip with light damping at 1.6 s), but no
!!   method follows the trajectory there; what such a run delivers is statistics, which
!!   an adaptive method's energy drift biases and this method's bounded balance does not
!!   (docs/theory/symplectic.md, "Why").
submodule (ropedyn_auto) ropedyn_auto_probe
    implicit none

contains

    module procedure probe_symplectic
        real(wp), allocatable :: y1(:), y2(:), w(:)
        integer, allocatable :: pos(:), vel(:)
        integer :: kl, ku, p, n
        real(wp) :: t_end, e, limit
        logical :: done
        passed = .true.
        text = ''
        t_end = min(self%options%t_end, self%t_stop)
        n = PROBE_STEPS
        if (.not. (h > 0.0_wp)) return
        if (self%t + real(n, wp)*h > t_end) n = floor((t_end - self%t)/h)
        if (n < PROBE_STEPS/10) return
        call probe_run(h, n, y1, done)
        if (done) call probe_run(0.5_wp*h, 2*n, y2, done)
        call self%sym_probe%finalize()
        if (.not. done) then
            passed = .false.
            write (text, '(a, i0, a, es9.2, a)') 'its probe of ', n, ' steps of ', h, &
                ' s from here did not finish'
        else
            p = tab%order
            if (self%problem%split_has_rest()) p = min(p, 2)
            call self%problem%second_order_layout(pos, vel, kl, ku)
            allocate (w(size(self%y)))
            w = error_weights(self%options, self%y)
            e = sqrt(sum(((y1(pos) - y2(pos))/w(pos))**2)/real(size(pos), wp))* &
                2.0_wp**p/(2.0_wp**p - 1.0_wp)
            limit = sqrt(real(n, wp))
            passed = e <= limit
            write (text, '(a, i0, a, es9.2, a, es9.2, a, es9.2, a)') 'its error over ', n, &
                ' steps of ', h, ' s from t = ', self%t, &
                ' s, estimated by halving the step, is ', e, ' tolerances'
            if (.not. passed) write (text, '(a, f5.1, a, i0, a)') trim(text)// &
                ', more than ', limit, ' (what ', n, ' errors of one tolerance each add '// &
                'up to at random; its step is fixed by the spectrum, not by the tolerance)'
        end if
        if (passed) return
        self%sym_wait = self%sym_backoff
        self%sym_backoff = int(min(0.5_wp*real(huge(0), wp), 2.0_wp*self%sym_backoff))
    contains
        !> The method from the state now over `steps` steps of h: its end state y, done
        !! unless it failed or stopped on request.
        subroutine probe_run(h, steps, y, done)
            real(wp), intent(in) :: h
            integer, intent(in) :: steps
            real(wp), allocatable, intent(out) :: y(:)
            logical, intent(out) :: done
            type(solver_options_t) :: opts
            type(solver_stats_t) :: used
            type(error_t), allocatable :: err
            real(wp), allocatable :: yq(:)
            real(wp) :: t, t1
            used = self%stats()
            opts = budget_left(self%options, used%steps)
            opts%max_order = 4
            y = self%y
            yq = self%yq
            t = self%t
            t1 = self%t + real(steps, wp)*h
            call self%sym_probe%init(self%problem, self%t, y, yq, opts, err)
            if (.not. allocated(err)) then
                call self%sym_probe%fix_step(tab%kind, h)
                call self%sym_probe%advance_to(t1, t, y, yq, err)
                used = self%sym_probe%stats()
                self%done%rhs_evals = self%done%rhs_evals + used%rhs_evals
            end if
            done = .not. allocated(err) .and. t >= t1
        end subroutine probe_run
    end procedure probe_symplectic
end submodule ropedyn_auto_probe
