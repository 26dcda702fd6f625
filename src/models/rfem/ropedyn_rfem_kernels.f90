!> The RFEM kernels: generalized forces, right-hand side, the analytic Jacobian as blocks of
!! element pairs (written into the band by ropedyn_rfem_jacobian), energies and the
!! dissipation and external power (the derivation is in docs/theory/rfem.md).
!!
!! Each kernel makes one pass over the internal SDEs j = 2 .. n (elements a = j-1, b = j),
!! with cos and sin of every angle computed once per call (self%cs), and takes the geometry
!! of each SDE from `sde_at` (and its rates from `sde_rates`):
!!     d = c_b - h_b e_b - c_a - h_a e_a,  dwx = e_a.d (tension),  dwy = n_a.d (shear),
!!     cd = e_a.e_b = cos(phi_b - phi_a),  sd = n_a.e_b = sin(phi_b - phi_a),
!! the strain rates (only when damping is on)
!!     rx = e_a.(v_b - v_a) + dwy w_a + h_b sd w_b,
!!     ry = n_a.(v_b - v_a) - (dwx + h_a) w_a - h_b cd w_b,   rp = w_b - w_a,
!! the SDE forces fx = Cx dwx + Bx rx, fy = Cy dwy + By ry, fp = Cp (phi_b - phi_a) + Bp rp
!! (each only when its strain is on) and, with F = fx e_a + fy n_a, the generalized forces
!!     element a: (F, fy (dwx + h_a) - fx dwy + fp),   element b: (-F, -h_b (fx sd - fy cd) - fp).
!! The Jacobian differentiates these expressions directly (rows of element a and b with
!! respect to the 12 coordinates and rates of both), which is the per-strain formula
!! dF/dq = -C g g^T - (C s + B s') H - B g (H q')^T, dF/dq' = -B g g^T summed over the
!! three strains. Supports and effects are separate small steps, only when present.
submodule (ropedyn_rfem) ropedyn_rfem_kernels
    use ropedyn_trig, only: cos_sin
    implicit none

    !> SDE j between elements a = j - 1 and b = j at a state y (the module header's
    !! formulas; self%cs holding the angles of y): where a's and b's coordinates start in y
    !! (ka, kb: x at ka + 1), cos, sin and half length of both, the tension and shear
    !! strains dwx, dwy and cos, sin of phi_b - phi_a (cd, sd); after `sde_rates` also the
    !! angular velocities wa, wb and the strain rates rx, ry, rp.
    type :: sde_t
        integer :: ka, kb
        real(wp) :: ca, sa, cb, sb, ha, hb
        real(wp) :: dwx, dwy, cd, sd
        real(wp) :: wa, wb, rx, ry, rp
    end type sde_t

    !> What a call of `forces` evaluates, from its optional arguments: the elastic energy,
    !! the dissipation power, the force split (split; with_rest: the rest too) and the
    !! dampers (damp: damping on, and not left out by the split).
    type :: force_mode_t
        logical :: energy, with_power, split, with_rest, damp
    end type force_mode_t

    !> For the Jacobian: the derivatives dfx, dfy, dfp of SDE j's forces fx, fy (N) and
    !! fp (N m) with respect to the 12 local variables (a's x, y, phi, x', y', phi', then
    !! b's) and the strain gradients gx, gy; kept from SDE to SDE (the entries that no
    !! strain sets stay zero).
    type :: sde_jac_t
        real(wp) :: gx(12), gy(12), dfx(12), dfy(12), dfp(12)
    end type sde_jac_t

contains

    !> cos and sin of every element angle into self%cs, once per call (gathered, then
    !! ropedyn_trig's vectorizing routine).
    module procedure angles
        integer :: i
        do i = 1, self%n
            self%phi(i) = y(6*i - 3)
        end do
        call cos_sin(self%phi, self%cs)
    end procedure angles

    !> The geometry of SDE j at y (sde_t), computed once for every kernel's pass.
    pure function sde_at(self, y, j) result(s)
        class(rfem_t), intent(in) :: self
        real(wp), intent(in) :: y(:)
        integer, intent(in) :: j
        type(sde_t) :: s
        real(wp) :: dx, dy
        s%ka = 6*(j - 2)
        s%kb = s%ka + 6
        s%ca = self%cs(1, j - 1)
        s%sa = self%cs(2, j - 1)
        s%cb = self%cs(1, j)
        s%sb = self%cs(2, j)
        s%ha = self%half(j - 1)
        s%hb = self%half(j)
        dx = y(s%kb + 1) - s%hb*s%cb - y(s%ka + 1) - s%ha*s%ca
        dy = y(s%kb + 2) - s%hb*s%sb - y(s%ka + 2) - s%ha*s%sa
        s%dwx = s%ca*dx + s%sa*dy
        s%dwy = -s%sa*dx + s%ca*dy
        s%cd = s%ca*s%cb + s%sa*s%sb
        s%sd = s%ca*s%sb - s%sa*s%cb
    end function sde_at

    !> The rates of SDE s at y: angular velocities and strain rates (only when damping is on).
    pure subroutine sde_rates(s, y)
        type(sde_t), intent(inout) :: s
        real(wp), intent(in) :: y(:)
        real(wp) :: dvx, dvy
        dvx = y(s%kb + 4) - y(s%ka + 4)
        dvy = y(s%kb + 5) - y(s%ka + 5)
        s%wa = y(s%ka + 6)
        s%wb = y(s%kb + 6)
        s%rx = s%ca*dvx + s%sa*dvy + s%dwy*s%wa + s%hb*s%sd*s%wb
        s%ry = -s%sa*dvx + s%ca*dvy - (s%dwx + s%ha)*s%wa - s%hb*s%cd*s%wb
        s%rp = s%wb - s%wa
    end subroutine sde_rates

    !> The displacement d = sgn (c - P) - h e of translational support k at state y, its
    !! element's angle having cosine co and sine si.
    pure function support_offset(self, k, y, co, si) result(d)
        class(rfem_t), intent(in) :: self
        integer, intent(in) :: k
        real(wp), intent(in) :: y(:), co, si
        real(wp) :: d(2)
        associate (sp => self%sup(k), m => 6*(self%sup(k)%elem - 1), &
                   h => self%half(self%sup(k)%elem))
            d(1) = sp%sgn*(y(m + 1) - sp%anchor(1)) - h*co
            d(2) = sp%sgn*(y(m + 2) - sp%anchor(2)) - h*si
        end associate
    end function support_offset

    !> The displacement a support's spring acts on: d (support_offset), but on a line that
    !! carries tension only (stretch_floor) with d along the rope, s = e.d, below the floor
    !! (the end pushed towards the support: slack) only d's part across the rope, u n with
    !! u = n.d. The spring stands for the end section of the rope (docs/theory/rfem.md,
    !! Supports), which cannot push either. Its energy Ct u^2 / 2 then turns with the
    !! element: besides the force Ct u n at the end it puts the couple Ct u s on the
    !! element (-dV/dphi = Ct u (s + h); slack_couple), as an internal SDE's shear force
    !! does through its fy dwx.
    pure function pin_offset(self, k, y, co, si) result(d)
        class(rfem_t), intent(in) :: self
        integer, intent(in) :: k
        real(wp), intent(in) :: y(:), co, si
        real(wp) :: d(2)
        d = support_offset(self, k, y, co, si)
        if (co*d(1) + si*d(2) < self%stretch_floor()) d = (co*d(2) - si*d(1))*[-si, co]
    end function pin_offset

    !> The couple (N m) on support k's element of its slack spring (pin_offset): Ct u s,
    !! 0 where the spring is not slack.
    pure real(wp) function slack_couple(self, k, y, co, si) result(couple)
        class(rfem_t), intent(in) :: self
        integer, intent(in) :: k
        real(wp), intent(in) :: y(:), co, si
        real(wp) :: d(2), s
        couple = 0.0_wp
        d = support_offset(self, k, y, co, si)
        s = co*d(1) + si*d(2)
        if (s < self%stretch_floor()) couple = self%sup(k)%ct*(co*d(2) - si*d(1))*s
    end function slack_couple

    !> Its rate d' = sgn (v - P') - h w n.
    pure function support_offset_rate(self, k, y, co, si) result(dd)
        class(rfem_t), intent(in) :: self
        integer, intent(in) :: k
        real(wp), intent(in) :: y(:), co, si
        real(wp) :: dd(2)
        associate (sp => self%sup(k), m => 6*(self%sup(k)%elem - 1), &
                   h => self%half(self%sup(k)%elem))
            dd(1) = sp%sgn*(y(m + 4) - sp%anchor_vel(1)) + h*y(m + 6)*si
            dd(2) = sp%sgn*(y(m + 5) - sp%anchor_vel(2)) - h*y(m + 6)*co
        end associate
    end function support_offset_rate

    !> Add the generalized force of support k (translational spring and damper on d, and
    !! for a clamp the rotational one) to f(3), the force on its element; with `energy`
    !! its spring energy to e_el. `sde`: the SDE's own forces, fs = Ct d + Bt d' (x, y) and
    !! fr = Cr s + Br s' (zero where it has none): the support's force on the rope is
    !! -sgn fs, its moment on the element -sgn fr. With `fr` (the force split) the dampers'
    !! part goes to fr, and with `rest` false it is not evaluated.
    pure subroutine support_force(self, k, y, f, energy, e_el, sde, fr, rest)
        class(rfem_t), intent(in) :: self
        integer, intent(in) :: k
        real(wp), intent(in) :: y(:)
        real(wp), intent(inout) :: f(3)
        logical, intent(in) :: energy
        real(wp), intent(inout) :: e_el
        real(wp), intent(out), optional :: sde(3)
        real(wp), intent(inout), optional :: fr(3)
        logical, intent(in), optional :: rest
        real(wp) :: h, co, si, d(2), fs(2), fd(2), s, fq
        integer :: m
        logical :: damp
        damp = .true.
        if (present(rest)) damp = rest
        if (present(sde)) sde = 0.0_wp
        associate (sp => self%sup(k))
            m = 6*(sp%elem - 1)
            h = self%half(sp%elem)
            co = self%cs(1, sp%elem)    ! cos and sin of its angle (angles, at y)
            si = self%cs(2, sp%elem)
            if (sp%translational) then
                d = pin_offset(self, k, y, co, si)
                fs = sp%ct*d
                if (energy) e_el = e_el + 0.5_wp*sp%ct*(d(1)**2 + d(2)**2)
                if (sp%damped_t .and. damp) then
                    fd = sp%bt*support_offset_rate(self, k, y, co, si)
                    if (present(fr)) then
                        fr(1:2) = fr(1:2) - sp%sgn*fd
                        fr(3) = fr(3) + h*(co*fd(2) - si*fd(1))
                    else
                        fs = fs + fd
                    end if
                end if
                f(1:2) = f(1:2) - sp%sgn*fs
                f(3) = f(3) + h*(co*fs(2) - si*fs(1))
                if (self%tension_only) f(3) = f(3) + slack_couple(self, k, y, co, si)
                if (present(sde)) sde(1:2) = fs
            end if
            if (sp%rotational) then
                s = sp%sgn*(y(m + 3) - sp%angle)
                fq = sp%cr*s
                if (energy) e_el = e_el + 0.5_wp*sp%cr*s**2
                if (sp%damped_r .and. damp) then
                    if (present(fr)) then
                        fr(3) = fr(3) - sp%br*(y(m + 6) - sp%angle_rate)
                    else
                        fq = fq + sp%br*sp%sgn*(y(m + 6) - sp%angle_rate)
                    end if
                end if
                f(3) = f(3) - sp%sgn*fq
                if (present(sde)) sde(3) = fq
            end if
        end associate
    end subroutine support_force

    !> Power of support k: its dissipation (W) and, when it moves, the work rate of its
    !! anchor on the rope (W): the force of the support times -sgn P', the moment times
    !! -sgn psi' (the strain rate's explicit part).
    pure subroutine support_power(self, k, y, power, work)
        class(rfem_t), intent(in) :: self
        integer, intent(in) :: k
        real(wp), intent(in) :: y(:)
        real(wp), intent(inout) :: power, work
        real(wp) :: dd(2), fs(2), s, sd, fr
        integer :: m
        associate (sp => self%sup(k), co => self%cs(1, self%sup(k)%elem), &
                   si => self%cs(2, self%sup(k)%elem))
            m = 6*(sp%elem - 1)
            if (sp%translational) then
                fs = sp%ct*pin_offset(self, k, y, co, si)
                if (sp%damped_t) then
                    dd = support_offset_rate(self, k, y, co, si)
                    fs = fs + sp%bt*dd
                    power = power + sp%bt*(dd(1)**2 + dd(2)**2)
                end if
                if (self%moving(k)) work = work - sp%sgn*(fs(1)*sp%anchor_vel(1) &
                                                          + fs(2)*sp%anchor_vel(2))
            end if
            if (sp%rotational) then
                s = sp%sgn*(y(m + 3) - sp%angle)
                sd = sp%sgn*(y(m + 6) - sp%angle_rate)
                fr = sp%cr*s
                if (sp%damped_r) then
                    fr = fr + sp%br*sd
                    power = power + sp%br*sd**2
                end if
                if (self%moving(k)) work = work - sp%sgn*fr*sp%angle_rate
            end if
        end associate
    end subroutine support_power

    !> Add -k G^T G, G = [[sg, 0, h si], [0, sg, -h co]] the gradient of a support's
    !! displacement d (or of d' with respect to the rates), to the 3x3 block b, except its
    !! (3, 3) entry -k h^2, which the caller adds (for the spring together with the moment
    !! of the force, as the force's other phi terms). sh = sg h.
    pure subroutine add_spring(b, k, sh, co, si)
        real(wp), intent(inout) :: b(3, 3)
        real(wp), intent(in) :: k, sh, co, si
        b(1, 1) = b(1, 1) - k
        b(2, 2) = b(2, 2) - k
        b(1, 3) = b(1, 3) - sh*k*si
        b(2, 3) = b(2, 3) + sh*k*co
        b(3, 1) = b(3, 1) - sh*k*si
        b(3, 2) = b(3, 2) + sh*k*co
    end subroutine add_spring

    !> Add to the 3x3 block b the derivatives of the force of a support's spring k (N/m)
    !! that acts on d's part across the rope only, u n with u = n.d (pin_offset; s = e.d),
    !! and of its couple k u s (slack_couple), except the (3, 3) entry's part that the
    !! caller adds as for add_spring: d(k u n)/dc = sg k n n^T, d(k u n)/dphi =
    !! k ((-h - s) n - u e); d(k u s)/dc = sg k (s n + u e), d(k u s)/dphi =
    !! k (u^2 - s^2 - h s); the moment h n.(k u n) = h k u has d/dphi = -k h (h + s).
    pure subroutine add_slack_spring(b, k, sg, h, d, co, si)
        real(wp), intent(inout) :: b(3, 3)
        real(wp), intent(in) :: k, sg, h, d(2), co, si
        real(wp) :: nv(2), u, s
        nv = [-si, co]
        u = co*d(2) - si*d(1)
        s = co*d(1) + si*d(2)
        b(1:2, 1) = b(1:2, 1) - k*nv(1)*nv
        b(1:2, 2) = b(1:2, 2) - k*nv(2)*nv
        b(1:2, 3) = b(1:2, 3) - sg*k*((-h - s)*nv - u*[co, si])
        b(3, 1:2) = b(3, 1:2) + sg*h*k*nv + sg*k*(s*nv + u*[co, si])
        b(3, 3) = b(3, 3) - h*k*s + k*(u**2 - s**2 - h*s)
    end subroutine add_slack_spring

    !> Add the derivatives of support k's generalized force with respect to its element's
    !! (x, y, phi, x', y', phi') to blk(3, 6).
    pure subroutine support_jacobian(self, k, y, blk)
        class(rfem_t), intent(in) :: self
        integer, intent(in) :: k
        real(wp), intent(in) :: y(:)
        real(wp), intent(inout) :: blk(3, 6)
        real(wp) :: h, co, si, w, fs(2), sg, d(2)
        integer :: m
        logical :: slack
        associate (sp => self%sup(k))
            m = 6*(sp%elem - 1)
            h = self%half(sp%elem)
            co = cos(y(m + 3))
            si = sin(y(m + 3))
            w = y(m + 6)
            sg = sp%sgn
            if (sp%translational) then
                ! F = Ct d + Bt d' acts as -sgn F on the centre and h n.F as moment; d and d'
                ! have the same gradient G with respect to (x, y, phi) and (x', y', phi'),
                ! so the spring's block and the damper's have one pattern (add_spring); a
                ! slack end section's spring acts across the rope only (pin_offset)
                d = support_offset(self, k, y, co, si)
                slack = co*d(1) + si*d(2) < self%stretch_floor()
                if (slack) then
                    fs = sp%ct*pin_offset(self, k, y, co, si)
                    call add_slack_spring(blk(:, 1:3), sp%ct, sg, h, d, co, si)
                else
                    fs = sp%ct*d
                    call add_spring(blk(:, 1:3), sp%ct, sg*h, co, si)
                end if
                if (sp%damped_t) then
                    fs = fs + sp%bt*support_offset_rate(self, k, y, co, si)
                    blk(1, 3) = blk(1, 3) - sg*h*sp%bt*w*co
                    blk(2, 3) = blk(2, 3) - sg*h*sp%bt*w*si
                    call add_spring(blk(:, 4:6), sp%bt, sg*h, co, si)
                    blk(3, 6) = blk(3, 6) - sp%bt*h**2
                end if
                blk(3, 3) = blk(3, 3) - h*(co*fs(1) + si*fs(2)) - sp%ct*h**2
            end if
            if (sp%rotational) then
                blk(3, 3) = blk(3, 3) - sp%cr
                if (sp%damped_r) blk(3, 6) = blk(3, 6) - sp%br
            end if
        end associate
    end subroutine support_jacobian
    module procedure fill_bodies
        integer :: i, k
        do i = 1, self%n
            k = 6*(i - 1)
            self%bodies%c(:, i) = y(k + 1:k + 2)
            self%bodies%phi(i) = y(k + 3)
            self%bodies%v(:, i) = y(k + 4:k + 5)
            self%bodies%w(i) = y(k + 6)
        end do
        self%bodies%cs = self%cs    ! ropedyn_trig's of the same angles (angles, at y)
    end procedure fill_bodies

    module procedure forces
        real(wp) :: fx, fy, fp, dx, dy, dp, c(3), cr(3), e_el, p_in, sup_sde(3, 2), floor
        type(sde_t) :: s
        type(force_mode_t) :: mode
        integer :: j, n

        n = self%n
        mode = force_mode(self, present(elastic), present(power), rest)
        e_el = 0.0_wp
        p_in = 0.0_wp
        floor = self%stretch_floor()
        call self%set_time(t)
        call angles(self, y)
        ! c: the force of the previous SDE on its element b (first: the top support's);
        ! cr: its dampers' part when split
        c = 0.0_wp
        sup_sde = 0.0_wp
        cr = 0.0_wp
        if (mode%with_rest) self%gen_r = 0.0_wp
        call end_support_force(self, 1, y, mode, c, cr, e_el, sup_sde(:, 1), rest)
        ! the internal SDEs, here and not in a helper: there gfortran 12 fused scatter's
        ! products (vfmaddsub, despite -ffp-contract=off), which changed the last bits
        do j = 2, n
            s = sde_at(self, y, j)
            fx = 0.0_wp
            fy = 0.0_wp
            fp = 0.0_wp
            if (self%tension) then
                ! spring_stretch, with the floor taken once
                fx = s%dwx
                if (fx < floor) fx = floor
                fx = self%cxj(j)*fx
            end if
            if (self%shear) fy = self%cy*s%dwy
            if (self%bending) fp = self%cpj(j)*(y(s%kb + 3) - y(s%ka + 3))
            if (mode%energy) e_el = e_el + 0.5_wp*(fx*s%dwx + fy*s%dwy &
                                                   + fp*(y(s%kb + 3) - y(s%ka + 3)))
            if (mode%damp) then
                call sde_rates(s, y)
                dx = self%bxj(j)*s%rx
                dy = self%by*s%ry
                dp = self%bpj(j)*s%rp
                if (mode%with_power) p_in = p_in + (self%bxj(j)*s%rx**2 + self%by*s%ry**2 + &
                                                    self%bpj(j)*s%rp**2)
                if (.not. mode%split) then
                    fx = fx + dx
                    fy = fy + dy
                    fp = fp + dp
                end if
            else
                dx = 0.0_wp
                dy = 0.0_wp
                dp = 0.0_wp
            end if
            if (present(joint)) joint(:, j - 1) = [fx, fy, fp]
            if (mode%with_rest) call scatter(self%gen_r, j, s, dx, dy, dp, cr)
            call scatter(self%gen, j, s, fx, fy, fp, c)
            self%gen(1, j - 1) = self%gen(1, j - 1) + self%weight(j - 1)
        end do
        call end_support_force(self, 2, y, mode, c, cr, e_el, sup_sde(:, 2), rest)
        if (present(support)) support = sup_sde
        self%gen(1, n) = c(1) + self%weight(n)
        self%gen(2:3, n) = c(2:3)
        if (mode%with_rest) self%gen_r(:, n) = cr
        call point_mass_moments(self)
        if (present(work)) call support_powers(self, y, p_in, work)
        if (size(self%effects) > 0 .or. self%water) &
            call effect_forces(self, t, y, mode, e_el, p_in, work)
        if (mode%energy) elastic = e_el
        if (mode%with_power) power = p_in
    end procedure forces

    !> The mode of a call of `forces` (force_mode_t) from which of its optional arguments
    !! elastic and power are present, and its `rest`.
    pure function force_mode(self, energy, with_power, rest) result(mode)
        class(rfem_t), intent(in) :: self
        logical, intent(in) :: energy, with_power
        logical, intent(in), optional :: rest
        type(force_mode_t) :: mode
        mode%energy = energy
        mode%with_power = with_power
        ! the force split: the dampers' and effects' forces into gen_r (rest), or not at all
        mode%split = present(rest)
        mode%with_rest = .false.
        if (mode%split) mode%with_rest = rest
        mode%damp = self%damped .and. (mode%with_rest .or. .not. mode%split)
    end function force_mode

    !> Add the moment of the point masses' weight about their element's centre to self%gen.
    pure subroutine point_mass_moments(self)
        class(rfem_t), intent(inout) :: self
        integer :: p, i
        if (self%gravity_on) then
            do p = 1, size(self%pm_elem)
                i = self%pm_elem(p)
                self%gen(3, i) = self%gen(3, i) - self%g*self%pm_moment(p)*self%cs(2, i)
            end do
        end if
    end subroutine point_mass_moments

    !> The supports' dissipation added to p_in and their work rate into work (W), before
    !! the effects', as in store_powers.
    pure subroutine support_powers(self, y, p_in, work)
        class(rfem_t), intent(in) :: self
        real(wp), intent(in) :: y(:)
        real(wp), intent(inout) :: p_in
        real(wp), intent(out) :: work
        integer :: k
        work = 0.0_wp
        do k = 1, 2
            if (self%sup(k)%active) call support_power(self, k, y, p_in, work)
        end do
    end subroutine support_powers

    !> The force of support k (1 top, 2 bottom), when active, on its element: into the
    !! carry c, with the dampers' part into cr when split (rest: forces' argument), else
    !! its SDE's forces into sde (support_force).
    pure subroutine end_support_force(self, k, y, mode, c, cr, e_el, sde, rest)
        class(rfem_t), intent(in) :: self
        integer, intent(in) :: k
        real(wp), intent(in) :: y(:)
        type(force_mode_t), intent(in) :: mode
        real(wp), intent(inout) :: c(3), cr(3), e_el, sde(3)
        logical, intent(in), optional :: rest
        if (self%sup(k)%active) then
            if (mode%split) then
                call support_force(self, k, y, c, mode%energy, e_el, fr=cr, rest=rest)
            else
                call support_force(self, k, y, c, mode%energy, e_el, sde=sde)
            end if
        end if
    end subroutine end_support_force

    !> The external effects' forces (into self%gen_r when split with the rest, else with
    !! their powers into p_in and work when work is present; their energy into e_el) and
    !! the water's (forces' arguments; mode: which).
    subroutine effect_forces(self, t, y, mode, e_el, p_in, work)
        class(rfem_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        type(force_mode_t), intent(in) :: mode
        real(wp), intent(inout) :: e_el, p_in
        real(wp), intent(inout), optional :: work
        if (size(self%effects) > 0 .and. (mode%with_rest .or. .not. mode%split)) then
            call self%fill_bodies(y)
            if (mode%with_rest) then
                call add_forces_of(self%effects, t, self%bodies, self%gen_r(1:2, :), &
                                   self%gen_r(3, :))
            else if (present(work)) then
                call add_forces_powers_of(self%effects, t, self%bodies, self%gen(1:2, :), &
                                          self%gen(3, :), p_in, work)
            else
                call add_forces_of(self%effects, t, self%bodies, self%gen(1:2, :), &
                                   self%gen(3, :))
            end if
            if (mode%energy) call add_energies_of(self%effects, t, self%bodies, e_el)
        end if
        if (self%water) then
            if (mode%energy) then
                call self%water_forces(y, e_el)
            else
                call self%water_forces(y)
            end if
        end if
    end subroutine effect_forces

    !> The generalized forces of SDE j (geometry s) with forces (fx, fy, fp): element a's into
    !! g(:, j - 1), with the carry c (the previous SDE's force on its element b, which is a),
    !! and the force on element b into c (the module header: F = fx e_a + fy n_a).
    pure subroutine scatter(g, j, s, fx, fy, fp, c)
        real(wp), intent(inout) :: g(:, :)
        integer, intent(in) :: j
        type(sde_t), intent(in) :: s
        real(wp), intent(in) :: fx, fy, fp
        real(wp), intent(inout) :: c(3)
        real(wp) :: ffx, ffy
        ffx = fx*s%ca - fy*s%sa
        ffy = fx*s%sa + fy*s%ca
        g(1, j - 1) = c(1) + ffx
        g(2, j - 1) = c(2) + ffy
        g(3, j - 1) = c(3) + (fy*(s%dwx + s%ha) - fx*s%dwy + fp)
        c(1) = -ffx
        c(2) = -ffy
        c(3) = -s%hb*(fx*s%sd - fy*s%cd) - fp
    end subroutine scatter

    module procedure rfem_generalized_forces
        real(wp) :: tt
        tt = 0.0_wp
        if (present(t)) tt = t
        call self%forces(tt, y, elastic)
        gen = self%gen
    end procedure rfem_generalized_forces

    module procedure rfem_rhs
        call self%forces(t, y)
        call accelerations(self, y, ydot)
        status = STATUS_OK
        if (.not. all_finite(ydot)) status = STATUS_RECOVERABLE
    end procedure rfem_rhs

    module procedure rfem_rhs_quad
        real(wp) :: power, work
        ! the order of the sums as in rfem_quad_rhs: internal SDEs, supports, effects (all
        ! in forces, each effect's power with its forces)
        call self%forces(t, y, power=power, work=work)
        call accelerations(self, y, ydot)
        call store_rates(self, power, work, yqdot, status)
        if (.not. all_finite(ydot)) status = STATUS_RECOVERABLE
    end procedure rfem_rhs_quad

    !> ydot from y and the generalized forces in self%gen.
    subroutine accelerations(self, y, ydot)
        class(rfem_t), intent(inout) :: self
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: ydot(:)
        integer :: i, k
        do i = 1, self%n
            k = 6*(i - 1)
            ydot(k + 1) = y(k + 4)
            ydot(k + 2) = y(k + 5)
            ydot(k + 3) = y(k + 6)
            ydot(k + 4) = self%gen(1, i)*self%rowscale(1, i)
            ydot(k + 5) = self%gen(2, i)*self%rowscale(2, i)
            ydot(k + 6) = self%gen(3, i)*self%rowscale(3, i)
        end do
        if (self%water) then
            call self%water_accelerations(y, self%gen, ydot)
        else if (size(self%pm_elem) > 0) then
            call self%point_mass_accelerations(y, self%gen, ydot)
        end if
    end subroutine accelerations

    module procedure rfem_has_jacobian
        has = .true.
    end procedure rfem_has_jacobian

    module procedure jacobian_blocks
        integer :: j, n
        real(wp) :: floor
        type(sde_t) :: s
        type(sde_jac_t) :: d
        real(wp) :: r1(12), r2(12), carry(3, 6), t6, fx, fy, fp

        n = self%n
        floor = self%stretch_floor()
        call self%set_time(t)
        call angles(self, y)
        ! carry: the diagonal block of element b of the previous SDE (first: the top support)
        carry = 0.0_wp
        if (self%sup(1)%active) call support_jacobian(self, 1, y, carry)
        d%gx = 0.0_wp
        d%gy = 0.0_wp
        d%dfx = 0.0_wp
        d%dfy = 0.0_wp
        d%dfp = 0.0_wp
        do j = 2, n
            s = sde_at(self, y, j)
            call strain_gradients(s, d)
            call spring_derivatives(self, y, j, s, floor, fx, fy, fp, d)
            if (self%damped) then
                ! d(rate)/dq = H q' (ry and -rx on phi_a), d(rate)/dq' = the gradient
                call sde_rates(s, y)
                if (self%tension) call tension_damper(self%bxj(j), s, fx, d)
                if (self%shear) call shear_damper(self%by, s, fy, d)
                if (self%bending) then
                    fp = fp + self%bpj(j)*s%rp
                    d%dfp(6) = -self%bpj(j)
                    d%dfp(12) = self%bpj(j)
                end if
            end if
            associate (dfx => d%dfx, dfy => d%dfy, dfp => d%dfp, gx => d%gx, gy => d%gy)
                ! rows of element a: d(F, fy (dwx + h_a) - fx dwy + fp); of element b:
                ! d(-F, -h_b (fx sd - fy cd) - fp); columns: a's coordinates, then b's
                r1 = s%ca*dfx - s%sa*dfy
                r2 = s%sa*dfx + s%ca*dfy
                r1(3) = r1(3) - fx*s%sa - fy*s%ca
                r2(3) = r2(3) + fx*s%ca - fy*s%sa
                self%blk(1, :, 0, j - 1) = carry(1, :) + r1(1:6)
                self%blk(2, :, 0, j - 1) = carry(2, :) + r2(1:6)
                self%blk(3, :, 0, j - 1) = carry(3, :) + (s%dwx + s%ha)*dfy(1:6) &
                                           - s%dwy*dfx(1:6) + dfp(1:6) + fy*gx(1:6) - fx*gy(1:6)
                self%blk(1, :, 1, j - 1) = r1(7:12)
                self%blk(2, :, 1, j - 1) = r2(7:12)
                self%blk(3, :, 1, j - 1) = (s%dwx + s%ha)*dfy(7:12) - s%dwy*dfx(7:12) &
                                           + dfp(7:12) + fy*gx(7:12) - fx*gy(7:12)
                t6 = s%hb*(fx*s%cd + fy*s%sd)
                self%blk(1, :, -1, j) = -r1(1:6)
                self%blk(2, :, -1, j) = -r2(1:6)
                self%blk(3, :, -1, j) = -s%hb*(s%sd*dfx(1:6) - s%cd*dfy(1:6)) - dfp(1:6)
                self%blk(3, 3, -1, j) = self%blk(3, 3, -1, j) + t6
                carry(1, :) = -r1(7:12)
                carry(2, :) = -r2(7:12)
                carry(3, :) = -s%hb*(s%sd*dfx(7:12) - s%cd*dfy(7:12)) - dfp(7:12)
                carry(3, 3) = carry(3, 3) - t6
            end associate
        end do
        if (self%sup(2)%active) call support_jacobian(self, 2, y, carry)
        self%blk(:, :, 0, n) = carry
        ! external effects: 3x6 blocks on each element's own coordinates
        if (size(self%effects) > 0) then
            call self%fill_bodies(y)
            call add_jacobians_of(self%effects, t, self%bodies, self%blk(:, :, 0, :))
        end if
    end procedure jacobian_blocks

    !> The gradients of SDE s's tension and shear strains into d%gx, d%gy (their entries on
    !! the rates stay zero).
    pure subroutine strain_gradients(s, d)
        type(sde_t), intent(in) :: s
        type(sde_jac_t), intent(inout) :: d
        d%gx(1) = -s%ca
        d%gx(2) = -s%sa
        d%gx(3) = s%dwy
        d%gx(7) = s%ca
        d%gx(8) = s%sa
        d%gx(9) = s%hb*s%sd
        d%gy(1) = s%sa
        d%gy(2) = -s%ca
        d%gy(3) = -(s%dwx + s%ha)
        d%gy(7) = -s%sa
        d%gy(8) = s%ca
        d%gy(9) = -s%hb*s%cd
    end subroutine strain_gradients

    !> The springs' forces fx, fy, fp of SDE j (geometry s) and their derivatives into d.
    pure subroutine spring_derivatives(self, y, j, s, floor, fx, fy, fp, d)
        class(rfem_t), intent(in) :: self
        real(wp), intent(in) :: y(:)
        integer, intent(in) :: j
        type(sde_t), intent(in) :: s
        real(wp), intent(in) :: floor
        real(wp), intent(out) :: fx, fy, fp
        type(sde_jac_t), intent(inout) :: d
        associate (dfx => d%dfx, dfy => d%dfy, dfp => d%dfp, gx => d%gx, gy => d%gy)
            fx = 0.0_wp
            fy = 0.0_wp
            fp = 0.0_wp
            if (self%tension) then
                ! spring_stretch and spring_slope, with the floor taken once
                fx = self%cxj(j)*s%dwx
                dfx = self%cxj(j)*gx
                if (s%dwx < floor) then
                    fx = self%cxj(j)*floor
                    dfx = 0.0_wp
                end if
            end if
            if (self%shear) then
                fy = self%cy*s%dwy
                dfy = self%cy*gy
            end if
            if (self%bending) then
                fp = self%cpj(j)*(y(s%kb + 3) - y(s%ka + 3))
                dfp(3) = -self%cpj(j)
                dfp(9) = self%cpj(j)
            end if
        end associate
    end subroutine spring_derivatives

    !> Add the tension damper's force (coefficient b, N s/m) of SDE s (its rates set) and
    !! its derivatives to d: d(rx)/dq = H q' (ry on phi_a), d(rx)/dq' = the gradient gx.
    pure subroutine tension_damper(b, s, fx, d)
        real(wp), intent(in) :: b
        type(sde_t), intent(in) :: s
        real(wp), intent(inout) :: fx
        type(sde_jac_t), intent(inout) :: d
        fx = fx + b*s%rx
        d%dfx(1) = d%dfx(1) + b*s%sa*s%wa
        d%dfx(2) = d%dfx(2) - b*s%ca*s%wa
        d%dfx(3) = d%dfx(3) + b*s%ry
        d%dfx(7) = d%dfx(7) - b*s%sa*s%wa
        d%dfx(8) = d%dfx(8) + b*s%ca*s%wa
        d%dfx(9) = d%dfx(9) + b*s%hb*s%cd*(s%wb - s%wa)
        d%dfx(4:6) = b*d%gx(1:3)
        d%dfx(10:12) = b*d%gx(7:9)
    end subroutine tension_damper

    !> Add the shear damper's force (coefficient b, N s/m) of SDE s (its rates set) and
    !! its derivatives to d: d(ry)/dq = H q' (-rx on phi_a), d(ry)/dq' = the gradient gy.
    pure subroutine shear_damper(b, s, fy, d)
        real(wp), intent(in) :: b
        type(sde_t), intent(in) :: s
        real(wp), intent(inout) :: fy
        type(sde_jac_t), intent(inout) :: d
        fy = fy + b*s%ry
        d%dfy(1) = d%dfy(1) + b*s%ca*s%wa
        d%dfy(2) = d%dfy(2) + b*s%sa*s%wa
        d%dfy(3) = d%dfy(3) - b*s%rx
        d%dfy(7) = d%dfy(7) - b*s%ca*s%wa
        d%dfy(8) = d%dfy(8) - b*s%sa*s%wa
        d%dfy(9) = d%dfy(9) + b*s%hb*s%sd*(s%wb - s%wa)
        d%dfy(4:6) = b*d%gy(1:3)
        d%dfy(10:12) = b*d%gy(7:9)
    end subroutine shear_damper

    !> Add the dissipation power sum B s'^2 of the internal SDEs (self%cs holding the
    !! angles of y; the module header's geometry and rates).
    subroutine internal_power(self, y, power)
        class(rfem_t), intent(in) :: self
        real(wp), intent(in) :: y(6*self%n)
        real(wp), intent(inout) :: power
        type(sde_t) :: s
        integer :: j
        do j = 2, self%n
            s = sde_at(self, y, j)
            call sde_rates(s, y)
            power = power + (self%bxj(j)*s%rx**2 + self%by*s%ry**2 + self%bpj(j)*s%rp**2)
        end do
    end subroutine internal_power

    module procedure rfem_quad_rhs
        real(wp) :: power
        call self%set_time(t)
        ! only the damped strains and the supports: no spring forces, no gravity, no scatter
        power = 0.0_wp
        call angles(self, y)    ! for the SDEs and the supports
        if (self%damped) call internal_power(self, y, power)
        if (size(self%effects) > 0) call self%fill_bodies(y)
        call store_powers(self, t, y, power, yqdot, status)
    end procedure rfem_quad_rhs

    !> Add the supports' and the effects' dissipation to power (the internal SDEs' share;
    !! self%bodies filled) and their external work rate, and store both as the quadratures'
    !! rates; STATUS_RECOVERABLE when either is not finite.
    subroutine store_powers(self, t, y, power, yqdot, status)
        class(rfem_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(inout) :: power
        real(wp), intent(out) :: yqdot(:)
        integer, intent(out) :: status
        real(wp) :: work
        integer :: k
        work = 0.0_wp
        do k = 1, 2
            if (self%sup(k)%active) call support_power(self, k, y, power, work)
        end do
        if (size(self%effects) > 0) call add_powers_of(self%effects, t, self%bodies, power, work)
        call store_rates(self, power, work, yqdot, status)
    end subroutine store_powers

    !> Store the dissipation power and the external work rate as the quadratures' rates;
    !! STATUS_RECOVERABLE when either is not finite.
    subroutine store_rates(self, power, work, yqdot, status)
        class(rfem_t), intent(in) :: self
        real(wp), intent(in) :: power, work
        real(wp), intent(out) :: yqdot(:)
        integer, intent(out) :: status
        yqdot(1) = power
        if (self%with_work) yqdot(2) = work
        status = STATUS_OK
        if (.not. (ieee_is_finite(power) .and. ieee_is_finite(work))) status = STATUS_RECOVERABLE
    end subroutine store_rates
end submodule ropedyn_rfem_kernels
