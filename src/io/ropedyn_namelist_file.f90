!> The one reader of namelist-syntax text: scene files, sweep files and the values of
!! `--set` (docs/reference/scene-file.md, "The file format"). It does not use the Fortran runtime's namelist
!! READ: it splits the text into groups of assignments and reports every syntax error with
!! the file, the group, the key, the value and the line.
!!
!! Syntax: groups `&name ... /` (or `... &end`); `!` comments; `key = value[, value ...]`
!! and `key(i) = value ...`, separated by blanks, commas or new lines; quoted strings with
!! ' or " (a doubled quote inside stands for one); repeat counts `r*value`. Values are kept
!! as words or strings; the caller converts them (`value_real`, `value_int`,
!! `value_logical`), since only it knows the type of a key. Errors: text outside a group,
!! an unknown group or one given twice, a group not closed, a control character (NUL ...),
!! unbalanced quotes, a null value (`key = /`, `key = ,`, `1, , 2`), a key given twice in a
!! group (case-insensitive; overlapping elements), a file larger than MAX_FILE_BYTES.
module ropedyn_namelist_file
    use ropedyn_kinds, only: wp, i8
    use ropedyn_error, only: error_t, make_error, ERR_INPUT
    use ropedyn_text, only: int_text, lower, line_quote, printable, text_t, clip, edit_distance
    use ropedyn_os, only: special_file_reason
    use ropedyn_namelist_lexer, only: token_t, lex_lines, TK_WORD, TK_STRING, TK_EQ, &
        TK_COMMA, TK_SLASH, TK_LPAREN, TK_RPAREN, TK_GROUP, TK_BAD_CHAR, TK_BAD_QUOTE
    use ropedyn_namelist_values, only: nml_value_t, value_token, parse_values, value_real, &
        value_int, value_logical, V_WORD, V_STRING, MAX_VALUES
    implicit none
    private
    public :: nml_value_t, nml_assignment_t, nml_group_t, nml_file_t
    public :: read_namelist_file, parse_namelist_lines, parse_values
    public :: value_real, value_int, value_logical
    public :: V_WORD, V_STRING, MAX_FILE_BYTES, MAX_VALUES, MAX_ASSIGNMENTS

    integer, parameter :: MAX_FILE_BYTES = 1048576  !< largest file read (1 MiB)
    integer, parameter :: MAX_ASSIGNMENTS = 1000    !< most assignments in one group
    !> The UTF-8 byte-order mark, skipped at the start of a file.
    character(len=*), parameter :: UTF8_BOM = achar(239)//achar(187)//achar(191)

    !> `key = values` or `key(index) = values`.
    type :: nml_assignment_t
        character(len=:), allocatable :: key         !< as written, with its index
        character(len=:), allocatable :: name        !< lower case, without the index
        integer :: index = 0                         !< the (i) given, else 0
        type(nml_value_t), allocatable :: values(:)
        character(len=:), allocatable :: value_text  !< the values as written
        integer :: line = 0                          !< line of the key
        character(len=:), allocatable :: line_text   !< that line
    end type nml_assignment_t

    type :: nml_group_t
        character(len=:), allocatable :: name        !< lower case
        integer :: line = 0                          !< line of `&name`
        type(nml_assignment_t), allocatable :: assignments(:)
    end type nml_group_t

    type :: nml_file_t
        character(len=:), allocatable :: origin      !< the file, for messages
        integer :: lines = 0                         !< number of lines
        type(nml_group_t), allocatable :: groups(:)  !< in the order of the file
    contains
        procedure :: find => file_find
    end type nml_file_t

    !> The parser's position and the assignment being collected.
    type :: parser_t
        character(len=:), allocatable :: origin
        type(text_t), allocatable :: lines(:)
        type(token_t), allocatable :: tk(:)
        integer :: j = 1                   !< next token
        integer :: group = 0               !< open group (index in the file), 0: outside
        integer :: closed_line = 0         !< line where the last group was closed
        logical :: open = .false.          !< an assignment is being collected
        integer :: last = 0                !< kind of the last token taken into it
        type(nml_assignment_t) :: a
        integer :: eq = 0                  !< the token '=' of the assignment
        integer :: end = 0                 !< its last token so far
        integer :: count = 0               !< assignments of the open group so far
    end type parser_t

contains

    !> Read a namelist file whose groups must be among `allowed` (lower case), each at most
    !! once. `hint` ends the message of an unknown group (default: the list of groups). A
    !! file without a `&required` header is reported first: 'no &required group: not_what'.
    subroutine read_namelist_file(path, allowed, file, err, hint, required, not_what)
        character(len=*), intent(in) :: path
        character(len=*), intent(in) :: allowed(:)
        type(nml_file_t), intent(out) :: file
        type(error_t), allocatable, intent(out) :: err
        character(len=*), intent(in), optional :: hint, required, not_what
        type(text_t), allocatable :: lines(:)
        type(token_t), allocatable :: tk(:)
        integer :: k
        call read_lines(path, lines, err)
        if (allocated(err)) return
        if (present(required)) then
            call lex_lines(lines, tk)
            if (.not. any(tk%kind == TK_GROUP .and. [(tk(k)%text == required, k = 1, size(tk))])) &
                then
                if (size(lines) == 0) then
                    call make_error(err, ERR_INPUT, path//': no &'//required//' group (the ' &
                        //'file is empty): '//not_what)
                else
                    call make_error(err, ERR_INPUT, path//': no &'//required//' group'// &
                        groups_found(tk, required)//': '//not_what)
                end if
                return
            end if
        end if
        call parse_namelist_lines(path, lines, allowed, file, err, hint)
    end subroutine read_namelist_file

    !> ' (found &a, &b; did you mean &required?)' for the groups the tokens `tk` open (''
    !! when none), the hint when one of them is a near miss of `required`.
    function groups_found(tk, required) result(text)
        type(token_t), intent(in) :: tk(:)
        character(len=*), intent(in) :: required
        character(len=:), allocatable :: text, hint
        integer :: k, shown
        text = ''
        hint = ''
        shown = 0
        do k = 1, size(tk)
            if (tk(k)%kind /= TK_GROUP .or. len(tk(k)%text) == 0) cycle
            if (tk(k)%text == 'end') cycle
            shown = shown + 1
            if (shown > 5) cycle
            if (shown > 1) text = text//', '
            text = text//'&'//clip(printable(tk(k)%text))
            if (len(hint) == 0 .and. edit_distance(tk(k)%text, required) <= 2) &
                hint = '; did you mean &'//required//'?'
        end do
        if (shown > 5) text = text//', ...'
        if (shown > 0) text = ' (found '//text//hint//')'
    end function groups_found

    !> Index of group `name` in the file, 0 if it is not there.
    pure integer function file_find(self, name) result(k)
        class(nml_file_t), intent(in) :: self
        character(len=*), intent(in) :: name
        do k = 1, size(self%groups)
            if (self%groups(k)%name == name) return
        end do
        k = 0
    end function file_find

    !> The lines of a text file (LF or CRLF), checked against MAX_FILE_BYTES first.
    subroutine read_lines(path, lines, err)
        character(len=*), intent(in) :: path
        type(text_t), allocatable, intent(out) :: lines(:)
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: bytes
        character(len=512) :: msg
        integer :: unit, ios, n, start, k, size_bytes
        integer(i8) :: file_size

        msg = ''
        ! a FIFO would block the open, a device such as /dev/zero read as empty or never end
        if (len(special_file_reason(path)) > 0) then
            call make_error(err, ERR_INPUT, path//': cannot read: '//special_file_reason(path))
            return
        end if
        open (newunit=unit, file=path, status='old', action='read', access='stream', &
              form='unformatted', iostat=ios, iomsg=msg)
        if (ios /= 0) then
            call make_error(err, ERR_INPUT, path//': cannot open: '//trim(msg))
            return
        end if
        inquire (unit=unit, size=file_size)
        if (file_size > MAX_FILE_BYTES) then
            call make_error(err, ERR_INPUT, path//': '//int_text(file_size)//' bytes: too ' &
                //'large for an input file (at most '//int_text(MAX_FILE_BYTES)//' bytes)')
            close (unit)
            return
        end if
        size_bytes = int(max(0_i8, file_size))
        allocate (character(len=size_bytes) :: bytes)
        if (size_bytes > 0) read (unit, iostat=ios, iomsg=msg) bytes
        close (unit)
        if (ios /= 0) then
            call make_error(err, ERR_INPUT, path//': cannot read: '//trim(msg))
            return
        end if
        ! a UTF-8 byte-order mark (some editors write one) is not part of the text
        if (size_bytes >= 3) then
            if (bytes(1:3) == UTF8_BOM) then
                bytes = bytes(4:)
                size_bytes = size_bytes - 3
            end if
        end if
        n = count([(bytes(k:k) == achar(10), k = 1, size_bytes)])
        if (size_bytes > 0) then
            if (bytes(size_bytes:size_bytes) /= achar(10)) n = n + 1
        end if
        allocate (lines(n))
        start = 1
        do k = 1, n
            ios = index(bytes(start:), achar(10))
            if (ios == 0) ios = size_bytes - start + 2
            lines(k)%s = bytes(start:start + ios - 2)
            start = start + ios
            ! CRLF: the CR belongs to the line end
            if (len(lines(k)%s) > 0) then
                if (lines(k)%s(len(lines(k)%s):) == achar(13)) &
                    lines(k)%s = lines(k)%s(:len(lines(k)%s) - 1)
            end if
        end do
    end subroutine read_lines

    !> Parse lines of namelist text (see `read_namelist_file`).
    subroutine parse_namelist_lines(origin, lines, allowed, file, err, hint)
        character(len=*), intent(in) :: origin
        type(text_t), intent(in) :: lines(:)
        character(len=*), intent(in) :: allowed(:)
        type(nml_file_t), intent(out) :: file
        type(error_t), allocatable, intent(out) :: err
        character(len=*), intent(in), optional :: hint
        type(parser_t) :: p
        integer :: k

        file%origin = origin
        file%lines = size(lines)
        allocate (file%groups(0))
        p%origin = origin
        p%lines = lines
        call lex_lines(lines, p%tk)
        do while (p%j <= size(p%tk))
            if (p%group == 0) then
                call outside(p, file, allowed, err, hint)
            else
                call inside(p, file, err)
            end if
            if (allocated(err)) return
        end do
        if (p%group > 0) then
            call make_error(err, ERR_INPUT, origin//': &'//file%groups(p%group)%name// &
                ': not closed by "/" before the end of the file (group starts at line ' &
                //int_text(file%groups(p%group)%line)//')')
            return
        end if
        do k = 1, size(file%groups)
            call check_duplicates(origin, file%groups(k), err)
            if (allocated(err)) return
        end do
    end subroutine parse_namelist_lines

    !> A token outside any group: only `&name` may start here.
    subroutine outside(p, file, allowed, err, hint)
        type(parser_t), intent(inout) :: p
        type(nml_file_t), intent(inout) :: file
        character(len=*), intent(in) :: allowed(:)
        type(error_t), allocatable, intent(out) :: err
        character(len=*), intent(in), optional :: hint
        type(nml_group_t), allocatable :: grown(:)
        character(len=:), allocatable :: name, list
        integer :: k, line

        call to_bad_token(p)
        associate (t => p%tk(p%j))
            line = t%line
            if (t%kind == TK_BAD_CHAR) then
                call make_error(err, ERR_INPUT, p%origin//': line '//int_text(line)// &
                    ': '//t%text//' '//line_quote(p%lines(line)%s))
                return
            end if
            if (line == p%closed_line) then
                call make_error(err, ERR_INPUT, p%origin//': line '//int_text(line)// &
                    ': text after the end of &'//file%groups(size(file%groups))%name// &
                    ': '//line_quote(p%lines(line)%s)//' (after the / of a group only a ' &
                    //'comment may follow on its line)')
                return
            else if (t%kind /= TK_GROUP .or. t%text == '' .or. t%text == 'end') then
                call make_error(err, ERR_INPUT, p%origin//': line '//int_text(line)// &
                    ': text outside any group: '//line_quote(p%lines(line)%s)// &
                    ' (a group starts with &name and ends with /)')
                return
            end if
            name = clip(printable(t%text))
        end associate
        if (.not. any(allowed == name)) then
            list = trim(allowed(1))
            do k = 2, size(allowed)
                list = list//', '//trim(allowed(k))
            end do
            if (present(hint)) list = hint
            if (.not. present(hint)) list = 'groups: '//list
            call make_error(err, ERR_INPUT, p%origin//': &'//name// &
                ': unknown group (line '//int_text(line)//': '// &
                line_quote(p%lines(line)%s)//'; '//list//')')
            return
        end if
        k = file%find(name)
        if (k > 0) then
            call make_error(err, ERR_INPUT, p%origin//': &'//name//': group given twice ' &
                //'(lines '//int_text(file%groups(k)%line)//' and '//int_text(line)//')')
            return
        end if
        allocate (grown(size(file%groups) + 1))
        grown(:size(file%groups)) = file%groups
        grown(size(grown))%name = name
        grown(size(grown))%line = line
        allocate (grown(size(grown))%assignments(0))
        call move_alloc(grown, file%groups)
        p%group = size(file%groups)
        p%open = .false.
        p%count = 0
        p%j = p%j + 1
    end subroutine outside

    !> A token inside the open group.
    subroutine inside(p, file, err)
        type(parser_t), intent(inout) :: p
        type(nml_file_t), intent(inout) :: file
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: where
        integer :: line, after

        where = p%origin//': &'//file%groups(p%group)%name//': '
        call to_bad_token(p)
        line = p%tk(p%j)%line
        select case (p%tk(p%j)%kind)
        case (TK_GROUP)
            if (p%tk(p%j)%text /= 'end') then
                call make_error(err, ERR_INPUT, where//'not closed by "/" before line '// &
                    int_text(line)//' ('//line_quote(p%lines(line)%s)//')')
                return
            end if
            call close_group(p, file, err)
        case (TK_SLASH)
            call close_group(p, file, err)
        case (TK_BAD_CHAR, TK_BAD_QUOTE)
            if (p%open) then
                call make_error(err, ERR_INPUT, where//'cannot read '//p%a%key//': ' &
                    //p%tk(p%j)%text//' (line '//int_text(line)//': ' &
                    //line_quote(p%lines(line)%s)//')')
            else
                call make_error(err, ERR_INPUT, where//'line '//int_text(line)//': ' &
                    //p%tk(p%j)%text//' '//line_quote(p%lines(line)%s))
            end if
        case (TK_WORD)
            after = key_end(p%tk, p%j)
            if (after > 0) then
                call finish_assignment(p, file, where, err)
                if (allocated(err)) return
                call start_assignment(p, after, where, err)
            else if (.not. p%open) then
                call make_error(err, ERR_INPUT, where//'line '//int_text(line)// &
                    ': expected key = value, found "'//clip(printable(p%tk(p%j)%text))//'" (' &
                    //line_quote(p%lines(line)%s)//')')
            else
                call take_value(p, where, err)
            end if
        case (TK_STRING)
            if (.not. p%open) then
                call make_error(err, ERR_INPUT, where//'line '//int_text(line)// &
                    ': expected key = value, found a string ('// &
                    line_quote(p%lines(line)%s)//')')
            else
                call take_value(p, where, err)
            end if
        case (TK_COMMA)
            if (p%open .and. (p%last == TK_EQ .or. p%last == TK_COMMA)) then
                call null_value(p, where, err)
                return
            end if
            if (p%open) call extend_to(p, p%j)
            p%last = TK_COMMA
            p%j = p%j + 1
        case default
            if (p%open) then
                call make_error(err, ERR_INPUT, where//'cannot read '//p%a%key//' = ' &
                    //clip(value_so_far(p, p%end))//': unexpected "'//clip(p%tk(p%j)%text)// &
                    '" (line '//int_text(line)//': '//line_quote(p%lines(line)%s)//')')
            else
                call make_error(err, ERR_INPUT, where//'line '//int_text(line)// &
                    ': expected key = value, found "'//clip(p%tk(p%j)%text)//'" (' &
                    //line_quote(p%lines(line)%s)//')')
            end if
        end select
    end subroutine inside

    !> A control character right after the next token (which it cut short) is reported
    !! first: move to it.
    subroutine to_bad_token(p)
        type(parser_t), intent(inout) :: p
        if (p%j + 1 > size(p%tk)) return
        if (p%tk(p%j + 1)%kind == TK_BAD_CHAR .and. p%tk(p%j + 1)%line == p%tk(p%j)%line &
            .and. p%tk(p%j + 1)%first == p%tk(p%j)%last + 1) p%j = p%j + 1
    end subroutine to_bad_token

    !> If tokens j.. are `name =` or `name ( int ) =`, the index of the '='; else 0.
    pure integer function key_end(tk, j) result(eq)
        type(token_t), intent(in) :: tk(:)
        integer, intent(in) :: j
        eq = 0
        if (j + 1 > size(tk)) return
        if (tk(j + 1)%kind == TK_EQ) then
            eq = j + 1
        else if (tk(j + 1)%kind == TK_LPAREN .and. j + 4 <= size(tk)) then
            if (tk(j + 2)%kind == TK_WORD .and. tk(j + 3)%kind == TK_RPAREN .and. &
                tk(j + 4)%kind == TK_EQ) eq = j + 4
        end if
    end function key_end

    !> Start the assignment whose key is tokens p%j .. eq - 1.
    subroutine start_assignment(p, eq, where, err)
        type(parser_t), intent(inout) :: p
        integer, intent(in) :: eq
        character(len=*), intent(in) :: where
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: name
        integer :: ios, line
        integer(i8) :: i

        line = p%tk(p%j)%line
        name = p%tk(p%j)%text
        p%a = nml_assignment_t()
        p%a%key = clip(printable(name))
        p%a%name = lower(name)
        p%a%line = line
        p%a%line_text = p%lines(line)%s
        allocate (p%a%values(0))
        if (verify(p%a%name, 'abcdefghijklmnopqrstuvwxyz0123456789_') > 0 .or. &
            verify(p%a%name(1:1), 'abcdefghijklmnopqrstuvwxyz') > 0) then
            call make_error(err, ERR_INPUT, where//'line '//int_text(line)//': "' &
                //p%a%key//'" is not a key name ('//line_quote(p%lines(line)%s)//')')
            return
        end if
        if (eq > p%j + 1) then
            p%a%key = p%a%key//'('//clip(printable(p%tk(p%j + 2)%text))//')'
            ios = 1
            if (verify(p%tk(p%j + 2)%text, '0123456789') == 0 .and. &
                len(p%tk(p%j + 2)%text) <= 9) read (p%tk(p%j + 2)%text, *, iostat=ios) i
            if (ios /= 0 .or. i < 1) then
                call make_error(err, ERR_INPUT, where//'line '//int_text(line)//': ' &
                    //p%a%key//': the index must be a whole number >= 1 (' &
                    //line_quote(p%lines(line)%s)//')')
                return
            end if
            p%a%index = int(i)
        end if
        p%open = .true.
        p%last = TK_EQ
        p%eq = eq
        p%end = eq
        p%j = eq + 1
    end subroutine start_assignment

    !> Take the value token at p%j (with a repeat count `r*value` or `r*'string'`).
    subroutine take_value(p, where, err)
        type(parser_t), intent(inout) :: p
        character(len=*), intent(in) :: where
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: reason
        integer :: used
        call value_token(p%tk, p%j, p%a%values, used, reason)
        if (len(reason) > 0) then
            call make_error(err, ERR_INPUT, where//'cannot read '//p%a%key//' = ' &
                //clip(value_so_far(p, p%j + max(used, 1) - 1))//': '//reason//' (line ' &
                //int_text(p%tk(p%j)%line)//': '//line_quote(p%lines(p%tk(p%j)%line)%s)//')')
            return
        end if
        call extend_to(p, p%j + used - 1)
        p%last = TK_WORD
        p%j = p%j + used
    end subroutine take_value

    !> The assignment now ends at token k.
    subroutine extend_to(p, k)
        type(parser_t), intent(inout) :: p
        integer, intent(in) :: k
        p%end = k
    end subroutine extend_to

    !> The values of the open assignment as written, from its '=' to the end of token k.
    function value_so_far(p, k) result(text)
        type(parser_t), intent(in) :: p
        integer, intent(in) :: k
        character(len=:), allocatable :: text
        integer :: line, a, b, first_line
        text = ''
        first_line = p%tk(p%eq)%line
        do line = first_line, p%tk(k)%line
            a = 1
            if (line == first_line) a = p%tk(p%eq)%last + 1
            b = len(p%lines(line)%s)
            if (line == p%tk(k)%line) b = p%tk(k)%last
            if (len(text) > 0) text = text//' '
            text = text//trim(adjustl(p%lines(line)%s(a:b)))
        end do
        text = trim(text)
        do while (len(text) > 0)
            if (text(len(text):) /= ',') exit
            text = trim(text(:len(text) - 1))
        end do
        text = printable(text)
    end function value_so_far

    !> End the open assignment (if any) and store it in the group.
    subroutine finish_assignment(p, file, where, err)
        type(parser_t), intent(inout) :: p
        type(nml_file_t), intent(inout) :: file
        character(len=*), intent(in) :: where
        type(error_t), allocatable, intent(out) :: err
        if (.not. p%open) return
        if (size(p%a%values) == 0) then
            call null_value(p, where, err)
            return
        end if
        p%a%value_text = value_so_far(p, p%end)
        if (p%count == MAX_ASSIGNMENTS) then
            call make_error(err, ERR_INPUT, where//'more than '//int_text(MAX_ASSIGNMENTS)// &
                ' keys in one group (line '//int_text(p%a%line)//')')
            return
        end if
        associate (g => file%groups(p%group))
            if (p%count == size(g%assignments)) then
                block
                    type(nml_assignment_t), allocatable :: grown(:)
                    allocate (grown(max(16, 2*p%count)))
                    grown(:p%count) = g%assignments(:p%count)
                    call move_alloc(grown, g%assignments)
                end block
            end if
            p%count = p%count + 1
            g%assignments(p%count) = p%a
        end associate
        p%open = .false.
    end subroutine finish_assignment

    !> The error of a key without a value, or with two commas in a row.
    subroutine null_value(p, where, err)
        type(parser_t), intent(in) :: p
        character(len=*), intent(in) :: where
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: what
        if (size(p%a%values) == 0) then
            what = 'no value (a null value would keep the default: give a value or leave ' &
                //'the key out)'
        else
            what = 'null value (two commas in a row)'
        end if
        call make_error(err, ERR_INPUT, where//p%a%key//': '//what//' (line ' &
            //int_text(p%a%line)//': '//line_quote(p%a%line_text)//')')
    end subroutine null_value

    !> '/' or '&end': the open group ends; nothing but a comment may follow on its line.
    subroutine close_group(p, file, err)
        type(parser_t), intent(inout) :: p
        type(nml_file_t), intent(inout) :: file
        type(error_t), allocatable, intent(out) :: err
        call finish_assignment(p, file, p%origin//': &'//file%groups(p%group)%name//': ', err)
        if (allocated(err)) return
        file%groups(p%group)%assignments = file%groups(p%group)%assignments(:p%count)
        p%closed_line = p%tk(p%j)%line
        p%group = 0
        p%j = p%j + 1
    end subroutine close_group

    !> A key given twice in a group (case-insensitive, overlapping elements) is an error.
    subroutine check_duplicates(origin, g, err)
        character(len=*), intent(in) :: origin
        type(nml_group_t), intent(in) :: g
        type(error_t), allocatable, intent(out) :: err
        integer :: a, b
        do b = 2, size(g%assignments)
            do a = 1, b - 1
                associate (x => g%assignments(a), y => g%assignments(b))
                    if (x%name /= y%name) cycle
                    if (max(x%index, 1) > max(y%index, 1) + size(y%values) - 1 .or. &
                        max(y%index, 1) > max(x%index, 1) + size(x%values) - 1) cycle
                    if (x%line == y%line) then
                        call make_error(err, ERR_INPUT, origin//': &'//g%name//': '//y%key// &
                            ' given twice (as '//x%key//' and '//y%key//' on line '// &
                            int_text(y%line)//': '//line_quote(y%line_text)// &
                            '; keys are case-insensitive)')
                    else
                        call make_error(err, ERR_INPUT, origin//': &'//g%name//': '//y%key// &
                            ' given twice (line '//int_text(x%line)//': '// &
                            line_quote(x%line_text)//', line '//int_text(y%line)//': '// &
                            line_quote(y%line_text)//'; keys are case-insensitive)')
                    end if
                    return
                end associate
            end do
        end do
    end subroutine check_duplicates

end module ropedyn_namelist_file
