!> Checks of a run's initial state against its scene that only the state can make: a held
!! end (pinned or clamped) that the initial shape leaves far from its anchor. The support's
!! spring then pulls the end there at the start, with an elastic energy the scene's author
!! rarely meant (a random scene: the lower end 0.31 m from its anchor, 3.5e7 J of elastic
!! energy in a rope whose m g L is 0.18 J, and a run that failed as a runaway). A run goes
!! ahead; the summary warns.
module ropedyn_start_checks
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use ropedyn_kinds, only: wp
    use ropedyn_text, only: text_t, append_text, real_text, significant_text
    use ropedyn_rope_model, only: rope_model_t, energy_t
    use ropedyn_scene, only: scene_t
    implicit none
    private
    public :: far_anchor_warnings

    !> a held end further from its anchor than this share of the rope's length is warned
    !! of: a start from a shape, the equilibrium or a record meets its anchors within the
    !! support spring's stretch, a small fraction of an element
    real(wp), parameter :: FAR_ANCHOR_SHARE = 0.01_wp

contains

    !> One line per held end that the initial state y (time t, energies e, m g L
    !! `weight_length`) leaves further than FAR_ANCHOR_SHARE of the length from its anchor:
    !! 'SCENE: &supports: END_anchor = X, Y: ...' with the distance, the elastic energy of
    !! the start and what to do.
    function far_anchor_warnings(scene, model, t, y, e, weight_length) result(list)
        type(scene_t), intent(in) :: scene
        class(rope_model_t), intent(in) :: model
        real(wp), intent(in) :: t, y(:)
        type(energy_t), intent(in) :: e
        real(wp), intent(in) :: weight_length
        type(text_t), allocatable :: list(:)
        real(wp) :: anchors(2, 2), d
        real(wp), allocatable :: points(:, :)
        character(len=6), parameter :: ENDS(2) = [character(len=6) :: 'top', 'bottom']
        character(len=:), allocatable :: energy
        integer :: k, p
        allocate (list(0))
        call model%support_positions(t, anchors)
        if (.not. any(ieee_is_finite(anchors))) return   ! both ends free
        allocate (points(2, 2*model%n_elements()))
        call model%polyline(y, points, t)
        do k = 1, 2
            if (.not. all(ieee_is_finite(anchors(:, k)))) cycle   ! a free end
            p = merge(1, size(points, 2), k == 1)
            d = norm2(points(:, p) - anchors(:, k))
            if (.not. d > FAR_ANCHOR_SHARE*scene%rope%length) cycle
            if (at_rest_start(scene)) then
                call append_text(list, anchor_text(k)//': the equilibrium leaves the '// &
                    trim(merge('upper', 'lower', k == 1))//' end '//distance_text(d)// &
                    ': the rope pulls its support''s spring that far'//reach(anchors))
                cycle
            end if
            energy = significant_text(e%elastic, 3)//' J'
            if (weight_length > 0.0_wp) energy = energy//' ('// &
                significant_text(e%elastic/weight_length, 3)//' m g L)'
            call append_text(list, anchor_text(k)//': the initial '// &
                'state leaves the '//trim(merge('upper', 'lower', k == 1))//' end '// &
                distance_text(d)//': '// &
                'its support spring pulls the end there at the start, and the start holds '// &
                energy//' of elastic energy; start from &initial shape = ''equilibrium'''// &
                hint(k))
        end do
    contains
        !> 'ORIGIN: &supports: END_anchor = X, Y'
        function anchor_text(k) result(text)
            integer, intent(in) :: k
            character(len=:), allocatable :: text
            text = scene%origin('supports.'//trim(ENDS(k))//'_anchor')//': &supports: '// &
                trim(ENDS(k))//'_anchor = '//real_text(anchors(1, k))//', '// &
                real_text(anchors(2, k))
        end function anchor_text

        !> 'D m from it (P % of the length)'
        function distance_text(d) result(text)
            real(wp), intent(in) :: d
            character(len=:), allocatable :: text
            text = significant_text(d, 3)//' m from it ('// &
                significant_text(100.0_wp*d/scene%rope%length, 3)//' % of the length)'
        end function distance_text

        !> Why an equilibrium stretches a support's spring: the anchors out of the rope's
        !! reach, or a soft support.
        function reach(anchors) result(text)
            real(wp), intent(in) :: anchors(2, 2)
            character(len=:), allocatable :: text
            real(wp) :: apart
            apart = norm2(anchors(:, 2) - anchors(:, 1))
            if (all(ieee_is_finite(anchors)) .and. apart > scene%rope%length) then
                text = ' (the anchors are '//significant_text(apart, 4)//' m apart, the '// &
                    'rope '//significant_text(scene%rope%length, 6)//' m long: out of its '// &
                    'reach unless it stretches)'
            else
                text = '; a stiffer support: &supports support_stiffness_factor'
            end if
        end function reach

        pure function hint(k) result(text)
            integer, intent(in) :: k
            character(len=:), allocatable :: text
            if (k == 1) then
                text = ', or give the anchor the upper end of the start'
            else
                text = ', or leave bottom_anchor out (the end is held where it starts)'
            end if
        end function hint
    end function far_anchor_warnings

    !> The scene starts in its equilibrium (&initial shape 'equilibrium', or 'mode': the
    !! equilibrium and a small mode shape): its support springs carry the rope's pull.
    pure logical function at_rest_start(scene)
        type(scene_t), intent(in) :: scene
        at_rest_start = scene%initial%shape == 'equilibrium' .or. scene%initial%shape == 'mode'
    end function at_rest_start
end module ropedyn_start_checks
