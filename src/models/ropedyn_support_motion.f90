!> Prescribed motion of a rope support: fixed, harmonic, tabulated (a file of rows
!! t, dx, dy, dangle interpolated by a C1 cubic Hermite spline), or coupled (driven by
!! another program through the library, one exchange at a time), evaluated with its
!! velocity and acceleration. The model asks for the state once per right-hand-side call.
!!
!! Harmonic, per axis: p(t) = p0 + r(t) a sin(omega t + phase); angle(t) = angle0 +
!! r(t) A sin(omega t + phase_angle), with the ramp r(t) = s(t/T) over the ramp time T
!! (s(u) = 10u^3 - 15u^4 + 6u^5 for 0 <= u <= 1, then 1: from rest, smooth to the second
!! derivative; T = 0: r = 1). Table: p(t) = p0 + (dx, dy)(t), angle(t) = angle0 +
!! dangle(t), with the slopes of the three-point (parabolic) rule at interior rows and zero
!! slope at the first and last row; before the first row and after the last the support rests
!! at the end values, so the motion is C1 for all t. Coupled: over the span [t0, t1] from
!! one exchange to the next, the cubic Hermite curve from the position and velocity at t0
!! to those prescribed for t1 (as a table's segment; the curve goes on beyond both ends),
!! the angle fixed at angle0; before the first exchange the support rests at its anchor.
!! Frame: x down, y horizontal, angles from x towards y (docs/guide/scenes.md,
!! `&supports`).
module ropedyn_support_motion
    use ropedyn_kinds, only: wp, PI
    implicit none
    private
    public :: support_motion_t, motion_state_t
    public :: MOTION_FIXED, MOTION_HARMONIC, MOTION_TABLE, MOTION_COUPLED
    public :: ramp

    integer, parameter :: MOTION_FIXED = 0, MOTION_HARMONIC = 1, MOTION_TABLE = 2, &
                          MOTION_COUPLED = 3

    !> The support at one time.
    type :: motion_state_t
        real(wp) :: p(2) = 0.0_wp          !< anchor position, m
        real(wp) :: v(2) = 0.0_wp          !< its velocity, m/s
        real(wp) :: a(2) = 0.0_wp          !< its acceleration, m/s^2
        real(wp) :: angle = 0.0_wp         !< support angle, rad
        real(wp) :: rate = 0.0_wp          !< its rate, rad/s
    end type motion_state_t

    type :: support_motion_t
        integer :: kind = MOTION_FIXED
        real(wp) :: p0(2) = 0.0_wp             !< anchor, m
        real(wp) :: angle0 = 0.0_wp            !< clamp angle, rad
        real(wp) :: amplitude(2) = 0.0_wp      !< harmonic amplitudes, m
        real(wp) :: omega = 0.0_wp             !< harmonic angular frequency, rad/s
        real(wp) :: phase(2) = 0.0_wp          !< harmonic phases, rad
        real(wp) :: angle_amplitude = 0.0_wp   !< rad
        real(wp) :: angle_phase = 0.0_wp       !< rad
        real(wp) :: ramp_time = 0.0_wp         !< harmonic: the amplitudes' ramp, s (0: none)
        !> coupled: the span [t0, t1] (s) of the current curve, the positions (m) and
        !! velocities (m/s) at its ends (columns 1 and 2)
        real(wp) :: span(2) = 0.0_wp
        real(wp) :: ends_p(2, 2) = 0.0_wp, ends_v(2, 2) = 0.0_wp
        !> table rows (4, m): t (s), dx, dy (m), dangle (rad)
        real(wp), allocatable :: table(:, :)
        real(wp), allocatable :: slope(:, :)   !< Hermite slopes (3, m) of dx, dy, dangle
    contains
        procedure :: state => motion_state
        procedure :: set_table => motion_set_table
        procedure :: configure => motion_configure
        procedure :: couple => motion_couple
    end type support_motion_t

contains

    !> Position, velocity, acceleration, angle and rate of the support at time t.
    pure function motion_state(self, t) result(s)
        class(support_motion_t), intent(in) :: self
        real(wp), intent(in) :: t
        type(motion_state_t) :: s
        real(wp) :: arg(2), arg_a, h, u, v(3), d(3), dd(3), b(4), db(4), eb(4), r(0:2)
        integer :: k, m

        s%p = self%p0
        s%angle = self%angle0
        select case (self%kind)
        case (MOTION_HARMONIC)
            r = ramp(t, self%ramp_time)
            arg = self%omega*t + self%phase
            s%p = self%p0 + r(0)*self%amplitude*sin(arg)
            s%v = r(0)*self%amplitude*self%omega*cos(arg) + r(1)*self%amplitude*sin(arg)
            s%a = -r(0)*self%amplitude*self%omega**2*sin(arg) + &
                  2.0_wp*r(1)*self%amplitude*self%omega*cos(arg) + r(2)*self%amplitude*sin(arg)
            arg_a = self%omega*t + self%angle_phase
            s%angle = self%angle0 + r(0)*self%angle_amplitude*sin(arg_a)
            s%rate = r(0)*self%angle_amplitude*self%omega*cos(arg_a) + &
                     r(1)*self%angle_amplitude*sin(arg_a)
        case (MOTION_COUPLED)
            h = self%span(2) - self%span(1)
            if (.not. h > 0.0_wp) then
                ! no span yet: on from the end with its velocity
                s%p = self%ends_p(:, 2) + self%ends_v(:, 2)*(t - self%span(2))
                s%v = self%ends_v(:, 2)
            else
                call hermite_basis((t - self%span(1))/h, b, db, eb)
                associate (p0 => self%ends_p(:, 1), p1 => self%ends_p(:, 2), &
                           v0 => self%ends_v(:, 1), v1 => self%ends_v(:, 2))
                    s%p = b(1)*p0 + b(2)*h*v0 + b(3)*p1 + b(4)*h*v1
                    s%v = (db(1)*p0 + db(2)*h*v0 + db(3)*p1 + db(4)*h*v1)/h
                    s%a = (eb(1)*p0 + eb(2)*h*v0 + eb(3)*p1 + eb(4)*h*v1)/h**2
                end associate
            end if
        case (MOTION_TABLE)
            m = size(self%table, 2)
            if (t <= self%table(1, 1)) then
                v = self%table(2:4, 1)
                d = 0.0_wp
                dd = 0.0_wp
            else if (t >= self%table(1, m)) then
                v = self%table(2:4, m)
                d = 0.0_wp
                dd = 0.0_wp
            else
                k = interval(self%table(1, :), t)
                h = self%table(1, k + 1) - self%table(1, k)
                u = (t - self%table(1, k))/h
                call hermite_basis(u, b, db, eb)
                associate (y0 => self%table(2:4, k), y1 => self%table(2:4, k + 1), &
                           m0 => self%slope(:, k), m1 => self%slope(:, k + 1))
                    v = b(1)*y0 + b(2)*h*m0 + b(3)*y1 + b(4)*h*m1
                    d = (db(1)*y0 + db(2)*h*m0 + db(3)*y1 + db(4)*h*m1)/h
                    dd = (eb(1)*y0 + eb(2)*h*m0 + eb(3)*y1 + eb(4)*h*m1)/h**2
                end associate
            end if
            s%p = self%p0 + v(1:2)
            s%v = d(1:2)
            s%a = dd(1:2)
            s%angle = self%angle0 + v(3)
            s%rate = d(3)
        end select
    end function motion_state

    !> The cubic Hermite basis h00, h10, h01, h11 at u (b), its first (db) and second (eb)
    !! derivatives in u: p(u) = h00 p0 + h10 H m0 + h01 p1 + h11 H m1 over a span H.
    pure subroutine hermite_basis(u, b, db, eb)
        real(wp), intent(in) :: u
        real(wp), intent(out) :: b(4), db(4), eb(4)
        b(1) = (1.0_wp + 2.0_wp*u)*(1.0_wp - u)**2
        b(2) = u*(1.0_wp - u)**2
        b(3) = u**2*(3.0_wp - 2.0_wp*u)
        b(4) = u**2*(u - 1.0_wp)
        db(1) = 6.0_wp*u*(u - 1.0_wp)
        db(2) = (1.0_wp - u)*(1.0_wp - 3.0_wp*u)
        db(3) = -db(1)
        db(4) = u*(3.0_wp*u - 2.0_wp)
        eb(1) = 12.0_wp*u - 6.0_wp
        eb(2) = 6.0_wp*u - 4.0_wp
        eb(3) = -eb(1)
        eb(4) = 6.0_wp*u - 2.0_wp
    end subroutine hermite_basis

    !> The ramp r(t) = s(t/T) of a harmonic motion and its first two derivatives in t:
    !! s(u) = 10u^3 - 15u^4 + 6u^5 on [0, 1], 0 before, 1 after (T <= 0: 1).
    pure function ramp(t, ramp_time) result(r)
        real(wp), intent(in) :: t, ramp_time
        real(wp) :: r(0:2), u
        r = [1.0_wp, 0.0_wp, 0.0_wp]
        if (.not. ramp_time > 0.0_wp) return
        if (t >= ramp_time) return
        r = 0.0_wp
        if (t <= 0.0_wp) return
        u = t/ramp_time
        r(0) = u**3*(10.0_wp + u*(-15.0_wp + 6.0_wp*u))
        r(1) = 30.0_wp*u**2*(1.0_wp - u)**2/ramp_time
        r(2) = 60.0_wp*u*(1.0_wp - u)*(1.0_wp - 2.0_wp*u)/ramp_time**2
    end function ramp

    !> Coupled: the curve from time t0 (the current one: position and velocity from the
    !! curve so far) to the position p1 (m) and velocity v1 (m/s) prescribed for t1 > t0, s.
    pure subroutine motion_couple(self, t0, t1, p1, v1)
        class(support_motion_t), intent(inout) :: self
        real(wp), intent(in) :: t0, t1, p1(2), v1(2)
        type(motion_state_t) :: now
        now = self%state(t0)
        self%span = [t0, t1]
        self%ends_p(:, 1) = now%p
        self%ends_v(:, 1) = now%v
        self%ends_p(:, 2) = p1
        self%ends_v(:, 2) = v1
    end subroutine motion_couple

    !> Index k with x(k) <= t < x(k+1) (x strictly increasing, x(1) < t < x(m)).
    pure integer function interval(x, t) result(k)
        real(wp), intent(in) :: x(:), t
        integer :: hi, mid
        k = 1
        hi = size(x)
        do while (hi - k > 1)
            mid = (k + hi)/2
            if (x(mid) <= t) then
                k = mid
            else
                hi = mid
            end if
        end do
    end function interval

    !> Set the motion from the `&supports` values of one end: kind 'harmonic', 'table' or
    !! 'coupled' (anything else leaves the support fixed); frequency in Hz, phases and the
    !! angle amplitude in degrees, the ramp in s, table rows as for `set_table`. A coupled
    !! support starts at rest at p0. True when it moves.
    logical function motion_configure(self, kind, amplitude, frequency, phase_deg, &
                                      angle_amplitude_deg, angle_phase_deg, rows, &
                                      ramp_time) result(moving)
        class(support_motion_t), intent(inout) :: self
        character(len=*), intent(in) :: kind
        real(wp), intent(in) :: amplitude(2), frequency, phase_deg(2), &
                                angle_amplitude_deg, angle_phase_deg
        real(wp), allocatable, intent(in) :: rows(:, :)
        real(wp), intent(in) :: ramp_time
        moving = .false.
        select case (kind)
        case ('harmonic')
            self%kind = MOTION_HARMONIC
            self%amplitude = amplitude
            self%omega = 2.0_wp*pi*frequency
            self%phase = phase_deg*pi/180.0_wp
            self%angle_amplitude = angle_amplitude_deg*pi/180.0_wp
            self%angle_phase = angle_phase_deg*pi/180.0_wp
            self%ramp_time = ramp_time
            moving = .true.
        case ('table')
            call self%set_table(rows)
            moving = .true.
        case ('coupled')
            self%kind = MOTION_COUPLED
            self%span = 0.0_wp
            self%ends_p = spread(self%p0, 2, 2)
            self%ends_v = 0.0_wp
            moving = .true.
        end select
    end function motion_configure

    !> Store table rows (4, m) (t in s, dx and dy in m, dangle in rad) and compute the
    !! Hermite slopes: three-point rule inside, zero at the ends.
    pure subroutine motion_set_table(self, rows)
        class(support_motion_t), intent(inout) :: self
        real(wp), intent(in) :: rows(:, :)
        integer :: k, m
        real(wp) :: h0, h1
        m = size(rows, 2)
        self%kind = MOTION_TABLE
        self%table = rows
        allocate (self%slope(3, m))
        self%slope = 0.0_wp
        do k = 2, m - 1
            h0 = rows(1, k) - rows(1, k - 1)
            h1 = rows(1, k + 1) - rows(1, k)
            self%slope(:, k) = (h1*(rows(2:4, k) - rows(2:4, k - 1))/h0 + &
                                h0*(rows(2:4, k + 1) - rows(2:4, k))/h1)/(h0 + h1)
        end do
    end subroutine motion_set_table
end module ropedyn_support_motion
