!> Sweep files: a base scene and lists of values whose cartesian product is a batch of
!! cases (docs/sweeps.md).
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
!!         reference = 'tightest'             ! 'none' or an HDF5 run file
!!     /
!!
!! Case ids run from 1 in the order of the cartesian product models > elements > vary(1) >
!! vary(2) ... > methods > max_orders > rtols, the last varying fastest. A list that is not
!! given is one value: whatever the base scene (after `set`) says. Every list value and
!! every case is checked by reading the base scene with its overrides (`read_scene`), so a
!! bad value is reported before anything runs, naming the sweep file, the key and the value.
module ropedyn_sweep
    use, intrinsic :: ieee_arithmetic, only: ieee_is_nan, ieee_is_finite
    use ropedyn_kinds, only: wp, i8
    use ropedyn_text, only: int_text, real_text, lower
    use ropedyn_error, only: error_t, make_error, ERR_INPUT
    use ropedyn_scene, only: scene_t, read_scene
    implicit none
    private
    public :: text_t, sweep_case_t, sweep_t, read_sweep, case_name
    public :: MAX_LIST, MAX_VARY, REF_NONE, REF_TIGHTEST, REF_FILE

    integer, parameter :: MAX_LIST = 64   !< most values of one list key
    integer, parameter :: MAX_VARY = 8    !< most `vary` entries
    integer, parameter :: BUF_LEN = 512   !< length of a string value in the sweep file

    !> How the errors of the summary are measured.
    integer, parameter :: REF_NONE = 0, REF_TIGHTEST = 1, REF_FILE = 2

    !> Sentinels of list entries that were not given.
    integer, parameter :: INT_UNSET = -huge(1)
    real(wp), parameter :: REAL_UNSET = transfer(9221120237041090560_i8, 1.0_wp)  ! NaN

    !> A string of any length (for arrays of strings of different lengths).
    type :: text_t
        character(len=:), allocatable :: s
    end type text_t

    !> One case: its overrides of the base scene and the effective scene they give.
    type :: sweep_case_t
        integer :: id = 0                       !< 1, 2, ... in product order
        type(text_t), allocatable :: overrides(:)  !< the case's own group.key=value (no set)
        type(text_t), allocatable :: vary_values(:) !< value of each `vary` entry
        character(len=:), allocatable :: file   !< <output_dir>/case_<id>.h5
        integer :: group = 0                    !< same model, elements and vary values
        type(scene_t) :: scene                  !< the effective scene of the case
    end type sweep_case_t

    !> A sweep: the base scene, the common and the per-case overrides, the cases.
    type :: sweep_t
        character(len=:), allocatable :: path        !< the sweep file
        character(len=:), allocatable :: name        !< file name without directory and .nml
        character(len=:), allocatable :: base        !< base scene, as a usable path
        character(len=:), allocatable :: output_dir  !< directory of the case files
        integer :: reference = REF_TIGHTEST           !< REF_*
        character(len=:), allocatable :: reference_file  !< REF_FILE: the run file
        type(text_t), allocatable :: set(:)          !< overrides of every case
        type(text_t), allocatable :: vary_keys(:)    !< 'group.key' of each `vary` entry
        type(sweep_case_t), allocatable :: cases(:)
        integer :: n_groups = 0                       !< distinct case%group values
    end type sweep_t

    !> One dimension of the product: its overrides, one per value.
    type :: dimension_t
        character(len=:), allocatable :: key     !< sweep key, for messages
        character(len=:), allocatable :: target  !< group.key it sets ('' if not given)
        type(text_t), allocatable :: values(:)   !< values as override text
    end type dimension_t

contains

    !> Read and check a sweep file and expand its cases.
    !! `output_dir`, when given and not empty, replaces the file's `output_dir`.
    subroutine read_sweep(path, sweep, err, output_dir)
        character(len=*), intent(in) :: path
        type(sweep_t), intent(out) :: sweep
        type(error_t), allocatable, intent(out) :: err
        character(len=*), intent(in), optional :: output_dir
        character(len=BUF_LEN) :: base, reference, out_dir
        character(len=BUF_LEN) :: models(MAX_LIST), methods(MAX_LIST), set(MAX_LIST), &
            vary(MAX_VARY)
        integer :: elements(MAX_LIST), max_orders(MAX_LIST)
        real(wp) :: rtols(MAX_LIST), atol_per_rtol
        type(dimension_t), allocatable :: dims(:)
        type(text_t), allocatable :: none(:)
        character(len=:), allocatable :: where, dir
        integer :: slash, k, n_set

        sweep%path = trim(path)
        where = sweep%path//': &sweep: '
        slash = index(sweep%path, '/', back=.true.)
        dir = sweep%path(:slash)
        sweep%name = sweep%path(slash + 1:)
        if (len(sweep%name) > 4) then
            if (lower(sweep%name(len(sweep%name) - 3:)) == '.nml') &
                sweep%name = sweep%name(:len(sweep%name) - 4)
        end if

        base = ''
        out_dir = ''
        reference = 'tightest'
        models = ''
        methods = ''
        set = ''
        vary = ''
        elements = INT_UNSET
        max_orders = INT_UNSET
        rtols = REAL_UNSET
        atol_per_rtol = REAL_UNSET
        call read_namelist(sweep%path, base, out_dir, reference, models, elements, methods, &
            max_orders, rtols, atol_per_rtol, set, vary, err)
        if (allocated(err)) return

        ! base scene
        if (len_trim(base) == 0) then
            call make_error(err, ERR_INPUT, where//'base: missing (the scene file the ' &
                //'cases start from)')
            return
        end if
        base = adjustl(base)
        if (base(1:1) == '/') then
            sweep%base = trim(base)
        else
            sweep%base = dir//trim(base)
        end if

        ! output directory
        if (present(output_dir)) then
            if (len_trim(output_dir) > 0) out_dir = output_dir
        end if
        if (len_trim(out_dir) == 0) out_dir = 'out/sweep_'//sweep%name
        sweep%output_dir = trim(adjustl(out_dir))
        do while (len(sweep%output_dir) > 1)
            if (sweep%output_dir(len(sweep%output_dir):) /= '/') exit
            sweep%output_dir = sweep%output_dir(:len(sweep%output_dir) - 1)
        end do

        ! reference
        select case (lower(trim(adjustl(reference))))
        case ('tightest')
            sweep%reference = REF_TIGHTEST
        case ('none', '')
            sweep%reference = REF_NONE
        case default
            sweep%reference = REF_FILE
            reference = adjustl(reference)
            if (reference(1:1) == '/') then
                sweep%reference_file = trim(reference)
            else
                sweep%reference_file = dir//trim(reference)
            end if
        end select

        ! common overrides
        call count_strings(where, 'set', set, n_set, err)
        if (allocated(err)) return
        allocate (sweep%set(n_set))
        do k = 1, n_set
            sweep%set(k)%s = trim(adjustl(set(k)))
            call check_not_reserved(where, 'set('//int_text(k)//')', sweep%set(k)%s, &
                                    [models(1), methods(1)], [elements(1), max_orders(1)], &
                                    rtols(1), atol_per_rtol, err)
            if (allocated(err)) return
        end do
        allocate (none(0))
        call check_scene_with(sweep, 'set', 'the common overrides', none, err)
        if (allocated(err)) return

        call build_dimensions(sweep, where, models, elements, methods, max_orders, rtols, &
                              atol_per_rtol, vary, dims, err)
        if (allocated(err)) return
        if (.not. (ieee_is_nan(atol_per_rtol))) then
            if (.not. (ieee_is_finite(atol_per_rtol) .and. atol_per_rtol > 0.0_wp)) then
                call make_error(err, ERR_INPUT, where//'atol_per_rtol = '// &
                    real_text(atol_per_rtol, compact=.true.)//': must be > 0')
                return
            end if
        end if
        call expand(sweep, dims, atol_per_rtol, err)
    end subroutine read_sweep

    !> The file name of case `id` in a sweep of `n` cases: case_0007.h5 (at least 4 digits).
    pure function case_name(id, n) result(name)
        integer, intent(in) :: id, n
        character(len=:), allocatable :: name
        character(len=16) :: buf
        integer :: width
        width = max(4, len(int_text(n)))
        write (buf, '(i0.'//int_text(width)//')') id
        name = 'case_'//trim(buf)//'.h5'
    end function case_name

    ! ------------------------------------------------------------------------------------
    ! Reading the file
    ! ------------------------------------------------------------------------------------

    subroutine read_namelist(path, base, output_dir, reference, models, elements, methods, &
                             max_orders, rtols, atol_per_rtol, set, vary, err)
        character(len=*), intent(in) :: path
        character(len=*), intent(inout) :: base, output_dir, reference, models(:), &
            methods(:), set(:), vary(:)
        integer, intent(inout) :: elements(:), max_orders(:)
        real(wp), intent(inout) :: rtols(:), atol_per_rtol
        type(error_t), allocatable, intent(out) :: err
        namelist /sweep/ base, output_dir, reference, models, elements, methods, max_orders, &
            rtols, atol_per_rtol, set, vary
        type(text_t), allocatable :: lines(:)
        character(len=:), allocatable :: recs(:)
        character(len=BUF_LEN) :: msg, line_msg
        integer :: ios, i, first, last, width

        call read_lines(path, lines, err)
        if (allocated(err)) return
        call locate_group(path, lines, first, last, err)
        if (allocated(err)) return
        width = 1
        do i = 1, size(lines)
            width = max(width, len(lines(i)%s))
        end do
        allocate (character(len=width) :: recs(last - first + 1))
        do i = first, last
            recs(i - first + 1) = lines(i)%s
        end do
        msg = ''
        read (recs, nml=sweep, iostat=ios, iomsg=msg)
        if (ios == 0) return
        ! Find the first line that cannot be read on its own.
        do i = first, last
            block
                character(len=max(len(lines(i)%s), 6)) :: one(3)
                one(1) = '&sweep'
                one(2) = lines(i)%s
                one(3) = '/'
                if (i == first) one(2) = lines(i)%s(index(lower(lines(i)%s), '&sweep') + 6:)
                if (i == last .and. index(one(2), '/') > 0) one(2) = one(2)(:index(one(2), '/', &
                    back=.true.) - 1)
                line_msg = ''
                read (one, nml=sweep, iostat=ios, iomsg=line_msg)
                if (ios /= 0) then
                    call make_error(err, ERR_INPUT, path//': &sweep: cannot read line '// &
                        int_text(i)//': "'//trim(lines(i)%s)//'" ['//trim(line_msg)// &
                        '] (keys: base, output_dir, models, elements, methods, max_orders, ' &
                        //'rtols, atol_per_rtol, set, vary, reference)')
                    return
                end if
            end block
        end do
        call make_error(err, ERR_INPUT, path//': &sweep: cannot read: '//trim(msg))
    end subroutine read_namelist

    !> All lines of a text file.
    subroutine read_lines(path, lines, err)
        character(len=*), intent(in) :: path
        type(text_t), allocatable, intent(out) :: lines(:)
        type(error_t), allocatable, intent(out) :: err
        type(text_t), allocatable :: grown(:)
        character(len=256) :: chunk
        character(len=BUF_LEN) :: msg
        character(len=:), allocatable :: line
        integer :: unit, ios, n, sz
        logical :: last

        msg = ''
        open (newunit=unit, file=path, status='old', action='read', iostat=ios, iomsg=msg)
        if (ios /= 0) then
            call make_error(err, ERR_INPUT, path//': cannot open: '//trim(msg))
            return
        end if
        allocate (lines(32))
        n = 0
        last = .false.
        do while (.not. last)
            line = ''
            do
                read (unit, '(a)', advance='no', size=sz, iostat=ios, iomsg=msg) chunk
                line = line//chunk(:sz)
                if (ios /= 0) exit
            end do
            if (is_iostat_eor(ios)) then
                ios = 0
            else if (is_iostat_end(ios)) then
                last = .true.
                if (len(line) == 0) exit
            else
                call make_error(err, ERR_INPUT, path//': cannot read: '//trim(msg))
                close (unit)
                return
            end if
            if (n == size(lines)) then
                allocate (grown(2*n))
                grown(:n) = lines
                call move_alloc(grown, lines)
            end if
            n = n + 1
            lines(n)%s = line
        end do
        close (unit)
        lines = lines(:n)
    end subroutine read_lines

    !> The lines of the one &sweep group; nothing else but blanks and comments is allowed.
    subroutine locate_group(path, lines, first, last, err)
        character(len=*), intent(in) :: path
        type(text_t), intent(in) :: lines(:)
        integer, intent(out) :: first, last
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: s
        integer :: i, lead
        first = 0
        last = 0
        do i = 1, size(lines)
            s = lower(lines(i)%s)
            lead = verify(s, ' '//achar(9))
            if (first > 0 .and. last == 0) then
                if (has_close(s)) last = i
                cycle
            end if
            if (lead == 0) cycle
            if (s(lead:lead) == '!') cycle
            if (first == 0 .and. len(s) >= lead + 5) then
                if (s(lead:lead + 5) == '&sweep') then
                    if (len(s) == lead + 5) then
                        first = i
                    else if (scan(s(lead + 6:lead + 6), ' ,'//achar(9)) > 0) then
                        first = i
                    end if
                    if (first == i) then
                        if (has_close(s(lead + 6:))) last = i
                        cycle
                    end if
                end if
            end if
            if (first > 0) then
                call make_error(err, ERR_INPUT, path//': line '//int_text(i)//': text after ' &
                    //'the &sweep group: "'//trim(lines(i)%s)//'" (a sweep file holds one ' &
                    //'&sweep group)')
            else
                call make_error(err, ERR_INPUT, path//': line '//int_text(i)//': "'// &
                    trim(lines(i)%s)//'": expected the &sweep group (a sweep file holds ' &
                    //'one &sweep group; scenes go in the base scene file)')
            end if
            return
        end do
        if (first == 0) then
            call make_error(err, ERR_INPUT, path//': no &sweep group: not a sweep file')
        else if (last == 0) then
            call make_error(err, ERR_INPUT, path//': &sweep: not closed by "/"')
        end if
    end subroutine locate_group

    !> True if a '/' outside quotes and comments ends the group on this line.
    pure logical function has_close(s)
        character(len=*), intent(in) :: s
        character :: quote
        integer :: i
        has_close = .false.
        quote = ' '
        do i = 1, len(s)
            if (quote /= ' ') then
                if (s(i:i) == quote) quote = ' '
                cycle
            end if
            select case (s(i:i))
            case ("'", '"')
                quote = s(i:i)
            case ('!')
                return
            case ('/')
                has_close = .true.
                return
            end select
        end do
    end function has_close

    ! ------------------------------------------------------------------------------------
    ! Checks and the product
    ! ------------------------------------------------------------------------------------

    !> Number of leading strings given; a value after a gap is an error.
    subroutine count_strings(where, key, values, n, err)
        character(len=*), intent(in) :: where, key
        character(len=*), intent(in) :: values(:)
        integer, intent(out) :: n
        type(error_t), allocatable, intent(out) :: err
        integer :: k
        n = 0
        do k = 1, size(values)
            if (len_trim(values(k)) == 0) exit
            n = k
        end do
        do k = n + 2, size(values)
            if (len_trim(values(k)) > 0) then
                call make_error(err, ERR_INPUT, where//key//'('//int_text(k)//') = "'// &
                    trim(values(k))//'": given, but '//key//'('//int_text(n + 1)//') is ' &
                    //'empty (lists have no gaps)')
                return
            end if
        end do
    end subroutine count_strings

    !> A `set` entry must not set what a list sets (the list would silently win) nor
    !! the output of a case.
    subroutine check_not_reserved(where, key, override, names, ints, rtol1, atol_factor, err)
        character(len=*), intent(in) :: where, key, override
        character(len=*), intent(in) :: names(2)
        integer, intent(in) :: ints(2)
        real(wp), intent(in) :: rtol1, atol_factor
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: target, list
        integer :: eq
        eq = index(override, '=')
        if (eq == 0) then
            call make_error(err, ERR_INPUT, where//key//' = "'//override//'": expected ' &
                //'group.key=value')
            return
        end if
        target = lower(trim(adjustl(override(:eq - 1))))
        list = ''
        select case (target)
        case ('model.kind')
            if (len_trim(names(1)) > 0) list = 'models'
        case ('solver.method')
            if (len_trim(names(2)) > 0) list = 'methods'
        case ('model.elements')
            if (ints(1) /= INT_UNSET) list = 'elements'
        case ('solver.max_order')
            if (ints(2) /= INT_UNSET) list = 'max_orders'
        case ('solver.rtol')
            if (.not. ieee_is_nan(rtol1)) list = 'rtols'
        case ('solver.atol')
            if (.not. ieee_is_nan(atol_factor)) list = 'atol_per_rtol'
        case ('output.file', 'output.progress')
            call make_error(err, ERR_INPUT, where//key//' = "'//override//'": '//target// &
                ' is set by the sweep for every case (use output_dir)')
            return
        end select
        if (len(list) > 0) call make_error(err, ERR_INPUT, where//key//' = "'//override// &
            '": '//target//' is already set by '//list)
    end subroutine check_not_reserved

    !> Read the base scene with the common overrides and `extra`; an error names `key`.
    subroutine check_scene_with(sweep, key, what, extra, err)
        type(sweep_t), intent(in) :: sweep
        character(len=*), intent(in) :: key, what
        type(text_t), intent(in) :: extra(:)
        type(error_t), allocatable, intent(out) :: err
        type(scene_t) :: scene
        type(text_t), allocatable :: all(:)
        all = sweep%set
        call extend(all, extra)
        call read_scene(sweep%base, override_array(all), scene, err)
        if (.not. allocated(err)) return
        if (len(what) > 0) then
            err%message = sweep%path//': &sweep: '//key//': '//what//': '//err%message
        else
            err%message = sweep%path//': &sweep: '//key//': '//without_set(err%message)
        end if
    end subroutine check_scene_with

    !> The lists as dimensions of the product, in product order; every value checked.
    subroutine build_dimensions(sweep, where, models, elements, methods, max_orders, rtols, &
                                atol_per_rtol, vary, dims, err)
        type(sweep_t), intent(inout) :: sweep
        character(len=*), intent(in) :: where
        character(len=*), intent(in) :: models(:), methods(:), vary(:)
        integer, intent(in) :: elements(:), max_orders(:)
        real(wp), intent(in) :: rtols(:), atol_per_rtol
        type(dimension_t), allocatable, intent(out) :: dims(:)
        type(error_t), allocatable, intent(out) :: err
        type(dimension_t) :: d
        integer :: n_vary, k, i, n, eq, nd
        character(len=:), allocatable :: entry, values, value
        type(text_t), allocatable :: one(:)

        call count_strings(where, 'vary', vary, n_vary, err)
        if (allocated(err)) return
        allocate (dims(5 + n_vary))
        nd = 0
        allocate (sweep%vary_keys(n_vary))

        ! models
        call count_strings(where, 'models', models, n, err)
        if (allocated(err)) return
        call new_dimension(d, 'models', '')
        if (n > 0) d%target = 'model.kind'
        do k = 1, n
            call append(d%values, trim(adjustl(models(k))))
        end do
        nd = nd + 1
        dims(nd) = d

        ! elements
        call new_dimension(d, 'elements', '')
        n = count_ints(elements)
        call check_no_int_gap(where, 'elements', elements, n, err)
        if (allocated(err)) return
        if (n > 0) d%target = 'model.elements'
        do k = 1, n
            if (elements(k) < 2) then
                call make_error(err, ERR_INPUT, where//'elements('//int_text(k)//') = '// &
                    int_text(elements(k))//': must be >= 2')
                return
            end if
            call append(d%values, int_text(elements(k)))
        end do
        nd = nd + 1
        dims(nd) = d

        ! vary entries: 'group.key = v1; v2; ...'
        do i = 1, n_vary
            entry = trim(adjustl(vary(i)))
            eq = index(entry, '=')
            if (eq <= 1) then
                call make_error(err, ERR_INPUT, where//'vary('//int_text(i)//') = "'//entry// &
                    '": expected "group.key = value1; value2; ..."')
                return
            end if
            call new_dimension(d, 'vary('//int_text(i)//')', lower(trim(entry(:eq - 1))))
            call check_not_reserved(where, 'vary('//int_text(i)//')', entry, &
                                    [models(1), methods(1)], [elements(1), max_orders(1)], &
                                    rtols(1), atol_per_rtol, err)
            if (allocated(err)) return
            do k = 1, i - 1
                if (sweep%vary_keys(k)%s == d%target) then
                    call make_error(err, ERR_INPUT, where//'vary('//int_text(i)//') = "'// &
                        entry//'": '//d%target//' is already varied by vary('//int_text(k)//')')
                    return
                end if
            end do
            sweep%vary_keys(i)%s = d%target
            values = entry(eq + 1:)
            do
                k = index(values, ';')
                if (k == 0) then
                    value = trim(adjustl(values))
                else
                    value = trim(adjustl(values(:k - 1)))
                end if
                if (len(value) == 0) then
                    call make_error(err, ERR_INPUT, where//'vary('//int_text(i)//') = "'// &
                        entry//'": empty value (values are separated by ";")')
                    return
                end if
                call append(d%values, value)
                if (k == 0) exit
                values = values(k + 1:)
            end do
            nd = nd + 1
            dims(nd) = d
        end do

        ! methods
        call count_strings(where, 'methods', methods, n, err)
        if (allocated(err)) return
        call new_dimension(d, 'methods', '')
        if (n > 0) d%target = 'solver.method'
        do k = 1, n
            call append(d%values, trim(adjustl(methods(k))))
        end do
        nd = nd + 1
        dims(nd) = d

        ! max_orders
        call new_dimension(d, 'max_orders', '')
        n = count_ints(max_orders)
        call check_no_int_gap(where, 'max_orders', max_orders, n, err)
        if (allocated(err)) return
        if (n > 0) d%target = 'solver.max_order'
        do k = 1, n
            if (max_orders(k) < 0) then
                call make_error(err, ERR_INPUT, where//'max_orders('//int_text(k)//') = '// &
                    int_text(max_orders(k))//': must be >= 0 (0: the method''s default)')
                return
            end if
            call append(d%values, int_text(max_orders(k)))
        end do
        nd = nd + 1
        dims(nd) = d

        ! rtols
        call new_dimension(d, 'rtols', '')
        n = 0
        do k = 1, size(rtols)
            if (ieee_is_nan(rtols(k))) exit
            n = k
        end do
        do k = n + 2, size(rtols)
            if (.not. ieee_is_nan(rtols(k))) then
                call make_error(err, ERR_INPUT, where//'rtols('//int_text(k)//') = '// &
                    real_text(rtols(k), compact=.true.)//': given, but rtols('//int_text(n + 1)// &
                    ') is not (lists have no gaps)')
                return
            end if
        end do
        if (n > 0) d%target = 'solver.rtol'
        do k = 1, n
            if (.not. (rtols(k) > 0.0_wp .and. rtols(k) < 1.0_wp)) then
                call make_error(err, ERR_INPUT, where//'rtols('//int_text(k)//') = '// &
                    real_text(rtols(k), compact=.true.)//': must be > 0 and < 1')
                return
            end if
            call append(d%values, real_text(rtols(k), compact=.true.))
        end do
        nd = nd + 1
        dims(nd) = d

        ! Every value on its own with the base scene and the common overrides (methods and
        ! max_orders are checked together, in the cases: the order range is per method).
        do i = 1, size(dims)
            if (len(dims(i)%target) == 0 .or. dims(i)%key == 'max_orders') cycle
            do k = 1, size(dims(i)%values)
                allocate (one(1))
                one(1)%s = dims(i)%target//'='//dims(i)%values(k)%s
                if (dims(i)%key(1:4) == 'vary') then
                    call check_scene_with(sweep, dims(i)%key//' = "'//trim(adjustl(vary(max(1, &
                        i - 2))))//'", value '//int_text(k), '', one, err)
                else
                    call check_scene_with(sweep, dims(i)%key//'('//int_text(k)//') = "'// &
                        dims(i)%values(k)%s//'"', '', one, err)
                end if
                deallocate (one)
                if (allocated(err)) return
            end do
        end do
    end subroutine build_dimensions

    pure integer function count_ints(values) result(n)
        integer, intent(in) :: values(:)
        integer :: k
        n = 0
        do k = 1, size(values)
            if (values(k) == INT_UNSET) exit
            n = k
        end do
    end function count_ints

    subroutine check_no_int_gap(where, key, values, n, err)
        character(len=*), intent(in) :: where, key
        integer, intent(in) :: values(:), n
        type(error_t), allocatable, intent(out) :: err
        integer :: k
        do k = n + 2, size(values)
            if (values(k) /= INT_UNSET) then
                call make_error(err, ERR_INPUT, where//key//'('//int_text(k)//') = '// &
                    int_text(values(k))//': given, but '//key//'('//int_text(n + 1)// &
                    ') is not (lists have no gaps)')
                return
            end if
        end do
    end subroutine check_no_int_gap

    !> The cartesian product: cases in product order, each read and checked.
    subroutine expand(sweep, dims, atol_per_rtol, err)
        type(sweep_t), intent(inout) :: sweep
        type(dimension_t), intent(in) :: dims(:)
        real(wp), intent(in) :: atol_per_rtol
        type(error_t), allocatable, intent(out) :: err
        integer :: sizes(size(dims)), digit(size(dims)), n_cases, c, i, n_vary, v, g
        type(text_t), allocatable :: own(:)
        type(text_t), allocatable :: group_keys(:)
        character(len=:), allocatable :: label, key
        real(wp) :: rtol

        do i = 1, size(dims)
            sizes(i) = max(1, size(dims(i)%values))
        end do
        n_cases = product(sizes)
        n_vary = size(sweep%vary_keys)
        allocate (sweep%cases(n_cases))
        allocate (group_keys(0))
        digit = 1
        do c = 1, n_cases
            if (allocated(own)) deallocate (own)
            allocate (own(0))
            associate (cs => sweep%cases(c))
                cs%id = c
                allocate (cs%vary_values(n_vary))
                v = 0
                key = ''
                do i = 1, size(dims)
                    if (dims(i)%key(1:min(4, len(dims(i)%key))) == 'vary') then
                        v = v + 1
                        cs%vary_values(v)%s = dims(i)%values(digit(i))%s
                    end if
                    if (len(dims(i)%target) == 0) cycle
                    call append(own, dims(i)%target//'='//dims(i)%values(digit(i))%s)
                end do
                cs%file = sweep%output_dir//'/'//case_name(c, n_cases)
                cs%overrides = own
                label = join(own)
                if (len(label) == 0) label = '(the base scene)'
                call read_scene(sweep%base, case_overrides(sweep, own, cs%file), cs%scene, err)
                if (allocated(err)) then
                    err%message = sweep%path//': &sweep: case '//int_text(c)//' ('//label// &
                        '): '//without_set(err%message)
                    return
                end if
                if (.not. ieee_is_nan(atol_per_rtol)) then
                    rtol = cs%scene%solver%rtol
                    call append(cs%overrides, 'solver.atol='//real_text(atol_per_rtol*rtol, compact=.true.))
                    call read_scene(sweep%base, case_overrides(sweep, cs%overrides, cs%file), &
                        cs%scene, err)
                    if (allocated(err)) then
                        err%message = sweep%path//': &sweep: case '//int_text(c)//' ('// &
                            label//'): '//without_set(err%message)
                        return
                    end if
                end if
                ! reference group: same model, elements and vary values
                key = trim(cs%scene%model%kind)//'|'//int_text(cs%scene%model%elements)
                do i = 1, n_vary
                    key = key//'|'//cs%vary_values(i)%s
                end do
                g = 0
                do i = 1, size(group_keys)
                    if (group_keys(i)%s == key) g = i
                end do
                if (g == 0) then
                    call append(group_keys, key)
                    g = size(group_keys)
                end if
                cs%group = g
            end associate
            ! next digit, the last dimension fastest
            do i = size(dims), 1, -1
                digit(i) = digit(i) + 1
                if (digit(i) <= sizes(i)) exit
                digit(i) = 1
            end do
        end do
        sweep%n_groups = size(group_keys)
    end subroutine expand

    !> The overrides of a case for read_scene: set, the case's own, its output file.
    function case_overrides(sweep, own, file) result(arr)
        type(sweep_t), intent(in) :: sweep
        type(text_t), intent(in) :: own(:)
        character(len=*), intent(in) :: file
        character(len=:), allocatable :: arr(:)
        type(text_t), allocatable :: all(:)
        all = sweep%set
        call extend(all, own)
        call append(all, 'output.file='//file)
        call append(all, 'output.progress=.false.')
        arr = override_array(all)
    end function case_overrides

    subroutine new_dimension(d, key, target)
        type(dimension_t), intent(out) :: d
        character(len=*), intent(in) :: key, target
        d%key = key
        d%target = target
        allocate (d%values(0))
    end subroutine new_dimension

    !> Append one string to a list (grown by one).
    subroutine append(list, value)
        type(text_t), allocatable, intent(inout) :: list(:)
        character(len=*), intent(in) :: value
        type(text_t), allocatable :: grown(:)
        integer :: k, n
        if (.not. allocated(list)) allocate (list(0))
        n = size(list)
        allocate (grown(n + 1))
        do k = 1, n
            call move_alloc(list(k)%s, grown(k)%s)
        end do
        grown(n + 1)%s = value
        call move_alloc(grown, list)
    end subroutine append

    !> Append all strings of `more` to a list.
    subroutine extend(list, more)
        type(text_t), allocatable, intent(inout) :: list(:)
        type(text_t), intent(in) :: more(:)
        integer :: k
        do k = 1, size(more)
            call append(list, more(k)%s)
        end do
    end subroutine extend

    !> A scene error without its leading '--set group.key=value: ' (the sweep names the
    !! value itself).
    function without_set(message) result(text)
        character(len=*), intent(in) :: message
        character(len=:), allocatable :: text
        integer :: colon
        text = message
        if (len(message) < 6) return
        if (message(1:6) /= '--set ') return
        colon = index(message, ': ')
        if (colon > 0) text = message(colon + 2:)
    end function without_set

    !> Overrides as a character array for read_scene.
    function override_array(list) result(arr)
        type(text_t), intent(in) :: list(:)
        character(len=:), allocatable :: arr(:)
        integer :: k, width
        width = 1
        do k = 1, size(list)
            width = max(width, len(list(k)%s))
        end do
        allocate (character(len=width) :: arr(size(list)))
        do k = 1, size(list)
            arr(k) = list(k)%s
        end do
    end function override_array

    function join(list) result(text)
        type(text_t), intent(in) :: list(:)
        character(len=:), allocatable :: text
        integer :: k
        text = ''
        do k = 1, size(list)
            if (k > 1) text = text//' '
            text = text//list(k)%s
        end do
    end function join

    ! ------------------------------------------------------------------------------------
    ! Text helpers
    ! ------------------------------------------------------------------------------------



end module ropedyn_sweep
