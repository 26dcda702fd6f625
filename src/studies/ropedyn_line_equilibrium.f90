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
module ropedyn_line_equilibrium
    use ropedyn_kinds, only: wp
    use ropedyn_error, only: error_t, ERR_SOLVER
    use ropedyn_text, only: int_text, significant_text
    use ropedyn_rope_model, only: rope_model_t
    use ropedyn_rope_spec, only: rope_spec_t
    use ropedyn_statics, only: statics_options_t, statics_result_t, find_equilibrium, &
        check_equilibrium_exists
    use ropedyn_catenary_start, only: catenary_start
    implicit none
    private
    public :: static_equilibrium

    !> a compression beyond this share of the line's weight is no equilibrium of a line that
    !! carries tension only (rounding and the iteration's last step leave far less)
    real(wp), parameter :: FALSE_COMPRESSION = 1.0e-3_wp

    !> The largest compression of a line's axial springs at a state, against the bounds.
    type :: compression_t
        real(wp) :: force = 0.0_wp           !< N (0: none, or a line that may be compressed)
        integer :: joint = 0                 !< where (0 the top)
        real(wp) :: weight = 0.0_wp          !< the line's, N
        real(wp) :: element_weight = 0.0_wp  !< its heaviest element's, N
    contains
        procedure :: suspect => compression_suspect
        procedure :: false => compression_false
        procedure :: text => compression_text
    end type compression_t

contains

    !> The equilibrium from the starting state y, as find_equilibrium, checked for a false
    !! equilibrium; from a catenary between the supports where the first descent fails or
    !! leaves the line compressed (result%restart says why; the lesser compression wins). A
    !! compression left is kept with result%caution. On success y holds the equilibrium.
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
            why = 'from the scene''s start: '//err%message
        else
            c1 = compression_at(model, y, result%weight)
            if (.not. c1%suspect()) return
            why = 'from the scene''s start the line '//c1%text()
        end if
        y_cat = y_start
        call catenary_start(model, spec, y_cat, found)
        tried = ''
        if (found) then
            call find_equilibrium(model, spec, y_cat, options, second, err2)
            if (allocated(err2)) then
                tried = '; from a catenary between the supports: '//err2%message
            else
                c2 = compression_at(model, y_cat, second%weight)
                tried = '; from a catenary between the supports the line '//c2%text()
                if (allocated(err) .or. c2%force < c1%force) then
                    if (allocated(err)) deallocate (err)
                    second%iterations = second%iterations + result%iterations
                    second%rejected = second%rejected + result%rejected
                    second%restart = why
                    result = second
                    y = y_cat
                    c1 = c2
                end if
            end if
        end if
        if (allocated(err)) then
            err%message = err%message//tried
        else if (c1%suspect()) then
            result%caution = 'the line '//c1%text()
        end if
    end subroutine static_equilibrium

    !> The compression of a line that carries tension only at the state y under the
    !! statics' linear law, which the forces of a run would clip (force 0 for a line that
    !! may be compressed, or without weight).
    function compression_at(model, y, weight) result(c)
        class(rope_model_t), intent(inout) :: model
        real(wp), intent(in) :: y(:), weight
        type(compression_t) :: c
        real(wp) :: axial(0:model%n_elements()), shear(0:model%n_elements())
        real(wp) :: moment(0:model%n_elements()), reaction(2, 2)
        real(wp) :: lengths(model%n_elements()), masses(model%n_elements())
        logical :: held
        if (.not. model%tension_only .or. .not. weight > 0.0_wp) return
        call model%element_data(lengths, masses)
        c%weight = weight
        c%element_weight = weight*maxval(masses)/sum(masses)
        held = model%supports_at_rest
        model%supports_at_rest = .true.
        call model%internal_forces(0.0_wp, y, axial, shear, moment, reaction)
        model%supports_at_rest = held
        c%joint = minloc(axial, 1) - 1
        c%force = max(0.0_wp, -axial(c%joint))
    end function compression_at

    !> Beyond FALSE_COMPRESSION of the weight: no equilibrium of the line, unless within an
    !! element's weight.
    pure logical function compression_suspect(self) result(suspect)
        class(compression_t), intent(in) :: self
        suspect = self%force > FALSE_COMPRESSION*self%weight
    end function compression_suspect

    !> Suspect and beyond the weight of an element: a fold or a push the linear law holds.
    pure logical function compression_false(self) result(false)
        class(compression_t), intent(in) :: self
        false = self%suspect() .and. self%force > self%element_weight
    end function compression_false

    !> 'is compressed by F N at joint j (P of its weight), which it cannot carry (&rope
    !! compression = .false.): ...' with what it means.
    function compression_text(self) result(text)
        class(compression_t), intent(in) :: self
        character(len=:), allocatable :: text
        text = 'is compressed by '//significant_text(self%force, 3)//' N at joint '// &
            int_text(self%joint)//' ('//significant_text(self%force/self%weight, 2)// &
            ' of its weight), which it cannot carry (&rope compression = .false.)'
        if (self%false()) then
            text = text//': the statics keep the springs'' linear law, which holds it (a '// &
                'fold, its tensions too high, or a stiff line pushed between its anchors): '// &
                'no equilibrium of the line; check the tensions, or set compression = .true.'
        else
            text = text//', less than the weight of one element: an element standing on '// &
                'the ground where the line comes down onto it, within the discretization''s '// &
                'error'
        end if
    end function compression_text
end module ropedyn_line_equilibrium
