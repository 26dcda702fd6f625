!> Kinds used throughout ropedyn: every real is real(wp).
module ropedyn_kinds
    use, intrinsic :: iso_fortran_env, only: real64, real128, int64
    implicit none
    private
    public :: wp, i8, qp

    integer, parameter :: wp = real64   !< working precision for all reals
    integer, parameter :: i8 = int64    !< wide integers (counters, sizes passed to C)
    !> extended precision, only for deriving method coefficients once (rounded to wp)
    integer, parameter :: qp = real128
end module ropedyn_kinds
