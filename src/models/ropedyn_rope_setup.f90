!> What the rope models (RFEM, MPP) take from a spec in the same way: the angle of the
!! straight initial shape, the supports' clamp angles and prescribed motions, and whether
!! external work has to be integrated.
module ropedyn_rope_setup
    use ropedyn_kinds, only: wp, PI
    use ropedyn_rope_spec, only: rope_spec_t
    use ropedyn_support_motion, only: support_motion_t
    use ropedyn_effect, only: effect_box_t
    implicit none
    private
    public :: initial_angle, clamp_angles, configure_motions, any_does_work


contains

    !> Angle of the straight initial shape from the downward x axis, rad ('hanging' and
    !! 'folded' start from 0).
    pure real(wp) function initial_angle(spec) result(angle)
        type(rope_spec_t), intent(in) :: spec
        if (spec%initial%shape == 'hanging' .or. spec%initial%shape == 'folded') then
            angle = 0.0_wp
        else
            angle = spec%initial%angle_deg*pi/180.0_wp
        end if
    end function initial_angle

    !> Clamp angles of the top and bottom supports, rad.
    pure function clamp_angles(spec) result(angles)
        type(rope_spec_t), intent(in) :: spec
        real(wp) :: angles(2)
        angles(1) = spec%supports%top_angle_deg*pi/180.0_wp
        angles(2) = spec%supports%bottom_angle_deg*pi/180.0_wp
    end function clamp_angles

    !> The prescribed motions of the spec's supports (1 top, 2 bottom) for those with
    !! `wanted`; `moving(k)`: support k moves (unchanged where not wanted). The anchors and
    !! clamp angles (p0, angle0) of `motion` must be set already.
    subroutine configure_motions(spec, wanted, motion, moving)
        type(rope_spec_t), intent(in) :: spec
        logical, intent(in) :: wanted(2)
        type(support_motion_t), intent(inout) :: motion(2)
        logical, intent(inout) :: moving(2)
        associate (s => spec%supports)
            if (wanted(1)) moving(1) = motion(1)%configure(s%top_motion, s%top_amplitude, &
                s%top_frequency, s%top_phase_deg, s%top_angle_amplitude_deg, &
                s%top_angle_phase_deg, s%top_table_rows, s%top_ramp_time)
            if (wanted(2)) moving(2) = motion(2)%configure(s%bottom_motion, s%bottom_amplitude, &
                s%bottom_frequency, s%bottom_phase_deg, s%bottom_angle_amplitude_deg, &
                s%bottom_angle_phase_deg, s%bottom_table_rows, s%bottom_ramp_time)
        end associate
    end subroutine configure_motions

    !> True when a support moves or an effect can do work: the model then integrates the
    !! external work as a second quadrature.
    pure logical function any_does_work(moving, effects) result(does)
        logical, intent(in) :: moving(2)
        type(effect_box_t), intent(in) :: effects(:)
        integer :: k
        does = any(moving)
        do k = 1, size(effects)
            if (effects(k)%e%does_work()) does = .true.
        end do
    end function any_does_work
end module ropedyn_rope_setup
