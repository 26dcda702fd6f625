!> What a scene asks of the solvers: the integrator it names and the options it gives.
module ropedyn_scene_solver
    use ropedyn_kinds, only: i8
    use ropedyn_error, only: error_t
    use ropedyn_integrator, only: integrator_t, solver_options_t, default_step_budget
    use ropedyn_solvers, only: new_integrator
    use ropedyn_scene_types, only: scene_t
    implicit none
    private
    public :: create_integrator, solver_options_of, step_budget

contains

    !> The integrator a scene names (its error names the scene and &solver).
    subroutine create_integrator(scene, integrator, err)
        type(scene_t), intent(in) :: scene
        class(integrator_t), allocatable, intent(out) :: integrator
        type(error_t), allocatable, intent(out) :: err
        call new_integrator(trim(scene%solver%method), integrator, err)
        if (allocated(err)) err%message = scene%path//': &solver: '//err%message
    end subroutine create_integrator

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
