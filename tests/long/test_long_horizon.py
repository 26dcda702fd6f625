"""Long-horizon guarantees (issue 18; docs/stability.md, "Long horizons"): every hard scene
of input/hard to its full t_end, with the default method and with every method of
ropedyn.studies.long_horizon.METHODS at rtol 1e-3, 1e-5 and 1e-7 (atol = rtol/100), in the
Release build. CTest label `long` (`scripts/test --long`, about 40 minutes on two cores);
not part of the normal suite.

For every case:
1. it completes, or fails with exit code 3 and a reason naming time, step size and cause;
2. no NaN or Inf reaches the output;
3. energy balance: max |T + V + dissipated - work - E0| <= B_E rtol S (S the run's energy
   scale, stability_metrics), B_E per method (three times the largest value measured over
   all scenes and tolerances, BALANCE_BOUND);
4. no energy gain: T + V + dissipated - work never lies above E0 by more than G rtol S,
   G = the order-safety bound `&solver energy_gain_bound` (10): what the energy monitor
   guarantees; on scenes with damping and without external work T + V also never rises by
   more than that;
5. the methods agree: at each tolerance, max |tip_a - tip_b| over the first AGREE_UNTIL
   seconds (before the motion from 75 degrees turns chaotic) <= B_X rtol L.

The order-safety cases (ORDER_CASES) show the monitor at work: MEBDF at order 7 and CVODE
at order 4 gain energy on the undamped rope at rtol 1e-3 with the monitor off, and are
lowered to their A-stable orders (4, 2) and keep the balance with it on; CVODE at its
default order 5 does not gain on the undamped rope and is left alone (on the lightly damped
one at rtol 1e-3 it does, and is lowered too).

Runs are cached in build/long (ROPEDYN_LONG_DIR): rerunning the suite after a change of
the bounds takes seconds; a new executable or scene file reruns the cases it touches.
"""
import re

import pytest

from ropedyn.studies import long_horizon as lh

#: B_E per method: bound on balance error / (rtol S), three times the largest measured
#: (82 of the 180 cases measured so far; docs/stability.md "Long horizons")
BALANCE_BOUND = {"cvode": 4e3,   # 1120: light_damping, rtol 1e-7
                 "mebdf": 2e2}   # 56: light_damping, rtol 1e-5
#: G: the energy monitor's default bound (&solver energy_gain_bound), in rtol S
GAIN_BOUND = 10.0
#: B_X: bound on max |tip_a - tip_b| / (rtol L) over AGREE_UNTIL s (per scene, default
#: 1 s); three times the largest measured (0.068: mpp_light_damping at 1e-7)
TIP_BOUND = 0.2
AGREE_UNTIL = {"default": 1.0,
               # the folded falls: up to the end of the fall (0.38 s), where the tension
               # at the tip becomes singular and accurate solutions separate
               "folded_release": 0.3, "folded_n301": 0.3}
#: cases that gain more than G rtol S although every order safety acted: not an order
#: instability (measured gain in rtol S and why)
GAIN_EXCEPTIONS = {
    # the end of the fall at 0.38 s (a singular whip at the tip) at rtol 1e-3: lowered to
    # BDF2 at 0.38 s it still gains (185 rtol S): an accuracy failure of the loose tolerance
    # at the singularity, which the order cannot cure
    "folded_n301/cvode/0.001": 600.0,
}

MATRIX = lh.matrix_cases()
ORDER = lh.order_cases()


@pytest.fixture(scope="module")
def results(ropedyn_exe):
    return lh.run_all(ropedyn_exe, MATRIX + ORDER, lh.default_workdir())


def diagnosis_ok(r):
    return (r["returncode"] == 3 and r.get("status") == "failed"
            and "t =" in r["reason"] and "step size" in r["reason"])


def rope_length(scene):
    m = re.search(r"^\s*&rope[^/]*length\s*=\s*([0-9.eE+-]+)",
                  (lh.HARD / f"{scene}.nml").read_text(), re.M)
    return float(m.group(1)) if m else 1.0


KEYS = [key for key, _, _ in MATRIX]


@pytest.mark.parametrize("key", KEYS)
def test_completes_or_diagnosed(results, key):
    r = results[key]
    assert "status" in r, r["outcome"]
    if r["returncode"] == 0:
        assert r["status"] == "complete"
        assert r["t_reached"] == pytest.approx(r["t_end"], rel=1e-12)
    else:
        assert diagnosis_ok(r), (r["returncode"], r["stderr"])


@pytest.mark.parametrize("key", KEYS)
def test_output_finite(results, key):
    assert results[key].get("nonfinite") == []


@pytest.mark.parametrize("key", KEYS)
def test_energy_balance(results, key):
    r = results[key]
    bound = BALANCE_BOUND[r["method"]]
    print(f"{key}: balance {r['balance_ratio']:.3g} rtol S (bound {bound})")
    assert r["balance_ratio"] <= bound


@pytest.mark.parametrize("key", KEYS)
def test_no_energy_gain(results, key):
    r = results[key]
    print(f"{key}: largest gain {r['max_gain_ratio']:.3g} rtol S")
    assert r["max_gain_ratio"] <= GAIN_EXCEPTIONS.get(key, GAIN_BOUND)
    if key in GAIN_EXCEPTIONS:
        return
    text = (lh.HARD / f"{r['scene']}.nml").read_text()
    if not lh.has_external_work(r["scene"]) and "damping = .false." not in text:
        assert r["energy_growth"] <= GAIN_BOUND * r["rtol"] * r["energy_scale"]


@pytest.mark.parametrize("scene,rtol", [(s, t) for s in lh.scenes() for t in lh.RTOLS])
def test_methods_agree(results, scene, rtol):
    runs = [results[f"{scene}/{m}/{rtol:g}"] for m in lh.METHODS]
    runs = [r for r in runs if "_series" in r]
    ref = runs[0]
    for other in runs[1:]:
        until = AGREE_UNTIL.get(scene, AGREE_UNTIL["default"])
        diff = lh.tip_difference(ref, other, until)
        ratio = diff / (rtol * rope_length(scene))
        print(f"{scene} {rtol:g} {ref['method']} - {other['method']}: {ratio:.3g} rtol L")
        assert ratio <= TIP_BOUND


def order_result(results, scene, label):
    return results[f"order/{scene}/{label}"]


@pytest.mark.parametrize("scene", ["undamped", "light_damping"])
def test_order_safety_lowers_mebdf_7(results, scene):
    off = order_result(results, scene, "mebdf 7, off")
    on = order_result(results, scene, "mebdf 7, lower")
    print(f"{scene}: mebdf 7 gains {off['max_gain_ratio']:.3g} rtol S unguarded, "
          f"{on['max_gain_ratio']:.3g} guarded (lowered at {on['order_lowered_at']})")
    assert on["status"] == "complete" and on["max_gain_ratio"] <= GAIN_BOUND
    if off["max_gain_ratio"] > GAIN_BOUND:
        assert on["order_lowered_to"] == 4 and max(on["orders"]) == 7
        assert on["order_lowered_at"] is not None
    if scene == "undamped":
        assert off["max_gain_ratio"] > GAIN_BOUND    # the instability the monitor is for


@pytest.mark.parametrize("scene", ["undamped", "light_damping"])
def test_order_safety_cvode(results, scene):
    off5 = order_result(results, scene, "cvode 5, off")
    on5 = order_result(results, scene, "cvode 5, lower")
    off4 = order_result(results, scene, "cvode 4, off")
    on4 = order_result(results, scene, "cvode 4, lower")
    print(f"{scene}: cvode 5 gains {off5['max_gain_ratio']:.3g} rtol S, cvode 4 "
          f"{off4['max_gain_ratio']:.3g} unguarded, {on4['max_gain_ratio']:.3g} guarded")
    # order 5: left alone where it does not gain (the same run); where it does (the lightly
    # damped rope at rtol 1e-3, measured: lowered at 1.2 s) lowered to BDF2
    if off5["max_gain_ratio"] <= GAIN_BOUND:
        assert on5["order_lowered_at"] is None and on5["steps"] == off5["steps"]
    else:
        assert on5["order_lowered_to"] == 2
    assert on5["max_gain_ratio"] <= GAIN_BOUND
    if scene == "undamped":
        assert on5["order_lowered_at"] is None
    # order 4 gains; guarded it is lowered to BDF2 and keeps the balance
    assert off4["max_gain_ratio"] > GAIN_BOUND
    assert on4["order_lowered_to"] == 2 and on4["max_gain_ratio"] <= GAIN_BOUND
