"""Work-precision diagrams of the stiff test-set problems for ropedyn's integrators.

The code of scripts/work_precision_testset (python -m ropedyn_tools.studies.work_precision_testset;
without --exe it builds the Release executable first).
For each problem, method and max order it sweeps rtol = 10^-(3 + m/2), m = 0 .. 16
(1e-3 .. 1e-11; atol by the test-set rules of `ropedyn testset`: atol = rtol, ROBER
1e-6 rtol, E5 1.7e-24), runs `ropedyn testset ... --csv` and collects the accuracy (scd;
mescd for E5), the counters and the median CPU time per run. It writes

- docs/data/testset_wp.csv: every run, failed ones included (status, message);
- docs/figures/wp_<problem>.png: CPU time and steps against the accuracy;
- the section between the markers below in docs/validation/testset.md: a table per problem and
  a comparison (MEBDF/CVODE CPU at equal scd; steps against the MEBDFI reference counts
  of docs/theory/testset.md). The rest of the page is kept.

A method whose runs fail (e.g. not implemented yet) is skipped with a note.
"""
import argparse
import csv
import io
import subprocess
import sys

import numpy as np

from ropedyn_tools.repo import DOCS, add_exe_argument, exe_or_build
from ropedyn_tools.studies.common import machine, update_doc, run_stamp
from ropedyn.docstrings import summary

BEGIN = "<!-- testset-wp:begin -->"
END = "<!-- testset-wp:end -->"
PROBLEMS = ["HIRES", "VDPOL", "OREGO", "ROBER", "E5", "POLLU"]
# (method, max order) pairs worth showing: CVODE's default 5; MEBDF 4 (its default) and 6
SETTINGS = [("cvode", 5), ("mebdf", 4), ("mebdf", 7)]
M_VALUES = list(range(17))          # rtol = 10^-(3 + m/2)
QUICK_M_VALUES = [0, 4, 8, 12]      # rtol 1e-3, 1e-5, 1e-7, 1e-9
# MEBDFI (classic Fortran, numerical Jacobian, max order 7) and CVODE 6.4.1 (dense,
# difference-quotient Jacobian), rtol = atol (ROBER atol = 1e-6 rtol): docs/theory/testset.md
REFERENCE_STEPS = [
    # problem, rtol, MEBDFI scd, MEBDFI steps, CVODE scd, CVODE steps
    ("HIRES", 1e-6, 3.30, 168, 2.37, 374),
    ("HIRES", 1e-10, 7.31, 425, 5.98, 847),
    ("VDPOL", 1e-6, 6.64, 1040, 4.42, 1440),
    ("OREGO", 1e-10, 9.50, 3314, 7.50, 7462),
    ("ROBER", 1e-10, 5.27, 15149, 7.34, 3986),
]
CPU_RATIO_PROBLEMS = ["HIRES", "VDPOL", "OREGO"]
FIELDS = ["problem", "method", "max_order", "m", "rtol", "atol", "scd", "mescd", "measure",
          "accuracy", "steps", "rejected", "rhs_evals", "jac_rhs_evals", "jac_evals",
          "lin_setups", "nonlin_iters", "nonlin_conv_fails", "cpu_time", "runs", "status",
          "message"]


def label(method, order):
    return f"{method} (max order {order})"


def run_point(exe, problem, method, order, m, repeat_time):
    rtol = 10.0 ** -(3 + m / 2)
    cmd = [str(exe), "testset", problem, "--method", method, "--max-order", str(order),
           "--rtol", f"{rtol:.10e}", "--repeat-time", str(repeat_time), "--csv"]
    result = subprocess.run(cmd, capture_output=True, text=True)
    row = {"problem": problem, "method": method, "max_order": order, "m": m, "rtol": rtol}
    if result.returncode != 0:
        message = result.stderr.strip().splitlines()
        row.update(status=f"failed (exit {result.returncode})",
                   message=message[-1] if message else "")
        return row
    (data,) = list(csv.DictReader(io.StringIO(result.stdout)))
    for key in FIELDS:
        if key in data and key not in ("problem", "method", "max_order", "rtol"):
            row[key] = data[key]
    for key in ("atol", "scd", "mescd", "accuracy", "cpu_time"):
        row[key] = float(row[key])
    for key in ("steps", "rejected", "rhs_evals", "jac_rhs_evals", "jac_evals", "lin_setups",
                "nonlin_iters", "nonlin_conv_fails", "runs"):
        row[key] = int(row[key])
    row.update(status="ok", message="")
    return row


def sweep(exe, problems, settings, m_values, repeat_time):
    rows, skipped = [], {}
    for problem in problems:
        for method, order in settings:
            key = (method, order)
            if key in skipped:
                continue
            for m in m_values:
                row = run_point(exe, problem, method, order, m, repeat_time)
                rows.append(row)
                if row["status"] == "ok":
                    print(f"{problem:6s} {label(method, order):22s} rtol {row['rtol']:8.1e}  "
                          f"{row['measure']} {row['accuracy']:6.2f}  steps {row['steps']:7d}  "
                          f"cpu {row['cpu_time']:.3e} s", flush=True)
                else:
                    print(f"{problem:6s} {label(method, order):22s} rtol {row['rtol']:8.1e}  "
                          f"{row['status']}: {row['message']}", flush=True)
                    if "not implemented" in row["message"]:
                        skipped[key] = row["message"]
                        break
    return rows, skipped


def curve(rows, problem, method, order):
    """Successful points of one curve, sorted by tolerance."""
    pts = [r for r in rows if r["problem"] == problem and r["method"] == method
           and r["max_order"] == order and r["status"] == "ok"]
    return sorted(pts, key=lambda r: r["m"])


def interp_log(points, key, accuracy):
    """log10(key) at the given accuracy, interpolated along a curve (None outside it)."""
    if len(points) < 2:
        return None
    acc = np.array([p["accuracy"] for p in points])
    val = np.log10([max(p[key], 1e-300) for p in points])
    order = np.argsort(acc)
    acc, val = acc[order], val[order]
    if not (acc[0] <= accuracy <= acc[-1]):
        return None
    return float(np.interp(accuracy, acc, val))


def plot(rows, problem, settings, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax_cpu, ax_steps) = plt.subplots(1, 2, figsize=(11, 4.4))
    markers = ["o", "s", "^", "D", "v"]
    measure = "scd"
    drawn = 0
    for i, (method, order) in enumerate(settings):
        pts = curve(rows, problem, method, order)
        if not pts:
            continue
        measure = pts[0]["measure"]
        x = [p["accuracy"] for p in pts]
        style = dict(marker=markers[i % len(markers)], label=label(method, order))
        ax_cpu.semilogy(x, [p["cpu_time"] for p in pts], **style)
        ax_steps.semilogy(x, [p["steps"] for p in pts], **style)
        for ax, key in ((ax_cpu, "cpu_time"), (ax_steps, "steps")):
            for p in (pts[0], pts[-1]):
                ax.annotate(f"{p['rtol']:.0e}", (p["accuracy"], p[key]), fontsize=7,
                            xytext=(3, 3), textcoords="offset points")
        drawn += 1
    if problem in {r[0] for r in REFERENCE_STEPS}:
        refs = [r for r in REFERENCE_STEPS if r[0] == problem]
        ax_steps.semilogy([r[2] for r in refs], [r[3] for r in refs], "k*", ms=10,
                          label="MEBDFI (reference counts)")
        ax_steps.semilogy([r[4] for r in refs], [r[5] for r in refs], "kx", ms=8,
                          label="CVODE, FD Jacobian (reference counts)")
    ax_cpu.set_xlabel(f"accuracy at t_end ({measure}, digits)")
    ax_cpu.set_ylabel("CPU time per run (s)")
    ax_steps.set_xlabel(f"accuracy at t_end ({measure}, digits)")
    ax_steps.set_ylabel("accepted steps")
    for ax in (ax_cpu, ax_steps):
        ax.grid(True, which="both", alpha=0.3)
        if drawn:
            ax.legend(fontsize=8)
    fig.suptitle(f"{problem}: work-precision, rtol = 1e-3 .. 1e-11 (marker per tolerance)")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def fmt_cell(p):
    if p is None:
        return ""
    if p["status"] != "ok":
        return "failed"
    return f"{p['accuracy']:.2f} / {p['steps']} / {1e3 * p['cpu_time']:.3g}"


def tables(rows, problems, settings, m_values):
    lines = []
    table_m = [m for m in m_values if m % 2 == 0] or m_values
    for problem in problems:
        present = [s for s in settings if any(r["problem"] == problem and r["method"] == s[0]
                                              and r["max_order"] == s[1] for r in rows)]
        if not present:
            continue
        measure = next((r["measure"] for r in rows
                        if r["problem"] == problem and r["status"] == "ok"), "scd")
        lines += [f"**{problem}** ({measure} / steps / CPU ms per run)", "",
                  "| rtol | " + " | ".join(label(*s) for s in present) + " |",
                  "|---|" + "---|" * len(present)]
        for m in table_m:
            cells = []
            for method, order in present:
                match = [r for r in rows if r["problem"] == problem and r["method"] == method
                         and r["max_order"] == order and r["m"] == m]
                cells.append(fmt_cell(match[0] if match else None))
            lines.append(f"| {10.0 ** -(3 + m / 2):.0e} | " + " | ".join(cells) + " |")
        lines.append("")
    return lines


def comparison(rows, problems, settings):
    lines = ["**MEBDF CPU time / CVODE CPU time at equal accuracy** (log CPU interpolated "
             "linearly in scd along each curve):", ""]
    mebdf = [s for s in settings if s[0] == "mebdf"]
    have_mebdf = any(curve(rows, p, *s) for p in problems for s in mebdf)
    if not mebdf:
        lines += ["MEBDF was not part of this sweep (`--methods`).", ""]
    elif not have_mebdf:
        lines += ["MEBDF: no successful runs in this sweep, so no comparison yet.", ""]
    else:
        lines += ["| problem | scd | " + " | ".join(label(*s) for s in mebdf) + " |",
                  "|---|---|" + "---|" * len(mebdf)]
        for problem in [p for p in CPU_RATIO_PROBLEMS if p in problems]:
            base = curve(rows, problem, "cvode", 5)
            for level in range(2, 12):
                cells, any_value = [], False
                for s in mebdf:
                    a = interp_log(curve(rows, problem, *s), "cpu_time", level)
                    b = interp_log(base, "cpu_time", level)
                    if a is None or b is None:
                        cells.append("")
                    else:
                        cells.append(f"{10 ** (a - b):.2f}")
                        any_value = True
                if any_value:
                    lines.append(f"| {problem} | {level} | " + " | ".join(cells) + " |")
        lines.append("")
    lines += ["**Steps against the reference counts of the classic codes** (MEBDFI: classic "
              "Fortran, numerical Jacobian, max order 7; CVODE there: dense FD Jacobian). Our "
              "step counts are interpolated (log steps linear in scd) at the reference scd; "
              "empty where that scd is outside our sweep:", "",
              "| problem | reference rtol | MEBDFI scd / steps | "
              + " | ".join(f"{label(*s)}: steps at MEBDFI's scd" for s in settings)
              + " | CVODE ref. scd / steps | cvode (max order 5): steps at that scd |",
              "|---|---|---|" + "---|" * len(settings) + "---|---|"]
    for problem, rtol, m_scd, m_steps, c_scd, c_steps in REFERENCE_STEPS:
        if problem not in problems:
            continue
        cells = []
        for s in settings:
            v = interp_log(curve(rows, problem, *s), "steps", m_scd)
            cells.append("" if v is None else f"{10 ** v:.0f}")
        v = interp_log(curve(rows, problem, "cvode", 5), "steps", c_scd)
        ours_c = "" if v is None else f"{10 ** v:.0f}"
        lines.append(f"| {problem} | {rtol:.0e} | {m_scd:.2f} / {m_steps} | "
                     + " | ".join(cells) + f" | {c_scd:.2f} / {c_steps} | {ours_c} |")
    lines.append("")
    return lines


def write_csv(rows, path):
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=FIELDS, extrasaction="ignore")
        writer.writeheader()
        for r in rows:
            out = dict(r)
            out["rtol"] = f"{r['rtol']:.6e}"
            writer.writerow(out)


def main(argv=None):
    parser = argparse.ArgumentParser(description=summary(__doc__))
    add_exe_argument(parser)
    parser.add_argument("--methods", default="cvode,mebdf",
                        help="comma-separated methods (default: cvode,mebdf)")
    parser.add_argument("--problems", default=",".join(PROBLEMS),
                        help="comma-separated problems (default: all six)")
    parser.add_argument("--quick", action="store_true",
                        help="rtol 1e-3, 1e-5, 1e-7, 1e-9 only and 0.05 s timing")
    parser.add_argument("--repeat-time", type=float, default=None,
                        help="CPU seconds per timing (default 0.5; --quick 0.05)")
    parser.add_argument("--no-write", action="store_true",
                        help="print only: leave docs/ untouched")
    args = parser.parse_args(argv)

    methods = [m.strip().lower() for m in args.methods.split(",") if m.strip()]
    problems = [p.strip().upper() for p in args.problems.split(",") if p.strip()]
    for p in problems:
        if p not in PROBLEMS:
            parser.error(f"--problems: unknown problem {p!r} (available: {', '.join(PROBLEMS)})")
    settings = [s for s in SETTINGS if s[0] in methods]
    unknown = set(methods) - {s[0] for s in SETTINGS}
    if unknown or not settings:
        parser.error(f"--methods: unknown method(s) {sorted(unknown)} (available: cvode, mebdf)")
    m_values = QUICK_M_VALUES if args.quick else M_VALUES
    repeat_time = args.repeat_time if args.repeat_time is not None else (
        0.05 if args.quick else 0.5)

    rows, skipped = sweep(exe_or_build(args.exe), problems, settings, m_values, repeat_time)
    failed = [r for r in rows if r["status"] != "ok"]
    notes = [f"- {label(*key)} skipped: {message}" for key, message in skipped.items()]
    for key in settings:
        if key in skipped:
            continue
        n_failed = sum(1 for r in failed if (r["method"], r["max_order"]) == key)
        if n_failed:
            where = ", ".join(f"{r['problem']} rtol {r['rtol']:.0e}" for r in failed
                              if (r["method"], r["max_order"]) == key)
            notes.append(f"- {label(*key)}: {n_failed} failed run(s): {where} (messages in "
                         "docs/data/testset_wp.csv)")
    for note in notes:
        print(note)
    shown = [s for s in settings if s not in skipped]
    if args.no_write:
        print("\n".join(["", *tables(rows, problems, shown, m_values),
                         *comparison(rows, problems, shown)]))
        return 0

    data = DOCS / "data" / "testset_wp.csv"
    write_csv(rows, data)
    for problem in problems:
        plot(rows, problem, shown, DOCS / "figures" / f"wp_{problem.lower()}.png")

    stamp = run_stamp()
    command = "scripts/work_precision_testset"
    if args.quick:
        command += " --quick"
    if args.methods != "cvode,mebdf":
        command += f" --methods {args.methods}"
    if args.problems != ",".join(PROBLEMS):
        command += f" --problems {args.problems}"
    figures = ", ".join(f"[{p}](../figures/wp_{p.lower()}.png)" for p in problems)
    block = [
        BEGIN,
        f"Command: `{command}` (Release build; rtol = 10^-(3 + m/2), "
        f"m = {m_values[0]} .. {m_values[-1]}; atol: rtol, ROBER 1e-6 rtol, E5 1.7e-24; "
        f"analytic Jacobians; CPU time: median per run over >= {repeat_time:g} s).",
        f"Machine: {machine()}. Run: {stamp}.",
        "",
        f"Figures: {figures}. Raw data (all 17 tolerances, every counter): "
        "[data/testset_wp.csv](../data/testset_wp.csv).",
        "",
        *([*notes, ""] if notes else []),
        *tables(rows, problems, shown, m_values),
        *comparison(rows, problems, shown),
        END,
    ]
    doc = DOCS / "validation" / "testset.md"
    update_doc(doc, BEGIN, END, "\n".join(block), default="# Benchmarks\n",
               heading="## Stiff test problems: work-precision\n\n"
               "The six stiff problems of the Bari test set ([testset.md](../validation/testset.md)) with\n"
               "every integrator; each point is one `ropedyn testset ... --csv` run.\n\n")
    print(f"work_precision_testset: {data}, docs/figures/wp_*.png and {doc} written")
    return 0


if __name__ == "__main__":
    sys.exit(main())
