!> The two integrators on the paper's rope (n = 30, 2 s from 75 deg, Table 1 damping):
!! they must agree to within a few tolerances, and MEBDF must keep the energy balance.
program test_rope_solvers
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t
    use ropedyn_rope_model, only: energy_t
    use ropedyn_scene, only: scene_t, read_scene
    use ropedyn_rope_model, only: rope_model_t
    use ropedyn_integrator, only: integrator_t, solver_stats_t
    use ropedyn_model_factory, only: create_model
    use ropedyn_scene_solver, only: create_integrator, solver_options_of
    use ropedyn_assert, only: test_suite_t
    implicit none

    integer, parameter :: NOUT = 20
    real(wp), parameter :: RTOL = 1.0e-7_wp, T_END = 2.0_wp
    type(test_suite_t) :: suite
    real(wp), allocatable :: q_cvode(:, :), q_mebdf(:, :)
    real(wp) :: scale, diff, balance(2), e_initial
    character(len=120) :: label

    suite%name = 'rope_solvers'
    call compare('rfem', 30)
    call compare('mpp', 10)
    call suite%finish()

contains

    subroutine compare(kind, n)
        character(len=*), intent(in) :: kind
        integer, intent(in) :: n
        call run(kind, n, 'cvode', q_cvode, balance(1))
        call run(kind, n, 'mebdf', q_mebdf, balance(2))
        scale = maxval(abs(q_cvode))
        diff = maxval(abs(q_cvode - q_mebdf))
        write (label, '(a, i0, a, es9.2, a, f5.2, a)') 'paper rope, '//kind//', n = ', n, &
            ', 2 s: |q_cvode - q_mebdf| = ', diff, ' (', diff/(RTOL*scale), ' rtol max|q|)'
        call suite%check_le(diff, 5.0_wp*RTOL*scale, trim(label))
        call suite%check_le(abs(balance(1)), 10.0_wp*RTOL*abs(e_initial), kind// &
                            ': cvode energy balance |T + V + dissipated - E0| <= 10 rtol |E0| (J)')
        call suite%check_le(abs(balance(2)), 10.0_wp*RTOL*abs(e_initial), kind// &
                            ': mebdf energy balance |T + V + dissipated - E0| <= 10 rtol |E0| (J)')
    end subroutine compare

    subroutine run(kind, n, method, q, balance_error)
        character(len=*), intent(in) :: kind
        integer, intent(in) :: n
        character(len=*), intent(in) :: method
        real(wp), allocatable, intent(out) :: q(:, :)
        real(wp), intent(out) :: balance_error
        type(scene_t) :: scene
        class(rope_model_t), allocatable, target :: model
        class(integrator_t), allocatable :: integ
        type(error_t), allocatable :: err
        real(wp), allocatable :: y(:), yq(:)
        real(wp) :: t
        real(wp), allocatable :: qe(:, :), qdot(:, :)
        type(energy_t) :: e0, e
        character(len=80) :: sets(5)
        character(len=1024) :: source_dir
        integer :: j

        write (sets(1), '(a)') 'solver.method = "'//method//'"'
        write (sets(2), '(a, es10.3)') 'solver.rtol = ', RTOL
        sets(3) = 'solver.atol = 1e-10'
        write (sets(4), '(a, i0)') 'model.elements = ', n
        sets(5) = 'model.kind = "'//kind//'"'
        ! the source directory is the first argument (CTest passes it)
        call get_command_argument(1, source_dir)
        if (len_trim(source_dir) == 0) source_dir = '.'
        call read_scene(trim(source_dir)//'/input/paper.nml', sets, scene, err)
        if (.not. allocated(err)) call create_model(scene%rope_spec_t, model, err)
        if (.not. allocated(err)) call create_integrator(scene, integ, err)
        if (allocated(err)) then
            call suite%check_true(.false., method//': '//err%message)
            call suite%finish()
        end if
        allocate (y(model%size()), yq(model%quad_size()), q(3*model%n_elements(), NOUT))
        allocate (qe(3, model%n_elements()), qdot(3, model%n_elements()))
        call model%initial_state(y)
        yq = 0.0_wp
        t = 0.0_wp
        e0 = model%energy(t, y, yq)
        call integ%init(model, t, y, yq, solver_options_of(scene), err)
        do j = 1, NOUT
            if (.not. allocated(err)) call integ%advance_to(j*T_END/NOUT, t, y, yq, err)
            call model%fields(y, qe, qdot)
            q(:, j) = reshape(qe, [size(qe)])   ! positions and angles of all elements
        end do
        call suite%check_true(.not. allocated(err), method//' completes 2 s')
        e = model%energy(t, y, yq)
        balance_error = e%balance() - e0%balance()
        e_initial = e0%balance()
    end subroutine run
end program test_rope_solvers
