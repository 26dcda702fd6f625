!> The MPP kernels: the O(n) Lagrange residual, the dense mass matrix, right-hand side,
!! Jacobian, energies and powers (the derivation is in docs/physics-mpp.md).
submodule (ropedyn_mpp) ropedyn_mpp_kernels
    implicit none

contains

    module procedure unpack
        integer :: n, nd
        n = self%n
        nd = self%ndof
        phi = y(1:n)
        phid = y(nd + 1:nd + n)
        u = 0.0_wp
        ud = 0.0_wp
        if (self%nu > 0) then
            u = y(n + 1:nd)
            ud = y(nd + n + 1:2*nd)
        end if
    end procedure unpack

    module procedure mpp_residual
        real(wp), dimension(self%n) :: phi, u, phid, ud, phidd, udd, hk, lk, mom
        real(wp) :: e(2, self%n), nv(2, self%n), pacc(2), cacc(2, self%n), w(2, self%n)
        real(wp) :: wsum(2), fb(2), pn(2), pnd(2), d, dd, tt, fp(2), pv(2)
        type(motion_state_t) :: top, bottom
        type(bodies_t) :: b
        logical :: bottom_on
        integer :: k, n, nd, i

        n = self%n
        nd = self%ndof
        tt = 0.0_wp
        if (present(t)) tt = t
        call self%supports_at(tt, top, bottom, bottom_on)
        call unpack(self, y, phi, u, phid, ud)
        phidd = qacc(1:n)
        udd = 0.0_wp
        if (self%nu > 0) udd = qacc(n + 1:nd)
        hk = u + 0.5_wp*self%l
        lk = u + self%l
        e(1, :) = cos(phi)
        e(2, :) = sin(phi)
        nv(1, :) = -e(2, :)
        nv(2, :) = e(1, :)

        ! Accelerations of the joints (prefix sums, from the top joint's) and the
        ! applied-minus-inertial force on each rod: w_i = m g x - m C_i''.
        pacc = top%a
        pn = top%p
        pnd = top%v
        do k = 1, n
            cacc(:, k) = pacc + (hk(k)*phidd(k) + 2.0_wp*ud(k)*phid(k))*nv(:, k) &
                         + (udd(k) - hk(k)*phid(k)**2)*e(:, k)
            pacc = pacc + (lk(k)*phidd(k) + 2.0_wp*ud(k)*phid(k))*nv(:, k) &
                   + (udd(k) - lk(k)*phid(k)**2)*e(:, k)
            w(:, k) = -self%m*cacc(:, k)
            w(1, k) = w(1, k) + self%m*self%g
            pn = pn + lk(k)*e(:, k)
            pnd = pnd + lk(k)*phid(k)*nv(:, k) + ud(k)*e(:, k)
        end do
        mom = 0.0_wp

        ! Point masses at P = C_i + r e_i: their applied-minus-inertial force joins w_i,
        ! its moment r e_i x f about the centre joins the rod's moment.
        do k = 1, size(self%pm_body)
            i = self%pm_body(k)
            pv = cacc(:, i) + self%pm_r(k)*(phidd(i)*nv(:, i) - phid(i)**2*e(:, i))
            fp = -self%pm_m(k)*pv
            fp(1) = fp(1) + self%pm_m(k)*self%g
            w(:, i) = w(:, i) + fp
            mom(i) = mom(i) + self%pm_r(k)*dot_product(nv(:, i), fp)
        end do

        ! External effects on the rods as bodies.
        if (size(self%effects) > 0) then
            call rod_bodies(self, y, top, b)
            call add_forces_of(self%effects, tt, b, w, mom)
        end if

        ! Force of the bottom support on the tip P_n.
        fb = 0.0_wp
        if (bottom_on) fb = -self%k_sup*(pn - bottom%p) - self%d_sup*(pnd - bottom%v)

        ! Generalized forces by suffix sums: Q[phi_k] = n_k . (h_k w_k + l_k sum_{i>k} w_i
        ! + l_k F_b) + M_k, Q[u_k] = e_k . (sum_{i>=k} w_i + F_b).
        wsum = fb
        do k = n, 1, -1
            r(k) = dot_product(nv(:, k), hk(k)*w(:, k) + lk(k)*wsum) + mom(k)
            wsum = wsum + w(:, k)
            if (self%nu > 0) r(n + k) = dot_product(e(:, k), wsum)
        end do
        if (present(pin)) pin = -wsum
        r(1:n) = r(1:n) - self%inertia*phidd

        ! Member springs and dampers.
        if (self%nu > 0) r(n + 1:nd) = r(n + 1:nd) - self%ks*u - self%ds*ud
        ! Joint bending springs and dampers between members.
        if (self%cb > 0.0_wp .or. self%db > 0.0_wp) then
            do k = 2, n
                d = self%cb*(phi(k) - phi(k - 1)) + self%db*(phid(k) - phid(k - 1))
                r(k) = r(k) - d
                r(k - 1) = r(k - 1) + d
            end do
        end if
        ! Rotational springs of clamped supports.
        if (self%top_clamped) then
            dd = self%c_rot*(phi(1) - top%angle) + self%d_rot*(phid(1) - top%rate)
            r(1) = r(1) - dd
        end if
        if (self%bottom == 2 .and. bottom_on) then
            dd = self%c_rot*(phi(n) - bottom%angle) + self%d_rot*(phid(n) - bottom%rate)
            r(n) = r(n) - dd
        end if
    end procedure mpp_residual

    !> The rods as bodies (centre, angle, their rates, length l) for the effects.
    pure subroutine rod_bodies(self, y, top, b)
        class(mpp_t), intent(in) :: self
        real(wp), intent(in) :: y(:)
        type(motion_state_t), intent(in) :: top
        type(bodies_t), intent(out) :: b
        real(wp), dimension(self%n) :: phi, u, phid, ud
        real(wp) :: p(2), pd(2), e(2), nv(2)
        integer :: k
        call unpack(self, y, phi, u, phid, ud)
        b%n = self%n
        allocate (b%c(2, self%n), b%v(2, self%n), b%l(self%n))
        b%phi = phi
        b%w = phid
        b%l = self%l
        p = top%p
        pd = top%v
        do k = 1, self%n
            e = [cos(phi(k)), sin(phi(k))]
            nv = [-e(2), e(1)]
            b%c(:, k) = p + (u(k) + 0.5_wp*self%l)*e
            b%v(:, k) = pd + (u(k) + 0.5_wp*self%l)*phid(k)*nv + ud(k)*e
            p = p + (self%l + u(k))*e
            pd = pd + (self%l + u(k))*phid(k)*nv + ud(k)*e
        end do
    end subroutine rod_bodies

    module procedure mpp_mass_dense
        real(wp), dimension(self%n) :: phi, u, phid, ud, hk, lk
        real(wp) :: cjk, sjk, s, jp(2, self%ndof), e(2), nv(2)
        integer :: k, j, n, p, i
        n = self%n
        call unpack(self, y, phi, u, phid, ud)
        hk = u + 0.5_wp*self%l
        lk = u + self%l
        mm = 0.0_wp
        do j = 1, n
            do k = 1, j
                cjk = cos(phi(k) - phi(j))
                sjk = sin(phi(j) - phi(k))     ! n_k . e_j
                if (k < j) then
                    s = lk(k)*(hk(j) + real(n - j, wp)*lk(j))
                else
                    s = hk(k)**2 + real(n - k, wp)*lk(k)**2
                end if
                mm(k, j) = self%m*cjk*s
                mm(j, k) = mm(k, j)
                if (self%nu > 0) then
                    mm(n + k, n + j) = self%m*cjk*real(n - j + 1, wp)
                    mm(n + j, n + k) = mm(n + k, n + j)
                    ! (phi_k, u_j), k <= j
                    if (k < j) then
                        s = real(n - j + 1, wp)*lk(k)
                    else
                        s = hk(k) + real(n - k, wp)*lk(k)
                    end if
                    mm(k, n + j) = self%m*sjk*s
                    mm(n + j, k) = mm(k, n + j)
                    ! (phi_j, u_k), k < j: n_j . e_k = -sjk
                    if (k < j) then
                        mm(j, n + k) = -self%m*sjk*(hk(j) + real(n - j, wp)*lk(j))
                        mm(n + k, j) = mm(j, n + k)
                    end if
                end if
            end do
            mm(j, j) = mm(j, j) + self%inertia
        end do
        ! point masses: m_p J_p^T J_p with J_p = dP/dq, P = C_i + r e_i
        do p = 1, size(self%pm_body)
            i = self%pm_body(p)
            jp = 0.0_wp
            do k = 1, i
                e = [cos(phi(k)), sin(phi(k))]
                nv = [-e(2), e(1)]
                if (k < i) then
                    jp(:, k) = lk(k)*nv
                else
                    jp(:, k) = (hk(k) + self%pm_r(p))*nv
                end if
                if (self%nu > 0) jp(:, n + k) = e
            end do
            mm = mm + self%pm_m(p)*matmul(transpose(jp), jp)
        end do
    end procedure mpp_mass_dense

    module procedure mpp_rhs
        real(wp) :: mm(self%ndof, self%ndof), f(self%ndof, 1), zero(self%ndof)
        integer :: nd, info
        nd = self%ndof
        zero = 0.0_wp
        call self%residual(y, zero, f(:, 1), t)
        call self%mass_dense(y, mm)
        call dpotrf('L', nd, mm, nd, info)
        if (info == 0) call dpotrs('L', nd, 1, mm, nd, f, nd, info)
        ydot(1:nd) = y(nd + 1:2*nd)
        ydot(nd + 1:2*nd) = f(:, 1)
        status = STATUS_OK
        if (info /= 0 .or. .not. all(ieee_is_finite(f))) status = STATUS_RECOVERABLE
    end procedure mpp_rhs

    module procedure mpp_implicit_rhs
        real(wp) :: zero(self%ndof)
        integer :: nd
        nd = self%ndof
        zero = 0.0_wp
        f(1:nd) = y(nd + 1:2*nd)
        call self%residual(y, zero, f(nd + 1:2*nd), t)
        status = STATUS_OK
        if (.not. all(ieee_is_finite(f))) status = STATUS_RECOVERABLE
    end procedure mpp_implicit_rhs

    module procedure mpp_mass_matrix
        real(wp) :: mm(self%ndof, self%ndof)
        integer :: i, j, nd
        nd = self%ndof
        call self%mass_dense(y, mm)
        do j = 1, nd
            mb(offset, j) = mb(offset, j) + 1.0_wp
            do i = 1, nd
                mb(offset + i - j, nd + j) = mb(offset + i - j, nd + j) + mm(i, j)
            end do
        end do
        status = STATUS_OK
    end procedure mpp_mass_matrix

    module procedure mpp_jacobian
        real(wp) :: mm(self%ndof, self%ndof), a0(self%ndof, 1), r0(self%ndof)
        real(wp) :: dr(self%ndof, 2*self%ndof), yp(size(y)), zero(self%ndof), inc
        integer :: nd, j, i, info
        nd = self%ndof
        zero = 0.0_wp
        call self%residual(y, zero, a0(:, 1), t)
        call self%mass_dense(y, mm)
        call dpotrf('L', nd, mm, nd, info)
        if (info /= 0) then
            status = STATUS_RECOVERABLE
            return
        end if
        call dpotrs('L', nd, 1, mm, nd, a0, nd, info)
        call self%residual(y, a0(:, 1), r0, t)
        do j = 1, 2*nd
            yp = y
            inc = sqrt(epsilon(1.0_wp))*max(abs(y(j)), 1.0e-3_wp)
            yp(j) = y(j) + inc
            call self%residual(yp, a0(:, 1), dr(:, j), t)
            dr(:, j) = (dr(:, j) - r0)/inc
        end do
        call dpotrs('L', nd, 2*nd, mm, nd, dr, nd, info)
        ! rows 1..nd: dq'/dv = I; rows nd+1..2nd: da/dy
        do j = 1, nd
            jb(offset + j - (nd + j), nd + j) = jb(offset + j - (nd + j), nd + j) + 1.0_wp
        end do
        do j = 1, 2*nd
            do i = 1, nd
                jb(offset + nd + i - j, j) = jb(offset + nd + i - j, j) + dr(i, j)
            end do
        end do
        status = STATUS_OK
        if (.not. all(ieee_is_finite(dr))) status = STATUS_RECOVERABLE
    end procedure mpp_jacobian

    module procedure mpp_energy
        real(wp) :: p(2, 0:self%n), c(2, self%n), pd(2, 0:self%n), cd(2, self%n)
        real(wp), dimension(self%n) :: phi, u, phid, ud
        real(wp) :: e(2), nv(2)
        type(motion_state_t) :: top, bottom
        type(bodies_t) :: b
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
        en%elastic = 0.5_wp*self%ks*sum(u**2)
        do k = 2, n
            en%elastic = en%elastic + 0.5_wp*self%cb*(phi(k) - phi(k - 1))**2
        end do
        if (self%top_clamped) en%elastic = en%elastic + 0.5_wp*self%c_rot* &
                                            (phi(1) - top%angle)**2
        if (bottom_on) en%elastic = en%elastic + 0.5_wp*self%k_sup* &
                                    sum((p(:, n) - bottom%p)**2)
        if (self%bottom == 2 .and. bottom_on) en%elastic = en%elastic + 0.5_wp*self%c_rot* &
                                                          (phi(n) - bottom%angle)**2
        if (size(self%effects) > 0) then
            call rod_bodies(self, y, top, b)
            call add_energies_of(self%effects, t, b, en%elastic)
        end if
        en%dissipated = 0.0_wp
        if (size(yq) >= 1) en%dissipated = yq(1)
        en%support_work = 0.0_wp
        if (self%with_work .and. size(yq) >= 2) en%support_work = yq(2)
    end procedure mpp_energy

    module procedure mpp_quad_rhs
        real(wp), dimension(self%n) :: phi, u, phid, ud
        real(wp) :: p(2, 0:self%n), c(2, self%n), pd(2, 0:self%n), cd(2, self%n)
        real(wp) :: power, work, rel(2), pin(2), mm(self%ndof, self%ndof), a(self%ndof, 1)
        real(wp) :: r(self%ndof), zero(self%ndof)
        type(motion_state_t) :: top, bottom
        type(bodies_t) :: b
        logical :: bottom_on
        integer :: k, n, info
        n = self%n
        call unpack(self, y, phi, u, phid, ud)
        call self%supports_at(t, top, bottom, bottom_on)
        power = self%ds*sum(ud**2)
        work = 0.0_wp
        do k = 2, n
            power = power + self%db*(phid(k) - phid(k - 1))**2
        end do
        if (self%top_clamped) then
            power = power + self%d_rot*(phid(1) - top%rate)**2
            if (self%moving(1)) work = work - (self%c_rot*(phi(1) - top%angle) &
                                                 + self%d_rot*(phid(1) - top%rate))*top%rate
        end if
        if (bottom_on) then
            call self%positions(y, p, c, pd, cd, t)
            rel = pd(:, n) - bottom%v
            power = power + self%d_sup*sum(rel**2)
            if (self%moving(2)) work = work + dot_product(-self%k_sup*(p(:, n) - bottom%p) &
                                                          - self%d_sup*rel, bottom%v)
            if (self%bottom == 2) then
                power = power + self%d_rot*(phid(n) - bottom%rate)**2
                if (self%moving(2)) work = work - (self%c_rot*(phi(n) - bottom%angle) &
                                                   + self%d_rot*(phid(n) - bottom%rate))*bottom%rate
            end if
        end if
        if (size(self%effects) > 0) then
            call rod_bodies(self, y, top, b)
            call add_powers_of(self%effects, t, b, power, work)
        end if
        status = STATUS_OK
        if (self%moving(1)) then
            ! the pin force needs the accelerations: a = M^{-1} f, then r(q, q', a) gives it
            zero = 0.0_wp
            call self%residual(y, zero, a(:, 1), t)
            call self%mass_dense(y, mm)
            call dpotrf('L', self%ndof, mm, self%ndof, info)
            if (info == 0) call dpotrs('L', self%ndof, 1, mm, self%ndof, a, self%ndof, info)
            if (info /= 0) status = STATUS_RECOVERABLE
            call self%residual(y, a(:, 1), r, t, pin)
            work = work + dot_product(pin, top%v)
        end if
        yqdot(1) = power
        if (self%with_work) yqdot(2) = work
        if (.not. (ieee_is_finite(power) .and. ieee_is_finite(work))) status = STATUS_RECOVERABLE
    end procedure mpp_quad_rhs
end submodule ropedyn_mpp_kernels
