!> Resuming a run from its file (`ropedyn run --resume FILE.h5`): the last record is the
!! starting point, the file is reopened for appending, and the restart is recorded in
!! /solver/restarts; the solver counters and the CPU time of the earlier parts add up.
submodule (ropedyn_run) ropedyn_run_resume
    use, intrinsic :: iso_fortran_env, only: error_unit
    use ropedyn_text, only: int_text, significant_text
    use ropedyn_version, only: version_string
    use ropedyn_case_file, only: case_data_t, read_case_file
    use ropedyn_output, only: whole_records
    use ropedyn_run_record, only: run_record_t, read_run_record, check_record_fits, LAST_RECORD, &
                                  read_peak_tension
    implicit none

contains

    !> The last record of the file as the start (it must be before t_end and the file not
    !! 'running'); the output times that follow it on the scene's grid; an off-grid last
    !! record (where an interrupted or failed run stopped) is the start but is cut from
    !! the file, replaced by the grid records that follow, so that the file ends with the
    !! records of an uninterrupted run.
    module procedure resume_from_file
        type(run_record_t) :: rec, first
        type(case_data_t) :: before
        real(wp) :: tol, peak, t_peak
        integer :: keep, j, joint, whole
        character(len=:), allocatable :: overrides, last_whole
        logical :: salvaged
        associate (file => self%summary%file)
            call read_run_record(file, LAST_RECORD, rec, err)
            ! a killed run's file (status running) may end in records cut in a write: it is
            ! continued from its last whole record (whole_records)
            salvaged = .false.
            last_whole = 'its last record'
            if (rec%status == 'running') then
                call salvage_record(file, rec, err, whole)
                salvaged = whole > 0
                if (salvaged) last_whole = 'its last whole record (record '// &
                    int_text(whole - 1)//'; the '//int_text(rec%records - whole)// &
                    ' after it did not all read back: the run was killed while writing them)'
            end if
            if (allocated(err)) return
            call check_record_fits(rec, self%model%model_name(), self%model%size(), self%nq, &
                                   err)
            if (allocated(err)) return
            call read_case_file(file, before, err)
            if (allocated(err)) return
            if (before%status == 'running') then
                ! no live process holds a lock of it (guard_output): its run was killed
                ! or crashed, and its records up to the last are valid
                if (.not. allocated(self%writer_gone)) self%writer_gone = ''
                if (len(self%writer_gone) == 0) self%writer_gone = 'no process holds a '// &
                    'lock of it: its run was killed or crashed'
                call append_text(self%summary%warnings, file//': status running: '// &
                    self%writer_gone//'; continued from '//last_whole//', at t = '// &
                    significant_text(rec%t, 10)//' s')
            end if
            tol = 1.0e-12_wp*max(abs(rec%t), self%dt)
            if (rec%t >= self%t_end - tol) then
                call make_error(err, ERR_INPUT, file//': nothing to continue: its last '// &
                    'record is at t = '//significant_text(rec%t, 10)//' s, t_end is '// &
                    real_text(self%t_end)//' s (status '//before%status//'; a longer '// &
                    'run: --set solver.t_end=...)')
                return
            end if
            call read_run_record(file, 0, first, err)
            if (allocated(err)) return
            self%summary%initial_energy = first%energy
            ! the file does not keep the level part of the elastic energy: the model's, at
            ! that record's state (the energy monitor counts it with gravity)
            self%summary%initial_energy%level = level_energy(self%model, first%t, first%y, &
                                                             first%yq)
            self%t = rec%t
            self%y = rec%y
            self%yq = 0.0_wp
            self%yq(1:self%nq) = rec%yq(1:self%nq)
            ! the first output time after t; an off-grid last record is replaced
            self%k_next = self%n_out
            do j = 1, self%n_out
                if (self%output_time(j) > self%t + tol) then
                    self%k_next = j
                    exit
                end if
            end do
            keep = rec%record + 1
            if (rec%record > 0 .and. abs(self%output_time(self%k_next - 1) - self%t) > tol) &
                keep = keep - 1
            ! a counter the file lacks (-1: jac_rhs_evals in a file of an earlier version)
            ! counts 0 for the earlier parts
            do j = 1, size(self%counters_before)
                self%counters_before(j) = max(0_i8, before%counters(j))
            end do
            if (ieee_is_finite(before%cpu_time)) self%cpu_before = before%cpu_time
            ! the peak tension of the records kept (a file without forces is refused next)
            call read_peak_tension(file, keep, peak, joint, t_peak, err)
            if (allocated(err)) return
            if (joint >= 0) call self%note_peak(t_peak, peak, joint)
            call self%model%support_positions(self%t, self%anchors)
            call self%out%reopen(file, self%model%n_elements(), self%model%size(), self%nq, &
                                 err, keep=keep, internal_forces=.true., &
                                 anchored=ieee_is_finite(self%anchors(1, :)), salvage=salvaged)
            if (allocated(err)) return
            overrides = ''
            if (allocated(self%scene%overrides)) overrides = self%scene%overrides
            call self%out%add_restart(rec%record, self%t, before%status, before%reason, &
                                      self%counters_before(1), self%cpu_before, &
                                      version_string, overrides, err)
            if (allocated(err)) return
            self%summary%records = keep
            self%summary%t_reached = self%t
            self%summary%final_energy = rec%energy
            if (keep < rec%records) write (error_unit, '(a)') 'ropedyn: '//file// &
                ': continuing from t = '//real_text(self%t)//' s (record '// &
                int_text(rec%record)//', off the output grid: replaced by the records '// &
                'that follow)'
        end associate
    end procedure resume_from_file

    !> For the file of a killed run (status running): when its last record is not whole
    !! (rec and err as read_run_record left them: a series shorter than /time, a record that
    !! does not read back), rec becomes its last whole record and err is cleared. `whole`:
    !! that record's count (0 when the last record is whole or no record is: rec and err
    !! unchanged).
    subroutine salvage_record(file, rec, err, whole)
        character(len=*), intent(in) :: file
        type(run_record_t), intent(inout) :: rec
        type(error_t), allocatable, intent(inout) :: err
        integer, intent(out) :: whole
        type(run_record_t) :: earlier
        type(error_t), allocatable :: werr
        call whole_records(file, whole, werr)
        if (allocated(werr) .or. whole < 1 .or. whole >= rec%records) then
            whole = 0
            return
        end if
        call read_run_record(file, whole - 1, earlier, werr)
        if (allocated(werr)) then
            whole = 0
            return
        end if
        rec = earlier
        if (allocated(err)) deallocate (err)
    end subroutine salvage_record

    !> The level part of the model's elastic energy at a state (energy_t%level), J.
    real(wp) function level_energy(model, t, y, yq) result(level)
        class(rope_model_t), intent(inout) :: model
        real(wp), intent(in) :: t, y(:), yq(:)
        type(energy_t) :: e
        e = model%energy(t, y, yq)
        level = e%level
    end function level_energy
end submodule ropedyn_run_resume
