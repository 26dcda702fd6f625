!> Independent anchors for the MPP's damping rules, the axial stiffness of both models and
!! point masses in both models (docs/development/testing.md, "Anchors"). lambda = rho A, M = lambda L,
!! EA, EI, tau = eta/E; x down, y horizontal.
!!
!! - MPP axial damping (factor a = 2): the members' springs k = EA/l and dampers
!!   d = a eta A/l = a tau k are proportional, so every axial mode of the hanging rope (a
!!   fixed-free chain of n masses m = M/n and n springs k) decays at sigma = a tau w^2/2, with
!!   w_1 = 2 sqrt(k/m) sin(pi/(2(2n + 1))), and rings at w_1 sqrt(1 - (sigma/w_1)^2).
!! - MPP bending damping (factor b = 3): two rods pinned at the top, no gravity, no
!!   extension: the joint's spring c = EI/l and damper b eta I/l = b tau c are proportional;
!!   the single bending mode (the rigid turn about the pin is a zero mode, not excited from
!!   rest) has w^2 = c v^T M^-1 v, v = (-1, 1), M the rods' mass matrix at phi = 0
!!   [[m(h^2 + l^2) + J, m l h], [m l h, m h^2 + J]], h = l/2, J = m (l^2/12 + d^2/16), and
!!   decays at sigma = b tau w^2/2.
!! - Static stretch of the hanging rope: MPP spring k carries the rods k .. n, so the tip is
!!   lower by sum (n - k + 1) m g/k = M g L (n + 1)/(2 n EA); RFEM SDE j carries the weight
!!   below s = (j - 3/2) dl, which sums to w L^2/(2 EA) for every n, plus the top support's
!!   stretch M g dl/EA.
!! - Point mass (both models): a very stiff rope (E x 1e6) swings as a rigid rod; with a
!!   point mass m_p at arc length s_p, w0^2 = g (M L/2 + m_p s_p)/(M L^2/3 + M d^2/16 +
!!   m_p s_p^2), and the period at amplitude theta0 is 2 pi/w0 (1 + theta0^2/16 + ...).
!! Tolerances are a few times the discrepancies measured (Debug build, CVODE; printed by
!! each check and listed in docs/development/testing.md).
program test_mpp_anchors
    use ropedyn_kinds, only: wp
    use ropedyn_test_run, only: run_t, simulate, completed, kind_set, SET_LEN
    use ropedyn_assert, only: test_suite_t
    implicit none

    type(test_suite_t) :: suite
    real(wp), parameter :: pi = acos(-1.0_wp), g = 9.81_wp, deg = pi/180.0_wp
    real(wp), parameter :: d = 0.005_wp, area = pi*d**2/4.0_wp, second = pi*d**4/64.0_wp
    real(wp), parameter :: lam = 6000.0_wp*area, rope_mass = lam, ea = 35.0e6_wp*area

    suite%name = 'mpp_anchors'
    call mpp_axial_decay()
    call mpp_bending_decay()
    call static_stretch('mpp')
    call static_stretch('rfem')
    call rigid_pendulum_with_point_mass('mpp')
    call rigid_pendulum_with_point_mass('rfem')
    call suite%finish()

contains



    !> Decay rate and angular frequency of a decaying oscillation s(t) (mean zero) from its
    !! maxima after t_from: parabolic peaks, a least-squares line through log(peak), and
    !! the mean distance of the peaks.
    subroutine decay_of(t, s, t_from, sigma, omega, peaks)
        real(wp), intent(in) :: t(0:), s(0:), t_from
        real(wp), intent(out) :: sigma, omega
        integer, intent(out) :: peaks
        real(wp) :: tp(size(t)), lp(size(t)), dt, den, off, mt, ml
        integer :: k
        peaks = 0
        dt = t(1) - t(0)
        do k = 1, ubound(t, 1) - 1
            if (t(k) < t_from) cycle
            if (s(k) > s(k - 1) .and. s(k) >= s(k + 1) .and. s(k) > 0.0_wp) then
                den = s(k - 1) - 2.0_wp*s(k) + s(k + 1)
                off = 0.5_wp*(s(k - 1) - s(k + 1))/den
                peaks = peaks + 1
                tp(peaks) = t(k) + off*dt
                lp(peaks) = log(s(k) - 0.25_wp*(s(k - 1) - s(k + 1))*off)
            end if
        end do
        sigma = 0.0_wp
        omega = 0.0_wp
        if (peaks < 3) return
        mt = sum(tp(1:peaks))/peaks
        ml = sum(lp(1:peaks))/peaks
        sigma = -sum((tp(1:peaks) - mt)*(lp(1:peaks) - ml))/sum((tp(1:peaks) - mt)**2)
        omega = 2.0_wp*pi*real(peaks - 1, wp)/(tp(peaks) - tp(1))
    end subroutine decay_of

    !> MPP, n = 10, hanging from rest unstretched (so the axial modes ring), eta = 1e4,
    !! axial damping factor 2: the tip's axial oscillation after the higher modes have died
    !! (t > 0.3 s) against sigma = a tau w_1^2/2 and the damped w_1.
    subroutine mpp_axial_decay()
        type(run_t) :: run
        integer, parameter :: n = 10
        real(wp), parameter :: eta = 1.0e4_wp, a = 2.0_wp
        real(wp) :: s(0:2600), p(2, 2*n), x_static, w1, sigma_expected, wd_expected
        real(wp) :: sigma, omega
        integer :: k, peaks
        call simulate([character(len=SET_LEN) :: 'model.kind=mpp', 'model.elements=10', &
            'effects.bending=.false.', 'initial.shape=hanging', 'rope.normal_damping=1e4', &
            'model.mpp_axial_damping_factor=2.0'], 1.3_wp, 5.0e-4_wp, 1.0e-9_wp, run, &
            atol=1.0e-12_wp)
        if (.not. completed(suite, run, 'mpp axial decay')) return
        x_static = 1.0_wp + rope_mass*g*(n + 1)/(2.0_wp*n*ea)
        do k = 0, run%last()
            p = run%points(k)
            s(k) = p(1, 2*n) - x_static
        end do
        call decay_of(run%t, s(0:run%last()), 0.3_wp, sigma, omega, peaks)
        w1 = 2.0_wp*sqrt(ea*n/(rope_mass/n))*sin(pi/(2.0_wp*(2*n + 1)))
        sigma_expected = a*(eta/35.0e6_wp)*w1**2/2.0_wp
        wd_expected = w1*sqrt(1.0_wp - (sigma_expected/w1)**2)
        write (*, '(a, i0, a, 2f12.6, a, 2f12.6, a)') '  mpp axial: ', peaks, &
            ' peaks; decay', sigma, sigma_expected, ' 1/s; frequency', omega, wd_expected, ' rad/s'
        call suite%check_close(sigma, sigma_expected, 3.0e-5_wp, 0.0_wp, &
            'mpp: axial decay rate = a tau w_1^2/2 (damping factor a = 2)')
        call suite%check_close(omega, wd_expected, 7.0e-9_wp, 0.0_wp, &
            'mpp: axial frequency = the fixed-free chain w_1, damped')
    end subroutine mpp_axial_decay

    !> Two rods, no gravity, inextensible, E = 3.5e9 Pa, eta = 1e7 N s/m^2, bending damping
    !! factor 3, the joint bent by 0.01 rad from rest: the joint angle's decay and frequency.
    subroutine mpp_bending_decay()
        type(run_t) :: run
        real(wp), parameter :: e_mod = 3.5e9_wp, eta = 1.0e7_wp, b = 3.0_wp
        real(wp) :: y0(4), s(0:2000), m, l, h, j, m11, m12, m22, w2, sigma_expected
        real(wp) :: wd_expected, sigma, omega
        integer :: k, peaks
        y0 = [-0.005_wp, 0.005_wp, 0.0_wp, 0.0_wp]
        call simulate([character(len=SET_LEN) :: 'model.kind=mpp', 'model.elements=2', &
            'effects.gravity=.false.', 'effects.tension=.false.', 'rope.young_modulus=3.5e9', &
            'rope.normal_damping=1e7', 'model.mpp_bending_damping_factor=3.0', &
            'initial.shape=hanging'], 4.0_wp, 2.0e-3_wp, 1.0e-10_wp, run, atol=1.0e-13_wp, &
            y0=y0)
        if (.not. completed(suite, run, 'mpp bending decay')) return
        do k = 0, run%last()
            s(k) = run%y(2, k) - run%y(1, k)
        end do
        call decay_of(run%t, s(0:run%last()), 0.0_wp, sigma, omega, peaks)
        m = rope_mass/2.0_wp
        l = 0.5_wp
        h = 0.5_wp*l
        j = m*(l**2/12.0_wp + d**2/16.0_wp)
        m11 = m*(h**2 + l**2) + j
        m12 = m*l*h
        m22 = m*h**2 + j
        w2 = (e_mod*second/l)*(m11 + 2.0_wp*m12 + m22)/(m11*m22 - m12**2)
        sigma_expected = b*(eta/e_mod)*w2/2.0_wp
        wd_expected = sqrt(w2 - sigma_expected**2)
        write (*, '(a, i0, a, 2f12.6, a, 2f12.6, a)') '  mpp bending: ', peaks, &
            ' peaks; decay', sigma, sigma_expected, ' 1/s; frequency', omega, wd_expected, ' rad/s'
        call suite%check_close(sigma, sigma_expected, 2.0e-5_wp, 0.0_wp, &
            'mpp: bending decay rate = b tau w^2/2 (damping factor b = 3)')
        call suite%check_close(omega, wd_expected, 1.5e-5_wp, 0.0_wp, &
            'mpp: bending frequency w^2 = c v^T M^-1 v, damped')
    end subroutine mpp_bending_decay

    !> Static equilibrium of the hanging rope, n = 10: the tip's stretch.
    subroutine static_stretch(kind)
        character(len=*), intent(in) :: kind
        type(run_t) :: run
        real(wp) :: p(2, 20), expected
        call simulate([character(len=SET_LEN) :: kind_set(kind), 'model.elements=10', &
            'initial.shape=equilibrium', 'initial.angle_deg=0'], 0.01_wp, 0.01_wp, &
            1.0e-8_wp, run)
        if (.not. completed(suite, run, kind//' static stretch')) return
        p = run%points(0)
        if (kind == 'mpp') then
            expected = rope_mass*g*11.0_wp/(2.0_wp*10.0_wp*ea)
        else
            expected = rope_mass*g/(2.0_wp*ea)*(1.0_wp + 2.0_wp/9.0_wp)
        end if
        write (*, '(a, 2es16.8, a)') '  '//kind//' static stretch', p(1, 20) - 1.0_wp, &
            expected, ' m'
        call suite%check_close(p(1, 20) - 1.0_wp, expected, 2.0e-12_wp, 0.0_wp, kind// &
            ': static tip stretch of the hanging rope (its springs carry the weight below)')
    end subroutine static_stretch

    !> A rope stiffened to a rigid rod (E, G x 1e6; eta x 1e6 keeps tau = eta/E, so that its
    !! fast modes stay damped) with a point mass 0.1 kg at s = 0.6 m, released at 2 deg: the period from the tip's zero crossings against the compound
    !! pendulum's.
    subroutine rigid_pendulum_with_point_mass(kind)
        character(len=*), intent(in) :: kind
        type(run_t) :: run
        real(wp), parameter :: mp = 0.1_wp, sp = 0.6_wp, theta0 = 2.0_wp*deg
        real(wp) :: crossings(4), prev, now, w0, expected, period, p(2, 10)
        integer :: k, nc, n
        character(len=SET_LEN) :: elements, tension
        if (kind == 'mpp') then
            elements = 'model.elements=4'
            tension = 'effects.tension=.false.'
        else
            elements = 'model.elements=5'
            tension = 'effects.tension=.true.'
        end if
        call simulate([character(len=SET_LEN) :: kind_set(kind), elements, tension, &
            'rope.young_modulus=35e12', 'rope.shear_modulus=14e12', 'rope.normal_damping=1e9', &
            'initial.angle_deg=2', 'attachments.mass_positions=0.6', 'attachments.masses=0.1'], &
            3.8_wp, 2.0e-3_wp, &
            1.0e-9_wp, run)
        if (.not. completed(suite, run, kind//' rigid pendulum')) return
        n = run%model%n_elements()
        nc = 0
        p(:, 1:2*n) = run%points(0)
        prev = p(2, 2*n)
        do k = 1, run%last()
            p(:, 1:2*n) = run%points(k)
            now = p(2, 2*n)
            if (prev > 0.0_wp .and. now <= 0.0_wp .and. nc < size(crossings)) then
                nc = nc + 1
                crossings(nc) = run%t(k - 1) + (run%t(k) - run%t(k - 1))*prev/(prev - now)
            end if
            prev = now
        end do
        call suite%check_true(nc >= 3, kind//': rigid pendulum: two periods')
        if (nc < 3) return
        period = (crossings(nc) - crossings(1))/real(nc - 1, wp)
        w0 = sqrt(g*(rope_mass/2.0_wp + mp*sp)/(rope_mass/3.0_wp + rope_mass*d**2/16.0_wp &
                                                 + mp*sp**2))
        expected = 2.0_wp*pi/w0*(1.0_wp + theta0**2/16.0_wp + 11.0_wp*theta0**4/3072.0_wp)
        write (*, '(a, 2f14.9, a)') '  '//kind//' rigid pendulum with point mass: period', &
            period, expected, ' s'
        call suite%check_close(period, expected, 2.0e-6_wp, 0.0_wp, kind// &
            ': point mass: period of the compound pendulum (rigid rope, mass at s = 0.6 m)')
    end subroutine rigid_pendulum_with_point_mass
end program test_mpp_anchors
