!> The start of a run from a record of an earlier run's file (`&initial shape = 'state'`,
!! docs/guide/output.md "Starting from a record"): its time, the model's ODE state and the
!! quadratures.
module ropedyn_state_start
    use ropedyn_kinds, only: wp
    use ropedyn_text, only: real_text, int_text
    use ropedyn_error, only: error_t, make_error, ERR_INPUT
    use ropedyn_rope_model, only: rope_model_t
    use ropedyn_scene, only: scene_t
    use ropedyn_state_record, only: state_record_t, read_state_record
    implicit none
    private
    public :: state_initial_state, check_state_start

contains

    !> Whether the record `&initial shape = 'state'` names can start a run of the scene's
    !! `model` (the checks of `state_initial_state`, without taking the state): a sweep asks
    !! it of every case before anything runs.
    subroutine check_state_start(scene, model, err)
        type(scene_t), intent(in) :: scene
        class(rope_model_t), intent(in) :: model
        type(error_t), allocatable, intent(out) :: err
        type(state_record_t) :: rec
        call read_start_record(scene, model, rec, err)
    end subroutine check_state_start

    !> The record of `state_file` nearest `state_time` (the last for < 0), checked: a run
    !! of the same model kind and number of elements, before t_end.
    subroutine read_start_record(scene, model, rec, err)
        type(scene_t), intent(in) :: scene
        class(rope_model_t), intent(in) :: model
        type(state_record_t), intent(out) :: rec
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: where
        where = start_where(scene)
        call read_state_record(trim(scene%initial%state_file), scene%initial%state_time, &
                               rec, err)
        if (allocated(err)) then
            err%message = where//', state_time = '//real_text(scene%initial%state_time)// &
                          ': '//err%message
            return
        end if
        if (rec%model /= model%model_name() .or. rec%n /= model%n_elements()) then
            call make_error(err, ERR_INPUT, where//': the file holds a run of the '//rec%model// &
                ' model with '//int_text(rec%n)//' elements; the scene is '// &
                model%model_name()//' with '//int_text(model%n_elements())// &
                ' (&model kind, elements must match)')
            return
        end if
        if (.not. rec%t < scene%solver%t_end) then
            call make_error(err, ERR_INPUT, where//': its record '//int_text(rec%record)// &
                ' is at t = '//real_text(rec%t)//' s, not before &solver t_end = '// &
                real_text(scene%solver%t_end)//' s')
        end if
    end subroutine read_start_record

    !> 'SCENE: &initial: state_file = "FILE"', where the messages of the start begin.
    pure function start_where(scene) result(where)
        type(scene_t), intent(in) :: scene
        character(len=:), allocatable :: where
        where = scene%origin('initial.state_file')//': &initial: state_file = "'// &
                trim(scene%initial%state_file)//'"'
    end function start_where

    !> The start of `&initial shape = 'state'`: the record of `state_file` nearest
    !! `state_time` (the last for < 0) gives the time t, the model's ODE state y (stored, or
    !! rebuilt from the element fields) and the quadratures yq (dissipated energy, external
    !! work). The file must hold a run of the same model kind and number of elements.
    subroutine state_initial_state(scene, model, t, y, yq, err)
        type(scene_t), intent(in) :: scene
        class(rope_model_t), intent(in) :: model
        real(wp), intent(out) :: t
        real(wp), intent(inout) :: y(:), yq(:)
        type(error_t), allocatable, intent(out) :: err
        type(state_record_t) :: rec
        logical :: ok
        integer :: nq

        t = 0.0_wp
        call read_start_record(scene, model, rec, err)
        if (allocated(err)) return
        nq = model%quad_size()
        ok = .false.
        if (allocated(rec%y)) then
            ! the native state (restart data), when its sizes are the model's
            if (size(rec%y) == size(y) .and. size(rec%yq) >= nq) then
                y = rec%y
                yq(1:nq) = rec%yq(1:nq)
                ok = .true.
            end if
        end if
        if (.not. ok) then
            call model%state_from_fields(rec%q, rec%qdot, rec%t, y, ok)
            if (.not. ok) then
                call make_error(err, ERR_INPUT, start_where(scene)//': the '// &
                    model%model_name()//' model cannot rebuild its state from the stored fields')
                return
            end if
            if (nq >= 1) yq(1) = rec%dissipated
            if (nq >= 2) yq(2) = rec%support_work
        end if
        t = rec%t
    end subroutine state_initial_state
end module ropedyn_state_start
