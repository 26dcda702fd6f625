!> Sums of squares (and of products) for the integrators' weighted norms (and energies), in a fixed order that runs at the
!! additions' throughput rather than their latency; and the finiteness test of the
!! right-hand sides, as such a sum.
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
    public :: sum_squares, sum_scaled_squares, sum_products, all_finite

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

    !> sum_i (x_i s_i)**2, in the fixed order of the module header: sum_squares of the
    !! products x_i s_i (the same bits) without storing them (a weighted norm's vector).
    pure real(wp) function sum_scaled_squares(x, s) result(t)
        real(wp), contiguous, intent(in) :: x(:), s(:)
        real(wp) :: a(8)
        integer :: i, n8
        a = 0.0_wp
        n8 = size(x) - mod(size(x), 8)
        do i = 1, n8, 8
            a = a + (x(i:i + 7)*s(i:i + 7))**2
        end do
        do i = n8 + 1, size(x)
            a(i - n8) = a(i - n8) + (x(i)*s(i))**2
        end do
        t = ((a(1) + a(2)) + (a(3) + a(4))) + ((a(5) + a(6)) + (a(7) + a(8)))
    end function sum_scaled_squares

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

    !> True when every x_i is finite, as a sum: x_i * 0 is 0 for a finite x_i and NaN for an
    !! infinite or NaN one, so the sum of those products is 0 exactly when all are finite.
    !! Four running sums, no branch per element: all(ieee_is_finite(x)) tests and branches
    !! element by element and took 13 % of the RFEM's right-hand side at n = 30 (1,077 of
    !! 8,322 instructions). x need not be contiguous (a `contiguous` dummy makes gfortran
    !! copy an assumed-shape actual argument).
    pure logical function all_finite(x) result(ok)
        real(wp), intent(in) :: x(:)
        real(wp) :: a1, a2, a3, a4
        integer :: i, n4
        a1 = 0.0_wp
        a2 = 0.0_wp
        a3 = 0.0_wp
        a4 = 0.0_wp
        n4 = size(x) - mod(size(x), 4)
        do i = 1, n4, 4
            a1 = a1 + x(i)*0.0_wp
            a2 = a2 + x(i + 1)*0.0_wp
            a3 = a3 + x(i + 2)*0.0_wp
            a4 = a4 + x(i + 3)*0.0_wp
        end do
        do i = n4 + 1, size(x)
            a1 = a1 + x(i)*0.0_wp
        end do
        ok = (a1 + a2) + (a3 + a4) == 0.0_wp
    end function all_finite
end module ropedyn_sums
