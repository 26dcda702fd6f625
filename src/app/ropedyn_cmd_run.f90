!> `ropedyn run SCENE.nml [--set group.key=value ...]`: run one scene, print its summary.
module ropedyn_cmd_run
    use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
    use ropedyn_kinds, only: wp, i8
    use ropedyn_text, only: int_text, fixed_text, significant_text
    use ropedyn_switch_log, only: switch_event_t
    use ropedyn_error, only: error_t, make_error, ERR_INPUT, ERR_INTERRUPTED
    use ropedyn_cli, only: cli_t
    use ropedyn_help, only: print_help
    use ropedyn_scene, only: scene_t, read_scene, read_scene_text
    use ropedyn_case_file, only: case_data_t, read_case_file
    use ropedyn_h5, only: held_open
    use ropedyn_simulation, only: run_summary_t, run_scene
    use ropedyn_scene_warnings, only: print_warnings
    use ropedyn_version, only: version_string
    use ropedyn_integrator, only: budget_covering
    use ropedyn_scene_solver, only: step_budget
    implicit none
    private
    public :: run_command

contains

    subroutine run_command(cli, err)
        type(cli_t), intent(inout) :: cli
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: resume_path, file
        type(scene_t) :: scene
        type(run_summary_t) :: summary
        logical :: verbose, force

        verbose = .false.
        force = .false.
        do while (cli%next())
            select case (cli%option)
            case ('--help', '-h')
                call cli%flag(err)
                if (allocated(err)) return
                call print_help('run', output_unit)
                return
            case ('--verbose', '-v')
                call cli%flag(err)
                verbose = .true.
            case ('--force')
                call cli%flag(err)
                force = .true.
            case ('--resume')
                if (allocated(resume_path)) then
                    call cli%usage_error('--resume is given twice', err)
                else
                    call cli%take_value(resume_path, err)
                end if
            case default
                call cli%scene_argument(err)
            end select
            if (allocated(err)) return
        end do
        if (allocated(resume_path)) then
            if (force) then
                call cli%usage_error('--force does not apply to --resume (a resume continues '// &
                                     'FILE.h5 in place)', err)
                return
            end if
            if (allocated(cli%scene_path)) then
                call cli%usage_error('--resume takes the scene from FILE.h5: give no scene '// &
                                     'file ('//cli%scene_path//')', err)
                return
            end if
            call resume_scene(resume_path, cli%scene_overrides(), scene, err)
            if (allocated(err)) return
            call print_warnings(scene)
            call run_scene(scene, summary, err, resume=.true.)
        else
            call cli%require(cli%scene_path, 'a scene file', err)
            if (allocated(err)) return
            call read_scene(cli%scene_path, cli%scene_overrides(), scene, err)
            if (allocated(err)) return
            call print_warnings(scene)
            call run_scene(scene, summary, err, force=force)
        end if
        if (summary%records > 0) call print_summary(scene, summary, verbose)
        if (allocated(err)) then
            ! (the file now: a resumed FILE.part may have been renamed to FILE)
            file = trim(scene%output%file)
            if (allocated(resume_path) .and. len(summary%file) > 0) file = summary%file
            if (err%code == ERR_INTERRUPTED) err%message = err%message// &
                '; continue with: ropedyn run --resume '//file
            if (summary%budget_rest > 0 .and. summary%records > 0) &
                err%message = err%message//resume_hint(file, scene, summary)
        end if
    end subroutine run_command

    !> How to go on after a run ended for its step budget: a resume, which has a budget of
    !! its own, larger when the rest of the run takes more steps than max_steps.
    function resume_hint(file, scene, summary) result(text)
        character(len=*), intent(in) :: file
        type(scene_t), intent(in) :: scene
        type(run_summary_t), intent(in) :: summary
        character(len=:), allocatable :: text
        character(len=16) :: since
        if (summary%passed_through >= 0.0_wp) then
            ! the torn line's loose end holds the step: more steps go on with a line that is
            ! no longer physical
            write (since, '(f16.3)') summary%passed_through
            text = '; the line passed through itself from t = '//trim(adjustl(since))// &
                   ' s on (its warning above), and its loose end holds the step: a resume '// &
                   'would not help. Give the line axial_damping, or let it push '// &
                   '(compression = .true.), and run it again'
            return
        end if
        text = '; continue with: ropedyn run --resume '//file
        if (summary%budget_rest <= step_budget(scene)) return
        if (budget_covering(summary%budget_rest) > huge(1)) then
            ! (max_steps is a default integer)
            text = '; no step budget covers that (solver.max_steps is at most '// &
                int_text(huge(1))//'): loosen solver.rtol and atol, or use another method '// &
                '(docs/guide/choosing.md)'
        else
            text = text//' --set solver.max_steps='//int_text(budget_covering(summary%budget_rest))
        end if
    end function resume_hint

    !> The scene of the run file `path` (its `scene` attribute) with `overrides`, its output
    !! going to `path` again.
    subroutine resume_scene(path, overrides, scene, err)
        character(len=*), intent(in) :: path
        character(len=*), intent(in) :: overrides(:)
        type(scene_t), intent(out) :: scene
        type(error_t), allocatable, intent(out) :: err
        type(case_data_t) :: data
        integer :: k
        logical :: there
        do k = 1, size(overrides)
            if (index(overrides(k), 'output.file') == 1) then
                call make_error(err, ERR_INPUT, '--set '//trim(overrides(k))//': --resume '// &
                                'appends to '//path//'; output.file cannot be set')
                return
            end if
        end do
        call read_case_file(path, data, err)
        if (allocated(err)) then
            ! (a file another process holds open stays an output error, as a live lock)
            if (held_open(err)) return
            err%code = ERR_INPUT   ! not a run file: bad input of --resume
            err%message = err%message//' (--resume needs a ropedyn run file)'
            return
        end if
        if (.not. data%exists) then
            call make_error(err, ERR_INPUT, path//': no such file (--resume)')
            inquire (file=path//'.part', exist=there)
            if (there) err%message = err%message//'; '//path//'.part is there, the file '// &
                'of a run of '//path//' that did not end (killed, or still going on): '// &
                'ropedyn run --resume '//path//'.part continues it'
            return
        end if
        if (len(data%scene) == 0) then
            call make_error(err, ERR_INPUT, path//': no scene attribute: not a ropedyn run file')
            return
        end if
        call read_scene_text(path//': scene', data%scene, overrides, scene, err)
        if (allocated(err)) return
        if (len(path) > len(scene%output%file)) then
            call make_error(err, ERR_INPUT, path//': the file name is too long (--resume)')
            return
        end if
        scene%output%file = path
    end subroutine resume_scene

    !> The summary of a run: what ran, its cost, the methods it used, its energies and how
    !! well they balance, the peak tension, the order safety's actions, the file. Counters that did not
    !! apply (no implicit step: no Jacobians, factorizations; no differenced Jacobian: the
    !! f evaluations they took) are left out. With `verbose` every switch of method or order
    !! on a line of its own.
    subroutine print_summary(scene, s, verbose)
        type(scene_t), intent(in) :: scene
        type(run_summary_t), intent(in) :: s
        logical, intent(in) :: verbose
        character(len=:), allocatable :: line
        integer :: k
        write (output_unit, '(a)') 'ropedyn '//version_string//': '//trim(scene%model%kind)// &
            ' model, '//trim(scene%solver%method)//' solver, scene '//scene%path
        write (output_unit, '(a, i0, a, es10.3, a, f9.4, a)') '  elements        ', &
            scene%model%elements, '   rtol ', scene%solver%rtol, '   t = ', s%t_reached, ' s'
        line = '  steps           '//int_text(s%stats%steps)//'   rhs evals '// &
            int_text(s%stats%rhs_evals)
        ! f evaluations of differenced Jacobians are not among the rhs evals (as in the
        ! testset's summary, ropedyn_cmd_testset)
        if (s%stats%jac_rhs_evals > 0) line = line//' (+ '//int_text(s%stats%jac_rhs_evals)// &
            ' for Jacobian differencing)'
        if (s%stats%jac_evals > 0) line = line//'   jacobians '//int_text(s%stats%jac_evals)
        if (s%stats%err_test_fails > 0) line = line//'   error-test fails '// &
            int_text(s%stats%err_test_fails)
        write (output_unit, '(a)') line
        write (output_unit, '(a, f10.4, a)') '  cpu time        ', s%cpu_time, ' s'
        if (s%stats%lin_setups > 0) write (output_unit, '(a, i0, a)') '  newton          '// &
            trim(merge('reduced (second-order) matrix', 'first-order matrix           ', &
                       s%stats%reduced_newton))//', ', s%stats%lin_setups, ' factorizations'
        if (scene%solver%profile) write (output_unit, '(a, 5(a, f9.4))') &
            '  time split (s) ', ' rhs ', s%stats%time_rhs, '  jacobian ', s%stats%time_jac, &
            '  factor ', s%stats%time_factor, '  solve ', s%stats%time_solve, '  rest ', &
            s%stats%time_advance - (s%stats%time_rhs + s%stats%time_jac + &
                                    s%stats%time_factor + s%stats%time_solve)
        call print_switches(scene, s, verbose)
        call print_energies(s)
        if (allocated(s%warnings)) then
            do k = 1, size(s%warnings)
                write (error_unit, '(a)') 'ropedyn: warning: '//s%warnings(k)%s
            end do
        end if
        if (s%peak_joint >= 0) write (output_unit, '(a, es12.5, a)') '  peak tension   ', &
            s%peak_tension, ' N at joint '//int_text(s%peak_joint)//' ('// &
            fixed_text(s%peak_arc, 4)//' m from the top), t = '//fixed_text(s%peak_time, 4)//' s'
        call print_safety(s)
        write (output_unit, '(a)') '  output          '//s%file
    end subroutine print_summary

    !> The energies at the end and the balance: every term it sums named, in J and in units
    !! of m g L (the rope's weight times its length) when there is gravity.
    subroutine print_energies(s)
        type(run_summary_t), intent(in) :: s
        character(len=16) :: number
        character(len=:), allocatable :: terms
        real(wp) :: e0, balance
        e0 = s%initial_energy%balance()
        balance = s%final_energy%balance() - e0
        write (output_unit, '(a)') '  energy (J)      kinetic, elastic, gravity, dissipated, '// &
            'external work:'
        write (output_unit, '(a, 5(es13.5))') '                  ', s%final_energy%kinetic, &
            s%final_energy%elastic, s%final_energy%gravity, s%final_energy%dissipated, &
            s%final_energy%support_work
        write (output_unit, '(a, es13.5, a)') '  E0              ', e0, ' J'
        write (number, '(es10.2)') balance
        terms = ' = kinetic + elastic + gravity + dissipated - work - E0'
        if (s%weight_length > 0.0_wp) then
            write (output_unit, '(a, es9.2, a)') '  balance error   '//trim(adjustl(number))// &
                ' J (', balance/s%weight_length, ' m g L)'//terms
        else
            write (output_unit, '(a)') '  balance error   '//trim(adjustl(number))//' J'//terms
        end if
    end subroutine print_energies

    !> What the order safety did, a line for each kind of action.
    subroutine print_safety(s)
        type(run_summary_t), intent(in) :: s
        character(len=:), allocatable :: why
        associate (r => s%safety)
            if (r%lowered_at >= 0.0_wp) write (output_unit, &
                '(a, es10.3, a, es10.3, a, i0, a, i0, a, f9.4, a)') &
                '  order safety    energy gain ', r%energy_gain, ' J > bound ', &
                r%energy_gain_bound, ' J: max order ', r%order_before, ' -> ', r%order_after, &
                ' from t = ', r%lowered_at, ' s'
            why = ' s at the safe order (not an order instability)'
            if (r%orderless) why = ' s: the method has no order to lower'
            if (r%unresolved_at >= 0.0_wp) write (output_unit, '(a, es10.3, a, f9.4, a)') &
                '  order safety    energy gain ', r%energy_gain, ' J above the bound at t = ', &
                r%unresolved_at, why
            if (r%kept_at >= 0.0_wp) write (output_unit, '(a, es10.3, a, f9.4, a)') &
                '  order safety    energy gain ', r%energy_gain, ' J above the bound at t = ', &
                r%kept_at, ' s: '//r%kept_reason//'; the order kept ('// &
                times_text(r%kept_count)//')'
        end associate
    end subroutine print_safety

    !> 'once', 'twice', 'n times'.
    pure function times_text(n) result(text)
        integer, intent(in) :: n
        character(len=:), allocatable :: text
        select case (n)
        case (1)
            text = 'once'
        case (2)
            text = 'twice'
        case default
            text = int_text(n)//' times'
        end select
    end function times_text

    !> The methods the run used, as one line: 'auto: erk 4 -> erk 5 -> erk 4 (2 switches)';
    !! with `verbose` each switch on a line with its time and reason. The switches that are
    !! warnings (a crawl cured by a lower order) also go to stderr, once.
    subroutine print_switches(scene, s, verbose)
        type(scene_t), intent(in) :: scene
        type(run_summary_t), intent(in) :: s
        logical, intent(in) :: verbose
        integer :: k
        character(len=80) :: head
        if (.not. allocated(s%switches)) return
        if (size(s%switches) == 0) return
        if (verbose) then
            do k = 1, size(s%switches)
                associate (e => s%switches(k))
                    write (head, '(a, f10.4, a, i0, a)') '  switch  t = ', e%t, ' s  '// &
                        trim(e%method)//' (max order ', e%max_order, ')'
                    write (output_unit, '(a)') trim(head)//': '//e%reason
                end associate
            end do
        else
            write (output_unit, '(a)') '  methods         '//trim(scene%solver%method)//': '// &
                method_chain(s%switches)
        end if
        do k = 1, size(s%switches)
            if (s%switches(k)%warning) write (error_unit, '(a, f10.4, a)') &
                'ropedyn: warning: at t = ', s%switches(k)%t, ' s: '//s%switches(k)%reason
        end do
    end subroutine print_switches

    !> 'erk 4 -> erk 5 -> erk 4 (2 switches; ropedyn run -v lists them)': the method and
    !! order limit in use after each event that changed them (an event that keeps both, such
    !! as the symplectic method's new step, is listed by -v only); of a long chain the
    !! first three and the last.
    pure function method_chain(events) result(text)
        type(switch_event_t), intent(in) :: events(:)
        character(len=:), allocatable :: text
        integer, parameter :: MOST = 5
        character(len=40) :: labels(size(events))
        integer :: k, n
        n = 1
        labels(1) = label(events(1))
        do k = 2, size(events)
            if (label(events(k)) == labels(n)) cycle
            n = n + 1
            labels(n) = label(events(k))
        end do
        text = trim(labels(1))
        do k = 2, n
            if (n > MOST .and. k > 3 .and. k < n) then
                if (k == 4) text = text//' -> ...'
                cycle
            end if
            text = text//' -> '//trim(labels(k))
        end do
        if (n == 2) text = text//' (1 switch; ropedyn run -v lists it)'
        if (n > 2) text = text//' ('//int_text(n - 1)//' switches; ropedyn run -v lists them)'
        if (n == 1 .and. size(events) > 1) text = text//' (ropedyn run -v lists its events)'
    contains
        pure function label(e) result(t)
            type(switch_event_t), intent(in) :: e
            character(len=:), allocatable :: t
            t = trim(e%method)//' '//int_text(e%max_order)
        end function label
    end function method_chain
end module ropedyn_cmd_run
