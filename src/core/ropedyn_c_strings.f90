!> C strings read into Fortran: the one copy that the CVODE wrapper (its error handler's
!! messages) and the C interface of the library (paths, scene text, settings) both use.
module ropedyn_c_strings
    use, intrinsic :: iso_c_binding, only: c_ptr, c_char, c_size_t, c_associated, c_f_pointer
    implicit none
    private

    public :: c_string

    interface
        pure integer(c_size_t) function c_strlen(s) bind(C, name='strlen')
            import :: c_ptr, c_size_t
            type(c_ptr), value, intent(in) :: s
        end function c_strlen
    end interface

contains

    !> The NUL-terminated C string at `p` as a Fortran string ('' for NULL).
    function c_string(p) result(s)
        type(c_ptr), intent(in) :: p
        character(len=:), allocatable :: s
        character(kind=c_char), pointer :: chars(:)
        integer :: k, n
        if (.not. c_associated(p)) then
            s = ''
            return
        end if
        n = int(c_strlen(p))
        call c_f_pointer(p, chars, [n])
        allocate (character(len=n) :: s)
        do k = 1, n
            s(k:k) = chars(k)
        end do
    end function c_string

end module ropedyn_c_strings
