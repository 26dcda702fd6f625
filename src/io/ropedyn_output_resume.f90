!> Continuing a run file (`ropedyn run --resume`, the sweep runner's resume): reopening it
!! after its last complete record and recording the restart in /solver/restarts; and
!! closing a file (shutdown, shared with the module's close and finalizer).
submodule (ropedyn_output) ropedyn_output_resume
    implicit none

contains

    module procedure output_reopen
        integer :: expected, k

        if (self%is_open) call shutdown(self)
        call self%file%open(path, err, writable=.true.)
        if (allocated(err)) return
        self%is_open = .true.
        self%n_elements = n_elements
        self%restart_data = .true.
        self%state_size = [state_size, quad_size]
        self%force_data = .false.
        if (present(internal_forces)) self%force_data = internal_forces
        call set_force_series(self, anchored)
        steps: block
            do k = 1, N_SERIES
                call self%file%open_series(self%series(k), trim(SERIES_NAME(k)), err)
                if (allocated(err)) exit steps
            end do
            do k = 1, 2
                if (.not. self%file%exists(trim(STATE_NAME(k)))) then
                    call make_error(err, ERR_IO, path//': '//trim(STATE_NAME(k))// &
                        ': missing (a file without restart data cannot be continued)')
                    exit steps
                end if
                call self%file%open_series(self%state(k), trim(STATE_NAME(k)), err)
                if (allocated(err)) exit steps
            end do
            do k = 1, N_SERIES
                expected = max(1, RECORD_ROWS(k)*RECORD_PER_ELEMENT(k)*n_elements)
                if (self%series(k)%record_size() /= expected) then
                    call make_error(err, ERR_IO, path//': '//trim(SERIES_NAME(k))// &
                        ': records of '//int_text(self%series(k)%record_size())// &
                        ' values, expected '//int_text(expected)//' for '// &
                        int_text(n_elements)//' elements')
                    exit steps
                end if
            end do
            do k = 1, 2
                if (self%state(k)%record_size() /= max(1, self%state_size(k))) then
                    call make_error(err, ERR_IO, path//': '//trim(STATE_NAME(k))// &
                        ': records of '//int_text(self%state(k)%record_size())// &
                        ' values, the model has '//int_text(self%state_size(k)))
                    exit steps
                end if
            end do
            self%n_records = self%series(S_TIME)%length()
            if (present(keep)) self%n_records = max(0_hsize_t, min(self%n_records, &
                                                                int(keep, hsize_t)))
            if (self%state(1)%length() < self%n_records .or. &
                self%state(2)%length() < self%n_records) then
                call make_error(err, ERR_IO, path//': /state/y: fewer records than /time')
                exit steps
            end if
            if (self%force_data) then
                call reopen_forces(self, path, err)
                if (allocated(err)) exit steps
            end if
            do k = 1, N_SERIES
                call self%series(k)%truncate(self%n_records, err)
                if (allocated(err)) exit steps
            end do
            do k = 1, 2
                call self%state(k)%truncate(self%n_records, err)
                if (allocated(err)) exit steps
            end do
            call self%file%attribute('/', 'status', 'running', err)
            if (allocated(err)) exit steps
            call self%file%delete_attribute('/', 'reason', err)
            if (allocated(err)) exit steps
            call self%file%flush(err)
        end block steps
        if (allocated(err)) then
            call shutdown(self)
        else
            call allocate_pending(self)
        end if
    end procedure output_reopen

    !> Open the internal-force series of a file being reopened (self%n_records set), check
    !! their record sizes and lengths, and cut them to n_records. A file without them was
    !! written before they were stored: it is not continued (its records would lack them).
    subroutine reopen_forces(self, path, err)
        type(output_file_t), intent(inout) :: self
        character(len=*), intent(in) :: path
        type(error_t), allocatable, intent(out) :: err
        integer :: k, expected
        do k = 1, N_FORCE_SERIES
            if (self%file%exists(trim(FORCE_NAME(k))) .neqv. self%force_on(k)) then
                if (k < N_FORCE_SERIES - 1) then
                    call make_error(err, ERR_IO, path//': '//trim(FORCE_NAME(k))// &
                        ': missing: the file was written by a version of ropedyn that did '// &
                        'not store the internal forces; it cannot be continued (run the '// &
                        'scene again)')
                else
                    call make_error(err, ERR_IO, path//': '//trim(FORCE_NAME(k))//': '// &
                        trim(merge('missing', 'present', self%force_on(k)))//': the '// &
                        'scene''s supports differ from those of the file')
                end if
                return
            end if
            if (.not. self%force_on(k)) cycle
            call self%file%open_series(self%force(k), trim(FORCE_NAME(k)), err)
            if (allocated(err)) return
            expected = force_record_size(k, self%n_elements)
            if (self%force(k)%record_size() /= expected) then
                call make_error(err, ERR_IO, path//': '//trim(FORCE_NAME(k))// &
                    ': records of '//int_text(self%force(k)%record_size())// &
                    ' values, expected '//int_text(expected)//' for '// &
                    int_text(self%n_elements)//' elements')
                return
            end if
            if (self%force(k)%length() < self%n_records) then
                call make_error(err, ERR_IO, path//': '//trim(FORCE_NAME(k))// &
                    ': fewer records than /time')
                return
            end if
            call self%force(k)%truncate(self%n_records, err)
            if (allocated(err)) return
        end do
    end subroutine reopen_forces

    module procedure output_add_restart
        type(h5_series_t) :: entry(size(RESTART_NAME))
        type(error_t), allocatable :: close_err
        integer(hsize_t) :: n
        integer :: k
        character(len=:), allocatable :: name

        if (.not. self%is_open) then
            call make_error(err, ERR_INTERNAL, file_label(self)//': add_restart: file is not open')
            return
        end if
        steps_: block
            if (.not. self%file%exists('/solver/restarts')) then
                call self%file%group('/solver/restarts', err)
                if (allocated(err)) exit steps_
            end if
            do k = 1, size(RESTART_NAME)
                name = '/solver/restarts/'//trim(RESTART_NAME(k))
                if (self%file%exists(name)) then
                    call self%file%open_series(entry(k), name, err)
                else if (RESTART_WIDTH(k) > 0) then
                    call self%file%create_text_series(entry(k), name, RESTART_WIDTH(k), '', err)
                else
                    call self%file%create_series(entry(k), name, [integer(hsize_t) ::], &
                                                 k == 2 .or. k == 3, trim(RESTART_UNITS(k)), &
                                                 '', err)
                end if
                if (allocated(err)) exit steps_
            end do
            n = entry(1)%length() + 1
            call entry(1)%append(n, [t], err)
            if (.not. allocated(err)) call entry(2)%append(n, [record], err)
            if (.not. allocated(err)) call entry(3)%append(n, [int(min(steps, &
                int(huge(1), i8)))], err)
            if (.not. allocated(err)) call entry(4)%append(n, [cpu_time], err)
            if (.not. allocated(err)) call entry(5)%append_text(n, utc_timestamp(), err)
            if (.not. allocated(err)) call entry(6)%append_text(n, previous_status, err)
            if (.not. allocated(err)) call entry(7)%append_text(n, previous_reason, err)
        end block steps_
        do k = 1, size(entry)
            call entry(k)%close(close_err)
            if (allocated(close_err) .and. .not. allocated(err)) call move_alloc(close_err, err)
        end do
        if (.not. allocated(err)) call self%file%flush(err)
    end procedure output_add_restart

    module procedure shutdown
        type(error_t), allocatable :: first, e
        integer :: k

        if (.not. self%is_open) return
        call write_pending(self, e)
        if (allocated(e)) call move_alloc(e, first)
        do k = 1, N_SERIES
            call self%series(k)%close(e)
            if (allocated(e) .and. .not. allocated(first)) call move_alloc(e, first)
        end do
        do k = 1, 2
            call self%state(k)%close(e)
            if (allocated(e) .and. .not. allocated(first)) call move_alloc(e, first)
        end do
        do k = 1, N_FORCE_SERIES
            call self%force(k)%close(e)
            if (allocated(e) .and. .not. allocated(first)) call move_alloc(e, first)
        end do
        call self%file%close(e)
        if (allocated(e) .and. .not. allocated(first)) call move_alloc(e, first)
        self%n_pending = 0
        self%is_open = .false.
        if (present(err) .and. allocated(first)) call move_alloc(first, err)
    end procedure shutdown

    module procedure file_label
        label = self%file%file_name()
        if (len(label) == 0) label = '(output file never created)'
    end procedure file_label
end submodule ropedyn_output_resume
