!> HDF5 output of one simulation run: one file per run, appended one output time at a time.
!!
!! Layout (as h5py sees it; Fortran writes the reversed shape, so time is the last Fortran
!! axis and the first h5py axis). All step-by-step datasets are chunked and extendible.
!!
!!     /time                   (times,)               s
!!     /state/q                (times, elements, 3)   m, m, rad     columns = 'x, y, phi'
!!     /state/qdot             (times, elements, 3)   m/s, m/s, rad/s
!!     /rope/points            (times, 2*elements, 2) m             columns = 'x, y'
!!     /rope/element_length    (elements,)            m   (written once at create)
!!     /rope/element_mass      (elements,)            kg  (written once at create)
!!     /energy/{kinetic, elastic, gravity, dissipated, support_work, total} (times,) J
!!     /solver/step_size       (times,)               s
!!     /solver/order           (times,)               1
!!     /solver/{steps, rhs_evals, jac_rhs_evals, jac_evals, lin_setups, err_test_fails,
!!              nonlin_iters, nonlin_conv_fails} () int64 1;  /solver/cpu_time () s
!!              (write_stats; jac_rhs_evals: the f evaluations of differenced Jacobians)
!!     /solver/{time_advance, time_rhs, time_jacobian, time_factor, time_solve} () s: the
!!              time in the integrator and where it went (&solver profile = .true.; else 0)
!!     /solver/reduced_newton () int64 1: 1 when the Newton systems were solved on the
!!              reduced second-order matrix
!!     /state/y                (times, state size)    SI            restart data (with the
!!     /state/yq               (times, quadratures)   J             state sizes at create)
!!     /forces/{axial, shear, moment}  (times, elements + 1)  N, N, N m   internal forces at
!!              the joints, 0 the top end (with internal_forces at create; FORCE_DESCRIPTION)
!!     /supports/{top, bottom}/reaction (times, 2)    N             force of the support on
!!              the rope; /supports/{top, bottom}/position (times, 2) m: its anchor (only
!!              for a support with one: not for a free end)
!!     /solver/restarts/{time, record, steps, cpu_time, wall_clock, previous_status,
!!              previous_reason, version, overrides} (restarts,)   one entry per resume
!!              (add_restart)
!!     /solver/order_lowered_at () s, /solver/order_lowered_from, _to () int64 1,
!!     /solver/energy_gain () J: only when the order safety lowered the order (the time
!!              from which the run went on at the lower order, and the gain that caused it)
!!     /solver/order_kept_at () s, /solver/order_kept_count () int64 1, /solver/energy_gain:
!!              only when a gain beyond the bound was not cured by the safe order (the
!!              order asked for kept; the first time, how often, the first gain)
!!
!! Root attributes: status ('running' | 'complete' | 'failed' | 'interrupted'), reason
!! (failed and interrupted), version, model, method, scene, created, units_convention.
!! See docs/reference/file-format.md (the layout), docs/development/internals.md. A file is continued (`ropedyn run --resume`) by `reopen`.
!!
!! The file is flushed after an `append` when FLUSH_PERIOD (wall clock) has passed since the
!! last flush, and always when it is finished or closed, so a run that crashes leaves
!! readable data up to at most FLUSH_PERIOD before the crash, with status 'running'.
!! `/time` is written last in each record, so its length is the number of complete records.
!!
!! The HDF5 calls are those of `ropedyn_h5`. An `output_file_t` must not be copied while open
!! (both copies would hold the same ids).
module ropedyn_output
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use, intrinsic :: iso_fortran_env, only: int8
    use hdf5, only: hsize_t
    use ropedyn_kinds, only: wp, i8
    use ropedyn_clock, only: utc_timestamp, clock_seconds
    use ropedyn_text, only: int_text, text_t
    use ropedyn_error, only: error_t, make_error, ERR_INTERNAL, ERR_IO
    use ropedyn_rope_model, only: energy_t
    use ropedyn_integrator, only: solver_stats_t
    use ropedyn_switch_log, only: switch_event_t
    use ropedyn_h5, only: h5_file_t, h5_series_t
    implicit none
    private
    public :: output_file_t, write_provenance, COUNTER_NAMES, counter_values, TIMER_NAMES
    public :: add_counter_values, write_forces, write_shape_record, whole_records

    !> The convention written into every file (root attribute `units_convention`).
    character(len=*), parameter :: units_convention = &
        'SI; x points down (gravity), y horizontal, angles from x towards y'

    !> Wall-clock time between flushes of the appended records, s: a flush (about 70 us for
    !! a small rope) after every record took a fifth of the paper run's time at 100 records
    !! per simulated second; a crash loses at most this much of a run.
    real(wp), parameter :: FLUSH_PERIOD = 0.1_wp

    !> Indices of the step-by-step datasets in `output_file_t%series`, in the order they
    !! are created; the scalar ones S_KINETIC .. S_STEP_SIZE are consecutive.
    integer, parameter :: S_TIME = 1, S_Q = 2, S_QDOT = 3, S_POINTS = 4, S_KINETIC = 5, &
        S_STEP_SIZE = 11, S_ORDER = 12
    integer, parameter :: N_SERIES = 12

    !> The step-by-step datasets: name, units, columns ('' for none), and the extents of one
    !! record as (rows, columns per element): (0, 0) a scalar, (3, 1) a (3, n) record,
    !! (2, 2) a (2, 2n) record.
    character(len=*), parameter :: SERIES_NAME(N_SERIES) = [character(len=20) :: '/time', &
        '/state/q', '/state/qdot', '/rope/points', '/energy/kinetic', '/energy/elastic', &
        '/energy/gravity', '/energy/dissipated', '/energy/support_work', '/energy/total', &
        '/solver/step_size', '/solver/order']
    character(len=*), parameter :: SERIES_UNITS(N_SERIES) = [character(len=15) :: 's', &
        'm, m, rad', 'm/s, m/s, rad/s', 'm', 'J', 'J', 'J', 'J', 'J', 'J', 's', '1']
    character(len=*), parameter :: SERIES_COLUMNS(N_SERIES) = [character(len=18) :: '', &
        'x, y, phi', 'xdot, ydot, phidot', 'x, y', '', '', '', '', '', '', '', '']
    integer, parameter :: RECORD_ROWS(N_SERIES) = [0, 3, 3, 2, 0, 0, 0, 0, 0, 0, 0, 0]
    integer, parameter :: RECORD_PER_ELEMENT(N_SERIES) = [0, 1, 1, 2, 0, 0, 0, 0, 0, 0, 0, 0]

    !> The restart data: the model's ODE state y and its quadratures at every record (what a
    !! run needs to continue from a record; ropedyn_run_record reads it back).
    character(len=*), parameter :: STATE_NAME(2) = [character(len=9) :: '/state/y', '/state/yq']
    character(len=*), parameter :: STATE_UNITS(2) = [character(len=2) :: 'SI', 'J']
    character(len=*), parameter :: STATE_DESCRIPTION(2) = [character(len=160) :: &
        "the model's ODE state y (rfem: x, y, phi, xdot, ydot, phidot of each element; mpp: " &
        //'the coordinates q, then their rates): m, rad, m/s, rad/s', &
        'the quadratures: dissipated energy, then (when supports move or effects do work) ' &
        //'the external work']

    !> The internal forces and the supports at every record (`create` with
    !! internal_forces; `append`'s axial, shear, moment, reaction, position): name, units,
    !! columns, description; a record of the first N_JOINT_SERIES holds the n + 1 joints,
    !! of the others x and y. The positions (the last two) exist only for the supports
    !! that have an anchor (`anchored`): a free end has none, and no record holds a NaN.
    !! The definitions: docs/theory/internal-forces.md.
    integer, parameter :: N_FORCE_SERIES = 7, N_JOINT_SERIES = 3
    character(len=*), parameter :: FORCE_NAME(N_FORCE_SERIES) = [character(len=25) :: &
        '/forces/axial', '/forces/shear', '/forces/moment', '/supports/top/reaction', &
        '/supports/bottom/reaction', '/supports/top/position', '/supports/bottom/position']
    character(len=*), parameter :: FORCE_UNITS(N_FORCE_SERIES) = [character(len=3) :: 'N', &
        'N', 'N m', 'N', 'N', 'm', 'm']
    !> Their columns: none for the joints' series, x and y for the supports'
    character(len=*), parameter :: FORCE_COLUMNS(N_FORCE_SERIES) = [character(len=4) :: '', &
        '', '', 'x, y', 'x, y', 'x, y', 'x, y']
    !> (FORCE_DESCRIPTION's length holds the longest text: an array constructor with a
    !! length cuts a longer one without a word; tests/e2e/test_internal_forces.py checks)
    character(len=*), parameter :: FORCE_FRAME = ' (frame: rfem, the element above the '// &
        'joint, at joint 0 element 1; mpp, the member below the joint, at joint n member n)'
    character(len=*), parameter :: FORCE_DESCRIPTION(N_FORCE_SERIES) = [character(len=400) :: &
        'tension (> 0: stretched) at joints 0 (top end) .. n (bottom end): the component '// &
        'along the rope of the force of the rope below the joint on the rope above it (at '// &
        'the ends: of the rope on the top support, of the bottom support on the rope)'// &
        FORCE_FRAME, &
        'shear force at joints 0 .. n: the component of that force along n = (-sin phi, '// &
        'cos phi) of the frame'//FORCE_FRAME, &
        'bending moment at joints 0 .. n: the moment of the rope below the joint on the '// &
        'rope above it, > 0 from x towards y: C (phi below - phi above) + B (its rate); '// &
        '0 at a pinned or free end', &
        'force of the top support on the rope (x, y); 0 when free or released', &
        'force of the bottom support on the rope (x, y); 0 when free or released', &
        'anchor of the top support at the time of the record, from its prescribed '// &
        'motion (x, y)', &
        'anchor of the bottom support at the time of the record, from its prescribed '// &
        'motion (x, y)']

    !> The entries of /solver/restarts (one per resume): name, units, width of a string
    !! (0: a number; integer for record, int64 for steps as for /solver/steps). The first
    !! RESTART_REQUIRED are in every file with restarts; version and overrides (the code
    !! that continued the run and the --set overrides it was given) are absent in files
    !! written before they were recorded.
    character(len=*), parameter :: RESTART_NAME(9) = [character(len=15) :: 'time', 'record', &
        'steps', 'cpu_time', 'wall_clock', 'previous_status', 'previous_reason', 'version', &
        'overrides']
    character(len=*), parameter :: RESTART_UNITS(9) = [character(len=1) :: 's', '1', '1', &
        's', '', '', '', '', '']
    integer, parameter :: RESTART_WIDTH(9) = [0, 0, 0, 0, 20, 16, 512, 64, 1024]
    integer, parameter :: RESTART_REQUIRED = 7
    !> /solver/warnings: the width of one line, characters (a longer line is cut there)
    integer, parameter :: WARNING_WIDTH = 1024

    !> The solver counters of `write_stats` (/solver/<name>, int64, units 1), in the order
    !! of `counter_values`.
    !! jac_rhs_evals (f evaluations spent differencing Jacobians) is absent in files of
    !! earlier versions: read as absent (ropedyn_case_file), it counts 0 for their parts.
    character(len=*), parameter :: COUNTER_NAMES(8) = [character(len=17) :: 'steps', &
        'rhs_evals', 'jac_rhs_evals', 'jac_evals', 'lin_setups', 'err_test_fails', &
        'nonlin_iters', 'nonlin_conv_fails']

    !> The time split of `write_stats` (/solver/<name>, s; solver_stats_t's time_* fields,
    !! measured with &solver profile = .true.), in the order of `timer_values`.
    character(len=*), parameter :: TIMER_NAMES(5) = [character(len=13) :: 'time_advance', &
        'time_rhs', 'time_jacobian', 'time_factor', 'time_solve']

    !> Records held in memory before they are written: about this many bytes, and at most
    !! MAX_PENDING records. One HDF5 write per series and record cost a tenth of the paper
    !! run's time (12 datasets); a block of records costs one write per series.
    integer, parameter :: PENDING_BYTES = 2**20, MAX_PENDING = 512
    !> Room kept free on the file system beyond the end of the file (ropedyn_os reserve_space,
    !! at create and reopen and after every block of records appended): when it cannot be
    !! kept, the disk is all but full, and the run stops while there is still room to close
    !! the file marked failed.
    integer(i8), parameter :: RESERVE_BYTES = 2*int(PENDING_BYTES, i8)

    !> The values of a series' pending records, one after the other.
    type :: block_t
        real(wp), allocatable :: v(:)
    end type block_t

    !> One HDF5 file of one simulation run.
    type, public :: output_file_t
        private
        type(h5_file_t) :: file                   !< the file (open from create to close_run)
        logical :: is_open = .false.              !< create succeeded and close_run not yet done
        integer :: n_elements = 0                 !< elements of the rope
        integer(hsize_t) :: n_records = 0         !< complete records (length of /time)
        !> the monotonic clock (s) at the last flush after an append (FLUSH_PERIOD)
        real(wp) :: last_flush = 0.0_wp
        type(h5_series_t) :: series(N_SERIES)     !< the step-by-step datasets
        !> restart data /state/y, /state/yq (when `restart_data`) and their record sizes
        type(h5_series_t) :: state(2)
        logical :: restart_data = .false.
        integer :: state_size(2) = 0
        !> the internal forces and supports (FORCE_NAME, when `force_data`; those of them
        !! that the file has: force_on)
        type(h5_series_t) :: force(N_FORCE_SERIES)
        logical :: force_data = .false.
        logical :: force_on(N_FORCE_SERIES) = .false.
        !> records appended but not yet written: record m of series k (the state's two
        !! after the N_SERIES, then the N_FORCE_SERIES) at pending(k)%v((m - 1) r + 1 : m r),
        !! r its record size; written as one block per series when `capacity` are held,
        !! when FLUSH_PERIOD has passed, and before the file is finished or closed
        !! (write_pending)
        type(block_t) :: pending(N_SERIES + 2 + N_FORCE_SERIES)
        integer, allocatable :: pending_order(:)
        integer :: n_pending = 0
        integer :: capacity = 1
        !> the I/O error after which the file was given up (`abandon`); later calls return it
        character(len=:), allocatable :: broken
        !> bytes of records written to HDF5 since the file was last flushed (held in its
        !! chunk cache: written to disk at the flush; keep_room keeps room for them)
        integer(i8) :: unflushed = 0
        !> the run's counters and CPU time (s) so far, kept by `keep_counters` for the next
        !! flush after an append, which writes them with the records (`has_kept`)
        type(solver_stats_t) :: kept_stats
        real(wp) :: kept_cpu = 0.0_wp
        logical :: has_kept = .false.
    contains
        procedure :: create => output_create
        procedure :: append => output_append
        procedure :: write_stats => output_write_stats
        procedure :: flush_due => output_flush_due
        procedure :: keep_counters => output_keep_counters
        procedure :: write_switches => output_write_switches
        procedure :: write_order_safety => output_write_order_safety
        procedure :: add_warnings => output_add_warnings
        procedure :: close_run => output_close_run
        procedure :: reopen => output_reopen
        procedure :: records => output_records
        procedure :: add_restart => output_add_restart
        final :: output_final
    end type output_file_t

    interface
        !> Open the run file `path`, written by `create` with restart data, to continue it:
        !! every series open for `append` after its last complete record (longer series, from a
        !! record cut short, are cut back to the length of /time, or to `keep` records), the
        !! status 'running' again and its old reason removed. The file must be for
        !! `n_elements` elements and the given state and quadrature sizes.
        module subroutine output_reopen(self, path, n_elements, state_size, quad_size, err, &
                                        keep, internal_forces, anchored, salvage)
            class(output_file_t), intent(inout) :: self
            character(len=*), intent(in) :: path
            integer, intent(in) :: n_elements, state_size, quad_size
            type(error_t), allocatable, intent(out) :: err
            !> keep only the first `keep` records (fewer than the file has: the others are cut)
            integer, intent(in), optional :: keep
            !> the file must hold the internal forces (ERR_IO naming the first missing series
            !! if not: a file written before they were stored cannot be continued)
            logical, intent(in), optional :: internal_forces
            !> with internal_forces: which supports (top, bottom) have an anchor, as at
            !! `create` (default both); the file's positions must be those
            logical, intent(in), optional :: anchored(2)
            !> with keep: the file of a killed run, cut back to its `keep` whole records
            !! (whole_records): its series need only hold those, and records on its output
            !! grid may be cut (default false)
            logical, intent(in), optional :: salvage
        end subroutine output_reopen

        !> The number of whole records of the run file `path`: the largest count such that
        !! every series of the file (/time and the rest, the restart data, the internal
        !! forces) reads its last of them back. A run killed inside a write (a flush) can
        !! leave series of unequal length, or a record HDF5 cannot read ("addr overflow");
        !! the records before it are whole. 0 when none reads back.
        module subroutine whole_records(path, count, err)
            character(len=*), intent(in) :: path
            integer, intent(out) :: count
            type(error_t), allocatable, intent(out) :: err
        end subroutine whole_records

        !> Add an entry to /solver/restarts: the run continues from record `record` (0-based, as
        !! h5py counts) at time `t`; the file's status and reason before, and the solver steps
        !! and CPU time of the run so far; the code version and the --set overrides of the
        !! run that continues it.
        module subroutine output_add_restart(self, record, t, previous_status, &
                                             previous_reason, steps, cpu_time, version, &
                                             overrides, err)
            class(output_file_t), intent(inout) :: self
            integer, intent(in) :: record
            real(wp), intent(in) :: t                         !< s
            character(len=*), intent(in) :: previous_status, previous_reason
            integer(i8), intent(in) :: steps
            real(wp), intent(in) :: cpu_time                  !< s
            !> code version; ' --set group.key=value' for each override ('' for none)
            character(len=*), intent(in) :: version, overrides
            type(error_t), allocatable, intent(out) :: err
        end subroutine output_add_restart

        !> /solver's counters, CPU time (s), time split and reduced_newton (no flush).
        module subroutine write_counters(self, stats, cpu_time, err)
            type(output_file_t), intent(inout) :: self
            type(solver_stats_t), intent(in) :: stats
            real(wp), intent(in) :: cpu_time
            type(error_t), allocatable, intent(out) :: err
        end subroutine write_counters

        !> Close all datasets and the file and mark `self` closed.
        !! Reports the first failure in `err` if present; closes everything regardless.
        module subroutine shutdown(self, err)
            type(output_file_t), intent(inout) :: self
            type(error_t), allocatable, intent(out), optional :: err
        end subroutine shutdown

        !> Append one output time (held in memory and written in blocks, see `pending`);
        !! flush the file when FLUSH_PERIOD has passed since the last flush. A file with
        !! restart data needs the ODE state `y` and quadratures `yq` of the record too, one
        !! with internal forces its axial, shear, moment, reaction and position.
        module subroutine output_append(self, t, q, qdot, points, energy, step_size, order, &
                                        err, y, yq, axial, shear, moment, reaction, position)
            class(output_file_t), intent(inout) :: self
            real(wp), intent(in) :: t                 !< time, s
            real(wp), intent(in) :: q(:, :)           !< (3, n) x, y (m), phi (rad) per element
            real(wp), intent(in) :: qdot(:, :)        !< (3, n) rates: m/s, m/s, rad/s
            real(wp), intent(in) :: points(:, :)      !< (2, 2n) element end points, m
            type(energy_t), intent(in) :: energy      !< energies at t, J
            real(wp), intent(in) :: step_size         !< last step size, s
            integer, intent(in) :: order              !< last order
            type(error_t), allocatable, intent(out) :: err
            real(wp), intent(in), optional :: y(:)    !< the model's ODE state (restart data)
            real(wp), intent(in), optional :: yq(:)   !< its quadratures, J (restart data)
            !> (n + 1) joints 0 (top end) .. n: tension (N), shear force (N), moment (N m)
            real(wp), intent(in), optional :: axial(:), shear(:), moment(:)
            !> (2, 2) top, bottom: force of the support on the rope (N), its anchor (m; only
            !! those of the supports with an anchor are written)
            real(wp), intent(in), optional :: reaction(:, :), position(:, :)
        end subroutine output_append

        !> The buffers of the pending records for the series of an open file (none held).
        module subroutine allocate_pending(self)
            type(output_file_t), intent(inout) :: self
        end subroutine allocate_pending

        !> Write the pending records, one block per series, /time last.
        module subroutine write_pending(self, err)
            type(output_file_t), intent(inout) :: self
            type(error_t), allocatable, intent(out) :: err
        end subroutine write_pending

        !> Record what the order safety did (docs/theory/energy-balance.md; times < 0: never): the order
        !! limit lowered from `from` to `to` at time `lowered_at`; the order kept at a gain
        !! judged the integration error, first at `kept_at`, `kept_count` times in all; `gain`,
        !! the first gain beyond the bound. Nothing when it did neither.
        module subroutine output_write_order_safety(self, gain, lowered_at, from, to, &
                                                    kept_at, kept_count, err)
            class(output_file_t), intent(inout) :: self
            real(wp), intent(in) :: gain                  !< J
            real(wp), intent(in) :: lowered_at, kept_at   !< s
            integer, intent(in) :: from, to, kept_count
            type(error_t), allocatable, intent(out) :: err
        end subroutine output_write_order_safety

        !> Append the warnings `lines` to /solver/warnings, a series of strings (created
        !! with the first; a resumed run appends its own). Nothing when there are none.
        module subroutine output_add_warnings(self, lines, err)
            class(output_file_t), intent(inout) :: self
            type(text_t), intent(in) :: lines(:)
            type(error_t), allocatable, intent(out) :: err
        end subroutine output_add_warnings

        !> The integrator's changes of method or order limit during the run
        !! (ropedyn_switch_log) as /solver/switch_time (s), switch_method, switch_max_order
        !! and switch_reason, one entry per change, oldest first (nothing when none).
        module subroutine output_write_switches(self, events, err)
            class(output_file_t), intent(inout) :: self
            type(switch_event_t), intent(in) :: events(:)
            type(error_t), allocatable, intent(out) :: err
        end subroutine output_write_switches

        !> After the I/O error `err` (a full disk, a failed device, ...), give the file up: the
        !! records not written yet are dropped, the status set to 'failed' with err's message
        !! as the reason while that can still be written, and every object closed (datasets
        !! before the file, so that nothing is left for the library to flush at exit). err's
        !! message then says which: '; the file is closed with status failed ...' or '; the
        !! file is incomplete ...'. Later calls on `self` return that error.
        module subroutine abandon(self, err)
            type(output_file_t), intent(inout) :: self
            type(error_t), allocatable, intent(inout) :: err
        end subroutine abandon

        !> The error of a call on a file that is not open: the I/O error it was given up
        !! after (ERR_IO), else ERR_INTERNAL naming `what` (the call).
        module subroutine not_open(self, what, err)
            type(output_file_t), intent(in) :: self
            character(len=*), intent(in) :: what
            type(error_t), allocatable, intent(out) :: err
        end subroutine not_open

        !> Flush the file (everything HDF5 holds goes to disk).
        module subroutine flush_file(self, err)
            type(output_file_t), intent(inout) :: self
            type(error_t), allocatable, intent(out) :: err
        end subroutine flush_file

        !> Keep room beyond the end of the file for what is not flushed yet and RESERVE_BYTES
        !! more; ERR_IO when the file system has not that much left (nothing when it cannot
        !! reserve at all).
        module subroutine keep_room(self, err)
            type(output_file_t), intent(inout) :: self
            type(error_t), allocatable, intent(out) :: err
        end subroutine keep_room
        !> Values in a record of force series k of a rope of n elements: n + 1 joints, or
        !! x, y (submodule ropedyn_output_pending; a private procedure of this module used
        !! only by its submodules is dropped from the object by gfortran).
        pure module function force_record_size(k, n) result(values)
            integer, intent(in) :: k, n
            integer :: values
        end function force_record_size

        !> Which force series a file with `force_data` has (force_on): all but the anchors
        !! of supports without one (`anchored`, default both; submodule
        !! ropedyn_output_pending).
        module subroutine set_force_series(self, anchored)
            type(output_file_t), intent(inout) :: self
            logical, intent(in), optional :: anchored(2)
        end subroutine set_force_series

        !> The path of the file, or a placeholder if create never succeeded.
        module function file_label(self) result(label)
            type(output_file_t), intent(in) :: self
            character(len=:), allocatable :: label
        end function file_label
    end interface

contains

    !> Create (or overwrite) the file `path` and write the run's fixed data; status 'running'.
    !! The directory of `path` must exist. An object that is still open is closed first
    !! (its file keeps status 'running'). With `state_size` and `quad_size` (the model's),
    !! every record also holds the restart data /state/y, /state/yq (`append`'s y, yq); with
    !! `internal_forces`, the internal forces and supports (FORCE_NAME; the anchors of
    !! those supports that have one, `anchored`, default both). With `memory`, the file is
    !! made in memory only (`path` its unique name; `close_run` gives its image).
    subroutine output_create(self, path, n_elements, element_length, element_mass, model, &
                             method, version, scene_text, err, state_size, quad_size, &
                             source, internal_forces, anchored, memory)
        class(output_file_t), intent(inout) :: self
        character(len=*), intent(in) :: path              !< e.g. out/run.h5
        integer, intent(in) :: n_elements                 !< elements of the rope
        real(wp), intent(in) :: element_length(:)         !< (n_elements) m
        real(wp), intent(in) :: element_mass(:)           !< (n_elements) kg
        character(len=*), intent(in) :: model             !< e.g. rfem
        character(len=*), intent(in) :: method            !< integrator name as in &solver
        character(len=*), intent(in) :: version           !< code version
        character(len=*), intent(in) :: scene_text        !< effective namelist text
        type(error_t), allocatable, intent(out) :: err
        integer, intent(in), optional :: state_size       !< unknowns of the ODE state
        integer, intent(in), optional :: quad_size        !< quadrature variables
        !> where the scene came from (root attribute `source`; scene_t's source)
        character(len=*), intent(in), optional :: source
        logical, intent(in), optional :: internal_forces  !< records hold the forces
        logical, intent(in), optional :: anchored(2)      !< top, bottom have an anchor
        logical, intent(in), optional :: memory           !< the file in memory only

        if (self%is_open) call shutdown(self)

        if (n_elements < 1) then
            call make_error(err, ERR_INTERNAL, path//': cannot create output for '// &
                            int_text(n_elements)//' elements')
            return
        end if
        if (size(element_length) /= n_elements .or. size(element_mass) /= n_elements) then
            call make_error(err, ERR_INTERNAL, path//': element_length has '// &
                            int_text(size(element_length))//' and element_mass '// &
                            int_text(size(element_mass))//' values, expected '// &
                            int_text(n_elements))
            return
        end if

        call self%file%create(path, err, memory)
        if (allocated(err)) return
        self%is_open = .true.
        self%n_elements = n_elements
        self%n_records = 0
        self%restart_data = present(state_size) .and. present(quad_size)
        if (self%restart_data) self%state_size = [state_size, quad_size]
        self%force_data = .false.
        if (present(internal_forces)) self%force_data = internal_forces
        call set_force_series(self, anchored)

        call write_contents()
        if (allocated(err)) then
            call abandon(self, err)
        else
            call allocate_pending(self)
        end if

    contains

        !> Everything after the file exists; on error `err` is set and the caller closes.
        subroutine write_contents()
            integer(hsize_t) :: record(2)
            integer :: k

            call self%file%attribute('/', 'status', 'running', err)
            if (allocated(err)) return
            call write_provenance(self%file, version, model, scene_text, err)
            if (allocated(err)) return
            if (present(source)) call self%file%attribute('/', 'source', source, err)
            if (allocated(err)) return
            call self%file%attribute('/', 'method', method, err)
            if (allocated(err)) return

            call self%file%group('/state', err)
            if (allocated(err)) return
            call self%file%group('/rope', err)
            if (allocated(err)) return
            call self%file%group('/energy', err)
            if (allocated(err)) return
            call self%file%group('/solver', err)
            if (allocated(err)) return

            do k = 1, N_SERIES
                record = int([RECORD_ROWS(k), RECORD_PER_ELEMENT(k)*n_elements], hsize_t)
                call self%file%create_series(self%series(k), trim(SERIES_NAME(k)), &
                                             record(1:merge(2, 0, RECORD_ROWS(k) > 0)), &
                                             k == S_ORDER, trim(SERIES_UNITS(k)), &
                                             trim(SERIES_COLUMNS(k)), err)
                if (allocated(err)) return
            end do

            call self%file%write('/rope/element_length', element_length, 'm', err)
            if (allocated(err)) return
            call self%file%write('/rope/element_mass', element_mass, 'kg', err)
            if (allocated(err)) return
            if (self%restart_data) call create_state_series(self, err)
            if (allocated(err)) return
            if (self%force_data) call create_force_series(self, err)
            if (allocated(err)) return

            call flush_file(self, err)
            if (.not. allocated(err)) call keep_room(self, err)
        end subroutine write_contents
    end subroutine output_create

    !> The restart data series /state/y and /state/yq of an open file (`self%state_size`).
    subroutine create_state_series(self, err)
        type(output_file_t), intent(inout) :: self
        type(error_t), allocatable, intent(out) :: err
        integer :: k
        do k = 1, 2
            call self%file%create_series(self%state(k), trim(STATE_NAME(k)), &
                                         [int(max(1, self%state_size(k)), hsize_t)], .false., &
                                         trim(STATE_UNITS(k)), '', err)
            if (allocated(err)) return
            call self%file%attribute(trim(STATE_NAME(k)), 'description', &
                                     trim(STATE_DESCRIPTION(k)), err)
            if (allocated(err)) return
        end do
    end subroutine create_state_series

    !> The groups of the internal-force and support datasets (FORCE_NAME) in `file`.
    subroutine force_groups(file, err)
        type(h5_file_t), intent(inout) :: file
        type(error_t), allocatable, intent(out) :: err
        character(len=*), parameter :: groups(4) = [character(len=17) :: '/forces', &
            '/supports', '/supports/top', '/supports/bottom']
        integer :: k
        do k = 1, size(groups)
            call file%group(trim(groups(k)), err)
            if (allocated(err)) return
        end do
    end subroutine force_groups

    !> The internal forces and supports of one state as the datasets of a run file with one
    !! record (FORCE_NAME: h5py shapes (1, n + 1) and (1, 2)), for the statics and modes
    !! files: axial, shear, moment (0:n) and reaction, position (2, 2; top, bottom; a
    !! position that is not finite, a free end's, is not written).
    subroutine write_forces(file, axial, shear, moment, reaction, position, err)
        type(h5_file_t), intent(inout) :: file
        real(wp), intent(in) :: axial(:), shear(:), moment(:)   !< N, N, N m
        real(wp), intent(in) :: reaction(2, 2), position(2, 2)  !< N, m
        type(error_t), allocatable, intent(out) :: err
        real(wp) :: values(size(axial), N_FORCE_SERIES)
        integer :: k, m
        call force_groups(file, err)
        if (allocated(err)) return
        values(:, 1) = axial
        values(:, 2) = shear
        values(:, 3) = moment
        values(1:2, 4:5) = reaction
        values(1:2, 6:7) = position
        do k = 1, N_FORCE_SERIES
            if (k >= N_FORCE_SERIES - 1 .and. .not. all(ieee_is_finite(values(1:2, k)))) cycle
            m = merge(size(axial), 2, k <= N_JOINT_SERIES)
            call file%write(trim(FORCE_NAME(k)), reshape(values(1:m, k), [m, 1]), &
                            trim(FORCE_UNITS(k)), err, trim(FORCE_DESCRIPTION(k)))
            if (allocated(err)) return
            if (len_trim(FORCE_COLUMNS(k)) > 0) &
                call file%attribute(trim(FORCE_NAME(k)), 'columns', trim(FORCE_COLUMNS(k)), err)
            if (allocated(err)) return
        end do
    end subroutine write_forces

    !> The shape of one state as the datasets of a run file with one record (SERIES_NAME,
    !! with their units and columns: h5py shapes (1, n, 3) and (1, 2n, 2)), for the statics
    !! and modes files: the element centres and angles q (3, n) and the polyline (2, 2n).
    subroutine write_shape_record(file, q, points, err)
        type(h5_file_t), intent(inout) :: file
        real(wp), intent(in) :: q(:, :)         !< m, m, rad
        real(wp), intent(in) :: points(:, :)    !< m
        type(error_t), allocatable, intent(out) :: err
        call file%group('/state', err)
        if (allocated(err)) return
        call file%write(trim(SERIES_NAME(S_Q)), reshape(q, [size(q, 1), size(q, 2), 1]), &
                        trim(SERIES_UNITS(S_Q)), err, &
                        'x, y, phi of each element centre (one record)')
        if (allocated(err)) return
        call file%attribute(trim(SERIES_NAME(S_Q)), 'columns', trim(SERIES_COLUMNS(S_Q)), err)
        if (allocated(err)) return
        call file%group('/rope', err)
        if (allocated(err)) return
        call file%write(trim(SERIES_NAME(S_POINTS)), &
                        reshape(points, [size(points, 1), size(points, 2), 1]), &
                        trim(SERIES_UNITS(S_POINTS)), err, &
                        'element end points A_1, B_1, A_2, ... (one record)')
        if (allocated(err)) return
        call file%attribute(trim(SERIES_NAME(S_POINTS)), 'columns', &
                            trim(SERIES_COLUMNS(S_POINTS)), err)
    end subroutine write_shape_record

    !> The internal-force and support series of an open file (FORCE_NAME) with their groups.
    subroutine create_force_series(self, err)
        type(output_file_t), intent(inout) :: self
        type(error_t), allocatable, intent(out) :: err
        integer :: k
        call force_groups(self%file, err)
        if (allocated(err)) return
        do k = 1, N_FORCE_SERIES
            if (.not. self%force_on(k)) cycle
            call self%file%create_series(self%force(k), trim(FORCE_NAME(k)), &
                                         [int(force_record_size(k, self%n_elements), hsize_t)], &
                                         .false., trim(FORCE_UNITS(k)), &
                                         trim(FORCE_COLUMNS(k)), err)
            if (allocated(err)) return
            call self%file%attribute(trim(FORCE_NAME(k)), 'description', &
                                     trim(FORCE_DESCRIPTION(k)), err)
            if (allocated(err)) return
        end do
    end subroutine create_force_series

    !> The root attributes every ropedyn HDF5 file carries so that it can be re-run and
    !! read: version, model, scene (the effective namelist text), created (UTC) and
    !! units_convention.
    subroutine write_provenance(file, version, model, scene_text, err)
        type(h5_file_t), intent(inout) :: file
        character(len=*), intent(in) :: version           !< code version
        character(len=*), intent(in) :: model             !< e.g. rfem
        character(len=*), intent(in) :: scene_text        !< effective namelist text
        type(error_t), allocatable, intent(out) :: err
        call file%attribute('/', 'version', version, err)
        if (allocated(err)) return
        call file%attribute('/', 'model', model, err)
        if (allocated(err)) return
        call file%attribute('/', 'scene', scene_text, err)
        if (allocated(err)) return
        call file%attribute('/', 'created', utc_timestamp(), err)
        if (allocated(err)) return
        call file%attribute('/', 'units_convention', units_convention, err)
    end subroutine write_provenance

    !> Whether the next `append` flushes the file (its first record, or FLUSH_PERIOD since
    !! the last flush): the time to `keep_counters`.
    logical function output_flush_due(self) result(due)
        class(output_file_t), intent(in) :: self
        due = self%is_open .and. (self%n_records + self%n_pending == 0 .or. &
                                  clock_seconds() - self%last_flush >= FLUSH_PERIOD)
    end function output_flush_due

    !> Keep the run's counters and CPU time so far (s) for the next flush after an append,
    !! which writes them into /solver with the records: a run killed later leaves them as
    !! of its last flush, with the records up to it (a resume counts on from them).
    subroutine output_keep_counters(self, stats, cpu_time)
        class(output_file_t), intent(inout) :: self
        type(solver_stats_t), intent(in) :: stats
        real(wp), intent(in) :: cpu_time
        self%kept_stats = stats
        self%kept_cpu = cpu_time
        self%has_kept = .true.
    end subroutine output_keep_counters

    !> Write the solver counters and the CPU time (also for a failed run); may be repeated.
    !! With `t_reached`, also /solver/t_reached: the time the integration got to (s; for an
    !! interrupted or failed run, where it stopped).
    subroutine output_write_stats(self, stats, cpu_time, err, t_reached)
        class(output_file_t), intent(inout) :: self
        type(solver_stats_t), intent(in) :: stats  !< counters of the integration
        real(wp), intent(in) :: cpu_time           !< CPU time of the run, s
        type(error_t), allocatable, intent(out) :: err
        real(wp), intent(in), optional :: t_reached

        if (.not. self%is_open) then
            call not_open(self, 'write_stats', err)
            return
        end if
        self%has_kept = .false.
        steps: block
            call write_pending(self, err)
            if (allocated(err)) exit steps
            call write_counters(self, stats, cpu_time, err)
            if (allocated(err)) exit steps
            if (present(t_reached)) then
                call self%file%write('/solver/t_reached', t_reached, 's', err)
                if (allocated(err)) exit steps
            end if
            call flush_file(self, err)
        end block steps
        if (allocated(err)) call abandon(self, err)
    end subroutine output_write_stats

    !> The counters of `stats` named in COUNTER_NAMES, in that order.
    pure function counter_values(stats) result(counters)
        type(solver_stats_t), intent(in) :: stats
        integer(i8) :: counters(size(COUNTER_NAMES))
        counters = [stats%steps, stats%rhs_evals, stats%jac_rhs_evals, stats%jac_evals, &
                    stats%lin_setups, stats%err_test_fails, stats%nonlin_iters, &
                    stats%nonlin_conv_fails]
    end function counter_values

    !> Add counters in COUNTER_NAMES order (those of the earlier parts of a resumed run) to
    !! `stats`: the inverse of counter_values.
    pure subroutine add_counter_values(stats, counters)
        type(solver_stats_t), intent(inout) :: stats
        integer(i8), intent(in) :: counters(size(COUNTER_NAMES))
        stats%steps = stats%steps + counters(1)
        stats%rhs_evals = stats%rhs_evals + counters(2)
        stats%jac_rhs_evals = stats%jac_rhs_evals + counters(3)
        stats%jac_evals = stats%jac_evals + counters(4)
        stats%lin_setups = stats%lin_setups + counters(5)
        stats%err_test_fails = stats%err_test_fails + counters(6)
        stats%nonlin_iters = stats%nonlin_iters + counters(7)
        stats%nonlin_conv_fails = stats%nonlin_conv_fails + counters(8)
    end subroutine add_counter_values

    !> Set the root status ('complete', or 'failed' or 'interrupted' with `reason`) and close
    !! everything. The file is closed even when writing the status fails.
    subroutine output_close_run(self, status, reason, err, image)
        class(output_file_t), intent(inout) :: self
        character(len=*), intent(in) :: status            !< complete, failed, interrupted
        character(len=*), intent(in), optional :: reason  !< why it failed or stopped
        type(error_t), allocatable, intent(out) :: err
        !> a file in memory: its bytes before it is closed (h5_file_t%image)
        integer(int8), allocatable, intent(out), optional :: image(:)

        if (.not. self%is_open) then
            call not_open(self, 'close_run', err)
            return
        end if
        if (status /= 'complete' .and. status /= 'failed' .and. status /= 'interrupted') then
            call make_error(err, ERR_INTERNAL, self%file%file_name()//': close_run: status "'// &
                            status//'" is not one of complete, failed, interrupted')
            return
        end if

        ! the records first: a file says 'complete' only when it holds all of them
        call write_pending(self, err)
        if (.not. allocated(err)) call self%file%attribute('/', 'status', trim(status), err)
        if (.not. allocated(err) .and. status /= 'complete') then
            if (present(reason)) then
                if (len_trim(reason) > 0) then
                    call self%file%attribute('/', 'reason', trim(reason), err)
                else
                    call self%file%attribute('/', 'reason', '(no reason given)', err)
                end if
            else
                call self%file%attribute('/', 'reason', '(no reason given)', err)
            end if
        end if
        if (.not. allocated(err)) call flush_file(self, err)
        if (.not. allocated(err) .and. present(image)) then
            if (self%file%in_memory()) call self%file%image(image, err)
        end if

        if (allocated(err)) then
            call abandon(self, err)
        else
            call shutdown(self, err)
        end if
    end subroutine output_close_run

    !> Records appended so far (written, or pending and written at the latest when the file
    !! is flushed, finished or closed).
    pure integer function output_records(self) result(records)
        class(output_file_t), intent(in) :: self
        records = int(self%n_records) + self%n_pending
    end function output_records

    !> Close the file if still open; its status stays 'running'.
    impure elemental subroutine output_final(self)
        type(output_file_t), intent(inout) :: self
        if (self%is_open) call shutdown(self)
    end subroutine output_final
end module ropedyn_output
