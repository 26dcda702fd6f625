!> Values of namelist-syntax text: the value tokens of an assignment (with repeat counts
!! `r*value`) and their conversion to reals, integers and logicals, for
!! `ropedyn_namelist_file` and its callers (which know the type of each key).
module ropedyn_namelist_values
    use ropedyn_kinds, only: wp, i8
    use ropedyn_text, only: int_text, lower, text_t
    use ropedyn_namelist_lexer, only: token_t, lex_lines, TK_WORD, TK_STRING, TK_EQ, &
        TK_COMMA, TK_BAD_CHAR, TK_BAD_QUOTE
    implicit none
    private
    public :: nml_value_t, value_token, parse_values, value_real, value_int, value_logical
    public :: V_WORD, V_STRING, MAX_VALUES

    integer, parameter :: V_WORD = 1      !< a number, logical or other unquoted word
    integer, parameter :: V_STRING = 2    !< a quoted string (quotes removed)
    integer, parameter :: MAX_VALUES = 1024         !< most values of one key (after r*)

    !> One value as written: a word, or a string without its quotes.
    type :: nml_value_t
        integer :: kind = V_WORD
        character(len=:), allocatable :: text
    end type nml_value_t

contains

    !> Append the value of token j (and j + 1 for `r*'string'`) to `values`; `used` is the
    !! number of tokens taken; `reason` is '' or why the value cannot be taken.
    subroutine value_token(tk, j, values, used, reason)
        type(token_t), intent(in) :: tk(:)
        integer, intent(in) :: j
        type(nml_value_t), allocatable, intent(inout) :: values(:)
        integer, intent(out) :: used
        character(len=:), allocatable, intent(out) :: reason
        type(nml_value_t) :: v
        integer :: star, ios, r
        reason = ''
        used = 1
        v%kind = merge(V_STRING, V_WORD, tk(j)%kind == TK_STRING)
        v%text = tk(j)%text
        r = 1
        star = index(tk(j)%text, '*')
        if (tk(j)%kind == TK_WORD .and. star > 1) then
            ios = 1
            if (verify(tk(j)%text(:star - 1), '0123456789') == 0 .and. star <= 8) &
                read (tk(j)%text(:star - 1), *, iostat=ios) r
            if (ios /= 0 .or. r < 1) then
                reason = 'bad repeat count "'//tk(j)%text(:star - 1)//'*"'
                return
            end if
            v%text = tk(j)%text(star + 1:)
            if (len(v%text) == 0) then
                used = 2
                if (j + 1 <= size(tk)) then
                    if (tk(j + 1)%kind == TK_STRING .and. tk(j + 1)%line == tk(j)%line &
                        .and. tk(j + 1)%first == tk(j)%last + 1) then
                        v%kind = V_STRING
                        v%text = tk(j + 1)%text
                    end if
                end if
                if (v%kind /= V_STRING) then
                    used = 1
                    reason = 'null value "'//tk(j)%text//'" (give a value after the *)'
                    return
                end if
            end if
        end if
        if (size(values) + r > MAX_VALUES) then
            reason = 'more than '//int_text(MAX_VALUES)//' values'
            return
        end if
        block
            type(nml_value_t), allocatable :: grown(:)
            integer :: n, k
            n = size(values)
            allocate (grown(n + r))
            grown(:n) = values
            do k = n + 1, n + r
                grown(k) = v
            end do
            call move_alloc(grown, values)
        end block
    end subroutine value_token

    !> The values of one `--set` argument (`text` after the '='); `reason` is '' or why they
    !! cannot be read. Strings must be quoted here (the caller quotes a bare string).
    subroutine parse_values(text, values, reason)
        character(len=*), intent(in) :: text
        type(nml_value_t), allocatable, intent(out) :: values(:)
        character(len=:), allocatable, intent(out) :: reason
        type(token_t), allocatable :: tk(:)
        type(text_t) :: one(1)
        integer :: j, used, last
        one(1)%s = text
        call lex_lines(one, tk)
        allocate (values(0))
        reason = ''
        last = TK_EQ
        j = 1
        do while (j <= size(tk))
            select case (tk(j)%kind)
            case (TK_WORD, TK_STRING)
                call value_token(tk, j, values, used, reason)
                if (len(reason) > 0) return
                j = j + used
                last = TK_WORD
            case (TK_COMMA)
                if (last /= TK_WORD) then
                    reason = 'null value (two commas, or a comma first)'
                    return
                end if
                last = TK_COMMA
                j = j + 1
            case (TK_BAD_CHAR, TK_BAD_QUOTE)
                reason = tk(j)%text
                return
            case default
                reason = 'unexpected "'//tk(j)%text//'"'
                return
            end select
        end do
        if (size(values) == 0) reason = 'no value'
    end subroutine parse_values

    !> A real number: Fortran's forms (1, 1.5, .5, 1e-3, 2.5d0, +Inf, -Infinity, NaN).
    subroutine value_real(v, x, ok)
        type(nml_value_t), intent(in) :: v
        real(wp), intent(out) :: x
        logical, intent(out) :: ok
        character(len=:), allocatable :: s, mant
        integer :: e, ios
        x = 0.0_wp
        ok = .false.
        if (v%kind /= V_WORD .or. len(v%text) == 0 .or. len(v%text) > 64) return
        s = lower(v%text)
        if (s(1:1) == '+' .or. s(1:1) == '-') s = s(2:)
        if (s == 'inf' .or. s == 'infinity' .or. s == 'nan') then
            ok = .true.
        else
            e = scan(s, 'ed')
            mant = s
            if (e > 0) then
                mant = s(:e - 1)
                ok = is_signed_digits(s(e + 1:))
            else
                ok = .true.
            end if
            ok = ok .and. len(mant) > 0 .and. verify(mant, '0123456789.') == 0 .and. &
                count([(mant(e:e) == '.', e = 1, len(mant))]) <= 1 .and. mant /= '.'
        end if
        if (.not. ok) return
        read (v%text, *, iostat=ios) x
        ok = ios == 0
    end subroutine value_real

    !> A whole number within the default integer range.
    subroutine value_int(v, n, ok)
        type(nml_value_t), intent(in) :: v
        integer, intent(out) :: n
        logical, intent(out) :: ok
        integer(i8) :: big
        integer :: ios
        n = 0
        ok = v%kind == V_WORD .and. is_signed_digits(v%text) .and. len(v%text) <= 12
        if (.not. ok) return
        read (v%text, *, iostat=ios) big
        ok = ios == 0 .and. abs(big) <= huge(n)
        if (ok) n = int(big)
    end subroutine value_int

    !> A logical: .true. .false. T F .t. .f. (any letter case).
    subroutine value_logical(v, b, ok)
        type(nml_value_t), intent(in) :: v
        logical, intent(out) :: b
        logical, intent(out) :: ok
        character(len=:), allocatable :: s
        b = .false.
        ok = .false.
        if (v%kind /= V_WORD) return
        s = lower(v%text)
        ok = .true.
        select case (s)
        case ('.true.', 't', '.t.')
            b = .true.
        case ('.false.', 'f', '.f.')
            b = .false.
        case default
            ok = .false.
        end select
    end subroutine value_logical

    pure logical function is_signed_digits(s) result(ok)
        character(len=*), intent(in) :: s
        integer :: start
        start = 1
        if (len(s) > 0) then
            if (s(1:1) == '+' .or. s(1:1) == '-') start = 2
        end if
        ok = len(s) >= start .and. verify(s(start:), '0123456789') == 0
    end function is_signed_digits
end module ropedyn_namelist_values
