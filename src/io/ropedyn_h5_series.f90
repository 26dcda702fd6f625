!> Series of `ropedyn_h5`: extendible, chunked datasets written one record at a time.
submodule (ropedyn_h5) ropedyn_h5_series
    implicit none

contains

    module procedure h5_create_series
        integer(hsize_t) :: dims(3), max_dims(3), chunk(3), record_bytes
        integer(hid_t) :: type_id
        integer :: rank

        rank = size(record_dims) + 1
        series%path = self%path
        series%name = name
        series%rank = rank
        series%record_dims = 1
        series%record_dims(1:rank - 1) = record_dims

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

        call new_dataset(self, name, type_id, dims(1:rank), series%id, err, max_dims(1:rank), &
                         chunk(1:rank))
        if (allocated(err)) return
        call string_attribute(self%path, series%id, name, 'units', units, err)
        if (allocated(err)) return
        if (len(columns) > 0) &
            call string_attribute(self%path, series%id, name, 'columns', columns, err)
    end procedure h5_create_series

    module procedure series_close
        integer :: hdferr
        if (self%id < 0) return
        call h5dclose_f(self%id, hdferr)
        self%id = -1
        if (hdferr < 0) call make_error(err, ERR_IO, self%path//': '//self%name// &
                                        ': cannot close dataset')
    end procedure series_close

    module procedure append_real
        call write_record(self, record, size(values), h5kind_to_type(wp, H5_REAL_KIND), &
                          c_loc(values), is_contiguous(values), err)
    end procedure append_real

    module procedure append_integer
        call write_record(self, record, size(values), h5kind_to_type(kind(0), H5_INTEGER_KIND), &
                          c_loc(values), is_contiguous(values), err)
    end procedure append_integer

    !> Extend the series to `record` records and write the `n_values` values at `buffer`
    !! (`packed`: one block) as that record.
    subroutine write_record(self, record, n_values, type_id, buffer, packed, err)
        class(h5_series_t), intent(inout) :: self
        integer(hsize_t), intent(in) :: record
        integer, intent(in) :: n_values
        integer(hid_t), intent(in) :: type_id
        type(c_ptr), intent(in) :: buffer
        logical, intent(in) :: packed
        type(error_t), allocatable, intent(out) :: err
        integer(hsize_t) :: dims(3), start(3), count(3)
        integer(hid_t) :: file_space, mem_space
        integer :: rank, hdferr
        character(len=:), allocatable :: label

        label = self%path//': '//self%name
        rank = self%rank
        if (.not. packed) then
            call make_error(err, ERR_INTERNAL, label//': record not contiguous')
            return
        end if
        if (int(product(self%record_dims(1:rank - 1))) /= n_values) then
            call make_error(err, ERR_INTERNAL, label//': record of '//int_text(n_values)// &
                            ' values, expected '// &
                            int_text(int(product(self%record_dims(1:rank - 1)))))
            return
        end if
        dims(1:rank - 1) = self%record_dims(1:rank - 1)
        dims(rank) = record
        call h5dset_extent_f(self%id, dims(1:rank), hdferr)
        if (hdferr < 0) then
            call make_error(err, ERR_IO, label//': cannot extend dataset')
            return
        end if
        call h5dget_space_f(self%id, file_space, hdferr)
        if (hdferr < 0) then
            call make_error(err, ERR_IO, label//': cannot get dataspace')
            return
        end if
        start = 0
        start(rank) = record - 1
        count(1:rank - 1) = self%record_dims(1:rank - 1)
        count(rank) = 1
        mem_space = -1
        steps: block
            call h5sselect_hyperslab_f(file_space, H5S_SELECT_SET_F, start(1:rank), &
                                       count(1:rank), hdferr)
            if (hdferr < 0) then
                call make_error(err, ERR_IO, label//': cannot select record '// &
                                int_text(int(record)))
                exit steps
            end if
            call h5screate_simple_f(1, [int(n_values, hsize_t)], mem_space, hdferr)
            if (hdferr < 0) then
                mem_space = -1
                call make_error(err, ERR_IO, label//': cannot create memory dataspace')
                exit steps
            end if
            call h5dwrite_f(self%id, type_id, buffer, hdferr, mem_space_id=mem_space, &
                            file_space_id=file_space)
            if (hdferr < 0) call make_error(err, ERR_IO, label//': cannot write record '// &
                                            int_text(int(record)))
        end block steps
        if (mem_space >= 0) call h5sclose_f(mem_space, hdferr)
        call h5sclose_f(file_space, hdferr)
    end subroutine write_record
end submodule ropedyn_h5_series
