!> The added mass of the water on a body (theory page "Water"): a body of length l moving
!! through still water, or water moving with a uniform current u, carries water with it,
!! normal to its axis m_an = C_a rho_w A per metre and along it m_at = C_at rho_w A (A the
!! displaced area). Wetted by the fraction f (ropedyn_wetting), its kinetic energy with the
!! velocity relative to the water v_r = v - u and angular velocity w is
!!     T_a = 1/2 v_r^T A v_r + 1/2 J_a w^2,   A = f B,  B = l (m_at e e^T + m_an n n^T),
!!                                            J_a = f J_b,  J_b = m_an l^3/12,
!! and Lagrange's equations with it add to the body's mass block A (translation) and J_a
!! (rotation), and to its generalized force
!!     g_v = -(f' B + f w B') v_r + 1/2 f_x (v_r^T B v_r + J_b w^2) e_x
!!     g_w = -f' J_b w + 1/2 (f_phi v_r^T B v_r + f v_r^T B' v_r + f_phi J_b w^2)
!! with f' = f_x x' + f_phi w the rate of the wetting and B' = dB/dphi = l (m_at - m_an)
!! (e n^T + n e^T). Fully wet and still, g_w is the Munk moment l (m_at - m_an) (v.e)(v.n).
!! The quantity these equations keep is T + 1/2 v^T A v + 1/2 J_a w^2 + V - 1/2 u^T A u:
!! the kinetic energy counts the added mass with the velocity itself, and -1/2 u^T A u is a
!! potential of the current (zero without one).
module ropedyn_added_mass
    use ropedyn_kinds, only: wp
    use ropedyn_wetting, only: wetting_t, wet_t
    implicit none
    private
    public :: added_mass_t

    type :: added_mass_t
        real(wp) :: man = 0.0_wp      !< normal added mass per length, kg/m
        real(wp) :: mat = 0.0_wp      !< tangential added mass per length, kg/m
        real(wp) :: u(2) = 0.0_wp     !< current, m/s
        type(wetting_t) :: wetting
    contains
        procedure :: terms => added_terms
        procedure :: terms_e => added_terms_e
        procedure :: kinetic => added_kinetic
        procedure :: potential => added_potential
    end type added_mass_t

contains

    !> The body's added mass block (3x3 on (x, y, phi)) and generalized force g (N, N, N m)
    !! at centre c (m), angle phi (rad), velocity v (m/s), angular velocity w (rad/s),
    !! length l (m).
    pure subroutine added_terms(self, c, phi, v, w, l, blk, g)
        class(added_mass_t), intent(in) :: self
        real(wp), intent(in) :: c(2), phi, v(2), w, l
        real(wp), intent(out) :: blk(3, 3), g(3)
        call self%terms_e(c, [cos(phi), sin(phi)], v, w, l, blk, g)
    end subroutine added_terms

    !> added_terms with the body's axis e = (cos phi, sin phi) given (a model that keeps
    !! them computes no angle's cosine again).
    pure subroutine added_terms_e(self, c, e, v, w, l, blk, g)
        class(added_mass_t), intent(in) :: self
        real(wp), intent(in) :: c(2), e(2), v(2), w, l
        real(wp), intent(out) :: blk(3, 3), g(3)
        type(wet_t) :: wt
        real(wp) :: nv(2), jb, vr(2), ve, vn, bv(2), bpv(2), q, qp, f_phi, fdot
        blk = 0.0_wp
        g = 0.0_wp
        wt = self%wetting%of(c(1), e(1), 0.5_wp*l)
        if (wt%f <= 0.0_wp .and. wt%f_d == 0.0_wp .and. wt%f_c == 0.0_wp) return
        nv = [-e(2), e(1)]
        ! B = l (m_at e e^T + m_an n n^T) and B' = l (m_at - m_an)(e n^T + n e^T) act on v_r
        ! through its components along the axis and the normal
        vr = v - self%u
        ve = dot_product(vr, e)
        vn = dot_product(vr, nv)
        bv = l*(self%mat*ve*e + self%man*vn*nv)
        bpv = l*(self%mat - self%man)*(vn*e + ve*nv)
        jb = self%man*l**3/12.0_wp
        blk(1, 1) = wt%f*l*(self%mat*e(1)**2 + self%man*nv(1)**2)
        blk(2, 2) = wt%f*l*(self%mat*e(2)**2 + self%man*nv(2)**2)
        blk(1, 2) = wt%f*l*(self%mat*e(1)*e(2) + self%man*nv(1)*nv(2))
        blk(2, 1) = blk(1, 2)
        blk(3, 3) = wt%f*jb
        q = dot_product(vr, bv)
        qp = dot_product(vr, bpv)
        f_phi = -e(2)*wt%f_c
        fdot = wt%f_d*v(1) + f_phi*w
        g(1:2) = -(fdot*bv + wt%f*w*bpv)
        g(1) = g(1) + 0.5_wp*wt%f_d*(q + jb*w**2)
        g(3) = -fdot*jb*w + 0.5_wp*(f_phi*q + wt%f*qp + f_phi*jb*w**2)
    end subroutine added_terms_e

    !> 1/2 v^T A v + 1/2 J_a w^2 of the body, J.
    pure real(wp) function added_kinetic(self, c, phi, v, w, l) result(e_k)
        class(added_mass_t), intent(in) :: self
        real(wp), intent(in) :: c(2), phi, v(2), w, l
        real(wp) :: blk(3, 3), g(3)
        call self%terms(c, phi, v, w, l, blk, g)
        e_k = 0.5_wp*(dot_product(v, matmul(blk(1:2, 1:2), v)) + blk(3, 3)*w**2)
    end function added_kinetic

    !> -1/2 u^T A u of the body (the current's potential), J.
    pure real(wp) function added_potential(self, c, phi, l) result(e_p)
        class(added_mass_t), intent(in) :: self
        real(wp), intent(in) :: c(2), phi, l
        real(wp) :: blk(3, 3), g(3)
        e_p = 0.0_wp
        if (.not. any(abs(self%u) > 0.0_wp)) return
        call self%terms(c, phi, self%u, 0.0_wp, l, blk, g)
        e_p = -0.5_wp*dot_product(self%u, matmul(blk(1:2, 1:2), self%u))
    end function added_potential
end module ropedyn_added_mass
