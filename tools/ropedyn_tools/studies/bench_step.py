"""Cost of one step before and after: CPU per step per element, interleaved runs.

The code of scripts/bench_step (python -m ropedyn_tools.studies.bench_step). Runs the paper scene
(input/paper.nml, rtol 1e-6) for each case (RFEM n = 30, 100 over 3 s, n = 1000 over 1 s;
the MPP n = 70 over 0.3 s; CVODE and MEBDF each) with the executable built from git revision
--baseline (git archive, Release; or --baseline-exe PATH) and with this tree's, one right
after the other, --repeat times; the smallest CPU time of each is kept (the machine is
shared: the smallest is the least disturbed). The table (between the bench_step markers of
docs/performance/step.md) gives steps, CPU per step per element (RFEM, us) or per step (MPP, ms)
and the speed-up.
"""
import argparse
import pathlib
import subprocess
import sys
import tempfile

from ropedyn_tools.repo import DOCS, PAPER, add_exe_argument, exe_or_build, set_args
from ropedyn_tools.studies.common import baseline_revision, machine, update_doc, run_stamp
from ropedyn_tools.studies.profile_step import build_baseline
from ropedyn.docstrings import summary

BEGIN = "<!-- bench_step:begin -->"
END = "<!-- bench_step:end -->"
CASES = [("rfem", 30, 3.0), ("rfem", 100, 3.0), ("rfem", 1000, 1.0), ("mpp", 70, 0.3)]
HEADER = ("| model | n | solver | horizon (s) | steps before / after | before | after | "
          "speed-up |")
RULE = "|---|---|---|---|---|---|---|---|"


def run(exe, model, n, method, t_end, workdir):
    """(steps, CPU seconds) of one run, from its summary lines. Its output file is removed
    after it (ropedyn replaces no file of another run: the next run writes it anew)."""
    out = workdir / f"step_{model}_{n}_{method}.h5"
    cmd = [str(exe), "run", str(PAPER), *set_args([
        f'model.kind="{model}"', f"model.elements={n}", f'solver.method="{method}"',
        f"solver.t_end={t_end}", f'output.file="{out}"', "solver.output_interval=0.1"])]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    out.unlink(missing_ok=True)
    if proc.returncode != 0:
        raise SystemExit(f"bench_step: {' '.join(cmd)} failed:\n{proc.stderr[-2000:]}")
    steps = cpu = None
    for text in proc.stdout.splitlines():
        words = text.split()
        if words[:1] == ["steps"]:
            steps = int(words[1])
        if words[:2] == ["cpu", "time"]:
            cpu = float(words[2])
    return steps, cpu


def cost(model, n, steps, cpu):
    """CPU per step per element (us) for RFEM, per step (ms) for the MPP."""
    return 1e6 * cpu / steps / n if model == "rfem" else 1e3 * cpu / steps


def main(argv=None):
    parser = argparse.ArgumentParser(description=summary(__doc__))
    add_exe_argument(parser)
    parser.add_argument("--baseline", default="97a3272", help="git revision of 'before'")
    parser.add_argument("--baseline-exe", default=None,
                        help="the 'before' executable (instead of building --baseline)")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--no-write", action="store_true", help="print only")
    args = parser.parse_args(argv)
    if not args.baseline_exe:
        baseline_revision(parser, args.baseline)
    exe = exe_or_build(args.exe)
    rows = []
    print(HEADER)
    print(RULE)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        before = pathlib.Path(args.baseline_exe) if args.baseline_exe else \
            build_baseline(args.baseline, tmp)
        for model, n, t_end in CASES:
            for method in ("cvode", "mebdf"):
                best = {"before": None, "after": None}
                for _ in range(args.repeat):
                    for tag, path in (("before", before), ("after", exe)):
                        steps, cpu = run(path, model, n, method, t_end, tmp)
                        if best[tag] is None or cpu < best[tag][1]:
                            best[tag] = (steps, cpu)
                (sb, cb), (sa, ca) = best["before"], best["after"]
                b, a = cost(model, n, sb, cb), cost(model, n, sa, ca)
                unit = "us/step/element" if model == "rfem" else "ms/step"
                rows.append(f"| {model} | {n} | {method} | {t_end:g} | {sb} / {sa} | "
                            f"{b:.2f} {unit} | {a:.2f} {unit} | {b / a:.1f} |")
                print(rows[-1], flush=True)
    if args.no_write:
        return 0
    block = "\n".join([
        BEGIN,
        f"Command: `scripts/bench_step --baseline {args.baseline} --repeat {args.repeat}` "
        + ("(with `--baseline-exe`: that revision's Release executable, built before) "
           if args.baseline_exe else "")
        + "(input/paper.nml, rtol 1e-6, default orders, output every 0.1 s; before: the "
        f"Release executable of {args.baseline}, after: this tree's; interleaved, the "
        "smallest CPU time of the repeats).",
        f"Machine: {machine()}. Run: {run_stamp()}.",
        "", HEADER, RULE, *rows, END])
    update_doc(DOCS / "performance" / "step.md", BEGIN, END, block,
               heading="### Before and after (scripts/bench_step)\n\n")
    print(f"bench_step: table written to {DOCS / 'performance' / 'step.md'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
