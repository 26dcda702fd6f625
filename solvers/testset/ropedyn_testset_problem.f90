!> The common base of the stiff test problems of the Bari "Test Set for IVP Solvers"
!! (F. Mazzia, C. Magherini et al., release 2.3): what a test-set driver needs besides
!! y' = f(t, y) itself.
!!
!! A test-set problem knows its interval [t0, t_end], its initial value y0, the reference
!! solution yref at t_end (computed by the test-set authors in extended precision), the
!! absolute tolerance the test set recommends for a given rtol, and which accuracy measure
!! (scd or mescd) is meaningful for it. Every problem here has an analytic Jacobian: an
!! extension writes df/dy as a dense n x n matrix in `dense_jacobian`, and this base type
!! stores it in the band layout of `problem_t%jacobian` (dense band, ml = mu = n - 1).
!! The problems are autonomous and carry no quadrature variables.
module ropedyn_testset_problem
    use ropedyn_kinds, only: wp
    use ropedyn_problem, only: problem_t, STATUS_OK
    implicit none
    private
    public :: testset_problem_t

    type, abstract, extends(problem_t) :: testset_problem_t
        character(len=:), allocatable :: name   !< short upper-case name, e.g. 'HIRES'
        character(len=:), allocatable :: title  !< one-line description
        real(wp) :: t0 = 0.0_wp                 !< start of the interval
        real(wp) :: t_end = 0.0_wp              !< end of the interval (where yref holds)
        real(wp), allocatable :: y0(:)          !< initial value at t0
        real(wp), allocatable :: yref(:)        !< reference solution at t_end
        !> recommended atol = atol_per_rtol * rtol (all components) ...
        real(wp) :: atol_per_rtol = 1.0_wp
        !> ... unless atol_fixed > 0: then atol = atol_fixed whatever rtol is
        real(wp) :: atol_fixed = 0.0_wp
        !> the accuracy of this problem is judged by mescd, not scd (E5: yref is tiny or 0)
        logical :: use_mescd = .false.
    contains
        procedure(setup_i), deferred :: setup
        procedure(dense_jacobian_i), deferred :: dense_jacobian
        procedure :: size => testset_size
        procedure :: bandwidths => testset_bandwidths
        procedure :: has_jacobian => testset_has_jacobian, jacobian => testset_jacobian
        procedure :: recommended_atol => testset_recommended_atol, atol_rule => testset_atol_rule
    end type testset_problem_t

    abstract interface
        !> Fill name, title, interval, y0, yref and the tolerance rule.
        subroutine setup_i(self)
            import :: testset_problem_t
            class(testset_problem_t), intent(inout) :: self
        end subroutine setup_i

        !> dfdy(i, j) = d f_i / d y_j at (t, y), all n x n entries (zeros included).
        subroutine dense_jacobian_i(self, t, y, dfdy)
            import :: testset_problem_t, wp
            class(testset_problem_t), intent(in) :: self
            real(wp), intent(in) :: t
            real(wp), intent(in) :: y(:)
            real(wp), intent(out) :: dfdy(:, :)
        end subroutine dense_jacobian_i
    end interface

contains

    !> Number of equations (the size of y0).
    pure integer function testset_size(self) result(n)
        class(testset_problem_t), intent(in) :: self
        n = 0
        if (allocated(self%y0)) n = size(self%y0)
    end function testset_size

    !> Dense Jacobian written as a band: ml = mu = n - 1.
    pure subroutine testset_bandwidths(self, ml, mu)
        class(testset_problem_t), intent(in) :: self
        integer, intent(out) :: ml, mu
        ml = max(self%size() - 1, 0)
        mu = ml
    end subroutine testset_bandwidths

    !> Every test-set problem here has an analytic Jacobian.
    pure logical function testset_has_jacobian(self) result(has)
        class(testset_problem_t), intent(in) :: self
        has = .true.
    end function testset_has_jacobian

    !> Add the dense analytic Jacobian into band storage: (i, j) -> jb(offset + i - j, j).
    subroutine testset_jacobian(self, t, y, jb, offset, status)
        class(testset_problem_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(inout) :: jb(:, :)
        integer, intent(in) :: offset
        integer, intent(out) :: status
        real(wp) :: dfdy(size(y), size(y))
        integer :: i, j
        call self%dense_jacobian(t, y, dfdy)
        do j = 1, size(y)
            do i = 1, size(y)
                jb(offset + i - j, j) = jb(offset + i - j, j) + dfdy(i, j)
            end do
        end do
        status = STATUS_OK
    end subroutine testset_jacobian

    !> The absolute tolerance the test set recommends with relative tolerance rtol,
    !! one value per component.
    pure function testset_recommended_atol(self, rtol) result(atol)
        class(testset_problem_t), intent(in) :: self
        real(wp), intent(in) :: rtol
        real(wp) :: atol(self%size())
        if (self%atol_fixed > 0.0_wp) then
            atol = self%atol_fixed
        else
            atol = self%atol_per_rtol*rtol
        end if
    end function testset_recommended_atol

    !> The tolerance rule in words, e.g. 'atol = rtol', 'atol = 1e-06 rtol'.
    function testset_atol_rule(self) result(text)
        class(testset_problem_t), intent(in) :: self
        character(len=:), allocatable :: text
        character(len=32) :: buffer
        if (self%atol_fixed > 0.0_wp) then
            write (buffer, '(es8.1)') self%atol_fixed
            text = 'atol = '//trim(adjustl(buffer))
        else if (self%atol_per_rtol == 1.0_wp) then
            text = 'atol = rtol'
        else
            write (buffer, '(es8.1)') self%atol_per_rtol
            text = 'atol = '//trim(adjustl(buffer))//' rtol'
        end if
    end function testset_atol_rule
end module ropedyn_testset_problem
