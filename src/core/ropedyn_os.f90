!> The operating-system services ropedyn needs, through POSIX: directories, the working
!! directory, renaming and removing files, whether a stream is a terminal, sleeping, the
!! number of processors; and, through the C glue `ropedyn_os.c`, what a path is (a regular
!! file, a FIFO, a device, ...), whether two paths are one file (device and inode, links
!! resolved), the system's text of an errno value and the holder of a file's lock.
module ropedyn_os
    use, intrinsic :: iso_c_binding, only: c_char, c_int, c_size_t, c_ptr, c_null_char, &
                                           c_associated, c_long_long
    use, intrinsic :: iso_fortran_env, only: int64
    use ropedyn_error, only: error_t, make_error, ERR_IO
    implicit none
    private
    public :: make_dirs, make_parent_dirs, current_dir, is_terminal, sleep_microseconds, &
              processor_count, absolute_path, unwritable_dir, rename_file, delete_file
    public :: file_kind, file_kind_name, special_file_reason, errno_text, real_path, &
              canonical_path, written_path, same_file, output_clash, lock_holder, try_lock, &
              reserve_space, release_space, create_whole
    public :: FILE_MISSING, FILE_REGULAR, FILE_DIRECTORY, FILE_FIFO, FILE_CHAR_DEVICE, &
              FILE_BLOCK_DEVICE, FILE_SOCKET, FILE_SYMLINK, FILE_OTHER

    !> What a path is (`file_kind`; the numbers of ropedyn_os.c).
    integer, parameter :: FILE_MISSING = 0, FILE_REGULAR = 1, FILE_DIRECTORY = 2, &
        FILE_FIFO = 3, FILE_CHAR_DEVICE = 4, FILE_BLOCK_DEVICE = 5, FILE_SOCKET = 6, &
        FILE_SYMLINK = 7, FILE_OTHER = 8
    !> errno values the callers tell apart (Linux)
    integer, parameter, public :: ERRNO_ENOENT = 2, ERRNO_EWOULDBLOCK = 11, ERRNO_EEXIST = 17, &
        ERRNO_ENOTDIR = 20, ERRNO_EFBIG = 27, ERRNO_ENOSPC = 28, ERRNO_EDQUOT = 122

    interface
        integer(c_int) function c_mkdir(path, mode) bind(C, name='ropedyn_mkdir')
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
        integer(c_int) function c_file_kind(path, follow, errnum) &
                bind(C, name='ropedyn_file_kind')
            import :: c_char, c_int
            character(kind=c_char), intent(in) :: path(*)
            integer(c_int), value :: follow
            integer(c_int), intent(out) :: errnum
        end function c_file_kind
        integer(c_int) function c_file_id(path, dev, ino) bind(C, name='ropedyn_file_id')
            import :: c_char, c_int, c_long_long
            character(kind=c_char), intent(in) :: path(*)
            integer(c_long_long), intent(out) :: dev, ino
        end function c_file_id
        integer(c_int) function c_real_path(path, buf, size) bind(C, name='ropedyn_real_path')
            import :: c_char, c_int
            character(kind=c_char), intent(in) :: path(*)
            character(kind=c_char), intent(out) :: buf(*)
            integer(c_int), value :: size
        end function c_real_path
        integer(c_int) function c_link_target(path, buf, size) bind(C, name='ropedyn_link_target')
            import :: c_char, c_int
            character(kind=c_char), intent(in) :: path(*)
            character(kind=c_char), intent(out) :: buf(*)
            integer(c_int), value :: size
        end function c_link_target
        subroutine c_errno_text(errnum, buf, size) bind(C, name='ropedyn_errno_text')
            import :: c_char, c_int
            integer(c_int), value :: errnum, size
            character(kind=c_char), intent(out) :: buf(*)
        end subroutine c_errno_text
        integer(c_int) function c_lock_holder(path) bind(C, name='ropedyn_lock_holder')
            import :: c_char, c_int
            character(kind=c_char), intent(in) :: path(*)
        end function c_lock_holder
        integer(c_int) function c_create_whole(path, text, length) &
                bind(C, name='ropedyn_create_whole')
            import :: c_char, c_int
            character(kind=c_char), intent(in) :: path(*), text(*)
            integer(c_int), value :: length
        end function c_create_whole
        integer(c_int) function c_try_lock(path) bind(C, name='ropedyn_try_lock')
            import :: c_char, c_int
            character(kind=c_char), intent(in) :: path(*)
        end function c_try_lock
        integer(c_int) function c_reserve_space(path, end, bytes) &
                bind(C, name='ropedyn_reserve_space')
            import :: c_char, c_int, c_long_long
            character(kind=c_char), intent(in) :: path(*)
            integer(c_long_long), value :: end, bytes
        end function c_reserve_space
        integer(c_int) function c_release_space(path) bind(C, name='ropedyn_release_space')
            import :: c_char, c_int
            character(kind=c_char), intent(in) :: path(*)
        end function c_release_space
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
                ! the system's reason (a file in the way, no permission, a full disk, ...)
                if (rc == 0 .or. rc == ERRNO_EEXIST) rc = ERRNO_ENOTDIR
                if (present(what)) then
                    call make_error(err, ERR_IO, what//': cannot create directory "'// &
                                    path(1:k - 1)//'": '//errno_text(rc))
                else
                    call make_error(err, ERR_IO, 'cannot create directory "'// &
                                    path(1:k - 1)//'": '//errno_text(rc))
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
        integer :: slash, errnum
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
            ! a dangling link (or a loop of links): mkdir cannot make a directory there
            if (file_kind(path, follow=.false.) == FILE_SYMLINK) then
                if (file_kind(path, errnum=errnum) == FILE_MISSING) then
                    reason = '"'//path//'" is a symbolic link to "'//link_target(path)// &
                        '": '//errno_text(errnum)
                    return
                end if
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

    !> The target of the symbolic link `path` as the link holds it ('' when it cannot be
    !! read).
    function link_target(path) result(target)
        character(len=*), intent(in) :: path
        character(len=:), allocatable :: target
        character(kind=c_char, len=4097) :: buf
        target = ''
        if (c_link_target(path//c_null_char, buf, int(len(buf), c_int)) /= 0) return
        target = buf(:index(buf, c_null_char) - 1)
    end function link_target

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

    !> Keep room on the file system for the file `path`: its blocks to its end (or to `end`
    !! bytes, the writer's idea of its end, when that is further) and `bytes` beyond
    !! allocated (its size unchanged), so that writing that much more cannot fail for want
    !! of space. 0, or the errno: ERRNO_ENOSPC / ERRNO_EDQUOT when there is not that much
    !! room left, ERRNO_EFBIG when the file-size limit (ulimit -f) is nearer; another (e.g.
    !! a file system that cannot reserve) when nothing is kept.
    integer function reserve_space(path, end, bytes)
        character(len=*), intent(in) :: path
        integer(int64), intent(in) :: end, bytes
        reserve_space = int(c_reserve_space(path//c_null_char, int(end, c_long_long), &
                                            int(bytes, c_long_long)))
    end function reserve_space

    !> Give back the room that reserve_space kept beyond the end of the file `path`.
    subroutine release_space(path)
        character(len=*), intent(in) :: path
        integer(c_int) :: rc
        rc = c_release_space(path//c_null_char)
    end subroutine release_space

    ! ---------------------------------------------------------------------------------------
    ! What a path is, and whether two paths are one file (ropedyn_os.c)
    ! ---------------------------------------------------------------------------------------

    !> What `path` is (FILE_*), symbolic links followed unless `follow` is false; FILE_MISSING
    !! when it cannot be had (`errnum`, if present: the errno, e.g. ERRNO_ENOENT).
    integer function file_kind(path, follow, errnum) result(kind)
        character(len=*), intent(in) :: path
        logical, intent(in), optional :: follow
        integer, intent(out), optional :: errnum
        integer(c_int) :: e, f
        f = 1
        if (present(follow)) f = merge(1_c_int, 0_c_int, follow)
        kind = int(c_file_kind(path//c_null_char, f, e))
        if (present(errnum)) errnum = int(e)
    end function file_kind

    !> 'a regular file', 'a directory', 'a FIFO (named pipe)', 'a character device', ...
    pure function file_kind_name(kind) result(name)
        integer, intent(in) :: kind
        character(len=:), allocatable :: name
        select case (kind)
        case (FILE_MISSING)
            name = 'missing'
        case (FILE_REGULAR)
            name = 'a regular file'
        case (FILE_DIRECTORY)
            name = 'a directory'
        case (FILE_FIFO)
            name = 'a FIFO (named pipe)'
        case (FILE_CHAR_DEVICE)
            name = 'a character device'
        case (FILE_BLOCK_DEVICE)
            name = 'a block device'
        case (FILE_SOCKET)
            name = 'a socket'
        case (FILE_SYMLINK)
            name = 'a symbolic link'
        case default
            name = 'not a regular file'
        end select
    end function file_kind_name

    !> Why `path` cannot be read as an input file although it exists: '' for a regular file
    !! (or one that is not there, or cannot be looked at: the opener says why), else e.g.
    !! 'a FIFO (named pipe), not a regular file'. Asked before an input is opened: a FIFO
    !! would block its reader, a device such as /dev/zero never end.
    function special_file_reason(path) result(reason)
        character(len=*), intent(in) :: path
        character(len=:), allocatable :: reason
        integer :: kind
        reason = ''
        kind = file_kind(path)
        if (kind == FILE_MISSING .or. kind == FILE_REGULAR) return
        reason = file_kind_name(kind)//', not a regular file'
        if (kind == FILE_DIRECTORY) reason = 'a directory, not a file'
    end function special_file_reason

    !> The system's text of the errno value `errnum`, e.g. 'No space left on device'.
    function errno_text(errnum) result(text)
        integer, intent(in) :: errnum
        character(len=:), allocatable :: text
        character(kind=c_char, len=256) :: buf
        integer :: k
        buf = repeat(c_null_char, len(buf))
        call c_errno_text(int(errnum, c_int), buf, int(len(buf), c_int))
        k = index(buf, c_null_char)
        if (k == 0) k = len(buf) + 1
        text = buf(:k - 1)
    end function errno_text

    !> realpath(3) of `path`: its absolute form with every link, '.' and '..' resolved
    !! (`errnum` 0); '' and the errno when it does not exist or cannot be resolved.
    function real_path(path, errnum) result(full)
        character(len=*), intent(in) :: path
        integer, intent(out), optional :: errnum
        character(len=:), allocatable :: full
        character(kind=c_char, len=4097) :: buf
        integer(c_int) :: rc
        integer :: k
        full = ''
        rc = c_real_path(path//c_null_char, buf, int(len(buf), c_int))
        if (present(errnum)) errnum = int(rc)
        if (rc /= 0) return
        k = index(buf, c_null_char)
        if (k > 0) full = buf(:k - 1)
    end function real_path

    !> The name of the file `path` refers to: its real_path when it exists, else the
    !! real_path of its directory followed by its last part (a file not created yet, or a
    !! dangling link's own name), else `path` made absolute.
    function canonical_path(path) result(full)
        character(len=*), intent(in) :: path
        character(len=:), allocatable :: full, dir
        integer :: slash
        full = real_path(path)
        if (len(full) > 0) return
        slash = index(path, '/', back=.true.)
        if (slash == 0) then
            dir = real_path('.')
        else if (slash == 1) then
            dir = '/'
        else
            dir = real_path(path(:slash - 1))
        end if
        if (len(dir) == 0) then
            full = absolute_path(path)
        else if (dir == '/') then
            full = '/'//path(slash + 1:)
        else
            full = dir//'/'//path(slash + 1:)
        end if
    end function canonical_path

    !> The file a write to `path` lands on: `path` itself, or for a symbolic link the file
    !! it points to (followed through links to links, 40 at most, as the system does), an
    !! existing one by its real_path, a missing one (a dangling link) by the canonical_path
    !! of the link's target, so that the file is created there and the link stays.
    function written_path(path) result(full)
        character(len=*), intent(in) :: path
        character(len=:), allocatable :: full, target
        character(kind=c_char, len=4097) :: buf
        integer :: hops, k, slash
        full = path
        if (file_kind(path, follow=.false.) /= FILE_SYMLINK) return
        if (file_kind(path) /= FILE_MISSING) then
            full = real_path(path)
            return
        end if
        do hops = 1, 40
            if (file_kind(full, follow=.false.) /= FILE_SYMLINK) exit
            if (c_link_target(full//c_null_char, buf, int(len(buf), c_int)) /= 0) exit
            k = index(buf, c_null_char)
            target = buf(:k - 1)
            slash = index(full, '/', back=.true.)
            if (target(1:1) /= '/' .and. slash > 0) target = full(:slash)//target
            full = target
        end do
        full = canonical_path(full)
    end function written_path

    !> Whether the paths `a` and `b` name one file: the same device and inode when both
    !! exist (links, relative paths and hard links alike), else the same canonical_path.
    logical function same_file(a, b)
        character(len=*), intent(in) :: a, b
        integer(c_long_long) :: dev_a, ino_a, dev_b, ino_b
        integer(c_int) :: rc_a, rc_b
        rc_a = c_file_id(trim(a)//c_null_char, dev_a, ino_a)
        rc_b = c_file_id(trim(b)//c_null_char, dev_b, ino_b)
        if (rc_a == 0 .and. rc_b == 0) then
            same_file = dev_a == dev_b .and. ino_a == ino_b
        else if (rc_a == 0 .neqv. rc_b == 0) then
            same_file = .false.
        else
            same_file = canonical_path(trim(a)) == canonical_path(trim(b))
        end if
    end function same_file

    !> The first of `inputs` (blank entries skipped; each trimmed) that is the same file
    !! as `output` (same_file): its index, 0 when there is none. An output that does not
    !! exist yet is compared by its canonical name (its directory resolved).
    integer function output_clash(output, inputs) result(k)
        character(len=*), intent(in) :: output
        character(len=*), intent(in) :: inputs(:)
        do k = 1, size(inputs)
            if (len_trim(inputs(k)) == 0) cycle
            if (same_file(output, trim(inputs(k)))) return
        end do
        k = 0
    end function output_clash

    !> The process that holds a lock on the file `path` (HDF5 locks the files it opens):
    !! its pid; 0 when none does; -1 when it cannot be told.
    integer function lock_holder(path)
        character(len=*), intent(in) :: path
        lock_holder = int(c_lock_holder(path//c_null_char))
    end function lock_holder

    !> Whether the existing file `path` could be locked exclusively now: 0 yes,
    !! ERRNO_EWOULDBLOCK when another process holds a lock on it, else the errno (the file
    !! is neither created nor truncated; a lock taken is released at once).
    !> Create the file `path` with the contents `text`, if no file of that name exists, so
    !! that it is never seen without them (a lock and its holder): 0 when created,
    !! ERRNO_EEXIST when `path` exists, else errno. A process killed while creating it
    !! leaves no `path`, or `path` whole (ropedyn_os.c tells the ways, by file system).
    integer function create_whole(path, text)
        character(len=*), intent(in) :: path, text
        create_whole = int(c_create_whole(path//c_null_char, text, int(len(text), c_int)))
    end function create_whole

    integer function try_lock(path)
        character(len=*), intent(in) :: path
        try_lock = int(c_try_lock(path//c_null_char))
    end function try_lock
end module ropedyn_os
