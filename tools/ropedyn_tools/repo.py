"""The repository and the ropedyn executable, for the studies and the tests.

- `ROOT`, `PAPER`, ...: paths in the repository (this file is ROOT/tools/ropedyn_tools/repo.py,
  used where it is, never installed);
- `add_exe_argument`/`exe_or_build`: the common `--exe PATH` option; without it the Release
  configuration is built (or brought up to date) with scripts/build, as the scripts/
  commands always did before running a study;
- `set_args`: `--set` arguments for `ropedyn run`.
"""
import pathlib
import subprocess
import sys

from ropedyn_tools.arguments import list_text, positive

ROOT = pathlib.Path(__file__).resolve().parents[2]
INPUT = ROOT / "input"
PAPER = INPUT / "paper.nml"
DOCS = ROOT / "docs"


def build(build_type="Release"):
    """Configure and build with scripts/build; returns the build directory. Exits (code 1)
    when the build fails: scripts/build has printed the end of its log."""
    result = subprocess.run([str(ROOT / "scripts" / "build"), build_type],
                            stdout=subprocess.PIPE, text=True)
    if result.returncode != 0:
        sys.exit(result.returncode)
    return pathlib.Path(result.stdout.strip())


def add_exe_argument(parser, help_text="the ropedyn executable"):
    """The --exe option (default: the Release build, see exe_or_build)."""
    parser.add_argument("--exe", default=None,
                        help=f"{help_text} (default: build the Release configuration with "
                             "scripts/build and use build/release/ropedyn)")


def add_scaling_arguments(parser, t_end, elements, rtol=1e-6):
    """--exe, and --t-end, --rtol and --elements (n, a space-separated list) of a study
    that runs the paper's rope at several n."""
    add_exe_argument(parser)
    parser.add_argument("--t-end", type=float, default=t_end)
    parser.add_argument("--rtol", type=float, default=rtol)
    parser.add_argument("--elements", type=list_text(positive(int)), default=elements,
                        help="numbers of elements, space-separated")


def exe_or_build(exe):
    """exe as given, or the executable of the Release build (built or updated first)."""
    return exe if exe is not None else str(build("Release") / "ropedyn")


def set_args(sets):
    """['--set', s1, '--set', s2, ...] for the overrides sets."""
    return [arg for item in sets for arg in ("--set", item)]
