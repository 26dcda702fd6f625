"""Auto's choice on every scene: `method = 'auto'` against each fixed method.

Runs every scene of input/ and input/hard/ with auto (the default) and with cvode, adams,
mebdf, erk and the symplectic method (each at its default order limit), all with the scene's own tolerances and
the same horizon, and writes a table between the auto_table markers of docs/performance/auto.md:
the scene, auto's choice and switches (time: method/order limit), auto's CPU time, the
fastest fixed method and its CPU time, and auto's CPU over the best's (target: <= 1.3).

- **Horizon**: the scene's t_end, shortened when auto's full run would take more than
  `--budget` s of CPU (predicted from a run over a twentieth of it; the horizon is then cut
  to a round value that fits the budget, and the table says so).
- **CPU**: the run's /solver/cpu_time (integration and output), the minimum of `--repeat`
  runs (more, up to 8, while they add up to less than 1 s); a fixed method is given
  max(`--cap-factor` x auto's CPU, `--cap-min` s) of CPU
  (RLIMIT_CPU) and shows as "> cap" when it needs more, or "failed" (exit code 3: a
  diagnosis, e.g. erk or adams held by stability) when it gives up; a fixed method that does
  not finish cannot be the best.
- The scenes' own `method` keys are overridden.
- A scene on which auto or a fixed method runs out of the step budget (`&solver
  max_steps`, by default 1e6 or 5e4 per second of t_end) is run again, with every method,
  at max_steps = 1e7, and says so: the table compares costs, the budget is a separate
  question.

The code of scripts/auto_table.
"""
import argparse
import math
import pathlib
import resource
import subprocess
import sys
import tempfile

import h5py

from ropedyn_tools.repo import DOCS, INPUT, add_exe_argument, exe_or_build, set_args
from ropedyn_tools.studies.common import (distinct_runs, machine, scene_number, update_doc,
                                          run_stamp)
from ropedyn.docstrings import summary

BEGIN = "<!-- auto_table:begin -->"
END = "<!-- auto_table:end -->"
FIXED = ("cvode", "adams", "mebdf", "erk", "symplectic")
#: how a method says it does not take a scene at all (the symplectic method on the MPP or
#: with ground contact): shown as n/a, not as a failure
REFUSED = "cannot integrate the"
ROUND = (1.0, 2.0, 5.0)


def scenes():
    return sorted(INPUT.glob("*.nml")) + sorted((INPUT / "hard").glob("*.nml"))


def scene_t_end(path):
    """The scene's t_end (s) from its text (ropedyn's default when absent)."""
    return scene_number(path, "t_end", 1.0)


def round_down(x):
    """The largest 1, 2, 5 x 10^k not above x."""
    k = math.floor(math.log10(x))
    return max(m * 10.0 ** k for m in ROUND if m * 10.0 ** k <= x * (1 + 1e-12))


def run(exe, scene, work, method, t_end, cap=None, extra=(), points=False):
    """One run with at most `cap` s of CPU: its status, CPU, steps and switches (and with
    `points`, /rope/points)."""
    out = work / f"{scene.stem}_{method}.h5"
    sets = [f"solver.t_end={t_end:.10g}", f'output.file="{out}"', f'solver.method="{method}"',
            *extra]

    def limit():
        if cap is not None:
            c = int(math.ceil(cap))
            resource.setrlimit(resource.RLIMIT_CPU, (c, c + 1))

    proc = subprocess.run([str(exe), "run", str(scene), *set_args(sets)], capture_output=True,
                          text=True, preexec_fn=limit, cwd=work)
    if proc.returncode != 0:
        # a run killed at its cap leaves its partial file and lock, which ropedyn keeps
        # for --resume: the next run into the same file (the pass at max_steps 1e7)
        # would be refused and show as failed
        for left in work.glob(out.name + ".*"):
            left.unlink()
        if proc.returncode < 0 or proc.returncode in (137, 152):
            return {"status": "cap"}
        reason = (proc.stderr.strip().splitlines()[-1] if proc.stderr.strip()
                  else f"exit code {proc.returncode}")
        return {"status": "n/a" if REFUSED in reason else "failed", "reason": reason[:200]}
    with h5py.File(out, "r") as f:
        cpu = float(f["solver/cpu_time"][()])
        steps = int(f["solver/steps"][()])
        switches = []
        if "solver/switch_time" in f:
            for t, m, o in zip(f["solver/switch_time"][()], f["solver/switch_method"][()],
                               f["solver/switch_max_order"][()]):
                switches.append((float(t), m.decode().strip(), int(o)))
        rope = f["rope/points"][()] if points else None
    out.unlink()
    return {"status": "complete", "cpu": cpu, "steps": steps, "switches": switches,
            "points": rope}


def best_of(exe, scene, work, method, t_end, repeat, cap=None, extra=(), points=False):
    """The run with the least CPU of `repeat` (a failed or capped run is returned at once)."""
    best, spent, runs = None, 0.0, 0
    # short runs are repeated more (up to 8 runs or 1 s of CPU): their minimum is noisy
    while runs < repeat or (spent < 1.0 and runs < 8):
        r = run(exe, scene, work, method, t_end, cap, extra, points)
        if r["status"] != "complete":
            return r
        runs += 1
        spent += r["cpu"]
        if best is None or r["cpu"] < best["cpu"]:
            best = r
    return best


def out_of_steps(r):
    """Whether the run `r` failed because it ran out of its step budget."""
    return r["status"] == "failed" and "max_steps" in r.get("reason", "")


def choice_text(switches):
    """'m o, t s: m o, ...' of a run's switches (time, method, order limit): the first
    three and how many there were when more than four. An event that keeps the method
    and its order limit (the symplectic method's change of step, a note) is not one."""
    switches = distinct_runs(switches, key=lambda x: x[1:])
    if not switches:
        return ""
    parts = [f"{m} {o}" if i == 0 else f"{t:.3g} s: {m} {o}"
             for i, (t, m, o) in enumerate(switches)]
    if len(parts) > 4:
        parts = parts[:3] + [f"... ({len(switches) - 1} switches)"]
    return ", ".join(parts)


def main(argv=None):
    parser = argparse.ArgumentParser(description=summary(__doc__))
    add_exe_argument(parser)
    parser.add_argument("--budget", type=float, default=20.0,
                        help="CPU (s) of auto's run above which the horizon is shortened")
    parser.add_argument("--repeat", type=int, default=2, help="runs per method (minimum CPU)")
    parser.add_argument("--cap-factor", type=float, default=4.0)
    parser.add_argument("--cap-min", type=float, default=3.0)
    parser.add_argument("--scenes", nargs="*", help="only these scene files")
    parser.add_argument("--no-write", action="store_true")
    args = parser.parse_args(argv)
    exe = exe_or_build(args.exe)
    todo = [pathlib.Path(s).resolve() for s in args.scenes] if args.scenes else scenes()
    header = ("| scene | horizon (s) | auto's choice (t: method max order) | auto CPU (s) "
              "| cvode | adams | mebdf | erk | symplectic | best fixed | auto / best |")
    rows = []
    print(header, flush=True)
    with tempfile.TemporaryDirectory() as tmp:
        work = pathlib.Path(tmp)
        for scene in todo:
            name = str(scene.relative_to(INPUT.parent))
            full = scene_t_end(scene)
            horizon, note = full, ""
            probe = run(exe, scene, work, "auto", full / 20, cap=args.budget)
            if probe["status"] == "complete" and 20 * probe["cpu"] > args.budget:
                horizon = round_down(full * args.budget / (20 * probe["cpu"]))
                note = f" (of {full:g})"
            # at the default step budget, then at 1e7 when any method ran out of it
            for extra in ((), ("solver.max_steps=10000000",)):
                auto = best_of(exe, scene, work, "auto", horizon, args.repeat,
                               cap=4 * args.budget, extra=extra)
                fixed = {}
                if auto["status"] == "complete":
                    cap = max(args.cap_factor * auto["cpu"], args.cap_min)
                    fixed = {m: best_of(exe, scene, work, m, horizon, args.repeat, cap=cap,
                                        extra=extra) for m in FIXED}
                if not any(out_of_steps(r) for r in (auto, *fixed.values())):
                    break
            if extra:
                note += ", max_steps 1e7"
            if auto["status"] != "complete":
                row = (f"| {name} | {horizon:g}{note} | auto {auto['status']}: "
                       f"{auto.get('reason', '')} | | | | | | | | |")
                rows.append(row)
                print(row, flush=True)
                continue
            cells, best = [], None
            for m, r in fixed.items():
                if r["status"] == "complete":
                    cells.append(f"{r['cpu']:.3g}")
                    if best is None or r["cpu"] < best[1]:
                        best = (m, r["cpu"])
                elif r["status"] == "cap":
                    cells.append(f"> {cap:.3g}")
                elif r["status"] == "n/a":
                    cells.append("n/a")
                else:
                    cells.append("failed")
            if best is None:
                best_text, ratio = f"none within {cap:.3g} s", f"< {auto['cpu'] / cap:.2f}"
            else:
                best_text, ratio = f"{best[0]} {best[1]:.3g}", f"{auto['cpu'] / best[1]:.2f}"
            row = (f"| {name} | {horizon:g}{note} | {choice_text(auto['switches'])} "
                   f"| {auto['cpu']:.3g} | {' | '.join(cells)} | {best_text} | {ratio} |")
            rows.append(row)
            print(row, flush=True)
    if args.no_write or args.scenes:
        return 0
    lines = [BEGIN,
             f"Command: `scripts/auto_table --budget {args.budget:g} --repeat {args.repeat}` "
             f"(code: tools/ropedyn_tools/studies/auto_table.py). Every scene with its own "
             f"tolerances; the horizon is the scene's t_end, cut to a round value where "
             f"auto's full run would take more than {args.budget:g} s CPU (the full t_end "
             f"in brackets), the same for all methods. CPU: /solver/cpu_time, the minimum of "
             f"{args.repeat} runs (up to 8 while they add up to less than 1 s); a fixed "
             f"method gets max({args.cap_factor:g} x auto's CPU, "
             f"{args.cap_min:g} s) of CPU ('> cap' when it needs more), 'failed': it ended "
             f"with its diagnosis (exit code 3), 'n/a': the method does not take the scene "
             f"(the symplectic method on the MPP and with ground contact). "
             f"Machine: {machine()}. Run: {run_stamp()}.",
             "", header, "|---|---|---|---|---|---|---|---|---|---|---|", *rows, END]
    update_doc(DOCS / "performance" / "auto.md", BEGIN, END, "\n".join(lines),
               heading="## Auto's choice on every scene (issue 15)\n\n")
    print(f"auto_table: {DOCS / 'performance' / 'auto.md'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
