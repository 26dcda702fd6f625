!> One run of a scene as an object: the model, the integrator, the output file and what the
!! run has done so far, with small type-bound steps that a driver calls in order:
!!
!!     call run%open(scene, err)            ! model, integrator, start state, file, record 0
!!     call run%begin(err, stop)            ! (or open with resume = .true.: from the file)
!!     do while (.not. run%done())
!!         call run%step(outcome, err)      ! to the next output time, checked and recorded
!!         if (outcome /= STEP_RECORDED) exit
!!     end do
!!     call run%finish(status, reason, err) ! counters, switches, the file's status, closed
!!
!! A step integrates to the next output time, lets the order safety look at the energy
!! balance there (ropedyn_run_safety) and appends the record. No record with a NaN or Inf
!! is ever written: a non-finite state or energy ends the run as a failed integration
!! (ERR_SOLVER) before it reaches the file. A step that fails finishes the run as 'failed'
!! itself; a step that stops early (the integrator returned before the output time, or
!! the driver's stop query said so) writes the state it reached as the last record and
!! leaves the finishing to the driver, which knows why it stopped (a signal).
!!
!! Resume (`open` with resume, submodule ropedyn_run_resume; the rules are in the output
!! guide, "Resume"): the last record of the file is the start, the file is reopened and
!! appended to; an off-grid last record is replaced by the grid records that follow.
!!
!! The output file is guarded (`open` with guard, submodule ropedyn_run_guard; the output
!! guide, "Write, lock and resume rules"): no input of the run is its output, a lock keeps
!! a second run off the file, a file the run may not replace is refused, and a new run
!! writes FILE.part and renames it to FILE when it finishes, so that the earlier FILE stays
!! whole until then.
!!
!! Output (`open`'s output): OUTPUT_FILE, the scene's file as above (the command line);
!! OUTPUT_MEMORY, the same records into an HDF5 file in memory whose bytes `take_image`
!! hands over after `finish` (the library's whole run, that writes no file); OUTPUT_NONE,
!! no records at all: the library's simulation, which a driver moves on with `advance`
!! (submodule ropedyn_run_library, which says what of the above applies there).
module ropedyn_run
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use, intrinsic :: iso_fortran_env, only: int8
    use ropedyn_kinds, only: wp, i8
    use ropedyn_text, only: real_text, text_t, append_text
    use ropedyn_start_checks, only: far_anchor_warnings
    use ropedyn_scene_warnings, only: scene_warnings
    use ropedyn_error, only: error_t, make_error, ERR_INPUT, ERR_SOLVER
    use ropedyn_rope_model, only: rope_model_t, energy_t
    use ropedyn_support_motion, only: support_motion_t
    use ropedyn_integrator, only: integrator_t, solver_options_t, solver_stats_t, &
                                  stop_query_i, budget_left
    use ropedyn_clock, only: clock_seconds
    use ropedyn_model_factory, only: create_model
    use ropedyn_scene, only: scene_t, scene_namelist_text, scene_physics_text, recorded_source
    use ropedyn_scene_solver, only: create_integrator, solver_options_of, step_budget, &
        check_method_fits
    use ropedyn_os, only: make_parent_dirs
    use ropedyn_output, only: output_file_t, add_counter_values, COUNTER_NAMES
    use ropedyn_progress, only: progress_t
    use ropedyn_switch_log, only: switch_event_t, switch_log_t
    use ropedyn_version, only: version_string
    use ropedyn_modes, only: equilibrium_initial_state
    use ropedyn_methods, only: METHODS, method_index, resolved_max_order
    use ropedyn_energy_monitor, only: energy_monitor_t, safety_record_t, loss_warning
    use ropedyn_state_start, only: state_initial_state
    use ropedyn_process, only: heartbeat_t
    use ropedyn_sweep_lock, only: lock_t
    implicit none
    private
    public :: run_t, run_summary_t, run_snapshot_t, STEP_RECORDED, STEP_STOPPED, STEP_FAILED
    public :: OUTPUT_FILE, OUTPUT_MEMORY, OUTPUT_NONE

    !> Where the records go (`open`'s output; see the module header).
    integer, parameter :: OUTPUT_FILE = 0, OUTPUT_MEMORY = 1, OUTPUT_NONE = 2

    !> What `step` did: recorded the next output time; stopped early (the last record is
    !! the state reached; the driver finishes); failed (`err`; finished unless the error is
    !! the output's).
    integer, parameter :: STEP_RECORDED = 0, STEP_STOPPED = 1, STEP_FAILED = 2

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
        type(safety_record_t) :: safety    !< what the order safety did
        !> m g L: the rope's weight (with its point masses) times its length, the unit in
        !! which the summary states the energy balance; 0 without gravity, J
        real(wp) :: weight_length = 0.0_wp
        !> the peak tension: the largest axial force of all records and joints (N), its
        !! joint (0 the top end; -1 before the first record), the joint's arc length from
        !! the top along the unstretched rope (m) and the record's time (s)
        real(wp) :: peak_tension = 0.0_wp, peak_arc = 0.0_wp, peak_time = 0.0_wp
        integer :: peak_joint = -1
        !> the integration ended for its step budget (solver.max_steps, spent or foreseen
        !! short): the steps the rest of the run takes at its last step (a resume goes on
        !! from the last record with a budget of its own); 0 otherwise
        integer(i8) :: budget_rest = 0
        !> a line carrying tension only that passed through itself: the first record's time
        !! at which it had (note_turned_back; its warning is in `warnings`), s; -1 if none
        real(wp) :: passed_through = -1.0_wp
        !> the run's own warnings, one line each: what the initial state does against the
        !! scene (ropedyn_start_checks: a held end far from its anchor) and a loss of a tenth
        !! of the energy the motion took in (the energy monitor's `lost`, with the order
        !! safety on); the summary prints them, and the file keeps them in /solver/warnings
        !! after the scene's own
        type(text_t), allocatable :: warnings(:)
    end type run_summary_t

    !> Where a line that carries tension only passed through itself (note_turned_back): the
    !! worst body (0: none), how far, in its lengths, and when; the time it first happened.
    type :: turned_back_t
        integer :: body = 0
        real(wp) :: share = 0.0_wp, at = 0.0_wp, first = 0.0_wp
    end type turned_back_t

    !> A state of a run without output kept in memory (`save`, `restore`): time, ODE state,
    !! quadratures, the supports' motions and the prescriptions for the next advance.
    type :: run_snapshot_t
        private
        logical :: valid = .false.
        real(wp) :: t = 0.0_wp
        real(wp), allocatable :: y(:), yq(:)
        type(support_motion_t) :: motion(2)
        real(wp) :: target_p(2, 2) = 0.0_wp, target_v(2, 2) = 0.0_wp
        logical :: target_given(2) = .false.
        !> the scene's rope and surroundings (scene_physics_text): a restore into a
        !! simulation of another rope of the same size is refused
        character(len=:), allocatable :: physics
    end type run_snapshot_t

    !> A run of one scene (see the module header for the order of the steps).
    type :: run_t
        private
        type(scene_t) :: scene
        class(rope_model_t), allocatable :: model
        class(integrator_t), allocatable :: integrator
        type(output_file_t) :: out
        type(progress_t) :: progress
        type(energy_monitor_t) :: monitor
        type(run_summary_t), public :: summary
        !> the counters and switches of integrators replaced by the order safety (a
        !! second look's lower order, auto's rescue)
        type(solver_stats_t) :: stats_before
        type(switch_log_t) :: switches_before
        !> auto went on with MEBDF at its safe order after a runaway (once per run)
        logical :: rescued = .false.
        !> the run goes on from its file (`open` with resume): its start, and the scene's
        !! warnings, are the earlier part's
        logical :: resumed = .false.
        !> resume: the counters (COUNTER_NAMES; one a file lacks counts 0) and CPU time (s)
        !! of the earlier parts of the run
        integer(i8) :: counters_before(size(COUNTER_NAMES)) = 0
        real(wp) :: cpu_before = 0.0_wp
        real(wp) :: cpu_start = 0.0_wp      !< CPU clock at `begin`, s
        !> the integration has begun: its counters are kept for the file's flushes
        logical :: counting = .false.
        real(wp) :: time_advance = 0.0_wp   !< &solver profile: time in advance_to, s
        integer(i8) :: steps_now = 0        !< steps of the run at the last record
        ! the state: time (s), ODE state and quadratures; at the previous record too
        real(wp) :: t = 0.0_wp, t_prev = 0.0_wp, t_last = 0.0_wp
        real(wp), allocatable :: y(:), yq(:), y_prev(:), yq_prev(:)
        ! work arrays of a record: element fields, the polyline, the internal forces at the
        ! joints (0:n), the supports' reactions and anchors (2, 2)
        real(wp), allocatable :: q(:, :), qdot(:, :), points(:, :)
        real(wp), allocatable :: axial(:), shear(:), moment(:)
        real(wp) :: reaction(2, 2) = 0.0_wp, anchors(2, 2) = 0.0_wp
        integer :: nq = 0                   !< quadratures of the model
        !> a line carrying tension only that passed through itself (note_turned_back)
        type(turned_back_t) :: turned_back
        ! the output grid: every dt up to t_end, records 0 .. n_out; the next is k_next
        real(wp) :: dt = 1.0_wp, t_end = 0.0_wp
        integer :: n_out = 1, k_next = 1
        ! the order safety: the order limit in use, the method's safe one, the steps of
        ! the integrator in use at the previous record
        integer :: max_order = 0, safe_order = 0
        logical :: monitoring = .false.
        integer(i8) :: steps_mark = 0
        procedure(stop_query_i), pointer, nopass :: stop_requested => null()
        ! the guard of the output file: the lock held ('' none), and for a new run the
        ! file written (FILE.part) and its final name
        character(len=:), allocatable :: lock_file, part_file, final_file
        !> the scene's rope and surroundings (scene_physics_text), made at the first save or
        !! restore: the scene does not change after open
        character(len=:), allocatable :: physics
        !> a resume: why the writer of the file is gone, from its abandoned lock ('': no
        !! lock of it was there); said when the file's status is still `running`
        character(len=:), allocatable :: writer_gone
        !> a resume: the abandoned lock it took over (exists false: none), handed back when
        !! the resume is refused, so that the lock goes on naming the killed writer
        type(lock_t) :: taken_over
        !> FILE (final_file) is checked again before FILE.part is renamed over it: a file put
        !! there while the run went on is replaced only if the run may replace it (no --force)
        logical :: recheck_final = .false.
        type(heartbeat_t) :: beat                 !< the lock's heartbeat
        integer :: output = OUTPUT_FILE        !< where the records go
        integer(int8), allocatable :: image(:) !< OUTPUT_MEMORY: the file's bytes at its end
        !> OUTPUT_NONE: the position (m) and velocity (m/s) prescribed for each coupled
        !! support at the next `advance` (columns 1 top, 2 bottom), and which are given
        real(wp) :: target_p(2, 2) = 0.0_wp, target_v(2, 2) = 0.0_wp
        logical :: target_given(2) = .false.
    contains
        procedure :: open => run_open
        procedure :: begin => run_begin
        procedure :: step => run_step
        procedure :: finish => run_finish
        procedure :: done => run_done
        procedure :: time => run_time
        procedure :: end_time => run_end_time
        procedure :: output_file => run_output_file
        procedure :: final_file_name => run_final_file_name
        procedure :: take_image => run_take_image
        procedure :: release => run_release
        procedure :: advance => run_advance
        procedure :: state_size => run_state_size
        procedure :: elements => run_elements
        procedure :: get_state => run_get_state
        procedure :: set_state => run_set_state
        procedure :: points_now => run_points_now
        procedure :: forces_now => run_forces_now
        procedure :: energy_now => run_energy_now
        procedure :: anchors_now => run_anchors_now
        procedure :: set_support => run_set_support
        procedure :: save => run_save
        procedure :: restore => run_restore
        procedure, private :: restart
        procedure, private :: fresh_start, output_time, start_integrator, record, &
                              integrator_options, &
                              steps_taken, keep_as_previous, asked_to_stop, end_on, &
                              start_monitor
        procedure, private :: note_turned_back, turned_back_warning
        procedure, private :: resume_from_file, check_energy, second_look, note_peak, &
                              fail_runaway, rescue, retire_integrator, keep_switches
        procedure, private :: guard_output, release_output, hand_back, file_warnings
        procedure, private :: counters_so_far => run_counters_so_far, &
                              cpu_so_far => run_cpu_so_far
    end type run_t

    interface
        !> Guard the output file before anything is written (submodule ropedyn_run_guard):
        !! refuse an input as output, take its lock, refuse a file not to be replaced
        !! (unless `force`) or left by a killed run; a new run then writes FILE.part.
        module subroutine guard_output(self, resume, force, err)
            class(run_t), intent(inout) :: self
            logical, intent(in) :: resume, force
            type(error_t), allocatable, intent(out) :: err
        end subroutine guard_output

        !> Give the guarded file its final name (a new run: FILE.part -> FILE) and drop the
        !! lock; an error of the rename goes into `err` unless it holds one.
        module subroutine release_output(self, err)
            class(run_t), intent(inout) :: self
            type(error_t), allocatable, intent(inout) :: err
        end subroutine release_output

        !> A refused resume: the abandoned lock it took over goes back to its killed writer
        !! (naming it still; the lock is then not the run's to drop).
        module subroutine hand_back(self)
            class(run_t), intent(inout) :: self
        end subroutine hand_back

        !> Resume: the last record of the run file as the starting point, the file reopened
        !! (an off-grid last record cut), the restart recorded (submodule
        !! ropedyn_run_resume).
        module subroutine resume_from_file(self, err)
            class(run_t), intent(inout) :: self
            type(error_t), allocatable, intent(out) :: err
        end subroutine resume_from_file

        !> The order safety at the output time just reached (submodule ropedyn_run_safety);
        !! e_now: the energy of the state it leaves, when it did not change it (for the
        !! record: one evaluation of the energy per record).
        module subroutine check_energy(self, tout, err, e_now)
            class(run_t), intent(inout) :: self
            real(wp), intent(in) :: tout
            type(error_t), allocatable, intent(out) :: err
            type(energy_t), allocatable, intent(out) :: e_now
        end subroutine check_energy

        !> The run's error at a runaway of state e (the energy monitor), the state back at
        !! the previous one looked at (submodule ropedyn_run_safety).
        module subroutine fail_runaway(self, e, err)
            class(run_t), intent(inout) :: self
            type(energy_t), intent(in) :: e
            type(error_t), allocatable, intent(out) :: err
        end subroutine fail_runaway

        !> OUTPUT_NONE: integrate to time t (s) > the current time, where the coupled
        !! supports are at the position and velocity prescribed by `set_support` (submodule
        !! ropedyn_run_library). A failure leaves the last good state.
        module subroutine run_advance(self, t, err)
            class(run_t), intent(inout) :: self
            real(wp), intent(in) :: t
            type(error_t), allocatable, intent(out) :: err
        end subroutine run_advance

        !> Unknowns of the ODE state (the model's; its layout: docs/reference/file-format.md,
        !! /state/y).
        pure module integer function run_state_size(self)
            class(run_t), intent(in) :: self
        end function run_state_size

        !> Elements (RFEM) or members (MPP) of the rope.
        pure module integer function run_elements(self)
            class(run_t), intent(in) :: self
        end function run_elements

        !> The ODE state now.
        module subroutine run_get_state(self, y)
            class(run_t), intent(in) :: self
            real(wp), intent(out) :: y(:)
        end subroutine run_get_state

        !> Replace the ODE state at the current time (finite values, the model's size); the
        !! integrator starts again from it.
        module subroutine run_set_state(self, y, err)
            class(run_t), intent(inout) :: self
            real(wp), intent(in) :: y(:)
            type(error_t), allocatable, intent(out) :: err
        end subroutine run_set_state

        !> The polyline now: end points A_1, B_1, A_2, ... (2, 2 n), m.
        module subroutine run_points_now(self, points)
            class(run_t), intent(in) :: self
            real(wp), intent(out) :: points(:, :)
        end subroutine run_points_now

        !> The internal forces at the joints 0 .. n and the supports' reactions (2, 2) now
        !! (rope_model_t%internal_forces).
        module subroutine run_forces_now(self, axial, shear, moment, reaction)
            class(run_t), intent(inout) :: self
            real(wp), intent(out) :: axial(0:), shear(0:), moment(0:), reaction(:, :)
        end subroutine run_forces_now

        !> The energies now.
        module subroutine run_energy_now(self, e)
            class(run_t), intent(inout) :: self
            type(energy_t), intent(out) :: e
        end subroutine run_energy_now

        !> The supports' anchors now (2, 2): columns top, bottom; NaN for a free end.
        module subroutine run_anchors_now(self, anchors)
            class(run_t), intent(in) :: self
            real(wp), intent(out) :: anchors(:, :)
        end subroutine run_anchors_now

        !> Prescribe the position p (m) and velocity v (m/s) of support k (1 top, 2
        !! bottom), a coupled one, at the time of the next `advance`.
        module subroutine run_set_support(self, k, p, v, err)
            class(run_t), intent(inout) :: self
            integer, intent(in) :: k
            real(wp), intent(in) :: p(2), v(2)
            type(error_t), allocatable, intent(out) :: err
        end subroutine run_set_support

        !> Keep the state now in `snap`; the integrator starts again from it, so that the
        !! run goes on from here as it will after `restore`.
        module subroutine run_save(self, snap, err)
            class(run_t), intent(inout) :: self
            type(run_snapshot_t), intent(out) :: snap
            type(error_t), allocatable, intent(out) :: err
        end subroutine run_save

        !> Go back to the state kept in `snap` (by `save` of this run); the integrator
        !! starts again from it.
        module subroutine run_restore(self, snap, err)
            class(run_t), intent(inout) :: self
            type(run_snapshot_t), intent(in) :: snap
            type(error_t), allocatable, intent(out) :: err
        end subroutine run_restore

        !> The integrator started again at the run's state (its counters kept).
        module subroutine restart(self, err)
            class(run_t), intent(inout) :: self
            type(error_t), allocatable, intent(out) :: err
        end subroutine restart

        !> The second look of the order safety (submodule ropedyn_run_safety).
        module subroutine second_look(self, tout, e, bound, err)
            class(run_t), intent(inout) :: self
            real(wp), intent(in) :: tout
            type(energy_t), intent(inout) :: e
            real(wp), intent(in) :: bound
            type(error_t), allocatable, intent(out) :: err
        end subroutine second_look

        !> auto's rescue at a runaway (submodule ropedyn_run_safety): the interval again
        !! with MEBDF at its safe order, and on with it; e: the state the run goes on from.
        module subroutine rescue(self, tout, e, err)
            class(run_t), intent(inout) :: self
            real(wp), intent(in) :: tout
            type(energy_t), intent(inout) :: e
            type(error_t), allocatable, intent(out) :: err
        end subroutine rescue

        !> The integrator in use replaced by `next`: its counters and switches kept for the
        !! run's summary (submodule ropedyn_run_safety).
        module subroutine retire_integrator(self, next)
            class(run_t), intent(inout) :: self
            class(integrator_t), allocatable, intent(inout) :: next
        end subroutine retire_integrator

        !> The switches of the integrator in use appended to those kept (its switch log
        !! emptied into the run's; submodule ropedyn_run_safety).
        module subroutine keep_switches(self)
            class(run_t), intent(inout) :: self
        end subroutine keep_switches
    end interface

contains

    !> Build the run of a validated scene: its model and integrator, the start (the
    !! scene's initial state, or with `resume` the last record of the run file
    !! scene%output%file) and the output file with its first record. A failure before the
    !! file exists leaves none; a failure after it is the caller's to finish. With `guard`
    !! (the default) the output file is guarded; `force` lets a run replace a file it would
    !! otherwise refuse (not an input, not a locked or special file).
    subroutine run_open(self, scene, err, resume, guard, force, output, name)
        class(run_t), intent(inout) :: self
        type(scene_t), intent(in) :: scene
        type(error_t), allocatable, intent(out) :: err
        logical, intent(in), optional :: resume, guard, force
        !> OUTPUT_FILE (the default), OUTPUT_MEMORY or OUTPUT_NONE; a run without a file
        !! neither resumes nor guards one. OUTPUT_MEMORY: `name` names the file in memory,
        !! unique among the files open in the process.
        integer, intent(in), optional :: output
        character(len=*), intent(in), optional :: name
        logical :: resuming, guarding, forced
        resuming = .false.
        if (present(resume)) resuming = resume
        guarding = .true.
        if (present(guard)) guarding = guard
        forced = .false.
        if (present(force)) forced = force
        self%output = OUTPUT_FILE
        if (present(output)) self%output = output
        self%scene = scene
        self%summary%file = trim(scene%output%file)
        if (self%output /= OUTPUT_FILE) then
            resuming = .false.
            guarding = .false.
            self%summary%file = ''
            if (present(name) .and. self%output == OUTPUT_MEMORY) self%summary%file = name
        end if
        ! the model and the integrator, and a method that cannot integrate the model is
        ! bad input: said before the guard touches the output's directory
        call create_model(scene%rope_spec_t, self%model, err)
        if (allocated(err)) return
        call create_integrator(scene, self%integrator, err)
        if (allocated(err)) return
        call check_method_fits(scene, self%integrator, self%model, err)
        if (allocated(err)) return
        if (guarding) then
            call self%guard_output(resuming, forced, err)
            if (allocated(err)) return
        end if
        call start_from(self, resuming, err)
        if (allocated(err) .and. guarding) then
            ! (a refused resume leaves its file where it is: no FILE.part renamed to FILE,
            ! and the abandoned lock it took over to its killed writer)
            if (resuming) then
                self%part_file = ''
                call self%hand_back()
            end if
            call self%release_output(err)
        end if
    end subroutine run_open

    !> open's work after the guard: the arrays of the model made before it, the start.
    subroutine start_from(self, resuming, err)
        class(run_t), intent(inout) :: self
        logical, intent(in) :: resuming
        type(error_t), allocatable, intent(out) :: err
        integer :: n
        associate (scene => self%scene)
        n = self%model%n_elements()
        self%nq = self%model%quad_size()
        self%summary%weight_length = weight_length(scene, self%model)
        allocate (self%y(self%model%size()), self%yq(max(1, self%nq)))
        allocate (self%q(3, n), self%qdot(3, n), self%points(2, 2*n))
        allocate (self%axial(0:n), self%shear(0:n), self%moment(0:n))
        self%dt = scene%solver%output_interval
        self%t_end = scene%solver%t_end
        self%n_out = max(1, ceiling(self%t_end/self%dt*(1.0_wp - 1.0e-12_wp)))
        self%k_next = 1
        end associate
        self%resumed = resuming
        if (resuming) then
            call self%resume_from_file(err)
        else
            call self%fresh_start(err)
        end if
        ! the start is the first state looked back to (a library simulation, which records
        ! nothing, has no other before its first look)
        if (.not. allocated(err)) call self%keep_as_previous()
    end subroutine start_from

    !> The scene's start: the initial state (statics and modes first for 'equilibrium' and
    !! 'mode'; a record of an earlier run for 'state', whose output times it keeps), checked
    !! finite; then the output file and record 0.
    subroutine fresh_start(self, err)
        class(run_t), intent(inout) :: self
        type(error_t), allocatable, intent(out) :: err
        real(wp), allocatable :: lengths(:), masses(:)
        type(text_t), allocatable :: start_notes(:)
        integer :: k
        associate (scene => self%scene, model => self%model)
            call model%initial_state(self%y)
            call equilibrium_initial_state(model, scene%rope_spec_t, self%y, err, start_notes)
            if (allocated(err)) return
            self%yq = 0.0_wp
            self%t = 0.0_wp
            if (trim(scene%initial%shape) == 'state') then
                call state_initial_state(scene, model, self%t, self%y, self%yq, err)
                if (allocated(err)) return
                if (self%t > 0.0_wp) &
                    self%k_next = floor(self%t/self%dt*(1.0_wp + 1.0e-12_wp)) + 1
            end if
            self%summary%initial_energy = model%energy(self%t, self%y, self%yq)
            self%summary%warnings = far_anchor_warnings(scene, model, self%t, self%y, &
                self%summary%initial_energy, self%summary%weight_length)
            do k = 1, size(start_notes)
                call append_text(self%summary%warnings, start_notes(k)%s)
            end do
            ! the scene's limits keep the start finite; should a value still make it not,
            ! that is bad input: say so before any file is created
            if (.not. (all(ieee_is_finite(self%y)) .and. &
                       ieee_is_finite(self%summary%initial_energy%balance()))) then
                call make_error(err, ERR_INPUT, scene%path//': the initial state or its '// &
                    'energy is not finite (energy '// &
                    real_text(self%summary%initial_energy%balance())//' J): a value of '// &
                    'the scene is too large or too small (docs/reference/scene-file.md, Limits)')
                return
            end if
            if (self%output == OUTPUT_NONE) then
                call model%support_positions(self%t, self%anchors)
                return
            end if
            if (self%output == OUTPUT_FILE) call make_parent_dirs(self%summary%file, err)
            if (allocated(err)) return
            allocate (lengths(model%n_elements()), masses(model%n_elements()))
            call model%element_data(lengths, masses)
            ! a free end has no anchor (NaN): the file has no position series for it
            call model%support_positions(self%t, self%anchors)
            call self%out%create(self%summary%file, model%n_elements(), lengths, masses, &
                                 model%model_name(), self%integrator%name(), &
                                 version_string, scene_namelist_text(scene), err, &
                                 state_size=model%size(), quad_size=self%nq, &
                                 source=recorded_source(scene), internal_forces=.true., &
                                 anchored=ieee_is_finite(self%anchors(1, :)), &
                                 memory=self%output == OUTPUT_MEMORY)
            if (allocated(err)) return
        end associate
        call self%record(err)
    end subroutine fresh_start

    !> Start integrating (after `open`): the CPU clock, the order safety's monitor and
    !! limits, the integrator at the start state, the progress display. `stop`, when
    !! given, is asked after every step (a signal caught by the driver, say): when it says
    !! so, `step` stops there. A failure here is the caller's to finish.
    subroutine run_begin(self, err, stop)
        class(run_t), intent(inout) :: self
        type(error_t), allocatable, intent(out) :: err
        procedure(stop_query_i), optional :: stop
        call cpu_time(self%cpu_start)
        self%time_advance = 0.0_wp
        if (present(stop)) self%stop_requested => stop
        self%max_order = resolved_max_order(self%integrator%name(), &
                                            self%scene%solver%max_order)
        self%safe_order = 0
        self%rescued = .false.
        call self%switches_before%clear()
        if (method_index(self%integrator%name()) > 0) &
            self%safe_order = METHODS(method_index(self%integrator%name()))%safe_order
        self%monitoring = trim(self%scene%solver%order_safety) /= 'off'
        call self%start_monitor(self%summary%initial_energy)
        call self%start_integrator(err)
        if (allocated(err)) return
        self%counting = .true.
        ! no progress display without a file: the caller's own loop is the run
        if (self%output == OUTPUT_FILE) &
            call self%progress%start_run(self%t, self%t_end, self%scene%output%progress, &
                                         self%scene%output%progress_given)
    end subroutine run_begin

    !> (Re)start the integrator at the run's state with the order limit `max_order` and the
    !! step budget that the integrators before it left.
    subroutine start_integrator(self, err)
        class(run_t), intent(inout) :: self
        type(error_t), allocatable, intent(out) :: err
        type(solver_options_t) :: options
        options = self%integrator_options(self%stats_before%steps)
        options%max_order = self%max_order
        call self%integrator%init(self%model, self%t, self%y, self%yq(1:self%nq), options, err)
        self%steps_mark = 0
    end subroutine start_integrator

    !> The scene's solver options for an integrator of this run that starts after `used`
    !! steps counted against the run's budget (what is left of it, and the whole budget
    !! and the steps before for its messages: budget_left), stopping when the driver asks;
    !! a run without output (the library's simulation) is driven by its caller.
    function integrator_options(self, used) result(options)
        class(run_t), intent(in) :: self
        integer(i8), intent(in) :: used
        type(solver_options_t) :: options
        options = budget_left(solver_options_of(self%scene), used)
        options%stop_requested => self%stop_requested
        options%driven = self%output == OUTPUT_NONE
    end function integrator_options

    !> Integrate to the next output time, let the order safety look, and record it (see
    !! the module header for the outcomes).
    subroutine run_step(self, outcome, err)
        class(run_t), intent(inout) :: self
        integer, intent(out) :: outcome
        type(error_t), allocatable, intent(out) :: err
        type(error_t), allocatable :: io_err
        type(energy_t), allocatable :: e_now
        real(wp) :: tout, clock_start
        tout = self%output_time(self%k_next)
        outcome = STEP_FAILED
        if (self%scene%solver%profile) clock_start = clock_seconds()
        call self%integrator%advance_to(tout, self%t, self%y, self%yq(1:self%nq), err)
        if (self%scene%solver%profile) &
            self%time_advance = self%time_advance + (clock_seconds() - clock_start)
        if (.not. allocated(err) .and. self%monitoring .and. self%t >= tout) &
            call self%check_energy(tout, err, e_now)
        if (allocated(err)) then
            call self%progress%done()
            self%summary%budget_rest = self%integrator%budget_shortfall(self%t)
            ! keep the last good state if the solver got past the previous record
            if (self%t > self%t_last) call self%record(io_err)
            call self%finish('failed', (err%message), err)
            return
        end if
        if (self%t < tout .or. self%asked_to_stop()) then
            ! stopped at a step boundary: that state is the last record
            call self%progress%done()
            if (self%t > self%t_last) call self%record(err, e_now)
            if (allocated(err)) then
                call self%end_on(err)
                return
            end if
            outcome = STEP_STOPPED
            return
        end if
        call self%record(err, e_now)
        if (allocated(err)) then
            call self%progress%done()
            call self%end_on(err)
            return
        end if
        outcome = STEP_RECORDED
        self%k_next = self%k_next + 1
        call self%progress%update(self%t, self%steps_now)
    end subroutine run_step

    !> Append the state at t to the file (after checking it is finite) and make it the
    !! previous record; e_now: its energy when already computed (absent or not allocated:
    !! computed here).
    subroutine record(self, err, e_now)
        class(run_t), intent(inout) :: self
        type(error_t), allocatable, intent(out) :: err
        type(energy_t), allocatable, intent(in), optional :: e_now
        logical :: have_e
        type(solver_stats_t) :: stats
        type(energy_t) :: e
        real(wp) :: h
        integer :: order
        character(len=64) :: where
        stats = self%integrator%stats()
        call stats%add(self%stats_before)
        h = stats%last_step
        order = stats%last_order
        self%steps_now = stats%steps
        call self%model%fields(self%y, self%q, self%qdot, self%t)
        call self%model%polyline(self%y, self%points, self%t)
        call self%model%internal_forces(self%t, self%y, self%axial, self%shear, self%moment, &
                                        self%reaction)
        call self%model%support_positions(self%t, self%anchors)
        have_e = .false.
        if (present(e_now)) have_e = allocated(e_now)
        if (have_e) then
            e = e_now
        else
            e = self%model%energy(self%t, self%y, self%yq)
        end if
        if (.not. (all(ieee_is_finite(self%y)) .and. all(ieee_is_finite(self%yq)) .and. &
                   ieee_is_finite(e%balance()) .and. all(ieee_is_finite(self%points)) .and. &
                   all(ieee_is_finite(self%axial)) .and. all(ieee_is_finite(self%shear)) .and. &
                   all(ieee_is_finite(self%moment)) .and. all(ieee_is_finite(self%reaction)))) then
            write (where, '(a, es12.5, a, es11.3e3, a)') 't = ', self%t, ' s, step size ', &
                h, ' s'
            call make_error(err, ERR_SOLVER, 'non-finite state or energy at '// &
                            trim(where)//' (integrator '//self%integrator%name()// &
                            '): not written to the output')
            return
        end if
        if (self%model%tension_only) call self%note_turned_back()
        ! the counters so far go with the records the next flush writes (a killed run's
        ! file then holds them as of its last flush)
        if (self%output /= OUTPUT_NONE .and. self%counting) then
            if (self%out%flush_due()) call self%out%keep_counters(self%counters_so_far(), &
                                                                   self%cpu_so_far())
        end if
        if (self%output /= OUTPUT_NONE) &
            call self%out%append(self%t, self%q, self%qdot, self%points, e, h, order, err, &
                                 y=self%y, yq=self%yq, axial=self%axial, shear=self%shear, &
                                 moment=self%moment, reaction=self%reaction, &
                                 position=self%anchors)
        if (allocated(err)) return
        call self%note_peak(self%t, maxval(self%axial), maxloc(self%axial, 1) - 1)
        self%summary%records = self%summary%records + 1
        self%summary%final_energy = e
        self%summary%t_reached = self%t
        call self%keep_as_previous()
    end subroutine record

    !> A line that carries tension only has no axial spring where it is slack, so nothing
    !! stops two neighbours from sliding past each other where it folds back on itself or
    !! whips slack (docs/guide/scenes.md, "A chain cannot push"). Keeps the record's worst
    !! body whose successor starts more than twice the body's length behind it
    !! (line_turned_back), and the time it first happened, for turned_back_warning.
    subroutine note_turned_back(self)
        class(run_t), intent(inout) :: self
        real(wp) :: lengths(self%model%n_elements()), masses(self%model%n_elements())
        integer :: k
        real(wp) :: share
        call self%model%element_data(lengths, masses)
        call line_turned_back(self%q, self%points, lengths, k, share)
        if (k == 0) return
        associate (b => self%turned_back)
            if (b%body == 0) b%first = self%t
            if (b%body == 0 .or. share > b%share) then
                b%body = k
                b%share = share
                b%at = self%t
            end if
        end associate
    end subroutine note_turned_back

    !> The warning of a line whose bodies slid past each other (note_turned_back).
    function turned_back_warning(self, model_name) result(text)
        use ropedyn_text, only: int_text
        class(run_t), intent(in) :: self
        character(len=*), intent(in) :: model_name
        character(len=:), allocatable :: text, what
        character(len=12) :: by, first, at
        associate (b => self%turned_back)
            write (by, '(f12.1)') b%share
            write (first, '(f12.3)') b%first
            write (at, '(f12.3)') b%at
            if (model_name == 'mpp') then
                what = 'member '//int_text(b%body)//' turned inside out'
            else
                what = 'element '//int_text(b%body + 1)//' slid past element '// &
                       int_text(b%body)
            end if
            text = 'the line passed through itself from t = '//trim(adjustl(first))// &
                   ' s on: '//what//' by up to '//trim(adjustl(by))//' times its length (t = '// &
                   trim(adjustl(at))//' s). A line that carries tension only '// &
                   '(&rope compression = .false.) has no axial spring where it is slack, '// &
                   'so where it folds back on itself or whips slack its bodies can slide '// &
                   'past each other, and a line torn open so lets its end fall through; '// &
                   'the records from then on are not physical. Give the line some '// &
                   'axial_damping (its dampers act while it is slack too), or let it push '// &
                   '(compression = .true.)'
        end associate
    end function turned_back_warning

    !> The body k (element or member) of the fields q (3, n) and polyline points (2, 2 n)
    !! whose successor starts furthest behind it, along = e_k . (A_{k+1} - A_k) with
    !! A_{n+1} = B_n, when that is more than twice its length (lengths, m) behind: share =
    !! -along/length > 2; k = 0 where there is none. On the RFEM: a joint that overlaps
    !! the element before it and more; on the MPP: a member turned inside out beyond its
    !! own length. A slack chain's joints overlap a little: the chain of
    !! tests/e2e/test_tension_only.py shaken slack reaches a share of 1.3.
    pure subroutine line_turned_back(q, points, lengths, k, share)
        real(wp), intent(in) :: q(:, :), points(:, :), lengths(:)
        integer, intent(out) :: k
        real(wp), intent(out) :: share
        integer :: n, j
        real(wp) :: a_next(2), along
        n = size(q, 2)
        k = 0
        share = 2.0_wp
        do j = 1, n
            a_next = points(:, min(2*j + 1, 2*n))
            along = cos(q(3, j))*(a_next(1) - points(1, 2*j - 1)) + &
                    sin(q(3, j))*(a_next(2) - points(2, 2*j - 1))
            if (-along > share*lengths(j)) then
                k = j
                share = -along/lengths(j)
            end if
        end do
    end subroutine line_turned_back

    !> End the run on an error of `record`: a failed integration finishes it as 'failed';
    !! an error of the file (which the io layer has closed and marked failed) only releases
    !! the guarded output.
    subroutine end_on(self, err)
        class(run_t), intent(inout) :: self
        type(error_t), allocatable, intent(inout) :: err
        if (err%code == ERR_SOLVER) then
            call self%finish('failed', (err%message), err)
        else
            call self%release_output(err)
        end if
    end subroutine end_on

    !> Keep `tension` (N), the largest axial force of a record at time t (s), at joint
    !! `joint` (0 the top end), as the peak tension when it exceeds the one so far.
    subroutine note_peak(self, t, tension, joint)
        class(run_t), intent(inout) :: self
        real(wp), intent(in) :: t, tension
        integer, intent(in) :: joint
        real(wp) :: lengths(self%model%n_elements()), masses(self%model%n_elements())
        associate (s => self%summary)
            if (s%peak_joint >= 0 .and. .not. tension > s%peak_tension) return
            call self%model%element_data(lengths, masses)
            s%peak_tension = tension
            s%peak_joint = joint
            s%peak_arc = sum(lengths(1:joint))
            s%peak_time = t
        end associate
    end subroutine note_peak

    !> The energy monitor from the energies e of the state now (its E0), with the scene's
    !! tolerance and bound and the rope's m g L.
    subroutine start_monitor(self, e)
        class(run_t), intent(inout) :: self
        type(energy_t), intent(in) :: e
        call self%monitor%start(e, self%scene%solver%rtol, self%scene%solver%energy_gain_bound, &
                                self%summary%weight_length)
    end subroutine start_monitor

    !> The state now is the previous record's (where the order safety looks back to; in a
    !! library simulation, the runaway rule's last look).
    subroutine keep_as_previous(self)
        class(run_t), intent(inout) :: self
        self%t_last = self%t
        self%t_prev = self%t
        self%y_prev = self%y
        self%yq_prev = self%yq
    end subroutine keep_as_previous

    !> Whether the driver's stop query says stop.
    logical function asked_to_stop(self)
        class(run_t), intent(in) :: self
        asked_to_stop = .false.
        if (associated(self%stop_requested)) asked_to_stop = self%stop_requested()
    end function asked_to_stop

    !> The run's counters so far, over its integrators and the earlier parts of a resumed
    !! run (as the file's /solver holds them), with the time spent in `advance`.
    function run_counters_so_far(self) result(stats)
        class(run_t), intent(in) :: self
        type(solver_stats_t) :: stats
        stats = self%integrator%stats()
        call stats%add(self%stats_before)
        stats%time_advance = self%time_advance
        call add_counter_values(stats, self%counters_before)
    end function run_counters_so_far

    !> The run's CPU time so far, s, with that of the earlier parts of a resumed run.
    real(wp) function run_cpu_so_far(self) result(cpu)
        class(run_t), intent(in) :: self
        real(wp) :: now
        call cpu_time(now)
        cpu = self%cpu_before + (now - self%cpu_start)
    end function run_cpu_so_far

    !> End the run: the summary's counters and CPU time, the solver's statistics, switches
    !! and order safety into the file, its status and reason, the file closed. An error of
    !! the file goes into `err` unless it already holds one.
    subroutine run_finish(self, status, reason, err)
        class(run_t), intent(inout) :: self
        character(len=*), intent(in) :: status, reason
        type(error_t), allocatable, intent(inout) :: err
        type(error_t), allocatable :: ferr
        real(wp) :: cpu_now
        call self%progress%done()
        call cpu_time(cpu_now)
        if (self%output == OUTPUT_NONE) then
            ! no file: the counters only
            self%summary%cpu_time = self%cpu_before + (cpu_now - self%cpu_start)
            self%summary%stats = self%integrator%stats()
            call self%summary%stats%add(self%stats_before)
            self%summary%t_reached = max(self%summary%t_reached, self%t)
            call self%integrator%finalize()
            return
        end if
        self%counting = .false.
        associate (s => self%summary)
            s%cpu_time = self%cpu_so_far()
            s%stats = self%counters_so_far()
            s%t_reached = max(s%t_reached, self%t)
            if (self%turned_back%body > 0) then
                call append_text(s%warnings, self%turned_back_warning(self%model%model_name()))
                s%passed_through = self%turned_back%first
            end if
            if (self%monitoring .and. s%records > 0) then
                if (self%monitor%lost(s%final_energy)) call append_text(s%warnings, &
                    loss_warning(self%monitor%loss(s%final_energy), self%monitor%intake(), &
                                 self%scene%solver%rtol))
            end if
            call self%out%write_stats(s%stats, s%cpu_time, ferr, t_reached=self%t)
            if (.not. allocated(ferr)) call self%out%add_warnings(self%file_warnings(), ferr)
            ! (a local copy, not an array constructor of the two function results: that
            ! leaked their reasons, valgrind in the library's memory test)
            call self%keep_switches()
            s%switches = self%switches_before%items()
            if (.not. allocated(ferr)) call self%out%write_switches(s%switches, ferr)
            associate (r => s%safety)
                if (.not. allocated(ferr)) &
                    call self%out%write_order_safety(r%energy_gain, r%lowered_at, &
                        r%order_before, r%order_after, r%kept_at, r%kept_count, ferr)
            end associate
        end associate
        if (self%output == OUTPUT_MEMORY) then
            call self%out%close_run(status, reason, ferr, self%image)
        else
            call self%out%close_run(status, reason, ferr)
        end if
        if (allocated(ferr) .and. .not. allocated(err)) call move_alloc(ferr, err)
        call self%integrator%finalize()
        call self%release_output(err)
    end subroutine run_finish

    !> The warnings this part of the run adds to its file's /solver/warnings: the scene's
    !! own (a fresh run: the part that read the scene) and the run's (the summary's).
    function file_warnings(self) result(list)
        class(run_t), intent(in) :: self
        type(text_t), allocatable :: list(:)
        integer :: k
        allocate (list(0))
        if (.not. self%resumed) list = scene_warnings(self%scene)
        if (.not. allocated(self%summary%warnings)) return
        do k = 1, size(self%summary%warnings)
            call append_text(list, self%summary%warnings(k)%s)
        end do
    end function file_warnings

    !> m g L of a scene's rope (its model's element masses), J; 0 without gravity.
    function weight_length(scene, model) result(mgl)
        type(scene_t), intent(in) :: scene
        class(rope_model_t), intent(in) :: model
        real(wp) :: mgl
        real(wp) :: lengths(model%n_elements()), masses(model%n_elements())
        mgl = 0.0_wp
        if (.not. scene%effects%gravity) return
        call model%element_data(lengths, masses)
        mgl = sum(masses)*scene%rope%gravity*scene%rope%length
    end function weight_length

    !> Whether every output time has been recorded.
    pure logical function run_done(self)
        class(run_t), intent(in) :: self
        run_done = self%k_next > self%n_out
    end function run_done

    !> The simulated time reached, s.
    pure real(wp) function run_time(self)
        class(run_t), intent(in) :: self
        run_time = self%t
    end function run_time

    !> The scene's end time, s.
    pure real(wp) function run_end_time(self)
        class(run_t), intent(in) :: self
        run_end_time = self%t_end
    end function run_end_time

    !> The run's output file.
    pure function run_output_file(self) result(path)
        class(run_t), intent(in) :: self
        character(len=:), allocatable :: path
        path = self%summary%file
    end function run_output_file

    !> The name the run's file has when the run ends: FILE, while it is written as FILE.part
    !! (a message stored in the file names it where it will be).
    pure function run_final_file_name(self) result(path)
        class(run_t), intent(in) :: self
        character(len=:), allocatable :: path
        path = self%summary%file
        if (.not. allocated(self%final_file)) return
        if (len(self%final_file) > 0) path = self%final_file
    end function run_final_file_name

    !> OUTPUT_MEMORY, after `finish`: the bytes of the run's file (an HDF5 file image),
    !! moved out of the run; none before, or after a failure to take them.
    subroutine run_take_image(self, image)
        class(run_t), intent(inout) :: self
        integer(int8), allocatable, intent(out) :: image(:)
        if (allocated(self%image)) call move_alloc(self%image, image)
    end subroutine run_take_image

    !> Free what the run holds outside Fortran's reach (the integrator's memory); after
    !! `finish` or for a run without output that ends here.
    subroutine run_release(self)
        class(run_t), intent(inout) :: self
        if (allocated(self%integrator)) call self%integrator%finalize()
    end subroutine run_release

    !> Output time k (k = 0: the start; n_out: t_end).
    pure real(wp) function output_time(self, k) result(tk)
        class(run_t), intent(in) :: self
        integer, intent(in) :: k
        tk = min(real(k, wp)*self%dt, self%t_end)
        if (k >= self%n_out) tk = self%t_end
    end function output_time

    !> Steps of the integrator in use so far.
    integer(i8) function steps_taken(self)
        class(run_t), intent(in) :: self
        type(solver_stats_t) :: now
        now = self%integrator%stats()
        steps_taken = now%steps
    end function steps_taken
end module ropedyn_run
