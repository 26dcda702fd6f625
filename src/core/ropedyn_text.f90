!> Text of numbers, logicals and names for messages, echoes and file names: the one place
!! every layer takes them from.
module ropedyn_text
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite, ieee_is_nan
    use ropedyn_kinds, only: wp, i8
    implicit none
    private
    public :: int_text, real_text, fixed_text, pair_text, logical_text, quoted, enclosed
    public :: significant_text, decimal_product, column_text
    public :: lower, line_quote, replaced, stripped, es_text
    public :: text_t, append_text, text_array, printable, clip, name_hint, edit_distance

    !> A string of any length, for lists of strings of different lengths.
    type :: text_t
        character(len=:), allocatable :: s
    end type text_t

    !> Decimal text of an integer (default or 64-bit kind).
    interface int_text
        module procedure int_text_default, int_text_i8
    end interface int_text

contains

    pure function int_text_default(n) result(s)
        integer, intent(in) :: n
        character(len=:), allocatable :: s
        character(len=12) :: buf
        write (buf, '(i0)') n
        s = trim(buf)
    end function int_text_default

    pure function int_text_i8(n) result(s)
        integer(i8), intent(in) :: n
        character(len=:), allocatable :: s
        character(len=24) :: buf
        write (buf, '(i0)') n
        s = trim(buf)
    end function int_text_i8

    !> Shortest decimal text that reads back to x exactly: '1.0', '0.005', '3.5e7', 'NaN',
    !! '+Infinity'. Plain decimals for exponents -4 .. 6, else 'd.ddde<exp>'. With
    !! `compact`, plain decimals only for exponents -3 .. 5 and a one-digit mantissa
    !! without '.0' ('1e-4'): the form of sweep labels.
    function real_text(x, compact) result(s)
        real(wp), intent(in) :: x
        logical, intent(in), optional :: compact
        character(len=:), allocatable :: s
        character(len=:), allocatable :: digits
        integer :: e, n, e_low, e_high
        logical :: short

        short = .false.
        if (present(compact)) short = compact
        e_low = merge(-3, -4, short)
        e_high = merge(5, 6, short)
        if (ieee_is_nan(x)) then
            s = 'NaN'
            return
        else if (.not. ieee_is_finite(x)) then
            s = merge('+Infinity', '-Infinity', x > 0.0_wp)
            return
        else if (.not. abs(x) > 0.0_wp) then
            s = '0.0'
            return
        end if
        call shortest_digits(x, digits, e)
        n = len(digits)
        if (e >= 0 .and. e <= e_high) then
            if (n <= e + 1) then
                s = digits//repeat('0', e + 1 - n)//'.0'
            else
                s = digits(:e + 1)//'.'//digits(e + 2:)
            end if
        else if (e < 0 .and. e >= e_low) then
            s = '0.'//repeat('0', -e - 1)//digits
        else if (n == 1) then
            if (short) then
                s = digits//'e'//int_text(e)
            else
                s = digits//'.0e'//int_text(e)
            end if
        else
            s = digits(1:1)//'.'//digits(2:)//'e'//int_text(e)
        end if
        if (x < 0.0_wp) s = '-'//s
    end function real_text

    !> The shortest decimal digits that read back to |x| (finite, not zero), without
    !! trailing zeros: |x| = d1.d2d3... * 10**e ('1', -4 for 1e-4).
    subroutine shortest_digits(x, digits, e)
        real(wp), intent(in) :: x
        character(len=:), allocatable, intent(out) :: digits
        integer, intent(out) :: e
        character(len=40) :: buf
        character(len=16) :: fmt
        real(wp) :: y
        integer :: d, ios, epos, n
        do d = 1, 17
            write (fmt, '(a, i0, a)') '(es40.', d, 'e3)'
            write (buf, fmt) abs(x)
            read (buf, *, iostat=ios) y
            if (ios == 0 .and. abs(y - abs(x)) <= 0.0_wp) exit
        end do
        buf = adjustl(buf)
        epos = scan(buf, 'Ee')
        read (buf(epos + 1:), *) e
        digits = buf(1:1)//buf(3:epos - 1)
        n = len(digits)
        do while (n > 1)
            if (digits(n:n) /= '0') exit
            n = n - 1
        end do
        digits = digits(:n)
    end subroutine shortest_digits

    !> x*y as the product of the decimals that x and y read from (their shortest texts,
    !! as real_text writes them), rounded once to the nearest real: 0.01*1e-4 is 1e-6,
    !! where the binary product is 1.0000000000000002e-6. A derived input (a sweep's
    !! atol = atol_per_rtol*rtol) is then the number its user would have written. A factor
    !! that is zero, infinite or NaN, or a product out of range: the binary product.
    function decimal_product(x, y) result(p)
        real(wp), intent(in) :: x, y
        real(wp) :: p
        character(len=:), allocatable :: a, b, digits
        integer :: prod(34), ex, ey, i, j, ios
        real(wp) :: q
        p = x*y
        if (.not. (ieee_is_finite(p) .and. abs(p) > 0.0_wp)) return
        call shortest_digits(x, a, ex)
        call shortest_digits(y, b, ey)
        ! schoolbook product of the digit strings, prod(i + j) collecting a(i) b(j)
        prod = 0
        do i = 1, len(a)
            do j = 1, len(b)
                prod(i + j) = prod(i + j) + (iachar(a(i:i)) - 48)*(iachar(b(j:j)) - 48)
            end do
        end do
        do i = len(a) + len(b), 2, -1
            prod(i - 1) = prod(i - 1) + prod(i)/10
            prod(i) = mod(prod(i), 10)
        end do
        ! a = 0.a1a2... 10**(ex + 1), likewise b: the product 0.p1p2... 10**(ex + ey + 2)
        digits = repeat(' ', len(a) + len(b))
        do i = 1, len(digits)
            digits(i:i) = achar(48 + prod(i))
        end do
        digits = digits(:1)//'.'//digits(2:)//'e'//int_text(ex + ey + 1)
        read (digits, *, iostat=ios) q
        if (ios /= 0 .or. .not. (ieee_is_finite(q) .and. q > 0.0_wp)) return
        p = sign(q, p)
    end function decimal_product

    !> x rounded to `digits` significant digits, as real_text writes that number: a
    !! measured or derived value without the noise of its last binary digits
    !! (0.09168699999999999 -> '0.091687' with 6).
    function significant_text(x, digits, compact) result(s)
        real(wp), intent(in) :: x
        integer, intent(in) :: digits
        logical, intent(in), optional :: compact
        character(len=:), allocatable :: s
        character(len=40) :: buf
        character(len=16) :: fmt
        real(wp) :: y
        integer :: ios
        y = x
        if (ieee_is_finite(x) .and. abs(x) > 0.0_wp) then
            write (fmt, '(a, i0, a)') '(es40.', max(digits, 1) - 1, 'e3)'
            write (buf, fmt) x
            read (buf, *, iostat=ios) y
            if (ios /= 0) y = x
        end if
        s = real_text(y, compact)
    end function significant_text

    !> x with `decimals` digits after the point and a digit before it ('12.3', '0.5000',
    !! '-0.1200').
    function fixed_text(x, decimals) result(s)
        real(wp), intent(in) :: x
        integer, intent(in) :: decimals
        character(len=:), allocatable :: s
        character(len=48) :: buf
        character(len=16) :: fmt
        write (fmt, '(a, i0, a)') '(f0.', decimals, ')'
        write (buf, fmt) x
        s = trim(adjustl(buf))
        if (s(1:1) == '.') then
            s = '0'//s
        else if (s(1:min(2, len(s))) == '-.') then
            s = '-0'//s(2:)
        end if
    end function fixed_text

    !> x right-aligned in a column of `width` characters: fixed-point with `decimals`
    !! digits after the point, or fewer where the number needs the room (a force of 138 kN in
    !! f12.6 is 14 characters), else in scientific notation (at least 11 characters wide).
    !! Fortran's own fixed formats print asterisks for a number too wide, and numbers that
    !! fill their whole field run into the next.
    function column_text(x, width, decimals) result(s)
        real(wp), intent(in) :: x
        integer, intent(in) :: width, decimals
        character(len=:), allocatable :: s
        character(len=64) :: buf
        character(len=24) :: fmt
        integer :: d, w
        do d = max(decimals, 0), 0, -1
            write (fmt, '(a, i0, a, i0, a)') '(f', width, '.', d, ')'
            write (buf, fmt) x
            if (index(buf(1:width), '*') == 0) then
                s = buf(1:width)
                return
            end if
        end do
        w = max(width, 11)
        write (fmt, '(a, i0, a, i0, a)') '(es', w, '.', w - 8, ')'
        write (buf, fmt) x
        s = buf(1:w)
    end function column_text

    !> 'x, y' of a pair, each as `real_text`.
    function pair_text(x) result(s)
        real(wp), intent(in) :: x(2)
        character(len=:), allocatable :: s
        s = real_text(x(1))//', '//real_text(x(2))
    end function pair_text

    pure function logical_text(b) result(s)
        logical, intent(in) :: b
        character(len=:), allocatable :: s
        if (b) then
            s = '.true.'
        else
            s = '.false.'
        end if
    end function logical_text

    !> A Fortran string literal: 'text', with embedded quotes doubled; with `escape`, each
    !! embedded quote is written as `escape` instead (a shell word: escape = "'\''").
    pure function quoted(text, escape) result(s)
        character(len=*), intent(in) :: text
        character(len=*), intent(in), optional :: escape
        character(len=:), allocatable :: s
        if (present(escape)) then
            s = enclosed(text, "'", escape)
        else
            s = enclosed(text, "'", "''")
        end if
    end function quoted

    !> `text` between two `mark` characters, each `mark` inside it written as `escape`
    !! (a Fortran literal: mark ', escape ''; a CSV field: mark ", escape "").
    pure function enclosed(text, mark, escape) result(s)
        character(len=*), intent(in) :: text
        character(len=1), intent(in) :: mark
        character(len=*), intent(in) :: escape
        character(len=:), allocatable :: s
        integer :: i
        s = mark
        do i = 1, len(text)
            if (text(i:i) == mark) then
                s = s//escape
            else
                s = s//text(i:i)
            end if
        end do
        s = s//mark
    end function enclosed

    !> `text` with every `old` (not empty) replaced by `new`, left to right.
    pure function replaced(text, old, new) result(out)
        character(len=*), intent(in) :: text, old, new
        character(len=:), allocatable :: out
        integer :: k, from
        out = ''
        from = 1
        do
            k = index(text(from:), old)
            if (k == 0) exit
            out = out//text(from:from + k - 2)//new
            from = from + k - 1 + len(old)
        end do
        out = out//text(from:)
    end function replaced

    !> ASCII lower case.
    pure function lower(s) result(t)
        character(len=*), intent(in) :: s
        character(len=len(s)) :: t
        integer :: i, c
        t = s
        do i = 1, len(s)
            c = iachar(s(i:i))
            if (c >= iachar('A') .and. c <= iachar('Z')) t(i:i) = achar(c + 32)
        end do
    end function lower

    !> x as the edit descriptor ESw.d writes it (w wide, d digits after the point), with a
    !! three-digit exponent where two do not hold it: ESw.d alone then drops the E
    !! (2.23460-153). Such a number is one character wider; w must leave room for that.
    pure function es_text(x, w, d) result(s)
        real(wp), intent(in) :: x
        integer, intent(in) :: w, d
        character(len=:), allocatable :: s
        character(len=32) :: buf, fmt
        ! (9.99...e99 rounds up to an exponent of 100 at d digits)
        if (abs(x) >= 9.99e99_wp .or. (abs(x) > 0.0_wp .and. abs(x) < 1.0e-99_wp)) then
            write (fmt, '(a, i0, a, i0, a)') '(es', w + 1, '.', d, 'e3)'
        else
            write (fmt, '(a, i0, a, i0, a)') '(es', w, '.', d, ')'
        end if
        write (buf, fmt) x
        s = buf(:len_trim(buf))
        if (len(s) < w) s = repeat(' ', w - len(s))//s
    end function es_text

    !> `text` without the blanks and tabs at its ends (a namelist file's white space; a
    !! command line's `--set` argument may carry tabs where a file would).
    pure function stripped(text) result(s)
        character(len=*), intent(in) :: text
        character(len=:), allocatable :: s
        character(len=*), parameter :: WHITE = ' '//achar(9)
        integer :: first, last
        first = verify(text, WHITE)
        last = verify(text, WHITE, back=.true.)
        if (first == 0) then
            s = ''
        else
            s = text(first:last)
        end if
    end function stripped

    !> A line for a message: in double quotes, trailing blanks removed, long lines shortened,
    !! control characters shown as `printable` does.
    pure function line_quote(line) result(s)
        character(len=*), intent(in) :: line
        character(len=:), allocatable :: s
        if (len_trim(line) > 80) then
            s = '"'//printable(line(:char_start(line, 78) - 1))//'..."'
        else
            s = '"'//printable(trim(line))//'"'
        end if
    end function line_quote

    !> Text safe to print: a control character (byte < 32 except tab, or 127) as `\xNN`; a
    !! character that shows as nothing or as a blank (UTF-8 of a no-break space, zero-width
    !! space, byte-order mark, soft hyphen, ...: `invisible`) as `<U+XXXX>`, so that a
    !! message names it; bytes that are not UTF-8 as `\xNN`.
    pure function printable(text) result(s)
        character(len=*), intent(in) :: text
        character(len=:), allocatable :: s
        character(len=*), parameter :: HEX = '0123456789abcdef', UPPER = '0123456789ABCDEF'
        character(len=:), allocatable :: buf
        integer :: i, c, n, code, length, k
        allocate (character(len=8*len(text)) :: buf)
        n = 0
        i = 1
        do while (i <= len(text))
            c = iachar(text(i:i))
            call utf8_at(text, i, code, length)
            if ((c < 32 .and. c /= 9) .or. c == 127 .or. (c >= 128 .and. length == 0)) then
                buf(n + 1:n + 4) = '\x'//HEX(c/16 + 1:c/16 + 1)//HEX(mod(c, 16) + 1:mod(c, 16) + 1)
                n = n + 4
                i = i + 1
            else if (c >= 128 .and. invisible(code)) then
                buf(n + 1:n + 3) = '<U+'
                do k = 3, 0, -1
                    buf(n + 7 - k:n + 7 - k) = UPPER(mod(code/16**k, 16) + 1:mod(code/16**k, 16) + 1)
                end do
                buf(n + 8:n + 8) = '>'
                n = n + 8
                i = i + length
            else
                length = max(length, 1)
                buf(n + 1:n + length) = text(i:i + length - 1)
                n = n + length
                i = i + length
            end if
        end do
        s = buf(:n)
    end function printable

    !> The UTF-8 character at byte i of `text`: its code point and its length in bytes (1
    !! for ASCII; 0 when the bytes there are not UTF-8).
    pure subroutine utf8_at(text, i, code, length)
        character(len=*), intent(in) :: text
        integer, intent(in) :: i
        integer, intent(out) :: code, length
        integer :: c, k, b
        c = iachar(text(i:i))
        code = c
        length = 1
        if (c < 128) return
        length = 0
        if (c >= 194 .and. c <= 223) then
            length = 2
            code = c - 192
        else if (c >= 224 .and. c <= 239) then
            length = 3
            code = c - 224
        else if (c >= 240 .and. c <= 244) then
            length = 4
            code = c - 240
        end if
        if (length == 0 .or. i + length - 1 > len(text)) then
            length = 0
            return
        end if
        do k = 1, length - 1
            b = iachar(text(i + k:i + k))
            if (b < 128 .or. b > 191) then
                length = 0
                return
            end if
            code = code*64 + (b - 128)
        end do
    end subroutine utf8_at

    !> Whether the code point shows as nothing or as a blank: spaces other than ' ', the
    !! zero-width characters, the byte-order mark, the soft hyphen, joiners, marks.
    pure logical function invisible(code)
        integer, intent(in) :: code
        select case (code)
        case (int(z'A0'), int(z'AD'), int(z'34F'), int(z'61C'), int(z'115F'), int(z'1160'), &
              int(z'17B4'), int(z'17B5'), int(z'180E'), int(z'2000'):int(z'200F'), &
              int(z'2028'):int(z'202F'), int(z'205F'):int(z'206F'), int(z'3000'), &
              int(z'3164'), int(z'FEFF'), int(z'FFA0'))
            invisible = .true.
        case default
            invisible = .false.
        end select
    end function invisible

    !> A value for a message: at most 60 bytes (a longer one as its first 40 and '...'),
    !! not cut inside a UTF-8 character.
    pure function clip(text) result(s)
        character(len=*), intent(in) :: text
        character(len=:), allocatable :: s
        if (len(text) > 60) then
            s = text(:char_start(text, 41) - 1)//'...'
        else
            s = text
        end if
    end function clip

    !> The first byte of the UTF-8 character that holds byte i of `text` (i itself when it
    !! is not a continuation byte; at most 3 bytes back), so that text(:result - 1) ends
    !! on a whole character.
    pure integer function char_start(text, i) result(k)
        character(len=*), intent(in) :: text
        integer, intent(in) :: i
        integer :: c
        k = i
        do while (k > max(1, i - 3) .and. k <= len(text))
            c = iachar(text(k:k))
            if (c < 128 .or. c > 191) exit
            k = k - 1
        end do
        if (k <= len(text)) then
            c = iachar(text(k:k))
            if (c >= 128 .and. c <= 191) k = i
        end if
    end function char_start

    !> A list of strings as a character array (as long as the longest, at least 1).
    pure function text_array(list) result(arr)
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
    end function text_array

    !> Append one string to a list (grown by one).
    pure subroutine append_text(list, value)
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
    end subroutine append_text
    !> '; did you mean "x"?' for a near miss of one of `names`, else '; keys: ' (or
    !! '; WHAT: ') and the list.
    function name_hint(names, key, what) result(text)
        type(text_t), intent(in) :: names(:)
        character(len=*), intent(in) :: key
        character(len=*), intent(in), optional :: what
        character(len=:), allocatable :: text
        integer :: k, d, best, best_k
        best = huge(1)
        best_k = 0
        text = ''
        do k = 1, size(names)
            d = huge(1)
            if (len(key) <= 64) d = edit_distance(lower(key), names(k)%s)
            if (d < best) then
                best = d
                best_k = k
            end if
            if (k > 1) text = text//', '
            text = text//names(k)%s
        end do
        if (best_k > 0 .and. best <= 2) then
            text = '; did you mean "'//names(best_k)%s//'"?'
        else if (present(what)) then
            text = '; '//what//': '//text
        else
            text = '; keys: '//text
        end if
    end function name_hint

    !> Optimal string alignment distance (Levenshtein with transpositions).
    pure integer function edit_distance(a, b) result(dist)
        character(len=*), intent(in) :: a, b
        integer :: d(0:len(a), 0:len(b)), i, j, cost
        do i = 0, len(a)
            d(i, 0) = i
        end do
        do j = 0, len(b)
            d(0, j) = j
        end do
        do j = 1, len(b)
            do i = 1, len(a)
                cost = merge(0, 1, a(i:i) == b(j:j))
                d(i, j) = min(d(i - 1, j) + 1, d(i, j - 1) + 1, d(i - 1, j - 1) + cost)
                if (i > 1 .and. j > 1) then
                    if (a(i:i) == b(j - 1:j - 1) .and. a(i - 1:i - 1) == b(j:j)) then
                        d(i, j) = min(d(i, j), d(max(i - 2, 0), max(j - 2, 0)) + 1)
                    end if
                end if
            end do
        end do
        dist = d(len(a), len(b))
    end function edit_distance
end module ropedyn_text
