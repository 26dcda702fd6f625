"""Run the hard scenes (input/hard) and the CVODE order study; write docs/validation/.

The code of scripts/stability_report (python -m ropedyn_tools.studies.stability_report; without
--exe it builds the Release executable first). Two
sections of docs/validation/ (PAGES) are rewritten between their markers; the text around them
(the reading of the numbers) is kept:

- `cvode-order`: the measurements behind CVODE's default maximum order: the light-damping
  and undamped paper scenes (n = 30) and the steel wire at CVODE max_order 2 .. 5, with and
  without stability-limit detection, and MEBDF at its default for comparison;
- `hard-scenes`: one table per hard scene (solver, settings, steps, CPU time, energy-balance
  error, energy growth, max tip speed, outcome);
- `long-horizon` (and with it `numerical-damping`, `order-safety` and `energy-horizon`,
  the balance error over 300 s in m g L): the long-horizon
  matrix of ropedyn_tools.studies.long_horizon (every scene of input/hard to its t_end, the
  default and every method at rtol 1e-3, 1e-5, 1e-7; the order-safety cases), the same runs
  as the CTest label `long` and from the same cache (build/long): after `scripts/test
  --long` this section only reads the files.

Horizons are chosen so that the whole report takes under 20 minutes on 2 cores
(`--jobs 2`, the default); `--quick` divides every horizon by 10 for a smoke run (no file written unless
`--write` is given). Measures: ropedyn_tools.studies.stability_metrics.
"""
import argparse
import concurrent.futures
import datetime
import pathlib
import re
import subprocess
import tempfile

from ropedyn_tools.repo import DOCS, INPUT, add_exe_argument, exe_or_build, set_args
from ropedyn_tools.studies import long_horizon, stability_metrics
from ropedyn_tools.studies.common import machine, run_commit, splice
from ropedyn.docstrings import summary

#: the page of each generated section
PAGES = {
    "hard-scenes": DOCS / "validation" / "hard-scenes.md",
    "cvode-order": DOCS / "validation" / "cvode-order.md",
    "long-horizon": DOCS / "validation" / "long-horizon.md",
    "order-safety": DOCS / "validation" / "order-safety.md",
    "numerical-damping": DOCS / "validation" / "order-safety.md",
    "energy-horizon": DOCS / "validation" / "energy.md",
}
HARD = INPUT / "hard"

# (label, scene file, horizon in s, extra --set overrides)
ORDER_SCENES = [
    ("paper_light_damping (n = 30)", INPUT / "paper_light_damping.nml", 5.0, []),
    ("undamped (n = 30)", HARD / "undamped.nml", 5.0, []),
    ("steel_wire (n = 30)", HARD / "steel_wire.nml", 0.1, []),
]
# (label, overrides) of the order study: CVODE orders with and without STALD, MEBDF default
ORDER_SETTINGS = (
    [(f"cvode {k}", ["solver.method=cvode", f"solver.max_order={k}",
                     "solver.stability_limit_detection=F"]) for k in (2, 3, 4, 5)]
    + [(f"cvode {k} + STALD", ["solver.method=cvode", f"solver.max_order={k}",
                               "solver.stability_limit_detection=T"]) for k in (3, 4, 5)]
    + [("mebdf 4 (default)", ["solver.method=mebdf", "solver.max_order=0"])])

# Hard scenes: (scene, horizon in s, settings). The settings are the defaults of both
# solvers and the alternatives studied where they are affordable.
DEFAULTS = [("cvode (default: max order 5)", ["solver.method=cvode"]),
            ("mebdf (default: max order 4)", ["solver.method=mebdf"])]
CVODE2 = [("cvode, max_order = 2", ["solver.method=cvode", "solver.max_order=2"])]
STALD = [("cvode + stability_limit_detection", ["solver.method=cvode",
                                                "solver.stability_limit_detection=T"])]
HARD_SCENES = [
    ("steel_wire", 1.0, DEFAULTS + CVODE2 + STALD),
    ("undamped", 5.0, DEFAULTS),
    ("light_damping", 5.0, DEFAULTS),
    ("no_bending", 2.0, DEFAULTS),
    ("thin_thread", 2.0, DEFAULTS),
    ("long_rope", 10.0, DEFAULTS),
    ("whip", 1.5, DEFAULTS),
    ("clamped_taut", 1.0, DEFAULTS + CVODE2),
    ("mpp_light_damping", 5.0, DEFAULTS),
    ("elements_1000", 0.2, DEFAULTS + CVODE2),
    ("elements_3000", 0.05, DEFAULTS + CVODE2),
    ("elements_10000", 0.02, DEFAULTS),
    ("shaken_support", 2.0, DEFAULTS),
    ("folded_release", 1.0, DEFAULTS),
    ("folded_n301", 0.6, DEFAULTS),
    ("whip_ground", 2.0, DEFAULTS),
    ("whip_ground_mpp", 2.0, DEFAULTS),
    ("snap_load", 2.0, DEFAULTS),
    ("snap_load_mpp", 2.0, DEFAULTS),
    ("heavy_mass", 5.0, DEFAULTS),
    ("heavy_mass_mpp", 5.0, DEFAULTS),
    ("mpp_light_damping_n30", 5.0, DEFAULTS),
    ("mpp_light_damping_n70", 1.0, DEFAULTS),
    ("mpp_undamped", 5.0, DEFAULTS),
]
# every scene of input/hard has its table (a new scene needs a horizon here)
_MISSING = sorted(set(p.stem for p in HARD.glob("*.nml")) - {s for s, _, _ in HARD_SCENES})
assert not _MISSING, f"input/hard scenes without a horizon in HARD_SCENES: {_MISSING}"


def run(exe, scene, t_end, overrides, out, timeout):
    """Run one case; return the measures (or the reason it gave no file)."""
    cmd = [str(exe), "run", str(scene),
           *set_args([f"solver.t_end={t_end}", f"output.file={out}", *overrides])]
    try:
        res = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return {"outcome": f"killed after {timeout} s wall time"}
    if not out.exists():
        what = "refused" if res.returncode == 2 else "no output"
        return {"outcome": f"{what} (exit {res.returncode}): "
                           f"{res.stderr.strip().removeprefix('ropedyn: error: ')}"}
    m = stability_metrics.analyse(out)
    bad = stability_metrics.all_finite(out)
    if m["status"] == "complete" and res.returncode == 0:
        outcome = "complete"
    else:
        outcome = f"failed (exit {res.returncode}) at t = {m['t_reached']:.4g} s: {m['reason']}"
    if bad:
        outcome += f"; NON-FINITE data in {', '.join(bad)}"
    m["outcome"] = outcome
    out.unlink()
    return m


def run_all(exe, cases, jobs, timeout):
    """cases: list of (key, scene, t_end, overrides); returns {key: measures}."""
    results = {}
    with tempfile.TemporaryDirectory() as tmp, \
            concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
        futures = {}
        for i, (key, scene, t_end, overrides) in enumerate(cases):
            out = pathlib.Path(tmp) / f"case{i}.h5"
            futures[pool.submit(run, exe, scene, t_end, overrides, out, timeout)] = key
        for fut in concurrent.futures.as_completed(futures):
            key = futures[fut]
            results[key] = fut.result()
            r = results[key]
            print(f"  {key}: {r['outcome']}"
                  + (f", {r['steps']} steps, {r['cpu_time']:.2f} s" if "steps" in r else ""),
                  flush=True)
    return results


def fmt(x, spec):
    return "" if x is None else format(x, spec)


def order_table(results, scale):
    lines = []
    for label, scene, t_end, _ in ORDER_SCENES:
        lines.append(f"**{label}**, {t_end * scale:g} s, rtol 1e-6, atol 1e-8\n")
        lines.append("| solver, max order | steps | error-test fails | CPU (s) | "
                     "energy-balance error (J) | final balance B-E0 (J) | energy growth (J) | "
                     "final T+V-E0 (J) | outcome |")
        lines.append("|---|---|---|---|---|---|---|---|---|")
        for slabel, _ in ORDER_SETTINGS:
            r = results[(label, slabel)]
            if "steps" not in r:
                lines.append(f"| {slabel} |  |  |  |  |  |  |  | {r['outcome']} |")
                continue
            final = r["mech"][-1] - r["mech"][0]
            lines.append(
                f"| {slabel} | {r['steps']} | {r['err_test_fails']} | "
                f"{fmt(r['cpu_time'], '.2f')} | {r['balance_error']:.1e} | "
                f"{r['balance_drift'][-1]:+.1e} | {r['energy_growth']:.1e} | {final:.2e} | "
                f"{short(r['outcome'])} |")
        lines.append("")
    return "\n".join(lines)


def short(outcome):
    return outcome if len(outcome) < 160 else outcome[:157] + "..."


def hard_tables(results, scale):
    lines = []
    for scene in dict.fromkeys(s for s, _, _ in HARD_SCENES):
        text = (HARD / f"{scene}.nml").read_text()
        header = []
        for line in text.splitlines():
            if not line.startswith("!"):
                break
            header.append(line[1:].strip())
        what = " ".join(header)[len("HARD: "):]
        lines.append(f"### {scene}\n")
        lines.append(f"`input/hard/{scene}.nml`: {what}\n")
        lines.append("| solver, settings | horizon (s) | steps | error-test fails | CPU (s) | "
                     "energy-balance error (J) | error / (rtol S) | energy growth (J) | "
                     "max tip speed (m/s) | outcome |")
        lines.append("|---|---|---|---|---|---|---|---|---|---|")
        for s, t_end, settings in HARD_SCENES:
            if s != scene:
                continue
            for slabel, _ in settings:
                r = results[(s, t_end, slabel)]
                if "steps" not in r:
                    lines.append(f"| {slabel} | {t_end * scale:g} |  |  |  |  |  |  |  | "
                                 f"{r['outcome']} |")
                    continue
                ratio = r["balance_error"] / (r["rtol"] * r["energy_scale"])
                if r["bottom_free"]:
                    speed, where = r["tip_speed"], ""
                else:
                    speed, where = r["mid_speed"], " (midpoint)"
                k = int(speed.argmax())
                lines.append(
                    f"| {slabel} | {r['t_reached']:.4g} | {r['steps']} | {r['err_test_fails']} | "
                    f"{fmt(r['cpu_time'], '.2f')} | {r['balance_error']:.1e} | {ratio:.2g} | "
                    f"{r['energy_growth']:.1e} | {speed[k]:.3g} at {r['time'][k]:.3g} s{where} | "
                    f"{short(r['outcome'])} |")
        lines.append("")
    return "\n".join(lines)


def replace_section(text, name, body):
    begin, end = f"<!-- {name}:begin -->", f"<!-- {name}:end -->"
    new = splice(text, begin, end, f"{begin}\n{body}\n{end}")
    if new is None:
        raise SystemExit(f"{PAGES[name]}: markers {begin} ... {end} not found")
    return new


def order_cases(scale):
    """The cases of the CVODE order study: (key, scene, t_end, overrides), slow ones first."""
    cases = [((label, slabel), scene, t_end * scale, ov + sov)
             for label, scene, t_end, ov in ORDER_SCENES
             for slabel, sov in ORDER_SETTINGS]
    # the slow ones (low orders) first, so that the workers finish together
    cases.sort(key=lambda c: not re.search(r"cvode [23]", c[0][1]))
    return cases


def hard_cases(scale):
    """The cases of the hard scenes: (key, scene, t_end, overrides), slow ones first."""
    cases = [((s, t_end, slabel), HARD / f"{s}.nml", t_end * scale, sov)
             for s, t_end, settings in HARD_SCENES for slabel, sov in settings]
    slow = ["steel_wire", "long_rope", "folded_n301", "light_damping", "undamped",
            "mpp_light_damping_n30", "mpp_undamped", "heavy_mass_mpp", "elements_3000"]
    cases.sort(key=lambda c: slow.index(c[0][0]) if c[0][0] in slow else len(slow))
    return cases


# section name -> (what is printed first, its cases, its introduction, its tables)
STUDIES = {
    "cvode-order": (
        "CVODE order study:", order_cases,
        "Energy-balance error: max |B - E0| with B = T+V+dissipated; final balance: B - E0 "
        "at the end, signed (positive: the integrator created energy, negative: it damped "
        "some numerically); energy growth: the largest rise of T+V above an earlier value "
        "(with damping on any rise beyond the integration error is an instability); final "
        "T+V-E0: the mechanical energy lost (dissipated, or damped numerically) or gained.",
        order_table),
    "hard-scenes": (
        "Hard scenes:", hard_cases,
        "rtol 1e-6, atol 1e-8 (the scenes' solver settings) unless stated; S is the "
        "energy scale (max T + max elastic + gravity range + dissipated); max tip speed: "
        "of the free end at the output times, a released end's too (of the midpoint where "
        "both ends are held throughout: clamped_taut and the snap loads).",
        hard_tables),
}


def long_matrix_table(res):
    lines = ["| scene | t_end (s) | run | steps | CPU (s) | balance error / (rtol S) | "
             "largest gain / (rtol S) | B - E0 at the end (J) | orders | outcome |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for key, scene, _ in long_horizon.matrix_cases():
        r = res[key]
        run = key.split("/", 1)[1].replace("/", ", rtol ")
        if "steps" not in r:
            lines.append(f"| {scene} |  | {run} |  |  |  |  |  |  | {short(r['outcome'])} |")
            continue
        orders = "-".join(str(k) for k in (min(r["orders"]), max(r["orders"]))) \
            if r["orders"] else ""
        if r.get("order_lowered_at") is not None:
            orders += f" (lowered to {r['order_lowered_to']} at {r['order_lowered_at']:.3g} s)"
        lines.append(
            f"| {scene} | {r['t_end']:g} | {run} | {r['steps']} | {fmt(r['cpu_time'], '.1f')} | "
            f"{r['balance_ratio']:.2g} | {r['max_gain_ratio']:.2g} | {r['final_drift']:+.1e} | "
            f"{orders} | {short(r['outcome'])} |")
    total = sum(r.get("cpu_time") or 0.0 for r in res.values())
    worst = {}
    for key, _, _ in long_horizon.matrix_cases():
        r = res[key]
        if "steps" in r:
            m = r["method"]
            worst[m] = max(worst.get(m, 0.0), r["balance_ratio"])
    lines.append("")
    lines.append(f"Total CPU time of the matrix: {total / 60:.0f} min. Largest balance error / "
                 "(rtol S) per method: " + ", ".join(f"{m} {v:.3g}" for m, v in
                                                      sorted(worst.items())) + ".")
    return "\n".join(lines)


def damping_table(res):
    """The energy the integrator removes per second on the undamped scenes."""
    undamped = [s for s in long_horizon.scenes() if long_horizon.is_undamped(s)]
    runs = [("default", None)] + [(m, t) for m in long_horizon.METHODS
                                  for t in long_horizon.RTOLS]
    lines = ["| scene | run | t_end (s) | E0 scale S (J) | removed per second (J/s) | "
             "per second / S | B - E0 at the end (J) |", "|---|---|---|---|---|---|---|"]
    for scene in undamped:
        for method, rtol in runs:
            key = f"{scene}/default" if rtol is None else f"{scene}/{method}/{rtol:g}"
            r = res[key]
            label = "default" if rtol is None else f"{method}, rtol {rtol:g}"
            if "steps" not in r or not r["energy_scale"]:
                # (not run, or stopped at its start: the symplectic method's refusal)
                lines.append(f"| {scene} | {label} |  |  |  |  | {short(r['outcome'])} |")
                continue
            lines.append(f"| {scene} | {label} | {r['t_reached']:g} | "
                         f"{r['energy_scale']:.3g} | {r['damping_rate']:.2e} | "
                         f"{r['damping_rate'] / r['energy_scale']:.1e} | "
                         f"{r['final_drift']:+.2e} |")
    return "\n".join(lines)


def order_safety_table(res):
    lines = ["| scene | method, max order, order_safety | steps | CPU (s) | "
             "largest gain / (rtol S) | balance error / (rtol S) | order lowered | outcome |",
             "|---|---|---|---|---|---|---|---|"]
    for key, scene, _ in long_horizon.order_cases():
        r = res[key]
        label = key.split("/", 2)[2]
        if "steps" not in r:
            lines.append(f"| {scene} | {label} |  |  |  |  |  | {short(r['outcome'])} |")
            continue
        low = "" if r.get("order_lowered_at") is None else \
            f"to {r['order_lowered_to']} at {r['order_lowered_at']:.3g} s"
        lines.append(f"| {scene} | {label} | {r['steps']} | {fmt(r['cpu_time'], '.1f')} | "
                     f"{r['max_gain_ratio']:.3g} | {r['balance_ratio']:.3g} | {low} | "
                     f"{short(r['outcome'])} |")
    return "\n".join(lines)


def energy_table(res):
    """The balance error over 300 s of every method (long_horizon.energy_cases), m g L."""
    lines = ["| scene | method | steps | CPU (s) | B - E0 at 30 s | at 300 s | "
             "max abs to 30 s | max abs to 300 s | outcome |",
             "|---|---|---|---|---|---|---|---|---|"]
    for key, scene, _ in long_horizon.energy_cases():
        r = res[key]
        method = key.rsplit("/", 1)[1]
        if "steps" not in r:
            lines.append(f"| {scene} | {method} |  |  |  |  |  |  | {short(r['outcome'])} |")
            continue
        at, mx = r.get("drift_mgl_at", {}), r.get("max_drift_mgl_to", {})
        cells = [f"{d[k]:+.1e}" if k in d else "" for d in (at,) for k in ("30", "300")] + \
            [f"{d[k]:.1e}" if k in d else "" for d in (mx,) for k in ("30", "300")]
        lines.append(f"| {scene} | {method} | {r['steps']} | {fmt(r['cpu_time'], '.1f')} | "
                     + " | ".join(cells) + f" | {short(r['outcome'])} |")
    return "\n".join(lines)


def long_sections(exe, jobs, command, stamp, cached_only=False):
    """Run (or read from the cache) the long-horizon matrix; the four sections."""
    cases = long_horizon.matrix_cases() + long_horizon.order_cases() + \
        long_horizon.energy_cases()
    res = long_horizon.run_all(exe, cases, long_horizon.default_workdir(), jobs=jobs,
                               cached_only=cached_only)
    head = (f"{command} (Release build; the runs of `scripts/test --long`, cached in "
            f"build/long). {stamp}\n\n")
    methods = ", ".join(long_horizon.METHODS)
    return {
        "long-horizon": head + (
            f"Every scene of `input/hard/` to its t_end: the default run (the scene's "
            f"settings: method auto, rtol 1e-6) and {methods} at rtol 1e-3, 1e-5, 1e-7 "
            "(atol = rtol/100). Balance error: max |T + V + dissipated - work - E0|; largest "
            "gain: max (B - E0), positive: energy created; orders: the lowest and highest "
            "order of the output records.\n\n") + long_matrix_table(res),
        "numerical-damping": head + (
            "The undamped scenes (no damper, no contact): everything the balance loses is "
            "the integrator's numerical damping. Removed per second: -(B - E0)/t at the "
            "end.\n\n") + damping_table(res),
        "order-safety": head + (
            "rtol 1e-3, atol 1e-5, 10 s. `off`: no energy monitor; `lower` (the default): "
            "on a gain above 10 rtol S the run goes back one record and on at the "
            "method's A-stable order.\n\n") + order_safety_table(res),
        "energy-horizon": head + (
            f"The undamped and the lightly damped rope (n = 30) to "
            f"{long_horizon.ENERGY_T_END:g} s, rtol 1e-3, atol 1e-5, a record every 0.1 s, "
            f"every method and auto: the balance error B - E0 = T + V + dissipated - "
            f"work - E0 in units of m g L (the rope's weight times its length, "
            f"1.156 J), signed at 30 s and 300 s, and its largest absolute value over "
            f"the records up to each.\n\n") + energy_table(res),
    }


def command_text(quick, only, cached_only=False):
    """The stamp's command: the one that remakes the sections a run wrote, and only them
    (the whole report remakes them too)."""
    words = ["scripts/stability_report"] + (["--quick"] if quick else [])
    if cached_only:
        words += ["--only", "long-horizon", "--cached-only"]
    elif only:
        words += ["--only", only]
    return "Command: `" + " ".join(words) + "`"


def main(argv=None):
    parser = argparse.ArgumentParser(description=summary(__doc__))
    add_exe_argument(parser)
    parser.add_argument("--jobs", type=int, default=2, help="runs at a time (default 2)")
    parser.add_argument("--only", choices=["cvode-order", "hard-scenes", "long-horizon"],
                        default=None)
    parser.add_argument("--quick", action="store_true", help="horizons / 10, no file written")
    parser.add_argument("--write", action="store_true", help="write the pages "
                        "even with --quick")
    parser.add_argument("--no-write", action="store_true", help="print only")
    parser.add_argument("--cached-only", action="store_true", help="long-horizon: only "
                        "the runs in the cache (build/long); the others are listed as not run")
    parser.add_argument("--timeout", type=float, default=1200.0, help="wall time per run (s)")
    args = parser.parse_args(argv)
    exe = exe_or_build(args.exe)
    scale = 0.1 if args.quick else 1.0
    write = not args.no_write and (args.write or not args.quick)
    started = datetime.datetime.now(datetime.timezone.utc)
    stamp = (f"Machine: {machine()}. Run: {started:%Y-%m-%d %H:%M} UTC{run_commit()}, "
             f"--jobs {args.jobs}.")
    command = command_text(args.quick, args.only)
    sections = {}

    for name, (heading, cases, intro, table) in STUDIES.items():
        if args.only not in (None, name):
            continue
        print(heading, flush=True)
        res = run_all(exe, cases(scale), args.jobs, args.timeout)
        sections[name] = f"{command} (Release build). {stamp}\n\n{intro}\n\n" + table(res, scale)
        print(sections[name])

    if args.only in (None, "long-horizon") and not args.quick:
        print("Long-horizon matrix:", flush=True)
        sections.update(long_sections(exe, args.jobs,
                                      command_text(args.quick, args.only, args.cached_only),
                                      stamp, args.cached_only))

    elapsed = datetime.datetime.now(datetime.timezone.utc) - started
    print(f"elapsed: {elapsed.total_seconds():.0f} s")
    if write:
        for page in sorted({PAGES[name] for name in sections}):
            text = page.read_text()
            for name, body in sections.items():
                if PAGES[name] == page:
                    text = replace_section(text, name, body)
            page.write_text(text)
            print(f"wrote {page}")


if __name__ == "__main__":
    main()
