!> The RFEM's Jacobian as 3x6 blocks of element pairs (held by the model, written into the
!! first-order band or the second-order blocks by ropedyn_rfem_kernels), with the supports'
!! blocks. docs/physics-rfem.md.
submodule (ropedyn_rfem) ropedyn_rfem_jacobian
    implicit none

contains

    module procedure jacobian_blocks
        integer :: j, ka, kb, n
        real(wp) :: dwx, dwy, cd, sd, rx, ry, rp, fx, fy, fp, t6
        real(wp) :: ca, sa, cb, sb, ha, hb, dx, dy, dvx, dvy, wa, wb
        ! local coordinates of an SDE: (x, y, phi, x', y', phi') of element a, then of b
        real(wp) :: gx(12), gy(12), dfx(12), dfy(12), dfp(12), r1(12), r2(12), carry(3, 6)

        n = self%n
        call self%set_time(t)
        call angles(self, y)
        ! carry: the diagonal block of element b of the previous SDE (first: the top support)
        carry = 0.0_wp
        if (self%sup(1)%active) call support_jacobian(self, 1, y, carry)
        gx = 0.0_wp
        gy = 0.0_wp
        dfx = 0.0_wp
        dfy = 0.0_wp
        dfp = 0.0_wp
        do j = 2, n
            ! geometry and rates of SDE j (the module header's formulas, written out)
            ka = 6*(j - 2)
            kb = ka + 6
            ca = self%cs(1, j - 1)
            sa = self%cs(2, j - 1)
            cb = self%cs(1, j)
            sb = self%cs(2, j)
            ha = self%half(j - 1)
            hb = self%half(j)
            dx = y(kb + 1) - hb*cb - y(ka + 1) - ha*ca
            dy = y(kb + 2) - hb*sb - y(ka + 2) - ha*sa
            dwx = ca*dx + sa*dy
            dwy = -sa*dx + ca*dy
            cd = ca*cb + sa*sb
            sd = ca*sb - sa*cb
            ! gradients of the tension and shear strains (zero on the rates)
            gx(1) = -ca
            gx(2) = -sa
            gx(3) = dwy
            gx(7) = ca
            gx(8) = sa
            gx(9) = hb*sd
            gy(1) = sa
            gy(2) = -ca
            gy(3) = -(dwx + ha)
            gy(7) = -sa
            gy(8) = ca
            gy(9) = -hb*cd
            ! forces fx, fy, fp and their derivatives
            fx = 0.0_wp
            fy = 0.0_wp
            fp = 0.0_wp
            if (self%tension) then
                fx = self%cx*dwx
                dfx = self%cx*gx
            end if
            if (self%shear) then
                fy = self%cy*dwy
                dfy = self%cy*gy
            end if
            if (self%bending) then
                fp = self%cpj(j)*(y(kb + 3) - y(ka + 3))
                dfp(3) = -self%cpj(j)
                dfp(9) = self%cpj(j)
            end if
            if (self%damped) then
                dvx = y(kb + 4) - y(ka + 4)
                dvy = y(kb + 5) - y(ka + 5)
                wa = y(ka + 6)
                wb = y(kb + 6)
                rx = ca*dvx + sa*dvy + dwy*wa + hb*sd*wb
                ry = -sa*dvx + ca*dvy - (dwx + ha)*wa - hb*cd*wb
                rp = wb - wa
                ! d(rate)/dq = H q' (ry and -rx on phi_a), d(rate)/dq' = the gradient
                if (self%tension) then
                    fx = fx + self%bx*rx
                    dfx(1) = dfx(1) + self%bx*sa*wa
                    dfx(2) = dfx(2) - self%bx*ca*wa
                    dfx(3) = dfx(3) + self%bx*ry
                    dfx(7) = dfx(7) - self%bx*sa*wa
                    dfx(8) = dfx(8) + self%bx*ca*wa
                    dfx(9) = dfx(9) + self%bx*hb*cd*(wb - wa)
                    dfx(4:6) = self%bx*gx(1:3)
                    dfx(10:12) = self%bx*gx(7:9)
                end if
                if (self%shear) then
                    fy = fy + self%by*ry
                    dfy(1) = dfy(1) + self%by*ca*wa
                    dfy(2) = dfy(2) + self%by*sa*wa
                    dfy(3) = dfy(3) - self%by*rx
                    dfy(7) = dfy(7) - self%by*ca*wa
                    dfy(8) = dfy(8) - self%by*sa*wa
                    dfy(9) = dfy(9) + self%by*hb*sd*(wb - wa)
                    dfy(4:6) = self%by*gy(1:3)
                    dfy(10:12) = self%by*gy(7:9)
                end if
                if (self%bending) then
                    fp = fp + self%bpj(j)*rp
                    dfp(6) = -self%bpj(j)
                    dfp(12) = self%bpj(j)
                end if
            end if
            ! rows of element a: d(F, fy (dwx + h_a) - fx dwy + fp); of element b:
            ! d(-F, -h_b (fx sd - fy cd) - fp); columns: a's coordinates, then b's
            r1 = ca*dfx - sa*dfy
            r2 = sa*dfx + ca*dfy
            r1(3) = r1(3) - fx*sa - fy*ca
            r2(3) = r2(3) + fx*ca - fy*sa
            self%blk(1, :, 0, j - 1) = carry(1, :) + r1(1:6)
            self%blk(2, :, 0, j - 1) = carry(2, :) + r2(1:6)
            self%blk(3, :, 0, j - 1) = carry(3, :) + (dwx + ha)*dfy(1:6) - dwy*dfx(1:6) &
                                       + dfp(1:6) + fy*gx(1:6) - fx*gy(1:6)
            self%blk(1, :, 1, j - 1) = r1(7:12)
            self%blk(2, :, 1, j - 1) = r2(7:12)
            self%blk(3, :, 1, j - 1) = (dwx + ha)*dfy(7:12) - dwy*dfx(7:12) + dfp(7:12) &
                                       + fy*gx(7:12) - fx*gy(7:12)
            t6 = hb*(fx*cd + fy*sd)
            self%blk(1, :, -1, j) = -r1(1:6)
            self%blk(2, :, -1, j) = -r2(1:6)
            self%blk(3, :, -1, j) = -hb*(sd*dfx(1:6) - cd*dfy(1:6)) - dfp(1:6)
            self%blk(3, 3, -1, j) = self%blk(3, 3, -1, j) + t6
            carry(1, :) = -r1(7:12)
            carry(2, :) = -r2(7:12)
            carry(3, :) = -hb*(sd*dfx(7:12) - cd*dfy(7:12)) - dfp(7:12)
            carry(3, 3) = carry(3, 3) - t6
        end do
        if (self%sup(2)%active) call support_jacobian(self, 2, y, carry)
        self%blk(:, :, 0, n) = carry
        ! external effects: 3x6 blocks on each element's own coordinates
        if (size(self%effects) > 0) then
            call self%fill_bodies(y)
            call add_jacobians_of(self%effects, t, self%bodies, self%blk(:, :, 0, :))
        end if
    end procedure jacobian_blocks

    !> Add the derivatives of support k's generalized force with respect to its element's
    !! (x, y, phi, x', y', phi') to blk(3, 6).
    pure subroutine support_jacobian(self, k, y, blk)
        class(rfem_t), intent(in) :: self
        integer, intent(in) :: k
        real(wp), intent(in) :: y(:)
        real(wp), intent(inout) :: blk(3, 6)
        real(wp) :: h, co, si, w, d(2), fs(2), sg
        integer :: m
        associate (sp => self%sup(k))
            m = 6*(sp%elem - 1)
            h = self%half(sp%elem)
            co = cos(y(m + 3))
            si = sin(y(m + 3))
            w = y(m + 6)
            sg = sp%sgn
            if (sp%translational) then
                ! F = Ct d + Bt d' acts as -sgn F on the centre and h n.F as moment
                d(1) = sg*(y(m + 1) - sp%anchor(1)) - h*co
                d(2) = sg*(y(m + 2) - sp%anchor(2)) - h*si
                fs = sp%ct*d
                blk(1, 1) = blk(1, 1) - sp%ct
                blk(2, 2) = blk(2, 2) - sp%ct
                blk(1, 3) = blk(1, 3) - sg*h*sp%ct*si
                blk(2, 3) = blk(2, 3) + sg*h*sp%ct*co
                blk(3, 1) = blk(3, 1) - sg*h*sp%ct*si
                blk(3, 2) = blk(3, 2) + sg*h*sp%ct*co
                if (sp%damped_t) then
                    fs(1) = fs(1) + sp%bt*(sg*(y(m + 4) - sp%anchor_vel(1)) + h*w*si)
                    fs(2) = fs(2) + sp%bt*(sg*(y(m + 5) - sp%anchor_vel(2)) - h*w*co)
                    blk(1, 3) = blk(1, 3) - sg*h*sp%bt*w*co
                    blk(2, 3) = blk(2, 3) - sg*h*sp%bt*w*si
                    blk(1, 4) = blk(1, 4) - sp%bt
                    blk(2, 5) = blk(2, 5) - sp%bt
                    blk(1, 6) = blk(1, 6) - sg*h*sp%bt*si
                    blk(2, 6) = blk(2, 6) + sg*h*sp%bt*co
                    blk(3, 4) = blk(3, 4) - sg*h*sp%bt*si
                    blk(3, 5) = blk(3, 5) + sg*h*sp%bt*co
                    blk(3, 6) = blk(3, 6) - sp%bt*h**2
                end if
                blk(3, 3) = blk(3, 3) - h*(co*fs(1) + si*fs(2)) - sp%ct*h**2
            end if
            if (sp%rotational) then
                blk(3, 3) = blk(3, 3) - sp%cr
                if (sp%damped_r) blk(3, 6) = blk(3, 6) - sp%br
            end if
        end associate
    end subroutine support_jacobian
end submodule ropedyn_rfem_jacobian
