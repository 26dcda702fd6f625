!> Sums of squares (and of products) for the integrators' weighted norms (and energies), in a fixed order that runs at the
!! additions' throughput rather than their latency.
!!
!! A plain sum s = s + x_i**2 is one chain of dependent additions: each waits for the last
!! (3-4 cycles), and on the rope's 600-unknown states the integrators' norms spent most of
!! their time waiting. Here eight partial sums take the components i = 8 m + j (j = 1..8)
!! and are added pairwise at the end: eight independent chains, which gfortran runs as two
!! vectors of four (x86-64-v3) or four of two (v2). The order of the additions is fixed by
!! the code, not by the machine, so the result has the same bits at every x86-64 level.
module ropedyn_sums
    use ropedyn_kinds, only: wp
    implicit none
    private
    public :: sum_squares, sum_products

contains

    !> sum_i x_i**2, in the fixed order of the module header.
    pure real(wp) function sum_squares(x) result(s)
        real(wp), contiguous, intent(in) :: x(:)
        real(wp) :: a(8)
        integer :: i, n8
        a = 0.0_wp
        n8 = size(x) - mod(size(x), 8)
        do i = 1, n8, 8
            a = a + x(i:i + 7)**2
        end do
        do i = n8 + 1, size(x)
            a(i - n8) = a(i - n8) + x(i)**2
        end do
        s = ((a(1) + a(2)) + (a(3) + a(4))) + ((a(5) + a(6)) + (a(7) + a(8)))
    end function sum_squares

    !> sum_i x_i y_i, in the fixed order of the module header.
    pure real(wp) function sum_products(x, y) result(s)
        real(wp), contiguous, intent(in) :: x(:), y(:)
        real(wp) :: a(8)
        integer :: i, n8
        a = 0.0_wp
        n8 = size(x) - mod(size(x), 8)
        do i = 1, n8, 8
            a = a + x(i:i + 7)*y(i:i + 7)
        end do
        do i = n8 + 1, size(x)
            a(i - n8) = a(i - n8) + x(i)*y(i)
        end do
        s = ((a(1) + a(2)) + (a(3) + a(4))) + ((a(5) + a(6)) + (a(7) + a(8)))
    end function sum_products
end module ropedyn_sums
