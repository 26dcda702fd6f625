!> The operating-system services ropedyn needs, through POSIX: directories, the working
!! directory, renaming and removing files, whether a stream is a terminal, sleeping, the
!! number of processors.
module ropedyn_os
    use, intrinsic :: iso_c_binding, only: c_char, c_int, c_size_t, c_ptr, c_null_char, &
                                           c_associated
    use ropedyn_error, only: error_t, make_error, ERR_IO
    implicit none
    private
    public :: make_dirs, make_parent_dirs, current_dir, is_terminal, sleep_microseconds, &
              processor_count, absolute_path, unwritable_dir, rename_file, delete_file

    interface
        integer(c_int) function c_mkdir(path, mode) bind(C, name='mkdir')
            import :: c_char, c_int
            character(kind=c_char), intent(in) :: path(*)
            integer(c_int), value :: mode
        end function c_mkdir
        function c_getcwd(buf, size) bind(C, name='getcwd') result(p)
            import :: c_char, c_size_t, c_ptr
            character(kind=c_char), intent(out) :: buf(*)
            integer(c_size_t), value :: size
            type(c_ptr) :: p
        end function c_getcwd
        integer(c_int) function c_isatty(fd) bind(C, name='isatty')
            import :: c_int
            integer(c_int), value :: fd
        end function c_isatty
        integer(c_int) function c_usleep(microseconds) bind(C, name='usleep')
            import :: c_int
            integer(c_int), value :: microseconds
        end function c_usleep
        integer(c_int) function c_get_nprocs() bind(C, name='get_nprocs')
            import :: c_int
        end function c_get_nprocs
        integer(c_int) function c_rename(old, new) bind(C, name='rename')
            import :: c_char, c_int
            character(kind=c_char), intent(in) :: old(*), new(*)
        end function c_rename
        integer(c_int) function c_unlink(path) bind(C, name='unlink')
            import :: c_char, c_int
            character(kind=c_char), intent(in) :: path(*)
        end function c_unlink
        integer(c_int) function c_access(path, mode) bind(C, name='access')
            import :: c_char, c_int
            character(kind=c_char), intent(in) :: path(*)
            integer(c_int), value :: mode
        end function c_access
    end interface

contains

    !> mkdir -p of `dir`; `what` starts the error message (e.g. the command or file).
    subroutine make_dirs(dir, err, what)
        character(len=*), intent(in) :: dir
        type(error_t), allocatable, intent(out) :: err
        character(len=*), intent(in), optional :: what
        integer :: k, rc
        logical :: exists
        character(len=:), allocatable :: path
        path = dir//'/'
        do k = 2, len(path)
            if (path(k:k) /= '/') cycle
            inquire (file=path(1:k - 1)//'/.', exist=exists)
            if (exists) cycle
            rc = c_mkdir(path(1:k - 1)//c_null_char, int(o'755', c_int))
            inquire (file=path(1:k - 1)//'/.', exist=exists)
            if (.not. exists) then
                if (present(what)) then
                    call make_error(err, ERR_IO, what//': cannot create directory "'// &
                                    path(1:k - 1)//'"')
                else
                    call make_error(err, ERR_IO, 'cannot create directory "'// &
                                    path(1:k - 1)//'"')
                end if
                return
            end if
        end do
    end subroutine make_dirs

    !> mkdir -p of the directory part of the file name `path`.
    subroutine make_parent_dirs(path, err)
        character(len=*), intent(in) :: path
        type(error_t), allocatable, intent(out) :: err
        integer :: slash
        slash = index(trim(path), '/', back=.true.)
        if (slash <= 1) return
        call make_dirs(path(:slash - 1), err, path)
    end subroutine make_parent_dirs

    !> The working directory ('' if it cannot be found).
    function current_dir() result(dir)
        character(len=:), allocatable :: dir
        character(kind=c_char, len=4096) :: buf
        integer :: k
        dir = ''
        if (.not. c_associated(c_getcwd(buf, int(len(buf), c_size_t)))) return
        k = index(buf, c_null_char)
        if (k <= 1) return
        dir = buf(:k - 1)
    end function current_dir

    !> `name` made absolute: as given when it starts with '/', else relative to the
    !! directory of the file `relative_to` (if given) and then to the working directory.
    function absolute_path(name, relative_to) result(full)
        character(len=*), intent(in) :: name
        character(len=*), intent(in), optional :: relative_to
        character(len=:), allocatable :: full, cwd
        integer :: slash
        if (name(1:1) == '/') then
            full = name
            return
        end if
        full = name
        if (present(relative_to)) then
            slash = index(relative_to, '/', back=.true.)
            full = relative_to(:slash)//name
            if (full(1:1) == '/') return
        end if
        cwd = current_dir()
        if (len(cwd) > 0) full = cwd//'/'//full
    end function absolute_path

    !> Why `dir` could not be created or written by `make_dirs` and the files in it: '' when
    !! it is a writable directory or its nearest existing ancestor is one, else the reason
    !! (creates nothing).
    function unwritable_dir(dir) result(reason)
        character(len=*), intent(in) :: dir
        character(len=:), allocatable :: reason, path
        integer(c_int), parameter :: W_OK = 2, X_OK = 1
        logical :: exists, is_dir
        integer :: slash
        path = trim(dir)
        if (len(path) == 0) path = '.'
        do
            inquire (file=path//'/.', exist=is_dir)
            if (is_dir) exit
            inquire (file=path, exist=exists)
            if (exists) then
                reason = '"'//path//'" is not a directory'
                return
            end if
            slash = index(path, '/', back=.true.)
            if (slash == 0) then
                path = '.'
            else if (slash == 1) then
                path = '/'
            else
                path = path(:slash - 1)
            end if
        end do
        reason = ''
        if (c_access(path//c_null_char, W_OK + X_OK) /= 0) reason = 'the directory "'// &
            path//'" is not writable'
    end function unwritable_dir

    !> rename(2): `old` becomes `new` in one step (replacing `new`; both in the same file
    !! system).
    subroutine rename_file(old, new, err)
        character(len=*), intent(in) :: old, new
        type(error_t), allocatable, intent(out) :: err
        if (c_rename(old//c_null_char, new//c_null_char) /= 0) call make_error(err, ERR_IO, &
            'cannot rename "'//old//'" to "'//new//'"')
    end subroutine rename_file

    !> Remove the file `path`; true if it was removed (false also when it did not exist).
    logical function delete_file(path) result(removed)
        character(len=*), intent(in) :: path
        removed = c_unlink(path//c_null_char) == 0
    end function delete_file

    !> True when the file descriptor (0 stdin, 1 stdout, 2 stderr) is a terminal.
    logical function is_terminal(fd)
        integer, intent(in) :: fd
        is_terminal = c_isatty(int(fd, c_int)) == 1
    end function is_terminal

    subroutine sleep_microseconds(us)
        integer, intent(in) :: us
        integer(c_int) :: rc
        rc = c_usleep(int(us, c_int))
    end subroutine sleep_microseconds

    !> Number of processors available (at least 1).
    integer function processor_count()
        processor_count = max(1, int(c_get_nprocs()))
    end function processor_count
end module ropedyn_os
