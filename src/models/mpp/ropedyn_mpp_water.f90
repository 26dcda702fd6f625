!> The MPP in water (docs/theory/mpp.md, "Water"): every rod, as a body with centre C_i and
!! angle phi_i, carries the water's added mass (ropedyn_added_mass): a 3x3 block blk_i on
!! (C_i, phi_i) that depends on the rod's angle and wetting (A_i in translation, J_a,i in
!! rotation) and a force g_i from that dependence. Lagrange's equations in the rod's own
!! coordinates give the rod the force g_i - blk_i (C_i'', phi_i''), and in q, as for every
!! force on a rod, J_i^T times it (the holonomic identity dC_i'/dq = d/dt dC_i/dq): so the
!! residual adds it to the rod's force w_i and moment, the mass matrix gains
!! sum_i J_i^T blk_i J_i, the O(n) solve takes m I + A_i and J + J_a,i as the rod's inertia
!! (mass_factor), and the energy adds 1/2 v^T A v + 1/2 J_a w^2 (kinetic) and -1/2 u^T A u
!! (the current's potential). The tangent takes the derivatives of g_i - blk_i acc_i with
!! respect to the rod's centre, angle and their rates at fixed accelerations as a 3x6 body
!! block (like the effects' blocks), by central differences of the closed forms (steps of
!! 1e-7 of each variable's scale, a relative error near 1e-9; g is quadratic in the rates,
!! for which they are exact), as the RFEM's ropedyn_rfem_water does.
submodule (ropedyn_mpp) ropedyn_mpp_water
    implicit none

contains

    !> blk's translational and rotational parts are uncoupled (added_terms_e leaves
    !! blk(1:2, 3) and blk(3, 1:2) zero): g - blk acc is written with the 2x2 and the
    !! scalar, without the temporaries of a matmul of an array constructor.
    module procedure water_forces
        real(wp) :: g(3)
        integer :: k
        do k = 1, self%n
            call self%added%terms_e(self%bodies%c(:, k), self%cs(:, k), &
                                    self%bodies%v(:, k), self%bodies%w(k), self%l, &
                                    self%wblk(:, :, k), g)
            associate (blk => self%wblk(:, :, k), a => self%cacc(:, k))
                self%w(1, k) = self%w(1, k) + (g(1) - (blk(1, 1)*a(1) + blk(1, 2)*a(2)))
                self%w(2, k) = self%w(2, k) + (g(2) - (blk(2, 1)*a(1) + blk(2, 2)*a(2)))
                self%mom(k) = self%mom(k) + (g(3) - blk(3, 3)*qacc(k))
            end associate
        end do
    end procedure water_forces

    module procedure water_jacobian
        real(wp) :: z(6), zp(6), zm(6), acc(3), fp(3), fm(3), h
        integer :: k, l
        do k = 1, self%n
            z = [self%bodies%c(:, k), self%bodies%phi(k), self%bodies%v(:, k), &
                 self%bodies%w(k)]
            acc = [self%cacc(:, k), qacc(k)]
            do l = 1, 6
                h = 1.0e-7_wp*max(abs(z(l)), step_scale(self, l))
                zp = z
                zm = z
                zp(l) = z(l) + h
                zm(l) = z(l) - h
                fp = rod_force(self, zp, acc)
                fm = rod_force(self, zm, acc)
                self%ejac(:, l, k) = self%ejac(:, l, k) + (fp - fm)/(2.0_wp*h)
            end do
        end do
    end procedure water_jacobian

    !> g - blk acc of a rod at z = (centre, angle, velocity, rate) and accelerations acc.
    pure function rod_force(self, z, acc) result(f)
        class(mpp_t), intent(in) :: self
        real(wp), intent(in) :: z(6), acc(3)
        real(wp) :: f(3)
        real(wp) :: blk(3, 3)
        call self%added%terms(z(1:2), z(3), z(4:5), z(6), self%l, blk, f)
        f = f - matmul(blk, acc)
    end function rod_force

    !> The scale of variable l of a rod's state for a difference step: its length (or the
    !! smoothed surface's half-width, if larger) for a position, 1 for an angle and for the
    !! rates.
    pure real(wp) function step_scale(self, l) result(s)
        class(mpp_t), intent(in) :: self
        integer, intent(in) :: l
        s = 1.0_wp
        if (l <= 2) s = max(self%l, self%added%wetting%delta)
    end function step_scale

    module procedure water_energy
        integer :: k
        kinetic = 0.0_wp
        potential = 0.0_wp
        do k = 1, b%n
            kinetic = kinetic + self%added%kinetic(b%c(:, k), b%phi(k), b%v(:, k), b%w(k), &
                                                   b%l(k))
            potential = potential + self%added%potential(b%c(:, k), b%phi(k), b%l(k))
        end do
    end procedure water_energy

    !> sum_i J_i^T blk_i J_i with J_i = dC_i/dq (columns a_ik n_k on phi_k, a_ik = lambda_k
    !! for k < i, eta_i for k = i, and e_k on u_k, k <= i) and J_a,i on phi_i, in O(n^2) by
    !! the suffix sums S_j = sum_{i>=j} A_i and Abar_j = eta_j A_j + lambda_j S_{j+1}:
    !!     M[phi_k, phi_j] += lambda_k n_k.Abar_j n_j  (k < j),
    !!     M[phi_j, phi_j] += n_j.(eta_j^2 A_j + lambda_j^2 S_{j+1}) n_j + J_a,j,
    !!     M[u_k, u_j] += e_k.S_j e_j  (k <= j),
    !!     M[phi_k, u_j] += lambda_k n_k.S_j e_j  (k < j),   n_k.Abar_k e_j  (k >= j).
    module procedure water_mass_dense
        type(motion_state_t) :: top, bottom
        type(bodies_t) :: b
        logical :: bottom_on
        real(wp) :: blk(3, 3, self%n), g(3), sfx(2, 2, self%n + 1), abar(2, 2), u(self%n)
        real(wp) :: eta(self%n), lam(self%n), e(2, self%n), nv(2, self%n), v
        integer :: j, k, n
        n = self%n
        call self%supports_at(t, top, bottom, bottom_on)
        call rod_bodies(self, y, top, b)
        u = 0.0_wp
        if (self%nu > 0) u = y(n + 1:self%ndof)
        eta = u + 0.5_wp*self%l
        lam = u + self%l
        sfx(:, :, n + 1) = 0.0_wp
        do j = n, 1, -1
            call self%added%terms_e(b%c(:, j), b%cs(:, j), b%v(:, j), b%w(j), b%l(j), &
                                    blk(:, :, j), g)
            sfx(:, :, j) = sfx(:, :, j + 1) + blk(1:2, 1:2, j)
            e(:, j) = b%cs(:, j)
            nv(:, j) = [-e(2, j), e(1, j)]
        end do
        do j = 1, n
            abar = eta(j)*blk(1:2, 1:2, j) + lam(j)*sfx(:, :, j + 1)
            do k = 1, j - 1
                v = lam(k)*dot_product(nv(:, k), matmul(abar, nv(:, j)))
                mm(k, j) = mm(k, j) + v
                mm(j, k) = mm(j, k) + v
                if (self%nu > 0) then
                    v = dot_product(e(:, k), matmul(sfx(:, :, j), e(:, j)))
                    mm(n + k, n + j) = mm(n + k, n + j) + v
                    mm(n + j, n + k) = mm(n + j, n + k) + v
                    v = lam(k)*dot_product(nv(:, k), matmul(sfx(:, :, j), e(:, j)))
                    mm(k, n + j) = mm(k, n + j) + v
                    mm(n + j, k) = mm(n + j, k) + v
                    v = dot_product(nv(:, j), matmul(abar, e(:, k)))
                    mm(j, n + k) = mm(j, n + k) + v
                    mm(n + k, j) = mm(n + k, j) + v
                end if
            end do
            mm(j, j) = mm(j, j) + dot_product(nv(:, j), matmul(eta(j)**2*blk(1:2, 1:2, j) &
                       + lam(j)**2*sfx(:, :, j + 1), nv(:, j))) + blk(3, 3, j)
            if (self%nu > 0) then
                mm(n + j, n + j) = mm(n + j, n + j) + &
                                   dot_product(e(:, j), matmul(sfx(:, :, j), e(:, j)))
                v = dot_product(nv(:, j), matmul(abar, e(:, j)))
                mm(j, n + j) = mm(j, n + j) + v
                mm(n + j, j) = mm(n + j, j) + v
            end if
        end do
    end procedure water_mass_dense
end submodule ropedyn_mpp_water
