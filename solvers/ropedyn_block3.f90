!> Block LU of a block-tridiagonal matrix with 3 x 3 blocks: the RFEM's reduced Newton
!! matrix M - g C - g^2 K (three unknowns x, y, phi per element, coupled to the
!! neighbouring elements only).
!!
!! The matrix comes in compact band storage with kl = ku = 5 (entry (i, j) at row
!! 6 + i - j), the storage of ropedyn_iteration_matrix. Factorization (block Thomas):
!!     D'_1 = D_1,  L'_i = L_i D'_{i-1}^{-1},  D'_i = D_i - L'_i U_{i-1},
!! keeping D'_i^{-1} (the adjugate over the determinant: exact under the scaling of the
!! translational and rotational rows, see invert3) and W_i = D'_i^{-1} U_i. Solve:
!!     z_i = b_i - L'_i z_{i-1},  c_i = D'_i^{-1} z_i,  x_i = c_i - W_i x_{i+1}.
!! 27 multiply-adds per block row in the solve against 3 (2 kl + ku + 1) = 48 for the band
!! LU with partial pivoting (whose row interchanges fill U to kl + ku super-diagonals on
!! the rope), and the 3 x 3 products are independent operations instead of a chain.
!!
!! Without pivoting between blocks the factorization needs nonsingular D'_i; it is stable
!! for the block diagonally dominant or positive definite matrices of a rope (the mass
!! blocks dominate for small g, the stiffness's discrete Laplacian for large g). A
!! singular or non-finite D'_i is reported (info = block); the caller checks the pattern
!! first (`block_tridiagonal`, and `set_k` for K, once per Jacobian) and uses the band LU
!! with partial pivoting for a matrix outside it or a singular block.
module ropedyn_block3
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use ropedyn_kinds, only: wp
    implicit none
    private
    public :: block3_t, block_tridiagonal

    !> The factors of a block-tridiagonal matrix of nb block rows. Each 3 x 3 block is
    !! stored with a fourth row of zeros, so that a block's column is one vector of four
    !! doubles: the solves' block products become whole-vector operations (AVX2), each row
    !! computed with the same operations in the same order as written out row by row.
    type :: block3_t
        integer :: nb = 0
        real(wp), allocatable :: dinv(:, :, :)   !< D'_i^{-1} (4, 3, nb)
        real(wp), allocatable :: lfac(:, :, :)   !< L'_i (4, 3, nb), i >= 2
        real(wp), allocatable :: wblk(:, :, :)   !< W_i = D'_i^{-1} U_i (4, 3, nb), i <= nb - 1
        !> blocks of a second block-tridiagonal matrix K (4, 3, -1:1, nb): (i, i-1), (i, i),
        !! (i, i+1), for solve_plus_product
        real(wp), allocatable :: kblk(:, :, :, :)
    contains
        procedure :: set_k => block3_set_k
        procedure :: factor => block3_factor
        procedure :: solve => block3_solve
        procedure :: solve_plus_product => block3_solve_plus_product
    end type block3_t

contains

    !> Keep the blocks of K (compact band storage, kl = ku = 5, n = 3 nb) for
    !! solve_plus_product; once per Jacobian. ok = .false.: K is not block tridiagonal (or
    !! n not a multiple of 3).
    pure subroutine block3_set_k(self, n, k, ok)
        class(block3_t), intent(inout) :: self
        integer, intent(in) :: n
        real(wp), intent(in) :: k(11, n)
        logical, intent(out) :: ok
        integer :: nb, ib, r, c, j0, o
        ok = mod(n, 3) == 0 .and. n >= 3
        if (.not. ok) return
        ok = block_tridiagonal(n, k)
        if (.not. ok) return
        nb = n/3
        if (self%nb /= nb) then
            if (allocated(self%dinv)) deallocate (self%dinv, self%lfac, self%wblk, self%kblk)
            allocate (self%dinv(4, 3, nb), self%lfac(4, 3, nb), self%wblk(4, 3, nb), &
                      self%kblk(4, 3, -1:1, nb))
            self%dinv = 0.0_wp
            self%lfac = 0.0_wp
            self%wblk = 0.0_wp
            self%nb = nb
        end if
        self%kblk = 0.0_wp
        ! the rows of a block column written out: as a loop over the three, gfortran makes
        ! each column a call of memcpy
        do ib = 1, nb
            j0 = 3*(ib - 1)
            do o = max(-1, 1 - ib), min(1, nb - ib)
                do c = 1, 3
                    r = 6 - (c + 3*o)
                    self%kblk(1, c, o, ib) = k(r + 1, j0 + 3*o + c)
                    self%kblk(2, c, o, ib) = k(r + 2, j0 + 3*o + c)
                    self%kblk(3, c, o, ib) = k(r + 3, j0 + 3*o + c)
                end do
            end do
        end do
    end subroutine block3_set_k

    !> Factor the n x n matrix a (compact band storage, kl = ku = 5, n = 3 nb), which the
    !! caller has found block tridiagonal (block_tridiagonal), after set_k for the same n.
    !! info = 0: done; j > 0: D'_j singular or not finite.
    pure subroutine block3_factor(self, n, a, info)
        class(block3_t), intent(inout) :: self
        integer, intent(in) :: n
        real(wp), intent(in) :: a(11, n)
        integer, intent(out) :: info
        ! dv: D'^{-1} of the block row in hand, kept into the next one; u, uprev: U of
        ! this row and of the last
        real(wp) :: d(3, 3), lb(3, 3), lf(3, 3), dv(3, 3), u(3, 3), uprev(3, 3)
        integer :: nb, ib, r, c, j0
        logical :: ok

        nb = n/3
        info = 0
        do ib = 1, nb
            j0 = 3*(ib - 1)
            do c = 1, 3
                do r = 1, 3
                    d(r, c) = a(6 + r - c, j0 + c)
                end do
            end do
            if (ib < nb) then
                do c = 1, 3
                    do r = 1, 3
                        u(r, c) = a(6 + r - (c + 3), j0 + 3 + c)
                    end do
                end do
            end if
            if (ib > 1) then
                do c = 1, 3
                    do r = 1, 3
                        lb(r, c) = a(6 + (r + 3) - c, j0 - 3 + c)
                    end do
                end do
                call mul3(lb, dv, lf)
                self%lfac(1:3, :, ib) = lf
                call mul3(lf, uprev, lb)
                d = d - lb
            end if
            call invert3(d, dv, ok)
            if (.not. ok) then
                info = ib
                return
            end if
            self%dinv(1:3, :, ib) = dv
            if (ib < nb) then
                call mul3(dv, u, lb)
                self%wblk(1:3, :, ib) = lb
                uprev = u
            end if
        end do
    end subroutine block3_factor

    !> No entry of the band matrix a (compact band storage, kl = ku = 5) outside the block
    !! tridiagonal of 3 x 3 blocks: row i of block I against column j of block I +- 2
    !! (within 5 of the diagonal).
    pure logical function block_tridiagonal(n, a) result(yes)
        integer, intent(in) :: n
        real(wp), intent(in) :: a(11, n)
        integer :: j0, c, r
        yes = .false.
        do j0 = 0, n - 1, 3
            do c = 1, 3
                do r = max(1, j0 + c - 5), j0 - 3
                    if (a(6 + r - (j0 + c), j0 + c) /= 0.0_wp) return
                end do
                do r = j0 + 7, min(n, j0 + c + 5)
                    if (a(6 + r - (j0 + c), j0 + c) /= 0.0_wp) return
                end do
            end do
        end do
        yes = .true.
    end function block_tridiagonal

    !> b <- A^{-1} b with the factors of block3_factor.
    pure subroutine block3_solve(self, b)
        class(block3_t), intent(in) :: self
        real(wp), intent(inout) :: b(:)
        call forward(self%nb, self%lfac, self%dinv, b)
        call backward(self%nb, self%wblk, b)
    end subroutine block3_solve

    !> b <- A^{-1} (b + g K x) with the factors and the K blocks of block3_factor: the
    !! product folded into the forward sweep (one pass over b instead of two).
    pure subroutine block3_solve_plus_product(self, g, x, b)
        class(block3_t), intent(in) :: self
        real(wp), intent(in) :: g
        real(wp), intent(in) :: x(:)
        real(wp), intent(inout) :: b(:)
        call forward_plus_product(self%nb, self%kblk, self%lfac, self%dinv, g, x, b)
        call backward(self%nb, self%wblk, b)
    end subroutine block3_solve_plus_product

    ! The sweeps take the blocks as explicit-shape arrays (b and x as (3, nb)): their
    ! addresses and strides then stay in registers through the loop. Each sweep is a chain
    ! (block i needs block i - 1's result): the forward sweep leaves c_i = D'_i^{-1} z_i in
    ! b (off the chain), so that a step of the backward chain is one block product,
    ! x_i = c_i - W_i x_{i+1}, not two.

    !> The forward sweep: z_i = b_i - L'_i z_{i-1}; b_i <- D'_i^{-1} z_i.
    pure subroutine forward(nb, lfac, dinv, b)
        integer, intent(in) :: nb
        real(wp), intent(in) :: lfac(4, 3, nb), dinv(4, 3, nb)
        real(wp), intent(inout) :: b(3, nb)
        real(wp) :: z(3), p(4), q(4)
        integer :: ib
        z = b(:, 1)
        do ib = 1, nb
            if (ib > 1) then
                q = lfac(:, 1, ib)*z(1) + lfac(:, 2, ib)*z(2) + lfac(:, 3, ib)*z(3)
                z = b(:, ib) - q(1:3)
            end if
            p = dinv(:, 1, ib)*z(1) + dinv(:, 2, ib)*z(2) + dinv(:, 3, ib)*z(3)
            b(:, ib) = p(1:3)
        end do
    end subroutine forward

    !> The forward sweep of b + g K x: z_i = b_i + g (K x)_i - L'_i z_{i-1};
    !! b_i <- D'_i^{-1} z_i.
    pure subroutine forward_plus_product(nb, kblk, lfac, dinv, g, x, b)
        integer, intent(in) :: nb
        real(wp), intent(in) :: kblk(4, 3, -1:1, nb), lfac(4, 3, nb), dinv(4, 3, nb)
        real(wp), intent(in) :: g
        real(wp), intent(in) :: x(3, nb)
        real(wp), intent(inout) :: b(3, nb)
        real(wp) :: z(3), p(4), q(4)
        integer :: ib
        z = 0.0_wp
        do ib = 1, nb
            ! p = K_{i,i-1} x_{i-1} + K_ii x_i + K_{i,i+1} x_{i+1}
            p = kblk(:, 1, 0, ib)*x(1, ib) + kblk(:, 2, 0, ib)*x(2, ib) &
                + kblk(:, 3, 0, ib)*x(3, ib)
            if (ib > 1) p = p + (kblk(:, 1, -1, ib)*x(1, ib - 1) &
                                 + kblk(:, 2, -1, ib)*x(2, ib - 1) &
                                 + kblk(:, 3, -1, ib)*x(3, ib - 1))
            if (ib < nb) p = p + (kblk(:, 1, 1, ib)*x(1, ib + 1) &
                                  + kblk(:, 2, 1, ib)*x(2, ib + 1) &
                                  + kblk(:, 3, 1, ib)*x(3, ib + 1))
            if (ib > 1) then
                q = lfac(:, 1, ib)*z(1) + lfac(:, 2, ib)*z(2) + lfac(:, 3, ib)*z(3)
                z = (b(:, ib) + g*p(1:3)) - q(1:3)
            else
                z = b(:, ib) + g*p(1:3)
            end if
            p = dinv(:, 1, ib)*z(1) + dinv(:, 2, ib)*z(2) + dinv(:, 3, ib)*z(3)
            b(:, ib) = p(1:3)
        end do
    end subroutine forward_plus_product

    !> The backward sweep: x_i = c_i - W_i x_{i+1}, b holding c on entry. x_{i+1} is kept
    !! as three scalars and each row of W_i x_{i+1} is summed on its own (the same
    !! operations in the same order as the column form): the chain from one block to the
    !! next is then a product and three sums, without moving x between the lanes of a vector
    !! (about a fifth less time than the column form at n = 100).
    pure subroutine backward(nb, wblk, b)
        integer, intent(in) :: nb
        real(wp), intent(in) :: wblk(4, 3, nb)
        real(wp), intent(inout) :: b(3, nb)
        real(wp) :: x1, x2, x3, t1, t2, t3
        integer :: ib
        x1 = b(1, nb)
        x2 = b(2, nb)
        x3 = b(3, nb)
        do ib = nb - 1, 1, -1
            t1 = b(1, ib) - row3(wblk(:, :, ib), 1, x1, x2, x3)
            t2 = b(2, ib) - row3(wblk(:, :, ib), 2, x1, x2, x3)
            t3 = b(3, ib) - row3(wblk(:, :, ib), 3, x1, x2, x3)
            x1 = t1
            x2 = t2
            x3 = t3
            b(1, ib) = x1
            b(2, ib) = x2
            b(3, ib) = x3
        end do
    end subroutine backward

    !> Row r of the block a (stored with a fourth row of zeros) times (v1, v2, v3):
    !! a(r, 1) v1 + a(r, 2) v2 + a(r, 3) v3, in that order (lane r of the column form).
    pure real(wp) function row3(a, r, v1, v2, v3) result(s)
        real(wp), intent(in) :: a(4, 3)
        integer, intent(in) :: r
        real(wp), intent(in) :: v1, v2, v3
        s = a(r, 1)*v1 + a(r, 2)*v2 + a(r, 3)*v3
    end function row3

    !> c = a b for 3 x 3 matrices, written out.
    pure subroutine mul3(a, b, c)
        real(wp), intent(in) :: a(3, 3), b(3, 3)
        real(wp), intent(out) :: c(3, 3)
        integer :: j
        do j = 1, 3
            c(:, j) = a(:, 1)*b(1, j) + a(:, 2)*b(2, j) + a(:, 3)*b(3, j)
        end do
    end subroutine mul3

    !> ainv = a^{-1} = adj(a)/det(a) (the cofactors written out); ok = .false. when det(a)
    !! is zero or the inverse is not finite. Each cofactor and each term of det takes one
    !! entry from each of the rows involved, so scaling a row (the rope's rotational and
    !! translational rows differ by orders of magnitude, e.g. about 6/dl in the neighbours'
    !! translation columns) scales them exactly and costs no accuracy: the
    !! result is as good as for the equilibrated block. It is a short chain of operations
    !! with no branch, where the factorization spent its time in Gauss-Jordan's pivot
    !! searches and row exchanges, block after dependent block.
    pure subroutine invert3(a, ainv, ok)
        real(wp), intent(in) :: a(3, 3)
        real(wp), intent(out) :: ainv(3, 3)
        logical, intent(out) :: ok
        real(wp) :: c11, c12, c13, det, r
        c11 = a(2, 2)*a(3, 3) - a(2, 3)*a(3, 2)
        c12 = a(2, 3)*a(3, 1) - a(2, 1)*a(3, 3)
        c13 = a(2, 1)*a(3, 2) - a(2, 2)*a(3, 1)
        det = a(1, 1)*c11 + a(1, 2)*c12 + a(1, 3)*c13
        ok = .false.
        ainv = 0.0_wp
        if (.not. abs(det) > 0.0_wp) return
        r = 1.0_wp/det
        ainv(1, 1) = c11*r
        ainv(2, 1) = c12*r
        ainv(3, 1) = c13*r
        ainv(1, 2) = (a(1, 3)*a(3, 2) - a(1, 2)*a(3, 3))*r
        ainv(2, 2) = (a(1, 1)*a(3, 3) - a(1, 3)*a(3, 1))*r
        ainv(3, 2) = (a(1, 2)*a(3, 1) - a(1, 1)*a(3, 2))*r
        ainv(1, 3) = (a(1, 2)*a(2, 3) - a(1, 3)*a(2, 2))*r
        ainv(2, 3) = (a(1, 3)*a(2, 1) - a(1, 1)*a(2, 3))*r
        ainv(3, 3) = (a(1, 1)*a(2, 2) - a(1, 2)*a(2, 1))*r
        ok = all(ieee_is_finite(ainv))
    end subroutine invert3
end module ropedyn_block3
