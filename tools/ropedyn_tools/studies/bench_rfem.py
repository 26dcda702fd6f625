"""Run the paper scene at several numbers of elements and tabulate the cost.

The code of scripts/bench_rfem (python -m ropedyn_tools.studies.bench_rfem; without --exe it
builds the Release executable first). Every n runs with each integrator (default: CVODE and
MEBDF, their default orders) with `&solver profile = .true.`, so the table gives the CPU time
per step and element and where it went (right-hand side, Jacobian, factorizations, solves,
the rest). The table goes into docs/performance/cost-vs-n.md between the markers of the section "RFEM
cost versus n"; the rest of that file (the reading of the numbers) is kept.
"""
import argparse
import pathlib
import subprocess
import sys
import tempfile

from ropedyn import io
from ropedyn_tools.arguments import check_names
from ropedyn_tools.repo import DOCS, PAPER, add_scaling_arguments, exe_or_build, set_args
from ropedyn_tools.studies.common import SPLIT_HEADER, machine, time_split, update_doc, run_stamp
from ropedyn.docstrings import summary

BEGIN = "<!-- bench_rfem:begin -->"
END = "<!-- bench_rfem:end -->"
HEADER = ("| n | solver | steps | RHS evals | Jacobians | factorizations | error-test fails | "
          f"CPU (s) | CPU per step per element (us) | {SPLIT_HEADER} | "
          "energy balance error (J) |")
RULE = "|---|---|---|---|---|---|---|---|---|---|---|"


def run_case(exe, n, method, t_end, rtol, workdir, extra=()):
    out = workdir / f"bench_n{n}_{method}.h5"
    cmd = [str(exe), "run", str(PAPER), *set_args([
        f"model.elements={n}", f'solver.method="{method}"', f"solver.rtol={rtol}",
        f"solver.t_end={t_end}", f'output.file="{out}"', "solver.output_interval=0.1",
        "solver.profile=.true.", *extra])]
    result = subprocess.run(cmd, capture_output=True, text=True)
    if result.returncode != 0:
        return {"n": n, "method": method, "status": f"failed ({result.stderr.strip()[:80]})"}
    run = io.load_run(out)
    return {"n": n, "method": method, "status": "complete", **run.stats,
            "balance": float(run.balance[-1] - run.e0)}


def line(r):
    """The table row of one run."""
    if r["status"] != "complete":
        return f"| {r['n']} | {r['method']} | {r['status']} |  |  |  |  |  |  |  |  |"
    per = 1e6 * r["cpu_time"] / r["steps"] / r["n"]
    return (f"| {r['n']} | {r['method']} | {r['steps']} | {r['rhs_evals']} | {r['jac_evals']} | "
            f"{r['lin_setups']} | {r['err_test_fails']} | {r['cpu_time']:.3f} | {per:.2f} | "
            f"{time_split(r)} | {r['balance']:.1e} |")


def main(argv=None):
    parser = argparse.ArgumentParser(description=summary(__doc__))
    add_scaling_arguments(parser, t_end=30.0, elements="10 30 100 300 1000")
    parser.add_argument("--solvers", default="cvode mebdf")
    parser.add_argument("--first-order-newton", action="store_true",
                        help="Newton systems on the first-order matrix (the path before the "
                             "reduced second-order one)")
    parser.add_argument("--no-write", action="store_true", help="print only")
    args = parser.parse_args(argv)
    exe = exe_or_build(args.exe)
    check_names(parser, exe, "--solvers", args.solvers.split(), "solver", "method")
    extra = ["solver.first_order_newton=.true."] if args.first_order_newton else []

    rows = []
    print(HEADER)
    print(RULE)
    with tempfile.TemporaryDirectory() as tmp:
        for n in map(int, args.elements.split()):
            for method in args.solvers.split():
                r = run_case(exe, n, method, args.t_end, args.rtol, pathlib.Path(tmp), extra)
                rows.append(line(r))
                print(rows[-1], flush=True)

    if args.no_write:
        return 0
    stamp = run_stamp()
    newton = ("first-order Newton matrix (`--first-order-newton`)" if args.first_order_newton
              else "reduced second-order Newton matrix")
    block = "\n".join([
        BEGIN,
        f"Command: `scripts/bench_rfem --t-end {args.t_end:g} --elements \"{args.elements}\" "
        f"--solvers \"{args.solvers}\"` "
        f"(rtol {args.rtol:g}, atol 1e-8, default maximum orders: CVODE BDF 5, MEBDF 4; "
        f"analytic Jacobian, {newton}; `solver.profile = .true.`: the split is measured "
        "inside the run with the monotonic clock, the rest is the CPU time less the parts).",
        f"Machine: {machine()}. Run: {stamp}.",
        "",
        HEADER,
        RULE,
        *rows,
        END,
    ])
    doc = DOCS / "performance" / "cost-vs-n.md"
    update_doc(doc, BEGIN, END, block, default="# Benchmarks\n\n## RFEM cost versus n\n\n")
    print(f"bench_rfem: table written to {doc}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
