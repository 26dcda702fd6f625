!> One record of a run file as a starting point: the time, the model's ODE state y and its
!! quadratures yq of record k (the restart data /state/y, /state/yq that `ropedyn_output`
!! writes with every record; docs/output.md, "Restart data"), and the energies of a record.
!! `ropedyn run --resume` continues a run from its last record; the same reader serves any
!! record of any run file written with restart data.
module ropedyn_run_record
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use hdf5, only: hsize_t
    use ropedyn_kinds, only: wp
    use ropedyn_text, only: int_text
    use ropedyn_error, only: error_t, make_error, ERR_INPUT
    use ropedyn_h5, only: h5_file_t
    use ropedyn_rope_model, only: energy_t
    implicit none
    private
    public :: run_record_t, read_run_record

    !> A record of a run file.
    type :: run_record_t
        integer :: record = -1                 !< its index, 0-based as h5py counts
        integer :: records = 0                 !< complete records in the file
        real(wp) :: t = 0.0_wp                 !< its time, s
        real(wp), allocatable :: y(:)          !< the model's ODE state
        real(wp), allocatable :: yq(:)         !< its quadratures, J
        type(energy_t) :: energy               !< the energies written with it, J
    end type run_record_t

    !> The energy datasets, in the order of energy_t's components.
    character(len=*), parameter :: ENERGY_NAMES(5) = [character(len=12) :: 'kinetic', &
        'elastic', 'gravity', 'dissipated', 'support_work']

contains

    !> Record `record` (0-based; -1: the last complete one) of the run file `path`. Errors
    !! (ERR_INPUT: the file is not a starting point; ERR_IO: it cannot be read) name the file
    !! and what is wrong: no such file, no restart data (written by an older version), no
    !! complete record, no such record, a state that is not finite.
    subroutine read_run_record(path, record, rec, err)
        character(len=*), intent(in) :: path
        integer, intent(in) :: record
        type(run_record_t), intent(out) :: rec
        type(error_t), allocatable, intent(out) :: err
        type(h5_file_t) :: h5
        type(error_t), allocatable :: close_err
        real(wp), allocatable :: time(:), values(:)
        integer(hsize_t) :: dims1(1), k
        logical :: exists
        real(wp) :: e(size(ENERGY_NAMES))
        integer :: j

        inquire (file=path, exist=exists)
        if (.not. exists) then
            call make_error(err, ERR_INPUT, path//': no such file')
            return
        end if
        call h5%open(path, err)
        if (allocated(err)) return
        steps: block
            if (.not. (h5%exists('/state/y') .and. h5%exists('/state/yq'))) then
                call make_error(err, ERR_INPUT, path//': no restart data (/state/y, /state/yq'// &
                    ' missing: written by an older version of ropedyn, or not a run file)')
                exit steps
            end if
            call h5%read_reals('/time', time, dims1, err)
            if (allocated(err)) exit steps
            rec%records = size(time)
            if (rec%records == 0) then
                call make_error(err, ERR_INPUT, path//': no complete record')
                exit steps
            end if
            rec%record = record
            if (record < 0) rec%record = rec%records - 1
            if (rec%record >= rec%records) then
                call make_error(err, ERR_INPUT, path//': no record '//int_text(rec%record)// &
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
            if (.not. (all(ieee_is_finite(rec%y)) .and. all(ieee_is_finite(rec%yq)) .and. &
                       ieee_is_finite(rec%t))) then
                call make_error(err, ERR_INPUT, path//': record '//int_text(rec%record)// &
                    ': the state is not finite')
                exit steps
            end if
        end block steps
        call h5%close(close_err)
        if (allocated(close_err) .and. .not. allocated(err)) call move_alloc(close_err, err)
        if (allocated(err)) return
        if (.not. allocated(rec%y)) allocate (rec%y(0))
        if (.not. allocated(rec%yq)) allocate (rec%yq(0))
    end subroutine read_run_record
end module ropedyn_run_record
