!> How much of a body lies in the water: the free surface is the line x = surface (x down,
!! the water where x > surface), and a body of length l = 2h with centre depth d = x_c -
!! surface and axis cos phi = c reaches from d - h c to d + h c below it. Its wetness along
!! the axis is a step H(z) smoothed over the section's half-thickness delta (the quintic
!! smoothstep, twice continuously differentiable), so that a body crossing the surface is
!! wetted by its submerged fraction and every force made of it is smooth. The integrals the
!! water's forces need (theory page "Water"), with a = h c:
!!     f    = (1/l) int_{-h}^{h} H(d + s c) ds          the wetted fraction
!!     f_d  = df/dd,  f_c = df/dc
!!     i1   = int s H(d + s c) ds   (m^2, = dV/dc: the moment of the buoyancy)
!!     j2   = int s^2 H'(d + s c) ds = di1/dc (m^2)
!!     v    = int G(d + s c) ds     (m^2, G' = H: the buoyancy's potential per rho g A)
!! in closed form from the antiderivatives G and K of H, and for a nearly level body
!! (|a| < delta/200, where the closed forms cancel) from their Taylor series in a. A body
!! wholly in the water or wholly out of it takes the exact values (1 and 0).
!! Summed over the bodies of a straight rope, f l adds up to the wetted length exactly:
!! the smoothing is symmetric about the surface.
module ropedyn_wetting
    use ropedyn_kinds, only: wp
    implicit none
    private
    public :: wetting_t, wet_t

    !> Where the water is.
    type :: wetting_t
        real(wp) :: surface = 0.0_wp   !< x of the free surface, m (water where x > surface)
        real(wp) :: delta = 1.0e-3_wp  !< half-width of the smoothed step, m (> 0)
    contains
        procedure :: of => wet_of
    end type wetting_t

    !> The wetness of one body (see the module header).
    type :: wet_t
        real(wp) :: f = 0.0_wp, f_d = 0.0_wp, f_c = 0.0_wp   !< -, 1/m, -
        real(wp) :: i1 = 0.0_wp, j2 = 0.0_wp, v = 0.0_wp     !< m^2
    end type wet_t

    !> |a|/delta below which the series are used
    real(wp), parameter :: SERIES_BELOW = 0.005_wp

contains

    !> The wetness of a body of centre x `xc` (m), axis cosine `c` and half length `h` (m).
    pure elemental function wet_of(self, xc, c, h) result(w)
        class(wetting_t), intent(in) :: self
        real(wp), intent(in) :: xc, c, h
        type(wet_t) :: w
        real(wp) :: d, a, zp, zm, dl, gp, gm, kp, km, hp, hm
        d = xc - self%surface
        a = h*c
        dl = self%delta
        if (d - abs(a) >= dl) then
            ! wholly wet: H = 1 along the body, G(z) = z
            w%f = 1.0_wp
            w%v = 2.0_wp*h*d
            return
        else if (d + abs(a) <= -dl) then
            return                                  ! wholly dry
        end if
        if (abs(a) < SERIES_BELOW*dl) then
            w%f = step(d, dl) + a**2/6.0_wp*step2(d, dl)
            w%f_d = step1(d, dl) + a**2/6.0_wp*step3(d, dl)
            w%f_c = h*a/3.0_wp*step2(d, dl)
            w%i1 = h**2*(2.0_wp*a/3.0_wp*step1(d, dl) + a**3/15.0_wp*step3(d, dl))
            w%j2 = h**3*(2.0_wp/3.0_wp*step1(d, dl) + a**2/5.0_wp*step3(d, dl))
            w%v = h*(2.0_wp*ramp(d, dl) + a**2/3.0_wp*step1(d, dl))
            return
        end if
        zp = d + a
        zm = d - a
        gp = ramp(zp, dl)
        gm = ramp(zm, dl)
        kp = ramp2(zp, dl)
        km = ramp2(zm, dl)
        hp = step(zp, dl)
        hm = step(zm, dl)
        w%f = (gp - gm)/(2.0_wp*a)
        w%f_d = (hp - hm)/(2.0_wp*a)
        w%f_c = h*((hp + hm)/(2.0_wp*a) - w%f/a)
        w%i1 = h**2*((gp + gm)/a - (kp - km)/a**2)
        w%j2 = h**3*(hp - hm)/a - 2.0_wp*h*w%i1/a
        w%v = h*(kp - km)/a
    end function wet_of

    !> H(z): 0 below -delta, 1 above delta, the quintic smoothstep between.
    pure real(wp) function step(z, dl) result(r)
        real(wp), intent(in) :: z, dl
        real(wp) :: u
        u = (z + dl)/(2.0_wp*dl)
        if (u <= 0.0_wp) then
            r = 0.0_wp
        else if (u >= 1.0_wp) then
            r = 1.0_wp
        else
            r = u**3*(10.0_wp + u*(-15.0_wp + 6.0_wp*u))
        end if
    end function step

    !> H'(z), 1/m.
    pure real(wp) function step1(z, dl) result(r)
        real(wp), intent(in) :: z, dl
        real(wp) :: u
        u = (z + dl)/(2.0_wp*dl)
        r = 0.0_wp
        if (u > 0.0_wp .and. u < 1.0_wp) r = 30.0_wp*u**2*(1.0_wp - u)**2/(2.0_wp*dl)
    end function step1

    !> H''(z), 1/m^2.
    pure real(wp) function step2(z, dl) result(r)
        real(wp), intent(in) :: z, dl
        real(wp) :: u
        u = (z + dl)/(2.0_wp*dl)
        r = 0.0_wp
        if (u > 0.0_wp .and. u < 1.0_wp) &
            r = 60.0_wp*u*(1.0_wp - u)*(1.0_wp - 2.0_wp*u)/(2.0_wp*dl)**2
    end function step2

    !> H'''(z), 1/m^3.
    pure real(wp) function step3(z, dl) result(r)
        real(wp), intent(in) :: z, dl
        real(wp) :: u
        u = (z + dl)/(2.0_wp*dl)
        r = 0.0_wp
        if (u > 0.0_wp .and. u < 1.0_wp) r = (60.0_wp - 360.0_wp*u + 360.0_wp*u**2)/ &
                                             (2.0_wp*dl)**3
    end function step3

    !> G(z) = int H: 0 below -delta, z above delta, (2 delta) P1(u) between, m.
    pure real(wp) function ramp(z, dl) result(r)
        real(wp), intent(in) :: z, dl
        real(wp) :: u
        u = (z + dl)/(2.0_wp*dl)
        if (u <= 0.0_wp) then
            r = 0.0_wp
        else if (u >= 1.0_wp) then
            r = z
        else
            r = 2.0_wp*dl*u**4*(2.5_wp + u*(-3.0_wp + u))
        end if
    end function ramp

    !> K(z) = int G: 0 below -delta, z^2/2 + delta^2/14 above delta, (2 delta)^2 P2(u)
    !! between, m^2.
    pure real(wp) function ramp2(z, dl) result(r)
        real(wp), intent(in) :: z, dl
        real(wp) :: u
        u = (z + dl)/(2.0_wp*dl)
        if (u <= 0.0_wp) then
            r = 0.0_wp
        else if (u >= 1.0_wp) then
            r = 0.5_wp*z**2 + dl**2/14.0_wp
        else
            r = (2.0_wp*dl)**2*u**5*(0.5_wp + u*(-0.5_wp + u/7.0_wp))
        end if
    end function ramp2
end module ropedyn_wetting
