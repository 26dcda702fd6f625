!> Contact of the rope with a ground plane (docs/theory/effects.md, "Ground contact").
!!
!! The plane passes through p0 with unit normal n_g pointing to the free side. The law is
!! per metre of rope (k in N/m per metre, c in N s/m per metre): at a point below the plane
!! by delta = -(X - p0) . n_g, sinking at delta' = -V . n_g (V the point's velocity),
!!     f = max(0, k delta + c delta')  per metre,
!! and regularized Coulomb friction acts along the tangent t_g = (-n_g2, n_g1):
!!     f_T = -mu f tanh(v_t / v_reg),  v_t = V . t_g.
!! Along a rigid body delta, delta' and so k delta + c delta' are linear in the offset from
!! its centre: the force acts on one interval of the body, where delta > 0 and f > 0, and
!! that interval's two Gauss points, each standing for half of it, give the law's force and
!! moment exactly (`body_contact`). A body lying on the ground gets the distributed law's
!! tilt stiffness and damping (k l^3/12, c l^3/12); a body touching with a part, or a
!! joint between two bodies, is held by the part below the plane. The contact springs store
!! V_c = int k delta^2/2 over the part below the plane (in the elastic energy); the
!! dissipation rate is the force points' (F_N delta' + mu F_N tanh(v_t/v_reg) v_t) less
!! d V_c/dt, >= 0.
module ropedyn_effect_ground
    use ropedyn_kinds, only: wp
    use ropedyn_effect, only: body_effect_t, bodies_t, point_force_block
    implicit none
    private
    public :: ground_effect_t, ground_effect

    type, extends(body_effect_t) :: ground_effect_t
        private
        real(wp) :: p0(2) = 0.0_wp       !< a point of the plane, m
        real(wp) :: ng(2) = [-1.0_wp, 0.0_wp]  !< unit normal to the free side
        real(wp) :: tg(2) = [0.0_wp, -1.0_wp]  !< unit tangent
        real(wp) :: k = 0.0_wp           !< stiffness per length, N/m^2
        real(wp) :: c = 0.0_wp           !< damping per length, N s/m^2
        real(wp) :: mu = 0.0_wp          !< friction coefficient
        real(wp) :: v_reg = 1.0e-3_wp    !< regularization speed, m/s
    contains
        procedure :: name => ground_name
        procedure :: add_forces => ground_add_forces
        procedure :: add_jacobian => ground_add_jacobian
        procedure :: energy => ground_energy
        procedure :: power => ground_power
        procedure :: add_forces_power => ground_add_forces_power
        procedure :: total_normal_force => ground_total_normal_force
        procedure :: split_refusal => ground_split_refusal
    end type ground_effect_t

    !> A force point of a body in contact (`body_contact`). No default initialization:
    !! `contact` sets every component, and the lists of contacts (automatic arrays of 2n in
    !! every caller of `touching`) would otherwise be filled with zeros on each call before
    !! being written.
    type :: contact_t
        integer :: i                  !< the body
        real(wp) :: e(2)              !< its axis (cos phi, sin phi)
        real(wp) :: r                 !< offset of the point from the body's centre, m
        real(wp) :: w                 !< the length of rope the point stands for, m
        real(wp) :: delta             !< penetration, m
        real(wp) :: ddelta            !< its rate, m/s
        real(wp) :: fn                !< normal force, N
        real(wp) :: vt                !< tangential speed, m/s
        real(wp) :: th                !< tanh(vt / v_reg)
        real(wp) :: f(2)              !< force on the body, N
    end type contact_t

    !> Body i's contact along its axis (offset r from the centre): penetration d0 + a r,
    !! its rate v0 + bb r, tangential speed t0 + t1 r; the part below the plane [s1, s2] and
    !! the force interval [r1, r2] in it (`body_line`), and what sets each end of the latter
    !! (END_BODY, END_PLANE: delta = 0, END_FORCE: k delta + c delta' = 0).
    type :: line_t
        real(wp) :: d0, a, v0, bb, t0, t1
        real(wp) :: s1, s2, r1, r2
        integer :: end1, end2
    end type line_t
    integer, parameter :: END_BODY = 0, END_PLANE = 1, END_FORCE = 2

    !> the two-point Gauss rule's offset from an interval's centre, in interval lengths:
    !! 1/(2 sqrt 3)
    real(wp), parameter :: GAUSS_OFFSET = 0.28867513459481288_wp

contains

    !> Ground through point p0 (m) with normal `normal` (any length > 0, towards the free
    !! side), stiffness k (N/m^2), damping c (N s/m^2), friction coefficient mu and
    !! regularization speed v_reg (m/s).
    pure function ground_effect(p0, normal, k, c, mu, v_reg) result(eff)
        real(wp), intent(in) :: p0(2), normal(2), k, c, mu, v_reg
        type(ground_effect_t) :: eff
        eff%p0 = p0
        eff%ng = normal/norm2(normal)
        eff%tg = [-eff%ng(2), eff%ng(1)]
        eff%k = k
        eff%c = c
        eff%mu = mu
        eff%v_reg = v_reg
    end function ground_effect

    pure function ground_name(self) result(name)
        class(ground_effect_t), intent(in) :: self
        character(len=:), allocatable :: name
        name = 'ground'
    end function ground_name

    !> The part [r1, r2] of the segment [lo, hi] where alpha + beta r > 0 (r2 <= r1: none);
    !! moved1, moved2: whether that end is the root -alpha/beta rather than lo or hi.
    pure subroutine positive_part(alpha, beta, lo, hi, r1, r2, moved1, moved2)
        real(wp), intent(in) :: alpha, beta, lo, hi
        real(wp), intent(out) :: r1, r2
        logical, intent(out) :: moved1, moved2
        r1 = lo
        r2 = hi
        moved1 = .false.
        moved2 = .false.
        if (beta > 0.0_wp) then
            r1 = max(lo, -alpha/beta)
            moved1 = -alpha/beta > lo
        else if (beta < 0.0_wp) then
            r2 = min(hi, -alpha/beta)
            moved2 = -alpha/beta < hi
        else if (alpha <= 0.0_wp) then
            r2 = lo
        end if
    end subroutine positive_part

    !> Body i's contact line (line_t): the part below the plane and the force interval in it.
    pure function body_line(self, b, i, e) result(g)
        class(ground_effect_t), intent(in) :: self
        type(bodies_t), intent(in) :: b
        integer, intent(in) :: i
        real(wp), intent(in) :: e(2)
        type(line_t) :: g
        real(wp) :: nv(2)
        logical :: p1, p2, f1, f2
        nv = [-e(2), e(1)]
        g%d0 = -dot_product(b%c(:, i) - self%p0, self%ng)
        g%a = -dot_product(e, self%ng)
        call positive_part(g%d0, g%a, -0.5_wp*b%l(i), 0.5_wp*b%l(i), g%s1, g%s2, p1, p2)
        g%v0 = -dot_product(b%v(:, i), self%ng)
        g%bb = -b%w(i)*dot_product(nv, self%ng)
        g%t0 = dot_product(b%v(:, i), self%tg)
        g%t1 = b%w(i)*dot_product(nv, self%tg)
        g%r1 = g%s1
        g%r2 = g%s1
        g%end1 = END_BODY
        g%end2 = END_BODY
        if (g%s2 <= g%s1) return
        call positive_part(self%k*g%d0 + self%c*g%v0, self%k*g%a + self%c*g%bb, g%s1, g%s2, &
                           g%r1, g%r2, f1, f2)
        g%end1 = merge(END_FORCE, merge(END_PLANE, END_BODY, p1), f1)
        g%end2 = merge(END_FORCE, merge(END_PLANE, END_BODY, p2), f2)
    end function body_line

    !> The contact of body i (axis e): its force points, appended to cc(nc+1:), and its
    !! springs' energy and rate, added to spring_energy and spring_rate. Along the body
    !! (offset r from the centre) the penetration delta(r) = d0 + a r, its rate
    !! delta'(r) = v0 + b r and the normal force per metre f(r) = k delta + c delta' are
    !! linear. The force acts where delta > 0 and f > 0, an interval [r1, r2]; the two Gauss
    !! points of that interval, each standing for half of it, integrate f, its moment and
    !! its power exactly. The springs' energy k delta^2/2 and rate k delta delta' are
    !! integrated over the interval where delta > 0 alone, by its own Gauss points.
    pure subroutine body_contact(self, b, i, e, cc, nc, spring_energy, spring_rate)
        class(ground_effect_t), intent(in) :: self
        type(bodies_t), intent(in) :: b
        integer, intent(in) :: i
        real(wp), intent(in) :: e(2)
        type(contact_t), intent(inout) :: cc(:)
        integer, intent(inout) :: nc
        real(wp), intent(inout) :: spring_energy, spring_rate
        type(line_t) :: g
        real(wp) :: s1, s2, r1, r2, mid, half, r, dl, dv
        integer :: s
        logical :: same
        g = body_line(self, b, i, e)
        s1 = g%s1
        s2 = g%s2
        if (s2 <= s1) return
        r1 = g%r1
        r2 = g%r2
        ! the force acts on all of the part below the plane (a body lying on it, one
        ! landing): then the force points are the springs' points too
        same = r1 == s1 .and. r2 == s2
        if (.not. same) then
            mid = 0.5_wp*(s1 + s2)
            half = 0.5_wp*(s2 - s1)
            do s = -1, 1, 2
                r = mid + 2.0_wp*GAUSS_OFFSET*real(s, wp)*half
                dl = g%d0 + g%a*r
                dv = g%v0 + g%bb*r
                spring_energy = spring_energy + half*0.5_wp*self%k*dl**2
                spring_rate = spring_rate + half*self%k*dl*dv
            end do
        end if
        if (r2 <= r1) return
        mid = 0.5_wp*(r1 + r2)
        half = 0.5_wp*(r2 - r1)
        do s = -1, 1, 2
            nc = nc + 1
            r = mid + 2.0_wp*GAUSS_OFFSET*real(s, wp)*half
            cc(nc) = contact(self, i, e, r, half, g%d0 + g%a*r, g%v0 + g%bb*r, g%t0 + g%t1*r)
            if (same) then
                spring_energy = spring_energy + half*0.5_wp*self%k*cc(nc)%delta**2
                spring_rate = spring_rate + half*self%k*cc(nc)%delta*cc(nc)%ddelta
            end if
        end do
    end subroutine body_contact

    !> The force point at offset r of body i (axis e), standing for the length w, with its
    !! penetration delta, its rate ddelta and its tangential speed vt: the normal force (at
    !! least 0), tanh(v_t / v_reg) and the force vector.
    pure function contact(self, i, e, r, w, delta, ddelta, vt) result(c)
        class(ground_effect_t), intent(in) :: self
        integer, intent(in) :: i
        real(wp), intent(in) :: e(2), r, w, delta, ddelta, vt
        type(contact_t) :: c
        c%i = i
        c%e = e
        c%r = r
        c%w = w
        c%delta = delta
        c%ddelta = ddelta
        c%fn = max(0.0_wp, w*(self%k*delta + self%c*ddelta))
        c%vt = vt
        c%th = smooth_sign(vt/self%v_reg)
        c%f = c%fn*(self%ng - self%mu*c%th*self%tg)
    end function contact

    !> tanh(x), as 1 - 2/(exp(2x) + 1): libm's tanh goes through expm1, twice the cost of
    !! exp, for a relative accuracy the friction does not need (the absolute error here is
    !! a few 1e-16, also near x = 0).
    elemental real(wp) function smooth_sign(x) result(th)
        real(wp), intent(in) :: x
        ! beyond |x| = 20 the formula gives +-1 exactly (2/(exp(40) + 1) < 1e-17): no exp
        if (abs(x) > 20.0_wp) then
            th = sign(1.0_wp, x)
        else
            th = 1.0_wp - 2.0_wp/(exp(2.0_wp*x) + 1.0_wp)
        end if
    end function smooth_sign

    !> The force points of the bodies in contact, body by body, in cc(1:nc) (cc holds at
    !! least 2 b%n), and the contact springs' energy, J, and its rate, W (`body_contact`).
    pure subroutine touching(self, b, cc, nc, spring_energy, spring_rate)
        class(ground_effect_t), intent(in) :: self
        type(bodies_t), intent(in) :: b
        type(contact_t), intent(inout) :: cc(:)
        integer, intent(out) :: nc
        real(wp), intent(out) :: spring_energy, spring_rate
        real(wp) :: hn, rg
        integer :: i
        nc = 0
        spring_energy = 0.0_wp
        spring_rate = 0.0_wp
        do i = 1, b%n
            ! the centre's height above the plane and the ends' offset along the normal:
            ! most bodies are clear of the plane
            hn = dot_product(b%c(:, i) - self%p0, self%ng)
            rg = 0.5_wp*b%l(i)*abs(dot_product(b%cs(:, i), self%ng))
            if (hn - rg >= 0.0_wp) cycle
            call body_contact(self, b, i, b%cs(:, i), cc, nc, spring_energy, spring_rate)
        end do
    end subroutine touching

    pure subroutine ground_add_forces(self, t, b, f, m)
        class(ground_effect_t), intent(in) :: self
        real(wp), intent(in) :: t
        type(bodies_t), intent(in) :: b
        real(wp), intent(inout) :: f(:, :), m(:)
        type(contact_t) :: cc(2*b%n)
        real(wp) :: es, er
        integer :: nc
        call touching(self, b, cc, nc, es, er)
        call add_contact_forces(cc(:nc), f, m)
    end subroutine ground_add_forces

    !> Add the forces and moments of the contacts cc.
    pure subroutine add_contact_forces(cc, f, m)
        type(contact_t), intent(in) :: cc(:)
        real(wp), intent(inout) :: f(:, :), m(:)
        integer :: k
        do k = 1, size(cc)
            associate (c => cc(k), i => cc(k)%i)
                if (c%fn <= 0.0_wp) cycle
                f(:, i) = f(:, i) + c%f
                m(i) = m(i) + c%r*(c%e(1)*c%f(2) - c%e(2)*c%f(1))
            end associate
        end do
    end subroutine add_contact_forces

    !> ground_add_forces and ground_power from one search for the contacts.
    pure subroutine ground_add_forces_power(self, t, b, f, m, dissipation, work)
        class(ground_effect_t), intent(in) :: self
        real(wp), intent(in) :: t
        type(bodies_t), intent(in) :: b
        real(wp), intent(inout) :: f(:, :), m(:)
        real(wp), intent(inout) :: dissipation, work
        type(contact_t) :: cc(2*b%n)
        real(wp) :: es, er
        integer :: nc
        call touching(self, b, cc, nc, es, er)
        call add_contact_forces(cc(:nc), f, m)
        call add_contact_power(self, cc(:nc), er, dissipation)
    end subroutine ground_add_forces_power

    !> Each force point's block with its offset and its length held fixed, and then the
    !! moving ends of each body's force interval: an end where delta = 0 (f = c delta' there)
    !! or where f = 0 moves with the state, and the quadrature moves with it (`end_terms`).
    pure subroutine ground_add_jacobian(self, t, b, jac)
        class(ground_effect_t), intent(in) :: self
        real(wp), intent(in) :: t
        type(bodies_t), intent(in) :: b
        real(wp), intent(inout) :: jac(:, :, :)
        type(contact_t) :: cc(2*b%n)
        real(wp) :: kp, cp, dir(2), dfdx(2, 2), dfdv(2, 2), es, er
        integer :: k, nc, p, i0
        call touching(self, b, cc, nc, es, er)
        i0 = 0
        do k = 1, nc
            associate (c => cc(k), i => cc(k)%i)
                if (i /= i0) call end_terms(self, b, i, jac(:, :, i))
                i0 = i
                if (c%fn <= 0.0_wp) cycle
                kp = self%k*c%w
                cp = self%c*c%w
                dir = self%ng - self%mu*c%th*self%tg
                ! dF_N/dX = -k_p n_g, dF_N/dV = -c_p n_g; d tanh/dV = (1 - th^2)/v_reg t_g
                do p = 1, 2
                    dfdx(:, p) = -kp*dir*self%ng(p)
                    dfdv(:, p) = -cp*dir*self%ng(p) - self%mu*c%fn*(1.0_wp - c%th**2)/self%v_reg &
                                 *self%tg*self%tg(p)
                end do
                jac(:, :, i) = jac(:, :, i) + point_force_block(c%r, b%phi(i), b%w(i), c%f, &
                                                                dfdx, dfdv)
            end associate
        end do
    end subroutine ground_add_jacobian

    !> Body i's force and moment from the two points of its force interval [r1, r2] depend
    !! on the ends; an end that is not the body's own moves with the body's coordinates and
    !! rates: add dG/dr_end (dr_end/dq)^T to the body's block (rows F_x, F_y, M; columns
    !! x, y, phi, v_x, v_y, w).
    pure subroutine end_terms(self, b, i, blk)
        class(ground_effect_t), intent(in) :: self
        type(bodies_t), intent(in) :: b
        integer, intent(in) :: i
        real(wp), intent(inout) :: blk(:, :)
        type(line_t) :: g
        real(wp) :: e(2), nv(2), dgdr(3), drdq(6), dadphi, root, alpha_q(6), beta_q(6)
        integer :: j, kind
        e = b%cs(:, i)
        g = body_line(self, b, i, e)
        if (g%r2 <= g%r1) return
        nv = [-e(2), e(1)]
        dadphi = -dot_product(nv, self%ng)
        do j = 1, 2
            kind = merge(g%end1, g%end2, j == 1)
            if (kind == END_BODY) cycle
            root = merge(g%r1, g%r2, j == 1)
            drdq = 0.0_wp
            if (kind == END_PLANE) then
                ! r = -d0/a: d0 = -(c - p0).n_g, a = -e.n_g
                drdq(1:2) = self%ng/g%a
                drdq(3) = -root/g%a*dadphi
            else
                ! r = -alpha/beta, alpha = k d0 + c v0, beta = k a + c bb
                alpha_q = 0.0_wp
                alpha_q(1:2) = -self%k*self%ng
                alpha_q(4:5) = -self%c*self%ng
                beta_q = 0.0_wp
                beta_q(3) = self%k*dadphi + self%c*b%w(i)*dot_product(e, self%ng)
                beta_q(6) = self%c*dadphi
                drdq = -(alpha_q + root*beta_q)/(self%k*g%a + self%c*g%bb)
            end if
            dgdr = interval_rate(self, g, e, j)
            blk(:, 1:6) = blk(:, 1:6) + spread(dgdr, 2, 6)*spread(drdq, 1, 3)
        end do
    end subroutine end_terms

    !> d(F_x, F_y, M)/d r_j of the two force points of interval [r1, r2] of line g (axis e),
    !! j = 1 or 2, the state held (the points move with the ends and stand for half of it).
    pure function interval_rate(self, g, e, j) result(dgdr)
        class(ground_effect_t), intent(in) :: self
        type(line_t), intent(in) :: g
        real(wp), intent(in) :: e(2)
        integer, intent(in) :: j
        real(wp) :: dgdr(3)
        real(wp) :: mid, half, dhalf, r, drs, u, du, th, dth, dir(2), ddir(2), f(2), df(2)
        integer :: s
        mid = 0.5_wp*(g%r1 + g%r2)
        half = 0.5_wp*(g%r2 - g%r1)
        dhalf = merge(-0.5_wp, 0.5_wp, j == 1)
        du = self%k*g%a + self%c*g%bb
        dgdr = 0.0_wp
        do s = -1, 1, 2
            r = mid + 2.0_wp*GAUSS_OFFSET*real(s, wp)*half
            drs = 0.5_wp + merge(-1.0_wp, 1.0_wp, j == 1)*GAUSS_OFFSET*real(s, wp)
            u = self%k*(g%d0 + g%a*r) + self%c*(g%v0 + g%bb*r)
            th = smooth_sign((g%t0 + g%t1*r)/self%v_reg)
            dth = (1.0_wp - th**2)*g%t1/self%v_reg
            dir = self%ng - self%mu*th*self%tg
            ddir = -self%mu*dth*self%tg
            f = half*u*dir
            df = dhalf*u*dir + half*(du*dir + u*ddir)*drs
            dgdr(1:2) = dgdr(1:2) + df
            dgdr(3) = dgdr(3) + drs*(e(1)*f(2) - e(2)*f(1)) + r*(e(1)*df(2) - e(2)*df(1))
        end do
    end function interval_rate

    !> The contact springs' energy, sum k_p delta^2 / 2, J.
    pure real(wp) function ground_energy(self, t, b) result(e)
        class(ground_effect_t), intent(in) :: self
        real(wp), intent(in) :: t
        type(bodies_t), intent(in) :: b
        type(contact_t) :: cc(2*b%n)
        real(wp) :: er
        integer :: nc
        call touching(self, b, cc, nc, e, er)
    end function ground_energy

    pure subroutine ground_power(self, t, b, dissipation, work)
        class(ground_effect_t), intent(in) :: self
        real(wp), intent(in) :: t
        type(bodies_t), intent(in) :: b
        real(wp), intent(inout) :: dissipation, work
        type(contact_t) :: cc(2*b%n)
        real(wp) :: es, er
        integer :: nc
        call touching(self, b, cc, nc, es, er)
        call add_contact_power(self, cc(:nc), er, dissipation)
    end subroutine ground_power

    !> Add the dissipation rate of the contacts: the power the force points take from the
    !! rope, F_N delta' + mu F_N tanh(v_t/v_reg) v_t each, less the rate at which the
    !! springs store energy, spring_rate (W). Where F_N is clipped to 0 (separating faster
    !! than the spring relaxes) the springs' energy still falls: -k delta delta' > 0.
    pure subroutine add_contact_power(self, cc, spring_rate, dissipation)
        class(ground_effect_t), intent(in) :: self
        type(contact_t), intent(in) :: cc(:)
        real(wp), intent(in) :: spring_rate
        real(wp), intent(inout) :: dissipation
        integer :: k
        dissipation = dissipation - spring_rate
        do k = 1, size(cc)
            associate (c => cc(k))
                dissipation = dissipation + c%fn*c%ddelta + self%mu*c%fn*c%th*c%vt
            end associate
        end do
    end subroutine add_contact_power

    !> The contact springs are potential energy, and their stiffness acts only while a point
    !! touches: absent from the spectrum of a rope above the ground, it would not bound a
    !! fixed step chosen at the start.
    pure function ground_split_refusal(self) result(why)
        class(ground_effect_t), intent(in) :: self
        character(len=:), allocatable :: why
        why = 'ground contact: its springs act only while the rope touches, so a fixed '// &
              'step chosen from the spectrum at the start need not be stable in contact'
    end function ground_split_refusal

    !> Sum of the normal contact forces on all bodies, N (a diagnostic).
    pure real(wp) function ground_total_normal_force(self, b) result(total)
        class(ground_effect_t), intent(in) :: self
        type(bodies_t), intent(in) :: b
        type(contact_t) :: cc(2*b%n)
        real(wp) :: es, er
        integer :: nc
        call touching(self, b, cc, nc, es, er)
        total = sum(cc(:nc)%fn)
    end function ground_total_normal_force
end module ropedyn_effect_ground
