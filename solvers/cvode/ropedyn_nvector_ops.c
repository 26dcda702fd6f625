/*
 * Vector operations for CVODE's serial N_Vectors, compiled with this project's flags.
 *
 * Debian's SUNDIALS 6.4.1 libraries are built without optimization (-O0: every element of
 * every vector operation goes through the stack, about 20 instructions per element), and
 * CVODE spends most of a step in these operations (docs/theory/cvode.md, "What ropedyn adds").
 * ropedyn_nvector_fast_ops(v) replaces the operations of a serial vector made by
 * N_VMake_Serial with the functions below; vectors cloned from it (all of CVODE's
 * internal vectors) copy the table. The content stays the serial one, so
 * N_VGetArrayPointer and the other serial functions keep working.
 *
 * Each operation does the same floating-point operations in the same order as the serial
 * implementation of SUNDIALS 6.4.1, with its special cases (a linear sum with a == b is
 * c (x + y), with a == 1 it is x + b y, ...), and the fused operations do what CVODE's
 * fallback loops of single operations do, element by element: results are bit for bit
 * those of the library (tests/unit/test_nvector_ops.f90 checks that).
 * Reductions stay sequential (no reassociation: no -ffast-math).
 */
#include <math.h>
#include <stddef.h>

#include <nvector/nvector_serial.h>

#define LEN(v) (NV_LENGTH_S(v))
#define DAT(v) (NV_DATA_S(v))

/* ---- element loops ---------------------------------------------------------------- */

static void axpy(sunindextype n, realtype a, const realtype *x, realtype *y)
{
    sunindextype i;
    if (a == 1.0) {
        for (i = 0; i < n; i++) y[i] += x[i];
    } else if (a == -1.0) {
        for (i = 0; i < n; i++) y[i] -= x[i];
    } else {
        for (i = 0; i < n; i++) y[i] += a * x[i];
    }
}

static void linear_sum(realtype a, N_Vector x, realtype b, N_Vector y, N_Vector z)
{
    sunindextype i, n = LEN(x);
    realtype *xd = DAT(x), *yd = DAT(y), *zd = DAT(z), c;
    const realtype *v1, *v2;
    int test;

    if (b == 1.0 && z == y) {
        axpy(n, a, xd, yd);
        return;
    }
    if (a == 1.0 && z == x) {
        axpy(n, b, yd, xd);
        return;
    }
    if (a == 1.0 && b == 1.0) {
        for (i = 0; i < n; i++) zd[i] = xd[i] + yd[i];
        return;
    }
    if ((test = (a == 1.0 && b == -1.0)) || (a == -1.0 && b == 1.0)) {
        v1 = test ? yd : xd;
        v2 = test ? xd : yd;
        for (i = 0; i < n; i++) zd[i] = v2[i] - v1[i];
        return;
    }
    if ((test = (a == 1.0)) || b == 1.0) {
        c = test ? b : a;
        v1 = test ? yd : xd;
        v2 = test ? xd : yd;
        for (i = 0; i < n; i++) zd[i] = (c * v1[i]) + v2[i];
        return;
    }
    if ((test = (a == -1.0)) || b == -1.0) {
        c = test ? b : a;
        v1 = test ? yd : xd;
        v2 = test ? xd : yd;
        for (i = 0; i < n; i++) zd[i] = (c * v1[i]) - v2[i];
        return;
    }
    if (a == b) {
        for (i = 0; i < n; i++) zd[i] = a * (xd[i] + yd[i]);
        return;
    }
    if (a == -b) {
        for (i = 0; i < n; i++) zd[i] = a * (xd[i] - yd[i]);
        return;
    }
    for (i = 0; i < n; i++) zd[i] = (a * xd[i]) + (b * yd[i]);
}

static void vconst(realtype c, N_Vector z)
{
    sunindextype i, n = LEN(z);
    realtype *zd = DAT(z);
    for (i = 0; i < n; i++) zd[i] = c;
}

static void prod(N_Vector x, N_Vector y, N_Vector z)
{
    sunindextype i, n = LEN(x);
    realtype *xd = DAT(x), *yd = DAT(y), *zd = DAT(z);
    for (i = 0; i < n; i++) zd[i] = xd[i] * yd[i];
}

static void vdiv(N_Vector x, N_Vector y, N_Vector z)
{
    sunindextype i, n = LEN(x);
    realtype *xd = DAT(x), *yd = DAT(y), *zd = DAT(z);
    for (i = 0; i < n; i++) zd[i] = xd[i] / yd[i];
}

static void scale(realtype c, N_Vector x, N_Vector z)
{
    sunindextype i, n = LEN(x);
    realtype *xd = DAT(x), *zd = DAT(z);
    if (z == x) {
        for (i = 0; i < n; i++) xd[i] *= c;
    } else if (c == 1.0) {
        for (i = 0; i < n; i++) zd[i] = xd[i];
    } else if (c == -1.0) {
        for (i = 0; i < n; i++) zd[i] = -xd[i];
    } else {
        for (i = 0; i < n; i++) zd[i] = c * xd[i];
    }
}

static void vabs(N_Vector x, N_Vector z)
{
    sunindextype i, n = LEN(x);
    realtype *xd = DAT(x), *zd = DAT(z);
    for (i = 0; i < n; i++) zd[i] = fabs(xd[i]);
}

static void inv(N_Vector x, N_Vector z)
{
    sunindextype i, n = LEN(x);
    realtype *xd = DAT(x), *zd = DAT(z);
    for (i = 0; i < n; i++) zd[i] = 1.0 / xd[i];
}

static void add_const(N_Vector x, realtype b, N_Vector z)
{
    sunindextype i, n = LEN(x);
    realtype *xd = DAT(x), *zd = DAT(z);
    for (i = 0; i < n; i++) zd[i] = xd[i] + b;
}

static realtype dot(N_Vector x, N_Vector y)
{
    sunindextype i, n = LEN(x);
    realtype *xd = DAT(x), *yd = DAT(y), sum = 0.0;
    for (i = 0; i < n; i++) sum += xd[i] * yd[i];
    return sum;
}

static realtype max_norm(N_Vector x)
{
    sunindextype i, n = LEN(x);
    realtype *xd = DAT(x), max = 0.0;
    for (i = 0; i < n; i++)
        if (fabs(xd[i]) > max) max = fabs(xd[i]);
    return max;
}

static realtype wsqr_sum(N_Vector x, N_Vector w)
{
    sunindextype i, n = LEN(x);
    realtype *xd = DAT(x), *wd = DAT(w), sum = 0.0, p;
    for (i = 0; i < n; i++) {
        p = xd[i] * wd[i];
        sum += p * p;
    }
    return sum;
}

static realtype wsqr_sum_mask(N_Vector x, N_Vector w, N_Vector id)
{
    sunindextype i, n = LEN(x);
    realtype *xd = DAT(x), *wd = DAT(w), *idd = DAT(id), sum = 0.0, p;
    for (i = 0; i < n; i++) {
        if (idd[i] > 0.0) {
            p = xd[i] * wd[i];
            sum += p * p;
        }
    }
    return sum;
}

static realtype wrms_norm(N_Vector x, N_Vector w)
{
    return sqrt(wsqr_sum(x, w) / (realtype)LEN(x));
}

static realtype wrms_norm_mask(N_Vector x, N_Vector w, N_Vector id)
{
    return sqrt(wsqr_sum_mask(x, w, id) / (realtype)LEN(x));
}

static realtype vmin(N_Vector x)
{
    sunindextype i, n = LEN(x);
    realtype *xd = DAT(x), min = xd[0];
    for (i = 1; i < n; i++)
        if (xd[i] < min) min = xd[i];
    return min;
}

static realtype wl2_norm(N_Vector x, N_Vector w)
{
    return sqrt(wsqr_sum(x, w));
}

static realtype l1_norm(N_Vector x)
{
    sunindextype i, n = LEN(x);
    realtype *xd = DAT(x), sum = 0.0;
    for (i = 0; i < n; i++) sum += fabs(xd[i]);
    return sum;
}

static void compare(realtype c, N_Vector x, N_Vector z)
{
    sunindextype i, n = LEN(x);
    realtype *xd = DAT(x), *zd = DAT(z);
    for (i = 0; i < n; i++) zd[i] = (fabs(xd[i]) >= c) ? 1.0 : 0.0;
}

static booleantype inv_test(N_Vector x, N_Vector z)
{
    sunindextype i, n = LEN(x);
    realtype *xd = DAT(x), *zd = DAT(z), no_zero = 1.0;
    for (i = 0; i < n; i++) {
        if (xd[i] == 0.0) {
            no_zero = 0.0;
        } else {
            zd[i] = 1.0 / xd[i];
        }
    }
    return no_zero == 0.0 ? SUNFALSE : SUNTRUE;
}

static booleantype constr_mask(N_Vector c, N_Vector x, N_Vector m)
{
    sunindextype i, n = LEN(x);
    realtype *cd = DAT(c), *xd = DAT(x), *md = DAT(m), temp = 0.0;
    booleantype test;
    for (i = 0; i < n; i++) {
        md[i] = 0.0;
        if (cd[i] == 0.0) continue;
        test = (fabs(cd[i]) > 1.5 && xd[i] * cd[i] <= 0.0) ||
               (fabs(cd[i]) > 0.5 && xd[i] * cd[i] < 0.0);
        if (test) {
            temp = 1.0;
            md[i] = 1.0;
        }
    }
    return temp == 1.0 ? SUNFALSE : SUNTRUE;
}

static realtype min_quotient(N_Vector num, N_Vector denom)
{
    sunindextype i, n = LEN(num);
    realtype *nd = DAT(num), *dd = DAT(denom), min = BIG_REAL;
    booleantype not_evaluated = SUNTRUE;
    for (i = 0; i < n; i++) {
        if (dd[i] == 0.0) continue;
        if (!not_evaluated) {
            if (nd[i] / dd[i] < min) min = nd[i] / dd[i];
        } else {
            min = nd[i] / dd[i];
            not_evaluated = SUNFALSE;
        }
    }
    return min;
}

/* ---- fused operations: what the fallback loops do, in one pass when z is not one of the
 * inputs read after it is written ---------------------------------------------------- */

/* z = c[0] X[0] + c[1] X[1] + ... (fallback: N_VScale(c0, X0, z), then z += c[i] X[i]) */
static int linear_combination(int nvec, realtype *c, N_Vector *X, N_Vector z)
{
    sunindextype j, n = LEN(z);
    realtype *zd = DAT(z), s;
    int i;
    for (i = 1; i < nvec; i++)
        if (X[i] == z) break;
    if (i < nvec || nvec > 8) {
        /* an input that the fallback overwrites first, or many vectors: pass by pass */
        scale(c[0], X[0], z);
        for (i = 1; i < nvec; i++) axpy(n, c[i], DAT(X[i]), zd);
        return 0;
    }
    {
        const realtype *x[8];
        for (i = 0; i < nvec; i++) x[i] = DAT(X[i]);
        for (j = 0; j < n; j++) {
            s = c[0] * x[0][j];
            for (i = 1; i < nvec; i++) s += c[i] * x[i][j];
            zd[j] = s;
        }
    }
    return 0;
}

/* Z[i] = a[i] x + Y[i] (fallback: N_VLinearSum(a[i], x, 1, Y[i], Z[i]), all of them the
 * same value a[i] x + y) */
static int scale_add_multi(int nvec, realtype *a, N_Vector x, N_Vector *Y, N_Vector *Z)
{
    sunindextype j, n = LEN(x);
    realtype *xd = DAT(x);
    int i;
    for (i = 0; i < nvec; i++) {
        if (Z[i] == x) {
            /* x overwritten: keep the fallback's order */
            for (i = 0; i < nvec; i++) linear_sum(a[i], x, 1.0, Y[i], Z[i]);
            return 0;
        }
    }
    for (i = 0; i < nvec; i++) {
        realtype *yd = DAT(Y[i]), *zd = DAT(Z[i]), ai = a[i];
        if (Y[i] == Z[i]) {
            axpy(n, ai, xd, zd);
        } else {
            for (j = 0; j < n; j++) zd[j] = ai * xd[j] + yd[j];
        }
    }
    return 0;
}

static int dot_prod_multi(int nvec, N_Vector x, N_Vector *Y, realtype *d)
{
    int i;
    for (i = 0; i < nvec; i++) d[i] = dot(x, Y[i]);
    return 0;
}

static int linear_sum_array(int nvec, realtype a, N_Vector *X, realtype b, N_Vector *Y,
                            N_Vector *Z)
{
    int i;
    for (i = 0; i < nvec; i++) linear_sum(a, X[i], b, Y[i], Z[i]);
    return 0;
}

static int scale_array(int nvec, realtype *c, N_Vector *X, N_Vector *Z)
{
    int i;
    for (i = 0; i < nvec; i++) scale(c[i], X[i], Z[i]);
    return 0;
}

static int const_array(int nvec, realtype c, N_Vector *Z)
{
    int i;
    for (i = 0; i < nvec; i++) vconst(c, Z[i]);
    return 0;
}

static int wrms_norm_array(int nvec, N_Vector *X, N_Vector *W, realtype *nrm)
{
    int i;
    for (i = 0; i < nvec; i++) nrm[i] = wrms_norm(X[i], W[i]);
    return 0;
}

static int wrms_norm_mask_array(int nvec, N_Vector *X, N_Vector *W, N_Vector id,
                                realtype *nrm)
{
    int i;
    for (i = 0; i < nvec; i++) nrm[i] = wrms_norm_mask(X[i], W[i], id);
    return 0;
}

/* Replace the operations of serial vector v (its table; clones copy it). 0 on success. */
int ropedyn_nvector_fast_ops(N_Vector v)
{
    N_Vector_Ops ops;
    if (v == NULL || v->ops == NULL || N_VGetVectorID(v) != SUNDIALS_NVEC_SERIAL) return -1;
    ops = v->ops;
    ops->nvlinearsum = linear_sum;
    ops->nvconst = vconst;
    ops->nvprod = prod;
    ops->nvdiv = vdiv;
    ops->nvscale = scale;
    ops->nvabs = vabs;
    ops->nvinv = inv;
    ops->nvaddconst = add_const;
    ops->nvdotprod = dot;
    ops->nvmaxnorm = max_norm;
    ops->nvwrmsnorm = wrms_norm;
    ops->nvwrmsnormmask = wrms_norm_mask;
    ops->nvmin = vmin;
    ops->nvwl2norm = wl2_norm;
    ops->nvl1norm = l1_norm;
    ops->nvcompare = compare;
    ops->nvinvtest = inv_test;
    ops->nvconstrmask = constr_mask;
    ops->nvminquotient = min_quotient;
    ops->nvlinearcombination = linear_combination;
    ops->nvscaleaddmulti = scale_add_multi;
    ops->nvdotprodmulti = dot_prod_multi;
    ops->nvlinearsumvectorarray = linear_sum_array;
    ops->nvscalevectorarray = scale_array;
    ops->nvconstvectorarray = const_array;
    ops->nvwrmsnormvectorarray = wrms_norm_array;
    ops->nvwrmsnormmaskvectorarray = wrms_norm_mask_array;
    ops->nvdotprodlocal = dot;
    ops->nvmaxnormlocal = max_norm;
    ops->nvminlocal = vmin;
    ops->nvl1normlocal = l1_norm;
    ops->nvinvtestlocal = inv_test;
    ops->nvconstrmasklocal = constr_mask;
    ops->nvminquotientlocal = min_quotient;
    ops->nvwsqrsumlocal = wsqr_sum;
    ops->nvwsqrsummasklocal = wsqr_sum_mask;
    ops->nvdotprodmultilocal = dot_prod_multi;
    return 0;
}
