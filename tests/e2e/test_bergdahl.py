"""The Bergdahl validation's pipeline (scripts/validation bergdahl,
tools/ropedyn_tools/studies/bergdahl.py): one short condition end to end, and its analysis
on made-up data. These check the pipeline, not the accuracy."""
import json
import math
import os
import pathlib
import subprocess
import sys

import numpy as np

from ropedyn_tools.studies import bergdahl as bg

ROOT = pathlib.Path(__file__).resolve().parents[2]


def test_cycle_maxima_are_the_peaks_of_the_last_whole_cycles():
    period = 1.25
    t = np.arange(0.0, 6 * period + 1e-9, 0.004)
    # a peak in the middle of each cycle, between two samples, 1 N higher each cycle
    force = 40.0 + np.floor(t / period) + 10.0 * np.cos(2 * math.pi * (t / period - 0.5013))
    maxima = bg.cycle_maxima(t, force, period, cycles=5)
    # cycles 2..6 (the last five whole periods before t[-1]): 50 + 1, ..., 50 + 5; the
    # parabola through the samples finds each peak to 2e-5 N (the largest sample alone is
    # up to 2.4e-4 N low)
    assert np.allclose(maxima, 51.0 + np.arange(5), rtol=0.0, atol=2e-5), maxima


def test_scores_of_a_known_error():
    s = bg.scores([11.0, 22.0, 33.0], [10.0, 20.0, 30.0])
    assert math.isclose(s["rmse"], math.sqrt((1 + 4 + 9) / 3))
    assert math.isclose(s["mape"], 10.0) and math.isclose(s["worst"], 10.0)
    assert math.isclose(s["bias"], 2.0) and math.isclose(s["corr"], 1.0)
    s = bg.scores([10.0, 22.0, 27.0], [10.0, 20.0, 30.0])
    assert math.isclose(s["bias"], -1.0 / 3) and math.isclose(s["worst"], 10.0)
    assert s["corr"] < 1.0


def test_sampling_error_of_a_convergence_change():
    """Two runs of 5 analysed cycles each: the standard errors of their means (spread over
    sqrt(5)) combine in quadrature, over the reference's mean."""
    row = dict(mean=50.5, spread=0.4, maxima=np.zeros(5))
    ref = dict(mean=50.0, spread=0.3, maxima=np.zeros(5))
    expected = 100 * math.sqrt(0.3**2 / 5 + 0.4**2 / 5) / 50.0     # 0.447 %
    assert math.isclose(bg.change_error(row, ref), expected)


def test_runs_with_another_law_change_against_their_own_reference():
    """The element halving with the axial springs carrying compression is measured against
    the run at the study's element length with that law, not against the study's own run."""
    n, rtol = bg.base_elements(), bg.base_rtol()

    def row(elements, law, mean):
        return dict(model="rfem", period=1.25, n=elements, rtol=rtol, law=law,
                    mean=mean, spread=0.0, maxima=np.zeros(5), cpu_time=1.0)

    rows = [row(n, "", 50.0), row(2 * n, "", 49.0), row(2 * n, "compression", 51.51),
            row(n, "compression", 51.0)]
    lines = bg.convergence_lines(rows)
    fine = next(x for x in lines if x.startswith(f"| RFEM, compression | 1.25 | {2 * n} |"))
    assert "| +1.00 % |" in fine, fine                    # against 51.0, not 50.0 (+3.02 %)
    assert "| -2.00 % |" in next(x for x in lines if x.startswith(f"| RFEM | 1.25 | {2 * n} |"))
    assert bg.is_base(rows[0]) and not bg.is_base(rows[3])


def test_runs_with_another_method_change_against_the_setting():
    """A run with another method (CONV_METHODS) has no run of its own at the study's
    element length: its change is against the scene's own run there."""
    n, rtol = bg.base_elements(), bg.base_rtol()
    fine = bg.CONV_ELEMENTS[-1]
    assert "cvode" in bg.CONV_METHODS

    def row(elements, law, mean):
        return dict(model="rfem", period=3.5, n=elements, rtol=rtol, law=law,
                    mean=mean, spread=0.0, maxima=np.zeros(5), cpu_time=1.0)

    rows = [row(n, "", 50.0), row(fine, "cvode", 50.5), row(n, "compression", 40.0)]
    line = next(x for x in bg.convergence_lines(rows) if x.startswith("| RFEM, cvode |"))
    assert "| +1.00 % |" in line, line


def test_one_short_condition_end_to_end(ropedyn_exe, tmp_path):
    """T = 1.25 s, R = 0.2 m, 20 elements, 2 cycles (one of them the ramp), both models:
    the runs complete, the analysis finds a cycle maximum of each and the page gets its
    table and figures."""
    page = tmp_path / "bergdahl.md"
    figs = tmp_path / "figures"
    env = dict(os.environ, PYTHONPATH=str(ROOT / "tools"))
    result = subprocess.run(
        [sys.executable, "-m", "ropedyn_tools.studies.bergdahl", "--exe", str(ropedyn_exe),
         "--quick", "20,2", "--periods", "1.25", "--radii", "0.2", "--work",
         str(tmp_path / "work"), "--out", str(page), "--figures", str(figs)],
        capture_output=True, text=True, env=env, timeout=900)
    assert result.returncode == 0, result.stderr
    results = bg.collect(tmp_path / "work", (1.25,), bg.MODELS, cycles=1)
    assert sorted(results) == [("mpp", 1.25, 0.2), ("rfem", 1.25, 0.2)]
    for r in results.values():
        assert len(r["maxima"]) == 1 and 20.0 < r["mean"] < 200.0, r
        assert r["cpu_time"] > 0 and r["steps"] > 0
    text = page.read_text()
    assert bg.BEGIN in text and bg.END in text
    row = next(line for line in text.splitlines() if line.startswith("| 1.25 | 0.2 | 70.3 |"))
    assert row.count("%") == 2, row                       # an error for each model
    assert "| RFEM | 1 |" in text and "| MPP | 1 |" in text     # the scores
    assert (figs / "bergdahl_measured.png").stat().st_size > 0
    # each model's cases ran from one queue; their wall time is kept, but counts towards
    # the 30-condition target only for all 30
    for model in bg.MODELS:
        record = json.loads((tmp_path / "work" / model / "wall.json").read_text())
        assert record["wall"] > 0 and record["periods"] == [1.25] and record["radii"] == [0.2]
    assert bg.sweep_walls(tmp_path / "work", bg.MODELS) == {}
    assert (figs / "bergdahl_histories.png").stat().st_size > 0
    # the page was new: a rerun keeps one section
    again = [sys.executable, "-m", "ropedyn_tools.studies.bergdahl", "--exe", str(ropedyn_exe),
             "--quick", "20,2", "--periods", "1.25", "--radii", "0.2", "--work",
             str(tmp_path / "work"), "--out", str(page), "--figures", str(figs)]
    subprocess.run(again + ["--analyse-only"], check=True, capture_output=True, env=env,
                   timeout=300)
    assert page.read_text().count(bg.BEGIN) == 1


def created(path):
    import h5py
    with h5py.File(path, "r") as f:
        return f.attrs["created"], f.attrs["version"].decode()


def test_case_files_of_other_code_run_again(ropedyn_exe, tmp_path):
    """A case file is kept only for the code that wrote it: one of another version is
    refused by --analyse-only and run again by the whole command; one of this code is
    kept."""
    import h5py
    work = tmp_path / "work"
    env = dict(os.environ, PYTHONPATH=str(ROOT / "tools"))
    cmd = [sys.executable, "-m", "ropedyn_tools.studies.bergdahl", "--exe", str(ropedyn_exe),
           "--quick", "12,2", "--periods", "1.25", "--radii", "0.2", "--work", str(work),
           "--out", str(tmp_path / "bergdahl.md"), "--figures", str(tmp_path / "figures")]
    subprocess.run(cmd, check=True, capture_output=True, env=env, timeout=900)
    rfem, mpp = (bg.case_path(work, 1.25, m, 0.2) for m in ("rfem", "mpp"))
    version = bg.exe_version(ropedyn_exe)
    assert created(rfem)[1] == version and bg.current(rfem, version)
    kept = created(mpp)
    with h5py.File(rfem, "r+") as f:
        f.attrs["version"] = np.bytes_(b"0.0.9+g0123456-dirty.89abcdef")
    assert not bg.current(rfem, version) and bg.stale_files([rfem, mpp], version) == [rfem]
    refused = subprocess.run(cmd + ["--analyse-only"], capture_output=True, text=True, env=env,
                             timeout=300)
    assert refused.returncode != 0 and str(rfem) in refused.stderr, refused.stderr
    assert "0.0.9+g0123456-dirty.89abcdef" in refused.stderr
    # the MoorDyn comparison reads the same files: refused there too, before MoorDyn is set up
    from ropedyn_tools.studies import bench_peers_bergdahl
    try:
        bench_peers_bergdahl.main(["--work", str(work), "--exe", str(ropedyn_exe),
                                   "--periods", "1.25", "--radii", "0.2", "--no-write"])
    except SystemExit as stop:
        assert str(rfem) in str(stop) and "0.0.9+g0123456-dirty.89abcdef" in str(stop), stop
    else:
        raise AssertionError("bench_peers bergdahl used a case file of other code")
    rerun = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=900)
    assert rerun.returncode == 0, rerun.stderr
    assert "rfem: 1 case files of other code" in rerun.stderr
    assert created(rfem)[1] == version                      # run again by this code
    assert created(mpp) == kept                             # current: kept as it was
