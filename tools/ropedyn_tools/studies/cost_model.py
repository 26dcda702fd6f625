"""auto's counted cost against CPU time: does an evaluation-of-f equivalent cost the same
for every method?

auto (solvers/auto/ropedyn_auto.f90, "Cost") compares methods by counted work, not by
timers, so that runs stay reproducible: erk its evaluations of f; mebdf those plus
IMPLICIT_STEP_COST per step; cvode those plus BDF_STEP_COST per step; both FACTOR_BASE per
factorization and JACOBIAN_COST per Jacobian (on the RFEM's band; wider Newton matrices add
more, not measured here). The constants were calibrated on the paper's rope at n = 30, rtol 1e-6.
This runs the paper's rope (RFEM) with each method over a grid of n and rtol and prints the
CPU time per counted unit, and its ratio to erk's at the same n and rtol: 1 where the model
is right, above 1 where it undercounts the method (auto then holds it cheaper than it is).
The constants are read from the Fortran source, so the table follows them. Writes the table
between the cost_model markers of docs/performance/auto.md.
The code of scripts/cost_model (python -m ropedyn_tools.studies.cost_model).
"""
import argparse
import pathlib
import re
import subprocess
import tempfile

from ropedyn import io
from ropedyn_tools.arguments import listing, positive
from ropedyn_tools.repo import DOCS, PAPER, ROOT, add_exe_argument, exe_or_build, set_args
from ropedyn_tools.studies.common import least_cpu, machine, update_doc, run_stamp
from ropedyn.docstrings import summary

BEGIN = "<!-- cost_model:begin -->"
END = "<!-- cost_model:end -->"
AUTO_SOURCE = ROOT / "solvers" / "auto" / "ropedyn_auto.f90"
METHODS = ("erk", "mebdf", "cvode")


def auto_parameter(name, path=AUTO_SOURCE, text=None):
    """The value of the Fortran parameter `name` (real `..._wp` or integer) in auto's
    source; ValueError naming it when the source has none."""
    text = pathlib.Path(path).read_text() if text is None else text
    m = re.search(rf"parameter\s*::\s*{name}\s*=\s*([0-9.]+)(_wp)?\b", text)
    if m is None:
        raise ValueError(f"{path}: no parameter {name}")
    return float(m.group(1)) if m.group(2) else int(m.group(1))


def auto_constants(path=AUTO_SOURCE):
    """auto's per-step and per-Jacobian costs (f-equivalents) from its Fortran source."""
    text = pathlib.Path(path).read_text()
    return {name: float(auto_parameter(name, path, text))
            for name in ("IMPLICIT_STEP_COST", "BDF_STEP_COST", "FACTOR_BASE",
                         "JACOBIAN_COST")}


def counted(method, stats, constants):
    """auto's counted cost of a run on a problem with the RFEM's band (lambda = 1)."""
    f = float(stats["rhs_evals"])
    if method == "erk":
        return f
    step = constants["IMPLICIT_STEP_COST" if method == "mebdf" else "BDF_STEP_COST"]
    return (f + step * float(stats["steps"])
            + constants["FACTOR_BASE"] * float(stats.get("lin_setups", 0))
            + constants["JACOBIAN_COST"] * float(stats["jac_evals"]))


def run_case(exe, n, rtol, method, t_end, workdir):
    out = workdir / f"cost_{method}_{n}_{rtol:g}.h5"
    cmd = [str(exe), "run", str(PAPER), *set_args([
        f"model.elements={n}", f"solver.t_end={t_end}", f"solver.rtol={rtol:g}",
        f"solver.atol={rtol / 100:g}", f'solver.method="{method}"', f'output.file="{out}"'])]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=3600)
    if proc.returncode != 0:
        return {"status": "failed: " + proc.stderr.strip()[:80]}
    stats = io.load_run(out).stats
    return {"status": "complete", "cpu": float(stats["cpu_time"]), "stats": stats}


def rows(results, constants):
    """Table rows: per (n, rtol, method) the counts, CPU, CPU per unit and its ratio to erk's."""
    out = []
    for (n, rtol), by_method in results.items():
        per_unit = {}
        for method in METHODS:
            r = by_method[method]
            if r["status"] == "complete":
                per_unit[method] = r["cpu"] / counted(method, r["stats"], constants)
        for method in METHODS:
            r = by_method[method]
            if r["status"] != "complete":
                out.append(f"| {n} | {rtol:g} | {method} | {r['status']} | | | | | | | |")
                continue
            s = r["stats"]
            steps = int(s["steps"])
            setups = int(s.get("lin_setups", 0))
            ratio = (f"{per_unit[method] / per_unit['erk']:.2f}" if "erk" in per_unit else "")
            out.append(f"| {n} | {rtol:g} | {method} | {steps} | {int(s['rhs_evals'])} "
                       f"| {int(s['jac_evals'])} | {setups} | {setups / max(steps, 1):.3f} "
                       f"| {counted(method, s, constants):.3g} | {r['cpu']:.3g} "
                       f"| {1e6 * per_unit[method]:.3f} | {ratio} |")
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(description=summary(__doc__))
    add_exe_argument(parser)
    parser.add_argument("--t-end", type=positive(float), default=10.0)
    parser.add_argument("--elements", type=listing(positive(int)), default="10 30 100",
                        help="numbers of elements, space-separated")
    parser.add_argument("--rtols", type=listing(positive(float)), default="1e-2 1e-4 1e-6 1e-8",
                        help="relative tolerances, space-separated")
    parser.add_argument("--repeat", type=positive(int), default=2,
                        help="runs per case (least CPU)")
    parser.add_argument("--no-write", action="store_true")
    args = parser.parse_args(argv)
    exe = exe_or_build(args.exe)
    constants = auto_constants()
    results = {}
    with tempfile.TemporaryDirectory() as tmp:
        for n in args.elements:
            for rtol in args.rtols:
                results[(n, rtol)] = {
                    m: least_cpu(lambda m=m: run_case(exe, n, rtol, m, args.t_end,
                                                      pathlib.Path(tmp)),
                                 args.repeat, lambda r: r["status"] == "complete")
                    for m in METHODS}
                print(f"cost_model: n = {n}, rtol {rtol:g} done", flush=True)
    header = ("| n | rtol | method | steps | f evals | Jacobians | factorizations "
              "| factorizations per step | counted (f-equivalents) | CPU (s) "
              "| CPU per counted unit (us) | / erk's |")
    table = [header, "|" + "---|" * 12, *rows(results, constants)]
    print("\n".join(table))
    if args.no_write:
        return 0
    consts = ", ".join(f"{k} = {v:g}" for k, v in constants.items())
    elements = " ".join(str(n) for n in args.elements)
    rtols = " ".join(f"{r:g}" for r in args.rtols)
    block = (f"{BEGIN}\nCommand: `scripts/cost_model --t-end {args.t_end:g} --elements "
             f"\"{elements}\" --rtols \"{rtols}\" --repeat {args.repeat}` (code: "
             "tools/ropedyn_tools/studies/cost_model.py). input/paper.nml (RFEM) with each method "
             "(atol = rtol / 100); counted as auto counts on the RFEM's band (erk: evaluations "
             "of f; mebdf and cvode: those plus a cost per step, per factorization and per "
             f"Jacobian; {consts}, "
             "read from solvers/auto/ropedyn_auto.f90); CPU: /solver/cpu_time, the least of "
             f"{args.repeat} runs. '/ erk's': CPU per counted unit over erk's at the same n and "
             "rtol (above 1: auto counts the method cheaper than it is). Machine: "
             f"{machine()}. Run: {run_stamp()}.\n\n" + "\n".join(table) + f"\n{END}")
    update_doc(DOCS / "performance" / "auto.md", BEGIN, END, block,
               heading="## Auto's counted cost against CPU time\n\n")
    print(f"cost_model: {DOCS / 'performance' / 'auto.md'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
