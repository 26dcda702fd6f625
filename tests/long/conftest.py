"""Fixtures of the long-horizon suite (CTest label `long`): the Release executable."""
import os
import pathlib

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def ropedyn_exe():
    exe = pathlib.Path(os.environ.get("ROPEDYN_EXE",
                                      ROOT / "build" / "release" / "ropedyn")).resolve()
    if not exe.is_file():
        pytest.fail(f"ropedyn executable not found at {exe} (set ROPEDYN_EXE)")
    return exe
