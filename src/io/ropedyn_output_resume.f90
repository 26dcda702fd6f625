!> Continuing a run file (`ropedyn run --resume`, the sweep runner's resume): checking that
!! it can be continued (before anything in it changes), reopening it after its last
!! complete record and recording the restart in /solver/restarts; and closing a file
!! (shutdown, shared with the module's close and finalizer; abandon, after an I/O error).
submodule (ropedyn_output) ropedyn_output_resume
    use ropedyn_text, only: real_text
    use ropedyn_error, only: ERR_INPUT
    use ropedyn_h5, only: SERIES_REAL, SERIES_INTEGER, SERIES_TEXT
    use ropedyn_scene, only: scene_t, read_scene_text
    use ropedyn_os, only: release_space
    implicit none

contains

    module procedure output_reopen
        integer :: k
        logical :: salvaging

        if (self%is_open) call shutdown(self)
        call self%file%open(path, err, writable=.true.)
        if (allocated(err)) return
        self%is_open = .true.
        self%n_elements = n_elements
        self%restart_data = .true.
        self%state_size = [state_size, quad_size]
        ! first every check, with nothing changed: a file that cannot be continued is left
        ! as it was (its status, its reason, its records)
        salvaging = .false.
        if (present(salvage) .and. present(keep)) salvaging = salvage
        if (salvaging) then
            call open_checked(self, path, err, int(keep, hsize_t))
        else
            call open_checked(self, path, err)
        end if
        self%force_data = .false.
        if (present(internal_forces)) self%force_data = internal_forces
        call set_force_series(self, anchored)
        if (.not. allocated(err) .and. self%force_data) call open_forces(self, path, err)
        if (.not. allocated(err) .and. present(keep) .and. .not. salvaging) &
            call check_cut(self, path, keep, err)
        if (allocated(err)) then
            call shutdown(self)
            return
        end if
        if (present(keep)) self%n_records = max(0_hsize_t, min(self%n_records, &
                                                               int(keep, hsize_t)))
        steps: block
            do k = 1, N_SERIES
                call self%series(k)%truncate(self%n_records, err)
                if (allocated(err)) exit steps
            end do
            do k = 1, 2
                call self%state(k)%truncate(self%n_records, err)
                if (allocated(err)) exit steps
            end do
            do k = 1, size(self%force)
                if (.not. self%force_on(k)) cycle
                call self%force(k)%truncate(self%n_records, err)
                if (allocated(err)) exit steps
            end do
            call self%file%attribute('/', 'status', 'running', err)
            if (allocated(err)) exit steps
            call self%file%delete_attribute('/', 'reason', err)
            if (allocated(err)) exit steps
            call flush_file(self, err)
            if (allocated(err)) exit steps
            call keep_room(self, err)
        end block steps
        if (allocated(err)) then
            call abandon(self, err)
        else
            call allocate_pending(self)
        end if
    end procedure output_reopen

    !> Open every series of a file being continued and check it (nothing is written): each
    !! one there, extendible, of its kind of values and record size, with at least as many
    !! records as /time; the restart entries (if any) likewise. self%n_records: the
    !! length of /time. Errors are ERR_INPUT naming the dataset: the file was changed by
    !! something else than ropedyn.
    subroutine open_checked(self, path, err, limit)
        type(output_file_t), intent(inout) :: self
        character(len=*), intent(in) :: path
        type(error_t), allocatable, intent(out) :: err
        !> the records the series must hold when fewer than /time's (a salvaged file)
        integer(hsize_t), intent(in), optional :: limit
        type(h5_series_t) :: entry
        type(error_t), allocatable :: close_err
        character(len=:), allocatable :: name
        integer(hsize_t) :: n
        integer :: expected, k, kind

        do k = 1, N_SERIES + 2
            if (k <= N_SERIES) then
                name = trim(SERIES_NAME(k))
                expected = max(1, RECORD_ROWS(k)*RECORD_PER_ELEMENT(k)*self%n_elements)
                kind = merge(SERIES_INTEGER, SERIES_REAL, k == S_ORDER)
                call open_one(self%series(k))
            else
                name = trim(STATE_NAME(k - N_SERIES))
                expected = max(1, self%state_size(k - N_SERIES))
                kind = SERIES_REAL
                call open_one(self%state(k - N_SERIES))
            end if
            if (allocated(err)) return
        end do
        self%n_records = self%series(S_TIME)%length()
        if (present(limit)) self%n_records = min(self%n_records, limit)
        do k = 1, N_SERIES + 2
            if (k <= N_SERIES) then
                n = self%series(k)%length()
                name = trim(SERIES_NAME(k))
            else
                n = self%state(k - N_SERIES)%length()
                name = trim(STATE_NAME(k - N_SERIES))
            end if
            if (n < self%n_records) then
                call make_error(err, ERR_INPUT, path//': '//name//': '//int_text(int(n))// &
                    ' records, fewer than /time ('//int_text(int(self%n_records))// &
                    '): the file cannot be continued')
                return
            end if
        end do
        if (.not. self%file%exists('/solver/restarts')) return
        do k = 1, size(RESTART_NAME)
            name = '/solver/restarts/'//trim(RESTART_NAME(k))
            kind = SERIES_REAL
            if (k == 2 .or. k == 3) kind = SERIES_INTEGER
            if (RESTART_WIDTH(k) > 0) kind = SERIES_TEXT
            expected = 1
            ! entries added later are absent in older files: created at the next restart
            if (k > RESTART_REQUIRED .and. .not. self%file%exists(name)) cycle
            call open_one(entry)
            if (.not. allocated(err) .and. k == 1) n = entry%length()
            if (.not. allocated(err) .and. entry%length() /= n) call make_error(err, &
                ERR_INPUT, path//': '//name//': '//int_text(int(entry%length()))// &
                ' entries, /solver/restarts/time has '//int_text(int(n))// &
                ': the file cannot be continued')
            call entry%close(close_err)
            if (allocated(err)) return
        end do
    contains
        !> Open series `name` (not there, unfit: an error) and check its record size.
        subroutine open_one(series)
            type(h5_series_t), intent(inout) :: series
            character(len=:), allocatable :: why
            if (.not. self%file%exists(name)) then
                why = 'missing'
                if (name(:7) == '/state/') why = why//' (a file without restart data cannot '// &
                    'be continued)'
            else
                call self%file%open_series(series, name, err)
                if (allocated(err)) return
                why = series%unfit(kind)
                if (len(why) == 0 .and. kind /= SERIES_TEXT .and. &
                    series%record_size() /= expected) why = 'records of '// &
                    int_text(series%record_size())//' values, expected '//int_text(expected)// &
                    ' for the '//int_text(self%n_elements)//' elements and state size '// &
                    int_text(self%state_size(1))//' of the scene'
            end if
            if (len(why) > 0) call make_error(err, ERR_INPUT, path//': '//name//': '//why// &
                                              ': the file cannot be continued')
        end subroutine open_one
    end subroutine open_checked

    module procedure whole_records
        type(h5_file_t) :: h5
        type(error_t), allocatable :: close_err
        real(wp), allocatable :: time(:)
        integer(hsize_t) :: dims(1), k

        count = 0
        call h5%open(path, err)
        if (allocated(err)) return
        call h5%read_reals('/time', time, dims, err)
        if (.not. allocated(err)) then
            do k = int(size(time), hsize_t), 1_hsize_t, -1_hsize_t
                if (.not. record_reads(k)) cycle
                count = int(k)
                exit
            end do
        end if
        call h5%close(close_err)
        if (allocated(close_err) .and. .not. allocated(err)) call move_alloc(close_err, err)
    contains
        !> Record k of every series reads back.
        logical function record_reads(k) result(reads)
            integer(hsize_t), intent(in) :: k
            integer :: j
            reads = .false.
            do j = 1, N_SERIES
                if (.not. reads_one(trim(SERIES_NAME(j)), k)) return
            end do
            do j = 1, size(STATE_NAME)
                if (.not. reads_one(trim(STATE_NAME(j)), k)) return
            end do
            do j = 1, N_FORCE_SERIES
                if (.not. h5%exists(trim(FORCE_NAME(j)))) cycle
                if (.not. reads_one(trim(FORCE_NAME(j)), k)) return
            end do
            reads = .true.
        end function record_reads

        !> Record k of the series `name` reads back, with finite values.
        logical function reads_one(name, k) result(reads)
            character(len=*), intent(in) :: name
            integer(hsize_t), intent(in) :: k
            real(wp), allocatable :: values(:)
            type(error_t), allocatable :: rerr
            call h5%read_record(name, k, values, rerr)
            reads = .not. allocated(rerr)
            if (reads) reads = all(ieee_is_finite(values))
        end function reads_one
    end procedure whole_records

    !> Records keep + 1 .. n_records are to be cut: only a last record off the file's own
    !! output grid may be (where an interrupted or failed run stopped). A record on that
    !! grid (a multiple of the stored scene's output_interval, or its t_end) is a completed
    !! record: ERR_INPUT (a resume with another output_interval would delete it).
    subroutine check_cut(self, path, keep, err)
        type(output_file_t), intent(inout) :: self
        character(len=*), intent(in) :: path
        integer, intent(in) :: keep
        type(error_t), allocatable, intent(out) :: err
        type(scene_t) :: stored
        character(len=:), allocatable :: text
        character(len=0) :: none(0)
        real(wp), allocatable :: t(:)
        real(wp) :: dt, tol
        integer(hsize_t) :: k

        if (int(keep, hsize_t) >= self%n_records) return
        call self%file%read_attribute('scene', text, err)
        if (.not. allocated(err)) call read_scene_text(path//': scene', text, none, stored, err)
        if (allocated(err)) return
        dt = stored%solver%output_interval
        do k = max(1_hsize_t, int(keep + 1, hsize_t)), self%n_records
            call self%file%read_record('/time', k, t, err)
            if (allocated(err)) return
            tol = 1.0e-12_wp*max(abs(t(1)), dt)
            if (abs(t(1) - dt*anint(t(1)/dt)) <= tol .or. &
                abs(t(1) - stored%solver%t_end) <= tol) then
                call make_error(err, ERR_INPUT, path//': record '//int_text(int(k) - 1)// &
                    ' (t = '//real_text(t(1))//' s) is on the output grid of the file '// &
                    '(output_interval = '//real_text(dt)//' s): continuing on another '// &
                    'grid would delete it (a resume keeps the output_interval)')
                return
            end if
        end do
    end subroutine check_cut

    !> Open the internal-force series of a file being reopened (self%n_records set) and
    !! check their record sizes and lengths (nothing changed). A file without them was
    !! written before they were stored: it is not continued (its records would lack them).
    subroutine open_forces(self, path, err)
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
        end do
    end subroutine open_forces

    module procedure output_add_restart
        type(h5_series_t) :: entry(size(RESTART_NAME))
        type(error_t), allocatable :: close_err
        integer(hsize_t) :: n
        integer :: k
        character(len=:), allocatable :: name

        if (.not. self%is_open) then
            call not_open(self, 'add_restart', err)
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
                                                 '', err, wide=(k == 3))
                end if
                if (allocated(err)) exit steps_
            end do
            n = entry(1)%length() + 1
            call entry(1)%append(n, [t], err)
            if (.not. allocated(err)) call entry(2)%append(n, [record], err)
            ! (a file written before steps were int64 keeps its int32 entries: HDF5
            ! converts; one beyond their range is clipped)
            if (.not. allocated(err)) call entry(3)%append(n, [steps], err)
            if (.not. allocated(err)) call entry(4)%append(n, [cpu_time], err)
            if (.not. allocated(err)) call entry(5)%append_text(n, utc_timestamp(), err)
            if (.not. allocated(err)) call entry(6)%append_text(n, previous_status, err)
            if (.not. allocated(err)) call entry(7)%append_text(n, previous_reason, err)
            if (.not. allocated(err)) call entry(8)%append_text(n, version, err)
            if (.not. allocated(err)) call entry(9)%append_text(n, overrides, err)
        end block steps_
        do k = 1, size(entry)
            call entry(k)%close(close_err)
            if (allocated(close_err) .and. .not. allocated(err)) call move_alloc(close_err, err)
        end do
        if (.not. allocated(err)) call flush_file(self, err)
        if (allocated(err)) call abandon(self, err)
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
        if (.not. self%file%in_memory()) call release_space(self%file%file_name())
        self%n_pending = 0
        self%is_open = .false.
        if (present(err) .and. allocated(first)) call move_alloc(first, err)
    end procedure shutdown

    module procedure abandon
        type(error_t), allocatable :: e
        character(len=:), allocatable :: note, kept
        integer :: k

        if (.not. self%is_open) return
        self%n_pending = 0      ! not to be written: the file takes nothing more
        do k = 1, N_SERIES
            call self%series(k)%close(e)
        end do
        do k = 1, 2
            call self%state(k)%close(e)
        end do
        do k = 1, N_FORCE_SERIES
            call self%force(k)%close(e)
        end do
        kept = int_text(int(self%n_records))//' complete records'
        call self%file%attribute('/', 'status', 'failed', e)
        if (.not. allocated(e)) call self%file%attribute('/', 'reason', err%message, e)
        if (.not. allocated(e)) call self%file%flush(e)
        if (allocated(e)) then
            note = '; the file is incomplete and may be unreadable (its status could not '// &
                'be set to failed)'
        else
            note = '; the file is closed with status failed ('//kept//' kept)'
        end if
        call self%file%close(e)
        if (allocated(e)) note = '; the file is incomplete and may be unreadable (it could '// &
            'not be closed)'
        call release_space(self%file%file_name())
        self%is_open = .false.
        err%message = err%message//note
        self%broken = err%message
    end procedure abandon

    module procedure not_open
        if (allocated(self%broken)) then
            call make_error(err, ERR_IO, self%broken)
        else
            call make_error(err, ERR_INTERNAL, file_label(self)//': '//what// &
                            ': file is not open')
        end if
    end procedure not_open

    module procedure file_label
        label = self%file%file_name()
        if (len(label) == 0) label = '(output file never created)'
    end procedure file_label
end submodule ropedyn_output_resume
