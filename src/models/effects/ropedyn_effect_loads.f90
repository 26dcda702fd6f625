!> Point loads at given points of the rope: a force of fixed direction in the global frame,
!! F(t) = F0 + A sin(omega t + phase), acting at the point X = c + r e of one body (r its
!! offset from the body's centre along the body). Its moment about the centre is r e x F.
!! A load is an outside agent: its work rate F . V (V the point's velocity) is integrated as
!! external work (energy_t%support_work).
module ropedyn_effect_loads
    use ropedyn_kinds, only: wp
    use ropedyn_effect, only: body_effect_t, bodies_t, point_force_block
    implicit none
    private
    public :: loads_effect_t, point_load_t

    type :: point_load_t
        integer :: body = 0                !< body the load acts on
        real(wp) :: r = 0.0_wp             !< offset from the body's centre along it, m
        real(wp) :: f0(2) = 0.0_wp         !< constant part, N
        real(wp) :: amplitude(2) = 0.0_wp  !< amplitude of the harmonic part, N
        real(wp) :: omega = 0.0_wp         !< rad/s
        real(wp) :: phase = 0.0_wp         !< rad
    end type point_load_t

    type, extends(body_effect_t) :: loads_effect_t
        type(point_load_t), allocatable :: loads(:)
    contains
        procedure :: name => loads_name
        procedure :: add_forces => loads_add_forces
        procedure :: add_jacobian => loads_add_jacobian
        procedure :: power => loads_power
        procedure :: does_work => loads_does_work
    end type loads_effect_t

contains

    pure function loads_name(self) result(name)
        class(loads_effect_t), intent(in) :: self
        character(len=:), allocatable :: name
        name = 'point loads'
    end function loads_name

    pure logical function loads_does_work(self) result(does)
        class(loads_effect_t), intent(in) :: self
        does = .true.
    end function loads_does_work

    pure function load_force(load, t) result(f)
        type(point_load_t), intent(in) :: load
        real(wp), intent(in) :: t
        real(wp) :: f(2)
        f = load%f0 + load%amplitude*sin(load%omega*t + load%phase)
    end function load_force

    pure subroutine loads_add_forces(self, t, b, f, m)
        class(loads_effect_t), intent(in) :: self
        real(wp), intent(in) :: t
        type(bodies_t), intent(in) :: b
        real(wp), intent(inout) :: f(:, :), m(:)
        real(wp) :: fl(2), e(2)
        integer :: k, i
        do k = 1, size(self%loads)
            i = self%loads(k)%body
            fl = load_force(self%loads(k), t)
            e = [cos(b%phi(i)), sin(b%phi(i))]
            f(:, i) = f(:, i) + fl
            m(i) = m(i) + self%loads(k)%r*(e(1)*fl(2) - e(2)*fl(1))
        end do
    end subroutine loads_add_forces

    pure subroutine loads_add_jacobian(self, t, b, jac)
        class(loads_effect_t), intent(in) :: self
        real(wp), intent(in) :: t
        type(bodies_t), intent(in) :: b
        real(wp), intent(inout) :: jac(:, :, :)
        real(wp), parameter :: zero(2, 2) = 0.0_wp
        integer :: k, i
        do k = 1, size(self%loads)
            i = self%loads(k)%body
            jac(:, :, i) = jac(:, :, i) + point_force_block(self%loads(k)%r, b%phi(i), b%w(i), &
                                                            load_force(self%loads(k), t), &
                                                            zero, zero)
        end do
    end subroutine loads_add_jacobian

    pure subroutine loads_power(self, t, b, dissipation, work)
        class(loads_effect_t), intent(in) :: self
        real(wp), intent(in) :: t
        type(bodies_t), intent(in) :: b
        real(wp), intent(inout) :: dissipation, work
        real(wp) :: nv(2)
        integer :: k, i
        do k = 1, size(self%loads)
            i = self%loads(k)%body
            nv = [-sin(b%phi(i)), cos(b%phi(i))]
            work = work + dot_product(load_force(self%loads(k), t), &
                                      b%v(:, i) + self%loads(k)%r*b%w(i)*nv)
        end do
    end subroutine loads_power
end module ropedyn_effect_loads
