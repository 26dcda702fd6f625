!> Sweep files (docs/reference/sweep-file.md): one `&sweep` group read by the namelist reader, its keys
!! from a small table, and every check that can be made before anything runs: the base
!! scene (named as `base`), each list value on its own (by the scene's key table) and with
!! the base scene, duplicate values, the `set` and `vary` entries, the reference (value and
!! file), the output directory and the number of cases. The cases are expanded by
!! `ropedyn_sweep` (src/studies).
!!
!!     &sweep
!!         base = 'paper.nml'                 ! relative to the sweep file's directory
!!         output_dir = 'out/sweep_demo'      ! relative to the working directory
!!         models = 'rfem'
!!         elements = 10, 30
!!         methods = 'cvode', 'mebdf'
!!         max_orders = 0                     ! 0: the method's default
!!         rtols = 1e-4, 1e-6
!!         atol_per_rtol = 0.01               ! atol = 0.01 rtol (else the scene's atol)
!!         set = 'solver.t_end=2', 'solver.output_interval=0.01'
!!         vary = 'rope.normal_damping = 1e3; 0.1'
!!         reference = 'tightest'             ! 'tightest_per_method', 'none' or a run file
!!     /
module ropedyn_sweep_file
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t, make_error, ERR_INPUT
    use ropedyn_text, only: int_text, real_text, lower, line_quote, text_t, clip, name_hint
    use ropedyn_os, only: unwritable_dir
    use ropedyn_namelist_file, only: nml_file_t, nml_assignment_t, read_namelist_file, &
        value_real, value_int, V_STRING
    use ropedyn_scene, only: scene_t, read_scene
    use ropedyn_case_file, only: case_data_t, read_case_file
    use ropedyn_sweep_lists, only: dimension_t, build_dimensions, without_set, MAX_LIST, &
        MAX_VARY, MAX_CASES
    implicit none
    private
    public :: sweep_file_t, dimension_t, read_sweep_file, without_set
    public :: MAX_LIST, MAX_VARY, MAX_CASES, REF_NONE, REF_TIGHTEST, REF_FILE, &
        REF_TIGHTEST_PER_METHOD

    !> How the errors of the summary are measured.
    integer, parameter :: REF_NONE = 0, REF_TIGHTEST = 1, REF_FILE = 2, REF_TIGHTEST_PER_METHOD = 3
    !> The `reference` keyword of each REF_* value (REF_FILE has none: a run file's name).
    character(len=*), parameter :: REFERENCE_KEYWORDS(0:3) = [character(len=19) :: 'none', &
        'tightest', '', 'tightest_per_method']

    !> The keys of a sweep file: name, type ('s' string, 'i' integer, 'r' real), most values.
    type :: sweep_key_t
        character(len=16) :: name
        character :: type
        integer :: most
    end type sweep_key_t
    type(sweep_key_t), parameter :: KEYS(*) = [sweep_key_t('base', 's', 1), &
        sweep_key_t('output_dir', 's', 1), sweep_key_t('models', 's', MAX_LIST), &
        sweep_key_t('elements', 'i', MAX_LIST), sweep_key_t('methods', 's', MAX_LIST), &
        sweep_key_t('max_orders', 'i', MAX_LIST), sweep_key_t('rtols', 'r', MAX_LIST), &
        sweep_key_t('atol_per_rtol', 'r', 1), sweep_key_t('set', 's', MAX_LIST), &
        sweep_key_t('vary', 's', MAX_VARY), sweep_key_t('reference', 's', 1)]
    integer, parameter :: K_BASE = 1, K_OUTPUT_DIR = 2, K_REFERENCE = 11, K_ATOL = 8

    !> The values of one key as read: text (as an override would give it) and, for reals,
    !! the number; `given` per index.
    type :: raw_t
        type(text_t), allocatable :: text(:)
        real(wp), allocatable :: x(:)
        logical, allocatable :: given(:)
        integer :: n = 0                !< values given (no gaps)
    end type raw_t

    !> A sweep file, read and checked.
    type :: sweep_file_t
        character(len=:), allocatable :: path        !< the sweep file
        character(len=:), allocatable :: name        !< file name without directory and .nml
        character(len=:), allocatable :: base        !< base scene, as a usable path
        character(len=:), allocatable :: output_dir  !< directory of the case files
        !> what gave output_dir, for messages about the files in it: 'PATH: &sweep:
        !! output_dir = "DIR"', '--output-dir "DIR"' or 'PATH: &sweep: output_dir (not given:
        !! "DIR")'
        character(len=:), allocatable :: output_dir_origin
        integer :: reference = REF_TIGHTEST           !< REF_*
        character(len=:), allocatable :: reference_file  !< REF_FILE: the run file
        type(text_t), allocatable :: set(:)          !< overrides of every case
        type(text_t), allocatable :: vary_keys(:)    !< 'group.key' of each `vary` entry
        !> the dimensions of the product in product order: models, elements, vary(1) ...,
        !! methods, max_orders, rtols
        type(dimension_t), allocatable :: dims(:)
        logical :: atol_given = .false.
        real(wp) :: atol_per_rtol = 0.0_wp           !< when atol_given
        !> an error of the base scene with the common overrides (or with one value) that
        !! the cases may not have: it stands when a case fails for `tentative_reason`
        type(error_t), allocatable :: tentative
        character(len=:), allocatable :: tentative_reason
    contains
        procedure :: reference_setting => sweep_reference_setting
    end type sweep_file_t

contains

    !> Read and check a sweep file. `output_dir`, when given and not empty, replaces the
    !! file's `output_dir` (the command line's --output-dir).
    subroutine read_sweep_file(path, sweep, err, output_dir)
        character(len=*), intent(in) :: path
        type(sweep_file_t), intent(out) :: sweep
        type(error_t), allocatable, intent(out) :: err
        character(len=*), intent(in), optional :: output_dir
        type(raw_t) :: raw(size(KEYS))
        character(len=:), allocatable :: where, dir
        type(scene_t) :: scene
        type(dimension_t) :: lists(5)
        integer :: slash

        sweep%path = trim(path)
        where = sweep%path//': &sweep: '
        slash = index(sweep%path, '/', back=.true.)
        dir = sweep%path(:slash)
        sweep%name = sweep%path(slash + 1:)
        if (len(sweep%name) > 4) then
            if (lower(sweep%name(len(sweep%name) - 3:)) == '.nml') &
                sweep%name = sweep%name(:len(sweep%name) - 4)
        end if
        call read_raw(sweep%path, raw, err)
        if (allocated(err)) return

        ! the base scene, on its own
        if (raw(K_BASE)%n == 0) then
            call make_error(err, ERR_INPUT, where//'base: missing (the scene file the ' &
                //'cases start from)')
            return
        end if
        sweep%base = relative_to(dir, raw(K_BASE)%text(1)%s)
        call read_scene(sweep%base, [character(len=1) ::], scene, err)
        if (allocated(err)) then
            err%message = where//'base = "'//clip(raw(K_BASE)%text(1)%s)//'": '//err%message
            return
        end if
        call set_output_dir(where, raw(K_OUTPUT_DIR), sweep, err, output_dir)
        if (allocated(err)) return
        call read_reference(where, dir, raw(K_REFERENCE), sweep, err)
        if (allocated(err)) return
        call read_atol_per_rtol(where, raw(K_ATOL), sweep, err)
        if (allocated(err)) return

        call set_list(raw, lists(1), 'models', 'model.kind')
        call set_list(raw, lists(2), 'elements', 'model.elements')
        call set_list(raw, lists(3), 'methods', 'solver.method')
        call set_list(raw, lists(4), 'max_orders', 'solver.max_order')
        call set_list(raw, lists(5), 'rtols', 'solver.rtol')
        call build_dimensions(where, sweep%base, list_of(raw, 'set'), list_of(raw, 'vary'), &
            lists, sweep%atol_given, sweep%set, sweep%vary_keys, sweep%dims, &
            sweep%tentative, sweep%tentative_reason, err)
    end subroutine read_sweep_file

    !> The output directory: --output-dir, else output_dir, else out/sweep_<name>, without
    !! trailing slashes; refused when it cannot hold the case files.
    subroutine set_output_dir(where, given, sweep, err, output_dir)
        character(len=*), intent(in) :: where
        type(raw_t), intent(in) :: given
        type(sweep_file_t), intent(inout) :: sweep
        type(error_t), allocatable, intent(out) :: err
        character(len=*), intent(in), optional :: output_dir
        character(len=:), allocatable :: why
        if (given%n > 0) sweep%output_dir = given%text(1)%s
        if (present(output_dir)) then
            if (len_trim(output_dir) > 0) sweep%output_dir = trim(adjustl(output_dir))
        end if
        if (.not. allocated(sweep%output_dir)) sweep%output_dir = ''
        if (len(sweep%output_dir) == 0) sweep%output_dir = 'out/sweep_'//sweep%name
        do while (len(sweep%output_dir) > 1)
            if (sweep%output_dir(len(sweep%output_dir):) /= '/') exit
            sweep%output_dir = sweep%output_dir(:len(sweep%output_dir) - 1)
        end do
        if (given%n > 0) then
            sweep%output_dir_origin = where//'output_dir = "'//sweep%output_dir//'"'
        else
            sweep%output_dir_origin = where//'output_dir (not given: "'//sweep%output_dir//'")'
        end if
        if (present(output_dir)) then
            if (len_trim(output_dir) > 0) &
                sweep%output_dir_origin = '--output-dir "'//sweep%output_dir//'"'
        end if
        why = unwritable_dir(sweep%output_dir)
        if (len(why) == 0) return
        call make_error(err, ERR_INPUT, where//'output_dir = "'//sweep%output_dir// &
            '": cannot hold the case files: '//why)
        if (present(output_dir)) then
            if (len_trim(output_dir) > 0) err%message = 'sweep: --output-dir "'// &
                sweep%output_dir//'": cannot hold the case files: '//why
        end if
    end subroutine set_output_dir

    !> atol_per_rtol, when given: finite and > 0.
    subroutine read_atol_per_rtol(where, given, sweep, err)
        character(len=*), intent(in) :: where
        type(raw_t), intent(in) :: given
        type(sweep_file_t), intent(inout) :: sweep
        type(error_t), allocatable, intent(out) :: err
        sweep%atol_given = given%n > 0
        if (.not. sweep%atol_given) return
        sweep%atol_per_rtol = given%x(1)
        if (.not. (ieee_is_finite(sweep%atol_per_rtol) .and. sweep%atol_per_rtol > 0.0_wp)) &
            call make_error(err, ERR_INPUT, where//'atol_per_rtol = '// &
                real_text(sweep%atol_per_rtol, compact=.true.)//': must be > 0')
    end subroutine read_atol_per_rtol

    !> The values given of key `name`.
    function list_of(raw, name) result(list)
        type(raw_t), intent(in) :: raw(:)
        character(len=*), intent(in) :: name
        type(text_t), allocatable :: list(:)
        integer :: k, i
        do k = 1, size(KEYS)
            if (KEYS(k)%name == name) exit
        end do
        allocate (list(raw(k)%n))
        do i = 1, raw(k)%n
            list(i)%s = raw(k)%text(i)%s
        end do
    end function list_of

    !> The dimension of a list key (`key`: the &sweep key, `target`: the scene key it sets).
    subroutine set_list(raw, d, key, target)
        type(raw_t), intent(in) :: raw(:)
        type(dimension_t), intent(out) :: d
        character(len=*), intent(in) :: key, target
        d%key = key
        d%target = target
        d%values = list_of(raw, key)
    end subroutine set_list

    !> A file name: as given when absolute, else relative to `dir`.
    pure function relative_to(dir, name) result(path)
        character(len=*), intent(in) :: dir, name
        character(len=:), allocatable :: path
        path = trim(adjustl(name))
        if (len(path) == 0) return
        if (path(1:1) /= '/') path = dir//path
    end function relative_to

    !> 'tightest' (the default), 'tightest_per_method', 'none' (or ''), or a run file that
    !! can be read and holds a complete run (that it suits every case is checked with the
    !! cases, by ropedyn_sweep).
    subroutine read_reference(where, dir, raw, sweep, err)
        character(len=*), intent(in) :: where, dir
        type(raw_t), intent(in) :: raw
        type(sweep_file_t), intent(inout) :: sweep
        type(error_t), allocatable, intent(out) :: err
        type(case_data_t) :: data
        character(len=:), allocatable :: value, hint
        integer :: k
        value = 'tightest'
        if (raw%n > 0) value = trim(adjustl(raw%text(1)%s))
        sweep%reference = REF_FILE
        if (len(value) == 0) sweep%reference = REF_NONE
        do k = lbound(REFERENCE_KEYWORDS, 1), ubound(REFERENCE_KEYWORDS, 1)
            if (k /= REF_FILE .and. lower(value) == trim(REFERENCE_KEYWORDS(k))) &
                sweep%reference = k
        end do
        if (sweep%reference == REF_FILE) then
            sweep%reference_file = relative_to(dir, value)
            call read_case_file(sweep%reference_file, data, err, series=.true.)
            if (allocated(err)) then
                err%code = ERR_INPUT
                err%message = where//'reference = "'//value//'": '//err%message// &
                    ' (expected ''tightest'', ''tightest_per_method'', ''none'' or a ropedyn ' &
                    //'run file)'
            else if (.not. data%exists) then
                call make_error(err, ERR_INPUT, where//'reference = "'//value//'": no such ' &
                    //'file ('//sweep%reference_file//'; expected ''tightest'', ' &
                    //'''tightest_per_method'', ''none'' or a ropedyn run file)')
                ! a misspelt keyword rather than a file?
                hint = name_hint([text_t('tightest'), text_t('tightest_per_method'), &
                                  text_t('none')], value)
                if (hint(1:3) == '; d') err%message = err%message//hint
            else if (data%status /= 'complete' .or. data%records < 1) then
                call make_error(err, ERR_INPUT, where//'reference = "'//value//'": not a ' &
                    //'complete run (status '//data%status//', '//int_text(data%records)// &
                    ' records)')
            end if
        end if
    end subroutine read_reference

    !> The `reference` setting as the sweep file gives it (its keyword, or the run file), as
    !! written in summary.h5 and on the terminal.
    function sweep_reference_setting(self) result(text)
        class(sweep_file_t), intent(in) :: self
        character(len=:), allocatable :: text
        if (self%reference == REF_FILE) then
            text = self%reference_file
        else
            text = trim(REFERENCE_KEYWORDS(self%reference))
        end if
    end function sweep_reference_setting

    !> The &sweep group, its values by key (typed, without gaps).
    subroutine read_raw(path, raw, err)
        character(len=*), intent(in) :: path
        type(raw_t), intent(out) :: raw(:)
        type(error_t), allocatable, intent(out) :: err
        type(nml_file_t) :: file
        type(text_t), allocatable :: names(:)
        integer :: k, j, i
        call read_namelist_file(path, ['sweep'], file, err, hint='a sweep file holds one ' &
            //'&sweep group, and nothing but comments before or after the &sweep group', &
            required='sweep', not_what='not a sweep file (expected the &sweep group; scenes ' &
            //'go in the base scene file)')
        if (allocated(err)) return
        allocate (names(size(KEYS)))
        do k = 1, size(KEYS)
            names(k)%s = trim(KEYS(k)%name)
            allocate (raw(k)%text(KEYS(k)%most), raw(k)%x(KEYS(k)%most))
            allocate (raw(k)%given(KEYS(k)%most), source=.false.)
        end do
        associate (g => file%groups(1))
            do j = 1, size(g%assignments)
                do k = 1, size(KEYS)
                    if (KEYS(k)%name == g%assignments(j)%name) exit
                end do
                if (k > size(KEYS)) then
                    call make_error(err, ERR_INPUT, path//': &sweep: unknown key "'// &
                        g%assignments(j)%key//'" (line '//int_text(g%assignments(j)%line)// &
                        ': '//line_quote(g%assignments(j)%line_text)//')'// &
                        name_hint(names, g%assignments(j)%name))
                    return
                end if
                call store(path, KEYS(k), g%assignments(j), raw(k), err)
                if (allocated(err)) return
            end do
        end associate
        ! lists have no gaps
        do k = 1, size(KEYS)
            associate (r => raw(k))
                r%n = size(r%given)
                do i = 1, size(r%given)
                    if (.not. r%given(i)) then
                        r%n = i - 1
                        exit
                    end if
                end do
                do i = r%n + 2, size(r%given)
                    if (.not. r%given(i)) cycle
                    r%text(i)%s = clip(r%text(i)%s)
                    if (KEYS(k)%type == 's') r%text(i)%s = '"'//r%text(i)%s//'"'
                    call make_error(err, ERR_INPUT, path//': &sweep: '//trim(KEYS(k)%name)// &
                        '('//int_text(i)//') = '//r%text(i)%s//': given, but '// &
                        trim(KEYS(k)%name)//'('//int_text(r%n + 1)//') is not (lists have ' &
                        //'no gaps)')
                    return
                end do
            end associate
        end do
    end subroutine read_raw

    !> Store the values of one assignment, typed, as text.
    subroutine store(path, key, a, raw, err)
        character(len=*), intent(in) :: path
        type(sweep_key_t), intent(in) :: key
        type(nml_assignment_t), intent(in) :: a
        type(raw_t), intent(inout) :: raw
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: expected
        integer :: first, k, n
        logical :: ok
        real(wp) :: x
        first = max(a%index, 1)
        select case (key%type)
        case ('s')
            expected = 'expected quoted strings'
        case ('i')
            expected = 'expected integers'
        case default
            expected = 'expected real numbers'
        end select
        if (key%most == 1) expected = expected(:len(expected) - 1)
        if (key%most == 1) expected = replace_plural(expected)
        ok = first + size(a%values) - 1 <= key%most
        if (.not. ok .and. key%most > 1) expected = expected//' (at most '// &
            int_text(key%most)//')'
        do k = 1, size(a%values)
            if (.not. ok) exit
            associate (v => a%values(k), i => first + k - 1)
                select case (key%type)
                case ('s')
                    ok = v%kind == V_STRING
                    if (ok) raw%text(i)%s = trim(adjustl(v%text))
                case ('i')
                    call value_int(v, n, ok)
                    if (ok) raw%text(i)%s = int_text(n)
                case default
                    call value_real(v, x, ok)
                    if (ok) raw%text(i)%s = real_text(x, compact=.true.)
                    if (ok) raw%x(i) = x
                end select
                raw%given(i) = ok
            end associate
        end do
        if (.not. ok) call make_error(err, ERR_INPUT, path//': &sweep: cannot read '//a%key// &
            ' = '//clip(a%value_text)//': '//expected//' (line '//int_text(a%line)//': '// &
            line_quote(a%line_text)//')')
    end subroutine store

    !> 'expected quoted string' -> 'expected a quoted string' (and likewise).
    pure function replace_plural(text) result(s)
        character(len=*), intent(in) :: text
        character(len=:), allocatable :: s
        s = 'expected a'//text(len('expected') + 1:)
        if (index(text, 'integer') > 0) s = 'expected an integer'
    end function replace_plural
end module ropedyn_sweep_file
