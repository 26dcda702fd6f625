!> Series of `ropedyn_h5`: extendible, chunked datasets written one record at a time.
submodule (ropedyn_h5) ropedyn_h5_series
    implicit none

contains

    module procedure h5_create_series
        integer(hsize_t) :: dims(3), max_dims(3), chunk(3), record_bytes
        integer(hid_t) :: type_id
        integer :: rank
        logical :: int64

        rank = size(record_dims) + 1
        series%path = self%path
        series%name = name
        series%rank = rank
        series%record_dims = 1
        series%record_dims(1:rank - 1) = record_dims

        int64 = .false.
        if (present(wide)) int64 = wide
        if (is_integer .and. int64) then
            type_id = h5kind_to_type(i8, H5_INTEGER_KIND)
            record_bytes = int(storage_size(0_i8)/8, hsize_t)*product(record_dims)
        else if (is_integer) then
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

        call new_dataset(self, name, type_id, dims(1:rank), series%id, err, max_dims(1:rank), &
                         chunk(1:rank))
        if (allocated(err)) return
        call string_attribute(self%path, series%id, name, 'units', units, err)
        if (allocated(err)) return
        if (len(columns) > 0) &
            call string_attribute(self%path, series%id, name, 'columns', columns, err)
    end procedure h5_create_series

    module procedure h5_create_text_series
        integer(hsize_t) :: dims(1), max_dims(1), chunk(1)
        integer(hid_t) :: type_id
        integer :: hdferr

        series%path = self%path
        series%name = name
        series%rank = 1
        series%record_dims = 1
        series%text_width = max(1, width)
        call string_type(series%text_width, type_id, hdferr)
        if (h5_failed(hdferr, self%path//': '//name//': cannot set up the string type', err)) return
        dims = 0
        max_dims = H5S_UNLIMITED_F
        chunk = max(1, min(MAX_CHUNK_RECORDS, CHUNK_BYTES/series%text_width))
        call new_dataset(self, name, type_id, dims, series%id, err, max_dims, chunk)
        call h5tclose_f(type_id, hdferr)
        if (allocated(err)) return
        call string_attribute(self%path, series%id, name, 'units', units, err)
    end procedure h5_create_text_series

    module procedure h5_open_series
        integer(hid_t) :: space_id, type_id
        integer(hsize_t) :: dims(3), max_dims(3)
        integer(size_t) :: width
        integer :: rank, hdferr, ierr, class
        rank = 0

        series%path = self%path
        series%name = name
        call h5dopen_f(self%id, name, series%id, hdferr)
        if (h5_failed(hdferr, self%path//': '//name//': cannot open dataset', err, &
                      series%id)) return
        call h5dget_space_f(series%id, space_id, hdferr)
        if (h5_failed(hdferr, self%path//': '//name//': cannot get dataspace', err)) return
        call h5sget_simple_extent_ndims_f(space_id, rank, hdferr)
        if (hdferr >= 0 .and. rank >= 1 .and. rank <= 3) &
            call h5sget_simple_extent_dims_f(space_id, dims(1:rank), max_dims(1:rank), hdferr)
        call h5sclose_f(space_id, ierr)
        if (hdferr < 0 .or. rank < 1 .or. rank > 3) then
            call make_error(err, ERR_IO, self%path//': '//name//': not a series (rank '// &
                            int_text(rank)//')')
            return
        end if
        series%rank = rank
        series%record_dims = 1
        series%record_dims(1:rank - 1) = dims(1:rank - 1)
        series%text_width = 0
        series%extendible = max_dims(rank) == H5S_UNLIMITED_F
        series%value_class = 0
        call h5dget_type_f(series%id, type_id, hdferr)
        if (h5_failed(hdferr, self%path//': '//name//': cannot get its type', err)) return
        call h5tget_class_f(type_id, class, hdferr)
        if (hdferr >= 0 .and. class == H5T_STRING_F) then
            call h5tget_size_f(type_id, width, hdferr)
            series%text_width = int(width)
            series%value_class = SERIES_TEXT
        else if (hdferr >= 0 .and. class == H5T_FLOAT_F) then
            series%value_class = SERIES_REAL
        else if (hdferr >= 0 .and. class == H5T_INTEGER_F) then
            series%value_class = SERIES_INTEGER
        end if
        call h5tclose_f(type_id, hdferr)
    end procedure h5_open_series

    module procedure series_unfit
        character(len=*), parameter :: NAMES(3) = [character(len=15) :: 'real numbers', &
            'integers', 'strings']
        reason = ''
        if (.not. self%extendible) then
            reason = 'not extendible (a fixed-size dataset: not written by ropedyn)'
        else if (self%value_class /= value_class) then
            reason = 'not a series of '//trim(NAMES(value_class))//' (not written by ropedyn)'
        end if
    end procedure series_unfit

    module procedure series_length
        integer(hid_t) :: space_id
        integer(hsize_t) :: dims(3), max_dims(3)
        integer :: hdferr
        records = -1
        if (self%id < 0) return
        call h5dget_space_f(self%id, space_id, hdferr)
        if (hdferr < 0) return
        call h5sget_simple_extent_dims_f(space_id, dims(1:self%rank), max_dims(1:self%rank), &
                                         hdferr)
        if (hdferr >= 0) records = dims(self%rank)
        call h5sclose_f(space_id, hdferr)
    end procedure series_length

    module procedure series_record_size
        n = int(product(self%record_dims(1:self%rank - 1)))
    end procedure series_record_size

    module procedure series_truncate
        integer(hsize_t) :: dims(3)
        integer :: hdferr
        if (closed_error(self, err)) return
        if (self%length() <= records) return
        dims(1:self%rank - 1) = self%record_dims(1:self%rank - 1)
        dims(self%rank) = records
        call h5dset_extent_f(self%id, dims(1:self%rank), hdferr)
        if (hdferr < 0) call h5_error(err, self%path//': '//self%name// &
                                        ': cannot cut to '//int_text(int(records))//' records')
    end procedure series_truncate

    module procedure series_append_text
        character(len=:), allocatable, target :: padded
        integer(hid_t) :: type_id
        integer :: hdferr
        if (closed_error(self, err)) return
        if (self%text_width < 1) then
            call make_error(err, ERR_INTERNAL, self%path//': '//self%name// &
                            ': not a series of strings')
            return
        end if
        allocate (character(len=self%text_width) :: padded)
        padded = repeat(achar(0), self%text_width)
        padded(1:min(len(value), self%text_width)) = value(1:min(len(value), self%text_width))
        call string_type(self%text_width, type_id, hdferr)
        if (hdferr < 0) then
            call h5_error(err, self%path//': '//self%name// &
                            ': cannot set up the string type')
            return
        end if
        call write_record(self, record, 1, type_id, c_loc(padded), .true., err)
        call h5tclose_f(type_id, hdferr)
    end procedure series_append_text

    module procedure h5_read_record
        integer(hid_t) :: dset_id, file_space, mem_space
        integer(hsize_t) :: dims(3), max_dims(3)
        integer :: rank, hdferr
        character(len=:), allocatable :: label
        type(c_ptr) :: buffer

        label = self%path//': '//name
        allocate (values(0))
        call h5dopen_f(self%id, name, dset_id, hdferr)
        if (h5_failed(hdferr, label//': cannot open dataset', err)) return
        file_space = -1
        mem_space = -1
        steps: block
            call h5dget_space_f(dset_id, file_space, hdferr)
            if (h5_failed(hdferr, label//': cannot get dataspace', err, file_space)) exit steps
            call h5sget_simple_extent_ndims_f(file_space, rank, hdferr)
            if (hdferr < 0 .or. rank < 1 .or. rank > 3) then
                call make_error(err, ERR_IO, label//': not a series')
                exit steps
            end if
            call h5sget_simple_extent_dims_f(file_space, dims(1:rank), max_dims(1:rank), hdferr)
            if (hdferr < 0 .or. record < 1 .or. record > dims(rank)) then
                call make_error(err, ERR_IO, label//': no record '//int_text(int(record)))
                exit steps
            end if
            deallocate (values)
            allocate (values(product(dims(1:rank - 1))))
            call select_record(file_space, dims(1:rank - 1), record, label, mem_space, err)
            if (allocated(err)) exit steps
            buffer = c_loc(values)
            if (size(values) > 0) call h5dread_f(dset_id, h5kind_to_type(wp, H5_REAL_KIND), &
                buffer, hdferr, mem_space_id=mem_space, file_space_id=file_space)
            if (hdferr < 0) call h5_error(err, label//': cannot read record '// &
                                            int_text(int(record)))
        end block steps
        if (mem_space >= 0) call h5sclose_f(mem_space, hdferr)
        if (file_space >= 0) call h5sclose_f(file_space, hdferr)
        call h5dclose_f(dset_id, hdferr)
    end procedure h5_read_record

    module procedure series_close
        integer :: hdferr
        if (self%id < 0) return
        call h5dclose_f(self%id, hdferr)
        self%id = -1
        if (hdferr < 0) call c_h5_close_failed()
        if (hdferr < 0) call h5_error(err, self%path//': '//self%name// &
                                        ': cannot close dataset')
        ! its names go with it: gfortran 12 does not free them with the output file's array
        ! of force series (valgrind, tests/lib/lib_memory.c); a closed series takes no
        ! more calls (closed_error)
        deallocate (self%path, self%name)
    end procedure series_close

    !> The error of a call on a series that is closed (or was never opened).
    logical function closed_error(self, err) result(closed)
        class(h5_series_t), intent(in) :: self
        type(error_t), allocatable, intent(inout) :: err
        closed = .not. allocated(self%name)
        if (closed) call make_error(err, ERR_INTERNAL, 'a closed HDF5 series was used')
    end function closed_error

    module procedure append_real
        call write_record(self, record, size(values), h5kind_to_type(wp, H5_REAL_KIND), &
                          c_loc(values), is_contiguous(values), err)
    end procedure append_real

    module procedure append_integer
        call write_record(self, record, size(values), h5kind_to_type(kind(0), H5_INTEGER_KIND), &
                          c_loc(values), is_contiguous(values), err)
    end procedure append_integer

    module procedure append_int64
        call write_record(self, record, size(values), h5kind_to_type(i8, H5_INTEGER_KIND), &
                          c_loc(values), is_contiguous(values), err)
    end procedure append_int64

    !> Write the `n_values` values at `buffer` (`packed`: one block) as the records `record`,
    !! `record` + 1, ... (as many as they fill), extending the series to the last of them.
    subroutine write_record(self, record, n_values, type_id, buffer, packed, err)
        class(h5_series_t), intent(inout) :: self
        integer(hsize_t), intent(in) :: record
        integer, intent(in) :: n_values
        integer(hid_t), intent(in) :: type_id
        type(c_ptr), intent(in) :: buffer
        logical, intent(in) :: packed
        type(error_t), allocatable, intent(out) :: err
        integer(hsize_t) :: dims(3), count
        integer(hid_t) :: file_space, mem_space
        integer :: rank, hdferr, record_size
        character(len=:), allocatable :: label

        if (closed_error(self, err)) return
        label = self%path//': '//self%name
        rank = self%rank
        if (.not. packed) then
            call make_error(err, ERR_INTERNAL, label//': record not contiguous')
            return
        end if
        record_size = int(product(self%record_dims(1:rank - 1)))
        if (n_values < record_size .or. mod(n_values, max(record_size, 1)) /= 0) then
            call make_error(err, ERR_INTERNAL, label//': '//int_text(n_values)// &
                            ' values, not a whole number of records of '// &
                            int_text(record_size))
            return
        end if
        count = int(n_values/record_size, hsize_t)
        dims(1:rank - 1) = self%record_dims(1:rank - 1)
        dims(rank) = record + count - 1
        call h5dset_extent_f(self%id, dims(1:rank), hdferr)
        if (hdferr < 0) then
            call h5_error(err, label//': cannot extend dataset')
            return
        end if
        call h5dget_space_f(self%id, file_space, hdferr)
        if (hdferr < 0) then
            call h5_error(err, label//': cannot get dataspace')
            return
        end if
        steps: block
            call select_record(file_space, self%record_dims(1:rank - 1), record, label, &
                               mem_space, err, count)
            if (allocated(err)) exit steps
            call h5dwrite_f(self%id, type_id, buffer, hdferr, mem_space_id=mem_space, &
                            file_space_id=file_space)
            if (hdferr < 0) call h5_error(err, label//': cannot write record '// &
                                            int_text(int(record)))
        end block steps
        if (mem_space >= 0) call h5sclose_f(mem_space, hdferr)
        call h5sclose_f(file_space, hdferr)
    end subroutine write_record

    !> Select record `record` (the last dimension, from 1), or `count` records from it, of a
    !! series with records of the dimensions `record_dims` in `file_space`, and create the
    !! memory dataspace of its values (mem_space = -1 on failure).
    subroutine select_record(file_space, record_dims, record, label, mem_space, err, count)
        integer(hid_t), intent(in) :: file_space
        integer(hsize_t), intent(in) :: record_dims(:)
        integer(hsize_t), intent(in) :: record
        character(len=*), intent(in) :: label
        integer(hid_t), intent(out) :: mem_space
        type(error_t), allocatable, intent(out) :: err
        integer(hsize_t), intent(in), optional :: count
        integer(hsize_t) :: start(size(record_dims) + 1), records
        integer :: hdferr
        mem_space = -1
        records = 1
        if (present(count)) records = count
        start = 0
        start(size(start)) = record - 1
        call h5sselect_hyperslab_f(file_space, H5S_SELECT_SET_F, start, &
                                   [record_dims, records], hdferr)
        if (hdferr < 0) then
            call h5_error(err, label//': cannot select record '//int_text(int(record)))
            return
        end if
        ! the memory space has the selection's shape, so that HDF5 copies the block whole
        ! (a flat one makes it iterate over the selection element by element)
        call h5screate_simple_f(size(start), [record_dims, records], mem_space, hdferr)
        if (hdferr < 0) then
            mem_space = -1
            call h5_error(err, label//': cannot create memory dataspace')
        end if
    end subroutine select_record
end submodule ropedyn_h5_series
