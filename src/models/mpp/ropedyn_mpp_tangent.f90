!> The MPP's exact residual tangent: one column of d r(q, q', a)/d(q, q') in O(n) (the
!! Jacobian and the implicit second-order blocks are built from these columns, in
!! ropedyn_mpp_kernels). The derivation is in docs/theory/mpp.md.
submodule (ropedyn_mpp) ropedyn_mpp_tangent
    implicit none

contains

    module procedure residual_column
        real(wp) :: c, s, e(2), nv(2), de(2), dn(2), u, ud, phd, pdd, udd, hk, lk
        real(wp) :: dhk, dlk, dphd, dud, dphi, a1, a2, da1, da2, dcacc(2), sh_a(2), sh_p(2), sh_v(2)
        real(wp) :: dcb(2), dvb(2), dw(2), dmom, dws(2), fp(2), dfp(2), pv(2), cb, db
        type(motion_state_t) :: top, bottom
        logical :: bottom_on, effects
        integer :: n, nd, m, kind, k, p

        n = self%n
        nd = self%ndof
        ! the effects' blocks self%ejac hold the water's too
        effects = size(self%effects) > 0 .or. self%water
        ! the member m and which of its variables (1 angle, 2 elongation, 3 and 4 their rates)
        if (j <= nd) then
            kind = merge(1, 2, j <= n)
            m = merge(j, j - n, j <= n)
        else
            kind = merge(3, 4, j - nd <= n)
            m = merge(j - nd, j - nd - n, j - nd <= n)
        end if
        c = self%cs(1, m)
        s = self%cs(2, m)
        e = [c, s]
        nv = [-s, c]
        u = 0.0_wp
        ud = 0.0_wp
        udd = 0.0_wp
        if (self%nu > 0) then
            u = y(n + m)
            ud = y(nd + n + m)
            udd = qacc(n + m)
        end if
        phd = y(nd + m)
        pdd = qacc(m)
        hk = u + 0.5_wp*self%l
        lk = u + self%l
        de = 0.0_wp
        dn = 0.0_wp
        dhk = 0.0_wp
        dphd = 0.0_wp
        dud = 0.0_wp
        dphi = 0.0_wp
        select case (kind)
        case (1)
            de = nv
            dn = -e
            dphi = 1.0_wp
        case (2)
            dhk = 1.0_wp
        case (3)
            dphd = 1.0_wp
        case (4)
            dud = 1.0_wp
        end select
        dlk = dhk
        ! member m: its centre's acceleration, position and velocity, and the shifts sh_a, sh_p,
        ! sh_v of every joint and centre below it
        a1 = hk*pdd + 2.0_wp*ud*phd
        a2 = udd - hk*phd**2
        da1 = dhk*pdd + 2.0_wp*(dud*phd + ud*dphd)
        da2 = -dhk*phd**2 - 2.0_wp*hk*phd*dphd
        dcacc = da1*nv + a1*dn + da2*e + a2*de
        a1 = lk*pdd + 2.0_wp*ud*phd
        a2 = udd - lk*phd**2
        da1 = dlk*pdd + 2.0_wp*(dud*phd + ud*dphd)
        da2 = -dlk*phd**2 - 2.0_wp*lk*phd*dphd
        sh_a = da1*nv + a1*dn + da2*e + a2*de
        dcb = dhk*e + hk*de
        dvb = (dhk*phd + hk*dphd)*nv + hk*phd*dn + dud*e + ud*de
        sh_p = dlk*e + lk*de
        sh_v = (dlk*phd + lk*dphd)*nv + lk*phd*dn + dud*e + ud*de

        ! the bottom support's force on the tip
        call self%supports_at(t, top, bottom, bottom_on)
        dws = 0.0_wp
        if (bottom_on) dws = -self%k_sup*sh_p - self%d_sup*sh_v

        ! members below m: w_k shifts by -m_k sh_a and the effects' response to sh_p, sh_v
        col = 0.0_wp
        do k = n, m + 1, -1
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
            call suffix_step(k, dw, dmom)
        end do

        ! member m itself
        dw = -self%m*dcacc
        dmom = 0.0_wp
        if (self%water) then
            dw = dw - matmul(self%wblk(1:2, 1:2, m), dcacc)
            dmom = dmom - dot_product(self%wblk(3, 1:2, m), dcacc)
        end if
        do p = 1, size(self%pm_body)
            if (self%pm_body(p) /= m) cycle
            pv = self%cacc(:, m) + self%pm_r(p)*(pdd*nv - phd**2*e)
            fp = -self%pm_m(p)*pv
            fp(1) = fp(1) + self%pm_m(p)*self%g
            dfp = -self%pm_m(p)*(dcacc + self%pm_r(p)*(pdd*dn - 2.0_wp*phd*dphd*e - phd**2*de))
            dw = dw + dfp
            dmom = dmom + self%pm_r(p)*(dot_product(dn, fp) + dot_product(nv, dfp))
        end do
        if (effects) then
            dw = dw + matmul(self%ejac(1:2, 1:2, m), dcb) + self%ejac(1:2, 3, m)*dphi &
                 + matmul(self%ejac(1:2, 4:5, m), dvb) + self%ejac(1:2, 6, m)*dphd
            dmom = dmom + dot_product(self%ejac(3, 1:2, m), dcb) + self%ejac(3, 3, m)*dphi &
                   + dot_product(self%ejac(3, 4:5, m), dvb) + self%ejac(3, 6, m)*dphd
        end if
        ! r[phi_m] = n.(h w_m + l ws_{m+1}) + ..., r[u_m] = e.ws_m: their own variables
        col(m) = dot_product(dn, hk*self%w(:, m) + lk*self%wsum(:, m + 1)) &
                 + dot_product(nv, dhk*self%w(:, m) + dlk*self%wsum(:, m + 1))
        if (self%nu > 0) col(n + m) = dot_product(de, self%wsum(:, m))
        call suffix_step(m, dw, dmom)

        ! members above m: only the suffix sums change
        do k = m - 1, 1, -1
            c = self%cs(1, k)
            s = self%cs(2, k)
            lk = self%l
            if (self%nu > 0) lk = lk + y(n + k)
            col(k) = lk*(-s*dws(1) + c*dws(2))
            if (self%nu > 0) col(n + k) = c*dws(1) + s*dws(2)
        end do

        ! springs, dampers and clamps on member m's own variables
        select case (kind)
        case (2)
            col(n + m) = col(n + m) - self%ksj(m)*self%spring_slope(y(n + m))
        case (4)
            col(n + m) = col(n + m) - self%dsj(m)
        case (1, 3)
            cb = merge(self%cb, self%db, kind == 1)
            if (m >= 2) then
                col(m) = col(m) - cb
                col(m - 1) = col(m - 1) + cb
            end if
            if (m < n) then
                col(m + 1) = col(m + 1) + cb
                col(m) = col(m) - cb
            end if
            db = 0.0_wp
            if (m == 1 .and. self%top_clamped) db = merge(self%c_rot, self%d_rot, kind == 1)
            if (m == n .and. self%bottom == 2 .and. bottom_on) &
                db = db + merge(self%c_rot, self%d_rot, kind == 1)
            col(m) = col(m) - db
        end select
    contains
        !> Member k's rows from its force change dw, moment change dmom and the suffix sum
        !! of the changes below it (dws, then including dw).
        subroutine suffix_step(k, dw, dmom)
            integer, intent(in) :: k
            real(wp), intent(in) :: dw(2), dmom
            real(wp) :: ck, sk, hkk, lkk
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
    end procedure residual_column
end submodule ropedyn_mpp_tangent
