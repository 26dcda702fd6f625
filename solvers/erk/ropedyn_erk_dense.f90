!> Dense output and quadratures of the explicit Runge-Kutta integration (ropedyn_erk): the
!! solution between step points (the pair's own continuous extension, or the cubic Hermite
!! interpolant), and the quadratures integrated from their right-hand side g at the
!! accepted step points only (the cubic through the last four values of g, integrated by
!! two-point Gauss-Legendre).
submodule (ropedyn_erk) ropedyn_erk_dense
    implicit none

contains

    !> g at the new step point and the increment of the quadratures over the step: the
    !! integral of the polynomial through the last (up to) four values of g.
    module procedure accept_quadrature
        integer :: j
        if (self%nqh == 4) then
            do j = 0, 2
                self%gq(:, j) = self%gq(:, j + 1)
                self%tq(j) = self%tq(j + 1)
            end do
            self%nqh = 3
        end if
        call self%problem%quad_rhs(self%t, self%y, self%gq(:, self%nqh), status)
        if (status /= STATUS_OK .or. .not. all(ieee_is_finite(self%gq(:, self%nqh)))) then
            if (status == STATUS_OK) status = STATUS_FATAL
            return
        end if
        self%tq(self%nqh) = self%t
        self%nqh = self%nqh + 1
        self%yq_old = self%yq
        self%yq = self%yq_old + self%quad_integral(self%t_old, self%t)
    end procedure accept_quadrature

    !> Integral from a to b (within the last step) of the polynomial through the
    !! quadrature history, by two-point Gauss-Legendre (exact for cubics).
    module procedure quad_integral
        real(wp) :: x(2), lj
        integer :: g, i, j, m
        m = self%nqh
        x = 0.5_wp*(a + b) + [-0.5_wp, 0.5_wp]*(b - a)/sqrt(3.0_wp)
        q = 0.0_wp
        do g = 1, 2
            do j = 0, m - 1
                lj = 1.0_wp
                do i = 0, m - 1
                    if (i /= j) lj = lj*(x(g) - self%tq(i))/(self%tq(j) - self%tq(i))
                end do
                q = q + (0.5_wp*(b - a)*lj)*self%gq(:, j)
            end do
        end do
    end procedure quad_integral

    !> The solution at tt within the last accepted step (t_old .. t).
    module procedure dense
        real(wp) :: th, th1, h
        integer :: j
        if (tt >= self%t) then
            y = self%y
            if (self%nq > 0) yq(1:self%nq) = self%yq
            return
        end if
        h = self%h_old
        th = (tt - self%t_old)/h
        th1 = 1.0_wp - th
        ! y(th) = y0 + th (dy + th1 (bspl + th (dy - h f1 - bspl + th1 r5))),
        ! dy = y1 - y0, bspl = h f0 - dy; r5 = 0 gives the cubic Hermite interpolant
        associate (f0 => self%k(:, 1), f1 => self%k(:, self%s), y0 => self%y_old, &
                   y1 => self%y)
            if (self%tab%dp5_dense) then
                y = 0.0_wp
                do j = 1, self%s
                    if (self%tab%d(j) /= 0.0_wp) y = y + (h*self%tab%d(j))*self%k(:, j)
                end do
                y = y0 + th*((y1 - y0) + th1*((h*f0 - (y1 - y0)) + th*(((y1 - y0) - h*f1 &
                    - (h*f0 - (y1 - y0))) + th1*y)))
            else
                y = y0 + th*((y1 - y0) + th1*((h*f0 - (y1 - y0)) + th*((y1 - y0) - h*f1 &
                    - (h*f0 - (y1 - y0)))))
            end if
        end associate
        if (self%nq > 0) yq(1:self%nq) = self%yq_old + self%quad_integral(self%t_old, tt)
    end procedure dense
end submodule ropedyn_erk_dense
