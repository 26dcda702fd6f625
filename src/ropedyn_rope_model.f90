!> What every rope model offers beyond the generic problem: element data for output,
!! the initial state of a scene, and the mapping from the ODE state to element fields
!! and to the polyline used for drawing.
module ropedyn_rope_model
    use ropedyn_kinds, only: wp
    use ropedyn_problem, only: problem_t
    implicit none
    private
    public :: rope_model_t

    type, abstract, extends(problem_t) :: rope_model_t
    contains
        procedure(n_elements_i), deferred :: n_elements
        procedure(model_name_i), deferred :: model_name
        procedure(initial_state_i), deferred :: initial_state
        procedure(fields_i), deferred :: fields
        procedure(polyline_i), deferred :: polyline
        procedure(element_data_i), deferred :: element_data
    end type rope_model_t

    abstract interface
        !> Number of bodies (rigid elements or pendulum members).
        pure integer function n_elements_i(self)
            import :: rope_model_t
            class(rope_model_t), intent(in) :: self
        end function n_elements_i

        !> 'rfem' or 'mpp'.
        pure function model_name_i(self) result(name)
            import :: rope_model_t
            class(rope_model_t), intent(in) :: self
            character(len=:), allocatable :: name
        end function model_name_i

        !> The ODE state of the scene's initial configuration.
        subroutine initial_state_i(self, y)
            import :: rope_model_t, wp
            class(rope_model_t), intent(in) :: self
            real(wp), intent(out) :: y(:)
        end subroutine initial_state_i

        !> Element centre x, y (m), angle phi (rad) and their rates, shape (3, elements).
        subroutine fields_i(self, y, q, qdot)
            import :: rope_model_t, wp
            class(rope_model_t), intent(in) :: self
            real(wp), intent(in) :: y(:)
            real(wp), intent(out) :: q(:, :), qdot(:, :)
        end subroutine fields_i

        !> End points A_1, B_1, A_2, B_2, ... of the elements, shape (2, 2*elements), m.
        subroutine polyline_i(self, y, points)
            import :: rope_model_t, wp
            class(rope_model_t), intent(in) :: self
            real(wp), intent(in) :: y(:)
            real(wp), intent(out) :: points(:, :)
        end subroutine polyline_i

        !> Length (m) and mass (kg) of each element.
        subroutine element_data_i(self, length, mass)
            import :: rope_model_t, wp
            class(rope_model_t), intent(in) :: self
            real(wp), intent(out) :: length(:), mass(:)
        end subroutine element_data_i
    end interface
end module ropedyn_rope_model
