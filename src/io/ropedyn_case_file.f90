!> Reading back a run file written by `ropedyn_output` (the case files of a sweep): the
!! root attributes, the solver counters and, on request, the time series needed for
!! error measures. Also adds the wall-clock time of a sweep case (`/solver/wall_time`).
!!
!! Every HDF5 call is checked; failures are `ERR_IO` errors naming the file and the object.
!! HDF5 is opened with `h5open_f` (idempotent) and never closed, as in `ropedyn_output`.
module ropedyn_case_file
    use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
    use hdf5, only: hid_t, hsize_t, size_t, h5open_f, h5eset_auto_f, &
        h5fopen_f, h5fclose_f, H5F_ACC_RDONLY_F, H5F_ACC_RDWR_F, &
        h5lexists_f, h5dopen_f, h5dclose_f, h5dread_f, h5dwrite_f, h5dcreate_f, &
        h5dget_space_f, h5sget_simple_extent_ndims_f, h5sget_simple_extent_dims_f, &
        h5screate_f, h5sclose_f, H5S_SCALAR_F, &
        h5aexists_f, h5aopen_f, h5aclose_f, h5aread_f, h5aget_type_f, h5acreate_f, &
        h5awrite_f, h5tget_size_f, h5tclose_f, h5tcopy_f, h5tset_size_f, h5tset_strpad_f, &
        H5T_NATIVE_CHARACTER, H5T_STR_NULLPAD_F, h5kind_to_type, H5_REAL_KIND, H5_INTEGER_KIND
    use ropedyn_kinds, only: wp, i8
    use ropedyn_error, only: error_t, make_error, ERR_IO
    implicit none
    private
    public :: case_data_t, read_case_file, write_wall_time, write_text_attribute

    !> What a run file holds (the counters are -1 and the times NaN when absent).
    type :: case_data_t
        logical :: exists = .false.
        character(len=:), allocatable :: status   !< complete | failed | running
        character(len=:), allocatable :: reason   !< failed runs: the error message
        character(len=:), allocatable :: scene    !< the effective namelist text
        character(len=:), allocatable :: model, method
        real(wp) :: cpu_time = 0.0_wp, wall_time = 0.0_wp  !< s (NaN when absent)
        integer(i8) :: steps = -1, rhs_evals = -1, jac_evals = -1, lin_setups = -1, &
            err_test_fails = -1, nonlin_iters = -1, nonlin_conv_fails = -1
        integer :: records = 0                      !< complete output records
        real(wp), allocatable :: time(:)            !< (records) s
        real(wp), allocatable :: points(:, :, :)    !< (2, 2n, records) m
        !> (records) J: kinetic + elastic + gravity + dissipated - support_work
        real(wp), allocatable :: balance(:)
    end type case_data_t

contains

    !> Read a run file. A missing file is not an error (`data%exists` is false); an
    !! unreadable one is. With `series`, also read time, points and the energy balance.
    subroutine read_case_file(path, data, err, series)
        character(len=*), intent(in) :: path
        type(case_data_t), intent(out) :: data
        type(error_t), allocatable, intent(out) :: err
        logical, intent(in), optional :: series
        integer(hid_t) :: file_id
        integer :: hdferr
        real(wp), allocatable :: e(:)
        character(len=*), parameter :: ENERGIES(5) = [character(len=12) :: 'kinetic', &
            'elastic', 'gravity', 'dissipated', 'support_work']
        real(wp), parameter :: SIGNS(5) = [1.0_wp, 1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp]
        integer :: k

        data%cpu_time = ieee_value(1.0_wp, ieee_quiet_nan)
        data%wall_time = data%cpu_time
        inquire (file=path, exist=data%exists)
        if (.not. data%exists) return
        call library_acquire(path, err)
        if (allocated(err)) return
        call h5fopen_f(path, H5F_ACC_RDONLY_F, file_id, hdferr)
        if (hdferr < 0) then
            call make_error(err, ERR_IO, path//': cannot open as HDF5 file')
            return
        end if
        steps: block
            call read_text_attribute(path, file_id, 'status', data%status, err)
            if (allocated(err)) exit steps
            call read_text_attribute(path, file_id, 'scene', data%scene, err)
            if (allocated(err)) exit steps
            call read_text_attribute(path, file_id, 'model', data%model, err)
            if (allocated(err)) exit steps
            call read_text_attribute(path, file_id, 'method', data%method, err)
            if (allocated(err)) exit steps
            call read_text_attribute(path, file_id, 'reason', data%reason, err, optional=.true.)
            if (allocated(err)) exit steps
            call read_int_scalar(path, file_id, '/solver/steps', data%steps, err)
            if (allocated(err)) exit steps
            call read_int_scalar(path, file_id, '/solver/rhs_evals', data%rhs_evals, err)
            if (allocated(err)) exit steps
            call read_int_scalar(path, file_id, '/solver/jac_evals', data%jac_evals, err)
            if (allocated(err)) exit steps
            call read_int_scalar(path, file_id, '/solver/lin_setups', data%lin_setups, err)
            if (allocated(err)) exit steps
            call read_int_scalar(path, file_id, '/solver/err_test_fails', &
                                 data%err_test_fails, err)
            if (allocated(err)) exit steps
            call read_int_scalar(path, file_id, '/solver/nonlin_iters', data%nonlin_iters, err)
            if (allocated(err)) exit steps
            call read_int_scalar(path, file_id, '/solver/nonlin_conv_fails', &
                                 data%nonlin_conv_fails, err)
            if (allocated(err)) exit steps
            call read_real_scalar(path, file_id, '/solver/cpu_time', data%cpu_time, err)
            if (allocated(err)) exit steps
            call read_real_scalar(path, file_id, '/solver/wall_time', data%wall_time, err)
            if (allocated(err)) exit steps
            call read_series_1d(path, file_id, '/time', data%time, err)
            if (allocated(err)) exit steps
            data%records = size(data%time)
            if (.not. present(series)) exit steps
            if (.not. series) exit steps
            call read_series_3d(path, file_id, '/rope/points', data%points, err)
            if (allocated(err)) exit steps
            if (size(data%points, 3) < data%records) then
                call make_error(err, ERR_IO, path//': /rope/points: fewer records than /time')
                exit steps
            end if
            data%points = data%points(:, :, :data%records)
            allocate (data%balance(data%records), source=0.0_wp)
            do k = 1, size(ENERGIES)
                call read_series_1d(path, file_id, '/energy/'//trim(ENERGIES(k)), e, err)
                if (allocated(err)) exit steps
                if (size(e) < data%records) then
                    call make_error(err, ERR_IO, path//': /energy/'//trim(ENERGIES(k))// &
                        ': fewer records than /time')
                    exit steps
                end if
                data%balance = data%balance + SIGNS(k)*e(:data%records)
            end do
        end block steps
        call h5fclose_f(file_id, hdferr)
        if (hdferr < 0 .and. .not. allocated(err)) &
            call make_error(err, ERR_IO, path//': cannot close file')
    end subroutine read_case_file

    !> Write (or overwrite) the scalar `/solver/wall_time` (s) of a closed run file.
    subroutine write_wall_time(path, seconds, err)
        character(len=*), intent(in) :: path
        real(wp), intent(in) :: seconds
        type(error_t), allocatable, intent(out) :: err
        character(len=*), parameter :: NAME = '/solver/wall_time'
        integer(hid_t) :: file_id, dset_id, space_id, type_id
        integer(hsize_t), parameter :: dims(1) = 1
        logical :: exists
        integer :: hdferr

        call library_acquire(path, err)
        if (allocated(err)) return
        call h5fopen_f(path, H5F_ACC_RDWR_F, file_id, hdferr)
        if (hdferr < 0) then
            call make_error(err, ERR_IO, path//': cannot open for writing')
            return
        end if
        type_id = h5kind_to_type(wp, H5_REAL_KIND)
        dset_id = -1
        steps: block
            call h5lexists_f(file_id, '/solver', exists, hdferr)
            if (hdferr < 0 .or. .not. exists) then
                call make_error(err, ERR_IO, path//': /solver: missing')
                exit steps
            end if
            call h5lexists_f(file_id, NAME, exists, hdferr)
            if (hdferr < 0) then
                call make_error(err, ERR_IO, path//': '//NAME//': cannot check existence')
                exit steps
            end if
            if (exists) then
                call h5dopen_f(file_id, NAME, dset_id, hdferr)
            else
                call h5screate_f(H5S_SCALAR_F, space_id, hdferr)
                if (hdferr < 0) then
                    call make_error(err, ERR_IO, path//': '//NAME//': cannot create dataspace')
                    exit steps
                end if
                call h5dcreate_f(file_id, NAME, type_id, space_id, dset_id, hdferr)
                call h5sclose_f(space_id, hdferr)
            end if
            if (dset_id < 0) then
                call make_error(err, ERR_IO, path//': '//NAME//': cannot create dataset')
                exit steps
            end if
            call h5dwrite_f(dset_id, type_id, seconds, dims, hdferr)
            if (hdferr < 0) then
                call make_error(err, ERR_IO, path//': '//NAME//': cannot write dataset')
                exit steps
            end if
            if (.not. exists) call write_text_attribute(path, dset_id, NAME, 'units', 's', err)
        end block steps
        if (dset_id >= 0) call h5dclose_f(dset_id, hdferr)
        call h5fclose_f(file_id, hdferr)
        if (hdferr < 0 .and. .not. allocated(err)) &
            call make_error(err, ERR_IO, path//': cannot close file')
    end subroutine write_wall_time

    !> Write (or replace) a scalar fixed-length string attribute `name` on `loc_id`.
    subroutine write_text_attribute(path, loc_id, where, name, value, err)
        character(len=*), intent(in) :: path, where, name, value
        integer(hid_t), intent(in) :: loc_id
        type(error_t), allocatable, intent(out) :: err
        integer(hid_t) :: type_id, space_id, attr_id
        integer(hsize_t), parameter :: dims(1) = 1
        logical :: exists
        integer :: hdferr, rc
        character(len=:), allocatable :: label, stored

        label = path//': '//where//' attribute '//name
        stored = value
        if (len(stored) == 0) stored = achar(0)
        call h5aexists_f(loc_id, name, exists, hdferr)
        if (hdferr < 0 .or. exists) then
            call make_error(err, ERR_IO, label//': exists already or cannot be checked')
            return
        end if
        call h5tcopy_f(H5T_NATIVE_CHARACTER, type_id, hdferr)
        if (hdferr < 0) then
            call make_error(err, ERR_IO, label//': cannot copy string type')
            return
        end if
        call h5tset_size_f(type_id, int(len(stored), size_t), rc)
        call h5tset_strpad_f(type_id, H5T_STR_NULLPAD_F, hdferr)
        rc = min(rc, hdferr)
        call h5screate_f(H5S_SCALAR_F, space_id, hdferr)
        rc = min(rc, hdferr)
        if (rc < 0) then
            call make_error(err, ERR_IO, label//': cannot make string type or dataspace')
            call h5tclose_f(type_id, hdferr)
            return
        end if
        call h5acreate_f(loc_id, name, type_id, space_id, attr_id, hdferr)
        if (hdferr < 0) then
            call make_error(err, ERR_IO, label//': cannot create attribute')
        else
            call h5awrite_f(attr_id, type_id, stored, dims, hdferr)
            if (hdferr < 0) call make_error(err, ERR_IO, label//': cannot write attribute')
            call h5aclose_f(attr_id, hdferr)
        end if
        call h5sclose_f(space_id, hdferr)
        call h5tclose_f(type_id, hdferr)
    end subroutine write_text_attribute

    ! ------------------------------------------------------------------------------------

    subroutine library_acquire(path, err)
        character(len=*), intent(in) :: path
        type(error_t), allocatable, intent(out) :: err
        integer :: hdferr
        call h5open_f(hdferr)
        if (hdferr < 0) then
            call make_error(err, ERR_IO, path//': cannot initialize the HDF5 library')
            return
        end if
        call h5eset_auto_f(0, hdferr)
    end subroutine library_acquire

    !> A scalar string attribute of the root group, NULs removed. A missing attribute is
    !! an error unless `optional` (then `value` is '').
    subroutine read_text_attribute(path, file_id, name, value, err, optional)
        character(len=*), intent(in) :: path, name
        integer(hid_t), intent(in) :: file_id
        character(len=:), allocatable, intent(out) :: value
        type(error_t), allocatable, intent(out) :: err
        logical, intent(in), optional :: optional
        integer(hid_t) :: attr_id, type_id
        integer(size_t) :: length
        integer(hsize_t), parameter :: dims(1) = 1
        logical :: exists
        integer :: hdferr, nul

        value = ''
        call h5aexists_f(file_id, name, exists, hdferr)
        if (hdferr < 0) then
            call make_error(err, ERR_IO, path//': attribute '//name//': cannot check existence')
            return
        end if
        if (.not. exists) then
            if (present(optional)) then
                if (optional) return
            end if
            call make_error(err, ERR_IO, path//': attribute '//name//' is missing (not a ' &
                //'ropedyn run file?)')
            return
        end if
        call h5aopen_f(file_id, name, attr_id, hdferr)
        if (hdferr < 0) then
            call make_error(err, ERR_IO, path//': attribute '//name//': cannot open')
            return
        end if
        call h5aget_type_f(attr_id, type_id, hdferr)
        if (hdferr >= 0) call h5tget_size_f(type_id, length, hdferr)
        if (hdferr < 0) then
            call make_error(err, ERR_IO, path//': attribute '//name//': cannot get its type')
        else
            block
                character(len=length) :: buffer
                buffer = ''
                call h5aread_f(attr_id, type_id, buffer, dims, hdferr)
                if (hdferr < 0) then
                    call make_error(err, ERR_IO, path//': attribute '//name//': cannot read')
                else
                    nul = index(buffer, achar(0))
                    if (nul > 0) then
                        value = buffer(:nul - 1)
                    else
                        value = buffer
                    end if
                end if
            end block
            call h5tclose_f(type_id, hdferr)
        end if
        call h5aclose_f(attr_id, hdferr)
    end subroutine read_text_attribute

    !> A scalar int64 dataset; absent: -1.
    subroutine read_int_scalar(path, file_id, name, value, err)
        character(len=*), intent(in) :: path, name
        integer(hid_t), intent(in) :: file_id
        integer(i8), intent(inout) :: value
        type(error_t), allocatable, intent(out) :: err
        integer(hid_t) :: dset_id
        integer(hsize_t), parameter :: dims(1) = 1
        integer :: hdferr
        if (.not. open_if_present(path, file_id, name, dset_id, err)) return
        call h5dread_f(dset_id, h5kind_to_type(i8, H5_INTEGER_KIND), value, dims, hdferr)
        if (hdferr < 0) call make_error(err, ERR_IO, path//': '//name//': cannot read')
        call h5dclose_f(dset_id, hdferr)
    end subroutine read_int_scalar

    !> A scalar real dataset; absent: unchanged.
    subroutine read_real_scalar(path, file_id, name, value, err)
        character(len=*), intent(in) :: path, name
        integer(hid_t), intent(in) :: file_id
        real(wp), intent(inout) :: value
        type(error_t), allocatable, intent(out) :: err
        integer(hid_t) :: dset_id
        integer(hsize_t), parameter :: dims(1) = 1
        integer :: hdferr
        if (.not. open_if_present(path, file_id, name, dset_id, err)) return
        call h5dread_f(dset_id, h5kind_to_type(wp, H5_REAL_KIND), value, dims, hdferr)
        if (hdferr < 0) call make_error(err, ERR_IO, path//': '//name//': cannot read')
        call h5dclose_f(dset_id, hdferr)
    end subroutine read_real_scalar

    !> A 1-d real dataset (a missing one reads as empty).
    subroutine read_series_1d(path, file_id, name, values, err)
        character(len=*), intent(in) :: path, name
        integer(hid_t), intent(in) :: file_id
        real(wp), allocatable, intent(out) :: values(:)
        type(error_t), allocatable, intent(out) :: err
        integer(hid_t) :: dset_id
        integer(hsize_t) :: dims(1)
        integer :: hdferr
        allocate (values(0))
        if (.not. open_if_present(path, file_id, name, dset_id, err)) return
        call extents(path, name, dset_id, 1, dims, err)
        if (.not. allocated(err)) then
            deallocate (values)
            allocate (values(dims(1)))
            if (dims(1) > 0) then
                call h5dread_f(dset_id, h5kind_to_type(wp, H5_REAL_KIND), values, dims, hdferr)
                if (hdferr < 0) call make_error(err, ERR_IO, path//': '//name//': cannot read')
            end if
        end if
        call h5dclose_f(dset_id, hdferr)
    end subroutine read_series_1d

    !> A 3-d real dataset, in Fortran order (a missing one reads as empty).
    subroutine read_series_3d(path, file_id, name, values, err)
        character(len=*), intent(in) :: path, name
        integer(hid_t), intent(in) :: file_id
        real(wp), allocatable, intent(out) :: values(:, :, :)
        type(error_t), allocatable, intent(out) :: err
        integer(hid_t) :: dset_id
        integer(hsize_t) :: dims(3)
        integer :: hdferr
        allocate (values(0, 0, 0))
        if (.not. open_if_present(path, file_id, name, dset_id, err)) return
        call extents(path, name, dset_id, 3, dims, err)
        if (.not. allocated(err)) then
            deallocate (values)
            allocate (values(dims(1), dims(2), dims(3)))
            if (product(dims) > 0) then
                call h5dread_f(dset_id, h5kind_to_type(wp, H5_REAL_KIND), values, dims, hdferr)
                if (hdferr < 0) call make_error(err, ERR_IO, path//': '//name//': cannot read')
            end if
        end if
        call h5dclose_f(dset_id, hdferr)
    end subroutine read_series_3d

    !> Open a dataset if it exists; false (and no error) if it does not.
    logical function open_if_present(path, file_id, name, dset_id, err) result(opened)
        character(len=*), intent(in) :: path, name
        integer(hid_t), intent(in) :: file_id
        integer(hid_t), intent(out) :: dset_id
        type(error_t), allocatable, intent(inout) :: err
        logical :: exists
        integer :: hdferr, slash
        opened = .false.
        dset_id = -1
        ! the parent group must exist before its member can be asked about
        slash = index(name, '/', back=.true.)
        if (slash > 1) then
            call h5lexists_f(file_id, name(:slash - 1), exists, hdferr)
            if (hdferr < 0 .or. .not. exists) return
        end if
        call h5lexists_f(file_id, name, exists, hdferr)
        if (hdferr < 0 .or. .not. exists) return
        call h5dopen_f(file_id, name, dset_id, hdferr)
        if (hdferr < 0) then
            call make_error(err, ERR_IO, path//': '//name//': cannot open dataset')
            return
        end if
        opened = .true.
    end function open_if_present

    !> The extents of a dataset of the expected rank (Fortran order).
    subroutine extents(path, name, dset_id, rank, dims, err)
        character(len=*), intent(in) :: path, name
        integer(hid_t), intent(in) :: dset_id
        integer, intent(in) :: rank
        integer(hsize_t), intent(out) :: dims(rank)
        type(error_t), allocatable, intent(out) :: err
        integer(hid_t) :: space_id
        integer(hsize_t) :: maxdims(rank)
        integer :: hdferr, actual
        dims = 0
        call h5dget_space_f(dset_id, space_id, hdferr)
        if (hdferr < 0) then
            call make_error(err, ERR_IO, path//': '//name//': cannot get dataspace')
            return
        end if
        call h5sget_simple_extent_ndims_f(space_id, actual, hdferr)
        if (hdferr < 0 .or. actual /= rank) then
            call make_error(err, ERR_IO, path//': '//name//': not of rank '// &
                            achar(iachar('0') + rank))
        else
            call h5sget_simple_extent_dims_f(space_id, dims, maxdims, hdferr)
            if (hdferr < 0) call make_error(err, ERR_IO, path//': '//name//': cannot get extents')
        end if
        call h5sclose_f(space_id, hdferr)
    end subroutine extents
end module ropedyn_case_file
