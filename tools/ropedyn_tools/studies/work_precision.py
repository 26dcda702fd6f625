"""Accuracy versus cost for the rope: work-precision of every (model, n, solver, max order).

The code of scripts/work_precision (python -m ropedyn_tools.studies.work_precision; without --exe
it builds the Release executable first). The scene is
input/paper.nml cut to --t-end seconds (default 2). For every model and number of elements:

1. Two references, one per integrator (CVODE and MEBDF), at rtol_ref = --ref-factor times the
   tightest measured rtol (default 1e-3: three orders tighter). They are compared with each
   other: the error horizon is the last output time up to which they agree within --agree
   (default 1e-6 m, every element end point). Errors are measured on [0, horizon] only.
2. The measured runs: every solver / max order / rtol (default 1e-3 .. 1e-6). The error of a
   run is taken against the reference of the *other* integrator (so neither is judged
   against its own bias): the tip and all element end points, at the horizon (final) and as
   an RMS over the output times in [0, horizon] (L2 in time); plus the energy-balance error
   max |T + V + D - W - E0| over the whole run.
3. CPU time: the run's own CPU time (integration and output), repeated with `ropedyn run`
   until >= --repeat-time seconds have accumulated; the median is reported.
4. A horizon check: both references of the first model at the smallest n run to
   --horizon-t (default 6 s) show when the motion's sensitivity makes them part.

All runs go through `ropedyn sweep` (references with 2 workers; measured runs with --jobs,
default 1 so that CPU times are not disturbed), so an interrupted study resumes where it
stopped. Writes docs/data/rope_wp.csv, docs/data/rope_references.csv,
docs/figures/rope_wp_<model>.png, docs/figures/rope_cost_vs_n.png,
docs/figures/rope_horizon.png and the section between the markers in docs/validation/work-precision.md.
"""
import argparse
import csv
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

from ropedyn import io
from ropedyn_tools.arguments import check_names, list_text, named_lists, positive
from ropedyn_tools.repo import DOCS, PAPER, ROOT, add_exe_argument, exe_or_build
from ropedyn_tools.studies.common import machine, update_doc, run_stamp

BEGIN = "<!-- work-precision:begin -->"
END = "<!-- work-precision:end -->"
#: the reference a method's runs are judged against: the other integrator's, never the code
#: that made the run (erk and auto against CVODE's; auto may run MEBDF, never CVODE on this
#: rope's RFEM, and the two references agree far below its errors anyway: the page's table
#: of references)
OTHER = {"cvode": "mebdf", "adams": "mebdf", "mebdf": "cvode", "erk": "cvode",
         "auto": "cvode"}
FIELDS = ["model", "elements", "method", "max_order", "rtol", "atol", "status", "steps",
          "rhs_evals", "jac_evals", "lin_setups", "err_test_fails", "cpu_time", "runs",
          "reference_method", "horizon", "tip_final", "tip_l2", "points_final", "points_l2",
          "energy_error_max", "energy_error_final", "reason"]


def number_list(text, kind=float):
    return [kind(x) for x in text.replace(",", " ").split()]


def run_sweep(exe, path, jobs, label):
    """Run a sweep file; returns its summary rows (failed cases included)."""
    t0 = time.monotonic()
    r = subprocess.run([str(exe), "sweep", str(path), "--jobs", str(jobs)],
                       capture_output=True, text=True)
    if r.returncode not in (0, 3):
        sys.exit(f"work_precision: sweep {path} failed:\n{r.stderr}")
    with open(path.parent / path.stem / "summary.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    bad = [row for row in rows if row["status"] != "complete"]
    print(f"work_precision: {label}: {len(rows)} runs, {len(bad)} not complete, "
          f"{time.monotonic() - t0:.0f} s", file=sys.stderr)
    return rows


def write_sweep(path, model, elements, methods, rtols, max_orders, t_end, atol_per_rtol,
                interval):
    lines = ["&sweep", f"    base = '{PAPER}'", f"    output_dir = '{path.parent / path.stem}'",
             f"    models = '{model}'", "    elements = " + ", ".join(map(str, elements)),
             "    methods = " + ", ".join(f"'{m}'" for m in methods),
             "    max_orders = " + ", ".join(map(str, max_orders)),
             "    rtols = " + ", ".join(f"{r:.1e}" for r in rtols),
             f"    atol_per_rtol = {atol_per_rtol}",
             f"    set = 'solver.t_end={t_end}', 'solver.output_interval={interval}'",
             "    reference = 'none'", "/"]
    path.write_text("\n".join(lines) + "\n")


def load(path):
    run = io.load_run(path)
    e = run.energy
    balance = e["kinetic"] + e["elastic"] + e["gravity"] + e["dissipated"] - e["support_work"]
    return {"time": run.time, "points": run.points, "balance": balance,
            "scene": run.attrs["scene"]}


def agreement(a, b):
    """Max over element end points of |a - b| at each common output time."""
    m = min(len(a["time"]), len(b["time"]))
    return np.linalg.norm(a["points"][:m] - b["points"][:m], axis=2).max(axis=1)


def horizon_of(a, b, agree):
    d = agreement(a, b)
    bad = np.nonzero(d > agree)[0]
    k = (bad[0] - 1) if len(bad) else len(d) - 1
    return max(k, 0), float(d[:k + 1].max()) if k >= 0 else float("nan")


def errors(run, ref, k):
    """Errors of `run` against `ref` over output records 0..k."""
    if len(run["time"]) <= k or not np.allclose(run["time"][:k + 1], ref["time"][:k + 1]):
        return None
    diff = np.linalg.norm(run["points"][:k + 1] - ref["points"][:k + 1], axis=2)  # (k+1, 2n)
    tip = diff[:, -1]
    return {"tip_final": tip[-1], "tip_l2": float(np.sqrt(np.mean(tip ** 2))),
            "points_final": float(np.sqrt(np.mean(diff[-1] ** 2))),
            "points_l2": float(np.sqrt(np.mean(diff ** 2)))}


def repeat_cpu(exe, row, first_cpu, repeat_time, work):
    """Median CPU time over repeated runs of a case's scene until >= repeat_time s."""
    times = [first_cpu]
    if repeat_time <= 0 or first_cpu >= repeat_time:
        return first_cpu, 1
    scene = load(row["file"])["scene"]
    with tempfile.TemporaryDirectory(dir=work) as tmp:
        nml = pathlib.Path(tmp) / "case.nml"
        nml.write_text(scene + "\n")
        out = pathlib.Path(tmp) / "repeat.h5"
        while sum(times) < repeat_time and len(times) < 200:
            r = subprocess.run([str(exe), "run", str(nml), "--set", f"output.file={out}"],
                               capture_output=True, text=True)
            if r.returncode != 0:
                break
            times.append(float(io.load_run(out).stats["cpu_time"]))
    return statistics.median(times), len(times)


def interpolate_cost(points, target):
    """CPU time at error `target` along a line of (error, cpu) points, ordered by rtol
    (log-log linear between the first pair that brackets the target). Returns (cpu, bound):
    bound is True when every point is more accurate than the target (cpu is then the
    cheapest point's: an upper bound); NaN when no point reaches the target."""
    pts = [(e, c) for e, c in points if e > 0 and np.isfinite(e) and c > 0]
    for (e1, c1), (e2, c2) in zip(pts, pts[1:]):
        if min(e1, e2) <= target <= max(e1, e2) and e1 != e2:
            w = (np.log(target) - np.log(e1)) / (np.log(e2) - np.log(e1))
            return float(np.exp(np.log(c1) + w * (np.log(c2) - np.log(c1)))), False
    if pts and all(e <= target for e, _ in pts):
        return min(c for _, c in pts), True
    return float("nan"), False


def fmt(x, digits=2):
    if x is None or (isinstance(x, float) and not np.isfinite(x)):
        return "–"
    return f"{x:.{digits}e}" if (abs(x) < 1e-2 or abs(x) >= 1e4) else f"{x:.{digits + 1}g}"


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    add_exe_argument(p)
    p.add_argument("--models", default="rfem,mpp",
                   help="models to study (names of `ropedyn keys`' model kind)")
    p.add_argument("--elements", type=list_text(positive(int), ", "), default=None,
                   help="default 10,30,70,100 (--quick: 10,30)")
    p.add_argument("--model-elements", action="append", default=None,
                   type=named_lists(positive(int), ", "),
                   help="MODEL=N,N,... element counts for one model (default: mpp=10,30,70: "
                        "MPP's dense mass matrix makes n = 100 cost 100 s per 2-s run)")
    p.add_argument("--methods", default="cvode,mebdf,erk,auto",
                   help="integrators to measure (default cvode,mebdf,erk,auto)")
    p.add_argument("--max-orders", default="cvode=2+5,mebdf=4+7",
                   type=named_lists(positive(int), "+", entries=","),
                   help="METHOD=K[+K...] per method, e.g. cvode=2+5,mebdf=4+7")
    p.add_argument("--rtols", type=list_text(positive(float), ", "), default=None, help="default 1e-3,1e-4,1e-5,1e-6 (--quick: "
                   "1e-3,1e-4,1e-5)")
    p.add_argument("--ref-factor", type=float, default=1e-3)
    p.add_argument("--atol-per-rtol", type=float, default=1e-2)
    p.add_argument("--t-end", type=float, default=2.0)
    p.add_argument("--interval", type=float, default=0.01)
    p.add_argument("--agree", type=float, default=1e-6)
    p.add_argument("--target", type=float, default=1e-5,
                   help="tip L2 error (m) at which the cost-versus-n figure compares")
    p.add_argument("--horizon-t", type=float, default=None, help="default 6 (--quick: 3)")
    p.add_argument("--repeat-time", type=float, default=0.5)
    p.add_argument("--jobs", type=int, default=1, help="workers for the measured runs")
    p.add_argument("--work", default=str(ROOT / "out" / "work_precision"))
    p.add_argument("--quick", action="store_true",
                   help="n = 10, 30; rtol 1e-3 .. 1e-5; references 1e-8; horizon check 3 s")
    p.add_argument("--no-write", action="store_true", help="do not touch docs/")
    args = p.parse_args(argv)
    if args.quick:
        args.elements = args.elements or "10,30"
        args.model_elements = args.model_elements or []
        args.rtols = args.rtols or "1e-3,1e-4,1e-5"
        args.horizon_t = args.horizon_t or 3.0
    args.elements = args.elements or "10,30,70,100"
    args.rtols = args.rtols or "1e-3,1e-4,1e-5,1e-6"
    args.horizon_t = args.horizon_t or 6.0
    exe = pathlib.Path(exe_or_build(args.exe)).resolve()
    check_names(p, exe, "--models", args.models.split(","), "model", "kind")
    check_names(p, exe, "--methods", args.methods.split(","), "solver", "method")
    check_names(p, exe, "--max-orders", [e.partition("=")[0] for e in args.max_orders.split(",")],
                "solver", "method")
    work = pathlib.Path(args.work)
    work.mkdir(parents=True, exist_ok=True)
    started = time.monotonic()

    methods = args.methods.split(",")
    rtols = number_list(args.rtols)
    ref_rtol = min(rtols) * args.ref_factor
    orders = {}
    for item in args.max_orders.split(","):
        method, ks = item.split("=")
        orders[method] = [int(k) for k in ks.split("+")]
    elements = {}
    default_elements = number_list(args.elements, int)
    model_elements = args.model_elements
    if model_elements is None:
        model_elements = ["mpp=10,30,70"]
    for item in model_elements:
        model, ns = item.split("=")
        elements[model] = number_list(ns, int)
    models = args.models.split(",")   # names checked against `ropedyn keys` above

    rows, refs = [], []
    for model in models:
        ns = elements.get(model, default_elements)
        # references: both integrators at ref_rtol (their default max order), 2 workers
        ref_sweep = work / f"ref_{model}.nml"
        write_sweep(ref_sweep, model, ns, ["cvode", "mebdf"], [ref_rtol], [0], args.t_end,
                    args.atol_per_rtol, args.interval)
        ref_rows = run_sweep(exe, ref_sweep, 2, f"{model} references (rtol {ref_rtol:.0e})")
        ref_data = {}
        for r in ref_rows:
            if r["status"] == "complete":
                ref_data[(int(r["elements"]), r["method"])] = (load(r["file"]), r)
        horizons = {}
        for n in ns:
            a, b = ref_data.get((n, "cvode")), ref_data.get((n, "mebdf"))
            if a is None or b is None:
                print(f"work_precision: {model} n={n}: a reference failed", file=sys.stderr)
                continue
            k, agree = horizon_of(a[0], b[0], args.agree)
            horizons[n] = k
            refs.append({"model": model, "elements": n, "rtol": ref_rtol,
                         "agreement": float(agreement(a[0], b[0]).max()),
                         "agreement_horizon": agree, "horizon": float(a[0]["time"][k]),
                         "cpu_cvode": float(a[1]["cpu_time"]),
                         "cpu_mebdf": float(b[1]["cpu_time"])})
        # measured runs: one sweep per method (its own max orders)
        for method in methods:
            sweep = work / f"runs_{model}_{method}.nml"
            write_sweep(sweep, model, ns, [method], rtols, orders.get(method, [0]),
                        args.t_end, args.atol_per_rtol, args.interval)
            for r in run_sweep(exe, sweep, args.jobs, f"{model} {method} runs"):
                n = int(r["elements"])
                row = {k: r.get(k, "") for k in FIELDS}
                row["reason"] = r["reason"]
                if r["status"] == "complete" and n in horizons:
                    cpu, runs = repeat_cpu(exe, r, float(r["cpu_time"]), args.repeat_time,
                                           work)
                    row["cpu_time"], row["runs"] = cpu, runs
                    ref_method = OTHER.get(method, "cvode")
                    run = load(r["file"])
                    e = errors(run, ref_data[(n, ref_method)][0], horizons[n])
                    row["reference_method"] = ref_method
                    row["horizon"] = float(run["time"][horizons[n]])
                    if e:
                        row.update(e)
                    bal = run["balance"]
                    row["energy_error_max"] = float(np.abs(bal - bal[0]).max())
                    row["energy_error_final"] = float(abs(bal[-1] - bal[0]))
                rows.append(row)

    # horizon check: both references of the first model at the smallest n, run long
    hz_model = models[0]
    hz_n = min(elements.get(hz_model, default_elements))
    hz_sweep = work / "horizon.nml"
    write_sweep(hz_sweep, hz_model, [hz_n], ["cvode", "mebdf"], [ref_rtol], [0],
                args.horizon_t, args.atol_per_rtol, args.interval)
    hz_rows = run_sweep(exe, hz_sweep, 2, f"horizon check ({hz_model}, n = {hz_n})")
    hz = None
    if all(r["status"] == "complete" for r in hz_rows):
        a, b = (load(r["file"]) for r in hz_rows)
        hz = {"model": hz_model, "n": hz_n, "t": a["time"], "d": agreement(a, b)}

    elapsed = time.monotonic() - started
    print(f"work_precision: done in {elapsed:.0f} s", file=sys.stderr)
    if args.no_write:
        for row in rows:
            print(row)
        return
    write_outputs(args, models, methods, orders, rtols, ref_rtol, rows, refs, hz, elapsed)


def curves(rows, model):
    """(method, max_order, n) -> sorted list of rows of one line of the diagram."""
    out = {}
    for r in rows:
        if r["model"] != model or r["status"] != "complete" or "tip_l2" not in r:
            continue
        out.setdefault((r["method"], int(r["max_order"]), int(r["elements"])), []).append(r)
    for v in out.values():
        v.sort(key=lambda r: -float(r["rtol"]))
    return out


def line_label(method, k):
    """'cvode (max order 5)', or 'erk (default)' for a method run at its default order."""
    return f"{method} (max order {k})" if k else f"{method} (default)"


def short_label(method, k):
    """'cvode (5)', or 'erk (default)': the tables' column and row names."""
    return f"{method} ({k or 'default'})"


def write_outputs(args, models, methods, orders, rtols, ref_rtol, rows, refs, hz, elapsed):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    data_dir, fig_dir = DOCS / "data", DOCS / "figures"
    data_dir.mkdir(parents=True, exist_ok=True)
    fig_dir.mkdir(parents=True, exist_ok=True)
    with open(data_dir / "rope_wp.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=FIELDS, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow(r)
    with open(data_dir / "rope_references.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(refs[0]) if refs else ["model"])
        w.writeheader()
        w.writerows(refs)

    markers = {r: m for r, m in zip(sorted(rtols, reverse=True), "os^Dvph*")}
    def color(method, k):
        return colors.get((method, k), colors.get((method, 0)))

    colors = {("cvode", 5): "C0", ("cvode", 2): "C9", ("cvode", 3): "C4",
              ("mebdf", 4): "C1", ("mebdf", 7): "C3", ("mebdf", 6): "C5", ("mebdf", 2): "C6",
              ("erk", 0): "C2", ("auto", 0): "k", ("adams", 0): "C8"}
    figures = []
    for model in models:
        lines = curves(rows, model)
        ns = sorted({k[2] for k in lines})
        if not ns:
            continue
        fig, axes = plt.subplots(2, len(ns), figsize=(3.6 * len(ns), 6.4), squeeze=False)
        for j, n in enumerate(ns):
            for i, (measure, label) in enumerate([("tip_l2", "tip error, L2 in time (m)"),
                                                  ("points_l2", "all points, L2 in time (m)")]):
                ax = axes[i][j]
                for (method, k, nn), rs in sorted(lines.items()):
                    if nn != n:
                        continue
                    x = [float(r["cpu_time"]) for r in rs]
                    y = [float(r[measure]) for r in rs]
                    c = color(method, k)
                    ax.loglog(x, y, "-", color=c, label=line_label(method, k))
                    for xi, yi, r in zip(x, y, rs):
                        ax.loglog(xi, yi, markers.get(float(r["rtol"]), "o"), color=c)
                ax.set_title(f"{model}, n = {n}")
                ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
                ax.set_xlabel("CPU time (s)")
                if j == 0:
                    ax.set_ylabel(label)
                ax.grid(True, which="both", alpha=0.3)
        handles, labels = axes[0][0].get_legend_handles_labels()
        for r, m in markers.items():
            handles.append(plt.Line2D([], [], marker=m, color="k", linestyle=""))
            labels.append(f"rtol {r:.0e}")
        fig.legend(handles, labels, loc="lower center", ncol=len(labels), fontsize=8)
        fig.suptitle(f"{model}: error against the other integrator's reference "
                     f"(rtol {ref_rtol:.0e}) over [0, horizon] versus CPU time")
        fig.tight_layout(rect=(0, 0.05, 1, 0.96))
        name = f"rope_wp_{model}.png"
        fig.savefig(fig_dir / name, dpi=110)
        plt.close(fig)
        figures.append(name)

    # cost versus n at a fixed accuracy (the paper's Figure 4)
    cost = {}
    fig, ax = plt.subplots(figsize=(6.4, 4.6))
    for model, style in zip(models, ["-", "--", ":"]):
        lines = curves(rows, model)
        for method in methods:
            for k in sorted({key[1] for key in lines if key[0] == method}):
                pts = []
                for n in sorted({key[2] for key in lines}):
                    rs = lines.get((method, k, n))
                    if not rs:
                        continue
                    c, bound = interpolate_cost([(float(r["tip_l2"]), float(r["cpu_time"]))
                                                 for r in rs], args.target)
                    cost[(model, method, k, n)] = (c, bound)
                    if np.isfinite(c):
                        pts.append((n, c, bound))
                if pts:
                    c = color(method, k)
                    ax.loglog([q[0] for q in pts], [q[1] for q in pts], style, color=c,
                              label=f"{model}, {line_label(method, k)}")
                    for q in pts:
                        ax.loglog(q[0], q[1], "v" if q[2] else "o", color=c,
                                  fillstyle="none" if q[2] else "full")
    ax.set_xlabel("number of elements n")
    ax.set_ylabel("CPU time (s)")
    ax.set_title(f"CPU time for tip L2 error {args.target:.0e} m over [0, horizon]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(fig_dir / "rope_cost_vs_n.png", dpi=110)
    plt.close(fig)
    figures.append("rope_cost_vs_n.png")

    if hz is not None:
        fig, ax = plt.subplots(figsize=(6.4, 4.0))
        ax.semilogy(hz["t"], np.maximum(hz["d"], 1e-16))
        ax.axhline(args.agree, color="k", linestyle=":", label=f"{args.agree:.0e} m")
        ax.axvline(args.t_end, color="C3", linestyle="--", label=f"study horizon {args.t_end} s")
        ax.set_xlabel("t (s)")
        ax.set_ylabel("max |CVODE ref - MEBDF ref| (m)")
        ax.set_title(f"Agreement of the two references ({hz['model']}, n = {hz['n']}, "
                     f"rtol {ref_rtol:.0e})")
        ax.legend()
        ax.grid(True, which="both", alpha=0.3)
        fig.tight_layout()
        fig.savefig(fig_dir / "rope_horizon.png", dpi=110)
        plt.close(fig)
        figures.append("rope_horizon.png")

    # the generated block of docs/validation/work-precision.md
    cmd = "scripts/work_precision" + (" --quick" if args.quick else "")
    stamp = run_stamp()
    b = [BEGIN, ""]
    b.append(f"Command: `{cmd}` ({elapsed / 60:.1f} min). Machine: {machine()}. Run: {stamp}.")
    b.append("")
    b.append(f"Scene: `input/paper.nml` to t = {args.t_end} s, output every {args.interval} s; "
             f"atol = {args.atol_per_rtol} rtol; rtol = "
             + ", ".join(f"{r:.0e}" for r in sorted(rtols, reverse=True))
             + f"; references at rtol {ref_rtol:.0e} with both integrators; errors over "
             f"[0, horizon] against the other integrator's reference (MEBDF's for cvode "
             "and adams, CVODE's for the others); CPU time: median over "
             f">= {args.repeat_time} s of repeated runs. Raw data: "
             "[data/rope_wp.csv](../data/rope_wp.csv), "
             "[data/rope_references.csv](../data/rope_references.csv).")
    b.append("")
    b.append("**References** (agreement: max over output times and element end points of "
             "|CVODE ref - MEBDF ref|; horizon: last time with agreement within "
             f"{args.agree:.0e} m)")
    b.append("")
    b.append("| model | n | agreement (m) | horizon (s) | CPU CVODE ref (s) | CPU MEBDF ref (s) |")
    b.append("|---|---|---|---|---|---|")
    for r in refs:
        b.append(f"| {r['model']} | {r['elements']} | {fmt(r['agreement'])} | "
                 f"{r['horizon']:g} | {fmt(r['cpu_cvode'])} | {fmt(r['cpu_mebdf'])} |")
    if hz is not None:
        d = hz["d"]
        t = hz["t"]
        marks = []
        for level in (1e-6, 1e-4, 1e-2):
            k = np.nonzero(d > level)[0]
            marks.append(f"{level:.0e} m at t = {t[k[0]]:.2f} s" if len(k)
                         else f"{level:.0e} m not reached by {t[-1]:.1f} s")
        b.append("")
        b.append(f"Horizon check ({hz['model']}, n = {hz['n']}, both references to "
                 f"{args.horizon_t} s): they part by " + "; ".join(marks) + ". "
                 "![agreement of the references](../figures/rope_horizon.png)")
    b.append("")
    for name in figures:
        if name.startswith("rope_wp_"):
            b.append(f"![work-precision {name[8:-4]}](../figures/{name})")
            b.append("")
    b.append(f"**CPU time (s) at tip L2 error {args.target:.0e} m** (log-log interpolation "
             "along each line; ≤: even the loosest rtol is more accurate, the value is the "
             "CPU time of the line's cheapest run, an upper bound, drawn as an open triangle; "
             "– : the line does not "
             "reach that accuracy) — the paper's Figure 4:")
    b.append("")
    b.append("![cost versus n](../figures/rope_cost_vs_n.png)")
    b.append("")
    keys = sorted({(k[0], k[1], k[2]) for k in cost})
    ns = sorted({k[3] for k in cost})
    b.append("| model, method (max order) | " + " | ".join(f"n = {n}" for n in ns) + " |")
    b.append("|---|" + "---|" * len(ns))
    for model, method, k in keys:
        cells = []
        for n in ns:
            c, bound = cost.get((model, method, k, n), (float("nan"), False))
            cells.append(("≤ " if bound else "") + fmt(c))
        b.append(f"| {model}, {short_label(method, k)} | " + " | ".join(cells) + " |")
    b.append("")
    b.append("**Every run** (tip L2 error m / all-points L2 error m / energy-balance error J / "
             "steps / CPU s):")
    for model in models:
        lines = curves(rows, model)
        ns = sorted({key[2] for key in lines})
        settings = sorted({(key[0], key[1]) for key in lines})
        b.append("")
        b.append(f"| {model}: n, rtol | " + " | ".join(short_label(m, k) for m, k in settings)
                 + " |")
        b.append("|---|" + "---|" * len(settings))
        for n in ns:
            for rtol in sorted(rtols, reverse=True):
                cells = []
                for m, k in settings:
                    match = [r for r in lines.get((m, k, n), [])
                             if abs(float(r["rtol"]) - rtol) <= 1e-9 * rtol]
                    if match:
                        r = match[0]
                        cells.append(f"{fmt(float(r['tip_l2']), 1)} / "
                                     f"{fmt(float(r['points_l2']), 1)} / "
                                     f"{fmt(float(r['energy_error_max']), 1)} / {r['steps']} / "
                                     f"{fmt(float(r['cpu_time']), 2)}")
                    else:
                        failed = [r for r in rows if r["model"] == model and r["method"] == m
                                  and int(r["elements"]) == n
                                  and abs(float(r["rtol"]) - rtol) <= 1e-9 * rtol]
                        cells.append("failed" if failed else "–")
                b.append(f"| {n}, {rtol:.0e} | " + " | ".join(cells) + " |")
    failed = [r for r in rows if r["status"] != "complete"]
    if failed:
        b.append("")
        b.append("Failed runs: " + "; ".join(
            f"{r['model']} n={r['elements']} {r['method']} rtol {float(r['rtol']):.0e}: "
            f"{r['reason']}" for r in failed))
    b.append("")
    b.append(END)

    update_doc(DOCS / "validation" / "work-precision.md", BEGIN, END, "\n".join(b), strip="\n",
               default="# Results\n\n" + BEGIN + "\n" + END + "\n")
    print(f"work_precision: wrote docs/validation/work-precision.md, docs/data/rope_wp.csv, figures "
          f"{', '.join(figures)}", file=sys.stderr)


if __name__ == "__main__":
    sys.exit(main())
