!> erk_stable_step (solvers/ropedyn_spectrum.f90), the explicit pair's stability-limited
!! step for a set of Ritz values, which auto uses to choose and to classify erk's steps:
!! - on the imaginary axis it is the pair's stability limit (tab%stability_limit, orders 3
!!   and 4) over |lambda|, to one sample of the scan (8 / radius / 2000);
!! - its scan of every 16th sample, then of the last stride, finds the same step as a scan
!!   of every sample, bitwise, for every bundled pair on single eigenvalues at angles 90 ..
!!   180 degrees and on random sets of fast eigenvalues (a stride would miss an unstable
!!   stretch shorter than 16 samples inside the region);
!! - Ritz values in the right half plane count as on the imaginary axis (else no step
!!   would be stable), and no estimate gives 0.
program test_stable_step
    use ropedyn_kinds, only: wp
    use ropedyn_erk_tables, only: erk_table_t, erk_table
    use ropedyn_spectrum, only: spectrum_t, erk_stable_step
    use ropedyn_assert, only: test_suite_t
    implicit none

    real(wp), parameter :: PI = 3.14159265358979323846_wp
    real(wp), parameter :: OMEGA = 1.0e3_wp   !< |lambda|, 1/s
    type(test_suite_t) :: suite
    type(erk_table_t) :: tab
    type(spectrum_t) :: spec
    integer :: order, deg, set, i, mismatches
    real(wp) :: h, angle, r(2, 5)
    character(len=60) :: label

    suite%name = 'stable_step'
    call random_seed(put=[(12345 + i, i = 1, 64)])
    do order = 3, 5
        tab = erk_table(order)
        write (label, '(a, i0)') 'pair of order ', order
        ! the imaginary axis: the pair's own limit, to one sample
        if (order < 5) then
            h = erk_stable_step(tab, one_value(cmplx(0.0_wp, OMEGA, wp)))
            call suite%check_le(h*OMEGA, tab%stability_limit, trim(label)//': i omega, not above')
            call suite%check_true(h*OMEGA > tab%stability_limit - 8.0_wp/2000, &
                                  trim(label)//': i omega, within one sample of the limit')
        end if
        ! the stride scan against the scan of every sample
        mismatches = 0
        do deg = 90, 180
            angle = deg*PI/180
            spec = one_value(OMEGA*cmplx(cos(angle), sin(angle), wp))
            if (erk_stable_step(tab, spec) /= full_scan(tab, spec)) mismatches = mismatches + 1
        end do
        do set = 1, 200
            call random_number(r)
            spec%ritz = [(OMEGA*(0.1_wp + 0.9_wp*r(1, i))* &
                          cmplx(cos(PI*(0.5_wp + 0.5_wp*r(2, i))), &
                                sin(PI*(0.5_wp + 0.5_wp*r(2, i))), wp), i = 1, 5)]
            spec%radius = maxval(abs(spec%ritz))
            if (erk_stable_step(tab, spec) /= full_scan(tab, spec)) mismatches = mismatches + 1
        end do
        call suite%check_true(mismatches == 0, trim(label)//': stride scan = full scan')
    end do
    ! right half plane as the axis; no estimate
    tab = erk_table(4)
    ! (the same radius for both: the scan's samples are fractions of 8 / radius)
    spec = one_value(cmplx(0.0_wp, OMEGA, wp))
    spec%radius = abs(cmplx(1.0e2_wp, OMEGA, wp))
    call suite%check_true(erk_stable_step(tab, one_value(cmplx(1.0e2_wp, OMEGA, wp))) == &
                          erk_stable_step(tab, spec), &
                          'right half plane counts as the imaginary axis')
    spec = one_value(cmplx(0.0_wp, OMEGA, wp))
    spec%valid = .false.
    call suite%check_true(erk_stable_step(tab, spec) == 0.0_wp, 'no estimate: 0')
    call suite%finish()

contains

    function one_value(lambda) result(sp)
        complex(wp), intent(in) :: lambda
        type(spectrum_t) :: sp
        sp%ritz = [lambda]
        sp%radius = abs(lambda)
        sp%valid = .true.
    end function one_value

    !> The step before the first unstable one of all 2000 samples up to 8 / radius.
    real(wp) function full_scan(tb, sp) result(hf)
        type(erk_table_t), intent(in) :: tb
        type(spectrum_t), intent(in) :: sp
        complex(wp), allocatable :: fast(:)
        real(wp) :: step
        integer :: k, j
        fast = pack(sp%ritz, abs(sp%ritz) >= 0.1_wp*sp%radius)
        where (real(fast, wp) > 0.0_wp) fast = cmplx(0.0_wp, aimag(fast), wp)
        step = 8.0_wp/sp%radius/2000
        hf = 0.0_wp
        do k = 1, 2000
            do j = 1, size(fast)
                if (tb%amplification(k*step*fast(j)) > 1.0_wp + 1.0e-12_wp) return
            end do
            hf = k*step
        end do
    end function full_scan
end program test_stable_step
