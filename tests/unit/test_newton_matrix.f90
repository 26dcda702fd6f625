!> The iteration matrix's reduced second-order solve (ropedyn_iteration_matrix) against a
!! dense LU solve (LAPACK dgesv) of the first-order Newton matrix M - g J:
!! - a linear toy problem with random band blocks K, C (bandwidths 2/1, weak diagonal so
!!   that the band LU pivots), coordinates and rates not interleaved, with and without a
!!   mass block, several g;
!! - the RFEM rope (explicit form, the CVODE case) at a disturbed state;
!! - the MPP rope in its implicit form (the MEBDF case: the model's exact implicit blocks,
!!   with d(M a)/dq) against a dense solve of the first-order matrix of the same blocks.
!> The linear toy problem of test_newton_matrix.
module test_newton_matrix_toy
    use ropedyn_kinds, only: wp
    use ropedyn_problem, only: problem_t, STATUS_OK
    implicit none
    private
    public :: toy_t, TOY_KL, TOY_KU

    integer, parameter :: TOY_KL = 2, TOY_KU = 1   !< bandwidths of the blocks

    !> y = (q, v), q' = v, Mv v' = K q + C v: first-order Jacobian [[0, I], [K, C]].
    type, extends(problem_t) :: toy_t
        integer :: np = 12
        logical :: with_mass = .false.
        real(wp), allocatable :: k(:, :), c(:, :), mv(:, :)   ! dense np x np
    contains
        procedure :: size => toy_size
        procedure :: bandwidths => toy_bandwidths
        procedure :: rhs => toy_rhs
        procedure :: has_jacobian => toy_has_jacobian
        procedure :: jacobian => toy_jacobian
        procedure :: has_mass_matrix => toy_has_mass
        procedure :: mass_matrix => toy_mass_matrix
        procedure :: has_implicit_jacobian => toy_has_jacobian
        procedure :: implicit_jacobian => toy_jacobian
        procedure :: has_second_order => toy_has_second_order
        procedure :: second_order_layout => toy_layout
    end type toy_t

contains

    pure integer function toy_size(self)
        class(toy_t), intent(in) :: self
        toy_size = 2*self%np
    end function toy_size

    pure subroutine toy_bandwidths(self, ml, mu)
        class(toy_t), intent(in) :: self
        integer, intent(out) :: ml, mu
        ml = 2*self%np - 1
        mu = ml
    end subroutine toy_bandwidths

    subroutine toy_rhs(self, t, y, ydot, status)
        class(toy_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(out) :: ydot(:)
        integer, intent(out) :: status
        ydot(1:self%np) = y(self%np + 1:)
        ydot(self%np + 1:) = matmul(self%k, y(1:self%np)) + matmul(self%c, y(self%np + 1:))
        status = STATUS_OK
    end subroutine toy_rhs

    pure logical function toy_has_jacobian(self) result(has)
        class(toy_t), intent(in) :: self
        has = .true.
    end function toy_has_jacobian

    pure logical function toy_has_mass(self) result(has)
        class(toy_t), intent(in) :: self
        has = self%with_mass
    end function toy_has_mass

    pure logical function toy_has_second_order(self) result(has)
        class(toy_t), intent(in) :: self
        has = .true.
    end function toy_has_second_order

    pure subroutine toy_layout(self, pos, vel, kl, ku)
        class(toy_t), intent(in) :: self
        integer, allocatable, intent(out) :: pos(:), vel(:)
        integer, intent(out) :: kl, ku
        integer :: i
        pos = [(i, i = 1, self%np)]
        vel = [(self%np + i, i = 1, self%np)]
        kl = TOY_KL
        ku = TOY_KU
    end subroutine toy_layout

    !> [[0, I], [K, C]] (the implicit form's dF/dy too) in band storage.
    subroutine toy_jacobian(self, t, y, jb, offset, status)
        class(toy_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(inout) :: jb(:, :)
        integer, intent(in) :: offset
        integer, intent(out) :: status
        integer :: i, j, np
        np = self%np
        do i = 1, np
            jb(offset + i - (np + i), np + i) = jb(offset + i - (np + i), np + i) + 1.0_wp
            do j = 1, np
                jb(offset + np + i - j, j) = jb(offset + np + i - j, j) + self%k(i, j)
                jb(offset + i - j, np + j) = jb(offset + i - j, np + j) + self%c(i, j)
            end do
        end do
        status = STATUS_OK
    end subroutine toy_jacobian

    !> blockdiag(I, Mv) in band storage.
    subroutine toy_mass_matrix(self, t, y, mb, offset, status)
        class(toy_t), intent(inout) :: self
        real(wp), intent(in) :: t
        real(wp), intent(in) :: y(:)
        real(wp), intent(inout) :: mb(:, :)
        integer, intent(in) :: offset
        integer, intent(out) :: status
        integer :: i, j, np
        np = self%np
        do i = 1, np
            mb(offset, i) = mb(offset, i) + 1.0_wp
            do j = 1, np
                mb(offset + i - j, np + j) = mb(offset + i - j, np + j) + self%mv(i, j)
            end do
        end do
        status = STATUS_OK
    end subroutine toy_mass_matrix
end module test_newton_matrix_toy

program test_newton_matrix
    use ropedyn_kinds, only: wp, i8
    use ropedyn_lapack, only: dgesv
    use ropedyn_error, only: error_t
    use ropedyn_problem, only: STATUS_OK
    use ropedyn_scene, only: scene_t, read_scene
    use ropedyn_rope_model, only: rope_model_t
    use ropedyn_model_factory, only: create_model
    use ropedyn_iteration_matrix, only: iteration_matrix_t
    use ropedyn_assert, only: test_suite_t
    use test_newton_matrix_toy, only: toy_t, TOY_KL, TOY_KU
    implicit none

    type(test_suite_t) :: suite
    character(len=1024) :: source_dir

    suite%name = 'newton_matrix'
    call get_command_argument(1, source_dir)
    if (len_trim(source_dir) == 0) source_dir = '.'
    call test_toy(.false.)
    call test_toy(.true.)
    call test_rope('rfem', implicit_form=.false.)
    call test_rope('mpp', implicit_form=.false.)
    call test_rope('mpp', implicit_form=.true.)
    call suite%finish()

contains

    subroutine test_toy(with_mass)
        logical, intent(in) :: with_mass
        type(toy_t) :: toy
        type(iteration_matrix_t) :: matrix
        real(wp), allocatable :: y(:), b(:), x(:), a(:, :), jd(:, :), md(:, :)
        real(wp) :: g
        integer :: i, j, np, n, status, info, ig
        integer, allocatable :: ipiv(:)
        integer(i8) :: nevals
        character(len=120) :: label

        np = toy%np
        n = 2*np
        toy%with_mass = with_mass
        allocate (toy%k(np, np), toy%c(np, np), toy%mv(np, np))
        toy%k = 0.0_wp
        toy%c = 0.0_wp
        toy%mv = 0.0_wp
        do j = 1, np
            do i = max(1, j - TOY_KU), min(np, j + TOY_KL)
                toy%k(i, j) = -1.0e3_wp*(0.5_wp + sin(3.1_wp*i + 1.7_wp*j))
                toy%c(i, j) = -2.0_wp*(0.3_wp + cos(2.3_wp*i - 0.9_wp*j))
                toy%mv(i, j) = 0.1_wp*sin(real(i + 2*j, wp))
            end do
            toy%k(j, j) = 1.0e-3_wp*toy%k(j, j)     ! weak diagonal: the LU must pivot
            toy%mv(j, j) = 1.0_wp + 0.2_wp*j
        end do
        if (.not. with_mass) toy%mv = reshape([((merge(1.0_wp, 0.0_wp, i == j), i = 1, np), &
                                                j = 1, np)], [np, np])
        allocate (y(n), b(n), x(n), a(n, n), jd(n, n), md(n, n), ipiv(n))
        y = 0.0_wp
        call matrix%setup(toy, implicit_form=.true., first_order=.false., fd_jacobian=.false.)
        call suite%check_true(matrix%is_reduced(), 'toy: reduced path chosen')
        call suite%check_true(.not. matrix%is_dense(), 'toy: reduced matrix in band storage')
        nevals = 0
        call matrix%evaluate_jacobian(toy, 0.0_wp, y, [(1.0_wp, i = 1, n)], 1.0e-3_wp, &
                                      status, nevals)
        call suite%check_true(status == STATUS_OK, 'toy: blocks evaluated')
        jd = 0.0_wp
        do i = 1, np
            jd(i, np + i) = 1.0_wp
        end do
        jd(np + 1:, 1:np) = toy%k
        jd(np + 1:, np + 1:) = toy%c
        md = 0.0_wp
        do i = 1, np
            md(i, i) = 1.0_wp
        end do
        md(np + 1:, np + 1:) = toy%mv
        do ig = 1, 3
            g = 10.0_wp**(-1 - ig)      ! g^2 |K| from 0.1 to 1e-3 of |M|
            call matrix%factor(toy, 0.0_wp, y, g, status)
            call suite%check_true(status == STATUS_OK, 'toy: factored')
            do i = 1, n
                b(i) = cos(0.7_wp*i) + 0.1_wp*i
            end do
            x = b
            call matrix%solve(x)
            a = md - g*jd
            call dgesv(n, 1, a, n, ipiv, b, n, info)
            write (label, '(a, l1, a, es8.1, a)') 'toy (mass ', with_mass, ', g = ', g, &
                '): reduced solve = dense solve of M - g J'
            call suite%check_le(maxval(abs(x - b)), 1.0e-11_wp*maxval(abs(b)), trim(label))
        end do
    end subroutine test_toy

    !> A rope model's reduced solve against a dense solve of its first-order Newton matrix
    !! (explicit form: I - g J with its analytic Jacobian) or against the iteration matrix's
    !! first-order path (implicit form of the MPP: the same difference quotients).
    subroutine test_rope(kind, implicit_form)
        character(len=*), intent(in) :: kind
        logical, intent(in) :: implicit_form
        type(scene_t) :: scene
        class(rope_model_t), allocatable, target :: model
        type(error_t), allocatable :: err
        type(iteration_matrix_t) :: reduced, first
        real(wp), allocatable :: y(:), w(:), b(:), x(:), xf(:), a(:, :), jb(:, :)
        integer, allocatable :: ipiv(:)
        integer :: n, i, j, ml, mu, status, info, ig
        integer(i8) :: nevals
        real(wp) :: g
        character(len=120) :: label
        character(len=64) :: sets(2)

        sets(1) = 'model.kind = "'//kind//'"'
        sets(2) = 'model.elements = 8'
        call read_scene(trim(source_dir)//'/input/paper.nml', sets, scene, err)
        if (.not. allocated(err)) call create_model(scene%rope_spec_t, model, err)
        if (allocated(err)) then
            call suite%check_true(.false., kind//': '//err%message)
            return
        end if
        n = model%size()
        allocate (y(n), w(n), b(n), x(n), xf(n), ipiv(n), a(n, n))
        call model%initial_state(y)
        do i = 1, n      ! a disturbed, moving state
            y(i) = y(i) + 0.05_wp*sin(1.3_wp*i)
        end do
        w = 1.0e-6_wp*abs(y) + 1.0e-8_wp
        call reduced%setup(model, implicit_form, first_order=.false., fd_jacobian=.false.)
        call first%setup(model, implicit_form, first_order=.true., fd_jacobian=.false.)
        call suite%check_true(reduced%is_reduced() .and. .not. first%is_reduced(), &
                              kind//': reduced and first-order paths chosen')
        nevals = 0
        call reduced%evaluate_jacobian(model, 0.1_wp, y, w, 1.0e-4_wp, status, nevals)
        call suite%check_true(status == STATUS_OK, kind//': reduced blocks evaluated')
        call first%evaluate_jacobian(model, 0.1_wp, y, w, 1.0e-4_wp, status, nevals)
        call model%bandwidths(ml, mu)
        ml = min(ml, n - 1)
        mu = min(mu, n - 1)
        allocate (jb(ml + mu + 1, n))
        jb = 0.0_wp
        if (.not. implicit_form) call model%jacobian(0.1_wp, y, jb, mu + 1, status)
        do ig = 1, 3
            g = 10.0_wp**(-2 - ig)
            call reduced%factor(model, 0.1_wp, y, g, status)
            call first%factor(model, 0.1_wp, y, g, status)
            do i = 1, n
                b(i) = cos(0.7_wp*i) + 0.1_wp*i
            end do
            x = b
            call reduced%solve(x)
            xf = b
            call first%solve(xf)
            write (label, '(a, es8.1, a)') kind//', implicit form '// &
                trim(merge('yes', 'no ', implicit_form))//', g = ', g, &
                ': reduced solve = first-order path''s solve'
            if (implicit_form) then
                ! the MPP's implicit blocks hold the exact tangent of M(q) q'' - F, with
                ! d(M a)/dq at the current accelerations; the first-order path differences F
                ! alone (M(q) - g dF/dy), so the two Newton matrices differ by g^2 d(M a)/dq.
                ! The reduction is checked against the dense first-order matrix of the same
                ! blocks, solved by LAPACK
                call dense_from_blocks(model, y, kind, g, a)
                xf = b
                call dgesv(n, 1, a, n, ipiv, xf, n, info)
                write (label, '(a, es8.1, a)') kind//', implicit form, g = ', g, &
                    ': reduced solve = dense solve of the first-order matrix of its blocks'
                call suite%check_le(maxval(abs(x - xf)), 1.0e-9_wp*maxval(abs(xf)), trim(label))
                cycle
            end if
            call suite%check_le(maxval(abs(x - xf)), 1.0e-9_wp*maxval(abs(xf)), trim(label))
            ! the dense I - g J of the analytic Jacobian, LAPACK
            a = 0.0_wp
            do j = 1, n
                do i = max(1, j - mu), min(n, j + ml)
                    a(i, j) = -g*jb(mu + 1 + i - j, j)
                end do
                a(j, j) = a(j, j) + 1.0_wp
            end do
            call dgesv(n, 1, a, n, ipiv, b, n, info)
            write (label, '(a, es8.1, a)') kind//', g = ', g, &
                ': reduced solve = dense solve of I - g J'
            call suite%check_le(maxval(abs(x - b)), 1.0e-9_wp*maxval(abs(b)), trim(label))
        end do
    end subroutine test_rope

    !> [[I, -g I], [-g K, M_v - g C]] in the unknowns' order, from the model's blocks.
    subroutine dense_from_blocks(model, y, kind, g, a)
        class(rope_model_t), intent(inout) :: model
    real(wp), intent(in) :: y(:)
    character(len=*), intent(in) :: kind
    real(wp), intent(in) :: g
        real(wp), intent(out) :: a(:, :)
        integer, allocatable :: pos(:), vel(:)
        real(wp), allocatable :: kb(:, :), cb(:, :), mb(:, :)
        integer :: kl, ku, np, p, r, off, st
        call model%second_order_layout(pos, vel, kl, ku)
        np = size(pos)
        off = ku + 1
        allocate (kb(kl + ku + 1, np), cb(kl + ku + 1, np), mb(kl + ku + 1, np))
        kb = 0.0_wp
        cb = 0.0_wp
        mb = 0.0_wp
        call model%second_order_blocks(0.1_wp, y, .true., kb, cb, mb, off, st)
        call suite%check_true(st == STATUS_OK, kind//': implicit blocks evaluated')
        a = 0.0_wp
        do p = 1, np
            a(pos(p), pos(p)) = 1.0_wp
            a(pos(p), vel(p)) = -g
            do r = max(1, p - ku), min(np, p + kl)
                a(vel(r), pos(p)) = -g*kb(off + r - p, p)
                a(vel(r), vel(p)) = mb(off + r - p, p) - g*cb(off + r - p, p)
            end do
        end do
    end subroutine dense_from_blocks

end program test_newton_matrix
