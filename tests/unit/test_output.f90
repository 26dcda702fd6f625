!> Unit test of ropedyn_output: write files, read them back with the HDF5 Fortran API.
!!
!! Leaves test_output.h5 (complete), test_output_failed.h5 and test_output_crashed.h5 in the
!! current directory, for python/ropedyn/layout.py (run by tests/e2e).
program test_output
    use hdf5, only: hid_t, hsize_t, size_t, h5open_f, h5close_f, h5fopen_f, h5fclose_f, &
        H5F_ACC_RDONLY_F, h5dopen_f, h5dclose_f, h5dread_f, h5dget_space_f, &
        h5sget_simple_extent_ndims_f, h5sget_simple_extent_dims_f, h5sclose_f, &
        h5aopen_by_name_f, h5aexists_by_name_f, h5aclose_f, h5aread_f, h5aget_type_f, &
        h5tget_size_f, h5tclose_f, h5kind_to_type, H5_REAL_KIND, H5_INTEGER_KIND, &
        h5fget_obj_count_f, H5F_OBJ_ALL_F
    use ropedyn_kinds, only: wp, i8
    use ropedyn_error, only: error_t, ERR_IO, ERR_INTERNAL
    use ropedyn_rope_model, only: energy_t
    use ropedyn_integrator, only: solver_stats_t
    use ropedyn_output, only: output_file_t, COUNTER_NAMES, counter_values, add_counter_values
    use ropedyn_assert, only: test_suite_t
    implicit none

    integer, parameter :: n = 3          !< elements
    integer, parameter :: n_records = 4  !< output times written to the complete file
    character(len=*), parameter :: complete_path = 'test_output.h5'
    character(len=*), parameter :: failed_path = 'test_output_failed.h5'
    character(len=*), parameter :: crashed_path = 'test_output_crashed.h5'
    character(len=*), parameter :: missing_path = 'no_such_dir_ropedyn_test/run.h5'
    character(len=*), parameter :: failure_reason = &
        'solver: step size 1.0e-14 s too small at t = 0.75 s'
    character(len=*), parameter :: scene = '&rope'//achar(10)//' n_elements = 3'// &
        achar(10)//'/'

    type(test_suite_t) :: suite
    type(output_file_t) :: out
    type(output_file_t), allocatable :: crashed
    type(error_t), allocatable :: err
    type(solver_stats_t) :: stats
    real(wp) :: element_length(n), element_mass(n)
    integer(size_t) :: open_objects
    integer :: k, hdferr

    suite%name = 'output'
    element_length = [0.1_wp, 0.2_wp, 0.3_wp]
    element_mass = [1.5_wp, 2.5_wp, 3.5_wp]

    ! --- a complete run -------------------------------------------------------------------
    call out%create(complete_path, n, element_length, element_mass, 'rfem', 'bdf', '0.0.0-test', &
                    scene, err)
    call suite%check_true(.not. allocated(err), 'create '//complete_path//error_text(err))
    do k = 1, n_records
        call out%append(time_of(k), q_of(k), qdot_of(k), points_of(k), energy_of(k), &
                        0.01_wp*k, k, err)
        call suite%check_true(.not. allocated(err), 'append record'//error_text(err))
    end do
    stats = solver_stats_t(steps=123_i8, rhs_evals=456_i8, jac_rhs_evals=45_i8, jac_evals=7_i8, &
                           lin_setups=8_i8, err_test_fails=9_i8, nonlin_iters=1000_i8, &
                           nonlin_conv_fails=2_i8)
    call check_counter_values(stats)
    call out%write_stats(stats, 1.25_wp, err)
    call suite%check_true(.not. allocated(err), 'write_stats'//error_text(err))
    call out%write_stats(stats, 1.5_wp, err)
    call suite%check_true(.not. allocated(err), 'write_stats again'//error_text(err))
    ! no leaked HDF5 ids: only the file and its 12 step-by-step datasets are open
    call h5fget_obj_count_f(int(H5F_OBJ_ALL_F, hid_t), H5F_OBJ_ALL_F, open_objects, hdferr)
    call suite%check_true(hdferr >= 0 .and. open_objects == 13_size_t, &
                          'open HDF5 objects = 13 (file + 12 datasets)')
    call out%close_run('complete', '', err)
    call suite%check_true(.not. allocated(err), 'close_run complete'//error_text(err))
    call out%append(time_of(5), q_of(5), qdot_of(5), points_of(5), energy_of(5), 0.1_wp, 1, err)
    call suite%check_true(allocated(err), 'append after close_run fails')
    if (allocated(err)) call suite%check_true(err%code == ERR_INTERNAL, &
                                              'append after close_run is ERR_INTERNAL')
    call check_complete_file()

    ! --- a failed run (same object reused) ------------------------------------------------
    call out%create(failed_path, n, element_length, element_mass, 'rfem', 'bdf', '0.0.0-test', &
                    scene, err)
    call suite%check_true(.not. allocated(err), 'create '//failed_path//error_text(err))
    call out%append(time_of(1), q_of(1), qdot_of(1), points_of(1), energy_of(1), 0.01_wp, 1, &
                    err)
    call suite%check_true(.not. allocated(err), 'append to failed run'//error_text(err))
    call out%append(time_of(2), reshape(q_of(2), [3, 2]), qdot_of(2), points_of(2), energy_of(2), &
                    0.01_wp, 1, err)
    call suite%check_true(allocated(err), 'append with a (3, 2) q fails')
    if (allocated(err)) then
        call suite%check_true(err%code == ERR_INTERNAL, 'wrong shape is ERR_INTERNAL')
        call suite%check_contains(err%message, '/state/q', 'wrong shape message')
    end if
    call out%write_stats(solver_stats_t(steps=5_i8), 0.5_wp, err)
    call suite%check_true(.not. allocated(err), 'write_stats of failed run'//error_text(err))
    call out%close_run('finished', failure_reason, err)
    call suite%check_true(allocated(err), 'close_run with an unknown status fails')
    call out%close_run('failed', failure_reason, err)
    call suite%check_true(.not. allocated(err), 'close_run failed'//error_text(err))
    call check_failed_file()

    ! --- a run that is never closed (the finalizer closes it, status stays running) -------
    allocate (crashed)
    call crashed%create(crashed_path, n, element_length, element_mass, 'rfem', 'bdf', &
                        '0.0.0-test', scene, err)
    call suite%check_true(.not. allocated(err), 'create '//crashed_path//error_text(err))
    call crashed%append(time_of(1), q_of(1), qdot_of(1), points_of(1), energy_of(1), &
                        0.01_wp, 1, err)
    call suite%check_true(.not. allocated(err), 'append to crashed run'//error_text(err))
    deallocate (crashed)
    call check_crashed_file()
    ! HDF5 cannot truncate a file that is still open: re-creating it shows the finalizer ran
    allocate (crashed)
    call crashed%create(crashed_path, n, element_length, element_mass, 'rfem', 'bdf', &
                        '0.0.0-test', scene, err)
    call suite%check_true(.not. allocated(err), 'finalizer closed '//crashed_path// &
                          error_text(err))
    call crashed%append(time_of(1), q_of(1), qdot_of(1), points_of(1), energy_of(1), &
                        0.01_wp, 1, err)
    deallocate (crashed)

    ! --- two files open at once ------------------------------------------------------------
    call two_files_at_once()

    ! --- many records: held in memory and written in blocks ---------------------------------
    call many_records()

    ! --- a directory that does not exist -----------------------------------------------------
    call out%create(missing_path, n, element_length, element_mass, 'rfem', 'bdf', '0.0.0-test', &
                    scene, err)
    call suite%check_true(allocated(err), 'create in a missing directory fails')
    if (allocated(err)) then
        call suite%check_true(err%code == ERR_IO, 'missing directory is ERR_IO')
        call suite%check_contains(err%message, missing_path, 'missing directory message')
        call suite%check_contains(err%message, 'directory', 'missing directory hint')
    end if
    call out%close_run('complete', '', err)
    call suite%check_true(allocated(err), 'close_run after a failed create fails')

    call suite%finish()

contains

    ! Known record values ------------------------------------------------------------------

    pure real(wp) function time_of(k) result(t)
        integer, intent(in) :: k
        t = 0.25_wp*(k - 1)
    end function time_of

    pure function q_of(k) result(q)
        integer, intent(in) :: k
        real(wp) :: q(3, n)
        integer :: i, j
        do j = 1, n
            do i = 1, 3
                q(i, j) = 100.0_wp*k + 10.0_wp*j + i
            end do
        end do
    end function q_of

    pure function qdot_of(k) result(qdot)
        integer, intent(in) :: k
        real(wp) :: qdot(3, n)
        qdot = -0.5_wp*q_of(k)
    end function qdot_of

    pure function points_of(k) result(points)
        integer, intent(in) :: k
        real(wp) :: points(2, 2*n)
        integer :: i, j
        do j = 1, 2*n
            do i = 1, 2
                points(i, j) = 1000.0_wp*k + 10.0_wp*j + i + 0.5_wp
            end do
        end do
    end function points_of

    pure function energy_of(k) result(e)
        integer, intent(in) :: k
        type(energy_t) :: e
        e = energy_t(kinetic=1.0_wp*k, elastic=0.1_wp*k, gravity=-3.0_wp*k, &
                     dissipated=0.01_wp*k, support_work=0.001_wp*k)
    end function energy_of

    function error_text(e) result(text)
        type(error_t), allocatable, intent(in) :: e
        character(len=:), allocatable :: text
        text = ''
        if (allocated(e)) text = ' ['//e%message//']'
    end function error_text

    ! Checks of the files --------------------------------------------------------------------

    !> counter_values gives every counter of `stats` once, under its name in COUNTER_NAMES,
    !! and add_counter_values (a resume's earlier parts) adds each back to its own field.
    subroutine check_counter_values(stats)
        type(solver_stats_t), intent(in) :: stats
        type(solver_stats_t) :: sum
        integer(i8) :: values(size(COUNTER_NAMES))
        values = counter_values(stats)
        call suite%check_true(values(findloc(COUNTER_NAMES, 'jac_rhs_evals', 1)) == 45_i8 &
                              .and. values(findloc(COUNTER_NAMES, 'rhs_evals', 1)) == 456_i8, &
                              'counter_values: jac_rhs_evals, rhs_evals under their names')
        sum = stats
        call add_counter_values(sum, values)
        call suite%check_true(all(counter_values(sum) == 2*values), &
                              'add_counter_values adds each counter to its own field')
    end subroutine check_counter_values

    subroutine check_complete_file()
        integer(hid_t) :: file_id
        integer(hsize_t), allocatable :: dims(:)
        real(wp), allocatable :: values(:), q(:, :, :), points(:, :, :)
        integer, allocatable :: orders(:)
        integer(i8) :: steps
        real(wp) :: cpu
        type(energy_t) :: energy
        integer :: hdferr, k

        call h5open_f(hdferr)
        call h5fopen_f(complete_path, H5F_ACC_RDONLY_F, file_id, hdferr)
        call suite%check_true(hdferr >= 0, 'reopen '//complete_path)
        if (hdferr < 0) return

        call read_real_1d(file_id, '/time', values)
        call suite%check_true(size(values) == n_records, '/time has 4 values')
        if (size(values) == n_records) then
            do k = 1, n_records
                call suite%check_close(values(k), time_of(k), 0.0_wp, 0.0_wp, '/time value')
            end do
        end if

        call dataset_dims(file_id, '/state/q', dims)
        call suite%check_true(size(dims) == 3, '/state/q has rank 3')
        if (size(dims) == 3) then
            call suite%check_true(all(dims == [3_hsize_t, 3_hsize_t, 4_hsize_t]), &
                                  '/state/q dims are (3, 3, 4) in Fortran order')
            if (all(dims == [3_hsize_t, 3_hsize_t, 4_hsize_t])) then
                allocate (q(3, n, n_records))
                call read_real_3d(file_id, '/state/q', q)
                do k = 1, n_records
                    call suite%check_le(maxval(abs(q(:, :, k) - q_of(k))), 0.0_wp, &
                                        '/state/q record values')
                end do
            end if
        end if

        call dataset_dims(file_id, '/rope/points', dims)
        call suite%check_true(size(dims) == 3, '/rope/points has rank 3')
        if (size(dims) == 3) then
            call suite%check_true(all(dims == [2_hsize_t, 6_hsize_t, 4_hsize_t]), &
                                  '/rope/points dims are (2, 6, 4)')
            if (all(dims == [2_hsize_t, 6_hsize_t, 4_hsize_t])) then
                allocate (points(2, 2*n, n_records))
                call read_real_3d(file_id, '/rope/points', points)
                call suite%check_le(maxval(abs(points(:, :, 3) - points_of(3))), 0.0_wp, &
                                    '/rope/points record 3 values')
            end if
        end if

        call read_real_1d(file_id, '/energy/total', values)
        call suite%check_true(size(values) == n_records, '/energy/total has 4 values')
        energy = energy_of(2)
        if (size(values) == n_records) call suite%check_close(values(2), energy%total(), &
            1.0e-15_wp, 0.0_wp, '/energy/total = kinetic+elastic+gravity')
        call read_real_1d(file_id, '/energy/support_work', values)
        if (size(values) == n_records) call suite%check_close(values(4), 0.004_wp, &
            1.0e-15_wp, 0.0_wp, '/energy/support_work value')
        call read_real_1d(file_id, '/rope/element_mass', values)
        call suite%check_true(size(values) == n, '/rope/element_mass has 3 values')
        if (size(values) == n) call suite%check_le(maxval(abs(values - element_mass)), &
                                                    0.0_wp, '/rope/element_mass values')

        call read_int_1d(file_id, '/solver/order', orders)
        call suite%check_true(size(orders) == n_records, '/solver/order has 4 values')
        if (size(orders) == n_records) call suite%check_true(all(orders == [1, 2, 3, 4]), &
                                                              '/solver/order values')
        call read_int8_scalar(file_id, '/solver/nonlin_iters', steps)
        call suite%check_true(steps == 1000_i8, '/solver/nonlin_iters = 1000')
        call read_int8_scalar(file_id, '/solver/jac_rhs_evals', steps)
        call suite%check_true(steps == 45_i8, '/solver/jac_rhs_evals = 45')
        call read_real_scalar(file_id, '/solver/cpu_time', cpu)
        call suite%check_close(cpu, 1.5_wp, 0.0_wp, 0.0_wp, '/solver/cpu_time (rewritten)')

        call suite%check_true(string_attribute(file_id, '/', 'status') == 'complete', &
                              'status is complete')
        call suite%check_true(.not. has_attribute(file_id, '/', 'reason'), &
                              'complete run has no reason')
        call suite%check_true(string_attribute(file_id, '/energy/total', 'units') == 'J', &
                              '/energy/total units is J')
        call suite%check_true(string_attribute(file_id, '/state/q', 'units') == 'm, m, rad', &
                              '/state/q units')
        call suite%check_true(string_attribute(file_id, '/state/q', 'columns') == 'x, y, phi', &
                              '/state/q columns')
        call suite%check_true(string_attribute(file_id, '/', 'scene') == scene, &
                              'scene text kept with its newlines')
        call suite%check_true(string_attribute(file_id, '/', 'model') == 'rfem', 'model')
        call suite%check_true(len(string_attribute(file_id, '/', 'created')) == 20, &
                              'created is yyyy-mm-ddThh:mm:ssZ: '// &
                              string_attribute(file_id, '/', 'created'))

        call h5fclose_f(file_id, hdferr)
        call suite%check_true(hdferr >= 0, 'close reopened file')
        call h5close_f(hdferr)
    end subroutine check_complete_file

    subroutine check_failed_file()
        integer(hid_t) :: file_id
        real(wp), allocatable :: values(:)
        integer(i8) :: steps
        integer :: hdferr

        call h5open_f(hdferr)
        call h5fopen_f(failed_path, H5F_ACC_RDONLY_F, file_id, hdferr)
        call suite%check_true(hdferr >= 0, 'reopen '//failed_path)
        if (hdferr < 0) return
        call suite%check_true(string_attribute(file_id, '/', 'status') == 'failed', &
                              'status is failed')
        call suite%check_true(string_attribute(file_id, '/', 'reason') == failure_reason, &
                              'reason is the error message')
        call read_real_1d(file_id, '/time', values)
        call suite%check_true(size(values) == 1, 'failed run has the 1 record written')
        call read_int8_scalar(file_id, '/solver/steps', steps)
        call suite%check_true(steps == 5_i8, 'failed run has its stats')
        call h5fclose_f(file_id, hdferr)
        call h5close_f(hdferr)
    end subroutine check_failed_file

    subroutine check_crashed_file()
        integer(hid_t) :: file_id
        real(wp), allocatable :: values(:)
        integer :: hdferr

        call h5open_f(hdferr)
        call h5fopen_f(crashed_path, H5F_ACC_RDONLY_F, file_id, hdferr)
        call suite%check_true(hdferr >= 0, 'reopen '//crashed_path)
        if (hdferr < 0) return
        call suite%check_true(string_attribute(file_id, '/', 'status') == 'running', &
                              'unclosed run keeps status running')
        call read_real_1d(file_id, '/time', values)
        call suite%check_true(size(values) == 1, 'unclosed run has its record')
        call h5fclose_f(file_id, hdferr)
        call h5close_f(hdferr)
    end subroutine check_crashed_file

    subroutine two_files_at_once()
        type(output_file_t) :: a, b
        type(error_t), allocatable :: e
        integer :: ok
        ok = 0
        call a%create('test_output_a.h5', n, element_length, element_mass, 'rfem', 'bdf', &
                      '0.0.0-test', scene, e)
        if (.not. allocated(e)) ok = ok + 1
        call b%create('test_output_b.h5', n, element_length, element_mass, 'rfem', 'bdf', &
                      '0.0.0-test', scene, e)
        if (.not. allocated(e)) ok = ok + 1
        call a%append(time_of(1), q_of(1), qdot_of(1), points_of(1), energy_of(1), 0.1_wp, 1, e)
        if (.not. allocated(e)) ok = ok + 1
        call a%close_run('complete', '', e)
        if (.not. allocated(e)) ok = ok + 1
        call b%append(time_of(1), q_of(1), qdot_of(1), points_of(1), energy_of(1), 0.1_wp, 1, e)
        if (.not. allocated(e)) ok = ok + 1
        call b%close_run('complete', '', e)
        if (.not. allocated(e)) ok = ok + 1
        call suite%check_true(ok == 6, 'two files open at once'//error_text(e))
    end subroutine two_files_at_once

    !> 1,300 records (more than two blocks of pending records for this small rope): every
    !! record of every series in its place, the last block written by close_run before
    !! the file says 'complete'.
    subroutine many_records()
        integer, parameter :: records = 1300
        character(len=*), parameter :: path = 'test_output_blocks.h5'
        type(output_file_t) :: run
        type(error_t), allocatable :: e
        integer(hid_t) :: file_id
        real(wp), allocatable :: times(:), q(:, :, :), qdot(:, :, :), points(:, :, :), &
                                 kinetic(:)
        integer, allocatable :: orders(:)
        integer :: j, bad, hdferr
        call run%create(path, n, element_length, element_mass, 'rfem', 'bdf', '0.0.0-test', &
                        scene, e)
        call suite%check_true(.not. allocated(e), 'create '//path//error_text(e))
        if (allocated(e)) return
        do j = 1, records
            call run%append(time_of(j), q_of(j), qdot_of(j), points_of(j), energy_of(j), &
                            0.001_wp*j, mod(j, 7), e)
            if (allocated(e)) exit
        end do
        call suite%check_true(.not. allocated(e), 'append 1300 records'//error_text(e))
        call suite%check_true(run%records() == records, 'records() counts the pending ones')
        call run%close_run('complete', '', e)
        call suite%check_true(.not. allocated(e), 'close_run after 1300'//error_text(e))

        call h5open_f(hdferr)
        call h5fopen_f(path, H5F_ACC_RDONLY_F, file_id, hdferr)
        call suite%check_true(hdferr >= 0, 'reopen '//path)
        if (hdferr < 0) return
        call suite%check_true(string_attribute(file_id, '/', 'status') == 'complete', &
                              path//' complete')
        call read_real_1d(file_id, '/time', times)
        call read_real_1d(file_id, '/energy/kinetic', kinetic)
        call read_int_1d(file_id, '/solver/order', orders)
        call suite%check_true(size(times) == records .and. size(kinetic) == records .and. &
                              size(orders) == records, 'every series has 1300 records')
        allocate (q(3, n, records), qdot(3, n, records), points(2, 2*n, records))
        call read_real_3d(file_id, '/state/q', q)
        call read_real_3d(file_id, '/state/qdot', qdot)
        call read_real_3d(file_id, '/rope/points', points)
        bad = 0
        if (size(times) == records .and. size(kinetic) == records .and. &
            size(orders) == records) then
            do j = 1, records
                if (times(j) /= time_of(j) .or. kinetic(j) /= 1.0_wp*j .or. &
                    orders(j) /= mod(j, 7) .or. any(q(:, :, j) /= q_of(j)) .or. &
                    any(qdot(:, :, j) /= qdot_of(j)) .or. &
                    any(points(:, :, j) /= points_of(j))) bad = bad + 1
            end do
        end if
        call suite%check_true(bad == 0, 'every record of 1300 in its place')
        call h5fclose_f(file_id, hdferr)
        call h5close_f(hdferr)
    end subroutine many_records

    ! HDF5 reading helpers (failures give empty results, which the checks then catch) ------

    subroutine dataset_dims(file_id, name, dims)
        integer(hid_t), intent(in) :: file_id
        character(len=*), intent(in) :: name
        integer(hsize_t), allocatable, intent(out) :: dims(:)
        integer(hsize_t), allocatable :: max_dims(:)
        integer(hid_t) :: dset_id, space_id
        integer :: rank, hdferr
        call h5dopen_f(file_id, name, dset_id, hdferr)
        if (hdferr < 0) then
            allocate (dims(0))
            return
        end if
        call h5dget_space_f(dset_id, space_id, hdferr)
        call h5sget_simple_extent_ndims_f(space_id, rank, hdferr)
        allocate (dims(rank), max_dims(rank))
        call h5sget_simple_extent_dims_f(space_id, dims, max_dims, hdferr)
        call h5sclose_f(space_id, hdferr)
        call h5dclose_f(dset_id, hdferr)
    end subroutine dataset_dims

    subroutine read_real_1d(file_id, name, values)
        integer(hid_t), intent(in) :: file_id
        character(len=*), intent(in) :: name
        real(wp), allocatable, intent(out) :: values(:)
        integer(hsize_t), allocatable :: dims(:)
        integer(hid_t) :: dset_id
        integer :: hdferr
        call dataset_dims(file_id, name, dims)
        allocate (values(0))
        if (size(dims) /= 1) return
        deallocate (values)
        allocate (values(dims(1)))
        call h5dopen_f(file_id, name, dset_id, hdferr)
        call h5dread_f(dset_id, h5kind_to_type(wp, H5_REAL_KIND), values, dims, hdferr)
        if (hdferr < 0) values = -huge(1.0_wp)
        call h5dclose_f(dset_id, hdferr)
    end subroutine read_real_1d

    subroutine read_int_1d(file_id, name, values)
        integer(hid_t), intent(in) :: file_id
        character(len=*), intent(in) :: name
        integer, allocatable, intent(out) :: values(:)
        integer(hsize_t), allocatable :: dims(:)
        integer(hid_t) :: dset_id
        integer :: hdferr
        call dataset_dims(file_id, name, dims)
        allocate (values(0))
        if (size(dims) /= 1) return
        deallocate (values)
        allocate (values(dims(1)))
        call h5dopen_f(file_id, name, dset_id, hdferr)
        call h5dread_f(dset_id, h5kind_to_type(kind(0), H5_INTEGER_KIND), values, dims, hdferr)
        if (hdferr < 0) values = -huge(0)
        call h5dclose_f(dset_id, hdferr)
    end subroutine read_int_1d

    subroutine read_real_3d(file_id, name, values)
        integer(hid_t), intent(in) :: file_id
        character(len=*), intent(in) :: name
        real(wp), intent(out) :: values(:, :, :)
        integer(hid_t) :: dset_id
        integer :: hdferr
        call h5dopen_f(file_id, name, dset_id, hdferr)
        call h5dread_f(dset_id, h5kind_to_type(wp, H5_REAL_KIND), values, &
                       int(shape(values), hsize_t), hdferr)
        if (hdferr < 0) values = -huge(1.0_wp)
        call h5dclose_f(dset_id, hdferr)
    end subroutine read_real_3d

    subroutine read_int8_scalar(file_id, name, value)
        integer(hid_t), intent(in) :: file_id
        character(len=*), intent(in) :: name
        integer(i8), intent(out) :: value
        integer(hid_t) :: dset_id
        integer :: hdferr
        value = -1_i8
        call h5dopen_f(file_id, name, dset_id, hdferr)
        if (hdferr < 0) return
        call h5dread_f(dset_id, h5kind_to_type(i8, H5_INTEGER_KIND), value, [1_hsize_t], hdferr)
        if (hdferr < 0) value = -1_i8
        call h5dclose_f(dset_id, hdferr)
    end subroutine read_int8_scalar

    subroutine read_real_scalar(file_id, name, value)
        integer(hid_t), intent(in) :: file_id
        character(len=*), intent(in) :: name
        real(wp), intent(out) :: value
        integer(hid_t) :: dset_id
        integer :: hdferr
        value = -huge(1.0_wp)
        call h5dopen_f(file_id, name, dset_id, hdferr)
        if (hdferr < 0) return
        call h5dread_f(dset_id, h5kind_to_type(wp, H5_REAL_KIND), value, [1_hsize_t], hdferr)
        if (hdferr < 0) value = -huge(1.0_wp)
        call h5dclose_f(dset_id, hdferr)
    end subroutine read_real_scalar

    logical function has_attribute(file_id, object, name) result(exists)
        integer(hid_t), intent(in) :: file_id
        character(len=*), intent(in) :: object, name
        integer :: hdferr
        call h5aexists_by_name_f(file_id, object, name, exists, hdferr)
        if (hdferr < 0) exists = .false.
    end function has_attribute

    !> A fixed-length string attribute, read with its stored type ('<missing>' on failure).
    function string_attribute(file_id, object, name) result(text)
        integer(hid_t), intent(in) :: file_id
        character(len=*), intent(in) :: object, name
        character(len=:), allocatable :: text
        integer(hid_t) :: attr_id, type_id
        integer(size_t) :: length
        integer :: hdferr
        text = '<missing>'
        call h5aopen_by_name_f(file_id, object, name, attr_id, hdferr)
        if (hdferr < 0) return
        call h5aget_type_f(attr_id, type_id, hdferr)
        call h5tget_size_f(type_id, length, hdferr)
        block
            character(len=length) :: buffer
            call h5aread_f(attr_id, type_id, buffer, [1_hsize_t], hdferr)
            if (hdferr >= 0) text = buffer
        end block
        call h5tclose_f(type_id, hdferr)
        call h5aclose_f(attr_id, hdferr)
    end function string_attribute
end program test_output
