"""MoorDyn-C on the Bergdahl chain, side by side with ropedyn: maxima, errors and CPU.

`scripts/bench_peers bergdahl` runs MoorDyn-C (PyPI `moordyn` in .venv-bench, never the
project venv) on the 30 measured conditions of docs/validation/bergdahl.md, with the same
line, water, seabed and fairlead motion as input/validation/bergdahl/base.nml:

- line: d = 3.654 mm (volume-equivalent), 0.0818 kg/m, EA = 1e4 N, BA = 2 N s (the scene's
  axial_damping), EI = 0; Cd = 1.5052 on d (2.5 on 2.2 mm), CdAx on pi d (the scene's
  tangential_drag_coefficient, the same convention), Ca = 3.8, CaAx = 0;
- seabed: MoorDyn multiplies kBot and cBot by d: kBot = 6.6e6 / d Pa/m, cBot = 1469.5 / d
  Pa s/m (the scene's per-metre stiffness and damping); FrictionCoefficient 0.3 (MoorDyn's
  own FricDamp and StatDynFricScale defaults); depth 3 m, rho 1000, g 9.81;
- fairlead: a coupled point driven every 2^-10 s by moordyn.Step on the scene's circle with
  the same quintic ramp over 3 cycles (position and velocity at the start of each coupling
  step); the anchor a fixed point on the seabed 32.554 m away;
- start: MoorDyn's own static solver (moordyn.Init: its dynamic relaxation);
- time integration: RK4 at dtM (default 3.26e-4 s, under its stability limit of about
  3.6e-4 s set by the seabed stiffness), 165 segments (0.2 m, as the scene);
- the fairlead tension every coupling step (GetLineFairTen); its cycle maxima over the last
  5 of 12 cycles, refined like ropedyn's (the vertex of the parabola through the three
  samples about the largest);
- CPU: process time of the whole case, Create and static start included (a result is
  kept in WORK/moordyn/ and reused by a rerun, CPU and all).

ropedyn's side comes from the case files of `scripts/validation bergdahl` (its --work
directory), its CPU from their /solver/cpu_time (the integration; the totals add the
static start per case, bergdahl.static_start_cpu), and only from those of the code of the
executable (--exe, else the Release build): a case file of other code is refused. The table
goes between the bergdahl_peers markers of docs/performance/peers.md.
"""
import argparse
import json
import pathlib
import subprocess
import sys
import tempfile
import time

import numpy as np

from ropedyn_tools.arguments import list_text, positive
from ropedyn_tools.repo import DOCS, ROOT, add_exe_argument, exe_or_build
from ropedyn_tools.studies import bergdahl as bg
from ropedyn_tools.studies.bench_peers import ensure_bench_venv
from ropedyn_tools.studies.common import machine, run_stamp, shown_arguments, update_doc
from ropedyn.docstrings import summary

BEGIN, END = "<!-- bergdahl_peers:begin -->", "<!-- bergdahl_peers:end -->"
D = 0.003654
K_GROUND, C_GROUND = 6.6e6, 1469.5      # per metre of chain, as the scene
CT_WIDTH = 0.09582                      # the scene's tangential drag coefficient (on pi d)
CT_PERIMETER = 0.30104                  # the other reading: 0.5 on the 2.2 mm perimeter
COUPLING = 2.0 ** -10

DRIVER = r"""
import json, math, sys, time
import moordyn
path, period, radius, cycles, ramp, dt = (sys.argv[1], float(sys.argv[2]), float(sys.argv[3]),
                                          int(sys.argv[4]), int(sys.argv[5]), float(sys.argv[6]))
c0 = time.process_time()
s = moordyn.Create(path)
moordyn.Init(s, [0.0, 0.0, 0.3], [0.0, 0.0, 0.0])
line = moordyn.GetLine(s, 1)
static = moordyn.GetLineFairTen(line)
c_static = time.process_time() - c0
w, t_ramp, t_end = 2 * math.pi / period, ramp * period, cycles * period
def smooth(t):
    u = min(max(t / t_ramp, 0.0), 1.0)
    return u**3 * (10 - 15 * u + 6 * u * u), 30 * u * u * (1 - u)**2 / t_ramp if u < 1 else 0.0
t, ten = 0.0, []
steps = int(round(t_end / dt))
for k in range(steps):
    a, da = smooth(t)
    c, sn = math.cos(w * t), math.sin(w * t)
    x = [a * radius * c, 0.0, 0.3 - a * radius * sn]
    v = [radius * (da * c - a * w * sn), 0.0, -radius * (da * sn + a * w * c)]
    moordyn.Step(s, x, v, t, dt)
    t = (k + 1) * dt
    ten.append(moordyn.GetLineFairTen(line))
cpu = time.process_time() - c0
moordyn.Close(s)
print("RESULT " + json.dumps({"cpu": cpu, "static_cpu": c_static, "static": static,
                               "tension": ten}), flush=True)
"""


def moordyn_file(path, segments, dt_m, ct):
    path.write_text(f"""--------------------- MoorDyn Input File ------------------------------------
ropedyn bench_peers bergdahl: the chain of Bergdahl et al. (2016)
----------------------- LINE TYPES ------------------------------------------
TypeName   Diam     Mass/m     EA     BA/-zeta    EI    Cd     Ca    CdAx    CaAx
(name)     (m)      (kg/m)     (N)    (N-s/-)    (N-m^2) (-)  (-)   (-)     (-)
chain      {D}  0.0818  1.0e4  2.0  0.0  1.5052  3.8  {ct:.6g}  0.0
---------------------- POINTS --------------------------------
ID   Attachment  X       Y     Z      Mass   Volume  CdA    Ca
(#)   (-)        (m)    (m)   (m)     (kg)   (m^3)   (m^2)  (-)
1    Fixed       -32.554  0     -3.0    0      0       0      0
2    Coupled     0        0     0.3     0      0       0      0
---------------------- LINES --------------------------------------
ID    LineType   AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#)   (name)     (#)      (#)      (m)       (-)       (-)
1     chain      1        2        33.0      {segments}        -
---------------------- OPTIONS -----------------------------------------
{dt_m:.6g}   dtM
9.81     g
3.0      WtrDpth
1000.0   rho
{K_GROUND / D:.6g}  kBot
{C_GROUND / D:.6g}  cBot
0.3      FrictionCoefficient
RK4      tScheme
------------------------- need this line --------------------------------------
""")


def run_case(py, work, period, radius, segments, dt_m, ct=CT_WIDTH, cycles=bg.CYCLES,
             cache=None):
    """MoorDyn on one condition: its cycle maxima, CPU and static tension. With a cache
    directory the result is kept there as JSON and reused by a rerun."""
    key = f"T{period:g}_R{radius:g}_n{segments}_dt{dt_m:g}_ct{ct:g}_c{cycles}.json"
    if cache is not None and (cache / key).exists():
        r = json.loads((cache / key).read_text())
        r["maxima"] = np.array(r["maxima"])
        return r
    r = run_moordyn(py, work, period, radius, segments, dt_m, ct, cycles)
    if cache is not None and r.get("ok"):
        cache.mkdir(parents=True, exist_ok=True)
        (cache / key).write_text(json.dumps(dict(r, maxima=list(r["maxima"]))))
    return r


def run_moordyn(py, work, period, radius, segments, dt_m, ct, cycles):
    f = work / f"chain_{segments}_{dt_m:g}_{ct:g}.txt"
    moordyn_file(f, segments, dt_m, ct)
    proc = subprocess.run([str(py), "-c", DRIVER, str(f), str(period), str(radius),
                           str(cycles), str(bg.RAMP_CYCLES), str(COUPLING)],
                          capture_output=True, text=True, cwd=work, timeout=7200)
    for line in proc.stdout.splitlines()[::-1]:
        if "RESULT " in line:          # MoorDyn's progress shares the line
            r = json.loads(line.split("RESULT ", 1)[1])
            ten = np.array(r.pop("tension"))
            if not np.all(np.isfinite(ten)):
                return {"ok": False, "error": "the tension is not finite (unstable)"}
            t = COUPLING * np.arange(1, len(ten) + 1)
            m = bg.cycle_maxima(t, ten, period, min(bg.ANALYSED, cycles))
            r.update(maxima=m, mean=float(m.mean()), spread=float(m.std(ddof=1))
                     if len(m) > 1 else 0.0, ok=bool(np.all(np.isfinite(ten))))
            return r
    return {"ok": False, "error": (proc.stderr.strip().splitlines() or ["no output"])[-1]}


def main(argv=None):
    parser = argparse.ArgumentParser(description=summary(__doc__))
    parser.add_argument("--work", default=str(ROOT / "out" / "bergdahl"),
                        help="the case files of scripts/validation bergdahl")
    parser.add_argument("--segments", type=int, default=165)
    parser.add_argument("--dt", type=float, default=3.26e-4, help="MoorDyn's dtM (s)")
    parser.add_argument("--periods", type=list_text(positive(float), ","),
                        default=",".join(str(p) for p in bg.PERIODS))
    parser.add_argument("--radii", type=list_text(positive(float), ","),
                        default=",".join(str(r) for r in bg.RADII))
    parser.add_argument("--convergence", action="store_true",
                        help="also T = 1.25 and 3.5 s at R = 0.2 m with dtM halved and the "
                             "segments doubled")
    parser.add_argument("--perimeter", action="store_true",
                        help="also every condition with the other reading of the tangential "
                             "drag (0.5 on the 2.2 mm perimeter)")
    parser.add_argument("--no-write", action="store_true")
    add_exe_argument(parser)
    args = parser.parse_args(argv)
    periods = [float(p) for p in args.periods.split(",")]
    radii = [float(r) for r in args.radii.split(",")]
    work = pathlib.Path(args.work).resolve()
    exe = pathlib.Path(exe_or_build(args.exe)).resolve()
    bg.refuse_stale([bg.case_path(work, p, m, r) for m in bg.MODELS for p in periods
                     for r in radii], work, exe, bg.exe_version(exe), "bench_peers bergdahl",
                    "run scripts/validation bergdahl first")
    py = ensure_bench_venv()
    ours = bg.collect(work, periods, bg.MODELS)
    cache = work / "moordyn"
    rows, md_res, md_per = [], {}, {}
    w0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        for period in periods:
            for radius in radii:
                r = run_case(py, tmp, period, radius, args.segments, args.dt, cache=cache)
                md_res[period, radius] = r
                meas = bg.MEASURED[period][bg.RADII.index(radius)]
                cells = [f"{period}", f"{radius}", f"{meas}"]
                if r.get("ok"):
                    cells += [f"{r['mean']:.2f}", f"{100 * (r['mean'] / meas - 1):+.1f} %",
                              f"{r['cpu']:.1f}"]
                else:
                    cells += [r.get("error", "failed")[:60], "", ""]
                if args.perimeter:
                    rp = run_case(py, tmp, period, radius, args.segments, args.dt,
                                  ct=CT_PERIMETER, cache=cache)
                    md_per[period, radius] = rp
                    cells += [f"{rp['mean']:.2f}", f"{100 * (rp['mean'] / meas - 1):+.1f} %"]
                for model in bg.MODELS:
                    o = ours.get((model, period, radius))
                    cells += ([f"{o['mean']:.2f}", f"{100 * (o['mean'] / meas - 1):+.1f} %",
                               f"{o['cpu_time']:.1f}"] if o else ["–", "–", "–"])
                rows.append("| " + " | ".join(cells) + " |")
                print(rows[-1], flush=True)
        wall = time.perf_counter() - w0
        conv = []
        if args.convergence:
            for period in (1.25, 3.5):
                base = md_res.get((period, 0.2)) or run_case(
                    py, tmp, period, 0.2, args.segments, args.dt, cache=cache)
                for segs, dt in ((args.segments, args.dt / 2), (2 * args.segments, args.dt),
                                 (2 * args.segments, args.dt / 2)):
                    r = run_case(py, tmp, period, 0.2, segs, dt, cache=cache)
                    if r.get("ok"):
                        conv.append(f"| {period} | {segs} | {dt:.3g} | {r['mean']:.3f} | "
                                    f"{100 * (r['mean'] / base['mean'] - 1):+.2f} % | "
                                    f"{r['cpu']:.1f} |")
                    else:
                        conv.append(f"| {period} | {segs} | {dt:.3g} | failed: "
                                    f"{r.get('error', 'not finite')[:50]} | | |")
                    print(conv[-1], flush=True)
    ok = [(k, r) for k, r in md_res.items() if r.get("ok")]
    lines = [BEGIN, "",
             f"Command: `{' '.join(['scripts/bench_peers bergdahl', *shown_arguments(argv if argv is not None else sys.argv[1:])])}` (code: "
             f"tools/ropedyn_tools/studies/bench_peers_bergdahl.py). MoorDyn-C 2.7.2 (PyPI "
             f"`moordyn`, .venv-bench): RK4 at dtM = {args.dt:g} s, {args.segments} segments, "
             f"its static start; CPU per case includes it. ropedyn: the case files of "
             f"`scripts/validation bergdahl`, CPU of the integration (/solver/cpu_time) and, in the "
             f"totals, of the static start. "
             f"Machine: {machine()}. Run: {run_stamp()}; MoorDyn's CPU is that of its own runs "
             f"(one after the other, on the shared cores; a kept result keeps its CPU; this "
             f"command took {wall:.0f} s).", ""]
    if ok:
        comp = [r["mean"] for _, r in ok]
        meas = [bg.MEASURED[p][bg.RADII.index(rad)] for (p, rad), _ in ok]
        s = bg.scores(comp, meas)
        cpu = [r["cpu"] for _, r in ok]
        static = [r["static_cpu"] for _, r in ok]
        lines += [f"MoorDyn-C over {len(ok)} conditions: RMSE {s['rmse']:.2f} N, MAPE "
                  f"{s['mape']:.2f} %, bias {s['bias']:+.2f} N, correlation {s['corr']:.4f}; "
                  f"CPU {np.mean(cpu):.1f} s per case ({np.mean(static):.1f} s of it the static "
                  f"start), {np.sum(cpu):.0f} s in all.", ""]
        for model in bg.MODELS:
            ro = [ours[model, p, rad] for (p, rad), _ in ok if (model, p, rad) in ours]
            start = bg.static_start_cpu(work, model)
            if len(ro) == len(ok) and start is not None:
                # MoorDyn's CPU includes its static start: ropedyn's with its own, which is
                # the same for every condition (scripts/validation bergdahl measures it)
                oc = sum(o["cpu_time"] for o in ro) + len(ro) * start
                lines.append(f"- ropedyn {model.upper()} on the same cases: CPU {oc:.0f} s "
                             f"({start:.2f} s of it per case the static start); "
                             f"MoorDyn / ropedyn = {np.sum(cpu) / oc:.2f}.")
        lines.append("")
    if md_per:
        okp = [(k, r) for k, r in md_per.items() if r.get("ok")]
        s = bg.scores([r["mean"] for _, r in okp],
                      [bg.MEASURED[p][bg.RADII.index(rad)] for (p, rad), _ in okp])
        lines += [f"MoorDyn-C with the other reading of the tangential drag (0.5 on the 2.2 mm "
                  f"perimeter, CdAx = {CT_PERIMETER}): RMSE {s['rmse']:.2f} N, MAPE "
                  f"{s['mape']:.2f} %, bias {s['bias']:+.2f} N, correlation {s['corr']:.4f}.",
                  ""]
    per_head = " MoorDyn, perimeter (N) | error |" if md_per else ""
    lines += ["| T (s) | R (m) | measured (N) | MoorDyn (N) | error | CPU (s) |" + per_head +
              " RFEM (N) | error | CPU (s) | MPP (N) | error | CPU (s) |",
              "|---|---|---|---|---|---|" + ("---|---|" if md_per else "") +
              "---|---|---|---|---|---|", *rows]
    if conv:
        lines += ["", "MoorDyn's convergence at R = 0.2 m (change of the mean cycle maximum "
                      f"against {args.segments} segments, dtM {args.dt:g} s):", "",
                  "| T (s) | segments | dtM (s) | mean cycle max (N) | change | CPU (s) |",
                  "|---|---|---|---|---|---|", *conv]
    lines.append(END)
    if not args.no_write:
        update_doc(DOCS / "performance" / "peers.md", BEGIN, END, "\n".join(lines),
                   heading="## MoorDyn-C on the Bergdahl chain\n\n")
        print(f"bench_peers bergdahl: {DOCS / 'performance' / 'peers.md'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
