!> One record of a run file as a starting point (`&initial shape = 'state'`): the record
!! nearest a requested time, its element fields (/state/q, /state/qdot), the energy
!! quadratures written with it (/energy/dissipated, /energy/support_work), and, when the file
!! holds the model's native ODE state (/state/y, /state/yq: restart data), that state too.
!! The model turns the fields back into its ODE state (`state_from_fields`) when there is no
!! native state. docs/guide/output.md, "Starting from a record".
module ropedyn_state_record
    use hdf5, only: hsize_t
    use ropedyn_kinds, only: wp
    use ropedyn_text, only: int_text, real_text
    use ropedyn_error, only: error_t, make_error, ERR_INPUT
    use ropedyn_h5, only: h5_file_t
    use ropedyn_run_record, only: read_record_times, check_record_values, speed_bound
    use ropedyn_scene_limits, only: MAGNITUDE_LIMIT
    implicit none
    private
    public :: state_record_t, read_state_record

    !> A record of a run file.
    type, public :: state_record_t
        integer :: record = -1                  !< its index, 0-based as h5py counts
        integer :: records = 0                  !< complete records in the file
        real(wp) :: t = 0.0_wp                  !< its time, s
        character(len=:), allocatable :: model  !< root attribute `model` (rfem, mpp)
        integer :: n = 0                        !< elements
        real(wp), allocatable :: q(:, :)        !< (3, n): x, y (m), phi (rad) per element
        real(wp), allocatable :: qdot(:, :)     !< (3, n): their rates
        real(wp) :: dissipated = 0.0_wp         !< J
        real(wp) :: support_work = 0.0_wp       !< J
        real(wp), allocatable :: y(:)           !< native ODE state (restart data), if stored
        real(wp), allocatable :: yq(:)          !< its quadratures, if stored
    end type state_record_t

contains

    !> The record of the run file `path` whose time is nearest `state_time` (s; < 0: the
    !! last complete record). ERR_INPUT names the file and what is wrong: no such file, not a
    !! run file (no /time, /state/q, model attribute), no complete record, `state_time`
    !! outside the file's times (by more than half the largest record spacing), times that
    !! do not increase, a value of the state that is not finite or beyond the limits of a
    !! scene (naming the dataset and the record). ERR_IO: the file cannot be read.
    subroutine read_state_record(path, state_time, rec, err)
        character(len=*), intent(in) :: path
        real(wp), intent(in) :: state_time
        type(state_record_t), intent(out) :: rec
        type(error_t), allocatable, intent(out) :: err
        type(h5_file_t) :: h5
        type(error_t), allocatable :: close_err
        real(wp), allocatable :: time(:)
        logical :: found
        integer :: k

        call h5%open(path, err)
        if (allocated(err)) then
            err%code = ERR_INPUT  ! missing or not an HDF5 file: bad input
            return
        end if
        steps: block
            call h5%read_attribute('model', rec%model, err, found)
            if (allocated(err)) exit steps
            if (.not. (found .and. h5%exists('/time') .and. h5%exists('/state/q') .and. &
                       h5%exists('/state/qdot'))) then
                call make_error(err, ERR_INPUT, path//': not a run file of ropedyn (it needs '// &
                                'the root attribute model, /time, /state/q and /state/qdot)')
                exit steps
            end if
            call read_record_times(h5, path, time, err)
            if (allocated(err)) exit steps
            rec%records = size(time)
            call pick_record(path, time, state_time, k, err)
            if (allocated(err)) exit steps
            rec%record = k - 1
            rec%t = time(k)
            call read_positions(h5, path, k, rec, err)
            if (allocated(err)) exit steps
            call read_scalar_record(h5, '/energy/dissipated', k, rec%dissipated, err)
            if (allocated(err)) exit steps
            call read_scalar_record(h5, '/energy/support_work', k, rec%support_work, err)
            if (allocated(err)) exit steps
            call read_native_state(h5, k, rec, err)
            if (allocated(err)) exit steps
            call check_record(h5, path, rec, err)
        end block steps
        call h5%close(close_err)
        if (allocated(close_err) .and. .not. allocated(err)) call move_alloc(close_err, err)
    end subroutine read_state_record

    !> The index k of the record at state_time (< 0: the last) among the records' times,
    !! within half the largest spacing of the records.
    subroutine pick_record(path, time, state_time, k, err)
        character(len=*), intent(in) :: path
        real(wp), intent(in) :: time(:), state_time
        integer, intent(out) :: k
        type(error_t), allocatable, intent(out) :: err
        real(wp) :: slack
        integer :: nt
        nt = size(time)
        if (state_time < 0.0_wp) then
            k = nt
            return
        end if
        k = minloc(abs(time - state_time), dim=1)
        slack = 1.0e-9_wp*max(1.0_wp, abs(state_time))
        if (nt > 1) slack = slack + 0.5_wp*maxval(time(2:) - time(:nt - 1))
        if (abs(time(k) - state_time) > slack) then
            call make_error(err, ERR_INPUT, path//': no record at t = '// &
                real_text(state_time)//' s (the records span '//real_text(time(1))// &
                ' .. '//real_text(time(nt))//' s)')
        end if
    end subroutine pick_record

    !> Record k of /state/q and /state/qdot, checked to be (times, n, 3) series: only that
    !! record is read (one hyperslab), not the series, so that a long run's file is not
    !! read whole to start from one of its records.
    subroutine read_positions(h5, path, k, rec, err)
        type(h5_file_t), intent(inout) :: h5
        character(len=*), intent(in) :: path
        integer, intent(in) :: k
        type(state_record_t), intent(inout) :: rec
        type(error_t), allocatable, intent(out) :: err
        real(wp), allocatable :: values(:)
        integer(hsize_t) :: dims3(3)
        integer :: nt
        nt = rec%records
        call h5%extents('/state/q', dims3, err)
        if (allocated(err)) return
        rec%n = int(dims3(2))
        if (dims3(1) /= 3 .or. dims3(3) < nt) then
            call make_error(err, ERR_INPUT, path//': /state/q: not (times, n, 3) with '// &
                            int_text(nt)//' records')
            return
        end if
        call h5%read_record('/state/q', int(k, hsize_t), values, err)
        if (allocated(err)) return
        rec%q = reshape(values, [3, rec%n])
        call h5%extents('/state/qdot', dims3, err)
        if (allocated(err)) return
        if (dims3(1) /= 3 .or. dims3(2) /= rec%n .or. dims3(3) < nt) then
            call make_error(err, ERR_INPUT, path//': /state/qdot: not (times, '// &
                            int_text(rec%n)//', 3) with '//int_text(nt)//' records')
            return
        end if
        call h5%read_record('/state/qdot', int(k, hsize_t), values, err)
        if (allocated(err)) return
        rec%qdot = reshape(values, [3, rec%n])
    end subroutine read_positions

    !> The native state of record k, where the writer stores it (restart data): y and yq
    !! both, or neither; record k only.
    subroutine read_native_state(h5, k, rec, err)
        type(h5_file_t), intent(inout) :: h5
        integer, intent(in) :: k
        type(state_record_t), intent(inout) :: rec
        type(error_t), allocatable, intent(out) :: err
        real(wp), allocatable :: values(:)
        integer(hsize_t) :: dims2(2)
        if (.not. (h5%exists('/state/y') .and. h5%exists('/state/yq'))) return
        call h5%extents('/state/y', dims2, err)
        if (allocated(err)) return
        if (dims2(2) >= rec%records) then
            call h5%read_record('/state/y', int(k, hsize_t), values, err)
            if (allocated(err)) return
            rec%y = values
        end if
        call h5%extents('/state/yq', dims2, err)
        if (allocated(err)) return
        if (dims2(2) >= rec%records) then
            call h5%read_record('/state/yq', int(k, hsize_t), values, err)
            if (allocated(err)) return
            rec%yq = values
        end if
        if (.not. (allocated(rec%y) .and. allocated(rec%yq))) then
            if (allocated(rec%y)) deallocate (rec%y)
            if (allocated(rec%yq)) deallocate (rec%yq)
        end if
    end subroutine read_native_state

    !> The record's values finite, and within the limits of a scene (ropedyn_run_record):
    !! speeds by the rope's element masses where the file has them.
    subroutine check_record(h5, path, rec, err)
        type(h5_file_t), intent(inout) :: h5
        character(len=*), intent(in) :: path
        type(state_record_t), intent(in) :: rec
        type(error_t), allocatable, intent(out) :: err
        real(wp), allocatable :: values(:)
        integer(hsize_t) :: dims1(1)
        real(wp) :: bound
        bound = MAGNITUDE_LIMIT
        if (h5%exists('/rope/element_mass')) then
            call h5%read_reals('/rope/element_mass', values, dims1, err)
            if (allocated(err)) return
            bound = speed_bound(values)
        end if
        call check_record_values(path, '/state/q', rec%record, rec%t, &
                                 reshape(rec%q, [size(rec%q)]), bound, err)
        if (allocated(err)) return
        call check_record_values(path, '/state/qdot', rec%record, rec%t, &
                                 reshape(rec%qdot, [size(rec%qdot)]), bound, err)
        if (allocated(err)) return
        if (allocated(rec%y)) then
            call check_record_values(path, '/state/y', rec%record, rec%t, rec%y, bound, err)
            if (allocated(err)) return
            call check_record_values(path, '/state/yq', rec%record, rec%t, rec%yq, &
                                     MAGNITUDE_LIMIT, err)
            if (allocated(err)) return
        end if
        call check_record_values(path, '/energy/dissipated', rec%record, rec%t, &
                                 [rec%dissipated], MAGNITUDE_LIMIT, err)
        if (allocated(err)) return
        call check_record_values(path, '/energy/support_work', rec%record, rec%t, &
                                 [rec%support_work], MAGNITUDE_LIMIT, err)
    end subroutine check_record

    !> Record k of a (times,) series (that value only); 0 when the file has no such
    !! dataset or the series is shorter.
    subroutine read_scalar_record(h5, name, k, value, err)
        type(h5_file_t), intent(inout) :: h5
        character(len=*), intent(in) :: name
        integer, intent(in) :: k
        real(wp), intent(out) :: value
        type(error_t), allocatable, intent(out) :: err
        real(wp), allocatable :: values(:)
        integer(hsize_t) :: d(1)
        value = 0.0_wp
        if (.not. h5%exists(name)) return
        call h5%extents(name, d, err)
        if (allocated(err)) return
        if (d(1) < k) return
        call h5%read_record(name, int(k, hsize_t), values, err)
        if (allocated(err)) return
        value = values(1)
    end subroutine read_scalar_record
end module ropedyn_state_record
