!> External effects acting on the bodies of a rope model (RFEM elements, MPP rods).
!!
!! A body is a rigid segment: centre c (m), angle phi (rad) from the x axis (down) towards y,
!! centre velocity v (m/s), angular velocity w (rad/s), length l (m); unit vectors
!! e = (cos phi, sin phi) along it and n = (-sin phi, cos phi) across it. An effect adds to
!! the force (2) and moment (1, about the centre) of each body it acts on; it reports its
!! potential energy (e.g. contact springs), the rate at which it dissipates energy and the
!! rate at which it does external work (e.g. a current or a prescribed load), so that
!!     T + V + dissipated - external work = E0
!! holds with these terms included; and, for RFEM's analytic Jacobian, the 3x6 block of the
!! derivatives of each body's (Fx, Fy, M) with respect to its own (x, y, phi, vx, vy, w).
!! Every effect here acts on each body separately, so the blocks keep RFEM's band.
!!
!! A model holds only the effects its spec enables (`effect_box_t` array): an effect that is
!! off is not allocated and costs nothing.
module ropedyn_effect
    use ropedyn_kinds, only: wp
    use ropedyn_trig, only: cos_sin
    implicit none
    private
    public :: body_effect_t, effect_box_t, bodies_t, point_force_block, set_axes
    public :: add_forces_of, add_jacobians_of, add_energies_of, add_powers_of
    public :: add_forces_powers_of, add_level_energies_of

    !> Kinematics of all bodies of a model at one instant.
    type :: bodies_t
        integer :: n = 0
        real(wp), allocatable :: c(:, :)    !< centres (2, n), m
        real(wp), allocatable :: phi(:)     !< angles (n), rad
        real(wp), allocatable :: v(:, :)    !< centre velocities (2, n), m/s
        real(wp), allocatable :: w(:)       !< angular velocities (n), rad/s
        real(wp), allocatable :: l(:)       !< lengths (n), m
        !> cos and sin of every angle (2, n), ropedyn_trig's (`set_axes`, or the model's own
        !! of the same angles): each body's axis e once per evaluation for every effect
        real(wp), allocatable :: cs(:, :)
    end type bodies_t

    type, abstract :: body_effect_t
    contains
        procedure(name_i), deferred :: name
        procedure(add_forces_i), deferred :: add_forces
        procedure(add_jacobian_i), deferred :: add_jacobian
        ! its part of the energy balance (the defaults: none)
        procedure :: does_work => effect_does_work, energy => effect_energy, power => effect_power
        ! the part of its energy that is a potential of the bodies' level (default: none)
        procedure :: level_energy => effect_energy
        ! add_forces and power at one instant in one call (default: the two one after the
        ! other; an effect whose power repeats its forces' work overrides it)
        procedure :: add_forces_power => effect_add_forces_power
        ! why a splitting method cannot take its forces as the rest (default: it can)
        procedure :: split_refusal => effect_split_refusal
    end type body_effect_t

    !> A container, so that a model can hold an array of different effects.
    type :: effect_box_t
        class(body_effect_t), allocatable :: e
    end type effect_box_t

    abstract interface
        pure function name_i(self) result(name)
            import :: body_effect_t
            class(body_effect_t), intent(in) :: self
            character(len=:), allocatable :: name
        end function name_i

        !> Add the effect's forces f(2, n) (N) and moments m(n) (N m) on the bodies at time t.
        pure subroutine add_forces_i(self, t, b, f, m)
            import :: body_effect_t, bodies_t, wp
            class(body_effect_t), intent(in) :: self
            real(wp), intent(in) :: t
            type(bodies_t), intent(in) :: b
            real(wp), intent(inout) :: f(:, :), m(:)
        end subroutine add_forces_i

        !> Add d(Fx, Fy, M)/d(x, y, phi, vx, vy, w) of each body into jac(3, 6, n).
        pure subroutine add_jacobian_i(self, t, b, jac)
            import :: body_effect_t, bodies_t, wp
            class(body_effect_t), intent(in) :: self
            real(wp), intent(in) :: t
            type(bodies_t), intent(in) :: b
            real(wp), intent(inout) :: jac(:, :, :)
        end subroutine add_jacobian_i
    end interface

contains

    !> Set b%cs from b%phi (allocating it when needed): after the angles change.
    pure subroutine set_axes(b)
        type(bodies_t), intent(inout) :: b
        if (allocated(b%cs)) then
            if (size(b%cs, 2) /= size(b%phi)) deallocate (b%cs)
        end if
        if (.not. allocated(b%cs)) allocate (b%cs(2, size(b%phi)))
        call cos_sin(b%phi, b%cs)
    end subroutine set_axes

    !> Potential energy of the effect, J (default: none).
    pure real(wp) function effect_energy(self, t, b) result(e)
        class(body_effect_t), intent(in) :: self
        real(wp), intent(in) :: t
        type(bodies_t), intent(in) :: b
        e = 0.0_wp
    end function effect_energy

    !> Add the dissipation rate (W, >= 0: energy the effect takes out of the rope for good)
    !! and the external power (W: work rate of an outside agent on the rope) at time t.
    pure subroutine effect_power(self, t, b, dissipation, work)
        class(body_effect_t), intent(in) :: self
        real(wp), intent(in) :: t
        type(bodies_t), intent(in) :: b
        real(wp), intent(inout) :: dissipation, work
    end subroutine effect_power

    !> add_forces, then power, at time t: an override must give the same forces and the
    !! same sums, term by term in the same order.
    pure subroutine effect_add_forces_power(self, t, b, f, m, dissipation, work)
        class(body_effect_t), intent(in) :: self
        real(wp), intent(in) :: t
        type(bodies_t), intent(in) :: b
        real(wp), intent(inout) :: f(:, :), m(:)
        real(wp), intent(inout) :: dissipation, work
        call self%add_forces(t, b, f, m)
        call self%power(t, b, dissipation, work)
    end subroutine effect_add_forces_power

    !> Why a model cannot offer a force split with this effect on ('' when it can). A
    !! splitting method (problem_t's force split) takes every effect's forces as forces
    !! other than the potential's; an effect with potential energy must say why that does
    !! not hold for it (default: '', the effect has none).
    pure function effect_split_refusal(self) result(why)
        class(body_effect_t), intent(in) :: self
        character(len=:), allocatable :: why
        why = ''
    end function effect_split_refusal

    !> True when the effect can do external work (then the model integrates it).
    pure logical function effect_does_work(self) result(does)
        class(body_effect_t), intent(in) :: self
        does = .false.
    end function effect_does_work

    !> Add the forces f(2, n) (N) and moments m(n) (N m) of all `effects` at time t.
    pure subroutine add_forces_of(effects, t, b, f, m)
        type(effect_box_t), intent(in) :: effects(:)
        real(wp), intent(in) :: t
        type(bodies_t), intent(in) :: b
        real(wp), intent(inout) :: f(:, :), m(:)
        integer :: k
        do k = 1, size(effects)
            call effects(k)%e%add_forces(t, b, f, m)
        end do
    end subroutine add_forces_of

    !> add_forces_of and add_powers_of in one pass over the `effects` (each effect's forces
    !! and power together; the same sums as the two passes, as the forces and the powers
    !! are separate sums).
    pure subroutine add_forces_powers_of(effects, t, b, f, m, dissipation, work)
        type(effect_box_t), intent(in) :: effects(:)
        real(wp), intent(in) :: t
        type(bodies_t), intent(in) :: b
        real(wp), intent(inout) :: f(:, :), m(:)
        real(wp), intent(inout) :: dissipation, work
        integer :: k
        do k = 1, size(effects)
            call effects(k)%e%add_forces_power(t, b, f, m, dissipation, work)
        end do
    end subroutine add_forces_powers_of

    !> Add the Jacobian blocks jac(3, 6, n) of all `effects` at time t.
    pure subroutine add_jacobians_of(effects, t, b, jac)
        type(effect_box_t), intent(in) :: effects(:)
        real(wp), intent(in) :: t
        type(bodies_t), intent(in) :: b
        real(wp), intent(inout) :: jac(:, :, :)
        integer :: k
        do k = 1, size(effects)
            call effects(k)%e%add_jacobian(t, b, jac)
        end do
    end subroutine add_jacobians_of

    !> Add the potential energies of all `effects` at time t to `energy`, J (one by one, in
    !! their order).
    pure subroutine add_energies_of(effects, t, b, energy)
        type(effect_box_t), intent(in) :: effects(:)
        real(wp), intent(in) :: t
        type(bodies_t), intent(in) :: b
        real(wp), intent(inout) :: energy
        integer :: k
        do k = 1, size(effects)
            energy = energy + effects(k)%e%energy(t, b)
        end do
    end subroutine add_energies_of

    !> Add the level potentials of all `effects` at time t to `energy`, J (the part of
    !! their energies whose zero is arbitrary: body_effect_t%level_energy).
    pure subroutine add_level_energies_of(effects, t, b, energy)
        type(effect_box_t), intent(in) :: effects(:)
        real(wp), intent(in) :: t
        type(bodies_t), intent(in) :: b
        real(wp), intent(inout) :: energy
        integer :: k
        do k = 1, size(effects)
            energy = energy + effects(k)%e%level_energy(t, b)
        end do
    end subroutine add_level_energies_of

    !> Add the dissipation rates and external powers (W) of all `effects` at time t.
    pure subroutine add_powers_of(effects, t, b, dissipation, work)
        type(effect_box_t), intent(in) :: effects(:)
        real(wp), intent(in) :: t
        type(bodies_t), intent(in) :: b
        real(wp), intent(inout) :: dissipation, work
        integer :: k
        do k = 1, size(effects)
            call effects(k)%e%power(t, b, dissipation, work)
        end do
    end subroutine add_powers_of

    !> Block (3, 6) of a force F acting at the point X = c + r e of a body, with velocity
    !! V = v + r w n, for the force's derivatives dfdx = dF/dX and dfdv = dF/dV (2, 2):
    !! d(F, M)/d(c, phi, v, w) with M = r e x F (moment about the centre).
    pure function point_force_block(r, phi, w, f, dfdx, dfdv) result(blk)
        real(wp), intent(in) :: r            !< offset of the point along the body, m
        real(wp), intent(in) :: phi, w       !< body angle (rad) and angular velocity (rad/s)
        real(wp), intent(in) :: f(2)         !< the force, N
        real(wp), intent(in) :: dfdx(2, 2), dfdv(2, 2)
        real(wp) :: blk(3, 6)
        real(wp) :: e(2), nv(2), dfdphi(2), dfdw(2)
        integer :: l
        e = [cos(phi), sin(phi)]
        nv = [-e(2), e(1)]
        ! dX/dphi = r n, dV/dphi = -r w e, dV/dw = r n
        dfdphi = matmul(dfdx, r*nv) - matmul(dfdv, r*w*e)
        dfdw = matmul(dfdv, r*nv)
        blk(1:2, 1:2) = dfdx
        blk(1:2, 3) = dfdphi
        blk(1:2, 4:5) = dfdv
        blk(1:2, 6) = dfdw
        ! M = r (e_x F_y - e_y F_x); dM = r (e x dF) + dphi r (n x F)
        do l = 1, 6
            blk(3, l) = r*(e(1)*blk(2, l) - e(2)*blk(1, l))
        end do
        blk(3, 3) = blk(3, 3) + r*(nv(1)*f(2) - nv(2)*f(1))
    end function point_force_block
end module ropedyn_effect
