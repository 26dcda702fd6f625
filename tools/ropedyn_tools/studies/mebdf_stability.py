"""Linear stability of the MEBDF formulas (and of BDF for comparison), from first principles.

For y' = lambda y and z = h lambda, one MEBDF step maps the last k values to the next k
values linearly (stage 1: BDF; stage 2: BDF one step further; stage 3: the modified
extended corrector). The method is stable at z when the spectral radius of that map is
<= 1. Prints, for k = 1..6 (order k+1, up to MEBDF's limit of 7): the A(alpha) angle
and the largest amplification per step on the imaginary axis (undamped oscillation), with
the range of h*omega where it exceeds 1. The coefficients are solved from the order conditions in exact rational
arithmetic, as solvers/ropedyn_mebdf_coefficients.f90 does in extended precision.

Writes the table into docs/theory/mebdf.md and its BDF columns (orders 2 .. 5, CVODE's)
into docs/theory/cvode.md, each between its mebdf_stability markers.

    scripts/mebdf_stability.py [--kmax 6] [--no-write]
"""
import argparse
import pathlib
from fractions import Fraction

import numpy as np

from ropedyn_tools.repo import ROOT
from ropedyn_tools.studies.common import run_stamp, update_doc
from ropedyn.docstrings import summary

#: the pages and their markers
MEBDF_PAGE = ROOT / "docs" / "theory" / "mebdf.md"
CVODE_PAGE = ROOT / "docs" / "theory" / "cvode.md"
BEGIN, END = "<!-- mebdf_stability:begin -->", "<!-- mebdf_stability:end -->"
BDF_BEGIN, BDF_END = "<!-- mebdf_stability bdf:begin -->", "<!-- mebdf_stability bdf:end -->"
#: CVODE's BDF orders
CVODE_ORDERS = range(2, 6)


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
    """Largest alpha such that the sector |arg(-z)| <= alpha is stable (bisection). Each
    ray is sampled at 400 radii and again, 400 times finer, between the neighbours of its
    least stable sample: the coarse grid alone misses the ray's worst radius and puts the
    angle up to 0.01 degrees too wide (BDF4 73.36 against 73.35)."""
    radii = np.logspace(-3, 5, 400)

    def stable(angle):
        ray = np.exp(1j * np.deg2rad(180.0 - angle))
        growth = [radius(matrix_of, coef, r * ray) for r in radii]
        if max(growth) > 1 + 1e-10:
            return False
        k = int(np.argmax(growth))
        fine = np.geomspace(radii[max(k - 1, 0)], radii[min(k + 1, len(radii) - 1)], 400)
        return all(radius(matrix_of, coef, r * ray) <= 1 + 1e-10 for r in fine)

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


def rows(kmax):
    """The table's rows by order p = k + 1: (MEBDF A(alpha), its amplification text, BDF_p's
    A(alpha) or None above order 6, its amplification text)."""
    table = {}
    for k in range(1, kmax + 1):
        coef = coefficients(k)
        rm, wm = imaginary_axis(step_matrix, coef)
        row = [a_alpha(step_matrix, coef), amplification(rm, wm), None, None]
        if k + 1 <= 6:
            cb = coefficients(k + 1)
            row[2] = a_alpha(bdf_matrix, cb)
            row[3] = amplification(*imaginary_axis(bdf_matrix, cb))
        table[k + 1] = row
    return table


def amplification(largest, below):
    """'1.191 (h ω < 4.71)': the largest amplification on the imaginary axis and where."""
    return f"{largest:.3f}" + (f" (h ω < {below:.2f})" if below else "")


def head(kmax):
    """The sections' first line: the command and the stamp."""
    return (f"Command: `scripts/mebdf_stability.py --kmax {kmax}` (code: "
            f"tools/ropedyn_tools/studies/mebdf_stability.py; exact rational coefficients, "
            f"no run of the program). Run: {run_stamp()}.")


def main(argv=None):
    parser = argparse.ArgumentParser(description=summary(__doc__))
    parser.add_argument('--kmax', type=int, default=6,
                        help='the largest k (order k + 1; default 6: order 7, MEBDF\'s limit)')
    parser.add_argument('--no-write', action='store_true',
                        help='print the table only; the pages are left alone')
    args = parser.parse_args(argv)
    table = rows(args.kmax)
    full = ["| order p | MEBDF A(α) | MEBDF max amplification on iℝ (h ω range) | BDF_p A(α) "
            "| BDF_p max amplification on iℝ |", "|---|---|---|---|---|"]
    for p, (am, ar, ab, br) in table.items():
        bdf = f"{ab:.2f} | {br}" if ab is not None else "– | –"
        full.append(f"| {p} | {am:.2f} | {ar} | {bdf} |")
    bdf_rows = ["| BDF order | A(α) | largest amplification per step on the imaginary axis |",
                "|---|---|---|"]
    for p in CVODE_ORDERS:
        if p in table:
            bdf_rows.append(f"| {p} | {table[p][2]:.2f}° | {table[p][3]} |")
    print("\n".join(full))
    if args.no_write:
        return 0
    update_doc(MEBDF_PAGE, BEGIN, END, "\n".join([BEGIN, head(args.kmax), "", *full, END]))
    update_doc(CVODE_PAGE, BDF_BEGIN, BDF_END,
               "\n".join([BDF_BEGIN, head(args.kmax), "", *bdf_rows, BDF_END]))
    print(f"mebdf_stability: {MEBDF_PAGE}, {CVODE_PAGE}")
    return 0


if __name__ == '__main__':
    main()
