!> The multiple physical pendulum (MPP) rope model: n identical members, each a massless
!! spring (elongation u_i) followed by a uniform rigid rod (length l = L/n, mass m = M/n),
!! joined by elastic-dissipative joints; Lagrange's equations M(q) q'' = f(t, q, q').
!! Derivation and parameter rules: docs/physics-mpp.md.
!!
!! Coordinates q = (phi_1 .. phi_n, u_1 .. u_nu) with nu = n (extensible, &effects
!! tension = .true.) or nu = 0 (inextensible members). State y = (q, q').
!! Joint positions P_i = P_0 + sum_{k<=i} (l + u_k) e_k, rod centres
!! C_i = P_{i-1} + (u_i + l/2) e_i, e_k = (cos phi_k, sin phi_k), n_k = de_k/dphi_k.
!!
!! The whole dynamics is one O(n) routine, the Lagrange residual
!!     r(q, q', q'') = Q(q, q') - sum_i m J_i^T C_i'' - J phi'' ,   J_i = dC_i/dq,
!! so that f = r(q, q', 0) and M q'' = f - r(q, q', q''). M(q) itself (dense) is
!! assembled in O(n^2) for the solve (Cholesky, LAPACK dpotrf/dpotrs), which makes the
!! explicit right-hand side O(n^3): the paper's reason RFEM wins at large n.
module ropedyn_mpp
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t, make_error, ERR_INPUT
    use ropedyn_problem, only: energy_t, STATUS_OK, STATUS_RECOVERABLE
    use ropedyn_rope_model, only: rope_model_t
    use ropedyn_scene, only: scene_t, bottom_anchor_given
    implicit none
    private
    public :: mpp_t, mpp_create

    real(wp), parameter :: pi = 4.0_wp*atan(1.0_wp)

    type, extends(rope_model_t) :: mpp_t
        private
        integer :: n = 0            !< members
        integer :: nu = 0           !< spring coordinates (n or 0)
        integer :: ndof = 0         !< n + nu
        real(wp) :: l = 0.0_wp      !< member length, m
        real(wp) :: m = 0.0_wp      !< member mass, kg
        real(wp) :: inertia = 0.0_wp  !< rod inertia about its centre (with rotary inertia), kg m^2
        real(wp) :: g = 0.0_wp      !< gravity, m/s^2 (0 when off)
        real(wp) :: ks = 0.0_wp, ds = 0.0_wp  !< member spring stiffness N/m, damping N s/m
        real(wp) :: cb = 0.0_wp, db = 0.0_wp  !< joint bending stiffness N m, damping N m s
        logical :: top_clamped = .false.
        integer :: bottom = 0       !< 0 free, 1 pinned, 2 clamped
        real(wp) :: k_sup = 0.0_wp, d_sup = 0.0_wp    !< bottom pin spring and damper
        real(wp) :: c_rot = 0.0_wp, d_rot = 0.0_wp    !< support rotational spring and damper
        real(wp) :: top_anchor(2) = 0.0_wp, bottom_anchor(2) = 0.0_wp
        real(wp) :: top_angle = 0.0_wp, bottom_angle = 0.0_wp
        real(wp) :: init_angle = 0.0_wp
    contains
        procedure :: size => mpp_size
        procedure :: bandwidths => mpp_bandwidths
        procedure :: rhs => mpp_rhs
        procedure :: has_jacobian => mpp_has_jacobian
        procedure :: jacobian => mpp_jacobian
        procedure :: has_mass_matrix => mpp_has_mass_matrix
        procedure :: mass_matrix => mpp_mass_matrix
        procedure :: implicit_rhs => mpp_implicit_rhs
        procedure :: energy => mpp_energy
        procedure :: quad_size => mpp_quad_size
        procedure :: quad_rhs => mpp_quad_rhs
        procedure :: n_elements => mpp_n_elements
        procedure :: model_name => mpp_model_name
        procedure :: initial_state => mpp_initial_state
        procedure :: fields => mpp_fields
        procedure :: polyline => mpp_polyline
        procedure :: element_data => mpp_element_data
        procedure :: residual => mpp_residual
        procedure :: mass_dense => mpp_mass_dense
        procedure, private :: positions
    end type mpp_t

    interface
        subroutine dpotrf(uplo, n, a, lda, info)
            import :: wp
            character, intent(in) :: uplo
            integer, intent(in) :: n, lda
            real(wp), intent(inout) :: a(lda, *)
            integer, intent(out) :: info
        end subroutine dpotrf
        subroutine dpotrs(uplo, n, nrhs, a, lda, b, ldb, info)
            import :: wp
            character, intent(in) :: uplo
            integer, intent(in) :: n, nrhs, lda, ldb
            real(wp), intent(in) :: a(lda, *)
            real(wp), intent(inout) :: b(ldb, *)
            integer, intent(out) :: info
        end subroutine dpotrs
    end interface

contains

    subroutine mpp_create(model, scene, err)
        type(mpp_t), intent(out) :: model
        type(scene_t), intent(in) :: scene
        type(error_t), allocatable, intent(out) :: err
        real(wp) :: area, second_moment, total_mass, factor

        model%n = scene%model%elements
        if (model%n < 1) then
            call make_error(err, ERR_INPUT, 'mpp: elements must be >= 1')
            return
        end if
        if (scene%supports%top == 'free') then
            call make_error(err, ERR_INPUT, 'mpp: the top support must be pinned or clamped')
            return
        end if
        model%nu = merge(model%n, 0, scene%effects%tension)
        model%ndof = model%n + model%nu
        area = pi*scene%rope%diameter**2/4.0_wp
        second_moment = pi*scene%rope%diameter**4/64.0_wp
        total_mass = scene%rope%density*area*scene%rope%length
        model%l = scene%rope%length/real(model%n, wp)
        model%m = total_mass/real(model%n, wp)
        model%inertia = model%m*(model%l**2/12.0_wp + scene%rope%diameter**2/16.0_wp)
        model%g = merge(scene%rope%gravity, 0.0_wp, scene%effects%gravity)
        model%ks = scene%rope%young_modulus*area/model%l
        if (scene%effects%bending) model%cb = scene%rope%young_modulus*second_moment/model%l
        if (scene%effects%damping) then
            model%ds = scene%model%mpp_axial_damping_factor* &
                       scene%rope%normal_damping*area/model%l
            if (scene%effects%bending) model%db = scene%model%mpp_bending_damping_factor* &
                                                  scene%rope%normal_damping*second_moment/model%l
        end if
        factor = scene%supports%support_stiffness_factor
        model%top_clamped = scene%supports%top == 'clamped'
        select case (scene%supports%bottom)
        case ('pinned')
            model%bottom = 1
        case ('clamped')
            model%bottom = 2
        case default
            model%bottom = 0
        end select
        ! Supports take the values of the rope's own springs (as in RFEM), times the factor.
        model%k_sup = factor*scene%rope%young_modulus*area/model%l
        model%c_rot = factor*scene%rope%young_modulus*second_moment/model%l
        if (scene%effects%damping) then
            model%d_sup = factor*scene%rope%normal_damping*area/model%l
            model%d_rot = factor*scene%rope%normal_damping*second_moment/model%l
        end if

        if (scene%initial%shape == 'hanging') then
            model%init_angle = 0.0_wp
        else
            model%init_angle = scene%initial%angle_deg*pi/180.0_wp
        end if
        model%top_anchor = scene%supports%top_anchor
        model%top_angle = scene%supports%top_angle_deg*pi/180.0_wp
        model%bottom_angle = scene%supports%bottom_angle_deg*pi/180.0_wp
        if (bottom_anchor_given(scene)) then
            model%bottom_anchor = scene%supports%bottom_anchor
        else
            model%bottom_anchor = model%top_anchor + scene%rope%length* &
                                  [cos(model%init_angle), sin(model%init_angle)]
        end if
    end subroutine mpp_create

    pure integer function mpp_size(self)
        class(mpp_t), intent(in) :: self
        mpp_size = 2*self%ndof
    end function mpp_size

    !> M(q) and the Jacobian are dense.
    pure subroutine mpp_bandwidths(self, ml, mu)
        class(mpp_t), intent(in) :: self
        integer, intent(out) :: ml, mu
        ml = 2*self%ndof - 1
        mu = 2*self%ndof - 1
    end subroutine mpp_bandwidths

    pure integer function mpp_quad_size(self)
        class(mpp_t), intent(in) :: self
        mpp_quad_size = 1
    end function mpp_quad_size

    pure integer function mpp_n_elements(self)
        class(mpp_t), intent(in) :: self
        mpp_n_elements = self%n
    end function mpp_n_elements

    pure function mpp_model_name(self) result(name)
        class(mpp_t), intent(in) :: self
        character(len=:), allocatable :: name
        name = 'mpp'
    end function mpp_model_name

    pure logical function mpp_has_jacobian(self)
        class(mpp_t), intent(in) :: self
        mpp_has_jacobian = .true.
    end function mpp_has_jacobian

    pure logical function mpp_has_mass_matrix(self)
        class(mpp_t), intent(in) :: self
        mpp_has_mass_matrix = .true.
    end function mpp_has_mass_matrix

    subroutine mpp_element_data(self, length, mass)
        class(mpp_t), intent(in) :: self
        real(wp), intent(out) :: length(:), mass(:)
        length = self%l
        mass = self%m
    end subroutine mpp_element_data

    subroutine mpp_initial_state(self, y)
        class(mpp_t), intent(in) :: self
        real(wp), intent(out) :: y(:)
        y = 0.0_wp
        y(1:self%n) = self%init_angle
    end subroutine mpp_initial_state

    !> Split y into angles, elongations and their rates (elongations 0 if inextensible).
    pure subroutine unpack(self, y, phi, u, phid, ud)
        class(mpp_t), intent(in) :: self
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: phi(:), u(:), phid(:), ud(:)
        integer :: n, nd
        n = self%n
        nd = self%ndof
        phi = y(1:n)
        phid = y(nd + 1:nd + n)
        u = 0.0_wp
        ud = 0.0_wp
        if (self%nu > 0) then
            u = y(n + 1:nd)
            ud = y(nd + n + 1:2*nd)
        end if
    end subroutine unpack

    !> Joints P_0 .. P_n, rod centres C_i, and their velocities.
    pure subroutine positions(self, y, p, c, pd, cd)
        class(mpp_t), intent(in) :: self
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: p(2, 0:self%n), c(2, self%n), pd(2, 0:self%n), cd(2, self%n)
        real(wp), dimension(self%n) :: phi, u, phid, ud
        real(wp) :: e(2), nv(2)
        integer :: k
        call unpack(self, y, phi, u, phid, ud)
        p(:, 0) = self%top_anchor
        pd(:, 0) = 0.0_wp
        do k = 1, self%n
            e = [cos(phi(k)), sin(phi(k))]
            nv = [-e(2), e(1)]
            c(:, k) = p(:, k - 1) + (u(k) + 0.5_wp*self%l)*e
            cd(:, k) = pd(:, k - 1) + (u(k) + 0.5_wp*self%l)*phid(k)*nv + ud(k)*e
            p(:, k) = p(:, k - 1) + (self%l + u(k))*e
            pd(:, k) = pd(:, k - 1) + (self%l + u(k))*phid(k)*nv + ud(k)*e
        end do
    end subroutine positions

    !> The Lagrange residual r = Q(q, q') - sum_i m J_i^T C_i''(q, q', q'') - J phi''
    !! for the generalized accelerations qacc (size ndof), O(n).
    pure subroutine mpp_residual(self, y, qacc, r)
        class(mpp_t), intent(in) :: self
        real(wp), intent(in) :: y(:)
        real(wp), intent(in) :: qacc(:)
        real(wp), intent(out) :: r(:)
        real(wp), dimension(self%n) :: phi, u, phid, ud, phidd, udd, hk, lk
        real(wp) :: e(2, self%n), nv(2, self%n), pacc(2), cacc(2), w(2, self%n)
        real(wp) :: wsum(2), fb(2), pn(2), pnd(2), d, dd
        integer :: k, n, nd

        n = self%n
        nd = self%ndof
        call unpack(self, y, phi, u, phid, ud)
        phidd = qacc(1:n)
        udd = 0.0_wp
        if (self%nu > 0) udd = qacc(n + 1:nd)
        hk = u + 0.5_wp*self%l
        lk = u + self%l
        e(1, :) = cos(phi)
        e(2, :) = sin(phi)
        nv(1, :) = -e(2, :)
        nv(2, :) = e(1, :)

        ! Accelerations of the joints (prefix sums) and the applied-minus-inertial force on
        ! each rod: w_i = m g x - m C_i''.
        pacc = 0.0_wp
        pn = self%top_anchor
        pnd = 0.0_wp
        do k = 1, n
            cacc = pacc + (hk(k)*phidd(k) + 2.0_wp*ud(k)*phid(k))*nv(:, k) &
                   + (udd(k) - hk(k)*phid(k)**2)*e(:, k)
            pacc = pacc + (lk(k)*phidd(k) + 2.0_wp*ud(k)*phid(k))*nv(:, k) &
                   + (udd(k) - lk(k)*phid(k)**2)*e(:, k)
            w(:, k) = -self%m*cacc
            w(1, k) = w(1, k) + self%m*self%g
            pn = pn + lk(k)*e(:, k)
            pnd = pnd + lk(k)*phid(k)*nv(:, k) + ud(k)*e(:, k)
        end do

        ! Force of the bottom pin on the tip P_n.
        fb = 0.0_wp
        if (self%bottom > 0) fb = -self%k_sup*(pn - self%bottom_anchor) - self%d_sup*pnd

        ! Generalized forces by suffix sums: Q[phi_k] = n_k . (h_k w_k + l_k sum_{i>k} w_i
        ! + l_k F_b), Q[u_k] = e_k . (sum_{i>=k} w_i + F_b).
        wsum = fb
        do k = n, 1, -1
            r(k) = dot_product(nv(:, k), hk(k)*w(:, k) + lk(k)*wsum)
            wsum = wsum + w(:, k)
            if (self%nu > 0) r(n + k) = dot_product(e(:, k), wsum)
        end do
        r(1:n) = r(1:n) - self%inertia*phidd

        ! Member springs and dampers.
        if (self%nu > 0) r(n + 1:nd) = r(n + 1:nd) - self%ks*u - self%ds*ud
        ! Joint bending springs and dampers between members.
        if (self%cb > 0.0_wp .or. self%db > 0.0_wp) then
            do k = 2, n
                d = self%cb*(phi(k) - phi(k - 1)) + self%db*(phid(k) - phid(k - 1))
                r(k) = r(k) - d
                r(k - 1) = r(k - 1) + d
            end do
        end if
        ! Rotational springs of clamped supports.
        if (self%top_clamped) then
            dd = self%c_rot*(phi(1) - self%top_angle) + self%d_rot*phid(1)
            r(1) = r(1) - dd
        end if
        if (self%bottom == 2) then
            dd = self%c_rot*(phi(n) - self%bottom_angle) + self%d_rot*phid(n)
            r(n) = r(n) - dd
        end if
    end subroutine mpp_residual

    !> The dense mass matrix M(q) (ndof x ndof), O(n^2).
    pure subroutine mpp_mass_dense(self, y, mm)
        class(mpp_t), intent(in) :: self
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: mm(:, :)
        real(wp), dimension(self%n) :: phi, u, phid, ud, hk, lk
        real(wp) :: cjk, sjk, s
        integer :: k, j, n
        n = self%n
        call unpack(self, y, phi, u, phid, ud)
        hk = u + 0.5_wp*self%l
        lk = u + self%l
        mm = 0.0_wp
        do j = 1, n
            do k = 1, j
                cjk = cos(phi(k) - phi(j))
                sjk = sin(phi(j) - phi(k))     ! n_k . e_j
                if (k < j) then
                    s = lk(k)*(hk(j) + real(n - j, wp)*lk(j))
                else
                    s = hk(k)**2 + real(n - k, wp)*lk(k)**2
                end if
                mm(k, j) = self%m*cjk*s
                mm(j, k) = mm(k, j)
                if (self%nu > 0) then
                    mm(n + k, n + j) = self%m*cjk*real(n - j + 1, wp)
                    mm(n + j, n + k) = mm(n + k, n + j)
                    ! (phi_k, u_j), k <= j
                    if (k < j) then
                        s = real(n - j + 1, wp)*lk(k)
                    else
                        s = hk(k) + real(n - k, wp)*lk(k)
                    end if
                    mm(k, n + j) = self%m*sjk*s
                    mm(n + j, k) = mm(k, n + j)
                    ! (phi_j, u_k), k < j: n_j . e_k = -sjk
                    if (k < j) then
                        mm(j, n + k) = -self%m*sjk*(hk(j) + real(n - j, wp)*lk(j))
                        mm(n + k, j) = mm(j, n + k)
                    end if
                end if
            end do
            mm(j, j) = mm(j, j) + self%inertia
        end do
    end subroutine mpp_mass_dense

    !> y' = (q', M^{-1} f): f = r(q, q', 0), solved by Cholesky.
    subroutine mpp_rhs(self, t, y, ydot, status)
        class(mpp_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: ydot(:)
        integer, intent(out) :: status
        real(wp) :: mm(self%ndof, self%ndof), f(self%ndof, 1), zero(self%ndof)
        integer :: nd, info
        nd = self%ndof
        zero = 0.0_wp
        call self%residual(y, zero, f(:, 1))
        call self%mass_dense(y, mm)
        call dpotrf('L', nd, mm, nd, info)
        if (info == 0) call dpotrs('L', nd, 1, mm, nd, f, nd, info)
        ydot(1:nd) = y(nd + 1:2*nd)
        ydot(nd + 1:2*nd) = f(:, 1)
        status = STATUS_OK
        if (info /= 0 .or. .not. all(ieee_is_finite(f))) status = STATUS_RECOVERABLE
    end subroutine mpp_rhs

    !> F = (q', f(q, q')) of the implicit form M(y) y' = F, O(n).
    subroutine mpp_implicit_rhs(self, t, y, f, status)
        class(mpp_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: f(:)
        integer, intent(out) :: status
        real(wp) :: zero(self%ndof)
        integer :: nd
        nd = self%ndof
        zero = 0.0_wp
        f(1:nd) = y(nd + 1:2*nd)
        call self%residual(y, zero, f(nd + 1:2*nd))
        status = STATUS_OK
        if (.not. all(ieee_is_finite(f))) status = STATUS_RECOVERABLE
    end subroutine mpp_implicit_rhs

    !> blockdiag(I, M(q)) in band storage (the band is the full matrix).
    subroutine mpp_mass_matrix(self, t, y, mb, offset, status)
        class(mpp_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(inout) :: mb(:, :)
        integer, intent(in) :: offset
        integer, intent(out) :: status
        real(wp) :: mm(self%ndof, self%ndof)
        integer :: i, j, nd
        nd = self%ndof
        call self%mass_dense(y, mm)
        do j = 1, nd
            mb(offset, j) = mb(offset, j) + 1.0_wp
            do i = 1, nd
                mb(offset + i - j, nd + j) = mb(offset + i - j, nd + j) + mm(i, j)
            end do
        end do
        status = STATUS_OK
    end subroutine mpp_mass_matrix

    !> Jacobian of y' = (q', a), a = M^{-1} f. With a0 = a(y) held fixed, M a = f gives
    !! da/dz = M^{-1} d r(q, q', a0)/dz (z = q or q'), exact: the residual's difference
    !! quotients are O(n) each, then one Cholesky solve with 2 ndof right-hand sides.
    subroutine mpp_jacobian(self, t, y, jb, offset, status)
        class(mpp_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(inout) :: jb(:, :)
        integer, intent(in) :: offset
        integer, intent(out) :: status
        real(wp) :: mm(self%ndof, self%ndof), a0(self%ndof, 1), r0(self%ndof)
        real(wp) :: dr(self%ndof, 2*self%ndof), yp(size(y)), zero(self%ndof), inc
        integer :: nd, j, i, info
        nd = self%ndof
        zero = 0.0_wp
        call self%residual(y, zero, a0(:, 1))
        call self%mass_dense(y, mm)
        call dpotrf('L', nd, mm, nd, info)
        if (info /= 0) then
            status = STATUS_RECOVERABLE
            return
        end if
        call dpotrs('L', nd, 1, mm, nd, a0, nd, info)
        call self%residual(y, a0(:, 1), r0)
        do j = 1, 2*nd
            yp = y
            inc = sqrt(epsilon(1.0_wp))*max(abs(y(j)), 1.0e-3_wp)
            yp(j) = y(j) + inc
            call self%residual(yp, a0(:, 1), dr(:, j))
            dr(:, j) = (dr(:, j) - r0)/inc
        end do
        call dpotrs('L', nd, 2*nd, mm, nd, dr, nd, info)
        ! rows 1..nd: dq'/dv = I; rows nd+1..2nd: da/dy
        do j = 1, nd
            jb(offset + j - (nd + j), nd + j) = jb(offset + j - (nd + j), nd + j) + 1.0_wp
        end do
        do j = 1, 2*nd
            do i = 1, nd
                jb(offset + nd + i - j, j) = jb(offset + nd + i - j, j) + dr(i, j)
            end do
        end do
        status = STATUS_OK
        if (.not. all(ieee_is_finite(dr))) status = STATUS_RECOVERABLE
    end subroutine mpp_jacobian

    function mpp_energy(self, t, y, yq) result(en)
        class(mpp_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(in) :: yq(:)
        type(energy_t) :: en
        real(wp) :: p(2, 0:self%n), c(2, self%n), pd(2, 0:self%n), cd(2, self%n)
        real(wp), dimension(self%n) :: phi, u, phid, ud
        integer :: k, n
        n = self%n
        call unpack(self, y, phi, u, phid, ud)
        call self%positions(y, p, c, pd, cd)
        en%kinetic = 0.5_wp*(self%m*sum(cd**2) + self%inertia*sum(phid**2))
        en%gravity = -self%m*self%g*sum(c(1, :))
        en%elastic = 0.5_wp*self%ks*sum(u**2)
        do k = 2, n
            en%elastic = en%elastic + 0.5_wp*self%cb*(phi(k) - phi(k - 1))**2
        end do
        if (self%top_clamped) en%elastic = en%elastic + 0.5_wp*self%c_rot* &
                                            (phi(1) - self%top_angle)**2
        if (self%bottom > 0) en%elastic = en%elastic + 0.5_wp*self%k_sup* &
                                          sum((p(:, n) - self%bottom_anchor)**2)
        if (self%bottom == 2) en%elastic = en%elastic + 0.5_wp*self%c_rot* &
                                           (phi(n) - self%bottom_angle)**2
        en%dissipated = 0.0_wp
        if (size(yq) >= 1) en%dissipated = yq(1)
        en%support_work = 0.0_wp
    end function mpp_energy

    !> Dissipation power 2D, W.
    subroutine mpp_quad_rhs(self, t, y, yqdot, status)
        class(mpp_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: yqdot(:)
        integer, intent(out) :: status
        real(wp), dimension(self%n) :: phi, u, phid, ud
        real(wp) :: power, pnd(2)
        integer :: k, n
        n = self%n
        call unpack(self, y, phi, u, phid, ud)
        power = self%ds*sum(ud**2)
        do k = 2, n
            power = power + self%db*(phid(k) - phid(k - 1))**2
        end do
        if (self%top_clamped) power = power + self%d_rot*phid(1)**2
        if (self%bottom > 0) then
            pnd = 0.0_wp
            do k = 1, n
                pnd = pnd + (self%l + u(k))*phid(k)*[-sin(phi(k)), cos(phi(k))] &
                      + ud(k)*[cos(phi(k)), sin(phi(k))]
            end do
            power = power + self%d_sup*sum(pnd**2)
        end if
        if (self%bottom == 2) power = power + self%d_rot*phid(n)**2
        yqdot(1) = power
        status = STATUS_OK
        if (.not. ieee_is_finite(power)) status = STATUS_RECOVERABLE
    end subroutine mpp_quad_rhs

    !> Members as elements: rod centre, angle and their rates.
    subroutine mpp_fields(self, y, q, qdot)
        class(mpp_t), intent(in) :: self
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: q(:, :), qdot(:, :)
        real(wp) :: p(2, 0:self%n), c(2, self%n), pd(2, 0:self%n), cd(2, self%n)
        call self%positions(y, p, c, pd, cd)
        q(1:2, :) = c
        q(3, :) = y(1:self%n)
        qdot(1:2, :) = cd
        qdot(3, :) = y(self%ndof + 1:self%ndof + self%n)
    end subroutine mpp_fields

    !> Member i drawn from joint P_{i-1} to joint P_i (spring and rod).
    subroutine mpp_polyline(self, y, points)
        class(mpp_t), intent(in) :: self
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: points(:, :)
        real(wp) :: p(2, 0:self%n), c(2, self%n), pd(2, 0:self%n), cd(2, self%n)
        integer :: i
        call self%positions(y, p, c, pd, cd)
        do i = 1, self%n
            points(:, 2*i - 1) = p(:, i - 1)
            points(:, 2*i) = p(:, i)
        end do
    end subroutine mpp_polyline
end module ropedyn_mpp
