!> The MEBDF history: the first step size, the error norm, rescaling the backward
!! differences to a new step size, and the dense output between steps.
submodule (ropedyn_mebdf) ropedyn_mebdf_history
    implicit none

contains

    module procedure interpolate
        real(wp) :: s, term
        integer :: j
        z = self%dif(:, 0)
        if (tt == self%t .or. self%h_used == 0.0_wp) return
        s = (tt - self%t)/self%h_used
        term = 1.0_wp
        do j = 1, self%k + 1
            term = term*(s + real(j - 1, wp))/real(j, wp)
            z = z + term*self%dif(:, j)
        end do
    end procedure interpolate

    module procedure initial_slope
        if (self%problem%has_mass_matrix()) then
            call self%problem%implicit_rhs(t, z(1:self%n), slope(1:self%n), status)
            self%counters%rhs_evals = self%counters%rhs_evals + 1
            if (status /= STATUS_OK) return
            call self%matrix%solve_mass(self%problem, t, z(1:self%n), slope(1:self%n), status)
            self%counters%lin_setups = self%counters%lin_setups + 1
            if (status /= STATUS_OK) return
        else
            call self%problem%rhs(t, z(1:self%n), slope(1:self%n), status)
            self%counters%rhs_evals = self%counters%rhs_evals + 1
            if (status /= STATUS_OK) return
        end if
        if (self%nq > 0) call self%problem%quad_rhs(t, z(1:self%n), slope(self%n + 1:), status)
    end procedure initial_slope

    module procedure initial_step
        real(wp) :: y0(self%nt), yp0(self%nt), yp1(self%nt), ytmp(self%nt)
        real(wp) :: hlb, hub, hg, hnew, ypnorm, yddnorm
        integer :: status, iter

        y0 = self%dif(:, 0)
        call self%initial_slope(self%t, y0, yp0, status)
        if (status /= STATUS_OK) then
            call make_error(err, ERR_SOLVER, 'mebdf failed at the initial time: the '// &
                            'right-hand side could not be evaluated at the initial state')
            return
        end if
        self%w = self%options%rtol*abs(y0) + self%atol
        self%wi = 1.0_wp/self%w
        ypnorm = self%wnorm(yp0)
        hlb = 100.0_wp*epsilon(1.0_wp)*max(abs(self%t), abs(self%t + span))
        hub = 0.1_wp*span
        if (ypnorm*hub > 1.0_wp) hub = 1.0_wp/ypnorm
        hg = sqrt(hlb*hub)
        if (hub < hlb) then
            ! fast initial change near a large time (CVODE's rule): the geometric mean
            self%h = hg
            self%h_used = 0.0_wp
            self%dif(:, 1) = self%h*yp0
            self%dif(:, 2:) = 0.0_wp
            self%k = 1
            self%steps_at_h = 0
            return
        end if
        hnew = hub
        do iter = 1, 4
            ytmp = y0 + hg*yp0
            call self%initial_slope(self%t + hg, ytmp, yp1, status)
            if (status /= STATUS_OK) then
                hg = 0.2_wp*hg
                cycle
            end if
            yddnorm = self%wnorm((yp1 - yp0)/hg)
            if (yddnorm*hub*hub > 2.0_wp*self%coef(1)%tq) then
                hnew = sqrt(2.0_wp*self%coef(1)%tq/yddnorm)
            else
                hnew = hub
            end if
            if (hnew > 0.5_wp*hg .and. hnew < 2.0_wp*hg) exit
            hg = hnew
        end do
        self%h = min(max(0.5_wp*hnew, hlb), hub)
        self%h_used = 0.0_wp
        self%dif(:, 1) = self%h*yp0
        self%dif(:, 2:) = 0.0_wp
        self%k = 1
        self%steps_at_h = 0
    end procedure initial_step

    module procedure wnorm
        integer :: n, nt
        n = self%n
        nt = self%nt
        wnorm = sqrt(sum_scaled_squares(v(1:n), self%wi(1:n))/real(n, wp))
        if (self%nq > 0) wnorm = max(wnorm, sqrt(sum_scaled_squares(v(n + 1:nt), &
                                                 self%wi(n + 1:nt))/real(self%nq, wp)))
    end procedure wnorm

    module procedure rescale
        real(wp) :: rmat(kk, kk), umat(kk, kk), ru(kk, kk), tmp(self%nt, kk)
        integer :: i, j
        do j = 1, kk
            rmat(1, j) = -real(j, wp)*ratio
            umat(1, j) = -real(j, wp)
            do i = 2, kk
                rmat(i, j) = rmat(i - 1, j)*(real(i - 1, wp) - real(j, wp)*ratio)/real(i, wp)
                umat(i, j) = umat(i - 1, j)*(real(i - 1, wp) - real(j, wp))/real(i, wp)
            end do
        end do
        ru = matmul(rmat, umat)
        tmp = matmul(self%dif(:, 1:kk), ru)
        self%dif(:, 1:kk) = tmp
        self%h = self%h*ratio
    end procedure rescale
end submodule ropedyn_mebdf_history
