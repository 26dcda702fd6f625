"""The 4th-order compositions that `method = 'symplectic'` could use, side by side.

The code of scripts/compositions; writes the section between the compositions markers of
docs/theory/symplectic.md. No runs of ropedyn: each composition is judged from its
coefficients alone (the measured runs of the same compositions on the rope are in the
prose of that page).

A composition B A B ... A B of kicks v += b_i h a(q) and drifts q += a_i h v is an explicit
Runge-Kutta-Nystrom method (stage times c_i = a_1 + ... + a_{i-1}, stage matrix
abar_ij = b_j (c_i - c_j), j < i). For each composition:

- **order**: the residuals of the Runge-Kutta-Nystrom order conditions up to order 4 (the
  trees with up to 4 nodes, velocity form: sum b = 1, sum b c = 1/2, sum b c^2 = 1/3,
  sum b abar 1 = 1/6, sum b c^3 = 1/4, sum b c abar 1 = 1/8, sum b abar c = 1/24), all below
  1e-13;
- **error constant**: the norm of the residuals of the six order-5 conditions (the leading
  local error of a 4th-order method on a nonlinear problem);
- **stability**: the one-step matrix on the oscillator q'' = -w^2 q is a polynomial matrix
  in x = h w with determinant 1; the method is stable where |trace| <= 2, and its
  eigenvalues' largest modulus is (|trace| + sqrt(trace^2 - 4))/2 where it is not. The first
  x where that modulus exceeds 1 + 1e-10 (scanned in steps of 1e-5 up to 8, so that narrow
  gaps are found; a threshold on the trace itself would see a trace that leaves -2
  tangentially, as Chin's does at 2 sqrt 3, only some 1e-3 later) is the limit X; the
  unstable intervals below 8 are listed;
- **the resonance-safe step**: S X, S = RESONANT_SAFETY of ropedyn_symplectic (what it takes
  where the fast modes are lightly damped: their combinations reach twice the fastest
  frequency, which must stay inside the stable interval with a margin), and at it the
  evaluations of the forces per unit of rho t (s / (S X): the cost per simulated second for
  a spectral radius rho) and the energy error of the fastest mode: the relative spread of
  E = (v^2 + w^2 q^2)/2 along the numerical orbit (the ratio of the axes of the invariant
  quadratic form, minus 1).
"""
import argparse
import re

import numpy as np

from ropedyn_tools.repo import DOCS, ROOT
from ropedyn_tools.studies.common import run_stamp, update_doc
from ropedyn.docstrings import summary

DOC = DOCS / "theory" / "symplectic.md"
TABLES = ROOT / "solvers" / "symplectic" / "ropedyn_split_tables.f90"
SYMPLECTIC = ROOT / "solvers" / "symplectic" / "ropedyn_symplectic.f90"
BEGIN = "<!-- compositions:begin -->"
END = "<!-- compositions:end -->"
XMAX, DX = 8.0, 1e-5
#: the row of the method's own SRKN6b
METHOD_BM6 = "Blanes-Moan SRKN6b (the method's)"


def symmetric(a_free, b_free, s):
    """Full drift and kick coefficients of a symmetric composition with s drifts (s + 1
    kicks) from the free coefficients of each first half; the coefficient next to the middle
    closes the sum to 1."""
    def full(free, count):
        free = list(free)
        if count % 2 == 0:
            half = free + [0.5 - sum(free)]
            return half + half[::-1]
        return free + [1.0 - 2.0 * sum(free)] + free[::-1]
    return np.array(full(a_free, s)), np.array(full(b_free, s + 1))


def fortran_parameter(path, name):
    """The value of the real parameter `name` (`name = 1.5_wp`) in the Fortran source
    `path`: this study reads the method's own numbers rather than repeating them."""
    m = re.search(rf"\b{name} = (-?[0-9.]+(?:e-?[0-9]+)?)_wp", path.read_text())
    if m is None:
        raise ValueError(f"{path}: no parameter {name}")
    return float(m.group(1))


def method_coefficients():
    """SRKN6b's free coefficients ([a1, a2], [b1, b2, b3]) as ropedyn_split_tables defines
    them."""
    def value(name):
        return fortran_parameter(TABLES, name)
    return [value("a1"), value("a2")], [value("b1"), value("b2"), value("b3")]


def compositions():
    """(name, where it comes from, a, b) of every composition compared."""
    bm = symmetric(*method_coefficients(), 6)
    x = 1.0 / (2.0 - 2.0 ** (1.0 / 3.0))
    fr = (np.array([x, 1.0 - 2.0 * x, x]), np.array([x / 2, (1 - x) / 2, (1 - x) / 2, x / 2]))
    # 4 drifts: a = (a1, 1/2 - a1, 1/2 - a1, a1), b = (b1, b2, 1 - 2 (b1 + b2), b2, b1), the
    # order conditions solved for a1 and b2 at b1 (a one-parameter family)
    s4_long = symmetric([0.5395919323309928], [0.16, 1.063249904964015], 4)
    s4_best = symmetric([-0.10414790604803639], [0.375, -0.1426961389312234], 4)
    c6 = symmetric([0.21380873723353594, -0.004463746431005043],
                   [0.07050341830480561, 1.017800970312149, -0.7022063006811358], 6)
    return [
        ("Stormer-Verlet", "order 2", np.array([1.0]), np.array([0.5, 0.5])),
        ("Forest-Ruth / Yoshida", "the triple jump", *fr),
        (METHOD_BM6, "Blanes & Moan 2002, table 3", *bm),
        ("4 stages, longest interval", "b1 = 0.16 of the family", *s4_long),
        ("4 stages, smallest error", "b1 = 0.375 of the family", *s4_best),
        ("6 stages, long interval", "searched: the interval to 6.5", *c6),
    ]


def rkn(a, b):
    c = np.concatenate([[0.0], np.cumsum(a)])
    n = len(b)
    abar = np.array([[b[j] * (c[i] - c[j]) if j < i else 0.0 for j in range(n)]
                     for i in range(n)])
    return c, abar


def order4_residuals(a, b):
    c, abar = rkn(a, b)
    a1 = abar.sum(1)
    return np.array([b.sum() - 1, b @ c - 1 / 2, b @ c ** 2 - 1 / 3, b @ a1 - 1 / 6,
                     b @ c ** 3 - 1 / 4, b @ (c * a1) - 1 / 8, b @ (abar @ c) - 1 / 24])


def order5_residuals(a, b):
    c, abar = rkn(a, b)
    a1 = abar.sum(1)
    return np.array([b @ c ** 4 - 1 / 5, b @ (c ** 2 * a1) - 1 / 10,
                     b @ (c * (abar @ c)) - 1 / 30, b @ (a1 * a1) - 1 / 20,
                     b @ (abar @ c ** 2) - 1 / 60, b @ (abar @ a1) - 1 / 120])


def one_step(a, b, x, grad=None):
    """The one-step matrix on q'' = -q at h = x, its entries as arrays over x; grad: per kick
    the coefficient g of a force-gradient kick, whose acceleration a + g h^2 (da/dq) a is
    (1 - g h^2 w^2) a(q) here (None: 0; ropedyn_split_tables' grad)."""
    grad = np.zeros(len(b)) if grad is None else np.asarray(grad)
    m11, m12 = np.ones_like(x), np.zeros_like(x)
    m21, m22 = np.zeros_like(x), np.ones_like(x)
    for i in range(len(a) + 1):
        k = b[i] * x * (1.0 - grad[i] * x * x)
        m21, m22 = m21 - k * m11, m22 - k * m12
        if i < len(a):
            m11, m12 = m11 + a[i] * x * m21, m12 + a[i] * x * m22
    return m11, m12, m21, m22


def unstable_intervals(a, b, grad=None):
    x = np.arange(DX, XMAX, DX)
    m11, _, _, m22 = one_step(a, b, x, grad)
    trace = np.abs(m11 + m22)
    radius = 0.5 * (trace + np.sqrt(np.maximum(trace * trace - 4.0, 0.0)))
    bad = radius > 1.0 + 1e-10
    idx = np.nonzero(bad)[0]
    if not len(idx):
        return []
    runs = np.split(idx, np.nonzero(np.diff(idx) > 1)[0] + 1)
    return [(x[r[0]], x[r[-1]] + DX if r[-1] < len(x) - 1 else None) for r in runs]


def table_arrays(case):
    """(a, b, grad) of the composition `case` (e.g. "TABLE_CHIN") as ropedyn_split_tables
    sets them: its `tab%a = [...]` lines, each entry a number or a quotient of two."""
    text = TABLES.read_text()
    m = re.search(rf"case \({case}\)(.*?)(?:case |end select)", text, re.S)
    if m is None:
        raise ValueError(f"{TABLES}: no case {case}")

    def entry(e):
        parts = [float(x.strip().removesuffix("_wp")) for x in e.split("/")]
        if not 1 <= len(parts) <= 2:
            raise ValueError(f"{TABLES}: cannot read {e!r}")
        return parts[0] / parts[1] if len(parts) == 2 else parts[0]

    def array(name):
        a = re.search(rf"tab%{name} = \[([^\]]*)\]", m.group(1))
        if a is None:
            raise ValueError(f"{TABLES}: {case} sets no tab%{name}")
        return np.array([entry(e) for e in a.group(1).split(",")])
    return array("a"), array("b"), array("grad")


CHIN = table_arrays("TABLE_CHIN")


#: the step over the stable step with lightly damped fast modes (ropedyn_symplectic's)
SAFETY = fortran_parameter(SYMPLECTIC, "RESONANT_SAFETY")


def method_step(a, b, grad, x, zeta):
    """The method's step as ropedyn_symplectic runs it, on x'' = -x - 2 zeta x' at h = x (an
    array): the linear map of (q, v, a_r) over one step (the D-map's halves with a_r at the
    predicted velocity; a gradient kick's acceleration a (1 - g h^2) for a = -q), as an array
    of 3 x 3 matrices."""
    x = np.asarray(x, dtype=float)
    out = np.empty(x.shape + (3, 3))
    for j in range(3):
        q, v, ar = (np.full(x.shape, float(j == k)) for k in range(3))
        v = v + 0.5 * x * ar
        for i in range(len(a)):
            ac = -q * (1.0 - grad[i] * x * x)
            v = v + b[i] * x * ac
            q = q + a[i] * x * v
        vt = v + b[-1] * x * ac + 0.5 * x * ar
        ar = -2.0 * zeta * vt
        v = v + b[-1] * x * (-q) + 0.5 * x * ar
        out[..., 0, j], out[..., 1, j], out[..., 2, j] = q, v, ar
    return out


def damped_limits(a, b, grad=None, dx=5e-4, xmax=8.0):
    """The method's stable h w at each damping of ropedyn_split_tables' STABLE_ZETA: the
    last step of a scan in steps of dx before the one-step map (method_step) has an
    eigenvalue above 1 + 1e-10 (how its LIMIT_* were made)."""
    grad = np.zeros(len(b)) if grad is None else np.asarray(grad)
    x = np.arange(1, int(round(xmax / dx)) + 1) * dx
    limits = []
    for zeta in fortran_array("STABLE_ZETA"):
        radius = np.abs(np.linalg.eigvals(method_step(a, b, grad, x, zeta))).max(axis=-1)
        first = int(np.argmax(radius > 1.0 + 1e-10))
        limits.append(round(float(x[first - 1]), 4))
    return limits


def fortran_array(name):
    """The real parameter array `name`(NZ) of ropedyn_split_tables, as a list."""
    m = re.search(rf"\b{name}\(NZ\) = \[([^\]]+)\]", TABLES.read_text())
    if m is None:
        raise ValueError(f"{TABLES}: no table {name}")
    return [float(v.strip().replace("_wp", "")) for v in m.group(1).replace("&", "").split(",")]


def fortran_limits(name):
    """The table LIMIT_<name> of ropedyn_split_tables."""
    return fortran_array(f"LIMIT_{name}")


def gaps_text(gaps):
    """The first three unstable intervals (unstable_intervals) as table text."""
    return "; ".join(f"{lo:.4f} .. {hi:.4f}" if hi else f"from {lo:.4f}" for lo, hi in gaps[:3])


def energy_spread(a, b, x, grad=None):
    """Relative spread of (v^2 + q^2)/2 along the orbit at h = x (0 for the exact flow)."""
    m11, m12, m21, m22 = (float(v[0]) for v in one_step(a, b, np.array([x]), grad))
    d = (m11 - m22) / 2
    w = np.linalg.eigvalsh(np.array([[-m21, d], [d, m12]]))
    return w.max() / w.min() - 1.0 if w.min() > 0 else float("inf")


def rows():
    out, limits = [], {}
    for name, source, a, b in compositions():
        s = len(a)
        res4 = float(np.abs(order4_residuals(a, b)).max())
        order = 4 if res4 < 1e-13 else 2
        if order == 2:
            assert abs(order4_residuals(a, b)[1]) < 1e-15
        e5 = float(np.linalg.norm(order5_residuals(a, b))) if order == 4 else float("nan")
        gaps = unstable_intervals(a, b)
        limit = gaps[0][0] if gaps else XMAX
        limits[name] = limit
        step = SAFETY * limit
        out.append(f"| {name} | {source} | {order} | {s} | {limit:.4f} | {gaps_text(gaps)} | "
                   f"{step:.3f} | {s / step:.2f} | {energy_spread(a, b, step):.1e} | "
                   + (f"{e5:.1e}" if order == 4 else "") + " |")
    out.append(force_gradient_row(SAFETY * limits[METHOD_BM6]))
    return out


def force_gradient_row(bm_step):
    """Chin's 4A, v += h/6 a, q += h/2 v, v += 2h/3 (a + h^2/24 (da/dq) a), q += h/2 v,
    v += h/6 a: the middle kick's force at a gradient-shifted point costs a second
    evaluation (a difference), so 3 per step; its order is checked on the oscillator (its
    order conditions are not those of a composition). Its energy spread is given also at
    `bm_step` (h rho), SRKN6b's resonance-safe step, for a comparison at equal steps."""
    a, b, grad = CHIN
    # order 4 on the oscillator: the phase error falls 32 times when h halves
    phase = [np.arccos(np.clip((lambda m: (m[0] + m[3]) / 2)(
        [float(v[0]) for v in one_step(a, b, np.array([x]), grad)]), -1, 1)) - x
        for x in (0.1, 0.05)]
    assert 30.0 < phase[0] / phase[1] < 34.0
    gaps = unstable_intervals(a, b, grad)
    limit = gaps[0][0]
    step = SAFETY * limit
    return (f"| Chin's 4A, force gradient (the method's) | S. A. Chin, Phys. Lett. A 226 "
            f"(1997) | 4 | 3 | {limit:.4f} | "
            f"{gaps_text(gaps)} | {step:.3f} | {3 / step:.2f} | "
            f"{energy_spread(a, b, step, grad):.1e} (at h rho = {bm_step:.3f}: "
            f"{energy_spread(a, b, bm_step, grad):.1e}) |  |")


def main(argv=None):
    parser = argparse.ArgumentParser(description=summary(__doc__))
    parser.add_argument("--no-write", action="store_true")
    args = parser.parse_args(argv)
    table = rows()
    for line in table:
        print(line)
    if args.no_write:
        return 0
    block = "\n".join([
        BEGIN,
        "Command: `scripts/compositions` (code: tools/ropedyn_tools/studies/compositions.py; "
        f"from the coefficients alone, no runs). Run: {run_stamp()}.", "",
        "| composition | source | order | force evaluations per step | first unstable h w | "
        f"unstable h w below 8 | step at {SAFETY:g} of it (h rho) | evaluations per unit of rho t "
        "| energy spread of the fastest mode there | order-5 residual norm |",
        "|---|---|---|---|---|---|---|---|---|---|", *table, END])
    update_doc(DOC, BEGIN, END, block)
    print(f"compositions: {DOC}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
