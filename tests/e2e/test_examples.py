"""The examples in examples/ run as a user runs them, against the library of the build
under test: the crane loop (Python, a coupled top, a plot), the floating body coupled to
the rope (C, compiled here with cc against include/ropedyn.h), the scan over EA
(Python). Each asserts what its physics says: the load's weight at the crane tip at rest,
the body pulled down by the rope's weight and towards the anchor, the scan's peak tension
as the command line's run of the same EA."""
import math
import re
import shutil
import subprocess
import sys

import h5py
import numpy as np
import pytest

from conftest import ROOT

EXAMPLES = ROOT / "examples"
G = 9.81
ROPE_MASS = 6000.0 * math.pi * 0.005 ** 2 / 4   # kg: the paper's rope, 1 m


def python(*args, cwd):
    result = subprocess.run([sys.executable, *map(str, args)], cwd=cwd, capture_output=True,
                            text=True, timeout=600)
    assert result.returncode == 0, result.stderr
    return result.stdout


def test_crane_tip_loop_plots_the_tension(tmp_path):
    out = python(EXAMPLES / "crane_tip.py", "--t-end", "2.5", "--out", "t.png", cwd=tmp_path)
    assert (tmp_path / "t.png").stat().st_size > 10000
    rest, most, least = map(float, re.findall(r"([\d.]+) N", out))
    # at rest the tip holds the load and the rope
    assert rest == pytest.approx((0.5 + ROPE_MASS) * G, rel=1e-3)
    # the load lags and swings: the tension moves away from the weight
    assert most > rest + 0.1 and least < rest


def test_floating_body_in_c(tmp_path, ropedyn_library):
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        pytest.skip("no C compiler")
    exe = tmp_path / "floating_body"
    subprocess.run([cc, "-std=c11", "-Wall", "-Wextra", "-Werror",
                    str(EXAMPLES / "floating_body.c"), "-I", str(ROOT / "include"),
                    "-L", str(ropedyn_library.parent), "-lropedyn",
                    f"-Wl,-rpath,{ropedyn_library.parent}", "-lm", "-o", str(exe)],
                   check=True)
    result = subprocess.run([str(exe), "4", "0.5"], cwd=tmp_path, capture_output=True,
                            text=True, timeout=600)
    assert result.returncode == 0, result.stderr
    lines = result.stdout.split("\n")
    rows = np.array([[float(v) for v in line.split()] for line in lines
                     if line and not line.startswith("mean")])
    mean = [float(v) for v in lines[-2].split()[1:]]
    assert rows.shape == (8, 5) and np.allclose(rows[:, 0], np.arange(8) * 0.5)
    # the rope at rest between the body and the anchor carries part of its weight on the
    # body: downwards (x), less than all of it, and pulls it towards the anchor (y > 0)
    assert 0.3 * ROPE_MASS * G < rows[0, 3] < ROPE_MASS * G and rows[0, 4] > 0
    # so the body sinks by about that force over the hydrostatic stiffness, and drifts
    # towards the anchor (0.5 m to the side) without reaching it
    assert mean[0] == pytest.approx(rows[0, 3] / 200.0, rel=0.3)
    assert 0.05 < mean[1] < 0.5
    assert np.all(np.abs(rows[:, 1]) < 0.05)


def test_scan_over_ea_is_the_command_lines_runs(run, tmp_path):
    out = python(EXAMPLES / "scan_ea.py", cwd=tmp_path)
    found = re.findall(r"EA = +([\d.]+) N: peak tension ([\d.]+) N", out)
    assert [float(ea) for ea, _ in found] == [100.0, 300.0, 1000.0, 3000.0]
    peaks = [float(p) for _, p in found]
    assert len(set(peaks)) == 4 and min(peaks) > ROPE_MASS * G
    # one of them against the command line
    area = math.pi * 0.005 ** 2 / 4
    result = run("run", ROOT / "input" / "paper.nml", "--set", "solver.t_end=2.0",
                 "--set", f"rope.young_modulus={1000.0 / area!r}", "--set",
                 "output.file=ea.h5")
    assert result.returncode == 0, result.stderr
    with h5py.File(tmp_path / "ea.h5") as f:
        assert f"{f['forces/axial'][:].max():.3f}" == f"{peaks[2]:.3f}"
