!> The work of `ropedyn statics` and `ropedyn modes` (src/app/ropedyn_cmd_statics.f90): the
!! static equilibrium of a scene (ropedyn_statics), optionally the lowest modes about it
!! (ropedyn_modes), the internal forces and support reactions there (the model's, with
!! its supports at rest), one HDF5 file and a printed summary. Layout and method:
!! docs/theory/statics-modes.md.
module ropedyn_analysis
    use, intrinsic :: iso_fortran_env, only: output_unit
    use ropedyn_kinds, only: wp, i8
    use ropedyn_error, only: error_t, make_error, ERR_INTERNAL
    use ropedyn_scene, only: scene_t, scene_namelist_text
    use ropedyn_rope_spec, only: rope_spec_t, bottom_anchor_given
    use ropedyn_rope_model, only: rope_model_t
    use ropedyn_os, only: make_parent_dirs
    use ropedyn_run_inputs, only: check_not_input
    use ropedyn_text, only: int_text
    use ropedyn_model_factory, only: create_model
    use ropedyn_statics, only: statics_options_t, statics_result_t, find_equilibrium, &
                               potential_energy, rope_length
    use ropedyn_modes, only: modes_result_t, compute_modes
    use ropedyn_h5, only: h5_file_t
    use ropedyn_output, only: write_provenance, write_forces
    use ropedyn_version, only: version_string
    implicit none
    private
    public :: run_analysis, support_forces, DEFAULT_MODE_COUNT

    integer, parameter :: DEFAULT_MODE_COUNT = 10
    real(wp), parameter :: PI = 4.0_wp*atan(1.0_wp)

    !> The scalar results in /statics: name, units, description ('': none).
    character(len=*), parameter :: STATICS_REALS(3, 4) = reshape([character(len=54) :: &
        'residual', 'N', 'max |generalized force| at the equilibrium (N or N m)', &
        'residual_relative', '1', 'residual / total weight', &
        'last_step', 'm', 'max |delta q| of the last step (m or rad)', &
        'weight', 'N', 'total weight'], [3, 4])
    character(len=*), parameter :: STATICS_COUNTS(3, 3) = reshape([character(len=51) :: &
        'iterations', '1', 'linear solves (accepted and rejected steps)', &
        'rejected', '1', '', &
        'stages', '1', 'continuation stages in the bottom anchor (0: none)'], [3, 3])
    !> The per-mode results in /modes of one value per mode: name, units, description.
    character(len=*), parameter :: MODE_VALUES(3, 5) = reshape([character(len=74) :: &
        'omega', 'rad/s', &
        'natural angular frequencies, ascending (negative: unstable, sqrt(-lambda))', &
        'frequency_hz', 'Hz', '', &
        'period', 's', '', &
        'damping_ratio', '1', 'z^T C z / (2 omega z^T M z)', &
        'axial_fraction', '1', 'share of the point motion along the rope'], [3, 5])

contains

    !> `ropedyn statics|modes` on a scene that is read already: the equilibrium from the
    !! scene's initial shape, the support forces, for 'modes' the lowest `count` modes;
    !! the HDF5 file `out_path` ('': out/<scene>_<command>.h5) and a printed summary.
    subroutine run_analysis(command, scene, options, count, out_path_given, err)
        character(len=*), intent(in) :: command   !< 'statics' or 'modes'
        type(scene_t), intent(in) :: scene
        type(statics_options_t), intent(in) :: options
        integer, intent(in) :: count              !< modes wanted ('modes' only)
        character(len=*), intent(in) :: out_path_given
        type(error_t), allocatable, intent(out) :: err
        character(len=:), allocatable :: out_path
        class(rope_model_t), allocatable :: model
        type(statics_result_t) :: sres
        type(modes_result_t) :: mres
        real(wp), allocatable :: y(:), axial(:), shear(:), moment(:)
        real(wp) :: reaction(2, 2), anchors(2, 2), force_top(2), force_bottom(2)

        out_path = out_path_given
        if (len(out_path) == 0) out_path = default_output(scene, command)
        ! never over an input (the scene, its tables, its state file): before any work
        call check_not_input(out_path, scene, err)
        if (allocated(err)) return
        call create_model(scene%rope_spec_t, model, err)
        if (allocated(err)) return
        ! a static state: the supports rest where they are at t = 0
        model%supports_at_rest = .true.
        allocate (y(model%size()))
        call model%initial_state(y)
        call find_equilibrium(model, scene%rope_spec_t, y, options, sres, err)
        if (allocated(err)) return
        allocate (axial(0:model%n_elements()), shear(0:model%n_elements()), &
                  moment(0:model%n_elements()))
        call model%internal_forces(0.0_wp, y, axial, shear, moment, reaction)
        call model%support_positions(0.0_wp, anchors)
        force_top = reaction(:, 1)
        force_bottom = reaction(:, 2)
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

        subroutine write_file()
            type(h5_file_t) :: h5
            type(error_t), allocatable :: close_err
            real(wp), allocatable :: q(:, :), qdot(:, :), points(:, :), lengths(:), masses(:)
            integer, allocatable :: pos(:), vel(:)
            real(wp) :: reals(size(STATICS_REALS, 2))
            integer(i8) :: counts(size(STATICS_COUNTS, 2))
            integer :: n, k
            n = model%n_elements()
            allocate (q(3, n), qdot(3, n), points(2, 2*n), lengths(n), masses(n))
            call model%fields(y, q, qdot)
            call model%polyline(y, points)
            call model%element_data(lengths, masses)
            call model%coordinates(pos, vel)
            reals = [sres%residual, sres%residual_relative, sres%last_step, sres%weight]
            counts = int([sres%iterations, sres%rejected, sres%stages], i8)

            call h5%create(out_path, err)
            if (allocated(err)) return
            steps: block
                call h5%attribute('/', 'status', 'complete', err)
                if (allocated(err)) exit steps
                call h5%attribute('/', 'analysis', command, err)
                if (allocated(err)) exit steps
                call write_provenance(h5, version_string, model%model_name(), &
                                      scene_namelist_text(scene), err)
                if (allocated(err)) exit steps
                call h5%group('/statics', err)
                if (allocated(err)) exit steps
                call h5%write('/statics/q', y(pos), coordinate_units(model%model_name()), err, &
                              'generalized coordinates of the equilibrium')
                if (allocated(err)) exit steps
                call h5%attribute('/statics', 'criterion', sres%criterion, err)
                if (allocated(err)) exit steps
                do k = 1, size(reals)
                    call h5%write('/statics/'//trim(STATICS_REALS(1, k)), reals(k), &
                                  trim(STATICS_REALS(2, k)), err, trim(STATICS_REALS(3, k)))
                    if (allocated(err)) exit steps
                end do
                do k = 1, size(counts)
                    call h5%write('/statics/'//trim(STATICS_COUNTS(1, k)), counts(k), &
                                  trim(STATICS_COUNTS(2, k)), err, trim(STATICS_COUNTS(3, k)))
                    if (allocated(err)) exit steps
                end do
                if (trim(scene%supports%top) /= 'free') then
                    call h5%write('/statics/support_force_top', force_top, 'N', err, &
                                  'force of the top support on the rope (x, y): '// &
                                  '/supports/top/reaction')
                    if (allocated(err)) exit steps
                end if
                if (trim(scene%supports%bottom) /= 'free') then
                    call h5%write('/statics/support_force_bottom', force_bottom, 'N', err, &
                                  'force of the bottom support on the rope (x, y): '// &
                                  '/supports/bottom/reaction')
                    if (allocated(err)) exit steps
                end if
                call h5%group('/energy', err)
                if (allocated(err)) exit steps
                call h5%write('/energy/elastic', sres%elastic, 'J', err)
                if (allocated(err)) exit steps
                call h5%write('/energy/gravity', sres%gravity, 'J', err)
                if (allocated(err)) exit steps
                call write_forces(h5, axial, shear, moment, reaction, anchors, err)
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
            type(h5_file_t), intent(inout) :: h5
            real(wp) :: values(mres%count, size(MODE_VALUES, 2))
            integer :: k
            values(:, 1) = mres%omega
            values(:, 2) = mres%omega/(2*PI)
            values(:, 3) = 2*PI/max(abs(mres%omega), tiny(1.0_wp))
            values(:, 4) = mres%damping_ratio
            values(:, 5) = mres%axial_fraction
            call h5%group('/modes', err)
            if (allocated(err)) return
            call h5%attribute('/modes', 'eigensolver', mres%eigensolver, err)
            if (allocated(err)) return
            do k = 1, size(MODE_VALUES, 2)
                call h5%write('/modes/'//trim(MODE_VALUES(1, k)), values(:, k), &
                              trim(MODE_VALUES(2, k)), err, trim(MODE_VALUES(3, k)))
                if (allocated(err)) return
            end do
            call h5%write('/modes/shape', mres%shape, coordinate_units(model%model_name()), &
                          err, 'mode shapes in the generalized coordinates of /statics/q, '// &
                          '(mode, coordinate), largest entry 1')
            if (allocated(err)) return
            call h5%write('/modes/shape_points', mres%shape_points, 'm', err, &
                          'displacement of the /rope/points per unit of /modes/shape')
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
                model%model_name()//' model, '//int_text(n)//' elements, scene '//scene%path
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
    end subroutine run_analysis

    !> Forces of the supports on the rope at the equilibrium y, N: R = dV/d(anchor) with
    !! the coordinates held fixed (virtual work), by central differences of the potential
    !! energy of models rebuilt with the anchor moved by +-h (V is quadratic in the anchor
    !! of a pinned support: exact up to rounding), point loads included (their potential at
    !! t = 0: an MPP's ideal pin carries them). Zero for a free end. Independent of the
    !! model's force laws: the check (in the tests) of the reactions that `run_analysis`
    !! takes from the model (rope_model_t%internal_forces).
    subroutine support_forces(scene, model, y, top, bottom, err)
        type(rope_spec_t), intent(in) :: scene
        class(rope_model_t), intent(inout) :: model
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: top(2), bottom(2)
        type(error_t), allocatable, intent(out) :: err
        type(rope_spec_t) :: base, moved
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
        v0 = potential_energy(model, y, base)
        if (abs(potential_energy(probe, y, base) - v0) > 1.0e-12_wp*(abs(v0) + 1.0_wp)) then
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
                vp = potential_energy(probe, y, moved)
                moved = base
                call shift(moved, s, c, -h)
                call create_model(moved, probe, err)
                if (allocated(err)) return
                vm = potential_energy(probe, y, moved)
                if (s == 1) then
                    top(c) = (vp - vm)/(2*h)
                else
                    bottom(c) = (vp - vm)/(2*h)
                end if
            end do
        end do
    contains
        subroutine shift(sc, side, comp, d)
            type(rope_spec_t), intent(inout) :: sc
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


end module ropedyn_analysis
