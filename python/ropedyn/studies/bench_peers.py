"""The peer side by side: MoorDyn-C and ropedyn's default method on the paper's rope.

MoorDyn-C (PyPI `moordyn`, a lumped-mass line with bending, explicit RK4 at a fixed step)
runs in its own benchmark venv (.venv-bench, created here on first use; never the project
venv) on the same rope as input/paper.nml: EA = E A, EI = E I, mass per length rho A,
diameter d, pinned top, straight at 75 degrees (the free end placed at the rope's length
from the top: MoorDyn's initial catenary of a taut line is the straight line; no dynamic
relaxation, Init_NoIC), gravity only (fluid density of air, drag and added mass off).
Damping: the same damping ratio of a segment's axial mode as ropedyn's Kelvin-Voigt eta
gives, zeta = eta A n / (2 L sqrt(EA mu)) (MoorDyn's negative BA is that ratio). Its time
step is the largest of a geometric ladder for which the run stays finite with the tip
within 5 % of the rope's length of the top (a 5 s probe). ropedyn runs the paper scene
with its default method; CPU times (process time of the stepping alone for MoorDyn, the
run's /solver/cpu_time for ropedyn) and their ratio go between the bench_peers markers of
docs/benchmarks.md. The code of scripts/bench_peers.

Status (issue 15, not finished): MoorDyn-C 2.7.2's `Create` segfaults on this input in most
runs here (faulthandler: inside cmoordyn's Create; one run of the same file completed:
3.5 s CPU for 30 s at n = 30, dt = 2e-4), so the table has not been written yet.
"""
import argparse
import json
import math
import pathlib
import subprocess
import sys
import tempfile

from ropedyn import io
from ropedyn.run import DOCS, PAPER, add_exe_argument, exe_or_build, set_args
from ropedyn.studies.common import machine, update_doc, utc_stamp

BEGIN = "<!-- bench_peers:begin -->"
END = "<!-- bench_peers:end -->"
ROOT = DOCS.parent
BENCH_VENV = ROOT / ".venv-bench"

# input/paper.nml
LENGTH, DENSITY, DIAMETER, YOUNG, ETA = 1.0, 6000.0, 0.005, 35.0e6, 1.0e3
ANGLE = math.radians(75.0)

DRIVER = r'''
import json, sys, time, math
import moordyn
path, t_end, dt_out = sys.argv[1], float(sys.argv[2]), float(sys.argv[3])
s = moordyn.Create(path)
moordyn.Init_NoIC(s, [], [])
line = moordyn.GetLine(s, 1)
n = moordyn.GetLineNumberNodes(line)
top = moordyn.GetLineNodePos(line, 0)
t, ok, c = 0.0, True, time.process_time()
steps = int(round(t_end / dt_out))
for k in range(steps):
    moordyn.Step(s, [], [], t, dt_out)
    t += dt_out
    p = moordyn.GetLineNodePos(line, n - 1)
    r = math.dist(p, top)
    if not (math.isfinite(r) and r < 1.05 * float(sys.argv[4])):
        ok = False
        break
cpu = time.process_time() - c
print("RESULT " + json.dumps({"cpu": cpu, "ok": ok, "t": t}), flush=True)
'''


def moordyn_file(path, n, dt):
    area = math.pi * DIAMETER ** 2 / 4
    ea, mu = YOUNG * area, DENSITY * area
    ei = YOUNG * math.pi * DIAMETER ** 4 / 64
    zeta = ETA * area * n / (2 * LENGTH * math.sqrt(ea * mu))
    x, z = LENGTH * math.sin(ANGLE), -1.0 - LENGTH * math.cos(ANGLE)
    path.write_text(f"""--------------------- MoorDyn Input File ------------------------------------
ropedyn bench_peers: the paper's rope
----------------------- LINE TYPES ------------------------------------------
TypeName   Diam     Mass/m     EA     BA/-zeta    EI    Cd     Ca    CdAx    CaAx
(name)     (m)      (kg/m)     (N)    (N-s/-)    (N-m^2) (-)  (-)   (-)     (-)
rope       {DIAMETER}  {mu:.6g}  {ea:.6g}  {-zeta:.6g}  {ei:.6g}  0.0  0.0  0.0  0.0
---------------------- POINTS --------------------------------
ID   Attachment  X       Y     Z      Mass   Volume  CdA    Ca
(#)   (-)        (m)    (m)   (m)     (kg)   (m^3)   (m^2)  (-)
1    Fixed       0      0     -1.0    0      0       0      0
2    Free        {x:.10f}   0    {z:.10f}  0      0       0      0
---------------------- LINES --------------------------------------
ID    LineType   AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#)   (name)     (#)      (#)      (m)       (-)       (-)
1     rope       1        2        {LENGTH}       {n}        -
---------------------- OPTIONS -----------------------------------------
{dt:.6g}   dtM
9.81     g
10.0     WtrDpth
1.2      rho
RK4      tScheme
""")
    return zeta


def ensure_bench_venv():
    py = BENCH_VENV / "bin" / "python"
    if not py.exists():
        subprocess.run([sys.executable, "-m", "venv", str(BENCH_VENV)], check=True)
    if subprocess.run([str(py), "-c", "import moordyn"], capture_output=True).returncode:
        subprocess.run([str(py), "-m", "pip", "install", "-q", "moordyn"], check=True)
    return py


def run_moordyn(py, workdir, n, dt, t_end):
    f = workdir / f"rope_{n}.txt"
    moordyn_file(f, n, dt)
    # MoorDyn prints its progress; keep stdout and stderr apart (it has crashed here
    # with both on one pipe) and read the result line printed before it closes
    proc = subprocess.run([str(py), "-X", "faulthandler", "-c", DRIVER, str(f), str(t_end),
                           "0.01", str(LENGTH)], capture_output=True, text=True,
                          cwd=workdir, timeout=3600)
    for line in proc.stdout.splitlines()[::-1]:
        if "RESULT " in line:
            return json.loads(line.split("RESULT ", 1)[1])
    return {"ok": False, "cpu": float("nan"), "t": 0.0}


def largest_stable_dt(py, workdir, n, probe):
    """The largest step of the ladder 2e-4 (30/n) * 2^(k/2) that stays stable."""
    base = 2.0e-4 * 30.0 / n
    best = None
    for k in range(4, -7, -1):
        dt = base * 2.0 ** (k / 2)
        r = run_moordyn(py, workdir, n, dt, probe)
        if r["ok"]:
            best = dt
            break
    return best


def run_ropedyn(exe, workdir, n, t_end):
    out = workdir / f"ropedyn_{n}.h5"
    cmd = [str(exe), "run", str(PAPER), *set_args([
        f"model.elements={n}", f"solver.t_end={t_end}", f'output.file="{out}"'])]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=7200)
    if proc.returncode != 0:
        return {"status": "failed: " + proc.stderr.strip()[:80]}
    run = io.load_run(out)
    total, dissipated = run.energy["total"], run.energy["dissipated"]
    methods = ""
    import h5py
    with h5py.File(out, "r") as f:
        if "/solver/switch_method" in f:
            methods = " -> ".join(m.decode().strip() for m in f["/solver/switch_method"][()])
    return {"status": "complete", "cpu": float(run.stats["cpu_time"]),
            "steps": int(run.stats["steps"]), "methods": methods,
            "balance": float(abs(total + dissipated - total[0]).max())}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_exe_argument(parser)
    parser.add_argument("--t-end", type=float, default=30.0)
    parser.add_argument("--probe", type=float, default=5.0, help="stability probe (s)")
    parser.add_argument("--elements", default="10 30 100")
    parser.add_argument("--no-write", action="store_true")
    args = parser.parse_args(argv)
    exe = exe_or_build(args.exe)
    py = ensure_bench_venv()
    header = ("| n | MoorDyn dt (s) | MoorDyn damping ratio | MoorDyn CPU (s) | ropedyn method "
              "| ropedyn steps | ropedyn CPU (s) | MoorDyn / ropedyn | ropedyn balance error (J) |")
    rows = []
    print(header, flush=True)
    with tempfile.TemporaryDirectory() as tmp:
        work = pathlib.Path(tmp)
        for n in (int(x) for x in args.elements.split()):
            dt = largest_stable_dt(py, work, n, args.probe)
            zeta = moordyn_file(work / "z.txt", n, dt or 1e-4)
            md = run_moordyn(py, work, n, dt, args.t_end) if dt else {"ok": False}
            rd = run_ropedyn(exe, work, n, args.t_end)
            md_cpu = f"{md['cpu']:.3g}" if md.get("ok") else "unstable"
            rd_cpu = f"{rd['cpu']:.3g}" if rd["status"] == "complete" else rd["status"]
            ratio = (f"{md['cpu'] / rd['cpu']:.2f}" if md.get("ok")
                     and rd["status"] == "complete" else "")
            dt_text = f"{dt:.3g}" if dt else "none stable (or MoorDyn crashed)"
            row = (f"| {n} | {dt_text} | {zeta:.4f} | {md_cpu} | auto ({rd.get('methods', '')}) "
                   f"| {rd.get('steps', '')} | {rd_cpu} | {ratio} | "
                   f"{rd.get('balance', float('nan')):.1e} |")
            rows.append(row)
            print(row, flush=True)
    if args.no_write:
        return 0
    lines = [BEGIN,
             f"Command: `scripts/bench_peers --t-end {args.t_end:g} --elements "
             f"\"{args.elements}\"` (MoorDyn-C from PyPI `moordyn` in .venv-bench, RK4 at the "
             f"largest stable step of the ladder, {args.probe:g} s probe; ropedyn: "
             f"input/paper.nml with its default method, rtol 1e-6). Machine: {machine()}. "
             f"Run: {utc_stamp()}.", "", header, "|---|---|---|---|---|---|---|---|---|",
             *rows, END]
    update_doc(DOCS / "benchmarks.md", BEGIN, END, "\n".join(lines),
               heading="## The peer side by side: MoorDyn-C (issue 15)\n\n")
    print(f"bench_peers: {DOCS / 'benchmarks.md'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
