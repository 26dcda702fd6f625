!> Unit test of the namelist reader (ropedyn_namelist_file, _values, _lexer): what it reads
!! (groups, keys, indices, strings, repeat counts, values over several lines, &end, CRLF) and
!! the message of every class of syntax error. Files go to test_namelist_tmp/.
program test_namelist_file
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t, ERR_INPUT
    use ropedyn_text, only: text_t
    use ropedyn_namelist_file, only: nml_file_t, nml_value_t, read_namelist_file, &
        parse_namelist_lines, parse_values, value_real, value_int, value_logical, V_WORD, &
        V_STRING, MAX_FILE_BYTES
    use ropedyn_assert, only: test_suite_t
    implicit none

    character(len=*), parameter :: DIR = 'test_namelist_tmp'
    character(len=*), parameter :: GROUPS(3) = [character(len=8) :: 'rope', 'model', 'solver']
    character(len=1), parameter :: NUL = achar(0), TAB = achar(9)
    type(test_suite_t) :: suite
    integer :: stat

    suite%name = 'namelist_file'
    call execute_command_line('mkdir -p '//DIR, exitstat=stat)
    call suite%check_true(stat == 0, 'create '//DIR)
    call test_reading()
    call test_values()
    call test_files()
    call test_errors()
    call suite%finish()

contains

    !> Lines from one string, '|' separating lines.
    function lines_of(text) result(lines)
        character(len=*), intent(in) :: text
        type(text_t), allocatable :: lines(:)
        integer :: start, bar, n
        n = count([(text(bar:bar) == '|', bar = 1, len(text))]) + 1
        allocate (lines(n))
        start = 1
        do n = 1, size(lines)
            bar = index(text(start:), '|')
            if (bar == 0) bar = len(text) - start + 2
            lines(n)%s = text(start:start + bar - 2)
            start = start + bar
        end do
    end function lines_of

    subroutine parse_ok(text, file, label)
        character(len=*), intent(in) :: text, label
        type(nml_file_t), intent(out) :: file
        type(error_t), allocatable :: err
        call parse_namelist_lines('x.nml', lines_of(text), GROUPS, file, err)
        call suite%check_true(.not. allocated(err), label//': no error')
        if (allocated(err)) write (*, '(a)') '      '//err%message
    end subroutine parse_ok

    !> The text must fail to parse with a message holding every one of `parts`.
    subroutine parse_error(text, parts, label)
        character(len=*), intent(in) :: text, label
        character(len=*), intent(in) :: parts(:)
        type(nml_file_t) :: file
        type(error_t), allocatable :: err
        integer :: k
        call parse_namelist_lines('x.nml', lines_of(text), GROUPS, file, err)
        call suite%check_true(allocated(err), label//': an error')
        if (.not. allocated(err)) return
        write (*, '(a)') '      message: '//err%message
        call suite%check_true(err%code == ERR_INPUT, label//': ERR_INPUT')
        do k = 1, size(parts)
            call suite%check_contains(err%message, trim(parts(k)), label)
        end do
    end subroutine parse_error

    subroutine test_reading()
        type(nml_file_t) :: f
        call parse_ok('! comment|&Rope length = 2.5, Density=7e3 ! c|  diameter =|  0.01,|/' &
            //'|&model kind = "it''s", elements = 3*4 &end|&solver x(2) = ''a'', "b""c" /', &
            f, 'reading')
        if (size(f%groups) /= 3) then
            call suite%check_true(.false., 'reading: three groups')
            return
        end if
        call suite%check_true(f%groups(1)%name == 'rope' .and. f%groups(1)%line == 2, &
            'reading: group name in lower case, its line')
        associate (a => f%groups(1)%assignments)
            call suite%check_true(size(a) == 3, 'reading: three keys in &rope')
            call suite%check_true(a(2)%key == 'Density' .and. a(2)%name == 'density', &
                'reading: key as written and in lower case')
            call suite%check_true(a(3)%line == 3 .and. a(3)%values(1)%text == '0.01' .and. &
                a(3)%value_text == '0.01', 'reading: a value on the next line')
            call suite%check_true(a(1)%value_text == '2.5', 'reading: value text without comma')
        end associate
        associate (a => f%groups(2)%assignments)
            call suite%check_true(a(1)%values(1)%kind == V_STRING .and. &
                a(1)%values(1)%text == 'it''s', 'reading: string with a doubled quote')
            call suite%check_true(size(a(2)%values) == 3 .and. all([(a(2)%values(stat)%text &
                == '4', stat = 1, 3)]), 'reading: repeat count 3*4')
        end associate
        associate (a => f%groups(3)%assignments)
            call suite%check_true(a(1)%index == 2 .and. a(1)%name == 'x' .and. &
                a(1)%key == 'x(2)', 'reading: key(i)')
            call suite%check_true(size(a(1)%values) == 2 .and. a(1)%values(2)%text == 'b"c', &
                'reading: strings in both quotes')
        end associate
        call parse_ok('&rope /|&model|/', f, 'empty groups')
        call parse_ok('&rope x(1) = 1 x(2) = 2 /', f, 'two elements of one key')
        call parse_ok('&rope x = 2*''ab'' /', f, 'repeat count of a string')
        if (allocated(f%groups)) call suite%check_true(size(f%groups(1)%assignments(1)%values) &
            == 2, 'repeat count of a string: two values')
        call parse_ok(TAB//'&rope'//TAB//'x = 1'//TAB//'/', f, 'tabs are blanks')
    end subroutine test_reading

    subroutine test_values()
        real(wp) :: x
        integer :: n
        logical :: b, ok
        character(len=12), parameter :: REALS(12) = [character(len=12) :: '1', '1.5', '.5', &
            '5.', '-1e-3', '2.5d0', '+3E+2', '+Inf', '-Infinity', 'NaN', '1e400', 'nan']
        character(len=12), parameter :: NOT_REALS(9) = [character(len=12) :: 'abc', '1.2.3', &
            '1e', 'e5', '--1', '.', '1e5.0', '0x10', 'T']
        character(len=12), parameter :: INTS(3) = [character(len=12) :: '30', '-3', '+7']
        character(len=12), parameter :: NOT_INTS(5) = [character(len=12) :: '3.0', '3e1', &
            '99999999999', '2147483648', 'x']
        character(len=8), parameter :: TRUES(4) = [character(len=8) :: '.true.', 'T', '.t.', &
            '.TRUE.']
        character(len=8), parameter :: FALSES(4) = [character(len=8) :: '.false.', 'f', '.F.', &
            '.False.']
        character(len=8), parameter :: NOT_LOGICALS(5) = [character(len=8) :: 'yes', 'true', &
            '2', '.tru.', '1']
        type(nml_value_t), allocatable :: v(:)
        character(len=:), allocatable :: reason
        integer :: k
        do k = 1, size(REALS)
            call value_real(nml_value_t(V_WORD, trim(REALS(k))), x, ok)
            call suite%check_true(ok, 'real: '//trim(REALS(k)))
        end do
        call value_real(nml_value_t(V_WORD, '1e400'), x, ok)
        call suite%check_true(ok .and. x > huge(x), 'real: 1e400 is +Infinity')
        call value_real(nml_value_t(V_WORD, '2.5d0'), x, ok)
        call suite%check_true(abs(x - 2.5_wp) <= 0.0_wp, 'real: 2.5d0 = 2.5')
        do k = 1, size(NOT_REALS)
            call value_real(nml_value_t(V_WORD, trim(NOT_REALS(k))), x, ok)
            call suite%check_true(.not. ok, 'not a real: '//trim(NOT_REALS(k)))
        end do
        call value_real(nml_value_t(V_STRING, '1.0'), x, ok)
        call suite%check_true(.not. ok, 'not a real: a string')
        do k = 1, size(INTS)
            call value_int(nml_value_t(V_WORD, trim(INTS(k))), n, ok)
            call suite%check_true(ok, 'integer: '//trim(INTS(k)))
        end do
        do k = 1, size(NOT_INTS)
            call value_int(nml_value_t(V_WORD, trim(NOT_INTS(k))), n, ok)
            call suite%check_true(.not. ok, 'not an integer: '//trim(NOT_INTS(k)))
        end do
        do k = 1, size(TRUES)
            call value_logical(nml_value_t(V_WORD, trim(TRUES(k))), b, ok)
            call suite%check_true(ok .and. b, 'logical true: '//trim(TRUES(k)))
            call value_logical(nml_value_t(V_WORD, trim(FALSES(k))), b, ok)
            call suite%check_true(ok .and. .not. b, 'logical false: '//trim(FALSES(k)))
        end do
        do k = 1, size(NOT_LOGICALS)
            call value_logical(nml_value_t(V_WORD, trim(NOT_LOGICALS(k))), b, ok)
            call suite%check_true(.not. ok, 'not a logical: '//trim(NOT_LOGICALS(k)))
        end do
        ! the values of --set
        call parse_values('1.0, 2*3', v, reason)
        call suite%check_true(len(reason) == 0 .and. size(v) == 3, '--set values: 1.0, 2*3')
        call parse_values("'a b/c'", v, reason)
        call suite%check_true(len(reason) == 0 .and. v(1)%text == 'a b/c', '--set values: string')
        call parse_values('1,,2', v, reason)
        call suite%check_contains(reason, 'null value', '--set values: 1,,2')
        call parse_values(',1', v, reason)
        call suite%check_contains(reason, 'null value', '--set values: ,1')
        call parse_values("'abc", v, reason)
        call suite%check_contains(reason, 'unbalanced quotes', '--set values: unbalanced')
        call parse_values('0*1', v, reason)
        call suite%check_contains(reason, 'bad repeat count', '--set values: 0*1')
        call parse_values('3*', v, reason)
        call suite%check_contains(reason, 'null value', '--set values: 3*')
        call parse_values('1 = 2', v, reason)
        call suite%check_contains(reason, 'unexpected "="', '--set values: =')
    end subroutine test_values

    !> Reading files: CRLF, no final new line, the size limit, a missing file.
    subroutine test_files()
        type(nml_file_t) :: f
        type(error_t), allocatable :: err
        integer :: unit
        character(len=:), allocatable :: big
        open (newunit=unit, file=DIR//'/crlf.nml', access='stream', form='unformatted', &
              status='replace')
        write (unit) '&rope x = 1'//achar(13)//achar(10)//'/'
        close (unit)
        call read_namelist_file(DIR//'/crlf.nml', GROUPS, f, err)
        call suite%check_true(.not. allocated(err), 'CRLF and no new line at the end')
        if (.not. allocated(err)) call suite%check_true(f%lines == 2 .and. &
            f%groups(1)%assignments(1)%values(1)%text == '1', 'CRLF: two lines, value 1')
        call read_namelist_file(DIR//'/nowhere.nml', GROUPS, f, err)
        call expect(err, [character(len=40) :: 'nowhere.nml: cannot open'], 'missing file')
        call read_namelist_file(DIR, GROUPS, f, err)
        call suite%check_true(allocated(err), 'a directory is an error')
        allocate (character(len=MAX_FILE_BYTES + 10) :: big)
        big(:) = '!'
        open (newunit=unit, file=DIR//'/big.nml', access='stream', form='unformatted', &
              status='replace')
        write (unit) big
        close (unit)
        call read_namelist_file(DIR//'/big.nml', GROUPS, f, err)
        call expect(err, [character(len=40) :: 'big.nml: 1048586 bytes: too large'], &
            'file too large')
        open (newunit=unit, file=DIR//'/empty.nml', status='replace')
        close (unit)
        call read_namelist_file(DIR//'/empty.nml', GROUPS, f, err, required='model', &
            not_what='not a scene file')
        call expect(err, [character(len=80) :: &
            'empty.nml: no &model group (the file is empty): not a scene file'], 'empty file')
    end subroutine test_files

    subroutine expect(err, parts, label)
        type(error_t), allocatable, intent(in) :: err
        character(len=*), intent(in) :: parts(:), label
        integer :: k
        call suite%check_true(allocated(err), label//': an error')
        if (.not. allocated(err)) return
        do k = 1, size(parts)
            call suite%check_contains(err%message, trim(parts(k)), label)
        end do
    end subroutine expect

    subroutine test_errors()
        integer, parameter :: L = 80
        call parse_error('x = 1', [character(len=L) :: &
            'x.nml: line 1: text outside any group: "x = 1"'], 'text outside')
        call parse_error('&rop x = 1 /', [character(len=L) :: &
            'x.nml: &rop: unknown group (line 1', 'groups: rope, model, solver'], 'unknown group')
        call parse_error('&rope /|&ROPE /', [character(len=L) :: &
            'x.nml: &rope: group given twice (lines 1 and 2)'], 'group twice')
        call parse_error('&rope x = 1|&model /', [character(len=L) :: &
            'x.nml: &rope: not closed by "/" before line 2 ("&model /")'], 'not closed')
        call parse_error('&rope x = 1', [character(len=L) :: &
            'x.nml: &rope: not closed by "/" before the end of the file'], 'not closed at end')
        call parse_error('&rope / &model /', [character(len=L) :: &
            'x.nml: line 1: text after the end of &rope'], 'text after /')
        call parse_error('&rope x = 1'//NUL//' /', [character(len=L) :: &
            'x.nml: &rope: cannot read x: control character \x00 at column 12'], 'NUL in a value')
        call parse_error('&rope x = 1 ! a'//achar(7)//'|/', [character(len=L) :: &
            'control character \x07 at column 16 (in a comment)'], 'control character in comment')
        call parse_error('&rope x = ''a'//achar(27)//''' /', [character(len=L) :: &
            'x.nml: &rope: cannot read x: control character \x1b', '(in a string)'], &
            'control character in a string')
        call parse_error('&rope x = ''abc /', [character(len=L) :: &
            'x.nml: &rope: cannot read x: unbalanced quotes', '(line 1:'], 'unbalanced quotes')
        call parse_error('&rope x = /', [character(len=L) :: &
            'x.nml: &rope: x: no value', '(line 1: "&rope x = /")'], 'null value before /')
        call parse_error('&rope x = , y = 2 /', [character(len=L) :: &
            'x.nml: &rope: x: no value'], 'null value before a comma')
        call parse_error('&rope x =|y = 2 /', [character(len=L) :: &
            'x.nml: &rope: x: no value'], 'null value before a key')
        call parse_error('&rope x = 1, , 2 /', [character(len=L) :: &
            'x.nml: &rope: x: null value (two commas in a row)'], 'two commas')
        call parse_error('&rope x = 3* /', [character(len=L) :: &
            'cannot read x = 3*: null value "3*"'], 'r* without a value')
        call parse_error('&rope x = 0*1 /', [character(len=L) :: &
            'cannot read x = 0*1: bad repeat count "0*"'], 'repeat count 0')
        call parse_error('&rope x = 2000*1 /', [character(len=L) :: &
            'more than 1024 values'], 'too many values')
        call parse_error('&rope x = 1|  X = 2 /', [character(len=L) :: &
            'x.nml: &rope: X given twice (line 1: "&rope x = 1", line 2: "  X = 2 /"'], &
            'key twice, other letter case')
        call parse_error('&rope x = 1, 2 x(2) = 3 /', [character(len=L) :: &
            'x.nml: &rope: x(2) given twice'], 'overlapping elements')
        call parse_error('&rope 2.0 /', [character(len=L) :: &
            'x.nml: &rope: line 1: expected key = value, found "2.0"'], 'value without a key')
        call parse_error('&rope x(0) = 1 /', [character(len=L) :: &
            'x.nml: &rope: line 1: x(0): the index must be a whole number >= 1'], 'index 0')
        call parse_error('&rope x(a) = 1 /', [character(len=L) :: &
            'x(a): the index must be a whole number >= 1'], 'index not a number')
        call parse_error('&rope 1x = 1 /', [character(len=L) :: &
            '"1x" is not a key name'], 'not a key name')
        call parse_error('&rope x = 1 (2) /', [character(len=L) :: &
            'cannot read x = 1: unexpected "("'], 'parenthesis in a value')
        call parse_error('&end', [character(len=L) :: 'text outside any group'], &
            '&end outside a group')
        call parse_error('&rope|'//repeat('x = 1|', 1001)//'/', [character(len=L) :: &
            'x.nml: &rope: more than 1000 keys in one group (line 1002)'], 'too many keys')
    end subroutine test_errors
end program test_namelist_file
