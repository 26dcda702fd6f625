!> `ropedyn run SCENE.nml [--set group.key=value ...]`: run one scene, print its summary.
module ropedyn_cmd_run
    use, intrinsic :: iso_fortran_env, only: output_unit
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t
    use ropedyn_cli, only: cli_t
    use ropedyn_text, only: text_t, append_text, text_array
    use ropedyn_scene, only: scene_t, read_scene
    use ropedyn_simulation, only: run_summary_t, run_scene
    use ropedyn_version, only: version_string
    implicit none
    private
    public :: run_command, run_usage

contains

    subroutine run_usage(unit)
        integer, intent(in) :: unit
        write (unit, '(a)') 'usage: ropedyn run SCENE.nml [--set group.key=value ...]'
        write (unit, '(a)') 'Integrates the scene and writes its HDF5 file (&output file); '// &
            'prints a summary.'
        write (unit, '(a)') '  --set group.key=value   override a key of the scene file '// &
            '(repeatable)'
        write (unit, '(a)') 'exit codes: 0 ok, 2 bad input, 3 integration failed, '// &
            '4 output error'
        write (unit, '(a)') 'input reference: docs/input.md'
    end subroutine run_usage

    subroutine run_command(cli, err)
        type(cli_t), intent(inout) :: cli
        type(error_t), allocatable, intent(out) :: err
        type(text_t), allocatable :: overrides(:)
        character(len=:), allocatable :: scene_path, value
        type(scene_t) :: scene
        type(run_summary_t) :: summary

        allocate (overrides(0))
        do while (cli%next())
            select case (cli%option)
            case ('--help', '-h')
                call run_usage(output_unit)
                return
            case ('--set')
                call cli%take_value(value, err)
                if (allocated(err)) return
                call append_text(overrides, value)
            case default
                call cli%positional('scene file', scene_path, err)
                if (allocated(err)) return
            end select
        end do
        if (.not. allocated(scene_path)) then
            call cli%usage_error('needs a scene file', err)
            return
        end if

        call read_scene(scene_path, text_array(overrides), scene, err)
        if (allocated(err)) return
        call run_scene(scene, summary, err)
        if (summary%records > 0) call print_summary(scene, summary)
    end subroutine run_command

    subroutine print_summary(scene, s)
        type(scene_t), intent(in) :: scene
        type(run_summary_t), intent(in) :: s
        real(wp) :: e0, drift
        e0 = s%initial_energy%balance()
        drift = s%final_energy%balance() - e0
        write (output_unit, '(a)') 'ropedyn '//version_string//': '//trim(scene%model%kind)// &
            ' model, '//trim(scene%solver%method)//' solver, scene '//scene%path
        write (output_unit, '(a, i0, a, es10.3, a, f9.4, a)') '  elements        ', &
            scene%model%elements, '   rtol ', scene%solver%rtol, '   t = ', s%t_reached, ' s'
        write (output_unit, '(a, i0, a, i0, a, i0, a, i0)') '  steps           ', &
            s%stats%steps, '   rhs evals ', s%stats%rhs_evals, '   jacobians ', &
            s%stats%jac_evals, '   error-test fails ', s%stats%err_test_fails
        write (output_unit, '(a, f10.4, a)') '  cpu time        ', s%cpu_time, ' s'
        write (output_unit, '(a, i0, a)') '  newton          '// &
            trim(merge('reduced (second-order) matrix', 'first-order matrix           ', &
                       s%stats%reduced_newton))//', ', s%stats%lin_setups, ' factorizations'
        if (scene%solver%profile) write (output_unit, '(a, 5(a, f9.4))') &
            '  time split (s) ', ' rhs ', s%stats%time_rhs, '  jacobian ', s%stats%time_jac, &
            '  factor ', s%stats%time_factor, '  solve ', s%stats%time_solve, '  rest ', &
            s%stats%time_advance - (s%stats%time_rhs + s%stats%time_jac + &
                                    s%stats%time_factor + s%stats%time_solve)
        write (output_unit, '(a, 5(es13.5))') '  energy (J)      kinetic, elastic, '// &
            'gravity, dissipated, total:'
        write (output_unit, '(a, 5(es13.5))') '                  ', s%final_energy%kinetic, &
            s%final_energy%elastic, s%final_energy%gravity, s%final_energy%dissipated, &
            s%final_energy%total()
        write (output_unit, '(a, es13.5, a, es10.2, a)') '  E0              ', e0, &
            ' J   balance error (T+V+dissipated-E0) ', drift, ' J'
        if (s%order_lowered_at >= 0.0_wp) write (output_unit, &
            '(a, es10.3, a, es10.3, a, i0, a, i0, a, f9.4, a)') &
            '  order safety    energy gain ', s%energy_gain, ' J > bound ', &
            s%energy_gain_bound, ' J: max order ', s%order_before, ' -> ', s%order_after, &
            ' from t = ', s%order_lowered_at, ' s'
        if (s%gain_unresolved_at >= 0.0_wp) write (output_unit, '(a, es10.3, a, f9.4, a)') &
            '  order safety    energy gain ', s%energy_gain, ' J above the bound at t = ', &
            s%gain_unresolved_at, ' s at the safe order (not an order instability)'
        write (output_unit, '(a)') '  output          '//s%file
    end subroutine print_summary
end module ropedyn_cmd_run
