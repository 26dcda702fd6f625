"""What accuracy costs over the whole 30 s motion (issue 16): writes docs/accuracy.md,
docs/data/acc_*.csv, docs/figures/acc_*.png and docs/choosing.md.

    scripts/accuracy windows        [--quick] [--methods cvode,cvode:2,mebdf,mebdf:7,...]
    scripts/accuracy discretization [--quick]
    scripts/accuracy chaos          [--quick]
    scripts/accuracy fig4           [--quick]
    scripts/accuracy choosing       (only reads the CSV files of the others)
    scripts/accuracy all            [--quick]
    (python -m ropedyn.studies.accuracy; without --exe it builds the Release executable)

A method is `name` or `name:max_order` with `name` any `&solver method` the executable
lists (`ropedyn keys`): new integrators (erk, adams, auto, ...) are measured by adding their
names to --methods. Runs go one at a time (`ropedyn run`, its own CPU time
/solver/cpu_time). --quick is a smoke test (small n, short horizons, few tolerances); the
full studies are meant for the final code and take hours on 2 cores (docs/accuracy.md).

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

from ropedyn.run import DOCS, add_exe_argument, exe_or_build
from ropedyn.studies.common import machine, update_doc, utc_stamp

PAGE = DOCS / "accuracy.md"
CHOOSING = DOCS / "choosing.md"
DATA = DOCS / "data"
FIGURES = DOCS / "figures"
SCENE = DOCS.parent / "input" / "paper.nml"
L, EA = 1.0, 35e6 * math.pi * 0.005**2 / 4
PAGE_HEAD = """# Accuracy over the whole motion: what it costs

Every table and figure on this page is written by `scripts/accuracy`
(`python/ropedyn/studies/accuracy.py`), one section per subcommand; re-run it, never edit
the numbers. Scene: `input/paper.nml` (Table 1 rope, top pinned, released straight at 75
degrees, damping (eta, eta_bar) = (1e3, 400)); atol = 0.01 rtol in every run. CPU times are
the runs' own (`/solver/cpu_time`, integration and HDF5 output), one run each, on a
machine shared with other jobs: read factors below 1.3 as ties.
"""


# --------------------------------------------------------------------------------------
# running

class Runner:
    def __init__(self, exe, tmp):
        self.exe, self.tmp, self.count = str(exe), pathlib.Path(tmp), 0

    def run(self, name, sets):
        """`ropedyn run input/paper.nml --set ...`; returns the output file's path."""
        self.count += 1
        out = self.tmp / f"{name}.h5"
        args = [self.exe, "run", str(SCENE), "--set", f"output.file='{out}'"]
        for k, v in sets.items():
            args += ["--set", f"{k}={v}"]
        r = subprocess.run(args, capture_output=True, text=True)
        if r.returncode != 0:
            return None, r.stderr.strip().splitlines()[-1] if r.stderr else "failed"
        return out, ""


def method_sets(method):
    name, _, order = method.partition(":")
    sets = {"solver.method": f"'{name}'"}
    if order:
        sets["solver.max_order"] = order
    return sets


def base_sets(model, n, rtol, t_end, dt=0.01):
    return {"model.kind": f"'{model}'", "model.elements": n, "solver.rtol": f"{rtol:g}",
            "solver.atol": f"{rtol * 1e-2:g}", "solver.t_end": f"{t_end:.12g}",
            "solver.output_interval": f"{dt:g}"}


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
    block = (f"{begin}\n\nCommand: `{command}` ({seconds / 60:.1f} min, {utc_stamp()}). "
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

def windows(runner, args):
    q = args.quick
    cases = [("rfem", 10), ("mpp", 10)] if q else \
        [("rfem", 10), ("rfem", 30), ("rfem", 100), ("rfem", 300),
         ("mpp", 10), ("mpp", 30), ("mpp", 100)]
    t_end = 6.0 if q else 30.0
    t0s = [0.0, 5.0] if q else [0.0, 5.0, 10.0, 20.0]
    width = 0.5
    rtols = [1e-3, 1e-4, 1e-5] if q else [1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8]
    ref_rtol = 1e-9 if q else 1e-10
    ref_methods = ["cvode", "mebdf"]
    rows, agreement = [], []
    for model, n in cases:
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
        agreement.append((model, n, horizon, a["cpu"], b["cpu"]))
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
    write_csv(DATA / "acc_windows.csv", rows)
    figure_windows(rows)
    md = [f"References to {t_end:g} s at rtol {ref_rtol:g} with {' and '.join(ref_methods)}; "
          f"windows of {width} s from t0 = {', '.join(f'{t:g}' for t in t0s)} s, each "
          "measured against a tight window reference restarted from the same record with "
          "the other reference method. Raw data: [data/acc_windows.csv]"
          "(data/acc_windows.csv).", "",
          "**References** (horizon: last time the two agree within 1e-6 m at every point; "
          "after it they are two different, equally valid motions, which is why the windows "
          "restart from one of them)", "",
          "| model | n | horizon (s) | CPU ref 1 (s) | CPU ref 2 (s) |", "|---|---|---|---|---|"]
    md += [f"| {m} | {n} | {h:.2f} | {c1:.3g} | {c2:.3g} |" for m, n, h, c1, c2 in agreement]
    md += ["", "**Per window** (tip L2 error m / all points m / pin force N / CPU s), median "
           "over the windows t0; the full table per t0 is in the CSV:", ""]
    md += window_table(rows, rtols)
    md += ["", "![windowed accuracy against CPU](figures/acc_windows.png)"]
    return "\n".join(md)


def window_table(rows, rtols):
    methods = list(dict.fromkeys(r["method"] for r in rows))
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


def figure_windows(rows):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    models = list(dict.fromkeys(r["model"] for r in rows))
    fig, axes = plt.subplots(1, len(models), figsize=(6 * len(models), 4.5), squeeze=False)
    for ax, model in zip(axes[0], models):
        for (n, m) in dict.fromkeys((int(r["n"]), r["method"]) for r in rows
                                    if r["model"] == model):
            sel = [r for r in rows if r["model"] == model and int(r["n"]) == n and
                   r["method"] == m and r["status"] == "ok"]
            rt = sorted(set(float(r["rtol"]) for r in sel), reverse=True)
            cpu = [np.median([float(r["cpu"]) for r in sel if float(r["rtol"]) == x]) for x in rt]
            err = [np.median([float(r["tip"]) for r in sel if float(r["rtol"]) == x]) for x in rt]
            ax.loglog(cpu, err, "o-", label=f"n={n} {m}")
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
    rtols = [1e-3, 1e-4, 1e-5] if q else [1e-3, 1e-4, 1e-5, 1e-6, 1e-7]
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
          f"{tight:g} run. Raw data: [data/acc_discretization.csv](data/acc_discretization.csv).",
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
    for target in (1e-1, 3e-2, 1e-2, 3e-3, 1e-3):
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
                rates.append((r["dissipated"][-1] - r["dissipated"][i1]) / (r["t"][-1] - r["t"][i1]))
                cpus.append(r["cpu"])
            if rates:
                rows.append(dict(method=m, rtol=rtol, starts=len(rates),
                                 mean=f"{np.mean(rates):.6e}", spread=f"{np.std(rates):.3e}",
                                 cpu=f"{np.mean(cpus):.4g}"))
                print(f"chaos: {rows[-1]}", flush=True)
    write_csv(DATA / "acc_chaos.csv", rows)
    best = min(rows, key=lambda r: float(r["rtol"]))
    md = [f"{model.upper()} n = {n}: mean dissipation rate (W) over [{t1:g}, {t_end:g}] s for "
          f"{starts} starts at 75 degrees + k 1e-9 rad (k = 0 .. {starts - 1}); per method and "
          "rtol its ensemble mean and spread (standard deviation); 'reproduces': the mean "
          f"within the spread of the tightest ensemble ({best['method']}, rtol {best['rtol']}). "
          "Raw data: [data/acc_chaos.csv](data/acc_chaos.csv).", "",
          "| method | rtol | mean rate (W) | spread (W) | reproduces | CPU per run (s) |",
          "|---|---|---|---|---|---|"]
    for r in rows:
        ok = abs(float(r["mean"]) - float(best["mean"])) <= max(float(best["spread"]), 1e-12)
        md.append(f"| {r['method']} | {float(r['rtol']):g} | {float(r['mean']):.5e} | "
                  f"{float(r['spread']):.2e} | {'yes' if ok else 'no'} | {r['cpu']} |")
    return "\n".join(md)


# --------------------------------------------------------------------------------------
# fig4

def fig4(runner, args):
    q = args.quick
    ns = [2, 5, 10] if q else [2, 3, 5, 10, 20, 30, 50, 70, 100, 200, 300]
    mpp_max = 10 if q else 100
    t_end = 3.0 if q else 30.0
    target = 1e-3
    win = read_csv(DATA / "acc_windows.csv")
    rows = []
    for model in ("rfem", "mpp"):
        for m in args.methods:
            rtol = chosen_rtol(win, model, m, target) or args.fig4_rtol
            for n in ns:
                if model == "mpp" and n > mpp_max:
                    continue
                if model == "rfem" and n < 2:
                    continue
                sets = {**base_sets(model, n, rtol, t_end, dt=0.05), **method_sets(m)}
                path, why = runner.run(f"f4_{model}{n}_{m}", sets)
                row = dict(model=model, method=m, n=n, rtol=rtol, cpu="", steps="", status="ok")
                if path is None:
                    row["status"] = why[:80]
                else:
                    r = read(path)
                    row.update(cpu=f"{r['cpu']:.4g}", steps=r["steps"])
                rows.append(row)
                print(f"fig4: {row}", flush=True)
    write_csv(DATA / "acc_fig4.csv", rows)
    figure_fig4(rows, t_end)
    md = [f"CPU time of the whole motion ({t_end:g} s, output every 0.05 s) against n, each "
          f"method at the loosest rtol whose windowed tip error (section 'windows', median "
          f"over the windows, from its largest n) is below {target:g} m (else rtol "
          f"{args.fig4_rtol:g}). Raw data: [data/acc_fig4.csv](data/acc_fig4.csv).", "",
          "![Figure 4 over the whole motion](figures/acc_fig4.png)", "",
          "| model, method (rtol) | " + " | ".join(f"n = {n}" for n in ns) + " |",
          "|---|" + "---|" * len(ns)]
    for key in dict.fromkeys((r["model"], r["method"], r["rtol"]) for r in rows):
        cells = []
        for n in ns:
            sel = [r for r in rows if (r["model"], r["method"], r["rtol"]) == key and r["n"] == n]
            cells.append(sel[0]["cpu"] if sel and sel[0]["status"] == "ok" else
                         ("failed" if sel else "-"))
        md.append(f"| {key[0]}, {key[1]} ({key[2]:g}) | " + " | ".join(cells) + " |")
    # the paper: "the MPP model is numerically more efficient only for small n"
    cross = []
    for m in args.methods:
        cheaper = [n for n in ns if mpp_cheaper(rows, m, n)]
        dearer = [n for n in ns if mpp_cheaper(rows, m, n) is False]
        cross.append(f"{m}: MPP cheaper at n = {cheaper or 'none'}, RFEM cheaper at "
                     f"n = {dearer or 'none'}")
    md += ["", "The paper (section 4, Fig. 4): \"in most cases the RFEM approach leads to "
           "considerably shorter time of calculations. The MPP model is numerically more "
           "efficient only for small n.\" Measured: " + "; ".join(cross) + "."]
    return "\n".join(md)


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
    good = []
    for rtol in sorted(set(float(r["rtol"]) for r in sel), reverse=True):
        tips = [float(r["tip"]) for r in sel if int(r["n"]) == nmax and float(r["rtol"]) == rtol]
        if tips and np.median(tips) < target:
            good.append(rtol)
    return max(good) if good else None


def figure_fig4(rows, t_end):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 5))
    for key in dict.fromkeys((r["model"], r["method"]) for r in rows):
        sel = [r for r in rows if (r["model"], r["method"]) == key and r["status"] == "ok"]
        ax.loglog([r["n"] for r in sel], [float(r["cpu"]) for r in sel],
                  "o-" if key[0] == "rfem" else "s--", label=f"{key[0]} {key[1]}")
    ax.set_xlabel("n")
    ax.set_ylabel(f"CPU time of {t_end:g} s of motion (s)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    FIGURES.mkdir(parents=True, exist_ok=True)
    fig.tight_layout()
    fig.savefig(FIGURES / "acc_fig4.png", dpi=90)
    plt.close(fig)


# --------------------------------------------------------------------------------------
# choosing

CHOOSING_HEAD = """# Which method, tolerance and n should I use, and what will it cost?

Written by `scripts/accuracy choosing` (`python/ropedyn/studies/accuracy.py`) from the
data of the other subcommands ([accuracy.md](accuracy.md)); re-run them and it, never edit
the numbers. Scene: the paper's rope (`input/paper.nml`).
"""


def choosing(args):
    win = read_csv(DATA / "acc_windows.csv")
    disc = read_csv(DATA / "acc_discretization.csv")
    f4 = read_csv(DATA / "acc_fig4.csv")
    md = ["1. **Pick n for the accuracy you need in space** (discretization error of the tip "
          "over the first second, [accuracy.md](accuracy.md#discretization)):", ""]
    if disc:
        md += ["| model | n | tip discretization error (m) |", "|---|---|---|"]
        md += [f"| {r['model']} | {r['n']} | {float(r['disc_tip']):.1e} |" for r in disc]
    else:
        md.append("(no data yet: run `scripts/accuracy discretization`)")
    md += ["", "2. **Pick rtol so that the time error stays below that** (the column 'rtol "
           "matching' of accuracy.md: tighter buys nothing, looser spoils the n you paid for).",
           "", "3. **Pick the method that is cheapest at that accuracy** (windows over the "
           "whole motion, median CPU per 0.5 s window at the loosest rtol reaching the "
           "accuracy):", ""]
    if win:
        md += ["| model | n | tip accuracy (m) | cheapest method (rtol): CPU per window (s) | "
               "runner-up |", "|---|---|---|---|---|"]
        for model, n in dict.fromkeys((r["model"], int(r["n"])) for r in win):
            for target in (1e-3, 1e-5):
                best = []
                for m in dict.fromkeys(r["method"] for r in win):
                    sel = [r for r in win if r["model"] == model and int(r["n"]) == n and
                           r["method"] == m and r["status"] == "ok"]
                    opts = []
                    for rtol in set(float(r["rtol"]) for r in sel):
                        rs = [r for r in sel if float(r["rtol"]) == rtol]
                        if np.median([float(r["tip"]) for r in rs]) < target:
                            opts.append((np.median([float(r["cpu"]) for r in rs]), rtol))
                    if opts:
                        cpu, rtol = min(opts)
                        best.append((cpu, m, rtol))
                best.sort()
                cell = lambda b: f"{b[1]} ({b[2]:g}): {b[0]:.3g}" if b else "-"
                md.append(f"| {model} | {n} | {target:g} | {cell(best[0] if best else None)} | "
                          f"{cell(best[1] if len(best) > 1 else None)} |")
    else:
        md.append("(no data yet: run `scripts/accuracy windows`)")
    md += ["", "4. **What the whole motion costs** (CPU of the full run at those settings, "
           "the paper's Figure 4 over the whole motion, [accuracy.md](accuracy.md#fig4)):", ""]
    if f4:
        md += ["| model | method (rtol) | n | CPU (s) |", "|---|---|---|---|"]
        md += [f"| {r['model']} | {r['method']} ({float(r['rtol']):g}) | {r['n']} | "
               f"{r['cpu'] or r['status']} |" for r in f4]
    else:
        md.append("(no data yet: run `scripts/accuracy fig4`)")
    CHOOSING.write_text(CHOOSING_HEAD + f"\nData as of {utc_stamp()}.\n\n" + "\n".join(md) + "\n")
    print(f"accuracy: wrote {CHOOSING}")


# --------------------------------------------------------------------------------------

STUDIES = {"windows": windows, "discretization": discretization, "chaos": chaos, "fig4": fig4}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("study", choices=[*STUDIES, "choosing", "all"])
    add_exe_argument(parser)
    parser.add_argument("--quick", action="store_true", help="smoke test: small n, short")
    parser.add_argument("--methods", default="cvode,cvode:2,mebdf,mebdf:7",
                        help="comma list of method[:max_order] (any &solver method)")
    parser.add_argument("--fig4-rtol", type=float, default=1e-5,
                        help="rtol for fig4 when the windows data has none below the target")
    args = parser.parse_args(argv)
    args.methods = [m for m in args.methods.split(",") if m]
    if args.study == "choosing":
        choosing(args)
        return
    exe = exe_or_build(args.exe)
    names = list(STUDIES) if args.study == "all" else [args.study]
    for name in names:
        wall0 = time.perf_counter()
        with tempfile.TemporaryDirectory() as tmp:
            body = STUDIES[name](Runner(exe, tmp), args)
        command = "scripts/accuracy " + name + (" --quick" if args.quick else "") + \
            ("" if args.methods == ["cvode", "cvode:2", "mebdf", "mebdf:7"]
             else " --methods " + ",".join(args.methods))
        section(name, command, f"## {name}\n\n" + body, time.perf_counter() - wall0)
        print(f"accuracy: wrote section {name} of {PAGE}")
    choosing(args)


if __name__ == "__main__":
    main()
