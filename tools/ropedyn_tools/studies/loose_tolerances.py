"""Loose tolerances: the energy a method creates at rtol 0.3, 0.1 and 0.03, unguarded and with
the run's guard (the order safety and the runaway rule).

The code of scripts/loose_tolerances; writes the section between the loose-tolerances markers
of docs/validation/order-safety.md.

Every scene of SCENES with every method of METHODS at rtol 0.3, 0.1 and 0.03 (atol = rtol /
100), over the scene's own t_end and output interval, twice: with `order_safety = 'off'` (no
energy check: what the method does by itself) and with the default `'lower'` (the order
safety, and the runaway rule: a run fails when B - E0 passes a tenth of max(S, m g L),
docs/theory/energy-balance.md). Measured from each file (stability_metrics): how it ended,
the largest B - E0 over its records in units of m g L, and the largest axial force, against
the scene at its own tolerances with the default method (the reference).

The table lists the runs that, unguarded, pass the runaway limit; the lines above it count
every run. Runs go two at a time (no timing is measured).
"""
import argparse
import concurrent.futures
import pathlib
import re
import subprocess
import sys
import tempfile

import numpy as np

from ropedyn import fields, io
from ropedyn_tools.repo import DOCS, INPUT, add_exe_argument, exe_or_build, set_args
from ropedyn_tools.studies import stability_metrics
from ropedyn_tools.studies.common import machine, run_stamp, update_doc
from ropedyn.docstrings import summary

DOC = DOCS / "validation" / "order-safety.md"
BEGIN = "<!-- loose-tolerances:begin -->"
END = "<!-- loose-tolerances:end -->"
SCENES = ("paper.nml", "paper_light_damping.nml", "folded_fall.nml", "ground_rest.nml",
          "shaken_top.nml", "drag_fall.nml", "chain_in_water.nml")
METHODS = ("auto", "cvode", "adams", "mebdf", "erk", "symplectic")
RTOLS = (0.3, 0.1, 0.03)
#: the runaway limit, in units of max(S, m g L) (ropedyn_energy_monitor's MAX_BOUND_SHARE)
RUNAWAY = 0.1


def run(exe, work, scene, sets, tag):
    """One run: how it ended and what its file says (None where it wrote no records)."""
    out = pathlib.Path(work) / f"{tag}.h5"
    proc = subprocess.run([str(exe), "run", str(INPUT / scene),
                           *set_args([f"output.file='{out}'", *sets])],
                          capture_output=True, text=True, timeout=900)
    why = (proc.stderr.strip().splitlines() or [""])[-1].replace("ropedyn: error: ", "")
    # auto's switch to MEBDF at a runaway: a warning naming the time it integrated from
    rescued = re.search(r"energy runaway: .* the interval again from t = ([0-9.e+-]+) s",
                        proc.stderr)
    r = {"code": proc.returncode, "why": why, "gain": None, "force": None,
         "rescued": rescued.group(1) if rescued else None}
    if not out.exists():
        return r
    try:
        f = io.load_run(out)
        m = stability_metrics.analyse(out, f)
    except (OSError, KeyError, ValueError):
        return r
    mgl = m["weight_length"]
    scale = max(m["energy_scale"], mgl)
    r.update(gain=float(m["balance_drift"].max()) / mgl,
             runaway=bool(np.any(m["balance_drift"] > RUNAWAY * scale)))
    axial, _ = fields.axial_force(f)
    if axial is not None:
        r["force"] = float(np.abs(axial.values).max())
    return r


def outcome(r):
    if r["code"] == 0 and r.get("rescued"):
        return f"complete, on with mebdf 4 from {r['rescued']} s"
    if r["code"] == 0:
        return "complete"
    if "it created" in r["why"]:
        t = r["why"].split("failed at t = ")[1].split(" s")[0]
        return f"runaway at {t} s"
    if "cannot integrate" in r["why"]:
        return "refused"
    return "failed: " + r["why"][:60]


def cases():
    for scene in SCENES:
        for method in METHODS:
            for rtol in RTOLS:
                yield scene, method, rtol


def main(argv=None):
    parser = argparse.ArgumentParser(description=summary(__doc__))
    add_exe_argument(parser)
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--no-write", action="store_true")
    args = parser.parse_args(argv)
    exe = exe_or_build(args.exe)
    with tempfile.TemporaryDirectory() as work, \
            concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
        ref = {s: pool.submit(run, exe, work, s, [], f"ref_{s[:-4]}") for s in SCENES}
        jobs = {}
        for scene, method, rtol in cases():
            sets = [f"solver.method='{method}'", f"solver.rtol={rtol:g}",
                    f"solver.atol={rtol / 100:g}"]
            tag = f"{scene[:-4]}_{method}_{rtol:g}"
            jobs[(scene, method, rtol)] = (
                pool.submit(run, exe, work, scene, sets + ["solver.order_safety='off'"],
                            tag + "_off"),
                pool.submit(run, exe, work, scene, sets, tag))
        ref = {s: f.result() for s, f in ref.items()}
        results = {k: (a.result(), b.result()) for k, (a, b) in jobs.items()}
    rows, counts = [], {"runs": len(results), "off_runaway_ok": 0, "complete": 0,
                        "runaway": 0, "other": 0, "refused": 0, "largest": 0.0,
                        "rescued": 0}
    for (scene, method, rtol), (off, on) in results.items():
        kind = outcome(on)
        key = ("complete" if kind.startswith("complete") else "runaway"
               if kind.startswith("runaway") else "refused" if kind == "refused" else "other")
        counts[key] += 1
        counts["rescued"] += bool(on.get("rescued"))
        if key == "complete" and on["gain"] is not None:
            counts["largest"] = max(counts["largest"], on["gain"])
        if not off.get("runaway"):
            continue
        counts["off_runaway_ok"] += off["code"] == 0
        force = (f"{off['force']:.3g} / {ref[scene]['force']:.3g}"
                 if off["force"] is not None and ref[scene]["force"] is not None else "")
        rows.append(f"| {scene} | {method} | {rtol:g} | {outcome(off)} | {off['gain']:+.2g} | "
                    f"{force} | {kind} | "
                    f"{'' if on['gain'] is None else format(on['gain'], '+.2g')} |")
        print(rows[-1], flush=True)
    if args.no_write:
        return 0
    block = "\n".join([
        BEGIN,
        "Command: `scripts/loose_tolerances` (code: "
        "tools/ropedyn_tools/studies/loose_tolerances.py). Machine: "
        f"{machine()}. Run: {run_stamp()}.", "",
        f"{len(SCENES)} scenes of input/ ({', '.join(SCENES)}) x {len(METHODS)} methods x "
        f"rtol {', '.join(f'{r:g}' for r in RTOLS)} (atol = rtol / 100), each over its own "
        f"t_end: {counts['runs']} runs, each unguarded (`order_safety = 'off'`) and with "
        "the default guard.", "",
        f"- Unguarded, {len(rows)} runs pass the runaway limit (B - E0 above a tenth of "
        f"max(S, m g L)); {counts['off_runaway_ok']} of them end with exit code 0.",
        f"- Guarded: {counts['complete']} runs complete ({counts['rescued']} of them auto's, "
        "on with MEBDF at order 4 after a runaway), the largest B - E0 among them "
        f"{counts['largest']:+.2g} m g L; {counts['runaway']} end at a runaway, "
        f"{counts['other']} fail otherwise (the method's own diagnosis), "
        f"{counts['refused']} are refused (the symplectic method: water, ground).", "",
        "The runs that pass the limit unguarded (B - E0: the largest over the records, m g L; "
        "force: the largest axial force of the run against the scene at its own tolerances "
        "with the default method, N):", "",
        "| scene | method | rtol | unguarded | B - E0 | force / reference | guarded | "
        "B - E0 |", "|---|---|---|---|---|---|---|---|", *rows, END])
    update_doc(DOC, BEGIN, END, block)
    print(f"loose_tolerances: {DOC}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
