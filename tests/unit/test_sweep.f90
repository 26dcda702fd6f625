!> Unit test of ropedyn_sweep: expansion of the cartesian product (order, ids, file names,
!! overrides, reference groups, atol_per_rtol, relative base path) and the error messages
!! of bad sweep files. Files are written into test_sweep_tmp/ under the working directory.
program test_sweep
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t, ERR_INPUT
    use ropedyn_sweep, only: sweep_t, read_sweep, case_name
    use ropedyn_text, only: real_text
    use ropedyn_assert, only: test_suite_t
    implicit none

    character(len=*), parameter :: DIR = 'test_sweep_tmp'
    type(test_suite_t) :: suite
    integer :: stat

    suite%name = 'sweep'
    call execute_command_line('mkdir -p '//DIR//'/scenes', exitstat=stat)
    call suite%check_true(stat == 0, 'create '//DIR)
    call write_file(DIR//'/scenes/base.nml', [character(len=60) :: &
        '&model kind = ''rfem'', elements = 8 /', '&solver t_end = 0.1, method = ''cvode'' /'])

    call test_names()
    call test_expansion()
    call test_defaults_and_atol()
    call test_errors()
    call suite%finish()

contains

    subroutine write_file(path, lines)
        character(len=*), intent(in) :: path
        character(len=*), intent(in) :: lines(:)
        integer :: unit, ios, i
        open (newunit=unit, file=path, status='replace', action='write', iostat=ios)
        call suite%check_true(ios == 0, 'write '//path)
        if (ios /= 0) return
        do i = 1, size(lines)
            write (unit, '(a)') trim(lines(i))
        end do
        close (unit)
    end subroutine write_file

    subroutine test_names()
        call suite%check_true(case_name(7, 12) == 'case_0007.h5', 'case_name: 4 digits')
        call suite%check_true(case_name(7, 12345) == 'case_00007.h5', 'case_name: 5 digits')
        call suite%check_true(real_text(1.0e-4_wp, compact=.true.) == '1e-4', 'real_text 1e-4: '// &
                              real_text(1.0e-4_wp, compact=.true.))
        call suite%check_true(real_text(2.5e-7_wp, compact=.true.) == '2.5e-7', 'real_text 2.5e-7')
        call suite%check_true(real_text(0.001_wp, compact=.true.) == '0.001', 'real_text 0.001')
        call suite%check_true(real_text(30.0_wp, compact=.true.) == '30.0', 'real_text 30.0')
        call suite%check_true(real_text(0.1_wp, compact=.true.) == '0.1', 'real_text 0.1')
    end subroutine test_names

    !> 2 elements x 2 vary values x 2 methods x 3 rtols = 24 cases in product order.
    subroutine test_expansion()
        type(sweep_t) :: s
        type(error_t), allocatable :: err
        character(len=*), parameter :: PATH = DIR//'/expand.nml'
        integer :: c
        call write_file(PATH, [character(len=80) :: &
            '! a comment', '&sweep', '    base = ''scenes/base.nml''', &
            '    output_dir = ''out/x/''', '    elements = 4, 6', &
            '    methods = ''cvode'', ''MEBDF''', '    rtols = 1e-3, 1e-5, 1e-4', &
            '    vary = ''rope.normal_damping = 1e3; 0.1''', &
            '    set = ''solver.output_interval=0.05''', '/'])
        call read_sweep(PATH, s, err)
        call suite%check_true(.not. allocated(err), 'expand: no error')
        if (allocated(err)) then
            write (*, '(a)') err%message
            return
        end if
        call suite%check_true(s%base == DIR//'/scenes/base.nml', 'expand: base relative to ' &
                              //'the sweep file: '//s%base)
        call suite%check_true(s%output_dir == 'out/x', 'expand: output_dir without /')
        call suite%check_true(size(s%cases) == 24, 'expand: 24 cases')
        do c = 1, size(s%cases)
            call suite%check_true(s%cases(c)%id == c, 'expand: ids are 1..24')
        end do
        ! case 1: first value of every list
        call suite%check_true(size(s%cases(1)%overrides) == 4, 'expand: 4 overrides')
        call suite%check_true(s%cases(1)%overrides(1)%s == 'model.elements=4' .and. &
            s%cases(1)%overrides(2)%s == 'rope.normal_damping=1e3' .and. &
            s%cases(1)%overrides(3)%s == 'solver.method=cvode' .and. &
            s%cases(1)%overrides(4)%s == 'solver.rtol=0.001', 'expand: overrides of case 1 '// &
            'in order elements, vary, methods, rtols')
        ! rtols vary fastest, then methods, then vary, then elements
        call suite%check_true(abs(s%cases(2)%scene%solver%rtol - 1.0e-5_wp) < 1.0e-20_wp, &
                              'expand: case 2 has the second rtol')
        call suite%check_true(s%cases(4)%scene%solver%method == 'mebdf', &
                              'expand: case 4 is the second method (lower case)')
        call suite%check_true(abs(s%cases(7)%scene%rope%normal_damping - 0.1_wp) < 1.0e-12_wp, &
                              'expand: case 7 has the second vary value')
        call suite%check_true(abs(s%cases(7)%scene%rope%tangential_damping - 0.04_wp) < &
                              1.0e-12_wp, 'expand: derived default follows the vary value')
        call suite%check_true(s%cases(13)%scene%model%elements == 6, &
                              'expand: case 13 has the second element count')
        call suite%check_true(s%cases(24)%file == 'out/x/case_0024.h5', 'expand: file name')
        call suite%check_true(s%cases(24)%scene%output%file == 'out/x/case_0024.h5', &
                              'expand: the scene writes the case file')
        call suite%check_true(abs(s%cases(24)%scene%solver%output_interval - 0.05_wp) < &
                              1.0e-15_wp, 'expand: set applies to every case')
        call suite%check_true(abs(s%cases(24)%scene%solver%t_end - 0.1_wp) < 1.0e-15_wp, &
                              'expand: base scene values kept')
        call suite%check_true(s%cases(1)%scene%solver%max_order == 5 .and. &
                              s%cases(4)%scene%solver%max_order == 4, &
                              'expand: max_order resolved per method')
        ! reference groups: elements x vary values = 4 groups of 6 cases
        call suite%check_true(s%n_groups == 4, 'expand: 4 reference groups')
        call suite%check_true(all(s%cases(1:6)%group == 1) .and. all(s%cases(7:12)%group == 2) &
            .and. all(s%cases(19:24)%group == 4), 'expand: groups are contiguous')
        call suite%check_true(size(s%vary_keys) == 1, 'expand: one vary key')
        call suite%check_true(s%vary_keys(1)%s == 'rope.normal_damping', 'expand: vary key')
        call suite%check_true(s%cases(8)%vary_values(1)%s == '0.1', 'expand: vary value text')

        ! --output-dir replaces output_dir
        call read_sweep(PATH, s, err, output_dir='elsewhere')
        call suite%check_true(.not. allocated(err), 'output_dir override: no error')
        if (.not. allocated(err)) call suite%check_true(s%cases(3)%file == &
            'elsewhere/case_0003.h5', 'output_dir override: file')
    end subroutine test_expansion

    subroutine test_defaults_and_atol()
        type(sweep_t) :: s
        type(error_t), allocatable :: err
        character(len=*), parameter :: PATH = DIR//'/only_base.nml'
        call write_file(PATH, [character(len=80) :: '&sweep base = ''scenes/base.nml'' /'])
        call read_sweep(PATH, s, err)
        call suite%check_true(.not. allocated(err), 'only base: no error')
        if (allocated(err)) return
        call suite%check_true(size(s%cases) == 1, 'only base: one case')
        call suite%check_true(size(s%cases(1)%overrides) == 0, 'only base: no overrides')
        call suite%check_true(s%output_dir == 'out/sweep_only_base', 'only base: default ' &
                              //'output_dir: '//s%output_dir)
        call suite%check_true(s%cases(1)%scene%model%elements == 8, 'only base: base scene')

        call write_file(PATH, [character(len=80) :: '&sweep base = ''scenes/base.nml''', &
            '  rtols = 1e-4, 1e-6  atol_per_rtol = 0.01 /'])
        call read_sweep(PATH, s, err)
        call suite%check_true(.not. allocated(err), 'atol_per_rtol: no error')
        if (allocated(err)) return
        ! 0.01*1e-4 in binary is 1.0000000000000002e-6: the case's atol is the 1e-6 the
        ! user would have written, in its overrides (--list, the worker's --set) and scene
        associate (c1 => s%cases(1), c2 => s%cases(2))
            call suite%check_true(c1%overrides(size(c1%overrides))%s == 'solver.atol=1e-6', &
                                  'atol_per_rtol: case 1 override: '// &
                                  c1%overrides(size(c1%overrides))%s)
            call suite%check_true(c1%scene%solver%atol == 1.0e-6_wp, &
                                  'atol_per_rtol: case 1 atol: '// &
                                  real_text(c1%scene%solver%atol))
            call suite%check_true(c2%overrides(size(c2%overrides))%s == 'solver.atol=1e-8', &
                                  'atol_per_rtol: case 2 override: '// &
                                  c2%overrides(size(c2%overrides))%s)
            call suite%check_true(c2%scene%solver%atol == 1.0e-8_wp, &
                                  'atol_per_rtol: case 2 atol: '// &
                                  real_text(c2%scene%solver%atol))
        end associate
    end subroutine test_defaults_and_atol

    !> A bad sweep file: one message naming the file, the key and the value.
    subroutine check_error(name, body, fragments)
        character(len=*), intent(in) :: name
        character(len=*), intent(in) :: body(:)
        character(len=*), intent(in) :: fragments(:)
        type(sweep_t) :: s
        type(error_t), allocatable :: err
        character(len=:), allocatable :: path
        integer :: k
        path = DIR//'/'//name//'.nml'
        call write_file(path, body)
        call read_sweep(path, s, err)
        call suite%check_true(allocated(err), name//': error reported')
        if (.not. allocated(err)) return
        call suite%check_true(err%code == ERR_INPUT, name//': class ERR_INPUT')
        call suite%check_contains(err%message, path, name//': names the file')
        do k = 1, size(fragments)
            call suite%check_contains(err%message, trim(fragments(k)), name//': says '// &
                                      trim(fragments(k)))
        end do
    end subroutine check_error

    subroutine test_errors()
        character(len=*), parameter :: B = '&sweep base = ''scenes/base.nml'''
        call check_error('no_group', [character(len=40) :: '&model /'], &
                         [character(len=20) :: 'expected the &sweep'])
        call check_error('no_base', [character(len=40) :: '&sweep elements = 3 /'], &
                         [character(len=20) :: 'base: missing'])
        call check_error('missing_base', [character(len=60) :: &
            '&sweep base = ''nowhere.nml'' /'], [character(len=20) :: 'nowhere.nml', &
            'cannot open'])
        call check_error('elements', [character(len=60) :: B//' elements = 10, 1 /'], &
                         [character(len=20) :: 'elements(2) = 1', '>= 2'])
        call check_error('gap', [character(len=60) :: B//' elements(1) = 10,', &
            ' elements(3) = 5 /'], [character(len=20) :: 'elements(3) = 5', 'gaps'])
        call check_error('method', [character(len=60) :: B//' methods = ''rk4'' /'], &
                         [character(len=20) :: 'methods(1)', 'rk4', 'allowed'])
        call check_error('model', [character(len=60) :: B//' models = ''fem'' /'], &
                         [character(len=20) :: 'models(1)', 'fem', 'allowed: rfem'])
        call check_error('rtol', [character(len=60) :: B//' rtols = 1e-3, 2.0 /'], &
                         [character(len=20) :: 'rtols(2) = 2.0', '< 1'])
        call check_error('max_order', [character(len=60) :: B//' max_orders = 7 /'], &
                         [character(len=20) :: 'case 1', 'max_order = 7', 'cvode'])
        call check_error('unknown_key', [character(len=60) :: B, ' elemnts = 3 /'], &
                         [character(len=20) :: 'line 2', 'elemnts'])
        call check_error('set_key', [character(len=60) :: B//' set = ''rope.lenght=2'' /'], &
                         [character(len=20) :: 'set', 'lenght', 'length'])
        call check_error('set_conflict', [character(len=70) :: B//' elements = 3', &
            ' set = ''model.elements=5'' /'], [character(len=30) :: 'set(1)', &
            'already set by elements'])
        call check_error('set_output', [character(len=70) :: B//' set = ''output.file=x'' /'], &
                         [character(len=20) :: 'output.file', 'output_dir'])
        call check_error('vary_value', [character(len=70) :: B//' vary = ''rope.length = ' &
            //'1; -2'' /'], [character(len=20) :: 'vary(1)', 'value 2', 'length', '> 0'])
        call check_error('vary_form', [character(len=70) :: B//' vary = ''rope.length'' /'], &
                         [character(len=30) :: 'vary(1)', 'group.key = value1'])
        call check_error('vary_empty', [character(len=70) :: B//' vary = ''rope.length = ' &
            //'1;;2'' /'], [character(len=20) :: 'vary(1)', 'empty value'])
        call check_error('text_after', [character(len=70) :: B//' /', '&model /'], &
                         [character(len=30) :: 'line 2', 'after the &sweep'])
        call check_error('not_closed', [character(len=70) :: B], &
                         [character(len=30) :: 'not closed'])
    end subroutine test_errors
end program test_sweep
