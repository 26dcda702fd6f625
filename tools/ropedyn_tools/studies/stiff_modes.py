"""Which modes of the paper's rope hold an explicit method's step, and what treating one kind
of them implicitly would gain.

The code of scripts/stiff_modes; writes the section between the stiff_modes markers of
docs/performance/peers.md.

An explicit method's step is held by the spectral radius rho (RK4: h rho <= 2.83; the
symplectic compositions: docs/theory/symplectic.md). An IMEX method treats some forces
implicitly and the rest explicitly; its step is then held by the fastest mode of the
explicit rest. Whether that pays depends on which modes are the fast ones. For the paper's
rope at each n (input/paper.nml, `--elements`), `ropedyn modes` gives every mode (3 n of
them) about the hanging equilibrium; each is put into the kind whose share of its motion
is the largest, from the motion of the elements' end points (/modes/shape_points):

- **along the rope**: /modes/axial_fraction, the share of the end points' motion along the
  rope (the springs' stretching);
- **turning of the elements**: the share of the end points' motion that is each rigid
  element turning about its centre: sum |d|^2 / sum (|c|^2 + |d|^2), c and d half the sum
  and half the difference of an element's two end-point motions (|c|^2 + |d|^2 is the
  mean of their squares; a rigid element does not stretch, so d is its turning);
- **across the rope**: the rest (the elements moving sideways: bending and the pendulum).

The table gives each kind's largest angular frequency, rho (the largest of all, with its
kind and damping ratio), the step an IMEX method would gain with one kind implicit (rho
over the largest frequency of the other two kinds: the factor by which its explicit part's
stability limit rises), and, as a check of the classification's premise, the spectral
radius that a run estimates at its start (the symplectic method's first switch-log entry,
/solver/switch_reason: ropedyn_spectrum's Ritz values at the released straight rope,
another state and another algorithm). No CPU is measured.
"""
import argparse
import pathlib
import re
import subprocess
import sys
import tempfile

import h5py
import numpy as np

from ropedyn_tools.arguments import list_text, positive
from ropedyn_tools.repo import DOCS, PAPER, add_exe_argument, exe_or_build, set_args
from ropedyn_tools.studies.common import machine, run_stamp, update_doc
from ropedyn.docstrings import summary

DOC = DOCS / "performance" / "peers.md"
BEGIN, END = "<!-- stiff_modes:begin -->", "<!-- stiff_modes:end -->"
KINDS = ("along the rope", "turning of the elements", "across the rope")
HEADER = ("| n | modes | largest omega along the rope (1/s) | turning of the elements | "
          "across the rope | rho (1/s) | its kind | its damping ratio | "
          "rho estimated by the run at its start | step gain, along implicit | "
          "turning implicit | across implicit |")
#: the n of the table (the --elements default)
ELEMENTS = "10 30 100"
_RADIUS = re.compile(r"spectral radius\s+([0-9.Ee+-]+)\s*1/s")


def turning_share(points):
    """The share of the end points' motion that is the elements turning about their
    centres, for the end-point motions `points` (2 n, 2) of one mode (end points a, b of
    element i at rows 2 i, 2 i + 1)."""
    a, b = points[0::2], points[1::2]
    c, d = 0.5 * (a + b), 0.5 * (b - a)
    total = float(np.sum(c ** 2) + np.sum(d ** 2))
    return float(np.sum(d ** 2)) / total if total > 0.0 else 0.0


def kinds(axial, turning):
    """The kind (index into KINDS) of each mode: the largest of its shares along the rope
    (`axial`), turning (`turning`) and across the rope (the rest)."""
    axial, turning = np.asarray(axial), np.asarray(turning)
    shares = np.column_stack([axial, turning, np.clip(1.0 - axial - turning, 0.0, None)])
    return np.argmax(shares, axis=1)


def step_gains(omega, kind):
    """{kind index: rho over the largest omega of the other kinds}: how much longer the
    stable step of an explicit part is when the modes of that kind are implicit."""
    rho = float(np.max(omega))
    gains = {}
    for k in range(len(KINDS)):
        rest = omega[kind != k]
        gains[k] = rho / float(np.max(rest)) if rest.size else float("inf")
    return gains


def modes_of(exe, work, n):
    """omega, damping ratio, kind of every mode of the paper's rope with n elements."""
    out = work / f"modes_{n}.h5"
    cmd = [str(exe), "modes", str(PAPER), "--count", str(3 * n), "-o", str(out),
           *set_args([f"model.elements={n}"])]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=3600)
    if proc.returncode != 0:
        raise SystemExit(f"stiff_modes: ropedyn modes failed at n = {n}: "
                         f"{proc.stderr.strip()}")
    with h5py.File(out, "r") as f:
        omega = f["/modes/omega"][()]
        zeta = f["/modes/damping_ratio"][()]
        axial = f["/modes/axial_fraction"][()]
        points = f["/modes/shape_points"][()]
    if len(omega) != 3 * n:
        raise SystemExit(f"stiff_modes: n = {n}: {len(omega)} modes of {3 * n}")
    turning = np.array([turning_share(points[m]) for m in range(len(omega))])
    return omega, zeta, kinds(axial, turning)


def run_radius(exe, work, n):
    """The spectral radius (1/s) the symplectic method estimates at the start of a run of
    the paper's rope with n elements (its first switch-log entry)."""
    out = work / f"start_{n}.h5"
    cmd = [str(exe), "run", str(PAPER), *set_args([
        f"model.elements={n}", 'solver.method="symplectic"', "solver.t_end=0.01",
        f'output.file="{out}"'])]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=3600)
    if proc.returncode != 0:
        raise SystemExit(f"stiff_modes: the run at n = {n} failed: {proc.stderr.strip()}")
    with h5py.File(out, "r") as f:
        reason = f["/solver/switch_reason"][0].decode()
    m = _RADIUS.search(reason)
    if not m:
        raise SystemExit(f"stiff_modes: no spectral radius in the switch log: {reason}")
    return float(m.group(1))


def row(exe, work, n):
    omega, zeta, kind = modes_of(exe, work, n)
    top = int(np.argmax(omega))
    largest = [f"{omega[kind == k].max():.0f}" if np.any(kind == k) else "-"
               for k in range(len(KINDS))]
    gains = step_gains(omega, kind)
    return (f"| {n} | {len(omega)} | {' | '.join(largest)} | {omega[top]:.0f} | "
            f"{KINDS[kind[top]]} | {zeta[top]:.3f} | {run_radius(exe, work, n):.3g} | "
            + " | ".join(f"{gains[k]:.2f}" for k in range(len(KINDS))) + " |")


def main(argv=None):
    parser = argparse.ArgumentParser(description=summary(__doc__))
    add_exe_argument(parser)
    parser.add_argument("--elements", type=list_text(positive(int)), default=ELEMENTS)
    parser.add_argument("--no-write", action="store_true")
    args = parser.parse_args(argv)
    exe = exe_or_build(args.exe)
    print(HEADER, flush=True)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for n in (int(x) for x in args.elements.split()):
            rows.append(row(exe, pathlib.Path(tmp), n))
            print(rows[-1], flush=True)
    if args.no_write:
        return 0
    command = "scripts/stiff_modes" + (f" --elements '{args.elements}'"
                                       if args.elements != ELEMENTS else "")
    block = "\n".join([
        BEGIN,
        f"Command: `{command}` (code: tools/ropedyn_tools/studies/stiff_modes.py; "
        "`ropedyn modes` about the hanging equilibrium, every mode; no CPU). The paper's "
        "rope (input/paper.nml): each mode's kind is the largest share of its end points' "
        "motion: along the rope (/modes/axial_fraction), the elements turning about their "
        "centres, or across the rope (the rest). The step gain of an IMEX method with one "
        "kind implicit: rho over the largest omega of the other two kinds. The estimate: "
        "the spectral radius the symplectic method finds at the start of a run (the "
        f"released straight rope). Machine: {machine()}. Run: {run_stamp()}.", "",
        HEADER, "|" + "---|" * (HEADER.count("|") - 1), *rows, END])
    update_doc(DOC, BEGIN, END, block, heading="## What holds the step\n\n")
    print(f"stiff_modes: {DOC}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
