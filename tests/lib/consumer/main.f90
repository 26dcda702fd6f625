!> consumer_fortran SCENE: the same as consumer_c, from Fortran (module ropedyn_c).
program consumer_fortran
    use, intrinsic :: iso_c_binding, only: c_ptr, c_double, c_null_char
    use ropedyn_c
    implicit none
    type(c_ptr) :: sim
    real(c_double) :: force(2)
    character(len=4096) :: scene
    call get_command_argument(1, scene)
    if (ropedyn_create_from_file(trim(scene)//c_null_char, sim) /= ROPEDYN_OK) call fail()
    if (ropedyn_set(sim, 'model.elements=8'//c_null_char) /= ROPEDYN_OK) call fail()
    if (ropedyn_init(sim, 0) /= ROPEDYN_OK) call fail()
    if (ropedyn_advance(sim, 0.5_c_double) /= ROPEDYN_OK) call fail()
    if (ropedyn_reaction(sim, ROPEDYN_TOP, force) /= ROPEDYN_OK) call fail()
    write (*, '(a, 2es25.17)') 'fortran', force
    call ropedyn_destroy(sim)
contains
    subroutine fail()
        write (*, '(a)') 'ropedyn: error: '//ropedyn_text(ropedyn_last_error(sim))
        call ropedyn_destroy(sim)
        error stop 1
    end subroutine fail
end program consumer_fortran
