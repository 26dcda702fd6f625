"""Fit the MPP damping constants so that its energy history matches an RFEM run.

The paper matched the two models' damping "by trial and error". ropedyn's default rule
(docs/theory/mpp.md) gives the MPP the RFEM's material law: member springs d_s = eta A/l,
joints d_b = eta I/l. RFEM also dissipates in its shear dampers, which the MPP lacks, so
the histories differ. This script runs the scene with the RFEM once (the target), then
minimizes over the MPP factors (a, b) = (mpp_axial_damping_factor,
mpp_bending_damping_factor)

    S(a, b) = sum_k (E_mpp(t_k; a, b) - E_rfem(t_k))^2,   E = T + V (total energy),

with both histories averaged over windows of `--window` seconds first: the swing itself is
sensitive (nearly chaotic) and its fast exchange between kinetic and elastic energy is
not what the damping constants should be fitted to; the windowed loss is.

by Nelder-Mead on (log a, log b), and prints the fitted values, the residual RMS and the
residual of the default rule (a = b = 1). Use the printed `--set` line in a scene. The fit
is also written to docs/data/mpp_damping_fit.csv (with --data), which `scripts/fig5`
reads for its calibrated MPP runs.

    scripts/calibrate [SCENE.nml] [--elements N] [--t-fit SECONDS] [--set g.k=v ...]
"""
import argparse
import csv
import math
import subprocess
import sys
import tempfile

import numpy as np

from ropedyn import io
from ropedyn_tools.arguments import check_names
from ropedyn_tools.repo import DOCS, PAPER, add_exe_argument, exe_or_build, set_args
from ropedyn.docstrings import summary

#: where the fit is written (and scripts/fig5 reads it)
FIT_DATA = DOCS / "data" / "mpp_damping_fit.csv"


def read_fit(path=FIT_DATA):
    """The last fit written by calibrate: dict with a, b, rms_default, rms_fit, ... (None
    when there is none)."""
    if not path.exists():
        return None
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return rows[-1] if rows else None


def energy_history(exe, scene, sets, out):
    cmd = [exe, "run", scene, "--set", f'output.file="{out}"', *set_args(sets)]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        raise RuntimeError(f"ropedyn failed ({' '.join(cmd)}): {proc.stderr.strip()}")
    run = io.load_run(out)
    return run.time, run.energy["total"]


def nelder_mead(fun, x0, step=0.5, tol=1e-3, max_evals=40):
    """Minimize fun over R^d (small d) by Nelder-Mead; returns (x, f, evaluations)."""
    d = len(x0)
    pts = [np.array(x0, float)] + [np.array(x0, float) + step * np.eye(d)[i] for i in range(d)]
    vals = [fun(p) for p in pts]
    evals = d + 1
    while evals < max_evals:
        order = np.argsort(vals)
        pts = [pts[i] for i in order]
        vals = [vals[i] for i in order]
        if abs(vals[-1] - vals[0]) <= tol * max(abs(vals[0]), 1e-300) and \
                max(np.linalg.norm(p - pts[0]) for p in pts) < 0.02:
            break
        centroid = sum(pts[:-1]) / d
        xr = centroid + (centroid - pts[-1])
        fr = fun(xr)
        evals += 1
        if fr < vals[0]:
            xe = centroid + 2.0 * (centroid - pts[-1])
            fe = fun(xe)
            evals += 1
            pts[-1], vals[-1] = (xe, fe) if fe < fr else (xr, fr)
        elif fr < vals[-2]:
            pts[-1], vals[-1] = xr, fr
        else:
            xc = centroid + 0.5 * (pts[-1] - centroid)
            fc = fun(xc)
            evals += 1
            if fc < vals[-1]:
                pts[-1], vals[-1] = xc, fc
            else:
                for i in range(1, d + 1):
                    pts[i] = pts[0] + 0.5 * (pts[i] - pts[0])
                    vals[i] = fun(pts[i])
                    evals += 1
    i = int(np.argmin(vals))
    return pts[i], vals[i], evals


def main(argv=None):
    parser = argparse.ArgumentParser(description=summary(__doc__))
    parser.add_argument("scene", nargs="?", default=str(PAPER))
    add_exe_argument(parser)
    parser.add_argument("--elements", type=int, default=10)
    parser.add_argument("--t-fit", type=float, default=5.0, help="fitted time span (s)")
    parser.add_argument("--method", default="auto")
    parser.add_argument("--data", default=str(FIT_DATA),
                        help="CSV the fit is written to ('' for none)")
    parser.add_argument("--max-evals", type=int, default=30)
    parser.add_argument("--window", type=float, default=0.5,
                        help="averaging window of the energy histories (s)")
    parser.add_argument("--set", action="append", default=[], dest="sets")
    args = parser.parse_args(argv)
    exe = exe_or_build(args.exe)
    check_names(parser, exe, "--method", [args.method], "solver", "method")

    common = [f"model.elements={args.elements}", f"solver.t_end={args.t_fit}",
              f'solver.method="{args.method}"', "solver.output_interval=0.05"] + args.sets
    with tempfile.TemporaryDirectory() as tmp:
        t_ref, e_ref = energy_history(exe, args.scene, common + ['model.kind="rfem"'],
                                      f"{tmp}/rfem.h5")
        width = max(1, int(round(args.window / 0.05)))

        def windowed(e):
            m = len(e) // width
            return e[:m * width].reshape(m, width).mean(axis=1)

        e_ref = windowed(e_ref)
        cache = {}

        def objective(x):
            a, b = math.exp(x[0]), math.exp(x[1])
            key = (round(x[0], 6), round(x[1], 6))
            if key not in cache:
                # a file of its own: ropedyn does not replace the file of another run
                _, e = energy_history(exe, args.scene, common + [
                    'model.kind="mpp"', f"model.mpp_axial_damping_factor={a:.6g}",
                    f"model.mpp_bending_damping_factor={b:.6g}"],
                    f"{tmp}/mpp_{len(cache)}.h5")
                e = windowed(e)
                m = min(len(e), len(e_ref))
                cache[key] = float(np.sum((e[:m] - e_ref[:m]) ** 2))
                print(f"  a = {a:9.4g}  b = {b:9.4g}  rms = {math.sqrt(cache[key] / m):.4e} J",
                      flush=True)
            return cache[key]

        n = len(e_ref)
        s_default = objective(np.zeros(2))
        x, s_fit, evals = nelder_mead(objective, np.zeros(2), max_evals=args.max_evals)
    a, b = math.exp(x[0]), math.exp(x[1])
    drop = e_ref[0] - e_ref[-1]
    print(f"calibrate: scene {args.scene}, n = {args.elements}, {args.t_fit} s, "
          f"{n} windows of {args.window} s, RFEM energy loss {drop:.4e} J, {evals} MPP runs")
    print(f"  default rule (a = b = 1): rms {math.sqrt(s_default / n):.4e} J")
    print(f"  fitted  a = {a:.4g}, b = {b:.4g}: rms {math.sqrt(s_fit / n):.4e} J")
    print(f"  use: --set model.mpp_axial_damping_factor={a:.4g} "
          f"--set model.mpp_bending_damping_factor={b:.4g}")
    if args.data:
        with open(args.data, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["scene", "elements", "t_fit_s", "window_s", "method", "mpp_runs",
                        "a", "b", "rms_default_J", "rms_fit_J", "rfem_energy_loss_J"])
            w.writerow([args.scene.split("/")[-1], args.elements, args.t_fit, args.window,
                        args.method, evals, f"{a:.4g}", f"{b:.4g}",
                        f"{math.sqrt(s_default / n):.4e}", f"{math.sqrt(s_fit / n):.4e}",
                        f"{drop:.4e}"])
        print(f"calibrate: wrote {args.data}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
