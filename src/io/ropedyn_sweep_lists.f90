!> The lists of a sweep file as dimensions of the product of cases, every value checked
!! before anything runs: on its own by the scene's key table (`check_override_value`),
!! against the other values of its list (no value twice), and with the base scene and the
!! common overrides (`read_scene`). Also the `set` and `vary` entries and the number of
!! cases (docs/reference/sweep-file.md).
module ropedyn_sweep_lists
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t, make_error, ERR_INPUT
    use ropedyn_text, only: int_text, real_text, lower, text_t, append_text, text_array, clip
    use ropedyn_scene, only: scene_t, read_scene, check_override_value, override_value_text
    implicit none
    private
    public :: dimension_t, build_dimensions, without_set
    public :: MAX_LIST, MAX_VARY, MAX_CASES

    integer, parameter :: MAX_LIST = 64     !< most values of one list key
    integer, parameter :: MAX_VARY = 8      !< most `vary` entries
    integer, parameter :: MAX_CASES = 100000   !< most cases of one sweep

    !> One dimension of the product: the sweep key, the scene key it sets, its values.
    type :: dimension_t
        character(len=:), allocatable :: key     !< sweep key, for messages
        character(len=:), allocatable :: target  !< group.key it sets ('' if not given)
        type(text_t), allocatable :: values(:)   !< values as override text
    end type dimension_t

contains

    !> The dimensions in product order: models, elements, vary(1), ..., methods,
    !! max_orders, rtols (`lists` holds the five lists, each with its key and target).
    !! The base scene with the common overrides, and with each value, may fail where the
    !! cases do not (a harmonic top_motion in `set`, its frequencies in `vary`): the first
    !! such error is `tentative`, with its scene message `tentative_reason`, and stands only
    !! when a case fails for that reason (`ropedyn_sweep`'s expand).
    subroutine build_dimensions(where, base, set_in, vary_in, lists, atol_given, set, &
            vary_keys, dims, tentative, tentative_reason, err)
        character(len=*), intent(in) :: where, base
        type(text_t), intent(in) :: set_in(:), vary_in(:)
        type(dimension_t), intent(in) :: lists(5)
        logical, intent(in) :: atol_given
        type(text_t), allocatable, intent(out) :: set(:), vary_keys(:)
        type(dimension_t), allocatable, intent(out) :: dims(:)
        type(error_t), allocatable, intent(out) :: tentative
        character(len=:), allocatable, intent(out) :: tentative_reason
        type(error_t), allocatable, intent(out) :: err
        type(text_t), allocatable :: targets(:)
        real(wp) :: cases
        integer :: k, i

        ! the common overrides
        allocate (set(0), targets(0))
        do k = 1, size(set_in)
            call check_entry('set('//int_text(k)//')', set_in(k)%s, lists, atol_given, &
                targets, err)
            if (allocated(err)) then
                err%message = where//err%message
                return
            end if
            call append_text(set, set_in(k)%s)
        end do
        call check_scene_with(where//'set: the common overrides: ', base, set, '', .true., &
            tentative, tentative_reason)

        ! the dimensions and each value on its own
        allocate (dims(5 + size(vary_in)), vary_keys(size(vary_in)))
        dims(1:2) = lists(1:2)
        dims(3 + size(vary_in):) = lists(3:5)
        do i = 1, size(vary_in)
            call vary_dimension(i, vary_in(i)%s, lists, atol_given, targets, dims(2 + i), &
                err)
            if (allocated(err)) then
                err%message = where//err%message
                return
            end if
            vary_keys(i)%s = dims(2 + i)%target
        end do
        cases = 1.0_wp
        do i = 1, size(dims)
            if (size(dims(i)%values) == 0) dims(i)%target = ''
            if (dims(i)%key(1:min(4, len(dims(i)%key))) /= 'vary') then
                call check_list(where, dims(i), err)
                if (allocated(err)) return
            end if
            cases = cases*max(1, size(dims(i)%values))
        end do
        if (cases > MAX_CASES) then
            call make_error(err, ERR_INPUT, where//'the lists make '// &
                real_text(cases)//' cases, more than the limit '//int_text(MAX_CASES)// &
                ' (docs/reference/sweep-file.md)')
            return
        end if

        ! every value with the base scene and the common overrides (max_orders are checked
        ! with their methods, in the cases: the order range is per method), until the
        ! first tentative error
        do i = 1, size(dims)
            if (len(dims(i)%target) == 0 .or. dims(i)%key == 'max_orders') cycle
            do k = 1, size(dims(i)%values)
                if (allocated(tentative)) return
                call check_scene_with(where//label(dims(i), k, vary_in)//': ', base, set, &
                    dims(i)%target//'='//dims(i)%values(k)%s, .false., tentative, &
                    tentative_reason)
            end do
        end do
    end subroutine build_dimensions

    !> 'elements(2) = "5"' or 'vary(1) = "rope.length = 1; 2", value 2' for messages.
    function label(d, k, vary_in) result(text)
        type(dimension_t), intent(in) :: d
        integer, intent(in) :: k
        type(text_t), intent(in) :: vary_in(:)
        character(len=:), allocatable :: text
        integer :: i
        if (d%key(1:min(4, len(d%key))) == 'vary') then
            read (d%key(6:len(d%key) - 1), *) i
            text = d%key//' = "'//clip(trim(adjustl(vary_in(i)%s)))//'", value '//int_text(k)
        else
            text = d%key//'('//int_text(k)//') = "'//clip(d%values(k)%s)//'"'
        end if
    end function label

    !> The values of a typed list on their own (the scene key's rule) and without repeats.
    subroutine check_list(where, d, err)
        character(len=*), intent(in) :: where
        type(dimension_t), intent(in) :: d
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: reason, shown
        integer :: k, j
        do k = 1, size(d%values)
            shown = clip(d%values(k)%s)
            if (d%key == 'models' .or. d%key == 'methods') shown = '"'//shown//'"'
            reason = check_override_value(d%target//'='//d%values(k)%s)
            if (len(reason) == 0) then
                do j = 1, k - 1
                    if (lower(d%values(j)%s) == lower(d%values(k)%s)) reason = 'given twice (' &
                        //d%key//'('//int_text(j)//') = '//d%values(j)%s//'): a case would ' &
                        //'run twice'
                end do
            end if
            if (len(reason) > 0) then
                call make_error(err, ERR_INPUT, where//d%key//'('//int_text(k)//') = '// &
                    shown//': '//without_set(reason))
                return
            end if
        end do
    end subroutine check_list

    !> A `vary` entry 'group.key = value1; value2; ...' as a dimension.
    subroutine vary_dimension(i, text, lists, atol_given, targets, d, err)
        integer, intent(in) :: i
        character(len=*), intent(in) :: text
        type(dimension_t), intent(in) :: lists(5)
        logical, intent(in) :: atol_given
        type(text_t), allocatable, intent(inout) :: targets(:)
        type(dimension_t), intent(out) :: d
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: entry, values, value, key, shown, same, shown_as
        type(text_t), allocatable :: read_as(:)   !< each value as its key reads it
        integer :: eq, k, j
        entry = trim(adjustl(text))
        shown = clip(entry)
        key = 'vary('//int_text(i)//')'
        d%key = key
        allocate (d%values(0), read_as(0))
        eq = index(entry, '=')
        if (eq <= 1) then
            call make_error(err, ERR_INPUT, key//' = "'//shown//'": expected "group.key = ' &
                //'value1; value2; ..."')
            return
        end if
        d%target = lower(trim(entry(:eq - 1)))
        call check_entry(key, entry, lists, atol_given, targets, err)
        if (allocated(err)) return
        values = entry(eq + 1:)
        do
            k = index(values, ';')
            if (k == 0) k = len(values) + 1
            value = trim(adjustl(values(:k - 1)))
            if (len(value) == 0) then
                call make_error(err, ERR_INPUT, key//' = "'//shown//'": empty value (values ' &
                    //'are separated by ";")')
                return
            end if
            ! the same value however written (1 and 1.0, 'CVODE' and 'cvode')
            same = lower(override_value_text(d%target//'='//value))
            do j = 1, size(d%values)
                if (read_as(j)%s /= same) cycle
                shown_as = ''
                if (d%values(j)%s /= value) shown_as = ' (as "'//d%values(j)%s//'")'
                call make_error(err, ERR_INPUT, key//' = "'//shown//'": value "'//value// &
                    '" given twice'//shown_as//': a case would run twice')
                return
            end do
            call append_text(d%values, value)
            call append_text(read_as, same)
            if (k > len(values)) exit
            values = values(k + 1:)
        end do
    end subroutine vary_dimension

    !> A `set` or `vary` entry must be group.key=..., set a key no list sets and no other
    !! entry sets, and not the output of a case. `targets` collects the keys set so far.
    subroutine check_entry(key, entry, lists, atol_given, targets, err)
        character(len=*), intent(in) :: key, entry
        type(dimension_t), intent(in) :: lists(5)
        logical, intent(in) :: atol_given
        type(text_t), allocatable, intent(inout) :: targets(:)
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: target, list, shown
        integer :: eq, k
        shown = clip(entry)
        eq = index(entry, '=')
        if (eq == 0) then
            call make_error(err, ERR_INPUT, key//' = "'//shown//'": expected group.key=value')
            return
        end if
        target = lower(trim(adjustl(entry(:eq - 1))))
        list = ''
        do k = 1, size(lists)
            if (lists(k)%target == target .and. size(lists(k)%values) > 0) list = lists(k)%key
        end do
        if (target == 'solver.atol' .and. atol_given) list = 'atol_per_rtol'
        if (target == 'output.file' .or. target == 'output.progress') then
            call make_error(err, ERR_INPUT, key//' = "'//shown//'": '//target// &
                ' is set by the sweep for every case (use output_dir)')
        else if (len(list) > 0) then
            call make_error(err, ERR_INPUT, key//' = "'//shown//'": '//target// &
                ' is already set by '//list)
        else if (any([(targets(k)%s == target, k = 1, size(targets))])) then
            call make_error(err, ERR_INPUT, key//' = "'//shown//'": '//target// &
                ' is already set by another set or vary entry')
        else
            call append_text(targets, target)
        end if
    end subroutine check_entry

    !> Read the base scene with the common overrides and `extra` (if not ''); an error starts
    !! with `where`, then the scene's message (without its '--set ...: ' unless `keep_set`);
    !! `reason` is the scene's message without its '--set ...: '.
    subroutine check_scene_with(where, base, set, extra, keep_set, err, reason)
        character(len=*), intent(in) :: where, base, extra
        type(text_t), intent(in) :: set(:)
        logical, intent(in) :: keep_set
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable, intent(out) :: reason
        type(scene_t) :: scene
        type(text_t), allocatable :: all(:)
        all = set
        if (len(extra) > 0) call append_text(all, extra)
        call read_scene(base, text_array(all), scene, err)
        if (.not. allocated(err)) return
        reason = without_set(err%message)
        if (keep_set) then
            err%message = where//err%message
        else
            err%message = where//without_set(err%message)
        end if
    end subroutine check_scene_with

    !> A scene error without its leading '--set group.key=value: ' (the sweep names the
    !! value itself).
    pure function without_set(message) result(text)
        character(len=*), intent(in) :: message
        character(len=:), allocatable :: text
        integer :: colon
        text = message
        if (len(message) < 6) return
        if (message(1:6) /= '--set ') return
        colon = index(message, ': ')
        if (colon > 0) text = message(colon + 2:)
    end function without_set

end module ropedyn_sweep_lists
