!> Tokens of namelist-syntax text, for `ropedyn_namelist_file`: words (numbers, logicals,
!! names), quoted strings, `= , / ( )`, group headers `&name`, and two kinds of bad token
!! (a control character, a string not closed on its line) that the parser reports with its
!! group and key. Comments (`!` to the end of the line) and blanks are dropped.
module ropedyn_namelist_lexer
    use ropedyn_text, only: int_text, lower, printable, text_t
    implicit none
    private
    public :: token_t, lex_lines
    public :: TK_WORD, TK_STRING, TK_EQ, TK_COMMA, TK_SLASH, TK_LPAREN, TK_RPAREN, TK_GROUP, &
        TK_BAD_CHAR, TK_BAD_QUOTE

    integer, parameter :: TK_WORD = 1, TK_STRING = 2, TK_EQ = 3, TK_COMMA = 4, TK_SLASH = 5, &
        TK_LPAREN = 6, TK_RPAREN = 7, TK_GROUP = 8, TK_BAD_CHAR = 9, TK_BAD_QUOTE = 10

    character(len=*), parameter :: TAB = achar(9)
    !> The one-character tokens and their kinds.
    character(len=*), parameter :: PUNCTUATION_CHARS = '=,/()'
    integer, parameter :: PUNCTUATION(5) = [TK_EQ, TK_COMMA, TK_SLASH, TK_LPAREN, TK_RPAREN]
    !> Characters that end a word.
    character(len=*), parameter :: WORD_END = ' ,/=()!&''"'//TAB

    type :: token_t
        integer :: kind = 0
        !> the word; a string's contents; a group's name (lower case); a bad token's reason
        character(len=:), allocatable :: text
        integer :: line = 0    !< line number
        integer :: first = 0   !< first column
        integer :: last = 0    !< last column
    end type token_t

contains

    !> The tokens of all lines, in order.
    subroutine lex_lines(lines, tk)
        type(text_t), intent(in) :: lines(:)
        type(token_t), allocatable, intent(out) :: tk(:)
        integer :: i, n
        allocate (tk(64))
        n = 0
        do i = 1, size(lines)
            call lex_line(lines(i)%s, i, tk, n)
        end do
        tk = tk(:n)
    end subroutine lex_lines

    subroutine lex_line(s, line, tk, n)
        character(len=*), intent(in) :: s
        integer, intent(in) :: line
        type(token_t), allocatable, intent(inout) :: tk(:)
        integer, intent(inout) :: n
        integer :: c, e, bad
        character(len=:), allocatable :: text

        c = 1
        do while (c <= len(s))
            bad = control_at(s(c:c))
            if (bad >= 0) then
                call add(TK_BAD_CHAR, 'control character '//printable(s(c:c))// &
                    ' at column '//int_text(c), c, c)
                return
            end if
            select case (s(c:c))
            case (' ', TAB)
                c = c + 1
            case ('!')
                e = first_control(s(c + 1:))
                if (e > 0) call add(TK_BAD_CHAR, 'control character '//printable(s(c + e:c + e)) &
                    //' at column '//int_text(c + e)//' (in a comment)', c + e, c + e)
                return
            case ("'", '"')
                call string_at(s, c, text, e, bad)
                if (bad > 0) then
                    call add(TK_BAD_CHAR, 'control character '//printable(s(bad:bad))// &
                        ' at column '//int_text(bad)//' (in a string)', bad, bad)
                    return
                else if (e == 0) then
                    call add(TK_BAD_QUOTE, 'unbalanced quotes: the string started at column ' &
                        //int_text(c)//' does not end on its line', c, len(s))
                    return
                end if
                call add(TK_STRING, text, c, e)
                c = e + 1
            case ('=', ',', '/', '(', ')')
                call add(PUNCTUATION(index(PUNCTUATION_CHARS, s(c:c))), s(c:c), c, c)
                c = c + 1
            case ('&')
                e = c + 1
                do while (e <= len(s))
                    if (verify(lower(s(e:e)), 'abcdefghijklmnopqrstuvwxyz0123456789_') > 0) exit
                    e = e + 1
                end do
                call add(TK_GROUP, lower(s(c + 1:e - 1)), c, e - 1)
                c = e
            case default
                e = c
                do while (e < len(s))
                    if (scan(s(e + 1:e + 1), WORD_END) > 0 .or. control_at(s(e + 1:e + 1)) >= 0) &
                        exit
                    e = e + 1
                end do
                call add(TK_WORD, s(c:e), c, e)
                c = e + 1
            end select
        end do
    contains
        subroutine add(kind, text, first, last)
            integer, intent(in) :: kind, first, last
            character(len=*), intent(in) :: text
            type(token_t), allocatable :: grown(:)
            if (n == size(tk)) then
                allocate (grown(2*n))
                grown(:n) = tk
                call move_alloc(grown, tk)
            end if
            n = n + 1
            tk(n) = token_t(kind, text, line, first, last)
        end subroutine add
    end subroutine lex_line

    !> The string starting with the quote at s(c:c): its contents (doubled quotes as one),
    !! the column `e` of its closing quote (0 if none on the line), and the column `bad` of a
    !! control character in it (0 if none).
    pure subroutine string_at(s, c, text, e, bad)
        character(len=*), intent(in) :: s
        integer, intent(in) :: c
        character(len=:), allocatable, intent(out) :: text
        integer, intent(out) :: e, bad
        character :: q
        integer :: i
        integer :: j, k
        q = s(c:c)
        text = ''
        e = 0
        bad = 0
        i = c + 1
        do
            j = index(s(i:), q)     ! the next quote; a doubled one stands for one
            if (j == 0) then
                k = first_control(s(i:))
                if (k > 0) bad = i + k - 1
                return
            end if
            k = first_control(s(i:i + j - 2))
            if (k > 0) then
                bad = i + k - 1
                return
            end if
            text = text//s(i:i + j - 2)
            i = i + j
            if (i <= len(s)) then
                if (s(i:i) == q) then
                    text = text//q
                    i = i + 1
                    cycle
                end if
            end if
            e = i - 1
            return
        end do
    end subroutine string_at

    !> Position of the first control character in s, 0 if there is none.
    pure integer function first_control(s) result(k)
        character(len=*), intent(in) :: s
        do k = 1, len(s)
            if (control_at(s(k:k)) >= 0) return
        end do
        k = 0
    end function first_control

    !> The code of a control character (other than tab), else -1.
    elemental integer function control_at(ch) result(code)
        character, intent(in) :: ch
        code = iachar(ch)
        if (.not. ((code < 32 .and. code /= 9) .or. code == 127)) code = -1
    end function control_at
end module ropedyn_namelist_lexer
