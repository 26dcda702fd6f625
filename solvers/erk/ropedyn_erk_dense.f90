!> Dense output and quadratures of the explicit Runge-Kutta integration (ropedyn_erk): the
!! solution between step points (the pair's own continuous extension, or the cubic Hermite
!! interpolant), and the quadratures' increment and error estimate over a step from
!! their right-hand side g at the stages; `combine`, the sum over a table's stages that
!! these and ropedyn_erk's stages and error estimate are made of.
submodule (ropedyn_erk) ropedyn_erk_dense
    implicit none

contains

    !> The quadratures' increment over the step just computed, dq = h sum b_i g_i (into
    !! self%dq; the estimate into self%eq), and
    !! the weighted RMS norm of its error estimate h sum e_i g_i (weights rtol
    !! max(|yq|, |yq + dq|) + atol, as CVODE's for its quadratures).
    module procedure quad_step
        call combine(self%tab%b(1:self%s), h, self%gk, self%dq)
        call combine(self%tab%e(1:self%s), h, self%gk, self%eq)
        errq = sqrt(sum((self%eq/(self%options%rtol*max(abs(self%yq), abs(self%yq + self%dq)) &
                                  + self%options%atol))**2)/self%nq)
    end procedure quad_step

    module procedure combine
        ! fixed size: automatic arrays would be allocated on the heap at every call
        real(wp) :: w(ERK_MAX_STAGES)
        integer :: idx(ERK_MAX_STAGES), j, m
        ! the nonzero terms, each weighed by h; then one fused pass over the components
        ! per stage (the sum kept left to right: ((base + w1 k1) + w2 k2) + ...)
        m = 0
        do j = 1, size(c)
            if (c(j) == 0.0_wp) cycle
            m = m + 1
            idx(m) = j
            w(m) = h*c(j)
        end do
        if (present(base)) then
            select case (m)
            case (0)
                out = base
            case (1)
                out = base + w(1)*k(:, idx(1))
            case (2)
                out = base + w(1)*k(:, idx(1)) + w(2)*k(:, idx(2))
            case (3)
                out = base + w(1)*k(:, idx(1)) + w(2)*k(:, idx(2)) + w(3)*k(:, idx(3))
            case (4)
                out = base + w(1)*k(:, idx(1)) + w(2)*k(:, idx(2)) + w(3)*k(:, idx(3)) &
                      + w(4)*k(:, idx(4))
            case default
                out = base + w(1)*k(:, idx(1)) + w(2)*k(:, idx(2)) + w(3)*k(:, idx(3)) &
                      + w(4)*k(:, idx(4))
                do j = 5, m
                    call axpy(w(j), k(:, idx(j)), out)
                end do
            end select
        else
            select case (m)
            case (0)
                out = 0.0_wp
            case (1)
                out = w(1)*k(:, idx(1))
            case (2)
                out = w(1)*k(:, idx(1)) + w(2)*k(:, idx(2))
            case (3)
                out = w(1)*k(:, idx(1)) + w(2)*k(:, idx(2)) + w(3)*k(:, idx(3))
            case (4)
                out = w(1)*k(:, idx(1)) + w(2)*k(:, idx(2)) + w(3)*k(:, idx(3)) &
                      + w(4)*k(:, idx(4))
            case default
                out = w(1)*k(:, idx(1)) + w(2)*k(:, idx(2)) + w(3)*k(:, idx(3)) &
                      + w(4)*k(:, idx(4)) + w(5)*k(:, idx(5))
                do j = 6, m
                    call axpy(w(j), k(:, idx(j)), out)
                end do
            end select
        end if
    end procedure combine

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
                y = hermite(y0, y1, f0, f1, h, th)
            end if
        end associate
        ! the quadratures: the cubic Hermite interpolant of yq and g at both ends
        if (self%nq > 0) yq(1:self%nq) = hermite(self%yq_old, self%yq, self%gk(:, 1), &
                                                 self%gk(:, self%s), h, th)
    end procedure dense

    !> The cubic Hermite interpolant at th (0 .. 1) of a step of size h from a0 to a1 with
    !! slopes f0 and f1 at its ends.
    elemental real(wp) function hermite(a0, a1, f0, f1, h, th) result(a)
        real(wp), intent(in) :: a0, a1, f0, f1, h, th
        real(wp) :: th1
        th1 = 1.0_wp - th
        a = a0 + th*((a1 - a0) + th1*((h*f0 - (a1 - a0)) + th*((a1 - a0) - h*f1 &
            - (h*f0 - (a1 - a0)))))
    end function hermite

    !> y = y + a x.
    pure subroutine axpy(a, x, y)
        real(wp), intent(in) :: a
        real(wp), intent(in), contiguous :: x(:)
        real(wp), intent(inout), contiguous :: y(:)
        y = y + a*x
    end subroutine axpy
end submodule ropedyn_erk_dense
