"""Regenerate the regression references tests/reference/<name>.h5 from <name>.nml, keeping
only converged ones.

usage: scripts/update_references [--exe PATH] [--check] [NAME ...]

A scene NAME.nml is run as `ropedyn run`, or as `ropedyn statics` / `ropedyn modes` when
NAME ends in `_statics` / `_modes`. The convergence guard: a run's reference is accepted only
when the same scene at a ten times tighter tolerance (rtol and atol / 10) agrees with it
within the comparison tolerances of ropedyn_tools.compare, so a reference holds the solution, not
the solver's noise; a statics or modes reference only when its equilibrium is at the rounding
level (residual / weight <= 1e-10). A refused reference is not written (the old one stays)
and the command exits 1 naming it. --check runs the guard on the existing references without
writing anything. Without --exe the Release configuration is built first. A commit that
changes the references must say why the results changed.
"""
import argparse
import pathlib
import shutil
import subprocess
import sys
import tempfile

import h5py

from ropedyn_tools.compare import compare
from ropedyn.namelist import parse_namelist
from ropedyn_tools.repo import ROOT, add_exe_argument, exe_or_build

REFERENCE = ROOT / "tests" / "reference"
#: solver tolerances of a scene that does not set them (docs/reference/keys.md, &solver)
DEFAULT_RTOL, DEFAULT_ATOL = 1e-6, 1e-8
#: largest residual / weight of an accepted statics or modes reference
STATICS_RESIDUAL = 1e-10


def names():
    """The reference scenes, sorted."""
    return sorted(p.stem for p in REFERENCE.glob("*.nml"))


def analysis_of(name):
    """'statics', 'modes' or 'run' (by the name's suffix)."""
    for analysis in ("statics", "modes"):
        if name.endswith(f"_{analysis}"):
            return analysis
    return "run"


def command(exe, scene, out, sets=()):
    """The ropedyn command that writes the output of scene (a reference .nml) to out."""
    analysis = analysis_of(pathlib.Path(scene).stem)
    extra = [arg for item in sets for arg in ("--set", item)]
    if analysis == "run":
        return [str(exe), "run", str(scene), "--set", f"output.file={out}", *extra]
    return [str(exe), analysis, str(scene), "-o", str(out), *extra]


def tighter(scene):
    """--set overrides with ten times tighter rtol and atol than the scene's."""
    solver = parse_namelist(pathlib.Path(scene).read_text()).get("solver", {})
    rtol = float(solver.get("rtol", DEFAULT_RTOL))
    atol = float(solver.get("atol", DEFAULT_ATOL))
    return [f"solver.rtol={rtol / 10:.3e}", f"solver.atol={atol / 10:.3e}"]


def produce(exe, scene, out, sets=()):
    """Run the reference scene's analysis into out; raises RuntimeError on failure."""
    result = subprocess.run(command(exe, scene, out, sets), capture_output=True, text=True,
                            cwd=pathlib.Path(scene).parent)
    if result.returncode != 0:
        raise RuntimeError(f"{pathlib.Path(scene).name}: ropedyn exited "
                           f"{result.returncode}: {result.stderr.strip()}")


def guard(exe, scene, candidate, workdir, out=sys.stdout):
    """Reasons why candidate (the output of scene) is not a converged reference ([] if it is)."""
    name = pathlib.Path(scene).stem
    if analysis_of(name) != "run":
        with h5py.File(candidate, "r") as f:
            residual = float(f["statics/residual_relative"][()])
        if residual > STATICS_RESIDUAL:
            return [f"equilibrium residual {residual:.1e} of the weight > {STATICS_RESIDUAL:.0e}"]
        return []
    tight = pathlib.Path(workdir) / f"{name}_tight.h5"
    sets = tighter(scene)
    produce(exe, scene, tight, sets)
    print(f"  {name}: against its run with {' '.join(sets)}", file=out)
    failures = compare(candidate, tight, out=out)
    return [f"differs from its run at ten times tighter tolerances in {', '.join(failures)}"] \
        if failures else []


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog="update_references", description=__doc__.split("\n\n")[0],
        formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("names", nargs="*", help="reference names (default: all)")
    parser.add_argument("--check", action="store_true",
                        help="run the guard on the existing references, write nothing")
    add_exe_argument(parser)
    args = parser.parse_args(argv)
    exe = pathlib.Path(exe_or_build(args.exe)).resolve()
    refused = []
    with tempfile.TemporaryDirectory() as workdir:
        for name in args.names or names():
            scene = REFERENCE / f"{name}.nml"
            if not scene.is_file():
                parser.error(f"no reference scene {scene}")
            try:
                if args.check:
                    candidate = REFERENCE / f"{name}.h5"
                else:
                    candidate = pathlib.Path(workdir) / f"{name}.h5"
                    produce(exe, scene, candidate)
                reasons = guard(exe, scene, candidate, workdir)
            except RuntimeError as failure:
                reasons = [str(failure)]
            if reasons:
                refused.append(name)
                print(f"update_references: REFUSED {name}: {'; '.join(reasons)}")
            elif args.check:
                print(f"update_references: {name} is converged")
            else:
                shutil.copyfile(candidate, REFERENCE / f"{name}.h5")
                print(f"update_references: tests/reference/{name}.h5")
    if refused:
        print(f"update_references: {len(refused)} not converged (kept as they were): "
              f"{', '.join(refused)}; tighten the scene's tolerances or shorten it")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
