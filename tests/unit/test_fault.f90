!> The failure path of a non-finite right-hand side, below the executable:
!! - both rope models return STATUS_RECOVERABLE (not OK, not fatal) when their forces are
!!   NaN or Inf (rhs, quad_rhs, and the implicit form of the MPP);
!! - the testing aid (`&effects fault_nan_after`, ropedyn_effect_fault) leaves a model's
!!   right-hand side unchanged, bit for bit, before its time and makes the model return NaN
!!   forces with STATUS_RECOVERABLE after it;
!! - both integrators treat that as recoverable (cut the step), end the run soon after with
!!   ERR_SOLVER and a message naming the time, the step size and the cause, and return the
!!   last good (finite) state: no crawl to round-off steps until max_steps.
!! The end-to-end part (exit code 3, the HDF5 file marked failed) is tests/hard.
program test_fault
    use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, ieee_positive_inf, &
                                             ieee_is_nan, ieee_is_finite
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t, ERR_SOLVER
    use ropedyn_problem, only: STATUS_OK, STATUS_RECOVERABLE
    use ropedyn_scene, only: scene_t, read_scene
    use ropedyn_rope_model, only: rope_model_t
    use ropedyn_integrator, only: integrator_t, solver_stats_t
    use ropedyn_model_factory, only: create_model
    use ropedyn_scene_solver, only: create_integrator, solver_options_of
    use ropedyn_assert, only: test_suite_t
    implicit none

    type(test_suite_t) :: suite
    character(len=1024) :: source_dir

    suite%name = 'fault'
    call get_command_argument(1, source_dir)
    if (len_trim(source_dir) == 0) source_dir = '.'

    call test_model_status('rfem', 6)
    call test_model_status('mpp', 5)
    call test_fault_effect('rfem', 6)
    call test_fault_effect('mpp', 5)
    call test_integrator('rfem', 6, 'cvode')
    call test_integrator('rfem', 6, 'mebdf')
    call test_integrator('mpp', 5, 'cvode')
    call test_integrator('mpp', 5, 'mebdf')
    call suite%finish()

contains

    !> The paper's scene with `kind`, n elements and `method`; NaN forces after t_fault (s)
    !! when given (`&effects fault_nan_after`).
    subroutine make(kind, n, method, scene, model, t_fault)
        character(len=*), intent(in) :: kind, method
        integer, intent(in) :: n
        type(scene_t), intent(out) :: scene
        class(rope_model_t), allocatable, intent(out) :: model
        real(wp), intent(in), optional :: t_fault
        type(error_t), allocatable :: err
        character(len=64) :: sets(4)
        sets(1) = 'model.kind = "'//kind//'"'
        write (sets(2), '(a, i0)') 'model.elements = ', n
        sets(3) = 'solver.method = "'//method//'"'
        sets(4) = 'effects.fault_nan_after = -1'
        if (present(t_fault)) write (sets(4), '(a, es23.16)') 'effects.fault_nan_after = ', &
            t_fault
        call read_scene(trim(source_dir)//'/input/paper.nml', sets, scene, err)
        if (.not. allocated(err)) call create_model(scene%rope_spec_t, model, err)
        if (allocated(err)) then
            call suite%check_true(.false., kind//': '//err%message)
            call suite%finish()
        end if
    end subroutine make

    !> A state moved off the initial one (so that every force is non-zero).
    subroutine moving_state(model, y)
        class(rope_model_t), intent(in) :: model
        real(wp), allocatable, intent(out) :: y(:)
        integer :: i
        allocate (y(model%size()))
        call model%initial_state(y)
        do i = 1, size(y)
            y(i) = y(i) + 1.0e-3_wp*sin(real(i, wp))
        end do
    end subroutine moving_state

    subroutine test_model_status(kind, n)
        character(len=*), intent(in) :: kind
        integer, intent(in) :: n
        type(scene_t) :: scene
        class(rope_model_t), allocatable :: model
        real(wp), allocatable :: y(:), f(:), g(:)
        real(wp) :: bad(2)
        integer :: status, k
        character(len=3), parameter :: WHAT(2) = ['NaN', 'Inf']

        call make(kind, n, 'cvode', scene, model)
        call moving_state(model, y)
        allocate (f(size(y)), g(max(1, model%quad_size())))
        call model%rhs(0.0_wp, y, f, status)
        call suite%check_true(status == STATUS_OK .and. all(ieee_is_finite(f)), &
                              kind//': finite state: rhs status OK')
        bad = [ieee_value(1.0_wp, ieee_quiet_nan), ieee_value(1.0_wp, ieee_positive_inf)]
        do k = 1, 2
            y(2) = bad(k)
            call model%rhs(0.0_wp, y, f, status)
            call suite%check_true(status == STATUS_RECOVERABLE, kind//': '//WHAT(k)// &
                                  ' in the state: rhs returns STATUS_RECOVERABLE')
            call model%implicit_rhs(0.0_wp, y, f, status)
            call suite%check_true(status == STATUS_RECOVERABLE, kind//': '//WHAT(k)// &
                                  ' in the state: implicit_rhs returns STATUS_RECOVERABLE')
        end do
        ! a velocity that is NaN reaches the dissipation power
        call moving_state(model, y)
        y(size(y)) = bad(1)
        call model%quad_rhs(0.0_wp, y, g, status)
        call suite%check_true(status == STATUS_RECOVERABLE, kind// &
                              ': NaN velocity: quad_rhs returns STATUS_RECOVERABLE')
    end subroutine test_model_status

    subroutine test_fault_effect(kind, n)
        character(len=*), intent(in) :: kind
        integer, intent(in) :: n
        type(scene_t) :: scene
        class(rope_model_t), allocatable :: model, faulty
        real(wp), allocatable :: y(:), f(:), fw(:), jb(:, :), jbw(:, :)
        integer :: status, sw, ml, mu

        call make(kind, n, 'cvode', scene, model)
        call make(kind, n, 'cvode', scene, faulty, t_fault=0.5_wp)
        call moving_state(model, y)
        allocate (f(size(y)), fw(size(y)))
        call model%rhs(0.5_wp, y, f, status)
        call faulty%rhs(0.5_wp, y, fw, sw)
        call suite%check_true(sw == status .and. all(f == fw), &
                              kind//': fault: rhs unchanged, bit for bit, up to the fault time')
        if (model%has_jacobian()) then
            call model%bandwidths(ml, mu)
            allocate (jb(ml + mu + 1, size(y)), jbw(ml + mu + 1, size(y)))
            jb = 0.0_wp
            jbw = 0.0_wp
            call model%jacobian(0.5_wp, y, jb, mu + 1, status)
            call faulty%jacobian(0.5_wp, y, jbw, mu + 1, sw)
            call suite%check_true(sw == status .and. all(jb == jbw), &
                                  kind//': fault: Jacobian unchanged up to the fault time')
        end if
        call faulty%rhs(0.5_wp + 1.0e-9_wp, y, fw, sw)
        call suite%check_true(sw == STATUS_RECOVERABLE .and. any(ieee_is_nan(fw)), &
                              kind//': fault: NaN and STATUS_RECOVERABLE after the fault time')
        call faulty%implicit_rhs(0.6_wp, y, fw, sw)
        call suite%check_true(sw == STATUS_RECOVERABLE, &
                              kind//': fault: implicit_rhs STATUS_RECOVERABLE after it')
    end subroutine test_fault_effect

    !> Integrate with the fault at T_FAULT towards 2 T_FAULT: a clean, prompt failure.
    subroutine test_integrator(kind, n, method)
        character(len=*), intent(in) :: kind, method
        integer, intent(in) :: n
        real(wp), parameter :: T_FAULT = 0.05_wp
        type(scene_t) :: scene
        class(rope_model_t), allocatable, target :: model, faulty
        class(integrator_t), allocatable :: integ
        type(error_t), allocatable :: err
        type(solver_stats_t) :: stats, stats_clean
        real(wp), allocatable :: y(:), yq(:)
        real(wp) :: t
        character(len=:), allocatable :: label

        label = kind//' + '//method
        call make(kind, n, method, scene, model)
        call create_integrator(scene, integ, err)
        allocate (y(model%size()), yq(model%quad_size()))
        ! the run without a fault, for the step count up to T_FAULT
        call model%initial_state(y)
        yq = 0.0_wp
        call integ%init(model, 0.0_wp, y, yq, solver_options_of(scene), err)
        if (.not. allocated(err)) call integ%advance_to(T_FAULT, t, y, yq, err)
        call suite%check_true(.not. allocated(err), label//': runs without the fault')
        stats_clean = integ%stats()
        call integ%finalize()

        call make(kind, n, method, scene, faulty, t_fault=T_FAULT)
        call faulty%initial_state(y)
        yq = 0.0_wp
        call integ%init(faulty, 0.0_wp, y, yq, solver_options_of(scene), err)
        if (.not. allocated(err)) call integ%advance_to(2.0_wp*T_FAULT, t, y, yq, err)
        stats = integ%stats()
        call integ%finalize()
        call suite%check_true(allocated(err), label//': NaN after the fault time ends the run')
        if (.not. allocated(err)) return
        write (*, '(a)') '      message: '//err%message
        call suite%check_true(err%code == ERR_SOLVER, label//': class ERR_SOLVER (exit code 3)')
        call suite%check_contains(err%message, 't = ', label//': message names the time')
        call suite%check_contains(err%message, 'step size', label//': message names the step')
        call suite%check_contains(err%message, 'NaN', label//': message names the cause')
        call suite%check_le(abs(t - T_FAULT), 1.0e-9_wp, label// &
                            ': stops at the fault time (|t - t_fault|, s)')
        call suite%check_true(all(ieee_is_finite(y)) .and. all(ieee_is_finite(yq)), &
                              label//': returns the last good, finite state')
        call suite%check_le(real(stats%steps - stats_clean%steps, wp), 500.0_wp, label// &
                            ': steps after the fault time (no crawl towards round-off)')
    end subroutine test_integrator
end program test_fault
