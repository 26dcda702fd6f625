!> The rope model a spec names: RFEM or MPP, built from the spec alone.
module ropedyn_model_factory
    use ropedyn_error, only: error_t, make_error, ERR_INPUT
    use ropedyn_rope_model, only: rope_model_t
    use ropedyn_rope_spec, only: rope_spec_t
    use ropedyn_rfem, only: rfem_t, rfem_create
    use ropedyn_mpp, only: mpp_t, mpp_create
    implicit none
    private
    public :: create_model

contains

    !> The model of `spec` (its values already checked by whoever filled it).
    subroutine create_model(spec, model, err)
        type(rope_spec_t), intent(in) :: spec
        class(rope_model_t), allocatable, intent(out) :: model
        type(error_t), allocatable, intent(out) :: err
        type(rfem_t), allocatable :: rfem
        type(mpp_t), allocatable :: mpp
        select case (spec%model%kind)
        case ('rfem')
            allocate (rfem)
            call rfem_create(rfem, spec, err)
            if (allocated(err)) return
            call move_alloc(rfem, model)
        case ('mpp')
            allocate (mpp)
            call mpp_create(mpp, spec, err)
            if (allocated(err)) return
            call move_alloc(mpp, model)
        case default
            call make_error(err, ERR_INPUT, spec%origin('model.kind')//': &model: kind = "'// &
                            trim(spec%model%kind)//'": not available in this version')
        end select
    end subroutine create_model
end module ropedyn_model_factory
