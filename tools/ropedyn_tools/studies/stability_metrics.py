"""Measures of one ropedyn run file used by the stiff-case suite (tests/hard) and by
scripts/stability_report (ropedyn_tools.studies.stability_report; docs/validation/hard-scenes.md).

Every measure is read from the HDF5 file alone (layout: docs/guide/output.md):

- energy balance error: max over the records of |B(t) - B(0)|, B = T + V + dissipated -
  support work (J);
- energy scale S: the energy the run moves around, max T + max elastic + (max - min) of the
  gravity energy + the energy dissipated at the end (J). It is the scale of the tolerance
  bounds: each accepted step keeps its local error near rtol |y| + atol, and dE = grad E . dy
  turns a relative state error rtol into an energy error of order rtol times the kinetic,
  elastic and gravity energies in play;
- energy growth: max over t of (T+V)(t) - min_{s <= t} (T+V)(s), the largest rise of the
  mechanical energy above an earlier value (J). With damping on and fixed supports
  T + V can only fall; a rise beyond the integration error is an integrator instability;
- rtol: the relative tolerance of the run (from the scene echo);
- tip position: /rope/points[:, -1, :] (m); tip speed |v| of the free end of the last
  element from the state: centre velocity + phi' (l/2) (-sin phi, cos phi) (m/s); for a
  rope held at both ends (no free tip) the speed of its midpoint (middle element's centre).
"""
import re

import h5py
import numpy as np

from ropedyn import io


def weight_length(run):
    """m g L of a run's rope (J; `run` from ropedyn.io.load_run), the unit the run summary
    gives the balance in, as the run computed it: its element masses times the scene's
    gravity times the rope's length; 0 when the scene switches gravity off."""
    if not run.group("effects").get("gravity", True):
        return 0.0
    rope = run.group("rope")
    return float(np.sum(run.element_mass)) * float(rope["gravity"]) * float(rope["length"])


def all_finite(path):
    """Names of the datasets that hold a NaN or Inf (empty: all finite)."""
    bad = []

    def visit(name, obj):
        if isinstance(obj, h5py.Dataset) and obj.dtype.kind in "fc":
            if not np.all(np.isfinite(obj[()])):
                bad.append(name)

    with h5py.File(path, "r") as f:
        f.visititems(visit)
    return bad


def analyse(path, run=None):
    """A dict of the measures above plus status, reason, counters, the raw series and m g L
    (weight_length); `run`: the file at `path` already loaded (io.load_run), for a caller
    that takes measures of its own from it too."""
    run = io.load_run(path) if run is None else run
    r = {"weight_length": weight_length(run),
         "status": run.attrs["status"], "reason": run.attrs.get("reason", ""),
         "scene": run.attrs["scene"], "model": run.attrs["model"], "method": run.attrs["method"]}
    t, e = run.time, run.energy
    kinetic, elastic, gravity = e["kinetic"], e["elastic"], e["gravity"]
    dissipated, work = e["dissipated"], e["support_work"]
    mech = kinetic + elastic + gravity
    q, qdot = run.q, run.qdot
    tip = run.points[:, -1, :]
    lengths = run.element_length
    for name in ("steps", "rhs_evals", "jac_evals", "err_test_fails", "nonlin_conv_fails",
                 "cpu_time"):
        r[name] = run.stats.get(name)
    r["order"] = run.order
    balance = mech + dissipated - work
    r["rtol"] = float(re.search(r"^\s*rtol = (\S+)", r["scene"], re.M).group(1))
    r["time"] = t
    r["t_reached"] = float(t[-1])
    r["mech"] = mech
    r["dissipated"] = dissipated
    r["balance_error"] = float(np.max(np.abs(balance - balance[0])))
    r["balance_drift"] = balance - balance[0]
    r["energy_scale"] = float(kinetic.max() + elastic.max() + (gravity.max() - gravity.min())
                              + abs(dissipated[-1]))
    r["energy_growth"] = float(np.max(mech - np.minimum.accumulate(mech)))
    r["tip"] = tip
    phi = q[:, -1, 2]
    omega = qdot[:, -1, 2]
    half = 0.5 * lengths[-1]
    vx = qdot[:, -1, 0] - omega * half * np.sin(phi)
    vy = qdot[:, -1, 1] + omega * half * np.cos(phi)
    speed = np.hypot(vx, vy)
    r["tip_speed"] = speed
    r["max_tip_speed"] = float(speed.max())
    r["t_max_tip_speed"] = float(t[int(speed.argmax())])
    # a rope held at both ends has no free tip: its midpoint (the middle element's centre)
    mid = qdot[:, qdot.shape[1] // 2, :2]
    r["mid_speed"] = np.hypot(mid[:, 0], mid[:, 1])
    r["bottom_free"] = lower_end_free(r["scene"])
    return r


def lower_end_free(scene):
    """Whether the rope's lower end is free at some time of the run: a free bottom, or a
    held one released (its release time >= 0), as the folded ropes' is at the start."""
    free = re.search(r"^\s*bottom = 'free'", scene, re.M) is not None
    release = re.search(r"^\s*bottom_release_time = (\S+)", scene, re.M)
    return free or (release is not None and float(release.group(1)) >= 0.0)
