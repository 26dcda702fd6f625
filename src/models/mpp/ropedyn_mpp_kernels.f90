!> The MPP kernels: the O(n) Lagrange residual, the O(n) solve of M(q) q'' = f by the
!! articulated-body recursion, the dense mass matrix (O(n^2)), the Jacobian and the
!! second-order blocks (O(n^2): a column of the residual's tangent, ropedyn_mpp_tangent, and
!! a solve per column). The energies and powers are in ropedyn_mpp_energy. The derivation
!! is in docs/theory/mpp.md.
!!
!! Work arrays are held by the model (allocated at creation): cos and sin of every angle
!! once per call (self%cs), the rods' forces, the factors of M and the residual's
!! derivatives. No allocation per call.
submodule (ropedyn_mpp) ropedyn_mpp_kernels
    use ropedyn_trig, only: cos_sin
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

    !> cos and sin of every angle of y into self%cs, once per call (ropedyn_trig's
    !! vectorized loop; libm's sincos, one call per angle, was 5 % of a run in water).
    module procedure angles
        real(wp) :: phi(self%n)
        phi = y(1:self%n)
        call cos_sin(phi, self%cs)
    end procedure angles

    module procedure mpp_residual
        real(wp) :: tt
        tt = 0.0_wp
        if (present(t)) tt = t
        call angles(self, y)
        call self%residual_core(tt, y, qacc, r, pin)
    end procedure mpp_residual

    module procedure residual_core
        real(wp) :: pn(2), pnd(2), wsum(2), fb(2), offset(2), couple
        type(motion_state_t) :: top, bottom
        logical :: bottom_on, effects, bodied

        effects = size(self%effects) > 0
        bodied = effects .or. self%water
        call self%supports_at(t, top, bottom, bottom_on)
        call chain_kinematics(self, y, qacc, top, bodied, pn, pnd)
        if (effects) self%bodies%cs = self%cs    ! the angles' of y (angles)
        self%tip = pn
        self%tipd = pnd
        self%mom = 0.0_wp
        call point_mass_forces(self, y, qacc)

        ! The water's added mass on the rods as bodies.
        if (self%water) call water_forces(self, qacc)

        ! External effects on the rods as bodies (and their powers).
        if (effects) then
            if (present(powers)) then
                call add_forces_powers_of(self%effects, t, self%bodies, self%w, self%mom, &
                                          powers(1), powers(2))
            else
                call add_forces_of(self%effects, t, self%bodies, self%w, self%mom)
            end if
        end if

        ! Force of the bottom support on the tip P_n (and the couple of a slack pin's
        ! spring on member n: bottom_pin_spring).
        fb = 0.0_wp
        couple = 0.0_wp
        if (bottom_on) then
            call self%bottom_pin_spring(pn - bottom%p, self%cs(:, self%n), offset, couple)
            fb = -self%k_sup*offset - self%d_sup*(pnd - bottom%v)
        end if
        call generalized_forces(self, y, qacc, fb, r, wsum)
        if (present(pin)) pin = -wsum
        call spring_forces(self, y, top, bottom, bottom_on, r)
        r(self%n) = r(self%n) - couple
    end procedure residual_core

    !> Accelerations of the joints (prefix sums, from the top joint's) and the
    !! applied-minus-inertial force on each rod, w_k = m g x - m C_k'', into self%cacc and
    !! self%w; with `bodied` the rods as bodies into self%bodies; the lower end P_n and its
    !! velocity in pn, pnd (m, m/s).
    pure subroutine chain_kinematics(self, y, qacc, top, bodied, pn, pnd)
        class(mpp_t), intent(inout) :: self
        real(wp), intent(in) :: y(:), qacc(:)
        type(motion_state_t), intent(in) :: top
        logical, intent(in) :: bodied
        real(wp), intent(out) :: pn(2), pnd(2)
        real(wp) :: pacc(2), c, s, u, ud, phd, pdd, udd, hk, lk, a1, a2
        integer :: k, n, nd

        n = self%n
        nd = self%ndof
        u = 0.0_wp
        ud = 0.0_wp
        udd = 0.0_wp
        pacc = top%a
        pn = top%p
        pnd = top%v
        do k = 1, n
            c = self%cs(1, k)
            s = self%cs(2, k)
            phd = y(nd + k)
            pdd = qacc(k)
            if (self%nu > 0) then
                u = y(n + k)
                ud = y(nd + n + k)
                udd = qacc(n + k)
            end if
            hk = u + 0.5_wp*self%l
            lk = u + self%l
            ! along n_k = (-s, c) and e_k = (c, s)
            a1 = hk*pdd + 2.0_wp*ud*phd
            a2 = udd - hk*phd**2
            self%cacc(1, k) = pacc(1) - a1*s + a2*c
            self%cacc(2, k) = pacc(2) + a1*c + a2*s
            self%w(1, k) = -self%m*self%cacc(1, k) + self%m*self%g
            self%w(2, k) = -self%m*self%cacc(2, k)
            a1 = lk*pdd + 2.0_wp*ud*phd
            a2 = udd - lk*phd**2
            pacc(1) = pacc(1) - a1*s + a2*c
            pacc(2) = pacc(2) + a1*c + a2*s
            if (bodied) then
                self%bodies%c(1, k) = pn(1) + hk*c
                self%bodies%c(2, k) = pn(2) + hk*s
                self%bodies%v(1, k) = pnd(1) - hk*phd*s + ud*c
                self%bodies%v(2, k) = pnd(2) + hk*phd*c + ud*s
                self%bodies%phi(k) = y(k)
                self%bodies%w(k) = phd
            end if
            pn(1) = pn(1) + lk*c
            pn(2) = pn(2) + lk*s
            pnd(1) = pnd(1) - lk*phd*s + ud*c
            pnd(2) = pnd(2) + lk*phd*c + ud*s
        end do
    end subroutine chain_kinematics

    !> Point masses at P = C_i + r e_i: their applied-minus-inertial force joins w_i,
    !! its moment r e_i x f about the centre joins the rod's moment.
    pure subroutine point_mass_forces(self, y, qacc)
        class(mpp_t), intent(inout) :: self
        real(wp), intent(in) :: y(:), qacc(:)
        real(wp) :: c, s, fp(2), pv(2)
        integer :: k, i, nd
        nd = self%ndof
        do k = 1, size(self%pm_body)
            i = self%pm_body(k)
            c = self%cs(1, i)
            s = self%cs(2, i)
            pv = self%cacc(:, i) + self%pm_r(k)*(qacc(i)*[-s, c] - y(nd + i)**2*[c, s])
            fp = -self%pm_m(k)*pv
            fp(1) = fp(1) + self%pm_m(k)*self%g
            self%w(:, i) = self%w(:, i) + fp
            self%mom(i) = self%mom(i) + self%pm_r(k)*(-s*fp(1) + c*fp(2))
        end do
    end subroutine point_mass_forces

    !> Generalized forces by suffix sums, from the bottom support's force fb:
    !! Q[phi_k] = n_k . (h_k w_k + l_k sum_{i>k} w_i + l_k F_b) + M_k,
    !! Q[u_k] = e_k . (sum_{i>=k} w_i + F_b), into r; the sums into self%wsum, the
    !! whole one (at the top joint) into wsum.
    pure subroutine generalized_forces(self, y, qacc, fb, r, wsum)
        class(mpp_t), intent(inout) :: self
        real(wp), intent(in) :: y(:), qacc(:), fb(2)
        real(wp), intent(out) :: r(:), wsum(2)
        real(wp) :: c, s, u, hk, lk
        integer :: k, n
        n = self%n
        u = 0.0_wp
        wsum = fb
        self%wsum(:, n + 1) = fb
        do k = n, 1, -1
            c = self%cs(1, k)
            s = self%cs(2, k)
            if (self%nu > 0) u = y(n + k)
            hk = u + 0.5_wp*self%l
            lk = u + self%l
            r(k) = -s*(hk*self%w(1, k) + lk*wsum(1)) + c*(hk*self%w(2, k) + lk*wsum(2)) &
                   + self%mom(k) - self%inertia*qacc(k)
            wsum = wsum + self%w(:, k)
            self%wsum(:, k) = wsum
            if (self%nu > 0) r(n + k) = c*wsum(1) + s*wsum(2)
        end do
    end subroutine generalized_forces

    !> Subtract from r the member springs and dampers, the joint bending springs and
    !! dampers and the clamped supports' rotational ones (top and bottom: the supports'
    !! states); the joints' and clamps' moments into self%jmom.
    pure subroutine spring_forces(self, y, top, bottom, bottom_on, r)
        class(mpp_t), intent(inout) :: self
        real(wp), intent(in) :: y(:)
        type(motion_state_t), intent(in) :: top, bottom
        logical, intent(in) :: bottom_on
        real(wp), intent(inout) :: r(:)
        real(wp) :: d, dd, floor
        integer :: k, n, nd
        n = self%n
        nd = self%ndof
        ! Member springs and dampers (spring_stretch, with the floor taken once: a call per
        ! member cost more than the spring)
        if (self%nu > 0) then
            floor = self%stretch_floor()
            r(n + 1:nd) = r(n + 1:nd) - self%ksj*merge(floor, y(n + 1:nd), y(n + 1:nd) < floor) &
                          - self%dsj*y(nd + n + 1:2*nd)
        end if
        ! Joint bending springs and dampers between members; their moments (the lower
        ! member's on the upper one) kept by joint for the internal forces.
        self%jmom = 0.0_wp
        if (self%cb > 0.0_wp .or. self%db > 0.0_wp) then
            do k = 2, n
                d = self%cb*(y(k) - y(k - 1)) + self%db*(y(nd + k) - y(nd + k - 1))
                r(k) = r(k) - d
                r(k - 1) = r(k - 1) + d
                self%jmom(k - 1) = d
            end do
        end if
        ! Rotational springs of clamped supports.
        if (self%top_clamped) then
            dd = self%c_rot*(y(1) - top%angle) + self%d_rot*(y(nd + 1) - top%rate)
            r(1) = r(1) - dd
            self%jmom(0) = dd
        end if
        if (self%bottom == 2 .and. bottom_on) then
            dd = self%c_rot*(y(n) - bottom%angle) + self%d_rot*(y(nd + n) - bottom%rate)
            r(n) = r(n) - dd
            self%jmom(n) = -dd
        end if
    end subroutine spring_forces

    !> The residual's pin force is -(F_b + sum_i w_i) and only the inertial part of w_i
    !! depends on the accelerations: w_i(a) = w_i(0) - (m I + A_i) dC_i, the point masses'
    !! forces -m_p (dC_i + r_p phi_i'' n_i), where dC_i = C_i''(a) - C_i''(0) is the part
    !! of the centre's acceleration linear in a (prefix sums from the top joint, whose own
    !! acceleration is in both): dC_i = dP_{i-1} + eta_i phi_i'' n_i + u_i'' e_i,
    !! dP_i = dP_{i-1} + lambda_i phi_i'' n_i + u_i'' e_i. So the pin force at a is the one
    !! at zero accelerations (-self%wsum(:, 1) of the last residual, the effects' forces
    !! in it) plus sum_i (m I + A_i) dC_i and the point masses' m_p dP_p (A_i: self%wblk).
    module procedure pin_force
        real(wp) :: dp(2), dc(2, self%n), c, s, u, udd, hk, lk
        integer :: k, n, i
        n = self%n
        u = 0.0_wp
        udd = 0.0_wp
        dp = 0.0_wp
        do k = 1, n
            c = self%cs(1, k)
            s = self%cs(2, k)
            if (self%nu > 0) then
                u = y(n + k)
                udd = qacc(n + k)
            end if
            hk = u + 0.5_wp*self%l
            lk = u + self%l
            dc(1, k) = dp(1) - hk*qacc(k)*s + udd*c
            dc(2, k) = dp(2) + hk*qacc(k)*c + udd*s
            dp(1) = dp(1) - lk*qacc(k)*s + udd*c
            dp(2) = dp(2) + lk*qacc(k)*c + udd*s
        end do
        pin = -self%wsum(:, 1) + self%m*sum(dc, dim=2)
        if (self%water) then
            do k = 1, n
                pin = pin + matmul(self%wblk(1:2, 1:2, k), dc(:, k))
            end do
        end if
        do k = 1, size(self%pm_body)
            i = self%pm_body(k)
            pin = pin + self%pm_m(k)*(dc(:, i) + self%pm_r(k)*qacc(i)* &
                                      [-self%cs(2, i), self%cs(1, i)])
        end do
    end procedure pin_force

    !> The rods as bodies (centre, angle, their rates, length l) for the effects.
    module procedure rod_bodies
        real(wp), dimension(self%n) :: phi, u, phid, ud
        real(wp) :: p(2), pd(2), e(2), nv(2)
        integer :: k
        call unpack(self, y, phi, u, phid, ud)
        b%n = self%n
        allocate (b%c(2, self%n), b%v(2, self%n), b%l(self%n))
        b%phi = phi
        b%w = phid
        b%l = self%l
        call set_axes(b)
        p = top%p
        pd = top%v
        do k = 1, self%n
            e = b%cs(:, k)
            nv = [-e(2), e(1)]
            b%c(:, k) = p + (u(k) + 0.5_wp*self%l)*e
            b%v(:, k) = pd + (u(k) + 0.5_wp*self%l)*phid(k)*nv + ud(k)*e
            p = p + (self%l + u(k))*e
            pd = pd + (self%l + u(k))*phid(k)*nv + ud(k)*e
        end do
    end procedure rod_bodies

    !> The articulated-body recursion, from the tip (docs/theory/mpp.md, "Solving
    !! M q'' = f in O(n)"). The members k .. n, hanging from joint P_{k-1}, exert on it the
    !! force S_k = I_k A + z_k for its acceleration A, with a 2x2 articulated inertia I_k
    !! (I_{n+1} = 0: the tip is free of inertia; springs are forces, not inertia). With
    !! I' = I_{k+1}, member k's unknowns x = (phi_k'', u_k'') satisfy D x = c - G^T A:
    !!     D11 = m eta^2 + 2 s1 eta + s2 + J + lambda^2 n.I'n,  D12 = lambda e.I'n,
    !!     D22 = m + e.I'e,  G = [(m eta + s1) n + lambda I'n, m e + I'e],
    !! and I_k = m I + I' - G D^{-1} G^T (m the member's mass with its point masses, s1, s2
    !! their first and second moments about the rod's centre). Inextensible members keep
    !! the angle row only. In water the rod's translational inertia is m I + A (A its
    !! added-mass block, self%wblk) and its rotational J + J_a: D11 gains eta^2 n.An + J_a,
    !! D12 eta n.Ae, D22 e.Ae, G's columns eta An and Ae, and I_k gains A.
    module procedure mass_factor
        real(wp) :: ixx, ixy, iyy, inx, iny, iex, iey, c, s, u, eta, lam, mb, s1, s2
        real(wp) :: d11, d12, d22, det, g1(2), g2(2), h1(2), h2(2), an(2), ae(2)
        integer :: k, n

        n = self%n
        status = STATUS_OK
        ixx = 0.0_wp
        ixy = 0.0_wp
        iyy = 0.0_wp
        u = 0.0_wp
        do k = n, 1, -1
            c = self%cs(1, k)
            s = self%cs(2, k)
            if (self%nu > 0) u = y(n + k)
            eta = u + 0.5_wp*self%l
            lam = u + self%l
            mb = self%mbar(k)
            s1 = self%pm_s1(k)
            s2 = self%pm_s2(k)
            ! I' n and I' e, n = (-s, c), e = (c, s)
            inx = -ixx*s + ixy*c
            iny = -ixy*s + iyy*c
            iex = ixx*c + ixy*s
            iey = ixy*c + iyy*s
            d11 = mb*eta**2 + 2.0_wp*s1*eta + s2 + self%inertia + lam**2*(-s*inx + c*iny)
            g1(1) = -(mb*eta + s1)*s + lam*inx
            g1(2) = (mb*eta + s1)*c + lam*iny
            if (self%water) then
                ! the added mass: A n and A e
                an = matmul(self%wblk(1:2, 1:2, k), [-s, c])
                ae = matmul(self%wblk(1:2, 1:2, k), [c, s])
                d11 = d11 + eta**2*(-s*an(1) + c*an(2)) + self%wblk(3, 3, k)
                g1 = g1 + eta*an
            end if
            if (self%nu > 0) then
                d12 = lam*(c*inx + s*iny)
                d22 = mb + c*iex + s*iey
                g2(1) = mb*c + iex
                g2(2) = mb*s + iey
                if (self%water) then
                    d12 = d12 + eta*(-s*ae(1) + c*ae(2))
                    d22 = d22 + c*ae(1) + s*ae(2)
                    g2 = g2 + ae
                end if
                det = d11*d22 - d12**2
                if (.not. (d11 > 0.0_wp .and. det > 0.0_wp)) then
                    status = STATUS_RECOVERABLE
                    return
                end if
                self%ab_dinv(1, 1, k) = d22/det
                self%ab_dinv(1, 2, k) = -d12/det
                self%ab_dinv(2, 1, k) = -d12/det
                self%ab_dinv(2, 2, k) = d11/det
                ! H = D^{-1} G^T: row 1 the angle's, row 2 the elongation's
                h1 = self%ab_dinv(1, 1, k)*g1 + self%ab_dinv(1, 2, k)*g2
                h2 = self%ab_dinv(2, 1, k)*g1 + self%ab_dinv(2, 2, k)*g2
            else
                if (.not. d11 > 0.0_wp) then
                    status = STATUS_RECOVERABLE
                    return
                end if
                self%ab_dinv(:, :, k) = 0.0_wp
                self%ab_dinv(1, 1, k) = 1.0_wp/d11
                g2 = 0.0_wp
                h1 = g1/d11
                h2 = 0.0_wp
            end if
            self%ab_g(:, 1, k) = g1
            self%ab_g(:, 2, k) = g2
            self%ab_h(1, :, k) = h1
            self%ab_h(2, :, k) = h2
            self%ab_lam(k) = lam
            ! I_k = m I + I' - G H
            ixx = mb + ixx - (g1(1)*h1(1) + g2(1)*h2(1))
            ixy = ixy - (g1(1)*h1(2) + g2(1)*h2(2))
            iyy = mb + iyy - (g1(2)*h1(2) + g2(2)*h2(2))
            if (self%water) then
                ixx = ixx + self%wblk(1, 1, k)
                ixy = ixy + self%wblk(1, 2, k)
                iyy = iyy + self%wblk(2, 2, k)
            end if
        end do
    end procedure mass_factor

    !> Solve M x = b with the factors of mass_factor (b in, x out), O(n): from the tip the
    !! bias forces z_k = z_{k+1} + G x0_k with x0_k = D^{-1} (b_k - (lambda n.z', e.z')), then
    !! from the top joint (acceleration 0) x_k = x0_k - H A_{k-1}, A_k = A_{k-1} + lambda
    !! phi_k'' n + u_k'' e.
    pure subroutine ab_solve(n, nu, cs, g, h, dinv, lam, b)
        integer, intent(in) :: n, nu
        real(wp), intent(in) :: cs(:, :), g(:, :, :), h(:, :, :), dinv(:, :, :), lam(:)
        real(wp), intent(inout) :: b(:)
        real(wp) :: x0(2, n), zx, zy, ax, ay, c1, c2, c, s, al, be
        integer :: k
        zx = 0.0_wp
        zy = 0.0_wp
        c2 = 0.0_wp
        do k = n, 1, -1
            c = cs(1, k)
            s = cs(2, k)
            c1 = b(k) - lam(k)*(-s*zx + c*zy)
            if (nu > 0) c2 = b(n + k) - (c*zx + s*zy)
            x0(1, k) = dinv(1, 1, k)*c1 + dinv(1, 2, k)*c2
            x0(2, k) = dinv(2, 1, k)*c1 + dinv(2, 2, k)*c2
            zx = zx + g(1, 1, k)*x0(1, k) + g(1, 2, k)*x0(2, k)
            zy = zy + g(2, 1, k)*x0(1, k) + g(2, 2, k)*x0(2, k)
        end do
        ax = 0.0_wp
        ay = 0.0_wp
        do k = 1, n
            c = cs(1, k)
            s = cs(2, k)
            al = x0(1, k) - (h(1, 1, k)*ax + h(1, 2, k)*ay)
            be = x0(2, k) - (h(2, 1, k)*ax + h(2, 2, k)*ay)
            b(k) = al
            if (nu > 0) b(n + k) = be
            ax = ax - lam(k)*al*s + be*c
            ay = ay + lam(k)*al*c + be*s
        end do
    end subroutine ab_solve

    !> Solve M x = b in place with the model's current factors.
    module procedure mass_solve
        call ab_solve(self%n, self%nu, self%cs, self%ab_g, self%ab_h, self%ab_dinv, &
                      self%ab_lam, b)
    end procedure mass_solve

    !> The dense M(q) from cos/sin of the angles and the elongations u (zero when
    !! inextensible), O(n^2): for k <= j, c = cos(phi_j - phi_k) = c_k c_j + s_k s_j,
    !! s = sin(phi_j - phi_k) = s_j c_k - c_j s_k (docs/theory/mpp.md, the table), then the
    !! point masses m_p J_p^T J_p.
    pure subroutine assemble_mass(n, nu, m, inertia, l, cs, u, pm_body, pm_r, pm_m, mm)
        integer, intent(in) :: n, nu, pm_body(:)
        real(wp), intent(in) :: m, inertia, l, cs(:, :), u(:), pm_r(:), pm_m(:)
        real(wp), intent(out) :: mm(:, :)
        real(wp) :: hk(n), lk(n), aj, bj, cjk, sjk, ak, al
        integer :: j, k, p, i
        hk = u + 0.5_wp*l
        lk = u + l
        do j = 1, n
            aj = hk(j) + real(n - j, wp)*lk(j)
            bj = real(n - j + 1, wp)
            do k = 1, j - 1
                cjk = cs(1, k)*cs(1, j) + cs(2, k)*cs(2, j)
                sjk = cs(2, j)*cs(1, k) - cs(1, j)*cs(2, k)
                mm(k, j) = m*cjk*(lk(k)*aj)
                mm(j, k) = mm(k, j)
                if (nu > 0) then
                    mm(n + k, n + j) = m*cjk*bj
                    mm(n + j, n + k) = mm(n + k, n + j)
                    mm(k, n + j) = m*sjk*(bj*lk(k))
                    mm(n + j, k) = mm(k, n + j)
                    mm(j, n + k) = -m*sjk*aj
                    mm(n + k, j) = mm(j, n + k)
                end if
            end do
            mm(j, j) = m*(hk(j)**2 + real(n - j, wp)*lk(j)**2) + inertia
            if (nu > 0) then
                mm(n + j, n + j) = m*bj
                mm(j, n + j) = 0.0_wp
                mm(n + j, j) = 0.0_wp
            end if
        end do
        ! point masses: m_p J_p^T J_p with J_p = dP/dq, P = C_i + r e_i: columns a_k n_k on
        ! phi_k (a_k = lambda_k for k < i, eta_i + r for k = i) and e_k on u_k, k <= i
        do p = 1, size(pm_body)
            i = pm_body(p)
            do j = 1, i
                al = merge(hk(i) + pm_r(p), lk(j), j == i)
                do k = 1, i
                    ak = merge(hk(i) + pm_r(p), lk(k), k == i)
                    cjk = cs(1, k)*cs(1, j) + cs(2, k)*cs(2, j)
                    sjk = cs(2, j)*cs(1, k) - cs(1, j)*cs(2, k)
                    if (k <= j) then
                        ! the symmetric pairs once, mirrored: M stays exactly symmetric
                        aj = pm_m(p)*cjk*(ak*al)
                        mm(k, j) = mm(k, j) + aj
                        if (k < j) mm(j, k) = mm(j, k) + aj
                        if (nu > 0) then
                            bj = pm_m(p)*cjk
                            mm(n + k, n + j) = mm(n + k, n + j) + bj
                            if (k < j) mm(n + j, n + k) = mm(n + j, n + k) + bj
                        end if
                    end if
                    if (nu > 0) then
                        ! (phi_k, u_j): a_k n_k . e_j = a_k sin(phi_j - phi_k)
                        mm(k, n + j) = mm(k, n + j) + pm_m(p)*ak*sjk
                        mm(n + j, k) = mm(n + j, k) + pm_m(p)*ak*sjk
                    end if
                end do
            end do
        end do
    end subroutine assemble_mass

    module procedure mpp_mass_dense
        real(wp) :: cs(2, self%n), phi(self%n), u(self%n), tt
        phi = y(1:self%n)
        call cos_sin(phi, cs)    ! as angles: the same M(q) as the solve's and the blocks'
        u = 0.0_wp
        if (self%nu > 0) u = y(self%n + 1:self%ndof)
        call assemble_mass(self%n, self%nu, self%m, self%inertia, self%l, cs, u, &
                           self%pm_body, self%pm_r, self%pm_m, mm)
        if (self%water) then
            tt = 0.0_wp
            if (present(t)) tt = t
            call water_mass_dense(self, tt, y, mm)
        end if
    end procedure mpp_mass_dense

    !> M(q) at time t (its added mass in water) into self%mm (self%cs holding the angles
    !! of y).
    subroutine assemble_mass_work(self, t, y)
        class(mpp_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp) :: u(self%n)
        u = 0.0_wp
        if (self%nu > 0) u = y(self%n + 1:self%ndof)
        call assemble_mass(self%n, self%nu, self%m, self%inertia, self%l, self%cs, u, &
                           self%pm_body, self%pm_r, self%pm_m, self%mm)
        if (self%water) call water_mass_dense(self, t, y, self%mm)
    end subroutine assemble_mass_work

    !> F of the implicit form M(q) y' = F: (q', r(t, q, q', 0)), the residual at zero
    !! accelerations (self%cs set to the angles of y on the way; `powers` as residual_core).
    subroutine implicit_form_rhs(self, t, y, f, powers)
        class(mpp_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: f(:)
        real(wp), intent(inout), optional :: powers(2)
        real(wp) :: zero(self%ndof)
        integer :: nd
        nd = self%ndof
        zero = 0.0_wp
        f(1:nd) = y(nd + 1:2*nd)
        call angles(self, y)
        call self%residual_core(t, y, zero, f(nd + 1:2*nd), powers=powers)
    end subroutine implicit_form_rhs

    module procedure mpp_rhs
        call rhs_powers(self, t, y, ydot, status)
    end procedure mpp_rhs

    module procedure rhs_powers
        integer :: nd
        nd = self%ndof
        call implicit_form_rhs(self, t, y, ydot, powers)
        call self%mass_factor(y, status)
        if (status /= STATUS_OK) return
        call mass_solve(self, ydot(nd + 1:2*nd))
        status = STATUS_OK
        if (.not. all(ieee_is_finite(ydot(nd + 1:2*nd)))) status = STATUS_RECOVERABLE
    end procedure rhs_powers

    module procedure mpp_implicit_rhs
        call implicit_form_rhs(self, t, y, f)
        status = STATUS_OK
        if (.not. all(ieee_is_finite(f))) status = STATUS_RECOVERABLE
    end procedure mpp_implicit_rhs

    module procedure mpp_mass_matrix
        integer :: j, nd
        nd = self%ndof
        call angles(self, y)
        call assemble_mass_work(self, t, y)
        do j = 1, nd
            mb(offset, j) = mb(offset, j) + 1.0_wp
        end do
        call add_to_band(mb, size(mb, 1), offset, self%mm, nd, nd)
        status = STATUS_OK
    end procedure mpp_mass_matrix

    module procedure derivatives
        real(wp) :: a(self%ndof), r0(self%ndof), col(self%ndof)
        integer :: nd, j

        nd = self%ndof
        call angles(self, y)
        a = 0.0_wp
        call self%residual_core(t, y, a, r0)
        call self%mass_factor(y, status)
        if (status /= STATUS_OK) return
        a = r0
        call mass_solve(self, a)
        call self%residual_core(t, y, a, r0)
        self%acc = a
        self%r0 = r0
        ! the effects' (and the water's) blocks at the bodies the residual left
        if (size(self%effects) > 0 .or. self%water) then
            self%ejac = 0.0_wp
            if (size(self%effects) > 0) call add_jacobians_of(self%effects, t, self%bodies, &
                                                              self%ejac)
            if (self%water) call water_jacobian(self, a)
        end if
        do j = 1, 2*nd
            call self%residual_column(t, y, a, j, col)
            self%dr(:, j) = col
        end do
        status = STATUS_OK
        if (.not. all(ieee_is_finite(self%dr))) status = STATUS_RECOVERABLE
        if (status /= STATUS_OK .or. .not. solved) return
        do j = 1, 2*nd
            call ab_solve(self%n, self%nu, self%cs, self%ab_g, self%ab_h, self%ab_dinv, &
                          self%ab_lam, self%dr(:, j))
        end do
        if (.not. all(ieee_is_finite(self%dr))) status = STATUS_RECOVERABLE
    end procedure derivatives

    !> Add the dense a(nr, nc) into band storage b(ld, *) (entry (i, j) at row
    !! offset + i - j) at rows i0 + 1 .. i0 + nr and columns j0 + 1 .. j0 + nc.
    pure subroutine add_to_band(b, ld, offset, a, i0, j0)
        integer, intent(in) :: ld, offset, i0, j0
        real(wp), intent(inout) :: b(ld, *)
        real(wp), intent(in) :: a(:, :)
        integer :: i, j, p
        do j = 1, size(a, 2)
            p = offset + i0 - j0 - j
            do i = 1, size(a, 1)
                b(p + i, j0 + j) = b(p + i, j0 + j) + a(i, j)
            end do
        end do
    end subroutine add_to_band

    module procedure mpp_jacobian
        integer :: nd, j

        nd = self%ndof
        call self%derivatives(t, y, .true., status)
        if (status /= STATUS_OK) return
        ! rows 1..nd: dq'/dv = I; rows nd+1..2nd: da/dy = M^{-1} dr/dy
        do j = 1, nd
            jb(offset - nd, nd + j) = jb(offset - nd, nd + j) + 1.0_wp
        end do
        call add_to_band(jb, size(jb, 1), offset, self%dr, nd, 0)
    end procedure mpp_jacobian

    module procedure mpp_second_order_blocks
        integer :: nd

        nd = self%ndof
        call self%derivatives(t, y, .not. implicit_form, status)
        if (status /= STATUS_OK) return
        if (implicit_form) then
            call assemble_mass_work(self, t, y)
            call add_to_band(mb, size(mb, 1), offset, self%mm, 0, 0)
        else
            mb(offset, 1:nd) = mb(offset, 1:nd) + 1.0_wp
        end if
        call add_to_band(kb, size(kb, 1), offset, self%dr(:, 1:nd), 0, 0)
        call add_to_band(cb, size(cb, 1), offset, self%dr(:, nd + 1:2*nd), 0, 0)
    end procedure mpp_second_order_blocks
end submodule ropedyn_mpp_kernels
