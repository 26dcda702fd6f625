!> The modified Cholesky factorization L D L^T = S a S + E (Gill, Murray & Wright) of a
!! symmetric matrix in band storage, and its solve: the linear algebra of the statics
!! solver (ropedyn_statics), which needs a descent direction also where the stiffness is
!! indefinite.
module ropedyn_ldl
    use ropedyn_kinds, only: wp
    implicit none
    private
    public :: ldl_t, ldl_factor, ldl_solve, bandwidth

    !> A modified L D L^T factorization of S a S (see `ldl_factor`), band storage.
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

    !> The modified Cholesky factorization of Gill, Murray & Wright (Practical Optimization,
    !! 1981, sec. 4.4.2.2) of a symmetric matrix: L D L^T = S a S + E with E >= 0 diagonal,
    !! zero when S a S is safely positive definite and just large enough otherwise, so that
    !! the solution of (a + S^-1 E S^-1) x = b is always a descent direction. S = diag(scale)
    !! evens out the rows (here scale = 1/sqrt(diag M)) so that E is measured in the same
    !! units for every coordinate. Band storage when a is narrow (bandwidth kd < n/4:
    !! O(n kd^2)), the same code with kd = n - 1 otherwise. `modified`: E /= 0.
    subroutine ldl_factor(a_in, scale, fac, modified)
        real(wp), intent(in) :: a_in(:, :), scale(:)
        type(ldl_t), intent(out) :: fac
        logical, intent(out) :: modified
        real(wp), allocatable :: c(:), a(:, :)
        real(wp) :: gamma, xi, beta2, delta, cjj, theta, acc
        integer :: n, kd, i, j, k

        n = size(scale)
        kd = bandwidth(a_in)
        if (4*kd >= n) kd = n - 1
        fac%n = n
        fac%kd = kd
        fac%scale = scale
        allocate (a(n, n), fac%lb(0:kd, n), fac%d(n), c(0:kd))
        associate (lb => fac%lb, d => fac%d)
            do j = 1, n
                do i = max(1, j - kd), min(n, j + kd)
                    a(i, j) = scale(i)*a_in(i, j)*scale(j)
                end do
            end do
            lb = 0.0_wp
            gamma = 0.0_wp
            xi = 0.0_wp
            do j = 1, n
                gamma = max(gamma, abs(a(j, j)))
                do i = j + 1, min(n, j + kd)
                    xi = max(xi, abs(a(i, j)))
                end do
            end do
            beta2 = max(gamma, epsilon(1.0_wp))
            if (n > 1) beta2 = max(beta2, xi/sqrt(real(n, wp)**2 - 1.0_wp))
            delta = epsilon(1.0_wp)*max(gamma + xi, 1.0_wp)
            modified = .false.
            do j = 1, n
                acc = a(j, j)
                do k = max(1, j - kd), j - 1
                    acc = acc - d(k)*lb(j - k, k)**2
                end do
                cjj = acc
                theta = 0.0_wp
                do i = j + 1, min(n, j + kd)
                    acc = a(i, j)
                    do k = max(1, i - kd), j - 1
                        acc = acc - lb(i - k, k)*d(k)*lb(j - k, k)
                    end do
                    c(i - j) = acc
                    theta = max(theta, abs(acc))
                end do
                d(j) = max(delta, abs(cjj), theta**2/beta2)
                if (d(j) - cjj > 1.0e-12_wp*abs(cjj) + delta) modified = .true.
                do i = j + 1, min(n, j + kd)
                    lb(i - j, j) = c(i - j)/d(j)
                end do
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
