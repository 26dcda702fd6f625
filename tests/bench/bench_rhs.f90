!> Benchmark (not a test): CPU time of the right-hand side and of the Jacobian of a scene's
!! model, per call and per element. Used by scripts/bench_effects (docs/benchmarks.md).
!!
!!   bench_rhs SCENE.nml [--set group.key=value ...] [--seconds S]
!!
!! The state is the scene's initial state with a fixed perturbation (velocities up to
!! 0.3 m/s and 1 rad/s, positions by 1e-4 m), so that velocity-dependent effects do work.
!! Each timing repeats calls for about S seconds (default 0.5) five times and reports the
!! fastest repetition. Prints one line: `n rhs_ns_per_element jac_ns_per_element`.
program bench_rhs
    use, intrinsic :: iso_fortran_env, only: error_unit, int64
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t
    use ropedyn_scene, only: scene_t, read_scene
    use ropedyn_rope_model, only: rope_model_t
    use ropedyn_simulation, only: create_model
    implicit none
    character(len=1024), allocatable :: sets(:)
    character(len=1024) :: arg, scene_path
    type(scene_t) :: scene
    class(rope_model_t), allocatable :: model
    type(error_t), allocatable :: err
    real(wp), allocatable :: y(:), ydot(:), jb(:, :)
    real(wp) :: seconds, rhs_ns, jac_ns, sink
    integer :: i, nargs, nsets, ml, mu, n, status

    nargs = command_argument_count()
    allocate (sets(nargs))
    nsets = 0
    seconds = 0.5_wp
    scene_path = ''
    i = 1
    do while (i <= nargs)
        call get_command_argument(i, arg)
        if (arg == '--set' .and. i < nargs) then
            nsets = nsets + 1
            call get_command_argument(i + 1, sets(nsets))
            i = i + 2
        else if (arg == '--seconds' .and. i < nargs) then
            call get_command_argument(i + 1, arg)
            read (arg, *) seconds
            i = i + 2
        else
            scene_path = arg
            i = i + 1
        end if
    end do
    if (len_trim(scene_path) == 0) then
        write (error_unit, '(a)') 'usage: bench_rhs SCENE.nml [--set group.key=value ...] '// &
            '[--seconds S]'
        error stop 2
    end if
    call read_scene(trim(scene_path), sets(1:nsets), scene, err)
    if (.not. allocated(err)) call create_model(scene%rope_spec_t, model, err)
    if (allocated(err)) then
        write (error_unit, '(a)') err%message
        error stop 2
    end if
    n = model%size()
    allocate (y(n), ydot(n))
    call model%initial_state(y)
    do i = 1, n
        select case (mod(i - 1, 6))
        case (0, 1)
            y(i) = y(i) + 1.0e-4_wp*sin(1.3_wp*i)
        case (3, 4)
            y(i) = y(i) + 0.3_wp*sin(0.7_wp*i)
        case (5)
            y(i) = y(i) + sin(0.9_wp*i)
        end select
    end do
    call model%bandwidths(ml, mu)
    allocate (jb(2*ml + mu + 1, n))
    sink = 0.0_wp
    rhs_ns = best_time(.false.)
    jac_ns = best_time(.true.)
    write (*, '(i0, 2(1x, f0.2), 1x, es10.3)') model%n_elements(), &
        rhs_ns/model%n_elements(), jac_ns/model%n_elements(), sink
contains
    !> Fastest of five repetitions, ns per call.
    real(wp) function best_time(jacobian) result(best)
        logical, intent(in) :: jacobian
        integer(int64) :: c0, c1, rate, calls, k
        integer :: rep
        real(wp) :: t0, t1
        ! calibrate the number of calls to about `seconds`
        calls = 1
        do
            call cpu_time(t0)
            do k = 1, calls
                call one(jacobian)
            end do
            call cpu_time(t1)
            if (t1 - t0 > 0.05_wp*seconds) exit
            calls = calls*4
        end do
        calls = max(1_int64, int(calls*0.2_wp*seconds/max(t1 - t0, 1.0e-9_wp), int64))
        best = huge(1.0_wp)
        call system_clock(c0, rate)
        do rep = 1, 5
            call cpu_time(t0)
            do k = 1, calls
                call one(jacobian)
            end do
            call cpu_time(t1)
            best = min(best, (t1 - t0)/real(calls, wp)*1.0e9_wp)
        end do
        call system_clock(c1)
    end function best_time

    subroutine one(jacobian)
        logical, intent(in) :: jacobian
        if (jacobian) then
            jb = 0.0_wp
            call model%jacobian(0.1_wp, y, jb, ml + mu + 1, status)
            sink = sink + jb(ml + mu + 1, 1)*1.0e-30_wp
        else
            call model%rhs(0.1_wp, y, ydot, status)
            sink = sink + ydot(n)*1.0e-30_wp
        end if
    end subroutine one
end program bench_rhs
