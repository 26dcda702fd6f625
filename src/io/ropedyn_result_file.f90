!> A small HDF5 writer for one-shot results (statics, modes): create a file, write groups,
!! real and integer datasets of rank 0 to 3 with a `units` attribute (and an optional
!! `description`), string attributes, close. Every HDF5 return code is checked; messages
!! name the file and the dataset. h5py sees the Fortran shape reversed.
!!
!!     type(result_file_t) :: h5
!!     call h5%create('out/x.h5', err)
!!     call h5%write('/modes/omega', omega, 'rad/s', err, 'natural angular frequencies')
!!     call h5%attribute('/', 'version', version_string, err)
!!     call h5%close(err)
module ropedyn_result_file
    use hdf5, only: hid_t, hsize_t, size_t, h5open_f, h5eset_auto_f, h5fcreate_f, h5fclose_f, &
        H5F_ACC_TRUNC_F, h5gcreate_f, h5gclose_f, h5screate_f, h5screate_simple_f, &
        h5sclose_f, H5S_SCALAR_F, h5dcreate_f, h5dclose_f, h5dwrite_f, h5oopen_f, h5oclose_f, &
        h5acreate_f, h5aclose_f, h5awrite_f, h5aexists_f, h5adelete_f, h5tcopy_f, &
        h5tclose_f, h5tset_size_f, h5tset_strpad_f, H5T_NATIVE_CHARACTER, H5T_STR_NULLPAD_F, &
        h5kind_to_type, H5_REAL_KIND, H5_INTEGER_KIND
    use ropedyn_kinds, only: wp, i8
    use ropedyn_error, only: error_t, make_error, ERR_IO
    implicit none
    private
    public :: result_file_t

    type :: result_file_t
        private
        character(len=:), allocatable :: path
        integer(hid_t) :: file_id = -1
        logical :: is_open = .false.
    contains
        procedure :: create => rf_create
        procedure :: group => rf_group
        procedure :: attribute => rf_attribute
        procedure, private :: write_r0, write_r1, write_r2, write_r3, write_i0
        generic :: write => write_r0, write_r1, write_r2, write_r3, write_i0
        procedure :: close => rf_close
        final :: rf_final
    end type result_file_t

contains

    !> Create (or overwrite) `path`; its directory must exist.
    subroutine rf_create(self, path, err)
        class(result_file_t), intent(inout) :: self
        character(len=*), intent(in) :: path
        type(error_t), allocatable, intent(out) :: err
        integer :: hdferr
        if (self%is_open) call self%close(err)
        if (allocated(err)) return
        call h5open_f(hdferr)
        if (hdferr < 0) then
            call make_error(err, ERR_IO, path//': cannot initialize the HDF5 library')
            return
        end if
        call h5eset_auto_f(0, hdferr)
        call h5fcreate_f(path, H5F_ACC_TRUNC_F, self%file_id, hdferr)
        if (hdferr < 0) then
            call make_error(err, ERR_IO, path//': cannot create file (does the directory '// &
                            'exist and is it writable?)')
            return
        end if
        self%path = path
        self%is_open = .true.
    end subroutine rf_create

    !> Create group `name` (its parent must exist).
    subroutine rf_group(self, name, err)
        class(result_file_t), intent(inout) :: self
        character(len=*), intent(in) :: name
        type(error_t), allocatable, intent(out) :: err
        integer(hid_t) :: gid
        integer :: hdferr
        call h5gcreate_f(self%file_id, name, gid, hdferr)
        if (hdferr < 0) then
            call make_error(err, ERR_IO, self%path//': '//name//': cannot create group')
            return
        end if
        call h5gclose_f(gid, hdferr)
    end subroutine rf_group

    !> String attribute `name` on the object `where` ('/' for the root).
    subroutine rf_attribute(self, where, name, value, err)
        class(result_file_t), intent(inout) :: self
        character(len=*), intent(in) :: where, name, value
        type(error_t), allocatable, intent(out) :: err
        integer(hid_t) :: obj
        integer :: hdferr
        call h5oopen_f(self%file_id, where, obj, hdferr)
        if (hdferr < 0) then
            call make_error(err, ERR_IO, self%path//': '//where//': cannot open object')
            return
        end if
        call string_attribute(self%path, obj, where, name, value, err)
        call h5oclose_f(obj, hdferr)
    end subroutine rf_attribute

    subroutine write_r0(self, name, value, units, err, description)
        class(result_file_t), intent(inout) :: self
        character(len=*), intent(in) :: name, units
        real(wp), intent(in) :: value
        type(error_t), allocatable, intent(out) :: err
        character(len=*), intent(in), optional :: description
        integer(hid_t) :: dset
        integer(hsize_t) :: dims(1)
        integer :: hdferr
        dims = 1
        call open_dataset(self, name, [integer(hsize_t) ::], .false., dset, err)
        if (allocated(err)) return
        call h5dwrite_f(dset, h5kind_to_type(wp, H5_REAL_KIND), value, dims, hdferr)
        call finish_dataset(self, name, dset, hdferr, units, description, err)
    end subroutine write_r0

    subroutine write_i0(self, name, value, units, err, description)
        class(result_file_t), intent(inout) :: self
        character(len=*), intent(in) :: name, units
        integer, intent(in) :: value
        type(error_t), allocatable, intent(out) :: err
        character(len=*), intent(in), optional :: description
        integer(hid_t) :: dset
        integer(hsize_t) :: dims(1)
        integer :: hdferr
        dims = 1
        call open_dataset(self, name, [integer(hsize_t) ::], .true., dset, err)
        if (allocated(err)) return
        call h5dwrite_f(dset, h5kind_to_type(i8, H5_INTEGER_KIND), int(value, i8), dims, hdferr)
        call finish_dataset(self, name, dset, hdferr, units, description, err)
    end subroutine write_i0

    subroutine write_r1(self, name, values, units, err, description)
        class(result_file_t), intent(inout) :: self
        character(len=*), intent(in) :: name, units
        real(wp), intent(in) :: values(:)
        type(error_t), allocatable, intent(out) :: err
        character(len=*), intent(in), optional :: description
        integer(hid_t) :: dset
        integer :: hdferr
        call open_dataset(self, name, int(shape(values), hsize_t), .false., dset, err)
        if (allocated(err)) return
        call h5dwrite_f(dset, h5kind_to_type(wp, H5_REAL_KIND), values, &
                        int(shape(values), hsize_t), hdferr)
        call finish_dataset(self, name, dset, hdferr, units, description, err)
    end subroutine write_r1

    subroutine write_r2(self, name, values, units, err, description)
        class(result_file_t), intent(inout) :: self
        character(len=*), intent(in) :: name, units
        real(wp), intent(in) :: values(:, :)
        type(error_t), allocatable, intent(out) :: err
        character(len=*), intent(in), optional :: description
        integer(hid_t) :: dset
        integer :: hdferr
        call open_dataset(self, name, int(shape(values), hsize_t), .false., dset, err)
        if (allocated(err)) return
        call h5dwrite_f(dset, h5kind_to_type(wp, H5_REAL_KIND), values, &
                        int(shape(values), hsize_t), hdferr)
        call finish_dataset(self, name, dset, hdferr, units, description, err)
    end subroutine write_r2

    subroutine write_r3(self, name, values, units, err, description)
        class(result_file_t), intent(inout) :: self
        character(len=*), intent(in) :: name, units
        real(wp), intent(in) :: values(:, :, :)
        type(error_t), allocatable, intent(out) :: err
        character(len=*), intent(in), optional :: description
        integer(hid_t) :: dset
        integer :: hdferr
        call open_dataset(self, name, int(shape(values), hsize_t), .false., dset, err)
        if (allocated(err)) return
        call h5dwrite_f(dset, h5kind_to_type(wp, H5_REAL_KIND), values, &
                        int(shape(values), hsize_t), hdferr)
        call finish_dataset(self, name, dset, hdferr, units, description, err)
    end subroutine write_r3

    !> Close the file (idempotent).
    subroutine rf_close(self, err)
        class(result_file_t), intent(inout) :: self
        type(error_t), allocatable, intent(out) :: err
        integer :: hdferr
        if (.not. self%is_open) return
        call h5fclose_f(self%file_id, hdferr)
        self%is_open = .false.
        self%file_id = -1
        if (hdferr < 0) call make_error(err, ERR_IO, self%path//': cannot close file')
    end subroutine rf_close

    !> Close a file left open (no error can be reported here).
    impure elemental subroutine rf_final(self)
        type(result_file_t), intent(inout) :: self
        integer :: hdferr
        if (self%is_open) call h5fclose_f(self%file_id, hdferr)
        self%is_open = .false.
    end subroutine rf_final

    !> Create a dataset of the given Fortran shape (empty: scalar).
    subroutine open_dataset(self, name, dims, is_integer, dset, err)
        class(result_file_t), intent(inout) :: self
        character(len=*), intent(in) :: name
        integer(hsize_t), intent(in) :: dims(:)
        logical, intent(in) :: is_integer
        integer(hid_t), intent(out) :: dset
        type(error_t), allocatable, intent(out) :: err
        integer(hid_t) :: space, type_id
        integer :: hdferr, create_err
        dset = -1
        if (.not. self%is_open) then
            call make_error(err, ERR_IO, name//': the result file is not open')
            return
        end if
        if (size(dims) == 0) then
            call h5screate_f(H5S_SCALAR_F, space, hdferr)
        else
            call h5screate_simple_f(size(dims), dims, space, hdferr)
        end if
        if (hdferr < 0) then
            call make_error(err, ERR_IO, self%path//': '//name//': cannot create dataspace')
            return
        end if
        if (is_integer) then
            type_id = h5kind_to_type(i8, H5_INTEGER_KIND)
        else
            type_id = h5kind_to_type(wp, H5_REAL_KIND)
        end if
        call h5dcreate_f(self%file_id, name, type_id, space, dset, create_err)
        call h5sclose_f(space, hdferr)
        if (create_err < 0) then
            dset = -1
            call make_error(err, ERR_IO, self%path//': '//name//': cannot create dataset')
        end if
    end subroutine open_dataset

    !> Check the write, add the attributes, close the dataset.
    subroutine finish_dataset(self, name, dset, write_err, units, description, err)
        class(result_file_t), intent(inout) :: self
        character(len=*), intent(in) :: name, units
        integer(hid_t), intent(in) :: dset
        integer, intent(in) :: write_err
        character(len=*), intent(in), optional :: description
        type(error_t), allocatable, intent(out) :: err
        integer :: hdferr
        if (write_err < 0) then
            call make_error(err, ERR_IO, self%path//': '//name//': cannot write dataset')
        else
            call string_attribute(self%path, dset, name, 'units', units, err)
            if (.not. allocated(err) .and. present(description)) &
                call string_attribute(self%path, dset, name, 'description', description, err)
        end if
        call h5dclose_f(dset, hdferr)
        if (hdferr < 0 .and. .not. allocated(err)) &
            call make_error(err, ERR_IO, self%path//': '//name//': cannot close dataset')
    end subroutine finish_dataset

    !> Write (or replace) a scalar fixed-length string attribute on object loc_id.
    subroutine string_attribute(path, loc_id, where, name, value, err)
        character(len=*), intent(in) :: path, where, name, value
        integer(hid_t), intent(in) :: loc_id
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
            if (hdferr >= 0) call h5tset_strpad_f(type_id, H5T_STR_NULLPAD_F, hdferr)
            if (hdferr < 0) then
                call make_error(err, ERR_IO, label//': cannot set up the string type')
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
            if (hdferr < 0) call make_error(err, ERR_IO, label//': cannot write attribute')
        end block steps
        if (attr_id >= 0) call h5aclose_f(attr_id, hdferr)
        if (space_id >= 0) call h5sclose_f(space_id, hdferr)
        if (type_id >= 0) call h5tclose_f(type_id, hdferr)
    end subroutine string_attribute
end module ropedyn_result_file
