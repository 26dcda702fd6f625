!> The reduced second-order Newton path against the first-order one (issue 14): both
!! integrators, both rope models, the paper scene (n = 10) and a clamped top shaken
!! harmonically, a few hundred steps each. The two solutions must agree to the tolerance:
!! against a reference (CVODE, first-order path, rtol 1e-11) the reduced path's error must
!! not exceed three times the first-order path's plus 10 rtol max|q|. (CVODE's global error
!! on the shaken rope is 6 to 20 rtol max|q| depending on rounding alone - Debug or Release
!! build, either path - so the two paths may differ by more than a few rtol while both are
!! equally accurate.) The iteration must converge as well as on the first-order matrix: a
!! wrong reduced matrix or solve shows as many more Newton iterations and convergence
!! failures per step.
program test_newton_paths
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t
    use ropedyn_scene, only: scene_t, read_scene
    use ropedyn_rope_model, only: rope_model_t
    use ropedyn_integrator, only: integrator_t, solver_stats_t, solver_options_t
    use ropedyn_model_factory, only: create_model
    use ropedyn_scene_solver, only: create_integrator, solver_options_of
    use ropedyn_assert, only: test_suite_t
    implicit none

    real(wp), parameter :: RTOL = 1.0e-7_wp, T_END = 0.3_wp
    integer, parameter :: NOUT = 10
    type(test_suite_t) :: suite
    character(len=1024) :: source_dir
    character(len=64), parameter :: PAPER(1) = [character(len=64) :: 'model.elements = 10']
    character(len=64), parameter :: SHAKEN(6) = [character(len=64) :: &
        'model.elements = 10', 'supports.top = "clamped"', 'supports.top_motion = "harmonic"', &
        'supports.top_amplitude = 0.02, 0.05', 'supports.top_frequency = 3.0', &
        'initial.angle_deg = 20']
    !> the shaken rope half in water (buoyancy, added mass, the wetted part's drag)
    character(len=64), parameter :: WET(11) = [character(len=64) :: SHAKEN, &
        'effects.water = .true.', 'fluid.density = 1000', 'fluid.surface = 0.5', &
        'fluid.added_mass_coefficient = 1.0', 'fluid.tangential_added_mass_coefficient = 0.3']
    character(len=8), parameter :: MODELS(2) = [character(len=8) :: 'rfem', 'mpp']
    character(len=8), parameter :: SOLVERS(2) = [character(len=8) :: 'cvode', 'mebdf']
    integer :: im, is
    real(wp), allocatable :: ref_paper(:, :), ref_shaken(:, :), ref_wet(:, :)

    suite%name = 'newton_paths'
    call get_command_argument(1, source_dir)
    if (len_trim(source_dir) == 0) source_dir = '.'
    do im = 1, size(MODELS)
        call reference(PAPER, trim(MODELS(im)), ref_paper)
        call reference(SHAKEN, trim(MODELS(im)), ref_shaken)
        call reference(WET, trim(MODELS(im)), ref_wet)
        do is = 1, size(SOLVERS)
            call compare('paper', PAPER, trim(MODELS(im)), trim(SOLVERS(is)), ref_paper)
            call compare('shaken clamped top', SHAKEN, trim(MODELS(im)), trim(SOLVERS(is)), &
                         ref_shaken)
            call compare('shaken, half in water', WET, trim(MODELS(im)), trim(SOLVERS(is)), &
                         ref_wet)
        end do
    end do
    call suite%finish()

contains

    !> The reference solution of a scene: CVODE, first-order path, rtol 1e-11.
    subroutine reference(sets, kind, q)
        character(len=*), intent(in) :: sets(:), kind
        real(wp), allocatable, intent(out) :: q(:, :)
        type(solver_stats_t) :: stats
        call run(sets, kind, 'cvode', T_END, .true., q, stats, 1.0e-11_wp)
    end subroutine reference

    subroutine compare(scene_name, sets, kind, method, q_ref)
        character(len=*), intent(in) :: scene_name, sets(:), kind, method
        real(wp), intent(in) :: q_ref(:, :)
        real(wp), allocatable :: q_red(:, :), q_first(:, :)
        type(solver_stats_t) :: s_red, s_first
        real(wp) :: err_red, err_first, scale, iters_red, iters_first
        character(len=160) :: label, what

        what = scene_name//', '//kind//', '//method
        call run(sets, kind, method, T_END, .false., q_red, s_red)
        call run(sets, kind, method, T_END, .true., q_first, s_first)
        call suite%check_true(s_red%reduced_newton, trim(what)//': reduced path used')
        call suite%check_true(.not. s_first%reduced_newton, &
                              trim(what)//': first-order path used on request')
        call suite%check_le(real(100, wp), real(s_red%steps, wp), &
                            trim(what)//': at least 100 steps')
        scale = maxval(abs(q_ref))
        err_red = maxval(abs(q_red - q_ref))
        err_first = maxval(abs(q_first - q_ref))
        write (label, '(2(a, f6.2), a)') ': error (rtol max|q|) reduced ', err_red/(RTOL*scale), &
            ' <= 3 x first order ', err_first/(RTOL*scale), ' + 10'
        call suite%check_le(err_red, 3.0_wp*err_first + 10.0_wp*RTOL*scale, &
                            trim(what)//trim(label))
        iters_red = real(s_red%nonlin_iters, wp)/real(s_red%steps, wp)
        iters_first = real(s_first%nonlin_iters, wp)/real(s_first%steps, wp)
        write (label, '(a, f6.3, a, f6.3)') ': Newton iterations per step, reduced ', &
            iters_red, ' <= 1.1 x first order ', iters_first
        call suite%check_le(iters_red, 1.1_wp*iters_first, trim(what)//trim(label))
        write (label, '(a, i0, a, i0)') ': Newton convergence failures, reduced ', &
            s_red%nonlin_conv_fails, ' <= first order + 2: ', s_first%nonlin_conv_fails
        call suite%check_le(real(s_red%nonlin_conv_fails, wp), &
                            real(s_first%nonlin_conv_fails + 2, wp), trim(what)//trim(label))
        write (label, '(a, i0, a, i0)') ': steps, reduced ', s_red%steps, &
            ' within 10 % of first order ', s_first%steps
        call suite%check_le(abs(real(s_red%steps - s_first%steps, wp)), &
                            0.1_wp*real(s_first%steps, wp), trim(what)//trim(label))
    end subroutine compare

    subroutine run(sets, kind, method, t_end, first_order, q, stats, rtol_run)
        character(len=*), intent(in) :: sets(:), kind, method
        real(wp), intent(in) :: t_end
        logical, intent(in) :: first_order
        real(wp), intent(in), optional :: rtol_run    !< default RTOL
        real(wp), allocatable, intent(out) :: q(:, :)
        type(solver_stats_t), intent(out) :: stats
        type(scene_t) :: scene
        class(rope_model_t), allocatable, target :: model
        class(integrator_t), allocatable :: integ
        type(error_t), allocatable :: err
        type(solver_options_t) :: options
        real(wp), allocatable :: y(:), yq(:), qe(:, :), qdot(:, :)
        real(wp) :: t
        character(len=64) :: all_sets(size(sets) + 4)
        integer :: j

        all_sets(1) = 'solver.method = "'//method//'"'
        write (all_sets(2), '(a, es10.3)') 'solver.rtol = ', RTOL
        if (present(rtol_run)) write (all_sets(2), '(a, es10.3)') 'solver.rtol = ', rtol_run
        all_sets(3) = 'solver.atol = 1e-10'
        all_sets(4) = 'model.kind = "'//kind//'"'
        all_sets(5:) = sets
        call read_scene(trim(source_dir)//'/input/paper.nml', all_sets, scene, err)
        if (.not. allocated(err)) call create_model(scene%rope_spec_t, model, err)
        if (.not. allocated(err)) call create_integrator(scene, integ, err)
        if (allocated(err)) then
            call suite%check_true(.false., kind//', '//method//': '//err%message)
            call suite%finish()
        end if
        allocate (y(model%size()), yq(model%quad_size()), q(3*model%n_elements(), NOUT))
        allocate (qe(3, model%n_elements()), qdot(3, model%n_elements()))
        call model%initial_state(y)
        yq = 0.0_wp
        t = 0.0_wp
        options = solver_options_of(scene)
        options%first_order_newton = first_order
        call integ%init(model, t, y, yq, options, err)
        do j = 1, NOUT
            if (.not. allocated(err)) call integ%advance_to(j*t_end/NOUT, t, y, yq, err)
            call model%fields(y, qe, qdot, t)
            q(:, j) = reshape(qe, [size(qe)])
        end do
        call suite%check_true(.not. allocated(err), kind//', '//method//' completes')
        stats = integ%stats()
        call integ%finalize()
    end subroutine run
end program test_newton_paths
