"""The symplectic method's targets: the energy of long runs against time, and its cost.

The code of scripts/bench_symplectic; writes the section between the symplectic-targets
markers of docs/validation/energy.md.

- The undamped paper rope (input/paper.nml with damping off) at n = 20 and 100, to 300 s,
  rtol 1e-3 (atol 1e-5), a record every 0.1 s: `method = 'symplectic'`, the default (auto,
  which now takes the symplectic method there) and erk (what auto ran there before):
  |T + V - E0| in units of m g L at 30 s and 300 s and its largest value up to each, and
  the CPU of each run.
- The same undamped runs of the symplectic method from `--starts` release angles 1e-7
  degrees apart (75, 75 + 1e-7, ...; the first is the run above): the growth from the
  largest error up to 30 s to the largest up to the end, start by start. The motion is
  chaotic, so the growth of one run is one draw: its median and range over the starts
  say what the method does. No CPU: these runs go two at a time.
- The lightly damped paper rope (input/paper_light_damping.nml) at n = 20 and 30, 30 s: the
  default method at rtol 1e-3, and MEBDF at max_order 7, rtol 1e-4 (n = 20): the balance
  T + V + dissipated - E0 at 30 s and its largest gain, m g L.

CPU: each run once (`--repeat` for the least of several), process CPU of the run
(/solver/cpu_time), on a shared two-core machine: 10-20 % from run to run.

`scripts/bench_symplectic elastic` writes the section between the elastic-growth markers
instead: whether the rise of the symplectic method's error over 300 s is the rope's or the
method's. The undamped rope (n = 20, from 75 degrees, as above) with the symplectic method
at rtol 1e-3, 1e-5 and 1e-7 (ever shorter steps and, from 1e-5, SRKN6b) and with cvode at
rtol 1e-9 (an independent method, its step held by accuracy): the growth of the elastic
energy and of the largest |T + V - E0|, as in the table above. Two runs at a time, no CPU.

`scripts/bench_symplectic plateau` writes the section between the energy-plateau markers
(docs/validation/energy.md too): whether the error stops growing once the fast modes have
filled. The undamped rope (n = 20 and 100, from 75 degrees, rtol 1e-3, as above) with the
symplectic method to 3000 s, and the largest n again at rtol 1e-5 (shorter steps: whether
the rise of the elastic energy is the rope's): window by window (300 s each) the largest
|T + V - E0|, its mean and the mean elastic energy, and the largest error up to 30 s,
300 s and the end.
The rope starts at rest, with its fast modes empty; the chaotic motion fills them over
minutes, and the error of a fixed step grows with their energy until they are full.
Two runs at a time, with the CPU of each (they share the two cores).

`scripts/bench_symplectic tolerance` writes the section between the symplectic-tolerance
markers (docs/validation/energy.md too): what a tighter rtol buys on an undamped rope whose
fast modes hold much of the energy (4 elements, 60 s; the step rule's energy spread of the
fastest mode: docs/theory/symplectic.md, "The step"). No CPU.
"""
import argparse
import concurrent.futures
import pathlib
import subprocess
import sys
import tempfile

import numpy as np

from ropedyn import io
from ropedyn_tools.arguments import list_text, positive
from ropedyn_tools.repo import DOCS, INPUT, PAPER, add_exe_argument, exe_or_build, set_args
from ropedyn_tools.studies import stability_metrics
from ropedyn_tools.studies.common import (baseline_revision, least_cpu, machine, run_stamp,
                                          update_doc)
from ropedyn_tools.studies.profile_step import build_baseline
from ropedyn.docstrings import summary

DOC = DOCS / "validation" / "energy.md"
BEGIN = "<!-- symplectic-targets:begin -->"
END = "<!-- symplectic-targets:end -->"
LIGHT = INPUT / "paper_light_damping.nml"
#: the last revision whose default method (auto) ran erk and MEBDF on the undamped rope,
#: before the symplectic method existed: the symplectic method's CPU target
FORMER = "4276956"
#: the window (s) of the growth columns and of the window tables
WINDOW = 30.0
#: the release angles of the ensemble: 75 degrees plus multiples of this (degrees)
START_SPACING = 1.0e-7


def run(exe, work, scene, name, sets):
    """One run; its records' balance error B - E0 (J), time, m g L (J) and CPU."""
    out = pathlib.Path(work) / f"{name}.h5"
    proc = subprocess.run([str(exe), "run", str(scene), *set_args(
        [f'output.file="{out}"', *sets])], capture_output=True, text=True, timeout=7200)
    if proc.returncode != 0:
        return {"ok": False, "why": (proc.stderr.strip().splitlines() or ["failed"])[-1][:90],
                "cpu": float("inf")}
    r = io.load_run(out)
    e = r.energy
    drift = r.balance - r.e0
    mgl = stability_metrics.weight_length(r)
    return {"ok": True, "t": r.time, "drift": drift / mgl, "cpu": float(r.stats["cpu_time"]),
            "steps": int(r.stats["steps"]), "elastic": e["elastic"] / mgl}


def at(r, when):
    k = int(np.searchsorted(r["t"], when - 1e-9))
    return r["drift"][min(k, len(r["t"]) - 1)]


def upto(r, when):
    return float(np.abs(r["drift"][r["t"] <= when + 1e-9]).max())


def elastic_growth(r, span=WINDOW):
    """The mean elastic energy (where the fast modes' energy is) over the last `span`
    seconds over its mean over the first: how much the fast modes gained."""
    t, e = r["t"], r["elastic"]
    return float(e[t >= t[-1] - span].mean() / e[t <= span].mean())


def window_masks(t, span):
    """The windows of `span` seconds over the record times t: their starts, and a mask of
    the records in each (the last window takes the last record too)."""
    edges = np.arange(0.0, t[-1] + 1e-9, span)[:-1]
    return edges, [(t >= a) & ((t < a + span) | (a + span >= t[-1])) for a in edges]


def scaled_growth(r, span=WINDOW):
    """The growth of the error relative to the fast modes' energy: in each window of `span`
    seconds the largest |T + V - E0| over the mean elastic energy, the largest of these over
    the first window's. A symplectic method's energy error is that of a modified energy,
    whose difference from the true one scales with the energy of the fast modes (their
    phase error per step times their energy); where the rope moves energy into its fast
    modes, the error grows with them without any drift of the method, and this stays near
    1. A method that drifts (or damps the fast modes away) makes it grow."""
    _, masks = window_masks(r["t"], span)
    ratios = [np.abs(r["drift"][m]).max() / r["elastic"][m].mean() for m in masks]
    return float(max(ratios) / ratios[0])


def window_rows(n, r, span=WINDOW):
    """The symplectic run's error and elastic energy window by window (`span` s each):
    the largest |T + V - E0|, its mean, and the mean elastic energy, m g L."""
    t = r["t"]
    edges, masks = window_masks(t, span)
    quantities = (("largest abs error", lambda m: np.abs(r["drift"][m]).max(), ".1e"),
                  ("mean error", lambda m: r["drift"][m].mean(), "+.1e"),
                  ("mean elastic energy", lambda m: r["elastic"][m].mean(), ".3f"),
                  ("largest abs error / mean elastic energy",
                   lambda m: np.abs(r["drift"][m]).max() / r["elastic"][m].mean(), ".1e"))
    head = f"| n | per window of {span:g} s (m g L) | " + " | ".join(
        f"{a:g}-{a + span:g} s" for a in edges) + " |"
    rows = [f"| {n} | {name} | " + " | ".join(format(f(m), spec) for m in masks) + " |"
            for name, f, spec in quantities]
    return head, rows


def undamped_rows(exe, work, ns, t_end, repeat, former):
    """The undamped rope's rows: the former default first (`former`: (revision, its
    executable)), then the symplectic method, auto and erk of this tree, each with its CPU
    over the former default's (the target: at most 1); and the symplectic runs by n."""
    rev, former_exe = former
    rows, symplectic = [], {}
    for n in ns:
        base = None
        for label, method, program in ((f"auto at {rev} (the former default)", "auto",
                                        former_exe), ("symplectic", "symplectic", exe),
                                       ("auto", "auto", exe), ("erk", "erk", exe)):
            sets = undamped_sets(n, method, t_end)
            tag = f"u{n}_{method}_{'former' if program is former_exe else 'now'}"
            r = least_cpu(lambda: run(program, work, PAPER, tag, sets), repeat,
                          complete=lambda x: x["ok"])
            if not r["ok"]:
                rows.append(f"| {n} | {label} | | | | | | | | | | {r['why']} |")
                continue
            base = base or r["cpu"]
            if method == "symplectic":
                symplectic[n] = r
            rows.append(f"| {n} | {label} | {at(r, 30):+.1e} | {at(r, t_end):+.1e} | "
                        f"{upto(r, 30):.1e} | {upto(r, t_end):.1e} | "
                        f"{upto(r, t_end) / upto(r, 30):.1f} | {elastic_growth(r):.1f} | "
                        f"{scaled_growth(r):.1f} | "
                        f"{r['cpu']:.3g} | {r['cpu'] / base:.2f} | "
                        f"{'yes' if upto(r, t_end) <= 1e-3 else 'no'} |")
            print(rows[-1], flush=True)
    return rows, symplectic


def undamped_sets(n, method, t_end):
    """The overrides of an undamped run (the table's and the ensemble's)."""
    return [f"model.elements={n}", "effects.damping=.false.", f"solver.method='{method}'",
            "solver.rtol=1e-3", "solver.atol=1e-5", f"solver.t_end={t_end:g}",
            "solver.output_interval=0.1", "solver.max_steps=100000000"]


def ensemble_rows(exe, work, ns, t_end, starts, first=None):
    """The symplectic method's growth (the largest error up to t_end over the largest up to
    WINDOW) and elastic energy growth from `starts` release angles START_SPACING degrees
    apart, per n: median, range, and how many starts meet the target of 2. `first`: the
    runs from the first angle (75 degrees, the scene's) already made, by n: not made again."""
    first = first or {}
    jobs = {(n, k): [*undamped_sets(n, "symplectic", t_end),
                     f"initial.angle_deg={75.0 + k * START_SPACING!r}"]
            for n in ns for k in range(starts) if k > 0 or n not in first}
    with concurrent.futures.ThreadPoolExecutor(2) as pool:
        futures = {key: pool.submit(run, exe, work, PAPER, f"ens{key[0]}_{key[1]}", sets)
                   for key, sets in jobs.items()}
        results = {key: f.result() for key, f in futures.items()}
    results.update({(n, 0): r for n, r in first.items()})
    rows = []
    for n in ns:
        runs = [results[(n, k)] for k in range(starts)]
        if not all(r["ok"] for r in runs):
            why = next(r["why"] for r in runs if not r["ok"])
            rows.append(f"| {n} | {starts} | | | | | | {why} |")
            continue
        growth = np.array([upto(r, t_end) / upto(r, WINDOW) for r in runs])
        elastic = np.array([elastic_growth(r) for r in runs])
        largest = np.array([upto(r, t_end) for r in runs])
        scaled = np.array([scaled_growth(r) for r in runs])
        rows.append(f"| {n} | {starts} | {np.median(largest):.1e} | {np.median(growth):.2f} | "
                    f"{growth.min():.2f} - {growth.max():.2f} | {int((growth <= 2).sum())} | "
                    f"{np.median(elastic):.1f} ({elastic.min():.1f} - {elastic.max():.1f}) | "
                    f"{np.median(scaled):.2f} ({scaled.min():.2f} - {scaled.max():.2f}) | "
                    f"{int((scaled <= 2).sum())} |")
        print(rows[-1], flush=True)
    return rows


def light_rows(exe, work, repeat):
    rows = []
    cases = [(20, "auto", 0, 1e-3), (30, "auto", 0, 1e-3), (20, "mebdf", 7, 1e-4)]
    for n, method, order, rtol in cases:
        sets = [f"model.elements={n}", f"solver.method='{method}'",
                f"solver.max_order={order}", f"solver.rtol={rtol:g}",
                f"solver.atol={rtol / 100:g}", "solver.t_end=30"]
        r = least_cpu(lambda: run(exe, work, LIGHT, f"l{n}_{method}{order}", sets), repeat,
                      complete=lambda x: x["ok"])
        label = f"{method}" + (f", max_order {order}" if order else "")
        if not r["ok"]:
            rows.append(f"| {n} | {label} | {rtol:g} | | | | {r['why']} |")
            continue
        gain = max(0.0, float(r["drift"].max()))
        # the targets: the default's |balance| at 30 s within 1e-3 m g L; MEBDF 7's gain
        # within 2 rtol m g L
        target = (f"gain <= 2 rtol: {'yes' if gain <= 2 * rtol else 'no'}" if order else
                  f"abs at 30 s <= 1e-3: {'yes' if abs(at(r, 30)) <= 1e-3 else 'no'}")
        rows.append(f"| {n} | {label} | {rtol:g} | {at(r, 30):+.1e} | {gain:.1e} | "
                    f"{r['cpu']:.3g} | {target} |")
        print(rows[-1], flush=True)
    return rows


ELASTIC_BEGIN = "<!-- elastic-growth:begin -->"
ELASTIC_END = "<!-- elastic-growth:end -->"
#: the runs of the elastic section: (method, rtol)
ELASTIC_RUNS = (("symplectic", 1e-3), ("symplectic", 1e-5), ("symplectic", 1e-7),
                ("cvode", 1e-9))


def elastic_rows(exe, work, n, t_end):
    """The elastic section's rows: each run of ELASTIC_RUNS on the undamped rope."""
    def one(method, rtol):
        sets = [*undamped_sets(n, method, t_end), f"solver.rtol={rtol:g}",
                f"solver.atol={rtol / 100:g}"]
        return run(exe, work, PAPER, f"el{n}_{method}_{rtol:g}", sets)
    with concurrent.futures.ThreadPoolExecutor(2) as pool:
        results = list(pool.map(lambda mr: one(*mr), ELASTIC_RUNS))
    rows = []
    for (method, rtol), r in zip(ELASTIC_RUNS, results):
        if not r["ok"]:
            rows.append(f"| {method} | {rtol:g} | | | | | | {r['why']} |")
            continue
        first = r["elastic"][r["t"] <= WINDOW].mean()
        rows.append(f"| {method} | {rtol:g} | {r['steps']} | {first:.3f} | "
                    f"{elastic_growth(r):.1f} | {upto(r, WINDOW):.1e} | {upto(r, t_end):.1e} | "
                    f"{upto(r, t_end) / upto(r, WINDOW):.1f} |")
        print(rows[-1], flush=True)
    return rows


def write_elastic(exe, n, t_end, no_write):
    with tempfile.TemporaryDirectory() as work:
        rows = elastic_rows(exe, work, n, t_end)
    if no_write:
        return 0
    block = "\n".join([
        ELASTIC_BEGIN,
        f"Command: `scripts/bench_symplectic elastic --elements {n} --t-end {t_end:g}` "
        "(code: tools/ropedyn_tools/studies/bench_symplectic.py). Machine: "
        f"{machine()}. Run: {run_stamp()}.", "",
        f"The undamped paper rope, n = {n}, from 75 degrees, to {t_end:g} s (atol = rtol / "
        "100, a record every 0.1 s): the mean elastic energy over the first "
        f"{WINDOW:g} s (m g L), its growth (the mean over the last {WINDOW:g} s over that), "
        f"the largest |T + V - E0| (m g L) up to {WINDOW:g} s and up to the end, and the "
        "growth from the one to the other (the target: at most 2). Shorter steps, and an "
        "independent method, show how much of the growth is the rope's:", "",
        f"| method | rtol | steps | elastic energy, first {WINDOW:g} s | elastic energy growth | "
        f"max abs to {WINDOW:g} s | max abs to the end | growth |",
        "|---|---|---|---|---|---|---|---|", *rows, ELASTIC_END])
    update_doc(DOC, ELASTIC_BEGIN, ELASTIC_END, block)
    print(f"bench_symplectic elastic: {DOC}")
    return 0


PLATEAU_BEGIN = "<!-- energy-plateau:begin -->"
PLATEAU_END = "<!-- energy-plateau:end -->"
#: the plateau section's run length and window (s)
PLATEAU_T_END, PLATEAU_WINDOW = 3000.0, 300.0
#: the largest n again at this rtol (SRKN6b at shorter steps): whether the rise of the
#: elastic energy is the rope's, whatever the step
PLATEAU_CHECK_RTOL = 1e-5


def plateau_runs(ns):
    """The plateau section's runs: (n, rtol) for each n at rtol 1e-3, and the largest n at
    PLATEAU_CHECK_RTOL."""
    return [(n, 1e-3) for n in ns] + [(max(ns), PLATEAU_CHECK_RTOL)]


def plateau_rows(r, t_end, span):
    """The plateau section's summary cells of one run: its steps and CPU, the largest
    |T + V - E0| up to WINDOW, up to `span` and up to `t_end`, the growths from each to the
    next, and the mean elastic energy over the first and the last `span` (m g L)."""
    t, e = r["t"], r["elastic"]
    first, last = e[t <= span].mean(), e[t >= t[-1] - span].mean()
    short, mid, end = upto(r, WINDOW), upto(r, span), upto(r, t_end)
    return (f"{r['steps']} | {r['cpu']:.3g} | {short:.1e} | {mid:.1e} | {end:.1e} | "
            f"{mid / short:.1f} | {end / mid:.2f} | {first:.3f} | {last:.3f}")


def write_plateau(exe, ns, t_end, span, no_write):
    runs = plateau_runs(ns)
    with tempfile.TemporaryDirectory() as work:
        def one(job):
            n, rtol = job
            return run(exe, work, PAPER, f"plateau{n}_{rtol:g}",
                       [*undamped_sets(n, "symplectic", t_end), f"solver.rtol={rtol:g}",
                        f"solver.atol={rtol / 100:g}"])
        with concurrent.futures.ThreadPoolExecutor(2) as pool:
            results = dict(zip(runs, pool.map(one, runs)))
    summary_rows, windows = [], {}
    for (n, rtol), r in results.items():
        if not r["ok"]:
            summary_rows.append(f"| {n} | {rtol:g} | | | | | | | | | {r['why']} |")
            continue
        summary_rows.append(f"| {n} | {rtol:g} | {plateau_rows(r, t_end, span)} |")
        windows[n, rtol] = window_rows(f"{n}, rtol {rtol:g}", r, span)
        print(summary_rows[-1], flush=True)
    if no_write:
        return 0
    block = [
        PLATEAU_BEGIN,
        f"Command: `scripts/bench_symplectic plateau --elements \"{' '.join(map(str, ns))}\" "
        f"--t-end {t_end:g}"
        + (f" --window {span:g}" if span != PLATEAU_WINDOW else "")
        + "` (code: tools/ropedyn_tools/studies/bench_symplectic.py; the runs "
        f"two at a time). Machine: {machine()}. Run: {run_stamp()}.", "",
        f"The undamped paper rope from 75 degrees to {t_end:g} s, `method = 'symplectic'`, "
        "rtol 1e-3 (and the largest n again at "
        f"{PLATEAU_CHECK_RTOL:g}, at shorter steps: whether the rise of the elastic energy "
        "is the rope's), atol = rtol / 100, a record every 0.1 s: the steps and CPU (s) of "
        "the run, the "
        f"largest |T + V - E0| (m g L) up to {WINDOW:g} s, up to {span:g} s and up to the "
        f"end, the growth from the first to the second (the target's) and from the second to "
        f"the third, and the mean elastic energy (m g L) over the first and the last "
        f"{span:g} s:", "",
        f"| n | rtol | steps | CPU (s) | max abs to {WINDOW:g} s | max abs to {span:g} s | "
        f"max abs to the end | growth {WINDOW:g} s to {span:g} s | growth {span:g} s to the "
        f"end | elastic energy, first {span:g} s | elastic energy, last {span:g} s |",
        "|---|---|---|---|---|---|---|---|---|---|---|", *summary_rows, "",
        f"Window by window ({span:g} s each): the largest |T + V - E0|, its mean, the mean "
        "elastic energy, m g L, and the first over the third:", ""]
    block += window_tables(windows)
    update_doc(DOC, PLATEAU_BEGIN, PLATEAU_END, "\n".join([*block[:-1], PLATEAU_END]))
    print(f"bench_symplectic plateau: {DOC}")
    return 0


TOLERANCE_BEGIN = "<!-- symplectic-tolerance:begin -->"
TOLERANCE_END = "<!-- symplectic-tolerance:end -->"
#: the tolerance section: the rtols, the rope's elements and the run's length (s)
TOLERANCE_RTOLS = (1e-3, 1e-4, 1e-5, 1e-6)
TOLERANCE_N, TOLERANCE_T_END = 4, 60.0


def composition(out):
    """The composition of a symplectic run's last switch-log entry (its label, the text
    before the first comma of /solver/switch_reason)."""
    import h5py
    with h5py.File(out, "r") as f:
        return f["/solver/switch_reason"][-1].decode().split(",")[0].strip()


def tolerance_rows(exe, work):
    """The tolerance section's rows: the undamped rope of TOLERANCE_N elements to
    TOLERANCE_T_END with the symplectic method at each of TOLERANCE_RTOLS."""
    rows = []
    for rtol in TOLERANCE_RTOLS:
        name = f"tol_{rtol:g}"
        sets = [*undamped_sets(TOLERANCE_N, "symplectic", TOLERANCE_T_END),
                f"solver.rtol={rtol:g}", f"solver.atol={rtol / 100:g}"]
        r = run(exe, work, PAPER, name, sets)
        if not r["ok"]:
            rows.append(f"| {rtol:g} | | | {r['why']} | |")
            continue
        worst = upto(r, TOLERANCE_T_END)
        rows.append(f"| {rtol:g} | {composition(pathlib.Path(work) / f'{name}.h5')} | "
                    f"{r['steps']} | {worst:.1e} | {worst / rtol:.2f} |")
        print(rows[-1], flush=True)
    return rows


def write_tolerance(exe, no_write):
    with tempfile.TemporaryDirectory() as work:
        rows = tolerance_rows(exe, work)
    if no_write:
        return 0
    block = "\n".join([
        TOLERANCE_BEGIN,
        "Command: `scripts/bench_symplectic tolerance` (code: "
        f"tools/ropedyn_tools/studies/bench_symplectic.py; no CPU). Run: {run_stamp()}.", "",
        f"The undamped paper rope of {TOLERANCE_N} elements from 75 degrees, "
        f"{TOLERANCE_T_END:g} s, `method = 'symplectic'` (atol = rtol / 100, a record every "
        "0.1 s): the composition the step rule took, its steps, and the largest "
        "|T + V - E0| over the records, in m g L and over rtol:", "",
        "| rtol | composition | steps | largest abs T + V - E0 (m g L) | over rtol |",
        "|---|---|---|---|---|", *rows, TOLERANCE_END])
    update_doc(DOC, TOLERANCE_BEGIN, TOLERANCE_END, block)
    print(f"bench_symplectic tolerance: {DOC}")
    return 0


def window_block(windows):
    """The window tables of the symplectic runs (one per n), with their heading."""
    if not windows:
        return []
    block = ["The symplectic method's runs window by window: the largest |T + V - E0| in "
             f"each {WINDOW:g} s, its mean, the mean elastic energy (where the fast "
             "modes' energy is), m g L, and the first over the third:", ""]
    return block + window_tables(windows)


def window_tables(windows):
    """The window tables of `windows` (window_rows' (head, rows), by run), one after the
    other, each followed by a blank line."""
    lines = []
    for head, rows in windows.values():
        lines += [head, "|" + "---|" * (head.count("|") - 1), *rows, ""]
    return lines


def main(argv=None):
    parser = argparse.ArgumentParser(description=summary(__doc__))
    add_exe_argument(parser)
    parser.add_argument("mode", nargs="?", choices=("targets", "elastic", "tolerance",
                                                    "plateau"),
                        default="targets", help="the targets' section (default), the "
                        "elastic-growth one, the tolerance one or the energy-plateau one")
    parser.add_argument("--elements", type=list_text(positive(int)), default="20 100")
    parser.add_argument("--t-end", type=positive(float), default=None,
                        help=f"s (default 300; plateau: {PLATEAU_T_END:g})")
    parser.add_argument("--window", type=positive(float), default=PLATEAU_WINDOW,
                        help=f"plateau: the window of its table, s (default {PLATEAU_WINDOW:g})")
    parser.add_argument("--repeat", type=int, default=1)
    parser.add_argument("--starts", type=int, default=8,
                        help="release angles of the symplectic method's ensemble")
    parser.add_argument("--former", default=FORMER,
                        help="git revision whose default method is the CPU target "
                             f"(built from git archive; default {FORMER})")
    parser.add_argument("--former-exe", default=None,
                        help="that revision's Release executable, built before")
    parser.add_argument("--no-write", action="store_true")
    args = parser.parse_args(argv)
    if args.mode == "plateau":
        return write_plateau(exe_or_build(args.exe), [int(x) for x in args.elements.split()],
                             args.t_end or PLATEAU_T_END, args.window, args.no_write)
    if args.t_end is None:
        args.t_end = 300.0
    if args.mode == "elastic":
        return write_elastic(exe_or_build(args.exe), int(args.elements.split()[0]),
                             args.t_end, args.no_write)
    if args.mode == "tolerance":
        return write_tolerance(exe_or_build(args.exe), args.no_write)
    if not args.former_exe:
        args.former = baseline_revision(parser, args.former)
    exe = exe_or_build(args.exe)
    with tempfile.TemporaryDirectory() as work:
        former_exe = pathlib.Path(args.former_exe) if args.former_exe else \
            build_baseline(args.former, pathlib.Path(tempfile.mkdtemp(dir=work)))
        ns = [int(x) for x in args.elements.split()]
        undamped, symplectic = undamped_rows(exe, work, ns, args.t_end, args.repeat,
                                             (args.former, former_exe))
        windows = {n: window_rows(n, r) for n, r in symplectic.items()}
        ensemble = ensemble_rows(exe, work, ns, args.t_end, args.starts, symplectic)
        light = light_rows(exe, work, args.repeat)
    if args.no_write:
        return 0
    block = "\n".join([
        BEGIN,
        f"Command: `scripts/bench_symplectic --elements \"{args.elements}\" --t-end "
        f"{args.t_end:g} --repeat {args.repeat} --starts {args.starts} --former "
        f"{args.former}` "
        + ("(with `--former-exe`: that revision's Release executable, built before) "
           if args.former_exe else "") + "(code: "
        "tools/ropedyn_tools/studies/bench_symplectic.py). Machine: "
        f"{machine()}. Run: {run_stamp()}.", "",
        f"The undamped paper rope to {args.t_end:g} s, rtol 1e-3, atol 1e-5: T + V - E0 in "
        "m g L at 30 s and at the end, its largest absolute value over the records (every "
        "0.1 s) up to each, the growth from the one to the other (the target: at most 2), "
        "the growth of the elastic energy (where the fast modes' energy is: its mean over "
        "the last 30 s over its mean over the first), the growth of the error relative to "
        "that energy (in each 30 s the largest |T + V - E0| over the mean elastic energy, "
        "the largest of these over the first's: it stays near 1 where the error only follows "
        "the fast modes' energy, and grows where the method drifts), the CPU of the run, its "
        "ratio to the "
        "CPU of the default method before the symplectic method "
        f"({args.former}'s auto, built from that revision and run in the same session; the "
        "target: at most 1), and whether it stays within 1e-3 m g L:", "",
        "| n | method | at 30 s | at the end | max abs to 30 s | max abs to the end | "
        "growth | elastic energy growth | growth over the elastic energy | CPU (s) | "
        "CPU / former default | within 1e-3 |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|", *undamped, "",
        *window_block(windows),
        f"The symplectic method from {args.starts} release angles {START_SPACING:g} degrees "
        "apart (75 degrees plus multiples; the first is the run above), the same rope and "
        "settings: the largest |T + V - E0| up to the end (median), the growth from the "
        f"largest up to {WINDOW:g} s to the largest up to the end (median, range, and the "
        "starts within the target of 2), the elastic energy growth and the growth over it as "
        "above (median and range), and the starts whose growth over the elastic energy is "
        "at most 2. The motion is chaotic: one run's growth is one draw.", "",
        "| n | starts | max abs to the end (median) | growth (median) | growth (range) | "
        "starts with growth <= 2 | elastic energy growth | growth over the elastic energy | "
        "starts with that <= 2 |",
        "|---|---|---|---|---|---|---|---|---|", *ensemble, "",
        "The lightly damped paper rope (eta 0.1 N s/m^2), 30 s: the balance T + V + "
        "dissipated - E0 at 30 s and its largest gain, m g L, against the targets (the "
        "default's balance within 1e-3 m g L at 30 s; MEBDF at order 7 gaining at most "
        "2 rtol m g L):", "",
        "| n | method | rtol | balance at 30 s | largest gain | CPU (s) | target |",
        "|---|---|---|---|---|---|---|", *light, END])
    update_doc(DOC, BEGIN, END, block)
    print(f"bench_symplectic: {DOC}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
