"""The long-horizon matrix of the hard scenes (issue 18; docs/validation/long-horizon.md).

Every scene of input/hard/ runs to its full t_end with the default method and settings, and
with every method of METHODS at every tolerance of RTOLS (atol = rtol / 100, as the scenes'
1e-6 / 1e-8), plus the order-safety cases (ORDER_CASES: MEBDF order 7 and CVODE orders 4
and 5 on the undamped and lightly damped rope at rtol 1e-3, with the monitor off and on)
and the energy cases (energy_cases: the undamped and lightly damped rope to 300 s with
every method and auto at rtol 1e-3, the balance error in m g L at 30 s and 300 s).
Used by the CTest label `long` (tests/long/test_long_horizon.py, `scripts/test --long`) and by
scripts/stability_report (the tables of docs/validation/long-horizon.md and order-safety.md).

**A new method is one line**: append its name to METHODS.

Runs are cached in a work directory (default build/long): a case is run again only when its
command or the code changed, so that the checks and the report can be re-evaluated without
the hour of runs. The code is the git content of src/, solvers/ and CMakeLists.txt with any
uncommitted change to them (`code_fingerprint`): a commit that touches only docs or scripts
relinks the executable (its version string) but keeps the cache; an executable older than
those files, or outside a git checkout, is keyed on its size and modification time.
`measures.json` there holds the scalar measures of every case.
"""
import concurrent.futures
import functools
import hashlib
import json
import os
import pathlib
import re
import subprocess
import time

import numpy as np

from ropedyn_tools.repo import INPUT, ROOT
from ropedyn_tools.studies import stability_metrics
from ropedyn_tools.studies.common import git, scene_number

HARD = INPUT / "hard"

#: the methods of the matrix (each at every tolerance); a new method is one more name here
METHODS = ["cvode", "mebdf", "adams", "erk", "symplectic"]
#: the tolerances of the matrix; atol = rtol * ATOL_RATIO
RTOLS = [1e-3, 1e-5, 1e-7]
ATOL_RATIO = 1e-2

#: order-safety cases: (label, scene, overrides), all at rtol 1e-3 (where the amplification
#: of orders that are not A-stable shows within 10 s; docs/validation/order-safety.md)
ORDER_CASES = [
    (f"{method} {order}, {policy}", scene,
     [f"solver.method={method}", f"solver.max_order={order}", f"solver.order_safety={policy}",
      "solver.rtol=1e-3", "solver.atol=1e-5"])
    for scene in ("undamped", "light_damping")
    for method, order in (("mebdf", 7), ("cvode", 5), ("cvode", 4))
    for policy in ("off", "lower")
]


#: the energy over long runs (docs/validation/energy.md): the undamped and the
#: lightly damped rope (n = 30) to ENERGY_T_END with every method and auto at rtol 1e-3;
#: the balance error (m g L) at ENERGY_TIMES and its largest value up to each
ENERGY_SCENES = ("undamped", "light_damping")
ENERGY_T_END = 300.0
ENERGY_TIMES = (30.0, 300.0)
ENERGY_RTOL = 1e-3


def energy_cases():
    """[(key, scene, overrides)]: every method and auto on the ENERGY_SCENES to 300 s."""
    return [(f"energy/{scene}/{method}", scene, [
        f"solver.method={method}", f"solver.rtol={ENERGY_RTOL:g}",
        f"solver.atol={ENERGY_RTOL * ATOL_RATIO:g}", f"solver.t_end={ENERGY_T_END:g}",
        "solver.output_interval=0.1", "solver.max_steps=100000000"])
        for scene in ENERGY_SCENES for method in METHODS + ["auto"]]


def scenes():
    """Every hard scene (file stem), sorted."""
    return sorted(p.stem for p in HARD.glob("*.nml"))


def scene_t_end(scene):
    return scene_number(HARD / f"{scene}.nml", "t_end")


def has_external_work(scene):
    """Moving supports or loads feed energy in: no 'T + V never rises' there."""
    text = (HARD / f"{scene}.nml").read_text()
    return bool(re.search(r"_motion\s*=\s*'(harmonic|table)'|load_positions", text))


def is_undamped(scene):
    """No damper and no other loss: all the balance loses is the integrator's."""
    text = (HARD / f"{scene}.nml").read_text()
    return "damping = .false." in text and "ground = .true." not in text


def matrix_cases():
    """[(key, scene, overrides)]: the default run and every method at every tolerance."""
    cases = []
    for scene in scenes():
        cases.append((f"{scene}/default", scene, []))
        for method in METHODS:
            for rtol in RTOLS:
                cases.append((f"{scene}/{method}/{rtol:g}", scene, [
                    f"solver.method={method}", f"solver.rtol={rtol:g}",
                    f"solver.atol={rtol * ATOL_RATIO:g}"]))
    return cases


def order_cases():
    return [(f"order/{scene}/{label}", scene, ov) for label, scene, ov in ORDER_CASES]


CODE_PATHS = ("src", "solvers", "CMakeLists.txt")


@functools.lru_cache(maxsize=8)
def _fingerprint(exe, size, mtime_ns, root):
    """See `code_fingerprint` (cached on the executable's identity)."""
    try:
        def listed(*which):
            return [f for f in git("ls-files", "-z", *which, "--", *CODE_PATHS,
                                   root=root).decode().split("\0") if f]
        untracked = listed("--others", "--exclude-standard")
        newest = max((root / f).stat().st_mtime_ns for f in listed("--cached") + untracked
                     if (root / f).exists())
        if newest > mtime_ns:
            raise ValueError("the executable is older than the code")
        parts = [git("rev-parse", *(f"HEAD:{p}" for p in CODE_PATHS), root=root),
                 git("diff", "HEAD", "--binary", "--", *CODE_PATHS, root=root)]
        parts += [f.encode() + (root / f).read_bytes() for f in sorted(untracked)]
        return "code " + hashlib.sha256(b"\0".join(parts)).hexdigest()
    except (subprocess.CalledProcessError, OSError, ValueError):
        return f"exe {size} {mtime_ns}"


def code_fingerprint(exe, root=ROOT):
    """What a cached run's result depends on besides its scene and overrides: the git content
    of CODE_PATHS under `root` (HEAD's trees plus the uncommitted diff and untracked files)
    when the executable is no older than every one of those files, else the executable's
    size and modification time. The executable's path is part of the key (Debug and Release
    builds are different codes)."""
    exe = pathlib.Path(exe).resolve()
    st = exe.stat()
    return f"{exe} " + _fingerprint(str(exe), st.st_size, st.st_mtime_ns,
                                    pathlib.Path(root).resolve())


def _stamp(exe, scene, overrides):
    text = (HARD / f"{scene}.nml").read_text()
    key = json.dumps([code_fingerprint(exe), text, overrides])
    return hashlib.sha256(key.encode()).hexdigest()


def _file_name(key):
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", key) + ".h5"


def run_case(exe, workdir, key, scene, overrides, timeout, cached_only=False):
    """Run one case (unless cached); return (returncode, stderr, h5 path); with
    `cached_only` a case not in the cache is not run (returncode None)."""
    workdir = pathlib.Path(workdir)
    out = workdir / _file_name(key)
    meta = out.with_suffix(".json")
    stamp = _stamp(exe, scene, overrides)
    if meta.exists():
        old = json.loads(meta.read_text())
        # (a refused case, exit 2, wrote no file)
        if old.get("stamp") == stamp and (out.exists() or old["returncode"] == 2):
            return old["returncode"], old["stderr"], out
    if cached_only:
        return None, "not run (not in the cache)", workdir / "missing.h5"
    out.unlink(missing_ok=True)   # an older code's file must not stand for this run's
    cmd = [str(exe), "run", str(HARD / f"{scene}.nml"), "--set", f"output.file={out}"]
    for o in overrides:
        cmd += ["--set", o]
    start = time.monotonic()
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout,
                              cwd=workdir)
        rc, err = proc.returncode, proc.stderr
    except subprocess.TimeoutExpired:
        rc, err = -9, f"killed after {timeout} s wall time"
    meta.write_text(json.dumps({"stamp": stamp, "returncode": rc, "stderr": err,
                                "wall": time.monotonic() - start, "cmd": cmd}))
    return rc, err, out


def measures(rc, stderr, path, scene):
    """The scalar measures of one case (JSON-able) plus the series under '_series'."""
    r = {"returncode": rc, "stderr": stderr.strip(), "scene": scene}
    if rc is None:
        r["outcome"] = stderr
        return r
    if not path.exists() and rc == 2:
        # a method the scene names for a model it cannot integrate (the symplectic method
        # and the MPP, water, ground contact): bad input, refused before any file
        reason = stderr.strip().removeprefix("ropedyn: error: ")
        r.update({"status": "refused", "reason": reason, "nonfinite": [],
                  "outcome": f"refused (exit 2): {reason}"})
        return r
    if not path.exists():
        r["outcome"] = f"no output (exit {rc}): {stderr.strip()}"
        return r
    m = stability_metrics.analyse(path)
    bad = stability_metrics.all_finite(path)
    # (a run that stopped at its start - a method that refused the problem, or a stiffness
    # watch at the first step - moved no energy: its ratios are 0)
    scale = m["rtol"] * m["energy_scale"] or float("inf")
    drift = m["balance_drift"]
    t = m["time"]
    r.update({
        "status": m["status"], "reason": m["reason"], "t_reached": m["t_reached"],
        "t_end": scene_t_end(scene), "steps": m["steps"], "cpu_time": m["cpu_time"],
        "err_test_fails": m["err_test_fails"], "rtol": m["rtol"],
        "energy_scale": m["energy_scale"], "balance_error": m["balance_error"],
        "balance_ratio": m["balance_error"] / scale,
        "max_gain": float(drift.max()), "max_gain_ratio": float(drift.max()) / scale,
        "final_drift": float(drift[-1]),
        # the energy the integrator removed per second (numerical damping), J/s
        "damping_rate": float(-drift[-1] / t[-1]) if t[-1] > 0 else 0.0,
        "energy_growth": m["energy_growth"], "nonfinite": bad,
        "method": m["method"], "orders": sorted(set(int(k) for k in m["order"][1:])),
        "order_lowered_at": None,
    })
    import h5py
    with h5py.File(path, "r") as f:
        if "order_lowered_at" in f["solver"]:
            r["order_lowered_at"] = float(f["solver/order_lowered_at"][()])
            r["order_lowered_to"] = int(f["solver/order_lowered_to"][()])
    r.update(energy_in_mgl(path, t, drift))
    r["outcome"] = "complete" if (m["status"] == "complete" and rc == 0) else \
        f"failed (exit {rc}) at t = {m['t_reached']:.4g} s: {m['reason']}"
    r["_series"] = {"time": t, "tip": m["tip"], "mech": m["mech"],
                    "dissipated": m["dissipated"], "drift": drift}
    return r


def energy_in_mgl(path, t, drift):
    """The balance error B - E0 in units of m g L (the rope's weight times its length) at
    ENERGY_TIMES and its largest |value| up to each (those reached), and m g L itself (J)."""
    import h5py
    with h5py.File(path, "r") as f:
        mass = float(np.sum(f["rope/element_mass"][()]))
        length = float(np.sum(f["rope/element_length"][()]))
        scene = f.attrs["scene"].decode()
    g = re.search(r"gravity\s*=\s*([0-9.eE+-]+)", scene)
    mgl = mass * (float(g.group(1)) if g else 9.81) * length
    out = {"mgl": mgl, "drift_mgl_at": {}, "max_drift_mgl_to": {}}
    for when in ENERGY_TIMES:
        if len(t) and t[-1] >= when - 1e-9:
            k = int(np.searchsorted(t, when - 1e-9))
            out["drift_mgl_at"][f"{when:g}"] = float(drift[k]) / mgl
            out["max_drift_mgl_to"][f"{when:g}"] = float(np.abs(drift[:k + 1]).max()) / mgl
    return out


def run_all(exe, cases, workdir, jobs=2, timeout=3000, log=print, cached_only=False):
    """Run `cases` [(key, scene, overrides)] two at a time (longest first when known);
    return {key: measures}; writes workdir/measures.json (without the series)."""
    workdir = pathlib.Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    walls = {}
    for key, _, _ in cases:
        meta = (workdir / _file_name(key)).with_suffix(".json")
        if meta.exists():
            walls[key] = json.loads(meta.read_text()).get("wall", 0.0)
    order = sorted(cases, key=lambda c: -walls.get(c[0], 1e9))
    results = {}
    with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
        futures = {pool.submit(run_case, exe, workdir, key, scene, ov, timeout,
                               cached_only): (key, scene)
                   for key, scene, ov in order}
        for fut in concurrent.futures.as_completed(futures):
            key, scene = futures[fut]
            rc, err, out = fut.result()
            results[key] = measures(rc, err, out, scene)
            r = results[key]
            if log:
                log(f"  {key}: {r['outcome'][:120]}"
                    + (f", {r['steps']} steps, {r['cpu_time'] or 0.0:.1f} s, balance "
                       f"{r['balance_ratio']:.3g} rtol S, gain {r['max_gain_ratio']:.3g}"
                       if "steps" in r else ""))
    saved = {k: {a: b for a, b in v.items() if a != "_series"} for k, v in results.items()}
    old = {}
    if (workdir / "measures.json").exists():
        old = json.loads((workdir / "measures.json").read_text())
    old.update(saved)
    (workdir / "measures.json").write_text(json.dumps(old, indent=1, sort_keys=True))
    return results


def tip_difference(a, b, until=None):
    """max |tip_a - tip_b| over the common output times (up to `until` s), m."""
    ta, tb = a["_series"]["time"], b["_series"]["time"]
    n = min(len(ta), len(tb))
    if until is not None:
        n = min(n, int(np.searchsorted(ta[:n], until + 1e-12)))
    # a failed run ends with a record at its failure time, off the output grid
    while n > 0 and not np.isclose(ta[n - 1], tb[n - 1], rtol=1e-12, atol=1e-12):
        n -= 1
    if n == 0:
        return 0.0
    assert np.allclose(ta[:n], tb[:n])
    return float(np.abs(a["_series"]["tip"][:n] - b["_series"]["tip"][:n]).max())


def default_workdir():
    return pathlib.Path(os.environ.get("ROPEDYN_LONG_DIR",
                                       pathlib.Path(__file__).resolve().parents[3]
                                       / "build" / "long"))
