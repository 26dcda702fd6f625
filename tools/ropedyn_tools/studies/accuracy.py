"""What accuracy costs over the whole 30 s motion (issue 16): writes docs/validation/accuracy.md,
docs/data/acc_*.csv, docs/figures/acc_*.png and docs/guide/choosing.md.

    scripts/accuracy windows        [--quick] [--methods cvode,cvode:2,adams,erk,mebdf:4,...]
    scripts/accuracy discretization [--quick]
    scripts/accuracy chaos          [--quick]
    scripts/accuracy fig4           [--quick]
    scripts/accuracy choosing       (only reads the CSV files of the others)
    scripts/accuracy all            [--quick]
    (python -m ropedyn_tools.studies.accuracy; without --exe it builds the Release executable)

A method is `name` or `name:max_order` with `name` any `&solver method` the executable
lists (`ropedyn keys`): new integrators (erk, adams, auto, ...) are measured by adding their
names to --methods. Runs go one at a time (`ropedyn run`, its own CPU time
/solver/cpu_time). --quick is a smoke test (small n, short horizons, few tolerances); the
full studies are meant for the final code and take hours on 2 cores (docs/validation/accuracy.md).

- windows: tight references to T (two integrators at rtol_ref, which must agree until the
  motion's divergence horizon); from the first reference's record at each t0 every method
  and rtol restarts (`&initial shape = 'state'`) for a window of length W, measured against
  a tight window reference started from the same record with the *other* reference
  method. Errors over the window (L2 in time): tip position, all element end points, the
  axial (spring) force at the pin. Accuracy against CPU per window.
- discretization: tip position over [0, 1 s] at n against a fine reference (the largest n
  times 3, or given), at rtol 1e-9; and the time error of rtol 1e-3 .. 1e-7 at each n
  against its own tight run: "n needed for an accuracy" and "the rtol whose time error
  matches the discretization error at that n".
- chaos: the mean dissipation rate over [t1, T] for 8 starts perturbed by 1e-9 rad, per
  rtol: its ensemble mean and spread; which rtol reproduces the tight ensemble.
- fig4: the paper's Figure 4 over the whole motion: CPU of a T-second run against n for
  both models and each method, each at the loosest rtol whose windowed tip error (from
  `windows`, else the rtol given) is below the target.
"""
import argparse
import csv
import math
import pathlib
import subprocess
import sys
import tempfile
import time

import h5py
import numpy as np

from ropedyn_tools import docs_status
from ropedyn_tools.arguments import check_methods, method_specs
from ropedyn_tools.repo import DOCS, add_exe_argument, exe_or_build
from ropedyn_tools.studies.common import machine, method_sets, update_doc, run_stamp
from ropedyn.docstrings import summary

PAGE = DOCS / "validation" / "accuracy.md"
CHOOSING = DOCS / "guide" / "choosing.md"
DATA = DOCS / "data"
FIGURES = DOCS / "figures"
SCENE = DOCS.parent / "input" / "paper.nml"
L, EA = 1.0, 35e6 * math.pi * 0.005**2 / 4
PAGE_HEAD = """# Accuracy over the whole motion: what it costs

Every table and figure on this page is written by `scripts/accuracy`
(`tools/ropedyn_tools/studies/accuracy.py`), one section per subcommand; re-run it, never edit
the numbers. Scene: `input/paper.nml` (Table 1 rope, top pinned, released straight at 75
degrees, damping (eta, eta_bar) = (1e3, 400)); atol = 0.01 rtol in every run. CPU times are
the runs' own (`/solver/cpu_time`, integration and HDF5 output), one run each, on a
machine shared with other jobs: read factors below 1.3 as ties. Methods: CVODE BDF at its
default order 5 and at order 2 (`cvode:2`), CVODE Adams, the explicit pair (`erk`, RK4),
MEBDF at orders 4 and 7, and `auto` (the default). The answers drawn from these data
(which n, rtol and method, and the cost of the whole motion) are on
[choosing.md](../guide/choosing.md), written by `scripts/accuracy choosing` from the CSV files.

Left out, for cost: Figure 4's MPP above n = 70 with the implicit methods.
"""


# --------------------------------------------------------------------------------------
# running

class Runner:
    def __init__(self, exe, tmp, timeout=None):
        self.exe, self.tmp, self.count = str(exe), pathlib.Path(tmp), 0
        self.timeout = timeout

    def run(self, name, sets):
        """`ropedyn run input/paper.nml --set ...`; returns the output file's path."""
        self.count += 1
        out = self.tmp / f"{name}.h5"
        args = [self.exe, "run", str(SCENE), "--set", f"output.file='{out}'"]
        for k, v in sets.items():
            args += ["--set", f"{k}={v}"]
        try:
            r = subprocess.run(args, capture_output=True, text=True, timeout=self.timeout)
        except subprocess.TimeoutExpired:
            return None, f"not finished within {self.timeout:g} s of wall time"
        if r.returncode != 0:
            return None, r.stderr.strip().splitlines()[-1] if r.stderr else "failed"
        return out, ""


def base_sets(model, n, rtol, t_end, dt=0.01):
    return {"model.kind": f"'{model}'", "model.elements": n, "solver.rtol": f"{rtol:g}",
            "solver.atol": f"{rtol * 1e-2:g}", "solver.t_end": f"{t_end:.12g}",
            "solver.output_interval": f"{dt:g}",
            # no step budget (the tight references take millions of steps); the runner's
            # wall-clock limit ends a crawl
            "solver.max_steps": "100000000"}


def restart_sets(state_file, t0):
    return {"initial.shape": "'state'", "initial.state_file": f"'{state_file}'",
            "initial.state_time": f"{t0:.12g}"}


def read(path):
    with h5py.File(path, "r") as f:
        d = {"t": f["time"][:], "points": f["rope/points"][:],
             "dissipated": f["energy/dissipated"][:], "cpu": float(f["solver/cpu_time"][()]),
             "steps": int(f["solver/steps"][()]), "model": f.attrs["model"].decode()}
    d["force"] = pin_force(d["points"], d["model"])
    return d


def pin_force(points, model):
    """Elastic axial force at the pin (N): the pin's spring (RFEM: EA/dl times the
    distance of the first element's start from the anchor) or the first member's spring
    (MPP: EA/l times its elongation). The damper's part is left out."""
    n = points.shape[1] // 2
    if model == "rfem":
        dl = L / (n - 1)
        return EA / dl * np.linalg.norm(points[:, 0, :], axis=1)
    l = L / n
    return EA / l * (np.linalg.norm(points[:, 1, :] - points[:, 0, :], axis=1) - l)


def l2(a, b, axis=None):
    """RMS over the output times of the distance between a and b (..., 2)."""
    d = np.linalg.norm(a - b, axis=-1)
    return float(np.sqrt(np.mean(d**2)))


def errors(run, ref):
    m = min(len(run["t"]), len(ref["t"]))
    return {"tip": l2(run["points"][:m, -1], ref["points"][:m, -1]),
            "points": l2(run["points"][:m], ref["points"][:m]),
            "force": float(np.sqrt(np.mean((run["force"][:m] - ref["force"][:m])**2)))}


def write_csv(path, rows):
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)


def read_csv(path):
    if not path.exists():
        return []
    with open(path) as f:
        return list(csv.DictReader(f))


def section(name, command, body, seconds):
    begin, end = f"<!-- accuracy-{name}:begin -->", f"<!-- accuracy-{name}:end -->"
    block = (f"{begin}\n\nCommand: `{command}` ({seconds / 60:.1f} min, {run_stamp()}). "
             f"Machine: {machine()}.\n\n{body}\n\n{end}")
    update_doc(PAGE, begin, end, block, default=PAGE_HEAD)


def loglog_cross(xs, ys, target):
    """x where the piecewise log-log line through (xs, ys) first falls to target."""
    pts = [(x, y) for x, y in zip(xs, ys) if y > 0 and x > 0]
    for (x0, y0), (x1, y1) in zip(pts, pts[1:]):
        if (y0 - target) * (y1 - target) <= 0 and y0 != y1:
            f = (math.log(target) - math.log(y0)) / (math.log(y1) - math.log(y0))
            return math.exp(math.log(x0) + f * (math.log(x1) - math.log(x0)))
    return None


# --------------------------------------------------------------------------------------
# windows

def merged(old, new, cases, methods):
    """The rows of old whose (model, n) is not among cases or whose method is not among
    methods, and new, in the order of a full run: what a run of those cases and methods
    leaves in the CSV file."""
    done = {(m, str(n)) for m, n in cases}
    rows = [r for r in old
            if (r["model"], str(r["n"])) not in done or r["method"] not in methods] + new
    # in the order of a full run: per case, window, method (DEFAULT_METHODS first), rtol
    order = {m: k for k, m in enumerate(dict.fromkeys(DEFAULT_METHODS + list(methods)))}
    return sorted(rows, key=lambda r: (("rfem", "mpp").index(r["model"]), int(r["n"]),
                                       float(r["t0"]), order.get(r["method"], len(order)),
                                       -float(r["rtol"])))


def windows(runner, args):
    q = args.quick
    cases = [("rfem", 10), ("mpp", 10)] if q else \
        [("rfem", 10), ("rfem", 30), ("rfem", 100), ("rfem", 300),
         ("mpp", 10), ("mpp", 30), ("mpp", 100)]
    if args.cases:
        # only these cases; the other cases' rows are kept from the CSV files
        cases = args.cases
    t_end = 6.0 if q else 30.0
    t0s = [0.0, 5.0] if q else [0.0, 5.0, 10.0, 20.0]
    width = 0.5
    rtols = [1e-3, 1e-4, 1e-5] if q else [1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8]
    rows, agreement = [], []
    for model, n in cases:
        # rtol 1e-10 for the references up to n = 30, 1e-9 above (cost); the agreement of
        # the two window references (column ref_agreement of the CSV) is the floor
        ref_rtol = 1e-9 if q or n > 30 else 1e-10
        # the MPP at large n: erk instead of mebdf (MEBDF's dense Newton matrix at rtol 1e-9
        # over 30 s would take hours)
        ref_methods = ["cvode", "erk"] if model == "mpp" and n >= 70 else ["cvode", "mebdf"]
        refs = {}
        for m in ref_methods:
            sets = {**base_sets(model, n, ref_rtol, t_end), **method_sets(m)}
            path, why = runner.run(f"ref_{model}{n}_{m}", sets)
            if path is None:
                sys.exit(f"accuracy: reference {model} n={n} {m} failed: {why}")
            refs[m] = (path, read(path))
        a, b = refs[ref_methods[0]][1], refs[ref_methods[1]][1]
        d = np.max(np.linalg.norm(a["points"] - b["points"], axis=-1), axis=1)
        horizon = a["t"][np.argmax(d > 1e-6)] if np.any(d > 1e-6) else a["t"][-1]
        agreement.append(dict(model=model, n=n, ref_rtol=ref_rtol,
                              methods=" and ".join(ref_methods), horizon=f"{horizon:.3f}",
                              cpu1=f"{a['cpu']:.3g}", cpu2=f"{b['cpu']:.3g}"))
        start_file = refs[ref_methods[0]][0]
        for t0 in t0s:
            if t0 + width > t_end + 1e-9:
                continue
            wref = {}
            for m in ref_methods:
                sets = {**base_sets(model, n, ref_rtol, t0 + width), **method_sets(m),
                        **restart_sets(start_file, t0)}
                path, why = runner.run(f"wref_{model}{n}_{t0}_{m}", sets)
                wref[m] = read(path)
            wagree = errors(wref[ref_methods[0]], wref[ref_methods[1]])["points"]
            for m in args.methods:
                other = ref_methods[1] if m.split(":")[0] == ref_methods[0] else ref_methods[0]
                for rtol in rtols:
                    sets = {**base_sets(model, n, rtol, t0 + width), **method_sets(m),
                            **restart_sets(start_file, t0)}
                    path, why = runner.run(f"w_{model}{n}_{t0}_{m}_{rtol}", sets)
                    row = dict(model=model, n=n, t0=t0, method=m, rtol=rtol,
                               ref_agreement=f"{wagree:.2e}")
                    if path is None:
                        row.update(tip="", points="", force="", cpu="", steps="",
                                   status=why[:80])
                    else:
                        r = read(path)
                        e = errors(r, wref[other])
                        row.update(tip=f"{e['tip']:.3e}", points=f"{e['points']:.3e}",
                                   force=f"{e['force']:.3e}", cpu=f"{r['cpu']:.4g}",
                                   steps=r["steps"], status="ok")
                    rows.append(row)
                    print(f"windows: {row}", flush=True)
    subset = not q and set(args.methods) != set(DEFAULT_METHODS)
    if args.cases or subset:
        # merged into the CSV files: rows of the cases and methods run here are replaced,
        # the others kept (the references are rerun with each case: their methods' code
        # is the same, so are they)
        rows = merged(read_csv(DATA / "acc_windows.csv"), rows, cases, args.methods)
        done = {(m, str(n)) for m, n in cases}
        agreement = [r for r in read_csv(DATA / "acc_windows_refs.csv")
                     if (r["model"], str(r["n"])) not in done] + agreement
    order = {("rfem", 0): 0, ("mpp", 0): 1}
    key = lambda r: (order[(r["model"], 0)], int(r["n"]))  # noqa: E731
    rows.sort(key=key)
    agreement.sort(key=key)
    write_csv(DATA / "acc_windows.csv", rows)
    write_csv(DATA / "acc_windows_refs.csv", agreement)
    figure_windows(rows)
    note = (f" Rows of {', '.join(args.methods)} from this run; the other methods' rows from "
            "the CSV file of the previous full run (their code is unchanged when this is "
            "used: to remeasure a changed method)." if subset else "")
    return windows_section(rows, agreement, t_end, t0s, width, rtols, note)


def windows_section(rows, agreement, t_end, t0s, width, rtols, note=""):
    """The section 'windows' of the page from the rows of the CSV files."""
    md = [f"References to {t_end:g} s at rtol 1e-10 (n <= 30; 1e-9 above) with two methods "
          "(cvode and mebdf; cvode and erk for the MPP at n >= 70); windows of "
          f"{width} s from t0 = {', '.join(f'{t:g}' for t in t0s)} s, each measured against "
          "a tight window reference restarted from the same record with the other "
          "reference method. Raw data: [data/acc_windows.csv](../data/acc_windows.csv), "
          "[data/acc_windows_refs.csv](../data/acc_windows_refs.csv)." + note, "",
          "**References** (horizon: last time the two agree within 1e-6 m at every point; "
          "after it they are two different, equally valid motions, which is why the windows "
          "restart from one of them)", "",
          "| model | n | rtol | methods | horizon (s) | CPU ref 1 (s) | CPU ref 2 (s) |",
          "|---|---|---|---|---|---|---|"]
    md += [f"| {r['model']} | {r['n']} | {float(r['ref_rtol']):g} | {r['methods']} | "
           f"{float(r['horizon']):.2f} | {r['cpu1']} | {r['cpu2']} |" for r in agreement]
    md += ["", "**Per window** (tip L2 error m / all points m / pin force N / CPU s), median "
           "over the windows t0; the full table per t0 is in the CSV:", ""]
    md += window_table(rows, rtols)
    md += ["", "![windowed accuracy against CPU](../figures/acc_windows.png)"]
    return "\n".join(md)


def window_table(rows, rtols):
    found = dict.fromkeys(r["method"] for r in rows)
    methods = [m for m in DEFAULT_METHODS if m in found] + \
        [m for m in found if m not in DEFAULT_METHODS]
    out = ["| model, n, rtol | " + " | ".join(methods) + " |",
           "|---|" + "---|" * len(methods)]
    keys = list(dict.fromkeys((r["model"], int(r["n"])) for r in rows))
    for model, n in keys:
        for rtol in rtols:
            cells = []
            for m in methods:
                sel = [r for r in rows if r["model"] == model and int(r["n"]) == n and
                       r["method"] == m and float(r["rtol"]) == rtol and r["status"] == "ok"]
                if not sel:
                    cells.append("failed")
                    continue
                med = {k: float(np.median([float(r[k]) for r in sel]))
                       for k in ("tip", "points", "force", "cpu")}
                cells.append(f"{med['tip']:.1e} / {med['points']:.1e} / {med['force']:.1e} / "
                             f"{med['cpu']:.3g}")
            out.append(f"| {model}, {n}, {rtol:g} | " + " | ".join(cells) + " |")
    return out


def window_medians(win, model, n, method):
    """{rtol: (median tip error, median CPU)} over the windows t0 of one model, n and
    method (completed runs only), loosest rtol first."""
    sel = [r for r in win if r["model"] == model and int(r["n"]) == n and
           r["method"] == method and r["status"] == "ok"]
    out = {}
    for rtol in sorted(set(float(r["rtol"]) for r in sel), reverse=True):
        rs = [r for r in sel if float(r["rtol"]) == rtol]
        out[rtol] = (float(np.median([float(r["tip"]) for r in rs])),
                     float(np.median([float(r["cpu"]) for r in rs])))
    return out


def figure_windows(rows):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    models = list(dict.fromkeys(r["model"] for r in rows))
    fig, axes = plt.subplots(1, len(models), figsize=(6 * len(models), 4.5), squeeze=False)
    for ax, model in zip(axes[0], models):
        for (n, m) in dict.fromkeys((int(r["n"]), r["method"]) for r in rows
                                    if r["model"] == model):
            med = window_medians(rows, model, n, m)
            ax.loglog([c for _, c in med.values()], [e for e, _ in med.values()], "o-",
                      label=f"n={n} {m}")
        ax.set_xlabel("CPU per 0.5 s window (s)")
        ax.set_ylabel("tip L2 error (m)")
        ax.set_title(model)
        ax.legend(fontsize=7)
        ax.grid(True, which="both", alpha=0.3)
    FIGURES.mkdir(parents=True, exist_ok=True)
    fig.tight_layout()
    fig.savefig(FIGURES / "acc_windows.png", dpi=90)
    plt.close(fig)


# --------------------------------------------------------------------------------------
# discretization

def discretization(runner, args):
    q = args.quick
    ns = [3, 5, 10, 30] if q else [3, 5, 10, 20, 30, 50, 100, 200, 300]
    fine = {"rfem": 100 if q else 1000, "mpp": 90 if q else 300}
    rtols = [1e-3, 1e-4, 1e-5] if q else [1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7]
    t_end, tight = 1.0, 1e-9
    rows = []
    for model in ("rfem", "mpp"):
        path, why = runner.run(f"fine_{model}", base_sets(model, fine[model], tight, t_end))
        if path is None:
            sys.exit(f"accuracy: fine reference {model} failed: {why}")
        ref = read(path)
        for n in ns:
            if n >= fine[model]:
                continue
            path, why = runner.run(f"d_{model}{n}", base_sets(model, n, tight, t_end))
            tightrun = read(path)
            disc = l2(tightrun["points"][:, -1], ref["points"][:, -1])
            row = dict(model=model, n=n, disc_tip=f"{disc:.3e}", cpu_tight=tightrun["cpu"])
            for rtol in rtols:
                path, why = runner.run(f"d_{model}{n}_{rtol}", base_sets(model, n, rtol, t_end))
                if path is None:
                    row[f"time_{rtol:g}"] = ""
                    continue
                r = read(path)
                row[f"time_{rtol:g}"] = f"{l2(r['points'][:, -1], tightrun['points'][:, -1]):.3e}"
            rows.append(row)
            print(f"discretization: {row}", flush=True)
    write_csv(DATA / "acc_discretization.csv", rows)
    md = [f"Tip position over [0, {t_end:g}] s (L2 in time) at n against a fine reference "
          f"(RFEM n = {fine['rfem']}, MPP n = {fine['mpp']}; rtol {tight:g}, CVODE): the "
          "discretization error. Time error: the same n at rtol r against its own rtol "
          f"{tight:g} run. Raw data: [data/acc_discretization.csv](../data/acc_discretization.csv).",
          "", "| model | n | discretization (m) | " +
          " | ".join(f"time error at {r:g}" for r in rtols) + " | rtol matching |",
          "|---|---|---|" + "---|" * len(rtols) + "---|"]
    for row in rows:
        te = [float(row[f"time_{r:g}"]) if row[f"time_{r:g}"] else float("nan") for r in rtols]
        match = loglog_cross(rtols, te, float(row["disc_tip"]))
        md.append(f"| {row['model']} | {row['n']} | {float(row['disc_tip']):.1e} | " +
                  " | ".join(f"{x:.1e}" for x in te) + " | " +
                  (f"{match:.0e}" if match else ("looser" if te[0] < float(row["disc_tip"])
                                                 else "tighter")) + " |")
    md += ["", "**n needed for a tip accuracy** (log-log interpolation of the discretization "
           "error; '>': not reached by the largest n; '<=': reached by the smallest):", "",
           "| accuracy (m) | RFEM n | MPP n |", "|---|---|---|"]
    for target in (1e-1, 3e-2, 1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5):
        cells = []
        for model in ("rfem", "mpp"):
            sel = [r for r in rows if r["model"] == model]
            x = loglog_cross([int(r["n"]) for r in sel], [float(r["disc_tip"]) for r in sel],
                             target)
            if not sel:
                cells.append("-")
            elif float(sel[0]["disc_tip"]) <= target:
                cells.append(f"<= {sel[0]['n']}")
            else:
                cells.append(f"{x:.0f}" if x else f"> {sel[-1]['n']}")
        md.append(f"| {target:g} | " + " | ".join(cells) + " |")
    return "\n".join(md)


# --------------------------------------------------------------------------------------
# chaos

def chaos(runner, args):
    q = args.quick
    model, n = "rfem", 10 if q else 30
    t1, t_end = (5.0, 10.0) if q else (5.0, 30.0)
    starts = 3 if q else 8
    rtols = [1e-4, 1e-6] if q else [1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8]
    if args.render:
        rows = read_csv(DATA / "acc_chaos.csv")
    else:
        rows = []
        for m in args.methods[:1] if q else args.methods:
            for rtol in rtols:
                rates, cpus = [], []
                for k in range(starts):
                    angle = 75.0 + math.degrees(k * 1e-9)
                    sets = {**base_sets(model, n, rtol, t_end, dt=0.05), **method_sets(m),
                            "initial.angle_deg": f"{angle:.15f}"}
                    path, why = runner.run(f"c_{m}_{rtol}_{k}", sets)
                    if path is None:
                        continue
                    r = read(path)
                    i1 = int(np.argmin(abs(r["t"] - t1)))
                    rates.append((r["dissipated"][-1] - r["dissipated"][i1]) /
                                 (r["t"][-1] - r["t"][i1]))
                    cpus.append(r["cpu"])
                if rates:
                    rows.append(dict(method=m, rtol=rtol, starts=len(rates),
                                     mean=f"{np.mean(rates):.6e}", spread=f"{np.std(rates):.3e}",
                                     cpu=f"{np.mean(cpus):.4g}"))
                    print(f"chaos: {rows[-1]}", flush=True)
        if not q and set(args.methods) != set(DEFAULT_METHODS):
            # some methods only: the other methods' rows kept from the CSV
            kept = [r for r in read_csv(DATA / "acc_chaos.csv")
                    if r["method"] not in args.methods]
            order = {m: k for k, m in enumerate(dict.fromkeys(
                DEFAULT_METHODS + [r["method"] for r in kept + rows]))}
            rows = sorted(kept + rows, key=lambda r: (order[r["method"]], -float(r["rtol"])))
        write_csv(DATA / "acc_chaos.csv", rows)
    best = min(rows, key=lambda r: float(r["rtol"]))

    zs = dict(zip((id(r) for r in rows), chaos_z(rows)))

    def z(r):
        return zs[id(r)]

    allmeans = [float(r["mean"]) for r in rows]
    md = [f"{model.upper()} n = {n}: mean dissipation rate (W) over [{t1:g}, {t_end:g}] s for "
          f"{starts} starts at 75 degrees + k 1e-9 rad (k = 0 .. {starts - 1}); per method and "
          "rtol its ensemble mean and spread (standard deviation over the starts). The "
          "starts part after about 3 s (section windows), so each ensemble samples the "
          "chaotic phase; a mean is only known to its standard error (spread / sqrt(starts "
          "- 1)). 'reproduces': the mean differs from the tightest ensemble's "
          f"({best['method']}, rtol {float(best['rtol']):g}) by less than twice the standard "
          "error of the difference (z < 2; 1 in 20 ensembles fails that by chance). Raw "
          "data: [data/acc_chaos.csv](../data/acc_chaos.csv).", "",
          "| method | rtol | mean rate (W) | spread (W) | z | reproduces | CPU per run (s) |",
          "|---|---|---|---|---|---|---|"]
    for r in rows:
        md.append(f"| {r['method']} | {float(r['rtol']):g} | {float(r['mean']):.5e} | "
                  f"{float(r['spread']):.2e} | {z(r):.1f} | {'yes' if z(r) < 2 else 'no'} | "
                  f"{r['cpu']} |")
    ok = [r for r in rows if z(r) < 2]
    cheapest = min(ok, key=lambda r: float(r["cpu"])) if ok else None
    md += ["", f"Over all {len(rows)} ensembles the means lie in "
           f"[{min(allmeans):.3e}, {max(allmeans):.3e}] W (mean {np.mean(allmeans):.4e}, "
           f"standard deviation {np.std(allmeans):.2e}, against a typical standard error of "
           f"one ensemble's mean of {np.median([chaos_stderr(r) for r in rows]):.2e}); "
           f"{len(ok)} of {len(rows)} reproduce the tightest ensemble."]
    if cheapest:
        md[-1] += (f" The cheapest that does: {cheapest['method']} at rtol "
                   f"{float(cheapest['rtol']):g}, {cheapest['cpu']} s CPU per 30 s run.")
    return "\n".join(md)


def chaos_stderr(r):
    """Standard error of an ensemble's mean (from its population standard deviation)."""
    k = int(r["starts"])
    return float(r["spread"]) * math.sqrt(k / max(k - 1, 1)) / math.sqrt(k)


def chaos_z(rows):
    """|mean - mean of the tightest ensemble| / standard error of the difference, per row."""
    best = min(rows, key=lambda r: float(r["rtol"]))
    return [abs(float(r["mean"]) - float(best["mean"])) /
            max(math.hypot(chaos_stderr(r), chaos_stderr(best)), 1e-300) for r in rows]


# --------------------------------------------------------------------------------------
# fig4

def fig4(runner, args):
    q = args.quick
    ns = [2, 5, 10] if q else [2, 3, 5, 10, 20, 30, 50, 70, 100, 200, 300]
    # the MPP with the implicit methods up to n = 70: their dense O(n^3) Newton matrix
    # makes a 30 s run at n = 300 take some 20 min per method; the explicit ones (and auto,
    # which runs them on this rope) to n = 300
    mpp_max = 10 if q else 70
    explicit = ("erk", "adams", "auto")
    t_end = 3.0 if q else 30.0
    win = read_csv(DATA / "acc_windows.csv")
    rows = []
    for target in FIG4_TARGETS:
        for model in ("rfem", "mpp"):
            for m in args.methods:
                rtol = chosen_rtol(win, model, m, target) or args.fig4_rtol
                for n in ns:
                    if model == "mpp" and n > mpp_max and m.split(":")[0] not in explicit:
                        continue
                    sets = {**base_sets(model, n, rtol, t_end, dt=0.05), **method_sets(m)}
                    path, why = runner.run(f"f4_{model}{n}_{m}_{rtol}", sets)
                    row = dict(target=target, model=model, method=m, n=n, rtol=rtol, cpu="",
                               steps="", status="ok")
                    if path is None:
                        row["status"] = why[:80]
                    else:
                        r = read(path)
                        row.update(cpu=f"{r['cpu']:.4g}", steps=r["steps"])
                    rows.append(row)
                    print(f"fig4: {row}", flush=True)
    methods = list(args.methods)
    if not q and methods != DEFAULT_METHODS:
        # only these methods: the other methods' rows are kept from the CSV file
        methods = list(dict.fromkeys(DEFAULT_METHODS + methods))
        kept = [dict(r, target=float(r["target"]), n=int(r["n"]), rtol=float(r["rtol"]))
                for r in read_csv(DATA / "acc_fig4.csv") if r["method"] not in args.methods]
        order = {m: k for k, m in enumerate(methods)}
        rows = sorted(kept + rows, key=lambda r: (FIG4_TARGETS.index(r["target"]),
                                                  ("rfem", "mpp").index(r["model"]),
                                                  order[r["method"]], r["n"]))
    write_csv(DATA / "acc_fig4.csv", rows)
    figure_fig4(rows, t_end)
    md = [f"CPU time of the whole motion ({t_end:g} s, output every 0.05 s) against n, each "
          "method at the loosest rtol whose windowed tip error (section 'windows', median "
          "over the windows, at its largest n) is below the target: 1e-3 m (about the "
          "discretization error at n = 30) and 1e-5 m (below it at every n up to 300); "
          f"else rtol {args.fig4_rtol:g}. The MPP with the implicit methods only up to n = "
          f"{mpp_max} ('-': not run; their dense O(n³) Newton matrix makes a 30 s run at n = "
          "300 take some 20 min each). Raw data: [data/acc_fig4.csv](../data/acc_fig4.csv).",
          "", "![Figure 4 over the whole motion](../figures/acc_fig4.png)"]
    if methods != list(args.methods):
        md[0] += (f" Rows of {', '.join(args.methods)} from this run (the rtol chosen from "
                  "the windows data as it stands); the other methods' rows from the CSV file "
                  "of the previous full run.")
    for target in FIG4_TARGETS:
        sel = [r for r in rows if float(r["target"]) == target]
        md += ["", f"**Target {target:g} m**", "",
               "| model, method (rtol) | " + " | ".join(f"n = {n}" for n in ns) + " |",
               "|---|" + "---|" * len(ns)]
        for key in dict.fromkeys((r["model"], r["method"], r["rtol"]) for r in sel):
            cells = []
            for n in ns:
                c = [r for r in sel if (r["model"], r["method"], r["rtol"]) == key and
                     r["n"] == n]
                cells.append(c[0]["cpu"] if c and c[0]["status"] == "ok" else
                             ("failed" if c else "-"))
            md.append(f"| {key[0]}, {key[1]} ({key[2]:g}) | " + " | ".join(cells) + " |")
        # the paper: "the MPP model is numerically more efficient only for small n"
        cross = []
        for m in methods:
            cheaper = [n for n in ns if mpp_cheaper(sel, m, n)]
            dearer = [n for n in ns if mpp_cheaper(sel, m, n) is False]
            cross.append(f"{m}: MPP cheaper at n = {cheaper or 'none'}, RFEM at "
                         f"n = {dearer or 'none'}")
        md += ["", "The paper (section 4, Fig. 4, MEBDF, 30 s, n up to about 100): \"in most "
               "cases the RFEM approach leads to considerably shorter time of calculations. "
               "The MPP model is numerically more efficient only for small n.\" Measured at "
               f"{target:g} m: " + "; ".join(cross) + "."]
    return "\n".join(md)


#: the tip accuracies (m) at which fig4 compares the methods
FIG4_TARGETS = (1e-3, 1e-5)


def mpp_cheaper(rows, m, n):
    c = {r["model"]: float(r["cpu"]) for r in rows if r["method"] == m and r["n"] == n and
         r["status"] == "ok" and r["cpu"]}
    if "rfem" in c and "mpp" in c:
        return c["mpp"] < c["rfem"]
    return None


def chosen_rtol(win, model, method, target):
    sel = [r for r in win if r["model"] == model and r["method"] == method and r["status"] == "ok"]
    if not sel:
        return None
    nmax = max(int(r["n"]) for r in sel)
    good = [rtol for rtol, (tip, _) in window_medians(win, model, nmax, method).items()
            if tip < target]
    return max(good) if good else None


def figure_fig4(rows, t_end):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    targets = list(dict.fromkeys(float(r["target"]) for r in rows))
    fig, axes = plt.subplots(1, len(targets), figsize=(7 * len(targets), 5), squeeze=False)
    for ax, target in zip(axes[0], targets):
        sel = [r for r in rows if float(r["target"]) == target and r["status"] == "ok"]
        for key in dict.fromkeys((r["model"], r["method"]) for r in sel):
            ks = [r for r in sel if (r["model"], r["method"]) == key]
            ax.loglog([int(r["n"]) for r in ks], [float(r["cpu"]) for r in ks],
                      "o-" if key[0] == "rfem" else "s--", label=f"{key[0]} {key[1]}")
        ax.set_xlabel("n")
        ax.set_ylabel(f"CPU time of {t_end:g} s of motion (s)")
        ax.set_title(f"tip accuracy {target:g} m")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7, ncol=2)
    FIGURES.mkdir(parents=True, exist_ok=True)
    fig.tight_layout()
    fig.savefig(FIGURES / "acc_fig4.png", dpi=90)
    plt.close(fig)


# --------------------------------------------------------------------------------------
# choosing

#: the generated section of the guide's page on choosing a method (docs/guide/choosing.md)
CHOOSING_BEGIN, CHOOSING_END = "<!-- choosing:begin -->", "<!-- choosing:end -->"


#: the page whose table (written by scripts/bench_symplectic) gives the symplectic method's
#: largest energy error over 300 s
ENERGY_PAGE = DOCS / "validation" / "energy.md"


def symplectic_bound(page=ENERGY_PAGE):
    """The largest |T + V - E0| up to the end (m g L) of the symplectic rows of the
    symplectic-targets table on `page`, as text ("1.1e-04"); None without that table."""
    try:
        text = page.read_text()
    except OSError:
        return None
    begin, end = "<!-- symplectic-targets:begin -->", "<!-- symplectic-targets:end -->"
    if begin not in text or end not in text:
        return None
    block = text.split(begin, 1)[1].split(end, 1)[0]
    header, values = None, []
    for line in block.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if "max abs to the end" in cells:
            header = cells
        elif header and len(cells) == len(header) and cells[1] == "symplectic":
            values.append(float(cells[header.index("max abs to the end")]))
    return f"{max(values):.1e}" if values else None


def long_runs(chaos_rows=()):
    """The guide's item on long runs and energy statistics: the symplectic method
    (docs/theory/symplectic.md; its bound from docs/validation/energy.md, its chaos
    statistics from the chaos study's rows)."""
    bound = symplectic_bound()
    within = (f"within {bound} m g L over 300 s at n = 20 and 100 at rtol 1e-3"
              if bound else "bounded over 300 s at n = 20 and 100 at rtol 1e-3")
    zs = [z for r, z in zip(chaos_rows, chaos_z(chaos_rows) if chaos_rows else [])
          if r["method"] == "symplectic"]
    statistics = (f"its statistics of the chaotic phase reproduce the tightest ensemble at "
                  f"{sum(z < 2 for z in zs)} of {len(zs)} tolerances (z < 2, which 1 in 20 "
                  "ensembles misses by chance)" if zs else
                  "its statistics of the chaotic phase are in the chaos study")
    return (
        "- **Long runs of lightly damped ropes** (statistics of energy, dissipation, spectra "
        "or peak loads over tens of seconds): the adaptive methods' energy balance drifts "
        "(the undamped rope, n = 20, rtol 1e-3: erk loses about a tenth of m g L in 30 s and "
        "more by 300 s), which biases those statistics. Where the fast modes are damped by "
        "less than 1 %, `auto` takes the symplectic method, whose balance error stays bounded "
        f"({within}, at less than erk's "
        f"CPU; a tighter rtol shortens its step for a smaller error); {statistics}. Its "
        "fixed steps over hundreds of seconds fit the default step budget, which grows with "
        "`t_end`; a `max_steps` you give that they outnumber makes auto go on without it, "
        "with a warning that names the budget it needs ([the step "
        "budget](#tolerances-rtol-atol)). Name "
        "`method = 'symplectic'` to have it on any RFEM scene without water, ground contact "
        "or point masses off an element's centre "
        "(not the MPP: [theory/symplectic.md](../theory/symplectic.md); the energy of every "
        "method over 300 s: [energy over long runs](../validation/energy.md)).")


def oldest_input(page=PAGE, names=None):
    """The stamp ('YYYY-MM-DD HH:MM UTC, commit `abc1234`') of the oldest of the accuracy
    page's sections `names`, whose data the choosing section reads, and that section's
    name; (None, None) when one has no stamp with a time and a commit. The choosing section
    is as current as its oldest input, not as its last run: rerunning one subcommand leaves
    the others' data as they were. The stamps are read as scripts/docs_status reads them."""
    found = {name: (stamp, commit) for name, _, stamp, commit in docs_status.sections(page)}
    stamps = []
    for name in names or STUDIES:
        stamp, commit = found.get(f"accuracy-{name}", (None, None))
        if not stamp or not commit or " " not in stamp:
            return None, None
        stamps.append((docs_status.run_time(stamp), f"{stamp}, commit `{commit}`", name))
    _, stamp, name = min(stamps)
    return stamp, name


def choosing(args):
    win = read_csv(DATA / "acc_windows.csv")
    disc = read_csv(DATA / "acc_discretization.csv")
    f4 = read_csv(DATA / "acc_fig4.csv")
    chaos_rows = read_csv(DATA / "acc_chaos.csv")
    md = headline(win, disc, f4, chaos_rows)
    md += ["", "### 1. Pick n for the accuracy you need in space", "",
           "Discretization error of the tip over the first second against a fine reference "
           "([accuracy](../validation/accuracy.md#discretization)):", ""]
    if disc:
        ns = list(dict.fromkeys(int(r["n"]) for r in disc))
        md += ["| model | " + " | ".join(f"n = {n}" for n in ns) + " |",
               "|---|" + "---|" * len(ns)]
        for model in ("rfem", "mpp"):
            cells = []
            for n in ns:
                c = [r for r in disc if r["model"] == model and int(r["n"]) == n]
                cells.append(f"{float(c[0]['disc_tip']):.1e} m" if c else "-")
            md.append(f"| {model} | " + " | ".join(cells) + " |")
    else:
        md.append("(no data yet: run `scripts/accuracy discretization`)")
    md += ["", "### 2. Pick rtol so that the time error stays below that", "",
           "Time error of the tip over the first second at each rtol (CVODE, against its "
           "own rtol 1e-9 run); tighter than the discretization error buys nothing, looser "
           "spoils the n you paid for ([accuracy](../validation/accuracy.md#discretization)).", ""]
    if disc:
        rt = [k for k in disc[0] if k.startswith("time_")]
        md += ["| model, n | discretization | " + " | ".join(f"rtol {k[5:]}" for k in rt) +
               " |", "|---|---|" + "---|" * len(rt)]
        for r in disc:
            md.append(f"| {r['model']}, {r['n']} | {float(r['disc_tip']):.1e} | " +
                      " | ".join(f"{float(r[k]):.1e}" if r[k] else "-" for k in rt) + " |")
    md += ["", "### 3. Pick the method that is cheapest at that accuracy", "",
           "Windows of 0.5 s across the whole motion (restarted from t0 = 0, 5, 10, 20 s), "
           "median CPU per window at the loosest rtol reaching the accuracy "
           "([accuracy](../validation/accuracy.md#windows)):", ""]
    if win:
        md += ["| model | n | tip accuracy (m) | cheapest method (rtol): CPU per window (s) | "
               "runner-up | auto (rtol): CPU |", "|---|---|---|---|---|---|"]
        for model, n in dict.fromkeys((r["model"], int(r["n"])) for r in win):
            for target in (1e-3, 1e-5, 1e-7):
                best = cheapest_in_windows(win, model, n, target)
                cell = lambda b: f"{b[1]} ({b[2]:g}): {b[0]:.3g}" if b else "-"
                au = [b for b in best if b[1] == "auto"]
                md.append(f"| {model} | {n} | {target:g} | {cell(best[0] if best else None)} | "
                          f"{cell(best[1] if len(best) > 1 else None)} | "
                          f"{cell(au[0] if au else None)} |")
        md += ["", "Why the windows go beyond the first seconds: at the same rtol, the windows "
               "after the fold (t0 = 5, 10, 20 s) have larger errors than the first one (t0 = "
               "0), by these factors (median and 90th percentile over models, n and rtol): " +
               "; ".join(f"{m} {a:.1f} ({b:.0f})" for m, a, b in later_over_first(win)) +
               ". A study of the first seconds alone ([over 2 s](../validation/work-precision.md))"
               " understates the error of the whole motion by that much."]
    else:
        md.append("(no data yet: run `scripts/accuracy windows`)")
    md += ["", "### 4. What the whole motion costs", "",
           "CPU of the whole 30 s run at the loosest rtol reaching the tip accuracy in the "
           "windows (the paper's Figure 4 over the whole motion, "
           "[accuracy](../validation/accuracy.md#fig4)): the cheapest method, and the default auto:", ""]
    if f4:
        for target in dict.fromkeys(float(r["target"]) for r in f4):
            sel = [r for r in f4 if float(r["target"]) == target and r["status"] == "ok"
                   and r["cpu"]]
            md += [f"**Tip accuracy {target:g} m**", "",
                   "| model | n | cheapest method (rtol): CPU (s) | auto (rtol): CPU (s) | "
                   "auto / cheapest |", "|---|---|---|---|---|"]
            for model in ("rfem", "mpp"):
                for n in dict.fromkeys(int(r["n"]) for r in sel if r["model"] == model):
                    c = sorted((float(r["cpu"]), r["method"], float(r["rtol"])) for r in sel
                               if r["model"] == model and int(r["n"]) == n)
                    au = [x for x in c if x[1] == "auto"]
                    md.append(f"| {model} | {n} | {c[0][1]} ({c[0][2]:g}): {c[0][0]:.3g} | " +
                              (f"{au[0][2]:g}: {au[0][0]:.3g} | {au[0][0] / c[0][0]:.2f} |"
                               if au else "- | - |"))
            md.append("")
    else:
        md.append("(no data yet: run `scripts/accuracy fig4`)")
    stamp, oldest = oldest_input()
    as_of = (f"{stamp} (its oldest input, the {oldest} section)" if stamp else
             f"{run_stamp()} (a section of the accuracy page has no stamp)")
    block = "\n".join([CHOOSING_BEGIN, "",
                        "Written by `scripts/accuracy choosing` from the data of the other "
                        "subcommands ([accuracy](../validation/accuracy.md)), data as of "
                        f"{as_of}. Scene: the paper's rope (`input/paper.nml`).", "",
                        *md, CHOOSING_END])
    update_doc(CHOOSING, CHOOSING_BEGIN, CHOOSING_END, block)
    print(f"accuracy: wrote {CHOOSING}")


def later_over_first(win):
    """Per method: median and 90th percentile, over (model, n, rtol), of the median tip
    error of the windows at t0 > 0 over that of the window at t0 = 0."""
    out = []
    for m in dict.fromkeys(r["method"] for r in win):
        ratios = []
        for key in dict.fromkeys((r["model"], r["n"], r["rtol"]) for r in win
                                 if r["method"] == m):
            sel = {float(r["t0"]): float(r["tip"]) for r in win if r["method"] == m and
                   r["status"] == "ok" and (r["model"], r["n"], r["rtol"]) == key}
            later = [v for t, v in sel.items() if t > 0]
            if sel.get(0.0, 0.0) > 0 and later:
                ratios.append(float(np.median(later)) / sel[0.0])
        if ratios:
            out.append((m, float(np.median(ratios)), float(np.percentile(ratios, 90))))
    return out


def cheapest_in_windows(win, model, n, target):
    """[(median CPU per window, method, rtol)] of every method at its loosest rtol whose
    median windowed tip error is below target, cheapest first."""
    best = []
    for m in dict.fromkeys(r["method"] for r in win):
        opts = [(cpu, rtol) for rtol, (tip, cpu) in window_medians(win, model, n, m).items()
                if tip < target]
        if opts:
            cpu, rtol = min(opts)
            best.append((cpu, m, rtol))
    return sorted(best)


def headline(win, disc, f4, chaos_rows):
    """The answer in a few lines, from the data of the studies."""
    md = ["### In short", ""]
    if not (win and disc and f4):
        return md + ["(run `scripts/accuracy all` for the data)"]
    lines = []
    for model, n in (("rfem", 10), ("rfem", 30), ("rfem", 100), ("mpp", 30)):
        d = [r for r in disc if r["model"] == model and int(r["n"]) == n]
        if not d:
            continue
        e = float(d[0]["disc_tip"])
        # the loosest rtol at which auto's windowed tip error is below a tenth of it
        ok = [rt for rt, (tip, _) in window_medians(win, model, n, "auto").items()
              if tip < e / 10]
        runs = [r for r in f4 if r["model"] == model and int(r["n"]) == n and
                r["status"] == "ok" and r["cpu"]]
        au = [r for r in runs if r["method"] == "auto"]
        if not (ok and au):
            continue
        cheapest = min(runs, key=lambda r: float(r["cpu"]))
        a = min(au, key=lambda r: float(r["cpu"]))
        lines.append(f"- **{model.upper()}, n = {n}**: tip accurate to {e:.0e} m in space; the "
                     f"default `auto` already at rtol {ok[0]:g} keeps the time error below a "
                     f"tenth of that over the whole motion; 30 s cost {float(a['cpu']):.2g} s "
                     f"CPU (cheapest fixed method: {cheapest['method']} at rtol "
                     f"{float(cheapest['rtol']):g}, {float(cheapest['cpu']):.2g} s).")
    md += lines
    if chaos_rows:
        zs = chaos_z(chaos_rows)
        loose = [r for r, z in zip(chaos_rows, zs) if float(r["rtol"]) >= 1e-3]
        loose_ok = [r for r, z in zip(chaos_rows, zs) if float(r["rtol"]) >= 1e-3 and z < 2]
        md += [f"- **Statistics of the chaotic phase** (mean dissipation rate over 5-30 s, "
               f"RFEM n = 30, 8 starts 1e-9 rad apart): {sum(z < 2 for z in zs)} of "
               f"{len(zs)} ensembles (methods x rtol) reproduce the tightest within sampling "
               f"error, {len(loose_ok)} of {len(loose)} at rtol 1e-3 "
               "([accuracy](../validation/accuracy.md#chaos)): a loose tolerance is enough for them."]
    # where the default is far off the cheapest fixed method over the whole motion
    misses = []
    for r in f4:
        if r["method"] != "auto":
            continue
        others = [float(o["cpu"]) for o in f4 if o["target"] == r["target"] and
                  o["model"] == r["model"] and o["n"] == r["n"] and o["status"] == "ok"
                  and o["cpu"] and o["method"] != "auto"]
        if not others:
            continue
        if r["status"] != "ok" or not r["cpu"]:
            misses.append(f"{r['model'].upper()} n = {r['n']} (target {float(r['target']):g} "
                          f"m: {r['status']})")
        elif float(r["cpu"]) > 2 * min(others):
            misses.append(f"{r['model'].upper()} n = {r['n']} (target {float(r['target']):g} "
                          f"m: {float(r['cpu']) / min(others):.0f}x)")
    if misses:
        md += ["- **Where the default is not the right choice**: auto costs more than twice "
               "the cheapest fixed method over the whole motion at " + "; ".join(misses) +
               "."]
    md += [long_runs(chaos_rows)]
    # is rtol 1e-3 with auto below the discretization error everywhere measured?
    below = []
    for model, n in dict.fromkeys((r["model"], int(r["n"])) for r in win):
        d = [r for r in disc if r["model"] == model and int(r["n"]) == n]
        w = window_medians(win, model, n, "auto").get(1e-3)
        if d and w:
            below.append((model, n, w[0] < float(d[0]["disc_tip"])))
    if below:
        good = [f"{m.upper()} n = {n}" for m, n, b in below if b]
        bad = [f"{m.upper()} n = {n}" for m, n, b in below if not b]
        md += ["- **So**: choose n for the accuracy in space (section 1) and keep the default "
               "method" + (" (but for the cases just listed)" if misses else "") + "; at rtol 1e-3 its windowed time error is below the discretization "
               f"error at {', '.join(good) or 'none'}" +
               (f" (not at {', '.join(bad)})" if bad else "") + ", at the default 1e-6 far "
               "below; tighten rtol only to follow one trajectory past the fold, which no rtol "
               "does for long (two tight integrations part after about 3 s)."]
    return md


# --------------------------------------------------------------------------------------

#: every method the executable has: CVODE BDF at orders 5 and 2, Adams, the explicit pair,
#: MEBDF at orders 4 (A-stable, its default) and 7, and auto (the default)
DEFAULT_METHODS = ["cvode", "cvode:2", "adams", "erk", "mebdf:4", "mebdf:7", "auto"]

STUDIES = {"windows": windows, "discretization": discretization, "chaos": chaos, "fig4": fig4}


def model_cases(text):
    """--cases: 'model:n,...' -> [(model, n)], model rfem or mpp, n >= 2."""
    cases = []
    for item in text.split(","):
        model, _, n = item.strip().partition(":")
        if model not in ("rfem", "mpp") or not n.isdigit() or int(n) < 2:
            raise argparse.ArgumentTypeError(
                f"'{item}': expected model:n with model rfem or mpp and n >= 2 (e.g. mpp:100)")
        cases.append((model, int(n)))
    return cases


def main(argv=None):
    parser = argparse.ArgumentParser(description=summary(__doc__))
    parser.add_argument("study", choices=[*STUDIES, "choosing", "all"])
    add_exe_argument(parser)
    parser.add_argument("--quick", action="store_true", help="smoke test: small n, short")
    parser.add_argument("--methods", default=",".join(DEFAULT_METHODS), type=method_specs(","),
                        help="comma list of method[:max_order] (any &solver method)")
    parser.add_argument("--cases", default=[], type=model_cases,
                        help="windows: only these model:n (comma list, e.g. mpp:100), merged "
                        "into the CSVs")
    parser.add_argument("--render", action="store_true",
                        help="chaos: rewrite the section from its CSV without running")
    parser.add_argument("--timeout", type=float, default=600.0,
                        help="wall-clock limit of one run (s); a run over it counts as failed")
    parser.add_argument("--fig4-rtol", type=float, default=1e-5,
                        help="rtol for fig4 when the windows data has none below the target")
    args = parser.parse_args(argv)
    args.methods = args.methods.split(",")
    if args.study == "choosing":
        choosing(args)
        return
    exe = exe_or_build(args.exe)
    check_methods(parser, exe, "--methods", args.methods)
    names = list(STUDIES) if args.study == "all" else [args.study]
    for name in names:
        wall0 = time.perf_counter()
        with tempfile.TemporaryDirectory() as tmp:
            body = STUDIES[name](Runner(exe, tmp, args.timeout), args)
        command = "scripts/accuracy " + name + (" --quick" if args.quick else "") + \
            (" --render" if args.render and name == "chaos" else "") + \
            (f" --cases {','.join(f'{m}:{n}' for m, n in args.cases)}` (the other cases' "
             "rows from the CSV files of the "
             "previous full run), `" if args.cases and name == "windows" else "") + \
            ("" if args.methods == DEFAULT_METHODS
             else " --methods " + ",".join(args.methods))
        section(name, command, f"## {name}\n\n" + body, time.perf_counter() - wall0)
        print(f"accuracy: wrote section {name} of {PAGE}")
    choosing(args)


if __name__ == "__main__":
    main()
