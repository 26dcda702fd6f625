!> Runs one test-set problem with one integrator and measures what the integration
!! achieved and cost: scd and mescd at t_end against the reference solution, the
!! integrator's counters and the CPU time of one run (docs/theory/testset.md).
!!
!! Accuracy measures (Test Set for IVP Solvers, release 2.3):
!! - scd   = -log10 max_i |y_i - yref_i| / |yref_i|, over the components with
!!           |yref_i| >= 1e-200 (E5's y1 ~ 1e-290 and y4 = 0 are skipped);
!! - mescd = -log10 max_i |y_i - yref_i| / (atol_i/rtol + |yref_i|), all components.
!! CPU time: the whole integration (init, one advance_to from t0 to t_end, finalize) is
!! repeated until at least `repeat_time` seconds of CPU time have accumulated; the median
!! per-run time is reported. Counters and the solution are those of the first run.
module ropedyn_testset_driver
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t, make_error, ERR_INPUT, ERR_SOLVER
    use ropedyn_integrator, only: integrator_t, solver_options_t, solver_stats_t
    use ropedyn_solvers, only: new_integrator, method_order_range
    use ropedyn_methods, only: resolved_max_order, METHODS
    use ropedyn_testset_problem, only: testset_problem_t
    implicit none
    private
    public :: testset_run_t, run_testset, scd_of, mescd_of, median_of, methods_for
    public :: DEFAULT_REPEAT_TIME, MAX_REPEATS, SCD_MIN_REFERENCE

    real(wp), parameter :: DEFAULT_REPEAT_TIME = 0.5_wp  !< s of CPU time to accumulate
    integer, parameter :: MAX_REPEATS = 100000           !< cap on the timed repetitions
    !> components whose |yref| is below this are left out of scd
    real(wp), parameter :: SCD_MIN_REFERENCE = 1.0e-200_wp

    !> What one test run reports.
    type :: testset_run_t
        character(len=:), allocatable :: problem  !< problem name, e.g. 'HIRES'
        character(len=:), allocatable :: method   !< integrator, e.g. 'cvode'
        real(wp) :: rtol = 0.0_wp                 !< relative tolerance
        real(wp), allocatable :: atol(:)          !< absolute tolerance per component
        integer :: max_order = 0                  !< maximum order used (0 resolved)
        real(wp) :: scd = 0.0_wp                  !< significant correct digits
        real(wp) :: mescd = 0.0_wp                !< mixed-error significant correct digits
        logical :: use_mescd = .false.            !< mescd is this problem's measure
        type(solver_stats_t) :: stats             !< counters of the first run
        real(wp) :: cpu_time = 0.0_wp             !< median CPU time of one run, s
        integer :: runs = 0                       !< timed runs
        real(wp) :: t_reached = 0.0_wp            !< time reached by the first run
        real(wp), allocatable :: y(:)             !< solution at t_end (first run)
    contains
        procedure :: accuracy => run_accuracy
        procedure :: uniform_atol => run_uniform_atol
    end type testset_run_t

contains

    !> Integrate `problem` from t0 to t_end with `method` and measure scd, mescd, counters
    !! and CPU time. `atol` (scalar) replaces the problem's recommended atol; `max_order`
    !! 0 or absent means the method's default; `repeat_time` (s, default 0.5) is the CPU
    !! time to accumulate for the timing, 0 for a single run.
    !! Errors: ERR_INPUT for bad tolerances, orders or methods; ERR_SOLVER when the
    !! integration fails (the message then carries the integrator's).
    subroutine run_testset(problem, method, rtol, result, err, atol, max_order, repeat_time)
        class(testset_problem_t), intent(inout), target :: problem
        character(len=*), intent(in) :: method
        real(wp), intent(in) :: rtol
        type(testset_run_t), intent(out) :: result
        type(error_t), allocatable, intent(out) :: err
        real(wp), intent(in), optional :: atol
        integer, intent(in), optional :: max_order
        real(wp), intent(in), optional :: repeat_time
        type(solver_options_t) :: options
        real(wp) :: budget
        character(len=120) :: buffer

        result%problem = problem%name
        result%method = method
        result%rtol = rtol
        result%use_mescd = problem%use_mescd
        call check_settings(problem, method, rtol, result, budget, err, atol, max_order, &
                            repeat_time)
        if (allocated(err)) return
        options%rtol = rtol
        if (result%uniform_atol()) then
            options%atol = result%atol(1)
        else
            options%atol = minval(result%atol)
            options%atol_vector = result%atol
        end if
        options%max_order = result%max_order
        write (buffer, '(a, a, a, a, a, es9.2)') 'testset ', problem%name, ', method ', &
            method, ', rtol', rtol
        call repeat_runs(problem, method, options, budget, trim(buffer), result, err)
    end subroutine run_testset

    !> The settings checked into the result: rtol, atol (the problem's recommendation when
    !! not given), the maximum order within the method's range, the CPU budget of repeats.
    subroutine check_settings(problem, method, rtol, result, budget, err, atol, max_order, &
                              repeat_time)
        class(testset_problem_t), intent(in) :: problem
        character(len=*), intent(in) :: method
        real(wp), intent(in) :: rtol
        type(testset_run_t), intent(inout) :: result
        real(wp), intent(out) :: budget
        type(error_t), allocatable, intent(out) :: err
        real(wp), intent(in), optional :: atol
        integer, intent(in), optional :: max_order
        real(wp), intent(in), optional :: repeat_time
        character(len=120) :: buffer
        integer :: lowest, highest
        budget = DEFAULT_REPEAT_TIME
        if (.not. (rtol > 0.0_wp .and. rtol < 1.0_wp)) then
            write (buffer, '(es12.4)') rtol
            call make_error(err, ERR_INPUT, 'rtol = '//trim(adjustl(buffer))// &
                            ': must be > 0 and < 1')
            return
        end if
        if (present(atol)) then
            if (.not. (atol > 0.0_wp .and. atol < huge(atol))) then
                write (buffer, '(es12.4)') atol
                call make_error(err, ERR_INPUT, 'atol = '//trim(adjustl(buffer))// &
                                ': must be > 0')
                return
            end if
            allocate (result%atol(problem%size()), source=atol)
        else
            result%atol = problem%recommended_atol(rtol)
        end if
        if (present(repeat_time)) budget = repeat_time
        if (.not. (budget >= 0.0_wp)) then
            call make_error(err, ERR_INPUT, 'repeat time must be >= 0 s')
            return
        end if
        call method_order_range(method, lowest, highest, err)
        if (allocated(err)) return
        result%max_order = resolved_max_order(method, 0)
        if (.not. present(max_order)) return
        if (max_order == 0) return
        if (max_order < lowest .or. max_order > highest) then
            write (buffer, '(a, i0, a, a, a, i0, a, i0, a)') 'max order ', max_order, &
                ' not available for method ', method, ' (', lowest, ' .. ', &
                highest, ', or 0 for the default)'
            call make_error(err, ERR_INPUT, trim(buffer))
            return
        end if
        result%max_order = max_order
    end subroutine check_settings

    !> The problem integrated from its start again and again until the runs' CPU reaches
    !! `budget` (or MAX_REPEATS runs): the first run's statistics, end state and accuracy,
    !! the median CPU time. A failed run is an ERR_SOLVER error in `context`; a method that
    !! refuses the problem (`integrator_t%refusal`) an ERR_INPUT error.
    subroutine repeat_runs(problem, method, options, budget, context, result, err)
        class(testset_problem_t), intent(inout), target :: problem
        character(len=*), intent(in) :: method, context
        type(solver_options_t), intent(in) :: options
        real(wp), intent(in) :: budget
        type(testset_run_t), intent(inout) :: result
        type(error_t), allocatable, intent(out) :: err
        class(integrator_t), allocatable :: integrator
        type(error_t), allocatable :: run_err
        real(wp), allocatable :: y(:), times(:), grown(:)
        real(wp) :: yq(0), t, start, finish, total
        character(len=:), allocatable :: why
        call new_integrator(method, integrator, err)
        if (allocated(err)) return
        ! a method that cannot integrate the problem at all is a bad argument, as in a scene
        why = integrator%refusal(problem)
        if (len(why) > 0) then
            call make_error(err, ERR_INPUT, 'method '//method//' cannot integrate test '// &
                            'problem '//problem%name//': '//why)
            return
        end if
        allocate (y(problem%size()), times(16))
        total = 0.0_wp
        do
            y = problem%y0
            call cpu_time(start)
            call integrator%init(problem, problem%t0, y, yq, options, run_err)
            if (.not. allocated(run_err)) then
                call integrator%advance_to(problem%t_end, t, y, yq, run_err)
            end if
            if (result%runs == 0) then
                result%stats = integrator%stats()
                result%t_reached = t
            end if
            call integrator%finalize()
            call cpu_time(finish)
            if (allocated(run_err)) then
                call make_error(err, ERR_SOLVER, context//': '//run_err%message)
                return
            end if
            result%runs = result%runs + 1
            if (result%runs > size(times)) then
                allocate (grown(2*size(times)))
                grown(1:size(times)) = times
                call move_alloc(grown, times)
            end if
            times(result%runs) = max(finish - start, 0.0_wp)
            if (result%runs == 1) then
                result%y = y
                result%scd = scd_of(y, problem%yref)
                result%mescd = mescd_of(y, problem%yref, result%atol, options%rtol)
            end if
            total = total + times(result%runs)
            if (total >= budget .or. result%runs >= MAX_REPEATS) exit
        end do
        result%cpu_time = median_of(times(1:result%runs))
    end subroutine repeat_runs

    !> The accuracy measure of this problem: mescd for E5, scd otherwise.
    pure real(wp) function run_accuracy(self) result(digits)
        class(testset_run_t), intent(in) :: self
        if (self%use_mescd) then
            digits = self%mescd
        else
            digits = self%scd
        end if
    end function run_accuracy

    !> True when all components have the same atol.
    pure logical function run_uniform_atol(self) result(uniform)
        class(testset_run_t), intent(in) :: self
        uniform = .true.
        if (allocated(self%atol)) then
            if (size(self%atol) > 0) uniform = all(self%atol == self%atol(1))
        end if
    end function run_uniform_atol

    !> scd = -log10 max_i |y_i - yref_i| / |yref_i| over |yref_i| >= 1e-200.
    pure real(wp) function scd_of(y, yref) result(scd)
        real(wp), intent(in) :: y(:)
        real(wp), intent(in) :: yref(:)
        real(wp) :: worst
        integer :: i
        worst = 0.0_wp
        do i = 1, size(y)
            if (abs(yref(i)) >= SCD_MIN_REFERENCE) then
                worst = max(worst, abs(y(i) - yref(i))/abs(yref(i)))
            end if
        end do
        scd = -log10(max(worst, tiny(worst)))
    end function scd_of

    !> mescd = -log10 max_i |y_i - yref_i| / (atol_i/rtol + |yref_i|).
    pure real(wp) function mescd_of(y, yref, atol, rtol) result(mescd)
        real(wp), intent(in) :: y(:)
        real(wp), intent(in) :: yref(:)
        real(wp), intent(in) :: atol(:)
        real(wp), intent(in) :: rtol
        real(wp) :: worst
        worst = maxval(abs(y - yref)/(atol/rtol + abs(yref)))
        mescd = -log10(max(worst, tiny(worst)))
    end function mescd_of

    !> Median of a sample (mean of the two middle values for an even count).
    pure real(wp) function median_of(values) result(m)
        real(wp), intent(in) :: values(:)
        real(wp) :: v(size(values))
        integer :: n
        n = size(values)
        m = 0.0_wp
        if (n == 0) return
        v = values
        call heap_sort(v)
        if (mod(n, 2) == 1) then
            m = v((n + 1)/2)
        else
            m = 0.5_wp*(v(n/2) + v(n/2 + 1))
        end if
    end function median_of

    !> Sort ascending in place (heap sort: O(n log n) for the up to MAX_REPEATS samples).
    pure subroutine heap_sort(v)
        real(wp), intent(inout) :: v(:)
        real(wp) :: swap
        integer :: n, i
        n = size(v)
        do i = n/2, 1, -1
            call sift_down(v, i, n)
        end do
        do i = n, 2, -1
            swap = v(1)
            v(1) = v(i)
            v(i) = swap
            call sift_down(v, 1, i - 1)
        end do
    end subroutine heap_sort

    !> Restore the max-heap property below node `root` of v(1:last).
    pure subroutine sift_down(v, root, last)
        real(wp), intent(inout) :: v(:)
        integer, intent(in) :: root, last
        real(wp) :: swap
        integer :: parent, child
        parent = root
        do
            child = 2*parent
            if (child > last) exit
            if (child < last) then
                if (v(child + 1) > v(child)) child = child + 1
            end if
            if (v(parent) >= v(child)) exit
            swap = v(parent)
            v(parent) = v(child)
            v(child) = swap
            parent = child
        end do
    end subroutine sift_down

    !> 'cvode, mebdf, ...': the methods of the method table that integrate `problem` (whose
    !! integrator does not refuse it; the symplectic method needs a rope's force split).
    function methods_for(problem) result(list)
        class(testset_problem_t), intent(in) :: problem
        character(len=:), allocatable :: list
        class(integrator_t), allocatable :: integrator
        type(error_t), allocatable :: err
        integer :: k
        list = ''
        do k = 1, size(METHODS)
            call new_integrator(trim(METHODS(k)%name), integrator, err)
            if (allocated(err)) cycle
            if (len(integrator%refusal(problem)) > 0) cycle
            if (len(list) > 0) list = list//', '
            list = list//trim(METHODS(k)%name)
        end do
    end function methods_for
end module ropedyn_testset_driver
