!> ropedyn_c: the C interface of libropedyn (ropedyn.h) for Fortran programs, as bind(C)
!! interfaces of the same names and arguments. Strings go in NUL-terminated
!! (`'input/paper.nml'//c_null_char`); texts come back as C pointers (`ropedyn_text` turns
!! one into a Fortran string). Statuses, supports and the rules of each call: ropedyn.h.
!! With CMake: find_package(ropedyn) and link ropedyn::fortran (this file, compiled into
!! the target).
module ropedyn_c
    use, intrinsic :: iso_c_binding, only: c_ptr, c_int, c_double, c_char, c_size_t, &
        c_f_pointer, c_associated
    implicit none
    private
    public :: ropedyn_version, ropedyn_create_from_file, ropedyn_create_from_text, &
        ropedyn_set, ropedyn_scene_text, ropedyn_warnings, ropedyn_init, ropedyn_advance, &
        ropedyn_time, ropedyn_size, ropedyn_get_state, ropedyn_set_state, ropedyn_points, &
        ropedyn_forces, ropedyn_reaction, ropedyn_support_position, ropedyn_energy, &
        ropedyn_set_support, ropedyn_save, ropedyn_restore, ropedyn_snapshot_destroy, &
        ropedyn_run, ropedyn_last_error, ropedyn_destroy, ropedyn_text
    public :: ROPEDYN_OK, ROPEDYN_ERROR_INPUT, ROPEDYN_ERROR_SOLVER, ROPEDYN_ERROR_IO, &
        ROPEDYN_ERROR_INTERNAL, ROPEDYN_TOP, ROPEDYN_BOTTOM

    integer(c_int), parameter :: ROPEDYN_OK = 0, ROPEDYN_ERROR_INPUT = 2, &
        ROPEDYN_ERROR_SOLVER = 3, ROPEDYN_ERROR_IO = 4, ROPEDYN_ERROR_INTERNAL = 5
    integer(c_int), parameter :: ROPEDYN_TOP = 0, ROPEDYN_BOTTOM = 1

    interface
        type(c_ptr) function ropedyn_version() bind(C, name='ropedyn_version')
            import :: c_ptr
        end function ropedyn_version
        integer(c_int) function ropedyn_create_from_file(path, sim) &
                bind(C, name='ropedyn_create_from_file')
            import :: c_int, c_char, c_ptr
            character(kind=c_char), intent(in) :: path(*)
            type(c_ptr), intent(out) :: sim
        end function ropedyn_create_from_file
        integer(c_int) function ropedyn_create_from_text(text, name, sim) &
                bind(C, name='ropedyn_create_from_text')
            import :: c_int, c_char, c_ptr
            character(kind=c_char), intent(in) :: text(*), name(*)
            type(c_ptr), intent(out) :: sim
        end function ropedyn_create_from_text
        integer(c_int) function ropedyn_set(sim, setting) bind(C, name='ropedyn_set')
            import :: c_int, c_char, c_ptr
            type(c_ptr), value :: sim
            character(kind=c_char), intent(in) :: setting(*)
        end function ropedyn_set
        integer(c_int) function ropedyn_scene_text(sim, text) bind(C, name='ropedyn_scene_text')
            import :: c_int, c_ptr
            type(c_ptr), value :: sim
            type(c_ptr), intent(out) :: text
        end function ropedyn_scene_text
        integer(c_int) function ropedyn_warnings(sim, text) bind(C, name='ropedyn_warnings')
            import :: c_int, c_ptr
            type(c_ptr), value :: sim
            type(c_ptr), intent(out) :: text
        end function ropedyn_warnings
        integer(c_int) function ropedyn_init(sim, from_statics) bind(C, name='ropedyn_init')
            import :: c_int, c_ptr
            type(c_ptr), value :: sim
            integer(c_int), value :: from_statics
        end function ropedyn_init
        integer(c_int) function ropedyn_advance(sim, t) bind(C, name='ropedyn_advance')
            import :: c_int, c_ptr, c_double
            type(c_ptr), value :: sim
            real(c_double), value :: t
        end function ropedyn_advance
        integer(c_int) function ropedyn_time(sim, t) bind(C, name='ropedyn_time')
            import :: c_int, c_ptr, c_double
            type(c_ptr), value :: sim
            real(c_double), intent(out) :: t
        end function ropedyn_time
        integer(c_int) function ropedyn_size(sim, elements, state_size) &
                bind(C, name='ropedyn_size')
            import :: c_int, c_ptr
            type(c_ptr), value :: sim
            integer(c_int), intent(out) :: elements, state_size
        end function ropedyn_size
        integer(c_int) function ropedyn_get_state(sim, y, size) bind(C, name='ropedyn_get_state')
            import :: c_int, c_ptr, c_double
            type(c_ptr), value :: sim
            integer(c_int), value :: size
            real(c_double), intent(out) :: y(size)
        end function ropedyn_get_state
        integer(c_int) function ropedyn_set_state(sim, y, size) bind(C, name='ropedyn_set_state')
            import :: c_int, c_ptr, c_double
            type(c_ptr), value :: sim
            integer(c_int), value :: size
            real(c_double), intent(in) :: y(size)
        end function ropedyn_set_state
        integer(c_int) function ropedyn_points(sim, xy, count) bind(C, name='ropedyn_points')
            import :: c_int, c_ptr, c_double
            type(c_ptr), value :: sim
            integer(c_int), value :: count
            real(c_double), intent(out) :: xy(2, count)
        end function ropedyn_points
        integer(c_int) function ropedyn_forces(sim, axial, shear, moment, joints) &
                bind(C, name='ropedyn_forces')
            import :: c_int, c_ptr, c_double
            type(c_ptr), value :: sim
            integer(c_int), value :: joints
            real(c_double), intent(out) :: axial(joints), shear(joints), moment(joints)
        end function ropedyn_forces
        integer(c_int) function ropedyn_reaction(sim, support, force) &
                bind(C, name='ropedyn_reaction')
            import :: c_int, c_ptr, c_double
            type(c_ptr), value :: sim
            integer(c_int), value :: support
            real(c_double), intent(out) :: force(2)
        end function ropedyn_reaction
        integer(c_int) function ropedyn_support_position(sim, support, position) &
                bind(C, name='ropedyn_support_position')
            import :: c_int, c_ptr, c_double
            type(c_ptr), value :: sim
            integer(c_int), value :: support
            real(c_double), intent(out) :: position(2)
        end function ropedyn_support_position
        integer(c_int) function ropedyn_energy(sim, energy) bind(C, name='ropedyn_energy')
            import :: c_int, c_ptr, c_double
            type(c_ptr), value :: sim
            real(c_double), intent(out) :: energy(6)
        end function ropedyn_energy
        integer(c_int) function ropedyn_set_support(sim, support, position, velocity) &
                bind(C, name='ropedyn_set_support')
            import :: c_int, c_ptr, c_double
            type(c_ptr), value :: sim
            integer(c_int), value :: support
            real(c_double), intent(in) :: position(2), velocity(2)
        end function ropedyn_set_support
        integer(c_int) function ropedyn_save(sim, snapshot) bind(C, name='ropedyn_save')
            import :: c_int, c_ptr
            type(c_ptr), value :: sim
            type(c_ptr), intent(out) :: snapshot
        end function ropedyn_save
        integer(c_int) function ropedyn_restore(sim, snapshot) bind(C, name='ropedyn_restore')
            import :: c_int, c_ptr
            type(c_ptr), value :: sim, snapshot
        end function ropedyn_restore
        subroutine ropedyn_snapshot_destroy(snapshot) bind(C, name='ropedyn_snapshot_destroy')
            import :: c_ptr
            type(c_ptr), value :: snapshot
        end subroutine ropedyn_snapshot_destroy
        integer(c_int) function ropedyn_run(sim, output, image, size) bind(C, name='ropedyn_run')
            import :: c_int, c_ptr, c_char, c_size_t
            type(c_ptr), value :: sim
            character(kind=c_char), intent(in) :: output(*)
            type(c_ptr), intent(out) :: image
            integer(c_size_t), intent(out) :: size
        end function ropedyn_run
        type(c_ptr) function ropedyn_last_error(sim) bind(C, name='ropedyn_last_error')
            import :: c_ptr
            type(c_ptr), value :: sim
        end function ropedyn_last_error
        subroutine ropedyn_destroy(sim) bind(C, name='ropedyn_destroy')
            import :: c_ptr
            type(c_ptr), value :: sim
        end subroutine ropedyn_destroy
        pure integer(c_size_t) function c_strlen(s) bind(C, name='strlen')
            import :: c_ptr, c_size_t
            type(c_ptr), value :: s
        end function c_strlen
    end interface

contains

    !> The C string at `p` as a Fortran string ('' for a null pointer).
    function ropedyn_text(p) result(s)
        type(c_ptr), intent(in) :: p
        character(len=:), allocatable :: s
        character(kind=c_char), pointer :: chars(:)
        integer :: k, n
        if (.not. c_associated(p)) then
            s = ''
            return
        end if
        n = int(c_strlen(p))
        call c_f_pointer(p, chars, [n])
        allocate (character(len=n) :: s)
        do k = 1, n
            s(k:k) = chars(k)
        end do
    end function ropedyn_text
end module ropedyn_c
