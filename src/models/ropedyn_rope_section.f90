!> The rope's cross-section as the models use it: mass per length, the stiffnesses EA, GA
!! and EI and the damping coefficients of the three strains, per unit length of rope (a
!! spring-damper over a length l takes each divided by l). The one place where the values
!! of `&rope`, of either set, become these numbers, and where the defaults derived from
!! other values are resolved (docs/guide/scenes.md, "The rope (`&rope`)").
!!
!! The solid-rod set (the paper's rope): a round rod of diameter d, density rho, moduli E
!! and G, shear shape factor chi and damping eta (axial, bending) and eta_bar (shear; not
!! set: eta G/E, eq. 13 of the paper): A = pi d^2/4, I = pi d^4/64, mass rho A, EA = E A,
!! GA = G A / chi, EI = E I, dampings eta A, eta_bar A / chi, eta I.
!!
!! The section set (a line as engineers give it): mass per length, EA, EI (not set: 0, a
!! chain), the shear stiffness of the RFEM joint (not set: EA) and the damping
!! coefficients (axial not set: 0; shear and bending not set: proportional to their
!! stiffness with the axial ratio, axial_damping GA/EA and axial_damping EI/EA, the rule
!! of eq. 13). `diameter` is the hydrodynamic diameter: A = pi d^2/4 is the displaced area.
module ropedyn_rope_section
    use, intrinsic :: ieee_arithmetic, only: ieee_is_nan
    use ropedyn_kinds, only: wp, PI
    use ropedyn_rope_spec, only: rope_params_t
    implicit none
    private
    public :: section_t, rope_section, resolved_rope, section_set_given, tangential_damping_of


    !> A section. The shear values are divided by `shape_factor` where they are used (so
    !! that G A / (chi l) keeps the order of its operations).
    type :: section_t
        real(wp) :: area = 0.0_wp             !< A (the section set: displaced), m^2
        real(wp) :: second_moment = 0.0_wp    !< I of a round section of the diameter, m^4
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

    !> Whether `rope` is given by the section set (any of its values given).
    pure logical function section_set_given(rope) result(given)
        type(rope_params_t), intent(in) :: rope
        given = .not. all(ieee_is_nan([rope%mass_per_length, rope%axial_stiffness, &
            rope%bending_stiffness, rope%shear_stiffness, rope%axial_damping, &
            rope%shear_damping, rope%bending_damping]))
    end function section_set_given

    !> `rope` with its derived defaults resolved: of the solid-rod set tangential_damping;
    !! of the section set EI, the joint's shear stiffness and the three dampings.
    pure function resolved_rope(rope) result(r)
        type(rope_params_t), intent(in) :: rope
        type(rope_params_t) :: r
        r = rope
        if (.not. section_set_given(rope)) then
            r%tangential_damping = tangential_damping_of(rope)
            return
        end if
        if (ieee_is_nan(r%bending_stiffness)) r%bending_stiffness = 0.0_wp
        if (ieee_is_nan(r%shear_stiffness)) r%shear_stiffness = r%axial_stiffness
        if (ieee_is_nan(r%axial_damping)) r%axial_damping = 0.0_wp
        if (ieee_is_nan(r%shear_damping)) &
            r%shear_damping = r%axial_damping*r%shear_stiffness/r%axial_stiffness
        if (ieee_is_nan(r%bending_damping)) &
            r%bending_damping = r%axial_damping*r%bending_stiffness/r%axial_stiffness
    end function resolved_rope

    !> The section of `rope` (either set; defaults resolved here).
    pure function rope_section(rope) result(s)
        type(rope_params_t), intent(in) :: rope
        type(section_t) :: s
        type(rope_params_t) :: r
        r = resolved_rope(rope)
        s%diameter = r%diameter
        s%area = pi*r%diameter**2/4.0_wp
        s%second_moment = pi*r%diameter**4/64.0_wp
        if (section_set_given(r)) then
            s%mass_per_length = r%mass_per_length
            s%ea = r%axial_stiffness
            s%ga = r%shear_stiffness
            s%shape_factor = 1.0_wp
            s%ei = r%bending_stiffness
            s%axial_damping = r%axial_damping
            s%shear_damping = r%shear_damping
            s%bending_damping = r%bending_damping
        else
            s%mass_per_length = r%density*s%area
            s%ea = r%young_modulus*s%area
            s%ga = r%shear_modulus*s%area
            s%shape_factor = r%shape_factor
            s%ei = r%young_modulus*s%second_moment
            s%axial_damping = r%normal_damping*s%area
            s%shear_damping = r%tangential_damping*s%area
            s%bending_damping = r%normal_damping*s%second_moment
        end if
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
