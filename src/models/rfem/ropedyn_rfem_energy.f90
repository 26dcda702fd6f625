!> The RFEM's energies and its force split (the derivation is in docs/theory/rfem.md; the
!! method that uses the split in docs/theory/symplectic.md).
!!
!! The potential V = the springs of the SDEs and of the supports + gravity (what
!! `rfem_energy` counts as elastic and gravity energy); the force split (problem_t's) gives
!! the forces of V and the rest: the dampers of the SDEs and supports, and every effect
!! (drag, loads; ground contact, the one effect with potential energy, refuses the split),
!! both from one pass of `forces` (with `rest`); the generalized force of an SDE is linear
!! in its (fx, fy, fp), so the two parts add up to the whole to rounding.
!!
!! Assumed by the split, and refused otherwise: the mass matrix of the coordinates is
!! constant and diagonal, diag(m_i, m_i, J_i). Point masses at an element's centre keep it
!! so; off the centre they couple translation and rotation through the angle. (Water's added
!! mass depends on an element's orientation, so it is neither: `rfem_force_split_refusal`
!! refuses the split with water on.)
submodule (ropedyn_rfem:ropedyn_rfem_kernels) ropedyn_rfem_energy
    implicit none

contains

    module procedure rfem_potential_energy
        type(energy_t) :: e
        e = self%energy(0.0_wp, y, [0.0_wp])
        v = e%elastic + e%gravity
    end procedure rfem_potential_energy

    module procedure rfem_energy
        integer :: i, k, p

        call self%set_time(t)
        e%kinetic = 0.0_wp
        e%gravity = 0.0_wp
        do i = 1, self%n
            k = 6*(i - 1)
            e%kinetic = e%kinetic + 0.5_wp*(self%mass(i)*(y(k + 4)**2 + y(k + 5)**2) + &
                                            self%inertia(i)*y(k + 6)**2)
            if (self%gravity_on) e%gravity = e%gravity - self%mass(i)*self%g*y(k + 1)
        end do
        ! point masses off the element centres: T += s w (v . n), V_g -= g s cos(phi)
        do p = 1, size(self%pm_elem)
            k = 6*(self%pm_elem(p) - 1)
            e%kinetic = e%kinetic + self%pm_moment(p)*y(k + 6)* &
                        (-y(k + 4)*sin(y(k + 3)) + y(k + 5)*cos(y(k + 3)))
            if (self%gravity_on) e%gravity = e%gravity - self%g*self%pm_moment(p)*cos(y(k + 3))
        end do
        if (self%water) e%kinetic = e%kinetic + self%water_kinetic(y)
        ! the springs' and the effects' potential energy, and its part that is a level's
        ! (forces, not split, has filled self%bodies at y for the effects)
        call self%forces(t, y, e%elastic)
        e%level = 0.0_wp
        if (size(self%effects) > 0) &
            call add_level_energies_of(self%effects, t, self%bodies, e%level)
        e%dissipated = 0.0_wp
        if (size(yq) >= 1) e%dissipated = yq(1)
        e%support_work = 0.0_wp  ! fixed supports and no loads: no external work
        if (self%with_work .and. size(yq) >= 2) e%support_work = yq(2)
    end procedure rfem_energy

    module procedure rfem_force_split_refusal
        integer :: k
        why = ''
        if (self%water) then
            why = 'water: the added mass makes each element''s mass block depend on its '// &
                  'angle and wetting, it is not constant'
            return
        end if
        if (any(self%pm_moment /= 0.0_wp)) then
            why = 'point masses off the element centres: the mass matrix couples translation '// &
                  'and rotation through the angle, it is not constant'
            return
        end if
        do k = 1, size(self%effects)
            why = self%effects(k)%e%split_refusal()
            if (len(why) > 0) return
        end do
    end procedure rfem_force_split_refusal

    module procedure rfem_split_has_rest
        rest = self%damped .or. any(self%sup%damped_t .or. self%sup%damped_r)
        if (allocated(self%effects)) rest = rest .or. size(self%effects) > 0
    end procedure rfem_split_has_rest

    module procedure rfem_split_layout
        integer :: i
        do i = 1, self%n
            mass(3*i - 2) = self%mass(i)
            mass(3*i - 1) = self%mass(i)
            mass(3*i) = self%inertia(i)
        end do
        signs = 0
        signs(1) = -1
        if (self%with_work .and. size(signs) >= 2) signs(2) = 1
    end procedure rfem_split_layout

    module procedure rfem_split_rhs
        real(wp) :: power, work
        integer :: i, k
        logical :: rest

        rest = present(ar)
        power = 0.0_wp
        if (rest .and. self%damped) then
            call self%forces(t, y, power=power, rest=.true.)
        else
            call self%forces(t, y, rest=rest)
        end if
        do i = 1, self%n
            ac(3*i - 2) = self%gen(1, i)*self%inv_mass(1, i)
            ac(3*i - 1) = self%gen(2, i)*self%inv_mass(2, i)
            ac(3*i) = self%gen(3, i)*self%inv_mass(3, i)
        end do
        gc = 0.0_wp
        status = STATUS_OK
        if (self%with_work) then
            ! the supports' springs on moving anchors: dV/dt at fixed q
            work = 0.0_wp
            do k = 1, 2
                if (self%sup(k)%active .and. self%moving(k)) &
                    call support_split_power(self, k, y, .false., power, work)
            end do
            gc(2) = work
        end if
        if (rest) then
            do i = 1, self%n
                ar(3*i - 2) = self%gen_r(1, i)*self%inv_mass(1, i)
                ar(3*i - 1) = self%gen_r(2, i)*self%inv_mass(2, i)
                ar(3*i) = self%gen_r(3, i)*self%inv_mass(3, i)
            end do
            work = 0.0_wp
            do k = 1, 2
                if (self%sup(k)%active) call support_split_power(self, k, y, .true., power, work)
            end do
            ! (forces filled the bodies of the effects)
            if (size(self%effects) > 0) &
                call add_powers_of(self%effects, t, self%bodies, power, work)
            if (present(gr)) then
                gr = 0.0_wp
                gr(1) = power
                if (self%with_work) gr(2) = work
            end if
            if (.not. (all_finite(ar) .and. ieee_is_finite(power) .and. &
                       ieee_is_finite(work))) status = STATUS_RECOVERABLE
        end if
        if (.not. (all_finite(ac) .and. all_finite(gc))) &
            status = STATUS_RECOVERABLE
    end procedure rfem_split_rhs

    !> Support k's power (support_power, split): without `rest` the work rate of its springs
    !! on a moving anchor (dV/dt at fixed q), with `rest` its dampers' dissipation and their
    !! work rate (W; added to power and work; self%cs at y).
    pure subroutine support_split_power(self, k, y, rest, power, work)
        class(rfem_t), intent(in) :: self
        integer, intent(in) :: k
        real(wp), intent(in) :: y(:)
        logical, intent(in) :: rest
        real(wp), intent(inout) :: power, work
        real(wp) :: dd(2), fs(2), sd, fr
        integer :: m
        associate (sp => self%sup(k), co => self%cs(1, self%sup(k)%elem), &
                   si => self%cs(2, self%sup(k)%elem))
            m = 6*(sp%elem - 1)
            if (sp%translational) then
                fs = 0.0_wp
                if (.not. rest) then
                    fs = sp%ct*support_offset(self, k, y, co, si)
                else if (sp%damped_t) then
                    dd = support_offset_rate(self, k, y, co, si)
                    fs = sp%bt*dd
                    power = power + sp%bt*(dd(1)**2 + dd(2)**2)
                end if
                if (self%moving(k)) work = work - sp%sgn*(fs(1)*sp%anchor_vel(1) &
                                                          + fs(2)*sp%anchor_vel(2))
            end if
            if (sp%rotational) then
                fr = 0.0_wp
                if (.not. rest) then
                    fr = sp%cr*sp%sgn*(y(m + 3) - sp%angle)
                else if (sp%damped_r) then
                    sd = sp%sgn*(y(m + 6) - sp%angle_rate)
                    fr = sp%br*sd
                    power = power + sp%br*sd**2
                end if
                if (self%moving(k)) work = work - sp%sgn*fr*sp%angle_rate
            end if
        end associate
    end subroutine support_split_power
end submodule ropedyn_rfem_energy
