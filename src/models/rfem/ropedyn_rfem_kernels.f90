!> The RFEM kernels: strains, generalized forces, right-hand side, analytic Jacobian,
!! energies and dissipation power (the derivation is in docs/physics-rfem.md).
submodule (ropedyn_rfem) ropedyn_rfem_kernels
    implicit none

contains

    module procedure strain
        integer :: ka, kb
        real(wp) :: ea(2), na(2), eb(2), nb(2), d(2), u(2), la, lb, dwx, dwy

        g = 0.0_wp
        if (present(h)) h = 0.0_wp
        select case (kind)
        case (FAM_TENSION, FAM_SHEAR)
            ka = 6*(j - 2)
            kb = 6*(j - 1)
            la = self%len(j - 1)
            lb = self%len(j)
            ea = [cos(y(ka + 3)), sin(y(ka + 3))]
            na = [-ea(2), ea(1)]
            eb = [cos(y(kb + 3)), sin(y(kb + 3))]
            nb = [-eb(2), eb(1)]
            d = y(kb + 1:kb + 2) - 0.5_wp*lb*eb - y(ka + 1:ka + 2) - 0.5_wp*la*ea
            dwx = dot_product(ea, d)
            dwy = dot_product(na, d)
            if (kind == FAM_TENSION) then
                s = dwx
                g = [-ea(1), -ea(2), dwy, ea(1), ea(2), -0.5_wp*lb*dot_product(ea, nb)]
                if (present(h)) then
                    call sym(h, 3, 1, -na(1))
                    call sym(h, 3, 2, -na(2))
                    call sym(h, 3, 4, na(1))
                    call sym(h, 3, 5, na(2))
                    call sym(h, 6, 3, -0.5_wp*lb*dot_product(na, nb))
                    h(3, 3) = -dwx - 0.5_wp*la
                    h(6, 6) = 0.5_wp*lb*dot_product(ea, eb)
                end if
            else
                s = dwy
                g = [-na(1), -na(2), -dwx - 0.5_wp*la, na(1), na(2), -0.5_wp*lb*dot_product(na, nb)]
                if (present(h)) then
                    call sym(h, 3, 1, ea(1))
                    call sym(h, 3, 2, ea(2))
                    call sym(h, 3, 4, -ea(1))
                    call sym(h, 3, 5, -ea(2))
                    call sym(h, 6, 3, 0.5_wp*lb*dot_product(ea, nb))
                    h(3, 3) = -dwy
                    h(6, 6) = 0.5_wp*lb*dot_product(na, eb)
                end if
            end if
        case (FAM_BEND)
            s = y(6*(j - 1) + 3) - y(6*(j - 2) + 3)
            g(3) = -1.0_wp
            g(6) = 1.0_wp
        case (FAM_TOP_X, FAM_TOP_Y)
            ! d = A_1 - P_top, strain along a fixed global axis u
            u = merge([1.0_wp, 0.0_wp], [0.0_wp, 1.0_wp], kind == FAM_TOP_X)
            lb = self%len(1)
            eb = [cos(y(3)), sin(y(3))]
            nb = [-eb(2), eb(1)]
            d = y(1:2) - 0.5_wp*lb*eb - self%top_anchor
            s = dot_product(u, d)
            g(4:6) = [u(1), u(2), -0.5_wp*lb*dot_product(u, nb)]
            if (present(h)) h(6, 6) = 0.5_wp*lb*dot_product(u, eb)
        case (FAM_TOP_ROT)
            s = y(3) - self%top_angle
            g(6) = 1.0_wp
        case (FAM_BOTTOM_X, FAM_BOTTOM_Y)
            ! d = P_bottom - B_n
            u = merge([1.0_wp, 0.0_wp], [0.0_wp, 1.0_wp], kind == FAM_BOTTOM_X)
            ka = 6*(self%n - 1)
            la = self%len(self%n)
            ea = [cos(y(ka + 3)), sin(y(ka + 3))]
            na = [-ea(2), ea(1)]
            d = self%bottom_anchor - y(ka + 1:ka + 2) - 0.5_wp*la*ea
            s = dot_product(u, d)
            g(1:3) = [-u(1), -u(2), -0.5_wp*la*dot_product(u, na)]
            if (present(h)) h(3, 3) = 0.5_wp*la*dot_product(u, ea)
        case (FAM_BOTTOM_ROT)
            s = self%bottom_angle - y(6*(self%n - 1) + 3)
            g(3) = -1.0_wp
        case default
            s = 0.0_wp
        end select
    contains
        pure subroutine sym(a, r, c, v)
            real(wp), intent(inout) :: a(6, 6)
            integer, intent(in) :: r, c
            real(wp), intent(in) :: v
            a(r, c) = v
            a(c, r) = v
        end subroutine sym
    end procedure strain

    module procedure local_rates
        v = 0.0_wp
        if (j >= 2) v(1:3) = y(6*(j - 2) + 4:6*(j - 2) + 6)
        if (j <= self%n) v(4:6) = y(6*(j - 1) + 4:6*(j - 1) + 6)
    end procedure local_rates

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

    module procedure point_mass_accelerations
        integer :: p, i, k
        real(wp) :: e(2), nv(2), g(3), sm, z3
        do p = 1, size(self%pm_elem)
            i = self%pm_elem(p)
            k = 6*(i - 1)
            sm = self%pm_moment(p)
            e = [cos(y(k + 3)), sin(y(k + 3))]
            nv = [-e(2), e(1)]
            g = gen(:, i)
            g(1:2) = g(1:2) + sm*y(k + 6)**2*e
            z3 = (g(3) - sm*dot_product(nv, g(1:2))/self%mass(i)) &
                 /(self%inertia(i) - sm**2/self%mass(i))
            ydot(k + 4:k + 5) = (g(1:2) - sm*nv*z3)/self%mass(i)
            ydot(k + 6) = z3
        end do
    end procedure point_mass_accelerations

    module procedure rfem_generalized_forces
        integer :: f, j, p
        real(wp) :: sd, tt

        tt = 0.0_wp
        if (present(t)) tt = t
        call self%set_time(tt)
        gen = 0.0_wp
        if (present(elastic)) elastic = 0.0_wp
        if (self%gravity_on) then
            gen(1, :) = self%mass*self%g
            ! moment of the point masses' weight about their element's centre
            do p = 1, size(self%pm_elem)
                gen(3, self%pm_elem(p)) = gen(3, self%pm_elem(p)) &
                    - self%g*self%pm_moment(p)*sin(y(6*self%pm_elem(p) - 3))
            end do
        end if
        do f = 1, size(self%families)
            associate (fam => self%families(f))
                if (.not. fam%active) cycle
                do j = fam%first, fam%last
                    call self%strain(fam%kind, j, y, self%s(j), self%grad(:, j))
                end do
                self%force(fam%first:fam%last) = fam%c*self%s(fam%first:fam%last)
                if (present(elastic)) elastic = elastic + &
                    0.5_wp*fam%c*sum(self%s(fam%first:fam%last)**2)
                if (fam%damped) then
                    do j = fam%first, fam%last
                        sd = dot_product(self%grad(:, j), self%local_rates(j, y))
                        self%force(j) = self%force(j) + fam%b*sd
                    end do
                    ! a moving support's strain rate has the part ds/dt at fixed q
                    if (fam%end > 0) self%force(fam%first:fam%last) = &
                        self%force(fam%first:fam%last) + fam%b*fam%st
                end if
                do j = fam%first, fam%last
                    if (j >= 2) gen(:, j - 1) = gen(:, j - 1) - self%force(j)*self%grad(1:3, j)
                    if (j <= self%n) gen(:, j) = gen(:, j) - self%force(j)*self%grad(4:6, j)
                end do
            end associate
        end do
        if (size(self%effects) > 0) then
            call self%fill_bodies(y)
            call add_forces_of(self%effects, tt, self%bodies, gen(1:2, :), gen(3, :))
            if (present(elastic)) call add_energies_of(self%effects, tt, self%bodies, elastic)
        end if
    end procedure rfem_generalized_forces

    module procedure rfem_rhs
        integer :: i, k

        call self%generalized_forces(y, self%gen, t=t)
        do i = 1, self%n
            k = 6*(i - 1)
            ydot(k + 1:k + 3) = y(k + 4:k + 6)
            ydot(k + 4) = self%gen(1, i)/self%mass(i)
            ydot(k + 5) = self%gen(2, i)/self%mass(i)
            ydot(k + 6) = self%gen(3, i)/self%inertia(i)
        end do
        if (size(self%pm_elem) > 0) call self%point_mass_accelerations(y, self%gen, ydot)
        status = STATUS_OK
        if (.not. all(ieee_is_finite(ydot))) status = STATUS_RECOVERABLE
    end procedure rfem_rhs

    module procedure rfem_has_jacobian
        has = .true.
    end procedure rfem_has_jacobian

    module procedure rfem_jacobian
        integer :: i, c, f, j, r, l, row, col_q, col_v, er, el
        real(wp) :: s, g(6), h(6, 6), v(6), hv(6), sd, coef, kq(6, 6), kv(6, 6), inv_m(6)

        call self%set_time(t)
        ! d(position)/dt = velocity
        do i = 1, self%n
            do c = 1, 3
                row = 6*(i - 1) + c
                jb(offset - 3, row + 3) = jb(offset - 3, row + 3) + 1.0_wp
            end do
        end do
        do f = 1, size(self%families)
            associate (fam => self%families(f))
                if (.not. fam%active) cycle
                do j = fam%first, fam%last
                    call self%strain(fam%kind, j, y, s, g, h)
                    coef = fam%c*s
                    kq = -fam%c*outer(g, g)
                    if (fam%damped) then
                        v = self%local_rates(j, y)
                        sd = dot_product(g, v) + fam%st
                        hv = matmul(h, v)
                        coef = coef + fam%b*sd
                        kq = kq - fam%b*outer(g, hv)
                        kv = -fam%b*outer(g, g)
                    end if
                    kq = kq - coef*h
                    ! scatter: local dof r belongs to element er = j-1 (r <= 3) or j (r > 3)
                    inv_m = 0.0_wp
                    if (j >= 2) inv_m(1:3) = self%rowscale(:, j - 1)
                    if (j <= self%n) inv_m(4:6) = self%rowscale(:, j)
                    do r = 1, 6
                        if (inv_m(r) == 0.0_wp) cycle
                        er = j - 1 + (r - 1)/3
                        row = 6*(er - 1) + 3 + mod(r - 1, 3) + 1
                        do l = 1, 6
                            if (inv_m(l) == 0.0_wp) cycle
                            el = j - 1 + (l - 1)/3
                            col_q = 6*(el - 1) + mod(l - 1, 3) + 1
                            col_v = col_q + 3
                            jb(offset + row - col_q, col_q) = jb(offset + row - col_q, col_q) &
                                                              + kq(r, l)*inv_m(r)
                            if (fam%damped) jb(offset + row - col_v, col_v) = &
                                jb(offset + row - col_v, col_v) + kv(r, l)*inv_m(r)
                        end do
                    end do
                end do
            end associate
        end do
        ! external effects: 3x6 blocks on each element's own columns
        if (size(self%effects) > 0) then
            call self%fill_bodies(y)
            self%ejac = 0.0_wp
            call add_jacobians_of(self%effects, t, self%bodies, self%ejac)
            do i = 1, self%n
                do r = 1, 3
                    row = 6*(i - 1) + 3 + r
                    do l = 1, 6
                        col_q = 6*(i - 1) + l
                        jb(offset + row - col_q, col_q) = jb(offset + row - col_q, col_q) &
                                                          + self%ejac(r, l, i)*self%rowscale(r, i)
                    end do
                end do
            end do
        end if
        if (size(self%pm_elem) > 0) call point_mass_rows()
        status = STATUS_OK
    contains
        !> Rows of the point-mass elements hold dG/dy so far (unscaled); add the terms of the
        !! weight's moment and the centripetal force, subtract (dA/dphi) a, and multiply by
        !! the inverse of the element's mass block A.
        subroutine point_mass_rows()
            real(wp) :: acc(6*self%n), raw(3), e(2), nv(2), sm, a(3), z3
            integer :: p, col, k0, c1, c2
            call self%generalized_forces(y, self%gen, t=t)
            call self%point_mass_accelerations(y, self%gen, acc)
            do p = 1, size(self%pm_elem)
                i = self%pm_elem(p)
                k0 = 6*(i - 1)
                sm = self%pm_moment(p)
                e = [cos(y(k0 + 3)), sin(y(k0 + 3))]
                nv = [-e(2), e(1)]
                a = acc(k0 + 4:k0 + 6)
                c1 = max(1, k0 - 5)
                c2 = min(6*self%n, k0 + 12)
                do col = c1, c2
                    raw = jb(offset + k0 + 4 - col:offset + k0 + 6 - col, col)
                    if (col == k0 + 3) then
                        raw(1:2) = raw(1:2) + sm*y(k0 + 6)**2*nv
                        if (self%gravity_on) raw(3) = raw(3) - self%g*sm*cos(y(k0 + 3))
                        raw = raw + sm*[e(1)*a(3), e(2)*a(3), dot_product(e, a(1:2))]
                    else if (col == k0 + 6) then
                        raw(1:2) = raw(1:2) + 2.0_wp*sm*y(k0 + 6)*e
                    end if
                    z3 = (raw(3) - sm*dot_product(nv, raw(1:2))/self%mass(i)) &
                         /(self%inertia(i) - sm**2/self%mass(i))
                    raw(1:2) = (raw(1:2) - sm*nv*z3)/self%mass(i)
                    raw(3) = z3
                    jb(offset + k0 + 4 - col:offset + k0 + 6 - col, col) = raw
                end do
            end do
        end subroutine point_mass_rows

        pure function outer(a, b) result(m)
            real(wp), intent(in) :: a(6), b(6)
            real(wp) :: m(6, 6)
            integer :: p
            do p = 1, 6
                m(:, p) = a*b(p)
            end do
        end function outer
    end procedure rfem_jacobian

    module procedure rfem_potential_energy
        type(energy_t) :: e
        e = self%energy(0.0_wp, y, [0.0_wp])
        v = e%elastic + e%gravity
    end procedure rfem_potential_energy

    module procedure rfem_energy
        integer :: i, k, f, j, p
        real(wp) :: s, g(6)

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
        e%elastic = 0.0_wp
        do f = 1, size(self%families)
            if (.not. self%families(f)%active) cycle
            do j = self%families(f)%first, self%families(f)%last
                call self%strain(self%families(f)%kind, j, y, s, g)
                e%elastic = e%elastic + 0.5_wp*self%families(f)%c*s**2
            end do
        end do
        if (size(self%effects) > 0) then
            call self%fill_bodies(y)
            call add_energies_of(self%effects, t, self%bodies, e%elastic)
        end if
        e%dissipated = 0.0_wp
        if (size(yq) >= 1) e%dissipated = yq(1)
        e%support_work = 0.0_wp  ! fixed supports and no loads: no external work
        if (self%with_work .and. size(yq) >= 2) e%support_work = yq(2)
    end procedure rfem_energy

    module procedure rfem_quad_rhs
        real(wp) :: power, work, s, g(6), sd
        integer :: f, j
        call self%set_time(t)
        ! only the damped strains: no spring forces, no gravity, no scatter
        power = 0.0_wp
        work = 0.0_wp
        do f = 1, size(self%families)
            associate (fam => self%families(f))
                if (.not. fam%active) cycle
                if (fam%end > 0 .and. self%moving(max(fam%end, 1))) then
                    do j = fam%first, fam%last
                        call self%strain(fam%kind, j, y, s, g)
                        sd = dot_product(g, self%local_rates(j, y)) + fam%st
                        if (fam%damped) power = power + fam%b*sd**2
                        work = work + (fam%c*s + merge(fam%b, 0.0_wp, fam%damped)*sd)*fam%st
                    end do
                else if (fam%damped) then
                    do j = fam%first, fam%last
                        call self%strain(fam%kind, j, y, s, g)
                        power = power + fam%b*dot_product(g, self%local_rates(j, y))**2
                    end do
                end if
            end associate
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
