!> Benchmark (not a test): CPU time of the kernels of a scene's model, per call and per
!! element: the right-hand side, the Jacobian of the first-order system, the second-order
!! blocks K, C, M of the reduced Newton systems (explicit and implicit form) and the
!! quadratures. Used by scripts/bench_effects and scripts/bench_kernels (docs/performance/effects.md, docs/performance/step.md).
!!
!!   bench_rhs SCENE.nml [--set group.key=value ...] [--seconds S]
!!   bench_rhs SCENE.nml [--set ...] --calls K --kernel rhs|jac|blocks|blocks_implicit|quad|
!!                                               split|split_rest
!!
!! The state is the scene's initial state with a fixed perturbation (RFEM: velocities up to
!! 0.3 m/s and 1 rad/s, positions by 1e-4 m; MPP: angles by 0.1 rad, elongations by 1e-4 m,
!! rates up to 1 rad/s and 0.03 m/s), so that velocity-dependent effects do work.
!! Each timing repeats calls for about S seconds (default 0.5) five times and reports the
!! fastest repetition. Prints one line:
!! `n rhs_ns jac_ns blocks_ns blocks_implicit_ns quad_ns sink` (ns per element and call;
!! every call includes zeroing its output arrays, as an integrator does; -1 for a kernel
!! that reports a status other than OK, e.g. blocks the model cannot give).
!! With --calls K it makes exactly K calls of one kernel and prints nothing: run it under
!! `valgrind --tool=callgrind` with two values of K to count instructions per call.
program bench_rhs
    use, intrinsic :: iso_fortran_env, only: error_unit, int64
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t
    use ropedyn_scene, only: scene_t, read_scene
    use ropedyn_rope_model, only: rope_model_t
    use ropedyn_model_factory, only: create_model
    implicit none
    integer, parameter :: K_RHS = 1, K_JAC = 2, K_BLOCKS = 3, K_BLOCKS_IMPLICIT = 4, K_QUAD = 5, &
                          K_SPLIT = 6, K_SPLIT_REST = 7
    character(len=*), parameter :: KERNELS(7) = [character(len=15) :: 'rhs', 'jac', 'blocks', &
                                                 'blocks_implicit', 'quad', 'split', 'split_rest']
    character(len=1024), allocatable :: sets(:)
    character(len=1024) :: arg, scene_path, kernel_name
    type(scene_t) :: scene
    class(rope_model_t), allocatable :: model
    type(error_t), allocatable :: err
    real(wp), allocatable :: y(:), ydot(:), jb(:, :), kb(:, :), cb(:, :), mb(:, :), yq(:)
    real(wp), allocatable :: ac(:), ar(:), gc(:), gr(:)
    integer, allocatable :: pos(:), vel(:)
    real(wp) :: seconds, ns(5), sink
    integer :: i, nargs, nsets, ml, mu, kl, ku, n, np, status, kernel
    integer(int64) :: fixed_calls, k

    nargs = command_argument_count()
    allocate (sets(nargs))
    nsets = 0
    seconds = 0.5_wp
    scene_path = ''
    fixed_calls = -1
    kernel_name = 'rhs'
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
        else if (arg == '--calls' .and. i < nargs) then
            call get_command_argument(i + 1, arg)
            read (arg, *) fixed_calls
            i = i + 2
        else if (arg == '--kernel' .and. i < nargs) then
            call get_command_argument(i + 1, kernel_name)
            i = i + 2
        else
            scene_path = arg
            i = i + 1
        end if
    end do
    kernel = findloc(KERNELS, trim(kernel_name), 1)
    if (len_trim(scene_path) == 0 .or. kernel == 0) then
        write (error_unit, '(a)') 'usage: bench_rhs SCENE.nml [--set group.key=value ...] '// &
            '[--seconds S] [--calls K --kernel rhs|jac|blocks|blocks_implicit|quad|split|'// &
            'split_rest]'
        error stop 2
    end if
    call read_scene(trim(scene_path), sets(1:nsets), scene, err)
    if (.not. allocated(err)) call create_model(scene%rope_spec_t, model, err)
    if (allocated(err)) then
        write (error_unit, '(a)') err%message
        error stop 2
    end if
    n = model%size()
    allocate (y(n), ydot(n), yq(model%quad_size()))
    allocate (ac(n/2), ar(n/2), gc(model%quad_size()), gr(model%quad_size()))
    call model%initial_state(y)
    if (model%model_name() == 'mpp') then
        ! (angles, elongations, their rates): angles by 0.1 rad, elongations by 1e-4 m,
        ! rates up to 1 rad/s and 0.03 m/s
        np = n/2
        do i = 1, np
            if (i <= model%n_elements()) then
                y(i) = y(i) + 0.1_wp*sin(1.3_wp*i)
                y(np + i) = y(np + i) + sin(0.9_wp*i)
            else
                y(i) = y(i) + 1.0e-4_wp*sin(1.3_wp*i)
                y(np + i) = y(np + i) + 0.03_wp*sin(0.7_wp*i)
            end if
        end do
    else
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
    end if
    call model%bandwidths(ml, mu)
    allocate (jb(2*ml + mu + 1, n))
    call model%second_order_layout(pos, vel, kl, ku)
    np = size(pos)
    ! LU storage, as an integrator that factors the reduced matrix in place allocates it
    allocate (kb(2*kl + ku + 1, np), cb(2*kl + ku + 1, np), mb(2*kl + ku + 1, np))
    sink = 0.0_wp
    if (fixed_calls >= 0) then
        do k = 1, fixed_calls
            call one(kernel)
        end do
        if (sink == 1.0_wp) write (*, '(a)') 'unlikely'
        stop
    end if
    do i = 1, 5
        ns(i) = best_time(i)
    end do
    write (*, '(i0, 5(1x, f0.2), 1x, es10.3)') model%n_elements(), &
        ns/model%n_elements(), sink
contains
    !> Fastest of five repetitions, ns per call.
    real(wp) function best_time(which) result(best)
        integer, intent(in) :: which
        integer(int64) :: calls, kk
        integer :: rep
        real(wp) :: t0, t1
        ! a kernel the model does not offer (status not OK) is reported as -1
        call one(which)
        if (status /= 0) then
            best = -real(model%n_elements(), wp)
            return
        end if
        ! calibrate the number of calls to about `seconds`
        calls = 1
        do
            call cpu_time(t0)
            do kk = 1, calls
                call one(which)
            end do
            call cpu_time(t1)
            if (t1 - t0 > 0.05_wp*seconds) exit
            calls = calls*4
        end do
        calls = max(1_int64, int(calls*0.2_wp*seconds/max(t1 - t0, 1.0e-9_wp), int64))
        best = huge(1.0_wp)
        do rep = 1, 5
            call cpu_time(t0)
            do kk = 1, calls
                call one(which)
            end do
            call cpu_time(t1)
            best = min(best, (t1 - t0)/real(calls, wp)*1.0e9_wp)
        end do
    end function best_time

    subroutine one(which)
        integer, intent(in) :: which
        select case (which)
        case (K_JAC)
            jb = 0.0_wp
            call model%jacobian(0.1_wp, y, jb, ml + mu + 1, status)
            sink = sink + jb(ml + mu + 1, 1)*1.0e-30_wp
        case (K_BLOCKS, K_BLOCKS_IMPLICIT)
            kb = 0.0_wp
            cb = 0.0_wp
            mb = 0.0_wp
            call model%second_order_blocks(0.1_wp, y, which == K_BLOCKS_IMPLICIT, kb, cb, mb, &
                                           kl + ku + 1, status)
            sink = sink + (kb(kl + ku + 1, 1) + cb(kl + ku + 1, 1) + mb(kl + ku + 1, 1))*1.0e-30_wp
        case (K_QUAD)
            call model%quad_rhs(0.1_wp, y, yq, status)
            sink = sink + yq(1)*1.0e-30_wp
        case (K_RHS)
            call model%rhs(0.1_wp, y, ydot, status)
            sink = sink + ydot(n)*1.0e-30_wp
        case (K_SPLIT)
            call model%split_rhs(0.1_wp, y, ac, gc, status)
            sink = sink + ac(1)*1.0e-30_wp
        case (K_SPLIT_REST)
            call model%split_rhs(0.1_wp, y, ac, gc, status, ar, gr)
            sink = sink + (ac(1) + ar(1))*1.0e-30_wp
        end select
    end subroutine one
end program bench_rhs
