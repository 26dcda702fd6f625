!> The one place that calls HDF5: a file object (create or open, groups, datasets of rank 0
!! to 3 with a `units` attribute and an optional `description`, columns of strings, string
!! attributes, the readers of run files, close) and extendible series for step-by-step
!! output. Every HDF5 return code is checked; errors are `ERR_IO` (a record of the wrong
!! size: `ERR_INTERNAL`) with messages naming the file and the object. h5py sees every
!! shape reversed, so time, the last Fortran axis of a series, is its first axis.
!!
!!     type(h5_file_t) :: h5
!!     call h5%create('out/x.h5', err)
!!     call h5%write('/modes/omega', omega, 'rad/s', err, 'natural angular frequencies')
!!     call h5%attribute('/', 'version', version_string, err)
!!     call h5%close(err)
!!
!! Values of any rank go to HDF5 through one pointer-based call per operation; the typed
!! procedures only pick the HDF5 type. Scalars get a scalar dataspace, strings are
!! fixed-length and null-padded (an empty string is one NUL byte, which readers see as '').
!! The library is opened with `h5open_f` once (each call of it copies the Fortran
!! interface's predefined types again and never frees the copies: 55 type ids a call, about
!! 30 KB), HDF5's own error printing silenced,
!! and never closed here: no module state, other HDF5 users undisturbed (HDF5 closes itself
!! at exit, unless a file failed to close: ropedyn_h5_glue.c). A failure's message ends
!! with the reason from HDF5's error stack (the system's, e.g. 'No space left on device'). An open `h5_file_t` or `h5_series_t` must not be copied (the copies would
!! share ids); series are closed by their owner before the file.
!!
!! Files and groups are here; attributes, datasets and readers in the submodule
!! ropedyn_h5_data, series in ropedyn_h5_series.
module ropedyn_h5
    use, intrinsic :: iso_c_binding, only: c_ptr, c_loc, c_null_ptr, c_char, c_int, c_null_char, &
        c_long_long
    use hdf5, only: hid_t, hsize_t, size_t, h5open_f, h5eset_auto_f, &
        h5fcreate_f, h5fopen_f, h5fclose_f, h5fflush_f, h5fget_filesize_f, H5F_ACC_TRUNC_F, H5F_ACC_RDONLY_F, &
        H5F_ACC_RDWR_F, H5F_SCOPE_GLOBAL_F, h5gcreate_f, h5gclose_f, h5lexists_f, &
        h5oopen_f, h5oclose_f, h5screate_f, h5screate_simple_f, h5sclose_f, &
        h5sselect_hyperslab_f, h5sget_simple_extent_ndims_f, h5sget_simple_extent_dims_f, &
        H5S_SCALAR_F, H5S_UNLIMITED_F, H5S_SELECT_SET_F, &
        h5pcreate_f, h5pclose_f, h5pset_chunk_f, H5P_DATASET_CREATE_F, H5P_DEFAULT_F, &
        h5dcreate_f, h5dopen_f, h5dclose_f, h5dwrite_f, h5dread_f, h5dset_extent_f, &
        h5dget_space_f, h5acreate_f, h5aopen_f, h5aclose_f, h5awrite_f, h5aread_f, &
        h5aexists_f, h5adelete_f, h5aget_type_f, h5tcopy_f, h5tclose_f, h5tset_size_f, &
        h5tget_size_f, h5tset_strpad_f, H5T_NATIVE_CHARACTER, H5T_STR_NULLPAD_F, &
        h5kind_to_type, H5_REAL_KIND, H5_INTEGER_KIND, h5dget_type_f, h5tget_class_f, &
        H5T_STRING_F, H5T_FLOAT_F, H5T_INTEGER_F, h5tis_variable_str_f, h5ldelete_f, &
        h5iis_valid_f
    use, intrinsic :: iso_fortran_env, only: int8
    use ropedyn_kinds, only: wp, i8
    use ropedyn_text, only: int_text, text_t, append_text
    use ropedyn_error, only: error_t, make_error, ERR_IO, ERR_INPUT, ERR_INTERNAL
    use ropedyn_os, only: special_file_reason, try_lock, lock_holder, ERRNO_EWOULDBLOCK
    implicit none
    private
    public :: held_open

    !> Target size of one chunk of a series, bytes.
    integer, parameter :: CHUNK_BYTES = 16384
    !> Most records in one chunk.
    integer, parameter :: MAX_CHUNK_RECORDS = 512

    !> One HDF5 file.
    type, public :: h5_file_t
        private
        character(len=:), allocatable :: path   !< as given to create/open
        integer(hid_t) :: id = -1
        logical :: is_open = .false.
        logical :: memory = .false.             !< created in memory (`create`'s memory)
    contains
        procedure :: create => h5_create
        procedure :: in_memory => h5_in_memory
        procedure :: image => h5_image
        procedure :: open => h5_open
        procedure :: close => h5_close
        procedure :: flush => h5_flush
        procedure :: file_name => h5_file_name
        procedure :: size => h5_size
        procedure :: group => h5_group
        procedure :: exists => h5_exists
        procedure :: attribute => h5_attribute
        procedure :: read_attribute => h5_read_attribute
        procedure, private :: write_real, write_int64
        generic :: write => write_real, write_int64
        procedure :: write_text => h5_write_text
        procedure, private :: read_real_scalar, read_int64_scalar
        generic :: read_scalar => read_real_scalar, read_int64_scalar
        procedure :: read_reals => h5_read_reals
        procedure :: extents => h5_extents
        procedure :: read_record => h5_read_record
        procedure :: read_texts => h5_read_texts
        procedure :: create_series => h5_create_series
        procedure :: create_text_series => h5_create_text_series
        procedure :: open_series => h5_open_series
        procedure :: delete_attribute => h5_delete_attribute
        final :: h5_final
    end type h5_file_t

    !> An extendible, chunked dataset with time on its last Fortran axis, open while the
    !! run writes it (real(wp), default-integer or int64 records).
    type, public :: h5_series_t
        private
        character(len=:), allocatable :: path     !< its file, for messages
        character(len=:), allocatable :: name     !< absolute path in the file
        integer(hid_t) :: id = -1
        integer :: rank = 1                       !< Fortran rank including the time axis
        integer(hsize_t) :: record_dims(2) = 1    !< extents of one record (first rank-1 used)
        integer :: text_width = 0                 !< a series of strings: their width, else 0
        !> what open_series found: its values (SERIES_REAL, _INTEGER, _TEXT, 0: other) and
        !! whether it can grow along time (unlimited)
        integer :: value_class = 0
        logical :: extendible = .true.
    contains
        procedure, private :: append_real, append_integer, append_int64
        generic :: append => append_real, append_integer, append_int64
        procedure :: append_text => series_append_text
        procedure :: length => series_length
        procedure :: record_size => series_record_size
        procedure :: truncate => series_truncate
        procedure :: close => series_close
        procedure :: unfit => series_unfit
    end type h5_series_t

    !> The values of a series (h5_series_t%value_class).
    integer, parameter, public :: SERIES_REAL = 1, SERIES_INTEGER = 2, SERIES_TEXT = 3

    interface
        !> Before the library is first opened: its end at exit (ropedyn_h5_glue.c).
        subroutine c_h5_prepare() bind(C, name='ropedyn_h5_prepare')
        end subroutine c_h5_prepare
        !> A file or dataset failed to close: the library is not ended at exit.
        subroutine c_h5_close_failed() bind(C, name='ropedyn_h5_close_failed')
        end subroutine c_h5_close_failed

        !> A variable-length string attribute (ropedyn_h5_glue.c).
        integer(c_int) function c_h5_vlen_attribute(loc, name, buf, size) &
                bind(C, name='ropedyn_h5_vlen_attribute')
            import :: c_char, c_int, hid_t
            integer(hid_t), value :: loc
            character(kind=c_char), intent(in) :: name(*)
            character(kind=c_char), intent(out) :: buf(*)
            integer(c_int), value :: size
        end function c_h5_vlen_attribute

        !> A file in memory, and its image (ropedyn_h5_glue.c).
        integer(hid_t) function c_h5_create_memory(name) bind(C, name='ropedyn_h5_create_memory')
            import :: c_char, hid_t
            character(kind=c_char), intent(in) :: name(*)
        end function c_h5_create_memory
        integer(c_long_long) function c_h5_image(file, buf, size) bind(C, name='ropedyn_h5_image')
            import :: c_long_long, c_ptr, hid_t
            integer(hid_t), value :: file
            type(c_ptr), value :: buf
            integer(c_long_long), value :: size
        end function c_h5_image

        !> HDF5's reason of its last failure (ropedyn_h5_glue.c).
        integer(c_int) function c_h5_reason(buf, size) bind(C, name='ropedyn_h5_reason')
            import :: c_char, c_int
            character(kind=c_char), intent(out) :: buf(*)
            integer(c_int), value :: size
        end function c_h5_reason

        !> Create the empty series `name` whose records have extents `record_dims` (none for a
        !! scalar time series; at most 2), of real(wp) values or, with `is_integer`, default
        !! integers (int64 with `wide`: counters); write its units (and `columns`, if not
        !! empty). The series stays open.
        module subroutine h5_create_series(self, series, name, record_dims, is_integer, units, &
                                           columns, err, wide)
            class(h5_file_t), intent(inout) :: self
            type(h5_series_t), intent(inout) :: series
            character(len=*), intent(in) :: name
            integer(hsize_t), intent(in) :: record_dims(:)
            logical, intent(in) :: is_integer
            character(len=*), intent(in) :: units
            character(len=*), intent(in) :: columns
            type(error_t), allocatable, intent(out) :: err
            logical, intent(in), optional :: wide
        end subroutine h5_create_series

        !> Open the HDF5 library (idempotent) and silence HDF5's own error printing.
        module subroutine library_acquire(path, err)
            character(len=*), intent(in) :: path
            type(error_t), allocatable, intent(out) :: err
        end subroutine library_acquire

        !> Create (or overwrite) the file `path`; its directory must exist. A file still open
        !! in this object is closed first. An existing `path` that is not a regular file (a
        !! device, a FIFO, a link to one) is bad input and left alone; one that another
        !! program holds open (locked) is not truncated. Errors give the system's reason.
        !! With `memory`, the file is made in memory only (`path` names it, unique among
        !! the files open in the process; nothing is written to disk): `image` gives it.
        module subroutine h5_create(self, path, err, memory)
            class(h5_file_t), intent(inout) :: self
            character(len=*), intent(in) :: path
            type(error_t), allocatable, intent(out) :: err
            logical, intent(in), optional :: memory
        end subroutine h5_create

        !> Open the existing file `path`, read-only unless `writable`; a missing file, or one
        !! that is not a regular file, is bad input (ERR_INPUT: the user named it), one that
        !! cannot be opened an I/O error naming the reason (the process that holds it
        !! locked).
        module subroutine h5_open(self, path, err, writable)
            class(h5_file_t), intent(inout) :: self
            character(len=*), intent(in) :: path
            type(error_t), allocatable, intent(out) :: err
            logical, intent(in), optional :: writable
        end subroutine h5_open

        !> An ERR_IO error (replacing one in `err`): `message` and the reason HDF5 gives for
        !! its last failure (the system's, e.g. 'No space left on device', when a system call
        !! failed).
        module subroutine h5_error(err, message)
            type(error_t), allocatable, intent(inout) :: err
            character(len=*), intent(in) :: message
        end subroutine h5_error

        !> The errno of the system call behind HDF5's last failure (0: none) and, in
        !! `reason`, that failure in words (ropedyn_h5_glue.c); to be read before the next
        !! HDF5 call, which clears it.
        module function h5_reason(reason) result(errnum)
            character(len=:), allocatable, intent(out), optional :: reason
            integer :: errnum
        end function h5_reason

        !> Create the empty series `name` of strings of `width` characters (one per record),
        !! with its units. The series stays open.
        module subroutine h5_create_text_series(self, series, name, width, units, err)
            class(h5_file_t), intent(inout) :: self
            type(h5_series_t), intent(inout) :: series
            character(len=*), intent(in) :: name
            integer, intent(in) :: width
            character(len=*), intent(in) :: units
            type(error_t), allocatable, intent(out) :: err
        end subroutine h5_create_text_series

        !> Open the existing series `name` (an extendible dataset written by a series, of
        !! numbers or strings) to append to it. The series stays open.
        module subroutine h5_open_series(self, series, name, err)
            class(h5_file_t), intent(inout) :: self
            type(h5_series_t), intent(inout) :: series
            character(len=*), intent(in) :: name
            type(error_t), allocatable, intent(out) :: err
        end subroutine h5_open_series

        !> Number of records of an open series (-1 if it cannot be had).
        module function series_length(self) result(records)
            class(h5_series_t), intent(in) :: self
            integer(hsize_t) :: records
        end function series_length

        !> Why an open series cannot be continued as one of `value_class` (SERIES_*): ''
        !! when it can, else e.g. 'not extendible (a fixed-size dataset)'.
        module function series_unfit(self, value_class) result(reason)
            class(h5_series_t), intent(in) :: self
            integer, intent(in) :: value_class
            character(len=:), allocatable :: reason
        end function series_unfit

        !> Number of values in one record of a series.
        pure module function series_record_size(self) result(n)
            class(h5_series_t), intent(in) :: self
            integer :: n
        end function series_record_size

        !> Cut an open series to its first `records` records (nothing when it has no more).
        module subroutine series_truncate(self, records, err)
            class(h5_series_t), intent(inout) :: self
            integer(hsize_t), intent(in) :: records
            type(error_t), allocatable, intent(out) :: err
        end subroutine series_truncate

        !> Write record number `record` of a series of strings (`value` clipped or padded to
        !! the width).
        module subroutine series_append_text(self, record, value, err)
            class(h5_series_t), intent(inout) :: self
            integer(hsize_t), intent(in) :: record
            character(len=*), intent(in) :: value
            type(error_t), allocatable, intent(out) :: err
        end subroutine series_append_text

        !> The strings of the rank-1 dataset `name` of fixed-length strings (a series of
        !! strings, create_text_series), each up to its first NUL and without trailing
        !! blanks; none when the dataset is absent.
        module subroutine h5_read_texts(self, name, lines, err)
            class(h5_file_t), intent(inout) :: self
            character(len=*), intent(in) :: name
            type(text_t), allocatable, intent(out) :: lines(:)
            type(error_t), allocatable, intent(out) :: err
        end subroutine h5_read_texts

        !> Read record `record` (1-based) of the real series `name` (a dataset whose last
        !! Fortran axis is time): its values in Fortran order.
        module subroutine h5_read_record(self, name, record, values, err)
            class(h5_file_t), intent(inout) :: self
            character(len=*), intent(in) :: name
            integer(hsize_t), intent(in) :: record
            real(wp), allocatable, target, intent(out) :: values(:)
            type(error_t), allocatable, intent(out) :: err
        end subroutine h5_read_record

        !> Close the series' dataset (nothing to do when it is not open).
        module subroutine series_close(self, err)
            class(h5_series_t), intent(inout) :: self
            type(error_t), allocatable, intent(out) :: err
        end subroutine series_close

        !> Write record number `record` (1-based; the series is extended to `record` records):
        !! `values` is the record in Fortran order; or several records at once, `values` the
        !! records `record`, `record` + 1, ... one after the other (one HDF5 write for all).
        module subroutine append_real(self, record, values, err)
            class(h5_series_t), intent(inout) :: self
            integer(hsize_t), intent(in) :: record
            real(wp), intent(in), target :: values(:)
            type(error_t), allocatable, intent(out) :: err
        end subroutine append_real

        !> Write record number `record` of an integer series, as `append_real`.
        module subroutine append_integer(self, record, values, err)
            class(h5_series_t), intent(inout) :: self
            integer(hsize_t), intent(in) :: record
            integer, intent(in), target :: values(:)
            type(error_t), allocatable, intent(out) :: err
        end subroutine append_integer

        !> Write record number `record` of an integer series, as `append_real` (HDF5 converts
        !! the values to the series' own integers).
        module subroutine append_int64(self, record, values, err)
            class(h5_series_t), intent(inout) :: self
            integer(hsize_t), intent(in) :: record
            integer(i8), intent(in), target :: values(:)
            type(error_t), allocatable, intent(out) :: err
        end subroutine append_int64

        !> Whether an HDF5 call failed (hdferr < 0); then err says `message` (ERR_IO) and `id`,
        !! the identifier the call was to give, is marked as none (-1). The message is built
        !! before the call, also on success: the calls made for every record (write_record,
        !! select_record, series_append_text) test hdferr themselves.
        module function h5_failed(hdferr, message, err, id) result(failed)
            integer, intent(in) :: hdferr
            character(len=*), intent(in) :: message
            type(error_t), allocatable, intent(inout) :: err
            integer(hid_t), intent(inout), optional :: id
            logical :: failed
        end function h5_failed

        !> A fixed-length, null-padded string type of `width` characters (at least 1).
        module subroutine string_type(width, type_id, hdferr)
            integer, intent(in) :: width
            integer(hid_t), intent(out) :: type_id
            integer, intent(out) :: hdferr
        end subroutine string_type

        !> Write (or replace) a scalar string attribute `name` on the open object `loc_id`
        !! (`where` names the object in messages).
        module subroutine string_attribute(path, loc_id, where, name, value, err)
            character(len=*), intent(in) :: path
            integer(hid_t), intent(in) :: loc_id
            character(len=*), intent(in) :: where, name, value
            type(error_t), allocatable, intent(out) :: err
        end subroutine string_attribute

        !> Real dataset `name` (rank 0 to 3, Fortran shape) with its units and a description
        !! (none when absent or ''). An existing dataset of that name is overwritten (its
        !! attributes are kept).
        module subroutine write_real(self, name, values, units, err, description)
            class(h5_file_t), intent(inout) :: self
            character(len=*), intent(in) :: name, units
            real(wp), intent(in), target :: values(..)
            type(error_t), allocatable, intent(out) :: err
            character(len=*), intent(in), optional :: description
        end subroutine write_real

        !> 64-bit integer dataset `name` (rank 0 to 3), as `write_real`.
        module subroutine write_int64(self, name, values, units, err, description)
            class(h5_file_t), intent(inout) :: self
            character(len=*), intent(in) :: name, units
            integer(i8), intent(in), target :: values(..)
            type(error_t), allocatable, intent(out) :: err
            character(len=*), intent(in), optional :: description
        end subroutine write_int64

        !> A column of strings: a 1-d fixed-length, null-padded string dataset of width
        !! len(values) >= 1 (shorter entries NUL-padded by the caller: trailing blanks are kept).
        module subroutine h5_write_text(self, name, values, units, err)
            class(h5_file_t), intent(inout) :: self
            character(len=*), intent(in) :: name, units
            character(len=*), intent(in), target :: values(:)
            type(error_t), allocatable, intent(out) :: err
        end subroutine h5_write_text

        !> Create dataset `name` of `type_id` with Fortran extents `dims` (none: scalar); with
        !! `max_dims` and `chunk` extendible and chunked. `dset_id` is open only on success.
        module subroutine new_dataset(self, name, type_id, dims, dset_id, err, max_dims, chunk)
            class(h5_file_t), intent(inout) :: self
            character(len=*), intent(in) :: name
            integer(hid_t), intent(in) :: type_id
            integer(hsize_t), intent(in) :: dims(:)
            integer(hid_t), intent(out) :: dset_id
            type(error_t), allocatable, intent(out) :: err
            integer(hsize_t), intent(in), optional :: max_dims(:), chunk(:)
        end subroutine new_dataset

        !> A scalar string attribute of the root group, NULs removed ('' when missing). Without
        !! `found` a missing attribute is an error.
        module subroutine h5_read_attribute(self, name, value, err, found)
            class(h5_file_t), intent(inout) :: self
            character(len=*), intent(in) :: name
            character(len=:), allocatable, intent(out) :: value
            type(error_t), allocatable, intent(out) :: err
            logical, intent(out), optional :: found
        end subroutine h5_read_attribute

        !> A scalar real dataset; `value` is unchanged when it is absent.
        module subroutine read_real_scalar(self, name, value, err)
            class(h5_file_t), intent(inout) :: self
            character(len=*), intent(in) :: name
            real(wp), intent(inout), target :: value
            type(error_t), allocatable, intent(out) :: err
        end subroutine read_real_scalar

        !> A scalar 64-bit integer dataset; `value` is unchanged when it is absent.
        module subroutine read_int64_scalar(self, name, value, err)
            class(h5_file_t), intent(inout) :: self
            character(len=*), intent(in) :: name
            integer(i8), intent(inout), target :: value
            type(error_t), allocatable, intent(out) :: err
        end subroutine read_int64_scalar

        !> A real dataset of rank size(dims) >= 1: its values in Fortran order and its Fortran
        !! extents `dims` (a missing dataset reads as empty, extents 0).
        module subroutine h5_read_reals(self, name, values, dims, err)
            class(h5_file_t), intent(inout) :: self
            character(len=*), intent(in) :: name
            real(wp), allocatable, target, intent(out) :: values(:)
            integer(hsize_t), intent(out) :: dims(:)
            type(error_t), allocatable, intent(out) :: err
        end subroutine h5_read_reals

        !> The Fortran extents `dims` of the dataset `name`, which must have rank size(dims),
        !! without reading its values (to read one record of a series, read_record); a
        !! missing dataset has extents 0. The errors are read_reals'.
        module subroutine h5_extents(self, name, dims, err)
            class(h5_file_t), intent(inout) :: self
            character(len=*), intent(in) :: name
            integer(hsize_t), intent(out) :: dims(:)
            type(error_t), allocatable, intent(out) :: err
        end subroutine h5_extents
    end interface

contains

    !> `err` is h5%open's refusal of a file another process holds open (HDF5's lock; the
    !! message of ropedyn_h5_files's h5_open, "PATH: cannot open: locked by ..."): a file
    !! being written or read, not a damaged one or no HDF5 file.
    pure logical function held_open(err)
        type(error_t), intent(in) :: err
        held_open = index(err%message, ': cannot open: locked by ') > 0
    end function held_open

    ! ---------------------------------------------------------------------------------------
    ! Library and file life cycle
    ! ---------------------------------------------------------------------------------------

    !> Close the file (nothing to do when it is not open). Its series must be closed first.
    subroutine h5_close(self, err)
        class(h5_file_t), intent(inout) :: self
        type(error_t), allocatable, intent(out) :: err
        integer :: hdferr
        if (.not. self%is_open) return
        call h5fclose_f(self%id, hdferr)
        self%is_open = .false.
        self%id = -1
        if (hdferr < 0) then
            call h5_error(err, self%path//': cannot close file')
            call c_h5_close_failed()
        end if
    end subroutine h5_close

    !> Close a file left open (no error can be reported here).
    impure elemental subroutine h5_final(self)
        type(h5_file_t), intent(inout) :: self
        integer :: hdferr
        if (self%is_open) call h5fclose_f(self%id, hdferr)
        if (self%is_open .and. hdferr < 0) call c_h5_close_failed()
        self%is_open = .false.
    end subroutine h5_final

    !> Whether the file was created in memory.
    pure logical function h5_in_memory(self)
        class(h5_file_t), intent(in) :: self
        h5_in_memory = self%memory
    end function h5_in_memory

    !> The bytes of the open file, as they would be on disk (an HDF5 file image: h5py
    !! opens it from a file-like object).
    subroutine h5_image(self, image, err)
        class(h5_file_t), intent(inout) :: self
        integer(int8), allocatable, target, intent(out) :: image(:)
        type(error_t), allocatable, intent(out) :: err
        integer(c_long_long) :: size
        size = c_h5_image(self%id, c_null_ptr, 0_c_long_long)
        if (size >= 0) then
            allocate (image(max(1_c_long_long, size)))
            size = c_h5_image(self%id, c_loc(image), size)
        end if
        if (size < 0) then
            call h5_error(err, self%path//': cannot take the image of the file')
            return
        end if
        image = image(1:size)
    end subroutine h5_image

    !> Write everything buffered to disk.
    subroutine h5_flush(self, err)
        class(h5_file_t), intent(inout) :: self
        type(error_t), allocatable, intent(out) :: err
        integer :: hdferr
        call h5fflush_f(self%id, H5F_SCOPE_GLOBAL_F, hdferr)
        if (hdferr < 0) call h5_error(err, self%path//': cannot flush file')
    end subroutine h5_flush

    !> The size of the open file as HDF5 sees it (its end of allocated space, which may lie
    !! beyond what is written yet), bytes; 0 when it cannot be had.
    integer(i8) function h5_size(self) result(bytes)
        class(h5_file_t), intent(in) :: self
        integer(hsize_t) :: size
        integer :: hdferr
        bytes = 0
        if (.not. self%is_open) return
        call h5fget_filesize_f(self%id, size, hdferr)
        if (hdferr >= 0) bytes = int(size, i8)
    end function h5_size

    !> The path given to the last successful create/open ('' if none).
    pure function h5_file_name(self) result(path)
        class(h5_file_t), intent(in) :: self
        character(len=:), allocatable :: path
        path = ''
        if (allocated(self%path)) path = self%path
    end function h5_file_name

    ! ---------------------------------------------------------------------------------------
    ! Groups and objects
    ! ---------------------------------------------------------------------------------------

    !> Create group `name` (its parent must exist).
    subroutine h5_group(self, name, err)
        class(h5_file_t), intent(inout) :: self
        character(len=*), intent(in) :: name
        type(error_t), allocatable, intent(out) :: err
        integer(hid_t) :: group_id
        integer :: hdferr
        call h5gcreate_f(self%id, name, group_id, hdferr)
        if (h5_failed(hdferr, self%path//': '//name//': cannot create group', err)) return
        call h5gclose_f(group_id, hdferr)
        if (hdferr < 0) call h5_error(err, self%path//': '//name// &
                                        ': cannot close group')
    end subroutine h5_group

    !> Whether the object `name` exists (its parents are asked about first, as HDF5
    !! requires); an HDF5 failure counts as absent.
    logical function h5_exists(self, name) result(exists)
        class(h5_file_t), intent(in) :: self
        character(len=*), intent(in) :: name
        integer :: hdferr, k
        exists = .false.
        if (.not. self%is_open) return
        do k = 2, len(name) - 1
            if (name(k:k) /= '/') cycle
            call h5lexists_f(self%id, name(:k - 1), exists, hdferr)
            if (hdferr < 0 .or. .not. exists) then
                exists = .false.
                return
            end if
        end do
        call h5lexists_f(self%id, name, exists, hdferr)
        if (hdferr < 0) exists = .false.
    end function h5_exists

    !> Remove the attribute `name` of the object `where` ('/' for the root), if it has one.
    subroutine h5_delete_attribute(self, where, name, err)
        class(h5_file_t), intent(inout) :: self
        character(len=*), intent(in) :: where, name
        type(error_t), allocatable, intent(out) :: err
        integer(hid_t) :: obj
        integer :: hdferr
        logical :: exists
        call h5oopen_f(self%id, where, obj, hdferr)
        if (h5_failed(hdferr, self%path//': '//where//': cannot open object', err)) return
        call h5aexists_f(obj, name, exists, hdferr)
        if (hdferr >= 0 .and. exists) call h5adelete_f(obj, name, hdferr)
        if (hdferr < 0) call h5_error(err, self%path//': '//where//' attribute '// &
                                        name//': cannot delete')
        call h5oclose_f(obj, hdferr)
    end subroutine h5_delete_attribute

    !> String attribute `name` on the object `where` ('/' for the root), replacing an old one.
    subroutine h5_attribute(self, where, name, value, err)
        class(h5_file_t), intent(inout) :: self
        character(len=*), intent(in) :: where, name, value
        type(error_t), allocatable, intent(out) :: err
        integer(hid_t) :: obj
        integer :: hdferr
        call h5oopen_f(self%id, where, obj, hdferr)
        if (h5_failed(hdferr, self%path//': '//where//': cannot open object', err)) return
        call string_attribute(self%path, obj, where, name, value, err)
        call h5oclose_f(obj, hdferr)
    end subroutine h5_attribute
end module ropedyn_h5
