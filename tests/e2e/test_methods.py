"""The explicit and switching methods end to end (issue 15): erk and adams integrate the
paper's rope like cvode does; auto records its choice in /solver/switch_* and the summary,
picks the explicit method for the soft rope and the implicit one for a steel wire."""
import re

import h5py
import numpy as np
import pytest

from ropedyn_tools.studies.cost_model import auto_parameter

ROOT = __import__("pathlib").Path(__file__).resolve().parents[2]
PAPER = ROOT / "input" / "paper.nml"
STEEL = ROOT / "input" / "hard" / "steel_wire.nml"
LIGHT = ROOT / "input" / "hard" / "light_damping.nml"
SHAKEN = ROOT / "input" / "hard" / "shaken_support.nml"
#: the light damping of input/hard/light_damping.nml (N s/m^2)
LIGHT_DAMPING = ("rope.normal_damping=0.1", "rope.tangential_damping=0.04")
#: the paper rope's m g L (J): 6000 kg/m3, 5 mm diameter, 1 m
MGL = 6000 * np.pi * 0.005 ** 2 / 4 * 9.81


def switch_log(f):
    """The run's switches from /solver (open h5py file): methods, times, order limits,
    reasons."""
    methods = [m.decode().strip() for m in f["/solver/switch_method"][()]]
    reasons = [r.decode() for r in f["/solver/switch_reason"][()]]
    return methods, f["/solver/switch_time"][()], f["/solver/switch_max_order"][()], reasons


def run_scene(run, tmp_path, scene, name, *sets):
    out = tmp_path / f"{name}.h5"
    args = ["run", scene, "--set", f"output.file='{out}'"]
    for s in sets:
        args += ["--set", s]
    proc = run(*args)
    return proc, out



@pytest.mark.parametrize("method", ["erk", "adams", "auto", "symplectic"])
def test_method_agrees_with_cvode(run, tmp_path, method):
    """0.3 s of the paper's rope at n = 8: the energy balance closes and the state agrees
    with cvode at rtol 1e-8 to well within the tolerance's reach (1e-4 of the rope's 1 m)."""
    common = ["model.elements=8", "solver.t_end=0.3", "solver.output_interval=0.05",
              "solver.rtol=1e-8", "solver.atol=1e-10"]
    ref, ref_out = run_scene(run, tmp_path, PAPER, "cvode", "solver.method='cvode'", *common)
    assert ref.returncode == 0, ref.stderr
    proc, out = run_scene(run, tmp_path, PAPER, method, f"solver.method='{method}'", *common)
    assert proc.returncode == 0, proc.stderr
    with h5py.File(ref_out, "r") as a, h5py.File(out, "r") as b:
        qa, qb = a["/state/q"][()], b["/state/q"][()]
        assert qa.shape == qb.shape
        assert np.max(np.abs(qa - qb)) < 1e-4
        assert b["/solver/steps"][()] > 0 and b["/solver/rhs_evals"][()] > 0
    assert "balance error" in proc.stdout


def test_auto_goes_symplectic_where_the_fast_modes_are_lightly_damped(run, tmp_path):
    """The undamped rope (n = 8, rtol 1e-3, 6 s): auto starts the symplectic method, says
    why in the switch log, names it in the summary, and its energy balance stays within 1e-4 m g L (erk's
    drifts past 1e-3 m g L by then); the paper's damped rope at n = 20 stays with erk and
    mebdf. (At n = 8 the slowest of the damped rope's fast modes are damped by less than 1 %,
    and auto takes the symplectic method there too.)"""
    proc, out = run_scene(run, tmp_path, PAPER, "undamped", "model.elements=8",
                          "effects.damping=.false.", "solver.rtol=1e-3", "solver.atol=1e-5",
                          "solver.t_end=6", "solver.output_interval=0.05")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(out, "r") as f:
        methods, _, orders, reasons = switch_log(f)
        total = f["/energy/total"][()]
    assert methods[0] == "symplectic" and orders[0] == 4, (methods, reasons)
    assert "lightly damped" in reasons[0], reasons
    assert "auto: symplectic 4 (" in proc.stdout, proc.stdout   # the step event is no switch
    assert np.max(np.abs(total - total[0])) < 1e-4 * MGL
    proc, out = run_scene(run, tmp_path, PAPER, "damped", "model.elements=20",
                          "solver.rtol=1e-3", "solver.atol=1e-5", "solver.t_end=6",
                          "solver.output_interval=0.05")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(out, "r") as f:
        methods, _, _, reasons = switch_log(f)
    assert "symplectic" not in methods, (methods, reasons)


def test_auto_leaves_the_symplectic_method_out_when_the_budget_is_short(run, tmp_path):
    """The undamped rope of the test above: with a step budget below what the symplectic
    method's step takes to t_end, auto goes on with its other methods and warns once, naming
    the steps and the budget to add; when the budget runs out later, the message ends with
    that diagnosis. With the budget raised as it says, auto goes symplectic and finishes."""
    common = ["model.elements=8", "effects.damping=.false.", "solver.rtol=1e-3",
              "solver.atol=1e-5", "solver.t_end=6", "solver.output_interval=0.05"]
    proc, out = run_scene(run, tmp_path, PAPER, "full", *common)
    assert proc.returncode == 0, proc.stderr
    with h5py.File(out, "r") as f:
        assert switch_log(f)[0][0] == "symplectic"
        taken = int(f["/solver/steps"][()])
    budget = taken * 5 // 8
    proc, out = run_scene(run, tmp_path, PAPER, "short", *common,
                          f"solver.max_steps={budget}")
    with h5py.File(out, "r") as f:
        methods, _, _, reasons = switch_log(f)
    assert "symplectic" not in methods, (methods, reasons)
    warning = re.findall(r"^ropedyn: warning: at t = +0\.0000 s: the symplectic method would "
                         r"keep the energy bounded .* takes about (\d+) of its steps .* more than the "
                         rf"{budget} that max_steps leaves: raise solver\.max_steps by (\d+) "
                         r"to use it$", proc.stderr, re.MULTILINE)
    assert len(warning) == 1, proc.stderr
    needed, more = (int(x) for x in warning[0])
    assert 0.97 * taken <= needed <= taken
    # erk and MEBDF take fewer steps than the symplectic method here but not few enough
    assert proc.returncode == 3, proc.stderr
    error = proc.stderr.strip().splitlines()[-1]
    # (the run's budget, not what was left of it for the method that spent it)
    assert f"max_steps exceeded ({budget} steps)" in error, error
    assert "the run had diagnosed at t = 0.000E+00 s: the symplectic method would keep the " \
        "energy bounded" in error, error
    proc, out = run_scene(run, tmp_path, PAPER, "raised", *common,
                          f"solver.max_steps={budget + more}")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(out, "r") as f:
        assert switch_log(f)[0][0] == "symplectic"


def test_auto_goes_symplectic_where_erk_costs_more_than_predicted(run, tmp_path):
    """The lightly damped rope of input/hard (n = 30, rtol 1e-6) over 6 s: at the start
    the symplectic method costs more than four times erk's predicted cost (erk at its stable
    step), so auto starts erk; but erk's steps are held by accuracy, and its measured cost
    after its second window is higher than the symplectic method's by more than the
    hysteresis: auto switches, says why, and the rest of the run costs less per simulated
    second than erk did, with its energy balance within 10 rtol m g L."""
    proc, out = run_scene(run, tmp_path, LIGHT, "auto", "solver.t_end=6",
                          "solver.output_interval=0.05")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(out, "r") as f:
        methods, times, _, reasons = switch_log(f)
        evals = int(f["/solver/rhs_evals"][()])
        balance = f["/energy/total"][()] + f["/energy/dissipated"][()]
    assert methods[0] == "erk" and "symplectic" in methods, (methods, reasons)
    k = methods.index("symplectic")
    measured = re.match(r"erk's cost +([0-9.E+-]+) f per second; the fast modes are lightly "
                        r"damped and the symplectic method costs less than erk as measured "
                        r"\(([0-9.]+) times its cost", reasons[k])
    assert measured, reasons[k]
    erk_rate, ratio = float(measured.group(1)), float(measured.group(2))
    assert ratio < 1 / auto_parameter("GAIN"), reasons[k]
    assert set(methods[k:]) == {"symplectic"}, methods      # kept to the end
    # the whole run, erk's start included, against erk's measured rate
    assert evals / 6.0 < erk_rate, (evals, erk_rate)
    assert np.max(np.abs(balance - balance[0])) < 10 * 1e-6 * MGL


def rope_distance(a, b, span):
    """The largest distance (m) between the rope points of two runs' records up to `span`
    seconds (open h5py files with the same output times)."""
    k = int(np.searchsorted(a["/time"][()], span + 1e-9))
    assert np.allclose(a["/time"][:k], b["/time"][:k])
    return float(np.max(np.linalg.norm(a["/rope/points"][:k] - b["/rope/points"][:k],
                                       axis=-1)))


def test_auto_probes_the_symplectic_method_before_taking_it(run, tmp_path):
    """The shaken support of input/hard with light damping, over 6 s: erk's steps are held
    by accuracy and its measured cost is higher than the symplectic method's, but the fixed
    step does not follow the 20 Hz shaking: the probe (the method's error over 400 steps,
    estimated by halving the step) finds more than sqrt(400) = 20 tolerances, and auto keeps
    erk and says why. Over the first 0.5 s auto's rope is then more than 5 times closer to
    cvode at rtol 1e-10 than the symplectic method's (measured: 20 times)."""
    common = ["solver.output_interval=0.01", *LIGHT_DAMPING]
    proc, out = run_scene(run, tmp_path, SHAKEN, "auto", "solver.t_end=6", *common)
    assert proc.returncode == 0, proc.stderr
    with h5py.File(out, "r") as f:
        methods, times, _, reasons = switch_log(f)
    refused = [k for k, r in enumerate(reasons) if "symplectic method would be used" in r]
    assert refused, reasons
    k = refused[0]
    found = re.search(r"its error over 400 steps of +[0-9.E+-]+ s from t = +[0-9.E+-]+ s, "
                      r"estimated by halving the step, is +([0-9.E+-]+) tolerances, more "
                      r"than +20\.0", reasons[k])
    assert found and float(found.group(1)) > 20, reasons[k]
    assert "symplectic" not in methods[:k], methods
    assert methods[k] == "erk" and times[k] < 0.5, (methods, times)
    after = [t for m, t in zip(methods, times) if m == "symplectic"]
    assert not after or min(after) > 0.5, (methods, times)
    ref_proc, ref = run_scene(run, tmp_path, SHAKEN, "ref", "solver.method='cvode'",
                              "solver.rtol=1e-10", "solver.atol=1e-12", "solver.t_end=0.5",
                              *common)
    assert ref_proc.returncode == 0, ref_proc.stderr
    sym_proc, sym = run_scene(run, tmp_path, SHAKEN, "sym", "solver.method='symplectic'",
                              "solver.t_end=0.5", *common)
    assert sym_proc.returncode == 0, sym_proc.stderr
    with h5py.File(ref, "r") as r, h5py.File(out, "r") as a, h5py.File(sym, "r") as s:
        auto_error, sym_error = rope_distance(a, r, 0.5), rope_distance(s, r, 0.5)
    assert 5 * auto_error < sym_error, (auto_error, sym_error)


def test_the_default_budget_grows_with_the_run(run, tmp_path):
    """A scene that names no max_steps has a budget that grows with t_end (`ropedyn keys`
    states the rule): the undamped 4-element rope over 2000 s takes more symplectic steps
    than the budget's floor, and auto still takes the method, without a warning, and
    finishes with its energy bounded. (With the floor alone, auto would leave the method
    out and drift: test_auto_leaves_the_symplectic_method_out_when_the_budget_is_short.)"""
    keys = run("keys")
    assert keys.returncode == 0, keys.stderr
    rule = re.search(r"^solver\tmax_steps\tinteger\t-\t0\t>= 0\tstep budget of a run "
                     r"\(0: (\d+), or (\d+) per second of t_end if more", keys.stdout,
                     re.MULTILINE)
    assert rule, keys.stdout
    floor, rate = (int(x) for x in rule.groups())
    t_end = 2000.0
    assert rate * t_end > floor
    proc, out = run_scene(run, tmp_path, PAPER, "long", "model.elements=4",
                          "effects.damping=.false.", "solver.rtol=1e-3", "solver.atol=1e-5",
                          f"solver.t_end={t_end:g}", "solver.output_interval=10")
    assert proc.returncode == 0, proc.stderr
    assert "warning" not in proc.stderr, proc.stderr
    with h5py.File(out, "r") as f:
        methods, _, _, reasons = switch_log(f)
        steps = int(f["/solver/steps"][()])
        total = f["/energy/total"][()]
    assert set(methods) == {"symplectic"}, (methods, reasons)   # its step events
    assert floor < steps <= rate * t_end, steps
    # the bound of issue 44's target; auto's former erk/MEBDF lose 0.15 m g L over 300 s
    assert np.max(np.abs(total - total[0])) < 1e-3 * MGL


def test_auto_records_its_choice(run, tmp_path):
    proc, out = run_scene(run, tmp_path, PAPER, "auto", "model.elements=8",
                          "solver.t_end=0.2")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(out, "r") as f:
        methods, times, _, reasons = switch_log(f)
    # the soft rope is not stiff for an explicit method: it starts (and stays) explicit;
    # no Adams for the RFEM (f is cheap: CVODE's work per step would outweigh it)
    assert methods[0] == "erk" and times[0] == 0.0
    assert "adams" not in methods
    assert "spectral radius" in reasons[0]
    assert "methods         auto: erk 4" in proc.stdout


def test_auto_starts_implicit_on_the_steel_wire(run, tmp_path):
    proc, out = run_scene(run, tmp_path, STEEL, "steel", "solver.t_end=0.002",
                          "solver.output_interval=0.001")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(out, "r") as f:
        methods, _, orders, _ = switch_log(f)
    assert methods[0] == "mebdf" and orders[0] == 4   # barely damped fast modes: A-stable


def test_auto_starts_implicit_on_a_rope_at_rest(run, tmp_path):
    """The catenary hangs at rest in its equilibrium: erk's step is held by stability
    (4.6e-5 s) while a first-order step within the tolerance is 13 times longer, and auto
    starts with the implicit method instead of spending a window of explicit steps: CVODE,
    since its fast modes are damped by 45 %, above the 12 % from which BDF's higher orders
    are safe (docs/guide/choosing.md); it takes a handful of steps for the 3 s (erk: 6e4).
    A rope released from rest (the paper's, test_auto_records_its_choice) starts explicit."""
    proc, out = run_scene(run, tmp_path, ROOT / "input" / "catenary.nml", "catenary")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(out, "r") as f:
        methods, times, orders, reasons = switch_log(f)
        steps = int(f["/solver/steps"][()])
    assert methods == ["cvode"] and times[0] == 0.0 and orders[0] == 5, (methods, reasons)
    assert "fast modes damped >=  0.450" in reasons[0], reasons
    assert "first-order step" in reasons[0] and "too slow for explicit steps" in reasons[0]
    assert steps < 100, steps


@pytest.mark.parametrize("interval, switch_before", [(None, 0.07), ("0.2", 0.12), ("1.0", 0.12)])
def test_auto_tries_implicit_early_where_erk_sits_at_its_stable_step(run, tmp_path, interval,
                                                                     switch_before):
    """drag_fall: a rope falling flat through water excites none of its fast modes, so
    erk's estimate of the spectral radius from its last stages (1e2 .. 3e3 1/s) misses
    them, yet its steps sit at the stable step of the Jacobian's spectrum (5.1e3 1/s,
    9.0e-4 s) from the start. auto counts those steps as held by stability and tries
    mebdf after its first 50 steps, at 0.05 s (after 400 steps it came at 0.77 s, with
    849 steps in all; after 100 at 0.1 s, and the share was erk's own, which waits for 51
    steps: with a look after 50 the switch still came at 0.06 s); mebdf is kept (its trial
    pays) and takes the remaining 1.95 s in about 100 steps.
    Whatever the output interval: before a method's first step auto's chunk was sized from
    nothing and ran to the next output time, so with outputs every 1 s the first look (and
    the switch) came at 1.0 s, 1,088 steps. The first chunk is now sized from the stable
    step h_e (after a switch, from the previous method's last step): with outputs 0.2 or
    1 s apart the switch comes at the first look after 50 steps, near 0.09 s (its chunk is
    about 100 steps; after 100 steps it came at 0.19 s), in the same steps."""
    sets = [f"solver.output_interval={interval}"] if interval else []
    proc, out = run_scene(run, tmp_path, ROOT / "input" / "drag_fall.nml", "drag_fall", *sets)
    assert proc.returncode == 0, proc.stderr
    with h5py.File(out, "r") as f:
        methods, times, _, reasons = switch_log(f)
        steps = int(f["/solver/steps"][()])
    assert methods == ["erk", "mebdf"], (methods, reasons)
    assert times[1] < switch_before, (times, reasons)
    assert "held by stability" in reasons[1], reasons
    assert steps < 220, steps


def test_auto_does_not_try_mebdf_early_on_the_mpp(run, tmp_path):
    """The early trial above is for problems without a mass matrix. On the MPP at rtol
    1e-2 erk's steps sit at the stable step too, but an MEBDF step there (M(q) in its
    residual, a dense Newton matrix) costs so much more that the trial is no cheap
    experiment: with it, the 0.5 s windows of docs/validation/accuracy.md went to mebdf at once
    and cost 7 to 11 times erk's. Here (n = 30, 0.5 s) auto stays explicit."""
    proc, out = run_scene(run, tmp_path, ROOT / "input" / "paper.nml", "mpp_loose",
                          "model.kind='mpp'", "model.elements=30", "solver.rtol=1e-2",
                          "solver.atol=1e-4", "solver.t_end=0.5")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(out, "r") as f:
        methods, times, _, reasons = switch_log(f)
    assert "mebdf" not in methods, (methods, times, reasons)


def test_auto_tries_the_implicit_method_again_when_its_cost_is_stale(run, tmp_path):
    """The steel wire: mebdf's cost is measured in the ringing after the release (steps
    of 1e-6 s, 2e7 f per second at 0.4 ms; 9.2e6 at 5.4 ms when its first window ran to
    the first output), and auto rightly goes to erk (0.7e6). mebdf's steps later grow to
    4e-5 s (2.3e5 f per second on its own run), but that old measurement kept it out for
    the whole run: erk to the end, 0.54 s CPU against mebdf's 0.36 .. 0.41. Now a cost
    measured 32 explicit windows ago (that many times, at least twice, the cost ratio of
    each trial that does not pay) is tried again where erk's steps are held by stability;
    the trials are few (one not cheaper yet at 0.077 s), and mebdf takes over (from
    0.27 s)."""
    proc, out = run_scene(run, tmp_path, STEEL, "stale", "solver.t_end=0.7")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(out, "r") as f:
        methods, times, _, reasons = switch_log(f)
    assert methods[:2] == ["mebdf", "erk"], (methods, reasons)
    again = [r for r in reasons if "trying mebdf again" in r]
    assert again, reasons
    assert len(again) <= 5, reasons      # growing waits: a few trials, not one a window
    assert methods[-1] == "mebdf", (methods, times, reasons)
    # the waits: 32 windows at first; after the trial that did not pay (8.8e5 against
    # 6.7e5 f per second, ratio 1.3) max(2, ceil(1.3)) = 2 times that
    ages = [int(re.search(r"measured (\d+) windows ago", r).group(1)) for r in again]
    stale = auto_parameter("STALE_WINDOWS")   # explicit windows a measured cost counts for
    assert stale <= ages[0] < 2 * stale, (ages, reasons)
    assert len(ages) >= 2 and ages[1] >= 2 * stale, (ages, reasons)


def test_no_retrial_of_mebdf_on_the_mpp(run, tmp_path):
    """The MPP at n = 30, rtol 1e-2, 30 s: the trial of mebdf at 0.53 s costs 6.3 times
    erk's (4.0e4 against 6.4e3 f per second: the dense Newton matrix). The staleness rule,
    waits doubling, brought a retrial at 26.6 s that cost as much again (on fig4's MPP
    runs at n = 200 .. 300 several, doubling their CPU). Two rules keep it out now: the
    wait grows by the trial's cost ratio, and stale-cost retrials are only for problems
    without a mass matrix. Here either alone suffices (the test fails with neither); the
    second alone is what keeps fig4's n = 200 and 300 at their old cost, too slow a run for
    this suite."""
    proc, out = run_scene(run, tmp_path, PAPER, "mpp_dear", "model.kind='mpp'",
                          "model.elements=30", "solver.rtol=1e-2", "solver.atol=1e-4")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(out, "r") as f:
        methods, times, _, reasons = switch_log(f)
    failed = [r for r in reasons if "mebdf was not cheaper" in r]
    assert failed, (methods, reasons)
    costs = re.findall(r"\( *([0-9.E+-]+) against +([0-9.E+-]+)", failed[0])[0]
    a, b = (float(x) for x in costs)
    assert a > 3 * b, failed[0]
    assert not [r for r in reasons if "trying mebdf again" in r], (methods, times, reasons)


def test_erk_on_the_steel_wire_within_the_guarantee_or_diagnosed(run, tmp_path):
    """The stiff wire: erk either completes within the step guarantee of the hard scenes
    (2e5 steps per simulated second) or, held by stability above it, gives up quickly with
    a diagnosis naming the implicit methods."""
    t_end = 0.2
    proc, out = run_scene(run, tmp_path, STEEL, "erk", "solver.method='erk'",
                          f"solver.t_end={t_end}")
    if proc.returncode == 0:
        with h5py.File(out, "r") as f:
            steps = int(f["/solver/steps"][()])
        assert steps <= 2e5 * t_end, steps
    else:
        assert proc.returncode == 3, proc.stderr
        assert "erk failed" in proc.stderr and "mebdf" in proc.stderr


def test_cvode_logs_its_start_at_the_start_of_the_run(run, tmp_path):
    """The steel wire with cvode: the crawl watch tries order 2 at 0.0094 s, its first
    change, and the log gets the order limit the run started with in front of it. That
    entry is at the run's start (t = 0), not at the start of the window that held the
    trial (0.0088 s: the limit of 5 was in force from t = 0)."""
    proc, out = run_scene(run, tmp_path, STEEL, "cvode", "solver.method='cvode'",
                          "solver.t_end=0.012")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(out, "r") as f:
        methods, times, orders, reasons = switch_log(f)
    assert len(times) >= 2 and "trying max order 2" in reasons[1], reasons
    assert (methods[0], orders[0], reasons[0].strip()) == ("cvode", 5, "start"), reasons
    assert times[0] == 0.0 and times[1] > 0.005, times


def test_auto_takes_cvode_where_the_fast_modes_are_damped(run, tmp_path):
    """n = 1000: the fastest modes are damped by far more than 12 % (the segment damping
    ratio grows with n); the A-stable MEBDF order 4 is not needed for them, and auto's
    implicit method is cvode (a cheaper step), not mebdf."""
    scene = ROOT / "input" / "hard" / "elements_1000.nml"
    proc, out = run_scene(run, tmp_path, scene, "n1000", "solver.t_end=1e-4",
                          "solver.output_interval=1e-4")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(out, "r") as f:
        methods, _, orders, _ = switch_log(f)
    assert methods[0] == "cvode" and orders[0] == 5


def test_auto_tries_adams_where_the_explicit_step_is_held_by_accuracy(run, tmp_path):
    """The lightly damped MPP (n = 10): erk's steps are held by accuracy, not stability, and
    f is costly; auto tries adams, keeps it (it needs about a quarter of the evaluations),
    and the run agrees with cvode at a tight tolerance."""
    scene = ROOT / "input" / "hard" / "mpp_light_damping.nml"
    common = ["solver.t_end=1.0", "solver.output_interval=0.1"]
    proc, out = run_scene(run, tmp_path, scene, "auto", *common)
    assert proc.returncode == 0, proc.stderr
    with h5py.File(out, "r") as f:
        methods, _, _, reasons = switch_log(f)
        q = f["/state/q"][()]
    assert methods[:2] == ["erk", "adams"], methods
    assert "held by accuracy" in reasons[1]
    ref, ref_out = run_scene(run, tmp_path, scene, "cvode", "solver.method='cvode'",
                             "solver.rtol=1e-9", "solver.atol=1e-11", *common)
    assert ref.returncode == 0, ref.stderr
    with h5py.File(ref_out, "r") as f:
        assert np.max(np.abs(f["/state/q"][()] - q)) < 1e-3


def test_auto_tries_adams_again_when_its_cost_is_stale(run, tmp_path):
    """The undamped MPP (n = 30): the first trial of adams, 0.04 s at 0.07 s, is not cheaper
    by GAIN and sends auto back to erk. That cost is evidence for STALE_WINDOWS explicit
    windows times the trial's cost ratio (at least 2), as the implicit method's: then the
    next window held by accuracy tries adams again (before, one trial decided the whole
    run: the Bergdahl chain's MPP ran erk to the end after a trial in its first cycle)."""
    scene = ROOT / "input" / "hard" / "mpp_undamped.nml"
    proc, out = run_scene(run, tmp_path, scene, "auto", "solver.t_end=2.6")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(out, "r") as f:
        methods, _, _, reasons = switch_log(f)
    first = next(i for i, r in enumerate(reasons) if "adams was not cheaper" in r)
    again = [r for r in reasons[first:] if "trying adams again" in r]
    assert again, (methods, reasons)
    age = int(re.search(r"measured (\d+) windows ago", again[0]).group(1))
    stale = auto_parameter("STALE_WINDOWS")
    assert 2 * stale <= age < 3 * stale, (age, reasons)


#: A rigid, stiff two-rod MPP pendulum (EA 1e7, EI 1e4, the joint's stiff modes damped,
#: swinging 1 degree), at a tight tolerance: erk's step is held by accuracy in the ringing
#: of the release and by the stiff modes' stability after it.
STIFF_PENDULUM = """&rope length = 1.0, mass_per_length = 0.5, axial_stiffness = 1.0e7,
      bending_stiffness = 1.0e4, axial_damping = 1.0e3, bending_damping = 5.0 /
&model kind = 'mpp', elements = 2 /
&supports top = 'pinned', bottom = 'free' /
&initial shape = 'straight', angle_deg = 1.0 /
&solver t_end = 2.0, output_interval = 0.001, rtol = 1e-9, atol = 1e-12 /
"""


def test_auto_measures_erk_again_when_adams_runs_long(run, tmp_path):
    """The stiff pendulum: erk's cost in the release's ringing (3.2e5 f per second over
    its first 0.007 s) sends auto to adams, whose steps the stiff modes then hold (11 % of
    them failed their error test). That first cost kept adams to the end: 6 s took 255,612
    evaluations of f, against 136,506 for erk alone and 1,585 for cvode. erk's cost is
    evidence for STALE_WINDOWS windows of the accuracy method, as for the order-5 pair;
    then erk runs again, finds its steps held by stability, and auto goes implicit.
    Counted work, not time: auto's evaluations of f stay below erk's own run's."""
    scene = tmp_path / "stiff_pendulum.nml"
    scene.write_text(STIFF_PENDULUM)
    proc, out = run_scene(run, tmp_path, scene, "auto")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(out, "r") as f:
        methods, _, _, reasons = switch_log(f)
        evals = int(f["/solver/rhs_evals"][()])
        q = f["/state/q"][()]
    assert methods[:2] == ["erk", "adams"], (methods, reasons)
    again = [i for i, r in enumerate(reasons) if "measuring it again" in r]
    assert again, (methods, reasons)
    k = again[0]
    age = int(re.search(r"measured (\d+) windows ago", reasons[k]).group(1))
    assert methods[k] == "erk" and age == auto_parameter("STALE_WINDOWS"), (age, reasons)
    assert methods[-1] in ("cvode", "mebdf"), (methods, reasons)
    proc, erk_out = run_scene(run, tmp_path, scene, "erk", "solver.method='erk'")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(erk_out, "r") as f:
        assert evals < int(f["/solver/rhs_evals"][()]), evals
        assert np.max(np.abs(f["/state/q"][()] - q)) < 1e-6


def test_erk_rejects_few_steps_where_stability_holds_them(run, tmp_path):
    """The paper's rope with erk at rtol 1e-2 (5 s): the step is held by stability (h rho
    near RK4's limit). With Gustafsson's PI gains there the controller cycled into the
    unstable region and back: 12.2 % of the steps rejected, 4.49 evaluations of f per
    step; with the gains for stability-held steps (K_I_STABLE, K_P_STABLE) 4.4 % and 4.17
    (Debug; Release over 30 s: 4.6 %)."""
    proc, out = run_scene(run, tmp_path, PAPER, "erk", "solver.method='erk'",
                          "solver.rtol=1e-2", "solver.atol=1e-4", "solver.t_end=5.0",
                          "solver.output_interval=0.1")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(out, "r") as f:
        steps = int(f["/solver/steps"][()])
        fails = int(f["/solver/err_test_fails"][()])
        evals = int(f["/solver/rhs_evals"][()])
    print(f"steps {steps}, rejected {fails / steps:.3f}, f per step {evals / steps:.2f}")
    assert fails < 0.07 * steps, (fails, steps)
    assert evals < 4.3 * steps, (evals, steps)


#: The whip on the ground with the friction regularized over 1 cm/s instead of the scene's
#: 1 mm/s. At 1 mm/s the struck tip sticks, and the friction's viscous rate there,
#: mu F_N / (v_reg m), about 3e6 1/s, is beyond an explicit method: erk stops at t = 0.556 s
#: with its diagnosis (too stiff; use auto or mebdf), and auto finishes.
WHIP_GROUND_SLIDING = "ground.friction_regularization_speed=1e-2"


def test_erk_resolves_the_ground_contact(run, tmp_path):
    """The whip hitting the ground (RFEM, n = 30, WHIP_GROUND_SLIDING), 1 s at rtol 1e-6:
    erk's rope stays within 2e-4 m of cvode at rtol 1e-10 (measured 9e-7 m). With the
    classical RK4 pair, whose error estimate h (k4 - k5)/6 looks only at the end of the
    step, the contact's kinks went unseen and the rope ended 4.6e-3 m away (the floor's law
    then at fixed Gauss points); the 3/8-rule pair's estimate uses every stage."""
    scene = ROOT / "input" / "hard" / "whip_ground.nml"
    common = ["solver.t_end=1.0", "solver.output_interval=0.02", WHIP_GROUND_SLIDING]
    proc, out = run_scene(run, tmp_path, scene, "erk", "solver.method='erk'",
                          "solver.rtol=1e-6", "solver.atol=1e-8", *common)
    assert proc.returncode == 0, proc.stderr
    ref, ref_out = run_scene(run, tmp_path, scene, "cvode", "solver.method='cvode'",
                             "solver.rtol=1e-10", "solver.atol=1e-12", *common)
    assert ref.returncode == 0, ref.stderr
    with h5py.File(out, "r") as a, h5py.File(ref_out, "r") as b:
        d = rope_distance(a, b, 1.0)
    assert d < 2e-4, d


def test_auto_looks_at_erk_whose_steps_collapse_within_a_chunk(run, tmp_path):
    """auto runs the method in use in chunks sized by time, from its last step. Here (a
    9.6 m rope started straight 6 m into the ground, drawn by scripts/random_scenes run
    --seed 1, reduced) auto leaves cvode for erk at 0.8 ms, at the stable step the
    spectrum then gives (9e-4 s: the rope is thrown out, its contact springs loose), and
    erk's steps collapse to 1e-9 s within its first chunk as the contact takes hold again.
    Unlooked-at, that chunk spent the whole step budget (here 20,000; the default million
    on 0.5 ms); with the chunk cut once its window is 10 windows overdue, auto goes back
    to the implicit method at 1.5 ms and finishes in about 11,000 steps."""
    from ropedyn_tools.random_scenes import section_scene
    scene = section_scene(tmp_path)
    proc, out = run_scene(
        run, tmp_path, scene, "collapse", "model.elements=10",
        "rope.length=9.64036590025285", "initial.angle_deg=-42.12530433268766",
        "effects.ground=.true.", "attachments.mass_positions=7.284", "attachments.masses=1.06",
        "attachments.load_positions=7.229", "solver.atol=5.8702700181086224e-08",
        "solver.t_end=0.2", "rope.mass_per_length=0.04952459064448364",
        "rope.axial_stiffness=1625.985876986998", "rope.bending_stiffness=0.0",
        "solver.max_steps=20000")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(out, "r") as f:
        methods, times, _, _ = switch_log(f)
    # the scene still shows what the test is about: erk taken early, then left early
    erk = methods.index("erk")
    assert times[erk] < 2e-3 and methods[erk + 1] != "erk" and times[erk + 1] < 3e-3, \
        list(zip(methods, times))


def test_auto_keeps_erk_on_the_paper_rope(run, tmp_path):
    """The paper's rope at rtol 1e-6: erk's step is held by accuracy (about a third of its
    stable step), so auto runs erk throughout: the order-4 pair, and the order-5 pair where
    it tries that for the steps held by accuracy (which on this rope are held by the
    order-5 pair's shorter stable step on the imaginary axis, and it goes back), never
    mebdf. Guards erk's spectral estimate, which decides 'held by stability': a stage
    combination of the 3/8 pair that weighs positions and velocities otherwise
    (Y5 - 3/2 Y3 + Y1/2) doubled rho there, counted 97 % of the steps as stability-held
    and made auto try mebdf at t = 0.44 s."""
    proc, out = run_scene(run, tmp_path, PAPER, "paper", "solver.t_end=1.0",
                          "solver.output_interval=0.1")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(out, "r") as f:
        methods, _, orders, reasons = switch_log(f)
    assert set(methods) == {"erk"}, reasons
    assert orders[0] == 4, reasons
    for order, reason in zip(orders[1:], reasons[1:]):
        if order == 5:
            assert "held by accuracy" in reason, reasons


def test_auto_weighs_the_dense_newton_matrix_of_the_mpp(run, tmp_path):
    """The MPP at n = 70, rtol 1e-2: erk's step is held by stability, so auto tries MEBDF;
    its Newton matrix is dense (140 rows against the RFEM's band of 11) and its residual
    multiplies by the dense M(q), so a step costs some 40-90 evaluations of erk's f
    (measured with solver.profile). Counted as on the RFEM (6 per step) MEBDF looked
    cheaper and ran on at 4-5x erk's CPU (the accuracy study's miss on the MPP at
    n >= 200: 12-20x); weighed by the matrix's width, the trial is not cheaper and auto
    goes back to erk after it."""
    proc, out = run_scene(run, tmp_path, PAPER, "mpp70", "model.kind='mpp'",
                          "model.elements=70", "solver.t_end=2.5", "solver.rtol=1e-2",
                          "solver.atol=1e-4", "solver.output_interval=0.1")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(out, "r") as f:
        methods, times, _, reasons = switch_log(f)
    assert "mebdf" in methods, methods
    k = methods.index("mebdf")
    assert "held by stability" in reasons[k]
    assert methods[k + 1] == "erk", methods
    assert "mebdf was not cheaper" in reasons[k + 1], reasons[k + 1]
    # the trial's counted cost against erk's (f per second), from the reason's numbers
    counted = [float(x) for x in reasons[k + 1].split("(")[1].split(" f per")[0]
               .split(" against ")]
    assert counted[0] > 3 * counted[1], counted
    assert "mebdf" not in methods[k + 1:], methods


def test_erk_stops_with_a_diagnosis_on_1000_elements(run, tmp_path):
    """1000 elements (modes up to 7.5e5 1/s): erk is held by stability at 2.8e5 steps per
    simulated second, above the hard scenes' 2e5, and must stop after one window (500
    steps, 1.8 ms) with exit code 3 and the full message naming rho and the implicit
    methods. (The message once overran its 160-character buffer: a Fortran runtime error,
    exit code 2, on every such stop: the long-horizon suite's erk runs on elements_1000,
    3000, 10000 and the MPP whip on the ground.)"""
    ELEMENTS = ROOT / "input" / "hard" / "elements_1000.nml"
    proc, out = run_scene(run, tmp_path, ELEMENTS, "erk", "solver.method='erk'",
                          "solver.t_end=0.01")
    assert proc.returncode == 3, proc.stderr
    assert "erk failed" in proc.stderr and "too stiff for an explicit method" in proc.stderr
    assert "steps per simulated second; use method = 'auto'" in proc.stderr
    assert "'mebdf'" in proc.stderr
    with h5py.File(out, "r") as f:
        status = f.attrs["status"]
        status = status.decode() if isinstance(status, bytes) else str(status)
        assert status.strip() == "failed"
        assert int(f["/solver/steps"][()]) <= 1000


def test_erk_closes_the_energy_balance_through_impacts(run, tmp_path):
    """The whip striking the ground (input/hard/whip_ground.nml, WHIP_GROUND_SLIDING) to
    0.8 s, past its first impacts and into stick-slip: erk integrates the dissipated energy
    with its own stages and error test, so T + V + dissipated = E0 to the tolerance's order
    (measured 2.2e-8 J at rtol 1e-6 on E0 = 0.50 J). Integrated from g at the step points
    only, the quadrature aliased the element-scale ringing at the impacts: -5.4e-3 J (the
    floor's law then at fixed Gauss points)."""
    proc, _ = run_scene(run, tmp_path, ROOT / "input" / "hard" / "whip_ground.nml", "wg",
                        "solver.method='erk'", "solver.rtol=1e-6", "solver.atol=1e-8",
                        "solver.t_end=0.8", "solver.output_interval=0.01",
                        WHIP_GROUND_SLIDING)
    assert proc.returncode == 0, proc.stderr
    line = [x for x in proc.stdout.splitlines() if "balance error" in x][0]
    balance = float(line.split()[2])
    assert abs(balance) <= 40 * 1e-6 * 0.5, line


def test_symplectic_without_other_forces_skips_only_zeros(run, tmp_path):
    """Without forces besides the potential (the undamped rope) the symplectic method skips
    the D-maps and the rest's evaluation. A point load of zero force brings the full step
    back, with the same forces: the two runs agree to the bit, so the skip drops nothing
    but zeros."""
    common = ["model.elements=8", "effects.damping=.false.", "solver.method='symplectic'",
              "solver.rtol=1e-3", "solver.atol=1e-5", "solver.t_end=2",
              "solver.output_interval=0.05"]
    bare, bare_out = run_scene(run, tmp_path, PAPER, "bare", *common)
    assert bare.returncode == 0, bare.stderr
    loaded, loaded_out = run_scene(run, tmp_path, PAPER, "zero_load", *common,
                                   "attachments.load_positions=0.5")
    assert loaded.returncode == 0, loaded.stderr
    with h5py.File(bare_out, "r") as a, h5py.File(loaded_out, "r") as b:
        assert a["/solver/steps"][()] == b["/solver/steps"][()] > 0
        for key in ("/state/y", "/energy/total", "/energy/dissipated"):
            assert np.array_equal(a[key][()], b[key][()]), key


def test_records_keep_the_step_at_a_switch_of_method(run, tmp_path):
    """/solver/step_size and /solver/order hold the last step taken before each record. At
    a record where auto switched method, the new method had taken none yet, and the record
    held step 0 and order 0 (input/ground_rest.nml switches at 0.08 and 0.21 s)."""
    scene = ROOT / "input" / "ground_rest.nml"
    proc, out = run_scene(run, tmp_path, str(scene), "ground", "solver.t_end=0.3")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(out, "r") as f:
        times = f["/solver/switch_time"][()]
        h, order, t = f["/solver/step_size"][()], f["/solver/order"][()], f["time"][()]
    switched = [x for x in times[1:] if np.isclose(t, x, atol=1e-12).any()]
    assert switched, (times, "no switch at a record: the test checks nothing")
    assert (h[1:] > 0).all() and (order[1:] > 0).all(), (t[h == 0], t[order == 0])


def test_erk_of_order_3_diagnoses_the_steel_wire(run, tmp_path):
    """The order-3 pair's spectral estimate (a stage combination free of z and z^2 terms,
    ropedyn_erk_tables) sees the steel wire's fast modes (4.4e5 1/s): erk at max_order = 3
    is held by stability at 2.7e5 steps per simulated second and stops with the
    diagnosis within 0.05 s. Its last two stages (c = 3/4 and 1) weighed the slow modes in
    at O(z): the run went on for the whole second at 2.8e5 steps per second undiagnosed."""
    proc, out = run_scene(run, tmp_path, STEEL, "erk3", "solver.method='erk'",
                          "solver.max_order=3", "solver.t_end=0.05")
    assert proc.returncode == 3, proc.stderr
    assert "order 3: the problem is too stiff for an explicit method" in proc.stderr
    rho = float(proc.stderr.split("spectral radius rho of about")[1].split()[0])
    assert 2e5 < rho < 4.5e5, rho


def test_symplectic_held_by_its_tolerance_says_so(run, tmp_path):
    """Störmer-Verlet alone (max_order = 2) on the paper's rope at rtol 1e-6: its energy
    limit for the lightly damped fast modes takes steps of about 1e-6 s, far below its
    stable step (2.5e-4 s). The run stops at its spectrum's second look (0.03 s), and the
    message names the tolerance, the composition and the cures; it said the step was held
    by stability. The steel wire, whose step is held by stability, keeps that message."""
    proc, _ = run_scene(run, tmp_path, PAPER, "verlet", "solver.method='symplectic'",
                        "solver.max_order=2", "solver.t_end=0.1")
    assert proc.returncode == 3, proc.stderr
    assert "the tolerance (rtol = 1.0e-6) asks for steps of" in proc.stderr, proc.stderr
    assert "of Stormer-Verlet (order 2)" in proc.stderr and "allow the 4th-order " \
        "compositions (max_order = 4, the default)" in proc.stderr, proc.stderr
    assert "held by stability" not in proc.stderr, proc.stderr
    proc, _ = run_scene(run, tmp_path, STEEL, "wire", "solver.method='symplectic'",
                        "solver.t_end=0.01")
    assert proc.returncode == 3 and "the step is held by stability" in proc.stderr, \
        proc.stderr
