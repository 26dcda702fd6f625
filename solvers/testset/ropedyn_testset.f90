!> The stiff test problems of the Bari "Test Set for IVP Solvers" (release 2.3) that
!! ropedyn carries, by name: the umbrella module of solvers/testset (docs/theory/testset.md).
module ropedyn_testset
    use ropedyn_error, only: error_t, make_error, ERR_INPUT
    use ropedyn_text, only: lower
    use ropedyn_testset_problem, only: testset_problem_t
    use ropedyn_testset_hires, only: hires_t
    use ropedyn_testset_vdpol, only: vdpol_t
    use ropedyn_testset_orego, only: orego_t
    use ropedyn_testset_rober, only: rober_t
    use ropedyn_testset_e5, only: e5_t
    use ropedyn_testset_pollu, only: pollu_t
    implicit none
    private
    public :: testset_problem_t, new_testset_problem, testset_names, testset_name_list

    !> Names of the available problems (as printed; the factory ignores case).
    character(len=*), parameter :: testset_names(6) = [character(len=5) :: &
        'HIRES', 'VDPOL', 'OREGO', 'ROBER', 'E5', 'POLLU']

contains

    !> A ready-to-use test problem of the given name (case-insensitive, e.g. 'hires').
    subroutine new_testset_problem(name, problem, err)
        character(len=*), intent(in) :: name
        class(testset_problem_t), allocatable, intent(out) :: problem
        type(error_t), allocatable, intent(out) :: err
        select case (lower(trim(adjustl(name))))
        case ('hires')
            allocate (hires_t :: problem)
        case ('vdpol')
            allocate (vdpol_t :: problem)
        case ('orego')
            allocate (orego_t :: problem)
        case ('rober')
            allocate (rober_t :: problem)
        case ('e5')
            allocate (e5_t :: problem)
        case ('pollu')
            allocate (pollu_t :: problem)
        case default
            call make_error(err, ERR_INPUT, 'unknown test problem "'//trim(name)// &
                            '" (available: '//testset_name_list()//')')
            return
        end select
        call problem%setup()
    end subroutine new_testset_problem

    !> 'HIRES, VDPOL, ...' for messages.
    pure function testset_name_list() result(list)
        character(len=:), allocatable :: list
        integer :: i
        list = trim(testset_names(1))
        do i = 2, size(testset_names)
            list = list//', '//trim(testset_names(i))
        end do
    end function testset_name_list
end module ropedyn_testset
