!> The C interface of the library, include/ropedyn.h: every function there is a bind(C)
!! procedure here (named capi_NAME for ropedyn_NAME), over an instance of ropedyn_lib. A
!! handle (ropedyn_t *) is the address of an `instance_t` made by the create functions and
!! freed by ropedyn_destroy; it holds the scene, the simulation and the texts handed out
!! (the last error's message, the scene text, the warnings, a run's file image), each
!! valid until the next call on that handle. Every function but the getters of texts
!! returns a status: 0, or the exit code of the command line for the error's class (2 bad
!! input or call, 3 integration failed, 4 output, 5 internal), with ropedyn_last_error
!! saying what the command line would print after "ropedyn: error: ". Nothing here is
!! shared between handles.
!!
!! This module touches the run (ropedyn_run) only through ropedyn_lib: in a file that
!! defines the C symbol ropedyn_run, gfortran 12 emitted calls of that module's procedures
!! and finalizers as calls of that symbol.
module ropedyn_capi
    use, intrinsic :: iso_c_binding, only: c_ptr, c_int, c_double, c_char, c_size_t, &
        c_null_ptr, c_null_char, c_loc, c_f_pointer, c_associated, c_intptr_t
    use, intrinsic :: iso_fortran_env, only: int8
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t, make_error, exit_code_of, ERR_USAGE
    use ropedyn_text, only: int_text
    use ropedyn_c_strings, only: c_string
    use ropedyn_version, only: version_string
    use ropedyn_rope_model, only: energy_t
    use ropedyn_scene, only: scene_namelist_text
    use ropedyn_lib, only: instance_t, snapshot_t, new_instance, delete_instance, new_snapshot, &
        delete_snapshot
    implicit none
    private


    !> The version as a C string: a constant (ropedyn_version hands out its address).
    character(kind=c_char), target :: VERSION_C(len(version_string) + 1) = &
        transfer(version_string//c_null_char, 'a', len(version_string) + 1)

contains

    ! ---- helpers ---------------------------------------------------------------------

    !> `text` as a NUL-terminated C array.
    pure function c_text(text) result(chars)
        character(len=*), intent(in) :: text
        character(kind=c_char), allocatable :: chars(:)
        integer :: k
        allocate (chars(len(text) + 1))
        do k = 1, len(text)
            chars(k) = text(k:k)
        end do
        chars(len(text) + 1) = c_null_char
    end function c_text

    !> The handle at `sim` (null for NULL).
    function handle_of(sim) result(h)
        type(c_ptr), intent(in) :: sim
        type(instance_t), pointer :: h
        h => null()
        if (c_associated(sim)) call c_f_pointer(sim, h)
    end function handle_of

    !> The status of `err` (0 without one); its message becomes the handle's last error.
    integer(c_int) function status_of(h, err) result(status)
        type(instance_t), intent(inout) :: h
        type(error_t), allocatable, intent(in) :: err
        status = 0
        if (allocated(h%message)) deallocate (h%message)
        if (.not. allocated(err)) return
        status = int(exit_code_of(err%code), c_int)
        h%message = c_text(err%message)
    end function status_of

    !> A new handle for the create functions: its address in `sim_out` (not NULL).
    function new_handle(sim_out) result(h)
        type(c_ptr), intent(in) :: sim_out
        type(instance_t), pointer :: h
        type(c_ptr), pointer :: out
        h => new_instance()
        call c_f_pointer(sim_out, out)
        out = c_loc(h)
    end function new_handle

    !> Support index of C (0 top, 1 bottom) as the run's (1, 2); 0 if neither.
    pure integer function support_of(support)
        integer(c_int), intent(in) :: support
        support_of = 0
        if (support == 0 .or. support == 1) support_of = support + 1
    end function support_of

    !> The error of a call on a NULL handle or with a NULL argument.
    subroutine null_argument(what, err)
        character(len=*), intent(in) :: what
        type(error_t), allocatable, intent(out) :: err
        call make_error(err, ERR_USAGE, what//' is NULL')
    end subroutine null_argument

    !> Whether the simulation of `h` has a state to read (started, maybe failed since).
    logical function has_state(h, what, err)
        type(instance_t), intent(in) :: h
        character(len=*), intent(in) :: what
        type(error_t), allocatable, intent(out) :: err
        has_state = .false.
        if (.not. h%readable(err)) return
        has_state = h%has_state()
        if (.not. has_state) call make_error(err, ERR_USAGE, what// &
            ': the simulation has not started (init)')
    end function has_state

    ! ---- life cycle ------------------------------------------------------------------

    function capi_version() result(text) bind(C, name='ropedyn_f_version')
        type(c_ptr) :: text
        text = c_loc(VERSION_C)
    end function capi_version

    integer(c_int) function capi_create_from_file(path, sim) result(status) &
            bind(C, name='ropedyn_f_create_from_file')
        type(c_ptr), value :: path, sim
        type(instance_t), pointer :: h
        type(error_t), allocatable :: err
        status = 2
        if (.not. c_associated(sim)) return   ! nowhere to put the instance
        h => new_handle(sim)
        if (.not. c_associated(path)) then
            call null_argument('create_from_file: the path', err)
            call h%unread(err)
        else
            call h%create(c_string(path), err)
        end if
        status = status_of(h, err)
    end function capi_create_from_file

    integer(c_int) function capi_create_from_text(text, name, sim) result(status) &
            bind(C, name='ropedyn_f_create_from_text')
        type(c_ptr), value :: text, name, sim
        type(instance_t), pointer :: h
        type(error_t), allocatable :: err
        character(len=:), allocatable :: origin
        status = 2
        if (.not. c_associated(sim)) return   ! nowhere to put the instance
        h => new_handle(sim)
        origin = c_string(name)
        if (len(origin) == 0) origin = 'scene'
        if (.not. c_associated(text)) then
            call null_argument('create_from_text: the text', err)
            call h%unread(err)
        else
            call h%create(origin, err, text=c_string(text))
        end if
        status = status_of(h, err)
    end function capi_create_from_text

    subroutine capi_destroy(sim) bind(C, name='ropedyn_f_destroy')
        type(c_ptr), value :: sim
        type(instance_t), pointer :: h
        h => handle_of(sim)
        if (.not. associated(h)) return
        call delete_instance(h)
    end subroutine capi_destroy

    function capi_last_error(sim) result(message) bind(C, name='ropedyn_f_last_error')
        type(c_ptr), value :: sim
        type(c_ptr) :: message
        type(instance_t), pointer :: h
        message = c_null_ptr
        h => handle_of(sim)
        if (.not. associated(h)) return
        if (.not. allocated(h%message)) h%message = c_text('')
        message = c_loc(h%message)
    end function capi_last_error

    integer(c_int) function capi_set(sim, setting) result(status) bind(C, name='ropedyn_f_set')
        type(c_ptr), value :: sim, setting
        type(instance_t), pointer :: h
        type(error_t), allocatable :: err
        status = 2
        h => handle_of(sim)
        if (.not. associated(h)) return
        if (.not. c_associated(setting)) then
            call null_argument('set: the setting', err)
        else
            call h%set(c_string(setting), err)
        end if
        status = status_of(h, err)
    end function capi_set

    integer(c_int) function capi_scene_text(sim, text) result(status) &
            bind(C, name='ropedyn_f_scene_text')
        type(c_ptr), value :: sim, text
        type(instance_t), pointer :: h
        type(c_ptr), pointer :: out
        type(error_t), allocatable :: err
        status = 2
        h => handle_of(sim)
        if (.not. associated(h)) return
        if (.not. c_associated(text)) then
            call null_argument('scene_text: the text', err)
        else if (h%readable(err)) then
            h%text_out = c_text(scene_namelist_text(h%scene))
            call c_f_pointer(text, out)
            out = c_loc(h%text_out)
        end if
        status = status_of(h, err)
    end function capi_scene_text

    integer(c_int) function capi_warnings(sim, text) result(status) &
            bind(C, name='ropedyn_f_warnings')
        type(c_ptr), value :: sim, text
        type(instance_t), pointer :: h
        type(c_ptr), pointer :: out
        type(error_t), allocatable :: err
        status = 2
        h => handle_of(sim)
        if (.not. associated(h)) return
        if (.not. c_associated(text)) then
            call null_argument('warnings: the text', err)
        else if (h%readable(err)) then
            h%text_out = c_text(h%warnings())
            call c_f_pointer(text, out)
            out = c_loc(h%text_out)
        end if
        status = status_of(h, err)
    end function capi_warnings

    integer(c_int) function capi_init(sim, from_statics) result(status) &
            bind(C, name='ropedyn_f_init')
        type(c_ptr), value :: sim
        integer(c_int), value :: from_statics
        type(instance_t), pointer :: h
        type(error_t), allocatable :: err
        status = 2
        h => handle_of(sim)
        if (.not. associated(h)) return
        call h%init(from_statics /= 0, err)
        status = status_of(h, err)
    end function capi_init

    integer(c_int) function capi_run(sim, output, image, nbytes) result(status) &
            bind(C, name='ropedyn_f_run')
        type(c_ptr), value :: sim, output, image, nbytes
        type(instance_t), pointer :: h
        type(c_ptr), pointer :: image_out
        integer(c_size_t), pointer :: size_out
        type(error_t), allocatable :: err
        character(len=32) :: name
        status = 2
        h => handle_of(sim)
        if (.not. associated(h)) return
        if (allocated(h%image)) deallocate (h%image)
        h%runs = h%runs + 1
        ! the name of the file in memory: unique in the process (this handle's address)
        write (name, '(a, z0, a, i0)') 'memory-', transfer(sim, 0_c_intptr_t), '-', h%runs
        call h%run_whole(c_string(output), trim(name), h%image, err)
        if (c_associated(image)) then
            call c_f_pointer(image, image_out)
            image_out = c_null_ptr
            if (allocated(h%image)) image_out = c_loc(h%image)
        end if
        if (c_associated(nbytes)) then
            call c_f_pointer(nbytes, size_out)
            size_out = 0
            if (allocated(h%image)) size_out = int(size(h%image), c_size_t)
        end if
        status = status_of(h, err)
    end function capi_run

    ! ---- the simulation ----------------------------------------------------------------

    integer(c_int) function capi_advance(sim, t) result(status) bind(C, name='ropedyn_f_advance')
        type(c_ptr), value :: sim
        real(c_double), value :: t
        type(instance_t), pointer :: h
        type(error_t), allocatable :: err
        status = 2
        h => handle_of(sim)
        if (.not. associated(h)) return
        call h%advance(real(t, wp), err)
        status = status_of(h, err)
    end function capi_advance

    integer(c_int) function capi_time(sim, t) result(status) bind(C, name='ropedyn_f_time')
        type(c_ptr), value :: sim, t
        type(instance_t), pointer :: h
        type(error_t), allocatable :: err
        real(c_double), pointer :: out(:)
        status = 2
        out => zeroed(t, 1)
        h => handle_of(sim)
        if (.not. associated(h)) return
        if (.not. associated(out)) then
            call null_argument('time: t', err)
        else if (has_state(h, 'time', err)) then
            out(1) = real(h%time(), c_double)
        end if
        status = status_of(h, err)
    end function capi_time

    integer(c_int) function capi_size(sim, elements, state_size) result(status) &
            bind(C, name='ropedyn_f_size')
        type(c_ptr), value :: sim, elements, state_size
        type(instance_t), pointer :: h
        type(error_t), allocatable :: err
        integer(c_int), pointer :: n_out, size_out
        integer(c_int), target :: scratch(2)
        status = 2
        ! a NULL pointer stands for an integer nobody reads (the call then fails)
        n_out => scratch(1)
        size_out => scratch(2)
        if (c_associated(elements)) call c_f_pointer(elements, n_out)
        if (c_associated(state_size)) call c_f_pointer(state_size, size_out)
        n_out = 0
        size_out = 0
        h => handle_of(sim)
        if (.not. associated(h)) return
        if (.not. (c_associated(elements) .and. c_associated(state_size))) then
            call null_argument('size: elements or state_size', err)
        else if (has_state(h, 'size', err)) then
            n_out = int(h%elements(), c_int)
            size_out = int(h%state_size(), c_int)
        end if
        status = status_of(h, err)
    end function capi_size

    integer(c_int) function capi_get_state(sim, y, size) result(status) &
            bind(C, name='ropedyn_f_get_state')
        type(c_ptr), value :: sim, y
        integer(c_int), value :: size
        type(instance_t), pointer :: h
        type(error_t), allocatable :: err
        status = 2
        h => handle_of(sim)
        if (.not. associated(h)) return
        if (.not. c_associated(y)) then
            call null_argument('get_state: y', err)
        else if (has_state(h, 'get_state', err)) then
            if (size /= h%state_size()) then
                call make_error(err, ERR_USAGE, 'get_state: size '//int_text(int(size))// &
                    ', the state has '//int_text(h%state_size()))
            else
                call h%get_state(doubles_at(y, int(size)))
            end if
        end if
        status = status_of(h, err)
    end function capi_get_state

    integer(c_int) function capi_set_state(sim, y, size) result(status) &
            bind(C, name='ropedyn_f_set_state')
        type(c_ptr), value :: sim, y
        integer(c_int), value :: size
        type(instance_t), pointer :: h
        type(error_t), allocatable :: err
        status = 2
        h => handle_of(sim)
        if (.not. associated(h)) return
        if (.not. c_associated(y)) then
            call null_argument('set_state: y', err)
        else if (h%running('set_state', err)) then
            call h%set_state(doubles_at(y, max(0, int(size))), err)
        end if
        status = status_of(h, err)
    end function capi_set_state

    integer(c_int) function capi_points(sim, xy, count) result(status) &
            bind(C, name='ropedyn_f_points')
        type(c_ptr), value :: sim, xy
        integer(c_int), value :: count
        type(instance_t), pointer :: h
        type(error_t), allocatable :: err
        real(c_double), pointer :: out(:, :)
        status = 2
        h => handle_of(sim)
        if (.not. associated(h)) return
        if (.not. c_associated(xy)) then
            call null_argument('points: xy', err)
        else if (has_state(h, 'points', err)) then
            if (count /= 2*h%elements()) then
                call make_error(err, ERR_USAGE, 'points: count '//int_text(int(count))// &
                    ', the rope has '//int_text(2*h%elements())//' points')
            else
                call c_f_pointer(xy, out, [2, int(count)])
                call h%points(out)
            end if
        end if
        status = status_of(h, err)
    end function capi_points

    integer(c_int) function capi_forces(sim, axial, shear, moment, joints) result(status) &
            bind(C, name='ropedyn_f_forces')
        type(c_ptr), value :: sim, axial, shear, moment
        integer(c_int), value :: joints
        type(instance_t), pointer :: h
        type(error_t), allocatable :: err
        real(wp), allocatable :: a(:), s(:), m(:)
        real(wp) :: reaction(2, 2)
        status = 2
        h => handle_of(sim)
        if (.not. associated(h)) return
        if (has_state(h, 'forces', err)) then
            if (joints /= h%elements() + 1) then
                call make_error(err, ERR_USAGE, 'forces: joints '//int_text(int(joints))// &
                    ', the rope has '//int_text(h%elements() + 1))
            else
                allocate (a(0:joints - 1), s(0:joints - 1), m(0:joints - 1))
                call h%forces(a, s, m, reaction)
                call put(axial, a)
                call put(shear, s)
                call put(moment, m)
            end if
        end if
        status = status_of(h, err)
    end function capi_forces

    !> The C array of `n` doubles at `p` (not NULL).
    function doubles_at(p, n) result(values)
        type(c_ptr), intent(in) :: p
        integer, intent(in) :: n
        real(c_double), pointer :: values(:)
        call c_f_pointer(p, values, [n])
    end function doubles_at

    !> The C array of `n` doubles at `p`, set to 0 (disassociated for NULL).
    function zeroed(p, n) result(values)
        type(c_ptr), intent(in) :: p
        integer, intent(in) :: n
        real(c_double), pointer :: values(:)
        values => null()
        if (.not. c_associated(p)) return
        call c_f_pointer(p, values, [n])
        values = 0.0_c_double
    end function zeroed

    !> Copy `values` to the C array at `p` (nothing for NULL).
    subroutine put(p, values)
        type(c_ptr), intent(in) :: p
        real(wp), intent(in) :: values(:)
        real(c_double), pointer :: out(:)
        if (.not. c_associated(p)) return
        call c_f_pointer(p, out, [size(values)])
        out = values
    end subroutine put

    integer(c_int) function capi_reaction(sim, support, force) result(status) &
            bind(C, name='ropedyn_f_reaction')
        type(c_ptr), value :: sim, force
        integer(c_int), value :: support
        type(instance_t), pointer :: h
        type(error_t), allocatable :: err
        real(wp), allocatable :: a(:), s(:), m(:)
        real(wp) :: reaction(2, 2)
        real(c_double), pointer :: out(:)
        integer :: n
        status = 2
        out => zeroed(force, 2)
        h => handle_of(sim)
        if (.not. associated(h)) return
        if (.not. associated(out)) then
            call null_argument('reaction: force', err)
        else if (support_of(support) == 0) then
            call make_error(err, ERR_USAGE, 'reaction: support '//int_text(int(support))// &
                            ' (0 top, 1 bottom)')
        else if (has_state(h, 'reaction', err)) then
            n = h%elements()
            allocate (a(0:n), s(0:n), m(0:n))
            call h%forces(a, s, m, reaction)
            out = reaction(:, support_of(support))
        end if
        status = status_of(h, err)
    end function capi_reaction

    integer(c_int) function capi_support_position(sim, support, position) result(status) &
            bind(C, name='ropedyn_f_support_position')
        type(c_ptr), value :: sim, position
        integer(c_int), value :: support
        type(instance_t), pointer :: h
        type(error_t), allocatable :: err
        real(wp) :: anchors(2, 2)
        real(c_double), pointer :: out(:)
        status = 2
        out => zeroed(position, 2)
        h => handle_of(sim)
        if (.not. associated(h)) return
        if (.not. associated(out)) then
            call null_argument('support_position: position', err)
        else if (support_of(support) == 0) then
            call make_error(err, ERR_USAGE, 'support_position: support '// &
                            int_text(int(support))//' (0 top, 1 bottom)')
        else if (has_state(h, 'support_position', err)) then
            call h%anchors(anchors)
            out = anchors(:, support_of(support))
        end if
        status = status_of(h, err)
    end function capi_support_position

    integer(c_int) function capi_energy(sim, energy) result(status) &
            bind(C, name='ropedyn_f_energy')
        type(c_ptr), value :: sim, energy
        type(instance_t), pointer :: h
        type(error_t), allocatable :: err
        type(energy_t) :: e
        real(c_double), pointer :: out(:)
        status = 2
        out => zeroed(energy, 6)
        h => handle_of(sim)
        if (.not. associated(h)) return
        if (.not. associated(out)) then
            call null_argument('energy: energy', err)
        else if (has_state(h, 'energy', err)) then
            call h%energy(e)
            out = [e%kinetic, e%elastic, e%gravity, e%dissipated, e%support_work, e%total()]
        end if
        status = status_of(h, err)
    end function capi_energy

    integer(c_int) function capi_set_support(sim, support, position, velocity) &
            result(status) bind(C, name='ropedyn_f_set_support')
        type(c_ptr), value :: sim, position, velocity
        integer(c_int), value :: support
        type(instance_t), pointer :: h
        type(error_t), allocatable :: err
        status = 2
        h => handle_of(sim)
        if (.not. associated(h)) return
        if (.not. (c_associated(position) .and. c_associated(velocity))) then
            call null_argument('set_support: the position or velocity', err)
        else if (support_of(support) == 0) then
            call make_error(err, ERR_USAGE, 'set_support: support '//int_text(int(support))// &
                            ' (0 top, 1 bottom)')
        else if (h%running('set_support', err)) then
            call h%set_support(support_of(support), real(doubles_at(position, 2), wp), &
                               real(doubles_at(velocity, 2), wp), err)
        end if
        status = status_of(h, err)
    end function capi_set_support

    integer(c_int) function capi_save(sim, snapshot) result(status) bind(C, name='ropedyn_f_save')
        type(c_ptr), value :: sim, snapshot
        type(instance_t), pointer :: h
        type(snapshot_t), pointer :: snap
        type(c_ptr), pointer :: out
        type(error_t), allocatable :: err
        status = 2
        h => handle_of(sim)
        if (.not. associated(h)) return
        if (.not. c_associated(snapshot)) then
            call null_argument('save: the snapshot', err)
        else if (h%running('save', err)) then
            call c_f_pointer(snapshot, out)
            out = c_null_ptr
            snap => new_snapshot()
            call h%save(snap, err)
            if (allocated(err)) then
                call delete_snapshot(snap)
            else
                out = c_loc(snap)
            end if
        end if
        status = status_of(h, err)
    end function capi_save

    integer(c_int) function capi_restore(sim, snapshot) result(status) &
            bind(C, name='ropedyn_f_restore')
        type(c_ptr), value :: sim, snapshot
        type(instance_t), pointer :: h
        type(snapshot_t), pointer :: snap
        type(error_t), allocatable :: err
        status = 2
        h => handle_of(sim)
        if (.not. associated(h)) return
        if (.not. c_associated(snapshot)) then
            call null_argument('restore: the snapshot', err)
        else if (has_state(h, 'restore', err)) then
            ! also after a failure: the simulation goes on from the kept state
            call c_f_pointer(snapshot, snap)
            call h%restore(snap, err)
        end if
        status = status_of(h, err)
    end function capi_restore

    subroutine capi_snapshot_destroy(snapshot) bind(C, name='ropedyn_f_snapshot_destroy')
        type(c_ptr), value :: snapshot
        type(snapshot_t), pointer :: snap
        if (.not. c_associated(snapshot)) return
        call c_f_pointer(snapshot, snap)
        call delete_snapshot(snap)
    end subroutine capi_snapshot_destroy
end module ropedyn_capi
