"""ropedyn sweep: case list and ids, the local runner (parallel workers, summary), skip-if-done,
a failing case recorded while the others finish, --task equal to the same case run alone,
--summary rebuilding the table from the case files."""
import csv
import pathlib

import h5py
import numpy as np
import pytest

BASE = """&model kind = 'rfem', elements = 4 /
&solver t_end = 0.1, output_interval = 0.01 /
"""

SWEEP = """! test sweep
&sweep
    base = 'scenes/base.nml'
    output_dir = 'out/sw'
    elements = 4, 5
    methods = 'cvode', 'mebdf'
    rtols = 1e-4, 1e-6
/
"""

# case 1 fails: 5 steps are not enough
FAILING = """&sweep
    base = 'scenes/base.nml'
    output_dir = 'out/fail'
    vary = 'solver.max_steps = 5; 100000'
    methods = 'cvode', 'mebdf'
/
"""


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


@pytest.fixture
def sweep_dir(tmp_path):
    (tmp_path / "scenes").mkdir()
    (tmp_path / "scenes" / "base.nml").write_text(BASE)
    (tmp_path / "sw.nml").write_text(SWEEP)
    (tmp_path / "fail.nml").write_text(FAILING)
    return tmp_path


def test_list_and_count(run, sweep_dir):
    result = run("sweep", "sw.nml", "--count")
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "8"
    result = run("sweep", "sw.nml", "--list")
    assert result.returncode == 0, result.stderr
    lines = [line for line in result.stdout.splitlines() if line[:4].isdigit()]
    assert len(lines) == 8
    # product order: elements > methods > rtols, the last fastest; ids zero-padded
    expected = [(n, m, r) for n in (4, 5) for m in ("cvode", "mebdf") for r in ("1e-4", "1e-6")]
    for k, (line, (n, m, r)) in enumerate(zip(lines, expected), start=1):
        fields = line.split()
        assert fields[0] == f"{k:04d}"
        assert fields[1] == "missing"
        assert fields[2:] == [f"model.elements={n}", f"solver.method={m}", f"solver.rtol={r}"]


def test_bad_sweep_file(run, sweep_dir):
    (sweep_dir / "bad.nml").write_text("&sweep base = 'scenes/base.nml'\n elements = 10, 1 /\n")
    result = run("sweep", "bad.nml", "--list")
    assert result.returncode == 2
    assert "bad.nml: &sweep: elements(2) = 1: must be >= 2" in result.stderr
    result = run("sweep", "sw.nml", "--task", "9")
    assert result.returncode == 2 and "no such case" in result.stderr
    result = run("sweep", "sw.nml", "--task", "1", "--jobs", "2")
    assert result.returncode == 2


def test_local_runner_and_skip_if_done(run, sweep_dir):
    result = run("sweep", "sw.nml", "--jobs", "2")
    assert result.returncode == 0, result.stderr
    assert "8/8 done" in result.stderr
    out = sweep_dir / "out" / "sw"
    files = sorted(p.name for p in out.glob("case_*.h5"))
    assert files == [f"case_{k:04d}.h5" for k in range(1, 9)]
    assert not list(out.glob("*.log")), "logs of successful cases are removed"
    rows = read_csv(out / "summary.csv")
    assert [int(r["case"]) for r in rows] == list(range(1, 9))
    assert all(r["status"] == "complete" for r in rows)
    for r in rows:
        assert int(r["steps"]) > 0 and float(r["cpu_time"]) > 0 and float(r["wall_time"]) > 0
        assert float(r["energy_error_final"]) < 1e-3
    # reference: the tightest rtol of the same n (case 2 for n = 4: cvode 1e-6, first of ties)
    assert [r["reference"] for r in rows[:4]] == ["2", "", "2", "2"]
    assert [r["reference"] for r in rows[4:]] == ["6", "", "6", "6"]
    assert rows[1]["tip_error_final"] == ""
    assert 0 < float(rows[0]["tip_error_max"]) < 1e-2
    with h5py.File(out / "summary.h5") as f:
        assert list(f["case"][:]) == list(range(1, 9))
        assert f["cpu_time"].attrs["units"] == b"s"
        assert f["tip_error_final"].attrs["units"] == b"m"
        assert [s.decode() for s in f["method"][:4]] == ["cvode", "cvode", "mebdf", "mebdf"]
        np.testing.assert_allclose(f["cpu_time"][:], [float(r["cpu_time"]) for r in rows])
    with h5py.File(out / "case_0003.h5") as f:
        assert f.attrs["status"] == b"complete"
        assert f["solver/wall_time"].attrs["units"] == b"s"

    # re-run: nothing to do, files untouched
    mtimes = {p.name: p.stat().st_mtime_ns for p in out.glob("case_*.h5")}
    result = run("sweep", "sw.nml", "--jobs", "2")
    assert result.returncode == 0, result.stderr
    assert "8 complete already, running 0" in result.stderr
    assert mtimes == {p.name: p.stat().st_mtime_ns for p in out.glob("case_*.h5")}

    # a changed case is stale and runs again; a removed one runs again; the others do not
    (out / "case_0005.h5").unlink()
    (sweep_dir / "sw.nml").write_text(SWEEP.replace("rtols = 1e-4, 1e-6", "rtols = 1e-4, 1e-7"))
    listing = run("sweep", "sw.nml", "--list").stdout
    assert "0001  complete" in listing and "0002  stale" in listing
    assert "0005  missing" in listing
    result = run("sweep", "sw.nml", "--jobs", "2")
    assert result.returncode == 0, result.stderr
    assert "3 complete already, running 5" in result.stderr
    after = {p.name: p.stat().st_mtime_ns for p in out.glob("case_*.h5")}
    for name in ("case_0001.h5", "case_0003.h5", "case_0007.h5"):
        assert after[name] == mtimes[name]
    for name in ("case_0002.h5", "case_0004.h5", "case_0005.h5", "case_0006.h5", "case_0008.h5"):
        assert name in after and after[name] != mtimes.get(name)


def test_failing_case_recorded_others_finish(run, sweep_dir):
    result = run("sweep", "fail.nml", "--jobs", "2")
    assert result.returncode == 3, result.stderr
    assert "2 of 4 cases not complete" in result.stderr
    out = sweep_dir / "out" / "fail"
    rows = read_csv(out / "summary.csv")
    assert [r["status"] for r in rows] == ["failed", "failed", "complete", "complete"]
    assert [r["solver.max_steps"] for r in rows] == ["5", "5", "100000", "100000"]
    assert "max_steps" in rows[0]["reason"] and "max_steps" in rows[1]["reason"]
    assert rows[2]["reason"] == "" and float(rows[2]["t_reached"]) == pytest.approx(0.1)
    assert int(rows[0]["steps"]) == 5
    assert (out / "case_0001.log").read_text().count("max_steps") >= 1
    # a failed case is not skipped: it runs (and fails) again
    result = run("sweep", "fail.nml", "--jobs", "1")
    assert result.returncode == 3 and "2 complete already, running 2" in result.stderr


def test_task_equals_case_run_alone(run, sweep_dir):
    result = run("sweep", "sw.nml", "--task", "7")
    assert result.returncode == 0, result.stderr
    assert "case 0007: complete" in result.stdout
    out = sweep_dir / "out" / "sw"
    assert [p.name for p in out.glob("case_*.h5")] == ["case_0007.h5"]
    # the same case alone: base scene plus the case's overrides
    alone = sweep_dir / "alone.h5"
    result = run("run", "scenes/base.nml", "--set", "model.elements=5", "--set",
                 "solver.method=mebdf", "--set", "solver.rtol=1e-4", "--set",
                 f"output.file={alone}")
    assert result.returncode == 0, result.stderr
    with h5py.File(out / "case_0007.h5") as a, h5py.File(alone) as b:
        for name in ("time", "state/q", "state/qdot", "rope/points", "energy/total",
                     "solver/steps", "solver/rhs_evals", "solver/jac_evals"):
            np.testing.assert_array_equal(a[name][()], b[name][()], err_msg=name)
        scene_a = a.attrs["scene"].decode().replace(str(out / "case_0007.h5"), "X")
        scene_a = scene_a.replace("out/sw/case_0007.h5", "X")
        scene_b = b.attrs["scene"].decode().replace(str(alone), "X")
        assert scene_a == scene_b
    # again: complete already, skipped
    result = run("sweep", "sw.nml", "--task", "7")
    assert result.returncode == 0 and "skipped" in result.stdout
    # --summary from the one case file: the others are missing
    result = run("sweep", "sw.nml", "--summary")
    assert result.returncode == 3
    rows = read_csv(out / "summary.csv")
    assert [r["status"] for r in rows] == ["missing"] * 6 + ["complete", "missing"]
