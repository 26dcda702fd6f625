!> The RFEM's internal forces and support reactions of a state, from the SDE forces that
!! the right-hand side forms (`forces` with its `joint` and `support` outputs: the same
!! spring and damper laws, the same values), and the anchors of the supports in time.
!! Definitions, frames and signs: docs/theory/internal-forces.md.
!!
!! Joint j (0 .. n) is SDE j + 1: j = 0 the top support, 1 .. n-1 the internal SDEs between
!! elements j and j + 1, n the bottom support. An internal SDE's forces fx, fy, fp are its
!! tension, shear force and bending moment: with F = fx e_a + fy n_a its force on the
!! element above (a = j), fx and fy are the components of F in a's frame, and fp its moment
!! on a. A support SDE's force fs = Ct d + Bt d' acts on the rope as -sgn fs (sgn = +1 top,
!! -1 bottom): the top's reaction is -fs, and fs is the rope's force on it, resolved in the
!! frame of element 1; the bottom's reaction is fs, the force of the part below (the
!! support) on the rope above it, resolved in the frame of element n. The moments follow
!! the same rule (fr of the top, fr of the bottom).
submodule (ropedyn_rfem) ropedyn_rfem_forces
    use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
    implicit none

contains

    module procedure rfem_internal_forces
        real(wp) :: joint(3, 0:self%n), sup(3, 2)
        integer :: n
        n = self%n
        joint = 0.0_wp
        ! one pass of the right-hand side's forces (it leaves cos and sin in self%cs)
        call self%forces(t, y, joint=joint, support=sup)
        reaction(:, 1) = -sup(1:2, 1)
        reaction(:, 2) = sup(1:2, 2)
        joint(1, 0) = dot_product(sup(1:2, 1), self%cs(:, 1))
        joint(2, 0) = dot_product(sup(1:2, 1), [-self%cs(2, 1), self%cs(1, 1)])
        joint(3, 0) = sup(3, 1)
        joint(1, n) = dot_product(sup(1:2, 2), self%cs(:, n))
        joint(2, n) = dot_product(sup(1:2, 2), [-self%cs(2, n), self%cs(1, n)])
        joint(3, n) = sup(3, 2)
        axial(0:n) = joint(1, :)
        shear(0:n) = joint(2, :)
        moment(0:n) = joint(3, :)
    end procedure rfem_internal_forces

    !> A support that holds the rope at the start (pinned or clamped, not released at
    !! t <= 0) is where its motion puts it (a fixed one at its anchor), also after a later
    !! release; a free end has no anchor (NaN).
    module procedure rfem_support_positions
        type(motion_state_t) :: ms
        integer :: k
        do k = 1, 2
            if (self%sup(k)%translational .or. self%sup(k)%rotational) then
                ms = self%motion(k)%state(t)
                positions(:, k) = ms%p
            else
                positions(:, k) = ieee_value(1.0_wp, ieee_quiet_nan)
            end if
        end do
    end procedure rfem_support_positions
end submodule ropedyn_rfem_forces
