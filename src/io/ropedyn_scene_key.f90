!> One key of a scene file (an entry of the table in `ropedyn_scene_keys`): what it is, the
!! rule its value obeys, and a pointer to the component of the scene that holds the value.
!! The operations every key shares: reading values into the component (`assign`), the
!! per-key check (`check`), the value as text for messages (`value_text`), the echo line
!! (`echo`) and the line of the listing `ropedyn keys` (`listing`).
module ropedyn_scene_key
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite, ieee_is_nan
    use ropedyn_kinds, only: wp
    use ropedyn_text, only: int_text, real_text, pair_text, logical_text, quoted, lower
    use ropedyn_namelist_file, only: nml_value_t, value_real, value_int, value_logical, &
        V_STRING
    implicit none
    private
    public :: scene_key_t
    public :: T_REAL, T_INT, T_LOGICAL, T_NAME, T_PATH, T_PAIR, T_LIST
    public :: R_NONE, R_FINITE, R_POSITIVE, R_NONNEGATIVE, R_UNIT, R_AT_LEAST, R_NAMES

    !> Types: a real, an integer, a logical, a name from a list, a file name, two reals
    !! (x, y), a list of up to N_ATTACH reals.
    integer, parameter :: T_REAL = 1, T_INT = 2, T_LOGICAL = 3, T_NAME = 4, T_PATH = 5, &
        T_PAIR = 6, T_LIST = 7
    !> Rules: none here (checked with other keys), finite, > 0, >= 0, in (0, 1), an integer
    !! >= lowest, a name from `allowed`. Every real rule includes finiteness.
    integer, parameter :: R_NONE = 0, R_FINITE = 1, R_POSITIVE = 2, R_NONNEGATIVE = 3, &
        R_UNIT = 4, R_AT_LEAST = 5, R_NAMES = 6

    !> The types' names in the listing, and what a value of each must be.
    character(len=*), parameter :: TYPE_NAMES(7) = [character(len=8) :: 'real', 'integer', &
        'logical', 'string', 'string', 'real, ', 'real, ']
    character(len=*), parameter :: EXPECTED_TEXT(7) = [character(len=32) :: 'a real number', &
        'an integer', '.true. or .false.', 'a quoted string', 'a quoted string', &
        'two real numbers (x, y)', '']

    type :: scene_key_t
        integer :: group = 0
        character(len=:), allocatable :: name        !< lower case
        integer :: type = 0                          !< T_*
        integer :: rule = R_NONE                     !< R_*
        integer :: lowest = 0                        !< R_AT_LEAST
        !> R_NAMES: the allowed names 'a, b, c'; otherwise the rule for the listing
        character(len=:), allocatable :: allowed
        character(len=:), allocatable :: unit
        character(len=:), allocatable :: doc         !< one line: what the key means
        !> a real or pair whose NaN value means "not set": the comment of the echo (a
        !! real not set is resolved or left out); a logical with this text is tri-state
        !! (not given is a third value); each is listed as 'not set'
        character(len=:), allocatable :: unset
        logical :: given = .false.                   !< set by the file or a --set
        character(len=:), allocatable :: origin      !< the file or the --set argument
        real(wp), pointer :: r => null()             !< T_REAL
        real(wp), pointer :: v(:) => null()          !< T_PAIR, T_LIST
        real(wp), pointer :: used(:) => null()       !< T_LIST: entry k used if used(k) given
        integer, pointer :: i => null()              !< T_INT
        logical, pointer :: l => null()              !< T_LOGICAL
        character(len=:), pointer :: s => null()     !< T_NAME, T_PATH
    contains
        procedure :: assign => key_assign
        procedure :: expected => key_expected
        procedure :: check => key_check
        procedure :: value_text => key_value_text
        procedure :: echo => key_echo
        procedure :: listing => key_listing
    end type scene_key_t

contains

    !> Store `values` (given with `index`, 0 for none) in the key's component; `reason` is
    !! '' or what was expected.
    subroutine key_assign(self, values, index, reason)
        class(scene_key_t), intent(inout) :: self
        type(nml_value_t), intent(in) :: values(:)
        integer, intent(in) :: index
        character(len=:), allocatable, intent(out) :: reason
        real(wp) :: x(size(values))
        integer :: k, first, n
        logical :: ok
        reason = self%expected(index, values)
        ok = .false.
        select case (self%type)
        case (T_REAL)
            if (size(values) == 1 .and. index == 0) call value_real(values(1), self%r, ok)
        case (T_INT)
            if (size(values) == 1 .and. index == 0) call value_int(values(1), n, ok)
            if (ok) self%i = n
            if (.not. ok .and. size(values) == 1 .and. index == 0) then
                if (verify(values(1)%text, '+-0123456789') == 0) reason = reason// &
                    ' (at most '//int_text(huge(n))//' in size)'
            end if
        case (T_LOGICAL)
            if (size(values) == 1 .and. index == 0) call value_logical(values(1), self%l, ok)
        case (T_NAME, T_PATH)
            if (size(values) == 1 .and. index == 0) ok = values(1)%kind == V_STRING
            if (ok .and. len(values(1)%text) > len(self%s)) then
                reason = 'too long (at most '//int_text(len(self%s))//' characters)'
                return
            end if
            if (ok) self%s = values(1)%text
        case (T_PAIR, T_LIST)
            first = max(index, 1)
            ok = first + size(values) - 1 <= size(self%v)
            ! a pair without an index takes both components (one alone: key(1) = x)
            if (self%type == T_PAIR .and. index == 0) ok = size(values) == size(self%v)
            if (.not. ok .and. self%type == T_PAIR .and. index == 0 .and. size(values) == 1) &
                reason = reason//' (or one component: '//self%name//'(1) = x or '// &
                self%name//'(2) = y)'
            do k = 1, size(values)
                if (ok) call value_real(values(k), x(k), ok)
            end do
            if (ok) self%v(first:first + size(values) - 1) = x
        end select
        if (ok) then
            reason = ''
            self%given = .true.
        end if
    end subroutine key_assign

    !> What a key expects, as the reason of a value that cannot be read.
    function key_expected(key, index, values) result(text)
        class(scene_key_t), intent(in) :: key
        integer, intent(in) :: index
        type(nml_value_t), intent(in) :: values(:)
        character(len=:), allocatable :: text
        text = 'expected '//trim(EXPECTED_TEXT(key%type))
        if (key%type == T_LIST) text = 'expected up to '//int_text(size(key%v))//' real numbers'
        if (key%type == T_PAIR .or. key%type == T_LIST) then
            if (index > 0) text = 'expected a real number at an index 1'// &
                merge(' or ', ' .. ', key%type == T_PAIR)//int_text(size(key%v))
        else if (index > 0) then
            text = text//' ('//key%name//' takes no index)'
        else if (size(values) > 1) then
            text = text//' (one value, not '//int_text(size(values))// &
                '; a repeat count r*x gives r values)'
        end if
        if ((key%type == T_NAME .or. key%type == T_PATH) .and. size(values) == 1) then
            if (values(1)%kind /= V_STRING) text = text//' ('//key%name//' = '// &
                quoted(values(1)%text)//')'
        end if
    end function key_expected

    !> The key's own rule: '' if the value obeys it, else the reason. A name is stored in
    !! lower case.
    function key_check(self) result(reason)
        class(scene_key_t), intent(inout) :: self
        character(len=:), allocatable :: reason, v
        reason = ''
        ! a real not set (NaN, not given): its rule applies once it is given
        if (self%type == T_REAL .and. len(self%unset) > 0 .and. .not. self%given) then
            if (ieee_is_nan(self%r)) return
        end if
        select case (self%rule)
        case (R_FINITE)
            if (.not. all(ieee_is_finite(reals(self)))) reason = 'must be finite'
        case (R_POSITIVE, R_NONNEGATIVE, R_UNIT)
            associate (x => self%r)
                if (.not. ieee_is_finite(x)) then
                    reason = 'must be finite'
                else if (self%rule == R_NONNEGATIVE .and. x < 0.0_wp) then
                    reason = 'must be >= 0'
                else if (self%rule /= R_NONNEGATIVE .and. .not. x > 0.0_wp) then
                    reason = 'must be > 0'
                else if (self%rule == R_UNIT .and. .not. x < 1.0_wp) then
                    reason = 'must be < 1'
                end if
            end associate
        case (R_AT_LEAST)
            if (self%i < self%lowest) reason = 'must be >= '//int_text(self%lowest)
        case (R_NAMES)
            v = lower(trim(adjustl(self%s)))
            if (index(', '//self%allowed//',', ' '//v//',') > 0 .and. len(v) > 0 .and. &
                verify(v, 'abcdefghijklmnopqrstuvwxyz0123456789_') == 0) then
                self%s = v
            else
                reason = 'unknown (allowed: '//self%allowed//')'
            end if
        end select
    end function key_check

    !> The real values of a real, pair or list key.
    function reals(key) result(x)
        type(scene_key_t), intent(in) :: key
        real(wp), allocatable :: x(:)
        if (associated(key%r)) then
            x = [key%r]
        else
            x = key%v
        end if
    end function reals

    !> The value for a message: 1.0, "name", x, y; a list in full.
    function key_value_text(self) result(text)
        class(scene_key_t), intent(in) :: self
        character(len=:), allocatable :: text
        integer :: k
        select case (self%type)
        case (T_REAL)
            text = real_text(self%r)
        case (T_INT)
            text = int_text(self%i)
        case (T_LOGICAL)
            text = logical_text(self%l)
        case (T_NAME, T_PATH)
            text = '"'//trim(self%s)//'"'
        case default
            text = real_text(self%v(1))
            do k = 2, size(self%v)
                text = text//', '//real_text(self%v(k))
            end do
        end select
    end function key_value_text

    !> The key's line of the scene echo (with its new line), re-readable by the scene
    !! reader; '' for a list none of whose entries is used.
    function key_echo(self) result(text)
        class(scene_key_t), intent(in) :: self
        character(len=:), allocatable :: text
        character(len=*), parameter :: I4 = '    '
        integer :: k, last
        select case (self%type)
        case (T_NAME, T_PATH)
            text = I4//self%name//' = '//quoted(trim(self%s))
        case (T_REAL)
            text = I4//self%name//' = '//self%value_text()
            if (len(self%unset) > 0 .and. ieee_is_nan(self%r)) text = I4//'! '//self%name// &
                ' = ('//self%unset//')'
        case (T_PAIR)
            text = I4//self%name//' = '//pair_text(self%v)
            if (len(self%unset) > 0 .and. any(ieee_is_nan(self%v))) text = text//'  ! '// &
                self%unset
        case (T_LIST)
            last = 0
            do k = 1, size(self%used)
                if (.not. ieee_is_nan(self%used(k))) last = k
            end do
            text = ''
            if (last == 0) return
            text = I4//self%name//' = '//real_text(self%v(1))
            do k = 2, last
                text = text//', '//real_text(self%v(k))
            end do
        case default
            text = I4//self%name//' = '//self%value_text()
        end select
        text = text//new_line('a')
    end function key_echo

    !> The default of a key left out that has no value then: its `unset` text ('not set:
    !! what stands for it'), or 'not set'.
    function unset_text(self) result(text)
        class(scene_key_t), intent(in) :: self
        character(len=:), allocatable :: text
        text = 'not set'
        if (allocated(self%unset)) then
            if (len(self%unset) > 0) text = self%unset
        end if
    end function unset_text

    !> The key's line of `ropedyn keys`: group, key, type, unit, default (the current value:
    !! call it on a default scene), allowed values and meaning, separated by tabs.
    function key_listing(self, group) result(text)
        class(scene_key_t), intent(in) :: self
        character(len=*), intent(in) :: group
        character(len=:), allocatable :: text, type, default, allowed
        character(len=*), parameter :: TAB = achar(9)
        type = trim(TYPE_NAMES(self%type))
        if (self%type == T_PAIR .or. self%type == T_LIST) type = type//' '// &
            int_text(size(self%v))
        select case (self%type)
        case (T_NAME, T_PATH)
            default = quoted(trim(self%s))
        case (T_LIST)
            default = real_text(self%v(1))
        case default
            default = self%value_text()
        end select
        ! not set: what stands for the value then, when the table says it
        if (self%type == T_PAIR .or. self%type == T_LIST) then
            if (any(ieee_is_nan(self%v))) default = unset_text(self)
        end if
        if (self%type == T_REAL .and. len(self%unset) > 0) then
            if (ieee_is_nan(self%r)) default = unset_text(self)
        end if
        ! a logical with an `unset` text is tri-state: its default is "not given"
        if (self%type == T_LOGICAL .and. len(self%unset) > 0) default = unset_text(self)
        select case (self%rule)
        case (R_FINITE)
            allowed = 'finite'
        case (R_POSITIVE)
            allowed = '> 0'
        case (R_NONNEGATIVE)
            allowed = '>= 0'
        case (R_UNIT)
            allowed = '0 < x < 1'
        case (R_AT_LEAST)
            allowed = '>= '//int_text(self%lowest)
        case default
            allowed = self%allowed
        end select
        if (self%type == T_LOGICAL) allowed = '.true., .false.'
        if (self%type == T_PATH) allowed = 'at most '//int_text(len(self%s))//' characters'
        text = group//TAB//self%name//TAB//type//TAB//self%unit//TAB//default//TAB// &
            allowed//TAB//self%doc
    end function key_listing
end module ropedyn_scene_key
