"""The peer side by side: MoorDyn-C and ropedyn's default method on the paper's rope.

MoorDyn-C (PyPI `moordyn`, a lumped-mass line with bending, explicit RK4 at a fixed step)
runs in its own benchmark venv (.venv-bench, created here on first use; never the project
venv) on the same rope as input/paper.nml, n segments against ropedyn's n elements:

- EA = E A, EI = E I, mass per length rho A, diameter d; pinned top, straight at 75 degrees
  (the free end placed at the rope's length from the top: MoorDyn's initial catenary of a
  taut line is the straight line; no dynamic relaxation, Init_NoIC); gravity only (drag and
  added mass off, fluid density 0, so no buoyancy).
- Damping: MoorDyn's internal damping is BA times the strain rate (N s), which is the axial
  part of ropedyn's Kelvin-Voigt law, eta A d(eps)/dt; so BA = eta A, the same physical
  damping (the same damping ratio of a segment's axial mode, zeta = eta A n / (2 L
  sqrt(EA mu)), in the table). MoorDyn has no bending damping (ropedyn damps bending with
  the same eta): this only makes MoorDyn's bending modes harder, not its step longer.
- Time step: the largest of a geometric ladder (steps 2^(1/4) apart) for which a 5 s probe
  stays finite with the tip within 5 % of the rope's length of the top, and whose tip over
  the probe agrees with the probe at half the step within 1 % of the length (L2 over the
  output times), and then the whole run stays finite (else the next smaller step). The
  agreement test is needed: at n = 10 the largest step that did not blow up (2.4e-3 s)
  gave a collapsed rope, its tip 0.3 m (L2 over [0, 2 s]) from the runs at smaller
  steps.
- Output: both write the whole rope every 0.01 s (MoorDyn its node positions to its line
  file, LineOutputs p; ropedyn its HDF5 records), and MoorDyn's tip is read every 0.01 s.
- CPU: process time of MoorDyn's stepping loop (Create and initialisation excluded) and the
  run's /solver/cpu_time for ropedyn (integration and output); each the least of
  `--repeat` runs (3 by default: on this VM one run's ratio moved by 10 %, 2.69 / 2.93 /
  3.02 at n = 30 in three runs of the same code).
- Accuracy: ropedyn's tip against a tight reference (ropedyn, cvode at rtol 1e-10, atol
  1e-12) over [0, 2 s], L2 over the output times; MoorDyn's time error the same way, its
  tip against its own run at a quarter of the step (RK4: 256 times smaller error). MoorDyn's
  tip against ropedyn's reference is listed too: that is the difference of the two models
  (lumped masses against rigid elements), not an error of either code.
- At equal accuracy (the second table): the paper scene's rtol 1e-6 holds ropedyn's tip
  some 1e5 times closer to its reference than MoorDyn's step holds MoorDyn's. The second
  table runs ropedyn's default method at the loosest rtol of the ladder 1e-1 .. 1e-6, half
  a decade apart (EQUAL_RTOLS; atol = rtol / 100, as the scene's), whose tip error over
  [0, 2 s] is at most MoorDyn's time error, over the whole run.

- At equal accuracy, ropedyn's default method (auto) and each method of `--methods`
  (`method` or `method:max_order`; by default `method = 'symplectic'`, and the implicit
  methods, whose steps the fast modes do not hold: CVODE's BDF and MEBDF).
- The undamped rope over 300 s (`--undamped-elements`, `--undamped-t-end`; alone with
  `--only-undamped`): damping off in both codes and MoorDyn's bending off too (a chain of
  tension-only springs, whose energy its driver sums: kinetic and gravity of the lumped node
  masses, mu L/n, half at the free end, and EA/(2 l0) (l - l0)^2 per stretched segment;
  MoorDyn's own node masses are 0 before its first step), RK4 at the largest step of the
  ladder that stays finite and whose energy never rises by m g L (no agreement test: the chain without damping and bending
  follows no trajectory that a smaller step converges on; its tip differs by 1 .. 3 cm over
  the first second between a step and its half); ropedyn's symplectic method at rtol 1e-3:
  the energy error at 30 s and 300 s in m g L and the CPU of each.

- The coupled case (its own table, also alone with --coupled-only): the same rope with
  its top driven from Python every millisecond, ropedyn through ropedyn.Simulation and
  MoorDyn through its Python package (COUPLED_DT and what follows it).

The tables go between the bench_peers (bench_peers_undamped, bench_peers_coupled) markers
of docs/performance/peers.md. The code of scripts/bench_peers.

MoorDyn-C 2.7.2's reader scans for the next line of dashes without a bound: an input file
that does not end with one (the "need this line" line of its examples) makes `Create`
segfault.
"""
import argparse
import json
import math
import pathlib
import shlex
import subprocess
import sys
import tempfile

import numpy as np

from ropedyn import io
from ropedyn.docstrings import summary
from ropedyn_tools.arguments import check_methods, list_text, method_specs, positive
from ropedyn_tools.repo import DOCS, PAPER, add_exe_argument, exe_or_build, set_args
from ropedyn_tools.studies.common import (least_cpu, machine, method_chain, method_label,
                                          method_sets, shown_arguments, update_doc, run_stamp)

BEGIN = "<!-- bench_peers:begin -->"
END = "<!-- bench_peers:end -->"
UNDAMPED_BEGIN = "<!-- bench_peers_undamped:begin -->"
UNDAMPED_END = "<!-- bench_peers_undamped:end -->"
UNDAMPED_HEADER = ("| n | MoorDyn dt (s) | MoorDyn E - E0 at 30 s | at 300 s | MoorDyn CPU (s) "
                   "| ropedyn E - E0 at 30 s | at 300 s | ropedyn max abs | ropedyn CPU (s) "
                   "| MoorDyn / ropedyn |")
ROOT = DOCS.parent
BENCH_VENV = ROOT / ".venv-bench"

# input/paper.nml
LENGTH, DENSITY, DIAMETER, YOUNG, ETA = 1.0, 6000.0, 0.005, 35.0e6, 1.0e3
ANGLE = math.radians(75.0)
TOP_Z = -1.0            # MoorDyn: z up; the top anchor
ACCURACY_SPAN = 2.0     # s: the tip is compared over [0, ACCURACY_SPAN]
OUT_DT = 0.01           # s: output interval of both

DRIVER = r"""
import json, sys, time, math
import moordyn
path, t_end, dt_out, length, span = (sys.argv[1], float(sys.argv[2]), float(sys.argv[3]),
                                     float(sys.argv[4]), float(sys.argv[5]))
# the energy (no bending, no damping: kinetic + gravity + tension-only segments) at these
# times, outside the timed loop's CPU (argv[6], EA:L0:mu:t1,t2,...); the node masses are
# the lumped ones, mu L0 (half at the free end; MoorDyn's own are 0 before its first step)
energy_at = []
if len(sys.argv) > 6:
    ea, l0, mu, when = sys.argv[6].split(":")
    ea, l0, mu, energy_at = float(ea), float(l0), float(mu), [float(x) for x in when.split(",")]
s = moordyn.Create(path)
moordyn.Init_NoIC(s, [], [])
line = moordyn.GetLine(s, 1)
n = moordyn.GetLineNumberNodes(line)
top = moordyn.GetLineNodePos(line, 0)
tips = [list(moordyn.GetLineNodePos(line, n - 1))]


def energy():
    e = 0.0
    pos = [moordyn.GetLineNodePos(line, i) for i in range(n)]
    for i in range(1, n):            # node 0 is fixed
        v = moordyn.GetLineNodeVel(line, i)
        m = mu * l0 * (0.5 if i == n - 1 else 1.0)
        # kinetic, and gravity (z up, g = 9.81 as in the input file; no added mass)
        e += 0.5 * m * sum(x * x for x in v) + m * 9.81 * pos[i][2]
    for i in range(n - 1):
        stretch = math.dist(pos[i], pos[i + 1]) - l0
        if stretch > 0.0:
            e += 0.5 * ea / l0 * stretch ** 2
    return e


energies = [energy()] if energy_at else []
t, ok, c, spent = 0.0, True, time.process_time(), 0.0
steps = int(round(t_end / dt_out))
for k in range(steps):
    moordyn.Step(s, [], [], t, dt_out)
    t += dt_out
    p = moordyn.GetLineNodePos(line, n - 1)
    if t <= span + 1e-9:
        tips.append(list(p))
    if any(abs(t - x) < 0.5 * dt_out for x in energy_at):
        e0 = time.process_time()
        energies.append(energy())
        spent += time.process_time() - e0
    r = math.dist(p, top)
    if not (math.isfinite(r) and r < 1.05 * length):
        ok = False
        break
cpu = time.process_time() - c - spent
moordyn.Close(s)
print("RESULT " + json.dumps({"cpu": cpu, "ok": ok, "t": t, "tip": tips,
                              "energies": energies}), flush=True)
"""


def segment_damping_ratio(n):
    """Damping ratio of a segment's axial mode for the axial damping eta A, n segments."""
    area = math.pi * DIAMETER ** 2 / 4
    return ETA * area * n / (2 * LENGTH * math.sqrt(YOUNG * area * DENSITY * area))


def moordyn_file(path, n, dt, undamped=False, top="Fixed", outputs="p"):
    """MoorDyn's input for the paper's rope; `undamped`: no internal damping and no bending
    stiffness (a chain of tension-only springs, whose energy the driver can sum); `top`: the
    top point's attachment (Fixed, or Coupled for the coupled case); `outputs`: the line's
    outputs (p: node positions; -: none)."""
    area = math.pi * DIAMETER ** 2 / 4
    ea, mu = YOUNG * area, DENSITY * area
    ei = YOUNG * math.pi * DIAMETER ** 4 / 64
    ba = ETA * area            # N s: force per unit strain rate, as ropedyn's eta A
    if undamped:
        ba, ei = 0.0, 0.0
    x, z = LENGTH * math.sin(ANGLE), TOP_Z - LENGTH * math.cos(ANGLE)
    path.write_text(f"""--------------------- MoorDyn Input File ------------------------------------
ropedyn bench_peers: the paper's rope
----------------------- LINE TYPES ------------------------------------------
TypeName   Diam     Mass/m     EA     BA/-zeta    EI    Cd     Ca    CdAx    CaAx
(name)     (m)      (kg/m)     (N)    (N-s/-)    (N-m^2) (-)  (-)   (-)     (-)
rope       {DIAMETER}  {mu:.10g}  {ea:.10g}  {ba:.10g}  {ei:.10g}  0.0  0.0  0.0  0.0
---------------------- POINTS --------------------------------
ID   Attachment  X       Y     Z      Mass   Volume  CdA    Ca
(#)   (-)        (m)    (m)   (m)     (kg)   (m^3)   (m^2)  (-)
1    {top}       0      0     {TOP_Z}    0      0       0      0
2    Free        {x:.12f}   0    {z:.12f}  0      0       0      0
---------------------- LINES --------------------------------------
ID    LineType   AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#)   (name)     (#)      (#)      (m)       (-)       (-)
1     rope       1        2        {LENGTH}       {n}        {outputs}
---------------------- OPTIONS -----------------------------------------
{dt:.6g}   dtM
{OUT_DT}     dtOut
9.81     g
10.0     WtrDpth
0.0      rho
RK4      tScheme
------------------------- need this line --------------------------------------
""")
    return segment_damping_ratio(n)


def ensure_bench_venv():
    py = BENCH_VENV / "bin" / "python"
    if not py.exists():
        subprocess.run([sys.executable, "-m", "venv", str(BENCH_VENV)], check=True)
    if subprocess.run([str(py), "-c", "import moordyn"], capture_output=True).returncode:
        subprocess.run([str(py), "-m", "pip", "install", "-q", "moordyn"], check=True)
    return py


def run_moordyn(py, workdir, n, dt, t_end, span=ACCURACY_SPAN, undamped=False,
                energy_at=()):
    """MoorDyn over [0, t_end] at step dt; the tip at the output times up to span; with
    `energy_at`, its energy at the start and at those times ("energies")."""
    f = workdir / f"rope_{n}{'_undamped' if undamped else ''}.txt"
    moordyn_file(f, n, dt, undamped)
    extra = []
    if energy_at:
        area = math.pi * DIAMETER ** 2 / 4
        extra = [f"{YOUNG * area!r}:{LENGTH / n!r}:{DENSITY * area!r}:"
                 + ",".join(f"{x:g}" for x in energy_at)]
    # MoorDyn prints its progress; keep stdout and stderr apart and read the result line
    proc = subprocess.run([str(py), "-X", "faulthandler", "-c", DRIVER, str(f), str(t_end),
                           str(OUT_DT), str(LENGTH), str(span), *extra], capture_output=True,
                          text=True, cwd=workdir, timeout=7200)
    return driver_result(proc, t=0.0)


def driver_result(proc, **failed):
    """The result a MoorDyn driver printed (its last RESULT line), the tip in ropedyn's
    frame; else a failure with the driver's last error line and `failed`'s entries."""
    for line in proc.stdout.splitlines()[::-1]:
        if "RESULT " in line:
            r = json.loads(line.split("RESULT ", 1)[1])
            xyz = np.array(r.pop("tip"))
            # ropedyn's frame: x down from the top anchor, y horizontal
            r["tip"] = np.column_stack([TOP_Z - xyz[:, 2], xyz[:, 0]])
            return r
    return {"ok": False, "cpu": float("nan"), **failed,
            "error": (proc.stderr.strip().splitlines() or ["no output"])[-1][:80]}


def ladder(n):
    """MoorDyn time steps to try, largest first: 2e-4 (30/n) 2^(k/4), k = 8 .. -12."""
    base = 2.0e-4 * 30.0 / n
    return [base * 2.0 ** (k / 4) for k in range(8, -13, -1)]


def stable_and_right(py, workdir, n, dt, probe, undamped=False):
    """The probe at dt stays finite and agrees with the probe at dt/2 (1 % of L, L2)."""
    coarse = run_moordyn(py, workdir, n, dt, probe, span=probe, undamped=undamped)
    if not coarse["ok"]:
        return False
    fine = run_moordyn(py, workdir, n, dt / 2, probe, span=probe, undamped=undamped)
    if not fine["ok"]:
        return False
    k = min(len(coarse["tip"]), len(fine["tip"]))
    d = np.linalg.norm(coarse["tip"][:k] - fine["tip"][:k], axis=1)
    return float(np.sqrt(np.mean(d ** 2))) < 0.01 * LENGTH


def run_ropedyn(exe, workdir, n, t_end, sets=(), name="run"):
    out = workdir / f"ropedyn_{name}_{n}.h5"
    cmd = [str(exe), "run", str(PAPER), *set_args([
        f"model.elements={n}", f"solver.t_end={t_end}", f'output.file="{out}"', *sets])]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=7200)
    if proc.returncode != 0:
        return {"status": "failed: " + proc.stderr.strip()[:80]}
    run = io.load_run(out)
    drift = run.balance - run.e0
    methods = ""
    import h5py
    with h5py.File(out, "r") as f:
        if "/solver/switch_method" in f:
            methods = method_chain(
                method_label(m.decode().strip(), o)
                for m, o in zip(f["/solver/switch_method"][()],
                                f["/solver/switch_max_order"][()]))
    return {"status": "complete", "cpu": float(run.stats["cpu_time"]),
            "steps": int(run.stats["steps"]), "methods": methods,
            "balance": float(abs(drift).max()), "drift": drift,
            "time": run.time, "tip": run.points[:, -1, :]}


def tip_l2(time, tip, ref):
    """L2 over the output times in [0, ACCURACY_SPAN] of |tip - reference tip| (m)."""
    k = min(len(tip), int(np.searchsorted(ref["time"], ACCURACY_SPAN + 1e-9)))
    if not np.allclose(time[:k], ref["time"][:k]):
        return float("nan")
    d = np.linalg.norm(tip[:k] - ref["tip"][:k], axis=1)
    return float(np.sqrt(np.mean(d ** 2)))


#: the rtols tried for "at equal accuracy", loosest first: half a decade apart, so that
#: the rung taken errs at most about 3 times less than MoorDyn (with decades ropedyn ran at
#: 0.01 on the rope of n = 30, its tip 10 times closer than MoorDyn's, where 0.03 was
#: within MoorDyn's error too)
EQUAL_RTOLS = (1e-1, 3e-2, 1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5, 1e-5, 3e-6, 1e-6)


#: the methods of the equal-accuracy table besides auto (`method` or `method:max_order`)
EQUAL_METHODS = "symplectic cvode mebdf"


def at_equal_accuracy(exe, work, n, t_end, ref, md, md_error, repeat=1, method="auto"):
    """ropedyn (`method`, with `:max_order` if given) at the loosest rtol of EQUAL_RTOLS
    whose tip error is <= MoorDyn's time error: the table row (n, MoorDyn's error, rtol,
    method, error, balance, CPU (the least of `repeat` runs), ratio)."""
    for rtol in EQUAL_RTOLS:
        sets = [f"solver.rtol={rtol:g}", f"solver.atol={rtol / 100:g}",
                *(f"{k}={v}" for k, v in method_sets(method).items())]
        r = run_ropedyn(exe, work, n, t_end, name=f"{method}_rtol{rtol:g}", sets=sets)
        if r["status"] != "complete":
            continue
        err = tip_l2(r["time"], r["tip"], ref)
        if err <= md_error:
            if repeat > 1:
                again = least_cpu(lambda: run_ropedyn(exe, work, n, t_end, sets=sets,
                                                      name=f"{method}_rtol{rtol:g}"), repeat - 1,
                                  complete=lambda x: x["status"] == "complete")
                if again["status"] == "complete" and again["cpu"] < r["cpu"]:
                    r["cpu"] = again["cpu"]
            used = f" ({r['methods']})" if r["methods"] else ""   # a switch log: auto's
            return (f"| {n} | {md_error:.1e} | {rtol:g} | {method}{used} | {err:.1e} "
                    f"| {r['balance']:.1e} | {r['steps']} | {r['cpu']:.3g} | {md['cpu']:.3g} "
                    f"| {md['cpu'] / r['cpu']:.2f} |")
    return (f"| {n} | {md_error:.1e} | none of {EQUAL_RTOLS} | {method} | | | | | "
            f"{md['cpu']:.3g} | |")


ENERGY_TIMES = (30.0, 300.0)
MGL = DENSITY * math.pi * DIAMETER ** 2 / 4 * LENGTH * 9.81 * LENGTH


def bounded(r):
    """A MoorDyn run of the undamped chain that stayed finite, its tip within 1.05 L of the
    top, and whose energy never rose by a whole m g L at the times it was taken (no energy
    can come in: such a rise is the step's instability; n = 20 at 1.0e-3 s kept its tip
    within bounds while its energy rose by 120 m g L in 30 s)."""
    e = r.get("energies") or [0.0]
    return bool(r.get("ok")) and max(e) - e[0] < MGL


def undamped_row(py, exe, work, n, t_end, probe, repeat):
    """The undamped rope (no damping in either code; MoorDyn without bending, a chain of
    tension-only springs whose energy its driver sums): MoorDyn's RK4 at the largest step of
    the ladder that stays finite over the probe and the whole run, and ropedyn's
    symplectic method at rtol 1e-3, each to t_end: the energy error at ENERGY_TIMES (m g L)
    and the CPU of each (the least of `repeat`)."""
    when = [x for x in ENERGY_TIMES if x <= t_end + 1e-9]
    steps = ladder(n)
    # stable only, no agreement test: without damping and bending the chain's tip differs
    # by 1 .. 3 cm (L2 over 1 s) between a step and its half at every step of the ladder
    # (n = 20), a trajectory no step converges on; the energy is what is compared
    k = next((i for i, h in enumerate(steps)
              if bounded(run_moordyn(py, work, n, h, probe, span=0.0, undamped=True,
                                     energy_at=(probe,)))), None)
    md, dt = {"ok": False}, None
    while k is not None and k < len(steps):
        h = steps[k]
        md = least_cpu(lambda: run_moordyn(py, work, n, h, t_end, span=0.0, undamped=True,
                                           energy_at=when), repeat,
                       complete=bounded)
        if bounded(md):
            dt = h
            break
        md = {"ok": False}
        k += 1
    sets = ["effects.damping=.false.", "solver.method='symplectic'", "solver.rtol=1e-3",
            "solver.atol=1e-5", "solver.output_interval=0.1", "solver.max_steps=100000000"]
    rd = least_cpu(lambda: run_ropedyn(exe, work, n, t_end, sets=sets, name="undamped"),
                   repeat, complete=lambda r: r["status"] == "complete")
    cells = [f"{dt:.3g}" if dt else "none stable"]
    if md.get("ok"):
        e = md["energies"]
        cells += [f"{(e[i + 1] - e[0]) / MGL:+.1e}" for i in range(len(when))]
        cells.append(f"{md['cpu']:.3g}")
    else:
        cells += [""] * (len(when) + 1)
    if rd["status"] == "complete":
        t = rd["time"]
        cells += [f"{rd['drift'][int(np.searchsorted(t, x - 1e-9))] / MGL:+.1e}" for x in when]
        cells += [f"{abs(rd['drift']).max() / MGL:.1e}", f"{rd['cpu']:.3g}"]
        cells.append(f"{md['cpu'] / rd['cpu']:.2f}" if md.get("ok") else "")
    else:
        cells += [""] * (len(when) + 2) + [rd["status"]]
    return f"| {n} | " + " | ".join(cells) + " |"


# The coupled case: the top driven from Python every COUPLED_DT by the smooth motion of
# coupled_motion, ropedyn through ropedyn.Simulation (top_motion = 'coupled') and MoorDyn
# through its Python package (a Coupled point), each reading the top's force back at every
# exchange; nothing written by either. MoorDyn takes the position and velocity at the
# start of each step and moves the point on with that velocity; ropedyn takes them at the
# end and moves the support on the cubic Hermite curve between.
COUPLED_DT = 1e-3                                      # s
COUPLED_AMPLITUDE, COUPLED_FREQUENCY, COUPLED_RAMP = 0.05, 1.5, 0.4   # m, Hz, s

DRIVER_COUPLED = r"""
import json, sys, time, math
import moordyn
path, t_end, dt, length, span, top_z, amp, freq, ramp = (
    sys.argv[1], *map(float, sys.argv[2:]))

def motion(t):
    u = min(t / ramp, 1.0)
    r = u ** 3 * (10 - 15 * u + 6 * u * u)
    dr = 30 * u * u * (1 - u) ** 2 / ramp if t < ramp else 0.0
    w = 2 * math.pi * freq
    return r * amp * math.sin(w * t), r * amp * w * math.cos(w * t) + dr * amp * math.sin(w * t)

s = moordyn.Create(path)
moordyn.Init_NoIC(s, [0.0, 0.0, top_z], [0.0, 0.0, 0.0])
line = moordyn.GetLine(s, 1)
n = moordyn.GetLineNumberNodes(line)
tips = [list(moordyn.GetLineNodePos(line, n - 1))]
steps, every = int(round(t_end / dt)), int(round(0.01 / dt))
ok, peak, c = True, 0.0, time.process_time()
for k in range(steps):
    t = k * dt
    y, v = motion(t)
    f = moordyn.Step(s, [y, 0.0, top_z], [v, 0.0, 0.0], t, dt)
    peak = max(peak, math.hypot(f[0], f[2]))
    if (k + 1) % every == 0:
        p = moordyn.GetLineNodePos(line, n - 1)
        if (k + 1) * dt <= span + 1e-9:
            tips.append(list(p))
        if not all(math.isfinite(x) for x in p):
            ok = False
            break
cpu = time.process_time() - c
moordyn.Close(s)
print("RESULT " + json.dumps({"cpu": cpu, "ok": ok, "peak": peak, "tip": tips}), flush=True)
"""


def coupled_motion(t):
    """The top's sideways position and velocity at t: a harmonic motion of
    COUPLED_AMPLITUDE at COUPLED_FREQUENCY, ramped from rest over COUPLED_RAMP (as a
    harmonic support with top_ramp_time); the same text runs in MoorDyn's driver."""
    u = min(t / COUPLED_RAMP, 1.0)
    r = u ** 3 * (10 - 15 * u + 6 * u * u)
    dr = 30 * u * u * (1 - u) ** 2 / COUPLED_RAMP if t < COUPLED_RAMP else 0.0
    w = 2 * math.pi * COUPLED_FREQUENCY
    return (r * COUPLED_AMPLITUDE * math.sin(w * t),
            r * COUPLED_AMPLITUDE * w * math.cos(w * t) + dr * COUPLED_AMPLITUDE * math.sin(w * t))


def run_moordyn_coupled(py, workdir, n, dt, t_end, span=ACCURACY_SPAN):
    f = workdir / f"coupled_{n}.txt"
    moordyn_file(f, n, dt, top="Coupled", outputs="-")
    proc = subprocess.run([str(py), "-X", "faulthandler", "-c", DRIVER_COUPLED, str(f),
                           str(t_end), str(COUPLED_DT), str(LENGTH), str(span), str(TOP_Z),
                           str(COUPLED_AMPLITUDE), str(COUPLED_FREQUENCY), str(COUPLED_RAMP)],
                          capture_output=True, text=True, cwd=workdir, timeout=3600)
    return driver_result(proc)


def run_ropedyn_coupled(n, t_end, sets=(), span=ACCURACY_SPAN):
    """The paper's rope with its top coupled, driven every COUPLED_DT from this process
    through ropedyn.Simulation; CPU (process time) of the loop, the peak top force, the
    tip every 0.01 s up to span."""
    import time
    import ropedyn
    scene = ropedyn.Scene.from_file(PAPER).set({
        "model.elements": n, "supports.top_motion": "coupled",
        **dict(item.split("=", 1) for item in sets)})
    tips, peak = [], 0.0
    steps, every = int(round(t_end / COUPLED_DT)), int(round(OUT_DT / COUPLED_DT))
    with ropedyn.Simulation(scene) as sim:
        tips.append(sim.points[-1])
        set_support, advance, reaction = sim.set_support, sim.advance, sim.reaction
        c = time.process_time()
        for k in range(1, steps + 1):
            t = k * COUPLED_DT
            y, v = coupled_motion(t)
            set_support("top", position=(0.0, y), velocity=(0.0, v))
            advance(t)
            f = reaction("top")
            peak = max(peak, math.hypot(f[0], f[1]))
            if k % every == 0 and t <= span + 1e-9:
                tips.append(sim.points[-1])
        cpu = time.process_time() - c
    return {"cpu": cpu, "peak": peak, "tip": np.array(tips)}


def l2(a, b):
    k = min(len(a), len(b))
    return float(np.sqrt(np.mean(np.linalg.norm(a[:k] - b[:k], axis=1) ** 2)))


def coupled_row(py, exe, work, n, t_end, probe, repeat):
    """The coupled case at n: the table row, MoorDyn at the step the ladder finds."""
    import os
    os.environ.setdefault("ROPEDYN_LIBRARY", str(pathlib.Path(exe).resolve().parent /
                                                  "libropedyn.so"))
    steps = ladder(n)
    k = next((i for i, h in enumerate(steps) if stable_and_right(py, work, n, h, probe)), None)
    md, dt = {"ok": False}, None
    while k is not None and k < len(steps):
        h = steps[k]
        md = least_cpu(lambda: run_moordyn_coupled(py, work, n, h, t_end), repeat,
                       complete=lambda r: r["ok"])
        if md["ok"]:
            dt = h
            break
        k += 1
    rd = least_cpu(lambda: run_ropedyn_coupled(n, t_end), repeat)
    ref = run_ropedyn_coupled(n, ACCURACY_SPAN, sets=('solver.method="cvode"',
                                                      "solver.rtol=1e-10", "solver.atol=1e-12"))
    rd_err = l2(rd["tip"], ref["tip"])
    if not md.get("ok"):
        return (f"| {n} | none stable | | | {rd['cpu']:.3g} | | {rd_err:.1e} | | "
                f"| {rd['peak']:.3f} | | | |")
    fine = run_moordyn_coupled(py, work, n, dt / 4, ACCURACY_SPAN)
    md_err = l2(md["tip"], fine["tip"]) if fine.get("ok") else float("nan")
    # at equal accuracy: the loosest rtol whose tip error is at most MoorDyn's time error
    equal = "| none | | "
    for rtol in EQUAL_RTOLS:
        sets = (f"solver.rtol={rtol:g}", f"solver.atol={rtol / 100:g}")
        if l2(run_ropedyn_coupled(n, ACCURACY_SPAN, sets=sets)["tip"], ref["tip"]) <= md_err:
            loose = least_cpu(lambda: run_ropedyn_coupled(n, t_end, sets=sets), repeat)
            equal = f"| {rtol:g} | {loose['cpu']:.3g} | {md['cpu'] / loose['cpu']:.2f}"
            break
    return (f"| {n} | {dt:.3g} | {md['cpu']:.3g} | {md['peak']:.3f} | {rd['cpu']:.3g} "
            f"| {md['cpu'] / rd['cpu']:.2f} | {rd_err:.1e} | {md_err:.1e} "
            f"| {l2(md['tip'], ref['tip']):.1e} | {rd['peak']:.3f} {equal} |")


COUPLED_BEGIN = "<!-- bench_peers_coupled:begin -->"
COUPLED_END = "<!-- bench_peers_coupled:end -->"
COUPLED_HEADER = ("| n | MoorDyn dt (s) | MoorDyn CPU (s) | MoorDyn peak top force (N) "
                  "| ropedyn CPU (s) | MoorDyn / ropedyn | ropedyn tip error [0, 2 s] (m) "
                  "| MoorDyn time error [0, 2 s] (m) "
                  "| MoorDyn tip - ropedyn reference [0, 2 s] (m) "
                  "| ropedyn peak top force (N) | ropedyn rtol at equal accuracy "
                  "| its CPU (s) | MoorDyn / ropedyn at equal accuracy |")


def coupled_main(args, exe, py):
    rows = []
    print(COUPLED_HEADER, flush=True)
    with tempfile.TemporaryDirectory() as tmp:
        for n in (int(x) for x in args.coupled_elements.split()):
            rows.append(coupled_row(py, exe, pathlib.Path(tmp), n, args.t_end, args.probe,
                                    args.repeat))
            print(rows[-1], flush=True)
    if args.no_write:
        return 0
    lines = [COUPLED_BEGIN,
             f"Command: `{args.command}` (code: "
             "tools/ropedyn_tools/studies/bench_peers.py; CPU: the least of "
             f"{args.repeat} runs each, the process time of the driving loop alone). "
             f"The paper's rope, its top driven sideways every {COUPLED_DT * 1e3:g} ms from "
             f"Python: {COUPLED_AMPLITUDE:g} m at {COUPLED_FREQUENCY:g} Hz, ramped from rest "
             f"over {COUPLED_RAMP:g} s; the top's force read back at every exchange; no "
             "output written. ropedyn: `ropedyn.Simulation` of input/paper.nml with "
             "`top_motion = 'coupled'` (its default method, rtol 1e-6). MoorDyn-C: its "
             "Python package, a Coupled point, RK4 at the step of the first table's ladder. "
             f"Tip columns as in the first table (ropedyn's reference: the same coupled "
             f"run with cvode at rtol 1e-10). Machine: {machine()}. Run: {run_stamp()}.", "",
             "At equal accuracy: ropedyn's default method only, at the "
             f"loosest rtol of {', '.join(f'{r:g}' for r in EQUAL_RTOLS)} (atol = rtol / 100) "
             "whose tip error over [0, 2 s] is at most MoorDyn's time error.", "",
             COUPLED_HEADER, "|---|---|---|---|---|---|---|---|---|---|---|---|---|", *rows,
             COUPLED_END]
    update_doc(DOCS / "performance" / "peers.md", COUPLED_BEGIN, COUPLED_END,
               "\n".join(lines), heading="## Coupled: the top driven from Python\n\n")
    print(f"bench_peers: {DOCS / 'performance' / 'peers.md'}")
    return 0


def command_text(argv):
    """The command as it ran (its arguments as given, --exe aside), for the pages' stamps."""
    return shlex.join(["scripts/bench_peers", *shown_arguments(argv)])


def main(argv=None):
    parser = argparse.ArgumentParser(description=summary(__doc__))
    add_exe_argument(parser)
    parser.add_argument("--t-end", type=float, default=30.0)
    parser.add_argument("--probe", type=float, default=5.0, help="stability probe (s)")
    parser.add_argument("--elements", type=list_text(positive(int)), default="10 30 100")
    parser.add_argument("--repeat", type=int, default=3,
                        help="runs of each timed run (the least CPU counts)")
    parser.add_argument("--undamped-elements", type=list_text(positive(int)), default="20 100",
                        help="n of the undamped comparison (energy over --undamped-t-end)")
    parser.add_argument("--undamped-t-end", type=float, default=300.0)
    parser.add_argument("--only-undamped", action="store_true",
                        help="only the undamped comparison (the other tables kept)")
    parser.add_argument("--no-undamped", action="store_true",
                        help="without the undamped comparison (its table kept)")
    parser.add_argument("--methods", default=EQUAL_METHODS, type=method_specs(),
                        help="methods at equal accuracy besides auto: method or "
                             "method:max_order, space-separated (default: %(default)s)")
    parser.add_argument("--no-write", action="store_true")
    parser.add_argument("--coupled-elements", type=list_text(positive(int)), default="30",
                        help="n of the coupled case (top driven from Python)")
    parser.add_argument("--coupled-only", action="store_true",
                        help="only the coupled case (its own table)")
    argv = sys.argv[1:] if argv is None else list(argv)
    args = parser.parse_args(argv)
    args.command = command_text(argv)
    exe = exe_or_build(args.exe)
    check_methods(parser, exe, "--methods", args.methods.split())
    py = ensure_bench_venv()
    if args.coupled_only:
        return coupled_main(args, exe, py)
    header = ("| n | MoorDyn dt (s) | segment damping ratio (both) | MoorDyn CPU (s) "
              "| ropedyn method | ropedyn steps | ropedyn CPU (s) | MoorDyn / ropedyn "
              "| ropedyn tip error [0, 2 s] (m) | ropedyn balance error (J) "
              "| MoorDyn time error [0, 2 s] (m) "
              "| MoorDyn tip - ropedyn reference [0, 2 s] (m) |")
    rows, equal_rows = [], []
    equal_header = ("| n | MoorDyn time error [0, 2 s] (m) | ropedyn rtol | ropedyn method "
                    "| ropedyn tip error [0, 2 s] (m) | ropedyn balance error (J) "
                    "| ropedyn steps | ropedyn CPU (s) | MoorDyn CPU (s) | MoorDyn / ropedyn |")
    if not args.only_undamped:
        print(header, flush=True)
    with tempfile.TemporaryDirectory() as tmp:
        work = pathlib.Path(tmp)
        undamped_rows = []
        if not args.no_undamped:
            print(UNDAMPED_HEADER, flush=True)
            for n in (int(x) for x in args.undamped_elements.split()):
                undamped_rows.append(undamped_row(py, exe, work, n, args.undamped_t_end,
                                                  args.probe, args.repeat))
                print(undamped_rows[-1], flush=True)
        for n in ([] if args.only_undamped else (int(x) for x in args.elements.split())):
            zeta = segment_damping_ratio(n)
            # the largest step of the ladder stable over the probe, then over the run (a
            # run that goes unstable later takes the next smaller step)
            md, dt = {"ok": False}, None
            steps = ladder(n)
            k = next((i for i, h in enumerate(steps)
                      if stable_and_right(py, work, n, h, args.probe)), None)
            while k is not None and k < len(steps):
                h = steps[k]
                md = least_cpu(lambda: run_moordyn(py, work, n, h, args.t_end), args.repeat,
                               complete=lambda r: r["ok"])
                if md["ok"]:
                    dt = steps[k]
                    break
                k += 1
            rd = least_cpu(lambda: run_ropedyn(exe, work, n, args.t_end), args.repeat,
                           complete=lambda r: r["status"] == "complete")
            ref = run_ropedyn(exe, work, n, ACCURACY_SPAN, name="reference", sets=[
                'solver.method="cvode"', "solver.rtol=1e-10", "solver.atol=1e-12"])
            complete = rd["status"] == "complete" and ref["status"] == "complete"
            md_cpu = f"{md['cpu']:.3g}" if md.get("ok") else "unstable"
            rd_cpu = f"{rd['cpu']:.3g}" if rd["status"] == "complete" else rd["status"]
            ratio = (f"{md['cpu'] / rd['cpu']:.2f}" if md.get("ok")
                     and rd["status"] == "complete" else "")
            rd_err = f"{tip_l2(rd['time'], rd['tip'], ref):.1e}" if complete else ""
            md_err, md_self = "", ""
            if md.get("ok") and ref["status"] == "complete":
                md_err = f"{tip_l2(ref['time'][:len(md['tip'])], md['tip'], ref):.1e}"
            if md.get("ok"):
                fine = run_moordyn(py, work, n, dt / 4, ACCURACY_SPAN)
                if fine.get("ok"):
                    k = min(len(fine["tip"]), len(md["tip"]))
                    d = np.linalg.norm(md["tip"][:k] - fine["tip"][:k], axis=1)
                    md_time_error = float(np.sqrt(np.mean(d ** 2)))
                    md_self = f"{md_time_error:.1e}"
                    if ref["status"] == "complete":
                        for method in ("auto", *args.methods.split()):
                            equal_rows.append(at_equal_accuracy(
                                exe, work, n, args.t_end, ref, md, md_time_error, args.repeat,
                                method))
                            print(equal_rows[-1], flush=True)
            dt_text = f"{dt:.3g}" if dt else "none stable (or MoorDyn crashed)"
            row = (f"| {n} | {dt_text} | {zeta:.4f} | {md_cpu} | auto ({rd.get('methods', '')}) "
                   f"| {rd.get('steps', '')} | {rd_cpu} | {ratio} | {rd_err} | "
                   f"{rd.get('balance', float('nan')):.1e} | {md_self} | {md_err} |")
            rows.append(row)
            print(row, flush=True)
    if args.no_write:
        return 0 if args.only_undamped else coupled_main(args, exe, py)
    if undamped_rows:
        update_doc(DOCS / "performance" / "peers.md", UNDAMPED_BEGIN, UNDAMPED_END, "\n".join([
            UNDAMPED_BEGIN,
            f"Command: `{args.command}` (code: "
            f"tools/ropedyn_tools/studies/bench_peers.py; CPU: the least of "
            f"{args.repeat} runs each). The paper's rope with damping off in both codes, "
            f"{args.undamped_t_end:g} s; MoorDyn without bending stiffness either (a chain of "
            "tension-only springs, whose energy - kinetic, gravity, springs - its driver sums "
            "outside the timed loop), RK4 at the largest step of the ladder that stays "
            f"finite (tip within 1.05 L of the top) and whose energy never rises by m g L, "
            f"over a {args.probe:g} s probe and over "
            "the whole run (no agreement test: without damping and bending the tip differs "
            "by 1 .. 3 cm over 1 s between any step of the ladder and its half); ropedyn: "
            "`method = 'symplectic'`, rtol 1e-3, a record every 0.1 s. The energy error "
            "E - E0 in units of m g L (1.156 J), MoorDyn's of its own energy. Machine: "
            f"{machine()}. Run: {run_stamp()}.", "", UNDAMPED_HEADER,
            "|" + "---|" * (UNDAMPED_HEADER.count("|") - 1), *undamped_rows, UNDAMPED_END]),
            heading="## The undamped rope over 300 s: MoorDyn's RK4 and the symplectic "
                    "method\n\n")
    if args.only_undamped:
        print(f"bench_peers: {DOCS / 'performance' / 'peers.md'}")
        return 0
    lines = [BEGIN,
             f"Command: `{args.command}` (code: "
             f"tools/ropedyn_tools/studies/bench_peers.py; CPU: the least of {args.repeat} runs "
             f"each). MoorDyn-C "
             f"from PyPI `moordyn` in .venv-bench: RK4 at the largest step of the ladder "
             f"2e-4 (30/n) 2^(k/4) that stays finite over a {args.probe:g} s probe, agrees "
             f"there with half the step within 1 % of the length, and stays finite over the "
             f"whole run; "
             f"axial damping BA = eta A, node positions written every {OUT_DT:g} s. "
             f"ropedyn: input/paper.nml with its default method (auto), rtol 1e-6, atol 1e-8, "
             f"an HDF5 record every {OUT_DT:g} s. The tip columns: L2 over the output times "
             f"in [0, {ACCURACY_SPAN:g} s] against ropedyn with cvode at rtol 1e-10, atol "
             f"1e-12, same n; MoorDyn's time error: its tip against its run at a quarter of the "
             f"step (MoorDyn against ropedyn's reference: the difference of the models). "
             f"Machine: {machine()}. Run: {run_stamp()}.", "", header,
             "|---|---|---|---|---|---|---|---|---|---|---|---|",
             *rows, "",
             "At equal accuracy: ropedyn's default method, and the methods "
             f"{', '.join(args.methods.split())} (method:max_order), each at the loosest "
             f"rtol of {', '.join(f'{r:g}' for r in EQUAL_RTOLS)} (atol = rtol / 100) whose "
             "tip error over [0, 2 s] is at most MoorDyn's time error (the same run length, "
             "output and MoorDyn run as above):", "", equal_header,
             "|---|---|---|---|---|---|---|---|---|---|", *equal_rows, END]
    update_doc(DOCS / "performance" / "peers.md", BEGIN, END, "\n".join(lines),
               heading="## The peer side by side: MoorDyn-C (issue 15)\n\n")
    print(f"bench_peers: {DOCS / 'performance' / 'peers.md'}")
    return coupled_main(args, exe, py)


if __name__ == "__main__":
    sys.exit(main())
