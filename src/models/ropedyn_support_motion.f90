!> Prescribed motion of a rope support: fixed, harmonic, or tabulated (a file of rows
!! t, dx, dy, dangle interpolated by a C1 cubic Hermite spline), evaluated with its velocity
!! and acceleration. The model asks for the state once per right-hand-side call.
!!
!! Harmonic, per axis: p(t) = p0 + a sin(omega t + phase); angle(t) = angle0 +
!! A sin(omega t + phase_angle). Table: p(t) = p0 + (dx, dy)(t), angle(t) = angle0 +
!! dangle(t), with the slopes of the three-point (parabolic) rule at interior rows and zero
!! slope at the first and last row; before the first row and after the last the support rests
!! at the end values, so the motion is C1 for all t. Frame: x down, y horizontal, angles
!! from x towards y (docs/guide/scenes.md, `&supports`).
module ropedyn_support_motion
    use ropedyn_kinds, only: wp
    implicit none
    private
    public :: support_motion_t, motion_state_t
    public :: MOTION_FIXED, MOTION_HARMONIC, MOTION_TABLE

    integer, parameter :: MOTION_FIXED = 0, MOTION_HARMONIC = 1, MOTION_TABLE = 2
    real(wp), parameter :: pi = acos(-1.0_wp)

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
        !> table rows (4, m): t (s), dx, dy (m), dangle (rad)
        real(wp), allocatable :: table(:, :)
        real(wp), allocatable :: slope(:, :)   !< Hermite slopes (3, m) of dx, dy, dangle
    contains
        procedure :: state => motion_state
        procedure :: set_table => motion_set_table
        procedure :: configure => motion_configure
    end type support_motion_t

contains

    !> Position, velocity, acceleration, angle and rate of the support at time t.
    pure function motion_state(self, t) result(s)
        class(support_motion_t), intent(in) :: self
        real(wp), intent(in) :: t
        type(motion_state_t) :: s
        real(wp) :: arg(2), arg_a, h, u, v(3), d(3), dd(3), h00, h10, h01, h11
        real(wp) :: d00, d10, d01, d11, e00, e10, e01, e11
        integer :: k, m

        s%p = self%p0
        s%angle = self%angle0
        select case (self%kind)
        case (MOTION_HARMONIC)
            arg = self%omega*t + self%phase
            s%p = self%p0 + self%amplitude*sin(arg)
            s%v = self%amplitude*self%omega*cos(arg)
            s%a = -self%amplitude*self%omega**2*sin(arg)
            arg_a = self%omega*t + self%angle_phase
            s%angle = self%angle0 + self%angle_amplitude*sin(arg_a)
            s%rate = self%angle_amplitude*self%omega*cos(arg_a)
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
                ! cubic Hermite basis, its first and second derivatives in u
                h00 = (1.0_wp + 2.0_wp*u)*(1.0_wp - u)**2
                h10 = u*(1.0_wp - u)**2
                h01 = u**2*(3.0_wp - 2.0_wp*u)
                h11 = u**2*(u - 1.0_wp)
                d00 = 6.0_wp*u*(u - 1.0_wp)
                d10 = (1.0_wp - u)*(1.0_wp - 3.0_wp*u)
                d01 = -d00
                d11 = u*(3.0_wp*u - 2.0_wp)
                e00 = 12.0_wp*u - 6.0_wp
                e10 = 6.0_wp*u - 4.0_wp
                e01 = -e00
                e11 = 6.0_wp*u - 2.0_wp
                associate (y0 => self%table(2:4, k), y1 => self%table(2:4, k + 1), &
                           m0 => self%slope(:, k), m1 => self%slope(:, k + 1))
                    v = h00*y0 + h10*h*m0 + h01*y1 + h11*h*m1
                    d = (d00*y0 + d10*h*m0 + d01*y1 + d11*h*m1)/h
                    dd = (e00*y0 + e10*h*m0 + e01*y1 + e11*h*m1)/h**2
                end associate
            end if
            s%p = self%p0 + v(1:2)
            s%v = d(1:2)
            s%a = dd(1:2)
            s%angle = self%angle0 + v(3)
            s%rate = d(3)
        end select
    end function motion_state

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

    !> Set the motion from the `&supports` values of one end: kind 'harmonic' or
    !! 'table' (anything else leaves the support fixed); frequency in Hz, phases and the
    !! angle amplitude in degrees, table rows as for `set_table`. True when it moves.
    logical function motion_configure(self, kind, amplitude, frequency, phase_deg, &
                                      angle_amplitude_deg, angle_phase_deg, rows) result(moving)
        class(support_motion_t), intent(inout) :: self
        character(len=*), intent(in) :: kind
        real(wp), intent(in) :: amplitude(2), frequency, phase_deg(2), &
                                angle_amplitude_deg, angle_phase_deg
        real(wp), allocatable, intent(in) :: rows(:, :)
        moving = .false.
        select case (kind)
        case ('harmonic')
            self%kind = MOTION_HARMONIC
            self%amplitude = amplitude
            self%omega = 2.0_wp*pi*frequency
            self%phase = phase_deg*pi/180.0_wp
            self%angle_amplitude = angle_amplitude_deg*pi/180.0_wp
            self%angle_phase = angle_phase_deg*pi/180.0_wp
            moving = .true.
        case ('table')
            call self%set_table(rows)
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
