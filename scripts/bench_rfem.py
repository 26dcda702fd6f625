#!/usr/bin/env python3
"""Run the paper scene at several numbers of elements and tabulate the cost.

Called by scripts/bench_rfem (which builds the Release executable first). The table goes
into docs/benchmarks.md between the markers of the section "RFEM cost versus n"; the rest
of that file (the reading of the numbers) is kept.
"""
import argparse
import datetime
import os
import pathlib
import platform
import re
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[1]
BEGIN = "<!-- bench_rfem:begin -->"
END = "<!-- bench_rfem:end -->"


def machine():
    cpu = "unknown CPU"
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{cpu}, {os.cpu_count()} cores, {platform.system()} {platform.release()}"


def run_case(exe, n, t_end, rtol, workdir):
    out = workdir / f"bench_n{n}.h5"
    cmd = [str(exe), "run", str(ROOT / "input" / "paper.nml"),
           "--set", f"model.elements={n}", "--set", f"solver.rtol={rtol}",
           "--set", f"solver.t_end={t_end}", "--set", f"output.file={out}",
           "--set", "solver.output_interval=0.1"]
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
    parser.add_argument("--exe", required=True)
    parser.add_argument("--t-end", type=float, default=30.0)
    parser.add_argument("--rtol", type=float, default=1e-6)
    parser.add_argument("--elements", default="10 30 70 100 300 1000")
    parser.add_argument("--no-write", action="store_true", help="print only")
    args = parser.parse_args(argv)

    rows = []
    header = ("| n | steps | RHS evals | Jacobians | error-test fails | CPU (s) | "
              "CPU per step per element (us) | energy balance error (J) |")
    print(header)
    print("|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for n in map(int, args.elements.split()):
            r = run_case(args.exe, n, args.t_end, args.rtol, pathlib.Path(tmp))
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
    stamp = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
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
    doc = ROOT / "docs" / "benchmarks.md"
    text = doc.read_text() if doc.exists() else "# Benchmarks\n\n## RFEM cost versus n\n\n"
    if BEGIN in text and END in text:
        text = text[:text.index(BEGIN)] + block + text[text.index(END) + len(END):]
    else:
        text = text.rstrip() + "\n\n" + block + "\n"
    doc.write_text(text)
    print(f"bench_rfem: table written to {doc}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
