!> What the integrator did, for the run file: the order safety's actions, the changes of
!! method or order limit (ropedyn_switch_log) and the run's warnings, written when the run
!! (or a resumed part of it) ends.
submodule (ropedyn_output) ropedyn_output_solver
    implicit none

contains

    module procedure output_write_order_safety
        if (lowered_at < 0.0_wp .and. kept_at < 0.0_wp) return
        if (.not. self%is_open) then
            call not_open(self, 'write_order_safety', err)
            return
        end if
        call self%file%write('/solver/energy_gain', gain, 'J', err)
        if (lowered_at >= 0.0_wp) then
            if (.not. allocated(err)) &
                call self%file%write('/solver/order_lowered_at', lowered_at, 's', err)
            if (.not. allocated(err)) &
                call self%file%write('/solver/order_lowered_from', int(from, i8), '1', err)
            if (.not. allocated(err)) &
                call self%file%write('/solver/order_lowered_to', int(to, i8), '1', err)
        end if
        if (kept_at >= 0.0_wp) then
            if (.not. allocated(err)) &
                call self%file%write('/solver/order_kept_at', kept_at, 's', err)
            if (.not. allocated(err)) &
                call self%file%write('/solver/order_kept_count', int(kept_count, i8), '1', err)
        end if
        if (.not. allocated(err)) call flush_file(self, err)
        if (allocated(err)) call abandon(self, err)
    end procedure output_write_order_safety

    module procedure output_add_warnings
        type(h5_series_t) :: series
        type(error_t), allocatable :: close_err
        character(len=*), parameter :: NAME = '/solver/warnings'
        integer(hsize_t) :: n
        integer :: k
        if (size(lines) == 0) return
        if (.not. self%is_open) then
            call not_open(self, 'add_warnings', err)
            return
        end if
        if (self%file%exists(NAME)) then
            call self%file%open_series(series, NAME, err)
        else
            call self%file%create_text_series(series, NAME, WARNING_WIDTH, '', err)
        end if
        if (.not. allocated(err)) then
            n = series%length()
            do k = 1, size(lines)
                call series%append_text(n + k, lines(k)%s, err)
                if (allocated(err)) exit
            end do
        end if
        call series%close(close_err)
        if (allocated(close_err) .and. .not. allocated(err)) call move_alloc(close_err, err)
        if (.not. allocated(err)) call flush_file(self, err)
        if (allocated(err)) call abandon(self, err)
    end procedure output_add_warnings

    module procedure output_write_switches
        character(len=16), allocatable :: methods(:)
        character(len=:), allocatable :: reasons(:)
        real(wp), allocatable :: times(:)
        integer(i8), allocatable :: orders(:)
        integer :: k, width

        if (size(events) == 0) return
        if (.not. self%is_open) then
            call not_open(self, 'write_switches', err)
            return
        end if
        width = 1
        do k = 1, size(events)
            if (allocated(events(k)%reason)) width = max(width, len(events(k)%reason))
        end do
        allocate (methods(size(events)))
        allocate (character(len=width) :: reasons(size(events)))
        do k = 1, size(events)
            methods(k) = events(k)%method
            reasons(k) = ''
            if (allocated(events(k)%reason)) reasons(k) = events(k)%reason
        end do
        times = events%t
        orders = int(events%max_order, i8)
        call self%file%write('/solver/switch_time', times, 's', err)
        if (.not. allocated(err)) call self%file%write('/solver/switch_max_order', orders, &
                                                       '1', err)
        if (.not. allocated(err)) call self%file%write_text('/solver/switch_method', methods, &
                                                            '', err)
        if (.not. allocated(err)) call self%file%write_text('/solver/switch_reason', reasons, &
                                                            '', err)
        if (allocated(err)) call abandon(self, err)
    end procedure output_write_switches
end submodule ropedyn_output_solver
