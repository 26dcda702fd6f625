"""Instruction profile of one step: where a paper run spends its time, before and after.

The code of scripts/profile_step (python -m ropedyn_tools.studies.profile_step). Runs the paper
scene (n = 30, --t-end seconds of motion, rtol 1e-6) under valgrind's callgrind with each
integrator, once with the executable of the working tree (Release) and, with --baseline REV,
once with the executable built from git revision REV (git archive; the working tree is
untouched). Instruction counts (not times: the machine is shared, counts are exact) are
split by the inclusive cost of the functions that do each part:

- RHS: the model's right-hand side and quadratures (rfem_rhs, rfem_quad_rhs, rfem_rhs_quad);
- Jacobian: CVODE's Jacobian callback or linear-system function (cv_jacobian, cv_linsys),
  MEBDF's matrix_evaluate_jacobian;
- factorization: CVODE's linear-solver setup less the Jacobian (cvLsSetup: forming
  I - gamma J and its LU, or the reduced matrix and its LU), MEBDF's matrix_factor;
- solves: SUNLinSolSolve (CVODE, either linear solver), MEBDF's matrix_solve;
- the rest of the integrator (CVode, mebdf_advance_to less the parts above): vector
  operations, error tests, step-size control.
`--methods erk` profiles the explicit method instead (no Jacobian, factorization or solves:
RHS and the rest of erk_advance_to: stages, error norm, step control, quadratures' history)
into its own table (the profile_step erk markers); `--methods symplectic` likewise (RHS: the
split forces, rfem_split_rhs; the rest: symplectic_advance_to's kicks, drifts, D-maps and
the state's scatter), and both together (`--methods "erk symplectic"`) into one table.
`--whole-run` profiles the whole program on the paper scene as it ships (output every
0.01 s, its default method unless --methods names one) into a table of its own (the
profile_step whole-run markers): the integrator's RHS and rest as above, the output (the
run file: output_append, and the stats and close that write the last records) and the
remainder (start-up, the records' fields and energies, the driver); per accepted step.
The table goes into docs/performance/step.md between the profile_step markers.
"""
import argparse
import os
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile

from ropedyn_tools.arguments import check_names
from ropedyn_tools.repo import DOCS, PAPER, ROOT, add_exe_argument, exe_or_build, set_args
from ropedyn_tools.studies.common import baseline_revision, machine, update_doc, run_stamp
from ropedyn.docstrings import summary

BEGIN = "<!-- profile_step:begin -->"
END = "<!-- profile_step:end -->"
PARTS = ("RHS", "Jacobian", "factorization", "solves", "rest")
WHOLE_PARTS = ("RHS", "rest of the integrator", "output (HDF5)", "the remainder")


def inclusive_costs(cg_file):
    """{function name: inclusive instruction count} from callgrind_annotate."""
    out = subprocess.run(["callgrind_annotate", "--inclusive=yes", "--threshold=100",
                          str(cg_file)], capture_output=True, text=True, check=True).stdout
    costs = {}
    for m in re.finditer(r"^\s*([\d,]+)\s+\([^)]*\)\s+\S*?:(\S+)", out, re.MULTILINE):
        name = m.group(2)
        costs[name] = max(costs.get(name, 0), int(m.group(1).replace(",", "")))
    return costs


def total_of(costs, *names):
    """Sum of the inclusive costs of the functions named: C functions by their exact name,
    Fortran module procedures ('_MOD_name') by the end of their mangled name."""
    return sum(v for k, v in costs.items()
               if any(k.endswith(n) if n.startswith("_MOD_") else k == n for n in names))


def split(costs, method):
    """Instructions of the parts (PARTS order) and the integrator's total."""
    # erk takes f and the quadratures' g in one call (rfem_rhs_quad) at every stage
    rhs = total_of(costs, "_MOD_rfem_rhs", "_MOD_rfem_quad_rhs", "_MOD_rfem_rhs_quad")
    if method == "erk":
        total = total_of(costs, "_MOD_erk_advance_to")
        return [rhs, 0, 0, 0, total - rhs], total
    if method == "symplectic":
        # the forces of the potential and of the rest in one call (rfem_split_rhs)
        rhs = total_of(costs, "_MOD_rfem_split_rhs")
        total = total_of(costs, "_MOD_symplectic_advance_to")
        return [rhs, 0, 0, 0, total - rhs], total
    if method == "cvode":
        total = total_of(costs, "CVode")
        jac = total_of(costs, "cv_jacobian", "cv_linsys")
        factor = total_of(costs, "cvLsSetup") - jac
        solve = total_of(costs, "SUNLinSolSolve")
    else:
        total = total_of(costs, "_MOD_mebdf_advance_to")
        jac = total_of(costs, "_MOD_matrix_evaluate_jacobian")
        factor = total_of(costs, "_MOD_matrix_factor")
        solve = total_of(costs, "_MOD_matrix_solve")
    parts = [rhs, jac, factor, solve]
    return [*parts, total - sum(parts)], total


def whole_split(costs):
    """Instructions of the WHOLE_PARTS and the program's total (any integrator)."""
    total = total_of(costs, "MAIN__")
    rhs = total_of(costs, "_MOD_rfem_rhs", "_MOD_rfem_quad_rhs", "_MOD_rfem_rhs_quad")
    # the outermost integrator (auto's inclusive cost holds the one it runs)
    integrator = next((c for c in (total_of(costs, name) for name in (
        "_MOD_auto_advance_to", "_MOD_erk_advance_to", "CVode", "_MOD_mebdf_advance_to"))
        if c > 0), 0)
    output = total_of(costs, "_MOD_output_append", "_MOD_output_write_stats",
                      "_MOD_output_close_run")
    return [rhs, integrator - rhs, output, total - integrator - output], total


def profile(exe, method, t_end, workdir, tag, whole=False):
    out = workdir / f"{tag}_{method}.h5"
    cg = workdir / f"{tag}_{method}.callgrind"
    log = workdir / f"{tag}_{method}.log"
    sets = [f"solver.t_end={t_end}", f'output.file="{out}"']
    if not whole:
        sets.append("solver.output_interval=0.1")
    if method != "default":
        sets.append(f'solver.method="{method}"')
    cmd = ["valgrind", "--tool=callgrind", f"--callgrind-out-file={cg}", str(exe), "run",
           str(PAPER), *set_args(sets)]
    with open(log, "w") as f:
        proc = subprocess.run(cmd, stdout=f, stderr=subprocess.STDOUT, text=True)
    text = log.read_text()
    if proc.returncode != 0:
        raise SystemExit(f"profile_step: {' '.join(cmd)} failed:\n{text[-2000:]}")
    steps = int(re.search(r"steps\s+(\d+)", text).group(1))
    costs = inclusive_costs(cg)
    parts, total = whole_split(costs) if whole else split(costs, method)
    return steps, parts, total


def build_baseline(rev, workdir, edit=None):
    """The ropedyn executable of git revision `rev` (Release, git archive); `edit(src)`, when
    given, changes the extracted source tree before the build (a variant of `rev`)."""
    src, build = workdir / "src", workdir / "build"
    src.mkdir()
    archive = subprocess.run(["git", "-C", str(ROOT), "archive", rev], capture_output=True,
                             check=True)
    subprocess.run(["tar", "-x", "-C", str(src)], input=archive.stdout, check=True)
    if edit is not None:
        edit(src)
    log = workdir / "build.log"
    with open(log, "w") as f:
        ok = subprocess.run(["cmake", "-S", str(src), "-B", str(build),
                             "-DCMAKE_BUILD_TYPE=Release"], stdout=f, stderr=f).returncode == 0
        ok = ok and subprocess.run(["cmake", "--build", str(build), "--target", "ropedyn",
                                    "-j", str(os.cpu_count())], stdout=f,
                                   stderr=f).returncode == 0
    if not ok:
        raise SystemExit(f"baseline build of {rev} failed; log: {log.read_text()[-3000:]}")
    return build / "ropedyn"


def row(label, method, steps, parts, total):
    per_step = total / steps
    shares = " | ".join(f"{p / steps / 1e3:.0f} ({100 * p / total:.0f} %)" for p in parts)
    return f"| {label} | {method} | {steps} | {per_step / 1e3:.0f} | {shares} |"


def main(argv=None):
    parser = argparse.ArgumentParser(description=summary(__doc__))
    add_exe_argument(parser)
    parser.add_argument("--t-end", type=float, default=1.0)
    parser.add_argument("--baseline", default=None,
                        help="git revision to profile as 'before' (e.g. main)")
    parser.add_argument("--methods", default="cvode mebdf",
                        help="integrators to profile: 'cvode mebdf' (default), 'erk', "
                             "'symplectic'")
    parser.add_argument("--whole-run", action="store_true",
                        help="the whole program with the scene's output (its own table)")
    parser.add_argument("--no-write", action="store_true", help="print only")
    args = parser.parse_args(argv)
    if args.whole_run and args.methods == "cvode mebdf":
        args.methods = "default"
    parts_names = WHOLE_PARTS if args.whole_run else PARTS
    rev = baseline_revision(parser, args.baseline)   # before the build, as every check
    if shutil.which("valgrind") is None:
        raise SystemExit("profile_step: valgrind is not installed")
    exe = exe_or_build(args.exe)
    check_names(parser, exe, "--methods", args.methods.split(), "solver", "method",
                extra=("default",))
    header = ("| build | solver | steps | instructions per step (k) | "
              + " | ".join(f"{p}: k per step (share)" for p in parts_names) + " |")
    rule = "|---|---|---|---|" + "---|" * len(parts_names)
    rows = []
    print(header)
    print(rule)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        builds = []
        if args.baseline:
            builds.append((f"{args.baseline} ({rev})", build_baseline(args.baseline, tmp)))
        builds.append(("this tree", exe))
        for label, path in builds:
            for method in args.methods.split():
                steps, parts, total = profile(path, method, args.t_end, tmp,
                                              re.sub(r"\W", "_", label), args.whole_run)
                rows.append(row(label, method, steps, parts, total))
                print(rows[-1], flush=True)
    if args.no_write:
        return 0
    command = "scripts/profile_step" + (f" --baseline {args.baseline}" if args.baseline
                                        else "") + f" --t-end {args.t_end:g}"
    begin, end, heading = BEGIN, END, "## Profile of a step (callgrind)\n\n"
    what = (f"{args.t_end:g} s, rtol 1e-6, default orders; instruction counts, inclusive, per "
            "accepted step")
    if args.whole_run:
        command += " --whole-run" + (f" --methods \"{args.methods}\""
                                     if args.methods != "default" else "")
        begin, end = "<!-- profile_step whole-run:begin -->", "<!-- profile_step whole-run:end -->"
        heading = "### Profile of the whole paper run (callgrind)\n\n"
        what = (f"{args.t_end:g} s as the scene ships it: its method (solver 'default'), rtol "
                "1e-6, a record every 0.01 s; instruction counts of the whole program, "
                "inclusive, per accepted step")
    elif args.methods.split() != ["cvode", "mebdf"]:
        command += f" --methods \"{args.methods}\""
        tag = "+".join(args.methods.split())
        begin, end = f"<!-- profile_step {tag}:begin -->", f"<!-- profile_step {tag}:end -->"
        heading = f"### Profile of a step: {tag} (callgrind)\n\n"
    block = "\n".join([
        begin,
        f"Command: `{command}` (valgrind callgrind, input/paper.nml, n = 30, {what}; see "
        "tools/ropedyn_tools/studies/profile_step.py for the functions that make each part).",
        f"Machine: {machine()}. Run: {run_stamp()}.",
        "", header, rule, *rows, end])
    update_doc(DOCS / "performance" / "step.md", begin, end, block, heading=heading)
    print(f"profile_step: table written to {DOCS / 'performance' / 'step.md'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
