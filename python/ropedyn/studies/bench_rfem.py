"""Run the paper scene at several numbers of elements and tabulate the cost.

The code of scripts/bench_rfem (python -m ropedyn.studies.bench_rfem; without --exe it
builds the Release executable first). The table goes into docs/benchmarks.md between the
markers of the section "RFEM cost versus n"; the rest of that file (the reading of the
numbers) is kept.
"""
import argparse
import pathlib
import re
import subprocess
import sys
import tempfile

from ropedyn.run import DOCS, PAPER, add_exe_argument, exe_or_build, set_args
from ropedyn.studies.common import machine, update_doc, utc_stamp

BEGIN = "<!-- bench_rfem:begin -->"
END = "<!-- bench_rfem:end -->"


def run_case(exe, n, t_end, rtol, workdir):
    out = workdir / f"bench_n{n}.h5"
    cmd = [str(exe), "run", str(PAPER), *set_args([
        f"model.elements={n}", f"solver.rtol={rtol}", f"solver.t_end={t_end}",
        f"output.file={out}", "solver.output_interval=0.1"])]
    result = subprocess.run(cmd, capture_output=True, text=True)
    text = result.stdout
    if result.returncode != 0:
        return {"n": n, "status": f"failed ({result.stderr.strip()})"}
    steps = re.search(r"steps\s+(\d+)\s+rhs evals\s+(\d+)\s+jacobians\s+(\d+)"
                      r"\s+error-test fails\s+(\d+)", text)
    cpu = re.search(r"cpu time\s+([0-9.]+)", text)
    bal = re.search(r"balance error \(T\+V\+dissipated-E0\)\s+(\S+)", text)
    return {"n": n, "status": "complete", "steps": int(steps.group(1)),
            "rhs": int(steps.group(2)), "jac": int(steps.group(3)),
            "fails": int(steps.group(4)), "cpu": float(cpu.group(1)),
            "balance": float(bal.group(1))}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_exe_argument(parser)
    parser.add_argument("--t-end", type=float, default=30.0)
    parser.add_argument("--rtol", type=float, default=1e-6)
    parser.add_argument("--elements", default="10 30 70 100 300 1000")
    parser.add_argument("--no-write", action="store_true", help="print only")
    args = parser.parse_args(argv)
    exe = exe_or_build(args.exe)

    rows = []
    header = ("| n | steps | RHS evals | Jacobians | error-test fails | CPU (s) | "
              "CPU per step per element (us) | energy balance error (J) |")
    print(header)
    print("|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for n in map(int, args.elements.split()):
            r = run_case(exe, n, args.t_end, args.rtol, pathlib.Path(tmp))
            if r["status"] != "complete":
                line = f"| {n} | {r['status']} |  |  |  |  |  |  |"
            else:
                per = 1e6 * r["cpu"] / r["steps"] / n
                line = (f"| {n} | {r['steps']} | {r['rhs']} | {r['jac']} | {r['fails']} | "
                        f"{r['cpu']:.3f} | {per:.2f} | {r['balance']:.1e} |")
            print(line, flush=True)
            rows.append(line)

    if args.no_write:
        return 0
    stamp = utc_stamp()
    block = "\n".join([
        BEGIN,
        f"Command: `scripts/bench_rfem --t-end {args.t_end:g} --elements \"{args.elements}\"` "
        f"(rtol {args.rtol:g}, atol 1e-8, CVODE BDF max order 5, band LU, analytic Jacobian).",
        f"Machine: {machine()}. Run: {stamp}.",
        "",
        header,
        "|---|---|---|---|---|---|---|---|",
        *rows,
        END,
    ])
    doc = DOCS / "benchmarks.md"
    update_doc(doc, BEGIN, END, block, default="# Benchmarks\n\n## RFEM cost versus n\n\n")
    print(f"bench_rfem: table written to {doc}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
