!> Unit test of the scene key table (ropedyn_scene_keys): every key reads a value other than
!! its default from a file and from --set, echoes it, and the echo reads back to the same
!! value; every key is in the listing of `ropedyn keys` with the default of a fresh scene_t;
!! the echo of the defaults lists every key. Files go to test_scene_keys_tmp/.
program test_scene_keys
    use, intrinsic :: ieee_arithmetic, only: ieee_is_nan
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t
    use ropedyn_text, only: text_t, int_text, real_text, append_text
    use ropedyn_scene, only: scene_t, read_scene, scene_namelist_text, scene_key_listing
    use ropedyn_scene_key, only: scene_key_t, T_REAL, T_INT, T_LOGICAL, T_NAME, T_PATH, &
        T_PAIR, T_LIST, R_UNIT
    use ropedyn_scene_keys, only: bind_keys, GROUP_NAMES
    use ropedyn_assert, only: test_suite_t
    implicit none

    character(len=*), parameter :: DIR = 'test_scene_keys_tmp'
    type(test_suite_t) :: suite
    type(scene_t), target :: defaults
    type(scene_key_t), allocatable :: keys(:)
    integer :: stat, k

    suite%name = 'scene_keys'
    call execute_command_line('mkdir -p '//DIR, exitstat=stat)
    call suite%check_true(stat == 0, 'create '//DIR)
    call bind_keys(defaults, keys)
    call suite%check_true(size(keys) == 104, 'the table has 104 keys: '//int_text(size(keys)))
    do k = 1, size(keys)
        call round_trip(keys(k))
    end do
    call test_listing()
    call test_control_character()
    call suite%finish()

contains

    subroutine write_file(path, text)
        character(len=*), intent(in) :: path, text
        integer :: unit
        open (newunit=unit, file=path, status='replace', action='write')
        write (unit, '(a)') text
        close (unit)
    end subroutine write_file

    !> Candidate values other than the default, as written in a file, and what else the
    !! scene needs for them (another key of the same group).
    subroutine candidates(key, values, extra)
        type(scene_key_t), intent(in) :: key
        type(text_t), allocatable, intent(out) :: values(:)
        character(len=:), allocatable, intent(out) :: extra
        character(len=:), allocatable :: names
        integer :: comma
        extra = ''
        allocate (values(0))
        select case (key%type)
        case (T_REAL)
            ! a key of the section set of &rope needs its two required keys
            select case (key%name)
            case ('mass_per_length')
                extra = 'axial_stiffness = 1000.0'
            case ('axial_stiffness')
                extra = 'mass_per_length = 0.1'
            case ('bending_stiffness', 'shear_stiffness', 'axial_damping', 'shear_damping', &
                  'bending_damping')
                extra = 'mass_per_length = 0.1, axial_stiffness = 1000.0'
            ! a clamp angle needs a clamped end
            case ('top_angle_deg')
                extra = "top = 'clamped'"
            case ('bottom_angle_deg')
                extra = "bottom = 'clamped'"
            end select
            if (ieee_is_nan(key%r)) then
                ! not set by default: any value of its rule
                call append_text(values, '0.25')
            else if (key%rule == R_UNIT) then
                call append_text(values, real_text(key%r/2.0_wp))
            else
                call append_text(values, real_text(key%r*1.5_wp + 0.25_wp))
            end if
        case (T_INT)
            call append_text(values, int_text(key%i + 1))
            ! max_order 1 is for cvode and adams (auto's range starts at 2)
            if (key%name == 'max_order') extra = "method = 'cvode'"
        case (T_LOGICAL)
            call append_text(values, trim(merge('.false.', '.true. ', key%l)))
            if (key%name == 'stability_limit_detection') extra = "method = 'cvode'"
        case (T_NAME)
            if (key%name == 'top_motion') extra = 'top_frequency = 2.0'
            if (key%name == 'bottom_motion') extra = "bottom = 'pinned', bottom_frequency = 2.0"
            names = key%allowed//','
            do
                comma = index(names, ',')
                if (comma == 0) exit
                if (names(:comma - 1) /= trim(key%s)) &
                    call append_text(values, "'"//names(:comma - 1)//"'")
                names = adjustl(names(comma + 1:))
            end do
        case (T_PATH)
            call append_text(values, "'out/keys test.h5'")
        case (T_PAIR)
            call append_text(values, '0.5, -0.25')
            ! an anchor needs an end that is held
            if (key%name == 'bottom_anchor') extra = "bottom = 'pinned'"
        case (T_LIST)
            call append_text(values, '0.5, 0.25')
            if (key%name == 'masses') extra = 'mass_positions = 0.1, 0.2'
            if (key%name == 'mass_positions') extra = 'masses = 1.0, 2.0'
            if (key%name(1:5) == 'load_' .and. key%name /= 'load_positions') &
                extra = 'load_positions = 0.1, 0.2'
        end select
    end subroutine candidates

    !> One key: some candidate reads (from a file and from --set), echoes, and re-reads.
    subroutine round_trip(key)
        type(scene_key_t), intent(in) :: key
        type(text_t), allocatable :: values(:)
        character(len=:), allocatable :: extra, group, path, echo, line, set_value, model
        type(scene_t), target :: a, b, c
        type(scene_key_t), allocatable :: ka(:)
        type(error_t), allocatable :: err
        character(len=200) :: arg(1)
        integer :: i, j
        logical :: done
        call candidates(key, values, extra)
        group = trim(GROUP_NAMES(key%group))
        path = DIR//'/'//key%name//'_'//group//'.nml'
        model = '&model /'//new_line('a')
        if (group == 'model') model = ''
        done = .false.
        do i = 1, size(values)
            call write_file(path, model//'&'//group//' '//key%name// &
                ' = '//values(i)%s//' '//extra//' /')
            call read_scene(path, [character(len=1) ::], a, err)
            if (allocated(err)) cycle
            done = .true.
            exit
        end do
        call suite%check_true(done, group//'.'//key%name//': a value other than the default '// &
            'reads')
        if (.not. done) return
        echo = scene_namelist_text(a)
        call bind_keys(a, ka)
        do j = 1, size(ka)
            if (ka(j)%group == key%group .and. ka(j)%name == key%name) exit
        end do
        line = ka(j)%echo()
        call suite%check_true(len(line) > 0 .and. index(echo, line) > 0, group//'.'// &
            key%name//': in the echo as '//line(:max(0, len(line) - 1)))
        call suite%check_true(ka(j)%value_text() /= key%value_text() .or. key%type == T_PATH, &
            group//'.'//key%name//': the value changed from the default')
        call write_file(path, echo)
        call read_scene(path, [character(len=1) ::], b, err)
        call suite%check_true(.not. allocated(err), group//'.'//key%name//': the echo reads')
        if (allocated(err)) return
        call suite%check_true(scene_namelist_text(b) == echo, group//'.'//key%name// &
            ': the echo reads back to the same scene')
        ! the same value by --set (strings without quotes)
        set_value = values(i)%s
        if (set_value(1:1) == "'") set_value = set_value(2:len(set_value) - 1)
        call write_file(path, model//'&'//group//' '//extra//' /')
        arg(1) = group//'.'//key%name//'='//set_value
        call read_scene(path, arg, c, err)
        call suite%check_true(.not. allocated(err), group//'.'//key%name//': reads by --set')
        if (.not. allocated(err)) call suite%check_true(scene_namelist_text(c) == echo, &
            group//'.'//key%name//': --set gives the same scene as the file')
    end subroutine round_trip

    !> A control character in a --set value (a new line in a file name would break the
    !! echo) is an error.
    subroutine test_control_character()
        type(scene_t) :: s
        type(error_t), allocatable :: err
        character(len=40) :: arg(1)
        call write_file(DIR//'/model.nml', '&model /')
        arg(1) = 'output.file=a'//new_line('a')//'b.h5'
        call read_scene(DIR//'/model.nml', arg, s, err)
        call suite%check_true(allocated(err), '--set with a new line: an error')
        if (allocated(err)) call suite%check_true(index(err%message, &
            '--set output.file=a\x0ab.h5: a control character') == 1, err%message)
    end subroutine test_control_character

    !> `ropedyn keys` lists every key once with the default of a fresh scene.
    subroutine test_listing()
        type(text_t), allocatable :: lines(:)
        character(len=:), allocatable :: expected, echo
        integer :: k, n, i
        character(len=1), parameter :: TAB = achar(9)
        lines = scene_key_listing()
        call suite%check_true(size(lines) == size(keys) + 1, 'listing: a header and one line '// &
            'per key')
        echo = scene_namelist_text(defaults)
        do k = 1, size(keys)
            expected = trim(GROUP_NAMES(keys(k)%group))//TAB//keys(k)%name//TAB
            n = 0
            do i = 2, size(lines)
                if (index(lines(i)%s, expected) == 1) n = n + 1
            end do
            call suite%check_true(n == 1, 'listing: '//keys(k)%name//' once')
            ! a key whose default is "not set" (progress) echoes as a comment
            if (keys(k)%type /= T_LIST) call suite%check_true(index(echo, '    '// &
                keys(k)%name//' = ') > 0 .or. index(echo, '    ! '//keys(k)%name//' = ') > 0, &
                'echo of the defaults: '//keys(k)%name)
        end do
    end subroutine test_listing
end program test_scene_keys
