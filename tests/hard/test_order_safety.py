"""Order safety end to end (docs/stability.md, "Order safety"): CVODE held at order 4 (not
A-stable) on the undamped rope at rtol 1e-3 creates energy within a second (measured:
T + V + dissipated reaches E0 + 10 rtol S at 0.7 s, 850 rtol S at 10 s). The run driver's
energy monitor sees the balance rise above E0 by more than `energy_gain_bound` rtol S and

- with `order_safety = 'lower'` (the default) goes back to the previous record and on at
  the method's A-stable order (BDF2): the file says when and from which order, every
  record after that is at order <= 2, and the balance stays within the bound;
- with 'stop' ends the run with exit code 3 and a reason naming time, step size, the gain
  and the cause; the record with the gain is not written;
- with 'off' the gain is there (the instability the monitor is for).

CVODE at its default order 5 does not gain on the same scene and is left alone. The
long-horizon suite (tests/long) shows the same for MEBDF at order 7 (which gains only after
~8 s) and on the lightly damped rope."""
import pathlib

import h5py
import numpy as np
import pytest

from ropedyn.studies import stability_metrics

ROOT = pathlib.Path(__file__).resolve().parents[2]
UNDAMPED = ROOT / "input" / "hard" / "undamped.nml"
T_END = 1.2
BOUND = 10.0      # &solver energy_gain_bound, its default
LOOSE = ["solver.rtol=1e-3", "solver.atol=1e-5", f"solver.t_end={T_END}",
         "solver.output_interval=0.01"]


@pytest.fixture(scope="module")
def runs(run_many, tmp_path_factory):
    workdir = tmp_path_factory.mktemp("order")
    jobs = {policy: (UNDAMPED, LOOSE + ["solver.method=cvode", "solver.max_order=4",
                                        f"solver.order_safety={policy}"])
            for policy in ("lower", "stop", "off")}
    jobs["default"] = (UNDAMPED, LOOSE + ["solver.method=cvode"])
    return run_many(jobs, workdir)


def gain_ratio(path):
    m = stability_metrics.analyse(path)
    return m["balance_drift"].max() / (m["rtol"] * m["energy_scale"]), m


def test_unguarded_order_4_gains(runs):
    proc, path = runs["off"]
    assert proc.returncode == 0, proc.stderr
    ratio, _ = gain_ratio(path)
    print(f"order 4 unguarded: gain {ratio:.3g} rtol S")
    assert ratio > BOUND


def test_lowered_to_the_a_stable_order(runs):
    proc, path = runs["lower"]
    assert proc.returncode == 0, proc.stderr
    assert "order safety" in proc.stdout and "max order 4 -> 2" in proc.stdout
    ratio, m = gain_ratio(path)
    with h5py.File(path, "r") as f:
        t_low = f["solver/order_lowered_at"][()]
        assert f["solver/order_lowered_from"][()] == 4
        assert f["solver/order_lowered_to"][()] == 2
        assert f["solver/energy_gain"][()] > 0
        order = f["solver/order"][:]
        time = f["time"][:]
    print(f"lowered at {t_low} s; gain {ratio:.3g} rtol S")
    assert 0.0 < t_low < T_END
    assert np.all(order[time > t_low + 1e-9] <= 2)
    assert order[(time > 0) & (time <= t_low)].max() >= 3
    assert ratio <= BOUND
    assert stability_metrics.all_finite(path) == []
    assert m["status"] == "complete"


def test_stop_is_a_diagnosed_failure(runs):
    proc, path = runs["stop"]
    assert proc.returncode == 3
    message = proc.stderr.strip()
    for fragment in ("t = ", "step size", "energy gain", "created energy", "order_safety"):
        assert fragment in message, (fragment, message)
    m = stability_metrics.analyse(path)
    assert m["status"] == "failed"
    ratio = m["balance_drift"].max() / (m["rtol"] * m["energy_scale"])
    assert ratio <= BOUND     # the record with the gain was not written
    assert stability_metrics.all_finite(path) == []


def test_default_order_5_left_alone(runs):
    proc, path = runs["default"]
    assert proc.returncode == 0, proc.stderr
    assert "order safety" not in proc.stdout
    with h5py.File(path, "r") as f:
        assert "order_lowered_at" not in f["solver"]
    ratio, _ = gain_ratio(path)
    assert ratio <= BOUND
