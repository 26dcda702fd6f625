!> The block-tridiagonal factorization of the RFEM's reduced Newton matrix
!! (solvers/ropedyn_block3.f90) and the band LU path it falls back to (band_lu_factor with
!! band_solve_rfem), against LAPACK's dgesv on the dense matrix:
!! - a random block-tridiagonal matrix with 3 x 3 blocks, rows scaled like the rope's (the
!!   rotational rows 1e-4 of the translational ones), solve_plus_product: A^{-1} (b + g K x)
!!   for a second random block-tridiagonal K;
!! - an entry outside the block-tridiagonal pattern (within the band) is found, K's refused
!!   by set_k, and a singular diagonal block reported (info > 0), so that the caller falls
!!   back to the band LU.
program test_block3
    use ropedyn_kinds, only: wp
    use ropedyn_lapack, only: dgesv
    use ropedyn_block3, only: block3_t, block_tridiagonal
    use ropedyn_band_lu, only: band_lu_factor, band_solve_rfem
    use ropedyn_assert, only: test_suite_t
    implicit none

    integer, parameter :: NB = 20, N = 3*NB
    type(test_suite_t) :: suite
    type(block3_t) :: f
    real(wp) :: a(11, N), k(11, N), dense(N, N), kd(N, N), x(N), b(N), ref(N), y(N)
    real(wp) :: ab(16, N), scale(N), g
    integer :: i, info, ipiv(N), kvu, piv(N)
    logical :: ok

    suite%name = 'block3'
    call random_seed(put=[(12345 + i, i = 1, 64)])
    scale = [(merge(1.0e-4_wp, 1.0_wp, mod(i, 3) == 0), i = 1, N)]
    call random_block_tridiagonal(a, dense, 6.0_wp)
    call random_block_tridiagonal(k, kd, 0.0_wp)
    call random_number(x)
    call random_number(b)
    g = 0.37_wp
    ! reference: A^{-1} (b + g K x), dense LU
    ref = b + g*matmul(kd, x)
    call dgesv(N, 1, dense, N, piv, ref, N, info)
    call suite%check_true(info == 0, 'dgesv of the reference')

    call f%set_k(N, k, ok)
    call suite%check_true(ok .and. block_tridiagonal(N, a), 'A and K block tridiagonal')
    call f%factor(N, a, info)
    call suite%check_true(info == 0, 'block-tridiagonal matrix factored (info = 0)')
    y = b
    call f%solve_plus_product(g, x, y)
    call suite%check_le(maxval(abs(y - ref))/maxval(abs(ref)), 1.0e-12_wp, &
                        'solve_plus_product against dgesv (max relative difference)')
    y = b + g*matmul(kd, x)
    call f%solve(y)
    call suite%check_le(maxval(abs(y - ref))/maxval(abs(ref)), 1.0e-12_wp, &
                        'solve against dgesv (max relative difference)')

    ! the band LU fallback on the same matrix
    ab = 0.0_wp
    ab(6:16, :) = a
    call band_lu_factor(N, 5, 5, ab, ipiv, info, kvu)
    y = b
    call band_solve_rfem(N, k, g, x, ab, ipiv, y)
    call suite%check_le(maxval(abs(y - ref))/maxval(abs(ref)), 1.0e-12_wp, &
                        'band LU fallback (band_solve_rfem) against dgesv')

    ! refusals
    a(6 + 4 - 8, 8) = 1.0e-3_wp    ! entry (4, 8): block 2 against block 3 is fine ...
    call suite%check_true(block_tridiagonal(N, a), 'entry (4, 8) is within the pattern')
    a(6 + 3 - 8, 8) = 1.0e-3_wp    ! ... entry (3, 8): block 1 against block 3 is not
    call suite%check_true(.not. block_tridiagonal(N, a), 'entry (3, 8) is outside')
    k(6 + 8 - 3, 3) = 1.0_wp       ! K entry (8, 3): block 3 against block 1
    call f%set_k(N, k, ok)
    call suite%check_true(.not. ok, 'K entry (8, 3) outside the pattern: set_k refuses')
    call f%set_k(N - 1, k(:, 1:N - 1), ok)
    call suite%check_true(.not. ok, 'n not a multiple of 3: set_k refuses')
    a(:, 1:3) = 0.0_wp             ! first diagonal block (and the block below it) zero
    call f%factor(N, a, info)
    call suite%check_true(info == 1, 'singular first block: info = 1')
    call suite%finish()

contains

    !> A random block-tridiagonal matrix (3 x 3 blocks) in compact band storage (row
    !! 6 + i - j) and dense; diagonal shifted by `shift` (diagonal dominance), rows scaled.
    subroutine random_block_tridiagonal(band, full, shift)
        real(wp), intent(out) :: band(11, N), full(N, N)
        real(wp), intent(in) :: shift
        real(wp) :: r
        integer :: i, j
        full = 0.0_wp
        band = 0.0_wp
        do j = 1, N
            do i = max(1, j - 5), min(N, j + 5)
                if (abs((i - 1)/3 - (j - 1)/3) > 1) cycle
                call random_number(r)
                r = r - 0.5_wp
                if (i == j) r = r + shift
                full(i, j) = scale(i)*r
                band(6 + i - j, j) = full(i, j)
            end do
        end do
    end subroutine random_block_tridiagonal
end program test_block3
