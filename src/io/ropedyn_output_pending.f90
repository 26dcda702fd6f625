!> Appending records to a run file: each record is held in memory and the records are
!! written in blocks, one HDF5 write per series and block (`pending` of output_file_t).
!! What a crash can lose is unchanged: pending records are written, and the file flushed,
!! whenever FLUSH_PERIOD has passed, and before the file is finished or closed.
submodule (ropedyn_output) ropedyn_output_pending
    use ropedyn_os, only: reserve_space, errno_text, ERRNO_ENOSPC, ERRNO_EDQUOT, ERRNO_EFBIG
    implicit none

contains

    module procedure output_append
        real(wp) :: scalars(S_KINETIC:S_STEP_SIZE)
        integer :: k, m

        if (.not. self%is_open) then
            call not_open(self, 'append', err)
            return
        end if
        call check_record_args(self, q, qdot, points, err, y, yq, axial, shear, moment, &
                               reaction, position)
        if (allocated(err)) return

        m = self%n_pending + 1
        call put(self, S_TIME, m, [t])
        call put(self, S_Q, m, reshape(q, [size(q)]))
        call put(self, S_QDOT, m, reshape(qdot, [size(qdot)]))
        call put(self, S_POINTS, m, reshape(points, [size(points)]))
        scalars = [energy%kinetic, energy%elastic, energy%gravity, energy%dissipated, &
                   energy%support_work, energy%total(), step_size]
        do k = S_KINETIC, S_STEP_SIZE
            call put(self, k, m, scalars(k:k))
        end do
        self%pending_order(m) = order
        if (self%restart_data) then
            call put(self, N_SERIES + 1, m, y)
            call put(self, N_SERIES + 2, m, [yq(1:self%state_size(2)), &
                                             spread(0.0_wp, 1, max(1, self%state_size(2)) &
                                                    - self%state_size(2))])
        end if
        if (self%force_data) then
            call put(self, N_SERIES + 3, m, axial)
            call put(self, N_SERIES + 4, m, shear)
            call put(self, N_SERIES + 5, m, moment)
            call put(self, N_SERIES + 6, m, reaction(:, 1))
            call put(self, N_SERIES + 7, m, reaction(:, 2))
            if (self%force_on(N_FORCE_SERIES - 1)) &
                call put(self, N_SERIES + 8, m, position(:, 1))
            if (self%force_on(N_FORCE_SERIES)) call put(self, N_SERIES + 9, m, position(:, 2))
        end if
        self%n_pending = m
        call write_when_due(self, err)
    end procedure output_append

    module procedure write_counters
        integer(i8) :: counters(size(COUNTER_NAMES))
        real(wp) :: times(size(TIMER_NAMES))
        integer :: k
        counters = counter_values(stats)
        do k = 1, size(COUNTER_NAMES)
            call self%file%write('/solver/'//trim(COUNTER_NAMES(k)), counters(k), '1', err)
            if (allocated(err)) return
        end do
        call self%file%write('/solver/cpu_time', cpu_time, 's', err)
        if (allocated(err)) return
        ! (in TIMER_NAMES' order)
        times = [stats%time_advance, stats%time_rhs, stats%time_jac, stats%time_factor, &
                 stats%time_solve]
        do k = 1, size(TIMER_NAMES)
            call self%file%write('/solver/'//trim(TIMER_NAMES(k)), times(k), 's', err)
            if (allocated(err)) return
        end do
        call self%file%write('/solver/reduced_newton', merge(1_i8, 0_i8, &
                             stats%reduced_newton), '1', err)
    end procedure write_counters

    !> The pending records written when they fill the block or are due (the first record,
    !! or FLUSH_PERIOD since the last flush; then the file is flushed too); a failure
    !! abandons the file.
    subroutine write_when_due(self, err)
        class(output_file_t), intent(inout) :: self
        type(error_t), allocatable, intent(inout) :: err
        real(wp) :: now
        logical :: due
        now = clock_seconds()
        due = self%n_records + self%n_pending == 1 .or. &
              now - self%last_flush >= FLUSH_PERIOD
        if (due .or. self%n_pending == self%capacity) then
            call write_pending(self, err)
            ! room for what follows (not at the end: a run that got all its records written
            ! closes its file whatever room is left)
            if (.not. allocated(err)) call keep_room(self, err)
        end if
        if (due .and. .not. allocated(err)) then
            call flush_file(self, err)
            self%last_flush = now
        end if
        ! the counters kept for this flush, written and flushed after the records: a kill
        ! inside a flush leaves the counters behind the records, never ahead of them (HDF5
        ! writes small datasets first: a resume counted the lost steps twice)
        if (due .and. self%has_kept .and. .not. allocated(err)) then
            call write_counters(self, self%kept_stats, self%kept_cpu, err)
            if (.not. allocated(err)) call flush_file(self, err)
            self%has_kept = .false.
        end if
        if (allocated(err)) call abandon(self, err)
    end subroutine write_when_due

    !> Record m of series k.
    subroutine put(self, k, m, values)
        class(output_file_t), intent(inout) :: self
        integer, intent(in) :: k, m
        real(wp), intent(in) :: values(:)
        integer :: r
        r = size(values)
        self%pending(k)%v((m - 1)*r + 1:m*r) = values
    end subroutine put

    !> ERR_INTERNAL unless a record's arrays have the shapes the file was made for, with
    !! the restart data and internal forces it holds.
    subroutine check_record_args(self, q, qdot, points, err, y, yq, axial, shear, moment, &
                                 reaction, position)
        class(output_file_t), intent(in) :: self
        real(wp), intent(in) :: q(:, :), qdot(:, :), points(:, :)
        type(error_t), allocatable, intent(inout) :: err
        real(wp), intent(in), optional :: y(:), yq(:), axial(:), shear(:), moment(:)
        real(wp), intent(in), optional :: reaction(:, :), position(:, :)
        integer :: n
        n = self%n_elements
        call check_shape(self, q, '/state/q', 3, n, err)
        if (allocated(err)) return
        call check_shape(self, qdot, '/state/qdot', 3, n, err)
        if (allocated(err)) return
        call check_shape(self, points, '/rope/points', 2, 2*n, err)
        if (allocated(err)) return
        if (self%restart_data) then
            if (.not. (present(y) .and. present(yq))) then
                call make_error(err, ERR_INTERNAL, self%file%file_name()//': append: the '// &
                                'file holds restart data: y and yq are needed')
            else if (size(y) /= self%state_size(1) .or. size(yq) < self%state_size(2)) then
                call make_error(err, ERR_INTERNAL, self%file%file_name()//': append: y has '// &
                                int_text(size(y))//' and yq '//int_text(size(yq))// &
                                ' values, expected '//int_text(self%state_size(1))//' and '// &
                                int_text(self%state_size(2)))
            end if
            if (allocated(err)) return
        end if
        if (self%force_data) call check_forces(self, n, err, axial, shear, moment, reaction, &
                                               position)
    end subroutine check_record_args

    !> ERR_INTERNAL unless the internal forces are present with n + 1 joints and the
    !! reactions and positions with shape (2, 2).
    subroutine check_forces(self, n, err, axial, shear, moment, reaction, position)
        class(output_file_t), intent(in) :: self
        integer, intent(in) :: n
        type(error_t), allocatable, intent(inout) :: err
        real(wp), intent(in), optional :: axial(:), shear(:), moment(:)
        real(wp), intent(in), optional :: reaction(:, :), position(:, :)
        if (.not. (present(axial) .and. present(shear) .and. present(moment) .and. &
                   present(reaction) .and. present(position))) then
            call make_error(err, ERR_INTERNAL, self%file%file_name()//': append: the '// &
                            'file holds internal forces: axial, shear, moment, '// &
                            'reaction and position are needed')
        else if (size(axial) /= n + 1 .or. size(shear) /= n + 1 .or. &
                 size(moment) /= n + 1) then
            call make_error(err, ERR_INTERNAL, self%file%file_name()//': append: '// &
                            'axial, shear, moment have '//int_text(size(axial))//', '// &
                            int_text(size(shear))//', '//int_text(size(moment))// &
                            ' values, expected '//int_text(n + 1))
        else
            call check_shape(self, reaction, '/supports/*/reaction', 2, 2, err)
            if (.not. allocated(err)) &
                call check_shape(self, position, '/supports/*/position', 2, 2, err)
        end if
    end subroutine check_forces

    !> ERR_INTERNAL unless the record `a` of dataset `name` has the shape (rows, cols).
    subroutine check_shape(self, a, name, rows, cols, err)
        class(output_file_t), intent(in) :: self
        real(wp), intent(in) :: a(:, :)
        character(len=*), intent(in) :: name
        integer, intent(in) :: rows, cols
        type(error_t), allocatable, intent(inout) :: err
        if (size(a, 1) /= rows .or. size(a, 2) /= cols) &
            call make_error(err, ERR_INTERNAL, self%file%file_name()//': '//name// &
                            ': record has shape ('//int_text(size(a, 1))//', '// &
                            int_text(size(a, 2))//'), expected ('//int_text(rows)//', '// &
                            int_text(cols)//')')
    end subroutine check_shape

    module procedure allocate_pending
        integer :: sizes(size(self%pending)), k
        do k = 1, N_SERIES
            sizes(k) = max(1, RECORD_ROWS(k)*RECORD_PER_ELEMENT(k)*self%n_elements)
        end do
        sizes(N_SERIES + 1:) = 0
        if (self%restart_data) sizes(N_SERIES + 1:N_SERIES + 2) = max(1, self%state_size)
        do k = 1, N_FORCE_SERIES
            if (self%force_on(k)) sizes(N_SERIES + 2 + k) = force_record_size(k, self%n_elements)
        end do
        self%capacity = max(1, min(MAX_PENDING, PENDING_BYTES/(8*sum(sizes))))
        do k = 1, size(self%pending)
            if (allocated(self%pending(k)%v)) deallocate (self%pending(k)%v)
            allocate (self%pending(k)%v(sizes(k)*self%capacity))
        end do
        if (allocated(self%pending_order)) deallocate (self%pending_order)
        allocate (self%pending_order(self%capacity))
        self%n_pending = 0
    end procedure allocate_pending

    module procedure write_pending
        integer(hsize_t) :: first
        integer :: k, m, r

        m = self%n_pending
        if (m == 0 .or. .not. self%is_open) return
        first = self%n_records + 1
        do k = 2, N_SERIES
            if (k == S_ORDER) then
                call self%series(k)%append(first, self%pending_order(1:m), err)
            else
                r = size(self%pending(k)%v)/self%capacity
                call self%series(k)%append(first, self%pending(k)%v(1:m*r), err)
            end if
            if (allocated(err)) return
        end do
        if (self%restart_data) then
            do k = 1, 2
                r = size(self%pending(N_SERIES + k)%v)/self%capacity
                call self%state(k)%append(first, self%pending(N_SERIES + k)%v(1:m*r), err)
                if (allocated(err)) return
            end do
        end if
        if (self%force_data) then
            do k = 1, N_FORCE_SERIES
                if (.not. self%force_on(k)) cycle
                r = size(self%pending(N_SERIES + 2 + k)%v)/self%capacity
                call self%force(k)%append(first, self%pending(N_SERIES + 2 + k)%v(1:m*r), err)
                if (allocated(err)) return
            end do
        end if
        ! /time last: its length counts the complete records
        call self%series(S_TIME)%append(first, self%pending(S_TIME)%v(1:m), err)
        if (allocated(err)) return
        self%n_records = self%n_records + int(m, hsize_t)
        self%n_pending = 0
        self%unflushed = self%unflushed + 8_i8*m*sum([(size(self%pending(k)%v), &
                                                       k = 1, N_SERIES + 2)])/self%capacity
    end procedure write_pending

    module procedure flush_file
        call self%file%flush(err)
        if (.not. allocated(err)) self%unflushed = 0
    end procedure flush_file

    module procedure keep_room
        integer :: errnum
        if (self%file%in_memory()) return
        errnum = reserve_space(self%file%file_name(), self%file%size(), &
                               self%unflushed + RESERVE_BYTES)
        if (errnum == ERRNO_ENOSPC .or. errnum == ERRNO_EDQUOT .or. errnum == ERRNO_EFBIG) &
            call make_error(err, ERR_IO, &
            self%file%file_name()//': '//errno_text(errnum)//' (no room for the records '// &
            'not flushed and a reserve of '//int_text(int(RESERVE_BYTES/2**20))//' MiB: '// &
            'the run stops while the file can still be closed)')
    end procedure keep_room

    module procedure set_force_series
        self%force_on = self%force_data
        if (present(anchored)) self%force_on(N_FORCE_SERIES - 1:) = self%force_data .and. anchored
    end procedure set_force_series

    module procedure force_record_size
        values = merge(n + 1, 2, k <= N_JOINT_SERIES)
    end procedure force_record_size
end submodule ropedyn_output_pending
