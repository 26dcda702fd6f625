!> The first-order path of the Newton iteration matrix (ropedyn_iteration_matrix): J = dF/dy
!! over all unknowns (analytic, or difference quotients of F by column groups of the band),
!! M - g J (or I - g J) factored with LAPACK, band or dense, and its solve.
submodule (ropedyn_iteration_matrix) ropedyn_iteration_matrix_first
    implicit none

contains

    !> (Re)allocate the first-order storage (empty unless `needed`).
    module procedure setup_first_order
        integer :: n
        n = self%n
        if (allocated(self%jac)) deallocate (self%jac, self%lu, self%ipiv, self%ywork, self%f1)
        if (allocated(self%mb)) deallocate (self%mb)
        if (.not. needed) n = 0
        self%dense = factored_dense(self%n, self%ml, self%mu)
        allocate (self%jac(self%ml + self%mu + 1, n))
        if (self%mass) then
            allocate (self%mb(self%ml + self%mu + 1, n))
            self%mb = 0.0_wp
        end if
        if (self%dense) then
            allocate (self%lu(n, n))
        else
            allocate (self%lu(2*self%ml + self%mu + 1, n))
        end if
        allocate (self%ipiv(n), self%f1(n), self%ywork(n))
        if (allocated(self%f0)) deallocate (self%f0)
        allocate (self%f0(n))
        self%jac = 0.0_wp
    end procedure setup_first_order

    !> J = dF/dy over all unknowns (first-order path).
    module procedure first_order_jacobian
        real(wp) :: inc(self%n), fnorm, min_inc
        integer :: width, group, j, i, n
        logical :: analytic

        self%jac = 0.0_wp
        if (self%implicit_form) then
            analytic = problem%has_implicit_jacobian()
        else
            analytic = problem%has_jacobian()
        end if
        if (present(differences)) analytic = analytic .and. .not. differences
        if (analytic .and. .not. self%fd_jacobian) then
            if (self%implicit_form) then
                call problem%implicit_jacobian(t, y, self%jac, self%mu + 1, status)
            else
                call problem%jacobian(t, y, self%jac, self%mu + 1, status)
            end if
            return
        end if
        n = self%n
        call form_rhs(y, self%f0)
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
            call form_rhs(self%ywork, self%f1)
            nevals = nevals + 1
            if (status /= STATUS_OK) return
            do j = group, n, width
                do i = max(1, j - self%mu), min(n, j + self%ml)
                    self%jac(self%mu + 1 + i - j, j) = (self%f1(i) - self%f0(i))/inc(j)
                end do
            end do
        end do
        status = STATUS_OK
    contains
        subroutine form_rhs(yy, ff)
            real(wp), intent(in) :: yy(:)
            real(wp), intent(out) :: ff(:)
            if (self%implicit_form) then
                call problem%implicit_rhs(t, yy, ff, status)
            else
                call problem%rhs(t, yy, ff, status)
            end if
        end subroutine form_rhs
    end procedure first_order_jacobian

    !> The first-order matrix M(t, y) - g J, factored.
    module procedure factor_first_order
        integer :: i, j, info, n, ml, mu

        n = self%n
        ml = self%ml
        mu = self%mu
        status = STATUS_OK
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
        if (info /= 0) status = STATUS_RECOVERABLE
    end procedure factor_first_order

    module procedure solve_first_order
        integer :: info
        if (self%dense) then
            call dgetrs('N', self%n, 1, self%lu, self%n, self%ipiv, b, self%n, info)
        else
            call dgbtrs('N', self%n, self%ml, self%mu, 1, self%lu, 2*self%ml + self%mu + 1, &
                        self%ipiv, b, self%n, info)
        end if
    end procedure solve_first_order
end submodule ropedyn_iteration_matrix_first
