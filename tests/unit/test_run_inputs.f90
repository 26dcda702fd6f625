!> Unit test of ropedyn_run_inputs: the inputs of a scene (the scene file, a motion table,
!! a state file) and the refusal of an output that is one of them (by another name, a
!! symbolic link); check_replaceable: only a file that ropedyn wrote may be replaced (not a
!! text file, an HDF5 file of another program, a device). Files go to test_run_inputs_tmp/.
program test_run_inputs
    use, intrinsic :: iso_c_binding, only: c_char, c_int, c_null_char
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t, ERR_USAGE
    use ropedyn_os, only: make_dirs, delete_file
    use ropedyn_scene, only: scene_t, read_scene
    use ropedyn_h5, only: h5_file_t
    use ropedyn_output, only: output_file_t
    use ropedyn_run_inputs, only: check_not_input, check_replaceable
    use ropedyn_assert, only: test_suite_t
    implicit none

    interface
        integer(c_int) function c_symlink(target, path) bind(C, name='symlink')
            import :: c_char, c_int
            character(kind=c_char), intent(in) :: target(*), path(*)
        end function c_symlink
    end interface

    character(len=*), parameter :: DIR = 'test_run_inputs_tmp'
    type(test_suite_t) :: suite
    type(error_t), allocatable :: err
    type(scene_t) :: scene
    character(len=0) :: none(0)
    logical :: removed
    integer :: rc

    suite%name = 'run_inputs'
    call make_dirs(DIR, err)
    removed = delete_file(DIR//'/table_link.h5')
    call write_text(DIR//'/table.dat', ['0 0 0 0', '1 0 0 0'])
    call write_text(DIR//'/s.nml', [character(len=80) :: '&model elements = 4 /', &
                    "&supports top_motion = 'table', top_table = 'table.dat' /"])
    rc = c_symlink('table.dat'//c_null_char, DIR//'/table_link.h5'//c_null_char)
    call read_scene(DIR//'/s.nml', none, scene, err)
    call suite%check_true(.not. allocated(err), 'the scene reads')
    call test_not_input()
    call test_replaceable()
    call suite%finish()

contains

    subroutine write_text(path, lines)
        character(len=*), intent(in) :: path
        character(len=*), intent(in) :: lines(:)
        integer :: unit, k
        open (newunit=unit, file=path, status='replace', action='write')
        do k = 1, size(lines)
            write (unit, '(a)') trim(lines(k))
        end do
        close (unit)
    end subroutine write_text

    subroutine test_not_input()
        call check_not_input(DIR//'/out.h5', scene, err)
        call suite%check_true(.not. allocated(err), 'a new output is no input')
        call check_not_input(DIR//'/../'//DIR//'/s.nml', scene, err)
        call suite%check_true(allocated(err), 'the scene by another name: refused')
        if (allocated(err)) then
            call suite%check_true(err%code == ERR_USAGE, 'a usage error')
            call suite%check_contains(err%message, 'the output file is the scene file', &
                                      'names the scene')
        end if
        call check_not_input(DIR//'/table_link.h5', scene, err)
        call suite%check_true(allocated(err), 'a link to the table: refused')
        if (allocated(err)) call suite%check_contains(err%message, &
            'the motion table top_table', 'names the table')
        call check_not_input(DIR//'/out.h5', scene, err, [DIR//'/out.h5'], ['the sweep file'])
        call suite%check_true(allocated(err), 'an extra input: refused')
        if (allocated(err)) call suite%check_contains(err%message, 'the sweep file', &
                                                      'names it')
    end subroutine test_not_input

    subroutine test_replaceable()
        type(h5_file_t) :: h5
        type(output_file_t) :: out
        type(error_t), allocatable :: e
        call check_replaceable(DIR//'/none.h5', err)
        call suite%check_true(.not. allocated(err), 'no file: may be written')
        call check_replaceable(DIR//'/s.nml', err)
        call suite%check_true(allocated(err), 'a text file: refused')
        if (allocated(err)) call suite%check_contains(err%message, 'not an HDF5 file', &
                                                      'says why')
        call check_replaceable('/dev/null', err)
        call suite%check_true(allocated(err), 'a device: refused')
        if (allocated(err)) call suite%check_contains(err%message, 'a character device', &
                                                      'says what it is')
        call h5%create(DIR//'/foreign.h5', e)
        if (.not. allocated(e)) call h5%write('/x', [1.0_wp, 2.0_wp], 'm', e)
        if (.not. allocated(e)) call h5%close(e)
        call check_replaceable(DIR//'/foreign.h5', err)
        call suite%check_true(allocated(err), 'an HDF5 file of another program: refused')
        if (allocated(err)) call suite%check_contains(err%message, &
            'an HDF5 file not written by ropedyn', 'says why')
        call out%create(DIR//'/own.h5', 2, [0.5_wp, 0.5_wp], [1.0_wp, 1.0_wp], 'rfem', &
                        'erk', 'test', '&model elements = 2 /', e)
        if (.not. allocated(e)) call out%close_run('complete', '', e)
        call suite%check_true(.not. allocated(e), 'a run file written')
        call check_replaceable(DIR//'/own.h5', err)
        call suite%check_true(.not. allocated(err), 'a run file of ropedyn: may be replaced')
    end subroutine test_replaceable
end program test_run_inputs
