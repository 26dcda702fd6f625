!> A second start for the statics of a line held at both ends: the inextensible catenary
!! between its supports, lying on a level ground between its touchdown and the anchor's
!! arc (docs/theory/statics-modes.md, "A catenary start").
!!
!! The descent from the scene's start may end in a false equilibrium: a chain whose lower
!! part lies on the seabed folded back and forth, its folds held by compressed joints that a
!! line carrying tension only cannot have (a newcomer's 150 m mooring chain: its fairlead
!! tension 21 % high). The catenary is the shape a uniform chain takes, close to the
!! equilibrium of a real line (its stretch, its bending stiffness, water above and below
!! the surface, the seabed's give are the descent's work), and a descent from it meets no
!! fold.
!!
!! x points down (gravity), y across. With a the catenary's parameter H/w:
!! - touchdown (ground level, normal -x; the fairlead h above it, the anchor on it or r
!!   above it; horizontal span D; length L): the fairlead's arc Ls = sqrt(h^2 + 2 a h)
!!   spans a acosh(1 + h/a), the anchor's arc Lr = sqrt(r^2 + 2 a r) spans a acosh(1 + r/a)
!!   (both with their vertex on the ground, one horizontal tension), the rest lies straight
!!   on the ground between them, so a solves
!!   a acosh(1 + h/a) + a acosh(1 + r/a) + L - Ls - Lr - D = 0;
!! - suspended (the anchor below the ground's level, or the line lifts off it):
!!   2 a sinh(D/(2a)) = sqrt(L^2 - dx^2), dx the anchor's depth below the top;
!! - taut (L at most the supports' distance): the straight line between them;
!! - slack (on a level ground, L >= h + r + D: more than the drops and the span): the line
!!   hangs straight down to the ground, lies back from its foot by half the excess
!!   e = L - h - r - D, turns, lies along the ground to below the anchor and rises straight
!!   to it, at no tension on the ground (a slack line's equilibrium on a ground without
!!   friction is any such shape).
!! No start where it does not apply: a free end, gravity off, both supports on one vertical
!! above the ground or without one, a catenary through the ground.
module ropedyn_catenary_start
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use ropedyn_kinds, only: wp
    use ropedyn_rope_spec, only: rope_spec_t
    use ropedyn_rope_model, only: rope_model_t
    implicit none
    private
    public :: catenary_start

    !> an anchor within this share of the length from the ground lies on it
    real(wp), parameter :: ON_GROUND_SHARE = 1.0e-3_wp
    !> a ground whose slope (across over down of its normal) is at most this counts as
    !! level (0.57 degrees): the catenary lies on the level through the anchor
    real(wp), parameter :: LEVEL_SLOPE = 0.01_wp
    !> bisection steps of the parameter a (on log a: far below the rounding of a)
    integer, parameter :: BISECTIONS = 200

    !> The catenary through the two supports: where it lies on the ground, a straight part.
    type :: catenary_t
        real(wp) :: top(2) = 0.0_wp      !< the top support, m
        real(wp) :: bottom(2) = 0.0_wp   !< the bottom support, m
        real(wp) :: length = 0.0_wp      !< L, m
        real(wp) :: a = 0.0_wp           !< H/w, m
        real(wp) :: side = 1.0_wp        !< +1 the anchor lies towards +y, -1 towards -y
        integer :: kind = 0              !< NONE, TAUT, SUSPENDED, TOUCHDOWN or SLACK
        real(wp) :: ground = 0.0_wp      !< TOUCHDOWN, SLACK: the ground's depth x, m
        real(wp) :: suspended = 0.0_wp   !< TOUCHDOWN: Ls, m; SLACK: the drop h, m
        real(wp) :: rise = 0.0_wp        !< TOUCHDOWN: Lr, m; SLACK: the anchor's height r, m
        real(wp) :: excess = 0.0_wp      !< SLACK: e, m
        real(wp) :: xi0 = 0.0_wp         !< SUSPENDED: the vertex's span from the top, m
    contains
        procedure :: point => catenary_point
    end type catenary_t

    integer, parameter :: NONE = 0, TAUT = 1, SUSPENDED = 2, TOUCHDOWN = 3, SLACK = 4

contains

    !> The state y (at rest) of the model on the catenary between its supports at t = 0;
    !! `found` false where the catenary does not apply (the module's header), y unchanged.
    subroutine catenary_start(model, spec, y, found)
        class(rope_model_t), intent(in) :: model
        type(rope_spec_t), intent(in) :: spec
        real(wp), intent(inout) :: y(:)
        logical, intent(out) :: found
        type(catenary_t) :: cat
        real(wp) :: anchors(2, 2), lengths(model%n_elements()), masses(model%n_elements())
        real(wp) :: points(2, 0:model%n_elements()), q(3, model%n_elements())
        real(wp) :: qdot(3, model%n_elements()), y_new(size(y)), s, d(2)
        integer :: i
        found = .false.
        if (.not. spec%effects%gravity) return
        call model%support_positions(0.0_wp, anchors)
        if (.not. all(ieee_is_finite(anchors))) return
        call model%element_data(lengths, masses)
        cat = shape_of(anchors(:, 1), anchors(:, 2), sum(lengths), spec)
        if (cat%kind == NONE) return
        s = 0.0_wp
        points(:, 0) = cat%point(0.0_wp)
        do i = 1, size(lengths)
            s = s + lengths(i)
            points(:, i) = cat%point(s)
        end do
        if (.not. all(ieee_is_finite(points))) return
        if (spec%effects%ground) then
            if (any(depth_below(spec, points) > ON_GROUND_SHARE*cat%length + &
                    tilt(spec)*abs(anchors(2, 2) - anchors(2, 1)))) return
        end if
        do i = 1, size(lengths)
            d = points(:, i) - points(:, i - 1)
            q(1:2, i) = 0.5_wp*(points(:, i - 1) + points(:, i))
            q(3, i) = atan2(d(2), d(1))
        end do
        qdot = 0.0_wp
        call model%state_from_fields(q, qdot, 0.0_wp, y_new, found)
        if (found) y = y_new
    end subroutine catenary_start

    !> The catenary of length L between the supports `top` and `bottom` (kind NONE where it
    !! does not apply).
    function shape_of(top, bottom, length, spec) result(cat)
        real(wp), intent(in) :: top(2), bottom(2), length
        type(rope_spec_t), intent(in) :: spec
        type(catenary_t) :: cat
        real(wp) :: span, drop, rise, ground
        cat%top = top
        cat%bottom = bottom
        cat%length = length
        span = abs(bottom(2) - top(2))
        if (bottom(2) < top(2)) cat%side = -1.0_wp
        if (length <= norm2(bottom - top)) then
            cat%kind = TAUT
            return
        end if
        if (level_ground_under(spec, top, bottom, length, ground)) then
            cat%ground = ground
            drop = ground - top(1)
            rise = ground - bottom(1)
            if (length >= drop + rise + span) then
                cat%kind = SLACK
                cat%suspended = drop
                cat%rise = rise
                cat%excess = length - drop - rise - span
                return
            end if
            call solve_touchdown(cat, drop, rise, span)
            if (cat%kind == TOUCHDOWN) return
        end if
        if (span > 0.0_wp) call suspended_between(cat, span, bottom(1) - top(1))
    end function shape_of

    !> The ground is on, level (its normal along -x, to LEVEL_SLOPE), the top above it and
    !! the anchor on it or above it; `ground` its depth x below the anchor (the anchor's own
    !! where it lies within ON_GROUND_SHARE of the length from it).
    logical function level_ground_under(spec, top, bottom, length, ground) result(level)
        type(rope_spec_t), intent(in) :: spec
        real(wp), intent(in) :: top(2), bottom(2), length
        real(wp), intent(out) :: ground
        real(wp) :: depth(0:1)
        ground = bottom(1)
        level = spec%effects%ground .and. spec%ground%normal(1) < 0.0_wp
        if (.not. level) return
        level = tilt(spec) <= LEVEL_SLOPE
        if (.not. level) return
        depth = depth_below(spec, reshape([bottom, top], [2, 2]))
        level = depth(0) <= ON_GROUND_SHARE*length .and. depth(1) < -ON_GROUND_SHARE*length
        if (level .and. abs(depth(0)) > ON_GROUND_SHARE*length) &
            ground = bottom(1) - depth(0)*norm2(spec%ground%normal)/abs(spec%ground%normal(1))
    end function level_ground_under

    !> The ground's slope: across over down of its normal (0 for a level ground).
    pure real(wp) function tilt(spec)
        type(rope_spec_t), intent(in) :: spec
        tilt = abs(spec%ground%normal(2))/max(abs(spec%ground%normal(1)), tiny(1.0_wp))
    end function tilt

    !> The touchdown catenary from a top `drop` above the ground to an anchor `rise` above
    !! it (0: on it) `span` away: kind TOUCHDOWN with a, Ls and Lr, or unchanged where the
    !! whole line hangs free (the catenary whose two arcs take all its length spans less
    !! than `span`, or the line cannot reach the ground from both ends).
    subroutine solve_touchdown(cat, drop, rise, span)
        type(catenary_t), intent(inout) :: cat
        real(wp), intent(in) :: drop, rise, span
        real(wp) :: lo, hi
        if (cat%length <= drop + rise) return
        lo = 1.0e-12_wp*cat%length
        if (rise > 0.0_wp) then
            hi = rising_root(reach, lo, cat%length**2/(2.0_wp*max(drop, rise)))  ! Ls + Lr = L
        else
            hi = (cat%length**2 - drop**2)/(2.0_wp*drop)                         ! Ls = L
        end if
        if (miss(hi) < 0.0_wp) return
        cat%a = rising_root(miss, lo, hi)
        cat%suspended = arc(cat%a, drop)
        cat%rise = arc(cat%a, rise)
        cat%kind = TOUCHDOWN
    contains
        !> The span reached less `span` (rises with a).
        real(wp) function miss(a)
            real(wp), intent(in) :: a
            miss = a*acosh(1.0_wp + drop/a) + a*acosh(1.0_wp + rise/a) + cat%length &
                   - arc(a, drop) - arc(a, rise) - span
        end function miss

        !> The two arcs' length less L (rises with a).
        real(wp) function reach(a)
            real(wp), intent(in) :: a
            reach = arc(a, drop) + arc(a, rise) - cat%length
        end function reach

        !> The arc of a catenary from its vertex to the height z above it, m.
        pure real(wp) function arc(a, z)
            real(wp), intent(in) :: a, z
            arc = sqrt(z**2 + 2.0_wp*a*z)
        end function arc
    end subroutine solve_touchdown

    !> The catenary hanging free between the supports, `span` apart across and the bottom
    !! `dx` below the top: kind SUSPENDED with a and the vertex's span xi0.
    subroutine suspended_between(cat, span, dx)
        type(catenary_t), intent(inout) :: cat
        real(wp), intent(in) :: span, dx
        real(wp) :: lo, hi, chord
        chord = sqrt(cat%length**2 - dx**2)
        lo = cat%length
        do while (excess(lo) <= 0.0_wp .and. lo > 1.0e-12_wp*cat%length)
            lo = 0.5_wp*lo
        end do
        hi = cat%length
        do while (excess(hi) > 0.0_wp .and. hi < 1.0e12_wp*cat%length)
            hi = 2.0_wp*hi
        end do
        if (.not. (excess(lo) > 0.0_wp .and. excess(hi) <= 0.0_wp)) return
        cat%a = rising_root(shortfall, lo, hi)
        cat%xi0 = 0.5_wp*span - cat%a*asinh(-dx/(2.0_wp*cat%a*sinh(span/(2.0_wp*cat%a))))
        cat%kind = SUSPENDED
    contains
        !> The arc's reach over the length it must have (falls with a; +huge for a tiny a).
        real(wp) function excess(a)
            real(wp), intent(in) :: a
            real(wp) :: half
            half = span/(2.0_wp*a)
            if (half > 700.0_wp) then
                excess = huge(1.0_wp)
            else
                excess = 2.0_wp*a*sinh(half) - chord
            end if
        end function excess

        !> -excess (rises with a).
        real(wp) function shortfall(a)
            real(wp), intent(in) :: a
            shortfall = -excess(a)
        end function shortfall
    end subroutine suspended_between

    !> The root of `f`, which rises with a, between lo (f < 0) and hi (f >= 0): BISECTIONS
    !! halvings of the interval in log a.
    real(wp) function rising_root(f, lo, hi) result(a)
        interface
            real(wp) function f(a)
                import :: wp
                real(wp), intent(in) :: a
            end function f
        end interface
        real(wp), intent(in) :: lo, hi
        real(wp) :: below, above, mid
        integer :: k
        below = lo
        above = hi
        do k = 1, BISECTIONS
            mid = sqrt(below*above)
            if (f(mid) < 0.0_wp) then
                below = mid
            else
                above = mid
            end if
        end do
        a = sqrt(below*above)
    end function rising_root

    !> The point at arc length s from the top, m.
    pure function catenary_point(self, s) result(p)
        class(catenary_t), intent(in) :: self
        real(wp), intent(in) :: s
        real(wp) :: p(2), u, xi, a
        a = self%a
        select case (self%kind)
        case (TAUT)
            p = self%top + (s/self%length)*(self%bottom - self%top)
        case (TOUCHDOWN)
            if (s <= self%suspended) then
                u = self%suspended - s                 ! arc from the touchdown up
                xi = a*asinh(self%suspended/a) - a*asinh(u/a)
                p = [self%ground - (sqrt(a**2 + u**2) - a), self%top(2) + self%side*xi]
            else if (s <= self%length - self%rise) then
                xi = a*asinh(self%suspended/a) + s - self%suspended
                p = [self%ground, self%top(2) + self%side*xi]
            else
                u = s - (self%length - self%rise)      ! arc from the anchor's vertex up
                xi = a*asinh(self%suspended/a) + self%length - self%rise - self%suspended &
                     + a*asinh(u/a)
                p = [self%ground - (sqrt(a**2 + u**2) - a), self%top(2) + self%side*xi]
            end if
        case (SLACK)
            if (s <= self%suspended) then
                p = [self%top(1) + s, self%top(2)]
            else
                ! back from the foot by e/2, then forth: the distance along the ground
                ! towards the anchor, from the foot
                xi = s - self%suspended
                if (xi <= self%excess) then
                    xi = -min(xi, self%excess - xi)
                else
                    xi = xi - self%excess
                end if
                p = [self%ground, self%top(2) + self%side*xi]
                ! up from below the anchor
                if (s > self%length - self%rise) &
                    p = [self%ground - (s - (self%length - self%rise)), self%bottom(2)]
            end if
        case default                                   ! SUSPENDED
            xi = self%xi0 + a*asinh(s/a + sinh(-self%xi0/a))
            ! the height z = -x rises by a (cosh((xi - xi0)/a) - cosh(-xi0/a))
            p = [self%top(1) - a*(cosh((xi - self%xi0)/a) - cosh(self%xi0/a)), &
                 self%top(2) + self%side*xi]
        end select
    end function catenary_point

    !> How deep each point lies in the spec's ground (-(p - point).normal/|normal|, m;
    !! negative above it).
    pure function depth_below(spec, points) result(depth)
        type(rope_spec_t), intent(in) :: spec
        real(wp), intent(in) :: points(:, 0:)
        real(wp) :: depth(0:size(points, 2) - 1)
        real(wp) :: nhat(2)
        integer :: j
        nhat = spec%ground%normal/norm2(spec%ground%normal)
        do j = 0, size(points, 2) - 1
            depth(j) = -dot_product(points(:, j) - spec%ground%point, nhat)
        end do
    end function depth_below
end module ropedyn_catenary_start
