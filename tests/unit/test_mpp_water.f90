!> The MPP in water against the RFEM and the continuum (docs/theory/mpp.md, "Water"): a
!! chain (section set, EI = 0, d = 2 cm, 1 kg/m) wholly under water, with the normal and
!! tangential added mass and buoyancy.
!! - A swing released straight at 30 degrees, 0.5 s (before the free end whips): the tips of
!!   the RFEM and the MPP at n = 40 stay within the sum of the two models' own
!!   discretization errors, each estimated by its change from n = 20 to n = 40 (a first-order
!!   estimate: the two models converge to the same rope, so they can differ by no more than
!!   both errors together), and their distance shrinks from n = 20 to n = 40; both runs keep
!!   T + V = E0 to 10 rtol of the largest kinetic energy.
!! - The lowest modes of the hanging chain: the heavy chain's omega_k = (j_{0,k}/2)
!!   sqrt(g_e/L) with g_e = g (m - rho A)/(m + m_an) (the buoyant weight moves the normal
!!   inertia m + m_an), the RFEM's at the same n, and the MPP's without the added mass
!!   lies far above.
program test_mpp_water
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t
    use ropedyn_scene, only: scene_t, read_scene
    use ropedyn_rope_model, only: rope_model_t, energy_t
    use ropedyn_model_factory, only: create_model
    use ropedyn_statics, only: statics_options_t, statics_result_t, find_equilibrium
    use ropedyn_modes, only: modes_result_t, compute_modes
    use ropedyn_test_run, only: run_t, simulate, kind_set, SET_LEN
    use ropedyn_assert, only: test_suite_t
    implicit none

    real(wp), parameter :: PI = acos(-1.0_wp), G = 9.81_wp, RTOL = 1.0e-8_wp
    !> the chain: mass per length (kg/m), water's density, the displaced area's water (kg/m)
    real(wp), parameter :: MASS = 1.0_wp, RHO = 1000.0_wp, RHO_A = RHO*PI*0.02_wp**2/4.0_wp
    !> zeros j_{0,k} of the Bessel function J0
    real(wp), parameter :: J0_ZEROS(3) = [2.404825557695773_wp, 5.520078110286311_wp, &
                                          8.653727912911013_wp]
    character(len=SET_LEN), parameter :: CHAIN(11) = [character(len=SET_LEN) :: &
        'rope.mass_per_length = 1.0', 'rope.axial_stiffness = 1e4', &
        'rope.bending_stiffness = 0', 'rope.diameter = 0.02', 'effects.water = .true.', &
        'fluid.density = 1000', 'fluid.surface = -0.1', 'fluid.added_mass_coefficient = 1.0', &
        'fluid.tangential_added_mass_coefficient = 0.2', 'initial.angle_deg = 30', &
        'solver.t_end = 0.5']
    type(test_suite_t) :: suite

    suite%name = 'mpp_water'
    call swing()
    call modes()
    call level('rfem')
    call level('mpp')
    call suite%finish()

contains

    !> The chain's swing with `kind` at n elements, recorded every 0.01 s.
    subroutine swing_run(kind, n, run)
        character(len=*), intent(in) :: kind
        integer, intent(in) :: n
        type(run_t), intent(out) :: run
        character(len=SET_LEN) :: sets(size(CHAIN) + 2)
        real(wp) :: worst, scale
        integer :: k
        sets(1:size(CHAIN)) = CHAIN
        sets(size(CHAIN) + 1) = kind_set(kind)
        write (sets(size(CHAIN) + 2), '(a, i0)') 'model.elements = ', n
        call simulate(sets, 0.5_wp, 0.01_wp, RTOL, run, scene_file='test_mpp_water.nml')
        call suite%check_true(run%ok, kind//': the swing in water completes '//run%message)
        if (.not. run%ok) return
        worst = 0.0_wp
        scale = 0.0_wp
        do k = 0, run%last()
            worst = max(worst, abs(run%e(k)%balance() - run%e(0)%balance()))
            scale = max(scale, run%e(k)%kinetic)
        end do
        write (*, '(a, i0, a, 2es11.3, a)') '  '//kind//' n = ', n, ': largest kinetic '// &
            'energy, balance error', scale, worst, ' J'
        call suite%check_le(worst, 10.0_wp*RTOL*scale, kind//': T + V = E0 in water to 10 '// &
                            'rtol of the largest kinetic energy')
    end subroutine swing_run

    !> The largest distance between the free tips of two runs, m.
    real(wp) function tip_distance(a, b) result(d)
        type(run_t), intent(in) :: a, b
        real(wp), allocatable :: pa(:, :), pb(:, :)
        integer :: k
        d = 0.0_wp
        do k = 0, min(a%last(), b%last())
            pa = a%points(k)
            pb = b%points(k)
            d = max(d, norm2(pa(:, size(pa, 2)) - pb(:, size(pb, 2))))
        end do
    end function tip_distance

    subroutine swing()
        type(run_t) :: mpp20, mpp40, rfem20, rfem40
        real(wp) :: d20, d40, e_mpp, e_rfem
        call swing_run('mpp', 20, mpp20)
        call swing_run('mpp', 40, mpp40)
        call swing_run('rfem', 20, rfem20)
        call swing_run('rfem', 40, rfem40)
        if (.not. (mpp20%ok .and. mpp40%ok .and. rfem20%ok .and. rfem40%ok)) return
        d20 = tip_distance(mpp20, rfem20)
        d40 = tip_distance(mpp40, rfem40)
        e_mpp = tip_distance(mpp20, mpp40)
        e_rfem = tip_distance(rfem20, rfem40)
        write (*, '(a, 4es11.3, a)') '  tips: rfem - mpp at n = 20, 40; mpp 20 - 40, '// &
            'rfem 20 - 40:', d20, d40, e_mpp, e_rfem, ' m'
        call suite%check_le(d40, e_mpp + e_rfem, 'rfem and mpp tips in water at n = 40 '// &
                            'within both models'' discretization errors')
        call suite%check_le(d40, 0.7_wp*d20, 'rfem and mpp tips in water: their distance '// &
                            'shrinks with the element length')
    end subroutine swing

    !> Equilibrium and the three lowest modes of `kind` at n = 40, hanging in water.
    subroutine modes_of(kind, added, omega)
        character(len=*), intent(in) :: kind
        logical, intent(in) :: added    !< with the added mass (else its coefficients 0)
        real(wp), intent(out) :: omega(3)
        type(scene_t) :: scene
        class(rope_model_t), allocatable :: model
        type(statics_result_t) :: sres
        type(modes_result_t) :: res
        type(error_t), allocatable :: err
        real(wp), allocatable :: y(:)
        character(len=SET_LEN) :: sets(size(CHAIN) + 4)
        integer :: unit
        sets(1:size(CHAIN)) = CHAIN
        sets(size(CHAIN) + 1) = kind_set(kind)
        sets(size(CHAIN) + 2) = 'model.elements = 40'
        sets(size(CHAIN) + 3) = 'initial.angle_deg = 0'
        sets(size(CHAIN) + 4) = 'fluid.added_mass_coefficient = 1.0'
        if (.not. added) sets(size(CHAIN) + 4) = 'fluid.added_mass_coefficient = 0'
        omega = 0.0_wp
        open (newunit=unit, file='test_mpp_water.nml', status='replace', action='write')
        write (unit, '(a)') '&model /'
        close (unit)
        call read_scene('test_mpp_water.nml', sets, scene, err)
        if (.not. allocated(err)) call create_model(scene%rope_spec_t, model, err)
        if (.not. allocated(err)) then
            allocate (y(model%size()))
            call model%initial_state(y)
            call find_equilibrium(model, scene%rope_spec_t, y, statics_options_t(), sres, err)
        end if
        if (.not. allocated(err)) call compute_modes(model, y, 3, res, err)
        call suite%check_true(.not. allocated(err), kind//': modes in water')
        if (allocated(err)) then
            print '(a)', err%message
            return
        end if
        omega = res%omega(1:3)
    end subroutine modes_of

    !> The model of the chain with `kind`, its surface at `surface`, and its energies at the
    !! straight start (wholly under water).
    function energies_at(kind, surface) result(e)
        character(len=*), intent(in) :: kind, surface
        type(energy_t) :: e
        character(len=SET_LEN) :: sets(size(CHAIN) + 2)
        type(scene_t) :: scene
        type(error_t), allocatable :: err
        class(rope_model_t), allocatable :: model
        real(wp), allocatable :: y(:)
        integer :: unit
        sets(1:size(CHAIN)) = CHAIN
        sets(size(CHAIN) + 1) = kind_set(kind)
        sets(size(CHAIN) + 2) = 'fluid.surface = '//surface
        open (newunit=unit, file='test_mpp_water.nml', status='replace', action='write')
        write (unit, '(a)') '&model /'
        close (unit)
        call read_scene('test_mpp_water.nml', sets, scene, err)
        if (.not. allocated(err)) call create_model(scene%rope_spec_t, model, err)
        call suite%check_true(.not. allocated(err), kind//': the chain at surface '//surface)
        if (allocated(err)) return
        allocate (y(model%size()))
        call model%initial_state(y)
        e = model%energy(0.0_wp, y, [0.0_wp])
    end function energies_at

    !> The buoyancy's potential is the level part of the elastic energy (energy_t%level,
    !! which the energy monitor counts by its range, as gravity): the chain wholly under water
    !! with its surface 0.1 m and 100.1 m above the top, the same state: the level part
    !! changes by the displaced water's weight times 100 m (rho g A L 100: the buoyancy's
    !! potential -rho g V x_c), the rest of the elastic energy not at all.
    subroutine level(kind)
        character(len=*), intent(in) :: kind
        type(energy_t) :: near, deep
        near = energies_at(kind, '-0.1')
        deep = energies_at(kind, '-100.1')
        call suite%check_close(deep%level - near%level, RHO_A*G*1.0_wp*100.0_wp, 1.0e-9_wp, &
                               0.0_wp, kind//': the level part grows with the depth')
        call suite%check_close(deep%elastic - deep%level, near%elastic - near%level, &
                               1.0e-12_wp, 1.0e-12_wp, kind//': the rest of elastic does not')
    end subroutine level

    subroutine modes()
        real(wp) :: mpp(3), rfem(3), bare(3), chain(3)
        integer :: k
        character(len=8) :: tag
        call modes_of('mpp', .true., mpp)
        call modes_of('rfem', .true., rfem)
        call modes_of('mpp', .false., bare)
        ! the heavy chain of length L = 1 m: buoyant weight, normal inertia with the added mass
        chain = 0.5_wp*J0_ZEROS*sqrt(G*(MASS - RHO_A)/(MASS + RHO_A))
        write (*, '(a, 3f11.6)') '  modes in water: mpp    ', mpp
        write (*, '(a, 3f11.6)') '                  rfem   ', rfem
        write (*, '(a, 3f11.6)') '                  chain  ', chain
        write (*, '(a, 3f11.6)') '  mpp without the added mass', bare
        do k = 1, 3
            write (tag, '(a, i0)') 'mode ', k
            ! the chain stretches by 3.4e-4 under its buoyant weight: omega -1.7e-4
            call suite%check_close(mpp(k), chain(k), merge(1.0e-3_wp, 2.0e-3_wp, k == 1), &
                                   0.0_wp, 'mpp in water: '//trim(tag)//' = heavy chain '// &
                                   'with buoyancy and added mass')
            call suite%check_close(mpp(k), rfem(k), 3.0e-4_wp, 0.0_wp, 'mpp in water: '// &
                                   trim(tag)//' = rfem''s at n = 40')
        end do
        call suite%check_true(bare(1) > 1.1_wp*mpp(1), 'mpp in water: the added mass lowers '// &
                              'omega_1 (by sqrt(m/(m + m_an)) = 0.87)')
    end subroutine modes
end program test_mpp_water
