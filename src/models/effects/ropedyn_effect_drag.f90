!> Drag of the surrounding fluid on each body (docs/theory/effects.md, "Drag").
!!
!! With the velocity relative to the fluid v_r = v - u (u a uniform current), split into the
!! tangential part a = e . v_r and the normal part b = n . v_r, a body of length l feels at
!! its centre
!!     F = -(q_n l |b| b + c_n l b) n - (q_t l |a| a + c_t l a) e,
!!     q_n = rho_f C_n d / 2 (projected area d l),  q_t = rho_f C_t pi d / 2 (wetted area),
!! and, for its rotation (the normal velocity xi w along the body integrated over
!! xi in [-l/2, l/2]), the moment M = -q_n l^4/32 |w| w - c_n l^3/12 w.
!! The dissipation rate is -(F . v_r + M w) >= 0; the current does the work F . u.
!! In water with a free surface (`&effects water`) a body feels the drag of its wetted
!! fraction f (ropedyn_wetting): F and M times f, and the derivatives of f in the Jacobian.
module ropedyn_effect_drag
    use ropedyn_kinds, only: wp, PI
    use ropedyn_effect, only: body_effect_t, bodies_t
    use ropedyn_wetting, only: wetting_t, wet_t
    implicit none
    private
    public :: drag_effect_t, drag_effect


    type, extends(body_effect_t) :: drag_effect_t
        private
        real(wp) :: qn = 0.0_wp, qt = 0.0_wp   !< quadratic coefficients per length, kg/m^2
        real(wp) :: cn = 0.0_wp, ct = 0.0_wp   !< linear coefficients per length, N s/m^2
        real(wp) :: u(2) = 0.0_wp              !< current, m/s
        logical :: quadratic = .false., linear = .false., current = .false.
        logical :: wet = .false.               !< only the wetted fraction feels the drag
        type(wetting_t) :: wetting
    contains
        procedure :: name => drag_name
        procedure :: add_forces => drag_add_forces
        procedure :: add_jacobian => drag_add_jacobian
        procedure :: power => drag_power
        procedure :: add_forces_power => drag_add_forces_power
        procedure :: does_work => drag_does_work
    end type drag_effect_t

contains

    !> Drag of a fluid of density rho (kg/m^3) with normal and tangential drag coefficients
    !! cd_n, cd_t (-), linear drag lin_n, lin_t (N s/m^2) and current u (m/s) on bodies of
    !! diameter d (m).
    !! With `wetting`, only the wetted fraction of each body feels it.
    pure function drag_effect(rho, cd_n, cd_t, lin_n, lin_t, u, d, wetting) result(eff)
        real(wp), intent(in) :: rho, cd_n, cd_t, lin_n, lin_t, u(2), d
        type(wetting_t), intent(in), optional :: wetting
        type(drag_effect_t) :: eff
        eff%qn = 0.5_wp*rho*cd_n*d
        eff%qt = 0.5_wp*rho*cd_t*pi*d
        eff%cn = lin_n
        eff%ct = lin_t
        eff%u = u
        eff%quadratic = eff%qn > 0.0_wp .or. eff%qt > 0.0_wp
        eff%linear = eff%cn > 0.0_wp .or. eff%ct > 0.0_wp
        eff%current = any(abs(u) > 0.0_wp)
        eff%wet = present(wetting)
        if (eff%wet) eff%wetting = wetting
    end function drag_effect

    pure function drag_name(self) result(name)
        class(drag_effect_t), intent(in) :: self
        character(len=:), allocatable :: name
        name = 'drag'
    end function drag_name

    pure logical function drag_does_work(self) result(does)
        class(drag_effect_t), intent(in) :: self
        does = self%current
    end function drag_does_work

    !> Length l of body i, its normal nv, and the components a (along its axis e = (cos phi,
    !! sin phi), b%cs) and bb (along nv) of its centre's
    !! velocity relative to the fluid.
    pure subroutine relative_motion(self, b, i, e, l, nv, a, bb)
        class(drag_effect_t), intent(in) :: self
        type(bodies_t), intent(in) :: b
        integer, intent(in) :: i
        real(wp), intent(in) :: e(2)
        real(wp), intent(out) :: l, nv(2), a, bb
        real(wp) :: vr(2)
        l = b%l(i)
        nv = [-e(2), e(1)]
        vr = b%v(:, i) - self%u
        a = dot_product(e, vr)
        bb = dot_product(nv, vr)
    end subroutine relative_motion

    !> Force and moment of body i with axis e (of its wetted fraction, unless `whole`).
    pure subroutine body_drag(self, b, i, e, f, m, whole)
        class(drag_effect_t), intent(in) :: self
        type(bodies_t), intent(in) :: b
        integer, intent(in) :: i
        real(wp), intent(in) :: e(2)
        real(wp), intent(out) :: f(2), m
        logical, intent(in), optional :: whole
        real(wp) :: nv(2), a, bb, l
        type(wet_t) :: wt
        call relative_motion(self, b, i, e, l, nv, a, bb)
        f = 0.0_wp
        m = 0.0_wp
        if (self%quadratic) then
            f = -self%qn*l*abs(bb)*bb*nv - self%qt*l*abs(a)*a*e
            m = -self%qn*l**4/32.0_wp*abs(b%w(i))*b%w(i)
        end if
        if (self%linear) then
            f = f - self%cn*l*bb*nv - self%ct*l*a*e
            m = m - self%cn*l**3/12.0_wp*b%w(i)
        end if
        if (.not. self%wet) return
        if (present(whole)) then
            if (whole) return
        end if
        wt = self%wetting%of(b%c(1, i), e(1), 0.5_wp*l)
        f = wt%f*f
        m = wt%f*m
    end subroutine body_drag

    pure subroutine drag_add_forces(self, t, b, f, m)
        class(drag_effect_t), intent(in) :: self
        real(wp), intent(in) :: t
        type(bodies_t), intent(in) :: b
        real(wp), intent(inout) :: f(:, :), m(:)
        real(wp) :: fi(2), mi
        integer :: i
        do i = 1, b%n
            call body_drag(self, b, i, b%cs(:, i), fi, mi)
            f(:, i) = f(:, i) + fi
            m(i) = m(i) + mi
        end do
    end subroutine drag_add_forces

    pure subroutine drag_add_jacobian(self, t, b, jac)
        class(drag_effect_t), intent(in) :: self
        real(wp), intent(in) :: t
        type(bodies_t), intent(in) :: b
        real(wp), intent(inout) :: jac(:, :, :)
        real(wp) :: e(2), nv(2), a, bb, l, kn, kt, dfdv(2, 2), dfdphi(2), dmdw
        real(wp) :: f0(2), m0, scale
        type(wet_t) :: wt
        integer :: i, p
        do i = 1, b%n
            e = b%cs(:, i)
            call relative_motion(self, b, i, e, l, nv, a, bb)
            dfdv = 0.0_wp
            dfdphi = 0.0_wp
            dmdw = 0.0_wp
            if (self%quadratic) then
                kn = self%qn*l
                kt = self%qt*l
                do p = 1, 2
                    dfdv(:, p) = -2.0_wp*kn*abs(bb)*nv*nv(p) - 2.0_wp*kt*abs(a)*e*e(p)
                end do
                dfdphi = kn*(2.0_wp*abs(bb)*a*nv + abs(bb)*bb*e) &
                         - kt*(2.0_wp*abs(a)*bb*e + abs(a)*a*nv)
                dmdw = -2.0_wp*self%qn*l**4/32.0_wp*abs(b%w(i))
            end if
            if (self%linear) then
                do p = 1, 2
                    dfdv(:, p) = dfdv(:, p) - self%cn*l*nv*nv(p) - self%ct*l*e*e(p)
                end do
                dfdphi = dfdphi + (self%cn - self%ct)*l*(a*nv + bb*e)
                dmdw = dmdw - self%cn*l**3/12.0_wp
            end if
            scale = 1.0_wp
            if (self%wet) then
                ! d(f F)/dz = f dF/dz + F df/dz, f depending on x and phi
                wt = self%wetting%of(b%c(1, i), e(1), 0.5_wp*l)
                scale = wt%f
                call body_drag(self, b, i, e, f0, m0, whole=.true.)
                jac(1:2, 1, i) = jac(1:2, 1, i) + f0*wt%f_d
                jac(3, 1, i) = jac(3, 1, i) + m0*wt%f_d
                jac(1:2, 3, i) = jac(1:2, 3, i) - f0*wt%f_c*e(2)
                jac(3, 3, i) = jac(3, 3, i) - m0*wt%f_c*e(2)
            end if
            jac(1:2, 3, i) = jac(1:2, 3, i) + scale*dfdphi
            jac(1:2, 4:5, i) = jac(1:2, 4:5, i) + scale*dfdv
            jac(3, 6, i) = jac(3, 6, i) + scale*dmdw
        end do
    end subroutine drag_add_jacobian


    pure subroutine drag_power(self, t, b, dissipation, work)
        class(drag_effect_t), intent(in) :: self
        real(wp), intent(in) :: t
        type(bodies_t), intent(in) :: b
        real(wp), intent(inout) :: dissipation, work
        real(wp) :: fi(2), mi
        integer :: i
        do i = 1, b%n
            call body_drag(self, b, i, b%cs(:, i), fi, mi)
            call add_body_power(self, b, i, fi, mi, dissipation, work)
        end do
    end subroutine drag_power

    !> Add the dissipation and the current's work rate of body i's drag fi, mi.
    pure subroutine add_body_power(self, b, i, fi, mi, dissipation, work)
        class(drag_effect_t), intent(in) :: self
        type(bodies_t), intent(in) :: b
        integer, intent(in) :: i
        real(wp), intent(in) :: fi(2), mi
        real(wp), intent(inout) :: dissipation, work
        dissipation = dissipation - dot_product(fi, b%v(:, i) - self%u) - mi*b%w(i)
        if (self%current) work = work + dot_product(fi, self%u)
    end subroutine add_body_power

    !> drag_add_forces and drag_power with one drag per body.
    pure subroutine drag_add_forces_power(self, t, b, f, m, dissipation, work)
        class(drag_effect_t), intent(in) :: self
        real(wp), intent(in) :: t
        type(bodies_t), intent(in) :: b
        real(wp), intent(inout) :: f(:, :), m(:)
        real(wp), intent(inout) :: dissipation, work
        real(wp) :: fi(2), mi
        integer :: i
        do i = 1, b%n
            call body_drag(self, b, i, b%cs(:, i), fi, mi)
            f(:, i) = f(:, i) + fi
            m(i) = m(i) + mi
            call add_body_power(self, b, i, fi, mi, dissipation, work)
        end do
    end subroutine drag_add_forces_power
end module ropedyn_effect_drag
