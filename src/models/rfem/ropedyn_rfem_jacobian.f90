!> The RFEM's point masses (the accelerations of the elements carrying them, and their rows
!! of the Jacobian blocks) and the writing of the 3x6 blocks of element pairs, which
!! ropedyn_rfem_kernels' `jacobian_blocks` leaves in self%blk, into the first-order band
!! (`jacobian`) or the second-order blocks (`second_order_blocks`). docs/theory/rfem.md.
submodule (ropedyn_rfem) ropedyn_rfem_jacobian
    implicit none

contains

    !> Accelerations (x'', y'', phi'') of the element carrying point-mass group p, from its
    !! generalized force g (3).
    pure function pm_acceleration(self, p, y, g) result(a)
        class(rfem_t), intent(in) :: self
        integer, intent(in) :: p
        real(wp), intent(in) :: y(:), g(3)
        real(wp) :: a(3)
        integer :: i, k
        real(wp) :: e(2), nv(2), f(2), sm
        i = self%pm_elem(p)
        k = 6*(i - 1)
        sm = self%pm_moment(p)
        e = [cos(y(k + 3)), sin(y(k + 3))]
        nv = [-e(2), e(1)]
        f = g(1:2) + sm*y(k + 6)**2*e
        a(3) = (g(3) - sm*dot_product(nv, f)/self%mass(i)) &
               /(self%inertia(i) - sm**2/self%mass(i))
        a(1:2) = (f - sm*nv*a(3))/self%mass(i)
    end function pm_acceleration

    module procedure point_mass_accelerations
        integer :: p, k
        do p = 1, size(self%pm_elem)
            k = 6*(self%pm_elem(p) - 1)
            ydot(k + 4:k + 6) = pm_acceleration(self, p, y, gen(:, self%pm_elem(p)))
        end do
    end procedure point_mass_accelerations

    module procedure point_mass_rows
        integer :: i, o, l, p, k0
        real(wp) :: raw(3), a(3), e(2), nv(2), sm, w

        ! Their rows hold dG/dy (rowscale 1): add the terms of the weight's moment and the
        ! centripetal force, subtract (dA/dphi) a, and multiply by the inverse of the
        ! element's mass block A.
        call self%forces(t, y)
        do p = 1, size(self%pm_elem)
            i = self%pm_elem(p)
            k0 = 6*(i - 1)
            sm = self%pm_moment(p)
            e = [cos(y(k0 + 3)), sin(y(k0 + 3))]
            nv = [-e(2), e(1)]
            w = y(k0 + 6)
            a = pm_acceleration(self, p, y, self%gen(:, i))
            do o = max(-1, 1 - i), min(1, self%n - i)
                do l = 1, 6
                    raw = self%blk(:, l, o, i)
                    if (o == 0 .and. l == 3) then
                        raw(1:2) = raw(1:2) + sm*w**2*nv
                        if (self%gravity_on) raw(3) = raw(3) - self%g*sm*e(1)
                        raw = raw + sm*[e(1)*a(3), e(2)*a(3), dot_product(e, a(1:2))]
                    else if (o == 0 .and. l == 6) then
                        raw(1:2) = raw(1:2) + 2.0_wp*sm*w*e
                    end if
                    raw(3) = (raw(3) - sm*dot_product(nv, raw(1:2))/self%mass(i)) &
                             /(self%inertia(i) - sm**2/self%mass(i))
                    raw(1:2) = (raw(1:2) - sm*nv*raw(3))/self%mass(i)
                    self%blk(:, l, o, i) = raw
                end do
            end do
        end do
    end procedure point_mass_rows

    !> The rows of the elements whose mass block is not diagonal (in water: every element;
    !! else those with point masses) from force rows to acceleration rows.
    subroutine mass_rows(self, t, y)
        class(rfem_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        if (self%water) then
            call self%forces(t, y)
            call self%water_rows(t, y)
        else if (size(self%pm_elem) > 0) then
            call self%point_mass_rows(t, y)
        end if
    end subroutine mass_rows

    !> Add the Jacobian of the first-order system into band storage jb(ld, 6n) (entry (i, j)
    !! at row offset + i - j): the identity of the position rows and the velocity rows from
    !! the blocks times the row scales.
    subroutine write_first_order(self, jb, ld, offset)
        class(rfem_t), intent(in) :: self
        integer, intent(in) :: ld, offset
        real(wp), intent(inout) :: jb(ld, 6*self%n)
        integer :: i, k, o, l, col, p
        do i = 1, self%n
            k = 6*(i - 1)
            ! d(position)/dt = velocity
            jb(offset - 3, k + 4:k + 6) = jb(offset - 3, k + 4:k + 6) + 1.0_wp
            ! rows k+4 .. k+6 (band rows p .. p+2 of column col) from the blocks of elements
            ! i-1, i, i+1, times the row scales
            do o = max(-1, 1 - i), min(1, self%n - i)
                do l = 1, 6
                    col = 6*(i + o - 1) + l
                    p = offset + k + 4 - col
                    jb(p:p + 2, col) = jb(p:p + 2, col) + self%rowscale(:, i)*self%blk(:, l, o, i)
                end do
            end do
        end do
    end subroutine write_first_order

    !> Add K (the blocks' coordinate columns), C (their rate columns), both times the row
    !! scales, and the identity mass block into band storage (ld, 3n).
    subroutine write_second_order(self, kb, cb, mb, ld, offset)
        class(rfem_t), intent(in) :: self
        integer, intent(in) :: ld, offset
        real(wp), intent(inout) :: kb(ld, 3*self%n), cb(ld, 3*self%n), mb(ld, 3*self%n)
        integer :: i, k, o, l, col, p
        real(wp) :: s(3)
        do i = 1, self%n
            k = 3*(i - 1)
            mb(offset, k + 1:k + 3) = mb(offset, k + 1:k + 3) + 1.0_wp
            s = self%rowscale(:, i)
            do o = max(-1, 1 - i), min(1, self%n - i)
                do l = 1, 3
                    col = 3*(i + o - 1) + l
                    p = offset + k + 1 - col
                    kb(p:p + 2, col) = kb(p:p + 2, col) + s*self%blk(:, l, o, i)
                    cb(p:p + 2, col) = cb(p:p + 2, col) + s*self%blk(:, l + 3, o, i)
                end do
            end do
        end do
    end subroutine write_second_order

    module procedure rfem_jacobian
        call self%jacobian_blocks(t, y)
        call mass_rows(self, t, y)
        call write_first_order(self, jb, size(jb, 1), offset)
        status = STATUS_OK
    end procedure rfem_jacobian

    module procedure rfem_second_order_blocks
        call self%jacobian_blocks(t, y)
        call mass_rows(self, t, y)
        call write_second_order(self, kb, cb, mb, size(kb, 1), offset)
        status = STATUS_OK
    end procedure rfem_second_order_blocks
end submodule ropedyn_rfem_jacobian
