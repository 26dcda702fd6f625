"""Long-horizon guarantees (issue 18; docs/validation/long-horizon.md): every hard scene
of input/hard to its full t_end, with the default method and with every method of
ropedyn_tools.studies.long_horizon.METHODS at rtol 1e-3, 1e-5 and 1e-7 (atol = rtol/100), in the
Release build (METHODS = cvode, mebdf, adams, erk, symplectic), and the energy cases: the
undamped and lightly damped rope to 300 s with every method and auto at rtol 1e-3. CTest label `long`
(`scripts/test --long`, about half an hour of CPU, see docs/validation/long-horizon.md); not part of the
normal suite.

For every case:
1. it completes, or fails with exit code 3 and a reason naming time, step size and cause,
   and the failure is one the suite knows and explains: a case of ACCEPTED_FAILURES (with
   the text its reason must contain), or an explicit method (erk, adams) stopped quickly
   on a stiff scene by its crawl watch, naming the implicit methods (STIFF_STOP); any other
   failure fails the test;
2. no NaN or Inf reaches the output;
3. energy balance: max |T + V + dissipated - work - E0| <= B_E rtol S (S the run's energy
   scale, stability_metrics), B_E per method (about three times the largest value measured
   over all scenes and tolerances, BALANCE_BOUND);
4. no energy gain: T + V + dissipated - work never lies above E0 by more than G rtol S,
   G = the order-safety bound `&solver energy_gain_bound` (10): what the energy monitor
   guarantees; on scenes with damping and without external work T + V also never rises by
   more than that;
5. the methods agree: at each tolerance, max |tip_cvode - tip_m| over the first
   AGREE_UNTIL seconds (before the motion from 75 degrees turns chaotic) <= B_X rtol L
   (B_X per method, TIP_BOUND).

Known defects (KNOWN_DEFECTS, none now) are strict expected failures: diagnosed, listed
with their cause, and flagged when a fix makes them pass (ERK's dissipated energy at
impacts was one until erk integrated its quadratures with its stages and error test). (ADAMS's energy gain on barely damped modes, up to 791 rtol S, was one until ADAMS got
a safe order, 2: the monitor now lowers it there, and the gains stay below G; where order
2 then needs steps too short, the run stops with the stiffness watch's diagnosis.)

The order-safety cases (ORDER_CASES) show the monitor at work: CVODE at order 4 gains energy
on the undamped rope at rtol 1e-3 with the monitor off, and is lowered to its A-stable order
(2) and keeps the balance with it on (MEBDF asked for order 7 starts at its safe order 4
there: the fast modes of both ropes are lightly damped, and it gains nothing); CVODE at its
default order 5 gains less than the bound on both ropes (a few rtol S at rtol 1e-3) and is
left alone.

Runs are cached in build/long (ROPEDYN_LONG_DIR): rerunning the suite after a change of
the bounds takes seconds; a new executable or scene file reruns the cases it touches.
"""
import re

import pytest

from ropedyn_tools.studies import long_horizon as lh

#: the symplectic method's bound (BALANCE_BOUND's rule: 15.6 on folded_release at rtol
#: 1e-5, its step at (1e-5 / 2e-6)^(1/4) of the tolerance rule's; 12.6 whip, 9.1
#: shaken_support at 1e-5; at most 1.5 at 1e-3)
SYMPLECTIC_BALANCE_BOUND = 50.0
#: B_E per method: bound on balance error / (rtol S), about three times the largest measured
#: over all scenes and tolerances outside KNOWN_DEFECTS (docs/validation/long-horizon.md)
BALANCE_BOUND = {"cvode": 6e3,   # 1871: undamped, rtol 1e-7
                 "mebdf": 2e2,   # 58: undamped, rtol 1e-5
                 # 18.4 on mpp_undamped (the default runs, rtol 1e-6), where auto now
                 # runs adams (orders up to 12) on the MPP: its order is not capped there
                 # (4.2 before auto took adams)
                 "auto": 60.0,
                 "adams": 5e2,   # 159: undamped, rtol 1e-7 (numerical damping, no gain)
                 # 31.6: undamped, rtol 1e-3 (whip_ground 0.32 since its quadratures are
                 # in the error test)
                 "erk": 1e2,
                 "symplectic": SYMPLECTIC_BALANCE_BOUND}
#: G: the energy monitor's default bound (&solver energy_gain_bound), in rtol S
GAIN_BOUND = 10.0
#: B_X: bound on max |tip_a - tip_b| / (rtol L) over AGREE_UNTIL s (per scene, default
#: 1 s) against cvode at the same tolerance; about three times the largest measured
TIP_BOUND = {"mebdf": 25.0,   # 7.7: steel_wire at 1e-3
             "adams": 20.0,   # 6.1: shaken_support at 1e-7
             "erk": 25.0,     # 7.9: steel_wire at 1e-3
             "symplectic": 25.0}
AGREE_UNTIL = {"default": 1.0,
               # the folded falls: up to the end of the fall (0.38 s), where the tension
               # at the tip becomes singular and accurate solutions separate
               "folded_release": 0.3, "folded_n301": 0.3,
               # the whips: up to their crack at 0.556 s (the tip speed peaks, the step
               # halves; over 1 s cvode and mebdf differ by up to 129 rtol L at 1e-7)
               "whip": 0.5, "whip_ground": 0.5, "whip_ground_mpp": 0.5}
#: cases that gain more than G rtol S although every order safety acted: not an order
#: instability (measured gain in rtol S and why)
GAIN_EXCEPTIONS = {
    # CVODE at rtol 1e-3 on the folded fall at n = 301 (0.19 J, 186 rtol S at 0.6 s): the
    # monitor lowers it to BDF2 at 0.38 s (the end of the fall), and the gain then grows
    # steadily over 0.48 ... 0.6 s while the chain rings after the snap. It lies in the
    # dissipated energy (0.34 J against 0.160 J of an rtol 1e-7 run), not in the motion (T
    # + V ends 6 mJ from that run): the dissipation power weighs the velocity errors of the
    # stiffest axial modes (overdamped at dl = 3.3 mm) by tau omega^2, so it grows with the
    # square of the tolerance: BDF2 from the start gains 0.115 J at rtol 1e-3 and 2.0e-3 J
    # at 1e-4; orders 3-5 unguarded 0.025 J; MEBDF at 1e-3 loses 9.5e-4 J. An accuracy
    # limit of rtol 1e-3 on this scene, not an order instability.
    "folded_n301/cvode/0.001": 600.0,
    # CVODE at rtol 1e-5 on the same fall (43 rtol S, 3.6e-4 J at 0.6 s, with the exe of
    # fb831c0): the same snap, chaotic: runs whose only difference is round-off (the
    # RFEM supports' cos and sin from the vectorized pass instead of libm) or rtol moved
    # by 1e-6 .. 1e-5 of itself end with balance errors from 9e-6 to 3.6e-4 J, with and
    # without the order safety acting (it lowered to BDF2 at 0.17 .. 0.53 s in 5 of 8);
    # this case passed before by chance. Here BDF5 is lowered at 0.384 s, and at BDF2
    # the gain grows from 1.8e-5 to 3.6e-4 J over 0.386 .. 0.5 s while the chain rings
    # after the snap, as at 1e-3; BDF2 from the start gains 4.7e-5 J (5.6 rtol S), MEBDF
    # and erk stay below 3 rtol S. An accuracy limit of CVODE through the snap.
    "folded_n301/cvode/1e-05": 60.0,
    # ADAMS at rtol 1e-3 on the lightly damped rope: the monitor watches T + V + dissipated
    # and lowers ADAMS to order 2 when that gains 10 rtol S; T + V alone rose 10.2 rtol S
    # (the dissipated energy rose with it), just past G. Measured, after the safe order.
    "light_damping/adams/0.001": 12.0,
}
#: diagnosed failures the suite accepts: key -> text the reason must contain. The step
#: budget (max_steps 1e6) runs out on the barely damped scenes at rtol 1e-7, at the
#: method's A-stable or explicit order: accuracy-limited, not unstable (the axial modes up
#: to 4.4e3 rad/s, rung by the release and barely damped, are followed by the error
#: test: MEBDF's steps per second on light_damping 2.0e4, 6.5e4, 1.6e5 at rtol 1e-3, 1e-5,
#: 1e-7, the rtol^(-1/5) of order 4; 10 s would need 1.6e6 steps). Raise max_steps, or
#: use cvode (580 000 steps for 10 s at 1e-7), for such runs.
ACCEPTED_FAILURES = {
    "undamped/mebdf/1e-07": "max_steps exceeded",              # at 6.29 s, h 4.7e-6 s
    "light_damping/mebdf/1e-07": "max_steps exceeded",         # at 6.30 s, h 4.5e-6 s
    "mpp_undamped/mebdf/1e-07": "max_steps exceeded",          # at 8.19 s, h 3.6e-6 s
    "mpp_light_damping_n30/mebdf/1e-07": "max_steps exceeded",  # at 8.24 s, h 5.3e-6 s
    "undamped/erk/1e-07": "max_steps exceeded",                # at 9.71 s, h 7.3e-6 s
    "light_damping/erk/1e-07": "max_steps exceeded",           # at 9.70 s, h 8.9e-6 s
    # the runaway rule: it gained 0.19 m g L (180 rtol S) by 0.6 s before the rule existed
    "folded_n301/cvode/0.001": "more than a tenth of the run's energy scale",  # at 0.55 s
}
#: the explicit methods give up on stiff scenes: the reason names the cause and the
#: implicit methods ('mebdf'), within STIFF_STOP_CPU seconds
#: (the symplectic method names the tolerance instead when its step is held by accuracy
#: far below its stable step: ropedyn_symplectic_steps, too_stiff)
STIFF_STOP = {"erk": ("too stiff for an explicit method",),
              "adams": ("the problem is stiff here",),
              "symplectic": ("too stiff for an explicit method", ") asks for steps of ")}


def stiff_diagnosis(key, reason):
    """The reason is the crawl watch's diagnosis of the key's method."""
    return any(words in reason for words in STIFF_STOP.get(case_method(key), ()))
#: problems a method refuses as bad input (exit 2, no file), with the text its message must
#: contain: the symplectic method needs the force split (no MPP, no water, no ground
#: contact, no point mass off an element's centre)
REFUSED = {"symplectic": "cannot integrate the"}
STIFF_STOP_CPU = 10.0   # measured at most 2.1 s (adams on elements_10000)
#: balance and gain bound, in rtol S, of a run the stiffness watch stopped: held at its
#: stability limit the explicit method may amplify the fastest modes until the watch acts,
#: within the first microseconds, whose energy scale S is tiny (measured: adams 569 rtol S
#: on elements_10000 at rtol 1e-3 over 16 us, erk 209 over 17 us)
STIFF_STOP_BOUND = 2e3
#: known defects, diagnosed but not fixed: {test: {key: why}}; these cases are expected to
#: fail that test (strict: a fix makes them pass, and the entry must go)
KNOWN_DEFECTS = {}
# (ERK's dissipated energy at impacts was one: integrated from g at the step points only,
# outside the error test, it missed 1 % of the dissipation on whip_ground, up to 10852
# rtol S; now integrated with the pair's stages and error test.)


MATRIX = lh.matrix_cases()
ORDER = lh.order_cases()
ENERGY = lh.energy_cases()
#: the symplectic method's balance error, m g L, at every record of the 300 s runs
SYMPLECTIC_ENERGY_BOUND = 1e-3


@pytest.fixture(scope="module")
def results(ropedyn_exe):
    return lh.run_all(ropedyn_exe, MATRIX + ORDER + ENERGY, lh.default_workdir())


def diagnosis_ok(r):
    return (r["returncode"] == 3 and r.get("status") == "failed"
            and "t =" in r["reason"] and "step size" in r["reason"])


def refused(key, r):
    """The case's method refused its scene as bad input: exit 2, no file, the reason."""
    return (r.get("status") == "refused" and r["returncode"] == 2
            and REFUSED.get(case_method(key), "\0") in r["reason"])


def skip_refused(key, r):
    """A refused case has no run to measure (test_completes_or_diagnosed checks it)."""
    if r.get("status") == "refused":
        pytest.skip(f"{key}: refused ({r['reason'][:80]})")


def case_method(key):
    return key.split("/")[1]


def stiff_stop(key, r):
    """The run was ended by an explicit method's stiffness watch."""
    return (r["returncode"] == 3 and case_method(key) in STIFF_STOP
            and stiff_diagnosis(key, r.get("reason", "")))


def rope_length(scene):
    m = re.search(r"^\s*&rope[^/]*length\s*=\s*([0-9.eE+-]+)",
                  (lh.HARD / f"{scene}.nml").read_text(), re.M)
    return float(m.group(1)) if m else 1.0


KEYS = [key for key, _, _ in MATRIX]


def keys_for(test):
    """KEYS, those with a known defect in `test` marked as expected failures (strict)."""
    defects = KNOWN_DEFECTS.get(test, {})
    return [pytest.param(k, marks=pytest.mark.xfail(reason=defects[k], strict=True))
            if k in defects else k for k in KEYS]


@pytest.mark.parametrize("key", KEYS)
def test_completes_or_diagnosed(results, key):
    r = results[key]
    assert "status" in r, r["outcome"]
    if r["status"] == "refused":
        assert refused(key, r), (r["returncode"], r["stderr"])
        print(f"{key}: {r['reason']}")
        return
    if r["returncode"] == 0:
        assert r["status"] == "complete"
        assert r["t_reached"] == pytest.approx(r["t_end"], rel=1e-12)
    else:
        assert diagnosis_ok(r), (r["returncode"], r["stderr"])
        print(f"{key}: {r['reason']} ({r['steps']} steps, {r['cpu_time']:.1f} s)")
        if key in ACCEPTED_FAILURES:
            assert ACCEPTED_FAILURES[key] in r["reason"]
        elif case_method(key) in STIFF_STOP:
            assert stiff_diagnosis(key, r["reason"]) and "'mebdf'" in r["reason"]
            assert r["cpu_time"] <= STIFF_STOP_CPU
        else:
            pytest.fail(f"{key}: a failure the suite does not know: {r['reason']}")


@pytest.mark.parametrize("key", KEYS)
def test_output_finite(results, key):
    assert results[key].get("nonfinite") == []


@pytest.mark.parametrize("key", keys_for("balance"))
def test_energy_balance(results, key):
    r = results[key]
    skip_refused(key, r)
    bound = STIFF_STOP_BOUND if stiff_stop(key, r) else BALANCE_BOUND[r["method"]]
    print(f"{key}: balance {r['balance_ratio']:.3g} rtol S (bound {bound})")
    assert r["balance_ratio"] <= bound


@pytest.mark.parametrize("key", keys_for("gain"))
def test_no_energy_gain(results, key):
    r = results[key]
    skip_refused(key, r)
    print(f"{key}: largest gain {r['max_gain_ratio']:.3g} rtol S")
    if stiff_stop(key, r):
        assert r["max_gain_ratio"] <= STIFF_STOP_BOUND
        return
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
        assert ratio <= TIP_BOUND[other["method"]]


def order_result(results, scene, label):
    return results[f"order/{scene}/{label}"]


@pytest.mark.parametrize("scene", ["undamped", "light_damping"])
def test_mebdf_7_starts_at_its_safe_order(results, scene):
    """MEBDF at order 7 gained on both ropes (undamped: 39 rtol S in 10 s unguarded; the
    lightly damped one 7.7e-4 m g L by 18.3 s at rtol 1e-4, n = 20, before the monitor
    acted): their fast modes are lightly damped, and it now starts at order 4."""
    for label in ("mebdf 7, off", "mebdf 7, lower"):
        r = order_result(results, scene, label)
        print(f"{scene}: {label}: orders {r['orders']}, gain {r['max_gain_ratio']:.3g} rtol S")
        assert r["status"] == "complete" and max(r["orders"]) <= 4
        assert r["max_gain_ratio"] <= GAIN_BOUND


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


@pytest.mark.parametrize("scene", lh.ENERGY_SCENES)
def test_energy_over_300_s(results, scene):
    """Every method and auto to 300 s at rtol 1e-3 (the table of docs/validation/energy.md,
    "Energy over 300 s"): each completes; the symplectic method's balance error stays within
    SYMPLECTIC_ENERGY_BOUND m g L at every record (bounded: the adaptive methods' drifts)."""
    for method in lh.METHODS + ["auto"]:
        r = results[f"energy/{scene}/{method}"]
        at = r.get("drift_mgl_at", {})
        print(f"{scene} {method}: B - E0 at 30 s {at.get('30', float('nan')):+.2e}, "
              f"at 300 s {at.get('300', float('nan')):+.2e} m g L; {r['outcome'][:60]}")
        assert r["returncode"] == 0 and r["status"] == "complete", r["outcome"]
    r = results[f"energy/{scene}/symplectic"]
    assert r["max_drift_mgl_to"]["300"] <= SYMPLECTIC_ENERGY_BOUND
