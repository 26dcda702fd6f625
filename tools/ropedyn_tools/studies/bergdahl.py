"""Validation against a measured chain, the Bergdahl experiment: writes docs/validation/bergdahl.md.

Bergdahl, Palm, Eskilsson and Lindahl (2016), "Dynamically scaled model experiment of a
mooring cable", J. Mar. Sci. Eng. 4(1):5, measured the mean cycle maximum of the fairlead
tension of a 33 m chain whose fairlead moves on a circle, for 6 periods T x 5 radii R. The
scene and the sweeps are input/validation/bergdahl/ (base.nml, sweeps/T*.nml, one file per
period: the ramp and the end time are multiples of T). This study runs their cases (RFEM and
MPP, two at a time, the longest periods first), takes the cycle maxima of |top reaction| over the last 5 of
12 cycles, and compares them with the measurement; the convergence runs (element length and
tolerance halved) on demand.

The case files in --work are kept between runs, but only those of the same code: a file
is used (and not run again) when its /@version is the executable's, or a commit from which
no commit up to the executable's counts against this page (scripts/docs_status's rule). Any
other is run again; --analyse-only refuses to analyse it.

    scripts/validation bergdahl [--models rfem,mpp] [--convergence] [--quick] [--out PAGE]
    (python -m ropedyn_tools.studies.bergdahl; without --exe it builds the Release executable)
"""
import argparse
import functools
import json
import math
import os
import pathlib
import re
import subprocess
import sys
import time

import h5py
import numpy as np

from ropedyn_tools.arguments import choice, list_text, positive
from ropedyn_tools.repo import DOCS, INPUT, ROOT, add_exe_argument, exe_or_build, set_args
from ropedyn_tools.docs_status import same_code
from ropedyn_tools.studies.common import (least_cpu, run_stamp, scene_number, shown_arguments,
                                          update_doc)
from ropedyn.docstrings import summary

SCENE_DIR = INPUT / "validation" / "bergdahl"
BASE = SCENE_DIR / "base.nml"
PERIODS = (1.25, 1.5, 2.0, 2.5, 3.0, 3.5)
RADII = (0.075, 0.1, 0.125, 0.15, 0.2)
#: mean cycle maximum of the fairlead tension (N), measured; rows T, columns R
MEASURED = {1.25: (42.5, 46.8, 54.1, 60.4, 70.3),
            1.50: (41.0, 45.3, 51.5, 59.0, 68.0),
            2.00: (36.0, 39.5, 47.5, 54.1, 62.3),
            2.50: (31.1, 35.4, 42.5, 49.0, 57.3),
            3.00: (29.5, 33.1, 39.3, 45.8, 54.0),
            3.50: (27.8, 31.5, 37.5, 42.5, 50.1)}
CYCLES, RAMP_CYCLES, ANALYSED = 12, 3, 5
#: the convergence runs: more cycles, so that the mean's sampling error (about 0.25 % over 5
#: cycles at T = 1.25 s, R = 0.2 m, whose maxima vary from cycle to cycle) is well below the
#: 0.5 % the runs must resolve
CONV_CYCLES, CONV_ANALYSED = 30, 25
MODELS = ("rfem", "mpp")
#: variants of a model (label MODEL_VARIANT, e.g. rfem_perimeter): their extra keys.
#: perimeter: the paper's tangential drag 0.5 read on the 2.2 mm perimeter (0.5 x 2.2 / 3.654
#: on our pi d), the reading the page does not take (docs/validation/bergdahl.md)
VARIANTS = {"perimeter": ["fluid.tangential_drag_coefficient=0.30104"]}
#: the labels --models takes
LABELS = (*MODELS, *(f"{m}_{v}" for m in MODELS for v in VARIANTS))
LENGTH = 33.0
#: the two conditions whose tension histories the page shows
HISTORIES = ((1.25, 0.2), (3.5, 0.075))
BEGIN, END = "<!-- bergdahl:begin -->", "<!-- bergdahl:end -->"
#: the section the case files' numbers go into (whose numbers-unchanged commits keep them)
SECTION = "bergdahl"


def sweep_path(period):
    return SCENE_DIR / "sweeps" / (f"T{period:.2f}".replace(".", "") + ".nml")


# ---------------------------------------------------------------- analysis

def peak(t, f, i):
    """The maximum near sample i of the sampled f(t): the vertex of the parabola through
    samples i-1, i, i+1 (the sample itself at an end or where the three are collinear)."""
    if i == 0 or i == len(f) - 1:
        return f[i]
    a, b, c = f[i - 1], f[i], f[i + 1]
    den = a - 2 * b + c
    if den >= 0:
        return b
    return b - (a - c) ** 2 / (8 * den)


def cycle_maxima(t, force, period, cycles=ANALYSED):
    """The maxima of force over each of the last `cycles` whole periods before t[-1]."""
    t_end = t[-1]
    maxima = []
    for k in range(cycles, 0, -1):
        lo, hi = t_end - k * period, t_end - (k - 1) * period
        idx = np.nonzero((t >= lo - 1e-9) & (t <= hi + 1e-9))[0]
        if len(idx) < 3:
            raise ValueError(f"cycle [{lo:.3f}, {hi:.3f}] s has {len(idx)} records")
        i = idx[np.argmax(force[idx])]
        maxima.append(peak(t, force, i))
    return np.array(maxima)


def fairlead_tension(path):
    """Times and |top support reaction| (N) of a run file: the fairlead tension."""
    with h5py.File(path, "r") as f:
        t = f["time"][:]
        r = f["supports/top/reaction"][:]
        solver = {k: float(f["solver"][k][()]) for k in ("cpu_time", "steps", "err_test_fails")
                  if k in f["solver"]}
        if "wall_time" in f["solver"]:
            solver["wall_time"] = float(f["solver/wall_time"][()])
    return t, np.hypot(r[:, 0], r[:, 1]), solver


def deepest(path, period, cycles=ANALYSED):
    """How far the rope's deepest point goes below the floor (m) over the last `cycles`
    cycles of a run file (the floor: the scene's &ground point, normal (-1, 0))."""
    floor = scene_number(BASE, "point")
    with h5py.File(path, "r") as f:
        t = f["time"][:]
        first = int(np.searchsorted(t, t[-1] - cycles * period))
        x = f["rope/points"][first:, :, 0]
    return float(np.max(x) - floor)


def static_sinking():
    """The floor law's sinking of rope lying still in water, (m - rho_w A) g / k (m)."""
    submerged = (scene_number(BASE, "mass_per_length") - scene_number(BASE, "density")
                 * math.pi / 4 * scene_number(BASE, "diameter") ** 2)
    return submerged * scene_number(BASE, "gravity") / scene_number(BASE, "stiffness")


def case_result(path, period, cycles=ANALYSED):
    t, tension, solver = fairlead_tension(path)
    m = cycle_maxima(t, tension, period, cycles)
    return dict(maxima=m, mean=float(m.mean()), spread=float(m.std(ddof=1)) if len(m) > 1
                else 0.0, deepest=deepest(path, period, cycles), **solver)


def scores(computed, measured):
    """RMSE (N), mean absolute percentage error (%), bias (N, computed - measured) and the
    correlation of computed with measured."""
    c, m = np.asarray(computed, float), np.asarray(measured, float)
    err = c - m
    corr = float(np.corrcoef(c, m)[0, 1]) if len(c) > 1 else float("nan")
    return dict(rmse=float(np.sqrt(np.mean(err ** 2))),
                mape=float(100 * np.mean(np.abs(err) / m)),
                bias=float(err.mean()), corr=corr, worst=float(100 * np.max(np.abs(err) / m)))


# ---------------------------------------------------------------- running

def base_elements():
    return int(scene_number(BASE, "elements"))


def base_rtol():
    """The study's setting: the base scene's rtol."""
    return scene_number(BASE, "rtol")


def base_atol():
    """The study's setting: the base scene's atol (halved with rtol in the convergence
    runs)."""
    return scene_number(BASE, "atol")


def at_setting(row):
    """Whether a convergence row has the study's element count and tolerance."""
    return row["n"] == base_elements() and row["rtol"] == base_rtol()


def is_base(row):
    """Whether a convergence row is the run at the study's setting."""
    return at_setting(row) and not row["law"]


def reference(rows, row):
    """The convergence row a row's change is measured against: the study's setting, with the
    law of the row (the runs with another law measure its share of the change; a row whose
    label has no run at the setting, another method's, against the scene's own)."""
    same = [r for r in rows if r["model"] == row["model"] and r["period"] == row["period"]
            and at_setting(r)]
    return next((r for r in same if r["law"] == row["law"]),
                next(r for r in same if not r["law"]))


def write_sweep(period, label, work, quick=None):
    """The period's sweep file for model label (MODEL or MODEL_VARIANT) in its folder
    work/LABEL/T<..>: the shipped file (the RFEM's) with the model, the variant's keys and,
    for quick = (elements, cycles), that many elements and cycles and a one-cycle ramp (a
    smoke test of the pipeline)."""
    model, _, variant = label.partition("_")
    src = sweep_path(period)
    out = work / label / src.stem
    out.mkdir(parents=True, exist_ok=True)
    text = src.read_text().replace("base = '../base.nml'", f"base = '{BASE}'")
    text = re.sub(r"^    models = .*$", f"    models = '{model}'", text, flags=re.M)
    sets = list(VARIANTS[variant]) if variant else []
    if quick is not None:
        text = text.replace(f"'solver.t_end={CYCLES * period:.12g}'",
                            f"'solver.t_end={quick[1] * period:.12g}'")
        text = text.replace(f"'supports.top_ramp_time={RAMP_CYCLES * period:.12g}'",
                            f"'supports.top_ramp_time={period:.12g}'")
        sets.append(f"model.elements={quick[0]}")
    if sets:
        text = text.replace("    set = ", "    set = " +
                            "".join(f"'{s}', " for s in sets), 1)
    sweep = out / src.name
    sweep.write_text(text)
    return sweep


def static_start_cpu(work, label, exe=None, repeat=3):
    """The CPU (s, user + system, the least of `repeat`) of one static start of model label
    (`ropedyn statics` of the base scene with the model and variant keys): the same
    equilibrium starts every condition (the fairlead's motion grows from zero), and a run's
    /solver/cpu_time does not include it. Kept in work/LABEL/static_start.json with the
    version that measured it; measured when missing, or (exe given) of other code than exe's;
    None when missing and no exe is given."""
    import resource
    path = work / label / "static_start.json"
    version = exe_version(exe) if exe is not None else None
    if path.exists():
        record = json.loads(path.read_text())
        if exe is None or same_code_as(record.get("version", ""), version):
            return record["cpu"]
    if exe is None:
        return None
    model, _, variant = label.partition("_")
    sets = [f"model.kind={model}", *(VARIANTS[variant] if variant else [])]
    path.parent.mkdir(parents=True, exist_ok=True)

    def one():
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        subprocess.run([str(exe), "statics", str(BASE), *set_args(
            sets + [f"output.file={path.parent / 'static_start.h5'}"])],
            check=True, capture_output=True)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        return {"cpu": after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime}

    best = least_cpu(one, repeat)["cpu"]
    path.write_text(json.dumps({"cpu": best, "repeat": repeat, "version": version}) + "\n")
    return best


def run_sweeps(exe, periods, models, radii, work, jobs, quick=None, version=None):
    """Run the cases of each model into work/MODEL/T<..> (the period sweeps' files), `jobs`
    at a time from one queue, the longest periods first (`ropedyn sweep FILE --task K`:
    one period's sweep alone would leave a core idle while its last case runs), then each
    sweep's summary. A case whose file another code wrote (not current for `version`, the
    executable's) runs anew (`--force`). Returns {model: wall seconds of its cases}, also
    kept in work/MODEL/wall.json for --analyse-only."""
    from concurrent.futures import ThreadPoolExecutor
    walls = {}
    for label in models:
        sweeps = {period: write_sweep(period, label, work, quick) for period in periods}
        queue = [(period, RADII.index(r) + 1) for period in sorted(periods, reverse=True)
                 for r in radii]

        def one(item):
            period, task = item
            sweep = sweeps[period]
            cmd = [str(exe), "sweep", str(sweep), "--output-dir", str(sweep.parent),
                   "--quiet", "--task", str(task)]
            if complete(case_path(work, period, label, RADII[task - 1])):
                cmd.append("--force")                 # complete, but of other code
            result = subprocess.run(cmd, capture_output=True, text=True)
            if result.returncode != 0:
                raise RuntimeError(f"{' '.join(cmd)}: exit {result.returncode}\n"
                                   f"{result.stdout}\n{result.stderr}")

        # the wall time counts only when every case of the queue runs now: kept cases
        # (a rerun) would make it short, and the file keeps the last full measurement
        todo = [(period, task) for period, task in queue
                if not current(case_path(work, period, label, RADII[task - 1]), version)]
        stale = sum(complete(case_path(work, p, label, RADII[t - 1])) for p, t in todo)
        if stale:
            print(f"bergdahl: {label}: {stale} case files of other code: run again",
                  file=sys.stderr)
        w0 = time.perf_counter()
        with ThreadPoolExecutor(max_workers=jobs) as pool:
            list(pool.map(one, todo))
        wall = time.perf_counter() - w0
        for sweep in sweeps.values():   # exit 3 when cases are missing (a subset of radii)
            subprocess.run([str(exe), "sweep", str(sweep), "--output-dir", str(sweep.parent),
                            "--summary"], capture_output=True, text=True)
        if len(todo) == len(queue):
            walls[label] = wall
            (work / label / "wall.json").write_text(json.dumps(
                {"wall": wall, "jobs": jobs, "periods": list(periods),
                 "radii": list(radii)}) + "\n")
        else:
            print(f"bergdahl: {label}: {len(queue) - len(todo)} of {len(queue)} cases kept; "
                  "their wall time is not measured again", file=sys.stderr)
    return walls


def complete(path):
    """Whether a case file exists and holds a complete run."""
    return path.exists() and status(path)[0] == "complete"


def exe_version(exe):
    """The version the executable writes into its files (`ropedyn --version`'s last word)."""
    return subprocess.run([str(exe), "--version"], check=True, capture_output=True,
                          text=True).stdout.split()[-1]


def file_version(path):
    """The /@version of a run file."""
    with h5py.File(path, "r") as f:
        value = f.attrs.get("version", b"")
    return value.decode() if isinstance(value, bytes) else str(value)


@functools.lru_cache(maxsize=None)
def same_code_as(file_version, version):
    """docs_status.same_code for this page's section, once per pair of versions in a
    process: each asks git and reads the numbers-unchanged list (0.12 s a file on 90 case
    files otherwise), and the repository does not change during a run."""
    return same_code(file_version, version, SECTION)


def current(path, version):
    """Whether a file holds a complete run of the code of `version` (see the module's
    docstring)."""
    return complete(path) and same_code_as(file_version(path), version)


def stale_files(paths, version):
    """Those of the complete files `paths` that another code wrote than `version`'s."""
    return [p for p in paths if complete(p) and not current(p, version)]


def refuse_stale(paths, work, exe, version, who, advice):
    """Stop (SystemExit, naming one file and its version) when any of the case files
    `paths` (in `work`) holds a run of other code than the executable exe's (`version`):
    `who` says which command refuses, `advice` what runs them again."""
    stale = stale_files(paths, version)
    if stale:
        raise SystemExit(
            f"{who}: {len(stale)} of the case files in {work} hold runs of other code than "
            f"{exe} ({version}), e.g. {stale[0]} ({file_version(stale[0])}); {advice}")


def name(label):
    """RFEM, MPP, or e.g. 'RFEM, perimeter' for a variant."""
    model, _, variant = label.partition("_")
    return model.upper() + (f", {variant}" if variant else "")


def case_path(work, period, model, radius):
    """The case file of a condition: work/MODEL/T<..>/case_<radius's place>.h5."""
    return work / model / sweep_path(period).stem / f"case_{RADII.index(radius) + 1:04d}.h5"


def sweep_walls(work, models):
    """{model: wall seconds} of the runs of all 30 conditions that run_sweeps made (its
    work/MODEL/wall.json), so that a later --analyse-only still knows them."""
    walls = {}
    for label in models:
        path = work / label / "wall.json"
        if path.exists():
            record = json.loads(path.read_text())
            if len(record["periods"]) * len(record["radii"]) == len(PERIODS) * len(RADII):
                walls[label] = record["wall"]
    return walls


def status(path):
    """The run file's status ('complete', 'failed', ...) and its reason."""
    with h5py.File(path, "r") as f:
        get = lambda k: f.attrs[k].decode() if isinstance(f.attrs.get(k), bytes) else \
            str(f.attrs.get(k, ""))
        return get("status"), get("reason")


def failures(work, periods, models):
    """The case files that are there but not complete: (label, period, radius, reason)."""
    out = []
    for model in models:
        for period in periods:
            for radius in RADII:
                path = case_path(work, period, model, radius)
                if path.exists():
                    state, reason = status(path)
                    if state != "complete":
                        out.append((model, period, radius, f"{state}: {reason}"))
    return out


def collect(work, periods, models, cycles=ANALYSED):
    results = {}
    for model in models:
        for period in periods:
            for radius in RADII:
                path = case_path(work, period, model, radius)
                if complete(path):
                    results[model, period, radius] = case_result(path, period, cycles)
    return results


# ---------------------------------------------------------------- convergence

#: the element counts of the convergence runs: elements of 0.4, 0.2 and 0.1 m
CONV_ELEMENTS = (83, 165, 330)
#: the convergence runs with another law than the scene's: label, overrides (at the two
#: coarsest element lengths, each against its own run at the study's element length)
CONV_LAWS = {"compression": ["rope.compression=.true."]}
#: the runs at the finest element length with another method (against the study's setting):
#: CVODE alone, and CVODE held at BDF2 (A-stable); with the tolerance quartered there, they
#: show what the finest row's change is made of
CONV_METHODS = {"cvode": ["solver.method=cvode"],
                "cvode, max order 2": ["solver.method=cvode", "solver.max_order=2"]}


def convergence_files(work, periods=(1.25, 3.5), models=MODELS):
    """The convergence runs [(model, period, n, rtol, law, atol, file)] (see convergence)."""
    base_n, base_r = base_elements(), base_rtol()
    finest = CONV_ELEMENTS[-1]
    variants = sorted({(n, base_r, "") for n in CONV_ELEMENTS + (base_n,)}) + [
        (base_n, base_r / 2, ""), (base_n, base_r / 4, "")] + [
        (n, base_r, law) for law in CONV_LAWS for n in CONV_ELEMENTS[:2]] + [
        (finest, base_r / 4, "")] + [(finest, base_r, method) for method in CONV_METHODS]
    runs = []
    for model in models:
        for period in periods:
            for n, rtol, law in variants:
                atol = base_atol() * rtol / base_r
                tag = "_" + re.sub(r"[^a-z0-9]+", "_", law) if law else ""
                runs.append((model, period, n, rtol, law, atol, work / "convergence" / (
                    f"{model}_T{period}_n{n}_rtol{rtol:g}_atol{atol:g}{tag}_c{CONV_CYCLES}.h5")))
    return runs


def convergence(exe, work, jobs, periods=(1.25, 3.5), radius=0.2, models=MODELS,
                version=None):
    """Mean cycle maxima at elements of 0.4, 0.2, 0.1 m (CONV_ELEMENTS) and at the
    tolerances (rtol and atol together) halved twice from the study's setting, each run
    CONV_CYCLES cycles with the last CONV_ANALYSED analysed; then the two coarsest element
    lengths with the axial springs carrying compression (the law's share of the change);
    `jobs` runs at a time, each unless its file is current for `version`."""
    from concurrent.futures import ThreadPoolExecutor
    todo = convergence_files(work, periods, models)
    (work / "convergence").mkdir(parents=True, exist_ok=True)

    def one(item):
        model, period, n, rtol, law, atol, out = item
        if current(out, version):
            return
        if out.exists():
            out.unlink()          # a failed or interrupted run, or one of other code: again
        # 330 elements over 30 cycles of 3.5 s take more than the default budget
        sets = [f"model.kind={model}", f"model.elements={n}", f"solver.rtol={rtol:g}",
                f"solver.atol={atol:g}", "solver.max_steps=100000000",
                f"supports.top_frequency={1 / period:.12g}",
                f"solver.t_end={CONV_CYCLES * period:.12g}",
                f"supports.top_ramp_time={RAMP_CYCLES * period:.12g}",
                f"supports.top_amplitude={radius},{radius}", f"output.file={out}"]
        sets += CONV_LAWS.get(law, []) + CONV_METHODS.get(law, [])
        subprocess.run([str(exe), "run", str(BASE), *set_args(sets)], check=True,
                       capture_output=True)

    # the longest first: the two cores stay busy to the end
    with ThreadPoolExecutor(max_workers=jobs) as pool:
        list(pool.map(one, sorted(todo, key=lambda x: -x[1] * x[2])))
    return [dict(model=m, period=p, n=n, rtol=r, law=law,
                 **case_result(out, p, CONV_ANALYSED)) for m, p, n, r, law, _, out in todo]


#: the contact-cost variants: label, overrides (from the run of T = 1.25 s, R = 0.2 m at its
#: 6th cycle, 2 cycles); the floor's law is the scene's unless named
CONTACT_VARIANTS = (
    ("default (auto)", []),
    ("cvode", ["solver.method=cvode"]),
    ("erk", ["solver.method=erk"]),
    ("erk, order-3 pair", ["solver.method=erk", "solver.max_order=3"]),
    ("mebdf", ["solver.method=mebdf"]),
    ("auto, atol 1e-8 (ropedyn's default)", ["solver.atol=1e-8"]),
    ("auto, no friction", ["ground.friction_coefficient=0"]),
    ("cvode, no friction", ["solver.method=cvode", "ground.friction_coefficient=0"]),
    ("auto, no contact damping", ["ground.damping=0"]),
    ("cvode, no contact damping", ["solver.method=cvode", "ground.damping=0"]),
    ("cvode, floor 100 x softer (k/100, c/10: still critical)",
     ["solver.method=cvode", "ground.stiffness=6.6e4", "ground.damping=146.95"]),
    ("cvode, no floor", ["solver.method=cvode", "effects.ground=.false."]),
)


def contact_files(work):
    """The files of the contact-cost variants, in CONTACT_VARIANTS' order."""
    return [work / "contact_cost" / f"variant_{k}.h5" for k in range(len(CONTACT_VARIANTS))]


def contact_cost(exe, work, jobs, period=1.25, radius=0.2, start_cycle=6, cycles=2,
                 version=None):
    """The cost of the floor contact: the same window of the motion (from a record of the
    sweep's run) with each of CONTACT_VARIANTS, each run unless its file is current for
    `version`; rows (label, steps, rejected, rhs, CPU)."""
    from concurrent.futures import ThreadPoolExecutor
    src = case_path(work, period, "rfem", radius)
    if not src.exists():
        return []
    t0 = start_cycle * period
    common = [f"supports.top_frequency={1 / period:.12g}",
              f"supports.top_ramp_time={RAMP_CYCLES * period:.12g}",
              f"supports.top_amplitude={radius},{radius}", "initial.shape=state",
              f"initial.state_file={src}", f"initial.state_time={t0:.12g}",
              f"solver.t_end={t0 + cycles * period:.12g}"]
    folder = work / "contact_cost"
    folder.mkdir(parents=True, exist_ok=True)

    def one(k):
        out = contact_files(work)[k]
        if not current(out, version):
            if out.exists():
                out.unlink()                  # of other code, or not complete: again
            subprocess.run([str(exe), "run", str(BASE),
                            *set_args(common + CONTACT_VARIANTS[k][1] + [f"output.file={out}"])],
                           check=True, capture_output=True)
        t, tension, _ = fairlead_tension(out)
        peak_mean = float(cycle_maxima(t, tension, period, cycles).mean())
        with h5py.File(out, "r") as f:
            return (CONTACT_VARIANTS[k][0], int(f["solver/steps"][()]),
                    int(f["solver/err_test_fails"][()]), int(f["solver/rhs_evals"][()]),
                    float(f["solver/cpu_time"][()]), peak_mean)

    with ThreadPoolExecutor(max_workers=jobs) as pool:
        return list(pool.map(one, range(len(CONTACT_VARIANTS))))


def contact_lines(rows):
    if not rows:
        return []
    return ["| variant | steps | rejected | f evaluations | CPU (s) | mean of the 2 cycle maxima (N) |",
            "|---|---|---|---|---|---|",
            *(f"| {label} | {steps:,} | {rej:,} | {rhs:,} | {cpu:.2f} | {peak:.2f} |"
              for label, steps, rej, rhs, cpu, peak in rows)]


# ---------------------------------------------------------------- page

def fmt(x, digits=1):
    return f"{x:.{digits}f}"


def results_table(results, models, periods):
    head = "| T (s) | R (m) | measured (N) | " + " | ".join(
        f"{name(m)} mean (N) | spread | error" for m in models) + " |"
    lines = [head, "|---|---|---|" + "---|---|---|" * len(models)]
    for period in periods:
        for j, radius in enumerate(RADII):
            meas = MEASURED[period][j]
            cells = []
            for model in models:
                r = results.get((model, period, radius))
                if r is None:
                    cells.append("– | – | –")
                else:
                    cells.append(f"{r['mean']:.2f} | {r['spread']:.2f} | "
                                 f"{100 * (r['mean'] / meas - 1):+.1f} %")
            lines.append(f"| {period} | {radius} | {meas} | " + " | ".join(cells) + " |")
    return lines


def model_scores(results, model, periods):
    comp, meas = [], []
    for period in periods:
        for j, radius in enumerate(RADII):
            r = results.get((model, period, radius))
            if r is not None:
                comp.append(r["mean"])
                meas.append(MEASURED[period][j])
    return (scores(comp, meas), len(comp)) if comp else (None, 0)


def cost_lines(results, models, periods, walls, work=None):
    lines = ["| model | cases | CPU per case, mean (s) | min | max | CPU, all (s) | steps per case | rejected |",
             "|---|---|---|---|---|---|---|---|"]
    for model in models:
        rs = [results[k] for k in results if k[0] == model and k[1] in periods]
        if not rs:
            continue
        cpu = np.array([r["cpu_time"] for r in rs])
        steps = np.mean([r["steps"] for r in rs])
        rej = np.mean([r["err_test_fails"] for r in rs])
        lines.append(f"| {name(model)} | {len(rs)} | {cpu.mean():.1f} | {cpu.min():.1f} | "
                     f"{cpu.max():.1f} | {cpu.sum():.0f} | {steps:,.0f} | {rej:,.0f} |")
    for model in models:
        start = static_start_cpu(work, model) if work is not None else None
        if start is not None:
            lines += ["", f"The {name(model)}'s static start (`ropedyn statics` of the base "
                          f"scene, the same for every condition, not in the CPU above): "
                          f"{start:.2f} s of CPU."]
    for model in models:
        cases = sum(1 for k in results if k[0] == model)
        if model in walls:
            lines += ["", f"Wall time of the {name(model)}'s {cases} cases, two at a time "
                          "(`ropedyn sweep FILE --task K` from one queue, the longest periods "
                          f"first; static start included): {walls[model]:.0f} s, on two "
                          "cores shared with other work."]
    return lines


def change_error(row, ref):
    """The sampling error of a convergence row's change against ref, %: the standard errors
    of the two means of cycle maxima (spread / sqrt(cycles)) combined, over ref's mean. The
    cycle maxima of an irregular condition vary from cycle to cycle, and a change smaller
    than this is not resolved by the runs."""
    se2 = sum(r["spread"] ** 2 / len(r["maxima"]) for r in (row, ref))
    return 100 * math.sqrt(se2) / ref["mean"]


def convergence_lines(rows):
    if not rows:
        return []
    lines = [f"| model | T (s) | elements | rtol (atol = {base_atol() / base_rtol():g} rtol) "
             f"| mean cycle max (N) | spread (N) | change from "
             f"{base_elements()}, {base_rtol():g} | its sampling error | CPU (s) |",
             "|---|---|---|---|---|---|---|---|---|"]
    for row in rows:
        ref = reference(rows, row)
        err = "" if row is ref else f"± {change_error(row, ref):.2f} %"
        label = row["model"].upper() + (f", {row['law']}" if row["law"] else "")
        lines.append(f"| {label} | {row['period']} | {row['n']} | {row['rtol']:g} | "
                     f"{row['mean']:.3f} | {row['spread']:.2f} | "
                     f"{100 * (row['mean'] / ref['mean'] - 1):+.2f} % | {err} | "
                     f"{row['cpu_time']:.1f} |")
    return lines


def figures(results, models, periods, work, figdir, stem):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    figdir.mkdir(parents=True, exist_ok=True)
    names = []
    fig, ax = plt.subplots(figsize=(5, 5))
    lo, hi = 20, 80
    ax.plot([lo, hi], [lo, hi], "k-", lw=0.8)
    for model, marker in zip(models, "os^v"):
        xs, ys = [], []
        for period in periods:
            for j, radius in enumerate(RADII):
                r = results.get((model, period, radius))
                if r is not None:
                    xs.append(MEASURED[period][j])
                    ys.append(r["mean"])
        ax.plot(xs, ys, marker, mfc="none", label=name(model))
    md = moordyn_means(work, periods)
    if md:
        ax.plot([MEASURED[p][RADII.index(r)] for p, r in md], list(md.values()), "x",
                color="0.4", label="MoorDyn-C")
    ax.set_xlabel("measured mean cycle maximum (N)")
    ax.set_ylabel("computed (N)")
    ax.set_xlim(lo, hi)
    ax.set_ylim(lo, hi)
    ax.legend()
    ax.grid(alpha=0.3)
    fig.tight_layout()
    names.append(f"{stem}_measured.png")
    fig.savefig(figdir / names[-1], dpi=110)
    plt.close(fig)
    conds = [c for c in HISTORIES if c[0] in periods]
    if conds:
        fig, axes = plt.subplots(len(conds), 1, figsize=(8, 2.6 * len(conds)), squeeze=False)
        for ax, (period, radius) in zip(axes[:, 0], conds):
            for model in models:
                path = case_path(work, period, model, radius)
                if complete(path):
                    t, tension, _ = fairlead_tension(path)
                    ax.plot(t / period, tension, lw=0.8, label=name(model))
            ax.axhline(MEASURED[period][RADII.index(radius)], color="k", ls="--", lw=0.8,
                       label="measured mean max")
            ax.axvspan(CYCLES - ANALYSED, CYCLES, color="0.9")
            ax.set_title(f"T = {period} s, R = {radius} m", fontsize=9)
            ax.set_ylabel("fairlead tension (N)")
            ax.legend(fontsize=7, loc="upper left")
        axes[-1, 0].set_xlabel("t / T (shaded: the analysed cycles)")
        fig.tight_layout()
        names.append(f"{stem}_histories.png")
        fig.savefig(figdir / names[-1], dpi=110)
        plt.close(fig)
    return names


def moordyn_file(work, period, radius):
    """The kept result of MoorDyn-C on a condition (scripts/bench_peers bergdahl, its default
    setting), or None."""
    path = (work / "moordyn" / f"T{period:g}_R{radius:g}_n165_dt0.000326_ct0.09582_"
            f"c{CYCLES}.json")
    return path if path.exists() else None


def moordyn_means(work, periods):
    import json
    return {(p, r): json.loads(f.read_text())["mean"] for p in periods for r in RADII
            if (f := moordyn_file(work, p, r)) is not None}


def moordyn_cpu(work, periods):
    """MoorDyn-C's CPU over the conditions it has run (scripts/bench_peers bergdahl keeps its
    results in WORK/moordyn/): (cases, seconds), or (0, 0)."""
    import json
    total, count = 0.0, 0
    for period in periods:
        for radius in RADII:
            hits = sorted((work / "moordyn").glob(f"T{period:g}_R{radius:g}_n165_dt0.000326_"
                                                  f"ct0.09582_c{CYCLES}.json"))
            if hits:
                total += json.loads(hits[0].read_text())["cpu"]
                count += 1
    return count, total


def target_lines(results, models, periods, walls, conv, work):
    """Each target of the study, met or not, from the results at hand."""
    lines = ["| target | value | met |", "|---|---|---|"]
    models = [m for m in models if m in MODELS]       # the variants are for information
    for model in models:
        s, count = model_scores(results, model, periods)
        if s is None:
            continue
        lines.append(f"| {name(model)}: RMSE <= 1.5 N ({count} conditions) | {s['rmse']:.2f} N | "
                     f"{'yes' if s['rmse'] <= 1.5 else 'no'} |")
        lines.append(f"| {name(model)}: MAPE <= 3 % | {s['mape']:.2f} % | "
                     f"{'yes' if s['mape'] <= 3 else 'no'} |")
    for model in models:
        rows = [r for r in conv if r["model"] == model and not r["law"]]
        if not rows:
            continue
        worst, worst_err = 0.0, 0.0
        for r in rows:
            if is_base(r):
                continue
            ref = reference(rows, r)
            if (base_elements() <= r["n"] <= 2 * base_elements() + 1
                    and abs(r["mean"] / ref["mean"] - 1) > worst):
                # the halvings, not the coarser run nor the quartered element length
                worst, worst_err = abs(r["mean"] / ref["mean"] - 1), change_error(r, ref)
        lines.append(f"| {name(model)}: halving the element length or the tolerances changes the mean "
                     f"cycle maximum by <= 0.5 % | {100 * worst:.2f} % (sampling error "
                     f"± {worst_err:.2f} %) | {'yes' if worst <= 0.005 else 'no'} |")
    for model in models:
        if model in walls and sum(1 for k in results if k[0] == model) == 30:
            w = walls[model]
            lines.append(f"| {name(model)}: all 30 in <= 2 min wall on 2 cores | {w:.0f} s | "
                         f"{'yes' if w <= 120 else 'no'} |")
    count, md = moordyn_cpu(work, periods)
    for model in models:
        rs = [results[k] for k in results if k[0] == model]
        start = static_start_cpu(work, model)
        if count == len(rs) == 30 and start is not None:
            # MoorDyn's CPU includes its static start: ropedyn's with its own
            ours = sum(r["cpu_time"] for r in rs) + len(rs) * start
            lines.append(f"| {name(model)}: MoorDyn-C CPU / ropedyn CPU >= 3 (30 cases, static "
                         f"starts included) | {md:.0f} s / {ours:.0f} s = {md / ours:.2f} | "
                         f"{'yes' if md / ours >= 3 else 'no'} |")
    return lines


def section(results, models, periods, walls, conv, figs, command, work, contact=()):
    md = [BEGIN, "",
          f"Generated by `{command}` ({run_stamp()}, {os.cpu_count()} cores); do not edit "
          "by hand.", ""]
    md += ["### Scores", "",
           "| model | cases | RMSE (N) | MAPE (%) | bias (N) | correlation | worst (%) |",
           "|---|---|---|---|---|---|---|"]
    for model in models:
        s, count = model_scores(results, model, periods)
        if s is not None:
            md.append(f"| {name(model)} | {count} | {s['rmse']:.2f} | {s['mape']:.2f} | "
                      f"{s['bias']:+.2f} | {s['corr']:.4f} | {s['worst']:.1f} |")
    mdm = moordyn_means(work, periods)
    for model in (m for m in models if m in MODELS):     # MoorDyn's reading is the scene's
        keys = [k for k in mdm if (model, *k) in results]
        if len(keys) > 2:
            d = np.array([results[model, p, r]["mean"] / mdm[p, r] - 1 for p, r in keys])
            e_md = [mdm[p, r] / MEASURED[p][RADII.index(r)] - 1 for p, r in keys]
            e_us = [results[model, p, r]["mean"] / MEASURED[p][RADII.index(r)] - 1
                    for p, r in keys]
            md += ["", f"{name(model)} against MoorDyn-C on the same {len(keys)} conditions: "
                   f"{100 * d.mean():+.2f} % on average ({100 * d.min():+.2f} .. "
                   f"{100 * d.max():+.2f} %); the correlation of the two codes' errors against "
                   f"the measurement is {np.corrcoef(e_md, e_us)[0, 1]:.3f}."]
    md += ["", "### Each condition", "",
           "Mean of the 5 cycle maxima, their standard deviation (spread) and the error "
           "against the measurement.", ""]
    md += results_table(results, models, periods)
    depths = [f"{name(m)} {1e3 * max(r['deepest'] for k, r in results.items() if k[0] == m):.2f} mm"
              for m in models if any(k[0] == m for k in results)]
    md += ["", "How deep the rope's deepest point goes below the floor over the analysed cycles "
           f"of all conditions: {', '.join(depths)}. Lying still, the floor's law sinks the "
           f"chain by {1e3 * static_sinking():.1e} mm; the rest is landings "
           "([ground contact](../theory/effects.md#ground-contact))."]
    if figs:
        md += ["", f"![measured against computed](../figures/{figs[0]})", ""]
        if len(figs) > 1:
            md += [f"![tension histories](../figures/{figs[1]})", ""]
    failed = failures(work, periods, models)
    if failed:
        md += ["", "Runs that did not complete (not in the scores):", ""]
        md += [f"- {name(m)}, T = {p} s, R = {r} m: {why}" for m, p, r, why in failed]
    md += ["", "### Targets", ""] + target_lines(results, models, periods, walls, conv, work)
    md += ["", "### Cost", ""] + cost_lines(results, models, periods, walls, work)
    if conv:
        md += ["", "### Convergence", "",
               f"R = 0.2 m, each run its own {CONV_CYCLES} cycles, the last {CONV_ANALYSED} "
               "analysed (more than the study's 5: see the sampling error); the change of the "
               "mean cycle maximum "
               f"against {base_elements()} elements at rtol {base_rtol():g}, atol "
               f"{base_atol():g} (the runs whose axial springs carry compression, the law "
               f"before `compression = .false.`, against their own {base_elements()} "
               "elements: what the compressed chain did to the element length's error). At "
               f"{CONV_ELEMENTS[-1]} elements also the tolerances quartered, and CVODE alone "
               "and held at BDF2 (`max_order = 2`), against the study's setting.", ""]
        md += convergence_lines(conv)
    if contact:
        md += ["", "### The floor's cost", "",
               f"RFEM, {base_elements()} elements, rtol {base_rtol():g}, atol {base_atol():g} "
               "(the scene's): T = 1.25 s, R = 0.2 m "
               "from its record at the "
               "start of the 7th cycle, 2 cycles (2.5 s), each variant the same window.", ""]
        md += contact_lines(contact)
    md += ["", END]
    return "\n".join(md)


def main(argv=None):
    parser = argparse.ArgumentParser(description=summary(__doc__))
    add_exe_argument(parser)
    parser.add_argument("--out", default=str(DOCS / "validation" / "bergdahl.md"))
    parser.add_argument("--work", default=str(ROOT / "out" / "bergdahl"),
                        help="directory of the case files (kept: a rerun reuses them)")
    parser.add_argument("--models", default="rfem,mpp", type=list_text(choice(LABELS), ","),
                        help="models or MODEL_VARIANT labels, comma-separated (default rfem,mpp)")
    parser.add_argument("--periods", type=list_text(positive(float), ","),
                        default=",".join(str(p) for p in PERIODS))
    parser.add_argument("--radii", type=list_text(positive(float), ","),
                        default=",".join(str(r) for r in RADII))
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--convergence", action="store_true",
                        help="also the runs at other element lengths and tolerances")
    parser.add_argument("--convergence-models", default=None,
                        type=list_text(choice(MODELS), ","),
                        help="the models of the convergence runs (default: --models)")
    parser.add_argument("--contact-cost", action="store_true",
                        help="also the cost of the floor: one window with other methods and "
                             "floor laws")
    parser.add_argument("--analyse-only", action="store_true",
                        help="no runs: analyse the case files in --work")
    parser.add_argument("--quick", type=list_text(positive(int), ",", length=2), default=None,
                        metavar="ELEMENTS,CYCLES",
                        help="smoke test: that many elements and cycles (one analysed), "
                             "a one-cycle ramp")
    parser.add_argument("--figures", default=str(DOCS / "figures"))
    args = parser.parse_args(argv)
    models = tuple(args.models.split(","))
    periods = tuple(float(p) for p in args.periods.split(","))
    radii = tuple(float(r) for r in args.radii.split(","))
    work = pathlib.Path(args.work).resolve()
    quick = tuple(int(v) for v in args.quick.split(",")) if args.quick else None
    cycles = 1 if quick else ANALYSED
    conv_models = tuple((args.convergence_models or ",".join(
        m for m in models if m in MODELS)).split(","))
    walls = {}
    exe = pathlib.Path(exe_or_build(args.exe)).resolve()
    version = exe_version(exe)          # the code whose case files count
    if args.analyse_only:
        used = [case_path(work, p, m, r) for m in models for p in periods for r in RADII]
        used += [run[-1] for run in convergence_files(work, models=conv_models)] \
            if args.convergence else []
        used += contact_files(work) if args.contact_cost else []
        refuse_stale(used, work, exe, version, "bergdahl: --analyse-only",
                     "run the command without --analyse-only, which runs them again")
    else:
        walls = run_sweeps(exe, periods, models, radii, work, args.jobs, quick=quick,
                           version=version)
    results = collect(work, periods, models, cycles)
    if not quick:
        walls = sweep_walls(work, models)
        for label in models:
            if any(k[0] == label for k in results):
                static_start_cpu(work, label, exe)
    conv = []
    if args.convergence:
        conv = convergence(exe, work, args.jobs, models=conv_models, version=version)
    contact = []
    if args.contact_cost:
        contact = contact_cost(exe, work, args.jobs, version=version)
    out = pathlib.Path(args.out)
    stem = out.stem
    figs = figures(results, models, periods, work, pathlib.Path(args.figures), stem)
    shown = shown_arguments(argv if argv is not None else sys.argv[1:])
    command = " ".join(["scripts/validation bergdahl", *shown])
    block = section(results, models, periods, walls, conv, figs, command, work, contact)
    update_doc(out, BEGIN, END, block, heading="## Results\n\n",
               default="# Bergdahl chain\n")
    for model in models:
        s, count = model_scores(results, model, periods)
        if s is not None:
            print(f"bergdahl {model}: {count} cases, RMSE {s['rmse']:.2f} N, MAPE "
                  f"{s['mape']:.2f} %, bias {s['bias']:+.2f} N, correlation {s['corr']:.4f}")
    print(f"bergdahl: wrote {out}")


if __name__ == "__main__":
    main()
