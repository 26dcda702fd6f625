"""The getting-started page's runs, pictures and numbers, made by the page's own commands.

usage: scripts/getting_started [--no-write] [--keep DIR]

The code of scripts/getting_started; writes the sections between the `getting_started ...`
markers of docs/getting-started.md (and the summary the output guide, docs/guide/output.md,
shows: the same run) and the pictures of docs/figures/getting-started/.

In a scratch folder that sees the clone's input/ (as the clone's top folder does), it does
what the page tells a newcomer to do, with the files the page writes (its `cat > FILE
<<'EOF'` here-documents, read from the page itself):

- `scripts/run input/paper.nml`: the summary it prints, the overview plot, and the
  strobe and energy pictures of Example 1 (studies/readme_figures.py draws them);
- the sweep of Example 2 (`ropedyn sweep my/methods.nml --jobs 2`) and the page's own
  plotting snippet, whose picture the page shows;
- `scripts/run input/chain_in_water.nml` (Example 3) and the tension the page predicts
  at rest, from the effective scene the run file holds;
- `scripts/run my/my_rope.nml` and `scripts/animate out/my_rope.h5` (the first own scene).

A command that fails stops the script with its output: the page would be wrong. Every
number in the written sections is taken from these runs; the prose around them names none.
"""
import argparse
import csv
import functools
import math
import os
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile

import numpy as np

from ropedyn import io
from ropedyn_tools.repo import DOCS, ROOT
from ropedyn_tools.studies.common import run_stamp, splice
from ropedyn_tools.studies.readme_figures import draw
from ropedyn.docstrings import summary

PAGE = DOCS / "getting-started.md"
FIGURES = DOCS / "figures" / "getting-started"
PYTHON = ROOT / ".venv" / "bin" / "python"

OUTPUT_GUIDE = DOCS / "guide" / "output.md"
#: the generated sections, `<!-- getting_started NAME:begin -->` .. `:end -->`, and their
#: pages: the page's own, and the output guide's summary (the page's first run)
SECTIONS = {"paper": PAGE, "paper balance": PAGE, "sweep": PAGE, "chain": PAGE,
            "chain tension": PAGE, "my_rope": PAGE, "summary": OUTPUT_GUIDE}
#: a here-document of the page: the command line that opens it and its body
_HEREDOC = re.compile(r"^(?P<command>[^\n]*)<<'EOF'\n(?P<body>.*?)^EOF$", re.S | re.M)
#: the file a `cat > FILE` here-document writes
_CAT = re.compile(r"\bcat > (?P<file>\S+)")


def heredocs(text):
    """The page's here-documents: ({FILE: text} of the `cat > FILE <<'EOF'` ones, [text] of
    the Python snippets, `... python - <<'EOF'`), in page order."""
    files, snippets = {}, []
    for m in _HEREDOC.finditer(text):
        cat = _CAT.search(m.group("command"))
        if cat:
            files[cat.group("file")] = m.group("body")
        elif "python" in m.group("command"):
            snippets.append(m.group("body"))
    return files, snippets


def command(args, cwd, stdin=None):
    """Run args in cwd; their standard output. A failure ends the study (exit 1) with the
    command's output: the page's command does not work as the page says."""
    result = subprocess.run([str(a) for a in args], cwd=cwd, input=stdin, text=True,
                            capture_output=True)
    if result.returncode != 0:
        sys.exit(f"getting_started: `{' '.join(map(str, args))}` failed in {cwd} "
                 f"(exit {result.returncode}):\n{result.stdout}{result.stderr}")
    return result.stdout


def scratch(work, page_text):
    """The scratch folder as the clone's top folder looks to the page: input/ and the
    files the page writes."""
    (work / "input").symlink_to(ROOT / "input")
    files, snippets = heredocs(page_text)
    for name, body in files.items():
        (work / name).parent.mkdir(parents=True, exist_ok=True)
        (work / name).write_text(body)
    return files, snippets


def scripts_run(work, scene, *sets):
    """`scripts/run SCENE [--set ...]` in the scratch folder: what it prints."""
    extra = [a for s in sets for a in ("--set", s)]
    return command([ROOT / "scripts" / "run", scene, *extra], work)


@functools.lru_cache(maxsize=None)
def stamp():
    """The run's stamp, the same on every section (git asked once)."""
    return f"(`scripts/getting_started`, {run_stamp()})"


def short(text):
    """A number's text without the exponent's sign and leading zeros: 1e-05 -> 1e-5."""
    return re.sub(r"e([+-])0*(\d)", lambda m: "e" + m.group(1).replace("+", "") + m.group(2),
                  text)


def sci(x):
    """x in two digits: -1.1e-7."""
    return short(f"{x:.1e}")


def largest_kinetic(run):
    return float(np.max(run.energy["kinetic"]))


def balance_error(run):
    """The energy balance error of every record, J (docs/theory/energy-balance.md)."""
    return run.balance - run.e0


def paper_sections(work, figures):
    """The first run: its summary, its pictures and Example 1's sentence."""
    printed = scripts_run(work, "input/paper.nml")
    run = io.load_run(work / "out" / "paper.h5")
    shutil.copy(work / "out" / "paper_plot.png", figures / "paper_plot.png")
    draw(work / "out" / "paper.h5", figures, 1.4, 15)
    error = balance_error(run)
    summary = "\n".join([
        f"What it printed {stamp()}; the version, the CPU time and the counts depend on "
        "the build and the machine:", "", "```text", printed.rstrip(), "```", "",
        f"Its balance error at the end is {sci(error[-1])} J, against a kinetic energy of "
        f"up to {largest_kinetic(run):.2f} J."])
    program = "\n".join(line for line in printed.rstrip().splitlines()
                        if not line.startswith(("plot:", "xdmf:")))
    guide = "\n".join([
        f"The summary of `ropedyn run input/paper.nml` {stamp()}:", "", "```text", program,
        "```"])
    example = (f"The energy balance error (lower panel) stays within "
               f"{sci(np.max(np.abs(error)))} J over the {run.time[-1]:.0f} s {stamp()}: "
               "the numbers are right to that level even where the motion is chaotic.")
    return {"paper": summary, "paper balance": example, "summary": guide}


def cheapest_text(rows):
    """What the sweep's summary says of the methods' CPU times at each tolerance."""
    cpu = {(r["method"], float(r["rtol"])): float(r["cpu_time"]) for r in rows}
    rtols = sorted({rtol for _, rtol in cpu}, reverse=True)
    methods = sorted({m for m, _ in cpu})
    cheapest = {}
    for t in rtols:
        cheapest.setdefault(min(methods, key=lambda m, t=t: cpu[m, t]), []).append(t)
    if len(cheapest) == 1:
        where = f"{next(iter(cheapest))} at every tolerance"
    else:
        where = "; ".join(f"{m} at {', '.join(short(f'{t:.0e}') for t in ts)}"
                          for m, ts in cheapest.items())
    ratios = {m: [cpu[m, t] / cpu["erk", t] for t in rtols] for m in methods if m != "erk"}
    against = "; ".join(f"{m} {min(r):.1f} to {max(r):.1f}" for m, r in ratios.items())
    return (f"The cheapest in this run: {where}. CPU time against erk's at the same "
            f"tolerance: {against} {stamp()}.")


def sweep_section(work, figures, snippets):
    """Example 2: the sweep, the page's plotting snippet, and what its summary says."""
    exe = ROOT / "build" / "release" / "ropedyn"
    listed = command([exe, "sweep", "my/methods.nml", "--list"], work)
    command([exe, "sweep", "my/methods.nml", "--jobs", "2"], work)
    status = command([exe, "sweep", "my/methods.nml", "--status"], work)
    command([PYTHON, "-"], work, stdin=snippets[0])
    shutil.copy(work / "out" / "methods" / "work_precision.png", figures / "sweep.png")
    with open(work / "out" / "methods" / "summary.csv", newline="") as f:
        rows = [r for r in csv.DictReader(f)]
    cases = len(re.findall(r"^\d{4}\s", listed, re.M))
    print(f"getting_started: sweep of {cases} cases; status:\n{status}")
    return {"sweep": cheapest_text(rows)}


def tension_at_rest(run):
    """The pin's force on the chain hanging at rest in the water of the run's scene, N, and
    the text of the sum: weight less the buoyancy of its part below the surface."""
    rope, fluid = run.group("rope"), run.group("fluid")
    g, length, mu = rope["gravity"], rope["length"], rope["mass_per_length"]
    d, rho, surface = rope["diameter"], fluid["density"], fluid["surface"]
    wet = length - surface
    force = mu * g * length - rho * g * math.pi * d ** 2 / 4 * wet
    text = (f"{mu:g} \u00b7 {g:g} \u00b7 {length:g} \u2212 {rho:g} \u00b7 {g:g} \u00b7 "
            f"\u03c0 ({d:g})\u00b2/4 \u00b7 {wet:g} = {force:.3f} N")
    return force, wet, text


def chain_section(work, figures):
    """Example 3: the dissipated energy, when the tip comes to the vertical, and the top
    tension against the tension at rest."""
    scripts_run(work, "input/chain_in_water.nml")
    run = io.load_run(work / "out" / "chain_in_water.h5")
    shutil.copy(work / "out" / "chain_in_water_plot.png", figures / "chain_in_water_plot.png")
    force, wet, text = tension_at_rest(run)
    top = np.hypot(*run.reactions["top"].T)
    tip = run.points[:, -1, :]
    off = np.abs(tip[:, 1] - run.points[:, 0, 1]) > 0.05 * run.group("rope")["length"]
    vertical = run.time[np.flatnonzero(off)[-1] + 1] if off.any() else 0.0
    return {"chain": (
        f"The drag is strong for so thin and light a chain: it does not swing but sinks "
        f"towards the vertical, its tip within 5 % of its length of the pin's vertical from "
        f"{vertical:.1f} s on, and the dampers and the water take "
        f"{run.energy['dissipated'][-1]:.2f} J out, the `dissipated` of the plot's energy "
        f"panel {stamp()}:"),
        "chain tension": (
        f"At rest the pin carries the weight of the chain less the buoyancy of its {wet:g} m "
        f"under water, {text}, and the run's tension at the top after "
        f"{run.time[-1]:.0f} s, as the file stores it, is {top[-1]:.4f} N, "
        f"{1e3 * abs(top[-1] - force):.1f} mN from it, the chain still settling "
        f"{stamp()}:")}


def own_scene_section(work, figures):
    """The first own scene: its balance error against its energies; the animation made."""
    scripts_run(work, "my/my_rope.nml")
    command([ROOT / "scripts" / "animate", "out/my_rope.h5"], work)
    if not (work / "out" / "my_rope.gif").is_file():
        sys.exit("getting_started: scripts/animate wrote no out/my_rope.gif")
    run = io.load_run(work / "out" / "my_rope.h5")
    shutil.copy(work / "out" / "my_rope_plot.png", figures / "my_rope_plot.png")
    error = balance_error(run)
    return {"my_rope": (
        f"The heavy tip swings down and up the other side and the rope whips around it; "
        f"the energy balance is printed as before: {sci(error[-1])} J at the end, against a "
        f"kinetic energy of up to {largest_kinetic(run):.1f} J {stamp()}.")}


def markers(name):
    """The begin and end markers of the page's section NAME."""
    return (f"<!-- getting_started {name}:begin -->", f"<!-- getting_started {name}:end -->")


def write_pages(parts):
    """Each part between its markers (see markers) on its page (SECTIONS); all must be
    there."""
    for page in dict.fromkeys(SECTIONS.values()):
        text = page.read_text()
        for name in (name for name, where in SECTIONS.items() if where == page):
            begin, end = markers(name)
            new = splice(text, begin, end, f"{begin}\n{parts[name]}\n{end}")
            if new is None:
                sys.exit(f"getting_started: {page} has no markers {begin} .. {end}")
            text = new
        page.write_text(text)


def main(argv=None):
    parser = argparse.ArgumentParser(description=summary(__doc__))
    parser.add_argument("--no-write", action="store_true",
                        help="run and print, write neither the page nor its pictures")
    parser.add_argument("--keep", type=pathlib.Path, default=None,
                        help="the scratch folder (kept; default: a temporary one)")
    args = parser.parse_args(argv)
    page_text = PAGE.read_text()
    with tempfile.TemporaryDirectory() as tmp:
        work = args.keep or pathlib.Path(tmp) / "clone"
        figures = pathlib.Path(tmp) / "figures" if args.no_write else FIGURES
        figures.mkdir(parents=True, exist_ok=True)
        work.mkdir(parents=True, exist_ok=True)
        files, snippets = scratch(work, page_text)
        print(f"getting_started: in {work}, the page's files {', '.join(files)}", flush=True)
        parts = {**paper_sections(work, figures), **sweep_section(work, figures, snippets),
                 **chain_section(work, figures), **own_scene_section(work, figures)}
    assert set(parts) == set(SECTIONS), "every section of SECTIONS is made"
    for name, body in parts.items():
        print(f"[{name}]\n{body}\n")
    if not args.no_write:
        write_pages(parts)
        print(f"getting_started: {PAGE}, {OUTPUT_GUIDE}, pictures in {figures}")
    return 0


if __name__ == "__main__":
    os.environ.setdefault("MPLBACKEND", "Agg")
    sys.exit(main())
