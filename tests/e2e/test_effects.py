"""Effects end to end (issue #7): the echo of a scene with a motion table re-runs from another
directory (the table path is resolved against the scene file and stored absolute); the support
work is in the HDF5 energy balance; the MPP's drawn rope follows its moving top joint."""
import math
import pathlib

import h5py
import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[2]


def test_table_scene_echo_reruns(run, tmp_path):
    scene = ROOT / "input" / "table_motion.nml"
    first = run("run", scene, "--set", "solver.t_end=0.1", "--set", "model.elements=8",
                "--set", "output.file=a.h5")
    assert first.returncode == 0, first.stderr
    with h5py.File(tmp_path / "a.h5") as f:
        echo = f.attrs["scene"].decode()
        q_first = f["state/q"][-1]
    assert str(ROOT / "input" / "top_motion.dat") in echo
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (elsewhere / "echo.nml").write_text(echo.replace("file = 'a.h5'", "file = 'b.h5'"))
    second = run("run", "echo.nml", cwd=elsewhere)
    assert second.returncode == 0, second.stderr
    with h5py.File(elsewhere / "b.h5") as f:
        np.testing.assert_array_equal(f["state/q"][-1], q_first)


def test_support_work_in_the_balance(run, tmp_path):
    result = run("run", ROOT / "input" / "shaken_top.nml", "--set", "solver.t_end=0.5",
                 "--set", "model.elements=10", "--set", "supports.top_frequency=2",
                 "--set", "output.file=s.h5")
    assert result.returncode == 0, result.stderr
    with h5py.File(tmp_path / "s.h5") as f:
        e = f["energy"]
        work = e["support_work"][:]
        balance = e["total"][:] + e["dissipated"][:] - work
    assert abs(work).max() > 1e-4
    assert abs(balance - balance[0]).max() < 1e-3 * abs(work).max()


def test_mpp_polyline_follows_the_moving_top(run, tmp_path):
    result = run("run", ROOT / "input" / "shaken_top.nml", "--set", "model.kind=mpp",
                 "--set", "model.elements=6", "--set", "solver.t_end=0.3",
                 "--set", "solver.output_interval=0.05", "--set", "output.file=m.h5")
    assert result.returncode == 0, result.stderr
    with h5py.File(tmp_path / "m.h5") as f:
        t = f["time"][:]
        top = f["rope/points"][:, 0, :]
    np.testing.assert_allclose(top[:, 0], 0.0, atol=1e-15)
    np.testing.assert_allclose(top[:, 1], 0.01 * np.sin(2 * math.pi * 0.6 * t), atol=1e-12)
