!> The Newton iteration matrix M - h*beta*J of implicit multistep methods, with LAPACK
!! dense (dgetrf/dgetrs) or band (dgbtrf/dgbtrs) factorization.
!!
!! The Jacobian J = dF/dy of the problem's implicit form M(t, y) y' = F(t, y) is kept
!! between factorizations, so that a new h*beta costs a factorization but no new
!! Jacobian. J is analytic when the problem supplies it, else difference quotients of F
!! (a band Jacobian by column groups of width ml + mu + 1: one F evaluation per group).
module ropedyn_iteration_matrix
    use ropedyn_kinds, only: wp, i8
    use ropedyn_problem, only: problem_t, STATUS_OK, STATUS_RECOVERABLE
    implicit none
    private
    public :: iteration_matrix_t

    type :: iteration_matrix_t
        private
        integer :: n = 0, ml = 0, mu = 0
        logical :: dense = .false.
        logical :: mass = .false.             !< the problem has a mass matrix
        real(wp), allocatable :: jac(:, :)    !< J in compact band storage (row mu+1+i-j)
        real(wp), allocatable :: mb(:, :)     !< M in compact band storage (work)
        real(wp), allocatable :: lu(:, :)     !< factors (dense n x n or band 2ml+mu+1 x n)
        integer, allocatable :: ipiv(:)
        real(wp), allocatable :: f0(:), f1(:), ywork(:)
        logical, public :: factored = .false.
        real(wp), public :: hbeta = 0.0_wp    !< h*beta of the current factorization
    contains
        procedure :: setup => matrix_setup
        procedure :: evaluate_jacobian => matrix_evaluate_jacobian
        procedure :: factor => matrix_factor
        procedure :: solve => matrix_solve
        procedure :: mass_times => matrix_mass_times
        procedure :: is_dense => matrix_is_dense
    end type iteration_matrix_t

    interface
        subroutine dgetrf(m, n, a, lda, ipiv, info)
            import :: wp
            integer, intent(in) :: m, n, lda
            real(wp), intent(inout) :: a(lda, *)
            integer, intent(out) :: ipiv(*), info
        end subroutine dgetrf
        subroutine dgetrs(trans, n, nrhs, a, lda, ipiv, b, ldb, info)
            import :: wp
            character, intent(in) :: trans
            integer, intent(in) :: n, nrhs, lda, ldb, ipiv(*)
            real(wp), intent(in) :: a(lda, *)
            real(wp), intent(inout) :: b(ldb, *)
            integer, intent(out) :: info
        end subroutine dgetrs
        subroutine dgbtrf(m, n, kl, ku, ab, ldab, ipiv, info)
            import :: wp
            integer, intent(in) :: m, n, kl, ku, ldab
            real(wp), intent(inout) :: ab(ldab, *)
            integer, intent(out) :: ipiv(*), info
        end subroutine dgbtrf
        subroutine dgbtrs(trans, n, kl, ku, nrhs, ab, ldab, ipiv, b, ldb, info)
            import :: wp
            character, intent(in) :: trans
            integer, intent(in) :: n, kl, ku, nrhs, ldab, ldb, ipiv(*)
            real(wp), intent(in) :: ab(ldab, *)
            real(wp), intent(inout) :: b(ldb, *)
            integer, intent(out) :: info
        end subroutine dgbtrs
    end interface

contains

    !> Storage for an n x n problem with bandwidths (ml, mu); dense storage is used when
    !! the band is nearly full (then the band LU has no advantage).
    subroutine matrix_setup(self, problem)
        class(iteration_matrix_t), intent(inout) :: self
        class(problem_t), intent(in) :: problem
        self%n = problem%size()
        call problem%bandwidths(self%ml, self%mu)
        self%ml = min(self%ml, self%n - 1)
        self%mu = min(self%mu, self%n - 1)
        self%dense = 2*self%ml + self%mu + 1 >= self%n
        self%mass = problem%has_mass_matrix()
        if (allocated(self%jac)) deallocate (self%jac, self%lu, self%ipiv, self%f0, self%f1, &
                                             self%ywork)
        if (allocated(self%mb)) deallocate (self%mb)
        allocate (self%jac(self%ml + self%mu + 1, self%n))
        if (self%mass) allocate (self%mb(self%ml + self%mu + 1, self%n))
        if (self%dense) then
            allocate (self%lu(self%n, self%n))
        else
            allocate (self%lu(2*self%ml + self%mu + 1, self%n))
        end if
        allocate (self%ipiv(self%n), self%f0(self%n), self%f1(self%n), self%ywork(self%n))
        self%jac = 0.0_wp
        self%factored = .false.
    end subroutine matrix_setup

    pure logical function matrix_is_dense(self)
        class(iteration_matrix_t), intent(in) :: self
        matrix_is_dense = self%dense
    end function matrix_is_dense

    !> J = dF/dy at (t, y): analytic, or by difference quotients when `differences` is
    !! set. w are the error weights (rtol |y| + atol), h the step size (they scale the
    !! increments as in CVODE's difference-quotient Jacobian). nevals counts the F
    !! evaluations spent.
    subroutine matrix_evaluate_jacobian(self, problem, t, y, w, h, differences, status, &
                                        nevals)
        class(iteration_matrix_t), intent(inout) :: self
        class(problem_t), intent(inout) :: problem
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(in) :: w(:)
        real(wp), intent(in) :: h
        logical, intent(in) :: differences
        integer, intent(out) :: status
        integer(i8), intent(inout) :: nevals
        real(wp) :: inc(self%n), fnorm, min_inc
        integer :: width, group, j, i, n

        self%jac = 0.0_wp
        self%factored = .false.
        if (.not. differences) then
            call problem%implicit_jacobian(t, y, self%jac, self%mu + 1, status)
            return
        end if
        n = self%n
        call problem%implicit_rhs(t, y, self%f0, status)
        nevals = nevals + 1
        if (status /= STATUS_OK) return
        fnorm = sqrt(sum((self%f0/w(1:n))**2)/real(n, wp))
        if (fnorm > 0.0_wp) then
            min_inc = 1000.0_wp*abs(h)*epsilon(1.0_wp)*real(n, wp)*fnorm
        else
            min_inc = 1.0_wp
        end if
        do j = 1, n
            inc(j) = max(sqrt(epsilon(1.0_wp))*abs(y(j)), min_inc*w(j))
        end do
        width = min(self%ml + self%mu + 1, n)
        do group = 1, width
            self%ywork = y(1:n)
            do j = group, n, width
                self%ywork(j) = y(j) + inc(j)
            end do
            call problem%implicit_rhs(t, self%ywork, self%f1, status)
            nevals = nevals + 1
            if (status /= STATUS_OK) return
            do j = group, n, width
                do i = max(1, j - self%mu), min(n, j + self%ml)
                    self%jac(self%mu + 1 + i - j, j) = (self%f1(i) - self%f0(i))/inc(j)
                end do
            end do
        end do
        status = STATUS_OK
    end subroutine matrix_evaluate_jacobian

    !> Factor M(t, y) - hbeta*J (M = I without a mass matrix). status is
    !! STATUS_RECOVERABLE when the matrix is singular.
    subroutine matrix_factor(self, problem, t, y, hbeta, status)
        class(iteration_matrix_t), intent(inout) :: self
        class(problem_t), intent(inout) :: problem
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(in) :: hbeta
        integer, intent(out) :: status
        integer :: i, j, info, n, ml, mu

        n = self%n
        ml = self%ml
        mu = self%mu
        status = STATUS_OK
        self%factored = .false.
        if (self%mass) then
            self%mb = 0.0_wp
            call problem%mass_matrix(t, y, self%mb, mu + 1, status)
            if (status /= STATUS_OK) return
        end if
        self%lu = 0.0_wp
        if (self%dense) then
            do j = 1, n
                do i = max(1, j - mu), min(n, j + ml)
                    self%lu(i, j) = -hbeta*self%jac(mu + 1 + i - j, j)
                    if (self%mass) self%lu(i, j) = self%lu(i, j) + self%mb(mu + 1 + i - j, j)
                end do
                if (.not. self%mass) self%lu(j, j) = self%lu(j, j) + 1.0_wp
            end do
            call dgetrf(n, n, self%lu, n, self%ipiv, info)
        else
            ! dgbtrf storage: (i, j) at row ml + mu + 1 + i - j of 2 ml + mu + 1 rows.
            self%lu(ml + 1:2*ml + mu + 1, :) = -hbeta*self%jac
            if (self%mass) then
                self%lu(ml + 1:2*ml + mu + 1, :) = self%lu(ml + 1:2*ml + mu + 1, :) + self%mb
            else
                self%lu(ml + mu + 1, :) = self%lu(ml + mu + 1, :) + 1.0_wp
            end if
            call dgbtrf(n, n, ml, mu, self%lu, 2*ml + mu + 1, self%ipiv, info)
        end if
        if (info /= 0) then
            status = STATUS_RECOVERABLE
            return
        end if
        self%factored = .true.
        self%hbeta = hbeta
    end subroutine matrix_factor

    !> b <- (M - hbeta J)^{-1} b with the current factors.
    subroutine matrix_solve(self, b)
        class(iteration_matrix_t), intent(inout) :: self
        real(wp), intent(inout) :: b(:)
        integer :: info
        if (self%dense) then
            call dgetrs('N', self%n, 1, self%lu, self%n, self%ipiv, b, self%n, info)
        else
            call dgbtrs('N', self%n, self%ml, self%mu, 1, self%lu, 2*self%ml + self%mu + 1, &
                        self%ipiv, b, self%n, info)
        end if
    end subroutine matrix_solve

    !> mv = M(t, y) v.
    subroutine matrix_mass_times(self, problem, t, y, v, mv, status)
        class(iteration_matrix_t), intent(inout) :: self
        class(problem_t), intent(inout) :: problem
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(in) :: v(:)
        real(wp), intent(out) :: mv(:)
        integer, intent(out) :: status
        integer :: i, j
        if (.not. self%mass) then
            mv = v(1:self%n)
            status = STATUS_OK
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
