!> The RFEM kernels: generalized forces, right-hand side, analytic Jacobian (as blocks of
!! element pairs, for the first-order band and for the second-order blocks), energies and
!! the dissipation and external power (the derivation is in docs/physics-rfem.md).
!!
!! Each kernel makes one pass over the internal SDEs j = 2 .. n (elements a = j-1, b = j),
!! with cos and sin of every angle computed once per call (self%cs):
!!     d = c_b - h_b e_b - c_a - h_a e_a,  dwx = e_a.d (tension),  dwy = n_a.d (shear),
!!     cd = e_a.e_b = cos(phi_b - phi_a),  sd = n_a.e_b = sin(phi_b - phi_a),
!! the strain rates (only when damping is on)
!!     rx = e_a.(v_b - v_a) + dwy w_a + h_b sd w_b,
!!     ry = n_a.(v_b - v_a) - (dwx + h_a) w_a - h_b cd w_b,   rp = w_b - w_a,
!! the SDE forces fx = Cx dwx + Bx rx, fy = Cy dwy + By ry, fp = Cp (phi_b - phi_a) + Bp rp
!! (each only when its strain is on) and, with F = fx e_a + fy n_a, the generalized forces
!!     element a: (F, fy (dwx + h_a) - fx dwy + fp),   element b: (-F, -h_b (fx sd - fy cd) - fp).
!! The Jacobian differentiates these expressions directly (rows of element a and b with
!! respect to the 12 coordinates and rates of both), which is the per-strain formula
!! dF/dq = -C g g^T - (C s + B s') H - B g (H q')^T, dF/dq' = -B g g^T summed over the
!! three strains. Supports and effects are separate small steps, only when present.
submodule (ropedyn_rfem) ropedyn_rfem_kernels
    use ropedyn_trig, only: cos_sin
    implicit none

contains

    !> cos and sin of every element angle into self%cs, once per call (gathered, then
    !! ropedyn_trig's vectorizing routine).
    module procedure angles
        integer :: i
        do i = 1, self%n
            self%phi(i) = y(6*i - 3)
        end do
        call cos_sin(self%phi, self%cs)
    end procedure angles

    !> Add the generalized force of support k (translational spring and damper on d, and
    !! for a clamp the rotational one) to f(3), the force on its element; with `energy`
    !! its spring energy to e_el.
    pure subroutine support_force(self, k, y, f, energy, e_el)
        class(rfem_t), intent(in) :: self
        integer, intent(in) :: k
        real(wp), intent(in) :: y(:)
        real(wp), intent(inout) :: f(3)
        logical, intent(in) :: energy
        real(wp), intent(inout) :: e_el
        real(wp) :: h, co, si, d(2), fs(2), s, fr
        integer :: m
        associate (sp => self%sup(k))
            m = 6*(sp%elem - 1)
            h = self%half(sp%elem)
            co = cos(y(m + 3))
            si = sin(y(m + 3))
            if (sp%translational) then
                ! d = sgn (c - P) - h e, d' = sgn (v - P') - h w n
                d(1) = sp%sgn*(y(m + 1) - sp%anchor(1)) - h*co
                d(2) = sp%sgn*(y(m + 2) - sp%anchor(2)) - h*si
                fs = sp%ct*d
                if (energy) e_el = e_el + 0.5_wp*sp%ct*(d(1)**2 + d(2)**2)
                if (sp%damped_t) then
                    fs(1) = fs(1) + sp%bt*(sp%sgn*(y(m + 4) - sp%anchor_vel(1)) + h*y(m + 6)*si)
                    fs(2) = fs(2) + sp%bt*(sp%sgn*(y(m + 5) - sp%anchor_vel(2)) - h*y(m + 6)*co)
                end if
                f(1:2) = f(1:2) - sp%sgn*fs
                f(3) = f(3) + h*(co*fs(2) - si*fs(1))
            end if
            if (sp%rotational) then
                s = sp%sgn*(y(m + 3) - sp%angle)
                fr = sp%cr*s
                if (energy) e_el = e_el + 0.5_wp*sp%cr*s**2
                if (sp%damped_r) fr = fr + sp%br*sp%sgn*(y(m + 6) - sp%angle_rate)
                f(3) = f(3) - sp%sgn*fr
            end if
        end associate
    end subroutine support_force

    !> Power of support k: its dissipation (W) and, when it moves, the work rate of its
    !! anchor on the rope (W): the force of the support times -sgn P', the moment times
    !! -sgn psi' (the strain rate's explicit part).
    pure subroutine support_power(self, k, y, power, work)
        class(rfem_t), intent(in) :: self
        integer, intent(in) :: k
        real(wp), intent(in) :: y(:)
        real(wp), intent(inout) :: power, work
        real(wp) :: h, co, si, d(2), dd(2), fs(2), s, sd, fr
        integer :: m
        associate (sp => self%sup(k))
            m = 6*(sp%elem - 1)
            h = self%half(sp%elem)
            co = cos(y(m + 3))
            si = sin(y(m + 3))
            if (sp%translational) then
                d(1) = sp%sgn*(y(m + 1) - sp%anchor(1)) - h*co
                d(2) = sp%sgn*(y(m + 2) - sp%anchor(2)) - h*si
                dd(1) = sp%sgn*(y(m + 4) - sp%anchor_vel(1)) + h*y(m + 6)*si
                dd(2) = sp%sgn*(y(m + 5) - sp%anchor_vel(2)) - h*y(m + 6)*co
                fs = sp%ct*d
                if (sp%damped_t) then
                    fs = fs + sp%bt*dd
                    power = power + sp%bt*(dd(1)**2 + dd(2)**2)
                end if
                if (self%moving(k)) work = work - sp%sgn*(fs(1)*sp%anchor_vel(1) &
                                                          + fs(2)*sp%anchor_vel(2))
            end if
            if (sp%rotational) then
                s = sp%sgn*(y(m + 3) - sp%angle)
                sd = sp%sgn*(y(m + 6) - sp%angle_rate)
                fr = sp%cr*s
                if (sp%damped_r) then
                    fr = fr + sp%br*sd
                    power = power + sp%br*sd**2
                end if
                if (self%moving(k)) work = work - sp%sgn*fr*sp%angle_rate
            end if
        end associate
    end subroutine support_power

    module procedure fill_bodies
        integer :: i, k
        do i = 1, self%n
            k = 6*(i - 1)
            self%bodies%c(:, i) = y(k + 1:k + 2)
            self%bodies%phi(i) = y(k + 3)
            self%bodies%v(:, i) = y(k + 4:k + 5)
            self%bodies%w(i) = y(k + 6)
        end do
    end procedure fill_bodies

    !> Accelerations (x'', y'', phi'') of the element carrying point-mass group p, from its
    !! generalized force g (3).
    pure function pm_acceleration(self, p, y, g) result(a)
        class(rfem_t), intent(in) :: self
        integer, intent(in) :: p
        real(wp), intent(in) :: y(:), g(3)
        real(wp) :: a(3)
        integer :: i, k
        real(wp) :: e(2), nv(2), f(2), sm
        i = self%pm_elem(p)
        k = 6*(i - 1)
        sm = self%pm_moment(p)
        e = [cos(y(k + 3)), sin(y(k + 3))]
        nv = [-e(2), e(1)]
        f = g(1:2) + sm*y(k + 6)**2*e
        a(3) = (g(3) - sm*dot_product(nv, f)/self%mass(i)) &
               /(self%inertia(i) - sm**2/self%mass(i))
        a(1:2) = (f - sm*nv*a(3))/self%mass(i)
    end function pm_acceleration

    module procedure point_mass_accelerations
        integer :: p, k
        do p = 1, size(self%pm_elem)
            k = 6*(self%pm_elem(p) - 1)
            ydot(k + 4:k + 6) = pm_acceleration(self, p, y, gen(:, self%pm_elem(p)))
        end do
    end procedure point_mass_accelerations

    module procedure forces
        integer :: j, ka, kb, n, p, i
        real(wp) :: dwx, dwy, cd, sd, rx, ry, rp, fx, fy, fp, ffx, ffy, c(3), e_el
        real(wp) :: ca, sa, cb, sb, ha, hb, dx, dy, dvx, dvy, wa, wb, p_in
        logical :: energy, with_power

        n = self%n
        energy = present(elastic)
        with_power = present(power)
        e_el = 0.0_wp
        p_in = 0.0_wp
        call self%set_time(t)
        call angles(self, y)
        ! c: the force of the previous SDE on its element b (first: the top support's)
        c = 0.0_wp
        if (self%sup(1)%active) call support_force(self, 1, y, c, energy, e_el)
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
            fx = 0.0_wp
            fy = 0.0_wp
            fp = 0.0_wp
            if (self%tension) fx = self%cx*dwx
            if (self%shear) fy = self%cy*dwy
            if (self%bending) fp = self%cpj(j)*(y(kb + 3) - y(ka + 3))
            if (energy) e_el = e_el + 0.5_wp*(fx*dwx + fy*dwy + fp*(y(kb + 3) - y(ka + 3)))
            if (self%damped) then
                dvx = y(kb + 4) - y(ka + 4)
                dvy = y(kb + 5) - y(ka + 5)
                wa = y(ka + 6)
                wb = y(kb + 6)
                rx = ca*dvx + sa*dvy + dwy*wa + hb*sd*wb
                ry = -sa*dvx + ca*dvy - (dwx + ha)*wa - hb*cd*wb
                rp = wb - wa
                fx = fx + self%bx*rx
                fy = fy + self%by*ry
                fp = fp + self%bpj(j)*rp
                if (with_power) p_in = p_in + (self%bx*rx**2 + self%by*ry**2 + &
                                               self%bpj(j)*rp**2)
            end if
            ffx = fx*ca - fy*sa
            ffy = fx*sa + fy*ca
            self%gen(1, j - 1) = c(1) + ffx + self%weight(j - 1)
            self%gen(2, j - 1) = c(2) + ffy
            self%gen(3, j - 1) = c(3) + (fy*(dwx + ha) - fx*dwy + fp)
            c(1) = -ffx
            c(2) = -ffy
            c(3) = -hb*(fx*sd - fy*cd) - fp
        end do
        if (self%sup(2)%active) call support_force(self, 2, y, c, energy, e_el)
        self%gen(1, n) = c(1) + self%weight(n)
        self%gen(2:3, n) = c(2:3)
        ! moment of the point masses' weight about their element's centre
        if (self%gravity_on) then
            do p = 1, size(self%pm_elem)
                i = self%pm_elem(p)
                self%gen(3, i) = self%gen(3, i) - self%g*self%pm_moment(p)*self%cs(2, i)
            end do
        end if
        if (size(self%effects) > 0) then
            call self%fill_bodies(y)
            call add_forces_of(self%effects, t, self%bodies, self%gen(1:2, :), self%gen(3, :))
            if (energy) call add_energies_of(self%effects, t, self%bodies, e_el)
        end if
        if (energy) elastic = e_el
        if (with_power) power = p_in
    end procedure forces

    module procedure rfem_generalized_forces
        real(wp) :: tt
        tt = 0.0_wp
        if (present(t)) tt = t
        call self%forces(tt, y, elastic)
        gen = self%gen
    end procedure rfem_generalized_forces

    module procedure rfem_rhs
        call self%forces(t, y)
        call accelerations(self, y, ydot)
        status = STATUS_OK
        if (.not. all(ieee_is_finite(ydot))) status = STATUS_RECOVERABLE
    end procedure rfem_rhs

    module procedure rfem_rhs_quad
        real(wp) :: power, work
        integer :: k
        ! the order of the sums as in rfem_quad_rhs: internal SDEs, supports, effects
        power = 0.0_wp
        if (self%damped) then
            call self%forces(t, y, power=power)
        else
            call self%forces(t, y)
        end if
        call accelerations(self, y, ydot)
        work = 0.0_wp
        do k = 1, 2
            if (self%sup(k)%active) call support_power(self, k, y, power, work)
        end do
        ! forces filled the bodies of the effects
        if (size(self%effects) > 0) call add_powers_of(self%effects, t, self%bodies, power, work)
        yqdot(1) = power
        if (self%with_work) yqdot(2) = work
        status = STATUS_OK
        if (.not. (all(ieee_is_finite(ydot)) .and. ieee_is_finite(power) .and. &
                   ieee_is_finite(work))) status = STATUS_RECOVERABLE
    end procedure rfem_rhs_quad

    !> ydot from y and the generalized forces in self%gen.
    subroutine accelerations(self, y, ydot)
        class(rfem_t), intent(inout) :: self
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: ydot(:)
        integer :: i, k
        do i = 1, self%n
            k = 6*(i - 1)
            ydot(k + 1) = y(k + 4)
            ydot(k + 2) = y(k + 5)
            ydot(k + 3) = y(k + 6)
            ydot(k + 4) = self%gen(1, i)*self%rowscale(1, i)
            ydot(k + 5) = self%gen(2, i)*self%rowscale(2, i)
            ydot(k + 6) = self%gen(3, i)*self%rowscale(3, i)
        end do
        if (size(self%pm_elem) > 0) call self%point_mass_accelerations(y, self%gen, ydot)
    end subroutine accelerations

    module procedure rfem_has_jacobian
        has = .true.
    end procedure rfem_has_jacobian

    module procedure point_mass_rows
        integer :: i, o, l, p, k0
        real(wp) :: raw(3), a(3), e(2), nv(2), sm, w

        ! Their rows hold dG/dy (rowscale 1): add the terms of the weight's moment and the
        ! centripetal force, subtract (dA/dphi) a, and multiply by the inverse of the
        ! element's mass block A.
        call self%forces(t, y)
        do p = 1, size(self%pm_elem)
            i = self%pm_elem(p)
            k0 = 6*(i - 1)
            sm = self%pm_moment(p)
            e = [cos(y(k0 + 3)), sin(y(k0 + 3))]
            nv = [-e(2), e(1)]
            w = y(k0 + 6)
            a = pm_acceleration(self, p, y, self%gen(:, i))
            do o = max(-1, 1 - i), min(1, self%n - i)
                do l = 1, 6
                    raw = self%blk(:, l, o, i)
                    if (o == 0 .and. l == 3) then
                        raw(1:2) = raw(1:2) + sm*w**2*nv
                        if (self%gravity_on) raw(3) = raw(3) - self%g*sm*e(1)
                        raw = raw + sm*[e(1)*a(3), e(2)*a(3), dot_product(e, a(1:2))]
                    else if (o == 0 .and. l == 6) then
                        raw(1:2) = raw(1:2) + 2.0_wp*sm*w*e
                    end if
                    raw(3) = (raw(3) - sm*dot_product(nv, raw(1:2))/self%mass(i)) &
                             /(self%inertia(i) - sm**2/self%mass(i))
                    raw(1:2) = (raw(1:2) - sm*nv*raw(3))/self%mass(i)
                    self%blk(:, l, o, i) = raw
                end do
            end do
        end do
    end procedure point_mass_rows

    !> Add the Jacobian of the first-order system into band storage jb(ld, 6n) (entry (i, j)
    !! at row offset + i - j): the identity of the position rows and the velocity rows from
    !! the blocks times the row scales.
    subroutine write_first_order(self, jb, ld, offset)
        class(rfem_t), intent(in) :: self
        integer, intent(in) :: ld, offset
        real(wp), intent(inout) :: jb(ld, 6*self%n)
        integer :: i, k, c, o, l, col, p
        real(wp) :: s1, s2, s3
        do i = 1, self%n
            k = 6*(i - 1)
            ! d(position)/dt = velocity
            do c = 1, 3
                jb(offset - 3, k + c + 3) = jb(offset - 3, k + c + 3) + 1.0_wp
            end do
            s1 = self%rowscale(1, i)
            s2 = self%rowscale(2, i)
            s3 = self%rowscale(3, i)
            ! rows k+4 .. k+6 from the blocks of elements i-1, i, i+1
            do o = max(-1, 1 - i), min(1, self%n - i)
                do l = 1, 6
                    col = 6*(i + o - 1) + l
                    p = offset + k + 4 - col
                    jb(p, col) = jb(p, col) + s1*self%blk(1, l, o, i)
                    jb(p + 1, col) = jb(p + 1, col) + s2*self%blk(2, l, o, i)
                    jb(p + 2, col) = jb(p + 2, col) + s3*self%blk(3, l, o, i)
                end do
            end do
        end do
    end subroutine write_first_order

    !> Add K (the blocks' coordinate columns), C (their rate columns), both times the row
    !! scales, and the identity mass block into band storage (ld, 3n).
    subroutine write_second_order(self, kb, cb, mb, ld, offset)
        class(rfem_t), intent(in) :: self
        integer, intent(in) :: ld, offset
        real(wp), intent(inout) :: kb(ld, 3*self%n), cb(ld, 3*self%n), mb(ld, 3*self%n)
        integer :: i, k, c, o, l, col, p
        real(wp) :: s1, s2, s3
        do i = 1, self%n
            k = 3*(i - 1)
            do c = 1, 3
                mb(offset, k + c) = mb(offset, k + c) + 1.0_wp
            end do
            s1 = self%rowscale(1, i)
            s2 = self%rowscale(2, i)
            s3 = self%rowscale(3, i)
            do o = max(-1, 1 - i), min(1, self%n - i)
                do l = 1, 3
                    col = 3*(i + o - 1) + l
                    p = offset + k + 1 - col
                    kb(p, col) = kb(p, col) + s1*self%blk(1, l, o, i)
                    kb(p + 1, col) = kb(p + 1, col) + s2*self%blk(2, l, o, i)
                    kb(p + 2, col) = kb(p + 2, col) + s3*self%blk(3, l, o, i)
                    cb(p, col) = cb(p, col) + s1*self%blk(1, l + 3, o, i)
                    cb(p + 1, col) = cb(p + 1, col) + s2*self%blk(2, l + 3, o, i)
                    cb(p + 2, col) = cb(p + 2, col) + s3*self%blk(3, l + 3, o, i)
                end do
            end do
        end do
    end subroutine write_second_order

    module procedure rfem_jacobian
        call self%jacobian_blocks(t, y)
        if (size(self%pm_elem) > 0) call self%point_mass_rows(t, y)
        call write_first_order(self, jb, size(jb, 1), offset)
        status = STATUS_OK
    end procedure rfem_jacobian

    module procedure rfem_second_order_blocks
        call self%jacobian_blocks(t, y)
        if (size(self%pm_elem) > 0) call self%point_mass_rows(t, y)
        call write_second_order(self, kb, cb, mb, size(kb, 1), offset)
        status = STATUS_OK
    end procedure rfem_second_order_blocks

    module procedure rfem_potential_energy
        type(energy_t) :: e
        e = self%energy(0.0_wp, y, [0.0_wp])
        v = e%elastic + e%gravity
    end procedure rfem_potential_energy

    module procedure rfem_energy
        integer :: i, k, p

        call self%set_time(t)
        e%kinetic = 0.0_wp
        e%gravity = 0.0_wp
        do i = 1, self%n
            k = 6*(i - 1)
            e%kinetic = e%kinetic + 0.5_wp*(self%mass(i)*(y(k + 4)**2 + y(k + 5)**2) + &
                                            self%inertia(i)*y(k + 6)**2)
            if (self%gravity_on) e%gravity = e%gravity - self%mass(i)*self%g*y(k + 1)
        end do
        ! point masses off the element centres: T += s w (v . n), V_g -= g s cos(phi)
        do p = 1, size(self%pm_elem)
            k = 6*(self%pm_elem(p) - 1)
            e%kinetic = e%kinetic + self%pm_moment(p)*y(k + 6)* &
                        (-y(k + 4)*sin(y(k + 3)) + y(k + 5)*cos(y(k + 3)))
            if (self%gravity_on) e%gravity = e%gravity - self%g*self%pm_moment(p)*cos(y(k + 3))
        end do
        ! the springs' and the effects' potential energy
        call self%forces(t, y, e%elastic)
        e%dissipated = 0.0_wp
        if (size(yq) >= 1) e%dissipated = yq(1)
        e%support_work = 0.0_wp  ! fixed supports and no loads: no external work
        if (self%with_work .and. size(yq) >= 2) e%support_work = yq(2)
    end procedure rfem_energy

    !> Add the dissipation power sum B s'^2 of the internal SDEs (self%cs holding the
    !! angles of y; the module header's geometry and rates).
    subroutine internal_power(self, y, power)
        class(rfem_t), intent(in) :: self
        real(wp), intent(in) :: y(6*self%n)
        real(wp), intent(inout) :: power
        real(wp) :: ca, sa, cb, sb, ha, hb, dx, dy, dwx, dwy, cd, sd, dvx, dvy, wa, wb
        real(wp) :: rx, ry, rp
        integer :: j, ka, kb
        do j = 2, self%n
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
            dvx = y(kb + 4) - y(ka + 4)
            dvy = y(kb + 5) - y(ka + 5)
            wa = y(ka + 6)
            wb = y(kb + 6)
            rx = ca*dvx + sa*dvy + dwy*wa + hb*sd*wb
            ry = -sa*dvx + ca*dvy - (dwx + ha)*wa - hb*cd*wb
            rp = wb - wa
            power = power + (self%bx*rx**2 + self%by*ry**2 + self%bpj(j)*rp**2)
        end do
    end subroutine internal_power

    module procedure rfem_quad_rhs
        real(wp) :: power, work
        integer :: k
        call self%set_time(t)
        ! only the damped strains and the supports: no spring forces, no gravity, no scatter
        power = 0.0_wp
        work = 0.0_wp
        if (self%damped) then
            call angles(self, y)
            call internal_power(self, y, power)
        end if
        do k = 1, 2
            if (self%sup(k)%active) call support_power(self, k, y, power, work)
        end do
        if (size(self%effects) > 0) then
            call self%fill_bodies(y)
            call add_powers_of(self%effects, t, self%bodies, power, work)
        end if
        yqdot(1) = power
        if (self%with_work) yqdot(2) = work
        status = STATUS_OK
        if (.not. (ieee_is_finite(power) .and. ieee_is_finite(work))) status = STATUS_RECOVERABLE
    end procedure rfem_quad_rhs
end submodule ropedyn_rfem_kernels
