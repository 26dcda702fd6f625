!> The statics' second start (ropedyn_catenary_start; docs/theory/statics-modes.md, "A
!! catenary start") against the geometry of a hanging chain, on the paper's 1 m rope (RFEM,
!! n = 40; the MPP at the touchdown) between a pin at the origin and a pinned anchor:
!! - suspended (anchor 0.3 m down, 0.8 m across, no ground): a catenary's slope dx/dy, x
!!   down, is linear in the arc length, (s - s0)/a; the ends are the supports;
!! - touchdown (a level ground 0.6 m down, the anchor on it 0.7 m across): the elements past
!!   the touchdown lie on the ground, the suspended ones on a catenary whose slope falls to
!!   0 where it meets the ground (tangent), and the inextensible closed form of the
!!   touchdown, a acosh(1 + h/a) + L - sqrt(h^2 + 2 a h) = D, holds for the a the slope
!!   gives;
!! - touchdown to a raised anchor (the ground 0.5 m down, the anchor 0.15 m above it, 0.6 m
!!   across): an arc from the ground up to the anchor too, its slope linear in s with the
!!   same 1/a as the top's (one horizontal tension), and the closed form with both arcs;
!! - slack (the anchor 0.2 m across: L > h + D): straight down to the ground, then on it;
!!   with the anchor 0.1 m above the ground, straight up to it at the end;
!! - taut (the anchor 1.2 m away): the straight line between the supports;
!! - none: a free bottom end.
program test_catenary_start
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t
    use ropedyn_scene, only: scene_t, read_scene
    use ropedyn_rope_model, only: rope_model_t
    use ropedyn_model_factory, only: create_model
    use ropedyn_catenary_start, only: catenary_start
    use ropedyn_assert, only: test_suite_t
    implicit none

    integer, parameter :: N = 40
    type(test_suite_t) :: suite
    character(len=1024) :: source_dir

    suite%name = 'catenary_start'
    call get_command_argument(1, source_dir)
    if (len_trim(source_dir) == 0) source_dir = '.'
    call test_suspended()
    call test_touchdown('rfem')
    call test_touchdown('mpp')
    call test_raised_anchor()
    call test_slack()
    call test_slack_to_a_raised_anchor()
    call test_taut()
    call test_none()
    call suite%finish()

contains

    !> The start of the scene (paper.nml with `sets`, bottom pinned, n = N), its element
    !! ends (2, 2n: each element's two ends in turn) and the arc length at each element's
    !! centre (the RFEM's end elements are half as long as the others).
    subroutine start_of(sets, kind, found, points, centres)
        character(len=*), intent(in) :: sets(:), kind
        logical, intent(out) :: found
        real(wp), allocatable, intent(out) :: points(:, :), centres(:)
        type(scene_t) :: scene
        type(error_t), allocatable :: err
        class(rope_model_t), allocatable :: model
        real(wp), allocatable :: y(:), lengths(:), masses(:)
        character(len=64) :: base(3)
        integer :: i
        base = [character(len=64) :: "model.kind='"//kind//"'", 'model.elements=40', &
                "supports.bottom='pinned'"]
        call read_scene(trim(source_dir)//'/input/paper.nml', [base, sets], scene, err)
        if (.not. allocated(err)) call create_model(scene%rope_spec_t, model, err)
        if (allocated(err)) then
            call suite%check_true(.false., err%message)
            call suite%finish()
        end if
        allocate (y(model%size()), points(2, 2*N))
        call model%initial_state(y)
        call catenary_start(model, scene%rope_spec_t, y, found)
        call model%polyline(y, points)
        allocate (lengths(N), masses(N), centres(N))
        call model%element_data(lengths, masses)
        do i = 1, N
            centres(i) = sum(lengths(1:i)) - 0.5_wp*lengths(i)
        end do
    end subroutine start_of

    !> Slope dx/dy of element i (x down, y across).
    pure real(wp) function slope_of(points, i) result(slope)
        real(wp), intent(in) :: points(:, :)
        integer, intent(in) :: i
        real(wp) :: d(2)
        d = points(:, 2*i) - points(:, 2*i - 1)
        slope = d(1)/d(2)
    end function slope_of

    !> Least-squares line through (s_i, slope_i) for elements i1..i2: its gradient 1/a,
    !! intercept and largest residual.
    subroutine fit_line(points, centres, i1, i2, gradient, intercept, worst)
        real(wp), intent(in) :: points(:, :), centres(:)
        integer, intent(in) :: i1, i2
        real(wp), intent(out) :: gradient, intercept, worst
        real(wp) :: s(i2 - i1 + 1), t(i2 - i1 + 1), sm, tm
        integer :: i
        do i = i1, i2
            t(i - i1 + 1) = slope_of(points, i)
            s(i - i1 + 1) = centres(i)
        end do
        sm = sum(s)/size(s)
        tm = sum(t)/size(t)
        gradient = sum((s - sm)*(t - tm))/sum((s - sm)**2)
        intercept = tm - gradient*sm
        worst = maxval(abs(t - (intercept + gradient*s)))
    end subroutine fit_line

    subroutine test_suspended()
        real(wp), allocatable :: p(:, :), c(:)
        real(wp) :: gradient, intercept, worst
        logical :: found
        call start_of([character(len=64) :: 'supports.bottom_anchor=0.3,0.8'], 'rfem', &
                      found, p, c)
        call suite%check_true(found, 'suspended: found')
        call fit_line(p, c, 1, N, gradient, intercept, worst)
        ! the slope runs from steeply down at the top (about 2.7) to up at the anchor
        call suite%check_le(worst, 1.0e-3_wp*abs(gradient), &
                            'suspended: dx/dy linear in s (largest residual over 1/a)')
        call suite%check_le(norm2(p(:, 1)), 1.0e-4_wp, 'suspended: starts at the top')
        call suite%check_le(norm2(p(:, 2*N) - [0.3_wp, 0.8_wp]), 1.0e-4_wp, &
                            'suspended: ends at the anchor')
    end subroutine test_suspended

    subroutine test_touchdown(kind)
        character(len=*), intent(in) :: kind
        real(wp), allocatable :: p(:, :), c(:)
        real(wp) :: gradient, intercept, worst, a, s_td
        logical :: found
        integer :: i, on_ground
        call start_of([character(len=64) :: 'supports.bottom_anchor=0.6,0.7', &
                       'effects.ground=.true.', 'ground.point=0.6,0.0'], kind, found, p, c)
        call suite%check_true(found, kind//' touchdown: found')
        on_ground = 0
        do i = 1, N
            if (abs(p(1, 2*i - 1) - 0.6_wp) < 1.0e-5_wp .and. &
                abs(p(1, 2*i) - 0.6_wp) < 1.0e-5_wp) on_ground = on_ground + 1
        end do
        call suite%check_true(on_ground >= 2 .and. on_ground < N/2, &
                              kind//' touchdown: a part lies on the ground')
        call fit_line(p, c, 1, N - on_ground - 1, gradient, intercept, worst)
        call suite%check_le(worst, 2.0e-3_wp*abs(gradient), &
                            kind//' touchdown: the suspended part a catenary')
        ! dx/dy = (s_td - s)/a: tangent where it meets the ground, at s_td
        a = -1.0_wp/gradient
        s_td = intercept*a
        ! (within the element that bends onto the ground)
        call suite%check_close(s_td, c(N - on_ground), 0.0_wp, 1.0_wp/(N - 1), &
                               kind//' touchdown: tangent to the ground at the touchdown')
        call suite%check_close(a*acosh(1.0_wp + 0.6_wp/a) + 1.0_wp - &
                               sqrt(0.36_wp + 1.2_wp*a), 0.7_wp, 1.0e-4_wp, 0.0_wp, &
                               kind//' touchdown: the closed form of the touchdown holds')
        call suite%check_le(norm2(p(:, 2*N) - [0.6_wp, 0.7_wp]), 1.0e-4_wp, &
                            kind//' touchdown: ends at the anchor')
    end subroutine test_touchdown

    subroutine test_raised_anchor()
        real(wp), allocatable :: p(:, :), c(:)
        real(wp) :: g_top, g_anchor, b, worst_top, worst_anchor, a
        logical :: found, on(N)
        integer :: i, first, last
        call start_of([character(len=64) :: 'supports.bottom_anchor=0.35,0.6', &
                       'effects.ground=.true.', 'ground.point=0.5,0.0'], 'rfem', found, p, c)
        call suite%check_true(found, 'raised anchor: found')
        do i = 1, N
            on(i) = all(abs(p(1, 2*i - 1:2*i) - 0.5_wp) < 1.0e-5_wp)
        end do
        first = findloc(on, .true., dim=1)
        last = findloc(on, .true., dim=1, back=.true.)
        call suite%check_true(first > 0 .and. last - first + 1 == count(on) .and. &
                              count(on) >= 3 .and. last < N - 3, &
                              'raised anchor: a part in the middle lies on the ground')
        call fit_line(p, c, 1, first - 2, g_top, b, worst_top)
        call fit_line(p, c, last + 2, N, g_anchor, b, worst_anchor)
        call suite%check_le(max(worst_top/abs(g_top), worst_anchor/abs(g_anchor)), 2.0e-3_wp, &
                            'raised anchor: both suspended parts catenaries')
        call suite%check_close(g_anchor, g_top, 1.0e-2_wp, 0.0_wp, &
                               'raised anchor: one horizontal tension (the same 1/a)')
        a = -1.0_wp/g_top
        call suite%check_close(a*acosh(1.0_wp + 0.5_wp/a) + a*acosh(1.0_wp + 0.15_wp/a) + &
                               1.0_wp - sqrt(0.25_wp + a) - sqrt(0.0225_wp + 0.3_wp*a), &
                               0.6_wp, 1.0e-4_wp, 0.0_wp, &
                               'raised anchor: the closed form with both arcs holds')
        call suite%check_le(norm2(p(:, 2*N) - [0.35_wp, 0.6_wp]), 1.0e-4_wp, &
                            'raised anchor: ends at the anchor')
    end subroutine test_raised_anchor

    subroutine test_slack()
        real(wp), allocatable :: p(:, :), c(:)
        logical :: found
        integer :: i, down, along
        call start_of([character(len=64) :: 'supports.bottom_anchor=0.6,0.2', &
                       'effects.ground=.true.', 'ground.point=0.6,0.0'], 'rfem', found, p, c)
        call suite%check_true(found, 'slack: found')
        down = 0
        along = 0
        do i = 1, N
            if (all(abs(p(2, 2*i - 1:2*i)) < 1.0e-12_wp)) down = down + 1
            if (all(abs(p(1, 2*i - 1:2*i) - 0.6_wp) < 1.0e-12_wp)) along = along + 1
        end do
        ! 0.6 m of 1 m straight down, the rest on the ground, but the element at the corner
        call suite%check_true(down == count(c + 0.5_wp/(N - 1) <= 0.6_wp + 1.0e-12_wp) .and. &
                              along == count(c - 0.5_wp/(N - 1) >= 0.6_wp - 1.0e-12_wp) .and. &
                              down + along == N - 1, 'slack: down, then along')
        call suite%check_le(norm2(p(:, 2*N) - [0.6_wp, 0.2_wp]), 1.0e-12_wp, &
                            'slack: ends at the anchor')
        call suite%check_le(minval(p(2, :)), -0.099_wp, 'slack: lies back half the excess')
    end subroutine test_slack

    subroutine test_slack_to_a_raised_anchor()
        real(wp), allocatable :: p(:, :), c(:)
        logical :: found
        integer :: i, up
        call start_of([character(len=64) :: 'supports.bottom_anchor=0.5,0.2', &
                       'effects.ground=.true.', 'ground.point=0.6,0.0'], 'rfem', found, p, c)
        call suite%check_true(found, 'slack, raised anchor: found')
        up = 0
        do i = 1, N
            if (all(abs(p(2, 2*i - 1:2*i) - 0.2_wp) < 1.0e-12_wp) .and. &
                all(p(1, 2*i - 1:2*i) < 0.6_wp - 1.0e-12_wp)) up = up + 1
        end do
        ! the last 0.1 m of 1 m straight up from the ground, but the element at the corner
        call suite%check_true(up == count(c - 0.5_wp/(N - 1) >= 0.9_wp - 1.0e-12_wp) .and. &
                              up > 1, 'slack, raised anchor: straight up to the anchor')
        call suite%check_le(norm2(p(:, 2*N) - [0.5_wp, 0.2_wp]), 1.0e-12_wp, &
                            'slack, raised anchor: ends at the anchor')
    end subroutine test_slack_to_a_raised_anchor

    subroutine test_taut()
        real(wp), allocatable :: p(:, :), c(:)
        logical :: found
        real(wp) :: cross
        integer :: j
        call start_of([character(len=64) :: 'supports.bottom_anchor=0.72,0.96'], 'rfem', &
                      found, p, c)
        call suite%check_true(found, 'taut: found')
        cross = 0.0_wp
        do j = 1, 2*N
            cross = max(cross, abs(p(1, j)*0.96_wp - p(2, j)*0.72_wp)/1.2_wp)
        end do
        call suite%check_le(cross, 1.0e-12_wp, 'taut: on the line between the supports')
        ! (the elements keep their length: each centre sits at 1.2 times its arc length)
        call suite%check_close(norm2(0.5_wp*(p(:, 2*N - 1) + p(:, 2*N))), 1.2_wp*c(N), 1.0e-12_wp, &
                               0.0_wp, 'taut: stretched to the anchor')
    end subroutine test_taut

    subroutine test_none()
        real(wp), allocatable :: p(:, :), c(:)
        logical :: found
        call start_of([character(len=64) :: "supports.bottom='free'"], 'rfem', found, p, c)
        call suite%check_true(.not. found, 'none: a free end has no catenary')
    end subroutine test_none
end program test_catenary_start
