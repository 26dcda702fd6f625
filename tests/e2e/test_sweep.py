"""ropedyn sweep: case list and ids, the local runner (parallel workers, summary), skip-if-done,
a failing case recorded while the others finish, --task equal to the same case run alone,
--summary rebuilding the table from the case files; one writer per case (two writers, the
lock rules, SIGTERM to the runner), complete only when the data reads back, task lists,
the reference named in the summary and its fallback warned about."""
import csv
import os
import pathlib
import signal
import socket
import subprocess
import time

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


def test_atol_per_rtol_is_the_decimal_product(run, sweep_dir):
    """atol = atol_per_rtol rtol as the user would have written it: 0.01 * 1e-4 is 1e-6
    in the listing, the case's run (its stored scene), summary.csv and summary.h5, not the
    binary product 1.0000000000000002e-6 (nor 1.0000000000000001e-7 for 1e-5)."""
    (sweep_dir / "tol.nml").write_text("&sweep\n    base = 'scenes/base.nml'\n"
                                       "    output_dir = 'out/tol'\n"
                                       "    rtols = 1e-4, 1e-5\n    atol_per_rtol = 0.01\n/\n")
    result = run("sweep", "tol.nml", "--list")
    assert result.returncode == 0, result.stderr
    lines = [line.split()[2:] for line in result.stdout.splitlines() if line[:4].isdigit()]
    assert lines == [["solver.rtol=1e-4", "solver.atol=1e-6"],
                     ["solver.rtol=1e-5", "solver.atol=1e-7"]]
    result = run("sweep", "tol.nml", "--jobs", "1")
    assert result.returncode == 0, result.stderr
    out = sweep_dir / "out" / "tol"
    assert [r["atol"] for r in read_csv(out / "summary.csv")] == ["1e-6", "1e-7"]
    with h5py.File(out / "summary.h5") as f:
        assert list(f["atol"][:]) == [1e-6, 1e-7]
    for k, atol in ((1, "1.0e-6"), (2, "1.0e-7")):
        with h5py.File(out / f"case_{k:04d}.h5") as f:
            scene = f.attrs["scene"].decode().splitlines()
            assert [line.strip() for line in scene if "atol" in line] == [f"atol = {atol}"]


def test_bad_sweep_file(run, sweep_dir):
    (sweep_dir / "bad.nml").write_text("&sweep base = 'scenes/base.nml'\n elements = 10, 1 /\n")
    result = run("sweep", "bad.nml", "--list")
    assert result.returncode == 2
    assert "bad.nml: &sweep: elements(2) = 1: must be >= 2" in result.stderr
    result = run("sweep", "sw.nml", "--task", "9")
    assert result.returncode == 2 and "no such case" in result.stderr
    result = run("sweep", "sw.nml", "--task", "1", "--jobs", "2")
    assert result.returncode == 2


def test_common_overrides_completed_by_the_cases(run, sweep_dir):
    """A harmonic top in `set` and its frequencies in `vary`: the base scene with the common
    overrides alone has no frequency, but every case has one, so the sweep is good. A case
    that still lacks it (frequency 0) is named with its own overrides; an error that every
    case has keeps the message of the common overrides."""
    def sweep_with(vary, set_=("supports.top_motion=harmonic",)):
        sets = ", ".join(f"'{s}'" for s in set_)
        (sweep_dir / "motion.nml").write_text(
            f"&sweep base = 'scenes/base.nml'\n output_dir = 'out/motion'\n"
            f" set = {sets}\n vary = {vary}\n/\n")
        return run("sweep", "motion.nml", "--list")
    result = sweep_with("'supports.top_frequency = 1.0; 2.0', "
                        "'supports.top_amplitude = 0.0,0.01; 0.01,0.0'")
    assert result.returncode == 0, result.stderr
    lines = [line.split()[2:] for line in result.stdout.splitlines() if line[:4].isdigit()]
    assert len(lines) == 4 and lines[0] == ["supports.top_frequency=1.0",
                                            "supports.top_amplitude=0.0,0.01"]
    result = sweep_with("'supports.top_frequency = 1.0; 0.0'")
    assert result.returncode == 2
    assert ("motion.nml: &sweep: case 2 (supports.top_frequency=0.0): &supports: "
            "top_frequency = 0.0: must be > 0") in result.stderr, result.stderr
    result = sweep_with("'supports.top_frequency = 1.0; 2.0'",
                        ("supports.top_motion=harmonic", "rope.length=-1"))
    assert result.returncode == 2
    assert ("motion.nml: &sweep: set: the common overrides: --set rope.length=-1: &rope: "
            "length = -1.0: must be > 0") in result.stderr, result.stderr


def test_output_dir_a_dangling_link_is_bad_input(run, sweep_dir):
    """An output_dir that is a symbolic link to nothing cannot be made a directory: it is
    refused when the sweep file is read (exit 2, the file, group, key, value and why), not
    when the runner makes the directory (exit 4)."""
    (sweep_dir / "out").mkdir()
    (sweep_dir / "out" / "sw").symlink_to("nowhere")
    for args in (["--list"], ["--jobs", "1"], ["--task", "1"], ["--summary"]):
        result = run("sweep", "sw.nml", *args)
        assert result.returncode == 2, (args, result.stderr)
        assert result.stderr.strip() == (
            'ropedyn: error: sw.nml: &sweep: output_dir = "out/sw": cannot hold the case '
            'files: "out/sw" is a symbolic link to "nowhere": No such file or directory'), \
            result.stderr
    assert [p.name for p in (sweep_dir / "out").iterdir()] == ["sw"]


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
        # measured values without the noise of their last binary digits
        for column in ("cpu_time", "wall_time", "energy_error_final", "energy_error_max"):
            digits = r[column].split("e")[0].lstrip("-").replace(".", "").strip("0")
            assert len(digits) <= 6, (column, r[column])
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
    # the same directory spelled another way: each case file holds its own path in its
    # scene, which made every case stale (and a run redid them all)
    for spelling in ("./out/sw", str(out)):
        listing = run("sweep", "sw.nml", "--list", "--output-dir", spelling).stdout
        assert listing.count("  complete") == 8, listing

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


def test_summary_counts_the_f_evaluations_of_differenced_jacobians(run, sweep_dir):
    """The summary's jac_rhs_evals is each case file's /solver/jac_rhs_evals: > 0 where MEBDF
    differences the MPP's Jacobian (first-order matrix), 0 with the analytic blocks of the
    reduced one. A case file of an earlier version lacks it: an empty field, -1 in
    summary.h5, as for any counter a file lacks."""
    (sweep_dir / "scenes" / "mpp.nml").write_text(
        "&model kind = 'mpp', elements = 3 /\n&solver method = 'mebdf', t_end = 0.1 /\n")
    (sweep_dir / "fd.nml").write_text("&sweep base = 'scenes/mpp.nml', output_dir = 'out/fd', "
                                      "vary = 'solver.first_order_newton = .true.; .false.' /\n")
    result = run("sweep", "fd.nml", "--jobs", "1")
    assert result.returncode == 0, result.stderr
    out = sweep_dir / "out" / "fd"
    rows = read_csv(out / "summary.csv")
    files = [h5py.File(out / f"case_{k:04d}.h5") for k in (1, 2)]
    counts = [int(f["solver/jac_rhs_evals"][()]) for f in files]
    for f in files:
        f.close()
    assert counts[0] > 0 and counts[1] == 0
    assert [int(r["jac_rhs_evals"]) for r in rows] == counts
    with h5py.File(out / "summary.h5") as f:
        assert f["jac_rhs_evals"].dtype == np.int64 and list(f["jac_rhs_evals"][:]) == counts
    with h5py.File(out / "case_0001.h5", "r+") as f:
        del f["solver/jac_rhs_evals"]
    assert run("sweep", "fd.nml", "--summary").returncode == 0
    assert [r["jac_rhs_evals"] for r in read_csv(out / "summary.csv")] == ["", "0"]
    with h5py.File(out / "summary.h5") as f:
        assert list(f["jac_rhs_evals"][:]) == [-1, 0]


def test_case_failing_before_its_file_says_why(run, sweep_dir):
    """A case whose run fails before it makes its file (here: its start, an equilibrium of a
    rope whose both ends are free) is failed with that reason in the status and the
    summary, not missing without one; once it completes, the reason is gone."""
    (sweep_dir / "scenes" / "eq.nml").write_text(
        BASE + "&initial shape = 'equilibrium' /\n")
    (sweep_dir / "eq.nml").write_text("&sweep base = 'scenes/eq.nml', output_dir = 'out/eq', "
                                      "vary = 'supports.top = pinned; free' /\n")
    result = run("sweep", "eq.nml", "--jobs", "1")
    assert result.returncode == 3, result.stderr
    assert "case 0002: failed: not run: " in result.stderr
    out = sweep_dir / "out" / "eq"
    rows = read_csv(out / "summary.csv")
    assert [r["status"] for r in rows] == ["complete", "failed"]
    assert rows[1]["reason"].startswith("not run: ") and \
        "statics: no equilibrium: both supports are free" in rows[1]["reason"]
    assert not (out / "case_0002.h5").exists()
    status = run("sweep", "eq.nml", "--status")
    assert "failed           1  0002" in status.stdout, status.stdout
    # the cause gone (a clamped top), the case completes and its note is gone
    (sweep_dir / "eq.nml").write_text("&sweep base = 'scenes/eq.nml', output_dir = 'out/eq', "
                                      "vary = 'supports.top = pinned; clamped' /\n")
    result = run("sweep", "eq.nml", "--jobs", "1")
    assert result.returncode == 0, result.stderr
    assert [r["reason"] for r in read_csv(out / "summary.csv")] == ["", ""]
    assert not list(out.glob(".*.failed"))


def test_case_starting_from_another_models_record_is_refused(run, sweep_dir):
    """A case that starts from a record (&initial shape = 'state') of a run of another
    model, or at or after its t_end, is bad input of the sweep: refused before anything
    runs, naming the case."""
    (sweep_dir / "scenes" / "mpp.nml").write_text(
        BASE.replace("'rfem'", "'mpp'") + "&output file = 'start.h5' /\n")
    assert run("run", "scenes/mpp.nml").returncode == 0
    (sweep_dir / "scenes" / "from.nml").write_text(
        BASE.replace("t_end = 0.1", "t_end = 0.2")
        + "&initial shape = 'state', state_file = '../start.h5' /\n")
    (sweep_dir / "from.nml").write_text("&sweep base = 'scenes/from.nml', "
                                        "output_dir = 'out/from', models = 'mpp', 'rfem' /\n")
    result = run("sweep", "from.nml", "--jobs", "1")
    assert result.returncode == 2, result.stderr
    assert ("from.nml: &sweep: case 2 (model.kind=rfem): scenes/from.nml: &initial: "
            "state_file = ") in result.stderr
    assert "the file holds a run of the mpp model with 4 elements" in result.stderr
    assert not (sweep_dir / "out" / "from").exists()
    (sweep_dir / "from.nml").write_text("&sweep base = 'scenes/from.nml', output_dir = "
                                        "'out/from', models = 'mpp', set = 'solver.t_end=0.1' /\n")
    result = run("sweep", "from.nml", "--jobs", "1")
    assert result.returncode == 2 and "not before &solver t_end" in result.stderr
    assert not (sweep_dir / "out" / "from").exists()


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
                 "output.progress=.false.", "--set", f"output.file={alone}")
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


# ---------------------------------------------------------------------------------------
# One writer per case, status, signals (docs/guide/sweeps.md, "One writer per case")
# ---------------------------------------------------------------------------------------

# cases of one to two seconds each (Debug build): long enough to be caught while running
LONG = """&sweep
    base = 'scenes/base.nml'
    output_dir = 'out/long'
    set = 'solver.t_end=4', 'model.elements=20'
    rtols = {rtols}
/
"""


def wait_for(predicate, timeout=30, what="condition"):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return
        time.sleep(0.02)
    raise AssertionError(f"timed out waiting for {what}")


def processes_mentioning(text):
    """Pids of live processes whose command line holds `text`."""
    pids = []
    for proc in pathlib.Path("/proc").iterdir():
        if not proc.name.isdigit():
            continue
        try:
            cmdline = (proc / "cmdline").read_bytes().replace(b"\0", b" ").decode()
        except OSError:
            continue
        if text in cmdline and int(proc.name) != os.getpid():
            pids.append(int(proc.name))
    return pids


def status_lines(run, sweep):
    result = run("sweep", sweep, "--status")
    counts = {}
    for line in result.stdout.splitlines()[1:8]:
        fields = line.split()
        counts[fields[0]] = int(fields[1])
    return result, counts


def test_two_writers_of_one_case(run, ropedyn_exe, sweep_dir):
    # one case of about 3 s: the checks below take about one
    (sweep_dir / "long.nml").write_text(LONG.format(rtols="1e-9").replace("=4'", "=7'"))
    out = sweep_dir / "out" / "long"
    lock, part, final = out / ".case_0001.lock", out / ".case_0001.h5.part", out / "case_0001.h5"
    first = subprocess.Popen([str(ropedyn_exe), "sweep", "long.nml", "--task", "1"],
                             cwd=sweep_dir, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                             text=True)
    try:
        wait_for(lambda: part.exists() and f"pid={first.pid}" in lock.read_text(),
                 what="the first writer's lock and .part file")
        # the case is not in place while it is written; it reads as running, named
        assert not final.exists()
        result, counts = status_lines(run, "long.nml")
        assert counts["running"] == 1 and result.returncode == 3, result.stdout
        assert f"0001 running: being written by host {socket.gethostname()}, " \
               f"pid {first.pid}" in result.stdout
        assert "0001  running" in run("sweep", "long.nml", "--list").stdout
        # the second writer (forced, too) finds it taken
        for extra in ([], ["--force"]):
            second = run("sweep", "long.nml", "--task", "1", *extra)
            assert second.returncode == 4, second.stderr
            assert f"not run: being written by host {socket.gethostname()}, pid {first.pid}" \
                   in second.stderr
            assert "a file is written by one process at a time" in second.stderr
        # the local runner does not start it either
        runner = run("sweep", "long.nml", "--jobs", "1")
        assert "being written by another process, not started here: 0001" in runner.stderr
        assert first.poll() is None, "the case ended before the checks: make it longer"
    finally:
        stdout, stderr = first.communicate(timeout=120)
    assert first.returncode == 0, stderr
    assert "case 0001: complete" in stdout
    assert not lock.exists() and not part.exists()
    with h5py.File(final) as f:
        assert f.attrs["status"] == b"complete"
        assert "out/long/case_0001.h5" in f.attrs["scene"].decode()
        assert f["time"].shape[0] == f["rope/points"].shape[0] == 701
    assert status_lines(run, "long.nml")[1]["complete"] == 1


def two_workers_running(ropedyn_exe, sweep_dir, rtols):
    """A runner of the long sweep over `rtols` with two jobs, once both its workers write
    their cases' .part files (killed if they do not)."""
    (sweep_dir / "long.nml").write_text(LONG.format(rtols=rtols))
    out = sweep_dir / "out" / "long"
    runner = subprocess.Popen([str(ropedyn_exe), "sweep", "long.nml", "--jobs", "2"],
                              cwd=sweep_dir, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              text=True)
    try:
        wait_for(lambda: len(list(out.glob(".case_*.h5.part"))) == 2, what="two workers")
    except BaseException:
        runner.kill()
        raise
    return runner


def test_sigterm_to_runner_stops_its_workers(run, ropedyn_exe, sweep_dir):
    out = sweep_dir / "out" / "long"
    runner = two_workers_running(ropedyn_exe, sweep_dir, "1e-6, 1e-7, 1e-8")
    try:
        workers = [p for p in processes_mentioning("long.nml --quiet")]
        assert len(workers) == 2
        runner.send_signal(signal.SIGTERM)
        _, stderr = runner.communicate(timeout=60)
    finally:
        if runner.poll() is None:
            runner.kill()
    assert runner.returncode == 130, stderr
    assert "stopped by SIGTERM: 0 of 3 cases ended, 2 interrupted (0001 0002), " \
           "1 not started" in stderr
    # no worker left; each interrupted case stopped at a step boundary, wrote that state
    # with status interrupted and was renamed into place (no lock, no .part); its log keeps
    # the worker's message
    assert processes_mentioning(str(sweep_dir)) == [] and processes_mentioning("long.nml") == []
    names = sorted(p.name for p in out.iterdir())
    assert names == ["case_0001.h5", "case_0001.log", "case_0002.h5", "case_0002.log"], names
    assert "interrupted by SIGTERM at t = " in (out / "case_0001.log").read_text()
    result, counts = status_lines(run, "long.nml")
    assert result.returncode == 3
    assert counts == {"complete": 0, "failed": 0, "interrupted": 2, "running": 0, "stale": 0,
                      "unreadable": 0, "missing": 1}, result.stdout
    assert "0001 interrupted: " in result.stdout
    assert "interrupted by SIGTERM at t = " in result.stdout
    # running again continues case 1 from its last record
    again = run("sweep", "long.nml", "--task", "1")
    assert again.returncode == 0, again.stderr
    assert "continuing it from its last record" in again.stdout
    assert sorted(p.name for p in out.iterdir()) == [
        "case_0001.h5", "case_0001.log", "case_0002.h5", "case_0002.log"]
    with h5py.File(out / "case_0001.h5") as f:
        assert f.attrs["status"] == b"complete" and f["solver/restarts/time"].shape == (1,)


def test_empty_logs_of_a_killed_runner_go(run, ropedyn_exe, sweep_dir):
    """A runner killed by SIGKILL cannot remove its workers' empty logs, and its workers
    finish their cases on their own: the next runner removes the empty logs of the
    complete cases (they stayed, the cases not being run again); a log with text stays."""
    out = sweep_dir / "out" / "long"
    runner = two_workers_running(ropedyn_exe, sweep_dir, "1e-7, 1e-8")
    try:
        runner.kill()
        runner.communicate(timeout=60)
        wait_for(lambda: processes_mentioning("long.nml --quiet") == [], timeout=120,
                 what="the workers' ends")
    finally:
        if runner.poll() is None:
            runner.kill()
    assert sorted(p.name for p in out.glob("case_*")) == [
        "case_0001.h5", "case_0001.log", "case_0002.h5", "case_0002.log"]
    assert all(p.stat().st_size == 0 for p in out.glob("*.log"))
    (out / "case_0002.log").write_text("a worker's message\n")
    again = run("sweep", "long.nml", "--jobs", "1")
    assert again.returncode == 0, again.stderr
    assert "2 complete already, running 0" in again.stderr
    assert sorted(p.name for p in out.glob("*.log")) == ["case_0002.log"]


def records_in(part):
    """The records the worker has flushed into `part` (0 while it cannot be read), read
    without HDF5's file lock, which the worker holds."""
    try:
        with h5py.File(part, "r", locking=False) as f:
            return len(f["time"]) if "time" in f else 0
    except (OSError, KeyError, ValueError, RuntimeError):  # (caught between writes)
        return 0


def signal_the_first_worker(ropedyn_exe, sweep_dir, rtols, sig, records=0):
    """Run the LONG sweep over `rtols` with one worker and send `sig` to that worker once
    it writes its case (and has flushed `records` records): the runner's exit code and
    stderr."""
    (sweep_dir / "long.nml").write_text(LONG.format(rtols=rtols))
    out = sweep_dir / "out" / "long"
    runner = subprocess.Popen([str(ropedyn_exe), "sweep", "long.nml", "--jobs", "1"],
                              cwd=sweep_dir, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              text=True)
    try:
        wait_for(lambda: (out / ".case_0001.h5.part").exists(), what="the first worker")
        wait_for(lambda: records_in(out / ".case_0001.h5.part") >= records, timeout=120,
                 what=f"{records} records")
        workers = processes_mentioning("long.nml --quiet")
        assert len(workers) == 1
        os.kill(workers[0], sig)
        _, stderr = runner.communicate(timeout=120)
    finally:
        if runner.poll() is None:
            runner.kill()
    return runner.returncode, stderr


def test_sigkill_to_a_worker_is_no_failed_case(run, ropedyn_exe, sweep_dir):
    """A worker killed by SIGKILL leaves its case interrupted (an abandoned lock and a
    .part): the runner says "ended by SIGKILL" and does not count it as failed (its
    progress said "1 failed" while --status said interrupted). Run again, the case
    continues from the last record of its .part (it ran anew before); its warning that
    it did names the case file (it named the .part); the summary says its counters are
    partial (the killed part's are lost)."""
    returncode, stderr = signal_the_first_worker(ropedyn_exe, sweep_dir, "1e-7",
                                                 signal.SIGKILL, records=3)
    assert returncode == 3, stderr
    line = next(l for l in stderr.splitlines() if l.startswith("sweep: case 0001 "))
    assert line.startswith("sweep: case 0001 ended by SIGKILL") and "0 failed" in line, line
    _, counts = status_lines(run, "long.nml")
    assert counts["interrupted"] == 1, counts
    out = sweep_dir / "out" / "long"
    with h5py.File(out / ".case_0001.h5.part", "r") as f:
        assert f.attrs["status"] == b"running"
        kept = f["time"][-1]
    again = run("sweep", "long.nml", "--task", "1")
    assert again.returncode == 0, again.stderr
    assert ("its writer was killed: continuing out/long/.case_0001.h5.part from its last "
            "record") in again.stdout, again.stdout
    with h5py.File(out / "case_0001.h5") as f:
        assert f.attrs["status"] == b"complete" and abs(f["time"][-1] - 4.0) < 1e-12
        assert f["solver/restarts/time"][:].tolist() == [kept]
        # the warning names the case file, not the .part the user never sees
        warning = f["solver/warnings"][-1].decode()
        assert "its run was killed or crashed" in warning
        assert warning.startswith("out/long/case_0001.h5: status running: ") and \
            ".part" not in warning, warning
    # the killed part left its counters as of its last flush (a run writes them with its
    # records), but not its wall time: the summary says the case's wall time is partial
    with h5py.File(out / "case_0001.h5") as f:
        assert 0 < f["solver/restarts/steps"][0] < f["solver/steps"][()]
    summary = run("sweep", "long.nml", "--summary")
    assert summary.returncode == 0, summary.stderr
    assert ("sweep: warning: case 1: wall_time (and where a killed part wrote none, the "
            "counters and cpu_time) is partial: a part of the run was killed before it "
            "wrote it") in summary.stderr, summary.stderr
    row = read_csv(out / "summary.csv")[0]
    assert row["warning"].startswith("wall_time is partial: the part of the run that ended "
                                     "at t = ") and \
        row["warning"].endswith(" s (its last record) was killed before writing it; steps, "
                                "the other counters and cpu_time count to its last flush"), row
    assert float(row["warning"].split("t = ")[1].split(" s")[0]) == pytest.approx(kept)
    # a part killed by a version that wrote its counters only at its end lost them
    with h5py.File(out / "case_0001.h5", "r+") as f:
        f["solver/restarts/steps"][0] = 0
    assert run("sweep", "long.nml", "--summary").returncode == 0
    assert read_csv(out / "summary.csv")[0]["warning"].startswith(
        "steps, the other counters, cpu_time and wall_time are partial: the part of the run "
        "that ended at t = ")


def test_a_killed_continuation_of_an_interrupted_case_continues(run, ropedyn_exe,
                                                                sweep_dir):
    """A writer continuing an interrupted case moves the case file back to its .part name,
    then reopens it (status `running`). Killed in between, it leaves a .part with status
    `interrupted` and an abandoned lock; the next task continues that .part from its last
    record (it was removed and the case run anew, losing the interrupted run's work)."""
    (sweep_dir / "long.nml").write_text(LONG.format(rtols="1e-7"))
    out = sweep_dir / "out" / "long"
    part, final = out / ".case_0001.h5.part", out / "case_0001.h5"
    first = subprocess.Popen([str(ropedyn_exe), "sweep", "long.nml", "--task", "1"],
                             cwd=sweep_dir, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                             text=True)
    try:
        wait_for(lambda: records_in(part) >= 3, timeout=120, what="3 records")
        first.send_signal(signal.SIGTERM)
        first.communicate(timeout=120)
    finally:
        if first.poll() is None:
            first.kill()
    assert first.returncode == 130
    with h5py.File(final, "r+") as f:
        assert f.attrs["status"] == b"interrupted"
        kept = f["time"][-1]
        # the interrupted part's wall time, made large to be told from the last part's
        f["solver/wall_time"][()] = 1000.0
    # the state of a writer killed right after it moved the file back: its lock (of a
    # process that is gone) and the interrupted file under the .part name
    final.rename(part)
    gone = subprocess.Popen(["true"])
    gone.wait()
    (out / ".case_0001.lock").write_text(
        f"ropedyn sweep case lock\nhost={socket.gethostname()}\npid={gone.pid}\n")
    _, counts = status_lines(run, "long.nml")
    assert counts["interrupted"] == 1, counts
    again = run("sweep", "long.nml", "--task", "1")
    assert again.returncode == 0, again.stderr
    assert ("its writer was killed: continuing out/long/.case_0001.h5.part from its last "
            "record") in again.stdout, again.stdout
    with h5py.File(final, "r") as f:
        assert f.attrs["status"] == b"complete" and abs(f["time"][-1] - 4.0) < 1e-12
        assert f["solver/restarts/time"][:].tolist() == [kept]
        assert f["solver/restarts/previous_status"][:].tolist() == [b"interrupted"]
        # the case's wall time is its parts': the interrupted one's and the last
        assert 1000.0 < f["solver/wall_time"][()] < 1100.0
    assert not part.exists()


def test_a_finished_part_of_a_killed_writer_is_put_in_place(run, sweep_dir):
    """A writer killed after its run ended (status complete) but before it renamed its
    .part into place leaves a finished run: the next sweep puts it in place, with the
    case's scene, says so in the case's log and counts the case done; it does not run the
    case again (it did)."""
    assert run("sweep", "sw.nml", "--task", "1").returncode == 0
    out = sweep_dir / "out" / "sw"
    part, final = out / ".case_0001.h5.part", out / "case_0001.h5"
    final.rename(part)
    # as the run left it: its scene names the .part, no wall time yet; a mark to find
    with h5py.File(part, "r+") as f:
        f.attrs["scene"] = f.attrs["scene"].decode().replace("out/sw/case_0001.h5",
                                                             "out/sw/.case_0001.h5.part")
        del f["solver/wall_time"]
        f.attrs["mark"] = "the finished run"
        steps = int(f["solver/steps"][()])
    missing = run("sweep", "sw.nml", "--status")
    assert ("0001 missing: out/sw/.case_0001.h5.part holds the finished run"
            in missing.stdout), missing.stdout
    gone = subprocess.Popen(["true"])
    gone.wait()
    (out / ".case_0001.lock").write_text(
        f"ropedyn sweep case lock\nhost={socket.gethostname()}\npid={gone.pid}\n")
    # the status says what the .part holds and what the next sweep does with it
    status = run("sweep", "sw.nml", "--status")
    assert ("0001 interrupted: its writer ended without finishing: killed or crashed "
            in status.stdout), status.stdout
    assert ("out/sw/.case_0001.h5.part holds the finished run (its writer was killed before "
            "it renamed the file): the next sweep puts it in place") in status.stdout, \
        status.stdout
    result = run("sweep", "sw.nml", "--jobs", "1")
    assert result.returncode == 0, result.stderr
    assert "sweep: case 0001 complete" in result.stderr
    assert not part.exists() and not (out / ".case_0001.lock").exists()
    with h5py.File(final) as f:
        assert f.attrs["mark"] == "the finished run"
        scene = f.attrs["scene"].decode()
        assert "out/sw/case_0001.h5" in scene and ".part" not in scene
        assert "wall_time" not in f["solver"]
    assert ("sweep: case 0001: complete in out/sw/.case_0001.h5.part (its writer was killed "
            "before it renamed the file): put in place as out/sw/case_0001.h5, not run "
            "again") in (out / "case_0001.log").read_text()
    row = read_csv(out / "summary.csv")[0]
    assert row["status"] == "complete" and int(row["steps"]) == steps and \
        row["wall_time"] == "", row


def test_sigterm_to_a_worker_reports_its_case_interrupted(run, ropedyn_exe, sweep_dir):
    """A worker stopped by SIGTERM ends with ropedyn's exit code 130 and writes its case
    interrupted: the runner says so (not "ended by SIGINT", which 128 + 2 would read as),
    counts it apart from the failed cases, and the other case still runs; the reason
    names the case file."""
    returncode, stderr = signal_the_first_worker(ropedyn_exe, sweep_dir, "1e-7, 1e-4",
                                                 signal.SIGTERM)
    out = sweep_dir / "out" / "long"
    assert returncode == 3, stderr
    line = next(l for l in stderr.splitlines() if l.startswith("sweep: case 0001 "))
    assert line.startswith("sweep: case 0001 interrupted (exit 130"), line
    assert "SIGINT" not in stderr and "0 failed" in line, stderr
    assert "sweep: case 0002 complete" in stderr
    result, counts = status_lines(run, "long.nml")
    assert counts["interrupted"] == 1 and counts["complete"] == 1, result.stdout
    log = (out / "case_0001.log").read_text()
    assert "interrupted by SIGTERM at t = " in log
    # the reason names the case file, not the .part it was written as (renamed since)
    reason = next(r["reason"] for r in read_csv(out / "summary.csv") if r["case"] == "1")
    for text in (reason, result.stdout, log):
        assert ".part" not in text and "out/long/case_0001.h5: interrupted by" in text, text
    # run again, the case continues from its last record; its log keeps the message of the
    # interrupted run (a worker appends to its case's log: it was cut before, and a second
    # runner's worker finding the case taken cut the log of the one writing it)
    again = run("sweep", "long.nml", "--jobs", "1")
    assert again.returncode == 0, again.stderr
    assert "interrupted by SIGTERM at t = " in (out / "case_0001.log").read_text()


def test_lock_rules(run, sweep_dir):
    """A lock of another host is live while its heartbeat is fresh; one of this host while
    its process lives; one that recorded a signal is abandoned; an abandoned lock is taken
    over."""
    out = sweep_dir / "out" / "sw"
    out.mkdir(parents=True)
    lock = out / ".case_0001.lock"
    text = "ropedyn sweep case lock\nhost=elsewhere\npid=4711\nstarted=2024-01-01T00:00:00Z\n" \
           "job=77_1\n"
    lock.write_text(text)
    result = run("sweep", "sw.nml", "--status")
    assert "0001 running: being written by host elsewhere, pid 4711, Slurm job 77_1" \
           in result.stdout
    taken = run("sweep", "sw.nml", "--task", "1")
    assert taken.returncode == 4 and "being written by host elsewhere" in taken.stderr
    # no heartbeat for 200 s: abandoned (another host: after 120 s)
    old = time.time() - 200
    os.utime(lock, (old, old))
    result = run("sweep", "sw.nml", "--status")
    assert "0001 interrupted: its writer ended without finishing: killed, crashed or its " \
           "node failed (host elsewhere, pid 4711, Slurm job 77_1" in result.stdout
    assert "no heartbeat for 2" in result.stdout
    took = run("sweep", "sw.nml", "--task", "1")
    assert took.returncode == 0, took.stderr
    assert not lock.exists() and (out / "case_0001.h5").exists()
    # this host: a process that is gone
    gone = subprocess.Popen(["true"])
    gone.wait()
    lock2 = out / ".case_0002.lock"
    lock2.write_text(f"ropedyn sweep case lock\nhost={socket.gethostname()}\npid={gone.pid}\n")
    result = run("sweep", "sw.nml", "--status")
    assert f"0002 interrupted: its writer ended without finishing: killed or crashed " \
           f"(host {socket.gethostname()}, pid {gone.pid}; that process is gone)" in result.stdout
    # this host: a process that has ended but is not reaped yet (a zombie) is gone too;
    # it was taken as the live writer until its parent reaped it
    zombie = subprocess.Popen(["true"])
    wait_for(lambda: pathlib.Path(f"/proc/{zombie.pid}/stat").read_text()
             .rsplit(")", 1)[1].split()[0] == "Z", what="the zombie")
    lock2.write_text(f"ropedyn sweep case lock\nhost={socket.gethostname()}\n"
                     f"pid={zombie.pid}\n")
    result = run("sweep", "sw.nml", "--status")
    zombie.wait()
    assert f"0002 interrupted: its writer ended without finishing: killed or crashed " \
           f"(host {socket.gethostname()}, pid {zombie.pid}; that process is gone)" \
           in result.stdout, result.stdout
    # a recorded signal
    lock2.write_text(f"host={socket.gethostname()}\npid={os.getpid()}\nsignal=2\n")
    assert "0002 interrupted: stopped by SIGINT at" in run("sweep", "sw.nml", "--status").stdout
    assert run("sweep", "sw.nml", "--task", "2").returncode == 0
    assert not lock2.exists()


def test_a_part_held_open_by_another_writer_is_left_alone(run, sweep_dir):
    """A case's .part that another process holds open for writing (HDF5's lock) is not
    the task's to remove: the case is not run (exit 4) and the file stays; once it is
    closed, a .part of another scene is removed and the case runs anew."""
    assert run("sweep", "sw.nml", "--task", "2").returncode == 0
    out = sweep_dir / "out" / "sw"
    part = out / ".case_0001.h5.part"
    part.write_bytes((out / "case_0002.h5").read_bytes())
    with h5py.File(part, "a"):
        held = run("sweep", "sw.nml", "--task", "1")
    assert held.returncode == 4, held.stderr
    assert "sweep: case 0001: not run: " in held.stderr and "cannot open: locked by pid" \
        in held.stderr, held.stderr
    assert part.exists() and not (out / "case_0001.h5").exists()
    again = run("sweep", "sw.nml", "--task", "1")
    assert again.returncode == 0, again.stderr
    assert not part.exists() and (out / "case_0001.h5").exists()


def test_complete_only_if_it_reads_back(run, sweep_dir):
    assert run("sweep", "sw.nml", "--task", "1-3").returncode == 0
    out = sweep_dir / "out" / "sw"
    # a damaged file: unreadable, not complete, runs again
    data = (out / "case_0001.h5").read_bytes()
    (out / "case_0001.h5").write_bytes(data[: len(data) // 2])
    # a file whose run was interrupted (as the run driver will write it): not complete
    with h5py.File(out / "case_0002.h5", "r+") as f:
        f.attrs["status"] = np.bytes_("interrupted")     # fixed-length, as ropedyn writes
        f.attrs["reason"] = np.bytes_("SIGTERM at t = 0.05 s")
    listing = run("sweep", "sw.nml", "--list").stdout
    assert "0001  unreadable" in listing and "0002  interrupted" in listing
    assert "0003  complete" in listing
    result = run("sweep", "sw.nml", "--status")
    assert "0002 interrupted: SIGTERM at t = 0.05 s" in result.stdout
    summary = run("sweep", "sw.nml", "--summary")
    assert summary.returncode == 3
    assert "case 0001: unreadable: " in summary.stderr
    assert "case 0002: interrupted: SIGTERM at t = 0.05 s" in summary.stderr
    rerun = run("sweep", "sw.nml", "--task", "1-3")
    assert rerun.returncode == 0, rerun.stderr
    assert rerun.stdout.count(": complete: ") == 2 and "0003: complete already" in rerun.stdout


def test_summary_written_aside_and_renamed(run, sweep_dir):
    """The summary files are written under a name of their own and renamed into place:
    a reader holding summary.h5 open (HDF5's lock) does not stop the summary (exit 4,
    "locked by another process", as did a second runner writing it at the same moment),
    it keeps reading the old file, and nothing is left beside the new one."""
    assert run("sweep", "sw.nml", "--task", "1-2").returncode == 0
    out = sweep_dir / "out" / "sw"
    assert run("sweep", "sw.nml", "--summary").returncode == 3
    assert run("sweep", "sw.nml", "--task", "3").returncode == 0
    with h5py.File(out / "summary.h5", "r") as held:
        result = run("sweep", "sw.nml", "--summary")
        assert result.returncode == 3 and "locked" not in result.stderr, result.stderr
        assert [s.decode() for s in held["status"][:3]] == ["complete", "complete", "missing"]
    with h5py.File(out / "summary.h5", "r") as f:
        assert [s.decode() for s in f["status"][:3]] == ["complete"] * 3
    assert [r["status"] for r in read_csv(out / "summary.csv")][:4] == \
        ["complete"] * 3 + ["missing"]
    assert sorted(p.name for p in out.iterdir() if "summary" in p.name) == \
        ["summary.csv", "summary.h5"]


def test_a_case_named_twice_in_a_task_runs_once(run, sweep_dir):
    """`--task 1,1,1-2 --force` ran case 1 three times (each anew): a case runs once, at
    its first place in the list."""
    result = run("sweep", "sw.nml", "--task", "1,1,1-2", "--force")
    assert result.returncode == 0, result.stderr
    assert result.stdout.count("sweep: case 0001: complete") == 1, result.stdout
    assert result.stdout.count("sweep: case 0002: complete") == 1, result.stdout


def test_task_list_runs_on_after_a_failure(run, sweep_dir):
    result = run("sweep", "fail.nml", "--task", "1,3-4,2")
    assert result.returncode == 3
    assert result.stdout.count(": complete: ") == 2
    assert result.stderr.count("max_steps") == 2
    assert "sweep: 2 of 4 cases of this task not complete: 0001, 0002" in result.stderr


FALLBACK = """&sweep
    base = 'scenes/base.nml'
    output_dir = 'out/fb'
    set = 'solver.max_steps=300'
    methods = 'cvode', 'mebdf'
    rtols = 1e-3, 1e-4, 1e-8
    reference = '{reference}'
/
"""


def test_reference_named_and_fallback_warned(run, sweep_dir):
    # with 300 steps, rtol 1e-8 fails for both methods, mebdf fails at 1e-4 too
    (sweep_dir / "fb.nml").write_text(FALLBACK.format(reference="tightest"))
    result = run("sweep", "fb.nml")
    assert result.returncode == 3
    rows = read_csv(sweep_dir / "out" / "fb" / "summary.csv")
    assert [r["status"] for r in rows] == ["complete", "complete", "failed", "complete",
                                           "failed", "failed"]
    warning = ("reference falls back to case 2 (rtol 1e-4): the tightest case 3 (rtol 1e-8) "
               "is not complete (failed)")
    assert f"sweep: warning: cases 1-6: {warning}" in result.stderr
    assert [r["reference"] for r in rows] == ["2", "", "", "2", "", ""]
    assert [r["reference_kind"] for r in rows] == ["tighter", "self", "", "tighter", "", ""]
    assert rows[0]["warning"] == warning and rows[2]["warning"] == ""
    assert float(rows[3]["tip_error_max"]) > 0
    # per method: mebdf is measured against its own tightest complete case (itself here)
    (sweep_dir / "fb.nml").write_text(FALLBACK.format(reference="tightest_per_method"))
    result = run("sweep", "fb.nml", "--summary")
    rows = read_csv(sweep_dir / "out" / "fb" / "summary.csv")
    assert [r["reference"] for r in rows] == ["2", "", "", "", "", ""]
    assert [r["reference_kind"] for r in rows] == ["tighter", "self", "", "self", "", ""]
    assert "sweep: warning: cases 4-6: reference falls back to case 4 (rtol 0.001)" \
           in result.stderr
    with h5py.File(sweep_dir / "out" / "fb" / "summary.h5") as f:
        assert f.attrs["reference"] == b"tightest_per_method"
        assert [s.decode() for s in f["reference_kind"][:2]] == ["tighter", "self"]
    # equal tolerances of two methods: the error is their disagreement, labelled so
    (sweep_dir / "eq.nml").write_text("&sweep base = 'scenes/base.nml'\n output_dir = 'out/eq'"
                                      "\n methods = 'cvode', 'mebdf'\n/\n")
    assert run("sweep", "eq.nml").returncode == 0
    rows = read_csv(sweep_dir / "out" / "eq" / "summary.csv")
    assert [r["reference_kind"] for r in rows] == ["self", "same_rtol"]
    assert [r["reference"] for r in rows] == ["", "1"]


def test_reference_file_checked_against_cases(run, sweep_dir):
    result = run("run", "scenes/base.nml", "--set", "output.file=ref.h5")
    assert result.returncode == 0, result.stderr
    body = "&sweep base = 'scenes/base.nml'\n output_dir = 'out/r'\n {} reference = 'ref.h5'\n/\n"
    (sweep_dir / "r1.nml").write_text(body.format("elements = 4, 5\n"))
    result = run("sweep", "r1.nml", "--count")
    assert result.returncode == 2
    assert 'r1.nml: &sweep: reference = "ref.h5": it has 4 elements, case 2 ' \
           '(model.elements=5) 5: a reference file serves cases of its element count only' \
           in result.stderr
    (sweep_dir / "r2.nml").write_text(body.format("set = 'solver.output_interval=0.02'\n"))
    result = run("sweep", "r2.nml", "--list")
    assert result.returncode == 2
    assert "its output times are not those of case 1 (every 0.02 s up to 0.1 s); its " \
           "records are every 0.01 s" in result.stderr
    # a finer case than the reference: its times, not its end (it ends at 0.1 s as the
    # case does; the message said "it ends at t = 0.1 s, case 1 at 0.1 s")
    (sweep_dir / "r4.nml").write_text(body.format("set = 'solver.output_interval=0.005'\n"))
    result = run("sweep", "r4.nml", "--list")
    assert result.returncode == 2
    assert "its output times are not those of case 1 (every 0.005 s up to 0.1 s); its " \
           "records are every 0.01 s" in result.stderr, result.stderr
    # a longer case: its end
    (sweep_dir / "r5.nml").write_text(body.format("set = 'solver.t_end=0.2'\n"))
    result = run("sweep", "r5.nml", "--list")
    assert result.returncode == 2
    assert "it ends at t = 0.1 s, case 1 at 0.2 s" in result.stderr, result.stderr
    (sweep_dir / "r3.nml").write_text(body.format("rtols = 1e-4, 1e-5\n"))
    assert run("sweep", "r3.nml").returncode == 0
    rows = read_csv(sweep_dir / "out" / "r" / "summary.csv")
    assert [r["reference_kind"] for r in rows] == ["file", "file"]
    assert all(float(r["tip_error_max"]) > 0 for r in rows)


WARNED = """&sweep
    base = 'scenes/base.nml'
    output_dir = 'out/warned'
    set = 'fluid.density = 1.225'
    vary = 'effects.water = .false.; .true.'
/
"""


def test_a_cases_run_warnings_reach_the_summary(run, sweep_dir):
    """What a case's run warned of (its /solver/warnings) is its row's run_warnings, in
    the CSV and the HDF5 summary, rebuilt alike by --summary from the case files; the
    terminal names the cases that warned. Water in air warns (a slip of units?); without
    water the same scene does not."""
    (sweep_dir / "warned.nml").write_text(WARNED)
    result = run("sweep", "warned.nml")
    assert result.returncode == 0, result.stderr
    rows = read_csv(sweep_dir / "out" / "warned" / "summary.csv")
    assert rows[0]["run_warnings"] == ""
    assert "&fluid: density = 1.225: water = .true. in a fluid this light" \
        in rows[1]["run_warnings"]
    with h5py.File(sweep_dir / "out" / "warned" / rows[1]["file"].split("/")[-1]) as f:
        kept = [w.decode() for w in f["solver/warnings"][()]]
    assert rows[1]["run_warnings"] == " | ".join(kept)
    line = [x for x in result.stderr.splitlines() if "warned in their runs" in x]
    assert line == [f"sweep: warning: 1 of 2 cases warned in their runs (cases 0002), the first: "
                    f"{kept[0]} (all in out/warned/summary.csv, run_warnings)"], result.stderr
    with h5py.File(sweep_dir / "out" / "warned" / "summary.h5") as f:
        assert [s.decode() for s in f["run_warnings"][()]] == ["", rows[1]["run_warnings"]]
    again = run("sweep", "warned.nml", "--summary")
    assert again.returncode == 0, again.stderr
    assert read_csv(sweep_dir / "out" / "warned" / "summary.csv") == rows


def test_the_abandoned_lock_of_a_complete_case_goes(run, sweep_dir):
    """A writer killed after it renamed its case file into place, before it removed the
    lock, leaves a complete case with an abandoned lock. A complete case is not run again,
    so the next task or runner removes that lock (taken over and dropped); a lock of a live
    writer, or one with a .part beside it (a killed rerun), stays."""
    assert run("sweep", "sw.nml", "--task", "1").returncode == 0
    out = sweep_dir / "out" / "sw"
    lock = out / ".case_0001.lock"
    gone = subprocess.Popen(["true"])
    gone.wait()
    lock.write_text(f"ropedyn sweep case lock\nhost={socket.gethostname()}\npid={gone.pid}\n")
    skipped = run("sweep", "sw.nml", "--task", "1")
    assert skipped.returncode == 0 and "complete already" in skipped.stdout, skipped.stderr
    assert not lock.exists()
    # the local runner does the same for the complete cases it does not start
    lock.write_text(f"ropedyn sweep case lock\nhost={socket.gethostname()}\npid={gone.pid}\n")
    (out / ".case_0002.lock").write_text(f"ropedyn sweep case lock\nhost={socket.gethostname()}"
                                         f"\npid={os.getpid()}\n")
    for k in range(3, 9):
        assert run("sweep", "sw.nml", "--task", str(k)).returncode == 0
    runner = run("sweep", "sw.nml", "--jobs", "1")
    assert runner.returncode == 3, runner.stderr       # case 2 is being written (this pid)
    assert not lock.exists()
    assert (out / ".case_0002.lock").exists()          # a live writer's lock stays
    (out / ".case_0002.lock").unlink()
    # a lock with a .part beside it stays with its .part
    lock.write_text(f"ropedyn sweep case lock\nhost={socket.gethostname()}\npid={gone.pid}\n")
    (out / ".case_0001.h5.part").write_bytes((out / "case_0001.h5").read_bytes())
    assert run("sweep", "sw.nml", "--task", "1").returncode == 0
    assert lock.exists() and (out / ".case_0001.h5.part").exists()


@pytest.mark.parametrize("cut", [3, "all"])
def test_a_killed_part_whose_records_do_not_read_back(run, sweep_dir, cut):
    """A writer killed in the middle of a flush can leave a .part (status `running`) whose
    last records HDF5 cannot read back (/state/y shorter than /time, or a chunk past the
    end of the file: "addr overflow"). Its resume continues from the last record every
    series reads back (its resume was refused, and the case run anew). With no such
    record, the case is run anew at once, as one that cannot be continued, not written
    `failed` with its .part removed and run anew only by the next sweep."""
    assert run("sweep", "sw.nml", "--task", "1").returncode == 0
    out = sweep_dir / "out" / "sw"
    part, final = out / ".case_0001.h5.part", out / "case_0001.h5"
    final.rename(part)
    with h5py.File(part, "r+") as f:
        f.attrs["status"] = "running"
        f.attrs["scene"] = f.attrs["scene"].decode().replace("out/sw/case_0001.h5",
                                                             "out/sw/.case_0001.h5.part")
        del f["solver/wall_time"]
        records = f["time"].shape[0]
        f["state/y"].resize(0 if cut == "all" else records - cut, axis=0)
    gone = subprocess.Popen(["true"])
    gone.wait()
    (out / ".case_0001.lock").write_text(
        f"ropedyn sweep case lock\nhost={socket.gethostname()}\npid={gone.pid}\n")
    again = run("sweep", "sw.nml", "--task", "1")
    assert again.returncode == 0, again.stderr
    with h5py.File(final, "r") as f:
        assert f.attrs["status"] == b"complete" and f["time"].shape[0] == records
        if cut == "all":
            assert "restarts" not in f["solver"]
        else:
            assert f["solver/restarts/record"][:].tolist() == [records - cut - 1]
            assert (f"continued from its last whole record (record {records - cut - 1}; "
                    f"the {cut} after it did not all read back") in \
                f["solver/warnings"][-1].decode()
    if cut == "all":
        assert "cannot be continued (" in again.stderr and "running it anew" in again.stderr, \
            again.stderr
    assert not part.exists() and not (out / ".case_0001.lock").exists()
    assert not (out / ".case_0001.failed").exists()
