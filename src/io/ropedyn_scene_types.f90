!> The scene: the rope models' parameters (`rope_spec_t`, src/models) plus the solver and the
!! output. Every component's default initialization is its key's default; the key table
!! (`ropedyn_scene_keys`) names each component once, with its rule, unit and meaning.
module ropedyn_scene_types
    use ropedyn_kinds, only: wp
    use ropedyn_rope_spec, only: rope_spec_t, NAME_LEN, PATH_LEN
    use ropedyn_integrator, only: DEFAULT_RTOL, DEFAULT_ATOL
    implicit none
    private
    public :: solver_params_t, output_params_t, scene_t

    !> `&solver`: time integration.
    type :: solver_params_t
        character(len=NAME_LEN) :: method = 'auto'  !< ropedyn_methods' names
        real(wp) :: rtol = DEFAULT_RTOL       !< relative tolerance [-]
        real(wp) :: atol = DEFAULT_ATOL       !< absolute tolerance [state units]
        !> highest order of accuracy; 0 in the file: the method's default (resolved by
        !! `read_scene` with `resolved_max_order`, so that the stored scene says it)
        integer :: max_order = 0
        !> step budget for the whole run; 0: the default for the run's length
        !! (`default_step_budget` of t_end, resolved when the run starts, so that a resume to a
        !! later t_end has the budget of its length) [-]
        integer :: max_steps = 0
        real(wp) :: t_end = 30.0_wp           !< end time [s]
        real(wp) :: output_interval = 0.01_wp !< time between output records [s]
        !> CVODE only: BDF stability-limit detection (lowers the order near the stability
        !! boundary of lightly damped oscillatory modes)
        logical :: stability_limit_detection = .false.
        !> Newton systems on the first-order matrix of all unknowns instead of the reduced
        !! second-order one (half the size; the default for the rope models)
        logical :: first_order_newton = .false.
        !> time the parts of the integration (right-hand side, Jacobian, factorizations,
        !! solves): printed and written to /solver (costs a few % on small ropes)
        logical :: profile = .false.
        !> what the run does when the energy balance gains more than energy_gain_bound:
        !! 'lower' the order to the method's A-stable one if, over the same output interval,
        !! that order does better (else the gain is the integration error: the order kept),
        !! 'stop' (a diagnosed failure), or 'off' (no check); docs/theory/energy-balance.md
        character(len=NAME_LEN) :: order_safety = 'lower'
        !> the gain that counts, in units of rtol S (S: the energy scale of the run) [-]
        real(wp) :: energy_gain_bound = 10.0_wp
    end type solver_params_t

    !> `&output`: where results go.
    type :: output_params_t
        !> HDF5 file; resolved by `read_scene` ('' in the file: out/<scene name>.h5)
        character(len=PATH_LEN) :: file = ''
        !> print progress while integrating (when `progress_given`; else: on when stderr
        !! is a terminal)
        logical :: progress = .false.
        logical :: progress_given = .false.   !< the file or a --set gives `progress`
        !> where `file` was set, for messages: the scene file or the `--set` argument (the
        !! scene's path when neither set it: the default); '' when the caller named the file
        !! instead (the library's whole run)
        character(len=:), allocatable :: file_origin
    end type output_params_t

    !> A complete scene: the rope models' parameters (the parent `rope_spec_t`, whose
    !! `path` is the file the scene was read from), the solver and the output.
    type, extends(rope_spec_t) :: scene_t
        type(solver_params_t) :: solver
        type(output_params_t) :: output
        !> where the scene came from: the scene file's full name and the --set overrides in
        !! their order, but those of &output ('/dir/a.nml --set model.elements=70'); a run
        !! file stores it, and a
        !! run replaces only a file of its own source (the output guide, "Write, lock and
        !! resume rules")
        character(len=:), allocatable :: source
        !> a resumed run's --set overrides in their order, ' --set group.key=value' each
        !! ('' for none; set by read_scene_text): /solver/restarts/overrides records them
        character(len=:), allocatable :: overrides
    end type scene_t
end module ropedyn_scene_types
