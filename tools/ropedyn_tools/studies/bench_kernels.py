"""Cost of the model kernels per call, before and after a change (issue 14).

The code of scripts/bench_kernels (python -m ropedyn_tools.studies.bench_kernels; without --build
it builds the Release configuration first). For RFEM (the paper's rope, every internal
effect) and the MPP (the same rope, model.kind = 'mpp') at several n it measures, with
tests/bench/bench_rhs, the right-hand side, the first-order Jacobian, the second-order
blocks K, C, M (explicit form; for the MPP also the implicit form) and the quadratures:
- CPU time per call and element (fastest of 5 repetitions; noisy on a shared machine);
- instructions per call counted by valgrind's callgrind (the difference of two runs with
  different numbers of calls, so set-up is not counted): the noise-free figure.
With --baseline REV the same bench_rhs.f90 is also built from git revision REV (git archive;
the working tree is untouched) and both are reported side by side. The table goes into
docs/performance/step.md between the markers of the section "Model kernels".
"""
import argparse
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile

from ropedyn_tools.arguments import list_text, positive
from ropedyn_tools.repo import DOCS, PAPER, build, set_args
from ropedyn_tools.studies.bench_rhs import build_bench_rhs
from ropedyn_tools.studies.common import baseline_revision, machine, update_doc, run_stamp
from ropedyn.docstrings import summary

BEGIN = "<!-- bench_kernels:begin -->"
END = "<!-- bench_kernels:end -->"
KERNELS = ["rhs", "jac", "blocks", "blocks_implicit", "quad"]
LABELS = {"rhs": "RHS", "jac": "Jacobian", "blocks": "blocks (explicit)",
          "blocks_implicit": "blocks (implicit)", "quad": "quadratures"}
MODELS = {"rfem": [], "mpp": ['model.kind="mpp"']}


def bench(exe, model, n, seconds):
    """ns per element of every kernel (None where the model does not offer it)."""
    cmd = [str(exe), str(PAPER), *set_args(MODELS[model] + [f"model.elements={n}"]),
           "--seconds", str(seconds)]
    out = subprocess.run(cmd, capture_output=True, text=True)
    if out.returncode != 0:
        raise SystemExit(f"bench_rhs failed: {' '.join(cmd)}\n{out.stderr}")
    fields = out.stdout.split()
    values = [float(x) for x in fields[1:6]]
    return {k: (v if v >= 0 else None) for k, v in zip(KERNELS, values)}


def instructions(exe, model, n, kernel, calls):
    """Instructions executed by `calls` calls of a kernel (callgrind total)."""
    with tempfile.TemporaryDirectory() as tmp:
        cmd = ["valgrind", "--tool=callgrind", f"--callgrind-out-file={tmp}/out",
               str(exe), str(PAPER), *set_args(MODELS[model] + [f"model.elements={n}"]),
               "--calls", str(calls), "--kernel", kernel]
        out = subprocess.run(cmd, capture_output=True, text=True)
    found = re.search(r"Collected\s*:\s*(\d+)", out.stderr)
    if out.returncode != 0 or not found:
        raise SystemExit(f"callgrind failed: {' '.join(cmd)}\n{out.stderr[-2000:]}")
    return int(found.group(1))


def per_call(exe, model, n, kernel, extra=3):
    """Instructions per call: (I(2 + extra) - I(2)) / extra (the first calls warm up)."""
    return (instructions(exe, model, n, kernel, 2 + extra)
            - instructions(exe, model, n, kernel, 2)) / extra


def fmt(x, digits=0):
    if x is None:
        return "n/a"
    return f"{x:,.{digits}f}"


def ratio(before, after):
    if before is None or after is None or after == 0:
        return ""
    return f"{before / after:.1f}x"


def main(argv=None):
    parser = argparse.ArgumentParser(description=summary(__doc__))
    parser.add_argument("--build", default=None, help="Release build directory (default: "
                        "build the Release configuration with scripts/build and use it)")
    parser.add_argument("--baseline", default=None,
                        help="git revision to compare with (e.g. the merge base)")
    parser.add_argument("--rfem-elements", type=list_text(positive(int)),
                        default="30 300 1000")
    parser.add_argument("--mpp-elements", type=list_text(positive(int)), default="10 30 70")
    parser.add_argument("--seconds", type=float, default=0.3,
                        help="time per repetition of each timing (5 repetitions, fastest kept)")
    parser.add_argument("--no-callgrind", action="store_true",
                        help="timings only (no instruction counts)")
    parser.add_argument("--no-write", action="store_true", help="print only")
    args = parser.parse_args(argv)
    base_rev = baseline_revision(parser, args.baseline)
    exe = pathlib.Path(args.build or build("Release")) / "tests" / "bench_rhs"
    cases = [("rfem", int(n)) for n in args.rfem_elements.split()] + \
            [("mpp", int(n)) for n in args.mpp_elements.split()]
    callgrind = not args.no_callgrind and shutil.which("valgrind") is not None

    with tempfile.TemporaryDirectory() as tmp:
        base_exe = build_bench_rhs(args.baseline, pathlib.Path(tmp)) if args.baseline else None
        rows = []
        for model, n in cases:
            # the two builds back to back, so that both see the same machine load
            now = bench(exe, model, n, args.seconds)
            before = bench(base_exe, model, n, args.seconds) if base_exe else None
            for kernel in KERNELS:
                if kernel == "blocks_implicit" and model == "rfem":
                    continue   # RFEM has no mass matrix: the implicit form is the explicit one
                ir_now = ir_before = None
                if callgrind:
                    ir_now = per_call(exe, model, n, kernel) if now[kernel] is not None \
                        else None
                    if before is not None and before[kernel] is not None:
                        ir_before = per_call(base_exe, model, n, kernel)
                row = (model, n, kernel, before[kernel] if before else None, now[kernel],
                       ir_before, ir_now)
                rows.append(row)
                print(row, flush=True)

    if base_exe:
        header = ("| model | n | kernel | before (ns per element) | after (ns per element) | "
                  "speed-up | before (instructions per call) | after (instructions per "
                  "call) | ratio |")
        sep = "|---|---|---|---|---|---|---|---|---|"
    else:
        header = "| model | n | kernel | ns per element | instructions per call |"
        sep = "|---|---|---|---|---|"
    lines = [header, sep]
    for model, n, kernel, tb, ta, ib, ia in rows:
        if base_exe:
            lines.append(f"| {model} | {n} | {LABELS[kernel]} | {fmt(tb, 1)} | {fmt(ta, 1)} | "
                         f"{ratio(tb, ta)} | {fmt(ib)} | {fmt(ia)} | {ratio(ib, ia)} |")
        else:
            lines.append(f"| {model} | {n} | {LABELS[kernel]} | {fmt(ta, 1)} | {fmt(ia)} |")
    print("\n".join(lines))
    if args.no_write:
        return 0

    cmd = "scripts/bench_kernels" + (f" --baseline {args.baseline}" if args.baseline else "")
    if args.rfem_elements != "30 300 1000":
        cmd += f' --rfem-elements "{args.rfem_elements}"'
    if args.mpp_elements != "10 30 70":
        cmd += f' --mpp-elements "{args.mpp_elements}"'
    before_note = (f" Before: git revision {args.baseline} ({base_rev}) built with the same "
                   "bench_rhs.f90." if base_exe else "")
    block = "\n".join([
        BEGIN,
        f"Command: `{cmd}` (Release build; `tests/bench/bench_rhs` on input/paper.nml with "
        "`model.elements` = n, RFEM or `model.kind = 'mpp'`; time: CPU time per call divided "
        f"by n, fastest of 5 repetitions of about {args.seconds} s, every call including the "
        "zeroing of its output arrays; instructions: callgrind, per call, set-up "
        f"excluded).{before_note} n/a: the kernel is not offered (the default second-order "
        "blocks need an analytic implicit Jacobian, which the MPP does not have).",
        f"Machine: {machine()}. Run: {run_stamp()}.",
        "",
        *lines,
        END,
    ])
    doc = DOCS / "performance" / "step.md"
    update_doc(doc, BEGIN, END, block, heading="## Model kernels (issue 14)\n\n", strip="\n")
    print(f"wrote {doc}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
