!> Coefficients of the k-step BDF and of Cash's modified extended BDF (MEBDF), derived from
!! their order conditions (docs/theory/mebdf.md, "The coefficients"; Cash 1980, 1983).
!!
!! Points are numbered 0 .. k+1 at unit spacing. The k-step BDF (order k)
!!     sum_{j=0..k} alpha_j y_j = h beta f_k,               alpha_k = 1,
!! and the MEBDF corrector (order k+1)
!!     sum_{j=0..k} ahat_j y_j = h (bhat_k f_k + bhat_{k+1} f_{k+1}),   ahat_k = 1,
!! are exact for polynomials of degree <= k and <= k+1:
!!     sum_j alpha_j j^q = q beta k^(q-1)                               (q = 0 .. k)
!!     sum_j ahat_j j^q = q (bhat_k k^(q-1) + bhat_{k+1} (k+1)^(q-1))    (q = 0 .. k+1).
!! Both systems are solved here in extended precision (the Vandermonde-like matrices are
!! ill-conditioned for large k) and rounded to working precision; a test compares them
!! with the exact fractions of docs/theory/mebdf.md.
module ropedyn_mebdf_coefficients
    use ropedyn_kinds, only: wp, qp
    implicit none
    private
    public :: mebdf_coefficients_t, mebdf_coefficients, KMAX_MEBDF

    !> Highest number of steps k (order k + 1 = 7, the classic MEBDF codes' limit too).
    integer, parameter :: KMAX_MEBDF = 6

    type :: mebdf_coefficients_t
        integer :: k = 0                      !< number of steps
        real(wp) :: alpha(0:KMAX_MEBDF) = 0.0_wp  !< BDF alpha_0 .. alpha_k (alpha_k = 1)
        real(wp) :: beta = 0.0_wp             !< BDF beta_k (= 1 / sum_{j=1..k} 1/j)
        real(wp) :: ahat(0:KMAX_MEBDF) = 0.0_wp   !< MEBDF ahat_0 .. ahat_k (ahat_k = 1)
        real(wp) :: bhat_k = 0.0_wp           !< MEBDF weight of f at point k
        real(wp) :: bhat_k1 = 0.0_wp          !< MEBDF weight of f at point k + 1
        !> error constant of the BDF with respect to the (k+1)-th backward difference of
        !! the solution: local error = nabla^{k+1} y / tq, tq = (k+1) sum_{j=1..k} 1/j
        real(wp) :: tq = 0.0_wp
        !> error constant C_{k+2} of the MEBDF corrector (residual of the order condition
        !! q = k+2 divided by (k+2)!, normalized by ahat_k = 1)
        real(wp) :: mebdf_error_constant = 0.0_wp
    end type mebdf_coefficients_t

contains

    !> The coefficients of the k-step formulas, 1 <= k <= KMAX_MEBDF.
    pure function mebdf_coefficients(k) result(c)
        integer, intent(in) :: k
        type(mebdf_coefficients_t) :: c
        real(qp) :: a(k + 2, k + 2), b(k + 2), fact
        integer :: q, j

        c%k = k
        ! BDF: unknowns alpha_0 .. alpha_{k-1}, beta; equations q = 0 .. k.
        a = 0.0_wp
        b = 0.0_wp
        do q = 0, k
            do j = 0, k - 1
                a(q + 1, j + 1) = real(j, qp)**q
            end do
            a(q + 1, k + 1) = -real(q, qp)*power(k, q - 1)
            b(q + 1) = -real(k, qp)**q
        end do
        call solve(a(1:k + 1, 1:k + 1), b(1:k + 1))
        c%alpha(0:k - 1) = real(b(1:k), wp)
        c%alpha(k) = 1.0_wp
        c%beta = real(b(k + 1), wp)

        ! MEBDF: unknowns ahat_0 .. ahat_{k-1}, bhat_k, bhat_{k+1}; equations q = 0 .. k+1.
        a = 0.0_wp
        b = 0.0_wp
        do q = 0, k + 1
            do j = 0, k - 1
                a(q + 1, j + 1) = real(j, qp)**q
            end do
            a(q + 1, k + 1) = -real(q, qp)*power(k, q - 1)
            a(q + 1, k + 2) = -real(q, qp)*power(k + 1, q - 1)
            b(q + 1) = -real(k, qp)**q
        end do
        call solve(a, b)
        c%ahat(0:k - 1) = real(b(1:k), wp)
        c%ahat(k) = 1.0_wp
        c%bhat_k = real(b(k + 1), wp)
        c%bhat_k1 = real(b(k + 2), wp)

        c%tq = real(k + 1, wp)*sum([(1.0_wp/real(j, wp), j=1, k)])

        q = k + 2
        fact = product([(real(j, qp), j=1, q)])
        c%mebdf_error_constant = real((sum([(b(j + 1)*real(j, qp)**q, j=0, k - 1)]) &
            + real(k, qp)**q - real(q, qp)*(b(k + 1)*power(k, q - 1) &
            + b(k + 2)*power(k + 1, q - 1)))/fact, wp)
    end function mebdf_coefficients

    !> j**e with 0**(-1) taken as 0 (the q = 0 term of the derivative).
    pure real(qp) function power(j, e)
        integer, intent(in) :: j, e
        if (e < 0) then
            power = 0.0_qp
        else
            power = real(j, qp)**e
        end if
    end function power

    !> Solve a x = b by Gaussian elimination with partial pivoting (tiny systems);
    !! b is overwritten by x.
    pure subroutine solve(a, b)
        real(qp), intent(inout) :: a(:, :)
        real(qp), intent(inout) :: b(:)
        integer :: n, i, p
        real(qp) :: row(size(a, 2)), tmp
        n = size(b)
        do i = 1, n
            p = i - 1 + maxloc(abs(a(i:n, i)), dim=1)
            if (p /= i) then
                row = a(i, :)
                a(i, :) = a(p, :)
                a(p, :) = row
                tmp = b(i)
                b(i) = b(p)
                b(p) = tmp
            end if
            a(i + 1:n, i) = a(i + 1:n, i)/a(i, i)
            do p = i + 1, n
                a(p, i + 1:n) = a(p, i + 1:n) - a(p, i)*a(i, i + 1:n)
                b(p) = b(p) - a(p, i)*b(i)
            end do
        end do
        do i = n, 1, -1
            b(i) = (b(i) - sum(a(i, i + 1:n)*b(i + 1:n)))/a(i, i)
        end do
    end subroutine solve
end module ropedyn_mebdf_coefficients
