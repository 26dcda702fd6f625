!> Runs a scene for the physics tests through the public path a user's run takes: a scene
!! file plus `--set` overrides (`read_scene`), the model of its spec (`create_model`), the
!! initial state with statics or a mode when the scene asks for it
!! (`equilibrium_initial_state`), and an integrator, recording every `dt`.
!!
!! The scene starts from the defaults (the paper's rope); `sets` are overrides of the form
!! 'group.key=value'. Records: time, state, energies; helpers give the polyline and the
!! centre of mass of a record.
module ropedyn_test_run
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t
    use ropedyn_rope_model, only: rope_model_t, energy_t
    use ropedyn_scene, only: scene_t, read_scene
    use ropedyn_model_factory, only: create_model
    use ropedyn_modes, only: equilibrium_initial_state
    use ropedyn_integrator, only: integrator_t, solver_options_t
    use ropedyn_solvers, only: new_integrator
    use ropedyn_assert, only: test_suite_t
    implicit none
    private
    public :: run_t, simulate, completed, kind_set, SET_LEN

    integer, parameter :: SET_LEN = 80   !< length of one override text

    !> One run: output times, states, quadratures and energies of each record.
    type :: run_t
        real(wp), allocatable :: t(:)           !< s, records 0 .. last
        real(wp), allocatable :: y(:, :)        !< states (size, 0:last)
        real(wp), allocatable :: yq(:, :)       !< quadratures (size, 0:last)
        type(energy_t), allocatable :: e(:)     !< energies
        class(rope_model_t), allocatable :: model
        type(scene_t) :: scene
        logical :: ok = .false.                 !< the run completed
        character(len=:), allocatable :: message  !< why not
    contains
        procedure :: last => run_last
        procedure :: points => run_points
        procedure :: centre_of_mass => run_centre_of_mass
    end type run_t

contains

    !> Read the scene (defaults plus `sets`), build its model and initial state, integrate
    !! it to `t_end` with `method` ('cvode' by default) at `rtol` (atol = rtol/100 unless
    !! given), recording every `dt`. `scene_file` names the scratch scene file (default
    !! 'test_run_<program>.nml' in the working directory, one per test program, since CTest
    !! runs them side by side in one directory; a relative motion table is found beside it).
    !! `y0`, when given, replaces the initial state.
    subroutine simulate(sets, t_end, dt, rtol, run, method, atol, scene_file, y0)
        character(len=*), intent(in) :: sets(:)
        real(wp), intent(in) :: t_end, dt, rtol
        type(run_t), intent(out) :: run
        character(len=*), intent(in), optional :: method, scene_file
        real(wp), intent(in), optional :: atol
        real(wp), intent(in), optional :: y0(:)
        type(error_t), allocatable :: err
        class(integrator_t), allocatable :: solver
        type(solver_options_t) :: options
        real(wp), allocatable :: y(:), yq(:)
        real(wp) :: t
        integer :: k, nout, unit
        character(len=:), allocatable :: path, name
        character(len=256) :: exe

        call get_command_argument(0, exe)
        path = 'test_run_'//trim(exe(index(exe, '/', back=.true.) + 1:))//'.nml'
        if (present(scene_file)) path = scene_file
        name = 'cvode'
        if (present(method)) name = method
        open (newunit=unit, file=path, status='replace', action='write')
        write (unit, '(a)') '&model /'
        close (unit)
        call read_scene(path, sets, run%scene, err)
        if (.not. allocated(err)) call create_model(run%scene%rope_spec_t, run%model, err)
        if (.not. allocated(err)) then
            allocate (y(run%model%size()), yq(run%model%quad_size()))
            call run%model%initial_state(y)
            call equilibrium_initial_state(run%model, run%scene%rope_spec_t, y, err)
            if (present(y0)) y = y0
        end if
        if (.not. allocated(err)) call new_integrator(name, solver, err)
        if (allocated(err)) then
            run%message = 'setup: '//err%message
            return
        end if
        yq = 0.0_wp
        options%rtol = rtol
        options%atol = 1.0e-2_wp*rtol
        if (present(atol)) options%atol = atol
        call solver%init(run%model, 0.0_wp, y, yq, options, err)
        if (allocated(err)) then
            run%message = 'init: '//err%message
            return
        end if
        nout = nint(t_end/dt)
        allocate (run%t(0:nout), run%y(size(y), 0:nout), run%yq(size(yq), 0:nout), &
                  run%e(0:nout))
        run%t(0) = 0.0_wp
        run%y(:, 0) = y
        run%yq(:, 0) = yq
        run%e(0) = run%model%energy(0.0_wp, y, yq)
        do k = 1, nout
            call solver%advance_to(real(k, wp)*dt, t, y, yq, err)
            if (allocated(err)) then
                run%message = 'integration: '//err%message
                return
            end if
            run%t(k) = t
            run%y(:, k) = y
            run%yq(:, k) = yq
            run%e(k) = run%model%energy(t, y, yq)
        end do
        call solver%finalize()
        run%ok = .true.
        run%message = ''
    end subroutine simulate

    !> 'model.kind=<kind>' (built apart: gfortran mis-sizes a concatenation inside a typed
    !! character array constructor).
    function kind_set(kind) result(set)
        character(len=*), intent(in) :: kind
        character(len=SET_LEN) :: set
        set = 'model.kind='//kind
    end function kind_set

    !> Whether the run completed, recorded as a check of the suite (with the reason if not).
    logical function completed(suite, run, label)
        type(test_suite_t), intent(inout) :: suite
        type(run_t), intent(in) :: run
        character(len=*), intent(in) :: label
        completed = run%ok
        call suite%check_true(run%ok, label//': run completes '//run%message)
    end function completed

    !> Index of the last record.
    pure integer function run_last(self)
        class(run_t), intent(in) :: self
        run_last = ubound(self%t, 1)
    end function run_last

    !> The element end points A_1, B_1, A_2, ... of record k, (2, 2 n), m.
    function run_points(self, k) result(points)
        class(run_t), intent(in) :: self
        integer, intent(in) :: k
        real(wp), allocatable :: points(:, :)
        allocate (points(2, 2*self%model%n_elements()))
        call self%model%polyline(self%y(:, k), points, self%t(k))
    end function run_points

    !> Centre of mass (x, y) of record k from the element centres and the masses that
    !! `element_data` reports, m (the rope's centre of mass for RFEM without point masses:
    !! its element centres are the mass centres).
    function run_centre_of_mass(self, k) result(com)
        class(run_t), intent(in) :: self
        integer, intent(in) :: k
        real(wp) :: com(2)
        real(wp), allocatable :: q(:, :), qdot(:, :), len(:), mass(:)
        integer :: n
        n = self%model%n_elements()
        allocate (q(3, n), qdot(3, n), len(n), mass(n))
        call self%model%fields(self%y(:, k), q, qdot, self%t(k))
        call self%model%element_data(len, mass)
        com = matmul(q(1:2, :), mass)/sum(mass)
    end function run_centre_of_mass
end module ropedyn_test_run
