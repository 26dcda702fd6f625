"""The failure path end to end: a NaN in the right-hand side (the testing aid
`&effects fault_nan_after`, docs/guide/effects.md) or an exhausted step budget ends the run with
exit code 3 and one message naming the time, the step size and the cause; the HDF5 file is
marked failed with that reason, holds only finite numbers, and keeps every record before
the failure unchanged (bit for bit the records of the same run without the fault)."""
import pathlib

import h5py
import numpy as np
import pytest

from ropedyn_tools.studies import stability_metrics

ROOT = pathlib.Path(__file__).resolve().parents[2]
PAPER = ROOT / "input" / "paper.nml"
STEEL = ROOT / "input" / "hard" / "steel_wire.nml"
T_FAULT = 0.1234  # s, between two output times (0.12, 0.13)
DT = 0.01
MODELS = {"rfem": ["model.kind=rfem", "model.elements=10"],
          "mpp": ["model.kind=mpp", "model.elements=6"]}
CASES = [(model, method) for model in MODELS for method in ("cvode", "mebdf")]


@pytest.fixture(scope="module")
def runs(run_many, tmp_path_factory):
    workdir = tmp_path_factory.mktemp("failure")
    jobs = {}
    for model, method in CASES:
        base = MODELS[model] + [f"solver.method={method}", "solver.t_end=0.3",
                                f"solver.output_interval={DT}"]
        jobs[f"{model}_{method}_fault"] = (PAPER, base + [f"effects.fault_nan_after={T_FAULT}"])
        jobs[f"{model}_{method}_clean"] = (PAPER, base)
    for method in ("cvode", "mebdf"):
        jobs[f"budget_{method}"] = (STEEL, [f"solver.method={method}", "solver.t_end=0.05",
                                            "solver.max_steps=300"])
    # the budget spent after cvode's own log diagnosed lightly damped stiff modes
    jobs["budget_diagnosed_cvode"] = (STEEL, ["solver.method=cvode", "solver.rtol=1e-7",
                                              "solver.atol=1e-9", "solver.max_steps=150000"])
    for method in ("erk", "symplectic"):
        jobs[f"budget_{method}"] = (PAPER, [f"solver.method={method}", "model.elements=10",
                                            "solver.t_end=0.05", "solver.max_steps=30"])
    jobs["stald_mebdf"] = (PAPER, ["solver.method=mebdf",
                                   "solver.stability_limit_detection=.true."])
    jobs["stald_cvode"] = (PAPER, ["solver.method=cvode", "model.elements=10",
                                   "solver.stability_limit_detection=.true.",
                                   "solver.t_end=0.05"])
    return run_many(jobs, workdir)


def check_diagnosis(proc, path, cause):
    """Exit 3, one stderr line, and the same reason in the failed file."""
    assert proc.returncode == 3, proc.stderr
    message = proc.stderr.strip()
    assert message.startswith("ropedyn: error: ") and len(message.splitlines()) == 1, message
    for fragment in ("t = ", "step size", cause):
        assert fragment in message, (fragment, message)
    with h5py.File(path, "r") as f:
        assert f.attrs["status"] == b"failed"
        assert f.attrs["reason"].decode() == message[len("ropedyn: error: "):]
        assert "steps" in f["solver"] and "cpu_time" in f["solver"]
    assert stability_metrics.all_finite(path) == []


@pytest.mark.parametrize("model,method", CASES)
def test_nan_in_rhs_fails_cleanly(runs, model, method):
    proc, path = runs[f"{model}_{method}_fault"]
    check_diagnosis(proc, path, "NaN")
    m = stability_metrics.analyse(path)
    # the last good state is the fault time itself: no step ever got past it
    assert m["t_reached"] == pytest.approx(T_FAULT, abs=1e-9)
    # no crawl towards round-off step sizes after the fault (CVODE used to run to max_steps)
    _, clean = runs[f"{model}_{method}_clean"]
    assert m["steps"] < stability_metrics.analyse(clean)["steps"]


@pytest.mark.parametrize("model,method", CASES)
def test_data_before_the_failure_kept(runs, model, method):
    _, path = runs[f"{model}_{method}_fault"]
    _, clean = runs[f"{model}_{method}_clean"]
    with h5py.File(path, "r") as f, h5py.File(clean, "r") as g:
        t = f["time"][:]
        kept = int(np.sum(t < T_FAULT - 1e-6))
        assert kept == round(T_FAULT / DT) + 1          # 0, 0.01, ..., 0.12
        assert len(t) == kept + 1                        # + the last good state at T_FAULT
        for name in ("time", "state/q", "state/qdot", "rope/points", "energy/total",
                     "energy/dissipated"):
            assert np.array_equal(f[name][:kept], g[name][:kept]), name


@pytest.mark.parametrize("method", ["cvode", "mebdf"])
def test_step_budget_exhausted(runs, method):
    proc, path = runs[f"budget_{method}"]
    check_diagnosis(proc, path, "max_steps")
    assert stability_metrics.analyse(path)["steps"] <= 300


@pytest.mark.parametrize("method", ["erk", "symplectic"])
def test_step_budget_exhausted_explicit(runs, method):
    proc, path = runs[f"budget_{method}"]
    check_diagnosis(proc, path, "max_steps exceeded (30 steps)")


def test_step_budget_exhausted_names_the_diagnosed_cause(runs):
    """The steel wire with cvode at rtol 1e-7: cvode's crawl watch diagnoses lightly
    damped stiff modes at 0.12 s (and lowers its order); when the budget runs out later, the
    message names that cause, when it was found, and the methods that avoid it."""
    proc, path = runs["budget_diagnosed_cvode"]
    assert proc.returncode == 3, proc.stderr
    # (the warning of the diagnosis was printed while the run went on)
    message = proc.stderr.strip().splitlines()[-1]
    for fragment in ("ropedyn: error: ", "max_steps exceeded (150000 steps)",
                     "the run had diagnosed at t = ", "lightly damped stiff modes",
                     "method = 'mebdf' or 'auto' avoids it"):
        assert fragment in message, (fragment, message)
    with h5py.File(path, "r") as f:
        assert f.attrs["reason"].decode() == message[len("ropedyn: error: "):]


def test_stability_limit_detection_only_for_cvode(runs):
    proc, path = runs["stald_mebdf"]
    assert proc.returncode == 2
    message = proc.stderr.strip()
    for fragment in ("--set solver.stability_limit_detection=.true.", "&solver",
                     "only for method cvode"):
        assert fragment in message, (fragment, message)
    assert not path.exists()
    proc, path = runs["stald_cvode"]
    assert proc.returncode == 0, proc.stderr
    with h5py.File(path, "r") as f:
        assert "stability_limit_detection = .true." in f.attrs["scene"].decode()
