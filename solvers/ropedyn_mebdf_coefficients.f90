!> Coefficients of the MEBDF formulas, derived from their order conditions.
module ropedyn_mebdf_coefficients
    use ropedyn_kinds, only: wp
    implicit none
    private
end module ropedyn_mebdf_coefficients
