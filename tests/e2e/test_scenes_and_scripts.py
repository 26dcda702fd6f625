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


def test_energy_plot_script_runs_itself_in_the_venv(run, tmp_path):
    """Started by the system's python3 (the shebang), which has no ropedyn package: before,
    an ImportError; now it runs itself with the project's venv."""
    (tmp_path / "e.nml").write_text("&model kind = 'rfem', elements = 4 /\n"
                                    "&solver t_end = 0.05, output_interval = 0.01 /\n")
    assert run("run", "e.nml").returncode == 0
    png = tmp_path / "e.png"
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    result = subprocess.run(["/usr/bin/python3", str(ROOT / "scripts" / "plot_energy.py"),
                             str(tmp_path / "out" / "e.h5"), "-o", str(png)],
                            capture_output=True, text=True, env=env)
    assert result.returncode == 0, result.stderr
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("script,words", [("build", "scripts/build [Release|Debug]"),
                                          ("setup", "scripts/setup --tests"),
                                          ("test", "scripts/test --long"),
                                          ("run", "ropedyn run --help")])
def test_shell_scripts_answer_help(script, words):
    """`--help` prints the script's usage and does nothing else (before, scripts/build --help
    configured a build in build/--help, and setup and run installed and built first)."""
    result = subprocess.run([str(ROOT / "scripts" / script), "--help"], capture_output=True,
                            text=True, timeout=30)
    assert result.returncode == 0 and words in result.stdout, result.stdout + result.stderr
    assert not (ROOT / "build" / "--help").exists()


def test_build_refuses_an_unknown_type():
    result = subprocess.run([str(ROOT / "scripts" / "build"), "Relase"], capture_output=True,
                            text=True, timeout=30)
    assert result.returncode == 2 and 'not "Relase"' in result.stderr
    assert not (ROOT / "build" / "relase").exists()


def test_build_refuses_an_option_as_a_target():
    """`scripts/build Release -j1` passed -j1 to CMake as a target (and built nothing); the
    way to fewer cores is CMAKE_BUILD_PARALLEL_LEVEL, which the refusal names."""
    result = subprocess.run([str(ROOT / "scripts" / "build"), "Release", "-j1"],
                            capture_output=True, text=True, timeout=30)
    assert result.returncode == 2 and '"-j1" is no target' in result.stderr
    assert "CMAKE_BUILD_PARALLEL_LEVEL" in result.stderr
