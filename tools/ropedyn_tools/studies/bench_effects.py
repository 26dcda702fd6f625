"""Cost of the right-hand side per element for sets of effects (issue #7).

The code of scripts/bench_effects (python -m ropedyn_tools.studies.bench_effects; without
--build it builds the Release configuration first). Times the
RFEM right-hand side and Jacobian with tests/bench/bench_rhs for: gravity + tension; all
internal effects (the paper's rope); each external effect added on its own; all effects;
all internal effects with every external effect configured but switched off; and, with
--baseline REV, all internal effects built from git revision REV (before the effects
existed), which shows that effects that are off cost nothing. The table goes into
docs/performance/effects.md between the markers of the section "Cost of the effects".
"""
import argparse
import pathlib
import subprocess
import sys
import tempfile

from ropedyn_tools.repo import DOCS, PAPER, build, set_args
from ropedyn_tools.studies.bench_rhs import build_bench_rhs
from ropedyn_tools.studies.common import baseline_revision, machine, update_doc, run_stamp
from ropedyn.docstrings import summary

BEGIN = "<!-- bench_effects:begin -->"
END = "<!-- bench_effects:end -->"

INTERNAL_OFF = ["effects.shear=F", "effects.bending=F", "effects.damping=F"]
DRAG = ["effects.drag=T", "fluid.density=1000", "fluid.linear_normal_drag=0.1",
        "fluid.current=0.1, 0.2"]
GROUND = ["effects.ground=T", "ground.point=0.13, 0.0", "ground.normal=-1.0, 0.1"]
MOTION = ["supports.top_motion=harmonic", "supports.top_amplitude=0.01, 0.02",
          "supports.top_frequency=2"]
MASSES = ["attachments.mass_positions=1.0, 0.5", "attachments.masses=0.1, 0.05"]
LOADS = ["attachments.load_positions=0.3, 0.7", "attachments.load_force_x=0.1, 0.2",
         "attachments.load_amplitude_y=0.1, 0.0", "attachments.load_frequency=2, 0"]
# every external effect configured, every switch off: the model must be the paper's
CONFIGURED_OFF = (DRAG + GROUND + MOTION + MASSES + LOADS) + [
    "effects.drag=F", "effects.ground=F", "effects.support_motion=F",
    "effects.point_masses=F", "effects.point_loads=F"]

CONFIGS = [
    ("gravity + tension", INTERNAL_OFF),
    ("all internal effects (gravity, tension, shear, bending, damping)", []),
    ("internal + drag (quadratic and linear, current)", DRAG),
    ("internal + ground contact (about half the rope touching)", GROUND),
    ("internal + moving top (harmonic)", MOTION),
    ("internal + 2 point masses", MASSES),
    ("internal + 2 point loads", LOADS),
    ("all effects", DRAG + GROUND + MOTION + MASSES + LOADS),
    ("all internal, external effects configured but off", CONFIGURED_OFF),
]


def bench(exe, n, sets, seconds):
    cmd = [str(exe), str(PAPER), "--set", f"model.elements={n}", "--seconds", str(seconds),
           *set_args(sets)]
    out = subprocess.run(cmd, capture_output=True, text=True)
    if out.returncode != 0:
        raise SystemExit(f"bench_rhs failed: {' '.join(cmd)}\n{out.stderr}")
    fields = out.stdout.split()
    return float(fields[1]), float(fields[2])


def main(argv=None):
    parser = argparse.ArgumentParser(description=summary(__doc__))
    parser.add_argument("--build", default=None, help="Release build directory (default: "
                        "build the Release configuration with scripts/build and use it)")
    parser.add_argument("--elements", type=int, default=100)
    parser.add_argument("--seconds", type=float, default=0.5,
                        help="time per repetition of each timing (5 repetitions, fastest kept)")
    parser.add_argument("--baseline", default=None,
                        help="git revision to time 'all internal effects' at (e.g. HEAD)")
    parser.add_argument("--no-write", action="store_true", help="print only")
    args = parser.parse_args(argv)
    rev = baseline_revision(parser, args.baseline)
    exe = pathlib.Path(args.build or build("Release")) / "tests" / "bench_rhs"
    n = args.elements

    rows = []
    header = ("| configuration | RHS (ns per element) | relative to all internal | "
              "Jacobian (ns per element) |")
    print(header)
    print("|---|---|---|---|")
    results = []
    for label, sets in CONFIGS:
        rhs, jac = bench(exe, n, sets, args.seconds)
        results.append((label, rhs, jac))
    if args.baseline:
        with tempfile.TemporaryDirectory() as tmp:
            base_exe = build_bench_rhs(args.baseline, pathlib.Path(tmp))
            rhs, jac = bench(base_exe, n, [], args.seconds)
            # the current build once more, right after, for a fair pair
            now_rhs, now_jac = bench(exe, n, [], args.seconds)
            results.append((f"all internal effects at {args.baseline} ({rev}), before the "
                            "effects existed", rhs, jac))
            results.append(("all internal effects, this build (timed right after)", now_rhs,
                            now_jac))
    internal = results[1][1]
    for label, rhs, jac in results:
        line = f"| {label} | {rhs:.1f} | {rhs / internal:.2f} | {jac:.1f} |"
        print(line, flush=True)
        rows.append(line)

    if args.no_write:
        return 0
    stamp = run_stamp()
    cmd = "scripts/bench_effects" + (f" --baseline {args.baseline}" if args.baseline else "") \
        + (f" --elements {n}" if n != 100 else "")
    block = "\n".join([
        BEGIN,
        f"Command: `{cmd}` (Release build, RFEM, the paper's rope, n = {n}; "
        "`tests/bench/bench_rhs`: CPU time per call divided by n, fastest of 5 repetitions "
        f"of about {args.seconds} s; state: the initial state with velocities up to 0.3 m/s).",
        f"Machine: {machine()}. Run: {stamp}.",
        "",
        header,
        "|---|---|---|---|",
        *rows,
        END,
    ])
    doc = DOCS / "performance" / "effects.md"
    update_doc(doc, BEGIN, END, block, heading="## Cost of the effects\n\n", strip="\n")
    print(f"wrote {doc}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
