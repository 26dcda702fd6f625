!> The rigid finite element (RFEM) rope model of Kaminski & Fritzkowski.
!!
!! n rigid elements (end elements of length dl/2, the others dl, dl = L/(n-1)) joined by
!! spring-damping elements (SDEs). SDE j (j = 1 .. n+1) joins element j-1 to element j;
!! elements 0 and n+1 are the supports. Its deformation, in the frame of element j-1, is
!! (tension, shear, bending) = (e_{j-1}.d, n_{j-1}.d, phi_j - phi_{j-1}), d = A_j - B_{j-1}.
!! The derivation (forces, the analytic Jacobian) is in docs/physics-rfem.md.
!!
!! Every deformation measure ("strain") s(q) enters as energy C s^2/2 and dissipation
!! B (ds/dt)^2/2, so its generalized force is -(C s + B s') grad s. Strains of one kind
!! form a family; a family exists only when its effect is on in &effects, and damping
!! terms are evaluated only when damping is on. Nothing is computed for an effect that is
!! off.
!!
!! State y (size 6n), element by element: x_i, y_i, phi_i, x_i', y_i', phi_i'.
module ropedyn_rfem
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t, make_error, ERR_INPUT
    use ropedyn_problem, only: energy_t, STATUS_OK, STATUS_RECOVERABLE
    use ropedyn_rope_model, only: rope_model_t
    use ropedyn_scene, only: scene_t, bottom_anchor_given
    implicit none
    private
    public :: rfem_t, rfem_create

    real(wp), parameter :: pi = acos(-1.0_wp)

    !> Strain families.
    integer, parameter :: FAM_TENSION = 1, FAM_SHEAR = 2, FAM_BEND = 3
    integer, parameter :: FAM_TOP_X = 4, FAM_TOP_Y = 5, FAM_TOP_ROT = 6
    integer, parameter :: FAM_BOTTOM_X = 7, FAM_BOTTOM_Y = 8, FAM_BOTTOM_ROT = 9

    !> A set of SDE strains of one kind with common stiffness and damping.
    type :: family_t
        integer :: kind = 0
        integer :: first = 0, last = -1  !< SDE range
        real(wp) :: c = 0.0_wp           !< stiffness (N/m or N m/rad)
        real(wp) :: b = 0.0_wp           !< damping (N s/m or N m s/rad)
        logical :: damped = .false.
    end type family_t

    type, extends(rope_model_t) :: rfem_t
        private
        integer :: n = 0                       !< number of rigid elements
        real(wp), allocatable :: len(:)        !< element lengths, m
        real(wp), allocatable :: mass(:)       !< element masses, kg
        real(wp), allocatable :: inertia(:)    !< central moments of inertia, kg m^2
        real(wp) :: g = 0.0_wp                 !< gravity, m/s^2
        logical :: gravity_on = .false.
        type(family_t), allocatable :: families(:)
        real(wp) :: top_anchor(2) = 0.0_wp     !< m
        real(wp) :: bottom_anchor(2) = 0.0_wp  !< m
        real(wp) :: top_angle = 0.0_wp         !< clamp angle, rad
        real(wp) :: bottom_angle = 0.0_wp      !< clamp angle, rad
        real(wp) :: init_angle = 0.0_wp        !< angle of the straight initial state, rad
        ! workspace (no state is kept between calls)
        real(wp), allocatable :: s(:)          !< strains of the current family
        real(wp), allocatable :: grad(:, :)    !< their gradients, (6, n+1)
        real(wp), allocatable :: force(:)      !< C s + B s' per SDE
        real(wp), allocatable :: gen(:, :)     !< generalized forces, (3, n)
    contains
        procedure :: size => rfem_size
        procedure :: bandwidths => rfem_bandwidths
        procedure :: rhs => rfem_rhs
        procedure :: has_jacobian => rfem_has_jacobian
        procedure :: jacobian => rfem_jacobian
        procedure :: energy => rfem_energy
        procedure :: quad_size => rfem_quad_size
        procedure :: quad_rhs => rfem_quad_rhs
        procedure :: n_elements => rfem_n_elements
        procedure :: model_name => rfem_model_name
        procedure :: initial_state => rfem_initial_state
        procedure :: fields => rfem_fields
        procedure :: polyline => rfem_polyline
        procedure :: element_data => rfem_element_data
        procedure :: generalized_forces => rfem_generalized_forces
        procedure :: potential_energy => rfem_potential_energy
        procedure, private :: strain
        procedure, private :: local_rates
    end type rfem_t

contains

    !> Build the model of a scene (scene values are already validated).
    subroutine rfem_create(model, scene, err)
        type(rfem_t), intent(out) :: model
        type(scene_t), intent(in) :: scene
        type(error_t), allocatable, intent(out) :: err
        integer :: n, nf
        real(wp) :: area, second_moment, dl, total_mass, cx, cy, cphi, bx, by, bphi, factor
        type(family_t) :: fams(9)
        logical :: damped

        n = scene%model%elements
        if (n < 2) then
            call make_error(err, ERR_INPUT, 'rfem: elements must be >= 2')
            return
        end if
        model%n = n
        area = pi*scene%rope%diameter**2/4.0_wp
        second_moment = pi*scene%rope%diameter**4/64.0_wp
        dl = scene%rope%length/real(n - 1, wp)
        total_mass = scene%rope%density*area*scene%rope%length
        allocate (model%len(n), model%mass(n), model%inertia(n))
        model%len = dl
        model%len(1) = dl/2.0_wp
        model%len(n) = dl/2.0_wp
        model%mass = total_mass*model%len/scene%rope%length
        model%inertia = model%mass*(model%len**2/12.0_wp + scene%rope%diameter**2/16.0_wp)

        model%g = scene%rope%gravity
        model%gravity_on = scene%effects%gravity
        damped = scene%effects%damping

        cx = scene%rope%young_modulus*area/dl
        cy = scene%rope%shear_modulus*area/(scene%rope%shape_factor*dl)
        cphi = scene%rope%young_modulus*second_moment/dl
        bx = scene%rope%normal_damping*area/dl
        by = scene%rope%tangential_damping*area/(scene%rope%shape_factor*dl)
        bphi = scene%rope%normal_damping*second_moment/dl
        factor = scene%supports%support_stiffness_factor

        nf = 0
        if (scene%effects%tension) call add(FAM_TENSION, 2, n, cx, bx)
        if (scene%effects%shear) call add(FAM_SHEAR, 2, n, cy, by)
        if (scene%effects%bending) call add(FAM_BEND, 2, n, cphi, bphi)
        select case (scene%supports%top)
        case ('pinned')
            call add(FAM_TOP_X, 1, 1, factor*cx, factor*bx)
            call add(FAM_TOP_Y, 1, 1, factor*cx, factor*bx)
        case ('clamped')
            call add(FAM_TOP_X, 1, 1, factor*cx, factor*bx)
            call add(FAM_TOP_Y, 1, 1, factor*cx, factor*bx)
            call add(FAM_TOP_ROT, 1, 1, factor*cphi, factor*bphi)
        end select
        select case (scene%supports%bottom)
        case ('pinned')
            call add(FAM_BOTTOM_X, n + 1, n + 1, factor*cx, factor*bx)
            call add(FAM_BOTTOM_Y, n + 1, n + 1, factor*cx, factor*bx)
        case ('clamped')
            call add(FAM_BOTTOM_X, n + 1, n + 1, factor*cx, factor*bx)
            call add(FAM_BOTTOM_Y, n + 1, n + 1, factor*cx, factor*bx)
            call add(FAM_BOTTOM_ROT, n + 1, n + 1, factor*cphi, factor*bphi)
        end select
        model%families = fams(1:nf)

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

        allocate (model%s(n + 1), model%grad(6, n + 1), model%force(n + 1), model%gen(3, n))
        model%s = 0.0_wp
        model%grad = 0.0_wp
        model%force = 0.0_wp
        model%gen = 0.0_wp
    contains
        subroutine add(kind, first, last, c, b)
            integer, intent(in) :: kind, first, last
            real(wp), intent(in) :: c, b
            nf = nf + 1
            fams(nf) = family_t(kind=kind, first=first, last=last, c=c, b=b, &
                                damped=damped .and. b > 0.0_wp)
        end subroutine add
    end subroutine rfem_create

    pure integer function rfem_size(self)
        class(rfem_t), intent(in) :: self
        rfem_size = 6*self%n
    end function rfem_size

    !> Element i's accelerations depend on elements i-1, i, i+1 (see the module header).
    pure subroutine rfem_bandwidths(self, ml, mu)
        class(rfem_t), intent(in) :: self
        integer, intent(out) :: ml, mu
        ml = min(11, 6*self%n - 1)
        mu = min(8, 6*self%n - 1)
    end subroutine rfem_bandwidths

    pure integer function rfem_quad_size(self)
        class(rfem_t), intent(in) :: self
        rfem_quad_size = 1
    end function rfem_quad_size

    pure integer function rfem_n_elements(self)
        class(rfem_t), intent(in) :: self
        rfem_n_elements = self%n
    end function rfem_n_elements

    pure function rfem_model_name(self) result(name)
        class(rfem_t), intent(in) :: self
        character(len=:), allocatable :: name
        name = 'rfem'
    end function rfem_model_name

    subroutine rfem_element_data(self, length, mass)
        class(rfem_t), intent(in) :: self
        real(wp), intent(out) :: length(:), mass(:)
        length = self%len
        mass = self%mass
    end subroutine rfem_element_data

    !> Straight rope from the top anchor at the initial angle, at rest, unstretched.
    subroutine rfem_initial_state(self, y)
        class(rfem_t), intent(in) :: self
        real(wp), intent(out) :: y(:)
        integer :: i, k
        real(wp) :: s_start, dir(2)
        dir = [cos(self%init_angle), sin(self%init_angle)]
        y = 0.0_wp
        s_start = 0.0_wp
        do i = 1, self%n
            k = 6*(i - 1)
            y(k + 1:k + 2) = self%top_anchor + (s_start + self%len(i)/2.0_wp)*dir
            y(k + 3) = self%init_angle
            s_start = s_start + self%len(i)
        end do
    end subroutine rfem_initial_state

    subroutine rfem_fields(self, y, q, qdot)
        class(rfem_t), intent(in) :: self
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: q(:, :), qdot(:, :)
        integer :: i
        do i = 1, self%n
            q(:, i) = y(6*(i - 1) + 1:6*(i - 1) + 3)
            qdot(:, i) = y(6*(i - 1) + 4:6*(i - 1) + 6)
        end do
    end subroutine rfem_fields

    subroutine rfem_polyline(self, y, points)
        class(rfem_t), intent(in) :: self
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: points(:, :)
        integer :: i, k
        real(wp) :: e(2)
        do i = 1, self%n
            k = 6*(i - 1)
            e = [cos(y(k + 3)), sin(y(k + 3))]
            points(:, 2*i - 1) = y(k + 1:k + 2) - (self%len(i)/2.0_wp)*e
            points(:, 2*i) = y(k + 1:k + 2) + (self%len(i)/2.0_wp)*e
        end do
    end subroutine rfem_polyline

    !> Strain s and gradient g (local dofs: x, y, phi of element j-1, then of element j)
    !! of SDE j in family `kind`; optionally the Hessian h.
    pure subroutine strain(self, kind, j, y, s, g, h)
        class(rfem_t), intent(in) :: self
        integer, intent(in) :: kind, j
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: s, g(6)
        real(wp), intent(out), optional :: h(6, 6)
        integer :: ka, kb
        real(wp) :: ea(2), na(2), eb(2), nb(2), d(2), u(2), la, lb, dwx, dwy

        g = 0.0_wp
        if (present(h)) h = 0.0_wp
        select case (kind)
        case (FAM_TENSION, FAM_SHEAR)
            ka = 6*(j - 2)
            kb = 6*(j - 1)
            la = self%len(j - 1)
            lb = self%len(j)
            ea = [cos(y(ka + 3)), sin(y(ka + 3))]
            na = [-ea(2), ea(1)]
            eb = [cos(y(kb + 3)), sin(y(kb + 3))]
            nb = [-eb(2), eb(1)]
            d = y(kb + 1:kb + 2) - 0.5_wp*lb*eb - y(ka + 1:ka + 2) - 0.5_wp*la*ea
            dwx = dot_product(ea, d)
            dwy = dot_product(na, d)
            if (kind == FAM_TENSION) then
                s = dwx
                g = [-ea(1), -ea(2), dwy, ea(1), ea(2), -0.5_wp*lb*dot_product(ea, nb)]
                if (present(h)) then
                    call sym(h, 3, 1, -na(1))
                    call sym(h, 3, 2, -na(2))
                    call sym(h, 3, 4, na(1))
                    call sym(h, 3, 5, na(2))
                    call sym(h, 6, 3, -0.5_wp*lb*dot_product(na, nb))
                    h(3, 3) = -dwx - 0.5_wp*la
                    h(6, 6) = 0.5_wp*lb*dot_product(ea, eb)
                end if
            else
                s = dwy
                g = [-na(1), -na(2), -dwx - 0.5_wp*la, na(1), na(2), -0.5_wp*lb*dot_product(na, nb)]
                if (present(h)) then
                    call sym(h, 3, 1, ea(1))
                    call sym(h, 3, 2, ea(2))
                    call sym(h, 3, 4, -ea(1))
                    call sym(h, 3, 5, -ea(2))
                    call sym(h, 6, 3, 0.5_wp*lb*dot_product(ea, nb))
                    h(3, 3) = -dwy
                    h(6, 6) = 0.5_wp*lb*dot_product(na, eb)
                end if
            end if
        case (FAM_BEND)
            s = y(6*(j - 1) + 3) - y(6*(j - 2) + 3)
            g(3) = -1.0_wp
            g(6) = 1.0_wp
        case (FAM_TOP_X, FAM_TOP_Y)
            ! d = A_1 - P_top, strain along a fixed global axis u
            u = merge([1.0_wp, 0.0_wp], [0.0_wp, 1.0_wp], kind == FAM_TOP_X)
            lb = self%len(1)
            eb = [cos(y(3)), sin(y(3))]
            nb = [-eb(2), eb(1)]
            d = y(1:2) - 0.5_wp*lb*eb - self%top_anchor
            s = dot_product(u, d)
            g(4:6) = [u(1), u(2), -0.5_wp*lb*dot_product(u, nb)]
            if (present(h)) h(6, 6) = 0.5_wp*lb*dot_product(u, eb)
        case (FAM_TOP_ROT)
            s = y(3) - self%top_angle
            g(6) = 1.0_wp
        case (FAM_BOTTOM_X, FAM_BOTTOM_Y)
            ! d = P_bottom - B_n
            u = merge([1.0_wp, 0.0_wp], [0.0_wp, 1.0_wp], kind == FAM_BOTTOM_X)
            ka = 6*(self%n - 1)
            la = self%len(self%n)
            ea = [cos(y(ka + 3)), sin(y(ka + 3))]
            na = [-ea(2), ea(1)]
            d = self%bottom_anchor - y(ka + 1:ka + 2) - 0.5_wp*la*ea
            s = dot_product(u, d)
            g(1:3) = [-u(1), -u(2), -0.5_wp*la*dot_product(u, na)]
            if (present(h)) h(3, 3) = 0.5_wp*la*dot_product(u, ea)
        case (FAM_BOTTOM_ROT)
            s = self%bottom_angle - y(6*(self%n - 1) + 3)
            g(3) = -1.0_wp
        case default
            s = 0.0_wp
        end select
    contains
        pure subroutine sym(a, r, c, v)
            real(wp), intent(inout) :: a(6, 6)
            integer, intent(in) :: r, c
            real(wp), intent(in) :: v
            a(r, c) = v
            a(c, r) = v
        end subroutine sym
    end subroutine strain

    !> Velocities of the local dofs of SDE j (zero for a support).
    pure function local_rates(self, j, y) result(v)
        class(rfem_t), intent(in) :: self
        integer, intent(in) :: j
        real(wp), intent(in) :: y(:)
        real(wp) :: v(6)
        v = 0.0_wp
        if (j >= 2) v(1:3) = y(6*(j - 2) + 4:6*(j - 2) + 6)
        if (j <= self%n) v(4:6) = y(6*(j - 1) + 4:6*(j - 1) + 6)
    end function local_rates

    !> Generalized forces (3, n) of all enabled effects at state y; optionally the
    !! elastic energy (J). (The dissipation power is `quad_rhs`.)
    subroutine rfem_generalized_forces(self, y, gen, elastic)
        class(rfem_t), intent(inout) :: self
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: gen(:, :)
        real(wp), intent(out), optional :: elastic
        integer :: f, j
        real(wp) :: sd

        gen = 0.0_wp
        if (present(elastic)) elastic = 0.0_wp
        if (self%gravity_on) gen(1, :) = self%mass*self%g
        do f = 1, size(self%families)
            associate (fam => self%families(f))
                do j = fam%first, fam%last
                    call self%strain(fam%kind, j, y, self%s(j), self%grad(:, j))
                end do
                self%force(fam%first:fam%last) = fam%c*self%s(fam%first:fam%last)
                if (present(elastic)) elastic = elastic + &
                    0.5_wp*fam%c*sum(self%s(fam%first:fam%last)**2)
                if (fam%damped) then
                    do j = fam%first, fam%last
                        sd = dot_product(self%grad(:, j), self%local_rates(j, y))
                        self%force(j) = self%force(j) + fam%b*sd
                    end do
                end if
                do j = fam%first, fam%last
                    if (j >= 2) gen(:, j - 1) = gen(:, j - 1) - self%force(j)*self%grad(1:3, j)
                    if (j <= self%n) gen(:, j) = gen(:, j) - self%force(j)*self%grad(4:6, j)
                end do
            end associate
        end do
    end subroutine rfem_generalized_forces

    subroutine rfem_rhs(self, t, y, ydot, status)
        class(rfem_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: ydot(:)
        integer, intent(out) :: status
        integer :: i, k

        call self%generalized_forces(y, self%gen)
        do i = 1, self%n
            k = 6*(i - 1)
            ydot(k + 1:k + 3) = y(k + 4:k + 6)
            ydot(k + 4) = self%gen(1, i)/self%mass(i)
            ydot(k + 5) = self%gen(2, i)/self%mass(i)
            ydot(k + 6) = self%gen(3, i)/self%inertia(i)
        end do
        status = STATUS_OK
        if (.not. all(ieee_is_finite(ydot))) status = STATUS_RECOVERABLE
    end subroutine rfem_rhs

    !> Analytic Jacobian of the first-order system, banded. For each strain:
    !! dF/dq = -C g g^T - (C s + B s') H - B g (H q')^T,  dF/dq' = -B g g^T.
    !> The RFEM Jacobian is analytic.
    pure logical function rfem_has_jacobian(self) result(has)
        class(rfem_t), intent(in) :: self
        has = .true.
    end function rfem_has_jacobian

    subroutine rfem_jacobian(self, t, y, jb, offset, status)
        class(rfem_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(inout) :: jb(:, :)
        integer, intent(in) :: offset
        integer, intent(out) :: status
        integer :: i, c, f, j, r, l, row, col_q, col_v, er, el
        real(wp) :: s, g(6), h(6, 6), v(6), hv(6), sd, coef, kq(6, 6), kv(6, 6), inv_m(6)

        ! d(position)/dt = velocity
        do i = 1, self%n
            do c = 1, 3
                row = 6*(i - 1) + c
                jb(offset - 3, row + 3) = jb(offset - 3, row + 3) + 1.0_wp
            end do
        end do
        do f = 1, size(self%families)
            associate (fam => self%families(f))
                do j = fam%first, fam%last
                    call self%strain(fam%kind, j, y, s, g, h)
                    coef = fam%c*s
                    kq = -fam%c*outer(g, g)
                    if (fam%damped) then
                        v = self%local_rates(j, y)
                        sd = dot_product(g, v)
                        hv = matmul(h, v)
                        coef = coef + fam%b*sd
                        kq = kq - fam%b*outer(g, hv)
                        kv = -fam%b*outer(g, g)
                    end if
                    kq = kq - coef*h
                    ! scatter: local dof r belongs to element er = j-1 (r <= 3) or j (r > 3)
                    inv_m = 0.0_wp
                    if (j >= 2) inv_m(1:3) = 1.0_wp/[self%mass(j - 1), self%mass(j - 1), &
                                                     self%inertia(j - 1)]
                    if (j <= self%n) inv_m(4:6) = 1.0_wp/[self%mass(j), self%mass(j), &
                                                          self%inertia(j)]
                    do r = 1, 6
                        if (inv_m(r) == 0.0_wp) cycle
                        er = j - 1 + (r - 1)/3
                        row = 6*(er - 1) + 3 + mod(r - 1, 3) + 1
                        do l = 1, 6
                            if (inv_m(l) == 0.0_wp) cycle
                            el = j - 1 + (l - 1)/3
                            col_q = 6*(el - 1) + mod(l - 1, 3) + 1
                            col_v = col_q + 3
                            jb(offset + row - col_q, col_q) = jb(offset + row - col_q, col_q) &
                                                              + kq(r, l)*inv_m(r)
                            if (fam%damped) jb(offset + row - col_v, col_v) = &
                                jb(offset + row - col_v, col_v) + kv(r, l)*inv_m(r)
                        end do
                    end do
                end do
            end associate
        end do
        status = STATUS_OK
    contains
        pure function outer(a, b) result(m)
            real(wp), intent(in) :: a(6), b(6)
            real(wp) :: m(6, 6)
            integer :: p
            do p = 1, 6
                m(:, p) = a*b(p)
            end do
        end function outer
    end subroutine rfem_jacobian

    !> Potential energy V = elastic + gravity, J (used by the gradient test).
    function rfem_potential_energy(self, y) result(v)
        class(rfem_t), intent(inout) :: self
        real(wp), intent(in) :: y(:)
        real(wp) :: v
        type(energy_t) :: e
        e = self%energy(0.0_wp, y, [0.0_wp])
        v = e%elastic + e%gravity
    end function rfem_potential_energy

    function rfem_energy(self, t, y, yq) result(e)
        class(rfem_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(in) :: yq(:)
        type(energy_t) :: e
        integer :: i, k, f, j
        real(wp) :: s, g(6)

        e%kinetic = 0.0_wp
        e%gravity = 0.0_wp
        do i = 1, self%n
            k = 6*(i - 1)
            e%kinetic = e%kinetic + 0.5_wp*(self%mass(i)*(y(k + 4)**2 + y(k + 5)**2) + &
                                            self%inertia(i)*y(k + 6)**2)
            if (self%gravity_on) e%gravity = e%gravity - self%mass(i)*self%g*y(k + 1)
        end do
        e%elastic = 0.0_wp
        do f = 1, size(self%families)
            do j = self%families(f)%first, self%families(f)%last
                call self%strain(self%families(f)%kind, j, y, s, g)
                e%elastic = e%elastic + 0.5_wp*self%families(f)%c*s**2
            end do
        end do
        e%dissipated = 0.0_wp
        if (size(yq) >= 1) e%dissipated = yq(1)
        e%support_work = 0.0_wp  ! supports are fixed: they do no work
    end function rfem_energy

    !> Quadrature: the dissipation power 2D = sum B s'^2, W.
    subroutine rfem_quad_rhs(self, t, y, yqdot, status)
        class(rfem_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: yqdot(:)
        integer, intent(out) :: status
        real(wp) :: power, s, g(6)
        integer :: f, j
        ! only the damped strains: no spring forces, no gravity, no scatter
        power = 0.0_wp
        do f = 1, size(self%families)
            if (.not. self%families(f)%damped) cycle
            do j = self%families(f)%first, self%families(f)%last
                call self%strain(self%families(f)%kind, j, y, s, g)
                power = power + self%families(f)%b*dot_product(g, self%local_rates(j, y))**2
            end do
        end do
        yqdot(1) = power
        status = STATUS_OK
        if (.not. ieee_is_finite(power)) status = STATUS_RECOVERABLE
    end subroutine rfem_quad_rhs
end module ropedyn_rfem
