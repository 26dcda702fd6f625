!> Kinds used throughout ropedyn: every real is real(wp); and pi, defined once.
module ropedyn_kinds
    use, intrinsic :: iso_fortran_env, only: real64, real128, int64
    implicit none
    private
    public :: wp, i8, qp, PI

    integer, parameter :: wp = real64   !< working precision for all reals
    integer, parameter :: i8 = int64    !< wide integers (counters, sizes passed to C)
    !> extended precision, only for deriving method coefficients once (rounded to wp)
    integer, parameter :: qp = real128
    !> pi, rounded to wp
    real(wp), parameter :: PI = acos(-1.0_wp)
end module ropedyn_kinds
