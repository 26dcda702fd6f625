"""`&initial shape = 'state'`: a run started from a record of an earlier run's file continues
that run. Each case runs a scene continuously to t_end, then again from its record at t0;
the restarted run must reproduce the first record exactly (up to the rebuilding of the
model's state from the stored fields) and every later record to the integrator's tolerance,
with the dissipated energy and the external work carried over.
Bad state files fail with a message naming the file, the key and what is wrong."""
import h5py
import numpy as np
import pytest

BASE = """
&model kind = '{kind}', elements = {n} /
&supports top = 'pinned' {motion} /
&initial shape = 'straight', angle_deg = 75.0 /
&effects tension = {tension} /
&solver t_end = 1.0, output_interval = 0.02, rtol = 1e-8, atol = 1e-10 /
&output file = 'full.h5' /
"""
MOTION = ", top_motion = 'harmonic', top_amplitude = 0.0, 0.02, top_frequency = 1.5"

# (kind, n, tension, moving top) and the bound on the largest point difference (m) over
# [t0, t_end]. Measured (Release): rfem 2.2e-9, mpp 1.1e-9, mpp inextensible 6.5e-9,
# mpp with the top shaken 7.2e-10, rfem shaken 1.7e-9 m: a fresh
# start of the integrator at t0 (first-order steps) differs from the continuous run by
# the integrator's error at rtol 1e-8. Bounds about 4x the measured values. A wrong
# rebuild (e.g. the MPP's elongation off by its rest length) is off by 1e-2 m or more.
CASES = [
    ("rfem", 6, ".true.", False, 1e-8),
    ("mpp", 6, ".true.", False, 5e-9),
    ("mpp", 6, ".false.", False, 3e-8),
    ("mpp", 6, ".true.", True, 3e-9),
    ("rfem", 6, ".true.", True, 8e-9),
]


@pytest.mark.parametrize("kind,n,tension,moving,bound", CASES)
def test_restart_matches_continuous_run(run, tmp_path, kind, n, tension, moving, bound):
    scene = BASE.format(kind=kind, n=n, tension=tension, motion=MOTION if moving else "")
    (tmp_path / "s.nml").write_text(scene)
    result = run("run", "s.nml")
    assert result.returncode == 0, result.stderr
    t0 = 0.5
    result = run("run", "s.nml", "--set", "initial.shape='state'", "--set",
                 "initial.state_file='full.h5'", "--set", f"initial.state_time={t0}",
                 "--set", "output.file='re.h5'")
    assert result.returncode == 0, result.stderr
    with h5py.File(tmp_path / "full.h5") as a, h5py.File(tmp_path / "re.h5") as b:
        ta, tb = a["time"][:], b["time"][:]
        i0 = int(np.argmin(abs(ta - t0)))
        # the same output times from the record on
        assert np.allclose(tb, ta[i0:], rtol=0, atol=1e-12)
        pa, pb = a["rope/points"][i0:], b["rope/points"][:]
        # the first record is the stored one, rebuilt (fields -> state -> polyline)
        assert np.max(np.abs(pa[0] - pb[0])) < 1e-12
        assert np.max(np.abs(pa - pb)) < bound
        for name in ("dissipated", "support_work", "total"):
            ea, eb = a["energy"][name][i0:], b["energy"][name][:]
            assert abs(ea[0] - eb[0]) < 1e-12, name
            assert np.max(np.abs(ea - eb)) < 1e-7, name
        if moving:
            assert abs(b["energy/support_work"][0]) > 1e-6  # carried over, not restarted
        assert b["energy/dissipated"][0] > 1e-6


@pytest.mark.parametrize("kind", ["rfem", "mpp"])
def test_start_from_the_fields_of_a_middle_record(run, tmp_path, kind):
    """A file without restart data (/state/y, /state/yq: written by an older version)
    starts from its record's element fields and energies: record 25 of 51, neither the
    first nor the last, so that a neighbouring record read instead (the reader reads one
    record of each series, not the series) shows in the first record of the new run: its
    points (q), kinetic energy (qdot), dissipated energy and the top's work, each stored
    at t0, rebuilt to rounding."""
    (tmp_path / "s.nml").write_text(BASE.format(kind=kind, n=6, tension=".true.",
                                                motion=MOTION))
    assert run("run", "s.nml").returncode == 0
    with h5py.File(tmp_path / "full.h5", "r+") as f:
        del f["state/y"], f["state/yq"]
    t0 = 0.5
    result = run("run", "s.nml", "--set", "initial.shape='state'", "--set",
                 "initial.state_file='full.h5'", "--set", f"initial.state_time={t0}",
                 "--set", "output.file='re.h5'")
    assert result.returncode == 0, result.stderr
    with h5py.File(tmp_path / "full.h5") as a, h5py.File(tmp_path / "re.h5") as b:
        ta = a["time"][:]
        i0 = int(np.argmin(abs(ta - t0)))
        assert i0 == 25 and len(ta) == 51 and b["time"][0] == ta[i0]
        assert np.max(np.abs(a["rope/points"][i0] - b["rope/points"][0])) < 1e-12
        for name in ("kinetic", "dissipated", "support_work"):
            ea, eb = a["energy"][name], b["energy"][name]
            assert abs(ea[i0] - eb[0]) < 1e-12 * max(1.0, abs(ea[i0])), name
            # the neighbours differ from it by far more than that
            assert min(abs(ea[i0 - 1] - ea[i0]), abs(ea[i0 + 1] - ea[i0])) > 1e-9, name


def test_last_record_by_default(run, tmp_path):
    """state_time < 0 (the default) takes the last record: the run continues to a later
    t_end from where the first one stopped."""
    (tmp_path / "s.nml").write_text(BASE.format(kind="rfem", n=4, tension=".true.",
                                                motion=""))
    assert run("run", "s.nml", "--set", "solver.t_end=0.3").returncode == 0
    result = run("run", "s.nml", "--set", "initial.shape='state'", "--set",
                 "initial.state_file='full.h5'", "--set", "output.file='more.h5'")
    assert result.returncode == 0, result.stderr
    with h5py.File(tmp_path / "more.h5") as f:
        t = f["time"][:]
    assert abs(t[0] - 0.3) < 1e-12 and abs(t[-1] - 1.0) < 1e-12


@pytest.mark.parametrize("sets,words", [
    ([], ["&initial", "state_file", "''", "needed"]),
    (["initial.state_file='nothere.h5'"], ["&initial", "state_file", "nothere.h5",
                                           "no such file"]),
    (["initial.state_file='full.h5'", "model.kind='mpp'"],
     ["state_file", "full.h5", "rfem", "mpp", "must match"]),
    (["initial.state_file='full.h5'", "model.elements=5"],
     ["state_file", "full.h5", "4 elements", "5", "must match"]),
    (["initial.state_file='full.h5'", "initial.state_time=7.5"],
     ["state_file", "full.h5", "state_time", "no record at t = 7.5"]),
    (["initial.state_file='s.nml'"], ["state_file", "s.nml", "HDF5"]),
])
def test_bad_state_files(run, tmp_path, sets, words):
    (tmp_path / "s.nml").write_text(BASE.format(kind="rfem", n=4, tension=".true.",
                                                motion=""))
    assert run("run", "s.nml", "--set", "solver.t_end=0.1").returncode == 0
    args = ["run", "s.nml", "--set", "initial.shape='state'", "--set", "output.file='x.h5'"]
    for s in sets:
        args += ["--set", s]
    result = run(*args)
    assert result.returncode == 2, (result.stdout, result.stderr)
    for w in words:
        assert w in result.stderr, (w, result.stderr)
    assert not (tmp_path / "x.h5").exists()
