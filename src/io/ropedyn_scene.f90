!> Scene files: the namelist input of ropedyn (rope, model, supports, initial state, effects,
!! solver and output), read with defaults, `--set group.key=value` overrides and a check of
!! every key. The reference is docs/reference/keys.md.
!!
!! Reading: the file is parsed by the one namelist reader (`ropedyn_namelist_file`); for
!! each group in order its assignments and then the overrides of that group are stored
!! through the key table (`ropedyn_scene_keys`), which also converts and checks each value;
!! then `ropedyn_scene_checks` checks the keys together, resolves the derived defaults and
!! the limits. Every error is one message of class `ERR_INPUT` naming the file (or the
!! `--set` argument), the group, the key and the value.
module ropedyn_scene
    use ropedyn_error, only: error_t, make_error, ERR_INPUT
    use ropedyn_text, only: int_text, real_text, lower, line_quote, printable, text_t, clip, &
        append_text, stripped
    use ropedyn_namelist_file, only: nml_file_t, nml_value_t, read_namelist_file, &
        parse_namelist_lines, parse_values, V_STRING
    use ropedyn_scene_types, only: scene_t, solver_params_t, output_params_t
    use ropedyn_os, only: canonical_path
    use ropedyn_scene_key, only: scene_key_t, T_NAME, T_PATH
    use ropedyn_scene_keys, only: bind_keys, find_key, key_hint, group_index, group_list, &
        GROUP_NAMES, N_GROUPS
    use ropedyn_scene_checks, only: check_scene
    implicit none
    private
    public :: solver_params_t, output_params_t, scene_t
    public :: read_scene, read_scene_text, read_scene_string, scene_namelist_text, &
        echo_without_output_file, override_value_text, &
        scene_key_listing, check_override_value, override_target, scene_physics_text, &
        recorded_source

    !> One `--set group.key=value` argument, parsed.
    type :: override_t
        character(len=:), allocatable :: text   !< as given (trimmed)
        integer :: group = 0
        integer :: key = 0                      !< index in the key table
        character(len=:), allocatable :: name   !< the key as given (lower case, with index)
        integer :: index = 0                    !< key(index)=..., else 0
        character(len=:), allocatable :: value  !< the value as given
        type(nml_value_t), allocatable :: values(:)
    end type override_t

contains

    !> Read a scene file, apply overrides, resolve derived defaults and check every key.
    !!
    !! `overrides` holds `group.key=value` strings (the `--set` arguments), applied after the
    !! file in the order given. On error `err` is allocated with class ERR_INPUT and a message
    !! naming the file (or the `--set` argument), group, key and value; `scene` is then not
    !! a valid scene.
    subroutine read_scene(path, overrides, scene, err)
        character(len=*), intent(in) :: path          !< scene file
        character(len=*), intent(in) :: overrides(:)  !< 'group.key=value', may be empty
        type(scene_t), target, intent(out) :: scene
        type(error_t), allocatable, intent(out) :: err

        scene%path = trim(path)
        if (printable(scene%path) /= scene%path) then
            call make_error(err, ERR_INPUT, printable(scene%path)//': a control character in ' &
                //'the file name')
            return
        end if
        call load_scene(overrides, scene, err)
        if (allocated(err)) return
        ! the scene file and the overrides that change the run (not those of &output)
        scene%source = canonical_path(scene%path)//set_arguments(overrides, .true.)
    end subroutine read_scene

    !> Read the scene of a run file being continued (its `scene` attribute, the echo of
    !! `scene_namelist_text`) as `read_scene` reads a file; `origin` names the text in
    !! messages (and becomes the scene's path). The overrides may not set output.file (the
    !! run appends to that file) nor change solver.output_interval (the file's records are
    !! on its grid; docs/guide/output.md, "Resume").
    subroutine read_scene_text(origin, text, overrides, scene, err)
        character(len=*), intent(in) :: origin        !< e.g. 'out/run.h5: scene'
        character(len=*), intent(in) :: text          !< lines separated by new lines
        character(len=*), intent(in) :: overrides(:)  !< 'group.key=value', may be empty
        type(scene_t), target, intent(out) :: scene
        type(error_t), allocatable, intent(out) :: err
        type(scene_t) :: stored
        character(len=0) :: none(0)
        integer :: k

        scene%path = origin
        call load_scene(overrides, scene, err, text)
        if (allocated(err)) return
        scene%overrides = trim(adjustl(set_arguments(overrides, .false.)))
        do k = 1, size(overrides)
            select case (override_target(overrides(k)))
            case ('output.file')
                call make_error(err, ERR_INPUT, '--set '//clip(printable(trim(overrides(k))))// &
                    ': a resume appends to the file it continues: output.file cannot be set')
            case ('solver.output_interval')
                stored%path = origin
                call load_scene(none, stored, err, text)
                if (allocated(err)) return
                if (stored%solver%output_interval /= scene%solver%output_interval) &
                    call make_error(err, ERR_INPUT, '--set '// &
                    clip(printable(trim(overrides(k))))//': a resume keeps the output grid '// &
                    'of the file it continues (output_interval = '// &
                    real_text(stored%solver%output_interval)//' s); start a new run to '// &
                    'change it')
            end select
            if (allocated(err)) return
        end do
    end subroutine read_scene_text

    !> Read a scene given as namelist text (the library's scenes) as `read_scene` reads a
    !! file: `name` names it in messages, gives the default output file (out/NAME.h5 without
    !! its .nml) and resolves relative paths (against its directory; the current one when
    !! it has none). A scene read so has no `source` (its files record recorded_source's).
    subroutine read_scene_string(name, text, overrides, scene, err)
        character(len=*), intent(in) :: name          !< e.g. 'scene' or 'input/paper.nml'
        character(len=*), intent(in) :: text          !< lines separated by new lines
        character(len=*), intent(in) :: overrides(:)  !< 'group.key=value', may be empty
        type(scene_t), target, intent(out) :: scene
        type(error_t), allocatable, intent(out) :: err
        scene%path = name
        if (printable(scene%path) /= scene%path) then
            call make_error(err, ERR_INPUT, printable(scene%path)//': a control character in ' &
                //'the scene''s name')
            return
        end if
        call load_scene(overrides, scene, err, text)
    end subroutine read_scene_string

    !> ' --set group.key=value' for each of `overrides` in their order (as the command line
    !! gave them); those of &output left out when `skip_output`.
    pure function set_arguments(overrides, skip_output) result(text)
        character(len=*), intent(in) :: overrides(:)
        logical, intent(in) :: skip_output
        character(len=:), allocatable :: text
        integer :: k
        text = ''
        do k = 1, size(overrides)
            if (skip_output .and. index(override_target(overrides(k)), 'output.') == 1) cycle
            text = text//' --set '//trim(adjustl(overrides(k)))
        end do
    end function set_arguments

    !> 'group.key' of a `--set group.key=value` argument as the scene reads it (lower case,
    !! blanks around the parts removed; '' when it has no '=').
    pure function override_target(arg) result(target)
        character(len=*), intent(in) :: arg
        character(len=:), allocatable :: target, lhs
        integer :: eq, dot
        target = ''
        eq = index(arg, '=')
        if (eq <= 1) return
        lhs = trim(adjustl(arg(:eq - 1)))
        dot = index(lhs, '.')
        if (dot <= 1) return
        target = lower(trim(lhs(:dot - 1)))//'.'//lower(trim(adjustl(lhs(dot + 1:))))
    end function override_target

    !> The steps of `read_scene` and `read_scene_text` after scene%path is set: the
    !! overrides parsed against the scene's keys, then the namelist read (from `text` when
    !! present, else from the file scene%path), stored and checked.
    subroutine load_scene(overrides, scene, err, text)
        character(len=*), intent(in) :: overrides(:)
        type(scene_t), target, intent(inout) :: scene
        type(error_t), allocatable, intent(out) :: err
        character(len=*), intent(in), optional :: text
        type(scene_key_t), allocatable :: keys(:)
        type(override_t), allocatable :: ov(:)
        type(nml_file_t) :: file
        type(text_t), allocatable :: lines(:)
        integer :: i, start, nl

        call bind_keys(scene, keys)
        allocate (ov(size(overrides)))
        do i = 1, size(overrides)
            call parse_override(overrides(i), keys, ov(i), err)
            if (allocated(err)) return
        end do
        if (present(text)) then
            allocate (lines(0))
            start = 1
            do while (start <= len(text))
                nl = index(text(start:), new_line('a'))
                if (nl == 0) nl = len(text) - start + 2
                call append_text(lines, text(start:start + nl - 2))
                start = start + nl
            end do
            call parse_namelist_lines(scene%path, lines, GROUP_NAMES, file, err)
            if (allocated(err)) return
            if (file%find('model') == 0) then
                call make_error(err, ERR_INPUT, scene%path//': no &model group: not a scene')
                return
            end if
        else
            call read_namelist_file(scene%path, GROUP_NAMES, file, err, required='model', &
                not_what='not a scene file (a scene needs at least &model)')
            if (allocated(err)) return
        end if
        call store_scene(file, ov, keys, scene, err)
    end subroutine load_scene

    !> The groups of a parsed file and the overrides, group by group, into the scene; then
    !! the checks of the whole scene.
    subroutine store_scene(file, ov, keys, scene, err)
        type(nml_file_t), intent(in) :: file
        type(override_t), intent(in) :: ov(:)
        type(scene_key_t), intent(inout) :: keys(:)
        type(scene_t), intent(inout) :: scene
        type(error_t), allocatable, intent(out) :: err
        integer :: i, g, k
        do g = 1, N_GROUPS
            k = file%find(trim(GROUP_NAMES(g)))
            if (k > 0) then
                call store_group(file, k, g, keys, err)
                if (allocated(err)) return
            end if
            do i = 1, size(ov)
                if (ov(i)%group /= g) cycle
                call apply_override(ov(i), keys, err)
                if (allocated(err)) return
            end do
        end do
        allocate (scene%set_keys(0), scene%set_origins(0))
        do i = 1, size(keys)
            if (keys(i)%group == group_index('output') .and. keys(i)%name == 'progress') &
                scene%output%progress_given = keys(i)%given
            if (.not. allocated(keys(i)%origin)) cycle
            if (keys(i)%origin == scene%path) cycle
            call append_text(scene%set_keys, trim(GROUP_NAMES(keys(i)%group))//'.'// &
                             trim(keys(i)%name))
            call append_text(scene%set_origins, keys(i)%origin)
        end do
        scene%output%file_origin = scene%origin('output.file')
        call check_scene(keys, scene, err)
    end subroutine store_scene

    !> Store the assignments of group k of the file (scene group g) through the key table.
    subroutine store_group(file, k, g, keys, err)
        type(nml_file_t), intent(in) :: file
        integer, intent(in) :: k, g
        type(scene_key_t), intent(inout) :: keys(:)
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: where, reason, line
        integer :: j, ki
        where = file%origin//': &'//trim(GROUP_NAMES(g))//': '
        do j = 1, size(file%groups(k)%assignments)
            associate (a => file%groups(k)%assignments(j))
                line = ' (line '//int_text(a%line)//': '//line_quote(a%line_text)//')'
                ki = find_key(keys, g, a%name)
                if (ki == 0) then
                    call make_error(err, ERR_INPUT, where//'unknown key "'//a%key// &
                        '"'//line//key_hint(keys, g, a%name))
                    return
                end if
                call keys(ki)%assign(a%values, a%index, reason)
                if (len(reason) > 0) then
                    call make_error(err, ERR_INPUT, where//'cannot read '//a%key//' = '// &
                        clip(a%value_text)//': '//reason//line)
                    return
                end if
                keys(ki)%origin = file%origin
            end associate
        end do
    end subroutine store_group

    !> Parse and check one `group.key=value` argument.
    subroutine parse_override(arg, keys, ov, err)
        character(len=*), intent(in) :: arg
        type(scene_key_t), intent(in) :: keys(:)
        type(override_t), intent(out) :: ov
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: s, lhs, group, loc, base, reason
        integer :: eq, dot, paren

        s = stripped(arg)
        ov%text = clip(printable(s))
        loc = '--set '//ov%text
        if (printable(s) /= s) then
            call make_error(err, ERR_INPUT, loc//': a control character in the argument')
            return
        end if
        eq = index(s, '=')
        if (eq <= 1) then
            call make_error(err, ERR_INPUT, loc//': expected group.key=value')
            return
        end if
        lhs = stripped(s(:eq - 1))
        ov%value = stripped(s(eq + 1:))
        dot = index(lhs, '.')
        if (dot <= 1 .or. dot >= len(lhs)) then
            call make_error(err, ERR_INPUT, loc//': expected group.key=value')
            return
        else if (len(ov%value) == 0) then
            call make_error(err, ERR_INPUT, loc//': no value after "=" (an empty text is '// &
                "written '')")
            return
        end if
        group = lower(stripped(lhs(:dot - 1)))
        ov%name = lower(stripped(lhs(dot + 1:)))
        ov%group = group_index(group)
        if (ov%group == 0) then
            call make_error(err, ERR_INPUT, loc//': unknown group "'//clip(printable(group))// &
                '" (groups: '//group_list()//')')
            return
        end if
        loc = loc//': &'//group//': '
        paren = index(ov%name, '(')
        base = ov%name
        if (paren > 0) then
            base = trim(ov%name(:paren - 1))
            if (ov%name(len(ov%name):) /= ')' .or. len(ov%name) - paren - 1 > 9 .or. &
                len(ov%name) - paren - 1 < 1) base = ''
            if (len(base) > 0) then
                if (verify(ov%name(paren + 1:len(ov%name) - 1), '0123456789') > 0) base = ''
            end if
            if (len(base) > 0) read (ov%name(paren + 1:len(ov%name) - 1), *) ov%index
            if (ov%index < 1) base = ''
        end if
        ov%key = find_key(keys, ov%group, base)
        if (ov%key == 0) then
            call make_error(err, ERR_INPUT, loc//'unknown key "'//clip(printable(ov%name))//'"' &
                //key_hint(keys, ov%group, base))
            return
        end if
        call override_values(keys(ov%key), ov%value, ov%values, reason)
        if (len(reason) > 0) call make_error(err, ERR_INPUT, loc//'cannot read '//ov%name// &
            ' = '//clip(ov%value)//': '//reason)
    end subroutine parse_override

    !> The values of `--set group.key=value`: a bare string for a string key, else namelist
    !! values without `= / & $ !` or quotes (so that one --set sets one key).
    subroutine override_values(key, value, values, reason)
        type(scene_key_t), intent(in) :: key
        character(len=*), intent(in) :: value
        type(nml_value_t), allocatable, intent(out) :: values(:)
        character(len=:), allocatable, intent(out) :: reason
        reason = ''
        if (key%type == T_NAME .or. key%type == T_PATH) then
            if (value(1:1) == "'" .or. value(1:1) == '"') then
                call parse_values(value, values, reason)
                if (len(reason) > 0 .or. size(values) /= 1) reason = 'unbalanced quotes'
            else
                allocate (values(1))
                values(1)%kind = V_STRING
                values(1)%text = value
            end if
        else if (scan(value, '=/&$!''"') > 0) then
            allocate (values(0))
            reason = key%expected(0, values)
        else
            call parse_values(value, values, reason)
        end if
    end subroutine override_values

    !> Store one override in the scene.
    subroutine apply_override(ov, keys, err)
        type(override_t), intent(in) :: ov
        type(scene_key_t), intent(inout) :: keys(:)
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: reason
        call keys(ov%key)%assign(ov%values, ov%index, reason)
        if (len(reason) > 0) then
            call make_error(err, ERR_INPUT, '--set '//ov%text//': &'// &
                trim(GROUP_NAMES(ov%group))//': cannot read '//ov%name//' = '// &
                clip(ov%value)//': '//reason)
            return
        end if
        keys(ov%key)%origin = '--set '//ov%text
    end subroutine apply_override

    !> The reason why `group.key=value` (as for --set) breaks the key's own rule, '' if it
    !! does not: the one check of a single value, for the lists of sweep files.
    function check_override_value(setting) result(reason)
        character(len=*), intent(in) :: setting
        character(len=:), allocatable :: reason
        type(scene_t), target :: scene
        type(scene_key_t), allocatable :: keys(:)
        type(error_t), allocatable :: err
        integer :: k
        call set_alone(setting, scene, keys, k, err)
        if (allocated(err)) then
            reason = err%message
            return
        end if
        reason = keys(k)%check()
    end function check_override_value

    !> The value a `group.key=value` setting gives its key, as the effective scene writes it
    !! ('1.0' for 1 and 1.0, 'cvode' for CVODE): two settings of one key with the same text
    !! set the same value. The setting's own value text when it cannot be applied.
    function override_value_text(setting) result(text)
        character(len=*), intent(in) :: setting
        character(len=:), allocatable :: text
        type(scene_t), target :: scene
        type(scene_key_t), allocatable :: keys(:)
        type(error_t), allocatable :: err
        integer :: k
        call set_alone(setting, scene, keys, k, err)
        if (allocated(err)) then
            text = setting(index(setting, '=') + 1:)
            return
        end if
        text = keys(k)%value_text()
    end function override_value_text

    !> `setting` ('group.key=value') applied alone to `scene` (a default one), through
    !! `keys` bound to it; `k` the key it set.
    subroutine set_alone(setting, scene, keys, k, err)
        character(len=*), intent(in) :: setting
        type(scene_t), target, intent(inout) :: scene
        type(scene_key_t), allocatable, intent(out) :: keys(:)
        integer, intent(out) :: k
        type(error_t), allocatable, intent(out) :: err
        type(override_t) :: ov
        k = 0
        call bind_keys(scene, keys)
        call parse_override(setting, keys, ov, err)
        if (.not. allocated(err)) call apply_override(ov, keys, err)
        if (.not. allocated(err)) k = ov%key
    end subroutine set_alone


    !> The effective scene as namelist text: all groups and keys, one per line,
    !! re-readable by `read_scene`.
    function scene_namelist_text(scene) result(text)
        type(scene_t), intent(in) :: scene
        character(len=:), allocatable :: text
        type(scene_t), target :: copy
        type(scene_key_t), allocatable :: keys(:)
        character(len=1), parameter :: NL = new_line('a')
        integer :: g, k
        copy = scene
        call bind_keys(copy, keys)
        text = ''
        do g = 1, N_GROUPS
            if (g > 1) text = text//NL
            text = text//'&'//trim(GROUP_NAMES(g))//NL
            do k = 1, size(keys)
                if (keys(k)%group /= g) cycle
                if (keys(k)%name == 'progress' .and. trim(GROUP_NAMES(g)) == 'output' .and. &
                    .not. scene%output%progress_given) then
                    ! not given: a comment, so that reading the echo back keeps it unset
                    text = text//'    ! progress = (not set: on when stderr is a terminal)'//NL
                else
                    text = text//keys(k)%echo()
                end if
            end do
            text = text//'/'
        end do
    end function scene_namelist_text

    !> An effective scene `text` (scene_namelist_text) without the line of its output file
    !! (the first of &output), for comparing two scenes that differ only in where their
    !! output goes: a sweep's case under its output directory spelled another way.
    pure function echo_without_output_file(text) result(rest)
        character(len=*), intent(in) :: text
        character(len=:), allocatable :: rest
        character(len=*), parameter :: HEAD = new_line('a')//'&output'//new_line('a')
        integer :: i, j
        rest = text
        i = index(text, HEAD)
        if (i == 0) return
        i = i + len(HEAD)
        j = index(text(i:), new_line('a'))
        if (j == 0) return
        if (index(adjustl(text(i:i + j - 2)), 'file = ') /= 1) return
        rest = text(:i - 1)//text(i + j:)
    end function echo_without_output_file

    !> The source a result file records for the scene (its root attribute `source`): the
    !! scene file and its --set overrides; for a scene given as text (the library's,
    !! read_scene_string, which has no source) what it was and the name it was given.
    !! Another run replaces the file only if its source is the same (ropedyn_run_inputs).
    function recorded_source(scene) result(text)
        type(scene_t), intent(in) :: scene
        character(len=:), allocatable :: text
        if (allocated(scene%source)) then
            text = scene%source
        else
            text = 'scene text given to the library, named "'//scene%path//'"'
        end if
    end function recorded_source

    !> The scene's effective text without the groups that do not define the rope and its
    !! surroundings (&initial, &solver, &output): two simulations whose physics texts are
    !! equal integrate the same equations, so a state of the one is a state of the other.
    function scene_physics_text(scene) result(text)
        type(scene_t), intent(in) :: scene
        character(len=:), allocatable :: text
        character(len=:), allocatable :: echo
        character(len=1), parameter :: NL = new_line('a')
        integer :: i, j
        logical :: kept
        echo = scene_namelist_text(scene)
        text = ''
        kept = .true.
        i = 1
        do while (i <= len(echo))
            j = index(echo(i:), NL)
            if (j == 0) j = len(echo) - i + 2
            associate (line => echo(i:i + j - 2))
                if (line == '&initial' .or. line == '&solver' .or. line == '&output') &
                    kept = .false.
                if (kept) text = text//line//NL
                if (line == '/') kept = .true.
            end associate
            i = i + j
        end do
    end function scene_physics_text

    !> The listing of `ropedyn keys`: a header and one line per key (tab-separated group,
    !! key, type, unit, default, allowed values, meaning); with `group`, that group's keys
    !! only (an unknown group: the header alone).
    function scene_key_listing(group) result(lines)
        character(len=*), intent(in), optional :: group
        type(text_t), allocatable :: lines(:)
        type(scene_t), target :: scene
        type(scene_key_t), allocatable :: keys(:)
        character(len=1), parameter :: TAB = achar(9)
        integer :: k
        call bind_keys(scene, keys)
        allocate (lines(0))
        call append_text(lines, 'group'//TAB//'key'//TAB//'type'//TAB//'unit'//TAB// &
                         'default'//TAB//'allowed'//TAB//'meaning')
        do k = 1, size(keys)
            if (present(group)) then
                if (trim(GROUP_NAMES(keys(k)%group)) /= group) cycle
            end if
            call append_text(lines, keys(k)%listing(trim(GROUP_NAMES(keys(k)%group))))
        end do
    end function scene_key_listing
end module ropedyn_scene
