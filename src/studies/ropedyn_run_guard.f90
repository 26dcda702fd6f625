!> The guard of a run's output file (the output guide, "Write, lock and resume rules"):
!!
!! - no input of the run (its scene, motion tables, state file) is its output;
!! - an output that is a symbolic link is the file it points to (a loop or a name too long
!!   for FILE.part is an error with the system's reason);
!! - FILE.lock is taken before anything is written, the lock a sweep case takes, so that a
!!   second run on the same file is refused before it touches it; a resume continues FILE
!!   in place under that lock; a resume of FILE.part (left by a killed new run of FILE)
!!   takes FILE.lock, as that run did, and renames it to FILE at its end when FILE is not
!!   there or holds a run of the same source;
!! - a new run replaces an existing FILE only when it is a file ropedyn wrote for the same
!!   source (the same scene file with the same --set overrides: a rerun); another file, a
!!   run of another scene or of a --set variant, is refused unless --force; a special file
!!   (a device, a FIFO, a link to one) always;
!! - a new run writes FILE.part and renames it to FILE when it finishes (complete, failed
!!   or interrupted), so that the earlier FILE stays whole until the new one is; a FILE.part
!!   left by a killed run is refused (resume it, or remove it) unless --force; an output
!!   named FILE.part is refused.
submodule (ropedyn_run) ropedyn_run_guard
    use ropedyn_os, only: make_parent_dirs, rename_file, delete_file, special_file_reason, &
                          file_kind, real_path, written_path, errno_text, FILE_SYMLINK, &
                          FILE_MISSING
    use ropedyn_sweep_lock, only: take_lock, drop_lock, read_lock, hand_back_lock, lock_t
    use ropedyn_run_inputs, only: check_not_input, check_may_replace
    use ropedyn_error, only: ERR_USAGE, ERR_IO
    use ropedyn_h5, only: h5_file_t, held_open
    use ropedyn_run_record, only: run_record_t, read_run_record, LAST_RECORD
    use ropedyn_output, only: whole_records
    use ropedyn_text, only: replaced
    implicit none

    !> The longest name of a file in a directory (Linux's NAME_MAX).
    integer, parameter :: NAME_MAX = 255

contains

    module procedure guard_output
        if (resume) then
            call guard_resume(self, self%summary%file, err)
        else
            call guard_new(self, self%summary%file, force, err)
        end if
    end procedure guard_output

    !> The guard of a new run's output `given`: the checks of the path, the lock, a FILE.part
    !! left by a killed run, may FILE be replaced; the run then writes FILE.part.
    subroutine guard_new(self, given, force, err)
        class(run_t), intent(inout) :: self
        character(len=*), intent(in) :: given
        logical, intent(in) :: force
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: file
        logical :: exists, removed
        call new_output_path(self, given, file, err)
        if (allocated(err)) return
        if (.not. force) then
            ! a FILE.part left by a killed run, refused before its abandoned lock is taken
            ! (and removed): that lock tells the resume of FILE.part who wrote it
            call check_part_left(file, err)
            if (allocated(err)) return
        end if
        call take_lock(file//'.lock', self%beat, err)
        if (allocated(err)) then
            err%message = file//': '//err%message
            return
        end if
        self%lock_file = file//'.lock'
        ! is there a FILE.part of a killed run, may the run replace FILE?
        inquire (file=file//'.part', exist=exists)
        if (exists .and. force) then
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
        self%recheck_final = .not. force
    end subroutine guard_new

    !> The file a new run writes for its output `given`, made ready: not an input, not a
    !! special file, not named FILE.part, its directories made; a link is the file it points
    !! to (written there, renamed there; the link stays).
    subroutine new_output_path(self, given, file, err)
        class(run_t), intent(in) :: self
        character(len=*), intent(in) :: given
        character(len=:), allocatable, intent(out) :: file
        type(error_t), allocatable, intent(out) :: err
        integer :: errnum
        file = given
        call check_not_input(file, self%scene, err, label=output_key(self%scene, given))
        if (allocated(err)) return
        if (is_part(file)) then
            call make_error(err, ERR_USAGE, output_key(self%scene, given)//': ends in '// &
                '".part", the name a run gives its file until it ends: choose another name')
            return
        end if
        call make_parent_dirs(file, err)
        if (allocated(err)) return
        if (len(special_file_reason(file)) > 0) then
            call make_error(err, ERR_USAGE, output_key(self%scene, file)// &
                ': exists and is '//special_file_reason(file)//': not replaced')
            return
        end if
        if (file_kind(file, follow=.false.) == FILE_SYMLINK) then
            if (file_kind(file) == FILE_MISSING) then
                ! a dangling link (or a loop: the system's reason)
                if (len(real_path(file, errnum)) == 0 .and. errnum /= 2) then
                    call make_error(err, ERR_IO, given//': cannot create file: '// &
                                    errno_text(errnum))
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
        end if
    end subroutine new_output_path

    !> The guard of a resume of `file`: the lock of the run that writes it (FILE.lock; for
    !! FILE.part, the file of a new run of FILE, FILE's own lock, which that run held), and
    !! what an abandoned one says of its writer. A FILE.part is renamed to FILE when the run
    !! ends, as the new run's would have been, if FILE may be replaced by it.
    subroutine guard_resume(self, file, err)
        class(run_t), intent(inout) :: self
        character(len=*), intent(in) :: file
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: lock_path, real_file
        type(lock_t) :: lock
        ! a link: the file it points to, whose lock its writer took and whose FILE.part is
        ! renamed (the link stays)
        real_file = written_path(file)
        if (is_case_part(real_file)) then
            call make_error(err, ERR_USAGE, file//': the file of a sweep case being '// &
                'written (its lock is .case_<id>.lock beside it): the sweep continues it '// &
                '(ropedyn sweep SWEEP --task <id>), not ropedyn run --resume')
            return
        end if
        if (.not. is_part(real_file)) then
            call check_killed_rerun(real_file, file, err)
            if (allocated(err)) return
        end if
        lock_path = real_file//'.lock'
        if (is_part(real_file)) lock_path = whole_name(real_file)//'.lock'
        self%writer_gone = ''
        call read_lock(lock_path, lock)
        if (lock%exists .and. .not. lock%live .and. len(lock%problem) == 0) then
            self%writer_gone = lock%gone()//' (lock '//lock_path//')'
            self%taken_over = lock
        end if
        call take_lock(lock_path, self%beat, err)
        if (allocated(err)) then
            err%message = file//': '//err%message
            return
        end if
        self%lock_file = lock_path
        if (is_part(real_file)) call plan_rename(self, real_file)
    end subroutine guard_resume

    !> A resume of FILE (`given`, `file` where it points) while FILE.part of a killed rerun of
    !! FILE is there (status running, no live lock, FILE's source): refused before FILE's
    !! lock is taken (that lock names the killed writer). Continued, that run replaces FILE
    !! at its end, as it would have: what this resume added to FILE would be lost.
    subroutine check_killed_rerun(file, given, err)
        character(len=*), intent(in) :: file, given
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: source
        if (.not. part_left(file)) return
        if (trim(root_attribute(file//'.part', 'status')) /= 'running') return
        source = root_attribute(file//'.part', 'source')
        if (len(source) == 0 .or. source /= root_attribute(file, 'source')) return
        call make_error(err, ERR_USAGE, given//': '//file//'.part is there, left by a '// &
            'rerun of '//file//' that was killed: continued, it replaces '//file// &
            ' at its end, and what this resume adds would be lost. Continue it first '// &
            '(ropedyn run --resume '//file//'.part), or remove it')
    end subroutine check_killed_rerun

    !> The name is that of a sweep case's file while it is written: .case_<digits>.h5.part.
    pure logical function is_case_part(file)
        character(len=*), intent(in) :: file
        character(len=:), allocatable :: base, id
        integer :: slash
        is_case_part = .false.
        slash = index(file, '/', back=.true.)
        base = file(slash + 1:)
        if (len(base) <= len('.case_.h5.part')) return
        if (base(:len('.case_')) /= '.case_') return
        if (base(len(base) - len('.h5.part') + 1:) /= '.h5.part') return
        id = base(len('.case_') + 1:len(base) - len('.h5.part'))
        is_case_part = verify(id, '0123456789') == 0
    end function is_case_part

    !> A resume of `part` (FILE.part) renames it to FILE when it ends if FILE is not there
    !! or holds a run of the same source (the run the killed one would have replaced); else
    !! it keeps its name, with a warning saying why. The resumed run is a run of the source
    !! the .part records: the scene's source from here on (a resume's scene has none, and
    !! writes none: the file has its own).
    subroutine plan_rename(self, part)
        class(run_t), intent(inout) :: self
        character(len=*), intent(in) :: part
        character(len=:), allocatable :: whole, source
        whole = whole_name(part)
        source = root_attribute(part, 'source')
        if (len(source) > 0) then
            self%scene%source = source
            if (.not. may_take_name(self, part, whole, ' is there')) return
        else if (file_kind(whole, follow=.false.) /= FILE_MISSING) then
            call append_text(self%summary%warnings, part//' keeps its name: '//whole// &
                ' is there, not a file of its run to replace ('//part//' records no source)')
            return
        end if
        self%part_file = part
        self%final_file = whole
        self%recheck_final = .true.
    end subroutine plan_rename

    !> May the run's file `part` take the name `whole` (FILE)? Yes when FILE is not there, or
    !! holds a file the run may replace (a run of the scene's source: check_may_replace);
    !! else a warning says why it keeps its name (`there`: how FILE is there).
    logical function may_take_name(self, part, whole, there) result(may)
        class(run_t), intent(inout) :: self
        character(len=*), intent(in) :: part, whole, there
        type(error_t), allocatable :: err
        may = .true.
        if (file_kind(whole, follow=.false.) == FILE_MISSING) return
        call check_may_replace(whole, self%scene, .false., err, can_force=.false.)
        if (.not. allocated(err)) return
        may = .false.
        call append_text(self%summary%warnings, part//' keeps its name: '//whole//there// &
            ', not a file of its run to replace ('//err%message//')')
    end function may_take_name

    !> The root attribute `name` (a string) of the HDF5 file `path`; '' when the file cannot
    !! be read or has none.
    function root_attribute(path, name) result(value)
        character(len=*), intent(in) :: path, name
        character(len=:), allocatable :: value
        type(h5_file_t) :: h5
        type(error_t), allocatable :: err, close_err
        logical :: found
        value = ''
        call h5%open(path, err)
        if (allocated(err)) return
        call h5%read_attribute(name, value, err, found)
        call h5%close(close_err)
        if (allocated(err) .or. .not. found) value = ''
    end function root_attribute

    !> Before a new run without --force takes FILE.lock: a FILE.part there, while no live
    !! process holds FILE.lock (its run was killed), is refused (a live lock: take_lock
    !! names its holder).
    subroutine check_part_left(file, err)
        character(len=*), intent(in) :: file
        type(error_t), allocatable, intent(out) :: err
        if (part_left(file)) call refuse_part(file, err)
    end subroutine check_part_left

    !> FILE.part is there and no live writer holds FILE.lock: the file of a run of FILE that
    !! stopped or was killed (a live lock, or one that is no lock, is take_lock's to report).
    logical function part_left(file)
        character(len=*), intent(in) :: file
        type(lock_t) :: lock
        inquire (file=file//'.part', exist=part_left)
        if (.not. part_left) return
        call read_lock(file//'.lock', lock)
        part_left = .not. (lock%exists .and. (lock%live .or. len(lock%problem) > 0))
    end function part_left

    !> The error of a new run on FILE that finds FILE.part (without --force), by what its
    !! status says: a killed run's (`running`, or unreadable), one that stopped, or a
    !! finished run's file that kept its name (FILE was not its to replace).
    subroutine refuse_part(file, err)
        character(len=*), intent(in) :: file
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: status, why
        status = trim(root_attribute(file//'.part', 'status'))
        select case (status)
        case ('complete')
            call make_error(err, ERR_USAGE, file//'.part: a finished run of '//file// &
                ' (status complete) that kept this name, as '//file//' was not its to '// &
                'replace: rename it or remove it, or give --force')
        case ('failed', 'interrupted')
            call make_error(err, ERR_USAGE, file//'.part: a run of '//file//' that '// &
                'stopped (status '//status//') and kept this name: continue it (ropedyn '// &
                'run --resume '//file//'.part) or remove it, or give --force')
        case default
            ! a run killed before its first flush leaves a file that cannot be read back:
            ! a resume of it would be refused
            why = unreadable_part(file//'.part')
            if (len(why) > 0) then
                call make_error(err, ERR_USAGE, file//'.part: left by a run of '//file// &
                    ' that was killed, and cannot be continued ('//why//'): remove it, '// &
                    'or give --force')
                return
            end if
            call make_error(err, ERR_USAGE, file//'.part: left by a run of '//file// &
                ' that was killed: continue it (ropedyn run --resume '//file//'.part) or '// &
                'remove it, or give --force')
        end select
    end subroutine refuse_part

    !> Why a resume of the run file `part` cannot start, as the resume reads it: its last
    !! record does not read back and no earlier record is whole (whole_records) ('' when
    !! it can start, or when another program holds the file open: then a resume says who).
    function unreadable_part(part) result(why)
        character(len=*), intent(in) :: part
        character(len=:), allocatable :: why
        type(run_record_t) :: rec
        type(error_t), allocatable :: err, werr
        integer :: whole
        why = ''
        call read_run_record(part, LAST_RECORD, rec, err)
        if (.not. allocated(err)) return
        if (held_open(err)) return
        ! a last record cut in a write: a resume goes on from the last whole one
        call whole_records(part, whole, werr)
        if (.not. allocated(werr) .and. whole >= 1) return
        why = replaced(err%message, part//': ', '')
    end function unreadable_part

    !> The name ends with '.part' (the file a new run writes before it is renamed).
    pure logical function is_part(file)
        character(len=*), intent(in) :: file
        is_part = .false.
        if (len(file) > len('.part')) is_part = file(len(file) - 4:) == '.part'
    end function is_part

    !> FILE for FILE.part.
    pure function whole_name(part) result(file)
        character(len=*), intent(in) :: part
        character(len=:), allocatable :: file
        file = part(1:len(part) - len('.part'))
    end function whole_name

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
                ! a file put at FILE while the run went on, which the run may not replace:
                ! the run's file keeps its .part name
                if (exists .and. self%recheck_final) call recheck_final(self)
                ! complete, failed or interrupted: the file is whole (closed, its status set)
                if (exists .and. len(self%part_file) > 0) then
                    call rename_file(self%part_file, self%final_file, rerr)
                    if (allocated(rerr) .and. .not. allocated(err)) call move_alloc(rerr, err)
                    ! a message about the file names it where it now is, and so does the
                    ! reason the file keeps
                    if (allocated(err) .and. .not. allocated(rerr)) then
                        err%message = replaced(err%message, self%part_file, self%final_file)
                        call rename_in_reason(self%final_file, self%part_file)
                    end if
                end if
                if (len(self%part_file) > 0) self%summary%file = self%final_file
                self%part_file = ''
            end if
        end if
        if (allocated(self%lock_file)) then
            if (len(self%lock_file) > 0) call drop_lock(self%lock_file, self%beat)
            self%lock_file = ''
        end if
    end procedure release_output

    module procedure hand_back
        if (.not. self%taken_over%exists .or. .not. allocated(self%lock_file)) return
        if (len(self%lock_file) == 0) return
        call hand_back_lock(self%lock_file, self%beat, self%taken_over)
        self%lock_file = ''
    end procedure hand_back

    !> Before FILE.part is renamed to FILE at the end: a FILE there now is checked again
    !! (one put there while the run went on, by the user or another program), against the
    !! run's source (a new run's own, which its .part records; a resume's, plan_rename);
    !! when the run may not replace it, the run's file keeps its .part name (part_file ''),
    !! with a warning saying why.
    subroutine recheck_final(self)
        class(run_t), intent(inout) :: self
        if (may_take_name(self, self%part_file, self%final_file, &
                          ' was put there while the run went on')) return
        self%summary%file = self%part_file
        self%part_file = ''
    end subroutine recheck_final

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
