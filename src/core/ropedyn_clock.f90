!> The clocks of ropedyn, in one place: a monotonic clock for elapsed times (profiles,
!! progress, flushes, timeouts), the calendar time in s since 1970 and as ISO 8601 UTC text.
!! (CPU time is Fortran's own `cpu_time`.)
module ropedyn_clock
    use, intrinsic :: iso_c_binding, only: c_long_long
    use, intrinsic :: iso_fortran_env, only: int64
    use ropedyn_kinds, only: wp
    implicit none
    private
    public :: clock_seconds, unix_time, utc_timestamp, utc_text

    interface
        integer(c_long_long) function c_unix_time() bind(C, name='ropedyn_unix_time')
            import :: c_long_long
        end function c_unix_time
    end interface

contains

    !> Seconds on the monotonic clock since an arbitrary origin (differences only).
    real(wp) function clock_seconds() result(s)
        integer(int64) :: count, rate
        call system_clock(count, rate)
        s = real(count, wp)/real(rate, wp)
    end function clock_seconds

    !> The time now, s since 1970.
    integer(int64) function unix_time()
        unix_time = int(c_unix_time(), int64)
    end function unix_time

    !> Current time as ISO 8601 UTC, e.g. 2024-05-01T12:34:56Z.
    function utc_timestamp() result(text)
        character(len=20) :: text
        integer :: values(8), offset, days, minutes, year, month, day
        call date_and_time(values=values)
        offset = values(4)
        if (offset == -huge(0)) offset = 0
        minutes = values(5)*60 + values(6) - offset
        days = days_from_civil(values(1), values(2), values(3)) &
               + (minutes - modulo(minutes, 1440))/1440
        minutes = modulo(minutes, 1440)
        call civil_from_days(days, year, month, day)
        write (text, '(i4.4, "-", i2.2, "-", i2.2, "T", i2.2, ":", i2.2, ":", i2.2, "Z")') &
            year, month, day, minutes/60, modulo(minutes, 60), values(7)
    end function utc_timestamp

    !> A time in s since 1970 as ISO 8601 UTC, e.g. 2024-05-01T12:34:56Z.
    function utc_text(seconds) result(text)
        integer(int64), intent(in) :: seconds
        character(len=20) :: text
        integer :: year, month, day, second_of_day
        call civil_from_days(int(floor_div64(seconds, 86400_int64)), year, month, day)
        second_of_day = int(seconds - floor_div64(seconds, 86400_int64)*86400_int64)
        write (text, '(i4.4, "-", i2.2, "-", i2.2, "T", i2.2, ":", i2.2, ":", i2.2, "Z")') &
            year, month, day, second_of_day/3600, mod(second_of_day, 3600)/60, &
            mod(second_of_day, 60)
    end function utc_text

    pure integer(int64) function floor_div64(a, b) result(q)
        integer(int64), intent(in) :: a, b
        q = a/b
        if (mod(a, b) /= 0 .and. a < 0) q = q - 1
    end function floor_div64

    !> Days since 1970-01-01 of a proleptic Gregorian date (H. Hinnant's algorithm).
    pure integer function days_from_civil(year, month, day) result(days)
        integer, intent(in) :: year, month, day
        integer :: y, era, yoe, doy, doe
        y = year
        if (month <= 2) y = y - 1
        era = floor_div(y, 400)
        yoe = y - era*400
        if (month > 2) then
            doy = (153*(month - 3) + 2)/5 + day - 1
        else
            doy = (153*(month + 9) + 2)/5 + day - 1
        end if
        doe = yoe*365 + yoe/4 - yoe/100 + doy
        days = era*146097 + doe - 719468
    end function days_from_civil

    !> Inverse of days_from_civil.
    pure subroutine civil_from_days(days, year, month, day)
        integer, intent(in) :: days
        integer, intent(out) :: year, month, day
        integer :: z, era, doe, yoe, doy, mp
        z = days + 719468
        era = floor_div(z, 146097)
        doe = z - era*146097
        yoe = (doe - doe/1460 + doe/36524 - doe/146096)/365
        doy = doe - (365*yoe + yoe/4 - yoe/100)
        mp = (5*doy + 2)/153
        day = doy - (153*mp + 2)/5 + 1
        if (mp < 10) then
            month = mp + 3
        else
            month = mp - 9
        end if
        year = yoe + era*400
        if (month <= 2) year = year + 1
    end subroutine civil_from_days

    !> floor(a / b) for b > 0 (Fortran's / truncates towards zero).
    pure integer function floor_div(a, b) result(q)
        integer, intent(in) :: a, b
        if (a >= 0) then
            q = a/b
        else
            q = (a - (b - 1))/b
        end if
    end function floor_div
end module ropedyn_clock
