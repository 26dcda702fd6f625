!> Sweeps: the cases of a sweep file (read and checked by `ropedyn_sweep_file`, src/io) as
!! the cartesian product of its lists (docs/reference/sweep-file.md).
!!
!! Case ids run from 1 in the order of the cartesian product models > elements > vary(1) >
!! vary(2) ... > methods > max_orders > rtols, the last varying fastest. A list that is not
!! given is one value: whatever the base scene (after `set`) says. Every case is read as a
!! scene (`read_scene`), its method checked against its model and a record it starts from
!! against both, so a bad combination is reported before anything runs, naming the sweep
!! file, the case and its overrides.
module ropedyn_sweep
    use ropedyn_text, only: int_text, real_text, text_t, append_text, text_array, &
        decimal_product
    use ropedyn_error, only: error_t, make_error, ERR_INPUT
    use ropedyn_scene, only: scene_t, read_scene
    use ropedyn_scene_solver, only: create_integrator, check_method_fits
    use ropedyn_integrator, only: integrator_t
    use ropedyn_rope_model, only: rope_model_t
    use ropedyn_model_factory, only: create_model
    use ropedyn_state_start, only: check_state_start
    use ropedyn_kinds, only: wp
    use ropedyn_case_file, only: case_data_t, read_case_file
    use ropedyn_run_inputs, only: check_not_input
    use ropedyn_sweep_file, only: sweep_file_t, read_sweep_file, without_set, MAX_LIST, &
        MAX_VARY, REF_NONE, REF_TIGHTEST, REF_FILE, REF_TIGHTEST_PER_METHOD
    implicit none
    private
    public :: text_t, sweep_case_t, sweep_t, read_sweep, case_name
    public :: MAX_LIST, MAX_VARY, REF_NONE, REF_TIGHTEST, REF_FILE, REF_TIGHTEST_PER_METHOD

    !> One case: its overrides of the base scene and the effective scene they give.
    type :: sweep_case_t
        integer :: id = 0                       !< 1, 2, ... in product order
        type(text_t), allocatable :: overrides(:)  !< the case's own group.key=value (no set)
        type(text_t), allocatable :: vary_values(:) !< value of each `vary` entry
        character(len=:), allocatable :: file   !< <output_dir>/case_<id>.h5
        integer :: group = 0                    !< same model, elements and vary values
        type(scene_t) :: scene                  !< the effective scene of the case
    end type sweep_case_t

    !> A sweep: the checked file (base scene, common overrides, dimensions) and its cases.
    type, extends(sweep_file_t) :: sweep_t
        type(sweep_case_t), allocatable :: cases(:)
        integer :: n_groups = 0                       !< distinct case%group values
    end type sweep_t

contains

    !> Read and check a sweep file and expand its cases.
    !! `output_dir`, when given and not empty, replaces the file's `output_dir`.
    subroutine read_sweep(path, sweep, err, output_dir)
        character(len=*), intent(in) :: path
        type(sweep_t), intent(out) :: sweep
        type(error_t), allocatable, intent(out) :: err
        character(len=*), intent(in), optional :: output_dir
        call read_sweep_file(path, sweep%sweep_file_t, err, output_dir)
        if (allocated(err)) return
        call expand(sweep, err)
        if (allocated(err)) return
        if (sweep%reference == REF_FILE) call check_reference_file(sweep, err)
        if (allocated(err)) return
        call check_outputs(sweep, err)
    end subroutine read_sweep

    !> No case file and no summary file is an input of the sweep: the sweep file, a
    !! reference file, a case's scene, tables or state file (ropedyn_run_inputs).
    subroutine check_outputs(sweep, err)
        type(sweep_t), intent(in) :: sweep
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: extra(:), reference
        character(len=20), parameter :: ROLES(2) = [character(len=20) :: 'the sweep file', &
            'the reference file']
        integer :: c
        reference = ''
        if (sweep%reference == REF_FILE) reference = sweep%reference_file
        allocate (character(len=max(len(sweep%path), len(reference))) :: extra(2))
        extra(1) = sweep%path
        extra(2) = reference
        do c = 1, size(sweep%cases)
            call check_not_input(sweep%cases(c)%file, sweep%cases(c)%scene, err, extra, ROLES, &
                label=sweep%output_dir_origin//': case '//int_text(c)//"'s file "// &
                sweep%cases(c)%file)
            if (allocated(err)) return
        end do
        if (size(sweep%cases) == 0) return
        call check_not_input(sweep%output_dir//'/summary.csv', sweep%cases(1)%scene, err, &
                             extra, ROLES, label=summary_label('summary.csv'))
        if (.not. allocated(err)) call check_not_input(sweep%output_dir//'/summary.h5', &
            sweep%cases(1)%scene, err, extra, ROLES, label=summary_label('summary.h5'))
    contains
        function summary_label(name) result(text)
            character(len=*), intent(in) :: name
            character(len=:), allocatable :: text
            text = sweep%output_dir_origin//': the summary '//sweep%output_dir//'/'//name
        end function summary_label
    end subroutine check_outputs

    !> A reference file serves every case: the same number of elements, and the case's
    !! output times (0, dt, 2 dt, ..., t_end, as the run driver writes them) are its first.
    subroutine check_reference_file(sweep, err)
        type(sweep_t), intent(in) :: sweep
        type(error_t), allocatable, intent(out) :: err
        type(case_data_t) :: ref
        real(wp), allocatable :: times(:)
        real(wp) :: dt, t_end
        integer :: c, k, m, n_out, n_ref
        character(len=:), allocatable :: where

        where = sweep%path//': &sweep: reference = "'//sweep%reference_file//'": '
        call read_case_file(sweep%reference_file, ref, err, series=.true.)
        if (allocated(err)) then
            err%code = ERR_INPUT
            err%message = where//err%message
            return
        end if
        n_ref = size(ref%points, 2)/2
        do c = 1, size(sweep%cases)
            associate (s => sweep%cases(c)%scene)
                if (s%model%elements /= n_ref) then
                    call make_error(err, ERR_INPUT, where//'it has '//int_text(n_ref)// &
                        ' elements, case '//int_text(c)//' ('//join(sweep%cases(c)%overrides) &
                        //') '//int_text(s%model%elements)//': a reference file serves ' &
                        //'cases of its element count only')
                    return
                end if
                dt = s%solver%output_interval
                t_end = s%solver%t_end
                n_out = max(1, ceiling(t_end/dt*(1.0_wp - 1.0e-12_wp)))
                times = [(min(real(k, wp)*dt, t_end), k=0, n_out)]
                times(n_out + 1) = t_end
                ! the times both have first (a coarser output interval ends no earlier)
                m = min(int(ref%records), size(times))
                if (maxval(abs(times(:m) - ref%time(:m))) > 1.0e-9_wp*(1.0_wp + t_end)) then
                    call make_error(err, ERR_INPUT, where//'its output times are not those ' &
                        //'of case '//int_text(c)//' (every '//real_text(dt, compact=.true.)// &
                        ' s up to '//real_text(t_end, compact=.true.)//' s)'//interval_text())
                    return
                end if
                if (ref%records < size(times)) then
                    call make_error(err, ERR_INPUT, where//'it ends at t = '// &
                        real_text(ref%time(ref%records), compact=.true.)//' s, case '// &
                        int_text(c)//' at '//real_text(t_end, compact=.true.)//' s')
                    return
                end if
            end associate
        end do
    contains
        !> '; its records are every DT s' (from its first two; '' with fewer)
        function interval_text() result(text)
            character(len=:), allocatable :: text
            text = ''
            if (ref%records >= 2) text = '; its records are every '// &
                real_text(ref%time(2) - ref%time(1), compact=.true.)//' s'
        end function interval_text
    end subroutine check_reference_file

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

    !> The cartesian product: cases in product order, each read and checked.
    subroutine expand(sweep, err)
        type(sweep_t), intent(inout) :: sweep
        type(error_t), allocatable, intent(out) :: err
        integer :: sizes(size(sweep%dims)), digit(size(sweep%dims)), n_cases, c, i, v, g
        type(text_t), allocatable :: own(:), group_keys(:)
        type(text_t), allocatable :: starts(:)   ! the state starts checked so far
        character(len=:), allocatable :: label, key

        associate (dims => sweep%dims)
            do i = 1, size(dims)
                sizes(i) = max(1, size(dims(i)%values))
            end do
            n_cases = product(sizes)
            allocate (sweep%cases(n_cases), group_keys(0), starts(0))
            digit = 1
            do c = 1, n_cases
                associate (cs => sweep%cases(c))
                    cs%id = c
                    allocate (own(0), cs%vary_values(size(sweep%vary_keys)))
                    v = 0
                    do i = 1, size(dims)
                        if (dims(i)%key(1:min(4, len(dims(i)%key))) == 'vary') then
                            v = v + 1
                            cs%vary_values(v)%s = dims(i)%values(digit(i))%s
                        end if
                        if (len(dims(i)%target) == 0) cycle
                        call append_text(own, dims(i)%target//'='//dims(i)%values(digit(i))%s)
                    end do
                    cs%file = sweep%output_dir//'/'//case_name(c, n_cases)
                    if (len(cs%file) + 6 > len(cs%scene%output%file)) then
                        call make_error(err, ERR_INPUT, sweep%path//': &sweep: output_dir = "' &
                            //sweep%output_dir//'": too long for the case files (at most '// &
                            int_text(len(cs%scene%output%file) - 6 - len(case_name(c, &
                            n_cases)))//' characters)')
                        return
                    end if
                    call move_alloc(own, cs%overrides)
                    label = join(cs%overrides)
                    if (len(label) == 0) label = '(the base scene)'
                    call read_case(sweep, cs, starts, err)
                    if (allocated(err) .and. allocated(sweep%tentative)) then
                        ! the error of the common overrides (or of a value) it has too
                        if (without_set(err%message) == sweep%tentative_reason) then
                            err%message = sweep%tentative%message
                            return
                        end if
                    end if
                    if (allocated(err)) then
                        err%message = sweep%path//': &sweep: case '//int_text(c)//' ('// &
                            label//'): '//without_set(err%message)
                        return
                    end if
                    ! reference group: same model, elements and vary values
                    key = trim(cs%scene%model%kind)//'|'//int_text(cs%scene%model%elements)
                    do i = 1, size(cs%vary_values)
                        key = key//'|'//cs%vary_values(i)%s
                    end do
                    g = 0
                    do i = 1, size(group_keys)
                        if (group_keys(i)%s == key) g = i
                    end do
                    if (g == 0) then
                        call append_text(group_keys, key)
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
        end associate
        sweep%n_groups = size(group_keys)
    end subroutine expand

    !> The effective scene of a case (with atol = atol_per_rtol rtol when given, the
    !! product of the decimals as written: 0.01 and 1e-4 give 1e-6, not the binary
    !! product's 1.0000000000000002e-6, in its overrides, its file and the summary), its
    !! method checked against its model.
    subroutine read_case(sweep, cs, starts, err)
        type(sweep_t), intent(in) :: sweep
        type(sweep_case_t), intent(inout) :: cs
        type(text_t), allocatable, intent(inout) :: starts(:)  !< see check_case_start
        type(error_t), allocatable, intent(out) :: err
        class(rope_model_t), allocatable :: model
        class(integrator_t), allocatable :: integrator
        call read_scene(sweep%base, case_overrides(sweep, cs%overrides, cs%file), cs%scene, err)
        if (allocated(err)) return
        if (sweep%atol_given) then
            call append_text(cs%overrides, 'solver.atol='// &
                real_text(decimal_product(sweep%atol_per_rtol, cs%scene%solver%rtol), &
                compact=.true.))
            call read_scene(sweep%base, case_overrides(sweep, cs%overrides, cs%file), &
                            cs%scene, err)
            if (allocated(err)) return
        end if
        ! the method must fit the case's model, and a record it starts from the case
        ! (bad input before anything runs)
        call create_model(cs%scene%rope_spec_t, model, err)
        if (allocated(err)) return
        call create_integrator(cs%scene, integrator, err)
        if (allocated(err)) return
        call check_method_fits(cs%scene, integrator, model, err)
        if (allocated(err)) return
        call check_case_start(cs%scene, model, starts, err)
    end subroutine read_case

    !> A case that starts from a record of another run (`&initial shape = 'state'`): the
    !! record must fit its model and come before its t_end (`check_state_start`). `starts`
    !! holds the starts checked so far (file, time, model, elements, t_end), so that the
    !! record is read once for the cases that share one (an HDF5 read per case made
    !! `--count` of 1000 such cases 4.4 times as slow).
    subroutine check_case_start(scene, model, starts, err)
        type(scene_t), intent(in) :: scene
        class(rope_model_t), intent(in) :: model   !< the case's
        type(text_t), allocatable, intent(inout) :: starts(:)
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: key
        integer :: k
        if (trim(scene%initial%shape) /= 'state') return
        key = trim(scene%initial%state_file)//'|'//real_text(scene%initial%state_time)// &
              '|'//trim(scene%model%kind)//'|'//int_text(scene%model%elements)//'|'// &
              real_text(scene%solver%t_end)
        do k = 1, size(starts)
            if (starts(k)%s == key) return
        end do
        call check_state_start(scene, model, err)
        if (.not. allocated(err)) call append_text(starts, key)
    end subroutine check_case_start

    !> The overrides of a case for read_scene: set, the case's own, its output file.
    function case_overrides(sweep, own, file) result(arr)
        type(sweep_t), intent(in) :: sweep
        type(text_t), intent(in) :: own(:)
        character(len=*), intent(in) :: file
        character(len=:), allocatable :: arr(:)
        type(text_t), allocatable :: all(:)
        integer :: k
        all = sweep%set
        do k = 1, size(own)
            call append_text(all, own(k)%s)
        end do
        call append_text(all, 'output.file='//file)
        call append_text(all, 'output.progress=.false.')
        arr = text_array(all)
    end function case_overrides

    pure function join(list) result(text)
        type(text_t), intent(in) :: list(:)
        character(len=:), allocatable :: text
        integer :: k
        text = ''
        do k = 1, size(list)
            if (k > 1) text = text//' '
            text = text//list(k)%s
        end do
    end function join
end module ropedyn_sweep
