!> The static equilibrium of a scene's line, checked: the descent from the scene's start
!! (ropedyn_statics' find_equilibrium), and where it fails, or ends in a false equilibrium,
!! the descent again from a catenary between the supports (ropedyn_catenary_start;
!! docs/theory/statics-modes.md, "A catenary start").
!!
!! A false equilibrium: the statics keep the axial springs' linear law (a line hanging in
!! tension is the same under it), so a line that carries tension only (&rope compression =
!! .false.) can come to rest compressed, its lower part folded back and forth on the
!! ground, the folds held by the compression (a 150 m mooring chain from its scene's start:
!! joints compressed by 39 kN, the fairlead tension 21 % high). The line cannot carry that
!! compression, so it is no equilibrium of the line. A compression beyond FALSE_COMPRESSION
!! of the weight starts the descent again from the catenary, and the lesser compression
!! wins. What is left beyond that share is kept with a caution that says what it means: up
!! to an element's weight the discretization's own (an element whose end rests on the
!! ground under the line above it, as where a slack chain hangs straight down onto the
!! seabed, carries up to its weight); beyond it, a fold or a line pushed (a stiff wire
!! between anchors closer than its length) that the statics' linear law holds.
!! Two more false equilibria are checked on every line: sections turned inside out (an
!! axial force below -EA), and a line with bending stiffness wound by whole turns
!! (neighbouring angles more than half a turn apart: loops its bending springs hold),
!! which first descends again with the turns taken off.
module ropedyn_line_equilibrium
    use ropedyn_kinds, only: wp, i8, PI
    use ropedyn_error, only: error_t, ERR_SOLVER
    use ropedyn_text, only: int_text, significant_text
    use ropedyn_rope_model, only: rope_model_t
    use ropedyn_rope_spec, only: rope_spec_t
    use ropedyn_rope_section, only: rope_section, section_t
    use ropedyn_statics, only: statics_options_t, statics_result_t, find_equilibrium, &
        check_equilibrium_exists
    use ropedyn_catenary_start, only: catenary_start
    implicit none
    private
    public :: static_equilibrium

    !> a compression beyond this share of the line's weight is no equilibrium of a line that
    !! carries tension only (rounding and the iteration's last step leave far less)
    real(wp), parameter :: FALSE_COMPRESSION = 1.0e-3_wp

    !> What marks a state as a false equilibrium: sections turned inside out, whole turns
    !! between neighbours (a wound line), the largest compression of a line that carries
    !! tension only; and the bounds that compression is judged against.
    type :: compression_t
        real(wp) :: force = 0.0_wp           !< N (0: none, or a line that may be compressed)
        integer :: joint = 0                 !< where (0 the top)
        real(wp) :: weight = 0.0_wp          !< the line's, N
        real(wp) :: element_weight = 0.0_wp  !< its heaviest element's, N
        logical :: ground = .false.          !< the scene has a ground
        !> joints where neighbouring elements' angles differ by more than half a turn: a
        !! line wound by whole turns, which its bending springs hold
        integer :: wound = 0
        !> joints compressed by more than their section's length (strain below -1): turned
        !! inside out, no equilibrium of any line (the linear law holds them)
        integer :: inverted = 0
    contains
        procedure :: worse => compression_worse
        procedure :: suspect => compression_suspect
        procedure :: false => compression_false
        procedure :: text => compression_text
    end type compression_t

contains

    !> The equilibrium from the starting state y, as find_equilibrium, checked for a false
    !! equilibrium (compression_t: sections turned inside out, a wound line, a line that
    !! carries tension only left compressed): a wound one descends again with its whole
    !! turns taken off; then, where the first descent failed or the result is still
    !! suspect, from a catenary between the supports. The better result wins
    !! (compression_t%worse; result%restart says which start and why); what is left is
    !! kept with result%caution. On success y holds the equilibrium.
    subroutine static_equilibrium(model, spec, y, options, result, err)
        class(rope_model_t), intent(inout) :: model
        type(rope_spec_t), intent(in) :: spec
        real(wp), intent(inout) :: y(:)
        type(statics_options_t), intent(in) :: options
        type(statics_result_t), intent(out) :: result
        type(error_t), allocatable, intent(out) :: err
        type(statics_result_t) :: second
        type(error_t), allocatable :: err2
        type(compression_t) :: c1, c2
        real(wp), allocatable :: y_start(:), y_cat(:)
        character(len=:), allocatable :: why, tried
        logical :: found
        ! (a scene without an equilibrium is said at once, from any start)
        call check_equilibrium_exists(spec, err)
        if (allocated(err)) return
        y_start = y
        call find_equilibrium(model, spec, y, options, result, err)
        if (allocated(err)) then
            if (err%code /= ERR_SOLVER) return
            why = 'from the scene''s start: '//reason(err%message)
        else
            c1 = compression_at(model, spec, y, result%weight)
            if (.not. c1%suspect()) return
            why = 'from the scene''s start the line '//c1%text()
            if (c1%wound > 0) then
                call unwound_descent(model, spec, y, options, result, c1, why)
                if (.not. c1%suspect()) return
            end if
        end if
        y_cat = y_start
        call catenary_start(model, spec, y_cat, found)
        tried = ''
        if (found) then
            call find_equilibrium(model, spec, y_cat, options, second, err2)
            if (allocated(err2)) then
                tried = '; from a catenary between the supports: '//reason(err2%message)
            else
                c2 = compression_at(model, spec, y_cat, second%weight)
                tried = '; from a catenary between the supports the line '//c2%text()
                if (allocated(err) .or. c1%worse(c2)) then
                    if (allocated(err)) deallocate (err)
                    call take(result, y, c1, second, y_cat, c2, &
                              'a catenary between the supports ('//why//')')
                end if
            end if
        end if
        if (allocated(err)) then
            err%message = err%message//tried
        else if (c1%suspect()) then
            result%caution = 'the line '//c1%text()
        end if
    end subroutine static_equilibrium

    !> The descent again from the equilibrium y of a wound line with its whole turns taken
    !! off (each element's angle brought within half a turn of its neighbour's above it: the
    !! same shape without the loops); where that is the better equilibrium (compression_t
    !! %worse), it replaces y, `result` (with result%restart) and `c`.
    subroutine unwound_descent(model, spec, y, options, result, c, why)
        class(rope_model_t), intent(inout) :: model
        type(rope_spec_t), intent(in) :: spec
        real(wp), intent(inout) :: y(:)
        type(statics_options_t), intent(in) :: options
        type(statics_result_t), intent(inout) :: result
        type(compression_t), intent(inout) :: c
        character(len=*), intent(in) :: why
        type(statics_result_t) :: again
        type(compression_t) :: c_again
        type(error_t), allocatable :: err
        integer, allocatable :: at(:)
        real(wp), allocatable :: y_again(:)
        real(wp), parameter :: TWO_PI = 2.0_wp*PI
        integer :: k
        at = angle_places(model)
        y_again = y
        do k = 2, size(at)
            y_again(at(k)) = y_again(at(k)) - &
                TWO_PI*anint((y_again(at(k)) - y_again(at(k - 1)))/TWO_PI)
        end do
        call find_equilibrium(model, spec, y_again, options, again, err)
        if (allocated(err)) return
        c_again = compression_at(model, spec, y_again, again%weight)
        if (.not. c%worse(c_again)) return
        call take(result, y, c, again, y_again, c_again, &
                  'its equilibrium with the whole turns taken off ('//why//')')
    end subroutine unwound_descent

    !> The equilibrium of a later start (`later`, `y_later`, `c_later`) replaces the one kept
    !! (`result`, `y`, `c`): its counts include those of the descents before it, and its
    !! restart says where it came from and why.
    subroutine take(result, y, c, later, y_later, c_later, restart)
        type(statics_result_t), intent(inout) :: result
        real(wp), intent(inout) :: y(:)
        type(compression_t), intent(inout) :: c
        type(statics_result_t), intent(in) :: later
        real(wp), intent(in) :: y_later(:)
        type(compression_t), intent(in) :: c_later
        character(len=*), intent(in) :: restart
        integer :: iterations, rejected
        iterations = result%iterations + later%iterations
        rejected = result%rejected + later%rejected
        result = later
        result%iterations = iterations
        result%rejected = rejected
        result%restart = restart
        y = y_later
        c = c_later
    end subroutine take

    !> The check of the state y (compression_t): its inverted joints, its wound ones (with
    !! bending springs), and for a line that carries tension only its compression under the
    !! statics' linear law, which the forces of a run would clip (force 0 for a line that
    !! may be compressed, or without weight).
    function compression_at(model, spec, y, weight) result(c)
        class(rope_model_t), intent(inout) :: model
        type(rope_spec_t), intent(in) :: spec
        real(wp), intent(in) :: y(:), weight
        type(compression_t) :: c
        real(wp) :: axial(0:model%n_elements()), shear(0:model%n_elements())
        real(wp) :: moment(0:model%n_elements()), reaction(2, 2)
        real(wp) :: lengths(model%n_elements()), masses(model%n_elements())
        type(section_t) :: sec
        logical :: held
        ! (without bending springs a whole turn between neighbours changes no force)
        sec = rope_section(spec%rope)
        if (spec%effects%bending .and. sec%ei > 0.0_wp) c%wound = wound_joints(model, y)
        held = model%supports_at_rest
        model%supports_at_rest = .true.
        call model%internal_forces(0.0_wp, y, axial, shear, moment, reaction)
        model%supports_at_rest = held
        ! a section shortened by more than its length (axial force below -EA: strain < -1)
        if (spec%effects%tension .and. sec%ea > 0.0_wp) c%inverted = count(axial < -sec%ea)
        if (.not. model%tension_only .or. .not. weight > 0.0_wp) return
        call model%element_data(lengths, masses)
        c%weight = weight
        c%element_weight = weight*maxval(masses)/sum(masses)
        c%ground = spec%effects%ground
        c%joint = minloc(axial, 1) - 1
        c%force = max(0.0_wp, -axial(c%joint))
    end function compression_at

    !> Wound, or compressed beyond FALSE_COMPRESSION of the weight: no equilibrium of the
    !! line (a compression within an element's weight excepted: compression_text).
    pure logical function compression_suspect(self) result(suspect)
        class(compression_t), intent(in) :: self
        suspect = self%inverted > 0 .or. self%wound > 0 .or. &
                  self%force > FALSE_COMPRESSION*self%weight
    end function compression_suspect

    !> `other` is the better equilibrium: fewer inverted joints, then fewer wound ones, then
    !! less compressed.
    pure logical function compression_worse(self, other) result(worse)
        class(compression_t), intent(in) :: self
        type(compression_t), intent(in) :: other
        worse = other%inverted < self%inverted .or. (other%inverted == self%inverted .and. &
                (other%wound < self%wound .or. &
                 (other%wound == self%wound .and. other%force < self%force)))
    end function compression_worse

    !> The joints where neighbouring elements' angles differ by more than half a turn.
    function wound_joints(model, y) result(wound)
        class(rope_model_t), intent(in) :: model
        real(wp), intent(in) :: y(:)
        integer :: wound
        real(wp), allocatable :: phi(:)
        phi = y(angle_places(model))
        wound = 0
        if (size(phi) > 1) wound = count(abs(phi(2:) - phi(:size(phi) - 1)) > PI)
    end function wound_joints

    !> Where the elements' angles sit in the state, in order along the line (the model's
    !! angle coordinates).
    function angle_places(model) result(at)
        class(rope_model_t), intent(in) :: model
        integer, allocatable :: at(:)
        integer, allocatable :: pos(:), vel(:)
        call model%coordinates(pos, vel)
        at = pack(pos, model%angle_coordinates())
    end function angle_places

    !> Compressed beyond FALSE_COMPRESSION of the weight and beyond the weight of an
    !! element: a fold or a push the linear law holds.
    pure logical function compression_false(self) result(false)
        class(compression_t), intent(in) :: self
        false = self%force > FALSE_COMPRESSION*self%weight .and. &
                self%force > self%element_weight
    end function compression_false

    !> 'is compressed by F N at joint j (P of its weight), which it cannot carry (&rope
    !! compression = .false.): ...' with what it means.
    function compression_text(self) result(text)
        class(compression_t), intent(in) :: self
        character(len=:), allocatable :: text
        if (self%inverted > 0) then
            text = 'is compressed beyond its length at '//int_text(self%inverted)// &
                ' joint'//trim(merge('s', ' ', self%inverted > 1))//' (a strain below -1: '// &
                'sections turned inside out, which the springs'' linear law holds): no '// &
                'equilibrium of any line; check the anchors and the start'
            return
        end if
        if (self%wound > 0) then
            text = 'is wound by whole turns at '//int_text(self%wound)//' joint'// &
                trim(merge('s', ' ', self%wound > 1))//' (neighbouring elements turned '// &
                'more than half a turn apart: loops its bending springs hold); check the '// &
                'shape and the tensions, or start from another &initial angle_deg'
            if (self%force > FALSE_COMPRESSION*self%weight) text = text//', and '// &
                compressed_text(self)
            return
        end if
        text = compressed_text(self)
    end function compression_text

    !> 'is compressed by ...' with what it means (compression_text).
    function compressed_text(self) result(text)
        class(compression_t), intent(in) :: self
        character(len=:), allocatable :: text
        text = 'is compressed by '//significant_text(self%force, 3)//' N at joint '// &
            int_text(self%joint)//' ('//share_text(self%force/self%weight)// &
            ' its weight), which it cannot carry (&rope compression = .false.)'
        if (self%false()) then
            text = text//': the statics keep the springs'' linear law, which holds it (a '// &
                'fold, its tensions too high, or a stiff line pushed between its anchors): '// &
                'no equilibrium of the line; check the tensions, or set compression = .true.'
        else if (self%ground) then
            text = text//', less than the weight of one element: an element standing on '// &
                'the ground where the line comes down onto it, within the discretization''s '// &
                'error'
        else
            text = text//', less than the weight of one element: within the '// &
                'discretization''s error'
        end if
    end function compressed_text

    !> 'P of' (a share below 1) or 'P times' (from 1 on), 2 significant digits.
    function share_text(share) result(text)
        real(wp), intent(in) :: share
        character(len=:), allocatable :: text
        if (share < 1.0_wp) then
            text = significant_text(share, 2)//' of'
        else if (share < 10.0_wp) then
            text = significant_text(share, 2)//' times'
        else
            text = int_text(nint(share, i8))//' times'
        end if
    end function share_text

    !> An error of the statics without the scene's name and 'statics: ' before it (the
    !! message that quotes it names them once).
    function reason(message) result(text)
        character(len=*), intent(in) :: message
        character(len=:), allocatable :: text
        integer :: k
        k = index(message, 'statics: ')
        text = message
        if (k > 0) text = message(k + len('statics: '):)
    end function reason
end module ropedyn_line_equilibrium
