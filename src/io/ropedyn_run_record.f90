!> One record of a run file as a starting point: the time, the model's native ODE state y
!! and its quadratures yq of a record (the restart data /state/y and /state/yq that
!! `ropedyn_output` writes with every record; docs/reference/file-format.md), with what is
!! needed to check that a model can start from it.
!!
!! API (io layer; no model is built here):
!!   call read_run_record(path, record, rec, err)   record k (0-based, as h5py counts), or
!!                                                  LAST_RECORD (-1): the last complete one
!!   call check_record_fits(rec, model, state_size, quad_size, err)
!!                                                  the record suits a model of that kind and
!!                                                  size (ERR_INPUT naming the file if not)
!!   rec%t, rec%y(1:state_size), rec%yq(1:quad_size)    the starting point
!!
!! Users: `ropedyn run --resume FILE` (ropedyn_simulation continues a run from its last
!! record) and the sweep runner resuming interrupted cases; meant for `&initial shape =
!! 'state'` (start from a record of another run's file) as well.
module ropedyn_run_record
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use hdf5, only: hsize_t
    use ropedyn_kinds, only: wp
    use ropedyn_text, only: int_text, real_text, clip, printable
    use ropedyn_error, only: error_t, make_error, ERR_INPUT
    use ropedyn_h5, only: h5_file_t
    use ropedyn_rope_model, only: energy_t
    use ropedyn_scene_limits, only: MAGNITUDE_LIMIT, MAX_TIME
    implicit none
    private
    public :: run_record_t, read_run_record, check_record_fits, read_record_times, LAST_RECORD
    public :: check_record_values, speed_bound, RUN_STATUSES

    !> The values of a run file's `status` attribute.
    character(len=*), parameter :: RUN_STATUSES(4) = [character(len=11) :: 'running', &
        'complete', 'failed', 'interrupted']
    public :: read_peak_tension

    !> `record` argument of read_run_record: the last complete record.
    integer, parameter :: LAST_RECORD = -1

    !> A record of a run file.
    type :: run_record_t
        character(len=:), allocatable :: path  !< the file
        character(len=:), allocatable :: model !< the file's model kind (root attribute)
        character(len=:), allocatable :: status !< the file's status (root attribute)
        integer :: n_elements = 0              !< elements of the file's rope
        integer :: record = -1                 !< its index, 0-based as h5py counts
        integer :: records = 0                 !< complete records in the file
        real(wp) :: t = 0.0_wp                 !< its time, s
        real(wp), allocatable :: y(:)          !< the model's ODE state
        !> its quadratures, J (at least one value: a model without quadratures has a 0 here)
        real(wp), allocatable :: yq(:)
        type(energy_t) :: energy               !< the energies written with it, J
    end type run_record_t

    !> The energy datasets, in the order of energy_t's components.
    character(len=*), parameter :: ENERGY_NAMES(5) = [character(len=12) :: 'kinetic', &
        'elastic', 'gravity', 'dissipated', 'support_work']

contains

    !> Record `record` (0-based; LAST_RECORD: the last complete one) of the run file `path`.
    !! Errors (ERR_INPUT: the file is not a starting point; ERR_IO: it cannot be read) name
    !! the file and what is wrong: no such file, a status that is not one of RUN_STATUSES,
    !! no restart data (written by an older version), no complete record, no such record,
    !! times that do not increase or lie beyond MAX_TIME, a value of the state, its
    !! quadratures or energies that is not finite or beyond the limits of a scene
    !! (check_record_values), naming the dataset and the record.
    subroutine read_run_record(path, record, rec, err)
        character(len=*), intent(in) :: path
        integer, intent(in) :: record
        type(run_record_t), intent(out) :: rec
        type(error_t), allocatable, intent(out) :: err
        type(h5_file_t) :: h5
        type(error_t), allocatable :: close_err
        real(wp), allocatable :: time(:), values(:)
        integer(hsize_t) :: dims1(1), k
        real(wp) :: e(size(ENERGY_NAMES)), bound
        integer :: j

        rec%path = path
        rec%model = ''
        rec%status = ''
        call h5%open(path, err)
        if (allocated(err)) return
        steps: block
            call h5%read_attribute('model', rec%model, err)
            if (allocated(err)) exit steps
            call h5%read_attribute('status', rec%status, err)
            if (allocated(err)) exit steps
            if (.not. any(RUN_STATUSES == rec%status)) then
                call make_error(err, ERR_INPUT, path//': status "'//clip(printable( &
                    rec%status))//'": not a status of a ropedyn run file (running, '// &
                    'complete, failed, interrupted)')
                exit steps
            end if
            if (.not. (h5%exists('/state/y') .and. h5%exists('/state/yq'))) then
                call make_error(err, ERR_INPUT, path//': no restart data (/state/y, /state/yq'// &
                    ' missing: written by an older version of ropedyn, or not a run file)')
                exit steps
            end if
            call h5%read_reals('/rope/element_length', values, dims1, err)
            if (allocated(err)) exit steps
            rec%n_elements = size(values)
            call h5%read_reals('/rope/element_mass', values, dims1, err)
            if (allocated(err)) exit steps
            bound = speed_bound(values)
            call read_record_times(h5, path, time, err)
            if (allocated(err)) exit steps
            rec%records = size(time)
            rec%record = record
            if (record == LAST_RECORD) rec%record = rec%records - 1
            if (rec%record < 0 .or. rec%record >= rec%records) then
                call make_error(err, ERR_INPUT, path//': no record '//int_text(record)// &
                    ' (the file has records 0 .. '//int_text(rec%records - 1)//')')
                exit steps
            end if
            k = int(rec%record + 1, hsize_t)
            rec%t = time(k)
            call h5%read_record('/state/y', k, rec%y, err)
            if (allocated(err)) exit steps
            call h5%read_record('/state/yq', k, rec%yq, err)
            if (allocated(err)) exit steps
            do j = 1, size(ENERGY_NAMES)
                call h5%read_record('/energy/'//trim(ENERGY_NAMES(j)), k, values, err)
                if (allocated(err)) exit steps
                e(j) = values(1)
            end do
            rec%energy = energy_t(kinetic=e(1), elastic=e(2), gravity=e(3), dissipated=e(4), &
                                  support_work=e(5))
            call check_record_values(path, '/state/y', rec%record, rec%t, rec%y, bound, err)
            if (.not. allocated(err)) call check_record_values(path, '/state/yq', rec%record, &
                rec%t, rec%yq, MAGNITUDE_LIMIT, err)
            do j = 1, size(ENERGY_NAMES)
                if (.not. allocated(err)) call check_record_values(path, '/energy/'// &
                    trim(ENERGY_NAMES(j)), rec%record, rec%t, e(j:j), MAGNITUDE_LIMIT, err)
            end do
        end block steps
        call h5%close(close_err)
        if (allocated(close_err) .and. .not. allocated(err)) call move_alloc(close_err, err)
        if (.not. allocated(rec%y)) allocate (rec%y(0))
        if (.not. allocated(rec%yq)) allocate (rec%yq(0))
    end subroutine read_run_record

    !> The peak tension of the first `records` records of the run file `path`: the largest
    !! value of /forces/axial (N), its joint (0 the top end) and its record's time (s);
    !! joint = -1 when the file has no internal forces (or no such records). One record
    !! read at a time: the memory of a long run stays small.
    subroutine read_peak_tension(path, records, peak, joint, t, err)
        character(len=*), intent(in) :: path
        integer, intent(in) :: records
        real(wp), intent(out) :: peak, t
        integer, intent(out) :: joint
        type(error_t), allocatable, intent(out) :: err
        type(h5_file_t) :: h5
        type(error_t), allocatable :: close_err
        real(wp), allocatable :: time(:), axial(:)
        integer :: k, j
        peak = 0.0_wp
        t = 0.0_wp
        joint = -1
        call h5%open(path, err)
        if (allocated(err)) return
        steps: block
            if (.not. h5%exists('/forces/axial')) exit steps
            call read_record_times(h5, path, time, err)
            if (allocated(err)) exit steps
            do k = 1, min(records, size(time))
                call h5%read_record('/forces/axial', int(k, hsize_t), axial, err)
                if (allocated(err)) exit steps
                if (size(axial) == 0) exit steps
                j = maxloc(axial, 1)
                if (joint >= 0 .and. .not. axial(j) > peak) cycle
                peak = axial(j)
                joint = j - 1
                t = time(k)
            end do
        end block steps
        call h5%close(close_err)
        if (allocated(close_err) .and. .not. allocated(err)) call move_alloc(close_err, err)
    end subroutine read_peak_tension

    !> The times of the complete records of the run file `path`, open as h5: /time, which
    !! the writer extends last in a record, so that its length counts the complete records.
    !! ERR_INPUT when there is none, or when they are not finite, >= 0 and at most MAX_TIME,
    !! each after the one before (naming the first record that is not).
    subroutine read_record_times(h5, path, time, err)
        type(h5_file_t), intent(inout) :: h5
        character(len=*), intent(in) :: path
        real(wp), allocatable, intent(out) :: time(:)
        type(error_t), allocatable, intent(out) :: err
        integer(hsize_t) :: dims1(1)
        integer :: k
        call h5%read_reals('/time', time, dims1, err)
        if (allocated(err)) return
        if (size(time) == 0) call make_error(err, ERR_INPUT, path//': no complete record')
        do k = 1, size(time)
            if (.not. (time(k) >= 0.0_wp .and. time(k) <= MAX_TIME)) then
                call make_error(err, ERR_INPUT, path//': /time: record '//int_text(k - 1)// &
                    ': t = '//real_text(time(k))//' s: not a time of a run (0 .. '// &
                    real_text(MAX_TIME)//' s; docs/reference/scene-file.md, Limits)')
                return
            end if
            if (k == 1) cycle
            if (.not. time(k) > time(k - 1)) then
                call make_error(err, ERR_INPUT, path//': /time: record '//int_text(k - 1)// &
                    ' (t = '//real_text(time(k))//' s) is not after record '// &
                    int_text(k - 2)//' (t = '//real_text(time(k - 1))//' s): the times '// &
                    'of a run file increase')
                return
            end if
        end do
    end subroutine read_record_times

    !> A run may start from the values of `dataset` at record `record` (0-based; time t)
    !! of the file `path` only when each is finite and at most `bound` in size; else an
    !! ERR_INPUT error naming the file, the dataset, the record and the first bad value.
    subroutine check_record_values(path, dataset, record, t, values, bound, err)
        character(len=*), intent(in) :: path, dataset
        integer, intent(in) :: record
        real(wp), intent(in) :: t, values(:), bound
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: where
        integer :: k
        do k = 1, size(values)
            if (ieee_is_finite(values(k)) .and. abs(values(k)) <= bound) cycle
            where = path//': '//dataset//': record '//int_text(record)//' (t = '// &
                real_text(t)//' s): value '//int_text(k)//' = '//real_text(values(k))
            if (.not. ieee_is_finite(values(k))) then
                call make_error(err, ERR_INPUT, where//': not finite')
            else
                call make_error(err, ERR_INPUT, where//': beyond the limits of a scene '// &
                    '(at most '//real_text(bound)//' here; docs/reference/scene-file.md, Limits)')
            end if
            return
        end do
    end subroutine check_record_values

    !> The largest value of a state a run may start from, for a rope whose elements have
    !! the masses `masses` (kg): a speed at which it would carry MAGNITUDE_LIMIT J of
    !! kinetic energy, the scene's own limit (ropedyn_scene_limits). Every value of the
    !! state (m, rad, m/s, rad/s) is held to it; positions of a real rope lie far below.
    pure real(wp) function speed_bound(masses) result(bound)
        real(wp), intent(in) :: masses(:)
        bound = sqrt(MAGNITUDE_LIMIT/max(sum(abs(masses)), 1.0_wp/MAGNITUDE_LIMIT))
        bound = min(bound, MAGNITUDE_LIMIT)
    end function speed_bound

    !> Whether a model of kind `model` ('rfem', 'mpp') with `state_size` unknowns and
    !! `quad_size` quadratures can start from `rec`; if not, an ERR_INPUT error naming the
    !! file, the record and the difference.
    subroutine check_record_fits(rec, model, state_size, quad_size, err)
        type(run_record_t), intent(in) :: rec
        character(len=*), intent(in) :: model
        integer, intent(in) :: state_size, quad_size
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: where
        where = rec%path//': record '//int_text(rec%record)//' (t = '//real_text(rec%t)//' s)'
        if (rec%model /= model) then
            call make_error(err, ERR_INPUT, where//': written by the '//rec%model// &
                ' model, the scene uses '//model)
        else if (size(rec%y) /= state_size) then
            call make_error(err, ERR_INPUT, where//': a state of '//int_text(size(rec%y))// &
                ' values ('//int_text(rec%n_elements)//' elements), the scene''s model has '// &
                int_text(state_size))
        else if (size(rec%yq) < quad_size .or. (size(rec%yq) > max(1, quad_size))) then
            call make_error(err, ERR_INPUT, where//': '//int_text(size(rec%yq))// &
                ' quadrature values, the scene''s model has '//int_text(quad_size)// &
                ' (its effects or supports differ)')
        end if
    end subroutine check_record_fits
end module ropedyn_run_record
