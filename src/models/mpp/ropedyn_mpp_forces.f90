!> The MPP's internal forces and support reactions of a state, and the anchors of the
!! supports in time. Definitions, frames and signs: docs/theory/internal-forces.md.
!!
!! The forces come from the Lagrange residual at the true accelerations a = M^{-1} f (the
!! right-hand side's solve), which forms the suffix sums S_k = sum_{i>=k} w_i + F_b
!! (self%wsum, w_i = applied minus inertial force of rod i, F_b the bottom support's
!! force): by Newton's law for members k .. n, S_k is the force of the rope below joint
!! k - 1 on the rope above it, carried by member k's spring (for extensible members its
!! axial component is k_s u_k + d_s u_k', the spring law, since r[u_k] = 0 at the true
!! accelerations; for inextensible ones it is the constraint force). Joint k - 1 is
!! resolved in the frame (e_k, n_k) of member k below it, joint n (F_b) in member n's.
!! The top joint's reaction is -S_1 (the pin force of the power balance), the bottom's
!! F_b. The moments are those of the joints' and the clamps' rotational springs and
!! dampers, as the residual forms them (self%jmom).
submodule (ropedyn_mpp) ropedyn_mpp_forces
    use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
    implicit none

contains

    module procedure mpp_internal_forces
        real(wp) :: a(self%ndof), r(self%ndof), f(2), c, s
        integer :: n, k, status
        n = self%n
        call angles(self, y)
        a = 0.0_wp
        call self%residual_core(t, y, a, r)
        call self%mass_factor(y, status)
        if (status /= STATUS_OK) then
            axial = ieee_value(1.0_wp, ieee_quiet_nan)
            shear = axial
            moment = axial
            reaction = ieee_value(1.0_wp, ieee_quiet_nan)
            return
        end if
        a = r
        call mass_solve(self, a)
        call self%residual_core(t, y, a, r)
        do k = 0, n
            ! joint k: the force of the rope below it, in the frame of member k + 1 (n: n)
            f = self%wsum(:, k + 1)
            c = self%cs(1, min(k + 1, n))
            s = self%cs(2, min(k + 1, n))
            axial(k) = c*f(1) + s*f(2)
            shear(k) = -s*f(1) + c*f(2)
        end do
        moment(0:n) = self%jmom
        reaction(:, 1) = -self%wsum(:, 1)
        reaction(:, 2) = self%wsum(:, n + 1)
    end procedure mpp_internal_forces

    !> The top joint is always held (pinned or clamped); the bottom anchor when the bottom
    !! is pinned or clamped (and not released at t <= 0), also after a later release.
    module procedure mpp_support_positions
        type(motion_state_t) :: ms
        ms = self%motion(1)%state(t)
        positions(:, 1) = ms%p
        if (self%bottom > 0) then
            ms = self%motion(2)%state(t)
            positions(:, 2) = ms%p
        else
            positions(:, 2) = ieee_value(1.0_wp, ieee_quiet_nan)
        end if
    end procedure mpp_support_positions
end submodule ropedyn_mpp_forces
