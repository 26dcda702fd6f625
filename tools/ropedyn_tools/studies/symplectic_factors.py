"""The symplectic method's safety factor for lightly damped fast modes: the balance over
1000 s at the factor in the code and at others.

The code of scripts/symplectic_factors; writes the section between the symplectic-factors
markers of docs/theory/symplectic.md ("The step"), the measurement behind RESONANT_SAFETY
(solvers/symplectic/ropedyn_symplectic.f90).

Where the fast modes are lightly damped the method steps at RESONANT_SAFETY times its stable
step. Near the stability limit, combinations of two such modes (up to twice the fastest
frequency) feed a slow drift of the energy that a 300 s run can miss. So: the undamped paper
rope (input/paper.nml with damping off) at n = 20 from four release angles (74.8, 74.9, 75.0
and 75.1 degrees) and at n = 100 from two (74.8, 75.0), and the lightly damped one
(input/paper_light_damping.nml) at n = 20 from two, each to 1000 s with `method =
'symplectic'`, rtol 1e-3, atol 1e-5, a record every 0.1 s, at each factor of --factors. The
factor in the code runs on this tree's Release build (or --exe); every other one on a
Release build of HEAD (git archive) with only that parameter changed.

Per case and factor, over the starts (ranges): the largest |B - E0| (B = T + V + dissipated
- work, m g L) in the first and in the last 100 s window, the smallest and largest window
mean (a drift moves the means), the mean elastic energy (where the fast modes' energy is) in
the first and last window, and the steps over those at the code's factor. Runs go two at a
time; no CPU.
"""
import argparse
import concurrent.futures
import pathlib
import re
import sys
import tempfile

import numpy as np

from ropedyn_tools.arguments import list_text, positive
from ropedyn_tools.repo import DOCS, INPUT, PAPER, ROOT, add_exe_argument, exe_or_build
from ropedyn_tools.studies.bench_symplectic import run, undamped_sets, window_masks
from ropedyn_tools.studies.common import machine, run_stamp, update_doc
from ropedyn_tools.studies.profile_step import build_baseline
from ropedyn.docstrings import summary

DOC = DOCS / "theory" / "symplectic.md"
BEGIN = "<!-- symplectic-factors:begin -->"
END = "<!-- symplectic-factors:end -->"
SOURCE = pathlib.Path("solvers") / "symplectic" / "ropedyn_symplectic.f90"
PARAMETER = re.compile(r"(real\(wp\), parameter :: RESONANT_SAFETY = )([0-9.]+)(_wp)")
#: the cases: label, scene, n, release angles (degrees)
CASES = (("undamped", PAPER, 20, (74.8, 74.9, 75.0, 75.1)),
         ("undamped", PAPER, 100, (74.8, 75.0)),
         ("lightly damped", INPUT / "paper_light_damping.nml", 20, (74.8, 75.0)))
#: the windows (s)
WINDOW = 100.0


def code_factor(root=ROOT):
    """RESONANT_SAFETY as the source at `root` has it."""
    m = PARAMETER.search((root / SOURCE).read_text())
    if m is None:
        raise SystemExit(f"symplectic_factors: no RESONANT_SAFETY in {root / SOURCE}")
    return float(m.group(2))


def with_factor(factor):
    """An edit of an extracted source tree: RESONANT_SAFETY set to `factor`."""
    def edit(src):
        path = src / SOURCE
        text, count = PARAMETER.subn(rf"\g<1>{factor!r}\g<3>", path.read_text())
        if count != 1:
            raise SystemExit(f"symplectic_factors: RESONANT_SAFETY not found in {path}")
        path.write_text(text)
    return edit


def windows(r, span=WINDOW):
    """Per window of `span` s: the largest |B - E0|, the mean of B - E0 and the mean
    elastic energy (m g L)."""
    _, masks = window_masks(r["t"], span)
    return [(float(np.abs(r["drift"][m]).max()), float(r["drift"][m].mean()),
             float(r["elastic"][m].mean())) for m in masks]


def span(values, spec):
    """'a - b' (or 'a' when they agree in print) of the smallest and largest value."""
    lo, hi = format(min(values), spec), format(max(values), spec)
    return lo if lo == hi else f"{lo} - {hi}"


def row(label, n, factor, runs, steps_code):
    """The table row of one case at one factor (`runs`: one per start)."""
    if not all(r["ok"] for r in runs):
        why = next(r["why"] for r in runs if not r["ok"])
        return f"| {label} | {n} | {factor:g} | {len(runs)} | | | | | | {why} |"
    ws = [windows(r) for r in runs]
    means = [m for w in ws for _, m, _ in w]
    steps = np.mean([r["steps"] for r in runs])
    return (f"| {label} | {n} | {factor:g} | {len(runs)} | {steps / steps_code:.2f} | "
            f"{span([w[0][0] for w in ws], '.1e')} | {span([w[-1][0] for w in ws], '.1e')} | "
            f"{min(means):+.1e} … {max(means):+.1e} | "
            f"{span([w[0][2] for w in ws], '.3f')} → {span([w[-1][2] for w in ws], '.3f')} | |")


def measure(exes, t_end, work):
    """Every case at every factor (`exes`: factor -> executable); the runs by (case index,
    factor, start index)."""
    jobs = {}
    for c, (_, scene, n, angles) in enumerate(CASES):
        for factor, exe in exes.items():
            for k, angle in enumerate(angles):
                sets = [*undamped_sets(n, "symplectic", t_end), f"initial.angle_deg={angle!r}"]
                if scene != PAPER:      # the lightly damped scene keeps its damping
                    sets = [s for s in sets if not s.startswith("effects.damping")]
                jobs[(c, factor, k)] = (exe, scene, f"f{c}_{factor:g}_{k}", sets)
    with concurrent.futures.ThreadPoolExecutor(2) as pool:
        futures = {key: pool.submit(run, exe, work, scene, name, sets)
                   for key, (exe, scene, name, sets) in jobs.items()}
        return {key: f.result() for key, f in futures.items()}


def main(argv=None):
    parser = argparse.ArgumentParser(description=summary(__doc__))
    add_exe_argument(parser, "the ropedyn executable of this tree (the code's factor)")
    parser.add_argument("--factors", type=list_text(positive(float)), default="0.3 0.35 0.4",
                        help="the factors, space-separated (one of them the code's)")
    parser.add_argument("--t-end", type=positive(float), default=1000.0)
    parser.add_argument("--no-write", action="store_true")
    args = parser.parse_args(argv)
    current = code_factor()
    factors = sorted({float(f) for f in args.factors.split()} | {current})
    with tempfile.TemporaryDirectory() as work:
        work = pathlib.Path(work)
        exes = {}
        for f in factors:
            if f == current:
                exes[f] = exe_or_build(args.exe)
            else:
                print(f"symplectic_factors: building HEAD with RESONANT_SAFETY = {f:g}",
                      flush=True)
                exes[f] = build_baseline("HEAD", pathlib.Path(tempfile.mkdtemp(dir=work)),
                                         edit=with_factor(f))
        results = measure(exes, args.t_end, work)
    rows = []
    for c, (label, _, n, angles) in enumerate(CASES):
        code_runs = [results[(c, current, k)] for k in range(len(angles))]
        steps_code = np.mean([r["steps"] for r in code_runs if r["ok"]] or [np.nan])
        for f in factors:
            rows.append(row(label, n, f, [results[(c, f, k)] for k in range(len(angles))],
                            steps_code))
            print(rows[-1], flush=True)
    if args.no_write:
        return 0
    command = "scripts/symplectic_factors" + (
        f" --factors '{args.factors}'" if args.factors != "0.3 0.35 0.4" else "") + (
        f" --t-end {args.t_end:g}" if args.t_end != 1000.0 else "")
    block = "\n".join([
        BEGIN,
        f"Command: `{command}` (code: tools/ropedyn_tools/studies/symplectic_factors.py; no "
        f"CPU). Machine: {machine()}. Run: {run_stamp()}.", "",
        f"The paper rope to {args.t_end:g} s with `method = 'symplectic'`, rtol 1e-3, atol "
        "1e-5, a record every 0.1 s: undamped (damping off) at n = 20 from release angles "
        "74.8, 74.9, 75.0 and 75.1 degrees and at n = 100 from 74.8 and 75.0, and lightly "
        "damped (input/paper_light_damping.nml) at n = 20 from 74.8 and 75.0; the factor "
        f"in the code is {current:g}, the others are builds of HEAD with only RESONANT_SAFETY "
        "changed. Over the starts (ranges), B - E0 = T + V + dissipated - work - E0 in m g "
        f"L: its largest absolute value in the first and in the last {WINDOW:g} s, the "
        f"smallest and the largest mean of a {WINDOW:g} s window, and the mean elastic "
        "energy (m g L; where the fast modes' energy is) in the first and the last window; "
        f"the steps over those at {current:g}:", "",
        f"| rope | n | factor | starts | steps / at {current:g} | largest abs, first "
        f"{WINDOW:g} s | largest abs, last {WINDOW:g} s | window means | elastic energy, "
        "first → last window | failed |",
        "|---|---|---|---|---|---|---|---|---|---|", *rows, END])
    update_doc(DOC, BEGIN, END, block)
    print(f"symplectic_factors: {DOC}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
