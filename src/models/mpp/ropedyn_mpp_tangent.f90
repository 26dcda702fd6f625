!> The MPP's exact residual tangent: one column of d r(q, q', a)/d(q, q') in O(n) (the
!! Jacobian and the implicit second-order blocks are built from these columns, in
!! ropedyn_mpp_kernels). The derivation is in docs/theory/mpp.md.
!!
!! A column perturbs one variable of one member m; its steps: the perturbation of member m's
!! kinematics (perturbation), the members below m (members_below), member m itself
!! (member_itself), the members above (members_above) and the springs on m's own variables
!! (own_springs). The first three pass the suffix sum dws of the force changes from the
!! tip up (suffix_step).
submodule (ropedyn_mpp) ropedyn_mpp_tangent
    implicit none

    !> The change of member m's kinematics with one of its variables: which (kind 1 angle,
    !! 2 elongation, 3 and 4 their rates), its axes e, n and their changes de, dn, the centre
    !! and joint distances hk, lk (m) and their changes, its rates phd, ud and accelerations
    !! pdd, the changes of its centre's acceleration (dcacc), position (dcb) and velocity
    !! (dvb), and the shifts sh_a, sh_p, sh_v of every joint and centre below it.
    type :: perturbation_t
        integer :: m, kind
        real(wp) :: e(2), nv(2), de(2), dn(2)
        real(wp) :: hk, lk, dhk, dlk, phd, pdd, dphd, dud, dphi
        real(wp) :: dcacc(2), dcb(2), dvb(2), sh_a(2), sh_p(2), sh_v(2)
    end type perturbation_t

contains

    module procedure residual_column
        real(wp) :: dws(2), dcouple
        type(motion_state_t) :: top, bottom
        type(perturbation_t) :: p
        logical :: bottom_on, effects

        ! the effects' blocks self%ejac hold the water's too
        effects = size(self%effects) > 0 .or. self%water
        p = perturbation(self, y, qacc, j)

        ! the bottom support's force on the tip
        call self%supports_at(t, top, bottom, bottom_on)
        dws = 0.0_wp
        dcouple = 0.0_wp
        if (bottom_on) then
            dws = -self%k_sup*p%sh_p - self%d_sup*p%sh_v
            call slack_pin_change(self, p, self%tip - bottom%p, dws, dcouple)
        end if

        col = 0.0_wp
        call members_below(self, y, p, effects, dws, col)
        call member_itself(self, y, p, effects, dws, col)
        call members_above(self, y, p%m, dws, col)
        call own_springs(self, y, p, bottom_on, col)
        col(self%n) = col(self%n) - dcouple
    end procedure residual_column

    !> A slack bottom pin's spring (bottom_pin_spring, d = P_n - P_bottom): its force -k u n
    !! changes by -k (du n + u dn) instead of -k sh_p (into dws, which holds the damper's
    !! part already), and its couple k u s by dcouple = k (du s + u ds), with du = sh_p.n +
    !! d.dn, ds = -sh_p.e - d.de, where e and n turn only with member n's angle (de = n,
    !! dn = -e); dws and dcouple unchanged where the spring is not slack.
    pure subroutine slack_pin_change(self, p, d, dws, dcouple)
        class(mpp_t), intent(in) :: self
        type(perturbation_t), intent(in) :: p
        real(wp), intent(in) :: d(2)
        real(wp), intent(inout) :: dws(2), dcouple
        real(wp) :: e(2), nv(2), de(2), dn(2), s, u, du, ds
        e = self%cs(:, self%n)
        nv = [-e(2), e(1)]
        s = -dot_product(e, d)
        if (.not. s < self%stretch_floor()) return
        u = dot_product(nv, d)
        de = 0.0_wp
        dn = 0.0_wp
        if (p%kind == 1 .and. p%m == self%n) then
            de = nv
            dn = -e
        end if
        du = dot_product(p%sh_p, nv) + dot_product(d, dn)
        ds = -dot_product(p%sh_p, e) - dot_product(d, de)
        dws = dws + self%k_sup*p%sh_p - self%k_sup*(du*nv + u*dn)
        dcouple = self%k_sup*(du*s + u*ds)
    end subroutine slack_pin_change

    !> The perturbation of member m's kinematics by variable j of the column (perturbation_t).
    pure function perturbation(self, y, qacc, j) result(p)
        class(mpp_t), intent(in) :: self
        real(wp), intent(in) :: y(:), qacc(:)
        integer, intent(in) :: j
        type(perturbation_t) :: p
        real(wp) :: c, s, u, ud, udd, a1, a2, da1, da2
        integer :: n, nd, m

        n = self%n
        nd = self%ndof
        ! the member m and which of its variables (1 angle, 2 elongation, 3 and 4 their rates)
        if (j <= nd) then
            p%kind = merge(1, 2, j <= n)
            m = merge(j, j - n, j <= n)
        else
            p%kind = merge(3, 4, j - nd <= n)
            m = merge(j - nd, j - nd - n, j - nd <= n)
        end if
        p%m = m
        c = self%cs(1, m)
        s = self%cs(2, m)
        p%e = [c, s]
        p%nv = [-s, c]
        u = 0.0_wp
        ud = 0.0_wp
        udd = 0.0_wp
        if (self%nu > 0) then
            u = y(n + m)
            ud = y(nd + n + m)
            udd = qacc(n + m)
        end if
        p%phd = y(nd + m)
        p%pdd = qacc(m)
        p%hk = u + 0.5_wp*self%l
        p%lk = u + self%l
        p%de = 0.0_wp
        p%dn = 0.0_wp
        p%dhk = 0.0_wp
        p%dphd = 0.0_wp
        p%dud = 0.0_wp
        p%dphi = 0.0_wp
        select case (p%kind)
        case (1)
            p%de = p%nv
            p%dn = -p%e
            p%dphi = 1.0_wp
        case (2)
            p%dhk = 1.0_wp
        case (3)
            p%dphd = 1.0_wp
        case (4)
            p%dud = 1.0_wp
        end select
        p%dlk = p%dhk
        associate (e => p%e, nv => p%nv, de => p%de, dn => p%dn, hk => p%hk, lk => p%lk, &
                   dhk => p%dhk, dlk => p%dlk, phd => p%phd, pdd => p%pdd, &
                   dphd => p%dphd, dud => p%dud)
            ! member m: its centre's acceleration, position and velocity, and the shifts
            ! sh_a, sh_p, sh_v of every joint and centre below it
            a1 = hk*pdd + 2.0_wp*ud*phd
            a2 = udd - hk*phd**2
            da1 = dhk*pdd + 2.0_wp*(dud*phd + ud*dphd)
            da2 = -dhk*phd**2 - 2.0_wp*hk*phd*dphd
            p%dcacc = da1*nv + a1*dn + da2*e + a2*de
            a1 = lk*pdd + 2.0_wp*ud*phd
            a2 = udd - lk*phd**2
            da1 = dlk*pdd + 2.0_wp*(dud*phd + ud*dphd)
            da2 = -dlk*phd**2 - 2.0_wp*lk*phd*dphd
            p%sh_a = da1*nv + a1*dn + da2*e + a2*de
            p%dcb = dhk*e + hk*de
            p%dvb = (dhk*phd + hk*dphd)*nv + hk*phd*dn + dud*e + ud*de
            p%sh_p = dlk*e + lk*de
            p%sh_v = (dlk*phd + lk*dphd)*nv + lk*phd*dn + dud*e + ud*de
        end associate
    end function perturbation

    !> Members below m: w_k shifts by -m_k sh_a and the effects' response to sh_p, sh_v.
    pure subroutine members_below(self, y, p, effects, dws, col)
        class(mpp_t), intent(in) :: self
        real(wp), intent(in) :: y(:)
        type(perturbation_t), intent(in) :: p
        logical, intent(in) :: effects
        real(wp), intent(inout) :: dws(2), col(:)
        real(wp) :: dw(2), dmom
        integer :: k
        associate (sh_a => p%sh_a, sh_p => p%sh_p, sh_v => p%sh_v)
            do k = self%n, p%m + 1, -1
                dw = -self%mbar(k)*sh_a
                dmom = -self%pm_s1(k)*(-self%cs(2, k)*sh_a(1) + self%cs(1, k)*sh_a(2))
                if (self%water) then
                    ! the added mass's inertia -blk (C_k'', phi_k'') at the shifted acceleration
                    dw = dw - matmul(self%wblk(1:2, 1:2, k), sh_a)
                    dmom = dmom - dot_product(self%wblk(3, 1:2, k), sh_a)
                end if
                if (effects) then
                    dw = dw + matmul(self%ejac(1:2, 1:2, k), sh_p) &
                         + matmul(self%ejac(1:2, 4:5, k), sh_v)
                    dmom = dmom + dot_product(self%ejac(3, 1:2, k), sh_p) &
                           + dot_product(self%ejac(3, 4:5, k), sh_v)
                end if
                call suffix_step(self, y, k, dw, dmom, dws, col)
            end do
        end associate
    end subroutine members_below

    !> Member m itself: its inertia, water and point masses at dcacc, the effects' response,
    !! and its own rows r[phi_m] = n.(h w_m + l ws_{m+1}) + ..., r[u_m] = e.ws_m.
    pure subroutine member_itself(self, y, p, effects, dws, col)
        class(mpp_t), intent(in) :: self
        real(wp), intent(in) :: y(:)
        type(perturbation_t), intent(in) :: p
        logical, intent(in) :: effects
        real(wp), intent(inout) :: dws(2), col(:)
        real(wp) :: dw(2), dmom, fp(2), dfp(2), pv(2)
        integer :: m, q
        m = p%m
        associate (e => p%e, nv => p%nv, de => p%de, dn => p%dn, phd => p%phd, &
                   pdd => p%pdd, dphd => p%dphd, dcacc => p%dcacc, dphi => p%dphi)
            dw = -self%m*dcacc
            dmom = 0.0_wp
            if (self%water) then
                dw = dw - matmul(self%wblk(1:2, 1:2, m), dcacc)
                dmom = dmom - dot_product(self%wblk(3, 1:2, m), dcacc)
            end if
            do q = 1, size(self%pm_body)
                if (self%pm_body(q) /= m) cycle
                pv = self%cacc(:, m) + self%pm_r(q)*(pdd*nv - phd**2*e)
                fp = -self%pm_m(q)*pv
                fp(1) = fp(1) + self%pm_m(q)*self%g
                dfp = -self%pm_m(q)*(dcacc + self%pm_r(q)*(pdd*dn - 2.0_wp*phd*dphd*e - phd**2*de))
                dw = dw + dfp
                dmom = dmom + self%pm_r(q)*(dot_product(dn, fp) + dot_product(nv, dfp))
            end do
            if (effects) then
                dw = dw + matmul(self%ejac(1:2, 1:2, m), p%dcb) + self%ejac(1:2, 3, m)*dphi &
                     + matmul(self%ejac(1:2, 4:5, m), p%dvb) + self%ejac(1:2, 6, m)*dphd
                dmom = dmom + dot_product(self%ejac(3, 1:2, m), p%dcb) + self%ejac(3, 3, m)*dphi &
                       + dot_product(self%ejac(3, 4:5, m), p%dvb) + self%ejac(3, 6, m)*dphd
            end if
            ! r[phi_m] = n.(h w_m + l ws_{m+1}) + ..., r[u_m] = e.ws_m: their own variables
            col(m) = dot_product(dn, p%hk*self%w(:, m) + p%lk*self%wsum(:, m + 1)) &
                     + dot_product(nv, p%dhk*self%w(:, m) + p%dlk*self%wsum(:, m + 1))
            if (self%nu > 0) col(self%n + m) = dot_product(de, self%wsum(:, m))
        end associate
        call suffix_step(self, y, m, dw, dmom, dws, col)
    end subroutine member_itself

    !> Members above m: only the suffix sums change (by dws, the bottom support's change).
    pure subroutine members_above(self, y, m, dws, col)
        class(mpp_t), intent(in) :: self
        real(wp), intent(in) :: y(:)
        integer, intent(in) :: m
        real(wp), intent(in) :: dws(2)
        real(wp), intent(inout) :: col(:)
        real(wp) :: c, s, lk
        integer :: k, n
        n = self%n
        do k = m - 1, 1, -1
            c = self%cs(1, k)
            s = self%cs(2, k)
            lk = self%l
            if (self%nu > 0) lk = lk + y(n + k)
            col(k) = lk*(-s*dws(1) + c*dws(2))
            if (self%nu > 0) col(n + k) = c*dws(1) + s*dws(2)
        end do
    end subroutine members_above

    !> Springs, dampers and clamps on member m's own variables.
    pure subroutine own_springs(self, y, p, bottom_on, col)
        class(mpp_t), intent(in) :: self
        real(wp), intent(in) :: y(:)
        type(perturbation_t), intent(in) :: p
        logical, intent(in) :: bottom_on
        real(wp), intent(inout) :: col(:)
        real(wp) :: cb, db
        integer :: n, m
        n = self%n
        m = p%m
        select case (p%kind)
        case (2)
            col(n + m) = col(n + m) - self%ksj(m)*self%spring_slope(y(n + m))
        case (4)
            col(n + m) = col(n + m) - self%dsj(m)
        case (1, 3)
            cb = merge(self%cb, self%db, p%kind == 1)
            if (m >= 2) then
                col(m) = col(m) - cb
                col(m - 1) = col(m - 1) + cb
            end if
            if (m < n) then
                col(m + 1) = col(m + 1) + cb
                col(m) = col(m) - cb
            end if
            db = 0.0_wp
            if (m == 1 .and. self%top_clamped) db = merge(self%c_rot, self%d_rot, p%kind == 1)
            if (m == n .and. self%bottom == 2 .and. bottom_on) &
                db = db + merge(self%c_rot, self%d_rot, p%kind == 1)
            col(m) = col(m) - db
        end select
    end subroutine own_springs

    !> Member k's rows from its force change dw, moment change dmom and the suffix sum
    !! of the changes below it (dws, then including dw).
    pure subroutine suffix_step(self, y, k, dw, dmom, dws, col)
        class(mpp_t), intent(in) :: self
        real(wp), intent(in) :: y(:)
        integer, intent(in) :: k
        real(wp), intent(in) :: dw(2), dmom
        real(wp), intent(inout) :: dws(2), col(:)
        real(wp) :: ck, sk, hkk, lkk
        integer :: n
        n = self%n
        ck = self%cs(1, k)
        sk = self%cs(2, k)
        hkk = 0.5_wp*self%l
        lkk = self%l
        if (self%nu > 0) then
            hkk = hkk + y(n + k)
            lkk = lkk + y(n + k)
        end if
        col(k) = col(k) - sk*(hkk*dw(1) + lkk*dws(1)) + ck*(hkk*dw(2) + lkk*dws(2)) + dmom
        dws = dws + dw
        if (self%nu > 0) col(n + k) = col(n + k) + ck*dws(1) + sk*dws(2)
    end subroutine suffix_step
end submodule ropedyn_mpp_tangent
