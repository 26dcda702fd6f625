!> A small assertion module for the Fortran test programs.
!!
!! Each check prints one line (PASS/FAIL with the values); `finish` prints the tally and
!! ends the program with a non-zero exit code when any check failed.
module ropedyn_assert
    use ropedyn_kinds, only: wp
    implicit none
    private
    public :: test_suite_t

    type :: test_suite_t
        character(len=:), allocatable :: name
        integer :: passed = 0
        integer :: failed = 0
    contains
        procedure :: check_true
        procedure :: check_close
        procedure :: check_le
        procedure :: check_contains
        procedure :: finish
    end type test_suite_t

contains

    subroutine check_true(self, condition, label)
        class(test_suite_t), intent(inout) :: self
        logical, intent(in) :: condition
        character(len=*), intent(in) :: label
        if (condition) then
            self%passed = self%passed + 1
            write (*, '(a)') 'PASS  '//label
        else
            self%failed = self%failed + 1
            write (*, '(a)') 'FAIL  '//label
        end if
    end subroutine check_true

    !> |actual - expected| <= rtol*|expected| + atol
    subroutine check_close(self, actual, expected, rtol, atol, label)
        class(test_suite_t), intent(inout) :: self
        real(wp), intent(in) :: actual, expected
        real(wp), intent(in) :: rtol, atol
        character(len=*), intent(in) :: label
        character(len=200) :: detail
        logical :: ok
        ok = abs(actual - expected) <= rtol*abs(expected) + atol
        write (detail, '(a, es16.8, a, es16.8, a, es9.2)') ' actual', actual, ' expected', &
            expected, ' diff', abs(actual - expected)
        call self%check_true(ok, label//trim(detail))
    end subroutine check_close

    !> value <= bound
    subroutine check_le(self, value, bound, label)
        class(test_suite_t), intent(inout) :: self
        real(wp), intent(in) :: value, bound
        character(len=*), intent(in) :: label
        character(len=120) :: detail
        write (detail, '(a, es12.4, a, es12.4)') ' value', value, ' bound', bound
        call self%check_true(value <= bound, label//trim(detail))
    end subroutine check_le

    !> `text` contains `part`
    subroutine check_contains(self, text, part, label)
        class(test_suite_t), intent(inout) :: self
        character(len=*), intent(in) :: text, part
        character(len=*), intent(in) :: label
        call self%check_true(index(text, part) > 0, label//' ["'//part//'" in "'//text//'"]')
    end subroutine check_contains

    !> Print the tally; stop with exit code 1 if any check failed.
    subroutine finish(self)
        class(test_suite_t), intent(in) :: self
        write (*, '(a, ": ", i0, " passed, ", i0, " failed")') self%name, self%passed, self%failed
        if (self%failed > 0 .or. self%passed == 0) error stop 1
    end subroutine finish
end module ropedyn_assert
