!> Files of `ropedyn_h5`: the library opened, a file created or opened, with the checks
!! that keep a run off files it must not touch (a device, a FIFO, a file another program
!! holds locked) and messages that name the reason of a failure.
submodule (ropedyn_h5) ropedyn_h5_files
    implicit none

contains

    module procedure library_acquire
        integer :: hdferr
        logical :: opened
        call c_h5_prepare()
        ! open once: h5open_f copies the Fortran interface's predefined types at every call
        ! and never frees the copies (55 type ids a call: a leak of a run or more). Their
        ! being valid says it was done (and not undone since by an h5close_f).
        call h5iis_valid_f(H5T_NATIVE_CHARACTER, opened, hdferr)
        if (hdferr < 0 .or. .not. opened) then
            call h5open_f(hdferr)
            if (h5_failed(hdferr, path//': cannot initialize the HDF5 library', err)) return
        end if
        call h5eset_auto_f(0, hdferr)
        if (hdferr < 0) call h5_error(err, path//': cannot silence HDF5 error printing')
    end procedure library_acquire

    module procedure h5_create
        character(len=:), allocatable :: special
        integer :: hdferr
        call self%close(err)
        if (allocated(err)) return
        self%memory = .false.
        if (present(memory)) self%memory = memory
        if (self%memory) then
            call library_acquire(path, err)
            if (allocated(err)) return
            self%id = c_h5_create_memory(path//c_null_char)
            if (self%id < 0) then
                self%id = -1
                call h5_error(err, path//': cannot create the file in memory')
                return
            end if
            self%path = path
            self%is_open = .true.
            return
        end if
        special = special_file_reason(path)
        if (len(special) > 0) then
            call make_error(err, ERR_INPUT, path//': cannot create file: it is '//special)
            return
        end if
        if (try_lock(path) == ERRNO_EWOULDBLOCK) then
            call make_error(err, ERR_IO, path//': cannot create file: '//locked_text(path)// &
                            ' (left as it is)')
            return
        end if
        call library_acquire(path, err)
        if (allocated(err)) return
        call h5fcreate_f(path, H5F_ACC_TRUNC_F, self%id, hdferr)
        if (hdferr < 0) then
            self%id = -1
            if (h5_reason() == ERRNO_EWOULDBLOCK) then
                call make_error(err, ERR_IO, path//': cannot create file: '//locked_text(path))
            else
                call h5_error(err, path//': cannot create file')
            end if
            return
        end if
        self%path = path
        self%is_open = .true.
    end procedure h5_create

    module procedure h5_open
        character(len=:), allocatable :: special
        logical :: rw, exists
        integer :: hdferr, errnum
        call self%close(err)
        if (allocated(err)) return
        inquire (file=path, exist=exists)
        if (.not. exists) then
            call make_error(err, ERR_INPUT, path//': no such file')
            return
        end if
        special = special_file_reason(path)
        if (len(special) > 0) then
            call make_error(err, ERR_INPUT, path//': cannot open: '//special)
            return
        end if
        call library_acquire(path, err)
        if (allocated(err)) return
        rw = .false.
        if (present(writable)) rw = writable
        if (rw) then
            call h5fopen_f(path, H5F_ACC_RDWR_F, self%id, hdferr)
        else
            call h5fopen_f(path, H5F_ACC_RDONLY_F, self%id, hdferr)
        end if
        if (hdferr < 0) then
            self%id = -1
            errnum = h5_reason()
            if (errnum == ERRNO_EWOULDBLOCK) then
                call make_error(err, ERR_IO, path//': cannot open: '//locked_text(path))
            else if (errnum > 0) then
                call h5_error(err, path//': cannot open')
            else if (rw) then
                call make_error(err, ERR_IO, path//': cannot open for writing')
            else
                call make_error(err, ERR_IO, path//': cannot open as HDF5 file')
            end if
            return
        end if
        self%path = path
        self%is_open = .true.
    end procedure h5_open

    !> 'locked by pid N (...)': a file another process holds open with HDF5.
    function locked_text(path) result(text)
        character(len=*), intent(in) :: path
        character(len=:), allocatable :: text
        integer :: pid
        pid = lock_holder(path)
        if (pid > 0) then
            text = 'locked by pid '//int_text(pid)
        else
            text = 'locked by another process'
        end if
        text = text//' (a run writing it, or a program reading it)'
    end function locked_text
end submodule ropedyn_h5_files
