"""The paper's Figure 5: total energy E(t) - E0 of the RFEM and MPP ropes.

Runs input/paper.nml (released from 75 deg, Table 1 damping 1e3/400) with both models at
n = 30 and n = 70 for 30 s, the MPP twice: with the default damping rule (factors a = b = 1)
and with the factors fitted to the RFEM's energy history by `scripts/calibrate` (read from
docs/data/mpp_damping_fit.csv). Plots T + V - E0 and the energy-balance error of each run;
writes docs/figures/fig5_energy.png, docs/data/fig5_energy.csv and the section of
docs/validation/fig5.md between its fig5 markers (with --no-write: none of them, it
prints the runs only). The code of scripts/fig5 (python -m
ropedyn_tools.studies.fig5).
"""
import argparse
import concurrent.futures as cf
import csv
import pathlib
import subprocess
import sys
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from ropedyn import io  # noqa: E402
from ropedyn_tools.arguments import check_names, list_text, positive  # noqa: E402
from ropedyn_tools.repo import (DOCS, PAPER, ROOT, add_exe_argument, exe_or_build,  # noqa: E402
                                set_args)
from ropedyn_tools.studies.calibrate import FIT_DATA, read_fit  # noqa: E402
from ropedyn_tools.studies.common import machine, update_doc, run_stamp  # noqa: E402
from ropedyn.docstrings import summary

PAGE = DOCS / "validation" / "fig5.md"
BEGIN, END = "<!-- fig5:begin -->", "<!-- fig5:end -->"


def run_case(exe, case, t_end, method, outdir):
    model, n, (a, b) = case
    out = outdir / f"fig5_{model}_{n}_{a}_{b}.h5"
    sets = [f'model.kind="{model}"', f"model.elements={n}", f"solver.t_end={t_end}",
            f'solver.method="{method}"', f'output.file="{out}"']
    if model == "mpp":
        sets += [f"model.mpp_axial_damping_factor={a}", f"model.mpp_bending_damping_factor={b}"]
    proc = subprocess.run([exe, "run", str(PAPER), *set_args(sets)], capture_output=True,
                          text=True)
    if proc.returncode != 0:
        raise RuntimeError(f"{model} n={n}: {proc.stderr.strip()}")
    return case, out


def label(case):
    model, n, (a, b) = case
    if model == "rfem":
        return f"RFEM n = {n}"
    return f"MPP n = {n}, " + ("a = b = 1" if (a, b) == ("1", "1") else f"a = {a}, b = {b}")


def main(argv=None):
    parser = argparse.ArgumentParser(description=summary(__doc__))
    add_exe_argument(parser)
    parser.add_argument("--t-end", type=float, default=30.0)
    parser.add_argument("--method", default="auto")
    parser.add_argument("--elements", type=list_text(positive(int), ","), default="30,70")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--outdir", default=str(ROOT / "out" / "fig5"))
    parser.add_argument("--figure", default=str(DOCS / "figures" / "fig5_energy.png"))
    parser.add_argument("--no-write", action="store_true",
                        help=f"print only: no figure, data or section of {PAGE.name}")
    args = parser.parse_args(argv)
    exe = exe_or_build(args.exe)
    check_names(parser, exe, "--method", [args.method], "solver", "method")
    outdir = pathlib.Path(args.outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    fit = read_fit()
    factors = [("1", "1")] + ([(fit["a"], fit["b"])] if fit else [])
    ns = [int(x) for x in args.elements.split(",")]
    cases = [("rfem", n, ("1", "1")) for n in ns] + \
        [("mpp", n, f) for n in ns for f in factors]
    wall0 = time.perf_counter()
    with cf.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        futures = [pool.submit(run_case, exe, c, args.t_end, args.method, outdir)
                   for c in cases]
        results = [f.result() for f in futures]

    fig, (ax, axb) = plt.subplots(2, 1, figsize=(8, 7), sharex=True,
                                  gridspec_kw={"height_ratios": [3, 1]})
    rows = []
    for case, path in results:
        model, n, (a, b) = case
        run = io.load_run(path)
        t, total, e0 = run.time, run.energy["total"], run.e0
        cpu, steps = float(run.stats["cpu_time"]), run.stats["steps"]
        balance = run.balance - e0
        style = "-" if model == "rfem" else ("--" if (a, b) == ("1", "1") else ":")
        ax.plot(t, total - e0, style, label=label(case))
        axb.plot(t, balance, style, label=label(case))
        rows.append({"model": model, "n": n, "axial_factor": a, "bending_factor": b,
                     "t_end": t[-1], "E_end_minus_E0_J": total[-1] - e0,
                     "dissipated_J": run.energy["dissipated"][-1],
                     "max_balance_error_J": abs(balance).max(),
                     "steps": steps, "cpu_s": cpu})
        print(f"{label(case)}: E(t_end) - E0 = {total[-1] - e0:.5f} J, "
              f"balance error max {abs(balance).max():.2e} J, {steps} steps, {cpu:.2f} s CPU")
    ax.set_ylabel("E(t) - E0 = T + V - E0 (J)")
    ax.set_title(f"Paper rope from 75 deg, Table 1 damping, method {args.method}")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    axb.set_ylabel("balance error (J)")
    axb.set_xlabel("t (s)")
    axb.grid(alpha=0.3)
    if args.no_write:
        return 0
    fig.tight_layout()
    pathlib.Path(args.figure).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.figure, dpi=110)
    data = DOCS / "data" / "fig5_energy.csv"
    data.parent.mkdir(parents=True, exist_ok=True)
    with open(data, "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    print(f"fig5: {args.figure}, {data}")
    update_doc(PAGE, BEGIN, END, section(rows, fit, args, time.perf_counter() - wall0))
    print(f"fig5: wrote the section of {PAGE}")
    return 0


def section(rows, fit, args, seconds):
    """The Figure 5 section of docs/validation/fig5.md: the runs' table and the calibration."""
    lines = [BEGIN, "",
             f"Written by `scripts/fig5` (method `{args.method}`, {args.t_end:g} s from 75°, "
             f"Table 1 damping 10³/400; {seconds / 60:.1f} min, {run_stamp()}, "
             f"{machine()}) → [figures/fig5_energy.png](../figures/fig5_energy.png), data in "
             "[data/fig5_energy.csv](../data/fig5_energy.csv). The MPP runs twice: with the "
             "default damping rule (member springs ηA/l, joints ηI/l: factors a = b = 1) and "
             "with the factors `scripts/calibrate` fitted to the RFEM's energy history "
             f"([data/{FIT_DATA.name}](../data/{FIT_DATA.name})).", "",
             "![E(t) - E0 of RFEM and MPP](../figures/fig5_energy.png)", "",
             "| model | n | MPP damping factors a, b | E(30 s) − E0 (J) | max balance error (J) "
             "| steps | CPU (s) |", "|---|---|---|---|---|---|---|"]
    for r in rows:
        ab = "–" if r["model"] == "rfem" else f"{r['axial_factor']}, {r['bending_factor']}"
        lines.append(f"| {r['model'].upper()} | {r['n']} | {ab} | {r['E_end_minus_E0_J']:.5f} | "
                     f"{r['max_balance_error_J']:.1e} | {r['steps']} | {r['cpu_s']:.2f} |")
    if fit:
        lines += ["", f"Calibration (`scripts/calibrate`, {fit['scene']}, n = {fit['elements']}, "
                  f"{fit['t_fit_s']} s, energies averaged over {fit['window_s']} s windows, "
                  f"{fit['mpp_runs']} MPP runs, method {fit['method']}): a = {fit['a']} (member "
                  f"springs), b = {fit['b']} (joints); the RMS mismatch of the windowed energy "
                  f"falls from {float(fit['rms_default_J']):.2e} J (a = b = 1) to "
                  f"{float(fit['rms_fit_J']):.2e} J, on an RFEM energy loss of "
                  f"{float(fit['rfem_energy_loss_J']):.3g} J over the fit."]
    else:
        lines += ["", "(No calibration yet: run `scripts/calibrate`, then this script.)"]
    lines.append("")
    # the gap between the models at the end, per n, default and calibrated
    for n in dict.fromkeys(r["n"] for r in rows):
        e = {(r["model"], r["axial_factor"]): r["E_end_minus_E0_J"] for r in rows if r["n"] == n}
        rf = e.get(("rfem", "1"))
        parts = [f"{label(('mpp', n, (r['axial_factor'], r['bending_factor'])))}: "
                 f"{r['E_end_minus_E0_J'] - rf:+.4f} J" for r in rows
                 if r["n"] == n and r["model"] == "mpp" and rf is not None]
        if parts:
            lines.append(f"- n = {n}, E(30 s) of the MPP minus the RFEM's: " + "; ".join(parts)
                         + ".")
    lines += ["", END]
    return "\n".join(lines)


if __name__ == "__main__":
    sys.exit(main())
