"""Auto's choice at equal accuracy: what each method's run is worth, not only what it costs.

The auto table (scripts/auto_table) compares the methods at the scene's own tolerances. The
same rtol does not give the same accuracy: on the folded rope at n = 301 CVODE's BDF at rtol
1e-6 is some 1000 times further from a tight reference than erk at rtol 1e-6. This study
measures, on every scene over a short span (before any chaotic phase parts trajectories),
each method's error and the cost of each fixed method at auto's accuracy:

- **Reference**: cvode at rtol `--ref-rtol` (1e-10), atol 1e-2 of it, same scene and span.
  Its spread: its distance from cvode at 10 times that rtol (about ten times the
  reference's own error, CVODE's error being about proportional to rtol there). While the
  spread exceeds a tenth of the largest error of the methods at the scene's tolerances (a
  chaotic phase, e.g. the folded rope's snap, or a reference that has not converged) the
  span is halved (up to six times). Errors below a tenth of the spread (the reference's
  reach) are not resolved: equal accuracy then means an error within that reach.
- **Error**: the largest distance over the output times (`--records` of them over the span)
  and over the rope's points (/rope/points, m) from the reference.
- **Auto** at the scene's own rtol and atol: its error e_auto and its CPU.
- **Each fixed method** (cvode, adams, mebdf, erk and the symplectic method at their
  default order limits; n/a where a method does not take the scene): its error at the
  scene's tolerances, and its CPU at equal accuracy: the loosest of the scene's rtol times
  1e3, 1e2, .. 1e-3 (atol scaled alike) whose error is at most SLACK = 1.5 times e_auto
  (errors below the reference's reach, or `--floor`, count as that).
- **auto / best at equal accuracy**: auto's CPU over the cheapest of those.

CPU: /solver/cpu_time, the minimum of `--repeat` runs (more, up to 8, while they add up to
less than 1 s). A run is given max(CAP_FACTOR = 4 x auto's CPU, CAP_MIN = 3 s) of process
CPU; one that needs more ('> cap' in the table) or ends with a diagnosis ('failed') does
not count. The table goes between the auto_accuracy markers of
docs/performance/auto.md. The code of scripts/auto_accuracy.
"""
import argparse
import pathlib
import sys
import tempfile

import numpy as np

from ropedyn_tools.repo import DOCS, add_exe_argument, exe_or_build
from ropedyn_tools.studies import auto_table
from ropedyn_tools.studies.auto_table import FIXED, scene_t_end, scenes
from ropedyn_tools.studies.common import (machine, method_chain, method_label, scene_number,
                                          update_doc, run_stamp)
from ropedyn.docstrings import summary

BEGIN = "<!-- auto_accuracy:begin -->"
END = "<!-- auto_accuracy:end -->"
FACTORS = (1e3, 1e2, 1e1, 1.0, 1e-1, 1e-2, 1e-3)
#: errors within this factor of auto's count as equal accuracy (runs of the same method
#: differ a little: auto starts erk with its own first step)
SLACK = 1.5
#: a fixed method's run gets at most max(CAP_FACTOR x auto's CPU, CAP_MIN s) of process CPU
CAP_FACTOR, CAP_MIN = 4.0, 3.0


def distance(a, b):
    """Largest distance (m) over the records and points of two /rope/points arrays."""
    k = min(len(a), len(b))
    return float(np.max(np.linalg.norm(a[:k] - b[:k], axis=-1)))


def measured(exe, scene, work, method, span, sets, repeat, cap, ref):
    """(cpu, error, switch methods: erk with its pair's order) of `method` with `sets`:
    the least CPU of `repeat` runs (auto_table's best_of); None when a run failed, "cap"
    when it ran over its CPU cap, "n/a" when the method does not take the scene."""
    r = auto_table.best_of(exe, scene, work, method, span, repeat, cap, sets, points=True)
    if r["status"] in ("n/a", "cap"):
        return r["status"]
    if r["status"] != "complete":
        return None
    return r["cpu"], distance(r["points"], ref), [
        method_label(m, o) for _, m, o in r["switches"]] or [method]


def error_cell(at_own, cap):
    """The table's cell for a fixed method at the scene's tolerances: its error, or what
    kept it from one: 'n/a' (the method does not take the scene), '> cap' (the run needed
    more than its CPU cap, `cap` s, not a failure of the method) or 'failed'."""
    if at_own == "n/a":
        return "n/a"
    if at_own == "cap":
        return f"> {cap:.3g} s"
    return f"{at_own[1]:.1e}" if at_own else "failed"


def main(argv=None):
    parser = argparse.ArgumentParser(description=summary(__doc__))
    add_exe_argument(parser)
    parser.add_argument("--span", type=float, default=1.0,
                        help="simulated time (s), at most the scene's t_end")
    parser.add_argument("--records", type=int, default=50)
    parser.add_argument("--ref-rtol", type=float, default=1e-10)
    parser.add_argument("--floor", type=float, default=1e-10,
                        help="errors below this (m) count as this (the reference's reach)")
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--scenes", nargs="*", help="only these scene files")
    parser.add_argument("--no-write", action="store_true")
    args = parser.parse_args(argv)
    exe = exe_or_build(args.exe)
    chosen = [pathlib.Path(s).resolve() for s in args.scenes] if args.scenes else scenes()
    header = ("| scene | span (s) | rtol | auto's choice | reference spread (m) "
              "| auto error (m) | auto CPU (s) | "
              + " | ".join(f"{m} error (m)" for m in FIXED)
              + " | best at auto's accuracy (rtol) | its CPU (s) | auto / best |")
    rows = []
    print(header, flush=True)
    with tempfile.TemporaryDirectory() as tmp:
        work = pathlib.Path(tmp)
        for scene in chosen:
            span = min(args.span, scene_t_end(scene))
            rtol, atol = scene_number(scene, "rtol", 1e-6), scene_number(scene, "atol", 1e-8)
            # the span is halved while the reference does not resolve the methods' errors
            # (a chaotic phase, or a reference that has not converged)
            for _ in range(6):
                common = [f"solver.output_interval={span / args.records:.10g}",
                          "solver.max_steps=10000000"]
                refs = [auto_table.run(exe, scene, work, "cvode", span, None, [
                    *common, f"solver.rtol={r:g}", f"solver.atol={r * 1e-2:g}"], points=True)
                    for r in (args.ref_rtol, 10 * args.ref_rtol)]
                auto = None
                if all(r["status"] == "complete" for r in refs):
                    auto = measured(exe, scene, work, "auto", span, common, args.repeat, None,
                                    refs[0]["points"])
                if not isinstance(auto, tuple):
                    auto = None
                    break
                spread = distance(refs[0]["points"], refs[1]["points"])
                cap = max(CAP_FACTOR * auto[0], CAP_MIN)
                own = {m: measured(exe, scene, work, m, span, common, args.repeat, cap,
                                   refs[0]["points"]) for m in FIXED}
                largest = max([auto[1]] + [r[1] for r in own.values() if isinstance(r, tuple)])
                if spread <= max(0.1 * largest, args.floor):
                    break
                span /= 2
            if auto is None:
                rows.append(f"| {scene.relative_to(DOCS.parent)} | {span:g} | {rtol:g} | "
                            f"reference or auto failed |")
                print(rows[-1], flush=True)
                continue
            ref = refs[0]["points"]
            auto_cpu, auto_err, choice = auto
            # errors below the reference's reach (a tenth of its spread) are not resolved
            reach = max(spread / 10, args.floor)
            target = max(auto_err, reach)
            errors, best = [], None
            for method in FIXED:
                at_own = own[method]
                errors.append(error_cell(at_own, cap))
                if at_own == "n/a":
                    continue
                for factor in FACTORS:
                    if factor == 1.0 and at_own is not None:
                        got = at_own
                    else:
                        got = measured(exe, scene, work, method, span, [
                            *common, f"solver.rtol={rtol * factor:.3g}",
                            f"solver.atol={atol * factor:.3g}"], args.repeat, cap, ref)
                    if isinstance(got, tuple) and max(got[1], reach) <= SLACK * target:
                        if best is None or got[0] < best[0]:
                            best = (got[0], f"{method} ({rtol * factor:.3g})")
                        break
            choice = method_chain(choice)
            best_text = (f"{best[1]} | {best[0]:.3g} | {auto_cpu / best[0]:.2f}"
                         if best else "none | | ")
            rows.append(f"| {scene.relative_to(DOCS.parent)} | {span:g} | {rtol:g} | "
                        f"{choice} | {spread:.0e} | {auto_err:.1e} | {auto_cpu:.3g} | "
                        + " | ".join(errors) + f" | {best_text} |")
            print(rows[-1], flush=True)
    if args.no_write:
        return 0
    lines = [BEGIN,
             f"Command: `scripts/auto_accuracy --span {args.span:g}` (code: "
             f"tools/ropedyn_tools/studies/auto_accuracy.py). Every scene over its first "
             f"{args.span:g} s (or its t_end; halved while the reference spread, cvode at "
             f"rtol {10 * args.ref_rtol:g} against {args.ref_rtol:g}, exceeds a tenth of "
             f"the largest error in the row; errors below a tenth of the spread are not "
             f"resolved), {args.records} records; error: the largest "
             f"distance of the rope's points from cvode at rtol {args.ref_rtol:g} over the "
             f"records; the fixed methods' errors at the scene's tolerances; 'best at "
             f"auto's accuracy': the cheapest fixed method at the loosest of the scene's "
             f"rtol x 1e3 .. 1e-3 (atol alike) whose error is at most {SLACK:g} times "
             f"auto's (errors below {args.floor:g} m count as {args.floor:g} m); each "
             f"fixed method's run gets max({CAP_FACTOR:g} x auto's CPU, {CAP_MIN:g} s) of "
             f"process CPU ('> cap' when it needs more), 'failed': it ended with its "
             f"diagnosis. CPU: /solver/cpu_time, minimum "
             f"of {args.repeat} runs. Machine: {machine()}. Run: {run_stamp()}.", "",
             header, "|" + "---|" * (10 + len(FIXED)), *rows, END]
    update_doc(DOCS / "performance" / "auto.md", BEGIN, END, "\n".join(lines),
               heading="## Auto's choice at equal accuracy (issue 15)\n\n")
    print(f"auto_accuracy: {DOCS / 'performance' / 'auto.md'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
