!> One instance of the library (include/ropedyn.h): a scene, read from a file or from
!! namelist text with `--set` overrides, and the simulation built from it (a run without
!! output, `ropedyn_run`), with the message of the last error. Each instance owns all it
!! uses: instances do not share state, so that two can run in two threads.
!!
!! Life cycle: created (the scene only: `set` may change it) -> `init` (model, integrator,
!! start state; from statics on request) -> `advance` and the rest -> destroyed. A scene
!! that could not be read leaves an instance whose every later call returns the reader's
!! error (it has no scene to set, show, run or simulate). A failed integration ends the
!! simulation: every later call that moves it on returns that error.
!! `run_whole` runs the scene from its start to t_end as `ropedyn run` does (records into
!! a file, or into a file in memory whose bytes it returns) without touching the
!! simulation.
module ropedyn_lib
    use, intrinsic :: iso_fortran_env, only: int8
    use, intrinsic :: iso_c_binding, only: c_char
    use ropedyn_kinds, only: wp
    use ropedyn_rope_model, only: energy_t
    use ropedyn_error, only: error_t, make_error, ERR_USAGE, ERR_INPUT
    use ropedyn_text, only: text_t, append_text
    use ropedyn_scene, only: scene_t, read_scene, read_scene_string
    use ropedyn_scene_warnings, only: scene_warnings
    use ropedyn_run, only: run_t, run_snapshot_t, STEP_RECORDED, OUTPUT_FILE, OUTPUT_MEMORY, &
                           OUTPUT_NONE
    implicit none
    private
    public :: instance_t, snapshot_t, new_instance, delete_instance, new_snapshot, &
              delete_snapshot
    public :: STAGE_SCENE, STAGE_RUNNING, STAGE_FAILED, STAGE_UNREAD

    !> Where an instance is in its life cycle (STAGE_UNREAD: its scene could not be read).
    integer, parameter :: STAGE_SCENE = 0, STAGE_RUNNING = 1, STAGE_FAILED = 2, &
                          STAGE_UNREAD = 3

    type :: instance_t
        !> the scene's origin: a file (from_file) or a name for the text
        character(len=:), allocatable :: origin, text
        logical :: from_file = .false.
        type(text_t), allocatable :: overrides(:)
        type(scene_t) :: scene
        type(run_t), allocatable :: run
        integer :: stage = STAGE_SCENE
        !> the error that ended the simulation (STAGE_FAILED) or the reading (STAGE_UNREAD)
        type(error_t), allocatable :: failure
        !> what the C interface hands out: the last error's message, a text (the scene,
        !! the warnings) and a run's file image, NUL-terminated where text; runs into
        !! memory so far (their files' names)
        character(kind=c_char), allocatable :: message(:), text_out(:)
        integer(int8), allocatable :: image(:)
        integer :: runs = 0
    contains
        procedure :: create => instance_create
        procedure :: readable => instance_readable
        procedure :: unread => instance_unread
        procedure :: set => instance_set
        procedure :: init => instance_init
        procedure :: running => instance_running
        procedure :: advance => instance_advance
        procedure :: run_whole => instance_run_whole
        procedure :: warnings => instance_warnings
        procedure :: revive => instance_revive
        procedure :: has_state => instance_has_state
        procedure :: release => instance_release
        ! the simulation's own calls (run_t; the C interface calls them only through here)
        procedure :: time => instance_time
        procedure :: elements => instance_elements
        procedure :: state_size => instance_state_size
        procedure :: get_state => instance_get_state
        procedure :: set_state => instance_set_state
        procedure :: points => instance_points
        procedure :: forces => instance_forces
        procedure :: anchors => instance_anchors
        procedure :: energy => instance_energy
        procedure :: set_support => instance_set_support
        procedure :: save => instance_save
        procedure :: restore => instance_restore
        procedure, private :: read
    end type instance_t

    !> A kept state of an instance's simulation.
    type :: snapshot_t
        type(run_snapshot_t) :: snap
    end type snapshot_t

contains

    !> A new instance on the heap (the C interface's handle; the instance is made and freed
    !! here: gfortran 12 gave the finalizers called in the C interface's own module, which
    !! defines a symbol ropedyn_run, that symbol's name).
    function new_instance() result(p)
        type(instance_t), pointer :: p
        allocate (p)
    end function new_instance

    !> Free an instance and what it holds.
    subroutine delete_instance(p)
        type(instance_t), pointer, intent(inout) :: p
        if (.not. associated(p)) return
        call p%release()
        deallocate (p)
    end subroutine delete_instance

    !> A new snapshot on the heap, and its end.
    function new_snapshot() result(p)
        type(snapshot_t), pointer :: p
        allocate (p)
    end function new_snapshot

    subroutine delete_snapshot(p)
        type(snapshot_t), pointer, intent(inout) :: p
        if (associated(p)) deallocate (p)
    end subroutine delete_snapshot

    !> Read the scene: from the file `origin` (text absent), or from `text`, named `origin`.
    subroutine instance_create(self, origin, err, text)
        class(instance_t), intent(inout) :: self
        character(len=*), intent(in) :: origin
        type(error_t), allocatable, intent(out) :: err
        character(len=*), intent(in), optional :: text
        self%origin = origin
        self%from_file = .not. present(text)
        if (present(text)) self%text = text
        allocate (self%overrides(0))
        call self%read(err)
        if (allocated(err)) call self%unread(err)
    end subroutine instance_create

    !> The instance has no scene: `err` (the reader's error, or a create call's bad
    !! argument) is what every later call returns.
    subroutine instance_unread(self, err)
        class(instance_t), intent(inout) :: self
        type(error_t), intent(in) :: err
        self%stage = STAGE_UNREAD
        self%failure = err
    end subroutine instance_unread

    !> Whether the instance has a scene (else `err` is the error that reading it gave).
    logical function instance_readable(self, err) result(readable)
        class(instance_t), intent(in) :: self
        type(error_t), allocatable, intent(out) :: err
        readable = self%stage /= STAGE_UNREAD
        if (.not. readable) call make_error(err, self%failure%code, self%failure%message)
    end function instance_readable

    !> The scene from its origin with the overrides so far.
    subroutine read(self, err)
        class(instance_t), intent(inout) :: self
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: list(:)
        integer :: k, width
        width = 1
        do k = 1, size(self%overrides)
            width = max(width, len(self%overrides(k)%s))
        end do
        allocate (character(len=width) :: list(size(self%overrides)))
        do k = 1, size(self%overrides)
            list(k) = self%overrides(k)%s
        end do
        if (self%from_file) then
            call read_scene(self%origin, list, self%scene, err)
        else
            call read_scene_string(self%origin, self%text, list, self%scene, err)
        end if
    end subroutine read

    !> Apply `group.key=value` as `--set` does (before `init`); several separated by new
    !! lines are applied together (as several --set). A bad one changes nothing.
    subroutine instance_set(self, setting, err)
        class(instance_t), intent(inout) :: self
        character(len=*), intent(in) :: setting
        type(error_t), allocatable, intent(out) :: err
        type(error_t), allocatable :: again
        integer :: before, start, nl
        if (.not. self%readable(err)) return
        if (self%stage /= STAGE_SCENE) then
            call make_error(err, ERR_USAGE, 'set: the simulation has started: a scene '// &
                            'changes only before init')
            return
        end if
        before = size(self%overrides)
        start = 1
        do while (start <= len(setting))
            nl = index(setting(start:), new_line('a'))
            if (nl == 0) nl = len(setting) - start + 2
            if (len_trim(setting(start:start + nl - 2)) > 0) &
                call append_text(self%overrides, trim(adjustl(setting(start:start + nl - 2))))
            start = start + nl
        end do
        call self%read(err)
        if (allocated(err)) then
            self%overrides = self%overrides(:before)
            call self%read(again)
        end if
    end subroutine instance_set

    !> Build the simulation: model, integrator, start state (with `from_statics`: the static
    !! equilibrium, at rest, whatever the scene's &initial shape).
    subroutine instance_init(self, from_statics, err)
        class(instance_t), intent(inout) :: self
        logical, intent(in) :: from_statics
        type(error_t), allocatable, intent(out) :: err
        type(scene_t) :: scene
        if (.not. self%readable(err)) return
        if (self%stage /= STAGE_SCENE) then
            call make_error(err, ERR_USAGE, 'init: the simulation has started already')
            return
        end if
        scene = self%scene
        if (from_statics) scene%initial%shape = 'equilibrium'
        allocate (self%run)
        call self%run%open(scene, err, output=OUTPUT_NONE)
        if (.not. allocated(err)) call self%run%begin(err)
        if (allocated(err)) then
            call self%run%release()
            deallocate (self%run)
            return
        end if
        self%stage = STAGE_RUNNING
    end subroutine instance_init

    !> Whether the simulation runs (else `err` says why not: not started, failed, or no
    !! scene).
    logical function instance_running(self, what, err) result(running)
        class(instance_t), intent(in) :: self
        character(len=*), intent(in) :: what
        type(error_t), allocatable, intent(out) :: err
        running = self%stage == STAGE_RUNNING
        if (running) return
        if (self%stage == STAGE_FAILED .or. self%stage == STAGE_UNREAD) then
            call make_error(err, self%failure%code, self%failure%message)
        else
            call make_error(err, ERR_USAGE, what//': the simulation has not started (init)')
        end if
    end function instance_running

    !> Advance the simulation to time t (s); a failed integration ends it.
    subroutine instance_advance(self, t, err)
        class(instance_t), intent(inout) :: self
        real(wp), intent(in) :: t
        type(error_t), allocatable, intent(out) :: err
        if (.not. self%running('advance', err)) return
        call self%run%advance(t, err)
        if (allocated(err)) then
            if (err%code /= ERR_USAGE) then
                self%stage = STAGE_FAILED
                self%failure = err
            end if
        end if
    end subroutine instance_advance

    !> Run the scene from its start to t_end as `ropedyn run` does (no signals caught):
    !! into the file `output` (guarded as the command line's), or into a file in memory
    !! whose bytes come back in `image` (output ''; `name` unique in the process).
    subroutine instance_run_whole(self, output, name, image, err)
        class(instance_t), intent(inout) :: self
        character(len=*), intent(in) :: output, name
        integer(int8), allocatable, intent(out) :: image(:)
        type(error_t), allocatable, intent(out) :: err
        type(run_t), allocatable :: run
        type(scene_t) :: scene
        integer :: outcome
        if (.not. self%readable(err)) return
        scene = self%scene
        allocate (run)
        if (len(output) > 0) then
            if (len(output) > len(scene%output%file)) then
                call make_error(err, ERR_INPUT, 'run: the output file name is too long')
                return
            end if
            scene%output%file = output
            scene%output%file_origin = ''   ! (named by the caller, not by a key)
            call run%open(scene, err)
        else
            call run%open(scene, err, output=OUTPUT_MEMORY, name=name)
        end if
        if (allocated(err)) then
            call run%release()
            return
        end if
        call run%begin(err)
        if (allocated(err)) then
            call run%finish('failed', (err%message), err)
        else
            outcome = STEP_RECORDED
            do while (.not. run%done() .and. outcome == STEP_RECORDED)
                call run%step(outcome, err)
            end do
            if (outcome == STEP_RECORDED) call run%finish('complete', '', err)
        end if
        call run%take_image(image)
        call run%release()
    end subroutine instance_run_whole

    !> The simulation runs again (a kept state restored after a failure).
    subroutine instance_revive(self)
        class(instance_t), intent(inout) :: self
        if (self%stage == STAGE_FAILED) self%stage = STAGE_RUNNING
        if (allocated(self%failure)) deallocate (self%failure)
    end subroutine instance_revive

    !> Whether the simulation has a state to read (started, maybe failed since).
    pure logical function instance_has_state(self)
        class(instance_t), intent(in) :: self
        instance_has_state = self%stage /= STAGE_SCENE .and. allocated(self%run)
    end function instance_has_state

    !> Free the simulation's memory outside Fortran's reach (before the instance goes).
    subroutine instance_release(self)
        class(instance_t), intent(inout) :: self
        if (allocated(self%run)) call self%run%release()
    end subroutine instance_release

    ! The simulation's calls (valid with `has_state`; run_t says what each does).

    real(wp) function instance_time(self)
        class(instance_t), intent(in) :: self
        instance_time = self%run%time()
    end function instance_time

    integer function instance_elements(self)
        class(instance_t), intent(in) :: self
        instance_elements = self%run%elements()
    end function instance_elements

    integer function instance_state_size(self)
        class(instance_t), intent(in) :: self
        instance_state_size = self%run%state_size()
    end function instance_state_size

    subroutine instance_get_state(self, y)
        class(instance_t), intent(in) :: self
        real(wp), intent(out) :: y(:)
        call self%run%get_state(y)
    end subroutine instance_get_state

    subroutine instance_set_state(self, y, err)
        class(instance_t), intent(inout) :: self
        real(wp), intent(in) :: y(:)
        type(error_t), allocatable, intent(out) :: err
        call self%run%set_state(y, err)
    end subroutine instance_set_state

    subroutine instance_points(self, points)
        class(instance_t), intent(in) :: self
        real(wp), intent(out) :: points(:, :)
        call self%run%points_now(points)
    end subroutine instance_points

    subroutine instance_forces(self, axial, shear, moment, reaction)
        class(instance_t), intent(inout) :: self
        real(wp), intent(out) :: axial(0:), shear(0:), moment(0:), reaction(:, :)
        call self%run%forces_now(axial, shear, moment, reaction)
    end subroutine instance_forces

    subroutine instance_anchors(self, anchors)
        class(instance_t), intent(in) :: self
        real(wp), intent(out) :: anchors(:, :)
        call self%run%anchors_now(anchors)
    end subroutine instance_anchors

    subroutine instance_energy(self, e)
        class(instance_t), intent(inout) :: self
        type(energy_t), intent(out) :: e
        call self%run%energy_now(e)
    end subroutine instance_energy

    subroutine instance_set_support(self, k, p, v, err)
        class(instance_t), intent(inout) :: self
        integer, intent(in) :: k
        real(wp), intent(in) :: p(2), v(2)
        type(error_t), allocatable, intent(out) :: err
        call self%run%set_support(k, p, v, err)
    end subroutine instance_set_support

    subroutine instance_save(self, snap, err)
        class(instance_t), intent(inout) :: self
        type(snapshot_t), intent(out) :: snap
        type(error_t), allocatable, intent(out) :: err
        call self%run%save(snap%snap, err)
    end subroutine instance_save

    !> Back to a kept state; after a failure the simulation runs again.
    subroutine instance_restore(self, snap, err)
        class(instance_t), intent(inout) :: self
        type(snapshot_t), intent(in) :: snap
        type(error_t), allocatable, intent(out) :: err
        call self%run%restore(snap%snap, err)
        if (.not. allocated(err)) call self%revive()
    end subroutine instance_restore

    !> The scene's warnings (values legal but probably a unit slip), one a line.
    function instance_warnings(self) result(text)
        class(instance_t), intent(in) :: self
        character(len=:), allocatable :: text
        type(text_t), allocatable :: list(:)
        integer :: k
        list = scene_warnings(self%scene)
        text = ''
        do k = 1, size(list)
            text = text//list(k)%s//new_line('a')
        end do
    end function instance_warnings
end module ropedyn_lib
