!> Contact of the rope with a ground plane (docs/theory/effects.md, "Ground contact").
!!
!! The plane passes through p0 with unit normal n_g pointing to the free side. The law is
!! per metre of rope (k in N/m per metre, c in N s/m per metre); on each body it is
!! integrated by the two-point Gauss rule: contact acts at X = c +- (l/(2 sqrt 3)) e, each
!! point standing for half the body's length: stiffness k_p = k l/2, damping c_p = c l/2.
!! For a body wholly in contact the rule is exact (the penetration is linear along the body,
!! the springs' energy quadratic): force k l delta and moment k l^3/12 per radian about the
!! centre, as the distributed law gives. (At the end points the body's rotation would get
!! three times the distributed stiffness and damping: a spurious fast mode of a rope lying
!! on the ground.) With the penetration delta = -(X - p0) . n_g > 0 and its rate
!! delta' = -V . n_g (V the point's velocity), the normal force is
!!     F_N = max(0, k_p delta + c_p delta'),
!! and regularized Coulomb friction acts along the tangent t_g = (-n_g2, n_g1):
!!     F_T = -mu F_N tanh(v_t / v_reg),  v_t = V . t_g.
!! The contact springs store V_c = sum k_p delta^2/2 (in the elastic energy); the
!! dissipation rate is (F_N - k_p delta) delta' + mu F_N tanh(v_t/v_reg) v_t >= 0.
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

    !> The contact at one Gauss point of a body (all zero but i, e, r and delta when not in
    !! contact). No default initialization: `contact` sets every component, and the lists
    !! of contacts (automatic arrays of 2n in every caller of `touching`) would otherwise be
    !! filled with zeros on each call before being written.
    type :: contact_t
        integer :: i                  !< the body
        real(wp) :: e(2)              !< its axis (cos phi, sin phi)
        real(wp) :: r                 !< offset of the point from the body's centre, m
        real(wp) :: delta             !< penetration, m
        real(wp) :: ddelta            !< its rate, m/s
        real(wp) :: fn                !< normal force, N
        real(wp) :: vt                !< tangential speed, m/s
        real(wp) :: th                !< tanh(vt / v_reg)
        real(wp) :: f(2)              !< force on the body, N
    end type contact_t

    !> the Gauss points' offset from a body's centre, in body lengths: 1/(2 sqrt 3)
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

    !> Contact at Gauss point s (-1: towards end A, +1: towards B) of body i, the point at
    !! offset r = s GAUSS_OFFSET l from the centre: penetration, its rate, normal force,
    !! tangential speed, tanh(v_t / v_reg) and the force vector (zero when not in
    !! contact). e: the body's axis (cos phi, sin phi), computed once per body by the caller
    !! for both points.
    pure function contact(self, b, i, s, e) result(c)
        class(ground_effect_t), intent(in) :: self
        type(bodies_t), intent(in) :: b
        integer, intent(in) :: i, s
        real(wp), intent(in) :: e(2)
        type(contact_t) :: c
        real(wp) :: nv(2), x(2), v(2), kp, cp
        c = contact_t(i=i, e=e, r=GAUSS_OFFSET*real(s, wp)*b%l(i), delta=0.0_wp, ddelta=0.0_wp, &
                      fn=0.0_wp, vt=0.0_wp, th=0.0_wp, f=0.0_wp)
        nv = [-e(2), e(1)]
        x = b%c(:, i) + c%r*e
        c%delta = -dot_product(x - self%p0, self%ng)
        if (c%delta <= 0.0_wp) return
        v = b%v(:, i) + c%r*b%w(i)*nv
        c%ddelta = -dot_product(v, self%ng)
        kp = 0.5_wp*self%k*b%l(i)
        cp = 0.5_wp*self%c*b%l(i)
        c%fn = kp*c%delta + cp*c%ddelta
        if (c%fn <= 0.0_wp) then
            c%fn = 0.0_wp
            return
        end if
        c%vt = dot_product(v, self%tg)
        c%th = smooth_sign(c%vt/self%v_reg)
        c%f = c%fn*(self%ng - self%mu*c%th*self%tg)
    end function contact

    !> tanh(x), as 1 - 2/(exp(2x) + 1): libm's tanh goes through expm1, twice the cost of
    !! exp, for a relative accuracy the friction does not need (the absolute error here is
    !! a few 1e-16, also near x = 0).
    elemental real(wp) function smooth_sign(x) result(th)
        real(wp), intent(in) :: x
        th = 1.0_wp - 2.0_wp/(exp(2.0_wp*min(x, 350.0_wp)) + 1.0_wp)
    end function smooth_sign

    !> The contact points below the plane (delta > 0), body by body, A's side before B's, in
    !! cc(1:nc) (cc holds at least 2 b%n). Those separating faster than their spring relaxes
    !! carry no force (fn = 0).
    pure subroutine touching(self, b, cc, nc)
        class(ground_effect_t), intent(in) :: self
        type(bodies_t), intent(in) :: b
        type(contact_t), intent(inout) :: cc(:)
        integer, intent(out) :: nc
        real(wp) :: hn, rg
        integer :: i, s
        nc = 0
        do i = 1, b%n
            ! the centre's height above the plane and the Gauss points' offset along the
            ! normal: most bodies are clear of the plane at both points
            hn = dot_product(b%c(:, i) - self%p0, self%ng)
            rg = GAUSS_OFFSET*b%l(i)*abs(dot_product(b%cs(:, i), self%ng))
            if (hn - rg >= 0.0_wp) cycle
            do s = -1, 1, 2
                nc = nc + 1
                cc(nc) = contact(self, b, i, s, b%cs(:, i))
                if (cc(nc)%delta <= 0.0_wp) nc = nc - 1
            end do
        end do
    end subroutine touching

    pure subroutine ground_add_forces(self, t, b, f, m)
        class(ground_effect_t), intent(in) :: self
        real(wp), intent(in) :: t
        type(bodies_t), intent(in) :: b
        real(wp), intent(inout) :: f(:, :), m(:)
        type(contact_t) :: cc(2*b%n)
        integer :: nc
        call touching(self, b, cc, nc)
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
        integer :: nc
        call touching(self, b, cc, nc)
        call add_contact_forces(cc(:nc), f, m)
        call add_contact_power(self, b, cc(:nc), dissipation)
    end subroutine ground_add_forces_power

    pure subroutine ground_add_jacobian(self, t, b, jac)
        class(ground_effect_t), intent(in) :: self
        real(wp), intent(in) :: t
        type(bodies_t), intent(in) :: b
        real(wp), intent(inout) :: jac(:, :, :)
        type(contact_t) :: cc(2*b%n)
        real(wp) :: kp, cp, dir(2), dfdx(2, 2), dfdv(2, 2)
        integer :: k, nc, p
        call touching(self, b, cc, nc)
        do k = 1, nc
            associate (c => cc(k), i => cc(k)%i)
                if (c%fn <= 0.0_wp) cycle
                kp = 0.5_wp*self%k*b%l(i)
                cp = 0.5_wp*self%c*b%l(i)
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

    !> The contact springs' energy, sum k_p delta^2 / 2, J.
    pure real(wp) function ground_energy(self, t, b) result(e)
        class(ground_effect_t), intent(in) :: self
        real(wp), intent(in) :: t
        type(bodies_t), intent(in) :: b
        type(contact_t) :: cc(2*b%n)
        integer :: k, nc
        e = 0.0_wp
        call touching(self, b, cc, nc)
        do k = 1, nc
            e = e + 0.25_wp*self%k*b%l(cc(k)%i)*cc(k)%delta**2
        end do
    end function ground_energy

    pure subroutine ground_power(self, t, b, dissipation, work)
        class(ground_effect_t), intent(in) :: self
        real(wp), intent(in) :: t
        type(bodies_t), intent(in) :: b
        real(wp), intent(inout) :: dissipation, work
        type(contact_t) :: cc(2*b%n)
        integer :: nc
        call touching(self, b, cc, nc)
        call add_contact_power(self, b, cc(:nc), dissipation)
    end subroutine ground_power

    !> Add the dissipation rate of the contacts cc.
    pure subroutine add_contact_power(self, b, cc, dissipation)
        class(ground_effect_t), intent(in) :: self
        type(bodies_t), intent(in) :: b
        type(contact_t), intent(in) :: cc(:)
        real(wp), intent(inout) :: dissipation
        integer :: k
        do k = 1, size(cc)
            associate (c => cc(k))
                ! F_N = 0 when separating faster than the spring relaxes: then the spring's
                ! energy still falls at -k_p delta delta' > 0 (th = 0 there)
                dissipation = dissipation + (c%fn - 0.5_wp*self%k*b%l(c%i)*c%delta)*c%ddelta &
                              + self%mu*c%fn*c%th*c%vt
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
        integer :: nc
        call touching(self, b, cc, nc)
        total = sum(cc(:nc)%fn)
    end function ground_total_normal_force
end module ropedyn_effect_ground
