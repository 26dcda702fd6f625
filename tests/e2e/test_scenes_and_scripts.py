"""Every shipped scene reads and runs; progress shows on request; the energy plot of
scripts/run is made from an output file."""
import os
import pathlib
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
# folders named sweeps hold sweep files (ropedyn sweep), not scenes
SCENES = sorted(p for p in (ROOT / "input").glob("**/*.nml") if "sweeps" not in p.parts)
SWEEPS = sorted(p for p in (ROOT / "input").glob("**/*.nml") if "sweeps" in p.parts)
# 10000 elements cost about 0.1 s of CPU per millisecond in the Debug build: a shorter run
HORIZON = {"elements_10000": 0.001}


@pytest.mark.parametrize("scene", SCENES, ids=[s.stem for s in SCENES])
def test_shipped_scene_runs(run, tmp_path, scene):
    t_end = HORIZON.get(scene.stem, 0.02)
    result = run("run", scene, "--set", f"solver.t_end={t_end}", "--set", "output.file=s.h5")
    assert result.returncode == 0, result.stderr
    assert "balance error" in result.stdout


@pytest.mark.parametrize("sweep", SWEEPS, ids=[str(s.relative_to(ROOT / "input")) for s in SWEEPS])
def test_shipped_sweep_reads(run, tmp_path, sweep):
    result = run("sweep", sweep, "--list")
    assert result.returncode == 0, result.stderr
    assert "missing" in result.stdout


def test_progress_on_request(run, tmp_path):
    (tmp_path / "p.nml").write_text(
        "&model kind = 'rfem', elements = 4 /\n&solver t_end = 0.05 /\n"
        "&output progress = .true. /\n")
    result = run("run", "p.nml")
    assert result.returncode == 0, result.stderr
    assert "left" in result.stderr and "100.0 %" in result.stderr and " s/s " in result.stderr


def test_progress_forced_off_on_a_terminal(ropedyn_exe, tmp_path):
    """Progress is on by default when stderr is a terminal; progress = .false. forces it off
    (stderr a pseudo-terminal here)."""
    import pty
    import subprocess
    (tmp_path / "t.nml").write_text("&model kind = 'rfem', elements = 4 /\n"
                                    "&solver t_end = 0.05 /\n")
    seen = {}
    for label, extra in (("default", []), ("off", ["--set", "output.progress=.false."])):
        leader, follower = pty.openpty()
        proc = subprocess.run([str(ropedyn_exe), "run", "t.nml", *extra], cwd=tmp_path,
                              stdout=subprocess.DEVNULL, stderr=follower, timeout=120)
        os.close(follower)
        chunks = []
        while True:
            try:
                chunk = os.read(leader, 4096)
            except OSError:
                break
            if not chunk:
                break
            chunks.append(chunk)
        os.close(leader)
        assert proc.returncode == 0
        seen[label] = b"".join(chunks).decode(errors="replace")
    assert "100.0 %" in seen["default"] and "left" in seen["default"], seen
    assert seen["off"] == "", seen


def test_silent_without_terminal(run, tmp_path):
    (tmp_path / "q.nml").write_text("&model kind = 'rfem', elements = 4 /\n"
                                    "&solver t_end = 0.05 /\n")
    result = run("run", "q.nml")
    assert result.returncode == 0 and result.stderr == ""


def test_energy_plot(run, tmp_path):
    (tmp_path / "e.nml").write_text("&model kind = 'rfem', elements = 4 /\n"
                                    "&solver t_end = 0.2, output_interval = 0.01 /\n")
    assert run("run", "e.nml").returncode == 0
    png = tmp_path / "out" / "e_energy.png"
    result = subprocess.run([sys.executable, str(ROOT / "scripts" / "plot_energy.py"),
                             str(tmp_path / "out" / "e.h5"), "-o", str(png)],
                            capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    data = png.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10000
