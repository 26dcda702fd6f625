!> The summary of a sweep, built from whatever case files exist: one row per case with its
!! parameters, status, cost counters, errors against the reference and energy-balance
!! error, written as `<output_dir>/summary.csv` and `<output_dir>/summary.h5`
!! (docs/sweeps.md lists the columns).
module ropedyn_sweep_summary
    use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, ieee_is_nan
    use ropedyn_kinds, only: wp, i8
    use ropedyn_text, only: int_text, real_text, enclosed
    use ropedyn_error, only: error_t, make_error, ERR_IO
    use ropedyn_scene, only: scene_namelist_text
    use ropedyn_sweep, only: sweep_t, sweep_case_t, REF_NONE, &
        REF_TIGHTEST, REF_FILE
    use ropedyn_case_file, only: case_data_t, read_case_file
    use ropedyn_h5, only: h5_file_t
    use ropedyn_output, only: COUNTER_NAMES
    use ropedyn_version, only: version_string
    implicit none
    private
    public :: case_row_t, case_status, build_summary

    !> Columns of summary.h5 measured per case: name and units (docs/sweeps.md).
    character(len=*), parameter :: MEASURED(2, 8) = reshape([character(len=18) :: &
        't_reached', 's', 'wall_time', 's', 'cpu_time', 's', 'tip_error_final', 'm', &
        'tip_error_max', 'm', 'position_error_max', 'm', 'energy_error_final', 'J', &
        'energy_error_max', 'J'], [2, 8])

    !> One row of the summary.
    type :: case_row_t
        integer :: id = 0
        character(len=:), allocatable :: status  !< complete|failed|running|stale|missing
        character(len=:), allocatable :: reason
        real(wp) :: t_reached, wall_time, cpu_time                     !< s (NaN: absent)
        !> the solver counters named in ropedyn_output's COUNTER_NAMES (-1: absent)
        integer(i8) :: counters(size(COUNTER_NAMES)) = -1
        integer :: reference = 0                 !< case id of the reference (0: none)
        real(wp) :: tip_error_final, tip_error_max, position_error_max  !< m
        real(wp) :: energy_error_final, energy_error_max                !< J
    end type case_row_t

contains

    !> Status of a case from its file: 'missing' (no file), 'stale' (a file of another
    !! scene: the sweep changed), else the file's status (complete, failed, running).
    subroutine case_status(c, status, reason, err, data, series)
        type(sweep_case_t), intent(in) :: c
        character(len=:), allocatable, intent(out) :: status, reason
        type(error_t), allocatable, intent(out) :: err
        type(case_data_t), intent(out), optional :: data
        logical, intent(in), optional :: series
        type(case_data_t) :: d
        reason = ''
        call read_case_file(c%file, d, err, series)
        if (allocated(err)) then
            status = 'unreadable'
            reason = err%message
        else if (.not. d%exists) then
            status = 'missing'
        else if (d%scene /= scene_namelist_text(c%scene)) then
            status = 'stale'
            reason = 'the file holds another scene than this case (the sweep changed); ' &
                //'run the sweep again'
        else
            status = d%status
            if (status == 'failed') reason = d%reason
            if (status == 'running') reason = 'the run did not finish (crashed, killed or ' &
                //'still running)'
        end if
        if (present(data)) data = d
    end subroutine case_status

    !> Build the rows from the case files and write summary.csv and summary.h5.
    subroutine build_summary(sweep, rows, err)
        type(sweep_t), intent(in) :: sweep
        type(case_row_t), allocatable, intent(out) :: rows(:)
        type(error_t), allocatable, intent(out) :: err
        type(case_data_t) :: data, ref_data
        type(error_t), allocatable :: case_err
        real(wp) :: nan
        integer :: c, g, best
        logical :: have_file_ref

        nan = ieee_value(1.0_wp, ieee_quiet_nan)
        allocate (rows(size(sweep%cases)))
        do c = 1, size(sweep%cases)
            rows(c)%id = c
            rows(c)%t_reached = nan
            rows(c)%wall_time = nan
            rows(c)%cpu_time = nan
            rows(c)%tip_error_final = nan
            rows(c)%tip_error_max = nan
            rows(c)%position_error_max = nan
            rows(c)%energy_error_final = nan
            rows(c)%energy_error_max = nan
            call case_status(sweep%cases(c), rows(c)%status, rows(c)%reason, case_err, data)
            if (rows(c)%status == 'missing' .or. rows(c)%status == 'unreadable' .or. &
                rows(c)%status == 'stale') cycle
            rows(c)%wall_time = data%wall_time
            rows(c)%cpu_time = data%cpu_time
            rows(c)%counters = data%counters
            if (data%records > 0) rows(c)%t_reached = data%time(data%records)
        end do

        ! errors against the reference
        have_file_ref = .false.
        if (sweep%reference == REF_FILE) then
            call read_case_file(sweep%reference_file, ref_data, err, series=.true.)
            if (allocated(err)) return
            if (.not. ref_data%exists) then
                call make_error(err, ERR_IO, sweep%path//': &sweep: reference = "'// &
                    sweep%reference_file//'": no such file')
                return
            end if
            have_file_ref = .true.
        end if
        do g = 1, sweep%n_groups
            best = 0
            if (sweep%reference == REF_TIGHTEST) then
                do c = 1, size(sweep%cases)
                    if (sweep%cases(c)%group /= g .or. rows(c)%status /= 'complete') cycle
                    if (best == 0) then
                        best = c
                    else if (sweep%cases(c)%scene%solver%rtol < &
                             sweep%cases(best)%scene%solver%rtol) then
                        best = c
                    end if
                end do
                if (best == 0) cycle
                call read_case_file(sweep%cases(best)%file, ref_data, err, series=.true.)
                if (allocated(err)) return
            else if (.not. have_file_ref) then
                cycle
            end if
            do c = 1, size(sweep%cases)
                if (sweep%cases(c)%group /= g .or. rows(c)%status /= 'complete') cycle
                call read_case_file(sweep%cases(c)%file, data, err, series=.true.)
                if (allocated(err)) return
                call energy_errors(data, rows(c))
                if (c == best) cycle
                rows(c)%reference = best
                call position_errors(data, ref_data, rows(c))
            end do
        end do
        ! energy errors of complete cases that had no reference group pass
        if (sweep%reference == REF_NONE) then
            do c = 1, size(sweep%cases)
                if (rows(c)%status /= 'complete') cycle
                call read_case_file(sweep%cases(c)%file, data, err, series=.true.)
                if (allocated(err)) return
                call energy_errors(data, rows(c))
            end do
        end if

        call write_csv(sweep, rows, err)
        if (allocated(err)) return
        call write_h5(sweep, rows, err)
    end subroutine build_summary

    !> |B(t_end) - B(0)| and max |B(t) - B(0)|, B = T + V + dissipated - support work.
    subroutine energy_errors(data, row)
        type(case_data_t), intent(in) :: data
        type(case_row_t), intent(inout) :: row
        if (data%records < 1) return
        row%energy_error_final = abs(data%balance(data%records) - data%balance(1))
        row%energy_error_max = maxval(abs(data%balance - data%balance(1)))
    end subroutine energy_errors

    !> Tip and all-point position errors against a reference with the same output times
    !! (the case's times must be the first times of the reference); NaN otherwise.
    subroutine position_errors(data, ref, row)
        type(case_data_t), intent(in) :: data, ref
        type(case_row_t), intent(inout) :: row
        integer :: m, np, k, j
        real(wp) :: tip, worst
        m = data%records
        np = size(data%points, 2)
        if (m < 1 .or. ref%records < m .or. size(ref%points, 2) /= np) return
        if (maxval(abs(data%time - ref%time(:m))) > 1.0e-9_wp*(1.0_wp + abs(data%time(m)))) &
            return
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
        open (newunit=unit, file=path, status='replace', action='write', iostat=ios, iomsg=msg)
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
        line = line//',reference,tip_error_final,tip_error_max,position_error_max,' &
            //'energy_error_final,energy_error_max,file,reason'
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
                line = line//','//num(r%tip_error_final)//','//num(r%tip_error_max)//','// &
                    num(r%position_error_max)//','//num(r%energy_error_final)//','// &
                    num(r%energy_error_max)//','//csv_text(sweep%cases(c)%file)//','// &
                    csv_text(one_line(r%reason))
            end associate
            write (unit, '(a)', iostat=ios, iomsg=msg) line
        end do
        if (ios /= 0) call make_error(err, ERR_IO, path//': cannot write: '//trim(msg))
        close (unit)
    end subroutine write_csv

    !> A real for the table: empty when NaN.
    function num(x) result(s)
        real(wp), intent(in) :: x
        character(len=:), allocatable :: s
        if (ieee_is_nan(x)) then
            s = ''
        else
            s = real_text(x, compact=.true.)
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
        character(len=:), allocatable :: path
        type(h5_file_t) :: h5
        type(error_t), allocatable :: close_err
        integer :: n, c, k
        real(wp), allocatable :: measures(:, :)
        integer(i8), allocatable :: counts(:, :)

        path = sweep%output_dir//'/summary.h5'
        n = size(rows)
        measures = reshape([rows%t_reached, rows%wall_time, rows%cpu_time, &
                            rows%tip_error_final, rows%tip_error_max, rows%position_error_max, &
                            rows%energy_error_final, rows%energy_error_max], [n, 8])
        counts = transpose(reshape([(rows(c)%counters, c=1, n)], [size(COUNTER_NAMES), n]))
        call h5%create(path, err)
        if (allocated(err)) return
        steps: block
            call h5%write('/case', int([(rows(c)%id, c=1, n)], i8), '1', err)
            if (allocated(err)) exit steps
            call text_column('status')
            if (allocated(err)) exit steps
            call text_column('model')
            if (allocated(err)) exit steps
            call h5%write('/elements', int([(sweep%cases(c)%scene%model%elements, c=1, n)], &
                i8), '1', err)
            if (allocated(err)) exit steps
            call text_column('method')
            if (allocated(err)) exit steps
            call h5%write('/max_order', int([(sweep%cases(c)%scene%solver%max_order, &
                c=1, n)], i8), '1', err)
            if (allocated(err)) exit steps
            call h5%write('/rtol', [(sweep%cases(c)%scene%solver%rtol, c=1, n)], '1', err)
            if (allocated(err)) exit steps
            call h5%write('/atol', [(sweep%cases(c)%scene%solver%atol, c=1, n)], &
                'state units (m, rad, m/s, rad/s)', err)
            if (allocated(err)) exit steps
            do k = 1, size(sweep%vary_keys)
                call text_column(sweep%vary_keys(k)%s, k)
                if (allocated(err)) exit steps
            end do
            call h5%write('/t_end', [(sweep%cases(c)%scene%solver%t_end, c=1, n)], 's', err)
            if (allocated(err)) exit steps
            do k = 1, size(MEASURED, 2)
                call h5%write('/'//trim(MEASURED(1, k)), measures(:, k), trim(MEASURED(2, k)), &
                              err)
                if (allocated(err)) exit steps
            end do
            do k = 1, size(COUNTER_NAMES)
                call h5%write('/'//trim(COUNTER_NAMES(k)), counts(:, k), '1', err)
                if (allocated(err)) exit steps
            end do
            call h5%write('/reference', int(rows%reference, i8), '1', err)
            if (allocated(err)) exit steps
            call text_column('file')
            if (allocated(err)) exit steps
            call text_column('reason')
            if (allocated(err)) exit steps
            call h5%attribute('/', 'sweep', sweep%path, err)
            if (allocated(err)) exit steps
            call h5%attribute('/', 'base', sweep%base, err)
            if (allocated(err)) exit steps
            call h5%attribute('/', 'reference', reference_text(), err)
            if (allocated(err)) exit steps
            call h5%attribute('/', 'version', version_string, err)
        end block steps
        call h5%close(close_err)
        if (allocated(close_err) .and. .not. allocated(err)) call move_alloc(close_err, err)
    contains
        function reference_text() result(text)
            character(len=:), allocatable :: text
            select case (sweep%reference)
            case (REF_NONE)
                text = 'none'
            case (REF_TIGHTEST)
                text = 'tightest'
            case default
                text = sweep%reference_file
            end select
        end function reference_text

        !> The column `name` of strings (a varied key's with its index `vary`), null-padded
        !! to the longest entry (at least one character).
        subroutine text_column(name, vary)
            character(len=*), intent(in) :: name
            integer, intent(in), optional :: vary
            integer :: width, j
            character(len=:), allocatable :: buffer(:), text
            width = 1
            do j = 1, n
                width = max(width, len(cell(name, j, vary)))
            end do
            allocate (character(len=width) :: buffer(n))
            do j = 1, n
                text = cell(name, j, vary)
                buffer(j) = text   ! blank-padded; NUL-padded below
                if (len(text) < width) buffer(j)(len(text) + 1:) = &
                    repeat(achar(0), width - len(text))
            end do
            call h5%write_text('/'//name, buffer, '', err)
        end subroutine text_column

        !> Case j's entry of the text column `name` (of varied key number `vary`).
        function cell(name, j, vary) result(value)
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
            case default
                value = rows(j)%reason
            end select
        end function cell
    end subroutine write_h5
end module ropedyn_sweep_summary
