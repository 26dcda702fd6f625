!> The work of `ropedyn statics` and `ropedyn modes` (src/app/ropedyn_cmd_statics.f90): the
!! static equilibrium of a scene (ropedyn_statics), optionally the lowest modes about it
!! (ropedyn_modes), the internal forces and support reactions there (the model's, with
!! its supports at rest), one HDF5 file and a printed summary. Layout and method:
!! docs/theory/statics-modes.md.
module ropedyn_analysis
    use, intrinsic :: iso_fortran_env, only: output_unit
    use ropedyn_kinds, only: wp, i8, PI
    use ropedyn_error, only: error_t, make_error, ERR_INTERNAL
    use ropedyn_scene, only: scene_t, scene_namelist_text, recorded_source
    use ropedyn_rope_spec, only: rope_spec_t, bottom_anchor_given
    use ropedyn_rope_model, only: rope_model_t
    use ropedyn_os, only: make_parent_dirs, written_path, rename_file, delete_file
    use ropedyn_run_inputs, only: check_not_input, check_may_replace, check_part_free
    use ropedyn_text, only: int_text, column_text
    use ropedyn_model_factory, only: create_model
    use ropedyn_statics, only: statics_options_t, statics_result_t, &
                               potential_energy, rope_length
    use ropedyn_modes, only: modes_result_t, compute_modes
    use ropedyn_line_equilibrium, only: static_equilibrium
    use ropedyn_h5, only: h5_file_t
    use ropedyn_output, only: write_provenance, write_forces, write_shape_record
    use ropedyn_version, only: version_string
    implicit none
    private
    public :: run_analysis, support_forces, DEFAULT_MODE_COUNT

    integer, parameter :: DEFAULT_MODE_COUNT = 10

    !> The scalar results in /statics: name, units, description ('': none).
    character(len=*), parameter :: STATICS_REALS(3, 4) = reshape([character(len=54) :: &
        'residual', 'N', 'max |generalized force| at the equilibrium (N or N m)', &
        'residual_relative', '1', 'residual / total weight', &
        'last_step', 'm', 'max |delta q| of the last step (m or rad)', &
        'weight', 'N', 'total weight'], [3, 4])
    character(len=*), parameter :: STATICS_COUNTS(3, 3) = reshape([character(len=51) :: &
        'iterations', '1', 'linear solves (accepted and rejected steps)', &
        'rejected', '1', '', &
        'stages', '1', 'continuation stages (anchor and ground, or current)'], [3, 3])
    !> The per-mode results in /modes of one value per mode: name, units, description.
    character(len=*), parameter :: MODE_VALUES(3, 5) = reshape([character(len=74) :: &
        'omega', 'rad/s', &
        'natural angular frequencies, ascending (negative: unstable, sqrt(-lambda))', &
        'frequency_hz', 'Hz', '', &
        'period', 's', '', &
        'damping_ratio', '1', 'z^T C z / (2 omega z^T M z)', &
        'axial_fraction', '1', 'share of the point motion along the rope'], [3, 5])

    !> One `ropedyn statics|modes` (`run_analysis`): the model, its equilibrium and modes,
    !! the internal forces and reactions there; steps: solve, write_file, print_summary.
    type :: analysis_t
        character(len=:), allocatable :: command    !< 'statics' or 'modes'
        character(len=:), allocatable :: out_path   !< the HDF5 file
        class(rope_model_t), allocatable :: model
        type(statics_result_t) :: sres
        type(modes_result_t) :: mres
        real(wp), allocatable :: y(:)               !< the equilibrium (ODE state)
        real(wp), allocatable :: axial(:), shear(:), moment(:)  !< at the joints 0:n, N, N m
        !> the supports' forces on the rope (x, y; top, bottom), N, and their anchors, m
        real(wp) :: reaction(2, 2) = 0.0_wp, anchors(2, 2) = 0.0_wp
    contains
        procedure :: solve => analysis_solve
        procedure :: write_file => analysis_write_file
        procedure :: write_statics => analysis_write_statics
        procedure :: write_shape => analysis_write_shape
        procedure :: write_modes => analysis_write_modes
        procedure :: print_summary => analysis_print_summary
    end type analysis_t

contains

    !> `ropedyn statics|modes` on a scene that is read already: the equilibrium from the
    !! scene's initial shape, the support forces, for 'modes' the lowest `count` modes;
    !! the HDF5 file `out_path` ('': out/<scene>_<command>.h5) and a printed summary. The
    !! file replaces an existing one only when that is the same analysis of the same source
    !! (or `force`), never an input of the scene or a special file, and is written as
    !! FILE.part, renamed to FILE when whole (the output guide's rules for a run's file).
    subroutine run_analysis(command, scene, options, count, out_path_given, err, force)
        character(len=*), intent(in) :: command   !< 'statics' or 'modes'
        type(scene_t), intent(in) :: scene
        type(statics_options_t), intent(in) :: options
        integer, intent(in) :: count              !< modes wanted ('modes' only)
        character(len=*), intent(in) :: out_path_given
        type(error_t), allocatable, intent(out) :: err
        logical, intent(in) :: force              !< replace any regular file that is no input
        type(analysis_t) :: analysis

        analysis%command = command
        analysis%out_path = out_path_given
        if (len(analysis%out_path) == 0) analysis%out_path = default_output(scene, command)
        ! never over an input (the scene, its tables, its state file) or a file of another
        ! analysis or source: before any work
        call check_not_input(analysis%out_path, scene, err)
        if (allocated(err)) return
        call check_may_replace(analysis%out_path, scene, force, err, command)
        if (allocated(err)) return
        call check_part_free(written_path(analysis%out_path)//'.part', force, err)
        if (allocated(err)) return
        call analysis%solve(scene, options, count, err)
        if (allocated(err)) return
        call make_parent_dirs(analysis%out_path, err)
        if (allocated(err)) return
        call analysis%write_file(scene, err)
        if (allocated(err)) return
        call analysis%print_summary(scene)
    end subroutine run_analysis

    !> The model of the scene (its supports at rest where they are at t = 0), its
    !! equilibrium from the initial shape, the internal forces and reactions there, and
    !! for 'modes' the lowest `count` modes.
    subroutine analysis_solve(self, scene, options, count, err)
        class(analysis_t), intent(inout) :: self
        type(scene_t), intent(in) :: scene
        type(statics_options_t), intent(in) :: options
        integer, intent(in) :: count
        type(error_t), allocatable, intent(out) :: err
        integer :: n
        call create_model(scene%rope_spec_t, self%model, err)
        if (allocated(err)) return
        ! a static state: the supports rest where they are at t = 0
        self%model%supports_at_rest = .true.
        allocate (self%y(self%model%size()))
        call self%model%initial_state(self%y)
        call static_equilibrium(self%model, scene%rope_spec_t, self%y, options, self%sres, err)
        if (allocated(err)) return
        n = self%model%n_elements()
        allocate (self%axial(0:n), self%shear(0:n), self%moment(0:n))
        call self%model%internal_forces(0.0_wp, self%y, self%axial, self%shear, self%moment, &
                                        self%reaction)
        call self%model%support_positions(0.0_wp, self%anchors)
        if (self%command == 'modes') call compute_modes(self%model, self%y, count, self%mres, err)
    end subroutine analysis_solve

    !> The HDF5 file: /statics and /energy, the forces, the shape, for 'modes' /modes;
    !! written as FILE.part (FILE: the file a link names) and renamed to FILE when closed,
    !! so that an earlier FILE stays whole until then and a failed write leaves no file.
    subroutine analysis_write_file(self, scene, err)
        class(analysis_t), intent(inout) :: self
        type(scene_t), intent(in) :: scene
        type(error_t), allocatable, intent(out) :: err
        type(h5_file_t) :: h5
        type(error_t), allocatable :: close_err
        character(len=:), allocatable :: file
        logical :: removed
        ! a link: the file it points to, even one not there yet (the link stays)
        file = written_path(self%out_path)
        if (file /= self%out_path) call make_parent_dirs(file, err)
        if (allocated(err)) return
        call h5%create(file//'.part', err)
        if (allocated(err)) return
        call self%write_statics(h5, scene, err)
        if (.not. allocated(err)) call self%write_shape(h5, err)
        if (.not. allocated(err) .and. self%command == 'modes') call self%write_modes(h5, err)
        call h5%close(close_err)
        if (allocated(close_err) .and. .not. allocated(err)) call move_alloc(close_err, err)
        if (.not. allocated(err)) call rename_file(file//'.part', file, err)
        if (allocated(err)) removed = delete_file(file//'.part')
    end subroutine analysis_write_file

    !> The root's attributes and provenance, /statics (the equilibrium, how it was found,
    !! the support forces) and /energy.
    subroutine analysis_write_statics(self, h5, scene, err)
        class(analysis_t), intent(inout) :: self
        type(h5_file_t), intent(inout) :: h5
        type(scene_t), intent(in) :: scene
        type(error_t), allocatable, intent(out) :: err
        integer, allocatable :: pos(:), vel(:)
        real(wp) :: reals(size(STATICS_REALS, 2))
        integer(i8) :: counts(size(STATICS_COUNTS, 2))
        integer :: k
        call self%model%coordinates(pos, vel)
        reals = [self%sres%residual, self%sres%residual_relative, self%sres%last_step, &
                 self%sres%weight]
        counts = int([self%sres%iterations, self%sres%rejected, self%sres%stages], i8)
        call h5%attribute('/', 'status', 'complete', err)
        if (allocated(err)) return
        call h5%attribute('/', 'analysis', self%command, err)
        if (allocated(err)) return
        call h5%attribute('/', 'source', recorded_source(scene), err)
        if (allocated(err)) return
        call write_provenance(h5, version_string, self%model%model_name(), &
                              scene_namelist_text(scene), err)
        if (allocated(err)) return
        call h5%group('/statics', err)
        if (allocated(err)) return
        call h5%write('/statics/q', self%y(pos), coordinate_units(self%model%model_name()), &
                      err, 'generalized coordinates of the equilibrium')
        if (allocated(err)) return
        call h5%attribute('/statics', 'criterion', self%sres%criterion, err)
        if (allocated(err)) return
        if (allocated(self%sres%restart)) then
            call h5%attribute('/statics', 'restart', 'started again from '// &
                              self%sres%restart, err)
            if (allocated(err)) return
        end if
        if (allocated(self%sres%caution)) then
            call h5%attribute('/statics', 'caution', self%sres%caution, err)
            if (allocated(err)) return
        end if
        do k = 1, size(reals)
            call h5%write('/statics/'//trim(STATICS_REALS(1, k)), reals(k), &
                          trim(STATICS_REALS(2, k)), err, trim(STATICS_REALS(3, k)))
            if (allocated(err)) return
        end do
        do k = 1, size(counts)
            call h5%write('/statics/'//trim(STATICS_COUNTS(1, k)), counts(k), &
                          trim(STATICS_COUNTS(2, k)), err, trim(STATICS_COUNTS(3, k)))
            if (allocated(err)) return
        end do
        if (trim(scene%supports%top) /= 'free') then
            call h5%write('/statics/support_force_top', self%reaction(:, 1), 'N', err, &
                          'force of the top support on the rope (x, y): '// &
                          '/supports/top/reaction')
            if (allocated(err)) return
        end if
        if (trim(scene%supports%bottom) /= 'free') then
            call h5%write('/statics/support_force_bottom', self%reaction(:, 2), 'N', err, &
                          'force of the bottom support on the rope (x, y): '// &
                          '/supports/bottom/reaction')
            if (allocated(err)) return
        end if
        call h5%group('/energy', err)
        if (allocated(err)) return
        call h5%write('/energy/elastic', self%sres%elastic, 'J', err)
        if (allocated(err)) return
        call h5%write('/energy/gravity', self%sres%gravity, 'J', err)
    end subroutine analysis_write_statics

    !> The internal forces and reactions, /state and /rope of the equilibrium (one record).
    subroutine analysis_write_shape(self, h5, err)
        class(analysis_t), intent(inout) :: self
        type(h5_file_t), intent(inout) :: h5
        type(error_t), allocatable, intent(out) :: err
        real(wp), allocatable :: q(:, :), qdot(:, :), points(:, :), lengths(:), masses(:)
        integer :: n
        n = self%model%n_elements()
        allocate (q(3, n), qdot(3, n), points(2, 2*n), lengths(n), masses(n))
        call self%model%fields(self%y, q, qdot)
        call self%model%polyline(self%y, points)
        call self%model%element_data(lengths, masses)
        call write_forces(h5, self%axial, self%shear, self%moment, self%reaction, self%anchors, &
                          err)
        if (allocated(err)) return
        call write_shape_record(h5, q, points, err)
        if (allocated(err)) return
        call h5%write('/rope/element_length', lengths, 'm', err)
        if (allocated(err)) return
        call h5%write('/rope/element_mass', masses, 'kg', err)
    end subroutine analysis_write_shape

    !> /modes: the frequencies and what else each mode has, and the shapes.
    subroutine analysis_write_modes(self, h5, err)
        class(analysis_t), intent(in) :: self
        type(h5_file_t), intent(inout) :: h5
        type(error_t), allocatable, intent(out) :: err
        real(wp) :: values(self%mres%count, size(MODE_VALUES, 2))
        integer :: k
        values(:, 1) = self%mres%omega
        values(:, 2) = self%mres%omega/(2*PI)
        values(:, 3) = 2*PI/max(abs(self%mres%omega), tiny(1.0_wp))
        values(:, 4) = self%mres%damping_ratio
        values(:, 5) = self%mres%axial_fraction
        call h5%group('/modes', err)
        if (allocated(err)) return
        call h5%attribute('/modes', 'eigensolver', self%mres%eigensolver, err)
        if (allocated(err)) return
        do k = 1, size(MODE_VALUES, 2)
            call h5%write('/modes/'//trim(MODE_VALUES(1, k)), values(:, k), &
                          trim(MODE_VALUES(2, k)), err, trim(MODE_VALUES(3, k)))
            if (allocated(err)) return
        end do
        call h5%write('/modes/shape', self%mres%shape, &
                      coordinate_units(self%model%model_name()), err, &
                      'mode shapes in the generalized coordinates of /statics/q, '// &
                      '(mode, coordinate), largest entry 1')
        if (allocated(err)) return
        call h5%write('/modes/shape_points', self%mres%shape_points, 'm', err, &
                      'displacement of the /rope/points per unit of /modes/shape')
        if (allocated(err)) return
        call h5%write('/modes/stiffness_asymmetry', self%mres%asymmetry, '1', err, &
                      'max |K - K^T| / max |K| before symmetrization')
    end subroutine analysis_write_modes

    !> The printed summary: the equilibrium, how it was found, the support forces, the modes.
    subroutine analysis_print_summary(self, scene)
        class(analysis_t), intent(inout) :: self
        type(scene_t), intent(in) :: scene
        real(wp), allocatable :: points(:, :)
        real(wp) :: force_top(2), force_bottom(2)
        integer :: n, deepest
        n = self%model%n_elements()
        allocate (points(2, 2*n))
        call self%model%polyline(self%y, points)
        deepest = maxloc(points(1, :), 1)
        force_top = self%reaction(:, 1)
        force_bottom = self%reaction(:, 2)
        write (output_unit, '(a)') 'ropedyn '//version_string//': '//self%command//', '// &
            self%model%model_name()//' model, '//int_text(n)//' elements, scene '//scene%path
        write (output_unit, '(a, i0, a, i0, a, i0, a)') '  equilibrium     '// &
            self%sres%criterion//' after ', self%sres%iterations, ' iterations (', &
            self%sres%rejected, ' rejected, ', self%sres%newton_steps, ' Newton'// &
            trim(stage_text(self%sres%stages))//')'
        write (output_unit, '(a, es10.3, a, es10.3, a)') '  residual        '// &
            'max |f| = ', self%sres%residual, ' N (', self%sres%residual_relative, &
            ' of the weight '//column_text(self%sres%weight, 8, 4)//' N)'
        if (allocated(self%sres%restart)) write (output_unit, '(a)') '  start           '// &
            self%sres%restart
        if (allocated(self%sres%caution)) write (output_unit, '(a)') '  caution         '// &
            self%sres%caution
        write (output_unit, '(a, es14.6, a, es14.6)') '  energy (J)      elastic', &
            self%sres%elastic, '   gravity', self%sres%gravity
        write (output_unit, '(a)') '  lowest point    x = '// &
            column_text(points(1, deepest), 12, 7)//' m at y = '// &
            column_text(points(2, deepest), 12, 7)//' m'
        write (output_unit, '(a)') '  lower end       x = '//column_text(points(1, 2*n), 12, 7)// &
            ' m,   y = '//column_text(points(2, 2*n), 12, 7)//' m'
        if (trim(scene%supports%top) /= 'free') write (output_unit, '(a)') &
            '  top support force on the rope (x, y, |F|) N:   '//force_columns(force_top)
        if (trim(scene%supports%bottom) /= 'free') write (output_unit, '(a)') &
            '  bottom support force on the rope (x, y, |F|) N:'//force_columns(force_bottom)
        if (self%command == 'modes') call print_modes(self%mres)
        write (output_unit, '(a)') '  output          '//self%out_path
    end subroutine analysis_print_summary

    !> A support force's columns x, y and |F| (N), each after a space: fixed-point where the
    !! force fits (column_text).
    function force_columns(force) result(text)
        real(wp), intent(in) :: force(2)
        character(len=:), allocatable :: text
        text = ' '//column_text(force(1), 11, 6)//' '//column_text(force(2), 11, 6)//' '// &
               column_text(norm2(force), 11, 6)
    end function force_columns

    !> The modes' lines of the summary.
    subroutine print_modes(mres)
        type(modes_result_t), intent(in) :: mres
        integer :: k
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
    end subroutine print_modes

    !> '; N continuation stages' when there were any, else ''.
    pure function stage_text(stages) result(text)
        integer, intent(in) :: stages
        character(len=40) :: text
        text = ''
        if (stages > 0) write (text, '(a, i0, a)') '; ', stages, ' continuation stages'
    end function stage_text

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
