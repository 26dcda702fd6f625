"""The library's own cost: one advance call on top of the integration, from C and from
Python, and the memory over many create / advance / destroy cycles.

- Overhead of `advance`: the paper's scene with a fixed method (erk, cvode, mebdf: their
  steps do not depend on where advance stops, so both ways take the same steps and end in
  the same bits, which the table checks; auto's switching looks at the times advance is
  called at and is left out), first advanced to DT by both, then on to T in one call, and
  in calls every DT. (CPU of the many calls - CPU of the one) / calls is the cost of a
  call: the interface, the interpolation to the time asked for, the checks. Each CPU time
  the least of --repeat runs (timings on a shared VM drift by 10-20 %). From C: the
  benchmark program bench_library (tests/bench/bench_library.c); from Python: a
  ropedyn.Simulation (ctypes) the same way, in this process. Also the cost of a call with
  nothing to integrate (advance to the time reached): the interface alone.
- Memory: VmRSS after the first and every 10 % of --cycles create / init / advance (10 ms)
  / destroy cycles of a 4-element scene, from C (tests/lib/lib_memory.c) and from Python
  (Simulation in a context manager, in a child process).

The table goes between the bench_library markers of docs/performance/library.md. The code
of scripts/bench_library.
"""
import argparse
import os
import pathlib
import subprocess
import sys
import tempfile
import textwrap
import time

from ropedyn_tools.repo import DOCS, PAPER, build
from ropedyn_tools.studies.common import machine, run_stamp, update_doc
from ropedyn.docstrings import summary

BEGIN = "<!-- bench_library:begin -->"
END = "<!-- bench_library:end -->"
METHODS = ("erk", "cvode", "mebdf")

PY_OVERHEAD = textwrap.dedent("""
    import sys, time
    import numpy as np
    import ropedyn
    scene, t_end, dt, repeat = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), int(sys.argv[4])
    scene = ropedyn.Scene.from_file(scene)

    def integrate(many):
        with ropedyn.Simulation(scene) as sim:
            sim.advance(dt)
            calls = int(round(t_end / dt))
            c = time.process_time()
            if many:
                advance = sim.advance
                for k in range(2, calls + 1):
                    advance(t_end if k == calls else k * dt)
            else:
                sim.advance(t_end)
            return time.process_time() - c, sim.state, calls - 1

    one = many = float("inf")
    for _ in range(repeat):
        a, y1, _ = integrate(False)
        b, y2, calls = integrate(True)
        one, many = min(one, a), min(many, b)
    with ropedyn.Simulation(scene) as sim:
        sim.advance(0.01)
        best = float("inf")
        for _ in range(repeat):
            c = time.process_time()
            for _ in range(200000):
                sim.advance(0.01)
            best = min(best, time.process_time() - c)
    print(calls, one, many, 1e6 * (many - one) / calls, 1e9 * best / 200000,
          float(np.abs(y1 - y2).max()))
""")

PY_RSS = textwrap.dedent("""
    import sys
    import ropedyn
    cycles, every = int(sys.argv[1]), int(sys.argv[2])
    scene = ropedyn.Scene("&model\\n kind = 'rfem', elements = 4\\n/\\n&solver\\n t_end = 0.01\\n/\\n")

    def rss():
        for line in open("/proc/self/status"):
            if line.startswith("VmRSS:"):
                return int(line.split()[1])

    for k in range(1, cycles + 1):
        with ropedyn.Simulation(scene) as sim:
            sim.advance(0.01)
        if k == 1 or k % every == 0:
            print(k, rss(), flush=True)
""")


def run_lines(cmd, env):
    out = subprocess.run(cmd, capture_output=True, text=True, env=env, check=True).stdout
    return [line.split() for line in out.splitlines() if line.strip()]


def overhead_rows(bench, env, work, t_end, dt, repeat):
    import ropedyn
    rows = []
    for method in METHODS:
        scene = ropedyn.Scene.from_file(PAPER).set("solver.method", method)
        path = scene.write(work / f"paper_{method}.nml")
        for side, cmd in (("C", [str(bench), "overhead", str(path)]),
                          ("Python", [sys.executable, "-c", PY_OVERHEAD, str(path)])):
            calls, one, many, over, empty, diff = run_lines(
                cmd + [f"{t_end:g}", f"{dt:g}", str(repeat)], env)[-1]
            rows.append(f"| {method} | {side} | {int(calls)} | {float(one):.3f} "
                        f"| {float(many):.3f} | {float(over):.2f} | {float(empty):.0f} "
                        f"| {'yes' if float(diff) == 0 else 'no (' + diff + ')'} |")
            print(rows[-1], flush=True)
    return rows


def rss_rows(memory, env, cycles):
    every = max(cycles // 10, 1)
    c = run_lines([str(memory), "cycles", str(cycles), str(every)], env)
    start = time.perf_counter()
    py = run_lines([sys.executable, "-c", PY_RSS, str(cycles), str(every)], env)
    seconds = time.perf_counter() - start
    rows = [f"| {int(a[0])} | {int(a[1])} | {int(b[1])} |" for a, b in zip(c, py)]
    growth = (int(c[-1][1]) - int(c[0][1]), int(py[-1][1]) - int(py[0][1]))
    return rows, growth, seconds


def main(argv=None):
    parser = argparse.ArgumentParser(description=summary(__doc__))
    parser.add_argument("--build", default=None,
                        help="a Release build folder (default: build it with scripts/build)")
    parser.add_argument("--t-end", type=float, default=10.0)
    parser.add_argument("--dt", type=float, default=1e-4)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--cycles", type=int, default=100000)
    parser.add_argument("--no-write", action="store_true")
    args = parser.parse_args(argv)
    folder = pathlib.Path(args.build) if args.build else build("Release")
    bench, memory = folder / "tests" / "bench_library", folder / "tests" / "lib_memory"
    subprocess.run(["cmake", "--build", str(folder), "--target", "bench_library",
                    "lib_memory"], check=True, capture_output=True)
    env = dict(os.environ, ROPEDYN_LIBRARY=str(folder / "libropedyn.so"))
    os.environ["ROPEDYN_LIBRARY"] = env["ROPEDYN_LIBRARY"]
    with tempfile.TemporaryDirectory() as tmp:
        rows = overhead_rows(bench, env, pathlib.Path(tmp), args.t_end, args.dt, args.repeat)
    rss, growth, seconds = rss_rows(memory, env, args.cycles)
    for row in rss:
        print(row, flush=True)
    print(f"RSS growth over {args.cycles} cycles: C {growth[0]} KiB, Python {growth[1]} KiB")
    if args.no_write:
        return 0
    lines = [
        BEGIN,
        f"Command: `scripts/bench_library --t-end {args.t_end:g} --dt {args.dt:g} --repeat "
        f"{args.repeat} --cycles {args.cycles}` (code: "
        "tools/ropedyn_tools/studies/bench_library.py, tests/bench/bench_library.c, "
        "tests/lib/lib_memory.c; "
        "Release build). "
        f"Machine: {machine()}. Run: {run_stamp()}.", "",
        f"The paper's scene, {args.t_end:g} s, advanced every {args.dt * 1e3:g} ms (after a "
        f"first call to {args.dt:g} s) against one call; CPU the least of {args.repeat} "
        "runs:", "",
        "| method | from | calls | CPU, one call (s) | CPU, every step (s) "
        "| cost of a call (us) | empty call (ns) | same end state (bits) |",
        "|---|---|---|---|---|---|---|---|",
        *rows, "",
        f"Resident memory (VmRSS, KiB) over {args.cycles} create / init / advance / destroy "
        f"cycles of a 4-element scene (Python: {seconds:.0f} s of wall time); growth from "
        f"the first cycle to the last: C {growth[0]} KiB, Python {growth[1]} KiB:", "",
        "| cycle | C | Python |", "|---|---|---|", *rss, END]
    update_doc(DOCS / "performance" / "library.md", BEGIN, END, "\n".join(lines),
               default=PAGE)
    print(f"bench_library: {DOCS / 'performance' / 'library.md'}")
    return 0


PAGE = """# The library's own cost

What embedding ropedyn costs on top of the integration: one `advance` call, from C and
from Python, and the memory over many simulations made and freed in one process. The
integration itself costs what a command-line run costs ([cost versus the number of
elements](cost-vs-n.md)). Made by `scripts/bench_library`.

A call's cost is the difference of the CPU time of the same integration advanced every
step and in one call, divided by the calls: the interface, the interpolation to the time
asked for and the checks. The methods are the fixed ones, whose steps do not depend on
where `advance` stops (the table checks that both end in the same bits); `auto`'s
switching looks at the times it is called at, so its steps differ and the difference of
the two CPU times would not be the calls' cost. An empty call (advance to the time
reached) is the interface alone. The calls come every 0.1 ms, ten times as often as a
coupling of 1 ms would make them: a call costs the same at any interval (the interpolation
to the time asked for does not depend on it), and the difference of the two CPU times
then stands well above the drift of the timings on a shared machine (at 1 ms over 30 s,
three runs gave -11 to +5 us a call for the same code).

The memory grows over the first cycles, while the allocators fill their pools, and then
stays flat to within a few pages: a leak of the smallest allocation, 16 bytes a cycle,
would add 1.6 MB over 100,000 cycles.

<!-- bench_library:begin -->
<!-- bench_library:end -->
"""

if __name__ == "__main__":
    sys.exit(main())
