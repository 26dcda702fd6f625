!> Runs one scene: builds the model and the integrator it names, integrates to t_end
!! with output at every output_interval, writes the HDF5 file and returns a summary.
module ropedyn_simulation
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use ropedyn_kinds, only: wp, i8
    use, intrinsic :: iso_fortran_env, only: error_unit
    use ropedyn_text, only: real_text, int_text
    use ropedyn_error, only: error_t, make_error, ERR_INPUT, ERR_IO, ERR_SOLVER, ERR_INTERRUPTED
    use ropedyn_signals, only: catch_signals, release_signals, signal_received, signal_name, &
        end_on_second_signal
    use ropedyn_process, only: process_text
    use ropedyn_rope_model, only: rope_model_t, energy_t
    use ropedyn_integrator, only: integrator_t, solver_options_t, solver_stats_t
    use ropedyn_clock, only: clock_seconds
    use ropedyn_solvers, only: new_integrator
    use ropedyn_rfem, only: rfem_t, rfem_create
    use ropedyn_mpp, only: mpp_t, mpp_create
    use ropedyn_rope_spec, only: rope_spec_t
    use ropedyn_scene, only: scene_t, scene_namelist_text
    use ropedyn_os, only: make_parent_dirs
    use ropedyn_output, only: output_file_t, add_counter_values
    use ropedyn_case_file, only: case_data_t, read_case_file
    use ropedyn_run_record, only: run_record_t, read_run_record, check_record_fits, LAST_RECORD
    use ropedyn_progress, only: progress_t
    use ropedyn_switch_log, only: switch_event_t
    use ropedyn_version, only: version_string
    use ropedyn_modes, only: equilibrium_initial_state
    use ropedyn_methods, only: METHODS, method_index
    use ropedyn_energy_monitor, only: energy_monitor_t, safety_record_t, high_order_to_blame, &
                                      sudden_gain, look_budget, look_action, LOOK_LOWER, &
                                      LOOK_NO_VERDICT, LOOK_FAIL
    use ropedyn_state_start, only: state_initial_state
    implicit none
    private
    public :: run_summary_t, run_scene, create_model, create_integrator, solver_options_of

    !> What a run reports back to the driver.
    type :: run_summary_t
        type(solver_stats_t) :: stats
        real(wp) :: cpu_time = 0.0_wp      !< s
        real(wp) :: t_reached = 0.0_wp     !< s
        type(energy_t) :: initial_energy
        type(energy_t) :: final_energy
        integer :: records = 0             !< output times written
        !> the integrator's changes of method or order limit (auto, cvode's crawl watch)
        type(switch_event_t), allocatable :: switches(:)
        character(len=:), allocatable :: file
        type(safety_record_t) :: safety   !< what the order safety did (docs/stability.md)
    end type run_summary_t

contains

    !> The model a spec names.
    subroutine create_model(spec, model, err)
        type(rope_spec_t), intent(in) :: spec
        class(rope_model_t), allocatable, intent(out) :: model
        type(error_t), allocatable, intent(out) :: err
        type(rfem_t), allocatable :: rfem
        type(mpp_t), allocatable :: mpp
        select case (spec%model%kind)
        case ('rfem')
            allocate (rfem)
            call rfem_create(rfem, spec, err)
            if (allocated(err)) return
            call move_alloc(rfem, model)
        case ('mpp')
            allocate (mpp)
            call mpp_create(mpp, spec, err)
            if (allocated(err)) return
            call move_alloc(mpp, model)
        case default
            call make_error(err, ERR_INPUT, spec%path//': &model: kind = "'// &
                            trim(spec%model%kind)//'": not available in this version')
        end select
    end subroutine create_model

    !> The integrator a scene names.
    subroutine create_integrator(scene, integrator, err)
        type(scene_t), intent(in) :: scene
        class(integrator_t), allocatable, intent(out) :: integrator
        type(error_t), allocatable, intent(out) :: err
        call new_integrator(trim(scene%solver%method), integrator, err)
        if (allocated(err)) err%message = scene%path//': &solver: '//err%message
    end subroutine create_integrator

    pure function solver_options_of(scene) result(options)
        type(scene_t), intent(in) :: scene
        type(solver_options_t) :: options
        options%rtol = scene%solver%rtol
        options%atol = scene%solver%atol
        options%max_order = scene%solver%max_order
        options%max_steps = int(scene%solver%max_steps, i8)
        options%stab_lim_det = scene%solver%stability_limit_detection
        options%first_order_newton = scene%solver%first_order_newton
        options%profile = scene%solver%profile
    end function solver_options_of

    !> Whether the run should stop at the step just taken: a SIGINT or SIGTERM was caught
    !! (the integrators ask it after every accepted step; options%stop_requested).
    logical function stop_on_signal()
        stop_on_signal = signal_received() /= 0
    end function stop_on_signal

    !> Run a validated scene. The output file is written as the run goes; a failed
    !! integration leaves the data up to the failure and status 'failed'. No record with a
    !! NaN or Inf is ever written: a non-finite state or energy ends the run as a failed
    !! integration (ERR_SOLVER) before it reaches the file.
    !!
    !! Signals: SIGINT and SIGTERM are caught while the run integrates; the integrator stops
    !! at the end of its current step, that state is written as a last record (off the output
    !! grid when between two output times), with the counters, status 'interrupted' and a
    !! reason naming the signal and the time reached; the error is ERR_INTERRUPTED (exit
    !! 130). A second signal ends the process at once (by that signal).
    !!
    !! With `resume`, `scene%output%file` is a run file to continue (`ropedyn run --resume`,
    !! docs/output.md "Resume"): from its last record (ropedyn_run_record) to the scene's
    !! t_end, appending to the file. A last record off the output grid (where an interrupted
    !! or failed run stopped) is the starting point but is replaced by the grid records that
    !! follow, so that the file ends with the records of an uninterrupted run. The restart is
    !! recorded in /solver/restarts; the solver counters and the CPU time add up.
    !!
    !! Order safety (`&solver order_safety`, docs/stability.md): at every output time the
    !! energy monitor compares the balance with E0; a gain above `energy_gain_bound` rtol S
    !! with 'lower' takes a second look at the method's safe order (second_look), with 'stop'
    !! ends the run as a failed integration naming the gain.
    subroutine run_scene(scene, summary, err, resume)
        type(scene_t), intent(in) :: scene
        type(run_summary_t), intent(out) :: summary
        type(error_t), allocatable, intent(out) :: err
        logical, intent(in), optional :: resume
        logical :: resuming, caught
        resuming = .false.
        if (present(resume)) resuming = resume
        call integrate_scene(scene, summary, err, resuming, caught)
        if (caught) call release_signals()
    end subroutine run_scene

    !> run_scene's work; `caught`: signals are caught (to be released by the caller).
    subroutine integrate_scene(scene, summary, err, resuming, caught)
        type(scene_t), intent(in) :: scene
        type(run_summary_t), intent(out) :: summary
        type(error_t), allocatable, intent(out) :: err
        logical, intent(in) :: resuming
        logical, intent(out) :: caught
        class(rope_model_t), allocatable, target :: model
        class(integrator_t), allocatable :: integrator
        type(energy_monitor_t) :: monitor
        type(solver_stats_t) :: stats_before   ! counters of the integrators replaced
        real(wp), allocatable :: y_prev(:), yq_prev(:)
        real(wp) :: t_prev
        integer :: max_order, safe_order
        logical :: monitoring
        type(output_file_t) :: out
        type(progress_t) :: progress
        type(error_t), allocatable :: io_err
        type(solver_options_t) :: options
        type(case_data_t) :: before          ! resume: the file as it was
        real(wp), allocatable :: y(:), yq(:), q(:, :), qdot(:, :), points(:, :)
        real(wp), allocatable :: lengths(:), masses(:)
        real(wp) :: t, t0, tout, cpu_start, cpu_now, dt, t_end, t_last
        real(wp) :: clock_start, time_advance   ! &solver profile: time in advance_to, s
        real(wp) :: cpu_before                   ! resume: CPU time of the earlier parts, s
        integer(i8) :: counters_before(7)       ! resume: counters of the earlier parts
        integer :: n, k, n_out, k_first, nq, sig
        integer(i8) :: steps_mark   ! the integrator's steps at the previous record
        type(solver_stats_t) :: stats

        caught = .false.
        cpu_before = 0.0_wp
        counters_before = 0
        call create_model(scene%rope_spec_t, model, err)
        if (allocated(err)) return
        call create_integrator(scene, integrator, err)
        if (allocated(err)) return

        n = model%n_elements()
        nq = model%quad_size()
        allocate (y(model%size()), yq(max(1, nq)))
        allocate (q(3, n), qdot(3, n), points(2, 2*n), lengths(n), masses(n))
        allocate (y_prev(size(y)), yq_prev(size(yq)))
        dt = scene%solver%output_interval
        t_end = scene%solver%t_end
        n_out = max(1, ceiling(t_end/dt*(1.0_wp - 1.0e-12_wp)))
        summary%file = trim(scene%output%file)
        k_first = 1
        if (resuming) then
            call start_from_file(err)
            if (allocated(err)) return
        else
            call model%initial_state(y)
            ! &initial shape = 'equilibrium' or 'mode': statics (and modes) first
            call equilibrium_initial_state(model, scene%rope_spec_t, y, err, create_model)
            if (allocated(err)) return
            yq = 0.0_wp
            t = 0.0_wp
            ! &initial shape = 'state': a record of an earlier run (its time, state,
            ! quadratures); the output keeps that run's times (the multiples of dt after t)
            if (trim(scene%initial%shape) == 'state') then
                call state_initial_state(scene, model, t, y, yq, err)
                if (allocated(err)) return
                if (t > 0.0_wp) k_first = floor(t/dt*(1.0_wp + 1.0e-12_wp)) + 1
            end if
            summary%initial_energy = model%energy(t, y, yq)
            ! the scene's limits keep the start finite; should a value still make it not,
            ! that is bad input: say so before any file is created
            if (.not. (all(ieee_is_finite(y)) .and. &
                       ieee_is_finite(summary%initial_energy%balance()))) then
                call make_error(err, ERR_INPUT, scene%path//': the initial state or its '// &
                    'energy is not finite (energy '// &
                    real_text(summary%initial_energy%balance())//' J): a value of the '// &
                    'scene is too large or too small (docs/input.md, Limits)')
                return
            end if
            call make_parent_dirs(summary%file, err)
            if (allocated(err)) return
            call model%element_data(lengths, masses)
            call out%create(summary%file, n, lengths, masses, model%model_name(), &
                            integrator%name(), version_string, scene_namelist_text(scene), &
                            err, state_size=model%size(), quad_size=nq)
            if (allocated(err)) return
            call write_record(err)
            if (allocated(err)) return
        end if
        t0 = t
        t_last = t
        t_prev = t
        y_prev = y
        yq_prev = yq

        call cpu_time(cpu_start)
        time_advance = 0.0_wp
        options = solver_options_of(scene)
        options%stop_requested => stop_on_signal
        call catch_signals(err)
        if (allocated(err)) then
            call finish('failed', err%message)
            return
        end if
        caught = .true.
        call end_on_second_signal(.true.)
        max_order = scene%solver%max_order
        if (max_order == 0) max_order = integrator%default_max_order()
        safe_order = 0
        if (method_index(integrator%name()) > 0) &
            safe_order = METHODS(method_index(integrator%name()))%safe_order
        monitoring = trim(scene%solver%order_safety) /= 'off'
        call monitor%start(summary%initial_energy, scene%solver%rtol, &
                           scene%solver%energy_gain_bound)
        call start_integrator(err)
        if (allocated(err)) then
            call finish('failed', err%message)
            return
        end if
        call progress%start_run(t0, t_end, scene%output%progress, scene%output%progress_given)
        do k = k_first, n_out
            tout = output_time(k)
            if (scene%solver%profile) clock_start = clock_seconds()
            call integrator%advance_to(tout, t, y, yq(1:nq), err)
            if (scene%solver%profile) time_advance = time_advance + &
                                                     (clock_seconds() - clock_start)
            if (.not. allocated(err) .and. monitoring .and. t >= tout) call check_energy(tout, err)
            if (allocated(err)) then
                call progress%done()
                ! keep the last good state if the solver got past the previous record
                if (t > t_last) call write_record(io_err)
                call finish('failed', err%message)
                return
            end if
            sig = signal_received()
            if (t < tout .or. sig /= 0) then
                ! stopped at a step boundary on a signal: that state is the last record
                call progress%done()
                if (t > t_last) call write_record(err)
                if (allocated(err)) then
                    if (err%code == ERR_SOLVER) call finish('failed', err%message)
                    return
                end if
                call make_error(err, ERR_INTERRUPTED, summary%file//': interrupted by '// &
                    signal_name(max(sig, signal_received()))//' at t = '//real_text(t)// &
                    ' s of '//real_text(t_end)//' s (its last record; '//process_text()//')')
                call finish('interrupted', err%message)
                return
            end if
            call write_record(err)  ! also refreshes `stats`
            if (allocated(err)) then
                call progress%done()
                if (err%code == ERR_SOLVER) call finish('failed', err%message)
                return
            end if
            call progress%update(t, stats%steps)
        end do
        call progress%done()
        call finish('complete', '')
    contains
        !> Output time k (k = 0: the start; n_out: t_end).
        pure real(wp) function output_time(k) result(tk)
            integer, intent(in) :: k
            tk = min(real(k, wp)*dt, t_end)
            if (k >= n_out) tk = t_end
        end function output_time

        !> Resume: the last record of the file as the starting point, the file reopened
        !! (an off-grid last record cut), the restart recorded.
        subroutine start_from_file(serr)
            type(error_t), allocatable, intent(out) :: serr
            type(run_record_t) :: rec, first
            real(wp) :: tol
            integer :: keep, j
            call read_run_record(summary%file, LAST_RECORD, rec, serr)
            if (allocated(serr)) return
            call check_record_fits(rec, model%model_name(), model%size(), nq, serr)
            if (allocated(serr)) return
            call read_case_file(summary%file, before, serr)
            if (allocated(serr)) return
            if (before%status == 'running') then
                call make_error(serr, ERR_INPUT, summary%file//': status running: the run '// &
                    'may still be going on (a run that was killed outright keeps this '// &
                    'status; to continue it, set its status: h5py '// &
                    'f.attrs["status"] = "interrupted")')
                return
            end if
            tol = 1.0e-12_wp*max(abs(rec%t), dt)
            if (rec%t >= t_end - tol) then
                call make_error(serr, ERR_INPUT, summary%file//': nothing to continue: its '// &
                    'last record is at t = '//real_text(rec%t)//' s, t_end is '// &
                    real_text(t_end)//' s (status '//before%status//'; a longer run: '// &
                    '--set solver.t_end=...)')
                return
            end if
            call read_run_record(summary%file, 0, first, serr)
            if (allocated(serr)) return
            summary%initial_energy = first%energy
            t = rec%t
            y = rec%y
            yq = 0.0_wp
            yq(1:nq) = rec%yq(1:nq)
            ! the first output time after t; an off-grid last record is replaced
            k_first = n_out
            do j = 1, n_out
                if (output_time(j) > t + tol) then
                    k_first = j
                    exit
                end if
            end do
            keep = rec%records
            if (rec%record > 0 .and. abs(output_time(k_first - 1) - t) > tol) keep = keep - 1
            do j = 1, size(counters_before)
                counters_before(j) = max(0_i8, before%counters(j))
            end do
            if (ieee_is_finite(before%cpu_time)) cpu_before = before%cpu_time
            call out%reopen(summary%file, n, model%size(), nq, serr, keep=keep)
            if (allocated(serr)) return
            call out%add_restart(rec%record, t, before%status, before%reason, &
                                 counters_before(1), cpu_before, serr)
            if (allocated(serr)) return
            summary%records = keep
            summary%t_reached = t
            summary%final_energy = rec%energy
            if (keep < rec%records) write (error_unit, '(a)') 'ropedyn: '//summary%file// &
                ': continuing from t = '//real_text(t)//' s (record '// &
                int_text(rec%record)//', off the output grid: replaced by the records '// &
                'that follow)'
        end subroutine start_from_file

        !> (Re)start the integrator at (t, y, yq) with the order limit `max_order` and the
        !! step budget that the integrators before it left.
        subroutine start_integrator(ierr)
            type(error_t), allocatable, intent(out) :: ierr
            type(solver_options_t) :: options
            options = solver_options_of(scene)
            options%stop_requested => stop_on_signal
            options%max_order = max_order
            options%max_steps = max(1_i8, options%max_steps - stats_before%steps)
            call integrator%init(model, t, y, yq(1:nq), options, ierr)
            steps_mark = 0
        end subroutine start_integrator

        !> The energy monitor at the output time just reached: on a gain beyond the bound,
        !! lower the order and integrate the interval again ('lower'), or fail ('stop').
        subroutine check_energy(tout, cerr)
            real(wp), intent(in) :: tout
            type(error_t), allocatable, intent(out) :: cerr
            type(energy_t) :: e
            character(len=200) :: what
            real(wp) :: next_bound
            e = model%energy(t, y, yq)
            if (.not. ieee_is_finite(e%balance())) return   ! write_record says so
            if (.not. monitor%gained(e)) then
                call monitor%observe(e)
                steps_mark = steps_taken()
                return
            end if
            block
                type(energy_monitor_t) :: next
                next = monitor
                call next%observe(e)
                next_bound = next%bound()
                write (what, '(a, es10.3, a, es10.3, a, es12.5, a, i0)') 'energy gain ', &
                    next%gain(e), ' J above E0 (bound ', next_bound, ' J) at t = ', t, &
                    ' s, max order ', max_order
                call summary%safety%alarm(next%gain(e), next_bound)
            end block
            if (trim(scene%solver%order_safety) == 'stop') then
                stats = integrator%stats()
                call make_error(cerr, ERR_SOLVER, integrator%name()//' failed at t = '// &
                    real_text(t_prev)//' s, step size '// &
                    real_text(stats%last_step)//' s: '//trim(what)// &
                    ': the integrator created energy (&solver '// &
                    'order_safety = ''stop''; docs/stability.md)')
                t = t_prev       ! the record with the gain is not written
                y = y_prev
                yq = yq_prev
                return
            end if
            if (safe_order > 0 .and. max_order > safe_order) then
                call second_look(tout, e, next_bound, cerr)
                if (allocated(cerr)) return
            else
                call summary%safety%unresolved(t)
            end if
            call monitor%observe(e)
            steps_mark = steps_taken()
        end subroutine check_energy

        !> A gain beyond the bound at the order limit in use: the interval [t_prev, tout]
        !! again at the safe (A-stable) order by a second integrator. When the gain is the
        !! order's (high_order_to_blame: gathered over earlier intervals, or made in this
        !! one and the safe order changed the balance less), the run goes on from tout at
        !! the safe order with that integrator, for good. A gain of this interval that the
        !! safe order matches is the integration error at this tolerance: the second
        !! integrator is dropped, the run goes on as it was and the monitor counts gains
        !! from that level on (lowering on the gain alone left every_effect_mpp_n7, rtol
        !! 1e-11, at BDF2 to crawl). For such a gain the safe order has SAFE_STEPS_FACTOR
        !! times the steps of the interval; if that is not enough, no verdict: the order is
        !! kept so, once. Otherwise it has the whole budget left; its failure is the run's.
        !! e: the energies of the state the run goes on from.
        subroutine second_look(tout, e, bound, lerr)
            real(wp), intent(in) :: tout
            type(energy_t), intent(inout) :: e
            real(wp), intent(in) :: bound   !< the monitor's bound at this record, J
            type(error_t), allocatable, intent(out) :: lerr
            class(integrator_t), allocatable :: safe
            type(solver_options_t) :: safe_options
            type(error_t), allocatable :: safe_err
            real(wp) :: t_safe, y_safe(size(y)), yq_safe(size(yq)), gain_prev, change_high, &
                        change_safe
            integer(i8) :: steps_high, budget
            logical :: sudden, reached
            integer :: action
            character(len=200) :: why
            gain_prev = monitor%gain(model%energy(t_prev, y_prev, yq_prev))
            change_high = monitor%gain(e) - gain_prev
            change_safe = 0.0_wp
            steps_high = steps_taken() - steps_mark
            sudden = sudden_gain(change_high, bound)
            budget = look_budget(sudden, summary%safety%crawled, steps_high, options%max_steps - &
                                 stats_before%steps - steps_taken())
            call create_integrator(scene, safe, lerr)
            if (allocated(lerr)) return
            safe_options = solver_options_of(scene)
            safe_options%stop_requested => stop_on_signal
            safe_options%max_order = safe_order
            safe_options%max_steps = max(1_i8, budget)
            t_safe = t_prev
            y_safe = y_prev
            yq_safe = yq_prev
            call safe%init(model, t_safe, y_safe, yq_safe(1:nq), safe_options, lerr)
            if (allocated(lerr)) return
            call safe%advance_to(tout, t_safe, y_safe, yq_safe(1:nq), safe_err)
            reached = .not. allocated(safe_err) .and. t_safe >= tout
            if (reached) change_safe = monitor%gain(model%energy(t_safe, y_safe, yq_safe)) - &
                                       gain_prev
            action = look_action(reached, signal_received() /= 0, sudden, summary%safety%crawled, &
                                 high_order_to_blame(change_high, change_safe, bound))
            if (action == LOOK_LOWER .or. action == LOOK_FAIL) then
                ! on from where the safe order got, with it (its failure is the run's)
                if (action == LOOK_LOWER) call summary%safety%lowered(t_prev, max_order, &
                                                                      safe_order)
                call stats_before%add(integrator%stats())
                call integrator%finalize()
                call move_alloc(safe, integrator)
                ! the whole budget that is left, no longer the second look's
                integrator%options%max_steps = max(1_i8, options%max_steps - &
                                                   stats_before%steps)
                max_order = safe_order
                t = t_safe
                y = y_safe
                yq = yq_safe
                e = model%energy(t, y, yq)
                if (allocated(safe_err)) call move_alloc(safe_err, lerr)
                return
            end if
            if (action == LOOK_NO_VERDICT) then
                summary%safety%crawled = .true.
                write (why, '(4(a, i0), a)') 'order ', safe_order, &
                    ' did not get through the same interval in ', budget, &
                    ' steps (order ', max_order, ' took ', steps_high, '): no verdict'
            else if (reached) then
                write (why, '(a, i0, a, es10.3, a, i0, a, es10.3, a)') 'order ', safe_order, &
                    ' changed the balance by ', change_safe, ' J over the same interval, '// &
                    'order ', max_order, ' by ', change_high, ' J: the integration error '// &
                    'at this rtol'
            else
                why = 'the second look at the safe order was interrupted'
            end if
            ! on at the order asked for; gains counted from this level
            call stats_before%add(safe%stats())
            call safe%finalize()
            call summary%safety%kept(t, trim(why))
            call monitor%accept(monitor%gain(e))
        end subroutine second_look

        !> Steps of the integrator in use so far.
        integer(i8) function steps_taken()
            type(solver_stats_t) :: now
            now = integrator%stats()
            steps_taken = now%steps
        end function steps_taken

        subroutine write_record(werr)
            type(error_t), allocatable, intent(out) :: werr
            type(energy_t) :: e
            real(wp) :: h
            integer :: order
            character(len=64) :: where
            h = 0.0_wp
            order = 0
            if (allocated(integrator)) then
                stats = integrator%stats()
                call stats%add(stats_before)
                h = stats%last_step
                order = stats%last_order
            end if
            call model%fields(y, q, qdot, t)
            call model%polyline(y, points, t)
            e = model%energy(t, y, yq)
            if (.not. (all(ieee_is_finite(y)) .and. all(ieee_is_finite(yq)) .and. &
                       ieee_is_finite(e%balance()) .and. all(ieee_is_finite(points)))) then
                write (where, '(a, es12.5, a, es11.3e3, a)') 't = ', t, ' s, step size ', h, ' s'
                call make_error(werr, ERR_SOLVER, 'non-finite state or energy at '// &
                                trim(where)//' (integrator '//integrator%name()// &
                                '): not written to the output')
                return
            end if
            call out%append(t, q, qdot, points, e, h, order, werr, y=y, yq=yq)
            summary%records = summary%records + 1
            summary%final_energy = e
            summary%t_reached = t
            t_last = t
            t_prev = t
            y_prev = y
            yq_prev = yq
        end subroutine write_record

        subroutine finish(status, reason)
            character(len=*), intent(in) :: status, reason
            type(error_t), allocatable :: ferr
            call cpu_time(cpu_now)
            summary%cpu_time = cpu_before + (cpu_now - cpu_start)
            summary%stats = integrator%stats()
            call summary%stats%add(stats_before)
            summary%stats%time_advance = time_advance
            call add_counter_values(summary%stats, counters_before)
            summary%t_reached = max(summary%t_reached, t)
            call out%write_stats(summary%stats, summary%cpu_time, ferr, t_reached=t)
            summary%switches = integrator%switch_log()
            if (.not. allocated(ferr)) call out%write_switches(summary%switches, ferr)
            associate (r => summary%safety)
                if (.not. allocated(ferr)) &
                    call out%write_order_safety(r%energy_gain, r%lowered_at, r%order_before, &
                                                r%order_after, r%kept_at, r%kept_count, ferr)
            end associate
            call out%close_run(status, reason, ferr)
            if (allocated(ferr) .and. .not. allocated(err)) call move_alloc(ferr, err)
            call integrator%finalize()
        end subroutine finish
    end subroutine integrate_scene
end module ropedyn_simulation
