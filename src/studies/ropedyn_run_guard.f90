!> The guard of a run's output file (the output guide, "Write, lock and resume rules"):
!!
!! - no input of the run (its scene, motion tables, state file) is its output;
!! - an output that is a symbolic link is the file it points to (a loop or a name too long
!!   for FILE.part is an error with the system's reason);
!! - FILE.lock is taken before anything is written, the lock a sweep case takes, so that a
!!   second run on the same file is refused before it touches it; a resume continues FILE
!!   in place under that lock, and a resume of FILE.part is refused while the run of FILE
!!   that writes it holds FILE.lock;
!! - a new run replaces an existing FILE only when it is a file ropedyn wrote for the same
!!   source (the same scene file with the same --set overrides: a rerun); another file, a
!!   run of another scene or of a --set variant, is refused unless --force; a special file
!!   (a device, a FIFO, a link to one) always;
!! - a new run writes FILE.part and renames it to FILE when it finishes (complete, failed
!!   or interrupted), so that the earlier FILE stays whole until the new one is; a FILE.part
!!   left by a killed run is refused (resume it, or remove it) unless --force, and while a
!!   resume of it goes on, always.
submodule (ropedyn_run) ropedyn_run_guard
    use ropedyn_os, only: make_parent_dirs, rename_file, delete_file, special_file_reason, &
                          file_kind, real_path, written_path, errno_text, FILE_SYMLINK, &
                          FILE_MISSING
    use ropedyn_sweep_lock, only: take_lock, drop_lock, read_lock, lock_t
    use ropedyn_run_inputs, only: check_not_input, check_may_replace
    use ropedyn_error, only: ERR_USAGE, ERR_IO
    use ropedyn_h5, only: h5_file_t
    use ropedyn_text, only: replaced
    implicit none

    !> The longest name of a file in a directory (Linux's NAME_MAX).
    integer, parameter :: NAME_MAX = 255

contains

    module procedure guard_output
        character(len=:), allocatable :: file, given
        logical :: exists, removed
        integer :: errnum
        file = self%summary%file
        given = file
        if (.not. resume) then
            call check_not_input(file, self%scene, err, label=output_key(self%scene, given))
            if (allocated(err)) return
            call make_parent_dirs(file, err)
            if (allocated(err)) return
            if (len(special_file_reason(file)) > 0) then
                call make_error(err, ERR_USAGE, output_key(self%scene, file)// &
                    ': exists and is '//special_file_reason(file)//': not replaced')
                return
            end if
            ! a link: the file it points to (written there, renamed there; the link stays)
            if (file_kind(file, follow=.false.) == FILE_SYMLINK) then
                if (file_kind(file) == FILE_MISSING) then
                    ! a dangling link (or a loop: the system's reason)
                    if (len(real_path(file, errnum)) == 0 .and. errnum /= 2) then
                        call make_error(err, ERR_IO, self%summary%file//': cannot create '// &
                                        'file: '//errno_text(errnum))
                        return
                    end if
                end if
                file = written_path(file)
                call make_parent_dirs(file, err)
                if (allocated(err)) return
            end if
            if (len(file) - index(file, '/', back=.true.) + len('.part') > NAME_MAX) then
                call make_error(err, ERR_IO, file//': cannot create file: File name too '// &
                                'long (the run writes FILE.part and FILE.lock beside it)')
                return
            end if
        end if
        if (resume) then
            call writers_gone(file, self%writer_gone, err)
        else if (.not. force) then
            ! a FILE.part left by a killed run, refused before its abandoned lock is taken
            ! (and removed): that lock tells the resume of FILE.part who wrote it
            call check_part_left(file, err)
        end if
        if (allocated(err)) return
        call take_lock(file//'.lock', self%beat, err)
        if (allocated(err)) then
            err%message = file//': '//err%message
            return
        end if
        self%lock_file = file//'.lock'
        if (resume) return
        ! a new run: is there a FILE.part of a killed run, may it replace FILE?
        inquire (file=file//'.part', exist=exists)
        if (exists) call check_part_idle(file//'.part', err)
        if (allocated(err)) then
            continue
        else if (exists .and. force) then
            removed = delete_file(file//'.part')
        else if (exists) then
            call refuse_part(file, err)
        else
            call check_may_replace(file, self%scene, force, err, &
                                   label=output_key(self%scene, given), &
                                   can_force=.not. caller_named(self%scene))
        end if
        if (allocated(err)) then
            call drop_lock(self%lock_file, self%beat)
            self%lock_file = ''
            return
        end if
        self%final_file = file
        self%part_file = file//'.part'
        self%summary%file = self%part_file
    end procedure guard_output

    !> Before a resume takes FILE.lock: the locks of the runs that may write `file` (a
    !! resume of it: FILE.lock; for a FILE.part also the new run of FILE that writes it:
    !! FILE's own lock). A live one of the latter refuses the resume (the former take_lock
    !! refuses); `gone` says why the writer of an abandoned one is gone ('' when there is
    !! none), for the warning of a resume of a file whose status is still `running`.
    subroutine writers_gone(file, gone, err)
        character(len=*), intent(in) :: file
        character(len=:), allocatable, intent(out) :: gone
        type(error_t), allocatable, intent(out) :: err
        type(lock_t) :: lock
        character(len=:), allocatable :: path
        integer :: k
        gone = ''
        do k = 1, 2
            path = file//'.lock'
            if (k == 2) then
                if (.not. is_part(file)) exit
                path = file(1:len(file) - len('.part'))//'.lock'
            end if
            call read_lock(path, lock)
            if (.not. lock%exists) cycle
            if (k == 2 .and. len(lock%problem) > 0) then
                call make_error(err, ERR_IO, file//': '//lock%problem)
                return
            else if (k == 2 .and. lock%live .and. .not. lock%mine) then
                call make_error(err, ERR_IO, file//': being written by '//lock%holder()// &
                    ' (lock '//path//'): the run of '//file(1:len(file) - len('.part'))// &
                    ' that writes it is going on')
                return
            else if (.not. lock%live .and. len(lock%problem) == 0) then
                gone = lock%gone()//' (lock '//path//')'
            end if
        end do
    end subroutine writers_gone

    !> A new run on FILE may not remove or refuse-and-name `part` (FILE.part) while a resume
    !! of it holds its lock: an ERR_IO error naming the holder.
    subroutine check_part_idle(part, err)
        character(len=*), intent(in) :: part
        type(error_t), allocatable, intent(out) :: err
        type(lock_t) :: lock
        call read_lock(part//'.lock', lock)
        if (lock%exists .and. lock%live .and. .not. lock%mine) &
            call make_error(err, ERR_IO, part//': being continued by '//lock%holder()// &
                ' (lock '//part//'.lock): a file is written by one process at a time')
    end subroutine check_part_idle

    !> Before a new run without --force takes FILE.lock: a FILE.part there, while no live
    !! process holds FILE.lock (its run was killed), is refused (a live lock: take_lock
    !! names its holder).
    subroutine check_part_left(file, err)
        character(len=*), intent(in) :: file
        type(error_t), allocatable, intent(out) :: err
        type(lock_t) :: lock
        logical :: exists
        inquire (file=file//'.part', exist=exists)
        if (.not. exists) return
        call read_lock(file//'.lock', lock)
        if (lock%exists .and. (lock%live .or. len(lock%problem) > 0)) return
        call check_part_idle(file//'.part', err)
        if (.not. allocated(err)) call refuse_part(file, err)
    end subroutine check_part_left

    !> The error of a new run on FILE that finds FILE.part (without --force).
    subroutine refuse_part(file, err)
        character(len=*), intent(in) :: file
        type(error_t), allocatable, intent(out) :: err
        call make_error(err, ERR_USAGE, file//'.part: left by a run of '//file// &
            ' that was killed: continue it (ropedyn run --resume '//file//'.part) or '// &
            'remove it, or give --force')
    end subroutine refuse_part

    !> The name ends with '.part' (the file a new run writes before it is renamed).
    pure logical function is_part(file)
        character(len=*), intent(in) :: file
        is_part = .false.
        if (len(file) > len('.part')) is_part = file(len(file) - 4:) == '.part'
    end function is_part

    !> The output `file` of a run of `scene` as the input that named it, for a message that
    !! refuses it: 'ORIGIN: &output: file = "FILE"' (ORIGIN: the scene file or the --set
    !! argument that set it), or FILE alone when the caller named it (no origin: the
    !! library's whole run).
    function output_key(scene, file) result(text)
        type(scene_t), intent(in) :: scene
        character(len=*), intent(in) :: file
        character(len=:), allocatable :: text
        text = file
        if (.not. allocated(scene%output%file_origin)) return
        if (len(scene%output%file_origin) > 0) &
            text = scene%output%file_origin//': &output: file = "'//file//'"'
    end function output_key

    !> The output file was named by the library's caller (its whole run), which has no
    !! --force: an &output file without an origin.
    pure logical function caller_named(scene)
        type(scene_t), intent(in) :: scene
        caller_named = .false.
        if (allocated(scene%output%file_origin)) &
            caller_named = len(scene%output%file_origin) == 0
    end function caller_named

    module procedure release_output
        type(error_t), allocatable :: rerr
        logical :: exists
        if (allocated(self%part_file)) then
            if (len(self%part_file) > 0) then
                inquire (file=self%part_file, exist=exists)
                ! complete, failed or interrupted: the file is whole (closed, its status set)
                if (exists) then
                    call rename_file(self%part_file, self%final_file, rerr)
                    if (allocated(rerr) .and. .not. allocated(err)) call move_alloc(rerr, err)
                    ! a message about the file names it where it now is, and so does the
                    ! reason the file keeps
                    if (allocated(err) .and. .not. allocated(rerr)) then
                        err%message = replaced(err%message, self%part_file, self%final_file)
                        call rename_in_reason(self%final_file, self%part_file)
                    end if
                end if
                self%summary%file = self%final_file
                self%part_file = ''
            end if
        end if
        if (allocated(self%lock_file)) then
            if (len(self%lock_file) > 0) call drop_lock(self%lock_file, self%beat)
            self%lock_file = ''
        end if
    end procedure release_output

    !> The root attribute `reason` of the run file `path` (written while it was `part`, by
    !! a failure that named it so) names `path` instead. Nothing when the file has no reason
    !! naming `part`, or cannot be opened or written (the file is whole and closed with its
    !! status; only the name in its reason stays the old one).
    subroutine rename_in_reason(path, part)
        character(len=*), intent(in) :: path, part
        type(h5_file_t) :: h5
        type(error_t), allocatable :: err, close_err
        character(len=:), allocatable :: reason
        logical :: found
        call h5%open(path, err, writable=.true.)
        if (allocated(err)) return
        call h5%read_attribute('reason', reason, err, found)
        if (.not. allocated(err) .and. found) then
            if (index(reason, part) > 0) &
                call h5%attribute('/', 'reason', replaced(reason, part, path), err)
        end if
        call h5%close(close_err)
    end subroutine rename_in_reason
end submodule ropedyn_run_guard
