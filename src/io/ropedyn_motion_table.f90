!> Motion tables of moving supports (`&supports top_table`, `bottom_table`): a text file of
!! rows t (s), dx, dy (m), dangle (deg), read into the rows a `support_motion_t` takes.
module ropedyn_motion_table
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use ropedyn_kinds, only: wp, i8, PI
    use ropedyn_namelist_file, only: MAX_FILE_BYTES
    use ropedyn_error, only: error_t, make_error, ERR_INPUT
    use ropedyn_text, only: int_text
    use ropedyn_os, only: special_file_reason
    implicit none
    private
    public :: read_motion_table


contains

    !> Read a motion table: rows of four numbers t (s), dx (m), dy (m), dangle (deg),
    !! separated by blanks or commas; blank lines and lines starting with '#' or '!' are
    !! skipped. At least two rows, t strictly increasing, every value finite. Returns
    !! rows (4, m) with the angle in rad. Errors (ERR_INPUT) name `where`, the file and the
    !! line.
    subroutine read_motion_table(path, where, rows, err)
        character(len=*), intent(in) :: path   !< the file
        !> prefix of messages, e.g. 'x.nml: &supports: top_table'
        character(len=*), intent(in) :: where
        real(wp), allocatable, intent(out) :: rows(:, :)
        type(error_t), allocatable, intent(out) :: err
        real(wp), allocatable :: grown(:, :)
        real(wp) :: r(4), extra
        character(len=:), allocatable :: line
        character(len=1024) :: msg
        integer :: unit, ios, m, lineno, lead, i, ios2
        integer(i8) :: bytes

        allocate (rows(4, 64))
        m = 0
        msg = ''
        line = ''
        lineno = 0
        ! a FIFO would block the open, a device such as /dev/zero never end
        if (len(special_file_reason(path)) > 0) then
            call make_error(err, ERR_INPUT, where//' = "'//path//'": cannot read: '// &
                special_file_reason(path))
            return
        end if
        open (newunit=unit, file=path, status='old', action='read', form='formatted', &
              iostat=ios, iomsg=msg)
        if (ios /= 0) then
            call make_error(err, ERR_INPUT, where//' = "'//path//'": cannot open: '//trim(msg))
            return
        end if
        inquire (unit=unit, size=bytes)
        if (bytes > MAX_FILE_BYTES) then
            call make_error(err, ERR_INPUT, where//' = "'//path//'": '//int_text(bytes)// &
                ' bytes: too large for an input file (at most '//int_text(MAX_FILE_BYTES)// &
                ' bytes)')
            close (unit)
            return
        end if
        do
            call read_line(unit, line, ios, msg)
            if (is_iostat_end(ios)) exit
            lineno = lineno + 1
            if (ios /= 0) then
                call fail('cannot read: '//trim(msg))
                return
            end if
            lead = verify(line, ' '//achar(9))
            if (lead == 0) cycle
            if (line(lead:lead) == '#' .or. line(lead:lead) == '!') cycle
            do i = 1, len(line)
                if (line(i:i) == ',' .or. line(i:i) == achar(9)) line(i:i) = ' '
            end do
            read (line, *, iostat=ios) r
            if (ios /= 0) then
                call fail('expected four numbers t, dx, dy, dangle_deg')
                return
            end if
            read (line, *, iostat=ios2) r, extra
            if (ios2 == 0) then
                call fail('more than four numbers (t, dx, dy, dangle_deg)')
                return
            end if
            if (.not. all(ieee_is_finite(r))) then
                call fail('every value must be finite')
                return
            end if
            if (m > 0) then
                if (.not. r(1) > rows(1, m)) then
                    call fail('times must increase strictly')
                    return
                end if
            end if
            if (m == size(rows, 2)) then
                allocate (grown(4, 2*m))
                grown(:, :m) = rows
                call move_alloc(grown, rows)
            end if
            m = m + 1
            rows(:, m) = [r(1:3), r(4)*pi/180.0_wp]
        end do
        close (unit)
        if (m < 2) then
            call make_error(err, ERR_INPUT, where//' = "'//path//'": needs at least two rows '// &
                            '(t, dx, dy, dangle_deg)')
            return
        end if
        rows = rows(:, :m)
    contains
        subroutine fail(reason)
            character(len=*), intent(in) :: reason
            call make_error(err, ERR_INPUT, where//' = "'//path//'": line '//int_text(lineno)// &
                            ' ("'//trim(line(:min(len_trim(line), 60)))//'"): '//reason)
            close (unit)
        end subroutine fail
    end subroutine read_motion_table

    !> The next line of the formatted unit, whole (however long).
    subroutine read_line(unit, line, ios, msg)
        integer, intent(in) :: unit
        character(len=:), allocatable, intent(out) :: line
        integer, intent(out) :: ios
        character(len=*), intent(inout) :: msg
        character(len=256) :: chunk
        integer :: n
        line = ''
        do
            read (unit, '(a)', advance='no', iostat=ios, iomsg=msg, size=n) chunk
            line = line//chunk(:n)
            if (ios /= 0) exit
        end do
        if (is_iostat_eor(ios)) ios = 0
        ! the last line without a new line: its text, then the end on the next call
        if (is_iostat_end(ios) .and. len(line) > 0) ios = 0
    end subroutine read_line
end module ropedyn_motion_table
