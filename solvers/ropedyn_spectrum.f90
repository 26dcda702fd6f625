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
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use ropedyn_kinds, only: wp
    use ropedyn_lapack, only: dgeev, zgeev
    use ropedyn_problem, only: problem_t, STATUS_OK
    use ropedyn_erk_tables, only: erk_table_t
    implicit none
    private
    public :: spectrum_t, estimate_spectrum, bdf_growth, erk_stable_step, LIGHT_DAMPING, &
              FAST_FRACTION

    !> Krylov dimension of the estimate. The Jacobian of a rope in first-order form is far
    !! from normal (m and m/s in one vector), so a Ritz value can lie well outside its
    !! spectrum with a small residual (in its pseudospectrum): on the paper's rope with 10
    !! elements (60 unknowns) 24 steps gave |lambda| 2.5 .. 5.6e3 1/s in the right half
    !! plane, against the spectral radius 2.08e3 1/s (damping 0.03) of every state's
    !! Jacobian (tests/unit/test_spectrum_estimate.f90). On a damped
    !! rope a fast Ritz value in the right half plane is that mark; there the estimate is
    !! made again on the balanced Jacobian (krylov_t's balance), whose Ritz values lie near
    !! the spectrum. Where none is, the first estimate stands (the paper's rope with 30
    !! elements: the spectral radius and its damping to four digits).
    integer, parameter :: KRYLOV = 24
    !> A fast mode damped by less than this is lightly damped: its energy stays for many
    !! periods, so a method that amplifies it (MEBDF at orders 5 .. 7) or drifts on it (an
    !! adaptive explicit one) spoils the energy balance of a long run, and the symplectic
    !! method takes the 4th-order composition for it (docs/validation/energy.md,
    !! docs/theory/symplectic.md).
    real(wp), parameter :: LIGHT_DAMPING = 0.01_wp
    !> A fast mode: a Ritz value of modulus at least this fraction of the spectral radius.
    real(wp), parameter :: FAST_FRACTION = 0.1_wp

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

    !> The Arnoldi process on df/dy at one (t, y): its Jacobian (or f there) and basis.
    type :: krylov_t
        real(wp), allocatable :: v(:, :), hess(:, :), jb(:, :), f0(:), w(:), yp(:), fp(:)
        integer :: m = 0                   !< Arnoldi steps
        integer :: ml = 0, mu = 0
        logical :: band = .false.          !< J from the problem's band Jacobian
    contains
        procedure :: begin => krylov_begin
        procedure :: ritz_values => krylov_ritz_values
        procedure :: balance => krylov_balance
    end type krylov_t

contains

    !> Ritz values of df/dy at (t, y) from `KRYLOV` Arnoldi steps (fewer for small
    !! systems); where a fast one lies in the right half plane, again on the balanced band
    !! Jacobian (krylov_t's balance: the header of KRYLOV says why).
    subroutine estimate_spectrum(problem, t, y, spec)
        class(problem_t), intent(inout) :: problem
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        type(spectrum_t), intent(out) :: spec
        type(krylov_t) :: kr
        integer :: i, status
        logical :: ok

        call kr%begin(problem, t, y, status)
        if (status /= STATUS_OK) return
        call kr%ritz_values(problem, t, y, spec%ritz, ok)
        if (.not. ok) return
        if (kr%band .and. any(real(spec%ritz, wp) > 0.0_wp .and. &
                              abs(spec%ritz) >= FAST_FRACTION*abs(spec%ritz(1)))) then
            call kr%balance()
            call kr%ritz_values(problem, t, y, spec%ritz, ok)
            if (.not. ok) return
        end if
        spec%radius = abs(spec%ritz(1))
        spec%fast_damping = 1.0_wp
        do i = 1, size(spec%ritz)
            if (abs(spec%ritz(i)) < FAST_FRACTION*spec%radius) exit
            spec%fast_damping = min(spec%fast_damping, &
                                    max(0.0_wp, -real(spec%ritz(i), wp)/abs(spec%ritz(i))))
        end do
        spec%valid = spec%radius > 0.0_wp
    end subroutine estimate_spectrum

    !> The Jacobian (band) or f(t, y) (for differences) at (t, y), and the start vector.
    subroutine krylov_begin(self, problem, t, y, status)
        class(krylov_t), intent(inout) :: self
        class(problem_t), intent(inout) :: problem
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        integer, intent(out) :: status
        integer :: n
        n = size(y)
        self%m = min(KRYLOV, n)
        allocate (self%v(n, self%m + 1), self%hess(self%m + 1, self%m), self%w(n))
        self%band = problem%has_jacobian()
        status = STATUS_OK
        if (self%band) then
            call problem%bandwidths(self%ml, self%mu)
            self%ml = min(self%ml, n - 1)
            self%mu = min(self%mu, n - 1)
            allocate (self%jb(self%ml + self%mu + 1, n))
            self%jb = 0.0_wp
            call problem%jacobian(t, y, self%jb, self%mu + 1, status)
        else
            allocate (self%f0(n), self%yp(n), self%fp(n))
            call problem%rhs(t, y, self%f0, status)
        end if
    end subroutine krylov_begin

    !> The Ritz values, largest modulus first, of `m` Arnoldi steps from the fixed start
    !! vector (fewer when an invariant subspace is found: its eigenvalues are exact).
    subroutine krylov_ritz_values(self, problem, t, y, ritz, ok)
        class(krylov_t), intent(inout) :: self
        class(problem_t), intent(inout) :: problem
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        complex(wp), allocatable, intent(out) :: ritz(:)
        logical, intent(out) :: ok
        real(wp), allocatable :: wr(:), wi(:), work(:)
        real(wp) :: dummy(1, 1), beta, eps
        integer :: n, m, j, i, k, status, info, order(KRYLOV)

        ok = .false.
        n = size(y)
        m = self%m
        self%hess = 0.0_wp
        ! a fixed start vector with every component, from the golden-ratio (Weyl) sequence:
        ! exact arithmetic, no sin, whose vectorized variants (libmvec) differ in the last
        ! bits from one x86-64 level to the next (so the run would follow the build's -march)
        do i = 1, n
            self%v(i, 1) = 0.5_wp + modulo(0.6180339887498949_wp*i, 1.0_wp)
        end do
        self%v(:, 1) = self%v(:, 1)/norm2(self%v(:, 1))
        k = m
        do j = 1, m
            if (self%band) then
                call band_product(self%jb, self%ml, self%mu, self%v(:, j), self%w)
            else
                eps = sqrt(epsilon(1.0_wp))*(1.0_wp + norm2(y)/sqrt(real(n, wp)))
                self%yp = y + eps*self%v(:, j)
                call problem%rhs(t, self%yp, self%fp, status)
                if (status /= STATUS_OK) return
                self%w = (self%fp - self%f0)/eps
            end if
            ! modified Gram-Schmidt, twice
            do i = 1, j
                beta = dot_product(self%v(:, i), self%w)
                self%hess(i, j) = beta
                self%w = self%w - beta*self%v(:, i)
            end do
            do i = 1, j
                beta = dot_product(self%v(:, i), self%w)
                self%hess(i, j) = self%hess(i, j) + beta
                self%w = self%w - beta*self%v(:, i)
            end do
            self%hess(j + 1, j) = norm2(self%w)
            if (self%hess(j + 1, j) <= 1.0e-12_wp*max(1.0_wp, maxval(abs(self%hess(1:j, j))))) then
                k = j   ! an invariant subspace: its eigenvalues are exact
                exit
            end if
            self%v(:, j + 1) = self%w/self%hess(j + 1, j)
        end do
        ! a J v that is not finite (a state whose forces overflow) gives no estimate: LAPACK's
        ! dgeev refuses a NaN through xerbla, which prints and stops the whole process
        if (.not. all(ieee_is_finite(self%hess(1:k + 1, 1:k)))) return
        allocate (wr(k), wi(k), work(8*k))
        ! dgeev balances H first (half its cost here): the Hessenberg QR alone (dhseqr),
        ! on an H this far from normal, moves the fast Ritz values' real parts
        call dgeev('N', 'N', k, self%hess, m + 1, wr, wi, dummy, 1, dummy, 1, work, 8*k, info)
        if (info /= 0) return
        ritz = cmplx(wr, wi, wp)
        ! largest modulus first
        order(1:k) = [(i, i = 1, k)]
        do i = 2, k
            j = i
            do while (j > 1)
                if (abs(ritz(order(j - 1))) >= abs(ritz(order(j)))) exit
                order(j - 1:j) = order([j, j - 1])
                j = j - 1
            end do
        end do
        ritz = ritz(order(1:k))
        ok = .true.
    end subroutine krylov_ritz_values

    !> Balance the band Jacobian by a diagonal similarity D^-1 J D (the same eigenvalues):
    !! each unknown's row and column (off the diagonal) brought to about the same size by
    !! powers of 2 (exact), as LAPACK's dgebal does for a dense matrix, until no scaling
    !! lowers the sum of their sizes by 5 %. A rope's J in first-order form, [0 I; A B] in
    !! m and m/s, becomes about [0 s I; A/s B], s of the order of the fast frequencies: near
    !! normal, so that Arnoldi's Ritz values lie near the spectrum.
    subroutine krylov_balance(self)
        class(krylov_t), intent(inout) :: self
        real(wp), parameter :: RADIX = 2.0_wp
        integer, parameter :: SWEEPS = 100
        real(wp) :: c, r, f, g, s
        integer :: n, i, j, sweep
        logical :: changed
        n = size(self%jb, 2)
        do sweep = 1, SWEEPS
            changed = .false.
            do i = 1, n
                c = 0.0_wp
                r = 0.0_wp
                do j = max(1, i - self%mu), min(n, i + self%ml)
                    if (j /= i) c = c + abs(self%jb(self%mu + 1 + j - i, i))   ! column i
                end do
                do j = max(1, i - self%ml), min(n, i + self%mu)
                    if (j /= i) r = r + abs(self%jb(self%mu + 1 + i - j, j))   ! row i
                end do
                if (c == 0.0_wp .or. r == 0.0_wp) cycle
                s = c + r
                f = 1.0_wp
                g = r/RADIX
                do while (c < g)
                    f = f*RADIX
                    c = c*RADIX*RADIX
                end do
                g = r*RADIX
                do while (c >= g)
                    f = f/RADIX
                    c = c/(RADIX*RADIX)
                end do
                ! (c now the column's size times f^2: (c + r)/f is the sum after scaling)
                if ((c + r)/f >= 0.95_wp*s) cycle
                call scale_unknown(self, i, f)
                changed = .true.
            end do
            if (.not. changed) exit
        end do
    end subroutine krylov_balance

    !> Column i of the band Jacobian times f, row i over f (D^-1 J D with d_i = f).
    subroutine scale_unknown(self, i, f)
        type(krylov_t), intent(inout) :: self
        integer, intent(in) :: i
        real(wp), intent(in) :: f
        integer :: n, j
        n = size(self%jb, 2)
        do j = max(1, i - self%mu), min(n, i + self%ml)
            self%jb(self%mu + 1 + j - i, i) = self%jb(self%mu + 1 + j - i, i)*f
        end do
        do j = max(1, i - self%ml), min(n, i + self%mu)
            self%jb(self%mu + 1 + i - j, j) = self%jb(self%mu + 1 + i - j, j)/f
        end do
    end subroutine scale_unknown

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
        fast = self%fast(FAST_FRACTION)
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
        fast = spec%fast(FAST_FRACTION)
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
