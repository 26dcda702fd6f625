"""Cost of the RFEM and MPP ropes versus the number of elements, with CVODE and MEBDF.

The paper's Figure 4 compares the CPU time of RFEM and MPP against n: "the MPP model is
numerically more efficient only for small n". This runs input/paper.nml (75 deg release,
Table 1 damping) for a short horizon at a fixed tolerance for every (model, solver, n),
skipping the larger n of a (model, solver) once one case exceeds the time budget, and
writes a table (between the bench_models markers in docs/performance/cost-vs-n.md) and
docs/figures/cost_vs_n.png. The crossover n where RFEM becomes cheaper is printed. The runs
have `&solver profile = .true.`: the table gives the CPU time per step and where it went.
The code of scripts/bench_models (python -m ropedyn_tools.studies.bench_models).
"""
import argparse
import pathlib
import subprocess
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from ropedyn import io  # noqa: E402
from ropedyn_tools.repo import (DOCS, PAPER, add_scaling_arguments, exe_or_build,  # noqa: E402
                                set_args)
from ropedyn_tools.studies.common import (SPLIT_HEADER, machine, time_split,  # noqa: E402
                                          update_doc, run_stamp)
from ropedyn.docstrings import summary

BEGIN = "<!-- bench_models:begin -->"
END = "<!-- bench_models:end -->"


def run_case(exe, model, method, n, t_end, rtol, workdir, timeout):
    out = workdir / f"bench_{model}_{method}_{n}.h5"
    cmd = [str(exe), "run", str(PAPER), *set_args([
        f'model.kind="{model}"', f"model.elements={n}", f'solver.method="{method}"',
        f"solver.rtol={rtol}", f"solver.t_end={t_end}", f'output.file="{out}"',
        "solver.output_interval=0.1", "solver.profile=.true."])]
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return {"status": f"over {timeout:.0f} s"}
    if proc.returncode != 0:
        return {"status": "failed: " + proc.stderr.strip()[:80]}
    run = io.load_run(out)
    return {"status": "complete", "cpu": float(run.stats["cpu_time"]),
            "steps": run.stats["steps"], "rhs": run.stats["rhs_evals"],
            "jac": run.stats["jac_evals"], "split": time_split(run.stats),
            "balance": float(abs(run.balance - run.e0).max())}


def main(argv=None):
    parser = argparse.ArgumentParser(description=summary(__doc__))
    add_scaling_arguments(parser, t_end=1.0, elements="10 20 30 50 70 100 150 200 300")
    parser.add_argument("--budget", type=float, default=300.0,
                        help="skip larger n of a (model, solver) after a case above this (s)")
    parser.add_argument("--no-write", action="store_true")
    args = parser.parse_args(argv)
    exe = exe_or_build(args.exe)
    ns = [int(x) for x in args.elements.split()]
    settings = [("rfem", "cvode"), ("rfem", "mebdf"), ("mpp", "cvode"), ("mpp", "mebdf")]
    results = {}
    header = ("| model | solver | n | steps | RHS evals | Jacobians | CPU (s) | CPU per step (ms) "
              f"| CPU per step per element (us) | {SPLIT_HEADER} | balance error (J) |")
    print(header, flush=True)
    with tempfile.TemporaryDirectory() as tmp:
        for model, method in settings:
            over = False
            for n in ns:
                if over:
                    results[(model, method, n)] = {"status": "skipped (budget)"}
                    continue
                r = run_case(exe, model, method, n, args.t_end, args.rtol,
                             pathlib.Path(tmp), timeout=4 * args.budget)
                results[(model, method, n)] = r
                if r["status"] != "complete" or r["cpu"] > args.budget:
                    over = True
                print(line(model, method, n, r), flush=True)

    crossover = {}
    for method in ("cvode", "mebdf"):
        for n in ns:
            a, b = results.get(("rfem", method, n)), results.get(("mpp", method, n))
            if a and b and a["status"] == "complete" and b["status"] == "complete" \
                    and a["cpu"] < b["cpu"]:
                crossover[method] = n
                break
    best = {}
    for n in ns:
        for model in ("rfem", "mpp"):
            c = [results[(model, m, n)]["cpu"] for m in ("cvode", "mebdf")
                 if results.get((model, m, n), {}).get("status") == "complete"]
            if c:
                best[(model, n)] = min(c)
    best_cross = next((n for n in ns if (("rfem", n) in best and ("mpp", n) in best
                                         and best[("rfem", n)] < best[("mpp", n)])), None)
    for method, n in crossover.items():
        print(f"crossover with {method}: RFEM cheaper than MPP from n = {n}")
    print(f"crossover, best solver for each model: RFEM cheaper from n = {best_cross}")

    fig, ax = plt.subplots(figsize=(7, 5))
    for model, method in settings:
        xs = [n for n in ns if results[(model, method, n)].get("status") == "complete"]
        ys = [results[(model, method, n)]["cpu"] for n in xs]
        ax.loglog(xs, ys, ("-o" if model == "rfem" else "--s"), label=f"{model.upper()}, {method}")
    ax.set_xlabel("number of elements n")
    ax.set_ylabel(f"CPU time for {args.t_end:g} s of motion (s)")
    ax.set_title(f"Paper rope, rtol {args.rtol:g}: cost versus n")
    ax.grid(alpha=0.3, which="both")
    ax.legend()
    fig.tight_layout()
    if args.no_write:
        return 0
    figpath = DOCS / "figures" / "cost_vs_n.png"
    figpath.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(figpath, dpi=110)
    stamp = run_stamp()
    lines = [BEGIN,
             f"Command: `scripts/bench_models --t-end {args.t_end:g} --elements "
             f"\"{args.elements}\"` (input/paper.nml, rtol {args.rtol:g}, atol 1e-8, default "
             f"max orders: CVODE 5, MEBDF 4). Machine: {machine()}. Run: {stamp}.",
             "", "![cost versus n](../figures/cost_vs_n.png)", "", header,
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    lines += [line(m, s, n, results[(m, s, n)]) for m, s in settings for n in ns]
    lines += ["", *(f"Crossover with {m}: RFEM cheaper than MPP from n = {n}."
                    for m, n in crossover.items()),
              f"Crossover with the best solver for each model: n = {best_cross}.", END]
    doc = DOCS / "performance" / "cost-vs-n.md"
    update_doc(doc, BEGIN, END, "\n".join(lines),
               heading="## RFEM and MPP cost versus n (the paper's Figure 4)\n\n")
    print(f"bench_models: {doc}, {figpath}")
    return 0


def line(model, method, n, r):
    if r.get("status") != "complete":
        return f"| {model} | {method} | {n} | {r.get('status')} |  |  |  |  |  |  |  |"
    return (f"| {model} | {method} | {n} | {r['steps']} | {r['rhs']} | {r['jac']} | "
            f"{r['cpu']:.3f} | {1e3 * r['cpu'] / r['steps']:.3f} | "
            f"{1e6 * r['cpu'] / r['steps'] / n:.2f} | {r['split']} | {r['balance']:.1e} |")


if __name__ == "__main__":
    sys.exit(main())
