"""The paper's Figure 5: total energy E(t) - E0 of the RFEM and MPP ropes.

Runs input/paper.nml (released from 75 deg, Table 1 damping 1e3/400) with both models at
n = 30 and n = 70 for 30 s, then plots T + V - E0 and the energy-balance error of each run.
Writes docs/figures/fig5_energy.png and docs/data/fig5_energy.csv (final values).
The code of scripts/fig5 (python -m ropedyn.studies.fig5).
"""
import argparse
import concurrent.futures as cf
import csv
import pathlib
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from ropedyn import io  # noqa: E402
from ropedyn.run import DOCS, PAPER, ROOT, add_exe_argument, exe_or_build, set_args  # noqa: E402


def run_case(exe, model, n, t_end, method, outdir):
    out = outdir / f"fig5_{model}_{n}.h5"
    cmd = [exe, "run", str(PAPER), *set_args([
        f'model.kind="{model}"', f"model.elements={n}", f"solver.t_end={t_end}",
        f'solver.method="{method}"', f'output.file="{out}"'])]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        raise RuntimeError(f"{model} n={n}: {proc.stderr.strip()}")
    return model, n, out


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_exe_argument(parser)
    parser.add_argument("--t-end", type=float, default=30.0)
    parser.add_argument("--method", default="mebdf", choices=["cvode", "mebdf"])
    parser.add_argument("--elements", default="30,70")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--outdir", default=str(ROOT / "out" / "fig5"))
    parser.add_argument("--figure", default=str(DOCS / "figures" / "fig5_energy.png"))
    args = parser.parse_args(argv)
    exe = exe_or_build(args.exe)
    outdir = pathlib.Path(args.outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    ns = [int(x) for x in args.elements.split(",")]
    cases = [(m, n) for n in ns for m in ("rfem", "mpp")]
    with cf.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        futures = [pool.submit(run_case, exe, m, n, args.t_end, args.method, outdir)
                   for m, n in cases]
        results = [f.result() for f in futures]

    fig, (ax, axb) = plt.subplots(2, 1, figsize=(8, 7), sharex=True,
                                  gridspec_kw={"height_ratios": [3, 1]})
    rows = []
    styles = {"rfem": "-", "mpp": "--"}
    for model, n, path in results:
        run = io.load_run(path)
        t, total, dissipated = run.time, run.energy["total"], run.energy["dissipated"]
        cpu, steps = float(run.stats["cpu_time"]), run.stats["steps"]
        e0 = total[0]
        balance = total + dissipated - e0
        ax.plot(t, total - e0, styles[model], label=f"{model.upper()} n = {n}")
        axb.plot(t, balance, styles[model], label=f"{model.upper()} n = {n}")
        rows.append({"model": model, "n": n, "t_end": t[-1], "E_end_minus_E0_J": total[-1] - e0,
                     "dissipated_J": dissipated[-1], "max_balance_error_J": abs(balance).max(),
                     "steps": steps, "cpu_s": cpu})
        print(f"{model:4s} n = {n:3d}: E(t_end) - E0 = {total[-1] - e0:.5f} J, "
              f"balance error max {abs(balance).max():.2e} J, {steps} steps, {cpu:.1f} s CPU")
    ax.set_ylabel("E(t) - E0 = T + V - E0 (J)")
    ax.set_title(f"Paper rope from 75 deg, Table 1 damping, {args.method}")
    ax.legend()
    ax.grid(alpha=0.3)
    axb.set_ylabel("balance error (J)")
    axb.set_xlabel("t (s)")
    axb.grid(alpha=0.3)
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
    return 0


if __name__ == "__main__":
    sys.exit(main())
