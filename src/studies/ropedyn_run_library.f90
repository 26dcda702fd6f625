!> A run without output driven step by step from outside (the library, src/lib): advance
!! to any time, read and replace the state, the polyline, internal forces, reactions and
!! energies of the state now, prescribe coupled supports, keep and restore states.
!!
!! What applies of a file's run: the scene's model, integrator, tolerances, initial state
!! (with statics and modes for 'equilibrium' and 'mode') and step budget (solver.max_steps,
!! for the whole simulation); a state that is not finite after an advance is a failed
!! integration (ERR_SOLVER), as it is before a record. What does not: the output grid and
!! t_end (an advance goes to any later time), records, the progress display, and the
!! order safety's second look and auto's rescue at a runaway (they integrate an output
!! interval a second time, which a coupled support's past motion and the states already
!! handed out do not allow; set solver.max_order to the method's A-stable order where a
!! run would need it). The runaway rule applies, looking at most
!! twice per output interval: B - E0 above a tenth of max(S, m g L) fails the advance and
!! leaves the state it last looked at. A state the caller sets is the rule's new start
!! (its energy came from the caller), a restored one its new last look. No signal is caught.
!!
!! Coupled supports (`&supports top_motion = 'coupled'`): `advance` to t1 moves each on
!! the cubic Hermite curve from its position and velocity now to those `set_support`
!! prescribed for t1 (not prescribed: on with its velocity now, a straight line), and
!! stops the integration exactly at t1, so that no step sees the next exchange's motion
!! before it is known (integrator_t%set_stop_time; mebdf's second stage still looks one
!! step ahead along the curve). With such a support the integrator is told at every
!! advance that f changed (integrator_t%rhs_changed).
submodule (ropedyn_run) ropedyn_run_library
    use ropedyn_error, only: ERR_USAGE
    use ropedyn_text, only: int_text
    use ropedyn_support_motion, only: motion_state_t, MOTION_COUPLED
    implicit none

contains

    module procedure run_advance
        type(motion_state_t) :: now
        type(energy_t) :: e
        logical :: coupled(2)
        integer :: k
        if (.not. ieee_is_finite(t)) then
            call make_error(err, ERR_USAGE, 'advance: t = '//real_text(t)//' s is not finite')
            return
        end if
        if (t < self%t) then
            call make_error(err, ERR_USAGE, 'advance: t = '//real_text(t)//' s lies before '// &
                'the time reached, '//real_text(self%t)//' s (a simulation only goes forward; '// &
                'restore a saved state to go back)')
            return
        end if
        ! (a t within rounding of the time reached: no step can end there, and none is
        ! needed; a coupled support keeps its target for the next advance)
        if (t - self%t <= 16.0_wp*epsilon(1.0_wp)*abs(t)) return
        coupled = self%model%moving .and. self%model%motion%kind == MOTION_COUPLED
        if (any(coupled)) then
            do k = 1, 2
                if (.not. coupled(k)) cycle
                if (.not. self%target_given(k)) then
                    now = self%model%motion(k)%state(self%t)
                    self%target_p(:, k) = now%p + now%v*(t - self%t)
                    self%target_v(:, k) = now%v
                end if
                call self%model%motion(k)%couple(self%t, t, self%target_p(:, k), &
                                                 self%target_v(:, k))
            end do
            self%target_given = .false.
            call self%integrator%set_stop_time(t)
            call self%integrator%rhs_changed()
        end if
        call self%integrator%advance_to(t, self%t, self%y, self%yq(1:self%nq), err)
        if (allocated(err)) return
        if (.not. (all(ieee_is_finite(self%y)) .and. all(ieee_is_finite(self%yq)))) then
            call make_error(err, ERR_SOLVER, 'non-finite state at t = '//real_text(self%t)// &
                            ' s (integrator '//self%integrator%name()//')')
            return
        end if
        ! the runaway rule as a run's records apply it, at most twice per output interval
        ! of the scene (one evaluation of the energy there); the order safety's second look
        ! is the records' alone
        if (.not. self%monitoring .or. self%t - self%t_prev < 0.5_wp*self%dt) return
        e = self%model%energy(self%t, self%y, self%yq)
        if (self%monitor%runaway(e)) then
            call self%fail_runaway(e, err)
            return
        end if
        call self%monitor%observe(e)
        call self%keep_as_previous()
    end procedure run_advance

    module procedure run_state_size
        run_state_size = self%model%size()
    end procedure run_state_size

    module procedure run_elements
        run_elements = self%model%n_elements()
    end procedure run_elements

    module procedure run_get_state
        y = self%y
    end procedure run_get_state

    module procedure run_set_state
        if (size(y) /= size(self%y)) then
            call make_error(err, ERR_USAGE, 'set_state: '//int_text(size(y))//' values, the '// &
                'state has '//int_text(size(self%y)))
            return
        end if
        if (.not. all(ieee_is_finite(y))) then
            call make_error(err, ERR_USAGE, 'set_state: a value is not finite')
            return
        end if
        self%y = y
        call self%restart(err)
        if (allocated(err)) return
        call self%start_monitor(self%model%energy(self%t, self%y, self%yq))
        call self%keep_as_previous()
    end procedure run_set_state

    module procedure run_points_now
        call self%model%polyline(self%y, points, self%t)
    end procedure run_points_now

    module procedure run_forces_now
        call self%model%internal_forces(self%t, self%y, axial, shear, moment, reaction)
    end procedure run_forces_now

    module procedure run_energy_now
        e = self%model%energy(self%t, self%y, self%yq)
    end procedure run_energy_now

    module procedure run_anchors_now
        call self%model%support_positions(self%t, anchors)
    end procedure run_anchors_now

    module procedure run_set_support
        character(len=*), parameter :: ENDS(2) = ['top   ', 'bottom']
        if (k < 1 .or. k > 2) then
            call make_error(err, ERR_USAGE, 'set_support: support '//int_text(k)// &
                            ' (1 top, 2 bottom)')
            return
        end if
        if (.not. (self%model%moving(k) .and. self%model%motion(k)%kind == MOTION_COUPLED)) then
            call make_error(err, ERR_USAGE, 'set_support: the '//trim(ENDS(k))//' support is '// &
                'not coupled (&supports '//trim(ENDS(k))//'_motion = '''// &
                trim(merge(self%scene%supports%top_motion, self%scene%supports%bottom_motion, &
                           k == 1))//''', '//trim(ENDS(k))//' = '''// &
                trim(merge(self%scene%supports%top, self%scene%supports%bottom, k == 1))// &
                '''; a coupled support needs '//trim(ENDS(k))//'_motion = ''coupled'' and '// &
                'a pinned or clamped end)')
            return
        end if
        if (.not. (all(ieee_is_finite(p)) .and. all(ieee_is_finite(v)))) then
            call make_error(err, ERR_USAGE, 'set_support: the '//trim(ENDS(k))//' support''s '// &
                'position or velocity is not finite')
            return
        end if
        self%target_p(:, k) = p
        self%target_v(:, k) = v
        self%target_given(k) = .true.
    end procedure run_set_support

    module procedure run_save
        call self%restart(err)
        if (allocated(err)) return
        snap%t = self%t
        snap%y = self%y
        snap%yq = self%yq
        snap%motion = self%model%motion
        snap%target_p = self%target_p
        snap%target_v = self%target_v
        snap%target_given = self%target_given
        if (.not. allocated(self%physics)) self%physics = scene_physics_text(self%scene)
        snap%physics = self%physics
        snap%valid = .true.
    end procedure run_save

    module procedure run_restore
        if (.not. snap%valid) then
            call make_error(err, ERR_USAGE, 'restore: the snapshot holds no state')
            return
        end if
        if (size(snap%y) /= size(self%y)) then
            call make_error(err, ERR_USAGE, 'restore: the snapshot is of another scene ('// &
                int_text(size(snap%y))//' unknowns, this one has '//int_text(size(self%y))//')')
            return
        end if
        if (allocated(snap%physics)) then
            if (.not. allocated(self%physics)) self%physics = scene_physics_text(self%scene)
            call check_same_physics(snap%physics, self%physics, err)
            if (allocated(err)) return
        end if
        if (size(snap%yq) /= size(self%yq)) then
            ! the same unknowns, other energy integrals (a moving support's work)
            call make_error(err, ERR_USAGE, 'restore: the snapshot is of another scene ('// &
                int_text(size(snap%yq))//' energy integrals, this one has '// &
                int_text(size(self%yq))//')')
            return
        end if
        self%t = snap%t
        self%y = snap%y
        self%yq = snap%yq
        self%model%motion = snap%motion
        self%target_p = snap%target_p
        self%target_v = snap%target_v
        self%target_given = snap%target_given
        call self%restart(err)
        call self%keep_as_previous()
    end procedure run_restore

    module procedure restart
        call self%stats_before%add(self%integrator%stats())
        call self%start_integrator(err)
    end procedure restart
    !> A snapshot's rope and surroundings (`saved`, scene_physics_text) must be this
    !! simulation's (`mine`): else ERR_USAGE naming the first line that differs and its group.
    subroutine check_same_physics(saved, mine, err)
        character(len=*), intent(in) :: saved, mine
        type(error_t), allocatable, intent(out) :: err
        character(len=1), parameter :: NL = new_line('a')
        character(len=:), allocatable :: group
        integer :: i, j, a, b
        if (saved == mine) return
        group = ''
        i = 1
        j = 1
        do
            a = index(saved(i:)//NL, NL)
            b = index(mine(j:)//NL, NL)
            if (saved(i:min(i + a - 2, len(saved))) /= mine(j:min(j + b - 2, len(mine)))) exit
            if (i <= len(saved)) then
                if (saved(i:i) == '&') group = ' (&'//saved(i + 1:i + a - 2)//')'
            end if
            i = i + a
            j = j + b
            if (i > len(saved) .and. j > len(mine)) return
        end do
        call make_error(err, ERR_USAGE, 'restore: the snapshot is of another scene: its "'// &
            trim(adjustl(saved(i:min(i + a - 2, len(saved)))))//'" against this one''s "'// &
            trim(adjustl(mine(j:min(j + b - 2, len(mine)))))//'"'//group)
    end subroutine check_same_physics
end submodule ropedyn_run_library
