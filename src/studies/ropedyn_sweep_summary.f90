!> The summary of a sweep, built from whatever case files exist: one row per case with its
!! parameters, status, cost counters, errors against the reference and energy-balance
!! error, written as `<output_dir>/summary.csv` and `<output_dir>/summary.h5`
!! (docs/sweeps.md lists the columns).
module ropedyn_sweep_summary
    use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, ieee_is_nan
    use hdf5, only: hid_t, hsize_t, size_t, h5open_f, h5eset_auto_f, h5fcreate_f, h5fclose_f, &
        H5F_ACC_TRUNC_F, h5screate_simple_f, h5sclose_f, h5dcreate_f, h5dwrite_f, h5dclose_f, &
        h5tcopy_f, h5tset_size_f, h5tset_strpad_f, h5tclose_f, H5T_NATIVE_CHARACTER, &
        H5T_STR_NULLPAD_F, h5kind_to_type, H5_REAL_KIND, H5_INTEGER_KIND
    use ropedyn_kinds, only: wp, i8
    use ropedyn_text, only: int_text, real_text
    use ropedyn_error, only: error_t, make_error, ERR_IO
    use ropedyn_scene, only: scene_namelist_text
    use ropedyn_sweep, only: sweep_t, sweep_case_t, text_t, REF_NONE, &
        REF_TIGHTEST, REF_FILE
    use ropedyn_case_file, only: case_data_t, read_case_file, write_text_attribute
    use ropedyn_version, only: version_string
    implicit none
    private
    public :: case_row_t, case_status, build_summary

    !> One row of the summary.
    type :: case_row_t
        integer :: id = 0
        character(len=:), allocatable :: status  !< complete|failed|running|stale|missing
        character(len=:), allocatable :: reason
        real(wp) :: t_reached, wall_time, cpu_time                     !< s (NaN: absent)
        integer(i8) :: steps = -1, rhs_evals = -1, jac_evals = -1, lin_setups = -1, &
            err_test_fails = -1, nonlin_iters = -1, nonlin_conv_fails = -1
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
            rows(c)%steps = data%steps
            rows(c)%rhs_evals = data%rhs_evals
            rows(c)%jac_evals = data%jac_evals
            rows(c)%lin_setups = data%lin_setups
            rows(c)%err_test_fails = data%err_test_fails
            rows(c)%nonlin_iters = data%nonlin_iters
            rows(c)%nonlin_conv_fails = data%nonlin_conv_fails
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
        line = line//',t_end,t_reached,wall_time,cpu_time,steps,rhs_evals,jac_evals,' &
            //'lin_setups,err_test_fails,nonlin_iters,nonlin_conv_fails,reference,' &
            //'tip_error_final,tip_error_max,position_error_max,energy_error_final,' &
            //'energy_error_max,file,reason'
        write (unit, '(a)', iostat=ios, iomsg=msg) line
        do c = 1, size(rows)
            if (ios /= 0) exit
            associate (r => rows(c), s => sweep%cases(c)%scene)
                line = int_text(r%id)//','//r%status//','//csv_text(trim(s%model%kind))// &
                    ','//int_text(s%model%elements)//','//csv_text(trim(s%solver%method))// &
                    ','//int_text(s%solver%max_order)//','//real_text(s%solver%rtol, compact=.true.)//','// &
                    real_text(s%solver%atol, compact=.true.)
                do v = 1, size(sweep%vary_keys)
                    line = line//','//csv_text(sweep%cases(c)%vary_values(v)%s)
                end do
                line = line//','//real_text(s%solver%t_end, compact=.true.)//','//num(r%t_reached)//','// &
                    num(r%wall_time)//','//num(r%cpu_time)//','//count_text(r%steps)//','// &
                    count_text(r%rhs_evals)//','//count_text(r%jac_evals)//','// &
                    count_text(r%lin_setups)//','//count_text(r%err_test_fails)//','// &
                    count_text(r%nonlin_iters)//','//count_text(r%nonlin_conv_fails)//','
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
        integer :: i
        if (scan(text, ',"'//new_line('a')) == 0) then
            s = text
            return
        end if
        s = '"'
        do i = 1, len(text)
            if (text(i:i) == '"') then
                s = s//'""'
            else
                s = s//text(i:i)
            end if
        end do
        s = s//'"'
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
        integer(hid_t) :: file_id
        integer :: hdferr, n, c, v
        type(text_t), allocatable :: strings(:)
        real(wp), allocatable :: rv(:)
        integer(i8), allocatable :: iv(:)

        path = sweep%output_dir//'/summary.h5'
        n = size(rows)
        allocate (strings(n))
        call h5open_f(hdferr)
        call h5eset_auto_f(0, hdferr)
        call h5fcreate_f(path, H5F_ACC_TRUNC_F, file_id, hdferr)
        if (hdferr < 0) then
            call make_error(err, ERR_IO, path//': cannot create file')
            return
        end if
        steps: block
            call int_column('case', int([(rows(c)%id, c=1, n)], i8), '1')
            if (allocated(err)) exit steps
            do c = 1, n
                strings(c)%s = rows(c)%status
            end do
            call text_column('status', strings)
            if (allocated(err)) exit steps
            do c = 1, n
                strings(c)%s = trim(sweep%cases(c)%scene%model%kind)
            end do
            call text_column('model', strings)
            if (allocated(err)) exit steps
            call int_column('elements', int([(sweep%cases(c)%scene%model%elements, c=1, n)], &
                i8), '1')
            if (allocated(err)) exit steps
            do c = 1, n
                strings(c)%s = trim(sweep%cases(c)%scene%solver%method)
            end do
            call text_column('method', strings)
            if (allocated(err)) exit steps
            call int_column('max_order', int([(sweep%cases(c)%scene%solver%max_order, c=1, n)], &
                i8), '1')
            if (allocated(err)) exit steps
            call real_column('rtol', [(sweep%cases(c)%scene%solver%rtol, c=1, n)], '1')
            if (allocated(err)) exit steps
            call real_column('atol', [(sweep%cases(c)%scene%solver%atol, c=1, n)], &
                'state units (m, rad, m/s, rad/s)')
            if (allocated(err)) exit steps
            do v = 1, size(sweep%vary_keys)
                do c = 1, n
                    strings(c)%s = sweep%cases(c)%vary_values(v)%s
                end do
                call text_column(sweep%vary_keys(v)%s, strings)
                if (allocated(err)) exit steps
            end do
            call real_column('t_end', [(sweep%cases(c)%scene%solver%t_end, c=1, n)], 's')
            if (allocated(err)) exit steps
            rv = rows%t_reached
            call real_column('t_reached', rv, 's')
            if (allocated(err)) exit steps
            rv = rows%wall_time
            call real_column('wall_time', rv, 's')
            if (allocated(err)) exit steps
            rv = rows%cpu_time
            call real_column('cpu_time', rv, 's')
            if (allocated(err)) exit steps
            iv = rows%steps
            call int_column('steps', iv, '1')
            if (allocated(err)) exit steps
            iv = rows%rhs_evals
            call int_column('rhs_evals', iv, '1')
            if (allocated(err)) exit steps
            iv = rows%jac_evals
            call int_column('jac_evals', iv, '1')
            if (allocated(err)) exit steps
            iv = rows%lin_setups
            call int_column('lin_setups', iv, '1')
            if (allocated(err)) exit steps
            iv = rows%err_test_fails
            call int_column('err_test_fails', iv, '1')
            if (allocated(err)) exit steps
            iv = rows%nonlin_iters
            call int_column('nonlin_iters', iv, '1')
            if (allocated(err)) exit steps
            iv = rows%nonlin_conv_fails
            call int_column('nonlin_conv_fails', iv, '1')
            if (allocated(err)) exit steps
            call int_column('reference', int(rows%reference, i8), '1')
            if (allocated(err)) exit steps
            rv = rows%tip_error_final
            call real_column('tip_error_final', rv, 'm')
            if (allocated(err)) exit steps
            rv = rows%tip_error_max
            call real_column('tip_error_max', rv, 'm')
            if (allocated(err)) exit steps
            rv = rows%position_error_max
            call real_column('position_error_max', rv, 'm')
            if (allocated(err)) exit steps
            rv = rows%energy_error_final
            call real_column('energy_error_final', rv, 'J')
            if (allocated(err)) exit steps
            rv = rows%energy_error_max
            call real_column('energy_error_max', rv, 'J')
            if (allocated(err)) exit steps
            do c = 1, n
                strings(c)%s = sweep%cases(c)%file
            end do
            call text_column('file', strings)
            if (allocated(err)) exit steps
            do c = 1, n
                strings(c)%s = rows(c)%reason
            end do
            call text_column('reason', strings)
            if (allocated(err)) exit steps
            call write_text_attribute(path, file_id, '/', 'sweep', sweep%path, err)
            if (allocated(err)) exit steps
            call write_text_attribute(path, file_id, '/', 'base', sweep%base, err)
            if (allocated(err)) exit steps
            call write_text_attribute(path, file_id, '/', 'reference', reference_text(), err)
            if (allocated(err)) exit steps
            call write_text_attribute(path, file_id, '/', 'version', version_string, err)
        end block steps
        call h5fclose_f(file_id, hdferr)
        if (hdferr < 0 .and. .not. allocated(err)) &
            call make_error(err, ERR_IO, path//': cannot close file')
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

        subroutine real_column(name, values, units)
            character(len=*), intent(in) :: name, units
            real(wp), intent(in) :: values(:)
            integer(hid_t) :: type_id
            real(wp), allocatable :: contiguous_values(:)
            contiguous_values = values
            type_id = h5kind_to_type(wp, H5_REAL_KIND)
            call numeric_column(name, type_id, units, rvalues=contiguous_values)
        end subroutine real_column

        subroutine int_column(name, values, units)
            character(len=*), intent(in) :: name, units
            integer(i8), intent(in) :: values(:)
            integer(hid_t) :: type_id
            integer(i8), allocatable :: contiguous_values(:)
            contiguous_values = values
            type_id = h5kind_to_type(i8, H5_INTEGER_KIND)
            call numeric_column(name, type_id, units, ivalues=contiguous_values)
        end subroutine int_column

        subroutine numeric_column(name, type_id, units, rvalues, ivalues)
            character(len=*), intent(in) :: name, units
            integer(hid_t), intent(in) :: type_id
            real(wp), intent(in), optional :: rvalues(:)
            integer(i8), intent(in), optional :: ivalues(:)
            integer(hid_t) :: space_id, dset_id
            integer(hsize_t) :: dims(1)
            integer :: rc
            dims = int(n, hsize_t)
            call h5screate_simple_f(1, dims, space_id, rc)
            if (rc < 0) then
                call make_error(err, ERR_IO, path//': /'//name//': cannot create dataspace')
                return
            end if
            call h5dcreate_f(file_id, name, type_id, space_id, dset_id, rc)
            call h5sclose_f(space_id, hdferr)
            if (rc < 0) then
                call make_error(err, ERR_IO, path//': /'//name//': cannot create dataset')
                return
            end if
            if (present(rvalues)) then
                call h5dwrite_f(dset_id, type_id, rvalues, dims, rc)
            else
                call h5dwrite_f(dset_id, type_id, ivalues, dims, rc)
            end if
            if (rc < 0) then
                call make_error(err, ERR_IO, path//': /'//name//': cannot write dataset')
            else
                call write_text_attribute(path, dset_id, '/'//name, 'units', units, err)
            end if
            call h5dclose_f(dset_id, hdferr)
        end subroutine numeric_column

        subroutine text_column(name, values)
            character(len=*), intent(in) :: name
            type(text_t), intent(in) :: values(:)
            integer(hid_t) :: space_id, dset_id, type_id
            integer(hsize_t) :: dims(1)
            integer :: rc, width, k
            character(len=:), allocatable :: buffer(:)
            width = 1
            do k = 1, size(values)
                width = max(width, len(values(k)%s))
            end do
            allocate (character(len=width) :: buffer(size(values)))
            do k = 1, size(values)
                buffer(k) = values(k)%s   ! blank-padded; stored null-padded below
                if (len(values(k)%s) < width) buffer(k)(len(values(k)%s) + 1:) = &
                    repeat(achar(0), width - len(values(k)%s))
            end do
            dims = int(size(values), hsize_t)
            call h5tcopy_f(H5T_NATIVE_CHARACTER, type_id, rc)
            call h5tset_size_f(type_id, int(width, size_t), rc)
            call h5tset_strpad_f(type_id, H5T_STR_NULLPAD_F, rc)
            call h5screate_simple_f(1, dims, space_id, rc)
            call h5dcreate_f(file_id, name, type_id, space_id, dset_id, rc)
            call h5sclose_f(space_id, hdferr)
            if (rc < 0) then
                call make_error(err, ERR_IO, path//': /'//name//': cannot create dataset')
                call h5tclose_f(type_id, hdferr)
                return
            end if
            call h5dwrite_f(dset_id, type_id, buffer, dims, rc)
            if (rc < 0) then
                call make_error(err, ERR_IO, path//': /'//name//': cannot write dataset')
            else
                call write_text_attribute(path, dset_id, '/'//name, 'units', '', err)
            end if
            call h5dclose_f(dset_id, hdferr)
            call h5tclose_f(type_id, hdferr)
        end subroutine text_column
    end subroutine write_h5
end module ropedyn_sweep_summary
