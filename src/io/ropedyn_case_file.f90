!> Reading back a run file written by `ropedyn_output` (the case files of a sweep): the
!! root attributes, the solver counters, the run's warnings and, on request, the time
!! series needed for error measures. Also finishes a sweep case's file before it is
!! renamed into place: its wall-clock time (`/solver/wall_time`) and the case's scene
!! (`finish_case_file`).
!!
!! The HDF5 calls are those of `ropedyn_h5`; failures are `ERR_IO` errors naming the file
!! and the object.
module ropedyn_case_file
    use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, ieee_is_nan
    use hdf5, only: hsize_t
    use ropedyn_kinds, only: wp, i8
    use ropedyn_error, only: error_t, make_error, ERR_IO
    use ropedyn_text, only: text_t
    use ropedyn_h5, only: h5_file_t, h5_series_t
    use ropedyn_output, only: COUNTER_NAMES
    implicit none
    private
    public :: case_data_t, read_case_file, finish_case_file

    !> What a run file holds (the counters are -1 and the times NaN when absent).
    type :: case_data_t
        logical :: exists = .false.
        character(len=:), allocatable :: status   !< complete | failed | running
        character(len=:), allocatable :: reason   !< failed runs: the error message
        character(len=:), allocatable :: scene    !< the effective namelist text
        character(len=:), allocatable :: model, method
        real(wp) :: cpu_time = 0.0_wp, wall_time = 0.0_wp  !< s (NaN when absent)
        !> the solver counters named in ropedyn_output's COUNTER_NAMES
        integer(i8) :: counters(size(COUNTER_NAMES)) = -1
        integer :: records = 0                      !< complete output records
        real(wp), allocatable :: time(:)            !< (records) s
        real(wp), allocatable :: points(:, :, :)    !< (2, 2n, records) m
        !> (records) J: kinetic + elastic + gravity + dissipated - support_work
        real(wp), allocatable :: balance(:)
        !> what the run warned of (/solver/warnings), one line each; none when absent
        type(text_t), allocatable :: warnings(:)
        !> where a part of the run was killed, s: the times of the restarts that continued
        !! a file with status running (/solver/restarts); that part wrote no wall time
        real(wp), allocatable :: killed_at(:)
        !> for each of killed_at: the part's counters were in the file (written at each
        !! flush, as of its last: the restart's steps > 0); else they were lost
        logical, allocatable :: killed_counted(:)
    end type case_data_t

contains

    !> Read a run file. A missing file is not an error (`data%exists` is false); an
    !! unreadable one is. With `series`, also read time, points and the energy balance.
    subroutine read_case_file(path, data, err, series)
        character(len=*), intent(in) :: path
        type(case_data_t), intent(out) :: data
        type(error_t), allocatable, intent(out) :: err
        logical, intent(in), optional :: series
        type(h5_file_t) :: h5
        type(error_t), allocatable :: close_err
        real(wp), allocatable :: e(:), values(:)
        integer(hsize_t) :: dims1(1), dims3(3)
        character(len=*), parameter :: ENERGIES(5) = [character(len=12) :: 'kinetic', &
            'elastic', 'gravity', 'dissipated', 'support_work']
        real(wp), parameter :: SIGNS(5) = [1.0_wp, 1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp]
        logical :: found
        integer :: k

        data%cpu_time = ieee_value(1.0_wp, ieee_quiet_nan)
        data%wall_time = data%cpu_time
        inquire (file=path, exist=data%exists)
        if (.not. data%exists) return
        call h5%open(path, err)
        if (allocated(err)) return
        steps: block
            call required_attribute('status', data%status)
            if (allocated(err)) exit steps
            call required_attribute('scene', data%scene)
            if (allocated(err)) exit steps
            call required_attribute('model', data%model)
            if (allocated(err)) exit steps
            call required_attribute('method', data%method)
            if (allocated(err)) exit steps
            call h5%read_attribute('reason', data%reason, err, found)
            if (allocated(err)) exit steps
            call read_counters()
            if (allocated(err)) exit steps
            call h5%read_scalar('/solver/cpu_time', data%cpu_time, err)
            if (allocated(err)) exit steps
            call h5%read_scalar('/solver/wall_time', data%wall_time, err)
            if (allocated(err)) exit steps
            call h5%read_texts('/solver/warnings', data%warnings, err)
            if (allocated(err)) exit steps
            call read_killed_parts()
            if (allocated(err)) exit steps
            call h5%read_reals('/time', data%time, dims1, err)
            if (allocated(err)) exit steps
            data%records = size(data%time)
            if (.not. present(series)) exit steps
            if (.not. series) exit steps
            call h5%read_reals('/rope/points', values, dims3, err)
            if (allocated(err)) exit steps
            data%points = reshape(values, dims3)
            if (size(data%points, 3) < data%records) then
                call make_error(err, ERR_IO, path//': /rope/points: fewer records than /time')
                exit steps
            end if
            data%points = data%points(:, :, :data%records)
            allocate (data%balance(data%records), source=0.0_wp)
            do k = 1, size(ENERGIES)
                call h5%read_reals('/energy/'//trim(ENERGIES(k)), e, dims1, err)
                if (allocated(err)) exit steps
                if (size(e) < data%records) then
                    call make_error(err, ERR_IO, path//': /energy/'//trim(ENERGIES(k))// &
                        ': fewer records than /time')
                    exit steps
                end if
                data%balance = data%balance + SIGNS(k)*e(:data%records)
            end do
        end block steps
        call h5%close(close_err)
        if (allocated(close_err) .and. .not. allocated(err)) call move_alloc(close_err, err)
    contains
        !> A root attribute every run file has.
        subroutine required_attribute(name, value)
            character(len=*), intent(in) :: name
            character(len=:), allocatable, intent(out) :: value
            logical :: found
            call h5%read_attribute(name, value, err, found)
            if (.not. allocated(err) .and. .not. found) &
                call make_error(err, ERR_IO, path//': attribute '//name//' is missing (not a ' &
                                //'ropedyn run file?)')
        end subroutine required_attribute

        !> data%killed_at from /solver/restarts (none when there are no restarts).
        subroutine read_killed_parts()
            type(text_t), allocatable :: previous(:)
            real(wp), allocatable :: times(:), steps(:)
            integer(hsize_t) :: dims(1)
            integer :: j
            allocate (data%killed_at(0), data%killed_counted(0))
            call h5%read_texts('/solver/restarts/previous_status', previous, err)
            if (allocated(err) .or. size(previous) == 0) return
            call h5%read_reals('/solver/restarts/time', times, dims, err)
            if (allocated(err)) return
            call h5%read_reals('/solver/restarts/steps', steps, dims, err)
            if (allocated(err)) return
            do j = 1, min(size(previous), size(times), size(steps))
                if (previous(j)%s /= 'running') cycle
                data%killed_at = [data%killed_at, times(j)]
                data%killed_counted = [data%killed_counted, steps(j) > 0.0_wp]
            end do
        end subroutine read_killed_parts

        !> The solver counters (-1 when absent).
        subroutine read_counters()
            integer :: j
            do j = 1, size(COUNTER_NAMES)
                call h5%read_scalar('/solver/'//trim(COUNTER_NAMES(j)), data%counters(j), err)
                if (allocated(err)) return
            end do
        end subroutine read_counters
    end subroutine read_case_file

    !> Finish a case file written under a temporary name: write (or overwrite) the scalar
    !! `/solver/wall_time` (s; a NaN `seconds`, not known, leaves it as it is) and set the
    !! root attribute `scene` to `scene_text`, the case's scene (the run saw the temporary
    !! file name as its output file), and, when `reason` is not empty, the root attribute
    !! `reason` (the run's, naming the case file); with `warnings`, /solver/warnings line
    !! by line (as many lines as the file holds: the run's, naming the case file).
    subroutine finish_case_file(path, seconds, scene_text, err, reason, warnings)
        character(len=*), intent(in) :: path
        real(wp), intent(in) :: seconds
        character(len=*), intent(in) :: scene_text
        type(error_t), allocatable, intent(out) :: err
        character(len=*), intent(in), optional :: reason
        type(text_t), intent(in), optional :: warnings(:)
        type(h5_file_t) :: h5
        type(h5_series_t) :: series
        type(error_t), allocatable :: close_err
        integer :: k

        call h5%open(path, err, writable=.true.)
        if (allocated(err)) return
        if (.not. h5%exists('/solver')) then
            call make_error(err, ERR_IO, path//': /solver: missing')
        else if (.not. ieee_is_nan(seconds)) then
            call h5%write('/solver/wall_time', seconds, 's', err)
        end if
        if (.not. allocated(err)) call h5%attribute('/', 'scene', scene_text, err)
        if (present(reason) .and. .not. allocated(err)) then
            if (len(reason) > 0) call h5%attribute('/', 'reason', reason, err)
        end if
        if (present(warnings) .and. .not. allocated(err)) then
            if (size(warnings) > 0) then
                call h5%open_series(series, '/solver/warnings', err)
                do k = 1, size(warnings)
                    if (allocated(err)) exit
                    call series%append_text(int(k, hsize_t), warnings(k)%s, err)
                end do
                call series%close(close_err)
                if (allocated(close_err) .and. .not. allocated(err)) call move_alloc(close_err, err)
            end if
        end if
        call h5%close(close_err)
        if (allocated(close_err) .and. .not. allocated(err)) call move_alloc(close_err, err)
    end subroutine finish_case_file
end module ropedyn_case_file
