!> The outer spectrum of a problem's Jacobian, and what it means for the integrators:
!! how long a step an explicit Runge-Kutta pair can take before it turns unstable, whether
!! BDF of order q amplifies a mode at a given step, and the damping of the fastest modes.
!!
!! The estimate is a few steps of the Arnoldi process on J = df/dy at (t, y): its Ritz
!! values converge first to the eigenvalues of largest modulus, which are the ones that
!! limit explicit steps and that decide the damping question (a Gershgorin bound is
!! useless here: the rows of the rope's Jacobian mix m and m/s and overestimate the
!! spectral radius by 10^5 .. 10^9). J v comes from the problem's analytic band Jacobian,
!! or from a difference of f when it has none. Cost: one Jacobian (or m evaluations of
!! f) and m band products, i.e. a few right-hand sides.
module ropedyn_spectrum
    use ropedyn_kinds, only: wp
    use ropedyn_problem, only: problem_t, STATUS_OK
    use ropedyn_erk_tables, only: erk_table_t
    implicit none
    private
    public :: spectrum_t, estimate_spectrum, bdf_growth, erk_stable_step, LIGHT_DAMPING

    !> Krylov dimension of the estimate.
    integer, parameter :: KRYLOV = 24
    !> A fast mode damped by less than this is lightly damped: its energy stays for many
    !! periods, so a method that amplifies it (MEBDF at orders 5 .. 7) or drifts on it (an
    !! adaptive explicit one) spoils the energy balance of a long run, and the symplectic
    !! method takes the 4th-order composition for it (docs/validation/energy.md,
    !! docs/theory/symplectic.md).
    real(wp), parameter :: LIGHT_DAMPING = 0.01_wp

    !> Ritz values of the Jacobian (1/s) and what follows from them.
    type :: spectrum_t
        complex(wp), allocatable :: ritz(:)   !< the Ritz values, largest modulus first
        real(wp) :: radius = 0.0_wp           !< largest |lambda|, 1/s
        !> smallest damping ratio -Re(lambda)/|lambda| among the fast modes (|lambda| >=
        !! radius/10), clipped at 0
        real(wp) :: fast_damping = 1.0_wp
        logical :: valid = .false.            !< the estimate could be made
    contains
        procedure :: fast => spectrum_fast
        procedure :: settled_damping => spectrum_settled_damping
    end type spectrum_t

    interface
        subroutine dgeev(jobvl, jobvr, n, a, lda, wr, wi, vl, ldvl, vr, ldvr, work, lwork, info)
            import :: wp
            character(len=1), intent(in) :: jobvl, jobvr
            integer, intent(in) :: n, lda, ldvl, ldvr, lwork
            real(wp), intent(inout) :: a(lda, *)
            real(wp), intent(out) :: wr(*), wi(*), vl(ldvl, *), vr(ldvr, *), work(*)
            integer, intent(out) :: info
        end subroutine dgeev
        subroutine zgeev(jobvl, jobvr, n, a, lda, w, vl, ldvl, vr, ldvr, work, lwork, rwork, &
                         info)
            import :: wp
            character(len=1), intent(in) :: jobvl, jobvr
            integer, intent(in) :: n, lda, ldvl, ldvr, lwork
            complex(wp), intent(inout) :: a(lda, *)
            complex(wp), intent(out) :: w(*), vl(ldvl, *), vr(ldvr, *), work(*)
            real(wp), intent(out) :: rwork(*)
            integer, intent(out) :: info
        end subroutine zgeev
    end interface

contains

    !> Ritz values of df/dy at (t, y) from `KRYLOV` Arnoldi steps (fewer for small systems).
    subroutine estimate_spectrum(problem, t, y, spec)
        class(problem_t), intent(inout) :: problem
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        type(spectrum_t), intent(out) :: spec
        real(wp), allocatable :: v(:, :), hess(:, :), jb(:, :), f0(:), w(:), yp(:), fp(:)
        real(wp), allocatable :: wr(:), wi(:), work(:)
        real(wp) :: dummy(1, 1), beta, eps
        integer :: n, m, ml, mu, j, i, k, status, info, order(KRYLOV)
        logical :: band

        n = problem%size()
        m = min(KRYLOV, n)
        allocate (v(n, m + 1), hess(m + 1, m), w(n))
        hess = 0.0_wp
        band = problem%has_jacobian()
        if (band) then
            call problem%bandwidths(ml, mu)
            ml = min(ml, n - 1)
            mu = min(mu, n - 1)
            allocate (jb(ml + mu + 1, n))
            jb = 0.0_wp
            call problem%jacobian(t, y, jb, mu + 1, status)
            if (status /= STATUS_OK) return
        else
            allocate (f0(n), yp(n), fp(n))
            call problem%rhs(t, y, f0, status)
            if (status /= STATUS_OK) return
        end if
        ! a fixed start vector with every component, from the golden-ratio (Weyl) sequence:
        ! exact arithmetic, no sin, whose vectorized variants (libmvec) differ in the last
        ! bits from one x86-64 level to the next (so the run would follow the build's -march)
        do i = 1, n
            v(i, 1) = 0.5_wp + modulo(0.6180339887498949_wp*i, 1.0_wp)
        end do
        v(:, 1) = v(:, 1)/norm2(v(:, 1))
        k = m
        do j = 1, m
            if (band) then
                call band_product(jb, ml, mu, v(:, j), w)
            else
                eps = sqrt(epsilon(1.0_wp))*(1.0_wp + norm2(y)/sqrt(real(n, wp)))
                yp = y + eps*v(:, j)
                call problem%rhs(t, yp, fp, status)
                if (status /= STATUS_OK) return
                w = (fp - f0)/eps
            end if
            ! modified Gram-Schmidt, twice
            do i = 1, j
                beta = dot_product(v(:, i), w)
                hess(i, j) = beta
                w = w - beta*v(:, i)
            end do
            do i = 1, j
                beta = dot_product(v(:, i), w)
                hess(i, j) = hess(i, j) + beta
                w = w - beta*v(:, i)
            end do
            hess(j + 1, j) = norm2(w)
            if (hess(j + 1, j) <= 1.0e-12_wp*max(1.0_wp, maxval(abs(hess(1:j, j))))) then
                k = j   ! an invariant subspace: its eigenvalues are exact
                exit
            end if
            v(:, j + 1) = w/hess(j + 1, j)
        end do
        allocate (wr(k), wi(k), work(8*k))
        ! dgeev balances H first (half its cost here): its eigenvalues straight from the
        ! Hessenberg QR (dhseqr) put the damping of catenary's fast modes at 0.45, not 0
        call dgeev('N', 'N', k, hess, m + 1, wr, wi, dummy, 1, dummy, 1, work, 8*k, info)
        if (info /= 0) return
        spec%ritz = cmplx(wr, wi, wp)
        ! largest modulus first
        order(1:k) = [(i, i = 1, k)]
        do i = 2, k
            j = i
            do while (j > 1)
                if (abs(spec%ritz(order(j - 1))) >= abs(spec%ritz(order(j)))) exit
                order(j - 1:j) = order([j, j - 1])
                j = j - 1
            end do
        end do
        spec%ritz = spec%ritz(order(1:k))
        spec%radius = abs(spec%ritz(1))
        spec%fast_damping = 1.0_wp
        do i = 1, k
            if (abs(spec%ritz(i)) < 0.1_wp*spec%radius) exit
            spec%fast_damping = min(spec%fast_damping, &
                                    max(0.0_wp, -real(spec%ritz(i), wp)/abs(spec%ritz(i))))
        end do
        spec%valid = spec%radius > 0.0_wp
    end subroutine estimate_spectrum

    !> The Ritz values of the fast modes (|lambda| >= fraction * radius).
    pure function spectrum_fast(self, fraction) result(fast)
        class(spectrum_t), intent(in) :: self
        real(wp), intent(in) :: fraction
        complex(wp), allocatable :: fast(:)
        if (.not. allocated(self%ritz)) then
            allocate (fast(0))
            return
        end if
        fast = pack(self%ritz, abs(self%ritz) >= fraction*self%radius)
    end function spectrum_fast

    !> The smallest damping ratio -Re(lambda)/|lambda| of the fast Ritz values (|lambda| >=
    !! radius/10) in the closed left half plane; 1 when there are none. Unlike fast_damping
    !! it leaves out Ritz values in the right half plane, which on a damped rope are not yet
    !! converged (the paper's rope, n = 30: 4.0e3 + 3.3e3 i among modes damped by 1.5 ..
    !! 12 %), so that a damped rope does not count as lightly damped.
    pure real(wp) function spectrum_settled_damping(self) result(zeta)
        class(spectrum_t), intent(in) :: self
        complex(wp), allocatable :: fast(:)
        integer :: i
        zeta = 1.0_wp
        fast = self%fast(0.1_wp)
        do i = 1, size(fast)
            if (real(fast(i), wp) > 0.0_wp .or. abs(fast(i)) <= 0.0_wp) cycle
            zeta = min(zeta, -real(fast(i), wp)/abs(fast(i)))
        end do
    end function spectrum_settled_damping

    !> w = J v for J in band storage (entry (i, j) at jb(mu + 1 + i - j, j)).
    pure subroutine band_product(jb, ml, mu, v, w)
        real(wp), intent(in) :: jb(:, :)
        integer, intent(in) :: ml, mu
        real(wp), intent(in) :: v(:)
        real(wp), intent(out) :: w(:)
        integer :: i, j, n
        n = size(v)
        w = 0.0_wp
        do j = 1, n
            do i = max(1, j - mu), min(n, j + ml)
                w(i) = w(i) + jb(mu + 1 + i - j, j)*v(j)
            end do
        end do
    end subroutine band_product

    !> Largest modulus of the roots xi of the fixed-step BDF of order q applied to
    !! y' = lambda y, z = h lambda: sum_{j=1..q} (1/j) xi^(q-j) (xi - 1)^j = z xi^q.
    !! Above 1 the method amplifies that mode.
    real(wp) function bdf_growth(q, z) result(growth)
        integer, intent(in) :: q
        complex(wp), intent(in) :: z
        complex(wp) :: c(0:q), comp(q, q), w(q), work(4*q), dummy(1, 1)
        real(wp) :: rwork(2*q), p(0:q), binom
        integer :: j, i, info
        ! coefficients of xi^0 .. xi^q of sum_j (1/j) xi^(q-j) (xi - 1)^j
        p = 0.0_wp
        do j = 1, q
            binom = 1.0_wp
            do i = 0, j
                ! (xi - 1)^j = sum_i C(j, i) xi^i (-1)^(j-i), times xi^(q-j)
                p(q - j + i) = p(q - j + i) + binom*(-1.0_wp)**(j - i)/j
                binom = binom*(j - i)/(i + 1)
            end do
        end do
        c = cmplx(p, 0.0_wp, wp)
        c(q) = c(q) - z
        ! companion matrix of the monic polynomial
        comp = (0.0_wp, 0.0_wp)
        do i = 2, q
            comp(i, i - 1) = (1.0_wp, 0.0_wp)
        end do
        comp(:, q) = -c(0:q - 1)/c(q)
        call zgeev('N', 'N', q, comp, q, w, dummy, 1, dummy, 1, work, 4*q, rwork, info)
        growth = huge(1.0_wp)
        if (info == 0) growth = maxval(abs(w))
    end function bdf_growth

    !> The largest step h (s) for which every Ritz value of `spec` with |lambda| >=
    !! radius/10 is stable for the explicit pair `tab` (|R(h lambda)| <= 1): the
    !! stability-limited step of an explicit method on this problem. Ritz values in the
    !! right half plane (slow, physically growing modes, or estimates just off the axis)
    !! count as on the imaginary axis. 0 when there is no estimate.
    !! h is the last of SAMPLES steps up to 8 / radius (beyond every table's region) before
    !! the first unstable one, found by a scan of every STRIDE-th sample and then of the
    !! samples of the last stride one by one (a tenth of the evaluations of |R|; the same
    !! h as a scan of all, unless an unstable stretch shorter than a stride lies inside
    !! the region: none for the bundled pairs, tests/unit/test_stable_step).
    real(wp) function erk_stable_step(tab, spec) result(h)
        type(erk_table_t), intent(in) :: tab
        type(spectrum_t), intent(in) :: spec
        complex(wp), allocatable :: fast(:)
        real(wp) :: step
        integer :: k, k0, i
        integer, parameter :: SAMPLES = 2000, STRIDE = 16
        h = 0.0_wp
        if (.not. spec%valid) return
        fast = spec%fast(0.1_wp)
        do i = 1, size(fast)
            if (real(fast(i), wp) > 0.0_wp) fast(i) = cmplx(0.0_wp, aimag(fast(i)), wp)
        end do
        step = 8.0_wp/spec%radius/SAMPLES
        k0 = 0
        do k = STRIDE, SAMPLES, STRIDE
            if (.not. stable(k*step)) exit
            k0 = k
        end do
        h = k0*step
        do k = k0 + 1, min(k0 + STRIDE - 1, SAMPLES)
            if (.not. stable(k*step)) exit
            h = k*step
        end do
    contains
        logical function stable(hs)
            real(wp), intent(in) :: hs
            integer :: j
            stable = .true.
            do j = 1, size(fast)
                if (tab%amplification(hs*fast(j)) > 1.0_wp + 1.0e-12_wp) then
                    stable = .false.
                    return
                end if
            end do
        end function stable
    end function erk_stable_step
end module ropedyn_spectrum
