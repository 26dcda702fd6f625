!> Attributes and datasets of `ropedyn_h5`: string attributes, values of any rank, string
!! columns, and the readers of run files. Each HDF5 call sequence is written once here.
submodule (ropedyn_h5) ropedyn_h5_data
    implicit none

contains

    module procedure h5_failed
        failed = hdferr < 0
        if (.not. failed) return
        call h5_error(err, message)
        if (present(id)) id = -1
    end procedure h5_failed

    module procedure h5_error
        character(len=:), allocatable :: reason
        integer :: errnum
        errnum = h5_reason(reason)
        if (allocated(err)) deallocate (err)
        if (len(reason) > 0) then
            call make_error(err, ERR_IO, message//': '//reason)
        else
            call make_error(err, ERR_IO, message)
        end if
    end procedure h5_error

    module procedure h5_reason
        character(kind=c_char, len=300) :: buf
        integer :: k
        buf = repeat(c_null_char, len(buf))
        errnum = int(c_h5_reason(buf, int(len(buf), c_int)))
        if (.not. present(reason)) return
        k = index(buf, c_null_char)
        if (k == 0) k = len(buf) + 1
        reason = trim(buf(:k - 1))
    end procedure h5_reason

    module procedure string_type
        call h5tcopy_f(H5T_NATIVE_CHARACTER, type_id, hdferr)
        if (hdferr < 0) then
            type_id = -1
            return
        end if
        call h5tset_size_f(type_id, int(max(width, 1), size_t), hdferr)
        if (hdferr >= 0) call h5tset_strpad_f(type_id, H5T_STR_NULLPAD_F, hdferr)
    end procedure string_type

    module procedure string_attribute
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
            if (h5_failed(hdferr, label//': cannot check existence', err)) exit steps
            if (exists) then
                call h5adelete_f(loc_id, name, hdferr)
                if (h5_failed(hdferr, label//': cannot delete old value', err)) exit steps
            end if
            call string_type(len(value), type_id, hdferr)
            if (h5_failed(hdferr, label//': cannot set up the string type', err)) exit steps
            call h5screate_f(H5S_SCALAR_F, space_id, hdferr)
            if (h5_failed(hdferr, label//': cannot create dataspace', err, space_id)) exit steps
            call h5acreate_f(loc_id, name, type_id, space_id, attr_id, hdferr)
            if (h5_failed(hdferr, label//': cannot create attribute', err, attr_id)) exit steps
            if (len(value) > 0) then
                call h5awrite_f(attr_id, type_id, value, dims, hdferr)
            else
                call h5awrite_f(attr_id, type_id, achar(0), dims, hdferr)
            end if
            if (hdferr < 0) call h5_error(err, label//': cannot write attribute')
        end block steps
        if (attr_id >= 0) then
            call h5aclose_f(attr_id, hdferr)
            if (hdferr < 0 .and. .not. allocated(err)) &
                call h5_error(err, label//': cannot close attribute')
        end if
        if (space_id >= 0) call h5sclose_f(space_id, hdferr)
        if (type_id >= 0) call h5tclose_f(type_id, hdferr)
    end procedure string_attribute

    ! ---------------------------------------------------------------------------------------
    ! Writing
    ! ---------------------------------------------------------------------------------------

    module procedure write_real
        call write_data(self, name, h5kind_to_type(wp, H5_REAL_KIND), &
                        int(shape(values), hsize_t), c_loc(values), is_contiguous(values), &
                        units, err, description)
    end procedure write_real

    module procedure write_int64
        call write_data(self, name, h5kind_to_type(i8, H5_INTEGER_KIND), &
                        int(shape(values), hsize_t), c_loc(values), is_contiguous(values), &
                        units, err, description)
    end procedure write_int64

    module procedure h5_write_text
        integer(hid_t) :: type_id
        type(c_ptr) :: buffer
        integer :: hdferr
        buffer = c_null_ptr
        if (size(values) > 0 .and. len(values) > 0) buffer = c_loc(values(1)(1:1))
        call string_type(len(values), type_id, hdferr)
        if (hdferr < 0) then
            call h5_error(err, self%path//': '//name//': cannot set up the string type')
        else
            call write_data(self, name, type_id, [size(values, kind=hsize_t)], buffer, &
                            is_contiguous(values), units, err)
        end if
        if (type_id >= 0) call h5tclose_f(type_id, hdferr)
    end procedure h5_write_text

    !> Create (or open, if it exists) dataset `name` of `type_id` and Fortran extents `dims`
    !! (none: scalar), write the values at `buffer` (`packed`: they are one block), add
    !! units and description to a new one.
    subroutine write_data(self, name, type_id, dims, buffer, packed, units, err, description)
        class(h5_file_t), intent(inout) :: self
        character(len=*), intent(in) :: name
        integer(hid_t), intent(in) :: type_id
        integer(hsize_t), intent(in) :: dims(:)
        type(c_ptr), intent(in) :: buffer
        logical, intent(in) :: packed
        character(len=*), intent(in) :: units
        type(error_t), allocatable, intent(out) :: err
        character(len=*), intent(in), optional :: description
        integer(hid_t) :: dset_id
        integer(hsize_t) :: old_dims(7)
        logical :: exists
        integer :: hdferr

        if (.not. self%is_open) then
            call make_error(err, ERR_IO, name//': the HDF5 file is not open')
            return
        end if
        if (.not. packed) then
            call make_error(err, ERR_INTERNAL, self%path//': '//name//': values not contiguous')
            return
        end if
        exists = self%exists(name)
        if (exists) then
            call h5dopen_f(self%id, name, dset_id, hdferr)
            if (h5_failed(hdferr, self%path//': '//name//': cannot open dataset', err)) return
            ! one of other extents (an earlier part of a resumed run wrote it) is replaced:
            ! writing into it would read past the values
            if (size(dims) > 0) then
                call extents(self, name, dset_id, old_dims(1:size(dims)), err)
                if (allocated(err)) deallocate (err)
                if (any(old_dims(1:size(dims)) /= dims)) then
                    call h5dclose_f(dset_id, hdferr)
                    call h5ldelete_f(self%id, name, hdferr)
                    if (h5_failed(hdferr, self%path//': '//name//': cannot replace dataset', &
                                  err)) return
                    exists = .false.
                end if
            end if
        end if
        if (.not. exists) then
            call new_dataset(self, name, type_id, dims, dset_id, err)
            if (allocated(err)) return
        end if
        hdferr = 0
        if (product(dims) > 0) call h5dwrite_f(dset_id, type_id, buffer, hdferr)
        if (hdferr < 0) then
            call h5_error(err, self%path//': '//name//': cannot write dataset')
        else if (.not. exists) then
            call string_attribute(self%path, dset_id, name, 'units', units, err)
            if (.not. allocated(err) .and. present(description)) then
                if (len(description) > 0) call string_attribute(self%path, dset_id, name, &
                                                                'description', description, err)
            end if
        end if
        call h5dclose_f(dset_id, hdferr)
        if (hdferr < 0 .and. .not. allocated(err)) &
            call h5_error(err, self%path//': '//name//': cannot close dataset')
    end subroutine write_data

    module procedure new_dataset
        integer(hid_t) :: space_id, plist_id
        integer :: hdferr

        dset_id = -1
        space_id = -1
        plist_id = H5P_DEFAULT_F
        steps: block
            if (size(dims) == 0) then
                call h5screate_f(H5S_SCALAR_F, space_id, hdferr)
            else if (present(max_dims)) then
                call h5screate_simple_f(size(dims), dims, space_id, hdferr, max_dims)
            else
                call h5screate_simple_f(size(dims), dims, space_id, hdferr)
            end if
            if (h5_failed(hdferr, self%path//': '//name// &
                                  ': cannot create dataspace', err, space_id)) exit steps
            if (present(chunk)) then
                call h5pcreate_f(H5P_DATASET_CREATE_F, plist_id, hdferr)
                if (hdferr < 0) then
                    plist_id = H5P_DEFAULT_F
                    call h5_error(err, self%path//': '//name// &
                                    ': cannot create property list')
                    exit steps
                end if
                call h5pset_chunk_f(plist_id, size(chunk), chunk, hdferr)
                if (h5_failed(hdferr, self%path//': '//name// &
                                      ': cannot set chunk size', err)) exit steps
            end if
            call h5dcreate_f(self%id, name, type_id, space_id, dset_id, hdferr, dcpl_id=plist_id)
            if (hdferr < 0) then
                dset_id = -1
                call h5_error(err, self%path//': '//name//': cannot create dataset')
            end if
        end block steps
        if (plist_id /= H5P_DEFAULT_F) call h5pclose_f(plist_id, hdferr)
        if (space_id >= 0) call h5sclose_f(space_id, hdferr)
    end procedure new_dataset

    ! ---------------------------------------------------------------------------------------
    ! Reading
    ! ---------------------------------------------------------------------------------------

    module procedure h5_read_attribute
        integer(hid_t) :: attr_id, type_id
        integer(size_t) :: length
        integer(hsize_t), parameter :: dims(1) = 1
        logical :: exists, vlen
        integer :: hdferr, nul, class
        integer(c_int) :: n
        character(kind=c_char, len=1) :: small
        character(kind=c_char, len=:), allocatable :: whole
        character(len=:), allocatable :: label

        label = self%path//': attribute '//name
        value = ''
        if (present(found)) found = .false.
        call h5aexists_f(self%id, name, exists, hdferr)
        if (h5_failed(hdferr, label//': cannot check existence', err)) return
        if (.not. exists) then
            if (.not. present(found)) call make_error(err, ERR_IO, label//' is missing')
            return
        end if
        if (present(found)) found = .true.
        call h5aopen_f(self%id, name, attr_id, hdferr)
        if (h5_failed(hdferr, label//': cannot open', err)) return
        call h5aget_type_f(attr_id, type_id, hdferr)
        if (hdferr >= 0) call type_facts(type_id, class, length, vlen, hdferr)
        if (hdferr < 0) then
            call h5_error(err, label//': cannot get its type')
        else if (class /= H5T_STRING_F) then
            call make_error(err, ERR_INPUT, label//': not a string (not written by ropedyn)')
            call h5tclose_f(type_id, hdferr)
        else if (vlen) then
            ! a string of variable length (h5py's): read by the C glue
            call h5tclose_f(type_id, hdferr)
            n = c_h5_vlen_attribute(self%id, name//c_null_char, small, 1_c_int)
            if (n >= 0) then
                allocate (character(len=n + 1) :: whole)
                n = c_h5_vlen_attribute(self%id, name//c_null_char, whole, int(n + 1, c_int))
            end if
            if (n < 0) then
                call h5_error(err, label//': cannot read')
            else
                value = whole(:n)
            end if
        else
            block
                character(len=length) :: buffer
                buffer = ''
                call h5aread_f(attr_id, type_id, buffer, dims, hdferr)
                if (hdferr < 0) then
                    call h5_error(err, label//': cannot read')
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
    end procedure h5_read_attribute

    module procedure read_real_scalar
        integer(hsize_t) :: dims(0)
        call read_data(self, name, h5kind_to_type(wp, H5_REAL_KIND), c_loc(value), dims, err)
    end procedure read_real_scalar

    module procedure read_int64_scalar
        integer(hsize_t) :: dims(0)
        call read_data(self, name, h5kind_to_type(i8, H5_INTEGER_KIND), c_loc(value), dims, err)
    end procedure read_int64_scalar

    module procedure h5_read_reals
        dims = 0
        call read_data(self, name, h5kind_to_type(wp, H5_REAL_KIND), values=values, &
                       dims=dims, err=err)
        if (.not. allocated(values)) allocate (values(0))
    end procedure h5_read_reals

    module procedure h5_extents
        integer(hid_t) :: dset_id
        integer :: hdferr
        dims = 0
        if (.not. self%exists(name)) return
        call h5dopen_f(self%id, name, dset_id, hdferr)
        if (h5_failed(hdferr, self%path//': '//name//': cannot open dataset', err)) return
        call extents(self, name, dset_id, dims, err)
        call h5dclose_f(dset_id, hdferr)
    end procedure h5_extents

    module procedure h5_read_texts
        integer(hid_t) :: dset_id, type_id, mem_type
        integer(hsize_t) :: dims(1)
        integer(size_t) :: width
        integer :: hdferr, ierr, class, k, w, nul
        logical :: vlen
        character(len=:), allocatable, target :: whole
        type(c_ptr) :: target_ptr

        allocate (lines(0))
        if (.not. self%exists(name)) return
        call h5dopen_f(self%id, name, dset_id, hdferr)
        if (h5_failed(hdferr, self%path//': '//name//': cannot open dataset', err)) return
        steps: block
            call h5dget_type_f(dset_id, type_id, hdferr)
            if (hdferr >= 0) call type_facts(type_id, class, width, vlen, hdferr)
            call h5tclose_f(type_id, ierr)
            if (hdferr < 0) then
                call h5_error(err, self%path//': '//name//': cannot get its type')
                exit steps
            end if
            if (class /= H5T_STRING_F .or. vlen) then
                call make_error(err, ERR_INPUT, self%path//': '//name//': not fixed-length '// &
                                'strings (not written by ropedyn)')
                exit steps
            end if
            call extents(self, name, dset_id, dims, err)
            if (allocated(err) .or. dims(1) == 0) exit steps
            w = int(width)
            allocate (character(len=w*int(dims(1))) :: whole)
            call string_type(w, mem_type, hdferr)
            if (hdferr >= 0) then
                target_ptr = c_loc(whole)
                call h5dread_f(dset_id, mem_type, target_ptr, hdferr)
                call h5tclose_f(mem_type, ierr)
            end if
            if (hdferr < 0) then
                call h5_error(err, self%path//': '//name//': cannot read')
                exit steps
            end if
            do k = 1, int(dims(1))
                associate (line => whole((k - 1)*w + 1:k*w))
                    nul = index(line, achar(0))
                    if (nul == 0) nul = w + 1
                    call append_text(lines, trim(line(:nul - 1)))
                end associate
            end do
        end block steps
        call h5dclose_f(dset_id, ierr)
    end procedure h5_read_texts

    !> The class of a type, its size (bytes) and whether it is a string of variable length;
    !! hdferr < 0 when a query failed (then the later facts are unset).
    subroutine type_facts(type_id, class, width, vlen, hdferr)
        integer(hid_t), intent(in) :: type_id
        integer, intent(out) :: class, hdferr
        integer(size_t), intent(out) :: width
        logical, intent(out) :: vlen
        class = -1
        width = 0
        vlen = .false.
        call h5tget_class_f(type_id, class, hdferr)
        if (hdferr >= 0) call h5tget_size_f(type_id, width, hdferr)
        if (hdferr >= 0 .and. class == H5T_STRING_F) call h5tis_variable_str_f(type_id, vlen, &
                                                                                hdferr)
    end subroutine type_facts

    !> Read dataset `name` (nothing when absent): a scalar to `buffer`, or, with `values`,
    !! an array of rank size(dims) into `values` (allocated here, extents `dims`).
    subroutine read_data(self, name, type_id, buffer, dims, err, values)
        class(h5_file_t), intent(inout) :: self
        character(len=*), intent(in) :: name
        integer(hid_t), intent(in) :: type_id
        type(c_ptr), intent(in), optional :: buffer
        integer(hsize_t), intent(inout) :: dims(:)
        type(error_t), allocatable, intent(out) :: err
        real(wp), allocatable, target, intent(inout), optional :: values(:)
        integer(hid_t) :: dset_id
        type(c_ptr) :: target_ptr
        integer :: hdferr

        if (.not. self%exists(name)) return
        call h5dopen_f(self%id, name, dset_id, hdferr)
        if (h5_failed(hdferr, self%path//': '//name//': cannot open dataset', err)) return
        steps: block
            if (present(values)) then
                call extents(self, name, dset_id, dims, err)
                if (allocated(err)) exit steps
                allocate (values(product(dims)))
                if (size(values) == 0) exit steps
                target_ptr = c_loc(values)
            else
                target_ptr = buffer
            end if
            call h5dread_f(dset_id, type_id, target_ptr, hdferr)
            if (hdferr < 0) call h5_error(err, self%path//': '//name//': cannot read')
        end block steps
        call h5dclose_f(dset_id, hdferr)
    end subroutine read_data

    !> The Fortran extents of an open dataset that must have rank size(dims).
    subroutine extents(self, name, dset_id, dims, err)
        class(h5_file_t), intent(in) :: self
        character(len=*), intent(in) :: name
        integer(hid_t), intent(in) :: dset_id
        integer(hsize_t), intent(out) :: dims(:)
        type(error_t), allocatable, intent(out) :: err
        integer(hid_t) :: space_id
        integer(hsize_t) :: maxdims(size(dims))
        integer :: hdferr, actual
        dims = 0
        call h5dget_space_f(dset_id, space_id, hdferr)
        if (h5_failed(hdferr, self%path//': '//name//': cannot get dataspace', err)) return
        call h5sget_simple_extent_ndims_f(space_id, actual, hdferr)
        if (hdferr < 0 .or. actual /= size(dims)) then
            call make_error(err, ERR_IO, self%path//': '//name//': not of rank '// &
                            int_text(size(dims)))
        else
            call h5sget_simple_extent_dims_f(space_id, dims, maxdims, hdferr)
            if (hdferr < 0) call h5_error(err, self%path//': '//name// &
                                            ': cannot get extents')
        end if
        call h5sclose_f(space_id, hdferr)
    end subroutine extents
end submodule ropedyn_h5_data
