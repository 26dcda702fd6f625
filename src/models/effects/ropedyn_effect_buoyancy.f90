!> Buoyancy of the water on each body (theory page "Water"): the water (x > surface, x
!! down) pushes a body up by the weight of the water it displaces, rho_w g A per metre of its
!! wetted length, acting at the centre of its wetted part. From the potential
!!     V = rho_w g A int_{-h}^{h} G(d + s cos phi) ds = rho_w g A v      (ropedyn_wetting)
!! the force and moment about the centre are
!!     F_x = -rho_w g A l f,   F_y = 0,   M = rho_w g A i1 sin phi,
!! and their derivatives dF_x/dx = -rho_w g A l f_d, dF_x/dphi = dM/dx = rho_w g A l f_c
!! sin phi, dM/dphi = rho_w g A (i1 cos phi - j2 sin^2 phi). The potential is the effect's
!! energy; buoyancy neither dissipates nor does work.
module ropedyn_effect_buoyancy
    use ropedyn_kinds, only: wp
    use ropedyn_effect, only: body_effect_t, bodies_t
    use ropedyn_wetting, only: wetting_t, wet_t
    implicit none
    private
    public :: buoyancy_effect_t, buoyancy_effect

    type, extends(body_effect_t) :: buoyancy_effect_t
        private
        real(wp) :: w = 0.0_wp          !< rho_w g A: the weight of displaced water per m, N/m
        type(wetting_t) :: wetting
    contains
        procedure :: name => buoyancy_name
        procedure :: add_forces => buoyancy_add_forces
        procedure :: add_jacobian => buoyancy_add_jacobian
        procedure :: energy => buoyancy_energy
        ! all of it: rho g A v grows with the depth below the surface, as gravity's with x
        procedure :: level_energy => buoyancy_energy
    end type buoyancy_effect_t

contains

    !> Buoyancy of water of density rho (kg/m^3) under gravity g (m/s^2) on bodies of
    !! displaced area area (m^2), the water where `wetting` says.
    pure function buoyancy_effect(rho, g, area, wetting) result(eff)
        real(wp), intent(in) :: rho, g, area
        type(wetting_t), intent(in) :: wetting
        type(buoyancy_effect_t) :: eff
        eff%w = rho*g*area
        eff%wetting = wetting
    end function buoyancy_effect

    pure function buoyancy_name(self) result(name)
        class(buoyancy_effect_t), intent(in) :: self
        character(len=:), allocatable :: name
        name = 'buoyancy'
    end function buoyancy_name

    pure subroutine buoyancy_add_forces(self, t, b, f, m)
        class(buoyancy_effect_t), intent(in) :: self
        real(wp), intent(in) :: t
        type(bodies_t), intent(in) :: b
        real(wp), intent(inout) :: f(:, :), m(:)
        type(wet_t) :: wt
        integer :: i
        do i = 1, b%n
            wt = self%wetting%of(b%c(1, i), b%cs(1, i), 0.5_wp*b%l(i))
            f(1, i) = f(1, i) - self%w*b%l(i)*wt%f
            m(i) = m(i) + self%w*wt%i1*b%cs(2, i)
        end do
    end subroutine buoyancy_add_forces

    pure subroutine buoyancy_add_jacobian(self, t, b, jac)
        class(buoyancy_effect_t), intent(in) :: self
        real(wp), intent(in) :: t
        type(bodies_t), intent(in) :: b
        real(wp), intent(inout) :: jac(:, :, :)
        type(wet_t) :: wt
        real(wp) :: s, c, cross
        integer :: i
        do i = 1, b%n
            c = b%cs(1, i)
            s = b%cs(2, i)
            wt = self%wetting%of(b%c(1, i), c, 0.5_wp*b%l(i))
            cross = self%w*b%l(i)*wt%f_c*s
            jac(1, 1, i) = jac(1, 1, i) - self%w*b%l(i)*wt%f_d
            jac(1, 3, i) = jac(1, 3, i) + cross
            jac(3, 1, i) = jac(3, 1, i) + cross
            jac(3, 3, i) = jac(3, 3, i) + self%w*(wt%i1*c - wt%j2*s**2)
        end do
    end subroutine buoyancy_add_jacobian

    !> The potential of the buoyancy, J.
    pure real(wp) function buoyancy_energy(self, t, b) result(e)
        class(buoyancy_effect_t), intent(in) :: self
        real(wp), intent(in) :: t
        type(bodies_t), intent(in) :: b
        type(wet_t) :: wt
        integer :: i
        e = 0.0_wp
        do i = 1, b%n
            wt = self%wetting%of(b%c(1, i), b%cs(1, i), 0.5_wp*b%l(i))
            e = e + self%w*wt%v
        end do
    end function buoyancy_energy
end module ropedyn_effect_buoyancy
