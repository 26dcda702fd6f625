!> What a scene asks of the solvers: the integrator it names and the options it gives.
module ropedyn_scene_solver
    use ropedyn_kinds, only: i8
    use ropedyn_error, only: error_t, make_error, ERR_INPUT
    use ropedyn_integrator, only: integrator_t, solver_options_t, default_step_budget
    use ropedyn_solvers, only: new_integrator
    use ropedyn_scene_types, only: scene_t
    use ropedyn_rope_model, only: rope_model_t
    implicit none
    private
    public :: create_integrator, solver_options_of, step_budget, check_method_fits

contains

    !> The integrator a scene names (its error names the scene and &solver).
    subroutine create_integrator(scene, integrator, err)
        type(scene_t), intent(in) :: scene
        class(integrator_t), allocatable, intent(out) :: integrator
        type(error_t), allocatable, intent(out) :: err
        call new_integrator(trim(scene%solver%method), integrator, err)
        if (allocated(err)) err%message = scene%origin('solver.method')//': &solver: '// &
                                          err%message
    end subroutine create_integrator

    !> The method the scene names must be able to integrate its model at all (a method that
    !! cannot, such as the symplectic method for the MPP, is bad input of &solver method,
    !! reported before anything runs: a run before it touches its output, a sweep's cases
    !! when it is read; `integrator_t%refusal`).
    subroutine check_method_fits(scene, integrator, model, err)
        type(scene_t), intent(in) :: scene
        class(integrator_t), intent(in) :: integrator
        class(rope_model_t), intent(in) :: model
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: why
        why = integrator%refusal(model)
        if (len(why) == 0) return
        call make_error(err, ERR_INPUT, scene%origin('solver.method')//': &solver: method = "'// &
            trim(scene%solver%method)//'": cannot integrate the '//model%model_name()// &
            ' model of this scene: '//why//' (use method = "auto" or "erk"; '// &
            'docs/guide/choosing.md)')
    end subroutine check_method_fits

    !> The solver options of a scene's &solver group.
    pure function solver_options_of(scene) result(options)
        type(scene_t), intent(in) :: scene
        type(solver_options_t) :: options
        options%rtol = scene%solver%rtol
        options%atol = scene%solver%atol
        options%max_order = scene%solver%max_order
        options%max_steps = step_budget(scene)
        options%stab_lim_det = scene%solver%stability_limit_detection
        options%first_order_newton = scene%solver%first_order_newton
        options%profile = scene%solver%profile
        options%t_end = scene%solver%t_end
    end function solver_options_of

    !> The step budget of a run of the scene: its max_steps, or when that is 0 the default
    !! for its length (`default_step_budget` of t_end).
    pure integer(i8) function step_budget(scene) result(budget)
        type(scene_t), intent(in) :: scene
        budget = int(scene%solver%max_steps, i8)
        if (budget <= 0) budget = default_step_budget(scene%solver%t_end)
    end function step_budget
end module ropedyn_scene_solver
