!> estimate_spectrum (solvers/ropedyn_spectrum.f90) against the exact spectrum: on the
!! paper's rope with 4, 10 and 30 elements (a run of 1 s from the release at 75 degrees,
!! a state every 0.1 s), the spectral radius and the damping ratio of the Ritz value of
!! largest modulus agree with those of the eigenvalue of largest modulus of the dense
!! Jacobian (LAPACK's dgeev, every eigenvalue) to 1e-3; and the fast modes' damping
!! (fast_damping, which picks auto's implicit method) is never read above the smallest
!! damping of the dense Jacobian's fast modes (|lambda| >= radius/10) by more than 1e-3:
!! the interior fast Ritz values have not converged after 24 steps, and an estimate that
!! trusted them would read those modes as more damped than they are (the settled Ritz
!! values alone give 0.04 at n = 30 where the modes go down to 0.01; docs/theory/auto.md). With 10 elements the Arnoldi
!! estimate on the Jacobian as it is put the radius at 2.5 .. 5.6e3 1/s, in the right half
!! plane, against 2.08e3 1/s damped by 0.03: the estimate again on the balanced Jacobian
!! is what this checks there.
program test_spectrum_estimate
    use ropedyn_kinds, only: wp
    use ropedyn_lapack, only: dgeev
    use ropedyn_spectrum, only: spectrum_t, estimate_spectrum
    use ropedyn_test_run, only: run_t, simulate
    use ropedyn_assert, only: test_suite_t
    implicit none
    integer, parameter :: ELEMENTS(3) = [4, 10, 30]
    type(test_suite_t) :: suite
    integer :: e

    suite%name = 'spectrum_estimate'
    do e = 1, size(ELEMENTS)
        call check_rope(ELEMENTS(e))
    end do
    call suite%finish()

contains

    !> Every record of a 1 s run of the paper's rope with `nel` elements: the estimate
    !! against the exact spectrum.
    subroutine check_rope(nel)
        integer, intent(in) :: nel
        type(run_t) :: run
        type(spectrum_t) :: spec
        complex(wp) :: exact
        real(wp) :: zeta_exact
        character(len=80) :: sets(1), label
        integer :: k
        write (sets(1), '(a, i0)') 'model.elements=', nel
        call simulate(sets, 1.0_wp, 0.1_wp, 1.0e-8_wp, run)
        call suite%check_true(run%ok, 'the run of the rope')
        if (.not. run%ok) return
        do k = 0, size(run%t) - 1
            exact = largest_eigenvalue(run, k, zeta_exact)
            call estimate_spectrum(run%model, run%t(k), run%y(:, k), spec)
            write (label, '(a, i0, a, f4.2, a)') 'n = ', nel, ', t = ', run%t(k), ' s: '
            call suite%check_true(spec%valid, trim(label)//' an estimate')
            if (.not. spec%valid) cycle
            call suite%check_close(spec%radius, abs(exact), 1.0e-3_wp, 0.0_wp, &
                                   trim(label)//' spectral radius')
            call suite%check_close(-real(spec%ritz(1), wp)/abs(spec%ritz(1)), &
                                   -real(exact, wp)/abs(exact), 0.0_wp, 1.0e-3_wp, &
                                   trim(label)//' its damping ratio')
            print '(a, 3(a, f7.4))', trim(label), ' fast damping: exact ', zeta_exact, &
                ', estimate ', spec%fast_damping, ', settled Ritz values ', spec%settled_damping()
            call suite%check_le(spec%fast_damping, zeta_exact + 1.0e-3_wp, &
                                trim(label)//' fast damping not above the exact')
        end do
    end subroutine check_rope

    !> The eigenvalue of largest modulus of the model's Jacobian at record k (dense), and
    !! the smallest damping ratio of the eigenvalues of at least a tenth of its modulus.
    complex(wp) function largest_eigenvalue(run, k, zeta) result(lambda)
        type(run_t), intent(inout) :: run
        integer, intent(in) :: k
        real(wp), intent(out) :: zeta
        real(wp), allocatable :: jb(:, :), a(:, :), wr(:), wi(:), work(:)
        real(wp) :: dummy(1, 1)
        integer :: n, ml, mu, i, j, status, info
        n = run%model%size()
        call run%model%bandwidths(ml, mu)
        ml = min(ml, n - 1)
        mu = min(mu, n - 1)
        allocate (jb(ml + mu + 1, n), a(n, n), wr(n), wi(n), work(8*n))
        jb = 0.0_wp
        call run%model%jacobian(run%t(k), run%y(:, k), jb, mu + 1, status)
        a = 0.0_wp
        do j = 1, n
            do i = max(1, j - mu), min(n, j + ml)
                a(i, j) = jb(mu + 1 + i - j, j)
            end do
        end do
        call dgeev('N', 'N', n, a, n, wr, wi, dummy, 1, dummy, 1, work, 8*n, info)
        lambda = (0.0_wp, 0.0_wp)
        zeta = 0.0_wp
        if (status /= 0 .or. info /= 0) return
        i = maxloc(hypot(wr, wi), 1)
        lambda = cmplx(wr(i), wi(i), wp)
        zeta = max(0.0_wp, minval(-wr/hypot(wr, wi), mask=hypot(wr, wi) >= 0.1_wp*abs(lambda)))
    end function largest_eigenvalue
end program test_spectrum_estimate
