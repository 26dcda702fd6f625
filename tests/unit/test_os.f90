!> Unit test of the file-system helpers of ropedyn_os: what a path is (regular file,
!! directory, FIFO, device, link), errno texts, and whether two paths name one file
!! (relative paths, '..', symbolic and hard links, files not created yet), the check that
!! keeps a run's output off its inputs. Files go to test_os_tmp/ under the working
!! directory.
program test_os
    use, intrinsic :: iso_c_binding, only: c_char, c_int, c_null_char
    use ropedyn_error, only: error_t
    use ropedyn_os, only: make_dirs, file_kind, special_file_reason, errno_text, real_path, &
        canonical_path, same_file, output_clash, try_lock, current_dir, delete_file, &
        FILE_REGULAR, FILE_DIRECTORY, FILE_FIFO, FILE_CHAR_DEVICE, FILE_SYMLINK, &
        FILE_MISSING, ERRNO_ENOENT
    use ropedyn_assert, only: test_suite_t
    implicit none

    interface
        integer(c_int) function c_symlink(target, path) bind(C, name='symlink')
            import :: c_char, c_int
            character(kind=c_char), intent(in) :: target(*), path(*)
        end function c_symlink
        integer(c_int) function c_link(old, new) bind(C, name='link')
            import :: c_char, c_int
            character(kind=c_char), intent(in) :: old(*), new(*)
        end function c_link
        integer(c_int) function c_mkfifo(path, mode) bind(C, name='mkfifo')
            import :: c_char, c_int
            character(kind=c_char), intent(in) :: path(*)
            integer(c_int), value :: mode
        end function c_mkfifo
    end interface

    character(len=*), parameter :: DIR = 'test_os_tmp'
    type(test_suite_t) :: suite
    type(error_t), allocatable :: err
    logical :: removed
    integer :: rc

    suite%name = 'os'
    call make_dirs(DIR//'/sub', err)
    call suite%check_true(.not. allocated(err), 'create '//DIR)
    removed = delete_file(DIR//'/link')
    removed = delete_file(DIR//'/hard')
    removed = delete_file(DIR//'/fifo')
    removed = delete_file(DIR//'/dangling')
    call write_file(DIR//'/a.nml')
    call write_file(DIR//'/b.nml')
    rc = c_symlink('a.nml'//c_null_char, DIR//'/link'//c_null_char)
    rc = c_link(DIR//'/a.nml'//c_null_char, DIR//'/hard'//c_null_char)
    rc = c_mkfifo(DIR//'/fifo'//c_null_char, int(o'644', c_int))
    rc = c_symlink('nowhere.h5'//c_null_char, DIR//'/dangling'//c_null_char)
    call test_kinds()
    call test_same_file()
    call test_clash()
    call suite%finish()

contains

    subroutine write_file(path)
        character(len=*), intent(in) :: path
        integer :: unit
        open (newunit=unit, file=path, status='replace', action='write')
        write (unit, '(a)') '&model elements = 4 /'
        close (unit)
    end subroutine write_file

    subroutine test_kinds()
        integer :: errnum
        call suite%check_true(file_kind(DIR//'/a.nml') == FILE_REGULAR, 'a file is regular')
        call suite%check_true(file_kind(DIR) == FILE_DIRECTORY, 'a directory')
        call suite%check_true(file_kind(DIR//'/fifo') == FILE_FIFO, 'a FIFO')
        call suite%check_true(file_kind('/dev/zero') == FILE_CHAR_DEVICE, '/dev/zero: a device')
        call suite%check_true(file_kind(DIR//'/link') == FILE_REGULAR, 'a link is followed')
        call suite%check_true(file_kind(DIR//'/link', follow=.false.) == FILE_SYMLINK, &
                              'a link not followed')
        call suite%check_true(file_kind(DIR//'/none', errnum=errnum) == FILE_MISSING .and. &
                              errnum == ERRNO_ENOENT, 'a missing file: ENOENT')
        call suite%check_true(special_file_reason(DIR//'/a.nml') == '', 'regular: no reason')
        call suite%check_true(special_file_reason(DIR//'/none') == '', 'missing: no reason')
        call suite%check_contains(special_file_reason(DIR//'/fifo'), &
                                  'a FIFO (named pipe), not a regular file', 'a FIFO refused')
        call suite%check_contains(special_file_reason('/dev/zero'), 'a character device', &
                                  '/dev/zero refused')
        call suite%check_contains(special_file_reason(DIR), 'a directory, not a file', &
                                  'a directory refused')
        call suite%check_true(errno_text(28) == 'No space left on device', 'errno 28: ENOSPC')
        call suite%check_true(errno_text(2) == 'No such file or directory', 'errno 2')
        call suite%check_true(try_lock(DIR//'/a.nml') == 0, 'a free file can be locked')
        call suite%check_true(try_lock(DIR//'/none') == ERRNO_ENOENT, 'no lock: no file')
    end subroutine test_kinds

    subroutine test_same_file()
        character(len=:), allocatable :: here
        here = current_dir()
        call suite%check_true(real_path(DIR//'/sub/../a.nml') == here//'/'//DIR//'/a.nml', &
                              'real_path resolves ..')
        call suite%check_true(canonical_path(DIR//'/sub/../new.h5') == &
                              here//'/'//DIR//'/new.h5', 'canonical_path of a file not there')
        call suite%check_true(same_file(DIR//'/a.nml', DIR//'/sub/../a.nml'), 'same: ..')
        call suite%check_true(same_file(DIR//'/a.nml', here//'/'//DIR//'/a.nml'), &
                              'same: absolute and relative')
        call suite%check_true(same_file(DIR//'/link', DIR//'/a.nml'), 'same: a symbolic link')
        call suite%check_true(same_file(DIR//'/hard', DIR//'/a.nml'), 'same: a hard link')
        call suite%check_true(.not. same_file(DIR//'/b.nml', DIR//'/a.nml'), 'two files')
        call suite%check_true(.not. same_file(DIR//'/new.h5', DIR//'/a.nml'), &
                              'a file not there is not an existing one')
        call suite%check_true(same_file(DIR//'/new.h5', DIR//'/sub/../new.h5'), &
                              'two names of one file not there yet')
        call suite%check_true(.not. same_file(DIR//'/dangling', DIR//'/a.nml'), &
                              'a dangling link is not the file')
    end subroutine test_same_file

    subroutine test_clash()
        character(len=20) :: inputs(3)
        inputs = [character(len=20) :: DIR//'/b.nml', '', DIR//'/a.nml']
        call suite%check_true(output_clash(DIR//'/link', inputs) == 3, &
                              'clash: the output is a link to an input')
        call suite%check_true(output_clash(DIR//'/hard', inputs) == 3, &
                              'clash: the output is a hard link of an input')
        call suite%check_true(output_clash(DIR//'/out.h5', inputs) == 0, 'no clash')
        call suite%check_true(output_clash(DIR//'/sub/../b.nml', inputs) == 1, &
                              'clash: the first input, by another path')
    end subroutine test_clash
end program test_os
