"""Benchmark of the local sweep runner: wall time of one sweep with 1 and with 2 workers.

The code of scripts/bench_sweep (python -m ropedyn_tools.studies.bench_sweep; without --exe it
builds the Release executable first). The sweep is 16
cases of the paper scene (n = 30, 1 s, CVODE and MEBDF, two tolerances, two release angles,
two dampings), each run with `ropedyn sweep --force` into a fresh directory; the median wall
time of --repeat runs per worker count gives the speed-up. The result goes into
docs/performance/sweeps.md between the markers of the section "Sweep runner: parallel workers".
"""
import argparse
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

from ropedyn_tools.repo import DOCS, PAPER, add_exe_argument, exe_or_build
from ropedyn_tools.studies.common import machine, update_doc, run_stamp

BEGIN = "<!-- bench_sweep:begin -->"
END = "<!-- bench_sweep:end -->"
SWEEP = """&sweep
    base = '{base}'
    output_dir = 'out'
    elements = 30
    vary = 'initial.angle_deg = 60; 75', 'rope.normal_damping = 1e3; 500'
    methods = 'cvode', 'mebdf'
    rtols = 1e-5, 1e-6
    set = 'solver.t_end={t_end}'
/
"""


SPIN = "x = 0\nfor i in range(15_000_000):\n    x += i\n"


def machine_capacity():
    """Speed-up of two independent CPU-bound processes over one (about 2 on an idle
    2-core machine): what any 2-worker run can get out of the machine right now."""
    def spin(count):
        t0 = time.monotonic()
        procs = [subprocess.Popen([sys.executable, "-c", SPIN]) for _ in range(count)]
        for proc in procs:
            proc.wait()
        return time.monotonic() - t0
    one, two = spin(1), spin(2)
    return 2 * one / two


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    add_exe_argument(p)
    p.add_argument("--t-end", type=float, default=1.0)
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--no-write", action="store_true")
    args = p.parse_args(argv)
    exe = pathlib.Path(exe_or_build(args.exe)).resolve()
    walls = {1: [], 2: []}
    load_before = os.getloadavg()[0]
    cpu_total = None
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        sweep = tmp / "bench.nml"
        sweep.write_text(SWEEP.format(base=PAPER, t_end=args.t_end))
        n = int(subprocess.run([str(exe), "sweep", str(sweep), "--count"], check=True,
                               capture_output=True, text=True).stdout)
        capacity = []
        for rep in range(args.repeat):
            capacity.append(machine_capacity())
            for jobs in (1, 2):
                t0 = time.monotonic()
                r = subprocess.run([str(exe), "sweep", str(sweep), "--jobs", str(jobs),
                                    "--force", "--quiet"], cwd=tmp, capture_output=True,
                                   text=True)
                wall = time.monotonic() - t0
                if r.returncode != 0:
                    sys.exit(f"bench_sweep: sweep failed:\n{r.stderr}")
                walls[jobs].append(wall)
                print(f"bench_sweep: {jobs} worker(s): {wall:.2f} s", file=sys.stderr)
        import csv
        with open(tmp / "out" / "summary.csv") as f:
            cpu_total = sum(float(row["cpu_time"]) for row in csv.DictReader(f))
    load_after = os.getloadavg()[0]
    w1, w2 = statistics.median(walls[1]), statistics.median(walls[2])
    speedup = w1 / w2
    best = min(walls[1]) / min(walls[2])
    cap = statistics.median(capacity)
    print(f"bench_sweep: {n} cases, median wall 1 worker {w1:.2f} s, 2 workers {w2:.2f} s, "
          f"speed-up {speedup:.2f} (fastest runs: {best:.2f}); two CPU-bound processes: "
          f"{cap:.2f}")
    if args.no_write:
        return
    stamp = run_stamp()
    block = "\n".join([
        BEGIN,
        f"Command: `scripts/bench_sweep` (Release; {n} cases of the paper scene, n = 30, "
        f"t = {args.t_end:g} s, CVODE and MEBDF, rtol 1e-5 and 1e-6, two release angles and "
        f"two dampings; `ropedyn sweep --force --quiet`, {args.repeat} runs each, interleaved).",
        f"Machine: {machine()}. Run: {stamp}. Load average (1 min) before / after: "
        f"{load_before:.1f} / {load_after:.1f} (a speed-up needs a second idle core: other "
        "processes on the machine lower it)"
        + (f"; run at nice {os.nice(0)} to take the cores from other processes "
           f"(`nice -n {os.nice(0)} scripts/bench_sweep`)." if os.nice(0) < 0 else "."),
        "",
        "| workers | wall time (s), fastest | median | runs (s) |",
        "|---|---|---|---|",
        f"| 1 | {min(walls[1]):.2f} | {w1:.2f} | {', '.join(f'{w:.2f}' for w in walls[1])} |",
        f"| 2 | {min(walls[2]):.2f} | {w2:.2f} | {', '.join(f'{w:.2f}' for w in walls[2])} |",
        "",
        f"**Speed-up with 2 workers: {best:.2f}** (fastest run of each, the least disturbed "
        f"by other processes; medians: {speedup:.2f}; target >= 1.8). Sum of the cases' "
        f"CPU times: {cpu_total:.2f} s.",
        "",
        f"What the machine allowed: two independent CPU-bound processes ran "
        f"{cap:.2f} times as fast as one (median of "
        f"{', '.join(f'{c:.2f}' for c in capacity)}; 2.0 on two idle cores). The sweep "
        f"runner's median speed-up was {speedup / cap:.0%} of that.",
        END])
    update_doc(DOCS / "performance" / "sweeps.md", BEGIN, END, block, strip="\n",
               heading="## Sweep runner: parallel workers\n\n"
               "`ropedyn sweep` runs each case in its own process; this measures what a "
               "second worker buys on a 2-core machine. The section between the markers is "
               "rewritten by `scripts/bench_sweep`.\n\n")
    print("bench_sweep: wrote docs/performance/sweeps.md", file=sys.stderr)


if __name__ == "__main__":
    sys.exit(main())
