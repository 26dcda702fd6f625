"""Shared fixtures for the end-to-end tests: the ropedyn executable and a runner."""
import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def ropedyn_exe():
    exe = pathlib.Path(os.environ.get("ROPEDYN_EXE", ROOT / "build" / "debug" / "ropedyn")).resolve()
    if not exe.is_file():
        pytest.fail(f"ropedyn executable not found at {exe} (set ROPEDYN_EXE)")
    return exe


def library_path():
    """libropedyn of the build under test: ROPEDYN_LIBRARY, else beside the executable."""
    if os.environ.get("ROPEDYN_LIBRARY"):
        return pathlib.Path(os.environ["ROPEDYN_LIBRARY"]).resolve()
    exe = pathlib.Path(os.environ.get("ROPEDYN_EXE", ROOT / "build" / "debug" / "ropedyn"))
    return exe.resolve().parent / "libropedyn.so"


# `import ropedyn` in the tests (and in the programs they start) loads the library of the
# build under test, not another build of the tree (python/ropedyn/_lib.py)
os.environ.setdefault("ROPEDYN_LIBRARY", str(library_path()))


@pytest.fixture(scope="session")
def ropedyn_library():
    path = library_path()
    if not path.is_file():
        pytest.fail(f"libropedyn not found at {path} (set ROPEDYN_LIBRARY)")
    return path


@pytest.fixture
def run(ropedyn_exe, tmp_path):
    """Run `ropedyn ARGS...` in tmp_path; returns the CompletedProcess."""

    def _run(*args, cwd=None, timeout=600):
        return subprocess.run([str(ropedyn_exe), *map(str, args)], cwd=cwd or tmp_path,
                              capture_output=True, text=True, timeout=timeout)

    return _run
