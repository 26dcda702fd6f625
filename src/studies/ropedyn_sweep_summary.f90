!> The summary of a sweep, built from whatever case files exist: one row per case with its
!! parameters, status, cost counters, errors against the reference and energy-balance
!! error, written as `<output_dir>/summary.csv` and `<output_dir>/summary.h5`
!! (docs/reference/file-format.md lists the columns).
!!
!! The reference of a row is named (`reference`: the case id; `reference_kind`: how it
!! relates to the row), and when the tightest case of a reference group is not complete,
!! the looser case used instead is a warning in the row and in `warnings` (printed by the
!! caller).
module ropedyn_sweep_summary
    use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, ieee_is_nan
    use ropedyn_kinds, only: wp, i8
    use ropedyn_text, only: int_text, real_text, significant_text, enclosed, text_t, replaced, &
                            append_text
    use ropedyn_error, only: error_t, make_error, ERR_IO
    use ropedyn_os, only: rename_file, delete_file
    use ropedyn_process, only: process_id, host_name
    use ropedyn_sweep, only: sweep_t, sweep_case_t, REF_NONE, &
        REF_TIGHTEST_PER_METHOD, REF_FILE
    use ropedyn_sweep_status, only: case_state_t, case_state
    use ropedyn_case_file, only: case_data_t, read_case_file
    use ropedyn_h5, only: h5_file_t
    use ropedyn_output, only: COUNTER_NAMES
    use ropedyn_version, only: version_string
    implicit none
    private
    public :: case_row_t, build_summary, RUN_WARNING_JOIN

    !> between two of a case's run warnings in its row (a warning holds '; ' itself)
    character(len=*), parameter :: RUN_WARNING_JOIN = ' | '
    !> Columns of summary.h5 measured per case: name and units (docs/reference/file-format.md).
    character(len=*), parameter :: MEASURED(2, 8) = reshape([character(len=18) :: &
        't_reached', 's', 'wall_time', 's', 'cpu_time', 's', 'tip_error_final', 'm', &
        'tip_error_max', 'm', 'position_error_max', 'm', 'energy_error_final', 'J', &
        'energy_error_max', 'J'], [2, 8])

    !> One row of the summary.
    type :: case_row_t
        integer :: id = 0
        character(len=:), allocatable :: status  !< one of STATUS_NAMES (ropedyn_sweep_status)
        character(len=:), allocatable :: reason
        real(wp) :: t_reached, wall_time, cpu_time                     !< s (NaN: absent)
        !> the solver counters named in ropedyn_output's COUNTER_NAMES (-1: absent)
        integer(i8) :: counters(size(COUNTER_NAMES)) = -1
        integer :: reference = 0                 !< case id of the reference (0: none)
        !> tighter | same_rtol | self | file | none (docs/guide/sweeps.md)
        character(len=:), allocatable :: reference_kind
        !> about the reference, and that the counters are partial ('' if none)
        character(len=:), allocatable :: warning
        !> that the counters and CPU time leave out a killed part of the run ('' if not)
        character(len=:), allocatable :: partial
        !> what the case's run warned of (its /solver/warnings), the lines joined by
        !! RUN_WARNING_JOIN ('' if none)
        character(len=:), allocatable :: run_warnings
        real(wp) :: tip_error_final, tip_error_max, position_error_max  !< m
        real(wp) :: energy_error_final, energy_error_max                !< J
    end type case_row_t

contains

    !> Build the rows from the case files and write summary.csv and summary.h5.
    !! `warnings`: one line per reference group whose reference fell back to a looser case.
    subroutine build_summary(sweep, rows, warnings, err)
        type(sweep_t), intent(in) :: sweep
        type(case_row_t), allocatable, intent(out) :: rows(:)
        type(text_t), allocatable, intent(out) :: warnings(:)
        type(error_t), allocatable, intent(out) :: err
        type(case_data_t) :: ref_data
        integer :: c, j, n
        integer, allocatable :: members(:)
        logical, allocatable :: done(:)

        n = size(sweep%cases)
        allocate (rows(n), warnings(0), done(n))
        do c = 1, n
            call read_row(sweep%cases(c), c, rows(c))
        end do
        if (sweep%reference == REF_FILE) then
            call read_case_file(sweep%reference_file, ref_data, err, series=.true.)
            if (allocated(err)) return
            if (.not. ref_data%exists) then
                call make_error(err, ERR_IO, sweep%path//': &sweep: reference = "'// &
                    sweep%reference_file//'": no such file')
                return
            end if
        end if
        ! the reference sets: the cases of one group (and method, per method)
        done = .false.
        do c = 1, n
            if (done(c)) cycle
            members = pack([(j, j=1, n)], [(same_set(sweep, c, j), j=1, n)])
            done(members) = .true.
            select case (sweep%reference)
            case (REF_NONE)
                do j = 1, size(members)
                    if (rows(members(j))%status == 'complete') &
                        rows(members(j))%reference_kind = 'none'
                end do
            case (REF_FILE)
                do j = 1, size(members)
                    associate (m => members(j))
                        if (rows(m)%status /= 'complete') cycle
                        rows(m)%reference_kind = 'file'
                        call compare(sweep, m, ref_data, rows(m), err)
                        if (allocated(err)) return
                    end associate
                end do
            case default
                call against_tightest(sweep, members, rows, warnings, err)
                if (allocated(err)) return
            end select
        end do

        call note_partial(rows, warnings)
        call write_csv(sweep, rows, err)
        if (allocated(err)) return
        call write_h5(sweep, rows, err)
    end subroutine build_summary

    !> The rows whose counters and CPU time leave out a killed part of the run: said in
    !! their warning, and in one line of `warnings` naming them.
    subroutine note_partial(rows, warnings)
        type(case_row_t), intent(inout) :: rows(:)
        type(text_t), allocatable, intent(inout) :: warnings(:)
        integer, allocatable :: partial(:)
        integer :: c
        partial = pack([(c, c=1, size(rows))], [(len(rows(c)%partial) > 0, c=1, size(rows))])
        if (size(partial) == 0) return
        do c = 1, size(partial)
            associate (row => rows(partial(c)))
                if (len(row%warning) > 0) row%warning = row%warning//'; '
                row%warning = row%warning//row%partial
            end associate
        end do
        call append_text(warnings, trim(merge('case ', 'cases', size(partial) == 1))//' '// &
            id_list(partial)//': wall_time (and where a killed part wrote none, the '// &
            'counters and cpu_time) is partial: a part of the run was killed before it '// &
            'wrote it (the warning column of summary.csv says which)')
    end subroutine note_partial

    !> The row of case c from its file as far as it goes: status, times, counters, warnings
    !! and, when complete, the energy errors; NaN where there is nothing to say.
    subroutine read_row(sweep_case, c, row)
        type(sweep_case_t), intent(in) :: sweep_case
        integer, intent(in) :: c
        type(case_row_t), intent(out) :: row
        type(case_state_t) :: state
        real(wp) :: nan
        nan = ieee_value(1.0_wp, ieee_quiet_nan)
        row%id = c
        row%t_reached = nan
        row%wall_time = nan
        row%cpu_time = nan
        row%tip_error_final = nan
        row%tip_error_max = nan
        row%position_error_max = nan
        row%energy_error_final = nan
        row%energy_error_max = nan
        row%reference_kind = ''
        row%warning = ''
        row%partial = ''
        row%run_warnings = ''
        call case_state(sweep_case, state)
        row%status = state%status
        row%reason = state%reason
        if (.not. state%data%exists .or. row%status == 'unreadable' .or. &
            row%status == 'stale') return
        ! interrupted by an abandoned lock: the file is an older run's
        if (row%status == 'interrupted' .and. state%data%status /= 'interrupted' .and. &
            state%data%status /= 'running') return
        row%wall_time = state%data%wall_time
        row%cpu_time = state%data%cpu_time
        row%run_warnings = joined(state%data%warnings)
        row%counters = state%data%counters
        row%partial = partial_text(state%data)
        if (state%data%records > 0) row%t_reached = state%data%time(state%data%records)
        if (row%status == 'complete') call energy_errors(state%data, row)
    end subroutine read_row

    !> '' unless a part of the run in `data` was killed (its wall time lost; its counters
    !! and CPU time too where an earlier version wrote them only at its end): then that,
    !! with where each such part stopped.
    function partial_text(data) result(text)
        type(case_data_t), intent(in) :: data
        character(len=:), allocatable :: text
        integer :: k
        text = ''
        if (.not. allocated(data%killed_at)) return
        if (size(data%killed_at) == 0) return
        do k = 1, size(data%killed_at)
            if (k > 1) text = text//', '
            text = text//significant_text(data%killed_at(k), 10)//' s'
        end do
        if (size(data%killed_at) == 1) then
            text = 'the part of the run that ended at t = '//text//' (its last record) was'
        else
            text = 'the parts of the run that ended at t = '//text//' (their last records) were'
        end if
        if (all(data%killed_counted)) then
            ! (a writer keeps its counters in the file at each flush, with its records)
            text = 'wall_time is partial: '//text//' killed before writing it; steps, the '// &
                'other counters and cpu_time count to its last flush'
        else
            text = 'steps, the other counters, cpu_time and wall_time are partial: '//text// &
                ' killed before writing them'
        end if
    end function partial_text

    !> The complete cases of one reference set against its tightest complete case (ties:
    !! lowest id); a warning, in the rows and in `warnings`, when that is not the set's
    !! tightest case.
    subroutine against_tightest(sweep, members, rows, warnings, err)
        type(sweep_t), intent(in) :: sweep
        integer, intent(in) :: members(:)
        type(case_row_t), intent(inout) :: rows(:)
        type(text_t), allocatable, intent(inout) :: warnings(:)
        type(error_t), allocatable, intent(out) :: err
        type(case_data_t) :: ref_data
        character(len=:), allocatable :: warning
        integer :: j, best, tightest
        tightest = members(1)
        best = 0
        do j = 1, size(members)
            associate (m => members(j))
                if (rtol(sweep, m) < rtol(sweep, tightest)) tightest = m
                if (rows(m)%status /= 'complete') cycle
                if (best == 0) then
                    best = m
                else if (rtol(sweep, m) < rtol(sweep, best)) then
                    best = m
                end if
            end associate
        end do
        if (best == 0) return
        warning = ''
        if (rtol(sweep, best) > rtol(sweep, tightest)) then
            warning = 'reference falls back to case '//int_text(best)//' (rtol '// &
                real_text(rtol(sweep, best), compact=.true.)//'): the tightest case '// &
                int_text(tightest)//' (rtol '//real_text(rtol(sweep, tightest), &
                compact=.true.)//') is not complete ('//rows(tightest)%status//')'
            call append_text(warnings, 'cases '//id_list(members)//': '//warning)
        end if
        call read_case_file(sweep%cases(best)%file, ref_data, err, series=.true.)
        if (allocated(err)) return
        do j = 1, size(members)
            associate (m => members(j))
                if (rows(m)%status /= 'complete') cycle
                rows(m)%warning = warning
                if (m == best) then
                    rows(m)%reference_kind = 'self'
                    cycle
                end if
                rows(m)%reference = best
                rows(m)%reference_kind = 'tighter'
                if (rtol(sweep, best) >= rtol(sweep, m)) rows(m)%reference_kind = 'same_rtol'
                call compare(sweep, m, ref_data, rows(m), err)
                if (allocated(err)) return
            end associate
        end do
    end subroutine against_tightest

    real(wp) function rtol(sweep, k)
        type(sweep_t), intent(in) :: sweep
        integer, intent(in) :: k
        rtol = sweep%cases(k)%scene%solver%rtol
    end function rtol

    !> Whether cases a and b share a reference.
    logical function same_set(sweep, a, b)
        type(sweep_t), intent(in) :: sweep
        integer, intent(in) :: a, b
        same_set = sweep%cases(a)%group == sweep%cases(b)%group
        if (sweep%reference == REF_TIGHTEST_PER_METHOD) same_set = same_set .and. &
            sweep%cases(a)%scene%solver%method == sweep%cases(b)%scene%solver%method
    end function same_set

    !> Position errors of complete case k (its row) against ref_data.
    subroutine compare(sweep, k, ref_data, row, err)
        type(sweep_t), intent(in) :: sweep
        integer, intent(in) :: k
        type(case_data_t), intent(in) :: ref_data
        type(case_row_t), intent(inout) :: row
        type(error_t), allocatable, intent(out) :: err
        type(case_data_t) :: data
        logical :: matched
        call read_case_file(sweep%cases(k)%file, data, err, series=.true.)
        if (allocated(err)) return
        call position_errors(data, ref_data, row, matched)
        if (.not. matched) then
            if (len(row%warning) > 0) row%warning = row%warning//'; '
            row%warning = row%warning//'no position errors: the output times or ' &
                //'the element count differ from the reference''s'
        end if
    end subroutine compare

    !> '1-4' or '1, 3, 5' for a sorted list of ids.
    function id_list(ids) result(text)
        integer, intent(in) :: ids(:)
        character(len=:), allocatable :: text
        integer :: k
        text = int_text(ids(1))
        if (ids(size(ids)) - ids(1) == size(ids) - 1) then
            if (size(ids) > 1) text = text//'-'//int_text(ids(size(ids)))
            return
        end if
        do k = 2, size(ids)
            text = text//', '//int_text(ids(k))
        end do
    end function id_list

    !> |B(t_end) - B(0)| and max |B(t) - B(0)|, B = T + V + dissipated - support work.
    subroutine energy_errors(data, row)
        type(case_data_t), intent(in) :: data
        type(case_row_t), intent(inout) :: row
        if (data%records < 1) return
        row%energy_error_final = abs(data%balance(data%records) - data%balance(1))
        row%energy_error_max = maxval(abs(data%balance - data%balance(1)))
    end subroutine energy_errors

    !> Tip and all-point position errors against a reference with the same output times
    !! (the case's times must be the first times of the reference); NaN otherwise
    !! (`matched` false).
    subroutine position_errors(data, ref, row, matched)
        type(case_data_t), intent(in) :: data, ref
        type(case_row_t), intent(inout) :: row
        logical, intent(out) :: matched
        integer :: m, np, k, j
        real(wp) :: tip, worst
        m = data%records
        np = size(data%points, 2)
        matched = .false.
        if (m < 1 .or. ref%records < m .or. size(ref%points, 2) /= np) return
        if (maxval(abs(data%time - ref%time(:m))) > 1.0e-9_wp*(1.0_wp + abs(data%time(m)))) &
            return
        matched = .true.
        row%tip_error_max = 0.0_wp
        row%position_error_max = 0.0_wp
        do k = 1, m
            tip = norm2(data%points(:, np, k) - ref%points(:, np, k))
            row%tip_error_max = max(row%tip_error_max, tip)
            worst = 0.0_wp
            do j = 1, np
                worst = max(worst, norm2(data%points(:, j, k) - ref%points(:, j, k)))
            end do
            row%position_error_max = max(row%position_error_max, worst)
            if (k == m) row%tip_error_final = tip
        end do
    end subroutine position_errors

    ! ------------------------------------------------------------------------------------
    ! CSV
    ! ------------------------------------------------------------------------------------

    subroutine write_csv(sweep, rows, err)
        type(sweep_t), intent(in) :: sweep
        type(case_row_t), intent(in) :: rows(:)
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: path, line
        character(len=512) :: msg
        integer :: unit, ios, c, v

        path = sweep%output_dir//'/summary.csv'
        msg = ''
        open (newunit=unit, file=aside(path), status='replace', action='write', iostat=ios, &
              iomsg=msg)
        if (ios /= 0) then
            call make_error(err, ERR_IO, path//': cannot write: '//trim(msg))
            return
        end if
        line = 'case,status,model,elements,method,max_order,rtol,atol'
        do v = 1, size(sweep%vary_keys)
            line = line//','//sweep%vary_keys(v)%s
        end do
        line = line//',t_end,t_reached,wall_time,cpu_time'
        do v = 1, size(COUNTER_NAMES)
            line = line//','//trim(COUNTER_NAMES(v))
        end do
        line = line//',reference,reference_kind,tip_error_final,tip_error_max,' &
            //'position_error_max,energy_error_final,energy_error_max,file,reason,warning,' &
            //'run_warnings'
        write (unit, '(a)', iostat=ios, iomsg=msg) line
        do c = 1, size(rows)
            if (ios /= 0) exit
            associate (r => rows(c), s => sweep%cases(c)%scene)
                line = int_text(r%id)//','//r%status//','//csv_text(trim(s%model%kind))// &
                    ','//int_text(s%model%elements)//','//csv_text(trim(s%solver%method))// &
                    ','//int_text(s%solver%max_order)//','// &
                    real_text(s%solver%rtol, compact=.true.)//','// &
                    real_text(s%solver%atol, compact=.true.)
                do v = 1, size(sweep%vary_keys)
                    line = line//','//csv_text(sweep%cases(c)%vary_values(v)%s)
                end do
                line = line//','//real_text(s%solver%t_end, compact=.true.)//','// &
                    num(r%t_reached)//','//num(r%wall_time)//','//num(r%cpu_time)//','
                do v = 1, size(COUNTER_NAMES)
                    line = line//count_text(r%counters(v))//','
                end do
                if (r%reference > 0) line = line//int_text(r%reference)
                line = line//','//r%reference_kind//','//num(r%tip_error_final)//','// &
                    num(r%tip_error_max)//','//num(r%position_error_max)//','// &
                    num(r%energy_error_final)//','//num(r%energy_error_max)//','// &
                    csv_text(sweep%cases(c)%file)//','//csv_text(one_line(r%reason))//','// &
                    csv_text(one_line(r%warning))//','//csv_text(r%run_warnings)
            end associate
            write (unit, '(a)', iostat=ios, iomsg=msg) line
        end do
        if (ios /= 0) call make_error(err, ERR_IO, path//': cannot write: '//trim(msg))
        close (unit)
        call put_in_place(path, err)
    end subroutine write_csv

    !> `dir/.name.<host>.<pid>.part`: where this process writes the summary file `path`
    !! before it renames it into place. Two runners of one sweep (or a runner and
    !! `--summary`) then never write one file at once, and a reader sees a whole file:
    !! the old one or the new one.
    function aside(path) result(temp)
        character(len=*), intent(in) :: path
        character(len=:), allocatable :: temp
        integer :: slash
        slash = index(path, '/', back=.true.)
        temp = path(:slash)//'.'//path(slash + 1:)//'.'//host_name()//'.'// &
            int_text(process_id())//'.part'
    end function aside

    !> The summary file written aside renamed to `path`; when `err` is set, removed instead,
    !! and the error names `path`.
    subroutine put_in_place(path, err)
        character(len=*), intent(in) :: path
        type(error_t), allocatable, intent(inout) :: err
        logical :: removed
        if (.not. allocated(err)) then
            call rename_file(aside(path), path, err)
            if (allocated(err)) removed = delete_file(aside(path))
            return
        end if
        removed = delete_file(aside(path))
        err%message = replaced(err%message, aside(path), path)
    end subroutine put_in_place

    !> A measured or derived real for the table: six significant digits (no noise of the
    !! last binary digits: 0.091687, not 0.09168699999999999); empty when NaN.
    function num(x) result(s)
        real(wp), intent(in) :: x
        character(len=:), allocatable :: s
        if (ieee_is_nan(x)) then
            s = ''
        else
            s = significant_text(x, 6, compact=.true.)
        end if
    end function num

    !> A counter for the table: empty when absent (-1).
    function count_text(n) result(s)
        integer(i8), intent(in) :: n
        character(len=:), allocatable :: s
        character(len=24) :: buf
        if (n < 0) then
            s = ''
        else
            write (buf, '(i0)') n
            s = trim(buf)
        end if
    end function count_text

    !> A CSV field: quoted (quotes doubled) when it holds a comma, quote or newline.
    pure function csv_text(text) result(s)
        character(len=*), intent(in) :: text
        character(len=:), allocatable :: s
        if (scan(text, ',"'//new_line('a')) == 0) then
            s = text
        else
            s = enclosed(text, '"', '""')
        end if
    end function csv_text

    !> The lines joined by RUN_WARNING_JOIN, each on one line; '' for none.
    function joined(lines) result(text)
        type(text_t), allocatable, intent(in) :: lines(:)
        character(len=:), allocatable :: text
        integer :: k
        text = ''
        if (.not. allocated(lines)) return
        do k = 1, size(lines)
            if (k > 1) text = text//RUN_WARNING_JOIN
            text = text//one_line(lines(k)%s)
        end do
    end function joined

    !> Newlines replaced by blanks.
    pure function one_line(text) result(s)
        character(len=*), intent(in) :: text
        character(len=len(text)) :: s
        integer :: i
        s = text
        do i = 1, len(s)
            if (s(i:i) == new_line('a') .or. s(i:i) == achar(13)) s(i:i) = ' '
        end do
    end function one_line

    ! ------------------------------------------------------------------------------------
    ! HDF5: one dataset per column
    ! ------------------------------------------------------------------------------------

    subroutine write_h5(sweep, rows, err)
        type(sweep_t), intent(in) :: sweep
        type(case_row_t), intent(in) :: rows(:)
        type(error_t), allocatable, intent(out) :: err
        type(h5_file_t) :: h5
        type(error_t), allocatable :: close_err

        call h5%create(aside(sweep%output_dir//'/summary.h5'), err)
        if (allocated(err)) then
            call put_in_place(sweep%output_dir//'/summary.h5', err)
            return
        end if
        steps: block
            call write_setting_columns(h5, sweep, rows, err)
            if (allocated(err)) exit steps
            call write_result_columns(h5, sweep, rows, err)
            if (allocated(err)) exit steps
            call h5%attribute('/', 'sweep', sweep%path, err)
            if (allocated(err)) exit steps
            call h5%attribute('/', 'base', sweep%base, err)
            if (allocated(err)) exit steps
            call h5%attribute('/', 'reference', sweep%reference_setting(), err)
            if (allocated(err)) exit steps
            call h5%attribute('/', 'version', version_string, err)
        end block steps
        call h5%close(close_err)
        if (allocated(close_err) .and. .not. allocated(err)) call move_alloc(close_err, err)
        call put_in_place(sweep%output_dir//'/summary.h5', err)
    end subroutine write_h5

    !> The columns of summary.h5 that say what each case is: id, status, model, elements,
    !! method, max_order, rtol, atol, the varied keys, t_end.
    subroutine write_setting_columns(h5, sweep, rows, err)
        type(h5_file_t), intent(inout) :: h5
        type(sweep_t), intent(in) :: sweep
        type(case_row_t), intent(in) :: rows(:)
        type(error_t), allocatable, intent(out) :: err
        integer :: c, k, n
        n = size(rows)
        call h5%write('/case', int([(rows(c)%id, c=1, n)], i8), '1', err)
        if (allocated(err)) return
        call text_column(h5, sweep, rows, 'status', err)
        if (allocated(err)) return
        call text_column(h5, sweep, rows, 'model', err)
        if (allocated(err)) return
        call h5%write('/elements', int([(sweep%cases(c)%scene%model%elements, c=1, n)], &
            i8), '1', err)
        if (allocated(err)) return
        call text_column(h5, sweep, rows, 'method', err)
        if (allocated(err)) return
        call h5%write('/max_order', int([(sweep%cases(c)%scene%solver%max_order, &
            c=1, n)], i8), '1', err)
        if (allocated(err)) return
        call h5%write('/rtol', [(sweep%cases(c)%scene%solver%rtol, c=1, n)], '1', err)
        if (allocated(err)) return
        call h5%write('/atol', [(sweep%cases(c)%scene%solver%atol, c=1, n)], &
            'state units (m, rad, m/s, rad/s)', err)
        if (allocated(err)) return
        do k = 1, size(sweep%vary_keys)
            call text_column(h5, sweep, rows, sweep%vary_keys(k)%s, err, k)
            if (allocated(err)) return
        end do
        call h5%write('/t_end', [(sweep%cases(c)%scene%solver%t_end, c=1, n)], 's', err)
    end subroutine write_setting_columns

    !> The columns of summary.h5 that say how each case went: the measures, the solver's
    !! counters, the reference and the texts.
    subroutine write_result_columns(h5, sweep, rows, err)
        type(h5_file_t), intent(inout) :: h5
        type(sweep_t), intent(in) :: sweep
        type(case_row_t), intent(in) :: rows(:)
        type(error_t), allocatable, intent(out) :: err
        character(len=*), parameter :: TEXTS(5) = [character(len=14) :: 'reference_kind', &
            'file', 'reason', 'warning', 'run_warnings']
        real(wp), allocatable :: measures(:, :)
        integer(i8), allocatable :: counts(:, :)
        integer :: c, k, n
        n = size(rows)
        measures = reshape([rows%t_reached, rows%wall_time, rows%cpu_time, &
                            rows%tip_error_final, rows%tip_error_max, rows%position_error_max, &
                            rows%energy_error_final, rows%energy_error_max], [n, 8])
        counts = transpose(reshape([(rows(c)%counters, c=1, n)], [size(COUNTER_NAMES), n]))
        do k = 1, size(MEASURED, 2)
            call h5%write('/'//trim(MEASURED(1, k)), measures(:, k), trim(MEASURED(2, k)), err)
            if (allocated(err)) return
        end do
        do k = 1, size(COUNTER_NAMES)
            call h5%write('/'//trim(COUNTER_NAMES(k)), counts(:, k), '1', err)
            if (allocated(err)) return
        end do
        call h5%write('/reference', int(rows%reference, i8), '1', err)
        if (allocated(err)) return
        do k = 1, size(TEXTS)
            call text_column(h5, sweep, rows, trim(TEXTS(k)), err)
            if (allocated(err)) return
        end do
    end subroutine write_result_columns

    !> The column `name` of strings (a varied key's with its index `vary`), null-padded to
    !! the longest entry (at least one character).
    subroutine text_column(h5, sweep, rows, name, err, vary)
        type(h5_file_t), intent(inout) :: h5
        type(sweep_t), intent(in) :: sweep
        type(case_row_t), intent(in) :: rows(:)
        character(len=*), intent(in) :: name
        type(error_t), allocatable, intent(out) :: err
        integer, intent(in), optional :: vary
        integer :: width, j, n
        character(len=:), allocatable :: buffer(:), text
        n = size(rows)
        width = 1
        do j = 1, n
            width = max(width, len(cell(sweep, rows, name, j, vary)))
        end do
        allocate (character(len=width) :: buffer(n))
        do j = 1, n
            text = cell(sweep, rows, name, j, vary)
            buffer(j) = text   ! blank-padded; NUL-padded below
            if (len(text) < width) buffer(j)(len(text) + 1:) = repeat(achar(0), width - len(text))
        end do
        call h5%write_text('/'//name, buffer, '', err)
    end subroutine text_column

    !> Case j's entry of the text column `name` (of varied key number `vary`).
    function cell(sweep, rows, name, j, vary) result(value)
        type(sweep_t), intent(in) :: sweep
        type(case_row_t), intent(in) :: rows(:)
        character(len=*), intent(in) :: name
        integer, intent(in) :: j
        integer, intent(in), optional :: vary
        character(len=:), allocatable :: value
        if (present(vary)) then
            value = sweep%cases(j)%vary_values(vary)%s
            return
        end if
        select case (name)
        case ('status')
            value = rows(j)%status
        case ('model')
            value = trim(sweep%cases(j)%scene%model%kind)
        case ('method')
            value = trim(sweep%cases(j)%scene%solver%method)
        case ('file')
            value = sweep%cases(j)%file
        case ('reference_kind')
            value = rows(j)%reference_kind
        case ('warning')
            value = rows(j)%warning
        case ('run_warnings')
            value = rows(j)%run_warnings
        case default
            value = rows(j)%reason
        end select
    end function cell
end module ropedyn_sweep_summary
