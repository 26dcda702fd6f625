!> HDF5 output of one simulation run: one file per run, appended one output time at a time.
!!
!! Layout (as h5py sees it; Fortran writes the reversed shape, so time is the last Fortran
!! axis and the first h5py axis). All step-by-step datasets are chunked and extendible.
!!
!!     /time                   (times,)               s
!!     /state/q                (times, elements, 3)   m, m, rad     columns = 'x, y, phi'
!!     /state/qdot             (times, elements, 3)   m/s, m/s, rad/s
!!     /rope/points            (times, 2*elements, 2) m             columns = 'x, y'
!!     /rope/element_length    (elements,)            m   (written once at create)
!!     /rope/element_mass      (elements,)            kg  (written once at create)
!!     /energy/{kinetic, elastic, gravity, dissipated, support_work, total} (times,) J
!!     /solver/step_size       (times,)               s
!!     /solver/order           (times,)               1
!!     /solver/{steps, rhs_evals, jac_evals, lin_setups, err_test_fails, nonlin_iters,
!!              nonlin_conv_fails} () int64 1;  /solver/cpu_time () s   (write_stats)
!!
!! Root attributes: status ('running' | 'complete' | 'failed'), reason (failed only),
!! version, model, method, scene, created, units_convention. See docs/output.md.
!!
!! The file is flushed after every `append`, so a run that crashes leaves readable data up to
!! its last output time with status 'running'. `/time` is written last in each record, so
!! its length is the number of complete records.
!!
!! `create` calls `h5open_f` (which may be called any number of times) and silences HDF5's
!! error printing; the library is never closed here, so the module keeps no state of its own
!! and other HDF5 users in the process are not disturbed (HDF5 closes itself at exit).
!! An `output_file_t` must not be copied while open (both copies would hold the same ids).
module ropedyn_output
    use hdf5, only: hid_t, hsize_t, size_t, h5open_f, h5eset_auto_f, &
        h5fcreate_f, h5fclose_f, h5fflush_f, H5F_ACC_TRUNC_F, H5F_SCOPE_GLOBAL_F, &
        h5gcreate_f, h5gclose_f, h5lexists_f, &
        h5screate_f, h5screate_simple_f, h5sclose_f, h5sselect_hyperslab_f, &
        H5S_SCALAR_F, H5S_UNLIMITED_F, H5S_SELECT_SET_F, &
        h5pcreate_f, h5pclose_f, h5pset_chunk_f, H5P_DATASET_CREATE_F, &
        h5dcreate_f, h5dopen_f, h5dclose_f, h5dwrite_f, h5dset_extent_f, h5dget_space_f, &
        h5acreate_f, h5aclose_f, h5awrite_f, h5aexists_f, h5adelete_f, &
        h5tcopy_f, h5tclose_f, h5tset_size_f, h5tset_strpad_f, &
        H5T_NATIVE_CHARACTER, H5T_STR_NULLPAD_F, h5kind_to_type, H5_REAL_KIND, H5_INTEGER_KIND
    use ropedyn_kinds, only: wp, i8
    use ropedyn_os, only: utc_timestamp
    use ropedyn_text, only: int_text
    use ropedyn_error, only: error_t, make_error, ERR_IO, ERR_INTERNAL
    use ropedyn_rope_model, only: energy_t
    use ropedyn_integrator, only: solver_stats_t
    implicit none
    private
    public :: output_file_t

    !> The convention written into every file (root attribute `units_convention`).
    character(len=*), parameter :: units_convention = &
        'SI; x points down (gravity), y horizontal, angles from x towards y'

    !> Indices of the step-by-step datasets in `output_file_t%series`.
    integer, parameter :: S_TIME = 1, S_Q = 2, S_QDOT = 3, S_POINTS = 4, S_KINETIC = 5, &
        S_ELASTIC = 6, S_GRAVITY = 7, S_DISSIPATED = 8, S_SUPPORT_WORK = 9, S_TOTAL = 10, &
        S_STEP_SIZE = 11, S_ORDER = 12
    integer, parameter :: N_SERIES = 12

    !> Target size of one chunk of a step-by-step dataset, bytes.
    integer, parameter :: CHUNK_BYTES = 16384
    !> Most records in one chunk.
    integer, parameter :: MAX_CHUNK_RECORDS = 512

    !> One extendible dataset with time on its last Fortran axis.
    type :: series_t
        character(len=:), allocatable :: name     !< absolute path in the file
        integer(hid_t) :: id = -1                 !< open dataset
        integer :: rank = 1                       !< Fortran rank including the time axis
        integer(hsize_t) :: record_dims(2) = 1    !< extents of one record (first rank-1 used)
    end type series_t

    !> One HDF5 file of one simulation run.
    type, public :: output_file_t
        private
        character(len=:), allocatable :: path     !< file name as given to create
        integer(hid_t) :: file_id = -1            !< open file
        logical :: is_open = .false.              !< create succeeded and close_run not yet done
        integer :: n_elements = 0                 !< elements of the rope
        integer(hsize_t) :: n_records = 0         !< complete records (length of /time)
        type(series_t) :: series(N_SERIES)        !< the step-by-step datasets
    contains
        procedure :: create => output_create
        procedure :: append => output_append
        procedure :: write_stats => output_write_stats
        procedure :: close_run => output_close_run
        final :: output_final
    end type output_file_t

contains

    !> Create (or overwrite) the file `path` and write the run's fixed data; status 'running'.
    !! The directory of `path` must exist. An object that is still open is closed first
    !! (its file keeps status 'running').
    subroutine output_create(self, path, n_elements, element_length, element_mass, model, &
                             method, version, scene_text, err)
        class(output_file_t), intent(inout) :: self
        character(len=*), intent(in) :: path              !< e.g. out/run.h5
        integer, intent(in) :: n_elements                 !< elements of the rope
        real(wp), intent(in) :: element_length(:)         !< (n_elements) m
        real(wp), intent(in) :: element_mass(:)           !< (n_elements) kg
        character(len=*), intent(in) :: model             !< e.g. rfem
        character(len=*), intent(in) :: method            !< integrator name as in &solver
        character(len=*), intent(in) :: version           !< code version
        character(len=*), intent(in) :: scene_text        !< effective namelist text
        type(error_t), allocatable, intent(out) :: err
        integer :: hdferr

        if (self%is_open) call shutdown(self)

        if (n_elements < 1) then
            call make_error(err, ERR_INTERNAL, path//': cannot create output for '// &
                            int_text(n_elements)//' elements')
            return
        end if
        if (size(element_length) /= n_elements .or. size(element_mass) /= n_elements) then
            call make_error(err, ERR_INTERNAL, path//': element_length has '// &
                            int_text(size(element_length))//' and element_mass '// &
                            int_text(size(element_mass))//' values, expected '// &
                            int_text(n_elements))
            return
        end if

        call library_acquire(path, err)
        if (allocated(err)) return

        call h5fcreate_f(path, H5F_ACC_TRUNC_F, self%file_id, hdferr)
        if (hdferr < 0) then
            if (directory_exists(path)) then
                call make_error(err, ERR_IO, path//': cannot create file (is it open in this '// &
                                'or another program, or is the directory read-only?)')
            else
                call make_error(err, ERR_IO, path// &
                                ': cannot create file (does the directory exist?)')
            end if
            return
        end if
        self%path = path
        self%is_open = .true.
        self%n_elements = n_elements
        self%n_records = 0

        call write_contents()
        if (allocated(err)) call shutdown(self)

    contains

        !> Everything after the file exists; on error `err` is set and the caller closes.
        subroutine write_contents()
            integer(hsize_t) :: n, n2
            n = int(n_elements, hsize_t)
            n2 = 2_hsize_t*n

            call write_string_attribute(self%path, self%file_id, '/', 'status', 'running', err)
            if (allocated(err)) return
            call write_string_attribute(self%path, self%file_id, '/', 'version', version, err)
            if (allocated(err)) return
            call write_string_attribute(self%path, self%file_id, '/', 'model', model, err)
            if (allocated(err)) return
            call write_string_attribute(self%path, self%file_id, '/', 'method', method, err)
            if (allocated(err)) return
            call write_string_attribute(self%path, self%file_id, '/', 'scene', scene_text, err)
            if (allocated(err)) return
            call write_string_attribute(self%path, self%file_id, '/', 'created', &
                                        utc_timestamp(), err)
            if (allocated(err)) return
            call write_string_attribute(self%path, self%file_id, '/', 'units_convention', &
                                        units_convention, err)
            if (allocated(err)) return

            call create_group(self, '/state', err)
            if (allocated(err)) return
            call create_group(self, '/rope', err)
            if (allocated(err)) return
            call create_group(self, '/energy', err)
            if (allocated(err)) return
            call create_group(self, '/solver', err)
            if (allocated(err)) return

            call create_series(self, S_TIME, '/time', [integer(hsize_t) ::], .false., 's', &
                               '', err)
            if (allocated(err)) return
            call create_series(self, S_Q, '/state/q', [3_hsize_t, n], .false., 'm, m, rad', &
                               'x, y, phi', err)
            if (allocated(err)) return
            call create_series(self, S_QDOT, '/state/qdot', [3_hsize_t, n], .false., &
                               'm/s, m/s, rad/s', 'xdot, ydot, phidot', err)
            if (allocated(err)) return
            call create_series(self, S_POINTS, '/rope/points', [2_hsize_t, n2], .false., 'm', &
                               'x, y', err)
            if (allocated(err)) return
            call create_series(self, S_KINETIC, '/energy/kinetic', [integer(hsize_t) ::], &
                               .false., 'J', '', err)
            if (allocated(err)) return
            call create_series(self, S_ELASTIC, '/energy/elastic', [integer(hsize_t) ::], &
                               .false., 'J', '', err)
            if (allocated(err)) return
            call create_series(self, S_GRAVITY, '/energy/gravity', [integer(hsize_t) ::], &
                               .false., 'J', '', err)
            if (allocated(err)) return
            call create_series(self, S_DISSIPATED, '/energy/dissipated', &
                               [integer(hsize_t) ::], .false., 'J', '', err)
            if (allocated(err)) return
            call create_series(self, S_SUPPORT_WORK, '/energy/support_work', &
                               [integer(hsize_t) ::], .false., 'J', '', err)
            if (allocated(err)) return
            call create_series(self, S_TOTAL, '/energy/total', [integer(hsize_t) ::], &
                               .false., 'J', '', err)
            if (allocated(err)) return
            call create_series(self, S_STEP_SIZE, '/solver/step_size', [integer(hsize_t) ::], &
                               .false., 's', '', err)
            if (allocated(err)) return
            call create_series(self, S_ORDER, '/solver/order', [integer(hsize_t) ::], &
                               .true., '1', '', err)
            if (allocated(err)) return

            call write_real_array(self, '/rope/element_length', element_length, 'm', err)
            if (allocated(err)) return
            call write_real_array(self, '/rope/element_mass', element_mass, 'kg', err)
            if (allocated(err)) return

            call h5fflush_f(self%file_id, H5F_SCOPE_GLOBAL_F, hdferr)
            if (hdferr < 0) call make_error(err, ERR_IO, self%path//': cannot flush file')
        end subroutine write_contents
    end subroutine output_create

    !> Append one output time and flush the file.
    subroutine output_append(self, t, q, qdot, points, energy, step_size, order, err)
        class(output_file_t), intent(inout) :: self
        real(wp), intent(in) :: t                 !< time, s
        real(wp), intent(in) :: q(:, :)           !< (3, n) x, y (m), phi (rad) per element
        real(wp), intent(in) :: qdot(:, :)        !< (3, n) rates: m/s, m/s, rad/s
        real(wp), intent(in) :: points(:, :)      !< (2, 2n) element end points A_1, B_1, ..., m
        type(energy_t), intent(in) :: energy      !< energies at t, J
        real(wp), intent(in) :: step_size         !< last step size, s
        integer, intent(in) :: order              !< last order
        type(error_t), allocatable, intent(out) :: err
        integer :: n, hdferr

        if (.not. self%is_open) then
            call make_error(err, ERR_INTERNAL, file_label(self)//': append: file is not open')
            return
        end if
        n = self%n_elements
        if (size(q, 1) /= 3 .or. size(q, 2) /= n) then
            call make_error(err, ERR_INTERNAL, self%path//': /state/q: record has shape ('// &
                            shape_text(shape(q))//'), expected (3, '//int_text(n)//')')
            return
        end if
        if (size(qdot, 1) /= 3 .or. size(qdot, 2) /= n) then
            call make_error(err, ERR_INTERNAL, self%path//': /state/qdot: record has shape ('// &
                            shape_text(shape(qdot))//'), expected (3, '//int_text(n)//')')
            return
        end if
        if (size(points, 1) /= 2 .or. size(points, 2) /= 2*n) then
            call make_error(err, ERR_INTERNAL, self%path//': /rope/points: record has shape ('// &
                            shape_text(shape(points))//'), expected (2, '//int_text(2*n)//')')
            return
        end if

        call append_real(self, S_Q, reshape(q, [size(q)]), err)
        if (allocated(err)) return
        call append_real(self, S_QDOT, reshape(qdot, [size(qdot)]), err)
        if (allocated(err)) return
        call append_real(self, S_POINTS, reshape(points, [size(points)]), err)
        if (allocated(err)) return
        call append_real(self, S_KINETIC, [energy%kinetic], err)
        if (allocated(err)) return
        call append_real(self, S_ELASTIC, [energy%elastic], err)
        if (allocated(err)) return
        call append_real(self, S_GRAVITY, [energy%gravity], err)
        if (allocated(err)) return
        call append_real(self, S_DISSIPATED, [energy%dissipated], err)
        if (allocated(err)) return
        call append_real(self, S_SUPPORT_WORK, [energy%support_work], err)
        if (allocated(err)) return
        call append_real(self, S_TOTAL, [energy%total()], err)
        if (allocated(err)) return
        call append_real(self, S_STEP_SIZE, [step_size], err)
        if (allocated(err)) return
        call append_integer(self, S_ORDER, [order], err)
        if (allocated(err)) return
        ! /time last: its length counts the complete records
        call append_real(self, S_TIME, [t], err)
        if (allocated(err)) return
        self%n_records = self%n_records + 1

        call h5fflush_f(self%file_id, H5F_SCOPE_GLOBAL_F, hdferr)
        if (hdferr < 0) call make_error(err, ERR_IO, self%path//': cannot flush file')
    end subroutine output_append

    !> Write the solver counters and the CPU time (also for a failed run); may be repeated.
    subroutine output_write_stats(self, stats, cpu_time, err)
        class(output_file_t), intent(inout) :: self
        type(solver_stats_t), intent(in) :: stats  !< counters of the integration
        real(wp), intent(in) :: cpu_time           !< CPU time of the run, s
        type(error_t), allocatable, intent(out) :: err
        integer :: hdferr

        if (.not. self%is_open) then
            call make_error(err, ERR_INTERNAL, &
                            file_label(self)//': write_stats: file is not open')
            return
        end if
        call write_scalar(self, '/solver/steps', '1', err, ivalue=stats%steps)
        if (allocated(err)) return
        call write_scalar(self, '/solver/rhs_evals', '1', err, ivalue=stats%rhs_evals)
        if (allocated(err)) return
        call write_scalar(self, '/solver/jac_evals', '1', err, ivalue=stats%jac_evals)
        if (allocated(err)) return
        call write_scalar(self, '/solver/lin_setups', '1', err, ivalue=stats%lin_setups)
        if (allocated(err)) return
        call write_scalar(self, '/solver/err_test_fails', '1', err, &
                          ivalue=stats%err_test_fails)
        if (allocated(err)) return
        call write_scalar(self, '/solver/nonlin_iters', '1', err, ivalue=stats%nonlin_iters)
        if (allocated(err)) return
        call write_scalar(self, '/solver/nonlin_conv_fails', '1', err, &
                          ivalue=stats%nonlin_conv_fails)
        if (allocated(err)) return
        call write_scalar(self, '/solver/cpu_time', 's', err, rvalue=cpu_time)
        if (allocated(err)) return

        call h5fflush_f(self%file_id, H5F_SCOPE_GLOBAL_F, hdferr)
        if (hdferr < 0) call make_error(err, ERR_IO, self%path//': cannot flush file')
    end subroutine output_write_stats

    !> Set the root status ('complete' or 'failed', with `reason` if failed) and close
    !! everything. The file is closed even when writing the status fails.
    subroutine output_close_run(self, status, reason, err)
        class(output_file_t), intent(inout) :: self
        character(len=*), intent(in) :: status            !< 'complete' or 'failed'
        character(len=*), intent(in), optional :: reason  !< error message (failed runs)
        type(error_t), allocatable, intent(out) :: err
        integer :: hdferr

        if (.not. self%is_open) then
            call make_error(err, ERR_INTERNAL, file_label(self)//': close_run: file is not open')
            return
        end if
        if (status /= 'complete' .and. status /= 'failed') then
            call make_error(err, ERR_INTERNAL, self%path//': close_run: status "'//status// &
                            '" is not one of complete, failed')
            return
        end if

        call write_string_attribute(self%path, self%file_id, '/', 'status', trim(status), err)
        if (.not. allocated(err) .and. status == 'failed') then
            if (present(reason)) then
                if (len_trim(reason) > 0) then
                    call write_string_attribute(self%path, self%file_id, '/', 'reason', &
                                                trim(reason), err)
                else
                    call write_string_attribute(self%path, self%file_id, '/', 'reason', &
                                                '(no reason given)', err)
                end if
            else
                call write_string_attribute(self%path, self%file_id, '/', 'reason', &
                                            '(no reason given)', err)
            end if
        end if
        if (.not. allocated(err)) then
            call h5fflush_f(self%file_id, H5F_SCOPE_GLOBAL_F, hdferr)
            if (hdferr < 0) call make_error(err, ERR_IO, self%path//': cannot flush file')
        end if

        if (allocated(err)) then
            call shutdown(self)
        else
            call shutdown(self, err)
        end if
    end subroutine output_close_run

    !> Close the file if still open; its status stays 'running'.
    impure elemental subroutine output_final(self)
        type(output_file_t), intent(inout) :: self
        if (self%is_open) call shutdown(self)
    end subroutine output_final

    ! ---------------------------------------------------------------------------------------
    ! Library and file life cycle
    ! ---------------------------------------------------------------------------------------

    !> Open the HDF5 library (idempotent) and silence HDF5's own error printing.
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
        if (hdferr < 0) then
            call make_error(err, ERR_IO, path//': cannot silence HDF5 error printing')
            return
        end if
    end subroutine library_acquire

    !> Close all datasets and the file and mark `self` closed.
    !! Reports the first failure in `err` if present; closes everything regardless.
    subroutine shutdown(self, err)
        type(output_file_t), intent(inout) :: self
        type(error_t), allocatable, intent(out), optional :: err
        integer :: k, hdferr
        character(len=:), allocatable :: message

        if (.not. self%is_open) return
        message = ''
        do k = 1, N_SERIES
            if (self%series(k)%id >= 0) then
                call h5dclose_f(self%series(k)%id, hdferr)
                if (hdferr < 0 .and. len(message) == 0) &
                    message = self%path//': '//self%series(k)%name//': cannot close dataset'
                self%series(k)%id = -1
            end if
        end do
        call h5fclose_f(self%file_id, hdferr)
        if (hdferr < 0 .and. len(message) == 0) message = self%path//': cannot close file'
        self%file_id = -1
        self%is_open = .false.
        if (present(err) .and. len(message) > 0) call make_error(err, ERR_IO, message)
    end subroutine shutdown

    ! ---------------------------------------------------------------------------------------
    ! Datasets, groups and attributes
    ! ---------------------------------------------------------------------------------------

    !> Create a group (and close it).
    subroutine create_group(self, name, err)
        type(output_file_t), intent(inout) :: self
        character(len=*), intent(in) :: name
        type(error_t), allocatable, intent(out) :: err
        integer(hid_t) :: group_id
        integer :: hdferr
        call h5gcreate_f(self%file_id, name, group_id, hdferr)
        if (hdferr < 0) then
            call make_error(err, ERR_IO, self%path//': '//name//': cannot create group')
            return
        end if
        call h5gclose_f(group_id, hdferr)
        if (hdferr < 0) call make_error(err, ERR_IO, self%path//': '//name// &
                                        ': cannot close group')
    end subroutine create_group

    !> Create an empty extendible, chunked dataset whose records have extents `record_dims`
    !! (empty for a scalar time series); write its units (and columns, if not empty).
    subroutine create_series(self, k, name, record_dims, is_integer, units, columns, err)
        type(output_file_t), intent(inout) :: self
        integer, intent(in) :: k
        character(len=*), intent(in) :: name
        integer(hsize_t), intent(in) :: record_dims(:)
        logical, intent(in) :: is_integer
        character(len=*), intent(in) :: units
        character(len=*), intent(in) :: columns
        type(error_t), allocatable, intent(out) :: err
        integer(hsize_t) :: dims(3), max_dims(3), chunk(3), record_bytes
        integer(hid_t) :: space_id, plist_id, type_id
        integer :: rank, hdferr

        rank = size(record_dims) + 1
        self%series(k)%name = name
        self%series(k)%rank = rank
        self%series(k)%record_dims = 1
        self%series(k)%record_dims(1:rank - 1) = record_dims

        if (is_integer) then
            type_id = h5kind_to_type(kind(0), H5_INTEGER_KIND)
            record_bytes = int(storage_size(0)/8, hsize_t)*product(record_dims)
        else
            type_id = h5kind_to_type(wp, H5_REAL_KIND)
            record_bytes = int(storage_size(1.0_wp)/8, hsize_t)*product(record_dims)
        end if
        dims(1:rank - 1) = record_dims
        dims(rank) = 0
        max_dims(1:rank - 1) = record_dims
        max_dims(rank) = H5S_UNLIMITED_F
        chunk(1:rank - 1) = record_dims
        chunk(rank) = max(1_hsize_t, min(int(MAX_CHUNK_RECORDS, hsize_t), &
                                         int(CHUNK_BYTES, hsize_t)/max(record_bytes, 1_hsize_t)))

        space_id = -1
        plist_id = -1
        steps: block
            call h5screate_simple_f(rank, dims(1:rank), space_id, hdferr, max_dims(1:rank))
            if (hdferr < 0) then
                call make_error(err, ERR_IO, self%path//': '//name//': cannot create dataspace')
                exit steps
            end if
            call h5pcreate_f(H5P_DATASET_CREATE_F, plist_id, hdferr)
            if (hdferr < 0) then
                call make_error(err, ERR_IO, self%path//': '//name// &
                                ': cannot create property list')
                exit steps
            end if
            call h5pset_chunk_f(plist_id, rank, chunk(1:rank), hdferr)
            if (hdferr < 0) then
                call make_error(err, ERR_IO, self%path//': '//name//': cannot set chunk size')
                exit steps
            end if
            call h5dcreate_f(self%file_id, name, type_id, space_id, self%series(k)%id, hdferr, &
                             dcpl_id=plist_id)
            if (hdferr < 0) then
                self%series(k)%id = -1
                call make_error(err, ERR_IO, self%path//': '//name//': cannot create dataset')
                exit steps
            end if
            call write_string_attribute(self%path, self%series(k)%id, name, 'units', units, err)
            if (allocated(err)) exit steps
            if (len(columns) > 0) then
                call write_string_attribute(self%path, self%series(k)%id, name, 'columns', &
                                            columns, err)
                if (allocated(err)) exit steps
            end if
        end block steps
        if (plist_id >= 0) call h5pclose_f(plist_id, hdferr)
        if (space_id >= 0) call h5sclose_f(space_id, hdferr)
    end subroutine create_series

    !> Extend series `k` by one record and write `values` (the record in Fortran order).
    subroutine append_real(self, k, values, err)
        type(output_file_t), intent(inout) :: self
        integer, intent(in) :: k
        real(wp), intent(in) :: values(:)
        type(error_t), allocatable, intent(out) :: err
        integer(hid_t) :: file_space, mem_space
        integer :: hdferr

        call select_new_record(self, k, size(values), file_space, mem_space, err)
        if (allocated(err)) return
        call h5dwrite_f(self%series(k)%id, h5kind_to_type(wp, H5_REAL_KIND), values, &
                        [int(size(values), hsize_t)], hdferr, mem_space_id=mem_space, &
                        file_space_id=file_space)
        if (hdferr < 0) call make_error(err, ERR_IO, self%path//': '//self%series(k)%name// &
                                        ': cannot write record '//int_text(int(self%n_records) + 1))
        call h5sclose_f(mem_space, hdferr)
        call h5sclose_f(file_space, hdferr)
    end subroutine append_real

    !> Extend integer series `k` by one record and write `values`.
    subroutine append_integer(self, k, values, err)
        type(output_file_t), intent(inout) :: self
        integer, intent(in) :: k
        integer, intent(in) :: values(:)
        type(error_t), allocatable, intent(out) :: err
        integer(hid_t) :: file_space, mem_space
        integer :: hdferr

        call select_new_record(self, k, size(values), file_space, mem_space, err)
        if (allocated(err)) return
        call h5dwrite_f(self%series(k)%id, h5kind_to_type(kind(0), H5_INTEGER_KIND), values, &
                        [int(size(values), hsize_t)], hdferr, mem_space_id=mem_space, &
                        file_space_id=file_space)
        if (hdferr < 0) call make_error(err, ERR_IO, self%path//': '//self%series(k)%name// &
                                        ': cannot write record '//int_text(int(self%n_records) + 1))
        call h5sclose_f(mem_space, hdferr)
        call h5sclose_f(file_space, hdferr)
    end subroutine append_integer

    !> Extend series `k` to n_records + 1 records and return a file space selecting the new
    !! record and a 1-D memory space of `n_values` values. Both are open only on success.
    subroutine select_new_record(self, k, n_values, file_space, mem_space, err)
        type(output_file_t), intent(inout) :: self
        integer, intent(in) :: k
        integer, intent(in) :: n_values
        integer(hid_t), intent(out) :: file_space, mem_space
        type(error_t), allocatable, intent(out) :: err
        integer(hsize_t) :: dims(3), start(3), count(3)
        integer :: rank, hdferr

        file_space = -1
        mem_space = -1
        associate (s => self%series(k))
            rank = s%rank
            if (int(product(s%record_dims(1:rank - 1))) /= n_values) then
                call make_error(err, ERR_INTERNAL, self%path//': '//s%name//': record of '// &
                                int_text(n_values)//' values, expected '// &
                                int_text(int(product(s%record_dims(1:rank - 1)))))
                return
            end if
            dims(1:rank - 1) = s%record_dims(1:rank - 1)
            dims(rank) = self%n_records + 1
            call h5dset_extent_f(s%id, dims(1:rank), hdferr)
            if (hdferr < 0) then
                call make_error(err, ERR_IO, self%path//': '//s%name//': cannot extend dataset')
                return
            end if
            call h5dget_space_f(s%id, file_space, hdferr)
            if (hdferr < 0) then
                file_space = -1
                call make_error(err, ERR_IO, self%path//': '//s%name//': cannot get dataspace')
                return
            end if
            start = 0
            start(rank) = self%n_records
            count(1:rank - 1) = s%record_dims(1:rank - 1)
            count(rank) = 1
            call h5sselect_hyperslab_f(file_space, H5S_SELECT_SET_F, start(1:rank), &
                                       count(1:rank), hdferr)
            if (hdferr < 0) then
                call h5sclose_f(file_space, hdferr)
                file_space = -1
                call make_error(err, ERR_IO, self%path//': '//s%name// &
                                ': cannot select record '//int_text(int(self%n_records) + 1))
                return
            end if
            call h5screate_simple_f(1, [int(n_values, hsize_t)], mem_space, hdferr)
            if (hdferr < 0) then
                call h5sclose_f(file_space, hdferr)
                file_space = -1
                mem_space = -1
                call make_error(err, ERR_IO, self%path//': '//s%name// &
                                ': cannot create memory dataspace')
                return
            end if
        end associate
    end subroutine select_new_record

    !> Write a fixed 1-D real dataset with its units.
    subroutine write_real_array(self, name, values, units, err)
        type(output_file_t), intent(inout) :: self
        character(len=*), intent(in) :: name
        real(wp), intent(in) :: values(:)
        character(len=*), intent(in) :: units
        type(error_t), allocatable, intent(out) :: err
        integer(hid_t) :: space_id, dset_id
        integer(hsize_t) :: dims(1)
        integer :: hdferr

        dims = int(size(values), hsize_t)
        call h5screate_simple_f(1, dims, space_id, hdferr)
        if (hdferr < 0) then
            call make_error(err, ERR_IO, self%path//': '//name//': cannot create dataspace')
            return
        end if
        steps: block
            call h5dcreate_f(self%file_id, name, h5kind_to_type(wp, H5_REAL_KIND), space_id, &
                             dset_id, hdferr)
            if (hdferr < 0) then
                call make_error(err, ERR_IO, self%path//': '//name//': cannot create dataset')
                exit steps
            end if
            call h5dwrite_f(dset_id, h5kind_to_type(wp, H5_REAL_KIND), values, dims, hdferr)
            if (hdferr < 0) then
                call make_error(err, ERR_IO, self%path//': '//name//': cannot write dataset')
            else
                call write_string_attribute(self%path, dset_id, name, 'units', units, err)
            end if
            call h5dclose_f(dset_id, hdferr)
            if (hdferr < 0 .and. .not. allocated(err)) &
                call make_error(err, ERR_IO, self%path//': '//name//': cannot close dataset')
        end block steps
        call h5sclose_f(space_id, hdferr)
    end subroutine write_real_array

    !> Write (or overwrite) a scalar dataset: int64 `ivalue` or real(wp) `rvalue`.
    subroutine write_scalar(self, name, units, err, ivalue, rvalue)
        type(output_file_t), intent(inout) :: self
        character(len=*), intent(in) :: name
        character(len=*), intent(in) :: units
        type(error_t), allocatable, intent(out) :: err
        integer(i8), intent(in), optional :: ivalue
        real(wp), intent(in), optional :: rvalue
        integer(hid_t) :: space_id, dset_id, type_id
        integer(hsize_t), parameter :: dims(1) = 1
        logical :: exists
        integer :: hdferr, create_err

        if (present(ivalue)) then
            type_id = h5kind_to_type(i8, H5_INTEGER_KIND)
        else
            type_id = h5kind_to_type(wp, H5_REAL_KIND)
        end if
        call h5lexists_f(self%file_id, name, exists, hdferr)
        if (hdferr < 0) then
            call make_error(err, ERR_IO, self%path//': '//name//': cannot check existence')
            return
        end if
        if (exists) then
            call h5dopen_f(self%file_id, name, dset_id, hdferr)
            if (hdferr < 0) then
                call make_error(err, ERR_IO, self%path//': '//name//': cannot open dataset')
                return
            end if
        else
            call h5screate_f(H5S_SCALAR_F, space_id, hdferr)
            if (hdferr < 0) then
                call make_error(err, ERR_IO, self%path//': '//name//': cannot create dataspace')
                return
            end if
            call h5dcreate_f(self%file_id, name, type_id, space_id, dset_id, create_err)
            call h5sclose_f(space_id, hdferr)
            if (create_err < 0) then
                call make_error(err, ERR_IO, self%path//': '//name//': cannot create dataset')
                return
            end if
        end if

        if (present(ivalue)) then
            call h5dwrite_f(dset_id, type_id, ivalue, dims, hdferr)
        else if (present(rvalue)) then
            call h5dwrite_f(dset_id, type_id, rvalue, dims, hdferr)
        else
            hdferr = -1
        end if
        if (hdferr < 0) then
            call make_error(err, ERR_IO, self%path//': '//name//': cannot write dataset')
        else if (.not. exists) then
            call write_string_attribute(self%path, dset_id, name, 'units', units, err)
        end if
        call h5dclose_f(dset_id, hdferr)
        if (hdferr < 0 .and. .not. allocated(err)) &
            call make_error(err, ERR_IO, self%path//': '//name//': cannot close dataset')
    end subroutine write_scalar

    !> Write (or replace) a scalar fixed-length string attribute `name` on object `loc_id`
    !! (`where` names the object in messages). Empty strings are stored as one NUL byte
    !! (null-padded, so readers see an empty string).
    subroutine write_string_attribute(path, loc_id, where, name, value, err)
        character(len=*), intent(in) :: path
        integer(hid_t), intent(in) :: loc_id
        character(len=*), intent(in) :: where
        character(len=*), intent(in) :: name
        character(len=*), intent(in) :: value
        type(error_t), allocatable, intent(out) :: err
        integer(hid_t) :: type_id, space_id, attr_id
        integer(hsize_t), parameter :: dims(1) = 1
        logical :: exists
        integer :: hdferr
        character(len=:), allocatable :: label

        label = path//': '//where//' attribute '//name
        type_id = -1
        space_id = -1
        attr_id = -1
        steps: block
            call h5aexists_f(loc_id, name, exists, hdferr)
            if (hdferr < 0) then
                call make_error(err, ERR_IO, label//': cannot check existence')
                exit steps
            end if
            if (exists) then
                call h5adelete_f(loc_id, name, hdferr)
                if (hdferr < 0) then
                    call make_error(err, ERR_IO, label//': cannot delete old value')
                    exit steps
                end if
            end if
            call h5tcopy_f(H5T_NATIVE_CHARACTER, type_id, hdferr)
            if (hdferr < 0) then
                type_id = -1
                call make_error(err, ERR_IO, label//': cannot copy string type')
                exit steps
            end if
            call h5tset_size_f(type_id, int(max(len(value), 1), size_t), hdferr)
            if (hdferr < 0) then
                call make_error(err, ERR_IO, label//': cannot set string length')
                exit steps
            end if
            call h5tset_strpad_f(type_id, H5T_STR_NULLPAD_F, hdferr)
            if (hdferr < 0) then
                call make_error(err, ERR_IO, label//': cannot set string padding')
                exit steps
            end if
            call h5screate_f(H5S_SCALAR_F, space_id, hdferr)
            if (hdferr < 0) then
                space_id = -1
                call make_error(err, ERR_IO, label//': cannot create dataspace')
                exit steps
            end if
            call h5acreate_f(loc_id, name, type_id, space_id, attr_id, hdferr)
            if (hdferr < 0) then
                attr_id = -1
                call make_error(err, ERR_IO, label//': cannot create attribute')
                exit steps
            end if
            if (len(value) > 0) then
                call h5awrite_f(attr_id, type_id, value, dims, hdferr)
            else
                call h5awrite_f(attr_id, type_id, achar(0), dims, hdferr)
            end if
            if (hdferr < 0) then
                call make_error(err, ERR_IO, label//': cannot write attribute')
                exit steps
            end if
        end block steps
        if (attr_id >= 0) then
            call h5aclose_f(attr_id, hdferr)
            if (hdferr < 0 .and. .not. allocated(err)) &
                call make_error(err, ERR_IO, label//': cannot close attribute')
        end if
        if (space_id >= 0) call h5sclose_f(space_id, hdferr)
        if (type_id >= 0) call h5tclose_f(type_id, hdferr)
    end subroutine write_string_attribute

    ! ---------------------------------------------------------------------------------------
    ! Small text helpers
    ! ---------------------------------------------------------------------------------------

    !> The path of the file, or a placeholder if create never succeeded.
    function file_label(self) result(label)
        type(output_file_t), intent(in) :: self
        character(len=:), allocatable :: label
        if (allocated(self%path)) then
            label = self%path
        else
            label = '(output file never created)'
        end if
    end function file_label

    !> Whether the directory part of `path` exists (gfortran's INQUIRE accepts directories;
    !! a compiler that does not merely gives the 'does the directory exist?' hint).
    function directory_exists(path) result(exists)
        character(len=*), intent(in) :: path
        logical :: exists
        integer :: slash, ios
        slash = index(path, '/', back=.true.)
        if (slash == 0) then
            inquire (file='.', exist=exists, iostat=ios)
        else if (slash == 1) then
            inquire (file='/', exist=exists, iostat=ios)
        else
            inquire (file=path(1:slash - 1), exist=exists, iostat=ios)
        end if
        if (ios /= 0) exists = .false.
    end function directory_exists


    !> "a, b" text of a shape.
    pure function shape_text(extents) result(text)
        integer, intent(in) :: extents(:)
        character(len=:), allocatable :: text
        integer :: k
        text = ''
        do k = 1, size(extents)
            if (k > 1) text = text//', '
            text = text//int_text(extents(k))
        end do
    end function shape_text
end module ropedyn_output
