!> The MPP's energies (kinetic, elastic, gravity, the effects') and the powers integrated
!! as quadratures (dissipation, external work). docs/theory/mpp.md.
submodule (ropedyn_mpp) ropedyn_mpp_energy
    implicit none

contains

    module procedure mpp_energy
        real(wp) :: p(2, 0:self%n), c(2, self%n), pd(2, 0:self%n), cd(2, self%n)
        real(wp), dimension(self%n) :: phi, u, phid, ud
        real(wp) :: e(2), nv(2), offset(2), couple
        type(motion_state_t) :: top, bottom
        type(bodies_t) :: b
        real(wp) :: e_kin, e_pot
        logical :: bottom_on
        integer :: k, n, i
        n = self%n
        call unpack(self, y, phi, u, phid, ud)
        call self%positions(y, p, c, pd, cd, t)
        call self%supports_at(t, top, bottom, bottom_on)
        en%kinetic = 0.5_wp*(self%m*sum(cd**2) + self%inertia*sum(phid**2))
        en%gravity = -self%m*self%g*sum(c(1, :))
        do k = 1, size(self%pm_body)
            i = self%pm_body(k)
            e = [cos(phi(i)), sin(phi(i))]
            nv = [-e(2), e(1)]
            en%kinetic = en%kinetic + 0.5_wp*self%pm_m(k)* &
                         sum((cd(:, i) + self%pm_r(k)*phid(i)*nv)**2)
            en%gravity = en%gravity - self%pm_m(k)*self%g*(c(1, i) + self%pm_r(k)*e(1))
        end do
        ! (the last member's own stiffness as a correction: the same sum as without it)
        u = self%spring_stretch(u)
        en%elastic = 0.5_wp*self%ks*sum(u**2) + 0.5_wp*(self%ksj(n) - self%ks)*u(n)**2
        do k = 2, n
            en%elastic = en%elastic + 0.5_wp*self%cb*(phi(k) - phi(k - 1))**2
        end do
        if (self%top_clamped) en%elastic = en%elastic + 0.5_wp*self%c_rot* &
                                            (phi(1) - top%angle)**2
        if (bottom_on) then
            call self%bottom_pin_spring(p(:, n) - bottom%p, [cos(phi(n)), sin(phi(n))], &
                                        offset, couple)
            en%elastic = en%elastic + 0.5_wp*self%k_sup*sum(offset**2)
        end if
        if (self%bottom == 2 .and. bottom_on) en%elastic = en%elastic + 0.5_wp*self%c_rot* &
                                                          (phi(n) - bottom%angle)**2
        if (size(self%effects) > 0 .or. self%water) then
            call rod_bodies(self, y, top, b)
            if (size(self%effects) > 0) then
                call add_energies_of(self%effects, t, b, en%elastic)
                call add_level_energies_of(self%effects, t, b, en%level)
            end if
            if (self%water) then
                ! the added mass's kinetic energy; the current's potential -1/2 u^T A u
                call water_energy(self, b, e_kin, e_pot)
                en%kinetic = en%kinetic + e_kin
                en%elastic = en%elastic + e_pot
            end if
        end if
        en%dissipated = 0.0_wp
        if (size(yq) >= 1) en%dissipated = yq(1)
        en%support_work = 0.0_wp
        if (self%with_work .and. size(yq) >= 2) en%support_work = yq(2)
    end procedure mpp_energy

    module procedure mpp_quad_rhs
        real(wp) :: a(self%ndof), r(self%ndof), pin(2), powers(2)
        type(motion_state_t) :: top, bottom
        logical :: bottom_on
        call self%supports_at(t, top, bottom, bottom_on)
        status = STATUS_OK
        pin = 0.0_wp
        powers = 0.0_wp
        ! the residual at zero accelerations places the rods as bodies and the tip, and
        ! gives the effects' powers
        if (size(self%effects) > 0 .or. self%moving(1) .or. bottom_on) then
            call angles(self, y)
            a = 0.0_wp
            call self%residual_core(t, y, a, r, powers=powers)
        end if
        if (self%moving(1)) then
            ! the pin force needs the accelerations a = M^{-1} f (pin_force)
            call self%mass_factor(y, status)
            if (status == STATUS_OK) then
                a = r
                call mass_solve(self, a)
                pin = pin_force(self, y, a)
            end if
        end if
        if (status == STATUS_OK) then
            call quad_rates(self, t, y, pin, powers, yqdot, status)
        else
            call quad_rates(self, t, y, pin, powers, yqdot)
        end if
    end procedure mpp_quad_rhs

    module procedure mpp_rhs_quad
        real(wp) :: pin(2), powers(2)
        integer :: nd
        nd = self%ndof
        powers = 0.0_wp
        call rhs_powers(self, t, y, ydot, status, powers)
        if (status /= STATUS_OK) return
        ! the right-hand side left the tip, the residual at zero accelerations and the
        ! factors; the pin force at the accelerations it solved for
        pin = 0.0_wp
        if (self%moving(1)) pin = pin_force(self, y, ydot(nd + 1:2*nd))
        call quad_rates(self, t, y, pin, powers, yqdot, status)
    end procedure mpp_rhs_quad

    !> The quadratures' rates at (t, y), the last residual_core having been at y (the tip
    !! P_n and its velocity), with pin the top joint's force on the rope (used when the top
    !! joint moves) and powers the effects' dissipation and work rates. status (if
    !! present) is STATUS_RECOVERABLE when a rate is not finite.
    subroutine quad_rates(self, t, y, pin, powers, yqdot, status)
        class(mpp_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(in) :: pin(2), powers(2)
        real(wp), intent(out) :: yqdot(:)
        integer, intent(out), optional :: status
        real(wp) :: power, work, rel(2), offset(2), couple
        type(motion_state_t) :: top, bottom
        logical :: bottom_on
        integer :: k, n, nd
        n = self%n
        nd = self%ndof
        call self%supports_at(t, top, bottom, bottom_on)
        power = 0.0_wp
        if (self%nu > 0) power = self%ds*sum(y(nd + n + 1:2*nd)**2) &
                                 + (self%dsj(n) - self%ds)*y(2*nd)**2
        work = 0.0_wp
        do k = 2, n
            power = power + self%db*(y(nd + k) - y(nd + k - 1))**2
        end do
        if (self%top_clamped) then
            power = power + self%d_rot*(y(nd + 1) - top%rate)**2
            if (self%moving(1)) work = work - (self%c_rot*(y(1) - top%angle) &
                                                 + self%d_rot*(y(nd + 1) - top%rate))*top%rate
        end if
        if (bottom_on) then
            rel = self%tipd - bottom%v
            power = power + self%d_sup*sum(rel**2)
            call self%bottom_pin_spring(self%tip - bottom%p, self%cs(:, n), offset, couple)
            if (self%moving(2)) work = work + dot_product(-self%k_sup*offset &
                                                          - self%d_sup*rel, bottom%v)
            if (self%bottom == 2) then
                power = power + self%d_rot*(y(nd + n) - bottom%rate)**2
                if (self%moving(2)) work = work - (self%c_rot*(y(n) - bottom%angle) &
                                                   + self%d_rot*(y(nd + n) - bottom%rate)) &
                                                  *bottom%rate
            end if
        end if
        power = power + powers(1)
        work = work + powers(2)
        if (self%moving(1)) work = work + dot_product(pin, top%v)
        yqdot(1) = power
        if (self%with_work) yqdot(2) = work
        if (present(status)) then
            status = STATUS_OK
            if (.not. (ieee_is_finite(power) .and. ieee_is_finite(work))) &
                status = STATUS_RECOVERABLE
        end if
    end subroutine quad_rates
end submodule ropedyn_mpp_energy
