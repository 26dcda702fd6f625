!> Band LU factorization and solves for the small bandwidths of the reduced Newton matrices
!! (ropedyn_iteration_matrix): LAPACK's algorithms written as loops, a copy with constant
!! bandwidths for the RFEM, and the band helpers of the reduced solve.
module ropedyn_band_lu
    use ropedyn_kinds, only: wp
    implicit none
    private
    public :: RFEM_KL, factored_dense, band_lu_factor, band_lu_solve, band_solve_rfem, &
              band_add_product, full_entry

    !> Bandwidths of the RFEM's reduced matrix (3 x 3 blocks, block tridiagonal): its solve
    !! has a copy of the band loops with these as constants, whose inner loops the compiler
    !! unrolls completely (half the instructions of the general loops at trip count 5).
    integer, parameter :: RFEM_KL = 5

contains

    !> True when a matrix of order n with bandwidths kl, ku is factored dense (dgetrf): its
    !! band LU storage (2 kl + ku + 1 rows) would be as large.
    pure logical function factored_dense(n, kl, ku) result(dense)
        integer, intent(in) :: n, kl, ku
        dense = 2*kl + ku + 1 >= n
    end function factored_dense

    !> LU factorization with partial pivoting of a band matrix in LAPACK's dgbtrf storage
    !! (entry (i, j) at row kl + ku + 1 + i - j of 2 kl + ku + 1 rows; rows 1 .. kl are
    !! the fill-in and must be zero on entry): dgbtf2's algorithm and output, written out
    !! as loops, except that the diagonal of U is stored inverted (the solve multiplies).
    !! For the small bandwidths of the reduced rope matrices (5/5) LAPACK's BLAS calls per
    !! column cost more than their arithmetic. info = j > 0: U(j, j) = 0. kvu: the number
    !! of super-diagonals of U that hold fill (ku without row interchanges, at most kl + ku):
    !! the solve skips the others, which are zero.
    pure subroutine band_lu_factor(n, kl, ku, ab, ipiv, info, kvu)
        integer, intent(in) :: n, kl, ku
        real(wp), intent(inout) :: ab(2*kl + ku + 1, n)
        integer, intent(out) :: ipiv(n)
        integer, intent(out) :: info
        integer, intent(out) :: kvu
        integer :: kv, j, jp, km, ju, i, c
        real(wp) :: pivot, big, x, u

        kv = kl + ku
        info = 0
        ju = 1
        kvu = min(ku, n - 1)
        do j = 1, n
            km = min(kl, n - j)
            ! pivot: largest |A(i, j)|, i = j .. j + km (row kv + 1 + i - j)
            jp = 1
            big = abs(ab(kv + 1, j))
            do i = 2, km + 1
                if (abs(ab(kv + i, j)) > big) then
                    big = abs(ab(kv + i, j))
                    jp = i
                end if
            end do
            ipiv(j) = jp + j - 1
            if (ab(kv + jp, j) == 0.0_wp) then
                if (info == 0) info = j
                cycle
            end if
            ju = max(ju, min(j + ku + jp - 1, n))
            kvu = max(kvu, ju - j)
            if (jp /= 1) then
                ! swap rows j and j + jp - 1 in columns j .. ju
                do c = j, ju
                    x = ab(kv + jp - (c - j), c)
                    ab(kv + jp - (c - j), c) = ab(kv + 1 - (c - j), c)
                    ab(kv + 1 - (c - j), c) = x
                end do
            end if
            pivot = 1.0_wp/ab(kv + 1, j)
            ab(kv + 1, j) = pivot
            ab(kv + 2:kv + 1 + km, j) = ab(kv + 2:kv + 1 + km, j)*pivot
            ! A(j+1 : j+km, c) -= l * A(j, c) for c = j+1 .. ju
            do c = j + 1, ju
                u = ab(kv + 1 + j - c, c)
                if (u /= 0.0_wp) then
                    do i = 1, km
                        ab(kv + 1 + j + i - c, c) = ab(kv + 1 + j + i - c, c) - ab(kv + 1 + i, j)*u
                    end do
                end if
            end do
        end do
    end subroutine band_lu_factor

    !> b <- A^{-1} b with the factors of band_lu_factor (dgbtrs's algorithm; U's
    !! super-diagonals beyond kvu are zero and skipped).
    pure subroutine band_lu_solve(n, kl, ku, kvu, ab, ipiv, b)
        integer, intent(in) :: n, kl, ku, kvu
        real(wp), intent(in) :: ab(2*kl + ku + 1, n)
        integer, intent(in) :: ipiv(n)
        real(wp), intent(inout) :: b(n)
        integer :: kv, j, km, i
        real(wp) :: x

        kv = kl + ku
        ! L y = P b
        do j = 1, n - 1
            km = min(kl, n - j)
            if (ipiv(j) /= j) call interchange(b, j, ipiv(j))
            x = b(j)
            do i = 1, km
                b(j + i) = b(j + i) - ab(kv + 1 + i, j)*x
            end do
        end do
        ! U x = y (U has kv super-diagonals; its diagonal is stored inverted)
        do j = n, 1, -1
            x = b(j)*ab(kv + 1, j)
            b(j) = x
            do i = max(1, j - kvu), j - 1
                b(i) = b(i) - ab(kv + 1 + i - j, j)*x
            end do
        end do
    end subroutine band_lu_solve

    !> band_product_rfem and band_lu_solve for kl = ku = RFEM_KL (n > 4 kl): y <- y + g K x,
    !! then y <- A^{-1} y; the solve's operations in band_lu_solve's order, the interior
    !! columns with constant trip counts (U's kl + ku super-diagonals all visited: those
    !! beyond the fill are zero).
    pure subroutine band_solve_rfem(n, kb, g, x, ab, ipiv, y)
        integer, intent(in) :: n
        real(wp), intent(in) :: kb(2*RFEM_KL + 1, n)
        real(wp), intent(in) :: g
        real(wp), intent(in) :: x(n)
        real(wp), intent(in) :: ab(3*RFEM_KL + 1, n)
        integer, intent(in) :: ipiv(n)
        real(wp), intent(inout) :: y(n)
        integer, parameter :: KL = RFEM_KL, KV = 2*RFEM_KL
        integer :: i, j
        real(wp) :: t

        call band_product_rfem(n, kb, g, x, y)
        ! L z = P y
        do j = 1, n - 1
            if (ipiv(j) /= j) call interchange(y, j, ipiv(j))
            t = y(j)
            if (j <= n - KL) then
                do i = 1, KL
                    y(j + i) = y(j + i) - ab(KV + 1 + i, j)*t
                end do
            else
                do i = 1, n - j
                    y(j + i) = y(j + i) - ab(KV + 1 + i, j)*t
                end do
            end if
        end do
        ! U x = z (diagonal stored inverted)
        do j = n, 1, -1
            t = y(j)*ab(KV + 1, j)
            y(j) = t
            if (j > KV) then
                do i = -KV, -1
                    y(j + i) = y(j + i) - ab(KV + 1 + i, j)*t
                end do
            else
                do i = 1, j - 1
                    y(i) = y(i) - ab(KV + 1 + i - j, j)*t
                end do
            end if
        end do
    end subroutine band_solve_rfem

    !> b(j) <-> b(l): a row interchange of the factorization's partial pivoting.
    pure subroutine interchange(b, j, l)
        real(wp), intent(inout) :: b(:)
        integer, intent(in) :: j, l
        real(wp) :: x
        x = b(l)
        b(l) = b(j)
        b(j) = x
    end subroutine interchange

    !> y <- y + g K x for kl = ku = RFEM_KL (n > 2 kl), row by row: each y(i) gets one dot
    !! product of constant length in the interior (independent rows, where the column
    !! order of band_add_product chains every update of y through memory).
    pure subroutine band_product_rfem(n, kb, g, x, y)
        integer, intent(in) :: n
        real(wp), intent(in) :: kb(2*RFEM_KL + 1, n)
        real(wp), intent(in) :: g
        real(wp), intent(in) :: x(n)
        real(wp), intent(inout) :: y(n)
        integer, parameter :: KL = RFEM_KL, KU = RFEM_KL
        integer :: i, j
        real(wp) :: acc
        ! row i holds columns i - kl .. i + ku, entry (i, j) at kb(ku + 1 + i - j, j)
        do i = 1, n
            acc = 0.0_wp
            if (i > KL .and. i <= n - KU) then
                do j = -KL, KU
                    acc = acc + kb(KU + 1 - j, i + j)*x(i + j)
                end do
            else
                do j = max(1, i - KL), min(n, i + KU)
                    acc = acc + kb(KU + 1 + i - j, j)*x(j)
                end do
            end if
            y(i) = y(i) + g*acc
        end do
    end subroutine band_product_rfem

    !> y <- y + g A x for A in compact band storage (row ku + 1 + i - j).
    pure subroutine band_add_product(n, kl, ku, a, g, x, y)
        integer, intent(in) :: n, kl, ku
        real(wp), intent(in) :: a(kl + ku + 1, n)
        real(wp), intent(in) :: g
        real(wp), intent(in) :: x(n)
        real(wp), intent(inout) :: y(n)
        integer :: i, j
        real(wp) :: gx
        do j = 1, n
            gx = g*x(j)
            do i = max(1, j - ku), min(n, j + kl)
                y(i) = y(i) + a(ku + 1 + i - j, j)*gx
            end do
        end do
    end subroutine band_add_product

    !> Entry (i, j) of a matrix in compact band storage (row mu + 1 + i - j), 0 off the band.
    pure real(wp) function full_entry(band, ml, mu, i, j) result(x)
        real(wp), intent(in) :: band(:, :)
        integer, intent(in) :: ml, mu, i, j
        x = 0.0_wp
        if (i - j <= ml .and. j - i <= mu) x = band(mu + 1 + i - j, j)
    end function full_entry
end module ropedyn_band_lu
