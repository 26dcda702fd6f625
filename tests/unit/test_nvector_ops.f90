!> CVODE's vector operations compiled by us (solvers/cvode/ropedyn_nvector_ops.c) against
!! the library's serial ones: every operation CVODE can call, with the special cases of the
!! coefficients (1, -1, 0, a = b, a = -b) and the aliasings (z = x, z = y, an input of a
!! fused operation that is also its output), on vectors with zeros and both signs. The
!! results must be bit for bit those of the library (its fused operations: its fallback
!! loops of single operations), so that CVODE takes the same steps with either.
program test_nvector_ops
    use, intrinsic :: iso_c_binding
    use ropedyn_kinds, only: wp
    use ropedyn_assert, only: test_suite_t
    use fsundials_context_mod, only: FSUNContext_Create, FSUNContext_Free
    use fsundials_nvector_mod
    use fnvector_serial_mod, only: FN_VMake_Serial
    implicit none

    interface
        integer(c_int) function nvector_fast_ops(v) bind(C, name='ropedyn_nvector_fast_ops')
            import :: c_int, N_Vector
            type(N_Vector) :: v
        end function nvector_fast_ops
    end interface

    !> An N_Vector pointer per entry, so that arrays of them can be made.
    type :: vec_t
        type(N_Vector), pointer :: v => null()
    end type vec_t

    integer, parameter :: N = 23, NV = 12
    real(wp), parameter :: COEFS(7) = [1.0_wp, -1.0_wp, 0.0_wp, 2.5_wp, -2.5_wp, 0.3_wp, &
                                       -7.0_wp/3.0_wp]
    type(test_suite_t) :: suite
    type(c_ptr) :: ctx
    real(c_double), target :: dr(N, NV), df(N, NV), d0(N, NV)
    type(vec_t) :: r(NV), f(NV)
    integer :: j, k, iz, ia, ib, nvec, bad
    integer(c_int) :: flag
    real(c_double) :: sr, sf, cr(NV), cf(NV), coef(NV)
    type(c_ptr) :: ar, af, br, bf, zr, zf
    !> storage of the N_Vector arrays (C: N_Vector *) passed to the fused operations
    type(c_ptr), target :: slots(NV, 6)

    suite%name = 'test_nvector_ops'
    flag = FSUNContext_Create(c_null_ptr, ctx)
    call random_seed(put=[(7*k + 3, k = 1, 64)])
    call random_number(d0)
    d0 = 4.0_wp*d0 - 2.0_wp
    d0(3, :) = 0.0_wp          ! zeros (InvTest, MinQuotient, ConstrMask)
    d0(5, 2) = 1.0_wp
    d0(7, 1) = -1.5_wp
    d0(8, 1) = 1.7_wp
    do k = 1, NV
        r(k)%v => FN_VMake_Serial(int(N, c_int64_t), dr(:, k), ctx)
        f(k)%v => FN_VMake_Serial(int(N, c_int64_t), df(:, k), ctx)
        flag = nvector_fast_ops(f(k)%v)
    end do
    call suite%check_true(flag == 0, 'the operations of a serial vector are replaced')

    ! ---- single operations ----
    bad = 0
    do ia = 1, size(COEFS)
        do ib = 1, size(COEFS)
            do iz = 1, 3   ! z = x, z = y, z separate
                call reset()
                call FN_VLinearSum(COEFS(ia), r(1)%v, COEFS(ib), r(2)%v, r(iz)%v)
                call FN_VLinearSum(COEFS(ia), f(1)%v, COEFS(ib), f(2)%v, f(iz)%v)
                if (.not. same()) bad = bad + 1
            end do
        end do
    end do
    call suite%check_true(bad == 0, 'LinearSum: all coefficient cases and aliasings')
    bad = 0
    do ia = 1, size(COEFS)
        do iz = 1, 2
            call reset()
            call FN_VScale(COEFS(ia), r(1)%v, r(iz)%v)
            call FN_VScale(COEFS(ia), f(1)%v, f(iz)%v)
            if (.not. same()) bad = bad + 1
        end do
        call reset()
        call FN_VConst(COEFS(ia), r(3)%v)
        call FN_VConst(COEFS(ia), f(3)%v)
        if (.not. same()) bad = bad + 1
        call reset()
        call FN_VAddConst(r(1)%v, COEFS(ia), r(3)%v)
        call FN_VAddConst(f(1)%v, COEFS(ia), f(3)%v)
        if (.not. same()) bad = bad + 1
        call reset()
        call FN_VCompare(abs(COEFS(ia)), r(1)%v, r(3)%v)
        call FN_VCompare(abs(COEFS(ia)), f(1)%v, f(3)%v)
        if (.not. same()) bad = bad + 1
    end do
    call suite%check_true(bad == 0, 'Scale, Const, AddConst, Compare')
    bad = 0
    call reset()
    call FN_VProd(r(1)%v, r(2)%v, r(3)%v)
    call FN_VProd(f(1)%v, f(2)%v, f(3)%v)
    if (.not. same()) bad = bad + 1
    call reset()
    call FN_VDiv(r(1)%v, r(4)%v, r(3)%v)
    call FN_VDiv(f(1)%v, f(4)%v, f(3)%v)
    if (.not. same()) bad = bad + 1
    call reset()
    call FN_VAbs(r(1)%v, r(3)%v)
    call FN_VAbs(f(1)%v, f(3)%v)
    if (.not. same()) bad = bad + 1
    call reset()
    call FN_VInv(r(4)%v, r(3)%v)
    call FN_VInv(f(4)%v, f(3)%v)
    if (.not. same()) bad = bad + 1
    call reset()
    if (FN_VInvTest(r(1)%v, r(3)%v) /= FN_VInvTest(f(1)%v, f(3)%v)) bad = bad + 1
    if (.not. same()) bad = bad + 1
    if (FN_VInvTest(r(4)%v, r(3)%v) /= FN_VInvTest(f(4)%v, f(3)%v)) bad = bad + 1
    if (.not. same()) bad = bad + 1
    call reset()
    dr(:, 5) = anint(dr(:, 5))   ! constraint flags -2 .. 2
    df(:, 5) = dr(:, 5)
    if (FN_VConstrMask(r(5)%v, r(1)%v, r(3)%v) /= FN_VConstrMask(f(5)%v, f(1)%v, f(3)%v)) &
        bad = bad + 1
    if (.not. same()) bad = bad + 1
    call suite%check_true(bad == 0, 'Prod, Div, Abs, Inv, InvTest, ConstrMask')

    ! ---- reductions (bitwise equal scalars) ----
    call reset()
    bad = 0
    if (FN_VDotProd(r(1)%v, r(2)%v) /= FN_VDotProd(f(1)%v, f(2)%v)) bad = bad + 1
    if (FN_VMaxNorm(r(1)%v) /= FN_VMaxNorm(f(1)%v)) bad = bad + 1
    if (FN_VWrmsNorm(r(1)%v, r(2)%v) /= FN_VWrmsNorm(f(1)%v, f(2)%v)) bad = bad + 1
    if (FN_VWrmsNormMask(r(1)%v, r(2)%v, r(6)%v) /= FN_VWrmsNormMask(f(1)%v, f(2)%v, f(6)%v)) &
        bad = bad + 1
    if (FN_VMin(r(1)%v) /= FN_VMin(f(1)%v)) bad = bad + 1
    if (FN_VWL2Norm(r(1)%v, r(2)%v) /= FN_VWL2Norm(f(1)%v, f(2)%v)) bad = bad + 1
    if (FN_VL1Norm(r(1)%v) /= FN_VL1Norm(f(1)%v)) bad = bad + 1
    if (FN_VMinQuotient(r(1)%v, r(2)%v) /= FN_VMinQuotient(f(1)%v, f(2)%v)) bad = bad + 1
    if (FN_VWSqrSumLocal(r(1)%v, r(2)%v) /= FN_VWSqrSumLocal(f(1)%v, f(2)%v)) bad = bad + 1
    if (FN_VWSqrSumMaskLocal(r(1)%v, r(2)%v, r(6)%v) /= &
        FN_VWSqrSumMaskLocal(f(1)%v, f(2)%v, f(6)%v)) bad = bad + 1
    if (FN_VDotProdLocal(r(1)%v, r(2)%v) /= FN_VDotProdLocal(f(1)%v, f(2)%v)) bad = bad + 1
    call suite%check_true(bad == 0, 'DotProd, MaxNorm, WrmsNorm(Mask), Min, WL2Norm, L1Norm, '// &
                          'MinQuotient, WSqrSum(Mask)Local: bitwise equal')
    sr = FN_VWrmsNorm(r(1)%v, r(2)%v)
    sf = sqrt(sum((d0(:, 1)*d0(:, 2))**2)/N)
    call suite%check_close(sr, sf, 1.0e-14_wp, 0.0_wp, 'WrmsNorm is the weighted RMS norm')

    ! ---- fused operations against the library's fallback loops ----
    bad = 0
    do nvec = 1, 10
        coef(1:nvec) = [(COEFS(mod(k - 1, size(COEFS)) + 1), k = 1, nvec)]
        do iz = 1, 3   ! z separate, z = X(1), z = X(2) (an input the fallback overwrites)
            if (iz == 3 .and. nvec < 2) cycle
            call reset()
            ar = vector_array(1, r, [(k, k = 1, nvec)])
            af = vector_array(2, f, [(k, k = 1, nvec)])
            j = merge(NV, iz - 1, iz == 1)
            flag = FN_VLinearCombination(int(nvec, c_int), coef, ar, r(j)%v)
            flag = FN_VLinearCombination(int(nvec, c_int), coef, af, f(j)%v)
            if (.not. same()) bad = bad + 1
        end do
    end do
    call suite%check_true(bad == 0, 'LinearCombination, 1 .. 10 vectors, z separate or an input')
    bad = 0
    do iz = 1, 3   ! Z = Y, Z separate, one Z = x
        nvec = 4
        call reset()
        coef(1:nvec) = [1.0_wp, -1.0_wp, 2.5_wp, 0.3_wp]
        br = vector_array(3, r, [2, 3, 4, 5])
        bf = vector_array(4, f, [2, 3, 4, 5])
        select case (iz)
        case (1)
            zr = vector_array(5, r, [2, 3, 4, 5])
            zf = vector_array(6, f, [2, 3, 4, 5])
        case (2)
            zr = vector_array(5, r, [6, 7, 8, 9])
            zf = vector_array(6, f, [6, 7, 8, 9])
        case default
            zr = vector_array(5, r, [6, 1, 8, 9])
            zf = vector_array(6, f, [6, 1, 8, 9])
        end select
        flag = FN_VScaleAddMulti(int(nvec, c_int), coef, r(1)%v, br, zr)
        flag = FN_VScaleAddMulti(int(nvec, c_int), coef, f(1)%v, bf, zf)
        if (.not. same()) bad = bad + 1
        flag = FN_VDotProdMulti(int(nvec, c_int), r(1)%v, br, cr)
        flag = FN_VDotProdMulti(int(nvec, c_int), f(1)%v, bf, cf)
        if (any(cr(1:nvec) /= cf(1:nvec))) bad = bad + 1
        flag = FN_VWrmsNormVectorArray(int(nvec, c_int), br, zr, cr)
        flag = FN_VWrmsNormVectorArray(int(nvec, c_int), bf, zf, cf)
        if (any(cr(1:nvec) /= cf(1:nvec))) bad = bad + 1
        flag = FN_VWrmsNormMaskVectorArray(int(nvec, c_int), br, zr, r(10)%v, cr)
        flag = FN_VWrmsNormMaskVectorArray(int(nvec, c_int), bf, zf, f(10)%v, cf)
        if (any(cr(1:nvec) /= cf(1:nvec))) bad = bad + 1
        flag = FN_VScaleVectorArray(int(nvec, c_int), coef, br, zr)
        flag = FN_VScaleVectorArray(int(nvec, c_int), coef, bf, zf)
        if (.not. same()) bad = bad + 1
        do ia = 1, size(COEFS)
            flag = FN_VLinearSumVectorArray(int(nvec, c_int), COEFS(ia), br, COEFS(8 - ia), &
                                            zr, zr)
            flag = FN_VLinearSumVectorArray(int(nvec, c_int), COEFS(ia), bf, COEFS(8 - ia), &
                                            zf, zf)
            if (.not. same()) bad = bad + 1
        end do
        flag = FN_VConstVectorArray(int(nvec, c_int), 0.7_wp, zr)
        flag = FN_VConstVectorArray(int(nvec, c_int), 0.7_wp, zf)
        if (.not. same()) bad = bad + 1
    end do
    call suite%check_true(bad == 0, 'ScaleAddMulti (Z = Y, Z separate, Z(2) = x), '// &
                          'DotProdMulti, WrmsNorm(Mask)VectorArray, Scale/LinearSum/'// &
                          'ConstVectorArray')

    ! ---- clones keep the operations (CVODE's vectors are clones) ----
    block
        type(N_Vector), pointer :: c1, c2
        real(c_double), pointer :: p1(:), p2(:)
        c1 => FN_VClone(r(1)%v)
        c2 => FN_VClone(f(1)%v)
        call reset()
        call FN_VLinearSum(2.5_wp, r(1)%v, 0.3_wp, r(2)%v, c1)
        call FN_VLinearSum(2.5_wp, f(1)%v, 0.3_wp, f(2)%v, c2)
        p1 => FN_VGetArrayPointer(c1)
        p2 => FN_VGetArrayPointer(c2)
        call suite%check_true(all(p1 == p2) .and. all(p2 == 2.5_wp*d0(:, 1) + 0.3_wp*d0(:, 2)), &
                              'a clone computes the same (and the right) linear sum')
        call suite%check_true(c_associated(c_funloc_of(c2)) .and. &
                              .not. same_op(c1, c2), 'a clone has the compiled operations')
        call FN_VDestroy(c1)
        call FN_VDestroy(c2)
    end block

    do k = 1, NV
        call FN_VDestroy(r(k)%v)
        call FN_VDestroy(f(k)%v)
    end do
    flag = FSUNContext_Free(ctx)
    call suite%finish()

contains

    subroutine reset()
        dr = d0
        df = d0
    end subroutine reset

    logical function same()
        same = all(dr == df .or. (dr /= dr .and. df /= df))
    end function same

    !> An N_Vector array (C) in storage slot `slot` holding vs(idx(1)), vs(idx(2)), ...
    type(c_ptr) function vector_array(slot, vs, idx) result(a)
        integer, intent(in) :: slot
        type(vec_t), intent(in) :: vs(:)
        integer, intent(in) :: idx(:)
        integer :: m
        do m = 1, size(idx)
            slots(m, slot) = c_loc(vs(idx(m))%v)
        end do
        a = c_loc(slots(1, slot))
    end function vector_array

    !> The linear-sum entry of a vector's operation table.
    type(c_funptr) function linear_sum_op(v) result(p)
        type(N_Vector), intent(in) :: v
        type(N_Vector_Ops), pointer :: ops
        call c_f_pointer(v%ops, ops)
        p = ops%nvlinearsum
    end function linear_sum_op

    logical function same_op(a, b)
        type(N_Vector), intent(in) :: a, b
        same_op = c_associated(linear_sum_op(a), linear_sum_op(b))
    end function same_op

    type(c_ptr) function c_funloc_of(v) result(p)
        type(N_Vector), intent(in) :: v
        p = v%ops
    end function c_funloc_of
end program test_nvector_ops
