!> The modified Cholesky factorization L D L^T = S a S + E (Gill, Murray & Wright) of a
!! symmetric matrix in band storage, and its solve: the linear algebra of the statics
!! solver (ropedyn_statics), which needs a descent direction also where the stiffness is
!! indefinite. Symmetric matrices are kept as their lower band, ab(i - j, j) = a(i, j) for
!! 0 <= i - j <= kd (kd = size(ab, 1) - 1; kd = n - 1 holds a dense matrix).
module ropedyn_ldl
    use ropedyn_kinds, only: wp
    implicit none
    private
    public :: ldl_t, ldl_factor, ldl_solve, bandwidth, band_of, band_matvec

    !> A modified L D L^T factorization of S a S (see `ldl_factor`), band storage. Its
    !! arrays are kept between factorizations of the same size.
    type :: ldl_t
        integer :: n = 0, kd = 0
        real(wp), allocatable :: lb(:, :)    !< L below the diagonal, lb(i - j, j)
        real(wp), allocatable :: d(:)        !< D
        real(wp), allocatable :: scale(:)    !< S
    end type ldl_t

contains

    !> Largest |i - j| of a non-zero entry of a square matrix.
    pure integer function bandwidth(a) result(kd)
        real(wp), intent(in) :: a(:, :)
        integer :: i, j
        kd = 0
        do j = 1, size(a, 2)
            do i = 1, size(a, 1)
                if (a(i, j) /= 0.0_wp) kd = max(kd, abs(i - j))
            end do
        end do
    end function bandwidth

    !> The lower band (0:kd, n) of the symmetric part (a + a^T)/2 of a square matrix.
    pure function band_of(a, kd) result(ab)
        real(wp), intent(in) :: a(:, :)
        integer, intent(in) :: kd
        real(wp) :: ab(0:kd, size(a, 2))
        integer :: i, j, n
        n = size(a, 2)
        ab = 0.0_wp
        do j = 1, n
            do i = j, min(n, j + kd)
                ab(i - j, j) = 0.5_wp*(a(i, j) + a(j, i))
            end do
        end do
    end function band_of

    !> a x for the symmetric a in lower band storage ab(0:kd, n).
    pure function band_matvec(ab, x) result(y)
        real(wp), intent(in) :: ab(0:, :), x(:)
        real(wp) :: y(size(x))
        integer :: i, j, n, kd
        n = size(x)
        kd = ubound(ab, 1)
        y = 0.0_wp
        do j = 1, n
            y(j) = y(j) + ab(0, j)*x(j)
            do i = j + 1, min(n, j + kd)
                y(i) = y(i) + ab(i - j, j)*x(j)
                y(j) = y(j) + ab(i - j, j)*x(i)
            end do
        end do
    end function band_matvec

    !> The modified Cholesky factorization of Gill, Murray & Wright (Practical Optimization,
    !! 1981, sec. 4.4.2.2) of a symmetric matrix a, given as its lower band ab(0:kd, n):
    !! L D L^T = S a S + E with E >= 0 diagonal, zero when S a S is safely positive definite
    !! and just large enough otherwise, so that the solution of (a + S^-1 E S^-1) x = b is
    !! always a descent direction. S = diag(scale) evens out the rows (here scale =
    !! 1/sqrt(diag M)) so that E is measured in the same units for every coordinate. L keeps
    !! the band: O(n kd^2). `modified`: E /= 0.
    subroutine ldl_factor(ab, scale, fac, modified)
        real(wp), intent(in) :: ab(0:, :), scale(:)
        type(ldl_t), intent(inout) :: fac
        logical, intent(out) :: modified
        real(wp), allocatable :: c(:)
        real(wp) :: gamma, xi, beta2, delta, cjj, theta, t
        integer :: n, kd, i, j, k, top

        n = size(scale)
        kd = min(ubound(ab, 1), n - 1)
        if (fac%n /= n .or. fac%kd /= kd .or. .not. allocated(fac%lb)) then
            if (allocated(fac%lb)) deallocate (fac%lb, fac%d, fac%scale)
            allocate (fac%lb(0:kd, n), fac%d(n), fac%scale(n))
        end if
        fac%n = n
        fac%kd = kd
        fac%scale = scale
        allocate (c(0:kd))
        associate (lb => fac%lb, d => fac%d)
            ! the scaled matrix into lb (column j is overwritten by L's column j below)
            gamma = 0.0_wp
            xi = 0.0_wp
            do j = 1, n
                top = min(kd, n - j)
                do i = 0, top
                    lb(i, j) = scale(i + j)*ab(i, j)*scale(j)
                end do
                gamma = max(gamma, abs(lb(0, j)))
                if (top > 0) xi = max(xi, maxval(abs(lb(1:top, j))))
            end do
            beta2 = max(gamma, epsilon(1.0_wp))
            if (n > 1) beta2 = max(beta2, xi/sqrt(real(n, wp)**2 - 1.0_wp))
            delta = epsilon(1.0_wp)*max(gamma + xi, 1.0_wp)
            modified = .false.
            do j = 1, n
                top = min(kd, n - j)
                ! c(i - j) = a(i, j) - sum_k L(i, k) d(k) L(j, k), i = j .. j + top, the
                ! earlier columns k in turn (each read contiguously)
                c(0:top) = lb(0:top, j)
                do k = max(1, j - kd), j - 1
                    t = d(k)*lb(j - k, k)
                    if (t == 0.0_wp) cycle
                    do i = j, min(n, k + kd)
                        c(i - j) = c(i - j) - lb(i - k, k)*t
                    end do
                end do
                cjj = c(0)
                theta = 0.0_wp
                if (top > 0) theta = maxval(abs(c(1:top)))
                d(j) = max(delta, abs(cjj), theta**2/beta2)
                if (d(j) - cjj > 1.0e-12_wp*abs(cjj) + delta) modified = .true.
                lb(0, j) = 1.0_wp
                lb(1:top, j) = c(1:top)/d(j)
            end do
        end associate
    end subroutine ldl_factor

    !> x = S (L D L^T)^-1 S b.
    function ldl_solve(fac, b) result(x)
        type(ldl_t), intent(in) :: fac
        real(wp), intent(in) :: b(:)
        real(wp) :: x(size(b))
        integer :: i, j
        x = fac%scale*b
        do j = 1, fac%n
            do i = j + 1, min(fac%n, j + fac%kd)
                x(i) = x(i) - fac%lb(i - j, j)*x(j)
            end do
        end do
        x = x/fac%d
        do j = fac%n, 1, -1
            do i = j + 1, min(fac%n, j + fac%kd)
                x(j) = x(j) - fac%lb(i - j, j)*x(i)
            end do
        end do
        x = fac%scale*x
    end function ldl_solve
end module ropedyn_ldl
