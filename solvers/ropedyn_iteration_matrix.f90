!> The Newton iteration matrix of implicit multistep methods, M - g J for the implicit form
!! M(t, y) y' = F(t, y) (MEBDF) or I - g J for y' = f(t, y) (CVODE), with g = h beta (MEBDF)
!! or CVODE's gamma, factored with LAPACK.
!!
!! Two paths:
!! - **reduced** (problems with second-order structure, ropedyn_problem): the blocks
!!   K = dF_v/dq, C = dF_v/dv and the mass block M_v are kept between Jacobian evaluations;
!!   a new g costs the matrix M_v - g C - g^2 K of size(pos) unknowns (half the system) and
!!   its factorization; a solve of (M - g J) x = b is
!!       (M_v - g C - g^2 K) x_v = b_v + g K b_q,   x_q = b_q + g x_v.
!!   The blocks are the problem's `second_order_blocks` of the form asked for (both models
!!   have them in both forms; the MPP's implicit ones hold the d(M a)/dq term). When a
!!   problem has none for the implicit form (STATUS_FATAL), they are difference quotients
!!   of the implicit F, taken as the first-order path takes them (the term dM/dq v' is left
!!   to the chord iteration, as there), and M_v comes from the mass matrix. Without any
!!   blocks the first-order path is taken.
!! - **first order** (problems without that structure, the stiff test set, or on request):
!!   J = dF/dy over all unknowns, analytic when the problem supplies it, else difference
!!   quotients of F (a band Jacobian by column groups of width ml + mu + 1: one F evaluation
!!   per group).
!! Both: LAPACK band (dgbtrf/dgbtrs), or dense (dgetrf/dgetrs) when the band is nearly full.
module ropedyn_iteration_matrix
    use ropedyn_kinds, only: wp, i8
    use ropedyn_lapack, only: dgetrf, dgetrs, dgbtrf, dgbtrs
    use ropedyn_problem, only: problem_t, STATUS_OK, STATUS_RECOVERABLE, STATUS_FATAL
    use ropedyn_block3, only: block3_t, block_tridiagonal
    use ropedyn_band_lu, only: RFEM_KL, factored_dense, band_lu_factor, band_lu_solve, &
                               band_solve_rfem, band_add_product, full_entry
    implicit none
    private
    public :: iteration_matrix_t
    public :: factored_dense   !< ropedyn_band_lu's, for the CVODE linear solver

    !> Where the reduced blocks come from.
    integer, parameter :: BLOCKS_OWN_FORM = 1     !< the problem's blocks of the form used
    integer, parameter :: BLOCKS_DIFFERENCES = 2  !< difference quotients of the implicit F

    type :: iteration_matrix_t
        private
        integer :: n = 0, ml = 0, mu = 0
        logical :: implicit_form = .true.     !< M - g J of M y' = F (else I - g J of y' = f)
        logical :: mass = .false.             !< the form used has a mass matrix
        logical :: fd_jacobian = .false.      !< difference F even with an analytic Jacobian
        logical :: reduced = .false.          !< the reduced path is in use
        logical :: blocks_seen = .false.      !< the blocks were evaluated successfully once
        integer :: blocks = BLOCKS_OWN_FORM
        ! first-order path (and the mass matrix for `solve_mass` and `mass_times`)
        logical :: dense = .false.
        real(wp), allocatable :: jac(:, :)    !< J in compact band storage (row mu+1+i-j)
        real(wp), allocatable :: mb(:, :)     !< M in compact band storage (work)
        real(wp), allocatable :: lu(:, :)     !< factors (dense n x n or band 2ml+mu+1 x n)
        integer, allocatable :: ipiv(:)
        real(wp), allocatable :: f0(:), f1(:), ywork(:)
        ! reduced path: blocks of np = size(pos) unknowns, bandwidths kl, ku
        integer :: np = 0, kl = 0, ku = 0
        logical :: rdense = .false.
        integer, allocatable :: pos(:), vel(:)
        logical :: vel_contiguous = .false.   !< vel(k) = vel(1) + k - 1
        !> m > 0: y is made of blocks of m positions followed by their m rates (RFEM: x, y,
        !! phi and their rates, element by element); m = 3 is gathered without the index
        !! vectors pos and vel
        integer :: interleave = 0
        real(wp), allocatable :: kb(:, :), cb(:, :), mk(:, :)  !< band (kl+ku+1, np), row ku+1+i-j
        real(wp), allocatable :: rlu(:, :)    !< factors (dense np x np or band 2kl+ku+1 x np)
        integer :: rkv = 0                    !< super-diagonals of the band U actually filled
        !> RFEM (kl = ku = RFEM_KL): the block-tridiagonal factors, used when `use_block3`
        !! (else the band LU: a matrix that is not block tridiagonal, or a singular block)
        type(block3_t) :: blk3
        logical :: block3_pattern = .false.   !< K, C, M_v block tridiagonal (per Jacobian)
        logical :: use_block3 = .false.
        real(wp), allocatable :: ra(:, :)     !< M_v - g C - g^2 K (kl+ku+1, np) for blk3
        integer, allocatable :: ripiv(:)
        real(wp), allocatable :: rq(:), rv(:)
        logical, public :: factored = .false.
        real(wp), public :: hbeta = 0.0_wp    !< g of the current factorization
    contains
        procedure :: setup => matrix_setup
        procedure :: evaluate_jacobian => matrix_evaluate_jacobian
        procedure :: factor => matrix_factor
        procedure :: solve => matrix_solve
        procedure :: solve_mass => matrix_solve_mass
        procedure :: mass_times => matrix_mass_times
        procedure :: is_dense => matrix_is_dense
        procedure :: is_reduced => matrix_is_reduced
        procedure, private :: setup_first_order
        procedure, private :: first_order_jacobian
        procedure, private :: reduced_blocks
        procedure, private :: factor_first_order
        procedure, private :: factor_reduced
        procedure, private :: solve_first_order
        procedure, private :: solve_reduced
    end type iteration_matrix_t

    interface
        ! the first-order path (submodule ropedyn_iteration_matrix_first)
        !> (Re)allocate the first-order storage (empty unless `needed`).
        module subroutine setup_first_order(self, needed)
            class(iteration_matrix_t), intent(inout) :: self
            logical, intent(in) :: needed
        end subroutine setup_first_order
        !> J = dF/dy over all unknowns (first-order path).
        module subroutine first_order_jacobian(self, problem, t, y, w, h, status, nevals, &
                                               differences)
            class(iteration_matrix_t), intent(inout) :: self
            class(problem_t), intent(inout) :: problem
            real(wp), intent(in) :: t
            real(wp), intent(in) :: y(:)
            real(wp), intent(in) :: w(:)
            real(wp), intent(in) :: h
            integer, intent(out) :: status
            integer(i8), intent(inout) :: nevals
            logical, intent(in), optional :: differences   !< difference quotients in any case
        end subroutine first_order_jacobian
        !> The first-order matrix M(t, y) - g J, factored.
        module subroutine factor_first_order(self, problem, t, y, hbeta, status)
            class(iteration_matrix_t), intent(inout) :: self
            class(problem_t), intent(inout) :: problem
            real(wp), intent(in) :: t
            real(wp), intent(in) :: y(:)
            real(wp), intent(in) :: hbeta
            integer, intent(out) :: status
        end subroutine factor_first_order
        module subroutine solve_first_order(self, b)
            class(iteration_matrix_t), intent(inout) :: self
            real(wp), intent(inout) :: b(:)
        end subroutine solve_first_order
    end interface

contains

    !> Storage for the problem's Newton matrix. `implicit_form`: M - g J of the implicit
    !! form (else I - g J of the explicit one). The reduced path is taken when the problem
    !! has second-order structure covering all unknowns, unless `first_order` or
    !! `fd_jacobian` (the blocks are analytic) is set.
    subroutine matrix_setup(self, problem, implicit_form, first_order, fd_jacobian)
        class(iteration_matrix_t), intent(inout) :: self
        class(problem_t), intent(in) :: problem
        logical, intent(in) :: implicit_form
        logical, intent(in) :: first_order
        logical, intent(in) :: fd_jacobian
        integer :: k
        logical :: covered

        self%n = problem%size()
        call problem%bandwidths(self%ml, self%mu)
        self%ml = min(self%ml, self%n - 1)
        self%mu = min(self%mu, self%n - 1)
        self%implicit_form = implicit_form
        self%mass = implicit_form .and. problem%has_mass_matrix()
        self%fd_jacobian = fd_jacobian
        self%factored = .false.
        self%blocks_seen = .false.
        self%blocks = BLOCKS_OWN_FORM
        self%reduced = .false.
        if (allocated(self%pos)) deallocate (self%pos, self%vel)
        if (.not. (first_order .or. fd_jacobian) .and. problem%has_second_order()) then
            call problem%second_order_layout(self%pos, self%vel, self%kl, self%ku)
            self%np = size(self%pos)
            covered = self%np > 0 .and. 2*self%np == self%n .and. size(self%vel) == self%np
            if (covered) then
                ! every unknown exactly once
                self%f0 = [(0.0_wp, k = 1, self%n)]
                self%f0(self%pos) = self%f0(self%pos) + 1.0_wp
                self%f0(self%vel) = self%f0(self%vel) + 1.0_wp
                covered = all(self%f0 == 1.0_wp)
            end if
            self%reduced = covered
            if (covered) self%vel_contiguous = all(self%vel == [(self%vel(1) + k - 1, &
                                                                 k = 1, self%np)])
            self%interleave = 0
            if (covered) self%interleave = interleaved_blocks(self%pos, self%vel)
        end if
        if (allocated(self%kb)) deallocate (self%kb, self%cb, self%mk, self%rlu, self%ripiv, &
                                            self%rq, self%rv)
        if (allocated(self%ra)) deallocate (self%ra)
        if (self%reduced) then
            self%kl = min(max(self%kl, 0), self%np - 1)
            self%ku = min(max(self%ku, 0), self%np - 1)
            self%rdense = factored_dense(self%np, self%kl, self%ku)
            associate (rows => self%kl + self%ku + 1, np => self%np)
                allocate (self%kb(rows, np), self%cb(rows, np), self%mk(rows, np))
                if (self%rdense) then
                    allocate (self%rlu(np, np))
                else
                    allocate (self%rlu(2*self%kl + self%ku + 1, np))
                end if
                allocate (self%ripiv(np), self%rq(np), self%rv(np))
            end associate
            self%kb = 0.0_wp
            self%cb = 0.0_wp
            self%mk = 0.0_wp
        end if
        ! first-order storage: its path, or the mass matrix of the implicit form
        call self%setup_first_order(.not. self%reduced .or. self%mass)
    end subroutine matrix_setup

    pure logical function matrix_is_dense(self)
        class(iteration_matrix_t), intent(in) :: self
        matrix_is_dense = merge(self%rdense, self%dense, self%reduced)
    end function matrix_is_dense

    !> True when the reduced path is in use.
    pure logical function matrix_is_reduced(self)
        class(iteration_matrix_t), intent(in) :: self
        matrix_is_reduced = self%reduced
    end function matrix_is_reduced

    !> The Jacobian at (t, y): the reduced blocks, or J = dF/dy (analytic, or by difference
    !! quotients when the problem has no analytic one or fd_jacobian was asked for). w are the
    !! error weights (rtol |y| + atol), h the step size (they scale the increments as in
    !! CVODE's difference-quotient Jacobian). nevals counts the F evaluations spent.
    subroutine matrix_evaluate_jacobian(self, problem, t, y, w, h, status, nevals)
        class(iteration_matrix_t), intent(inout) :: self
        class(problem_t), intent(inout) :: problem
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(in) :: w(:)
        real(wp), intent(in) :: h
        integer, intent(out) :: status
        integer(i8), intent(inout) :: nevals

        self%factored = .false.
        if (self%reduced) then
            call self%reduced_blocks(problem, t, y, w, h, status, nevals)
            self%block3_pattern = .false.
            if (status == STATUS_OK .and. .not. self%rdense .and. self%kl == RFEM_KL .and. &
                self%ku == RFEM_KL) then
                call self%blk3%set_k(self%np, self%kb, self%block3_pattern)
                self%block3_pattern = self%block3_pattern .and. &
                                      block_tridiagonal(self%np, self%cb) .and. &
                                      block_tridiagonal(self%np, self%mk)
            end if
            if (status /= STATUS_FATAL .or. self%blocks_seen) return
            ! no blocks at all: the first-order path from now on
            self%reduced = .false.
            call self%setup_first_order(.true.)
        end if
        call self%first_order_jacobian(problem, t, y, w, h, status, nevals)
    end subroutine matrix_evaluate_jacobian

    !> K, C, M_v at (t, y) (see the module header); on the first evaluation a problem
    !! without implicit-form blocks switches to difference quotients.
    subroutine reduced_blocks(self, problem, t, y, w, h, status, nevals)
        class(iteration_matrix_t), intent(inout) :: self
        class(problem_t), intent(inout) :: problem
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(in) :: w(:)
        real(wp), intent(in) :: h
        integer, intent(out) :: status
        integer(i8), intent(inout) :: nevals
        integer :: a, b, np, off, ml, mu

        np = self%np
        off = self%ku + 1
        self%kb = 0.0_wp
        self%cb = 0.0_wp
        self%mk = 0.0_wp
        if (self%blocks == BLOCKS_OWN_FORM) then
            call problem%second_order_blocks(t, y, self%implicit_form, self%kb, self%cb, &
                                             self%mk, off, status)
            if (status == STATUS_OK) self%blocks_seen = .true.
            if (status /= STATUS_FATAL .or. self%blocks_seen .or. .not. self%mass) return
            self%blocks = BLOCKS_DIFFERENCES
        end if
        ! difference quotients of the implicit F over all unknowns, then the rate rows
        call self%first_order_jacobian(problem, t, y, w, h, status, nevals, differences=.true.)
        if (status /= STATUS_OK) return
        self%mb = 0.0_wp
        call problem%mass_matrix(t, y, self%mb, self%mu + 1, status)
        if (status /= STATUS_OK) return
        self%blocks_seen = .true.
        ml = self%ml
        mu = self%mu
        do b = 1, np
            do a = max(1, b - self%ku), min(np, b + self%kl)
                self%kb(off + a - b, b) = full_entry(self%jac, ml, mu, self%vel(a), self%pos(b))
                self%cb(off + a - b, b) = full_entry(self%jac, ml, mu, self%vel(a), self%vel(b))
                self%mk(off + a - b, b) = full_entry(self%mb, ml, mu, self%vel(a), self%vel(b))
            end do
        end do
    end subroutine reduced_blocks

    !> Factor the Newton matrix for g = hbeta (M - g J; M = I without a mass matrix).
    !! status is STATUS_RECOVERABLE when the matrix is singular.
    subroutine matrix_factor(self, problem, t, y, hbeta, status)
        class(iteration_matrix_t), intent(inout) :: self
        class(problem_t), intent(inout) :: problem
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(in) :: hbeta
        integer, intent(out) :: status
        self%factored = .false.
        if (self%reduced) then
            call self%factor_reduced(hbeta, status)
        else
            call self%factor_first_order(problem, t, y, hbeta, status)
        end if
        if (status /= STATUS_OK) return
        self%factored = .true.
        self%hbeta = hbeta
    end subroutine matrix_factor

    !> M_v - g C - g^2 K from the kept blocks, factored.
    subroutine factor_reduced(self, g, status)
        class(iteration_matrix_t), intent(inout) :: self
        real(wp), intent(in) :: g
        integer, intent(out) :: status
        integer :: i, j, info, np, kl, ku
        real(wp) :: g2

        np = self%np
        kl = self%kl
        ku = self%ku
        g2 = g*g
        if (self%rdense) then
            do j = 1, np
                self%rlu(1:max(1, j - ku) - 1, j) = 0.0_wp
                do i = max(1, j - ku), min(np, j + kl)
                    self%rlu(i, j) = self%mk(ku + 1 + i - j, j) - g*self%cb(ku + 1 + i - j, j) &
                                     - g2*self%kb(ku + 1 + i - j, j)
                end do
                self%rlu(min(np, j + kl) + 1:np, j) = 0.0_wp
            end do
            call dgetrf(np, np, self%rlu, np, self%ripiv, info)
        else
            self%use_block3 = .false.
            if (self%block3_pattern) then
                if (.not. allocated(self%ra)) allocate (self%ra(kl + ku + 1, np))
                call combine_blocks(size(self%ra), self%mk, self%cb, self%kb, g, g2, self%ra)
                call self%blk3%factor(np, self%ra, info)
                self%use_block3 = info == 0
            end if
            if (.not. self%use_block3) then
                ! dgbtrf storage: (i, j) at row kl + ku + 1 + i - j of 2 kl + ku + 1 rows
                self%rlu(1:kl, :) = 0.0_wp
                self%rlu(kl + 1:, :) = self%mk - g*self%cb - g2*self%kb
                call band_lu_factor(np, kl, ku, self%rlu, self%ripiv, info, self%rkv)
            end if
        end if
        status = merge(STATUS_OK, STATUS_RECOVERABLE, info == 0)
    end subroutine factor_reduced

    !> a = mk - g cb - g2 kb over the m entries of the band storage, as one vector (the
    !! statement on the (kl+ku+1, np) arrays loops over columns of 11 entries: two vectors
    !! and three single entries each).
    pure subroutine combine_blocks(m, mk, cb, kb, g, g2, a)
        integer, intent(in) :: m
        real(wp), intent(in) :: mk(m), cb(m), kb(m), g, g2
        real(wp), intent(out) :: a(m)
        integer :: i
        do i = 1, m
            a(i) = mk(i) - g*cb(i) - g2*kb(i)
        end do
    end subroutine combine_blocks

    !> b <- (M - g J)^{-1} b with the current factors.
    subroutine matrix_solve(self, b)
        class(iteration_matrix_t), intent(inout) :: self
        real(wp), intent(inout) :: b(:)
        if (self%reduced) then
            call self%solve_reduced(b)
        else
            call self%solve_first_order(b)
        end if
    end subroutine matrix_solve

    !> (M_v - g C - g^2 K) x_v = b_v + g K b_q, x_q = b_q + g x_v.
    subroutine solve_reduced(self, b)
        class(iteration_matrix_t), intent(inout) :: self
        real(wp), intent(inout) :: b(:)
        integer :: i, info, np, kl, ku
        real(wp) :: g

        np = self%np
        kl = self%kl
        ku = self%ku
        g = self%hbeta
        if (self%interleave == 3) then
            call split_blocks3(np/3, b, self%rq, self%rv)
        else
            do i = 1, np
                self%rq(i) = b(self%pos(i))
                self%rv(i) = b(self%vel(i))
            end do
        end if
        if (self%rdense) then
            call band_add_product(np, kl, ku, self%kb, g, self%rq, self%rv)
            call dgetrs('N', np, 1, self%rlu, np, self%ripiv, self%rv, np, info)
        else if (self%use_block3) then
            call self%blk3%solve_plus_product(g, self%rq, self%rv)
        else if (kl == RFEM_KL .and. ku == RFEM_KL .and. np > 4*RFEM_KL) then
            call band_solve_rfem(np, self%kb, g, self%rq, self%rlu, self%ripiv, self%rv)
        else
            call band_add_product(np, kl, ku, self%kb, g, self%rq, self%rv)
            call band_lu_solve(np, kl, ku, self%rkv, self%rlu, self%ripiv, self%rv)
        end if
        if (self%interleave == 3) then
            call join_blocks3(np/3, g, self%rq, self%rv, b)
        else
            do i = 1, np
                b(self%vel(i)) = self%rv(i)
                b(self%pos(i)) = self%rq(i) + g*self%rv(i)
            end do
        end if
    end subroutine solve_reduced

    !> m when pos and vel make y of blocks of m positions followed by their m rates
    !! (pos(k) = 2 m (b - 1) + c, vel(k) = pos(k) + m for k = m (b - 1) + c), else 0.
    pure integer function interleaved_blocks(pos, vel) result(m)
        integer, intent(in) :: pos(:), vel(:)
        integer :: k
        m = vel(1) - pos(1)
        if (pos(1) /= 1 .or. m < 1 .or. mod(size(pos), max(m, 1)) /= 0) then
            m = 0
            return
        end if
        do k = 1, size(pos)
            if (pos(k) /= 2*m*((k - 1)/m) + mod(k - 1, m) + 1 .or. vel(k) /= pos(k) + m) then
                m = 0
                return
            end if
        end do
    end function interleaved_blocks

    !> rq, rv = the positions' and the rates' entries of b (nb blocks of three of each).
    !! Written out: as loops over the three, gfortran makes each block a call of memcpy.
    pure subroutine split_blocks3(nb, b, rq, rv)
        integer, intent(in) :: nb
        real(wp), intent(in) :: b(3, 2, nb)
        real(wp), intent(out) :: rq(3, nb), rv(3, nb)
        integer :: ib
        do ib = 1, nb
            rq(1, ib) = b(1, 1, ib)
            rq(2, ib) = b(2, 1, ib)
            rq(3, ib) = b(3, 1, ib)
            rv(1, ib) = b(1, 2, ib)
            rv(2, ib) = b(2, 2, ib)
            rv(3, ib) = b(3, 2, ib)
        end do
    end subroutine split_blocks3

    !> b = (rq + g rv, rv), block by block: the inverse of split_blocks3 for x_q = b_q + g x_v.
    pure subroutine join_blocks3(nb, g, rq, rv, b)
        integer, intent(in) :: nb
        real(wp), intent(in) :: g
        real(wp), intent(in) :: rq(3, nb), rv(3, nb)
        real(wp), intent(out) :: b(3, 2, nb)
        integer :: ib
        do ib = 1, nb
            b(1, 1, ib) = rq(1, ib) + g*rv(1, ib)
            b(2, 1, ib) = rq(2, ib) + g*rv(2, ib)
            b(3, 1, ib) = rq(3, ib) + g*rv(3, ib)
            b(1, 2, ib) = rv(1, ib)
            b(2, 2, ib) = rv(2, ib)
            b(3, 2, ib) = rv(3, ib)
        end do
    end subroutine join_blocks3

    !> b <- M(t, y)^{-1} b (the implicit form's mass matrix, first-order storage); the
    !! Newton matrix must be factored again afterwards. status: STATUS_RECOVERABLE when M
    !! is singular.
    subroutine matrix_solve_mass(self, problem, t, y, b, status)
        class(iteration_matrix_t), intent(inout) :: self
        class(problem_t), intent(inout) :: problem
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(inout) :: b(:)
        integer, intent(out) :: status
        self%factored = .false.
        call self%factor_first_order(problem, t, y, 0.0_wp, status)
        if (status /= STATUS_OK) return
        call self%solve_first_order(b)
    end subroutine matrix_solve_mass

    !> mv = M(t, y) v. With second-order structure M = blockdiag(I, M_v) (the coordinate
    !! rows are q' = v): only the entries of M_v and the coordinates' diagonal are cleared,
    !! filled and used (for the dense MPP a quarter of the full matrix).
    subroutine matrix_mass_times(self, problem, t, y, v, mv, status)
        class(iteration_matrix_t), intent(inout) :: self
        class(problem_t), intent(inout) :: problem
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(in) :: v(:)
        real(wp), intent(out) :: mv(:)
        integer, intent(out) :: status
        integer :: i, j, b, v0, lo, hi
        real(wp) :: x
        if (.not. self%mass) then
            mv = v(1:self%n)
            status = STATUS_OK
            return
        end if
        if (self%reduced .and. self%vel_contiguous) then
            ! the rates are y(v0 + 1 .. v0 + np): M_v's column b is a slice of band column
            ! v0 + b (M_v is within the first-order band: the problem's bandwidths cover M)
            v0 = self%vel(1) - 1
            do b = 1, self%np
                self%mb(self%mu + 1, self%pos(b)) = 0.0_wp
                lo = max(1, b - self%ku)
                hi = min(self%np, b + self%kl)
                self%mb(self%mu + 1 + lo - b:self%mu + 1 + hi - b, v0 + b) = 0.0_wp
            end do
            call problem%mass_matrix(t, y, self%mb, self%mu + 1, status)
            if (status /= STATUS_OK) return
            do b = 1, self%np
                i = self%pos(b)
                mv(i) = self%mb(self%mu + 1, i)*v(i)
            end do
            mv(v0 + 1:v0 + self%np) = 0.0_wp
            do b = 1, self%np
                x = v(v0 + b)
                lo = max(1, b - self%ku)
                hi = min(self%np, b + self%kl)
                mv(v0 + lo:v0 + hi) = mv(v0 + lo:v0 + hi) + &
                    self%mb(self%mu + 1 + lo - b:self%mu + 1 + hi - b, v0 + b)*x
            end do
            return
        end if
        self%mb = 0.0_wp
        call problem%mass_matrix(t, y, self%mb, self%mu + 1, status)
        if (status /= STATUS_OK) return
        mv = 0.0_wp
        do j = 1, self%n
            do i = max(1, j - self%mu), min(self%n, j + self%ml)
                mv(i) = mv(i) + self%mb(self%mu + 1 + i - j, j)*v(j)
            end do
        end do
    end subroutine matrix_mass_times

end module ropedyn_iteration_matrix
