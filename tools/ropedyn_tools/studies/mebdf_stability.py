"""Linear stability of the MEBDF formulas (and of BDF for comparison), from first principles.

For y' = lambda y and z = h lambda, one MEBDF step maps the last k values to the next k
values linearly (stage 1: BDF; stage 2: BDF one step further; stage 3: the modified
extended corrector). The method is stable at z when the spectral radius of that map is
<= 1. Prints, for k = 1..7 (order k+1): the A(alpha) angle and the largest amplification
per step on the imaginary axis (undamped oscillation), with the range of h*omega where it
exceeds 1. The coefficients are solved from the order conditions in exact rational
arithmetic, as solvers/ropedyn_mebdf_coefficients.f90 does in extended precision.

    .venv/bin/python scripts/mebdf_stability.py [--kmax 7]
    (python -m ropedyn_tools.studies.mebdf_stability)
"""
import argparse
from fractions import Fraction

import numpy as np


def solve_exact(a, b):
    """Gaussian elimination on Fractions."""
    n = len(b)
    a = [row[:] for row in a]
    b = b[:]
    for i in range(n):
        p = next(r for r in range(i, n) if a[r][i] != 0)
        a[i], a[p] = a[p], a[i]
        b[i], b[p] = b[p], b[i]
        for r in range(i + 1, n):
            f = a[r][i] / a[i][i]
            a[r] = [x - f * y for x, y in zip(a[r], a[i])]
            b[r] -= f * b[i]
    x = [Fraction(0)] * n
    for i in reversed(range(n)):
        x[i] = (b[i] - sum(a[i][j] * x[j] for j in range(i + 1, n))) / a[i][i]
    return x


def d(q, j):
    """d/dt of t^q at t = j (0 for q = 0)."""
    return Fraction(q * j ** (q - 1)) if q > 0 else Fraction(0)


def coefficients(k):
    """BDF alpha_0..k, beta and MEBDF ahat_0..k, bhat_k, bhat_{k+1} (exact)."""
    a = [[Fraction(j ** q) for j in range(k)] + [-d(q, k)] for q in range(k + 1)]
    x = solve_exact(a, [Fraction(-(k ** q)) for q in range(k + 1)])
    alpha, beta = x[:k] + [Fraction(1)], x[k]
    a = [[Fraction(j ** q) for j in range(k)] + [-d(q, k), -d(q, k + 1)] for q in range(k + 2)]
    x = solve_exact(a, [Fraction(-(k ** q)) for q in range(k + 2)])
    return alpha, beta, x[:k] + [Fraction(1)], x[k], x[k + 1]


def step_matrix(coef, z):
    alpha, beta, ahat, bk, bk1 = [np.array([float(c) for c in v]) if isinstance(v, list)
                                  else float(v) for v in coef]
    k = len(alpha) - 1
    m = np.zeros((k, k), complex)
    for col in range(k):
        y = np.zeros(k, complex)
        y[col] = 1.0
        yb1 = -(alpha[:k] @ y) / (1 - beta * z)
        hist = np.append(y[1:], yb1)
        yb2 = -(alpha[:k] @ hist) / (1 - beta * z)
        ynew = (-(ahat[:k] @ y) + z * ((bk - beta) * yb1 + bk1 * yb2)) / (1 - beta * z)
        m[:, col] = np.append(y[1:], ynew)
    return m


def bdf_matrix(coef, z):
    alpha, beta = np.array([float(c) for c in coef[0]]), float(coef[1])
    k = len(alpha) - 1
    m = np.zeros((k, k), complex)
    m[:-1, 1:] = np.eye(k - 1)
    m[-1, :] = -alpha[:k] / (1 - beta * z)
    return m


def radius(matrix_of, coef, z):
    return max(abs(np.linalg.eigvals(matrix_of(coef, z))))


def a_alpha(matrix_of, coef):
    """Largest alpha such that the sector |arg(-z)| <= alpha is stable (bisection)."""
    radii = np.logspace(-3, 5, 400)

    def stable(angle):
        th = np.deg2rad(180.0 - angle)
        return all(radius(matrix_of, coef, r * np.exp(1j * th)) <= 1 + 1e-10 for r in radii)

    if stable(90.0):
        return 90.0
    lo, hi = 0.0, 90.0
    for _ in range(30):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if stable(mid) else (lo, mid)
    return lo


def imaginary_axis(matrix_of, coef):
    w = np.linspace(1e-3, 20.0, 4000)
    r = np.array([radius(matrix_of, coef, 1j * x) for x in w])
    unstable = w[r > 1 + 1e-10]
    return r.max(), (unstable.max() if unstable.size else 0.0)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--kmax', type=int, default=7)
    args = parser.parse_args(argv)
    print('| order p | MEBDF A(alpha) | MEBDF max amplification on iR (h omega range) '
          '| BDF_p A(alpha) | BDF_p max amplification on iR |')
    print('|---|---|---|---|---|')
    for k in range(1, args.kmax + 1):
        coef = coefficients(k)
        am = a_alpha(step_matrix, coef)
        rm, wm = imaginary_axis(step_matrix, coef)
        text_bdf = '–'
        if k + 1 <= 6:
            cb = coefficients(k + 1)
            ab = a_alpha(bdf_matrix, cb)
            rb, wb = imaginary_axis(bdf_matrix, cb)
            text_bdf = f'{ab:.2f} | {rb:.3f}' + (f' (h omega < {wb:.2f})' if wb else '')
        else:
            text_bdf = '– | –'
        rng = f' (h omega < {wm:.2f})' if wm else ''
        print(f'| {k + 1} | {am:.2f} | {rm:.3f}{rng} | {text_bdf} |')


if __name__ == '__main__':
    main()
