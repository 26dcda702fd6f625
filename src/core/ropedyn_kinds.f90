!> Kinds used throughout ropedyn: every real is real(wp).
module ropedyn_kinds
    use, intrinsic :: iso_fortran_env, only: real64, int64
    implicit none
    private
    public :: wp, i8

    integer, parameter :: wp = real64   !< working precision for all reals
    integer, parameter :: i8 = int64    !< wide integers (counters, sizes passed to C)
end module ropedyn_kinds
