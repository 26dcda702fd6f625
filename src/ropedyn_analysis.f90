!> The `ropedyn statics` and `ropedyn modes` commands: read a scene, find its static
!! equilibrium (ropedyn_statics), optionally the lowest modes about it (ropedyn_modes), the
!! support forces, write one HDF5 file and print a summary. Layout and method:
!! docs/statics-modes.md.
!!
!!   ropedyn statics SCENE.nml [--set group.key=value ...] [-o FILE.h5] [--max-iterations N]
!!   ropedyn modes SCENE.nml [--count K] [--set ...] [-o FILE.h5] [--max-iterations N]
module ropedyn_analysis
    use, intrinsic :: iso_fortran_env, only: output_unit
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t, make_error, ERR_USAGE, ERR_INTERNAL
    use ropedyn_scene, only: scene_t, read_scene, scene_namelist_text, bottom_anchor_given
    use ropedyn_rope_model, only: rope_model_t
    use ropedyn_simulation, only: create_model, make_parent_dirs
    use ropedyn_statics, only: statics_options_t, statics_result_t, find_equilibrium, &
                               potential_energy, rope_length
    use ropedyn_modes, only: modes_result_t, compute_modes
    use ropedyn_result_file, only: result_file_t
    use ropedyn_version, only: version_string
    implicit none
    private
    public :: analysis_command, support_forces, DEFAULT_MODE_COUNT

    integer, parameter :: DEFAULT_MODE_COUNT = 10
    real(wp), parameter :: PI = 4.0_wp*atan(1.0_wp)

contains

    !> Run `ropedyn statics|modes` with the arguments after the command.
    subroutine analysis_command(command, args, err)
        character(len=*), intent(in) :: command   !< 'statics' or 'modes'
        character(len=*), intent(in) :: args(:)
        type(error_t), allocatable, intent(out) :: err
        character(len=1024), allocatable :: overrides(:)
        character(len=:), allocatable :: scene_path, out_path, arg, value, option
        type(statics_options_t) :: options
        type(scene_t) :: scene
        class(rope_model_t), allocatable :: model
        type(statics_result_t) :: sres
        type(modes_result_t) :: mres
        real(wp), allocatable :: y(:)
        real(wp) :: force_top(2), force_bottom(2)
        integer :: i, n_over, count, eq
        logical :: has_value

        allocate (overrides(size(args)))
        n_over = 0
        count = DEFAULT_MODE_COUNT
        i = 1
        do while (i <= size(args))
            arg = trim(args(i))
            i = i + 1
            option = arg
            has_value = .false.
            eq = index(arg, '=')
            if (len(arg) > 2 .and. eq > 0) then
                if (arg(1:2) == '--') then
                    option = arg(1:eq - 1)
                    value = arg(eq + 1:)
                    has_value = .true.
                end if
            end if
            select case (option)
            case ('--help', '-h')
                call usage(command)
                return
            case ('--no-continuation')
                options%continuation = .false.
            case ('--set', '-o', '--output', '--count', '--max-iterations')
                if (.not. has_value) then
                    if (i > size(args)) then
                        call usage_error(option//' needs a value')
                        return
                    end if
                    value = trim(args(i))
                    i = i + 1
                end if
                select case (option)
                case ('--set')
                    n_over = n_over + 1
                    overrides(n_over) = value
                case ('-o', '--output')
                    out_path = value
                case ('--count')
                    if (command /= 'modes') then
                        call usage_error('--count is an option of "ropedyn modes"')
                        return
                    end if
                    count = int_value(option, value, 1)
                    if (allocated(err)) return
                case ('--max-iterations')
                    options%max_iterations = int_value(option, value, 1)
                    if (allocated(err)) return
                end select
            case default
                if (len(arg) == 0) then
                    call usage_error('empty argument')
                    return
                end if
                if (arg(1:1) == '-') then
                    call usage_error('unknown option "'//arg//'"')
                    return
                end if
                if (allocated(scene_path)) then
                    call usage_error('more than one scene file: "'//scene_path//'", "'// &
                                     arg//'"')
                    return
                end if
                scene_path = arg
            end select
        end do
        if (.not. allocated(scene_path)) then
            call usage_error(command//' needs a scene file')
            return
        end if

        call read_scene(scene_path, overrides(1:n_over), scene, err)
        if (allocated(err)) return
        if (.not. allocated(out_path)) out_path = default_output(scene, command)
        call create_model(scene, model, err)
        if (allocated(err)) return
        allocate (y(model%size()))
        call model%initial_state(y)
        call find_equilibrium(model, scene, y, options, sres, err, create_model)
        if (allocated(err)) return
        call support_forces(scene, model, y, force_top, force_bottom, err)
        if (allocated(err)) return
        if (command == 'modes') then
            call compute_modes(model, y, count, mres, err)
            if (allocated(err)) return
        end if
        call make_parent_dirs(out_path, err)
        if (allocated(err)) return
        call write_file()
        if (allocated(err)) return
        call print_summary()

    contains

        function stage_text() result(text)
            character(len=40) :: text
            text = ''
            if (sres%stages > 0) write (text, '(a, i0, a)') '; ', sres%stages, &
                ' continuation stages'
        end function stage_text

        subroutine usage_error(message)
            character(len=*), intent(in) :: message
            call make_error(err, ERR_USAGE, command//': '//message//' (see ropedyn '// &
                            command//' --help)')
        end subroutine usage_error

        integer function int_value(name, text, lowest) result(n)
            character(len=*), intent(in) :: name, text
            integer, intent(in) :: lowest
            integer :: ios
            n = 0
            ios = 1
            if (len_trim(text) > 0 .and. verify(trim(text), '0123456789+') == 0) &
                read (text, *, iostat=ios) n
            if (ios /= 0 .or. n < lowest) call usage_error(name//' "'//text// &
                '": expected an integer >= '//itoa(lowest))
        end function int_value

        subroutine write_file()
            type(result_file_t) :: h5
            type(error_t), allocatable :: close_err
            real(wp), allocatable :: q(:, :), qdot(:, :), points(:, :), lengths(:), masses(:)
            integer, allocatable :: pos(:), vel(:)
            integer :: n
            n = model%n_elements()
            allocate (q(3, n), qdot(3, n), points(2, 2*n), lengths(n), masses(n))
            call model%fields(y, q, qdot)
            call model%polyline(y, points)
            call model%element_data(lengths, masses)
            call model%coordinates(pos, vel)

            call h5%create(out_path, err)
            if (allocated(err)) return
            steps: block
                call h5%attribute('/', 'status', 'complete', err)
                if (allocated(err)) exit steps
                call h5%attribute('/', 'analysis', command, err)
                if (allocated(err)) exit steps
                call h5%attribute('/', 'version', version_string, err)
                if (allocated(err)) exit steps
                call h5%attribute('/', 'model', model%model_name(), err)
                if (allocated(err)) exit steps
                call h5%attribute('/', 'scene', scene_namelist_text(scene), err)
                if (allocated(err)) exit steps
                call h5%attribute('/', 'created', timestamp(), err)
                if (allocated(err)) exit steps
                call h5%attribute('/', 'units_convention', 'SI; x points down (gravity), '// &
                                  'y horizontal, angles from x towards y', err)
                if (allocated(err)) exit steps
                call h5%group('/statics', err)
                if (allocated(err)) exit steps
                call h5%write('/statics/q', y(pos), coordinate_units(model%model_name()), err, &
                              'generalized coordinates of the equilibrium')
                if (allocated(err)) exit steps
                call h5%attribute('/statics', 'criterion', sres%criterion, err)
                if (allocated(err)) exit steps
                call h5%write('/statics/residual', sres%residual, 'N', err, &
                              'max |generalized force| at the equilibrium (N or N m)')
                if (allocated(err)) exit steps
                call h5%write('/statics/residual_relative', sres%residual_relative, '1', err, &
                              'residual / total weight')
                if (allocated(err)) exit steps
                call h5%write('/statics/iterations', sres%iterations, '1', err, &
                              'linear solves (accepted and rejected steps)')
                if (allocated(err)) exit steps
                call h5%write('/statics/rejected', sres%rejected, '1', err)
                if (allocated(err)) exit steps
                call h5%write('/statics/stages', sres%stages, '1', err, &
                              'continuation stages in the bottom anchor (0: none)')
                if (allocated(err)) exit steps
                call h5%write('/statics/last_step', sres%last_step, 'm', err, &
                              'max |delta q| of the last step (m or rad)')
                if (allocated(err)) exit steps
                call h5%write('/statics/weight', sres%weight, 'N', err, 'total weight')
                if (allocated(err)) exit steps
                if (trim(scene%supports%top) /= 'free') then
                    call h5%write('/statics/support_force_top', force_top, 'N', err, &
                                  'force of the top support on the rope (x, y)')
                    if (allocated(err)) exit steps
                end if
                if (trim(scene%supports%bottom) /= 'free') then
                    call h5%write('/statics/support_force_bottom', force_bottom, 'N', err, &
                                  'force of the bottom support on the rope (x, y)')
                    if (allocated(err)) exit steps
                end if
                call h5%group('/energy', err)
                if (allocated(err)) exit steps
                call h5%write('/energy/elastic', sres%elastic, 'J', err)
                if (allocated(err)) exit steps
                call h5%write('/energy/gravity', sres%gravity, 'J', err)
                if (allocated(err)) exit steps
                call h5%group('/state', err)
                if (allocated(err)) exit steps
                call h5%write('/state/q', reshape(q, [3, n, 1]), 'm, m, rad', err, &
                              'x, y, phi of each element centre (one record)')
                if (allocated(err)) exit steps
                call h5%group('/rope', err)
                if (allocated(err)) exit steps
                call h5%write('/rope/points', reshape(points, [2, 2*n, 1]), 'm', err, &
                              'element end points A_1, B_1, A_2, ... (one record)')
                if (allocated(err)) exit steps
                call h5%write('/rope/element_length', lengths, 'm', err)
                if (allocated(err)) exit steps
                call h5%write('/rope/element_mass', masses, 'kg', err)
                if (allocated(err)) exit steps
                if (command == 'modes') call write_modes(h5)
            end block steps
            call h5%close(close_err)
            if (allocated(close_err) .and. .not. allocated(err)) call move_alloc(close_err, err)
        end subroutine write_file

        subroutine write_modes(h5)
            type(result_file_t), intent(inout) :: h5
            call h5%group('/modes', err)
            if (allocated(err)) return
            call h5%attribute('/modes', 'eigensolver', mres%eigensolver, err)
            if (allocated(err)) return
            call h5%write('/modes/omega', mres%omega, 'rad/s', err, 'natural angular '// &
                          'frequencies, ascending (negative: unstable, sqrt(-lambda))')
            if (allocated(err)) return
            call h5%write('/modes/frequency_hz', mres%omega/(2*PI), 'Hz', err)
            if (allocated(err)) return
            call h5%write('/modes/period', 2*PI/max(abs(mres%omega), tiny(1.0_wp)), 's', err)
            if (allocated(err)) return
            call h5%write('/modes/shape', mres%shape, coordinate_units(model%model_name()), &
                          err, 'mode shapes in the generalized coordinates of /statics/q, '// &
                          '(mode, coordinate), largest entry 1')
            if (allocated(err)) return
            call h5%write('/modes/shape_points', mres%shape_points, 'm', err, &
                          'displacement of the /rope/points per unit of /modes/shape')
            if (allocated(err)) return
            call h5%write('/modes/damping_ratio', mres%damping_ratio, '1', err, &
                          'z^T C z / (2 omega z^T M z)')
            if (allocated(err)) return
            call h5%write('/modes/axial_fraction', mres%axial_fraction, '1', err, &
                          'share of the point motion along the rope')
            if (allocated(err)) return
            call h5%write('/modes/stiffness_asymmetry', mres%asymmetry, '1', err, &
                          'max |K - K^T| / max |K| before symmetrization')
        end subroutine write_modes

        subroutine print_summary()
            real(wp), allocatable :: points(:, :)
            integer :: k, n, deepest
            n = model%n_elements()
            allocate (points(2, 2*n))
            call model%polyline(y, points)
            deepest = maxloc(points(1, :), 1)
            write (output_unit, '(a)') 'ropedyn '//version_string//': '//command//', '// &
                model%model_name()//' model, '//itoa(n)//' elements, scene '//scene%path
            write (output_unit, '(a, i0, a, i0, a, i0, a)') '  equilibrium     '// &
                sres%criterion//' after ', sres%iterations, ' iterations (', sres%rejected, &
                ' rejected, ', sres%newton_steps, ' Newton'//trim(stage_text())//')'
            write (output_unit, '(a, es10.3, a, es10.3, a, f8.4, a)') '  residual        '// &
                'max |f| = ', sres%residual, ' N (', sres%residual_relative, &
                ' of the weight ', sres%weight, ' N)'
            write (output_unit, '(a, es14.6, a, es14.6)') '  energy (J)      elastic', &
                sres%elastic, '   gravity', sres%gravity
            write (output_unit, '(a, f12.7, a, f12.7, a)') '  lowest point    x = ', &
                points(1, deepest), ' m at y = ', points(2, deepest), ' m'
            write (output_unit, '(a, f12.7, a, f12.7, a)') '  lower end       x = ', &
                points(1, 2*n), ' m,   y = ', points(2, 2*n), ' m'
            if (trim(scene%supports%top) /= 'free') write (output_unit, '(a, 3f12.6)') &
                '  top support force on the rope (x, y, |F|) N:   ', force_top, norm2(force_top)
            if (trim(scene%supports%bottom) /= 'free') write (output_unit, '(a, 3f12.6)') &
                '  bottom support force on the rope (x, y, |F|) N:', force_bottom, &
                norm2(force_bottom)
            if (command == 'modes') then
                write (output_unit, '(a, i0, a, i0, 2a, es8.1, a)') '  modes           ', &
                    mres%count, ' of ', mres%ndof, ' (', mres%eigensolver// &
                    ', stiffness asymmetry ', mres%asymmetry, ')'
                write (output_unit, '(a)') '   mode   omega (rad/s)    f (Hz)     period (s)'// &
                    '   damping ratio   axial share'
                do k = 1, mres%count
                    write (output_unit, '(i7, f16.6, f11.5, f14.6, es16.3, f12.3)') k, &
                        mres%omega(k), mres%omega(k)/(2*PI), &
                        2*PI/max(abs(mres%omega(k)), tiny(1.0_wp)), mres%damping_ratio(k), &
                        mres%axial_fraction(k)
                end do
            end if
            write (output_unit, '(a)') '  output          '//out_path
        end subroutine print_summary
    end subroutine analysis_command

    !> Forces of the supports on the rope at the equilibrium y, N: R = dV/d(anchor) with
    !! the coordinates held fixed (virtual work), by central differences of the potential
    !! energy of models rebuilt with the anchor moved by +-h (V is quadratic in the anchor
    !! of a pinned support: exact up to rounding). Zero for a free end.
    subroutine support_forces(scene, model, y, top, bottom, err)
        type(scene_t), intent(in) :: scene
        class(rope_model_t), intent(inout) :: model
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: top(2), bottom(2)
        type(error_t), allocatable, intent(out) :: err
        type(scene_t) :: base, moved
        class(rope_model_t), allocatable :: probe
        real(wp), allocatable :: y0(:), points(:, :)
        real(wp) :: h, vp, vm, v0
        integer :: c, s

        top = 0.0_wp
        bottom = 0.0_wp
        base = scene
        if (.not. bottom_anchor_given(scene)) then
            ! the models' default: the lower end of the initial configuration
            allocate (y0(model%size()), points(2, 2*model%n_elements()))
            call model%initial_state(y0)
            call model%polyline(y0, points)
            base%supports%bottom_anchor = points(:, size(points, 2))
            base%supports%bottom_anchor_set = .true.
        end if
        call create_model(base, probe, err)
        if (allocated(err)) return
        v0 = potential_energy(model, y)
        if (abs(potential_energy(probe, y) - v0) > 1.0e-12_wp*(abs(v0) + 1.0_wp)) then
            call make_error(err, ERR_INTERNAL, scene%path//': support forces: cannot '// &
                            'reproduce the default bottom anchor')
            return
        end if
        h = 1.0e-4_wp*rope_length(model)
        do s = 1, 2
            if (s == 1 .and. trim(scene%supports%top) == 'free') cycle
            if (s == 2 .and. trim(scene%supports%bottom) == 'free') cycle
            do c = 1, 2
                moved = base
                call shift(moved, s, c, h)
                call create_model(moved, probe, err)
                if (allocated(err)) return
                vp = potential_energy(probe, y)
                moved = base
                call shift(moved, s, c, -h)
                call create_model(moved, probe, err)
                if (allocated(err)) return
                vm = potential_energy(probe, y)
                if (s == 1) then
                    top(c) = (vp - vm)/(2*h)
                else
                    bottom(c) = (vp - vm)/(2*h)
                end if
            end do
        end do
    contains
        subroutine shift(sc, side, comp, d)
            type(scene_t), intent(inout) :: sc
            integer, intent(in) :: side, comp
            real(wp), intent(in) :: d
            if (side == 1) then
                sc%supports%top_anchor(comp) = sc%supports%top_anchor(comp) + d
            else
                sc%supports%bottom_anchor(comp) = sc%supports%bottom_anchor(comp) + d
            end if
        end subroutine shift
    end subroutine support_forces

    !> out/<scene>_statics.h5 or out/<scene>_modes.h5 from the scene's output file.
    function default_output(scene, command) result(path)
        type(scene_t), intent(in) :: scene
        character(len=*), intent(in) :: command
        character(len=:), allocatable :: path
        path = trim(scene%output%file)
        if (len(path) > 3) then
            if (path(len(path) - 2:) == '.h5') path = path(1:len(path) - 3)
        end if
        path = path//'_'//command//'.h5'
    end function default_output

    !> Units of the generalized coordinates of a model.
    pure function coordinate_units(model_name) result(units)
        character(len=*), intent(in) :: model_name
        character(len=:), allocatable :: units
        select case (model_name)
        case ('rfem')
            units = 'm, m, rad (x, y, phi of each element)'
        case ('mpp')
            units = 'rad (phi_1..phi_n), m (u_1..u_n if extensible)'
        case default
            units = 'model coordinates'
        end select
    end function coordinate_units

    subroutine usage(command)
        character(len=*), intent(in) :: command
        if (command == 'modes') then
            write (output_unit, '(a)') 'usage: ropedyn modes SCENE.nml [--count K] '// &
                '[--set group.key=value ...] [-o FILE.h5] [--max-iterations N]'
            write (output_unit, '(a)') 'The lowest K (default 10) natural frequencies and '// &
                'mode shapes about the static equilibrium'
            write (output_unit, '(a)') '(undamped, linearized), printed and written to '// &
                'FILE.h5 (default out/<scene>_modes.h5).'
        else
            write (output_unit, '(a)') 'usage: ropedyn statics SCENE.nml '// &
                '[--set group.key=value ...] [-o FILE.h5] [--max-iterations N]'
            write (output_unit, '(a)') 'The static equilibrium of the scene (started from '// &
                'its &initial shape), printed and'
            write (output_unit, '(a)') 'written to FILE.h5 (default out/<scene>_statics.h5).'
        end if
        write (output_unit, '(a)') '  --max-iterations N  limit of the equilibrium iteration '// &
            '(default 2000)'
        write (output_unit, '(a)') '  --no-continuation   solve directly even when the bottom '// &
            'anchor is far from the start'
        write (output_unit, '(a)') 'exit codes: 0 ok, 2 bad input, 3 no equilibrium or '// &
            'solver failure, 4 output error'
        write (output_unit, '(a)') 'See docs/statics-modes.md.'
    end subroutine usage

    !> Local time in ISO 8601 with its UTC offset.
    function timestamp() result(text)
        character(len=:), allocatable :: text
        character(len=8) :: d
        character(len=10) :: t
        character(len=5) :: z
        call date_and_time(d, t, z)
        text = d(1:4)//'-'//d(5:6)//'-'//d(7:8)//'T'//t(1:2)//':'//t(3:4)//':'//t(5:6)// &
               z(1:3)//':'//z(4:5)
    end function timestamp

    pure function itoa(i) result(text)
        integer, intent(in) :: i
        character(len=:), allocatable :: text
        character(len=16) :: buffer
        write (buffer, '(i0)') i
        text = trim(buffer)
    end function itoa
end module ropedyn_analysis
