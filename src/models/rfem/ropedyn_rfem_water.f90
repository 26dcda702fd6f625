!> The RFEM in water: the added mass of every element (ropedyn_added_mass; theory page
!! "Water") makes its 3x3 mass block depend on its angle and wetting, and adds to its
!! generalized force the terms of Lagrange's equations that come from that dependence
!! (added to self%gen by `forces`, so that statics sees them too). Every element's
!! accelerations are then the solution of its own 3x3 block (point masses included), and
!! its Jacobian rows go from force rows to acceleration rows through it:
!!     d a/dz = M^{-1} (dG/dz + dg/dz - (dM/dz) a)
!! where G are the forces of the springs, effects and the point masses' weight (self%blk,
!! with that weight's moment added here as in the point masses' rows), g the element-local
!! forces (the added mass's, the point masses' centripetal force) and M the block. Their
!! derivatives with respect to the element's own six coordinates and rates are central
!! differences of their closed forms (steps of 1e-7 of each variable's scale, a relative
!! error near 1e-9; g is quadratic in the rates, for which they are exact): the Jacobian
!! only steers the Newton iterations.
submodule (ropedyn_rfem) ropedyn_rfem_water
    implicit none

contains

    !> The mass block (3x3 on x, y, phi) of element i at z = (x, y, phi, x', y', phi') and
    !! its local force g (N, N, N m): the structural mass and inertia, the point masses'
    !! coupling s n and centripetal force s w^2 e, the added mass's block and force.
    pure subroutine local_inertia(self, i, z, m, g)
        class(rfem_t), intent(in) :: self
        integer, intent(in) :: i
        real(wp), intent(in) :: z(6)
        real(wp), intent(out) :: m(3, 3), g(3)
        real(wp) :: blk(3, 3), ga(3)
        call self%added%terms(z(1:2), z(3), z(4:5), z(6), self%len(i), blk, ga)
        call inertia_with(self, i, z, blk, ga, m, g)
    end subroutine local_inertia

    !> local_inertia with the added mass's block blk and force ga at z given.
    pure subroutine inertia_with(self, i, z, blk, ga, m, g)
        class(rfem_t), intent(in) :: self
        integer, intent(in) :: i
        real(wp), intent(in) :: z(6), blk(3, 3), ga(3)
        real(wp), intent(out) :: m(3, 3), g(3)
        real(wp) :: e(2)
        integer :: p
        m = 0.0_wp
        m(1, 1) = self%mass(i)
        m(2, 2) = self%mass(i)
        m(3, 3) = self%inertia(i)
        g = 0.0_wp
        do p = 1, size(self%pm_elem)
            if (self%pm_elem(p) /= i) cycle
            e = [cos(z(3)), sin(z(3))]
            m(1:2, 3) = self%pm_moment(p)*[-e(2), e(1)]
            m(3, 1:2) = m(1:2, 3)
            g(1:2) = self%pm_moment(p)*z(6)**2*e
        end do
        m = m + blk
        g = g + ga
    end subroutine inertia_with

    !> x with m x = b, m (3x3) symmetric positive definite (Gaussian elimination).
    pure function solve3(m, b) result(x)
        real(wp), intent(in) :: m(3, 3), b(3)
        real(wp) :: x(3)
        real(wp) :: a(3, 3), r(3), f
        integer :: i, k
        a = m
        r = b
        do k = 1, 2
            do i = k + 1, 3
                f = a(i, k)/a(k, k)
                a(i, k:3) = a(i, k:3) - f*a(k, k:3)
                r(i) = r(i) - f*r(k)
            end do
        end do
        x(3) = r(3)/a(3, 3)
        x(2) = (r(2) - a(2, 3)*x(3))/a(2, 2)
        x(1) = (r(1) - a(1, 2)*x(2) - a(1, 3)*x(3))/a(1, 1)
    end function solve3

    !> Element i's state z = (x, y, phi, x', y', phi') from y.
    pure function element_state(i, y) result(z)
        integer, intent(in) :: i
        real(wp), intent(in) :: y(:)
        real(wp) :: z(6)
        z = y(6*(i - 1) + 1:6*(i - 1) + 6)
    end function element_state

    !> The added mass's forces into self%gen (its blocks and forces kept in self%am_blk,
    !! self%am_g for water_accelerations) and, with `energy`, its potential (the current's,
    !! -1/2 u^T A u) added to e_el.
    module procedure water_forces
        real(wp) :: z(6)
        integer :: i
        do i = 1, self%n
            z = element_state(i, y)
            call self%added%terms_e(z(1:2), self%cs(:, i), z(4:5), z(6), self%len(i), &
                                    self%am_blk(:, :, i), self%am_g(:, i))
            self%gen(:, i) = self%gen(:, i) + self%am_g(:, i)
            if (present(e_el)) e_el = e_el + self%added%potential(z(1:2), z(3), self%len(i))
        end do
    end procedure water_forces

    !> The accelerations of every element from its block: M a = gen + the point masses'
    !! centripetal force (the added mass's force is in gen already; its block and force at
    !! y are those water_forces kept).
    module procedure water_accelerations
        real(wp) :: m(3, 3), g(3), z(6), a11, a12, a22, det
        integer :: i, k
        if (size(self%pm_elem) == 0) then
            ! no point mass couples translation and rotation: each block is a symmetric 2x2
            ! (mass and the added mass's translational block) and the rotational inertia
            do i = 1, self%n
                k = 6*(i - 1)
                associate (blk => self%am_blk(:, :, i), f => gen(:, i))
                    a11 = self%mass(i) + blk(1, 1)
                    a12 = blk(1, 2)
                    a22 = self%mass(i) + blk(2, 2)
                    det = a11*a22 - a12*a12
                    ydot(k + 4) = (a22*f(1) - a12*f(2))/det
                    ydot(k + 5) = (a11*f(2) - a12*f(1))/det
                    ydot(k + 6) = f(3)/(self%inertia(i) + blk(3, 3))
                end associate
            end do
            return
        end if
        do i = 1, self%n
            k = 6*(i - 1)
            z = element_state(i, y)
            call inertia_with(self, i, z, self%am_blk(:, :, i), self%am_g(:, i), m, g)
            ydot(k + 4:k + 6) = solve3(m, gen(:, i) + g - self%am_g(:, i))
        end do
    end procedure water_accelerations

    !> Kinetic energy of the added mass, 1/2 v^T A v + 1/2 J_a w^2 summed, J.
    module procedure water_kinetic
        real(wp) :: z(6)
        integer :: i
        e_k = 0.0_wp
        do i = 1, self%n
            z = element_state(i, y)
            e_k = e_k + self%added%kinetic(z(1:2), z(3), z(4:5), z(6), self%len(i))
        end do
    end procedure water_kinetic

    !> The rows of self%blk (force rows: dG/dz) of every element to acceleration rows (see
    !! the module header); self%gen must hold the forces at (t, y).
    module procedure water_rows
        real(wp) :: m(3, 3), g(3), a(3), z(6), zp(6), zm(6), mp(3, 3), mm(3, 3), gp(3), &
                    gm(3), dg(3, 6), dm(3, 3, 3), raw(3), h, blk(3, 3), ga(3)
        integer :: i, o, l, p
        do i = 1, self%n
            z = element_state(i, y)
            call local_inertia(self, i, z, m, g)
            call self%added%terms(z(1:2), z(3), z(4:5), z(6), self%len(i), blk, ga)
            a = solve3(m, self%gen(:, i) + g - ga)
            do l = 1, 6
                h = 1.0e-7_wp*max(abs(z(l)), step_scale(self, i, l))
                zp = z
                zm = z
                zp(l) = z(l) + h
                zm(l) = z(l) - h
                call local_inertia(self, i, zp, mp, gp)
                call local_inertia(self, i, zm, mm, gm)
                dg(:, l) = (gp - gm)/(2.0_wp*h)
                if (l <= 3) dm(:, :, l) = (mp - mm)/(2.0_wp*h)
            end do
            ! the moment -g s sin(phi) of the point masses' weight (in gen; not in blk)
            if (self%gravity_on) then
                do p = 1, size(self%pm_elem)
                    if (self%pm_elem(p) == i) dg(3, 3) = dg(3, 3) - &
                        self%g*self%pm_moment(p)*cos(z(3))
                end do
            end if
            do o = max(-1, 1 - i), min(1, self%n - i)
                do l = 1, 6
                    raw = self%blk(:, l, o, i)
                    if (o == 0) then
                        raw = raw + dg(:, l)
                        if (l <= 3) raw = raw - matmul(dm(:, :, l), a)
                    end if
                    self%blk(:, l, o, i) = solve3(m, raw)
                end do
            end do
        end do
    end procedure water_rows

    !> The scale of variable l of element i's state for a difference step: its length for
    !! a position, 1 for an angle and for the rates.
    pure real(wp) function step_scale(self, i, l) result(s)
        class(rfem_t), intent(in) :: self
        integer, intent(in) :: i, l
        s = 1.0_wp
        if (l <= 2) s = max(self%len(i), self%added%wetting%delta)
    end function step_scale
end submodule ropedyn_rfem_water
