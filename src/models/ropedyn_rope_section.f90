!> The rope's cross-section as the models use it: mass per length, the stiffnesses EA, GA
!! and EI and the damping coefficients of the three strains, per unit length of rope (a
!! spring-damper over a length l takes each divided by l). The one place where the
!! material values of `&rope` become these numbers (the theory pages, "Springs and
!! dampers").
module ropedyn_rope_section
    use, intrinsic :: ieee_arithmetic, only: ieee_is_nan
    use ropedyn_kinds, only: wp
    use ropedyn_rope_spec, only: rope_params_t
    implicit none
    private
    public :: section_t, rope_section, tangential_damping_of

    real(wp), parameter :: pi = acos(-1.0_wp)

    !> A section. The shear values are divided by `shape_factor` where they are used (so
    !! that G A / (chi l) keeps the order of its operations).
    type :: section_t
        real(wp) :: area = 0.0_wp             !< m^2
        real(wp) :: second_moment = 0.0_wp    !< I, m^4
        real(wp) :: mass_per_length = 0.0_wp  !< kg/m
        real(wp) :: ea = 0.0_wp               !< axial stiffness, N
        real(wp) :: ga = 0.0_wp               !< shear stiffness times shape_factor, N
        real(wp) :: shape_factor = 1.0_wp     !< chi, -
        real(wp) :: ei = 0.0_wp               !< bending stiffness, N m^2
        real(wp) :: axial_damping = 0.0_wp    !< eta A, N s
        real(wp) :: shear_damping = 0.0_wp    !< eta_bar A (times 1/chi where used), N s
        real(wp) :: bending_damping = 0.0_wp  !< eta I, N m^2 s
        real(wp) :: diameter = 0.0_wp         !< m
    end type section_t

contains

    !> The section of a solid round rod of `rope`'s diameter, density, moduli and damping.
    pure function rope_section(rope) result(s)
        type(rope_params_t), intent(in) :: rope
        type(section_t) :: s
        s%diameter = rope%diameter
        s%area = pi*rope%diameter**2/4.0_wp
        s%second_moment = pi*rope%diameter**4/64.0_wp
        s%mass_per_length = rope%density*s%area
        s%ea = rope%young_modulus*s%area
        s%ga = rope%shear_modulus*s%area
        s%shape_factor = rope%shape_factor
        s%ei = rope%young_modulus*s%second_moment
        s%axial_damping = rope%normal_damping*s%area
        s%shear_damping = tangential_damping_of(rope)*s%area
        s%bending_damping = rope%normal_damping*s%second_moment
    end function rope_section

    !> eta_bar of the shear dampers: as given, or when not set eta G/E (eq. 13 of the
    !! paper), from the final eta, G and E.
    pure real(wp) function tangential_damping_of(rope) result(eta_bar)
        type(rope_params_t), intent(in) :: rope
        eta_bar = rope%tangential_damping
        if (ieee_is_nan(eta_bar)) eta_bar = rope%normal_damping*rope%shear_modulus/ &
                                            rope%young_modulus
    end function tangential_damping_of
end module ropedyn_rope_section
