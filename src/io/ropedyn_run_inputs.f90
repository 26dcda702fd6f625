!> The input files of a run and the check that an output file is none of them: a run must
!! never write over what it reads (docs/guide/output.md, "Inputs are never outputs").
!!
!! The inputs of a scene: the scene file itself, its motion tables (`&supports
!! top_table`, `bottom_table` with motion 'table') and the run file of its starting record
!! (`&initial state_file` with shape 'state'); a caller adds its own (a sweep file, a
!! reference file). Two paths are one file when they have the same device and inode (links,
!! relative paths and hard links resolved: ropedyn_os output_clash); an output not created
!! yet is compared by its canonical name.
!!
!!     call check_not_input(out_path, scene, err)              ! statics -o, modes -o, run
!!     call check_not_input(case_file, scene, err, [sweep_file], ['the sweep file'])
!!
!! And whether an existing file may be replaced at all (check_replaceable): only a run file
!! that ropedyn wrote (docs/guide/output.md, "Write, lock and resume rules").
module ropedyn_run_inputs
    use ropedyn_error, only: error_t, make_error, ERR_USAGE, ERR_INPUT
    use ropedyn_os, only: output_clash, special_file_reason
    use ropedyn_scene_types, only: scene_t
    use ropedyn_h5, only: h5_file_t
    implicit none
    private
    public :: scene_inputs, check_not_input, check_replaceable, check_own_source, &
              check_may_replace, check_part_free

    !> The first bytes of an HDF5 file (its signature at offset 0: ropedyn writes no user
    !! block).
    character(len=*), parameter :: HDF5_SIGNATURE = achar(137)//'HDF'//achar(13)//achar(10)// &
        achar(26)//achar(10)
    !> Root attributes every file ropedyn writes has.
    character(len=*), parameter :: OWN_ATTRIBUTES(3) = [character(len=7) :: 'version', &
        'model', 'created']

    !> Width of an entry of the lists: the longest path of a scene (PATH_MAX of Linux; the
    !! scene's own keys hold at most 512 characters).
    integer, parameter :: W = 4096

contains

    !> The input files of `scene` (blank entries where it has none) and what each is.
    subroutine scene_inputs(scene, paths, roles)
        type(scene_t), intent(in) :: scene
        character(len=W), intent(out) :: paths(4)
        character(len=40), intent(out) :: roles(4)
        paths = ''
        roles = [character(len=40) :: 'the scene file', 'the motion table top_table', &
                 'the motion table bottom_table', 'the state file']
        paths(1) = scene%path
        if (trim(scene%supports%top_motion) == 'table') paths(2) = scene%supports%top_table
        if (trim(scene%supports%bottom_motion) == 'table') &
            paths(3) = scene%supports%bottom_table
        if (trim(scene%initial%shape) == 'state') paths(4) = scene%initial%state_file
    end subroutine scene_inputs

    !> ERR_USAGE (exit 2) when the file `output` is one of the inputs of `scene` or of
    !! `extra` (described by `extra_roles`), naming both (`output` as `label` when given:
    !! the input that named it); nothing else happens.
    subroutine check_not_input(output, scene, err, extra, extra_roles, label)
        character(len=*), intent(in) :: output
        type(scene_t), intent(in) :: scene
        type(error_t), allocatable, intent(out) :: err
        character(len=*), intent(in), optional :: extra(:), extra_roles(:)
        character(len=*), intent(in), optional :: label
        character(len=W) :: paths(4)
        character(len=40) :: roles(4)
        integer :: k
        call scene_inputs(scene, paths, roles)
        k = output_clash(output, paths)
        if (k > 0) then
            call clash(trim(roles(k)), trim(paths(k)))
            return
        end if
        if (.not. present(extra)) return
        k = output_clash(output, extra)
        if (k > 0) call clash(trim(extra_roles(k)), trim(extra(k)))
    contains
        subroutine clash(role, path)
            character(len=*), intent(in) :: role, path
            call make_error(err, ERR_USAGE, named(output, label)//': the output file is '// &
                role//' "'// &
                path//'" (the same file): writing it would destroy an input of this run; '// &
                'choose another output file')
        end subroutine clash
    end subroutine check_not_input

    !> Whether the existing file `path` may be replaced by an output of ropedyn: ERR_USAGE
    !! (exit 2) naming what it is when it is not a regular file, not an HDF5 file (a text
    !! file, ...), or an HDF5 file without ropedyn's root attributes (version, model,
    !! created); an error of the file's own (locked by a process: ERR_IO) as it is. Nothing
    !! when `path` does not exist or is a file ropedyn wrote. For the rule that a run
    !! replaces only what it wrote unless told to (--force). The messages name `path` as
    !! `label` when given (the input that named it); an error of the file's own names the
    !! file.
    subroutine check_replaceable(path, err, label)
        character(len=*), intent(in) :: path
        type(error_t), allocatable, intent(out) :: err
        character(len=*), intent(in), optional :: label
        character(len=len(HDF5_SIGNATURE)) :: head
        character(len=:), allocatable :: value
        type(h5_file_t) :: h5
        type(error_t), allocatable :: close_err
        logical :: exists, found
        integer :: unit, ios, k
        inquire (file=path, exist=exists)
        if (.not. exists) return
        if (len(special_file_reason(path)) > 0) then
            call make_error(err, ERR_USAGE, named(path, label)//': exists and is '// &
                special_file_reason(path)//': not replaced')
            return
        end if
        head = ''
        open (newunit=unit, file=path, status='old', action='read', access='stream', &
              form='unformatted', iostat=ios)
        if (ios == 0) read (unit, iostat=ios) head
        if (ios == 0) close (unit)
        if (head /= HDF5_SIGNATURE) then
            call make_error(err, ERR_USAGE, named(path, label)//': exists and is not an '// &
                'HDF5 file (not '// &
                'written by ropedyn): not replaced')
            return
        end if
        call h5%open(path, err)
        if (allocated(err)) then
            if (err%code == ERR_INPUT) err%code = ERR_USAGE
            return
        end if
        do k = 1, size(OWN_ATTRIBUTES)
            call h5%read_attribute(trim(OWN_ATTRIBUTES(k)), value, err, found)
            if (allocated(err) .or. .not. found) exit
        end do
        call h5%close(close_err)
        if (.not. allocated(err) .and. .not. found) call make_error(err, ERR_USAGE, &
            named(path, label)// &
            ': exists and is an HDF5 file not written by ropedyn (no root attribute '// &
            trim(OWN_ATTRIBUTES(k))//'): not replaced')
    end subroutine check_replaceable

    !> A run replaces a file of its own source only (a rerun of the same scene file with
    !! the same --set overrides), and `ropedyn statics|modes` (`analysis`) a file of that
    !! analysis of its own source only: ERR_USAGE naming what the existing ropedyn file at
    !! `path` holds when it is of another kind (a run, a statics or a modes result: root
    !! attribute `analysis`, absent for a run), its root attribute `source` is another (a
    !! --set variant, another scene) or missing (written by a version before the rule).
    !! Nothing when `path` does not exist; call check_replaceable first (a file ropedyn did
    !! not write). `label`, `can_force`: as check_may_replace's. `source` '': a scene
    !! without one (the library's, from text), whose file is checked for its kind only.
    subroutine check_own_source(path, source, err, analysis, label, can_force)
        character(len=*), intent(in) :: path, source
        type(error_t), allocatable, intent(out) :: err
        character(len=*), intent(in), optional :: analysis, label
        logical, intent(in), optional :: can_force
        character(len=:), allocatable :: stored, kind, mine, hint
        type(h5_file_t) :: h5
        type(error_t), allocatable :: close_err
        logical :: exists, found, has_kind
        inquire (file=path, exist=exists)
        if (.not. exists) return
        call h5%open(path, err)
        if (allocated(err)) return
        call h5%read_attribute('source', stored, err, found)
        if (.not. allocated(err)) call h5%read_attribute('analysis', kind, err, has_kind)
        call h5%close(close_err)
        if (allocated(err)) return
        mine = 'run'
        hint = 'give this run another file (--set output.file=...) or --force'
        if (present(analysis)) then
            mine = analysis
            hint = 'give it another file (-o FILE.h5) or --force'
        end if
        if (present(can_force)) then
            if (.not. can_force) hint = 'write elsewhere, or remove it'
        end if
        if (.not. has_kind) kind = 'run'
        if (kind /= mine) then
            call make_error(err, ERR_USAGE, named(path, label)//': exists and holds a '// &
                kind//' result, not a '//mine//' one: not replaced; '//hint)
        else if (len(source) == 0) then
            return
        else if (.not. found) then
            call make_error(err, ERR_USAGE, named(path, label)//': exists and holds a '// &
                kind//' whose source is not recorded (an older file): not replaced; '//hint)
        else if (stored /= source) then
            call make_error(err, ERR_USAGE, named(path, label)//': exists and holds the '// &
                kind//' of "'//stored//'", not of this '//mine//' "'//source// &
                '": not replaced; '//hint)
        end if
    end subroutine check_own_source

    !> May an existing output `path` be replaced by this run (or by the analysis
    !! `analysis`, 'statics' or 'modes') of `scene`? Never a special file (a device, a FIFO,
    !! a link to one), whatever `force`; unless `force`, only a file ropedyn wrote for the
    !! same kind of result of the same source (check_replaceable, check_own_source): else
    !! ERR_USAGE naming what the file is. Nothing when `path` does not exist. `label`: as
    !! check_replaceable's. `can_force` (default true): the caller has --force to offer (the
    !! library's whole run has not: its refusal says to remove the file instead).
    subroutine check_may_replace(path, scene, force, err, analysis, label, can_force)
        character(len=*), intent(in) :: path
        type(scene_t), intent(in) :: scene
        logical, intent(in) :: force
        type(error_t), allocatable, intent(out) :: err
        character(len=*), intent(in), optional :: analysis, label
        logical, intent(in), optional :: can_force
        logical :: offer
        if (len(special_file_reason(path)) > 0) then
            call make_error(err, ERR_USAGE, named(path, label)//': exists and is '// &
                            special_file_reason(path)//': not replaced')
            return
        end if
        if (force) return
        call check_replaceable(path, err, label)
        if (allocated(err)) then
            offer = .true.
            if (present(can_force)) offer = can_force
            if (err%code == ERR_USAGE .and. offer) &
                err%message = err%message//' (--force replaces it)'
            if (err%code == ERR_USAGE .and. .not. offer) &
                err%message = err%message//' (remove it, or write elsewhere)'

            return
        end if
        ! (a scene without a source, the library's: the file's kind only)
        if (allocated(scene%source)) then
            call check_own_source(path, scene%source, err, analysis, label, can_force)
        else
            call check_own_source(path, '', err, analysis, label, can_force)
        end if
    end subroutine check_may_replace

    !> May a statics or modes result write `part` (FILE.part), its file until it is whole?
    !! Unless `force`, only when it is not there or is such a result itself (one a killed
    !! analysis left): a run's FILE.part holds the records of a run that was killed (or goes
    !! on), and any other file is the user's: ERR_USAGE, the file untouched.
    subroutine check_part_free(part, force, err)
        character(len=*), intent(in) :: part
        logical, intent(in) :: force
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: kind
        type(h5_file_t) :: h5
        type(error_t), allocatable :: open_err, close_err
        logical :: exists, found
        inquire (file=part, exist=exists)
        if (.not. exists .or. force) return
        found = .false.
        call h5%open(part, open_err)
        if (.not. allocated(open_err)) then
            call h5%read_attribute('analysis', kind, open_err, found)
            call h5%close(close_err)
        end if
        if (found .and. .not. allocated(open_err)) then
            if (kind == 'statics' .or. kind == 'modes') return
        end if
        call make_error(err, ERR_USAGE, part//': there already, and not a statics or '// &
            'modes result (the file of a run that was killed or goes on: ropedyn run '// &
            '--resume '//part//' continues a killed one): not replaced; remove it, or '// &
            'give --force')
    end subroutine check_part_free

    !> How a message names the file `path`: as `label` when given, else by its path.
    pure function named(path, label) result(text)
        character(len=*), intent(in) :: path
        character(len=*), intent(in), optional :: label
        character(len=:), allocatable :: text
        text = path
        if (present(label)) text = label
    end function named
end module ropedyn_run_inputs
