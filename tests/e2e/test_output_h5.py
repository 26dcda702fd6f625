"""The HDF5 output read back with h5py: layout, shapes, units, status, energies, the
effective scene stored in the file re-runs to the same result, and the f evaluations of
differenced Jacobians are counted, printed and carried across resumes."""
import subprocess
import sys

import h5py
import numpy as np
import pytest

from ropedyn import layout
from ropedyn.io import load_run
from ropedyn.layout import check_layout

SCENE = """
&model kind = 'rfem', elements = 5 /
&solver t_end = 0.3, output_interval = 0.05, rtol = 1e-8, atol = 1e-10 /
&output file = 'out/small.h5' /
"""


def test_layout_and_rerun(run, tmp_path):
    (tmp_path / "small.nml").write_text(SCENE)
    result = run("run", "small.nml")
    assert result.returncode == 0, result.stderr
    path = tmp_path / "out" / "small.h5"
    summary = check_layout(str(path), 5)
    assert summary["status"] == "complete"
    with h5py.File(path) as f:
        t = f["time"][:]
        assert np.allclose(t, np.arange(7) * 0.05, rtol=0, atol=1e-12)
        assert f["state/q"].shape == (7, 5, 3)
        assert f["rope/points"].shape == (7, 10, 2)
        assert f.attrs["model"].decode() == "rfem" and f.attrs["method"].decode() == "auto"
        assert f["energy/total"].attrs["units"].decode() == "J"
        # initial state: straight at 75 degrees from the top anchor, at rest
        q0 = f["state/q"][0]
        assert np.allclose(q0[:, 2], np.radians(75.0))
        assert np.allclose(f["state/qdot"][0], 0.0)
        assert np.allclose(f["rope/points"][0, 0], [0.0, 0.0], atol=1e-15)
        assert np.allclose(f["rope/points"][0, -1], [np.cos(np.radians(75)),
                                                     np.sin(np.radians(75))], atol=1e-12)
        e = {k: f["energy"][k][:] for k in f["energy"]}
        assert np.allclose(e["total"], e["kinetic"] + e["elastic"] + e["gravity"])
        balance = e["total"] + e["dissipated"] - e["support_work"]
        assert np.max(np.abs(balance - balance[0])) < 1e-6 * abs(balance[0])
        scene_text = f.attrs["scene"].decode()
        q_end = f["state/q"][-1]
    # the stored effective scene re-runs to the same result
    (tmp_path / "again.nml").write_text(scene_text.replace("out/small.h5", "out/again.h5"))
    result = run("run", "again.nml")
    assert result.returncode == 0, result.stderr
    with h5py.File(tmp_path / "out" / "again.h5") as f:
        assert np.array_equal(f["state/q"][-1], q_end)


def test_free_rope_falls_freely(run, tmp_path):
    """The same rope with its top free: released straight and unstretched, every element
    starts in free fall (docs/theory/rfem.md, "Initial states") and no strain ever builds
    up, so every element centre falls g t^2/2 from rest, none moves sideways or turns.
    Measured: 7.5e-10 m at rtol 1e-8 (the integrator's error of its first, low-order
    steps); bound 5e-9 m."""
    (tmp_path / "free.nml").write_text(SCENE.replace("&model kind = 'rfem', elements = 5 /",
                                                     "&model kind = 'rfem', elements = 5 /\n"
                                                     "&supports top = 'free' /"))
    result = run("run", "free.nml", "--set", "output.file=free.h5")
    assert result.returncode == 0, result.stderr
    with h5py.File(tmp_path / "free.h5") as f:
        t = f["time"][:]
        q = f["state/q"][:]
    fall = q[:, :, 0] - q[0, :, 0]
    assert np.max(np.abs(fall - 9.81 * t[:, None]**2 / 2)) < 5e-9
    assert np.max(np.abs(q[:, :, 1:] - q[0, :, 1:])) < 5e-9


def test_layout_refuses_a_sweep_summary(tmp_path):
    """A sweep's summary.h5 has no layout per element: python -m ropedyn.layout says what
    the file is instead of failing on the first dataset a run file has."""
    path = tmp_path / "summary.h5"
    with h5py.File(path, "w") as f:
        f.attrs["sweep"] = np.bytes_("s.sweep")
        f["case"] = np.arange(1, 3)
    result = subprocess.run([sys.executable, "-m", "ropedyn.layout", str(path), "5"],
                            capture_output=True, text=True)
    assert result.returncode == 1
    assert f"{path}: a sweep summary (root attribute 'sweep')" in result.stderr, \
        result.stderr



def test_layout_checks_an_interrupted_and_a_killed_runs_file(run, tmp_path):
    """The file of an interrupted run (status `interrupted`, a reason, its statistics) and of
    a killed one (status `running`, no statistics of its own, a block of records written
    halfway: the series one record longer than /time) have the layout of a complete run's:
    python -m ropedyn.layout checks them and says what the status means. Made from a
    complete run's file as the run would have left them."""
    (tmp_path / "small.nml").write_text(SCENE)
    assert run("run", "small.nml").returncode == 0
    complete = tmp_path / "out" / "small.h5"
    interrupted, killed = tmp_path / "interrupted.h5", tmp_path / "killed.h5.part"
    for path in (interrupted, killed):
        path.write_bytes(complete.read_bytes())
    with h5py.File(interrupted, "r+") as f:
        f.attrs["status"] = np.bytes_("interrupted")
        f.attrs["reason"] = np.bytes_("interrupted.h5: interrupted by SIGTERM at t = 0.3 s "
                                      "of 1.0 s (its last record; host h, pid 1)")
    with h5py.File(killed, "r+") as f:
        f.attrs["status"] = np.bytes_("running")
        for name in [name for name in f["solver"] if f["solver"][name].shape == ()]:
            del f["solver"][name]
        for name in ("state/q", "energy/total"):              # written before /time
            f[name].resize(f["time"].shape[0] + 1, axis=0)
    for path, status, says in ((interrupted, "interrupted", "a signal stopped the run"),
                               (killed, "running", "the run was killed or crashed")):
        assert check_layout(str(path), 5)["status"] == status
        result = subprocess.run([sys.executable, "-m", "ropedyn.layout", str(path), "5"],
                                capture_output=True, text=True)
        assert result.returncode == 0, result.stderr
        assert f"layout OK (run file, 7 records, status {status}" in result.stdout
        assert f"status {status}: {says}" in result.stdout, result.stdout
    # a complete file must still have its statistics
    with h5py.File(complete, "r+") as f:
        del f["solver/steps"]
    with pytest.raises(AssertionError, match="/solver/steps is missing"):
        check_layout(str(complete), 5)


def test_layout_fails_a_killed_file_whose_last_record_does_not_read_back(run, tmp_path,
                                                                          monkeypatch):
    """A run killed in the middle of a flush can leave series whose last chunk HDF5 cannot
    read ("addr overflow"); such a file is not "valid up to the last record", and a resume
    of it is refused. python -m ropedyn.layout fails it, naming the series and the record,
    and fails, not crashes, on a file h5py cannot walk (RuntimeError). Made here from a
    complete run's file: /state/y rewritten compressed, its last chunk then damaged."""
    (tmp_path / "small.nml").write_text(SCENE)
    assert run("run", "small.nml").returncode == 0
    killed = tmp_path / "killed.h5.part"
    killed.write_bytes((tmp_path / "out" / "small.h5").read_bytes())
    with h5py.File(killed, "r+") as f:
        f.attrs["status"] = np.bytes_("running")
        y = f["state/y"]
        values, chunks, attrs = y[()], y.chunks, dict(y.attrs)
        del f["state/y"]
        y = f.create_dataset("state/y", data=values, chunks=chunks,
                             maxshape=(None,) + values.shape[1:], compression="gzip")
        y.attrs.update(attrs)
    assert check_layout(str(killed), 5)["status"] == "running"
    with h5py.File(killed, "r") as f:
        y = f["state/y"]
        last = y.id.get_chunk_info(y.id.get_num_chunks() - 1)
    with open(killed, "r+b") as raw:
        raw.seek(last.byte_offset)
        raw.write(b"\xff" * last.size)
    with pytest.raises(AssertionError, match=r"/state/y: record 6 \(the last of /time\) "
                                             r"does not read back"):
        check_layout(str(killed), 5)
    result = subprocess.run([sys.executable, "-m", "ropedyn.layout", str(killed), "5"],
                            capture_output=True, text=True)
    assert result.returncode == 1 and "FAIL" in result.stderr, result.stderr
    assert "Traceback" not in result.stderr

    def walk_fails(path, n_elements):
        raise RuntimeError("Object visitation failed (len not positive after adjustment "
                           "for EOA)")
    monkeypatch.setattr(layout, "check_layout", walk_fails)
    assert layout.main([str(killed), "5"]) == 1


# the MPP model on MEBDF's first-order Newton matrix: its mass matrix leaves no analytic
# Jacobian of the first-order system, so MEBDF differences it (ropedyn_iteration_matrix_first)
DIFFERENCED = """
&model kind = 'mpp', elements = 4 /
&solver method = 'mebdf', first_order_newton = .true., t_end = 0.2, output_interval = 0.05,
        rtol = 1e-5, atol = 1e-8 /
&output file = 'fd.h5', progress = .false. /
"""
COUNTERS = ("rhs_evals", "jac_rhs_evals", "jac_evals")


def counters(path):
    """/solver's rhs_evals, jac_rhs_evals and jac_evals (None when absent) and the state
    size."""
    with h5py.File(path) as f:
        return ({k: int(f[f"solver/{k}"][()]) if f"solver/{k}" in f else None
                 for k in COUNTERS}, f["state/y"].shape[1])


def test_f_evaluations_of_differenced_jacobians_are_written_and_printed(run, tmp_path):
    """/solver/jac_rhs_evals holds the f evaluations spent differencing Jacobians, which
    /solver/rhs_evals leaves out, and the summary adds them to its rhs evals. A differenced
    Jacobian of MEBDF evaluates F at y and once per column group, and the MPP's band is
    full: N + 1 evaluations per Jacobian for a state of N. With analytic Jacobians (MEBDF's
    reduced matrix, CVODE's first-order one on the same rope) the counter is 0 and the
    summary says nothing of it. ropedyn.load_run gives it among the stats."""
    (tmp_path / "fd.nml").write_text(DIFFERENCED)
    result = run("run", "fd.nml")
    assert result.returncode == 0, result.stderr
    c, n = counters(tmp_path / "fd.h5")
    print(f"mebdf, first-order matrix: {c}, state size {n}")
    assert c["jac_evals"] > 0 and c["jac_rhs_evals"] == (n + 1) * c["jac_evals"]
    assert (f"rhs evals {c['rhs_evals']} (+ {c['jac_rhs_evals']} for Jacobian "
            f"differencing)") in result.stdout, result.stdout
    check_layout(str(tmp_path / "fd.h5"), 4)
    with h5py.File(tmp_path / "fd.h5") as f:
        dset = f["solver/jac_rhs_evals"]
        assert dset.dtype == np.int64 and dset.attrs["units"] == b"1"
    assert load_run(tmp_path / "fd.h5").stats["jac_rhs_evals"] == c["jac_rhs_evals"]
    for name, setting in (("reduced", "solver.first_order_newton=.false."),
                          ("cvode", "solver.method='cvode'")):
        result = run("run", "fd.nml", "--set", f"output.file='{name}.h5'", "--set", setting)
        assert result.returncode == 0, result.stderr
        c, _ = counters(tmp_path / f"{name}.h5")
        assert c["jac_evals"] > 0 and c["jac_rhs_evals"] == 0, (name, c)
        assert "Jacobian differencing" not in result.stdout
    # a layout check that holds the counter to the others' type and units
    with h5py.File(tmp_path / "fd.h5", "r+") as f:
        f["solver/jac_rhs_evals"].attrs["units"] = np.bytes_("s")
    with pytest.raises(AssertionError, match="/solver/jac_rhs_evals units 's'"):
        check_layout(str(tmp_path / "fd.h5"), 4)


def test_f_evaluations_of_differenced_jacobians_add_up_over_a_resume(run, tmp_path):
    """A resumed run's /solver/jac_rhs_evals counts its parts, as its jac_evals do: N + 1
    per Jacobian over both (the second part's own alone would fall short by the first's).
    A file of an earlier version, without the dataset, passes the layout check and is
    continued; its earlier part counts 0, the dataset is written again for the part that
    continued it."""
    (tmp_path / "fd.nml").write_text(DIFFERENCED)
    for name in ("a.h5", "b.h5"):
        result = run("run", "fd.nml", "--set", "solver.t_end=0.1", "--set",
                     f"output.file='{name}'")
        assert result.returncode == 0, result.stderr
    first, n = counters(tmp_path / "a.h5")
    assert first["jac_rhs_evals"] > 0
    result = run("run", "--resume", "a.h5", "--set", "solver.t_end=0.2")
    assert result.returncode == 0, result.stderr
    both, _ = counters(tmp_path / "a.h5")
    print(f"first part {first}, both {both}")
    assert both["jac_evals"] > first["jac_evals"]
    assert both["jac_rhs_evals"] == (n + 1) * both["jac_evals"]
    assert f"(+ {both['jac_rhs_evals']} for Jacobian differencing)" in result.stdout
    # as a file of an earlier version
    with h5py.File(tmp_path / "b.h5", "r+") as f:
        del f["solver/jac_rhs_evals"]
    check_layout(str(tmp_path / "b.h5"), 4)
    assert "jac_rhs_evals" not in load_run(tmp_path / "b.h5").stats
    result = run("run", "--resume", "b.h5", "--set", "solver.t_end=0.2")
    assert result.returncode == 0, result.stderr
    later, _ = counters(tmp_path / "b.h5")
    assert later["jac_evals"] == both["jac_evals"]
    assert later["jac_rhs_evals"] == (n + 1) * (later["jac_evals"] - first["jac_evals"]) > 0
    check_layout(str(tmp_path / "b.h5"), 4)
