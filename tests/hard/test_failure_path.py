"""The failure path end to end: a NaN in the right-hand side (the testing aid
`&effects fault_nan_after`, docs/guide/effects.md) or an exhausted step budget ends the run with
exit code 3 and one message naming the time, the step size and the cause; the HDF5 file is
marked failed with that reason, holds only finite numbers, and keeps every record before
the failure unchanged (bit for bit the records of the same run without the fault)."""
import pathlib
import re
import subprocess

import h5py
import numpy as np
import pytest

from ropedyn_tools.studies import stability_metrics

ROOT = pathlib.Path(__file__).resolve().parents[2]
PAPER = ROOT / "input" / "paper.nml"
STEEL = ROOT / "input" / "hard" / "steel_wire.nml"
LIGHT = ROOT / "input" / "paper_light_damping.nml"
T_FAULT = 0.1234  # s, between two output times (0.12, 0.13)
DT = 0.01
MODELS = {"rfem": ["model.kind=rfem", "model.elements=10"],
          "mpp": ["model.kind=mpp", "model.elements=6"]}
CASES = [(model, method) for model in MODELS for method in ("cvode", "mebdf")]
BUDGET_SYMPLECTIC = ["solver.method=symplectic", "model.elements=10", "solver.t_end=0.05"]


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
    # the budget spent after the order safety started cvode again at its safe order
    jobs["budget_lowered_cvode"] = (LIGHT, ["solver.method=cvode", "solver.max_order=3",
                                            "solver.energy_gain_bound=0.1", "solver.t_end=3",
                                            "model.elements=10", "solver.max_steps=60000"])
    jobs["budget_erk"] = (PAPER, ["solver.method=erk", "model.elements=10",
                                  "solver.t_end=0.05", "solver.max_steps=30"])
    jobs["budget_symplectic"] = (PAPER, BUDGET_SYMPLECTIC + ["solver.max_steps=30"])
    jobs["stald_mebdf"] = (PAPER, ["solver.method=mebdf",
                                   "solver.stability_limit_detection=.true."])
    jobs["stald_cvode"] = (PAPER, ["solver.method=cvode", "model.elements=10",
                                   "solver.stability_limit_detection=.true.",
                                   "solver.t_end=0.05"])
    return run_many(jobs, workdir)


def check_diagnosis(proc, path, cause, budget_spent=False):
    """Exit 3, one stderr line, and the same reason in the failed file; after a spent step
    budget the line goes on with how to continue (a resume, which has a budget of its own),
    which is not part of the file's reason. Returns that continuation ('' when none)."""
    assert proc.returncode == 3, proc.stderr
    message = proc.stderr.strip()
    assert message.startswith("ropedyn: error: ") and len(message.splitlines()) == 1, message
    for fragment in ("t = ", "step size", cause):
        assert fragment in message, (fragment, message)
    with h5py.File(path, "r") as f:
        assert f.attrs["status"] == b"failed"
        reason = f.attrs["reason"].decode()
        assert "steps" in f["solver"] and "cpu_time" in f["solver"]
    assert stability_metrics.all_finite(path) == []
    body = message[len("ropedyn: error: "):]
    assert body.startswith(reason), (body, reason)
    rest = body[len(reason):]
    if budget_spent:
        assert rest.startswith(f"; continue with: ropedyn run --resume {path}"), rest
    else:
        assert rest == "", rest
    return rest


def resume_as_told(ropedyn_exe, path, rest):
    """Follow the failure's continuation: `ropedyn run --resume FILE [--set ...]`, as
    printed; the run then completes."""
    words = rest[len("; continue with: ropedyn "):].split()
    proc = subprocess.run([str(ropedyn_exe), *words], capture_output=True, text=True,
                          timeout=600)
    assert proc.returncode == 0, proc.stderr
    with h5py.File(path, "r") as f:
        assert f.attrs["status"] == b"complete"


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
def test_step_budget_exhausted(runs, method, ropedyn_exe):
    """The budget spent: the message says what the rest takes at the last step and how to
    go on, and going on as it says finishes the run."""
    proc, path = runs[f"budget_{method}"]
    rest = check_diagnosis(proc, path, "max_steps", budget_spent=True)
    assert "the rest of the run, to t = 0.05 s, takes about " in proc.stderr, proc.stderr
    assert stability_metrics.analyse(path)["steps"] <= 300
    resume_as_told(ropedyn_exe, path, rest)


def test_step_budget_exhausted_explicit(runs, ropedyn_exe):
    proc, path = runs["budget_erk"]
    rest = check_diagnosis(proc, path, "max_steps exceeded (30 steps)", budget_spent=True)
    # the rest takes more than a budget of 30 at erk's step: the resume asks for more
    m = re.search(r"takes about (\d+) steps more", proc.stderr)
    assert m and int(m.group(1)) > 30, proc.stderr
    assert re.search(r" --set solver\.max_steps=(\d+)$", rest), rest
    resume_as_told(ropedyn_exe, path, rest)


def test_step_budget_after_a_restart_names_the_whole_budget(runs):
    """The order safety lowers cvode's order at 0.7 s, starting it again with what is left
    of the budget: when that runs out, the message names the run's budget (it named what
    was left, 47749 steps), which the run has taken."""
    proc, path = runs["budget_lowered_cvode"]
    assert proc.returncode == 3, proc.stderr
    # (after the scene's warning on the damping ratio of 10 elements)
    message = proc.stderr.strip().splitlines()[-1]
    assert message.startswith("ropedyn: error: cvode failed at t = ") and \
        "max_steps exceeded (60000 steps); at the size of the last accepted step" in message, \
        message
    with h5py.File(path, "r") as f:
        assert f["solver/order_lowered_at"][()] == pytest.approx(0.7)
        assert f["solver/steps"][()] == 60000


def test_symplectic_says_at_once_that_the_budget_is_short(runs, ropedyn_exe, tmp_path):
    """The symplectic method's step is known before it steps: a budget that cannot reach
    t_end ends the run at its start, with the steps the run takes (exactly: at its step
    fitted to the output interval) and the budget to add; with that added it completes,
    run again or resumed as the message says (the file of the failed run holds another
    run's scene: running again on it is refused)."""
    proc, path = runs["budget_symplectic"]
    rest = check_diagnosis(proc, path, "raise solver.max_steps by ", budget_spent=True)
    m = re.search(r"failed at t =  0\.0+E\+00 s.*takes about (\d+) steps of .* more than "
                  r"the 30 that max_steps leaves: raise solver\.max_steps by (\d+);",
                  proc.stderr.strip())
    assert m, proc.stderr
    needed, more = int(m.group(1)), int(m.group(2))
    assert rest.endswith(f" --set solver.max_steps={30 + more}"), rest
    assert stability_metrics.analyse(path)["steps"] == 0
    out = tmp_path / "enough.h5"
    done = subprocess.run([str(ropedyn_exe), "run", str(PAPER), "--set", f"output.file={out}",
                           *sum((["--set", s] for s in BUDGET_SYMPLECTIC), []),
                           "--set", f"solver.max_steps={30 + more}"],
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    steps = stability_metrics.analyse(out)["steps"]
    # the count it said: at its step fitted to the output interval (t_end is on the
    # outputs), not at the rule's step before the fit (113 of the 115 steps)
    assert steps == needed, (steps, needed)
    # a budget one step short of that (more than the count at the rule's step) is refused
    # at the start too, not spent part of the way
    short = tmp_path / "short.h5"
    one_short = subprocess.run([str(ropedyn_exe), "run", str(PAPER), "--set",
                                f"output.file={short}",
                                *sum((["--set", s] for s in BUDGET_SYMPLECTIC), []),
                                "--set", f"solver.max_steps={needed - 1}"],
                               capture_output=True, text=True, timeout=600)
    assert one_short.returncode == 3, one_short.stderr
    assert f"takes about {needed} steps" in one_short.stderr, one_short.stderr
    assert stability_metrics.analyse(short)["steps"] == 0
    resume_as_told(ropedyn_exe, path, rest)


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
        reason = f.attrs["reason"].decode()
    # the file's reason, then (not in the file) how to go on
    assert message[len("ropedyn: error: "):] == (
        f"{reason}; continue with: ropedyn run --resume {path} --set solver.max_steps="
        + message.rsplit("=", 1)[1]), message


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
